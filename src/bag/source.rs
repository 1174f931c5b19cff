//! Where a bag file's bytes come from: the file itself, read where needed (positioned reads, so
//! a bag of any length is never held whole), or bytes already in memory (tests, fuzzing). A
//! [`Window`] serves the scan's many small reads from one buffer of [`WINDOW_BYTES`].

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::sync::Arc;

/// Size of the scan's read buffer (bytes): 1 MiB.
pub(super) const WINDOW_BYTES: usize = 1 << 20;

/// The bytes of one MCAP file.
#[derive(Debug, Clone)]
pub(super) enum Source {
    /// An open regular file and its length.
    File(Arc<File>, u64),
    /// The file's contents, in memory.
    Bytes(Arc<[u8]>),
}

impl Source {
    /// Length of the file (bytes).
    pub fn len(&self) -> u64 {
        match self {
            Self::File(_, n) => *n,
            Self::Bytes(b) => b.len() as u64,
        }
    }

    /// `n` bytes from `at`; an error if the file is shorter or cannot be read.
    pub fn read_at(&self, at: u64, n: usize) -> std::io::Result<Vec<u8>> {
        let short = || std::io::Error::new(std::io::ErrorKind::UnexpectedEof, "file too short");
        if at.checked_add(n as u64).is_none_or(|e| e > self.len()) {
            return Err(short());
        }
        match self {
            Self::File(f, _) => {
                let mut buf = vec![0; n];
                f.read_exact_at(&mut buf, at)?;
                Ok(buf)
            }
            Self::Bytes(b) => Ok(b[at as usize..at as usize + n].to_vec()),
        }
    }
}

/// Buffered reads of a [`Source`]: a read inside the buffer costs no system call; one outside
/// refills it from there (a read longer than the buffer gets a buffer of its own length).
pub(super) struct Window<'a> {
    src: &'a Source,
    at: u64,
    buf: Vec<u8>,
    /// the first read error (the file then reads as if it ended there)
    pub error: Option<std::io::Error>,
}

impl<'a> Window<'a> {
    pub fn new(src: &'a Source) -> Self {
        Self {
            src,
            at: 0,
            buf: Vec::new(),
            error: None,
        }
    }

    /// Length of the file (bytes).
    pub fn len(&self) -> usize {
        self.src.len() as usize
    }

    /// Bytes `at..at + n`, or None past the end of the file (or after a read error).
    pub fn get(&mut self, at: usize, n: usize) -> Option<&[u8]> {
        let end = at.checked_add(n)?;
        if end > self.len() || self.error.is_some() {
            return None;
        }
        let (at64, have) = (at as u64, self.at + self.buf.len() as u64);
        if at64 < self.at || end as u64 > have {
            let want = n.max(WINDOW_BYTES.min(self.len() - at));
            match self.src.read_at(at64, want) {
                Ok(b) => {
                    self.buf = b;
                    self.at = at64;
                }
                Err(e) => {
                    self.error = Some(e);
                    return None;
                }
            }
        }
        let from = (at64 - self.at) as usize;
        Some(&self.buf[from..from + n])
    }

    /// The byte at `at`.
    pub fn byte(&mut self, at: usize) -> Option<u8> {
        self.get(at, 1).map(|b| b[0])
    }

    /// The little-endian u64 at `at`.
    pub fn u64_at(&mut self, at: usize) -> Option<u64> {
        self.get(at, 8)
            .and_then(|b| b.try_into().ok())
            .map(u64::from_le_bytes)
    }
}
