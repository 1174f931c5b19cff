//! Live calibration (issue 12): the measured 1X vectors and mean positions of the node's 1X
//! blocks ([`super::OneXBlock`]), gathered by speed, fitted to the twin's viscosity and unbalance
//! by [`crate::calibrate`] (the replay's `--calibrate` fit: the viscosity scale first, from the
//! mean journal positions by the films' static equilibrium, then the unbalance from the 1X
//! vectors by the twin's influence coefficients at that viscosity), and the estimate applied to
//! the running twin on request and taken back ([`super::Driver::apply_calibration`]).
//!
//! A block is used for the unbalance only when it is referenced to the keyphasor (the phase is
//! then from the mark), and for either only when its 1X and mean leave at most
//! `MAX_WINDOW_RESIDUAL_SHARE` (30 %) of its 1X semi-major axis (no whirl), the replay's rule.
//! Mean positions count only at stations whose probes keep the DC gap (DC-coupled raw probes, or
//! displacement pairs): an AC-coupled station's mean is the twin's own. Blocks within
//! [`SPEED_BIN_RPM`] share one vector (their phasors averaged), so the fit computes the influence
//! coefficients and the equilibria at a few speeds; past [`MAX_SPEED_BINS`] × 4 bins, one of the
//! two nearest in speed goes (the older), so a long run-up keeps its whole speed range.

use super::OneXBlock;
use crate::calibrate::MAX_WINDOW_RESIDUAL_SHARE;
use crate::calibrate::{
    estimate_viscosity_and_unbalance, CalibrationError, MeanPosition, NonlinearRefinement,
    OneXVector, UnbalanceEstimate, ViscosityEstimate, DEFAULT_CORRECTION_RADIUS_M,
};
use crate::rotor::Rotor;

/// Width of a speed bin (rpm): 10 rpm, 0.1 % of the rated speed. The influence coefficients
/// move by less than that between two speeds of one bin below the first critical's
/// neighbourhood (they vary on the scale of the modes' half-power bandwidth).
pub const SPEED_BIN_RPM: f64 = 10.0;

/// Speed bins kept, × 4 (spread over the speeds seen: [`LiveCalibration::add`]).
pub const MAX_SPEED_BINS: usize = 16;

/// The sums of one station at one speed bin.
#[derive(Debug, Clone, Copy, Default)]
struct Bin {
    station: usize,
    bin: i64,
    speed_sum: f64,
    /// keyphasor-referenced 1X phasors (x, y axes), summed, and their count
    phasors: [[f64; 2]; 2],
    locked: usize,
    /// mean positions summed, and their count (DC stations only)
    mean: [f64; 2],
    means: usize,
    blocks: usize,
    updated: u64,
}

/// The averaged measurements a fit takes: 1X vectors and mean positions.
pub type MeasuredSet = (Vec<OneXVector>, Vec<MeanPosition>);

/// The measurements gathered for the live calibration.
#[derive(Debug, Clone, Default)]
pub struct LiveCalibration {
    bins: Vec<Bin>,
    updates: u64,
    /// Blocks left out for non-synchronous motion.
    pub whirl_blocks: u64,
}

/// What one fit gives: the viscosity (None with the reason) and the unbalance at it.
#[derive(Debug, Clone, PartialEq)]
pub struct LiveEstimate {
    /// The viscosity estimate, or why there is none.
    pub viscosity: Result<ViscosityEstimate, String>,
    /// The unbalance estimate, or why there is none.
    pub unbalance: Result<UnbalanceEstimate, String>,
    /// 1X vectors and mean positions used.
    pub vectors: usize,
    /// Mean positions used.
    pub positions: usize,
}

impl LiveCalibration {
    /// Adds a block of station `dc` (its probes keep the DC gap) to its speed bin.
    pub fn add(&mut self, b: &OneXBlock, dc: bool) {
        if b.residual_rms_m > MAX_WINDOW_RESIDUAL_SHARE * b.measured_major_m() {
            self.whirl_blocks += 1;
            return;
        }
        let rpm = crate::units::rad_s_to_rpm(b.speed_rad_s);
        let bin = (rpm / SPEED_BIN_RPM).round() as i64;
        self.updates += 1;
        let i = match self
            .bins
            .iter()
            .position(|e| e.station == b.station && e.bin == bin)
        {
            Some(i) => i,
            None => {
                if self.bins.len() >= MAX_SPEED_BINS * 4 {
                    self.drop_densest();
                }
                self.bins.push(Bin {
                    station: b.station,
                    bin,
                    ..Bin::default()
                });
                self.bins.len() - 1
            }
        };
        let e = &mut self.bins[i];
        e.updated = self.updates;
        e.blocks += 1;
        e.speed_sum += b.speed_rad_s;
        if b.null_reason.is_none() {
            for a in 0..2 {
                let p = b.measured_xy[a].phasor_m();
                e.phasors[a] = [e.phasors[a][0] + p[0], e.phasors[a][1] + p[1]];
            }
            e.locked += 1;
        }
        if dc {
            e.mean = [
                e.mean[0] + b.measured_mean_m[0],
                e.mean[1] + b.measured_mean_m[1],
            ];
            e.means += 1;
        }
    }

