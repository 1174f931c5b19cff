//! The node's recording: every input as received and every output, on their own thread, to a
//! rosbag2 MCAP bag flushed every second and finished when the node stops.

use super::model::{Outgoing, Published};
use crate::messages;
use crate::record::Recorder;
use crate::topics::{
    self as qos, DIAGNOSTICS, FILM, JOURNAL, MARGIN, ORBIT, PROBE, RESIDUAL, SPEED, UNBALANCE,
    WARNING,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::thread::JoinHandle;
use std::time::Duration;

/// A record request for the recorder thread: a message and its receive or send time (ns).
pub(super) enum ToRecord {
    Out(Published, i64),
    Speed(messages::RotorSpeed, i64),
    Speed64(messages::Float64, i64),
    Unbalance(messages::Unbalance, i64),
    Probe(messages::ProbeDisplacement, i64),
    /// A PointStamped probe pair of the `usize`-th `probe_point_topics` entry.
    Point(usize, messages::PointStamped, i64),
    /// The oil supply temperature (issue 12).
    Temperature(messages::Temperature, i64),
    /// A keyphasor event (issue 12).
    Keyphasor(messages::Keyphasor, i64),
    /// A raw probe reading (issue 12).
    ProbeSignal(messages::ProbeSignal, i64),
    /// A keyphasor event as std_msgs/Header (`keyphasor_type:=header`).
    KeyphasorHeader(messages::Header, i64),
    /// A raw probe reading as std_msgs/Float64 of the `usize`-th `probe_signal_topics` entry.
    ProbeValue(usize, messages::Float64, i64),
}

/// Stamps an unstamped input (header stamp 0: a tool that leaves it empty, e.g. `ros2 topic
/// pub` without `--stamp`) with its receive time `ns` on the node's clock, in the recorded copy:
/// the driver already takes the receive time for such an input (driver::inputs), and a stamp of
/// 0 beside stamps of ~1.8·10⁹ s stretches a viewer's time axis so far that no data shows
/// (Lichtblick, plotting by header stamp). Refusing them instead would lose a speed the twin
/// ran on. Returns true if it stamped (the caller counts). std_msgs/Float64 inputs have no
/// stamp and are left as they are.
fn stamp_on_receipt(item: &mut ToRecord) -> bool {
    let (header, ns) = match item {
        ToRecord::Speed(m, ns) => (&mut m.header, *ns),
        ToRecord::Unbalance(m, ns) => (&mut m.header, *ns),
        ToRecord::Probe(m, ns) => (&mut m.header, *ns),
        ToRecord::Point(_, m, ns) => (&mut m.header, *ns),
        ToRecord::Temperature(m, ns) => (&mut m.header, *ns),
        ToRecord::Keyphasor(m, ns) => (&mut m.header, *ns),
        ToRecord::ProbeSignal(m, ns) => (&mut m.header, *ns),
        ToRecord::KeyphasorHeader(m, ns) => (m, *ns),
        ToRecord::Speed64(..) | ToRecord::ProbeValue(..) | ToRecord::Out(..) => return false,
    };
    if header.stamp != messages::Time::default() {
        return false;
    }
    header.stamp = messages::Time::from_nanos(ns);
    true
}

/// The recording's topic handles.
struct Handles {
    speed: usize,
    unbalance: usize,
    journal: usize,
    film: usize,
    orbit: usize,
    /// each bearing's orbit topic for viewers, and the rule that fills them
    bearing_orbits: Vec<usize>,
    orbit_routes: crate::viewer::BearingOrbits,
    warning: usize,
    diagnostics: usize,
    probe: usize,
    residual: usize,
    margin: usize,
    forecast: usize,
    oil: usize,
    keyphasor: usize,
    signal: usize,
    one_x: usize,
    calibration: usize,
    points: Vec<usize>,
    values: Vec<usize>,
}

impl Handles {
    /// Every topic, the inputs in the types the node's parameters `params` subscribe them.
    fn add(
        rec: &mut Recorder,
        params: &super::NodeParams,
        orbit_routes: crate::viewer::BearingOrbits,
    ) -> anyhow::Result<Self> {
        let input = qos::INPUT_RECORDED;
        let speed = if params.speed_type == super::SpeedType::Float64 {
            rec.add_topic::<messages::Float64>(SPEED, input)?
        } else {
            rec.add_topic::<messages::RotorSpeed>(SPEED, input)?
        };
        let keyphasor = if params.keyphasor_type == super::KeyphasorType::Header {
            rec.add_topic::<messages::Header>(crate::topics::KEYPHASOR, input)?
        } else {
            rec.add_topic::<messages::Keyphasor>(crate::topics::KEYPHASOR, input)?
        };
        let mut each = |pairs: &[(String, String)], float64: bool| {
            pairs
                .iter()
                .map(|(_, topic)| match float64 {
                    true => rec.add_topic::<messages::Float64>(topic, input),
                    false => rec.add_topic::<messages::PointStamped>(topic, input),
                })
                .collect::<Result<Vec<_>, _>>()
        };
        let points = each(&params.probe_point_topics, false)?;
        let values = each(&params.probe_signal_topics, true)?;
        let bearing_orbits = orbit_routes
            .topics()
            .iter()
            .map(|t| rec.add_topic::<messages::Orbit>(t, qos::STATE))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            bearing_orbits,
            orbit_routes,
            speed,
            keyphasor,
            points,
            values,
            unbalance: rec.add_topic::<messages::Unbalance>(UNBALANCE, input)?,
            journal: rec.add_topic::<messages::JournalState>(JOURNAL, qos::STATE)?,
            film: rec.add_topic::<messages::FilmState>(FILM, qos::STATE)?,
            orbit: rec.add_topic::<messages::Orbit>(ORBIT, qos::STATE)?,
            warning: rec.add_topic::<messages::InstabilityWarning>(WARNING, qos::WARNING_QOS)?,
            diagnostics: rec.add_topic::<messages::DiagnosticArray>(DIAGNOSTICS, qos::STATE)?,
            probe: rec.add_topic::<messages::ProbeDisplacement>(PROBE, input)?,
            residual: rec.add_topic::<messages::OrbitResidual>(RESIDUAL, qos::STATE)?,
            margin: rec.add_topic::<messages::StabilityMargin>(MARGIN, qos::MARGIN_QOS)?,
            forecast: rec.add_topic::<messages::Forecast>(qos::FORECAST, qos::FORECAST_QOS)?,
            oil: rec.add_topic::<messages::Temperature>(qos::OIL_TEMPERATURE, input)?,
            signal: rec.add_topic::<messages::ProbeSignal>(qos::PROBE_SIGNAL, input)?,
            one_x: rec.add_topic::<messages::OneXVectors>(qos::ONE_X, qos::STATE)?,
            calibration: rec.add_topic::<messages::CalibrationEstimate>(
                qos::CALIBRATION,
                qos::CALIBRATION_QOS,
            )?,
        })
    }

    /// Writes one item on its topic.
    fn write(
        &mut self,
        rec: &mut Recorder,
        item: &ToRecord,
    ) -> Result<(), crate::record::RecordError> {
        let t = |ns: &i64| *ns as u64;
        if let ToRecord::Out(Published::Twin(Outgoing::Orbit(m)), ns) = item {
            if let Some(k) = self.orbit_routes.route(m) {
                rec.write(self.bearing_orbits[k], m, t(ns), t(ns))?;
            }
        }
        match item {
            ToRecord::Speed(m, ns) => rec.write(self.speed, m, t(ns), t(ns)),
            ToRecord::Speed64(m, ns) => rec.write(self.speed, m, t(ns), t(ns)),
            ToRecord::Unbalance(m, ns) => rec.write(self.unbalance, m, t(ns), t(ns)),
            ToRecord::Probe(m, ns) => rec.write(self.probe, m, t(ns), t(ns)),
            ToRecord::Point(i, m, ns) => rec.write(self.points[*i], m, t(ns), t(ns)),
            ToRecord::Temperature(m, ns) => rec.write(self.oil, m, t(ns), t(ns)),
            ToRecord::Keyphasor(m, ns) => rec.write(self.keyphasor, m, t(ns), t(ns)),
            ToRecord::KeyphasorHeader(m, ns) => rec.write(self.keyphasor, m, t(ns), t(ns)),
            ToRecord::ProbeSignal(m, ns) => rec.write(self.signal, m, t(ns), t(ns)),
            ToRecord::ProbeValue(i, m, ns) => rec.write(self.values[*i], m, t(ns), t(ns)),
            ToRecord::Out(Published::OneX(m), ns) => rec.write(self.one_x, m, t(ns), t(ns)),
            ToRecord::Out(Published::Calibration(m), ns) => {
                rec.write(self.calibration, &**m, t(ns), t(ns))
            }
            ToRecord::Out(Published::Twin(o), ns) => {
                let (h, ns) = (self.output(o), t(ns));
                match o {
                    Outgoing::Journal(m) => rec.write(h, m, ns, ns),
                    Outgoing::Film(m) => rec.write(h, m, ns, ns),
                    Outgoing::Orbit(m) => rec.write(h, m, ns, ns),
                    Outgoing::Warning(m) => rec.write(h, m, ns, ns),
                    Outgoing::Diagnostics(m) => rec.write(h, m, ns, ns),
                    Outgoing::Residual(m) => rec.write(h, m, ns, ns),
                    Outgoing::Margin(m) => rec.write(h, m, ns, ns),
                    Outgoing::Forecast(m) => rec.write(h, &**m, ns, ns),
                }
            }
        }
    }

    /// The topic of one of the twin's messages.
    fn output(&self, o: &Outgoing) -> usize {
        match o {
            Outgoing::Journal(_) => self.journal,
            Outgoing::Film(_) => self.film,
            Outgoing::Orbit(_) => self.orbit,
            Outgoing::Warning(_) => self.warning,
            Outgoing::Diagnostics(_) => self.diagnostics,
            Outgoing::Residual(_) => self.residual,
            Outgoing::Margin(_) => self.margin,
            Outgoing::Forecast(_) => self.forecast,
        }
    }
}

