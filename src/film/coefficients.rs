//! The eight linearised film coefficients (seed eq. 3–4).

use nalgebra::{Matrix2, Rotation2, Vector2};
use serde::Serialize;

/// The 2 × 2 matrix written as rows `[[a00, a01], [a10, a11]]` (the machine file's and the JSON
/// outputs' form).
pub fn matrix2(rows: &[[f64; 2]; 2]) -> Matrix2<f64> {
    Matrix2::new(rows[0][0], rows[0][1], rows[1][0], rows[1][1])
}

/// The rows of a 2 × 2 matrix.
pub fn rows2(m: &Matrix2<f64>) -> [[f64; 2]; 2] {
    [[m[(0, 0)], m[(0, 1)]], [m[(1, 0)], m[(1, 1)]]]
}

/// x = A⁻¹ b for a 2 × 2 matrix, zero if `a` is singular (a static deflection under a load).
pub fn solve2(a: &Matrix2<f64>, b: [f64; 2]) -> [f64; 2] {
    a.try_inverse()
        .map(|inv| (inv * Vector2::from(b)).into())
        .filter(|x: &[f64; 2]| x.iter().all(|v| v.is_finite()))
        .unwrap_or([0.0, 0.0])
}

/// Serde of a 2 × 2 matrix as its rows `[[a00, a01], [a10, a11]]` (`#[serde(with = ...)]`):
/// the machine file's and the JSON outputs' form, whatever nalgebra's own serde would write.
pub mod rows {
    use nalgebra::Matrix2;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `m` as its rows.
    pub fn serialize<S: Serializer>(m: &Matrix2<f64>, s: S) -> Result<S::Ok, S::Error> {
        super::rows2(m).serialize(s)
    }

    /// Reads the rows of a matrix.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Matrix2<f64>, D::Error> {
        <[[f64; 2]; 2]>::deserialize(d).map(|r| super::matrix2(&r))
    }

    /// A list of matrices, each as its rows.
    pub fn serialize_all<S: Serializer>(ms: &[Matrix2<f64>], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(ms.iter().map(super::rows2))
    }
}

/// Stiffness, damping and added mass of the film about one journal state: the film force
/// changes by `ΔF = −k Δq − c Δq̇ − m Δq̈`, with `k[i][j] = −∂F_i/∂q_j`, `c[i][j] = −∂F_i/∂q̇_j`
/// and `m[i][j] = −∂F_i/∂q̈_j`, indices 0 = x, 1 = y of the fixed frame. The added mass is zero
/// unless the bearing carries its film's fluid inertia ([`crate::film::FilmInertia`]); the film
/// solvers give the eight coefficients only.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct FilmCoefficients {
    /// `[[k_xx, k_xy], [k_yx, k_yy]]` (N/m).
    #[serde(with = "rows")]
    pub stiffness_n_per_m: Matrix2<f64>,
    /// `[[c_xx, c_xy], [c_yx, c_yy]]` (N·s/m).
    #[serde(with = "rows")]
    pub damping_n_s_per_m: Matrix2<f64>,
    /// `[[m_xx, m_xy], [m_yx, m_yy]]` (kg): the film's fluid inertia, zero without it.
    #[serde(with = "rows", skip_serializing_if = "is_zero")]
    pub added_mass_kg: Matrix2<f64>,
}

fn is_zero(m: &Matrix2<f64>) -> bool {
    m.iter().all(|&v| v == 0.0)
}

impl FilmCoefficients {
    /// Dimensionless stiffness K = k c / W (Lund & Thomsen's normalisation), for load `load_n`
    /// (N) and radial clearance `clearance_m` (m).
    pub fn dimensionless_stiffness(&self, load_n: f64, clearance_m: f64) -> Matrix2<f64> {
        self.stiffness_n_per_m * (clearance_m / load_n)
    }

    /// Dimensionless damping B = c ω c_r / W, for load `load_n` (N), clearance `clearance_m` (m)
    /// and speed `speed_rad_s` (rad/s).
    pub fn dimensionless_damping(
        &self,
        load_n: f64,
        clearance_m: f64,
        speed_rad_s: f64,
    ) -> Matrix2<f64> {
        self.damping_n_s_per_m * (speed_rad_s.abs() * clearance_m / load_n)
    }

    /// The coefficients of the same film seen from a frame turned by `r` against this one:
    /// `Rᵀ k R` and `Rᵀ c R` (for a state turned by R, these are the fixed frame's again).
    pub fn turned_back(&self, r: &Rotation2<f64>) -> Self {
        let m = r.matrix();
        let back = |a: &Matrix2<f64>| m.transpose() * a * m;
        Self {
            stiffness_n_per_m: back(&self.stiffness_n_per_m),
            damping_n_s_per_m: back(&self.damping_n_s_per_m),
            added_mass_kg: back(&self.added_mass_kg),
        }
    }

    /// Every coefficient times `s`.
    pub fn scaled(&self, s: f64) -> Self {
        Self {
            stiffness_n_per_m: self.stiffness_n_per_m * s,
            damping_n_s_per_m: self.damping_n_s_per_m * s,
            added_mass_kg: self.added_mass_kg * s,
        }
    }

    /// The sum of two sets of coefficients.
    pub fn plus(&self, o: &Self) -> Self {
        Self {
            stiffness_n_per_m: self.stiffness_n_per_m + o.stiffness_n_per_m,
            damping_n_s_per_m: self.damping_n_s_per_m + o.damping_n_s_per_m,
            added_mass_kg: self.added_mass_kg + o.added_mass_kg,
        }
    }

    /// True if every coefficient is a finite number.
    pub fn is_finite(&self) -> bool {
        self.stiffness_n_per_m
            .iter()
            .chain(self.damping_n_s_per_m.iter())
            .chain(self.added_mass_kg.iter())
            .all(|v| v.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows form is row-major both ways (k_xy is row 0, column 1; nalgebra's own serde
    /// would write the columns), and a FilmCoefficients' JSON keeps the nested rows of the
    /// arrays it replaced, the zero added mass left out.
    #[test]
    fn matrices_read_and_write_as_rows() {
        let text = "[[1.0, 2.0], [3.0, 4.0]]";
        let m = rows::deserialize(&mut serde_json::Deserializer::from_str(text)).unwrap();
        assert_eq!((m[(0, 1)], m[(1, 0)]), (2.0, 3.0));
        let c = FilmCoefficients {
            stiffness_n_per_m: m,
            ..FilmCoefficients::default()
        };
        let v = serde_json::to_value(c).unwrap();
        assert_eq!(
            v["stiffness_n_per_m"],
            serde_json::json!([[1.0, 2.0], [3.0, 4.0]])
        );
        assert_eq!(
            v["damping_n_s_per_m"],
            serde_json::json!([[0.0, 0.0], [0.0, 0.0]])
        );
        assert!(v.get("added_mass_kg").is_none(), "{v}");
    }
}
