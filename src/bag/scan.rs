//! A damage-tolerant reader of one MCAP file (format: <https://mcap.dev/spec>). The file is a
//! sequence of records `opcode (u8) | length (u64 LE) | body`; messages sit in chunks, each with a
//! CRC32 of its uncompressed records; the summary section at the end repeats the schemas and
//! channels and lists every chunk's offset (the chunk index), and has its own CRC.
//!
//! Reading follows the records from the start. A record that does not frame (unknown opcode, a
//! length past the end of the file) or a chunk that does not decode or fails its CRC starts a
//! damaged range; reading resumes at the next chunk that decodes and passes its CRC (found by
//! scanning, or listed in the chunk index), and the range up to it is reported. A chunk is used
//! whole or not at all: its CRC is checked before any of its messages is taken. Records outside
//! chunks (which carry no CRC) are used only while the chain of records from the start of the
//! file is unbroken, so that nothing found by scanning through damage is delivered unverified.

//!
//! The file is never held whole: the scan ([`index_mcap`]) reads it through a 1 MiB window and
//! keeps, of each intact chunk (and each run of loose messages), only where it lies and the
//! count and receive-time range of its messages (a [`Segment`]); the replay reads a segment's
//! messages again when it needs them ([`read_segment`]), checking its CRC again.

use super::source::{Source, Window};
use mcap::records::{MessageHeader, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::{BTreeSet, HashMap};

const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
const OP_FOOTER: u8 = 0x02;
const OP_SCHEMA: u8 = 0x03;
const OP_CHANNEL: u8 = 0x04;
const OP_MESSAGE: u8 = 0x05;
const OP_CHUNK: u8 = 0x06;
const OP_DATA_END: u8 = 0x0F;
/// opcode and length prefix of every record (bytes)
const PREFIX: usize = 9;
/// a footer record: prefix + summary_start + summary_offset_start + summary_crc
const FOOTER_LEN: usize = PREFIX + 20;
/// the fixed part of a chunk's header: start and end time, uncompressed size and CRC,
/// compression length (the compressed size follows the compression string)
const CHUNK_HEADER_FIXED: usize = 8 + 8 + 8 + 4 + 4;
/// A run of messages outside chunks is cut into segments of at most this many bytes, so that
/// reading one back is bounded too: 1 MiB.
const LOOSE_SEGMENT_BYTES: usize = 1 << 20;

/// A schema: name, encoding, text.
pub(super) type SchemaDef = (String, String, Vec<u8>);

/// Count and receive-time range of some messages.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Stats {
    pub count: usize,
    pub min_ns: u64,
    pub max_ns: u64,
}

impl Stats {
    pub fn add(&mut self, t: u64) {
        if self.count == 0 {
            (self.min_ns, self.max_ns) = (t, t);
        } else {
            self.min_ns = self.min_ns.min(t);
            self.max_ns = self.max_ns.max(t);
        }
        self.count += 1;
    }
}

/// An intact chunk, or a run of loose messages, of one file: the unit read back.
#[derive(Debug, Clone, Default)]
pub(super) struct Segment {
    /// index of the file in the bag
    pub file: usize,
    /// loose records (else one chunk record)
    pub loose: bool,
    /// byte range in the file
    pub start: usize,
    pub end: usize,
    /// its messages that are delivered (a known channel, and within the bag's receive-time
    /// window once outliers are known)
    pub kept: Stats,
    /// its messages left out as receive-time outliers
    pub outside: Stats,
    /// the channels its messages are on, each once
    pub channels: Vec<u16>,
}

/// A damaged byte range of the file and what was wrong at its start.
#[derive(Debug, Clone)]
pub(super) struct Damaged {
    pub start: usize,
    pub end: usize,
    pub why: String,
    /// messages of this file read before the range
    pub messages_before: usize,
    /// receive time of the last of them
    pub last_good_log_time_ns: Option<u64>,
}

/// What one file holds that can be trusted, without its messages.
#[derive(Debug, Default)]
pub(super) struct FileIndex {
    pub schemas: HashMap<u16, SchemaDef>,
    pub channels: HashMap<u16, mcap::records::Channel>,
    pub segments: Vec<Segment>,
    pub damage: Vec<Damaged>,
    /// messages read, per channel (known or not)
    pub channel_counts: HashMap<u16, usize>,
    /// messages read in all
    pub messages: usize,
}

/// The schemas and channels of one decoded chunk, CRC already checked.
#[derive(Default)]
struct ChunkDefs {
    schemas: Vec<(u16, SchemaDef)>,
    channels: Vec<mcap::records::Channel>,
}

