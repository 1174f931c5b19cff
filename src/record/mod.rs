//! Recording to MCAP in the rosbag2 conventions: a bag directory with `<name>_0.mcap` (profile
//! `ros2`, CDR messages, `ros2msg` schemas, each channel's `offered_qos_profiles` and RIHS01
//! `topic_type_hash`) and `metadata.yaml` (rosbag2 version 9, with each type's
//! `type_description_hash`). metadata.yaml is written when the recording starts and
//! rewritten at every flush (the node flushes at least every second), so a killed process loses at
//! most the last chunk and leaves a bag directory that [`recover`] (`rotor-twin bag recover`)
//! makes whole; [`Recorder::finish`] writes the summary and the final metadata. A write that fails
//! (a full disk) is returned as [`RecordError::Write`], naming the file: the caller must stop
//! and say so; what was flushed before stays readable.

mod recover;
mod split;

pub use recover::{recover, resolved_path, RecoverError, Recovered};
pub use split::{SplitLimits, DEFAULT_MAX_BAGFILE_BYTES, MIN_MAX_BAGFILE_BYTES};

use split::{FileEntry, McapWriter, SizedFile};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use crate::messages::RosMessage;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// QoS a topic is offered with, as rosbag2 records it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TopicQos {
    /// Depth of a keep-last history.
    pub depth: u32,
    /// Reliable (else best effort).
    pub reliable: bool,
    /// Transient local (else volatile): late joiners get the last samples.
    pub transient_local: bool,
}

impl TopicQos {
    /// Reliable, volatile, keep last `depth`.
    pub const fn reliable(depth: u32) -> Self {
        Self {
            depth,
            reliable: true,
            transient_local: false,
        }
    }

    /// Reliable, transient local, keep last `depth` (latched).
    pub const fn latched(depth: u32) -> Self {
        Self {
            depth,
            reliable: true,
            transient_local: true,
        }
    }

    /// Best effort, volatile, keep last `depth` (sensor data).
    pub const fn sensor(depth: u32) -> Self {
        Self {
            depth,
            reliable: false,
            transient_local: false,
        }
    }

    /// rosbag2's YAML list for this QoS (one profile).
    pub fn rosbag2_yaml(&self) -> String {
        let zero = "{sec: 0, nsec: 0}";
        format!(
            "- history: keep_last\n  depth: {}\n  reliability: {}\n  durability: {}\n  deadline: {zero}\n  lifespan: {zero}\n  liveliness: automatic\n  liveliness_lease_duration: {zero}\n  avoid_ros_namespace_conventions: false\n",
            self.depth,
            if self.reliable { "reliable" } else { "best_effort" },
            if self.transient_local { "transient_local" } else { "volatile" },
        )
    }
}

/// A topic being recorded.
#[derive(Debug, Clone)]
struct TopicEntry {
    name: String,
    type_name: String,
    /// schema encoding and text (to define the topic again in each new file)
    encoding: String,
    schema: Vec<u8>,
    /// RIHS01 type hash ('' where the schema could not be hashed).
    type_hash: String,
    qos: TopicQos,
    channel: u16,
    count: u64,
}

/// Why recording failed.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// File-system trouble, with the path.
    #[error("{path}: {cause}")]
    Io {
        /// The path concerned.
        path: PathBuf,
        /// The error (part of the message, so not also a `source`: reported once).
        cause: std::io::Error,
    },
    /// The MCAP writer failed (its message is part of this one: reported once).
    #[error("MCAP writer: {0}")]
    Mcap(mcap::McapError),
    /// A message could not be encoded.
    #[error("encoding a {type_name} for {topic}: {why}")]
    Encode {
        /// Topic.
        topic: String,
        /// Type.
        type_name: String,
        /// Why.
        why: String,
    },
    /// Writing the recording failed (a full disk, a lost device): the recording cannot go on.
    #[error("{path}: the recording failed and stops: {why}; what was flushed before is readable (`rotor-twin bag recover` makes it a complete bag)")]
    Write {
        /// The file being written.
        path: PathBuf,
        /// What the writer said.
        why: String,
    },
    /// A topic was written before it was added.
    #[error("topic {0} was not added to the recording")]
    UnknownTopic(String),
}

impl From<mcap::McapError> for RecordError {
    fn from(e: mcap::McapError) -> Self {
        Self::Mcap(e)
    }
}

