//! Regressions of the command line: each test guards a fixed bug and cites it.
//!
//! The binary under hostile input and conditions: one test per kind of
//! failure (bad bytes and huge lines on stdin, stale gaze, pacing, option
//! ranges, contradictory files, outputs that would replace inputs, plots,
//! exit codes, message wording, byte-order marks, beam widths); the ARGUS
//! road mask's memory is tested with the simulator (`tests/it/simulate/pipeline.rs`).
//! Each test failed before its fix; the comment on each says how.

use crate::common;

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{expect, no_panic, run, run_bytes, stderr, stdout};

const BIN: &str = env!("CARGO_BIN_EXE_gaze-lidar");
const PERIOD_S: f64 = 0.05;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn sample(t: f64, g: f64) -> String {
    format!("{{\"t_s\": {t}, \"gaze_deg\": {g}}}\n")
}

/// Samples at 200 Hz from `k0 * 5 ms` to `k1 * 5 ms` (inclusive), gaze 90°.
fn samples(k0: u32, k1: u32) -> String {
    (k0..=k1)
        .map(|k| sample(f64::from(k) * 0.005, 90.0))
        .collect()
}

/// (t_s, state) of every frame on stdout.
fn frames(out: &[u8]) -> Vec<(f64, String)> {
    String::from_utf8_lossy(out)
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            (
                v["t_s"].as_f64().unwrap(),
                v["state"].as_str().unwrap().to_owned(),
            )
        })
        .collect()
}

struct Dir(tempfile::TempDir);

impl Dir {
    fn new() -> Self {
        Self(tempfile::tempdir().unwrap())
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }
    fn file(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, contents).unwrap();
        p
    }
}

// ---------------------------------------------------------------------------
// `stream`

/// A malformed live line in the middle of valid samples: skipped with its
/// number, the samples after it still make their frames, exit 0.
fn skips_line(bad: &[u8], bad_line: usize, needle: &str) {
    let mut input = samples(0, 29).into_bytes();
    input.extend_from_slice(bad);
    input.extend_from_slice(samples(30, 59).as_bytes());
    let o = run_bytes(&["stream", "--bins", "36"], Some(&input));
    no_panic(&o, needle);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains(&format!("<stdin>:{bad_line}: skipped: {needle}")),
        "{err}"
    );
    let f = frames(&o.stdout);
    // 60 samples over 0.295 s: frames at 0, 0.05, …, 0.25 — the ones after
    // the bad line (at 0.15 s) included.
    assert_eq!(f.len(), 6, "{f:?}");
    assert!(err.contains("60 samples"), "{err}");
}

/// Regression: before the fix, `<stdin>:31: stream did not contain valid UTF-8`, exit 2.
#[test]
fn a_non_utf8_line_on_stdin_is_skipped() {
    skips_line(b"\xff\xfe\x00garbage\n", 31, "not UTF-8");
    // Invalid UTF-8 inside an otherwise valid-looking sample, too.
    skips_line(
        b"{\"t_s\": 0.1, \"gaze_deg\": \"\xc3\x28\"}\n",
        31,
        "not UTF-8",
    );
}

/// Regression: before the fix, "line longer than 65536 bytes", exit 2.
#[test]
fn a_10_mib_line_on_stdin_is_skipped() {
    let mut bad = vec![b'x'; 10 << 20];
    bad.push(b'\n');
    skips_line(&bad, 31, "line longer than 65536 bytes");
    // Without a final newline, at the very end: skipped too.
    let mut input = samples(0, 29).into_bytes();
    input.extend(std::iter::repeat_n(b'{', 1 << 20));
    let o = run_bytes(&["stream", "--bins", "36"], Some(&input));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("<stdin>:31: skipped"), "{}", stderr(&o));
}

/// Regression: before the fix, after the silence, frames 2.05 and 2.1 are adaptive
/// (the run of 61 valid samples before the loss still counted).
#[test]
fn staleness_resets_the_recovery_run_in_replay() {
    let mut input = samples(0, 60); // 0 … 0.3 s
    input.push_str(&sample(2.0, 90.0));
    input.push_str(&sample(2.2, 90.0));
    let o = run(&["stream", "--bins", "36"], Some(&input));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let f = frames(&o.stdout);
    let at = |t: f64| {
        f.iter()
            .find(|x| (x.0 - t).abs() < 1e-6)
            .unwrap_or_else(|| panic!("no frame at {t}: {f:?}"))
            .1
            .clone()
    };
    assert_eq!(at(0.25), "adaptive", "before the loss");
    for t in [2.05, 2.1, 2.15, 2.2] {
        assert_eq!(at(t), "fail_safe", "t = {t}: one sample after a loss");
    }
    // With the default recover_samples 4, four samples do recover.
    let mut input = samples(0, 60);
    for k in 0..4 {
        input.push_str(&sample(2.0 + f64::from(k) * 0.005, 90.0));
    }
    input.push_str(&sample(2.1, 90.0));
    let o = run(&["stream", "--bins", "36"], Some(&input));
    let f = frames(&o.stdout);
    assert_eq!(f.last().unwrap().1, "adaptive", "{f:?}");
}

