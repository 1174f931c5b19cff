//! Mode shapes compared and followed: the whirl-sense form that labels a mode forward or
//! backward, the rotation of a repeated (degenerate) pair into its circular forward and backward
//! modes, the modal assurance criterion (MAC) and the tracking of modes from speed to speed by
//! shape rather than by their rank in frequency.
//!
//! A repeated eigenvalue (an isotropic rotor at rest, or a mode untouched by the gyroscopic
//! coupling, such as the translation of a disc at midspan) has a plane of eigenvectors: the
//! eigen solver returns an arbitrary basis of it, elliptical or planar, and their whirl sense is
//! noise. Inside such a plane the circular forward and backward modes are the extremes of the
//! whirl-sense form s(v) over the normalised vectors (Lancaster & Tismenetsky's Rayleigh quotient
//! of a Hermitian pencil restricted to the subspace); they are the modes a rotordynamics code
//! reports (Friswell et al., *Dynamics of Rotating Machines*, CUP 2010, §3.5 and §3.6).

use super::Rotor;
use faer::{c64, Mat, Side};

/// Complex amplitude of every global DOF (m for x, y; rad for θx, θy) of one mode.
pub type Shape = Vec<c64>;

/// Weights of the whirl-sense and norm forms: the cross-section rotations count with ℓ², ℓ a
/// tenth of the rotor's length, so that a tilting mode has a sense as a translating one does.
pub(crate) fn tilt_weight_m2(rotor: &Rotor) -> f64 {
    let span = rotor.node_z_m.last().copied().unwrap_or(1.0) - rotor.node_z_m[0];
    (0.1 * span).powi(2)
}

/// The inner product n(u, v) = Σ_nodes ū_x v_x + ū_y v_y + ℓ²(ū_θx v_θx + ū_θy v_θy).
pub(crate) fn inner(u: &[c64], v: &[c64], n_nodes: usize, ell2: f64) -> c64 {
    let mut s = c64::new(0.0, 0.0);
    for node in 0..n_nodes {
        let b = 4 * node;
        s += u[b].conj() * v[b] + u[b + 1].conj() * v[b + 1];
        s += (u[b + 2].conj() * v[b + 2] + u[b + 3].conj() * v[b + 3]) * ell2;
    }
    s
}

/// The whirl-sense form s(u, v) = Σ_nodes [ū_x v_y − ū_y v_x + ℓ²(ū_θx v_θy − ū_θy v_θx)]/(2i),
/// Hermitian; s(v, v) = Σ Im(x̄ y) + ℓ² Im(θ̄x θy). For the e^{+iωt} convention of the state
/// eigenvectors a negative s(v, v) is a forward whirl (x leads y by a quarter period: the orbit
/// turns from +x towards +y, with the rotation).
pub(crate) fn sense(u: &[c64], v: &[c64], n_nodes: usize, ell2: f64) -> c64 {
    let mut s = c64::new(0.0, 0.0);
    for node in 0..n_nodes {
        let b = 4 * node;
        s += u[b].conj() * v[b + 1] - u[b + 1].conj() * v[b];
        s += (u[b + 2].conj() * v[b + 3] - u[b + 3].conj() * v[b + 2]) * ell2;
    }
    s / c64::new(0.0, 2.0)
}

/// Scales `v` to unit norm n(v, v) = 1 (a zero vector is left alone).
pub(crate) fn normalise(v: &mut [c64], n_nodes: usize, ell2: f64) {
    let norm = inner(v, v, n_nodes, ell2).re.sqrt();
    if norm > 0.0 {
        v.iter_mut().for_each(|x| *x /= norm);
    }
}

/// Modal assurance criterion MAC(u, v) = |n(u, v)|² / (n(u, u) n(v, v)) ∈ [0, 1] (Allemang &
/// Brown 1982): 1 for the same shape, 0 for orthogonal ones (a forward and a backward circular
/// mode of the same deflected line have MAC 0).
pub fn mac(u: &[c64], v: &[c64], n_nodes: usize, ell2: f64) -> f64 {
    let uv = inner(u, v, n_nodes, ell2);
    let uu = inner(u, u, n_nodes, ell2).re;
    let vv = inner(v, v, n_nodes, ell2).re;
    if uu <= 0.0 || vv <= 0.0 {
        0.0
    } else {
        uv.norm_sqr() / (uu * vv)
    }
}

