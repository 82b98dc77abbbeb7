//! Core-level tests of `firmware::build` (found by `cargo mutants`: the
//! quantizer `FirmwareTable::from_certified`, `as_run_segments` and
//! `table_exposure` had no test inside the core crate). Expected tick counts,
//! codes, bounds and budgets are worked out by hand in the comments.

use gaze_lidar_core::testing;

use gaze_lidar_core::checker::{certify, certify_with, CheckOptions};
use gaze_lidar_core::eye_safety::bound::Seg;
use gaze_lidar_core::eye_safety::evaluate_segments;
use gaze_lidar_core::firmware::eye::{evaluate, IntEyeLimits};
use gaze_lidar_core::firmware::{
    as_run_segments, check_table, table_exposure, FirmwareConfig, FirmwareError, FirmwareTable,
    FwViolation, QuantizeError, FIRMWARE_FORMAT, MAX_TABLE_BINS,
};
use gaze_lidar_core::model::lidar::{Limits, PowerAccounting};
use gaze_lidar_core::profile::Profile;
use std::f64::consts::{PI, TAU};

const FRAME_HZ: f64 = 10.0;
const POWER_W: f64 = 1e-4;
/// 2π·10 rad/s: one turn in 0.1 s.
const SPIN: f64 = TAU * FRAME_HZ;

use gaze_lidar_core::testing::params;

/// Spin limits exactly at the profile's spin, so every dwell bound is
/// exactly the ideal dwell (`θ·f/ω`), within the checker's tolerance.
fn limits(spin_min: f64, spin_max: f64) -> Limits {
    testing::limits((0.5e-4, 2e-4), (spin_min, spin_max))
}

/// Bins of the given widths (degrees, summing to 360) at `POWER_W` and
/// constant spin `SPIN`.
fn profile(widths: &[f64], accounting: PowerAccounting, lim: Limits) -> Profile {
    testing::profile_of_widths(widths, FRAME_HZ, POWER_W, accounting, lim)
}

fn uniform(accounting: PowerAccounting) -> Profile {
    profile(&[10.0; 36], accounting, limits(SPIN, SPIN))
}

fn build(p: Profile, tick_hz: u64, step: Option<f64>) -> Result<FirmwareTable, FirmwareError> {
    let c = certify(p).expect("certified");
    FirmwareTable::from_certified(
        &c,
        &FirmwareConfig {
            tick_hz,
            power_w_per_code: step,
        },
    )
}

fn config_field(r: Result<FirmwareTable, FirmwareError>) -> &'static str {
    match r {
        Err(FirmwareError::Config { field, .. }) => field,
        other => panic!("expected a configuration error, got {other:?}"),
    }
}

