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

use mcap::records::Record;
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

/// A schema: name, encoding, text.
pub(super) type SchemaDef = (String, String, Vec<u8>);

/// One message read: its channel id (of this file), times and payload range in the caller's
/// payload buffer.
#[derive(Debug, Clone, Copy)]
pub(super) struct RawMessage {
    pub channel: u16,
    pub log_time_ns: u64,
    pub publish_time_ns: u64,
    pub start: usize,
    pub len: usize,
}

/// A damaged byte range of the file and what was wrong at its start.
#[derive(Debug, Clone)]
pub(super) struct Damaged {
    pub start: usize,
    pub end: usize,
    pub why: String,
    /// messages of this file read before the range
    pub messages_before: usize,
}

/// What one file held that could be trusted.
#[derive(Debug, Default)]
pub(super) struct FileContent {
    pub schemas: HashMap<u16, SchemaDef>,
    pub channels: HashMap<u16, mcap::records::Channel>,
    pub messages: Vec<RawMessage>,
    pub damage: Vec<Damaged>,
}

/// The records of one decoded chunk, CRC already checked.
#[derive(Default)]
struct ChunkContent {
    schemas: Vec<(u16, SchemaDef)>,
    channels: Vec<mcap::records::Channel>,
    messages: Vec<(mcap::records::MessageHeader, Vec<u8>)>,
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

/// Reads `bytes` (one MCAP file), putting the payloads into `payloads`. Never fails: what cannot
/// be read is in [`FileContent::damage`].
pub(super) fn read_mcap(bytes: &[u8], payloads: &mut Vec<u8>, record_limit: usize) -> FileContent {
    let mut content = FileContent::default();
    let summary = match read_summary(bytes, record_limit) {
        Ok(s) => s,
        Err(d) => {
            content.damage.push(d);
            None
        }
    };
    let data_end = summary.as_ref().map_or(bytes.len(), |s| s.data_end);
    let index: BTreeSet<usize> = summary
        .as_ref()
        .map(|s| s.chunks.clone())
        .unwrap_or_default();
    if let Some(s) = summary {
        content.schemas = s.schemas;
        content.channels = s.channels;
    }
    let mut scan = Scan {
        bytes,
        data_end,
        record_limit,
        index,
        done: BTreeSet::new(),
        content,
        payloads,
    };
    scan.walk();
    scan.chunks_from_index();
    scan.content
}

struct Scan<'a> {
    bytes: &'a [u8],
    data_end: usize,
    record_limit: usize,
    index: BTreeSet<usize>,
    /// chunk offsets already taken
    done: BTreeSet<usize>,
    content: FileContent,
    payloads: &'a mut Vec<u8>,
}

