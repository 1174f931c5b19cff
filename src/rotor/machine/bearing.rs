//! A bearing entry of the machine file: read as written ([`RawBearingSpec`], every field optional
//! so that serde's errors name the exact field), then parsed once into [`BearingSpec`], one
//! variant per model, whose contents are already checked (parse, don't validate): what the rotor
//! assembly reads cannot be missing or out of range.

use super::rules::Rules;
use super::LubricantSpec;
use crate::film::{
    matrix2, BearingGeometry, FilmCoefficients, FilmGrid, FluidInertia, Lubricant, ViscosityLaw,
};
use crate::rotor::ConfigError;
use nalgebra::Matrix2;
use serde::{Deserialize, Serialize};

/// A film bearing at most this many diameters long (the film model's own bound).
const MAX_BEARING_LENGTH_DIAMETERS: f64 = 10.0;
/// Largest radial clearance, as a fraction of the journal diameter (5 % of the radius).
const MAX_CLEARANCE_PER_DIAMETER: f64 = 0.025;
/// Angular width of each supply groove of a `two-axial` bearing (deg).
const AXIAL_GROOVE_WIDTH_DEG: f64 = 20.0;

/// How a bearing is modelled, as the machine file's `model` names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum BearingModelName {
    Finite,
    Short,
    Linear,
    Rigid,
}

/// Supply grooves of a film bearing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GroovesSpec {
    /// Plain 360° bearing.
    #[default]
    None,
    /// Two axial grooves, 90° either side of the static load.
    TwoAxial,
}

/// A bearing entry as written in the file; [`RawBearingSpec::parse`] turns it into a
/// [`BearingSpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBearingSpec {
    /// Name (also the ROS frame suffix).
    pub name: String,
    /// Shaft node at the journal centre.
    pub node: usize,
    /// How it is modelled: `finite`, `short`, `linear` or `rigid`.
    model: BearingModelName,
    /// Film bearings: journal diameter D (m).
    #[serde(default)]
    diameter_m: Option<f64>,
    /// Film bearings: length L (m).
    #[serde(default)]
    length_m: Option<f64>,
    /// Film bearings: radial clearance c (m).
    #[serde(default)]
    radial_clearance_m: Option<f64>,
    /// Film bearings: lubricant.
    #[serde(default)]
    lubricant: Option<LubricantSpec>,
    /// Film bearings: grid over the half bearing, `NTHxNZ` (default 60x10).
    #[serde(default)]
    grid: Option<String>,
    /// Finite film bearings: supply grooves.
    #[serde(default)]
    grooves: GroovesSpec,
    /// Linear bearings: `[[kxx, kxy], [kyx, kyy]]` (N/m).
    #[serde(default)]
    stiffness_n_per_m: Option<[[f64; 2]; 2]>,
    /// Linear bearings: `[[cxx, cxy], [cyx, cyy]]` (N·s/m); zero if absent.
    #[serde(default)]
    damping_n_s_per_m: Option<[[f64; 2]; 2]>,
    /// Linear bearings: added mass `[[mxx, mxy], [myx, myy]]` (kg), weightless (a film's fluid
    /// inertia, as bearing codes give it beside K and C); zero if absent.
    #[serde(default)]
    added_mass_kg: Option<[[f64; 2]; 2]>,
    /// Film bearings: `none` (default, the seed's model) or `temporal`, the film's temporal
    /// fluid inertia as added-mass coefficients ([`crate::film::FilmInertia`]).
    #[serde(default)]
    fluid_inertia: FluidInertia,
    /// Film bearings: `laminar` (default), `turbulent` or `auto` (`src/film/turbulence.rs`).
    #[serde(default)]
    flow: Option<crate::film::FlowRegime>,
    /// Flexible support under the bearing (the seed's C_mn, D_mn); rigid if absent.
    #[serde(default)]
    support: Option<SupportSpec>,
}

/// A bearing at a shaft node, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct BearingSpec {
    /// Name (also the ROS frame suffix).
    pub name: String,
    /// Shaft node at the journal centre.
    pub node: usize,
    /// The model and its data.
    pub model: BearingModelSpec,
    /// Flexible support under the bearing; rigid to the ground if absent (never under a
    /// rigid bearing).
    pub support: Option<SupportSpec>,
}

