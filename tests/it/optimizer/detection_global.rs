//! The global bound under `objective.kind = "detection"`: on small
//! instances of every shipped config, the optimizer's answer and thousands
//! of feasible perturbations of it (power traded between two bins at equal
//! spend; without an acceleration limit, dwell traded too) never exceed
//! `upper_bound`, and the answer's figures carry it.

use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::optimizer::global::{model_objective, upper_bound};
use gaze_lidar::optimizer::{optimize, ObjectiveKind, OptimizerConfig};
use rand::{Rng, SeedableRng};

const CONFIGS: [&str; 4] = ["paper", "multi_level", "smooth", "vls128_eye"];

#[test]
fn the_detection_bound_is_never_exceeded_on_small_instances() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(30);
    for name in CONFIGS {
        let text = std::fs::read_to_string(format!("examples/configs/{name}.toml")).unwrap();
        let mut problem = OptimizerConfig::from_toml(&text, name)
            .unwrap()
            .problem()
            .unwrap();
        problem.bins = 12;
        problem.objective.kind = ObjectiveKind::Detection;
        let gaze = 90.0;
        let answer = optimize(&problem, gaze).unwrap().profile().clone();
        let ub = upper_bound(&problem, gaze).unwrap();
        let j0 = model_objective(&problem, gaze, &answer).unwrap();
        assert!(j0 <= ub, "{name}: answer {j0} above the bound {ub}");
        let global = answer
            .optimality
            .as_ref()
            .and_then(|o| o.global.as_ref())
            .expect("optimality.global under detection");
        assert!(global.upper_bound == ub && global.objective <= j0);
        let lid = &problem.lidar;
        let l = &lid.limits;
        let mode = problem.objective.mode;
        let accel = l.spin_accel_rad_s2_max.is_some();
        let n = answer.bins.len();
        let theta: Vec<f64> = answer
            .bins
            .iter()
            .map(|b| b.width_deg.to_radians())
            .collect();
        let period = 1.0 / lid.frame_rate_hz;
        let levels = &problem.levels.power_w;
        let (p_lo, p_hi) = (l.power_w_min, l.power_w_max);
        // The problem as posed: its spins are its set-points (their hull
        // bounds them) where it has them.
        let sp = &problem.levels.spin_rad_s;
        let (w_lo, w_hi) = if sp.is_empty() {
            (l.spin_rad_s_min, l.spin_rad_s_max)
        } else {
            (
                sp.iter().copied().fold(f64::INFINITY, f64::min),
                sp.iter().copied().fold(0.0, f64::max),
            )
        };
        let feasible = |p: &[f64], t: &[f64]| -> bool {
            let frame: f64 = t.iter().sum();
            let spend = match lid.power_accounting {
                PowerAccounting::Angle => {
                    p.iter().zip(&theta).map(|(a, b)| a * b).sum::<f64>() / std::f64::consts::TAU
                }
                PowerAccounting::Time => p.iter().zip(t).map(|(a, b)| a * b).sum::<f64>() / period,
            };
            let slew_ok = l.power_slew_w_per_deg_max.is_none_or(|s| {
                (0..n).all(|i| {
                    let j = (i + 1) % n;
                    (p[j] - p[i]).abs()
                        <= s * 0.5 * (answer.bins[i].width_deg + answer.bins[j].width_deg)
                })
            });
            let spin_ok = (0..n).all(|i| {
                let w = theta[i] / t[i];
                w >= w_lo * (1.0 - 1e-12) && w <= w_hi * (1.0 + 1e-12)
            });
            (frame - period).abs() <= 1e-12 * period
                && spend <= lid.average_power_w
                && p.iter().all(|&v| v >= p_lo && v <= p_hi)
                && slew_ok
                && spin_ok
        };
        let p0: Vec<f64> = answer.bins.iter().map(|b| b.power_w).collect();
        let t0: Vec<f64> = answer.bins.iter().map(|b| b.dwell_s.unwrap()).collect();
        let (mut tried, mut best) = (0, j0);
        for _ in 0..3000 {
            let (mut p, mut t) = (p0.clone(), t0.clone());
            let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
            if i == j {
                continue;
            }
            let scale: f64 = rng.random_range(-0.3..0.3);
            if mode.controls_range() {
                if levels.is_empty() {
                    let dp = scale * (p_hi - p_lo);
                    let (wi, wj) = match lid.power_accounting {
                        PowerAccounting::Angle => (theta[i], theta[j]),
                        PowerAccounting::Time => (t[i], t[j]),
                    };
                    p[i] += dp;
                    p[j] -= dp * wi / wj;
                } else {
                    // Levels: two bins moved to random levels.
                    p[i] = levels[rng.random_range(0..levels.len())];
                    p[j] = levels[rng.random_range(0..levels.len())];
                }
            }
            if mode.controls_resolution() && !accel && rng.random_bool(0.5) {
                let dt = scale * t[i].min(t[j]);
                t[i] += dt;
                t[j] -= dt;
            }
            if !feasible(&p, &t) {
                continue;
            }
            let mut prof = answer.clone();
            for (k, b) in prof.bins.iter_mut().enumerate() {
                b.power_w = p[k];
                if !accel {
                    b.dwell_s = Some(t[k]);
                    b.spin_start_rad_s = theta[k] / t[k];
                    b.spin_end_rad_s = theta[k] / t[k];
                }
            }
            if let Some(params) = prof.limits.eye_safety.as_ref() {
                let r = gaze_lidar::eye_safety::evaluate_profile(&prof, params).unwrap();
                if r.worst_ratio > 1.0 {
                    continue;
                }
            }
            tried += 1;
            let jv = model_objective(&problem, gaze, &prof).unwrap();
            best = best.max(jv);
            assert!(
                jv <= ub,
                "{name}: a feasible point reaches {jv} above the bound {ub}"
            );
        }
        eprintln!(
            "{name} (12 bins, detection): answer {j0}, best of {tried} feasible perturbations {best}, bound {ub} (relative gap {:.2e})",
            (ub - j0) / ub
        );
        assert!(tried > 50, "{name}: only {tried} feasible perturbations");
    }
}
