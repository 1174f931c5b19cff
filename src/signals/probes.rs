//! Raw proximity probes: one scalar reading per probe along its own axis, as the transducer
//! system delivers it, turned into the shaft displacement in the machine frame.
//!
//! Conventions. A probe's angle α is measured in the machine frame from +x towards +y (the
//! direction of rotation; +y up on the shipped machines, where the usual X–Y pair, 45° either side
//! of vertical as API 670 places it, sits at 45° and 135°). The reading is the **gap** g between
//! probe tip and shaft, in m, µm, mil or V (V = sensitivity × gap; 7.87 V/mm = 200 mV/mil, the
//! usual API 670 figure, by default; a negative sensitivity, as from a −24 V driver, is allowed).
//! The shaft's displacement along the probe's axis, towards the probe, is d = g_ref − g: a DC-coupled
//! probe keeps it as the journal's position relative to where its gap is the reference gap (the
//! shaft centerline); an AC-coupled probe loses the mean, and only the dynamic part is compared.
//! Two probes at one station give the machine-frame displacement (x, y) from
//! d_j = x cos α_j + y sin α_j.

/// The unit a raw probe reading comes in (machine file: `m`, `um` or `µm`, `mil`, `V`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ProbeUnit {
    /// Metres.
    #[serde(rename = "m")]
    M,
    /// Micrometres.
    #[serde(rename = "um", alias = "µm")]
    Um,
    /// Mils (thousandths of an inch, 25.4 µm).
    #[serde(rename = "mil")]
    Mil,
    /// Volts, with a sensitivity (V/m).
    #[serde(rename = "V", alias = "v")]
    V,
}

impl std::str::FromStr for ProbeUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "m" => Ok(ProbeUnit::M),
            "um" | "µm" => Ok(ProbeUnit::Um),
            "mil" => Ok(ProbeUnit::Mil),
            "V" | "v" => Ok(ProbeUnit::V),
            other => Err(format!("'{other}' must be m, um, mil or V")),
        }
    }
}

/// The usual sensitivity of a proximity-probe system (V/m): 7.87 V/mm = 200 mV/mil (API 670).
pub const DEFAULT_SENSITIVITY_V_PER_M: f64 = 7870.0;

/// A reading in `unit` as a length (m); `sensitivity_v_per_m` is used for volts only.
pub fn reading_to_m(value: f64, unit: ProbeUnit, sensitivity_v_per_m: f64) -> f64 {
    match unit {
        ProbeUnit::M => value,
        ProbeUnit::Um => value * 1e-6,
        ProbeUnit::Mil => value * 25.4e-6,
        ProbeUnit::V => value / sensitivity_v_per_m,
    }
}

/// Largest departure from orthogonality accepted for a probe pair (degrees): 5°. Field pairs are
/// mounted at 90°; more than this is most likely a typing error in the machine file.
pub const MAX_NON_ORTHOGONALITY_DEG: f64 = 5.0;

/// Checks that two probe angles (rad) are orthogonal within [`MAX_NON_ORTHOGONALITY_DEG`].
pub fn check_orthogonal(angles_rad: [f64; 2]) -> Result<(), String> {
    let between = (angles_rad[1] - angles_rad[0])
        .to_degrees()
        .rem_euclid(180.0);
    if (between - 90.0).abs() > MAX_NON_ORTHOGONALITY_DEG {
        return Err(format!(
            "probes at {:.1}° and {:.1}° are {between:.1}° apart, not orthogonal within {MAX_NON_ORTHOGONALITY_DEG}°",
            angles_rad[0].to_degrees(),
            angles_rad[1].to_degrees()
        ));
    }
    Ok(())
}

/// The machine-frame displacement (x, y) (m) from the displacements d_j (m) along two probe axes
/// at angles α_j (rad): the solution of d_j = x cos α_j + y sin α_j (any non-parallel pair).
pub fn machine_from_probes(d_m: [f64; 2], angles_rad: [f64; 2]) -> [f64; 2] {
    let (s0, c0) = angles_rad[0].sin_cos();
    let (s1, c1) = angles_rad[1].sin_cos();
    let det = c0 * s1 - s0 * c1;
    [
        (d_m[0] * s1 - d_m[1] * s0) / det,
        (c0 * d_m[1] - c1 * d_m[0]) / det,
    ]
}

/// How a probe's signal is coupled (machine file: `ac` or `dc`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProbeCoupling {
    /// AC: the mean (the gap) is removed; only the dynamic part is compared.
    Ac,
    /// DC: the gap is kept, against the reference gap, as the journal's mean position.
    Dc,
}

impl std::str::FromStr for ProbeCoupling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim() {
            "ac" => Ok(ProbeCoupling::Ac),
            "dc" => Ok(ProbeCoupling::Dc),
            other => Err(format!("'{other}' must be ac or dc")),
        }
    }
}

