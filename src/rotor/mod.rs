//! The rotor: Timoshenko finite-element model of the shaft (4 DOF a node: x, y, θx, θy), rigid
//! discs, bearings and their supports, assembled into global M, K, G and C (seed §"Model").
//!
//! Global DOFs: node n holds `4n … 4n+3` = (x, y, θx, θy); each flexible pedestal adds two DOFs
//! (x, y) after the shaft's. The equations of motion are M q̈ + (C + Ω G) q̇ + K q = F plus the
//! bearing forces between each journal and its pedestal (or the ground).

mod critical_speeds;
mod element;
mod error;
mod forces;
mod machine;
mod modal;
pub mod mode_tracking;
mod oil_heating;
mod statics;
mod thermal_threshold;
mod unbalance_response;
mod zone_following;

pub use critical_speeds::{
    critical_speeds, critical_speeds_zone_following, CriticalSpeed,
    API_684_MIN_AMPLIFICATION_FACTOR,
};
pub use element::{Disc, ElementMatrix, Material, ShaftElement};
pub use error::{ConfigError, RotorError};
pub use forces::unbalance_force;
pub use machine::max_speed_rpm;
pub(crate) use machine::{mapping_name, shown};
pub use machine::{
    AlarmLevelsSpec, BearingModelSpec, BearingSpec, DiscSpec, FilmSpec, GroovesSpec, LubricantSpec,
    MachineDescription, MachineDescriptionOf, MaterialSpec, OilHeatingModel, OilHeatingSpec,
    ProbeSpec, ProximityProbeSpec, RawBearingSpec, RunoutSpec, ShaftSection, SupportSpec,
    UnbalanceSpec, ViscosityTableSpec, ViscosityTemperatureSpec, DEFAULT_CARRY_OVER,
    DEFAULT_MACHINE_NAME, DEFAULT_MACHINE_YAML, MAX_SURFACE_SPEED_M_S,
};
pub(crate) use modal::BearingSolvers;
pub use modal::{
    campbell, campbell_zone_following, damped_mode_shapes, damped_modes, natural_frequencies,
    stability_threshold, stability_threshold_tabulated, stability_threshold_zone_following,
    undamped_frequencies_hz, BearingCoefficientSet, CampbellPoint, Constraint, Mode, ModeShape,
    NaturalFrequencies, Threshold, WhirlDirection,
};
pub use oil_heating::BearingTemperature;
pub use statics::{static_solution, StaticSolution};
pub use thermal_threshold::{
    effective_temperature_threshold, stability_threshold_thermal, thermal_equilibria,
    ThermalBearing,
};
pub use unbalance_response::{
    influence_coefficients, journal_orbits, required_separation_margin_pct, response_peaks,
    response_stations, unbalance_response, unbalance_response_zone_following, ResponsePeak,
    Station, StationResponse, UnbalanceResponse,
};
pub use zone_following::{following_minus_held, ZONE_FOLLOWING_STEP};

use crate::film::{
    BearingGeometry, FilmCoefficients, FilmGrid, FilmModel, FiniteFilm, Lubricant, ShortFilm,
};
use crate::units::rpm_to_rad_s;
use faer::Mat;

/// How a bearing acts on its journal (a film bearing carries its viscosity table in place, see
/// [`crate::film::ViscosityLaw`]: under 1 kB a bearing).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum BearingModel {
    /// A fluid film (finite-length Reynolds or short bearing).
    Film(FilmBearing),
    /// Constant coefficients.
    Linear(FilmCoefficients),
    /// A rigid, pinned support.
    Rigid,
}

