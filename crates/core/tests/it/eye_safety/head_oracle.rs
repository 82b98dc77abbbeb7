//! The head oracle (`tests/it/head_oracle_defs.rs`): a brute-force reference for
//! the eye safety of a whole multi-beam head, and its self-tests (each able
//! to fail). `HEAD_ORACLE_CASES` scales the random runs; `HEAD_ORACLE_SHAPES`
//! caps the fixed-shape runs (real heads, separated pairs) for quick nets
//! such as "The quick net for the bound and the head" of `specs/mutants.md`
//! (default: all of them).

use crate::head_oracle_defs;
use crate::reference_defs;

use gaze_lidar_core::eye_safety::exposure::{evaluate_segments_at_declared_distance, segments};
use gaze_lidar_core::eye_safety::head::{Channel, Head};
use gaze_lidar_core::profile::Profile;
use head_oracle_defs::{hit, Fast, OBin, OScan, Oracle, Pos, Train};
use reference_defs::{DBin, DScan, DefReference};
use serde_json::json;

fn channel(id: u32, elevation_deg: f64, azimuth_offset_deg: f64, slot_s: f64) -> Channel {
    Channel {
        id,
        elevation_deg,
        azimuth_offset_deg,
        slot_s,
        power_scale: 1.0,
    }
}

fn head(channels: Vec<Channel>, cycle_s: f64, origin_radius_mm: f64, exit_mm: f64) -> Head {
    let h = Head {
        cycle_s,
        origin_radius_mm,
        origin_height_mm: 0.0,
        exit_diameter_mm: exit_mm,
        divergence_mrad: 0.0,
        aperture_distance_mm: 100.0,
        channels,
    };
    h.validate().expect("a valid head");
    h
}

/// A 4-bin scan: a hot slow sector, an accelerating one, two plain ones.
fn scan(lambda_nm: f64, frame_hz: f64, p_w: f64) -> OScan {
    let w = std::f64::consts::TAU * frame_hz;
    OScan {
        bins: vec![
            OBin {
                start_deg: 0.0,
                width_deg: 30.0,
                power_w: 2.0 * p_w,
                w0: 0.5 * w,
                w1: 0.5 * w,
            },
            OBin {
                start_deg: 30.0,
                width_deg: 60.0,
                power_w: p_w,
                w0: 0.5 * w,
                w1: 1.5 * w,
            },
            OBin {
                start_deg: 90.0,
                width_deg: 180.0,
                power_w: 0.5 * p_w,
                w0: 1.5 * w,
                w1: 1.5 * w,
            },
            OBin {
                start_deg: 270.0,
                width_deg: 90.0,
                power_w: p_w,
                w0: w,
                w1: w,
            },
        ],
        lambda_nm,
        pulse_s: 5e-9,
    }
}

fn pos(azimuth_deg: f64, height_mm: f64) -> Pos {
    Pos {
        azimuth_deg,
        height_mm,
    }
}

fn one_train(o: &Oracle, p: Pos, t0: f64, horizon_s: f64) -> Train {
    let ivs = o.intervals(p.azimuth_deg, 0.05);
    o.train(p, t0, horizon_s, &ivs)
}

#[test]
fn forward_geometry_by_hand() {
    // Crossing point 40 mm out, aperture plane 100 mm out: 60 mm of ray.
    let h = head(vec![channel(0, 5.0, 0.0, 0.0)], 1e-5, 40.0, 2.0);
    let x = hit(&h, 0, 0.0, pos(0.0, 0.0), 7.0).unwrap();
    assert!((x.along_mm - 60.0 / 5f64.to_radians().cos()).abs() < 1e-9);
    assert!((x.height_mm - 60.0 * 5f64.to_radians().tan()).abs() < 1e-9);
    // 5.249 mm up: the 1 mm beam radius reaches the 3.5 mm disc at 4.5 mm.
    assert!(!x.overlaps);
    assert!(hit(&h, 0, 0.0, pos(0.0, 0.8), 7.0).unwrap().overlaps);
    assert!(!hit(&h, 0, 0.0, pos(0.0, 0.7), 7.0).unwrap().overlaps);
    // Head turned by δ: the ray from (40 cos δ, 40 sin δ) along δ meets the
    // plane x = 100 at y = 100 tan δ (it passes through the axis).
    let h0 = head(vec![channel(0, 0.0, 0.0, 0.0)], 1e-5, 40.0, 2.0);
    let d = 2.7f64.to_radians();
    let x = hit(&h0, 0, d, pos(0.0, 0.0), 7.0).unwrap();
    assert!((x.lateral_mm - 100.0 * d.tan()).abs() < 1e-9, "{x:?}");
    assert!(!x.overlaps); // 4.716 mm > 3.5 + 1
    assert!(
        hit(&h0, 0, 2.0f64.to_radians(), pos(0.0, 0.0), 7.0)
            .unwrap()
            .overlaps
    );
    // An azimuth offset with parallax: offset α, head at θ: the ray meets
    // x = 100 at y = 40 sin θ + (100 − 40 cos θ) tan(θ + α).
    let ha = head(vec![channel(0, 0.0, 10.0, 0.0)], 1e-5, 40.0, 2.0);
    let th = -6.0f64.to_radians();
    let x = hit(&ha, 0, th, pos(0.0, 0.0), 7.0).unwrap();
    let y = 40.0 * th.sin() + (100.0 - 40.0 * th.cos()) * (th + 10f64.to_radians()).tan();
    assert!((x.lateral_mm - y).abs() < 1e-9);
    // Where a channel passes: offset 10° from 40 mm out, head at 0°: the
    // ray (40, 0) + s (cos 10°, sin 10°) meets the 100 mm circle at
    // s = −40 cos 10° + √(1600 cos² 10° − 1600 + 10⁴).
    let oa = Oracle::new(&ha, &scan(905.0, 10.0, 1e-3));
    let c10 = 10f64.to_radians().cos();
    let s10 = -40.0 * c10 + (1600.0 * c10 * c10 - 1600.0 + 1e4).sqrt();
    let want = (s10 * 10f64.to_radians().sin())
        .atan2(40.0 + s10 * c10)
        .to_degrees();
    assert!((oa.pass_azimuth_deg(0, 0.0) - want).abs() < 1e-9);
    assert!((oa.pass_azimuth_deg(0, 30.0) - want - 30.0).abs() < 1e-9);
    // The beam centre is there: the ray meets that aperture on its axis.
    let x = hit(&ha, 0, 0.0, pos(want, 0.0), 7.0).unwrap();
    assert!(x.miss_mm < 1e-9, "{x:?}");
    // Divergence: 10 mrad over 60 mm adds 0.6 mm of diameter.
    let mut hd = h0.clone();
    hd.divergence_mrad = 10.0;
    // 4.79 mm off: beyond the bare 4.5 mm reach, inside the 5.0 mm one.
    let off: f64 = (3.5 + 1.0 + 0.29) / 100.0;
    assert!(
        hit(&hd, 0, off.atan(), pos(0.0, 0.0), 7.0)
            .unwrap()
            .overlaps
    );
    assert!(
        !hit(&h0, 0, off.atan(), pos(0.0, 0.0), 7.0)
            .unwrap()
            .overlaps
    );
}