/// One variant per bearing model, each with exactly the data it needs.
#[derive(Debug, Clone, PartialEq)]
pub enum BearingModelSpec {
    /// Fluid film, finite-length Reynolds equation (seed eq. 2), plain or grooved.
    Finite(FilmSpec),
    /// Fluid film, short-bearing (Ocvirk) closed form; plain only.
    Short(FilmSpec),
    /// Constant stiffness and damping.
    Linear(FilmCoefficients),
    /// Rigid: the journal cannot move (a pinned support).
    Rigid,
}

/// A fluid-film bearing's checked data.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmSpec {
    /// Diameter, length, clearance and grooves (each checked by `BearingGeometry`).
    pub geometry: BearingGeometry,
    /// The lubricant at its design supply temperature.
    pub lubricant: Lubricant,
    /// The oil's viscosity–temperature law, when the file gives one (checked against
    /// `lubricant` at the design supply temperature).
    pub viscosity_law: Option<ViscosityLaw>,
    /// The law's design supply temperature (K), with the law.
    pub design_supply_temperature_k: Option<f64>,
    /// The bearing's own heating by an effective temperature, if the file asks for it.
    pub heating: Option<crate::film::OilHeating>,
    /// Finite-volume grid over the half bearing.
    pub grid: FilmGrid,
    /// Whether the film carries its fluid inertia (added mass).
    pub fluid_inertia: FluidInertia,
    /// Laminar, turbulent or auto (finite model only).
    pub flow: crate::film::FlowRegime,
}

/// A pedestal: a mass on a spring–damper to the ground, carrying the bearing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupportSpec {
    /// Pedestal mass (kg), greater than zero.
    pub mass_kg: f64,
    /// `[[kxx, kxy], [kyx, kyy]]` to the ground (N/m).
    #[serde(with = "crate::film::rows")]
    pub stiffness_n_per_m: Matrix2<f64>,
    /// `[[cxx, cxy], [cyx, cyy]]` to the ground (N·s/m).
    #[serde(default, with = "crate::film::rows")]
    pub damping_n_s_per_m: Matrix2<f64>,
}

impl BearingSpec {
    /// The film data of a film bearing (finite or short).
    pub fn film(&self) -> Option<&FilmSpec> {
        match &self.model {
            BearingModelSpec::Finite(f) | BearingModelSpec::Short(f) => Some(f),
            BearingModelSpec::Linear(_) | BearingModelSpec::Rigid => None,
        }
    }
}

impl RawBearingSpec {
    /// The lubricant as written, of a film bearing.
    pub(super) fn film_lubricant(&self) -> Option<LubricantSpec> {
        match self.model {
            BearingModelName::Finite | BearingModelName::Short => self.lubricant.clone(),
            BearingModelName::Linear | BearingModelName::Rigid => None,
        }
    }

    /// Entry `i` of `bearings`, parsed: every field its model needs present and valid, none it
    /// cannot use.
    pub(super) fn parse(self, i: usize, rules: &Rules) -> Result<BearingSpec, ConfigError> {
        let field = |name: &str| format!("bearings[{i}].{name}");
        self.refuse_fields_of_other_models(i, rules)?;
        let model = match self.model {
            BearingModelName::Finite => BearingModelSpec::Finite(self.film(i, rules)?),
            BearingModelName::Short => {
                if self.grooves != GroovesSpec::None {
                    return Err(rules.error(
                        field("grooves"),
                        "two-axial",
                        "the short-bearing model has no grooves",
                    ));
                }
                BearingModelSpec::Short(self.film(i, rules)?)
            }
            BearingModelName::Linear => BearingModelSpec::Linear(self.linear(i, rules)?),
            BearingModelName::Rigid => {
                if self.support.is_some() {
                    return Err(rules.error(
                        field("support"),
                        "(given)",
                        "a rigid bearing has no flexible support",
                    ));
                }
                BearingModelSpec::Rigid
            }
        };
        if let Some(s) = &self.support {
            rules.positive(field("support.mass_kg"), s.mass_kg)?;
            rules.finite_matrix(field("support.stiffness_n_per_m"), &s.stiffness_n_per_m)?;
            rules.finite_matrix(field("support.damping_n_s_per_m"), &s.damping_n_s_per_m)?;
        }
        Ok(BearingSpec {
            name: self.name,
            node: self.node,
            model,
            support: self.support,
        })
    }