/// A fluid-film bearing's data, from which film solvers are built.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmBearing {
    /// Geometry.
    pub geometry: BearingGeometry,
    /// Lubricant.
    pub lubricant: Lubricant,
    /// Finite-volume grid (finite model).
    pub grid: FilmGrid,
    /// Short-bearing closed form instead of the finite solver.
    pub short: bool,
    /// The oil's viscosity–temperature law, if the machine file gives one.
    pub viscosity_law: Option<crate::film::ViscosityLaw>,
    /// The law's design supply temperature (K), with the law.
    pub design_supply_temperature_k: Option<f64>,
    /// The bearing's own heating by an effective temperature (`oil_heating` in the machine
    /// file), if asked for: see [`Rotor::heat_films`].
    pub heating: Option<crate::film::OilHeating>,
    /// The running oil's viscosity over `lubricant.viscosity_pa_s` (1: the machine file's).
    /// The films are solved (and tabulated) at `lubricant` and scaled: exact for the isoviscous
    /// film without supply pressure ([`crate::film::ViscosityScaledFilm`]).
    pub viscosity_scale: f64,
    /// The viscosity around the bearing relative to the scale's, µ(T_i)/µ(T̄) per grid column,
    /// from the last thermal-film heat balance (`oil_heating: {model: thermal_film}`; empty:
    /// uniform). The finite film runs with it ([`FilmBearing::fielded`]), a table at the
    /// uniform scale.
    pub viscosity_field: Vec<f64>,
    /// The film's fluid inertia (added mass), if the bearing carries it.
    pub inertia: Option<crate::film::FilmInertia>,
    /// Laminar, turbulent or auto (finite model; `src/film/turbulence.rs`).
    pub flow: crate::film::FlowRegime,
    /// Reynolds or mass-conserving cavitation (finite model, direct film; issue 18).
    pub cavitation: crate::film::Cavitation,
    /// The largest speed a turbulent or auto film's table covers (rad/s):
    /// [`TURBULENT_TABLE_SPEED_OVER_RATED`] × the machine's rated speed.
    pub table_max_speed_rad_s: f64,
}

/// The speeds a turbulent film's table covers, over the machine's rated speed: run-ups to
/// overspeed trips (≈ 1.1–1.2 ×) and the threshold searches of `modes` with margin; beyond it
/// the tabulated film refuses the speed by name (the direct film has no such bound).
pub const TURBULENT_TABLE_SPEED_OVER_RATED: f64 = 2.5;

// --- oil supply temperature (issue 12) ---
impl FilmBearing {
    /// The viscosity of the running oil (Pa·s): the reference times the scale.
    pub fn viscosity_pa_s(&self) -> f64 {
        self.lubricant.viscosity_pa_s * self.viscosity_scale
    }

    /// `coef` with the added mass of the film `film` at relative position `d` (m) and shaft
    /// speed `speed_rad_s`, if the bearing carries its fluid inertia (and with `full` the
    /// convective inertia's stiffness and damping).
    pub fn with_added_mass(
        &self,
        coef: FilmCoefficients,
        d: [f64; 2],
        film: &crate::film::FilmResult,
        speed_rad_s: f64,
    ) -> FilmCoefficients {
        match &self.inertia {
            Some(inertia) => inertia.add_to(coef, d, film, self.viscosity_pa_s(), speed_rad_s),
            None => coef,
        }
    }

    /// The static equilibrium under `load` (N) at `speed_rad_s` with the film solver `s`; with
    /// `fluid_inertia: full` the film carries the load plus the steady convective inertia force
    /// (fixed point: the force is ≈ 4 % of the load in the seed case, each pass shrinks the
    /// change by about that ratio; stops at 1e-9 of the clearance).
    pub fn equilibrium(
        &self,
        s: &mut dyn crate::film::FilmModel,
        load: [f64; 2],
        speed_rad_s: f64,
    ) -> Result<crate::film::Equilibrium, crate::film::FilmError> {
        let mu = self.viscosity_pa_s();
        crate::film::equilibrium_with_inertia(s, self.inertia, mu, load, speed_rad_s)
    }

    /// A film solver at the running viscosity (each user owns one: it carries the warm start),
    /// with the bearing's viscosity field where it has one.
    pub fn solver(&self) -> Box<dyn FilmModel + Send> {
        Box::new(self.fielded(self.reference_solver()))
    }