/// The fast overlap test (trigonometry once per channel and aperture) is
/// [`hit`]'s, on random heads, positions and head angles.
#[test]
fn fast_hit_is_hit() {
    let mut r = Rng(77);
    let (mut yes, mut total) = (0usize, 0usize);
    for _ in 0..200 {
        let h = random_head(&mut r, 4);
        let p = pos(r.range(0.0, 360.0), r.range(-6.0, 6.0));
        for c in 0..h.channels.len() {
            let f = Fast::new(&h, c, p, 7.0);
            for _ in 0..200 {
                // Near the aperture half the time.
                let th = if r.unit() < 0.5 {
                    r.range(0.0, std::f64::consts::TAU)
                } else {
                    (p.azimuth_deg - h.channels[c].azimuth_offset_deg + r.range(-8.0, 8.0))
                        .to_radians()
                };
                let slow = hit(&h, c, th, p, 7.0).is_some_and(|x| x.overlaps);
                assert_eq!(f.overlaps(th), slow, "{h:?} {p:?} {th}");
                yes += usize::from(slow);
                total += 1;
            }
        }
    }
    assert!(yes > total / 20, "{yes} of {total}");
}

/// A 1-channel head on the axis (origin 0, elevation 0, no offset, no
/// divergence) is the single-channel model: the existing definitions
/// reference on the same profile gives the same worst ratio, to the
/// sampling tolerance (the arc `|θ − φ| ≤ h` against the plane's
/// `100·tan|θ − φ| ≤ 4.5 mm`, and the window grids).
#[test]
fn one_channel_head_is_the_single_channel_reference() {
    // (pulse rate, frame rate, power): the pulse rule binds in the first,
    // windows in the others.
    let mut configs = vec![(20_000.0, 10.0, 0.4e-3), (200_000.0, 20.0, 0.5e-3)];
    if long_run() {
        configs.push((500_000.0, 2.0, 0.4e-3));
    }
    for (fp, frame_hz, p_w) in configs {
        let sc = scan(905.0, frame_hz, p_w);
        let h = head(vec![channel(0, 0.0, 0.0, 0.0)], 1.0 / fp, 0.0, 2.0);
        let o = Oracle::new(&h, &sc);
        let ds = DScan {
            bins: sc
                .bins
                .iter()
                .map(|b| DBin {
                    start_deg: b.start_deg,
                    width_deg: b.width_deg,
                    power_w: b.power_w,
                    w0: b.w0,
                    w1: b.w1,
                })
                .collect(),
            pulse_rate_hz: fp,
            lambda_nm: 905.0,
            pulse_s: sc.pulse_s,
            beam_mm: 2.0,
        };
        let defs = DefReference::new(&ds);
        let phis = [15.0, 45.0, 29.0, 180.0, 300.0];
        let d = defs.worst(&phis, false, 3, 1);
        let positions: Vec<Pos> = phis.iter().map(|&p| pos(p, 0.0)).collect();
        let effort = head_oracle_defs::Effort {
            top_k: 5,
            ..Default::default()
        };
        let w = o.worst(&positions, &effort);
        println!("definitions reference {d}\nhead oracle           {w}");
        let rel = (w.ratio / d.ratio - 1.0).abs();
        assert!(
            rel < 0.03,
            "1-channel head {} vs single channel {}",
            w.ratio,
            d.ratio
        );
    }
}

