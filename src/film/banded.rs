//! Cholesky factorisation of a symmetric positive-definite band matrix, in place, allocation-free.
//!
//! The film's finite-volume matrix restricted to the pressurised nodes is a symmetric M-matrix
//! whose bandwidth is the number of axial nodes (columns ordered around the circumference, nodes
//! within a column along the axis). Factor cost n·b²/2, solve cost 2·n·b.

/// Lower band of an n × n symmetric matrix with half-bandwidth `b`; row `i` holds the entries
/// `A[i][i-b] … A[i][i]` (the last is the diagonal). Storage is reserved once for the largest
/// `n` and `b` the owner will ever need.
#[derive(Debug, Clone)]
pub(crate) struct BandMatrix {
    data: Vec<f64>,
    n: usize,
    b: usize,
}

impl BandMatrix {
    /// Reserves room for matrices up to `max_n` rows with half-bandwidth up to `max_b`.
    pub(crate) fn with_capacity(max_n: usize, max_b: usize) -> Self {
        Self {
            data: vec![0.0; max_n * (max_b + 1)],
            n: 0,
            b: 0,
        }
    }

    /// Starts a new zero matrix of `n` rows and half-bandwidth `b` within the reserved room.
    pub(crate) fn reset(&mut self, n: usize, b: usize) {
        let len = n * (b + 1);
        assert!(len <= self.data.len(), "band matrix capacity exceeded");
        self.n = n;
        self.b = b;
        self.data[..len].fill(0.0);
    }

    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        // j in i-b..=i
        i * (self.b + 1) + (self.b + j - i)
    }

    /// Adds `value` to `A[i][j]` for `j ≤ i` (the symmetric entry is implied).
    #[inline]
    pub(crate) fn add(&mut self, i: usize, j: usize, value: f64) {
        debug_assert!(j <= i && i - j <= self.b);
        let k = self.idx(i, j);
        self.data[k] += value;
    }

    /// Factors A = L Lᵀ in place. Returns false if a pivot is not positive (A not SPD).
    pub(crate) fn factor(&mut self) -> bool {
        let (n, b) = (self.n, self.b);
        let w = b + 1;
        for i in 0..n {
            let j0 = i.saturating_sub(b);
            for j in j0..=i {
                // s = A[i][j] − Σ_{k=max(j0, j−b)}^{j−1} L[i][k] L[j][k]
                let k0 = j0.max(j.saturating_sub(b));
                let mut s = self.data[i * w + (b + j - i)];
                let ri = i * w + b - i;
                let rj = j * w + b - j;
                for k in k0..j {
                    s -= self.data[ri + k] * self.data[rj + k];
                }
                if i == j {
                    if s <= 0.0 || !s.is_finite() {
                        return false;
                    }
                    self.data[ri + i] = s.sqrt();
                } else {
                    self.data[ri + j] = s / self.data[rj + j];
                }
            }
        }
        true
    }

    /// Solves L Lᵀ x = r in place (after [`factor`](Self::factor)); `x` holds r on entry.
    pub(crate) fn solve(&self, x: &mut [f64]) {
        let (n, b) = (self.n, self.b);
        let w = b + 1;
        // forward: L y = r
        for i in 0..n {
            let ri = i * w + b - i;
            let mut s = x[i];
            for (k, xk) in x.iter().enumerate().take(i).skip(i.saturating_sub(b)) {
                s -= self.data[ri + k] * xk;
            }
            x[i] = s / self.data[ri + i];
        }
        // backward: Lᵀ x = y
        for i in (0..n).rev() {
            let ri = i * w + b - i;
            let xi = x[i] / self.data[ri + i];
            x[i] = xi;
            for k in i.saturating_sub(b)..i {
                x[k] -= self.data[ri + k] * xi;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random diagonally dominant band matrix: the factor reproduces A x = r to round-off.
    #[test]
    fn solves_a_diagonally_dominant_band_system() {
        let (n, b) = (37, 5);
        let mut dense = vec![vec![0.0; n]; n];
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut m = BandMatrix::with_capacity(n, b);
        m.reset(n, b);
        for i in 0..n {
            for j in i.saturating_sub(b)..i {
                let v = rnd();
                dense[i][j] = v;
                dense[j][i] = v;
                m.add(i, j, v);
            }
        }
        for i in 0..n {
            let d = 2.0 * b as f64 + rnd().abs();
            dense[i][i] = d;
            m.add(i, i, d);
        }
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| dense[i][j] * x_true[j]).sum())
            .collect();
        assert!(m.factor());
        m.solve(&mut x);
        for i in 0..n {
            assert!(
                (x[i] - x_true[i]).abs() < 1e-12,
                "row {i}: {} vs {}",
                x[i],
                x_true[i]
            );
        }
    }
}
