//! `check` on large profiles: the checker (library) at 10^4 and 10^5 bins
//! with the eye-safety bound's branch and bound against its exhaustive
//! search in the same run, and the CLI (`gaze-lidar check FILE`, parsing
//! included) on a 10^6-bin file. The workload is the paper preset's
//! closed-form joint profile cut into sub-bins (`benches/common`), smooth
//! (steps) and rough (power ripple, in-bin acceleration everywhere).
//! Run: `cargo bench --bench check`.

#[path = "common/big_profile.rs"]
mod big_profile;

use big_profile::{big_profile, Roughness};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode};
use std::hint::black_box;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

use gaze_lidar::checker::check;
use gaze_lidar::eye_safety::bound::Search;
use gaze_lidar::eye_safety::exposure::evaluate_profile_with;

fn library(c: &mut Criterion) {
    let mut g = c.benchmark_group("check");
    g.sample_size(10).sampling_mode(SamplingMode::Flat);
    let sizes: &[usize] = if std::env::args().any(|a| a == "--bench") {
        &[10_000, 100_000]
    } else {
        &[10_000]
    };
    for &n in sizes {
        for (name, r) in [("smooth", Roughness::Smooth), ("rough", Roughness::Rough)] {
            let p = big_profile(n, r);
            assert!(
                check(&p).is_empty(),
                "the {name} {n}-bin workload certifies"
            );
            let params = p.limits.eye_safety.clone().unwrap();
            g.bench_with_input(BenchmarkId::new(format!("check_{name}"), n), &p, |b, p| {
                b.iter(|| check(black_box(p)))
            });
            for (label, search) in [
                ("pruned", Search::Pruned),
                ("exhaustive", Search::Exhaustive),
            ] {
                g.bench_with_input(
                    BenchmarkId::new(format!("eye_safety_{name}_{label}"), n),
                    &p,
                    |b, p| b.iter(|| evaluate_profile_with(black_box(p), &params, search).unwrap()),
                );
            }
        }
    }
    g.finish();
}

/// Runs `gaze-lidar check FILE` once; panics unless it certifies.
fn cli_check(path: &PathBuf) -> Duration {
    let t = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_gaze-lidar"))
        .arg("check")
        .arg(path)
        .output()
        .expect("gaze-lidar runs");
    let dt = t.elapsed();
    assert!(
        out.status.success(),
        "gaze-lidar check {}: {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    dt
}

fn cli(c: &mut Criterion) {
    // `cargo bench` passes `--bench`; under `cargo test --all-targets` the
    // bench runs once as a smoke test, on a small file.
    let n = if std::env::args().any(|a| a == "--bench") {
        1_000_000usize
    } else {
        20_000
    };
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let mut g = c.benchmark_group("cli_check");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(1));
    for (name, r) in [("smooth", Roughness::Smooth), ("rough", Roughness::Rough)] {
        let path = dir.join(format!("check_{n}_{name}.json"));
        let json = big_profile(n, r).to_json().expect("serializes");
        std::fs::write(&path, json).expect("writes the workload");
        eprintln!(
            "gaze-lidar check, {n} bins ({name}): {:.2} s (one run)",
            cli_check(&path).as_secs_f64()
        );
        g.bench_with_input(BenchmarkId::new(name, n), &path, |b, path| {
            b.iter_custom(|iters| (0..iters).map(|_| cli_check(path)).sum())
        });
        std::fs::remove_file(&path).ok();
    }
    g.finish();
}

criterion_group!(benches, library, cli);
criterion_main!(benches);
