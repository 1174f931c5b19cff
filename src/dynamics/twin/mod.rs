//! The engine: state, construction at the static equilibrium, and the time step.

use super::bearing_link::{BearingLink, LinearReference, LinkEvaluation};
use super::linear::{SparseMcg, StepFactor};
use super::{BearingState, ProbeState, StepOutput, TwinConfig, TwinError};
use crate::film::{FilmCoefficients, FilmModel, JournalKinematics};
use crate::rotor::Unbalance;
use faer::Mat;

/// Substep levels of a step that Newton cannot take whole: h, h/2, …, h/16. Wall contact
/// with the mass-conserving film needs the deep ones (issue 18: at 9,000 rpm, t = 0.352 s, the
/// film's slope changes within 40 pm of the iterate where φ's sets switch, and Newton cycles
/// between two iterates at h, h/2 and h/4; at h/16 the film's share of the iteration matrix
/// I + S D, ∝ h, is small enough for it to converge).
const LEVELS: usize = 5;

/// The levels kept factored at the running speed (h, h/2, h/4); the deeper ones are factored
/// when a step first needs them at a speed (rarely: a speed change need not pay for them).
const EAGER_LEVELS: usize = 3;

/// Marks a full DOF that is held (rigid bearing) and so not in the reduced system.
const HELD: usize = usize::MAX;

/// The dynamic state (explicit, copyable into checkpoints).
#[derive(Debug, Clone, PartialEq)]
struct State {
    time_s: f64,
    angle_rad: f64,
    speed_rad_s: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
}

impl State {
    /// Becomes a copy of `other` in place (same sizes: no allocation).
    fn copy_from(&mut self, other: &State) {
        self.time_s = other.time_s;
        self.angle_rad = other.angle_rad;
        self.speed_rad_s = other.speed_rad_s;
        self.q.copy_from_slice(&other.q);
        self.qd.copy_from_slice(&other.qd);
        self.qdd.copy_from_slice(&other.qdd);
    }
}

/// A saved twin state: restoring it makes the following steps repeat exactly.
pub struct Checkpoint {
    state: State,
    films: Vec<crate::film::ViscosityScaledFilm>,
    previous_raw: Vec<Option<FilmCoefficients>>,
    linear_reference: Vec<Option<LinearReference>>,
    last: Vec<LinkEvaluation>,
    unbalance: Vec<Unbalance>,
    external: Vec<f64>,
}

/// A probe station in the step: the reduced DOFs of its node (x, y), and the sine and cosine of
/// each probe's angle (taken once: a reading is x cos a + y sin a).
type ProbeStation = ([usize; 2], [(f64, f64); 2]);

/// The twin core (see the module documentation of [`crate::dynamics`]).
pub struct Twin {
    config: TwinConfig,
    m: Mat<f64>,
    c: Mat<f64>,
    g: Mat<f64>,
    k: Mat<f64>,
    /// M, C, G in compressed rows for the step's right-hand side
    mcg_rows: SparseMcg,
    /// full DOF → reduced index (or HELD)
    reduced_of: Vec<usize>,
    gravity: Vec<f64>,
    unbalance: Vec<Unbalance>,
    external: Vec<f64>,
    links: Vec<BearingLink>,
    b_dofs: Vec<usize>,
    /// factors for h, h/2, …, h/16 ([`LEVELS`])
    factors: Vec<StepFactor>,
    probes: Vec<ProbeStation>,
    state: State,
    rated_speed_rad_s: f64,
    // scratch, sized once
    rhs: Vec<f64>,
    tmp: Vec<f64>,
    tmp_c: Vec<f64>,
    q_lin: Vec<f64>,
    next: State,
    /// the state before a step, for retries
    saved: State,
    qb: Vec<f64>,
    a_b: Vec<f64>,
    f_b: Vec<f64>,
    d_b: Vec<f64>,
    jac: Vec<f64>,
    delta: Vec<f64>,
    raw: Vec<Option<FilmCoefficients>>,
    /// prehistory: the relaxed film coefficients of the current step, per bearing
    relaxed: Vec<FilmCoefficients>,
    /// prehistory: substeps of the current step that fell back to Newton
    fallbacks: usize,
    output: StepOutput,
}

impl Twin {
    /// The settings.
    pub fn config(&self) -> &TwinConfig {
        &self.config
    }

    /// The state vectors on the reduced DOFs (all but rigid bearings' journals): displacement
    /// q (m, rad), velocity q̇ and acceleration q̈.
    pub fn state_vectors(&self) -> (&[f64], &[f64], &[f64]) {
        (&self.state.q, &self.state.qd, &self.state.qdd)
    }

