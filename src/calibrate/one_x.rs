//! The mean position and the 1X vector of a probe station over windows of whole revolutions:
//! per axis, the least-squares fit a(θ) = m + b cos θ + c sin θ (X = b − i c, the convention of
//! [`super::OneXVector`]), with the RMS of what the fit leaves (noise, non-synchronous motion).

use super::linalg::solve_spd;
use super::{MeanPosition, OneXVector};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// One measured sample of a probe station with the shaft angle at its time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AngleSample {
    /// Shaft angle from the reference mark (rad); wrapped or not.
    pub angle_rad: f64,
    /// Shaft speed (rad/s).
    pub speed_rad_s: f64,
    /// Displacement `[x, y]` in the machine frame (m).
    pub displacement_m: [f64; 2],
}

/// The fit over one window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WindowFit {
    /// Mean speed over the window (rad/s).
    pub speed_rad_s: f64,
    /// Mean displacement `[x, y]` (m).
    pub mean_m: [f64; 2],
    /// Complex 1X amplitude per axis, `[[re, im] of X, [re, im] of Y]` (m).
    pub one_x_m: [[f64; 2]; 2],
    /// RMS of the samples less the fit, both axes (m).
    pub residual_rms_m: f64,
    /// Samples in the window.
    pub samples: usize,
}

impl WindowFit {
    /// The window's 1X vectors of `station` (x, then y).
    pub fn one_x(&self, station: usize) -> [OneXVector; 2] {
        [0, 1].map(|a| OneXVector::from_complex(station, a, self.speed_rad_s, self.one_x_m[a]))
    }

    /// The window's mean position at `station`.
    pub fn mean_position(&self, station: usize) -> MeanPosition {
        MeanPosition {
            station,
            speed_rad_s: self.speed_rad_s,
            position_m: self.mean_m,
        }
    }

    /// The 1X semi-major axis |X + iY|/2 + |X − iY|/2 (m).
    pub fn one_x_major_m(&self) -> f64 {
        let [x, y] = self.one_x_m;
        let f = ((x[0] - y[1]).powi(2) + (x[1] + y[0]).powi(2)).sqrt() / 2.0;
        let b = ((x[0] + y[1]).powi(2) + (x[1] - y[0]).powi(2)).sqrt() / 2.0;
        f + b
    }
}

/// Fits consecutive windows of `revolutions` whole revolutions of shaft angle (at least 8
/// samples a window) over `samples`, in time order. Angles are unwrapped (consecutive samples
/// less than half a revolution apart).
pub fn fit_windows(samples: &[AngleSample], revolutions: f64) -> Vec<WindowFit> {
    let mut fits = WindowFits::new(revolutions);
    for s in samples {
        fits.push(*s);
    }
    fits.finish()
}

/// A window that gathers more samples than this without completing its revolutions (a shaft
/// all but stopped) is dropped unfitted: the memory of a fit is bounded by it whatever the length
/// of the data (2^20 samples of 40 bytes: 40 MB).
pub const MAX_WINDOW_SAMPLES: usize = 1 << 20;

/// [`fit_windows`] as the samples arrive: only the window being gathered is held, so memory
/// does not grow with the length of the data; the fits are the same, bit for bit.
#[derive(Debug, Clone)]
pub struct WindowFits {
    span: f64,
    /// the unwrapped angle of the last sample, and its raw angle
    theta: f64,
    previous_angle_rad: Option<f64>,
    window: Vec<AngleSample>,
    window_theta: Vec<f64>,
    fits: Vec<WindowFit>,
    /// windows dropped for holding over [`MAX_WINDOW_SAMPLES`]
    pub overlong_windows: usize,
}

impl WindowFits {
    /// Windows of `revolutions` whole revolutions (at least 1).
    pub fn new(revolutions: f64) -> Self {
        Self {
            span: revolutions.max(1.0) * TAU,
            theta: 0.0,
            previous_angle_rad: None,
            window: Vec::new(),
            window_theta: Vec::new(),
            fits: Vec::new(),
            overlong_windows: 0,
        }
    }