    /// Drops the bin whose removal leaves the smallest hole in its station's speeds (the span
    /// between its neighbours below and above; the lowest and highest are kept; the older of a
    /// tie), so that the bins kept spread evenly over every speed seen. Dropping the least
    /// recently updated (before session 15) kept only the last 310 rpm of a 100 rpm/s run-up
    /// 3,000 → 6,000 rpm, 5,680–5,990, and the unbalance read 324 g·mm at 233° for the plant's
    /// 280 at 243° (+16 %, −10°: tests/runup_unbalance.rs).
    fn drop_densest(&mut self) {
        let bins = &self.bins;
        let hole = |i: usize| {
            let e = &bins[i];
            let (mut below, mut above) = (None::<i64>, None::<i64>);
            for o in bins.iter().filter(|o| o.station == e.station) {
                if o.bin < e.bin {
                    below = Some(below.map_or(o.bin, |b| b.max(o.bin)));
                } else if o.bin > e.bin {
                    above = Some(above.map_or(o.bin, |a| a.min(o.bin)));
                }
            }
            match (below, above) {
                (Some(b), Some(a)) => a - b,
                _ => i64::MAX,
            }
        };
        if let Some(i) = (0..bins.len()).min_by_key(|&i| (hole(i), bins[i].updated)) {
            self.bins.swap_remove(i);
        }
    }

    /// The averaged measurements: keyphasor-referenced 1X vectors per station, axis and speed
    /// bin, and DC mean positions per station and speed bin.
    pub fn measurements(&self) -> MeasuredSet {
        let mut vectors = Vec::new();
        let mut positions = Vec::new();
        for e in &self.bins {
            let w = e.speed_sum / e.blocks as f64;
            if e.locked > 0 {
                for a in 0..2 {
                    let n = e.locked as f64;
                    let x = [e.phasors[a][0] / n, e.phasors[a][1] / n];
                    vectors.push(OneXVector::from_complex(e.station, a, w, x));
                }
            }
            if e.means > 0 {
                let n = e.means as f64;
                positions.push(MeanPosition {
                    station: e.station,
                    speed_rad_s: w,
                    position_m: [e.mean[0] / n, e.mean[1] / n],
                });
            }
        }
        (vectors, positions)
    }
}

/// The fit of `measured` (as [`LiveCalibration::measurements`] gives them) for the machine
/// `rotor` describes (at its file's viscosity): the viscosity scale from the mean positions
/// (when there are at least two), then the unbalance at that viscosity (at the file's when the
/// viscosity cannot be fitted), then the viscosity again under the journal orbits of that
/// unbalance and the unbalance at it (`calibrate::estimate_viscosity_and_unbalance`).
///
/// With `refine` (a nonlinear twin's: [`super::Driver::calibration_refinement`]) the unbalance is
/// refined on the nonlinear twin (`calibrate::refine_unbalance`), so that the twin that runs it
/// meets the measured 1X.
pub fn estimate(
    rotor: &Rotor,
    measured: &MeasuredSet,
    refine: Option<NonlinearRefinement>,
) -> LiveEstimate {
    let (vectors, positions) = measured;
    let mut reference = rotor.clone();
    // the scale is fitted against the machine file's viscosity (1.0 is always valid: the
    // result cannot be an error)
    let _ = reference.set_viscosity_scale(1.0);
    let text = |e: CalibrationError| e.to_string();
    let (viscosity, unbalance) = estimate_viscosity_and_unbalance(
        &reference,
        positions,
        vectors,
        DEFAULT_CORRECTION_RADIUS_M,
        refine,
    );
    LiveEstimate {
        viscosity: viscosity.map_err(text),
        unbalance: unbalance.map_err(text),
        vectors: vectors.len(),
        positions: positions.len(),
    }
}

