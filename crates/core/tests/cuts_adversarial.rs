//! Adversarial review of the optimizer's cuts (`eye_safety::cuts`): every
//! cut must stay at or under the bound's worst ratio (`bound::evaluate`)
//! for the powers it was found at, over a wider input space than
//! `tests/cuts.rs` draws from: pass angles up to and beyond 360°, bins
//! narrower than a pass and down to 1e-6 of a turn, spins from 0.01 to
//! 2,000 rad/s, pulse rates up to 2 MHz (several pulses within `T_i`),
//! pulses at and beyond `T_i`, equal neighbours (which the bound merges).

use gaze_lidar_core::eye_safety::ael::Band;
use gaze_lidar_core::eye_safety::bound::{evaluate, Laser, Seg};
use gaze_lidar_core::eye_safety::cuts::cuts;
use proptest::prelude::*;

fn profile(bins: &[(f64, f64, f64, bool)]) -> Vec<Seg> {
    let total: f64 = bins.iter().map(|b| b.0).sum();
    let n = bins.len();
    let mut start = 0.0;
    (0..n)
        .map(|i| {
            let (w, p, w0, accel) = bins[i];
            let width = 360.0 * w / total;
            let w1 = if accel { bins[(i + 1) % n].2 } else { w0 };
            let s = Seg {
                start_deg: start,
                width_deg: width,
                power_w: p,
                spin_start_rad_s: w0,
                spin_end_rad_s: w1,
            };
            start += width;
            s
        })
        .collect()
}

fn cases() -> u32 {
    std::env::var("GAZE_LIDAR_CUTS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(24)
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
        let segs = profile(&bins);
        let pulse_s = pulse_s.min(0.9 / f_p);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: pulse_s, pulse_rate_hz: f_p };
        let (r, what) = worst_excess(&segs, half_deg, &laser, &[extra]);
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
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4), 1..6),
    ) {
        let f_p = (f64::from(n) + off) / 5e-6;
        let spin = std::f64::consts::TAU / frame_s;
        let half_deg = 0.5 * (spin * k / f_p).to_degrees();
        let b: Vec<(f64, f64, f64, bool)> = bins.iter().map(|&(w, p)| (w, p, spin, false)).collect();
        let segs = profile(&b);
        let laser = Laser { band: Band::RetinalNir, c4: 1.0, pulse_duration_s: 1e-9, pulse_rate_hz: f_p };
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
/// "optimal among certifiable" fails there.
#[test]
#[ignore = "finding: T_i group cut above the bound at T_i·f_p integer"]
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
