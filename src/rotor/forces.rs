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

    /// Adds the unbalance forces (N) to `out` (length n_dof) for rotor angle `angle_rad` (rad),
    /// speed `speed_rad_s` (rad/s) and angular acceleration `accel_rad_s2` (rad/s²):
    /// F = m e [ψ̇² (cos(ψ+φ), sin(ψ+φ)) + ψ̈ (−sin(ψ+φ), cos(ψ+φ))]. Allocates nothing.
    pub fn add_unbalance_force(
        &self,
        angle_rad: f64,
        speed_rad_s: f64,
        accel_rad_s2: f64,
        out: &mut [f64],
    ) {
        for u in &self.unbalance {
            let (s, c) = (angle_rad + u.phase_rad).sin_cos();
            let centrifugal = u.magnitude_kg_m * speed_rad_s * speed_rad_s;
            let tangential = u.magnitude_kg_m * accel_rad_s2;
            out[4 * u.node] += centrifugal * c - tangential * s;
            out[4 * u.node + 1] += centrifugal * s + tangential * c;
        }
    }
}
