//! Small dense least squares for the calibrations: complex problems in their real embedding,
//! normal equations (a handful of unknowns), eigenvalues by Jacobi rotations for the condition
//! number.

/// Solves the real symmetric positive definite system `a x = b` (n × n, row-major) by Cholesky;
/// None if not positive definite.
pub fn solve_spd(a: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = a[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            if i == j {
                if s.is_nan() || s <= 0.0 {
                    return None;
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    let mut y = vec![0.0; n];
    for i in 0..n {
        y[i] = (b[i] - (0..i).map(|k| l[i * n + k] * y[k]).sum::<f64>()) / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        x[i] = (y[i] - (i + 1..n).map(|k| l[k * n + i] * x[k]).sum::<f64>()) / l[i * n + i];
    }
    Some(x)
}

/// Eigenvalues of the real symmetric matrix `a` (n × n, row-major) by cyclic Jacobi rotations.
pub fn symmetric_eigenvalues(a: &[f64], n: usize) -> Vec<f64> {
    let mut m = a.to_vec();
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * n + j] * m[i * n + j])
            .sum();
        let scale: f64 = (0..n).map(|i| m[i * n + i] * m[i * n + i]).sum();
        if off <= 1e-30 * scale.max(1e-300) {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (m[q * n + q] - m[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[k * n + p], m[k * n + q]);
                    m[k * n + p] = c * mkp - s * mkq;
                    m[k * n + q] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[p * n + k], m[q * n + k]);
                    m[p * n + k] = c * mpk - s * mqk;
                    m[q * n + k] = s * mpk + c * mqk;
                }
            }
        }
    }
    (0..n).map(|i| m[i * n + i]).collect()
}

/// The complex least-squares problem min |A u − b|, A m × p given by rows of [re, im] pairs,
/// solved in its real embedding [Re A −Im A; Im A Re A]. Returns (u as [re, im] pairs, the
/// residual |A u − b|, the 2-norm condition number of A), or None if AᴴA is singular.
pub fn complex_least_squares(
    rows: &[Vec<[f64; 2]>],
    b: &[[f64; 2]],
) -> Option<(Vec<[f64; 2]>, f64, f64)> {
    let p = rows.first()?.len();
    let n = 2 * p;
    // real embedding: row (re) = [Re a, −Im a], row (im) = [Im a, Re a]
    let mut ata = vec![0.0; n * n];
    let mut atb = vec![0.0; n];
    let mut real_rows = Vec::with_capacity(2 * rows.len());
    for (row, bk) in rows.iter().zip(b) {
        let re: Vec<f64> = row
            .iter()
            .map(|a| a[0])
            .chain(row.iter().map(|a| -a[1]))
            .collect();
        let im: Vec<f64> = row
            .iter()
            .map(|a| a[1])
            .chain(row.iter().map(|a| a[0]))
            .collect();
        real_rows.push((re, bk[0]));
        real_rows.push((im, bk[1]));
    }
    for (r, bv) in &real_rows {
        for i in 0..n {
            atb[i] += r[i] * bv;
            for j in 0..n {
                ata[i * n + j] += r[i] * r[j];
            }
        }
    }
    let x = solve_spd(&ata, &atb)?;
    let residual = real_rows
        .iter()
        .map(|(r, bv)| {
            let e = r.iter().zip(&x).map(|(a, xi)| a * xi).sum::<f64>() - bv;
            e * e
        })
        .sum::<f64>()
        .sqrt();
    let eig = symmetric_eigenvalues(&ata, n);
    let (lo, hi) = eig.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    let cond = if lo > 0.0 {
        (hi / lo).sqrt()
    } else {
        f64::INFINITY
    };
    let u = (0..p).map(|k| [x[k], x[p + k]]).collect();
    Some((u, residual, cond))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_consistent_complex_system_is_solved_exactly() {
        // A = [[1+i, 2], [0, 1−i], [3, i]], u = [2−i, −1+3i]
        let a = vec![
            vec![[1.0, 1.0], [2.0, 0.0]],
            vec![[0.0, 0.0], [1.0, -1.0]],
            vec![[3.0, 0.0], [0.0, 1.0]],
        ];
        let u = [[2.0, -1.0], [-1.0, 3.0]];
        let mul = |x: [f64; 2], y: [f64; 2]| [x[0] * y[0] - x[1] * y[1], x[0] * y[1] + x[1] * y[0]];
        let b: Vec<[f64; 2]> = a
            .iter()
            .map(|r| {
                let (p, q) = (mul(r[0], u[0]), mul(r[1], u[1]));
                [p[0] + q[0], p[1] + q[1]]
            })
            .collect();
        let (x, res, cond) = complex_least_squares(&a, &b).unwrap();
        for k in 0..2 {
            assert!((x[k][0] - u[k][0]).abs() < 1e-12 && (x[k][1] - u[k][1]).abs() < 1e-12);
        }
        assert!(res < 1e-12 && cond.is_finite() && cond >= 1.0);
        // eigenvalues of [[2, 1], [1, 2]]: 1 and 3
        let mut e = symmetric_eigenvalues(&[2.0, 1.0, 1.0, 2.0], 2);
        e.sort_by(f64::total_cmp);
        assert!((e[0] - 1.0).abs() < 1e-12 && (e[1] - 3.0).abs() < 1e-12);
    }
}
