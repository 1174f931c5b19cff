//! The turbulent film tabulated (issue 18): the film Reynolds number as a third dimension.
//!
//! Why a third dimension, and not a rescaling. In the finite solver's Π form the turbulent film
//! (eq. T1) is ∇·(G(H; Re) ∇Π) = source(U, W), with G = H³·12/k(Re·H) and Re = ρωRc/µ: the
//! conductances depend on the speed and the viscosity through Re only, the source on the
//! journal's state through (U, W) only. So at a *fixed* Re the problem is positively homogeneous
//! in (U, W), as the laminar one is, and p = V·P(θ, z; ε, ψ, Re): one (ε, ψ) table per Re, each
//! built as the laminar table is (at ω = 0, with the factors frozen at that Re,
//! [`FiniteFilm::with_frozen_reynolds`](crate::film::FiniteFilm::with_frozen_reynolds)). No
//! exact rescaling folds Re away: a change of ω or µ changes Re·H in every conductance, and the
//! factors k = 12 + a (Re H)^b (eq. T2) have no scaling symmetry: the laminar 12 is additive and
//! the circumferential and axial exponents differ (0.90, 0.96), so no power of Re scales both
//! G_x and G_z by the same factor at every H (even the fully turbulent limit, G_x ∝ Re^-0.90,
//! G_z ∝ Re^-0.96, scales them unequally: the pressure field's shape changes with Re). The
//! eight coefficients are derivatives at fixed speed, so at fixed Re: no ∂/∂Re is needed.
//!
//! The axis: slices equally spaced in x = Re^0.9 (k_x − 12 ∝ x: the factors' leading
//! dependence made linear, and smooth at Re = 0, where Re^0.9 is not), interpolated by
//! Catmull–Rom over four slices (linear extrapolation past the ends), from Re = 0 (laminar) to
//! the bearing's largest Re for `turbulent`; for `auto`, the laminar table up to Taylor's onset
//! Re_T (exact: the factors are laminar there) and slices from one below Re_T (laminar) to the
//! largest Re. Spacing: [`ReynoldsAxis::default_spacing`], from the convergence study in the README.

use super::{FilmTable, LineOfCentres, Node, SliceFlow, TableResolution, TabulatedFilm};
use crate::film::turbulence::{taylor_onset, FlowRegime};
use crate::film::{
    BearingGeometry, FilmCoefficients, FilmError, FilmGrid, FilmModel, FilmResult,
    JournalKinematics, Lubricant,
};
use std::sync::Arc;

/// The exponent of the axis coordinate x = Re^0.9.
const AXIS_EXPONENT: f64 = 0.9;

/// The Reynolds-number axis of a turbulent table: slices at x_j = x_0 + j·h, x = Re^0.9.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReynoldsAxis {
    /// The flow regime of every slice.
    pub regime: FlowRegime,
    /// x of slice 0.
    x0: f64,
    /// Spacing in x.
    h: f64,
    /// Slices.
    n: usize,
    /// Below this Re the film is laminar (0 for `turbulent`, Re_T for `auto`).
    laminar_below: f64,
    /// The largest Re covered.
    re_max: f64,
}

impl ReynoldsAxis {
    /// The default largest spacing in x = Re^0.9 between slices for `turbulent` (the README's
    /// study: 0.020 % at 150).
    pub const SPACING: f64 = 150.0;

    /// The spacing for `auto` (the README's study: 4.4 % at 150, 0.22 % at 75): its smoothstep
    /// from Re_T to 1.5 Re_T spans only ≈ 246 in Re^0.9 and needs slices well inside it.
    pub const AUTO_SPACING: f64 = 75.0;

    /// The default spacing of `regime` ([`Self::SPACING`], [`Self::AUTO_SPACING`] for `auto`).
    pub fn default_spacing(regime: FlowRegime) -> f64 {
        if regime == FlowRegime::Auto {
            Self::AUTO_SPACING
        } else {
            Self::SPACING
        }
    }

