//! The film model that reads a [`FilmTable`]: force, zone, friction and the mid-plane profile
//! interpolated, the eight coefficients by the chain rule.

use super::{from_source_frame, FilmTable, ForceFrame, LineOfCentres, Node};
use crate::film::{
    wrap_angle_rad, BearingGeometry, FilmCoefficients, FilmError, FilmModel, FilmResult,
    JournalKinematics,
};
use std::f64::consts::TAU;
use std::sync::Arc;

/// A film model that evaluates a [`FilmTable`] (see the module documentation).
#[derive(Clone)]
pub struct TabulatedFilm {
    table: Arc<FilmTable>,
    last: JournalKinematics,
    /// The last solve if it was lean ([`FilmModel::solve_lean`]): what its outputs need.
    pending: Option<Lean>,
}

/// What a lean solve keeps for its outputs ([`FilmModel::completed_result`]): the state, the
/// interpolated force per unit V in the line of centres, and the stencil's 16 nodes (table
/// index, signs of angles and force, weight) in the order of the interpolation's sums.
#[derive(Clone, Copy)]
struct Lean {
    s: LineOfCentres,
    omega: f64,
    force: [f64; 2],
    nodes: [(usize, [f64; 2], f64); 16],
}

impl TabulatedFilm {
    /// A model reading `table`.
    pub fn new(table: Arc<FilmTable>) -> Self {
        Self {
            table,
            last: JournalKinematics::default(),
            pending: None,
        }
    }

    /// A model reading `table` whose last state was `last` (for its mid-plane profile).
    pub(super) fn at(table: Arc<FilmTable>, last: JournalKinematics) -> Self {
        Self {
            table,
            last,
            pending: None,
        }
    }
}

impl FilmModel for TabulatedFilm {
    fn geometry(&self) -> &BearingGeometry {
        &self.table.geometry
    }

    fn clone_box(&self) -> Box<dyn FilmModel + Send> {
        Box::new(self.clone())
    }

    fn solve(&mut self, kin: &JournalKinematics) -> Result<FilmResult, FilmError> {
        let c = self.table.geometry.radial_clearance_m;
        kin.validate(c)?;
        self.last = *kin;
        self.pending = None;
        let s = self.table.line_of_centres(kin);
        let n = self.table.node_at(s.eps, s.psi);
        Ok(result_of(&s, &n, kin.speed_rad_s))
    }