    /// The inertia fields of the other kind of bearing: refused, not ignored.
    fn refuse_fields_of_other_models(&self, i: usize, rules: &Rules) -> Result<(), ConfigError> {
        let film = matches!(
            self.model,
            BearingModelName::Finite | BearingModelName::Short
        );
        if film && self.added_mass_kg.is_some() {
            return Err(rules.error(
                format!("bearings[{i}].added_mass_kg"),
                "(given)",
                "is for linear bearings; a film bearing's comes from `fluid_inertia: temporal`",
            ));
        }
        if self
            .flow
            .is_some_and(|f| f != crate::film::FlowRegime::Laminar)
            && self.model != BearingModelName::Finite
        {
            return Err(rules.error(
                format!("bearings[{i}].flow"),
                format!("{:?}", self.flow.unwrap_or_default()),
                "turbulent flow is built in the finite film model only (model: finite)",
            ));
        }
        if !film && self.fluid_inertia != FluidInertia::None {
            return Err(rules.error(
                format!("bearings[{i}].fluid_inertia"),
                "temporal",
                "is for film bearings; give a linear bearing its `added_mass_kg`",
            ));
        }
        Ok(())
    }

    /// The film data of entry `i`.
    fn film(&self, i: usize, rules: &Rules) -> Result<FilmSpec, ConfigError> {
        let field = |name: &str| format!("bearings[{i}].{name}");
        let required = |name: &str, v: Option<f64>| {
            let v = v.ok_or_else(|| {
                rules.error(field(name), "(missing)", "is required for a film bearing")
            })?;
            rules.positive(field(name), v).map(|_| v)
        };
        let d = required("diameter_m", self.diameter_m)?;
        let l = required("length_m", self.length_m)?;
        let c = required("radial_clearance_m", self.radial_clearance_m)?;
        if l > MAX_BEARING_LENGTH_DIAMETERS * d {
            return Err(rules.error(
                field("length_m"),
                l,
                format!("must not exceed {MAX_BEARING_LENGTH_DIAMETERS} diameters (diameter_m = {d}): beyond it the film model does not hold"),
            ));
        }
        if c > MAX_CLEARANCE_PER_DIAMETER * d {
            return Err(rules.error(
                field("radial_clearance_m"),
                c,
                "must be below 5 % of the journal radius",
            ));
        }
        let geometry = match self.grooves {
            GroovesSpec::None => BearingGeometry::plain(d, l, c),
            GroovesSpec::TwoAxial => BearingGeometry::two_axial_grooves(
                d,
                l,
                c,
                AXIAL_GROOVE_WIDTH_DEG.to_radians(),
                0.0,
            ),
        }
        .map_err(|e| rules.error(field("(geometry)"), format!("D {d}, L {l}, c {c}"), e))?;
        let grid = match &self.grid {
            Some(g) => FilmGrid::parse(g).map_err(|e| rules.error(field("grid"), g, e))?,
            None => FilmGrid::default(),
        };
        let (lubricant, viscosity_law) = self.oil(i, rules)?;
        let spec = self.lubricant.as_ref();
        let heating = match spec.and_then(|l| l.oil_heating.map(|h| (l, h))) {
            Some((l, h)) => Some(h.checked(l, &format!("bearings[{i}].lubricant"), rules)?),
            None => None,
        };
        if heating.is_some_and(|h| h.balance == crate::film::HeatBalance::ThermalFilm) {
            self.check_thermal_film(i, rules)?;
        }
        Ok(FilmSpec {
            geometry,
            lubricant,
            viscosity_law,
            design_supply_temperature_k: spec
                .and_then(|l| l.viscosity_temperature.as_ref())
                .map(|v| v.design_supply_temperature_c + crate::film::ZERO_CELSIUS_K),
            heating,
            grid,
            fluid_inertia: self.fluid_inertia,
            flow: self.flow.unwrap_or_default(),
        })
    }

