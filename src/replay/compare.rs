//! Predicted against measured orbits at one probe station, streamed: the samples are gathered
//! in blocks of [`BLOCK_REVS`] revolutions of the shaft (amplitude against speed, onset of
//! instability) and the last [`SUMMARY_REVS`] revolutions are kept for the summary. Both orbits
//! are sampled at the same instants, so they are aligned by shaft angle by construction; the
//! shaft angle is the twin's, integrated from the bag's speed (and locked to the keyphasor).
//!
//! The measured 1X vectors of a block are read against the plant's own angle, interpolated
//! between the bag's keyphasor events that bracket each sample's stamp, by the node's rule
//! ([`crate::signals::keyphasor_one_x`]): a finished block waits for the event after its last
//! sample. The twin's keyphasor-locked angle trails an accelerating shaft (by about a·T²), the
//! plant's does not. The predicted vectors stay on the twin's angle: the twin's unbalance turns
//! with that angle, so its response's lag against it is the model's prediction; read against
//! the plant's angle it would carry the lock's tracking error as well.

use super::orbit_shape::{OrbitEllipse, ShapeDifference};
use crate::driver::one_x::{NO_CLOSING_EVENT, NO_OPENING_EVENT};
use crate::monitor::spectrum::{
    one_x_component, order_spectrum, subsynchronous_peak, OrderComponent,
};
use crate::monitor::ClassifierSettings;
use crate::signals::{
    keyphasor_one_x, one_x_vector, KeyphasorEvents, OneXVector, PhaseReference, Unbracketed,
};
use serde::Serialize;
use std::collections::VecDeque;
use std::f64::consts::TAU;

/// Keeps items 0, 2, 4, … of `v` (in place, its capacity kept).
fn keep_every_other<T>(v: &mut Vec<T>) {
    let mut k = 0;
    v.retain(|_| {
        k += 1;
        k % 2 == 1
    });
}

/// Revolutions per block of the amplitude–speed series and of the onset detector.
pub const BLOCK_REVS: usize = 8;
/// Revolutions of the summary window at the end of the bag.
pub const SUMMARY_REVS: usize = 32;
/// Consecutive blocks over which a sub-synchronous component must persist or grow to be an
/// onset (24 revolutions: 0.16 s at 9,000 rpm).
pub const ONSET_BLOCKS: usize = 3;
/// Most blocks a station keeps for the report and plots (issue 17: memory bounded whatever the
/// bag's length). Beyond it every other kept block is dropped and only every `stride`-th block
/// is kept from then on (stride 2, 4, 8, …): at 9,000 rpm (18.75 blocks a second) the first
/// 54.6 s are kept whole, a 10-minute bag keeps every 16th block (704). The onset, transients
/// and the plant's whip are detected on every block as they come ([`OnsetDetector`]).
pub const MAX_KEPT_BLOCKS: usize = 1024;
/// Most transients kept per station and per orbit (measured, predicted); later ones are
/// counted in [`StationComparison::transients_dropped`].
pub const MAX_TRANSIENTS: usize = 64;

/// A run of blocks whose sub-synchronous component counted but decayed: a transient.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TransientSpan {
    /// Start of its first block, bag time (s).
    pub start_s: f64,
    /// End of its last block (s).
    pub end_s: f64,
    /// Its largest sub-synchronous semi-major axis (m).
    pub largest_subsync_m: f64,
}

/// The onset rule of [`StationComparison::onset`] over blocks as they come, holding only the
/// current run of counting blocks' last [`ONSET_BLOCKS`] (issue 17: the blocks themselves are
/// decimated). The first window of [`ONSET_BLOCKS`] consecutive counting blocks of one run,
/// each ≥ `least_ratio` × the one before, is the onset (its first block's end time and speed);
/// the counting blocks before it in its run, and every earlier run, are transients.
#[derive(Debug, Clone, Default)]
struct OnsetDetector {
    onset: Option<(f64, f64)>,
    transients: Vec<TransientSpan>,
    dropped: usize,
    run: Option<CountingRun>,
}

/// The counting run under way: its start, the blocks that left the window (their last end and
/// largest amplitude), and its last blocks `(amplitude m, end s, speed rpm)`.
#[derive(Debug, Clone)]
struct CountingRun {
    start_s: f64,
    before: Option<(f64, f64)>,
    window: VecDeque<(f64, f64, f64)>,
}

impl CountingRun {
    /// The run as a transient, whole.
    fn span(&self) -> Option<TransientSpan> {
        let last = self.window.back()?;
        let largest = self.window.iter().map(|w| w.0).fold(0.0, f64::max);
        Some(TransientSpan {
            start_s: self.start_s,
            end_s: last.1,
            largest_subsync_m: self.before.map_or(largest, |b| b.1.max(largest)),
        })
    }
}

impl OnsetDetector {
    /// One block (start, end s; speed rpm), its sub-synchronous amplitude when it counts.
    fn push(&mut self, start_s: f64, end_s: f64, speed_rpm: f64, amp: Option<f64>, least: f64) {
        if self.onset.is_some() {
            return;
        }
        let Some(a) = amp else {
            if let Some(span) = self.run.take().and_then(|r| r.span()) {
                self.note_transient(span);
            }
            return;
        };
        let run = self.run.get_or_insert_with(|| CountingRun {
            start_s,
            before: None,
            window: VecDeque::with_capacity(ONSET_BLOCKS),
        });
        if run.window.len() == ONSET_BLOCKS {
            if let Some((a0, e0, _)) = run.window.pop_front() {
                run.before = Some((e0, run.before.map_or(a0, |b| b.1.max(a0))));
            }
        }
        run.window.push_back((a, end_s, speed_rpm));
        let w = &run.window;
        if w.len() == ONSET_BLOCKS && (1..w.len()).all(|j| w[j].0 >= least * w[j - 1].0) {
            self.onset = Some((w[0].1, w[0].2));
            let prefix = run.before.map(|(end_s, largest)| TransientSpan {
                start_s: run.start_s,
                end_s,
                largest_subsync_m: largest,
            });
            self.run = None;
            if let Some(span) = prefix {
                self.note_transient(span);
            }
        }
    }

