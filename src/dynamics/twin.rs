//! The engine: state, construction at the static equilibrium, and the time step.

use super::bearing_link::{BearingLink, LinearReference, LinkEvaluation};
use super::linear::{solve_small, SparseRows, StepFactor};
use super::{BearingState, Coupling, ProbeState, StepInput, StepOutput, TwinConfig, TwinError};
use crate::film::{equilibrium_under_load, FilmCoefficients, FilmModel, JournalKinematics};
use crate::rotor::{static_solution, BearingModel, Rotor, Unbalance};
use faer::Mat;

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

/// A saved twin state: restoring it makes the following steps repeat exactly.
pub struct Checkpoint {
    state: State,
    films: Vec<Box<dyn FilmModel + Send>>,
    previous_raw: Vec<Option<FilmCoefficients>>,
    linear_reference: Vec<Option<LinearReference>>,
    last: Vec<LinkEvaluation>,
    unbalance: Vec<Unbalance>,
    external: Vec<f64>,
}

/// The twin core (see the module documentation of [`crate::dynamics`]).
pub struct Twin {
    config: TwinConfig,
    m: Mat<f64>,
    c: Mat<f64>,
    g: Mat<f64>,
    k: Mat<f64>,
    m_rows: SparseRows,
    c_rows: SparseRows,
    g_rows: SparseRows,
    /// full DOF → reduced index (or HELD)
    reduced_of: Vec<usize>,
    gravity: Vec<f64>,
    unbalance: Vec<Unbalance>,
    external: Vec<f64>,
    links: Vec<BearingLink>,
    b_dofs: Vec<usize>,
    /// factors for h, h/2, h/4
    factors: Vec<StepFactor>,
    probes: Vec<([usize; 2], [f64; 2])>,
    state: State,
    rated_speed_rad_s: f64,
    // scratch, sized once
    rhs: Vec<f64>,
    tmp: Vec<f64>,
    q_lin: Vec<f64>,
    next: State,
    qb: Vec<f64>,
    a_b: Vec<f64>,
    f_b: Vec<f64>,
    d_b: Vec<f64>,
    jac: Vec<f64>,
    delta: Vec<f64>,
    raw: Vec<Option<FilmCoefficients>>,
    output: StepOutput,
}

