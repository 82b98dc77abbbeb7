//! The optimizer's refactor (good_lp, one loop, typed
//! errors) keeps its outputs byte-identical. The files under
//! `tests/data/optimizer_golden/` were written by the binary *before* the
//! refactor (`profile --config examples/configs/C.toml --gaze-deg G
//! --certificate DIR --out F`, for the four shipped configs at gazes 0, 90
//! and 200), except `smooth_*`, regenerated when the programs moved onto
//! good_lp (two-sided rows became two rows; the differences, ≤ 2·10⁻¹³
//! relative in the profile, are tabled in `specs/optimizer.md`); this test
//! runs today's binary with the same arguments and
//! compares every byte of the profile, `problem.mps` and `certificate.json`.
//!
//! Regenerate only for a change that is meant to move the answers (and say
//! why in the commit): `scripts/optimizer_golden.sh`.
#![cfg(all(feature = "solver", feature = "cli"))]

use std::path::{Path, PathBuf};
use std::process::Command;

const CONFIGS: [&str; 4] = ["paper", "multi_level", "smooth", "vls128_eye"];
const GAZES_DEG: [&str; 3] = ["0", "90", "200"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn first_difference(a: &[u8], b: &[u8]) -> String {
    let at = a
        .iter()
        .zip(b)
        .position(|(x, y)| x != y)
        .unwrap_or(a.len().min(b.len()));
    let line = a[..at].iter().filter(|&&c| c == b'\n').count() + 1;
    format!(
        "{} bytes against {}; first difference at byte {at} (line {line})",
        a.len(),
        b.len()
    )
}

fn compare(golden: &Path, fresh: &Path, failures: &mut Vec<String>) {
    let want = std::fs::read(golden).unwrap_or_else(|e| panic!("{}: {e}", golden.display()));
    match std::fs::read(fresh) {
        Ok(got) if got == want => {}
        Ok(got) => failures.push(format!(
            "{}: {}",
            golden.display(),
            first_difference(&got, &want)
        )),
        Err(e) => failures.push(format!("{}: not written ({e})", fresh.display())),
    }
}

#[test]
fn shipped_configs_give_the_recorded_bytes() {
    let data = root().join("tests/data/optimizer_golden");
    let tmp = std::env::temp_dir().join(format!("optimizer_golden_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    let mut failures = Vec::new();
    for config in CONFIGS {
        for gaze in GAZES_DEG {
            let name = format!("{config}_g{gaze}");
            let out = tmp.join(format!("{name}.json"));
            let dir = tmp.join(&name);
            let status = Command::new(env!("CARGO_BIN_EXE_gaze-lidar"))
                .current_dir(root())
                .args(["profile", "--config"])
                .arg(format!("examples/configs/{config}.toml"))
                .args(["--gaze-deg", gaze, "--certificate"])
                .arg(&dir)
                .arg("--out")
                .arg(&out)
                .status()
                .unwrap();
            assert!(status.success(), "{name}: exit {status}");
            compare(&data.join(format!("{name}.json")), &out, &mut failures);
            for file in ["problem.mps", "certificate.json"] {
                compare(&data.join(&name).join(file), &dir.join(file), &mut failures);
            }
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The comparison can fail: one changed byte is found and located.
#[test]
fn a_changed_byte_is_reported() {
    let tmp = std::env::temp_dir().join(format!("optimizer_golden_neg_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let golden = root().join("tests/data/optimizer_golden/paper_g90.json");
    let mut bytes = std::fs::read(&golden).unwrap();
    let k = bytes.len() / 2;
    bytes[k] ^= 1;
    let fresh = tmp.join("changed.json");
    std::fs::write(&fresh, &bytes).unwrap();
    let mut failures = Vec::new();
    compare(&golden, &fresh, &mut failures);
    let _ = std::fs::remove_dir_all(&tmp);
    assert_eq!(failures.len(), 1);
    assert!(
        failures[0].contains(&format!("first difference at byte {k}")),
        "{failures:?}"
    );
}
