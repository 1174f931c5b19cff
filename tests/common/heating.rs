//! Helpers of the oil-heating tests (`tests/oil_heating*.rs`): the inputs the node decodes and
//! the driver's wakes.

use rotor_twin::driver::{Driver, Input};

/// A speed message (rpm) as the node decodes it, unstamped.
pub fn speed_rpm(rpm: f64) -> Input {
    Input::Speed {
        speed_rad_s: rpm * std::f64::consts::PI / 30.0,
        accel_rad_s2: 0.0,
        stamp_ns: 0,
    }
}

/// An oil supply temperature message (°C) as the node decodes it.
pub fn supply(celsius: f64) -> Input {
    use rotor_twin::messages::{Header, Temperature, Time};
    Input::from(&Temperature {
        header: Header {
            stamp: Time::from_nanos(0),
            frame_id: String::new(),
        },
        temperature: celsius,
        variance: 0.0,
    })
}

/// The process's film tables from the tests' cache directory (built once for all tests).
pub fn use_test_table_cache() {
    rotor_twin::film::set_disk_cache(Some(rotor_twin::film::TableCache::new(
        super::test_cache_dir(),
    )));
}

/// Wakes `d` every 1 ms of its time from `*t_ns` (advanced) until its heat balances on the
/// worker thread are done; bounded: panics after 600 s of waiting.
pub fn settle_heat(d: &mut Driver, t_ns: &mut i64) {
    for _ in 0..600_000 {
        *t_ns += 1_000_000;
        d.advance_to(*t_ns, 8, &mut |_| {});
        if !d.heat_balance_pending() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    panic!("the heat-balance worker never finished");
}

/// Steps `d` on to `t_ns` and asserts the twin runs with a finite eccentricity inside the
/// clearance.
pub fn assert_steps_on(d: &mut Driver, t_ns: i64) {
    d.advance_to(t_ns, usize::MAX, &mut |_| {});
    let e = d.session().unwrap().twin().output().bearings[0].eccentricity_ratio;
    assert!(e.is_finite() && e < 1.0, "ε {e}");
}