    /// The axis of `regime` from Re 0 to `re_max` for clearance ratio `r_over_c`, slices at
    /// most `spacing` apart in x = Re^0.9.
    pub fn new(
        regime: FlowRegime,
        re_max: f64,
        r_over_c: f64,
        spacing: f64,
    ) -> Result<Self, FilmError> {
        if !(re_max.is_finite() && re_max >= 0.0) {
            return Err(FilmError::InvalidParameter {
                name: "largest film Reynolds number (turbulent table)",
                value: re_max,
                rule: "finite, at least 0",
            });
        }
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(FilmError::InvalidParameter {
                name: "slice spacing in Re^0.9 (turbulent table)",
                value: spacing,
                rule: "finite, positive",
            });
        }
        let x_max = re_max.powf(AXIS_EXPONENT);
        let laminar = |laminar_below| Self {
            regime,
            x0: 0.0,
            h: 1.0,
            n: 1,
            laminar_below,
            re_max,
        };
        Ok(match regime {
            FlowRegime::Laminar => laminar(f64::INFINITY),
            FlowRegime::Turbulent if re_max == 0.0 => laminar(0.0),
            FlowRegime::Turbulent => {
                let m = (x_max / spacing).ceil().max(1.0);
                Self {
                    regime,
                    x0: 0.0,
                    h: x_max / m,
                    n: m as usize + 1,
                    laminar_below: 0.0,
                    re_max,
                }
            }
            FlowRegime::Auto => {
                let onset = taylor_onset(r_over_c);
                let x_on = onset.powf(AXIS_EXPONENT);
                if re_max <= onset {
                    laminar(onset)
                } else {
                    let m = ((x_max - x_on) / spacing).ceil().max(1.0);
                    let h = (x_max - x_on) / m;
                    // slice 0 one step below the onset (laminar), slice 1 at the onset
                    Self {
                        regime,
                        x0: x_on - h,
                        h,
                        n: m as usize + 2,
                        laminar_below: onset,
                        re_max,
                    }
                }
            }
        })
    }

    /// Number of slices.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether the axis has no slice (never: at least the laminar one).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The largest Re covered.
    pub fn re_max(&self) -> f64 {
        self.re_max
    }

    /// The film Reynolds number of slice `j`.
    pub fn reynolds(&self, j: usize) -> f64 {
        (self.x0 + j as f64 * self.h)
            .max(0.0)
            .powf(1.0 / AXIS_EXPONENT)
    }

    /// The flow a slice is built with: None where the factors are laminar (the laminar table,
    /// shared with laminar bearings), else the regime at the slice's Re.
    pub fn slice_flow(&self, j: usize) -> SliceFlow {
        let re = self.reynolds(j);
        if self.n == 1 || re <= self.laminar_below {
            None
        } else {
            Some((self.regime, re))
        }
    }

    /// The four slices around `re` and their Catmull–Rom weights (unused ones weigh 0). `re`
    /// must be within the axis (the caller checks).
    #[inline]
    fn stencil(&self, re: f64) -> ([usize; 4], [f64; 4]) {
        if self.n == 1 || re <= self.laminar_below {
            return ([0; 4], [1.0, 0.0, 0.0, 0.0]);
        }
        let n = self.n;
        let t = ((re.powf(AXIS_EXPONENT) - self.x0) / self.h).clamp(0.0, (n - 1) as f64);
        let i = (t.floor() as usize).min(n - 2);
        let w = super::catmull_rom(t - i as f64);
        if n == 2 {
            // two slices: linear
            let f = t - i as f64;
            return ([0, 1, 0, 0], [1.0 - f, f, 0.0, 0.0]);
        }
        // `auto` just past the onset (slice 1): the blend is laminar + s(Re)·(turbulent excess)
        // with s(Re_T) = s'(Re_T) = 0 (smoothstep), so the force's slope in Re is 0 at the
        // onset; the laminar slice 0 below it would give Catmull–Rom a wrong slope there
        // (0.5–0.7 % force error at Re 1,170–1,260, README): an even ghost, slice 0 := slice 2
        if self.regime == FlowRegime::Auto && i == 1 && n >= 4 {
            return ([1, 2, 3, 0], [w[1], w[2] + w[0], w[3], 0.0]);
        }
        // past the ends the missing slice is the linear extrapolation of the two nearest
        if i == 0 {
            ([0, 1, 2, 0], [w[1] + 2.0 * w[0], w[2] - w[0], w[3], 0.0])
        } else if i + 2 > n - 1 {
            (
                [i - 1, i, i + 1, 0],
                [w[0], w[1] - w[3], w[2] + 2.0 * w[3], 0.0],
            )
        } else {
            ([i - 1, i, i + 1, i + 2], w)
        }
    }
}

