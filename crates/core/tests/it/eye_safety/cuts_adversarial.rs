//! Adversarial review of the optimizer's cuts (`eye_safety::cuts`): every
//! cut must stay at or under the bound's worst ratio (`bound::evaluate`)
//! for the powers it was found at, over a wider input space than
//! `tests/it/eye_safety/cuts.rs` draws from: pass angles up to and beyond 360°, bins
//! narrower than a pass and down to 1e-6 of a turn, spins from 0.01 to
//! 2,000 rad/s, pulse rates up to 2 MHz (several pulses within `T_i`),
//! pulses at and beyond `T_i`, equal neighbours (which the bound merges).

use gaze_lidar_core::eye_safety::ael::Band;
use gaze_lidar_core::eye_safety::bound::{evaluate, Laser, Seg};
use gaze_lidar_core::eye_safety::cuts::cuts;
use proptest::prelude::*;

use gaze_lidar_core::testing::segments;

fn cases() -> u32 {
    std::env::var("GAZE_LIDAR_CUTS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(12)
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

/// The worst cut ratio over the bound's worst ratio (≤ 1 when valid).
fn worst_excess(segs: &[Seg], half_deg: f64, laser: &Laser, extra: &[f64]) -> (f64, String) {
    let b = evaluate(segs, half_deg, laser).worst_ratio;
    let p: Vec<f64> = segs.iter().map(|s| s.power_w).collect();
    let mut worst = (0.0, String::new());
    for c in cuts(segs, half_deg, laser, extra, 0.0) {
        let r = c.ratio(&p, laser.pulse_rate_hz) / b;
        if r > worst.0 {
            worst = (
                r,
                format!("{c:?} ratio {} bound {b}", c.ratio(&p, laser.pulse_rate_hz)),
            );
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn every_cut_is_at_most_the_bound_wide(
        bins in proptest::collection::vec(
            (
                prop_oneof![log_uniform(1e-6, 1.0), Just(1.0)],
                prop_oneof![0.0f64..0.4, Just(0.1), Just(0.0)],
                prop_oneof![log_uniform(0.01, 2000.0), Just(20.0)],
                any::<bool>(),
            ),
            1..10,
        ),
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
        f_p in prop_oneof![log_uniform(10.0, 2e6), Just(2e5), Just(4e5), Just(1e6), Just(1e3)],
        pulse_s in prop_oneof![Just(1e-9), Just(5e-6), Just(1e-5), Just(1e-3), log_uniform(1e-9, 1e-2)],
        half_deg in prop_oneof![log_uniform(1e-4, 400.0), Just(180.0), Just(360.0), Just(90.0)],
        extra in 0.0f64..360.0,
    ) {
        let segs = segments(&bins);
        let pulse_s = pulse_s.min(0.9 / f_p);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: pulse_s, pulse_rate_hz: f_p };
        let (r, what) = worst_excess(&segs, half_deg, &laser, &[extra]);
        prop_assert!(r <= 1.0, "cut over the bound by {r}: {what}");
    }

    /// Bins far narrower than the pass and than the bound's touch snap
    /// (1e-9°): hot slivers of 1e-13 to 1e-6 of a turn next to cool bins,
    /// constant spin or accelerating, the pass from 0.01° to 20°.
    #[test]
    fn every_cut_is_at_most_the_bound_with_slivers(
        bins in proptest::collection::vec(
            (prop_oneof![log_uniform(1e-13, 1e-6), 0.05f64..1.0], 0.0f64..0.4, 5.0f64..100.0, any::<bool>()),
            2..8,
        ),
        f_p in prop_oneof![Just(18_761.0), 1e3f64..3e5],
        half_deg in log_uniform(0.005, 10.0),
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
    ) {
        let segs = segments(&bins);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let (r, what) = worst_excess(&segs, half_deg, &laser, &[]);
        prop_assert!(r <= 1.0, "cut over the bound by {r}: {what}");
    }

    /// Table 3 row edges: frames that divide 10 s, 0.35 s and 1 ms, and
    /// passes a hair either side of 5 µs, 1 ms, 0.35 s and 10 s, every band.
    #[test]
    fn every_cut_is_at_most_the_bound_at_row_edges(
        edge in prop_oneof![Just(5e-6), Just(1e-3), Just(0.35), Just(10.0)],
        frame_base in prop_oneof![Just(10.0), Just(0.35), Just(1e-3), Just(100.0)],
        div in 1u32..40,
        rel in prop_oneof![Just(0.0), Just(1e-12), Just(-1e-12), Just(1e-9), Just(-1e-9), -1e-3f64..1e-3],
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
        f_p in prop_oneof![Just(1e3), Just(1e4), Just(2e5), Just(18_761.0), 100.0f64..1e5],
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4), 1..5),
        accel in any::<bool>(),
    ) {
        let frame_s = frame_base / f64::from(div);
        prop_assume!(edge < frame_s);
        let spin = std::f64::consts::TAU / frame_s;
        let half_deg = 0.5 * (spin * edge * (1.0 + rel)).to_degrees();
        let b: Vec<(f64, f64, f64, bool)> = bins
            .iter()
            .enumerate()
            .map(|(i, &(w, p))| (w, p, spin * (1.0 + 0.3 * (i % 2) as f64), accel))
            .collect();
        let segs = segments(&b);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: 1e-9, pulse_rate_hz: f_p };
        let (r, what) = worst_excess(&segs, half_deg, &laser, &[]);
        prop_assert!(r <= 1.0, "cut over the bound by {r}: {what}");
    }

    /// The `T_i` groups (700–1050 nm, several pulses within 5 µs): pulse
    /// rates near integer multiples of `1/T_i` and passes of a few pulses
    /// to a few hundred, where the group term is the bound's Rule 1 figure.
    /// Off the integer edge (`off` > 0) the cut should hold.
    #[test]
    fn t_i_group_cuts_are_at_most_the_bound_off_the_edge(
        n in 2u32..60,
        off in prop_oneof![1e-6f64..0.9, Just(0.5)],
        k in 1.0f64..300.0,
        frame_s in log_uniform(1e-3, 1.0),
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 0.5f64..2.0, any::<bool>()), 1..6),
        pulse_frac in prop_oneof![Just(1e-4), 1e-4f64..0.9],
    ) {
        let f_p = (f64::from(n) + off) / 5e-6;
        let spin = std::f64::consts::TAU / frame_s;
        let half_deg = 0.5 * (spin * k / f_p).to_degrees();
        let b: Vec<(f64, f64, f64, bool)> =
            bins.iter().map(|&(w, p, s, a)| (w, p, spin * s, a)).collect();
        let segs = segments(&b);
        let pulse_s = pulse_frac / f_p;
        let laser = Laser { band: Band::RetinalNir, c4: 1.0, pulse_duration_s: pulse_s, pulse_rate_hz: f_p };
        let (r, what) = worst_excess(&segs, half_deg, &laser, &[]);
        prop_assert!(r <= 1.0, "cut over the bound by {r}: {what}");
    }
}

