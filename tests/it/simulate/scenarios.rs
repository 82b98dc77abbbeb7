//! Gaze behaviour from the stream drives `simulate`, and
//! the scenario files under `examples/scenarios/`.

use crate::common;

use common::{assert_bad_input, run, stderr};
use gaze_lidar::gaze::Format;
use gaze_lidar::pipeline::PipelineConfig;
use gaze_lidar::sim::gaze_drive::{self, Behaviour, GazeDrive, GazeSource, Trace};
use gaze_lidar::sim::{self, GridResult, ModelKind, Scenario, SimConfig, Variant};

fn scenario(name: &str) -> Scenario {
    let path = format!("{}/examples/scenarios/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    Scenario::from_toml(&text, &path).unwrap()
}

fn config(scenario: Scenario, trials: usize) -> SimConfig {
    SimConfig {
        models: vec![ModelKind::Physical],
        variants: vec![Variant::Baseline, Variant::Range, Variant::Joint],
        fog_pcts: vec![0],
        trials,
        seed: 5,
        scenario,
        ..SimConfig::default()
    }
}

fn driven(config: &SimConfig, source: GazeSource) -> GridResult {
    let drive = GazeDrive {
        source,
        pipeline: PipelineConfig::default(),
    };
    gaze_drive::run(config, &drive, &|| {}).unwrap()
}

fn behaviour(spec: &str) -> GazeSource {
    GazeSource::Behaviour(Behaviour::parse(spec, 90.0).unwrap())
}

#[test]
fn every_scenario_file_runs() {
    let dir = format!("{}/examples/scenarios", env!("CARGO_MANIFEST_DIR"));
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 3, "{names:?}");
    for name in &names {
        let r = sim::run(&config(scenario(name), 3), &|| {}).unwrap();
        assert_eq!(r.rows.len(), 3, "{name}");
        assert!(r.rows.iter().all(|x| x.trials == 3), "{name}");
    }
}

#[test]
fn pedestrian_is_a_small_slow_target() {
    let sc = scenario("pedestrian.toml");
    assert_eq!((sc.vehicle_width_m, sc.speed_kmh), (0.5, 5.0));
    let c = SimConfig {
        fog_pcts: vec![0, 50],
        ..config(sc, 3)
    };
    let r = sim::run(&c, &|| {}).unwrap();
    for row in &r.rows {
        assert_eq!(row.detected, 3, "{row:?}");
        // Seen at most from the corner 60 m away (+3 m offset) at 1.39 m/s.
        let tta = row.tta_median_s.unwrap();
        assert!(tta > 1.0 && tta < 63.0 / (5.0 / 3.6), "{tta}");
    }
    // Far and small: in clear air seen as it comes into view, in fog much later.
    let at = |variant: &str, fog: u32| {
        r.row(ModelKind::Physical, variant, fog)
            .unwrap()
            .tta_median_s
            .unwrap()
    };
    assert!(at("baseline", 0) > 40.0, "{}", at("baseline", 0));
    assert!(at("baseline", 50) < at("baseline", 0) - 5.0);
}

#[test]
fn second_car_reports_both_cars() {
    let r = sim::run(&config(scenario("second_car.toml"), 3), &|| {}).unwrap();
    for row in &r.rows {
        assert_eq!((row.detected, row.left_detected), (3, 3), "{row:?}");
    }
}

#[test]
fn false_alarms_are_counted_and_can_come_early() {
    let with = config(scenario("false_alarms.toml"), 20);
    let r = sim::run(&with, &|| {}).unwrap();
    let base = sim::run(&config(Scenario::default(), 20), &|| {}).unwrap();
    for (row, b) in r.rows.iter().zip(&base.rows) {
        // 0.01 per frame over ≈ 2,600 frames: ≈ 26 expected.
        assert!(
            row.false_alarms_per_frame > 0.004 && row.false_alarms_per_frame < 0.02,
            "{row:?}"
        );
        assert_eq!(b.false_alarms_per_frame, 0.0);
        assert_eq!(b.early_false, 0);
        // The true detections are untouched.
        assert_eq!(row.tta_median_s, b.tta_median_s);
    }
    let early: usize = r.rows.iter().map(|x| x.early_false).sum();
    assert!(early > 0, "some false alarm precedes a detection");
    // An early false TTA is larger than the true one (earlier in time).
    for t in &r.trials {
        if let (Some(e), Some(d)) = (t.outcome.early_false_tta_s, t.outcome.tta_s[1]) {
            assert!(e > d, "{e} {d}");
        }
        assert!(t.outcome.early_false_tta_s.is_none() || t.outcome.false_alarms > 0);
    }
    // Every variant of a trial sees the same false alarms (paired).
    let per_variant: Vec<Vec<u64>> = r
        .rows
        .iter()
        .map(|row| {
            r.trials
                .iter()
                .filter(|t| t.variant == row.variant)
                .map(|t| t.outcome.false_alarms)
                .collect()
        })
        .collect();
    assert!(per_variant.windows(2).all(|w| w[0] == w[1]));
}

