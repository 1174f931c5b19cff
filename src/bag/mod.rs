//! Reading rosbag2 MCAP bags: a bag directory (metadata.yaml and one or more .mcap files, as
//! written by `ros2 bag record`, by rosbags or by the node) or a bare .mcap file. Messages come out
//! in receive-time order (the order `ros2 bag play` uses). A bag that is damaged part-way (cut off
//! by a crash, a bad chunk) yields every message before the damage and says what and where the
//! damage is; it is not an error unless nothing at all can be read.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a bag cannot be read at all.
#[derive(Debug, Error)]
pub enum BagError {
    /// The path cannot be read.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
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

/// Damage found while reading: where reading stopped and why.
#[derive(Debug, Clone, PartialEq)]
pub struct BagDamage {
    /// The damaged file.
    pub file: PathBuf,
    /// Messages of that file read before the damage.
    pub messages_before: usize,
    /// Receive time (ns since the epoch) of the last good message, if any.
    pub last_good_log_time_ns: Option<u64>,
    /// What the MCAP reader said.
    pub why: String,
}

impl std::fmt::Display for BagDamage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: damaged after message {} of this file",
            self.file.display(),
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
    /// Messages in receive-time order (ties keep file order).
    pub messages: Vec<BagMessage>,
    /// Damage found, one entry per damaged file.
    pub damage: Vec<BagDamage>,
    payloads: Vec<u8>,
}

impl Bag {
    /// Reads the bag at `path`: a bag directory or a bare .mcap file.
    pub fn read(path: &Path) -> Result<Self, BagError> {
        let files = mcap_files(path)?;
        let mut bag = Bag {
            files: files.clone(),
            ..Bag::default()
        };
        for file in &files {
            let bytes = std::fs::read(file).map_err(|source| BagError::Io {
                path: file.clone(),
                source,
            })?;
            bag.read_file(file, &bytes)?;
        }
        Ok(bag)
    }

