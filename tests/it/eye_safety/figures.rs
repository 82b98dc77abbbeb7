//! AEL figures, per-azimuth exposure, check integration.

use crate::common;
use gaze_lidar_core::testing::reference;

use common::{assert_bad_input, run, stdout};
use gaze_lidar::checker::{certify, check, Violation};
use gaze_lidar::eye_safety::{evaluate_profile, Rule};
use gaze_lidar::model::presets::{self, PRESET_NAMES};
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::{closed_form, Mode};
use gaze_lidar::profile::Profile;
use proptest::prelude::*;

fn ael_json(args: &[&str]) -> serde_json::Value {
    let mut full = vec!["ael", "--format", "json"];
    full.extend_from_slice(args);
    let o = run(&full, None);
    assert_eq!(o.status.code(), Some(0));
    serde_json::from_str(&stdout(&o)).unwrap()
}

fn within(v: &serde_json::Value, expected: f64) {
    let x = v.as_f64().unwrap();
    assert!((x / expected - 1.0).abs() <= 0.02, "{x} vs {expected}");
}

#[test]
fn ael_command_figures() {
    let v = ael_json(&["--wavelength-nm", "905", "--pulse-duration-s", "5e-9"]);
    within(&v["single_pulse_ael_j"], 1.98e-7);
    within(&v["average_power_ael_w"], 1.0e-3);
    let v = ael_json(&["--wavelength-nm", "850", "--pulse-duration-s", "5e-9"]);
    within(&v["average_power_ael_w"], 7.8e-4);
    let v = ael_json(&["--wavelength-nm", "1550", "--pulse-duration-s", "5e-9"]);
    within(&v["single_pulse_ael_j"], 8e-3);
    within(&v["average_power_ael_w"], 1e-2);
    assert!(v["c4"].is_number() && v["time_base_s"] == 100.0);
    let v = ael_json(&[
        "--wavelength-nm",
        "905",
        "--pulse-duration-s",
        "5e-9",
        "--pulse-rate-hz",
        "7812.5",
        "--beam-diameter-mm",
        "8",
    ]);
    assert_eq!(v["stationary_beam"]["c5"], 0.4);
    assert!(v["scan_pass_angle_deg"].as_f64().unwrap() > 8.0);
}

#[test]
fn ael_bad_input() {
    assert_bad_input(
        &run(
            &[
                "ael",
                "--wavelength-nm",
                "600",
                "--pulse-duration-s",
                "5e-9",
            ],
            None,
        ),
        "wavelength",
    );
    assert_bad_input(
        &run(
            &[
                "ael",
                "--wavelength-nm",
                "1200",
                "--pulse-duration-s",
                "5e-9",
            ],
            None,
        ),
        "wavelength",
    );
    assert_bad_input(
        &run(
            &[
                "ael",
                "--wavelength-nm",
                "NaN",
                "--pulse-duration-s",
                "5e-9",
            ],
            None,
        ),
        "wavelength",
    );
    assert_bad_input(
        &run(
            &["ael", "--wavelength-nm", "905", "--pulse-duration-s", "0"],
            None,
        ),
        "pulse-duration-s",
    );
    assert_bad_input(
        &run(
            &["ael", "--wavelength-nm", "905", "--pulse-duration-s", "-1"],
            None,
        ),
        "pulse-duration-s",
    );
    assert_bad_input(
        &run(
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "1e-15",
            ],
            None,
        ),
        "pulse-duration-s",
    );
    assert_bad_input(
        &run(
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                "--pulse-rate-hz",
                "0",
            ],
            None,
        ),
        "pulse-rate-hz",
    );
}

/// The paper profile with 200× the power (relative to the rest) in a 3°
/// sector, average kept, max-power limit removed.
fn concentrated() -> Profile {
    let mut p = build_profile(&presets::paper(), Mode::Baseline, None, 360).unwrap();
    let p_mean = p.average_power_w;
    let rest = 360.0 * p_mean / (3.0 * 200.0 + 357.0);
    for (i, b) in p.bins.iter_mut().enumerate() {
        b.power_w = if (100..103).contains(&i) {
            200.0 * rest
        } else {
            rest
        };
    }
    p.limits.power_w_max = 1e3;
    p
}

