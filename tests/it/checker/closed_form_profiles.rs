//! The paper's closed-form profiles through the binary.

use crate::common;
use crate::independent;

use common::{assert_bad_input, run, stdout};
use gaze_lidar::model::angle::diff_deg;
use gaze_lidar::profile::{Profile, Region};

fn profile(mode: &str, gaze: &str) -> Profile {
    common::profile_from(&[
        "profile",
        "--preset",
        "paper",
        "--mode",
        mode,
        "--gaze-deg",
        gaze,
        "--format",
        "json",
    ])
}

fn distinct(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

#[test]
fn paper_profiles_match_the_paper() {
    for mode in ["range", "resolution", "joint"] {
        for gaze in [90.0, 0.0, 350.0, 200.0] {
            let p = profile(mode, &gaze.to_string());
            // Within every declared limit, recomputed independently of the
            // checker the binary ran before writing the file.
            let broken = independent::recheck(&p);
            assert!(broken.is_empty(), "{mode} {gaze}: {broken:?}");
            let p_mean = p.average_power_w;
            let w_mean = std::f64::consts::TAU * p.frame_rate_hz;
            // RoF exactly ±30° about the gaze (also through 0°).
            let rof: Vec<_> = p
                .bins
                .iter()
                .filter(|b| b.region == Some(Region::Rof))
                .collect();
            let roi: Vec<_> = p
                .bins
                .iter()
                .filter(|b| b.region == Some(Region::Roi))
                .collect();
            let rof_deg: f64 = rof.iter().map(|b| b.width_deg).sum();
            assert!(
                (rof_deg - 60.0).abs() < 1e-9,
                "{mode} {gaze}: RoF {rof_deg}"
            );
            for b in &rof {
                assert!(diff_deg(b.start_deg, gaze).abs() <= 30.0 + 1e-9);
                assert!(diff_deg(b.start_deg + b.width_deg, gaze).abs() <= 30.0 + 1e-9);
            }
            for b in &roi {
                assert!(diff_deg(b.center_deg(), gaze).abs() > 30.0);
            }
            let rof_p = distinct(rof.iter().map(|b| b.power_w));
            let roi_p = distinct(roi.iter().map(|b| b.power_w));
            let rof_w = distinct(rof.iter().map(|b| b.spin_start_rad_s));
            let roi_w = distinct(roi.iter().map(|b| b.spin_start_rad_s));
            assert_eq!(
                (rof_p.len(), roi_p.len(), rof_w.len(), roi_w.len()),
                (1, 1, 1, 1)
            );
            assert!(p
                .bins
                .iter()
                .all(|b| b.spin_start_rad_s == b.spin_end_rad_s));
            if mode == "resolution" {
                assert_eq!(rof_p, roi_p, "uniform power in resolution mode");
            } else {
                assert!(roi_p[0] > rof_p[0], "RoI above RoF");
                assert!((rof_p[0] - 0.5 * p_mean).abs() < 1e-15);
            }
            if mode == "range" {
                assert_eq!(rof_w, roi_w, "uniform spin in range mode");
                assert!((rof_w[0] - w_mean).abs() < 1e-12);
            } else {
                assert!(rof_w[0] > roi_w[0], "RoF spins faster");
                assert!((rof_w[0] / roi_w[0] - 5.4).abs() < 1e-12);
            }
            // Eq. 4 (angle accounting) and eq. 6 as equalities.
            let eq4: f64 = p.bins.iter().map(|b| b.power_w * b.width_deg).sum::<f64>() / 360.0;
            assert!(
                (eq4 / p_mean - 1.0).abs() < 1e-12,
                "{mode} {gaze}: eq4 {eq4}"
            );
            let eq6: f64 = p
                .bins
                .iter()
                .map(|b| b.width_deg.to_radians() / b.spin_start_rad_s)
                .sum();
            assert!(
                (eq6 * w_mean / std::f64::consts::TAU - 1.0).abs() < 1e-12,
                "eq6 {eq6}"
            );
            let s = p.summary.as_ref().unwrap();
            assert!(s.average_power_time_w > 0.0 && s.average_power_angle_w > 0.0);
        }
    }
}

#[test]
fn csv_has_one_row_per_bin() {
    let o = run(
        &[
            "profile",
            "--mode",
            "joint",
            "--gaze-deg",
            "47.5",
            "--format",
            "csv",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    let text = stdout(&o);
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "start_deg,width_deg,power_w,spin_start_rad_s,spin_end_rad_s,region,dwell_s"
    );
    // 360 bins + the two RoF edges at 17.5° and 77.5°.
    assert_eq!(lines.count(), 362);
}

#[test]
fn check_rejects_tripled_power_naming_the_limit() {
    let mut p = profile("range", "90");
    p.bins[200].power_w *= 3.0;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tampered.json");
    std::fs::write(&path, p.to_json().unwrap()).unwrap();
    let o = run(&["check", path.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(1));
    let out = stdout(&o);
    assert!(
        out.contains("bins[200].power_w") && out.contains("power_w_max"),
        "{out}"
    );
    assert!(out.contains("average_power_w"), "{out}");
    assert!(out.lines().all(|l| l.starts_with("violation: ")));
    // The untampered file passes.
    let ok = profile("range", "90");
    std::fs::write(&path, ok.to_json().unwrap()).unwrap();
    let o = run(&["check", path.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    // stdin works too.
    let o = run(
        &["check", "-", "--format", "json"],
        Some(&ok.to_json().unwrap()),
    );
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["certified"], true);
}

#[test]
fn bad_arguments_exit_2_without_panic() {
    let cases: &[(&[&str], &str)] = &[
        (&["profile", "--gaze-deg", "NaN"], "gaze-deg"),
        (&["profile", "--gaze-deg", "inf"], "gaze-deg"),
        (&["profile", "--gaze-deg", "1e300"], "gaze-deg"),
        (&["profile", "--gaze-deg", "abc"], "gaze-deg"),
        (&["profile", "--gaze-deg", "90", "--bins", "0"], "bins"),
        (&["profile", "--gaze-deg", "90", "--bins", "3"], "bins"),
        (
            &["profile", "--gaze-deg", "90", "--bins", "10000000"],
            "bins",
        ),
        (&["profile", "--gaze-deg", "90", "--bins", "-1"], "bins"),
        (&["profile", "--gaze-deg", "90", "--mode", "warp"], "mode"),
        (
            &["profile", "--gaze-deg", "90", "--preset", "nope"],
            "preset",
        ),
        (&["profile", "--mode", "range"], "gaze-deg"),
        (
            &["check", "/nonexistent/profile.json"],
            "/nonexistent/profile.json",
        ),
    ];
    for (args, needle) in cases {
        assert_bad_input(&run(args, None), needle);
    }
}

#[test]
fn malformed_profiles_name_line_and_field() {
    let good = profile("range", "0").to_json().unwrap();
    let truncated = &good[..good.len() / 2];
    let o = run(&["check", "-"], Some(truncated));
    assert_bad_input(&o, "<stdin>:");
    let missing_limit = good.replace("\"spin_accel_rad_s2_max\": null,", "");
    let o = run(&["check", "-"], Some(&missing_limit));
    assert_bad_input(&o, "spin_accel_rad_s2_max");
    let wrong_format = good.replace("gaze-lidar/profile@1", "other@2");
    assert_bad_input(&run(&["check", "-"], Some(&wrong_format)), "format");
    let o = run(&["check", "-"], Some("[1, 2"));
    assert_bad_input(&o, "<stdin>:1:");
    // Bins that do not cover the circle: a structural violation, exit 1.
    let mut p = Profile::from_json(&good, "x").unwrap();
    p.bins.remove(17);
    let o = run(&["check", "-"], Some(&p.to_json().unwrap()));
    assert_eq!(o.status.code(), Some(1));
    assert!(stdout(&o).contains("bins[17].start_deg"), "{}", stdout(&o));
}

#[test]
fn out_is_atomic_and_never_partial() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.json");
    let o = run(
        &[
            "profile",
            "--gaze-deg",
            "NaN",
            "--out",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    let missing_dir = dir.path().join("no/such/dir/p.json");
    let o = run(
        &[
            "profile",
            "--gaze-deg",
            "90",
            "--out",
            missing_dir.to_str().unwrap(),
        ],
        None,
    );
    assert_bad_input(&o, "no/such/dir");
    assert!(
        std::fs::read_dir(dir.path()).unwrap().count() == 0,
        "left a file behind"
    );
    let o = run(
        &[
            "profile",
            "--gaze-deg",
            "90",
            "--out",
            out.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    Profile::read_json(&out).unwrap();
    assert!(stdout(&o).is_empty());
}

#[test]
fn output_is_deterministic() {
    let a = stdout(&run(
        &[
            "profile",
            "--mode",
            "joint",
            "--gaze-deg",
            "123.4",
            "--bins",
            "999",
        ],
        None,
    ));
    let b = stdout(&run(
        &[
            "profile",
            "--mode",
            "joint",
            "--gaze-deg",
            "123.4",
            "--bins",
            "999",
        ],
        None,
    ));
    assert_eq!(a, b);
    let p = Profile::from_json(&a, "a").unwrap();
    assert_eq!(
        Profile::from_json(&p.to_json().unwrap(), "b").unwrap(),
        p,
        "JSON round trip"
    );
}

/// `profile --preset P --mode M --optimize` answers for
/// every preset × mode; where a finite acceleration limit forbids the
/// closed form's spin set-points they are dropped (ramps instead) with one
/// line on stderr; the text summary labels every gap.
#[cfg(feature = "solver")]
#[test]
fn every_preset_and_mode_optimizes_from_the_command_line() {
    for preset in gaze_lidar::model::presets::PRESET_NAMES {
        let accel = gaze_lidar::model::presets::preset(preset)
            .unwrap()
            .lidar
            .limits
            .spin_accel_rad_s2_max
            .is_some();
        for mode in ["range", "resolution", "joint"] {
            let o = run(
                &[
                    "profile",
                    "--preset",
                    preset,
                    "--mode",
                    mode,
                    "--gaze-deg",
                    "90",
                    "--optimize",
                    "--format",
                    "text",
                ],
                None,
            );
            let err = common::stderr(&o);
            assert!(o.status.success(), "{preset} {mode}: {err}");
            let text = stdout(&o);
            // Every gap labelled; an optimality block in every mode.
            for l in text.lines() {
                assert_eq!(
                    l.matches(", gap ").count(),
                    l.matches(" absolute (").count(),
                    "{preset} {mode}: {l}"
                );
            }
            assert!(
                text.contains(" relative to the bound)"),
                "{preset} {mode}: {text}"
            );
            let note = err.lines().filter(|l| l.contains("ramps the spin")).count();
            let dropped = accel && mode != "range";
            assert_eq!(note, usize::from(dropped), "{preset} {mode}: {err}");
        }
    }
}

/// A closed form the sensor's limits reject says so in one
/// line: the first violated limit, the count of the rest, and a command
/// that works (run here).
#[cfg(feature = "solver")]
#[test]
fn a_rejected_closed_form_names_its_first_violation_and_a_command_that_works() {
    let o = run(
        &[
            "profile",
            "--preset",
            "vls128",
            "--mode",
            "joint",
            "--gaze-deg",
            "90",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    let err = common::stderr(&o);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.len() < 600, "{} characters: {err}", err.len());
    assert!(err.contains("violates the sensor's limits"), "{err}");
    let cmd = err
        .split("the optimizer meets them: ")
        .nth(1)
        .unwrap_or_else(|| panic!("no command: {err}"))
        .trim();
    let args: Vec<&str> = cmd.split_whitespace().skip(1).collect();
    assert_eq!(args.last(), Some(&"--optimize"), "{cmd}");
    let o = run(&args, None);
    assert!(o.status.success(), "{cmd}: {}", common::stderr(&o));
}
