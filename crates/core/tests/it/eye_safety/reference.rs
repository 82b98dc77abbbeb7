#![allow(clippy::needless_range_loop)]
//! Differential soundness test of the eye-safety checker against two
//! independent brute-force references: `testing::reference` (explicit pulse runs,
//! windows between run boundaries, the AEL at the span of the pulses a
//! window holds, its own copy of Table 3) and `reference_defs.rs` (written
//! from the standard's definitions: explicit pulses, windows `[t, t + T)`
//! for every length `T` of a dense grid through every row edge ± ε, the AEL
//! and Table 10's aperture at the window's own length). The two share no
//! code and no modelling shortcut with the bound or with each other.
//!
//! Each reference reports exposures of concrete pulse trains in concrete
//! windows, so it is a lower bound of the true worst case; a sound checker is
//! never below either. Run (from the workspace root):
//!
//! ```text
//! cargo test --release -p gaze-lidar-core --test eye_safety_reference -- --nocapture
//! # long run (≥ 1e5 random profiles over several seeds), the same summary:
//! GAZE_LIDAR_REF_SEED=1 GAZE_LIDAR_REF_CASES=20000 cargo test --release \
//!     -p gaze-lidar-core --test eye_safety_reference differential -- --nocapture
//! ```
//! `GAZE_LIDAR_REF_SEED=<u64>` picks another deterministic case stream;
//! `GAZE_LIDAR_REF_PHASES=<n>` the number of uniformly spread clock phases;
//! `GAZE_LIDAR_REF_ONLY=<i>,<j>` runs only those cases of the stream and
//! writes their profiles to `target/tmp/eye_safety_reference_case_<i>.json`.

use crate::reference_defs;
use gaze_lidar_core::testing::eye_cases;
use gaze_lidar_core::testing::reference;

use eye_cases::{ael_step_cases, constructed, load, t_into};
use gaze_lidar_core::eye_safety::bound::Search;
use gaze_lidar_core::eye_safety::exposure::evaluate_profile_with;
use gaze_lidar_core::eye_safety::{evaluate_profile, EyeSafetyParams};
use gaze_lidar_core::profile::Profile;
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use reference::{ael_j, c5, Band, Clock, Effort, Reference, RuleKind, Scan, Worst};
use reference_defs::{DBin, DScan, DefReference};
use serde_json::json;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::time::Instant;

/// How far above the reference the checker may be on phase-locked step
/// profiles at ≥ 20 kHz (the goal is "a few per cent"). Measured on the
/// default stream (500 cases): 74 such profiles, 72 within 1.05, the
/// loosest 1.058; long runs (5,000 cases per seed) report theirs, e.g.
/// seed 606: 649 profiles, 646 within 1.05, the loosest 1.067. The loose
/// ones now bind on the multi-pass rules (T2Train), which combine the
/// largest pass energy and the longest pass of different apertures.
/// History: 1.31 before passes were capped per bin (`pulse_capped_j`); then
/// 1.112 on the default stream and 1.413 on seed 606 (case 2084, now
/// `hot_fast_bin_before_a_slow_dark_sector_is_tight`) before the
/// within-pass walks were limited to one pass. Asserted on the default case
/// stream only (a regression guard); see `specs/eye_safety.md`.
const TIGHT_FACTOR: f64 = 1.06;

/// The case stream `cargo test` runs.
const DEFAULT_SEED: u64 = 0x6a7e_11da;

fn params_of(p: &Profile) -> EyeSafetyParams {
    p.limits.eye_safety.clone().expect("eye_safety params")
}

/// A profile's bins and laser as the definitions reference reads them.
fn def_scan(p: &Profile) -> DScan {
    let es = params_of(p);
    DScan {
        bins: p
            .bins
            .iter()
            .map(|b| DBin {
                start_deg: b.start_deg,
                width_deg: b.width_deg,
                power_w: b.power_w,
                w0: b.spin_start_rad_s,
                w1: b.spin_end_rad_s,
            })
            .collect(),
        pulse_rate_hz: p.pulse_rate_hz,
        lambda_nm: es.wavelength_nm,
        pulse_s: es.pulse_duration_s,
        beam_mm: es.beam_diameter_mm,
    }
}

// ---------------------------------------------------------------------------
// Random profiles.

/// Parameters of one random profile.
#[derive(Debug, Clone)]
struct Spec {
    band: usize,
    accel: bool,
    n_bins: usize,
    frame_hz: f64,
    fp_log: f64,
    locked: bool,
    uniform_widths: bool,
    hot: Option<(usize, f64, f64)>, // bin, width deg, power factor
    dark: Option<(usize, usize, f64, f64)>, // first bin, bins, spin factor, power factor
    v_dips: Vec<(usize, f64)>,      // edge, spin factor (accel only)
    u_w: Vec<f64>,
    u_p: Vec<f64>,
    u_s: Vec<f64>,
    beam_mm: f64,
    pulse_log: f64,
    scale: f64,
    /// Bins come in runs of this many with one power and one spin (runs of
    /// constant spin for `accel`), which the bound merges: 1 for none.
    run: usize,
}

