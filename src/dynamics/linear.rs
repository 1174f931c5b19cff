//! The linear part of the implicit Newmark step, factored once and reused.
//!
//! Average-acceleration Newmark (γ = ½, β = ¼) turns seed eq. 5 at t + h into
//!
//! ```text
//!   K_eff q_{n+1} = r_n + F_b(q_{n+1}, q̇_{n+1}),   K_eff = K + (2/h) C_t + (4/h²) M,
//!   r_n = F_ext + M(4/h² q_n + 4/h q̇_n + q̈_n) + C_t(2/h q_n + q̇_n),   C_t = C + Ω G,
//! ```
//!
//! where F_b acts only on the bearing DOFs B. With Z = K_eff⁻¹ E_B and S = E_Bᵀ Z the step
//! condenses exactly onto B: q_B = a + S f_B, a = (K_eff⁻¹ r_n)_B, and the full state follows as
//! q = K_eff⁻¹ r_n + Z f_B. The nonlinear iteration therefore runs on a handful of unknowns.

use super::band_lu::BandLu;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::{Mat, Par};

/// M, C and G in compressed rows on their common pattern (an entry where any of the three is
/// nonzero), for the step's right-hand side: one pass over the rows with four independent sums
/// (the products' add chains overlap) instead of four passes. A zero entry of one matrix adds an
/// exact zero to its sum, so each sum is the same, bit for bit, as over that matrix's own
/// nonzeros in the same column order. Where the three are banded (a rotor's FE matrices with
/// its DOFs node by node), the rows away from the ends are also held as a band ([`McgBand`]),
/// which sums the same products in the same order for [`LANES`] rows at once.
#[derive(Debug, Clone)]
pub(crate) struct SparseMcg {
    start: Vec<usize>,
    /// per entry: column, then the M, C and G values
    entries: Vec<(usize, [f64; 3])>,
    /// rows whose whole band lies inside the matrix, in band form (None: a wide band)
    band: Option<McgBand>,
}

/// Rows the band kernel sums at once (independent sums: vector lanes).
const LANES: usize = 4;

/// Rows `lo..hi` of M, C and G in band form: for each block of [`LANES`] rows and each
/// diagonal k = 0..2b (column i − b + k of row i), the LANES values of M, then of C, then of G.
/// No column indices: the products are straight loops over contiguous memory.
#[derive(Debug, Clone)]
struct McgBand {
    b: usize,
    lo: usize,
    hi: usize,
    values: Vec<f64>,
    /// The same blocks with M and C_t = C + Ω_f G (Ω_f = `spin`) only: the step's products
    /// M x_m + C x_c + Ω_f G x_c as two sums (round-off differs from three: ≤ 1e-15 relative
    /// per row; `fused_band_products_agree_with_the_compressed_rows`).
    fused: Vec<f64>,
    /// Ω_f of `fused` (rad/s); NaN before the first product.
    spin: f64,
    /// The CPU has AVX (detected at run time): the fixed-band kernel runs on 4-wide vectors,
    /// one block's LANES rows in one register (the same products and sums, lane by lane).
    avx: bool,
}

impl McgBand {
    /// The band form of rows lo..hi, lo the first multiple of LANES ≥ b and hi − lo a multiple
    /// of LANES with hi + b ≤ n (every column i − b..=i + b of those rows exists). None if the
    /// band is too wide for it to pay (fewer than half the rows inside).
    fn of(m: &Mat<f64>, c: &Mat<f64>, g: &Mat<f64>) -> Option<Self> {
        let n = m.nrows();
        let b = [m, c, g]
            .iter()
            .map(|a| BandLu::half_bandwidth_of(a))
            .max()
            .unwrap_or(0);
        let lo = b.div_ceil(LANES) * LANES;
        let hi = lo + (n.saturating_sub(b + lo)) / LANES * LANES;
        if 2 * (hi - lo) < n {
            return None;
        }
        let w = 2 * b + 1;
        let mut values = Vec::with_capacity((hi - lo) * w * 3);
        for i0 in (lo..hi).step_by(LANES) {
            for k in 0..w {
                for a in [m, c, g] {
                    values.extend((i0..i0 + LANES).map(|i| a[(i, i - b + k)]));
                }
            }
        }
        let fused = vec![0.0; (hi - lo) * w * 2];
        Some(Self {
            b,
            lo,
            hi,
            values,
            fused,
            spin: f64::NAN,
            #[cfg(target_arch = "x86_64")]
            avx: std::arch::is_x86_feature_detected!("avx"),
            #[cfg(not(target_arch = "x86_64"))]
            avx: false,
        })
    }

    /// Sets `fused` to M and C + Ω_f G (when Ω_f changed: a speed change, never in a steady
    /// step). Allocates nothing.
    fn set_spin(&mut self, omega_f: f64) {
        if omega_f.to_bits() == self.spin.to_bits() {
            return;
        }
        let per = 3 * LANES;
        for (src, dst) in self
            .values
            .chunks_exact(per)
            .zip(self.fused.chunks_exact_mut(2 * LANES))
        {
            for l in 0..LANES {
                dst[l] = src[l];
                dst[LANES + l] = src[LANES + l] + omega_f * src[2 * LANES + l];
            }
        }
        self.spin = omega_f;
    }