    /// [`scaled`](Self::scaled), and with the bearing's viscosity field (`viscosity_field`, set
    /// by a thermal-film heat balance) where `inner` can hold one (the finite film; a table
    /// runs at the uniform scale) and the field fits its grid.
    pub fn fielded(&self, inner: Box<dyn FilmModel + Send>) -> crate::film::ViscosityScaledFilm {
        let mut film = self.scaled(inner);
        if self.viscosity_field.len() == self.grid.n_theta {
            // fits the grid, each ratio positive (from the law): cannot fail
            let _ = film.set_viscosity_field(&self.viscosity_field);
        }
        film
    }

    /// `inner` (solved at the reference viscosity) scaled to the running one.
    pub fn scaled(&self, inner: Box<dyn FilmModel + Send>) -> crate::film::ViscosityScaledFilm {
        crate::film::ViscosityScaledFilm::new(inner, self.viscosity_scale)
            .expect("the scale is checked when it is set")
    }
}

impl Rotor {
    /// Sets the viscosity scale (µ / µ_reference) of every film bearing (checked).
    pub fn set_viscosity_scale(&mut self, scale: f64) -> Result<(), crate::film::FilmError> {
        let scale = crate::film::check_viscosity_scale(scale)?;
        for b in &mut self.bearings {
            if let BearingModel::Film(f) = &mut b.model {
                f.viscosity_scale = scale;
            }
        }
        Ok(())
    }

    /// Sets each film bearing's own viscosity scale, `scales` in the order of the film
    /// bearings (one per film bearing; each checked, none set if one fails; allocates nothing).
    pub fn set_film_viscosity_scales(
        &mut self,
        scales: &[f64],
    ) -> Result<(), crate::film::FilmError> {
        let films = self.film_bearing_count();
        if scales.len() != films {
            return Err(crate::film::FilmError::InvalidParameter {
                name: "viscosity scales (one per film bearing)",
                value: scales.len() as f64,
                rule: "must give one scale per film bearing",
            });
        }
        for &s in scales {
            crate::film::check_viscosity_scale(s)?;
        }
        for (f, &s) in self.film_bearings_mut().zip(scales) {
            f.viscosity_scale = s;
        }
        Ok(())
    }

    /// The film bearings, in order.
    pub fn film_bearings(&self) -> impl Iterator<Item = &FilmBearing> {
        self.bearings.iter().filter_map(|b| match &b.model {
            BearingModel::Film(f) => Some(f),
            _ => None,
        })
    }

    /// The film bearings, in order, to change.
    pub fn film_bearings_mut(&mut self) -> impl Iterator<Item = &mut FilmBearing> {
        self.bearings.iter_mut().filter_map(|b| match &mut b.model {
            BearingModel::Film(f) => Some(f),
            _ => None,
        })
    }

    /// The number of film bearings.
    pub fn film_bearing_count(&self) -> usize {
        (self.bearings.iter())
            .filter(|b| matches!(b.model, BearingModel::Film(_)))
            .count()
    }

    /// Gives every film bearing its film's fluid inertia, or takes it away (`choice`), whatever
    /// the machine file said (for studies: `--fluid-inertia`).
    pub fn set_fluid_inertia(&mut self, choice: crate::film::FluidInertia) {
        for b in &mut self.bearings {
            if let BearingModel::Film(f) = &mut b.model {
                f.inertia = fluid_inertia(&f.geometry, &f.lubricant, choice);
            }
        }
    }

    /// Sets the cavitation model of every film bearing (issue 18): mass conservation needs the
    /// finite model and the direct film (`reference_solver`); refused with a short-bearing film.
    pub fn set_cavitation(
        &mut self,
        cavitation: crate::film::Cavitation,
    ) -> Result<(), crate::film::FilmError> {
        let short = self
            .bearings
            .iter()
            .any(|b| matches!(&b.model, BearingModel::Film(f) if f.short));
        if short && cavitation != crate::film::Cavitation::Reynolds {
            return Err(crate::film::FilmError::InvalidParameter {
                name: "cavitation (short-bearing film)",
                value: 0.0,
                rule: "mass-conserving cavitation is built in the finite model only",
            });
        }
        for b in &mut self.bearings {
            if let BearingModel::Film(f) = &mut b.model {
                f.cavitation = cavitation;
            }
        }
        Ok(())
    }