#[test]
fn concentrated_power_fails_check_naming_eye_safety() {
    let p = concentrated();
    let v = check(&p);
    assert!(
        v.len() == 1 && matches!(v[0], Violation::EyeSafety { .. }),
        "{v:?}"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hot.json");
    std::fs::write(&path, p.to_json().unwrap()).unwrap();
    let o = run(&["check", path.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(1));
    let out = stdout(&o);
    assert!(
        out.contains("eye_safety: at azimuth") && out.contains("Class 1 limit"),
        "{out}"
    );
    let r = evaluate_profile(&p, p.limits.eye_safety.as_ref().unwrap()).unwrap();
    assert!(
        (95.0..=108.0).contains(&r.worst_azimuth_deg),
        "{}",
        r.worst_azimuth_deg
    );
    assert!(r.worst_ratio > 10.0);
}

#[test]
fn every_preset_baseline_and_adaptive_profile_is_class_1() {
    for name in PRESET_NAMES {
        let preset = presets::preset(name).unwrap();
        for mode in Mode::ALL {
            for gaze in [0.0, 90.0, 271.0] {
                match closed_form(&preset, mode, Some(gaze), 360) {
                    Ok(c) => {
                        let p = c.profile();
                        // Not `worst_ratio <= 1` (certification already
                        // implies it): the brute-force reference finds no
                        // concrete pulse train over the limit, and the
                        // checker's bound is not below what it finds.
                        let r = evaluate_profile(p, p.limits.eye_safety.as_ref().unwrap()).unwrap();
                        let found = reference::Reference::new(&reference::Scan::of_profile(p))
                            .worst(&reference::Effort::default());
                        assert!(found.ratio <= 1.0, "{name} {mode:?} {gaze}: {found}");
                        assert!(
                            r.worst_ratio >= found.ratio * (1.0 - 1e-12),
                            "{name} {mode:?} {gaze}: checker {} below {found}",
                            r.worst_ratio
                        );
                    }
                    Err(e) => assert!(
                        !e.to_string().contains("eye_safety"),
                        "{name} {mode:?}: {e}"
                    ),
                }
            }
        }
    }
}

fn uniform(bins: usize) -> Profile {
    build_profile(&presets::paper(), Mode::Baseline, None, bins).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn exposure_grows_with_power(scale in 1.0f64..50.0, gaze in 0.0f64..360.0) {
        let base = build_profile(&presets::paper(), Mode::Range, Some(gaze), 90).unwrap();
        let params = base.limits.eye_safety.clone().unwrap();
        let mut hot = base.clone();
        for b in &mut hot.bins { b.power_w *= scale; }
        let r0 = evaluate_profile(&base, &params).unwrap();
        let r1 = evaluate_profile(&hot, &params).unwrap();
        // Every rule is linear in power.
        for k in 0..4 {
            prop_assert!((r1.rule_ratios[k] - scale * r0.rule_ratios[k]).abs() <= 1e-9 * r1.rule_ratios[k].max(1e-300));
        }
        prop_assert!(r1.worst_ratio >= r0.worst_ratio);
    }

    #[test]
    fn exposure_grows_with_dwell(slow in 0.05f64..1.0, bins in 8usize..200) {
        let base = uniform(bins);
        let params = base.limits.eye_safety.clone().unwrap();
        let mut slower = base.clone();
        for b in &mut slower.bins { b.spin_start_rad_s *= slow; b.spin_end_rad_s *= slow; }
        let r0 = evaluate_profile(&base, &params).unwrap();
        let r1 = evaluate_profile(&slower, &params).unwrap();
        prop_assert!(r1.max_pulses_per_pass >= r0.max_pulses_per_pass);
        prop_assert!(r1.max_pass_energy_j >= r0.max_pass_energy_j * (1.0 - 1e-12));
        prop_assert!(r1.max_pass_duration_s >= r0.max_pass_duration_s * (1.0 - 1e-12));
        // The within-pass rule grows with the energy per pass.
        prop_assert!(r1.rule_ratios[1] >= r0.rule_ratios[1] * (1.0 - 1e-12));
    }

    #[test]
    fn uniform_profile_single_pulse_binds(bins in 4usize..720) {
        let p = uniform(bins);
        let r = evaluate_profile(&p, p.limits.eye_safety.as_ref().unwrap()).unwrap();
        // The uniform baseline of the paper preset: C5 binds, and the
        // result does not depend on how the circle is binned.
        let r360 = evaluate_profile(&uniform(360), p.limits.eye_safety.as_ref().unwrap()).unwrap();
        prop_assert!((r.worst_ratio / r360.worst_ratio - 1.0).abs() < 1e-9, "{} vs {}", r.worst_ratio, r360.worst_ratio);
        prop_assert_eq!(r.binding_rule, Rule::SinglePulse);
    }
}

#[test]
fn slowing_one_sector_raises_its_single_pulse_exposure() {
    // Resolution control slows the RoI: more pulses per pass there, lower C5.
    let base = uniform(360);
    let res = build_profile(&presets::paper(), Mode::Resolution, Some(90.0), 360).unwrap();
    let params = base.limits.eye_safety.clone().unwrap();
    let r0 = evaluate_profile(&base, &params).unwrap();
    let r1 = evaluate_profile(&res, &params).unwrap();
    assert!(r1.max_pulses_per_pass > r0.max_pulses_per_pass);
    assert!(r1.rule_ratios[0] > r0.rule_ratios[0]);
    // The worst aperture sits in the slow RoI, opposite the gaze.
    assert!(!(60.0..=120.0).contains(&r1.worst_azimuth_deg));
}

#[test]
fn certified_profiles_carry_their_eye_safety_params() {
    let c =
        certify(build_profile(&presets::vls128(), Mode::Range, Some(45.0), 720).unwrap()).unwrap();
    let json = c.profile().to_json().unwrap();
    assert!(json.contains("\"wavelength_nm\": 903.0"));
}
