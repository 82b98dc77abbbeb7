//! `replay` throughput: 2 s of a 128-channel drive at 10 Hz (230,400
//! points per cloud, 2.3 M points/s; gaze at 100 Hz) replayed with the
//! `vls128` preset's range control, against a baseline in the same run:
//! the same bag copied through the mcap reader and writer alone. Prints
//! the real-time factor (seconds of drive per second of replay, one core).
//! Run: `cargo bench --bench replay`.

#[path = "common/bag.rs"]
mod bag;

use std::io::Cursor;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use gaze_lidar::gaze::ClosedFormPlanner;
use gaze_lidar::model::presets;
use gaze_lidar::planner::Mode;
use gaze_lidar::replay::{replay, Compression, PipelineConfig, ReplayOptions};

const SECONDS: u64 = 2;

fn run(input: &[u8], compression: Compression) -> Vec<u8> {
    let preset = presets::vls128();
    let mut opts = ReplayOptions::new("/dms/gaze", "/lidar/points", preset.lidar.rated_range_m);
    opts.compression = compression;
    let planner = ClosedFormPlanner {
        preset,
        mode: Mode::Range,
        bins: 360,
    };
    let mut out = Cursor::new(Vec::with_capacity(input.len() * 2));
    replay(
        input,
        "bench",
        &mut out,
        planner,
        PipelineConfig::default(),
        &opts,
    )
    .unwrap();
    out.into_inner()
}

/// Baseline: every message read and written back, nothing else.
fn copy(input: &[u8]) -> Vec<u8> {
    let mut out = Cursor::new(Vec::with_capacity(input.len()));
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .create(&mut out)
        .unwrap();
    for m in mcap::MessageStream::new(input).unwrap() {
        w.write(&m.unwrap()).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    out.into_inner()
}

fn bench(c: &mut Criterion) {
    let mut input = Cursor::new(Vec::new());
    bag::write_bag(&mut input, SECONDS).unwrap();
    let input = input.into_inner();
    let mut g = c.benchmark_group("replay");
    g.sample_size(10);
    g.bench_function("copy_only_2s", |b| b.iter(|| copy(&input)));
    g.bench_function("replay_2s_uncompressed", |b| {
        b.iter(|| run(&input, Compression::None))
    });
    g.bench_function("replay_2s_lz4", |b| {
        b.iter(|| run(&input, Compression::Lz4))
    });
    g.finish();
    // The real-time factor, best of 5.
    for (name, compression) in [
        ("uncompressed", Compression::None),
        ("lz4", Compression::Lz4),
    ] {
        let best = (0..5)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(run(&input, compression));
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min);
        let copy_s = (0..5)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(copy(&input));
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min);
        println!(
            "replay ({name} output): {SECONDS} s of drive ({} points) in {best:.3} s = {:.1}× real time; copy alone {copy_s:.3} s (replay/copy = {:.2})",
            SECONDS * 10 * bag::POINTS as u64,
            SECONDS as f64 / best,
            best / copy_s
        );
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