/// Replaces the basis `shapes` of a repeated eigenvalue's eigenspace by the vectors that make
/// the whirl-sense form diagonal: orthonormalised under n (modified Gram–Schmidt), then the
/// k × k Hermitian matrix s(qᵢ, qⱼ) diagonalised. Returns them in ascending sense (most
/// forward first).
pub(crate) fn rotate_to_whirl_senses(shapes: &mut [Shape], n_nodes: usize, ell2: f64) {
    let k = shapes.len();
    if k < 2 {
        return;
    }
    let mut q: Vec<Shape> = Vec::with_capacity(k);
    for v in shapes.iter() {
        let mut w = v.clone();
        for b in &q {
            let p = inner(b, &w, n_nodes, ell2);
            w.iter_mut().zip(b).for_each(|(x, y)| *x -= p * *y);
        }
        if inner(&w, &w, n_nodes, ell2).re.sqrt() < 1e-8 * inner(v, v, n_nodes, ell2).re.sqrt() {
            // numerically dependent: leave the cluster as the solver gave it
            return;
        }
        normalise(&mut w, n_nodes, ell2);
        q.push(w);
    }
    let h = Mat::<c64>::from_fn(k, k, |i, j| sense(&q[i], &q[j], n_nodes, ell2));
    let Ok(eig) = h.self_adjoint_eigen(Side::Lower) else {
        return;
    };
    let w = eig.U();
    for (col, out) in shapes.iter_mut().enumerate() {
        for (d, x) in out.iter_mut().enumerate() {
            *x = (0..k).map(|j| q[j][d] * w[(j, col)]).sum();
        }
    }
}

/// Track labels for the modes `current` at one speed, given the tracked modes `previous` at the
/// speed before (each with its track id): pairs are taken greedily in descending MAC, and a pair
/// counts only with MAC ≥ [`MIN_TRACK_MAC`]; a mode left without a partner starts a new track
/// (`next_id` is advanced).
pub(crate) fn assign_tracks(
    previous: &[(usize, Shape)],
    current: &[Shape],
    n_nodes: usize,
    ell2: f64,
    next_id: &mut usize,
) -> Vec<usize> {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for (i, (_, p)) in previous.iter().enumerate() {
        for (j, c) in current.iter().enumerate() {
            let m = mac(p, c, n_nodes, ell2);
            if m >= MIN_TRACK_MAC {
                pairs.push((m, i, j));
            }
        }
    }
    pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut taken_prev = vec![false; previous.len()];
    let mut ids = vec![usize::MAX; current.len()];
    for (_, i, j) in pairs {
        if !taken_prev[i] && ids[j] == usize::MAX {
            taken_prev[i] = true;
            ids[j] = previous[i].0;
        }
    }
    for id in ids.iter_mut().filter(|id| **id == usize::MAX) {
        *id = *next_id;
        *next_id += 1;
    }
    ids
}

/// Least MAC for two modes at neighbouring speeds to be the same mode followed.
pub const MIN_TRACK_MAC: f64 = 0.5;

#[cfg(test)]
mod tests {
    use super::*;

    fn planar(n_nodes: usize, x: c64, y: c64) -> Shape {
        let mut v = vec![c64::new(0.0, 0.0); 4 * n_nodes];
        for node in 0..n_nodes {
            let bend = (std::f64::consts::PI * node as f64 / (n_nodes - 1) as f64).sin();
            v[4 * node] = x * bend;
            v[4 * node + 1] = y * bend;
        }
        v
    }

    /// Two planar modes (x only, y only) span the same plane as the forward and backward
    /// circular modes (x, ∓iy)/√2: rotated, they become those, with senses −½ and +½, and the
    /// two are MAC-orthogonal.
    #[test]
    fn a_planar_pair_rotates_into_circular_forward_and_backward_modes() {
        let n = 5;
        let (one, zero, i) = (c64::new(1.0, 0.0), c64::new(0.0, 0.0), c64::new(0.0, 1.0));
        let mut pair = vec![planar(n, one, zero), planar(n, zero + one * 0.3, one)];
        rotate_to_whirl_senses(&mut pair, n, 0.01);
        let s: Vec<f64> = pair
            .iter()
            .map(|v| sense(v, v, n, 0.01).re / inner(v, v, n, 0.01).re)
            .collect();
        assert!(
            (s[0] + 0.5).abs() < 1e-12 && (s[1] - 0.5).abs() < 1e-12,
            "{s:?}"
        );
        assert!(mac(&pair[0], &pair[1], n, 0.01) < 1e-12);
        // the forward one is (x, −iy) up to a complex factor
        let forward = planar(n, one, -i);
        assert!((mac(&pair[0], &forward, n, 0.01) - 1.0).abs() < 1e-12);
    }

    /// Tracks follow the shape: two modes that swap their order in frequency keep their ids.
    #[test]
    fn tracks_follow_shapes_not_order() {
        let n = 5;
        let (one, i) = (c64::new(1.0, 0.0), c64::new(0.0, 1.0));
        let forward = planar(n, one, -i);
        let backward = planar(n, one, i);
        let mut next = 2;
        let ids = assign_tracks(
            &[(0, forward.clone()), (1, backward.clone())],
            &[backward, forward],
            n,
            0.01,
            &mut next,
        );
        assert_eq!(ids, vec![1, 0]);
        assert_eq!(next, 2);
    }
}