fn spec_strategy() -> impl Strategy<Value = Spec> {
    let n_bins = prop_oneof![8usize..40, 40usize..400];
    (
        (
            0usize..3,
            any::<bool>(),
            n_bins,
            5.0f64..25.0,
            (1e3f64).ln()..(5e5f64).ln(),
            any::<bool>(),
            any::<bool>(),
        ),
        (
            proptest::option::of((0usize..400, 0.5f64..2.0, 3.0f64..40.0)),
            proptest::option::of((0usize..400, 1usize..60, 0.15f64..0.6, 0.0f64..0.2)),
            proptest::collection::vec((0usize..400, 0.2f64..0.7), 0..3),
        ),
        (
            proptest::collection::vec(0.0f64..1.0, 400),
            proptest::collection::vec(0.0f64..1.0, 400),
            proptest::collection::vec(0.0f64..1.0, 400),
            1.0f64..10.0,
            (1e-9f64).ln()..(1e-7f64).ln(),
            0.5f64..1.5,
            prop_oneof![2 => Just(1usize), 1 => 2usize..16],
        ),
    )
        .prop_map(
            |(
                (band, accel, n_bins, frame_hz, fp_log, locked, uniform_widths),
                (hot, dark, v_dips),
                (u_w, u_p, u_s, beam_mm, pulse_log, scale, run),
            )| Spec {
                band,
                accel,
                n_bins,
                frame_hz,
                fp_log,
                locked,
                uniform_widths,
                hot,
                dark,
                v_dips,
                u_w,
                u_p,
                u_s,
                beam_mm,
                pulse_log,
                scale,
                run,
            },
        )
}

const LAMBDAS: [f64; 3] = [905.0, 1450.0, 1550.0];

/// profile@1 JSON with generous non-eye-safety limits.
fn profile_json(
    frame_hz: f64,
    fp: f64,
    bins: &[(f64, f64, f64, f64, f64)],
    es: (f64, f64, f64),
) -> serde_json::Value {
    json!({
        "format": "gaze-lidar/profile@1",
        "frame_rate_hz": frame_hz,
        "pulse_rate_hz": fp,
        "average_power_w": 1e3,
        "power_accounting": "time",
        "gaze_deg": null,
        "limits": {
            "power_w_min": 0.0, "power_w_max": 1e3,
            "spin_rad_s_min": 0.0, "spin_rad_s_max": 1e6,
            "spin_accel_rad_s2_max": null, "power_slew_w_per_deg_max": null,
            "eye_safety": {"wavelength_nm": es.0, "pulse_duration_s": es.1, "beam_diameter_mm": es.2}
        },
        "bins": bins.iter().map(|&(s, w, p, w0, w1)| json!({
            "start_deg": s, "width_deg": w, "power_w": p,
            "spin_start_rad_s": w0, "spin_end_rad_s": w1
        })).collect::<Vec<_>>()
    })
}

fn build(spec: &Spec) -> Profile {
    let n = spec.n_bins;
    // Widths.
    let mut w: Vec<f64> = (0..n)
        .map(|i| {
            if spec.uniform_widths {
                1.0
            } else {
                0.2 + spec.u_w[i]
            }
        })
        .collect();
    let total: f64 = w.iter().sum();
    for x in &mut w {
        *x *= 360.0 / total;
    }
    let hot = spec
        .hot
        .map(|(j, hw, k)| (j % n, hw.min(180.0 / n as f64 * 4.0), k));
    if let Some((j, hw, _)) = hot {
        let rest: f64 = w
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != j)
            .map(|(_, x)| x)
            .sum();
        for (i, x) in w.iter_mut().enumerate() {
            *x = if i == j { hw } else { *x * (360.0 - hw) / rest };
        }
    }
    let mut starts = Vec::with_capacity(n);
    let mut s = 0.0;
    for x in &w {
        starts.push(s);
        s += x;
    }
    let widths: Vec<f64> = (0..n)
        .map(|i| {
            if i + 1 < n {
                starts[i + 1] - starts[i]
            } else {
                360.0 - starts[i]
            }
        })
        .collect();
    // The first bin of `i`'s run (the runs share their draws).
    let head = |i: usize| i / spec.run.max(1) * spec.run.max(1);
    let in_dark = |i: usize| {
        spec.dark
            .is_some_and(|(d0, len, _, _)| (i + n - d0 % n) % n < len.min(n / 2))
    };
    // Spin.
    let base = TAU * spec.frame_hz;
    let mut spins: Vec<(f64, f64)> = if spec.accel {
        let mut edge: Vec<f64> = (0..n)
            .map(|i| base * (0.6 + 0.8 * spec.u_s[head(i)]))
            .collect();
        for i in 0..n {
            if in_dark(i) {
                edge[i] *= spec.dark.unwrap().2;
            }
        }
        for &(e, k) in &spec.v_dips {
            edge[e % n] = base * k;
        }
        (0..n).map(|i| (edge[i], edge[(i + 1) % n])).collect()
    } else {
        (0..n)
            .map(|i| {
                let mut x = base * (0.5 + spec.u_s[head(i)]);
                if in_dark(i) {
                    x *= spec.dark.unwrap().2;
                }
                (x, x)
            })
            .collect()
    };
    // Scale the spin so that the period is exactly 1/f (dwell ∝ 1/ω).
    let period: f64 = (0..n)
        .map(|i| 2.0 * widths[i].to_radians() / (spins[i].0 + spins[i].1))
        .sum();
    let k = period * spec.frame_hz;
    for x in &mut spins {
        x.0 *= k;
        x.1 *= k;
    }
    // Power (scaled later so that the reference ratio is `spec.scale`).
    let powers: Vec<f64> = (0..n)
        .map(|i| {
            let mut p = 1e-3 * (0.3 + 0.7 * spec.u_p[head(i)]);
            if in_dark(i) {
                p *= spec.dark.unwrap().3.max(1e-3);
            }
            if let Some((j, _, kh)) = hot {
                if i == j {
                    p *= kh;
                }
            }
            p
        })
        .collect();
    let mut fp = spec.fp_log.exp();
    if spec.locked {
        fp = (fp / spec.frame_hz).round().max(1.0) * spec.frame_hz;
    }
    let bins: Vec<_> = (0..n)
        .map(|i| (starts[i], widths[i], powers[i], spins[i].0, spins[i].1))
        .collect();
    let v = profile_json(
        spec.frame_hz,
        fp,
        &bins,
        (LAMBDAS[spec.band], spec.pulse_log.exp(), spec.beam_mm),
    );
    Profile::from_json(&v.to_string(), "generated").expect("generated profile parses")
}

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// Per-class statistics of checker / reference.
#[derive(Default)]
struct Stats {
    n: usize,
    below: usize,
    /// Phase-locked step profiles at ≥ 20 kHz above [`TIGHT_FACTOR`].
    untight: usize,
    min: f64,
    max: f64,
    min_case: String,
}