/// The summary section, if present and intact.
struct Summary {
    /// where the data section ends (the summary's start, or the footer's when it has none)
    data_end: usize,
    schemas: HashMap<u16, SchemaDef>,
    channels: HashMap<u16, mcap::records::Channel>,
    /// chunk offsets from the chunk index
    chunks: BTreeSet<usize>,
}

/// Indexes one MCAP file. Never fails: what cannot be read is in [`FileIndex::damage`]; a read
/// error of the file is returned beside the index (the file then reads as if it ended there).
pub(super) fn index_mcap(src: &Source, record_limit: usize) -> (FileIndex, Option<std::io::Error>) {
    let mut win = Window::new(src);
    let mut content = FileIndex::default();
    let summary = match read_summary(&mut win, record_limit) {
        Ok(s) => s,
        Err(d) => {
            content.damage.push(d);
            None
        }
    };
    let data_end = summary.as_ref().map_or(win.len(), |s| s.data_end);
    let index: BTreeSet<usize> = summary
        .as_ref()
        .map(|s| s.chunks.clone())
        .unwrap_or_default();
    if let Some(s) = summary {
        content.schemas = s.schemas;
        content.channels = s.channels;
    }
    let mut scan = Scan {
        win,
        data_end,
        record_limit,
        index,
        done: BTreeSet::new(),
        content,
        loose: None,
        last_ns: None,
    };
    scan.walk();
    scan.chunks_from_index();
    (scan.content, scan.win.error)
}

struct Scan<'a> {
    win: Window<'a>,
    data_end: usize,
    record_limit: usize,
    index: BTreeSet<usize>,
    /// chunk offsets already taken
    done: BTreeSet<usize>,
    content: FileIndex,
    /// the loose segment being extended, if any
    loose: Option<usize>,
    /// receive time of the last message read
    last_ns: Option<u64>,
}

