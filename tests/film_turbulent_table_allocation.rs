//! The turbulent table's evaluation allocates nothing (the step's rule, `twin_allocation.rs`):
//! force, coefficients and the mid-plane profile of a [`ReynoldsTabulatedFilm`] at states
//! across ε, ψ and Re (both ends of the Re axis and the centre's fallback among them), counted
//! with a counting allocator. A coarse (ε, ψ) resolution: the evaluation's code path is the
//! default table's.

use rotor_twin::film::{
    BearingGeometry, EccentricityMap, FilmGrid, FilmModel, FlowRegime, ForceFrame,
    JournalKinematics, Lubricant, ReynoldsAxis, ReynoldsTable, ReynoldsTabulatedFilm,
    TableResolution,
};
use std::sync::Arc;

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations;

/// One test only: the counter is global to the process.
#[test]
fn the_turbulent_tables_evaluation_allocates_nothing() {
    let g = BearingGeometry::plain(0.06, 0.03, 40e-6).unwrap();
    let oil = Lubricant::new(900.0, 0.0008).unwrap();
    let grid = FilmGrid::new(60, 10).unwrap();
    let res = TableResolution {
        n_ecc: 8,
        n_psi: 16,
        grid_phases: 1,
        map: EccentricityMap::Atanh,
        frame: ForceFrame::Source,
        wall: None,
    };
    let re_per_speed = 900.0 * 0.03 * 40e-6 / 0.0008;
    for regime in [FlowRegime::Turbulent, FlowRegime::Auto] {
        let axis = ReynoldsAxis::new(regime, 3000.0, 750.0, 300.0).unwrap();
        let table = ReynoldsTable::build_with(&g, oil, grid, axis, res).unwrap();
        let mut film = ReynoldsTabulatedFilm::new(Arc::new(table));
        let mut profile = [0.0; 120];
        let before = allocations();
        let mut evaluated = 0;
        for k in 0..1000 {
            let x = k as f64;
            let re = 3000.0 * (0.5 + 0.5 * (0.37 * x).sin());
            let eps = 0.95 * (0.5 + 0.5 * (0.11 * x).cos()) + if k % 97 == 0 { -0.94 } else { 0.0 };
            let w = re / re_per_speed;
            let kin = JournalKinematics {
                position_m: [
                    eps.max(1e-4) * 40e-6 * (0.7 * x).cos(),
                    eps.max(1e-4) * 40e-6 * (0.7 * x).sin(),
                ],
                velocity_m_s: [
                    0.1 * 40e-6 * w * (0.3 * x).sin(),
                    -0.1 * 40e-6 * w * (0.2 * x).cos(),
                ],
                speed_rad_s: w,
            };
            film.solve_with_coefficients(&kin).unwrap();
            film.solve(&kin).unwrap();
            film.midplane_pressure(&mut profile);
            evaluated += 1;
        }
        assert_eq!(evaluated, 1000);
        assert_eq!(allocations() - before, 0, "{regime:?}");
    }
}
