//! The bag reader streams (issue 15, item 18): messages are read back chunk by chunk, and the
//! result must be what reading the whole bag and sorting it gives. Reference: the `mcap` crate's
//! own `MessageStream` over each file's bytes held whole (an independent reader), the files'
//! messages concatenated in file order and sorted stably by receive time (the order `ros2 bag
//! play` uses, and the one the reader kept before it streamed).

use rotor_twin::bag::Bag;
use rotor_twin::messages::{from_cdr, Float64};
use rotor_twin::record::{Recorder, TopicQos};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// (topic, receive time, publish time, payload) of one message.
type Key = (String, u64, u64, Vec<u8>);

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-stream-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// The reference: every message of `files` by the mcap crate, stably sorted by receive time.
fn reference(files: &[PathBuf]) -> Vec<Key> {
    let mut all = Vec::new();
    for f in files {
        let bytes = std::fs::read(f).unwrap();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            all.push((
                m.channel.topic.clone(),
                m.log_time,
                m.publish_time,
                m.data.into_owned(),
            ));
        }
    }
    all.sort_by_key(|k| k.1);
    all
}

/// The streamed messages of `bag`, and the most chunks held at once.
fn streamed(bag: &Bag) -> (Vec<Key>, usize) {
    let mut s = bag.messages();
    let keys = s
        .by_ref()
        .map(|m| {
            (
                bag.topics[m.topic].name.clone(),
                m.log_time_ns,
                m.publish_time_ns,
                m.payload().to_vec(),
            )
        })
        .collect();
    assert!(s.problems().is_empty(), "{:?}", s.problems());
    (keys, s.peak_open_chunks())
}

fn chunk_count(file: &Path) -> usize {
    let bytes = std::fs::read(file).unwrap();
    mcap::Summary::read(&bytes)
        .unwrap()
        .unwrap()
        .chunk_indexes
        .len()
}

#[test]
fn the_sample_bag_streams_as_read_whole_and_sorted() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = root.join("bags/orc_runup_synthetic");
    let bag = Bag::read(&dir).unwrap();
    let want = reference(&bag.files);
    assert_eq!(want.len(), 76_627, "bags/README.md: 76,627 messages");
    let (got, peak) = streamed(&bag);
    assert_eq!(bag.message_count(), want.len());
    assert!(got == want, "streamed order or content differs");
    // a recording in receive order: a chunk or two in memory at a time, of many
    let chunks = chunk_count(&bag.files[0]);
    assert!(
        chunks >= 10 && peak <= 2,
        "{peak} of {chunks} chunks held at once"
    );
}

/// Writes a bag of `n` Float64 on /t (and /u) received at `time(i)`, a chunk every 50 messages.
fn write(dir: &Path, n: usize, time: impl Fn(usize) -> u64) -> PathBuf {
    let mut rec = Recorder::create(dir).unwrap();
    let t = rec
        .add_topic::<Float64>("/t", TopicQos::reliable(10))
        .unwrap();
    let u = rec
        .add_topic::<Float64>("/u", TopicQos::reliable(10))
        .unwrap();
    for i in 0..n {
        let at = time(i);
        let h = if i % 3 == 0 { u } else { t };
        rec.write(h, &Float64 { data: i as f64 }, at, at + 7)
            .unwrap();
        if i % 50 == 49 {
            rec.flush_if_due(Duration::ZERO).unwrap();
        }
    }
    let dir = rec.finish().unwrap();
    let name = format!("{}_0.mcap", dir.file_name().unwrap().to_string_lossy());
    dir.join(name)
}

/// Two files whose messages interleave in time, with receive times out of order inside each
/// chunk and equal times across the files: the same sequence as the whole bag sorted, ties in
/// file order, and only the chunks that overlap in time held at once.
#[test]
fn interleaved_files_and_unordered_chunks_merge_as_a_stable_sort() {
    const T0: u64 = 1_700_000_000_000_000_000;
    const MS: u64 = 1_000_000;
    let dir = scratch("merge");
    std::fs::create_dir_all(&dir).unwrap();
    // file a: every ms, shuffled within blocks of 10; file b: every 2 ms, the same times as a
    let a = write(&scratch("merge-a"), 3000, |i| {
        T0 + ((i / 10) * 10 + (i * 7) % 10) as u64 * MS
    });
    let b = write(&scratch("merge-b"), 1500, |i| T0 + (2 * i) as u64 * MS);
    let files = [dir.join("m_0.mcap"), dir.join("m_1.mcap")];
    std::fs::rename(&a, &files[0]).unwrap();
    std::fs::rename(&b, &files[1]).unwrap();
    let bag = Bag::read(&dir).unwrap();
    assert_eq!(bag.files, files);
    let want = reference(&files);
    let (got, peak) = streamed(&bag);
    assert_eq!(got.len(), 4500);
    assert!(got == want, "merge differs from the stable sort");
    // a tie at T0 + 2 ms: file a's message (i = 6, as 6·7 mod 10 = 2) before file b's (i = 1)
    let ties: Vec<f64> = got
        .iter()
        .filter(|k| k.1 == T0 + 2 * MS)
        .map(|k| from_cdr::<Float64>(&k.3).unwrap().data)
        .collect();
    assert_eq!(ties, vec![6.0, 1.0], "file a's message first at a tie");
    let chunks = chunk_count(&files[0]) + chunk_count(&files[1]);
    assert!(
        chunks >= 80 && peak <= 4,
        "{peak} of {chunks} chunks held at once"
    );
    // the per-topic counts the replay uses agree with the messages
    for (k, t) in bag.topics.iter().enumerate() {
        let n = got.iter().filter(|g| g.0 == t.name).count();
        assert_eq!(bag.topic_message_count(k), n, "{}", t.name);
    }
}

/// A chunk damaged after the bag was indexed (the file changed under the replay): its CRC is
/// checked again when it is read back, so its messages are left out and the chunk named, never
/// delivered changed; the other chunks still come.
#[test]
fn a_chunk_changed_after_indexing_is_left_out_and_named() {
    let dir = scratch("changed");
    let file = write(&dir, 1000, |i| {
        1_700_000_000_000_000_000 + i as u64 * 1_000_000
    });
    let bag = Bag::read(&file).unwrap();
    assert_eq!(bag.message_count(), 1000);
    let bytes = std::fs::read(&file).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let c = &summary.chunk_indexes[3];
    let mid = (c.chunk_start_offset + c.chunk_length / 2) as usize;
    let mut changed = bytes.clone();
    changed[mid] ^= 0x40;
    std::fs::write(&file, &changed).unwrap();
    let mut s = bag.messages();
    let got = s.by_ref().count();
    assert_eq!(got, 950, "one chunk of 50 left out");
    assert_eq!(s.problems().len(), 1, "{:?}", s.problems());
    assert!(s.problems()[0].contains("CRC"), "{:?}", s.problems());
}