impl Stats {
    fn add(&mut self, q: f64, sound: bool, tight: bool, label: &str) {
        if self.n == 0 {
            self.min = f64::INFINITY;
            self.max = f64::NEG_INFINITY;
        }
        self.n += 1;
        self.below += usize::from(!sound);
        self.untight += usize::from(!tight);
        if q < self.min {
            self.min = q;
            self.min_case = label.to_owned();
        }
        self.max = self.max.max(q);
    }
}

/// The branch and bound (the default) against the exhaustive search over
/// every cell and window walk: the same report, bit for bit, on random
/// profiles of every kind the differential test draws.
#[test]
fn pruned_search_is_bit_identical_to_exhaustive() {
    let mut runner = TestRunner::new(Config {
        cases: 300,
        ..Config::default()
    });
    runner
        .run(&spec_strategy(), |spec| {
            let p = build(&spec);
            let params = params_of(&p);
            let pruned = evaluate_profile_with(&p, &params, Search::Pruned);
            let exhaustive = evaluate_profile_with(&p, &params, Search::Exhaustive);
            match (pruned, exhaustive) {
                (Ok(a), Ok(b)) => {
                    prop_assert_eq!(a.worst_ratio.to_bits(), b.worst_ratio.to_bits());
                    prop_assert_eq!(a.binding_rule, b.binding_rule);
                    prop_assert_eq!(a, b);
                }
                (a, b) => prop_assert_eq!(a.err(), b.err()),
            }
            Ok(())
        })
        .unwrap();
}

/// One differential case's result.
struct Outcome {
    class: String,
    q: f64,
    /// Checker over the definitions reference.
    q_defs: f64,
    sound: bool,
    /// A phase-locked step profile at ≥ 20 kHz (where tightness is asserted).
    asserted: bool,
    tight: bool,
    label: String,
    json: String,
}

/// Build case `case` from `spec`, scale it so the reference lands on
/// `spec.scale`, and compare the checker with the reference.
fn one_case(case: usize, spec: &Spec, phases: usize, keep_json: bool) -> Outcome {
    let raw = build(spec);
    let effort = Effort {
        phases,
        locked: spec.locked,
        ..Effort::default()
    };
    let t_ref = Instant::now();
    let r_raw = Reference::new(&Scan::of_profile(&raw)).worst(&effort);
    let t_ref = t_ref.elapsed();
    // Energies are linear in power and C5 does not depend on it: scale
    // the powers so that the reference ratio lands on `spec.scale`.
    let k = spec.scale / r_raw.ratio;
    let mut p = raw.clone();
    for b in &mut p.bins {
        b.power_w *= k;
    }
    let reference = r_raw.ratio * k;
    let report = evaluate_profile(&p, &params_of(&p)).expect("checker evaluates");
    let q = report.worst_ratio / reference;
    // The definitions reference on the scaled profile, at the checker's and
    // the first reference's worst apertures (one uniform clock phase and the
    // phases aligned on each aperture class's entry; `GAZE_LIDAR_DEFS_PHASES`
    // uniform ones in long runs).
    let mut defs = DefReference::new(&def_scan(&p));
    defs.per_decade = 20;
    let mut phis = vec![report.worst_azimuth_deg];
    if (r_raw.azimuth_deg - report.worst_azimuth_deg).abs() > 1e-9 {
        phis.push(r_raw.azimuth_deg);
    }
    let spread = env_usize("GAZE_LIDAR_DEFS_PHASES", 1);
    let t_defs = Instant::now();
    let d = defs.worst(&phis, spec.locked, spread, 2);
    if std::env::var_os("GAZE_LIDAR_REF_TIMING").is_some() {
        eprintln!(
            "case {case}: reference {t_ref:?}, definitions reference {:?}",
            t_defs.elapsed()
        );
    }
    let q_defs = report.worst_ratio / d.ratio;
    let sound_defs = d.ratio <= 0.0 || report.worst_ratio >= d.ratio * (1.0 - 1e-12);
    let sound = report.worst_ratio >= reference * (1.0 - 1e-12) && sound_defs;
    let step = !spec.accel;
    // Tightness is asserted where the reference plays the worst clock:
    // phase-locked (the checker bounds every phase, and a free-running
    // clock with few pulses per pass averages below the per-pass maximum).
    // Below ~20 kHz a pass holds a handful of pulses and the checker's
    // envelope (one pulse spacing of hot power per pass) is measurably
    // looser; those cases are printed, not asserted.
    let asserted = step && spec.locked && p.pulse_rate_hz >= 20_000.0;
    let tight = !asserted || report.worst_ratio <= reference * TIGHT_FACTOR;
    let class = format!(
        "{:>4} nm {} {} {:?}",
        LAMBDAS[spec.band],
        if spec.accel { "accel" } else { "step " },
        if spec.locked { "locked" } else { "free  " },
        r_raw.rule
    );
    let label = format!(
        "case {case}: {class}, {} bins (runs of {}), f={:.2} Hz, fp={:.0} Hz, hot={:?}, dark={}, checker {:.6} ({:?}) vs reference {}; definitions reference {d}",
        p.bins.len(),
        spec.run,
        spec.frame_hz,
        p.pulse_rate_hz,
        spec.hot.map(|h| h.2),
        spec.dark.is_some(),
        report.worst_ratio,
        report.binding_rule,
        Worst { ratio: reference, ..r_raw },
    );
    Outcome {
        class,
        q,
        q_defs: if d.ratio > 0.0 { q_defs } else { f64::INFINITY },
        sound,
        asserted,
        tight,
        json: if sound && tight && !keep_json {
            String::new()
        } else {
            p.to_json().unwrap()
        },
        label,
    }
}

