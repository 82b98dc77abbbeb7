//! Property tests (proptest) for the floating-point side: closed-form
//! profiles certify, rotate with the gaze, meet eq. 4 and eq. 6, round-trip
//! through JSON, and quantize into valid firmware tables.

use gaze_lidar::firmware::{FirmwareConfig, FirmwareTable};
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};
use gaze_lidar::profile::kinematics::Timeline;
use gaze_lidar::profile::Profile;
use proptest::prelude::*;

use crate::independent;

fn mode() -> impl Strategy<Value = Mode> {
    prop_oneof![
        Just(Mode::Baseline),
        Just(Mode::Range),
        Just(Mode::Resolution),
        Just(Mode::Joint)
    ]
}

fn power_at(p: &Profile, az: f64) -> f64 {
    p.bins[Timeline::new(p).bin_index(gaze_lidar::model::angle::wrap_deg(az))].power_w
}

fn spin_at(p: &Profile, az: f64) -> f64 {
    p.bins[Timeline::new(p).bin_index(gaze_lidar::model::angle::wrap_deg(az))].spin_start_rad_s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// REQ-PROF-1: every closed-form profile is certified, for any gaze,
    /// bin count, accounting and a scaled budget and frame rate.
    #[test]
    fn closed_forms_certify(
        gaze in -720.0f64..720.0, bins in 4usize..2000, m in mode(),
        angle in any::<bool>(), budget_scale in 0.2f64..1.0, frame_hz in 10.0f64..20.0,
    ) {
        let mut p = presets::paper();
        p.lidar.power_accounting = if angle { PowerAccounting::Angle } else { PowerAccounting::Time };
        p.lidar.average_power_w *= budget_scale;
        p.lidar.frame_rate_hz = frame_hz;
        let c = closed_form(&p, m, Some(gaze), bins).unwrap();
        // Within every declared limit, recomputed independently of the checker.
        let broken = independent::recheck(c.profile());
        prop_assert!(broken.is_empty(), "{:?}", broken);
        let s = c.summary();
        let avg = if angle { s.average_power_angle_w } else { s.average_power_time_w };
        prop_assert!((avg / p.lidar.average_power_w - 1.0).abs() < 1e-9);
    }

    /// REQ-PROF-2: rotating the gaze rotates the profile.
    #[test]
    fn gaze_rotation_rotates_the_profile(gaze in 0.0f64..360.0, shift in 0.0f64..360.0, m in mode(), probe in 0.0f64..360.0) {
        let p = presets::paper();
        let a = closed_form(&p, m, Some(gaze), 720).unwrap();
        let b = closed_form(&p, m, Some(gaze + shift), 720).unwrap();
        // Compare away from region edges (bin boundaries differ there).
        let rel = gaze_lidar::model::angle::diff_deg(probe, gaze).abs();
        prop_assume!((rel - 30.0).abs() > 0.6);
        // Equal up to the rounding of the summed region widths.
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs());
        prop_assert!(close(power_at(a.profile(), probe), power_at(b.profile(), probe + shift)));
        prop_assert!(close(spin_at(a.profile(), probe), spin_at(b.profile(), probe + shift)));
    }

    /// REQ-PROF-3: eq. 4 (angle accounting) and eq. 6 hold as equalities.
    #[test]
    fn eq4_eq6_identities(gaze in 0.0f64..360.0, bins in 4usize..5000, m in mode()) {
        let p = presets::paper();
        let c = closed_form(&p, m, Some(gaze), bins).unwrap();
        let prof = c.profile();
        let eq4: f64 = prof.bins.iter().map(|b| b.power_w * b.width_deg).sum::<f64>() / 360.0;
        prop_assert!((eq4 / p.lidar.average_power_w - 1.0).abs() < 1e-12);
        let period: f64 = prof.bins.iter().map(|b| b.width_deg.to_radians() / b.spin_start_rad_s).sum();
        prop_assert!((period * p.lidar.frame_rate_hz - 1.0).abs() < 1e-12);
    }

    /// REQ-IN-2: profile JSON round-trips exactly.
    #[test]
    fn json_round_trip(gaze in -400.0f64..400.0, bins in 4usize..500, m in mode()) {
        let c = closed_form(&presets::paper(), m, Some(gaze), bins).unwrap();
        let text = c.profile().to_json().unwrap();
        let back = Profile::from_json(&text, "x").unwrap();
        prop_assert_eq!(&back, c.profile());
        prop_assert_eq!(back.to_json().unwrap(), text);
    }

    /// REQ-FW-1/2 end to end: every certified closed form quantizes into a
    /// table that passes the integer checker, within one tick and one code.
    #[test]
    fn firmware_from_any_closed_form(gaze in 0.0f64..360.0, bins in 4usize..1500, m in mode(), tick_mhz in 1u64..200) {
        let c = closed_form(&presets::paper(), m, Some(gaze), bins).unwrap();
        let cfg = FirmwareConfig { tick_hz: tick_mhz * 1_000_000, power_w_per_code: None };
        let t = match FirmwareTable::from_certified(&c, &cfg) {
            Ok(t) => t,
            // A bin narrower than the spin limits allow at this tick rate
            // (an inserted region edge a few millidegrees wide at 1 MHz)
            // cannot be quantized: a refusal, not a table.
            Err(gaze_lidar::firmware::FirmwareError::Quantize(_)) => return Ok(()),
            Err(e) => panic!("{e}"),
        };
        // Not `check_table` (`from_certified` returns only tables it
        // accepts): the integer limits restated independently.
        let broken = independent::recheck_table(&t);
        prop_assert!(broken.is_empty(), "{:?}", broken);
        prop_assert_eq!(t.bins.iter().map(|b| b.dwell_ticks).sum::<u64>(), t.frame_ticks);
        for (b, fw) in c.profile().bins.iter().zip(&t.bins) {
            prop_assert!((fw.dwell_ticks as f64 - b.dwell_time_s() * cfg.tick_hz as f64).abs() < 1.0);
            prop_assert!(f64::from(fw.power_code) * t.power_w_per_code <= b.power_w);
        }
    }
}

