//! The fallback (M5) of the mass-conserving solve: projected (nonlinear) Gauss–Seidel on one
//! unknown per node, then the active set polished from its sets.
//!
//! Row k of (M3) with the other nodes held is a_k Π_k + b_k φ_k + r_k = 0 (a_k > 0 the
//! Poiseuille diagonal, b_k > 0 the storage and upwind Couette coefficient of φ_k). With the
//! universal variable w_k (Π_k = max(w_k, 0), φ_k = 1 + min(w_k, 0)·a_k/b_k) it reads
//! a_k w_k + b_k + r_k = 0 in both states, so the node's update is
//!
//! ```text
//!   (M5)  w_k ← −(r_k + b_k)/a_k ,   full if w_k > 0 (Π = w_k, φ = 1), else ruptured
//!         (Π = 0, φ = −r_k/b_k < 1)
//! ```
//!
//! The map w ↦ residual is off-diagonally antitone (every neighbour coefficient of Π and of the
//! upwind φ is ≤ 0) and each of its linear pieces is column diagonally dominant (a column of
//! the Poiseuille matrix sums to ≥ 0; a φ column sums to the storage term 2V(Ḣ + H/Δt) > 0):
//! an M-function, for which the nonlinear Gauss–Seidel iteration converges to the unique
//! solution from any start (Rheinboldt 1970, J. Math. Anal. Appl. 32, thm. 6.2; the p–θ
//! Gauss–Seidel of Ausas, Jai & Buscaglia 2009 and the projected Gauss–Seidel of Giacopini et
//! al. 2010 are this iteration). The active set is Newton's method on the same piecewise
//! linear map: fast, but with no global guarantee — its pieces are neither all convex nor all
//! concave (a node's slope is a_k full and b_k ruptured, either larger), so it can cycle. When
//! the sweeps have settled the sets, a few active-set passes give the linear solution of those
//! sets (the flow balance to round-off).

use super::super::FiniteFilm;
use crate::film::error::FilmError;
use crate::film::{FilmResult, JournalKinematics};

/// Gauss–Seidel sweeps allowed for one solve.
const MAX_SWEEPS: usize = 20_000;

/// The sweeps have settled when a sweep changes no w_k by more than this share of max |w|.
const SWEEP_TOLERANCE: f64 = 1e-12;

/// Active-set passes from the swept sets (the first two with the exact complementarity, then
/// violations up to 1e-9 of max Π or of φ = 1 let pass: nodes on the rupture boundary).
const POLISH_PASSES: usize = 8;

