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
    /// Mid-plane fluid fraction φ of each bearing, one row a step over the last two
    /// revolutions ([`FLUID_FRACTION_POINTS`] around the bearing): with mass-conserving
    /// cavitation only (empty otherwise: a Reynolds film is full wherever it carries load).
    pub fluid_fraction_maps: Vec<Vec<Vec<f64>>>,
    /// Where each bearing's mass-conserving plain film is fed (rad from `+x`, fixed through the
    /// run; None for other films).
    pub feed_angles_rad: Vec<Option<f64>>,
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
    /// With `oil_heating`: heat balances redone as the speed moved (the first, at the start,
    /// not counted); 0 without.
    pub heat_balances: usize,
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
        self.growth_from(n - take)
    }

    /// [`Self::growth_per_rev`] fitted over the revolutions from index `from` of the history to
    /// the end (a window chosen by the caller, e.g. where a kicked orbit is still linear).
    pub fn growth_from(&self, from: usize) -> f64 {
        let pts: Vec<(f64, f64)> = self.history[from.min(self.history.len())..]
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
    run_driven(rotor, spec, initial, &Drive::default())
}

/// An impulse on a shaft node: the force J/h over the one time step whose end first reaches
/// `time_s` (Newmark's trapezoidal rule integrates that force to exactly J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kick {
    /// When (s of model time).
    pub time_s: f64,
    /// Shaft node (from 0 at z = 0).
    pub node: usize,
    /// Impulse `[J_x, J_y]` (N·s).
    pub impulse_n_s: [f64; 2],
}

/// A speed history: (time (s), speed (rpm)) points, piecewise linear between them, constant
/// before the first and after the last.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedHistory {
    points: Vec<(f64, f64)>,
}

impl SpeedHistory {
    /// From points (t (s), speed (rpm)); refused unless there is at least one, the times are
    /// finite, from 0 and strictly increasing, and every speed finite and above zero.
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, TwinError> {
        let bad = |name, value, rule| Err(TwinError::InvalidInput { name, value, rule });
        if points.is_empty() {
            return bad("speed history points", 0.0, "must be at least one");
        }
        for (k, &(t, rpm)) in points.iter().enumerate() {
            if !(t.is_finite() && t >= 0.0) {
                return bad("speed history time (s)", t, "must be finite and at least 0");
            }
            if k > 0 && t <= points[k - 1].0 {
                return bad(
                    "speed history time (s)",
                    t,
                    "must increase from point to point",
                );
            }
            if !(rpm.is_finite() && rpm > 0.0) {
                return bad(
                    "speed history speed (rpm)",
                    rpm,
                    "must be finite and above zero",
                );
            }
        }
        Ok(Self { points })
    }

    /// A ramp from `from_rpm` to `to_rpm` at `rate_rpm_s` (rpm/s, above zero; the sign follows
    /// the direction), starting at t = 0.
    pub fn ramp(from_rpm: f64, to_rpm: f64, rate_rpm_s: f64) -> Result<Self, TwinError> {
        if !(rate_rpm_s.is_finite() && rate_rpm_s > 0.0) {
            return Err(TwinError::InvalidInput {
                name: "ramp rate (rpm/s)",
                value: rate_rpm_s,
                rule: "must be finite and above zero",
            });
        }
        let duration = (to_rpm - from_rpm).abs() / rate_rpm_s;
        if duration > 0.0 {
            Self::new(vec![(0.0, from_rpm), (duration, to_rpm)])
        } else {
            Self::new(vec![(0.0, from_rpm)])
        }
    }

    /// Speed (rpm) and its rate (rpm/s) at time `t_s`.
    pub fn at(&self, t_s: f64) -> (f64, f64) {
        let p = &self.points;
        let k = p.partition_point(|&(t, _)| t <= t_s);
        if k == 0 {
            return (p[0].1, 0.0);
        }
        if k == p.len() {
            return (p[k - 1].1, 0.0);
        }
        let ((t0, s0), (t1, s1)) = (p[k - 1], p[k]);
        let rate = (s1 - s0) / (t1 - t0);
        (s0 + rate * (t_s - t0), rate)
    }

