//! The node's recording: every input as received and every output, on their own thread, to a
//! rosbag2 MCAP bag flushed every second and finished when the node stops.

use super::model::Outgoing;
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
    Out(Outgoing, i64),
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
}

/// Starts recording to bag directory `dir` (a new file whenever one reaches `split`) what arrives on `rx` (the speed as std_msgs/Float64
/// if `speed_float64`; the PointStamped probe topics `points` as `(station, topic)`), until `stop`
/// is set and a quiet moment follows or the senders are gone.
pub(super) fn spawn(
    dir: &Path,
    split: crate::record::SplitLimits,
    speed_float64: bool,
    points: &[(String, String)],
    rx: mpsc::Receiver<ToRecord>,
    stop: Arc<AtomicBool>,
) -> anyhow::Result<JoinHandle<anyhow::Result<PathBuf>>> {
    let mut rec = Recorder::create_split(dir, split)?;
    let input = qos::INPUT_RECORDED;
    let h_speed = if speed_float64 {
        rec.add_topic::<messages::Float64>(SPEED, input)?
    } else {
        rec.add_topic::<messages::RotorSpeed>(SPEED, input)?
    };
    let h_unb = rec.add_topic::<messages::Unbalance>(UNBALANCE, input)?;
    let h_journal = rec.add_topic::<messages::JournalState>(JOURNAL, qos::STATE)?;
    let h_film = rec.add_topic::<messages::FilmState>(FILM, qos::STATE)?;
    let h_orbit = rec.add_topic::<messages::Orbit>(ORBIT, qos::STATE)?;
    let h_warning = rec.add_topic::<messages::InstabilityWarning>(WARNING, qos::WARNING_QOS)?;
    let h_diag = rec.add_topic::<messages::DiagnosticArray>(DIAGNOSTICS, qos::STATE)?;
    let h_probe = rec.add_topic::<messages::ProbeDisplacement>(PROBE, input)?;
    let h_residual = rec.add_topic::<messages::OrbitResidual>(RESIDUAL, qos::STATE)?;
    let h_margin = rec.add_topic::<messages::StabilityMargin>(MARGIN, qos::MARGIN_QOS)?;
    let h_forecast =
        rec.add_topic::<messages::Forecast>(crate::topics::FORECAST, qos::FORECAST_QOS)?;
    let h_oil = rec.add_topic::<messages::Temperature>(crate::topics::OIL_TEMPERATURE, input)?;
    let h_keyphasor = rec.add_topic::<messages::Keyphasor>(crate::topics::KEYPHASOR, input)?;
    let h_signal = rec.add_topic::<messages::ProbeSignal>(crate::topics::PROBE_SIGNAL, input)?;
    let h_points = points
        .iter()
        .map(|(_, topic)| rec.add_topic::<messages::PointStamped>(topic, input))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(std::thread::spawn(move || -> anyhow::Result<PathBuf> {
        loop {
            match rx.recv_timeout(Duration::from_millis(200)) {
                Ok(item) => {
                    let t = |ns: &i64| *ns as u64;
                    match &item {
                        ToRecord::Speed(m, ns) => rec.write(h_speed, m, t(ns), t(ns))?,
                        ToRecord::Speed64(m, ns) => rec.write(h_speed, m, t(ns), t(ns))?,
                        ToRecord::Unbalance(m, ns) => rec.write(h_unb, m, t(ns), t(ns))?,
                        ToRecord::Probe(m, ns) => rec.write(h_probe, m, t(ns), t(ns))?,
                        ToRecord::Point(i, m, ns) => rec.write(h_points[*i], m, t(ns), t(ns))?,
                        ToRecord::Temperature(m, ns) => rec.write(h_oil, m, t(ns), t(ns))?,
                        ToRecord::Keyphasor(m, ns) => rec.write(h_keyphasor, m, t(ns), t(ns))?,
                        ToRecord::ProbeSignal(m, ns) => rec.write(h_signal, m, t(ns), t(ns))?,
                        ToRecord::Out(o, ns) => match o {
                            Outgoing::Journal(m) => rec.write(h_journal, m, t(ns), t(ns))?,
                            Outgoing::Film(m) => rec.write(h_film, m, t(ns), t(ns))?,
                            Outgoing::Orbit(m) => rec.write(h_orbit, m, t(ns), t(ns))?,
                            Outgoing::Warning(m) => rec.write(h_warning, m, t(ns), t(ns))?,
                            Outgoing::Diagnostics(m) => rec.write(h_diag, m, t(ns), t(ns))?,
                            Outgoing::Residual(m) => rec.write(h_residual, m, t(ns), t(ns))?,
                            Outgoing::Margin(m) => rec.write(h_margin, m, t(ns), t(ns))?,
                            Outgoing::Forecast(m) => rec.write(h_forecast, &**m, t(ns), t(ns))?,
                        },
                    }
                }
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