#[test]
fn fixating_through_the_stream_is_the_constant_gaze_run() {
    // No jitter: the driven run plans the same profile every frame as the
    // plain run plans once, so the outcomes agree bit for bit.
    let sc = Scenario {
        gaze_jitter_deg: 0.0,
        ..Scenario::default()
    };
    let c = config(sc, 4);
    let plain = sim::run(&c, &|| {}).unwrap();
    let d = driven(&c, behaviour("fixate"));
    assert_eq!(plain.trials.len(), d.trials.len());
    for (a, b) in plain.trials.iter().zip(&d.trials) {
        assert_eq!((a.variant, a.trial), (b.variant, b.trial));
        assert_eq!(a.outcome.tta_s, b.outcome.tta_s);
        assert_eq!(a.outcome.hybrid_tta_s, b.outcome.hybrid_tta_s);
        assert_eq!(a.outcome.roi_points, b.outcome.roi_points);
        assert_eq!(b.outcome.fail_safe_frames, 0);
    }
}

#[test]
fn each_named_behaviour_runs_and_is_deterministic() {
    let c = config(Scenario::default(), 3);
    for spec in [
        "fixate",
        "scan",
        "mirror",
        "blink",
        "scan:rate_hz=1,step_deg=15",
    ] {
        let a = driven(&c, behaviour(spec));
        let b = driven(&c, behaviour(spec));
        assert_eq!(a, b, "{spec}");
        assert_eq!(a.rows.len(), 3, "{spec}");
    }
    // The scan sweeps the profile: some frames aim right, where the car comes from.
    let scan = driven(&c, behaviour("scan"));
    let fix = driven(&c, behaviour("fixate"));
    assert_ne!(scan.trials, fix.trials);
}

#[test]
fn a_blink_at_the_wrong_moment_runs_the_fail_safe_profile() {
    // Long blinks: many frames fail-safe; in some trial the car is detected
    // in a fail-safe frame, and the record says so.
    let c = config(Scenario::default(), 6);
    let blink = driven(&c, behaviour("blink:every_s=1,blink_s=0.5"));
    assert!(blink.rows.iter().all(|r| r.fail_safe_frame_share > 0.3));
    let in_fail_safe = blink
        .trials
        .iter()
        .filter(|t| t.variant != "baseline")
        .filter(|t| t.outcome.detected_in_fail_safe[1] == Some(true))
        .count();
    assert!(in_fail_safe > 0);
    // The fixating driver never does.
    let fix = driven(&c, behaviour("fixate"));
    assert!(fix
        .trials
        .iter()
        .all(|t| t.outcome.fail_safe_frames == 0
            && t.outcome.detected_in_fail_safe[1] == Some(false)));
    // The baseline is the fail-safe profile: blinking cannot change it.
    for (a, b) in blink.trials.iter().zip(&fix.trials) {
        if a.variant == "baseline" {
            assert_eq!(a.outcome.tta_s, b.outcome.tta_s);
        }
    }
}