/// The film functions of one bearing over (ε, ψ, Re): one [`FilmTable`] a slice.
pub struct ReynoldsTable {
    axis: ReynoldsAxis,
    slices: Vec<Arc<FilmTable>>,
    /// ρ R c / µ (s): Re = this × |ω|.
    reynolds_per_speed: f64,
}

impl ReynoldsTable {
    /// The table of `regime` up to Re `re_max` on the default resolution, each slice shared in
    /// the process and cached on disk as the laminar table is ([`FilmTable::shared_slice`]:
    /// the key carries the regime and the slice's Re; laminar slices are the laminar table).
    pub fn shared(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        regime: FlowRegime,
        re_max: f64,
    ) -> Result<Self, FilmError> {
        let spacing = ReynoldsAxis::default_spacing(regime);
        let axis = ReynoldsAxis::new(regime, re_max, r_over_c(geometry), spacing)?;
        let slices = (0..axis.len())
            .map(|j| {
                FilmTable::shared_slice(geometry, lubricant, grid, axis.slice_flow(j))
                    .map(|(t, _)| t)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self::of(axis, slices, geometry, lubricant))
    }

    /// The table on `axis` and resolution `res`, built here (not cached): the studies' tables.
    pub fn build_with(
        geometry: &BearingGeometry,
        lubricant: Lubricant,
        grid: FilmGrid,
        axis: ReynoldsAxis,
        res: TableResolution,
    ) -> Result<Self, FilmError> {
        let slices = (0..axis.len())
            .map(|j| {
                FilmTable::build_slice(geometry, lubricant, grid, res, axis.slice_flow(j))
                    .map(Arc::new)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self::of(axis, slices, geometry, lubricant))
    }

    fn of(
        axis: ReynoldsAxis,
        slices: Vec<Arc<FilmTable>>,
        geometry: &BearingGeometry,
        lubricant: Lubricant,
    ) -> Self {
        Self {
            axis,
            slices,
            reynolds_per_speed: lubricant.density_kg_m3
                * geometry.radius_m()
                * geometry.radial_clearance_m
                / lubricant.viscosity_pa_s,
        }
    }

    /// The axis.
    pub fn axis(&self) -> &ReynoldsAxis {
        &self.axis
    }

    /// The slice tables (slice j at [`ReynoldsAxis::reynolds`]`(j)`).
    pub fn slices(&self) -> &[Arc<FilmTable>] {
        &self.slices
    }

    /// The slices and weights at speed `omega` (rad/s) with the oil at `viscosity_scale` × the
    /// table's (Re = ρωRc/µ follows both); an error beyond the table's Re.
    #[inline]
    fn stencil(
        &self,
        omega: f64,
        viscosity_scale: f64,
    ) -> Result<([usize; 4], [f64; 4]), FilmError> {
        let re = self.reynolds_per_speed * omega.abs() / viscosity_scale;
        if re > self.axis.re_max * (1.0 + 1e-9) && self.axis.regime != FlowRegime::Laminar {
            return Err(FilmError::InvalidParameter {
                name: "journal speed (turbulent film table), rad/s",
                value: omega,
                rule: "within the table's film Reynolds range (the table was built up to a \
                       largest Re); use the direct film beyond",
            });
        }
        Ok(self.axis.stencil(re))
    }
}

fn r_over_c(geometry: &BearingGeometry) -> f64 {
    geometry.radius_m() / geometry.radial_clearance_m
}

/// A film model that evaluates a [`ReynoldsTable`] (see the module documentation): at the
/// journal's speed, the Catmull–Rom blend of four slices' interpolated nodes and force slopes.
#[derive(Clone)]
pub struct ReynoldsTabulatedFilm {
    table: Arc<ReynoldsTable>,
    last: JournalKinematics,
    /// µ/µ₀ its Reynolds number is taken at (its [`crate::film::ViscosityScaledFilm`]'s scale)
    viscosity_scale: f64,
}

impl ReynoldsTabulatedFilm {
    /// A model reading `table`.
    pub fn new(table: Arc<ReynoldsTable>) -> Self {
        Self {
            table,
            last: JournalKinematics::default(),
            viscosity_scale: 1.0,
        }
    }

    fn base(&self) -> &FilmTable {
        &self.table.slices[0]
    }

    /// The blended node at (ε, ψ) with its force's slopes d/dε, d/dψ (per unit V).
    fn blend(&self, s: &LineOfCentres, omega: f64) -> Result<(Node, [[f64; 2]; 2]), FilmError> {
        let (idx, w) = self.table.stencil(omega, self.viscosity_scale)?;
        let mut node = Node::default();
        let mut slopes = [[0.0; 2]; 2];
        for (&j, &wj) in idx.iter().zip(&w) {
            if wj == 0.0 {
                continue;
            }
            let (n, f_eps, f_psi) = self.table.slices[j].node_with_slopes(s.eps, s.psi);
            node.add(wj, [1.0, 1.0], &n);
            for k in 0..2 {
                slopes[0][k] += wj * f_eps[k];
                slopes[1][k] += wj * f_psi[k];
            }
        }
        Ok((node, slopes))
    }
}

impl FilmModel for ReynoldsTabulatedFilm {
    fn geometry(&self) -> &BearingGeometry {
        &self.base().geometry
    }

    fn clone_box(&self) -> Box<dyn FilmModel + Send> {
        Box::new(self.clone())
    }

    fn set_reynolds_viscosity_scale(&mut self, scale: f64) {
        self.viscosity_scale = scale;
    }

    fn solve(&mut self, kin: &JournalKinematics) -> Result<FilmResult, FilmError> {
        kin.validate(self.base().geometry.radial_clearance_m)?;
        self.last = *kin;
        let s = self.base().line_of_centres(kin);
        let (n, _) = self.blend(&s, kin.speed_rad_s)?;
        Ok(super::tabulated::result_of(&s, &n, kin.speed_rad_s))
    }

    fn solve_with_coefficients(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError> {
        kin.validate(self.base().geometry.radial_clearance_m)?;
        self.last = *kin;
        let base = &self.table.slices[0];
        let s = base.line_of_centres(kin);
        let (n, [f_eps, f_psi]) = self.blend(&s, kin.speed_rad_s)?;
        let (k, d) = if s.eps > 1e-3 && s.v > 0.0 {
            base.coefficients_from_slopes(kin, &s, [n.force, f_eps, f_psi])
        } else {
            // near the centre: the slices' difference coefficients, blended (linear in the force)
            let (idx, w) = self.table.stencil(kin.speed_rad_s, self.viscosity_scale)?;
            let (mut k, mut d) = (nalgebra::Matrix2::zeros(), nalgebra::Matrix2::zeros());
            for (&j, &wj) in idx.iter().zip(&w) {
                if wj != 0.0 {
                    let (kj, dj) = self.table.slices[j].difference_coefficients(kin);
                    k += kj * wj;
                    d += dj * wj;
                }
            }
            (k, d)
        };
        Ok((
            super::tabulated::result_of(&s, &n, kin.speed_rad_s),
            FilmCoefficients {
                stiffness_n_per_m: k,
                damping_n_s_per_m: d,
                ..FilmCoefficients::default()
            },
        ))
    }

    /// The profile of the slice that weighs most at the last state's speed (for display and the
    /// monitor's revolution-to-revolution difference, as the laminar table's is bilinear).
    fn midplane_pressure(&self, out: &mut [f64]) {
        let j = match self
            .table
            .stencil(self.last.speed_rad_s, self.viscosity_scale)
        {
            Ok((idx, w)) => {
                let best = (0..4).fold(0, |b, k| if w[k] > w[b] { k } else { b });
                idx[best]
            }
            Err(_) => self.table.slices.len() - 1,
        };
        TabulatedFilm::at(self.table.slices[j].clone(), self.last).midplane_pressure(out);
    }
}
