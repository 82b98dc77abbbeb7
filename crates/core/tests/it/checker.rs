//! Core-level tests of the certifying checker (found by `cargo mutants`:
//! the checker had no test inside the core crate). Every expected value is
//! constructed by hand from a uniform profile, every violation is provoked
//! by a change just past its limit, and the limit itself is shown to pass.

use gaze_lidar_core::checker::{
    certify, certify_for_sensor, certify_with, check, check_with, summarize, summarize_list,
    CheckOptions, Violation,
};
use gaze_lidar_core::eye_safety::{EyeSafetyParams, Rule};
use gaze_lidar_core::model::lidar::{LidarSpec, Limits, PowerAccounting};
use gaze_lidar_core::profile::{Bin, Profile, Region, PROFILE_FORMAT};
use std::f64::consts::TAU;

const N: usize = 36;
const FRAME_HZ: f64 = 10.0;
const POWER_W: f64 = 1e-4;

use gaze_lidar_core::testing::{self, params};

/// Power 0.5e-4–2e-4 W, spin 50–80 rad/s, acceleration ≤ 1e4 rad/s², slew
/// ≤ 1e-5 W/deg, the usual beam.
fn limits() -> Limits {
    Limits {
        spin_accel_rad_s2_max: Some(1e4),
        power_slew_w_per_deg_max: Some(1e-5),
        ..testing::limits((0.5e-4, 2e-4), (50.0, 80.0))
    }
}

/// 36 bins of 10° at `POWER_W`, constant spin 2π·10 rad/s (one turn in
/// 0.1 s), the first six in the region of interest.
fn uniform() -> Profile {
    let mut p = testing::uniform(N, FRAME_HZ, POWER_W, PowerAccounting::Angle, limits());
    for b in &mut p.bins[..6] {
        b.region = Some(Region::Rof);
    }
    p
}

fn sensor() -> LidarSpec {
    LidarSpec {
        name: "test".into(),
        frame_rate_hz: FRAME_HZ,
        pulse_rate_hz: 20_000.0,
        channels: 1,
        average_power_w: POWER_W,
        rated_range_m: 100.0,
        reference_reflectivity: 0.1,
        power_accounting: PowerAccounting::Angle,
        limits: limits(),
    }
}

fn keys(v: &[Violation]) -> Vec<&'static str> {
    v.iter().map(Violation::limit_key).collect()
}

/// The only violations of `p` are about `key` (and there is one).
fn only(p: &Profile, key: &str) -> Vec<Violation> {
    let v = check(p);
    assert!(!v.is_empty(), "expected a violation of {key}");
    assert!(keys(&v).iter().all(|k| *k == key), "{key}: {v:?}");
    v
}

#[test]
fn uniform_profile_is_certified_with_its_constructed_summary() {
    let p = uniform();
    assert_eq!(check(&p), vec![]);
    let c = certify(p.clone()).unwrap();
    let s = &c.summary().clone();
    assert_eq!(s, &summarize(&p));
    assert_eq!(c.profile().bins, p.bins);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
    assert!(close(s.frame_period_s, 0.1), "{}", s.frame_period_s);
    assert!(close(s.energy_per_frame_j, POWER_W * 0.1));
    assert!(close(s.average_power_angle_w, POWER_W));
    assert!(close(s.average_power_time_w, POWER_W));
    assert_eq!(s.max_spin_accel_rad_s2, Some(0.0));
    assert!(close(s.rof_width_deg, 60.0));
    assert_eq!(s.power_w_range, [POWER_W, POWER_W]);
    assert_eq!(s.spin_rad_s_range, [TAU * FRAME_HZ, TAU * FRAME_HZ]);
    assert_eq!(c.into_inner().summary.as_ref(), Some(s));
}

#[test]
fn summary_of_a_non_uniform_profile() {
    let mut p = uniform();
    // Two power levels, one accelerating bin pair (spin continuous).
    p.bins[0].power_w = 2.0 * POWER_W;
    p.bins[1].power_w = 0.5 * POWER_W;
    p.bins[2].spin_end_rad_s = 70.0;
    p.bins[3].spin_start_rad_s = 70.0;
    let s = summarize(&p);
    let w = TAU * FRAME_HZ;
    let dth = 10f64.to_radians();
    let a = (70.0f64 * 70.0 - w * w) / (2.0 * dth);
    assert!((s.max_spin_accel_rad_s2.unwrap() - a.abs()).abs() <= 1e-9 * a.abs());
    assert_eq!(s.power_w_range, [0.5 * POWER_W, 2.0 * POWER_W]);
    assert_eq!(s.spin_rad_s_range, [w, 70.0]);
    let t_fast = 2.0 * dth / (w + 70.0);
    let period = 34.0 * dth / w + 2.0 * t_fast;
    assert!((s.frame_period_s - period).abs() <= 1e-12 * period);
    // Bins 0 (2P) and 1 (P/2) and 32 more at P turn at w; bins 2, 3 at P are faster.
    let energy = POWER_W * (dth / w) * (2.0 + 0.5 + 32.0) + POWER_W * 2.0 * t_fast;
    assert!((s.energy_per_frame_j - energy).abs() <= 1e-12 * energy);
    assert!((s.average_power_time_w - energy / period).abs() <= 1e-12 * energy / period);
    let angle_avg = POWER_W * (34.0 * 10.0 + 20.0 + 5.0) / 360.0;
    assert!((s.average_power_angle_w - angle_avg).abs() <= 1e-15);
    // A spin step between bins: no finite acceleration.
    p.bins[3].spin_start_rad_s = 71.0;
    assert_eq!(summarize(&p).max_spin_accel_rad_s2, None);
}

