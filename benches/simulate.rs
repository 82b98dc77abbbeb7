//! Simulator throughput: rays per second for one trial in both geometries
//! (planar: one channel; carla: all 64 channels over the road), and the
//! full paper grid (2 models × 4 variants × 3 fog levels) at 10 trials per
//! cell (planar) and 2 per cell (carla, the paper's pipeline), with culling
//! (carla: the fast path) against the brute-force reference measured in the
//! same run.
//!
//! The carla grid at 2 trials per cell is 1/50 of the paper's 100: trials
//! are independent draws of the same distribution run in parallel, so the
//! full grid takes about 50 × as long; the run prints that extrapolation and
//! the brute-force ratio (best of three timings each, outside criterion).
//! The planar grid of `simulate --trials 100` (2 × 4 × 3 × 100 trials) is
//! timed with its shared casts against every cell cast alone (the code
//! before them), best of three each, ratio printed.
//! Run: `cargo bench --bench simulate`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::time::{Duration, Instant};

use gaze_lidar::sim::{self, Arrival, Detector, Geometry, ModelKind, SimConfig};

fn bench(c: &mut Criterion) {
    let one = |brute_force| SimConfig {
        models: vec![ModelKind::Physical],
        variants: vec![gaze_lidar::sim::Variant::Joint],
        fog_pcts: vec![25],
        trials: 1,
        brute_force,
        ..SimConfig::default()
    };
    // Pulses of one trial, for the throughput figure.
    let r = sim::run(&one(false), &|| {}).unwrap();
    let pulses = (r.trials[0].outcome.duration_s * 7812.5) as u64;
    let mut g = c.benchmark_group("trial");
    g.throughput(Throughput::Elements(pulses));
    g.bench_function("culled", |b| {
        b.iter(|| sim::run(black_box(&one(false)), &|| {}).unwrap())
    });
    g.bench_function("brute_force", |b| {
        b.iter(|| sim::run(black_box(&one(true)), &|| {}).unwrap())
    });
    g.finish();
    let mut g = c.benchmark_group("paper_grid");
    g.sample_size(10);
    let grid = SimConfig {
        trials: 10,
        ..SimConfig::default()
    };
    g.bench_function("2x4x3x10", |b| {
        b.iter(|| sim::run(black_box(&grid), &|| {}).unwrap())
    });
    g.finish();

    // The planar grid of `simulate --trials 100` (2,400 trials): cells that
    // share a timeline cast together, against every cell cast alone (the
    // code before the shared casts, kept as the reference path).
    let planar = |per_cell| SimConfig {
        per_cell,
        ..SimConfig::default()
    };
    let mut g = c.benchmark_group("planar_grid");
    g.sample_size(10);
    g.bench_function("2x4x3x100_shared", |b| {
        b.iter(|| sim::run(black_box(&planar(false)), &|| {}).unwrap())
    });
    g.bench_function("2x4x3x100_per_cell", |b| {
        b.iter(|| sim::run(black_box(&planar(true)), &|| {}).unwrap())
    });
    g.finish();
    let best_of_3 = |config: &SimConfig| -> Duration {
        (0..3)
            .map(|_| {
                let t = Instant::now();
                black_box(sim::run(config, &|| {}).unwrap());
                t.elapsed()
            })
            .min()
            .unwrap_or_default()
    };
    // Timed only under `cargo bench` (criterion's test mode runs each
    // benchmark once and skips this).
    let benching = std::env::args().any(|a| a == "--bench");
    if benching {
        let (shared, alone) = (best_of_3(&planar(false)), best_of_3(&planar(true)));
        eprintln!(
            "planar_grid 2x4x3x100 ({} threads): shared casts {:.2} s, per cell {:.2} s, \
             per-cell/shared {:.2}x",
            rayon::current_num_threads(),
            shared.as_secs_f64(),
            alone.as_secs_f64(),
            alone.as_secs_f64() / shared.as_secs_f64(),
        );
    }

    // The carla geometry: one trial of the paper's pipeline, rays = pulses × channels.
    let carla = |brute_force| SimConfig {
        models: vec![ModelKind::Argus],
        variants: vec![gaze_lidar::sim::Variant::Baseline],
        fog_pcts: vec![0],
        trials: 1,
        brute_force,
        geometry: Geometry::Carla,
        detector: Detector::Argus,
        arrival: Arrival::ArgusCentre,
        ..SimConfig::default()
    };
    let r = sim::run(&carla(false), &|| {}).unwrap();
    let o = &r.trials[0].outcome;
    let rays = (o.duration_s * 7812.5) as u64 * u64::from(o.channels_simulated);
    let mut g = c.benchmark_group("carla_trial");
    g.sample_size(10);
    g.throughput(Throughput::Elements(rays));
    g.bench_function("culled", |b| {
        b.iter(|| sim::run(black_box(&carla(false)), &|| {}).unwrap())
    });
    g.bench_function("brute_force", |b| {
        b.iter(|| sim::run(black_box(&carla(true)), &|| {}).unwrap())
    });
    g.finish();
    let mut g = c.benchmark_group("carla_grid");
    g.sample_size(10);
    let grid = |brute_force| SimConfig {
        trials: 2,
        geometry: Geometry::Carla,
        detector: Detector::Argus,
        arrival: Arrival::ArgusCentre,
        brute_force,
        ..SimConfig::default()
    };
    g.bench_function("2x4x3x2", |b| {
        b.iter(|| sim::run(black_box(&grid(false)), &|| {}).unwrap())
    });
    g.bench_function("2x4x3x2_brute_force", |b| {
        b.iter(|| sim::run(black_box(&grid(true)), &|| {}).unwrap())
    });
    g.finish();
    let (fast, slow) = (best_of_3(&grid(false)), best_of_3(&grid(true)));
    let threads = rayon::current_num_threads();
    eprintln!(
        "carla_grid 2x4x3x2 ({threads} threads): fast path {:.2} s, brute force {:.2} s, \
         brute/fast {:.1}x; the paper's grid (100 trials per cell, 50x) extrapolates to \
         {:.0} s fast, {:.0} s brute force",
        fast.as_secs_f64(),
        slow.as_secs_f64(),
        slow.as_secs_f64() / fast.as_secs_f64(),
        50.0 * fast.as_secs_f64(),
        50.0 * slow.as_secs_f64(),
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
