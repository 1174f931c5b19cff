//! External forces on the rotor: gravity and residual unbalance (seed eq. 5, F(t) = Q + R).

use super::Rotor;

impl Rotor {
    /// Consistent gravity load (N, N·m) on every global DOF: F = M·g, with g the rigid translation
    /// field (g_x on every x DOF, g_y on every y DOF, pedestals included).
    pub fn gravity_force(&self) -> Vec<f64> {
        let n = self.n_dof();
        let mut field = vec![0.0; n];
        for node in 0..self.n_nodes() {
            field[4 * node] = self.gravity_m_s2[0];
            field[4 * node + 1] = self.gravity_m_s2[1];
        }
        for b in &self.bearings {
            if let Some(p) = b.pedestal_dofs {
                field[p[0]] = self.gravity_m_s2[0];
                field[p[1]] = self.gravity_m_s2[1];
            }
        }
        (0..n)
            .map(|i| (0..n).map(|j| self.mass[(i, j)] * field[j]).sum())
            .collect()
    }
}

/// The force `[F_x, F_y]` (N) of an unbalance m·e = `magnitude_kg_m` (kg·m) at angle
/// `angle_rad` (rad, rotor angle plus the heavy spot's phase) on the shaft, turning at
/// ψ̇ = `speed_rad_s` (rad/s) with ψ̈ = `accel_rad_s2` (rad/s²): the d'Alembert force −m r̈ of
/// the mass point r = e (cos ψ, sin ψ), i.e.
/// F = m e [ψ̇² (cos ψ, sin ψ) + ψ̈ (sin ψ, −cos ψ)]: under acceleration the mass lags and pulls
/// the shaft backwards, against the rotation.
pub fn unbalance_force(
    magnitude_kg_m: f64,
    angle_rad: f64,
    speed_rad_s: f64,
    accel_rad_s2: f64,
) -> [f64; 2] {
    let (s, c) = angle_rad.sin_cos();
    let centrifugal = magnitude_kg_m * speed_rad_s * speed_rad_s;
    let tangential = magnitude_kg_m * accel_rad_s2;
    [
        centrifugal * c + tangential * s,
        centrifugal * s - tangential * c,
    ]
}
