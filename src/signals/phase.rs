//! The 1X vector of one probe axis, referenced to the keyphasor: amplitude and **phase lag** in
//! the API 670 / Bently convention, the degrees of rotation from the keyphasor event (shaft angle
//! 0) to the next positive peak of the 1X-filtered signal, 0–360°, lag positive.
//!
//! A signal s(ψ) = A cos(ψ − φ) against the keyphasor-referenced shaft angle ψ peaks at ψ = φ
//! after each event: φ is the lag. Its 1X phasor X = A e^{−iφ} (s = Re X e^{iψ}) is found by the
//! discrete Fourier transform at order 1 with a Hann window, X = 2 Σ w (s − s̄) e^{−iψ} / Σ w (the
//! Hann window suppresses the leakage of sub-synchronous components, e.g. a 0.5X whip, into 1X;
//! over whole revolutions it leaves an exact 1X component unchanged).

use serde::Serialize;
use std::f64::consts::TAU;

/// A 1X vector of one probe axis.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct OneXVector {
    /// Amplitude (zero to peak) of the 1X component along the axis (m).
    pub amplitude_m: f64,
    /// Phase lag from the keyphasor event to the next positive peak (degrees, [0, 360)).
    pub phase_lag_deg: f64,
}

impl OneXVector {
    /// The phasor X = A e^{−iφ} as (re, im) (m): s(ψ) = Re X e^{iψ}. Influence coefficients and
    /// runout subtraction work on these.
    pub fn phasor_m(&self) -> [f64; 2] {
        let phi = self.phase_lag_deg.to_radians();
        [self.amplitude_m * phi.cos(), -self.amplitude_m * phi.sin()]
    }

    /// The vector of phasor (re, im) (m).
    pub fn from_phasor_m(p: [f64; 2]) -> Self {
        Self {
            amplitude_m: p[0].hypot(p[1]),
            phase_lag_deg: (-p[1].atan2(p[0])).to_degrees().rem_euclid(360.0) % 360.0,
        }
    }

    /// This vector minus `other` (e.g. the slow-roll runout), as phasors.
    pub fn minus(&self, other: &OneXVector) -> Self {
        let (a, b) = (self.phasor_m(), other.phasor_m());
        Self::from_phasor_m([a[0] - b[0], a[1] - b[1]])
    }
}

/// The 1X vector of `n` samples (ψ rad: shaft angle from the keyphasor, increasing; s: the
/// signal), or None with fewer than 8 samples or less than one revolution. Allocates nothing.
pub fn one_x_vector(
    samples: impl Iterator<Item = (f64, f64)> + Clone,
    n: usize,
) -> Option<OneXVector> {
    if n < 8 {
        return None;
    }
    let (first, last) = samples
        .clone()
        .fold((None, 0.0), |(f, _), (psi, _)| (f.or(Some(psi)), psi));
    if last - first? < TAU * (1.0 - 1e-9) {
        return None;
    }
    let mean = samples.clone().map(|(_, s)| s).sum::<f64>() / n as f64;
    let (mut re, mut im, mut wsum) = (0.0, 0.0, 0.0);
    for (i, (psi, s)) in samples.enumerate().take(n) {
        let w = 0.5 - 0.5 * (TAU * (i as f64 + 0.5) / n as f64).cos();
        let (sn, cs) = psi.sin_cos();
        re += w * (s - mean) * cs;
        im -= w * (s - mean) * sn;
        wsum += w;
    }
    (wsum > 0.0).then(|| OneXVector::from_phasor_m([2.0 * re / wsum, 2.0 * im / wsum]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The known signal of the issue: s = A cos(Ωt − φ) with the keyphasor at t = 0, so ψ = Ωt;
    /// the positive peak comes φ after the event. 32 revolutions, 16 samples a revolution
    /// (the sample bag's rate), offset by a mean and a 0.47X component of twice the amplitude:
    /// the lag within 0.5° (the tolerance) and the amplitude within 1 %.
    #[test]
    fn a_known_lag_is_read_back() {
        for phi_deg in [0.0, 37.0, 90.0, 181.5, 300.0, 359.0] {
            let phi = f64::to_radians(phi_deg);
            let (a, n) = (3e-6, 32 * 16);
            let psi = |i: usize| TAU * i as f64 / 16.0;
            let s =
                |i: usize| 10e-6 + a * (psi(i) - phi).cos() + 2.0 * a * (0.47 * psi(i) + 0.3).cos();
            let v = one_x_vector((0..n).map(|i| (psi(i), s(i))), n).unwrap();
            let d = (v.phase_lag_deg - phi_deg + 180.0).rem_euclid(360.0) - 180.0;
            assert!(d.abs() < 0.5, "φ {phi_deg}°: read {}°", v.phase_lag_deg);
            assert!((v.amplitude_m / a - 1.0).abs() < 0.01, "{v:?}");
            assert!((0.0..360.0).contains(&v.phase_lag_deg));
        }
    }

    #[test]
    fn phasors_subtract_as_vectors() {
        let a = OneXVector {
            amplitude_m: 5e-6,
            phase_lag_deg: 30.0,
        };
        let back = OneXVector::from_phasor_m(a.phasor_m());
        assert!(
            (back.amplitude_m - 5e-6).abs() < 1e-18 && (back.phase_lag_deg - 30.0).abs() < 1e-9
        );
        // 5 µm at 30° minus itself is nothing; minus 5 µm at 210° is 10 µm at 30°
        assert!(a.minus(&a).amplitude_m < 1e-18);
        let opposite = OneXVector {
            amplitude_m: 5e-6,
            phase_lag_deg: 210.0,
        };
        let d = a.minus(&opposite);
        assert!((d.amplitude_m - 10e-6).abs() < 1e-15 && (d.phase_lag_deg - 30.0).abs() < 1e-9);
        assert!(one_x_vector((0..4).map(|i| (i as f64, 0.0)), 4).is_none());
    }
}