    fn note_transient(&mut self, span: TransientSpan) {
        if self.transients.len() < MAX_TRANSIENTS {
            self.transients.push(span);
        } else {
            self.dropped += 1;
        }
    }

    /// The transients so far, with the run under way (it has not persisted yet).
    fn transients(&self) -> Vec<TransientSpan> {
        let mut t = self.transients.clone();
        if self.onset.is_none() && t.len() < MAX_TRANSIENTS {
            t.extend(self.run.as_ref().and_then(|r| r.span()));
        }
        t
    }
}

/// One probe sample with the prediction at the same instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Bag time since the bag's first message (s).
    pub time_s: f64,
    /// The sample's time on the driver's clock (ns; its stamp where it is on the bag's clock):
    /// the keyphasor events' time base.
    pub time_ns: i64,
    /// Shaft angle (rad).
    pub angle_rad: f64,
    /// Speed (rad/s).
    pub speed_rad_s: f64,
    /// Measured displacement `[x, y]` (m).
    pub measured_m: [f64; 2],
    /// Predicted displacement `[x, y]` (m).
    pub predicted_m: [f64; 2],
    /// Whether `angle_rad` was locked to the plant's keyphasor (issue 12).
    pub phase_reference: PhaseReference,
}

impl Sample {
    /// The driver's comparison of one probe sample, at `time_s` since the bag's first message.
    pub fn of(c: &crate::driver::ProbeComparison, time_s: f64) -> Sample {
        Sample {
            time_s,
            time_ns: c.time_ns,
            angle_rad: c.angle_rad,
            speed_rad_s: c.speed_rad_s,
            measured_m: c.measured_m,
            predicted_m: c.predicted_m,
            phase_reference: c.phase_reference,
        }
    }
}

/// The features of one orbit over a window.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct OrbitFeatures {
    /// 1X semi-major axis (m).
    pub one_x_amplitude_m: f64,
    /// Phase of the forward 1X component at the window's start (degrees): only for comparing
    /// two orbits of one window, and only with a keyphasor (not serialized).
    #[serde(skip)]
    pub one_x_forward_phase_deg: f64,
    /// The 1X vector along each probe axis of the station (the machine file's angles), its
    /// phase lag from the keyphasor (API 670); null without a keyphasor lock over the window.
    pub one_x_probe_axes: Option<[OneXVector; 2]>,
    /// The 1X amplitude along each probe axis (m), given with or without a keyphasor (the
    /// amplitude needs no phase reference).
    pub one_x_probe_amplitudes_m: [f64; 2],
    /// Largest sub-synchronous semi-major axis (m), orders 2/R … (R−3)/R, corrected between
    /// bins ([`subsynchronous_peak`], the monitor's detector).
    pub subsync_amplitude_m: f64,
    /// Its order, refined between bins; None unless it counts by the monitor's rule (≥ 2 % of
    /// the clearance and ≥ half the 1X amplitude).
    pub subsync_ratio: Option<f64>,
    /// Mean position `[x, y]` (m).
    pub mean_m: [f64; 2],
    /// The ellipse of the 1X orbit (axes, inclination, precession; phase-free).
    pub one_x_ellipse: OrbitEllipse,
    /// The ellipse of the largest sub-synchronous component, at its order; null unless it
    /// counts (as `subsync_ratio`).
    pub subsync_ellipse: Option<OrbitEllipse>,
}

/// Predicted and measured over one window.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct WindowComparison {
    /// Window start and end, bag time (s).
    pub start_s: f64,
    /// Window end, bag time (s).
    pub end_s: f64,
    /// Mean speed over the window (rpm).
    pub speed_rpm: f64,
    /// Revolutions in the window.
    pub revolutions: usize,
    /// The measured orbit.
    pub measured: OrbitFeatures,
    /// The predicted orbit.
    pub predicted: OrbitFeatures,
    /// RMS distance between the two orbits with their means removed (m), sample by sample at
    /// equal times: it mixes a phase difference with a shape difference (two equal ellipses a
    /// quarter turn apart in phase differ by √2 × their radius), so it is no measure of shape
    /// alone; the 1X vectors and the sub-synchronous figures are.
    pub orbit_rms_distance_m: f64,
    /// Distance between the two mean positions (m).
    pub mean_position_distance_m: f64,
    /// The 1X ellipses compared, predicted minus measured: axes, inclination, precession and
    /// their RMS distance minimised over a phase shift (shape alone).
    pub one_x_shape: ShapeDifference,
    /// The same of the sub-synchronous ellipses (null unless both count).
    pub subsync_shape: Option<ShapeDifference>,
    /// Why the window's phases are null (None: keyphasor-referenced).
    pub phase_null_reason: Option<&'static str>,
}

