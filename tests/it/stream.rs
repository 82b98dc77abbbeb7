//! The gaze pipeline through the binary.

use crate::common;
use crate::independent;

use common::{assert_bad_input, run, stderr, stdout};
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
            let broken = independent::recheck(&p);
            assert!(broken.is_empty(), "frame outside its limits: {broken:?}");
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

// ---------------------------------------------------------------------------
// The frame clock drives the fail-safe.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const TIMEOUT_S: f64 = 0.1;
const PERIOD_S: f64 = 0.05;
/// Scheduling slack for wall-clock assertions on a loaded 2-core machine
/// (measured: the first fail-safe frame comes 0.103–0.150 s after the last
/// sample, by the phase of the frame grid; the bound is 0.150 s).
const SLACK_S: f64 = 0.075;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gaze-lidar"))
}

fn sample(t: f64, g: f64) -> String {
    format!("{{\"t_s\": {t}, \"gaze_deg\": {g}}}\n")
}

/// (t_s, state, gaze_deg) of one frame.
type FrameRow = (f64, String, Option<f64>);
/// Exit code, frames, stderr, seconds.
type Replay = (Option<i32>, Vec<FrameRow>, String, f64);

/// Replays `input` through `stream` (stdin), returns (exit code, frames as
/// (t_s, state, gaze), stderr, seconds).
fn replay(args: &[&str], input: String) -> Replay {
    let t = Instant::now();
    let mut child = bin()
        .arg("stream")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(input.as_bytes());
    });
    let o = child.wait_with_output().unwrap();
    writer.join().unwrap();
    let secs = t.elapsed().as_secs_f64();
    let frames = stdout(&o)
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            (
                v["t_s"].as_f64().unwrap(),
                v["state"].as_str().unwrap().to_owned(),
                v["gaze_deg"].as_f64(),
            )
        })
        .collect();
    (o.status.code(), frames, stderr(&o), secs)
}

#[test]
fn realtime_silence_emits_fail_safe_frames_until_stdin_closes() {
    let mut child = bin()
        .args(["stream", "--realtime", "--bins", "36"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = child.stdout.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(out).lines() {
            let Ok(line) = line else { break };
            let v: serde_json::Value = serde_json::from_str(&line).unwrap();
            let state = v["state"].as_str().unwrap().to_owned();
            if tx
                .send((Instant::now(), state, v["gaze_deg"].as_f64()))
                .is_err()
            {
                break;
            }
        }
    });
    let mut stdin = child.stdin.take().unwrap();
    // 0.1 s of valid gaze at 200 Hz, paced by the wall clock.
    let t0 = Instant::now();
    for k in 0..=20u32 {
        let due = t0 + Duration::from_millis(5 * u64::from(k));
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
        stdin
            .write_all(sample(f64::from(k) * 0.005, 90.0).as_bytes())
            .unwrap();
        stdin.flush().unwrap();
    }
    let last_sample = Instant::now();
    // Silence, with the pipe still open.
    std::thread::sleep(Duration::from_millis(1000));
    assert!(
        child.try_wait().unwrap().is_none(),
        "exited while stdin open"
    );
    let silence: Vec<_> = rx.try_iter().collect();
    drop(stdin);
    let closed = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        assert!(
            closed.elapsed() < Duration::from_secs(5),
            "no exit after EOF"
        );
        std::thread::sleep(Duration::from_millis(10));
    };
    let exit_after = closed.elapsed().as_secs_f64();
    reader.join().unwrap();
    assert_eq!(status.code(), Some(0));

    let since = |at: Instant| at.saturating_duration_since(last_sample).as_secs_f64();
    let adaptive: Vec<_> = silence.iter().filter(|f| f.1 == "adaptive").collect();
    assert!(
        !adaptive.is_empty(),
        "the 0.1 s of gaze adapted the profile"
    );
    for f in &adaptive {
        assert!(diff_deg(f.2.unwrap(), 90.0).abs() < 1.0);
        // Wall-clock property (slack for scheduling on a loaded machine).
        assert!(
            since(f.0) <= TIMEOUT_S + PERIOD_S + SLACK_S,
            "adaptive frame {:.3} s after the last sample",
            since(f.0)
        );
    }
    let last_adaptive = silence.iter().rposition(|f| f.1 == "adaptive").unwrap();
    let after = &silence[last_adaptive + 1..];
    assert!(after.iter().all(|f| f.1 == "fail_safe" && f.2.is_none()));
    let first = since(after[0].0);
    // Keeps emitting through the silence, one frame per period.
    let in_silence = after.iter().filter(|f| since(f.0) > 0.3).count();
    let max_gap = after
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).as_secs_f64())
        .fold(0.0, f64::max);
    eprintln!(
        "first fail-safe frame {first:.3} s after the last sample; {} fail-safe frames in 1 s of silence, largest gap {max_gap:.3} s; exit {exit_after:.3} s after EOF",
        after.len()
    );
    assert!(
        first <= TIMEOUT_S + PERIOD_S + SLACK_S,
        "first fail-safe after {first:.3} s"
    );
    assert!(in_silence >= 10, "{in_silence} frames in 0.7 s of silence");
    assert!(max_gap <= 2.0 * PERIOD_S + SLACK_S, "{max_gap}");
}

