//! Building the twin: reduced matrices, film links, and the static equilibrium it starts from.

use super::{State, Twin, HELD};
use crate::dynamics::bearing_link::{BearingLink, LinkEvaluation};
use crate::dynamics::linear::{SparseMcg, StepFactor};
use crate::dynamics::{
    BearingState, Coupling, FilmEvaluation, ProbeState, StepOutput, TwinConfig, TwinError,
};
use crate::film::{solve2, FilmCoefficients};
use crate::rotor::{static_solution, BearingModel, Rotor};
use faer::linalg::solvers::Solve;
use faer::Mat;
use nalgebra::Matrix2;

impl Twin {
    /// Builds the twin of `rotor`, at rest in its static equilibrium on the films at
    /// `speed_rad_s` (rad/s): rigid-support bearing loads, each film's equilibrium under its load,
    /// the shaft deflected statically and moved rigidly onto the journal positions, then put on
    /// the synchronous orbit of the system linearised there.
    pub fn new(rotor: &Rotor, config: TwinConfig, speed_rad_s: f64) -> Result<Self, TwinError> {
        validate_config(&config)?;
        if !(speed_rad_s.is_finite() && speed_rad_s > 0.0) {
            return Err(TwinError::InvalidInput {
                name: "initial speed (rad/s)",
                value: speed_rad_s,
                rule: "must be finite and greater than zero",
            });
        }
        let sys = ReducedSystem::of(rotor);
        let (mut links, b_dofs) = film_links(rotor, &sys.reduced_of, &config)?;
        let q_full = static_start(rotor, &mut links, speed_rad_s)?;
        let mut q: Vec<f64> = sys.full_of.iter().map(|&d| q_full[d]).collect();
        // start on the synchronous orbit of the linearised system, so that only the nonlinear
        // part of the response has to settle
        let (response, velocity, acceleration) =
            synchronous_response(rotor, &sys, &links, speed_rad_s);
        for (qi, r) in q.iter_mut().zip(&response) {
            *qi += r;
        }
        let mut factors = Vec::new();
        for level in 0..super::LEVELS {
            let h = config.time_step_s / f64::from(1u32 << level);
            factors.push(
                StepFactor::new(&sys.m, &sys.c, &sys.g, &sys.k, h, speed_rad_s, &b_dofs)
                    .ok_or_else(|| {
                        TwinError::Setup(
                            "the effective stiffness K + 2C/h + 4M/h² is singular".into(),
                        )
                    })?,
            );
        }
        let state = State {
            time_s: 0.0,
            angle_rad: 0.0,
            speed_rad_s,
            q,
            qd: velocity,
            qdd: acceleration,
        };
        let parts = Parts {
            sys,
            links,
            b_dofs,
            factors,
            state,
        };
        let mut twin = Self::assemble(rotor, config, parts);
        twin.fill_output(0, 1);
        Ok(twin)
    }

    /// The twin of `rotor` from its built parts, with its scratch allocated once.
    fn assemble(rotor: &Rotor, config: TwinConfig, parts: Parts) -> Self {
        let Parts {
            sys,
            links,
            b_dofs,
            factors,
            state,
        } = parts;
        let (n, nb) = (sys.full_of.len(), b_dofs.len());
        let probes = rotor
            .probes
            .iter()
            .map(|p| {
                let r = &sys.reduced_of;
                let [a, b] = p.angles_rad;
                (
                    [r[4 * p.node], r[4 * p.node + 1]],
                    [a.sin_cos(), b.sin_cos()],
                )
            })
            .collect();
        let output = StepOutput {
            bearings: vec![BearingState::default(); links.len()],
            probes: vec![ProbeState::default(); rotor.probes.len()],
            ..StepOutput::default()
        };
        Self {
            config,
            mcg_rows: SparseMcg::from_dense(&sys.m, &sys.c, &sys.g),
            m: sys.m,
            c: sys.c,
            g: sys.g,
            k: sys.k,
            reduced_of: sys.reduced_of,
            gravity: sys.gravity,
            unbalance: rotor.unbalance.clone(),
            external: vec![0.0; n],
            raw: vec![None; links.len()],
            relaxed: vec![FilmCoefficients::default(); links.len()],
            fallbacks: 0,
            links,
            b_dofs,
            factors,
            probes,
            next: state.clone(),
            saved: state.clone(),
            state,
            rated_speed_rad_s: rotor.rated_speed_rad_s,
            rhs: vec![0.0; n],
            tmp: vec![0.0; n],
            tmp_c: vec![0.0; n],
            q_lin: vec![0.0; n],
            qb: vec![0.0; nb],
            a_b: vec![0.0; nb],
            f_b: vec![0.0; nb],
            d_b: vec![0.0; nb * nb],
            jac: vec![0.0; nb * nb],
            delta: vec![0.0; nb],
            output,
        }
    }
}

/// What [`Twin::new`] builds before the twin itself.
struct Parts {
    sys: ReducedSystem,
    links: Vec<BearingLink>,
    b_dofs: Vec<usize>,
    factors: Vec<StepFactor>,
    state: State,
}

