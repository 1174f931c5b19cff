//! Issue 17: the replay's memory bounded independently of the bag's length. What grew with the
//! bag (measured, `/usr/bin/time -v` and heaptrack, README "Replay memory") was each probe
//! station's per-block series (every 8 revolutions: the comparison and its order spectra, ≈ 1.5
//! kB a block, 37.5 blocks a second at 9,000 rpm with two stations), kept for the report and
//! plots and then serialised whole into report.json. Now a station keeps at most
//! `MAX_KEPT_BLOCKS` blocks (decimated by 2 each time it fills) and reads the onset, its
//! transients and the plant's whip over every block as they come.
//!
//! Checked with the counting allocator's live bytes: the heap a station's comparison holds
//! after 120 s and after 240 s of a 9,000 rpm whip orbit (16 samples a revolution, as the
//! synthetic bags) differs by less than 16 KiB (before: by the 2,250 blocks more, ≥ 3 MB), and
//! stays under the bound the cap gives; the onset and whip are still found at the first block.

use rotor_twin::replay::compare::{
    BlockSpectra, Sample, StationComparison, WindowComparison, BLOCK_REVS, MAX_KEPT_BLOCKS,
};
use std::f64::consts::TAU;

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::live_bytes;

const SPEED_RAD_S: f64 = 9000.0 * TAU / 60.0;
const SAMPLES_PER_REV: usize = 16;
/// the microturbine's radial clearance (m); whip is a sub-synchronous axis ≥ 0.75 of it
const CLEARANCE_M: f64 = 40e-6;

/// A station's comparison fed `seconds` of a developed whip at 9,000 rpm (a forward 0.5X
/// circle of 35 µm and a 1X circle of 3 µm, measured and predicted alike), and the heap bytes
/// it holds (live bytes after minus before).
fn fed(seconds: f64) -> (StationComparison, isize) {
    let before = live_bytes();
    let mut c = StationComparison::new("probe", CLEARANCE_M);
    let n = (seconds * SPEED_RAD_S / TAU * SAMPLES_PER_REV as f64) as usize;
    for k in 0..n {
        let psi = k as f64 * TAU / SAMPLES_PER_REV as f64;
        let (half, one) = (35e-6, 3e-6);
        let xy = [
            half * (0.5 * psi).cos() + one * psi.cos(),
            half * (0.5 * psi).sin() + one * psi.sin(),
        ];
        let t = psi / SPEED_RAD_S;
        c.push(
            Sample {
                time_s: t,
                time_ns: (t * 1e9) as i64,
                angle_rad: psi,
                speed_rad_s: SPEED_RAD_S,
                measured_m: xy,
                predicted_m: xy,
                ..Default::default()
            },
            None,
        );
    }
    c.finish(None);
    let held = live_bytes() - before;
    (c, held)
}

#[test]
fn a_stations_comparison_does_not_grow_with_the_bag() {
    let (short, held_short) = fed(20.0);
    drop(short);
    let (mid, held_mid) = fed(120.0);
    let (long, held_long) = fed(240.0);
    let per_block = std::mem::size_of::<WindowComparison>() + std::mem::size_of::<BlockSpectra>();
    // the blocks (at most MAX_KEPT_BLOCKS) plus the summary window (33 revolutions of samples,
    // a ring of up to 1,024 samples), the current and the waiting block (≤ 256 samples each):
    // 192 KiB for those and the name
    let sample = std::mem::size_of::<Sample>();
    let bound = (MAX_KEPT_BLOCKS * per_block + (1024 + 2 * 256) * sample + 64 * 1024) as isize;
    println!(
        "held: 20 s {held_short} B, 120 s {held_mid} B, 240 s {held_long} B; bound {bound} B; blocks seen {} / {}, kept {} / {} (stride {} / {})",
        mid.blocks_seen,
        long.blocks_seen,
        mid.blocks.len(),
        long.blocks.len(),
        mid.block_stride,
        long.block_stride
    );
    // 150 revolutions a second, blocks of 8: 2,250 and 4,500 blocks; a block is closed by the
    // first sample a full block past its start, which rounding of the angle can make the 129th
    // (then 1/129 fewer blocks): within 1 %
    let expected = |s: f64| s * 150.0 / BLOCK_REVS as f64;
    assert!((mid.blocks_seen as f64 / expected(120.0) - 1.0).abs() <= 0.01);
    assert!((long.blocks_seen as f64 / expected(240.0) - 1.0).abs() <= 0.01);
    assert!(held_mid <= bound, "120 s holds {held_mid} B > {bound} B");
    assert!(held_long <= bound, "240 s holds {held_long} B > {bound} B");
    assert!(
        (held_long - held_mid).abs() < 16 * 1024,
        "the comparison grew from {held_mid} B (120 s) to {held_long} B (240 s)"
    );
    // the kept blocks still span the bag: the first starts at 0, the last ends within one
    // stride of blocks of the end
    let block_s = BLOCK_REVS as f64 / 150.0;
    let last = long.blocks.last().map_or(0.0, |b| b.end_s);
    assert!(long.blocks[0].start_s.abs() < 1e-9);
    assert!(240.0 - last <= (long.block_stride + 1) as f64 * block_s + 1e-6);
    assert_eq!(long.blocks.len(), long.block_spectra.len());
    // the onset (sub-synchronous ≥ 2 % of the clearance and ≥ half the 1X, persisting over 3
    // blocks) is the first block, read over every block; the whip (≥ 0.75 × clearance over 3
    // blocks) starts at 0
    for c in [&mid, &long] {
        let (t, rpm) = c.onset(false).expect("an onset");
        assert!((t - block_s).abs() < 2.0 / (150.0 * SAMPLES_PER_REV as f64));
        assert!((rpm - 9000.0).abs() < 1e-6);
        assert_eq!(c.onset(true), c.onset(false));
        assert!(c.transients(false).is_empty());
        assert_eq!(c.observed_whip_start_s(), Some(0.0));
    }
}
