//! Core-level tests of `eye_safety::report` and `model::lidar` (found by
//! `cargo mutants`): the `ael` report's fields and stationary-beam figures,
//! and the sensor's derived quantities, against values worked out by hand
//! from Table 3 / Table 9 / Table 10.

use approx::assert_relative_eq;
use gaze_lidar_core::eye_safety::ael::Band;
use gaze_lidar_core::eye_safety::ael_report;
use gaze_lidar_core::model::lidar::{LidarSpec, Limits, PowerAccounting};

/// C4 at 905 nm: 10^0.41.
const C4_905: f64 = 2.570_395_782_768_864;

#[test]
fn report_constants_by_hand() {
    let r = ael_report(905.0, 5e-9, None).unwrap();
    assert_eq!(r.wavelength_nm, 905.0);
    assert_eq!(r.band, Band::RetinalNir);
    assert_eq!(r.pulse_duration_s, 5e-9);
    assert_relative_eq!(r.single_pulse_ael_j, 7.7e-8 * C4_905, max_relative = 1e-12);
    // 3.9e-4·C4 W over the 100 s time base.
    assert_relative_eq!(r.average_power_ael_w, 3.9e-4 * C4_905, max_relative = 1e-12);
    assert_relative_eq!(r.c4, C4_905, max_relative = 1e-12);
    assert_eq!((r.c6, r.c7), (1.0, 1.0));
    assert_eq!((r.t2_s, r.t_i_s, r.time_base_s), (10.0, 5e-6, 100.0));
    assert_eq!(
        (r.aperture_diameter_mm, r.aperture_distance_mm),
        (7.0, 100.0)
    );
    assert_eq!(r.stationary_beam, None);

    let r = ael_report(1450.0, 1e-3, None).unwrap();
    assert_eq!(r.band, Band::Ir1400);
    // 4.4e-3·(1e-3)^0.25 < 8e-3 on the 1 ms row edge.
    assert_relative_eq!(
        r.single_pulse_ael_j,
        7.824_429_404_171_262e-4,
        max_relative = 1e-12
    );
    assert_relative_eq!(r.average_power_ael_w, 1e-2, max_relative = 1e-12);
    // Table 10's largest aperture over every duration, 1.5·10^0.375 mm.
    assert_eq!(
        (r.c4, r.t_i_s, r.aperture_diameter_mm),
        (1.0, 1e-3, 3.557_060_558_492_482_4)
    );

    let r = ael_report(1550.0, 5e-9, None).unwrap();
    assert_eq!(
        (r.band, r.t_i_s, r.aperture_diameter_mm),
        (Band::Ir1500, 10.0, 3.557_060_558_492_482_4)
    );
    assert!(ael_report(1200.0, 5e-9, None).is_err());
    assert!(ael_report(905.0, 0.0, None).is_err());
}

/// 905 nm, 10 µs pulses (longer than T_i = 5 µs) at 1 kHz: no grouping, C5 = 1
/// (2014 rule), N = ⌊10·1000⌋ + 1 = 10001, each pulse AEL(10 µs) =
/// 7e-4·C4·(1e-5)^0.75 = 7e-4·C4·10^-3.75.
#[test]
fn stationary_long_pulses_by_hand() {
    let s = ael_report(905.0, 1e-5, Some(1000.0))
        .unwrap()
        .stationary_beam
        .unwrap();
    assert_eq!(s.pulse_rate_hz, 1000.0);
    assert_eq!(s.pulses_in_t_max, 10_001.0);
    assert_eq!(s.c5, 1.0);
    let ael = 7e-4 * C4_905 * 1.778_279_410_038_923e-4;
    assert_relative_eq!(s.per_pulse_ael_j, ael, max_relative = 1e-12);
}

/// 905 nm, pulses of exactly T_i = 5 µs at 1 kHz: C5 applies,
/// 5·10001^−0.25, and AEL(5 µs) is the smaller row, 7e-4·C4·(5e-6)^0.75.
#[test]
fn stationary_pulses_at_t_i_by_hand() {
    let s = ael_report(905.0, 5e-6, Some(1000.0))
        .unwrap()
        .stationary_beam
        .unwrap();
    assert_eq!(s.pulses_in_t_max, 10_001.0);
    let c5 = 5.0 / 10_001f64.sqrt().sqrt();
    assert_relative_eq!(s.c5, c5, max_relative = 1e-12);
    assert_relative_eq!(
        s.per_pulse_ael_j,
        c5 * 7.401_598_844_083_949e-8 * C4_905,
        max_relative = 1e-12
    );
}

