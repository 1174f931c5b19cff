//! Reading rosbag2 MCAP bags: a bag directory (metadata.yaml and one or more .mcap files, as
//! written by `ros2 bag record`, by rosbags or by the node) or a bare .mcap file. Messages come out
//! in receive-time order (the order `ros2 bag play` uses). A damaged bag (cut off by a crash, bad
//! chunks, flipped bits) yields every message of every intact chunk, never one of a chunk that
//! fails its CRC, and names each damaged byte range; it is an error only if nothing at all can
//! be read. metadata.yaml is checked, not trusted (see [`files`]).

mod files;
mod scan;
mod source;
mod stream;
mod yaml;

pub use yaml::{check_yaml_shape, MAX_YAML_FLOW_DEPTH, MAX_YAML_INDENT};

use mcap::records::MessageHeader;
use scan::{Segment, Stats};
use source::Source;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
pub use stream::Messages;
use thiserror::Error;

/// Why a bag cannot be read at all.
#[derive(Debug, Error)]
pub enum BagError {
    /// The path cannot be read.
    #[error("{path}: {cause}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The cause (part of the message, so not also a `source`: reported once).
        cause: std::io::Error,
    },
    /// A directory without a .mcap file.
    #[error("{0}: no .mcap file in this directory (is it a rosbag2 bag recorded with the mcap storage?)")]
    NoMcap(PathBuf),
    /// A compressed bag (rosbag2 file compression), which is not supported.
    #[error("{path}: file-compressed bags ({what}) are not supported; decompress with `ros2 bag convert` first")]
    Compressed {
        /// The file.
        path: PathBuf,
        /// The compression found.
        what: String,
    },
    /// Not an MCAP file, or damaged before its first message.
    #[error("{path}: not a readable MCAP file: {why}")]
    NotMcap {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

/// One topic of the bag.
#[derive(Debug, Clone, PartialEq)]
pub struct BagTopic {
    /// Topic name, e.g. `/rotor_twin/speed`.
    pub name: String,
    /// ROS 2 type, e.g. `std_msgs/msg/Float64` (the schema name).
    pub type_name: String,
    /// Schema encoding, e.g. `ros2msg`.
    pub schema_encoding: String,
    /// Schema text (the message definition).
    pub schema: Vec<u8>,
    /// Message encoding, e.g. `cdr`.
    pub message_encoding: String,
    /// The channel metadata `offered_qos_profiles`, if recorded.
    pub offered_qos_profiles: Option<String>,
}

/// One message: its topic (index into [`Bag::topics`]), receive time and CDR payload.
#[derive(Debug, Clone, PartialEq)]
pub struct BagMessage {
    /// Index into [`Bag::topics`].
    pub topic: usize,
    /// Receive (log) time, ns since the epoch.
    pub log_time_ns: u64,
    /// Publish time, ns since the epoch.
    pub publish_time_ns: u64,
    data: Vec<u8>,
}

impl BagMessage {
    /// The CDR payload.
    pub fn payload(&self) -> &[u8] {
        &self.data
    }
}

/// A damaged part of a file: skipped, the intact records after it read.
#[derive(Debug, Clone, PartialEq)]
pub struct BagDamage {
    /// The damaged file.
    pub file: PathBuf,
    /// The damaged byte range `[start, end)` of the file, when the damage is one.
    pub bytes: Option<(usize, usize)>,
    /// Messages of that file read before the damage (in file order).
    pub messages_before: usize,
    /// Receive time (ns since the epoch) of the last good message before it, if any.
    pub last_good_log_time_ns: Option<u64>,
    /// What was wrong.
    pub why: String,
}

impl std::fmt::Display for BagDamage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: ", self.file.display())?;
        if let Some((a, b)) = self.bytes {
            write!(f, "bytes {a} to {b} unreadable, skipped; ")?;
        }
        write!(
            f,
            "damaged after message {} of this file",
            self.messages_before
        )?;
        if let Some(t) = self.last_good_log_time_ns {
            write!(f, " (last good receive time {:.6} s)", t as f64 * 1e-9)?;
        }
        write!(f, ": {}", self.why)
    }
}

