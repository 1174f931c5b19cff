//! The finite-length film of a plain bearing, solved once over all the states it can be in and
//! interpolated: the same Reynolds solutions as [`FiniteFilm`], at a fraction of the cost.
//!
//! Why two parameters suffice. In the frame of the line of centres (journal at eccentricity ε on
//! its x axis), the Reynolds equation's source (seed eq. 2) is
//!   ω ∂h/∂θ + 2 ∂h/∂t = U sin θ − W cos θ,  U = ω ε − 2 ε φ̇,  W = 2 ε̇,
//! (h = 1 − ε cos θ over c; φ̇ the whirl rate of the line of centres, ε̇ the radial rate). For a
//! plain bearing without supply pressure, the film pressure solves a complementarity problem
//! (Reynolds cavitation condition) whose data are the film shape (ε only) and this source; the
//! problem is positively homogeneous in the source: scaling (U, W) by λ > 0 scales the pressure
//! by λ and leaves the cavitated zone alone. So, with V = √(U² + W²) and ψ = atan2(W, U),
//!   p(θ, z) = V · P(θ, z; ε, ψ),
//! and every film quantity is V (or ω, for the Couette shear) times a function of (ε, ψ) alone.
//! [`FilmTable`] holds those functions on a grid in (ε, ψ), made with [`FiniteFilm`]; the
//! evaluation interpolates bicubically (Catmull–Rom) and rotates back by the attitude φ. The
//! eight coefficients are central differences of the interpolant. The table is checked against
//! the direct solver at random states in `tests/film_table.rs`.

use super::{
    turbulence::FlowRegime, wrap_angle_rad, BearingGeometry, FilmError, FilmGrid, FilmModel,
    FiniteFilm, JournalKinematics, Lubricant, MAX_ECCENTRICITY_RATIO,
};
use nalgebra::Matrix2;
use std::collections::HashMap;
use std::f64::consts::TAU;
use std::sync::{Arc, Mutex, OnceLock};

mod cache;
mod reynolds;
mod tabulated;
pub use cache::{
    disk_cache, set_disk_cache, table_key, CacheWarning, Lookup, TableCache, TableOrigin,
    FORMAT_VERSION, SOLVER_VERSION,
};
pub use reynolds::{ReynoldsAxis, ReynoldsTable, ReynoldsTabulatedFilm};
pub use tabulated::TabulatedFilm;

/// The table's resolution and map of ε, and the grid phases each node averages: what the
/// convergence study in the README ("The film table's resolution") varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TableResolution {
    /// Rows, equally spaced in the map's coordinate u from ε = 0 to [`MAX_ECCENTRICITY_RATIO`].
    pub n_ecc: usize,
    /// Columns around ψ (periodic; even, so that ψ + π is a column).
    pub n_psi: usize,
    /// Grid phases over which each node is averaged: the line of centres at α_k = kΔθ/m
    /// against the grid. One solve's force is piecewise smooth in the state (a kink each time a
    /// pressure-zone boundary crosses a grid node), so an interpolant of single-phase solves
    /// carries that O(Δθ) jitter into its derivatives, the coefficients (up to 12 % of their
    /// scale in the whip domain on 60 × 10, `tests/film_table.rs`); the phase average is
    /// smooth, as in [`crate::film::FilmModel::linearised_coefficients`].
    pub grid_phases: usize,
    /// How the rows are spread in ε.
    pub map: EccentricityMap,
    /// The frame the force is held in.
    pub frame: ForceFrame,
    /// The rows near the wall with their own (finer) ψ spacing and phases; None: every row as
    /// above.
    pub wall: Option<WallRows>,
}

/// The rows at ε ≥ `from_ecc_per_mille`/1000 with their own column count and grid phases.
/// ψ-interpolation is what limits the coefficients at the wall (README "The film table's
/// resolution", session 12), while at the centre finer columns make them worse: so only
/// these rows are refined. The 4 × 4 stencil interpolates each of its rows in ψ with that
/// row's own spacing, then across the rows in ε: still Catmull–Rom (C¹) in each direction.
/// Finer columns need more phases: a node's phase average keeps a jitter along ψ (where
/// pressure-zone boundaries cross grid nodes), and the ψ-slope of the interpolant divides it
/// by the spacing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WallRows {
    /// The first ε of the wall rows, in thousandths.
    pub from_ecc_per_mille: u32,
    /// Columns around ψ on those rows (even).
    pub n_psi: usize,
    /// Grid phases averaged at their nodes.
    pub grid_phases: usize,
}

/// Where each row's nodes are: rows below `wall_row` have `n_psi` columns, the others
/// `n_psi_wall`, row after row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Layout {
    n_psi: usize,
    n_psi_wall: usize,
    wall_row: usize,
}

impl Layout {
    /// The columns of row `i`.
    #[inline]
    fn columns(&self, i: usize) -> usize {
        if i < self.wall_row {
            self.n_psi
        } else {
            self.n_psi_wall
        }
    }

    /// The index of row `i`'s first node.
    #[inline]
    fn start(&self, i: usize) -> usize {
        if i < self.wall_row {
            i * self.n_psi
        } else {
            self.wall_row * self.n_psi + (i - self.wall_row) * self.n_psi_wall
        }
    }
}

