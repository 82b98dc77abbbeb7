//! Optimizer cost: closed form, fresh LP, MILP and the fast path at N = 360
//! and 1440 bins (`MAX_OPTIMIZER_BINS`; 3600 is refused since the cap); the fast path's speed-up over a fresh HiGHS solve is
//! measured in the same run, and its p50/p99 latency (gaze sample →
//! certified profile, cache warm) is printed from 2000 samples.
//! The shipped configs (`examples/configs/`) at 360 bins, gaze 90°, under
//! both objectives (`shipped_C/sqrt`, `shipped_C/detection`).
//! The detection value's sampling, cold, on 360 bins of a smooth spin
//! (`detection_ranges/along`: each bin's ranges guessed along its own
//! nodes; `detection_ranges/across`: from the previous bin's ranges).
//! Run: `cargo bench --bench optimizer`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;
use std::time::Instant;

use gaze_lidar::model::presets;
use gaze_lidar::optimizer::fast::FastPlanner;
use gaze_lidar::optimizer::{optimize, ObjectiveKind, OptimizerConfig, Problem};
use gaze_lidar::planner::{closed_form, Mode};

fn continuous(n: usize) -> Problem {
    let text = "[lidar]\npreset = \"paper\"\npower_accounting = \"time\"\n[focus]\nthreshold = 0.0831\nacuity = { model = \"levi_e2\", e2_deg = 2.72 }\n[objective]\nmode = \"joint\"\n";
    let mut p = OptimizerConfig::from_toml(text, "bench")
        .unwrap()
        .problem()
        .unwrap();
    p.bins = n;
    p
}

fn milp(n: usize) -> Problem {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/configs/multi_level.toml"
    );
    let mut p = OptimizerConfig::read(std::path::Path::new(path))
        .unwrap()
        .problem()
        .unwrap();
    p.bins = n;
    p
}

/// The shipped config `name` (`examples/configs/`) at 360 bins with the
/// power step's value `kind`.
fn shipped(name: &str, kind: ObjectiveKind) -> Problem {
    let path = format!(
        "{}/examples/configs/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut p = OptimizerConfig::read(std::path::Path::new(&path))
        .unwrap()
        .problem()
        .unwrap();
    p.objective.kind = kind;
    p
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

fn latency_report() {
    // The latency trace warms one fresh solve per phase it meets (21), so
    // it stays at 360 bins.
    for n in [360usize] {
        let problem = continuous(n);
        let mut fast = FastPlanner::new(problem.clone());
        // A gaze trace: fixations with small jitter, some saccades; warm the cache.
        let trace: Vec<f64> = (0..2000)
            .map(|k| 90.0 + 40.0 * ((k / 80) % 3) as f64 + (k % 7) as f64 * 0.01)
            .collect();
        for g in &trace {
            fast.plan(*g).unwrap();
        }
        let mut us: Vec<f64> = trace
            .iter()
            .map(|g| {
                let t = Instant::now();
                black_box(fast.plan(*g).unwrap());
                t.elapsed().as_secs_f64() * 1e6
            })
            .collect();
        us.sort_by(f64::total_cmp);
        let t = Instant::now();
        black_box(optimize(&problem, 91.3).unwrap());
        let fresh_us = t.elapsed().as_secs_f64() * 1e6;
        eprintln!(
            "fast path N={n}: p50 {:.1} µs, p99 {:.1} µs (incl. certification); one fresh joint solve {:.0} µs; speed-up at p50 ≈ {:.0}×",
            percentile(&us, 0.5),
            percentile(&us, 0.99),
            fresh_us,
            fresh_us / percentile(&us, 0.5)
        );
    }
}

fn bench(c: &mut Criterion) {
    // Only under `cargo bench` (criterion's test mode, from `cargo test
    // --all-targets`, runs each benchmark once and should stay quick).
    if std::env::args().any(|a| a == "--bench") {
        latency_report();
    }
    let mut g = c.benchmark_group("optimizer");
    g.sample_size(10);
    let sizes: &[usize] = if std::env::args().any(|a| a == "--bench") {
        &[360, 1440]
    } else {
        &[360]
    };
    for &n in sizes {
        let paper = presets::paper();
        g.bench_with_input(BenchmarkId::new("closed_form_joint", n), &n, |b, &n| {
            b.iter(|| closed_form(&paper, Mode::Joint, Some(black_box(91.3)), n).unwrap())
        });
        let mut range_lp = continuous(n);
        range_lp.objective.mode = Mode::Range;
        g.bench_with_input(BenchmarkId::new("fresh_lp_range", n), &range_lp, |b, p| {
            b.iter(|| optimize(p, black_box(91.3)).unwrap())
        });
        let joint = continuous(n);
        g.bench_with_input(BenchmarkId::new("fresh_lp_joint", n), &joint, |b, p| {
            b.iter(|| optimize(p, black_box(91.3)).unwrap())
        });
        let m = milp(n);
        g.bench_with_input(BenchmarkId::new("fresh_milp_range", n), &m, |b, p| {
            b.iter(|| optimize(p, black_box(91.3)).unwrap())
        });
        let mut fast = FastPlanner::new(joint.clone());
        fast.plan(91.3).unwrap();
        g.bench_with_input(BenchmarkId::new("fast_path_joint", n), &n, |b, _| {
            b.iter(|| fast.plan(black_box(91.3 + 2.0)).unwrap())
        });
    }
    // The shipped configs under both objectives at gaze 90° (one solve:
    // the power step's segment cache is warm after the first iteration, so
    // the detection value's sampling is paid only there; the whole process,
    // cold, is `scripts/bench-profile.sh`).
    for name in ["paper", "multi_level", "vls128_eye", "smooth"] {
        for (kind, tag) in [
            (ObjectiveKind::Sqrt, "sqrt"),
            (ObjectiveKind::Detection, "detection"),
        ] {
            let p = shipped(name, kind);
            g.bench_with_input(
                BenchmarkId::new(format!("shipped_{name}"), tag),
                &p,
                |b, p| b.iter(|| optimize(p, black_box(90.0)).unwrap()),
            );
        }
    }
    g.finish();
    detection_ranges(c);
}

/// The power step's detection samples of 360 bins whose dwell ramps by
/// ±30 % around the frame's mean (a smooth spin), cold: every bin's 65
/// nodes under each condition, guessed along the nodes or across bins.
fn detection_ranges(c: &mut Criterion) {
    use gaze_lidar::optimizer::detection::{nodes, values_near};
    let p = shipped("smooth", ObjectiveKind::Detection);
    let theta = std::f64::consts::TAU / 360.0;
    let spacing: Vec<f64> = (0..360)
        .map(|i| {
            let ramp = 1.0 + 0.3 * (std::f64::consts::TAU * i as f64 / 360.0).sin();
            theta / (p.lidar.pulse_rate_hz * ramp * p.lidar.frame_period_s() / 360.0)
        })
        .collect();
    let hi = p.lidar.limits.power_w_max / p.lidar.average_power_w;
    let xs = nodes(p.lidar.limits.power_w_min / p.lidar.average_power_w, hi);
    let mut g = c.benchmark_group("detection_ranges");
    g.sample_size(10);
    g.bench_function("along", |b| {
        b.iter(|| {
            for &s in &spacing {
                black_box(values_near(&p, s, &xs, None));
            }
        })
    });
    g.bench_function("across", |b| {
        b.iter(|| {
            let mut near: Option<Vec<Vec<f64>>> = None;
            for &s in &spacing {
                near = Some(values_near(&p, s, &xs, near.as_deref()).1);
            }
            black_box(near)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
