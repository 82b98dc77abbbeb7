//! The block-coordinate LP/MILP (see the module docs of [`super`]).
//!
//! Variables are normalised to order one (`x = p/P̄`, `τ = t·N/T`) because
//! HiGHS's feasibility tolerances are absolute (1e-7). Continuous solutions
//! are clamped and rescaled to meet bounds, budget and frame exactly, which
//! is why continuous bounds carry a [`MARGIN`]; level (MILP) solutions are
//! exact by construction.

// Loops over bins index several parallel per-bin arrays (θ, weights, caps,
// variables); indices read like the formulation.
#![allow(clippy::needless_range_loop)]

use super::certificate::{Certified, LinearProgram, SolveOptions, Step};
use super::utility::{sqrt_segments, sqrt_segments_n, SqrtSegments};
use std::f64::consts::TAU;

use super::{OptError, Problem};
use crate::eye_safety::bound::{Laser, Rule, Seg, RATIO_MARGIN};
use crate::eye_safety::cuts::{cuts_for, Cut};
use crate::eye_safety::{exposure, EyeSafetyParams};
use crate::model::angle::{next_index, wrap_deg, Arc, Binning};
use crate::model::lidar::PowerAccounting;
use crate::planner::Mode;
use crate::profile::{Bin, Profile, Region, PROFILE_FORMAT};

/// Relative margin kept from continuous bounds, budget and caps.
const MARGIN: f64 = 1e-6;
/// Relative slack on the budget row of a level (MILP) power step: HiGHS
/// accepts a MILP's rows to `MIP_FEASIBILITY_TOL` (1e-10, absolute, on a
/// row of order one to 2π) and a level choice has no continuous part to
/// trim, so the certified row allows 2e-10 relative; 5× inside the
/// checker's `REL_TOL` (1e-9).
const LEVEL_BUDGET_SLACK: f64 = 2e-10;
/// Tie-break added to the weights, growing with signed eccentricity: makes
/// the optimum unique where the acuity is symmetric about the gaze, and is
/// itself rotation-equivariant (a function of eccentricity only), so a
/// rotated problem has the rotated optimum.
const TIE_BREAK: f64 = 1e-3;
/// Trust region of the sequential LP for acceleration limits.
const TRUST: f64 = 0.3;
/// Share of the acceleration limit the linearised constraint may use.
const ACCEL_SHARE: f64 = 0.8;
/// Relative margin every eye-safety cut keeps below its limit: HiGHS's
/// feasibility tolerance (1e-7 on rows normalised to 1) beyond the
/// head-room and the bound's own rounding margin (`RATIO_MARGIN`).
const CUT_MARGIN: f64 = 2e-7;
/// Head-room the power step leaves under the Class 1 limit of the bound, so
/// that a rotated copy of its answer (the fast path) still certifies.
pub(super) const EYE_SAFETY_HEADROOM: f64 = 1e-9;
/// Right-hand side of a cut row normalised to its limit: a power vector
/// that meets it with equality is at `1 − headroom` of the bound's figure
/// for that cut once the bound's rounding margin is applied.
fn cut_rhs() -> f64 {
    level_rhs() * (1.0 - CUT_MARGIN)
}

/// As [`cut_rhs`] for a cut on one bin when the power takes hardware
/// levels: the levels are exact (no solver tolerance enters), so only the
/// head-room and the bound's rounding margin.
fn level_rhs() -> f64 {
    (1.0 - EYE_SAFETY_HEADROOM) / (1.0 + RATIO_MARGIN)
}

/// Rounds of the cutting-plane loop of one power step.
const CUT_ROUNDS: usize = 60;
/// Cuts at or above this ratio of the current iterate are binding: the
/// dwell step linearises them.
const BINDING: f64 = 1.0 - 1e-3;
/// Chords of the density utility on a dwell column inside a trust region
/// (±[`TRUST`] around the iterate: a sequential LP's first-order model,
/// where the acceleration rows allow far smaller moves still). Measured on
/// `smooth` (360 bins, joint): 16 chords → 4 makes the whole solve 1.8×
/// faster (99 → 55 ms) and moves the answer's exact objective by 2e-14
/// relative (`optimality.global.objective` 8.864885452179 either way).
/// Columns without a trust region keep [`super::UTILITY_SEGMENTS`].
const TRUST_REGION_SEGMENTS: usize = 4;

/// Dwell-step iterations when the acceleration limit is finite (at most).
const SLP_ROUNDS: usize = 5;
/// The sequential LP stops once a dwell step moves no bin's dwell by more
/// than this (relative). On `smooth` (360 bins, joint) the five rounds'
/// moves were 2.7e-2, 7.6e-4, 2.4e-5, 3.2e-6, 3.7e-6; stopping after the
/// second changes the answer's exact objective by −1.4e-7 relative
/// (8.864885070 with five rounds, 8.864884199 with two; the global gap is
/// 2.4e-2) and makes the whole process 1.24× faster than stopping after the
/// third (1e-4).
const SLP_SETTLED: f64 = 1e-3;

/// Whether the dwell `next` is within [`SLP_SETTLED`] of `t` in every bin.
fn settled(next: &[f64], t: &[f64]) -> bool {
    next.iter()
        .zip(t)
        .all(|(a, b)| (a - b).abs() <= SLP_SETTLED * b.abs())
}

pub(super) struct Grid {
    pub(super) n: usize,
    pub(super) width_deg: Vec<f64>,
    pub(super) theta: Vec<f64>,
    pub(super) start_deg: Vec<f64>,
    pub(super) weight: Vec<f64>,
    in_rof: Vec<bool>,
}

