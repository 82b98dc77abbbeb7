//! Firmware tables at the boundary: the quantizer over every preset, mode
//! and bin count (every table certified by the integer checker), and tables
//! with impossible header numbers refused whatever the flags.
//!
//! Add tests here when a firmware table is built or read (quantization,
//! the header's numbers, the `format` field).

use crate::common;

use common::{expect, run, run_bytes, stdout};
use gaze_lidar::firmware::{
    binary, check_table, floor_code, FirmwareConfig, FirmwareTable, FwViolation,
};
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets::{preset, PRESET_NAMES};
use gaze_lidar::planner::{closed_form, Mode};

/// Builds the table of every preset × accounting × mode × gaze at `bins`
/// and asserts what the quantizer promises for every profile the closed
/// form certifies: a table comes back, the integer checker certifies it,
/// and no code is above its bin's certified power. Returns the tables built
/// and the combinations the closed form itself refused (a sensor's limits
/// the paper's levels exceed: exit 1 before any table).
fn quantizes_and_certifies(bins: usize) -> (usize, Vec<String>) {
    let mut built = 0;
    let mut refused = Vec::new();
    for name in PRESET_NAMES {
        for accounting in [
            None,
            Some(PowerAccounting::Time),
            Some(PowerAccounting::Angle),
        ] {
            let mut p = preset(name).unwrap();
            if let Some(acc) = accounting {
                p.lidar.power_accounting = acc;
            }
            for mode in Mode::ALL {
                for gaze in [0.0, 90.0, -135.0] {
                    let what = format!(
                        "{name} {accounting:?} {} gaze {gaze} bins {bins}",
                        mode.name()
                    );
                    let g = (mode != Mode::Baseline).then_some(gaze);
                    let c = match closed_form(&p, mode, g, bins) {
                        Ok(c) => c,
                        Err(_) => {
                            refused.push(format!("{name} {}", mode.name()));
                            continue;
                        }
                    };
                    let t = FirmwareTable::from_certified(&c, &FirmwareConfig::default())
                        .unwrap_or_else(|e| panic!("{what}: quantizer: {e}"));
                    let v = check_table(&t);
                    assert!(v.is_empty(), "{what}: {v:?}");
                    for (b, fb) in c.profile().bins.iter().zip(&t.bins) {
                        let ceiling = floor_code(b.power_w, t.power_w_per_code).unwrap();
                        assert!(
                            fb.power_code <= ceiling,
                            "{what}: code above the certified power"
                        );
                    }
                    built += 1;
                }
            }
        }
    }
    (built, refused)
}

/// Only the closed forms the sensor's own limits refuse are left out: a
/// sensor with a finite spin-acceleration limit (vls128, vlp16, os1-128:
/// 100 rad/s²) cannot run the paper's resolution levels, whose spin steps
/// between bins (an infinite acceleration).
fn only_known_refusals(bins: usize, built: usize, refused: &[String]) {
    for r in refused {
        let (name, mode) = r.split_once(' ').expect("preset mode");
        let accel_limited = preset(name)
            .expect("preset")
            .lidar
            .limits
            .spin_accel_rad_s2_max
            .is_some();
        assert!(
            accel_limited && (mode == "resolution" || mode == "joint"),
            "bins {bins}: the closed form refused {r}"
        );
    }
    assert_eq!(
        built + refused.len(),
        PRESET_NAMES.len() * 3 * Mode::ALL.len() * 3,
        "bins {bins}"
    );
    assert!(built >= 54, "bins {bins}: only {built} tables");
}

/// 3600 bins included: the whole table takes about two seconds.
#[test]
fn every_preset_mode_and_bin_count_quantizes_to_a_certified_table() {
    for bins in [8, 72, 360, 3600] {
        let (built, refused) = quantizes_and_certifies(bins);
        only_known_refusals(bins, built, &refused);
    }
}