impl LiveEstimate {
    /// The message of this estimate, stamped `ns`; `applied`: in force in the running twin.
    pub fn to_message(&self, ns: i64, applied: bool) -> crate::messages::CalibrationEstimate {
        let mut m = crate::messages::CalibrationEstimate {
            header: crate::session::header(ns, ""),
            vectors: self.vectors as u32,
            positions: self.positions as u32,
            applied,
            correction_radius: DEFAULT_CORRECTION_RADIUS_M,
            ..Default::default()
        };
        match &self.viscosity {
            Ok(v) => {
                m.viscosity_valid = true;
                m.viscosity_scale = v.scale;
                m.viscosity_scale_std = v.scale_std;
                m.viscosity = v.viscosity_pa_s;
                m.viscosity_residual = v.residual_rms_m;
                if let (Some(t), Some(s), Some(o)) =
                    (v.temperature_c, v.temperature_std_k, v.temperature_offset_k)
                {
                    m.temperature_valid = true;
                    m.oil_temperature = t + crate::film::ZERO_CELSIUS_K;
                    m.oil_temperature_std = s;
                    m.temperature_offset = o;
                }
            }
            Err(why) => m.viscosity_reason = why.clone(),
        }
        match &self.unbalance {
            Ok(u) => {
                m.unbalance_valid = true;
                for p in &u.planes {
                    m.unbalance_nodes.push(p.node as u32);
                    m.unbalance_magnitudes.push(p.magnitude_g_mm * 1e-6);
                    m.unbalance_phases.push(p.phase_deg.to_radians());
                    m.correction_masses.push(p.correction.mass_g * 1e-3);
                    m.correction_angles
                        .push(p.correction.angle_deg.to_radians());
                }
                // one field in the message: the first plane's (each mass is at its plane's own)
                if let Some(p) = u.planes.first() {
                    m.correction_radius = p.correction.radius_m;
                }
                m.unbalance_residual = u.residual_rms_m;
                m.unbalance_relative_residual = u.relative_residual;
                m.condition_number = u.condition_number;
            }
            Err(why) => m.unbalance_reason = why.clone(),
        }
        m
    }

    /// What applying it sets: the unbalance per plane (m·e kg·m, phase rad), if fitted, and
    /// the viscosity scale, if fitted.
    pub fn values(&self) -> (Option<Vec<(f64, f64)>>, Option<f64>) {
        let unbalance = self.unbalance.as_ref().ok().map(|u| {
            u.planes
                .iter()
                .map(|p| {
                    let me = (p.magnitude_g_mm * 1e-6).min(super::inputs::MAX_UNBALANCE_KG_M);
                    (me, p.phase_deg.to_radians())
                })
                .collect()
        });
        (unbalance, self.viscosity.as_ref().ok().map(|v| v.scale))
    }
}

/// The calibration in force in the running twin (set by [`super::Driver::apply_calibration`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Applied {
    /// m·e (kg·m) and phase (rad) per plane, if applied.
    pub unbalance: Option<Vec<(f64, f64)>>,
    /// Viscosity scale, if applied.
    pub viscosity_scale: Option<f64>,
}

impl super::Driver {
    /// How an estimate for this twin is refined: on its own film evaluation and steps a
    /// revolution when it is nonlinear (or prehistory); None for a linear twin, whose best
    /// unbalance is the linear fit itself.
    pub fn calibration_refinement(&self) -> Option<NonlinearRefinement> {
        let twin = &self.settings.twin;
        if twin.coupling == crate::dynamics::Coupling::Linear {
            return None;
        }
        let rev_s = std::f64::consts::TAU / self.rotor.rated_speed_rad_s;
        Some(NonlinearRefinement {
            film: twin.film,
            steps_per_rev: (rev_s / twin.time_step_s).round().max(1.0) as usize,
        })
    }

