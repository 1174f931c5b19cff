//! The bag's messages in receive-time order, read chunk by chunk: a chunk is read back (and its
//! CRC checked again) when the merge reaches the earliest receive time in it, and dropped when
//! its last message is delivered. Ties keep the reading order (file by file, then the order in
//! the file), as a stable sort of the whole bag would.

use super::{Bag, BagMessage};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, VecDeque};

/// Iterator over a bag's messages (see [`Bag::messages`]).
pub struct Messages<'a> {
    bag: &'a Bag,
    /// the outliers (else the messages kept)
    excluded: bool,
    /// segments with messages of this stream, by earliest receive time (then reading order)
    order: Vec<usize>,
    next: usize,
    /// the segments read back, their messages not yet delivered
    open: HashMap<usize, VecDeque<BagMessage>>,
    /// (receive time of the next message, segment) of each open segment
    heads: BinaryHeap<Reverse<(u64, usize)>>,
    peak_open: usize,
    problems: Vec<String>,
}

impl<'a> Messages<'a> {
    pub(super) fn new(bag: &'a Bag, excluded: bool) -> Self {
        let stats = |i: usize| {
            let s = &bag.segments[i];
            if excluded {
                s.outside
            } else {
                s.kept
            }
        };
        let mut order: Vec<usize> = (0..bag.segments.len())
            .filter(|&i| stats(i).count > 0)
            .collect();
        order.sort_by_key(|&i| (stats(i).min_ns, i));
        Self {
            bag,
            excluded,
            order,
            next: 0,
            open: HashMap::new(),
            heads: BinaryHeap::new(),
            peak_open: 0,
            problems: Vec::new(),
        }
    }

    /// The most chunks (or runs of loose messages) held at once so far: what bounds the memory.
    pub fn peak_open_chunks(&self) -> usize {
        self.peak_open
    }

    /// Chunks that could not be read back (the file changed or failed since it was indexed),
    /// one sentence each; their messages were not delivered.
    pub fn problems(&self) -> &[String] {
        &self.problems
    }

    fn min_ns(&self, i: usize) -> u64 {
        let s = &self.bag.segments[i];
        if self.excluded {
            s.outside.min_ns
        } else {
            s.kept.min_ns
        }
    }

    /// Reads segment `i` back: its messages of this stream, stably sorted by receive time.
    fn open_segment(&mut self, i: usize) {
        let bag = self.bag;
        let messages = match bag.segment_messages(i) {
            Ok(m) => m,
            Err(why) => {
                let file = bag.files.get(bag.segments[i].file);
                self.problems.push(format!(
                    "{}: {why}; its messages left out",
                    file.map_or("a bag file".into(), |f| f.display().to_string())
                ));
                return;
            }
        };
        let mut queue: Vec<BagMessage> = messages
            .into_iter()
            .filter(|(_, h, _)| bag.in_window(h.log_time) != self.excluded)
            .map(|(topic, h, data)| BagMessage {
                topic,
                log_time_ns: h.log_time,
                publish_time_ns: h.publish_time,
                data,
            })
            .collect();
        queue.sort_by_key(|m| m.log_time_ns);
        if let Some(first) = queue.first() {
            self.heads.push(Reverse((first.log_time_ns, i)));
            self.open.insert(i, queue.into());
            self.peak_open = self.peak_open.max(self.open.len());
        }
    }
}

impl Iterator for Messages<'_> {
    type Item = BagMessage;

    fn next(&mut self) -> Option<BagMessage> {
        loop {
            let head = self.heads.peek().map(|Reverse((t, _))| *t);
            if let Some(&i) = self.order.get(self.next) {
                if head.is_none_or(|t| self.min_ns(i) <= t) {
                    self.next += 1;
                    self.open_segment(i);
                    continue;
                }
            }
            let Reverse((_, i)) = self.heads.pop()?;
            let queue = self.open.get_mut(&i)?;
            let m = queue.pop_front()?;
            match queue.front() {
                Some(n) => self.heads.push(Reverse((n.log_time_ns, i))),
                None => {
                    self.open.remove(&i);
                }
            }
            return Some(m);
        }
    }
}
