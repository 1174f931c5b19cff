//! Cholesky factorisation of a symmetric positive-definite band matrix, in place, allocation-free.
//!
//! The film's finite-volume matrix restricted to the pressurised nodes is a symmetric M-matrix
//! whose bandwidth is the number of axial nodes (columns ordered around the circumference, nodes
//! within a column along the axis). Factor cost n·b²/2, solve cost 2·n·b.

/// Lower band of an n × n symmetric matrix with half-bandwidth `b`, stored by columns (LAPACK's
/// `dpbtrf` 'L' layout): column `j` holds `A[j][j] … A[j+b][j]` contiguously, so the factor's
/// updates are unit-stride `axpy`s. Storage is reserved once for the largest `n` and `b` the
/// owner will ever need.
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
            data: vec![0.0; (max_n + max_b) * (max_b + 1)],
            n: 0,
            b: 0,
        }
    }

    /// Starts a new zero matrix of `n` rows and half-bandwidth `b` within the reserved room.
    pub(crate) fn reset(&mut self, n: usize, b: usize) {
        // b extra columns of padding let the last columns' updates run unclipped
        let len = (n + b) * (b + 1);
        assert!(len <= self.data.len(), "band matrix capacity exceeded");
        self.n = n;
        self.b = b;
        self.data[..len].fill(0.0);
    }

    /// Adds `value` to `A[i][j]` for `j ≤ i ≤ j + b` (the symmetric entry is implied).
    #[inline]
    pub(crate) fn add(&mut self, i: usize, j: usize, value: f64) {
        debug_assert!(j <= i && i - j <= self.b);
        self.data[j * (self.b + 1) + (i - j)] += value;
    }

    /// Factors A = L Lᵀ in place (right-looking). Returns false if a pivot is not positive.
    pub(crate) fn factor(&mut self) -> bool {
        let n = self.n;
        let d = &mut self.data;
        // constant widths let the compiler unroll the short column updates
        match self.b + 1 {
            3 => factor_width(d, n, 3),
            4 => factor_width(d, n, 4),
            5 => factor_width(d, n, 5),
            6 => factor_width(d, n, 6),
            7 => factor_width(d, n, 7),
            8 => factor_width(d, n, 8),
            9 => factor_width(d, n, 9),
            10 => factor_width(d, n, 10),
            11 => factor_width(d, n, 11),
            12 => factor_width(d, n, 12),
            13 => factor_width(d, n, 13),
            17 => factor_width(d, n, 17),
            21 => factor_width(d, n, 21),
            w => factor_width(d, n, w),
        }
    }

    /// Solves L Lᵀ x = r in place (after [`factor`](Self::factor)); `x` holds r on entry.
    pub(crate) fn solve(&self, x: &mut [f64]) {
        let (n, d) = (self.n, &self.data);
        match self.b + 1 {
            3 => solve_width(d, n, 3, x),
            4 => solve_width(d, n, 4, x),
            5 => solve_width(d, n, 5, x),
            6 => solve_width(d, n, 6, x),
            7 => solve_width(d, n, 7, x),
            8 => solve_width(d, n, 8, x),
            9 => solve_width(d, n, 9, x),
            10 => solve_width(d, n, 10, x),
            11 => solve_width(d, n, 11, x),
            12 => solve_width(d, n, 12, x),
            13 => solve_width(d, n, 13, x),
            17 => solve_width(d, n, 17, x),
            21 => solve_width(d, n, 21, x),
            w => solve_width(d, n, w, x),
        }
    }
}

impl BandMatrix {
    /// Solves L Lᵀ X = R for four right-hand sides at once, stored interleaved (`x[k]` holds row
    /// k of all four): one sweep over the factor serves all four, and the four independent
    /// chains overlap in the pipeline.
    pub(crate) fn solve4(&self, x: &mut [[f64; 4]]) {
        let (n, d) = (self.n, &self.data);
        match self.b + 1 {
            9 => solve4_width(d, n, 9, x),
            10 => solve4_width(d, n, 10, x),
            11 => solve4_width(d, n, 11, x),
            12 => solve4_width(d, n, 12, x),
            w => solve4_width(d, n, w, x),
        }
    }
}