    /// The viscosity scale of the first film bearing (1 without one).
    pub fn viscosity_scale(&self) -> f64 {
        self.bearings
            .iter()
            .find_map(|b| match &b.model {
                BearingModel::Film(f) => Some(f.viscosity_scale),
                _ => None,
            })
            .unwrap_or(1.0)
    }
}
// --- end oil supply temperature ---

impl FilmBearing {
    /// A film solver at the reference viscosity `lubricant` (unscaled).
    pub fn reference_solver(&self) -> Box<dyn FilmModel + Send> {
        if !self.short {
            return Box::new(
                FiniteFilm::new(self.geometry.clone(), self.lubricant, self.grid)
                    .expect("geometry checked when the machine was read")
                    .with_flow(self.flow)
                    .with_cavitation(self.cavitation),
            );
        }
        if self.short {
            Box::new(
                ShortFilm::new(self.geometry.clone(), self.lubricant)
                    .expect("geometry checked when the machine was read"),
            )
        } else {
            Box::new(
                FiniteFilm::new(self.geometry.clone(), self.lubricant, self.grid)
                    .expect("geometry checked when the machine was read"),
            )
        }
    }
}

impl FilmBearing {
    /// The tabulated film of this bearing (the table shared in the process, built on first use):
    /// for plain bearings on the finite model.
    pub fn tabulated_solver(&self) -> Result<Box<dyn FilmModel + Send>, crate::film::FilmError> {
        Ok(Box::new(self.scaled(self.reference_tabulated_solver()?)))
    }

    /// The largest film Reynolds number ρωRc/µ a turbulent or auto table of this bearing
    /// covers: at [`Self::table_max_speed_rad_s`] and the reference viscosity.
    pub fn table_max_reynolds(&self) -> f64 {
        let (l, g) = (self.lubricant, &self.geometry);
        l.density_kg_m3 * self.table_max_speed_rad_s * g.radius_m() * g.radial_clearance_m
            / l.viscosity_pa_s
    }

    /// The tabulated film at the reference viscosity `lubricant` (unscaled).
    pub fn reference_tabulated_solver(
        &self,
    ) -> Result<Box<dyn FilmModel + Send>, crate::film::FilmError> {
        if self.cavitation != crate::film::Cavitation::Reynolds {
            return Err(crate::film::FilmError::InvalidParameter {
                name: "cavitation (tabulated film)",
                value: 0.0,
                rule: "the table holds Reynolds-condition films: a mass-conserving film carries \
                       its fluid fraction from step to step and cannot be tabulated over (ε, ψ); \
                       use the direct film (--film direct) with --cavitation mass-conserving",
            });
        }
        if self.short {
            return Err(crate::film::FilmError::InvalidParameter {
                name: "film model (tabulated film)",
                value: 0.0,
                rule: "the table tabulates the finite model; this bearing uses the short-bearing model",
            });
        }
        if self.flow != crate::film::FlowRegime::Laminar {
            // a turbulent film tabulated over (ε, ψ, Re): `src/film/table/reynolds.rs`
            let (l, g) = (self.lubricant, &self.geometry);
            let re_max = self.table_max_reynolds();
            let table = crate::film::ReynoldsTable::shared(g, l, self.grid, self.flow, re_max)?;
            return Ok(Box::new(crate::film::ReynoldsTabulatedFilm::new(
                std::sync::Arc::new(table),
            )));
        }
        let table = crate::film::FilmTable::shared(&self.geometry, self.lubricant, self.grid)?;
        Ok(Box::new(crate::film::TabulatedFilm::new(table)))
    }
}

