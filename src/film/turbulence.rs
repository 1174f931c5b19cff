//! The turbulent film (issue 18): Ng–Pan / Elrod linearised turbulence with the Taylor–Dowson
//! fits of the flow factors.
//!
//! Above the laminar range the film's mean flow obeys the Reynolds equation with the laminar
//! 1/12 replaced by flow factors that depend on the local Reynolds number Re_h = ρωRh/µ (Ng & Pan,
//! ASLE Trans. 8 (1965) 1; Elrod & Ng, J. Lubr. Technol. 89 (1967) 346); the Couette flow ωRh/2
//! is unchanged in the linearised theory:
//!
//!   ∂/∂x (h³/(k_x µ) ∂p/∂x) + ∂/∂z (h³/(k_z µ) ∂p/∂z) = (ωR/2) ∂h/∂x + ∂h/∂t          (eq. T1)
//!
//! with the fits of Taylor & Dowson (J. Lubr. Technol. 96 (1974), their fits to Ng–Pan) to the Ng–Pan factors
//!   k_x = 12 + 0.0136 Re_h^0.90,   k_z = 12 + 0.0043 Re_h^0.96                        (eq. T2)
//! and the Couette shear stress τ = (µωR/h)(1 + 0.0012 Re_h^0.94) (same source)          (eq. T3).
//! In the finite solver's Π form (p = 6µ(R/c)² Π) each conductance H³ becomes
//! H³ · 12/k(Re·H), Re = ρωRc/µ the film's mean Reynolds number.
//!
//! `auto` is laminar below Taylor's vortex onset Re_T = 41.3 √(R/c) and fully turbulent above
//! 1.5 Re_T, with the factors' excess over laminar (k − 12 and the shear's excess) weighted by a
//! cubic smoothstep of the mean Re in between (continuous, with a continuous slope).

use serde::{Deserialize, Serialize};

/// The flow regime of a film bearing (machine file `flow`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum FlowRegime {
    /// The laminar Reynolds equation (seed eq. 2), the default.
    #[default]
    Laminar,
    /// Ng–Pan / Elrod turbulence at every Reynolds number (eq. T1–T3).
    Turbulent,
    /// Laminar below Taylor's onset 41.3 √(R/c), turbulent above 1.5 × it, blended between.
    Auto,
}

/// The film's flow factors at one speed: the weight of the turbulent excess and the mean
/// Reynolds number.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowFactors {
    /// ρωRc/µ (dimensionless).
    reynolds: f64,
    /// Weight of the turbulent excess over laminar, 0 … 1.
    weight: f64,
}

impl FlowFactors {
    /// The factors of `regime` for a film of mean Reynolds number `reynolds` = ρωRc/µ and
    /// clearance ratio `r_over_c`.
    pub fn new(regime: FlowRegime, reynolds: f64, r_over_c: f64) -> Self {
        let reynolds = reynolds.abs();
        let weight = match regime {
            FlowRegime::Laminar => 0.0,
            FlowRegime::Turbulent => 1.0,
            FlowRegime::Auto => {
                let onset = taylor_onset(r_over_c);
                let s = ((reynolds - onset) / (0.5 * onset)).clamp(0.0, 1.0);
                s * s * (3.0 - 2.0 * s)
            }
        };
        Self { reynolds, weight }
    }

    /// Whether the film is laminar at this speed (no factor differs from the laminar one).
    pub fn is_laminar(&self) -> bool {
        self.weight == 0.0 || self.reynolds == 0.0
    }

    /// (G_x, dG_x/dH, G_z, dG_z/dH) at dimensionless film thickness `h`: the circumferential and
    /// axial conductances H³·12/k (laminar: H³, 3H²) and their slopes.
    #[inline]
    pub fn conductances(&self, h: f64) -> [f64; 4] {
        let h2 = h * h;
        if self.is_laminar() {
            return [h2 * h, 3.0 * h2, h2 * h, 3.0 * h2];
        }
        let re_h = self.reynolds * h;
        let g = |a: f64, b: f64| {
            // k = 12 + w a (Re H)^b, dk/dH = w a b Re^b H^(b−1)
            let t = self.weight * a * re_h.powf(b);
            let k = 12.0 + t;
            let dk = t * b / h;
            let gc = 12.0 * h2 * h / k;
            (gc, 12.0 * (3.0 * h2 / k - h2 * h * dk / (k * k)))
        };
        let (gx, dgx) = g(0.0136, 0.90);
        let (gz, dgz) = g(0.0043, 0.96);
        [gx, dgx, gz, dgz]
    }

    /// The Couette shear factor 1 + 0.0012 Re_h^0.94 (eq. T3) at thickness `h` (1: laminar).
    #[inline]
    pub fn couette_shear(&self, h: f64) -> f64 {
        if self.is_laminar() {
            1.0
        } else {
            1.0 + self.weight * 0.0012 * (self.reynolds * h).powf(0.94)
        }
    }
}

/// Taylor's vortex onset in the film Reynolds number ρωRc/µ: 41.3 √(R/c).
pub fn taylor_onset(r_over_c: f64) -> f64 {
    41.3 * r_over_c.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slopes_are_the_derivatives_of_the_conductances() {
        let f = FlowFactors::new(FlowRegime::Turbulent, 1270.0, 750.0);
        for h in [0.3, 1.0, 1.7] {
            let d = 1e-6;
            let (p, m, c) = (
                f.conductances(h + d),
                f.conductances(h - d),
                f.conductances(h),
            );
            for (g, dg) in [(0, 1), (2, 3)] {
                let fd = (p[g] - m[g]) / (2.0 * d);
                assert!((fd / c[dg] - 1.0).abs() < 1e-7, "h {h}: {fd} vs {}", c[dg]);
            }
        }
    }

    #[test]
    fn auto_is_laminar_below_the_onset_and_turbulent_above() {
        // seed bearing: R/c = 750, onset 41.3·√750 = 1,131
        let onset = taylor_onset(750.0);
        assert!((onset - 1131.0).abs() < 1.0);
        assert!(FlowFactors::new(FlowRegime::Auto, 0.99 * onset, 750.0).is_laminar());
        let hi = FlowFactors::new(FlowRegime::Auto, 1.5 * onset, 750.0);
        let t = FlowFactors::new(FlowRegime::Turbulent, 1.5 * onset, 750.0);
        assert_eq!(hi.conductances(0.8), t.conductances(0.8));
        // k_x at Re_h 1,000: 12 + 0.0136·1000^0.9 = 12 + 6.82 (Taylor–Dowson fit)
        let k = 12.0 / FlowFactors::new(FlowRegime::Turbulent, 1000.0, 750.0).conductances(1.0)[0];
        assert!(
            (k - (12.0 + 0.0136 * 1000f64.powf(0.9))).abs() < 1e-12,
            "{k}"
        );
    }
}
