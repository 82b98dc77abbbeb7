//! Firmware tables of the paper's profiles.

use crate::common;
use crate::independent;
use gaze_lidar_core::testing::reference;

use common::{run, stdout};
use gaze_lidar::firmware::{binary, check_table, FirmwareTable};
use gaze_lidar::profile::Profile;

fn profile_and_table(mode: &str, gaze: &str) -> (Profile, FirmwareTable) {
    let t = run(
        &common::profile_args("paper", mode, gaze, &["--format", "firmware"]),
        None,
    );
    assert_eq!(t.status.code(), Some(0), "{}", common::stderr(&t));
    (
        common::profile_from(&common::profile_args("paper", mode, gaze, &[])),
        serde_json::from_str(&stdout(&t)).unwrap(),
    )
}

#[test]
fn paper_tables_are_exact_and_conservative() {
    for mode in ["range", "resolution", "joint"] {
        for gaze in ["90", "5"] {
            let (p, t) = profile_and_table(mode, gaze);
            assert_eq!(
                t.frame_ticks,
                (t.tick_hz as f64 / p.frame_rate_hz).round() as u64
            );
            assert_eq!(
                t.bins.iter().map(|b| b.dwell_ticks).sum::<u64>(),
                t.frame_ticks,
                "{mode} {gaze}"
            );
            assert_eq!(t.bins.len(), p.bins.len());
            for (b, fw) in p.bins.iter().zip(&t.bins) {
                let ideal = b.dwell_time_s() * t.tick_hz as f64;
                assert!(
                    (fw.dwell_ticks as f64 - ideal).abs() < 1.0,
                    "{mode} {gaze}: {} vs {ideal}",
                    fw.dwell_ticks
                );
                let code_w = f64::from(fw.power_code) * t.power_w_per_code;
                assert!(code_w <= b.power_w, "code above the certified power");
                assert!(
                    b.power_w - code_w < t.power_w_per_code,
                    "more than one code below"
                );
            }
            // Not `check_table` (the CLI only writes tables it accepts): the
            // integer limits restated independently, and the brute-force
            // reference finds no pulse train over Class 1 on the table as
            // it will run.
            let broken = independent::recheck_table(&t);
            assert!(broken.is_empty(), "{mode} {gaze}: {broken:?}");
            let found = reference::Reference::new(&scan_of_table(&t)).worst(&reference::Effort {
                phases: 4,
                ..reference::Effort::default()
            });
            assert!(found.ratio <= 1.0, "{mode} {gaze}: as run {found}");
        }
    }
}