pub(super) fn grid(problem: &Problem, gaze_deg: f64) -> Result<Grid, OptError> {
    super::validate_bins(problem.bins, "bins")?;
    // A `Problem` built in code, not from a config, is checked too.
    let o = &problem.objective;
    super::config::weight("objective.range_weight", o.range_weight)?;
    super::config::weight("objective.resolution_weight", o.resolution_weight)?;
    super::config::weight("objective.floor_weight", o.floor_weight)?;
    for (k, p) in o.priors.iter().enumerate() {
        super::config::weight(&format!("objective.priors[{k}].weight"), p.weight)?;
    }
    let b = Binning::uniform(problem.bins).map_err(|e| OptError::Invalid {
        field: "bins".into(),
        reason: e.to_string(),
    })?;
    let n = b.len();
    let regions = problem.focus.regions(gaze_deg);
    let eps = problem.objective.floor_weight;
    let mut weight = Vec::with_capacity(n);
    let mut in_rof = Vec::with_capacity(n);
    for i in 0..n {
        let c = b.center_deg(i);
        let prior: f64 = problem
            .objective
            .priors
            .iter()
            .filter(|p| {
                Arc {
                    start_deg: wrap_deg(p.start_deg),
                    width_deg: p.width_deg,
                }
                .contains(c)
            })
            .map(|p| p.weight)
            .sum();
        let ecc = crate::model::angle::diff_deg(c, gaze_deg);
        weight.push(
            problem.focus.acuity.deficit(ecc) + prior + eps + TIE_BREAK * (ecc + 180.0) / 360.0,
        );
        in_rof.push(regions.rof.contains(c));
    }
    Ok(Grid {
        n,
        width_deg: (0..n).map(|i| b.width_deg(i)).collect(),
        theta: (0..n).map(|i| b.width_deg(i).to_radians()).collect(),
        start_deg: (0..n).map(|i| b.start_deg(i)).collect(),
        weight,
        in_rof,
    })
}

/// The one eye-safety model as the optimizer asks it: the core's sound
/// bound decides (the verdict `check` gives), and its concrete exposures
/// ([`crate::eye_safety::cuts`]) are the linear cuts the programs carry
/// (`specs/optimizer.md`, "Eye safety as cuts"). No eye-safety formula
/// lives here.
struct Eye {
    params: EyeSafetyParams,
    laser: Laser,
    pulse_rate_hz: f64,
}

fn eye(problem: &Problem) -> Result<Option<Eye>, OptError> {
    let Some(params) = &problem.lidar.limits.eye_safety else {
        return Ok(None);
    };
    let laser =
        exposure::laser(params, problem.lidar.pulse_rate_hz).map_err(|e| OptError::Invalid {
            field: "limits.eye_safety".into(),
            reason: e.to_string(),
        })?;
    Ok(Some(Eye {
        params: params.clone(),
        laser,
        pulse_rate_hz: problem.lidar.pulse_rate_hz,
    }))
}

/// The bins as the eye-safety model sees them.
fn segs(g: &Grid, spins: &[(f64, f64)], p: &[f64]) -> Vec<Seg> {
    (0..g.n)
        .map(|i| Seg {
            start_deg: g.start_deg[i],
            width_deg: g.width_deg[i],
            power_w: p[i],
            spin_start_rad_s: spins[i].0,
            spin_end_rad_s: spins[i].1,
        })
        .collect()
}

impl Eye {
    /// The bound's worst ratio and the azimuth where it binds.
    fn verdict(&self, segs: &[Seg]) -> Result<(f64, f64), OptError> {
        self.report(segs)
            .map(|r| (r.worst_ratio, r.worst_azimuth_deg))
    }

    /// The bound's whole report.
    fn report(&self, segs: &[Seg]) -> Result<exposure::ExposureReport, OptError> {
        exposure::evaluate_segments(segs, &self.params, self.pulse_rate_hz)
            .map_err(|e| OptError::Infeasible(format!("eye safety: {e}")))
    }

    /// The concrete exposures at or above `threshold` for these bins, of
    /// the head's bound when the sensor has a head.
    /// Every Rule 1 cut on one bin comes too (a column bound, free). An
    /// error of the head's evaluation gives no cuts: the bound's own
    /// evaluation ([`Self::report`]) reports it before any answer stands.
    fn cuts(&self, segs: &[Seg], witness_deg: &[f64], threshold: f64) -> Vec<Cut> {
        cuts_for(segs, &self.params, &self.laser, witness_deg, threshold, 0.0).unwrap_or_default()
    }
}

/// Plain-words checks of requests that cannot be met, before any solve.
fn prechecks(problem: &Problem, eye: Option<&Eye>) -> Result<(), OptError> {
    let l = &problem.lidar.limits;
    let lid = &problem.lidar;
    let w_mean = lid.mean_spin_rad_s();
    if l.spin_rad_s_max < w_mean * (1.0 - 1e-12) {
        return Err(OptError::Infeasible(format!(
            "spin_rad_s_max {:.3} rad/s cannot meet the frame period: one turn in 1/frame_rate_hz = {:.4} s needs a mean spin of {:.3} rad/s",
            l.spin_rad_s_max,
            1.0 / lid.frame_rate_hz,
            w_mean
        )));
    }
    if l.spin_rad_s_min > w_mean * (1.0 + 1e-12) {
        return Err(OptError::Infeasible(format!(
            "spin_rad_s_min {:.3} rad/s is above the mean spin {w_mean:.3} rad/s that frame_rate_hz {} requires",
            l.spin_rad_s_min, lid.frame_rate_hz
        )));
    }
    if l.power_w_min > lid.average_power_w * (1.0 + 1e-12) {
        return Err(OptError::Infeasible(format!(
            "power_w_min {:.4e} W alone exceeds the average power budget {:.4e} W",
            l.power_w_min, lid.average_power_w
        )));
    }
    if l.power_w_min > l.power_w_max {
        return Err(OptError::Invalid {
            field: "limits.power_w_min".into(),
            reason: format!("{} is above power_w_max {}", l.power_w_min, l.power_w_max),
        });
    }
    if let Some(e) = eye {
        // With the spin fixed (range mode: the mean spin everywhere), the
        // floor alone must be Class 1; more power never lowers the bound.
        if l.power_w_min > 0.0 && !problem.objective.mode.controls_resolution() {
            let g = grid(problem, 0.0)?;
            let w = lid.mean_spin_rad_s();
            let (ratio, at) =
                e.verdict(&segs(&g, &vec![(w, w); g.n], &vec![l.power_w_min; g.n]))?;
            if ratio > 1.0 {
                return Err(OptError::Infeasible(format!(
                    "eye safety: power_w_min {:.4e} W everywhere at the mean spin is {:.1} % of the Class 1 limit (worst at {at:.3}°) at {} nm",
                    l.power_w_min,
                    100.0 * ratio,
                    e.params.wavelength_nm
                )));
            }
        }
    }
    if !problem.levels.spin_rad_s.is_empty()
        && l.spin_accel_rad_s2_max.is_some()
        && problem.objective.mode.controls_resolution()
    {
        return Err(OptError::Invalid {
            field: "levels.spin_rad_s".into(),
            reason: "spin set-points step the spin, which a finite limits.spin_accel_rad_s2_max forbids; drop the set-points for smooth spin".into(),
        });
    }
    for (k, &lv) in problem.levels.power_w.iter().enumerate() {
        if !(lv.is_finite() && lv >= 0.0) {
            return Err(OptError::Invalid {
                field: format!("levels.power_w[{k}]"),
                reason: format!("{lv} must be finite and >= 0"),
            });
        }
    }
    for (k, &lv) in problem.levels.spin_rad_s.iter().enumerate() {
        if !(lv.is_finite() && lv > 0.0) {
            return Err(OptError::Invalid {
                field: format!("levels.spin_rad_s[{k}]"),
                reason: format!("{lv} must be finite and > 0"),
            });
        }
    }
    Ok(())
}