/// One bin at a constant spin, 700–1050 nm, a pulse rate with `T_i·f_p` an
/// integer `N` (so a closed `T_i` window holds `N + 1` pulses) and a pass
/// of `N + 1` pulses (`τ` just over `N·Δ`).
fn t_i_edge(n: f64, frame_s: f64) -> (Vec<Seg>, f64, Laser) {
    let f_p = n / 5e-6;
    let delta = 1.0 / f_p;
    let spin = std::f64::consts::TAU / frame_s;
    // τ = N·Δ·1.002: N + 1 pulses in every pass, for the bound and the cut.
    let tau = n * delta * 1.002;
    let half_deg = 0.5 * (spin * tau).to_degrees();
    let segs = vec![Seg {
        start_deg: 0.0,
        width_deg: 360.0,
        power_w: 1e-3,
        spin_start_rad_s: spin,
        spin_end_rad_s: spin,
    }];
    let laser = Laser {
        band: Band::RetinalNir,
        c4: 1.0,
        pulse_duration_s: 1e-9,
        pulse_rate_hz: f_p,
    };
    (segs, half_deg, laser)
}

/// BREAKS: the `T_i` group cut exceeds the bound when `T_i·f_p` is an
/// integer `N`. The bound reads a closed `T_i` window (`max_pulses_in`:
/// `N + 1` pulses a group, `⌈K/(N + 1)⌉` groups a pass); the cut groups by
/// half-open windows shrunk by `COUNT_INSIDE` (`N` pulses a group, so the
/// greedy cover of `K = N + 1` pulses has 2 groups a pass, not 1), and
/// holds its `N` pulses against `C5(2·passes)`: `N/(N + 1)·2^¼` times the
/// bound's group figure, 1.1323 at `N = 20` (4 MHz, 1 ns pulses, 100 Hz
/// spin, 1 mW: cut 0.09035 against the bound's 0.07979) wherever the group
/// term is the bound's Rule 1 figure (at `N = 6` the single-pulse term
/// wins and nothing shows). A certifiable profile (the bound ≤ 1 after
/// scaling the powers up by up to 13 %) is cut off, so the optimizer's
/// "optimal among certifiable" fails there. Fixed: the group cuts now take
/// `g` = `Laser::group` consecutive pulses (the bound's closed `T_i`
/// window) at the bound's group count.
#[test]
fn t_i_group_cut_is_at_most_the_bound_at_an_integer_t_i_f_p() {
    for (n, frame_s) in [(20.0, 0.01), (20.0, 0.1), (12.0, 0.01)] {
        let (segs, half_deg, laser) = t_i_edge(n, frame_s);
        let (r, what) = worst_excess(&segs, half_deg, &laser, &[]);
        assert!(
            r <= 1.0,
            "N = {n}, T_f = {frame_s}: cut over the bound by {r}: {what}"
        );
    }
}

