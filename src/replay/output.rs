//! The replay's output bag, written on a thread of its own (issue 17): the replay hands each
//! message, owned, to [`OutputWriter`], which passes them in batches through a bounded channel
//! to a thread that serialises them, frames them in MCAP chunks, compresses and writes them. One
//! channel and one writer keep the order; what is written is what the replay wrote itself
//! before (the same records in the same order: the same bytes). The channel holds at most
//! [`BATCHES_IN_FLIGHT`] batches of [`BATCH_RECORDS`] messages, so a writer that falls behind
//! holds the replay back instead of growing the memory. metadata.yaml is written when the bag
//! is created, as before, so a run killed part-way leaves a bag directory that `rotor-twin bag
//! recover` makes whole; a write that fails stops the replay with the writer's error at the
//! next hand-over.

use super::{ReplayError, ReplayOptions, Role};
use crate::bag::{Bag, BagMessage};
use crate::messages;
use crate::record::{RecordError, Recorder};
use crate::rotor::Rotor;
use crate::session::Outgoing;
use std::sync::mpsc::{channel, sync_channel, Receiver, Sender, SyncSender};
use std::thread::JoinHandle;

/// Messages a batch carries to the writer thread: a hand-over (a channel operation, possibly
/// a wake-up of the writer) every few hundred messages, not at each.
const BATCH_RECORDS: usize = 256;
/// Batches the channel holds at most: the bound of the memory between the replay and the
/// writer (≈ 2,000 messages; on the 10-minute bag the replay's peak RSS is 96.5 MB, main's
/// 101–108 MB with the bag written on the replay's thread).
const BATCHES_IN_FLIGHT: usize = 8;

/// One message for the output bag.
enum Record {
    /// A prediction of the twin.
    Outgoing(Outgoing),
    /// An input message of the bag (written if the twin uses its topic).
    Input(BagMessage),
}

/// The output bag written on a thread of its own: [`Self::outgoing`] and [`Self::input`] in the
/// order the replay has them, then [`Self::finish`].
pub(super) struct OutputWriter {
    batch: Vec<Record>,
    /// the bag's topics the output bag records (the rest are not handed over)
    recorded: Vec<bool>,
    to_writer: Option<SyncSender<Vec<Record>>>,
    /// emptied batches coming back for reuse
    spare: Receiver<Vec<Record>>,
    thread: Option<JoinHandle<Result<u64, ReplayError>>>,
}

impl OutputWriter {
    /// Starts the writer thread of `bag`.
    pub(super) fn start(bag: OutputBag, dir: &std::path::Path) -> Result<Self, ReplayError> {
        let recorded = bag.inputs.iter().map(Option::is_some).collect();
        let (to_writer, batches) = sync_channel(BATCHES_IN_FLIGHT);
        let (give_back, spare) = channel();
        let thread = std::thread::Builder::new()
            .name("replay-bag".into())
            .spawn(move || write_batches(bag, batches, give_back))
            .map_err(|cause| RecordError::Io {
                path: dir.to_path_buf(),
                cause,
            })?;
        Ok(Self {
            batch: Vec::with_capacity(BATCH_RECORDS),
            recorded,
            to_writer: Some(to_writer),
            spare,
            thread: Some(thread),
        })
    }

    /// A prediction of the twin, to be written.
    pub(super) fn outgoing(&mut self, o: Outgoing) -> Result<(), ReplayError> {
        self.push(Record::Outgoing(o))
    }

    /// An input message, to be written if its topic is recorded.
    pub(super) fn input(&mut self, m: BagMessage) -> Result<(), ReplayError> {
        match self.recorded.get(m.topic) {
            Some(true) => self.push(Record::Input(m)),
            _ => Ok(()),
        }
    }

    fn push(&mut self, r: Record) -> Result<(), ReplayError> {
        self.batch.push(r);
        if self.batch.len() < BATCH_RECORDS {
            return Ok(());
        }
        self.hand_over()
    }

    /// The batch to the writer (a spare one, or a new one, takes its place); the writer's error
    /// if it has stopped.
    fn hand_over(&mut self) -> Result<(), ReplayError> {
        let next = self
            .spare
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH_RECORDS));
        let batch = std::mem::replace(&mut self.batch, next);
        let sent = match &self.to_writer {
            Some(tx) => tx.send(batch).is_ok(),
            None => false,
        };
        match sent {
            true => Ok(()),
            // the writer stopped at an error: that error
            false => self.join().map(|_| ()),
        }
    }

    /// The rest handed over, the bag closed; returns the number of messages written.
    pub(super) fn finish(mut self) -> Result<u64, ReplayError> {
        if !self.batch.is_empty() {
            self.hand_over()?;
        }
        self.to_writer = None;
        self.join()
    }

    /// Waits for the writer thread (the channel closed or the thread stopped): its count or its
    /// error.
    fn join(&mut self) -> Result<u64, ReplayError> {
        self.to_writer = None;
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => Err(ReplayError::Record(RecordError::Write {
                path: std::path::PathBuf::new(),
                why: "the output bag's writer has already stopped".into(),
            })),
        }
    }
}

