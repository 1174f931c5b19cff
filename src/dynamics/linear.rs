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

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::{Mat, Par};

/// A square sparse matrix in compressed rows, for the per-step products (M, C, G).
#[derive(Debug, Clone)]
pub(crate) struct SparseRows {
    start: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
}

impl SparseRows {
    /// The nonzero entries of a dense matrix.
    pub(crate) fn from_dense(m: &Mat<f64>) -> Self {
        let mut start = vec![0];
        let (mut col, mut val) = (Vec::new(), Vec::new());
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                if m[(i, j)] != 0.0 {
                    col.push(j);
                    val.push(m[(i, j)]);
                }
            }
            start.push(col.len());
        }
        Self { start, col, val }
    }

    /// out += scale · A x. Allocates nothing.
    pub(crate) fn add_product(&self, scale: f64, x: &[f64], out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            let mut s = 0.0;
            for k in self.start[i]..self.start[i + 1] {
                s += self.val[k] * x[self.col[k]];
            }
            *o += scale * s;
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
        let mut f = Self {
            h,
            speed_rad_s,
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

    /// Factors K + (2/h)(C + ΩG) + (4/h²) M again for spin `speed_rad_s` (rad/s), in place
    /// (faer's partial-pivoting LU and the inverse from it). False if singular (the previous
    /// factor is then invalid).
    pub(crate) fn refactor(
        &mut self,
        m: &Mat<f64>,
        c: &Mat<f64>,
        g: &Mat<f64>,
        k: &Mat<f64>,
        speed_rad_s: f64,
        bearing_dofs: &[usize],
    ) -> bool {
        use faer::linalg::lu::partial_pivoting::{factor, inverse};
        let (n, h) = (self.n, self.h);
        for j in 0..n {
            for i in 0..n {
                self.work[(i, j)] = k[(i, j)]
                    + 2.0 / h * (c[(i, j)] + speed_rad_s * g[(i, j)])
                    + 4.0 / (h * h) * m[(i, j)];
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
        for (r, &b) in bearing_dofs.iter().enumerate() {
            for i in 0..n {
                self.z[i * self.nb + r] = self.inverse[(i, b)];
            }
            for (q, &a) in bearing_dofs.iter().enumerate() {
                self.s[q * self.nb + r] = self.inverse[(a, b)];
            }
        }
        self.speed_rad_s = speed_rad_s;
        (0..n).all(|j| (0..n).all(|i| self.inverse[(i, j)].is_finite()))
    }

    /// out = K_eff⁻¹ r (faer's matrix–vector product, vectorised for the CPU it runs on).
    /// Allocates nothing.
    pub(crate) fn solve(&self, r: &[f64], out: &mut [f64]) {
        let n = self.n;
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
        for (i, qi) in q.iter_mut().enumerate().take(self.n) {
            let row = &self.z[i * self.nb..(i + 1) * self.nb];
            *qi += row.iter().zip(f_b).map(|(a, b)| a * b).sum::<f64>();
        }
    }
}

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