/// The frame in which the table holds the film force per unit V.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForceFrame {
    /// Along and across the line of centres (up to session 10): the centre's coefficients
    /// carry the interpolation error of ∂f/∂ψ times 1/ε ([`source_frame`]).
    LineOfCentres,
    /// Turned by −ψ from the line of centres, g = R(−ψ) f ([`source_frame`]): constant along
    /// the centre's row.
    Source,
}

/// The coordinate u(ε) in which the table's rows are equally spaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EccentricityMap {
    /// u = −ln(1 − ε) (sessions up to 9): rows crowd toward the wall; the interpolant ends at
    /// ε = 0 (rows beyond it extrapolated linearly), so its slope there is first order.
    Log,
    /// u = atanh ε: rows crowd toward the wall as densely (dε/du = 1 − ε²), and u is odd in ε,
    /// so the rows continue through the centre as exact mirror images, f(−ε, ψ) = −f(ε, ψ + π)
    /// (the same journal seen from the line of centres turned by π: U, W change sign): the
    /// interpolant and its slope are as smooth at the centre as elsewhere.
    Atanh,
}

impl EccentricityMap {
    fn u(self, eps: f64) -> f64 {
        match self {
            EccentricityMap::Log => -(1.0 - eps).ln(),
            EccentricityMap::Atanh => eps.atanh(),
        }
    }

    fn eps(self, u: f64) -> f64 {
        match self {
            EccentricityMap::Log => 1.0 - (-u).exp(),
            EccentricityMap::Atanh => u.tanh(),
        }
    }

    /// dε/du at ε.
    fn slope(self, eps: f64) -> f64 {
        match self {
            EccentricityMap::Log => 1.0 - eps,
            EccentricityMap::Atanh => 1.0 - eps * eps,
        }
    }
}

impl TableResolution {
    /// The default, chosen by the convergence study (README "The film table's resolution").
    pub const DEFAULT: TableResolution = TableResolution {
        n_ecc: 160,
        n_psi: 192,
        grid_phases: 8,
        map: EccentricityMap::Atanh,
        frame: ForceFrame::Source,
        // 384 columns × 32 phases on the 98 rows at ε ≥ 0.90: coefficients within 0.34 % in
        // every band on two independent sets of states (session 14; from ε 0.95, session 13,
        // the rows' edge missed: 0.64 % at ε 0.9504, 1.88 % worst at 0.950); finer columns
        // need more phases (512 × 8: 0.61 / 1.63 %, 512 × 16: 0.33 / 0.67 %; README)
        wall: Some(WallRows {
            from_ecc_per_mille: 900,
            n_psi: 384,
            grid_phases: 32,
        }),
    };

    fn validate(&self) -> Result<(), FilmError> {
        let bad = |name, value: usize, rule| {
            Err(FilmError::InvalidParameter {
                name,
                value: value as f64,
                rule,
            })
        };
        if self.n_ecc < 4 {
            return bad("table rows n_ecc", self.n_ecc, "at least 4");
        }
        if self.n_psi < 4 || !self.n_psi.is_multiple_of(2) {
            return bad("table columns n_psi", self.n_psi, "even, at least 4");
        }
        if self.grid_phases == 0 {
            return bad("table grid_phases", 0, "at least 1");
        }
        if let Some(w) = self.wall {
            if w.n_psi < 4 || !w.n_psi.is_multiple_of(2) {
                return bad("table wall columns n_psi", w.n_psi, "even, at least 4");
            }
            if w.grid_phases == 0 {
                return bad("table wall grid_phases", 0, "at least 1");
            }
        }
        Ok(())
    }

    /// ε of row `i` (the build's and the cache's).
    fn row_eps(&self, i: usize) -> f64 {
        let u_max = self.map.u(MAX_ECCENTRICITY_RATIO);
        self.map.eps(i as f64 * u_max / (self.n_ecc - 1) as f64)
    }

    /// Where the rows' nodes are.
    fn layout(&self) -> Layout {
        let (n_psi_wall, wall_row) = match self.wall {
            Some(w) => {
                let from = f64::from(w.from_ecc_per_mille) / 1000.0;
                let first = (0..self.n_ecc).find(|&i| self.row_eps(i) >= from);
                (w.n_psi, first.unwrap_or(self.n_ecc))
            }
            None => (self.n_psi, self.n_ecc),
        };
        Layout {
            n_psi: self.n_psi,
            n_psi_wall,
            wall_row,
        }
    }

    /// Columns and grid phases of row `i`.
    fn row_columns(&self, i: usize) -> (usize, usize) {
        match self.wall {
            Some(w) if i >= self.layout().wall_row => (w.n_psi, w.grid_phases),
            _ => (self.n_psi, self.grid_phases),
        }
    }

    /// Nodes of a table on this resolution.
    pub fn nodes(&self) -> usize {
        self.layout().start(self.n_ecc)
    }

    /// Film solves to build a table on this resolution.
    pub fn solves(&self) -> usize {
        (0..self.n_ecc)
            .map(|i| {
                let (n, m) = self.row_columns(i);
                n * (m + 1)
            })
            .sum()
    }
}

/// Largest ε of the solves on the last row (the row itself sits at [`MAX_ECCENTRICITY_RATIO`]).
const ROW_ECC_CAP: f64 = 0.9989;
/// The source of everything that computes a table's numbers: part of the cache key.
const TABLE_SOURCES: [&str; 5] = [
    include_str!("../finite.rs"),
    include_str!("../turbulence.rs"),
    include_str!("../finite/outputs.rs"),
    include_str!("../banded.rs"),
    include_str!("mod.rs"),
];

