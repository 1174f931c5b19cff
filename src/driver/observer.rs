//! A nudging observer (issue 12, session 14): the running nonlinear twin's motion drawn toward
//! the measured probe orbits by a virtual spring and damper at each probe station, so that its
//! free (sub-synchronous) whirl follows the plant's instead of growing from its own history.
//!
//! Newtonian relaxation ("nudging", Hoke & Anthes, Mon. Wea. Rev. 104, 1976) with the
//! relaxation term as a force, as a Luenberger observer with output injection:
//! F_k = k_obs r_k + c_obs ṙ_k at station k's shaft node, r_k = x_measured − x_twin (m) the
//! probe residual at the sample's time. ṙ is the derivative of the residual after a one-pole
//! low-pass at `cutoff_hz` (the probes' noise differentiated unfiltered would dominate). The
//! force is held from one sample to the next. Off by default; with the observer on, the twin is
//! an estimator, not an open-loop prediction: a prediction runs from its state with the
//! observer off ([`super::Driver::set_observer`]).

/// The observer's gains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObserverGains {
    /// Virtual spring between the twin and the measured motion at each probe station (N/m).
    pub stiffness_n_m: f64,
    /// Virtual damper on the residual's rate (N·s/m).
    pub damping_n_s_m: f64,
    /// Cutoff of the residual's low-pass before its rate is taken (Hz).
    pub cutoff_hz: f64,
}

impl ObserverGains {
    /// Refuses gains that are negative or not finite, or a cutoff that is not positive.
    pub fn check(&self) -> Result<(), String> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !(ok(self.stiffness_n_m) && ok(self.damping_n_s_m)) {
            return Err(format!("observer gains must be finite and ≥ 0: {self:?}"));
        }
        if !(self.cutoff_hz.is_finite() && self.cutoff_hz > 0.0) {
            return Err(format!("observer cutoff must be positive: {self:?}"));
        }
        Ok(())
    }
}

/// One station's filtered residual.
#[derive(Debug, Clone, Copy, Default)]
struct StationFilter {
    /// low-passed residual (m)
    r: [f64; 2],
    /// its rate (m/s)
    rate: [f64; 2],
    /// time of the last sample (s of twin time)
    t_s: Option<f64>,
}

/// The observer's state: its gains and each probe station's filter (sized once).
#[derive(Debug, Clone)]
pub(super) struct Observer {
    pub(super) gains: ObserverGains,
    stations: Vec<StationFilter>,
}

impl Observer {
    pub(super) fn new(gains: ObserverGains, stations: usize) -> Self {
        Self {
            gains,
            stations: vec![StationFilter::default(); stations],
        }
    }

    /// Forgets the residuals (a restarted twin).
    pub(super) fn reset(&mut self) {
        self.stations.fill(StationFilter::default());
    }

    /// Takes station `k`'s residual `r_m` (measured − twin, m) at `t_s` (s); returns the force
    /// (N) to hold at its node until its next sample. A sample not later than the last one
    /// leaves the filter as it is.
    pub(super) fn update(&mut self, k: usize, r_m: [f64; 2], t_s: f64) -> [f64; 2] {
        let Some(f) = self.stations.get_mut(k) else {
            return [0.0; 2];
        };
        match f.t_s {
            None => {
                f.r = r_m;
                f.t_s = Some(t_s);
            }
            Some(t0) if t_s > t0 => {
                let dt = t_s - t0;
                let a = 1.0 - (-std::f64::consts::TAU * self.gains.cutoff_hz * dt).exp();
                for j in 0..2 {
                    let next = f.r[j] + a * (r_m[j] - f.r[j]);
                    f.rate[j] = (next - f.r[j]) / dt;
                    f.r[j] = next;
                }
                f.t_s = Some(t_s);
            }
            Some(_) => {}
        }
        let g = self.gains;
        [0, 1].map(|j| g.stiffness_n_m * f.r[j] + g.damping_n_s_m * f.rate[j])
    }
}

impl super::Driver {
    /// Turns the nudging observer on with `gains`, or off (None): off, the forces it holds on
    /// the running twin are taken away at once. Off by default.
    pub fn set_observer(&mut self, gains: Option<ObserverGains>) -> Result<(), String> {
        if let Some(g) = gains {
            g.check()?;
            self.observer = Some(Observer::new(g, self.rotor.probes.len()));
            return Ok(());
        }
        self.observer = None;
        if let Some(s) = self.session.as_mut() {
            for p in &self.rotor.probes {
                s.twin_mut()
                    .set_external_force(p.node, [0.0; 2])
                    .map_err(|e| format!("observer: {e}"))?;
            }
        }
        Ok(())
    }

    /// The observer's gains, when it is on.
    pub fn observer(&self) -> Option<ObserverGains> {
        self.observer.as_ref().map(|o| o.gains)
    }

    /// A compared sample of station `k`: its residual `r_m` (measured − twin, m) at `t_s` (s of
    /// twin time) moves the observer's force at the station's node.
    pub(super) fn observe(&mut self, k: usize, r_m: [f64; 2], t_s: f64) {
        let (Some(o), Some(s)) = (self.observer.as_mut(), self.session.as_mut()) else {
            return;
        };
        let Some(p) = self.rotor.probes.get(k) else {
            return;
        };
        let f = o.update(k, r_m, t_s);
        // the node is the machine's own probe station's: cannot fail
        let _ = s.twin_mut().set_external_force(p.node, f);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A residual growing linearly at 1 µm/s, sampled every 0.1 ms through a 1 kHz low-pass:
    /// after 20 time constants the filtered rate is the residual's, 1e-6 m/s (to 1e-12), and the
    /// force c·ṙ + k·r_f with the filter's lag 1/(2π·1 kHz) behind r.
    #[test]
    fn the_force_is_the_spring_and_damper_on_the_filtered_residual() {
        let g = ObserverGains {
            stiffness_n_m: 2.0e6,
            damping_n_s_m: 300.0,
            cutoff_hz: 1000.0,
        };
        let mut o = Observer::new(g, 1);
        let mut f = [0.0; 2];
        let dt = 1e-4;
        for i in 0..2000 {
            let t = i as f64 * dt;
            f = o.update(0, [1e-6 * t, 0.0], t);
        }
        let t = 1999.0 * dt;
        // the one-pole filter of a ramp lags it by its time constant τ' (discrete: dt·(1−a)/a)
        let a = 1.0 - (-std::f64::consts::TAU * 1000.0 * dt).exp();
        let lag = dt * (1.0 - a) / a;
        let want = 2.0e6 * 1e-6 * (t - lag) + 300.0 * 1e-6;
        assert!((f[0] - want).abs() < 1e-9, "{f:?} against {want}");
        assert_eq!(f[1], 0.0);
        assert!(g.check().is_ok());
        assert!(ObserverGains {
            cutoff_hz: 0.0,
            ..g
        }
        .check()
        .is_err());
        assert!(ObserverGains {
            damping_n_s_m: -1.0,
            ..g
        }
        .check()
        .is_err());
    }
}