impl Scan<'_> {
    /// Follows the records from the start, resynchronising after each damaged range.
    fn walk(&mut self) {
        let mut at = MAGIC.len();
        let mut unbroken = true;
        if self.win.get(0, MAGIC.len()) != Some(MAGIC) {
            unbroken = false;
            at = self.damaged(0, "no MCAP magic at the start of the file".into());
        }
        while at < self.data_end {
            let Some((opcode, body, end)) = self.frame(at, self.data_end) else {
                let why = self.why_unframed(at);
                unbroken = false;
                at = self.damaged(at, why);
                continue;
            };
            if !matches!(opcode, OP_SCHEMA | OP_CHANNEL | OP_MESSAGE) {
                self.loose = None;
            }
            let used = match opcode {
                OP_CHUNK => self.take_chunk(at, end),
                OP_SCHEMA | OP_CHANNEL | OP_MESSAGE if unbroken => {
                    self.take_loose(opcode, at, body, end)
                }
                // a loose record after damage: no CRC vouches for it
                OP_SCHEMA | OP_CHANNEL | OP_MESSAGE => Ok(()),
                OP_DATA_END => return,
                // the header belongs at the start, the summary records after DataEnd: one of
                // them here is a damaged opcode (a chunk whose opcode flipped would otherwise be
                // skipped as a record the replay does not use)
                0x01 if at != MAGIC.len() => Err(format!("a header record at byte {at}")),
                OP_FOOTER | 0x08 | 0x0A | 0x0B | 0x0D | 0x0E => Err(format!(
                    "a summary record (opcode 0x{opcode:02x}) inside the data section at byte {at}"
                )),
                _ => Ok(()),
            };
            match used {
                Ok(()) => at = end,
                Err(why) => {
                    unbroken = false;
                    self.loose = None;
                    at = self.damaged(at, why);
                }
            }
        }
        if self.data_end == self.win.len() && self.content.damage.is_empty() {
            // no DataEnd, no footer: a recording cut off at a record boundary
            let n = self.win.len();
            self.note(
                n,
                n,
                "the file ends without its summary section (cut off)".into(),
            );
        }
    }

    /// The record at `at`: (opcode, body start, end) if its opcode is known and it ends by
    /// `limit`.
    fn frame(&mut self, at: usize, limit: usize) -> Option<(u8, usize, usize)> {
        frame(&mut self.win, at, limit, self.record_limit)
    }

    /// Notes a damaged range starting at `start` and returns where reading resumes: the next
    /// chunk that decodes and passes its CRC, or the end of the data section.
    fn damaged(&mut self, start: usize, why: String) -> usize {
        self.loose = None;
        let end = (start + 1..self.data_end)
            .find(|&q| {
                self.win.byte(q) == Some(OP_CHUNK)
                    && !self.done.contains(&q)
                    && self.is_intact_chunk(q)
            })
            .unwrap_or(self.data_end);
        self.note(start, end, why);
        end
    }

    /// Whether a chunk record that decodes and passes its CRC starts at `q`. The header is
    /// checked first as the decoder checks it (its compression string one the decoder knows,
    /// its compressed size within the record), so that a byte 0x06 inside damage costs no read
    /// of the length it seems to declare.
    fn is_intact_chunk(&mut self, q: usize) -> bool {
        let Some((_, body, end)) = self.frame(q, self.data_end) else {
            return false;
        };
        let len = end - body;
        let Some(head) = self.win.get(body, CHUNK_HEADER_FIXED) else {
            return false;
        };
        let clen = u32::from_le_bytes([head[28], head[29], head[30], head[31]]) as usize;
        let header_len = CHUNK_HEADER_FIXED + clen + 8;
        if !matches!(clen, 0 | 3 | 4) || header_len > len {
            return false;
        }
        let known = match self.win.get(body + CHUNK_HEADER_FIXED, clen) {
            Some(c) => matches!(c, b"" | b"zstd" | b"lz4"),
            None => false,
        };
        let compressed = self.win.u64_at(body + CHUNK_HEADER_FIXED + clen);
        if !known || compressed.is_none_or(|c| c > (len - header_len) as u64) {
            return false;
        }
        let record_limit = self.record_limit;
        self.win
            .get(q, end - q)
            .is_some_and(|r| decode_chunk(r, record_limit, &mut |_, _| {}).is_ok())
    }

    fn note(&mut self, start: usize, end: usize, why: String) {
        let messages_before = self.content.messages;
        // a range that continues the previous one is the same damage
        if let Some(last) = self.content.damage.last_mut() {
            if last.end == start && last.start < start {
                last.end = end;
                return;
            }
        }
        self.content.damage.push(Damaged {
            start,
            end,
            why,
            messages_before,
            last_good_log_time_ns: self.last_ns,
        });
    }

    fn why_unframed(&mut self, at: usize) -> String {
        let n = self.win.len();
        let Some(prefix) = self.win.get(at, PREFIX) else {
            return format!("a record at byte {at} is cut off (file ends at {n})");
        };
        let op = prefix[0];
        let len = u64::from_le_bytes(prefix[1..].try_into().unwrap_or_default());
        if !(0x01..=0x0F).contains(&op) {
            format!("unknown record opcode 0x{op:02x} at byte {at}")
        } else if op == OP_CHUNK && len == u64::MAX {
            format!("the chunk at byte {at} was never finished (its length is still the writer's placeholder): cut off while recording")
        } else if (at as u64 + PREFIX as u64).saturating_add(len) > n as u64 {
            format!("a record at byte {at} declares {len} bytes, past the end of the file ({n}): cut off")
        } else {
            format!("a record at byte {at} declares {len} bytes, past the data section")
        }
    }

    /// Decodes the chunk at `at..end` and indexes it, or says why not.
    fn take_chunk(&mut self, at: usize, end: usize) -> Result<(), String> {
        if !self.done.insert(at) {
            return Ok(());
        }
        let record_limit = self.record_limit;
        let mut seg = Segment {
            start: at,
            end,
            ..Segment::default()
        };
        let mut times = Vec::new();
        let record = self
            .win
            .get(at, end - at)
            .ok_or_else(|| format!("chunk at byte {at}: cannot be read"))?;
        let defs = decode_chunk(record, record_limit, &mut |h, _| {
            times.push((h.channel_id, h.log_time))
        })
        .map_err(|e| format!("chunk at byte {at}: {e}"))?;
        for (id, s) in defs.schemas {
            self.content.schemas.insert(id, s);
        }
        for c in defs.channels {
            self.content.channels.insert(c.id, c);
        }
        for (channel, t) in times {
            self.count_message(&mut seg, channel, t);
        }
        self.content.segments.push(seg);
        Ok(())
    }

    fn count_message(&mut self, seg: &mut Segment, channel: u16, t: u64) {
        seg.kept.add(t);
        if !seg.channels.contains(&channel) {
            seg.channels.push(channel);
        }
        *self.content.channel_counts.entry(channel).or_default() += 1;
        self.content.messages += 1;
        self.last_ns = Some(t);
    }

    /// Chunks the index lists that the walk did not reach; one that cannot be read is damage
    /// (unless it lies in a range already reported).
    fn chunks_from_index(&mut self) {
        let missed: Vec<usize> = self.index.difference(&self.done).copied().collect();
        for at in missed {
            let (end, result) = match self.frame(at, self.data_end) {
                Some((OP_CHUNK, _, end)) => (end, self.take_chunk(at, end)),
                Some((op, _, end)) => (
                    end,
                    Err(format!(
                        "the summary's chunk index lists a chunk at byte {at}, but the record there has opcode 0x{op:02x}"
                    )),
                ),
                None => (
                    at + 1,
                    Err(format!(
                        "the summary's chunk index lists a chunk at byte {at} that does not frame"
                    )),
                ),
            };
            let known = self
                .content
                .damage
                .iter()
                .any(|d| d.start <= at && at < d.end);
            if let (Err(why), false) = (result, known) {
                self.note(at, end, why);
            }
        }
    }

    /// A schema, channel or message outside any chunk (record `at..end`, body from `body`).
    fn take_loose(&mut self, opcode: u8, at: usize, body: usize, end: usize) -> Result<(), String> {
        let bytes = self
            .win
            .get(body, end - body)
            .ok_or_else(|| format!("record at byte {at}: cannot be read"))?;
        match mcap::parse_record(opcode, bytes).map_err(|e| e.to_string())? {
            Record::Schema { header, data } => {
                let s = (header.name, header.encoding, data.into_owned());
                self.content.schemas.insert(header.id, s);
            }
            Record::Channel(c) => {
                self.content.channels.insert(c.id, c);
            }
            Record::Message { header, .. } => {
                let open = self
                    .loose
                    .filter(|&i| end - self.content.segments[i].start <= LOOSE_SEGMENT_BYTES);
                let i = open.unwrap_or_else(|| {
                    self.content.segments.push(Segment {
                        loose: true,
                        start: at,
                        ..Segment::default()
                    });
                    self.content.segments.len() - 1
                });
                let mut seg = std::mem::take(&mut self.content.segments[i]);
                seg.end = end;
                self.count_message(&mut seg, header.channel_id, header.log_time);
                self.content.segments[i] = seg;
                self.loose = Some(i);
            }
            _ => {}
        }
        Ok(())
    }
}