impl FiniteFilm {
    /// (M5): sweeps to the solution, then the active set from its sets.
    pub(super) fn solve_by_sweeps(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<FilmResult, FilmError> {
        if let Some(path) = debug::dump_path() {
            self.dump_state(path, kin);
        }
        let n = self.order_unknowns();
        self.sweep_until_settled(n, kin)?;
        for pass in 1..=POLISH_PASSES {
            self.solve_mixed_system()?;
            let tol = if pass <= 2 { 1e-12 } else { 1e-9 };
            if !self.update_mixed_sets(tol) {
                return Ok(self.settled(self.fast_passes + pass, kin));
            }
        }
        // the linear solves keep switching nodes on the rupture boundary: the swept solution
        self.sweep_until_settled(n, kin)?;
        Ok(self.settled(self.fast_passes + POLISH_PASSES, kin))
    }

    /// Sweeps (M5) over the `n` unknown nodes until settled; the number of sweeps.
    fn sweep_until_settled(
        &mut self,
        n: usize,
        kin: &JournalKinematics,
    ) -> Result<usize, FilmError> {
        for sweep in 1..=MAX_SWEEPS {
            let (change, scale) = self.sweep_once(n)?;
            if change <= SWEEP_TOLERANCE * scale {
                return Ok(sweep);
            }
        }
        self.warm = false;
        Err(self.not_converged(kin, self.fast_passes + MAX_SWEEPS))
    }

    /// One Gauss–Seidel sweep of (M5) in the order of the unknowns (downstream from the feed
    /// for ω > 0, so the Couette transport of the ruptured zone is carried in one sweep).
    /// Returns (largest change of w, largest |w|).
    fn sweep_once(&mut self, n: usize) -> Result<(f64, f64), FilmError> {
        let nz = self.grid.n_z;
        let speed = self.speed_now;
        let (mut change, mut scale) = (0.0_f64, 0.0_f64);
        for r in 0..n {
            let (i, j) = (self.order[r].0 as usize, self.order[r].1 as usize);
            let k = i * nz + j;
            let (a, b, rest) = self.node_terms(i, j, speed);
            if !(a > 0.0 && b > 0.0) {
                return Err(FilmError::SingularFilm);
            }
            let w = -(rest + b) / a;
            let old = if self.free[k] {
                self.pi[k]
            } else {
                (self.phi[k] - 1.0) * b / a
            };
            if w > 0.0 {
                (self.pi[k], self.phi[k], self.free[k]) = (w, 1.0, true);
            } else {
                (self.pi[k], self.phi[k], self.free[k]) = (0.0, 1.0 + w * a / b, false);
            }
            change = change.max((w - old).abs());
            scale = scale.max(w.abs());
        }
        Ok((change, scale))
    }

    /// Row k = (i, j) of (M3) as a_k Π_k + b_k φ_k + r_k with the other nodes at their current
    /// Π and φ: (a_k, b_k, r_k).
    fn node_terms(&self, i: usize, j: usize, speed: f64) -> (f64, f64, f64) {
        let k = i * self.grid.n_z + j;
        let row = self.mixed_row(i, j, speed);
        let (mut a, mut b, mut rest) = (0.0, 0.0, row.constant);
        for (m, c) in row.pi {
            if m == k {
                a += c;
            } else {
                rest += c * self.pi[m];
            }
        }
        for (m, c) in row.phi {
            if m == k {
                b += c;
            } else {
                rest += c * self.phi[m];
            }
        }
        (a, b, rest)
    }

    /// Writes the state of a solve whose active set cycled (kinematics, φ⁰, sets) and the
    /// nodes each of 12 more passes switches, to `<path>.<n>` (the first 200 only).
    fn dump_state(&mut self, path: &str, kin: &JournalKinematics) {
        let Some(file) = debug::next_file(path) else {
            return;
        };
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let mut out = format!(
            "n_theta {nt}\nn_z {nz}\nradius_m {:?}\nlength_m {:?}\nclearance_m {:?}\n\
             viscosity_pa_s {:?}\ndensity_kg_m3 {:?}\nposition_m {:?} {:?}\nvelocity_m_s {:?} \
             {:?}\nspeed_rad_s {:?}\ninverse_step_1_s {:?}\ntwin_form {}\nfeed_column {}\n",
            self.geometry.radius_m(),
            self.geometry.length_m,
            self.geometry.radial_clearance_m,
            self.lubricant.viscosity_pa_s,
            self.lubricant.density_kg_m3,
            kin.position_m[0],
            kin.position_m[1],
            kin.velocity_m_s[0],
            kin.velocity_m_s[1],
            kin.speed_rad_s,
            self.inverse_step,
            self.twin_form,
            self.feed_column.map_or(-1, |f| f as i64),
        );
        let list = |v: Vec<String>| v.join(" ") + "\n";
        out += &("phi0 ".to_string()
            + &list(self.content_old.iter().map(|v| format!("{v:?}")).collect()));
        out += &("full ".to_string()
            + &list(self.free.iter().map(|&f| u8::from(f).to_string()).collect()));
        let speed = self.speed_now;
        let worst_b = (0..nt * nz)
            .filter(|&k| self.fixed_pi(k / nz).is_none())
            .map(|k| self.node_terms(k / nz, k % nz, speed).1)
            .fold(f64::INFINITY, f64::min);
        out += &format!("least_b {worst_b:?}\n");
        for pass in 1..=12 {
            let before = self.free.clone();
            if self.solve_mixed_system().is_err() {
                out += "singular\n";
                break;
            }
            let pmax = self.pi.iter().fold(0.0_f64, |m, p| m.max(p.abs()));
            let neg = self.pi.iter().fold(0.0_f64, |m, p| m.min(*p));
            let over = self.phi.iter().fold(0.0_f64, |m, p| m.max(*p - 1.0));
            self.update_mixed_sets(1e-12);
            let flips: Vec<String> = (0..nt * nz)
                .filter(|&k| before[k] != self.free[k])
                .map(|k| {
                    format!(
                        "{}:{}{}",
                        k / nz,
                        k % nz,
                        if self.free[k] { "+" } else { "-" }
                    )
                })
                .collect();
            out += &format!(
                "pass {pass} max_pi {pmax:?} least_pi {neg:?} most_phi_over_1 {over:?} flips {}",
                list(flips)
            );
        }
        let _ = std::fs::write(file, out);
    }
}

/// The state dump of a cycling solve, for diagnosis only: written when the environment
/// variable `ROTOR_TWIN_MCAV_DUMP` names a path prefix (read once).
mod debug {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::OnceLock;

    static PATH: OnceLock<Option<String>> = OnceLock::new();
    static COUNT: AtomicUsize = AtomicUsize::new(0);

    pub(super) fn dump_path() -> Option<&'static str> {
        PATH.get_or_init(|| std::env::var("ROTOR_TWIN_MCAV_DUMP").ok())
            .as_deref()
    }

    /// `<path>.<n>` for the first 200 dumps, then None.
    pub(super) fn next_file(path: &str) -> Option<String> {
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        (n < 200).then(|| format!("{path}.{n}"))
    }
}
