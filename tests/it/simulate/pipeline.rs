//! The paper's pipeline sampled as
//! CARLA samples, cars with ground clearance, the planar grid's shared
//! casts, and the ARGUS road mask's memory.

use crate::common;

use common::{assert_bad_input, run, stdout};
use gaze_lidar::sim::carla::geometry::{PosedBox, Surface};
use gaze_lidar::sim::{
    self, Arrival, Detector, Geometry, KOfN, ModelKind, Sampling, Scenario, SimConfig, Variant,
};
use nalgebra::{Point3, Vector3};

#[test]
fn planar_shared_casts_equal_every_cell_cast_alone() {
    // Both models, the paper's four variants, all fog levels, a k-of-n
    // rule and gaze jitter: the grouped run is the per-cell run, bit for bit.
    let scenario = Scenario {
        gaze_jitter_deg: 5.0,
        ..Scenario::default()
    };
    for detection in [KOfN::default(), KOfN { k: 2, n: 3 }] {
        let config = |per_cell| SimConfig {
            trials: 3,
            seed: 11,
            detection,
            per_cell,
            scenario: scenario.clone(),
            ..SimConfig::default()
        };
        let grouped = sim::run(&config(false), &|| {}).unwrap();
        let alone = sim::run(&config(true), &|| {}).unwrap();
        assert_eq!(grouped.trials, alone.trials);
        assert_eq!(grouped.rows, alone.rows);
        assert_eq!(grouped.trials.len(), 2 * 4 * 3 * 3);
    }
    // Argus arrival and brute force too.
    let config = |per_cell| SimConfig {
        trials: 2,
        seed: 5,
        per_cell,
        brute_force: true,
        arrival: Arrival::ArgusCentre,
        ..SimConfig::default()
    };
    assert_eq!(
        sim::run(&config(false), &|| {}).unwrap().trials,
        sim::run(&config(true), &|| {}).unwrap().trials
    );
}

/// A short carla scene (cars 40 m out at 100 km/h).
fn short_carla() -> Scenario {
    let mut s = Scenario {
        speed_kmh: 100.0,
        ..Scenario::default()
    };
    s.carla.spawn_distance_m = 40.0;
    s
}

fn carla_config(sampling: Option<Sampling>, brute_force: bool) -> SimConfig {
    SimConfig {
        models: vec![ModelKind::Argus, ModelKind::Physical],
        variants: vec![Variant::Baseline, Variant::Resolution],
        fog_pcts: vec![0, 50],
        trials: 2,
        seed: 3,
        geometry: Geometry::Carla,
        detector: Detector::Argus,
        arrival: Arrival::ArgusCentre,
        sampling,
        brute_force,
        scenario: short_carla(),
        ..SimConfig::default()
    }
}

#[test]
fn carla_sampling_fast_path_equals_reference_in_every_sampling() {
    for sampling in [Sampling::Carla, Sampling::CarlaAsync, Sampling::Drift] {
        let fast = sim::run(&carla_config(Some(sampling), false), &|| {}).unwrap();
        let slow = sim::run(&carla_config(Some(sampling), true), &|| {}).unwrap();
        assert_eq!(fast.trials, slow.trials, "{sampling:?}");
        assert!(fast.rows.iter().all(|r| r.sampling == Some(sampling)));
    }
}

#[test]
fn carla_sampling_is_the_default_and_fires_whole_ticks() {
    let default = sim::run(&carla_config(None, false), &|| {}).unwrap();
    let carla = sim::run(&carla_config(Some(Sampling::Carla), false), &|| {}).unwrap();
    let drift = sim::run(&carla_config(Some(Sampling::Drift), false), &|| {}).unwrap();
    assert_eq!(default.trials, carla.trials);
    assert_ne!(carla.trials, drift.trials);
    for t in &carla.trials {
        // A whole number of 0.05 s ticks (drift stops at the last pulse).
        let ticks = t.outcome.duration_s / 0.05;
        assert!((ticks - ticks.round()).abs() < 1e-9, "{ticks}");
    }
    for t in drift.trials.iter().filter(|t| t.variant == "baseline") {
        let pulses = t.outcome.duration_s * 7812.5;
        assert!((pulses - pulses.round()).abs() < 1e-6, "{pulses}");
    }
}