/// Writes one bag directory: `<name>_0.mcap`, and `<name>_1.mcap`, … when a file reaches the
/// recording's [`SplitLimits`].
pub struct Recorder {
    dir: PathBuf,
    /// the directory's name, the files' stem
    stem: String,
    split: SplitLimits,
    writer: McapWriter,
    /// how large the current file has grown (bytes)
    size: Arc<AtomicU64>,
    /// every file so far, the current one last
    files: Vec<FileEntry>,
    topics: Vec<TopicEntry>,
    sequence: u32,
    last_flush: Instant,
    custom_data: BTreeMap<String, String>,
}

/// Opens `path` for the MCAP writer, in the rosbag2 conventions.
fn open_writer(path: &Path) -> Result<(McapWriter, Arc<AtomicU64>), RecordError> {
    let file = File::create(path).map_err(|cause| RecordError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    let (file, size) = SizedFile::new(file);
    let writer = mcap::WriteOptions::new()
        .profile("ros2")
        .library("rotor-twin")
        // chunks of 64 KiB: a file cut off (a crash, a full disk) loses at most that much
        .chunk_size(Some(64 * 1024))
        .create(BufWriter::new(file))
        .map_err(|e| write_failed(path, e))?;
    Ok((writer, size))
}

/// A writer error with its causes in one message (the I/O error, e.g. "No space left on
/// device", is the MCAP error's source).
fn write_failed(path: &Path, e: mcap::McapError) -> RecordError {
    let mut why = e.to_string();
    let mut cause = std::error::Error::source(&e);
    while let Some(c) = cause {
        why = format!("{why}: {c}");
        cause = c.source();
    }
    RecordError::Write {
        path: path.to_path_buf(),
        why,
    }
}

impl Recorder {
    /// Creates bag directory `dir` (which must not exist yet, as with `ros2 bag record -o`),
    /// split into files of [`DEFAULT_MAX_BAGFILE_BYTES`].
    pub fn create(dir: &Path) -> Result<Self, RecordError> {
        Self::create_split(dir, SplitLimits::default())
    }

    /// Creates bag directory `dir`, going on in a new file whenever one reaches `split`.
    pub fn create_split(dir: &Path, split: SplitLimits) -> Result<Self, RecordError> {
        let io = |cause| RecordError::Io {
            path: dir.to_path_buf(),
            cause,
        };
        if dir.exists() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "bag directory already exists",
            )));
        }
        std::fs::create_dir_all(dir).map_err(io)?;
        let stem = dir
            .file_name()
            .map_or("rotor_twin".into(), |s| s.to_string_lossy().into_owned());
        let file_name = format!("{stem}_0.mcap");
        let (writer, size) = open_writer(&dir.join(&file_name))?;
        let rec = Self {
            dir: dir.to_path_buf(),
            stem,
            split,
            writer,
            size,
            files: vec![FileEntry::new(file_name)],
            topics: Vec::new(),
            sequence: 0,
            last_flush: Instant::now(),
            custom_data: BTreeMap::new(),
        };
        rec.write_metadata()?;
        Ok(rec)
    }

    /// The .mcap file being written.
    pub fn file(&self) -> PathBuf {
        let current = self.files.last().map_or("", |f| f.name.as_str());
        self.dir.join(current)
    }

    /// Every .mcap file of the recording so far, the one being written last.
    pub fn files(&self) -> Vec<PathBuf> {
        self.files.iter().map(|f| self.dir.join(&f.name)).collect()
    }

    fn failed(&self, e: mcap::McapError) -> RecordError {
        write_failed(&self.file(), e)
    }

    /// Finishes the current file (its summary written) and goes on in the next one, with every
    /// topic defined again; metadata.yaml then lists it.
    fn roll_over(&mut self) -> Result<(), RecordError> {
        let name = format!("{}_{}.mcap", self.stem, self.files.len());
        let (mut writer, size) = open_writer(&self.dir.join(&name))?;
        for t in &mut self.topics {
            t.channel = define_topic(&mut writer, t)?;
        }
        let done = self.file();
        let mut old = std::mem::replace(&mut self.writer, writer);
        self.size = size;
        self.files.push(FileEntry::new(name));
        old.finish().map_err(|e| write_failed(&done, e))?;
        std::io::Write::flush(&mut old.into_inner())
            .map_err(|e| write_failed(&done, mcap::McapError::Io(e)))?;
        self.write_metadata()
    }

    /// Writes metadata.yaml as the recording stands (atomically: a kill while writing leaves
    /// the previous one).
    fn write_metadata(&self) -> Result<(), RecordError> {
        let path = self.dir.join("metadata.yaml");
        let tmp = self.dir.join(".metadata.yaml.partial");
        std::fs::write(&tmp, self.metadata_yaml())
            .and_then(|()| std::fs::rename(&tmp, &path))
            .map_err(|cause| RecordError::Io { path, cause })
    }

    /// Adds topic `name` of type `T` offered with `qos`; returns its handle. Adding the same name
    /// twice returns the first handle.
    pub fn add_topic<T: RosMessage>(
        &mut self,
        name: &str,
        qos: TopicQos,
    ) -> Result<usize, RecordError> {
        let schema = T::schema();
        self.add_channel(
            name,
            T::TYPE_NAME,
            "ros2msg",
            schema.as_bytes(),
            T::type_hash(),
            qos,
        )
    }

    /// Adds topic `name` with a schema given as is (to copy a topic from another bag): ROS type
    /// `type_name`, schema `encoding` and `schema` text. Its RIHS01 hash is computed from a
    /// `ros2msg` schema ('' for another encoding or a schema that does not parse). Returns its
    /// handle; adding the same name twice returns the first handle.
    pub fn add_topic_raw(
        &mut self,
        name: &str,
        type_name: &str,
        encoding: &str,
        schema: &[u8],
        qos: TopicQos,
    ) -> Result<usize, RecordError> {
        let hash = match (encoding, std::str::from_utf8(schema)) {
            ("ros2msg", Ok(text)) => {
                crate::messages::type_hash::rihs01(type_name, text).unwrap_or_default()
            }
            _ => String::new(),
        };
        self.add_channel(name, type_name, encoding, schema, hash, qos)
    }

    /// The channel (and its schema) of a new topic, with the metadata rosbag2 Jazzy writes:
    /// `offered_qos_profiles` and `topic_type_hash`.
    fn add_channel(
        &mut self,
        name: &str,
        type_name: &str,
        encoding: &str,
        schema: &[u8],
        type_hash: String,
        qos: TopicQos,
    ) -> Result<usize, RecordError> {
        if let Some(i) = self.topics.iter().position(|t| t.name == name) {
            return Ok(i);
        }
        let mut entry = TopicEntry {
            name: name.into(),
            type_name: type_name.into(),
            encoding: encoding.into(),
            schema: schema.to_vec(),
            type_hash,
            qos,
            channel: 0,
            count: 0,
        };
        entry.channel = define_topic(&mut self.writer, &entry)?;
        self.topics.push(entry);
        Ok(self.topics.len() - 1)
    }

    /// Notes `key: value` about the whole bag: in metadata.yaml's `custom_data` (as `ros2 bag
    /// record --custom-data` does) and in an MCAP metadata record named `rotor_twin`.
    pub fn set_custom_data(&mut self, key: &str, value: &str) {
        self.custom_data.insert(key.into(), value.into());
    }

    /// Records `message` on topic handle `topic`, received at `log_time_ns` and sent at
    /// `publish_time_ns` (ns since the epoch).
    pub fn write<T: Serialize>(
        &mut self,
        topic: usize,
        message: &T,
        log_time_ns: u64,
        publish_time_ns: u64,
    ) -> Result<(), RecordError> {
        let entry = self
            .topics
            .get(topic)
            .ok_or_else(|| RecordError::UnknownTopic(format!("#{topic}")))?;
        let bytes = crate::messages::to_cdr(message).map_err(|why| RecordError::Encode {
            topic: entry.name.clone(),
            type_name: entry.type_name.clone(),
            why,
        })?;
        self.write_cdr(topic, &bytes, log_time_ns, publish_time_ns)
    }

    /// Records an already encoded CDR payload (with its encapsulation header).
    pub fn write_cdr(
        &mut self,
        topic: usize,
        cdr: &[u8],
        log_time_ns: u64,
        publish_time_ns: u64,
    ) -> Result<(), RecordError> {
        if topic >= self.topics.len() {
            return Err(RecordError::UnknownTopic(format!("#{topic}")));
        }
        let current = self.files.last().and_then(|f| f.first_ns);
        if (self.split).full(self.size.load(Ordering::Relaxed), current, log_time_ns) {
            self.roll_over()?;
        }
        self.sequence = self.sequence.wrapping_add(1);
        let channel = self.topics[topic].channel;
        self.writer
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: channel,
                    sequence: self.sequence,
                    log_time: log_time_ns,
                    publish_time: publish_time_ns,
                },
                cdr,
            )
            .map_err(|e| self.failed(e))?;
        self.topics[topic].count += 1;
        if let Some(f) = self.files.last_mut() {
            f.note(log_time_ns);
        }
        Ok(())
    }

    /// Closes the current chunk and rewrites metadata.yaml if `every` has passed since the last
    /// flush, so that a killed process loses at most that much.
    pub fn flush_if_due(&mut self, every: Duration) -> Result<(), RecordError> {
        if self.last_flush.elapsed() >= every {
            self.flush()?;
        }
        Ok(())
    }

    /// Closes the current chunk (written to the file) and rewrites metadata.yaml.
    pub fn flush(&mut self) -> Result<(), RecordError> {
        self.writer.flush().map_err(|e| self.failed(e))?;
        self.last_flush = Instant::now();
        self.write_metadata()
    }

    /// Messages recorded per topic so far.
    pub fn counts(&self) -> Vec<(String, u64)> {
        self.topics
            .iter()
            .map(|t| (t.name.clone(), t.count))
            .collect()
    }

    /// Writes the summary section and `metadata.yaml`. Returns the bag directory.
    pub fn finish(mut self) -> Result<PathBuf, RecordError> {
        if !self.custom_data.is_empty() {
            let m = mcap::records::Metadata {
                name: "rotor_twin".into(),
                metadata: self.custom_data.clone(),
            };
            self.writer.write_metadata(&m).map_err(|e| self.failed(e))?;
        }
        self.writer.finish().map_err(|e| self.failed(e))?;
        self.write_metadata()?;
        Ok(self.dir)
    }

    fn metadata_yaml(&self) -> String {
        let start = self
            .files
            .iter()
            .filter_map(|f| f.first_ns)
            .min()
            .unwrap_or(0);
        let last = self.files.iter().map(|f| f.last_ns).max().unwrap_or(0);
        let duration = last.saturating_sub(start);
        let total: u64 = self.topics.iter().map(|t| t.count).sum();
        let mut topics = String::new();
        for t in &self.topics {
            let qos: String = t
                .qos
                .rosbag2_yaml()
                .lines()
                .map(|l| format!("        {l}\n"))
                .collect();
            topics.push_str(&format!(
                "  - message_count: {}\n    topic_metadata:\n      name: {}\n      offered_qos_profiles:\n{qos}      serialization_format: cdr\n      type: {}\n      type_description_hash: {}\n",
                t.count,
                t.name,
                t.type_name,
                if t.type_hash.is_empty() { "''" } else { &t.type_hash }
            ));
        }
        let paths: String = self
            .files
            .iter()
            .map(|f| format!("  - {}\n", f.name))
            .collect();
        let files: String = self
            .files
            .iter()
            .map(|f| {
                let first = f.first_ns.unwrap_or(start);
                format!(
                    "  - path: {}\n    starting_time:\n      nanoseconds_since_epoch: {first}\n    duration:\n      nanoseconds: {}\n    message_count: {}\n",
                    f.name,
                    f.last_ns.saturating_sub(first),
                    f.count
                )
            })
            .collect();
        format!(
            "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: mcap\n  duration:\n    nanoseconds: {duration}\n  starting_time:\n    nanoseconds_since_epoch: {start}\n  message_count: {total}\n  topics_with_message_count:\n{topics}  compression_format: ''\n  compression_mode: ''\n  relative_file_paths:\n{paths}  files:\n{files}  custom_data: {custom}\n  ros_distro: jazzy\n",
            custom = self.custom_data_yaml()
        )
    }

    /// metadata.yaml's `custom_data`.
    fn custom_data_yaml(&self) -> String {
        if self.custom_data.is_empty() {
            return "{}".to_string();
        }
        // JSON strings are valid YAML scalars (quotes and escapes included)
        let quote = |v: &String| serde_json::to_string(v).unwrap_or_default();
        self.custom_data
            .iter()
            .map(|(k, v)| format!("\n    {}: {}", quote(k), quote(v)))
            .collect()
    }
}

/// Defines topic `t` (its schema and channel, with the metadata rosbag2 Jazzy writes:
/// `offered_qos_profiles` and `topic_type_hash`) in `writer`; returns its channel id.
fn define_topic(writer: &mut McapWriter, t: &TopicEntry) -> Result<u16, RecordError> {
    let schema = writer.add_schema(&t.type_name, &t.encoding, &t.schema)?;
    let metadata = BTreeMap::from([
        ("offered_qos_profiles".to_string(), t.qos.rosbag2_yaml()),
        ("topic_type_hash".to_string(), t.type_hash.clone()),
    ]);
    Ok(writer.add_channel(schema, &t.name, "cdr", &metadata)?)
}