impl Scan<'_> {
    /// Follows the records from the start, resynchronising after each damaged range.
    fn walk(&mut self) {
        let mut at = MAGIC.len();
        let mut unbroken = true;
        if !self.bytes.starts_with(MAGIC) {
            unbroken = false;
            at = self.damaged(0, "no MCAP magic at the start of the file".into());
        }
        while at < self.data_end {
            let Some((opcode, body, end)) = frame(self.bytes, at, self.data_end, self.record_limit)
            else {
                let why = self.why_unframed(at);
                unbroken = false;
                at = self.damaged(at, why);
                continue;
            };
            let used = match opcode {
                OP_CHUNK => self.take_chunk(at, end),
                OP_SCHEMA | OP_CHANNEL | OP_MESSAGE if unbroken => {
                    self.take_loose(opcode, &self.bytes[body..end])
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
                    at = self.damaged(at, why);
                }
            }
        }
        if self.data_end == self.bytes.len() && self.content.damage.is_empty() {
            // no DataEnd, no footer: a recording cut off at a record boundary
            let n = self.bytes.len();
            self.note(
                n,
                n,
                "the file ends without its summary section (cut off)".into(),
            );
        }
    }

    /// Notes a damaged range starting at `start` and returns where reading resumes: the next
    /// chunk that decodes and passes its CRC, or the end of the data section.
    fn damaged(&mut self, start: usize, why: String) -> usize {
        let end = (start + 1..self.data_end)
            .find(|&q| {
                self.bytes[q] == OP_CHUNK
                    && !self.done.contains(&q)
                    && frame(self.bytes, q, self.data_end, self.record_limit).is_some_and(
                        |(_, _, e)| decode_chunk(&self.bytes[q..e], self.record_limit).is_ok(),
                    )
            })
            .unwrap_or(self.data_end);
        self.note(start, end, why);
        end
    }

    fn note(&mut self, start: usize, end: usize, why: String) {
        let messages_before = self.content.messages.len();
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
        });
    }

    fn why_unframed(&self, at: usize) -> String {
        let Some(prefix) = self.bytes.get(at..at + PREFIX) else {
            return format!(
                "a record at byte {at} is cut off (file ends at {})",
                self.bytes.len()
            );
        };
        let len = u64::from_le_bytes(prefix[1..].try_into().unwrap_or_default());
        if !(0x01..=0x0F).contains(&prefix[0]) {
            format!("unknown record opcode 0x{:02x} at byte {at}", prefix[0])
        } else if prefix[0] == OP_CHUNK && len == u64::MAX {
            format!("the chunk at byte {at} was never finished (its length is still the writer's placeholder): cut off while recording")
        } else if (at as u64 + PREFIX as u64).saturating_add(len) > self.bytes.len() as u64 {
            format!(
                "a record at byte {at} declares {len} bytes, past the end of the file ({}): cut off",
                self.bytes.len()
            )
        } else {
            format!("a record at byte {at} declares {len} bytes, past the data section")
        }
    }

    /// Decodes the chunk at `at..end` and takes its records, or says why not.
    fn take_chunk(&mut self, at: usize, end: usize) -> Result<(), String> {
        if !self.done.insert(at) {
            return Ok(());
        }
        let chunk = decode_chunk(&self.bytes[at..end], self.record_limit)
            .map_err(|e| format!("chunk at byte {at}: {e}"))?;
        for (id, s) in chunk.schemas {
            self.content.schemas.insert(id, s);
        }
        for c in chunk.channels {
            self.content.channels.insert(c.id, c);
        }
        for (header, data) in chunk.messages {
            self.push_message(&header, &data);
        }
        Ok(())
    }

    /// Chunks the index lists that the walk did not reach; one that cannot be read is damage
    /// (unless it lies in a range already reported).
    fn chunks_from_index(&mut self) {
        let missed: Vec<usize> = self.index.difference(&self.done).copied().collect();
        for at in missed {
            let framed = frame(self.bytes, at, self.data_end, self.record_limit);
            let (end, result) = match framed {
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

    /// A schema, channel or message outside any chunk.
    fn take_loose(&mut self, opcode: u8, body: &[u8]) -> Result<(), String> {
        match mcap::parse_record(opcode, body).map_err(|e| e.to_string())? {
            Record::Schema { header, data } => {
                let s = (header.name, header.encoding, data.into_owned());
                self.content.schemas.insert(header.id, s);
            }
            Record::Channel(c) => {
                self.content.channels.insert(c.id, c);
            }
            Record::Message { header, data } => self.push_message(&header, &data),
            _ => {}
        }
        Ok(())
    }

    fn push_message(&mut self, header: &mcap::records::MessageHeader, data: &[u8]) {
        let start = self.payloads.len();
        self.payloads.extend_from_slice(data);
        self.content.messages.push(RawMessage {
            channel: header.channel_id,
            log_time_ns: header.log_time,
            publish_time_ns: header.publish_time,
            start,
            len: data.len(),
        });
    }
}

/// The record at `at`: (opcode, body start, end) if its opcode is known and it ends by `limit`.
fn frame(bytes: &[u8], at: usize, limit: usize, record_limit: usize) -> Option<(u8, usize, usize)> {
    let prefix = bytes.get(at..at.checked_add(PREFIX)?)?;
    let opcode = prefix[0];
    let len = usize::try_from(u64::from_le_bytes(prefix[1..].try_into().ok()?)).ok()?;
    let end = (at + PREFIX).checked_add(len)?;
    ((0x01..=0x0F).contains(&opcode) && len <= record_limit && end <= limit).then_some((
        opcode,
        at + PREFIX,
        end,
    ))
}

/// Decodes one chunk record (`record` = opcode, length and body), checking its CRC before any
/// record in it is parsed; every record in it must parse.
fn decode_chunk(record: &[u8], record_limit: usize) -> Result<ChunkContent, String> {
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_prevalidate_chunk_crcs(true)
            .with_record_length_limit(record_limit),
    );
    let mut rest = record;
    let mut out = ChunkContent::default();
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
                    Record::Message { header, data } => {
                        out.messages.push((header, data.into_owned()))
                    }
                    _ => {}
                }
            }
        }
    }
    Ok(out)
}

/// The summary section: `Ok(None)` if the file has none (or is too short to tell), `Err` if it
/// is there but damaged (its CRC fails, a record in it does not parse), then it is not used.
fn read_summary(bytes: &[u8], record_limit: usize) -> Result<Option<Summary>, Damaged> {
    let n = bytes.len();
    if n < MAGIC.len() * 2 + FOOTER_LEN || !bytes.ends_with(MAGIC) {
        return Ok(None);
    }
    let footer_at = n - MAGIC.len() - FOOTER_LEN;
    let f = &bytes[footer_at..n - MAGIC.len()];
    let u64_at = |i: usize| u64::from_le_bytes(f[i..i + 8].try_into().unwrap_or_default());
    if f[0] != OP_FOOTER || u64_at(1) != 20 {
        return Ok(None);
    }
    let bad = |why: String| Damaged {
        start: footer_at,
        end: n,
        why,
        messages_before: 0,
    };
    let summary_start = usize::try_from(u64_at(PREFIX)).unwrap_or(usize::MAX);
    if summary_start == 0 {
        let data_end = footer_at;
        return Ok(Some(Summary::empty(data_end)));
    }
    if summary_start < MAGIC.len() || summary_start > footer_at {
        return Err(bad(format!(
            "the footer's summary start {summary_start} is outside the file"
        )));
    }
    let crc = u32::from_le_bytes(f[PREFIX + 16..PREFIX + 20].try_into().unwrap_or_default());
    let computed = crc32fast::hash(&bytes[summary_start..footer_at + PREFIX + 16]);
    if crc != 0 && crc != computed {
        return Err(Damaged {
            start: summary_start,
            ..bad(format!("the summary section fails its CRC (0x{crc:08x} recorded, 0x{computed:08x} read): not used"))
        });
    }
    let mut s = Summary::empty(summary_start);
    let mut at = summary_start;
    while at < footer_at {
        let Some((opcode, body, end)) = frame(bytes, at, footer_at, record_limit) else {
            return Err(Damaged {
                start: at,
                ..bad(format!(
                    "the summary record at byte {at} does not frame: summary not used"
                ))
            });
        };
        s.take(opcode, &bytes[body..end]).map_err(|e| Damaged {
            start: at,
            ..bad(format!("summary record at byte {at}: {e}"))
        })?;
        at = end;
    }
    Ok(Some(s))
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