/// Starts recording to bag directory `dir` (a new file whenever one reaches `split`) what arrives on `rx` (the inputs in the types the
/// node's parameters `params` subscribe them: the speed as std_msgs/Float64 with `speed_type`
/// float64, the keyphasor as std_msgs/Header with `keyphasor_type` header, the PointStamped and
/// Float64 probe topics of `probe_point_topics` and `probe_signal_topics`), until `stop` is set
/// and a quiet moment follows or the senders are gone.
pub(super) fn spawn(
    dir: &Path,
    split: crate::record::SplitLimits,
    params: &super::NodeParams,
    orbit_routes: crate::viewer::BearingOrbits,
    rx: mpsc::Receiver<ToRecord>,
    stop: Arc<AtomicBool>,
) -> anyhow::Result<JoinHandle<anyhow::Result<PathBuf>>> {
    let mut rec = Recorder::create_split(dir, split)?;
    let mut handles = Handles::add(&mut rec, params, orbit_routes)?;
    Ok(std::thread::spawn(move || -> anyhow::Result<PathBuf> {
        let mut stamped = 0u64;
        loop {
            match rx.recv_timeout(Duration::from_millis(200)) {
                Ok(mut item) => {
                    if stamp_on_receipt(&mut item) {
                        stamped += 1;
                        if stamped == 1 {
                            super::log::warn("recording: an input with header stamp 0 is recorded with its receive time as its stamp (counted; the total is said when the recording ends)");
                        }
                    }
                    handles.write(&mut rec, &item)?
                }
                // after shutdown, the first quiet moment ends the recording
                Err(mpsc::RecvTimeoutError::Timeout) if stop.load(Ordering::Relaxed) => break,
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            rec.flush_if_due(Duration::from_secs(1))?;
        }
        if stamped > 0 {
            super::log::warn(&format!(
                "recording: {stamped} unstamped inputs recorded with their receive time as their stamp"
            ));
        }
        Ok(rec.finish()?)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An unstamped speed gets its receive time; a stamped one and a Float64 (no stamp) keep
    /// theirs.
    #[test]
    fn unstamped_inputs_get_their_receive_time() {
        let recv_ns = 1_764_000_000_123_456_789;
        let mut unstamped = ToRecord::Speed(messages::RotorSpeed::default(), recv_ns);
        assert!(stamp_on_receipt(&mut unstamped));
        let ToRecord::Speed(m, _) = &unstamped else {
            unreachable!()
        };
        assert_eq!(m.header.stamp.as_nanos(), recv_ns);
        let mut stamped = messages::RotorSpeed::default();
        stamped.header.stamp = messages::Time::from_nanos(5);
        assert!(!stamp_on_receipt(&mut ToRecord::Speed(stamped, recv_ns)));
        let mut header = ToRecord::KeyphasorHeader(messages::Header::default(), recv_ns);
        assert!(stamp_on_receipt(&mut header));
        let bare = messages::Float64 { data: 1.0 };
        assert!(!stamp_on_receipt(&mut ToRecord::Speed64(bare, recv_ns)));
    }
}