/// Spawns `stream --realtime` with piped stdin/stdout/stderr and a thread
/// collecting (arrival, state) per frame line.
fn live_child(
    args: &[&str],
) -> (
    Child,
    std::sync::mpsc::Receiver<(Instant, String)>,
    std::thread::JoinHandle<()>,
) {
    let mut child = Command::new(BIN)
        .args(["stream", "--realtime"])
        .args(args)
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
            if tx.send((Instant::now(), state)).is_err() {
                break;
            }
        }
    });
    (child, rx, reader)
}

/// Writes 200 Hz samples `k0..=k1` paced by the wall clock from `t0`.
fn feed_paced(stdin: &mut impl Write, t0: Instant, k0: u32, k1: u32, offset_s: f64) {
    for k in k0..=k1 {
        let due = t0 + Duration::from_millis(5 * u64::from(k - k0));
        std::thread::sleep(due.saturating_duration_since(Instant::now()));
        stdin
            .write_all(sample(offset_s + f64::from(k) * 0.005, 90.0).as_bytes())
            .unwrap();
        stdin.flush().unwrap();
    }
}

fn wait_exit(child: &mut Child, within: Duration) -> std::process::ExitStatus {
    let closed = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        assert!(closed.elapsed() < within, "no exit after EOF");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Regression (live): before the fix, after a 0.8 s pause one sample made the next
/// frames adaptive.
#[test]
fn staleness_resets_the_recovery_run_live() {
    let (mut child, rx, reader) = live_child(&["--bins", "36"]);
    let mut stdin = child.stdin.take().unwrap();
    feed_paced(&mut stdin, Instant::now(), 0, 20, 0.0);
    std::thread::sleep(Duration::from_millis(800));
    let before: Vec<_> = rx.try_iter().collect();
    // One sample, timestamped as if the tracker kept its clock.
    stdin.write_all(sample(0.9, 90.0).as_bytes()).unwrap();
    stdin.flush().unwrap();
    let one = Instant::now();
    std::thread::sleep(Duration::from_millis(400));
    drop(stdin);
    let status = wait_exit(&mut child, Duration::from_secs(5));
    reader.join().unwrap();
    assert_eq!(status.code(), Some(0));
    assert!(
        before.iter().any(|f| f.1 == "adaptive"),
        "the first 0.1 s of gaze adapted the profile"
    );
    let after: Vec<_> = rx.try_iter().filter(|f| f.0 > one).collect();
    assert!(after.len() >= 5, "{} frames after the sample", after.len());
    assert!(
        after.iter().all(|f| f.1 == "fail_safe"),
        "one sample after a loss flapped the profile: {:?}",
        after.iter().map(|f| &f.1).collect::<Vec<_>>()
    );
}

/// Regression: before the fix, `--max-gap-frames 0 --realtime --input` finished a 1 s
/// recording in 24 ms with one frame.
#[test]
fn max_gap_frames_0_keeps_realtime_pacing() {
    let d = Dir::new();
    let rec = d.file("rec.jsonl", samples(0, 200)); // 0 … 1.0 s
    for gap in ["0", "200"] {
        let t = Instant::now();
        let o = run(
            &[
                "stream",
                "--realtime",
                "--bins",
                "36",
                "--max-gap-frames",
                gap,
                "--input",
                s(&rec),
            ],
            None,
        );
        let secs = t.elapsed().as_secs_f64();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let n = frames(&o.stdout).len();
        eprintln!("--max-gap-frames {gap}: {n} frames in {secs:.3} s");
        assert!(
            secs >= 0.9,
            "--max-gap-frames {gap}: {secs} s for a 1 s recording"
        );
        assert!(n >= 15, "--max-gap-frames {gap}: {n} frames");
    }
}

/// Every numeric option of every subcommand, given a negative number (and
/// floats `-inf`): exit 2, one line naming the option — main: "unexpected
/// argument '-1' found" for `stream --recover-samples`, `--max-gap-frames`,
/// `--bins`, and "unexpected argument '-i' found" for `--timeout-ms -inf`.
#[test]
fn negative_numbers_reach_the_range_check_and_name_the_option() {
    let gaze = ["profile", "--gaze-deg", "90"];
    let fw = ["profile", "--gaze-deg", "90", "--format", "firmware"];
    let ael = [
        "ael",
        "--wavelength-nm",
        "905",
        "--pulse-duration-s",
        "5e-9",
    ];
    let sim = ["simulate", "--trials", "1"];
    // (base command, option, whether it is a float)
    let cases: &[(&[&str], &str, bool)] = &[
        (&["profile"], "--gaze-deg", true),
        (&gaze, "--bins", false),
        (&fw, "--tick-hz", false),
        (&fw, "--power-w-per-code", true),
        (
            &["ael", "--pulse-duration-s", "5e-9"],
            "--wavelength-nm",
            true,
        ),
        (
            &["ael", "--wavelength-nm", "905"],
            "--pulse-duration-s",
            true,
        ),
        (&ael, "--pulse-rate-hz", true),
        (&ael, "--beam-diameter-mm", true),
        (&["simulate"], "--trials", false),
        (&sim, "--seed", false),
        (&sim, "--fog", false),
        (&sim, "--paper-pipeline-trials", false),
        (&["stream"], "--bins", false),
        (&["stream"], "--timeout-ms", true),
        (&["stream"], "--recover-samples", false),
        (&["stream"], "--saccade-deg-s", true),
        (&["stream"], "--max-gap-frames", false),
    ];
    for (base, opt, float) in cases {
        let mut values = vec!["-1", "-1e300"];
        if *float {
            values.extend(["-inf", "-nan"]);
        }
        for v in values {
            let mut args = base.to_vec();
            args.extend([*opt, v]);
            let o = run(&args, Some(""));
            let what = format!("{args:?}");
            if *opt == "--gaze-deg" && v == "-1" {
                // A valid azimuth.
                assert_eq!(o.status.code(), Some(0), "{what}: {}", stderr(&o));
                continue;
            }
            expect(&o, 2, &[opt], &what);
            assert!(
                !stderr(&o).contains("unexpected argument"),
                "{what}: {}",
                stderr(&o)
            );
        }
    }
    // 0 where it makes no sense is refused, naming the option.
    for (args, opt) in [
        (
            &["stream", "--recover-samples", "0"][..],
            "--recover-samples",
        ),
        (&["stream", "--timeout-ms", "0"], "--timeout-ms"),
        (&["stream", "--saccade-deg-s", "0"], "--saccade-deg-s"),
        (&["stream", "--bins", "0"], "--bins"),
        (&["simulate", "--trials", "0"], "--trials"),
        (&[&fw[..], &["--tick-hz", "0"]].concat(), "--tick-hz"),
        (
            &[&ael[..], &["--pulse-rate-hz", "0"]].concat(),
            "--pulse-rate-hz",
        ),
    ] {
        expect(&run(args, Some("")), 2, &[opt], &format!("{args:?}"));
    }
}

/// Regression: before the fix, `stream --config` whose limits have power_w_min >
/// power_w_max exited 1 (as infeasible).
#[cfg(feature = "solver")]
#[test]
fn contradictory_limits_in_a_config_are_bad_input() {
    let d = Dir::new();
    let c = d.file(
        "c.toml",
        "[limits]\npower_w_min = 0.005\npower_w_max = 0.002\n",
    );
    let spin = d.file(
        "spin.toml",
        "[limits]\nspin_rad_s_min = 300.0\nspin_rad_s_max = 200.0\n",
    );
    for (cfg, key) in [(&c, "limits.power_w_min"), (&spin, "limits.spin_rad_s_min")] {
        let o = run(&["stream", "--config", s(cfg)], Some(""));
        expect(&o, 2, &[key], "stream");
        let o = run(&["profile", "--config", s(cfg), "--gaze-deg", "90"], None);
        expect(&o, 2, &[key], "profile");
        let o = run(
            &[
                "simulate",
                "--trials",
                "1",
                "--variant",
                "optimized",
                "--optimizer-config",
                s(cfg),
            ],
            None,
        );
        expect(&o, 2, &[key], "simulate");
    }
}

/// Regression: before the fix, live, a tracker clock running backwards was reported as
/// "one fail-safe frame, frame clock restarted at 0 s" (the replay message;
/// neither happens live).
#[test]
fn the_live_clock_restart_message_says_what_happens_live() {
    let (mut child, rx, reader) = live_child(&["--bins", "36"]);
    let mut stdin = child.stdin.take().unwrap();
    feed_paced(&mut stdin, Instant::now(), 0, 20, 100.0);
    // The tracker's clock restarts at 0.
    stdin.write_all(sample(0.0, 90.0).as_bytes()).unwrap();
    stdin.flush().unwrap();
    std::thread::sleep(Duration::from_millis(200));
    drop(stdin);
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    let status = wait_exit(&mut child, Duration::from_secs(5));
    reader.join().unwrap();
    let frames: Vec<_> = rx.try_iter().collect();
    assert_eq!(status.code(), Some(0), "{err}");
    let warning = err
        .lines()
        .find(|l| l.contains("warning: gaze clock"))
        .unwrap_or_else(|| panic!("no clock warning: {err}"));
    assert!(warning.contains("ran backwards"), "{warning}");
    assert!(warning.contains("history discarded"), "{warning}");
    assert!(!warning.contains("frame clock restarted"), "{warning}");
    assert!(!warning.contains("one fail-safe frame"), "{warning}");
    // The frames kept their wall-clock spacing through it.
    let gaps: Vec<f64> = frames
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).as_secs_f64())
        .collect();
    assert!(gaps.iter().all(|g| *g < 2.0 * PERIOD_S + 0.075), "{gaps:?}");
}