impl Drop for OutputWriter {
    /// A replay that stops early (an error) still closes the bag: what was handed over is
    /// written and the summary follows.
    fn drop(&mut self) {
        self.to_writer = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The writer thread: every batch into `bag`, in the order received, the emptied batch given
/// back; the bag closed when the channel closes. Stops at the first error (the channel then
/// refuses the next batch).
fn write_batches(
    mut bag: OutputBag,
    batches: Receiver<Vec<Record>>,
    give_back: Sender<Vec<Record>>,
) -> Result<u64, ReplayError> {
    for mut batch in batches {
        for r in batch.drain(..) {
            match r {
                Record::Outgoing(o) => bag.write_outgoing(&o)?,
                Record::Input(m) => bag.write_input(&m)?,
            }
        }
        // the replay may be done with its spares: nothing to give back to then
        let _ = give_back.send(batch);
    }
    bag.finish()
}

/// The output bag: the inputs used (under the twin's topic names) and every prediction.
pub(super) struct OutputBag {
    rec: Recorder,
    inputs: Vec<Option<usize>>,
    journal: usize,
    film: usize,
    orbit: usize,
    /// each bearing's orbit topic for viewers, and the rule that fills them (as the node's)
    bearing_orbits: Vec<usize>,
    orbit_routes: crate::viewer::BearingOrbits,
    warning: usize,
    residual: usize,
    margin: usize,
    /// the forecast topic, when forecasting
    forecast: Option<usize>,
}

impl OutputBag {
    pub(super) fn create(
        dir: &std::path::Path,
        bag: &Bag,
        rotor: &Rotor,
        roles: &[Role],
        options: &ReplayOptions,
    ) -> Result<Self, ReplayError> {
        let mut rec = Recorder::create(dir)?;
        let mut inputs = Vec::with_capacity(roles.len());
        for (t, role) in bag.topics.iter().zip(roles) {
            let name = options
                .remaps
                .iter()
                .find(|(from, _)| *from == t.name)
                .map_or(t.name.as_str(), |(_, to)| to.as_str());
            inputs.push(if *role == Role::Other {
                None
            } else {
                Some(rec.add_topic_raw(
                    name,
                    &t.type_name,
                    &t.schema_encoding,
                    &t.schema,
                    crate::topics::INPUT_RECORDED,
                )?)
            });
        }
        use crate::topics;
        let orbit_routes = crate::viewer::BearingOrbits::new(rotor);
        let bearing_orbits = orbit_routes
            .topics()
            .iter()
            .map(|t| rec.add_topic::<messages::Orbit>(t, topics::STATE))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            bearing_orbits,
            orbit_routes,
            journal: rec.add_topic::<messages::JournalState>(topics::JOURNAL, topics::STATE)?,
            film: rec.add_topic::<messages::FilmState>(topics::FILM, topics::STATE)?,
            orbit: rec.add_topic::<messages::Orbit>(topics::ORBIT, topics::STATE)?,
            warning: rec
                .add_topic::<messages::InstabilityWarning>(topics::WARNING, topics::WARNING_QOS)?,
            residual: rec.add_topic::<messages::OrbitResidual>(topics::RESIDUAL, topics::STATE)?,
            margin: rec
                .add_topic::<messages::StabilityMargin>(topics::MARGIN, topics::MARGIN_QOS)?,
            forecast: match options.forecast {
                Some(_) => Some(
                    rec.add_topic::<messages::Forecast>(topics::FORECAST, topics::FORECAST_QOS)?,
                ),
                None => None,
            },
            rec,
            inputs,
        })
    }

    fn write_input(&mut self, m: &BagMessage) -> Result<(), ReplayError> {
        if let Some(h) = self.inputs[m.topic] {
            self.rec
                .write_cdr(h, m.payload(), m.log_time_ns, m.publish_time_ns)?;
        }
        Ok(())
    }

    fn write_outgoing(&mut self, o: &Outgoing) -> Result<(), ReplayError> {
        let t = |h: &messages::Header| h.stamp.as_nanos().max(0) as u64;
        if let Outgoing::Orbit(m) = o {
            if let Some(k) = self.orbit_routes.route(m) {
                let h = self.bearing_orbits[k];
                self.rec.write(h, m, t(&m.header), t(&m.header))?;
            }
        }
        match o {
            Outgoing::Journal(m) => self.rec.write(self.journal, m, t(&m.header), t(&m.header)),
            Outgoing::Film(m) => self.rec.write(self.film, m, t(&m.header), t(&m.header)),
            Outgoing::Orbit(m) => self.rec.write(self.orbit, m, t(&m.header), t(&m.header)),
            Outgoing::Warning(m) => self.rec.write(self.warning, m, t(&m.header), t(&m.header)),
            Outgoing::Residual(m) => self.rec.write(self.residual, m, t(&m.header), t(&m.header)),
            Outgoing::Margin(m) => self.rec.write(self.margin, m, t(&m.header), t(&m.header)),
            Outgoing::Forecast(m) => match self.forecast {
                Some(h) => self.rec.write(h, &**m, t(&m.header), t(&m.header)),
                None => Ok(()),
            },
            // the replay has no diagnostics of its own
            Outgoing::Diagnostics(_) => Ok(()),
        }?;
        Ok(())
    }

    /// Closes the bag; returns the number of messages written.
    fn finish(self) -> Result<u64, ReplayError> {
        let total = self.rec.counts().iter().map(|(_, c)| c).sum();
        self.rec.finish()?;
        Ok(total)
    }
}