#[test]
fn uniform_profile_quantizes_by_hand() {
    for (accounting, tick_hz) in [
        (PowerAccounting::Angle, 3_600_000),
        (PowerAccounting::Time, 7_200_000),
    ] {
        let t = build(uniform(accounting), tick_hz, None).expect("quantizes");
        let per_bin = tick_hz / 360; // 0.1 s / 36 of the tick rate
        assert_eq!(t.format, FIRMWARE_FORMAT);
        assert_eq!(t.tick_hz, tick_hz);
        // frame_ticks = tick_hz / 10 Hz.
        assert_eq!(t.frame_ticks, tick_hz / 10);
        // Default step: 2e-4 W / 4095.
        assert_eq!(t.power_w_per_code, 2e-4 / 4095.0);
        assert_eq!(t.power_accounting, accounting);
        assert_eq!(t.pulse_rate_hz, 20_000.0);
        assert_eq!(t.eye_safety, Some(params()));
        // power_code_min = ⌈0.5e-4 / step⌉ = ⌈1023.75⌉ (a lower limit rounds
        // up), max = 4095 exactly.
        assert_eq!(t.limits.power_code_min, 1024);
        assert_eq!(t.limits.power_code_max, 4095);
        // Budget: ⌊P̄/step⌋ = ⌊2047.5⌋ = 2047 per unit of weight, plus the
        // remainder's share 0.5 × weight; the weight is 360,000 mdeg (angle)
        // or frame_ticks = 720,000 (time).
        let weight: u64 = match accounting {
            PowerAccounting::Angle => 360_000,
            PowerAccounting::Time => 720_000,
        };
        // (The remainder (1e-4 − 2047·step)/step comes out just below 0.5 in
        // floating point, so its share may be one unit short.)
        let budget = 2047 * weight + weight / 2;
        assert!(
            t.limits.energy_budget == budget || t.limits.energy_budget == budget - 1,
            "{} vs {budget}",
            t.limits.energy_budget
        );
        assert_eq!(t.limits.window_bins, 1);
        assert_eq!(t.limits.window_energy_max, u64::MAX);
        assert_eq!(t.bins.len(), 36);
        for (i, b) in t.bins.iter().enumerate() {
            assert_eq!(b.start_deg, 10.0 * i as f64);
            assert_eq!(b.width_mdeg, 10_000, "bin {i}");
            // θ·f/ω = (π/18)·f / (20π) = f/360, at both spin limits.
            assert_eq!(b.dwell_ticks, per_bin, "bin {i}");
            assert_eq!((b.dwell_ticks_min, b.dwell_ticks_max), (per_bin, per_bin));
            // ⌊1e-4 / (2e-4/4095)⌋ = ⌊2047.5⌋: far below the limit, not lowered.
            assert_eq!(b.power_code, 2047, "bin {i}");
            assert!(b.power_code_cap <= 4095 && b.power_code_cap >= 2047);
        }
        assert_eq!(check_table(&t), vec![]);
        // The cap is rule 1 of the integer check, at most power_code_max.
        let rule1 = IntEyeLimits::derive(&t).expect("limits").pulse_code_max;
        assert_eq!(
            u64::from(t.bins[0].power_code_cap),
            rule1.min(4095),
            "cap = min(power_code_max, pulse_code_max)"
        );
    }
}

/// Unequal widths, so the fractional parts of the ideal dwells differ and
/// the largest remainders are rounded up first.
#[test]
fn largest_remainders_round_up_by_hand() {
    // 1000 Hz, frame 100 ticks; ideals 100·w/360 = 27.78, 22.22, 33.33, 16.67:
    // floors 27 + 22 + 33 + 16 = 98, two round up, the largest remainders
    // (0.78 and 0.67): 28, 22, 33, 17.
    let p = profile(
        &[100.0, 80.0, 120.0, 60.0],
        PowerAccounting::Angle,
        limits(50.0, 80.0),
    );
    let t = build(p, 1000, None).expect("quantizes");
    assert_eq!(t.frame_ticks, 100);
    let ticks: Vec<u64> = t.bins.iter().map(|b| b.dwell_ticks).collect();
    assert_eq!(ticks, [28, 22, 33, 17]);
    let widths: Vec<u32> = t.bins.iter().map(|b| b.width_mdeg).collect();
    assert_eq!(widths, [100_000, 80_000, 120_000, 60_000]);
    // Bounds ⌈θ·f/80⌉ and ⌊θ·f/50⌋, θ·f = 1000·w·π/180:
    // 100°: 21.8 → 22, 34.9 → 34; 80°: 17.5 → 18, 27.9 → 27;
    // 120°: 26.2 → 27, 41.9 → 41; 60°: 13.1 → 14, 20.9 → 20.
    let bounds: Vec<(u64, u64)> = t
        .bins
        .iter()
        .map(|b| (b.dwell_ticks_min, b.dwell_ticks_max))
        .collect();
    assert_eq!(bounds, [(22, 34), (18, 27), (27, 41), (14, 20)]);
    assert_eq!(check_table(&t), vec![]);
}

#[test]
fn zero_spin_minimum_leaves_the_dwell_unbounded_above() {
    let p = profile(&[10.0; 36], PowerAccounting::Angle, limits(0.0, SPIN));
    let t = build(p, 3_600_000, None).expect("quantizes");
    for b in &t.bins {
        assert_eq!((b.dwell_ticks_min, b.dwell_ticks_max), (10_000, u64::MAX));
    }
}