/// The gap between the bound and the best cut on a uniform profile (one
/// bin, constant spin): where it is above the optimizer's head-room the
/// cutting-plane loop cannot close once that rule binds.
fn uniform_gap(
    band: Band,
    c4: f64,
    pulse_s: f64,
    f_p: f64,
    frame_s: f64,
    half_deg: f64,
) -> (f64, String) {
    let spin = std::f64::consts::TAU / frame_s;
    let segs = vec![Seg {
        start_deg: 0.0,
        width_deg: 360.0,
        power_w: 1e-3,
        spin_start_rad_s: spin,
        spin_end_rad_s: spin,
    }];
    let laser = Laser {
        band,
        c4,
        pulse_duration_s: pulse_s,
        pulse_rate_hz: f_p,
    };
    let b = evaluate(&segs, half_deg, &laser);
    let (r, what) = worst_excess(&segs, half_deg, &laser, &[b.worst_azimuth_deg]);
    (1.0 / r, format!("{what}; bound {b:?}"))
}

/// Prints the bound over the best cut on uniform profiles of the lasers
/// where the optimizer's loop was seen to stop without an answer.
#[test]
#[ignore = "exploration (prints)"]
fn bound_over_best_cut_on_uniform_profiles() {
    let c4 = gaze_lidar_core::eye_safety::ael::c4(903.0);
    let h = 0.5 * ((7.0 + 8.0) / 100.0f64).to_degrees();
    let h_ir =
        0.5 * ((gaze_lidar_core::eye_safety::ael::APERTURE_IR_MM + 8.0) / 100.0f64).to_degrees();
    for (name, band, c4, pulse_s, f_p, h) in [
        (
            "903 nm 3 ns 18.8 kHz",
            Band::RetinalNir,
            c4,
            3e-9,
            18_761.0,
            h,
        ),
        (
            "903 nm 10 us 18.8 kHz",
            Band::RetinalNir,
            c4,
            1e-5,
            18_761.0,
            h,
        ),
        ("903 nm 3 ns 500 kHz", Band::RetinalNir, c4, 3e-9, 5e5, h),
        ("903 nm 3 ns 2 MHz", Band::RetinalNir, c4, 3e-9, 2e6, h),
        (
            "1450 nm 3 ns 18.8 kHz",
            Band::Ir1400,
            1.0,
            3e-9,
            18_761.0,
            h_ir,
        ),
        (
            "1550 nm 3 ns 18.8 kHz",
            Band::Ir1500,
            1.0,
            3e-9,
            18_761.0,
            h_ir,
        ),
    ] {
        let (g, what) = uniform_gap(band, c4, pulse_s, f_p, 0.1, h);
        eprintln!("{name}: bound / best cut = {g:.6}\n    {what}");
    }
}

