//! What a viewer subscribes to (Foxglove, Lichtblick: config/foxglove_layout*.json): one orbit
//! topic per bearing ([`topics::bearing_orbit`]), because an XY plot of the latest message
//! filtered by bearing draws nothing for the bearing whose orbit comes first on a shared topic,
//! and at most [`topics::VIEWER_MAX_HZ`] per bearing, because the viewers warn above 60 Hz (an
//! orbit per revolution is 150 Hz at 9,000 rpm). The shared [`topics::ORBIT`] keeps every
//! revolution for the consumers that rely on it. One rule for the node, its recording and the
//! replay's output bag, so that all three keep the same orbits.

use crate::messages::Orbit;
use crate::rotor::{BearingModel, Rotor};
use crate::topics;

/// Routes the orbits of the shared topic to the per-bearing viewer topics.
#[derive(Debug, Clone)]
pub struct BearingOrbits {
    names: Vec<String>,
    /// stamp (ns) of the last orbit kept for each bearing's topic
    last_kept_ns: Vec<Option<i64>>,
}

impl BearingOrbits {
    /// The film bearings of `rotor` (those the twin publishes orbits of), in output order.
    pub fn new(rotor: &Rotor) -> Self {
        let names: Vec<String> = rotor
            .bearings
            .iter()
            .filter(|b| matches!(b.model, BearingModel::Film(_)))
            .map(|b| b.name.clone())
            .collect();
        Self {
            last_kept_ns: vec![None; names.len()],
            names,
        }
    }

    /// The viewer topic of each bearing, in output order (un-namespaced, as [`topics::ORBIT`]).
    pub fn topics(&self) -> Vec<String> {
        self.names
            .iter()
            .map(|n| topics::bearing_orbit(n))
            .collect()
    }

    /// The index of the per-bearing topic that orbit `m` also goes to, or None: an unknown
    /// bearing, or less than 1/[`topics::VIEWER_MAX_HZ`] s of model time after the last orbit
    /// kept for its bearing (a stamp going backwards, a restarted twin, is kept).
    pub fn route(&mut self, m: &Orbit) -> Option<usize> {
        let k = self.names.iter().position(|n| *n == m.bearing)?;
        let stamp = m.header.stamp.as_nanos();
        let min_gap_ns = (1e9 / topics::VIEWER_MAX_HZ).ceil() as i64;
        let keep = match self.last_kept_ns[k] {
            Some(last) => stamp - last >= min_gap_ns || stamp < last,
            None => true,
        };
        keep.then(|| {
            self.last_kept_ns[k] = Some(stamp);
            k
        })
    }
}
