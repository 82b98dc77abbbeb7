//! What the command line writes: every output path declared and checked
//! before any work, `-` as stdout, and all-or-nothing replacement — on a
//! full disk (a private tmpfs filled to the last block) and with stdout on
//! a full device, the old outputs stay byte-identical and no new file or
//! folder is left.
//!
//! Add tests here when a command gains an output (a file, a folder, a
//! stream): one full-disk case per command that writes files.

use crate::common;

use common::expect;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const PAPER_CONFIG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/configs/paper.toml");

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs the binary in `cwd` with stdout to `stdout` (a file such as
/// `/dev/full`) or captured.
fn run_in(cwd: &Path, args: &[&str], stdout: Option<&Path>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_gaze-lidar"));
    cmd.current_dir(cwd)
        .args(args)
        .stdin(Stdio::null())
        .stderr(Stdio::piped());
    match stdout {
        Some(p) => {
            let f = std::fs::OpenOptions::new().write(true).open(p).unwrap();
            cmd.stdout(f);
        }
        None => {
            cmd.stdout(Stdio::piped());
        }
    }
    cmd.output().expect("run gaze-lidar")
}

/// Every file and folder under `root` with its bytes (folders: empty),
/// except the names in `skip`.
fn tree(root: &Path, skip: &[&str]) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let e = e.unwrap();
            let p = e.path();
            if skip.iter().any(|n| e.file_name() == **n) {
                continue;
            }
            if e.file_type().unwrap().is_dir() {
                out.insert(p.clone(), None);
                stack.push(p);
            } else {
                out.insert(p.clone(), Some(std::fs::read(&p).unwrap()));
            }
        }
    }
    out
}

/// A private tmpfs, filled to its last block by [`FullDisk::fill`];
/// unmounted when dropped. `None` where mounting is not allowed (not root,
/// no mount namespace): the test then says so and passes vacuously.
struct FullDisk {
    _dir: tempfile::TempDir,
    mnt: PathBuf,
}

impl FullDisk {
    fn new() -> Option<Self> {
        let dir = tempfile::tempdir().unwrap();
        let mnt = dir.path().join("mnt");
        std::fs::create_dir(&mnt).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=256k", "tmpfs", s(&mnt)])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|st| st.success());
        if !ok {
            eprintln!("note: cannot mount a tmpfs here; full-disk case skipped");
            return None;
        }
        Some(Self { _dir: dir, mnt })
    }

    fn path(&self, name: &str) -> PathBuf {
        self.mnt.join(name)
    }

    /// Fills the file system: a file of zeros until the first write fails.
    fn fill(&self) {
        use std::io::Write;
        let mut f = std::fs::File::create(self.path(".fill")).unwrap();
        let block = [0u8; 4096];
        while f.write_all(&block).is_ok() {}
        let _ = f.flush();
    }

    fn tree(&self) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
        tree(&self.mnt, &[".fill"])
    }
}

impl Drop for FullDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.mnt).status();
    }
}

/// Old outputs and their folder in `disk`, filled; runs `args` (with `cwd`
/// the tmpfs' parent folder) and asserts exit 1 naming the disk's error and
/// an unchanged tree. Returns the output for further checks.
fn fails_on_full_disk(disk: &FullDisk, args: &[&str], what: &str) -> Output {
    disk.fill();
    let before = disk.tree();
    let o = run_in(&disk.mnt, args, None);
    expect(&o, 1, &["No space left on device"], what);
    assert_eq!(disk.tree(), before, "{what}: the disk's files changed");
    o
}

#[test]
fn a_certificate_folder_on_another_outputs_path_is_refused_before_solving() {
    let d = tempfile::tempdir().unwrap();
    for (cert, out) in [("nx", "nx"), ("f/sub", "f"), ("./nx", "nx")] {
        let o = run_in(
            d.path(),
            &[
                "profile",
                "--config",
                PAPER_CONFIG,
                "--gaze-deg",
                "90",
                "--certificate",
                cert,
                "--out",
                out,
            ],
            None,
        );
        expect(
            &o,
            2,
            &[&format!("--certificate {cert}"), &format!("--out {out}")],
            cert,
        );
        assert!(o.stdout.is_empty());
        assert!(
            tree(d.path(), &[]).is_empty(),
            "{cert}: something was written"
        );
    }
}

