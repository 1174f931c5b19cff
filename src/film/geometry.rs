//! Bearing geometry, lubricant and the film grid.

use super::error::{positive, FilmError};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// An axial supply groove: a circumferential arc, running the full bearing length, where the film
/// pressure equals the supply pressure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AxialGroove {
    /// Centre of the groove, from `+x` in the direction of rotation (rad).
    pub center_rad: f64,
    /// Arc width of the groove (rad).
    pub width_rad: f64,
    /// Film pressure at the groove, gauge (Pa).
    pub supply_pressure_pa: f64,
}

impl AxialGroove {
    /// True if angle `theta_rad` (rad) lies inside the groove arc (edges included).
    pub fn contains(&self, theta_rad: f64) -> bool {
        let d = (theta_rad - self.center_rad + PI).rem_euclid(2.0 * PI) - PI;
        d.abs() <= 0.5 * self.width_rad + 1e-12
    }
}

/// Geometry of a plain cylindrical journal bearing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BearingGeometry {
    /// Journal diameter D (m).
    pub diameter_m: f64,
    /// Bearing length L (m).
    pub length_m: f64,
    /// Radial clearance c (m).
    pub radial_clearance_m: f64,
    /// Axial supply grooves (none for a plain 360° bearing).
    pub grooves: Vec<AxialGroove>,
}

impl BearingGeometry {
    /// A plain 360° bearing without grooves; checks every dimension.
    pub fn plain(
        diameter_m: f64,
        length_m: f64,
        radial_clearance_m: f64,
    ) -> Result<Self, FilmError> {
        let g = Self {
            diameter_m,
            length_m,
            radial_clearance_m,
            grooves: Vec::new(),
        };
        g.validate()?;
        Ok(g)
    }

    /// The two-axial-groove bearing of Lund & Thomsen (1978): two grooves of `width_rad` (rad) on
    /// the split line, 90° either side of the load direction `+x`, at `supply_pressure_pa` (Pa).
    pub fn two_axial_grooves(
        diameter_m: f64,
        length_m: f64,
        radial_clearance_m: f64,
        width_rad: f64,
        supply_pressure_pa: f64,
    ) -> Result<Self, FilmError> {
        let groove = |center_rad| AxialGroove {
            center_rad,
            width_rad,
            supply_pressure_pa,
        };
        let g = Self {
            diameter_m,
            length_m,
            radial_clearance_m,
            grooves: vec![groove(0.5 * PI), groove(1.5 * PI)],
        };
        g.validate()?;
        Ok(g)
    }

    /// Journal radius R (m).
    pub fn radius_m(&self) -> f64 {
        0.5 * self.diameter_m
    }

    /// Length-to-diameter ratio L/D.
    pub fn slenderness(&self) -> f64 {
        self.length_m / self.diameter_m
    }

    /// Checks every dimension: positive, finite, clearance far below the radius.
    pub fn validate(&self) -> Result<(), FilmError> {
        positive("bearing diameter (m)", self.diameter_m)?;
        positive("bearing length (m)", self.length_m)?;
        positive("radial clearance (m)", self.radial_clearance_m)?;
        if self.radial_clearance_m > 0.05 * self.radius_m() {
            return Err(FilmError::InvalidParameter {
                name: "radial clearance (m)",
                value: self.radial_clearance_m,
                rule: "must be below 5 % of the journal radius for a thin-film (Reynolds) model",
            });
        }
        if self.length_m > 10.0 * self.diameter_m {
            return Err(FilmError::InvalidParameter {
                name: "bearing length (m)",
                value: self.length_m,
                rule: "must not exceed 10 diameters",
            });
        }
        for g in &self.grooves {
            if !g.center_rad.is_finite() {
                return Err(FilmError::InvalidParameter {
                    name: "groove centre angle (rad)",
                    value: g.center_rad,
                    rule: "must be finite",
                });
            }
            if !(g.width_rad.is_finite() && g.width_rad > 0.0 && g.width_rad < PI) {
                return Err(FilmError::InvalidParameter {
                    name: "groove arc width (rad)",
                    value: g.width_rad,
                    rule: "must be greater than zero and less than π",
                });
            }
            if !(g.supply_pressure_pa.is_finite() && g.supply_pressure_pa >= 0.0) {
                return Err(FilmError::InvalidParameter {
                    name: "groove supply pressure (Pa)",
                    value: g.supply_pressure_pa,
                    rule: "must be finite and not negative (gauge)",
                });
            }
        }
        Ok(())
    }
}

/// An isoviscous lubricant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lubricant {
    /// Density ρ (kg/m³).
    pub density_kg_m3: f64,
    /// Dynamic viscosity µ (Pa·s).
    pub viscosity_pa_s: f64,
}

impl Lubricant {
    /// A lubricant; checks both properties.
    pub fn new(density_kg_m3: f64, viscosity_pa_s: f64) -> Result<Self, FilmError> {
        positive("lubricant density (kg/m³)", density_kg_m3)?;
        positive("lubricant viscosity (Pa·s)", viscosity_pa_s)?;
        Ok(Self {
            density_kg_m3,
            viscosity_pa_s,
        })
    }

    /// Film Reynolds number Re = ρ ω R c / µ (dimensionless); laminar theory holds well below ~1,000.
    pub fn film_reynolds_number(&self, speed_rad_s: f64, radius_m: f64, clearance_m: f64) -> f64 {
        self.density_kg_m3 * speed_rad_s.abs() * radius_m * clearance_m / self.viscosity_pa_s
    }
}

/// Finite-volume grid of the film over one half of the bearing (the aligned journal makes the
/// film symmetric about the mid-plane).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct FilmGrid {
    /// Nodes around the circumference (periodic).
    pub n_theta: usize,
    /// Intervals from the mid-plane to the bearing edge (nodes with unknown pressure: the
    /// mid-plane and the `n_z − 1` nodes between it and the edge).
    pub n_z: usize,
}

impl FilmGrid {
    /// Default grid: 60 × 10 on the half bearing.
    pub const DEFAULT: FilmGrid = FilmGrid {
        n_theta: 60,
        n_z: 10,
    };

    /// A grid; rejects sizes too small to resolve the film or too large to be sensible.
    pub fn new(n_theta: usize, n_z: usize) -> Result<Self, FilmError> {
        if !(12..=2048).contains(&n_theta) {
            return Err(FilmError::InvalidParameter {
                name: "grid nodes around the circumference",
                value: n_theta as f64,
                rule: "must be between 12 and 2048",
            });
        }
        if !(2..=64).contains(&n_z) {
            return Err(FilmError::InvalidParameter {
                name: "grid intervals over the half length",
                value: n_z as f64,
                rule: "must be between 2 and 64",
            });
        }
        Ok(Self { n_theta, n_z })
    }

    /// Parses `NTHxNZ`, e.g. `60x10`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (a, b) = text
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("grid '{text}' must be written NTHxNZ, e.g. 60x10"))?;
        let n_theta: usize = a
            .trim()
            .parse()
            .map_err(|_| format!("grid '{text}': '{a}' is not a whole number"))?;
        let n_z: usize = b
            .trim()
            .parse()
            .map_err(|_| format!("grid '{text}': '{b}' is not a whole number"))?;
        Self::new(n_theta, n_z).map_err(|e| format!("grid '{text}': {e}"))
    }
}

impl Default for FilmGrid {
    fn default() -> Self {
        Self::DEFAULT
    }
}
