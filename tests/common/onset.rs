//! The replay's onset rule on per-revolution bearing values, shared by the onset studies
//! (tests/onset_study.rs, tests/onset_b.rs).

/// The replay's onset rule (`StationComparison::onset`) on per-revolution values `(speed,
/// amplitude, counts)`: blocks of 8 revolutions, the first 3 consecutive blocks that count
/// (every revolution of each) whose amplitude (at the block's end) is ≥ e^(−0.002·8) × the
/// block's before; the speed at the first block's end.
pub fn onset_by_rule(per_rev: &[(f64, f64, bool)]) -> Option<f64> {
    let least = (-0.002f64 * 8.0).exp();
    let blocks: Vec<(f64, f64, bool)> = per_rev
        .chunks_exact(8)
        .map(|b| (b[7].0, b[7].1, b.iter().all(|p| p.2)))
        .collect();
    (0..blocks.len().saturating_sub(2)).find_map(|k| {
        let w = &blocks[k..k + 3];
        let ok = w.iter().all(|b| b.2) && (1..3).all(|j| w[j].1 >= least * w[j - 1].1);
        ok.then_some(w[0].0)
    })
}