// ---------------------------------------------------------------------------
// Flags with `--config`

/// Regression: before the fix, `profile --config c.toml --accounting time` gave
/// `power_accounting: "angle"`; `--bins` and `--preset` were ignored too.
/// A flag now replaces the file's value: the output equals that of the file
/// edited to say the same.
#[cfg(feature = "solver")]
#[test]
fn profile_flags_given_with_config_replace_the_file_values() {
    let d = Dir::new();
    let base = "bins = 72\n[lidar]\npreset = \"paper\"\n";
    let c = d.file("c.toml", base);
    let profile = |cfg: &Path, extra: &[&str]| {
        let mut args = vec!["profile", "--config", s(cfg), "--gaze-deg", "90"];
        args.extend_from_slice(extra);
        let o = run(&args, None);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        o.stdout
    };
    let cases: &[(&[&str], &str)] = &[
        (
            &["--accounting", "time"],
            "bins = 72\n[lidar]\npreset = \"paper\"\npower_accounting = \"time\"\n",
        ),
        (
            &["--bins", "36"],
            "bins = 36\n[lidar]\npreset = \"paper\"\n",
        ),
        (
            &["--preset", "vls128"],
            "bins = 72\n[lidar]\npreset = \"vls128\"\n",
        ),
    ];
    let plain = profile(&c, &[]);
    for (i, (flags, edited)) in cases.iter().enumerate() {
        let e = d.file(&format!("edited{i}.toml"), edited);
        let with_flag = profile(&c, flags);
        assert_ne!(with_flag, plain, "{flags:?} changed nothing");
        assert_eq!(with_flag, profile(&e, &[]), "{flags:?}");
    }
    let v: serde_json::Value =
        serde_json::from_slice(&profile(&c, &["--accounting", "time"])).unwrap();
    assert_eq!(v["power_accounting"], "time");
    // And a bad flag value is named as the flag.
    let o = run(
        &[
            "profile",
            "--config",
            s(&c),
            "--gaze-deg",
            "90",
            "--bins",
            "3",
        ],
        None,
    );
    expect(&o, 2, &["--bins"], "--bins 3");
}