    /// Applies a calibration to the running twin and to every later start: the unbalance per
    /// plane (m·e kg·m, phase rad from the mark) and the viscosity scale (over the machine
    /// file's). The viscosity is kept as a correction on the law, s_fit / s_law(T), T the oil
    /// temperature in force when it is applied (the one it was fitted at; none: the machine
    /// file's), so a later oil temperature T' gives s_law(T') × that correction; the oil
    /// temperature's own scale is kept for [`Self::revert_calibration`]. Returns what changed,
    /// for the log.
    ///
    /// A nonlinear twin that is running takes the new values over [`CALIBRATION_BLEND_S`]
    /// (a `Blend`), not at once: a step of the viscosity or the unbalance is a kick to the
    /// rotor, whose free whirl near the stability threshold decays slowly and seeds the whip
    /// in a later run-up hundreds of rpm early (README, "The onset after a live calibration").
    pub fn apply_calibration(&mut self, applied: Applied) -> Result<String, String> {
        let from = self.blend_start();
        let said = self.apply_at_once(applied)?;
        if let (Some(mut b), Some(s)) = (from, self.session.as_mut()) {
            // back to where the twin was; the steps move it on (`Self::blend_step`)
            b.set(s.twin_mut(), 0.0)
                .map_err(|e| format!("calibration blend: {e}"))?;
            self.blend = Some(b);
        }
        Ok(said)
    }

    /// The twin's values before a calibration is applied, when it blends: a nonlinear twin
    /// running.
    fn blend_start(&self) -> Option<Blend> {
        let s = self.session.as_ref()?;
        if self.settings.twin.coupling == crate::dynamics::Coupling::Linear {
            return None;
        }
        let twin = s.twin();
        let scales: Vec<f64> = (0..).map_while(|i| twin.film_viscosity_scale(i)).collect();
        let unbalance: Vec<[f64; 2]> = (0..self.unbalance.len())
            .map(|p| phasor(self.unbalance_in_force(p)))
            .collect();
        Some(Blend {
            start_ns: s.stamp_ns(),
            from_scales: scales.clone(),
            to_scales: scales.clone(),
            now_scales: scales,
            from_unbalance: unbalance.clone(),
            to_unbalance: unbalance,
        })
    }

    /// Moves the running twin's viscosity and unbalance along a calibration's blend to the
    /// values in force, before the step from the twin's time; ends the blend at its end.
    pub(super) fn blend_step(&mut self) {
        let Some(b) = self.blend.as_mut() else {
            return;
        };
        let Some(s) = self.session.as_mut() else {
            self.blend = None;
            return;
        };
        let f = (s.stamp_ns() - b.start_ns) as f64 * 1e-9 / CALIBRATION_BLEND_S;
        // values checked when applied or received: a blend of two valid ones is valid
        if b.set(s.twin_mut(), f.clamp(0.0, 1.0)).is_err() || f >= 1.0 {
            self.blend = None;
        }
    }

    /// The blend's targets: the values in force (a later oil temperature moves them).
    pub(super) fn blend_targets(&mut self) {
        let Some(mut b) = self.blend.take() else {
            return;
        };
        let films = self.rotor.bearings.iter().filter_map(|x| match &x.model {
            crate::rotor::BearingModel::Film(f) => Some(f.viscosity_scale),
            _ => None,
        });
        for (t, s) in b.to_scales.iter_mut().zip(films) {
            *t = s;
        }
        for p in 0..b.to_unbalance.len() {
            b.to_unbalance[p] = phasor(self.unbalance_in_force(p));
        }
        self.blend = Some(b);
    }

    fn apply_at_once(&mut self, applied: Applied) -> Result<String, String> {
        let mut said = Vec::new();
        if let Some(s) = applied.viscosity_scale {
            self.set_scale(s)?;
            let k = s / self.oil_scale.unwrap_or(1.0);
            self.viscosity_correction = Some(k);
            said.push(format!("viscosity × {s:.4} (× {k:.4} on the law)"));
        }
        if let Some(u) = &applied.unbalance {
            for (p, &(me, phase)) in u.iter().enumerate() {
                super::check_unbalance(p as u32, me, phase, self.limits.planes)?;
                if let Some(s) = self.session.as_mut() {
                    s.twin_mut()
                        .set_unbalance(p, me, phase)
                        .map_err(|e| format!("unbalance: {e}"))?;
                }
                said.push(format!(
                    "plane {p}: {:.1} g·mm at {:.1}°",
                    me * 1e6,
                    phase.to_degrees().rem_euclid(360.0)
                ));
            }
        }
        self.calibration = Some(applied);
        Ok(said.join(", "))
    }

