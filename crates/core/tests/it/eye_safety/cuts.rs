//! The optimizer's cuts (`eye_safety::cuts`): valid wherever the bound
//! certifies (no cut is ever above the bound's worst ratio, on random
//! profiles of every band with steps and in-bin acceleration), tight where
//! the bound's Rule 1 binds, and worked by hand.

use gaze_lidar_core::eye_safety::ael::{self, Band};
use gaze_lidar_core::eye_safety::bound::{evaluate, Laser, Rule, Seg};
use gaze_lidar_core::eye_safety::cuts::cuts;
use proptest::prelude::*;

use gaze_lidar_core::testing::segments;

fn powers(segs: &[Seg]) -> Vec<f64> {
    segs.iter().map(|s| s.power_w).collect()
}

/// Cases per property: `GAZE_LIDAR_CUTS_CASES` (default 256; the long run
/// in `specs/optimizer.md` used more).
fn cases() -> u32 {
    std::env::var("GAZE_LIDAR_CUTS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(256)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// Validity: every cut (a concrete exposure, or the bound's Rule 1
    /// figure at one aperture) is at most the bound's worst ratio, for the
    /// powers it was found at — so a power vector the bound certifies meets
    /// every cut. Cuts are linear in the powers and the bound positively
    /// homogeneous, so one power vector per spin profile is no loss: the
    /// profiles are random in both.
    #[test]
    fn every_cut_is_at_most_the_bound(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 2.0f64..80.0, any::<bool>()), 1..16),
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
        f_p in prop_oneof![Just(1e3), 1e3f64..3e5],
        pulse_s in prop_oneof![Just(5e-9), Just(2e-6), Just(8e-6)],
        half_deg in 0.05f64..5.0,
        extra in 0.0f64..360.0,
    ) {
        let segs = segments(&bins);
        // Pulses never overlap (the model's validation): f_p·t_pulse < 1.
        let f_p = f_p.min(0.9 / pulse_s);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: pulse_s, pulse_rate_hz: f_p };
        let b = evaluate(&segs, half_deg, &laser).worst_ratio;
        let p = powers(&segs);
        let all = cuts(&segs, half_deg, &laser, &[extra], 0.0);
        prop_assert!(!all.is_empty());
        for c in &all {
            prop_assert!(c.ratio(&p, f_p) <= b, "{c:?}: {} above the bound {b}", c.ratio(&p, f_p));
            prop_assert!(c.limit_j > 0.0 && c.pulses.iter().all(|&(_, n)| n >= 1.0));
            prop_assert!(c.window_s.0 <= c.window_s.1);
        }
    }

    /// The search's pruning skips only what cannot reach the threshold:
    /// with a threshold, the cuts are exactly those at or above it among
    /// all of them (`threshold` drawn around the strongest cut's ratio).
    #[test]
    fn a_threshold_drops_only_the_cuts_below_it(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 2.0f64..80.0, any::<bool>()), 1..12),
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
        f_p in 1e3f64..1e5,
        half_deg in 0.05f64..5.0,
        share in 0.0f64..1.2,
    ) {
        let segs = segments(&bins);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let p = powers(&segs);
        let all = cuts(&segs, half_deg, &laser, &[], 0.0);
        let top = all.iter().map(|c| c.ratio(&p, f_p)).fold(0.0, f64::max);
        prop_assume!(top > 0.0);
        let t = top * share;
        let mut want: Vec<_> = all.into_iter().filter(|c| c.ratio(&p, f_p) >= t).collect();
        let mut got = cuts(&segs, half_deg, &laser, &[], t);
        let key = |c: &gaze_lidar_core::eye_safety::cuts::Cut| (c.pulses.clone(), c.limit_j.to_bits());
        want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        prop_assert_eq!(got.len(), want.len());
        for (a, b) in got.iter().zip(&want) {
            prop_assert_eq!(key(a), key(b));
        }
    }

    /// The cap for every spin no faster than a limit: on random profiles
    /// whose spins stay at or below it, the bound's Rule 1 ratio is at
    /// least the hottest bin's power over the cap.
    #[test]
    fn the_rule_one_cap_holds_at_every_spin_below_the_limit(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 2.0f64..80.0, any::<bool>()), 1..16),
        band in prop_oneof![Just(Band::RetinalNir), Just(Band::Ir1400), Just(Band::Ir1500)],
        f_p in 1e3f64..3e5,
        half_deg in 0.05f64..5.0,
        above in 1.0f64..3.0,
    ) {
        let segs = segments(&bins);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let w_max = segs
            .iter()
            .map(|s| s.spin_start_rad_s.max(s.spin_end_rad_s))
            .fold(0.0, f64::max)
            * above;
        let frame_s = gaze_lidar_core::profile::kinematics::Timeline::from_bins(&segs).period_s();
        let cap = gaze_lidar_core::eye_safety::cuts::rule_one_cap_w(&laser, half_deg, w_max, frame_s);
        let p_max = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
        let b = evaluate(&segs, half_deg, &laser);
        prop_assert!(p_max / cap <= b.ratios[0], "{} > {}", p_max / cap, b.ratios[0]);
    }

    /// Tightness where Rule 1 decides: at a constant spin the largest
    /// single-bin cut equals the bound's Rule 1 figure (to the bound's
    /// rounding margin), so the cutting-plane loop stops on the limit.
    #[test]
    fn rule_one_cuts_are_the_bound_s_figure_at_constant_spin(
        p in proptest::collection::vec(0.0f64..0.4, 2..24),
        spin in 5.0f64..200.0,
        f_p in 1e3f64..1e5,
        half_deg in 0.05f64..5.0,
    ) {
        let bins: Vec<(f64, f64, f64, bool)> = p.iter().map(|&q| (1.0, q, spin, false)).collect();
        let segs = segments(&bins);
        let laser = Laser { band: Band::RetinalNir, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let b = evaluate(&segs, half_deg, &laser);
        prop_assume!(b.ratios[0] > 0.0);
        let pw = powers(&segs);
        let best = cuts(&segs, half_deg, &laser, &[], 0.0)
            .iter()
            .filter(|c| c.rule == Rule::SinglePulse && c.pulses.len() == 1)
            .map(|c| c.ratio(&pw, f_p))
            .fold(0.0, f64::max);
        prop_assert!(best <= b.ratios[0]);
        prop_assert!(best >= b.ratios[0] * (1.0 - 1e-8), "{best} vs {}", b.ratios[0]);
    }
}

