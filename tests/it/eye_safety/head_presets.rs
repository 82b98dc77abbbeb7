//! The real heads' presets certified for the whole head, everywhere a
//! profile is certified (closed form, `--config` and `--optimize`, the
//! stream, the optimizer's fast path), with the head's figures, and output
//! that names the head.

use crate::common;

use common::{run, stderr, stdout};
use gaze_lidar::checker::certify;
use gaze_lidar::eye_safety::evaluate_profile;
use gaze_lidar::model::presets::{preset, PRESET_NAMES};
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;
use gaze_lidar::profile::Profile;

const HEADS: [(&str, u32); 3] = [("vls128", 128), ("vlp16", 16), ("os1-128", 128)];

/// For each real head's closed-form range profile (gaze 90°, 360 bins):
/// the head's ratio, the single-channel ratio of the same profile (the
/// head removed), their quotient, and the worst aperture position. The
/// quotient is at least the number of beams of one firing group that can
/// meet one aperture (every channel at `power_scale` 1, so the weight of
/// the simultaneous group is that count): the head's Rule 1 charges every
/// such beam's pulse at once. Run with `--nocapture` for the numbers.
#[test]
fn real_heads_closed_form_range_figures() {
    for (name, channels) in HEADS {
        let profile = build_profile(&preset(name).unwrap(), Mode::Range, Some(90.0), 360).unwrap();
        let params = profile.limits.eye_safety.clone().unwrap();
        let head = evaluate_profile(&profile, &params).unwrap();
        let mut one = params.clone();
        one.head = None;
        let single = evaluate_profile(&profile, &one).unwrap();
        let hf = head
            .head
            .clone()
            .expect("a head's report carries its figures");
        assert_eq!(hf.channels, channels);
        let quotient = head.worst_ratio / single.worst_ratio;
        eprintln!(
            "{name}: head ratio {:.6} ({}), single-channel ratio {:.6} ({}), quotient {:.4}; \
             same-group beams meeting one aperture {} (W_sim {:.3}); worst aperture {:.3}° azimuth, \
             height {:.3} mm ({} beams over a sweep, W_v {:.3}); Rule 1 group {} beams at {:.3} mm; \
             stalled rotor {:.3}",
            head.worst_ratio,
            head.binding_rule,
            single.worst_ratio,
            single.binding_rule,
            quotient,
            hf.weight_simultaneous.round(),
            hf.weight_simultaneous,
            head.worst_azimuth_deg,
            hf.worst_height_mm,
            hf.channels_at_worst,
            hf.weight_vertical,
            hf.count_group,
            hf.group_height_mm,
            head.stalled_rotor_ratio,
        );
        assert!(
            quotient >= hf.weight_simultaneous,
            "{name}: quotient {quotient} below the {} same-group beams meeting one aperture",
            hf.weight_simultaneous
        );
        assert!(
            head.worst_ratio <= 1.0,
            "{name}: head ratio {}",
            head.worst_ratio
        );
        let c = certify(profile).unwrap();
        assert_eq!(
            c.eye_safety().unwrap().head.as_ref().unwrap().channels,
            channels
        );
    }
}

/// Every preset's closed-form profiles certify, with the head where the
/// preset has one (`paper`: one channel); where a spin step leaves the
/// preset's spin range, for that reason alone, never eye safety.
#[test]
fn every_preset_closed_form_certifies_as_its_head() {
    for name in PRESET_NAMES {
        let p = preset(name).unwrap();
        let has_head = p.lidar.limits.eye_safety.as_ref().unwrap().head.is_some();
        assert_eq!(has_head, *name != "paper", "{name}");
        for mode in [Mode::Baseline, Mode::Range, Mode::Resolution, Mode::Joint] {
            for gaze in [Some(0.0), Some(90.0), Some(200.0)] {
                let gaze = if mode == Mode::Baseline { None } else { gaze };
                // A finite acceleration limit refuses the closed form's spin
                // steps: nothing to certify.
                let Ok(profile) = build_profile(&p, mode, gaze, 360) else {
                    assert!(
                        p.lidar.limits.spin_accel_rad_s2_max.is_some(),
                        "{name} {mode:?}"
                    );
                    continue;
                };
                match certify(profile) {
                    Ok(c) => assert_eq!(c.eye_safety().unwrap().head.is_some(), has_head),
                    // The closed form's spin steps may leave the preset's
                    // spin range (resolution, joint): never eye safety.
                    Err(e) => {
                        assert!(
                            matches!(mode, Mode::Resolution | Mode::Joint),
                            "{name} {mode:?} {gaze:?}: {e}"
                        );
                        assert!(
                            e.violations.iter().all(|v| v.limit_key() != "eye_safety"),
                            "{name} {mode:?} {gaze:?}: {e}"
                        );
                    }
                }
            }
        }
    }
}