/// 1550 nm, 5 ns at 10 Hz: C5 = 1, N = 101, each pulse 8e-3 J. The mean
/// power is bound by the train: a window of T receives at most P·(T + 0.1 s),
/// against 1e-2·T J for T ≥ 10 s and 1.8e-2·T^0.75 J below; the worst is
/// T = 10 s, P·10.1 ≤ 0.1 J → P ≤ 1/101 W (the pulse rule allows 0.08 W).
#[test]
fn stationary_1550_by_hand() {
    let s = ael_report(1550.0, 5e-9, Some(10.0))
        .unwrap()
        .stationary_beam
        .unwrap();
    assert_eq!(s.pulses_in_t_max, 101.0);
    assert_eq!(s.c5, 1.0);
    assert_relative_eq!(s.per_pulse_ael_j, 8e-3, max_relative = 1e-12);
    assert_relative_eq!(s.max_average_power_w, 1.0 / 101.0, max_relative = 1e-6);
}

#[test]
fn stationary_rate_bounds() {
    // rate · duration must stay below 1.
    assert!(ael_report(905.0, 1e-6, Some(999_999.0)).is_ok());
    assert!(ael_report(905.0, 1e-6, Some(1e6)).is_err());
    assert!(ael_report(905.0, 5e-9, Some(-1.0)).is_err());
    assert!(ael_report(905.0, 5e-9, Some(f64::INFINITY)).is_err());
}

/// Power 0–1 W, spin 1–100 rad/s, no other limit, no eye safety.
fn limits() -> Limits {
    Limits {
        eye_safety: None,
        ..gaze_lidar_core::testing::limits((0.0, 1.0), (1.0, 100.0))
    }
}

#[test]
fn sensor_derived_quantities_by_hand() {
    let s = LidarSpec {
        name: "s".into(),
        frame_rate_hz: 8.0,
        pulse_rate_hz: 20_000.0,
        channels: 1,
        average_power_w: 0.01,
        rated_range_m: 100.0,
        reference_reflectivity: 0.1,
        power_accounting: PowerAccounting::Angle,
        limits: limits(),
    };
    assert_relative_eq!(
        s.mean_spin_rad_s(),
        16.0 * std::f64::consts::PI,
        max_relative = 1e-15
    );
    assert_eq!(s.frame_period_s(), 0.125);
    assert_eq!(s.points_per_turn(), 2500.0);
}

#[test]
fn limits_optional_fields_are_read_when_present() {
    let json = r#"{"power_w_min": 0.0, "power_w_max": 1.0, "spin_rad_s_min": 1.0,
        "spin_rad_s_max": 100.0, "spin_accel_rad_s2_max": 5.0,
        "power_slew_w_per_deg_max": 0.25,
        "eye_safety": {"wavelength_nm": 905.0, "pulse_duration_s": 5e-9, "beam_diameter_mm": 8.0}}"#;
    let l: Limits = serde_json::from_str(json).unwrap();
    assert_eq!(l.spin_accel_rad_s2_max, Some(5.0));
    assert_eq!(l.power_slew_w_per_deg_max, Some(0.25));
    assert_eq!(l.eye_safety.unwrap().beam_diameter_mm, 8.0);
    // Present as null: None; absent: an error (the keys are required).
    let nulls = json
        .replace(
            "\"spin_accel_rad_s2_max\": 5.0",
            "\"spin_accel_rad_s2_max\": null",
        )
        .replace(
            "\"power_slew_w_per_deg_max\": 0.25",
            "\"power_slew_w_per_deg_max\": null",
        );
    let l: Limits = serde_json::from_str(&nulls).unwrap();
    assert_eq!(
        (l.spin_accel_rad_s2_max, l.power_slew_w_per_deg_max),
        (None, None)
    );
    let absent = json.replace("\"spin_accel_rad_s2_max\": 5.0,", "");
    assert!(serde_json::from_str::<Limits>(&absent).is_err());
}
