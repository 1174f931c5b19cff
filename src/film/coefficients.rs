//! The eight linearised film coefficients (seed eq. 3–4).

use serde::Serialize;

/// Stiffness and damping of the film about one journal state: the film force changes by
/// `ΔF = −k Δq − c Δq̇`, with `k[i][j] = −∂F_i/∂q_j` and `c[i][j] = −∂F_i/∂q̇_j`, indices 0 = x,
/// 1 = y of the fixed frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct FilmCoefficients {
    /// `[[k_xx, k_xy], [k_yx, k_yy]]` (N/m).
    pub stiffness_n_per_m: [[f64; 2]; 2],
    /// `[[c_xx, c_xy], [c_yx, c_yy]]` (N·s/m).
    pub damping_n_s_per_m: [[f64; 2]; 2],
}

impl FilmCoefficients {
    /// Dimensionless stiffness K = k c / W (Lund & Thomsen's normalisation), for load `load_n`
    /// (N) and radial clearance `clearance_m` (m).
    pub fn dimensionless_stiffness(&self, load_n: f64, clearance_m: f64) -> [[f64; 2]; 2] {
        self.stiffness_n_per_m
            .map(|row| row.map(|k| k * clearance_m / load_n))
    }

    /// Dimensionless damping B = c ω c_r / W, for load `load_n` (N), clearance `clearance_m` (m)
    /// and speed `speed_rad_s` (rad/s).
    pub fn dimensionless_damping(
        &self,
        load_n: f64,
        clearance_m: f64,
        speed_rad_s: f64,
    ) -> [[f64; 2]; 2] {
        self.damping_n_s_per_m
            .map(|row| row.map(|b| b * speed_rad_s.abs() * clearance_m / load_n))
    }

    /// True if every coefficient is a finite number.
    pub fn is_finite(&self) -> bool {
        self.stiffness_n_per_m
            .iter()
            .chain(self.damping_n_s_per_m.iter())
            .flatten()
            .all(|v| v.is_finite())
    }
}
