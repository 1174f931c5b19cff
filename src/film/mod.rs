//! The oil film of a plain journal bearing.
//!
//! Frame used throughout (as in Lund & Thomsen 1978): `x` is the first fixed axis (in a bearing
//! analysis, the direction of the static load), `y` is 90° ahead of `x` in the direction of
//! rotation. The angle θ is measured from `+x` in the direction of rotation. The journal centre
//! position `(x, y)` is relative to the bearing centre, in metres.
//!
//! Two film models stand behind one interface ([`FilmModel`]):
//! - [`FiniteFilm`]: the finite-length Reynolds equation (seed eq. 2, isoviscous) by finite
//!   volumes, with the Reynolds (Swift–Stieber) cavitation condition solved as the
//!   complementarity problem it is (primal–dual active set with a banded Cholesky factor);
//! - [`ShortFilm`]: Ocvirk's short-bearing closed form with the π-film condition;
//! - [`TabulatedFilm`]: the finite film of a plain bearing solved once over every state it can be
//!   in (two parameters suffice) and interpolated.

mod banded;
mod coefficients;
mod equilibrium;
mod error;
mod finite;
mod geometry;
mod heating;
mod inertia;
mod short;
mod table;
mod thermal;
mod turbulence;
mod viscosity;

pub use coefficients::{matrix2, rows, rows2, solve2, FilmCoefficients};
pub use equilibrium::{
    equilibrium_at_eccentricity, equilibrium_position, equilibrium_under_load,
    short_bearing_eccentricity, sommerfeld_number, Equilibrium, MAX_EQUILIBRIUM_ECCENTRICITY,
};
pub use error::FilmError;
pub use finite::{Cavitation, FiniteFilm, FlowBalance};
pub use geometry::{AxialGroove, BearingGeometry, FilmGrid, Lubricant};
pub use heating::{
    effective_temperature, thermal_film_temperature, EffectiveTemperature, HeatBalance, OilHeating,
};
pub use inertia::{equilibrium_with_inertia, FilmInertia, FluidInertia, InertiaForce};
pub use short::ShortFilm;
pub use table::{
    disk_cache, set_disk_cache, table_key, CacheWarning, Lookup, TableCache, TableOrigin,
    FORMAT_VERSION as TABLE_FORMAT_VERSION, SOLVER_VERSION as TABLE_SOLVER_VERSION,
};
pub use table::{
    EccentricityMap, FilmTable, ForceFrame, ReynoldsAxis, ReynoldsTable, ReynoldsTabulatedFilm,
    SliceFlow, TableResolution, TabulatedFilm, WallRows,
};
pub use thermal::{ThermalFilm, ThermalOil, ThermalState};
pub use turbulence::{taylor_onset, FlowFactors, FlowRegime};
pub use viscosity::{
    check_viscosity_scale, ViscosityLaw, ViscosityScaledFilm, ViscosityTable, WaltherLaw,
    MAX_TABLE_POINTS, MAX_VISCOSITY_SCALE, MIN_VISCOSITY_SCALE, ZERO_CELSIUS_K,
};

/// Position and velocity of the journal centre relative to the bearing centre, and its speed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JournalKinematics {
    /// Journal centre position `[x, y]` relative to the bearing centre (m).
    pub position_m: [f64; 2],
    /// Journal centre velocity `[ẋ, ẏ]` (m/s).
    pub velocity_m_s: [f64; 2],
    /// Journal angular speed ω (rad/s), positive when turning from `x` towards `y`.
    pub speed_rad_s: f64,
}

impl JournalKinematics {
    /// A journal at rest in position, turning at `speed_rad_s` (rad/s).
    pub fn at_position(position_m: [f64; 2], speed_rad_s: f64) -> Self {
        Self {
            position_m,
            velocity_m_s: [0.0, 0.0],
            speed_rad_s,
        }
    }

    /// Eccentricity ratio ε = e / c (dimensionless) for radial clearance `clearance_m` (m).
    pub fn eccentricity_ratio(&self, clearance_m: f64) -> f64 {
        self.position_m[0].hypot(self.position_m[1]) / clearance_m
    }

