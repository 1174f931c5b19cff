//! The oil in the live twin (issue 12): each film bearing's viscosity from the oil supply
//! temperature in force through its own viscosity–temperature law, and, with `oil_heating` in
//! the machine file, at its own effective temperature (`Rotor::heat_films`, Raimondi–Boyd's
//! adiabatic heat balance (H1)–(H2) of `film::heating`).
//!
//! The heat balance is not redone per step: only when the speed in force has moved by more than
//! [`HEAT_BALANCE_SPEED_STEP`] or the supply temperature by more than
//! [`HEAT_BALANCE_TEMPERATURE_STEP_K`] since the last one (and at the first speed). Between two
//! balances each film keeps its scale; the step itself only reads the scale (allocates nothing).

use super::heat_worker::{balance, FilmHeat, HeatJob, HeatWorker};
use super::{inputs, Driver, Fed};

/// The heat balance is redone when the speed has moved by more than this fraction since the
/// last one: 1 % (90 rpm at 9,000 rpm) moves the seed case's T_eff by about 0.02 K (ΔT grows
/// 0.36 K from 8,000 to 9,000 rpm, T_eff by half of it), µ by 0.02 %.
pub const HEAT_BALANCE_SPEED_STEP: f64 = 0.01;

/// Whether a speed `speed_rad_s` has moved past [`HEAT_BALANCE_SPEED_STEP`] from the speed of
/// the last balance, `balanced_rad_s`: the rule the live twin and the offline runs
/// (`transient::HeatFollower`) both redo a balance by.
pub fn speed_moved_past_balance(balanced_rad_s: f64, speed_rad_s: f64) -> bool {
    (speed_rad_s / balanced_rad_s - 1.0).abs() > HEAT_BALANCE_SPEED_STEP
}

/// … or when the supply temperature has moved by more than this (K): 0.05 K is 0.05 % of µ on
/// the built-in law (about −1 %/K).
pub const HEAT_BALANCE_TEMPERATURE_STEP_K: f64 = 0.05;

/// The oil state the driver keeps, per film bearing (in the order of the film bearings).
#[derive(Debug, Default)]
pub(super) struct OilState {
    /// µ_i(T_s) / µ_reference,i of the supply temperature in force (1 before one is received:
    /// the machine file's viscosity)
    law_scales: Vec<f64>,
    /// the scales of a temperature being checked
    scratch: Vec<f64>,
    /// the scale in force: the heated or the law's, times the calibration's correction
    scales: Vec<f64>,
    /// the last heat balance: (T_eff K, µ(T_eff) / µ_reference) where the bearing is heated
    heated: Vec<Option<(f64, f64)>>,
    /// (speed rad/s, supply temperature K; None: the law's design one) of the last heat balance
    balanced_at: Option<(f64, Option<f64>)>,
    /// why the last heat balance failed, if it did (the scales before it stay in force)
    heating_error: Option<String>,
    /// heat balances done
    balances: u64,
    /// heat balances that failed (or whose scales the film refused), and the last one's reason
    failures: u64,
    last_failure: Option<String>,
    /// whether any film bearing models its own heating
    heating: bool,
    /// the thread the balances run on, when off the model thread (`heat_worker`)
    worker: Option<HeatWorker>,
}

impl OilState {
    /// The state of `rotor`'s film bearings at the machine file's viscosity; their heat
    /// balances on a worker thread when `settings` say so and a bearing is heated (on the
    /// caller's thread if that thread cannot be started).
    pub(super) fn of(rotor: &crate::rotor::Rotor, settings: &super::DriverSettings) -> Self {
        let n = rotor.film_bearing_count();
        let heating = rotor.has_oil_heating();
        let worker = (heating && settings.heat_balance_off_thread)
            .then(|| HeatWorker::start(rotor, settings.twin.film).ok())
            .flatten();
        Self {
            law_scales: vec![1.0; n],
            scratch: vec![1.0; n],
            scales: vec![1.0; n],
            heated: vec![None; n],
            heating,
            worker,
            ..Self::default()
        }
    }
}

