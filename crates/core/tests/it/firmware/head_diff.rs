//! Differential property test of the integer firmware check of a head
//! against the float head bound on the same table as it runs
//! (`specs/eye_safety.md`, "The head in the integer check").
//!
//! Random heads from the head reference's generator
//! (`eye_safety::head_reference::random_case`: 1–128 channels, slots in
//! 1–16 firing groups, azimuth offsets, origins, beam sizes, divergences,
//! power scales) × random firmware tables drawn by proptest: the head's
//! bins quantized at 1, 10 or 80 MHz ticks (spins as whole ticks) and 2^8,
//! 2^12 or 2^16 codes over the hottest bin (powers as whole codes), either
//! accounting, wavelengths at and beside the band edges, the step scaled
//! so the float figure lands in `[0.8, 1.25]` (the accept/reject border).
//!
//! Per case: the integer figure over the float figure (`int/float`); where
//! the integer check accepts a table the float bound rejects, or its figure
//! is below the float one by more than the quantization margin (`1e-6`:
//! the ppm rounding and the `1e-9` limit cut), the definitions reference
//! (`head_reference::reference`, explicit pulses of every channel) must be
//! at most the integer figure: the integer check is then tighter than the
//! float bound, never unsound (counted apart: the cases with one channel
//! per height, where no head candidate is below `W_v` and only the two
//! checks' own counting differs). The instantaneous candidate
//! (`IntEyeLimits::instant`) must never raise the integer figure, and must
//! lower it somewhere; where it does, the reference is checked too.
//!
//! Run: `cargo test --release -p gaze-lidar-core --test it firmware::head_diff -- --nocapture`
//! (`GAZE_LIDAR_FW_HEAD_DIFF_CASES` sets the cases, 200 by default;
//! `GAZE_LIDAR_FW_HEAD_DIFF_SEED` the seed).

use std::cell::RefCell;

use crate::eye_safety::head_reference::{random_case, reference, Case, Rng};

use gaze_lidar_core::eye_safety::head::bound::head_figures;
use gaze_lidar_core::firmware::eye::{evaluate, IntEyeLimits};
use gaze_lidar_core::firmware::{as_run_segments, table_exposure, FirmwareTable};
use gaze_lidar_core::model::accounting::PowerAccounting;
use gaze_lidar_core::testing as common;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Relative margin of the comparison: the integer ratio is rounded up to a
/// ppm and every limit loses `1e-9` before it is rounded down (both only
/// raise the integer figure), the float bound's margins are `1e-9`; an
/// integer figure more than this below the float one is a difference of
/// the two bounds, not of their rounding (checked against the reference).
const MARGIN: f64 = 1e-6;

/// Wavelengths: the head reference's three, and both sides of the band
/// edges the model evaluates (700 nm, just inside 1050 and 1400 nm, 1500
/// and 1800 nm: the stricter column).
const LAMBDAS: [f64; 9] = [
    905.0, 1450.0, 1550.0, 700.0, 1049.9, 1400.1, 1500.0, 1500.1, 1800.0,
];

#[derive(Debug, Clone)]
struct Drawn {
    seed: u64,
    tick_hz: u64,
    codes_top: u32,
    angle: bool,
    lambda: f64,
    target: f64,
}

fn drawn() -> impl Strategy<Value = Drawn> {
    (
        any::<u64>(),
        prop::sample::select(vec![1_000_000u64, 10_000_000, 80_000_000]),
        prop::sample::select(vec![255u32, 4095, 65_535]),
        any::<bool>(),
        prop::sample::select(LAMBDAS.to_vec()),
        0.8f64..1.25,
    )
        .prop_map(|(seed, tick_hz, codes_top, angle, lambda, target)| Drawn {
            seed,
            tick_hz,
            codes_top,
            angle,
            lambda,
            target,
        })
}

