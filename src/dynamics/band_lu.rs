//! LU factorisation of a band matrix without pivoting, in place and allocation-free: the
//! effective stiffness of the Newmark step, K_eff = K + (2/h)(C + ΩG) + (4/h²)M, on a rotor whose
//! DOFs run node by node along the shaft (half-bandwidth 7 for 4 DOFs a node).
//!
//! Without pivoting Gaussian elimination keeps the fill inside the band and is backward stable
//! when the matrix is diagonally dominant or close to symmetric positive definite (Golub & Van
//! Loan, Matrix Computations, 4th ed., §4.1.1 and §4.3.5): K_eff is, at a time step of a
//! revolution's 1/128th, the SPD (4/h²)M + K plus the small skew part (2/h)ΩG. The owner checks
//! the factor by a residual and falls back to the dense LU with pivoting if it is not accurate.
//! Factor cost n·b², solve cost 4·n·b (b the half-bandwidth), against n³ for the dense inverse.

/// An n × n matrix of half-bandwidth b (A[i][j] = 0 for |i − j| > b), stored by rows with the
/// 2b + 1 diagonals of each row contiguous, overwritten by its LU factors.
#[derive(Debug, Clone)]
pub(crate) struct BandLu {
    data: Vec<f64>,
    /// 1 / U[i][i]: the back substitution multiplies (a division's latency is the solve's).
    inverse_diagonal: Vec<f64>,
    n: usize,
    b: usize,
}

impl BandLu {
    /// A zero n × n matrix of half-bandwidth `b`.
    pub(crate) fn zeros(n: usize, b: usize) -> Self {
        Self {
            data: vec![0.0; n * (2 * b + 1)],
            inverse_diagonal: vec![0.0; n],
            n,
            b,
        }
    }

    /// The half-bandwidth of a dense square matrix: the largest |i − j| of a nonzero entry.
    pub(crate) fn half_bandwidth_of(a: &faer::Mat<f64>) -> usize {
        let mut b = 0;
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                if a[(i, j)] != 0.0 {
                    b = b.max(i.abs_diff(j));
                }
            }
        }
        b
    }

    /// Half-bandwidth.
    pub(crate) fn half_bandwidth(&self) -> usize {
        self.b
    }

    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        i * (2 * self.b + 1) + (j + self.b - i)
    }

    /// Sets the whole matrix from `entry(i, j)` for the entries inside the band.
    pub(crate) fn fill(&mut self, entry: impl Fn(usize, usize) -> f64) {
        let (n, b) = (self.n, self.b);
        for i in 0..n {
            for j in i.saturating_sub(b)..(i + b + 1).min(n) {
                let k = self.at(i, j);
                self.data[k] = entry(i, j);
            }
        }
    }

    /// Factors A = L U in place (L unit lower). False if a pivot is zero or not finite.
    pub(crate) fn factor(&mut self) -> bool {
        let (n, b) = (self.n, self.b);
        for k in 0..n {
            let pivot = self.data[self.at(k, k)];
            if !(pivot != 0.0 && pivot.is_finite()) {
                return false;
            }
            self.inverse_diagonal[k] = 1.0 / pivot;
            let last = (k + b).min(n - 1);
            for i in k + 1..=last {
                let ik = self.at(i, k);
                let l = self.data[ik] / pivot;
                self.data[ik] = l;
                if l == 0.0 {
                    continue;
                }
                let (row_k, row_i) = (self.at(k, k + 1), self.at(i, k + 1));
                for t in 0..last - k {
                    self.data[row_i + t] -= l * self.data[row_k + t];
                }
            }
        }
        true
    }

    /// x = A⁻¹ r from the factors (`x` may not alias `r`). Allocates nothing.
    pub(crate) fn solve(&self, r: &[f64], x: &mut [f64]) {
        // the half-bandwidths of rotors numbered node by node (4 DOFs a node: 7; a pedestal
        // or a coarser model less), with the band's length known to the compiler
        match self.b {
            7 => self.solve_band::<7>(r, x),
            6 => self.solve_band::<6>(r, x),
            5 => self.solve_band::<5>(r, x),
            3 => self.solve_band::<3>(r, x),
            _ => self.solve_any(r, x),
        }
    }

    /// [`solve`](Self::solve) for any half-bandwidth.
    fn solve_any(&self, r: &[f64], x: &mut [f64]) {
        let (n, b, w) = (self.n, self.b, 2 * self.b + 1);
        // L y = r: row i's multipliers are the b entries left of its diagonal
        for i in 0..n {
            x[i] = r[i] - self.lower_sum(i, x);
        }
        // U x = y: row i's diagonal and the b entries right of it
        for i in (0..n).rev() {
            let last = (i + b).min(n - 1);
            let row = &self.data[i * w + b..i * w + b + (last - i) + 1];
            x[i] =
                (x[i] - dot_nearest_last(&row[1..], &x[i + 1..=last])) * self.inverse_diagonal[i];
        }
    }

    /// Row i's sum Σ L[i][j] y[j] over the band left of the diagonal.
    fn lower_sum(&self, i: usize, y: &[f64]) -> f64 {
        let (b, w) = (self.b, 2 * self.b + 1);
        let first = i.saturating_sub(b);
        dot(&self.data[i * w + (first + b - i)..i * w + b], &y[first..i])
    }

    /// [`solve`](Self::solve) with the half-bandwidth B a constant: the rows whose band is
    /// whole take fixed-length sums (the same products summed in the same order as
    /// [`solve_any`](Self::solve_any): the same result, bit for bit), the ends the general ones.
    ///
    /// Both substitutions are chains, each unknown waiting for the one found before it, so
    /// their cost is the chain's latency, not the arithmetic: the unknown just found is carried
    /// in a register (read back from `x` by a wide load it waited for the store to land) and
    /// enters its row's sum last, after the products that do not wait for it (the back
    /// substitution summed it first, so all B additions waited: ORC-9000's step 4.3 → 3.1 µs).
    fn solve_band<const B: usize>(&self, r: &[f64], x: &mut [f64]) {
        let (n, w) = (self.n, 2 * B + 1);
        if n <= 2 * B {
            return self.solve_any(r, x);
        }
        for i in 0..B {
            x[i] = r[i] - self.lower_sum(i, x);
        }
        let mut last = x[B - 1];
        for i in B..n {
            let row: &[f64; B] = fixed(&self.data[i * w..]);
            let head = dot(&row[..B - 1], &x[i - B..i - 1]);
            last = r[i] - (head + row[B - 1] * last);
            x[i] = last;
        }
        for i in (n - B..n).rev() {
            let row = &self.data[i * w + B + 1..i * w + B + (n - i)];
            x[i] = (x[i] - dot_nearest_last(row, &x[i + 1..n])) * self.inverse_diagonal[i];
        }
        let mut last = x[n - B];
        for i in (0..n - B).rev() {
            let row: &[f64; B] = fixed(&self.data[i * w + B + 1..]);
            let far = dot_nearest_last(&row[1..], &x[i + 2..i + 1 + B]);
            last = (x[i] - (far + row[0] * last)) * self.inverse_diagonal[i];
            x[i] = last;
        }
    }
}