impl OilState {
    /// A finished heat balance counted and kept (a failure keeps the scales of the last good
    /// one in force, `push_oil_scales`); true when it succeeded.
    fn take_balance(&mut self, result: &Result<Vec<FilmHeat>, String>) -> bool {
        self.balances += 1;
        match result {
            Ok(films) => {
                for f in films {
                    self.heated[f.film] = Some((f.temperature_k, f.scale));
                }
                self.heating_error = None;
                true
            }
            Err(e) => {
                self.failed(e.clone());
                false
            }
        }
    }

    /// A heat balance failed for `why`: counted, kept as the last failure and as the reason
    /// in force until a balance succeeds.
    fn failed(&mut self, why: String) {
        self.failures += 1;
        self.last_failure = Some(why.clone());
        self.heating_error = Some(why);
    }
}

/// One film bearing's oil as the driver holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmOil {
    /// The bearing's name.
    pub name: String,
    /// Its viscosity scale in force (µ / µ_reference of the machine file).
    pub viscosity_scale: f64,
    /// Its effective temperature at the last heat balance (K), where it is heated.
    pub effective_temperature_k: Option<f64>,
}

/// The bearings' heat balances over a run (issue 12): each failure left the last good
/// viscosity in force.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HeatBalanceReport {
    /// Heat balances done.
    pub balances: u64,
    /// Those that failed.
    pub failures: u64,
    /// Why the last failure failed (None without one).
    pub last_failure: Option<String>,
    /// Each heated film bearing at the end: its temperature (°C) and viscosity scale in force.
    pub films: Vec<HeatedFilm>,
}

/// A heated film bearing in [`HeatBalanceReport`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HeatedFilm {
    /// The bearing's name.
    pub bearing: String,
    /// Its temperature at the last good balance (°C): Raimondi–Boyd's effective temperature or
    /// the thermal film's mean.
    pub temperature_c: f64,
    /// Its viscosity scale in force (µ / µ_reference, with any calibration's factor).
    pub viscosity_scale: f64,
}

/// The oil's diagnostic values ([`Driver::oil_diagnostics`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OilDiagnostics {
    /// (key, value) pairs, in order.
    pub values: Vec<(String, String)>,
    /// Why the model status warns, while the last heat balance has failed.
    pub warning: Option<String>,
}

impl Driver {
    /// An oil supply temperature (K): each film's scale through its own law (or its effective
    /// temperature when heated), applied to the running twin and kept for later starts; a
    /// refused one leaves the last good value in force.
    pub(super) fn take_oil_temperature(&mut self, t_k: f64) -> Fed {
        let mut scratch = std::mem::take(&mut self.oil.scratch);
        let checked = inputs::oil_viscosity_scales(&self.rotor, t_k, &mut scratch).and_then(|()| {
            // a calibrated viscosity in force is a factor on the law: it follows the temperature
            let k = self.viscosity_correction.unwrap_or(1.0);
            match scratch
                .iter()
                .find_map(|s| crate::film::check_viscosity_scale(s * k).err())
            {
                Some(e) => Err(format!("oil temperature with the calibration: {e}")),
                None => Ok(()),
            }
        });
        if let Err(why) = checked {
            self.oil.scratch = scratch;
            return Fed::Refused(why);
        }
        self.oil.law_scales.copy_from_slice(&scratch);
        self.oil.scratch = scratch;
        self.oil_scale = self.oil.law_scales.first().copied();
        self.oil_temperature_k = Some(t_k);
        self.heat_if_due();
        match self.push_oil_scales() {
            Ok(()) => Fed::Taken,
            Err(why) => Fed::Refused(why),
        }
    }

