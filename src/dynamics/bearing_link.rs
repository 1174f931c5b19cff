//! A film bearing inside the time step: the film force on the journal, its stiffness and damping,
//! and the contact with the bearing wall when the film can no longer hold the journal.

use crate::film::{
    equilibrium_with_inertia, Equilibrium, FilmCoefficients, FilmError, FilmInertia, FilmModel,
    FilmResult, JournalKinematics, ViscosityScaledFilm,
};
use nalgebra::{Matrix2, Vector2};

/// Contact with the bearing wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactModel {
    /// Eccentricity ratio at which the wall takes over (the film is evaluated no further out):
    /// 0.99 leaves a minimum film of 1 % of the clearance, the scale of surface roughness.
    pub onset_eccentricity_ratio: f64,
    /// Radial wall stiffness beyond the onset (N/m).
    pub wall_stiffness_n_per_m: f64,
    /// Coulomb friction coefficient of the rubbing contact.
    pub friction_coefficient: f64,
    /// Smallest film thickness (m) at which the film pressure is reported as valid: full-film
    /// lubrication needs a film thickness ratio Λ = h_min/σ ≥ 3 (Hamrock, Schmid & Jacobson,
    /// Fundamentals of Machine Elements, §8.8), σ the composite roughness of journal and bush;
    /// ASSUMED σ = 0.5 µm (ground journal Ra ≈ 0.2 µm, bored bush Ra ≈ 0.4 µm, σ ≈ 1.25 √(Ra₁² +
    /// Ra₂²)), so 1.5 µm. Thinner, the mixed-lubrication regime begins and the isoviscous
    /// rigid-surface pressure, rising as h⁻³ towards the wall, is no physical figure.
    pub full_film_min_thickness_m: f64,
}

impl Default for ContactModel {
    fn default() -> Self {
        Self {
            onset_eccentricity_ratio: 0.99,
            wall_stiffness_n_per_m: 2e9,
            friction_coefficient: 0.15,
            full_film_min_thickness_m: 1.5e-6,
        }
    }
}

/// What one evaluation of a bearing gives the step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkEvaluation {
    /// Total force on the journal: film plus wall contact (N).
    pub force_n: [f64; 2],
    /// −∂F/∂d (N/m).
    pub stiffness: Matrix2<f64>,
    /// −∂F/∂ḋ (N·s/m).
    pub damping: Matrix2<f64>,
    /// The film's own share of `stiffness` (the rest is the wall's) (N/m).
    pub film_stiffness: Matrix2<f64>,
    /// −∂F/∂d̈ (kg): the film's fluid inertia, zero without it (its force −m d̈ is added by
    /// the step, which knows the acceleration).
    pub added_mass_kg: Matrix2<f64>,
    /// The film solution.
    pub film: FilmResult,
    /// True if the journal was in contact with the wall.
    pub contact: bool,
    /// Power dissipated by the wall's Coulomb friction (W): μ N |ωR + v_t|, zero without contact.
    pub rub_power_w: f64,
}

/// The static equilibrium a linear coupling linearises about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LinearReference {
    /// Journal position relative to the bearing (m).
    pub position_m: [f64; 2],
    /// Film force there (N).
    pub force_n: [f64; 2],
    /// The eight coefficients there.
    pub coefficients: FilmCoefficients,
}

/// A film bearing as the step sees it.
pub(crate) struct BearingLink {
    pub name: String,
    /// Reduced DOF indices of the journal centre (x, y).
    pub journal: [usize; 2],
    /// Reduced DOF indices of the pedestal (x, y), if flexible.
    pub pedestal: Option<[usize; 2]>,
    /// Position of this bearing's journal x in the condensed vector q_B.
    pub b_offset: usize,
    pub clearance_m: f64,
    pub radius_m: f64,
    /// The reference viscosity the film is solved at (Pa·s); the running one is
    /// [`viscosity`](Self::viscosity).
    pub viscosity_pa_s: f64,
    /// The film, scaled to the running viscosity.
    pub film: ViscosityScaledFilm,
    /// Linear coupling: the static equilibrium (relative position, film force) and its coefficients.
    pub linear_reference: Option<LinearReference>,
    /// Prehistory: the raw coefficients of the previous step, c(k−1) of seed eq. 8.
    pub previous_raw: Option<FilmCoefficients>,
    /// The film's fluid inertia, if the bearing carries it.
    pub inertia: Option<FilmInertia>,
    /// The inertia's length factor κ of the last evaluation with coefficients (the iterations
    /// without coefficients keep it).
    pub kappa: f64,
    /// The last evaluation.
    pub last: LinkEvaluation,
}

