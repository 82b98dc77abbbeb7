//! Closed-form planning, certification and eye-safety evaluation at N = 360
//! and 3600 bins. Run: `cargo bench --bench profiles`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

use gaze_lidar::checker::certify;
use gaze_lidar::eye_safety::evaluate_profile;
use gaze_lidar::model::presets;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::{closed_form, Mode};

fn bench(c: &mut Criterion) {
    let preset = presets::paper();
    let mut g = c.benchmark_group("closed_form");
    for n in [360usize, 3600] {
        let uncertified = build_profile(&preset, Mode::Joint, Some(90.0), n).unwrap();
        let params = uncertified.limits.eye_safety.clone().unwrap();
        g.bench_with_input(BenchmarkId::new("build_only", n), &n, |b, &n| {
            b.iter(|| build_profile(&preset, Mode::Joint, Some(black_box(90.0)), n).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("build_and_certify", n), &n, |b, &n| {
            b.iter(|| closed_form(&preset, Mode::Joint, Some(black_box(90.0)), n).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("certify", n), &uncertified, |b, p| {
            b.iter(|| certify(black_box(p.clone())).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("eye_safety", n), &uncertified, |b, p| {
            b.iter(|| evaluate_profile(black_box(p), &params).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