impl Twin {
    /// Builds the twin of `rotor`, at rest in its static equilibrium on the films at
    /// `speed_rad_s` (rad/s): rigid-support bearing loads, each film's equilibrium under its load,
    /// the shaft deflected statically and moved rigidly onto the journal positions.
    pub fn new(rotor: &Rotor, config: TwinConfig, speed_rad_s: f64) -> Result<Self, TwinError> {
        validate_config(&config)?;
        if !(speed_rad_s.is_finite() && speed_rad_s > 0.0) {
            return Err(TwinError::InvalidInput {
                name: "initial speed (rad/s)",
                value: speed_rad_s,
                rule: "must be finite and greater than zero",
            });
        }
        let n_full = rotor.n_dof();
        let held: Vec<usize> = rotor
            .bearings
            .iter()
            .filter(|b| matches!(b.model, BearingModel::Rigid))
            .flat_map(|b| b.journal_dofs)
            .collect();
        let mut reduced_of = vec![HELD; n_full];
        let mut full_of = Vec::new();
        for d in 0..n_full {
            if !held.contains(&d) {
                reduced_of[d] = full_of.len();
                full_of.push(d);
            }
        }
        let n = full_of.len();
        let sub = |a: &Mat<f64>| Mat::<f64>::from_fn(n, n, |i, j| a[(full_of[i], full_of[j])]);
        let m = sub(&rotor.mass);
        let mut k = sub(&rotor.stiffness);
        let mut c = sub(&rotor.damping);
        let g = sub(&rotor.gyroscopic);
        // constant-coefficient bearings join the linear part
        for b in &rotor.bearings {
            if let BearingModel::Linear(coef) = &b.model {
                let j = b.journal_dofs.map(|d| reduced_of[d]);
                let p = b.pedestal_dofs.map(|p| p.map(|d| reduced_of[d]));
                add_relative_block(&mut k, j, p, &coef.stiffness_n_per_m);
                add_relative_block(&mut c, j, p, &coef.damping_n_s_per_m);
            }
        }
        let gravity_full = rotor.gravity_force();
        let gravity: Vec<f64> = full_of.iter().map(|&d| gravity_full[d]).collect();

        // film bearings and the condensed DOFs
        let mut links = Vec::new();
        let mut b_dofs = Vec::new();
        for b in &rotor.bearings {
            if let BearingModel::Film(f) = &b.model {
                let journal = b.journal_dofs.map(|d| reduced_of[d]);
                let pedestal = b.pedestal_dofs.map(|p| p.map(|d| reduced_of[d]));
                let b_offset = b_dofs.len();
                b_dofs.extend(journal);
                if let Some(p) = pedestal {
                    b_dofs.extend(p);
                }
                links.push(BearingLink {
                    name: b.name.clone(),
                    journal,
                    pedestal,
                    b_offset,
                    clearance_m: f.geometry.radial_clearance_m,
                    radius_m: f.geometry.radius_m(),
                    viscosity_pa_s: f.lubricant.viscosity_pa_s,
                    film: f.solver(),
                    linear_reference: None,
                    previous_raw: None,
                    last: LinkEvaluation::default(),
                });
            }
        }
        let nb = b_dofs.len();

        // static equilibrium at the starting speed
        let statics = static_solution(rotor).map_err(|e| TwinError::Setup(e.to_string()))?;
        let mut q_full = statics.displacement.clone();
        q_full.resize(n_full, 0.0);
        let mut journal_abs: Vec<(f64, [f64; 2])> = Vec::new();
        let mut link_index = 0;
        for (b, load) in rotor.bearings.iter().zip(&statics.bearing_loads_n) {
            let z = rotor.node_z_m[b.node];
            let d = match &b.model {
                BearingModel::Film(_) => {
                    let link = &mut links[link_index];
                    link_index += 1;
                    let eq = equilibrium_under_load(
                        link.film.as_mut(),
                        link.viscosity_pa_s,
                        *load,
                        speed_rad_s,
                    )
                    .map_err(|source| TwinError::Film {
                        bearing: link.name.clone(),
                        time_s: 0.0,
                        source,
                    })?;
                    link.linear_reference = Some(LinearReference {
                        position_m: eq.position_m,
                        force_n: eq.film.force_n,
                        coefficients: eq.coefficients,
                    });
                    link.last = LinkEvaluation {
                        force_n: eq.film.force_n,
                        stiffness: eq.coefficients.stiffness_n_per_m,
                        damping: eq.coefficients.damping_n_s_per_m,
                        film: eq.film,
                        contact: false,
                    };
                    eq.position_m
                }
                BearingModel::Linear(coef) => solve2(&coef.stiffness_n_per_m, *load),
                BearingModel::Rigid => [0.0, 0.0],
            };
            // pedestal: its spring carries the journal's load and its own weight
            let mut p_abs = [0.0, 0.0];
            if let (Some(p), Some(spec_k)) =
                (b.pedestal_dofs, pedestal_stiffness(rotor, b.pedestal_dofs))
            {
                let mp = rotor.mass[(p[0], p[0])];
                let f = [
                    load[0] + mp * rotor.gravity_m_s2[0],
                    load[1] + mp * rotor.gravity_m_s2[1],
                ];
                p_abs = solve2(&spec_k, f);
                q_full[p[0]] = p_abs[0];
                q_full[p[1]] = p_abs[1];
            }
            if !matches!(b.model, BearingModel::Rigid) {
                journal_abs.push((z, [p_abs[0] + d[0], p_abs[1] + d[1]]));
            }
        }
        // move the statically deflected shaft rigidly onto the journal positions (exact for two
        // bearings; a least-squares fit for more)
        let fit = rigid_fit(&journal_abs);
        for (node, &z) in rotor.node_z_m.iter().enumerate() {
            for plane in 0..2 {
                let (a, slope) = fit[plane];
                q_full[4 * node + plane] += a + slope * z;
            }
            q_full[4 * node + 2] += -fit[1].1; // θx = −dy/dz
            q_full[4 * node + 3] += fit[0].1; // θy = dx/dz
        }
        let q: Vec<f64> = full_of.iter().map(|&d| q_full[d]).collect();

        let mut factors = Vec::new();
        for level in 0..3 {
            let h = config.time_step_s / f64::from(1u32 << level);
            factors.push(
                StepFactor::new(&m, &c, &g, &k, h, speed_rad_s, &b_dofs).ok_or_else(|| {
                    TwinError::Setup("the effective stiffness K + 2C/h + 4M/h² is singular".into())
                })?,
            );
        }
        let probes = rotor
            .probes
            .iter()
            .map(|p| {
                (
                    [reduced_of[4 * p.node], reduced_of[4 * p.node + 1]],
                    p.angles_rad,
                )
            })
            .collect();
        let state = State {
            time_s: 0.0,
            angle_rad: 0.0,
            speed_rad_s,
            q,
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
        };
        let output = StepOutput {
            bearings: vec![BearingState::default(); links.len()],
            probes: vec![ProbeState::default(); rotor.probes.len()],
            ..StepOutput::default()
        };
        let mut twin = Self {
            config,
            m_rows: SparseRows::from_dense(&m),
            c_rows: SparseRows::from_dense(&c),
            g_rows: SparseRows::from_dense(&g),
            m,
            c,
            g,
            k,
            reduced_of,
            gravity,
            unbalance: rotor.unbalance.clone(),
            external: vec![0.0; n],
            raw: vec![None; links.len()],
            links,
            b_dofs,
            factors,
            probes,
            next: state.clone(),
            state,
            rated_speed_rad_s: rotor.rated_speed_rad_s,
            rhs: vec![0.0; n],
            tmp: vec![0.0; n],
            q_lin: vec![0.0; n],
            qb: vec![0.0; nb],
            a_b: vec![0.0; nb],
            f_b: vec![0.0; nb],
            d_b: vec![0.0; nb * nb],
            jac: vec![0.0; nb * nb],
            delta: vec![0.0; nb],
            output,
        };
        twin.fill_output(0, 1);
        Ok(twin)
    }