    /// Checks that every field is finite and the journal is inside the clearance circle.
    pub fn validate(&self, clearance_m: f64) -> Result<(), FilmError> {
        let fields = [
            ("journal position x (m)", self.position_m[0]),
            ("journal position y (m)", self.position_m[1]),
            ("journal velocity x (m/s)", self.velocity_m_s[0]),
            ("journal velocity y (m/s)", self.velocity_m_s[1]),
            ("journal speed (rad/s)", self.speed_rad_s),
        ];
        for (name, value) in fields {
            if !value.is_finite() {
                return Err(FilmError::InvalidParameter {
                    name,
                    value,
                    rule: "must be a finite number",
                });
            }
        }
        let eps = self.eccentricity_ratio(clearance_m);
        if eps >= MAX_ECCENTRICITY_RATIO {
            return Err(FilmError::JournalOutsideFilm {
                eccentricity_ratio: eps,
            });
        }
        Ok(())
    }
}

/// Largest eccentricity ratio a film solve accepts: beyond it the minimum film is below 0.1 % of
/// the clearance and the journal is in contact (a contact model, not the film, must carry it).
pub const MAX_ECCENTRICITY_RATIO: f64 = 0.999;

/// What one film solve reports. All angles are measured from `+x` in the direction of rotation,
/// in radians, wrapped to [0, 2π).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FilmResult {
    /// Film force on the journal `[F_x, F_y]` in the fixed frame (N).
    pub force_n: [f64; 2],
    /// Largest film pressure (Pa, gauge).
    pub max_pressure_pa: f64,
    /// Angle of the largest pressure (rad).
    pub max_pressure_angle_rad: f64,
    /// ζ1: where the positive-pressure zone starts in the mid-plane (rad).
    pub film_start_rad: f64,
    /// ζ2: where the film ruptures in the mid-plane (rad), p = ∂p/∂θ = 0 there (seed eq. 6).
    pub film_end_rad: f64,
    /// Viscous friction torque on the journal, opposing rotation (N·m).
    pub friction_torque_n_m: f64,
    /// Power dissipated in the film, torque × ω (W).
    pub power_loss_w: f64,
    /// Flow leaving both ends of the bearing (m³/s).
    pub side_flow_m3_s: f64,
    /// Circumferential flow entering the pressure zone at ζ1 (m³/s).
    pub inflow_m3_s: f64,
}

/// A film model: maps the journal kinematics to the film force and its derivatives.
pub trait FilmModel {
    /// Bearing geometry this model was built for.
    fn geometry(&self) -> &BearingGeometry;

    /// A copy with the same warm-start state (for checkpoints).
    fn clone_box(&self) -> Box<dyn FilmModel + Send>;

    /// Solves the film for `kin`. A model may start from its previous solution (warm start).
    fn solve(&mut self, kin: &JournalKinematics) -> Result<FilmResult, FilmError>;