#[test]
fn power_limits_are_inclusive_and_named() {
    let mut p = uniform();
    p.average_power_w = 1.0; // keep the budget out of the way
    p.limits.power_slew_w_per_deg_max = None;
    p.bins[4].power_w = p.limits.power_w_max;
    assert_eq!(check(&p), vec![]);
    p.bins[4].power_w = p.limits.power_w_max * (1.0 + 1e-6);
    let v = only(&p, "power_w_max");
    assert!(matches!(v[0], Violation::PowerMax { bin: 4, .. }), "{v:?}");
    let mut p = uniform();
    p.limits.power_slew_w_per_deg_max = None;
    p.bins[5].power_w = p.limits.power_w_min;
    assert_eq!(check(&p), vec![]);
    p.bins[5].power_w = p.limits.power_w_min * (1.0 - 1e-6);
    let v = only(&p, "power_w_min");
    assert!(matches!(v[0], Violation::PowerMin { bin: 5, .. }), "{v:?}");
}

/// Spin within [min, max] at both ends of every bin; the turn still takes
/// exactly one frame period (a faster and a slower bin compensate).
#[test]
fn spin_limits_are_inclusive_and_named() {
    let w = TAU * FRAME_HZ;
    let with_pair = |fast: f64| {
        let mut p = uniform();
        p.limits.spin_accel_rad_s2_max = None;
        let dth = 10f64.to_radians();
        // Bin 0 at `fast`, bin 1 slower so that the period is unchanged.
        let t = 2.0 * dth / w - dth / fast;
        let slow = dth / t;
        p.bins[0].spin_start_rad_s = fast;
        p.bins[0].spin_end_rad_s = fast;
        p.bins[1].spin_start_rad_s = slow;
        p.bins[1].spin_end_rad_s = slow;
        (p, slow)
    };
    let (p, slow) = with_pair(80.0);
    assert!(slow > 50.0);
    assert_eq!(check(&p), vec![]);
    let (p, _) = with_pair(80.0 * (1.0 + 1e-6));
    let v = only(&p, "spin_rad_s_max");
    assert!(matches!(v[0], Violation::SpinMax { bin: 0, .. }), "{v:?}");
    // Lower limit: raise it to just above the slow bin.
    let (mut p, slow) = with_pair(75.0);
    p.limits.spin_rad_s_min = slow;
    assert_eq!(check(&p), vec![]);
    p.limits.spin_rad_s_min = slow * (1.0 + 1e-6);
    let v = only(&p, "spin_rad_s_min");
    assert!(matches!(v[0], Violation::SpinMin { bin: 1, .. }), "{v:?}");
}

#[test]
fn acceleration_and_spin_steps() {
    let w = TAU * FRAME_HZ;
    // Bin 0 accelerates w → w1, bin 1 decelerates back (period shrinks a
    // little; the frame rate is set to match).
    let make = |w1: f64, accel_max: f64| {
        let mut p = uniform();
        p.bins[0].spin_end_rad_s = w1;
        p.bins[1].spin_start_rad_s = w1;
        p.limits.spin_accel_rad_s2_max = Some(accel_max);
        let period: f64 = p.bins.iter().map(Bin::dwell_time_s).sum();
        p.frame_rate_hz = 1.0 / period;
        p.average_power_w = 1.0;
        p
    };
    let dth = 10f64.to_radians();
    let w1 = 70.0;
    let a = (w1 * w1 - w * w) / (2.0 * dth);
    assert_eq!(check(&make(w1, a)), vec![]);
    let v = only(&make(w1, a * (1.0 - 1e-6)), "spin_accel_rad_s2_max");
    assert_eq!(v.len(), 2, "bins 0 and 1: {v:?}");
    assert!(matches!(v[0], Violation::SpinAccel { bin: 0, .. }), "{v:?}");
    // A step between bins violates the acceleration limit, whatever it is.
    let mut p = make(w1, 1e12);
    p.bins[1].spin_start_rad_s = w1 * (1.0 + 1e-6);
    p.frame_rate_hz = 1.0 / p.bins.iter().map(Bin::dwell_time_s).sum::<f64>();
    let v = only(&p, "spin_accel_rad_s2_max");
    assert!(
        v.iter()
            .any(|x| matches!(x, Violation::SpinStep { bin: 0, .. })),
        "{v:?}"
    );
    // A step within the relative tolerance (1e-9 of the spin) is not one.
    let mut q = make(w1, 1e12);
    q.bins[1].spin_start_rad_s = w1 * (1.0 + 1e-10);
    q.frame_rate_hz = 1.0 / q.bins.iter().map(Bin::dwell_time_s).sum::<f64>();
    assert_eq!(check(&q), vec![]);
    // Without an acceleration limit, a step is allowed.
    p.limits.spin_accel_rad_s2_max = None;
    assert_eq!(check(&p), vec![]);
}