/// The record at `at`: (opcode, body start, end) if its opcode is known and it ends by `limit`.
fn frame(
    win: &mut Window,
    at: usize,
    limit: usize,
    record_limit: usize,
) -> Option<(u8, usize, usize)> {
    let prefix = win.get(at, PREFIX)?;
    let opcode = prefix[0];
    let len = usize::try_from(u64::from_le_bytes(prefix[1..].try_into().ok()?)).ok()?;
    let end = (at + PREFIX).checked_add(len)?;
    ((0x01..=0x0F).contains(&opcode) && len <= record_limit && end <= limit).then_some((
        opcode,
        at + PREFIX,
        end,
    ))
}

/// The messages of `seg` read back from `src`, in file order; a chunk's CRC is checked again
/// (the file may have changed since it was indexed).
pub(super) fn read_segment(
    src: &Source,
    seg: &Segment,
    record_limit: usize,
) -> Result<Vec<(MessageHeader, Vec<u8>)>, String> {
    let bytes = src
        .read_at(seg.start as u64, seg.end - seg.start)
        .map_err(|e| format!("bytes {} to {}: {e}", seg.start, seg.end))?;
    let mut out = Vec::with_capacity(seg.kept.count + seg.outside.count);
    if !seg.loose {
        decode_chunk(&bytes, record_limit, &mut |h, d| out.push((*h, d.to_vec())))?;
        return Ok(out);
    }
    let mut at = 0;
    while at < bytes.len() {
        let prefix = bytes.get(at..at + PREFIX).ok_or("a loose record cut off")?;
        let len = u64::from_le_bytes(prefix[1..].try_into().map_err(|_| "short prefix")?);
        let end = usize::try_from(len)
            .ok()
            .and_then(|l| (at + PREFIX).checked_add(l))
            .filter(|&e| e <= bytes.len())
            .ok_or("a loose record does not frame")?;
        if prefix[0] == OP_MESSAGE {
            if let Record::Message { header, data } =
                mcap::parse_record(OP_MESSAGE, &bytes[at + PREFIX..end])
                    .map_err(|e| e.to_string())?
            {
                out.push((header, data.into_owned()));
            }
        }
        at = end;
    }
    Ok(out)
}

