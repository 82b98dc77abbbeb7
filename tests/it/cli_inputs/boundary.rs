//! The one validated input boundary, through the binary: numbers of
//! physical size (subnormal rates never certified), sensor files that are
//! exactly a preset's `lidar` and are refused (exit 2, naming the key) when
//! a limit is NaN, negative or inverted, `gaze-lidar sensor --preset`, and
//! `check` on firmware tables (firmware@1 JSON and the binary).

use crate::common;

use common::{assert_bad_input, run, stderr, stdout};
use gaze_lidar::firmware::{binary, check_table_evaluated, FirmwareTable};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `check ARGS…`: (exit code, stdout, stderr).
fn check(args: &[&str]) -> (Option<i32>, String, String) {
    let mut all = vec!["check"];
    all.extend_from_slice(args);
    let o = run(&all, None);
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    (o.status.code(), stdout(&o), stderr(&o))
}

/// `profile --preset PRESET --mode range --gaze-deg 90`'s JSON.
fn range_profile(preset: &str) -> String {
    let o = run(
        &[
            "profile",
            "--preset",
            preset,
            "--mode",
            "range",
            "--gaze-deg",
            "90",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    stdout(&o)
}

fn paper_range_profile() -> String {
    range_profile("paper")
}

fn sensor_file(preset: &str) -> String {
    let o = run(&["sensor", "--preset", preset], None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    stdout(&o)
}

/// Replaces the line `key = …` (the first one) of a TOML text.
fn set_key(toml: &str, key: &str, value: &str) -> String {
    let prefix = format!("{key} = ");
    let mut done = false;
    let out: Vec<String> = toml
        .lines()
        .map(|l| {
            if !done && l.starts_with(&prefix) {
                done = true;
                format!("{prefix}{value}")
            } else {
                l.to_owned()
            }
        })
        .collect();
    assert!(done, "no key {key} in\n{toml}");
    out.join("\n") + "\n"
}

/// Guards the rate boundary: `frame_rate_hz: 5e-324` (and 4e-309) in an otherwise
/// certified profile was certified ("frame period 0.050000000 s"): its
/// period 1/f overflows to infinity, which matched any dwell sum within a
/// relative tolerance. Now every subnormal or unphysical rate is rejected,
/// naming the key; 1e-300 was and is rejected.
#[test]
fn subnormal_rates_are_never_certified() {
    let dir = tempfile::tempdir().unwrap();
    let good: Value = serde_json::from_str(&paper_range_profile()).unwrap();
    let ok = write(dir.path(), "ok.json", good.to_string());
    assert_eq!(check(&[s(&ok)]).0, Some(0));
    for field in ["frame_rate_hz", "pulse_rate_hz"] {
        for bad in [
            "5e-324",
            "4e-309",
            "1e-300",
            "2.2250738585072014e-308",
            "1e13",
        ] {
            let mut v = good.clone();
            v[field] = bad.parse::<f64>().unwrap().into();
            let round: Value = serde_json::from_str(&v.to_string()).unwrap();
            assert_eq!(round[field].as_f64(), bad.parse::<f64>().ok(), "{field}");
            let p = write(dir.path(), "bad.json", v.to_string());
            for format in ["text", "json"] {
                let (code, out, _) = check(&[s(&p), "--format", format]);
                assert_eq!(code, Some(1), "{field} = {bad} was certified: {out}");
                assert!(out.contains(field), "{field} = {bad}: {out}");
                assert!(!out.contains("certified: "), "{out}");
            }
        }
    }
}

/// Flags pass the same boundary: a subnormal DAC step, pulse rate or beam
/// diameter is bad input (exit 2) naming the flag.
#[test]
fn subnormal_flags_are_bad_input() {
    let o = run(
        &[
            "profile",
            "--preset",
            "paper",
            "--mode",
            "range",
            "--gaze-deg",
            "90",
            "--format",
            "firmware",
            "--power-w-per-code",
            "5e-324",
        ],
        None,
    );
    assert_bad_input(&o, "--power-w-per-code");
    for (flag, value) in [
        ("--pulse-rate-hz", "5e-324"),
        ("--pulse-rate-hz", "4e-309"),
        ("--beam-diameter-mm", "5e-324"),
    ] {
        let o = run(
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                flag,
                value,
            ],
            None,
        );
        assert_bad_input(&o, flag);
    }
}

/// Guards the sensor file's boundary: `power_w_max = nan` in a sensor file certified a
/// profile declaring 2 mW (the paper sensor allows 1.25 mW); a negative
/// budget or `power_w_min > power_w_max` was blamed on the profile (exit 1).
/// Now every such sensor file is refused as bad input (exit 2), naming the
/// sensor key.
#[test]
fn bad_sensor_limits_exit_2_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let paper = sensor_file("paper");
    // The loose profile: declares 2 mW as its power limit.
    let mut loose: Value = serde_json::from_str(&paper_range_profile()).unwrap();
    loose["limits"]["power_w_max"] = 2e-3.into();
    let loose = write(dir.path(), "loose.json", loose.to_string());
    let real = write(dir.path(), "real.toml", &paper);
    let (code, out, _) = check(&[s(&loose), "--sensor", s(&real)]);
    assert_eq!(code, Some(1), "the real sensor rejects it: {out}");
    assert!(out.contains("power_w_max"), "{out}");
    let cases = [
        ("power_w_max", "nan", "limits.power_w_max"),
        ("power_w_max", "-1.0", "limits.power_w_max"),
        ("power_w_max", "inf", "limits.power_w_max"),
        ("power_w_max", "5e-324", "limits.power_w_max"),
        ("power_w_min", "0.01", "limits.power_w_min"),
        ("power_w_min", "-1e-3", "limits.power_w_min"),
        ("spin_rad_s_min", "1000.0", "limits.spin_rad_s_min"),
        ("spin_rad_s_max", "nan", "limits.spin_rad_s_max"),
        (
            "spin_accel_rad_s2_max",
            "-1.0",
            "limits.spin_accel_rad_s2_max",
        ),
        (
            "power_slew_w_per_deg_max",
            "nan",
            "limits.power_slew_w_per_deg_max",
        ),
        ("average_power_w", "-0.001", "average_power_w"),
        ("average_power_w", "nan", "average_power_w"),
        ("frame_rate_hz", "5e-324", "frame_rate_hz"),
        ("frame_rate_hz", "4e-309", "frame_rate_hz"),
        ("pulse_rate_hz", "nan", "pulse_rate_hz"),
        ("wavelength_nm", "nan", "limits.eye_safety.wavelength_nm"),
        (
            "beam_diameter_mm",
            "-8.0",
            "limits.eye_safety.beam_diameter_mm",
        ),
    ];
    for (key, value, named) in cases {
        let p = write(dir.path(), "s.toml", set_key(&paper, key, value));
        let o = run(&["check", s(&loose), "--sensor", s(&p)], None);
        assert_bad_input(&o, named);
        assert!(stderr(&o).contains("--sensor"), "{}", stderr(&o));
    }
    // The schema: a key left out or added, "unlimited" misspelled, a
    // missing [limits.eye_safety]; each names the key and the line.
    let missing = paper.replace("power_slew_w_per_deg_max = \"unlimited\"\n", "");
    let extra = paper.replace("channels = 64\n", "channels = 64\ncolour = 3\n");
    let word = paper.replace("\"unlimited\"", "\"none\"");
    let cut = paper.find("[limits.eye_safety]").unwrap();
    let no_eye = paper[..cut].to_owned();
    for (text, named) in [
        (missing, "power_slew_w_per_deg_max"),
        (extra, "colour"),
        (word, "unlimited"),
        (no_eye, "eye_safety"),
    ] {
        let p = write(dir.path(), "s.toml", text);
        let o = run(&["check", s(&loose), "--sensor", s(&p)], None);
        assert_bad_input(&o, named);
        assert!(stderr(&o).contains("s.toml:"), "{}", stderr(&o));
    }
}

/// `gaze-lidar sensor --preset P` writes the preset as a sensor file, and
/// `check --sensor` on it gives exactly the verdict (exit code and JSON
/// report) of `check --preset P`, for both presets' closed-form profiles
/// and for a profile declaring a limit looser than the sensor's.
#[test]
fn sensor_files_from_both_presets_certify_what_the_presets_certify() {
    let dir = tempfile::tempdir().unwrap();
    let mut certified = 0;
    for preset in ["paper", "vls128"] {
        let text = sensor_file(preset);
        assert!(text.contains("\"unlimited\""), "{text}");
        let sensor = write(dir.path(), &format!("{preset}.toml"), &text);
        // --out writes the same bytes.
        let out = dir.path().join(format!("{preset}-out.toml"));
        let o = run(&["sensor", "--preset", preset, "--out", s(&out)], None);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert_eq!(std::fs::read_to_string(&out).unwrap(), text);
        for mode in ["baseline", "range", "resolution", "joint"] {
            let o = run(
                &[
                    "profile",
                    "--preset",
                    preset,
                    "--mode",
                    mode,
                    "--gaze-deg",
                    "45",
                ],
                None,
            );
            if o.status.code() != Some(0) {
                // vls128 cannot step its spin (resolution, joint): no profile.
                assert_eq!(preset, "vls128", "{mode}: {}", stderr(&o));
                continue;
            }
            let mut variants = vec![stdout(&o)];
            let mut loose: Value = serde_json::from_str(&stdout(&o)).unwrap();
            loose["limits"]["spin_rad_s_max"] = 1e4.into();
            variants.push(loose.to_string());
            for (k, profile) in variants.iter().enumerate() {
                let p = write(dir.path(), "p.json", profile);
                let by_preset = check(&[s(&p), "--preset", preset, "--format", "json"]);
                let by_file = check(&[s(&p), "--sensor", s(&sensor), "--format", "json"]);
                assert_eq!(by_preset.0, by_file.0, "{preset} {mode} {k}");
                assert_eq!(by_preset.1, by_file.1, "{preset} {mode} {k}");
                assert_eq!(
                    by_preset.0,
                    Some(if k == 0 { 0 } else { 1 }),
                    "{preset} {mode} {k}: {}",
                    by_preset.1
                );
                certified += usize::from(k == 0);
            }
        }
    }
    assert!(certified >= 6, "{certified}");
}

fn table_files(dir: &Path, preset: &str) -> (PathBuf, PathBuf) {
    let json = dir.join(format!("{preset}-fw.json"));
    let bin = dir.join(format!("{preset}-fw.bin"));
    for (format, path) in [("firmware", &json), ("firmware-bin", &bin)] {
        let o = run(
            &[
                "profile",
                "--preset",
                preset,
                "--mode",
                "range",
                "--gaze-deg",
                "90",
                "--format",
                format,
                "--out",
                s(path),
            ],
            None,
        );
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    (json, bin)
}

/// `check` certifies a table written by `profile --format firmware` and by
/// `--format firmware-bin` (also against its preset and its sensor file),
/// with the figures of `firmware::check_table`'s own evaluation; the same
/// table with one power code raised past the eye-safety limit is rejected.
#[test]
fn check_certifies_firmware_tables_and_rejects_a_raised_code() {
    let dir = tempfile::tempdir().unwrap();
    for preset in ["paper", "vls128"] {
        let (json, bin) = table_files(dir.path(), preset);
        let sensor = write(dir.path(), "s.toml", sensor_file(preset));
        let table =
            FirmwareTable::from_json(&std::fs::read_to_string(&json).unwrap(), "t").unwrap();
        assert_eq!(binary::decode(&std::fs::read(&bin).unwrap()).unwrap(), {
            let mut t = table.clone();
            // The binary does not carry start_deg (informational).
            for (b, d) in t
                .bins
                .iter_mut()
                .zip(binary::decode(&std::fs::read(&bin).unwrap()).unwrap().bins)
            {
                b.start_deg = d.start_deg;
            }
            t
        });
        let (violations, report) = check_table_evaluated(&table);
        assert!(violations.is_empty(), "{violations:?}");
        let report = report.unwrap();
        for file in [&json, &bin] {
            for extra in [
                vec![],
                vec!["--preset", preset],
                vec!["--sensor", s(&sensor)],
            ] {
                let mut args = vec![s(file), "--format", "json"];
                args.extend(extra.iter().copied());
                let (code, out, err) = check(&args);
                assert_eq!(code, Some(0), "{args:?}: {out} {err}");
                let v: Value = serde_json::from_str(&out).unwrap();
                assert_eq!(v["certified"], true);
                assert_eq!(v["eye_safety_evaluated"], true);
                assert_eq!(v["violations"], Value::Array(vec![]));
                let e = &v["eye_safety"];
                assert_eq!(e["worst_ratio"], report.worst_ratio_ppm as f64 / 1e6);
                assert_eq!(
                    e["worst_azimuth_deg"],
                    f64::from(report.azimuth_mdeg) / 1000.0
                );
                assert_eq!(e["binding_rule"], report.rule.to_string());
                for key in ["margin", "stalled_rotor_ratio"] {
                    assert!(e.get(key).is_some(), "{key}");
                }
                assert!(v["summary"].is_object());
            }
            let (code, out, _) = check(&[s(file)]);
            assert_eq!(code, Some(0));
            assert!(
                out.starts_with("certified: ") && out.contains("eye safety: Class 1"),
                "{out}"
            );
        }
        // One code raised past the eye-safety limit (past the integer
        // check's Rule 1 code, which the head's short windows no longer
        // keep far below it): first with the table's declared caps (the
        // integer rules catch it), then with the caps raised too, so that
        // only the eye-safety evaluation can.
        let worst = (0..table.bins.len())
            .max_by_key(|&i| table.bins[i].power_code)
            .unwrap();
        let rule_one = gaze_lidar::firmware::eye::IntEyeLimits::derive(&table)
            .unwrap()
            .pulse_code_cap();
        let raised = (table.bins[worst].power_code * 3 / 2 + 1)
            .max(u32::try_from(rule_one + 1).unwrap_or(u32::MAX));
        for loosen_caps in [false, true] {
            let mut t = table.clone();
            t.bins[worst].power_code = raised;
            if loosen_caps {
                t.limits.power_code_max = u32::MAX;
                t.limits.energy_budget = u64::MAX;
                for b in &mut t.bins {
                    b.power_code_cap = u32::MAX;
                }
            }
            let tj = write(dir.path(), "raised.json", t.to_json().unwrap());
            let tb = write(dir.path(), "raised.bin", binary::encode(&t));
            for file in [&tj, &tb] {
                let (code, out, err) = check(&[s(file), "--format", "json"]);
                assert_eq!(code, Some(1), "{out} {err}");
                let v: Value = serde_json::from_str(&out).unwrap();
                assert_eq!(v["certified"], false);
                let limits: Vec<&str> = v["violations"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x["limit"].as_str().unwrap())
                    .collect();
                let named = if loosen_caps {
                    "eye_safety"
                } else {
                    "power_code"
                };
                assert!(limits.contains(&named), "{limits:?}");
                if loosen_caps {
                    assert_eq!(limits, vec!["eye_safety"], "only eye safety can see it");
                }
                let (code, out, _) = check(&[s(file)]);
                assert_eq!(code, Some(1));
                assert!(out.lines().all(|l| l.starts_with("violation: ")), "{out}");
            }
        }
    }
}

/// A table checked for another sensor names what differs; a table without
/// eye-safety parameters is not certified unless `--no-eye-safety`; broken
/// tables are bad input (exit 2) naming the field, with line and column for
/// JSON; sums past u64 are reported, not a panic.
#[test]
fn tables_against_the_wrong_sensor_and_broken_tables() {
    let dir = tempfile::tempdir().unwrap();
    let (json, bin) = table_files(dir.path(), "paper");
    for file in [&json, &bin] {
        let (code, out, _) = check(&[s(file), "--preset", "vls128"]);
        assert_eq!(code, Some(1));
        for key in [
            "pulse_rate_hz",
            "power_accounting",
            "eye_safety",
            "frame_ticks",
        ] {
            assert!(out.contains(&format!("violation: {key}")), "{key}: {out}");
        }
    }
    let table = FirmwareTable::from_json(&std::fs::read_to_string(&json).unwrap(), "t").unwrap();
    let mut no_eye = table.clone();
    no_eye.eye_safety = None;
    let p = write(dir.path(), "noeye.json", no_eye.to_json().unwrap());
    let (code, out, _) = check(&[s(&p)]);
    assert_eq!(code, Some(1));
    assert!(out.contains("eye_safety"), "{out}");
    let (code, out, _) = check(&[s(&p), "--no-eye-safety"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("NOT evaluated"), "{out}");
    // A subnormal pulse rate or DAC step is never certified: bad input at
    // the header boundary (exit 2), in JSON and binary alike.
    for (rate, step, field) in [
        (5e-324, table.power_w_per_code, "pulse_rate_hz"),
        (table.pulse_rate_hz, 5e-324, "power_w_per_code"),
    ] {
        let mut t = table.clone();
        t.pulse_rate_hz = rate;
        t.power_w_per_code = step;
        let p = write(dir.path(), "sub.json", t.to_json().unwrap());
        assert_bad_input(&run(&["check", s(&p)], None), field);
        let p = write(dir.path(), "sub.bin", binary::encode(&t));
        assert_bad_input(&run(&["check", s(&p)], None), field);
    }
    // Broken inputs.
    let text = std::fs::read_to_string(&json).unwrap();
    let unknown = text.replacen("\"tick_hz\"", "\"tick_hz_x\": 1, \"tick_hz\"", 1);
    let p = write(dir.path(), "bad.json", unknown);
    assert_bad_input(&run(&["check", s(&p)], None), "bad.json:");
    let mut bytes = std::fs::read(&bin).unwrap();
    bytes.truncate(bytes.len() - 3);
    let p = write(dir.path(), "bad.bin", bytes);
    assert_bad_input(&run(&["check", s(&p)], None), "firmware-bin");
    // Sums past u64::MAX (a crafted table): exit 1, no panic, valid JSON.
    let mut huge = table.clone();
    huge.power_accounting = gaze_lidar::model::lidar::PowerAccounting::Time;
    for b in &mut huge.bins {
        b.power_code = u32::MAX;
        b.dwell_ticks = 1 << 50;
    }
    let p = write(dir.path(), "huge.json", huge.to_json().unwrap());
    let (code, out, _) = check(&[s(&p), "--format", "json"]);
    assert_eq!(code, Some(1));
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["certified"], false);
}

/// The `firmware_check` fuzz target's oracle, on its committed seeds and on
/// real and tampered tables: the integer rules accept exactly the tables
/// the integer restatement accepts, `check_table` keeps every integer
/// violation and certifies only tables within their integer limits.
#[test]
fn check_table_agrees_with_the_integer_restatement() {
    use gaze_lidar::firmware::check::within_integer_limits;
    use gaze_lidar::firmware::{check_integer, check_table};
    let dir = tempfile::tempdir().unwrap();
    let mut tables = Vec::new();
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/firmware_check");
    for e in std::fs::read_dir(seeds).unwrap() {
        if let Ok(t) = binary::decode(&std::fs::read(e.unwrap().path()).unwrap()) {
            tables.push(t);
        }
    }
    for preset in ["paper", "vls128"] {
        let (json, _) = table_files(dir.path(), preset);
        let t = FirmwareTable::from_json(&std::fs::read_to_string(&json).unwrap(), "t").unwrap();
        for k in 0..6 {
            let mut u = t.clone();
            match k {
                0 => {}
                1 => u.bins[3].power_code += 1_000,
                2 => u.bins[3].width_mdeg += 1,
                3 => u.bins[3].dwell_ticks += 1,
                4 => u.limits.energy_budget /= 2,
                _ => u.eye_safety = None,
            }
            tables.push(u);
        }
    }
    let (mut accepted, mut rejected) = (0, 0);
    for t in &tables {
        let within = within_integer_limits(t);
        let integer = check_integer(t);
        assert_eq!(integer.is_empty(), within, "{integer:?}");
        let full = check_table(t);
        assert!(integer.iter().all(|v| full.contains(v)));
        if full.is_empty() {
            assert!(within && t.eye_safety.is_some());
            accepted += 1;
        } else {
            rejected += 1;
        }
    }
    assert!(accepted >= 2 && rejected >= 8, "{accepted} {rejected}");
}

/// A profile whose `head.cycle_s` is 0 is refused naming `head.cycle_s`
/// (not the consequence, an infinite `1/head.cycle_s`); a `--config`
/// setting a `pulse_rate_hz` its head preset cannot fire is bad input (the
/// config's inconsistency, not an infeasible problem) naming
/// `lidar.pulse_rate_hz` at its line and column, with no output written.
#[test]
fn a_head_s_cycle_and_a_config_rate_against_its_head_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut p: Value = serde_json::from_str(&range_profile("vlp16")).unwrap();
    p["limits"]["eye_safety"]["head"]["cycle_s"] = Value::from(0.0);
    let file = write(dir.path(), "c0.json", p.to_string());
    let (code, out, err) = check(&[s(&file)]);
    assert_eq!(code, Some(1), "{out}{err}");
    assert!(out.contains("head.cycle_s = 0"), "{out}");
    assert!(!out.contains("= inf"), "{out}");

    let config = write(
        dir.path(),
        "c1.toml",
        "bins = 36\n[lidar]\npreset = \"vlp16\"\npulse_rate_hz = 20000.0\n",
    );
    let target = dir.path().join("o.json");
    let o = run(
        &[
            "profile",
            "--config",
            s(&config),
            "--gaze-deg",
            "90",
            "--out",
            s(&target),
        ],
        None,
    );
    assert_bad_input(&o, "c1.toml:4:17: lidar.pulse_rate_hz");
    assert!(!target.exists());
}
