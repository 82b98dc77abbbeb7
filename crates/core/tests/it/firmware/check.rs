//! Core-level tests of `firmware::eye` and `firmware::check` (found by
//! `cargo mutants`). The integer eye-safety evaluation of a table against its
//! integer limits is compared with a plain re-statement of the module's
//! specification (every aperture cell recomputed from scratch: every unrolled
//! bin tested against both cell ends, no prefix sums, no sliding maximum, no
//! early exits) on seeded random tables; plus hand-computed cases, the error
//! paths, and the checker's assembly of violations.

use gaze_lidar_core::testing;

use gaze_lidar_core::eye_safety::Rule;
use gaze_lidar_core::firmware::eye::{
    evaluate, millihz_ceil, pass_timing, DeriveError, IntEyeError, IntEyeLimits, IntRule,
    TrainLimit,
};
use gaze_lidar_core::firmware::{
    check_integer, check_table, check_table_with, FirmwareTable, FwViolation,
};
use std::sync::OnceLock;

const W: i64 = 360_000;

/// A table of `(width_mdeg, dwell_ticks, code)` bins; frame = Σ dwell.
fn table(tick_hz: u64, bins: &[(u32, u64, u32)]) -> FirmwareTable {
    testing::open_table(tick_hz, 100.0, Some(testing::params()), bins)
}

/// Limits for `t` with every figure given (the struct is non-exhaustive:
/// derived once for a plain table, then overwritten field by field).
fn limits(
    t: &FirmwareTable,
    millihz: u64,
    arc_mdeg: u32,
    code_max: u64,
    train: &[(u64, u64)],
    pass_max: u64,
) -> IntEyeLimits {
    static BASE: OnceLock<IntEyeLimits> = OnceLock::new();
    let mut l = BASE
        .get_or_init(|| {
            IntEyeLimits::derive(&table(1000, &[(360_000, 1000, 1)])).expect("derivable")
        })
        .clone();
    l.tick_hz = t.tick_hz;
    l.frame_ticks = t.frame_ticks;
    l.pulse_rate_millihz_ceil = millihz;
    l.pass_arc_mdeg = arc_mdeg;
    l.pass_ticks_max = u64::MAX;
    l.pulses_per_pass_max = u64::MAX;
    l.pulse_code_max = code_max;
    l.train = train
        .iter()
        .map(|&(pulses_from, energy_max_quanta)| TrainLimit {
            pulses_from,
            energy_max_quanta,
        })
        .collect();
    l.pass_energy_max_quanta = pass_max;
    l.pass_energy_rule = IntRule::T2Train;
    l
}

/// `a/b > c/d` for non-negative rationals (b, d > 0).
fn rgt(a: (u128, u128), b: (u128, u128)) -> bool {
    a.0 * b.1 > b.0 * a.1
}

/// Pulses in a closed interval of `t` ticks at `millihz`, any phase.
fn pulses(t: (u128, u128), millihz: u128, tick_hz: u128) -> u128 {
    t.0 * millihz / (t.1 * 1000 * tick_hz) + 1
}

/// One check: (energy, limit) is "greater" than another, a zero limit with
/// energy being infinite.
fn worse(a: (u128, u64), b: (u128, u64)) -> bool {
    let inf = |x: (u128, u64)| x.1 == 0 && x.0 > 0;
    match (inf(a), inf(b)) {
        (true, true) => false,
        (true, false) => a.0 > 0,
        (false, true) => false,
        (false, false) => wide(a.0, b.1) > wide(b.0, a.1),
    }
}

/// `a · b` exactly, as (the bits above 64, the low 64 bits).
fn wide(a: u128, b: u64) -> (u128, u128) {
    let lo = (a & u128::from(u64::MAX)) * u128::from(b);
    let hi = (a >> 64) * u128::from(b) + (lo >> 64);
    (hi, lo & u128::from(u64::MAX))
}

#[derive(Debug, PartialEq)]
struct Verdict {
    ppm: u64,
    rule: IntRule,
    azimuth: u32,
    class1: bool,
    pass_ticks_max: u64,
    pulses_max: u64,
}