/// Dwell of each bin under `spins` (constant acceleration within a bin), s.
fn dwell_of(g: &Grid, spins: &[(f64, f64)]) -> Vec<f64> {
    spins
        .iter()
        .zip(&g.theta)
        .map(|(w, th)| 2.0 * th / (w.0 + w.1))
        .collect()
}

/// Power step: the spin fixed (`spins`, rad/s at each bin's two edges).
/// Without eye safety one LP. With it, a cutting-plane loop
/// (`specs/optimizer.md`, "Eye safety as cuts"): solve, ask the core bound,
/// add the concrete exposures the answer breaks (valid for every power
/// vector), repeat until the bound certifies. `pool` holds the cuts of
/// these spins (empty for new spins) and keeps the ones added.
fn power_step(
    problem: &Problem,
    g: &Grid,
    eye: Option<&Eye>,
    spins: &[(f64, f64)],
    pool: &mut Vec<Cut>,
) -> Result<(Vec<f64>, PowerLp), OptError> {
    let t = &dwell_of(g, spins)[..];
    let lid = &problem.lidar;
    let l = &lid.limits;
    let p_mean = lid.average_power_w;
    let period: f64 = t.iter().sum();
    let lam = problem.objective.range_weight;
    let levels = &problem.levels.power_w;
    let mut round = 0;
    // Where no valid cut separates (see below), the limits of one class of
    // cuts — Rule 1's (0) or the windows' (1) — are divided by a factor.
    let mut factor = [1.0f64; 2];
    let class = |c: &Cut| usize::from(c.rule != Rule::SinglePulse);
    loop {
        // A cut on one bin's power alone is that bin's column bound (the
        // utility's chords then span the reachable powers only).
        let rhs = if levels.is_empty() {
            cut_rhs()
        } else {
            level_rhs()
        };
        let mut caps = vec![f64::INFINITY; g.n];
        // The same without margins: a floor between the two is kept (the
        // bound decides), one above the bare limit is infeasible.
        let mut bare = vec![f64::INFINITY; g.n];
        if let Some(e) = eye {
            for c in pool.iter() {
                if let [(b, n)] = c.pulses[..] {
                    caps[b] = caps[b].min(rhs * c.limit_j / factor[class(c)] * e.pulse_rate_hz / n);
                    bare[b] = bare[b].min(c.limit_j * e.pulse_rate_hz / n);
                }
            }
        }
        let mut lp = LinearProgram::default();
        // x_i = p_i / P̄ as a linear form (a continuous column or Σ levels·z).
        let mut x: Vec<Vec<(usize, f64)>> = Vec::with_capacity(g.n);
        let mut bins: Vec<PowerBin> = Vec::with_capacity(g.n);
        let mut utility_constant = 0.0;
        for i in 0..g.n {
            if bare[i] < l.power_w_min {
                let wl = l.eye_safety.as_ref().map_or(0.0, |p| p.wavelength_nm);
                return Err(OptError::Infeasible(format!(
                    "eye-safety cap {:.4e} W at {wl} nm in bin {i} (the single-pulse limit at this spin) is below power_w_min {:.4e} W",
                    bare[i], l.power_w_min
                )));
            }
            let caps_i = caps[i].max(l.power_w_min);
            let hi = l.power_w_max.min(caps_i);
            if levels.is_empty() {
                let lo_x = l.power_w_min / p_mean;
                let hi_x = (hi / p_mean * (1.0 - MARGIN)).max(lo_x);
                let xi = lp.add_col(lo_x, hi_x, 0.0, false);
                // The utility as boxed segment columns (see `utility`).
                let c = lam * g.theta[i] * g.weight[i];
                let shape = sqrt_segments(lo_x, hi_x);
                let deltas = shape.add_to(&mut lp, xi, 1.0, lo_x, c);
                utility_constant += c * shape.base;
                x.push(vec![(xi, 1.0)]);
                bins.push(PowerBin::Continuous {
                    x: xi,
                    lo: lo_x,
                    deltas,
                    shape,
                });
            } else {
                let allowed: Vec<f64> = levels
                    .iter()
                    .copied()
                    .filter(|&lv| lv >= l.power_w_min && lv <= hi)
                    .collect();
                if allowed.is_empty() {
                    return Err(OptError::Infeasible(format!(
                            "no power level lies within [power_w_min, min(power_w_max, the bin's eye-safety cut)] = [{:.4e}, {:.4e}] W in bin {i}",
                            l.power_w_min, hi
                        )));
                }
                let zs: Vec<(f64, usize)> = allowed
                    .iter()
                    .map(|&lv| {
                        let cost = lam * g.theta[i] * g.weight[i] * (lv / p_mean).sqrt();
                        (lv, lp.add_col(0.0, 1.0, cost, true))
                    })
                    .collect();
                let one: Vec<(usize, f64)> = zs.iter().map(|&(_, z)| (z, 1.0)).collect();
                lp.add_row(&one, 1.0, 1.0);
                x.push(zs.iter().map(|&(lv, z)| (z, lv / p_mean)).collect());
                bins.push(PowerBin::Levels(zs));
            }
        }
        // The utilities' constants Σ c·√lo as one column fixed at 1.
        let one = (utility_constant != 0.0).then(|| lp.add_col(1.0, 1.0, utility_constant, false));
        let scaled = |k: f64, form: &[(usize, f64)], out: &mut Vec<(usize, f64)>| {
            out.extend(form.iter().map(|&(j, a)| (j, k * a)));
        };
        // Budget.
        // Levels: the budget exactly, plus [`LEVEL_BUDGET_SLACK`] (far inside
        // the checker's REL_TOL) so that a level choice that meets it in
        // floating point (the closed form's does, to the last bit) also meets
        // it in the exact arithmetic of the certificate.
        let budget_margin = if levels.is_empty() {
            1.0 - MARGIN
        } else {
            1.0 + LEVEL_BUDGET_SLACK
        };
        let mut spend = Vec::new();
        let budget = match lid.power_accounting {
            PowerAccounting::Angle => {
                for i in 0..g.n {
                    scaled(g.theta[i], &x[i], &mut spend);
                }
                TAU * budget_margin
            }
            PowerAccounting::Time => {
                for i in 0..g.n {
                    scaled(t[i] / period, &x[i], &mut spend);
                }
                budget_margin
            }
        };
        // A floor that spends the whole budget (power_w_min = P̄) keeps its
        // own spend: the margin must not make the all-floor answer
        // infeasible.
        let floor_spend: f64 = spend.iter().map(|&(j, a)| a * lp.col_lo[j]).sum();
        lp.add_row(&spend, f64::NEG_INFINITY, budget.max(floor_spend));
        // Slew.
        if let Some(s) = l.power_slew_w_per_deg_max {
            for i in 0..g.n {
                let j = next_index(i, g.n);
                let lim = s * 0.5 * (g.width_deg[i] + g.width_deg[j]) / p_mean * (1.0 - MARGIN);
                let mut d = Vec::new();
                scaled(1.0, &x[j], &mut d);
                scaled(-1.0, &x[i], &mut d);
                lp.add_row(&d, -lim, lim);
            }
        }

        if let Some(e) = eye {
            for c in pool.iter().filter(|c| c.pulses.len() > 1) {
                let mut row = Vec::new();
                let limit = c.limit_j / factor[class(c)];
                for &(b, n) in &c.pulses {
                    scaled(n * p_mean / (e.pulse_rate_hz * limit), &x[b], &mut row);
                }
                // A floor alone at more than the row's side (but within the
                // bare limit: checked below) keeps its own value.
                let at_floor: f64 = c.pulses.iter().map(|&(_, n)| n).sum::<f64>() * l.power_w_min
                    / (e.pulse_rate_hz * limit);
                if at_floor > factor[class(c)] {
                    let wl = l.eye_safety.as_ref().map_or(0.0, |p| p.wavelength_nm);
                    return Err(OptError::Infeasible(format!(
                        "eye safety at {wl} nm: power_w_min {:.4e} W in every bin is {:.4} of the limit of a window at {:.3}° ({:?})",
                        l.power_w_min,
                        at_floor / factor[class(c)],
                        c.azimuth_deg,
                        c.rule
                    )));
                }
                lp.add_row(
                    &row,
                    f64::NEG_INFINITY,
                    cut_rhs().max(at_floor * (1.0 + 1e-12)),
                );
            }
        }
        let solved = lp.solve("power").map_err(|err| match (err, eye) {
            (OptError::Infeasible(_), Some(_)) => OptError::Infeasible(format!(
                "the power step has no solution within the limits: {} eye-safety cuts (concrete exposures at the Class 1 limit) leave no powers within power_w_min/max, the budget and the slew limit",
                pool.len()
            )),
            (other, _) => other,
        })?;
        let p = powers(problem, g, t, &bins, &x, &solved.x);
        if let Some(e) = eye {
            let s = segs(g, spins, &p);
            let report = e.report(&s)?;
            let (ratio, witness) = (report.worst_ratio, report.worst_azimuth_deg);
            if ratio > 1.0 - EYE_SAFETY_HEADROOM {
                round += 1;
                // Every bin edge ± h first (rotation-equivariant: a rotated
                // problem gets the rotated cuts); the bound's witness only
                // when those hold.
                let new_cuts = |extra: &[f64]| -> Vec<Cut> {
                    e.cuts(&s, extra, cut_rhs())
                        .into_iter()
                        .filter(|c| !pool.contains(c))
                        .collect()
                };
                let mut fresh = new_cuts(&[]);
                if fresh.is_empty() {
                    fresh = new_cuts(&[witness]);
                }
                if round > CUT_ROUNDS {
                    return Err(OptError::Solver(format!(
                        "eye-safety cuts: after {round} rounds the bound still gives {ratio:.6} at {witness:.3}° ({} cuts, limits divided by {factor:?})",
                        pool.len(),
                    )));
                }
                if fresh.is_empty() {
                    // The bound exceeds every valid cut here (its
                    // conservatism in the rule that binds): divide the
                    // limits of that rule's class of cuts by the bound's
                    // excess over the strongest of them, so the next answer
                    // meets them where the bound would.
                    let k = usize::from(report.binding_rule != Rule::SinglePulse);
                    let near: Vec<Cut> = e
                        .cuts(&s, &[witness], 0.0)
                        .into_iter()
                        .filter(|c| class(c) == k)
                        .collect();
                    let top = near
                        .iter()
                        .map(|c| c.ratio(&p, e.pulse_rate_hz))
                        .fold(0.0, f64::max);
                    if top <= 0.0 {
                        return Err(OptError::Solver(format!(
                            "eye-safety cuts: the bound gives {ratio:.6} at {witness:.3}° ({:?}) and no cut of that rule has any exposure there",
                            report.binding_rule
                        )));
                    }
                    factor[k] = (factor[k] * ratio / (1.0 - EYE_SAFETY_HEADROOM)).max(ratio / top)
                        * (1.0 + 1e-9);
                    let top_cuts: Vec<Cut> = near
                        .into_iter()
                        .filter(|c| {
                            c.ratio(&p, e.pulse_rate_hz) * factor[k] >= cut_rhs()
                                && !pool.contains(c)
                        })
                        .collect();
                    pool.extend(top_cuts);
                    continue;
                }
                pool.extend(fresh);
                continue;
            }
        }
        return Ok((
            p,
            PowerLp {
                lp,
                bins,
                one,
                tightening: (factor[0].max(factor[1]) > 1.0).then_some(factor[0].max(factor[1])),
                p_mean,
                floor_w: l.power_w_min,
                y: solved.y,
                solver_dual_bound: solved.solver_dual_bound,
            },
        ));
    }
}