/// Regression: before the fix, `stream --config c.toml --preset nope --bins 3` exited 0.
#[cfg(feature = "solver")]
#[test]
fn stream_flags_given_with_config_are_checked_and_honoured() {
    let d = Dir::new();
    let c = d.file("c.toml", "bins = 72\n");
    let input = samples(0, 40);
    let stream = |extra: &[&str]| {
        let mut args = vec!["stream", "--config", s(&c)];
        args.extend_from_slice(extra);
        run(&args, Some(&input))
    };
    expect(
        &stream(&["--preset", "nope", "--bins", "3"]),
        2,
        &["--preset"],
        "preset",
    );
    expect(&stream(&["--bins", "3"]), 2, &["--bins"], "bins");
    // Honoured: --bins 36 gives the frames of a file saying bins = 36.
    let o = stream(&["--bins", "36"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let c36 = d.file("c36.toml", "bins = 36\n");
    let want = run(&["stream", "--config", s(&c36)], Some(&input));
    assert_eq!(o.stdout, want.stdout);
    assert_ne!(o.stdout, stream(&[]).stdout);
}

// ---------------------------------------------------------------------------
// Outputs

/// Regression: before the fix, `profile --config c.toml --out c.toml` replaced the
/// config; `simulate --scenario s.toml --export-json s.toml` the scenario.
/// Refused now, through symbolic and hard links too, nothing changed.
#[test]
fn an_output_never_replaces_an_input() {
    let d = Dir::new();
    let scenario = d.file("s.toml", "speed_kmh = 50.0\n");
    let link = d.path("s-link.json");
    std::os::unix::fs::symlink(&scenario, &link).unwrap();
    let hard = d.path("s-hard.json");
    std::fs::hard_link(&scenario, &hard).unwrap();
    let sim = |flag: &str, out: &Path| {
        run(
            &common::tiny_sim(&["--scenario", s(&scenario), flag, s(out)]),
            None,
        )
    };
    for flag in ["--export-json", "--export-csv", "--trials-csv", "--report"] {
        for out in [&scenario, &link, &hard] {
            let o = sim(flag, out);
            expect(
                &o,
                2,
                &[flag, "--scenario", "input"],
                &format!("{flag} {out:?}"),
            );
            assert!(o.stdout.is_empty(), "the run started");
            assert_eq!(
                std::fs::read_to_string(&scenario).unwrap(),
                "speed_kmh = 50.0\n"
            );
        }
    }
    #[cfg(feature = "solver")]
    {
        let c = d.file("c.toml", "bins = 72\n");
        let o = run(
            &[
                "profile",
                "--config",
                s(&c),
                "--gaze-deg",
                "90",
                "--out",
                s(&c),
            ],
            None,
        );
        expect(
            &o,
            2,
            &["--out", "--config", "input"],
            "profile --out config",
        );
        assert_eq!(std::fs::read_to_string(&c).unwrap(), "bins = 72\n");
        let o = run(
            &[
                "simulate",
                "--trials",
                "1",
                "--variant",
                "optimized",
                "--optimizer-config",
                s(&c),
                "--report",
                s(&d.path("./c.toml")),
            ],
            None,
        );
        expect(
            &o,
            2,
            &["--report", "--optimizer-config"],
            "report over config",
        );
        assert_eq!(std::fs::read_to_string(&c).unwrap(), "bins = 72\n");
    }
    let stray: Vec<_> = std::fs::read_dir(d.0.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".gaze-lidar"))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
}

fn run_sim(extra: &[&str]) -> std::process::Output {
    run(&common::tiny_sim(extra), None)
}

/// Regression: before the fix, with `pl/density_argus.svg` a folder, the run exited 1
/// only after `rows.json` and `pl/tta_argus.svg/.png` were replaced.
/// Now every plot file is checked before the run: nothing is replaced.
#[test]
fn plots_are_all_or_nothing_with_the_other_outputs() {
    let d = Dir::new();
    let pl = d.path("pl");
    std::fs::create_dir(&pl).unwrap();
    std::fs::create_dir(pl.join("density_argus.svg")).unwrap();
    std::fs::write(pl.join("tta_argus.svg"), "old svg").unwrap();
    std::fs::write(pl.join("tta_argus.png"), "old png").unwrap();
    let rows = d.file("rows.json", "precious");
    let o = run_sim(&["--plots", s(&pl), "--export-json", s(&rows)]);
    expect(
        &o,
        2,
        &["density_argus.svg", "directory"],
        "plot over a folder",
    );
    assert!(o.stdout.is_empty(), "the run started");
    assert_eq!(std::fs::read_to_string(&rows).unwrap(), "precious");
    assert_eq!(
        std::fs::read_to_string(pl.join("tta_argus.svg")).unwrap(),
        "old svg"
    );
    assert_eq!(
        std::fs::read_to_string(pl.join("tta_argus.png")).unwrap(),
        "old png"
    );
    // With the folder out of the way every output is written, the plots
    // exactly the files the command announced.
    std::fs::remove_dir(pl.join("density_argus.svg")).unwrap();
    let fresh = d.path("new/deeper/pl");
    for dir in [&pl, &fresh] {
        let o = run_sim(&["--plots", s(dir), "--export-json", s(&rows)]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert!(std::fs::read_to_string(&rows).unwrap().contains("rows"));
        let mut written: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        written.sort();
        let mut announced: Vec<String> = stderr(&o)
            .lines()
            .filter_map(|l| l.strip_prefix("gaze-lidar: wrote "))
            .map(|p| {
                Path::new(p)
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect();
        announced.sort();
        assert_eq!(written, announced);
        assert_eq!(written.len(), 6, "{written:?}");
        assert_ne!(
            std::fs::read(dir.join("tta_argus.svg")).unwrap(),
            b"old svg"
        );
    }
    // A plots folder that cannot be created: nothing is created or replaced.
    let blocked = d.file("blocked", "a file");
    let o = run_sim(&["--plots", s(&blocked.join("pl")), "--export-json", s(&rows)]);
    expect(&o, 2, &["--plots", "not a directory"], "plots under a file");
}

/// Regression: before the fix, `--plots pl --export-json pl/tta_argus.svg` exited 0 and
/// the JSON export was silently overwritten by the plot.
#[test]
fn an_output_named_like_a_plot_is_refused() {
    let d = Dir::new();
    for existing in [true, false] {
        let pl = d.path(if existing { "pl" } else { "fresh" });
        if existing {
            std::fs::create_dir(&pl).unwrap();
        }
        for name in ["tta_argus.svg", "profiles_polar.png"] {
            let clash = pl.join(name);
            let o = run_sim(&["--plots", s(&pl), "--export-json", s(&clash)]);
            expect(&o, 2, &["two outputs", name], &format!("{clash:?}"));
            assert!(o.stdout.is_empty());
            // Spelled differently, the same file.
            let other = d.path(&format!(
                "{}/../{}/{name}",
                pl.display(),
                pl.file_name().unwrap().to_string_lossy()
            ));
            let o = run_sim(&["--plots", s(&pl), "--export-csv", s(&other)]);
            expect(&o, 2, &["two outputs"], &format!("{other:?}"));
        }
        assert!(!existing || std::fs::read_dir(&pl).unwrap().next().is_none());
        assert!(existing || !pl.exists(), "the folder was created");
    }
    // Two exports through a symbolic link to the same file.
    let a = d.file("a.json", "keep");
    let b = d.path("b.json");
    std::os::unix::fs::symlink(&a, &b).unwrap();
    let o = run_sim(&["--export-json", s(&a), "--export-csv", s(&b)]);
    expect(&o, 2, &["two outputs"], "link");
    assert_eq!(std::fs::read_to_string(&a).unwrap(), "keep");
}

/// Regression: before the fix, the exit code of a failed write (full disk: 1) was
/// documented nowhere a user looks. The README's CLI reference and
/// `gaze-lidar --help` both state every exit code.
#[test]
fn exit_codes_are_documented_where_a_user_looks() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let help = stdout(&run(&["--help"], None));
    let docs: [(&str, &str, [&str; 3]); 2] = [
        ("README", readme.as_str(), ["| `0` |", "| `1` |", "| `2` |"]),
        ("--help", help.as_str(), ["\n  0  ", "\n  1  ", "\n  2  "]),
    ];
    for (name, text, codes) in docs {
        let at = text
            .find("Exit codes")
            .unwrap_or_else(|| panic!("{name}: no exit codes"));
        let section: String = text[at..].chars().take(1200).collect();
        for needle in codes.iter().copied().chain(["write", "full disk", "input"]) {
            assert!(section.contains(needle), "{name}: '{needle}' in: {section}");
        }
    }
    // And the code is what they say: a full disk (stdout on /dev/full) is 1.
    if Path::new("/dev/full").exists() {
        let f = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(BIN)
            .args(["profile", "--gaze-deg", "90"])
            .stdout(f)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        expect(&o, 1, &["stdout"], "> /dev/full");
    }
}

// ---------------------------------------------------------------------------
// Messages

/// No run of more than 17 digits (a full-precision f64 mantissa) in any
/// message: huge and tiny numbers are printed in scientific form. (Data on
/// stdout — JSON — is serde_json's shortest form and not a message.)
fn compact(o: &std::process::Output, what: &str) {
    // Messages: stderr, and `check`'s violation lines on stdout.
    let violations: String = stdout(o)
        .lines()
        .filter(|l| l.starts_with("violation:"))
        .collect();
    let err = format!("{}{violations}", stderr(o));
    let longest = err
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest <= 17, "{what}: a {longest}-digit number in: {err}");
}

/// Regression: before the fix, `ael --pulse-duration-s 1e300` and a sensor limit of
/// 1e300 ("looser than the sensor's 1000…0") printed 301 digits.
#[test]
fn numbers_in_messages_are_compact() {
    let d = Dir::new();
    let ael = ["ael", "--wavelength-nm", "905", "--pulse-duration-s"];
    let mut cases: Vec<Vec<String>> = Vec::new();
    let v = |a: &[&str]| a.iter().map(|x| (*x).to_owned()).collect::<Vec<_>>();
    for huge in ["1e300", "-1e300", "1e-300"] {
        cases.push(v(&[&ael[..], &[huge]].concat()));
        cases.push(v(&[
            "ael",
            "--wavelength-nm",
            huge,
            "--pulse-duration-s",
            "5e-9",
        ]));
        cases.push(v(&[&ael[..], &["5e-9", "--pulse-rate-hz", huge]].concat()));
        cases.push(v(
            &[&ael[..], &["5e-9", "--beam-diameter-mm", huge]].concat()
        ));
        cases.push(v(&["profile", "--gaze-deg", huge]));
        cases.push(v(&["stream", "--timeout-ms", huge]));
        cases.push(v(&["stream", "--saccade-deg-s", huge]));
        let scen = d.file(&format!("s{huge}.toml"), format!("speed_kmh = {huge}\n"));
        cases.push(v(&["simulate", "--trials", "1", "--scenario", s(&scen)]));
        let cfg = d.file(
            &format!("c{huge}.toml"),
            format!("[lidar]\naverage_power_w = {huge}\n"),
        );
        cases.push(v(&["profile", "--gaze-deg", "90", "--config", s(&cfg)]));
        let cfg = d.file(
            &format!("l{huge}.toml"),
            format!("[limits]\nspin_accel_rad_s2_max = {huge}\npower_w_max = {huge}\n"),
        );
        cases.push(v(&["profile", "--gaze-deg", "90", "--config", s(&cfg)]));
    }
    // A profile whose numbers are huge: the checker's violations.
    let good = run(&["profile", "--gaze-deg", "90", "--bins", "36"], None);
    let mut p: serde_json::Value = serde_json::from_slice(&good.stdout).unwrap();
    p["bins"][0]["power_w"] = serde_json::json!(1e300);
    p["limits"]["power_w_max"] = serde_json::json!(1e300);
    let prof = d.file("huge.json", p.to_string());
    cases.push(v(&["check", s(&prof)]));
    // A sensor file whose limit is tiny: "looser than the sensor's …" (a
    // valid sensor file: its lower power limit 1e-300 W, above the
    // profile's 0).
    let mut lidar = gaze_lidar::model::presets::paper().lidar;
    lidar.limits.power_w_min = 1e-300;
    // (TOML has no null: every limit given.)
    lidar.limits.spin_accel_rad_s2_max = Some(1e300);
    lidar.limits.power_slew_w_per_deg_max = Some(1e-300);
    let sensor = d.file("sensor.toml", toml::to_string(&lidar).unwrap());
    let good_file = d.file("good.json", &good.stdout);
    cases.push(v(&["check", s(&good_file), "--sensor", s(&sensor)]));
    for args in &cases {
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = run(&refs, Some(""));
        no_panic(&o, &format!("{refs:?}"));
        compact(&o, &format!("{refs:?}"));
    }
    // The 1e300 cases were refused with the value spelled 1e300.
    let o = run(&[&ael[..], &["1e300"]].concat(), None);
    expect(&o, 2, &["--pulse-duration-s", "1e300"], "ael 1e300");
    let o = run(&["check", s(&good_file), "--sensor", s(&sensor)], None);
    assert!(
        stdout(&o).contains("looser than the sensor's 1e-300"),
        "{}{}",
        stderr(&o),
        stdout(&o)
    );
}

/// Regression: before the fix, toml's ASCII-art snippet (`  |`, `^^^`) was flattened
/// into the one-line error of a bad `--sensor` file.
#[test]
fn toml_errors_are_line_column_and_message() {
    let d = Dir::new();
    let good = d.file(
        "good.json",
        run(&["profile", "--gaze-deg", "90", "--bins", "36"], None).stdout,
    );
    let cases: &[(&str, &str, &[&str])] = &[
        ("syntax.toml", "name = = 3\n", &["syntax.toml", "1:8:"]),
        (
            "type.toml",
            "name = \"x\"\n[limits]\npower_w_max = \"high\"\n",
            &["type.toml", "3:15:", "power_w_max"],
        ),
    ];
    for (name, text, needles) in cases {
        let p = d.file(name, text);
        let mut runs = vec![
            run(&["check", s(&good), "--sensor", s(&p)], None),
            run_sim(&["--scenario", s(&p)]),
        ];
        if cfg!(feature = "solver") {
            runs.push(run(
                &["profile", "--gaze-deg", "90", "--config", s(&p)],
                None,
            ));
        }
        for o in runs {
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{err}");
            assert!(
                !err.contains(" | ") && !err.contains('^'),
                "snippet in: {err}"
            );
            assert!(!err.contains("TOML parse error at"), "{err}");
            assert!(err.contains(needles[0]), "{err}");
            if name.starts_with("syntax") {
                assert!(err.contains(needles[1]), "{err}");
            }
        }
        // The sensor file names position and key.
        let o = run(&["check", s(&good), "--sensor", s(&p)], None);
        expect(&o, 2, needles, name);
    }
}

/// Regression: before the fix, a profile starting with a UTF-8 BOM got "1:1: expected
/// value" without naming the BOM. Every text input names it.
#[test]
fn a_byte_order_mark_is_named() {
    let d = Dir::new();
    let good = run(&["profile", "--gaze-deg", "90", "--bins", "36"], None).stdout;
    let mut bom = b"\xEF\xBB\xBF".to_vec();
    bom.extend_from_slice(&good);
    let p = d.file("bom.json", &bom);
    expect(
        &run(&["check", s(&p)], None),
        2,
        &["bom.json", "byte-order mark"],
        "file",
    );
    let o = run_bytes(&["check", "-"], Some(&bom));
    expect(&o, 2, &["<stdin>", "byte-order mark"], "stdin");
    let scen = d.file("bom.toml", b"\xEF\xBB\xBFspeed_kmh = 50.0\n");
    expect(
        &run_sim(&["--scenario", s(&scen)]),
        2,
        &["bom.toml", "byte-order mark"],
        "scenario",
    );
    #[cfg(feature = "solver")]
    expect(
        &run(&["profile", "--gaze-deg", "90", "--config", s(&scen)], None),
        2,
        &["bom.toml", "byte-order mark"],
        "config",
    );
    // A gaze file: named at line 1 (an error in a file, skipped on stdin).
    let mut g = b"\xEF\xBB\xBF".to_vec();
    g.extend_from_slice(samples(0, 20).as_bytes());
    let gf = d.file("bom.jsonl", &g);
    expect(
        &run(&["stream", "--input", s(&gf)], None),
        2,
        &["bom.jsonl:1:", "byte-order mark"],
        "stream file",
    );
    let o = run_bytes(&["stream"], Some(&g));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("<stdin>:1: skipped: starts with a UTF-8 byte-order mark"));
}

/// Regression: before the fix, `ael --beam-diameter-mm 1e300` exited 0 with a scan
/// pass angle above 360°.
#[test]
fn a_beam_wider_than_a_turn_is_refused() {
    let ael = |d: &str| {
        run(
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                "--beam-diameter-mm",
                d,
                "--format",
                "json",
            ],
            None,
        )
    };
    for d in ["1e300", "1e5", "700"] {
        expect(&ael(d), 2, &["--beam-diameter-mm", "360°"], d);
    }
    // The widest beam that does not reach the aperture at every head
    // angle: (7 mm + d)/2 < 100 mm (the pass, 2·asin((7 + d)/200), below a
    // whole turn).
    let edge = 200.0 - 7.0;
    for d in [8.0, 150.0, edge - 1e-9] {
        let o = ael(&d.to_string());
        assert_eq!(o.status.code(), Some(0), "{d}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let pass = v["scan_pass_angle_deg"].as_f64().unwrap();
        assert!(pass > 0.0 && pass <= 360.0, "{d}: {pass}");
    }
    expect(
        &ael(&edge.to_string()),
        2,
        &["--beam-diameter-mm", "every head angle"],
        "edge",
    );
}

// ---------------------------------------------------------------------------
// Must show: the live stream survives hostile bytes.

/// `stream --realtime` fed a line of non-UTF-8 bytes and a 10 MiB line
/// between valid samples keeps emitting frames every period, reports both
/// lines with their numbers, and exits 0 when stdin closes. Guards the
/// live path of the two stdin regressions above (invalid UTF-8, a line over
/// 64 KiB).
#[test]
fn realtime_stream_survives_bad_bytes_and_a_10_mib_line() {
    let (mut child, rx, reader) = live_child(&["--bins", "36"]);
    let mut stdin = child.stdin.take().unwrap();
    let start = Instant::now();
    feed_paced(&mut stdin, Instant::now(), 0, 20, 0.0); // lines 1–21
    stdin.write_all(b"\xff\xfe\xfd not text \x80\n").unwrap(); // line 22
    stdin.flush().unwrap();
    let mut big = vec![b'x'; 10 << 20];
    big.push(b'\n');
    stdin.write_all(&big).unwrap(); // line 23
    stdin.flush().unwrap();
    feed_paced(&mut stdin, Instant::now(), 21, 60, 0.0); // lines 24–63
                                                         // Silence with the pipe open, then close.
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "exited while stdin open"
    );
    let open_for = start.elapsed().as_secs_f64();
    drop(stdin);
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    let status = wait_exit(&mut child, Duration::from_secs(5));
    reader.join().unwrap();
    assert_eq!(status.code(), Some(0), "{err}");
    assert!(err.contains("<stdin>:22: skipped: not UTF-8"), "{err}");
    assert!(
        err.contains("<stdin>:23: skipped: line longer than 65536 bytes"),
        "{err}"
    );
    let frames: Vec<_> = rx.try_iter().collect();
    let expected = open_for / PERIOD_S;
    let gaps: Vec<f64> = frames
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).as_secs_f64())
        .collect();
    let max_gap = gaps.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "{} frames in {open_for:.3} s open (≈{expected:.0} periods); largest gap {max_gap:.3} s",
        frames.len()
    );
    assert!(
        frames.len() as f64 >= expected - 3.0,
        "{} frames",
        frames.len()
    );
    assert!(max_gap <= 2.0 * PERIOD_S + 0.075, "{gaps:?}");
    assert!(
        frames.iter().any(|f| f.1 == "adaptive"),
        "the samples around the bad lines were used"
    );
}
