//! The detection objective's global bound as an exact certificate:
//! `profile --certificate DIR` writes `DIR/detection_bound.json` for a
//! `kind = "detection"` config; the exact checker
//! (`optimizer::global::check_detection_certificate`) accepts it for every
//! shipped config, proves the profile's `optimality.global.upper_bound`,
//! and rejects it once corrupted. On small instances the checked bound lies
//! above a brute-force enumeration of the relaxation it bounds.
#![cfg(feature = "solver")]

use crate::common;

use common::{run, stderr};
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::optimizer::global::{
    check_detection_certificate, detection_certificate, model_objective, DetectionCertificate,
    DetectionCertificateError,
};
use gaze_lidar::optimizer::{optimize, ObjectiveKind, OptimizerConfig, Problem};
use num_rational::BigRational;

const CONFIGS: [&str; 4] = ["paper", "multi_level", "smooth", "vls128_eye"];

fn q(v: f64) -> BigRational {
    BigRational::from_float(v).unwrap()
}

/// The shipped config `name` with `kind = "detection"` (its text, and the
/// problem it poses; the kind set where the config leaves it out).
fn detection_config(name: &str) -> (String, Problem) {
    let text = std::fs::read_to_string(format!("examples/configs/{name}.toml")).unwrap();
    let text = if text.contains("\nkind = ") {
        text
    } else {
        text.replacen("[objective]", "[objective]\nkind = \"detection\"", 1)
    };
    let problem = OptimizerConfig::from_toml(&text, name)
        .unwrap()
        .problem()
        .unwrap();
    assert_eq!(problem.objective.kind, ObjectiveKind::Detection);
    (text, problem)
}