impl BearingLink {
    /// The running viscosity (Pa·s).
    pub fn viscosity(&self) -> f64 {
        self.viscosity_pa_s * self.film.scale()
    }

    /// `coef` with the added mass of the film `film` at relative position `d` (m), if the
    /// bearing carries its fluid inertia.
    pub fn with_added_mass(
        &self,
        coef: FilmCoefficients,
        d: [f64; 2],
        film: &FilmResult,
        speed_rad_s: f64,
    ) -> FilmCoefficients {
        match &self.inertia {
            Some(inertia) => inertia.add_to(coef, d, film, self.viscosity(), speed_rad_s),
            None => coef,
        }
    }

    /// Puts the linear reference at the film's equilibrium under `load` (N) at `speed_rad_s`
    /// (with `fluid_inertia: full` the film carries the steady convective force too: the
    /// reference force is the total, −load) and returns it with that total force (N).
    pub fn linearise(
        &mut self,
        load: [f64; 2],
        speed_rad_s: f64,
    ) -> Result<(Equilibrium, [f64; 2]), FilmError> {
        let mu = self.viscosity();
        let eq = equilibrium_with_inertia(&mut self.film, self.inertia, mu, load, speed_rad_s)?;
        let coefficients =
            self.with_added_mass(eq.coefficients, eq.position_m, &eq.film, speed_rad_s);
        let mut force_n = eq.film.force_n;
        if let Some(inertia) = self.inertia {
            let f = inertia.convective_force_at(&eq, mu, speed_rad_s);
            force_n = [force_n[0] + f[0], force_n[1] + f[1]];
            let damping = &eq.coefficients.damping_n_s_per_m;
            self.kappa = inertia.length_factor(eq.position_m, &eq.film, damping, mu);
        }
        self.linear_reference = Some(LinearReference {
            position_m: eq.position_m,
            force_n,
            coefficients,
        });
        Ok((eq, force_n))
    }

    /// `coef` with the temporal added mass of the film `film` at relative position `d` (m), if
    /// the bearing carries its fluid inertia; keeps the length factor κ.
    fn with_temporal_mass(
        &mut self,
        coef: FilmCoefficients,
        d: [f64; 2],
        film: &FilmResult,
    ) -> FilmCoefficients {
        let Some(inertia) = self.inertia else {
            return coef;
        };
        let (mu, damping) = (self.viscosity(), &coef.damping_n_s_per_m);
        self.kappa = inertia.length_factor(d, film, damping, mu);
        FilmCoefficients {
            added_mass_kg: inertia.added_mass(d, film, damping, mu),
            ..coef
        }
    }

    /// With `fluid_inertia: full`, eq. I1's force beyond the added mass (N) at the journal's
    /// state (relative position `d`, velocity `v`, speed `speed`) on the zone of `film`; its
    /// derivatives join `coef` (the Newton iteration's Jacobian: the force is ≈ 4 % of the load
    /// and its slopes 3–9 % of the film's, too much to leave explicit without slowing Newton's
    /// quadratic convergence, which the step's acceptance test relies on).
    fn convective_inertia(
        &self,
        coef: &mut FilmCoefficients,
        d: [f64; 2],
        v: [f64; 2],
        film: &FilmResult,
        speed: f64,
    ) -> [f64; 2] {
        let Some(inertia) = self.inertia.filter(|i| i.convective) else {
            return [0.0; 2];
        };
        let f = inertia.transient_force(d, v, film, speed, self.kappa);
        coef.stiffness_n_per_m += f.stiffness_n_per_m;
        coef.damping_n_s_per_m += f.damping_n_s_per_m;
        f.force_n
    }

    /// Number of condensed DOFs of this bearing (journal, and pedestal if any).
    pub fn width(&self) -> usize {
        if self.pedestal.is_some() {
            4
        } else {
            2
        }
    }

