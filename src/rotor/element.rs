//! Finite elements of the rotor: the Timoshenko shaft element and the rigid disc.
//!
//! Node degrees of freedom, in this order: `x`, `y` (m), `θx`, `θy` (rad), the small rotations of
//! the cross-section about the fixed `x` and `y` axes; the shaft spins about `+z` from `x`
//! towards `y`. For a slender shaft θy = ∂x/∂z and θx = −∂y/∂z.
//!
//! Each bending plane is the classical planar Timoshenko element with cubic interdependent
//! interpolation (Przemieniecki 1968; Nelson 1980, J. Mech. Des. 102:793; Friswell et al.,
//! *Dynamics of Rotating Machines*, CUP 2010, §5.4): DOFs (w₁, φ₁, w₂, φ₂) with φ the
//! cross-section rotation (φ = dw/dz without shear), shear parameter Φ = 12EI/(κGAL²).
//! Plane x–z uses (x, θy); plane y–z uses (y, −θx).

use serde::Serialize;

/// An isotropic, linear-elastic material.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub youngs_modulus_pa: f64,
    /// Shear modulus G (Pa).
    pub shear_modulus_pa: f64,
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
}

impl Material {
    /// A material from E (Pa), Poisson's ratio ν and ρ (kg/m³); G = E / (2(1 + ν)).
    pub fn from_poisson(youngs_modulus_pa: f64, poisson_ratio: f64, density_kg_m3: f64) -> Self {
        Self {
            youngs_modulus_pa,
            shear_modulus_pa: youngs_modulus_pa / (2.0 * (1.0 + poisson_ratio)),
            density_kg_m3,
        }
    }

    /// Poisson's ratio ν = E/(2G) − 1.
    pub fn poisson_ratio(&self) -> f64 {
        self.youngs_modulus_pa / (2.0 * self.shear_modulus_pa) - 1.0
    }
}

/// One Timoshenko beam element of a circular (hollow) shaft.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ShaftElement {
    /// Element length L (m).
    pub length_m: f64,
    /// Outer diameter (m).
    pub outer_diameter_m: f64,
    /// Inner (bore) diameter (m); 0 for a solid shaft.
    pub inner_diameter_m: f64,
    /// The element's material.
    pub material: Material,
}

/// An 8 × 8 element matrix in the DOF order (x₁, y₁, θx₁, θy₁, x₂, y₂, θx₂, θy₂).
pub type ElementMatrix = [[f64; 8]; 8];

/// Where each planar DOF (w₁, φ₁, w₂, φ₂) of plane x–z and plane y–z goes, with its sign.
const PLANE_XZ: [(usize, f64); 4] = [(0, 1.0), (3, 1.0), (4, 1.0), (7, 1.0)];
const PLANE_YZ: [(usize, f64); 4] = [(1, 1.0), (2, -1.0), (5, 1.0), (6, -1.0)];

impl ShaftElement {
    /// Cross-section area A (m²).
    pub fn area_m2(&self) -> f64 {
        std::f64::consts::PI / 4.0 * (self.outer_diameter_m.powi(2) - self.inner_diameter_m.powi(2))
    }

    /// Second moment of area I (m⁴) about a diameter.
    pub fn second_moment_m4(&self) -> f64 {
        std::f64::consts::PI / 64.0
            * (self.outer_diameter_m.powi(4) - self.inner_diameter_m.powi(4))
    }

    /// Mass (kg).
    pub fn mass_kg(&self) -> f64 {
        self.material.density_kg_m3 * self.area_m2() * self.length_m
    }

