//! A recording split into files of bounded size and duration, as rosbag2 does with
//! `--max-bag-size` / `--max-bag-duration` (`max_bagfile_size`, `max_bagfile_duration`): the
//! bag directory holds `<name>_0.mcap`, `<name>_1.mcap`, …, each a complete MCAP file with its
//! own summary, and metadata.yaml lists them all. The MCAP writer keeps one chunk-index entry
//! per chunk until its file is finished (about 1 kB per 64 KiB chunk), so bounding the file
//! bounds the recording's memory.

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Default largest file of a recording (bytes): 256 MiB. The writer's chunk index then holds
/// at most some 4,100 entries of 64 KiB chunks (≈ 1 kB each); measured in the 30-minute soak
/// (README "Soak", a file every 7 minutes at ≈ 37 MB/min): the node's RSS rose 7 MiB while the
/// first file filled, then stayed flat.
pub const DEFAULT_MAX_BAGFILE_BYTES: u64 = 256 << 20;

/// Smallest size limit accepted (bytes): 64 KiB, one chunk (rosbag2's own floor is 86 kB).
pub const MIN_MAX_BAGFILE_BYTES: u64 = 64 << 10;

/// When a recording goes on in a new file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SplitLimits {
    /// Largest file (bytes): the next message goes to a new file once this is reached
    /// (None: no limit by size).
    pub max_bytes: Option<u64>,
    /// Longest span of receive times in one file (ns) (None: no limit by duration).
    pub max_duration_ns: Option<u64>,
}

impl Default for SplitLimits {
    fn default() -> Self {
        Self {
            max_bytes: Some(DEFAULT_MAX_BAGFILE_BYTES),
            max_duration_ns: None,
        }
    }
}

impl SplitLimits {
    /// No splitting: one file, however long.
    pub const NONE: Self = Self {
        max_bytes: None,
        max_duration_ns: None,
    };

    /// The limits of the command line: `max_bytes` (0: no limit by size) and `max_duration_s`
    /// (0: no limit by duration), checked; the error names the option and the value.
    pub fn from_options(max_bytes: u64, max_duration_s: f64) -> Result<Self, String> {
        if max_bytes != 0 && max_bytes < MIN_MAX_BAGFILE_BYTES {
            return Err(format!(
                "--record-max-bag-size {max_bytes}: must be 0 (no limit) or at least {MIN_MAX_BAGFILE_BYTES} bytes (one chunk)"
            ));
        }
        if !(0.0..=1e9).contains(&max_duration_s) {
            return Err(format!(
                "--record-max-bag-duration {max_duration_s}: must be 0 (no limit) or a positive number of seconds"
            ));
        }
        Ok(Self {
            max_bytes: (max_bytes > 0).then_some(max_bytes),
            max_duration_ns: (max_duration_s > 0.0).then_some((max_duration_s * 1e9) as u64),
        })
    }

    /// Whether a file of `bytes` whose receive times began at `first_ns` is full for a
    /// message received at `t_ns`.
    pub(super) fn full(&self, bytes: u64, first_ns: Option<u64>, t_ns: u64) -> bool {
        let Some(first) = first_ns else {
            return false;
        };
        self.max_bytes.is_some_and(|m| bytes >= m)
            || self
                .max_duration_ns
                .is_some_and(|d| t_ns.saturating_sub(first) >= d)
    }
}

/// One file of the recording, for metadata.yaml.
#[derive(Debug, Clone)]
pub(super) struct FileEntry {
    pub name: String,
    pub first_ns: Option<u64>,
    pub last_ns: u64,
    pub count: u64,
}

impl FileEntry {
    pub fn new(name: String) -> Self {
        Self {
            name,
            first_ns: None,
            last_ns: 0,
            count: 0,
        }
    }

    pub fn note(&mut self, t_ns: u64) {
        self.first_ns = Some(self.first_ns.map_or(t_ns, |f| f.min(t_ns)));
        self.last_ns = self.last_ns.max(t_ns);
        self.count += 1;
    }
}

/// A file that knows how large it has grown (the furthest byte written), shared with the
/// recorder.
pub(super) struct SizedFile {
    file: File,
    pos: u64,
    size: Arc<AtomicU64>,
}

impl SizedFile {
    pub fn new(file: File) -> (Self, Arc<AtomicU64>) {
        let size = Arc::new(AtomicU64::new(0));
        (
            Self {
                file,
                pos: 0,
                size: size.clone(),
            },
            size,
        )
    }
}

impl Write for SizedFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(buf)?;
        self.pos += n as u64;
        self.size.fetch_max(self.pos, Ordering::Relaxed);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Seek for SizedFile {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        self.pos = self.file.seek(to)?;
        Ok(self.pos)
    }
}

/// The MCAP writer of one file of the recording.
pub(super) type McapWriter = mcap::Writer<BufWriter<SizedFile>>;