/// The case's head and bins as a firmware table: widths in whole mdeg,
/// dwells in whole ticks at each bin's starting spin, powers in whole codes
/// of `p_max / codes_top`.
fn table_of(case: &Case, d: &Drawn) -> FirmwareTable {
    let n = case.segs.len();
    let p_max = case.segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
    let step = p_max / f64::from(d.codes_top);
    let mut ends: Vec<u32> = case
        .segs
        .iter()
        .map(|s| ((s.start_deg + s.width_deg) * 1000.0).round() as u32)
        .collect();
    ends[n - 1] = 360_000;
    let mut bins = Vec::with_capacity(n);
    let mut start = 0u32;
    for (s, &end) in case.segs.iter().zip(&ends) {
        let width = end - start;
        let rad = (f64::from(width) / 1000.0).to_radians();
        let dwell = ((rad / s.spin_start_rad_s * d.tick_hz as f64).round() as u64).max(1);
        bins.push((width, dwell, (s.power_w / step).round() as u32));
        start = end;
    }
    let mut params = case.params.clone();
    params.wavelength_nm = d.lambda;
    let mut t = common::open_table(d.tick_hz, case.f_p, Some(params), &bins);
    t.power_w_per_code = step;
    t.power_accounting = if d.angle {
        PowerAccounting::Angle
    } else {
        PowerAccounting::Time
    };
    t
}

fn float_ratio(t: &FirmwareTable) -> f64 {
    table_exposure(t)
        .expect("params")
        .expect("float")
        .worst_ratio
}

/// `K_v`: the most channels that can meet one aperture height.
fn count_vertical(t: &FirmwareTable) -> u32 {
    let params = t.eye_safety.as_ref().unwrap();
    let head = params.head.as_ref().unwrap();
    let laser = gaze_lidar_core::eye_safety::exposure::laser(params, t.pulse_rate_hz).unwrap();
    head_figures(head, params, &laser, 600.0)
        .unwrap()
        .count_vertical
}

#[derive(Default)]
struct Stats {
    cases: usize,
    /// (smallest int/float, its case), (largest, its case).
    lo: (f64, String),
    hi: (f64, String),
    int_accepts_float_rejects: usize,
    float_accepts_int_rejects: usize,
    below_float: usize,
    /// Cases the instantaneous candidate lowered the integer figure, and
    /// the largest quotient without / with it.
    instant_used: usize,
    instant_gain: f64,
    /// Of `below_float`, the cases with one channel per height, and their
    /// smallest int/float.
    single_below: usize,
    single_lo: f64,
    /// Seconds in `evaluate` with the limits as derived, and with the
    /// instantaneous alternatives removed (the same tables, one run).
    eval_s: (f64, f64),
    /// Smallest reference/integer headroom over the cases checked against
    /// the reference (integer / reference).
    ref_checked: usize,
    ref_lo: f64,
}