/// The linear part on the DOFs left free by the rigid bearings: M, K, C, G with the
/// constant-coefficient bearings in them, and gravity.
struct ReducedSystem {
    /// Reduced index of each global DOF ([`HELD`] for a rigid bearing's journal).
    reduced_of: Vec<usize>,
    /// Global DOF of each reduced one.
    full_of: Vec<usize>,
    m: Mat<f64>,
    k: Mat<f64>,
    c: Mat<f64>,
    g: Mat<f64>,
    /// M g of the rotor's own mass (N): the bearings' added mass is weightless.
    gravity: Vec<f64>,
}

impl ReducedSystem {
    fn of(rotor: &Rotor) -> Self {
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
        let (mut m, mut k, mut c) = (sub(&rotor.mass), sub(&rotor.stiffness), sub(&rotor.damping));
        // constant-coefficient bearings join the linear part
        for b in &rotor.bearings {
            if let BearingModel::Linear(coef) = &b.model {
                let j = b.journal_dofs.map(|d| reduced_of[d]);
                let p = b.pedestal_dofs.map(|p| p.map(|d| reduced_of[d]));
                add_relative_block(&mut k, j, p, &coef.stiffness_n_per_m);
                add_relative_block(&mut c, j, p, &coef.damping_n_s_per_m);
                add_relative_block(&mut m, j, p, &coef.added_mass_kg);
            }
        }
        let gravity_full = rotor.gravity_force();
        Self {
            gravity: full_of.iter().map(|&d| gravity_full[d]).collect(),
            g: sub(&rotor.gyroscopic),
            reduced_of,
            full_of,
            m,
            k,
            c,
        }
    }
}

/// The film bearings as the step sees them, and the condensed DOFs (each bearing's journal,
/// then its pedestal if flexible).
fn film_links(
    rotor: &Rotor,
    reduced_of: &[usize],
    config: &TwinConfig,
) -> Result<(Vec<BearingLink>, Vec<usize>), TwinError> {
    let mut links = Vec::new();
    let mut b_dofs = Vec::new();
    for b in &rotor.bearings {
        let BearingModel::Film(f) = &b.model else {
            continue;
        };
        let journal = b.journal_dofs.map(|d| reduced_of[d]);
        let pedestal = b.pedestal_dofs.map(|p| p.map(|d| reduced_of[d]));
        let b_offset = b_dofs.len();
        b_dofs.extend(journal);
        if let Some(p) = pedestal {
            b_dofs.extend(p);
        }
        // the linear coupling evaluates films only to re-linearise: direct
        let film = match (config.film, config.coupling) {
            (FilmEvaluation::Direct, _) | (_, Coupling::Linear) => f.reference_solver(),
            (FilmEvaluation::Table, _) => f
                .reference_tabulated_solver()
                .map_err(|e| TwinError::Setup(format!("bearing '{}': {e}", b.name)))?,
        };
        links.push(BearingLink {
            name: b.name.clone(),
            journal,
            pedestal,
            b_offset,
            clearance_m: f.geometry.radial_clearance_m,
            radius_m: f.geometry.radius_m(),
            viscosity_pa_s: f.lubricant.viscosity_pa_s,
            film: f.fielded(film),
            linear_reference: None,
            previous_raw: None,
            inertia: f.inertia,
            kappa: 1.0,
            last: LinkEvaluation::default(),
        });
    }
    Ok((links, b_dofs))
}

/// The global displacement of the static start at `speed_rad_s`: each film's equilibrium under
/// its rigid-support load (set as the link's linear reference), pedestals under their loads,
/// the statically deflected shaft moved rigidly onto the journals (exact for two bearings; a
/// least-squares fit for more).
fn static_start(
    rotor: &Rotor,
    links: &mut [BearingLink],
    speed_rad_s: f64,
) -> Result<Vec<f64>, TwinError> {
    let statics = static_solution(rotor).map_err(|e| TwinError::Setup(e.to_string()))?;
    let mut q_full = statics.displacement.clone();
    q_full.resize(rotor.n_dof(), 0.0);
    let mut journal_abs: Vec<(f64, [f64; 2])> = Vec::new();
    let mut films = links.iter_mut();
    for (b, load) in rotor.bearings.iter().zip(&statics.bearing_loads_n) {
        let d = match &b.model {
            BearingModel::Film(_) => match films.next() {
                Some(link) => link.start_at_equilibrium(*load, speed_rad_s)?,
                None => [0.0, 0.0],
            },
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
            journal_abs.push((rotor.node_z_m[b.node], [p_abs[0] + d[0], p_abs[1] + d[1]]));
        }
    }
    let fit = rigid_fit(&journal_abs);
    for (node, &z) in rotor.node_z_m.iter().enumerate() {
        for plane in 0..2 {
            let (a, slope) = fit[plane];
            q_full[4 * node + plane] += a + slope * z;
        }
        q_full[4 * node + 2] += -fit[1].1; // θx = −dy/dz
        q_full[4 * node + 3] += fit[0].1; // θy = dx/dz
    }
    Ok(q_full)
}