#[test]
fn two_identical_channels_in_one_slot_double_every_pulse() {
    let sc = scan(905.0, 10.0, 4e-3);
    let one = head(vec![channel(0, 1.0, 2.0, 1e-6)], 5e-5, 40.0, 5.0);
    let mut two = one.clone();
    two.channels.push(Channel {
        id: 7,
        ..one.channels[0].clone()
    });
    let (o1, o2) = (Oracle::new(&one, &sc), Oracle::new(&two, &sc));
    for p in [pos(10.0, 1.0), pos(100.0, 0.0), pos(33.0, 3.0)] {
        let (a, b) = (one_train(&o1, p, 1e-5, 1.0), one_train(&o2, p, 1e-5, 1.0));
        assert!(!a.t.is_empty());
        assert_eq!(a.t, b.t);
        for (x, y) in a.e.iter().zip(&b.e) {
            assert_eq!(2.0 * x, *y);
        }
        // And the single-pulse rule sees the doubled pulse.
        let (wa, wb) = (o1.evaluate(&a, p, 1e-5, 50), o2.evaluate(&b, p, 1e-5, 50));
        assert!(wb.ratio >= 2.0 * wa.ratio * (1.0 - 1e-12) || wa.rule != "pulse");
    }
}

#[test]
fn beams_twenty_degrees_apart_never_meet_one_aperture_together() {
    let sc = scan(905.0, 10.0, 4e-3);
    let mut h = head(
        vec![channel(0, 0.0, -10.0, 0.0), channel(1, 0.0, 10.0, 0.0)],
        5e-5,
        40.0,
        5.0,
    );
    h.divergence_mrad = 3.0;
    let o = Oracle::new(&h, &sc);
    let alone: Vec<Oracle> = (0..2)
        .map(|k| {
            let mut hk = h.clone();
            hk.channels[1 - k].power_scale = 0.0;
            Oracle::new(&hk, &sc)
        })
        .collect();
    let mut met = 0;
    for az in (0..36).map(|k| k as f64 * 10.0 + 3.0) {
        for height in [-2.0, 0.0, 2.0] {
            let p = pos(az, height);
            let both = one_train(&o, p, 2e-6, 0.3);
            let a = one_train(&alone[0], p, 2e-6, 0.3);
            let b = one_train(&alone[1], p, 2e-6, 0.3);
            met += usize::from(!a.t.is_empty() && !b.t.is_empty());
            // No instant and no T_i group holds both beams: the two
            // channels' pulses are more than 5 µs apart everywhere.
            for &ta in &a.t {
                let k = b.t.partition_point(|&t| t < ta - 5e-6);
                assert!(k == b.t.len() || b.t[k] > ta + 5e-6, "φ = {az}, t = {ta}");
            }
            assert_eq!(both.t.len(), a.t.len() + b.t.len());
        }
    }
    // Each aperture is still met by both beams, at different times.
    assert!(met > 50, "{met}");
}

#[test]
fn a_channel_at_power_scale_zero_contributes_nothing() {
    let sc = scan(1550.0, 5.0, 20e-3);
    let mut h = head(
        vec![channel(0, 0.0, 0.0, 0.0), channel(1, 0.3, 0.2, 1e-6)],
        5e-5,
        20.0,
        3.0,
    );
    let only = head(vec![channel(0, 0.0, 0.0, 0.0)], 5e-5, 20.0, 3.0);
    let o_only = Oracle::new(&only, &sc);
    let full = Oracle::new(&h, &sc);
    h.channels[1].power_scale = 0.0;
    let o = Oracle::new(&h, &sc);
    let p = pos(20.0, 0.0);
    let (a, b, c) = (
        one_train(&o, p, 0.0, 1.0),
        one_train(&o_only, p, 0.0, 1.0),
        one_train(&full, p, 0.0, 1.0),
    );
    assert!(!a.t.is_empty());
    assert_eq!((&a.t, &a.e), (&b.t, &b.e));
    // With its power the second channel adds pulses (the test can fail).
    assert!(c.e.iter().sum::<f64>() > 1.5 * a.e.iter().sum::<f64>());
}

// ---------------------------------------------------------------------------
// Head shapes: real heads from public data (`docs/heads.md`) and random
// heads.

/// VLS-128 elevations (docs/heads.md Appendix A, from ros-drivers/velodyne
/// `velodyne_pointcloud/params/VLS128.yaml`); the azimuth offset is set by
/// `id mod 8`, each row of 8 is one firing group.
#[allow(clippy::approx_constant)] // vendor data (6.280°), not τ
const VLS128_ELEVATION_DEG: [f64; 128] = [
    -11.742, -1.990, 3.400, -5.290, -0.780, 4.610, -4.080, 1.310, -6.500, -1.110, 4.280, -4.410,
    0.100, 6.480, -3.200, 2.190, -3.860, 1.530, -9.244, -1.770, 2.740, -5.950, -0.560, 4.830,
    -2.980, 2.410, -6.280, -0.890, 3.620, -5.070, 0.320, 7.580, -0.340, 5.180, -3.640, 1.750,
    -25.000, -2.430, 2.960, -5.730, 0.540, 9.700, -2.760, 2.630, -7.650, -1.550, 3.840, -4.850,
    3.180, -5.510, -0.120, 5.730, -4.300, 1.090, -16.042, -2.210, 4.060, -4.630, 0.760, 15.000,
    -3.420, 1.970, -6.850, -1.330, -5.620, -0.230, 5.430, -3.530, 0.980, -19.582, -2.320, 3.070,
    -4.740, 0.650, 11.750, -2.650, 1.860, -7.150, -1.440, 3.950, -2.100, 3.290, -5.400, -0.010,
    4.500, -4.190, 1.200, -13.565, -1.220, 4.170, -4.520, 0.870, 6.080, -3.310, 2.080, -6.650,
    1.420, -10.346, -1.880, 3.510, -6.060, -0.670, 4.720, -3.970, 2.300, -6.390, -1.000, 4.390,
    -5.180, 0.210, 6.980, -3.090, 4.980, -3.750, 1.640, -8.352, -2.540, 2.850, -5.840, -0.450,
    8.430, -2.870, 2.520, -6.170, -1.660, 3.730, -4.960, 0.430,
];
const VLS128_COLUMN_DEG: [f64; 8] = [-6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354];