#[test]
fn explicit_step_sets_the_codes() {
    // step 2e-6 W: ⌊1e-4/2e-6⌋ = 50 (exact in floating point: 50·2e-6 ≤ 1e-4 < 51·2e-6);
    // min ⌈0.5e-4/2e-6⌉ = 25 (25·2e-6 is 5e-5 within the checker's REL_TOL),
    // max ⌊2e-4/2e-6⌋ = 100.
    let t = build(uniform(PowerAccounting::Angle), 3_600_000, Some(2e-6)).expect("quantizes");
    assert_eq!(t.power_w_per_code, 2e-6);
    assert_eq!(t.limits.power_code_min, 25);
    assert_eq!(t.limits.power_code_max, 100);
    assert!(t.bins.iter().all(|b| b.power_code == 50));
    // Budget: q = 50, remainder 0 → 50 × 360,000.
    assert_eq!(t.limits.energy_budget, 50 * 360_000);
}

#[test]
fn configuration_errors_name_their_setting() {
    let u = || uniform(PowerAccounting::Angle);
    assert_eq!(config_field(build(u(), 0, None)), "tick_hz");
    assert_eq!(config_field(build(u(), 10_000_000_001, None)), "tick_hz");
    for step in [0.0, -1e-6, f64::NAN, f64::INFINITY] {
        match build(u(), 3_600_000, Some(step)) {
            Err(FirmwareError::Config { field, reason }) => {
                assert_eq!(field, "power_w_per_code", "{step}");
                // Refused as a step, not later as a code that does not fit.
                assert!(
                    reason.contains("must be finite and > 0"),
                    "{step}: {reason}"
                );
            }
            other => panic!("{step}: expected a configuration error, got {other:?}"),
        }
    }
    // A step so small that the codes do not fit a u32.
    assert_eq!(
        config_field(build(u(), 3_600_000, Some(1e-20))),
        "power_w_per_code"
    );
}

#[test]
fn tick_rate_limit_is_inclusive() {
    // 1e10 Hz: frame 1e9 ticks, 1e9/36 = 27,777,777.8 per bin.
    let p = profile(&[10.0; 36], PowerAccounting::Angle, limits(50.0, 80.0));
    let t = build(p, 10_000_000_000, None).expect("1e10 Hz is allowed");
    assert_eq!(t.frame_ticks, 1_000_000_000);
    assert_eq!(
        t.bins.iter().map(|b| b.dwell_ticks).sum::<u64>(),
        1_000_000_000
    );
    assert!(t
        .bins
        .iter()
        .all(|b| b.dwell_ticks == 27_777_777 || b.dwell_ticks == 27_777_778));
}

#[test]
fn bin_count_limit_is_inclusive() {
    // A table holds 36,000 bins; 36,001 is refused before quantizing. No
    // eye-safety parameters: the checker is told to allow that, and the
    // table is then rejected by its own integer check (not Class 1 evidence).
    let make = |n: usize| {
        let w = 360.0 / n as f64;
        let mut lim = limits(50.0, 80.0);
        lim.eye_safety = None;
        let mut p = profile(&vec![w; n], PowerAccounting::Angle, lim);
        for (i, b) in p.bins.iter_mut().enumerate() {
            b.start_deg = w * i as f64;
        }
        let c = certify_with(p, &CheckOptions::declared().allow_missing_eye_safety(true))
            .expect("certified without eye safety");
        FirmwareTable::from_certified(&c, &FirmwareConfig::default())
    };
    assert_eq!(config_field(make(MAX_TABLE_BINS + 1)), "bins");
    match make(MAX_TABLE_BINS) {
        Err(FirmwareError::Rejected(v)) => {
            assert_eq!(v, vec![FwViolation::EyeSafetyMissing]);
        }
        other => panic!("expected the missing-parameters rejection, got {other:?}"),
    }
}

#[test]
fn dwell_outside_the_spin_bounds_is_a_quantize_error() {
    // Spin limits exactly at the profile's spin: at 3,600,018 Hz each bin's
    // ideal is 10,000.05 ticks, its bounds ⌈10,000.05⌉ = 10,001 and
    // ⌊10,000.05⌋ = 10,000: neither rounding is admissible.
    let r = build(uniform(PowerAccounting::Angle), 3_600_018, None);
    match r {
        Err(FirmwareError::Quantize(QuantizeError::BinBounds { bin })) => assert_eq!(bin, 0),
        other => panic!("expected a bin without admissible rounding, got {other:?}"),
    }
}