/// Quantities tabulated at each node, per unit V (1/s) unless said otherwise.
#[derive(Debug, Clone, Copy, Default)]
struct Node {
    /// Film force in the frame of the source direction ψ: turned by −ψ from the line of
    /// centres ([`source_frame`]) (N·s).
    force: [f64; 2],
    /// Largest pressure (Pa·s).
    p_max: f64,
    /// Unit vectors of the angles (from the line of centres) of p_max, ζ1 and ζ2.
    angles: [[f64; 2]; 3],
    /// Pressure-flow friction torque (N·m·s).
    torque_pressure: f64,
    /// Couette friction torque per unit ω (N·m·s).
    torque_couette: f64,
    /// Side flow (m³).
    side_flow: f64,
    /// Pressure part of the inflow at ζ1 (m³).
    inflow_pressure: f64,
    /// Couette part of the inflow per unit ω (m³).
    inflow_couette: f64,
}

impl Node {
    /// Adds `w` × `m`, field by field; `sign` [angles, force] −1 for a mirrored row, whose
    /// angles turn by π (and its force, held in the line of centres; in the source's frame,
    /// [`source_frame`], it stays the same, as do the scalars).
    #[inline]
    fn add(&mut self, w: f64, [sign, force_sign]: [f64; 2], m: &Node) {
        self.force[0] += force_sign * w * m.force[0];
        self.force[1] += force_sign * w * m.force[1];
        self.add_outputs(w, sign, m);
    }

    /// [`add`](Self::add) without the force: `w` × `m`'s outputs (`sign` −1 for a mirrored
    /// row: its angles turn by π). The lean evaluation's outputs of the accepted iterate.
    #[inline]
    pub(super) fn add_outputs(&mut self, w: f64, sign: f64, m: &Node) {
        let ws = sign * w;
        self.p_max += w * m.p_max;
        for k in 0..3 {
            self.angles[k][0] += ws * m.angles[k][0];
            self.angles[k][1] += ws * m.angles[k][1];
        }
        self.torque_pressure += w * m.torque_pressure;
        self.torque_couette += w * m.torque_couette;
        self.side_flow += w * m.side_flow;
        self.inflow_pressure += w * m.inflow_pressure;
        self.inflow_couette += w * m.inflow_couette;
    }
}

/// One row of the table as built: its index, nodes and mid-plane profiles.
type Row = (usize, Vec<Node>, Vec<f64>);

/// The flow factors a table is built with: None laminar, else the regime and the film Reynolds
/// number ρωRc/µ they are frozen at (one slice of a [`ReynoldsTable`]).
pub type SliceFlow = Option<(FlowRegime, f64)>;

/// The film functions of one bearing over (ε, ψ).
pub struct FilmTable {
    geometry: BearingGeometry,
    /// The lubricant and grid it was built with (its cache key, with the geometry and flow).
    lubricant: Lubricant,
    grid: FilmGrid,
    /// Laminar (None), or the turbulent slice's regime and frozen Re.
    flow: SliceFlow,
    nodes: Vec<Node>,
    /// mid-plane pressure per unit V at the grid's n_θ angles from the line of centres (Pa·s)
    profiles: Vec<f64>,
    n_theta: usize,
    /// The resolution it was built on, and u at [`MAX_ECCENTRICITY_RATIO`].
    res: TableResolution,
    layout: Layout,
    u_max: f64,
    /// κ = sin(Δθ/2)/(Δθ/2) of the grid ([`couette_factor`]).
    couette_factor: f64,
}

impl FilmTable {
    /// The table of a plain bearing (no grooves) on `grid`, shared between all users of the same
    /// bearing in this process: on first use read from the disk cache ([`set_disk_cache`]) or
    /// built ([`TableResolution::solves`] film solves, on all cores) and stored there, then reused.
    pub fn shared(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
    ) -> Result<Arc<FilmTable>, FilmError> {
        Self::shared_with_origin(geometry, lubricant, grid).map(|(t, _)| t)
    }

    /// [`FilmTable::shared`], saying where the table came from. Cache problems are printed to
    /// standard error as warnings (and the table built); they are never errors.
    pub fn shared_with_origin(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
    ) -> Result<(Arc<FilmTable>, TableOrigin), FilmError> {
        Self::shared_slice(geometry, lubricant, grid, None)
    }