    /// out[lo..hi] += M x_m + (C + Ω_f G) x_c with the fused values (see [`set_spin`](Self::set_spin)).
    fn add_fused_products(&self, x_m: &[f64], x_c: &[f64], out: &mut [f64]) {
        // the half-bandwidths of rotors numbered node by node (4 DOFs a node: 7), with the
        // band's width known to the compiler (no bounds checks inside a block)
        match self.b {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `avx` is true only where the CPU was found to have AVX (`of`)
            7 if self.avx => unsafe { self.add_fused_band_avx::<7, 15, 18>(x_m, x_c, out) },
            7 => self.add_fused_band::<7, 15, 18>(x_m, x_c, out),
            _ => self.add_fused_any(x_m, x_c, out),
        }
    }

    /// [`add_fused_band`](Self::add_fused_band) on AVX: a block's LANES = 4 sums of M and of
    /// C_t in one 4-wide register each, a diagonal's 4 values and the 4 entries of x they meet
    /// loaded whole (multiply, then add: no fused multiply-add, so each lane rounds as the
    /// scalar code does; the same result, bit for bit,
    /// `fixed_band_products_equal_the_general_ones_exactly`). Only where the CPU has AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn add_fused_band_avx<const B: usize, const W: usize, const X: usize>(
        &self,
        x_m: &[f64],
        x_c: &[f64],
        out: &mut [f64],
    ) {
        use std::arch::x86_64::{
            _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_storeu_pd,
        };
        assert!(LANES == 4 && W == 2 * B + 1 && X == 2 * B + LANES && self.b == B);
        let (values, _) = self.fused.as_chunks::<{ 2 * LANES }>();
        let (blocks, _) = values.as_chunks::<W>();
        for (i0, block) in (self.lo..self.hi).step_by(LANES).zip(blocks) {
            let first = i0 - B;
            let xm: &[f64; X] = x_m[first..].first_chunk().expect("inside the band");
            let xc: &[f64; X] = x_c[first..].first_chunk().expect("inside the band");
            let o: &mut [f64; LANES] = out[i0..].first_chunk_mut().expect("inside the band");
            let (mut sm, mut sc) = (_mm256_setzero_pd(), _mm256_setzero_pd());
            for (k, v) in block.iter().enumerate() {
                let xmk: &[f64; LANES] = xm[k..].first_chunk().expect("k + LANES ≤ X");
                let xck: &[f64; LANES] = xc[k..].first_chunk().expect("k + LANES ≤ X");
                // SAFETY: each load reads the 4 f64 of an array of at least 4 (v holds 8)
                let (vm, vc, am, ac) = unsafe {
                    (
                        _mm256_loadu_pd(v.as_ptr()),
                        _mm256_loadu_pd(v[LANES..].as_ptr()),
                        _mm256_loadu_pd(xmk.as_ptr()),
                        _mm256_loadu_pd(xck.as_ptr()),
                    )
                };
                sm = _mm256_add_pd(sm, _mm256_mul_pd(vm, am));
                sc = _mm256_add_pd(sc, _mm256_mul_pd(vc, ac));
            }
            // SAFETY: reads and writes the 4 f64 of `o`
            unsafe {
                let sum = _mm256_add_pd(_mm256_loadu_pd(o.as_ptr()), _mm256_add_pd(sm, sc));
                _mm256_storeu_pd(o.as_mut_ptr(), sum);
            }
        }
    }

    /// [`add_fused_products`](Self::add_fused_products) for any half-bandwidth.
    fn add_fused_any(&self, x_m: &[f64], x_c: &[f64], out: &mut [f64]) {
        let w = 2 * self.b + 1;
        let blocks = self.fused.chunks_exact(2 * LANES * w);
        for (i0, block) in (self.lo..self.hi).step_by(LANES).zip(blocks) {
            let (mut sm, mut sc) = ([0.0; LANES], [0.0; LANES]);
            let first = i0 - self.b;
            for (k, v) in block.chunks_exact(2 * LANES).enumerate() {
                let xm: &[f64; LANES] = x_m[first + k..].first_chunk().expect("inside the band");
                let xc: &[f64; LANES] = x_c[first + k..].first_chunk().expect("inside the band");
                for l in 0..LANES {
                    sm[l] += v[l] * xm[l];
                    sc[l] += v[LANES + l] * xc[l];
                }
            }
            for (l, o) in out[i0..i0 + LANES].iter_mut().enumerate() {
                *o += sm[l] + sc[l];
            }
        }
    }

    /// [`add_fused_products`](Self::add_fused_products) with the half-bandwidth B a constant:
    /// each block's W = 2B + 1 diagonals and the X = 2B + LANES entries of x it reads taken
    /// once as arrays (W and X given with B: checked), so the block's sums run without bounds
    /// checks, the LANES independent sums side by side. The same products summed in the same
    /// order as [`add_fused_any`](Self::add_fused_any): the same result, bit for bit
    /// (`fixed_band_products_equal_the_general_ones_exactly`).
    fn add_fused_band<const B: usize, const W: usize, const X: usize>(
        &self,
        x_m: &[f64],
        x_c: &[f64],
        out: &mut [f64],
    ) {
        assert!(W == 2 * B + 1 && X == 2 * B + LANES && self.b == B);
        let (values, _) = self.fused.as_chunks::<{ 2 * LANES }>();
        let (blocks, _) = values.as_chunks::<W>();
        for (i0, block) in (self.lo..self.hi).step_by(LANES).zip(blocks) {
            let (mut sm, mut sc) = ([0.0; LANES], [0.0; LANES]);
            let first = i0 - B;
            let xm: &[f64; X] = x_m[first..].first_chunk().expect("inside the band");
            let xc: &[f64; X] = x_c[first..].first_chunk().expect("inside the band");
            for (k, v) in block.iter().enumerate() {
                for l in 0..LANES {
                    sm[l] += v[l] * xm[k + l];
                    sc[l] += v[LANES + l] * xc[k + l];
                }
            }
            for (l, o) in out[i0..i0 + LANES].iter_mut().enumerate() {
                *o += sm[l] + sc[l];
            }
        }
    }

    /// out[lo..hi] += M x_m + C x_c + Ω_f G x_c (+ Ω_d G x_g when `WITH_D`), each of the four
    /// sums over the row's columns in ascending order from 0, as the compressed rows sum them.
    fn add_products<const WITH_D: bool>(
        &self,
        [x_m, x_c, x_g]: [&[f64]; 3],
        omega_f: f64,
        omega_d: f64,
        out: &mut [f64],
    ) {
        let w = 2 * self.b + 1;
        let blocks = self.values.chunks_exact(3 * LANES * w);
        for (i0, block) in (self.lo..self.hi).step_by(LANES).zip(blocks) {
            let (mut sm, mut sc, mut sg, mut sd) =
                ([0.0; LANES], [0.0; LANES], [0.0; LANES], [0.0; LANES]);
            let first = i0 - self.b;
            for (k, v) in block.chunks_exact(3 * LANES).enumerate() {
                let (xm, xc) = (&x_m[first + k..][..LANES], &x_c[first + k..][..LANES]);
                let xg = &x_g[first + k..][..LANES];
                for l in 0..LANES {
                    sm[l] += v[l] * xm[l];
                    sc[l] += v[LANES + l] * xc[l];
                    sg[l] += v[2 * LANES + l] * xc[l];
                    if WITH_D {
                        sd[l] += v[2 * LANES + l] * xg[l];
                    }
                }
            }
            for (l, o) in out[i0..i0 + LANES].iter_mut().enumerate() {
                *o += sm[l];
                *o += sc[l];
                *o += omega_f * sg[l];
                if WITH_D {
                    *o += omega_d * sd[l];
                }
            }
        }
    }
}