#[test]
fn differential_checker_never_below_reference() {
    let cases = env_usize("GAZE_LIDAR_REF_CASES", 500);
    let seed = std::env::var("GAZE_LIDAR_REF_SEED")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(DEFAULT_SEED);
    let phases = env_usize("GAZE_LIDAR_REF_PHASES", 4);
    let mut seed_bytes = [0u8; 32];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(
        Config::default(),
        TestRng::from_seed(RngAlgorithm::ChaCha, &seed_bytes),
    );
    let strategy = spec_strategy();
    let started = Instant::now();
    let mut by_class: BTreeMap<String, Stats> = BTreeMap::new();
    let mut all = Stats::default();
    let mut failures: Vec<(f64, String, String)> = Vec::new();
    let mut untight: Vec<(f64, String, String)> = Vec::new();
    // Phase-locked step profiles at ≥ 20 kHz: how many, within 1.05, loosest.
    let mut locked_steps = (0usize, 0usize, 0.0f64);
    // Checker / definitions reference: smallest (case), largest.
    let mut defs = (f64::INFINITY, String::new(), 0.0f64);
    // Specs are drawn in order from the seeded runner; the cases are then
    // evaluated in parallel (rayon) and folded in case order, so the output
    // does not depend on the thread count.
    let specs: Vec<Spec> = (0..cases)
        .map(|_| strategy.new_tree(&mut runner).expect("case").current())
        .collect();
    // `GAZE_LIDAR_REF_ONLY=2084,17`: only those cases of the stream (to
    // re-examine what a long run printed).
    let only: Option<Vec<usize>> = std::env::var("GAZE_LIDAR_REF_ONLY")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect());
    let outcomes: Vec<(usize, Outcome)> = {
        use rayon::prelude::*;
        specs
            .par_iter()
            .enumerate()
            .filter(|(case, _)| only.as_ref().is_none_or(|o| o.contains(case)))
            .map(|(case, spec)| (case, one_case(case, spec, phases, only.is_some())))
            .collect()
    };
    // The cases asked for are written out (profile@1, as scaled).
    if only.is_some() {
        for (case, o) in &outcomes {
            let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
                .join(format!("eye_safety_reference_case_{case}.json"));
            std::fs::write(&path, &o.json).unwrap();
            println!("case {case} written to {}", path.display());
        }
    }
    let outcomes = outcomes.into_iter().map(|(_, o)| o);
    for o in outcomes {
        if o.q_defs < defs.0 {
            defs.0 = o.q_defs;
            defs.1 = o.label.clone();
        }
        if o.q_defs.is_finite() {
            defs.2 = defs.2.max(o.q_defs);
        }
        by_class
            .entry(o.class)
            .or_default()
            .add(o.q, o.sound, o.tight, &o.label);
        all.add(o.q, o.sound, o.tight, &o.label);
        if !o.sound {
            failures.push((o.q, o.label.clone(), o.json.clone()));
        }
        if o.asserted {
            locked_steps.0 += 1;
            locked_steps.1 += usize::from(o.q <= 1.05);
            locked_steps.2 = locked_steps.2.max(o.q);
        }
        if !o.tight {
            untight.push((o.q, o.label, o.json));
        }
    }
    let secs = started.elapsed().as_secs_f64();
    println!("differential: {cases} cases in {secs:.1} s (seed {seed}, {phases} uniform clock phases + aligned ones)");
    println!(
        "checker/reference: smallest {:.9}, largest {:.6}",
        all.min, all.max
    );
    println!("  smallest at {}", all.min_case);
    println!(
        "checker/definitions reference: smallest {:.9}, largest {:.6}",
        defs.0, defs.2
    );
    println!("  smallest at {}", defs.1);
    println!(
        "phase-locked step profiles at ≥ 20 kHz: {}, {} within 1.05, loosest {:.4}",
        locked_steps.0, locked_steps.1, locked_steps.2
    );
    println!(
        "{:<36} {:>6} {:>7} {:>9} {:>12} {:>10}",
        "class (reference's binding rule)", "cases", "below", "untight", "min q", "max q"
    );
    for (c, s) in &by_class {
        println!(
            "{c:<36} {:>6} {:>7} {:>9} {:>12.6} {:>10.4}",
            s.n, s.below, s.untight, s.min, s.max
        );
    }
    failures.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (q, l, _) in failures.iter().take(10) {
        println!("BELOW reference ({q:.6}): {l}");
    }
    if let Some((_, _, json)) = failures.first() {
        let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join("eye_safety_reference_worst.json");
        std::fs::write(&path, json).unwrap();
        println!("worst failing profile written to {}", path.display());
    }
    untight.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (q, l, _) in untight.iter().take(5) {
        println!("phase-locked step profile above {TIGHT_FACTOR}× the reference ({q:.4}): {l}");
    }
    if let Some((_, _, json)) = untight.first() {
        let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join("eye_safety_reference_loosest.json");
        std::fs::write(&path, json).unwrap();
        println!("loosest step profile written to {}", path.display());
    }
    assert!(
        failures.is_empty(),
        "{} of {cases} profiles: checker below a reference (smallest checker/reference {:.6}, checker/definitions reference {:.6})",
        failures.len(),
        all.min,
        defs.0
    );
    if seed != DEFAULT_SEED {
        // Long runs measure tightness (printed above); soundness is asserted.
        println!(
            "tightness not asserted on seed {seed}: {} phase-locked step profiles above {TIGHT_FACTOR}×",
            untight.len()
        );
        return;
    }
    assert!(
        untight.is_empty(),
        "{} phase-locked step profiles at ≥ 20 kHz: checker more than {TIGHT_FACTOR}× the reference (loosest {:.4})",
        untight.len(),
        untight.first().map_or(0.0, |u| u.0)
    );
}