    /// Time of the last point (s).
    pub fn duration_s(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.0)
    }

    /// Lowest and highest speed (rpm).
    pub fn range_rpm(&self) -> (f64, f64) {
        self.points
            .iter()
            .fold((f64::INFINITY, 0.0), |(lo, hi), p| {
                (lo.min(p.1), hi.max(p.1))
            })
    }
}

/// What drives a run besides its constant speed: a speed history (then `speed_rpm` of the spec
/// is ignored and the run lasts the history and `revolutions` more at its last speed) and kicks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Drive {
    /// Speed against time; None: the spec's constant speed.
    pub speed: Option<SpeedHistory>,
    /// Impulses, applied in time order.
    pub kicks: Vec<Kick>,
}

/// Sets the external forces of the kicks for the step from `t_s` to `t_s + h_s`: J/h on its node
/// for each kick not yet applied whose time is at most the step's end (a kick before the start
/// goes into the first step), zero on the nodes of the others; `applied[k]` marks kick k done.
/// True if one is applied in this step.
pub fn apply_kicks(
    twin: &mut Twin,
    kicks: &[Kick],
    applied: &mut [bool],
    t_s: f64,
    h_s: f64,
) -> Result<bool, TwinError> {
    let end = t_s + h_s * (1.0 + 1e-9);
    let due = |k: usize| !applied[k] && kicks[k].time_s <= end;
    let mut any = false;
    for (k, kick) in kicks.iter().enumerate() {
        // the sum of the due kicks on this node (several may share one)
        let mut f = [0.0, 0.0];
        for (m, other) in kicks.iter().enumerate() {
            if other.node == kick.node && due(m) {
                f = [
                    f[0] + other.impulse_n_s[0] / h_s,
                    f[1] + other.impulse_n_s[1] / h_s,
                ];
            }
        }
        twin.set_external_force(kick.node, f)?;
        any |= due(k);
    }
    for (done, kick) in applied.iter_mut().zip(kicks) {
        *done |= kick.time_s <= end;
    }
    Ok(any)
}

/// With `oil_heating` in the machine file, the films' heat balance as the live twin's driver
/// keeps it (`driver::oil`): taken at the start, redone when the speed has moved past
/// [`crate::driver::HEAT_BALANCE_SPEED_STEP`], its viscosity scales set on the twin. Used by
/// the offline runs (`simulate`, `sweep`) and the bench, so that they heat as the node does.
pub struct HeatFollower {
    rotor: Rotor,
    film: FilmEvaluation,
    at_speed_rad_s: f64,
    scales: Vec<f64>,
    /// each film's viscosity field (thermal-film heating; empty where uniform)
    fields: Vec<Vec<f64>>,
    /// Balances after the first, their slowest and summed times (µs).
    balances: usize,
    slowest_us: f64,
    total_us: f64,
}

impl HeatFollower {
    /// The first balance, at `speed_rad_s`, left on `rotor` (None without `oil_heating`).
    /// Err says why it failed.
    pub fn of(
        rotor: &mut Rotor,
        film: FilmEvaluation,
        speed_rad_s: f64,
    ) -> Result<Option<Self>, TwinError> {
        if !rotor.has_oil_heating() {
            return Ok(None);
        }
        let mut me = Self {
            rotor: rotor.clone(),
            film,
            at_speed_rad_s: speed_rad_s,
            scales: vec![1.0; rotor.film_bearing_count()],
            fields: Vec::new(),
            balances: 0,
            slowest_us: 0.0,
            total_us: 0.0,
        };
        me.balance(speed_rad_s)?;
        (me.balances, me.slowest_us, me.total_us) = (0, 0.0, 0.0);
        *rotor = me.rotor.clone();
        Ok(Some(me))
    }

    fn balance(&mut self, speed_rad_s: f64) -> Result<(), TwinError> {
        let t = Instant::now();
        (self.rotor)
            .heat_films_with(None, speed_rad_s, 1.0, self.film)
            .map_err(|e| TwinError::Setup(format!("oil_heating: {e}")))?;
        let us = t.elapsed().as_secs_f64() * 1e6;
        self.slowest_us = self.slowest_us.max(us);
        self.total_us += us;
        self.balances += 1;
        self.at_speed_rad_s = speed_rad_s;
        for (s, f) in self.scales.iter_mut().zip(self.rotor.film_bearings()) {
            *s = f.viscosity_scale;
        }
        self.fields = self.rotor.film_viscosity_fields();
        Ok(())
    }