    /// `oil_heating: {model: thermal_film}` needs the film `src/film/thermal.rs` solves: the
    /// finite, laminar film of a plain bearing (`FilmBearing::thermal_film_unsupported`).
    fn check_thermal_film(&self, i: usize, rules: &Rules) -> Result<(), ConfigError> {
        let field = format!("bearings[{i}].lubricant.oil_heating.model");
        let refuse = |given: String, rule: &str| {
            Err(rules.error(&field, format!("thermal_film with {given}"), rule))
        };
        if self.model != BearingModelName::Finite {
            return refuse(
                format!("model {:?}", self.model).to_lowercase(),
                "the thermal film is built on the finite model (model: finite)",
            );
        }
        if self.grooves != GroovesSpec::None {
            return refuse(
                "grooves two-axial".into(),
                "the thermal film is built for a plain bearing (grooves: none)",
            );
        }
        if let Some(f) = self.flow.filter(|f| *f != crate::film::FlowRegime::Laminar) {
            return refuse(
                format!("flow {f:?}").to_lowercase(),
                "the thermal film is laminar (flow: laminar)",
            );
        }
        Ok(())
    }

    /// The lubricant of entry `i`, and its viscosity–temperature law if given.
    fn oil(
        &self,
        i: usize,
        rules: &Rules,
    ) -> Result<(Lubricant, Option<ViscosityLaw>), ConfigError> {
        let field = |name: &str| format!("bearings[{i}].{name}");
        let Some(lub) = &self.lubricant else {
            return Err(rules.error(
                field("lubricant"),
                "(missing)",
                "is required for a film bearing",
            ));
        };
        rules.positive(field("lubricant.density_kg_m3"), lub.density_kg_m3)?;
        rules.positive(field("lubricant.viscosity_pa_s"), lub.viscosity_pa_s)?;
        let oil = Lubricant::new(lub.density_kg_m3, lub.viscosity_pa_s)
            .map_err(|e| rules.error(field("lubricant"), format!("{lub:?}"), e))?;
        let law = match &lub.viscosity_temperature {
            Some(spec) => Some(spec.checked_law(lub, &field("lubricant"), rules)?),
            None => None,
        };
        Ok((oil, law))
    }

    /// The constant coefficients of entry `i`.
    fn linear(&self, i: usize, rules: &Rules) -> Result<FilmCoefficients, ConfigError> {
        let field = |name: &str| format!("bearings[{i}].{name}");
        let Some(k) = self.stiffness_n_per_m else {
            return Err(rules.error(
                field("stiffness_n_per_m"),
                "(missing)",
                "is required for a linear bearing",
            ));
        };
        let k = matrix2(&k);
        rules.finite_matrix(field("stiffness_n_per_m"), &k)?;
        let c = matrix2(&self.damping_n_s_per_m.unwrap_or_default());
        rules.finite_matrix(field("damping_n_s_per_m"), &c)?;
        // a support that pushes the journal away (or holds it not at all) carries no rotor
        for d in 0..2 {
            if k[(d, d)] <= 0.0 {
                return Err(rules.error(
                    format!("bearings[{i}].stiffness_n_per_m[{d}][{d}]"),
                    k[(d, d)],
                    "a direct stiffness must be greater than zero (a linear bearing with none, or a negative one, cannot carry the rotor)",
                ));
            }
            if c[(d, d)] < 0.0 {
                return Err(rules.error(
                    format!("bearings[{i}].damping_n_s_per_m[{d}][{d}]"),
                    c[(d, d)],
                    "a direct damping must be zero or more (a negative one feeds energy into the rotor)",
                ));
            }
        }
        let m = matrix2(&self.added_mass_kg.unwrap_or_default());
        rules.finite_matrix(field("added_mass_kg"), &m)?;
        for d in 0..2 {
            if m[(d, d)] < 0.0 {
                return Err(rules.error(
                    format!("bearings[{i}].added_mass_kg[{d}][{d}]"),
                    m[(d, d)],
                    "a direct added mass must be zero or more",
                ));
            }
        }
        Ok(FilmCoefficients {
            stiffness_n_per_m: k,
            damping_n_s_per_m: c,
            added_mass_kg: m,
        })
    }
}