/// VLS-128-like: groups of 8 (`id / 8`) every 2.665 µs, a 2.665 µs pause
/// after the 8th group, 53.3 µs cycle (VLS-128 manual p.49 via docs/heads.md §2);
/// crossing point 58.63 mm (valgur/velodyne_decoder `calib_db.cpp`, §3);
/// divergence 3 mrad (manual p.115, the larger axis); exit diameter not
/// public: 8 mm assumed.
fn vls128_like() -> Head {
    let channels = (0..128u32)
        .map(|id| {
            let g = (id / 8) as f64;
            let slot = if g < 8.0 { g } else { g + 1.0 } * 2.665e-6;
            channel(
                id,
                VLS128_ELEVATION_DEG[id as usize],
                VLS128_COLUMN_DEG[(id % 8) as usize],
                slot,
            )
        })
        .collect();
    let mut h = head(channels, 53.3e-6, 58.63, 8.0);
    h.divergence_mrad = 3.0;
    h
}

/// OS1-128-like: the whole column at once, rows from +20.95° down by
/// 0.3387° to −21.82°, azimuth offsets by `row mod 4` (+4.21, +1.41, −1.40,
/// −4.22), origin 15.806 mm (ouster-sdk metadata, docs/heads.md §1/§3), 10 mm
/// exit beam and 0.18° (3.14 mrad) divergence (OS1 datasheet, §3), column
/// period 97.7 µs (1024 × 10 Hz).
#[allow(clippy::approx_constant)] // 3.14 mrad = 0.18°, not π
fn os1_128_like() -> Head {
    let cols = [4.21, 1.41, -1.40, -4.22];
    let channels = (0..128u32)
        .map(|r| {
            let el = 20.95 - (20.95 + 21.82) * r as f64 / 127.0;
            channel(r, el, cols[(r % 4) as usize], 0.0)
        })
        .collect();
    let mut h = head(channels, 97.7e-6, 15.806, 10.0);
    h.divergence_mrad = 3.14;
    h
}

/// VLP-16-like: sequential firing 2.304 µs apart, 55.296 µs cycle, 2°
/// interleaved elevations, no offsets, crossing point 41.91 mm (docs/heads.md
/// §1–§3); exit diameter not public: 8 mm assumed, 3 mrad.
fn vlp16_like() -> Head {
    let el = [
        -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0,
        15.0,
    ];
    let channels = (0..16u32)
        .map(|k| channel(k, el[k as usize], 0.0, 2.304e-6 * k as f64))
        .collect();
    let mut h = head(channels, 55.296e-6, 41.91, 8.0);
    h.divergence_mrad = 3.0;
    h
}

/// A deterministic generator (splitmix64).
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A random head of `1..=max_channels` channels: elevations clustered near
/// the horizon (so beams share apertures), a few azimuth columns, slots in
/// shared groups or sequential, random origin, beam size, divergence and
/// power scales (some zero).
fn random_head(r: &mut Rng, max_channels: usize) -> Head {
    let n = 1 + r.below(max_channels);
    let cycle_s = r.range(10e-6, 100e-6);
    let n_cols = 1 + r.below(4);
    let cols: Vec<f64> = (0..n_cols).map(|_| r.range(-8.0, 8.0)).collect();
    let spread = r.range(0.05, 3.0);
    let n_slots = 1 + r.below(n.min(16));
    let slots: Vec<f64> = (0..n_slots).map(|_| r.range(0.0, cycle_s)).collect();
    let channels = (0..n)
        .map(|k| Channel {
            id: k as u32 * 3 + 1,
            elevation_deg: r.range(-1.0, 1.0) * spread * (n as f64).sqrt(),
            azimuth_offset_deg: cols[k % n_cols] + r.range(-0.05, 0.05),
            slot_s: slots[r.below(n_slots)],
            power_scale: if r.unit() < 0.1 {
                0.0
            } else {
                r.range(0.2, 1.5)
            },
        })
        .collect();
    let h = Head {
        cycle_s,
        origin_radius_mm: r.range(0.0, 60.0),
        origin_height_mm: r.range(-5.0, 5.0),
        exit_diameter_mm: r.range(0.5, 10.0),
        divergence_mrad: r.range(0.0, 3.0),
        aperture_distance_mm: 100.0,
        channels,
    };
    h.validate().expect("valid random head");
    h
}

/// A random scan: 2–6 bins with steps of power and spin and in-bin
/// acceleration; 905 or 1550 nm.
fn random_scan(r: &mut Rng) -> OScan {
    let nb = 2 + r.below(5);
    let mut cuts: Vec<f64> = (0..nb - 1).map(|_| r.range(5.0, 355.0)).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.insert(0, 0.0);
    cuts.push(360.0);
    let frame_hz = r.range(2.0, 20.0);
    let w = std::f64::consts::TAU * frame_hz;
    let mut spins: Vec<f64> = (0..nb).map(|_| w * r.range(0.4, 2.0)).collect();
    spins.push(spins[0]);
    let lambda_nm = if r.unit() < 0.5 { 905.0 } else { 1550.0 };
    let base = if lambda_nm < 1000.0 { 0.5e-3 } else { 10e-3 };
    let bins = (0..nb)
        .map(|k| {
            let accel = r.unit() < 0.5;
            OBin {
                start_deg: cuts[k],
                width_deg: cuts[k + 1] - cuts[k],
                power_w: base * r.range(0.1, 2.0),
                w0: spins[k],
                w1: if accel { spins[k + 1] } else { spins[k] },
            }
        })
        .collect();
    OScan {
        bins,
        lambda_nm,
        pulse_s: r.range(2e-9, 20e-9),
    }
}

