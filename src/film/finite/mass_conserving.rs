//! Mass-conserving (Jakobsson–Floberg–Olsson / Elrod–Adams) cavitation: the film's fluid
//! fraction φ is an unknown beside the pressure, and the fluid is carried through the ruptured
//! zone to where the film re-forms.
//!
//! The p–θ form of Ausas, Jai & Buscaglia (2009) and the complementarity form of Giacopini,
//! Fowell, Dini & Strozzi (2010), written in the units of [`FiniteFilm`] (Π = p/6µ(R/c)²,
//! H = h/c, x = Rθ, z̄ = z/R):
//!
//! ```text
//!   (M1)  ∂/∂θ(H³ ∂Π/∂θ) + ∂/∂z̄(H³ ∂Π/∂z̄) = ω ∂(φH)/∂θ + 2 ∂(φH)/∂t ,
//!   (M2)  Π ≥ 0,   0 ≤ φ ≤ 1,   Π·(1 − φ) = 0 ,
//! ```
//!
//! i.e. where the film is whole (φ = 1) (M1) is the Reynolds equation of `finite.rs`; where it
//! is ruptured (Π = 0) the Couette flow ωRh/2·φ is carried unchanged and φ follows the gap.
//!
//! Finite volumes on the grid of the Reynolds solver (node k = column i, axial row j, volume
//! V = Δθ·w_j), the Couette flux upwinded (face i+½ carries ω H_{i+½} φ_i for ω > 0):
//!
//! ```text
//!   (M3)  (A Π)_k + w_j ω (H_{i+½} φ_i − H_{i−½} φ_{i−1}) + 2 V D_k = 0 ,
//!         D_k = φ_k Ḣ_i                          (steady: ∂φ/∂t = 0, Ḣ from the journal velocity)
//!         D_k = (φ_k H_k − φ⁰_k H⁰_k) / Δt       (transient, backward Euler; ⁰ = last committed step)
//! ```
//!
//! In a rotor transient (the twin, `simulate`/`sweep --cavitation mass-conserving`) the step's
//! journal velocity comes from the Newmark update, and the film takes the squeeze term from it,
//! as the Reynolds film does, and only the fluid fraction from the last committed step:
//!
//! ```text
//!   (M4)  D_k = φ⁰_k Ḣ_i + H_i (φ_k − φ⁰_k) / Δt     (twin's form: `FilmModel::begin_step`)
//! ```
//!
//! (M4) is backward Euler of ∂(φH)/∂t, (φH − φ⁰H⁰)/Δt, with the step's starting gap taken as
//! H⁰ = H − ḢΔt: where the film is whole (φ = φ⁰ = 1) it is the Reynolds film's squeeze term
//! exactly, so a stable orbit fed at its widest gap matches the Reynolds twin; the fluid
//! volume it conserves is that of the continuous rate (the flow balance holds to round-off at
//! each solve, the volume over a step to O(Δt²)). φ's own coefficient is H/Δt > 0 whatever the
//! squeeze. (Session 12 took φ_k Ḣ_i: φ's coefficient 2V(Ḣ + H/Δt) + w_jωH_{i+½} turns
//! negative where the gap closes fast, Ḣ < −H/Δt − ωH_{i+½}/2Δθ — the minimum gap of the seed case's whip
//! at ε 0.94–0.97, the journal running into the wall at 47–80 mm/s — and the mixed problem
//! loses its M-matrix pieces: the active set flipped the minimum-gap column full ↔ ruptured
//! each pass and no solution was found.)
//!
//! A as in `finite.rs`. The complementarity (M2) is solved by an active-set iteration on the
//! mixed unknowns: each node is either full (unknown Π, φ = 1) or ruptured (unknown φ, Π = 0);
//! one pass solves the linear system (M3) of the current sets (not symmetric: band LU), then a
//! full node with Π < 0 ruptures and a ruptured node with φ > 1 fills. The sets of the previous
//! solve are the next one's first guess. If the sets still change after 40 passes, projected
//! Gauss–Seidel (M5, `mass_conserving_sweep.rs`) finds the solution and its sets.
//!
//! Feeding: the grooves of the geometry hold Π at their supply pressure and φ = 1. A plain
//! bearing (no groove) is fed at ambient pressure (Π = 0, φ = 1) at the column of the widest gap
//! of the current journal position — the film flooded at the start of its convergent part, the
//! idealisation under which the Reynolds condition is the steady limit of (M1–M2).