    fn solve_with_coefficients(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError> {
        let c = self.table.geometry.radial_clearance_m;
        kin.validate(c)?;
        self.last = *kin;
        self.pending = None;
        let s = self.table.line_of_centres(kin);
        // one stencil pass gives the node and its force's slopes (the analytic coefficients)
        let (result, (k, d)) = if s.eps > 1e-3 && s.v > 0.0 {
            let (n, f_eps, f_psi) = self.table.node_with_slopes(s.eps, s.psi);
            let coefficients =
                self.table
                    .coefficients_from_slopes(kin, &s, [n.force, f_eps, f_psi]);
            (result_of(&s, &n, kin.speed_rad_s), coefficients)
        } else {
            let n = self.table.node_at(s.eps, s.psi);
            let coefficients = self.table.difference_coefficients(kin);
            (result_of(&s, &n, kin.speed_rad_s), coefficients)
        };
        Ok((
            result,
            FilmCoefficients {
                stiffness_n_per_m: k,
                damping_n_s_per_m: d,
                ..FilmCoefficients::default()
            },
        ))
    }

    /// The force and its slopes from one stencil pass (the coefficients by the chain rule), the
    /// other 12 node values left for [`completed_result`](FilmModel::completed_result): the same
    /// sums in the same order as `solve_with_coefficients`, so the same force, coefficients and
    /// (completed) result, bit for bit (`lean_solve_equals_the_whole_solve_exactly`). Near the
    /// centre (ε ≤ 10⁻³) or without a source (V = 0) the whole solve.
    fn solve_lean(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError> {
        let c = self.table.geometry.radial_clearance_m;
        kin.validate(c)?;
        let s = self.table.line_of_centres(kin);
        if !(s.eps > 1e-3 && s.v > 0.0) {
            return self.solve_with_coefficients(kin);
        }
        self.last = *kin;
        let (lean, f_eps, f_psi) = self.lean_pass(&s, kin.speed_rad_s);
        let f = lean.force;
        let (k, d) = self
            .table
            .coefficients_from_slopes(kin, &s, [f, f_eps, f_psi]);
        self.pending = Some(lean);
        let result = FilmResult {
            force_n: s.rotate_to_fixed([s.v * f[0], s.v * f[1]]),
            ..FilmResult::default()
        };
        let coefficients = FilmCoefficients {
            stiffness_n_per_m: k,
            damping_n_s_per_m: d,
            ..FilmCoefficients::default()
        };
        Ok((result, coefficients))
    }

    fn completed_result(&self) -> Option<FilmResult> {
        let lean = self.pending.as_ref()?;
        let mut n = Node {
            force: lean.force,
            ..Node::default()
        };
        for &(index, [sign, _], w) in &lean.nodes {
            n.add_outputs(w, sign, &self.table.nodes[index]);
        }
        Some(result_of(&lean.s, &n, lean.omega))
    }

    fn midplane_pressure(&self, out: &mut [f64]) {
        let t = &self.table;
        let s = t.line_of_centres(&self.last);
        // bilinear between the four nodes around the state: the profile is for display and the
        // monitor's revolution-to-revolution pressure difference, not for the force
        let (index, weight) = t.bilinear(s.eps, s.psi);
        let len = out.len().max(1);
        // θ_k − φ in grid columns of the line-of-centres frame, linear between the two columns
        // around it (a nearest column would jump as the attitude turns)
        let shift = s.phi() / TAU * t.n_theta as f64;
        let scale = t.n_theta as f64 / len as f64;
        let nt = t.n_theta as i64;
        // the column of each output angle and the next, wrapped by additions (x lies within a
        // turn or two of the grid: two integer divisions an angle cost more than the blend)
        let at = |k: usize| {
            let x = k as f64 * scale - shift;
            let i = x.floor();
            let i0 = wrap_column(i as i64, nt);
            let i1 = if i0 + 1 == t.n_theta { 0 } else { i0 + 1 };
            (i0, i1, x - i)
        };
        // blend the four nodes' profiles first (on the stack, for grids of up to 512 columns),
        // then sample the blend; larger grids blend at each output angle
        let mut blend = [0.0; 512];
        // the four nodes: weight and the start of the profile
        let nodes: [(f64, usize); 4] = std::array::from_fn(|n| (weight[n], index[n] * t.n_theta));
        let profile = |start: usize| &t.profiles[start..start + t.n_theta];
        if t.n_theta <= blend.len() {
            let blend = &mut blend[..t.n_theta];
            for &(w, start) in &nodes {
                for (b, v) in blend.iter_mut().zip(profile(start)) {
                    *b += w * v;
                }
            }
            for (k, p) in out.iter_mut().enumerate() {
                let (i0, i1, f) = at(k);
                *p = blend[i0] + f * (blend[i1] - blend[i0]);
            }
        } else {
            for (k, p) in out.iter_mut().enumerate() {
                let (i0, i1, f) = at(k);
                *p = nodes
                    .iter()
                    .map(|&(w, start)| {
                        let q = profile(start);
                        w * (q[i0] + f * (q[i1] - q[i0]))
                    })
                    .sum();
            }
        }
        for p in out.iter_mut() {
            *p = (s.v * *p).max(0.0);
        }
    }
}

impl TabulatedFilm {
    /// The stencil pass of [`solve_lean`](FilmModel::solve_lean) at state `s`, speed `omega`
    /// (rad/s): the force per unit V and its slopes d/dε, d/dψ in the line of centres, summed as
    /// `FilmTable::node_with_slopes` sums them, and the stencil's nodes for the outputs.
    fn lean_pass(&self, s: &LineOfCentres, omega: f64) -> (Lean, [f64; 2], [f64; 2]) {
        let t = &self.table;
        let st = t.stencil_with_slopes(s.eps, s.psi);
        let mut lean = Lean {
            s: *s,
            omega,
            force: [0.0; 2],
            nodes: [(0, [1.0, 1.0], 0.0); 16],
        };
        let (mut f, mut f_eps, mut f_psi) = ([0.0; 2], [0.0; 2], [0.0; 2]);
        for a in 0..4 {
            for b in 0..4 {
                let (index, sign) = st.node(a, b);
                let m = &t.nodes[index];
                let w = st.wr[a] * st.wc[a][b];
                // Node::add's force terms, then node_with_slopes' slope terms
                f[0] += sign[1] * w * m.force[0];
                f[1] += sign[1] * w * m.force[1];
                let (w_eps, w_psi) = (
                    sign[1] * st.dwr[a] * st.wc[a][b],
                    sign[1] * st.wr[a] * st.dwc[a][b],
                );
                f_eps[0] += w_eps * m.force[0];
                f_eps[1] += w_eps * m.force[1];
                f_psi[0] += w_psi * m.force[0];
                f_psi[1] += w_psi * m.force[1];
                lean.nodes[4 * a + b] = (index, sign, w);
            }
        }
        if t.res.frame == ForceFrame::Source {
            (f, f_eps, f_psi) = from_source_frame(s.psi, f, f_eps, f_psi);
        }
        lean.force = f;
        (lean, f_eps, f_psi)
    }
}

/// Column `i` of a grid of `n` columns around the circumference, wrapped into 0..n: equal to
/// `i.rem_euclid(n)`, by additions (the profile's columns lie within a turn or two of the grid,
/// and an integer division costs tens of cycles).
fn wrap_column(i: i64, n: i64) -> usize {
    let mut i = i;
    while i < 0 {
        i += n;
    }
    while i >= n {
        i -= n;
    }
    i as usize
}

/// The film's result at state `s` (line-of-centres frame) from the interpolated node `n`, at
/// speed `omega` (rad/s): the force turned back to the fixed frame, the angles of p_max, ζ1 and
/// ζ2 from the attitude (computed once) and their unit vectors in the node.
pub(super) fn result_of(s: &LineOfCentres, n: &Node, omega: f64) -> FilmResult {
    let zone = s.v > 0.0 && n.p_max > 0.0;
    let phi = if zone { s.phi() } else { 0.0 };
    let angle = |k: usize| {
        if zone {
            wrap_angle_rad(phi + n.angles[k][1].atan2(n.angles[k][0]))
        } else {
            0.0
        }
    };
    let torque = omega * n.torque_couette + s.v * n.torque_pressure;
    FilmResult {
        force_n: s.rotate_to_fixed([s.v * n.force[0], s.v * n.force[1]]),
        max_pressure_pa: (s.v * n.p_max).max(0.0),
        max_pressure_angle_rad: angle(0),
        film_start_rad: angle(1),
        film_end_rad: angle(2),
        friction_torque_n_m: torque,
        power_loss_w: torque * omega,
        side_flow_m3_s: s.v * n.side_flow,
        inflow_m3_s: omega * n.inflow_couette + s.v * n.inflow_pressure,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::{FilmGrid, Lubricant};

    /// The seed bearing's table (D 60 mm, L 30 mm, c 40 µm, 60 × 10).
    fn seed_table() -> Arc<FilmTable> {
        let geometry = BearingGeometry::plain(0.06, 0.03, 40e-6).unwrap();
        let lubricant = Lubricant::new(900.0, 0.0008).unwrap();
        FilmTable::shared(&geometry, lubricant, FilmGrid::new(60, 10).unwrap()).unwrap()
    }

    /// The journal at ε, attitude φ, with radial and tangential velocities given as fractions
    /// of c ω, in the fixed frame.
    fn kinematics(eps: f64, phi: f64, [vr, vt]: [f64; 2], c: f64, w: f64) -> JournalKinematics {
        let (vr, vt) = (vr * c * w, vt * c * w);
        JournalKinematics {
            position_m: [eps * c * f64::cos(phi), eps * c * f64::sin(phi)],
            velocity_m_s: [
                vr * f64::cos(phi) - vt * f64::sin(phi),
                vr * f64::sin(phi) + vt * f64::cos(phi),
            ],
            speed_rad_s: w,
        }
    }

    /// The film's one-pass evaluation (node and slopes from one stencil pass, issue 17) gives,
    /// bit for bit, what the separate passes give: the result of `solve`, and the coefficients
    /// of the chain rule on `force_with_slopes` (the same sums in the same order), at states
    /// across the table (whip orbits near the wall, fast squeeze, the centre's fallback).
    #[test]
    fn one_pass_evaluation_equals_the_separate_passes_exactly() {
        let (table, c, w) = (seed_table(), 40e-6, 942.0);
        let mut film = TabulatedFilm::new(table.clone());
        for (eps, phi, vr, vt) in [
            (0.3, 0.4, 0.01, -0.02),
            (0.6, 2.0, -0.05, 0.1),
            (0.85, 4.0, 0.2, 0.05),
            (0.97, 5.5, -0.1, -0.2),
            (0.5, -2.5, 0.3, 0.6),
            (0.0005, 1.0, 0.0, 0.0),
        ] {
            let kin = kinematics(eps, phi, [vr, vt], c, w);
            let (r, coef) = film.solve_with_coefficients(&kin).unwrap();
            let alone = film.solve(&kin).unwrap();
            assert_eq!(r, alone, "ε {eps}: result");
            let s = table.line_of_centres(&kin);
            let (k, d) = if s.eps > 1e-3 && s.v > 0.0 {
                table.analytic_coefficients(&kin, &s)
            } else {
                table.difference_coefficients(&kin)
            };
            assert_eq!(coef.stiffness_n_per_m, k, "ε {eps}: stiffness");
            assert_eq!(coef.damping_n_s_per_m, d, "ε {eps}: damping");
        }
    }

    /// The lean solve (force and coefficients for a Newton iterate, issue 17) gives, bit for
    /// bit, the force and coefficients of the whole solve, and its completed result is the whole
    /// result (every output: p_max, ζ1, ζ2, friction, flows); a whole solve leaves nothing to
    /// complete. States across the table: whip orbits near the wall, fast squeeze, the first
    /// row interval (mirrored or extrapolated row), the centre's fallback, an attitude beyond π.
    #[test]
    fn lean_solve_equals_the_whole_solve_exactly() {
        let (table, c, w) = (seed_table(), 40e-6, 942.0);
        let (mut lean, mut whole) = (TabulatedFilm::new(table.clone()), TabulatedFilm::new(table));
        let mut compared = 0;
        for (eps, phi, vr, vt) in [
            (0.3, 0.4, 0.01, -0.02),
            (0.6, 2.0, -0.05, 0.1),
            (0.85, 4.0, 0.2, 0.05),
            (0.97, 5.5, -0.1, -0.2),
            (0.5, -2.5, 0.3, 0.6),
            (0.002, 1.0, 0.01, 0.0),
            (0.02, 3.5, -0.02, 0.01),
            (0.0005, 1.0, 0.0, 0.0),
        ] {
            let kin = kinematics(eps, phi, [vr, vt], c, w);
            let (r, coef) = whole.solve_with_coefficients(&kin).unwrap();
            assert_eq!(whole.completed_result(), None, "ε {eps}: whole solve");
            let (rl, coef_l) = lean.solve_lean(&kin).unwrap();
            assert_eq!(rl.force_n, r.force_n, "ε {eps}: force");
            assert_eq!(coef_l, coef, "ε {eps}: coefficients");
            let completed = lean.completed_result().unwrap_or(rl);
            compared += usize::from(lean.completed_result().is_some());
            assert_eq!(completed, r, "ε {eps}: completed result");
            assert!(
                r.max_pressure_pa > 0.0,
                "ε {eps}: a pressure zone to compare"
            );
        }
        // all but the centre's state (ε 5·10⁻⁴ ≤ 10⁻³: the whole solve) went the lean way
        assert_eq!(compared, 7);
    }

    /// The chain-rule coefficients of the interpolant equal its central differences (steps
    /// 1e-6 c, 1e-6 c ω) to 1e-4 of the matrix scale, at states across the table.
    #[test]
    fn analytic_coefficients_match_differences_of_the_interpolant() {
        let (table, c, w) = (seed_table(), 40e-6, 942.0);
        for (eps, phi, vr, vt) in [
            (0.3, 0.4, 0.01, -0.02),
            (0.6, 2.0, -0.05, 0.1),
            (0.85, 4.0, 0.2, 0.05),
            (0.95, 5.5, -0.1, -0.2),
            (0.05, 1.0, 0.0, 0.0),
        ] {
            let kin = kinematics(eps, phi, [vr, vt], c, w);
            let s = table.line_of_centres(&kin);
            let (ka, da) = table.analytic_coefficients(&kin, &s);
            // fine central differences (not the coarse fallback's steps)
            let (dq, dv) = (1e-6 * c, 1e-6 * c * w);
            for j in 0..2 {
                let (mut p, mut m) = (kin, kin);
                p.position_m[j] += dq;
                m.position_m[j] -= dq;
                let (fp, fm) = (table.force(&p), table.force(&m));
                let (mut pv, mut mv) = (kin, kin);
                pv.velocity_m_s[j] += dv;
                mv.velocity_m_s[j] -= dv;
                let (gp, gm) = (table.force(&pv), table.force(&mv));
                let kscale = ka.amax();
                let dscale = da.amax();
                for i in 0..2 {
                    let kf = -(fp[i] - fm[i]) / (2.0 * dq);
                    let df = -(gp[i] - gm[i]) / (2.0 * dv);
                    assert!(
                        (ka[(i, j)] - kf).abs() < 1e-4 * kscale,
                        "ε {eps}: k[{i}][{j}] {} vs {kf}",
                        ka[(i, j)]
                    );
                    assert!(
                        (da[(i, j)] - df).abs() < 1e-4 * dscale,
                        "ε {eps}: c[{i}][{j}] {} vs {df}",
                        da[(i, j)]
                    );
                }
            }
        }
    }

    /// `wrap_angle_rad`'s path within a turn (no library remainder) gives, bit for bit, what
    /// the Euclidean remainder gives (the reference: `f64::rem_euclid`, then 2π → 0), for
    /// angles across ±3 turns and at the edges (±0, ±2π and the doubles next to them, a
    /// negative angle so small that adding 2π rounds to 2π).
    #[test]
    fn angle_wrap_is_the_euclidean_remainder() {
        let reference = |a: f64| {
            let r = a.rem_euclid(TAU);
            if r >= TAU {
                0.0
            } else {
                r
            }
        };
        let below = |x: f64| f64::from_bits(x.to_bits() - 1);
        let mut angles = vec![
            0.0,
            -0.0,
            TAU,
            -TAU,
            below(TAU),
            -below(TAU),
            -1e-300,
            1e-300,
        ];
        angles.extend((-3000..=3000).map(|k| k as f64 * 0.00627 + 1e-7));
        for a in angles {
            let (got, want) = (wrap_angle_rad(a), reference(a));
            assert_eq!(
                got.to_bits(),
                want.to_bits(),
                "angle {a:e}: {got} vs {want}"
            );
            assert!((0.0..TAU).contains(&got), "angle {a:e}: {got}");
        }
    }

    /// The profile's column wrap is the Euclidean remainder for every column within three turns
    /// either way (the reference: `i64::rem_euclid`), for grids of one to 61 columns.
    #[test]
    fn column_wrap_is_the_euclidean_remainder() {
        for n in 1..=61_i64 {
            for i in -3 * n..3 * n {
                assert_eq!(
                    wrap_column(i, n),
                    i.rem_euclid(n) as usize,
                    "column {i} of {n}"
                );
            }
        }
    }
}