// ---------------------------------------------------------------------------
// The reference against closed forms.

#[test]
fn reference_ael_table() {
    let c4 = 10f64.powf(0.002 * 205.0);
    let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-12;
    assert!(close(ael_j(Band::Nir, c4, 5e-9), 7.7e-8 * c4));
    // Row edges: the more restrictive reading.
    assert!(close(
        ael_j(Band::Nir, c4, 5e-6),
        7e-4 * c4 * 5e-6f64.powf(0.75)
    ));
    assert!(close(ael_j(Band::Nir, c4, 10.0), 3.9e-3 * c4));
    assert!(close(ael_j(Band::Nir, c4, 100.0), 3.9e-2 * c4));
    assert!(close(
        ael_j(Band::Ir1400, 1.0, 0.35),
        4.4e-3 * 0.35f64.powf(0.25)
    ));
    assert!(close(ael_j(Band::Ir1400, 1.0, 1.0), 1e-2));
    assert!(close(
        ael_j(Band::Ir1400, 1.0, 1e-3),
        8e-4f64.min(4.4e-3 * 1e-3f64.powf(0.25))
    ));
    assert!(close(ael_j(Band::Ir1500, 1.0, 0.35), 8e-3));
    assert!(close(ael_j(Band::Ir1500, 1.0, 10.0), 0.1));
    assert!(close(
        ael_j(Band::Ir1500, 1.0, 5.0),
        1.8e-2 * 5f64.powf(0.75)
    ));
}

/// Uniform spin and power, phase-locked clock (400 pulses per turn): with
/// the worst phase every pass holds k = ⌊W·f_p⌋ + 1 pulses (W the pass
/// duration), and the worst window is one of a few closed forms. The frame
/// rate 19.3731 Hz keeps every window clear of the AEL breakpoints.
#[test]
fn reference_matches_closed_form_on_a_uniform_profile() {
    let (f, n_turn) = (19.3731, 400.0);
    let fp = n_turn * f;
    let w = TAU * f;
    let p_w = 1e-3;
    let bins: Vec<_> = (0..36)
        .map(|i| (10.0 * f64::from(i), 10.0, p_w, w, w))
        .collect();
    let v = profile_json(f, fp, &bins, (905.0, 5e-9, 8.0));
    let p = Profile::from_json(&v.to_string(), "uniform").unwrap();
    let r = Reference::new(&Scan::of_profile(&p));
    let c4 = 10f64.powf(0.41);
    let t_f = 1.0 / f;
    let h = 0.5 * (7.0 + 8.0) / 100.0;
    let pass_s = 2.0 * h / w;
    let k = (pass_s * fp).floor() + 1.0; // 10 pulses per pass (9.55 on average)
    assert_eq!(k, 10.0);
    let e = p_w / fp;
    let pass_span = (k - 1.0) / fp;
    let ael = |t: f64| ael_j(Band::Nir, c4, t);
    // m whole passes span (m−1)·T_f + (k−1)/f_p.
    let passes = |m: f64| m * k * e / ael((m - 1.0) * t_f + pass_span);
    let m10 = ((10.0 - pass_span) / t_f).floor() + 1.0; // 194 passes within 10 s
    let m100 = ((100.0 - pass_span) / t_f).floor() + 1.0; // 1938 within 100 s
                                                          // Rule 1: N = m10·k pulses within 10 s (no pass is cut: the next pass
                                                          // starts 10.016 s after the first pulse).
    let n = m10 * k;
    let r1 = e / ((5.0 * n.powf(-0.25)).clamp(0.4, 1.0) * 7.7e-8 * c4);
    let cands = [
        ("rule 1", r1),
        ("one pass", passes(1.0)),
        ("m10 passes", passes(m10)),
        ("m10+1 passes", passes(m10 + 1.0)),
        ("m100 passes", passes(m100)),
    ];
    let expect = cands.iter().map(|c| c.1).fold(0.0, f64::max);
    let worst = r.worst_at(
        &[180.0, 3.3],
        &Effort {
            phases: 8,
            locked: true,
            ..Effort::default()
        },
    );
    println!("uniform: reference {worst}; closed forms {cands:?}");
    assert!(
        (worst.ratio / expect - 1.0).abs() < 1e-9,
        "{} vs {}",
        worst.ratio,
        expect
    );
    // And the full search (all apertures) finds the same.
    let full = r.worst(&Effort {
        phases: 8,
        locked: true,
        ..Effort::default()
    });
    assert!(
        (full.ratio / expect - 1.0).abs() < 1e-9,
        "{} vs {}",
        full.ratio,
        expect
    );
    assert!(matches!(worst.clock, Clock::PerTurn { .. }));
    let _ = RuleKind::Pulse;
}