/// By hand: 905 nm, 10 kHz, 10 Hz at a constant spin (62.83 rad/s), pass
/// angle 4° (τ = 4°/3600°/s = 1.111 ms). The bound's counts: 12 pulses a
/// pass (⌊11.11⌋ + 1) and 101 passes meeting a T2 = 10 s window
/// (⌊(10 + 0.00111)/0.1⌋ + 1), N = 1,212, C5 = 5·1212^−¼ = 0.84746;
/// AEL(5 ns) = 7.7e-8·C4 J with C4 = 10^(0.002·205) = 2.5704: a pulse of
/// `p/f_p` J is held to 1.6773e-7 J, so the hottest bin's cut is
/// `p ≤ 1.6773e-3 W`. The multi-pass cut of q whole passes of 12 pulses
/// holds `12·q` pulses.
#[test]
fn a_single_pulse_cut_by_hand() {
    let spin = std::f64::consts::TAU * 10.0;
    let segs: Vec<Seg> = (0..4)
        .map(|i| Seg {
            start_deg: 90.0 * i as f64,
            width_deg: 90.0,
            power_w: if i == 1 { 2e-3 } else { 1e-3 },
            spin_start_rad_s: spin,
            spin_end_rad_s: spin,
        })
        .collect();
    let c4 = ael::c4(905.0);
    let laser = Laser {
        band: Band::RetinalNir,
        c4,
        pulse_duration_s: 5e-9,
        pulse_rate_hz: 1e4,
    };
    let n = 12.0 * 101.0;
    let c5 = 5.0 * f64::powf(n, -0.25);
    let limit = c5 * 7.7e-8 * c4;
    assert!((c4 - 2.570_395_782_768_864).abs() < 1e-12);
    assert!((limit - 1.6773e-7).abs() < 1e-10, "{limit}");
    let all = cuts(&segs, 2.0, &laser, &[], 0.0);
    let hot = all
        .iter()
        .find(|c| c.pulses == vec![(1, 1.0)] && c.rule == Rule::SinglePulse)
        .expect("bin 1's Rule 1 cut");
    assert!(
        (hot.limit_j - limit).abs() <= 1e-12 * limit,
        "{} vs {limit}",
        hot.limit_j
    );
    // A pass wholly inside bin 1 (12 pulses at the concrete clock), q = 2:
    // 24 pulses of bin 1, held to the smallest AEL over the lengths from
    // just over 0.1 s + 1.1 ms to just under 0.2 s (7e-4·C4·T^0.75 rises:
    // its value just over 0.10110 s).
    let two = all
        .iter()
        .find(|c| c.pulses == vec![(1, 24.0)])
        .expect("two whole passes of bin 1");
    let span = 11.0 / 1e4;
    let t = (0.1 + span) * (1.0 + 1e-9);
    assert!((two.window_s.0 - t).abs() < 1e-12, "{:?}", two.window_s);
    let want = 7e-4 * c4 * t.powf(0.75);
    assert!(
        (two.limit_j - want).abs() <= 1e-12 * want,
        "{} vs {want}",
        two.limit_j
    );
    assert_eq!(two.rule, Rule::T2Train);
}

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases() / 4 + 1))]

    /// As `a_threshold_drops_only_the_cuts_below_it`, where every pruning
    /// test decides: passes of a few pulses to a few hundred (every run, or
    /// the runs to and from the bins' edges), pulse rates up to MHz in
    /// 700–1050 nm (several pulses within `T_i`: the group cuts, C5 below 1
    /// at their counts), and thresholds around the strongest cut of each
    /// kind (runs, groups, whole passes), where dropping a cut it reaches
    /// shows.
    #[test]
    fn a_threshold_drops_only_the_cuts_below_it_in_every_regime(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, log_uniform(5.0, 1000.0), any::<bool>()), 1..8),
        band in prop_oneof![3 => Just(Band::RetinalNir), 1 => Just(Band::Ir1400), 1 => Just(Band::Ir1500)],
        half_deg in log_uniform(1e-3, 5.0),
        pulses in log_uniform(1.5, 300.0),
        kind in 0usize..3,
        share in prop_oneof![0.0f64..1.2, 0.999f64..1.0],
    ) {
        let segs = segments(&bins);
        let spin = segs.iter().map(|s| s.spin_start_rad_s).sum::<f64>() / segs.len() as f64;
        let f_p = (pulses * spin / (2.0 * half_deg).to_radians()).min(2e7);
        let laser = Laser { band, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let p = powers(&segs);
        let all = cuts(&segs, half_deg, &laser, &[], 0.0);
        let frame_s = gaze_lidar_core::profile::kinematics::Timeline::from_bins(&segs).period_s();
        let t_i = laser.band.t_i_s();
        let of_kind = |c: &gaze_lidar_core::eye_safety::cuts::Cut| match kind {
            // Runs within a pass (Rule 1's one-pulse cuts aside).
            0 => c.window_s.0 < frame_s && c.window_s.1 > c.window_s.0,
            // T_i groups.
            1 => c.window_s == (t_i, t_i) && c.pulses.iter().map(|e| e.1).sum::<f64>() > 1.0,
            // Whole passes.
            _ => c.window_s.0 > frame_s,
        };
        let top = all.iter().filter(|c| of_kind(c)).map(|c| c.ratio(&p, f_p)).fold(0.0, f64::max);
        prop_assume!(top > 0.0);
        let t = top * share;
        let key = |c: &gaze_lidar_core::eye_safety::cuts::Cut| (c.pulses.clone(), c.limit_j.to_bits());
        let mut want: Vec<_> = all.iter().filter(|c| c.ratio(&p, f_p) >= t).map(key).collect();
        let mut got: Vec<_> = cuts(&segs, half_deg, &laser, &[], t).iter().map(key).collect();
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        got.sort_by(|a, b| a.partial_cmp(b).unwrap());
        prop_assert_eq!(got, want);
    }

    /// The Rule 1 cuts' own threshold (`cuts_with`): with no other cut
    /// wanted, the Rule 1 cuts are exactly those of all of them at or above
    /// it, one per bin.
    #[test]
    fn the_rule_one_threshold_drops_only_rule_one_cuts_below_it(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4, 2.0f64..80.0, any::<bool>()), 1..12),
        f_p in 1e3f64..1e6,
        half_deg in 0.05f64..5.0,
        share in prop_oneof![0.0f64..1.2, Just(1.0)],
    ) {
        let segs = segments(&bins);
        let laser = Laser { band: Band::RetinalNir, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let p = powers(&segs);
        let single = gaze_lidar_core::eye_safety::cuts::cuts_with(&segs, half_deg, &laser, &[], f64::INFINITY, 0.0);
        prop_assert!(single.iter().all(|c| c.rule == Rule::SinglePulse && c.pulses.len() == 1 && c.pulses[0].1 == 1.0));
        let mut bins_cut: Vec<usize> = single.iter().map(|c| c.pulses[0].0).collect();
        bins_cut.sort_unstable();
        bins_cut.dedup();
        prop_assert_eq!(bins_cut.len(), single.len());
        let ratios: Vec<f64> = single.iter().map(|c| c.ratio(&p, f_p)).collect();
        let t1 = ratios.iter().copied().fold(0.0, f64::max) * share;
        let got = gaze_lidar_core::eye_safety::cuts::cuts_with(&segs, half_deg, &laser, &[], f64::INFINITY, t1);
        let want: Vec<_> = single.iter().zip(&ratios).filter(|(_, &r)| r >= t1).map(|(c, _)| c.clone()).collect();
        prop_assert_eq!(got, want);
    }
}