/// A bag, indexed: its files, topics, damage and notes, and where each intact chunk lies with
/// the count and receive-time range of its messages. The messages themselves stay in the files
/// and are read chunk by chunk, in receive-time order, by [`Bag::messages`]; memory is bounded
/// by the chunks whose receive-time ranges overlap (for a recording in receive order, about one
/// per file) plus 100 bytes or so of index per chunk, whatever the bag's length.
#[derive(Debug, Clone, Default)]
pub struct Bag {
    /// The .mcap files of the bag, in order.
    pub files: Vec<PathBuf>,
    /// Topics, in order of first appearance.
    pub topics: Vec<BagTopic>,
    /// Damage found: every damaged range of every file.
    pub damage: Vec<BagDamage>,
    /// What else was wrong and worked around: metadata.yaml naming missing, repeated or outside
    /// files; receive-time outliers left out. One sentence each.
    pub notes: Vec<String>,
    /// the files read, and per file its channels' topics
    sources: Vec<(Source, HashMap<u16, usize>)>,
    /// intact chunks and runs of loose messages, in reading order (file by file)
    segments: Vec<Segment>,
    /// receive times outside this window are outliers, left out (None: none left out)
    window: Option<(u64, u64)>,
    /// messages delivered, per topic
    topic_counts: Vec<usize>,
}

impl Bag {
    /// Reads the bag at `path`: a bag directory or a bare .mcap file. A file that cannot be read
    /// at all is noted and skipped when another file of the bag can be read.
    pub fn read(path: &Path) -> Result<Self, BagError> {
        let listing = files::bag_files(path)?;
        let mut bag = Bag {
            files: listing.files.clone(),
            notes: listing.notes,
            ..Bag::default()
        };
        let mut first_error = None;
        for file in &listing.files {
            let read = files::open_regular(file).and_then(|src| bag.add_source(file, src));
            if let Err(e) = read {
                bag.notes.push(format!("{e}; file skipped"));
                first_error.get_or_insert(e);
            }
        }
        if bag.message_count() == 0 {
            if let Some(e) = first_error {
                return Err(e);
            }
        }
        bag.exclude_time_outliers();
        Ok(bag)
    }

    /// Adds one file whose contents are `bytes` (an MCAP file held in memory; tests and
    /// fuzzing), as [`Bag::read`] adds each file of a bag.
    pub fn read_file(&mut self, file: &Path, bytes: &[u8]) -> Result<(), BagError> {
        self.add_source(file, Source::Bytes(bytes.into()))
    }

    /// Indexes one file: every intact chunk is found; each damaged range is noted in
    /// [`Bag::damage`]; it is an error only if the file yields no message at all.
    fn add_source(&mut self, file: &Path, src: Source) -> Result<(), BagError> {
        let (index, read_error) = scan::index_mcap(&src, MAX_RECORD_BYTES);
        if let Some(cause) = read_error {
            return Err(BagError::Io {
                path: file.to_path_buf(),
                cause,
            });
        }
        let topic_of = self.add_topics(&index);
        let mut damage: Vec<BagDamage> = index
            .damage
            .iter()
            .map(|d| BagDamage {
                file: file.to_path_buf(),
                bytes: Some((d.start, d.end)),
                messages_before: d.messages_before,
                last_good_log_time_ns: d.last_good_log_time_ns,
                why: d.why.clone(),
            })
            .collect();
        let mut orphans: Vec<(u16, usize)> = index
            .channel_counts
            .iter()
            .filter(|(c, _)| !topic_of.contains_key(c))
            .map(|(&c, &n)| (c, n))
            .collect();
        orphans.sort_unstable();
        for &(channel, n) in &orphans {
            damage.push(BagDamage {
                file: file.to_path_buf(),
                bytes: None,
                messages_before: index.messages,
                last_good_log_time_ns: None,
                why: format!(
                    "{n} intact message(s) on channel {channel} left out: the channel's definition was in a damaged range"
                ),
            });
        }
        let read: usize = index.messages - orphans.iter().map(|o| o.1).sum::<usize>();
        if read == 0 && !damage.is_empty() {
            return Err(BagError::NotMcap {
                path: file.to_path_buf(),
                why: damage
                    .iter()
                    .map(|d| d.why.as_str())
                    .collect::<Vec<_>>()
                    .join("; "),
            });
        }
        for (c, n) in &index.channel_counts {
            if let Some(&t) = topic_of.get(c) {
                self.topic_counts[t] += n;
            }
        }
        self.damage.extend(damage);
        let k = self.sources.len();
        self.sources.push((src, topic_of));
        let first = self.segments.len();
        self.segments
            .extend(index.segments.into_iter().map(|s| Segment { file: k, ..s }));
        // a chunk with messages on an unknown channel: its counts without them
        for i in first..self.segments.len() {
            if orphans
                .iter()
                .any(|o| self.segments[i].channels.contains(&o.0))
            {
                self.reclassify(i);
            }
        }
        Ok(())
    }

