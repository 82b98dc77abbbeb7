//! A corpus of hostile input and hostile conditions, through the
//! real binary, for every subcommand and every file format (profile JSON,
//! scenario TOML, optimizer TOML). Each case asserts the exit code (2 bad
//! input, 1 infeasible / rejected / failed write), one message line naming
//! the field or argument, no panic, and no partial or clobbered file.
//! Special files are nodes created in a temporary folder, never a real
//! `/dev` path (except `/dev/zero` as an endless *input* and `/dev/full` as
//! a full stdout).

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use common::{expect, no_panic, run, stderr, stdout};

const BIN: &str = env!("CARGO_BIN_EXE_gaze-lidar");

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

struct Fixture {
    dir: tempfile::TempDir,
}

impl Fixture {
    fn new() -> Self {
        Self {
            dir: tempfile::tempdir().unwrap(),
        }
    }
    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }
    fn file(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, contents).unwrap();
        p
    }
    /// A valid, certified profile@1 file.
    fn profile(&self) -> PathBuf {
        let o = run(&["profile", "--gaze-deg", "90", "--bins", "36"], None);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        self.file("good.json", &o.stdout)
    }
}

/// Runs with stdout redirected to a file (e.g. `/dev/full`).
fn run_stdout_to(args: &[&str], out: &Path) -> Output {
    let f = std::fs::OpenOptions::new().write(true).open(out).unwrap();
    Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .stdout(f)
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

/// `gaze-lidar ARGS | head -c1` (or `head -1`) through a shell; returns
/// the exit code of gaze-lidar (PIPESTATUS[0]) and its stderr.
fn run_into_head(args: &[&str], head: &str) -> (i32, String) {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let script = format!(
        "'{BIN}' {} 2>\"$ERR\" | head {head} >/dev/null; echo ${{PIPESTATUS[0]}}",
        quoted.join(" ")
    );
    let err = tempfile::NamedTempFile::new().unwrap();
    let o = Command::new("bash")
        .arg("-c")
        .arg(script)
        .env("ERR", err.path())
        .output()
        .unwrap();
    let code = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
    (code, std::fs::read_to_string(err.path()).unwrap())
}

/// [`common::tiny_sim`] at seed 3.
fn tiny_sim<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    common::tiny_sim(&[&["--seed", "3"][..], extra].concat())
}