/// By hand: the Rule 1 cap at 905 nm, 10 kHz, pass angle 4°, at most 10
/// turns a second (62.83 rad/s) with a 0.1 s frame: the shortest pass is
/// 4°/3600°/s = 1.111 ms, 12 pulses a pass, 101 passes meeting T2, C5 =
/// 5·1212^−¼ = 0.84741, so a pulse may carry C5·7.7e-8·C4 = 1.6772e-7 J
/// (C4 = 2.5704): 1.6772e-3 W at 10 kHz. At 20 turns a second the pass
/// halves: 6 pulses, 101 passes (⌊(10 + 0.00056)/0.1⌋ + 1), C5 =
/// 5·606^−¼ = 1.0 (clamped), 7.7e-8·C4·1e4 = 1.9792e-3 W. And a spin
/// limit so slow that the shortest pass is the whole frame (0.111 s,
/// capped at 0.1 s): about 1,000 pulses a pass, about 100 passes meeting
/// T2, 5·N^−¼ ≈ 0.28: C5 clamped to 0.4, 0.4·7.7e-8·C4·1e4 W.
#[test]
fn the_rule_one_cap_by_hand() {
    use gaze_lidar_core::eye_safety::cuts::rule_one_cap_w;
    let c4 = ael::c4(905.0);
    let laser = Laser {
        band: Band::RetinalNir,
        c4,
        pulse_duration_s: 5e-9,
        pulse_rate_hz: 1e4,
    };
    let tau = std::f64::consts::TAU;
    let cap = rule_one_cap_w(&laser, 2.0, tau * 10.0, 0.1);
    let want = 5.0 * 1212f64.powf(-0.25) * 7.7e-8 * c4 * 1e4;
    assert!((want - 1.6772e-3).abs() < 1e-7, "{want}");
    assert!((cap - want).abs() <= 1e-12 * want, "{cap} vs {want}");
    let cap = rule_one_cap_w(&laser, 2.0, tau * 20.0, 0.1);
    let want = 7.7e-8 * c4 * 1e4;
    assert!((cap - want).abs() <= 1e-12 * want, "{cap} vs {want}");
    // Half-angle 2° at 0.1 turn/s: a pass of 0.111 s, capped at the frame.
    let cap = rule_one_cap_w(&laser, 2.0, tau * 0.1, 0.1);
    let want = 0.4 * 7.7e-8 * c4 * 1e4;
    assert!((cap - want).abs() <= 1e-12 * want, "{cap} vs {want}");
}

