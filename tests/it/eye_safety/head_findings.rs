//! What a file checked against a sensor with a head is told: a laser
//! parameter set that differs from the sensor's is named by its first
//! differing field, in one line.

use gaze_lidar::checker::{certify_with, CheckOptions};
use gaze_lidar::model::presets::preset;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;

/// A stricter head (one channel at half power) is still not the sensor's:
/// refused naming `limits.eye_safety.head.channels[3].power_scale`, with
/// both values, and without a dump of either parameter set. (Before, the
/// line held two whole `EyeSafetyParams` Debug dumps.)
#[test]
fn a_head_differing_from_the_presets_names_the_first_differing_field() {
    let p = preset("vls128").unwrap();
    let mut profile = build_profile(&p, Mode::Range, Some(90.0), 360).unwrap();
    let head = profile
        .limits
        .eye_safety
        .as_mut()
        .and_then(|e| e.head.as_mut())
        .expect("vls128 has a head");
    head.channels[3].power_scale = 0.5;
    let rejected = certify_with(profile, &CheckOptions::for_sensor(&p.lidar)).unwrap_err();
    let lines: Vec<String> = rejected
        .violations
        .iter()
        .map(ToString::to_string)
        .collect();
    let line = lines
        .iter()
        .find(|l| l.contains("limits.eye_safety.head"))
        .unwrap_or_else(|| panic!("{lines:?}"));
    assert!(
        line.contains(
            "limits.eye_safety.head.channels[3].power_scale: 0.5 differs from the sensor's 1"
        ),
        "{line}"
    );
    assert!(!line.contains("EyeSafetyParams"), "{line}");
    assert!(!line.contains('\n'), "{line}");
    assert!(line.len() < 300, "{line}");
}

/// A DAC step so coarse that every bin's power rounds down to code 0 would
/// write a laser-off table (exit 0, silently, before): refused as bad input
/// naming `--power-w-per-code` and why; a fine step still writes the table.
#[test]
fn a_firmware_step_that_zeroes_every_code_is_refused_by_name() {
    let args = |step: &'static str| {
        [
            "profile",
            "--preset",
            "os1-128",
            "--mode",
            "range",
            "--gaze-deg",
            "45",
            "--format",
            "firmware",
            "--power-w-per-code",
            step,
        ]
    };
    let o = crate::common::run(&args("1.0"), None);
    crate::common::assert_bad_input(&o, "--power-w-per-code");
    let err = crate::common::stderr(&o);
    assert!(err.contains("code 0"), "{err}");
    assert!(o.stdout.is_empty());
    let o = crate::common::run(&args("1e-7"), None);
    assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
}

/// A sensor file's head error prints the value written (it printed `NaN`
/// before): `divergence_mrad = -3.0` is named with `-3`, exit 2.
#[test]
fn a_sensor_file_head_error_prints_the_value_written() {
    let o = crate::common::run(&["sensor", "--preset", "vlp16"], None);
    assert_eq!(o.status.code(), Some(0));
    let toml = crate::common::stdout(&o);
    let line = toml
        .lines()
        .find(|l| l.starts_with("divergence_mrad"))
        .expect("the head's divergence")
        .to_owned();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sensor.toml");
    std::fs::write(&path, toml.replace(&line, "divergence_mrad = -3.0")).unwrap();
    let profile = dir.path().join("p.json");
    let o = crate::common::run(
        &[
            "profile",
            "--preset",
            "vlp16",
            "--mode",
            "range",
            "--gaze-deg",
            "90",
            "--out",
            profile.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", crate::common::stderr(&o));
    let o = crate::common::run(
        &[
            "check",
            "--sensor",
            path.to_str().unwrap(),
            profile.to_str().unwrap(),
        ],
        None,
    );
    crate::common::assert_bad_input(&o, "limits.eye_safety.head.divergence_mrad = -3:");
    assert!(!crate::common::stderr(&o).contains("NaN"));
}

/// A head value refused for being subnormal says so (1e-320 is finite,
/// `>= 0` and inside the cycle: the old reason did not hold), with the
/// value, in a profile as in the single-channel messages.
#[test]
fn a_subnormal_head_value_is_refused_for_being_subnormal() {
    let p = preset("vlp16").unwrap();
    let mut profile = build_profile(&p, Mode::Range, Some(90.0), 360).unwrap();
    let head = profile
        .limits
        .eye_safety
        .as_mut()
        .and_then(|e| e.head.as_mut())
        .expect("vlp16 has a head");
    head.channels[1].slot_s = 1e-320;
    let rejected = gaze_lidar::checker::certify(profile).unwrap_err();
    let lines: Vec<String> = rejected
        .violations
        .iter()
        .map(ToString::to_string)
        .collect();
    assert!(
        lines
            .iter()
            .any(|l| l.contains("head.channels[1].slot_s = 1e-320: is subnormal")),
        "{lines:?}"
    );
}

/// `check` of a head declared at 10 000 mm says the verdict covers the
/// 100 mm surface too, and rejects the vlp16 range profile at 11.83× its
/// power (certified at 10 000 mm alone, 6.33× over at 100 mm by the outside
/// tester's reference) with the 100 mm figure.
#[test]
fn check_of_a_far_declared_surface_names_both_surfaces() {
    let p = preset("vlp16").unwrap();
    let mut profile = build_profile(&p, Mode::Range, Some(90.0), 360).unwrap();
    for b in &mut profile.bins {
        b.power_w *= 11.83;
    }
    profile.average_power_w *= 11.83;
    profile.limits.power_w_max *= 11.83;
    let mut near = profile.clone();
    profile
        .limits
        .eye_safety
        .as_mut()
        .and_then(|e| e.head.as_mut())
        .expect("vlp16 has a head")
        .aperture_distance_mm = 10_000.0;
    let dir = tempfile::tempdir().unwrap();
    let far_path = dir.path().join("far.json");
    std::fs::write(&far_path, profile.to_json().unwrap()).unwrap();
    near.limits
        .eye_safety
        .as_mut()
        .unwrap()
        .head
        .as_mut()
        .unwrap()
        .aperture_distance_mm = 100.0;
    let near_path = dir.path().join("near.json");
    std::fs::write(&near_path, near.to_json().unwrap()).unwrap();
    let far = crate::common::run(&["check", far_path.to_str().unwrap()], None);
    let near = crate::common::run(&["check", near_path.to_str().unwrap()], None);
    assert_eq!(
        far.status.code(),
        Some(1),
        "{}",
        crate::common::stdout(&far)
    );
    assert_eq!(near.status.code(), Some(1));
    let far_out = crate::common::stdout(&far);
    assert!(
        far_out.contains(
            "evaluated on the 100 mm Condition 3 surfaces and on the declared 10000 mm ones"
        ),
        "{far_out}"
    );
    let near_out = crate::common::stdout(&near);
    assert!(!near_out.contains("declared"), "{near_out}");
    let percent = |s: &str| {
        s.split(" % of")
            .next()
            .unwrap()
            .rsplit(' ')
            .next()
            .unwrap()
            .to_owned()
    };
    assert_eq!(
        percent(&far_out),
        percent(&near_out),
        "{far_out}\n{near_out}"
    );
}