#[test]
fn power_slew_is_checked_between_neighbours_including_the_wrap() {
    let mut p = uniform();
    p.average_power_w = 1.0;
    // 1e-5 W/° over a 10° centre distance allows a step of 1e-4 W.
    p.bins[N - 1].power_w = POWER_W + 1e-4 * (1.0 - 1e-9);
    p.limits.power_w_max = 1.0;
    assert_eq!(check(&p), vec![]);
    p.bins[N - 1].power_w = POWER_W + 1e-4 * (1.0 + 1e-6);
    let v = only(&p, "power_slew_w_per_deg_max");
    // Bins N−2 → N−1 and N−1 → 0 (the wrap).
    let bins: Vec<usize> = v
        .iter()
        .map(|x| match x {
            Violation::PowerSlew { bin, .. } => *bin,
            _ => unreachable!(),
        })
        .collect();
    assert_eq!(bins, vec![N - 2, N - 1]);
    p.limits.power_slew_w_per_deg_max = None;
    assert_eq!(check(&p), vec![]);
}

#[test]
fn average_power_under_both_accountings() {
    let mut p = uniform();
    p.limits.power_slew_w_per_deg_max = None;
    p.bins[0].power_w = 2.0 * POWER_W;
    // Angle: mean over angle = P·(1 + 1/36).
    let angle_avg = POWER_W * (1.0 + 1.0 / 36.0);
    p.average_power_w = angle_avg;
    assert_eq!(check(&p), vec![]);
    p.average_power_w = angle_avg * (1.0 - 1e-6);
    let v = only(&p, "average_power_w");
    assert!(matches!(
        v[0],
        Violation::AveragePower {
            accounting: PowerAccounting::Angle,
            ..
        }
    ));
    // Time: bin 0 spins slower (twice its dwell), bin 1 faster to keep the
    // frame: the time average weights bin 0 by 2/36 of the frame.
    let w = TAU * FRAME_HZ;
    p.power_accounting = PowerAccounting::Time;
    p.limits.spin_accel_rad_s2_max = None;
    p.limits.spin_rad_s_min = 0.0;
    p.limits.spin_rad_s_max = 1e6;
    p.bins[0].spin_start_rad_s = w / 2.0;
    p.bins[0].spin_end_rad_s = w / 2.0;
    // Bins 1 and 2 at 2w give the time back: the frame period is unchanged.
    p.bins[1].spin_start_rad_s = 2.0 * w;
    p.bins[1].spin_end_rad_s = 2.0 * w;
    p.bins[2].spin_start_rad_s = 2.0 * w;
    p.bins[2].spin_end_rad_s = 2.0 * w;
    let time_avg = POWER_W * (1.0 + 2.0 / 36.0);
    p.average_power_w = time_avg;
    assert_eq!(check(&p), vec![]);
    p.average_power_w = time_avg * (1.0 - 1e-6);
    let v = only(&p, "average_power_w");
    assert!(matches!(
        v[0],
        Violation::AveragePower {
            accounting: PowerAccounting::Time,
            ..
        }
    ));
}

#[test]
fn frame_period_must_match_the_frame_rate() {
    let mut p = uniform();
    p.frame_rate_hz = FRAME_HZ * (1.0 + 1e-6);
    let v = check(&p);
    assert!(keys(&v).contains(&"frame_rate_hz"), "{v:?}");
    p.frame_rate_hz = FRAME_HZ * (1.0 + 1e-12);
    assert_eq!(check(&p), vec![]);
    // The tolerance is relative (1e-9 of the period): 5e-9 off is refused,
    // 5e-10 off is not.
    p.frame_rate_hz = FRAME_HZ * (1.0 + 5e-9);
    assert_eq!(keys(&check(&p)), vec!["frame_rate_hz"]);
    p.frame_rate_hz = FRAME_HZ * (1.0 + 5e-10);
    assert_eq!(check(&p), vec![]);
}