/// By hand: `Laser::c5` is the standard's C5 (5·N^−¼ above 600 pulses,
/// 700–1050 nm, clamped to [0.4, 1]) for pulses up to and including
/// `T_i` = 5 µs, and 1 for longer pulses; 1 outside 700–1050 nm.
#[test]
fn laser_c5_by_hand() {
    let at = |band, pulse_duration_s| Laser {
        band,
        c4: 1.0,
        pulse_duration_s,
        pulse_rate_hz: 1e3,
    };
    let c5_1212 = 5.0 * 1212f64.powf(-0.25);
    assert!((c5_1212 - 0.847_41).abs() < 1e-5);
    for p in [5e-9, 1e-6, 5e-6] {
        assert_eq!(at(Band::RetinalNir, p).c5(1212.0), c5_1212, "{p}");
        assert_eq!(at(Band::RetinalNir, p).c5(100.0), 1.0, "{p}");
        assert_eq!(at(Band::RetinalNir, p).c5(1e9), 0.4, "{p}");
    }
    for p in [5.000_001e-6, 1e-5, 1e-3] {
        assert_eq!(at(Band::RetinalNir, p).c5(1212.0), 1.0, "{p}");
    }
    assert_eq!(at(Band::Ir1400, 5e-9).c5(1212.0), 1.0);
    assert_eq!(at(Band::Ir1500, 5e-9).c5(1212.0), 1.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases() / 8 + 1))]

    /// Where only the `T_i` groups reach the threshold: 700–1050 nm at 4
    /// to 20 MHz (a group of g ≥ 21 pulses within `T_i`), passes of g + 1
    /// or g + 2 pulses (two groups a pass), 200–255 rad/s (at most 4,096
    /// whole-pass windows up to the time base, and about 800 groups in T2:
    /// C5 ≈ 0.94). The group cut, `g` pulses against `C5·AEL(T_i)`, is
    /// then above what any run of the pass can reach (`g + 2` pulses
    /// against at least `AEL(T_i)`, `(g + 2)/g < 1/0.94`) or whole passes
    /// (at most ~10⁵ per joule of a pulse, the group ~3·10⁸), so the search
    /// must keep the aperture for its groups alone: the cuts at a threshold
    /// near the strongest group cut are exactly those at or above it.
    #[test]
    fn a_threshold_keeps_the_group_cuts_where_only_they_reach_it(
        bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..0.4), 1..5),
        spin in 200.0f64..255.0,
        f_p in 4e6f64..2e7,
        extra_pulses in prop_oneof![Just(1.5f64), Just(2.5f64)],
        share in 0.9f64..1.0,
    ) {
        let total: f64 = bins.iter().map(|b| b.0).sum();
        let mut start = 0.0;
        let segs: Vec<Seg> = bins
            .iter()
            .map(|&(w, p)| {
                let width = 360.0 * w / total;
                let seg = Seg { start_deg: start, width_deg: width, power_w: p, spin_start_rad_s: spin, spin_end_rad_s: spin };
                start += width;
                seg
            })
            .collect();
        let laser = Laser { band: Band::RetinalNir, c4: 1.0, pulse_duration_s: 5e-9, pulse_rate_hz: f_p };
        let g = laser.group(f64::INFINITY);
        prop_assert!(g >= 21.0);
        let tau_s = (g - 1.0 + extra_pulses) / f_p;
        let half_deg = (tau_s * spin / 2.0).to_degrees();
        let p = powers(&segs);
        let all = cuts(&segs, half_deg, &laser, &[], 0.0);
        let t_i = laser.band.t_i_s();
        let is_group = |c: &gaze_lidar_core::eye_safety::cuts::Cut| {
            c.window_s == (t_i, t_i) && c.pulses.iter().map(|e| e.1).sum::<f64>() > 1.0
        };
        let top = all.iter().filter(|c| is_group(c)).map(|c| c.ratio(&p, f_p)).fold(0.0, f64::max);
        prop_assume!(top > 0.0);
        let t = top * share;
        let key = |c: &gaze_lidar_core::eye_safety::cuts::Cut| (c.pulses.clone(), c.limit_j.to_bits());
        let mut want: Vec<_> = all.iter().filter(|c| c.ratio(&p, f_p) >= t).map(key).collect();
        let mut got: Vec<_> = cuts(&segs, half_deg, &laser, &[], t).iter().map(key).collect();
        want.sort_by(|a, b| a.partial_cmp(b).unwrap());
        got.sort_by(|a, b| a.partial_cmp(b).unwrap());
        prop_assert_eq!(got, want);
    }
}

