//! The shape of an orbit at one order, free of its phase (issue 16): the ellipse a vibration
//! analyst reads off a filtered orbit plot — semi-major and semi-minor axes, inclination of the
//! major axis, direction of precession — and a phase-free distance between two such ellipses.
//!
//! The motion at order r is z(ψ) = x + iy = F e^{irψ} + B e^{−irψ}, a forward circle of complex
//! radius F and a backward one B (the full spectrum's two lines): with X_x, X_y the phasors of
//! x and y (x = Re X_x e^{irψ}), F = (X_x + i X_y)/2 and B = (X̄_x + i X̄_y)/2. The ellipse has
//! semi-major axis |F| + |B|, semi-minor ||F| − |B||, its major axis inclined at
//! (arg F + arg B)/2 (mod 180°) from +x towards +y, and precesses forward (with the rotation)
//! when |F| > |B|. A shift of the phase reference or of time, ψ → ψ + δ, turns F by +rδ and B
//! by −rδ: the sum of their arguments, so the ellipse, does not change.
//!
//! The shape distance of two ellipses is their RMS distance minimised over such a shift,
//! D² = min_δ mean_ψ |z₁(ψ + δ) − z₂(ψ)|² = |F₁|² + |B₁|² + |F₂|² + |B₂|² − 2 |F₁F̄₂ + B̄₁B₂|
//! (the mean square is |F₁e^{iδ} − F₂|² + |B₁e^{−iδ} − B₂|², whose δ-dependent part is
//! −2 Re(e^{iδ}(F₁F̄₂ + B̄₁B₂))): zero for a time-shifted copy, √2 × the radius for a forward and
//! a backward circle of one radius, however the two are phased.

use crate::signals::OneXVector;
use serde::Serialize;

/// Direction of precession of an orbit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Precession {
    /// With the rotation (|F| ≥ |B|).
    #[default]
    Forward,
    /// Against the rotation.
    Backward,
}

/// The ellipse of an orbit's component at one order.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct OrbitEllipse {
    /// The order (frequency / running frequency).
    pub order: f64,
    /// Semi-major axis (m).
    pub semi_major_m: f64,
    /// Semi-minor axis (m, ≥ 0; 0 for a line).
    pub semi_minor_m: f64,
    /// Inclination of the major axis from +x towards +y (degrees, [0, 180)); meaningless for a
    /// circle (semi-minor = semi-major).
    pub inclination_deg: f64,
    /// Forward (with the rotation) or backward.
    pub precession: Precession,
    /// The forward circle's complex radius F (m, re and im; not serialized).
    #[serde(skip)]
    forward_m: [f64; 2],
    /// The backward circle's complex radius B (m).
    #[serde(skip)]
    backward_m: [f64; 2],
}

impl OrbitEllipse {
    /// The ellipse at `order` of the motion whose x and y components there are the vectors
    /// `x` and `y` (x = Re X_x e^{i·order·ψ}, [`OneXVector::phasor_m`]).
    pub fn from_vectors(order: f64, x: &OneXVector, y: &OneXVector) -> Self {
        let ([xr, xi], [yr, yi]) = (x.phasor_m(), y.phasor_m());
        let f = [0.5 * (xr - yi), 0.5 * (xi + yr)];
        let b = [0.5 * (xr + yi), 0.5 * (yr - xi)];
        let (rf, rb) = (f[0].hypot(f[1]), b[0].hypot(b[1]));
        let tilt = 0.5 * (f[1].atan2(f[0]) + b[1].atan2(b[0]));
        Self {
            order,
            semi_major_m: rf + rb,
            semi_minor_m: (rf - rb).abs(),
            inclination_deg: tilt.to_degrees().rem_euclid(180.0) % 180.0,
            precession: if rf >= rb {
                Precession::Forward
            } else {
                Precession::Backward
            },
            forward_m: f,
            backward_m: b,
        }
    }

    /// The RMS distance between this ellipse and `other`, minimised over a shift of phase
    /// (time) between them (m): the module's D.
    pub fn shape_distance_m(&self, other: &OrbitEllipse) -> f64 {
        let ([f1r, f1i], [b1r, b1i]) = (self.forward_m, self.backward_m);
        let ([f2r, f2i], [b2r, b2i]) = (other.forward_m, other.backward_m);
        // C = F₁F̄₂ + B̄₁B₂
        let cr = f1r * f2r + f1i * f2i + b1r * b2r + b1i * b2i;
        let ci = f1i * f2r - f1r * f2i + b1r * b2i - b1i * b2r;
        let power = [f1r, f1i, b1r, b1i, f2r, f2i, b2r, b2i]
            .iter()
            .map(|v| v * v)
            .sum::<f64>();
        (power - 2.0 * cr.hypot(ci)).max(0.0).sqrt()
    }
}