/// Cases of the random stream (env `HEAD_ORACLE_CASES`, default `d`).
fn cases(d: usize) -> usize {
    std::env::var("HEAD_ORACLE_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(d)
}

/// How many of a fixed-shape test's cases run (env `HEAD_ORACLE_SHAPES`,
/// default all): the first `n` in the test's order, at least one.
fn shapes_max() -> usize {
    std::env::var("HEAD_ORACLE_SHAPES")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(usize::MAX, |n: usize| n.max(1))
}

/// `HEAD_ORACLE_LONG=1`: full effort (more phases, starts and positions).
fn long_run() -> bool {
    std::env::var_os("HEAD_ORACLE_LONG").is_some()
}

/// Positions for a case: every bin's start, middle and end (± 0.5°) and a
/// few fixed azimuths, × a height grid plus every channel's edge heights.
fn case_positions(o: &Oracle, heights: &[f64], extra_az: usize) -> Vec<Pos> {
    case_positions_max(o, heights, extra_az, usize::MAX)
}

/// [`case_positions`] with the edge heights of at most `edge_channels`
/// channels (evenly chosen).
fn case_positions_max(
    o: &Oracle,
    heights: &[f64],
    extra_az: usize,
    edge_channels: usize,
) -> Vec<Pos> {
    let mut az: Vec<f64> = Vec::new();
    for b in &o.scan.bins {
        az.push(b.start_deg + 0.5);
        az.push(b.start_deg + 0.5 * b.width_deg);
        az.push((b.start_deg + b.width_deg - 0.5).rem_euclid(360.0));
    }
    az.extend((0..extra_az).map(|k| 360.0 * (k as f64 + 0.5) / extra_az as f64));
    let n = o.head.channels.len();
    // Where (up to 6) channels pass while the head is in the hottest bin:
    // its start, middle and end.
    let hot = o
        .scan
        .bins
        .iter()
        .max_by(|a, b| a.power_w.total_cmp(&b.power_w))
        .unwrap();
    for k in 0..n.min(6) {
        let c = k * n / n.min(6);
        for th in [
            hot.start_deg + 0.3,
            hot.start_deg + 0.5 * hot.width_deg,
            hot.start_deg + hot.width_deg - 0.3,
        ] {
            az.push(o.pass_azimuth_deg(c, th));
        }
    }
    if n <= edge_channels {
        return o.positions(&az, heights);
    }
    let mut out = Vec::new();
    for &phi in &az {
        let mut hs: Vec<f64> = heights.to_vec();
        for k in 0..edge_channels {
            hs.extend(o.edge_heights(k * n / edge_channels, phi, 1e-6));
        }
        hs.sort_by(f64::total_cmp);
        hs.dedup();
        out.extend(hs.into_iter().map(|h| pos(phi, h)));
    }
    out
}

fn one_channel_of(h: &Head, c: usize) -> Head {
    let mut one = h.clone();
    one.channels = vec![Channel {
        power_scale: 1.0,
        ..h.channels[c].clone()
    }];
    one
}

/// The real-head shapes: the head's worst, each channel alone (at power
/// scale 1) at the same positions, and their quotient (the issue asks it to
/// reach at least the number of same-group beams that can meet one
/// aperture). Numbers printed for the report; the assertions are what the
/// definitions force: the head is never below its hottest channel alone at
/// the single-pulse and group rules, and VLS-128's simultaneous group puts
/// several beams in one aperture.
#[test]
#[ignore = "long: the report's numbers (cargo test --release --test head_oracle -- --ignored)"]
fn real_head_shapes() {
    let sc = |lambda| OScan {
        lambda_nm: lambda,
        ..scan(lambda, 10.0, 0.05e-3)
    };
    for (name, h, lambda) in [
        ("vlp16-like", vlp16_like(), 905.0),
        ("vls128-like", vls128_like(), 905.0),
        ("os1-128-like", os1_128_like(), 865.0),
    ] {
        let t = std::time::Instant::now();
        let s = sc(lambda);
        let o = Oracle::new(&h, &s);
        let heights: Vec<f64> = (-4..=4).map(|k| k as f64 * 2.0).collect();
        let positions = o.positions(&[15.0], &heights);
        let effort = if long_run() {
            head_oracle_defs::Effort::default()
        } else {
            head_oracle_defs::Effort {
                phases: 1,
                starts_max: 50,
                top_k: 1,
                ..Default::default()
            }
        };
        let w = o.worst(&positions, &effort);
        // The most beams of one slot in one instant at the worst position.
        let ivs = o.intervals(w.pos.azimuth_deg, 0.05);
        let tr = o.train(w.pos, w.t0_s, 0.3, &ivs);
        let e1 = s.bins.iter().map(|b| b.power_w).fold(0.0, f64::max) * h.cycle_s;
        let beams_at_once =
            tr.e.iter()
                .map(|e| (e / e1).round() as usize)
                .max()
                .unwrap_or(0);
        // The best single channel at the head's worst position: the three
        // channels with the most energy there in 1.5 turns, in full.
        let mut by_energy: Vec<(f64, usize)> = (0..h.channels.len())
            .map(|c| {
                let oc = Oracle::new(&one_channel_of(&h, c), &s);
                let ivs = oc.intervals(w.pos.azimuth_deg, 0.05);
                let tr = oc.train(w.pos, w.t0_s, 1.5 * oc.motion.period_s, &ivs);
                (tr.e.iter().sum::<f64>(), c)
            })
            .collect();
        by_energy.sort_by(|a, b| b.0.total_cmp(&a.0));
        let reaching = by_energy.iter().filter(|x| x.0 > 0.0).count();
        let single = by_energy
            .iter()
            .take(3)
            .map(|&(_, c)| {
                let oc = Oracle::new(&one_channel_of(&h, c), &s);
                oc.worst(&[w.pos], &effort).ratio
            })
            .fold(0.0, f64::max);
        println!(
            "{name}: head {w}\n  single channel at that position {single:.6}, quotient {:.3}, \
             {beams_at_once} beams in one instant there, {reaching} channels reach it; \
             {} positions, {:?}",
            w.ratio / single,
            positions.len(),
            t.elapsed()
        );
        assert!(w.ratio >= single * (1.0 - 1e-12));
        if name == "vls128-like" {
            assert!(beams_at_once >= 2);
        }
    }
}

/// The profile the checker reads for `scan` turned by `head` (pulse rate
/// `1/cycle_s`; `beam_diameter_mm` the head's footprint at the aperture, as
/// a single-channel file would state it).
fn profile_of(s: &OScan, h: &Head) -> Profile {
    let period: f64 = s
        .bins
        .iter()
        .map(|b| 2.0 * b.width_deg.to_radians() / (b.w0 + b.w1))
        .sum();
    let footprint = h.exit_diameter_mm
        + h.divergence_mrad * 1e-3 * (h.aperture_distance_mm - h.origin_radius_mm);
    let v = json!({
        "format": "gaze-lidar/profile@1",
        "frame_rate_hz": 1.0 / period,
        "pulse_rate_hz": 1.0 / h.cycle_s,
        "average_power_w": 1e3,
        "power_accounting": "time",
        "gaze_deg": null,
        "limits": {
            "power_w_min": 0.0, "power_w_max": 1e3,
            "spin_rad_s_min": 0.0, "spin_rad_s_max": 1e6,
            "spin_accel_rad_s2_max": null, "power_slew_w_per_deg_max": null,
            "eye_safety": {
                "wavelength_nm": s.lambda_nm,
                "pulse_duration_s": s.pulse_s,
                "beam_diameter_mm": footprint,
                "head": serde_json::to_value(h).unwrap(),
            }
        },
        "bins": s.bins.iter().map(|b| json!({
            "start_deg": b.start_deg, "width_deg": b.width_deg, "power_w": b.power_w,
            "spin_start_rad_s": b.w0, "spin_end_rad_s": b.w1
        })).collect::<Vec<_>>()
    });
    Profile::from_json(&v.to_string(), "head oracle").expect("generated profile parses")
}

/// The bound's figure for the profile on the head's declared surface (the
/// verdict also covers 100 mm; the bound is tested at any distance).
fn bound_ratio(p: &Profile) -> f64 {
    let params = p.limits.eye_safety.clone().unwrap();
    evaluate_segments_at_declared_distance(&segments(p), &params, p.pulse_rate_hz)
        .expect("evaluates")
        .worst_ratio
}

/// Harness check on what exists today: a 1-channel head on the axis
/// (origin 0, elevation 0, no offset) is the single-channel model, and the
/// certified single-channel bound (reading the footprint at the aperture as
/// its beam) is never below the oracle.
#[test]
fn one_channel_axis_heads_never_above_the_single_channel_bound() {
    let mut r = Rng(0x4ead_0a11);
    let mut worst_q = f64::INFINITY;
    for case in 0..cases(6) {
        let s = random_scan(&mut r);
        let mut h = random_head(&mut r, 1);
        h.origin_radius_mm = 0.0;
        h.origin_height_mm = 0.0;
        h.channels[0].elevation_deg = 0.0;
        h.channels[0].azimuth_offset_deg = 0.0;
        h.channels[0].power_scale = 1.0;
        let o = Oracle::new(&h, &s);
        let positions = case_positions(&o, &[0.0], 4);
        let effort = head_oracle_defs::Effort {
            phases: 2,
            starts_max: 100,
            top_k: 2,
            ..Default::default()
        };
        let w = o.worst(&positions, &effort);
        let mut single = h.clone();
        single.channels.clear();
        let b = bound_ratio(&profile_of(&s, &h));
        println!(
            "case {case}: bound {b:.6}, oracle {w}, bound/oracle {:.4}",
            b / w.ratio
        );
        worst_q = worst_q.min(b / w.ratio);
        assert!(
            b >= w.ratio * (1.0 - 1e-12),
            "case {case}: bound {b} < oracle {w}"
        );
    }
    println!("smallest bound/oracle {worst_q:.6}");
}

/// Statistics of bound / oracle.
#[derive(Debug, Default)]
struct Quot {
    n: usize,
    min: f64,
    max: f64,
    min_case: String,
    max_case: String,
}

impl Quot {
    fn add(&mut self, q: f64, label: String) {
        if self.n == 0 {
            (self.min, self.max) = (f64::INFINITY, 0.0);
        }
        self.n += 1;
        if q < self.min {
            self.min = q;
            self.min_case = label.clone();
        }
        if q > self.max {
            self.max = q;
            self.max_case = label;
        }
    }
}

/// One differential case: the head bound against the oracle; returns
/// bound / oracle (∞ when the oracle sees nothing).
fn differential(
    label: &str,
    s: &OScan,
    h: &Head,
    effort: &head_oracle_defs::Effort,
    edge_channels: usize,
) -> (f64, f64, String) {
    let o = Oracle::new(h, s);
    let heights: Vec<f64> = (-3..=3)
        .map(|k| h.origin_height_mm + k as f64 * 2.5)
        .collect();
    let positions = case_positions_max(&o, &heights, 4, edge_channels);
    let w = o.worst(&positions, effort);
    let b = bound_ratio(&profile_of(s, h));
    let line = format!(
        "{label}: {} channels, {} nm, bound {b:.6}, oracle {w}, bound/oracle {:.12}",
        h.channels.len(),
        s.lambda_nm,
        b / w.ratio
    );
    if w.ratio > 0.0 && b < w.ratio * (1.0 - 1e-12) {
        println!(
            "BELOW: {line}\nhead = {}\nscan = {s:?}",
            serde_json::to_string(h).unwrap()
        );
    }
    (b, w.ratio, line)
}

/// The head bound is never below the oracle: random heads (1–128 channels,
/// random slots, offsets, origins, beam sizes, power scales, 905/1550 nm,
/// profiles with steps and in-bin acceleration). `HEAD_ORACLE_CASES` for
/// long runs (default 5); `HEAD_ORACLE_SEED` another stream.
#[test]
fn head_bound_is_never_below_the_oracle_on_random_heads() {
    let seed = std::env::var("HEAD_ORACLE_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x000a_c1e5_u64);
    let mut r = Rng(seed);
    let effort = head_oracle_defs::Effort {
        phases: 2,
        starts_max: 60,
        top_k: 2,
        scan_step_deg: 0.05,
    };
    let mut q = Quot::default();
    let mut below = Vec::new();
    for case in 0..cases(5) {
        let max_ch = if r.unit() < 0.15 { 128 } else { 12 };
        let h = random_head(&mut r, max_ch);
        let s = random_scan(&mut r);
        let (b, o, line) = differential(&format!("seed {seed} case {case}"), &s, &h, &effort, 12);
        println!("{line}");
        if o > 0.0 {
            q.add(b / o, line.clone());
        }
        if b < o * (1.0 - 1e-12) {
            below.push(line);
        }
    }
    println!(
        "{} cases: bound/oracle min {:.12} ({}), max {:.4} ({})",
        q.n, q.min, q.min_case, q.max, q.max_case
    );
    assert!(
        below.is_empty(),
        "bound below the oracle:\n{}",
        below.join("\n")
    );
}

/// The same on the real-head shapes, on the 4-bin scan: VLP-16 and
/// OS1-128 at 905/865 nm by default; with `HEAD_ORACLE_LONG=1` also
/// VLS-128 and every shape at 1550 nm; `HEAD_ORACLE_SHAPES=n` only the
/// first `n` of them.
#[test]
fn head_bound_is_never_below_the_oracle_on_real_heads() {
    let effort = head_oracle_defs::Effort {
        phases: 1,
        starts_max: 40,
        top_k: 1,
        scan_step_deg: 0.05,
    };
    let mut below = Vec::new();
    let mut shapes = vec![
        ("vlp16-like", vlp16_like(), 905.0),
        ("os1-128-like", os1_128_like(), 865.0),
    ];
    if long_run() {
        shapes.extend([
            ("vls128-like", vls128_like(), 905.0),
            ("vlp16-like", vlp16_like(), 1550.0),
            ("os1-128-like", os1_128_like(), 1550.0),
            ("vls128-like", vls128_like(), 1550.0),
        ]);
    }
    shapes.truncate(shapes_max());
    for (name, h, lambda) in shapes {
        let p = if lambda > 1000.0 { 2e-3 } else { 0.05e-3 };
        let s = OScan {
            lambda_nm: lambda,
            ..scan(lambda, 10.0, p)
        };
        let (b, o, line) = differential(name, &s, &h, &effort, 24);
        println!("{line}");
        if b < o * (1.0 - 1e-12) {
            below.push(line);
        }
    }
    assert!(
        below.is_empty(),
        "bound below the oracle:\n{}",
        below.join("\n")
    );
}

/// A head at the edges of the description: crossing point close to the
/// aperture (parallax), an aperture distance other than 100 mm, large offsets and elevations, pencil or very
/// divergent beams, cycles that put 1–3 of one channel's pulses in `T_i`,
/// slots at the cycle's end, large power scales, one shared slot for many.
fn wild_head(r: &mut Rng, max_channels: usize) -> Head {
    let n = 1 + r.below(max_channels);
    let cycle_s = match r.below(4) {
        0 => 5e-6,
        1 => 2.5e-6 * r.range(0.9, 1.1),
        2 => r.range(1e-6, 20e-6),
        _ => r.range(20e-6, 300e-6),
    };
    let origin_radius_mm = match r.below(3) {
        0 => r.range(80.0, 99.0),
        1 => 0.0,
        _ => r.range(0.0, 80.0),
    };
    let big_offsets = r.unit() < 0.4;
    let shared = r.unit() < 0.4;
    let el0 = r.range(-30.0, 30.0);
    let channels = (0..n)
        .map(|k| Channel {
            id: 1000 - k as u32,
            elevation_deg: el0 + r.range(-1.0, 1.0) * r.range(0.0, 4.0),
            azimuth_offset_deg: if big_offsets {
                r.range(-45.0, 45.0)
            } else {
                r.range(-3.0, 3.0)
            },
            slot_s: if shared {
                0.0
            } else if r.unit() < 0.3 {
                cycle_s * (1.0 - 1e-9)
            } else {
                r.range(0.0, cycle_s)
            },
            power_scale: match r.below(4) {
                0 => 0.0,
                1 => r.range(1.0, 10.0),
                _ => r.range(0.1, 1.0),
            },
        })
        .collect();
    let h = Head {
        cycle_s,
        origin_radius_mm,
        origin_height_mm: r.range(-20.0, 20.0),
        exit_diameter_mm: if r.unit() < 0.3 {
            r.range(0.01, 0.2)
        } else {
            r.range(0.2, 20.0)
        },
        divergence_mrad: if r.unit() < 0.2 {
            r.range(10.0, 200.0)
        } else {
            r.range(0.0, 3.0)
        },
        aperture_distance_mm: if r.unit() < 0.3 {
            origin_radius_mm + r.range(5.0, 200.0)
        } else {
            100.0
        },
        channels,
    };
    h.validate().expect("valid wild head");
    h
}

/// The head bound against the oracle on [`wild_head`]s (default 2 cases;
/// `HEAD_ORACLE_WILD_CASES` for long runs).
#[test]
fn head_bound_is_never_below_the_oracle_on_wild_heads() {
    let n_cases = std::env::var("HEAD_ORACLE_WILD_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2usize);
    let seed = std::env::var("HEAD_ORACLE_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x0003_111d_u64);
    let mut r = Rng(seed);
    let effort = head_oracle_defs::Effort {
        phases: 2,
        starts_max: 60,
        top_k: 2,
        scan_step_deg: 0.02,
    };
    let mut q = Quot::default();
    let mut below = Vec::new();
    for case in 0..n_cases {
        let h = wild_head(&mut r, 12);
        let s = random_scan(&mut r);
        let (b, o, line) = differential(
            &format!("wild seed {seed} case {case}"),
            &s,
            &h,
            &effort,
            12,
        );
        println!("{line}");
        if o > 0.0 {
            q.add(b / o, line.clone());
        }
        if b < o * (1.0 - 1e-12) {
            below.push(line);
        }
    }
    println!(
        "{} wild cases: bound/oracle min {:.12} ({}), max {:.4} ({})",
        q.n, q.min, q.min_case, q.max, q.max_case
    );
    assert!(
        below.is_empty(),
        "bound below the oracle:\n{}",
        below.join("\n")
    );
}

/// Directed: two channels whose beams never meet one aperture together
/// (azimuth offsets `Δ` apart) but whose passes of one aperture are a short
/// turn apart, so one window holds both: at 1550 nm every window up to
/// 0.35 s has one AEL (8 mJ), so such a window holds twice one pass; at
/// 905 nm the windows of a few ms. Scans with a fast or slow sector between
/// the two passes, turning at 5 Hz or at 0.05 Hz (a turn longer than T2, so
/// the short windows, not the 10 s ones, bind). `HEAD_ORACLE_SHAPES=n`:
/// only the first `n` pairs (in loop order).
#[test]
fn head_bound_is_never_below_the_oracle_on_separated_pairs() {
    let effort = head_oracle_defs::Effort {
        phases: 2,
        starts_max: 80,
        top_k: 2,
        scan_step_deg: 0.05,
    };
    let mut below = Vec::new();
    let mut q = Quot::default();
    let (deltas, motions): (&[f64], &[(f64, f64)]) = if long_run() {
        (
            &[3.0, 6.0, 12.0, 25.0, 40.0, 80.0],
            &[(0.2, 5.0), (5.0, 5.0), (5.0, 0.05), (0.5, 0.05)],
        )
    } else {
        (&[6.0], &[(0.2, 5.0), (0.5, 0.05)])
    };
    let mut left = shapes_max();
    for &lambda in &[1550.0, 905.0] {
        for &delta in deltas {
            for &(between, frame_hz) in motions {
                if left == 0 {
                    continue;
                }
                left -= 1;
                let w = std::f64::consts::TAU * frame_hz;
                let p = if lambda > 1000.0 { 20e-3 } else { 0.5e-3 };
                // The aperture at φ ≈ 100°: channel 0 (offset +Δ/2) passes
                // it first, then channel 1 (offset −Δ/2), with a sector of
                // spin `between · w` in between.
                let a = 100.0 - 0.5 * delta;
                let s = OScan {
                    bins: vec![
                        OBin {
                            start_deg: 0.0,
                            width_deg: a - 3.0,
                            power_w: p,
                            w0: w,
                            w1: w,
                        },
                        OBin {
                            start_deg: a - 3.0,
                            width_deg: delta + 6.0,
                            power_w: p,
                            w0: between * w,
                            w1: between * w,
                        },
                        OBin {
                            start_deg: a + delta + 3.0,
                            width_deg: 360.0 - (a + delta + 3.0),
                            power_w: p,
                            w0: w,
                            w1: w,
                        },
                    ],
                    lambda_nm: lambda,
                    pulse_s: 5e-9,
                };
                let mut h = head(
                    vec![
                        channel(0, 0.0, 0.5 * delta, 0.0),
                        channel(1, 0.0, -0.5 * delta, 3e-6),
                    ],
                    20e-6,
                    40.0,
                    4.0,
                );
                h.divergence_mrad = 2.0;
                let (b, o, line) = differential(
                    &format!("pair Δ = {delta}°, between ×{between}, {frame_hz} Hz"),
                    &s,
                    &h,
                    &effort,
                    2,
                );
                println!("{line}");
                if o > 0.0 {
                    q.add(b / o, line.clone());
                }
                if b < o * (1.0 - 1e-12) {
                    below.push(line);
                }
            }
        }
    }
    println!(
        "{} pairs: bound/oracle min {:.12} ({})",
        q.n, q.min, q.min_case
    );
    assert!(
        below.is_empty(),
        "bound below the oracle:\n{}",
        below.join("\n")
    );
}