#[inline(always)]
fn solve4_width(data: &[f64], n: usize, w: usize, x: &mut [[f64; 4]]) {
    let x = &mut x[..n];
    for (k, col) in data.chunks_exact(w).take(n).enumerate() {
        let (done, rest) = x.split_at_mut(k + 1);
        let inv = col[0];
        let yk = done[k].map(|v| v * inv);
        done[k] = yk;
        for (xi, &l) in rest.iter_mut().zip(&col[1..]) {
            for r in 0..4 {
                xi[r] -= l * yk[r];
            }
        }
    }
    for k in (0..n).rev() {
        let col = &data[k * w..(k + 1) * w];
        let (head, rest) = x.split_at_mut(k + 1);
        // two partial sums halve the dependency chain of the reduction
        let (mut s0, mut s1) = ([0.0; 4], [0.0; 4]);
        let band = &col[1..];
        let mut pairs = rest.chunks_exact(2).zip(band.chunks_exact(2));
        for (xs, ls) in &mut pairs {
            for r in 0..4 {
                s0[r] += ls[0] * xs[0][r];
                s1[r] += ls[1] * xs[1][r];
            }
        }
        let m = rest.len().min(band.len());
        if m % 2 == 1 {
            for r in 0..4 {
                s0[r] += band[m - 1] * rest[m - 1][r];
            }
        }
        let inv = col[0];
        for r in 0..4 {
            head[k][r] = (head[k][r] - s0[r] - s1[r]) * inv;
        }
    }
}

/// Band Cholesky of `n` columns of width `w` = b + 1 (see [`BandMatrix`]).
#[inline(always)]
fn factor_width(data: &mut [f64], n: usize, w: usize) -> bool {
    for k in 0..n {
        let (head, tail) = data.split_at_mut((k + 1) * w);
        let col_k = &mut head[k * w..];
        let pivot = col_k[0];
        if pivot <= 0.0 || !pivot.is_finite() {
            return false;
        }
        let inv = 1.0 / pivot.sqrt();
        // the diagonal is kept as its reciprocal: the solves multiply instead of divide
        col_k[0] = inv;
        for v in &mut col_k[1..] {
            *v *= inv;
        }
        // A[i][j] −= L[i][k] L[j][k] for k < j ≤ i ≤ k + b (padding past n is harmless)
        for m in 1..w {
            let ljk = col_k[m];
            let col_j = &mut tail[(m - 1) * w..(m - 1) * w + (w - m)];
            for (a, l) in col_j.iter_mut().zip(&col_k[m..]) {
                *a -= l * ljk;
            }
        }
    }
    true
}

/// Forward and back substitution with the factor of [`factor_width`]: column `axpy`s forward,
/// column dot products backward, both unit-stride.
#[inline(always)]
fn solve_width(data: &[f64], n: usize, w: usize, x: &mut [f64]) {
    let x = &mut x[..n];
    // forward: L y = r
    for (k, col) in data.chunks_exact(w).take(n).enumerate() {
        let (done, rest) = x.split_at_mut(k + 1);
        let yk = done[k] * col[0];
        done[k] = yk;
        for (xi, l) in rest.iter_mut().zip(&col[1..]) {
            *xi -= l * yk;
        }
    }
    // backward: Lᵀ x = y
    for k in (0..n).rev() {
        let col = &data[k * w..(k + 1) * w];
        let (head, rest) = x.split_at_mut(k + 1);
        let s = dot(&col[1..], rest);
        head[k] = (head[k] - s) * col[0];
    }
}