/// The specification, cell by cell, from scratch.
fn oracle(t: &FirmwareTable, l: &IntEyeLimits) -> Verdict {
    let h = i64::from(l.pass_arc_mdeg);
    let (mhz, tick) = (u128::from(l.pulse_rate_millihz_ceil), u128::from(t.tick_hz));
    // Unrolled bins over three turns.
    let mut iv = Vec::new();
    for turn in -1..=1i64 {
        let mut s = 0i64;
        for b in &t.bins {
            let e = s + i64::from(b.width_mdeg);
            iv.push((s + turn * W, e + turn * W, b));
            s = e;
        }
    }
    let mut cuts: Vec<i64> = Vec::new();
    let mut s = 0i64;
    for b in &t.bins {
        cuts.push(s);
        cuts.push((s - h).rem_euclid(W));
        s += i64::from(b.width_mdeg);
    }
    cuts.sort_unstable();
    cuts.dedup();
    let mut worst: (u128, u64) = (0, 1);
    let (mut rule, mut azimuth, mut class1) = (IntRule::SinglePulse, 0u32, true);
    let (mut ticks_max, mut pulses_max) = (0u64, 0u64);
    for (j, &a0) in cuts.iter().enumerate() {
        let a1 = cuts.get(j + 1).copied().unwrap_or(W);
        let mut tau = [(0u128, 1u128); 2];
        let mut bins: Vec<(u32, u128)> = Vec::new();
        let mut hottest = 0u32;
        for &(s, e, b) in &iv {
            if !(e >= a0 && s <= a1 + h) {
                continue;
            }
            hottest = hottest.max(b.power_code);
            let w = e - s;
            let d = u128::from(b.dwell_ticks);
            let mut x_max: Option<i64> = None;
            for (end, a) in [a0, a1].into_iter().enumerate() {
                if !(s <= a + h && e >= a) {
                    continue;
                }
                let x = (e.min(a + h) - s.max(a)).max(0);
                x_max = Some(x_max.map_or(x, |m: i64| m.max(x)));
                let add = if w == 0 || x == w {
                    (d, 1)
                } else if x > 0 {
                    (x as u128 * d, w as u128)
                } else {
                    (0, 1)
                };
                let (n0, d0) = tau[end];
                tau[end] = (n0 * add.1 + add.0 * d0, d0 * add.1);
            }
            let cap = match x_max {
                Some(x) if w == 0 || x == w => pulses((d, 1), mhz, tick),
                Some(x) if x > 0 => pulses((x as u128 * d, w as u128), mhz, tick),
                _ => 1,
            };
            bins.push((b.power_code, cap));
        }
        let tau = if rgt(tau[1], tau[0]) { tau[1] } else { tau[0] };
        let k = pulses(tau, mhz, tick);
        ticks_max = ticks_max.max(u64::try_from(tau.0.div_ceil(tau.1)).unwrap());
        pulses_max = pulses_max.max(u64::try_from(k).unwrap());
        // G(k): the hottest pulses first, each bin at most its cap.
        bins.sort_by_key(|x| std::cmp::Reverse(x.0));
        let g = |k: u128| {
            let (mut left, mut e) = (k, 0u128);
            for &(c, cap) in &bins {
                let take = cap.min(left);
                e += u128::from(c) * take;
                left -= take;
            }
            e
        };
        let mut checks = vec![(u128::from(hottest), l.pulse_code_max, IntRule::SinglePulse)];
        for (i, b) in l.train.iter().enumerate() {
            if u128::from(b.pulses_from) > k {
                break;
            }
            let to = l
                .train
                .get(i + 1)
                .map_or(k, |n| (u128::from(n.pulses_from) - 1).min(k));
            checks.push((g(to), b.energy_max_quanta, IntRule::PassTrain));
        }
        checks.push((g(k), l.pass_energy_max_quanta, l.pass_energy_rule));
        let az = ((a0 + h / 2).rem_euclid(W)) as u32;
        for (e, lim, r) in checks {
            if e > u128::from(lim) {
                class1 = false;
            }
            if worse((e, lim), worst) {
                worst = (e, lim);
                rule = r;
                azimuth = az;
            }
        }
    }
    let ppm = if worst.0 == 0 {
        0
    } else if worst.1 == 0 {
        u64::MAX
    } else {
        worst
            .0
            .checked_mul(1_000_000)
            .and_then(|x| u64::try_from(x.div_ceil(u128::from(worst.1))).ok())
            .unwrap_or(u64::MAX)
    };
    Verdict {
        ppm,
        rule,
        azimuth,
        class1,
        pass_ticks_max: ticks_max,
        pulses_max,
    }
}

fn run(t: &FirmwareTable, l: &IntEyeLimits) -> Verdict {
    let r = evaluate(t, l).expect("within bounds");
    let p = pass_timing(t, l.pulse_rate_millihz_ceil, l.pass_arc_mdeg).expect("within bounds");
    Verdict {
        ppm: r.worst_ratio_ppm,
        rule: r.rule,
        azimuth: r.azimuth_mdeg,
        class1: r.class1,
        pass_ticks_max: p.pass_ticks_max,
        pulses_max: p.pulses_per_pass_max,
    }
}

/// xorshift64*: a fixed, seeded stream (no dependency on a test RNG).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

#[test]
fn evaluate_matches_the_specification_cell_by_cell() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let (mut rejected, mut accepted, mut multi_bucket) = (0, 0, 0);
    for case in 0..1500 {
        let n = 1 + rng.below(12) as usize;
        // Widths: random cut points of the turn (zero widths allowed).
        let mut cut: Vec<u32> = (1..n).map(|_| rng.below(360_001) as u32).collect();
        if case % 3 == 0 {
            // Round cuts: many coincident breakpoints.
            for c in &mut cut {
                *c = *c / 30_000 * 30_000;
            }
        }
        cut.sort_unstable();
        let mut bins = Vec::new();
        let mut prev = 0;
        for &c in cut.iter().chain(&[360_000]) {
            let w = c - prev;
            prev = c;
            let dwell = if w == 0 {
                rng.below(3)
            } else {
                1 + rng.below(400)
            };
            bins.push((w, dwell, rng.below(60) as u32));
        }
        let t = table(1 + rng.below(5000), &bins);
        let millihz = 1 + rng.below(2_000_000);
        let arc = if case % 4 == 0 {
            30_000 * (1 + rng.below(5) as u32)
        } else {
            1 + rng.below(179_999) as u32
        };
        // Each limit: loose (above anything the table can reach) three
        // times in four, else random below that.
        let hot = u64::from(bins.iter().map(|b| b.2).max().unwrap());
        let k = pass_timing(&t, millihz, arc).unwrap().pulses_per_pass_max;
        let pick = |rng: &mut Rng, top: u64| {
            if rng.below(4) == 0 {
                rng.below(top + 1)
            } else {
                top + rng.below(10)
            }
        };
        let code_max = pick(&mut rng, hot);
        let mut froms = vec![1u64];
        for _ in 0..rng.below(4) {
            let last = *froms.last().unwrap();
            froms.push(last + 1 + rng.below(k.min(1000) / 3 + 1));
        }
        let mut train: Vec<(u64, u64)> = Vec::new();
        for (i, &from) in froms.iter().enumerate() {
            let to = froms.get(i + 1).map_or(k, |n| n - 1).min(k);
            let floor = train.last().map_or(0, |x| x.1);
            train.push((from, floor.max(pick(&mut rng, hot * to))));
        }
        let pass_max = pick(&mut rng, hot * k);
        let l = limits(&t, millihz, arc, code_max, &train, pass_max);
        let want = oracle(&t, &l);
        assert_eq!(run(&t, &l), want, "case {case}: {bins:?} {l:?}");
        if want.class1 {
            accepted += 1;
        } else {
            rejected += 1;
        }
        if want.rule == IntRule::PassTrain && train.len() > 1 {
            multi_bucket += 1;
        }
    }
    assert!(
        accepted > 50 && rejected > 50 && multi_bucket > 20,
        "{accepted} {rejected} {multi_bucket}"
    );
}