/// One raw proximity probe of the machine (from the machine file's `proximity_probes`).
#[derive(Debug, Clone, PartialEq)]
pub struct RawProbe {
    /// Probe name (the ProbeSignal's `probe`).
    pub name: String,
    /// Index of its station in the machine's probe stations.
    pub station: usize,
    /// Which of the station's two axes it is (0 or 1, in the order of the file).
    pub axis: usize,
    /// Mounting angle from +x towards +y (rad).
    pub angle_rad: f64,
    /// Unit of its readings.
    pub unit: ProbeUnit,
    /// Sensitivity (V/m), for readings in volts.
    pub sensitivity_v_per_m: f64,
    /// AC or DC coupling.
    pub coupling: ProbeCoupling,
    /// Gap at the reference position (the shaft centerline) (m); DC coupling.
    pub reference_gap_m: f64,
    /// Slow-roll runout as given in the machine file (None: measured below the slow-roll speed,
    /// or none).
    pub runout: Option<super::OneXVector>,
    /// The transducer system's linear range as readings in the probe's unit, (low, high) with
    /// low < high (None: only [`MAX_GAP_M`] applies). A reading outside it is a saturated
    /// proximitor (at its supply rail), an open or shorted channel, or a shaft out of reach.
    pub linear_range: Option<(f64, f64)>,
}

impl RawProbe {
    /// The shaft displacement along the probe's axis, towards the probe (m), from a reading in
    /// the probe's unit: d = g_ref − g (for AC coupling g_ref = 0; the mean goes later).
    pub fn displacement_m(&self, value: f64) -> f64 {
        let gap = reading_to_m(value, self.unit, self.sensitivity_v_per_m);
        match self.coupling {
            ProbeCoupling::Dc => self.reference_gap_m - gap,
            ProbeCoupling::Ac => -gap,
        }
    }
}

/// Largest gap a probe reading may stand for (m): 10 mm (a proximity probe's linear range is
/// about 2 mm; more is a unit error or a saturated, open or shorted channel).
pub const MAX_GAP_M: f64 = 0.01;

/// Checks a raw reading: finite, its gap within ±[`MAX_GAP_M`], and within the probe's linear
/// range when the machine file gives one.
pub fn check_reading(p: &RawProbe, value: f64) -> Result<f64, String> {
    let gap = reading_to_m(value, p.unit, p.sensitivity_v_per_m);
    if !value.is_finite() || !gap.is_finite() || gap.abs() > MAX_GAP_M {
        return Err(format!(
            "probe '{}' reading {value} is not finite or beyond {} mm of gap (out of range or saturated)",
            p.name,
            MAX_GAP_M * 1e3
        ));
    }
    if let Some((low, high)) = p.linear_range {
        if !(low..=high).contains(&value) {
            return Err(format!(
                "probe '{}' reading {value} is outside its linear range {low} to {high} (saturated or out of range)",
                p.name
            ));
        }
    }
    Ok(p.displacement_m(value))
}

/// The runout of a probe at shaft angle ψ (rad from the keyphasor), from its slow-roll 1X
/// vector: Re(X e^{iψ}) (m).
pub fn runout_at(runout: &super::OneXVector, psi_rad: f64) -> f64 {
    let [re, im] = runout.phasor_m();
    let (s, c) = psi_rad.sin_cos();
    re * c - im * s
}

/// The slow-roll 1X vector of one probe, accumulated over whole revolutions (rectangular
/// window, exact for 1X over whole revolutions) while the shaft turns below the slow-roll speed.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SlowRoll {
    n: usize,
    sum: f64,
    sum_c: f64,
    sum_s: f64,
    sum_dc: f64,
    sum_ds: f64,
    first_psi: Option<f64>,
    last_psi: f64,
}

impl SlowRoll {
    /// Adds a displacement `d_m` (m) at shaft angle `psi_rad` (rad from the keyphasor, increasing).
    pub fn add(&mut self, psi_rad: f64, d_m: f64) {
        let (s, c) = psi_rad.sin_cos();
        self.n += 1;
        self.sum += d_m;
        self.sum_c += c;
        self.sum_s += s;
        self.sum_dc += d_m * c;
        self.sum_ds += d_m * s;
        self.first_psi.get_or_insert(psi_rad);
        self.last_psi = psi_rad;
    }

    /// Whole revolutions covered.
    pub fn revolutions(&self) -> f64 {
        self.first_psi
            .map_or(0.0, |f| (self.last_psi - f) / std::f64::consts::TAU)
    }

