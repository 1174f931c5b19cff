//! The time step: Newmark predictor, condensed Newton iteration on the bearing DOFs, update.

use super::{Twin, HELD};
use crate::dynamics::bearing_link::LinearReference;
use crate::dynamics::linear::solve_small;
use crate::dynamics::{Coupling, StepInput, StepOutput, TwinError};
use crate::film::{equilibrium_under_load, FilmCoefficients};
use crate::rotor::unbalance_force;

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
        for level in 0..3 {
            let substeps = 1usize << level;
            // the state to return to if the step must be retried (scratch reused: no allocation)
            self.saved.copy_from(&self.state);
            let mut ok = true;
            for s in 1..=substeps {
                let speed =
                    start_speed + (input.speed_rad_s - start_speed) * s as f64 / substeps as f64;
                match self.advance(level, speed, input.accel_rad_s2) {
                    Ok(it) => iterations += it,
                    Err(Some(e)) => {
                        self.state.copy_from(&self.saved);
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
            self.state.copy_from(&self.saved);
        }
        Err(TwinError::NotConverged {
            time_s: self.state.time_s,
            iterations,
        })
    }

    fn refactor_if_needed(&mut self, speed: f64) {
        let f = &self.factors[0];
        if (speed - f.speed_rad_s).abs()
            > self.config.speed_refactor_tolerance * f.speed_rad_s.max(1.0)
        {
            for f in &mut self.factors {
                f.refactor(&self.m, &self.c, &self.g, &self.k, speed, &self.b_dofs);
            }
            if self.config.coupling == Coupling::Linear {
                self.relinearise_films(speed);
            }
        }
    }

    /// Linear coupling: re-linearises each film about its equilibrium under the same load at
    /// `speed` (rad/s) and the running viscosity.
    pub(super) fn relinearise_films(&mut self, speed: f64) {
        for l in &mut self.links {
            if let Some(r) = l.linear_reference {
                let load = [-r.force_n[0], -r.force_n[1]];
                let mu = l.viscosity();
                if let Ok(eq) = equilibrium_under_load(&mut l.film, mu, load, speed) {
                    l.linear_reference = Some(LinearReference {
                        position_m: eq.position_m,
                        force_n: eq.film.force_n,
                        coefficients: eq.coefficients,
                    });
                }
            }
        }
    }

    /// One Newmark step with factor `level` (h / 2^level) to `speed` (rad/s). Ok(iterations);
    /// Err(None) if Newton did not converge (retry smaller); Err(Some) for a hard failure.
    // Long (≈230 lines): predictor, condensed Newton loop and corrector share the step's
    // scratch state, kept in one function so the hot path allocates nothing; splitting it into
    // predictor / iteration / corrector methods on that scratch is open in issue 10.
    fn advance(
        &mut self,
        level: usize,
        speed: f64,
        accel: f64,
    ) -> Result<usize, Option<TwinError>> {
        let h = self.factors[level].h;
        let factored_speed = self.factors[level].speed_rad_s;
        let (a0, a1, a2) = (4.0 / (h * h), 4.0 / h, 2.0 / h);
        let n = self.state.q.len();
        let nb = self.b_dofs.len();
        let angle = self.state.angle_rad + 0.5 * h * (self.state.speed_rad_s + speed);
        let time = self.state.time_s + h;

        // r = F_ext + M(a0 q + a1 q̇ + q̈) + (C + Ω_f G)(a2 q + q̇) − (Ω − Ω_f) G q̇
        for i in 0..n {
            self.rhs[i] = self.gravity[i] + self.external[i];
        }
        self.add_unbalance(angle, speed, accel);
        let f = &self.factors[level];
        let s = &self.state;
        for i in 0..n {
            self.tmp[i] = a0 * s.q[i] + a1 * s.qd[i] + s.qdd[i];
        }
        self.m_rows.add_product(1.0, &self.tmp, &mut self.rhs);
        for i in 0..n {
            self.tmp[i] = a2 * s.q[i] + s.qd[i];
        }
        self.c_rows.add_product(1.0, &self.tmp, &mut self.rhs);
        self.g_rows
            .add_product(factored_speed, &self.tmp, &mut self.rhs);
        self.g_rows
            .add_product(-(speed - factored_speed), &s.qd, &mut self.rhs);
        f.solve(&self.rhs, &mut self.q_lin);
        for (r, &d) in self.b_dofs.iter().enumerate() {
            self.a_b[r] = self.q_lin[d];
            // predictor: q* = q + h q̇ + h²/2 q̈
            self.qb[r] = s.q[d] + h * s.qd[d] + 0.5 * h * h * s.qdd[d];
        }

        let max_iterations = match self.config.coupling {
            Coupling::Nonlinear | Coupling::Prehistory { .. } => self.config.max_newton_iterations,
            Coupling::Linear => 1,
        };
        // prehistory iterates with its relaxed coefficients; if that does not converge, the
        // step falls back to Newton (fresh coefficients each iteration) and says so
        let prehistory = matches!(self.config.coupling, Coupling::Prehistory { .. });
        let mut fallback = false;
        let mut iterations = 0;
        let mut total_iterations = 0;
        let mut converged = false;
        while iterations < max_iterations || (prehistory && !fallback) {
            if iterations == max_iterations {
                // restart from the predictor with Newton
                fallback = true;
                total_iterations += iterations;
                iterations = 0;
                for (r, &d) in self.b_dofs.iter().enumerate() {
                    let s = &self.state;
                    self.qb[r] = s.q[d] + h * s.qd[d] + 0.5 * h * h * s.qdd[d];
                }
            }
            iterations += 1;
            // bearing forces and their derivatives at the current iterate
            self.f_b.fill(0.0);
            self.d_b.fill(0.0);
            for (li, link) in self.links.iter_mut().enumerate() {
                let o = link.b_offset;
                let rel = |v: &dyn Fn(usize) -> f64| -> [f64; 2] {
                    match link.pedestal {
                        Some(_) => [v(o) - v(o + 2), v(o + 1) - v(o + 3)],
                        None => [v(o), v(o + 1)],
                    }
                };
                let qb = &self.qb;
                let b_dofs = &self.b_dofs;
                let state = &self.state;
                let d = rel(&|r| qb[r]);
                let v = rel(&|r| a2 * (qb[r] - state.q[b_dofs[r]]) - state.qd[b_dofs[r]]);
                // prehistory: the film coefficients are computed once a step (first iteration),
                // relaxed by seed eq. 8 and kept as the iteration matrix; the force is the
                // Reynolds force at every iteration
                let fresh = !prehistory || iterations == 1 || fallback;
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
                if let (Coupling::Prehistory { delta }, false) = (self.config.coupling, fallback) {
                    if fresh {
                        // c(k+1) = δ c(k) + (1 − δ) c(k−1) on the film coefficients
                        let raw = FilmCoefficients {
                            stiffness_n_per_m: ev.film_stiffness,
                            damping_n_s_per_m: ev.damping,
                        };
                        self.raw[li] = Some(raw);
                        let mut relaxed = raw;
                        if let Some(prev) = link.previous_raw {
                            for i in 0..2 {
                                for j in 0..2 {
                                    relaxed.stiffness_n_per_m[i][j] = delta
                                        * raw.stiffness_n_per_m[i][j]
                                        + (1.0 - delta) * prev.stiffness_n_per_m[i][j];
                                    relaxed.damping_n_s_per_m[i][j] = delta
                                        * raw.damping_n_s_per_m[i][j]
                                        + (1.0 - delta) * prev.damping_n_s_per_m[i][j];
                                }
                            }
                        }
                        self.relaxed[li] = relaxed;
                    }
                    // the wall's stiffness (contact) is not a film coefficient: never relaxed
                    let r = self.relaxed[li];
                    for i in 0..2 {
                        for j in 0..2 {
                            let wall = ev.stiffness[i][j] - ev.film_stiffness[i][j];
                            ev.stiffness[i][j] = wall + r.stiffness_n_per_m[i][j];
                            ev.damping[i][j] = r.damping_n_s_per_m[i][j];
                        }
                    }
                }
                // f_B: +F on the journal, −F on the pedestal; D = Tᵀ (K + a2 C) T
                let w = link.width();
                for i in 0..2 {
                    self.f_b[o + i] += ev.force_n[i];
                    if w == 4 {
                        self.f_b[o + 2 + i] -= ev.force_n[i];
                    }
                    for j in 0..2 {
                        let kd = ev.stiffness[i][j] + a2 * ev.damping[i][j];
                        self.d_b[(o + i) * nb + o + j] += kd;
                        if w == 4 {
                            self.d_b[(o + i) * nb + o + 2 + j] -= kd;
                            self.d_b[(o + 2 + i) * nb + o + j] -= kd;
                            self.d_b[(o + 2 + i) * nb + o + 2 + j] += kd;
                        }
                    }
                }
            }
            // residual g = q_B − a − S f_B; Jacobian J = I + S D
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
            if !solve_small(&self.jac, &mut self.delta, nb) {
                return Err(None);
            }
            // limit a Newton move to a fifth of the clearance
            let mut largest = 0.0_f64;
            for link in &self.links {
                let o = link.b_offset;
                let step = self.delta[o].hypot(self.delta[o + 1]) / link.clearance_m;
                largest = largest.max(step);
            }
            let scale = if largest > 0.2 { 0.2 / largest } else { 1.0 };
            for i in 0..nb {
                self.delta[i] *= scale;
                self.qb[i] += self.delta[i];
            }
            // the bearing force consistent with the new iterate: f_B − D Δ
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
            if largest * scale < accept && scale == 1.0 {
                converged = true;
                break;
            }
        }
        if self.config.coupling != Coupling::Linear && !converged {
            return Err(None);
        }

        // full state: q = K_eff⁻¹ r + Z f_B
        let f = &self.factors[level];
        let next = &mut self.next;
        next.q.copy_from_slice(&self.q_lin);
        f.add_bearing_response(&self.f_b, &mut next.q);
        let s = &self.state;
        for i in 0..n {
            next.qdd[i] = a0 * (next.q[i] - s.q[i]) - a1 * s.qd[i] - s.qdd[i];
            next.qd[i] = s.qd[i] + 0.5 * h * (s.qdd[i] + next.qdd[i]);
        }
        if !next
            .q
            .iter()
            .chain(&next.qd)
            .chain(&next.qdd)
            .all(|v| v.is_finite())
        {
            return Err(None);
        }
        next.time_s = time;
        next.angle_rad = angle;
        next.speed_rad_s = speed;
        std::mem::swap(&mut self.state, &mut self.next);
        if let Coupling::Prehistory { .. } = self.config.coupling {
            for (l, r) in self.links.iter_mut().zip(&self.raw) {
                l.previous_raw = *r;
            }
        }
        self.fallbacks += usize::from(fallback);
        Ok(iterations + total_iterations)
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