impl SparseMcg {
    /// The entries of three dense matrices of one size where any is nonzero.
    pub(crate) fn from_dense(m: &Mat<f64>, c: &Mat<f64>, g: &Mat<f64>) -> Self {
        let mut start = vec![0];
        let mut entries = Vec::new();
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                let v = [m[(i, j)], c[(i, j)], g[(i, j)]];
                if v != [0.0; 3] {
                    entries.push((j, v));
                }
            }
            start.push(entries.len());
        }
        Self {
            start,
            entries,
            band: McgBand::of(m, c, g),
        }
    }

    /// out += M x_m + C x_c + Ω_f G x_c + Ω_d G x_g (summed in that order, row by row); the last
    /// term is left out when Ω_d = 0 (it would add exact zeros: the inputs are finite).
    /// Allocates nothing.
    pub(crate) fn add_products(&self, x: [&[f64]; 3], omega_f: f64, omega_d: f64, out: &mut [f64]) {
        if omega_d == 0.0 {
            self.add_products_with::<false>(x, omega_f, omega_d, out);
        } else {
            self.add_products_with::<true>(x, omega_f, omega_d, out);
        }
    }

    /// The step's products, out += M x_m + C x_c + Ω_f G x_c + Ω_d G x_g: as
    /// [`add_products`](Self::add_products), except that at a steady speed (Ω_d = 0) the band
    /// rows take M and C + Ω_f G (two sums instead of three: the same to round-off, not bit for
    /// bit). Allocates nothing (the fused band is refreshed in place when Ω_f changes).
    pub(crate) fn add_step_products(
        &mut self,
        x: [&[f64]; 3],
        omega_f: f64,
        omega_d: f64,
        out: &mut [f64],
    ) {
        let Some(band) = self.band.as_mut().filter(|_| omega_d == 0.0) else {
            return self.add_products(x, omega_f, omega_d, out);
        };
        band.set_spin(omega_f);
        let (lo, hi) = (band.lo, band.hi);
        for i in (0..lo).chain(hi..out.len()) {
            self.add_row::<false>(i, x, omega_f, omega_d, &mut out[i]);
        }
        if let Some(band) = &self.band {
            band.add_fused_products(x[0], x[1], out);
        }
    }

    fn add_products_with<const WITH_D: bool>(
        &self,
        x: [&[f64]; 3],
        omega_f: f64,
        omega_d: f64,
        out: &mut [f64],
    ) {
        let n = out.len();
        let (lo, hi) = self.band.as_ref().map_or((n, n), |b| (b.lo, b.hi));
        for i in (0..lo).chain(hi..n) {
            self.add_row::<WITH_D>(i, x, omega_f, omega_d, &mut out[i]);
        }
        if let Some(band) = &self.band {
            band.add_products::<WITH_D>(x, omega_f, omega_d, out);
        }
    }

    /// Row i of the products from the compressed entries.
    fn add_row<const WITH_D: bool>(
        &self,
        i: usize,
        [x_m, x_c, x_g]: [&[f64]; 3],
        omega_f: f64,
        omega_d: f64,
        o: &mut f64,
    ) {
        let (mut sm, mut sc, mut sg, mut sd) = (0.0, 0.0, 0.0, 0.0);
        for &(j, [m, c, g]) in &self.entries[self.start[i]..self.start[i + 1]] {
            sm += m * x_m[j];
            sc += c * x_c[j];
            sg += g * x_c[j];
            if WITH_D {
                sd += g * x_g[j];
            }
        }
        *o += sm;
        *o += sc;
        *o += omega_f * sg;
        if WITH_D {
            *o += omega_d * sd;
        }
    }
}