/// A bearing at a shaft node.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingSite {
    /// Name.
    pub name: String,
    /// Shaft node of the journal.
    pub node: usize,
    /// Global DOFs of the journal centre (x, y).
    pub journal_dofs: [usize; 2],
    /// Global DOFs of the pedestal (x, y), if the support is flexible.
    pub pedestal_dofs: Option<[usize; 2]>,
    /// How the bearing acts.
    pub model: BearingModel,
}

/// A residual unbalance m·e at a node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unbalance {
    /// Shaft node.
    pub node: usize,
    /// m·e (kg·m).
    pub magnitude_kg_m: f64,
    /// Angle of the heavy spot at rotor angle 0, from +x towards +y (rad).
    pub phase_rad: f64,
    /// Radius of a balancing correction mass in this plane (m), if the machine file gives one.
    pub correction_radius_m: Option<f64>,
}

/// A probe station: two probes at a node.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeStation {
    /// Name.
    pub name: String,
    /// Shaft node.
    pub node: usize,
    /// Probe mounting angles from +x towards +y (rad).
    pub angles_rad: [f64; 2],
}

/// The assembled rotor model.
#[derive(Debug, Clone)]
pub struct Rotor {
    /// Machine name.
    pub name: String,
    /// Axial position of each shaft node (m).
    pub node_z_m: Vec<f64>,
    /// Shaft elements; element e joins nodes e and e+1.
    pub elements: Vec<ShaftElement>,
    /// Rigid discs.
    pub discs: Vec<Disc>,
    /// Bearings.
    pub bearings: Vec<BearingSite>,
    /// Unbalances.
    pub unbalance: Vec<Unbalance>,
    /// Probe stations.
    pub probes: Vec<ProbeStation>,
    /// Gravity (m/s²) in the machine frame.
    pub gravity_m_s2: [f64; 2],
    /// Rated speed (rad/s).
    pub rated_speed_rad_s: f64,
    /// Vibration alarm levels from the machine file (None: the monitor's API 617 / ISO 20816
    /// defaults).
    pub alarm_levels: Option<machine::AlarmLevelsSpec>,
    /// Raw proximity probes (issue 12; empty: none).
    pub proximity_probes: Vec<crate::signals::probes::RawProbe>,
    /// Slow-roll speed below which raw probes' runout is measured (rad/s).
    pub slow_roll_speed_rad_s: Option<f64>,
    /// Global mass matrix (kg, kg·m²).
    pub mass: Mat<f64>,
    /// Global stiffness: shaft plus support springs (N/m, N·m/rad).
    pub stiffness: Mat<f64>,
    /// Global gyroscopic matrix per unit spin (multiplied by Ω in the equations).
    pub gyroscopic: Mat<f64>,
    /// Global constant damping: support dampers and the shaft's structural damping (N·s/m).
    pub damping: Mat<f64>,
}

impl Rotor {
    /// Assembles the rotor of a (checked) machine description.
    pub fn from_description(desc: &MachineDescription) -> Self {
        let (elements, node_z_m) = shaft_elements(desc);
        let bearings = bearing_sites(desc, node_z_m.len());
        let discs = discs(desc);
        let mut rotor = Rotor {
            name: desc.name.clone(),
            unbalance: desc
                .unbalance
                .iter()
                .map(|u| Unbalance {
                    node: u.node,
                    magnitude_kg_m: u.magnitude_g_mm * 1e-6,
                    phase_rad: u.phase_deg.to_radians(),
                    correction_radius_m: u.correction_radius_m,
                })
                .collect(),
            probes: desc
                .probes
                .iter()
                .map(|p| ProbeStation {
                    name: p.name.clone(),
                    node: p.node,
                    angles_rad: p.angles_deg.map(f64::to_radians),
                })
                .collect(),
            gravity_m_s2: desc.gravity_m_s2,
            rated_speed_rad_s: rpm_to_rad_s(desc.rated_speed_rpm),
            alarm_levels: desc.alarm_levels,
            // checked by MachineDescription::validate: a description that did not pass it gives none
            proximity_probes: desc.raw_probes("").unwrap_or_default(),
            slow_roll_speed_rad_s: desc.slow_roll_speed_rpm.map(rpm_to_rad_s),
            node_z_m,
            elements,
            discs,
            bearings,
            mass: Mat::zeros(0, 0),
            stiffness: Mat::zeros(0, 0),
            gyroscopic: Mat::zeros(0, 0),
            damping: Mat::zeros(0, 0),
        };
        rotor.assemble(desc);
        rotor
    }