/// The order spectra of one block of [`BLOCK_REVS`] revolutions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BlockSpectra {
    /// Mean speed (rpm).
    pub speed_rpm: f64,
    /// End of the block, bag time (s).
    pub end_s: f64,
    /// Measured semi-major axes (m) at orders k/8, k = 1 … 16.
    pub measured_m: [f64; 2 * BLOCK_REVS],
    /// Predicted semi-major axes (m) at the same orders.
    pub predicted_m: [f64; 2 * BLOCK_REVS],
    /// The full spectrum of the measured orbit x + iy: radii (m) of the forward (`[0]`) and
    /// backward (`[1]`) circular components at orders k/8, k = 1 … 16.
    pub measured_full_m: [[f64; 2 * BLOCK_REVS]; 2],
    /// The same of the predicted orbit.
    pub predicted_full_m: [[f64; 2 * BLOCK_REVS]; 2],
}

/// The streaming comparison at one station.
#[derive(Debug, Clone)]
pub struct StationComparison {
    /// Station name.
    pub station: String,
    clearance_m: f64,
    /// the station's two probe axes (rad from +x towards +y)
    axes_rad: [f64; 2],
    settings: ClassifierSettings,
    block: Vec<Sample>,
    /// a finished block waiting for the keyphasor event after its last sample
    waiting: Vec<Sample>,
    /// the keyphasor events at the end of the bag (for the summary window)
    final_events: Option<Box<KeyphasorEvents>>,
    recent: VecDeque<Sample>,
    /// Completed blocks, every `block_stride`-th (at most [`MAX_KEPT_BLOCKS`]).
    pub blocks: Vec<WindowComparison>,
    /// Each kept block's order spectra, semi-major axes (m) at orders k/8, k = 1 … 16: measured,
    /// predicted (for the waterfall plot).
    pub block_spectra: Vec<BlockSpectra>,
    /// Blocks completed (kept or not).
    pub blocks_seen: usize,
    /// One block in this many is kept (1, 2, 4, …).
    pub block_stride: usize,
    /// the onset rule on the predicted and the measured orbit, over every block
    onset_predicted: OnsetDetector,
    onset_measured: OnsetDetector,
    /// the plant's whip ([`crate::replay::observed_whip_s`]): consecutive blocks at or above the
    /// level and the first's start, then the first such run's start
    whip_run: (usize, f64),
    observed_whip_start_s: Option<f64>,
    /// Samples compared.
    pub samples: usize,
    /// Why the measured mean position is not the plant's (None: it is, e.g. DC-coupled probes
    /// or displacement pairs): an AC-coupled probe's mean is the twin's.
    pub mean_not_measured: Option<String>,
}

impl StationComparison {
    /// A comparison at `station`; sub-synchronous motion counts relative to `clearance_m`.
    pub fn new(station: &str, clearance_m: f64) -> Self {
        Self {
            station: station.into(),
            clearance_m,
            axes_rad: [0.0, std::f64::consts::FRAC_PI_2],
            settings: ClassifierSettings::default(),
            block: Vec::new(),
            waiting: Vec::new(),
            final_events: None,
            recent: VecDeque::new(),
            blocks: Vec::new(),
            block_spectra: Vec::new(),
            blocks_seen: 0,
            block_stride: 1,
            onset_predicted: OnsetDetector::default(),
            onset_measured: OnsetDetector::default(),
            whip_run: (0, 0.0),
            observed_whip_start_s: None,
            samples: 0,
            mean_not_measured: None,
        }
    }

    /// The station's probe axes (rad from +x towards +y).
    pub fn axes_rad(&self) -> [f64; 2] {
        self.axes_rad
    }

    /// The station's probe axes (rad from +x towards +y), along which 1X phase lags are read
    /// (default: x and y).
    pub fn with_axes(mut self, axes_rad: [f64; 2]) -> Self {
        self.axes_rad = axes_rad;
        self
    }

    /// The clearance sub-synchronous motion is judged against (m).
    pub fn clearance_m(&self) -> f64 {
        self.clearance_m
    }

    /// Adds a sample (in time order). With the plant's keyphasor `events` (the driver's), a
    /// finished block's measured 1X vectors are read against them: the block waits for the
    /// event after its last sample, at most until the next block is finished (or
    /// [`Self::finish`]). Without (`None`), against the sample's angle.
    pub fn push(&mut self, s: Sample, events: Option<&KeyphasorEvents>) {
        self.samples += 1;
        if let Some(first) = self.block.first() {
            if s.angle_rad - first.angle_rad >= BLOCK_REVS as f64 * TAU || s.time_s < first.time_s {
                self.take_waiting(events, true);
                self.waiting = std::mem::take(&mut self.block);
            }
        }
        self.take_waiting(events, false);
        self.block.push(s);
        self.recent.push_back(s);
        while self
            .recent
            .front()
            .is_some_and(|f| s.angle_rad - f.angle_rad > (SUMMARY_REVS + 1) as f64 * TAU)
        {
            self.recent.pop_front();
        }
    }

    /// The end of the bag: the block waiting for its closing event is finished with the
    /// events there are (its last revolution extrapolated at the last interval's speed), and
    /// the summary window is read against `events`.
    pub fn finish(&mut self, events: Option<&KeyphasorEvents>) {
        self.take_waiting(events, true);
        self.final_events = events.map(|e| Box::new(e.clone()));
    }

    /// The waiting block into the blocks, once its closing keyphasor event has come (or
    /// `give_up`: then with its measured phases null if it is not bracketed).
    fn take_waiting(&mut self, events: Option<&KeyphasorEvents>, give_up: bool) {
        if self.waiting.is_empty() {
            return;
        }
        match self.compare(&self.waiting, BLOCK_REVS, events, give_up) {
            Err(()) => return,
            Ok(Some(w)) => {
                let spectra = block_spectra(&self.waiting, &w);
                self.note_block(w, spectra);
            }
            Ok(None) => {}
        }
        self.waiting.clear();
    }

