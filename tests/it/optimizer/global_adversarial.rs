//! Attacks on the optimizer's global bound
//! (`src/optimizer/global.rs`): the claim is that
//! `optimality.global.upper_bound` ≥ `model_objective` of EVERY profile the
//! checker (`gaze_lidar::checker::certify`) accepts for the problem. Each
//! test builds a checker-accepted profile by hand and compares. Two
//! findings were fixed (`dwell_s` trusted, another grid evaluated); two
//! showed the claim's scope (the problem's levels and mode), now stated in
//! `specs/optimizer.md` and pinned here; the rest held.

#![cfg(feature = "solver")]

use crate::common;

use gaze_lidar::checker::certify;
use gaze_lidar::optimizer::global::{model_objective, upper_bound};
use gaze_lidar::optimizer::{optimize, Problem};
use gaze_lidar::profile::Profile;

fn problem(name: &str, bins: usize) -> Problem {
    common::shipped_problem(name, bins)
}

fn answer(problem: &Problem, gaze: f64) -> Profile {
    optimize(problem, gaze).unwrap().profile().clone()
}

/// `dwell_s` is "informational; the checker recomputes it"
/// (`profile::Bin`), but `objective_of` reads it when present: a profile
/// that is the optimizer's answer with every `dwell_s` doubled is accepted
/// by the checker unchanged and its model objective exceeds the bound.
#[test]
// Fixed (was: model_objective trusted the informational Bin::dwell_s; it now
// takes each bin's dwell from its spins, `optimizer::utilities`).
fn a_stale_dwell_field_lifts_the_model_objective_above_the_bound() {
    let problem = problem("paper", 12);
    let gaze = 90.0;
    let mut prof = answer(&problem, gaze);
    let ub = upper_bound(&problem, gaze).unwrap();
    for b in &mut prof.bins {
        b.dwell_s = Some(b.dwell_time_s() * 4.0);
    }
    let prof = certify(prof)
        .expect("the checker ignores dwell_s")
        .profile()
        .clone();
    let j = model_objective(&problem, gaze, &prof).unwrap();
    assert!(j <= ub, "accepted profile: J = {j} above the bound {ub}");
}

/// The checker accepts bins of any widths that tile the circle (coverage
/// within its angle tolerance), but `model_objective` evaluates a profile
/// on the problem's uniform grid (`θ_i` of the grid, the profile's spins
/// and powers), so a profile whose hot, slow bins are narrow (little time,
/// little budget) and whose one cheap bin is wide and fast meets every
/// limit while its model objective counts each narrow bin as a full grid
/// bin at the slowest spin and highest power. (The optimizer's answer on
/// `paper` at 12 bins, gaze 90°, sits at the bound: 11.1425.)
#[test]
// Fixed (was: model_objective evaluated a profile on another grid with the
// grid's widths): the bound is over the problem's grid, and such a profile is
// now refused, naming the first bin that differs.
fn a_profile_with_non_uniform_bins_exceeds_the_bound() {
    let problem = problem("paper", 12);
    let gaze = 90.0;
    let base = answer(&problem, gaze);
    let ub = upper_bound(&problem, gaze).unwrap();
    let l = base.limits.clone();
    let period = 1.0 / base.frame_rate_hz;
    let p_hi = *problem
        .levels
        .power_w
        .iter()
        .max_by(|a, b| a.total_cmp(b))
        .unwrap();
    let p_lo = *problem
        .levels
        .power_w
        .iter()
        .min_by(|a, b| a.total_cmp(b))
        .unwrap();
    let w_slow = problem
        .levels
        .spin_rad_s
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .max(l.spin_rad_s_min);
    let n = base.bins.len();
    let narrow_deg = 0.5;
    let wide_deg = 360.0 - narrow_deg * (n - 1) as f64;
    let slow_s = (n - 1) as f64 * narrow_deg.to_radians() / w_slow;
    let w_fast = wide_deg.to_radians() / (period - slow_s);
    let mut prof = base.clone();
    let mut start = 0.0;
    for (i, b) in prof.bins.iter_mut().enumerate() {
        // Bin 3 (90–120°) is under the gaze: the lowest weight.
        let (w, p, spin) = if i == 3 {
            (wide_deg, p_lo, w_fast)
        } else {
            (narrow_deg, p_hi, w_slow)
        };
        b.start_deg = start;
        b.width_deg = w;
        b.power_w = p;
        b.spin_start_rad_s = spin;
        b.spin_end_rad_s = spin;
        b.dwell_s = None;
        b.region = None;
        start += w;
    }
    prof.summary = None;
    prof.optimality = None;
    let prof = match certify(prof) {
        Ok(c) => c.profile().clone(),
        Err(e) => panic!("rejected: {e:?}"),
    };
    let e = model_objective(&problem, gaze, &prof).unwrap_err();
    assert!(e.is_input_error() && e.to_string().contains("bins["), "{e}");
    assert!(model_objective(&problem, gaze, &base).unwrap() <= ub);
}