use super::{FiniteFilm, NOT_FREE};
use crate::film::banded::PivotedBandLu;
use crate::film::coefficients::FilmCoefficients;
use crate::film::error::FilmError;
use crate::film::{FilmResult, JournalKinematics};
use serde::{Deserialize, Serialize};

#[path = "mass_conserving_sweep.rs"]
mod sweep;

/// How the film cavitates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Cavitation {
    /// Reynolds (Swift–Stieber) condition: p ≥ 0 and p = ∂p/∂n = 0 where the film ruptures
    /// (seed eq. 6); mass is not conserved where the film re-forms.
    #[default]
    Reynolds,
    /// Jakobsson–Floberg–Olsson / Elrod–Adams: pressure and fluid fraction, eq. (M1–M3).
    MassConserving,
}

/// The flow balance of the whole film (both halves) after a solve (m³/s): what the feed
/// (grooves or feed line) delivers, what leaves at the bearing ends from the film outside the
/// feed, and the rate of change of the fluid volume ∫φh dA. Mass is conserved when
/// `feed = side + storage`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FlowBalance {
    /// Net flow out of the fed nodes into the rest of the film (m³/s).
    pub feed_m3_s: f64,
    /// Flow out of both bearing ends from the nodes that are not fed (m³/s).
    pub side_m3_s: f64,
    /// d/dt ∫φh dA over the nodes that are not fed (m³/s).
    pub storage_m3_s: f64,
}

/// The terms of (M3) at one node: `(node, coefficient)` of Π (own, west, east, south, north) and
/// of φ (own, the two upwind faces), and the constant term.
struct MixedRow {
    pi: [(usize, f64); 5],
    phi: [(usize, f64); 3],
    constant: f64,
}

/// Active-set passes before the fallback (M5) takes over (the fast path: 3–7 passes from a
/// cold start, 1–2 warm).
pub(super) const FAST_PASSES: usize = 40;

impl FiniteFilm {
    /// This solver with the cavitation model `cavitation` (Reynolds by default).
    pub fn with_cavitation(mut self, cavitation: Cavitation) -> Self {
        self.cavitation = cavitation;
        // the Reynolds condition's flows read φ = 1 everywhere
        self.phi.fill(1.0);
        self.feed_column = None;
        if cavitation == Cavitation::MassConserving {
            let nodes = self.grid.n_theta * self.grid.n_z;
            self.lu = PivotedBandLu::with_capacity(nodes, self.grid.n_z + 1);
            self.content_saved = vec![0.0; nodes];
        }
        self.warm = false;
        self
    }

    /// The cavitation model.
    pub fn cavitation(&self) -> Cavitation {
        self.cavitation
    }

    /// Fluid fraction φ at node (`i` around, `j` from mid-plane to edge) of the last solve
    /// (1 where the film is whole; always 1 with the Reynolds condition).
    pub fn fluid_fraction(&self, i: usize, j: usize) -> f64 {
        self.phi[i * self.grid.n_z + j.min(self.grid.n_z - 1)]
    }

    /// Transient mode with step `step_s` (s): the next solves use D_k of (M3) with the fluid
    /// content of the last committed step, which this call sets to that of the last solve.
    /// `None`: steady mode (∂φ/∂t = 0).
    pub fn set_time_step(&mut self, step_s: Option<f64>) -> Result<(), FilmError> {
        match step_s {
            Some(dt) => {
                crate::film::error::positive("film time step (s)", dt)?;
                self.twin_form = false;
                self.inverse_step = 1.0 / dt;
                self.commit_step();
            }
            None => {
                self.twin_form = false;
                self.inverse_step = 0.0;
            }
        }
        Ok(())
    }