    /// The settings.
    pub fn config(&self) -> &TwinConfig {
        &self.config
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
        if !(magnitude_kg_m.is_finite() && (0.0..=1.0).contains(&magnitude_kg_m)) {
            return Err(TwinError::InvalidInput {
                name: "unbalance (kg·m)",
                value: magnitude_kg_m,
                rule: "must be finite, 0 to 1 kg·m",
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
            films: self.links.iter().map(|l| l.film.clone_box()).collect(),
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
            l.film = cp.films[i].clone_box();
            l.previous_raw = cp.previous_raw[i];
            l.linear_reference = cp.linear_reference[i];
            l.last = cp.last[i];
        }
        self.unbalance = cp.unbalance.clone();
        self.external = cp.external.clone();
        self.fill_output(0, 1);
    }

    /// Advances one time step of `config.time_step_s` to the input speed. On failure the state is
    /// unchanged and the error says when and why; the output never holds a non-finite number.
    pub fn step(&mut self, input: &StepInput) -> Result<&StepOutput, TwinError> {
        if !(input.speed_rad_s.is_finite()
            && input.speed_rad_s > 0.0
            && input.speed_rad_s <= 10.0 * self.rated_speed_rad_s)
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
        for level in 0..3 {
            let substeps = 1usize << level;
            let saved = self.state.clone();
            let mut ok = true;
            for s in 1..=substeps {
                let speed =
                    start_speed + (input.speed_rad_s - start_speed) * s as f64 / substeps as f64;
                match self.advance(level, speed, input.accel_rad_s2) {
                    Ok(it) => iterations += it,
                    Err(Some(e)) => {
                        self.state = saved;
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
            self.state = saved;
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
                // re-linearise each film about its equilibrium under the same load at the new speed
                for l in &mut self.links {
                    if let Some(r) = l.linear_reference {
                        let load = [-r.force_n[0], -r.force_n[1]];
                        if let Ok(eq) =
                            equilibrium_under_load(l.film.as_mut(), l.viscosity_pa_s, load, speed)
                        {
                            l.linear_reference = Some(LinearReference {
                                position_m: eq.position_m,
                                force_n: eq.film.force_n,
                                coefficients: eq.coefficients,
                            });
                        }
                    }
                }
            }
        }
    }

    /// One Newmark step with factor `level` (h / 2^level) to `speed` (rad/s). Ok(iterations);
    /// Err(None) if Newton did not converge (retry smaller); Err(Some) for a hard failure.
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
            Coupling::Nonlinear => self.config.max_newton_iterations,
            Coupling::Linear | Coupling::Prehistory { .. } => 1,
        };
        let mut iterations = 0;
        let mut converged = false;
        while iterations < max_iterations {
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
                let mut ev = match self.config.coupling {
                    Coupling::Linear => link.evaluate_linear(d, v),
                    _ => link
                        .evaluate(d, v, speed, &self.config.contact)
                        .map_err(|source| {
                            Some(TwinError::Film {
                                bearing: link.name.clone(),
                                time_s: time,
                                source,
                            })
                        })?,
                };
                if let Coupling::Prehistory { delta } = self.config.coupling {
                    // seed eq. 8: c(k+1) = δ c(k) + (1 − δ) c(k−1)
                    let raw = FilmCoefficients {
                        stiffness_n_per_m: ev.stiffness,
                        damping_n_s_per_m: ev.damping,
                    };
                    self.raw[li] = Some(raw);
                    if let Some(prev) = link.previous_raw {
                        for i in 0..2 {
                            for j in 0..2 {
                                ev.stiffness[i][j] = delta * raw.stiffness_n_per_m[i][j]
                                    + (1.0 - delta) * prev.stiffness_n_per_m[i][j];
                                ev.damping[i][j] = delta * raw.damping_n_s_per_m[i][j]
                                    + (1.0 - delta) * prev.damping_n_s_per_m[i][j];
                            }
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
            if !solve_small(&mut self.jac, &mut self.delta, nb) {
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
            if largest * scale < self.config.newton_tolerance && scale == 1.0 {
                converged = true;
                break;
            }
        }
        if self.config.coupling == Coupling::Nonlinear && !converged {
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
        Ok(iterations)
    }

    fn add_unbalance(&mut self, angle: f64, speed: f64, accel: f64) {
        for u in &self.unbalance {
            let (s, c) = (angle + u.phase_rad).sin_cos();
            let centrifugal = u.magnitude_kg_m * speed * speed;
            let tangential = u.magnitude_kg_m * accel;
            let (rx, ry) = (self.reduced_of[4 * u.node], self.reduced_of[4 * u.node + 1]);
            if rx != HELD {
                self.rhs[rx] += centrifugal * c - tangential * s;
            }
            if ry != HELD {
                self.rhs[ry] += centrifugal * s + tangential * c;
            }
        }
    }

    fn fill_output(&mut self, iterations: usize, substeps: usize) {
        let s = &self.state;
        let out = &mut self.output;
        out.time_s = s.time_s;
        out.angle_rad = s.angle_rad;
        out.speed_rad_s = s.speed_rad_s;
        out.newton_iterations = iterations;
        out.substeps = substeps;
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
            };
        }
        for (p, (dofs, angles)) in out.probes.iter_mut().zip(&self.probes) {
            let at = |r: usize| if r == HELD { 0.0 } else { s.q[r] };
            let x = [at(dofs[0]), at(dofs[1])];
            *p = ProbeState {
                displacement_m: x,
                readings_m: angles.map(|a| x[0] * a.cos() + x[1] * a.sin()),
            };
        }
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

fn validate_config(c: &TwinConfig) -> Result<(), TwinError> {
    let bad = |name, value, rule| Err(TwinError::InvalidInput { name, value, rule });
    if !(c.time_step_s.is_finite() && c.time_step_s > 0.0 && c.time_step_s < 0.1) {
        return bad(
            "time step (s)",
            c.time_step_s,
            "must be finite, above zero and below 0.1 s",
        );
    }
    if !(c.newton_tolerance.is_finite() && c.newton_tolerance > 0.0 && c.newton_tolerance < 0.1) {
        return bad(
            "Newton tolerance (share of clearance)",
            c.newton_tolerance,
            "must lie in (0, 0.1)",
        );
    }
    if c.max_newton_iterations == 0 || c.max_newton_iterations > 1000 {
        return bad(
            "Newton iterations",
            c.max_newton_iterations as f64,
            "must be 1 to 1000",
        );
    }
    if let Coupling::Prehistory { delta } = c.coupling {
        if !(delta.is_finite() && delta > 0.0 && delta <= 1.0) {
            return bad("prehistory relaxation δ", delta, "must lie in (0, 1]");
        }
    }
    let ct = &c.contact;
    if !(ct.onset_eccentricity_ratio > 0.5 && ct.onset_eccentricity_ratio < 0.999) {
        return bad(
            "contact onset eccentricity ratio",
            ct.onset_eccentricity_ratio,
            "must lie in (0.5, 0.999)",
        );
    }
    if !(ct.wall_stiffness_n_per_m.is_finite() && ct.wall_stiffness_n_per_m > 0.0) {
        return bad(
            "wall stiffness (N/m)",
            ct.wall_stiffness_n_per_m,
            "must be finite and above zero",
        );
    }
    if !(ct.friction_coefficient.is_finite() && (0.0..=2.0).contains(&ct.friction_coefficient)) {
        return bad(
            "wall friction coefficient",
            ct.friction_coefficient,
            "must lie in [0, 2]",
        );
    }
    Ok(())
}

/// Adds a 2 × 2 block acting on the relative motion journal − pedestal (or journal − ground).
fn add_relative_block(
    m: &mut Mat<f64>,
    j: [usize; 2],
    p: Option<[usize; 2]>,
    block: &[[f64; 2]; 2],
) {
    for a in 0..2 {
        for b in 0..2 {
            let v = block[a][b];
            if j[a] != HELD && j[b] != HELD {
                m[(j[a], j[b])] += v;
            }
            if let Some(p) = p {
                m[(p[a], p[b])] += v;
                if j[a] != HELD {
                    m[(j[a], p[b])] -= v;
                }
                if j[b] != HELD {
                    m[(p[a], j[b])] -= v;
                }
            }
        }
    }
}

/// The pedestal's spring matrix (N/m), read back from the rotor's stiffness.
fn pedestal_stiffness(rotor: &Rotor, p: Option<[usize; 2]>) -> Option<[[f64; 2]; 2]> {
    p.map(|p| {
        [
            [rotor.stiffness[(p[0], p[0])], rotor.stiffness[(p[0], p[1])]],
            [rotor.stiffness[(p[1], p[0])], rotor.stiffness[(p[1], p[1])]],
        ]
    })
}

/// x = A⁻¹ b for a 2 × 2 matrix (zero if singular).
fn solve2(a: &[[f64; 2]; 2], b: [f64; 2]) -> [f64; 2] {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    if det == 0.0 || !det.is_finite() {
        return [0.0, 0.0];
    }
    [
        (a[1][1] * b[0] - a[0][1] * b[1]) / det,
        (-a[1][0] * b[0] + a[0][0] * b[1]) / det,
    ]
}

/// Least-squares straight lines x(z) = a + b z, y(z) = a + b z through the journal positions:
/// [(a_x, b_x), (a_y, b_y)].
fn rigid_fit(points: &[(f64, [f64; 2])]) -> [(f64, f64); 2] {
    let n = points.len() as f64;
    if points.is_empty() {
        return [(0.0, 0.0); 2];
    }
    let zm = points.iter().map(|p| p.0).sum::<f64>() / n;
    let szz: f64 = points.iter().map(|p| (p.0 - zm).powi(2)).sum();
    let mut out = [(0.0, 0.0); 2];
    for (plane, o) in out.iter_mut().enumerate() {
        let vm = points.iter().map(|p| p.1[plane]).sum::<f64>() / n;
        let slope = if szz > 0.0 {
            points
                .iter()
                .map(|p| (p.0 - zm) * (p.1[plane] - vm))
                .sum::<f64>()
                / szz
        } else {
            0.0
        };
        *o = (vm - slope * zm, slope);
    }
    out
}