    /// After an accepted speed: the heat balance redone if it is due, and the scales applied.
    pub(super) fn follow_speed_heating(&mut self) {
        if self.oil.heating && self.heat_if_due() {
            if let Err(why) = self.push_oil_scales() {
                self.oil.failed(why);
            }
        }
    }

    /// Redoes the heat balance when the speed or the supply temperature has moved past its step
    /// since the last one (module documentation); true when it was redone.
    fn heat_if_due(&mut self) -> bool {
        if !self.oil.heating {
            return false;
        }
        let Some(speed) = self.speed.as_ref().map(|s| s.speed_rad_s) else {
            return false;
        };
        if speed < self.settings.min_speed_rad_s {
            return false;
        }
        let supply = self.oil_temperature_k;
        if let Some((w0, t0)) = self.oil.balanced_at {
            let moved_t = match (supply, t0) {
                (Some(a), Some(b)) => (a - b).abs() > HEAT_BALANCE_TEMPERATURE_STEP_K,
                (None, None) => false,
                _ => true,
            };
            if !speed_moved_past_balance(w0, speed) && !moved_t {
                return false;
            }
        }
        self.oil.balanced_at = Some((speed, supply));
        let job = HeatJob {
            supply_k: supply,
            speed_rad_s: speed,
        };
        if let Some(w) = self.oil.worker.as_mut() {
            // taken by `take_finished_heat` at a later wake
            if let Err(why) = w.request(job) {
                self.oil.failed(why);
            }
            return false;
        }
        let result = balance(&mut self.rotor, job, self.settings.twin.film);
        if self.oil.take_balance(&result) {
            self.push_viscosity_fields();
        }
        true
    }

    /// A balance the worker has finished since the last wake, if any: its scales applied.
    pub(super) fn take_finished_heat(&mut self) {
        let Some(result) = self.oil.worker.as_mut().and_then(HeatWorker::finished) else {
            return;
        };
        // the worker set the scales and fields on its own copy of the machine: the fields are
        // set on this one here, the scales by `push_oil_scales`
        if let Ok(films) = &result {
            for f in films {
                self.rotor.set_film_viscosity_field(f.film, &f.field);
            }
        }
        if self.oil.take_balance(&result) {
            self.push_viscosity_fields();
            if let Err(why) = self.push_oil_scales() {
                self.oil.failed(why);
            }
        }
    }

    /// After a good balance: the machine's viscosity fields (a thermal-film balance's) on the
    /// running twin, whose finite films run them (a table keeps its uniform scale). A field the
    /// twin refuses fails the balance, the last good fields staying in force.
    fn push_viscosity_fields(&mut self) {
        let Some(s) = self.session.as_mut() else {
            return;
        };
        let fields = self.rotor.film_viscosity_fields();
        if let Err(e) = s.twin_mut().set_viscosity_fields(&fields) {
            self.oil.failed(format!("oil heating: {e}"));
        }
    }

    /// Whether a heat balance is running or waiting on the worker thread.
    pub fn heat_balance_pending(&self) -> bool {
        self.oil.worker.as_ref().is_some_and(HeatWorker::busy)
    }

    /// Sets the scales in force (heated or law, × the calibration's correction) on the machine
    /// and the running twin.
    fn push_oil_scales(&mut self) -> Result<(), String> {
        let k = self.viscosity_correction.unwrap_or(1.0);
        for ((s, law), heated) in self
            .oil
            .scales
            .iter_mut()
            .zip(&self.oil.law_scales)
            .zip(&self.oil.heated)
        {
            *s = heated.map_or(*law, |(_, h)| h) * k;
        }
        self.rotor
            .set_film_viscosity_scales(&self.oil.scales)
            .map_err(|e| format!("oil temperature: {e}"))?;
        // a calibration blending into the running twin takes the new scales as its target
        // (`blend_targets`, next step); set here they would jump the twin there and back
        if let Some(s) = self.session.as_mut().filter(|_| self.blend.is_none()) {
            s.twin_mut()
                .set_viscosity_scales(&self.oil.scales)
                .map_err(|e| format!("oil temperature: {e}"))?;
        }
        Ok(())
    }