    /// Accepts the last solve as the start of the next step: φ⁰H⁰ ← φH (φ⁰ ← φ in the twin's
    /// form).
    pub fn commit_step(&mut self) {
        let nz = self.grid.n_z;
        for (k, c) in self.content_old.iter_mut().enumerate() {
            *c = if self.twin_form {
                self.phi[k]
            } else {
                self.phi[k] * self.h_node[k / nz]
            };
        }
    }

    /// The twin's transient form (M4) with step `step_s` (s): the first call commits the last
    /// (steady) solve as the film's starting state and fixes a plain bearing's feed where it is.
    /// Without mass conservation, or with a step that is not positive and finite, nothing.
    pub(super) fn twin_begin_step(&mut self, step_s: f64) {
        if self.cavitation != Cavitation::MassConserving || !(step_s.is_finite() && step_s > 0.0) {
            return;
        }
        let first = !self.twin_form || self.inverse_step == 0.0;
        self.twin_form = true;
        self.inverse_step = 1.0 / step_s;
        if first {
            self.commit_step();
        }
    }

    /// Mid-plane φ of the last solve at `out.len()` equally spaced angles from +x (nearest
    /// column).
    pub(super) fn midplane_phi(&self, out: &mut [f64]) {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let len = out.len().max(1);
        for (k, p) in out.iter_mut().enumerate() {
            let i = (k * nt + len / 2) / len % nt;
            *p = self.phi[i * nz];
        }
    }

    /// Multiplies the committed fluid fraction φ⁰ of the ruptured nodes (φ⁰ < 1) by `factor`
    /// (clamped to [0, 1]): a disturbance of the film's memory, to see how long it lasts
    /// (twin's form only; otherwise nothing).
    pub fn disturb_committed_fraction(&mut self, factor: f64) {
        if !self.twin_form {
            return;
        }
        for c in &mut self.content_old {
            if *c < 1.0 {
                *c = (*c * factor).clamp(0.0, 1.0);
            }
        }
    }

    /// Replaces the committed fluid fraction φ⁰ (the twin's form, node `i·n_z + j`, `i` around,
    /// `j` from the mid-plane): to reproduce a recorded film state. Errors if the film is not in
    /// the twin's form or the length is not `n_theta·n_z`.
    pub fn set_committed_fraction(&mut self, phi0: &[f64]) -> Result<(), FilmError> {
        if !self.twin_form || phi0.len() != self.content_old.len() {
            return Err(FilmError::InvalidParameter {
                name: "committed fluid fraction (nodes)",
                value: phi0.len() as f64,
                rule: "the twin's transient form, one value per node (n_theta·n_z)",
            });
        }
        self.content_old.copy_from_slice(phi0);
        Ok(())
    }

    /// The full (true) and ruptured nodes the next mass-conserving solve starts its active set
    /// from (node `i·n_z + j`): to reproduce a recorded film state.
    pub fn set_full_nodes(&mut self, full: &[bool]) -> Result<(), FilmError> {
        if full.len() != self.free.len() {
            return Err(FilmError::InvalidParameter {
                name: "full nodes (count)",
                value: full.len() as f64,
                rule: "one per node (n_theta·n_z)",
            });
        }
        self.free.copy_from_slice(full);
        self.warm = true;
        Ok(())
    }

    /// This film with `passes` active-set passes (default 40) before the fallback (M5) of the
    /// mass-conserving solve takes over; 0: the projected Gauss–Seidel sweeps alone.
    pub fn with_active_set_passes(mut self, passes: usize) -> Self {
        self.fast_passes = passes;
        self
    }