/// Four 90° bins of 250 ticks at 1 kHz (one turn per second), 100 Hz pulses,
/// a 10° pass: the pass lasts 10/90·250 = 27.8 ticks and holds
/// ⌊27.8·0.1⌋ + 1 = 3 pulses; inside bin 1 (code 5) they carry 15 quanta.
#[test]
fn hand_computed_four_bins() {
    let t = table(
        1000,
        &[
            (90_000, 250, 1),
            (90_000, 250, 5),
            (90_000, 250, 2),
            (90_000, 250, 3),
        ],
    );
    let l =
        |code_max, train: &[(u64, u64)], pass| limits(&t, 100_000, 10_000, code_max, train, pass);
    let p = pass_timing(&t, 100_000, 10_000).unwrap();
    assert_eq!((p.pass_ticks_max, p.pulses_per_pass_max), (28, 3));
    // Rule 1: code 5 against 4 → 1.25; first met by the cell [0°, 80°]
    // whose end touches bin 1 (pass centre 5°).
    let r = evaluate(&t, &l(4, &[(1, 100)], 100)).unwrap();
    assert_eq!(
        (r.worst_ratio_ppm, r.rule, r.azimuth_mdeg, r.class1),
        (1_250_000, IntRule::SinglePulse, 5_000, false)
    );
    // At the limit: Class 1, ratio exactly 1.
    let r = evaluate(&t, &l(5, &[(1, 15)], 15)).unwrap();
    assert_eq!((r.worst_ratio_ppm, r.class1), (1_000_000, true));
    // Pass energy: G(3) = 15 against 12 → 1.25, first from the cell
    // [80°, 90°] (centre 85°), whose end has the pass wholly in bin 1 (its
    // cap: 3 pulses); in [0°, 80°] bin 1 is only touched (cap 1):
    // G(3) = 5 + 3 + 1. The pulse and train limits are loose.
    let r = evaluate(&t, &l(50, &[(1, 500)], 12)).unwrap();
    assert_eq!(
        (r.worst_ratio_ppm, r.rule, r.azimuth_mdeg, r.class1),
        (1_250_000, IntRule::T2Train, 85_000, false)
    );
    // Train buckets {1}, {2, 3}: G(1) = 5 against 4 and G(3) = 15 against 10
    // → the second (1.5) is the worst; a one-pulse bucket ratio is 1.25.
    let r = evaluate(&t, &l(50, &[(1, 4), (2, 10)], 1000)).unwrap();
    assert_eq!(
        (r.worst_ratio_ppm, r.rule, r.azimuth_mdeg, r.class1),
        (1_500_000, IntRule::PassTrain, 85_000, false)
    );
    // A ratio that does not divide: 15/7 → ⌈2,142,857.14⌉.
    let r = evaluate(&t, &l(50, &[(1, 500)], 7)).unwrap();
    assert_eq!(r.worst_ratio_ppm, 2_142_858);
    // A zero limit with energy: infinite.
    let r = evaluate(&t, &l(0, &[(1, 500)], 500)).unwrap();
    assert_eq!((r.worst_ratio_ppm, r.class1), (u64::MAX, false));
    // All codes zero: ratio 0, Class 1 even at zero limits.
    let z = table(
        1000,
        &[
            (90_000, 250, 0),
            (90_000, 250, 0),
            (90_000, 250, 0),
            (90_000, 250, 0),
        ],
    );
    let r = evaluate(&z, &limits(&z, 100_000, 10_000, 0, &[(1, 0)], 0)).unwrap();
    assert_eq!((r.worst_ratio_ppm, r.class1), (0, true));
}

/// Two checks whose ratios round to the same ppm: the exactly larger one is
/// reported (compared by cross-multiplication, not by rounded ppm). One 360°
/// bin of 1000 ticks at 1 kHz, 100 Hz pulses, a 10° pass: 27.8 ticks, 3
/// pulses. Code 10,000,001 against 10,000,000: 1.0000001 (⌈1,000,000.1⌉ =
/// 1,000,001 ppm); bucket {1}: the same ratio (a tie: the first is kept);
/// bucket {2, 3}: G(3) = 30,000,003 against 29,999,999 = 1.00000013…,
/// also 1,000,001 ppm but larger, so the within-pass rule is the worst.
#[test]
fn ratios_equal_to_the_ppm_are_still_ordered_exactly() {
    let t = table(1000, &[(360_000, 1000, 10_000_001)]);
    let l = limits(
        &t,
        100_000,
        10_000,
        10_000_000,
        &[(1, 10_000_000), (2, 29_999_999)],
        1 << 40,
    );
    let r = evaluate(&t, &l).unwrap();
    assert_eq!(
        (r.worst_ratio_ppm, r.rule, r.azimuth_mdeg, r.class1),
        (1_000_001, IntRule::PassTrain, 5_000, false)
    );
    // Bucket {2, 3} at 30,000,000: 1.0000001, a tie with rule 1, which came first.
    let l = limits(
        &t,
        100_000,
        10_000,
        10_000_000,
        &[(1, 10_000_000), (2, 30_000_000)],
        1 << 40,
    );
    let r = evaluate(&t, &l).unwrap();
    assert_eq!(
        (r.worst_ratio_ppm, r.rule, r.azimuth_mdeg, r.class1),
        (1_000_001, IntRule::SinglePulse, 5_000, false)
    );
}