    /// Sets the state vectors (same layout as [`state_vectors`](Self::state_vectors)); time,
    /// angle and speed stay. Refused if a length differs or a value is not finite.
    pub fn set_state_vectors(
        &mut self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
    ) -> Result<(), TwinError> {
        let n = self.state.q.len();
        for (name, v) in [("displacement", q), ("velocity", qd), ("acceleration", qdd)] {
            if v.len() != n {
                return Err(TwinError::Setup(format!(
                    "{name} vector has {} entries, the model {n}",
                    v.len()
                )));
            }
            if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
                return Err(TwinError::InvalidInput {
                    name: "state vector entry",
                    value: *bad,
                    rule: "must be finite",
                });
            }
        }
        self.state.q.copy_from_slice(q);
        self.state.qd.copy_from_slice(qd);
        self.state.qdd.copy_from_slice(qdd);
        self.fill_output(0, 1);
        Ok(())
    }

    /// Turns the rotor's angle (the phase reference of the unbalance) by `delta_rad` (rad),
    /// e.g. to lock it to the plant's keyphasor; the motion stays. A non-finite value is ignored.
    pub fn shift_angle(&mut self, delta_rad: f64) {
        if delta_rad.is_finite() {
            self.state.angle_rad += delta_rad;
            self.output.angle_rad = self.state.angle_rad;
        }
    }

    /// Re-references the rotor's angle to a mark turned by `delta_rad` (rad) against the shaft:
    /// the angle turns by `delta_rad` and every heavy spot by −`delta_rad`, so the unbalance
    /// force (at angle + phase, eq. of `unbalance_force`) and the motion are unchanged (a
    /// keyphasor relock, `Driver::move_mark`). A non-finite value is ignored.
    pub fn turn_reference(&mut self, delta_rad: f64) {
        if delta_rad.is_finite() {
            self.shift_angle(delta_rad);
            for u in &mut self.unbalance {
                u.phase_rad -= delta_rad;
            }
        }
    }

    /// The last step's output (the initial state before the first step).
    pub fn output(&self) -> &StepOutput {
        &self.output
    }

    /// Time (s).
    pub fn time_s(&self) -> f64 {
        self.state.time_s
    }

    /// Names of the film bearings, in output order.
    pub fn bearing_names(&self) -> impl Iterator<Item = &str> {
        self.links.iter().map(|l| l.name.as_str())
    }

    /// Radial clearance of each film bearing (m), in output order.
    pub fn bearing_clearances_m(&self) -> Vec<f64> {
        self.links.iter().map(|l| l.clearance_m).collect()
    }

    /// Mid-plane pressure of bearing `bearing` at the last solve (see
    /// [`FilmModel::midplane_pressure`]).
    pub fn midplane_pressure(&self, bearing: usize, out: &mut [f64]) {
        self.links[bearing].film.midplane_pressure(out);
    }

    /// Mid-plane fluid fraction φ of bearing `bearing`'s last film solve at `out.len()` equally
    /// spaced angles from +x (1 everywhere with the Reynolds condition; issue 18).
    pub fn midplane_fluid_fraction(&self, bearing: usize, out: &mut [f64]) {
        self.links[bearing].film.midplane_fluid_fraction(out);
    }

    /// Where bearing `bearing`'s mass-conserving plain film is fed (rad from `+x`), if it is one.
    pub fn feed_angle_rad(&self, bearing: usize) -> Option<f64> {
        self.links[bearing].film.feed_angle_rad()
    }

    // --- oil supply temperature (issue 12) ---
    /// Sets the viscosity of every film to `scale` × its reference viscosity (the machine
    /// file's): exact for the isoviscous film ([`crate::film::ViscosityScaledFilm`]). Takes effect
    /// at the next step and allocates nothing; the linear coupling is re-linearised about the
    /// equilibrium at the new viscosity at once.
    pub fn set_viscosity_scale(&mut self, scale: f64) -> Result<(), TwinError> {
        let scale =
            crate::film::check_viscosity_scale(scale).map_err(|_| TwinError::InvalidInput {
                name: "viscosity scale (µ / µ_reference)",
                value: scale,
                rule: "must be finite, between 0.02 and 50",
            })?;
        for l in &mut self.links {
            // checked above: cannot fail
            let _ = l.film.set_scale(scale);
        }
        if self.config.coupling == crate::dynamics::Coupling::Linear {
            self.relinearise_films(self.state.speed_rad_s);
        }
        Ok(())
    }

    /// Sets each film's own viscosity scale (µ_i / µ_reference,i), `scales` in the order of the
    /// film bearings (one each; all checked before any is set). As
    /// [`set_viscosity_scale`](Self::set_viscosity_scale): next step, allocates nothing.
    pub fn set_viscosity_scales(&mut self, scales: &[f64]) -> Result<(), TwinError> {
        if scales.len() != self.links.len() {
            return Err(TwinError::InvalidInput {
                name: "viscosity scales (one per film bearing)",
                value: scales.len() as f64,
                rule: "must give one scale per film bearing",
            });
        }
        for &s in scales {
            crate::film::check_viscosity_scale(s).map_err(|_| TwinError::InvalidInput {
                name: "viscosity scale (µ / µ_reference)",
                value: s,
                rule: "must be finite, between 0.02 and 50",
            })?;
        }
        for (l, &s) in self.links.iter_mut().zip(scales) {
            // checked above: cannot fail
            let _ = l.film.set_scale(s);
        }
        if self.config.coupling == crate::dynamics::Coupling::Linear {
            self.relinearise_films(self.state.speed_rad_s);
        }
        Ok(())
    }

    /// Sets each film's viscosity field (µ_i/µ per grid column relative to its scale; an empty
    /// field: uniform), `fields` in the order of the film bearings, as a thermal-film heat
    /// balance finds them ([`crate::rotor::FilmBearing::viscosity_field`]). A film that holds
    /// only a uniform viscosity (a table) keeps it. Next step; the linear coupling is
    /// re-linearised at once when a film took its field.
    pub fn set_viscosity_fields(&mut self, fields: &[Vec<f64>]) -> Result<(), TwinError> {
        if fields.len() != self.links.len() {
            return Err(TwinError::InvalidInput {
                name: "viscosity fields (one per film bearing)",
                value: fields.len() as f64,
                rule: "must give one field per film bearing",
            });
        }
        let mut taken = false;
        for (l, f) in self.links.iter_mut().zip(fields) {
            taken |= l
                .film
                .set_viscosity_field(f)
                .map_err(|e| TwinError::Setup(format!("bearing '{}': {e}", l.name)))?;
        }
        if taken && self.config.coupling == crate::dynamics::Coupling::Linear {
            self.relinearise_films(self.state.speed_rad_s);
        }
        Ok(())
    }

    /// The viscosity scale of film `i` (in the order of the film bearings), if it exists.
    pub fn film_viscosity_scale(&self, i: usize) -> Option<f64> {
        self.links.get(i).map(|l| l.film.scale())
    }

    /// The viscosity scale of the films (µ / µ_reference; 1 without a film).
    pub fn viscosity_scale(&self) -> f64 {
        self.links.first().map_or(1.0, |l| l.film.scale())
    }
    // --- end oil supply temperature ---

    /// Sets unbalance plane `plane` (index in the machine's list): m·e (kg·m) and heavy-spot
    /// angle (rad). Takes effect at the next step.
    pub fn set_unbalance(
        &mut self,
        plane: usize,
        magnitude_kg_m: f64,
        phase_rad: f64,
    ) -> Result<(), TwinError> {
        if plane >= self.unbalance.len() {
            return Err(TwinError::InvalidInput {
                name: "unbalance plane",
                value: plane as f64,
                rule: "must be a plane of the machine",
            });
        }
        let max = crate::driver::inputs::MAX_UNBALANCE_KG_M;
        if !(magnitude_kg_m.is_finite() && (0.0..=max).contains(&magnitude_kg_m)) {
            return Err(TwinError::InvalidInput {
                name: "unbalance (kg·m)",
                value: magnitude_kg_m,
                rule: "must be finite, 0 to MAX_UNBALANCE_KG_M (0.01 kg·m)",
            });
        }
        if !phase_rad.is_finite() {
            return Err(TwinError::InvalidInput {
                name: "unbalance phase (rad)",
                value: phase_rad,
                rule: "must be finite",
            });
        }
        self.unbalance[plane].magnitude_kg_m = magnitude_kg_m;
        self.unbalance[plane].phase_rad = phase_rad;
        Ok(())
    }

    /// Sets a constant external force `[F_x, F_y]` (N) at shaft node `node` until changed.
    pub fn set_external_force(&mut self, node: usize, force_n: [f64; 2]) -> Result<(), TwinError> {
        if 4 * node + 1 >= self.reduced_of.len() {
            return Err(TwinError::InvalidInput {
                name: "external force node",
                value: node as f64,
                rule: "must be a shaft node",
            });
        }
        for (i, f) in force_n.iter().enumerate() {
            if !f.is_finite() {
                return Err(TwinError::InvalidInput {
                    name: "external force (N)",
                    value: *f,
                    rule: "must be finite",
                });
            }
            let r = self.reduced_of[4 * node + i];
            if r != HELD {
                self.external[r] = *f;
            }
        }
        Ok(())
    }

    /// Saves the complete state.
    pub fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            state: self.state.clone(),
            films: self.links.iter().map(|l| l.film.clone()).collect(),
            previous_raw: self.links.iter().map(|l| l.previous_raw).collect(),
            linear_reference: self.links.iter().map(|l| l.linear_reference).collect(),
            last: self.links.iter().map(|l| l.last).collect(),
            unbalance: self.unbalance.clone(),
            external: self.external.clone(),
        }
    }

    /// Restores a state saved by [`checkpoint`](Self::checkpoint) of this twin.
    pub fn restore(&mut self, cp: &Checkpoint) {
        self.state = cp.state.clone();
        for (i, l) in self.links.iter_mut().enumerate() {
            l.film = cp.films[i].clone();
            l.previous_raw = cp.previous_raw[i];
            l.linear_reference = cp.linear_reference[i];
            l.last = cp.last[i];
        }
        self.unbalance = cp.unbalance.clone();
        self.external = cp.external.clone();
        self.fill_output(0, 1);
    }

    fn fill_output(&mut self, iterations: usize, substeps: usize) {
        let s = &self.state;
        let out = &mut self.output;
        out.time_s = s.time_s;
        out.angle_rad = s.angle_rad;
        out.speed_rad_s = s.speed_rad_s;
        out.newton_iterations = iterations;
        out.substeps = substeps;
        out.prehistory_fallbacks = self.fallbacks;
        for (b, link) in out.bearings.iter_mut().zip(&self.links) {
            let pos = |v: &[f64]| -> [f64; 2] {
                let j = link.journal;
                match link.pedestal {
                    Some(p) => [v[j[0]] - v[p[0]], v[j[1]] - v[p[1]]],
                    None => [v[j[0]], v[j[1]]],
                }
            };
            let d = pos(&s.q);
            let e = link.last;
            *b = BearingState {
                position_m: d,
                velocity_m_s: pos(&s.qd),
                eccentricity_ratio: d[0].hypot(d[1]) / link.clearance_m,
                attitude_rad: crate::film::wrap_angle_rad(d[1].atan2(d[0])),
                force_n: e.force_n,
                max_pressure_pa: e.film.max_pressure_pa,
                max_pressure_angle_rad: e.film.max_pressure_angle_rad,
                film_start_rad: e.film.film_start_rad,
                film_end_rad: e.film.film_end_rad,
                power_loss_w: e.film.power_loss_w,
                contact: e.contact,
                rub_power_w: e.rub_power_w,
            };
        }
        for (p, (dofs, angles)) in out.probes.iter_mut().zip(&self.probes) {
            let at = |r: usize| if r == HELD { 0.0 } else { s.q[r] };
            let x = [at(dofs[0]), at(dofs[1])];
            *p = ProbeState {
                displacement_m: x,
                readings_m: angles.map(|(sin, cos)| x[0] * cos + x[1] * sin),
            };
        }
    }

    /// Bearing `bearing`'s film memory (mass-conserving: the committed fluid fraction φ⁰ and the
    /// full nodes, node `i·n_z + j`), to record a state; `None` without memory.
    pub fn film_memory(&self, bearing: usize) -> Option<(Vec<f64>, Vec<bool>)> {
        self.links.get(bearing).and_then(|l| l.film.memory())
    }

    /// Sets bearing `bearing`'s film memory to a recorded one (after a first step: the film
    /// must be in a time step).
    pub fn set_film_memory(
        &mut self,
        bearing: usize,
        phi0: &[f64],
        full: &[bool],
    ) -> Result<(), TwinError> {
        let Some(link) = self.links.get_mut(bearing) else {
            return Err(TwinError::Setup(format!("no bearing {bearing}")));
        };
        let name = link.name.clone();
        link.film
            .set_memory(phi0, full)
            .map_err(|cause| TwinError::Film {
                bearing: name,
                time_s: self.state.time_s,
                cause,
            })
    }

    /// Journal kinematics of bearing `bearing` now (relative to its pedestal).
    pub fn journal_kinematics(&self, bearing: usize) -> JournalKinematics {
        let b = &self.output.bearings[bearing];
        JournalKinematics {
            position_m: b.position_m,
            velocity_m_s: b.velocity_m_s,
            speed_rad_s: self.state.speed_rad_s,
        }
    }
}

mod setup;
mod step;
