//! The head's bound: `evaluate_segments` on a 360-bin profile with the
//! 128-channel heads of the `vls128` and `os1-128` presets (and `vlp16`'s 16
//! channels), each against the same profile as one channel (the preset's
//! eye-safety parameters without the head: today's single-channel code path)
//! in the same run. Prints p50/p99 of plain timed runs ([`SAMPLES`] each) and
//! the p99 ratios, then the criterion figures. Run: `cargo bench --bench head`.
//!
//! The same run also times the single-channel paths the head must not slow
//! down, in thread CPU time: gaze sample → certified profile through the
//! stream (closed form on the `paper` preset, 360 bins; the optimizer's fast
//! path, cache warm) and the checker (`check`, library: structure, limits,
//! the eye-safety bound; no file parsing) on the 10⁶-bin rough profile of
//! `benches/check.rs`. To compare two versions of the code, build this
//! bench at each and run the two binaries in turn on the same machine (see
//! `specs/eye_safety.md`, "Performance").
//!
//! `GAZE_LIDAR_HEAD_BENCH_ONLY=PRESET/WHICH` (`WHICH` = `head` or `one`, e.g.
//! `vls128/head`) times that one evaluation alone and skips the rest: for an
//! instruction count under a profiler (`valgrind --tool=callgrind
//! --toggle-collect='head::percentiles*'`).

#[path = "common/big_profile.rs"]
mod big_profile;

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::time::Instant;

use gaze_lidar::checker::check;
use gaze_lidar::eye_safety::bound::Seg;
use gaze_lidar::eye_safety::head::power_scale_to_certify;
use gaze_lidar::eye_safety::{evaluate_segments, EyeSafetyParams};
use gaze_lidar::gaze::{ClosedFormPlanner, FailSafeConfig, FilterConfig, GazeSample, GazeStream};
use gaze_lidar::model::presets::{self, preset};
use gaze_lidar::planner::Mode;

/// Timed runs per percentile figure (`GAZE_LIDAR_HEAD_BENCH_SAMPLES`
/// overrides it and skips the criterion groups: for a profiler's run).
const SAMPLES: usize = 1000;

fn samples() -> (usize, bool) {
    match std::env::var("GAZE_LIDAR_HEAD_BENCH_SAMPLES") {
        Ok(v) => (v.parse().expect("a sample count"), false),
        Err(_) => (SAMPLES, true),
    }
}

/// The calling thread's CPU time, s (`CLOCK_THREAD_CPUTIME_ID`): time the
/// thread ran, not time it waited for a core on a shared machine.
fn thread_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a
    // constant Linux and the BSDs define.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime");
    ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64
}

/// 360 one-degree bins: power `scale·(1 + 0.5 sin 3x)`, spin 62.8 ± 10 rad/s
/// (inside every preset's 5–20 Hz limits), accelerating inside the bins.
fn profile(scale: f64) -> Vec<Seg> {
    (0..360)
        .map(|i| {
            let x = i as f64;
            Seg {
                start_deg: x,
                width_deg: 1.0,
                power_w: scale * (1.0 + 0.5 * (x.to_radians() * 3.0).sin()),
                spin_start_rad_s: 62.8 + 10.0 * (x.to_radians()).cos(),
                spin_end_rad_s: 62.8 + 10.0 * ((x + 1.0).to_radians()).cos(),
            }
        })
        .collect()
}

/// p50 and p99 of `n` runs, s: `[cpu p50, cpu p99, wall p50, wall p99]`
/// (thread CPU time and wall time of each run).
fn percentiles(n: usize, mut f: impl FnMut()) -> [f64; 4] {
    for _ in 0..n.min(20) {
        f();
    }
    let (mut cpu, mut wall): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|_| {
            let (s, c) = (Instant::now(), thread_cpu_s());
            f();
            (thread_cpu_s() - c, s.elapsed().as_secs_f64())
        })
        .unzip();
    cpu.sort_by(f64::total_cmp);
    wall.sort_by(f64::total_cmp);
    let (m, q) = (n / 2, (n * 99 / 100).min(n - 1));
    [cpu[m], cpu[q], wall[m], wall[q]]
}