    /// The runout vector, once at least 2 revolutions are in: X = (2/N) Σ (d − d̄) e^{−iψ}.
    pub fn vector(&self) -> Option<super::OneXVector> {
        if self.revolutions() < 2.0 || self.n < 16 {
            return None;
        }
        let n = self.n as f64;
        let mean = self.sum / n;
        let re = 2.0 / n * (self.sum_dc - mean * self.sum_c);
        let im = -2.0 / n * (self.sum_ds - mean * self.sum_s);
        Some(super::OneXVector::from_phasor_m([re, im]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Volts to metres: 7.87 V/mm, so 1.5740 V is 200 µm and 1 mil is 0.2 V (200 mV/mil, the
    /// same figure in other units); µm and mil by their definitions.
    #[test]
    fn volts_mils_and_micrometres_to_metres() {
        let s = DEFAULT_SENSITIVITY_V_PER_M;
        assert!((reading_to_m(1.574, ProbeUnit::V, s) - 200e-6).abs() < 1e-12);
        assert!((reading_to_m(25.4e-6 * s, ProbeUnit::V, s) - 25.4e-6).abs() < 1e-15);
        assert!((25.4e-6 * s - 0.2).abs() < 1e-3, "200 mV/mil");
        assert!((reading_to_m(2.0, ProbeUnit::Mil, s) - 50.8e-6).abs() < 1e-15);
        assert!((reading_to_m(12.5, ProbeUnit::Um, s) - 12.5e-6).abs() < 1e-18);
        assert!("furlong".parse::<ProbeUnit>().is_err());
    }

    /// Probe frame to machine frame: a displacement (x, y) = (3, −4) µm read by probes at 45°
    /// and 135° (API 670's X–Y pair) reads d = (x + y)/√2 and (−x + y)/√2; solving back gives (x, y)
    /// to rounding, also for a non-orthogonal pair; the orthogonality check passes 45°/135° and
    /// refuses 45°/120°.
    #[test]
    fn probe_frame_to_machine_frame() {
        let (x, y) = (3e-6, -4e-6);
        for angles in [[45f64, 135.0], [0.0, 90.0], [30.0, 100.0]] {
            let a = angles.map(f64::to_radians);
            let d = a.map(|t| x * t.cos() + y * t.sin());
            let back = machine_from_probes(d, a);
            assert!(
                (back[0] - x).abs() < 1e-18 && (back[1] - y).abs() < 1e-18,
                "{back:?}"
            );
        }
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let a = [45f64, 135.0].map(f64::to_radians);
        let d = a.map(|t| x * t.cos() + y * t.sin());
        assert!((d[0] - (x + y) * h).abs() < 1e-18 && (d[1] - (y - x) * h).abs() < 1e-18);
        assert!(check_orthogonal(a).is_ok());
        assert!(check_orthogonal([45f64, 120.0].map(f64::to_radians)).is_err());
    }

    /// Runout subtraction: a reading made of a 1X shaft motion (3 µm at 40° lag) plus 5 µm of
    /// runout at 250° lag; the slow-roll vector measured over 3 revolutions where only the
    /// runout shows is 5 µm at 250° (to rounding), and subtracting it at each angle leaves the
    /// motion's own 1X vector, 3 µm at 40° (within 0.5°, 1 %; the reference is the signal as made).
    #[test]
    fn slow_roll_runout_is_measured_and_subtracted() {
        let runout = super::super::OneXVector {
            amplitude_m: 5e-6,
            phase_lag_deg: 250.0,
        };
        let motion = super::super::OneXVector {
            amplitude_m: 3e-6,
            phase_lag_deg: 40.0,
        };
        let mut slow = SlowRoll::default();
        for i in 0..(3 * 64) {
            let psi = std::f64::consts::TAU * i as f64 / 64.0;
            slow.add(psi, 20e-6 + runout_at(&runout, psi));
        }
        let measured = slow.vector().expect("3 revolutions");
        assert!((measured.amplitude_m - 5e-6).abs() < 1e-15, "{measured:?}");
        assert!(
            (measured.phase_lag_deg - 250.0).abs() < 1e-6,
            "{measured:?}"
        );
        let n = 32 * 16;
        let psi = |i: usize| std::f64::consts::TAU * i as f64 / 16.0;
        let compensated = (0..n).map(|i| {
            let raw = runout_at(&motion, psi(i)) + runout_at(&runout, psi(i));
            (psi(i), raw - runout_at(&measured, psi(i)))
        });
        let v = super::super::one_x_vector(compensated, n).unwrap();
        assert!(
            (v.amplitude_m / 3e-6 - 1.0).abs() < 0.01 && (v.phase_lag_deg - 40.0).abs() < 0.5,
            "{v:?}"
        );
        // and as phasors: raw minus runout is the motion
        let raw = (0..n).map(|i| {
            (
                psi(i),
                runout_at(&motion, psi(i)) + runout_at(&runout, psi(i)),
            )
        });
        let raw_v = super::super::one_x_vector(raw, n).unwrap();
        let d = raw_v.minus(&measured);
        assert!((d.phase_lag_deg - 40.0).abs() < 0.5, "{d:?}");
    }
}
