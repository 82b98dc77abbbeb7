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

/// Runs `gaze-lidar` expecting success and parses its stdout as profile@1.
pub fn profile_from(args: &[&str]) -> gaze_lidar::profile::Profile {
    let o = run(args, None);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    gaze_lidar::profile::Profile::from_json(&stdout(&o), "stdout").unwrap()
}
