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

/// The recording's topic handles.
struct Handles {
    speed: usize,
    unbalance: usize,
    journal: usize,
    film: usize,
    orbit: usize,
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
    fn add(rec: &mut Recorder, params: &super::NodeParams) -> anyhow::Result<Self> {
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
        Ok(Self {
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
    fn write(&self, rec: &mut Recorder, item: &ToRecord) -> Result<(), crate::record::RecordError> {
        let t = |ns: &i64| *ns as u64;
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
    rx: mpsc::Receiver<ToRecord>,
    stop: Arc<AtomicBool>,
) -> anyhow::Result<JoinHandle<anyhow::Result<PathBuf>>> {
    let mut rec = Recorder::create_split(dir, split)?;
    let handles = Handles::add(&mut rec, params)?;
    Ok(std::thread::spawn(move || -> anyhow::Result<PathBuf> {
        loop {
            match rx.recv_timeout(Duration::from_millis(200)) {
                Ok(item) => handles.write(&mut rec, &item)?,
                // after shutdown, the first quiet moment ends the recording
                Err(mpsc::RecvTimeoutError::Timeout) if stop.load(Ordering::Relaxed) => break,
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            rec.flush_if_due(Duration::from_secs(1))?;
        }
        Ok(rec.finish()?)
    }))
}