#[test]
fn argument_errors_name_the_argument() {
    let cases: &[(&[&str], i32, &[&str])] = &[
        // profile
        (&["profile", "--gaze-deg", "abc"], 2, &["--gaze-deg"]),
        (&["profile", "--gaze-deg", "1e300"], 2, &["gaze"]),
        (&["profile", "--gaze-deg", "NaN"], 2, &["gaze"]),
        (&["profile", "--gaze-deg", "inf"], 2, &["gaze"]),
        (
            &["profile", "--gaze-deg", "90", "--bins", "-5"],
            2,
            &["--bins"],
        ),
        (
            &["profile", "--gaze-deg", "90", "--bins", "3"],
            2,
            &["bins"],
        ),
        (
            &["profile", "--gaze-deg", "90", "--bins", "36001"],
            2,
            &["bins"],
        ),
        (
            &["profile", "--gaze-deg", "90", "--bins", "1e3"],
            2,
            &["--bins"],
        ),
        (
            &["profile", "--gaze-deg", "90", "--preset", "nope"],
            2,
            &["--preset"],
        ),
        (
            &["profile", "--gaze-deg", "90", "--mode", "warp"],
            2,
            &["--mode"],
        ),
        (&["profile", "--mode", "joint"], 2, &["--gaze-deg"]),
        (
            &["profile", "--gaze-deg", "90", "--tick-hz", "-1"],
            2,
            &["--tick-hz"],
        ),
        (
            &[
                "profile",
                "--gaze-deg",
                "90",
                "--format",
                "firmware",
                "--power-w-per-code",
                "-1",
            ],
            2,
            &["--power-w-per-code"],
        ),
        (
            &["profile", "--gaze-deg", "90", "--format", "firmware-bin"],
            2,
            &["--out"],
        ),
        (&["profile", "--frobnicate"], 2, &["--frobnicate"]),
        (&["profile", "--gaze-deg"], 2, &["--gaze-deg"]),
        // check
        (&["check"], 2, &["<FILE>"]),
        (
            &["check", "/no/such/profile.json"],
            2,
            &["/no/such/profile.json"],
        ),
        (&["check", "x.json", "--format", "xml"], 2, &["--format"]),
        // ael
        (&["ael"], 2, &["--wavelength-nm", "--pulse-duration-s"]),
        (
            &["ael", "--wavelength-nm", "905"],
            2,
            &["--pulse-duration-s"],
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "500",
                "--pulse-duration-s",
                "5e-9",
            ],
            2,
            &["--wavelength-nm"],
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "inf",
                "--pulse-duration-s",
                "5e-9",
            ],
            2,
            &["--wavelength-nm"],
        ),
        (
            &["ael", "--wavelength-nm", "905", "--pulse-duration-s", "-1"],
            2,
            &["--pulse-duration-s"],
        ),
        (
            &["ael", "--wavelength-nm", "905", "--pulse-duration-s", "0"],
            2,
            &["--pulse-duration-s"],
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                "--pulse-rate-hz",
                "1e300",
            ],
            2,
            &["--pulse-rate-hz", "overlap"],
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "1e-3",
                "--pulse-rate-hz",
                "1000",
            ],
            2,
            &["--pulse-rate-hz", "overlap"],
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                "--pulse-rate-hz",
                "-5",
            ],
            2,
            &["--pulse-rate-hz"],
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                "--beam-diameter-mm",
                "nan",
            ],
            2,
            &["--beam-diameter-mm"],
        ),
        // simulate
        (&["simulate", "--trials", "0"], 2, &["--trials"]),
        (&["simulate", "--trials", "-1"], 2, &["--trials"]),
        (&["simulate", "--seed", "-1"], 2, &["--seed"]),
        (&["simulate", "--fog", "30"], 2, &["--fog"]),
        (&["simulate", "--fog", "-5"], 2, &["--fog"]),
        (&["simulate", "--detect", "3/2"], 2, &["--detect"]),
        (&["simulate", "--detect", "0/0"], 2, &["--detect"]),
        (&["simulate", "--model", "carla"], 2, &["--model"]),
        (&["simulate", "--variant", "warp"], 2, &["--variant"]),
        (
            &["simulate", "--scenario", "/no/such.toml"],
            2,
            &["/no/such.toml"],
        ),
        (
            &["simulate", "--optimizer-config", "/no/such.toml"],
            2,
            &["--variant optimized"],
        ),
        // stream: argument parsing only
        (&["stream", "--format", "bogus"], 2, &["--format"]),
        (&["stream", "--timeout-ms", "abc"], 2, &["--timeout-ms"]),
        (&["stream", "--preset", "nope"], 2, &["--preset"]),
        (&["stream", "--bins", "3"], 2, &["--bins"]),
        (
            &["stream", "--input", "/no/such.jsonl"],
            2,
            &["/no/such.jsonl"],
        ),
        (
            &["stream", "--config", "/no/such.toml"],
            2,
            &["/no/such.toml"],
        ),
        // top level
        (&["frobnicate"], 2, &["frobnicate"]),
    ];
    for (args, code, needles) in cases {
        let o = run(args, None);
        expect(&o, *code, needles, &format!("{args:?}"));
        assert!(o.stdout.is_empty(), "{args:?}: stdout not empty");
    }
}