/// The bound takes the problem's hardware levels as exact (module docs:
/// "boxes from limits (not levels, which are exact)"), but the checker
/// knows only the profile's limits: on `paper` (levels 108.6 and 586.4
/// rad/s, limits 31.4–628.3) the answer at 12 bins, gaze 90°, with its two
/// fast bins at the limit 628.3 rad/s and the ten slow ones a little
/// slower (108.33 rad/s, frame kept) is accepted and beats the bound by
/// 0.06 % (the answer sits 3.6e-12 under it).
#[test]
// Scope, not a bug: the bound is over the problem as the optimizer poses it
// (its hardware levels exact). This pins that the scope statement is needed:
// off the levels, a checker-accepted profile can exceed it.
fn off_level_spins_are_outside_the_bound_s_scope() {
    let problem = problem("paper", 12);
    let gaze = 90.0;
    let base = answer(&problem, gaze);
    let ub = upper_bound(&problem, gaze).unwrap();
    let period = 1.0 / base.frame_rate_hz;
    let w_max = base.limits.spin_rad_s_max;
    let level_lo = problem.levels.spin_rad_s[0];
    let fast: Vec<usize> = (0..base.bins.len())
        .filter(|&i| base.bins[i].spin_start_rad_s > 2.0 * level_lo)
        .collect();
    let slow_n = (base.bins.len() - fast.len()) as f64;
    let theta = base.bins[0].width_deg.to_radians();
    let fast_s = fast.len() as f64 * theta / w_max;
    let w_slow = slow_n * theta / (period - fast_s);
    assert!(w_slow < level_lo && w_slow >= base.limits.spin_rad_s_min);
    let mut prof = base.clone();
    for (i, b) in prof.bins.iter_mut().enumerate() {
        let w = if fast.contains(&i) { w_max } else { w_slow };
        b.spin_start_rad_s = w;
        b.spin_end_rad_s = w;
        b.dwell_s = None;
    }
    prof.summary = None;
    prof.optimality = None;
    let prof = match certify(prof) {
        Ok(c) => c.profile().clone(),
        Err(e) => panic!("rejected: {e:?}"),
    };
    let j = model_objective(&problem, gaze, &prof).unwrap();
    assert!(j > ub, "off-level: J = {j}, bound {ub}");
}

/// A block the mode does not move is fixed at its start value in the
/// bound (range mode: every spin at the mean spin), but the checker
/// accepts any spin within the limits: the joint answer on `paper` at 12
/// bins (levels only, limits met, accepted) scored on the same problem in
/// range mode exceeds that mode's bound.
#[test]
// Scope, not a bug: in `range` mode the dwell is the problem's (fixed), and the
// bound is over that problem; a profile that moves the dwell is another
// problem's answer. This pins that the scope statement is needed.
fn another_mode_s_answer_is_outside_the_bound_s_scope() {
    let joint = problem("paper", 12);
    let gaze = 90.0;
    let prof = answer(&joint, gaze);
    let prof = match certify(prof) {
        Ok(c) => c.profile().clone(),
        Err(e) => panic!("rejected: {e:?}"),
    };
    let mut range = problem("paper", 12);
    range.objective.mode = gaze_lidar::planner::Mode::Range;
    let ub = upper_bound(&range, gaze).unwrap();
    let j = model_objective(&range, gaze, &prof).unwrap();
    assert!(j > ub, "joint answer: J = {j}, range-mode bound {ub}");
}