#[test]
fn car_bodies_stand_on_their_ground_clearance() {
    // A ray along the road at 0.1 m passes under a car lifted 0.15 m and
    // meets a car standing on the road; one at 0.2 m meets both.
    let size = Vector3::new(4.5, 1.8, 1.4);
    let lifted = PosedBox::above_road(20.0, 0.0, 0.15, 0.0, size);
    let standing = PosedBox::on_road(20.0, 0.0, 0.0, Vector3::new(4.5, 1.8, 1.55));
    let d = Vector3::new(1.0, 0.0, 0.0);
    for (z, hits_lifted) in [
        (0.1, false),
        (0.149, false),
        (0.151, true),
        (0.2, true),
        (1.54, true),
    ] {
        let o = Point3::new(0.0, 0.0, z);
        assert_eq!(
            lifted.ray_hit(&o, &d, Surface::Vehicle(0)).is_some(),
            hits_lifted,
            "{z}"
        );
        let h = standing.ray_hit(&o, &d, Surface::Vehicle(0)).unwrap();
        assert!((h.range_m - 17.75).abs() < 1e-12);
    }
    // Same roof either way.
    let (_, z) = lifted.bounds();
    assert!(
        (z.0 - 0.15).abs() < 1e-12 && (z.1 - 1.55).abs() < 1e-12,
        "{z:?}"
    );
}

#[test]
fn ground_clearance_and_jitter_are_range_checked() {
    for (key, value) in [
        ("vehicle_ground_clearance_m", "-0.1"),
        ("vehicle_ground_clearance_m", "0.9"),
        ("async_tick_jitter_frac", "0.95"),
        ("async_tick_jitter_frac", "-0.01"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.toml");
        std::fs::write(&path, format!("[carla]\n{key} = {value}\n")).unwrap();
        let o = run(
            &[
                "simulate",
                "--geometry",
                "carla",
                "--trials",
                "1",
                "--scenario",
                path.to_str().unwrap(),
            ],
            None,
        );
        assert_bad_input(&o, key);
    }
}

#[test]
fn sampling_needs_the_carla_geometry() {
    for s in ["carla", "carla-async"] {
        let o = run(&["simulate", "--trials", "1", "--sampling", s], None);
        assert_bad_input(&o, "--sampling");
    }
    // Drift is the planar geometry's own clock: accepted, the same output.
    let a = run(
        &[
            "simulate", "--trials", "2", "--model", "argus", "--format", "json",
        ],
        None,
    );
    let b = run(
        &[
            "simulate",
            "--trials",
            "2",
            "--model",
            "argus",
            "--format",
            "json",
            "--sampling",
            "drift",
        ],
        None,
    );
    assert_eq!(a.status.code(), Some(0));
    assert_eq!(a.stdout, b.stdout);
    assert!(!stdout(&a).contains("sampling"));
}

#[test]
fn fine_road_mask_over_a_long_trace_runs_in_4_gib() {
    // Guards the road mask's memory: `argus_cell_m = 0.05`, `range_m = 1000` allocated a
    // dense 1.6 GB mask per detector and aborted under a 4 GiB cap.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fine.toml");
    std::fs::write(&path, "[carla]\nargus_cell_m = 0.05\nrange_m = 1000.0\n").unwrap();
    let cmd = format!(
        "ulimit -v 4194304 && exec '{}' simulate --geometry carla --detector argus --trials 2 \
         --model argus --variant baseline --variant joint --format json --scenario '{}'",
        env!("CARGO_BIN_EXE_gaze-lidar"),
        path.display()
    );
    let o = std::process::Command::new("bash")
        .args(["-c", &cmd])
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["rows"].as_array().unwrap().len(), 6);
}