    /// The topics of one file's channels (in order of channel id), added to [`Bag::topics`].
    fn add_topics(&mut self, index: &scan::FileIndex) -> HashMap<u16, usize> {
        let mut topic_of = HashMap::new();
        let mut ids: Vec<u16> = index.channels.keys().copied().collect();
        ids.sort_unstable();
        for id in ids {
            let c = &index.channels[&id];
            let (type_name, schema_encoding, schema) =
                index.schemas.get(&c.schema_id).cloned().unwrap_or_default();
            let topic = self.topic_index(BagTopic {
                name: c.topic.clone(),
                type_name,
                schema_encoding,
                schema,
                message_encoding: c.message_encoding.clone(),
                offered_qos_profiles: c.metadata.get("offered_qos_profiles").cloned(),
            });
            topic_of.insert(id, topic);
        }
        topic_of
    }

    fn topic_index(&mut self, topic: BagTopic) -> usize {
        if let Some(i) = self.topics.iter().position(|t| *t == topic) {
            return i;
        }
        self.topics.push(topic);
        self.topic_counts.push(0);
        self.topics.len() - 1
    }

    /// Messages delivered by [`Bag::messages`] (outliers excluded).
    pub fn message_count(&self) -> usize {
        self.segments.iter().map(|s| s.kept.count).sum()
    }

    /// Messages left out as receive-time outliers (delivered by [`Bag::excluded_messages`]).
    pub fn excluded_count(&self) -> usize {
        self.segments.iter().map(|s| s.outside.count).sum()
    }

    /// Messages delivered on topic `topic` (index into [`Bag::topics`]).
    pub fn topic_message_count(&self, topic: usize) -> usize {
        self.topic_counts.get(topic).copied().unwrap_or(0)
    }