#[test]
fn constructed_cases_true_ratio_and_reference() {
    for c in constructed() {
        let p = load(c.name);
        let r = Reference::new(&Scan::of_profile(&p));
        let effort = Effort {
            phases: 16,
            locked: c.locked,
            ..Effort::default()
        };
        let at = r.worst_at(&c.phis, &effort);
        let full = r.worst(&effort);
        let checker = evaluate_profile(&p, &params_of(&p)).unwrap();
        println!(
            "{}: true {:.6} ({}); reference at the constructed aperture {at}; reference search {:.6}; checker today {:.6} ({:?})",
            c.name, c.truth, c.how, full.ratio, checker.worst_ratio, checker.binding_rule
        );
        assert!(
            c.truth > 1.0,
            "{}: constructed to be over the limit",
            c.name
        );
        assert!(
            at.ratio > 1.0 && full.ratio > 1.0,
            "{}: the reference finds it over",
            c.name
        );
        // The reference is a lower bound of the truth, and reaches it.
        assert!(
            at.ratio <= c.truth * (1.0 + 1e-9),
            "{}: reference {} above the true {}",
            c.name,
            at.ratio,
            c.truth
        );
        assert!(
            full.ratio <= c.truth * (1.0 + 1e-9),
            "{}: reference {} above the true {}",
            c.name,
            full.ratio,
            c.truth
        );
        assert!(
            at.ratio >= c.truth_low * (1.0 - 1e-9),
            "{}: reference {} below {}",
            c.name,
            at.ratio,
            c.truth_low
        );
    }
}

/// Regression (case 145 of seed 101, found by the 10,000-case run): a
/// free-running 2049 Hz clock at 1450 nm, the aperture's pass ending on a
/// V-shaped spin minimum. Nine consecutive passes can each hold three
/// pulses, within `8·T_f + (2 − 8d)·Δ` (`d` the clock's drift per turn in
/// pulse spacings): fewer seconds than the old multi-pass bound allowed
/// nine pulse-capped passes (it spent the envelope's partial-period term
/// on pulse-capped pass energies). The true ratio of that window is computed
/// here by hand from the bins; the checker must not be below it.
#[test]
fn free_clock_nine_pass_window_is_at_least_its_ratio_by_hand() {
    let p = load("regression_free_clock_nine_passes_1450.json");
    let es = p.limits.eye_safety.clone().unwrap();
    let fp = p.pulse_rate_hz;
    let delta = 1.0 / fp;
    let frame_s: f64 = p
        .bins
        .iter()
        .map(|b| 2.0 * b.width_deg.to_radians() / (b.spin_start_rad_s + b.spin_end_rad_s))
        .sum();
    // The pass ends on the edge after bin 8 (the spin minimum), inside bin 8.
    let b = &p.bins[8];
    let (w0, w1) = (b.spin_start_rad_s, b.spin_end_rad_s);
    let d_rad = b.width_deg.to_radians();
    let a = (w1 * w1 - w0 * w0) / (2.0 * d_rad);
    let h = 0.5 * (3.5 + es.beam_diameter_mm) / 100.0;
    let tau = t_into(w0, a, d_rad) - t_into(w0, a, d_rad - 2.0 * h);
    // Pulse offsets in a pass fall by `d` spacings per turn; a pass holds 3
    // pulses while its first-pulse offset is at most τ/Δ − 2.
    let d = (frame_s * fp).fract();
    assert!(
        8.0 * d <= tau / delta - 2.0,
        "nine 3-pulse passes exist: 8d = {}, τ/Δ − 2 = {}",
        8.0 * d,
        tau / delta - 2.0
    );
    let span = 8.0 * frame_s + (2.0 - 8.0 * d) * delta;
    assert!(
        span > 0.35 && span < 10.0,
        "span {span} in the 1e-2·t J row"
    );
    let truth = 27.0 * b.power_w * delta / (1e-2 * span);
    let checker = evaluate_profile(&p, &es).unwrap();
    let phi = (b.start_deg + b.width_deg - h.to_degrees()).rem_euclid(360.0);
    let at = Reference::new(&Scan::of_profile(&p)).worst_at(&[phi], &Effort::default());
    println!(
        "true {truth:.6} (span {span:.6} s), reference at {phi:.4}° {:.6}, checker {:.6} ({:?})",
        at.ratio, checker.worst_ratio, checker.binding_rule
    );
    assert!(truth > 1.3, "the window is over the limit: {truth}");
    assert!(
        at.ratio <= truth * (1.0 + 1e-9) && at.ratio >= truth * (1.0 - 1e-3),
        "the reference reaches the hand-computed window: {} vs {truth}",
        at.ratio
    );
    assert!(
        checker.worst_ratio >= truth,
        "checker {} below the true ratio {truth}",
        checker.worst_ratio
    );
}

/// The loosest phase-locked step profile of the long runs before the walks
/// were limited to one pass (seed 606, case 2084: checker 1.046 against the
/// reference's 0.740, 1.413×): a hot bin at 268 rad/s just before a slow
/// dark bin at 14.8 rad/s, 1450 nm. The within-pass walks used to charge
/// the hot bin's power for as long as the slowest pass anywhere, and the
/// whole-pass bound took the largest pass energy over the smallest pass
/// duration. Now: within 5 % of the reference, never below it.
#[test]
fn hot_fast_bin_before_a_slow_dark_sector_is_tight() {
    assert_tight_against_reference(
        "regression_hot_fast_before_slow_dark_1450.json",
        1.05,
        "1.413",
    );
}

/// The loosest phase-locked step profile of the default stream once its
/// profiles came in runs (case 362: checker 0.7054 against the reference's
/// 0.6633, 1.0635×, on the time-base rule): a 0.69° bin at 2.68 W between a
/// slow neighbour (58 rad/s) and a fast one (89 rad/s), 1550 nm. One union
/// arc per cell gave the cell the pulse count of its slow end and the fast
/// neighbour's cap of its other end; the pass energy was 6.11e-4 J where
/// no pass holds more than ≈ 5.8e-4 J. The caps are now taken over eight
/// sub-cells: within 2 % of the reference, never below it.
#[test]
fn hot_bin_between_a_slow_and_a_fast_neighbour_is_tight() {
    assert_tight_against_reference(
        "regression_hot_bin_between_slow_and_fast_1550.json",
        1.02,
        "1.0635",
    );
}

