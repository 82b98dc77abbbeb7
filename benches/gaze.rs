//! Gaze sample → certified profile latency through the stream pipeline
//! (filter, fail-safe, planner, checker): p50/p99 over 4000 samples at
//! 200 Hz (one frame in ten samples plans a profile), closed form and the
//! optimizer's fast path. Run: `cargo bench --bench gaze`.

#[path = "common/planned.rs"]
mod planned;

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::time::Instant;

use gaze_lidar::checker::check;
use gaze_lidar::gaze::{FailSafeConfig, FilterConfig, GazeSample};
use gaze_lidar::model::presets;
use gaze_lidar::pipeline::{ClosedFormPlanner, FramePlanner, GazeStream};
use gaze_lidar::planner::Mode;
use planned::planned_profiles;

fn samples() -> Vec<GazeSample> {
    (0..4000)
        .map(|k| {
            let t = f64::from(k) / 200.0;
            // Fixations of 0.4 s at three directions, small jitter.
            let g = 90.0 + 40.0 * f64::from((k / 80) % 3) + 0.02 * f64::from(k % 5);
            GazeSample {
                t_s: t,
                gaze_deg: g,
                valid: true,
            }
        })
        .collect()
}

fn frame_latencies<P: FramePlanner>(planner: P) -> (f64, f64) {
    let mut s = GazeStream::new(planner, FilterConfig::default(), FailSafeConfig::default());
    let mut us = Vec::new();
    for x in samples() {
        let t = Instant::now();
        let frames = s.push(&x).unwrap();
        let dt = t.elapsed().as_secs_f64() * 1e6;
        if !frames.is_empty() {
            us.push(dt);
        }
        black_box(frames);
    }
    us.sort_by(f64::total_cmp);
    (us[us.len() / 2], us[(us.len() as f64 * 0.99) as usize])
}

/// The checker alone (`check`: structure, limits and the eye-safety bound)
/// on the closed-form planner's 360-bin profile for each gaze of the
/// trace's three fixations: p50/p99 over `reps` calls, µs. Separates the
/// checker's time from the stream's and from scheduling noise.
/// With `distinct`, no two bins alike (see `common/planned.rs`).
fn checker_latencies(reps: usize, distinct: bool) -> (f64, f64) {
    let profiles = planned_profiles(distinct);
    let mut us = Vec::with_capacity(reps);
    for k in 0..reps {
        let p = &profiles[k % profiles.len()];
        let t = Instant::now();
        let v = check(black_box(p));
        us.push(t.elapsed().as_secs_f64() * 1e6);
        assert!(v.is_empty(), "the planned profile certifies");
    }
    us.sort_by(f64::total_cmp);
    (us[us.len() / 2], us[(us.len() as f64 * 0.99) as usize])
}

fn bench(c: &mut Criterion) {
    let cf = ClosedFormPlanner {
        preset: presets::paper(),
        mode: Mode::Joint,
        bins: 360,
    };
    let (p50, p99) = frame_latencies(cf.clone());
    eprintln!(
        "gaze → certified profile, closed form (joint, 360 bins): p50 {p50:.1} µs, p99 {p99:.1} µs"
    );
    let (p50, p99) = checker_latencies(3000, false);
    eprintln!(
        "checker alone on the planned profile (joint, 360 bins): p50 {p50:.1} µs, p99 {p99:.1} µs"
    );
    let (p50, p99) = checker_latencies(1000, true);
    eprintln!(
        "checker alone, the same with no two bins alike (nothing to merge): p50 {p50:.1} µs, p99 {p99:.1} µs"
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
        let mut planner = gaze_lidar::pipeline::OptimizerPlanner::new(problem).unwrap();
        // Warm the cache over the phases the trace uses.
        for x in samples().iter().step_by(10) {
            planner.plan(Some(x.gaze_deg)).unwrap();
        }
        let (p50, p99) = frame_latencies(planner);
        eprintln!("gaze → certified profile, optimizer fast path (multi_level, cache warm): p50 {p50:.1} µs, p99 {p99:.1} µs");
    }
    let mut g = c.benchmark_group("gaze");
    let trace = samples();
    g.bench_function("stream_2s_closed_form", |b| {
        b.iter(|| {
            let mut s = GazeStream::new(
                cf.clone(),
                FilterConfig::default(),
                FailSafeConfig::default(),
            );
            for x in &trace[..400] {
                black_box(s.push(x).unwrap());
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
