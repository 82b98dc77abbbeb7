//! Core-level tests of `profile` (the `Bin` helpers and the JSON format),
//! `profile::kinematics` (the `Timeline` of a profile worked by hand) and
//! `model::accounting` (found by `cargo mutants`). Expected values by hand.

use gaze_lidar_core::model::lidar::{Limits, PowerAccounting};
use gaze_lidar_core::profile::{Bin, IoError, Profile, PROFILE_FORMAT};
use std::f64::consts::PI;

fn bin(start: f64, width: f64, w0: f64, w1: f64) -> Bin {
    Bin {
        start_deg: start,
        width_deg: width,
        power_w: 1e-4,
        spin_start_rad_s: w0,
        spin_end_rad_s: w1,
        region: None,
        dwell_s: None,
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn bin_helpers_by_hand() {
    // 90° from 10 to 30 rad/s: dwell 2·(π/2)/40 = π/40 s; acceleration
    // (900 − 100)/(2·π/2) = 800/π rad/s²; centre 20° + 45° = 65°.
    let b = bin(20.0, 90.0, 10.0, 30.0);
    assert!(close(b.dwell_time_s(), PI / 40.0), "{}", b.dwell_time_s());
    assert!(close(b.spin_accel_rad_s2(), 800.0 / PI));
    assert_eq!(b.center_deg(), 65.0);
    // Decelerating: 180° from 30 to 10 rad/s: dwell 2π/40, acceleration −800/(2π).
    let d = bin(0.0, 180.0, 30.0, 10.0);
    assert!(close(d.dwell_time_s(), PI / 20.0));
    assert!(close(d.spin_accel_rad_s2(), -400.0 / PI));
    assert_eq!(d.center_deg(), 90.0);
    assert_eq!(bin(300.0, 4.0, 1.0, 1.0).center_deg(), 302.0);
}

#[test]
fn accounting_displays_its_name() {
    assert_eq!(PowerAccounting::Time.to_string(), "time");
    assert_eq!(PowerAccounting::Angle.to_string(), "angle");
}

fn profile() -> Profile {
    Profile {
        format: PROFILE_FORMAT.to_owned(),
        frame_rate_hz: 10.0,
        pulse_rate_hz: 20_000.0,
        average_power_w: 1e-4,
        power_accounting: PowerAccounting::Angle,
        gaze_deg: Some(12.5),
        limits: Limits {
            eye_safety: None,
            ..gaze_lidar_core::testing::limits((0.5e-4, 2e-4), (50.0, 80.0))
        },
        bins: vec![bin(0.0, 360.0, 62.5, 62.5)],
        mode: Some("test".into()),
        summary: None,
        optimality: None,
    }
}

#[test]
fn json_round_trips_and_reads_the_gaze() {
    let p = profile();
    let s = p.to_json().expect("json");
    assert!(s.ends_with("}\n"), "{s}");
    assert!(s.contains("\"gaze_deg\": 12.5"), "{s}");
    assert_eq!(Profile::from_json(&s, "x").expect("parses"), p);
    // A gaze-free profile writes and reads `null`.
    let mut free = p.clone();
    free.gaze_deg = None;
    let s = free.to_json().expect("json");
    assert!(s.contains("\"gaze_deg\": null"), "{s}");
    assert_eq!(Profile::from_json(&s, "x").expect("parses").gaze_deg, None);
    // The key itself is required.
    let missing = s.replace("\"gaze_deg\": null,", "");
    assert_ne!(missing, s);
    match Profile::from_json(&missing, "in.json") {
        Err(IoError::Json { path, message, .. }) => {
            assert_eq!(path, "in.json");
            assert!(message.contains("gaze_deg"), "{message}");
        }
        other => panic!("expected a JSON error, got {other:?}"),
    }
}

#[test]
fn json_errors_name_the_place_once() {
    let s = profile().to_json().expect("json");
    // Line 3 of the pretty output is `"frame_rate_hz": 10.0,`.
    let bad = s.replacen("\"frame_rate_hz\": 10.0", "\"frame_rate_hz\": \"ten\"", 1);
    match Profile::from_json(&bad, "in.json") {
        Err(IoError::Json {
            path,
            line,
            column,
            message,
        }) => {
            assert_eq!(path, "in.json");
            assert_eq!(line, 3);
            assert!(column > 0);
            assert!(message.starts_with("invalid type"), "{message}");
            assert!(!message.contains(" at line "), "{message}");
        }
        other => panic!("expected a JSON error, got {other:?}"),
    }
    let other = s.replace(PROFILE_FORMAT, "gaze-lidar/profile@2");
    match Profile::from_json(&other, "in.json") {
        Err(IoError::Format { path, found }) => {
            assert_eq!(path, "in.json");
            assert_eq!(found, "gaze-lidar/profile@2");
        }
        other => panic!("expected a format error, got {other:?}"),
    }
}

#[test]
fn read_json_reads_a_file_or_names_it() {
    let dir = std::env::temp_dir().join(format!("gaze-lidar-core-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("p.json");
    let p = profile();
    std::fs::write(&path, p.to_json().expect("json")).expect("written");
    assert_eq!(Profile::read_json(&path).expect("reads"), p);
    let missing = dir.join("missing.json");
    match Profile::read_json(&missing) {
        Err(IoError::File { path, .. }) => assert!(path.ends_with("missing.json"), "{path}"),
        other => panic!("expected a file error, got {other:?}"),
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Four bins whose timeline is worked by hand (spins in °/s, written as rad/s):
/// - `[0, 90)` at 90 °/s, 1 W: 1 s, 1 J;
/// - `[90, 180)` at 45 °/s, 2 W: 2 s, 4 J;
/// - `[180, 270)` from 45 to 135 °/s, 3 W: dwell 2·90/(45 + 135) = 1 s, 3 J;
///   a = (135² − 45²)/(2·90) = 90 °/s², x(t) = 45t + 45t², ω(x)² = 45² + 180x:
///   x = 20° at ω = 75, t = 2·20/(45 + 75) = 1/3 s; x = 50° at t = 2/3 s;
/// - `[270, 360)` from 135 to 45 °/s, 0.5 W: 1 s, 0.5 J; x(t) = 135t − 45t²:
///   x = 40° at t = 1/3 s (ω = 105), x(0.5) = 56.25°.
///
/// Bin starts at 0, 1, 3, 4 s, period 5 s; energies 0, 1, 5, 8, 8.5 J.
fn hand_bins() -> Vec<Bin> {
    let d = f64::to_radians;
    let b = |start: f64, w0: f64, w1: f64, p: f64| Bin {
        power_w: p,
        ..bin(start, 90.0, d(w0), d(w1))
    };
    vec![
        b(0.0, 90.0, 90.0, 1.0),
        b(90.0, 45.0, 45.0, 2.0),
        b(180.0, 45.0, 135.0, 3.0),
        b(270.0, 135.0, 45.0, 0.5),
    ]
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-11 * b.abs().max(1.0)
}

macro_rules! assert_near {
    ($a:expr, $b:expr) => {{
        let (a, b): (f64, f64) = ($a, $b);
        assert!(near(a, b), "{} = {a}, expected {b}", stringify!($a));
    }};
}

/// `Timeline`: cumulative time and energy, time/energy at an azimuth and over
/// windows (found by `cargo mutants` on `profile/kinematics.rs`: the core's
/// tests reached these only through the eye-safety bound, or not at all).
#[test]
fn timeline_times_and_energies_by_hand() {
    use gaze_lidar_core::profile::kinematics::Timeline;
    let bins = hand_bins();
    let tl = Timeline::from_bins(&bins);
    assert_eq!(tl.bins().len(), 4);
    assert_near!(tl.period_s(), 5.0);
    assert_near!(tl.energy_per_turn_j(), 8.5);
    for (i, t) in [0.0, 1.0, 3.0, 4.0, 5.0].into_iter().enumerate() {
        assert_near!(tl.bin_start_time_s(i), t);
    }
    // Bin of an azimuth: an edge belongs to the bin it starts; 360 → last bin.
    let idx: Vec<usize> = [0.0, 89.9, 90.0, 269.9, 270.0, 360.0]
        .iter()
        .map(|&a| tl.bin_index(a))
        .collect();
    assert_eq!(idx, [0, 0, 1, 2, 3, 3]);
    for (az, t, e) in [
        (0.0, 0.0, 0.0),
        (45.0, 0.5, 0.5),
        (90.0, 1.0, 1.0),
        (135.0, 2.0, 3.0),
        (200.0, 3.0 + 1.0 / 3.0, 5.0 + 1.0),
        (230.0, 3.0 + 2.0 / 3.0, 5.0 + 2.0),
        (310.0, 4.0 + 1.0 / 3.0, 8.0 + 1.0 / 6.0),
        (360.0, 5.0, 8.5),
    ] {
        let (tt, ee) = tl.time_energy_at(az);
        assert!(
            near(tt, t) && near(ee, e),
            "{az}: ({tt}, {ee}) vs ({t}, {e})"
        );
    }
    // Windows: [45, 135): 1.5 s, 2.5 J; [310, 50) through 0°: 2/3 s + 5/9 s
    // (50° at 90 °/s), 1/3 J + 5/9 J; wider than a turn: one turn.
    let (t, e) = tl.window(45.0, 90.0);
    assert!(near(t, 1.5) && near(e, 2.5), "({t}, {e})");
    for lo in [310.0, -50.0, 670.0] {
        let (t, e) = tl.window(lo, 100.0);
        let (te, ee) = (2.0 / 3.0 + 5.0 / 9.0, 1.0 / 3.0 + 5.0 / 9.0);
        assert!(
            near(t, te) && near(e, ee),
            "{lo}: ({t}, {e}) vs ({te}, {ee})"
        );
    }
    let (t, e) = tl.window(10.0, 400.0);
    assert!(near(t, 5.0) && near(e, 8.5), "({t}, {e})");
    let (t, e) = tl.window(200.0, 0.0);
    assert!(near(t + 1.0, 1.0) && near(e + 1.0, 1.0), "({t}, {e})");
}

/// `Timeline`: unwrapped time ↔ azimuth, with and without a search hint.
#[test]
fn timeline_unwrapped_time_and_azimuth_by_hand() {
    use gaze_lidar_core::profile::kinematics::Timeline;
    let bins = hand_bins();
    let tl = Timeline::from_bins(&bins);
    // (azimuth, unwrapped time): turn k starts at 5k s.
    let pairs = [
        (-50.0, -5.0 + 4.0 + 1.0 / 3.0),
        (0.0, 0.0),
        (45.0, 0.5),
        (135.0, 2.0),
        (200.0, 3.0 + 1.0 / 3.0),
        (230.0, 3.0 + 2.0 / 3.0),
        (326.25, 4.5),
        (360.0 + 45.0, 5.5),
        (720.0 + 200.0, 10.0 + 3.0 + 1.0 / 3.0),
    ];
    let mut hint = 0;
    let mut hint_t = 0;
    for &(az, t) in &pairs {
        assert_near!(tl.time_at_unwrapped_s(az), t);
        assert_near!(tl.time_at_unwrapped_from_s(az, &mut hint), t);
        assert_near!(tl.azimuth_at_unwrapped_deg(t), az);
        assert_near!(tl.azimuth_at_unwrapped_from_deg(t, &mut hint_t), az);
    }
    // Just before 0°: the turn is −1 and the time within it rounds to the
    // period itself (−1e-20 + 5 = 5 in f64), which must stay in the last bin.
    assert_near!(tl.azimuth_at_unwrapped_deg(-1e-20), 0.0);
    assert_near!(tl.azimuth_at_unwrapped_from_deg(-1e-20, &mut 0), 0.0);
    assert_near!(tl.time_at_unwrapped_s(-1e-20), 0.0);
    // Hints left on the last bin still find earlier bins.
    let (mut h, mut ht) = (3, 3);
    assert_near!(tl.time_at_unwrapped_from_s(45.0, &mut h), 0.5);
    assert_eq!(h, 0);
    assert_near!(tl.azimuth_at_unwrapped_from_deg(2.0, &mut ht), 135.0);
    assert_eq!(ht, 1);
    // A hint beyond the bins is clamped.
    let mut big = 99;
    assert_near!(tl.azimuth_at_unwrapped_from_deg(4.5, &mut big), 326.25);
    assert_eq!(big, 3);
    // locate: (whole turns, bin, offset into the bin in degrees).
    for (theta, k, i, x) in [
        (200.0, 0.0, 2, 20.0),
        (-40.0, -1.0, 3, 50.0),
        (810.0, 2.0, 1, 0.0),
        (359.0, 0.0, 3, 89.0),
        (0.0, 0.0, 0, 0.0),
    ] {
        let (kk, ii, xx) = tl.locate_unwrapped(theta);
        assert!(
            kk == k && ii == i && near(xx, x),
            "{theta}: ({kk}, {ii}, {xx})"
        );
        for start in [0, 2, 3, 7] {
            let mut h = start;
            let (kk, ii, xx) = tl.locate_unwrapped_from(theta, &mut h);
            assert!(
                kk == k && ii == i && near(xx, x) && h == i,
                "{theta} from {start}"
            );
        }
    }
    // Azimuth within the turn and its bin; an edge time starts the next bin.
    for (t, az, i) in [
        (0.0, 0.0, 0),
        (0.5, 45.0, 0),
        (1.0, 90.0, 1),
        (2.0, 135.0, 1),
        (3.0 + 2.0 / 3.0, 230.0, 2),
        (4.5, 326.25, 3),
    ] {
        let (a, j) = tl.azimuth_at(t);
        assert!(near(a, az) && j == i, "{t}: ({a}, {j})");
        for hint in [0, 1, 3, 9] {
            let (a, j) = tl.azimuth_at_from(t, hint);
            assert!(near(a, az) && j == i, "{t} from {hint}: ({a}, {j})");
        }
    }
}

/// `Timeline::bins_touching` and `max_power_in`: closed arcs, edges included.
#[test]
fn timeline_bins_touching_by_hand() {
    use gaze_lidar_core::profile::kinematics::Timeline;
    let bins = hand_bins();
    let tl = Timeline::from_bins(&bins);
    assert_eq!(tl.bins_touching(100.0, 50.0), [1]);
    assert_eq!(tl.bins_touching(80.0, 20.0), [0, 1]);
    // [90, 180] touches bin 0 at 90 and bin 2 at 180.
    assert_eq!(tl.bins_touching(90.0, 90.0), [0, 1, 2]);
    assert_eq!(tl.bins_touching(350.0, 20.0), [3, 0]);
    assert_eq!(tl.bins_touching(-10.0, 20.0), [3, 0]);
    assert_eq!(tl.bins_touching(710.0, 20.0), [3, 0]);
    assert_eq!(tl.bins_touching(0.0, 360.0), [3, 0, 1, 2]);
    assert_eq!(tl.bins_touching(300.0, 10.0), [3]);
    // Powers 1, 2, 3, 0.5 W.
    assert_eq!(tl.max_power_in(100.0, 50.0), 2.0);
    assert_eq!(tl.max_power_in(80.0, 20.0), 2.0);
    assert_eq!(tl.max_power_in(180.0, 10.0), 3.0);
    assert_eq!(tl.max_power_in(350.0, 20.0), 1.0);
    assert_eq!(tl.max_power_in(300.0, 10.0), 0.5);
    assert_eq!(tl.max_power_in(0.0, 360.0), 3.0);
}

/// The per-bin kinematics (`time_into_bin_s`, `angle_into_bin_rad`) by hand.
#[test]
fn bin_kinematics_by_hand() {
    use gaze_lidar_core::profile::kinematics::{angle_into_bin_rad, time_into_bin_s, BinMotion};
    let bins = hand_bins();
    let d = f64::to_radians;
    let (acc, dec) = (&bins[2], &bins[3]);
    assert_near!(acc.dwell_s(), 1.0);
    assert_near!(acc.accel_rad_s2(), d(90.0));
    assert_near!(dec.accel_rad_s2(), d(-90.0));
    assert_near!(time_into_bin_s(acc, d(20.0)), 1.0 / 3.0);
    assert_near!(time_into_bin_s(acc, d(50.0)), 2.0 / 3.0);
    assert_near!(time_into_bin_s(acc, d(90.0)), 1.0);
    assert_near!(time_into_bin_s(dec, d(40.0)), 1.0 / 3.0);
    assert_near!(time_into_bin_s(&bins[1], d(30.0)), 30.0 / 45.0);
    assert_eq!(time_into_bin_s(acc, 0.0), 0.0);
    assert_eq!(time_into_bin_s(acc, -1.0), 0.0);
    assert_near!(angle_into_bin_rad(acc, 1.0 / 3.0), d(20.0));
    assert_near!(angle_into_bin_rad(acc, 2.0 / 3.0), d(50.0));
    assert_near!(angle_into_bin_rad(dec, 0.5), d(56.25));
    assert_near!(angle_into_bin_rad(&bins[1], 1.0), d(45.0));
    // Clamped to the dwell: never beyond the bin, never before it.
    assert_near!(angle_into_bin_rad(acc, 5.0), d(90.0));
    assert_near!(angle_into_bin_rad(dec, 5.0), d(90.0));
    assert_eq!(angle_into_bin_rad(acc, -1.0), 0.0);
    assert_eq!(
        (acc.start_deg(), acc.width_deg(), acc.power_w()),
        (180.0, 90.0, 3.0)
    );
    assert_near!(acc.spin_start_rad_s(), d(45.0));
    assert_near!(acc.spin_end_rad_s(), d(135.0));
}