#[test]
fn hyphenated_numbers_are_numbers() {
    let a = run(&["profile", "--gaze-deg", "-0.25"], None);
    let b = run(&["profile", "--gaze-deg", "-2.5e-1"], None);
    assert_eq!(a.status.code(), Some(0), "{}", stderr(&a));
    assert_eq!(b.status.code(), Some(0), "{}", stderr(&b));
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn hostile_profile_files() {
    let f = Fixture::new();
    let good = std::fs::read_to_string(f.profile()).unwrap();
    let tampered = {
        let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
        v["bins"][0]["power_w"] = serde_json::json!(1.0);
        v.to_string()
    };
    let wrong_type = good.replacen("\"width_deg\": 10.0", "\"width_deg\": \"wide\"", 1);
    assert_ne!(wrong_type, good);
    let cases: Vec<(&str, Vec<u8>, i32, Vec<&str>)> = vec![
        ("empty.json", vec![], 2, vec!["empty.json"]),
        (
            "trunc.json",
            good.as_bytes()[..good.len() / 2].to_vec(),
            2,
            vec!["trunc.json:"],
        ),
        ("array.json", b"[1, 2, 3]".to_vec(), 2, vec!["array.json"]),
        (
            "format.json",
            good.replace("gaze-lidar/profile@1", "gaze-lidar/profile@9")
                .into_bytes(),
            2,
            vec!["format.json", "profile@9"],
        ),
        (
            "type.json",
            wrong_type.into_bytes(),
            2,
            vec!["type.json:", "invalid type"],
        ),
        (
            "huge_number.json",
            good.replacen("\"width_deg\": 10.0", "\"width_deg\": 1e999", 1)
                .into_bytes(),
            2,
            vec!["huge_number.json"],
        ),
        (
            "binary.json",
            vec![0xff, 0xfe, 0x00, 0x7b],
            2,
            vec!["binary.json", "UTF-8"],
        ),
        (
            "tampered.json",
            tampered.into_bytes(),
            1,
            vec!["tampered.json", "rejected"],
        ),
    ];
    for (name, bytes, code, needles) in &cases {
        let p = f.file(name, bytes);
        let o = run(&["check", s(&p)], None);
        expect(&o, *code, needles, name);
        let o = run(
            &["check", "-", "--format", "json"],
            Some(&String::from_utf8_lossy(bytes)),
        );
        no_panic(&o, name);
        assert_eq!(
            o.status.code(),
            Some(*code),
            "{name} on stdin: {}",
            stderr(&o)
        );
    }
    // A directory, an endless character device, an over-size (sparse) file.
    let o = run(&["check", s(f.dir.path())], None);
    expect(&o, 2, &["directory"], "check DIR");
    let t = std::time::Instant::now();
    let o = run(&["check", "/dev/zero"], None);
    expect(&o, 2, &["/dev/zero", "limit"], "check /dev/zero");
    assert!(
        t.elapsed().as_secs() < 20,
        "check /dev/zero took {:?}",
        t.elapsed()
    );
    let big = f.path("big.json");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(600 << 20)
        .unwrap();
    let o = run(&["check", s(&big)], None);
    expect(&o, 2, &["big.json", "limit"], "check big");
}

#[test]
fn hostile_scenario_files() {
    let f = Fixture::new();
    let cases: &[(&str, &str, &[&str])] = &[
        ("speed_tiny.toml", "speed_kmh = 1e-300\n", &["speed_kmh"]),
        ("speed_slow.toml", "speed_kmh = 0.01\n", &["speed_kmh"]),
        ("speed_zero.toml", "speed_kmh = 0.0\n", &["speed_kmh"]),
        ("speed_neg.toml", "speed_kmh = -50.0\n", &["speed_kmh"]),
        ("speed_nan.toml", "speed_kmh = nan\n", &["speed_kmh"]),
        ("speed_fast.toml", "speed_kmh = 1e6\n", &["speed_kmh"]),
        ("speed_str.toml", "speed_kmh = \"fast\"\n", &["speed_kmh"]),
        (
            "far.toml",
            "bend_distance_m = 9000.0\n",
            &["speed_kmh", "bend_distance_m", "maximum"],
        ),
        (
            "offset.toml",
            "start_offset_m = [5.0, 1.0]\n",
            &["start_offset_m"],
        ),
        ("unknown.toml", "warp_factor = 9\n", &["warp_factor"]),
        ("syntax.toml", "speed_kmh = = 3\n", &["syntax.toml"]),
        (
            "refl.toml",
            "vehicle_reflectivity = 2.0\n",
            &["vehicle_reflectivity"],
        ),
        ("binary.toml", "\u{0}\u{1}\u{2}", &["binary.toml"]),
    ];
    for (name, text, needles) in cases {
        let p = f.file(name, text);
        let t = std::time::Instant::now();
        let o = run(&tiny_sim(&["--scenario", s(&p)]), None);
        expect(&o, 2, needles, name);
        assert!(t.elapsed().as_secs() < 10, "{name}: {:?}", t.elapsed());
    }
    let o = run(&tiny_sim(&["--scenario", "/dev/zero"]), None);
    expect(&o, 2, &["/dev/zero", "limit"], "scenario /dev/zero");
    let o = run(&tiny_sim(&["--scenario", s(f.dir.path())]), None);
    expect(&o, 2, &["directory"], "scenario DIR");
}

#[cfg(feature = "solver")]
#[test]
fn hostile_optimizer_configs() {
    let f = Fixture::new();
    let sim = |p: &Path| {
        run(
            &tiny_sim(&["--variant", "optimized", "--optimizer-config", s(p)]),
            None,
        )
    };
    let missing = f.path("missing.toml");
    expect(&sim(&missing), 2, &["missing.toml"], "missing");
    let cases: &[(&str, &str, i32, &[&str])] = &[
        ("unknown.toml", "[limits]\nwarp = 1.0\n", 2, &["warp"]),
        ("mode.toml", "[objective]\nmode = \"warp\"\n", 2, &["mode"]),
        (
            "accel.toml",
            "[limits]\nspin_accel_rad_s2_max = \"fast\"\n",
            2,
            &["limits.spin_accel_rad_s2_max"],
        ),
        (
            "neg.toml",
            "[lidar]\naverage_power_w = -1.0\n",
            2,
            &["lidar.average_power_w"],
        ),
        ("bins.toml", "bins = 36000\n", 2, &["bins"]),
        ("bins_low.toml", "bins = 2\n", 2, &["bins"]),
        (
            "preset.toml",
            "[lidar]\npreset = \"nope\"\n",
            2,
            &["lidar.preset"],
        ),
        (
            "infeasible.toml",
            "[limits]\nspin_rad_s_max = 100.0\n",
            1,
            &["infeasible", "spin_rad_s_max"],
        ),
        (
            "infeasible_power.toml",
            "[limits]\npower_w_min = 0.002\npower_w_max = 0.003\n",
            1,
            &["infeasible", "power_w_min"],
        ),
    ];
    for (name, text, code, needles) in cases {
        let p = f.file(name, text);
        let t = std::time::Instant::now();
        expect(&sim(&p), *code, needles, &format!("simulate {name}"));
        assert!(t.elapsed().as_secs() < 20, "{name}: {:?}", t.elapsed());
        let o = run(&["profile", "--gaze-deg", "90", "--config", s(&p)], None);
        expect(&o, *code, needles, &format!("profile {name}"));
    }
    let o = sim(Path::new("/dev/zero"));
    expect(&o, 2, &["/dev/zero", "limit"], "optimizer /dev/zero");
    // Without the optimized variant the flag would do nothing: refused.
    let good = f.file("good.toml", "bins = 72\n");
    let o = run(&tiny_sim(&["--optimizer-config", s(&good)]), None);
    expect(
        &o,
        2,
        &["--optimizer-config", "--variant optimized"],
        "dead flag",
    );
}

#[test]
fn output_paths_are_never_clobbered() {
    let f = Fixture::new();
    let gaze = ["profile", "--gaze-deg", "90", "--bins", "36", "--out"];
    let with_out = |p: &Path| {
        let mut v = gaze.to_vec();
        v.push(s(p));
        run(&v, None)
    };
    // A directory, a missing parent, a parent that is a file.
    expect(&with_out(f.dir.path()), 2, &["directory"], "--out DIR");
    expect(
        &with_out(&f.path("no/such/dir/p.json")),
        2,
        &["no/such/dir"],
        "--out missing parent",
    );
    let plain = f.file("plain.txt", "keep me");
    expect(
        &with_out(&plain.join("p.json")),
        2,
        &["plain.txt"],
        "--out under a file",
    );
    assert_eq!(std::fs::read_to_string(&plain).unwrap(), "keep me");
    // An existing file is replaced whole; a symbolic link is kept.
    let target = f.file("target.json", "old");
    let link = f.path("link.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let o = with_out(&link);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let text = std::fs::read_to_string(&target).unwrap();
    gaze_lidar::profile::Profile::from_json(&text, "target").unwrap();
    // A FIFO is written in place and stays a FIFO.
    let fifo = f.path("fifo");
    let st = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(st.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let o = with_out(&fifo);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let got = reader.join().unwrap();
    gaze_lidar::profile::Profile::from_json(&got, "fifo").unwrap();
    {
        use std::os::unix::fs::FileTypeExt;
        let ft = std::fs::symlink_metadata(&fifo).unwrap().file_type();
        assert!(ft.is_fifo(), "the FIFO was replaced: {ft:?}");
    }
    // A character device node (root only: mknod), created here, stays one.
    let node = f.path("null-node");
    let made = Command::new("mknod")
        .arg(&node)
        .args(["c", "1", "3"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if made {
        let o = with_out(&node);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        use std::os::unix::fs::FileTypeExt;
        let ft = std::fs::symlink_metadata(&node).unwrap().file_type();
        assert!(ft.is_char_device(), "the device node was replaced: {ft:?}");
    } else {
        eprintln!("note: mknod not permitted; device-node case skipped");
    }
    // A failed run leaves no temporary files behind.
    let stray: Vec<_> = std::fs::read_dir(f.dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with(".gaze-lidar"))
        .collect();
    assert!(stray.is_empty(), "{stray:?}");
}

#[test]
fn several_outputs_are_all_or_nothing() {
    let f = Fixture::new();
    let earlier = f.file("rows.json", "precious");
    let plots_file = f.file("plots", "not a dir");
    let cases: Vec<(Vec<String>, &[&str])> = vec![
        (
            vec!["--export-csv".into(), s(f.dir.path()).into()],
            &["directory"],
        ),
        (
            vec!["--trials-csv".into(), s(&f.path("no/dir/t.csv")).into()],
            &["no/dir"],
        ),
        (
            vec!["--report".into(), s(&f.path("nope/r.md")).into()],
            &["nope"],
        ),
        (
            vec!["--plots".into(), s(&plots_file).into()],
            &["--plots", "not a directory"],
        ),
        (
            vec!["--export-csv".into(), s(&earlier).into()],
            &["two outputs"],
        ),
    ];
    for (extra, needles) in &cases {
        let mut args: Vec<&str> = tiny_sim(&["--export-json", s(&earlier)]);
        args.extend(extra.iter().map(String::as_str));
        let o = run(&args, None);
        expect(&o, 2, needles, &format!("{extra:?}"));
        assert!(o.stdout.is_empty(), "{extra:?}: the run started");
        assert_eq!(std::fs::read_to_string(&earlier).unwrap(), "precious");
        assert_eq!(std::fs::read_to_string(&plots_file).unwrap(), "not a dir");
    }
    // And all of them when every path is good.
    let csv = f.path("rows.csv");
    let o = run(
        &tiny_sim(&["--export-json", s(&earlier), "--export-csv", s(&csv)]),
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(std::fs::read_to_string(&earlier).unwrap().contains("rows"));
    assert!(std::fs::read_to_string(&csv).unwrap().contains("variant"));
}

#[test]
fn full_stdout_is_an_error() {
    if !Path::new("/dev/full").exists() {
        eprintln!("note: no /dev/full; skipped");
        return;
    }
    let f = Fixture::new();
    let good = f.profile();
    let full = Path::new("/dev/full");
    let cases: Vec<Vec<&str>> = vec![
        vec!["check", s(&good)],
        vec!["check", s(&good), "--format", "json"],
        vec![
            "ael",
            "--wavelength-nm",
            "905",
            "--pulse-duration-s",
            "5e-9",
        ],
        vec![
            "ael",
            "--wavelength-nm",
            "905",
            "--pulse-duration-s",
            "5e-9",
            "--format",
            "json",
        ],
        vec!["profile", "--gaze-deg", "90"],
        vec!["profile", "--gaze-deg", "90", "--format", "csv"],
        tiny_sim(&[]),
        vec!["--help"],
    ];
    for args in &cases {
        let o = run_stdout_to(args, full);
        expect(&o, 1, &["stdout"], &format!("{args:?} > /dev/full"));
    }
}

#[test]
fn closed_pipes_are_quiet() {
    let f = Fixture::new();
    let good = f.profile();
    let sim = tiny_sim(&[]);
    let cases: Vec<(Vec<&str>, &str, usize)> = vec![
        (vec!["check", s(&good)], "-c1", 30),
        (vec!["check", s(&good), "--format", "json"], "-c1", 10),
        (
            vec![
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
            ],
            "-c1",
            30,
        ),
        (
            vec!["profile", "--gaze-deg", "90", "--bins", "3600"],
            "-c1",
            10,
        ),
        (sim, "-1", 5),
    ];
    for (args, head, n) in &cases {
        for _ in 0..*n {
            let (code, err) = run_into_head(args, head);
            assert!(
                code == 0 || code == 141,
                "{args:?} | head {head}: exit {code}: {err}"
            );
            // No message about the pipe (a stall warning from `check` may stand).
            let low = err.to_lowercase();
            assert!(
                !low.contains("error") && !low.contains("pipe") && !low.contains("panicked"),
                "{args:?} | head {head}: {err}"
            );
        }
    }
    let _ = stdout;
}