    /// The last accepted oil supply temperature (K), if any.
    pub fn oil_temperature_k(&self) -> Option<f64> {
        self.oil_temperature_k
    }

    /// The viscosity scale in force of the first film bearing (µ / µ_reference of the machine
    /// file); each bearing's: [`Self::film_oil`].
    pub fn viscosity_scale(&self) -> f64 {
        self.rotor.viscosity_scale()
    }

    /// Each film bearing's oil: its scale in force and, when heated, its effective temperature.
    pub fn film_oil(&self) -> Vec<FilmOil> {
        let films = self.rotor.bearings.iter().filter_map(|b| match &b.model {
            crate::rotor::BearingModel::Film(f) => Some((b, f)),
            _ => None,
        });
        films
            .zip(&self.oil.heated)
            .map(|((b, f), h)| FilmOil {
                name: b.name.clone(),
                viscosity_scale: f.viscosity_scale,
                effective_temperature_k: h.map(|(t, _)| t),
            })
            .collect()
    }

    /// Heat balances done, and why the last one failed if it did.
    pub fn heat_balances(&self) -> (u64, Option<&str>) {
        (self.oil.balances, self.oil.heating_error.as_deref())
    }

    /// Heat balances that failed since the start (no convergence, an effective temperature
    /// beyond the viscosity law's range, a scale the film refuses): each leaves the last good
    /// viscosity in force (the law's at the supply temperature before any good balance).
    pub fn heat_balance_failures(&self) -> u64 {
        self.oil.failures
    }

    /// The heat balances as a replay reports them: None when no film bearing is heated.
    pub fn heat_balance_report(&self) -> Option<HeatBalanceReport> {
        let films = (self.film_oil().into_iter())
            .filter_map(|f| {
                f.effective_temperature_k.map(|t| HeatedFilm {
                    bearing: f.name,
                    temperature_c: t - crate::film::ZERO_CELSIUS_K,
                    viscosity_scale: f.viscosity_scale,
                })
            })
            .collect();
        self.oil.heating.then(|| HeatBalanceReport {
            balances: self.oil.balances,
            failures: self.oil.failures,
            last_failure: self.oil.last_failure.clone(),
            films,
        })
    }

    /// The oil in force as the node's model status carries it (issue 12): the supply
    /// temperature once one is received, each film bearing's viscosity scale and, with
    /// `oil_heating`, its effective temperature, the heat balances done and failed and why the
    /// last one failed; `warning` while the last heat balance has failed (the last good viscosity
    /// in force). Keys and values as diagnostic_msgs/KeyValue holds them.
    pub fn oil_diagnostics(&self) -> OilDiagnostics {
        let c = |k: f64| k - crate::film::ZERO_CELSIUS_K;
        let mut values = Vec::new();
        if let Some(t) = self.oil_temperature_k {
            values.push(("oil_supply_temperature_c".into(), format!("{:.2}", c(t))));
        }
        for f in self.film_oil() {
            let name = &f.name;
            let scale = format!("{:.5}", f.viscosity_scale);
            values.push((format!("viscosity_scale {name}"), scale));
            if let Some(t) = f.effective_temperature_k {
                values.push((
                    format!("effective_temperature_c {name}"),
                    format!("{:.3}", c(t)),
                ));
            }
        }
        let mut warning = None;
        if self.oil.heating {
            values.push(("heat_balances".into(), self.oil.balances.to_string()));
            values.push((
                "heat_balance_failures".into(),
                self.oil.failures.to_string(),
            ));
            if let Some(why) = &self.oil.heating_error {
                values.push(("heat_balance_error".into(), why.clone()));
                warning = Some(format!(
                    "heat balance failed ({} so far): {why}; the last good viscosity stays in force",
                    self.oil.failures
                ));
            }
        }
        OilDiagnostics { values, warning }
    }
}