#[test]
fn a_recorded_trace_drives_the_profile() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gaze/");
    let c = config(Scenario::default(), 3);
    for (file, format) in [
        ("right.csv", Format::Csv),
        ("varjo_base.csv", Format::Varjo),
        ("neon_gaze.csv", Format::Neon),
    ] {
        let text = std::fs::read_to_string(format!("{dir}{file}")).unwrap();
        let trace = Trace::parse(&text, format, file).unwrap();
        let r = driven(&c, GazeSource::Trace(trace));
        assert_eq!(r.rows.len(), 3, "{file}");
        // right.csv marks 10 of its 101 samples invalid: fail-safe frames.
        let lossy = file == "right.csv";
        assert!(
            r.rows
                .iter()
                .all(|x| (!lossy || x.fail_safe_frame_share > 0.0) && x.fail_safe_frame_share < 0.5),
            "{file}: {:?}",
            r.rows
        );
    }
    // A malformed line is an error naming the file and line.
    let text = std::fs::read_to_string(format!("{dir}loss_200hz.jsonl")).unwrap();
    let e = Trace::parse(&text, Format::Jsonl, "loss_200hz.jsonl").unwrap_err();
    assert!(e.to_string().starts_with("loss_200hz.jsonl:151:"), "{e}");
    // A trace that loses tracking for 0.3 s of every 2 s runs fail-safe frames.
    let mut text = String::new();
    for k in 0..400 {
        let t = f64::from(k) * 0.005;
        let valid = !(1.0..1.3).contains(&t);
        text.push_str(&format!(
            "{{\"t_s\": {t}, \"gaze_deg\": 90.0, \"valid\": {valid}}}\n"
        ));
    }
    let trace = Trace::parse(&text, Format::Jsonl, "lossy").unwrap();
    let r = driven(&c, GazeSource::Trace(trace));
    for row in &r.rows {
        // ≥ 0.3 s of 2 s (plus the recovery) but far from all.
        assert!(
            row.fail_safe_frame_share > 0.15 && row.fail_safe_frame_share < 0.3,
            "{row:?}"
        );
    }
}