/// BREAKS (the loop cannot close; the bound is loose, not unsound): with
/// pulses longer than `T_i` (903 nm, 10 µs, 18,761 Hz; C5 = 1) the bound's
/// within-pass figure at a window of one pulse duration charges the
/// envelope `P·(T + Δ)` — `1 + t_p·f_p` = 1.1876 pulses — where a window of
/// 10 µs < Δ = 53 µs holds one pulse; no cut (a concrete exposure, or Rule
/// 1 at C5 = 1 with the same AEL(t_p)) can reach it. On one uniform bin
/// at 10 Hz the bound is 0.199673 and the best cut 0.168130 (ratio
/// 1.187610 = 1 + 1e-5·18,761). The optimizer's loop then stops with "no
/// concrete exposure there is over its limit" on every such laser where
/// eye safety binds (`tests/it/optimizer/eye_cuts_adversarial.rs`). The same factor
/// `1 + T·f_p`, `T` the bound's worst window, is 1.005 for 3 ns pulses at
/// 1 kHz (`T` = 5 µs, the row edge where the AEL steps down): any laser
/// whose within-pass figure binds is out of the loop's reach (head-room
/// 1e-6).
#[test]
#[ignore = "finding: the bound exceeds every cut by 1 + t_p·f_p where a one-pulse window binds"]
fn the_best_cut_reaches_the_bound_with_long_pulses() {
    let c4 = gaze_lidar_core::eye_safety::ael::c4(903.0);
    let h = 0.5 * ((7.0 + 8.0) / 100.0f64).to_degrees();
    // 3 ns pulses at 1 kHz (303 pulses in T2: C5 = 1): the bound's worst
    // window is the 5 µs row edge (where the AEL steps down), charged
    // `P·(5 µs + Δ)`: 1.005000 over the best cut (one pulse against
    // AEL(5 µs)). 10 µs pulses at 18,761 Hz: 1.187610.
    for (pulse_s, f_p) in [(3e-9, 1e3), (1e-5, 18_761.0)] {
        let (g, what) = uniform_gap(Band::RetinalNir, c4, pulse_s, f_p, 0.1, h);
        assert!(
            g <= 1.0 + 1e-6,
            "{pulse_s} s at {f_p} Hz: bound / best cut = {g}: {what}"
        );
    }
}

/// Prints how long `cuts` and the bound take on 360 bins with many pulses
/// a pass (robustness of the loop's separation step).
#[test]
#[ignore = "timing (prints)"]
fn timing_of_cuts_against_the_bound() {
    let c4 = gaze_lidar_core::eye_safety::ael::c4(903.0);
    let h = 0.5 * ((7.0 + 8.0) / 100.0f64).to_degrees();
    for (f_p, frame_s) in [(18_761.0, 0.1), (5e5, 0.1), (2e6, 0.1), (2e6, 1.0)] {
        let spin = std::f64::consts::TAU / frame_s;
        let b: Vec<(f64, f64, f64, bool)> = (0..360)
            .map(|i| {
                (
                    1.0,
                    1e-3 * (1.0 + f64::from(i % 7) / 7.0),
                    spin * (1.0 + 0.2 * f64::from(i % 3)),
                    true,
                )
            })
            .collect();
        let segs = segments(&b);
        let laser = Laser {
            band: Band::RetinalNir,
            c4,
            pulse_duration_s: 3e-9,
            pulse_rate_hz: f_p,
        };
        let t0 = std::time::Instant::now();
        let bound = evaluate(&segs, h, &laser).worst_ratio;
        let t1 = t0.elapsed().as_secs_f64();
        let t0 = std::time::Instant::now();
        let n = cuts(&segs, h, &laser, &[], 0.999 * bound).len();
        let t2 = t0.elapsed().as_secs_f64();
        eprintln!("{f_p} Hz, T_f {frame_s} s: bound {t1:.3} s ({bound:.4}), cuts {t2:.3} s ({n} cuts), ratio {:.1}", t2 / t1);
    }
}