/// A random head: `n` channels in `groups` firing groups (channels of a
/// group fire together; the groups' slots spread over the cycle), their
/// elevations within `±spread_el`, offsets within `±spread_az`, two power
/// scales; `cycle_s` the firing cycle.
fn random_head(
    n: usize,
    groups: usize,
    cycle_s: f64,
    (spread_el, spread_az): (f64, f64),
    draws: &[f64],
) -> gaze_lidar_core::eye_safety::head::Head {
    use gaze_lidar_core::eye_safety::head::{Channel, Head};
    let d = |i: usize| draws[i % draws.len()];
    Head {
        cycle_s,
        origin_radius_mm: 40.0 * d(0),
        origin_height_mm: 0.0,
        exit_diameter_mm: 2.0 + 8.0 * d(1),
        divergence_mrad: 3.0 * d(2),
        aperture_distance_mm: 100.0,
        channels: (0..n)
            .map(|i| Channel {
                id: i as u32,
                elevation_deg: spread_el * (2.0 * d(3 * i + 3) - 1.0),
                azimuth_offset_deg: spread_az * (2.0 * d(3 * i + 4) - 1.0),
                slot_s: cycle_s * ((i % groups) as f64 / groups as f64),
                power_scale: if d(3 * i + 5) < 0.5 { 1.0 } else { 0.5 },
            })
            .collect(),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases() / 4))]

    /// With a head, every cut of `cuts_for` (single-channel cuts scaled by
    /// their own factor: the smallest any candidate of the head's energy
    /// figure puts on the cut's windows, or Rule 1's) is at most the head
    /// bound's worst ratio — at the powers it was found at and at a second
    /// random power vector of the same spins (the factors depend on the
    /// spins only, so a cut holds for every power vector the head bound
    /// certifies). Random heads of 2–40 channels in 1–16 firing groups,
    /// 905 nm (the short windows by firing slots and `T_i` groups) and
    /// 1550 nm, steps and in-bin acceleration.
    #[test]
    fn head_cuts_never_exceed_the_head_bound(
        bins in proptest::collection::vec((0.05f64..1.0, 1e-4f64..0.02, 20.0f64..120.0, any::<bool>()), 1..10),
        other in proptest::collection::vec(1e-4f64..0.02, 10),
        n in 2usize..40,
        groups in 1usize..16,
        cycle_s in 1.5e-5f64..1e-4,
        spread in (0.2f64..10.0, prop_oneof![Just(0.0), 0.0f64..20.0]),
        draws in proptest::collection::vec(0.0f64..1.0, 16..64),
        lambda in prop_oneof![Just(905.0), Just(905.0), Just(1550.0)],
        extra in 0.0f64..360.0,
    ) {
        use gaze_lidar_core::eye_safety::cuts::cuts_for;
        use gaze_lidar_core::eye_safety::{evaluate_segments, exposure, EyeSafetyParams};
        let head = random_head(n, groups.min(n), cycle_s, spread, &draws);
        let f_p = 1.0 / cycle_s;
        let params = EyeSafetyParams {
            wavelength_nm: lambda,
            pulse_duration_s: 5e-9,
            beam_diameter_mm: head.exit_diameter_mm,
            head: Some(head),
        };
        let laser = exposure::laser(&params, f_p).unwrap();
        let segs = segments(&bins);
        let b = evaluate_segments(&segs, &params, f_p).unwrap().worst_ratio;
        let all = cuts_for(&segs, &params, &laser, &[extra], 0.0, 0.0).unwrap();
        prop_assert!(!all.is_empty());
        let p = powers(&segs);
        let mut segs2 = segs.clone();
        for (s, &q) in segs2.iter_mut().zip(&other) {
            s.power_w = q;
        }
        let b2 = evaluate_segments(&segs2, &params, f_p).unwrap().worst_ratio;
        let p2 = powers(&segs2);
        for c in &all {
            prop_assert!(c.ratio(&p, f_p) <= b, "{c:?}: {} above the head bound {b}", c.ratio(&p, f_p));
            prop_assert!(c.ratio(&p2, f_p) <= b2, "{c:?}: {} above the head bound {b2} at other powers", c.ratio(&p2, f_p));
        }
    }
}