    /// Redoes the balance if the speed has moved past the driver's step, and sets the scales
    /// on `twin`.
    pub fn follow(&mut self, twin: &mut Twin, speed_rad_s: f64) -> Result<(), TwinError> {
        if !crate::driver::speed_moved_past_balance(self.at_speed_rad_s, speed_rad_s) {
            return Ok(());
        }
        self.balance(speed_rad_s)?;
        twin.set_viscosity_scales(&self.scales)?;
        twin.set_viscosity_fields(&self.fields)
    }

    /// Balances after the first.
    pub fn balances(&self) -> usize {
        self.balances
    }

    /// The slowest of them (µs).
    pub fn slowest_us(&self) -> f64 {
        self.slowest_us
    }

    /// Their mean (µs).
    pub fn mean_us(&self) -> f64 {
        self.total_us / self.balances.max(1) as f64
    }
}

/// Points around the bearing of [`TransientResult::fluid_fraction_maps`] (4° apart; each the
/// nearest grid column's φ).
pub const FLUID_FRACTION_POINTS: usize = 90;

/// The mid-plane fluid fraction of each bearing over the last steps of a run: a ring of rows
/// (one a step), allocated once.
struct FractionRing {
    rows: Vec<std::collections::VecDeque<Vec<f64>>>,
    capacity: usize,
}

impl FractionRing {
    /// For `twin`'s bearings when one of `rotor`'s films is mass-conserving, keeping
    /// `capacity` steps (None otherwise).
    fn of(rotor: &Rotor, twin: &Twin, capacity: usize) -> Option<Self> {
        let mass_conserving = rotor.bearings.iter().any(|b| {
            matches!(&b.model, BearingModel::Film(f)
                if f.cavitation == crate::film::Cavitation::MassConserving)
        });
        mass_conserving.then(|| Self {
            rows: vec![
                std::collections::VecDeque::with_capacity(capacity);
                twin.output().bearings.len()
            ],
            capacity,
        })
    }

    fn record(&mut self, twin: &Twin) {
        for (b, ring) in self.rows.iter_mut().enumerate() {
            let mut row = if ring.len() == self.capacity {
                ring.pop_front().unwrap_or_default()
            } else {
                vec![0.0; FLUID_FRACTION_POINTS]
            };
            twin.midplane_fluid_fraction(b, &mut row);
            ring.push_back(row);
        }
    }

    /// The rows of the last two revolutions of each of `n` bearings, a step turning the shaft
    /// by `step_angle_rad` at the end (empty rows without a ring).
    fn last_two_revolutions(
        ring: Option<Self>,
        n: usize,
        step_angle_rad: f64,
    ) -> Vec<Vec<Vec<f64>>> {
        let Some(me) = ring else {
            return vec![Vec::new(); n];
        };
        let steps = (4.0 * std::f64::consts::PI / step_angle_rad).round() as usize;
        (me.rows.into_iter())
            .map(|ring| {
                let skip = ring.len().saturating_sub(steps);
                ring.into_iter().skip(skip).collect()
            })
            .collect()
    }
}