/// K_eff⁻¹ and its condensation onto the bearing DOFs, for one time step and one spin speed.
/// All storage is reserved at construction: refactoring for a new speed allocates nothing.
#[derive(Debug, Clone)]
pub(crate) struct StepFactor {
    /// Time step h (s).
    pub h: f64,
    /// Spin speed the gyroscopic term was factored with (rad/s).
    pub speed_rad_s: f64,
    /// K_eff⁻¹ (dense, for the per-step product).
    inverse: Mat<f64>,
    /// Z = K_eff⁻¹ E_B, row-major n × nb.
    z: Vec<f64>,
    /// S = E_Bᵀ K_eff⁻¹ E_B, row-major nb × nb.
    pub s: Vec<f64>,
    /// K_eff as a band matrix and its LU without pivoting, when its band is narrow (rotors whose
    /// DOFs run node by node) and the factor is accurate: the inverse is formed from it; else
    /// None and faer's dense LU forms it.
    band: Option<BandLu>,
    /// Scratch of the band path: a unit vector and K_eff⁻¹ of it (n each).
    unit: Vec<f64>,
    column: Vec<f64>,
    /// K_eff, overwritten by its LU factors (faer's partial-pivoting LU, in place).
    work: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    scratch: LuScratch,
    n: usize,
    nb: usize,
}

/// faer's workspace for the LU and the inverse of an n × n matrix, reserved once.
struct LuScratch {
    buf: MemBuffer,
    n: usize,
}

impl LuScratch {
    fn new(n: usize) -> Self {
        use faer::linalg::lu::partial_pivoting::{factor, inverse};
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, Default::default()),
            inverse::inverse_scratch::<usize, f64>(n, Par::Seq),
        ]);
        Self {
            buf: MemBuffer::new(req),
            n,
        }
    }

    fn stack(&mut self) -> &mut MemStack {
        MemStack::new(&mut self.buf)
    }
}

impl Clone for LuScratch {
    fn clone(&self) -> Self {
        Self::new(self.n)
    }
}

impl std::fmt::Debug for LuScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "LuScratch {{ n: {} }}", self.n)
    }
}

