//! `replay` throughput: 2 s of a 128-channel drive at 10 Hz (230,400
//! points per cloud, 2.3 M points/s; gaze at 100 Hz) replayed with the
//! `vls128` preset's range control, against a baseline in the same run:
//! the same bag copied through the mcap reader and writer alone. Prints
//! the real-time factor (seconds of drive per second of replay) on the
//! wall clock and on the process's CPU time (user + system, from
//! `/proc/self/stat`: the one-core figure, meaningful on a loaded machine;
//! the replay is single-threaded), and the output's size; then the size
//! of the uncompressed output rewritten with zstd at its default level
//! (3) against the level replay writes ([`ZSTD_LEVEL`]).
//! Run: `cargo bench --bench replay`.

#[path = "common/bag.rs"]
mod bag;

use std::io::Cursor;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use gaze_lidar::model::presets;
use gaze_lidar::pipeline::ClosedFormPlanner;
use gaze_lidar::planner::Mode;
use gaze_lidar::replay::{replay, Compression, PipelineConfig, ReplayOptions, ZSTD_LEVEL};

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
    copy_as(input, None, 0)
}

/// Every message read and written back with this compression and level.
fn copy_as(input: &[u8], compression: Option<mcap::Compression>, level: u32) -> Vec<u8> {
    let mut out = Cursor::new(Vec::with_capacity(input.len()));
    let mut w = mcap::WriteOptions::new()
        .compression(compression)
        .compression_level(level)
        .compression_threads(0)
        .create(&mut out)
        .unwrap();
    for m in mcap::MessageStream::new(input).unwrap() {
        w.write(&m.unwrap()).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    out.into_inner()
}

/// This process's CPU time (user + system), s; 0 where `/proc` is absent.
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which ends with the last ')'):
    // utime and stime are the 12th and 13th, in clock ticks (100 per s).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
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
    g.bench_function("replay_2s_zstd", |b| {
        b.iter(|| run(&input, Compression::Zstd))
    });
    g.finish();
    // The real-time factor, best of 5.
    for (name, compression) in [
        ("uncompressed", Compression::None),
        ("lz4", Compression::Lz4),
        ("zstd", Compression::Zstd),
    ] {
        let mut best = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        let mut size = 0;
        for _ in 0..5 {
            let (t, c) = (Instant::now(), cpu_s());
            size = std::hint::black_box(run(&input, compression)).len();
            best = best.min(t.elapsed().as_secs_f64());
            best_cpu = best_cpu.min(cpu_s() - c);
        }
        let copy_s = (0..5)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(copy(&input));
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min);
        println!(
            "replay ({name} output): {SECONDS} s of drive ({} points) in {best:.3} s wall = {:.1}× real time, {best_cpu:.3} s CPU = {:.1}× real time on one core; copy alone {copy_s:.3} s wall (replay/copy = {:.2}); output {size} bytes",
            SECONDS * 10 * bag::POINTS as u64,
            SECONDS as f64 / best,
            SECONDS as f64 / best_cpu,
            best / copy_s
        );
    }
    // The size cost of the fast zstd level: the uncompressed output
    // rewritten at zstd's default level and at replay's.
    let plain = run(&input, Compression::None);
    let zstd = Some(mcap::Compression::Zstd);
    let (t3, d3) = (Instant::now(), copy_as(&plain, zstd, 3).len());
    let t3 = t3.elapsed().as_secs_f64();
    let (t1, d1) = (Instant::now(), copy_as(&plain, zstd, ZSTD_LEVEL).len());
    let t1 = t1.elapsed().as_secs_f64();
    println!(
        "zstd on the {} -byte output: level 3 {d3} bytes in {t3:.3} s, level {ZSTD_LEVEL} {d1} bytes in {t1:.3} s (size ×{:.3}, time ×{:.2})",
        plain.len(),
        d1 as f64 / d3 as f64,
        t1 / t3
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