    /// Shear coefficient κ of a hollow circular section (Cowper 1966, J. Appl. Mech. 33:335):
    /// κ = 6(1+ν)(1+m²)² / [(7+6ν)(1+m²)² + (20+12ν)m²], m = d_i/d_o.
    pub fn shear_coefficient(&self) -> f64 {
        let nu = self.material.poisson_ratio();
        let m2 = (self.inner_diameter_m / self.outer_diameter_m).powi(2);
        let a = (1.0 + m2).powi(2);
        6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m2)
    }

    /// Shear deformation parameter Φ = 12 E I / (κ G A L²).
    pub fn shear_parameter(&self) -> f64 {
        let m = &self.material;
        12.0 * m.youngs_modulus_pa * self.second_moment_m4()
            / (self.shear_coefficient()
                * m.shear_modulus_pa
                * self.area_m2()
                * self.length_m.powi(2))
    }

    /// Planar bending stiffness (N/m, N, N·m per rad), DOFs (w₁, φ₁, w₂, φ₂).
    fn planar_stiffness(&self) -> [[f64; 4]; 4] {
        let (l, p) = (self.length_m, self.shear_parameter());
        let k = self.material.youngs_modulus_pa * self.second_moment_m4() / ((1.0 + p) * l.powi(3));
        let (a, b, c, d) = (12.0, 6.0 * l, (4.0 + p) * l * l, (2.0 - p) * l * l);
        [
            [a * k, b * k, -a * k, b * k],
            [b * k, c * k, -b * k, d * k],
            [-a * k, -b * k, a * k, -b * k],
            [b * k, d * k, -b * k, c * k],
        ]
    }

    /// Planar translational inertia, consistent with the shear-deformable interpolation (kg).
    fn planar_translational_mass(&self) -> [[f64; 4]; 4] {
        let (l, p) = (self.length_m, self.shear_parameter());
        let s = self.material.density_kg_m3 * self.area_m2() * l / (1.0 + p).powi(2);
        let m1 = 13.0 / 35.0 + 7.0 * p / 10.0 + p * p / 3.0;
        let m2 = (11.0 / 210.0 + 11.0 * p / 120.0 + p * p / 24.0) * l;
        let m3 = 9.0 / 70.0 + 3.0 * p / 10.0 + p * p / 6.0;
        let m4 = (13.0 / 420.0 + 3.0 * p / 40.0 + p * p / 24.0) * l;
        let m5 = (1.0 / 105.0 + p / 60.0 + p * p / 120.0) * l * l;
        let m6 = (1.0 / 140.0 + p / 60.0 + p * p / 120.0) * l * l;
        [
            [m1 * s, m2 * s, m3 * s, -m4 * s],
            [m2 * s, m5 * s, m4 * s, -m6 * s],
            [m3 * s, m4 * s, m1 * s, -m2 * s],
            [-m4 * s, -m6 * s, -m2 * s, m5 * s],
        ]
    }

    /// ∫ Nφᵀ Nφ dz of the rotation interpolation (m): ρI times this is the rotary inertia.
    fn planar_rotation_integral(&self) -> [[f64; 4]; 4] {
        let (l, p) = (self.length_m, self.shear_parameter());
        let s = 1.0 / (l * (1.0 + p).powi(2));
        let r1 = 6.0 / 5.0;
        let r2 = (1.0 / 10.0 - p / 2.0) * l;
        let r3 = (2.0 / 15.0 + p / 6.0 + p * p / 3.0) * l * l;
        let r4 = (1.0 / 30.0 + p / 6.0 - p * p / 6.0) * l * l;
        [
            [r1 * s, r2 * s, -r1 * s, r2 * s],
            [r2 * s, r3 * s, -r2 * s, -r4 * s],
            [-r1 * s, -r2 * s, r1 * s, -r2 * s],
            [r2 * s, -r4 * s, -r2 * s, r3 * s],
        ]
    }

    /// Element stiffness matrix (both planes).
    pub fn stiffness(&self) -> ElementMatrix {
        both_planes(&self.planar_stiffness())
    }

    /// Element mass matrix: translational plus rotary inertia (both planes).
    pub fn mass(&self) -> ElementMatrix {
        let mt = self.planar_translational_mass();
        let rho_i = self.material.density_kg_m3 * self.second_moment_m4();
        let r = self.planar_rotation_integral();
        let mut m = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] = mt[i][j] + rho_i * r[i][j];
            }
        }
        both_planes(&m)
    }

    /// Element gyroscopic matrix per unit spin speed (kg·m²·… per rad/s): the term Ω G q̇ of
    /// the equations of motion. It couples the planes through the polar inertia ρJ = 2ρI:
    /// G = ρJ [[0, R], [−R, 0]] in (plane x–z, plane y–z), R = ∫ Nφᵀ Nφ dz.
    pub fn gyroscopic(&self) -> ElementMatrix {
        let rho_j = 2.0 * self.material.density_kg_m3 * self.second_moment_m4();
        let r = self.planar_rotation_integral();
        let mut g = [[0.0; 8]; 8];
        for (i, &(gi, si)) in PLANE_XZ.iter().enumerate() {
            for (j, &(gj, sj)) in PLANE_YZ.iter().enumerate() {
                g[gi][gj] += si * sj * rho_j * r[i][j];
                g[gj][gi] -= si * sj * rho_j * r[i][j];
            }
        }
        g
    }
}

