//! Offline transient runs at a constant speed: drive the twin core and its monitor for a number
//! of revolutions and gather what `simulate`, `sweep`, the tests and the benchmark report.

use crate::dynamics::{Coupling, FilmEvaluation, StepInput, Twin, TwinConfig, TwinError};
use crate::film::FilmGrid;
use crate::monitor::{ClassifierSettings, Monitor, OrderComponent, RevolutionReport};
use crate::rotor::{BearingModel, Rotor};
use crate::units::rpm_to_rad_s;
use std::time::Instant;

/// What to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransientSpec {
    /// Constant speed (rpm).
    pub speed_rpm: f64,
    /// Revolutions to simulate.
    pub revolutions: usize,
    /// Bearing coupling.
    pub coupling: Coupling,
    /// Time steps per revolution.
    pub steps_per_rev: usize,
    /// Film grid for every finite film bearing, overriding the machine file.
    pub grid: Option<FilmGrid>,
    /// Film evaluation: direct (the reference) or tabulated.
    pub film: FilmEvaluation,
}

/// What a run gives.
#[derive(Debug, Clone)]
pub struct TransientResult {
    /// The last revolution's report.
    pub report: RevolutionReport,
    /// Per revolution: the worst state and the largest eccentricity ratio (for onset timing).
    pub history: Vec<RevolutionReport>,
    /// Film bearing names.
    pub bearing_names: Vec<String>,
    /// Their clearances (m).
    pub clearances_m: Vec<f64>,
    /// Orbit of each bearing over the last two revolutions (m).
    pub orbits: Vec<Vec<[f64; 2]>>,
    /// Mid-plane pressure profiles of each bearing over the last two revolutions (Pa).
    pub pressure_maps: Vec<Vec<Vec<f64>>>,
    /// Order spectrum of each bearing over the last 16 revolutions.
    pub spectra: Vec<Vec<OrderComponent>>,
    /// Simulated time (s).
    pub simulated_s: f64,
    /// Wall-clock time of the stepping (s).
    pub wall_time_s: f64,
    /// Steps taken.
    pub steps: usize,
    /// Newton iterations in all.
    pub newton_iterations: usize,
    /// Most substeps any step needed.
    pub max_substeps: usize,
    /// Prehistory: substeps that fell back to Newton.
    pub prehistory_fallbacks: usize,
    /// The state vectors at the end (q, q̇, q̈ on the twin's reduced DOFs).
    pub final_state: StateVectors,
}

/// Displacement, velocity and acceleration on the twin's reduced DOFs.
pub type StateVectors = (Vec<f64>, Vec<f64>, Vec<f64>);

impl TransientResult {
    /// Simulated time over wall time.
    pub fn real_time_factor(&self) -> f64 {
        self.simulated_s / self.wall_time_s.max(1e-12)
    }

    /// Growth rate of the non-synchronous motion (1/rev): the least-squares slope of
    /// ln(rev-to-rev orbit difference) over the last half of the run (at least 10 revolutions).
    /// Negative: the motion settles; positive: it grows (linearly unstable, or not yet at its
    /// limit cycle).
    pub fn growth_per_rev(&self) -> f64 {
        let n = self.history.len();
        let take = (n / 2).max(10).min(n);
        let pts: Vec<(f64, f64)> = self.history[n - take..]
            .iter()
            .filter(|r| r.rev_to_rev_orbit_diff > 0.0)
            .map(|r| (r.revolution as f64, r.rev_to_rev_orbit_diff.ln()))
            .collect();
        if pts.len() < 3 {
            return 0.0;
        }
        let m = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / m,
            pts.iter().map(|p| p.1).sum::<f64>() / m,
        );
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        if sxx > 0.0 {
            sxy / sxx
        } else {
            0.0
        }
    }
}

/// Applies a grid override to every finite film bearing of `rotor`.
pub fn with_grid(rotor: &Rotor, grid: Option<FilmGrid>) -> Rotor {
    let mut r = rotor.clone();
    if let Some(g) = grid {
        for b in &mut r.bearings {
            if let BearingModel::Film(f) = &mut b.model {
                f.grid = g;
            }
        }
    }
    r
}

/// Runs `spec` on `rotor` from its static equilibrium plus the linear synchronous orbit.
pub fn run_transient(rotor: &Rotor, spec: &TransientSpec) -> Result<TransientResult, TwinError> {
    run_transient_from(rotor, spec, None)
}

/// Runs `spec` on `rotor`, starting from `initial` state vectors if given (e.g. the end of an
/// earlier run of the same machine), else as [`run_transient`].
pub fn run_transient_from(
    rotor: &Rotor,
    spec: &TransientSpec,
    initial: Option<&StateVectors>,
) -> Result<TransientResult, TwinError> {
    if !(spec.speed_rpm.is_finite() && spec.speed_rpm > 0.0) {
        return Err(TwinError::InvalidInput {
            name: "speed (rpm)",
            value: spec.speed_rpm,
            rule: "must be finite and above zero",
        });
    }
    if !(2..=100_000).contains(&spec.revolutions) {
        return Err(TwinError::InvalidInput {
            name: "revolutions",
            value: spec.revolutions as f64,
            rule: "must be 2 to 100,000",
        });
    }
    if !(16..=4096).contains(&spec.steps_per_rev) {
        return Err(TwinError::InvalidInput {
            name: "steps per revolution",
            value: spec.steps_per_rev as f64,
            rule: "must be 16 to 4096",
        });
    }
    let rotor = with_grid(rotor, spec.grid);
    let omega = rpm_to_rad_s(spec.speed_rpm);
    let config = TwinConfig {
        film: spec.film,
        ..TwinConfig::with_steps_per_rev(spec.coupling, omega, spec.steps_per_rev)
    };
    let mut twin = Twin::new(&rotor, config, omega)?;
    if let Some((q, qd, qdd)) = initial {
        twin.set_state_vectors(q, qd, qdd)?;
    }
    let mut monitor = Monitor::new(&twin, spec.steps_per_rev + 2, ClassifierSettings::default());
    let mut history = Vec::with_capacity(spec.revolutions);
    let input = StepInput {
        speed_rad_s: omega,
        accel_rad_s2: 0.0,
    };
    let (mut steps, mut iterations, mut max_substeps, mut fallbacks) = (0, 0, 1, 0);
    let start = Instant::now();
    while history.len() < spec.revolutions {
        let out = twin.step(&input)?;
        steps += 1;
        iterations += out.newton_iterations;
        max_substeps = max_substeps.max(out.substeps);
        fallbacks += out.prehistory_fallbacks;
        if let Some(r) = monitor.record(&twin) {
            history.push(r.clone());
        }
    }
    let wall_time_s = start.elapsed().as_secs_f64();
    let n = twin.output().bearings.len();
    let (q, qd, qdd) = twin.state_vectors();
    let final_state = (q.to_vec(), qd.to_vec(), qdd.to_vec());
    Ok(TransientResult {
        report: monitor.report().clone(),
        history,
        bearing_names: twin.bearing_names().map(str::to_string).collect(),
        clearances_m: twin.bearing_clearances_m(),
        orbits: (0..n).map(|b| monitor.recent_orbit(b, 2)).collect(),
        pressure_maps: (0..n).map(|b| monitor.recent_pressure(b, 2)).collect(),
        spectra: (0..n).map(|b| monitor.full_spectrum(b)).collect(),
        simulated_s: twin.time_s(),
        wall_time_s,
        steps,
        newton_iterations: iterations,
        max_substeps,
        prehistory_fallbacks: fallbacks,
        final_state,
    })
}