impl StepFactor {
    /// Reserves room for n DOFs and nb bearing DOFs, factored for step `h` (s) and `speed_rad_s`.
    /// None if K_eff is singular.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        m: &Mat<f64>,
        c: &Mat<f64>,
        g: &Mat<f64>,
        k: &Mat<f64>,
        h: f64,
        speed_rad_s: f64,
        bearing_dofs: &[usize],
    ) -> Option<Self> {
        let n = m.nrows();
        let nb = bearing_dofs.len();
        let b = [m, c, g, k]
            .iter()
            .map(|a| BandLu::half_bandwidth_of(a))
            .max()
            .unwrap_or(0);
        let mut f = Self {
            h,
            speed_rad_s,
            band: (BAND_SIZE_RATIO * b <= n).then(|| BandLu::zeros(n, b)),
            unit: vec![0.0; n],
            column: vec![0.0; n],
            inverse: Mat::zeros(n, n),
            z: vec![0.0; n * nb],
            s: vec![0.0; nb * nb],
            work: Mat::zeros(n, n),
            perm: vec![0; n],
            perm_inv: vec![0; n],
            scratch: LuScratch::new(n),
            n,
            nb,
        };
        f.refactor(m, c, g, k, speed_rad_s, bearing_dofs)
            .then_some(f)
    }

    /// Factors K + (2/h)(C + ΩG) + (4/h²) M again for spin `speed_rad_s` (rad/s) and forms its
    /// inverse, in place: by the band LU when the band is narrow and its backward error below
    /// [`BAND_BACKWARD_ERROR`] (n band solves give the inverse: ≈ n²·4b operations instead of
    /// the dense LU's and inverse's ≈ 2n³), else (for good) by faer's partial-pivoting LU.
    /// False if singular (the previous factor is then invalid). Allocates nothing.
    pub(crate) fn refactor(
        &mut self,
        m: &Mat<f64>,
        c: &Mat<f64>,
        g: &Mat<f64>,
        k: &Mat<f64>,
        speed_rad_s: f64,
        bearing_dofs: &[usize],
    ) -> bool {
        let h = self.h;
        let entry = |i: usize, j: usize| {
            k[(i, j)] + 2.0 / h * (c[(i, j)] + speed_rad_s * g[(i, j)]) + 4.0 / (h * h) * m[(i, j)]
        };
        if let Some(band) = &mut self.band {
            band.fill(entry);
            if band.factor() && self.band_is_accurate(&entry) {
                self.condense_band(bearing_dofs);
                self.speed_rad_s = speed_rad_s;
                return self.z.iter().chain(&self.s).all(|v| v.is_finite());
            }
            self.band = None;
        }
        if !self.dense_inverse(&entry) {
            return false;
        }
        for (r, &b) in bearing_dofs.iter().enumerate() {
            for i in 0..self.n {
                self.z[i * self.nb + r] = self.inverse[(i, b)];
            }
            for (q, &a) in bearing_dofs.iter().enumerate() {
                self.s[q * self.nb + r] = self.inverse[(a, b)];
            }
        }
        self.speed_rad_s = speed_rad_s;
        (0..self.n).all(|j| (0..self.n).all(|i| self.inverse[(i, j)].is_finite()))
    }

    /// Uses faer's dense LU from the next refactor on (see [`refactor`](Self::refactor)).
    pub(crate) fn drop_band(&mut self) {
        self.band = None;
    }

    /// The band factor's backward error on one solve, ‖A x − r‖∞ / (‖A‖∞ ‖x‖∞), is below
    /// [`BAND_BACKWARD_ERROR`] (`entry(i, j)` gives A).
    fn band_is_accurate(&mut self, entry: &impl Fn(usize, usize) -> f64) -> bool {
        let Some(band) = &self.band else {
            return false;
        };
        let (n, b) = (self.n, band.half_bandwidth());
        for (i, u) in self.unit.iter_mut().enumerate() {
            *u = 1.0 + (i % 7) as f64;
        }
        band.solve(&self.unit, &mut self.column);
        let (mut residual, mut norm_a) = (0.0_f64, 0.0_f64);
        for i in 0..n {
            let (mut ax, mut row) = (0.0, 0.0);
            for j in i.saturating_sub(b)..(i + b + 1).min(n) {
                let a = entry(i, j);
                ax += a * self.column[j];
                row += a.abs();
            }
            residual = residual.max((ax - self.unit[i]).abs());
            norm_a = norm_a.max(row);
        }
        let norm_x = self.column.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        residual <= BAND_BACKWARD_ERROR * norm_a * norm_x
    }

    /// Z and S from the band factor: one solve per bearing DOF.
    fn condense_band(&mut self, bearing_dofs: &[usize]) {
        let Some(band) = &self.band else {
            return;
        };
        for (r, &b) in bearing_dofs.iter().enumerate() {
            self.unit.fill(0.0);
            self.unit[b] = 1.0;
            band.solve(&self.unit, &mut self.column);
            for i in 0..self.n {
                self.z[i * self.nb + r] = self.column[i];
            }
            for (q, &a) in bearing_dofs.iter().enumerate() {
                self.s[q * self.nb + r] = self.column[a];
            }
        }
    }

    /// K_eff⁻¹ by faer's partial-pivoting LU in place and the inverse from it (`entry(i, j)`
    /// gives K_eff). False if a pivot is zero or not finite.
    fn dense_inverse(&mut self, entry: &impl Fn(usize, usize) -> f64) -> bool {
        use faer::linalg::lu::partial_pivoting::{factor, inverse};
        let n = self.n;
        for j in 0..n {
            for i in 0..n {
                self.work[(i, j)] = entry(i, j);
            }
        }
        let (_, perm) = factor::lu_in_place(
            self.work.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            self.scratch.stack(),
            Default::default(),
        );
        if (0..n).any(|i| !(self.work[(i, i)] != 0.0 && self.work[(i, i)].is_finite())) {
            return false;
        }
        inverse::inverse(
            self.inverse.as_mut(),
            self.work.as_ref(),
            self.work.as_ref(),
            perm,
            Par::Seq,
            self.scratch.stack(),
        );
        true
    }

    /// out = K_eff⁻¹ r (faer's matrix–vector product with the inverse, vectorised for the CPU it
    /// runs on: faster per step than the band factor's two sequential triangular solves).
    /// Allocates nothing.
    pub(crate) fn solve(&self, r: &[f64], out: &mut [f64]) {
        let n = self.n;
        if let Some(band) = &self.band {
            band.solve(&r[..n], &mut out[..n]);
            return;
        }
        faer::linalg::matmul::matmul(
            faer::MatMut::from_column_major_slice_mut(&mut out[..n], n, 1),
            faer::Accum::Replace,
            self.inverse.as_ref(),
            faer::MatRef::from_column_major_slice(&r[..n], n, 1),
            1.0,
            faer::Par::Seq,
        );
    }

    /// q += Z f_B. Allocates nothing.
    pub(crate) fn add_bearing_response(&self, f_b: &[f64], q: &mut [f64]) {
        let row_sum = |row: &[f64], f: &[f64]| row.iter().zip(f).map(|(a, b)| a * b).sum::<f64>();
        match self.nb {
            // two film bearings on rigid supports: rows of a length the compiler knows
            4 => {
                for (qi, row) in q.iter_mut().zip(self.z.chunks_exact(4)) {
                    *qi += row_sum(row, &f_b[..4]);
                }
            }
            0 => {}
            nb => {
                for (qi, row) in q.iter_mut().zip(self.z.chunks_exact(nb)) {
                    *qi += row_sum(row, &f_b[..nb]);
                }
            }
        }
    }
}

