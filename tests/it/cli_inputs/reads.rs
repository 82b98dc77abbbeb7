//! What the command line reads: gaze rows, numeric flags, scenario arrays.
//! Each test is one kind of bad input, named for what it asserts.
//!
//! Add tests here when a command reads a new file format, column or flag
//! (bad input: exit 2, one line naming the flag, or the file, line and
//! column).

use crate::common;

use common::{expect, run, stderr};
use std::path::{Path, PathBuf};

struct Dir(tempfile::TempDir);

impl Dir {
    fn new() -> Self {
        Self(tempfile::tempdir().unwrap())
    }
    fn file(&self, name: &str, contents: &str) -> PathBuf {
        let p = self.0.path().join(name);
        std::fs::write(&p, contents).unwrap();
        p
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// CSV rows every 10 ms with gaze 10°; `bad` replaces row `at` (0-based).
fn csv(header: &str, row: impl Fn(u32) -> String, n: u32, at: u32, bad: &str) -> String {
    let mut t = format!("{header}\n");
    for k in 0..n {
        if k == at {
            t.push_str(bad);
        } else {
            t.push_str(&row(k));
        }
        t.push('\n');
    }
    t
}

fn plain_row(k: u32) -> String {
    format!("{:.3},10", f64::from(k) * 0.01)
}

fn neon_row(k: u32) -> String {
    format!(
        "{},-10,1",
        1_700_000_000_000_000_000u64 + u64::from(k) * 10_000_000
    )
}

#[test]
fn a_malformed_gaze_in_an_input_file_is_bad_input_naming_line_and_column() {
    let d = Dir::new();
    let f = d.file("g.csv", &csv("t_s,gaze_deg", plain_row, 20, 5, "0.050,abc"));
    let o = run(&["stream", "--format", "csv", "--input", s(&f)], None);
    expect(
        &o,
        2,
        &["g.csv:7:", "column 7", "gaze_deg", "'abc'"],
        "csv abc",
    );
    let f = d.file(
        "gaze.csv",
        &csv(
            "timestamp [ns],azimuth [deg],worn",
            neon_row,
            20,
            3,
            "1700000000030000000,abc,1",
        ),
    );
    let o = run(&["stream", "--format", "neon", "--input", s(&f)], None);
    expect(
        &o,
        2,
        &["gaze.csv:5:", "column 21", "azimuth [deg]", "'abc'"],
        "neon abc",
    );
}

#[test]
fn a_malformed_row_on_a_live_stream_is_reported_with_its_line_and_skipped() {
    let text = csv("t_s,gaze_deg", plain_row, 20, 5, "0.050,abc");
    let o = run(&["stream", "--format", "csv"], Some(&text));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("<stdin>:7: skipped: column 7: field 'gaze_deg'"),
        "{err}"
    );
    // Skipped, not counted as an invalid sample: 19 samples, none invalid.
    assert!(err.contains("19 samples (0 invalid"), "{err}");
    assert!(err.contains("1 malformed lines skipped"), "{err}");
}

#[test]
fn an_invalid_sample_stays_an_invalid_sample() {
    // The tracker's own flag, NaN, an empty gaze (a blink): samples.
    for bad in ["0.050,10,false", "0.050,NaN,true", "0.050,,true"] {
        let text = csv("t_s,gaze_deg,valid", |k| plain_row(k) + ",true", 20, 5, bad);
        let o = run(&["stream", "--format", "csv"], Some(&text));
        assert_eq!(o.status.code(), Some(0), "{bad}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains("20 samples (1 invalid"), "{bad}: {err}");
        assert!(!err.contains("skipped"), "{bad}: {err}");
    }
}

#[test]
fn a_duplicate_header_column_is_refused_by_name() {
    let d = Dir::new();
    let f = d.file(
        "gaze.csv",
        &csv(
            "timestamp [ns],azimuth [deg],worn,azimuth [deg]",
            |k| neon_row(k) + ",20",
            5,
            99,
            "",
        ),
    );
    let o = run(&["stream", "--format", "neon", "--input", s(&f)], None);
    expect(
        &o,
        2,
        &["gaze.csv:1:", "column 'azimuth [deg]' appears twice"],
        "duplicate",
    );
}

#[test]
fn a_subnormal_flag_value_is_refused_naming_the_flag() {
    for (args, flag) in [
        (&["stream", "--timeout-ms", "5e-324"][..], "--timeout-ms"),
        (
            &["stream", "--saccade-deg-s", "5e-324"][..],
            "--saccade-deg-s",
        ),
        (&["profile", "--gaze-deg", "5e-324"][..], "--gaze-deg"),
        (
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-324",
            ][..],
            "--pulse-duration-s",
        ),
        (
            &[
                "ael",
                "--wavelength-nm",
                "905",
                "--pulse-duration-s",
                "5e-9",
                "--pulse-rate-hz",
                "5e-324",
            ][..],
            "--pulse-rate-hz",
        ),
    ] {
        let o = run(args, Some(""));
        expect(&o, 2, &[flag, "5e-324"], &format!("{args:?}"));
    }
}

#[test]
fn a_scenario_array_of_the_wrong_length_is_refused() {
    let d = Dir::new();
    for (value, found) in [
        ("[2, 12, -5]", "3"),
        ("[2]", "1"),
        ("[2, 12, \"junk\"]", ""),
    ] {
        let f = d.file("s.toml", &format!("start_offset_m = {value}\n"));
        let o = run(
            &[
                "simulate",
                "--scenario",
                s(&f),
                "--trials",
                "1",
                "--fog",
                "0",
            ],
            None,
        );
        expect(&o, 2, &["s.toml", "start_offset_m", found], value);
        assert!(o.stdout.is_empty(), "{value}: the run started");
    }
}

#[test]
fn a_negative_detect_rule_names_detect() {
    for v in ["-1/2", "0/1", "3/2", "x"] {
        let o = run(&["simulate", "--detect", v, "--trials", "1"], None);
        expect(&o, 2, &["--detect", v], v);
    }
}