#[test]
fn exported_detection_bounds_check_exactly_for_every_shipped_config() {
    for name in CONFIGS {
        let (text, problem) = detection_config(name);
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join(format!("{name}.toml"));
        std::fs::write(&config, text).unwrap();
        let cert_dir = dir.path().join("cert");
        let out = dir.path().join("profile.json");
        let o = run(
            &[
                "profile",
                "--config",
                config.to_str().unwrap(),
                "--gaze-deg",
                "90",
                "--certificate",
                cert_dir.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
            None,
        );
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let cert: DetectionCertificate = serde_json::from_str(
            &std::fs::read_to_string(cert_dir.join("detection_bound.json")).unwrap(),
        )
        .unwrap();
        let exact = check_detection_certificate(&problem, 90.0, &cert)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let p: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        let global = &p["optimality"]["global"];
        let stated = global["upper_bound"].as_f64().unwrap();
        // The profile states the certificate's bound, which the exact sum
        // does not exceed, and its objective lies below it.
        assert_eq!(stated, cert.upper_bound, "{name}");
        assert!(exact <= q(stated), "{name}");
        assert!(q(global["objective"].as_f64().unwrap()) <= exact, "{name}");
        // The exact sum is the float bound to within its stated slack.
        let ratio = stated / num_traits::ToPrimitive::to_f64(&exact).unwrap();
        assert!((1.0..1.0 + 1e-11).contains(&ratio), "{name}: {ratio}");
        let cells: usize = cert.classes.iter().map(|c| c.cells.len()).sum();
        eprintln!(
            "{name}: upper_bound {stated}, objective {}, relative gap {:.3e}; {} classes, {cells} cells, {} envelope points, mu {:e}, nu {:e}",
            global["objective"],
            global["gap"].as_f64().unwrap() / stated,
            cert.classes.len(),
            cert.tables.iter().map(|t| t.points.len()).sum::<usize>(),
            cert.budget_multiplier,
            cert.frame_multiplier,
        );
    }
}

/// A certificate with one change is rejected, naming the field.
fn rejected(
    problem: &Problem,
    cert: &DetectionCertificate,
    change: impl FnOnce(&mut DetectionCertificate),
    field: &str,
) {
    let mut bad = cert.clone();
    change(&mut bad);
    match check_detection_certificate(problem, 90.0, &bad) {
        Err(DetectionCertificateError::Rejected { field: f, reason }) => {
            assert!(
                f.contains(field),
                "rejected for {f} ({reason}), not {field}"
            );
        }
        other => panic!("a corrupted certificate ({field}) passed: {other:?}"),
    }
}

#[test]
fn a_corrupted_certificate_is_rejected() {
    for name in ["paper", "smooth"] {
        let (_, mut problem) = detection_config(name);
        problem.bins = 36;
        let cert = detection_certificate(&problem, 90.0).unwrap();
        check_detection_certificate(&problem, 90.0, &cert).unwrap();
        // The multiplier moved (another valid Lagrangian, but not the sum
        // stated), or made negative.
        rejected(
            &problem,
            &cert,
            |c| c.budget_multiplier *= 1.01,
            "upper_bound_exact",
        );
        rejected(
            &problem,
            &cert,
            |c| c.budget_multiplier = -c.budget_multiplier - 1e-3,
            "budget_multiplier",
        );
        rejected(
            &problem,
            &cert,
            |c| c.frame_multiplier = -1.0,
            "frame_multiplier",
        );
        // An envelope point lowered: below its ranges' weighted sum.
        rejected(
            &problem,
            &cert,
            |c| {
                let p = c.tables[0]
                    .points
                    .iter_mut()
                    .max_by(|a, b| a.value.total_cmp(&b.value));
                let p = p.unwrap();
                p.value *= 0.999;
            },
            "value",
        );
        // A range lowered below the model's own detection range: the model
        // still detects beyond it.
        rejected(
            &problem,
            &cert,
            |c| {
                let p = c.tables[0]
                    .points
                    .iter_mut()
                    .find(|p| p.range_m[0] > 1.0)
                    .unwrap();
                p.range_m[0] *= 0.99;
            },
            "range_m",
        );
        // A cell dropped: the box is no longer covered.
        rejected(
            &problem,
            &cert,
            |c| {
                c.classes[0].cells.remove(0);
            },
            "cells",
        );
        // A √ bound lowered.
        rejected(
            &problem,
            &cert,
            |c| {
                let s = c.tables[0].sqrt_up.last_mut().unwrap();
                *s *= 1.0 - 1e-12;
            },
            "sqrt_up",
        );
        // A dwell node moved inside the box.
        rejected(
            &problem,
            &cert,
            |c| {
                let t = &mut c.tables[0].tau;
                if t.len() > 1 {
                    t[0] = 0.5 * (t[0] + t[1]);
                } else {
                    t[0] *= 0.999;
                }
            },
            "tau",
        );
        // The stated bound lowered below the exact sum.
        rejected(
            &problem,
            &cert,
            |c| c.upper_bound *= 1.0 - 1e-9,
            "upper_bound",
        );
        // Another gaze's certificate.
        let other = detection_certificate(&problem, 200.0).unwrap();
        assert!(check_detection_certificate(&problem, 90.0, &other).is_err());
    }
}

/// Brute force: every assignment of the allowed power levels and spin
/// set-points to the bins of a small instance that meets the relaxation's
/// rows (budget, and the frame's upper side, each widened by 1e-9 as in
/// the bound; powers that break eye safety alone left out), scored by `model_objective`
/// (separable per bin, so each bin's options are scored once against a
/// base profile), never exceeds the exact bound the certificate proves.
#[test]
fn the_checked_bound_is_above_a_brute_force_enumeration() {
    for (name, bins) in [("multi_level", 9), ("paper", 12)] {
        let (_, mut problem) = detection_config(name);
        problem.bins = bins;
        let gaze = 90.0;
        let cert = detection_certificate(&problem, gaze).unwrap();
        let exact = check_detection_certificate(&problem, gaze, &cert).unwrap();
        let base = optimize(&problem, gaze).unwrap().profile().clone();
        let lid = &problem.lidar;
        let l = &lid.limits;
        let powers: Vec<f64> = problem
            .levels
            .power_w
            .iter()
            .copied()
            .filter(|&p| p >= l.power_w_min && p <= l.power_w_max)
            .collect();
        let spins: Vec<f64> = if problem.objective.mode.controls_resolution() {
            problem
                .levels
                .spin_rad_s
                .iter()
                .copied()
                .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max)
                .collect()
        } else {
            vec![base.bins[0].spin_start_rad_s]
        };
        let set = |prof: &mut gaze_lidar::profile::Profile, i: usize, (p, w): (f64, f64)| {
            let b = &mut prof.bins[i];
            b.power_w = p;
            b.spin_start_rad_s = w;
            b.spin_end_rad_s = w;
            b.dwell_s = Some(b.width_deg.to_radians() / w);
        };
        // Eye safety: a power that fails alone in one bin (the rest at the
        // lowest level, the slowest set-point) is in no accepted profile.
        let slowest = spins.iter().copied().fold(f64::INFINITY, f64::min);
        let lowest = powers.iter().copied().fold(f64::INFINITY, f64::min);
        let alone_ok = |p: f64| {
            let Some(params) = base.limits.eye_safety.as_ref() else {
                return true;
            };
            let mut prof = base.clone();
            for i in 0..bins {
                set(&mut prof, i, (if i == 0 { p } else { lowest }, slowest));
            }
            let r = gaze_lidar::eye_safety::evaluate_profile(&prof, params).unwrap();
            r.worst_ratio <= 1.0
        };
        let powers: Vec<f64> = powers.into_iter().filter(|&p| alone_ok(p)).collect();
        let options: Vec<(f64, f64)> = powers
            .iter()
            .flat_map(|&p| spins.iter().map(move |&w| (p, w)))
            .collect();
        let mut flat = base.clone();
        for i in 0..bins {
            set(&mut flat, i, options[0]);
        }
        let j0 = model_objective(&problem, gaze, &flat).unwrap();
        let delta: Vec<Vec<f64>> = (0..bins)
            .map(|i| {
                options
                    .iter()
                    .map(|&o| {
                        let mut p = flat.clone();
                        set(&mut p, i, o);
                        model_objective(&problem, gaze, &p).unwrap() - j0
                    })
                    .collect()
            })
            .collect();
        let period = 1.0 / lid.frame_rate_hz;
        let theta: Vec<f64> = base.bins.iter().map(|b| b.width_deg.to_radians()).collect();
        // Per bin and option: (frame share Σ t/T, budget share).
        let use_of = |i: usize, (p, w): (f64, f64)| {
            let t = theta[i] / w;
            let x = p / lid.average_power_w;
            let spend = match lid.power_accounting {
                PowerAccounting::Angle => theta[i] * x / std::f64::consts::TAU,
                PowerAccounting::Time => t * x / period,
            };
            (t / period, spend)
        };
        let n_opt = options.len();
        let mut best = f64::NEG_INFINITY;
        let mut best_choice = vec![0; bins];
        let mut choice = vec![0usize; bins];
        let total = n_opt.pow(bins as u32);
        for code in 0..total {
            let mut c = code;
            let (mut frame, mut spend, mut gain) = (0.0, 0.0, 0.0);
            for (i, slot) in choice.iter_mut().enumerate() {
                *slot = c % n_opt;
                c /= n_opt;
                let (f, s) = use_of(i, options[*slot]);
                frame += f;
                spend += s;
                gain += delta[i][*slot];
            }
            // The relaxation's rows, widened by the checker's 1e-9 as the
            // bound's are.
            if frame <= 1.0 + 1e-9 && spend <= 1.0 + 1e-9 && gain > best {
                best = gain;
                best_choice.clone_from(&choice);
            }
        }
        assert!(best.is_finite(), "{name}: no assignment meets the rows");
        // The best assignment scored as one profile (not by the sums).
        let mut p = flat.clone();
        for (i, &k) in best_choice.iter().enumerate() {
            set(&mut p, i, options[k]);
        }
        let j_best = model_objective(&problem, gaze, &p).unwrap();
        assert!(
            (j_best - (j0 + best)).abs() <= 1e-12 * j_best.abs(),
            "{name}: separable"
        );
        assert!(
            q(j_best) <= exact,
            "{name}: brute force {j_best} above the checked bound"
        );
        let ub = num_traits::ToPrimitive::to_f64(&exact).unwrap();
        eprintln!(
            "{name} ({bins} bins, {total} assignments): brute-force optimum of the relaxation {j_best}, checked bound {ub} (relative gap {:.2e})",
            (ub - j_best) / ub
        );
    }
}

/// The power step builds the detection objective's segments for runs of
/// contiguous bins on rayon's threads. Each segment is the same bits
/// whichever neighbour's ranges guessed it, so the answer is the same
/// profile, bit for bit, on one thread and on three (`smooth`, every bin's
/// dwell its own: each power step builds all of them).
#[test]
fn the_detection_segments_give_the_same_profile_on_any_thread_count() {
    let (_, problem) = detection_config("smooth");
    let solve = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let (answer, bound) = pool.install(|| {
            (
                optimize(&problem, 90.0).unwrap(),
                detection_certificate(&problem, 90.0).unwrap(),
            )
        });
        // The profile, and the global bound's certificate (its nodes are
        // computed on all threads, its classes' maxima one per thread).
        (
            serde_json::to_string(answer.profile()).unwrap(),
            serde_json::to_string(&bound).unwrap(),
        )
    };
    let one = solve(1);
    assert_eq!(one, solve(3));
    assert_eq!(one, solve(2));
}