/// Four unequal bins at their float eye-safety limit (single-pulse rule:
/// C5 falls with the pulses a bin's dwell holds), quantized at 1 kHz: the
/// 60° bin's dwell rounds up from 16.67 to 17 ticks (2 % more pulses), so the
/// table as it runs exceeds the integer limit and its codes are lowered —
/// by a little (C5 ∝ N^−¼: about 0.5 %), not refused.
#[test]
fn near_limit_codes_are_lowered_until_the_integer_check_holds() {
    let mut p = profile(
        &[100.0, 80.0, 120.0, 60.0],
        PowerAccounting::Angle,
        limits(50.0, 80.0),
    );
    p.limits.power_w_max = 1.0;
    p.limits.power_w_min = 0.0;
    let ratio = certify(p.clone())
        .expect("certified")
        .eye_safety()
        .expect("evaluated")
        .worst_ratio;
    let power = POWER_W / ratio;
    for b in &mut p.bins {
        b.power_w = power;
    }
    p.average_power_w = power;
    // Unlowered code: ⌊power/step⌋ = 4·10⁹ (or one less by float rounding).
    let t = build(p, 1000, Some(power / 4e9)).expect("lowered, not refused");
    assert_eq!(
        t.bins.iter().map(|b| b.dwell_ticks).collect::<Vec<_>>(),
        [28, 22, 33, 17]
    );
    let r = evaluate(&t, &IntEyeLimits::derive(&t).expect("limits")).expect("evaluates");
    assert!(r.class1, "{r:?}");
    for b in &t.bins {
        assert!(b.power_code < 3_999_999_999, "lowered: {}", b.power_code);
        assert!(
            b.power_code >= 3_960_000_000,
            "lowered by ~0.5 %: {}",
            b.power_code
        );
    }
}

#[test]
fn json_round_trips_with_a_newline() {
    let t = build(uniform(PowerAccounting::Angle), 3_600_000, None).expect("quantizes");
    let s = t.to_json().expect("json");
    assert!(s.ends_with("}\n"));
    assert!(s.contains("\"frame_ticks\": 360000"));
    let back: FirmwareTable = serde_json::from_str(&s).expect("parses");
    assert_eq!(back, t);
}

