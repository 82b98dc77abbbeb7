//! The head's bound: `evaluate_segments` on a 360-bin profile with the
//! 128-channel heads of the `vls128` and `os1-128` presets (and `vlp16`'s 16
//! channels), each against the same profile as one channel (the preset's
//! eye-safety parameters without the head: today's single-channel code path)
//! in the same run. Prints p50/p99 of plain timed runs ([`SAMPLES`] each) and
//! the p99 ratios, then the criterion figures. Run: `cargo bench --bench head`.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::time::Instant;

use gaze_lidar::eye_safety::bound::Seg;
use gaze_lidar::eye_safety::head::power_scale_to_certify;
use gaze_lidar::eye_safety::{evaluate_segments, EyeSafetyParams};
use gaze_lidar::model::presets::preset;

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

fn bench(c: &mut Criterion) {
    let (n, criterion) = samples();
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