#[test]
fn structure_header_and_limits_are_validated() {
    let mut p = uniform();
    p.format = "gaze-lidar/profile@2".into();
    assert_eq!(keys(&check(&p)), vec!["format"]);

    for field in ["frame_rate_hz", "pulse_rate_hz"] {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let mut p = uniform();
            if field == "frame_rate_hz" {
                p.frame_rate_hz = bad;
            } else {
                p.pulse_rate_hz = bad;
            }
            assert!(keys(&check(&p)).contains(&field), "{field} = {bad}");
        }
    }
    let mut p = uniform();
    p.average_power_w = -1e-9;
    assert!(
        check(&p).iter().any(|x| matches!(
            x,
            Violation::Header {
                field: "average_power_w",
                ..
            }
        )),
        "{:?}",
        check(&p)
    );
    // Equal minimum and maximum limits are valid (a fixed power, a fixed spin).
    let mut p = uniform();
    p.limits.power_slew_w_per_deg_max = None;
    p.limits.power_w_min = POWER_W;
    p.limits.power_w_max = POWER_W;
    p.limits.spin_rad_s_min = TAU * FRAME_HZ;
    p.limits.spin_rad_s_max = TAU * FRAME_HZ;
    assert_eq!(check(&p), vec![]);
    p.average_power_w = 0.0;
    p.bins.iter_mut().for_each(|b| b.power_w = 0.0);
    p.limits.power_w_min = 0.0;
    assert_eq!(check(&p), vec![]);
    let mut p = uniform();
    p.gaze_deg = Some(f64::NAN);
    assert_eq!(keys(&check(&p)), vec!["gaze_deg"]);
    p.gaze_deg = Some(-400.0);
    assert_eq!(check(&p), vec![]);

    let mut p = uniform();
    p.limits.power_w_min = 3e-4;
    let v = check(&p);
    assert!(
        v.iter().any(|x| matches!(
            x,
            Violation::BadLimit {
                field: "power_w_min",
                ..
            }
        )),
        "{v:?}"
    );
    let mut p = uniform();
    p.limits.spin_rad_s_min = 90.0;
    assert!(check(&p).iter().any(|x| matches!(
        x,
        Violation::BadLimit {
            field: "spin_rad_s_min",
            ..
        }
    )));
    for i in 0..6 {
        let mut p = uniform();
        let l = &mut p.limits;
        match i {
            0 => l.power_w_max = -1.0,
            1 => l.spin_rad_s_max = f64::NAN,
            2 => l.spin_accel_rad_s2_max = Some(-1.0),
            3 => l.power_slew_w_per_deg_max = Some(f64::INFINITY),
            4 => l.power_w_min = -0.0 - 1e-9,
            _ => l.spin_rad_s_min = -1.0,
        }
        assert!(
            check(&p)
                .iter()
                .any(|x| matches!(x, Violation::BadLimit { .. })),
            "case {i}"
        );
    }

    let mut p = uniform();
    p.bins.clear();
    assert_eq!(check(&p), vec![Violation::BinCount { count: 0 }]);
    let mut p = uniform();
    p.bins[3].width_deg = 0.0;
    assert!(keys(&check(&p)).contains(&"width_deg"));
    let mut p = uniform();
    p.bins[3].spin_end_rad_s = 0.0;
    assert!(keys(&check(&p)).contains(&"spin_end_rad_s"));
    let mut p = uniform();
    p.bins[3].power_w = f64::NAN;
    assert!(keys(&check(&p)).contains(&"power_w"));
    let mut p = uniform();
    p.bins[3].start_deg += 1e-6;
    let v = check(&p);
    assert!(
        v.iter()
            .any(|x| matches!(x, Violation::Coverage { bin: 3, .. })),
        "{v:?}"
    );
    let mut p = uniform();
    p.bins[N - 1].width_deg = 9.0;
    let v = check(&p);
    assert!(
        v.iter().any(|x| matches!(x, Violation::CoverageEnd { .. })),
        "{v:?}"
    );
    // Edges within the angle tolerance are accepted.
    let mut p = uniform();
    p.bins[3].start_deg += 1e-10;
    assert_eq!(check(&p), vec![]);
}

#[test]
fn eye_safety_is_required_unless_opted_out() {
    let mut p = uniform();
    p.limits.eye_safety = None;
    assert_eq!(check(&p), vec![Violation::EyeSafetyMissing]);
    let opts = CheckOptions::declared().allow_missing_eye_safety(true);
    assert_eq!(check_with(&p, &opts), vec![]);
    assert!(certify_with(p.clone(), &opts).is_ok());
    assert!(certify(p).is_err());
}

#[test]
fn eye_safety_violation_names_rule_and_ratio() {
    // Slow the head 10× over bins 0..=2 at full power: the single pulse
    // count per pass grows, and a high power makes it exceed the limit.
    let mut p = uniform();
    p.limits.power_w_max = 10.0;
    p.limits.power_slew_w_per_deg_max = None;
    p.average_power_w = 10.0;
    p.bins.iter_mut().for_each(|b| b.power_w = 5.0);
    let v = check(&p);
    let Some(Violation::EyeSafety { ratio, rule, .. }) = v.first() else {
        panic!("{v:?}")
    };
    assert!(*ratio > 1.0, "{ratio}");
    // At 5 W the pulses of one pass exceed the C5-corrected single-pulse
    // AEL first: that rule binds, and the message names it.
    assert_eq!(*rule, Rule::SinglePulse);
    assert!(v[0].to_string().contains("single-pulse energy"), "{}", v[0]);
    assert_eq!(keys(&v), vec!["eye_safety"]);
    // Bad laser parameters are a named violation, not a panic.
    let mut p = uniform();
    p.limits.eye_safety = Some(EyeSafetyParams {
        wavelength_nm: 300.0,
        ..params()
    });
    assert!(check(&p)
        .iter()
        .any(|x| matches!(x, Violation::EyeSafetyParams { .. })));
}