/// The powers (W) of a solved power step: levels as chosen, continuous
/// powers clamped into their bounds and trimmed to the budget exactly
/// (lower powers never break a cut: every cut has nonnegative
/// coefficients).
fn powers(
    problem: &Problem,
    g: &Grid,
    t: &[f64],
    bins: &[PowerBin],
    x: &[Vec<(usize, f64)>],
    sol: &[f64],
) -> Vec<f64> {
    let lid = &problem.lidar;
    let l = &lid.limits;
    let p_mean = lid.average_power_w;
    let period: f64 = t.iter().sum();
    let eval = |form: &[(usize, f64)]| form.iter().map(|&(j, a)| a * sol[j]).sum::<f64>();
    let mut p: Vec<f64> = bins
        .iter()
        .zip(x)
        .map(|(b, form)| match b {
            PowerBin::Continuous { .. } => eval(form) * p_mean,
            PowerBin::Levels(zs) => zs
                .iter()
                .max_by(|a, b| sol[a.1].total_cmp(&sol[b.1]))
                .map_or(0.0, |&(level, _)| level),
        })
        .collect();
    if problem.levels.power_w.is_empty() {
        for pi in &mut p {
            *pi = pi.clamp(l.power_w_min, l.power_w_max);
        }
        // Exact budget: HiGHS meets it to 1e-7 absolute; trim the excess.
        let spent = match lid.power_accounting {
            PowerAccounting::Angle => p.iter().zip(&g.theta).map(|(a, b)| a * b).sum::<f64>() / TAU,
            PowerAccounting::Time => p.iter().zip(t).map(|(a, b)| a * b).sum::<f64>() / period,
        };
        if spent > p_mean {
            let scale = p_mean / spent;
            for pi in &mut p {
                *pi = (*pi * scale).max(l.power_w_min);
            }
        }
        if let Some(s) = l.power_slew_w_per_deg_max {
            slew_down(&mut p, g, s);
        }
    }
    p
}

