//! Reading rosbag2 MCAP bags: a bag directory (metadata.yaml and one or more .mcap files, as
//! written by `ros2 bag record`, by rosbags or by the node) or a bare .mcap file. Messages come out
//! in receive-time order (the order `ros2 bag play` uses). A damaged bag (cut off by a crash, bad
//! chunks, flipped bits) yields every message of every intact chunk, never one of a chunk that
//! fails its CRC, and names each damaged byte range; it is an error only if nothing at all can
//! be read. metadata.yaml is checked, not trusted (see [`files`]).

mod files;
mod scan;
mod yaml;

pub use yaml::{check_yaml_shape, MAX_YAML_FLOW_DEPTH, MAX_YAML_INDENT};

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
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

/// One message: its topic (index into [`Bag::topics`]), receive time and CDR payload range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BagMessage {
    /// Index into [`Bag::topics`].
    pub topic: usize,
    /// Receive (log) time, ns since the epoch.
    pub log_time_ns: u64,
    /// Publish time, ns since the epoch.
    pub publish_time_ns: u64,
    start: usize,
    len: usize,
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

/// A bag read into memory.
#[derive(Debug, Clone, Default)]
pub struct Bag {
    /// The .mcap files read, in order.
    pub files: Vec<PathBuf>,
    /// Topics, in order of first appearance.
    pub topics: Vec<BagTopic>,
    /// Messages in receive-time order (ties keep file order), without the receive-time outliers
    /// of [`Bag::excluded`].
    pub messages: Vec<BagMessage>,
    /// Damage found: every damaged range of every file.
    pub damage: Vec<BagDamage>,
    /// What else was wrong and worked around: metadata.yaml naming missing, repeated or outside
    /// files; receive-time outliers left out. One sentence each.
    pub notes: Vec<String>,
    /// Messages left out because their receive time lies far outside the rest of the bag.
    pub excluded: Vec<BagMessage>,
    payloads: Vec<u8>,
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
            let read = files::read_regular(file).and_then(|bytes| bag.read_file(file, &bytes));
            if let Err(e) = read {
                bag.notes.push(format!("{e}; file skipped"));
                first_error.get_or_insert(e);
            }
        }
        if bag.messages.is_empty() {
            if let Some(e) = first_error {
                return Err(e);
            }
        }
        bag.exclude_time_outliers();
        Ok(bag)
    }

    /// Reads one file's messages from `bytes` (an MCAP file's contents) and puts all messages
    /// in receive-time order again. Every intact chunk is read; each damaged range is noted in
    /// [`Bag::damage`]; it is an error only if the file yields no message at all.
    pub fn read_file(&mut self, file: &Path, bytes: &[u8]) -> Result<(), BagError> {
        let content = scan::read_mcap(bytes, &mut self.payloads, MAX_RECORD_BYTES);
        let mut topic_of: HashMap<u16, usize> = HashMap::new();
        let mut ids: Vec<u16> = content.channels.keys().copied().collect();
        ids.sort_unstable();
        for id in ids {
            let c = &content.channels[&id];
            let (type_name, schema_encoding, schema) = content
                .schemas
                .get(&c.schema_id)
                .cloned()
                .unwrap_or_default();
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
        let mut orphans: BTreeMap<u16, usize> = BTreeMap::new();
        let mut read = 0;
        for m in &content.messages {
            let Some(&topic) = topic_of.get(&m.channel) else {
                *orphans.entry(m.channel).or_default() += 1;
                continue;
            };
            read += 1;
            self.messages.push(BagMessage {
                topic,
                log_time_ns: m.log_time_ns,
                publish_time_ns: m.publish_time_ns,
                start: m.start,
                len: m.len,
            });
        }
        let time_before = |k: usize| k.checked_sub(1).map(|i| content.messages[i].log_time_ns);
        let mut damage: Vec<BagDamage> = content
            .damage
            .iter()
            .map(|d| BagDamage {
                file: file.to_path_buf(),
                bytes: Some((d.start, d.end)),
                messages_before: d.messages_before,
                last_good_log_time_ns: time_before(d.messages_before),
                why: d.why.clone(),
            })
            .collect();
        for (channel, n) in orphans {
            damage.push(BagDamage {
                file: file.to_path_buf(),
                bytes: None,
                messages_before: content.messages.len(),
                last_good_log_time_ns: None,
                why: format!(
                    "{n} intact message(s) on channel {channel} left out: the channel's definition was in a damaged range"
                ),
            });
        }
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
        self.damage.extend(damage);
        self.messages.sort_by_key(|m| m.log_time_ns);
        Ok(())
    }

    fn topic_index(&mut self, topic: BagTopic) -> usize {
        if let Some(i) = self.topics.iter().position(|t| *t == topic) {
            return i;
        }
        self.topics.push(topic);
        self.topics.len() - 1
    }

    /// The CDR payload of `message`.
    pub fn payload(&self, message: &BagMessage) -> &[u8] {
        &self.payloads[message.start..message.start + message.len]
    }

    /// First and last receive time (ns since the epoch), if any message (outliers excluded, see
    /// [`Bag::exclude_time_outliers`]).
    pub fn time_span_ns(&self) -> Option<(u64, u64)> {
        Some((
            self.messages.first()?.log_time_ns,
            self.messages.last()?.log_time_ns,
        ))
    }

    /// Moves receive-time outliers from [`Bag::messages`] to [`Bag::excluded`] (with a note), so
    /// that one bad clock reading does not become the bag's start or end. The bulk of the bag is
    /// its middle half (the quartiles q1..q3 of the receive times); a message is an outlier if it
    /// lies more than max(1 h, 4·(q3 − q1)) outside it, and only if at most 1 % of the messages
    /// (at least one) are: a bag with two large groups of times is left as it is.
    pub fn exclude_time_outliers(&mut self) {
        let n = self.messages.len();
        if n < 4 {
            return;
        }
        let (q1, q3) = (
            self.messages[n / 4].log_time_ns,
            self.messages[(3 * n) / 4].log_time_ns,
        );
        let margin = (4 * (q3 - q1)).max(OUTLIER_MIN_MARGIN_NS);
        let (lo, hi) = (q1.saturating_sub(margin), q3.saturating_add(margin));
        let outside = |m: &BagMessage| m.log_time_ns < lo || m.log_time_ns > hi;
        let count = self.messages.iter().filter(|m| outside(m)).count();
        if count == 0 || count > (n / 100).max(1) {
            return;
        }
        let (excluded, kept): (Vec<BagMessage>, Vec<BagMessage>) =
            self.messages.iter().partition(|m| outside(m));
        let times: Vec<String> = excluded
            .iter()
            .take(5)
            .map(|m| {
                format!(
                    "{} at {:.3} s",
                    self.topics[m.topic].name,
                    m.log_time_ns as f64 * 1e-9
                )
            })
            .collect();
        self.notes.push(format!(
            "{count} message(s) with a receive time far outside the rest of the bag ({:.3} s to {:.3} s) left out: {}{}",
            kept.first().map_or(0.0, |m| m.log_time_ns as f64 * 1e-9),
            kept.last().map_or(0.0, |m| m.log_time_ns as f64 * 1e-9),
            times.join(", "),
            if count > 5 { ", …" } else { "" }
        ));
        self.messages = kept;
        self.excluded.extend(excluded);
    }
}

/// Smallest distance from the bulk of the bag's receive times at which a message counts as an
/// outlier: 1 h (ns).
const OUTLIER_MIN_MARGIN_NS: u64 = 3_600_000_000_000;

/// Largest record believed (bytes): 256 MiB. A damaged length above it is reported, not
/// allocated.
const MAX_RECORD_BYTES: usize = 256 << 20;