/// The loosest phase-locked step profile of the first long run on the
/// merged runs and sub-cell caps (seed 3102, case 4754: checker 1.4899
/// against the reference's 1.3129, 1.135×, on Rule 1), 905 nm: a slow
/// dark bin (42 rad/s) next to a 3.2 mW bin, then a 4.0 mW bin. Rule 1
/// took, per cell, the hottest bin its union arc touches (the 4.0 mW one,
/// met only by the passes at the cell's far end, the shortest ones) with
/// the pulse count of its longest pass. Now each cell end is paired with
/// its own count and the inside with the bins it meets: 1.059× the
/// reference, never below it (the pass at the far end does meet the 4.0 mW
/// bin's first instant; a pulse may sit there for some clock phase).
#[test]
fn rule_one_pairs_a_touched_hot_bin_with_its_own_pulse_count() {
    assert_tight_against_reference(
        "regression_rule1_hot_bin_touched_at_a_cell_end_905.json",
        1.07,
        "1.135",
    );
}

/// The committed profile `file` against the reference (four clock phases,
/// locked): never below it, at most `max_q` times it (it was `was`×).
fn assert_tight_against_reference(file: &str, max_q: f64, was: &str) {
    let p = load(file);
    let es = p.limits.eye_safety.clone().unwrap();
    let checker = evaluate_profile(&p, &es).unwrap();
    let effort = Effort {
        phases: 4,
        locked: true,
        ..Effort::default()
    };
    let reference = Reference::new(&Scan::of_profile(&p)).worst(&effort);
    let q = checker.worst_ratio / reference.ratio;
    println!(
        "checker {:.6} ({:?}), reference {}: {q:.4}×",
        checker.worst_ratio, checker.binding_rule, reference
    );
    assert!(q >= 1.0 - 1e-12, "checker below the reference: {q}");
    assert!(q <= max_q, "checker {q:.4}× the reference (was {was}×)");
}

/// Rule 1 where a pass ends on a hot bin's first instant, by hand, on the
/// profile of `rule_one_pairs_a_touched_hot_bin_with_its_own_pulse_count`:
/// the aperture whose pass `[a − 2h, a]` ends at the 4.0 mW bin's start `a`
/// holds `⌊τ f_p⌋ + 1` pulses per pass for the clock phase that puts the
/// last one on `a` (it carries the 4.0 mW bin's power: bins are `[start,
/// end)`), the clock locked, so every pass of the `⌊(T2 + τ)/T_f⌋ + 1` a
/// 10 s window meets does the same. The checker's Rule 1 figure must be at
/// least that pulse's ratio (a bound that drops the touched bin, or pairs
/// it with too few pulses, is not).
#[test]
fn rule_one_counts_a_pulse_on_a_hot_bin_s_first_instant() {
    let p = load("regression_rule1_hot_bin_touched_at_a_cell_end_905.json");
    let es = p.limits.eye_safety.clone().unwrap();
    let checker = evaluate_profile(&p, &es).unwrap();
    // The 4.0 mW bin after the 3.2 mW one that follows the slow dark bin.
    let k = p
        .bins
        .iter()
        .position(|b| (b.start_deg - 277.381).abs() < 1e-3)
        .unwrap();
    assert!(p.bins[k - 2].spin_start_rad_s < 45.0 && p.bins[k].power_w > 3.9e-3);
    let a = p.bins[k].start_deg;
    let two_h = checker.pass_angle_deg;
    // The pass's duration: constant-spin bins, overlap over spin.
    let tau: f64 = p
        .bins
        .iter()
        .map(|b| {
            assert_eq!(b.spin_start_rad_s, b.spin_end_rad_s, "a step profile");
            let lo = b.start_deg.max(a - two_h);
            let hi = (b.start_deg + b.width_deg).min(a);
            (hi - lo).max(0.0).to_radians() / b.spin_start_rad_s
        })
        .sum();
    let frame_s = 1.0 / p.frame_rate_hz;
    let per_pass = (tau * p.pulse_rate_hz).floor() + 1.0;
    let passes = ((10.0 + tau) / frame_s).floor() + 1.0;
    let band = Band::of(es.wavelength_nm);
    let c4 = 10f64.powf(0.002 * (es.wavelength_nm - 700.0));
    let e = p.bins[k].power_w / p.pulse_rate_hz;
    let by_hand = e / (c5(band, per_pass * passes) * ael_j(band, c4, es.pulse_duration_s));
    println!(
        "Rule 1: checker {:.6}, by hand {by_hand:.6} ({per_pass} pulses × {passes} passes)",
        checker.rule_ratios[0]
    );
    assert!(
        checker.rule_ratios[0] >= by_hand * (1.0 - 1e-12),
        "checker {} below {by_hand}",
        checker.rule_ratios[0]
    );
}

// ---------------------------------------------------------------------------
// Windows longer than the pulses they hold, across a step-down of
// Table 3 (`eye_cases::ael_step_cases`, true ratios by hand there).

/// Both profiles are rejected naming eye safety, the checker's figure at
/// least the true ratio (computed by hand, best clock phase, the model's
/// aperture), which the AEL at the pulses' span (the monotone reading the
/// checker used to make) puts below 1.
#[test]
fn windows_longer_than_their_pulses_across_an_ael_step_down_are_rejected() {
    use gaze_lidar_core::checker::{check, Violation};
    for c in ael_step_cases() {
        let p = load(c.name);
        let report = evaluate_profile(&p, &params_of(&p)).unwrap();
        println!(
            "{}: true {:.6} (every phase {:.6}; at the span {:.6}; Table 10 by duration {:?}): {}; checker {:.6} ({:?})",
            c.name,
            c.truth,
            c.truth_low,
            c.monotone,
            c.truth_standard,
            c.how,
            report.worst_ratio,
            report.binding_rule
        );
        assert!(
            c.truth_low > 1.0 && c.monotone < 1.0,
            "{}: constructed so",
            c.name
        );
        assert!(
            report.worst_ratio >= c.truth,
            "{}: checker {} below the true ratio {}",
            c.name,
            report.worst_ratio,
            c.truth
        );
        let v = check(&p);
        assert!(
            v.iter().any(|x| matches!(x, Violation::EyeSafety { .. })),
            "{}: not rejected for eye safety: {v:?}",
            c.name
        );
        assert!(
            v.iter().all(|x| matches!(x, Violation::EyeSafety { .. })),
            "{}: only eye safety is violated: {v:?}",
            c.name
        );
    }
}