#[test]
fn sensor_limits_are_enforced_naming_the_key() {
    let p = uniform();
    assert!(certify_for_sensor(p.clone(), &sensor()).is_ok());
    type Change = Box<dyn Fn(&mut Profile)>;
    let cases: Vec<(&str, Change)> = vec![
        ("power_w_min", Box::new(|p| p.limits.power_w_min = 0.4e-4)),
        ("power_w_max", Box::new(|p| p.limits.power_w_max = 2.1e-4)),
        (
            "spin_rad_s_min",
            Box::new(|p| p.limits.spin_rad_s_min = 49.0),
        ),
        (
            "spin_rad_s_max",
            Box::new(|p| p.limits.spin_rad_s_max = 81.0),
        ),
        (
            "spin_accel_rad_s2_max",
            Box::new(|p| p.limits.spin_accel_rad_s2_max = None),
        ),
        (
            "spin_accel_rad_s2_max",
            Box::new(|p| p.limits.spin_accel_rad_s2_max = Some(2e4)),
        ),
        (
            "power_slew_w_per_deg_max",
            Box::new(|p| p.limits.power_slew_w_per_deg_max = Some(2e-5)),
        ),
        ("average_power_w", Box::new(|p| p.average_power_w = 2e-4)),
        ("pulse_rate_hz", Box::new(|p| p.pulse_rate_hz = 20_001.0)),
        (
            "frame_rate_hz",
            Box::new(|p| {
                p.frame_rate_hz = 10.000001;
            }),
        ),
        (
            "power_accounting",
            Box::new(|p| p.power_accounting = PowerAccounting::Time),
        ),
        (
            "eye_safety",
            Box::new(|p| {
                p.limits.eye_safety = Some(EyeSafetyParams {
                    beam_diameter_mm: 9.0,
                    head: None,
                    ..params()
                })
            }),
        ),
        ("eye_safety", Box::new(|p| p.limits.eye_safety = None)),
    ];
    for (key, change) in cases {
        let mut p = uniform();
        change(&mut p);
        let err = certify_for_sensor(p, &sensor()).unwrap_err();
        assert!(
            keys(&err.violations).contains(&key),
            "{key}: {:?}",
            err.violations
        );
    }
    // Stricter than the sensor is fine.
    let mut p = uniform();
    p.limits.power_w_max = 1.5e-4;
    p.limits.spin_rad_s_min = 55.0;
    p.limits.spin_accel_rad_s2_max = Some(1.0);
    p.average_power_w = 0.9 * POWER_W;
    p.bins.iter_mut().for_each(|b| b.power_w = 0.9 * POWER_W);
    assert!(certify_for_sensor(p, &sensor()).is_ok());
}

#[test]
fn rejection_lists_every_violation() {
    let mut p = uniform();
    p.limits.power_slew_w_per_deg_max = None;
    p.average_power_w = 1.0;
    p.bins[1].power_w = 1.0;
    p.bins[2].power_w = 1.0;
    let v = check(&p);
    let err = certify(p).unwrap_err();
    assert_eq!(err.violations, v);
    let power_max: Vec<_> = v
        .iter()
        .filter(|x| matches!(x, Violation::PowerMax { .. }))
        .collect();
    assert_eq!(power_max.len(), 2);
    let msg = err.to_string();
    assert!(msg.contains(&format!("{} violation(s)", v.len())), "{msg}");
    assert!(
        msg.contains("bins[1]") || msg.contains("power_w_max"),
        "{msg}"
    );
}

#[test]
fn summarize_list_shows_five_and_counts_the_rest() {
    let items: Vec<u32> = (1..=7).collect();
    assert_eq!(summarize_list(&items), "1; 2; 3; 4; 5; … and 2 more");
    assert_eq!(summarize_list(&items[..5]), "1; 2; 3; 4; 5");
    assert_eq!(summarize_list::<u32>(&[]), "");
}

/// The bin-count limit is inclusive: 10⁶ bins are structurally admissible
/// (a broken field, not the count, is reported), 10⁶ + 1 are refused by count
/// before anything else is evaluated.
#[test]
fn bin_count_limit_is_inclusive() {
    use gaze_lidar_core::checker::MAX_PROFILE_BINS;
    let many = |n: usize| {
        let mut p = uniform();
        let w = 360.0 / n as f64;
        let b = p.bins[0].clone();
        p.bins = (0..n)
            .map(|i| Bin {
                start_deg: w * i as f64,
                width_deg: w,
                ..b.clone()
            })
            .collect();
        p
    };
    let mut p = many(MAX_PROFILE_BINS);
    p.bins[0].power_w = f64::NAN; // keeps the check structural (fast)
    let v = check(&p);
    assert!(
        v.iter().all(|x| matches!(
            x,
            Violation::BinField {
                field: "power_w",
                ..
            }
        )),
        "{:?}",
        &v[..v.len().min(3)]
    );
    let p = many(MAX_PROFILE_BINS + 1);
    assert_eq!(
        check(&p),
        vec![Violation::BinCount {
            count: MAX_PROFILE_BINS + 1
        }]
    );
}

/// A broken header stops the physical checks (their numbers would mean
/// nothing); a sensor mismatch or a missing eye-safety block does not.
#[test]
fn structural_violations_stop_evaluation_and_sensor_ones_do_not() {
    let mut p = uniform();
    p.limits.power_slew_w_per_deg_max = None;
    p.average_power_w = 1.0;
    p.bins[2].power_w = 3e-4; // above power_w_max
    p.format = "gaze-lidar/profile@0".into();
    assert_eq!(keys(&check(&p)), vec!["format"]);
    p.format = PROFILE_FORMAT.to_owned();
    assert_eq!(keys(&check(&p)), vec!["power_w_max"]);
    // Against a sensor with a stricter average budget: both are reported.
    let v = check_with(&p, &CheckOptions::for_sensor(&sensor()));
    assert!(keys(&v).contains(&"average_power_w"), "{v:?}");
    assert!(keys(&v).contains(&"power_w_max"), "{v:?}");
    // Missing eye safety, opted out: the limits are still checked.
    p.limits.eye_safety = None;
    let v = check_with(&p, &CheckOptions::declared().allow_missing_eye_safety(true));
    assert_eq!(keys(&v), vec!["power_w_max"]);
}