/// Places one planar matrix in both bending planes.
fn both_planes(p: &[[f64; 4]; 4]) -> ElementMatrix {
    let mut m = [[0.0; 8]; 8];
    for plane in [PLANE_XZ, PLANE_YZ] {
        for (i, &(gi, si)) in plane.iter().enumerate() {
            for (j, &(gj, sj)) in plane.iter().enumerate() {
                m[gi][gj] += si * sj * p[i][j];
            }
        }
    }
    m
}

/// A rigid disc at a node.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Disc {
    /// Name for reports.
    pub name: String,
    /// Shaft node it sits on.
    pub node: usize,
    /// Mass (kg).
    pub mass_kg: f64,
    /// Polar moment of inertia Ip about the spin axis (kg·m²).
    pub polar_inertia_kg_m2: f64,
    /// Diametral moment of inertia Id about a diameter (kg·m²).
    pub diametral_inertia_kg_m2: f64,
}

impl Disc {
    /// Disc mass matrix at its node DOFs (x, y, θx, θy): diag(m, m, Id, Id).
    pub fn mass(&self) -> [[f64; 4]; 4] {
        let (m, id) = (self.mass_kg, self.diametral_inertia_kg_m2);
        [
            [m, 0.0, 0.0, 0.0],
            [0.0, m, 0.0, 0.0],
            [0.0, 0.0, id, 0.0],
            [0.0, 0.0, 0.0, id],
        ]
    }

    /// Disc gyroscopic matrix per unit spin: from dH/dt with H = Ip Ω n + Id θ̇, n ≈ (θy, −θx, 1):
    /// M_x = Id θ̈x + Ip Ω θ̇y, M_y = Id θ̈y − Ip Ω θ̇x.
    pub fn gyroscopic(&self) -> [[f64; 4]; 4] {
        let ip = self.polar_inertia_kg_m2;
        let mut g = [[0.0; 4]; 4];
        g[2][3] = ip;
        g[3][2] = -ip;
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel_element(length_m: f64, d: f64) -> ShaftElement {
        ShaftElement {
            length_m,
            outer_diameter_m: d,
            inner_diameter_m: 0.0,
            material: Material::from_poisson(2.1e11, 0.3, 7850.0),
        }
    }

    /// A rigid-body translation stores no strain energy; the mass matrix carries the element's
    /// mass in each direction; G is skew-symmetric.
    #[test]
    fn element_matrices_satisfy_rigid_body_and_symmetry_checks() {
        let e = steel_element(0.1, 0.05);
        let k = e.stiffness();
        let m = e.mass();
        let g = e.gyroscopic();
        // rigid translation in x: x1 = x2 = 1, rotations 0
        let t = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        // rigid rotation about y by a small angle a: x = a z, θy = a
        let r = [0.0, 0.0, 0.0, 1.0, 0.1, 0.0, 0.0, 1.0];
        for v in [t, r] {
            for row in &k {
                let f: f64 = row.iter().zip(&v).map(|(a, b)| a * b).sum();
                assert!(
                    f.abs() < 1e-6 * k[0][0],
                    "rigid motion strains the element: {f}"
                );
            }
        }
        let mx: f64 = (0..8)
            .map(|i| (0..8).map(|j| t[i] * m[i][j] * t[j]).sum::<f64>())
            .sum();
        assert!((mx - e.mass_kg()).abs() < 1e-12 * e.mass_kg());
        for i in 0..8 {
            for j in 0..8 {
                assert!((k[i][j] - k[j][i]).abs() <= 1e-9 * k[0][0]);
                assert!((m[i][j] - m[j][i]).abs() <= 1e-15);
                assert!((g[i][j] + g[j][i]).abs() <= 1e-18);
            }
        }
    }

    /// Cowper's κ for a solid circle: 6(1+ν)/(7+6ν) = 0.886 at ν = 0.3.
    #[test]
    fn cowper_shear_coefficient_of_a_solid_circle() {
        let k = steel_element(0.1, 0.05).shear_coefficient();
        assert!((k - 6.0 * 1.3 / 8.8).abs() < 1e-12);
    }
}