#[test]
fn the_vls128_preset_quantizes_at_72_bins_through_the_cli() {
    let o = run(
        &[
            "profile",
            "--preset",
            "vls128",
            "--gaze-deg",
            "90",
            "--bins",
            "72",
            "--format",
            "firmware",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    let t: FirmwareTable = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(check_table(&t).is_empty());
}

fn table_json() -> serde_json::Value {
    let o = run(
        &[
            "profile",
            "--gaze-deg",
            "10",
            "--bins",
            "8",
            "--format",
            "firmware",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap()
}

/// Checks a JSON table on stdin, with and without `--no-eye-safety` (and
/// without eye-safety parameters under it): exit 2 naming `needle`.
fn refused_whatever_the_flags(t: &serde_json::Value, needle: &str) {
    let mut bare = t.clone();
    bare["eye_safety"] = serde_json::Value::Null;
    for (table, flags) in [
        (t, &[][..]),
        (t, &["--no-eye-safety"][..]),
        (&bare, &["--no-eye-safety"][..]),
    ] {
        let text = serde_json::to_string(table).unwrap();
        let mut args = vec!["check", "-"];
        args.extend_from_slice(flags);
        let o = run(&args, Some(&text));
        expect(&o, 2, &[needle], &format!("{needle} {flags:?}"));
    }
}

#[test]
fn a_zero_hz_timer_and_a_zero_tick_frame_are_bad_input() {
    let mut t = table_json();
    t["tick_hz"] = 0.into();
    t["frame_ticks"] = 0.into();
    refused_whatever_the_flags(&t, "tick_hz = 0");
    refused_whatever_the_flags(&t, "frame_ticks = 0");
    let mut t = table_json();
    t["frame_ticks"] = 0.into();
    refused_whatever_the_flags(&t, "frame_ticks = 0");
}

#[test]
fn a_negative_dac_step_is_bad_input_in_json_and_binary() {
    let mut t = table_json();
    t["power_w_per_code"] = (-1e-7).into();
    refused_whatever_the_flags(&t, "power_w_per_code");
    // The binary encoding of the same defect: the same exit code.
    let good: FirmwareTable = serde_json::from_value(table_json()).unwrap();
    let mut bytes = binary::encode(&good);
    bytes[24..32].copy_from_slice(&(-1e-7f64).to_le_bytes());
    for flags in [&[][..], &["--no-eye-safety"][..]] {
        let mut args = vec!["check", "-"];
        args.extend_from_slice(flags);
        let o = run_bytes(&args, Some(&bytes));
        expect(&o, 2, &["power_w_per_code"], "binary step");
    }
    // A subnormal step passes the decoder and stops at the header boundary.
    bytes[24..32].copy_from_slice(&5e-324f64.to_le_bytes());
    let o = run_bytes(&["check", "-", "--no-eye-safety"], Some(&bytes));
    expect(&o, 2, &["power_w_per_code"], "binary subnormal step");
}

#[test]
fn an_absurd_pulse_rate_is_bad_input() {
    let mut t = table_json();
    t["pulse_rate_hz"] = 1e300.into();
    refused_whatever_the_flags(&t, "pulse_rate_hz = 1e300");
}

#[test]
fn the_header_boundary_is_part_of_the_library_checker() {
    let mut t: FirmwareTable = serde_json::from_value(table_json()).unwrap();
    t.tick_hz = 0;
    t.pulse_rate_hz = f64::NAN;
    let fields: Vec<&str> = check_table(&t)
        .iter()
        .filter_map(|v| match v {
            FwViolation::Header { field, .. } => Some(*field),
            _ => None,
        })
        .collect();
    assert_eq!(fields, ["tick_hz", "pulse_rate_hz"]);
    // Eye safety is not evaluated on such numbers; a table without its
    // parameters still says it has none.
    assert!(!check_table(&t).iter().any(|v| matches!(
        v,
        FwViolation::EyeSafety { .. } | FwViolation::EyeSafetyParams { .. }
    )));
    t.eye_safety = None;
    assert!(check_table(&t).contains(&FwViolation::EyeSafetyMissing));
}

#[test]
fn an_unknown_table_format_is_named() {
    let mut t = table_json();
    t["format"] = "gaze-lidar/firmware@2".into();
    let text = serde_json::to_string(&t).unwrap();
    let o = run(&["check", "-"], Some(&text));
    expect(
        &o,
        2,
        &["'gaze-lidar/firmware@2'", "not a format this build reads"],
        "firmware@2",
    );
    assert!(!common::stderr(&o).contains("unknown field"));
}