/// Dot product of two equal-length slices with four independent partial sums.
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let len = a.len().min(b.len());
    let (a, b) = (&a[..len], &b[..len]);
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for q in 0..4 {
            acc[q] += x[q] * y[q];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// LU factorisation with partial pivoting of a general (non-symmetric) band matrix, in place,
/// (`src/dynamics/band_lu.rs` does not pivot: fine for its near-SPD Newmark matrix, not here),
/// allocation-free after [`PivotedBandLu::with_capacity`] (the mass-conserving film's mixed system of
/// pressures and fluid fractions is not symmetric).
///
/// Stored by columns in LAPACK's `dgbtrf` layout: `kl` sub-diagonals, `ku` super-diagonals and
/// `kl` more rows for the fill-in that row interchanges bring; `A[i][j]` lives at
/// `j·ld + (kl + ku + i − j)` with `ld = 2·kl + ku + 1`. Factor cost n·kl·(kl + ku).
#[derive(Debug, Clone, Default)]
pub(crate) struct PivotedBandLu {
    /// The band and its fill-in by columns, overwritten by L and U.
    data: Vec<f64>,
    /// Row interchanged with row k at step k.
    pivot: Vec<usize>,
    /// Rows.
    n: usize,
    /// Sub-diagonals.
    kl: usize,
    /// Super-diagonals (before fill-in).
    ku: usize,
}

impl PivotedBandLu {
    /// Leading dimension: stored rows a column.
    fn ld(&self) -> usize {
        2 * self.kl + self.ku + 1
    }

    /// Position of A[i][j] in `data`.
    #[inline]
    fn at(&self, i: usize, j: usize) -> usize {
        j * self.ld() + (self.kl + self.ku + i - j)
    }

    /// Reserves room for matrices up to `max_n` rows with up to `max_k` sub- and super-diagonals.
    pub(crate) fn with_capacity(max_n: usize, max_k: usize) -> Self {
        Self {
            data: vec![0.0; max_n * (3 * max_k + 1)],
            pivot: vec![0; max_n],
            ..Self::default()
        }
    }

    /// Starts a new zero matrix of `n` rows with `kl` sub- and `ku` super-diagonals.
    pub(crate) fn reset(&mut self, n: usize, kl: usize, ku: usize) {
        let len = n * (2 * kl + ku + 1);
        assert!(
            len <= self.data.len() && n <= self.pivot.len(),
            "band LU capacity exceeded"
        );
        (self.n, self.kl, self.ku) = (n, kl, ku);
        self.data[..len].fill(0.0);
    }

    /// Adds `value` to `A[i][j]` for `j − ku ≤ i ≤ j + kl`.
    #[inline]
    pub(crate) fn add(&mut self, i: usize, j: usize, value: f64) {
        debug_assert!(i <= j + self.kl && j <= i + self.ku);
        let k = self.at(i, j);
        self.data[k] += value;
    }

    /// Factors P A = L U in place (partial pivoting). Returns false if A is singular.
    pub(crate) fn factor(&mut self) -> bool {
        let (n, kl) = (self.n, self.kl);
        let reach = self.ku + self.kl;
        for k in 0..n {
            let last = (k + kl).min(n - 1);
            let mut p = k;
            for i in k + 1..=last {
                if self.data[self.at(i, k)].abs() > self.data[self.at(p, k)].abs() {
                    p = i;
                }
            }
            self.pivot[k] = p;
            let pivot = self.data[self.at(p, k)];
            if pivot == 0.0 || !pivot.is_finite() {
                return false;
            }
            let right = (k + reach).min(n - 1);
            if p != k {
                for j in k..=right {
                    let (a, b) = (self.at(k, j), self.at(p, j));
                    self.data.swap(a, b);
                }
            }
            for i in k + 1..=last {
                let ik = self.at(i, k);
                let l = self.data[ik] / pivot;
                self.data[ik] = l;
                if l != 0.0 {
                    for j in k + 1..=right {
                        let (ij, kj) = (self.at(i, j), self.at(k, j));
                        self.data[ij] -= l * self.data[kj];
                    }
                }
            }
        }
        true
    }

    /// Solves A x = r in place (after [`factor`](Self::factor)); `x` holds r on entry.
    pub(crate) fn solve(&self, x: &mut [f64]) {
        let (n, kl) = (self.n, self.kl);
        let reach = self.ku + self.kl;
        for k in 0..n {
            x.swap(k, self.pivot[k]);
            for i in k + 1..=(k + kl).min(n - 1) {
                x[i] -= self.data[self.at(i, k)] * x[k];
            }
        }
        for k in (0..n).rev() {
            let mut s = x[k];
            for j in k + 1..=(k + reach).min(n - 1) {
                s -= self.data[self.at(k, j)] * x[j];
            }
            x[k] = s / self.data[self.at(k, k)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in [−½, ½) from a linear congruential generator seeded with `seed`.
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// A random diagonally dominant band matrix: the factor reproduces A x = r to round-off.
    #[test]
    fn solves_a_diagonally_dominant_band_system() {
        let (n, b) = (37, 5);
        let mut dense = vec![vec![0.0; n]; n];
        let mut rnd = uniform(12345);
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

    /// A film-like matrix (the five-point Reynolds operator −∇·(h³∇) on a 60 × 10 half grid,
    /// columns around the circumference, h = 1 + 0.8 cos θ: an M-matrix of half-bandwidth 10
    /// whose coefficients span 700:1) factored here and by faer's dense Cholesky (a second
    /// method): the factors' entries agree to 1e-12 of the largest and the solutions to 1e-10.
    #[test]
    fn agrees_with_faers_dense_cholesky_on_a_film_matrix() {
        use faer::linalg::solvers::Solve;
        let (nth, nz) = (60, 10);
        let n = nth * nz;
        let h3 = |t: f64| (1.0 + 0.8 * (std::f64::consts::TAU * t / nth as f64).cos()).powi(3);
        let mut dense = faer::Mat::<f64>::zeros(n, n);
        let mut m = BandMatrix::with_capacity(n, nz);
        m.reset(n, nz);
        let idx = |i: usize, k: usize| i * nz + k;
        for i in 0..nth {
            for k in 0..nz {
                let p = idx(i, k);
                // circumferential faces (no wrap: the film's pressurised zone is open), axial
                // faces, the outer axial face at ambient pressure (a Dirichlet boundary)
                let mut diag = 0.0;
                for (di, w) in [
                    (i.checked_sub(1), h3(i as f64 - 0.5)),
                    ((i + 1 < nth).then_some(i + 1), h3(i as f64 + 0.5)),
                ] {
                    diag += w;
                    if let Some(j) = di {
                        let q = idx(j, k);
                        if q < p {
                            m.add(p, q, -w);
                        }
                        dense[(p, q)] = -w;
                    }
                }
                let wz = 4.0 * h3(i as f64);
                for dk in [k.checked_sub(1), Some(k + 1)] {
                    diag += wz;
                    if let Some(j) = dk.filter(|&j| j < nz) {
                        let q = idx(i, j);
                        if q < p {
                            m.add(p, q, -wz);
                        }
                        dense[(p, q)] = -wz;
                    }
                }
                m.add(p, p, diag);
                dense[(p, p)] = diag;
            }
        }
        let rhs: Vec<f64> = (0..n).map(|p| ((p as f64) * 0.13).sin()).collect();
        let mut x = rhs.clone();
        assert!(m.factor());
        m.solve(&mut x);
        let llt = dense
            .llt(faer::Side::Lower)
            .expect("the film matrix is positive definite");
        let want = llt.solve(faer::Mat::<f64>::from_fn(n, 1, |i, _| rhs[i]));
        let scale = (0..n).map(|i| want[(i, 0)].abs()).fold(0.0, f64::max);
        for i in 0..n {
            assert!((x[i] - want[(i, 0)]).abs() < 1e-10 * scale, "row {i}");
        }
        // the band keeps 1/L[j][j] on its diagonal and L[j+r][j] below it
        let l = llt.L();
        let lmax = (0..n).map(|j| l[(j, j)]).fold(0.0, f64::max);
        for j in 0..n {
            for r in 0..=nz.min(n - 1 - j) {
                let band = m.data[j * (nz + 1) + r];
                let got = if r == 0 { 1.0 / band } else { band };
                assert!(
                    (got - l[(j + r, j)]).abs() < 1e-12 * lmax,
                    "L[{}][{j}]",
                    j + r
                );
            }
        }
    }

    /// A random non-symmetric band matrix with small diagonal entries (row interchanges are
    /// needed): the LU factor reproduces A x = r to round-off (residual of the dense product).
    #[test]
    fn band_lu_solves_a_system_that_needs_pivoting() {
        let (n, kl, ku) = (41, 4, 3);
        let mut rnd = uniform(987);
        let mut dense = vec![vec![0.0; n]; n];
        let mut lu = PivotedBandLu::with_capacity(n, kl.max(ku));
        lu.reset(n, kl, ku);
        for (i, row) in dense.iter_mut().enumerate() {
            for (j, a) in row.iter_mut().enumerate() {
                if i <= j + kl && j <= i + ku {
                    // the diagonal is the smallest entry of its row
                    let v = if i == j { 1e-3 * rnd() } else { rnd() };
                    *a = v;
                    lu.add(i, j, v);
                }
            }
        }
        let rhs: Vec<f64> = (0..n).map(|p| ((p as f64) * 0.37).cos()).collect();
        let mut x = rhs.clone();
        assert!(lu.factor());
        lu.solve(&mut x);
        let xmax = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for i in 0..n {
            let ax: f64 = (0..n).map(|j| dense[i][j] * x[j]).sum();
            assert!(
                (ax - rhs[i]).abs() < 1e-12 * xmax,
                "row {i}: {ax} vs {}",
                rhs[i]
            );
        }
        // and a singular matrix is refused
        lu.reset(3, 1, 1);
        lu.add(0, 0, 1.0);
        lu.add(1, 0, 1.0);
        assert!(!lu.factor());
    }
}
