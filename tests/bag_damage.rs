//! Damaged MCAP files: bits flipped at many positions of a written bag. The reader must deliver
//! every message of every intact chunk (a chunk is intact when the flipped byte lies outside it)
//! and never a message whose value or stamp was changed: each message's value encodes its own
//! index, and its receive time is fixed by that index, so a corrupted one cannot pass unseen.

use rotor_twin::bag::Bag;
use rotor_twin::messages::{from_cdr, Float64};
use rotor_twin::record::{Recorder, TopicQos};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::Duration;

const N: usize = 6000;
const T0_NS: u64 = 1_700_000_000_000_000_000;
const STEP_NS: u64 = 1_000_000;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-bagdmg-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// A bag of N Float64 messages on /t, value i at T0 + i ms, a chunk closed every 400 messages.
fn written_bag(name: &str) -> Vec<u8> {
    let dir = scratch(name);
    let mut rec = Recorder::create(&dir).unwrap();
    let t = rec
        .add_topic::<Float64>("/t", TopicQos::reliable(10))
        .unwrap();
    for i in 0..N {
        let stamp = T0_NS + i as u64 * STEP_NS;
        rec.write(t, &Float64 { data: i as f64 }, stamp, stamp)
            .unwrap();
        if i % 400 == 399 {
            rec.flush_if_due(Duration::ZERO).unwrap();
        }
    }
    let dir = rec.finish().unwrap();
    let file = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|e| e == "mcap"))
        .unwrap();
    std::fs::read(file).unwrap()
}

/// Chunk extents [start, end) and the messages in each, from the intact file's chunk index.
fn chunks(bytes: &[u8]) -> Vec<(usize, usize, usize)> {
    let summary = mcap::Summary::read(bytes).unwrap().unwrap();
    summary
        .chunk_indexes
        .iter()
        .map(|c| {
            let start = c.chunk_start_offset as usize;
            let n = (c.message_end_time - c.message_start_time) / STEP_NS + 1;
            (start, start + c.chunk_length as usize, n as usize)
        })
        .collect()
}

/// Reads `bytes`; checks that every message delivered is an original, once; returns how many.
fn delivered(bytes: &[u8], what: &str) -> (usize, Bag) {
    let mut bag = Bag::default();
    bag.read_file(Path::new("flipped.mcap"), bytes)
        .unwrap_or_else(|e| panic!("{what}: refused: {e}"));
    let mut seen = HashSet::new();
    for m in bag.messages() {
        assert_eq!(bag.topics[m.topic].name, "/t", "{what}");
        let v = from_cdr::<Float64>(m.payload())
            .unwrap_or_else(|e| panic!("{what}: undecodable payload delivered: {e}"))
            .data;
        assert!(
            v.fract() == 0.0 && (0.0..N as f64).contains(&v),
            "{what}: value {v}"
        );
        let i = v as u64;
        assert_eq!(m.log_time_ns, T0_NS + i * STEP_NS, "{what}: stamp of {i}");
        assert_eq!(
            m.publish_time_ns,
            T0_NS + i * STEP_NS,
            "{what}: stamp of {i}"
        );
        assert!(seen.insert(i), "{what}: message {i} delivered twice");
    }
    (bag.message_count(), bag)
}

#[test]
fn every_intact_chunk_is_read_and_no_damaged_one_is_used() {
    let bytes = written_bag("flips");
    let chunks = chunks(&bytes);
    assert!(chunks.len() >= 10, "{} chunks", chunks.len());
    assert_eq!(chunks.iter().map(|c| c.2).sum::<usize>(), N);
    assert_eq!(delivered(&bytes, "intact").0, N);
    // every 149th byte, and every byte of the first chunk's header and of the file's end
    let mut positions: Vec<usize> = (0..bytes.len()).step_by(149).collect();
    positions.extend(chunks[0].0..chunks[0].0 + 60);
    positions.extend(bytes.len().saturating_sub(200)..bytes.len());
    let mut lost_total = 0;
    for (k, &p) in positions.iter().enumerate() {
        let mut b = bytes.clone();
        b[p] ^= 1 << (k % 8);
        let what = format!("bit {} of byte {p}", k % 8);
        let intact: usize = chunks
            .iter()
            .filter(|c| !(c.0..c.1).contains(&p))
            .map(|c| c.2)
            .sum();
        let (got, bag) = delivered(&b, &what);
        assert!(
            got >= intact,
            "{what}: {got} messages, {intact} in intact chunks"
        );
        if got < N {
            assert!(!bag.damage.is_empty(), "{what}: {} lost unnamed", N - got);
        }
        lost_total += N - got;
    }
    // a flipped bit costs at most its own chunk (≤ 400 messages), on average much less
    assert!(lost_total <= positions.len() * 400, "{lost_total}");
}

/// Several flips at once and a cut: still every intact chunk after the first damage.
#[test]
fn a_cut_file_with_damaged_chunks_keeps_every_intact_chunk() {
    let bytes = written_bag("cut");
    let chunks = chunks(&bytes);
    let cut = chunks[chunks.len() * 7 / 10].0 + 10;
    let mut b = bytes[..cut].to_vec();
    // damage chunks 2 and 5 in their records
    for c in [chunks[2], chunks[5]] {
        let mid = (c.0 + c.1) / 2;
        b[mid] ^= 0x55;
    }
    let intact: usize = chunks
        .iter()
        .enumerate()
        .filter(|(i, c)| *i != 2 && *i != 5 && c.1 <= cut)
        .map(|(_, c)| c.2)
        .sum();
    let (got, bag) = delivered(&b, "cut and two flips");
    assert_eq!(got, intact);
    // three damaged ranges: two chunks and the cut, each named with its bytes
    assert_eq!(bag.damage.len(), 3, "{:#?}", bag.damage);
    for (d, c) in bag.damage.iter().zip([chunks[2], chunks[5]]) {
        let (a, z) = d.bytes.unwrap();
        assert!(a == c.0 && z >= c.1, "{d}");
        assert!(d.to_string().contains(&format!("bytes {a} to")), "{d}");
    }
    assert!(bag.damage[2].why.contains("cut off"), "{}", bag.damage[2]);
}
