//! Samples lost before they reached the node (issue 15, item 8): every DDS sample carries its
//! writer's RTPS sequence number (1, 2, 3, … per writer, RTPS 2.5 §8.3.5.4), so a jump from n to
//! n + k + 1 between two samples of one writer says that k samples were lost on the way: on a
//! best-effort link (a datagram dropped), or overwritten in the reader's history before the node
//! read them (RustDDS keeps the last `SENSOR_READER` depth and drops older unread ones silently).
//!
//! What this cannot count, stated: samples lost after a writer's last delivered one (no later
//! number shows the gap), and those before its first delivered one (a reader that matched late
//! never was owed them). A sample that does not decode also leaves a gap in its writer's
//! numbers; it is counted as refused by the driver, so each gap is counted less the decode
//! failures seen on the topic since the last gap.

use std::collections::HashMap;
use std::hash::Hash;

/// Writers (one of them is the common case; a bound keeps a flood of writers from growing the
/// map without end: beyond it the oldest-numbered writers are forgotten).
pub const MAX_WRITERS: usize = 256;

/// Sequence-number gaps per writer of one topic.
#[derive(Debug, Default)]
pub struct SequenceGaps<K> {
    last: HashMap<K, i64>,
    undecoded: u64,
    /// Samples counted as lost so far.
    pub lost: u64,
}

impl<K: Eq + Hash + Copy> SequenceGaps<K> {
    /// A sample of `writer` numbered `sequence` arrived; returns how many were lost before it.
    pub fn sample(&mut self, writer: K, sequence: i64) -> u64 {
        if self.last.len() >= MAX_WRITERS && !self.last.contains_key(&writer) {
            self.last.clear();
        }
        let prev = self.last.get(&writer).copied();
        if prev.is_some_and(|p| sequence <= p) {
            // repeated or reordered: neither a loss nor a new last number
            return 0;
        }
        self.last.insert(writer, sequence);
        let gap = match prev {
            Some(p) if sequence > p + 1 => (sequence - p - 1) as u64,
            // the writer's first sample, or the next one
            _ => return 0,
        };
        let refused = self.undecoded.min(gap);
        self.undecoded -= refused;
        let lost = gap - refused;
        self.lost += lost;
        lost
    }

    /// A sample that did not decode (its writer and number are unknown).
    pub fn undecoded(&mut self) {
        self.undecoded += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two writers interleaved: 1, 2, 5 (two lost), 9 (three lost) from one, 1, 3 (one lost)
    /// from the other: six lost; a repeat or a step back counts nothing; a decode failure is
    /// not counted again as a loss.
    #[test]
    fn gaps_in_each_writers_numbers_are_the_lost_samples() {
        let mut g = SequenceGaps::default();
        let seen: u64 = [
            (1, 1),
            (1, 2),
            (2, 1),
            (1, 5),
            (2, 3),
            (1, 9),
            (1, 9),
            (1, 4),
        ]
        .iter()
        .map(|&(w, n)| g.sample(w, n))
        .sum();
        assert_eq!(seen, 6);
        assert_eq!(g.lost, 6);
        g.undecoded();
        assert_eq!(
            g.sample(1, 11),
            0,
            "the one missing number was the undecoded sample"
        );
        assert_eq!(g.sample(1, 14), 2);
        assert_eq!(g.lost, 8);
    }
}
