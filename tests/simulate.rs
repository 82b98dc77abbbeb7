//! Issue 5 acceptance: the intersection experiment.

mod common;

use common::{assert_bad_input, run, stdout};
use gaze_lidar::planner::Mode;
use gaze_lidar::sim::{self, GridResult, ModelKind, SimConfig};

fn grid(models: &[ModelKind], trials: usize, brute_force: bool) -> GridResult {
    let config = SimConfig {
        models: models.to_vec(),
        trials,
        brute_force,
        ..SimConfig::default()
    };
    sim::run(&config, &|| {}).unwrap()
}

#[test]
fn culling_is_bit_identical_to_brute_force() {
    let both = [ModelKind::Argus, ModelKind::Physical];
    let fast = grid(&both, 2, false);
    let slow = grid(&both, 2, true);
    assert_eq!(fast.trials, slow.trials);
    assert_eq!(fast.rows, slow.rows);
}

#[test]
fn same_seed_same_json_whatever_the_threads() {
    let args = [
        "simulate", "--trials", "3", "--seed", "42", "--format", "json", "--model", "physical",
    ];
    let a = run(&args, None);
    assert_eq!(a.status.code(), Some(0));
    let b = {
        let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_gaze-lidar"));
        cmd.args(args).env("RAYON_NUM_THREADS", "1");
        cmd.output().unwrap()
    };
    assert_eq!(a.stdout, b.stdout);
    let v: serde_json::Value = serde_json::from_slice(&a.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 12);
    for key in [
        "model",
        "variant",
        "fog_pct",
        "trials",
        "detected",
        "tta_median_s",
        "tta_q1_s",
        "tta_q3_s",
        "density_median_pts_per_deg",
    ] {
        assert!(rows[0].get(key).is_some(), "missing {key}");
    }
    let c = run(
        &[
            "simulate", "--trials", "3", "--seed", "43", "--format", "json", "--model", "physical",
        ],
        None,
    );
    assert_ne!(a.stdout, c.stdout, "the seed matters");
}

fn median(r: &GridResult, m: ModelKind, v: Mode, fog: u32) -> f64 {
    r.row(m, v.name(), fog)
        .and_then(|x| x.tta_median_s)
        .unwrap()
}

fn density(r: &GridResult, m: ModelKind, v: Mode, fog: u32) -> f64 {
    r.row(m, v.name(), fog).unwrap().density_median_pts_per_deg
}

#[test]
fn paper_grid_at_100_trials_shows_the_expected_effects() {
    let r = grid(&[ModelKind::Argus, ModelKind::Physical], 100, false);
    let a = ModelKind::Argus;
    let base0 = median(&r, a, Mode::Baseline, 0);
    assert!((5.0..=6.6).contains(&base0), "argus clear baseline {base0}");
    assert!(median(&r, a, Mode::Baseline, 25) < base0);
    assert!(median(&r, a, Mode::Baseline, 50) < median(&r, a, Mode::Baseline, 25));
    for fog in [25, 50] {
        let gain = median(&r, a, Mode::Range, fog) - median(&r, a, Mode::Baseline, fog);
        assert!(gain >= 0.5, "argus range gain at {fog} %: {gain}");
    }
    assert!((median(&r, a, Mode::Range, 0) - base0).abs() <= 0.35);
    for fog in [0, 25, 50] {
        let d = (median(&r, a, Mode::Resolution, fog) - median(&r, a, Mode::Baseline, fog)).abs();
        assert!(d <= 0.35, "argus resolution vs baseline at {fog} %: {d}");
        assert!(density(&r, a, Mode::Resolution, fog) > density(&r, a, Mode::Baseline, fog));
        assert!(density(&r, a, Mode::Joint, fog) >= density(&r, a, Mode::Resolution, fog));
    }
    let p = ModelKind::Physical;
    for fog in [0, 25, 50] {
        assert!(
            median(&r, p, Mode::Range, fog) >= median(&r, p, Mode::Baseline, fog),
            "physical range at {fog} %"
        );
        assert!(density(&r, p, Mode::Resolution, fog) > density(&r, p, Mode::Baseline, fog));
    }
    assert!(median(&r, p, Mode::Baseline, 25) < median(&r, p, Mode::Baseline, 0));
    assert!(median(&r, p, Mode::Baseline, 50) < median(&r, p, Mode::Baseline, 25));
    // Every trial detects the right car before arrival in these conditions.
    assert!(r.rows.iter().all(|x| x.detected == x.trials));
    // The report is generated from the run and names the physics limits.
    let md = sim::report::render(&r, &SimConfig::default());
    assert!(
        md.contains("1.20·P̄") && md.contains("more energy than the baseline"),
        "{md}"
    );
}