/// The sensor requires eye-safety parameters even when the caller opted
/// out of them for declared-limit checks.
#[test]
fn the_sensor_requires_eye_safety_even_with_the_opt_out() {
    let mut p = uniform();
    p.limits.eye_safety = None;
    let strict = sensor();
    let opts = CheckOptions::for_sensor(&strict).allow_missing_eye_safety(true);
    assert_eq!(check_with(&p, &opts), vec![Violation::EyeSafetyMissing]);
    // A sensor without eye-safety parameters does not require them.
    let mut s = sensor();
    s.limits.eye_safety = None;
    let opts = CheckOptions::for_sensor(&s).allow_missing_eye_safety(true);
    assert_eq!(check_with(&p, &opts), vec![]);
}

/// At the library: a NaN in the sensor's limits must not
/// let a profile through `certify_for_sensor` (the comparison used to be
/// `x > y`, false against NaN). Every comparison with a NaN sensor limit is
/// "looser", for upper and lower limits alike. (The CLI refuses such a
/// sensor file before this point; this is the checker not resting on it.)
#[test]
fn nan_sensor_limits_never_pass() {
    type Change = Box<dyn Fn(&mut LidarSpec)>;
    let cases: Vec<(&str, Change)> = vec![
        ("power_w_max", Box::new(|s| s.limits.power_w_max = f64::NAN)),
        ("power_w_min", Box::new(|s| s.limits.power_w_min = f64::NAN)),
        (
            "spin_rad_s_max",
            Box::new(|s| s.limits.spin_rad_s_max = f64::NAN),
        ),
        (
            "spin_rad_s_min",
            Box::new(|s| s.limits.spin_rad_s_min = f64::NAN),
        ),
        (
            "spin_accel_rad_s2_max",
            Box::new(|s| s.limits.spin_accel_rad_s2_max = Some(f64::NAN)),
        ),
        (
            "power_slew_w_per_deg_max",
            Box::new(|s| s.limits.power_slew_w_per_deg_max = Some(f64::NAN)),
        ),
        (
            "average_power_w",
            Box::new(|s| s.average_power_w = f64::NAN),
        ),
        ("pulse_rate_hz", Box::new(|s| s.pulse_rate_hz = f64::NAN)),
        ("frame_rate_hz", Box::new(|s| s.frame_rate_hz = f64::NAN)),
    ];
    for (key, change) in cases {
        let mut s = sensor();
        change(&mut s);
        let err = certify_for_sensor(uniform(), &s).unwrap_err();
        assert!(keys(&err.violations).contains(&key), "{key}: {err}");
        assert!(s.validate().is_err(), "{key}");
    }
}

/// Subnormal rates must not certify (`frame_rate_hz: 5e-324` would give an
/// infinite expected period, which matches any dwell sum within a relative
/// tolerance). Every rate outside 1e-9..=1e12 Hz and every
/// subnormal number of the header, limits and bins is a violation naming
/// its key; 1e-9 and 1e12 themselves are only judged by the other rules.
#[test]
fn subnormal_and_unphysical_numbers_are_rejected_naming_the_key() {
    for bad in [5e-324, 4e-309, 1e-300, 9.9e-10, 1.1e12] {
        let mut p = uniform();
        p.frame_rate_hz = bad;
        let v = check(&p);
        assert!(
            v.iter().any(|x| matches!(
                x,
                Violation::Header {
                    field: "frame_rate_hz",
                    ..
                }
            )),
            "{bad}: {v:?}"
        );
        let mut p = uniform();
        p.pulse_rate_hz = bad;
        assert!(keys(&check(&p)).contains(&"pulse_rate_hz"), "{bad}");
    }
    let sub = f64::from_bits(1);
    let mut p = uniform();
    p.average_power_w = sub;
    assert!(keys(&check(&p)).contains(&"average_power_w"));
    let mut p = uniform();
    p.limits.power_w_max = sub;
    assert!(check(&p).iter().any(|x| matches!(
        x,
        Violation::BadLimit {
            field: "power_w_max",
            ..
        }
    )));
    let mut p = uniform();
    p.limits.spin_accel_rad_s2_max = Some(sub);
    assert!(keys(&check(&p)).contains(&"spin_accel_rad_s2_max"));
    for field in 0..3 {
        let mut p = uniform();
        match field {
            0 => p.bins[4].power_w = sub,
            1 => p.bins[4].width_deg = sub,
            _ => p.bins[4].spin_end_rad_s = sub,
        }
        assert!(
            check(&p)
                .iter()
                .any(|x| matches!(x, Violation::BinField { bin: 4, .. })),
            "{field}"
        );
    }
    // Inverted limits are named once each (not also as NaN).
    let mut p = uniform();
    p.limits.power_w_min = 3e-4;
    p.limits.spin_rad_s_min = 90.0;
    let bad: Vec<_> = check(&p)
        .into_iter()
        .filter(|x| matches!(x, Violation::BadLimit { .. }))
        .collect();
    assert_eq!(bad.len(), 2, "{bad:?}");
}

