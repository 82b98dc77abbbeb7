//! Helpers shared by the integration tests: run the real binary.
#![allow(dead_code)]

use std::process::{Command, Output, Stdio};

/// Runs `gaze-lidar` with `args` and optional stdin.
pub fn run(args: &[&str], stdin: Option<&str>) -> Output {
    run_bytes(args, stdin.map(str::as_bytes))
}

/// Runs `gaze-lidar` with `args` and optional stdin bytes (written from a
/// thread, so a child that stops reading early cannot block the test).
pub fn run_bytes(args: &[&str], stdin: Option<&[u8]>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_gaze-lidar"));
    cmd.args(args).stdout(Stdio::piped()).stderr(Stdio::piped());
    cmd.stdin(if stdin.is_some() {
        Stdio::piped()
    } else {
        Stdio::null()
    });
    let mut child = cmd.spawn().expect("spawn gaze-lidar");
    let writer = stdin.map(|s| {
        let bytes = s.to_vec();
        let mut pipe = child.stdin.take().expect("stdin");
        std::thread::spawn(move || {
            use std::io::Write;
            // The child may exit before reading everything (an error).
            let _ = pipe.write_all(&bytes);
        })
    });
    let out = child.wait_with_output().expect("wait gaze-lidar");
    if let Some(w) = writer {
        w.join().expect("stdin writer");
    }
    out
}

/// No panic, whatever the outcome.
pub fn no_panic(o: &Output, what: &str) {
    let err = stderr(o);
    assert_ne!(o.status.code(), Some(101), "{what}: exit 101: {err}");
    assert!(!err.contains("panicked"), "{what}: panic: {err}");
    assert!(!err.contains("RUST_BACKTRACE"), "{what}: panic: {err}");
}

/// Exit `code`, one stderr line containing every needle, no panic.
pub fn expect(o: &Output, code: i32, needles: &[&str], what: &str) {
    no_panic(o, what);
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{what}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{what}: one line expected: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{what}: expected '{n}' in: {err}");
    }
}

/// The smallest `simulate` run: one trial of the argus model's baseline
/// variant without fog.
pub const TINY_SIM: [&str; 9] = [
    "simulate",
    "--trials",
    "1",
    "--model",
    "argus",
    "--variant",
    "baseline",
    "--fog",
    "0",
];

/// [`TINY_SIM`] followed by `extra`.
pub fn tiny_sim<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    [&TINY_SIM[..], extra].concat()
}

/// Stdout as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Stderr as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a bad-input failure: exit 2, one message line on stderr, no panic.
pub fn assert_bad_input(o: &Output, needle: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one line expected: {err}"
    );
    assert!(err.contains(needle), "expected '{needle}' in: {err}");
}

/// The arguments of `gaze-lidar profile --preset PRESET --mode MODE
/// --gaze-deg GAZE`, then `extra`.
pub fn profile_args<'a>(
    preset: &'a str,
    mode: &'a str,
    gaze_deg: &'a str,
    extra: &[&'a str],
) -> Vec<&'a str> {
    let head = [
        "profile",
        "--preset",
        preset,
        "--mode",
        mode,
        "--gaze-deg",
        gaze_deg,
    ];
    [&head[..], extra].concat()
}

/// Runs `gaze-lidar` expecting success and parses its stdout as profile@1.
pub fn profile_from(args: &[&str]) -> gaze_lidar::profile::Profile {
    let o = run(args, None);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    gaze_lidar::profile::Profile::from_json(&stdout(&o), "stdout").unwrap()
}

/// What HiGHS said solving a model file afresh.
#[cfg(feature = "solver")]
pub struct HighsRun {
    /// `Highs_run`'s return (0 ok, 1 warning, negative error).
    pub run_status: i32,
    /// `Highs_getModelStatus` (7 = optimal).
    pub model_status: i32,
    /// The objective HiGHS reports.
    pub objective: f64,
}

/// HiGHS reads `path` (free MPS) with its own reader (through the C API,
/// single-threaded, quiet) and solves it with every tolerance named in
/// `tight` set to 1e-10: a point 1e-7 outside a row (HiGHS's default) can
/// score above the exact optimum by that much times a dual.
#[cfg(feature = "solver")]
pub fn highs_solve_file(path: &std::path::Path, tight: &[&str]) -> HighsRun {
    use std::ffi::CString;
    let file = CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: the documented HiGHS C API; the handle lives until destroy.
    unsafe {
        let h = highs_sys::Highs_create();
        let quiet = CString::new("output_flag").unwrap();
        highs_sys::Highs_setBoolOptionValue(h, quiet.as_ptr(), 0);
        let threads = CString::new("threads").unwrap();
        highs_sys::Highs_setIntOptionValue(h, threads.as_ptr(), 1);
        for name in tight {
            let key = CString::new(*name).unwrap();
            highs_sys::Highs_setDoubleOptionValue(h, key.as_ptr(), 1e-10);
        }
        let st = highs_sys::Highs_readModel(h, file.as_ptr());
        assert_eq!(st, 0, "HiGHS read {}", path.display());
        let run_status = highs_sys::Highs_run(h);
        let run = HighsRun {
            run_status,
            model_status: highs_sys::Highs_getModelStatus(h),
            objective: highs_sys::Highs_getObjectiveValue(h),
        };
        highs_sys::Highs_destroy(h);
        run
    }
}

/// A shipped optimizer config (`examples/configs/NAME.toml`) as a problem
/// of `bins` bins.
#[cfg(feature = "solver")]
pub fn shipped_problem(name: &str, bins: usize) -> gaze_lidar::optimizer::Problem {
    let text = std::fs::read_to_string(format!("examples/configs/{name}.toml")).unwrap();
    let mut p = gaze_lidar::optimizer::OptimizerConfig::from_toml(&text, name)
        .unwrap()
        .problem()
        .unwrap();
    p.bins = bins;
    p
}