#[test]
fn a_dash_means_stdout_for_every_file_output_or_is_refused_by_name() {
    let d = tempfile::tempdir().unwrap();
    let o = run_in(
        d.path(),
        &["profile", "--gaze-deg", "10", "--out", "-"],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stdout.starts_with(b"{"), "profile JSON on stdout");
    let o = run_in(
        d.path(),
        &[
            "profile",
            "--gaze-deg",
            "10",
            "--format",
            "firmware-bin",
            "--out",
            "-",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stdout.starts_with(b"GLFW"), "binary table on stdout");
    let o = run_in(
        d.path(),
        &["sensor", "--preset", "paper", "--out", "-"],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    assert!(o.stdout.starts_with(b"name = "), "sensor TOML on stdout");
    assert!(
        tree(d.path(), &[]).is_empty(),
        "a file named '-' was written"
    );
    // Where stdout already carries the command's data, or a folder is asked.
    for (args, needle) in [
        (
            &[
                "simulate",
                "--trials",
                "1",
                "--fog",
                "0",
                "--export-json",
                "-",
            ][..],
            "--export-json -: stdout already carries the results table",
        ),
        (
            &["simulate", "--trials", "1", "--fog", "0", "--plots", "-"][..],
            "--plots -: a folder of files cannot go to stdout",
        ),
        (
            &[
                "profile",
                "--config",
                PAPER_CONFIG,
                "--gaze-deg",
                "90",
                "--certificate",
                "-",
            ][..],
            "--certificate -: a folder of files cannot go to stdout",
        ),
    ] {
        let o = run_in(d.path(), args, None);
        expect(&o, 2, &[needle], needle);
        assert!(o.stdout.is_empty());
    }
}

#[test]
fn stdout_or_out_on_a_full_device_leaves_the_certificate_folder_as_it_was() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("note: no /dev/full; skipped");
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let cd = d.path().join("cd");
    std::fs::create_dir(&cd).unwrap();
    std::fs::write(cd.join("certificate.json"), "old certificate").unwrap();
    std::fs::write(cd.join("problem.mps"), "old problem").unwrap();
    let before = tree(d.path(), &[]);
    for cert in ["cd", "nd/a/b"] {
        let o = run_in(
            d.path(),
            &[
                "profile",
                "--config",
                PAPER_CONFIG,
                "--gaze-deg",
                "90",
                "--certificate",
                cert,
            ],
            Some(full),
        );
        expect(&o, 1, &["stdout"], cert);
        assert_eq!(tree(d.path(), &[]), before, "{cert}: files changed");
        // The same with the output file on the full device.
        let o = run_in(
            d.path(),
            &[
                "profile",
                "--config",
                PAPER_CONFIG,
                "--gaze-deg",
                "90",
                "--certificate",
                cert,
                "--out",
                "/dev/full",
            ],
            None,
        );
        expect(&o, 1, &["/dev/full"], cert);
        assert_eq!(
            tree(d.path(), &[]),
            before,
            "{cert} --out /dev/full: files changed"
        );
    }
}

#[test]
fn profile_outputs_on_a_full_disk_change_nothing() {
    let Some(disk) = FullDisk::new() else { return };
    std::fs::create_dir(disk.path("cd")).unwrap();
    std::fs::write(disk.path("cd/certificate.json"), "old certificate").unwrap();
    std::fs::write(disk.path("cd/problem.mps"), "old problem").unwrap();
    std::fs::write(disk.path("p.json"), "old profile").unwrap();
    for args in [
        &["profile", "--gaze-deg", "10", "--out", "p.json"][..],
        &[
            "profile",
            "--gaze-deg",
            "10",
            "--format",
            "firmware-bin",
            "--out",
            "new.bin",
        ][..],
        &[
            "profile",
            "--config",
            PAPER_CONFIG,
            "--gaze-deg",
            "90",
            "--certificate",
            "cd",
            "--out",
            "p.json",
        ][..],
        &[
            "profile",
            "--config",
            PAPER_CONFIG,
            "--gaze-deg",
            "90",
            "--certificate",
            "nd/a/b",
        ][..],
    ] {
        let o = fails_on_full_disk(&disk, args, &format!("{args:?}"));
        assert!(o.stdout.is_empty(), "{args:?}: data on stdout");
    }
}

#[test]
fn an_out_file_on_a_full_disk_leaves_no_certificate_folder_elsewhere() {
    let Some(disk) = FullDisk::new() else { return };
    let other = tempfile::tempdir().unwrap();
    let nd = other.path().join("nd/a");
    let o = fails_on_full_disk(
        &disk,
        &[
            "profile",
            "--config",
            PAPER_CONFIG,
            "--gaze-deg",
            "90",
            "--certificate",
            s(&nd),
            "--out",
            "p.json",
        ],
        "out on the full disk",
    );
    assert!(o.stdout.is_empty());
    assert!(
        tree(other.path(), &[]).is_empty(),
        "the certificate folder was left"
    );
}

#[test]
fn sensor_out_on_a_full_disk_changes_nothing() {
    let Some(disk) = FullDisk::new() else { return };
    std::fs::write(disk.path("s.toml"), "old sensor").unwrap();
    for out in ["s.toml", "new.toml"] {
        fails_on_full_disk(&disk, &["sensor", "--preset", "paper", "--out", out], out);
    }
}

#[test]
fn simulate_outputs_on_a_full_disk_change_nothing() {
    let Some(disk) = FullDisk::new() else { return };
    std::fs::write(disk.path("rows.json"), "old rows").unwrap();
    std::fs::write(disk.path("rows.csv"), "old csv").unwrap();
    std::fs::create_dir(disk.path("pl")).unwrap();
    std::fs::write(disk.path("pl/tta_argus.svg"), "old svg").unwrap();
    for extra in [
        &["--export-json", "rows.json", "--export-csv", "rows.csv"][..],
        &["--trials-csv", "trials.csv", "--report", "report.md"][..],
        &["--plots", "pl", "--export-json", "rows.json"][..],
        &["--plots", "new/plots"][..],
    ] {
        let args = common::tiny_sim(extra);
        let o = fails_on_full_disk(&disk, &args, &format!("{extra:?}"));
        assert!(o.stdout.is_empty(), "{extra:?}: the table was printed");
    }
}