/// `LidarSpec::validate`: each key refused for NaN, infinity, a negative or
/// subnormal value, or an inverted pair, and named in the error; a valid
/// sensor passes.
#[test]
fn sensor_validation_names_the_key() {
    assert_eq!(sensor().validate(), Ok(()));
    type Change = Box<dyn Fn(&mut LidarSpec, f64)>;
    let keys: Vec<(&str, Change)> = vec![
        ("frame_rate_hz", Box::new(|s, x| s.frame_rate_hz = x)),
        ("pulse_rate_hz", Box::new(|s, x| s.pulse_rate_hz = x)),
        ("average_power_w", Box::new(|s, x| s.average_power_w = x)),
        ("rated_range_m", Box::new(|s, x| s.rated_range_m = x)),
        (
            "reference_reflectivity",
            Box::new(|s, x| s.reference_reflectivity = x),
        ),
        (
            "limits.power_w_min",
            Box::new(|s, x| s.limits.power_w_min = x),
        ),
        (
            "limits.power_w_max",
            Box::new(|s, x| s.limits.power_w_max = x),
        ),
        (
            "limits.spin_rad_s_min",
            Box::new(|s, x| s.limits.spin_rad_s_min = x),
        ),
        (
            "limits.spin_rad_s_max",
            Box::new(|s, x| s.limits.spin_rad_s_max = x),
        ),
        (
            "limits.spin_accel_rad_s2_max",
            Box::new(|s, x| s.limits.spin_accel_rad_s2_max = Some(x)),
        ),
        (
            "limits.power_slew_w_per_deg_max",
            Box::new(|s, x| s.limits.power_slew_w_per_deg_max = Some(x)),
        ),
        (
            "limits.eye_safety.beam_diameter_mm",
            Box::new(|s, x| {
                s.limits.eye_safety.as_mut().unwrap().beam_diameter_mm = x;
            }),
        ),
        (
            "limits.eye_safety.wavelength_nm",
            Box::new(|s, x| s.limits.eye_safety.as_mut().unwrap().wavelength_nm = x),
        ),
    ];
    for (key, change) in &keys {
        for bad in [f64::NAN, f64::INFINITY, -1.0, f64::from_bits(1)] {
            let mut s = sensor();
            change(&mut s, bad);
            let e = s.validate().expect_err(key);
            assert_eq!(e.field, *key, "{bad}: {e}");
            assert!(e.to_string().starts_with(key), "{e}");
        }
    }
    let mut s = sensor();
    s.limits.power_w_min = 3e-4;
    assert_eq!(s.validate().unwrap_err().field, "limits.power_w_min");
    let mut s = sensor();
    s.limits.spin_rad_s_min = 90.0;
    assert_eq!(s.validate().unwrap_err().field, "limits.spin_rad_s_min");
    let mut s = sensor();
    s.reference_reflectivity = 1.5;
    assert_eq!(s.validate().unwrap_err().field, "reference_reflectivity");
    let mut s = sensor();
    s.channels = 0;
    assert_eq!(s.validate().unwrap_err().field, "channels");
    let mut s = sensor();
    s.limits.eye_safety = None;
    assert_eq!(s.validate().unwrap_err().field, "limits.eye_safety");
    // Unlimited (None) optional limits are valid.
    let mut s = sensor();
    s.limits.spin_accel_rad_s2_max = None;
    s.limits.power_slew_w_per_deg_max = None;
    assert_eq!(s.validate(), Ok(()));
}

/// One comparator for a profile and for its firmware table: a sensor whose
/// pulse clock, accounting or laser differs is named, field for field, the
/// same way by both checkers, and so is a declared limit looser than the
/// sensor's. (The table compared its pulse rate by bit pattern and the
/// profile by `!=`; both now call `lidar::laser_mismatches`.)
#[test]
fn profile_and_its_table_name_the_same_sensor_mismatches() {
    use gaze_lidar_core::firmware::sensor::against_sensor;
    use gaze_lidar_core::firmware::{FirmwareConfig, FirmwareTable, FwViolation};
    let certified = certify(uniform()).expect("uniform certifies");
    let table = FirmwareTable::from_certified(&certified, &FirmwareConfig::default())
        .expect("table builds");
    let fields = |v: Vec<FwViolation>| -> Vec<&'static str> {
        v.iter()
            .filter_map(|x| match x {
                FwViolation::SensorMismatch { field, .. } => Some(*field),
                _ => None,
            })
            .collect()
    };
    assert!(fields(against_sensor(&table, &sensor())).is_empty());
    type Change = Box<dyn Fn(&mut LidarSpec)>;
    let cases: Vec<(&str, Change)> = vec![
        (
            "pulse_rate_hz",
            Box::new(|s| s.pulse_rate_hz *= 1.0 + 1e-15),
        ),
        ("pulse_rate_hz", Box::new(|s| s.pulse_rate_hz = f64::NAN)),
        (
            "power_accounting",
            Box::new(|s| s.power_accounting = PowerAccounting::Time),
        ),
        (
            "eye_safety",
            Box::new(|s| {
                if let Some(e) = s.limits.eye_safety.as_mut() {
                    e.wavelength_nm += 1.0;
                }
            }),
        ),
    ];
    for (key, change) in cases {
        let mut s = sensor();
        change(&mut s);
        let profile = check_with(certified.profile(), &CheckOptions::for_sensor(&s));
        let profile_fields: Vec<&str> = profile
            .iter()
            .filter_map(|x| match x {
                Violation::SensorMismatch { field, .. } => Some(*field),
                _ => None,
            })
            .collect();
        assert_eq!(profile_fields, vec![key], "profile: {profile:?}");
        assert_eq!(fields(against_sensor(&table, &s)), vec![key], "table");
    }
}

