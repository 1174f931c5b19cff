//! The amplitude–speed characteristic: one nonlinear transient at each speed of a range, run in
//! parallel, and the onset of instability read from them (the seed's Fig. 12 kind of result).
//! I/O-free: the CLI's `sweep` writes and prints what this computes.

use crate::dynamics::TwinError;
use crate::monitor::RotorState;
use crate::rotor::Rotor;
use crate::transient::{run_transient, TransientResult, TransientSpec};
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// One speed of a sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SweepPoint {
    /// Speed (rpm).
    pub speed_rpm: f64,
    /// The monitor's classification of the last revolutions.
    pub state: RotorState,
    /// The monitor's growth rate of the sub-synchronous amplitude (1/rev: the slope of its
    /// logarithm per revolution), the largest of the bearings'; None before the monitor has
    /// enough revolutions to tell (the same figure as `simulate`'s `subsync_growth_per_rev`).
    pub subsync_growth_per_rev: Option<f64>,
    /// Largest eccentricity ratio of any bearing.
    pub max_eccentricity_ratio: f64,
    /// Largest sub-synchronous frequency ratio of any bearing (× running speed).
    pub subsync_ratio: f64,
    /// Per bearing: [amplitude (m, half peak-to-peak), sub-synchronous amplitude (m), p_max (Pa)].
    pub bearings: Vec<[f64; 3]>,
}

/// One bearing's curves over the sweep.
#[derive(Debug, Clone)]
pub struct BearingSeries {
    /// Bearing name.
    pub name: String,
    /// Orbit amplitude at each speed (m, half peak-to-peak).
    pub amplitude_m: Vec<f64>,
    /// Sub-synchronous amplitude at each speed (m).
    pub subsync_amplitude_m: Vec<f64>,
}

/// The result of a sweep.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// Every speed, ascending.
    pub points: Vec<SweepPoint>,
    /// Per bearing, the curves to plot.
    pub series: Vec<BearingSeries>,
}

/// A transient of the sweep that failed.
#[derive(Debug, thiserror::Error)]
#[error("transient at {speed_rpm:.0} rpm: {cause}")]
pub struct SweepError {
    /// Its speed (rpm).
    pub speed_rpm: f64,
    /// Why.
    pub cause: TwinError,
}

impl Sweep {
    /// The onset: the first speed the monitor classifies other than stable (rpm); None if
    /// stable over the range. The monitor's rule is the one rule (a growth above zero alone
    /// made an onset before, beside rows the monitor called stable).
    pub fn onset_speed_rpm(&self) -> Option<f64> {
        self.points
            .iter()
            .find(|p| p.state != RotorState::Stable)
            .map(|p| p.speed_rpm)
    }

    /// The speeds (rpm).
    pub fn speeds_rpm(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.speed_rpm).collect()
    }

    /// The sweep as CSV: one row per speed, three columns per bearing.
    pub fn csv(&self) -> String {
        let mut csv = String::from(
            "speed_rpm,state,subsync_growth_per_rev,max_eccentricity_ratio,subsync_ratio",
        );
        for s in &self.series {
            let name = &s.name;
            csv.push_str(&format!(
                ",{name}_amplitude_m,{name}_subsync_amplitude_m,{name}_max_pressure_pa"
            ));
        }
        csv.push('\n');
        for p in &self.points {
            csv.push_str(
                &format!(
                    "{},{:?},{},{},{}",
                    p.speed_rpm,
                    p.state,
                    p.subsync_growth_per_rev
                        .map_or(String::new(), |g| g.to_string()),
                    p.max_eccentricity_ratio,
                    p.subsync_ratio
                )
                .to_lowercase(),
            );
            for b in &p.bearings {
                csv.push_str(&format!(",{},{},{}", b[0], b[1], b[2]));
            }
            csv.push('\n');
        }
        csv
    }
}