/// Predicted against measured ellipse at one order.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ShapeDifference {
    /// Predicted minus measured semi-major axis (m).
    pub semi_major_m: f64,
    /// Predicted minus measured semi-minor axis (m).
    pub semi_minor_m: f64,
    /// Predicted minus measured inclination of the major axis, in (−90°, 90°] (degrees).
    pub inclination_deg: f64,
    /// Whether both precess the same way.
    pub same_precession: bool,
    /// RMS distance between the two ellipses minimised over a phase shift (m): the shape
    /// difference alone (zero for a time-shifted copy).
    pub shape_distance_m: f64,
}

impl ShapeDifference {
    /// Predicted `p` against measured `m`.
    pub fn of(p: &OrbitEllipse, m: &OrbitEllipse) -> Self {
        let d = (p.inclination_deg - m.inclination_deg).rem_euclid(180.0);
        Self {
            semi_major_m: p.semi_major_m - m.semi_major_m,
            semi_minor_m: p.semi_minor_m - m.semi_minor_m,
            inclination_deg: if d > 90.0 { d - 180.0 } else { d },
            same_precession: p.precession == m.precession,
            shape_distance_m: p.shape_distance_m(m),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signals::one_x_vector;
    use std::f64::consts::TAU;

    /// An ellipse of semi-axes a, b (b < 0: backward), its major axis at `tilt`, at phase `p0`,
    /// sampled over 8 revolutions (64 a revolution) and read back through the 1X fit of x and y.
    fn read(a: f64, b: f64, tilt: f64, p0: f64) -> OrbitEllipse {
        let n = 8 * 64;
        let pt = |i: usize| {
            let psi = TAU * i as f64 / 64.0;
            let (u, v) = (a * (psi + p0).cos(), b * (psi + p0).sin());
            let (s, c) = tilt.sin_cos();
            (psi, [u * c - v * s, u * s + v * c])
        };
        let x = one_x_vector((0..n).map(|i| (pt(i).0, pt(i).1[0])), n).unwrap();
        let y = one_x_vector((0..n).map(|i| (pt(i).0, pt(i).1[1])), n).unwrap();
        OrbitEllipse::from_vectors(1.0, &x, &y)
    }

    /// Known ellipses (3 µm × 1 µm inclined 30°, 130° and 175°, at arbitrary phases) read back
    /// within 1e-3 of their axes and 1e-3° of their inclination, precession forward; the same
    /// one traversed backward reads backward with the same axes and inclination.
    #[test]
    fn an_ellipse_reads_back_its_axes_inclination_and_precession() {
        for (tilt_deg, p0) in [(30.0f64, 0.0), (130.0, 1.1), (175.0, -2.3)] {
            for minor in [1e-6, -1e-6] {
                let e = read(3e-6, minor, tilt_deg.to_radians(), p0);
                assert!((e.semi_major_m / 3e-6 - 1.0).abs() < 1e-3, "{e:?}");
                assert!((e.semi_minor_m / 1e-6 - 1.0).abs() < 1e-3, "{e:?}");
                assert!((e.inclination_deg - tilt_deg).abs() < 1e-3, "{e:?}");
                let want = if minor > 0.0 {
                    Precession::Forward
                } else {
                    Precession::Backward
                };
                assert_eq!(e.precession, want);
            }
        }
    }

    /// A forward and a backward circle of one radius r: equal axes, opposite precession, shape
    /// distance √2·r (the closed form above: |F₁|² + |B₂|² with C = 0) whatever their phases; a
    /// time-shifted copy of a 3 µm × 1 µm ellipse (a quarter turn later): distance 0 (to 1e-9
    /// of its size); the same ellipse turned by 90° in space: the axes agree, the inclination
    /// differs by 90°, and the distance is 2|B| = a − b = 2 µm (z → iz: C = i(|F|² − |B|²)).
    #[test]
    fn the_shape_distance_ignores_phase_and_sees_shape() {
        let r = 2e-6;
        for p0 in [0.0, 0.7, 2.0] {
            let f = read(r, r, 0.0, p0);
            let b = read(r, -r, 0.0, 0.3);
            assert_eq!(f.precession, Precession::Forward);
            assert_eq!(b.precession, Precession::Backward);
            let d = ShapeDifference::of(&f, &b);
            assert!(d.semi_major_m.abs() < 1e-12 && d.semi_minor_m.abs() < 1e-12);
            assert!(!d.same_precession);
            assert!(
                (d.shape_distance_m / (2f64.sqrt() * r) - 1.0).abs() < 1e-9,
                "{d:?}"
            );
        }
        let e = read(3e-6, 1e-6, 0.4, 0.0);
        let shifted = read(3e-6, 1e-6, 0.4, TAU / 4.0);
        assert!(e.shape_distance_m(&shifted) < 1e-9 * 3e-6);
        let d = ShapeDifference::of(&e, &shifted);
        assert!(d.inclination_deg.abs() < 1e-6 && d.same_precession, "{d:?}");
        let turned = read(3e-6, 1e-6, 0.4 + TAU / 4.0, 0.0);
        let d = ShapeDifference::of(&turned, &e);
        assert!((d.inclination_deg.abs() - 90.0).abs() < 1e-6, "{d:?}");
        let want = 3e-6 - 1e-6;
        assert!((d.shape_distance_m / want - 1.0).abs() < 1e-9, "{d:?}");
    }
}
