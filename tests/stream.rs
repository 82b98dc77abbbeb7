//! Issue 7 acceptance: the gaze pipeline through the binary.

mod common;

use common::{assert_bad_input, run, stderr, stdout};
use gaze_lidar::checker::check;
use gaze_lidar::model::angle::diff_deg;
use gaze_lidar::profile::Profile;

fn data(name: &str) -> String {
    format!("{}/tests/data/gaze/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// (t_s, state, gaze_deg, profile) per output line, each re-checked.
fn frames(out: &str) -> Vec<(f64, String, Option<f64>, Profile)> {
    out.lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let p = Profile::from_json(l, "frame").unwrap();
            assert!(check(&p).is_empty(), "uncertified frame: {:?}", check(&p));
            (
                v["t_s"].as_f64().unwrap(),
                v["state"].as_str().unwrap().to_owned(),
                v["gaze_deg"].as_f64(),
                p,
            )
        })
        .collect()
}

#[test]
fn two_seconds_with_a_loss_and_a_malformed_line() {
    let input = std::fs::read_to_string(data("loss_200hz.jsonl")).unwrap();
    let o = run(
        &["stream", "--preset", "paper", "--mode", "range"],
        Some(&input),
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(!err.contains("panicked"));
    assert!(err.contains("<stdin>:151: skipped"), "{err}");
    let f = frames(&stdout(&o));
    assert_eq!(f.len(), 40, "20 Hz for 2 s");
    for (t, state, gaze, p) in &f {
        // A frame is decided from the samples before its start: the loss
        // (invalid samples from 0.8 s to 1.195 s) shows from the frame after
        // 0.8 s to the frame at 1.2 s.
        let during_loss = *t > 0.8 && *t <= 1.2 + 1e-9;
        let startup = *t < 0.02;
        if during_loss || startup {
            assert_eq!(state, "fail_safe", "t = {t}");
            assert!(gaze.is_none());
            let powers: std::collections::BTreeSet<u64> =
                p.bins.iter().map(|b| b.power_w.to_bits()).collect();
            assert_eq!(powers.len(), 1, "uniform baseline during the loss");
        } else if *t >= 1.25 || (0.04..0.8).contains(t) {
            assert_eq!(state, "adaptive", "t = {t}");
            assert!(diff_deg(gaze.unwrap(), 90.0).abs() < 3.0);
        }
    }
    let adaptive_after = f.iter().filter(|x| x.0 > 1.2 && x.1 == "adaptive").count();
    assert!(adaptive_after >= 14, "{adaptive_after}");
    // Deterministic replay.
    let again = run(
        &["stream", "--preset", "paper", "--mode", "range"],
        Some(&input),
    );
    assert_eq!(again.stdout, o.stdout);
}

#[test]
fn csv_input() {
    let o = run(
        &[
            "stream",
            "--input",
            &data("right.csv"),
            "--format",
            "csv",
            "--mode",
            "joint",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let f = frames(&stdout(&o));
    assert_eq!(f.len(), 20);
    assert!(f
        .iter()
        .any(|x| x.1 == "fail_safe" && (0.3..0.45).contains(&x.0)));
    let g = f.iter().find_map(|x| x.2).unwrap();
    assert!(diff_deg(g, 270.1).abs() < 0.2, "{g}");
}

#[test]
fn varjo_input_rotates_head_relative_gaze_into_the_vehicle_frame() {
    let o = run(
        &[
            "stream",
            "--input",
            &data("varjo_base.csv"),
            "--format",
            "varjo",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let f = frames(&stdout(&o));
    assert_eq!(f.len(), 10, "0.5 s at 20 Hz");
    // Head 30° left, eyes 20° left in the head: 50° in the vehicle frame.
    let g = f.iter().find_map(|x| x.2).unwrap();
    assert!(diff_deg(g, 50.0).abs() < 1e-3, "{g}");
    // status 0 samples (k = 20..25, t = 0.20..0.24 s) force fail-safe.
    assert!(f
        .iter()
        .any(|x| x.1 == "fail_safe" && (0.2..0.3).contains(&(x.0 - f[0].0))));
}

#[test]
fn pupil_neon_input() {
    let o = run(
        &[
            "stream",
            "--input",
            &data("neon_gaze.csv"),
            "--format",
            "neon",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let f = frames(&stdout(&o));
    assert_eq!(f.len(), 6);
    let g = f.iter().find_map(|x| x.2).unwrap();
    assert!(
        diff_deg(g, -10.01).abs() < 0.02,
        "10° right of the camera: {g}"
    );
    assert!(
        f.iter().any(|x| x.1 == "fail_safe" && x.0 - f[0].0 >= 0.2),
        "not worn at 0.20–0.275 s"
    );
}

#[test]
fn recorded_files_fail_fast_with_the_line_number() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.jsonl");
    std::fs::write(
        &path,
        "{\"t_s\": 0.0, \"gaze_deg\": 90}\n{\"t_s\": 0.005, \"gaze_deg\": \"left\"}\n",
    )
    .unwrap();
    let o = run(&["stream", "--input", path.to_str().unwrap()], None);
    assert_bad_input(&o, "bad.jsonl:2");
    assert!(stdout(&o).lines().count() <= 1);
    let path = dir.path().join("bad.csv");
    std::fs::write(&path, "time,gaze\n0,1\n").unwrap();
    assert_bad_input(
        &run(
            &[
                "stream",
                "--input",
                path.to_str().unwrap(),
                "--format",
                "csv",
            ],
            None,
        ),
        "missing column 't_s'",
    );
    assert_bad_input(
        &run(&["stream", "--timeout-ms", "0"], Some("")),
        "timeout-ms",
    );
}

#[cfg(feature = "solver")]
#[test]
fn stream_with_the_optimizer_fast_path() {
    let input = std::fs::read_to_string(data("loss_200hz.jsonl")).unwrap();
    let cfg = format!(
        "{}/examples/configs/multi_level.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = run(&["stream", "--config", &cfg], Some(&input));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let f = frames(&stdout(&o));
    assert_eq!(f.len(), 40);
    assert!(f.iter().filter(|x| x.1 == "adaptive").count() >= 28);
}