#[test]
fn a_saccadic_sweep_never_aims_far_from_the_true_gaze() {
    // 3 s at 60°/s from 90°: every sample is a saccade after the first.
    let truth = |t: f64| 90.0 + 60.0 * t;
    let input: String = (0..600)
        .map(|k| {
            let t = f64::from(k) * 0.005;
            sample(t, truth(t))
        })
        .collect();
    let (code, frames, err, _) = replay(&["--bins", "36"], input);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(frames.len(), 60);
    let mut worst: f64 = 0.0;
    for (t, state, gaze) in &frames {
        if state == "adaptive" {
            // Against the true gaze anywhere during the frame.
            for tt in [*t, t + PERIOD_S] {
                worst = worst.max(diff_deg(gaze.unwrap(), truth(tt)).abs());
            }
        }
    }
    eprintln!("worst adaptive aim error during the sweep: {worst:.2}°");
    assert!(worst <= 30.0, "{worst}");
    // Held fixation at most timeout + one frame old: 60°/s · 0.15 s = 9°.
    assert!(worst <= 9.0 + 1e-6, "{worst}");
    assert!(frames.iter().filter(|f| f.1 == "fail_safe").count() >= 57);
}

#[test]
fn a_gap_in_replay_produces_its_frames_in_order() {
    let mut input: String = (0..=20)
        .map(|k| sample(f64::from(k) * 0.005, 90.0))
        .collect();
    input.push_str(&sample(2.1, 90.0));
    let (code, frames, err, _) = replay(&["--bins", "36"], input);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(frames.len(), 43);
    for w in frames.windows(2) {
        assert!((w[1].0 - w[0].0 - PERIOD_S).abs() < 1e-6);
    }
    // Sample-clock property: last fixation at 0.1 s.
    for (t, state, _) in &frames {
        if state == "adaptive" {
            assert!(t + PERIOD_S - 0.1 <= TIMEOUT_S + PERIOD_S + 1e-9, "t = {t}");
        }
    }
    assert!(frames.iter().any(|f| f.1 == "adaptive"));
    assert!(!err.contains("jumped"), "{err}");
}

#[test]
fn timestamp_jumps_are_bounded_in_time_and_output() {
    for jump in [2000.0, 1e9, 1e300] {
        let mut input: String = (0..=20)
            .map(|k| sample(f64::from(k) * 0.005, 90.0))
            .collect();
        for k in 0..=20 {
            input.push_str(&sample(jump + f64::from(k) * 0.005, 90.0));
        }
        let (code, frames, err, secs) = replay(&["--bins", "360"], input);
        eprintln!("jump to {jump:e} s: {} frames, {secs:.3} s", frames.len());
        assert_eq!(code, Some(0), "{err}");
        assert!(secs < 5.0, "{secs} s");
        assert!(frames.len() <= 10, "{} frames", frames.len());
        assert!(err.contains("warning: gaze clock jumped"), "{err}");
        // The frame at the jump is fail-safe; frames stay in order.
        let at_jump = frames.iter().position(|f| f.0 >= jump).unwrap();
        assert_eq!(frames[at_jump].1, "fail_safe");
        assert!(frames[at_jump - 1].0 < frames[at_jump].0);
    }
}

#[test]
fn absurd_gaze_is_an_invalid_sample() {
    let input: String = (0..=40)
        .map(|k| sample(f64::from(k) * 0.005, 1e300))
        .collect();
    let (code, frames, err, _) = replay(&["--bins", "36"], input);
    assert_eq!(code, Some(0), "{err}");
    assert!(frames.iter().all(|f| f.1 == "fail_safe" && f.2.is_none()));
    assert!(err.contains("41 invalid"), "{err}");
}

#[test]
fn a_truncated_neon_file_is_rejected_with_line_and_field() {
    let full = std::fs::read_to_string(data("neon_gaze.csv")).unwrap();
    let cut = &full[..full.len() - 20];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gaze.csv");
    std::fs::write(&path, cut).unwrap();
    let lines = cut.lines().count();
    let o = run(
        &[
            "stream",
            "--input",
            path.to_str().unwrap(),
            "--format",
            "neon",
        ],
        None,
    );
    assert_bad_input(&o, &format!("gaze.csv:{lines}: row:"));
    assert!(stderr(&o).contains("missing"), "{}", stderr(&o));
}

#[test]
fn closing_stdout_early_is_quiet() {
    use std::os::unix::process::ExitStatusExt;
    let input = data("loss_200hz.jsonl");
    for _ in 0..100 {
        let mut child = bin()
            .args(["stream"])
            .stdin(std::fs::File::open(&input).unwrap())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut first = String::new();
        out.read_line(&mut first).unwrap();
        assert!(first.starts_with('{'));
        drop(out); // `| head -1`
        let o = child.wait_with_output().unwrap();
        let err = stderr(&o);
        let ok = o.status.code() == Some(0) || o.status.signal() == Some(13);
        assert!(ok, "{:?}: {err}", o.status);
        assert!(!err.contains("panicked") && !err.contains("error"), "{err}");
    }
}

#[test]
fn other_stdout_errors_are_one_line_exit_1() {
    let input = std::fs::read_to_string(data("loss_200hz.jsonl")).unwrap();
    let mut child = bin()
        .args(["stream"])
        .stdin(Stdio::piped())
        .stdout(
            std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap(),
        )
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let w = std::thread::spawn(move || {
        let _ = stdin.write_all(input.as_bytes());
    });
    let o = child.wait_with_output().unwrap();
    w.join().unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("stdout"), "{err}");
}

#[cfg(feature = "solver")]
#[test]
fn an_invalid_config_exits_2_under_profile_and_stream_alike() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, "bins = 3\n[lidar]\npreset = \"paper\"\n").unwrap();
    let p = path.to_str().unwrap();
    let prof = run(&["profile", "--config", p, "--gaze-deg", "90"], None);
    let strm = run(&["stream", "--config", p], Some(""));
    assert_eq!(prof.status.code(), Some(2), "{}", stderr(&prof));
    assert_eq!(strm.status.code(), Some(2), "{}", stderr(&strm));
}
