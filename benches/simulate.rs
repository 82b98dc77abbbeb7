//! Simulator throughput: rays per second for one trial in both geometries
//! (planar: one channel; carla: all 64 channels over the road), and the
//! full paper grid (2 models × 4 variants × 3 fog levels) at 10 trials per
//! cell (planar) and 2 per cell (carla, the paper's pipeline), with culling
//! against the brute-force reference measured in the same run.
//! Run: `cargo bench --bench simulate`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;

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
    let grid = SimConfig {
        trials: 2,
        geometry: Geometry::Carla,
        detector: Detector::Argus,
        arrival: Arrival::ArgusCentre,
        ..SimConfig::default()
    };
    g.bench_function("2x4x3x2", |b| {
        b.iter(|| sim::run(black_box(&grid), &|| {}).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