    /// [`FilmTable::shared_with_origin`] for the flow `flow` (a turbulent slice, or laminar).
    pub fn shared_slice(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        flow: SliceFlow,
    ) -> Result<(Arc<FilmTable>, TableOrigin), FilmError> {
        static CACHE: OnceLock<Mutex<HashMap<String, Arc<FilmTable>>>> = OnceLock::new();
        let key = format!("{geometry:?}|{lubricant:?}|{grid:?}|{flow:?}");
        let cache = CACHE.get_or_init(Default::default);
        if let Some(t) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return Ok((t.clone(), TableOrigin::InProcess));
        }
        let (table, origin) = match disk_cache() {
            Some(disk) => disk.load_or_build_slice(geometry, lubricant, grid, flow, &mut |w| {
                eprintln!("rotor-twin: warning: {w}")
            })?,
            None => (
                Self::build_slice(geometry, lubricant, grid, TableResolution::DEFAULT, flow)?,
                TableOrigin::Built(None),
            ),
        };
        let table = Arc::new(table);
        cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(key, table.clone());
        Ok((table, origin))
    }

    /// Every tabulated number (the nodes' values, then the mid-plane profiles), in the cache
    /// file's order: for comparing two tables bit for bit.
    pub fn values(&self) -> Vec<f64> {
        self.nodes
            .iter()
            .flat_map(cache::node_values)
            .chain(self.profiles.iter().copied())
            .collect()
    }

    /// Builds the table with the direct solver on the default resolution.
    pub fn build(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
    ) -> Result<FilmTable, FilmError> {
        Self::build_with(geometry, lubricant, grid, TableResolution::DEFAULT)
    }

    /// Builds the table with the direct solver on `res` (the convergence study's tables; only
    /// the default resolution is cached).
    pub fn build_with(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        res: TableResolution,
    ) -> Result<FilmTable, FilmError> {
        Self::build_slice(geometry, lubricant, grid, res, None)
    }

    /// [`FilmTable::build_with`] with the flow factors of `flow` (None: laminar).
    pub fn build_slice(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        res: TableResolution,
        flow: SliceFlow,
    ) -> Result<FilmTable, FilmError> {
        res.validate()?;
        if !geometry.grooves.is_empty() {
            return Err(FilmError::InvalidParameter {
                name: "bearing grooves (tabulated film)",
                value: geometry.grooves.len() as f64,
                rule: "the table is for plain bearings; grooved bearings use the direct solver",
            });
        }
        let u_max = res.map.u(MAX_ECCENTRICITY_RATIO);
        let n_ecc = res.n_ecc;
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let rows: Vec<usize> = (0..n_ecc).collect();
        let chunks: Vec<&[usize]> = rows.chunks(n_ecc.div_ceil(threads)).collect();
        let n_theta = grid.n_theta;
        let results: Vec<Result<Vec<Row>, FilmError>> = std::thread::scope(|s| {
            let handles: Vec<_> = chunks
                .iter()
                .map(|chunk| {
                    let geometry = geometry.clone();
                    s.spawn(move || {
                        let mut film = FiniteFilm::new(geometry.clone(), lubricant, grid)?;
                        if let Some((regime, reynolds)) = flow {
                            film = film.with_frozen_reynolds(regime, reynolds);
                        }
                        let mut out = Vec::new();
                        for &i in chunk.iter() {
                            let eps = res.row_eps(i).min(ROW_ECC_CAP);
                            let (n_psi, m) = res.row_columns(i);
                            let (nodes, profiles) =
                                row(&mut film, &geometry, eps, [n_psi, m], res.frame)?;
                            out.push((i, nodes, profiles));
                        }
                        Ok(out)
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("table builder thread"))
                .collect()
        });
        let layout = res.layout();
        let mut nodes = vec![Node::default(); res.nodes()];
        let mut profiles = vec![0.0; res.nodes() * n_theta];
        for part in results {
            for (i, row_nodes, row_profiles) in part? {
                let (a, b) = (layout.start(i), layout.start(i + 1));
                nodes[a..b].copy_from_slice(&row_nodes);
                profiles[a * n_theta..b * n_theta].copy_from_slice(&row_profiles);
            }
        }
        Ok(FilmTable {
            geometry: geometry.clone(),
            lubricant,
            grid,
            flow,
            nodes,
            profiles,
            n_theta,
            res,
            layout,
            u_max,
            couette_factor: couette_factor(grid),
        })
    }

    /// The journal state `kin` in its line of centres, U with the grid's [`couette_factor`].
    fn line_of_centres(&self, kin: &JournalKinematics) -> LineOfCentres {
        LineOfCentres::of(kin, self.geometry.radial_clearance_m, self.couette_factor)
    }

    /// The resolution this table was built on.
    pub fn resolution(&self) -> TableResolution {
        self.res
    }

    /// The fractional row index of ε and its derivative d(row)/dε.
    fn row_coordinate(&self, eps: f64) -> (f64, f64) {
        let e = eps.clamp(0.0, MAX_ECCENTRICITY_RATIO);
        let per_u = (self.res.n_ecc - 1) as f64 / self.u_max;
        let last = (self.res.n_ecc - 1) as f64 - 1e-9;
        (
            (self.res.map.u(e) * per_u).clamp(0.0, last),
            per_u / self.res.map.slope(e),
        )
    }

    /// The column of ψ among `n` columns and the fraction past it.
    fn column_coordinate(n: usize, psi: f64) -> (usize, f64) {
        let fp = wrap_angle_rad(psi) / TAU * n as f64;
        let ip = (fp.floor() as usize).min(n - 1);
        (ip, fp - ip as f64)
    }

    /// The four nodes around (ε, ψ) (each row's two columns at its own spacing) and their
    /// bilinear weights: for the mid-plane profile, where a smooth display suffices.
    fn bilinear(&self, eps: f64, psi: f64) -> ([usize; 4], [f64; 4]) {
        let (fu, _) = self.row_coordinate(eps);
        let iu = fu.floor() as usize;
        let tu = fu - iu as f64;
        let rows = [iu, (iu + 1).min(self.res.n_ecc - 1)];
        let mut index = [0; 4];
        let mut weight = [0.0; 4];
        for (a, (&r, wr)) in rows.iter().zip([1.0 - tu, tu]).enumerate() {
            let n = self.layout.columns(r);
            let (ip, tp) = Self::column_coordinate(n, psi);
            let start = self.layout.start(r);
            index[2 * a] = start + ip;
            index[2 * a + 1] = start + (ip + 1) % n;
            weight[2 * a] = wr * (1.0 - tp);
            weight[2 * a + 1] = wr * tp;
        }
        (index, weight)
    }

    /// The 4 × 4 Catmull–Rom stencil at (ε, ψ) with the weights' derivatives d/dε and d/dψ.
    /// Each stencil row is interpolated in ψ on its own columns ([`WallRows`]).
    fn stencil_with_slopes(&self, eps: f64, psi: f64) -> Stencil {
        let n_ecc = self.res.n_ecc;
        let (fu, dfu) = self.row_coordinate(eps);
        let iu = fu.floor() as usize;
        // below the first interval: row −1 is row 1's mirror image (atanh map), or the linear
        // extrapolation of rows 0 and 1 (log map); beyond the last, the linear extrapolation of
        // the last two. Extrapolations are folded into the weights of the rows that exist.
        let mirror = iu == 0 && self.res.map == EccentricityMap::Atanh;
        let fold = |w: [f64; 4]| -> [f64; 4] {
            if iu == 0 && !mirror {
                // row −1 = 2·row 0 − row 1
                [0.0, w[1] + 2.0 * w[0], w[2] - w[0], w[3]]
            } else if iu + 2 > n_ecc - 1 {
                // row N = 2·row N−1 − row N−2
                [w[0], w[1] - w[3], w[2] + 2.0 * w[3], 0.0]
            } else {
                w
            }
        };
        let rows = if iu == 0 {
            [usize::from(mirror), 0, 1, 2]
        } else if iu + 2 > n_ecc - 1 {
            [iu - 1, iu, iu + 1, iu + 1]
        } else {
            [iu - 1, iu, iu + 1, iu + 2]
        };
        // the columns and weights in ψ on n columns
        let in_psi = |n: usize| {
            let (ip, tp) = Self::column_coordinate(n, psi);
            let cols = [(ip + n - 1) % n, ip, (ip + 1) % n, (ip + 2) % n];
            // d(fp)/dψ = N_ψ/2π
            let dfp = n as f64 / TAU;
            (
                n,
                cols,
                catmull_rom(tp),
                catmull_rom_slope(tp).map(|w| w * dfp),
            )
        };
        let main = in_psi(self.layout.n_psi);
        let wall = if self.layout.n_psi_wall == self.layout.n_psi {
            main
        } else {
            in_psi(self.layout.n_psi_wall)
        };
        let per_row = rows.map(|r| if r < self.layout.wall_row { main } else { wall });
        let tu = fu - iu as f64;
        Stencil {
            start: rows.map(|r| self.layout.start(r)),
            n_cols: per_row.map(|p| p.0),
            mirrored: [mirror, false, false, false],
            mirrored_force_sign: match self.res.frame {
                ForceFrame::Source => 1.0,
                ForceFrame::LineOfCentres => -1.0,
            },
            cols: per_row.map(|p| p.1),
            wr: fold(catmull_rom(tu)),
            wc: per_row.map(|p| p.2),
            dwr: fold(catmull_rom_slope(tu)).map(|w| w * dfu),
            dwc: per_row.map(|p| p.3),
        }
    }

    /// The force along and across the line of centres per unit V (N·s) at (ε, ψ), and its
    /// derivatives with respect to ε and ψ (those of the interpolant).
    fn force_with_slopes(&self, eps: f64, psi: f64) -> [[f64; 2]; 3] {
        let st = self.stencil_with_slopes(eps, psi);
        let mut out = [[0.0; 2]; 3];
        for a in 0..4 {
            for b in 0..4 {
                let (index, [_, sign]) = st.node(a, b);
                let m = &self.nodes[index];
                let w = [
                    sign * st.wr[a] * st.wc[a][b],
                    sign * st.dwr[a] * st.wc[a][b],
                    sign * st.wr[a] * st.dwc[a][b],
                ];
                for (o, wk) in out.iter_mut().zip(w) {
                    o[0] += wk * m.force[0];
                    o[1] += wk * m.force[1];
                }
            }
        }
        if self.res.frame == ForceFrame::LineOfCentres {
            return out;
        }
        let [g, g_eps, g_psi] = out;
        let (f, f_eps, f_psi) = from_source_frame(psi, g, g_eps, g_psi);
        [f, f_eps, f_psi]
    }

    /// The interpolated node at (ε, ψ), its force turned to the line of centres.
    fn node_at(&self, eps: f64, psi: f64) -> Node {
        let st = self.stencil_with_slopes(eps, psi);
        let mut n = Node::default();
        for a in 0..4 {
            for b in 0..4 {
                let (index, sign) = st.node(a, b);
                n.add(st.wr[a] * st.wc[a][b], sign, &self.nodes[index]);
            }
        }
        if self.res.frame == ForceFrame::Source {
            n.force = source_frame(psi, n.force, 1.0);
        }
        n
    }

    /// The interpolated node at (ε, ψ) and its force's derivatives with respect to ε and ψ
    /// (those of [`force_with_slopes`](Self::force_with_slopes), from the same stencil pass:
    /// the same sums in the same order).
    fn node_with_slopes(&self, eps: f64, psi: f64) -> (Node, [f64; 2], [f64; 2]) {
        let st = self.stencil_with_slopes(eps, psi);
        let mut n = Node::default();
        let (mut f_eps, mut f_psi) = ([0.0; 2], [0.0; 2]);
        for a in 0..4 {
            for b in 0..4 {
                let (index, sign) = st.node(a, b);
                let m = &self.nodes[index];
                n.add(st.wr[a] * st.wc[a][b], sign, m);
                let (w_eps, w_psi) = (
                    sign[1] * st.dwr[a] * st.wc[a][b],
                    sign[1] * st.wr[a] * st.dwc[a][b],
                );
                f_eps[0] += w_eps * m.force[0];
                f_eps[1] += w_eps * m.force[1];
                f_psi[0] += w_psi * m.force[0];
                f_psi[1] += w_psi * m.force[1];
            }
        }
        if self.res.frame == ForceFrame::LineOfCentres {
            return (n, f_eps, f_psi);
        }
        let (f, f_eps, f_psi) = from_source_frame(psi, n.force, f_eps, f_psi);
        n.force = f;
        (n, f_eps, f_psi)
    }

    /// The film force `[F_x, F_y]` (N) in the fixed frame for `kin` (no checks).
    pub fn force(&self, kin: &JournalKinematics) -> [f64; 2] {
        let s = self.line_of_centres(kin);
        if s.v == 0.0 {
            return [0.0, 0.0];
        }
        let [fr, ft] = self.force_with_slopes(s.eps, s.psi)[0];
        s.rotate_to_fixed([s.v * fr, s.v * ft])
    }
}

impl FilmTable {
    /// −∂F/∂(x, y) and −∂F/∂(ẋ, ẏ) of the interpolant by the chain rule through the line of
    /// centres: F = R(φ) V f(ε, ψ), with U = ω ε − 2 v_t / c, W = 2 v_r / c, V = √(U² + W²),
    /// ψ = atan2(W, U). Away from the centre (ε > 10⁻³) only. (The film reads
    /// [`node_with_slopes`](Self::node_with_slopes) and
    /// [`coefficients_from_slopes`](Self::coefficients_from_slopes); this is the tests' path.)
    #[cfg(test)]
    fn analytic_coefficients(
        &self,
        kin: &JournalKinematics,
        s: &LineOfCentres,
    ) -> (Matrix2<f64>, Matrix2<f64>) {
        let [f, f_eps, f_psi] = self.force_with_slopes(s.eps, s.psi);
        self.coefficients_from_slopes(kin, s, [f, f_eps, f_psi])
    }

    /// [`analytic_coefficients`](Self::analytic_coefficients) from the interpolated force per
    /// unit V and its slopes d/dε, d/dψ at the state.
    fn coefficients_from_slopes(
        &self,
        kin: &JournalKinematics,
        s: &LineOfCentres,
        [f, f_eps, f_psi]: [[f64; 2]; 3],
    ) -> (Matrix2<f64>, Matrix2<f64>) {
        let c = self.geometry.radial_clearance_m;
        let (cp, sp) = (s.cos_phi, s.sin_phi);
        let e = s.eps * c;
        let [vx, vy] = kin.velocity_m_s;
        let v_r = vx * cp + vy * sp;
        let v_t = -vx * sp + vy * cp;
        let omega = kin.speed_rad_s;
        let omega = omega * self.couette_factor;
        let (u, w) = (omega * s.eps - 2.0 * v_t / c, 2.0 * v_r / c);
        let g = [s.v * f[0], s.v * f[1]];
        // per variable x, y, ẋ, ẏ: derivatives of ε, φ, v_r, v_t
        let eps_q = [cp / c, sp / c, 0.0, 0.0];
        let phi_q = [-sp / e, cp / e, 0.0, 0.0];
        let vr_q = [v_t * phi_q[0], v_t * phi_q[1], cp, sp];
        let vt_q = [-v_r * phi_q[0], -v_r * phi_q[1], -sp, cp];
        let mut dfdq = [[0.0; 2]; 4];
        for q in 0..4 {
            let u_q = omega * eps_q[q] - 2.0 * vt_q[q] / c;
            let w_q = 2.0 * vr_q[q] / c;
            let v_q = (u * u_q + w * w_q) / s.v;
            let psi_q = (u * w_q - w * u_q) / (s.v * s.v);
            // dg/dq + J g φ_q, J = [[0, −1], [1, 0]] (the turn of the frame), then back to x, y
            let local = [
                v_q * f[0] + s.v * (f_eps[0] * eps_q[q] + f_psi[0] * psi_q) - g[1] * phi_q[q],
                v_q * f[1] + s.v * (f_eps[1] * eps_q[q] + f_psi[1] * psi_q) + g[0] * phi_q[q],
            ];
            dfdq[q] = s.rotate_to_fixed(local);
        }
        let k = Matrix2::from_fn(|i, j| -dfdq[j][i]);
        let d = Matrix2::from_fn(|i, j| -dfdq[2 + j][i]);
        (k, d)
    }

    /// The same by central differences of the interpolant (near the centre, where the attitude
    /// turns fast with the position): steps of 1e-4 c and 1e-4 c ω (at least 1e-4 c /s), small
    /// against the table's spacing, large enough that the interpolant's small inconsistencies
    /// under rotation do not swamp the derivative.
    fn difference_coefficients(&self, kin: &JournalKinematics) -> (Matrix2<f64>, Matrix2<f64>) {
        let c = self.geometry.radial_clearance_m;
        let dq = 1e-4 * c;
        let dv = 1e-4 * c * kin.speed_rad_s.abs().max(1.0);
        let mut k = Matrix2::zeros();
        let mut d = Matrix2::zeros();
        for j in 0..2 {
            let mut plus = *kin;
            let mut minus = *kin;
            plus.position_m[j] += dq;
            minus.position_m[j] -= dq;
            let (fp, fm) = (self.force(&plus), self.force(&minus));
            let mut vplus = *kin;
            let mut vminus = *kin;
            vplus.velocity_m_s[j] += dv;
            vminus.velocity_m_s[j] -= dv;
            let (gp, gm) = (self.force(&vplus), self.force(&vminus));
            for i in 0..2 {
                k[(i, j)] = -(fp[i] - fm[i]) / (2.0 * dq);
                d[(i, j)] = -(gp[i] - gm[i]) / (2.0 * dv);
            }
        }
        (k, d)
    }
}

/// Rows and columns of a 4 × 4 interpolation stencil, the weights and their derivatives; each
/// stencil row has its own columns and ψ-weights (its own spacing, [`WallRows`]).
struct Stencil {
    /// each stencil row's first node in the table, and its column count
    start: [usize; 4],
    n_cols: [usize; 4],
    /// rows read as their mirror image through the centre, f(−ε, ψ) = −f(ε, ψ + π), i.e.
    /// g(−ε, ψ) = g(ε, ψ + π) for the force in the source's frame ([`source_frame`])
    mirrored: [bool; 4],
    /// the sign of a mirrored row's force: −1 in the line of centres, +1 in the source's frame
    mirrored_force_sign: f64,
    cols: [[usize; 4]; 4],
    wr: [f64; 4],
    wc: [[f64; 4]; 4],
    /// d wr / dε
    dwr: [f64; 4],
    /// d wc / dψ
    dwc: [[f64; 4]; 4],
}

impl Stencil {
    /// The index of node (a, b) of the stencil in the table, and the signs of its angles' unit
    /// vectors and of its force (−1 in a mirrored row; a force in the source's frame keeps its
    /// sign there).
    #[inline]
    fn node(&self, a: usize, b: usize) -> (usize, [f64; 2]) {
        if self.mirrored[a] {
            let n = self.n_cols[a];
            let col = (self.cols[a][b] + n / 2) % n;
            (self.start[a] + col, [-1.0, self.mirrored_force_sign])
        } else {
            (self.start[a] + self.cols[a][b], [1.0, 1.0])
        }
    }
}

/// The derivatives of the Catmull–Rom weights with respect to `t`.
fn catmull_rom_slope(t: f64) -> [f64; 4] {
    let t2 = t * t;
    [
        0.5 * (-3.0 * t2 + 4.0 * t - 1.0),
        0.5 * (9.0 * t2 - 10.0 * t),
        0.5 * (-9.0 * t2 + 8.0 * t + 1.0),
        0.5 * (3.0 * t2 - 2.0 * t),
    ]
}

/// The Catmull–Rom weights of the four stencil values at fraction `t` ∈ [0, 1).
fn catmull_rom(t: f64) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

/// One row of the table (fixed ε): at each ψ, a direct solve at each grid phase with ω = 0 and
/// the whole source from the journal's velocity (pressure parts), and one more at phase 0 with
/// ω = 1 rad/s and the whirl that keeps U (the Couette parts, by difference). Angles and the
/// force are turned back to the line of centres; the mid-plane profile is that of phase 0 (on
/// the grid's angles).
fn row(
    film: &mut FiniteFilm,
    geometry: &BearingGeometry,
    eps: f64,
    [n_psi, m]: [usize; 2],
    frame: ForceFrame,
) -> Result<(Vec<Node>, Vec<f64>), FilmError> {
    let c = geometry.radial_clearance_m;
    let n_theta = film.grid().n_theta;
    let mut nodes = Vec::with_capacity(n_psi);
    let mut profiles = vec![0.0; n_psi * n_theta];
    let kappa = couette_factor(film.grid());
    for j in 0..n_psi {
        let psi = TAU * j as f64 / n_psi as f64;
        let (u, w) = (psi.cos(), psi.sin());
        let mut node = Node::default();
        for k in 0..m {
            let alpha = k as f64 * TAU / n_theta as f64 / m as f64;
            let (ca, sa) = (alpha.cos(), alpha.sin());
            let turn = |v: [f64; 2]| [ca * v[0] - sa * v[1], sa * v[0] + ca * v[1]];
            let back = |v: [f64; 2]| [ca * v[0] + sa * v[1], -sa * v[0] + ca * v[1]];
            // U = ω ε − 2 v_t / c, W = 2 v_r / c, journal at (ε c, 0) turned by α
            let kin = |omega: f64| JournalKinematics {
                position_m: turn([eps * c, 0.0]),
                velocity_m_s: turn([0.5 * w * c, 0.5 * (kappa * omega * eps - u) * c]),
                speed_rad_s: omega,
            };
            let pressure = film.solve(&kin(0.0))?;
            if k == 0 {
                film.midplane_pressure(&mut profiles[j * n_theta..(j + 1) * n_theta]);
            }
            let unit = |a: f64| [(a - alpha).cos(), (a - alpha).sin()];
            let share = 1.0 / m as f64;
            let f = match frame {
                ForceFrame::Source => source_frame(psi, back(pressure.force_n), -1.0),
                ForceFrame::LineOfCentres => back(pressure.force_n),
            };
            node.force[0] += share * f[0];
            node.force[1] += share * f[1];
            node.p_max += share * pressure.max_pressure_pa;
            if pressure.max_pressure_pa > 0.0 {
                let a = [
                    unit(pressure.max_pressure_angle_rad),
                    unit(pressure.film_start_rad),
                    unit(pressure.film_end_rad),
                ];
                for (n, v) in node.angles.iter_mut().zip(a) {
                    n[0] += share * v[0];
                    n[1] += share * v[1];
                }
            }
            node.torque_pressure += share * pressure.friction_torque_n_m;
            node.side_flow += share * pressure.side_flow_m3_s;
            node.inflow_pressure += share * pressure.inflow_m3_s;
            if k == 0 {
                // the Couette parts (friction, inflow) enter no coefficient: phase 0 suffices
                let with_shear = film.solve(&kin(1.0))?;
                node.torque_couette = with_shear.friction_torque_n_m - pressure.friction_torque_n_m;
                node.inflow_couette = with_shear.inflow_m3_s - pressure.inflow_m3_s;
            }
        }
        nodes.push(node);
    }
    Ok((nodes, profiles))
}

/// The direct solver's Couette source, differenced across a cell, ω (h_{i+½} − h_{i−½})/Δθ =
/// κ ω ε sin(θ_i − φ) with κ = sin(Δθ/2)/(Δθ/2) (1 − 4.6·10⁻⁴ on 60 columns), while its squeeze
/// source is taken at the node: the discrete problem is homogeneous in (U, W) with
/// U = κ ω ε − 2 v_t / c, not ω ε − 2 v_t / c. The table (built at ω = 0) uses that U, so it
/// tabulates the direct solver's own discrete problem; with the plain U its force was 0.8 % off
/// where whirl nearly cancels rotation (V ≪ ω ε: ε 0.78, V 93/s against ω ε 737/s).
fn couette_factor(grid: FilmGrid) -> f64 {
    let half = 0.5 * TAU / grid.n_theta as f64;
    half.sin() / half
}

/// `v` (a force per unit V in the line of centres) turned by `sign` × ψ: −1 into the frame of
/// the source direction ψ, where the table holds it, +1 back.
///
/// Why the table holds the force in the source's frame: at the centre the film is round, so
/// turning the source (U, W) by ψ turns the pressure field and the force with it,
/// f(0, ψ) = R(ψ) f(0, 0); in the source's frame g = R(−ψ) f the centre's row is constant and
/// g's ψ-dependence grows from zero with ε. The position coefficients across the line of
/// centres are (J f − ∂f/∂ψ)/ε c + … (J the quarter turn): two terms of order 1/ε that cancel,
/// leaving R(ψ) ∂g/∂ψ / ε. Interpolating f, the interpolation error of ∂f/∂ψ (≈ 10⁻⁴ of |f| on
/// 192 columns) was multiplied by 1/ε: 0.77 % of the coefficient scale at ε < 0.03. Interpolating
/// g, that error is itself of order ε. The mirror row reads g(−ε, ψ) = g(ε, ψ + π).
#[inline]
fn source_frame(psi: f64, v: [f64; 2], sign: f64) -> [f64; 2] {
    let (s, c) = psi.sin_cos();
    let s = sign * s;
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// The force per unit V in the line of centres and its slopes d/dε, d/dψ from those of the
/// tabulated g = R(−ψ) f: f = R(ψ) g, f_ε = R(ψ) g_ε, f_ψ = R(ψ) (g_ψ + J g).
#[inline]
fn from_source_frame(
    psi: f64,
    g: [f64; 2],
    g_eps: [f64; 2],
    g_psi: [f64; 2],
) -> ([f64; 2], [f64; 2], [f64; 2]) {
    let turn = |v: [f64; 2]| source_frame(psi, v, 1.0);
    (
        turn(g),
        turn(g_eps),
        turn([g_psi[0] - g[1], g_psi[1] + g[0]]),
    )
}

/// A journal state in the frame of its line of centres.
#[derive(Debug, Clone, Copy)]
struct LineOfCentres {
    eps: f64,
    /// cosine and sine of the attitude φ
    cos_phi: f64,
    sin_phi: f64,
    /// V = √(U² + W²) (1/s) and ψ = atan2(W, U)
    v: f64,
    psi: f64,
}

impl LineOfCentres {
    fn of(kin: &JournalKinematics, c: f64, couette_factor: f64) -> Self {
        let [x, y] = kin.position_m;
        let [vx, vy] = kin.velocity_m_s;
        let e = (x * x + y * y).sqrt();
        // at the centre the frame is arbitrary: the x axis
        let (cos_phi, sin_phi) = if e > 1e-12 * c {
            (x / e, y / e)
        } else {
            (1.0, 0.0)
        };
        let v_r = vx * cos_phi + vy * sin_phi;
        let v_t = -vx * sin_phi + vy * cos_phi;
        let eps = e / c;
        let u = couette_factor * kin.speed_rad_s * eps - 2.0 * v_t / c;
        let w = 2.0 * v_r / c;
        Self {
            eps,
            cos_phi,
            sin_phi,
            v: (u * u + w * w).sqrt(),
            psi: w.atan2(u),
        }
    }

    /// The attitude φ (rad).
    fn phi(&self) -> f64 {
        self.sin_phi.atan2(self.cos_phi)
    }

    fn rotate_to_fixed(&self, f: [f64; 2]) -> [f64; 2] {
        [
            f[0] * self.cos_phi - f[1] * self.sin_phi,
            f[0] * self.sin_phi + f[1] * self.cos_phi,
        ]
    }
}