    /// The messages in receive-time order (ties keep file order), without the receive-time
    /// outliers; read from the files chunk by chunk.
    pub fn messages(&self) -> Messages<'_> {
        Messages::new(self, false)
    }

    /// The receive-time outliers left out of [`Bag::messages`], in receive-time order.
    pub fn excluded_messages(&self) -> Messages<'_> {
        Messages::new(self, true)
    }

    /// First and last receive time (ns since the epoch), if any message (outliers excluded, see
    /// [`Bag::exclude_time_outliers`]).
    pub fn time_span_ns(&self) -> Option<(u64, u64)> {
        let kept = self.segments.iter().filter(|s| s.kept.count > 0);
        Some((
            kept.clone().map(|s| s.kept.min_ns).min()?,
            kept.map(|s| s.kept.max_ns).max()?,
        ))
    }

    /// The messages of segment `i` on known channels, in file order: (topic, header, payload).
    fn segment_messages(&self, i: usize) -> Result<Vec<(usize, MessageHeader, Vec<u8>)>, String> {
        let seg = &self.segments[i];
        let (src, topic_of) = &self.sources[seg.file];
        Ok(scan::read_segment(src, seg, MAX_RECORD_BYTES)?
            .into_iter()
            .filter_map(|(h, d)| topic_of.get(&h.channel_id).map(|&t| (t, h, d)))
            .collect())
    }

    /// Whether receive time `t` is delivered (inside the window, when there is one).
    fn in_window(&self, t: u64) -> bool {
        self.window.is_none_or(|(lo, hi)| lo <= t && t <= hi)
    }

    /// Counts segment `i`'s messages again (known channels; inside and outside the window);
    /// returns the outliers (receive time, position in the segment, topic). A segment that
    /// cannot be read back any more is noted and counts as empty.
    fn reclassify(&mut self, i: usize) -> Vec<(u64, usize, usize)> {
        let (mut kept, mut outside, mut out) = (Stats::default(), Stats::default(), Vec::new());
        match self.segment_messages(i) {
            Ok(messages) => {
                for (k, (topic, h, _)) in messages.iter().enumerate() {
                    if self.in_window(h.log_time) {
                        kept.add(h.log_time);
                    } else {
                        outside.add(h.log_time);
                        out.push((h.log_time, k, *topic));
                    }
                }
            }
            Err(why) => self.notes.push(format!(
                "{}: {why}; left out",
                self.files
                    .get(self.segments[i].file)
                    .map_or("a file".into(), |f| f.display().to_string())
            )),
        }
        self.segments[i].kept = kept;
        self.segments[i].outside = outside;
        out
    }

    /// The receive time of rank `k` (0-based) among the delivered messages, exactly, without
    /// holding them: the range that holds it is cut into [`SELECT_BINS`] bins, the messages
    /// counted per bin (a chunk lying within one bin counted from the index, only the others
    /// read), and the bin holding rank `k` cut again, until one time is left.
    fn time_of_rank(&self, k: usize) -> Option<u64> {
        let (mut lo, mut hi) = self.time_span_ns()?;
        while lo < hi {
            let width = (hi - lo) / SELECT_BINS as u64 + 1;
            let bin = |t: u64| ((t - lo) / width) as usize;
            let (mut below, mut hist) = (0usize, vec![0usize; SELECT_BINS]);
            for (i, s) in self.segments.iter().enumerate() {
                let st = s.kept;
                if st.count == 0 || st.min_ns > hi {
                } else if st.max_ns < lo {
                    below += st.count;
                } else if st.min_ns >= lo && st.max_ns <= hi && bin(st.min_ns) == bin(st.max_ns) {
                    hist[bin(st.min_ns)] += st.count;
                } else {
                    for (_, h, _) in self.segment_messages(i).unwrap_or_default() {
                        let t = h.log_time;
                        if t < lo {
                            below += 1;
                        } else if t <= hi && self.in_window(t) {
                            hist[bin(t)] += 1;
                        }
                    }
                }
            }
            let mut acc = below;
            let b = hist.iter().position(|&c| {
                acc += c;
                acc > k
            })?;
            lo += b as u64 * width;
            hi = hi.min(lo + (width - 1));
        }
        Some(lo)
    }

    /// Leaves receive-time outliers out of [`Bag::messages`] (with a note; they are still
    /// delivered by [`Bag::excluded_messages`]), so that one bad clock reading does not become the
    /// bag's start or end. The bulk of the bag is its middle half (the quartiles q1..q3 of the
    /// receive times); a message is an outlier if it lies more than max(1 h, 4·(q3 − q1))
    /// outside it, and only if at most 1 % of the messages (at least one) are: a bag with two
    /// large groups of times is left as it is.
    pub fn exclude_time_outliers(&mut self) {
        let n = self.message_count();
        if n < 4 || self.window.is_some() {
            return;
        }
        let (Some(q1), Some(q3)) = (self.time_of_rank(n / 4), self.time_of_rank((3 * n) / 4))
        else {
            return;
        };
        let margin = (4 * (q3 - q1)).max(OUTLIER_MIN_MARGIN_NS);
        let (lo, hi) = (q1.saturating_sub(margin), q3.saturating_add(margin));
        let outside = |s: &Segment| s.kept.count > 0 && (s.kept.min_ns < lo || s.kept.max_ns > hi);
        let straddling: Vec<usize> = (0..self.segments.len())
            .filter(|&i| outside(&self.segments[i]))
            .collect();
        let saved: Vec<Segment> = straddling
            .iter()
            .map(|&i| self.segments[i].clone())
            .collect();
        self.window = Some((lo, hi));
        let mut excluded = Vec::new();
        for &i in &straddling {
            let found = self.reclassify(i);
            excluded.extend(found.into_iter().map(|(t, k, topic)| (t, i, k, topic)));
        }
        let count = excluded.len();
        if count == 0 || count > (n / 100).max(1) {
            // not outliers: the bag as it was
            self.window = None;
            for (&i, s) in straddling.iter().zip(saved) {
                self.segments[i] = s;
            }
            return;
        }
        excluded.sort_unstable();
        for &(_, _, _, topic) in &excluded {
            self.topic_counts[topic] -= 1;
        }
        self.note_outliers(&excluded);
    }

    /// The note on the outliers left out (receive time, segment, position, topic; sorted).
    fn note_outliers(&mut self, excluded: &[(u64, usize, usize, usize)]) {
        let count = excluded.len();
        let times: Vec<String> = excluded
            .iter()
            .take(5)
            .map(|&(t, _, _, topic)| {
                format!("{} at {:.3} s", self.topics[topic].name, t as f64 * 1e-9)
            })
            .collect();
        let (a, z) = self.time_span_ns().unwrap_or_default();
        self.notes.push(format!(
            "{count} message(s) with a receive time far outside the rest of the bag ({:.3} s to {:.3} s) left out: {}{}",
            a as f64 * 1e-9,
            z as f64 * 1e-9,
            times.join(", "),
            if count > 5 { ", …" } else { "" }
        ));
    }
}

/// Bins per pass of the exact selection of the quartiles ([`Bag::time_of_rank`]): 1024 (so at
/// most 7 passes for 64-bit times; for a recording in receive order 2 or 3, reading only the
/// chunks that straddle a bin).
const SELECT_BINS: usize = 1024;

/// Smallest distance from the bulk of the bag's receive times at which a message counts as an
/// outlier: 1 h (ns).
const OUTLIER_MIN_MARGIN_NS: u64 = 3_600_000_000_000;

/// Largest record believed (bytes): 256 MiB. A damaged length above it is reported, not
/// allocated.
const MAX_RECORD_BYTES: usize = 256 << 20;