    /// Film (and wall) force, stiffness and damping at relative position `d` (m), velocity `v`
    /// (m/s) and speed `speed` (rad/s). Without `with_coefficients` the film's coefficients are
    /// not computed (left zero; the wall's still are). With them and without fluid inertia
    /// the film's outputs in `film` may be left zero until [`complete_film`](Self::complete_film)
    /// (force and coefficients are whole). Allocates nothing.
    pub fn evaluate(
        &mut self,
        d: [f64; 2],
        v: [f64; 2],
        speed: f64,
        contact: &ContactModel,
        with_coefficients: bool,
    ) -> Result<LinkEvaluation, FilmError> {
        let c = self.clearance_m;
        let e = d[0].hypot(d[1]);
        let onset = contact.onset_eccentricity_ratio * c;
        let in_contact = e > onset;
        let d_film = if in_contact {
            [d[0] * onset / e, d[1] * onset / e]
        } else {
            d
        };
        let kin = JournalKinematics {
            position_m: d_film,
            velocity_m_s: v,
            speed_rad_s: speed,
        };
        let (film, mut coef) = if with_coefficients && self.inertia.is_none() {
            // a Newton iterate needs the force and coefficients only: the film's outputs
            // (p_max, ζ1, ζ2, friction) of the accepted iterate by `complete_film`
            self.film.solve_lean(&kin)?
        } else if with_coefficients {
            let (film, coef) = self.film.solve_with_coefficients(&kin)?;
            (film, self.with_temporal_mass(coef, d_film, &film))
        } else {
            // the added mass of the iteration before (prehistory keeps its matrix for the step)
            let mass = self.last.added_mass_kg;
            let coef = FilmCoefficients {
                added_mass_kg: mass,
                ..FilmCoefficients::default()
            };
            (self.film.solve(&kin)?, coef)
        };
        let inertia_force = self.convective_inertia(&mut coef, d_film, v, &film, speed);
        let mut out = LinkEvaluation {
            force_n: [
                film.force_n[0] + inertia_force[0],
                film.force_n[1] + inertia_force[1],
            ],
            stiffness: coef.stiffness_n_per_m,
            damping: coef.damping_n_s_per_m,
            film_stiffness: coef.stiffness_n_per_m,
            added_mass_kg: coef.added_mass_kg,
            film,
            contact: in_contact,
            rub_power_w: 0.0,
        };
        if in_contact {
            let n = [d[0] / e, d[1] / e];
            let t = [-n[1], n[0]];
            let n_nt = Vector2::from(n) * Vector2::from(n).transpose();
            // the film is evaluated on the onset circle: it sees only the tangential motion,
            // K_f · (I − n nᵀ) · (onset / e)
            out.stiffness = coef.stiffness_n_per_m * (Matrix2::identity() - n_nt) * (onset / e);
            out.film_stiffness = out.stiffness;
            // wall: radial spring beyond the onset, Coulomb friction against the surface sliding
            let penetration = e - onset;
            let normal = contact.wall_stiffness_n_per_m * penetration;
            let slide = speed * self.radius_m + (v[0] * t[0] + v[1] * t[1]);
            let friction = -contact.friction_coefficient * normal * slide.signum();
            out.rub_power_w = (friction * slide).abs();
            for i in 0..2 {
                out.force_n[i] += -normal * n[i] + friction * t[i];
            }
            out.stiffness += n_nt * contact.wall_stiffness_n_per_m;
        }
        self.last = out;
        Ok(out)
    }

    /// The film's outputs (p_max, ζ1, ζ2, friction, flows) in the last evaluation when that was
    /// lean (`evaluate` leaves them for the accepted iterate): after the step's iteration, once.
    pub fn complete_film(&mut self) {
        if let Some(film) = self.film.completed_result() {
            self.last.film = film;
        }
    }

    /// The linear coupling's force law F = F₀ − K₀(d − d₀) − C₀ ḋ about the static equilibrium
    /// (and − M₀ d̈ with the film's fluid inertia, added by the step).
    pub fn evaluate_linear(&mut self, d: [f64; 2], v: [f64; 2]) -> LinkEvaluation {
        let LinearReference {
            position_m: d0,
            force_n: f0,
            coefficients: coef,
        } = self
            .linear_reference
            .expect("linear reference set at construction");
        let k = coef.stiffness_n_per_m;
        let cc = coef.damping_n_s_per_m;
        let (d, d0, v) = (Vector2::from(d), Vector2::from(d0), Vector2::from(v));
        let f = Vector2::from(f0) - k * (d - d0) - cc * v;
        let out = LinkEvaluation {
            force_n: f.into(),
            stiffness: k,
            damping: cc,
            film_stiffness: k,
            added_mass_kg: coef.added_mass_kg,
            film: self.last.film,
            contact: false,
            rub_power_w: 0.0,
        };
        self.last = out;
        out
    }
}