/// A table's `power_code_min` is a lower limit: against a sensor it must be
/// at least the sensor's minimum power rounded **up** to a code (the loose
/// direction would let a bin run below the sensor's minimum). A minimum of
/// 2.5 codes needs a table minimum of 3: 2 is looser than the sensor, 3
/// is not; a minimum of exactly 2 codes accepts 2. The quantizer rounds
/// its own minimum the same way, so a table built for a sensor passes it.
#[test]
fn table_minimum_code_is_the_sensors_minimum_power_rounded_up() {
    use gaze_lidar_core::firmware::sensor::against_sensor;
    use gaze_lidar_core::firmware::{ceil_code, FirmwareConfig, FirmwareTable, FwViolation};
    let certified = certify(uniform()).expect("uniform certifies");
    let mut table = FirmwareTable::from_certified(&certified, &FirmwareConfig::default())
        .expect("table builds");
    let step = table.power_w_per_code;
    let looser = |t: &FirmwareTable, s: &LidarSpec| {
        against_sensor(t, s).iter().any(|x| {
            matches!(
                x,
                FwViolation::LooserThanSensor {
                    field: "limits.power_code_min",
                    ..
                }
            )
        })
    };
    for (min_codes, table_min, want_looser) in [
        (2.5, 2, true),
        (2.5, 3, false),
        (2.0, 2, false),
        (2.0, 1, true),
    ] {
        let mut s = sensor();
        s.limits.power_w_min = min_codes * step;
        table.limits.power_code_min = table_min;
        assert_eq!(
            looser(&table, &s),
            want_looser,
            "{min_codes} codes, table {table_min}"
        );
    }
    assert_eq!(ceil_code(2.5 * step, step), Some(3));
    assert_eq!(ceil_code(2.0 * step, step), Some(2));
    assert_eq!(ceil_code(0.0, step), Some(0));
    // Built against a limit of 2.5 codes: the table's minimum is 3 and it
    // passes the sensor.
    let mut p = uniform();
    p.limits.power_w_min = 2.5 * step;
    let mut s = sensor();
    s.limits.power_w_min = p.limits.power_w_min;
    let c = certify_for_sensor(p, &s).expect("certifies");
    let t = FirmwareTable::from_certified(&c, &FirmwareConfig::default()).expect("builds");
    assert_eq!(t.limits.power_code_min, 3);
    assert!(!looser(&t, &s));
}

/// The one serialisable verdict: certified and rejected alike, built from
/// the checker's own evaluation. A profile rejected for a non-eye-safety
/// limit still carries the eye-safety figures the checker computed, and
/// the JSON names every violation's key with its message and typed detail.
#[test]
fn verdict_is_the_checkers_own_result_as_data() {
    use gaze_lidar_core::checker::Verdict;
    let p = uniform();
    let ok = certify_with(p.clone(), &CheckOptions::declared());
    let v = Verdict::of(&ok, &p, None);
    let c = ok.as_ref().expect("uniform certifies");
    assert!(v.certified && v.violations.is_empty() && v.eye_safety_evaluated);
    assert_eq!(v.summary.as_ref(), Some(c.summary()));
    let eye = v.eye_safety.as_ref().expect("evaluated");
    let report = c.eye_safety().expect("evaluated");
    assert_eq!(eye.worst_ratio.to_bits(), report.worst_ratio.to_bits());
    assert_eq!(eye.binding_rule, report.binding_rule);
    assert_eq!(eye.evaluated_for, "one channel");
    assert!(eye.head.is_none());

    // Over the power limit but eye-safe: rejected, eye figures kept.
    let mut q = uniform();
    q.limits.power_w_max = 0.5 * q.bins[0].power_w;
    let rej = certify_with(q.clone(), &CheckOptions::for_sensor(&sensor()));
    let v = Verdict::of(&rej, &q, Some(&sensor()));
    let err = rej.as_ref().unwrap_err();
    assert!(!v.certified);
    assert_eq!(v.violations.len(), err.violations.len());
    assert!(v.violations.iter().any(|e| e.limit == "power_w_max"));
    assert_eq!(v.sensor.as_deref(), Some("test"));
    let eye = v
        .eye_safety
        .as_ref()
        .expect("the checker evaluated eye safety");
    assert!(eye.worst_ratio < 1.0, "{}", eye.worst_ratio);
    let json = serde_json::to_value(&v).unwrap();
    assert_eq!(json["certified"], false);
    let first = &json["violations"][0];
    assert_eq!(first["limit"], v.violations[0].limit);
    assert_eq!(first["message"], v.violations[0].message);
    assert!(first["detail"]["kind"].is_string());
    assert_eq!(json["eye_safety"]["evaluated_for"], "one channel");
}