#[test]
fn binary_tables_round_trip_and_tampering_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.bin");
    let o = run(
        &[
            "profile",
            "--mode",
            "joint",
            "--gaze-deg",
            "90",
            "--format",
            "firmware-bin",
            "--out",
            path.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    let bytes = std::fs::read(&path).unwrap();
    let mut t = binary::decode(&bytes).unwrap();
    // The control of the tampering checks below: the decoded table is
    // accepted, so each rejection that follows is due to its one change.
    assert!(check_table(&t).is_empty());
    assert_eq!(binary::encode(&t), bytes);
    t.bins[3].dwell_ticks += 1;
    let v = check_table(&t);
    assert!(
        v.iter().any(|x| x.to_string().contains("frame_ticks")),
        "{v:?}"
    );
    t.bins[3].dwell_ticks -= 1;
    t.bins[200].power_code = t.bins[200].power_code_cap + 1;
    assert!(!check_table(&t).is_empty());
    assert!(binary::decode(&bytes[..bytes.len() - 1]).is_err());
}

// ---------------------------------------------------------------------------
// Eye safety of a table as it will run: the integer check.

use gaze_lidar::checker::certify;
use gaze_lidar::eye_safety::{evaluate_profile, EyeSafetyParams};
use gaze_lidar::firmware::eye::{evaluate, IntEyeLimits};
use gaze_lidar::firmware::{
    check_table_with, table_exposure, FirmwareConfig, FwBin, FwViolation, IntLimits,
};
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use reference::{Effort, RBin, Reference, Scan};

/// `p` with every power (and every power limit) scaled so that the checker's
/// eye-safety ratio is `target`; certified again.
fn at_ratio(p: &Profile, target: f64) -> gaze_lidar::checker::CertifiedProfile {
    let params = p.limits.eye_safety.clone().expect("eye-safety parameters");
    let r = evaluate_profile(p, &params).unwrap().worst_ratio;
    let k = target / r;
    let mut q = p.clone();
    q.summary = None;
    for b in &mut q.bins {
        b.power_w *= k;
    }
    q.average_power_w *= k;
    q.limits.power_w_max *= k;
    q.limits.power_w_min *= k;
    if let Some(s) = q.limits.power_slew_w_per_deg_max.as_mut() {
        *s *= k;
    }
    let c = certify(q).expect("a scaled certified profile stays certified");
    let r = evaluate_profile(c.profile(), &params).unwrap().worst_ratio;
    assert!((r / target - 1.0).abs() < 1e-9, "{r} vs {target}");
    c
}

/// The reference's view of a table as it runs: bin `i` at constant spin
/// `width · tick_hz / dwell`, power `code · step`.
fn scan_of_table(t: &FirmwareTable) -> Scan {
    let es = t.eye_safety.as_ref().expect("eye-safety parameters");
    let mut start_mdeg = 0u64;
    let mut bins = Vec::new();
    for b in &t.bins {
        if b.width_mdeg > 0 {
            let width_deg = f64::from(b.width_mdeg) / 1000.0;
            let w = width_deg.to_radians() * t.tick_hz as f64 / b.dwell_ticks as f64;
            bins.push(RBin {
                start_deg: start_mdeg as f64 / 1000.0,
                width_deg,
                power_w: f64::from(b.power_code) * t.power_w_per_code,
                w0: w,
                w1: w,
            });
        }
        start_mdeg += u64::from(b.width_mdeg);
    }
    Scan {
        bins,
        pulse_rate_hz: t.pulse_rate_hz,
        lambda_nm: es.wavelength_nm,
        pulse_s: es.pulse_duration_s,
        beam_mm: es.beam_diameter_mm,
    }
}

/// Worst reference ratio of a table: free-running clock, and phase-locked
/// when a turn holds a whole number of pulses (a clock restarted every turn
/// otherwise fires two pulses closer than 1/f_p at the wrap: not a clock of
/// rate f_p, which is what the table declares).
fn reference_ratio(t: &FirmwareTable, phases: usize) -> f64 {
    let r = Reference::new(&scan_of_table(t));
    let per_turn = t.pulse_rate_hz * t.frame_ticks as f64 / t.tick_hz as f64;
    let whole = (per_turn - per_turn.round()).abs() < 1e-9 * per_turn.max(1.0);
    [false, true]
        .iter()
        .filter(|&&locked| !locked || whole)
        .map(|&locked| {
            r.worst(&Effort {
                phases,
                locked,
                ..Effort::default()
            })
            .ratio
        })
        .fold(0.0, f64::max)
}

fn int_ratio(t: &FirmwareTable) -> f64 {
    let limits = IntEyeLimits::derive(t).expect("limits");
    evaluate(t, &limits).expect("evaluates").worst_ratio_ppm as f64 / 1e6
}

const MODES: [Mode; 4] = [Mode::Baseline, Mode::Range, Mode::Resolution, Mode::Joint];

/// Must show: a table quantized at 100 kHz from a paper profile at 0.999999
/// of the limit is either refused or runs at ≤ 1 in the brute-force
/// reference (the old float-capped quantizer handed out a table at 1.013).
#[test]
fn near_limit_table_at_100khz_is_refused_or_class1_in_the_reference() {
    let cfg = FirmwareConfig {
        tick_hz: 100_000,
        power_w_per_code: None,
    };
    let mut built = 0;
    for mode in MODES {
        for gaze in [90.0, 5.0] {
            let c = closed_form(&presets::paper(), mode, Some(gaze), 360).unwrap();
            let c = at_ratio(c.profile(), 0.999_999);
            match FirmwareTable::from_certified(&c, &cfg) {
                Ok(t) => {
                    built += 1;
                    let reference = reference_ratio(&t, 4);
                    let int = int_ratio(&t);
                    println!(
                        "{mode:?} {gaze}: integer {int:.6}, reference {reference:.6}, float as-run {:.6}",
                        table_exposure(&t).unwrap().unwrap().worst_ratio
                    );
                    assert!(reference <= 1.0, "{mode:?} {gaze}: reference {reference}");
                    assert!(int <= 1.0 && int >= reference * (1.0 - 1e-12));
                }
                Err(e) => println!("{mode:?} {gaze}: refused: {e}"),
            }
        }
    }
    // Not vacuous: at 100 kHz the integer check lowers codes rather than refuse.
    assert!(built > 0);
}

/// Must show: at the default 80 MHz the certified near-limit paper profiles
/// (baseline included) quantize, and the integer check costs little power.
#[test]
fn default_80mhz_quantizes_certified_near_limit_profiles() {
    for mode in MODES {
        for gaze in [90.0, 5.0] {
            for target in [1.0 - 1e-4, 0.999_999, 1.0 - 1e-9] {
                let c = closed_form(&presets::paper(), mode, Some(gaze), 360).unwrap();
                let c = at_ratio(c.profile(), target);
                let t = FirmwareTable::from_certified(&c, &FirmwareConfig::default())
                    .unwrap_or_else(|e| panic!("{mode:?} {gaze} {target}: {e}"));
                // Codes kept, relative to the code of the certified power.
                let kept = c
                    .profile()
                    .bins
                    .iter()
                    .zip(&t.bins)
                    .map(|(b, fw)| f64::from(fw.power_code) * t.power_w_per_code / b.power_w)
                    .fold(f64::INFINITY, f64::min);
                let int = int_ratio(&t);
                println!(
                    "{mode:?} {gaze} {target}: integer ratio {int:.6}, least power kept {kept:.4}"
                );
                assert!(int <= 1.0);
                assert!(
                    kept >= 0.995,
                    "{mode:?} {gaze} {target}: only {kept} of the power kept"
                );
            }
        }
    }
}

/// Parameters of one random table.
#[derive(Debug, Clone)]
struct TableSpec {
    band: usize,
    n: usize,
    tick_log: f64,
    frame_hz: f64,
    fp_log: f64,
    locked: bool,
    widths: Vec<u32>,
    dwells: Vec<u32>,
    codes: Vec<u16>,
    hot: Option<(usize, u32)>,
    dark: Option<(usize, usize, u32)>,
    beam_mm: f64,
    pulse_log: f64,
}

fn table_spec() -> impl Strategy<Value = TableSpec> {
    (0usize..3, 3usize..40)
        .prop_flat_map(|(band, n)| {
            (
                Just(band),
                Just(n),
                (5.0f64..7.9, 5.0f64..30.0, 3.0f64..5.7, any::<bool>()),
                (
                    prop::collection::vec(1u32..100, n),
                    prop::collection::vec(1u32..100, n),
                    prop::collection::vec(0u16..4096, n),
                ),
                (
                    prop::option::of((0..n, 2u32..60)),
                    prop::option::of((0..n, 1..n.max(2), 2u32..20)),
                    0.5f64..10.0,
                    -9.0f64..-7.0,
                ),
            )
        })
        .prop_map(
            |(
                band,
                n,
                (tick_log, frame_hz, fp_log, locked),
                (widths, dwells, codes),
                (hot, dark, beam_mm, pulse_log),
            )| TableSpec {
                band,
                n,
                tick_log,
                frame_hz,
                fp_log,
                locked,
                widths,
                dwells,
                codes,
                hot,
                dark,
                beam_mm,
                pulse_log,
            },
        )
}

/// Splits `total` into parts proportional to `weights`, each ≥ 1, exactly.
fn split(total: u64, weights: &[u64]) -> Vec<u64> {
    let sum: u64 = weights.iter().sum();
    let mut out: Vec<u64> = weights.iter().map(|&w| (total * w / sum).max(1)).collect();
    let used: u64 = out.iter().sum();
    let last = out.len() - 1;
    // Give the remainder (or take the excess) from the widest part.
    let widest = (0..out.len()).max_by_key(|&i| out[i]).unwrap_or(last);
    out[widest] = out[widest] + total - used;
    out
}

const LAMBDAS: [f64; 3] = [905.0, 1450.0, 1550.0];

fn build_table(s: &TableSpec) -> FirmwareTable {
    let n = s.n;
    let tick_hz = 10f64.powf(s.tick_log).round() as u64;
    let frame_ticks = (tick_hz as f64 / s.frame_hz).round() as u64;
    let mut ww: Vec<u64> = s.widths.iter().map(|&w| u64::from(w)).collect();
    if let Some((j, _)) = s.hot {
        ww[j] = 1; // a narrow hot sector
    }
    let widths = split(360_000, &ww);
    let in_dark = |i: usize| {
        s.dark
            .is_some_and(|(d0, len, _)| (i + n - d0) % n < len.min(n / 2))
    };
    let dw: Vec<u64> = (0..n)
        .map(|i| {
            let slow = s
                .dark
                .map_or(1, |d| if in_dark(i) { u64::from(d.2) } else { 1 });
            // dwell ∝ width / spin, spin in (0.5, 1.5) of nominal, slower in the dark sector.
            widths[i] * (50 + u64::from(s.dwells[i])) * slow
        })
        .collect();
    let dwell = split(frame_ticks, &dw);
    let codes: Vec<u32> = (0..n)
        .map(|i| {
            let mut c = u32::from(s.codes[i]);
            if in_dark(i) {
                c /= 50;
            }
            if let Some((j, k)) = s.hot {
                if i == j {
                    c = (c.max(100) * k).min(40_000);
                }
            }
            c
        })
        .collect();
    let as_run_frame_hz = tick_hz as f64 / frame_ticks as f64;
    let fp = if s.locked {
        // A whole number of pulses per turn of the table as it runs.
        (10f64.powf(s.fp_log) / as_run_frame_hz).round().max(1.0) * as_run_frame_hz
    } else {
        10f64.powf(s.fp_log)
    };
    let lambda = LAMBDAS[s.band];
    let bins = (0..n)
        .map(|i| FwBin {
            start_deg: 0.0,
            width_mdeg: widths[i] as u32,
            dwell_ticks: dwell[i],
            power_code: codes[i],
            dwell_ticks_min: 0,
            dwell_ticks_max: u64::MAX,
            power_code_cap: u32::MAX,
        })
        .collect();
    FirmwareTable {
        format: gaze_lidar::firmware::FIRMWARE_FORMAT.to_owned(),
        tick_hz,
        frame_ticks,
        power_w_per_code: 1e-3 / 4095.0,
        power_accounting: PowerAccounting::Time,
        pulse_rate_hz: fp,
        eye_safety: Some(EyeSafetyParams {
            wavelength_nm: lambda,
            pulse_duration_s: 10f64.powf(s.pulse_log),
            beam_diameter_mm: s.beam_mm,
            head: None,
        }),
        limits: IntLimits {
            power_code_min: 0,
            power_code_max: u32::MAX,
            energy_budget: u64::MAX,
            window_bins: 1,
            window_energy_max: u64::MAX,
        },
        bins,
    }
}

/// The differential soundness test of the integer check: on random tables
/// (narrow hot sectors, slow dark sectors, 1–500 kHz, free-running and
/// phase-locked clocks, 905/1450/1550 nm, 100 kHz–80 MHz ticks) the integer
/// ratio is never below the brute-force reference on the table as it runs —
/// so a table the integer check passes is ≤ 1 in the reference — and the
/// float bound on the same table is printed next to it (the integer check
/// is the conservative one of the two). `GAZE_LIDAR_FW_CASES` sets the count.
#[test]
fn differential_integer_check_never_below_reference() {
    let cases: usize = std::env::var("GAZE_LIDAR_FW_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let mut seed = [0u8; 32];
    seed[..8].copy_from_slice(&0x00f1_ee7e_u64.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed),
    );
    let strategy = table_spec();
    let (mut q_ref_min, mut q_ref_max) = (f64::INFINITY, 0.0f64);
    let (mut q_float_min, mut q_float_max) = (f64::INFINITY, 0.0f64);
    let mut loosest = String::new();
    let mut evaluated = 0;
    let mut rejected_by_int_not_float = 0;
    for case in 0..cases {
        let spec = strategy.new_tree(&mut runner).unwrap().current();
        let t = build_table(&spec);
        let Ok(limits) = IntEyeLimits::derive(&t) else {
            // Pulses overlapping, a frame too short: no limits, no verdict.
            continue;
        };
        let int = evaluate(&t, &limits)
            .expect("within bounds")
            .worst_ratio_ppm as f64
            / 1e6;
        if int == 0.0 {
            continue;
        }
        let float = table_exposure(&t).unwrap().unwrap().worst_ratio;
        let reference = reference_ratio(&t, 3);
        evaluated += 1;
        let q = int / reference;
        if int < reference * (1.0 - 1e-12) {
            let r = Reference::new(&scan_of_table(&t));
            for locked in [false, true] {
                let w = r.worst(&Effort {
                    phases: 3,
                    locked,
                    ..Effort::default()
                });
                println!("reference locked={locked}: {w}");
            }
            let rep = table_exposure(&t).unwrap().unwrap();
            println!("float: {rep:?}");
            println!("int: {:?}", evaluate(&t, &limits));
            println!(
                "limits: pulse_code_max {} pass {} K {} tau {} arc {} train0 {:?} trainlast {:?}",
                limits.pulse_code_max,
                limits.pass_energy_max_quanta,
                limits.pulses_per_pass_max,
                limits.pass_ticks_max,
                limits.pass_arc_mdeg,
                limits.train.first(),
                limits.train.last()
            );
            println!(
                "{:?}",
                t.bins
                    .iter()
                    .map(|b| (b.width_mdeg, b.dwell_ticks, b.power_code))
                    .collect::<Vec<_>>()
            );
        }
        assert!(
            int >= reference * (1.0 - 1e-12),
            "case {case}: integer {int} below the reference {reference} (float {float}): {spec:?}"
        );
        // ppm rounding: the integer ratio is at most 1e-6 coarser.
        q_ref_min = q_ref_min.min(q);
        if q > q_ref_max {
            q_ref_max = q;
            loosest = format!(
                "case {case}: {} nm, fp {:.0} Hz, {} bins, hot {:?}, dark {:?}, locked {}, {:?} integer {int:.3e} vs reference {reference:.3e}",
                LAMBDAS[spec.band], t.pulse_rate_hz, spec.n, spec.hot, spec.dark, spec.locked, evaluate(&t, &limits).unwrap().rule
            );
        }
        q_float_min = q_float_min.min(int / float);
        q_float_max = q_float_max.max(int / float);
        if int > 1.0 && float <= 1.0 {
            rejected_by_int_not_float += 1;
        }
    }
    println!(
        "integer/reference: smallest {q_ref_min:.6}, largest {q_ref_max:.4}; integer/float: smallest {q_float_min:.6}, largest {q_float_max:.4}; {evaluated} of {cases} tables evaluated; {rejected_by_int_not_float} over 1 in integers only"
    );
    println!("loosest: {loosest}");
    assert!(
        evaluated * 2 > cases,
        "too few tables evaluated: {evaluated}"
    );
}

/// A table whose codes were raised after quantization (caps and budget
/// moved out of the way, as a careless or hostile edit would) fails the
/// integer eye-safety check by name; the no-float path against host-derived
/// limits gives the same verdict; rotating the table keeps it.
#[test]
fn raised_codes_fail_the_integer_eye_safety_check() {
    let c = closed_form(&presets::paper(), Mode::Joint, Some(90.0), 360).unwrap();
    let c = at_ratio(c.profile(), 0.999_999);
    let mut t = FirmwareTable::from_certified(&c, &FirmwareConfig::default()).unwrap();
    let limits = IntEyeLimits::derive(&t).unwrap();
    let before = evaluate(&t, &limits).unwrap();
    assert!(
        before.class1 && before.worst_ratio_ppm > 999_000,
        "{before:?}"
    );
    for b in &mut t.bins {
        b.power_code = b.power_code * 101 / 100 + 1;
        b.power_code_cap = u32::MAX;
    }
    t.limits.power_code_max = u32::MAX;
    t.limits.energy_budget = u64::MAX;
    let v = check_table(&t);
    assert_eq!(v.len(), 1, "{v:?}");
    assert!(
        matches!(&v[0], FwViolation::EyeSafety { ratio_ppm, .. } if *ratio_ppm > 1_000_000),
        "{v:?}"
    );
    assert!(v[0].to_string().starts_with("eye_safety: as quantized"));
    assert_eq!(check_table_with(&t, &limits), v);
    let mut rotated = t.clone();
    rotated.bins.rotate_left(37);
    assert_eq!(
        evaluate(&rotated, &limits).unwrap().worst_ratio_ppm,
        evaluate(&t, &limits).unwrap().worst_ratio_ppm
    );
}