    /// Π of a node whose pressure is imposed (a groove, or the feed line of a plain bearing in
    /// the mass-conserving mode), else `None`.
    #[inline]
    pub(super) fn fixed_pi(&self, i: usize) -> Option<f64> {
        if self.groove_pi[i].is_finite() {
            Some(self.groove_pi[i])
        } else if self.feed_column == Some(i) {
            Some(0.0)
        } else {
            None
        }
    }

    /// The mass-conserving solve of (M1–M3) for the film shape of `kin`.
    pub(super) fn solve_mass_conserving(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<FilmResult, FilmError> {
        // a plain bearing's feed line follows the widest gap when steady, and stays where it
        // was at the start of a transient (a fixed feed hole)
        let steady = self.inverse_step == 0.0;
        if self.geometry.grooves.is_empty() && (steady || self.feed_column.is_none()) {
            let nt = self.grid.n_theta;
            let widest = (0..nt).max_by(|&a, &b| self.h_node[a].total_cmp(&self.h_node[b]));
            // hysteresis: the feed stays while it is next to the widest column, so the force is
            // continuous along a Newton path (else an equilibrium whose widest gap lies at a
            // column boundary has no root: `sweep` at 8,100 rpm, residual 0.3 N)
            self.feed_column = match (self.feed_column, widest) {
                (Some(f), Some(w)) if (f + nt - w) % nt <= 1 || (w + nt - f) % nt <= 1 => Some(f),
                _ => widest,
            };
        }
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        for i in 0..nt {
            let fixed = self.fixed_pi(i);
            if let Some(p) = fixed {
                self.pi[i * nz..(i + 1) * nz].fill(p);
                self.phi[i * nz..(i + 1) * nz].fill(1.0);
            }
            if !self.warm || fixed.is_some() {
                let full = fixed.is_none() && self.source[i] < 0.0;
                self.free[i * nz..(i + 1) * nz].fill(full);
            }
        }
        for pass in 1..=self.fast_passes {
            self.solve_mixed_system()?;
            if !self.update_mixed_sets(1e-12) {
                return Ok(self.settled(pass, kin));
            }
        }
        // the active set cycles (or was given no passes): (M5)
        self.solve_by_sweeps(kin)
    }

    /// A solve that settled after `passes` passes: its sets start the next solve.
    fn settled(&mut self, passes: usize, kin: &JournalKinematics) -> FilmResult {
        self.last_passes = passes;
        self.warm = true;
        self.outputs(kin.speed_rad_s)
    }

    /// Orders the unknown nodes column by column from just after a fed column (every mixed
    /// system has one, so the ring is cut there and the bandwidth is n_z). Returns the count.
    fn order_unknowns(&mut self) -> usize {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let cut = (0..nt).find(|&i| self.fixed_pi(i).is_some()).unwrap_or(0);
        let mut n = 0;
        for m in 1..=nt {
            let i = (cut + m) % nt;
            for j in 0..nz {
                let k = i * nz + j;
                if self.fixed_pi(i).is_none() {
                    self.slot[k] = n as u32;
                    self.order[n] = (i as u32, j as u32);
                    n += 1;
                } else {
                    self.slot[k] = NOT_FREE;
                }
            }
        }
        n
    }

    /// The terms of (M3) at node (i, j) at speed `speed` (rad/s).
    fn mixed_row(&self, i: usize, j: usize, speed: f64) -> MixedRow {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let k = i * nz + j;
        let west = if i == 0 { nt - 1 } else { i - 1 };
        let east = if i + 1 == nt { 0 } else { i + 1 };
        let rw = self.row_width(j);
        let w = rw / self.dtheta;
        let (cw, ce) = (w * self.h3_face[west], w * self.h3_face[i]);
        let ca = self.dtheta * self.h3_node[i] / self.dz;
        let south = if j > 0 { ca } else { 0.0 };
        let north = if j + 1 < nz { ca } else { 0.0 };
        let pi_terms = [
            (k, cw + ce + ca + south),
            (west * nz + j, -cw),
            (east * nz + j, -ce),
            (k.saturating_sub(1), -south),
            ((k + 1).min(nt * nz - 1), -north),
        ];
        let (up_east, up_west) = if speed >= 0.0 { (i, west) } else { (east, i) };
        let volume = self.dtheta * rw;
        let (own, constant) = if self.inverse_step > 0.0 && self.twin_form {
            // (M4): φ⁰Ḣ + H(φ − φ⁰)/Δt, Ḣ from the journal velocity; φ's coefficient H/Δt > 0
            let v = self.journal_velocity;
            let squeeze = -v[0] * self.cos_node[i] - v[1] * self.sin_node[i];
            let s = 2.0 * volume * self.inverse_step * self.h_node[i];
            let old = self.content_old[k];
            (s, (2.0 * volume * squeeze - s) * old)
        } else if self.inverse_step > 0.0 {
            let s = 2.0 * volume * self.inverse_step;
            (s * self.h_node[i], -s * self.content_old[k])
        } else {
            let v = self.journal_velocity;
            let squeeze = -v[0] * self.cos_node[i] - v[1] * self.sin_node[i];
            (2.0 * volume * squeeze, 0.0)
        };
        let phi_terms = [
            (k, own),
            (up_east * nz + j, rw * speed * self.h_face[i]),
            (up_west * nz + j, -rw * speed * self.h_face[west]),
        ];
        MixedRow {
            pi: pi_terms,
            phi: phi_terms,
            constant,
        }
    }

    /// Assembles and solves (M3) for the current full / ruptured sets, and stores Π and φ.
    fn solve_mixed_system(&mut self) -> Result<(), FilmError> {
        let nz = self.grid.n_z;
        let n = self.order_unknowns();
        let mut lu = std::mem::replace(&mut self.lu, PivotedBandLu::with_capacity(0, 0));
        lu.reset(n, nz, nz);
        let speed = self.speed_now;
        for r in 0..n {
            let (i, j) = (self.order[r].0 as usize, self.order[r].1 as usize);
            let row = self.mixed_row(i, j, speed);
            let mut rhs = -row.constant;
            for (m, a) in row.pi {
                if a == 0.0 {
                    continue;
                }
                let s = self.slot[m];
                if s == NOT_FREE {
                    rhs -= a * self.pi[m];
                } else if self.free[m] {
                    lu.add(r, s as usize, a);
                }
            }
            for (m, a) in row.phi {
                let s = self.slot[m];
                if s == NOT_FREE || self.free[m] {
                    rhs -= a;
                } else {
                    lu.add(r, s as usize, a);
                }
            }
            self.rhs[r] = rhs;
        }
        let ok = lu.factor();
        if ok {
            lu.solve(&mut self.rhs[..n]);
        }
        self.lu = lu;
        if !ok {
            self.warm = false;
            return Err(FilmError::SingularFilm);
        }
        for r in 0..n {
            let k = self.order[r].0 as usize * nz + self.order[r].1 as usize;
            if self.free[k] {
                (self.pi[k], self.phi[k]) = (self.rhs[r], 1.0);
            } else {
                (self.pi[k], self.phi[k]) = (0.0, self.rhs[r]);
            }
        }
        Ok(())
    }

    /// One update of the full / ruptured sets by (M2), violations below `tol` (of the largest
    /// |Π|, or of φ = 1) let pass; true if anything changed.
    fn update_mixed_sets(&mut self, tol: f64) -> bool {
        let scale = self.pi.iter().fold(0.0_f64, |m, p| m.max(p.abs()));
        let mut changed = false;
        for k in 0..self.pi.len() {
            if self.slot[k] == NOT_FREE {
                continue;
            }
            if self.free[k] && self.pi[k] < -tol * scale {
                self.free[k] = false;
                changed = true;
            } else if !self.free[k] && self.phi[k] > 1.0 + tol {
                self.free[k] = true;
                changed = true;
            }
        }
        changed
    }

    /// The eight coefficients of the mass-conserving film by central differences of the film
    /// force (a position step of 10⁻⁴ c, a velocity step of 10⁻⁴ cω); leaves the model as a
    /// solve at `kin`.
    pub(super) fn mass_conserving_coefficients(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError> {
        let c = self.geometry.radial_clearance_m;
        let dq = 1e-4 * c;
        let dv = dq * kin.speed_rad_s.abs().max(1.0);
        let mut out = FilmCoefficients::default();
        for q in 0..4 {
            let step = if q < 2 { dq } else { dv };
            let mut force = [[0.0; 2]; 2];
            for (side, sign) in [(0, 1.0), (1, -1.0)] {
                let mut moved = *kin;
                if q < 2 {
                    moved.position_m[q] += sign * step;
                } else {
                    moved.velocity_m_s[q - 2] += sign * step;
                }
                force[side] = self.solve_mass_conserving_at(&moved)?.force_n;
            }
            for i in 0..2 {
                let slope = (force[0][i] - force[1][i]) / (2.0 * step);
                if q < 2 {
                    out.stiffness_n_per_m[(i, q)] = -slope;
                } else {
                    out.damping_n_s_per_m[(i, q - 2)] = -slope;
                }
            }
        }
        let result = self.solve_mass_conserving_at(kin)?;
        Ok((result, out))
    }

    /// Film shape and mass-conserving solve at `kin`.
    pub(super) fn solve_mass_conserving_at(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<FilmResult, FilmError> {
        kin.validate(self.geometry.radial_clearance_m)?;
        self.update_film_shape(kin);
        self.solve_mass_conserving(kin)
    }

    /// The fluid volume ∫φh dA of the last solve over the nodes that are not fed, both halves
    /// (m³).
    pub fn fluid_volume_m3(&self) -> f64 {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let mut sum = 0.0;
        for i in (0..nt).filter(|&i| self.fixed_pi(i).is_none()) {
            for j in 0..nz {
                sum += self.row_width(j) * self.phi[i * nz + j] * self.h_node[i];
            }
        }
        let r = self.geometry.radius_m();
        2.0 * r * r * self.geometry.radial_clearance_m * self.dtheta * sum
    }

    /// The flow balance of the last solve (both halves), from the same finite-volume fluxes
    /// as (M3); with the Reynolds condition φ = 1 everywhere.
    pub fn flow_balance(&self) -> FlowBalance {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let (mut feed, mut side, mut storage) = (0.0, 0.0, 0.0);
        let speed = self.speed_now;
        for i in 0..nt {
            if self.fixed_pi(i).is_some() {
                continue;
            }
            let west = if i == 0 { nt - 1 } else { i - 1 };
            let east = if i + 1 == nt { 0 } else { i + 1 };
            for j in 0..nz {
                let k = i * nz + j;
                let row = self.mixed_row(i, j, speed);
                // flow into node k across the faces it shares with a fed column
                for (nb, face) in [(west, west), (east, i)] {
                    if self.fixed_pi(nb).is_none() {
                        continue;
                    }
                    let m = nb * nz + j;
                    let cond = self.row_width(j) / self.dtheta * self.h3_face[face];
                    let poiseuille = cond * (self.pi[m] - self.pi[k]);
                    let up = if (speed >= 0.0) == (nb == west) { m } else { k };
                    let couette = self.row_width(j) * speed * self.h_face[face] * self.phi[up];
                    feed += poiseuille + if nb == west { couette } else { -couette };
                }
                if j + 1 == nz {
                    // the face to the bearing edge, Π = 0 there
                    side += self.dtheta * self.h3_node[i] / self.dz * self.pi[k];
                }
                storage += row.phi[0].1 * self.phi[k] + row.constant;
            }
        }
        let r = self.geometry.radius_m();
        let scale = r * r * self.geometry.radial_clearance_m;
        FlowBalance {
            feed_m3_s: scale * feed,
            side_m3_s: scale * side,
            storage_m3_s: scale * storage,
        }
    }
}