/// Held: in scope (the problem's grid, levels and mode, no `dwell_s`),
/// the answers pushed to the checker's tolerances — powers ×(1 + 0.99e-9)
/// where they are not levels, every spin ×(1 − 0.99e-9) (the frame then
/// 0.99e-9 long), both, and every bin's end spin moved to the next bin's
/// start within the step tolerance — stay under the bound on the three
/// configs whose answers sit near it with free spins (12 bins, gaze 90°).
#[test]
fn answers_pushed_to_the_checker_s_tolerances_stay_under_the_bound() {
    for name in ["multi_level", "smooth", "vls128_eye"] {
        let problem = problem(name, 12);
        let gaze = 90.0;
        let base = answer(&problem, gaze);
        let ub = upper_bound(&problem, gaze).unwrap();
        let free_power = problem.levels.power_w.is_empty();
        let mut accepted = 0;
        for (dp, dw) in [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.0, -1.0), (1.0, -1.0)] {
            let mut prof = base.clone();
            for b in &mut prof.bins {
                if free_power {
                    b.power_w *= 1.0 + dp * 0.99e-9;
                }
                b.spin_start_rad_s *= 1.0 - dw * 0.99e-9;
                b.spin_end_rad_s *= 1.0 - dw * 0.99e-9;
                b.dwell_s = None;
            }
            prof.summary = None;
            prof.optimality = None;
            let Ok(c) = certify(prof) else { continue };
            accepted += 1;
            let j = model_objective(&problem, gaze, c.profile()).unwrap();
            assert!(j <= ub, "{name} ({dp}, {dw}): J = {j} above the bound {ub}");
        }
        assert!(accepted >= 2, "{name}: only {accepted} accepted");
    }
}

/// Held: on `smooth` (acceleration limit 1000 rad/s²) at 12 bins, the
/// extreme spin profiles the acceleration box is built from — the
/// triangle `ω² = W − 2a·d` (`d` the angle from the fastest point,
/// at the limit in every bin) centred on each bin edge, at the mean power —
/// are accepted by the checker and stay under the bound.
#[test]
fn triangle_spin_profiles_at_the_acceleration_limit_stay_under_the_bound() {
    use std::f64::consts::PI;
    let problem = problem("smooth", 12);
    let gaze = 90.0;
    let base = answer(&problem, gaze);
    let ub = upper_bound(&problem, gaze).unwrap();
    let a = base.limits.spin_accel_rad_s2_max.unwrap();
    let period = 1.0 / base.frame_rate_hz;
    let q = a * period / 2.0;
    let (s1, s2) = ((2.0 * a * PI / q + q) / 2.0, (2.0 * a * PI / q - q) / 2.0);
    let w_top = s1 * s1;
    let n = base.bins.len();
    let mut accepted = 0;
    for centre in 0..n {
        let spin_at = |k: usize| {
            let th = (((k + n - centre) % n) as f64) * 2.0 * PI / n as f64;
            let d = th.min(2.0 * PI - th);
            (w_top - 2.0 * a * d).max(0.0).sqrt()
        };
        let mut prof = base.clone();
        for (i, b) in prof.bins.iter_mut().enumerate() {
            b.spin_start_rad_s = spin_at(i);
            b.spin_end_rad_s = spin_at(i + 1);
            b.power_w = base.average_power_w;
            b.dwell_s = None;
        }
        prof.summary = None;
        prof.optimality = None;
        match certify(prof) {
            Ok(c) => {
                accepted += 1;
                let j = model_objective(&problem, gaze, c.profile()).unwrap();
                assert!(j <= ub, "centre {centre}: J = {j} above the bound {ub}");
            }
            Err(e) => eprintln!("centre {centre}: rejected {e:?} (spins {s2}..{s1})"),
        }
    }
    assert!(accepted == n, "{accepted} of {n} accepted");
}