/// Runs the transient `specs[k]` of `rotor` for every k on all cores, calling
/// `progress(done, total)` as each finishes, and collects the sweep (in the order of `specs`).
pub fn run_sweep(
    rotor: &Rotor,
    specs: &[TransientSpec],
    progress: impl Fn(usize, usize) + Sync,
) -> Result<Sweep, SweepError> {
    let count = specs.len();
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(count.max(1));
    let (next, done) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let results: Vec<Mutex<Option<Result<TransientResult, TwinError>>>> =
        (0..count).map(|_| Mutex::new(None)).collect();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= count {
                    break;
                }
                let r = run_transient(rotor, &specs[k]);
                *results[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(r);
                progress(done.fetch_add(1, Ordering::SeqCst) + 1, count);
            });
        }
    });
    let mut sweep = Sweep {
        points: Vec::with_capacity(count),
        series: Vec::new(),
    };
    for (slot, spec) in results.into_iter().zip(specs) {
        let fail = |cause| SweepError {
            speed_rpm: spec.speed_rpm,
            cause,
        };
        let r = slot
            .into_inner()
            .unwrap_or_else(|e| e.into_inner())
            .unwrap_or_else(|| Err(TwinError::Setup("not run".into())))
            .map_err(fail)?;
        sweep.add(spec.speed_rpm, &r);
    }
    Ok(sweep)
}

impl Sweep {
    /// Adds the point of transient `r` at `speed_rpm`.
    fn add(&mut self, speed_rpm: f64, r: &TransientResult) {
        if self.series.is_empty() {
            self.series = r
                .bearing_names
                .iter()
                .map(|n| BearingSeries {
                    name: n.clone(),
                    amplitude_m: Vec::new(),
                    subsync_amplitude_m: Vec::new(),
                })
                .collect();
        }
        let rep = &r.report;
        let amplitude =
            |b: &crate::monitor::BearingRevolution| 0.5 * b.orbit_pp_x_m.max(b.orbit_pp_y_m);
        for (s, b) in self.series.iter_mut().zip(&rep.bearings) {
            s.amplitude_m.push(amplitude(b));
            s.subsync_amplitude_m.push(b.subsync_amplitude_m);
        }
        let largest = |f: fn(&crate::monitor::BearingRevolution) -> f64| {
            rep.bearings.iter().map(f).fold(0.0, f64::max)
        };
        self.points.push(SweepPoint {
            speed_rpm,
            state: rep.state,
            subsync_growth_per_rev: rep
                .bearings
                .iter()
                .filter_map(|b| b.subsync_growth_per_rev)
                .reduce(f64::max),
            max_eccentricity_ratio: largest(|b| b.max_eccentricity_ratio),
            subsync_ratio: largest(|b| b.subsync_ratio),
            bearings: rep
                .bearings
                .iter()
                .map(|b| [amplitude(b), b.subsync_amplitude_m, b.max_pressure_pa])
                .collect(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{Coupling, FilmEvaluation};
    use crate::rotor::MachineDescription;

    /// The seed machine at 8,000 and 9,000 rpm (the seed's stable and whip speeds), 60
    /// revolutions each: points in the order asked for whatever the order the workers finish,
    /// 8,000 stable and decaying, the onset at 9,000 (linear threshold 8,471 rpm), one CSV row
    /// a speed with three columns a bearing.
    #[test]
    fn a_sweep_keeps_its_order_and_finds_the_onset() {
        let rotor = Rotor::from_description(&MachineDescription::builtin_default());
        let spec = |speed_rpm| TransientSpec {
            speed_rpm,
            revolutions: 60,
            coupling: Coupling::Nonlinear,
            steps_per_rev: 64,
            grid: None,
            film: FilmEvaluation::Table,
        };
        let calls = AtomicUsize::new(0);
        let sweep = run_sweep(&rotor, &[spec(9000.0), spec(8000.0)], |_, total| {
            assert_eq!(total, 2);
            calls.fetch_add(1, Ordering::SeqCst);
        })
        .unwrap();
        assert_eq!(calls.load(Ordering::SeqCst), 2);
        assert_eq!(sweep.speeds_rpm(), vec![9000.0, 8000.0]);
        assert_eq!(sweep.points[1].state, RotorState::Stable);
        let g = sweep.points[1]
            .subsync_growth_per_rev
            .expect("60 revolutions give a rate");
        assert!(g < 0.0, "{g}");
        assert_eq!(sweep.onset_speed_rpm(), Some(9000.0));
        let csv = sweep.csv();
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0].split(',').count(), 5 + 3 * 2);
        assert!(rows[2].starts_with("8000,stable,"), "{}", rows[2]);
    }
}