/// Decodes one chunk record (`record` = opcode, length and body), checking its CRC before any
/// record in it is parsed; every record in it must parse. Each message goes to `on_message`.
fn decode_chunk(
    record: &[u8],
    record_limit: usize,
    on_message: &mut dyn FnMut(&MessageHeader, &[u8]),
) -> Result<ChunkDefs, String> {
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(record_limit),
    );
    let mut rest = record;
    let mut out = ChunkDefs::default();
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| e.to_string())? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            LinearReadEvent::Record { opcode, data } => {
                match mcap::parse_record(opcode, data).map_err(|e| e.to_string())? {
                    Record::Schema { header, data } => out
                        .schemas
                        .push((header.id, (header.name, header.encoding, data.into_owned()))),
                    Record::Channel(c) => out.channels.push(c),
                    Record::Message { header, data } => on_message(&header, &data),
                    _ => {}
                }
            }
        }
    }
    Ok(out)
}

/// The summary section: `Ok(None)` if the file has none (or is too short to tell), `Err` if it
/// is there but damaged (its CRC fails, a record in it does not parse), then it is not used.
/// Read twice in pieces (the CRC, then the records), never whole.
fn read_summary(win: &mut Window, record_limit: usize) -> Result<Option<Summary>, Damaged> {
    let n = win.len();
    if n < MAGIC.len() * 2 + FOOTER_LEN || win.get(n - MAGIC.len(), MAGIC.len()) != Some(MAGIC) {
        return Ok(None);
    }
    let footer_at = n - MAGIC.len() - FOOTER_LEN;
    let Some(f) = win.get(footer_at, FOOTER_LEN).map(<[u8]>::to_vec) else {
        return Ok(None);
    };
    let u64_at = |i: usize| u64::from_le_bytes(f[i..i + 8].try_into().unwrap_or_default());
    if f[0] != OP_FOOTER || u64_at(1) != 20 {
        return Ok(None);
    }
    let bad = |why: String| Damaged {
        start: footer_at,
        end: n,
        why,
        messages_before: 0,
        last_good_log_time_ns: None,
    };
    let summary_start = usize::try_from(u64_at(PREFIX)).unwrap_or(usize::MAX);
    if summary_start == 0 {
        return Ok(Some(Summary::empty(footer_at)));
    }
    if summary_start < MAGIC.len() || summary_start > footer_at {
        return Err(bad(format!(
            "the footer's summary start {summary_start} is outside the file"
        )));
    }
    let crc = u32::from_le_bytes(f[PREFIX + 16..PREFIX + 20].try_into().unwrap_or_default());
    let computed = crc_of(win, summary_start, footer_at + PREFIX + 16);
    if crc != 0 && Some(crc) != computed {
        let read = computed.map_or("unreadable".into(), |c| format!("0x{c:08x} read"));
        return Err(Damaged {
            start: summary_start,
            ..bad(format!(
                "the summary section fails its CRC (0x{crc:08x} recorded, {read}): not used"
            ))
        });
    }
    let mut s = Summary::empty(summary_start);
    let mut at = summary_start;
    while at < footer_at {
        let Some((opcode, body, end)) = frame(win, at, footer_at, record_limit) else {
            return Err(Damaged {
                start: at,
                ..bad(format!(
                    "the summary record at byte {at} does not frame: summary not used"
                ))
            });
        };
        let taken = match win.get(body, end - body) {
            Some(b) => s.take(opcode, b),
            None => Err("cannot be read".into()),
        };
        taken.map_err(|e| Damaged {
            start: at,
            ..bad(format!("summary record at byte {at}: {e}"))
        })?;
        at = end;
    }
    Ok(Some(s))
}

/// CRC32 of bytes `a..b`, read in pieces; None if they cannot be read.
fn crc_of(win: &mut Window, a: usize, b: usize) -> Option<u32> {
    let mut h = crc32fast::Hasher::new();
    let mut at = a;
    while at < b {
        let n = (b - at).min(super::source::WINDOW_BYTES);
        h.update(win.get(at, n)?);
        at += n;
    }
    Some(h.finalize())
}

impl Summary {
    fn empty(data_end: usize) -> Self {
        Self {
            data_end,
            schemas: HashMap::new(),
            channels: HashMap::new(),
            chunks: BTreeSet::new(),
        }
    }

    fn take(&mut self, opcode: u8, body: &[u8]) -> Result<(), String> {
        match mcap::parse_record(opcode, body).map_err(|e| e.to_string())? {
            Record::Schema { header, data } => {
                let s = (header.name, header.encoding, data.into_owned());
                self.schemas.insert(header.id, s);
            }
            Record::Channel(c) => {
                self.channels.insert(c.id, c);
            }
            Record::ChunkIndex(c) => {
                if let Ok(at) = usize::try_from(c.chunk_start_offset) {
                    self.chunks.insert(at);
                }
            }
            _ => {}
        }
        Ok(())
    }
}
