//! The head's bound: `evaluate_segments` on a 360-bin profile with a
//! 128-channel head (an OS1-128-like column head: every channel fired
//! together, four azimuth columns; and a VLS-128-like head: sixteen groups
//! of eight), against the same profile as one channel (today's code path)
//! in the same run. Prints p50/p99 of plain timed runs and the ratios, then
//! the criterion figures. Run: `cargo bench --bench head`.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::time::Instant;

use gaze_lidar::eye_safety::bound::Seg;
use gaze_lidar::eye_safety::head::{power_scale_to_certify, Channel, Head};
use gaze_lidar::eye_safety::{evaluate_segments, EyeSafetyParams};

const F_P: f64 = 18_761.726_078_799_25; // 1 / 53.3 µs

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

fn head(kind: &str) -> Head {
    let cycle = 1.0 / F_P;
    let channels = (0..128u32)
        .map(|i| {
            let (az, slot) = match kind {
                "column" => ([-3.0, -1.0, 1.0, 3.0][(i % 4) as usize], 0.0),
                _ => (
                    [-4.5, -3.3, -2.0, -0.7, 0.7, 2.0, 3.3, 4.5][(i % 8) as usize] * 0.5,
                    (i / 8) as f64 * 2.665e-6,
                ),
            };
            Channel {
                id: i,
                elevation_deg: -22.5 + 0.35 * f64::from(i),
                azimuth_offset_deg: az,
                slot_s: slot,
                power_scale: 1.0,
            }
        })
        .collect();
    Head {
        cycle_s: cycle,
        origin_radius_mm: if kind == "column" { 15.806 } else { 58.63 },
        origin_height_mm: 0.0,
        exit_diameter_mm: if kind == "column" { 10.0 } else { 5.0 },
        divergence_mrad: 3.0,
        aperture_distance_mm: 100.0,
        channels,
    }
}

fn params(head: Option<Head>) -> EyeSafetyParams {
    EyeSafetyParams {
        wavelength_nm: 905.0,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: 5.0,
        head,
    }
}

fn percentiles(mut f: impl FnMut()) -> (f64, f64) {
    let mut t: Vec<f64> = (0..300)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    (t[150], t[296])
}

fn bench(c: &mut Criterion) {
    let single = params(None);
    let base = evaluate_segments(&profile(1.0), &single, F_P).unwrap();
    let segs_single = profile(power_scale_to_certify(base.worst_ratio));
    let (p50_s, p99_s) = percentiles(|| {
        black_box(evaluate_segments(black_box(&segs_single), &single, F_P).unwrap());
    });
    println!(
        "single channel: p50 {:.1} µs, p99 {:.1} µs",
        p50_s * 1e6,
        p99_s * 1e6
    );
    let mut g = c.benchmark_group("head");
    g.bench_function("single_channel_360_bins", |b| {
        b.iter(|| evaluate_segments(black_box(&segs_single), &single, F_P).unwrap())
    });
    for kind in ["column", "groups"] {
        let hp = params(Some(head(kind)));
        let r = evaluate_segments(&profile(1.0), &hp, F_P).unwrap();
        let segs = profile(power_scale_to_certify(r.worst_ratio));
        let cert = evaluate_segments(&segs, &hp, F_P).unwrap();
        assert!(cert.worst_ratio <= 1.0, "the {kind} head certifies");
        let (p50, p99) = percentiles(|| {
            black_box(evaluate_segments(black_box(&segs), &hp, F_P).unwrap());
        });
        println!(
            "128-channel {kind} head: p50 {:.1} µs, p99 {:.1} µs ({:.1}× the single channel's p99); head/single ratio {:.2}",
            p50 * 1e6,
            p99 * 1e6,
            p99 / p99_s,
            r.worst_ratio / base.worst_ratio
        );
        g.bench_function(format!("head128_{kind}_360_bins"), |b| {
            b.iter(|| evaluate_segments(black_box(&segs), &hp, F_P).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
