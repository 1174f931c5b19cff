//! `rotor-twin bag recover`: a recording cut off (SIGKILL, a full disk, a crash) or damaged made
//! into a complete bag again, as `ros2 bag reindex` does for rosbag2: every intact message (the
//! damage-tolerant reader, [`crate::bag`]) written to a NEW bag directory with its summary and
//! metadata.yaml, which rosbags and indexed MCAP readers open. The input is never written to.

use super::{RecordError, Recorder, TopicQos};
use crate::bag::{Bag, BagError};
use std::path::{Path, PathBuf};

/// Why a bag could not be recovered.
#[derive(Debug, thiserror::Error)]
pub enum RecoverError {
    /// Nothing could be read.
    #[error(transparent)]
    Bag(#[from] BagError),
    /// The new bag could not be written.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// The output would lie inside the input.
    #[error("{out}: lies inside the input bag {input}; choose an output directory apart from it")]
    Overlap {
        /// The input bag.
        input: PathBuf,
        /// The output asked for.
        out: PathBuf,
    },
}

/// What was recovered.
#[derive(Debug, Clone)]
pub struct Recovered {
    /// The new bag directory.
    pub dir: PathBuf,
    /// Messages written per topic.
    pub counts: Vec<(String, u64)>,
    /// The damage skipped, one line each.
    pub damage: Vec<String>,
    /// Other problems worked around (metadata, time outliers, topics left out).
    pub notes: Vec<String>,
}

/// Reads the bag at `input` (directory or .mcap file) and writes every intact message to the new
/// bag directory `out` (which must not exist), with the topics' types, schemas and QoS.
pub fn recover(input: &Path, out: &Path) -> Result<Recovered, RecoverError> {
    let (input_real, out_real) = (resolved_path(input), resolved_path(out));
    if out_real.starts_with(&input_real) {
        return Err(RecoverError::Overlap {
            input: input.to_path_buf(),
            out: out.to_path_buf(),
        });
    }
    let bag = Bag::read(input)?;
    let mut notes = bag.notes.clone();
    let mut rec = Recorder::create(out)?;
    let mut handles = Vec::with_capacity(bag.topics.len());
    for t in &bag.topics {
        let clash = bag
            .topics
            .iter()
            .take_while(|o| !std::ptr::eq(*o, t))
            .any(|o| o.name == t.name && o.type_name != t.type_name);
        if clash {
            notes.push(format!(
                "{} appears with a second type {}: those messages left out",
                t.name, t.type_name
            ));
            handles.push(None);
            continue;
        }
        let qos = qos_of(t.offered_qos_profiles.as_deref());
        let h = rec.add_topic_raw(&t.name, &t.type_name, &t.schema_encoding, &t.schema, qos)?;
        handles.push(Some(h));
    }
    let (mut kept, mut excluded) = (bag.messages(), bag.excluded_messages());
    for m in kept.by_ref().chain(excluded.by_ref()) {
        if let Some(h) = handles[m.topic] {
            rec.write_cdr(h, m.payload(), m.log_time_ns, m.publish_time_ns)?;
        }
    }
    notes.extend(kept.problems().iter().chain(excluded.problems()).cloned());
    rec.set_custom_data("recovered_from", &input.display().to_string());
    let counts = rec.counts();
    let dir = rec.finish()?;
    Ok(Recovered {
        dir,
        counts,
        damage: bag.damage.iter().map(|d| d.to_string()).collect(),
        notes,
    })
}

/// The QoS a rosbag2 `offered_qos_profiles` entry describes (reliable, volatile, depth 10 where
/// it says nothing).
fn qos_of(yaml: Option<&str>) -> TopicQos {
    let text = yaml.unwrap_or("");
    let depth = text
        .lines()
        .find_map(|l| l.trim().trim_start_matches("- ").strip_prefix("depth:"))
        .and_then(|d| d.trim().parse().ok())
        .unwrap_or(10);
    TopicQos {
        depth,
        reliable: !text.contains("reliability: best_effort"),
        transient_local: text.contains("durability: transient_local"),
    }
}

/// `path` made absolute with its symbolic links resolved, as far as it exists (the rest
/// appended as given): for telling whether one path lies inside another.
pub fn resolved_path(path: &Path) -> PathBuf {
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = abs.as_path();
    let mut rest = Vec::new();
    while !existing.exists() {
        match (existing.parent(), existing.file_name()) {
            (Some(parent), Some(name)) => {
                rest.push(name.to_owned());
                existing = parent;
            }
            _ => break,
        }
    }
    let mut real = existing
        .canonicalize()
        .unwrap_or_else(|_| existing.to_path_buf());
    for name in rest.iter().rev() {
        real.push(name);
    }
    real
}