/// The band path is taken when K_eff's size is at least this many times its half-bandwidth
/// (the microturbine: 124 DOFs, half-bandwidth 7); a wider band (e.g. pedestal DOFs numbered
/// after the shaft's) keeps the dense inverse.
const BAND_SIZE_RATIO: usize = 8;

/// Largest backward error ‖A x − r‖∞ / (‖A‖∞ ‖x‖∞) of the band factor before the dense LU with
/// pivoting takes over: a few hundred times the double-precision unit round-off (measured on
/// the microturbine: see `band_and_dense_factors_agree`).
pub(crate) const BAND_BACKWARD_ERROR: f64 = 1e-13;

/// Most condensed bearing DOFs the step's Newton system may have: 16 (two per film bearing
/// and two per flexible pedestal under one: eight film bearings on rigid supports or four on
/// pedestals). The system is solved on the stack by nalgebra's fixed-size LU; the machine file
/// is refused beyond it (`MachineDescription::validate`).
pub const MAX_CONDENSED_DOFS: usize = 16;

/// Solves the small dense system A x = b (A row-major n × n; x returned in `b`) by LU with
/// partial pivoting (nalgebra, fixed size, on the stack); n = 0 (no film bearing) is solved.
/// False if A is singular, the solution not finite, or n odd or above [`MAX_CONDENSED_DOFS`].
/// Allocates nothing.
pub(crate) fn solve_small(a: &[f64], b: &mut [f64], n: usize) -> bool {
    // one arm per size: nalgebra's fixed-size LU is typed by its dimension
    macro_rules! fixed {
        ($($size:literal)*) => {
            match n {
                // no film bearing: nothing to solve
                0 => true,
                $($size => {
                    let m = nalgebra::SMatrix::<f64, $size, $size>::from_row_slice(&a[..$size * $size]);
                    let mut x = nalgebra::SVector::<f64, $size>::from_column_slice(&b[..$size]);
                    let solved = m.lu().solve_mut(&mut x) && x.iter().all(|v| v.is_finite());
                    if solved {
                        b[..$size].copy_from_slice(x.as_slice());
                    }
                    solved
                })*
                _ => false,
            }
        };
    }
    fixed!(2 4 6 8 10 12 14 16)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The stack LU against faer's dense partial-pivoting LU, every size the step uses, on
    /// seeded random systems (diagonally weighted like I + S D, and general).
    #[test]
    fn small_solve_agrees_with_faer() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for n in (2..=MAX_CONDENSED_DOFS).step_by(2) {
            for trial in 0..20 {
                let diag = if trial % 2 == 0 { 3.0 } else { 0.0 };
                let a: Vec<f64> = (0..n * n)
                    .map(|k| {
                        rng.random_range(-1.0..1.0) + if k % (n + 1) == 0 { diag } else { 0.0 }
                    })
                    .collect();
                let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let mut x = b.clone();
                assert!(solve_small(&a, &mut x, n), "n {n}");
                let am = Mat::<f64>::from_fn(n, n, |i, j| a[i * n + j]);
                let bm = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
                use faer::linalg::solvers::Solve;
                let want = am.partial_piv_lu().solve(&bm);
                for i in 0..n {
                    let tol = 1e-9 * want[(i, 0)].abs().max(1.0);
                    assert!((x[i] - want[(i, 0)]).abs() < tol, "n {n} row {i}");
                }
            }
        }
    }

    /// The band form of M, C, G against the compressed rows alone (second method: the same
    /// sums over the entries with their column indices): equal bit for bit, on the
    /// microturbine (124 DOFs, half-bandwidth 7) and on seeded random band matrices of other
    /// sizes and bands, with Ω_d zero (the last product left out) and not.
    #[test]
    fn band_products_equal_the_compressed_rows_exactly() {
        use crate::rotor::{MachineDescription, Rotor};
        let rotor = Rotor::from_description(&MachineDescription::builtin_default());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut cases = vec![(
            rotor.mass.clone(),
            rotor.damping.clone(),
            rotor.gyroscopic.clone(),
        )];
        for (n, b) in [(37, 3), (64, 7), (50, 1), (29, 5)] {
            let mut band = |density: f64| {
                Mat::<f64>::from_fn(n, n, |i, j| {
                    let inside = i.abs_diff(j) <= b && rng.random_range(0.0..1.0) < density;
                    if inside {
                        rng.random_range(-1.0..1.0)
                    } else {
                        0.0
                    }
                })
            };
            cases.push((band(0.9), band(0.5), band(0.7)));
        }
        for (m, c, g) in &cases {
            let n = m.nrows();
            let banded = SparseMcg::from_dense(m, c, g);
            let band = banded.band.as_ref().expect("a narrow band");
            assert!(2 * (band.hi - band.lo) >= n, "n {n}");
            let rows = SparseMcg {
                band: None,
                ..banded.clone()
            };
            let x: Vec<Vec<f64>> = (0..3)
                .map(|_| (0..n).map(|_| rng.random_range(-1e3..1e3)).collect())
                .collect();
            for omega_d in [0.0, -3.7] {
                let base: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let (mut a, mut b, mut all) = (base.clone(), base.clone(), base);
                let x = [&x[0][..], &x[1][..], &x[2][..]];
                banded.add_products(x, 942.5, omega_d, &mut a);
                rows.add_products(x, 942.5, omega_d, &mut b);
                // the four products always (as before the band): Ω_d = 0 adds exact zeros
                rows.add_products_with::<true>(x, 942.5, omega_d, &mut all);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&a), bits(&b), "n {n}, Ω_d {omega_d}");
                assert_eq!(bits(&a), bits(&all), "n {n}, Ω_d {omega_d}");
            }
        }
    }

    /// The fused band products with the half-bandwidth a constant (the microturbine's 7)
    /// against the general band kernel (the same sums in the same order): equal bit for bit,
    /// on the microturbine and on seeded random band matrices of half-bandwidth 7, at two spins;
    /// so is the kernel the step dispatches to (AVX, 4-wide; this machine has it) against the
    /// scalar one.
    #[test]
    fn fixed_band_products_equal_the_general_ones_exactly() {
        use crate::rotor::{MachineDescription, Rotor};
        let rotor = Rotor::from_description(&MachineDescription::builtin_default());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut cases = vec![(
            rotor.mass.clone(),
            rotor.damping.clone(),
            rotor.gyroscopic.clone(),
        )];
        for n in [64, 31] {
            let mut band = || {
                Mat::<f64>::from_fn(n, n, |i, j| {
                    if i.abs_diff(j) <= 7 {
                        rng.random_range(-1.0..1.0)
                    } else {
                        0.0
                    }
                })
            };
            cases.push((band(), band(), band()));
        }
        for (m, c, g) in &cases {
            let n = m.nrows();
            let mut mcg = SparseMcg::from_dense(m, c, g);
            let x: Vec<Vec<f64>> = (0..2)
                .map(|_| (0..n).map(|_| rng.random_range(-1e3..1e3)).collect())
                .collect();
            for omega_f in [942.5, 1000.0] {
                let band = mcg.band.as_mut().expect("a narrow band");
                assert_eq!(band.b, 7, "n {n}");
                band.set_spin(omega_f);
                let base: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let (mut a, mut b) = (base.clone(), base.clone());
                band.add_fused_products(&x[0], &x[1], &mut a);
                band.add_fused_any(&x[0], &x[1], &mut b);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&a), bits(&b), "n {n}, Ω_f {omega_f}");
                // the dispatched kernel (AVX where the CPU has it, as this machine does)
                // against the scalar one
                let mut scalar = base.clone();
                band.add_fused_band::<7, 15, 18>(&x[0], &x[1], &mut scalar);
                assert_eq!(bits(&a), bits(&scalar), "n {n}, Ω_f {omega_f}: AVX");
                // every band row took its products (108 of the microturbine's 124), no other
                let changed = (0..n).filter(|&i| a[i] != base[i]).count();
                assert_eq!(changed, band.hi - band.lo, "n {n}: rows changed");
            }
        }
    }

    /// The step's fused band products (M and C + Ω_f G, two sums) against the compressed rows
    /// (second method: M, C and G separately, with their column indices) on the microturbine
    /// and on seeded random band matrices: each row within 1e-14 of Σ|terms| (a few
    /// round-offs), at two spins in turn (the fused band refreshed), Ω_d zero and not.
    #[test]
    fn fused_band_products_agree_with_the_compressed_rows() {
        use crate::rotor::{MachineDescription, Rotor};
        let rotor = Rotor::from_description(&MachineDescription::builtin_default());
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut cases = vec![(
            rotor.mass.clone(),
            rotor.damping.clone(),
            rotor.gyroscopic.clone(),
        )];
        for (n, b) in [(37, 3), (64, 7), (29, 5)] {
            let mut band = || {
                Mat::<f64>::from_fn(n, n, |i, j| {
                    if i.abs_diff(j) <= b {
                        rng.random_range(-1.0..1.0)
                    } else {
                        0.0
                    }
                })
            };
            cases.push((band(), band(), band()));
        }
        for (m, c, g) in &cases {
            let n = m.nrows();
            let mut fused = SparseMcg::from_dense(m, c, g);
            let rows = SparseMcg {
                band: None,
                ..fused.clone()
            };
            let x: Vec<Vec<f64>> = (0..3)
                .map(|_| (0..n).map(|_| rng.random_range(-1e3..1e3)).collect())
                .collect();
            let x = [&x[0][..], &x[1][..], &x[2][..]];
            // Σ|terms| of each row: the scale of its round-off
            let size = |i: usize, omega_f: f64, omega_d: f64| -> f64 {
                (0..n)
                    .map(|j| {
                        (m[(i, j)] * x[0][j]).abs()
                            + (c[(i, j)] * x[1][j]).abs()
                            + (omega_f * g[(i, j)] * x[1][j]).abs()
                            + (omega_d * g[(i, j)] * x[2][j]).abs()
                    })
                    .sum()
            };
            for (omega_f, omega_d) in [(942.5, 0.0), (942.5, -3.7), (1000.0, 0.0)] {
                let (mut a, mut b) = (vec![0.5; n], vec![0.5; n]);
                fused.add_step_products(x, omega_f, omega_d, &mut a);
                rows.add_products(x, omega_f, omega_d, &mut b);
                for i in 0..n {
                    let bound = 1e-14 * (size(i, omega_f, omega_d) + 0.5);
                    assert!(
                        (a[i] - b[i]).abs() <= bound,
                        "n {n}, row {i}, Ω_f {omega_f}: {} vs {}",
                        a[i],
                        b[i]
                    );
                }
            }
        }
    }

    /// The microturbine's K_eff (124 DOFs, half-bandwidth 7, at 128 steps a revolution of
    /// 9,000 rpm) through the band LU without pivoting and through faer's dense LU with
    /// pivoting (second method): solves, Z and S agree to 1e-10 of their scale, and the band
    /// factor's backward error is far below [`BAND_BACKWARD_ERROR`]'s bound.
    #[test]
    fn band_and_dense_factors_agree() {
        use crate::rotor::{MachineDescription, Rotor};
        let rotor = Rotor::from_description(&MachineDescription::builtin_default());
        let (m, c, g, k) = (
            &rotor.mass,
            &rotor.damping,
            &rotor.gyroscopic,
            &rotor.stiffness,
        );
        let omega = 9000.0 * std::f64::consts::PI / 30.0;
        let h = std::f64::consts::TAU / omega / 128.0;
        let dofs = [12, 13, 108, 109];
        let band = StepFactor::new(m, c, g, k, h, omega, &dofs).expect("regular");
        assert_eq!(band.band.as_ref().map(|b| b.half_bandwidth()), Some(7));
        let mut dense = band.clone();
        dense.band = None;
        assert!(dense.refactor(m, c, g, k, omega, &dofs));
        let n = m.nrows();
        let r: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos()).collect();
        let (mut xb, mut xd) = (vec![0.0; n], vec![0.0; n]);
        band.solve(&r, &mut xb);
        dense.solve(&r, &mut xd);
        let close = |a: &[f64], b: &[f64]| {
            let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-10 * scale)
        };
        assert!(close(&xb, &xd));
        assert!(close(&band.z, &dense.z));
        assert!(close(&band.s, &dense.s));
    }

    /// K_eff⁻¹ from faer's in-place LU: K_eff · K_eff⁻¹ = I on a seeded non-symmetric system
    /// (C + ΩG is not symmetric), S and Z its entries at the bearing DOFs; refactoring at another
    /// speed gives the inverse at that speed.
    #[test]
    fn step_factor_inverts_k_eff() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let n = 24;
        let mut r =
            |scale: f64| Mat::<f64>::from_fn(n, n, |_, _| scale * rng.random_range(-1.0..1.0));
        let (m, c, g) = (r(1.0), r(1.0), r(1.0));
        let k = Mat::<f64>::from_fn(n, n, |i, j| if i == j { 50.0 } else { 0.0 }) + r(1.0);
        let (h, dofs) = (0.05, [3, 4, 17, 18]);
        let mut f = StepFactor::new(&m, &c, &g, &k, h, 10.0, &dofs).expect("regular");
        for speed in [10.0, -3.0] {
            assert!(f.refactor(&m, &c, &g, &k, speed, &dofs));
            let keff = &k + (2.0 / h) * (&c + speed * &g) + (4.0 / (h * h)) * &m;
            let product = &keff * &f.inverse;
            for i in 0..n {
                for j in 0..n {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (product[(i, j)] - want).abs() < 1e-10,
                        "({i}, {j}) at {speed}"
                    );
                }
            }
            for (q, &a) in dofs.iter().enumerate() {
                for (p, &b) in dofs.iter().enumerate() {
                    assert_eq!(f.s[q * dofs.len() + p], f.inverse[(a, b)]);
                }
            }
        }
    }

    #[test]
    fn singular_and_unsupported_sizes_are_refused() {
        let mut b = [1.0, 2.0];
        assert!(!solve_small(&[1.0, 2.0, 2.0, 4.0], &mut b, 2));
        let mut b = [1.0; 3];
        assert!(!solve_small(&[1.0; 9], &mut b, 3));
        let n = MAX_CONDENSED_DOFS + 2;
        let mut b = vec![1.0; n];
        let eye: Vec<f64> = (0..n * n)
            .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
            .collect();
        assert!(!solve_small(&eye, &mut b, n));
    }
}