fn fw_table(tick_hz: u64, bins: &[(u32, u64, u32)]) -> FirmwareTable {
    testing::open_table(tick_hz, 20_000.0, Some(params()), bins)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn as_run_segments_by_hand() {
    // 90° in 250 ticks of 1 kHz: π/2 rad in 0.25 s = 2π rad/s; a zero-width
    // bin (no dwell) is left out; 270° in 500 ticks: 3π/2 rad in 0.5 s = 3π rad/s.
    let t = fw_table(1000, &[(90_000, 250, 2), (0, 0, 9), (270_000, 500, 4)]);
    let s = as_run_segments(&t).expect("segments");
    assert_eq!(s.len(), 2);
    let want = [(0.0, 90.0, 2e-3, 2.0 * PI), (90.0, 270.0, 4e-3, 3.0 * PI)];
    for (g, w) in s.iter().zip(want) {
        assert!(close(g.start_deg, w.0), "{g:?}");
        assert!(close(g.width_deg, w.1), "{g:?}");
        assert!(close(g.power_w, w.2), "{g:?}");
        assert!(close(g.spin_start_rad_s, w.3), "{g:?}");
        assert!(close(g.spin_end_rad_s, w.3), "{g:?}");
    }
    // A bin with width but no dwell, or no clock: not a table that runs.
    assert!(as_run_segments(&fw_table(1000, &[(90_000, 0, 2), (270_000, 500, 4)])).is_none());
    assert!(as_run_segments(&fw_table(0, &[(360_000, 500, 4)])).is_none());
    assert_eq!(
        as_run_segments(&fw_table(1000, &[(0, 5, 4)])).map(|s| s.len()),
        Some(0)
    );
}

#[test]
fn table_exposure_by_hand() {
    let t = fw_table(1000, &[(90_000, 250, 2), (270_000, 500, 4)]);
    let got = table_exposure(&t)
        .expect("has parameters")
        .expect("evaluates");
    let segs = [
        Seg {
            start_deg: 0.0,
            width_deg: 90.0,
            power_w: 2e-3,
            spin_start_rad_s: 2.0 * PI,
            spin_end_rad_s: 2.0 * PI,
        },
        Seg {
            start_deg: 90.0,
            width_deg: 270.0,
            power_w: 4e-3,
            spin_start_rad_s: 3.0 * PI,
            spin_end_rad_s: 3.0 * PI,
        },
    ];
    let want = evaluate_segments(&segs, &params(), 20_000.0).expect("evaluates");
    assert!(close(got.worst_ratio, want.worst_ratio), "{got:?} {want:?}");
    assert!(got.worst_ratio > 0.0);

    let mut none = t.clone();
    none.eye_safety = None;
    assert!(table_exposure(&none).is_none());
    for bad in [
        fw_table(1000, &[(0, 5, 4)]),
        fw_table(1000, &[(360_000, 0, 4)]),
    ] {
        match table_exposure(&bad) {
            Some(Err(gaze_lidar_core::eye_safety::EyeSafetyError::Param {
                field, reason, ..
            })) => {
                assert_eq!(field, "bins");
                assert_eq!(
                    reason,
                    "a table needs at least one bin with width and dwell"
                );
            }
            other => panic!("expected the no-segment error, got {other:?}"),
        }
    }
}

/// The quantizer raises a code below the least code at or above
/// `power_w_min` to that code, so a bin can run one code above its
/// certified power: the profile's certificate does not hold the table. The
/// table is not handed out on it: `from_certified` checks the table as it
/// runs (`check_table`, the integer Class 1 check on its own codes and
/// ticks) and, codes never going below `power_code_min`, refuses it when
/// over. By hand: 36 bins of 10° at 10 Hz and 3.6 MHz ticks (10,000 ticks
/// each), every bin at `p` = `power_w_min`, step `p/1000.5`: the rounded
/// code is ⌊1000.5⌋ = 1000, the least code at or above the minimum is
/// ⌈1000.5·(1 − 1e-9)⌉ = 1001 (0.05 % above `p`). At 60 % of the Class 1
/// limit the table keeps 1001 and passes both checks as it runs; at 99.99 %
/// it would run at 1.0004 of the limit and is refused naming eye safety.
#[test]
fn minimum_code_above_the_certified_power_is_checked_as_it_runs() {
    let base = profile(&[10.0; 36], PowerAccounting::Time, limits(SPIN, SPIN));
    let ratio = certify(base.clone())
        .expect("certified")
        .eye_safety()
        .expect("evaluated")
        .worst_ratio;
    let at = |fraction: f64| {
        let p_w = POWER_W * fraction / ratio;
        let mut p = base.clone();
        for b in &mut p.bins {
            b.power_w = p_w;
        }
        p.average_power_w = 2.0 * p_w;
        p.limits.power_w_min = p_w;
        p.limits.power_w_max = 4.0 * p_w;
        (p, p_w)
    };
    let (p, p_w) = at(0.6);
    let step = p_w / 1000.5;
    let t = build(p, 3_600_000, Some(step)).expect("quantizes");
    assert_eq!(t.limits.power_code_min, 1001);
    for b in &t.bins {
        assert_eq!((b.dwell_ticks, b.power_code), (10_000, 1001));
        assert!(f64::from(b.power_code) * step > p_w);
    }
    let r = evaluate(&t, &IntEyeLimits::derive(&t).expect("limits")).expect("evaluates");
    assert!(r.class1, "{r:?}");
    let float = table_exposure(&t).expect("params").expect("float");
    assert!(float.worst_ratio <= 1.0, "{}", float.worst_ratio);
    assert!(
        (float.worst_ratio / (0.6 * 1001.0 / 1000.5) - 1.0).abs() < 1e-3,
        "{}",
        float.worst_ratio
    );
    let (p, p_w) = at(0.9999);
    match build(p, 3_600_000, Some(p_w / 1000.5)) {
        Err(FirmwareError::Rejected(v)) => {
            assert!(v.iter().any(|x| x.limit_key() == "eye_safety"), "{v:?}")
        }
        other => panic!("one code above the limit must be refused: {other:?}"),
    }
}