/// Lowers powers (W) until every neighbour pair meets the program's slew
/// rows, `|p_j − p_i| ≤ s·(Δ_i + Δ_j)/2·(1 − MARGIN)`, a few ulps inside:
/// each power becomes the least over all bins of that bin's power plus the
/// slew allowance along the circle between them (sweeps both ways until
/// nothing moves). HiGHS meets those rows only to its absolute tolerance
/// (1e-7 of `P̄`), more than the limit itself when the limit is tiny or 0
/// (found by breaker3: a 0 W/deg limit gave a profile the checker
/// rejected). Lowering never breaks the budget or an eye-safety cut (their
/// coefficients are nonnegative) nor the floor (a power is only ever set to
/// a neighbour's plus a nonnegative allowance); a no-op where HiGHS kept
/// the rows.
fn slew_down(p: &mut [f64], g: &Grid, s: f64) {
    let n = p.len();
    let lim: Vec<f64> = (0..n)
        .map(|i| {
            let j = next_index(i, n);
            s * 0.5
                * (g.width_deg[i] + g.width_deg[j])
                * (1.0 - MARGIN)
                * (1.0 - 8.0 * f64::EPSILON)
        })
        .collect();
    // A min-plus closure on a cycle settles within a few sweeps each way;
    // the cap only guards against a rounding cycle.
    for _ in 0..4 * n + 4 {
        let mut moved = false;
        for i in 0..n {
            let j = next_index(i, n);
            if p[j] > p[i] + lim[i] {
                p[j] = p[i] + lim[i];
                moved = true;
            }
        }
        for i in (0..n).rev() {
            let j = next_index(i, n);
            if p[i] > p[j] + lim[i] {
                p[i] = p[j] + lim[i];
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
}

/// How a bin's power enters the power step's program.
enum PowerBin {
    /// `x = p/P̄` column (lower bound `lo`), the utility's segment
    /// columns (see `utility`).
    Continuous {
        x: usize,
        lo: f64,
        deltas: Vec<usize>,
        shape: SqrtSegments,
    },
    /// One binary per allowed level (W, column).
    Levels(Vec<(f64, usize)>),
}

/// The final power step's program, with what it takes to certify any power
/// vector against it.
pub(super) struct PowerLp {
    lp: LinearProgram,
    bins: Vec<PowerBin>,
    /// The largest factor an eye-safety cut was tightened by, if any.
    pub(super) tightening: Option<f64>,
    /// The column fixed at 1 that carries the utilities' constants.
    one: Option<usize>,
    p_mean: f64,
    floor_w: f64,
    y: Vec<f64>,
    solver_dual_bound: Option<f64>,
}

/// Shrink steps tried (towards the power floor) when rounding leaves a
/// row a few ulps over.
const REPAIR_TRIES: usize = 40;

impl PowerLp {
    /// The program's point for powers `p` (W): `x = p/P̄`, the segments
    /// filled greedily (a few ulps short, so the row holds exactly); `None`
    /// when a power is not an allowed level.
    fn point(&self, p: &[f64]) -> Option<Vec<f64>> {
        let mut v = vec![0.0; self.lp.cost.len()];
        if let Some(one) = self.one {
            v[one] = 1.0;
        }
        for (b, &pi) in self.bins.iter().zip(p) {
            match b {
                PowerBin::Continuous {
                    x,
                    lo,
                    deltas,
                    shape,
                } => {
                    let xi = (pi / self.p_mean).clamp(self.lp.col_lo[*x], self.lp.col_hi[*x]);
                    v[*x] = xi;
                    for (&d, f) in deltas.iter().zip(shape.fill(*lo, xi)) {
                        v[d] = f;
                    }
                }
                PowerBin::Levels(zs) => {
                    let k = zs.iter().position(|&(lv, _)| lv == pi)?;
                    v[zs[k].1] = 1.0;
                }
            }
        }
        Some(v)
    }

    /// Certifies the powers `p` (the profile's) against this program: the
    /// point is checked exactly, shrinking continuous powers towards the
    /// floor by a few ulps where rounding left a row over.
    /// Returns the certificate and the powers it is for (`p`, or `p` shrunk
    /// by a few ulps; never higher).
    pub(super) fn certify(&self, p: &[f64]) -> Result<(Certified, Vec<f64>), String> {
        let floor = self.floor_w;
        let mut q = p.to_vec();
        for k in 0..REPAIR_TRIES {
            let v = self.point(&q).ok_or_else(|| {
                "a power is not one of the hardware levels (the eye-safety fit scaled it)"
                    .to_owned()
            })?;
            match Certified::new(
                Step::Power,
                self.lp.clone(),
                v,
                self.y.clone(),
                self.solver_dual_bound,
            ) {
                Ok(c) => return Ok((c, q)),
                Err(e)
                    if k + 1 == REPAIR_TRIES
                        || self.bins.iter().any(|b| matches!(b, PowerBin::Levels(_))) =>
                {
                    return Err(e.to_string())
                }
                Err(_) => {}
            }
            let shrink = 1.0 - f64::EPSILON * f64::from(1u32 << k.min(30));
            for qi in &mut q {
                *qi = floor + (*qi - floor).max(0.0) * shrink;
            }
        }
        Err("the power step's answer could not be certified exactly".into())
    }
}

/// HiGHS's primal feasibility tolerance on the dwell step's program (its
/// default is 1e-7): the certified program's rows are widened by
/// `2·DWELL_FEASIBILITY_TOL·(1 + Σ|a|)` ([`LinearProgram::widened`]).
const DWELL_FEASIBILITY_TOL: f64 = 1e-9;

/// A dwell step's answer: the dwell (s), and its program's exact
/// certificate or why there is none.
pub(super) struct DwellStep {
    t: Vec<f64>,
    cert: Result<Certified, String>,
}

/// Dwell step: power `p` fixed; `current` is the iterate for linearisation.
///
/// Eye safety: the cuts `binding` at `(p, current)` (concrete exposures at
/// their limit, found by the power step before) linearised in dwell — the
/// pulses a cut counts from bin `b` scaled by `t_b/t_b⁰` (a pass over `b`
/// holds pulses in proportion to its time there), the limits held at the
/// iterate's — inside a trust region of ±[`TRUST`] on the bins they touch.
/// Exact at the iterate, first order around it; the bound decides after
/// (the power step that follows restores certified powers; without one the
/// move is shortened until the bound certifies, see [`solve`]).
///
/// Certificate (`specs/optimizer.md`, "The dwell step's certificate"):
/// HiGHS solves the program at [`DWELL_FEASIBILITY_TOL`]; its point, with
/// the columns clamped into their bounds and the binaries rounded, is
/// checked exactly against the program with every row widened by twice
/// that tolerance (the frame equality `Σ τ = N` becomes a range of width
/// `4·10⁻⁹·(1 + N)`), with the relaxation's row duals as multipliers. The
/// dwell handed on is that point's, rescaled to the exact frame period (a
/// relative move of at most `2·10⁻⁹·(1 + 1/N)`).
fn dwell_step(
    problem: &Problem,
    g: &Grid,
    binding: &[Cut],
    pulse_rate_hz: f64,
    p: &[f64],
    current: &[f64],
) -> Result<DwellStep, OptError> {
    let mut touched = vec![false; g.n];
    for c in binding {
        for &(b, _) in &c.pulses {
            touched[b] = true;
        }
    }
    let lid = &problem.lidar;
    let l = &lid.limits;
    let period = 1.0 / lid.frame_rate_hz;
    let unit = period / g.n as f64; // τ = t / unit
    let w_mean = lid.mean_spin_rad_s();
    let lam = problem.objective.resolution_weight;
    let setpoints = &problem.levels.spin_rad_s;
    let mut lp = LinearProgram::default();
    // τ_i as a linear form over the columns.
    let mut tau: Vec<Vec<(usize, f64)>> = Vec::with_capacity(g.n);
    // Per bin with set-points, (spin, binary column) per set-point.
    let mut sp_cols: Vec<Vec<(f64, usize)>> = Vec::new();
    let mut start: Vec<f64> = Vec::new();
    let mut utility_constant = 0.0;
    let allowed: Vec<f64> = setpoints
        .iter()
        .copied()
        .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max)
        .collect();
    if !setpoints.is_empty() && allowed.is_empty() {
        return Err(OptError::Infeasible(
            "no spin set-point lies within [spin_rad_s_min, spin_rad_s_max]".into(),
        ));
    }
    for i in 0..g.n {
        let th = g.theta[i];
        if setpoints.is_empty() {
            let lo = th / l.spin_rad_s_max / unit * (1.0 + MARGIN);
            let hi = if l.spin_rad_s_min > 0.0 {
                th / l.spin_rad_s_min / unit * (1.0 - MARGIN)
            } else {
                1e9
            };
            // Where the margins cross (spin limits within 2e-6 of each
            // other, e.g. equal: a fixed spin), the limits themselves.
            let (lo, hi) = if lo <= hi {
                (lo, hi)
            } else {
                let bare = |w: f64| th / w / unit;
                (
                    bare(l.spin_rad_s_max),
                    bare(l.spin_rad_s_min).max(bare(l.spin_rad_s_max)),
                )
            };
            let (mut lo, mut hi) = (lo, hi);
            let trust = l.spin_accel_rad_s2_max.is_some() || touched[i];
            if trust {
                lo = lo.max(current[i] / unit * (1.0 - TRUST));
                hi = hi.min(current[i] / unit * (1.0 + TRUST)).max(lo);
            }
            let t0 = (current[i] / unit).max(lo).min(hi);
            let ti = lp.add_col(lo, hi, 0.0, false);
            start.push(t0);
            // Density ratio r = t·2π/(θ·T) = τ · (unit·2π/(θ·T)).
            let k = unit * TAU / (th * period);
            let (r_lo, r_hi) = (
                w_mean / l.spin_rad_s_max,
                if l.spin_rad_s_min > 0.0 {
                    w_mean / l.spin_rad_s_min
                } else {
                    1e3
                },
            );
            // The utility as boxed segment columns on the densities this
            // column reaches (its box: the spin limits, and the trust region
            // where it applies), Σ δ ≤ k·τ − r_0 (see `utility`; its
            // constant does not move the optimum).
            let r_0 = r_lo.max(k * lo);
            let chords = if trust {
                TRUST_REGION_SEGMENTS
            } else {
                super::UTILITY_SEGMENTS
            };
            let shape = sqrt_segments_n(r_0, r_hi.min(k * hi).max(r_0), chords);
            let c = lam * th * g.weight[i];
            shape.add_to(&mut lp, ti, k, r_0, c);
            utility_constant += c * shape.base;
            start.extend(shape.fill(r_0, k * t0));
            tau.push(vec![(ti, 1.0)]);
        } else {
            let ys: Vec<(f64, usize)> = allowed
                .iter()
                .map(|&w| {
                    let cost = lam * th * g.weight[i] * (w_mean / w).sqrt();
                    start.push(0.0);
                    (w, lp.add_col(0.0, 1.0, cost, true))
                })
                .collect();
            let one: Vec<(usize, f64)> = ys.iter().map(|&(_, y)| (y, 1.0)).collect();
            lp.add_row(&one, 1.0, 1.0);
            tau.push(ys.iter().map(|&(w, y)| (y, th / w / unit)).collect());
            sp_cols.push(ys);
        }
    }
    // The utilities' constants Σ c·√r_0 as one column fixed at 1 (as the
    // power step's), so the program's objective is the chord model's value
    // of the profile, comparable with `exact_objective`.
    if utility_constant != 0.0 {
        lp.add_col(1.0, 1.0, utility_constant, false);
        start.push(1.0);
    }
    let n = g.n as f64;
    lp.add_row(&tau.concat(), n, n);
    if lid.power_accounting == PowerAccounting::Time {
        // No margin here: with uniform P̄ the budget is exactly tight. The
        // power step that ends every joint solve trims the budget exactly.
        let spend: Vec<(usize, f64)> = tau
            .iter()
            .zip(p)
            .flat_map(|(form, &pi)| {
                form.iter()
                    .map(move |&(j, a)| (j, a * pi / lid.average_power_w))
            })
            .collect();
        lp.add_row(&spend, f64::NEG_INFINITY, n);
    }
    if let Some(a_max) = l.spin_accel_rad_s2_max {
        for i in 0..g.n {
            let j = next_index(i, g.n);
            let w_cur = (g.theta[i] / current[i]).max(g.theta[j] / current[j]);
            let dtheta = 0.5 * (g.theta[i] + g.theta[j]);
            let ds = ACCEL_SHARE * a_max * dtheta * (1.0 - TRUST).powi(3) / w_cur.powi(3);
            // s = t/θ = τ·unit/θ.
            let (ki, kj) = (unit / g.theta[i], unit / g.theta[j]);
            let scaled = |form: &[(usize, f64)], k: f64| -> Vec<(usize, f64)> {
                form.iter().map(|&(c, a)| (c, a * k)).collect()
            };
            let diff = [scaled(&tau[j], kj), scaled(&tau[i], -ki)].concat();
            lp.add_row(&diff, -ds, ds);
        }
    }
    for c in binding {
        let mut en: Vec<(usize, f64)> = Vec::new();
        for &(b, cnt) in &c.pulses {
            let tau0 = current[b] / unit;
            let k = cnt * p[b] / (pulse_rate_hz * c.limit_j) / tau0;
            en.extend(tau[b].iter().map(|&(col, a)| (col, a * k)));
        }
        lp.add_row(&en, f64::NEG_INFINITY, cut_rhs());
    }
    let solved = lp.solve_with(
        "dwell",
        &SolveOptions {
            initial: Some(&start),
            primal_feasibility_tolerance: DWELL_FEASIBILITY_TOL,
        },
    )?;
    let x = lp.clamped(&solved.x);
    let eval = |form: &[(usize, f64)]| form.iter().map(|&(j, a)| a * x[j]).sum::<f64>();
    let mut t: Vec<f64> = if setpoints.is_empty() {
        tau.iter().map(|form| eval(form) * unit).collect()
    } else {
        sp_cols
            .iter()
            .zip(&g.theta)
            .map(|(ys, th)| {
                let w = ys
                    .iter()
                    .max_by(|a, b| x[a.1].total_cmp(&x[b.1]))
                    .map_or(0.0, |&(w, _)| w);
                th / w
            })
            .collect()
    };
    if setpoints.is_empty() {
        // Exact frame period.
        let s: f64 = t.iter().sum();
        for ti in &mut t {
            *ti *= period / s;
        }
    }
    let cert = Certified::new(
        Step::Dwell,
        lp.widened(2.0 * DWELL_FEASIBILITY_TOL),
        x,
        solved.y,
        solved.solver_dual_bound,
    )
    .map_err(|e| format!("the dwell step's answer could not be certified exactly: {e}"));
    Ok(DwellStep { t, cert })
}

/// The spin of dwell `t`: one spin per bin (steps) when `smooth` is
/// false, else continuous node spins (the harmonic mean of the
/// neighbours' slowness) rescaled so the frame period is exact.
fn spins_of(g: &Grid, t: &[f64], smooth: bool, frame_rate_hz: f64) -> Vec<(f64, f64)> {
    if !smooth {
        return t
            .iter()
            .zip(&g.theta)
            .map(|(t, th)| (th / t, th / t))
            .collect();
    }
    let s: Vec<f64> = t.iter().zip(&g.theta).map(|(t, th)| t / th).collect();
    let node: Vec<f64> = (0..g.n)
        .map(|i| 2.0 / (s[(i + g.n - 1) % g.n] + s[i]))
        .collect();
    let dwell: f64 = (0..g.n)
        .map(|i| 2.0 * g.theta[i] / (node[i] + node[next_index(i, g.n)]))
        .sum();
    let c = dwell * frame_rate_hz;
    (0..g.n)
        .map(|i| (node[i] * c, node[next_index(i, g.n)] * c))
        .collect()
}

/// What [`solve`] hands out: the (uncertified) profile, the final power
/// step's program (none when the power does not move) and the dwell
/// steps' certificates.
pub(super) struct Solution {
    pub(super) profile: Profile,
    pub(super) power: Option<PowerLp>,
    pub(super) dwell: Option<DwellCertificates>,
}

/// The dwell steps' certificates.
pub(super) struct DwellCertificates {
    /// The last program's certificate, or the first failure.
    pub(super) last: Result<Certified, String>,
    /// Programs solved.
    pub(super) programs: usize,
    /// Whether the profile's dwell is the last program's point (rescaled
    /// to the exact period): `resolution` mode with spin steps, the move
    /// not shortened for eye safety. Its certificate is then the answer's.
    pub(super) is_answer: bool,
}

impl DwellCertificates {
    fn push(this: &mut Option<Self>, step: DwellStep) -> Vec<f64> {
        let d = this.get_or_insert(Self {
            last: Err(String::new()),
            programs: 0,
            is_answer: false,
        });
        if d.programs == 0 || d.last.is_ok() {
            d.last = step.cert;
        }
        d.programs += 1;
        step.t
    }
}

/// Solves and builds the (uncertified) profile, with the programs' certificates.
pub(super) fn solve(problem: &Problem, gaze_deg: f64) -> Result<Solution, OptError> {
    let g = grid(problem, gaze_deg)?;
    let lid = &problem.lidar;
    let eye = eye(problem)?;
    prechecks(problem, eye.as_ref())?;
    let w_mean = lid.mean_spin_rad_s();
    let t_base: Vec<f64> = g.theta.iter().map(|th| th / w_mean).collect();
    let mut t = t_base.clone();
    let p_start = lid
        .average_power_w
        .clamp(lid.limits.power_w_min, lid.limits.power_w_max);
    let mut p: Vec<f64> = vec![p_start; g.n];
    let mode = problem.objective.mode;
    let mut last: Option<PowerLp> = None;
    let smooth_spin = lid.limits.spin_accel_rad_s2_max.is_some();
    let spin_rounds = if smooth_spin { SLP_ROUNDS } else { 1 };
    let f_p = lid.pulse_rate_hz;
    // The cuts of new spins, found at the powers before the step (a warm
    // start: valid whatever the powers).
    let warm = |spins: &[(f64, f64)], p: &[f64]| -> Vec<Cut> {
        eye.as_ref()
            .map_or_else(Vec::new, |e| e.cuts(&segs(&g, spins, p), &[], BINDING))
    };
    let steps = |t: &[f64]| spins_of(&g, t, false, lid.frame_rate_hz);
    let mut binding: Vec<Cut> = Vec::new();
    let mut dwell: Option<DwellCertificates> = None;
    match mode {
        Mode::Baseline => {}
        Mode::Range => {
            let sp = steps(&t);
            let mut pool = warm(&sp, &p);
            let (pp, plp) = power_step(problem, &g, eye.as_ref(), &sp, &mut pool)?;
            p = pp;
            last = Some(plp);
        }
        Mode::Resolution => {
            for round in 0..spin_rounds {
                let step = match dwell_step(problem, &g, &[], f_p, &p, &t) {
                    // See the joint loop.
                    Err(OptError::Infeasible(_)) if round > 0 => break,
                    r => r?,
                };
                let next = DwellCertificates::push(&mut dwell, step);
                let settled = settled(&next, &t);
                t = next;
                if settled {
                    break;
                }
            }
        }
        Mode::Joint => {
            let rounds = spin_rounds.max(2);
            for round in 0..rounds {
                let step = match dwell_step(problem, &g, &binding, f_p, &p, &t) {
                    // A later round's program (re-linearised acceleration
                    // rows, trust region, the budget at the new powers) can
                    // have no point even though the iterate is a certified
                    // profile's (found by breaker3 at 10⁴ rad/s²): the
                    // sequential LP cannot move from it, so it stops there.
                    Err(OptError::Infeasible(_)) if round > 0 => break,
                    r => r?,
                };
                let next = DwellCertificates::push(&mut dwell, step);
                if last.is_some() && next == t {
                    // A fixed point: both steps are deterministic functions
                    // of (p, t) (the binding cuts are found afresh from
                    // them), so every further round repeats this one.
                    break;
                }
                let settled = smooth_spin && settled(&next, &t);
                t = next;
                if smooth_spin && (settled || round + 1 == rounds) {
                    // The last dwell of a smoothed spin: the final power
                    // step below, on the rebuilt spin, replaces this
                    // round's power step on the step spins.
                    break;
                }
                let sp = steps(&t);
                let mut pool = warm(&sp, &p);
                let (pp, plp) = power_step(problem, &g, eye.as_ref(), &sp, &mut pool)?;
                p = pp;
                last = Some(plp);
                // The binding cuts of the new iterate, found afresh (a
                // function of the iterate alone, not of the loop's path).
                binding = warm(&sp, &p)
                    .into_iter()
                    .filter(|c| c.ratio(&p, f_p) >= BINDING)
                    .collect();
            }
        }
    }
    let smooth = smooth_spin && mode.controls_resolution();
    let mut spins = spins_of(&g, &t, smooth, lid.frame_rate_hz);
    if smooth && mode.controls_range() {
        // Final power step on the exact spin of the rebuilt profile.
        let mut pool = warm(&spins, &p);
        let (pp, plp) = power_step(problem, &g, eye.as_ref(), &spins, &mut pool)?;
        p = pp;
        last = Some(plp);
    }
    let mut shortened = false;
    if let (Some(e), Mode::Resolution) = (eye.as_ref(), mode) {
        // No power step follows the dwell steps: shorten the move from the
        // uniform spin until the bound certifies (the uniform spin itself
        // is the last resort, and the checker has the last word).
        let safe = |sp: &[(f64, f64)]| -> Result<bool, OptError> {
            Ok(e.verdict(&segs(&g, sp, &p))?.0 <= 1.0 - EYE_SAFETY_HEADROOM)
        };
        let mut alpha = 1.0;
        while !safe(&spins)? && alpha > 0.0 {
            shortened = true;
            alpha = if alpha > 1.0 / 64.0 { alpha / 2.0 } else { 0.0 };
            let ta: Vec<f64> = t_base
                .iter()
                .zip(&t)
                .map(|(b, x)| b + alpha * (x - b))
                .collect();
            spins = spins_of(&g, &ta, smooth, lid.frame_rate_hz);
        }
        let (ratio, at) = e.verdict(&segs(&g, &spins, &p))?;
        if ratio > 1.0 - EYE_SAFETY_HEADROOM {
            return Err(OptError::Infeasible(format!(
                "eye safety: the power ({:.4e} W in every bin; resolution mode does not move it) is {:.1} % of the Class 1 limit at {at:.3}° even at the uniform spin",
                p[0],
                100.0 * ratio
            )));
        }
    }
    let bins = (0..g.n)
        .map(|i| Bin {
            start_deg: g.start_deg[i],
            width_deg: g.width_deg[i],
            power_w: p[i],
            spin_start_rad_s: spins[i].0,
            spin_end_rad_s: spins[i].1,
            region: Some(if g.in_rof[i] {
                Region::Rof
            } else {
                Region::Roi
            }),
            dwell_s: Some(2.0 * g.theta[i] / (spins[i].0 + spins[i].1)),
        })
        .collect();
    let profile = Profile {
        format: PROFILE_FORMAT.to_owned(),
        frame_rate_hz: lid.frame_rate_hz,
        pulse_rate_hz: lid.pulse_rate_hz,
        average_power_w: lid.average_power_w,
        power_accounting: lid.power_accounting,
        gaze_deg: Some(wrap_deg(gaze_deg)),
        limits: lid.limits.clone(),
        bins,
        mode: Some(format!("optimized {}", mode.name())),
        summary: None,
        optimality: None,
    };
    if let Some(d) = dwell.as_mut() {
        d.is_answer = mode == Mode::Resolution && !smooth && !shortened;
    }
    Ok(Solution {
        profile,
        power: last,
        dwell,
    })
}