    /// Reads one file's messages from `bytes` (an MCAP file's contents) and puts all messages
    /// in receive-time order again. Reading stops at the first damaged record, which is noted in
    /// [`Bag::damage`]; nothing read is an error only if the file has no message at all.
    pub fn read_file(&mut self, file: &Path, bytes: &[u8]) -> Result<(), BagError> {
        use mcap::records::Record;
        use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
        // the reader trusts the sizes a file declares: the limit keeps a damaged size from
        // making it allocate without bound; chunk CRCs catch damaged compressed data
        let mut reader = LinearReader::new_with_options(
            LinearReaderOptions::default()
                .with_record_length_limit(MAX_RECORD_BYTES)
                .with_validate_chunk_crcs(true),
        );
        let mut schemas: HashMap<u16, (String, String, Vec<u8>)> = HashMap::new();
        let mut channel_topic: HashMap<u16, usize> = HashMap::new();
        let messages_at_start = self.messages.len();
        let mut last_time = None;
        let mut rest = bytes;
        let mut failure = None;
        while let Some(event) = reader.next_event() {
            let (opcode, data) = match event {
                Ok(LinearReadEvent::ReadRequest(need)) => {
                    let n = need.min(rest.len());
                    reader.insert(n).copy_from_slice(&rest[..n]);
                    reader.notify_read(n);
                    rest = &rest[n..];
                    continue;
                }
                Ok(LinearReadEvent::Record { opcode, data }) => (opcode, data),
                Err(e) => {
                    failure = Some(e.to_string());
                    break;
                }
            };
            match mcap::parse_record(opcode, data) {
                Ok(Record::Schema { header, data }) => {
                    schemas.insert(header.id, (header.name, header.encoding, data.into_owned()));
                }
                Ok(Record::Channel(c)) => {
                    let (type_name, schema_encoding, schema) =
                        schemas.get(&c.schema_id).cloned().unwrap_or_default();
                    let topic = self.topic_index(BagTopic {
                        name: c.topic,
                        type_name,
                        schema_encoding,
                        schema,
                        message_encoding: c.message_encoding,
                        offered_qos_profiles: c.metadata.get("offered_qos_profiles").cloned(),
                    });
                    channel_topic.insert(c.id, topic);
                }
                Ok(Record::Message { header, data }) => {
                    let Some(&topic) = channel_topic.get(&header.channel_id) else {
                        failure = Some(format!(
                            "message {} names channel {}, which was never defined",
                            header.sequence, header.channel_id
                        ));
                        break;
                    };
                    let start = self.payloads.len();
                    self.payloads.extend_from_slice(&data);
                    self.messages.push(BagMessage {
                        topic,
                        log_time_ns: header.log_time,
                        publish_time_ns: header.publish_time,
                        start,
                        len: data.len(),
                    });
                    last_time = Some(header.log_time);
                }
                // the summary repeats schemas and channels; the rest is not needed to replay
                Ok(Record::DataEnd(_)) => break,
                Ok(_) => {}
                Err(e) => {
                    failure = Some(e.to_string());
                    break;
                }
            }
        }
        let read = self.messages.len() - messages_at_start;
        if let Some(why) = failure {
            if read == 0 {
                return Err(BagError::NotMcap {
                    path: file.to_path_buf(),
                    why,
                });
            }
            self.damage.push(BagDamage {
                file: file.to_path_buf(),
                messages_before: read,
                last_good_log_time_ns: last_time,
                why,
            });
        }
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

    /// First and last receive time (ns since the epoch), if any message.
    pub fn time_span_ns(&self) -> Option<(u64, u64)> {
        Some((
            self.messages.first()?.log_time_ns,
            self.messages.last()?.log_time_ns,
        ))
    }
}

/// The .mcap files of a bag: the file itself, or those metadata.yaml lists (falling back to the
/// directory's .mcap files when there is no usable metadata.yaml).
fn mcap_files(path: &Path) -> Result<Vec<PathBuf>, BagError> {
    let io = |source| BagError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_dir() {
        return check_compression(vec![path.to_path_buf()]);
    }
    let from_metadata = std::fs::read_to_string(path.join("metadata.yaml"))
        .ok()
        .and_then(|text| relative_file_paths(&text));
    let files = match from_metadata {
        Some(names) if !names.is_empty() => names.iter().map(|n| path.join(n)).collect(),
        _ => {
            let mut found: Vec<PathBuf> = std::fs::read_dir(path)
                .map_err(io)?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    let name = p.to_string_lossy();
                    name.ends_with(".mcap") || name.ends_with(".mcap.zstd")
                })
                .collect();
            found.sort();
            found
        }
    };
    if files.is_empty() {
        return Err(BagError::NoMcap(path.to_path_buf()));
    }
    check_compression(files)
}

fn check_compression(files: Vec<PathBuf>) -> Result<Vec<PathBuf>, BagError> {
    for f in &files {
        let name = f.to_string_lossy();
        if let Some(ext) = [".zstd", ".zst", ".lz4"]
            .iter()
            .find(|e| name.ends_with(*e))
        {
            return Err(BagError::Compressed {
                path: f.clone(),
                what: ext.trim_start_matches('.').into(),
            });
        }
    }
    Ok(files)
}

/// `rosbag2_bagfile_information.relative_file_paths` of a metadata.yaml.
fn relative_file_paths(text: &str) -> Option<Vec<String>> {
    let doc: serde_yaml_ng::Value = serde_yaml_ng::from_str(text).ok()?;
    let list = doc
        .get("rosbag2_bagfile_information")?
        .get("relative_file_paths")?
        .as_sequence()?;
    Some(
        list.iter()
            .filter_map(|v| v.as_str().map(str::to_string))
            .collect(),
    )
}

/// Largest record believed (bytes): 256 MiB. A damaged length above it is reported, not
/// allocated.
const MAX_RECORD_BYTES: usize = 256 << 20;