    /// Solves the film for `kin` and returns the eight dynamic coefficients there (seed eq. 3–4),
    /// obtained by perturbation of the film equations about this position and velocity.
    fn solve_with_coefficients(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError>;

    /// [`FilmModel::solve_with_coefficients`] for an iterate of a Newton iteration: the force
    /// and the eight coefficients are the same, bit for bit; the result's other fields (the
    /// outputs: p_max, ζ1, ζ2, friction, flows) may be left unset (zero) and are then given, for
    /// the last solve, by [`FilmModel::completed_result`]. By default the whole solve.
    fn solve_lean(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<(FilmResult, FilmCoefficients), FilmError> {
        self.solve_with_coefficients(kin)
    }

    /// The whole result of the last solve when that was a [`FilmModel::solve_lean`] that left
    /// fields unset (as `solve_with_coefficients` would have given it, bit for bit); `None` when
    /// the last solve's result was whole.
    fn completed_result(&self) -> Option<FilmResult> {
        None
    }

    /// The eight coefficients for a constant-coefficient (linearised) analysis about `kin`: the
    /// seed's "classical" description, the stability threshold. By default those of
    /// [`FilmModel::solve_with_coefficients`]; a grid-based model may return a better estimate of
    /// the continuous film's derivatives (see [`FiniteFilm`]). Leaves the model as a solve at
    /// `kin` would.
    fn linearised_coefficients(
        &mut self,
        kin: &JournalKinematics,
    ) -> Result<FilmCoefficients, FilmError> {
        self.solve_with_coefficients(kin).map(|(_, c)| c)
    }

    /// The mid-plane pressure of the last solve at `out.len()` equally spaced angles
    /// θ_k = 2πk/len from `+x` (Pa). Allocates nothing.
    fn midplane_pressure(&self, out: &mut [f64]);

    /// The mid-plane fluid fraction φ of the last solve at `out.len()` equally spaced angles
    /// from `+x` (1 where the film is whole; 1 everywhere for a film without memory).
    fn midplane_fluid_fraction(&self, out: &mut [f64]) {
        out.fill(1.0);
    }

    /// Where a mass-conserving plain bearing is fed (rad from `+x`; its feed line, fixed in a
    /// transient where it was at the start), or None (no such film, or a grooved bearing, whose
    /// grooves are its feed).
    fn feed_angle_rad(&self) -> Option<f64> {
        None
    }

    /// Sets a viscosity field around the film: µ(ζ_i)/µ per grid column, relative to the
    /// film's uniform viscosity (the thermal film's field, issue 18; an empty slice restores
    /// the uniform film). Ok(false) where the film holds only a uniform viscosity (the tables,
    /// the short film): it then runs at that viscosity. Err if the field does not fit the grid.
    fn set_viscosity_field(&mut self, _ratio: &[f64]) -> Result<bool, FilmError> {
        Ok(false)
    }

    /// The viscosity scale s = µ/µ₀ its [`ViscosityScaledFilm`] applies, for a film whose flow
    /// depends on the Reynolds number: it then takes Re = ρωRc/(µ₀·s), so that scaling its
    /// outputs by s is exact (the turbulent film: its conductances depend on Re, the rest of
    /// its Π form does not depend on µ). No-op for a laminar film, whose Π does not depend on µ.
    fn set_reynolds_viscosity_scale(&mut self, _scale: f64) {}

    /// A film with memory (mass-conserving cavitation, issue 18): the next solves belong to a
    /// time step of `step_s` (s) that starts from the last committed state. No-op otherwise.
    fn begin_step(&mut self, _step_s: f64) {}

    /// Accepts the last solve as the state the next time step starts from. No-op without memory.
    fn commit_step(&mut self) {}

    /// Saves the committed state (before a step that may be retried). No-op without memory.
    fn save_memory(&mut self) {}

    /// Returns to the state of the last [`FilmModel::save_memory`]. No-op without memory.
    fn restore_memory(&mut self) {}

    /// A film with memory: its committed fluid fraction φ⁰ and the full nodes of its last solve
    /// (to record a state); `None` without memory.
    fn memory(&self) -> Option<(Vec<f64>, Vec<bool>)> {
        None
    }

    /// Sets what [`FilmModel::memory`] gives (a recorded state, once a step has begun); an
    /// error without memory or on a size mismatch.
    fn set_memory(&mut self, _phi0: &[f64], _full: &[bool]) -> Result<(), FilmError> {
        Err(FilmError::InvalidParameter {
            name: "film memory",
            value: 0.0,
            rule: "only a mass-conserving film in a time step has one",
        })
    }
}

/// Wraps an angle (rad) to [0, 2π).
pub fn wrap_angle_rad(angle: f64) -> f64 {
    use std::f64::consts::TAU;
    // within a turn (atan2's angles and their sums: the film's every call) the remainder is the
    // angle itself (fmod is exact): rem_euclid without its library call, the same result
    let a = if angle.abs() < TAU {
        if angle < 0.0 {
            angle + TAU
        } else {
            angle
        }
    } else {
        angle.rem_euclid(TAU)
    };
    if a >= TAU {
        0.0
    } else {
        a
    }
}