/// The profile scaled to certify under `params` (the largest uniform scale).
fn certified(params: &EyeSafetyParams, f_p: f64) -> (Vec<Seg>, f64) {
    let r = evaluate_segments(&profile(1.0), params, f_p).unwrap();
    let segs = profile(power_scale_to_certify(r.worst_ratio));
    let cert = evaluate_segments(&segs, params, f_p).unwrap();
    assert!(cert.worst_ratio <= 1.0, "the profile certifies");
    (segs, r.worst_ratio)
}

/// Gaze samples at 200 Hz: fixations of 0.4 s at three directions, small
/// jitter (the trace of `benches/gaze.rs`), `n` of them.
fn gaze_trace(n: usize) -> Vec<GazeSample> {
    (0..n)
        .map(|k| {
            let g = 90.0 + 40.0 * ((k / 80) % 3) as f64 + 0.02 * (k % 5) as f64;
            GazeSample {
                t_s: k as f64 / 200.0,
                gaze_deg: g,
                valid: true,
            }
        })
        .collect()
}

/// Thread CPU time of every `push` that produced a frame (one sample in
/// ten plans and certifies a profile), over `n` samples: `[p50, p99]`, s.
fn frame_cpu<P: gaze_lidar::gaze::FramePlanner>(planner: P, n: usize) -> [f64; 2] {
    let mut s = GazeStream::new(planner, FilterConfig::default(), FailSafeConfig::default());
    let mut cpu = Vec::new();
    for x in gaze_trace(n) {
        let c = thread_cpu_s();
        let frames = s.push(&x).unwrap();
        let dt = thread_cpu_s() - c;
        if !frames.is_empty() {
            cpu.push(dt);
        }
        black_box(frames);
    }
    cpu.sort_by(f64::total_cmp);
    let q = (cpu.len() * 99 / 100).min(cpu.len() - 1);
    [cpu[cpu.len() / 2], cpu[q]]
}

/// The single-channel targets (see the module doc). `GAZE_LIDAR_HEAD_BENCH_BIG`
/// sets the runs of the 10⁶-bin check (default 3 under `cargo bench`, 0 as
/// the smoke test of `cargo test --all-targets`).
fn single_channel_targets(n: usize) {
    let us = |x: f64| x * 1e6;
    let cf = ClosedFormPlanner {
        preset: presets::paper(),
        mode: Mode::Joint,
        bins: 360,
    };
    let samples = 10 * n.max(400);
    let [p50, p99] = frame_cpu(cf, samples);
    println!(
        "single channel: gaze -> certified, closed form (paper, joint, 360 bins; {} frames): \
         CPU p50 {:.1} µs p99 {:.1} µs",
        samples / 10,
        us(p50),
        us(p99)
    );
    #[cfg(feature = "solver")]
    {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/examples/configs/multi_level.toml"
        );
        let problem = gaze_lidar::optimizer::OptimizerConfig::read(std::path::Path::new(path))
            .unwrap()
            .problem()
            .unwrap();
        let mut planner = gaze_lidar::gaze::OptimizerPlanner::new(problem).unwrap();
        for x in gaze_trace(samples).iter().step_by(10) {
            use gaze_lidar::gaze::FramePlanner;
            planner.plan(Some(x.gaze_deg)).unwrap();
        }
        let [p50, p99] = frame_cpu(planner, samples);
        println!(
            "single channel: gaze -> certified, optimizer fast path (multi_level, cache warm): \
             CPU p50 {:.1} µs p99 {:.1} µs",
            us(p50),
            us(p99)
        );
    }
    let runs: usize = std::env::var("GAZE_LIDAR_HEAD_BENCH_BIG")
        .map(|v| v.parse().expect("a run count"))
        .unwrap_or(if std::env::args().any(|a| a == "--bench") {
            3
        } else {
            0
        });
    if runs > 0 {
        let p = big_profile::big_profile(1_000_000, big_profile::Roughness::Rough);
        let mut cpu: Vec<f64> = (0..runs)
            .map(|_| {
                let c = thread_cpu_s();
                assert!(
                    check(black_box(&p)).is_empty(),
                    "the 10^6-bin profile certifies"
                );
                thread_cpu_s() - c
            })
            .collect();
        cpu.sort_by(f64::total_cmp);
        println!(
            "single channel: check (library) of the 10^6-bin rough profile ({runs} runs): \
             CPU min {:.3} s median {:.3} s",
            cpu[0],
            cpu[runs / 2]
        );
    }
}