/// A pass wider than several bins: the middle bins count all their pulses.
/// Twelve 30° bins of 100 ticks (1 kHz, 1.2 s per turn), 10 Hz pulses, a 95°
/// pass: τ = 95/30·100 = 316.7 ticks → ⌊3.167⌋ + 1 = 4 pulses; each whole bin
/// holds ⌊100·0.01⌋ + 1 = 2. One hot bin (code 9) among code 1: G(4) = 9·2 + 1·2.
#[test]
fn hand_computed_wide_pass() {
    let mut bins = vec![(30_000, 100, 1); 12];
    bins[6].2 = 9;
    let t = table(1000, &bins);
    let p = pass_timing(&t, 10_000, 95_000).unwrap();
    assert_eq!((p.pass_ticks_max, p.pulses_per_pass_max), (317, 4));
    let r = evaluate(&t, &limits(&t, 10_000, 95_000, 100, &[(1, 1000)], 10)).unwrap();
    assert_eq!((r.worst_ratio_ppm, r.class1), (2_000_000, false));
}

#[test]
fn mismatched_or_out_of_bounds_inputs_are_errors() {
    let t = table(1000, &[(180_000, 500, 3), (180_000, 500, 4)]);
    let ok = limits(&t, 100_000, 10_000, 10, &[(1, 10)], 10);
    assert!(evaluate(&t, &ok).is_ok());
    let mismatch = |f: fn(&mut IntEyeLimits)| {
        let mut l = ok.clone();
        f(&mut l);
        evaluate(&t, &l).unwrap_err()
    };
    assert_eq!(
        mismatch(|l| l.tick_hz = 999),
        IntEyeError::Mismatch {
            field: "tick_hz",
            found: 1000,
            allowed: 999
        }
    );
    assert_eq!(
        mismatch(|l| l.frame_ticks = 999),
        IntEyeError::Mismatch {
            field: "frame_ticks",
            found: 1000,
            allowed: 999
        }
    );
    // A 10° pass over 180° bins of 500 ticks lasts 27.8 ticks, 3 pulses.
    assert!(matches!(
        mismatch(|l| l.pass_ticks_max = 27),
        IntEyeError::Mismatch {
            field: "pass duration (ticks)",
            found: 28,
            allowed: 27
        }
    ));
    let mut at = ok.clone();
    at.pass_ticks_max = 28;
    at.pulses_per_pass_max = 3;
    assert!(evaluate(&t, &at).is_ok());
    assert!(matches!(
        mismatch(|l| l.pulses_per_pass_max = 2),
        IntEyeError::Mismatch {
            field: "pulses per pass",
            found: 3,
            allowed: 2
        }
    ));
    // Train buckets: must start at 1, increase, never decrease their limits.
    for bad in [
        vec![],
        vec![(2, 10)],
        vec![(1, 10), (1, 12)],
        vec![(1, 10), (3, 9)],
    ] {
        let mut l = ok.clone();
        l.train = bad
            .iter()
            .map(|&(pulses_from, energy_max_quanta)| TrainLimit {
                pulses_from,
                energy_max_quanta,
            })
            .collect();
        assert!(
            matches!(
                evaluate(&t, &l),
                Err(IntEyeError::Bounds { field: "train", .. })
            ),
            "{bad:?}"
        );
    }
    let mut l = ok.clone();
    l.train = vec![
        TrainLimit {
            pulses_from: 1,
            energy_max_quanta: 10,
        },
        TrainLimit {
            pulses_from: 2,
            energy_max_quanta: 10,
        },
    ];
    assert!(evaluate(&t, &l).is_ok());
}