    /// The global M, K, G and C of the elements, discs and pedestals (seed eq. 5's matrices).
    fn assemble(&mut self, desc: &MachineDescription) {
        let n_dof = 4 * self.node_z_m.len()
            + 2 * self
                .bearings
                .iter()
                .filter(|b| b.pedestal_dofs.is_some())
                .count();
        let mut mass = Mat::<f64>::zeros(n_dof, n_dof);
        let mut stiffness = Mat::<f64>::zeros(n_dof, n_dof);
        let mut gyroscopic = Mat::<f64>::zeros(n_dof, n_dof);
        let mut damping = Mat::<f64>::zeros(n_dof, n_dof);
        for (e, el) in self.elements.iter().enumerate() {
            let at = 4 * e;
            let k = el.stiffness();
            add_block(&mut stiffness, at, &k);
            add_block(&mut mass, at, &el.mass());
            add_block(&mut gyroscopic, at, &el.gyroscopic());
            if desc.shaft_damping_beta_s > 0.0 {
                let c = k.map(|row| row.map(|v| desc.shaft_damping_beta_s * v));
                add_block(&mut damping, at, &c);
            }
        }
        for d in &self.discs {
            add_block(&mut mass, 4 * d.node, &d.mass());
            add_block(&mut gyroscopic, 4 * d.node, &d.gyroscopic());
        }
        for (b, spec) in self.bearings.iter().zip(&desc.bearings) {
            if let (Some(p), Some(s)) = (b.pedestal_dofs, &spec.support) {
                for i in 0..2 {
                    mass[(p[i], p[i])] += s.mass_kg;
                    for j in 0..2 {
                        stiffness[(p[i], p[j])] += s.stiffness_n_per_m[(i, j)];
                        damping[(p[i], p[j])] += s.damping_n_s_per_m[(i, j)];
                    }
                }
            }
        }
        (self.mass, self.stiffness) = (mass, stiffness);
        (self.gyroscopic, self.damping) = (gyroscopic, damping);
    }

    /// Number of global DOFs.
    pub fn n_dof(&self) -> usize {
        self.mass.nrows()
    }

    /// Number of shaft nodes.
    pub fn n_nodes(&self) -> usize {
        self.node_z_m.len()
    }

    /// Mass of the rotor: shaft elements and discs (kg); pedestals excluded.
    pub fn rotor_mass_kg(&self) -> f64 {
        self.elements.iter().map(|e| e.mass_kg()).sum::<f64>()
            + self.discs.iter().map(|d| d.mass_kg).sum::<f64>()
    }

    /// Axial position of the rotor's centre of mass (m).
    pub fn centre_of_mass_z_m(&self) -> f64 {
        let mut m = 0.0;
        let mut mz = 0.0;
        for (e, el) in self.elements.iter().enumerate() {
            let zc = 0.5 * (self.node_z_m[e] + self.node_z_m[e + 1]);
            m += el.mass_kg();
            mz += el.mass_kg() * zc;
        }
        for d in &self.discs {
            m += d.mass_kg;
            mz += d.mass_kg * self.node_z_m[d.node];
        }
        mz / m
    }
}

