//! Static deflection of the shaft under gravity on rigid supports at the bearing nodes, and the
//! bearing reactions: the static loads the bearing films must carry.

use super::{Rotor, RotorError};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use serde::Serialize;

/// The rotor's static equilibrium under gravity, journals held at the bearing centres.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StaticSolution {
    /// Displacement of every shaft DOF (m, rad); 0 at the journals.
    pub displacement: Vec<f64>,
    /// Static load on each bearing, in bearing order: the force of the journal on the bearing,
    /// `[F_x, F_y]` (N). The film must carry it.
    pub bearing_loads_n: Vec<[f64; 2]>,
    /// Largest lateral deflection of any node (m).
    pub max_deflection_m: f64,
}

/// Solves K u = F_gravity on the shaft DOFs with the journals' x and y held at zero (pedestals
/// left out); reactions R = K_cf u_f − F_c, bearing load = −R.
pub fn static_solution(rotor: &Rotor) -> Result<StaticSolution, RotorError> {
    let n_shaft = 4 * rotor.n_nodes();
    let held: Vec<usize> = rotor.bearings.iter().flat_map(|b| b.journal_dofs).collect();
    let free: Vec<usize> = (0..n_shaft).filter(|d| !held.contains(d)).collect();
    let gravity = rotor.gravity_force();
    let k = &rotor.stiffness;
    let kff = Mat::<f64>::from_fn(free.len(), free.len(), |i, j| k[(free[i], free[j])]);
    let mut u = Mat::<f64>::from_fn(free.len(), 1, |i, _| gravity[free[i]]);
    let llt = kff
        .llt(Side::Lower)
        .map_err(|_| RotorError::LinearAlgebra {
            what: "static deflection",
            why: "the shaft is not held by its bearings (at least two bearing nodes are needed)"
                .into(),
        })?;
    llt.solve_in_place(&mut u);
    let mut displacement = vec![0.0; n_shaft];
    for (i, &d) in free.iter().enumerate() {
        displacement[d] = u[(i, 0)];
    }
    let bearing_loads_n = rotor
        .bearings
        .iter()
        .map(|b| {
            b.journal_dofs.map(|c| {
                let r: f64 = free
                    .iter()
                    .map(|&f| k[(c, f)] * displacement[f])
                    .sum::<f64>()
                    - gravity[c];
                -r
            })
        })
        .collect();
    let max_deflection_m = (0..rotor.n_nodes())
        .map(|n| displacement[4 * n].hypot(displacement[4 * n + 1]))
        .fold(0.0, f64::max);
    Ok(StaticSolution {
        displacement,
        bearing_loads_n,
        max_deflection_m,
    })
}