    /// Takes a calibration back: the unbalance received (else the machine file's) and the oil
    /// temperature's viscosity scale (else the machine file's).
    pub fn revert_calibration(&mut self) -> Result<(), String> {
        self.blend = None;
        let Some(applied) = self.calibration.take() else {
            return Ok(());
        };
        if applied.viscosity_scale.is_some() {
            self.viscosity_correction = None;
            self.set_scale(self.oil_scale.unwrap_or(1.0))?;
        }
        if applied.unbalance.is_some() {
            for p in 0..self.unbalance.len() {
                let (me, phase) = self.unbalance_in_force(p);
                if let Some(s) = self.session.as_mut() {
                    s.twin_mut()
                        .set_unbalance(p, me, phase)
                        .map_err(|e| format!("unbalance: {e}"))?;
                }
            }
        }
        Ok(())
    }

    /// The calibration in force, if any.
    pub fn calibration(&self) -> Option<&Applied> {
        self.calibration.as_ref()
    }

    /// The unbalance of plane `p` a (re)started twin gets: the calibration's when applied, else
    /// the last received, else the machine file's (m·e kg·m, phase rad).
    pub(super) fn unbalance_in_force(&self, p: usize) -> (f64, f64) {
        if let Some(u) = self.calibration.as_ref().and_then(|c| c.unbalance.as_ref()) {
            if let Some(&v) = u.get(p) {
                return v;
            }
        }
        match self.unbalance[p] {
            Some(u) => (u.magnitude_kg_m, u.phase_rad),
            None => {
                let u = &self.rotor.unbalance[p];
                (u.magnitude_kg_m, u.phase_rad)
            }
        }
    }

    /// Sets the viscosity scale of the machine and of the running twin.
    fn set_scale(&mut self, s: f64) -> Result<(), String> {
        self.rotor
            .set_viscosity_scale(s)
            .map_err(|e| format!("viscosity scale: {e}"))?;
        if let Some(t) = self.session.as_mut() {
            t.twin_mut()
                .set_viscosity_scale(s)
                .map_err(|e| format!("viscosity scale: {e}"))?;
        }
        Ok(())
    }
}

/// How long a running nonlinear twin takes to move to an applied calibration (s): 1 s, some
/// 130 revolutions at 8,000 rpm. Measured (`tests/onset_study.rs` `onset_switch`: the
/// machine file's twin on 60 × 10 at 8,000 rpm taking the live estimate of
/// `tests/live_calibration.rs`, then the 400 rpm/s run-up): the run-up onset at once 8,442 rpm,
/// blended over 8, 24, 48 and 100 revolutions 9,057, 9,099, 9,183 and 9,266 rpm, with the
/// estimate's values from the start (no kick) 9,268 rpm.
pub const CALIBRATION_BLEND_S: f64 = 1.0;

/// A calibration being blended into the running twin: the viscosity scale of each film and the
/// unbalance phasor of each plane (m·e (cos φ, sin φ), kg·m) move linearly in time from where
/// they were to the values in force. Allocates nothing once made.
#[derive(Debug, Clone)]
pub(super) struct Blend {
    start_ns: i64,
    from_scales: Vec<f64>,
    to_scales: Vec<f64>,
    now_scales: Vec<f64>,
    from_unbalance: Vec<[f64; 2]>,
    to_unbalance: Vec<[f64; 2]>,
}

impl Blend {
    /// Turns both ends' unbalance phasors by `delta_rad` (a keyphasor relock restates every
    /// heavy spot from the new mark).
    pub(super) fn turn_unbalance(&mut self, delta_rad: f64) {
        let (s, c) = delta_rad.sin_cos();
        for u in self.from_unbalance.iter_mut().chain(&mut self.to_unbalance) {
            *u = [u[0] * c - u[1] * s, u[0] * s + u[1] * c];
        }
    }

    /// Sets `twin` to the values at fraction `f` of the way.
    fn set(&mut self, twin: &mut crate::dynamics::Twin, f: f64) -> Result<(), String> {
        for ((n, a), b) in self
            .now_scales
            .iter_mut()
            .zip(&self.from_scales)
            .zip(&self.to_scales)
        {
            *n = a + f * (b - a);
        }
        if !self.now_scales.is_empty() {
            twin.set_viscosity_scales(&self.now_scales)
                .map_err(|e| e.to_string())?;
        }
        for (p, (a, b)) in self
            .from_unbalance
            .iter()
            .zip(&self.to_unbalance)
            .enumerate()
        {
            let (x, y) = (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]));
            twin.set_unbalance(p, x.hypot(y), y.atan2(x))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }
}

/// m·e (cos φ, sin φ) of (m·e, φ).
fn phasor((me, phase): (f64, f64)) -> [f64; 2] {
    [me * phase.cos(), me * phase.sin()]
}
