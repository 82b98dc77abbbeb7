//! The firmware table's eye-safety check at N = 360, 3600 and 36,000 bins:
//! the integer check (`check_table`: integer rules, limits derived from the
//! model, integer evaluation) against the float bound evaluated on the same
//! table as it runs (`table_exposure`, the baseline in the same run).
//! Run: `cargo bench --bench firmware`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::hint::black_box;

use gaze_lidar::firmware::eye::{evaluate, IntEyeLimits};
use gaze_lidar::firmware::{check_table, table_exposure, FirmwareConfig, FirmwareTable};
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};

fn bench(c: &mut Criterion) {
    let preset = presets::paper();
    let mut g = c.benchmark_group("firmware_eye_safety");
    g.sample_size(10);
    for n in [360usize, 3600, 36_000] {
        let certified = closed_form(&preset, Mode::Joint, Some(90.0), n).unwrap();
        let table = FirmwareTable::from_certified(&certified, &FirmwareConfig::default()).unwrap();
        let limits = IntEyeLimits::derive(&table).unwrap();
        g.bench_with_input(
            BenchmarkId::new("float_table_exposure", n),
            &table,
            |b, t| b.iter(|| table_exposure(black_box(t)).unwrap().unwrap()),
        );
        g.bench_with_input(
            BenchmarkId::new("integer_check_table", n),
            &table,
            |b, t| b.iter(|| check_table(black_box(t))),
        );
        g.bench_with_input(
            BenchmarkId::new("integer_evaluate_only", n),
            &table,
            |b, t| b.iter(|| evaluate(black_box(t), &limits).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