/// The independent re-checks used above can fail: each broken limit of a
/// certified profile and of its table is found.
#[test]
fn independent_rechecks_find_broken_limits() {
    let c = closed_form(&presets::paper(), Mode::Joint, Some(90.0), 360).unwrap();
    assert!(independent::recheck(c.profile()).is_empty());
    let mut p = c.profile().clone();
    p.bins[7].power_w = p.limits.power_w_max * 1.001;
    assert!(
        !independent::recheck(&p).is_empty(),
        "power above power_w_max"
    );
    let mut p = c.profile().clone();
    p.average_power_w *= 0.99;
    assert!(!independent::recheck(&p).is_empty(), "average above budget");
    let mut p = c.profile().clone();
    p.bins[3].spin_start_rad_s *= 1.01;
    assert!(!independent::recheck(&p).is_empty(), "turn period off");
    let cfg = FirmwareConfig {
        tick_hz: 80_000_000,
        power_w_per_code: None,
    };
    let t = FirmwareTable::from_certified(&c, &cfg).unwrap();
    assert!(independent::recheck_table(&t).is_empty());
    let mut bad = t.clone();
    bad.bins[5].dwell_ticks += 1;
    assert!(!independent::recheck_table(&bad).is_empty(), "frame ticks");
    let mut bad = t.clone();
    bad.bins[5].power_code = bad.bins[5].power_code_cap + 1;
    assert!(
        !independent::recheck_table(&bad).is_empty(),
        "code above cap"
    );
    let mut bad = t;
    bad.limits.window_energy_max = 0;
    assert!(
        !independent::recheck_table(&bad).is_empty(),
        "window energy"
    );
}