/// `check` names the head (channels evaluated, the worst aperture position,
/// the beams meeting it, the binding rule), or says "one channel"; and for
/// a rejected profile the largest uniform power scale that certifies, which
/// does certify when applied.
#[test]
fn check_output_names_the_head_and_the_scale_that_certifies() {
    let dir = std::env::temp_dir().join(format!("gl-head-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["vls128", "paper"] {
        let profile = build_profile(&preset(name).unwrap(), Mode::Range, Some(90.0), 360).unwrap();
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, profile.to_json().unwrap()).unwrap();
        let o = run(&["check", path.to_str().unwrap()], None);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let text = stdout(&o);
        if name == "paper" {
            assert!(text.contains("evaluated for one channel"), "{text}");
        } else {
            assert!(
                text.contains("head: 128 channels evaluated; worst aperture position"),
                "{text}"
            );
            assert!(text.contains("beam(s) meet it; binding rule:"), "{text}");
        }
        let o = run(&["check", "--format", "json", path.to_str().unwrap()], None);
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
        let eye = &v["eye_safety"];
        if name == "paper" {
            assert_eq!(eye["evaluated_for"], "one channel");
            assert!(eye["head"].is_null());
        } else {
            assert_eq!(eye["evaluated_for"], "head");
            assert_eq!(eye["head"]["channels_evaluated"], 128);
            assert!(eye["head"]["beams_meeting_worst"].as_u64().unwrap() >= 1);
            assert!(eye["head"]["worst_height_mm"].is_number());
        }
        // Over the limit: every power ×5 (limits widened to allow it; the
        // range profile is at 0.32 of the head's limit on `vls128`).
        let mut hot: Profile = profile.clone();
        hot.limits.power_w_max *= 5.0;
        hot.average_power_w *= 5.0;
        for b in &mut hot.bins {
            b.power_w *= 5.0;
        }
        let path = dir.join(format!("{name}-hot.json"));
        std::fs::write(&path, hot.to_json().unwrap()).unwrap();
        let o = run(&["check", "--format", "json", path.to_str().unwrap()], None);
        assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
        let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
        let scale = v["eye_safety"]["power_scale_to_certify"].as_f64().unwrap();
        assert!(scale < 1.0, "{scale}");
        let o = run(&["check", path.to_str().unwrap()], None);
        assert!(
            stdout(&o).contains("to certify: scale every bin power by at most"),
            "{}",
            stdout(&o)
        );
        assert!(stdout(&o).lines().all(|l| l.starts_with("violation: ")));
        // The stated scale certifies; 1 % more does not.
        for (k, ok) in [(scale, true), (scale * 1.01, false)] {
            let mut p = hot.clone();
            for b in &mut p.bins {
                b.power_w *= k;
            }
            let r = evaluate_profile(&p, p.limits.eye_safety.as_ref().unwrap()).unwrap();
            assert_eq!(r.worst_ratio <= 1.0, ok, "{name} ×{k}: {}", r.worst_ratio);
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `sensor --preset P` writes the head, and `check --sensor` of a head's
/// profile against that file certifies; `ael --preset P` shows the head.
#[test]
fn sensor_and_ael_show_the_head() {
    let dir = std::env::temp_dir().join(format!("gl-head-io-sensor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let sensor = dir.join("vlp16.toml");
    let o = run(
        &[
            "sensor",
            "--preset",
            "vlp16",
            "--out",
            sensor.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&sensor).unwrap();
    assert!(text.contains("[limits.eye_safety.head]"), "{text}");
    assert_eq!(
        text.matches("[[limits.eye_safety.head.channels]]").count(),
        16
    );
    let profile = build_profile(&preset("vlp16").unwrap(), Mode::Range, Some(90.0), 360).unwrap();
    let path = dir.join("p.json");
    std::fs::write(&path, profile.to_json().unwrap()).unwrap();
    let o = run(
        &[
            "check",
            path.to_str().unwrap(),
            "--sensor",
            sensor.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).contains("head: 16 channels evaluated"));
    let o = run(&["ael", "--preset", "os1-128"], None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let t = stdout(&o);
    assert!(t.contains("head                    128 channels"), "{t}");
    // Both surfaces a certificate covers, each with its figures.
    assert!(
        t.contains("head on the cylinder around the spin axis:"),
        "{t}"
    );
    assert!(
        t.contains("head on the sphere around the scan centre:"),
        "{t}"
    );
    assert_eq!(t.matches("  overlap ").count(), 2, "{t}");
    let o = run(&["ael", "--preset", "paper"], None);
    assert!(stdout(&o).contains("none: one channel"));
    let o = run(&["ael", "--preset", "vls128", "--format", "json"], None);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(
        v["head"]["description"]["channels"]
            .as_array()
            .unwrap()
            .len(),
        128
    );
    assert!(v["head"]["figures"]["weight_vertical"].as_f64().unwrap() >= 1.0);
    let by = v["head"]["figures_by_surface"].as_array().unwrap();
    assert_eq!(by.len(), 2, "{v}");
    assert_eq!(by[0]["surface"], "cylinder");
    assert_eq!(by[1]["surface"], "sphere");
    assert_eq!(by[0]["figures"], v["head"]["figures"]);
    // The VLS-128's channels reach 25° down: the sphere's widest pass is
    // the wider.
    let pass = |i: usize| by[i]["figures"]["pass_angle_deg"].as_f64().unwrap();
    assert!(pass(1) > pass(0), "{v}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The stream's profiles (closed form and the optimizer's fast path) are
/// certified for the head: each frame re-checks with the head's figures.
#[test]
fn stream_and_fast_path_certify_the_head() {
    let input: String = (0..60)
        .map(|k| {
            format!(
                "{{\"t_s\": {}, \"gaze_deg\": 90.0}}\n",
                f64::from(k) * 0.005
            )
        })
        .collect();
    let cfg = format!(
        "{}/examples/configs/vls128_eye.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    for args in [
        vec!["stream", "--preset", "vls128", "--mode", "range"],
        vec!["stream", "--config", cfg.as_str(), "--bins", "72"],
    ] {
        let o = run(&args, Some(&input));
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let out = stdout(&o);
        assert!(out.lines().count() >= 2, "{out}");
        for line in out.lines() {
            let p = Profile::from_json(line, "frame").unwrap();
            let c = certify(p).unwrap();
            assert_eq!(c.eye_safety().unwrap().head.as_ref().unwrap().channels, 128);
        }
    }
    // The fast path in the library.
    let problem = common::shipped_problem("vls128_eye", 72);
    let mut fast = gaze_lidar::optimizer::fast::FastPlanner::new(problem);
    let c = fast.plan(90.0).unwrap();
    assert_eq!(c.eye_safety().unwrap().head.as_ref().unwrap().channels, 128);
}

/// Every shipped `--config` file gives a profile certified as its head
/// (the optimizer's cuts come from the head's bound), and `--optimize`
/// with a head's preset too.
#[test]
fn shipped_configs_and_optimize_certify_the_head() {
    let dir = format!("{}/examples/configs", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 4);
    for path in &names {
        let o = run(
            &[
                "profile",
                "--config",
                path.to_str().unwrap(),
                "--gaze-deg",
                "90",
                "--bins",
                "72",
            ],
            None,
        );
        assert_eq!(o.status.code(), Some(0), "{path:?}: {}", stderr(&o));
        let p = Profile::from_json(&stdout(&o), "out").unwrap();
        let has_head = p.limits.eye_safety.as_ref().unwrap().head.is_some();
        let c = certify(p).unwrap();
        assert_eq!(c.eye_safety().unwrap().head.is_some(), has_head, "{path:?}");
    }
    for name in ["vlp16", "os1-128"] {
        let o = run(
            &[
                "profile",
                "--preset",
                name,
                "--optimize",
                "--gaze-deg",
                "90",
                "--bins",
                "72",
            ],
            None,
        );
        assert_eq!(o.status.code(), Some(0), "{name}: {}", stderr(&o));
        let c = certify(Profile::from_json(&stdout(&o), "out").unwrap()).unwrap();
        assert!(c.eye_safety().unwrap().head.is_some());
    }
}

/// The integer firmware checker evaluates the head with the float bound's
/// candidates: every real head's closed-form range profile builds into a
/// table the integer check certifies at the float head bound's figure of
/// the same table as it runs, within 0.5 % either way (measured: `vls128`
/// 0.3180 against 0.3184, `vlp16` 0.5809 against 0.5808, `os1-128` 0.5535
/// against 0.5535; the integer check took `W_v ×` the single-channel
/// figures before, 0.689 on `vls128`), the table round-trips through the
/// binary codec with its head, and the same table with its codes scaled
/// past the head's limit is rejected by the integer check while one channel
/// alone would still pass it.
#[test]
fn firmware_tables_are_checked_as_the_head() {
    use gaze_lidar::firmware::{
        binary, check_table_evaluated, table_exposure, FirmwareConfig, FirmwareTable,
    };
    for (name, _) in HEADS {
        let c =
            certify(build_profile(&preset(name).unwrap(), Mode::Range, Some(90.0), 360).unwrap())
                .unwrap();
        let certified = c.eye_safety().unwrap().worst_ratio;
        let table = FirmwareTable::from_certified(&c, &FirmwareConfig::default()).unwrap();
        assert!(table.eye_safety.as_ref().unwrap().head.is_some());
        let (v, report) = check_table_evaluated(&table);
        assert!(v.is_empty(), "{name}: {v:?}");
        let int = report.unwrap().worst_ratio_ppm as f64 / 1e6;
        let float = table_exposure(&table).unwrap().unwrap().worst_ratio;
        eprintln!(
            "{name}: integer head ratio {int:.6}, float head ratio of the table {float:.6} (of the profile {certified:.6})"
        );
        // Two sound upper bounds of one model on one table, taking the
        // same candidates (the integer one per window length, with exact
        // pass counts).
        assert!(
            int >= 0.995 * float && int <= 1.005 * float,
            "{name}: {int} vs {float}"
        );
        // The binary codec carries the head.
        let back = binary::decode(&binary::encode(&table)).unwrap();
        assert_eq!(back.eye_safety, table.eye_safety);
        // Codes scaled until the head's integer check fails.
        let mut hot = table.clone();
        let k = (1.2 / int).ceil() as u32;
        hot.limits.power_code_max = u32::MAX;
        hot.limits.energy_budget = u64::MAX;
        hot.limits.window_energy_max = u64::MAX;
        for b in &mut hot.bins {
            b.power_code = b.power_code.saturating_mul(k);
            b.power_code_cap = u32::MAX;
        }
        let (v, _) = check_table_evaluated(&hot);
        assert!(
            v.iter().any(|x| x.limit_key() == "eye_safety"),
            "{name} ×{k}: {v:?}"
        );
        let mut one = hot.clone();
        one.eye_safety.as_mut().unwrap().head = None;
        let (_, r1) = check_table_evaluated(&one);
        let r1 = r1.unwrap().worst_ratio_ppm as f64 / 1e6;
        eprintln!("{name} ×{k}: one channel alone {r1:.4}");
    }
}
