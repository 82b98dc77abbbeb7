//! Core-level tests of `profile` (the `Bin` helpers and the JSON format) and
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
            power_w_min: 0.5e-4,
            power_w_max: 2e-4,
            spin_rad_s_min: 50.0,
            spin_rad_s_max: 80.0,
            spin_accel_rad_s2_max: None,
            power_slew_w_per_deg_max: None,
            eye_safety: None,
        },
        bins: vec![bin(0.0, 360.0, 62.5, 62.5)],
        mode: Some("test".into()),
        summary: None,
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