impl BearingLink {
    /// Puts the film at its equilibrium under `load` (N) at `speed_rad_s`: the linear
    /// reference (with the added mass, if the film carries its inertia) and the last
    /// evaluation. Returns the journal's position relative to the bearing (m).
    fn start_at_equilibrium(
        &mut self,
        load: [f64; 2],
        speed_rad_s: f64,
    ) -> Result<[f64; 2], TwinError> {
        let (eq, force_n) = self
            .linearise(load, speed_rad_s)
            .map_err(|cause| TwinError::Film {
                bearing: self.name.clone(),
                time_s: 0.0,
                cause,
            })?;
        let coefficients = self
            .linear_reference
            .map(|r| r.coefficients)
            .unwrap_or_default();
        self.last = LinkEvaluation {
            force_n,
            stiffness: eq.coefficients.stiffness_n_per_m,
            damping: eq.coefficients.damping_n_s_per_m,
            film_stiffness: eq.coefficients.stiffness_n_per_m,
            added_mass_kg: coefficients.added_mass_kg,
            film: eq.film,
            contact: false,
            rub_power_w: 0.0,
        };
        Ok(eq.position_m)
    }
}

/// The steady 1X unbalance response of the system linearised about the static equilibrium
/// (film coefficients there): (K_t − Ω²M + iΩ C_t) Q = F_u, solved in real form. Returns
/// displacement, velocity and acceleration at rotor angle 0 (reduced DOFs). Zeros if singular.
fn synchronous_response(
    rotor: &Rotor,
    sys: &ReducedSystem,
    links: &[BearingLink],
    speed: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (m0, c, g, k, reduced_of) = (&sys.m, &sys.c, &sys.g, &sys.k, &sys.reduced_of);
    let n = m0.nrows();
    let (mut kt, mut m) = (k.clone(), m0.clone());
    let mut ct = Mat::<f64>::from_fn(n, n, |i, j| c[(i, j)] + speed * g[(i, j)]);
    for l in links {
        if let Some(r) = l.linear_reference {
            let coef = &r.coefficients;
            add_relative_block(&mut kt, l.journal, l.pedestal, &coef.stiffness_n_per_m);
            add_relative_block(&mut ct, l.journal, l.pedestal, &coef.damping_n_s_per_m);
            add_relative_block(&mut m, l.journal, l.pedestal, &coef.added_mass_kg);
        }
    }
    // [A_r −A_i; A_i A_r], A_r = K_t − Ω²M, A_i = Ω C_t
    let a = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| {
        let (ii, jj) = (i % n, j % n);
        let ar = kt[(ii, jj)] - speed * speed * m[(ii, jj)];
        let ai = speed * ct[(ii, jj)];
        match (i < n, j < n) {
            (true, true) | (false, false) => ar,
            (true, false) => -ai,
            (false, true) => ai,
        }
    });
    let mut f = Mat::<f64>::zeros(2 * n, 1);
    for u in &rotor.unbalance {
        let amp = u.magnitude_kg_m * speed * speed;
        let (s, co) = u.phase_rad.sin_cos();
        // x = Re(F e^{iΩt}) with F_x = A e^{iφ}; y = sin(Ωt+φ) → F_y = −i A e^{iφ}
        let (rx, ry) = (reduced_of[4 * u.node], reduced_of[4 * u.node + 1]);
        if rx != HELD {
            f[(rx, 0)] += amp * co;
            f[(n + rx, 0)] += amp * s;
        }
        if ry != HELD {
            f[(ry, 0)] += amp * s;
            f[(n + ry, 0)] -= amp * co;
        }
    }
    let x = a.partial_piv_lu().solve(&f);
    let ok = (0..2 * n).all(|i| x[(i, 0)].is_finite());
    let re = |i: usize| if ok { x[(i, 0)] } else { 0.0 };
    let im = |i: usize| if ok { x[(n + i, 0)] } else { 0.0 };
    (
        (0..n).map(re).collect(),
        (0..n).map(|i| -speed * im(i)).collect(),
        (0..n).map(|i| -speed * speed * re(i)).collect(),
    )
}

fn validate_config(c: &TwinConfig) -> Result<(), TwinError> {
    let bad = |name, value, rule| Err(TwinError::InvalidInput { name, value, rule });
    if !(c.time_step_s.is_finite()
        && c.time_step_s > 0.0
        && c.time_step_s < crate::dynamics::MAX_TIME_STEP_S)
    {
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
    block: &Matrix2<f64>,
) {
    for a in 0..2 {
        for b in 0..2 {
            let v = block[(a, b)];
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
fn pedestal_stiffness(rotor: &Rotor, p: Option<[usize; 2]>) -> Option<Matrix2<f64>> {
    p.map(|p| Matrix2::from_fn(|i, j| rotor.stiffness[(p[i], p[j])]))
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