/// Σ a_k b_k in order (the triangular solves' row sums).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(u, v)| u * v).sum()
}

/// Σ a_k b_k from the last term to the first (the back substitution's row sums: b_0 is the
/// unknown nearest the diagonal, found last). An empty sum is −0.0, as `Iterator::sum`'s.
#[inline(always)]
fn dot_nearest_last(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).rev().fold(-0.0, |s, (u, v)| s + u * v)
}

/// The first N entries of `v` as an array (v has at least N: the band's rows do).
#[inline(always)]
fn fixed<const N: usize>(v: &[f64]) -> &[f64; N] {
    v.first_chunk::<N>()
        .expect("a band row holds its half-bandwidth's entries")
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// A nonsymmetric band matrix: an SPD pentadiagonal part plus a skew tridiagonal one.
    fn sample(n: usize) -> Mat<f64> {
        Mat::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 6.0 + (i % 3) as f64,
            1 => -1.5 + if i > j { 0.7 } else { -0.7 },
            2 => 0.4,
            _ => 0.0,
        })
    }

    #[test]
    fn solves_a_band_system_to_round_off() {
        // residual of the solve against the dense matrix (a second method: the product)
        let n = 40;
        let a = sample(n);
        let b = BandLu::half_bandwidth_of(&a);
        assert_eq!(b, 2);
        let mut lu = BandLu::zeros(n, b);
        lu.fill(|i, j| a[(i, j)]);
        assert!(lu.factor());
        let r: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = vec![0.0; n];
        lu.solve(&r, &mut x);
        let worst = (0..n)
            .map(|i| ((0..n).map(|j| a[(i, j)] * x[j]).sum::<f64>() - r[i]).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-13, "residual {worst}");
    }

    /// The fixed-bandwidth solves against the general one (the same sums in the same order):
    /// equal bit for bit, for every specialised half-bandwidth and sizes around 2b.
    #[test]
    fn fixed_band_solves_equal_the_general_solve_exactly() {
        for b in [3, 5, 6, 7] {
            for n in [2 * b, 2 * b + 1, 4 * b + 3, 124] {
                let a = Mat::<f64>::from_fn(n, n, |i, j| {
                    let d = i.abs_diff(j);
                    if d > b {
                        0.0
                    } else if d == 0 {
                        10.0 + (i % 5) as f64
                    } else {
                        ((i * 7 + j * 3) as f64 * 0.61).sin() / d as f64
                    }
                });
                let mut lu = BandLu::zeros(n, b);
                lu.fill(|i, j| a[(i, j)]);
                assert!(lu.factor());
                let r: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos() * 1e3).collect();
                let (mut x, mut y) = (vec![0.0; n], vec![0.0; n]);
                lu.solve(&r, &mut x);
                lu.solve_any(&r, &mut y);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&x), bits(&y), "b {b}, n {n}");
            }
        }
    }

    #[test]
    fn a_zero_pivot_is_refused() {
        let mut lu = BandLu::zeros(3, 1);
        lu.fill(|i, j| if i == j && i == 1 { 0.0 } else { 1.0 });
        // row 1 after elimination: 0 − 1·1 = −1 ≠ 0; make the first pivot zero instead
        lu.fill(|i, j| if i == 0 && j == 0 { 0.0 } else { 1.0 });
        assert!(!lu.factor());
    }
}