    /// The comparison over the last [`SUMMARY_REVS`] revolutions (or as many whole ones as
    /// there are, at least 2); None with fewer.
    pub fn summary(&self) -> Option<WindowComparison> {
        let recent: Vec<Sample> = self.recent.iter().copied().collect();
        let (first, last) = (recent.first()?, recent.last()?);
        let revs = (((last.angle_rad - first.angle_rad) / TAU).floor() as usize).min(SUMMARY_REVS);
        if revs < 2 {
            return None;
        }
        let start = recent
            .iter()
            .position(|s| last.angle_rad - s.angle_rad < revs as f64 * TAU)
            .unwrap_or(0);
        let events = self.final_events.as_deref();
        self.compare(&recent[start..], revs, events, true)
            .ok()
            .flatten()
    }

    /// A finished block through the onset and whip rules, and kept (with its spectra) if it is
    /// one of every `block_stride`; at [`MAX_KEPT_BLOCKS`] every other kept block is dropped
    /// and the stride doubles.
    fn note_block(&mut self, w: WindowComparison, spectra: BlockSpectra) {
        let least = (-self.settings.growth_threshold_per_rev * BLOCK_REVS as f64).exp();
        let counting = |f: &OrbitFeatures| f.subsync_ratio.map(|_| f.subsync_amplitude_m);
        let (p, m) = (counting(&w.predicted), counting(&w.measured));
        self.onset_predicted
            .push(w.start_s, w.end_s, w.speed_rpm, p, least);
        self.onset_measured
            .push(w.start_s, w.end_s, w.speed_rpm, m, least);
        let level = self.settings.whip_eccentricity_ratio * self.clearance_m;
        if w.measured.subsync_amplitude_m >= level {
            if self.whip_run.0 == 0 {
                self.whip_run.1 = w.start_s;
            }
            self.whip_run.0 += 1;
            if self.whip_run.0 >= ONSET_BLOCKS && self.observed_whip_start_s.is_none() {
                self.observed_whip_start_s = Some(self.whip_run.1);
            }
        } else {
            self.whip_run.0 = 0;
        }
        let k = self.blocks_seen;
        self.blocks_seen += 1;
        if !k.is_multiple_of(self.block_stride) {
            return;
        }
        if self.blocks.len() == MAX_KEPT_BLOCKS {
            keep_every_other(&mut self.blocks);
            keep_every_other(&mut self.block_spectra);
            self.block_stride *= 2;
            if !k.is_multiple_of(self.block_stride) {
                return;
            }
        }
        self.blocks.push(w);
        self.block_spectra.push(spectra);
    }

    /// The onset (measured, or predicted with `predicted`): the first block of a run of
    /// [`ONSET_BLOCKS`] consecutive blocks whose sub-synchronous component counts (the monitor's
    /// rule) and persists or grows: over the run it decays by less than the classifier's growth
    /// threshold allows (e^{−0.002/rev · 8 revolutions} a block). Its end time (s) and speed
    /// (rpm). A decaying start-up transient is no onset (see [`Self::transients`]). Read over
    /// every block, kept or not.
    pub fn onset(&self, predicted: bool) -> Option<(f64, f64)> {
        self.detector(predicted).onset
    }

    /// The runs of consecutive counting blocks before the onset that do not persist: decaying
    /// transients (e.g. the free vibration after a sudden unbalance), reported as such (the
    /// first [`MAX_TRANSIENTS`]).
    pub fn transients(&self, predicted: bool) -> Vec<TransientSpan> {
        self.detector(predicted).transients()
    }

    /// Transients beyond the first [`MAX_TRANSIENTS`], not reported (predicted, measured).
    pub fn transients_dropped(&self) -> (usize, usize) {
        (self.onset_predicted.dropped, self.onset_measured.dropped)
    }

    /// The start of the first [`ONSET_BLOCKS`] consecutive blocks whose measured
    /// sub-synchronous semi-major axis is at or above the monitor's whip eccentricity times the
    /// clearance (bag time, s), over every block.
    pub fn observed_whip_start_s(&self) -> Option<f64> {
        self.observed_whip_start_s
    }

    fn detector(&self, predicted: bool) -> &OnsetDetector {
        if predicted {
            &self.onset_predicted
        } else {
            &self.onset_measured
        }
    }

    /// The order spectra (measured, predicted) of the summary window, orders 1/R … 2.
    pub fn summary_spectra(&self) -> Option<(Vec<OrderComponent>, Vec<OrderComponent>)> {
        let w = self.summary()?;
        let samples: Vec<Sample> = self
            .recent
            .iter()
            .filter(|s| s.time_s >= w.start_s)
            .copied()
            .collect();
        let revs = w.revolutions;
        Some((
            spectrum(&samples, revs, |s| s.measured_m),
            spectrum(&samples, revs, |s| s.predicted_m),
        ))
    }

    /// The samples of the last `revs` revolutions (for plots).
    pub fn recent_samples(&self, revs: usize) -> Vec<Sample> {
        let Some(last) = self.recent.back() else {
            return Vec::new();
        };
        self.recent
            .iter()
            .filter(|s| last.angle_rad - s.angle_rad <= revs as f64 * TAU)
            .copied()
            .collect()
    }