fn one_case(d: &Drawn, stats: &RefCell<Stats>) -> Result<(), TestCaseError> {
    let case = random_case(&mut Rng(d.seed));
    let mut table = table_of(&case, d);
    // Powers scaled (through the step: the codes keep their resolution)
    // so the float figure lands at `target` (the accept/reject border).
    let r0 = float_ratio(&table);
    prop_assume!(r0 > 0.0);
    table.power_w_per_code *= d.target / r0;
    let float = float_ratio(&table);
    prop_assume!(float > 0.0);
    let limits = IntEyeLimits::derive(&table)
        .map_err(|e| TestCaseError::fail(format!("derive: {e} ({d:?})")))?;
    let started = std::time::Instant::now();
    let report = evaluate(&table, &limits)
        .map_err(|e| TestCaseError::fail(format!("evaluate: {e} ({d:?})")))?;
    let with_s = started.elapsed().as_secs_f64();
    let int = report.worst_ratio_ppm as f64 / 1e6;
    let q = int / float;
    let n_ch = case.params.head.as_ref().unwrap().channels.len();
    let tag = format!(
        "seed {:#x}, {n_ch} ch, {} nm, {} Hz ticks, {} codes, {:?}",
        d.seed, d.lambda, d.tick_hz, d.codes_top, report.rule
    );
    if std::env::var("GAZE_LIDAR_FW_HEAD_DIFF_VERBOSE").is_ok() {
        let f = table_exposure(&table).unwrap().unwrap();
        println!(
            "{tag}: int {int:.6}, float {float:.6}, float rules {:?}, float pass {} s {} pulses, int pass {} s {} pulses, {limits:?}",
            f.rule_ratios,
            f.max_pass_duration_s,
            f.max_pulses_per_pass,
            limits.pass_ticks_max as f64 / table.tick_hz as f64,
            limits.pulses_per_pass_max
        );
    }
    let mut s = stats.borrow_mut();
    s.cases += 1;
    if s.cases == 1 || q < s.lo.0 {
        s.lo = (q, tag.clone());
    }
    if q > s.hi.0 {
        s.hi = (q, tag.clone());
    }
    let accepts_wrongly = report.class1 && float > 1.0;
    if accepts_wrongly {
        s.int_accepts_float_rejects += 1;
    }
    if !report.class1 && float <= 1.0 {
        s.float_accepts_int_rejects += 1;
    }
    // The same limits without the instantaneous candidate: never tighter.
    let mut plain = limits.clone();
    let mut at = Some(&mut plain);
    while let Some(set) = at {
        set.instant.clear();
        at = set.other_surface.as_deref_mut();
    }
    let started = std::time::Instant::now();
    let without = evaluate(&table, &plain).unwrap().worst_ratio_ppm as f64 / 1e6;
    s.eval_s.0 += with_s;
    s.eval_s.1 += started.elapsed().as_secs_f64();
    prop_assert!(
        int <= without,
        "{tag}: {int} with the instant candidate, {without} without"
    );
    let by_instant = int < without;
    if by_instant {
        s.instant_used += 1;
        s.instant_gain = s.instant_gain.max(without / int);
    }
    let below = q < 1.0 - MARGIN;
    if below {
        s.below_float += 1;
        // Without a candidate below `W_v` (one channel per height) only the
        // two checks' own counting differs: counted apart.
        if count_vertical(&table) <= 1 {
            s.single_below += 1;
            s.single_lo = s.single_lo.min(q);
        }
    }
    if below || accepts_wrongly || by_instant {
        // Tighter, never unsound: the table as it runs, by the definitions.
        let as_run = Case {
            segs: as_run_segments(&table).unwrap(),
            params: table.eye_safety.clone().unwrap(),
            f_p: table.pulse_rate_hz,
        };
        let phases = if n_ch > 8 { 1 } else { 2 };
        let r = reference(&as_run, phases, &mut Rng(d.seed ^ 0x5eed));
        s.ref_checked += 1;
        let h = if r > 0.0 { int / r } else { f64::INFINITY };
        if s.ref_checked == 1 || h < s.ref_lo {
            s.ref_lo = h;
        }
        prop_assert!(
            int >= r * (1.0 - 1e-12),
            "{tag}: integer {int} below the definitions reference {r} (float {float})"
        );
    }
    Ok(())
}

/// The integer check of a head against the float head bound on random
/// heads × random firmware tables (see the module docs).
#[test]
fn integer_head_check_against_the_float_head_bound() {
    let cases: u32 = std::env::var("GAZE_LIDAR_FW_HEAD_DIFF_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200);
    let seed: u64 = std::env::var("GAZE_LIDAR_FW_HEAD_DIFF_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(29);
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases,
            max_global_rejects: cases * 4,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );
    let stats = RefCell::new(Stats {
        single_lo: f64::INFINITY,
        ..Stats::default()
    });
    let result = runner.run(&drawn(), |d| one_case(&d, &stats));
    let s = stats.into_inner();
    println!(
        "integer head check vs float head bound: {} cases (seed {seed}), int/float in [{:.6} ({}), {:.4} ({})]; \
         int accepts / float rejects: {}, float accepts / int rejects: {}; \
         below the float beyond {MARGIN}: {} ({} with one channel per height, int/float ≥ {:.6}); lowered by the instantaneous candidate: {} (by up to {:.4}×); \
         int/reference ≥ {:.4} over the {} of these checked against the definitions reference",
        s.cases,
        s.lo.0,
        s.lo.1,
        s.hi.0,
        s.hi.1,
        s.int_accepts_float_rejects,
        s.float_accepts_int_rejects,
        s.below_float,
        s.single_below,
        s.single_lo,
        s.instant_used,
        s.instant_gain,
        s.ref_lo,
        s.ref_checked
    );
    println!(
        "evaluate: {:.1} ms with the instantaneous alternatives, {:.1} ms without ({:.2}×)",
        s.eval_s.0 * 1e3,
        s.eval_s.1 * 1e3,
        s.eval_s.0 / s.eval_s.1
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    assert!(s.cases as u32 >= cases, "{} of {cases} cases", s.cases);
    // The instantaneous candidate is taken where it binds.
    assert!(
        s.instant_used > 0,
        "the instantaneous candidate never lowered a figure"
    );
}