/// The definitions reference on the AEL step-down profiles: it finds the 10 s
/// window of the 1550 nm one over the limit under the standard's own
/// Table 10 aperture (3.5 mm at 10 s), as computed by hand, and never
/// exceeds the hand-computed supremum (the model's wider aperture); the
/// first reference (AEL at the span) cannot see either.
#[test]
fn definitions_reference_finds_the_ael_step_down_windows() {
    for c in ael_step_cases() {
        let p = load(c.name);
        let defs = DefReference::new(&def_scan(&p));
        let phi = p.bins[0].start_deg + p.bins[0].width_deg;
        let d = defs.worst(&[phi], false, 4, 2);
        let r1 = Reference::new(&Scan::of_profile(&p)).worst_at(&[phi], &Effort::default());
        println!("{}: definitions {d}; first reference {r1}", c.name);
        assert!(
            d.ratio <= c.truth * (1.0 + 1e-9),
            "{}: above the truth",
            c.name
        );
        if let Some(std) = c.truth_standard {
            assert!(
                d.ratio >= std * (1.0 - 1e-9),
                "{}: {} below {std}",
                c.name,
                d.ratio
            );
            assert!(d.ratio > 1.0 && r1.ratio < 1.0);
        }
    }
}

/// The definitions reference on the four constructed profiles: never above
/// the hand-computed true ratio (it is a lower bound), and over the limit
/// on the three whose worst window its apertures share (905 nm, 7 mm).
#[test]
fn definitions_reference_on_the_constructed_cases() {
    for c in constructed() {
        let p = load(c.name);
        let defs = DefReference::new(&def_scan(&p));
        let d = defs.worst(&c.phis, c.locked, 8, 2);
        println!("{}: true {:.6}, definitions reference {d}", c.name, c.truth);
        assert!(
            d.ratio <= c.truth * (1.0 + 1e-9),
            "{}: {} above the true {}",
            c.name,
            d.ratio,
            c.truth
        );
        if p.limits.eye_safety.as_ref().unwrap().wavelength_nm < 1400.0 {
            assert!(d.ratio > 1.0, "{}: {}", c.name, d.ratio);
        }
    }
}

/// The definitions reference's own Table 3 and Table 10, by hand at points
/// inside rows and on every edge (the smaller row there).
#[test]
fn definitions_reference_tables_by_hand() {
    use reference_defs::{def_ael_j, def_aperture_mm, DBand};
    let c4 = 10f64.powf(0.41);
    let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-12;
    assert!(close(def_ael_j(DBand::Nir, 905.0, 1e-9), 7.7e-8 * c4));
    assert!(close(
        def_ael_j(DBand::Nir, 905.0, 5e-6),
        7e-4 * c4 * 5e-6f64.powf(0.75)
    ));
    assert!(close(def_ael_j(DBand::Nir, 905.0, 10.0), 3.9e-3 * c4));
    assert!(close(
        def_ael_j(DBand::Ir1400, 1450.0, 1e-3),
        4.4e-3 * 1e-3f64.powf(0.25)
    ));
    assert!(close(def_ael_j(DBand::Ir1400, 1450.0, 0.5e-3), 8e-4));
    assert!(close(def_ael_j(DBand::Ir1400, 1450.0, 2.0), 2e-2));
    assert!(close(def_ael_j(DBand::Ir1500, 1550.0, 10.0), 0.1));
    assert!(close(
        def_ael_j(DBand::Ir1500, 1550.0, 9.99),
        1.8e-2 * 9.99f64.powf(0.75)
    ));
    assert!(close(def_ael_j(DBand::Ir1500, 1550.0, 0.35), 8e-3));
    assert_eq!(def_aperture_mm(DBand::Ir1500, 0.35), 1.0);
    assert!(close(def_aperture_mm(DBand::Ir1500, 1.0), 1.5));
    assert!(def_aperture_mm(DBand::Ir1500, 9.9) > 3.5);
    assert_eq!(def_aperture_mm(DBand::Ir1500, 10.0), 3.5);
    assert_eq!(def_aperture_mm(DBand::Nir, 1e-3), 7.0);
}

/// The brute-force reference and the hand-computed cases share no code with
/// the model they check: the only items of the crate they name are the
/// profile type they read and the test-data path.
#[test]
fn references_use_nothing_of_the_crate_but_the_profile_type() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/testing");
    let allowed = ["crate::profile::Profile", "super::data_path"];
    for file in ["reference.rs", "eye_cases.rs"] {
        let text = std::fs::read_to_string(dir.join(file)).expect("reference source");
        let mut named = 0;
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let mut rest = code;
            while let Some(at) = rest.find("crate::").or_else(|| rest.find("super::")) {
                let path = &rest[at..];
                assert!(
                    allowed.iter().any(|a| path.starts_with(a)),
                    "{file}:{}: names the crate's `{}`",
                    i + 1,
                    path.trim_end()
                );
                named += 1;
                rest = &path[7..];
            }
        }
        assert!(named > 0, "{file}: no path of the crate found (moved?)");
    }
}