fn bounds_field(t: &FirmwareTable, millihz: u64, arc: u32) -> Option<&'static str> {
    match pass_timing(t, millihz, arc) {
        Ok(_) => None,
        Err(IntEyeError::Bounds { field, .. }) => Some(field),
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn evaluation_bounds_by_hand() {
    let t = table(1000, &[(180_000, 500, 3), (180_000, 500, 4)]);
    assert_eq!(bounds_field(&t, 100_000, 10_000), None);
    // Pass arc: 1 ..< 180,000 mdeg.
    assert_eq!(bounds_field(&t, 100_000, 0), Some("pass arc (mdeg)"));
    assert_eq!(bounds_field(&t, 100_000, 179_999), None);
    assert_eq!(bounds_field(&t, 100_000, 180_000), Some("pass arc (mdeg)"));
    // Pulse rate: 1 ..= 2^40 mHz.
    assert_eq!(bounds_field(&t, 0, 10_000), Some("pulse_rate_hz (mHz)"));
    assert_eq!(bounds_field(&t, 1, 10_000), None);
    // 2^40 mHz at 1 s per turn is 2^40/1000 pulses per turn: fine.
    assert_eq!(bounds_field(&t, 1 << 40, 10_000), None);
    assert_eq!(
        bounds_field(&t, (1 << 40) + 1, 10_000),
        Some("pulse_rate_hz (mHz)")
    );
    // Pulses per turn < 2^40: a turn of 2^44 ticks at 1 Hz tick and 2^40 mHz.
    let mut long = table(1, &[(360_000, 1 << 44, 1)]);
    assert_eq!(bounds_field(&long, 62, 10_000), None);
    assert_eq!(bounds_field(&long, 63, 10_000), Some("pulses per turn"));
    // Exactly 2^40 pulses per turn is refused: 2^44 ticks at 2 Hz, 125 mHz.
    let mut even = table(2, &[(360_000, 1 << 44, 1)]);
    assert_eq!(bounds_field(&even, 124, 10_000), None);
    assert_eq!(bounds_field(&even, 125, 10_000), Some("pulses per turn"));
    even.tick_hz = 1;
    assert_eq!(bounds_field(&even, 62, 10_000), None);
    long.bins[0].dwell_ticks = (1 << 44) + 1;
    long.frame_ticks = (1 << 44) + 1;
    assert_eq!(bounds_field(&long, 1, 10_000), Some("frame_ticks"));
    // tick_hz: 1 ..= 2^34.
    let mut fast = t.clone();
    fast.tick_hz = 1 << 34;
    assert_eq!(bounds_field(&fast, 1000, 10_000), None);
    fast.tick_hz = (1 << 34) + 1;
    assert_eq!(bounds_field(&fast, 1000, 10_000), Some("tick_hz"));
    fast.tick_hz = 0;
    assert_eq!(bounds_field(&fast, 1000, 10_000), Some("tick_hz"));
    // Dwell and width sums, a bin with width and no dwell, bin counts.
    let mut bad = t.clone();
    bad.frame_ticks = 999;
    assert_eq!(bounds_field(&bad, 1000, 10_000), Some("dwell_ticks"));
    let bad = table(1000, &[(180_000, 500, 3), (179_999, 500, 4)]);
    assert_eq!(bounds_field(&bad, 1000, 10_000), Some("width_mdeg"));
    let bad = table(1000, &[(180_000, 1000, 3), (180_000, 0, 4)]);
    assert_eq!(bounds_field(&bad, 1000, 10_000), Some("dwell_ticks"));
    let zero = table(1000, &[(360_000, 1000, 3), (0, 0, 4)]);
    assert_eq!(bounds_field(&zero, 1000, 10_000), None);
    let empty = table(1000, &[]);
    assert_eq!(bounds_field(&empty, 1000, 10_000), Some("bins"));
    let mut frame0 = table(1000, &[(360_000, 0, 3)]);
    frame0.frame_ticks = 0;
    assert_eq!(bounds_field(&frame0, 1000, 10_000), Some("frame_ticks"));
    let mut most = vec![(10, 1, 0); 36_000];
    most[0].0 = 360_000 - 35_999 * 10;
    assert_eq!(bounds_field(&table(1000, &most), 1000, 10_000), None);
    let many = table(1000, &vec![(10, 1, 0); 36_001]);
    assert_eq!(bounds_field(&many, 1000, 10_000), Some("bins"));
}

#[test]
fn check_table_with_reports_the_integer_verdict() {
    let t = table(
        1000,
        &[
            (90_000, 250, 1),
            (90_000, 250, 5),
            (90_000, 250, 2),
            (90_000, 250, 3),
        ],
    );
    // As in `hand_computed_four_bins`: code 5 against 4.
    let over = limits(&t, 100_000, 10_000, 4, &[(1, 100)], 100);
    assert_eq!(
        check_table_with(&t, &over),
        vec![FwViolation::EyeSafety {
            ratio_ppm: 1_250_000,
            azimuth_mdeg: 5_000,
            rule: Rule::SinglePulse,
        }]
    );
    let at = limits(&t, 100_000, 10_000, 5, &[(1, 15)], 15);
    assert_eq!(check_table_with(&t, &at), vec![]);
    let mut other = at.clone();
    other.tick_hz = 999;
    assert_eq!(
        check_table_with(&t, &other),
        vec![FwViolation::EyeSafetyParams {
            reason:
                "eye-safety limits do not apply to this table: tick_hz is 1000, limits allow 999"
                    .into(),
        }]
    );
    // Integer violations come first, the eye-safety one after.
    let mut bad = t.clone();
    bad.limits.power_code_max = 4;
    assert_eq!(
        check_table_with(&bad, &over),
        vec![
            FwViolation::PowerCode { bin: 1, code: 5 },
            FwViolation::EyeSafety {
                ratio_ppm: 1_250_000,
                azimuth_mdeg: 5_000,
                rule: Rule::SinglePulse,
            }
        ]
    );
    // No bins: that alone, after the header's zero-tick frame.
    let empty = table(1000, &[]);
    let zero_frame = FwViolation::Header {
        field: "frame_ticks",
        value: "0".into(),
        reason: "must be >= 1 (a frame lasts at least one tick)",
    };
    assert_eq!(
        check_table_with(&empty, &at),
        vec![zero_frame.clone(), FwViolation::BinCount { count: 0 }]
    );
    assert_eq!(
        check_table(&empty),
        vec![zero_frame, FwViolation::BinCount { count: 0 }]
    );
}

#[test]
fn check_table_derives_limits_or_says_why_not() {
    // 1e-7 W per code at 100 Hz, codes ≤ 5: pulses of at most 5e-9 J, far
    // below the 1.98e-7 J single-pulse AEL at 905 nm (and 0.5 µW ≪ 1 mW).
    let mut t = table(
        1000,
        &[
            (90_000, 250, 1),
            (90_000, 250, 5),
            (90_000, 250, 2),
            (90_000, 250, 3),
        ],
    );
    t.power_w_per_code = 1e-7;
    assert_eq!(check_table(&t), vec![]);
    // 2 W per code: 20 mJ pulses, far over.
    let mut hot = t.clone();
    hot.power_w_per_code = 2.0;
    let v = check_table(&hot);
    assert!(
        matches!(v.as_slice(), [FwViolation::EyeSafety { ratio_ppm, .. }] if *ratio_ppm > 1_000_000),
        "{v:?}"
    );
    let mut none = t.clone();
    none.eye_safety = None;
    assert_eq!(check_table(&none), vec![FwViolation::EyeSafetyMissing]);
    let mut no_rate = t.clone();
    no_rate.pulse_rate_hz = 0.0;
    // A pulse rate of 0 stops at the header boundary (eye safety, which
    // reads it, is not evaluated).
    let v = check_table(&no_rate);
    assert!(
        matches!(
            v.as_slice(),
            [FwViolation::Header {
                field: "pulse_rate_hz",
                ..
            }]
        ),
        "{v:?}"
    );
    // Integer violations are kept alongside.
    let mut both = none.clone();
    both.frame_ticks = 999;
    assert_eq!(
        check_table(&both),
        vec![
            FwViolation::FrameTicks {
                sum: 1000,
                frame_ticks: 999
            },
            FwViolation::EyeSafetyMissing
        ]
    );
}

#[test]
fn bin_count_limit_is_inclusive() {
    let mut t = table(1000, &vec![(10, 1, 0); 36_000]);
    assert!(
        check_integer(&t).is_empty(),
        "{:?}",
        check_integer(&t).first()
    );
    t.bins.push(t.bins[0].clone());
    assert_eq!(
        check_integer(&t),
        vec![FwViolation::BinCount { count: 36_001 }]
    );
}

#[test]
fn violations_read_as_stated() {
    let s = |v: FwViolation| v.to_string();
    assert_eq!(
        s(FwViolation::FrameTicks {
            sum: 3,
            frame_ticks: 4
        }),
        "dwell_ticks sum to 3, frame_ticks is 4"
    );
    assert_eq!(
        s(FwViolation::EyeSafety {
            ratio_ppm: 1_250_000,
            azimuth_mdeg: 5_000,
            rule: Rule::TimeBase
        }),
        "eye_safety: as quantized, at azimuth 5.000° the average power over the 100 s time base is 125.0000 % of the Class 1 limit"
    );
    assert_eq!(
        s(FwViolation::BinCount { count: 0 }),
        "bins: 0; a table needs 1 to 36000"
    );
}

/// The integer limits of the four-bin table, worked out by hand: 905 nm,
/// 5 ns, 8 mm beam, 100 Hz, 1e-7 W per code → quantum q = 1e-9 J,
/// C4 = 10^0.41.
/// - pass arc: 2·asin(7.5/100) = 8.60244° → 8603 mdeg; pass 8603/90000·250 =
///   23.897 ticks → 24; ⌊2.3897⌋ + 1 = 3 pulses;
/// - rule 1: N = 3 · (⌊(10,000 + 24)/1000⌋ + 1) = 33 ≤ 600, C5 = 1, one
///   pulse per T_i: ⌊7.7e-8·C4/q⌋ = ⌊197.92⌋;
/// - train: k pulses span (k − 1)/100 s; AEL_inf(0) = AEL(5 µs edge) =
///   7e-4·C4·(5e-6)^0.75 = 190.25 q; 7e-4·C4·0.01^0.75 = 56898.1 q;
///   7e-4·C4·0.02^0.75 = 95690.9 q;
/// - several passes: m passes span (m − 1)·1 s − 24 ticks; the least
///   AEL/m is at m = 2: 7e-4·C4·0.976^0.75 = 1766791.9 q, / 2 → 883395,
///   within T2.
#[test]
fn derived_limits_by_hand() {
    let mut t = table(
        1000,
        &[
            (90_000, 250, 1),
            (90_000, 250, 5),
            (90_000, 250, 2),
            (90_000, 250, 3),
        ],
    );
    t.power_w_per_code = 1e-7;
    let l = IntEyeLimits::derive(&t).unwrap();
    assert_eq!((l.tick_hz, l.frame_ticks), (1000, 1000));
    assert_eq!(
        (l.pulse_rate_millihz_ceil, l.pass_arc_mdeg),
        (100_000, 8_603)
    );
    assert_eq!((l.pass_ticks_max, l.pulses_per_pass_max), (24, 3));
    assert_eq!(l.pulse_code_max, 197);
    let train: Vec<(u64, u64)> = l
        .train
        .iter()
        .map(|b| (b.pulses_from, b.energy_max_quanta))
        .collect();
    assert_eq!(train, vec![(1, 190), (2, 56_898), (3, 95_690)]);
    assert_eq!(
        (l.pass_energy_max_quanta, l.pass_energy_rule),
        (883_395, IntRule::T2Train)
    );
}

/// A 20 s turn (four bins of 5000 ticks at 1 kHz): the pass lasts
/// 8603/90000·5000 = 477.9 ticks → 478, ⌊47.79⌋ + 1 = 48 pulses, one pass per
/// T2 window; two passes span at least 20 s − 0.478 s = 19.522 s, past T2:
/// 3.9e-4·C4·19.522 = 19569913.9 q, / 2 = 9784956 (the time-base rule). The
/// 48th pulse bucket: 7e-4·C4·0.47^0.75 = 1021342.6 q.
#[test]
fn derived_limits_of_a_slow_turn_by_hand() {
    let mut t = table(
        1000,
        &[
            (90_000, 5000, 1),
            (90_000, 5000, 5),
            (90_000, 5000, 2),
            (90_000, 5000, 3),
        ],
    );
    t.power_w_per_code = 1e-7;
    let l = IntEyeLimits::derive(&t).unwrap();
    assert_eq!((l.pass_ticks_max, l.pulses_per_pass_max), (478, 48));
    assert_eq!(l.pulse_code_max, 197);
    assert_eq!(l.train.len(), 48);
    let last = l.train[47];
    assert_eq!((last.pulses_from, last.energy_max_quanta), (48, 1_021_342));
    assert_eq!(
        (l.pass_energy_max_quanta, l.pass_energy_rule),
        (9_784_956, IntRule::TimeBase)
    );
}

/// More pulses per pass than `EXACT_PULSE_BUCKETS` (256): the slow turn of
/// `derived_limits_of_a_slow_turn_by_hand` at 2 kHz pulses: the pass holds
/// ⌊477.5·2⌋ + 1 = 956 pulses. Buckets start at every count up to 511
/// (511 buckets; from 256 on the step is ⌊k/256⌋ = 1), then every second
/// count 512…766 (128), then every third from 768 until the first start
/// ≥ 956: 768 + 3·63 = 957 (64): 703 buckets. Bucket 957 holds windows of
/// at least 956 pulse periods: ⌊7e-4·C4·0.478^0.75/q·(1 − 10⁻⁹)⌋, q = 1e-7 W / 2 kHz.
#[test]
fn derived_buckets_grow_beyond_256_pulses_by_hand() {
    let mut t = table(1000, &[(90_000, 5000, 1); 4]);
    t.pulse_rate_hz = 2000.0;
    t.power_w_per_code = 1e-7;
    let l = IntEyeLimits::derive(&t).unwrap();
    assert_eq!(l.pulses_per_pass_max, 956);
    let starts: Vec<u64> = l.train.iter().map(|b| b.pulses_from).collect();
    assert_eq!(starts.len(), 703);
    assert_eq!(starts[..3], [1, 2, 3]);
    assert_eq!(starts[254..258], [255, 256, 257, 258]);
    assert_eq!(starts[509..513], [510, 511, 512, 514]);
    assert_eq!(starts[637..641], [764, 766, 768, 771]);
    assert_eq!(starts[702], 957);
    let q = 1e-7 / 2000.0;
    let want = (7e-4 * c4_905() * 0.478f64.powf(0.75) / q * (1.0 - 1e-9)).floor() as u64;
    assert_eq!(l.train[702].energy_max_quanta, want);
    // 7e-4 · 2.5704 · 0.5749 / 5e-11 ≈ 2.0688e7.
    assert_eq!(l.train[702].energy_max_quanta, 20_687_068);
}

/// C4 at 905 nm (Table 9), by hand: 10^(0.002·205).
fn c4_905() -> f64 {
    10f64.powf(0.41)
}

/// Rule 1 with C5 < 1: ten turns a second (four 90° bins of 25 ticks at
/// 1 kHz), 10 kHz pulses, q = 1e-7 W / 10^4 Hz = 1e-11 J. The pass lasts
/// 8603/90000·25 = 2.3897 ticks → 3, holds ⌊23.897⌋ + 1 = 24 pulses; a T2
/// window meets ⌊(10,000 + 3)/100⌋ + 1 = 101 passes: N = 2424 > 600, C5 =
/// 5·2424^−¼ = 0.7126; pulses 100 µs apart, one per T_i = 5 µs. So
/// pulse_code_max = ⌊(1 − 10⁻⁹)·C5·7.7e-8·C4/q⌋ = ⌊14,103.6⌋.
#[test]
fn derived_pulse_limit_with_c5_by_hand() {
    let mut t = table(1000, &[(90_000, 25, 1); 4]);
    t.pulse_rate_hz = 10_000.0;
    t.power_w_per_code = 1e-7;
    let l = IntEyeLimits::derive(&t).unwrap();
    assert_eq!(l.pulse_rate_millihz_ceil, 10_000_000);
    assert_eq!((l.pass_ticks_max, l.pulses_per_pass_max), (3, 24));
    let c5 = 5.0 * 2424f64.powf(-0.25);
    assert!((0.712..0.713).contains(&c5));
    let want = ((1.0 - 1e-9) * c5 * 7.7e-8 * c4_905() / 1e-11).floor() as u64;
    assert_eq!(want, 14_103);
    assert_eq!(l.pulse_code_max, want);
}

/// Every integer limit loses `LIMIT_MARGIN` (10⁻⁹) before it is rounded
/// down: a limit that is a whole number of quanta (to float precision)
/// becomes one less. The four-bin table of `derived_limits_by_hand` with the
/// step chosen so that q is 1/1000 of (a) the single-pulse AEL 7.7e-8·C4
/// (C5 = 1) and (b) AEL_inf(0) = 7e-4·C4·(5 µs)^0.75 (the first bucket).
#[test]
fn derived_limits_lose_the_margin_on_whole_numbers() {
    let mut t = table(
        1000,
        &[
            (90_000, 250, 1),
            (90_000, 250, 5),
            (90_000, 250, 2),
            (90_000, 250, 3),
        ],
    );
    // q = step / 100 Hz.
    t.power_w_per_code = 7.7e-8 * c4_905() / 1000.0 * 100.0;
    let l = IntEyeLimits::derive(&t).unwrap();
    assert_eq!(l.pulse_code_max, 999);
    t.power_w_per_code = 7e-4 * c4_905() * 5e-6f64.powf(0.75) / 1000.0 * 100.0;
    let l = IntEyeLimits::derive(&t).unwrap();
    assert_eq!(
        l.train[0],
        TrainLimit {
            pulses_from: 1,
            energy_max_quanta: 999
        }
    );
}

#[test]
fn derive_refuses_what_it_cannot_bound() {
    let mut t = table(1000, &[(360_000, 1000, 1)]);
    t.eye_safety = None;
    assert_eq!(IntEyeLimits::derive(&t), Err(DeriveError::Missing));
    let mut t = table(1000, &[(360_000, 1000, 1)]);
    t.power_w_per_code = 0.0;
    assert!(matches!(
        IntEyeLimits::derive(&t),
        Err(DeriveError::Range {
            field: "power_w_per_code",
            ..
        })
    ));
    t.power_w_per_code = f64::NAN;
    assert!(matches!(
        IntEyeLimits::derive(&t),
        Err(DeriveError::Range {
            field: "power_w_per_code",
            ..
        })
    ));
    // A 10 µs turn (10 ticks at 1 MHz): 10^7 + 2 passes in 100 s, refused.
    let t = table(1_000_000, &[(360_000, 10, 1)]);
    assert!(matches!(
        IntEyeLimits::derive(&t),
        Err(DeriveError::Range {
            field: "frame_ticks",
            ..
        })
    ));
}

#[test]
fn millihz_ceil_by_hand() {
    assert_eq!(millihz_ceil(100.0), Some(100_000));
    // 0.125 Hz is exact in binary: 125 mHz.
    assert_eq!(millihz_ceil(0.125), Some(125));
    // The double nearest 0.1 is 0.1000000000000000055…, so f·1000 exceeds
    // 100 mHz (the product rounds to 100.0; the residual is positive).
    assert_eq!(millihz_ceil(0.1), Some(101));
    assert_eq!(millihz_ceil(1.0005), Some(1001));
    assert_eq!(millihz_ceil(0.0), None);
    assert_eq!(millihz_ceil(-1.0), None);
    assert_eq!(millihz_ceil(f64::NAN), None);
    assert_eq!(millihz_ceil(1.8e16), None);
    assert_eq!(millihz_ceil(1e16), Some(10_000_000_000_000_000_000));
}

/// Tables at the magnitudes the evaluation is bounded for (codes near 2^32,
/// turns of up to 2^44 ticks, up to 2^40 pulses per turn, limits near 2^64):
/// the energy × limit cross products overflow `u128`, and the worst ratio
/// and verdict still match the specification compared exactly (in 192 bits).
#[test]
fn evaluate_matches_the_specification_at_extreme_magnitudes() {
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    for case in 0..300 {
        let n = 1 + rng.below(4) as usize;
        let mut cut: Vec<u32> = (1..n).map(|_| rng.below(360_001) as u32).collect();
        cut.sort_unstable();
        let tick_hz = 1 + rng.below(4);
        let frame = (1u64 << 44) - rng.below(1 << 40);
        let mut bins = Vec::new();
        let (mut prev, mut left) = (0, frame);
        for (i, &c) in cut.iter().chain(&[360_000]).enumerate() {
            let w = c - prev;
            prev = c;
            let dwell = if i + 1 == n {
                left
            } else {
                1 + rng.below(left - (n - i) as u64)
            };
            left -= dwell;
            bins.push((w, dwell, u32::MAX - rng.below(1 << 20) as u32));
        }
        // Fewer than 2^40 pulses per turn.
        let most = ((1u128 << 40) * 1000 * u128::from(tick_hz) - 1) / u128::from(frame);
        let millihz = 1 + rng.below(u64::try_from(most).unwrap());
        let t = table(tick_hz, &bins);
        let arc = 1 + rng.below(179_999) as u32;
        let big = |rng: &mut Rng| rng.next() >> rng.below(24);
        let (a, b, c, d) = (big(&mut rng), big(&mut rng), big(&mut rng), big(&mut rng));
        let code_max = rng.next() >> 31;
        let train = [(1, a.min(b)), (2 + rng.below(1000), a.max(b))];
        let l = limits(&t, millihz, arc, code_max, &train, c.min(d));
        let (got, want) = (run(&t, &l), oracle(&t, &l));
        assert_eq!(
            (got.ppm, got.class1, got.pass_ticks_max, got.pulses_max),
            (want.ppm, want.class1, want.pass_ticks_max, want.pulses_max),
            "case {case}: {bins:?} {l:?}"
        );
    }
}

/// A bin touched by the pass only at the cell's start (its end is the
/// cell's first azimuth) still lends the pass one pulse at its code (the code
/// at a boundary instant is ambiguous). Bins, 10 ticks per degree at 1 kHz:
/// P = [0°, 10°) code 5, Q = [10°, 100°) code 0, R = [100°, 110°) code 9,
/// S = [110°, 360°) code 0; a 95° pass (950 ticks, 10 pulses at 10 Hz).
/// In the cell [10°, 15°] the pass holds all of R (100 ticks: 2 pulses) and
/// touches P at 10°: G(10) = 2·9 + 5 = 23 (centre 10° + 47.5°). Elsewhere at
/// most 2·5 + 9 = 19 (the cell [0°, 5°]: all of P, R touched at 100°).
#[test]
fn a_bin_touched_at_the_cell_start_counts_one_pulse() {
    let t = table(
        1000,
        &[
            (10_000, 100, 5),
            (90_000, 900, 0),
            (10_000, 100, 9),
            (250_000, 2500, 0),
        ],
    );
    let l = limits(&t, 10_000, 95_000, 100, &[(1, 1000)], 20);
    let r = evaluate(&t, &l).unwrap();
    assert_eq!(
        (r.worst_ratio_ppm, r.rule, r.azimuth_mdeg, r.class1),
        (1_150_000, IntRule::T2Train, 57_500, false)
    );
    assert_eq!(run(&t, &l), oracle(&t, &l));
    // At 23 quanta per pass: Class 1 exactly.
    let l = limits(&t, 10_000, 95_000, 100, &[(1, 1000)], 23);
    assert!(evaluate(&t, &l).unwrap().class1);
}