#[test]
fn cli_gaze_options() {
    let trace = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gaze/right.csv");
    let o = run(
        &[
            "simulate",
            "--trials",
            "2",
            "--fog",
            "0",
            "--gaze",
            trace,
            "--gaze-format",
            "csv",
            "--format",
            "json",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4);
    assert!(rows.iter().all(|r| r["model"] == "physical"));
    let o = run(
        &[
            "simulate",
            "--trials",
            "2",
            "--fog",
            "0",
            "--gaze-behaviour",
            "blink:blink_s=0.3",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_bad_input(
        &run(&["simulate", "--gaze-behaviour", "wink"], None),
        "'wink' is not one of",
    );
    assert_bad_input(
        &run(&["simulate", "--gaze-behaviour", "scan:rate=2"], None),
        "no parameter 'rate'",
    );
    assert_bad_input(
        &run(&["simulate", "--gaze-behaviour", "blink:blink_s=9"], None),
        "blink_s",
    );
    assert_bad_input(
        &run(
            &["simulate", "--gaze-behaviour", "fixate", "--model", "argus"],
            None,
        ),
        "--model physical",
    );
    assert_bad_input(
        &run(
            &["simulate", "--gaze", trace, "--gaze-format", "jsonl"],
            None,
        ),
        "right.csv:1",
    );
}

#[test]
fn the_report_tabulates_its_scenario_files() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.md");
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenarios/second_car.toml"
    );
    let o = run(
        &[
            "simulate",
            "--trials",
            "3",
            "--seed",
            "4",
            "--model",
            "physical",
            "--fog",
            "0",
            "--report",
            report.to_str().unwrap(),
            "--report-scenario",
            file,
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let md = std::fs::read_to_string(&report).unwrap();
    // The section holds the table the library computes for the same run
    // (every variant and fog level, 3 trials, seed 4), and the file's own
    // description.
    let expected = sim::run(
        &SimConfig {
            models: vec![ModelKind::Physical],
            trials: 3,
            seed: 4,
            scenario: scenario("second_car.toml"),
            ..SimConfig::default()
        },
        &|| {},
    )
    .unwrap();
    assert_eq!(expected.rows.len(), 12);
    let table = sim::report::scenario_table("second_car", &expected, 4);
    let section = md.split("### second_car\n").nth(1).expect("the section");
    assert!(section.contains(&table), "{section}");
    assert!(section.contains("Two cars arriving together"), "{section}");
    assert!(section.contains(&format!(
        "--scenario {file} --model physical --trials 3 --seed 4"
    )));
    // Without --report it is refused; a bad file is named, and nothing is written.
    assert_bad_input(
        &run(&["simulate", "--report-scenario", file], None),
        "--report-scenario",
    );
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "speed_kmh = -3.0\n").unwrap();
    let fresh = dir.path().join("fresh.md");
    assert_bad_input(
        &run(
            &[
                "simulate",
                "--trials",
                "2",
                "--report",
                fresh.to_str().unwrap(),
                "--report-scenario",
                bad.to_str().unwrap(),
            ],
            None,
        ),
        "speed_kmh",
    );
    assert!(!fresh.exists());
}

#[test]
fn the_committed_report_and_scenarios_doc_show_the_same_tables() {
    // docs/reproduction.md (scripts/experiment.sh) and docs/scenarios.md
    // (scripts/scenarios.sh) tabulate the pedestrian and two-car scenarios
    // with the same code, trials and seed: the tables agree byte for byte.
    let root = env!("CARGO_MANIFEST_DIR");
    let report = std::fs::read_to_string(format!("{root}/docs/reproduction.md")).unwrap();
    let doc = std::fs::read_to_string(format!("{root}/docs/scenarios.md")).unwrap();
    let table_after = |text: &str, heading: &str| -> String {
        let rest = text
            .split(heading)
            .nth(1)
            .unwrap_or_else(|| panic!("{heading}"));
        rest.lines()
            .skip_while(|l| !l.starts_with('|'))
            .take_while(|l| l.starts_with('|'))
            .collect::<Vec<_>>()
            .join("\n")
    };
    for name in ["pedestrian", "second_car", "false_alarms"] {
        let a = table_after(&report, &format!("### {name}\n"));
        let b = table_after(&doc, &format!("## {name}\n"));
        assert_eq!(a.lines().count(), 14, "{name}: {a}");
        assert_eq!(a, b, "{name}");
    }
    // The gaze tables: every named behaviour and a recorded trace of each
    // format, in the report's gaze section and in docs/scenarios.md.
    for source in [
        "--gaze-behaviour fixate",
        "--gaze-behaviour scan",
        "--gaze-behaviour mirror",
        "--gaze-behaviour blink",
        "--gaze tests/data/gaze/right.csv --gaze-format csv",
        "--gaze tests/data/gaze/varjo_base.csv --gaze-format varjo",
        "--gaze tests/data/gaze/neon_gaze.csv --gaze-format neon",
    ] {
        let heading = format!("### `{source}`\n");
        let a = table_after(&report, &heading);
        let b = table_after(&doc, &heading);
        assert_eq!(a.lines().count(), 14, "{source}: {a}");
        assert_eq!(a, b, "{source}");
    }
}

#[test]
fn the_report_tabulates_its_gaze_runs() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.md");
    let trace = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gaze/right.csv");
    let report_gaze = format!("csv={trace}");
    let o = run(
        &[
            "simulate",
            "--trials",
            "3",
            "--seed",
            "4",
            "--model",
            "physical",
            "--fog",
            "0",
            "--fog",
            "50",
            "--report",
            report.to_str().unwrap(),
            "--report-gaze-behaviour",
            "scan",
            "--report-gaze",
            &report_gaze,
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let md = std::fs::read_to_string(&report).unwrap();
    // Each section holds the table the library computes for the same gaze
    // (every variant at the run's fog levels, 3 trials, seed 4).
    let c = SimConfig {
        models: vec![ModelKind::Physical],
        fog_pcts: vec![0, 50],
        trials: 3,
        seed: 4,
        ..SimConfig::default()
    };
    let text = std::fs::read_to_string(trace).unwrap();
    for (args, source) in [
        ("--gaze-behaviour scan".to_owned(), behaviour("scan")),
        (
            format!("--gaze {trace} --gaze-format csv"),
            GazeSource::Trace(Trace::parse(&text, Format::Csv, trace).unwrap()),
        ),
    ] {
        let r = driven(&c, source);
        assert_eq!(r.rows.len(), 8);
        let table = sim::report::gaze_table(&args, &r, 4);
        assert!(
            table.lines().next().unwrap().contains("| fog % |"),
            "{table}"
        );
        let section = md
            .split(&format!("### `{args}`\n"))
            .nth(1)
            .unwrap_or_else(|| panic!("{args}: {md}"));
        assert!(section.contains(&table), "{section}");
        assert!(section.contains(&format!("{args} --fog 0 --fog 50 --trials 3 --seed 4")));
    }
    // Without --report it is refused, a bad source is named, and nothing
    // is written.
    assert_bad_input(
        &run(&["simulate", "--report-gaze-behaviour", "scan"], None),
        "--report-gaze",
    );
    let fresh = dir.path().join("fresh.md");
    for (flag, value, names) in [
        ("--report-gaze-behaviour", "wink", "'wink' is not one of"),
        ("--report-gaze", "right.csv", "FORMAT=PATH"),
        ("--report-gaze", "tobii2=x.csv", "tobii2"),
        ("--report-gaze", "jsonl=/no/such.jsonl", "/no/such.jsonl"),
    ] {
        assert_bad_input(
            &run(
                &[
                    "simulate",
                    "--trials",
                    "2",
                    "--report",
                    fresh.to_str().unwrap(),
                    flag,
                    value,
                ],
                None,
            ),
            names,
        );
        assert!(!fresh.exists());
    }
}

#[test]
fn the_carla_pipeline_refuses_the_gaze_stream_with_the_reason() {
    // The carla geometry plans one profile and one region of focus per
    // trial: a gaze stream cannot change them frame by frame there, so
    // `--gaze`/`--gaze-behaviour` are refused with that reason, for every
    // sampling and for the paper's detector.
    let trace = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/gaze/right.csv");
    for extra in [
        &["--geometry", "carla"][..],
        &["--geometry", "carla", "--sampling", "carla-async"][..],
        &[
            "--geometry",
            "carla",
            "--detector",
            "argus",
            "--arrival",
            "argus-centre",
            "--model",
            "physical",
        ][..],
    ] {
        for gaze in [
            &["--gaze-behaviour", "scan"][..],
            &["--gaze", trace, "--gaze-format", "csv"][..],
        ] {
            let mut args = vec!["simulate", "--trials", "1", "--fog", "0"];
            args.extend_from_slice(extra);
            args.extend_from_slice(gaze);
            assert_bad_input(
                &run(&args, None),
                "one profile and one region of focus per trial",
            );
        }
    }
    // The argus return model: its resolution variant is a fixed decimation.
    assert_bad_input(
        &run(
            &[
                "simulate",
                "--gaze-behaviour",
                "fixate",
                "--geometry",
                "carla",
                "--detector",
                "argus",
                "--model",
                "argus",
            ],
            None,
        ),
        "--gaze/--gaze-behaviour: only",
    );
}

#[test]
fn a_sweep_drives_every_value_from_the_gaze() {
    // `--sweep` with `--gaze-behaviour`: one table per key whose rows are
    // the gaze-driven grid of each value run alone, and one figure per key.
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &[
            "simulate",
            "--trials",
            "3",
            "--seed",
            "5",
            "--fog",
            "0",
            "--variant",
            "baseline",
            "--variant",
            "range",
            "--gaze-behaviour",
            "scan",
            "--sweep",
            "speed_kmh=40,60",
            "--format",
            "json",
            "--plots",
            dir.path().to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let values = v["sweeps"][0]["values"].as_array().unwrap();
    assert_eq!(values.len(), 2);
    for (value, speed) in values.iter().zip([40.0, 60.0]) {
        let s = Scenario {
            speed_kmh: speed,
            ..Scenario::default()
        };
        let c = SimConfig {
            models: vec![ModelKind::Physical],
            variants: vec![Variant::Baseline, Variant::Range],
            fog_pcts: vec![0],
            trials: 3,
            seed: 5,
            scenario: s,
            ..SimConfig::default()
        };
        let alone = driven(&c, behaviour("scan"));
        let rows = value["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 2);
        for (row, expected) in rows.iter().zip(&alone.rows) {
            assert_eq!(row["tta_median_s"].as_f64(), expected.tta_median_s);
            assert_eq!(
                row["fail_safe_frame_share"].as_f64(),
                Some(expected.fail_safe_frame_share)
            );
        }
    }
    // Slower cars arrive later from the same distance: the TTA grows.
    let tta = |i: usize| values[i]["rows"][0]["tta_median_s"].as_f64().unwrap();
    assert!(tta(0) > tta(1) + 1.0, "{} {}", tta(0), tta(1));
    let svg = std::fs::read_to_string(dir.path().join("sweep_speed_kmh.svg")).unwrap();
    assert!(svg.contains("speed_kmh"));
    // A key the gaze-driven grid does not read is refused.
    assert_bad_input(
        &run(
            &[
                "simulate",
                "--gaze-behaviour",
                "scan",
                "--sweep",
                "tick=0.05,0.1",
            ],
            None,
        ),
        "--geometry carla",
    );
}