    /// The next sample in time order; a window completes (and is fitted) when this sample is a
    /// whole window's angle past the window's first.
    pub fn push(&mut self, s: AngleSample) {
        self.theta = match self.previous_angle_rad {
            // the step wrapped to (−π, π], added as one term (the batch fit's rounding)
            Some(prev) => self.theta + ((s.angle_rad - prev + PI).rem_euclid(TAU) - PI),
            None => s.angle_rad,
        };
        self.previous_angle_rad = Some(s.angle_rad);
        let complete = self
            .window_theta
            .first()
            .is_some_and(|&t0| self.theta - t0 >= self.span);
        if complete {
            if let Some(f) = fit(&self.window, &self.window_theta) {
                self.fits.push(f);
            }
        }
        if complete || self.window.len() >= MAX_WINDOW_SAMPLES {
            self.overlong_windows += usize::from(!complete);
            self.window.clear();
            self.window_theta.clear();
        }
        self.window.push(s);
        self.window_theta.push(self.theta);
    }

    /// The windows fitted so far.
    pub fn fits(&self) -> &[WindowFit] {
        &self.fits
    }

    /// The fitted windows (a window not complete at the end is not fitted).
    pub fn finish(self) -> Vec<WindowFit> {
        self.fits
    }
}

/// The fit over one window (None with fewer than 8 samples or a singular fit).
fn fit(samples: &[AngleSample], theta: &[f64]) -> Option<WindowFit> {
    if samples.len() < 8 {
        return None;
    }
    let mut ata = [0.0; 9];
    let mut atb = [[0.0; 3]; 2];
    for (s, &t) in samples.iter().zip(theta) {
        let r = [1.0, t.cos(), t.sin()];
        for i in 0..3 {
            for j in 0..3 {
                ata[3 * i + j] += r[i] * r[j];
            }
            for a in 0..2 {
                atb[a][i] += r[i] * s.displacement_m[a];
            }
        }
    }
    let cx = solve_spd(&ata, &atb[0])?;
    let cy = solve_spd(&ata, &atb[1])?;
    let mut sq = 0.0;
    for (s, &t) in samples.iter().zip(theta) {
        for (a, c) in [&cx, &cy].iter().enumerate() {
            let e = s.displacement_m[a] - (c[0] + c[1] * t.cos() + c[2] * t.sin());
            sq += e * e;
        }
    }
    let n = samples.len() as f64;
    Some(WindowFit {
        speed_rad_s: samples.iter().map(|s| s.speed_rad_s).sum::<f64>() / n,
        mean_m: [cx[0], cy[0]],
        one_x_m: [[cx[1], -cx[2]], [cy[1], -cy[2]]],
        residual_rms_m: (sq / (2.0 * n)).sqrt(),
        samples: samples.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constructed signal x = 3 µm cos(θ − 40°) + 1 µm, y = 2 µm cos(θ − 130°) − 5 µm gives
    /// those amplitudes, lags and means (to round-off).
    #[test]
    fn a_known_signal_gives_its_lag_amplitude_and_mean() {
        let samples: Vec<AngleSample> = (0..640)
            .map(|k| {
                let th = k as f64 * TAU / 32.0;
                AngleSample {
                    angle_rad: th.rem_euclid(TAU),
                    speed_rad_s: 900.0,
                    displacement_m: [
                        3e-6 * (th - 40f64.to_radians()).cos() + 1e-6,
                        2e-6 * (th - 130f64.to_radians()).cos() - 5e-6,
                    ],
                }
            })
            .collect();
        let w = fit_windows(&samples, 4.0);
        assert_eq!(w.len(), 4);
        let [x, y] = w[0].one_x(0);
        assert!((x.amplitude_m - 3e-6).abs() < 1e-15 && (x.phase_lag_deg - 40.0).abs() < 1e-9);
        assert!((y.amplitude_m - 2e-6).abs() < 1e-15 && (y.phase_lag_deg - 130.0).abs() < 1e-9);
        assert!((w[0].mean_m[0] - 1e-6).abs() < 1e-15 && (w[0].mean_m[1] + 5e-6).abs() < 1e-15);
        assert!(w[0].residual_rms_m < 1e-15);
    }
}