/// `GAZE_LIDAR_HEAD_BENCH_ONLY`, split: the preset and which evaluation.
fn only() -> Option<(String, String)> {
    let v = std::env::var("GAZE_LIDAR_HEAD_BENCH_ONLY").ok()?;
    let (name, which) = v.split_once('/').expect("PRESET/WHICH");
    assert!(which == "head" || which == "one", "WHICH is head or one");
    Some((name.to_owned(), which.to_owned()))
}

fn bench(c: &mut Criterion) {
    let (n, criterion) = samples();
    if let Some((name, which)) = only() {
        let p = preset(&name).unwrap();
        let f_p = p.lidar.pulse_rate_hz;
        let mut params = p.lidar.limits.eye_safety.clone().unwrap();
        if which == "one" {
            params.head = None;
        }
        let (segs, _) = certified(&params, f_p);
        let [p50, p99, _, _] = percentiles(n, || {
            black_box(evaluate_segments(black_box(&segs), &params, f_p).unwrap());
        });
        println!(
            "{name}/{which} ({n} runs): CPU p50 {:.1} µs p99 {:.1} µs",
            p50 * 1e6,
            p99 * 1e6
        );
        return;
    }
    single_channel_targets(n);
    let mut g = c.benchmark_group("head");
    for name in ["vls128", "os1-128", "vlp16"] {
        let p = preset(name).unwrap();
        let f_p = p.lidar.pulse_rate_hz;
        let hp = p.lidar.limits.eye_safety.clone().unwrap();
        let single = EyeSafetyParams {
            head: None,
            ..hp.clone()
        };
        let (segs_single, r_single) = certified(&single, f_p);
        let (segs, r_head) = certified(&hp, f_p);
        let one = percentiles(n, || {
            black_box(evaluate_segments(black_box(&segs_single), &single, f_p).unwrap());
        });
        let head = percentiles(n, || {
            black_box(evaluate_segments(black_box(&segs), &hp, f_p).unwrap());
        });
        let channels = hp.head.as_ref().unwrap().channels.len();
        let us = |x: f64| x * 1e6;
        println!(
            "{name} ({n} runs each): one channel CPU p50 {:.1} µs p99 {:.1} µs (wall p50 {:.1} p99 {:.1}); \
             {channels}-channel head CPU p50 {:.1} µs p99 {:.1} µs (wall p50 {:.1} p99 {:.1}); \
             head/one p99 CPU {:.2}×, wall {:.2}×; head/single eye-safety ratio {:.2}",
            us(one[0]),
            us(one[1]),
            us(one[2]),
            us(one[3]),
            us(head[0]),
            us(head[1]),
            us(head[2]),
            us(head[3]),
            head[1] / one[1],
            head[3] / one[3],
            r_head / r_single
        );
        if !criterion {
            continue;
        }
        g.bench_function(format!("{name}_single_channel_360_bins"), |b| {
            b.iter(|| evaluate_segments(black_box(&segs_single), &single, f_p).unwrap())
        });
        g.bench_function(format!("{name}_head_360_bins"), |b| {
            b.iter(|| evaluate_segments(black_box(&segs), &hp, f_p).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
