//! Issue 6 acceptance: firmware tables of the paper's profiles.

mod common;

use common::{run, stdout};
use gaze_lidar::firmware::{binary, check_table, FirmwareTable};
use gaze_lidar::profile::Profile;

fn profile_and_table(mode: &str, gaze: &str) -> (Profile, FirmwareTable) {
    let t = run(
        &[
            "profile",
            "--preset",
            "paper",
            "--mode",
            mode,
            "--gaze-deg",
            gaze,
            "--format",
            "firmware",
        ],
        None,
    );
    assert_eq!(t.status.code(), Some(0), "{}", common::stderr(&t));
    (
        common::profile_from(&[
            "profile",
            "--preset",
            "paper",
            "--mode",
            mode,
            "--gaze-deg",
            gaze,
        ]),
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
            assert!(check_table(&t).is_empty());
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
// Eye safety of a table as it will run: the integer check (issue 10, Build 6).

#[allow(dead_code)]
mod reference;

use gaze_lidar::checker::certify;
use gaze_lidar::eye_safety::{evaluate_profile, EyeSafetyParams};
use gaze_lidar::firmware::eye::{evaluate, IntEyeLimits};
use gaze_lidar::firmware::{table_exposure, FirmwareConfig, FwBin, FwViolation, IntLimits};
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use reference::{Clock as _Unused, Effort, RBin, Reference, Scan};

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

/// Worst reference ratio of a table over free-running and phase-locked clocks.
fn reference_ratio(t: &FirmwareTable, phases: usize) -> f64 {
    let r = Reference::new(&scan_of_table(t));
    [false, true]
        .iter()
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
                println!("{mode:?} {gaze} {target}: integer ratio {int:.6}, least power kept {kept:.4}");
                assert!(int <= 1.0);
                assert!(kept >= 0.995, "{mode:?} {gaze} {target}: only {kept} of the power kept");
            }
        }
    }
}
