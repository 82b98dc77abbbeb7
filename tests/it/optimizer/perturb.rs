//! Random feasible perturbations of an optimizer answer, the search both
//! global-bound tests run (`certificate.rs` under the √ utility,
//! `detection_global.rs` under detection): power traded between two bins at
//! equal spend (or two bins moved to random levels), and without an
//! acceleration limit dwell traded too; every point kept only if it meets the
//! box, the budget, the frame period, the slew limit, the spin range and eye
//! safety. No point may beat the global bound.

use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::optimizer::global::model_objective;
use gaze_lidar::optimizer::Problem;
use gaze_lidar::profile::Profile;
use rand::Rng;

/// What the perturbations may do, i.e. the relaxation the bound is tested on.
#[derive(Clone, Copy)]
pub struct Moves {
    /// With power levels: move two bins to random levels (the power box is
    /// the limits'). Without: trade power inside the levels' hull (clipped
    /// to the limits), which is what the √ relaxation allows.
    pub level_jumps: bool,
    /// Spins bounded by the spin set-points' hull where the problem has
    /// set-points (the problem as posed), instead of the spin limits.
    pub spins_in_setpoint_hull: bool,
    /// How many perturbations to draw.
    pub draws: usize,
}

/// Draws `moves.draws` perturbations of `answer` and asserts that none
/// that is feasible has a model objective above `ub`. Returns how many were
/// feasible and the best objective met (at least the answer's `j0`).
pub fn never_above_the_bound(
    name: &str,
    problem: &Problem,
    gaze_deg: f64,
    answer: &Profile,
    (j0, ub): (f64, f64),
    moves: Moves,
    rng: &mut impl Rng,
) -> (usize, f64) {
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
    let hull = |v: &[f64]| {
        (
            v.iter().copied().fold(f64::INFINITY, f64::min),
            v.iter().copied().fold(0.0, f64::max),
        )
    };
    let (p_lo, p_hi) = if levels.is_empty() || moves.level_jumps {
        (l.power_w_min, l.power_w_max)
    } else {
        let (lo, hi) = hull(levels);
        (lo.max(l.power_w_min), hi.min(l.power_w_max))
    };
    let sp = &problem.levels.spin_rad_s;
    let (w_lo, w_hi) = if sp.is_empty() || !moves.spins_in_setpoint_hull {
        (l.spin_rad_s_min, l.spin_rad_s_max)
    } else {
        hull(sp)
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
    for _ in 0..moves.draws {
        let (mut p, mut t) = (p0.clone(), t0.clone());
        let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
        if i == j {
            continue;
        }
        let scale: f64 = rng.random_range(-0.3..0.3);
        if mode.controls_range() {
            if moves.level_jumps && !levels.is_empty() {
                p[i] = levels[rng.random_range(0..levels.len())];
                p[j] = levels[rng.random_range(0..levels.len())];
            } else {
                // Trade power between i and j at equal spend.
                let dp = scale * (p_hi - p_lo);
                let (wi, wj) = match lid.power_accounting {
                    PowerAccounting::Angle => (theta[i], theta[j]),
                    PowerAccounting::Time => (t[i], t[j]),
                };
                p[i] += dp;
                p[j] -= dp * wi / wj;
            }
        }
        // Under an acceleration limit a dwell trade steps the spin, which
        // the checker rejects: spin moves are another test's.
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
        // The relaxation keeps eye safety's Rule 1 cap (valid for every
        // certifiable profile): points the bound rejects are not feasible.
        if let Some(params) = prof.limits.eye_safety.as_ref() {
            let r = gaze_lidar::eye_safety::evaluate_profile(&prof, params).unwrap();
            if r.worst_ratio > 1.0 {
                continue;
            }
        }
        tried += 1;
        let jv = model_objective(problem, gaze_deg, &prof).unwrap();
        best = best.max(jv);
        assert!(
            jv <= ub,
            "{name}: a feasible point reaches {jv} above the bound {ub}"
        );
    }
    (tried, best)
}