    /// Predicted against measured over `samples` (`revs` whole revolutions of the twin's angle).
    /// With `events` and a locked twin, the measured 1X vectors are read against the plant's
    /// angle ([`keyphasor_one_x`], the node's rule); Err while the event after the last sample
    /// has not come (unless `no_more_events`).
    fn compare(
        &self,
        samples: &[Sample],
        revs: usize,
        events: Option<&KeyphasorEvents>,
        no_more_events: bool,
    ) -> Result<Option<WindowComparison>, ()> {
        if samples.len() < 8 * revs.max(1) {
            return Ok(None);
        }
        let mut reason = samples.iter().find_map(|s| s.phase_reference.null_reason());
        // the closing event not yet in: the wait goes on before any feature is computed (they
        // were computed, then dropped, at every sample of the wait, ≈ half a revolution)
        if let (None, Some(ev), false) = (reason, events, no_more_events) {
            let last = samples[samples.len() - 1].time_ns;
            if ev.angle_at(last) == Err(Unbracketed::Pending) {
                return Err(());
            }
        }
        let mut measured = self.features(samples, revs, |s| s.measured_m);
        let predicted = self.features(samples, revs, |s| s.predicted_m);
        let mut plant_speed = None;
        if let (None, Some(ev)) = (reason, events) {
            match self.plant_axes(samples, ev, no_more_events) {
                Ok(Some((axes, speed))) => {
                    measured.one_x_probe_axes = Some(axes);
                    measured.one_x_probe_amplitudes_m = axes.map(|v| v.amplitude_m);
                    plant_speed = speed;
                }
                Ok(None) => {}
                Err(Unbracketed::Pending) if !no_more_events => return Err(()),
                Err(Unbracketed::Pending) => reason = Some(NO_CLOSING_EVENT),
                Err(Unbracketed::Missing) => reason = Some(NO_OPENING_EVENT),
            }
        }
        let mut w = window(samples, revs, measured, predicted, reason);
        if let Some(speed) = plant_speed {
            w.speed_rpm = crate::units::rad_s_to_rpm(speed);
        }
        Ok(Some(w))
    }

    /// The measured 1X vectors along the station's probe axes against the plant's angle from
    /// `events`, and the plant's mean speed over the samples (rad/s: its angle travelled over
    /// the time taken). The twin's speed, from the last keyphasor interval, trails an
    /// accelerating shaft (by about one revolution's gain of speed), so a block's speed is the
    /// plant's where the events give it: the Bode plot's abscissa.
    #[allow(clippy::type_complexity)]
    fn plant_axes(
        &self,
        samples: &[Sample],
        events: &KeyphasorEvents,
        no_more_events: bool,
    ) -> Result<Option<([OneXVector; 2], Option<f64>)>, Unbracketed> {
        let axis = |a: f64| {
            let (sn, cs) = a.sin_cos();
            let along = samples
                .iter()
                .map(move |s| (s.time_ns, s.measured_m[0] * cs + s.measured_m[1] * sn));
            keyphasor_one_x(along, samples.len(), events, no_more_events)
        };
        let angle = |t: i64| match no_more_events {
            true => events.angle_at_or_after(t).ok(),
            false => events.angle_at(t).ok(),
        };
        let (first, last) = (samples[0].time_ns, samples[samples.len() - 1].time_ns);
        let speed = match (angle(first), angle(last)) {
            (Some(a), Some(b)) if last > first => Some((b - a) / ((last - first) as f64 * 1e-9)),
            _ => None,
        };
        match (axis(self.axes_rad[0])?, axis(self.axes_rad[1])?) {
            (Some(a), Some(b)) => Ok(Some(([a, b], speed))),
            _ => Ok(None),
        }
    }

    fn features(
        &self,
        samples: &[Sample],
        revs: usize,
        pick: impl Fn(&Sample) -> [f64; 2],
    ) -> OrbitFeatures {
        let spec = spectrum(samples, revs, &pick);
        let n = samples.len() as f64;
        let mean = [
            samples.iter().map(|s| pick(s)[0]).sum::<f64>() / n,
            samples.iter().map(|s| pick(s)[1]).sum::<f64>() / n,
        ];
        let one_x = one_x_component(&spec, revs);
        // the monitor's detector (bins 2 … R−3, interpolated between bins)
        let peak = subsynchronous_peak(&spec, revs);
        let abest = peak.semi_major_m();
        let counts = self
            .settings
            .subsync_counts(abest, one_x.semi_major_m(), self.clearance_m);
        let ratio = counts.then_some(peak.order);
        let axis = |a: f64| {
            let (sn, cs) = a.sin_cos();
            let values = samples.iter().map(|s| {
                let p = pick(s);
                (s.angle_rad, p[0] * cs + p[1] * sn)
            });
            one_x_vector(values, samples.len()).unwrap_or_default()
        };
        let axes = [axis(self.axes_rad[0]), axis(self.axes_rad[1])];
        OrbitFeatures {
            one_x_ellipse: ellipse(samples, 1.0, &pick).unwrap_or_default(),
            subsync_ellipse: ratio.and_then(|r| ellipse(samples, r, &pick)),
            one_x_amplitude_m: one_x.semi_major_m(),
            one_x_forward_phase_deg: one_x.forward_phase_rad.to_degrees(),
            one_x_probe_axes: Some(axes),
            one_x_probe_amplitudes_m: axes.map(|v| v.amplitude_m),
            subsync_amplitude_m: abest,
            subsync_ratio: ratio,
            mean_m: mean,
        }
    }
}