#[test]
fn plots_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(
        &[
            "simulate",
            "--trials",
            "2",
            "--model",
            "argus",
            "--fog",
            "0",
            "--plots",
            dir.path().to_str().unwrap(),
            "--format",
            "csv",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    let csv = stdout(&o);
    assert_eq!(csv.lines().count(), 1 + 4, "{csv}");
    for f in [
        "tta_argus.svg",
        "tta_argus.png",
        "density_argus.svg",
        "profiles_polar.svg",
        "profiles_polar.png",
    ] {
        let meta = std::fs::metadata(dir.path().join(f)).unwrap();
        assert!(meta.len() > 1000, "{f}");
    }
    let svg = std::fs::read_to_string(dir.path().join("tta_argus.svg")).unwrap();
    assert!(svg.contains("baseline") && svg.contains("fog 0 %"));
}

#[test]
fn bad_simulate_input() {
    assert_bad_input(&run(&["simulate", "--trials", "0"], None), "trials");
    assert_bad_input(&run(&["simulate", "--trials", "-5"], None), "trials");
    assert_bad_input(&run(&["simulate", "--fog", "30"], None), "fog");
    assert_bad_input(&run(&["simulate", "--model", "carla"], None), "model");
    assert_bad_input(&run(&["simulate", "--detect", "3/2"], None), "detect");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(&path, "speed_kmh = \"fast\"\n").unwrap();
    assert_bad_input(
        &run(&["simulate", "--scenario", path.to_str().unwrap()], None),
        "speed_kmh",
    );
    std::fs::write(&path, "bend_distance_m = -1.0\n").unwrap();
    assert_bad_input(
        &run(&["simulate", "--scenario", path.to_str().unwrap()], None),
        "bend_distance_m",
    );
    assert_bad_input(
        &run(&["simulate", "--scenario", "/no/such.toml"], None),
        "/no/such.toml",
    );
}

#[test]
fn scenario_speed_changes_tta_as_expected() {
    // At 30 km/h the car needs longer to arrive from the same visible distance.
    let mut slow = SimConfig {
        models: vec![ModelKind::Argus],
        variants: vec![gaze_lidar::sim::Variant::Baseline],
        fog_pcts: vec![0],
        trials: 5,
        ..SimConfig::default()
    };
    slow.scenario.speed_kmh = 30.0;
    let r = sim::run(&slow, &|| {}).unwrap();
    let t = r.rows[0].tta_median_s.unwrap();
    assert!((9.0..10.5).contains(&t), "{t}");
}

#[cfg(feature = "solver")]
#[test]
fn optimized_variant_runs_on_shared_phase_solutions() {
    use gaze_lidar::sim::Variant;
    let config = SimConfig {
        models: vec![ModelKind::Physical],
        variants: vec![Variant::Baseline, Variant::Optimized],
        fog_pcts: vec![25],
        trials: 6,
        ..SimConfig::default()
    };
    let r = sim::run(&config, &|| {}).unwrap();
    let base = r.row(ModelKind::Physical, "baseline", 25).unwrap();
    let opt = r.row(ModelKind::Physical, "optimized", 25).unwrap();
    assert_eq!(opt.detected, opt.trials);
    // More power and points where the driver does not look: detected earlier.
    assert!(opt.tta_median_s.unwrap() > base.tta_median_s.unwrap());
    assert!(opt.density_median_pts_per_deg > base.density_median_pts_per_deg);
    // Same seed, same answer (the phase table is built in parallel).
    assert_eq!(sim::run(&config, &|| {}).unwrap().rows, r.rows);
}