/// Runs `spec` on `rotor` under `drive` (speed history, kicks), from `initial` if given.
pub fn run_driven(
    rotor: &Rotor,
    spec: &TransientSpec,
    initial: Option<&StateVectors>,
    drive: &Drive,
) -> Result<TransientResult, TwinError> {
    check_spec(spec)?;
    let mut rotor = with_grid(rotor, spec.grid);
    let (lo_rpm, hi_rpm) = drive
        .speed
        .as_ref()
        .map_or((spec.speed_rpm, spec.speed_rpm), SpeedHistory::range_rpm);
    let speed_at = |t: f64| match &drive.speed {
        Some(h) => h.at(t),
        None => (spec.speed_rpm, 0.0),
    };
    let mut heat = HeatFollower::of(&mut rotor, spec.film, rpm_to_rad_s(speed_at(0.0).0))?;
    let mut twin = start_twin(&rotor, spec, (hi_rpm, speed_at(0.0).0), initial)?;
    let h = twin.config().time_step_s;
    let per_rev = (spec.steps_per_rev as f64 * hi_rpm / lo_rpm).ceil() as usize + 2;
    let mut monitor = Monitor::new(&twin, per_rev, ClassifierSettings::default());
    let mut fractions = FractionRing::of(&rotor, &twin, 2 * per_rev);
    let mut history = Vec::with_capacity(spec.revolutions);
    let mut applied = vec![false; drive.kicks.len()];
    let duration = drive.speed.as_ref().map_or(0.0, SpeedHistory::duration_s);
    let mut revs_at_end = (duration <= 0.0).then_some(0);
    let (mut steps, mut iterations, mut max_substeps, mut fallbacks) = (0, 0, 1, 0);
    let start = Instant::now();
    while revs_at_end.is_none_or(|r| history.len() < r + spec.revolutions) {
        let t = twin.time_s();
        let (rpm, rate) = speed_at(t + h);
        let input = StepInput {
            speed_rad_s: rpm_to_rad_s(rpm),
            accel_rad_s2: rpm_to_rad_s(rate),
        };
        apply_kicks(&mut twin, &drive.kicks, &mut applied, t, h)?;
        if let Some(f) = heat.as_mut() {
            f.follow(&mut twin, input.speed_rad_s)?;
        }
        let out = twin.step(&input)?;
        steps += 1;
        iterations += out.newton_iterations;
        max_substeps = max_substeps.max(out.substeps);
        fallbacks += out.prehistory_fallbacks;
        if let Some(f) = fractions.as_mut() {
            f.record(&twin);
        }
        if let Some(r) = monitor.record(&twin) {
            history.push(r.clone());
        }
        if revs_at_end.is_none() && twin.time_s() >= duration {
            revs_at_end = Some(history.len());
        }
    }
    let wall_time_s = start.elapsed().as_secs_f64();
    let n = twin.output().bearings.len();
    let (q, qd, qdd) = twin.state_vectors();
    let final_state = (q.to_vec(), qd.to_vec(), qdd.to_vec());
    let final_omega = rpm_to_rad_s(speed_at(twin.time_s()).0);
    let fluid_fraction_maps = FractionRing::last_two_revolutions(fractions, n, final_omega * h);
    Ok(TransientResult {
        report: monitor.report().clone(),
        history,
        bearing_names: twin.bearing_names().map(str::to_string).collect(),
        clearances_m: twin.bearing_clearances_m(),
        orbits: (0..n).map(|b| monitor.recent_orbit(b, 2)).collect(),
        pressure_maps: (0..n).map(|b| monitor.recent_pressure(b, 2)).collect(),
        fluid_fraction_maps,
        feed_angles_rad: (0..n).map(|b| twin.feed_angle_rad(b)).collect(),
        spectra: (0..n).map(|b| monitor.full_spectrum(b)).collect(),
        simulated_s: twin.time_s(),
        wall_time_s,
        steps,
        newton_iterations: iterations,
        max_substeps,
        prehistory_fallbacks: fallbacks,
        heat_balances: heat.as_ref().map_or(0, HeatFollower::balances),
        final_state,
    })
}

/// The twin of a run of `spec` on `rotor` whose highest speed is `hi_rpm`, at `start_rpm`,
/// from `initial` if given: the time step gives `steps_per_rev` steps a revolution at the
/// highest speed (more below).
fn start_twin(
    rotor: &Rotor,
    spec: &TransientSpec,
    (hi_rpm, start_rpm): (f64, f64),
    initial: Option<&StateVectors>,
) -> Result<Twin, TwinError> {
    let config = TwinConfig {
        film: spec.film,
        ..TwinConfig::with_steps_per_rev(spec.coupling, rpm_to_rad_s(hi_rpm), spec.steps_per_rev)
    };
    let mut twin = Twin::new(rotor, config, rpm_to_rad_s(start_rpm))?;
    if let Some((q, qd, qdd)) = initial {
        twin.set_state_vectors(q, qd, qdd)?;
    }
    Ok(twin)
}

/// The spec's own checks (speed, revolutions, steps a revolution).
fn check_spec(spec: &TransientSpec) -> Result<(), TwinError> {
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
    Ok(())
}