/// The shaft's Timoshenko elements, each section split into its equal elements, and the axial
/// position of every node (m).
fn shaft_elements(desc: &MachineDescription) -> (Vec<ShaftElement>, Vec<f64>) {
    let mut elements = Vec::new();
    let mut node_z_m = vec![0.0];
    for s in &desc.shaft {
        let m = &desc.materials[&s.material];
        let material =
            Material::from_poisson(m.youngs_modulus_pa, m.poisson_ratio, m.density_kg_m3);
        let l = s.length_m / s.elements as f64;
        for _ in 0..s.elements {
            elements.push(ShaftElement {
                length_m: l,
                outer_diameter_m: s.outer_diameter_m,
                inner_diameter_m: s.inner_diameter_m,
                material,
            });
            node_z_m.push(node_z_m.last().copied().unwrap_or(0.0) + l);
        }
    }
    (elements, node_z_m)
}

/// The bearings at their journals; each flexible pedestal gets two DOFs after the shaft's
/// `4 · nodes`.
fn bearing_sites(desc: &MachineDescription, nodes: usize) -> Vec<BearingSite> {
    let mut next_pedestal = 4 * nodes;
    desc.bearings
        .iter()
        .map(|b| {
            let pedestal_dofs = b.support.as_ref().map(|_| {
                let d = [next_pedestal, next_pedestal + 1];
                next_pedestal += 2;
                d
            });
            BearingSite {
                name: b.name.clone(),
                node: b.node,
                journal_dofs: [4 * b.node, 4 * b.node + 1],
                pedestal_dofs,
                model: bearing_model(b, rpm_to_rad_s(desc.rated_speed_rpm)),
            }
        })
        .collect()
}

/// The rigid discs, named `disc N` where the file gives no name.
fn discs(desc: &MachineDescription) -> Vec<Disc> {
    desc.discs
        .iter()
        .enumerate()
        .map(|(i, d)| Disc {
            name: if d.name.is_empty() {
                format!("disc {i}")
            } else {
                d.name.clone()
            },
            node: d.node,
            mass_kg: d.mass_kg,
            polar_inertia_kg_m2: d.polar_inertia_kg_m2,
            diametral_inertia_kg_m2: d.diametral_inertia_kg_m2,
        })
        .collect()
}

fn bearing_model(b: &BearingSpec, rated_speed_rad_s: f64) -> BearingModel {
    match &b.model {
        BearingModelSpec::Finite(f) | BearingModelSpec::Short(f) => {
            BearingModel::Film(FilmBearing {
                geometry: f.geometry.clone(),
                lubricant: f.lubricant,
                grid: f.grid,
                short: matches!(b.model, BearingModelSpec::Short(_)),
                viscosity_law: f.viscosity_law,
                design_supply_temperature_k: f.design_supply_temperature_k,
                heating: f.heating,
                viscosity_scale: 1.0,
                viscosity_field: Vec::new(),
                inertia: fluid_inertia(&f.geometry, &f.lubricant, f.fluid_inertia),
                flow: f.flow,
                cavitation: crate::film::Cavitation::Reynolds,
                table_max_speed_rad_s: TURBULENT_TABLE_SPEED_OVER_RATED * rated_speed_rad_s,
            })
        }
        BearingModelSpec::Linear(coef) => BearingModel::Linear(*coef),
        BearingModelSpec::Rigid => BearingModel::Rigid,
    }
}

/// The added-mass model of a film bearing, if `choice` asks for it.
fn fluid_inertia(
    geometry: &BearingGeometry,
    lubricant: &Lubricant,
    choice: crate::film::FluidInertia,
) -> Option<crate::film::FilmInertia> {
    match choice {
        crate::film::FluidInertia::None => None,
        crate::film::FluidInertia::Temporal => Some(crate::film::FilmInertia::new(
            geometry,
            lubricant.density_kg_m3,
        )),
        crate::film::FluidInertia::Full => {
            let mut i = crate::film::FilmInertia::new(geometry, lubricant.density_kg_m3);
            i.convective = true;
            Some(i)
        }
    }
}

/// Adds an N × N block at (at, at).
fn add_block<const N: usize>(m: &mut Mat<f64>, at: usize, block: &[[f64; N]; N]) {
    for (i, row) in block.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            m[(at + i, at + j)] += v;
        }
    }
}
