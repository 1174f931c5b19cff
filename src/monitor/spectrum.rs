//! Order spectrum of an orbit: the complex signal z = x + i y analysed against the shaft angle,
//! so positive orders whirl forward (with the rotation) and negative ones backward (the "full
//! spectrum" of rotordynamics). A Hann window over the samples; amplitudes are orbit radii (m).

/// Forward and backward orbit radii at one order.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OrderComponent {
    /// Order (frequency / running frequency), positive.
    pub order: f64,
    /// Radius of the forward circular component (m).
    pub forward_m: f64,
    /// Radius of the backward circular component (m).
    pub backward_m: f64,
    /// Phase of the forward component at the window start (rad).
    pub forward_phase_rad: f64,
}

impl OrderComponent {
    /// Semi-major axis of the elliptical orbit at this order: forward + backward radius (m).
    pub fn semi_major_m(&self) -> f64 {
        self.forward_m + self.backward_m
    }
}

/// Computes the components at orders k/`resolution` for k = 1 ..= `max_k` into `out`
/// (`out.len()` ≥ max_k), from samples `x`, `y` (m) at shaft angles `angle` (rad). The mean is
/// removed first. Allocates nothing.
pub fn order_spectrum(
    x: impl Iterator<Item = f64> + Clone,
    y: impl Iterator<Item = f64> + Clone,
    angle: impl Iterator<Item = f64> + Clone,
    n: usize,
    resolution: usize,
    out: &mut [OrderComponent],
) {
    let max_k = out.len();
    for (k, o) in out.iter_mut().enumerate() {
        *o = OrderComponent {
            order: (k + 1) as f64 / resolution as f64,
            ..OrderComponent::default()
        };
    }
    if n < 4 {
        return;
    }
    let (mx, my) = (
        x.clone().sum::<f64>() / n as f64,
        y.clone().sum::<f64>() / n as f64,
    );
    let angle0 = angle.clone().next().unwrap_or(0.0);
    // accumulators: forward Σ w z e^{−i r ψ}, backward Σ w z e^{+i r ψ}
    let mut acc = [[0.0_f64; 4]; 64];
    let max_k = max_k.min(acc.len());
    let mut wsum = 0.0;
    for (i, ((xv, yv), a)) in x.zip(y).zip(angle).enumerate().take(n) {
        let w = 0.5 - 0.5 * (std::f64::consts::TAU * (i as f64 + 0.5) / n as f64).cos();
        wsum += w;
        let (zr, zi) = (w * (xv - mx), w * (yv - my));
        let (s, c) = ((a - angle0) / resolution as f64).sin_cos();
        // base phasor e^{−i ψ/R}; its k-th power by repeated multiplication
        let (br, bi) = (c, -s);
        let (mut pr, mut pi) = (1.0, 0.0);
        for row in acc.iter_mut().take(max_k) {
            let (nr, ni) = (pr * br - pi * bi, pr * bi + pi * br);
            pr = nr;
            pi = ni;
            // forward: z · e^{−ikψ/R}
            row[0] += zr * pr - zi * pi;
            row[1] += zr * pi + zi * pr;
            // backward: z · e^{+ikψ/R}
            row[2] += zr * pr + zi * pi;
            row[3] += -zr * pi + zi * pr;
        }
    }
    for (o, row) in out.iter_mut().zip(&acc).take(max_k) {
        o.forward_m = row[0].hypot(row[1]) / wsum;
        o.backward_m = row[2].hypot(row[3]) / wsum;
        o.forward_phase_rad = row[1].atan2(row[0]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A forward 1X orbit of radius 3 plus a backward 0.5X one of radius 1, sampled over 16 revs:
    /// each is found at its order with its radius (Hann window, exact bins).
    #[test]
    fn finds_forward_and_backward_components_at_their_orders() {
        let n = 16 * 128;
        let psi: Vec<f64> = (0..n)
            .map(|i| std::f64::consts::TAU * i as f64 / 128.0)
            .collect();
        let x: Vec<f64> = psi
            .iter()
            .map(|p| 3.0 * p.cos() + (0.5 * p).cos())
            .collect();
        let y: Vec<f64> = psi
            .iter()
            .map(|p| 3.0 * p.sin() - (0.5 * p).sin())
            .collect();
        let mut out = [OrderComponent::default(); 16];
        order_spectrum(
            x.iter().copied(),
            y.iter().copied(),
            psi.iter().copied(),
            n,
            16,
            &mut out,
        );
        let one = out[15];
        let half = out[7];
        assert!((one.order - 1.0).abs() < 1e-12 && (half.order - 0.5).abs() < 1e-12);
        assert!(
            (one.forward_m - 3.0).abs() < 1e-6 && one.backward_m < 1e-6,
            "{one:?}"
        );
        assert!(
            (half.backward_m - 1.0).abs() < 1e-6 && half.forward_m < 1e-6,
            "{half:?}"
        );
    }
}