/// The comparison of `samples` (`revs` revolutions) from the two orbits' features; `reason`:
/// why the phases are null (then the probe-axis vectors are).
fn window(
    samples: &[Sample],
    revs: usize,
    mut measured: OrbitFeatures,
    mut predicted: OrbitFeatures,
    reason: Option<&'static str>,
) -> WindowComparison {
    if reason.is_some() {
        measured.one_x_probe_axes = None;
        predicted.one_x_probe_axes = None;
    }
    let (mm, pm) = (measured.mean_m, predicted.mean_m);
    let n = samples.len() as f64;
    let equal_times = samples
        .iter()
        .map(|s| {
            let dx = (s.predicted_m[0] - pm[0]) - (s.measured_m[0] - mm[0]);
            let dy = (s.predicted_m[1] - pm[1]) - (s.measured_m[1] - mm[1]);
            dx * dx + dy * dy
        })
        .sum::<f64>()
        / n;
    WindowComparison {
        start_s: samples[0].time_s,
        end_s: samples[samples.len() - 1].time_s,
        speed_rpm: samples.iter().map(|s| s.speed_rad_s).sum::<f64>() / n * 30.0
            / std::f64::consts::PI,
        revolutions: revs,
        measured,
        predicted,
        orbit_rms_distance_m: equal_times.sqrt(),
        mean_position_distance_m: (pm[0] - mm[0]).hypot(pm[1] - mm[1]),
        one_x_shape: ShapeDifference::of(&predicted.one_x_ellipse, &measured.one_x_ellipse),
        subsync_shape: match (predicted.subsync_ellipse, measured.subsync_ellipse) {
            (Some(p), Some(m)) => Some(ShapeDifference::of(&p, &m)),
            _ => None,
        },
        phase_null_reason: reason,
    }
}

/// The ellipse of the orbit `pick` at `order` over `samples`: the x and y components fitted at
/// that order of the samples' angle ([`one_x_vector`] at order·ψ: Hann-weighted, exact for a
/// mean and a whole number of cycles of the order); None with less than one cycle.
fn ellipse(
    samples: &[Sample],
    order: f64,
    pick: &impl Fn(&Sample) -> [f64; 2],
) -> Option<OrbitEllipse> {
    let part = |j: usize| {
        let values = samples.iter().map(|s| (order * s.angle_rad, pick(s)[j]));
        one_x_vector(values, samples.len())
    };
    Some(OrbitEllipse::from_vectors(order, &part(0)?, &part(1)?))
}

/// The order spectra of one block: semi-major axes and the full (forward and backward) spectra,
/// measured and predicted.
fn block_spectra(block: &[Sample], w: &WindowComparison) -> BlockSpectra {
    let of = |pick: fn(&Sample) -> [f64; 2]| {
        let spec = spectrum(block, BLOCK_REVS, pick);
        let (mut semi, mut full) = ([0.0; 2 * BLOCK_REVS], [[0.0; 2 * BLOCK_REVS]; 2]);
        for (k, c) in spec.iter().enumerate().take(2 * BLOCK_REVS) {
            semi[k] = c.semi_major_m();
            full[0][k] = c.forward_m;
            full[1][k] = c.backward_m;
        }
        (semi, full)
    };
    let (measured_m, measured_full_m) = of(|s| s.measured_m);
    let (predicted_m, predicted_full_m) = of(|s| s.predicted_m);
    BlockSpectra {
        speed_rpm: w.speed_rpm,
        end_s: w.end_s,
        measured_m,
        predicted_m,
        measured_full_m,
        predicted_full_m,
    }
}

/// The order spectrum at orders k/`revs`, k = 1 … 2·revs (at most 64 bins).
fn spectrum(
    samples: &[Sample],
    revs: usize,
    pick: impl Fn(&Sample) -> [f64; 2],
) -> Vec<OrderComponent> {
    let mut out = vec![OrderComponent::default(); (2 * revs).clamp(1, 64)];
    order_spectrum(
        samples.iter().map(|s| pick(s)[0]),
        samples.iter().map(|s| pick(s)[1]),
        samples.iter().map(|s| s.angle_rad),
        samples.len(),
        revs,
        &mut out,
    );
    out
}

