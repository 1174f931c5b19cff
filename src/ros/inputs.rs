//! Checks on what arrives from the bus: a NaN, negative, absurd, stale or backwards value is
//! rejected with a reason and never reaches the model.

/// Gate for speed messages: finite, not negative, at most `max_speed_rad_s`, acceleration
/// finite and bounded, stamps not going backwards and not older than the timeout.
#[derive(Debug, Clone)]
pub struct SpeedGate {
    /// Largest plausible speed (rad/s).
    pub max_speed_rad_s: f64,
    /// Largest plausible angular acceleration (rad/s²).
    pub max_accel_rad_s2: f64,
    /// A stamp older than this (ns) against the receive time is stale.
    pub timeout_ns: i64,
    last_stamp_ns: Option<i64>,
}

impl SpeedGate {
    /// A gate accepting speeds up to `max_speed_rad_s` and stamps up to `timeout_s` old.
    pub fn new(max_speed_rad_s: f64, timeout_s: f64) -> Self {
        Self {
            max_speed_rad_s,
            max_accel_rad_s2: 1.0e4,
            timeout_ns: (timeout_s * 1e9) as i64,
            last_stamp_ns: None,
        }
    }

    /// Checks one speed (rad/s) and acceleration (rad/s²) stamped `stamp_ns` (0: unstamped)
    /// received at `now_ns`. Ok((speed, accel)) or the reason for refusing it.
    pub fn check(
        &mut self,
        speed: f64,
        accel: f64,
        stamp_ns: i64,
        now_ns: i64,
    ) -> Result<(f64, f64), String> {
        if !speed.is_finite() {
            return Err(format!("speed {speed} rad/s is not a finite number"));
        }
        if speed < 0.0 {
            return Err(format!(
                "speed {speed} rad/s is negative (the machine turns one way)"
            ));
        }
        if speed > self.max_speed_rad_s {
            return Err(format!(
                "speed {speed:.1} rad/s is absurd (above {:.1} rad/s, 10× rated)",
                self.max_speed_rad_s
            ));
        }
        if !accel.is_finite() || accel.abs() > self.max_accel_rad_s2 {
            return Err(format!(
                "angular acceleration {accel} rad/s² is not finite or above {} rad/s²",
                self.max_accel_rad_s2
            ));
        }
        if stamp_ns != 0 {
            if let Some(last) = self.last_stamp_ns {
                if stamp_ns < last {
                    return Err(format!(
                        "stamp {:.6} s goes backwards (last {:.6} s)",
                        stamp_ns as f64 * 1e-9,
                        last as f64 * 1e-9
                    ));
                }
            }
            if now_ns - stamp_ns > self.timeout_ns {
                return Err(format!(
                    "stamp is stale: {:.3} s old",
                    (now_ns - stamp_ns) as f64 * 1e-9
                ));
            }
            self.last_stamp_ns = Some(stamp_ns);
        }
        Ok((speed, accel))
    }
}

/// Checks an unbalance: plane index among `planes`, m·e (kg·m) finite in [0, 0.01] (100,000 g·mm
/// is absurd for any machine the twin models), phase (rad) finite.
pub fn check_unbalance(
    plane: u32,
    magnitude: f64,
    phase: f64,
    planes: usize,
) -> Result<(usize, f64, f64), String> {
    let p = plane as usize;
    if p >= planes {
        return Err(format!(
            "unbalance plane {plane} does not exist (the machine has {planes})"
        ));
    }
    if !magnitude.is_finite() || !(0.0..=0.01).contains(&magnitude) {
        return Err(format!(
            "unbalance {magnitude} kg·m must be finite, 0 to 0.01 kg·m"
        ));
    }
    if !phase.is_finite() {
        return Err(format!("unbalance phase {phase} rad is not finite"));
    }
    Ok((p, magnitude, phase))
}

/// Checks a probe displacement (m): finite and within 10 mm.
pub fn check_probe(x: f64, y: f64) -> Result<(f64, f64), String> {
    if !(x.is_finite() && y.is_finite()) || x.abs() > 0.01 || y.abs() > 0.01 {
        return Err(format!(
            "probe displacement ({x}, {y}) m is not finite or beyond 10 mm"
        ));
    }
    Ok((x, y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_gate_refuses_bad_values_and_stamps() {
        let mut g = SpeedGate::new(9424.0, 1.0);
        let now = 100_000_000_000;
        assert!(g.check(942.0, 0.0, now - 1_000_000, now).is_ok());
        for bad in [f64::NAN, f64::INFINITY, -1.0, 1e6] {
            assert!(g.check(bad, 0.0, now, now).is_err(), "{bad}");
        }
        assert!(g.check(942.0, f64::NAN, now, now).is_err());
        assert!(g
            .check(942.0, 0.0, now - 2_000_000, now)
            .unwrap_err()
            .contains("backwards"));
        assert!(g
            .check(942.0, 0.0, now - 500_000, now + 2_000_000_000)
            .unwrap_err()
            .contains("stale"));
        assert!(g.check(942.0, 0.0, 0, now).is_ok(), "unstamped is accepted");
        assert!(check_unbalance(0, 1.4e-4, 0.0, 1).is_ok());
        assert!(check_unbalance(1, 1.4e-4, 0.0, 1).is_err());
        assert!(check_unbalance(0, f64::NAN, 0.0, 1).is_err());
        assert!(check_unbalance(0, 5.0, 0.0, 1).is_err());
        assert!(check_probe(f64::NAN, 0.0).is_err());
    }
}
