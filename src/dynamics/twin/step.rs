//! The time step: Newmark predictor, condensed Newton iteration on the bearing DOFs, update.

use super::{Twin, HELD};
use crate::dynamics::bearing_link::LinkEvaluation;
use crate::dynamics::linear::solve_small;
use crate::dynamics::{Coupling, StepInput, StepOutput, TwinError};
use crate::film::{FilmCoefficients, FilmModel};
use crate::rotor::unbalance_force;
use nalgebra::{Matrix2, Vector2};

impl Twin {
    /// Advances one time step of `config.time_step_s` to the input speed. On failure the state is
    /// unchanged and the error says when and why; the output never holds a non-finite number.
    pub fn step(&mut self, input: &StepInput) -> Result<&StepOutput, TwinError> {
        if !(input.speed_rad_s.is_finite()
            && input.speed_rad_s > 0.0
            && input.speed_rad_s <= crate::dynamics::MAX_SPEED_OVER_RATED * self.rated_speed_rad_s)
        {
            return Err(TwinError::InvalidInput {
                name: "speed (rad/s)",
                value: input.speed_rad_s,
                rule: "must be finite, above zero and at most 10× the rated speed",
            });
        }
        if !input.accel_rad_s2.is_finite() {
            return Err(TwinError::InvalidInput {
                name: "angular acceleration (rad/s²)",
                value: input.accel_rad_s2,
                rule: "must be finite",
            });
        }
        self.refactor_if_needed(input.speed_rad_s);
        let start_speed = self.state.speed_rad_s;
        let mut iterations = 0;
        self.fallbacks = 0;
        // a film with memory (mass-conserving) returns to this state if the step is retried
        for l in &mut self.links {
            l.film.save_memory();
        }
        for level in 0..self.factors.len() {
            if level >= super::EAGER_LEVELS {
                self.factor_level_at(level, self.factors[0].speed_rad_s);
            }
            let substeps = 1usize << level;
            // the state to return to if the step must be retried (scratch reused: no
            // allocation); a failed `advance` leaves the state as it was, so one substep
            // (level 0) needs no copy
            if level > 0 {
                self.saved.copy_from(&self.state);
            }
            let mut ok = true;
            for s in 1..=substeps {
                let speed =
                    start_speed + (input.speed_rad_s - start_speed) * s as f64 / substeps as f64;
                match self.advance(level, speed, input.accel_rad_s2) {
                    Ok(it) => iterations += it,
                    Err(Some(e)) => {
                        if level > 0 {
                            self.state.copy_from(&self.saved);
                        }
                        self.restore_film_memory();
                        return Err(e);
                    }
                    Err(None) => {
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                self.fill_output(iterations, substeps);
                return Ok(&self.output);
            }
            if level > 0 {
                self.state.copy_from(&self.saved);
            }
            self.restore_film_memory();
        }
        Err(TwinError::NotConverged {
            time_s: self.state.time_s,
            iterations,
        })
    }

    /// Every film with memory back to its state at the start of the step.
    fn restore_film_memory(&mut self) {
        for l in &mut self.links {
            l.film.restore_memory();
        }
    }

    fn refactor_if_needed(&mut self, speed: f64) {
        let f = &self.factors[0];
        if (speed - f.speed_rad_s).abs()
            > self.config.speed_refactor_tolerance * f.speed_rad_s.max(1.0)
        {
            self.renew_factors(speed);
            if self.config.coupling == Coupling::Linear {
                self.relinearise_films(speed);
            }
        }
    }

    /// Factors the step's K_eff again at `speed` (rad/s), every substep level (what a speed
    /// change beyond the tolerance costs; `rotor-twin bench factor` times it).
    pub(crate) fn renew_factors(&mut self, speed: f64) {
        for f in self.factors.iter_mut().take(super::EAGER_LEVELS) {
            f.refactor(&self.m, &self.c, &self.g, &self.k, speed, &self.b_dofs);
        }
    }

    /// Factors level `level` at `speed` (rad/s) if it was factored at another speed: the
    /// deep levels (h/8, h/16), used only by the rare step that fails at h/4, are brought to
    /// the running speed when first needed there.
    fn factor_level_at(&mut self, level: usize, speed: f64) {
        let f = &mut self.factors[level];
        if f.speed_rad_s != speed {
            f.refactor(&self.m, &self.c, &self.g, &self.k, speed, &self.b_dofs);
        }
    }

    /// Drops the band factorisation of every level for good: faer's dense LU from now on (for
    /// the bench's comparison of the two).
    pub(crate) fn use_dense_factors(&mut self) {
        for f in &mut self.factors {
            f.drop_band();
        }
    }

    /// Linear coupling: re-linearises each film about its equilibrium under the same load at
    /// `speed` (rad/s) and the running viscosity.
    pub(super) fn relinearise_films(&mut self, speed: f64) {
        for l in &mut self.links {
            if let Some(r) = l.linear_reference {
                // on failure the reference stays where it was
                let _ = l.linearise([-r.force_n[0], -r.force_n[1]], speed);
            }
        }
    }

    /// One Newmark step with factor `level` (h / 2^level) to `speed` (rad/s). Ok(iterations);
    /// Err(None) if Newton did not converge (retry smaller); Err(Some) for a hard failure.
    /// Allocates nothing: predictor, iteration and corrector work on the twin's scratch.
    fn advance(
        &mut self,
        level: usize,
        speed: f64,
        accel: f64,
    ) -> Result<usize, Option<TwinError>> {
        let nm = Newmark::of(self.factors[level].h);
        let angle = self.state.angle_rad + 0.5 * nm.h * (self.state.speed_rad_s + speed);
        let time = self.state.time_s + nm.h;
        self.linear_response(level, nm, angle, speed, accel);
        for l in &mut self.links {
            l.film.begin_step(nm.h);
        }
        let (iterations, fallback) = self.iterate_bearings(level, nm, speed, time)?;
        // the films' outputs of the accepted iterate (the iterates took force and coefficients)
        for l in &mut self.links {
            l.complete_film();
        }
        self.correct(level, nm, time, angle, speed)?;
        for l in &mut self.links {
            l.film.commit_step();
        }
        self.fallbacks += usize::from(fallback);
        if let Coupling::Prehistory { .. } = self.config.coupling {
            for (l, r) in self.links.iter_mut().zip(&self.raw) {
                l.previous_raw = *r;
            }
        }
        Ok(iterations)
    }

    /// The linear part's response to everything but the bearing forces, a = K_eff⁻¹ r with
    /// r = F_ext + M(a0 q + a1 q̇ + q̈) + (C + Ω_f G)(a2 q + q̇) − (Ω − Ω_f) G q̇, on the
    /// condensed DOFs (`a_b`), and the predictor q* = q + h q̇ + h²/2 q̈ there (`qb`).
    fn linear_response(&mut self, level: usize, nm: Newmark, angle: f64, speed: f64, accel: f64) {
        let factored_speed = self.factors[level].speed_rad_s;
        // element-wise loops over zipped slices (no index checks; vectorised): the same
        // expressions element by element as indexed loops, so the same values
        for (r, (g, e)) in self
            .rhs
            .iter_mut()
            .zip(self.gravity.iter().zip(&self.external))
        {
            *r = g + e;
        }
        self.add_unbalance(angle, speed, accel);
        let s = &self.state;
        let state = s.q.iter().zip(s.qd.iter().zip(&s.qdd));
        for ((t, tc), (q, (qd, qdd))) in self.tmp.iter_mut().zip(self.tmp_c.iter_mut()).zip(state) {
            *t = nm.a0 * q + nm.a1 * qd + qdd;
            *tc = nm.a2 * q + qd;
        }
        self.mcg_rows.add_step_products(
            [&self.tmp, &self.tmp_c, &s.qd],
            factored_speed,
            -(speed - factored_speed),
            &mut self.rhs,
        );
        self.factors[level].solve(&self.rhs, &mut self.q_lin);
        for (r, &d) in self.b_dofs.iter().enumerate() {
            self.a_b[r] = self.q_lin[d];
        }
        self.predict(nm);
    }

    /// The predictor q* = q + h q̇ + h²/2 q̈ on the condensed DOFs.
    fn predict(&mut self, nm: Newmark) {
        let s = &self.state;
        for (r, &d) in self.b_dofs.iter().enumerate() {
            self.qb[r] = s.q[d] + nm.h * s.qd[d] + 0.5 * nm.h * nm.h * s.qdd[d];
        }
    }

    /// The condensed iteration on the bearing DOFs: Newton on g = q_B − a − S f_B(q_B); with
    /// prehistory, first with its relaxed coefficients and, if that does not converge, again
    /// from the predictor with Newton (a fallback). Ok((iterations, fallback)).
    fn iterate_bearings(
        &mut self,
        level: usize,
        nm: Newmark,
        speed: f64,
        time: f64,
    ) -> Result<(usize, bool), Option<TwinError>> {
        let max_iterations = match self.config.coupling {
            Coupling::Nonlinear | Coupling::Prehistory { .. } => self.config.max_newton_iterations,
            Coupling::Linear => 1,
        };
        let prehistory = matches!(self.config.coupling, Coupling::Prehistory { .. });
        let (mut fallback, mut iterations, mut total) = (false, 0, 0);
        while iterations < max_iterations || (prehistory && !fallback) {
            if iterations == max_iterations {
                fallback = true;
                total += iterations;
                iterations = 0;
                self.predict(nm);
            }
            iterations += 1;
            // prehistory: the film coefficients are computed once a step (first iteration),
            // relaxed by seed eq. 8 and kept as the iteration matrix; the force is the Reynolds
            // force at every iteration
            let fresh = !prehistory || iterations == 1 || fallback;
            let relax = prehistory && !fallback;
            self.bearing_forces(nm, speed, time, fresh, relax)?;
            if self.newton_move(level)? {
                return Ok((iterations + total, fallback));
            }
        }
        if self.config.coupling == Coupling::Linear {
            Ok((iterations + total, fallback))
        } else {
            Err(None)
        }
    }

    /// The bearing forces f_B and their derivatives D at the current iterate `qb`: +F on the
    /// journal, −F on the pedestal, D = Tᵀ (K + a2 C + a0 M) T.
    fn bearing_forces(
        &mut self,
        nm: Newmark,
        speed: f64,
        time: f64,
        fresh: bool,
        relax: bool,
    ) -> Result<(), Option<TwinError>> {
        let nb = self.b_dofs.len();
        self.f_b.fill(0.0);
        self.d_b.fill(0.0);
        for li in 0..self.links.len() {
            let ev = self.link_force(li, nm, speed, time, fresh, relax)?;
            let (o, w) = (self.links[li].b_offset, self.links[li].width());
            for i in 0..2 {
                self.f_b[o + i] += ev.force_n[i];
                if w == 4 {
                    self.f_b[o + 2 + i] -= ev.force_n[i];
                }
                for j in 0..2 {
                    let kd = ev.stiffness[(i, j)]
                        + nm.a2 * ev.damping[(i, j)]
                        + nm.a0 * ev.added_mass_kg[(i, j)];
                    self.d_b[(o + i) * nb + o + j] += kd;
                    if w == 4 {
                        self.d_b[(o + i) * nb + o + 2 + j] -= kd;
                        self.d_b[(o + 2 + i) * nb + o + j] -= kd;
                        self.d_b[(o + 2 + i) * nb + o + 2 + j] += kd;
                    }
                }
            }
        }
        Ok(())
    }

    /// Bearing `li`'s force and derivatives at the iterate: the film (or its linearisation),
    /// the prehistory relaxation of its coefficients when `relax`, and the film's fluid
    /// inertia −m ä with the Newmark acceleration ä = a0 (d − d_n) − a1 ḋ_n − d̈_n.
    fn link_force(
        &mut self,
        li: usize,
        nm: Newmark,
        speed: f64,
        time: f64,
        fresh: bool,
        relax: bool,
    ) -> Result<LinkEvaluation, Option<TwinError>> {
        let link = &mut self.links[li];
        let (o, pedestal) = (link.b_offset, link.pedestal.is_some());
        let rel = |v: &dyn Fn(usize) -> f64| -> [f64; 2] {
            if pedestal {
                [v(o) - v(o + 2), v(o + 1) - v(o + 3)]
            } else {
                [v(o), v(o + 1)]
            }
        };
        let (qb, b_dofs, s) = (&self.qb, &self.b_dofs, &self.state);
        let d = rel(&|r| qb[r]);
        let v = rel(&|r| nm.a2 * (qb[r] - s.q[b_dofs[r]]) - s.qd[b_dofs[r]]);
        let mut ev = match self.config.coupling {
            Coupling::Linear => link.evaluate_linear(d, v),
            _ => link
                .evaluate(d, v, speed, &self.config.contact, fresh)
                .map_err(|cause| {
                    Some(TwinError::Film {
                        bearing: link.name.clone(),
                        time_s: time,
                        cause,
                    })
                })?,
        };
        let m = ev.added_mass_kg;
        if m != Matrix2::zeros() {
            let acc = rel(&|r| {
                let d = b_dofs[r];
                nm.a0 * (qb[r] - s.q[d]) - nm.a1 * s.qd[d] - s.qdd[d]
            });
            let inertia = m * Vector2::from(acc);
            ev.force_n[0] -= inertia.x;
            ev.force_n[1] -= inertia.y;
        }
        if relax {
            self.relax_prehistory(li, &mut ev, fresh);
        }
        Ok(ev)
    }

    /// Seed eq. 8 on bearing `li`'s film coefficients, c(k+1) = δ c(k) + (1 − δ) c(k−1), computed
    /// on a `fresh` evaluation and kept as the iteration matrix; the wall's stiffness (contact)
    /// is not a film coefficient and is never relaxed.
    fn relax_prehistory(&mut self, li: usize, ev: &mut LinkEvaluation, fresh: bool) {
        let Coupling::Prehistory { delta } = self.config.coupling else {
            return;
        };
        if fresh {
            let raw = FilmCoefficients {
                stiffness_n_per_m: ev.film_stiffness,
                damping_n_s_per_m: ev.damping,
                ..FilmCoefficients::default()
            };
            self.raw[li] = Some(raw);
            self.relaxed[li] = match self.links[li].previous_raw {
                Some(prev) => raw.scaled(delta).plus(&prev.scaled(1.0 - delta)),
                None => raw,
            };
        }
        let r = self.relaxed[li];
        let wall = ev.stiffness - ev.film_stiffness;
        ev.stiffness = wall + r.stiffness_n_per_m;
        ev.damping = r.damping_n_s_per_m;
    }

    /// The largest residual |g| of a bearing, g = q_B − a − S f_B, as a share of its clearance.
    fn residual_norm(&self, level: usize) -> f64 {
        let nb = self.b_dofs.len();
        let sm = &self.factors[level].s;
        let g = |i: usize| {
            let mut g = self.qb[i] - self.a_b[i];
            for k in 0..nb {
                g -= sm[i * nb + k] * self.f_b[k];
            }
            g
        };
        self.links
            .iter()
            .map(|l| g(l.b_offset).hypot(g(l.b_offset + 1)) / l.clearance_m)
            .fold(0.0, f64::max)
    }

    /// One Newton move Δ = −J⁻¹ g, g = q_B − a − S f_B, J = I + S D, limited to a fifth of the
    /// clearance, and f_B carried to the new iterate as f_B − D Δ. Ok(true) when converged.
    fn newton_move(&mut self, level: usize) -> Result<bool, Option<TwinError>> {
        let nb = self.b_dofs.len();
        let sm = &self.factors[level].s;
        for i in 0..nb {
            let mut g = self.qb[i] - self.a_b[i];
            for k in 0..nb {
                g -= sm[i * nb + k] * self.f_b[k];
            }
            self.delta[i] = -g;
            for j in 0..nb {
                let mut v = if i == j { 1.0 } else { 0.0 };
                for k in 0..nb {
                    v += sm[i * nb + k] * self.d_b[k * nb + j];
                }
                self.jac[i * nb + j] = v;
            }
        }
        let traced = trace::from().is_some_and(|t| self.state.time_s >= t);
        let residual = if traced {
            self.residual_norm(level)
        } else {
            0.0
        };
        if !solve_small(&self.jac, &mut self.delta, nb) {
            return Err(None);
        }
        let mut largest = 0.0_f64;
        for link in &self.links {
            let o = link.b_offset;
            largest = largest.max(self.delta[o].hypot(self.delta[o + 1]) / link.clearance_m);
        }
        let scale = if largest > 0.2 { 0.2 / largest } else { 1.0 };
        if traced {
            self.trace_move(level, residual, largest);
        }
        for i in 0..nb {
            self.delta[i] *= scale;
            self.qb[i] += self.delta[i];
        }
        for i in 0..nb {
            for j in 0..nb {
                self.f_b[i] -= self.d_b[i * nb + j] * self.delta[j];
            }
        }
        // Newton converges quadratically: after a correction Δ the error left is of order
        // |Δ|²/c, so a correction below √tol leaves less than tol and needs no further film
        // solve (the force used is the linearised one at the new iterate, f_B − D Δ)
        let accept = if self.config.coupling == Coupling::Nonlinear
            && !self.links.iter().any(|l| l.last.contact)
        {
            self.config.newton_tolerance.sqrt()
        } else {
            self.config.newton_tolerance
        };
        Ok(largest * scale < accept && scale == 1.0)
    }

    /// The full state at the end of the step, q = K_eff⁻¹ r + Z f_B, and its velocity and
    /// acceleration (Newmark); Err(None) (retry smaller) if any is not finite.
    fn correct(
        &mut self,
        level: usize,
        nm: Newmark,
        time: f64,
        angle: f64,
        speed: f64,
    ) -> Result<(), Option<TwinError>> {
        let f = &self.factors[level];
        let next = &mut self.next;
        next.q.copy_from_slice(&self.q_lin);
        f.add_bearing_response(&self.f_b, &mut next.q);
        let s = &self.state;
        // zipped (no index checks), and the finite check without an early exit: one flag
        // or-ed over every entry (vectorised); the same values and the same verdict
        let state = s.q.iter().zip(s.qd.iter().zip(&s.qdd));
        let mut bad = false;
        for (((q1, qd1), qdd1), (q, (qd, qdd))) in (next
            .q
            .iter()
            .zip(next.qd.iter_mut())
            .zip(next.qdd.iter_mut()))
        .zip(state)
        {
            *qdd1 = nm.a0 * (q1 - q) - nm.a1 * qd - qdd;
            *qd1 = qd + 0.5 * nm.h * (qdd + *qdd1);
            bad |= !(q1.is_finite() & qd1.is_finite() & qdd1.is_finite());
        }
        if bad {
            return Err(None);
        }
        next.time_s = time;
        next.angle_rad = angle;
        next.speed_rad_s = speed;
        std::mem::swap(&mut self.state, &mut self.next);
        Ok(())
    }

    fn add_unbalance(&mut self, angle: f64, speed: f64, accel: f64) {
        for u in &self.unbalance {
            let [fx, fy] = unbalance_force(u.magnitude_kg_m, angle + u.phase_rad, speed, accel);
            let (rx, ry) = (self.reduced_of[4 * u.node], self.reduced_of[4 * u.node + 1]);
            if rx != HELD {
                self.rhs[rx] += fx;
            }
            if ry != HELD {
                self.rhs[ry] += fy;
            }
        }
    }
}

/// The average-acceleration Newmark constants of a step h: a0 = 4/h², a1 = 4/h, a2 = 2/h.
#[derive(Debug, Clone, Copy)]
struct Newmark {
    h: f64,
    a0: f64,
    a1: f64,
    a2: f64,
}

impl Newmark {
    fn of(h: f64) -> Self {
        Self {
            h,
            a0: 4.0 / (h * h),
            a1: 4.0 / h,
            a2: 2.0 / h,
        }
    }
}

/// Diagnosis only, read once from the environment: `ROTOR_TWIN_NEWTON_TRACE=<t in s>` prints
/// every Newton move of the steps from t on to stderr (residual, move, and each bearing's ε,
/// contact, force and coefficients at the iterate).
mod trace {
    use std::sync::OnceLock;

    pub(super) fn from() -> Option<f64> {
        static FROM: OnceLock<Option<f64>> = OnceLock::new();
        *FROM.get_or_init(|| {
            std::env::var("ROTOR_TWIN_NEWTON_TRACE")
                .ok()
                .and_then(|s| s.parse().ok())
        })
    }
}

impl Twin {
    /// Prints one Newton move (diagnosis: [`trace`]).
    fn trace_move(&self, level: usize, residual: f64, largest: f64) {
        let mut line = format!(
            "newton t {:.6} level {level} |g|/c {residual:.3e} |d|/c {largest:.3e}",
            self.state.time_s
        );
        for l in &self.links {
            let o = l.b_offset;
            let e = self.qb[o].hypot(self.qb[o + 1]) / l.clearance_m;
            let ev = &l.last;
            line += &format!(
                " | e {e:.5} contact {} F ({:.1}, {:.1}) Kxx {:.3e} Cxx {:.3e} Cyy {:.3e}",
                u8::from(ev.contact),
                ev.force_n[0],
                ev.force_n[1],
                ev.stiffness[(0, 0)],
                ev.damping[(0, 0)],
                ev.damping[(1, 1)]
            );
        }
        eprintln!("{line}");
    }
}