/// `a − b` in degrees wrapped into (−180, 180].
pub fn phase_difference_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::super::orbit_shape::Precession;
    use super::*;

    /// Known orbits: measured = forward 1X circle of 3 µm at phase 0 plus a forward 0.45X circle
    /// of 2 µm; predicted = forward 1X circle of 2.5 µm at phase +20°. 64 samples a revolution
    /// over 40 revolutions at 150 rev/s. Expected: 1X −0.5 µm and +20°, measured sub-synchronous
    /// 2 µm at 0.45X (between bins 14/32 and 15/32: the interpolation must find it), predicted
    /// none, shape distance = RMS of the difference of the two signals, computed directly.
    #[test]
    fn finds_known_amplitudes_phases_and_orders() {
        let mut c = StationComparison::new("s", 40e-6);
        let (spr, revs, f) = (64usize, 40usize, 150.0);
        let mut sum2 = 0.0;
        let mut n = 0usize;
        let last_start = (revs - SUMMARY_REVS) * spr;
        for i in 0..=revs * spr {
            let psi = TAU * i as f64 / spr as f64;
            let m = [
                3e-6 * psi.cos() + 2e-6 * (0.45 * psi).cos(),
                3e-6 * psi.sin() + 2e-6 * (0.45 * psi).sin(),
            ];
            let p = [
                2.5e-6 * (psi + 20f64.to_radians()).cos(),
                2.5e-6 * (psi + 20f64.to_radians()).sin(),
            ];
            if i >= last_start {
                sum2 += (p[0] - m[0]).powi(2) + (p[1] - m[1]).powi(2);
                n += 1;
            }
            c.push(
                Sample {
                    time_s: psi / (TAU * f),
                    time_ns: 0,
                    angle_rad: psi,
                    speed_rad_s: TAU * f,
                    measured_m: m,
                    predicted_m: p,
                    phase_reference: PhaseReference::Locked,
                },
                None,
            );
        }
        let w = c.summary().unwrap();
        assert_eq!(w.revolutions, SUMMARY_REVS);
        assert!((w.speed_rpm - 9000.0).abs() < 1e-6);
        // Hann-windowed bins: the exact-order components to 1 %
        assert!(
            (w.measured.one_x_amplitude_m - 3e-6).abs() < 0.03e-6,
            "{w:?}"
        );
        assert!(
            (w.predicted.one_x_amplitude_m - 2.5e-6).abs() < 0.025e-6,
            "{w:?}"
        );
        let dphi = phase_difference_deg(
            w.predicted.one_x_forward_phase_deg,
            w.measured.one_x_forward_phase_deg,
        );
        assert!((dphi - 20.0).abs() < 1.0, "phase error {dphi}°");
        let r = w.measured.subsync_ratio.expect("0.45X found");
        assert!((r - 0.45).abs() < 0.01, "ratio {r}");
        // off-bin (14.4 bins of 1/32 order): the interpolation undoes the Hann window's
        // scalloping loss (13 % here), so to 1 %
        assert!(
            (w.measured.subsync_amplitude_m / 2e-6 - 1.0).abs() < 0.01,
            "{w:?}"
        );
        assert!(w.predicted.subsync_ratio.is_none());
        // the means (removed for the shape) are ~0 for both, so the shape distance is the RMS
        // difference of the signals, up to the window's end effects on the means
        let direct = (sum2 / n as f64).sqrt();
        assert!(
            (w.orbit_rms_distance_m / direct - 1.0).abs() < 0.03,
            "{} vs {direct}",
            w.orbit_rms_distance_m
        );
        // blocks of 8 revolutions, each closed by the first sample a full block past its start
        // (the last sample, at exactly 40 revolutions, closes the fifth); the 0.45X component
        // counts from the first block on
        assert_eq!(c.blocks.len(), revs / BLOCK_REVS);
        assert!(c.onset(false).is_some() && c.onset(true).is_none());
    }

    /// Feeds `revs` revolutions of a 1X circle of 1 µm plus a forward 0.45X circle of radius
    /// `sub(rev)` (64 samples a revolution, 150 rev/s) into a comparison (clearance 40 µm), as
    /// the measured orbit.
    fn fed(revs: usize, sub: impl Fn(f64) -> f64) -> StationComparison {
        let mut c = StationComparison::new("s", 40e-6);
        for i in 0..=revs * 64 {
            let psi = TAU * i as f64 / 64.0;
            let a = sub(psi / TAU);
            let m = [
                1e-6 * psi.cos() + a * (0.45 * psi).cos(),
                1e-6 * psi.sin() + a * (0.45 * psi).sin(),
            ];
            c.push(
                Sample {
                    time_s: psi / (TAU * 150.0),
                    time_ns: 0,
                    angle_rad: psi,
                    speed_rad_s: TAU * 150.0,
                    measured_m: m,
                    predicted_m: [1e-6 * psi.cos(), 1e-6 * psi.sin()],
                    phase_reference: PhaseReference::Locked,
                },
                None,
            );
        }
        c
    }

    /// A start-up transient: 0.45X from 5 µm decaying at 0.02/rev (it counts, ≥ 0.8 µm and
    /// ≥ half the 1X, for some 9 blocks): no onset, one transient from the start. A component
    /// growing at 0.02/rev from 0.2 µm counts from about revolution 70 (0.8 µm) on: the onset is
    /// the first counting block, and there is no transient. A steady one (a limit cycle) is an
    /// onset at its first block.
    #[test]
    fn decaying_transients_are_no_onsets() {
        let decaying = fed(120, |rev| 5e-6 * (-0.02 * rev).exp());
        assert!(
            decaying.onset(false).is_none(),
            "{:?}",
            decaying.onset(false)
        );
        let t = decaying.transients(false);
        assert_eq!(t.len(), 1, "{t:?}");
        assert!(
            t[0].start_s < 1e-9 && t[0].largest_subsync_m > 3e-6,
            "{t:?}"
        );
        // formerly: the first block counted and was the onset
        assert!(decaying.blocks[0].measured.subsync_ratio.is_some());

        let growing = fed(120, |rev| 0.2e-6 * (0.02 * rev).exp());
        let (t_on, _) = growing.onset(false).expect("an onset");
        let first = growing
            .blocks
            .iter()
            .find(|b| b.measured.subsync_ratio.is_some())
            .unwrap();
        assert!(
            (t_on - first.end_s).abs() < 1e-9,
            "{t_on} vs {}",
            first.end_s
        );
        assert!(
            (60.0..90.0).contains(&(t_on * 150.0)),
            "onset at rev {}",
            t_on * 150.0
        );
        assert!(growing.transients(false).is_empty());

        let steady = fed(60, |_| 3e-6);
        let (t_on, _) = steady.onset(false).expect("an onset");
        assert!((t_on - steady.blocks[0].end_s).abs() < 1e-9);
    }

    /// Three blocks of the orbits `measured` and `predicted` (functions of the shaft angle), 64
    /// samples a revolution at 150 rev/s, keyphasor-locked.
    fn three_blocks(
        measured: impl Fn(f64) -> [f64; 2],
        predicted: impl Fn(f64) -> [f64; 2],
    ) -> StationComparison {
        let mut c = StationComparison::new("s", 40e-6);
        for i in 0..=3 * BLOCK_REVS * 64 {
            let psi = TAU * i as f64 / 64.0;
            let s = Sample {
                time_s: psi / (TAU * 150.0),
                time_ns: 0,
                angle_rad: psi,
                speed_rad_s: TAU * 150.0,
                measured_m: measured(psi),
                predicted_m: predicted(psi),
                phase_reference: PhaseReference::Locked,
            };
            c.push(s, None);
        }
        c
    }

    /// The full spectrum of x + iy (issue 16), known signals through the blocks: a forward
    /// circle of 2 µm puts all of it in +1X; a backward one in −1X; a line (a degenerate
    /// ellipse) x = 2 µm cos ψ splits equally, 1 µm each way; a forward 0.5X whirl shows at
    /// +0.5X (bin 4 of the 1/8 orders). Exact orders over whole revolutions under the Hann
    /// window: the bin to 1e-3 of the radius, its two neighbours half of it (the Hann window's
    /// main lobe), every other bin below 1e-3 of the radius.
    #[test]
    fn the_full_spectrum_separates_forward_and_reverse_whirl() {
        type Orbit = fn(f64) -> [f64; 2];
        let r = 2e-6;
        let cases: [(&str, Orbit, usize, [f64; 2]); 4] = [
            (
                "forward 1X",
                |p| [2e-6 * p.cos(), 2e-6 * p.sin()],
                7,
                [r, 0.0],
            ),
            (
                "backward 1X",
                |p| [2e-6 * p.cos(), -2e-6 * p.sin()],
                7,
                [0.0, r],
            ),
            ("line", |p| [2e-6 * p.cos(), 0.0], 7, [r / 2.0, r / 2.0]),
            (
                "forward 0.5X",
                |p| [2e-6 * (0.5 * p).cos(), 2e-6 * (0.5 * p).sin()],
                3,
                [r, 0.0],
            ),
        ];
        for (name, orbit, bin, [fwd, bwd]) in cases {
            let c = three_blocks(orbit, orbit);
            assert_eq!(c.block_spectra.len(), 3, "{name}");
            for b in &c.block_spectra {
                let full = b.measured_full_m;
                assert!((full[0][bin] - fwd).abs() < 1e-3 * r, "{name}: {full:?}");
                assert!((full[1][bin] - bwd).abs() < 1e-3 * r, "{name}: {full:?}");
                for k in (0..2 * BLOCK_REVS).filter(|&k| k != bin) {
                    // the Hann window's neighbouring bins hold half the component
                    let share = if k + 1 == bin || k == bin + 1 {
                        0.5
                    } else {
                        0.0
                    };
                    for (w, v) in [(0, fwd), (1, bwd)] {
                        let e = (full[w][k] - share * v).abs();
                        assert!(e < 1e-3 * r, "{name}: bin {k}: {full:?}");
                    }
                }
                assert_eq!(b.predicted_full_m, full);
                // the semi-major axis is forward + backward
                assert!((b.measured_m[bin] - fwd - bwd).abs() < 1e-3 * r);
            }
        }
    }

    /// The shape comparison is phase-free: predicted = the measured orbit a quarter revolution
    /// later (a 1X ellipse 3 µm × 1 µm inclined 25°, forward, plus a 4 µm × 2 µm backward 0.5X
    /// ellipse inclined 110°, a whirl that counts). Each block's ellipses read back their axes
    /// and inclination within 1e-3 (relative; degrees), the 0.5X one backward; the shape
    /// distances are 0 (below 1e-3 of the size) while the distance at equal times is large
    /// (above 2 µm: two points a quarter turn apart on each ellipse).
    #[test]
    fn a_time_shifted_orbit_has_the_same_shape() {
        let orbit = |psi: f64| {
            let ell = |a: f64, b: f64, tilt: f64, p: f64| {
                let (u, v) = (a * p.cos(), b * p.sin());
                let (s, c) = tilt.to_radians().sin_cos();
                [u * c - v * s, u * s + v * c]
            };
            let (one, sub) = (
                ell(3e-6, 1e-6, 25.0, psi),
                ell(4e-6, -2e-6, 110.0, 0.5 * psi),
            );
            [one[0] + sub[0], one[1] + sub[1]]
        };
        let c = three_blocks(orbit, |psi| orbit(psi + TAU / 4.0));
        assert_eq!(c.blocks.len(), 3);
        for b in &c.blocks {
            for f in [&b.measured, &b.predicted] {
                let e = f.one_x_ellipse;
                assert!((e.semi_major_m / 3e-6 - 1.0).abs() < 1e-3, "{e:?}");
                assert!((e.semi_minor_m / 1e-6 - 1.0).abs() < 1e-3, "{e:?}");
                assert!((e.inclination_deg - 25.0).abs() < 1e-3, "{e:?}");
                assert_eq!(e.precession, Precession::Forward);
                let s = f.subsync_ellipse.expect("the 0.5X whirl counts");
                assert!((s.order - 0.5).abs() < 1e-3, "{s:?}");
                assert!((s.semi_major_m / 4e-6 - 1.0).abs() < 1e-3, "{s:?}");
                assert!((s.semi_minor_m / 2e-6 - 1.0).abs() < 1e-3, "{s:?}");
                assert!((s.inclination_deg - 110.0).abs() < 1e-3, "{s:?}");
                assert_eq!(s.precession, Precession::Backward);
            }
            assert!(b.one_x_shape.shape_distance_m < 1e-3 * 3e-6, "{b:?}");
            let sub = b.subsync_shape.expect("both count");
            assert!(sub.shape_distance_m < 1e-3 * 4e-6, "{sub:?}");
            assert!(b.orbit_rms_distance_m > 2e-6, "{}", b.orbit_rms_distance_m);
        }
    }

    #[test]
    fn phase_differences_wrap() {
        assert_eq!(phase_difference_deg(170.0, -170.0), -20.0);
        assert_eq!(phase_difference_deg(-170.0, 170.0), 20.0);
        assert_eq!(phase_difference_deg(10.0, 10.0), 0.0);
    }
}
