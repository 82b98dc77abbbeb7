//! The block-coordinate LP/MILP (see the module docs of [`super`]).
//!
//! Variables are normalised to order one (`x = p/P̄`, `τ = t·N/T`) because
//! HiGHS's feasibility tolerances are absolute (1e-7). Continuous solutions
//! are clamped and rescaled to meet bounds, budget and frame exactly, which
//! is why continuous bounds carry a `settings::margin`; level (MILP) solutions are
//! exact by construction.

// Loops over bins index several parallel per-bin arrays (θ, weights, caps,
// variables); indices read like the formulation.
#![allow(clippy::needless_range_loop)]

use super::certificate::{Certified, LinearProgram, Step};
use super::level_choice::{Level, Ring};
use super::program::{Heuristic, Program, SolveOptions, Warm};
use super::utility::{sqrt_segments_n, SqrtSegments};
use good_lp::{Expression, IntoAffineExpression, Variable};
use std::f64::consts::TAU;

use super::error::{CertificateError, Infeasible, SpinLimit};
use super::settings::S;
use super::{OptError, Problem};
use crate::eye_safety::bound::{Laser, Rule, Seg, RATIO_MARGIN};
use crate::eye_safety::cuts::{cuts_for, Cut};
use crate::eye_safety::head::bound::head_figures_on;
use crate::eye_safety::{exposure, EyeSafetyParams};
use crate::model::angle::{next_index, wrap_deg, Arc, Binning};
use crate::model::lidar::PowerAccounting;
use crate::model::Mode;
use crate::profile::{Bin, Profile, Region, PROFILE_FORMAT};

/// Right-hand side of a cut row normalised to its limit: a power vector
/// that meets it with equality is at `1 − headroom` of the bound's figure
/// for that cut once the bound's rounding margin is applied.
fn cut_rhs() -> f64 {
    level_rhs() * (1.0 - S.cut_margin)
}

/// As [`cut_rhs`] for a cut on one bin when the power takes hardware
/// levels: the levels are exact (no solver tolerance enters), so only the
/// head-room and the bound's rounding margin.
fn level_rhs() -> f64 {
    (1.0 - S.eye_safety_headroom) / (1.0 + RATIO_MARGIN)
}

/// What `check` accepts of a limit `v ≥ 0`: its relative `REL_TOL`, and a
/// relative 1e-12 more for the rounding of the checker's floating-point
/// sums. The power step's rows and boxes sit inside the limits (margins);
/// its certificate's bound is taken on the program with these sides
/// (`Program::relax_row`), so it bounds every profile `check` certifies,
/// not only the tightened program's points.
fn accepted(v: f64) -> f64 {
    v * (1.0 + crate::checker::REL_TOL) * (1.0 + 1e-12)
}

/// The bound's figure at or below which an answer counts as eye-safe:
/// continuous powers keep `eye_safety_headroom` below the Class 1 limit;
/// hardware levels are exact, so a level the checker accepts (the bound's
/// figure at most 1) stays available, however close to the limit it is.
fn eye_accept(problem: &Problem) -> f64 {
    if problem.levels.power_w.is_empty() {
        1.0 - S.eye_safety_headroom
    } else {
        1.0
    }
}

/// Whether the dwell `next` is within `settings::slp_settled` of `t` in every bin.
fn settled(next: &[f64], t: &[f64]) -> bool {
    next.iter()
        .zip(t)
        .all(|(a, b)| (a - b).abs() <= S.slp_settled * b.abs())
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
            problem.focus.acuity.deficit(ecc) + prior + eps + S.tie_break * (ecc + 180.0) / 360.0,
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
    warm_head(params, &laser);
    Ok(Some(Eye {
        params: params.clone(),
        laser,
        pulse_rate_hz: problem.lidar.pulse_rate_hz,
    }))
}

/// Computes the head's figures on every surface its verdict covers, one
/// surface per thread, before the first verdict asks for them one after
/// another: what depends on the head alone is kept
/// (`head::bound::HeadOverlaps`, shared by all threads), so the verdicts
/// find it computed. An error is left for the verdict to report.
fn warm_head(params: &EyeSafetyParams, laser: &Laser) {
    use rayon::prelude::*;
    let Some(head) = &params.head else {
        return;
    };
    if let Ok(surfaces) = exposure::surfaces(head) {
        surfaces.par_iter().for_each(|(h, surface)| {
            // The figures that do not depend on the spin (no widening).
            let _ = head_figures_on(h, *surface, params, laser, 0.0);
        });
    }
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
            .map_err(|e| Infeasible::EyeSafety(e.to_string()).into())
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
        return Err(Infeasible::FrameUnreachable {
            limit: SpinLimit::Max,
            spin_rad_s: l.spin_rad_s_max,
            mean_spin_rad_s: w_mean,
            frame_rate_hz: lid.frame_rate_hz,
        }
        .into());
    }
    if l.spin_rad_s_min > w_mean * (1.0 + 1e-12) {
        return Err(Infeasible::FrameUnreachable {
            limit: SpinLimit::Min,
            spin_rad_s: l.spin_rad_s_min,
            mean_spin_rad_s: w_mean,
            frame_rate_hz: lid.frame_rate_hz,
        }
        .into());
    }
    if l.power_w_min > lid.average_power_w * (1.0 + 1e-12) {
        return Err(Infeasible::FloorOverBudget {
            power_w_min: l.power_w_min,
            average_power_w: lid.average_power_w,
        }
        .into());
    }
    // Every bin at a level at or above the lowest (either accounting:
    // the mean over angle or over time is at least the lowest level).
    let lowest_level = problem
        .levels
        .power_w
        .iter()
        .copied()
        .filter(|&v| v >= l.power_w_min && v <= l.power_w_max)
        .fold(f64::INFINITY, f64::min);
    if problem.objective.mode.controls_range()
        && lowest_level.is_finite()
        && lowest_level > lid.average_power_w * (1.0 + crate::checker::REL_TOL)
    {
        return Err(Infeasible::LevelsOverBudget {
            level_w: lowest_level,
            average_power_w: lid.average_power_w,
        }
        .into());
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
                return Err(Infeasible::EyeFloorOverLimit {
                    power_w_min: l.power_w_min,
                    ratio,
                    at_deg: at,
                    wavelength_nm: e.params.wavelength_nm,
                }
                .into());
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
    levels_valid(problem)?;
    setpoints_reach_frame(problem)
}

/// The hardware levels and spin set-points are finite, ≥ 0 (powers) and
/// > 0 (spins).
pub(super) fn levels_valid(problem: &Problem) -> Result<(), OptError> {
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

/// With spin set-points on equal bins, some choice of them must make one
/// turn take the frame period (see [`super::setpoints`]); otherwise the
/// request is [`SpinLimit::SetPoints`] unreachable.
fn setpoints_reach_frame(problem: &Problem) -> Result<(), OptError> {
    use super::setpoints::{reach, Reach};
    let l = &problem.lidar.limits;
    let allowed: Vec<f64> = (problem.levels.spin_rad_s.iter().copied())
        .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max)
        .collect();
    if allowed.is_empty() || !problem.objective.mode.controls_resolution() {
        return Ok(());
    }
    let g = grid(problem, 0.0)?;
    if !equal_bins(&g) {
        return Ok(());
    }
    let w_mean = problem.lidar.mean_spin_rad_s();
    let r: Vec<f64> = allowed.iter().map(|&w| w_mean / w).collect();
    let Reach::Misses { below, above } = reach(&r, g.n, S.setpoint_search_steps) else {
        return Ok(());
    };
    let period = 1.0 / problem.lidar.frame_rate_hz;
    let per = |v: f64| v * period / g.n as f64;
    Err(Infeasible::FrameUnreachable {
        limit: SpinLimit::SetPoints {
            bins: g.n,
            count: allowed.len(),
            below_s: below.map(per),
            above_s: above.map(per),
        },
        spin_rad_s: allowed.iter().copied().fold(0.0, f64::max),
        mean_spin_rad_s: w_mean,
        frame_rate_hz: problem.lidar.frame_rate_hz,
    }
    .into())
}

/// Whether the grid's bins are equal: their widths within a relative
/// `10⁻¹²` of the first's (`N` equal bins' widths, `360·(i+1)/N − 360·i/N`
/// in doubles, differ by ulps unless `N` divides 360 evenly in binary).
/// A frame sum over such bins moves by less than `10⁻¹²` relative, far
/// inside the `0.2·10⁻⁹` between [`super::setpoints::reach`]'s tolerance
/// and the checker's.
fn equal_bins(g: &Grid) -> bool {
    let th0 = g.theta.first().copied().unwrap_or(0.0);
    g.theta
        .iter()
        .all(|&th| (th - th0).abs() <= 1e-12 * th0.abs())
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
///
/// The loop is a skeleton of named steps: [`power_program`] builds the
/// program from the pool, HiGHS solves it, [`powers`] repairs the answer,
/// and [`power_checkpoint`] decides what comes next.
fn power_step(
    problem: &Problem,
    g: &Grid,
    eye: Option<&Eye>,
    spins: &[(f64, f64)],
    pool: &mut Vec<Cut>,
) -> Result<(Vec<f64>, PowerLp), OptError> {
    let t = &dwell_of(g, spins)[..];
    // Where no valid cut separates (see `power_checkpoint`), the limits of
    // one class of cuts — Rule 1's (0) or the windows' (1) — are divided
    // by a factor.
    let mut factor = [1.0f64; 2];
    let mut round = 0;
    // A round that only added cuts re-solves the last round's HiGHS model
    // from its optimal basis.
    let mut warm = Warm::default();
    loop {
        let program = power_program(problem, g, eye, t, pool, &factor)?;
        let opts = SolveOptions {
            heuristic: program.ring.as_ref().map(|r| r as &dyn Heuristic),
            ..SolveOptions::default()
        };
        // Without eye safety there is one round: nothing to keep.
        let solved = match eye {
            Some(_) => program.lp.solve_warm("power", &opts, &mut warm),
            None => program.lp.solve_with("power", &opts),
        }
        .map_err(|err| match (err, eye) {
            (OptError::Infeasible(_), Some(_)) => {
                Infeasible::CutsLeaveNoPower { cuts: pool.len() }.into()
            }
            (other, _) => other,
        })?;
        let p = powers(problem, g, t, &program, &solved.x);
        let checkpoint = match eye {
            None => Checkpoint::Certified,
            Some(e) => {
                let at = (round, eye_accept(problem));
                power_checkpoint(e, g, spins, &p, pool, &factor, at)?
            }
        };
        match checkpoint {
            Checkpoint::Certified => {
                let top = factor[0].max(factor[1]);
                let budget_price = program
                    .lp
                    .names()
                    .iter()
                    .position(|n| *n == "budget")
                    .and_then(|r| solved.y.get(r))
                    .map_or(0.0, |y| y.abs());
                return Ok((
                    p,
                    PowerLp {
                        lp: program.lp.view(),
                        outer: program.lp.outer_view(),
                        bins: program.bins,
                        one: program.one,
                        tightening: (top > 1.0).then_some(top),
                        p_mean: problem.lidar.average_power_w,
                        floor_w: problem.lidar.limits.power_w_min,
                        y: solved.y,
                        solver_dual_bound: solved.solver_dual_bound,
                        budget_price,
                    },
                ));
            }
            Checkpoint::AddCuts(fresh) => pool.extend(fresh),
            Checkpoint::Tighten {
                class,
                factor: f,
                cuts,
            } => {
                factor[class] = f;
                pool.extend(cuts);
            }
            Checkpoint::Fail(why) => return Err(why),
        }
        round += 1;
    }
}

/// A linear form over a program's columns (a good_lp expression).
type LinearForm = Expression;

/// What one round of the power step's cutting-plane loop decides (in the
/// manner of Clarabel's `solve()`: each named step returns where to go).
enum Checkpoint {
    /// The core's bound certifies the answer: done.
    Certified,
    /// Concrete exposures the answer breaks: add them and solve again.
    AddCuts(Vec<Cut>),
    /// No valid cut separates (the bound's conservatism in the rule that
    /// binds): divide the limits of cut class `class` by `factor`, add
    /// `cuts`, solve again.
    Tighten {
        class: usize,
        factor: f64,
        cuts: Vec<Cut>,
    },
    /// No way on: why.
    Fail(OptError),
}

/// Rule 1's cuts are class 0, the windows' class 1.
fn cut_class(c: &Cut) -> usize {
    usize::from(c.rule != Rule::SinglePulse)
}

/// Asks the core's bound about the powers `p` of round `round` and decides
/// the next step of the cutting-plane loop.
fn power_checkpoint(
    e: &Eye,
    g: &Grid,
    spins: &[(f64, f64)],
    p: &[f64],
    pool: &[Cut],
    factor: &[f64; 2],
    (round, accept): (usize, f64),
) -> Result<Checkpoint, OptError> {
    let s = segs(g, spins, p);
    let report = e.report(&s)?;
    let (ratio, witness) = (report.worst_ratio, report.worst_azimuth_deg);
    if ratio <= accept {
        return Ok(Checkpoint::Certified);
    }
    let round = round + 1;
    // Every bin edge ± h first (rotation-equivariant: a rotated problem gets
    // the rotated cuts); the bound's witness only when those hold. A
    // tightened class's program divides its cuts' limits by its factor, so
    // a cut of that class breaks the answer there from `cut_rhs / factor`
    // on: those come too (before any further tightening), with every cut at
    // or above `cut_rhs` and every Rule 1 cut the core gives.
    let scale = factor[0].max(factor[1]);
    let new_cuts = |extra: &[f64]| -> Vec<Cut> {
        e.cuts(&s, extra, cut_rhs() / scale)
            .into_iter()
            .filter(|c| {
                let r = c.ratio(p, e.pulse_rate_hz);
                (r >= cut_rhs()
                    || r * factor[cut_class(c)] >= cut_rhs()
                    || c.rule == Rule::SinglePulse)
                    && !pool.contains(c)
            })
            .collect()
    };
    let mut fresh = new_cuts(&[]);
    if fresh.is_empty() {
        fresh = new_cuts(&[witness]);
    }
    // No cut separates the answer (or the rounds ran out) and the checker
    // accepts it (the bound's figure at most 1): a floor within the
    // head-room of the limit holds bins there whatever the cuts say, and
    // the head-room is a preference, not a limit.
    if ratio <= 1.0 && (fresh.is_empty() || round > S.cut_rounds) {
        return Ok(Checkpoint::Certified);
    }
    if round > S.cut_rounds {
        return Ok(Checkpoint::Fail(OptError::Solver(format!(
            "eye-safety cuts: after {round} rounds the bound still gives {ratio:.6} at {witness:.3}° ({} cuts, limits divided by {factor:?})",
            pool.len(),
        ))));
    }
    if !fresh.is_empty() {
        if round <= S.cut_rounds / 2 {
            strongest_windows(&mut fresh, p, e.pulse_rate_hz);
        }
        return Ok(Checkpoint::AddCuts(fresh));
    }
    // The bound exceeds every valid cut here: divide the limits of that
    // rule's class of cuts by the bound's excess over the strongest of
    // them, so the next answer meets them where the bound would.
    let k = usize::from(report.binding_rule != Rule::SinglePulse);
    let f_lo = factor[k] * ratio / (1.0 - S.eye_safety_headroom);
    let (near, top) = near_cuts(e, &s, p, (witness, ratio), k, f_lo);
    if top <= 0.0 {
        return Ok(Checkpoint::Fail(OptError::Solver(format!(
            "eye-safety cuts: the bound gives {ratio:.6} at {witness:.3}° ({:?}) and no cut of that rule has any exposure there",
            report.binding_rule
        ))));
    }
    let f = f_lo.max(ratio / top) * (1.0 + 1e-9);
    let cuts = near
        .into_iter()
        .filter(|c| c.ratio(p, e.pulse_rate_hz) * f >= cut_rhs() && !pool.contains(c))
        .collect();
    Ok(Checkpoint::Tighten {
        class: k,
        factor: f,
        cuts,
    })
}

/// Keeps Rule 1's cuts (column bounds) and the [`S`]`.cuts_per_round`
/// window cuts the answer `p` breaks most (ratio descending, ties in the
/// core's order): the next program grows by a few hundred rows, which
/// HiGHS adds to the last round's model and re-solves from its basis
/// ([`Program::solve_warm`]); the cuts left out come back in a later round
/// if the next answer still breaks them. The first half of the loop's
/// rounds only: after that every cut found is added, so the cap never
/// makes the loop run out of rounds.
fn strongest_windows(fresh: &mut Vec<Cut>, p: &[f64], pulse_rate_hz: f64) {
    let (single, mut windows): (Vec<Cut>, Vec<Cut>) = std::mem::take(fresh)
        .into_iter()
        .partition(|c| c.pulses.len() == 1);
    let mut keyed: Vec<(f64, Cut)> = windows
        .drain(..)
        .map(|c| (c.ratio(p, pulse_rate_hz), c))
        .collect();
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0));
    keyed.truncate(S.cuts_per_round);
    *fresh = single;
    fresh.extend(keyed.into_iter().map(|(_, c)| c));
}

/// The cuts of class `k` at the aperture `witness` and every bin edge, and
/// the largest ratio among them, for [`power_checkpoint`]'s tightening by
/// `f = max(f_lo, ratio / top)·(1 + 1e-9)`, which keeps only the cuts with
/// `ratio · f ≥ cut_rhs`. Asking the core for every cut (threshold 0)
/// costs tens of milliseconds on a real head, so only those above a
/// threshold `t`, less a relative [`NEAR_SLACK`] (far above the rounding
/// of the core's threshold test, so every cut at or above `t` comes): first
/// `t = NEAR_FIRST · cut_rhs / f_lo`, then half of it, and so on down to
/// [`NEAR_FLOOR`], until the strongest cut found is at or above `t`: it is
/// the strongest of all, which fixes `f`, and then `t = cut_rhs / f`. The
/// answer holds every cut the tightening keeps, in the same order (a
/// sub-list of the same sort), so the tightening is the one every cut would
/// give (the caller keeps only the cuts at or above `cut_rhs / f`, so a
/// longer list from a lower threshold keeps the same ones in the same
/// order). If no cut reaches the floor: every cut. Each call of the core
/// enumerates the exposures at every bin edge, and its cost grows as the
/// threshold falls: halving (not quartering) keeps the last call's
/// threshold within 2× of the strongest cut.
fn near_cuts(
    e: &Eye,
    s: &[Seg],
    p: &[f64],
    at: (f64, f64),
    k: usize,
    f_lo: f64,
) -> (Vec<Cut>, f64) {
    let (witness, ratio) = at;
    let of_class = |t: f64| -> (Vec<Cut>, f64) {
        let near: Vec<Cut> = e
            .cuts(s, &[witness], t * (1.0 - NEAR_SLACK))
            .into_iter()
            .filter(|c| cut_class(c) == k)
            .collect();
        let top = near
            .iter()
            .map(|c| c.ratio(p, e.pulse_rate_hz))
            .fold(0.0, f64::max);
        (near, top)
    };
    let mut t_a = cut_rhs() / f_lo * NEAR_FIRST;
    while t_a.is_finite() && t_a >= NEAR_FLOOR {
        let (near, top) = of_class(t_a);
        if top >= t_a {
            let t_b = cut_rhs() / (f_lo.max(ratio / top) * (1.0 + 1e-9));
            return if t_b >= t_a {
                (near, top)
            } else {
                of_class(t_b)
            };
        }
        t_a *= 0.5;
    }
    of_class(0.0)
}

/// The first threshold [`near_cuts`] tries, relative to `cut_rhs / f_lo`:
/// a little below it, so that where the strongest cut fixes `f` at `f_lo`
/// (its threshold `cut_rhs / f` then a hair below `cut_rhs / f_lo`) one
/// call of the core holds every cut the tightening keeps.
const NEAR_FIRST: f64 = 0.99;

/// The lowest first threshold [`near_cuts`] tries (each try half the
/// last) before it asks for every cut.
const NEAR_FLOOR: f64 = 1e-3;

/// The relative margin by which [`near_cuts`] asks for more cuts than it
/// needs.
const NEAR_SLACK: f64 = 1e-6;

/// The power step's program for the cuts in `pool` (their limits divided by
/// `factor`), and how each bin's power reads from its columns.
struct PowerProgram {
    lp: Program,
    /// `x_i = p_i / P̄` as a linear form (a continuous column or Σ levels·z).
    x: Vec<LinearForm>,
    bins: Vec<PowerBin>,
    /// The column fixed at 1 that carries the utilities' constants.
    one: Option<usize>,
    /// With hardware levels (and no eye-safety row over several bins), the
    /// level choice as a ring, for the primal heuristic.
    ring: Option<LevelRing>,
}

/// The power step's level choice as a [`Ring`] over the program's columns.
struct LevelRing {
    ring: Ring,
    /// Per bin, the column of each of its levels (the ring's order).
    cols: Vec<Vec<usize>>,
    /// The budget row.
    budget_row: usize,
    columns: usize,
}

impl Heuristic for LevelRing {
    fn start(&self, relaxed: &[f64], duals: &[f64]) -> Option<Vec<f64>> {
        if !relaxed.is_empty() && relaxed.len() != self.columns || duals.len() <= self.budget_row {
            return None;
        }
        // The relaxation's point rounded down: per bin, of its levels with
        // the largest binary, the first (the lowest index).
        let rounded = (!relaxed.is_empty()).then(|| {
            self.cols
                .iter()
                .map(|cs| {
                    let mut best = 0;
                    for (k, &c) in cs.iter().enumerate() {
                        if relaxed[c] > relaxed[cs[best]] {
                            best = k;
                        }
                    }
                    best
                })
                .collect()
        });
        let choice = self.ring.heuristic(duals[self.budget_row], rounded)?;
        let mut x = vec![0.0; self.columns];
        for (cs, k) in self.cols.iter().zip(choice) {
            x[cs[k]] = 1.0;
        }
        Some(x)
    }

    /// Without a slew limit, the relaxation's multipliers in closed form
    /// ([`Ring::relaxation`]): bin `i`'s one-hot row is row `i`, the
    /// budget row follows them, and the program has no other rows.
    fn duals(&self, rows: usize) -> Option<Vec<f64>> {
        let n = self.cols.len();
        if self.budget_row != n || rows != n + 1 {
            return None;
        }
        let (lambda, mut y) = self.ring.relaxation()?;
        y.push(lambda);
        Some(y)
    }
}

/// Per bin, the hardware levels (W) the power step offers: within the
/// power limits and the bin's eye-safety cap, less those no level choice
/// within the budget and the slew limit can use ([`Ring::probe`]); `None`
/// without levels, or where a bin has none (the program says why).
fn offered_levels(problem: &Problem, g: &Grid, t: &[f64], caps: &[f64]) -> Option<Vec<Vec<f64>>> {
    let l = &problem.lidar.limits;
    if problem.levels.power_w.is_empty() {
        return None;
    }
    let allowed: Vec<Vec<f64>> = caps
        .iter()
        .map(|&cap| {
            let hi = l.power_w_max.min(cap.max(l.power_w_min));
            (problem.levels.power_w.iter().copied())
                .filter(|&lv| lv >= l.power_w_min && lv <= hi)
                .collect()
        })
        .collect();
    if allowed.iter().any(Vec::is_empty) {
        return None;
    }
    let p_mean = problem.lidar.average_power_w;
    let (w, budget) = budget_weights(problem, g, t);
    let ring = Ring {
        bins: allowed
            .iter()
            .zip(&w)
            .map(|(lvs, &wi)| {
                lvs.iter()
                    .map(|&lv| Level {
                        x: lv / p_mean,
                        spend: wi * (lv / p_mean),
                        value: 0.0,
                    })
                    .collect()
            })
            .collect(),
        budget,
        reach: slew_reach(problem, g),
    };
    let keep = ring.probe();
    Some(
        allowed
            .into_iter()
            .zip(keep)
            .map(|(lvs, k)| {
                lvs.into_iter()
                    .zip(k)
                    .filter(|x| x.1)
                    .map(|x| x.0)
                    .collect()
            })
            .collect(),
    )
}

/// The budget row's weight per bin (of `x = p/P̄`) and its side, for
/// hardware levels (`budget`'s row, with `level_budget_slack`).
fn budget_weights(problem: &Problem, g: &Grid, t: &[f64]) -> (Vec<f64>, f64) {
    let slack = 1.0 + S.level_budget_slack;
    match problem.lidar.power_accounting {
        PowerAccounting::Angle => (g.theta.clone(), TAU * slack),
        PowerAccounting::Time => {
            let period: f64 = t.iter().sum();
            (t.iter().map(|ti| ti / period).collect(), slack)
        }
    }
}

/// The `slew` rows' side relative to the limit: continuous powers keep
/// the continuous margin inside it (they are clamped and lowered to meet
/// it); hardware levels are exact, so their rows sit at the limit plus
/// `level_budget_slack` (inside the checker's relative 10⁻⁹), as the
/// budget row does: a pair of levels one slew step apart (`0.0011 −
/// 0.0009` is `2.0000000000000006e-4` in doubles) stays compatible, as
/// `check` accepts it. With the margin, such a pair was incompatible and
/// a whole level was lost from every bin.
fn slew_side(problem: &Problem) -> f64 {
    if problem.levels.power_w.is_empty() {
        1.0 - S.margin
    } else {
        1.0 + S.level_budget_slack
    }
}

/// Per bin `i`, the largest `|x_next − x_i|` the `slew` rows allow, with a
/// relative 10⁻⁹ of head-room; `None` without a slew limit.
fn slew_reach(problem: &Problem, g: &Grid) -> Option<Vec<f64>> {
    let s = problem.lidar.limits.power_slew_w_per_deg_max?;
    let p_mean = problem.lidar.average_power_w;
    Some(
        (0..g.n)
            .map(|i| {
                let j = next_index(i, g.n);
                s * 0.5 * (g.width_deg[i] + g.width_deg[j]) / p_mean
                    * slew_side(problem)
                    * (1.0 + 1e-9)
            })
            .collect(),
    )
}

/// Builds the power step's program: per bin its columns and utility (and
/// with levels its one-hot row), then the constraint families in a fixed
/// order — `budget`, `slew`, `eye_cuts` — so HiGHS sees the same rows in
/// the same order every time.
fn power_program(
    problem: &Problem,
    g: &Grid,
    eye: Option<&Eye>,
    t: &[f64],
    pool: &[Cut],
    factor: &[f64; 2],
) -> Result<PowerProgram, OptError> {
    let (caps, bare) = eye_caps(problem, g, eye, pool, factor);
    let offered = offered_levels(problem, g, t, &caps);
    let mut shapes = bin_shapes(problem, g, t, &caps).into_iter();
    let mut lp = Program::default();
    let mut x = Vec::with_capacity(g.n);
    let mut bins = Vec::with_capacity(g.n);
    let mut utility_constant = 0.0;
    for i in 0..g.n {
        let offer = offered.as_ref().map(|o| &o[i][..]);
        let shape = shapes.next().flatten();
        let (form, bin, constant) = power_bin(
            &mut lp,
            problem,
            g,
            (i, t[i]),
            (caps[i], bare[i]),
            (offer, shape),
        )?;
        x.push(form);
        bins.push(bin);
        utility_constant += constant;
    }
    // The utilities' constants Σ c·√lo as one column fixed at 1.
    let one = (utility_constant != 0.0).then(|| {
        let v = lp.column(1.0, 1.0, utility_constant, false);
        lp.col(v)
    });
    let budget_row = lp.rows();
    budget(&mut lp, problem, g, t, &x);
    if let Some(s) = problem.lidar.limits.power_slew_w_per_deg_max {
        let (p_mean, side) = (problem.lidar.average_power_w, slew_side(problem));
        slew(&mut lp, g, &x, s, (p_mean, side));
        if !problem.levels.power_w.is_empty() {
            slew_levels(&mut lp, g, &x, s, (p_mean, side));
        }
    }
    let rows_before_cuts = lp.rows();
    if let Some(e) = eye {
        eye_cuts(&mut lp, problem, e, pool, factor, &x)?;
    }
    let ring = (lp.rows() == rows_before_cuts && one.is_none())
        .then(|| level_ring(problem, g, t, &lp, &bins, budget_row))
        .flatten();
    Ok(PowerProgram {
        lp,
        x,
        bins,
        one,
        ring,
    })
}

/// The level choice of a program whose columns are all level binaries.
fn level_ring(
    problem: &Problem,
    g: &Grid,
    t: &[f64],
    lp: &Program,
    bins: &[PowerBin],
    budget_row: usize,
) -> Option<LevelRing> {
    if !bins.iter().all(|b| matches!(b, PowerBin::Levels(_))) {
        return None;
    }
    let p_mean = problem.lidar.average_power_w;
    let (w, budget) = budget_weights(problem, g, t);
    let mut cols = Vec::with_capacity(bins.len());
    let mut ring_bins = Vec::with_capacity(bins.len());
    for (b, &wi) in bins.iter().zip(&w) {
        let PowerBin::Levels(zs) = b else {
            return None;
        };
        cols.push(zs.iter().map(|z| z.1).collect());
        ring_bins.push(
            zs.iter()
                .map(|&(lv, c)| Level {
                    x: lv / p_mean,
                    spend: wi * (lv / p_mean),
                    value: lp.cost(c),
                })
                .collect(),
        );
    }
    Some(LevelRing {
        ring: Ring {
            bins: ring_bins,
            budget,
            reach: slew_reach(problem, g),
        },
        columns: cols.iter().map(Vec::len).sum(),
        cols,
        budget_row,
    })
}

/// Per bin, the eye-safety caps of the single-bin cuts in `pool` as column
/// bounds, W: with the cut margins (`caps`), and bare (a floor between the
/// two is kept, the bound decides; one above the bare limit is infeasible).
fn eye_caps(
    problem: &Problem,
    g: &Grid,
    eye: Option<&Eye>,
    pool: &[Cut],
    factor: &[f64; 2],
) -> (Vec<f64>, Vec<f64>) {
    // A cut on one bin's power alone is that bin's column bound (the
    // utility's chords then span the reachable powers only).
    // Levels: a level the checker accepts (the bound's figure at most 1,
    // its rounding margin applied) stays; the checkpoint decides.
    let rhs = if problem.levels.power_w.is_empty() {
        cut_rhs()
    } else {
        1.0 / (1.0 + RATIO_MARGIN)
    };
    let mut caps = vec![f64::INFINITY; g.n];
    let mut bare = vec![f64::INFINITY; g.n];
    if let Some(e) = eye {
        for c in pool {
            if let [(b, n)] = c.pulses[..] {
                caps[b] = caps[b].min(rhs * c.limit_j / factor[cut_class(c)] * e.pulse_rate_hz / n);
                bare[b] = bare[b].min(c.limit_j * e.pulse_rate_hz / n);
            }
        }
    }
    (caps, bare)
}

/// Bin `i`'s columns, boxed by the power limits and its eye-safety cap
/// (`levels`: one binary per allowed level and their one-hot row; else a
/// continuous column and its utility's segments). Returns `x_i` as a linear
/// form, how the bin reads back, and its utility's constant.
fn power_bin(
    lp: &mut Program,
    problem: &Problem,
    g: &Grid,
    (i, dwell_s): (usize, f64),
    (cap_w, bare_w): (f64, f64),
    (offered, shape): (Option<&[f64]>, Option<SqrtSegments>),
) -> Result<(LinearForm, PowerBin, f64), OptError> {
    let l = &problem.lidar.limits;
    if bare_w < l.power_w_min {
        return Err(Infeasible::EyeCapBelowFloor {
            cap_w: bare_w,
            wavelength_nm: l.eye_safety.as_ref().map_or(0.0, |p| p.wavelength_nm),
            bin: i,
            power_w_min: l.power_w_min,
        }
        .into());
    }
    let c = problem.objective.range_weight * g.theta[i] * g.weight[i];
    if !problem.levels.power_w.is_empty() {
        let hi = l.power_w_max.min(cap_w.max(l.power_w_min));
        let value = |x: f64| super::detection::level_value(problem, g.theta[i], dwell_s, x);
        let (form, bin) = levels(lp, problem, (i, hi), offered, c, value)?;
        return Ok((form, bin, 0.0));
    }
    let (lo_x, hi_x) = bin_box(problem, cap_w);
    let xi = lp.column(lo_x, hi_x, 0.0, false);
    // The utility as boxed segment columns (see `utility`).
    let shape = shape.unwrap_or_else(|| {
        super::detection::range_segments(problem, g.theta[i], dwell_s, lo_x, hi_x)
    });
    let deltas = shape.add_to(lp, xi, 1.0, lo_x, c);
    relax_bin(lp, problem, (xi, &deltas, &shape), (lo_x, hi_x), bare_w);
    let constant = c * shape.base;
    let bin = PowerBin::Continuous {
        x: lp.col(xi),
        lo: lo_x,
        deltas: deltas.into_iter().map(|d| lp.col(d)).collect(),
        shape,
    };
    Ok((xi.into(), bin, constant))
}

/// A continuous bin's power box `[lo, hi]` (ratios to `P̄`): the floor,
/// and `power_w_max` or the bin's eye-safety cap less the margin.
fn bin_box(problem: &Problem, cap_w: f64) -> (f64, f64) {
    let l = &problem.lidar.limits;
    let p_mean = problem.lidar.average_power_w;
    let hi = l.power_w_max.min(cap_w.max(l.power_w_min));
    let lo_x = l.power_w_min / p_mean;
    (lo_x, (hi / p_mean * (1.0 - S.margin)).max(lo_x))
}

/// The detection objective's segments of every continuous bin, built in
/// parallel (contiguous runs of bins per thread, so each run's neighbour
/// guesses stay as in one pass; a segment is the same bits whatever the
/// guess, `values_near_another_spacing_are_the_values`), or `None` per bin
/// where [`power_bin`] builds its own: `√` segments (cheap), hardware
/// levels, a bin whose floor is above its cap (refused there).
fn bin_shapes(problem: &Problem, g: &Grid, t: &[f64], caps: &[f64]) -> Vec<Option<SqrtSegments>> {
    use rayon::prelude::*;
    if problem.objective.kind != super::detection::ObjectiveKind::Detection
        || !problem.levels.power_w.is_empty()
    {
        return vec![None; g.n];
    }
    let runs = rayon::current_num_threads().max(1);
    let per_run = g.n.div_ceil(runs).max(1);
    let idx: Vec<usize> = (0..g.n).collect();
    idx.par_chunks(per_run)
        .flat_map_iter(|run| {
            run.iter()
                .map(|&i| {
                    let (lo_x, hi_x) = bin_box(problem, caps[i]);
                    Some(super::detection::range_segments(
                        problem, g.theta[i], t[i], lo_x, hi_x,
                    ))
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The user's box of a continuous bin (as `check` accepts the floor,
/// `power_w_max` and the bin's bare single-bin eye-safety cap) recorded on
/// the program (`Program::relax_col`): `x` between them, and the utility's
/// first and last segments extended by the difference (a chord of a concave
/// utility extended past its ends lies above it, so the extended program
/// still bounds the utility there).
fn relax_bin(
    lp: &mut Program,
    problem: &Problem,
    (xi, deltas, shape): (Variable, &[Variable], &SqrtSegments),
    (lo_x, hi_x): (f64, f64),
    bare_w: f64,
) {
    let l = &problem.lidar.limits;
    let p_mean = problem.lidar.average_power_w;
    let lo_o = (l.power_w_min / p_mean * (1.0 - crate::checker::REL_TOL) * (1.0 - 1e-12)).min(lo_x);
    let hi_o = (accepted(l.power_w_max.min(bare_w)) / p_mean).max(hi_x);
    let j = lp.col(xi);
    lp.relax_col(j, lo_o, hi_o);
    if let (Some(first), Some(last)) = (deltas.first(), deltas.last()) {
        let (first, last) = (lp.col(*first), lp.col(last.to_owned()));
        let below = (lo_x - lo_o) * (1.0 + 1e-12);
        let above = (hi_o - hi_x) * (1.0 + 1e-12);
        let n = shape.segments.len();
        let len = |k: usize| shape.segments[k].1;
        if first == last {
            lp.relax_col(first, -below, len(0) + above);
        } else {
            lp.relax_col(first, -below, len(0));
            lp.relax_col(last, 0.0, len(n - 1) + above);
        }
    }
}

/// `levels`: one binary column per hardware level within
/// `[power_w_min, hi_w]` (cost `c·√(level/P̄)`) and the one-hot row `Σ z = 1`.
fn levels(
    lp: &mut Program,
    problem: &Problem,
    (i, hi_w): (usize, f64),
    offered: Option<&[f64]>,
    c: f64,
    value: impl Fn(f64) -> f64,
) -> Result<(LinearForm, PowerBin), OptError> {
    let floor = problem.lidar.limits.power_w_min;
    let p_mean = problem.lidar.average_power_w;
    let allowed: Vec<f64> = offered.map_or_else(
        || {
            (problem.levels.power_w.iter().copied())
                .filter(|&lv| lv >= floor && lv <= hi_w)
                .collect()
        },
        <[f64]>::to_vec,
    );
    if allowed.is_empty() {
        return Err(Infeasible::NoLevelFits {
            power_w_min: floor,
            hi_w,
            bin: i,
        }
        .into());
    }
    let zs: Vec<(f64, Variable)> = allowed
        .iter()
        .map(|&lv| (lv, lp.column(0.0, 1.0, c * value(lv / p_mean), true)))
        .collect();
    lp.equal("levels", zs.iter().map(|&(_, z)| z).sum(), 1.0);
    let mut form = Expression::with_capacity(zs.len());
    for &(lv, z) in &zs {
        form.add_mul(lv / p_mean, z);
    }
    let cols = zs.iter().map(|&(lv, z)| (lv, lp.col(z))).collect();
    Ok((form, PowerBin::Levels(cols)))
}

/// `budget`: `Σ θ_i x_i ≤ 2π` (angle accounting) or `Σ (t_i/T) x_i ≤ 1`
/// (time), with the continuous margin, or for levels the budget exactly
/// plus `level_budget_slack` (far inside the checker's REL_TOL) so that a
/// level choice that meets it in floating point (the closed form's does, to
/// the last bit) also meets it in the exact arithmetic of the certificate.
fn budget(lp: &mut Program, problem: &Problem, g: &Grid, t: &[f64], x: &[LinearForm]) {
    let budget_margin = if problem.levels.power_w.is_empty() {
        1.0 - S.margin
    } else {
        1.0 + S.level_budget_slack
    };
    let period: f64 = t.iter().sum();
    let mut spend = Expression::default();
    let budget = match problem.lidar.power_accounting {
        PowerAccounting::Angle => {
            for i in 0..g.n {
                spend.add_mul(g.theta[i], &x[i]);
            }
            TAU * budget_margin
        }
        PowerAccounting::Time => {
            for i in 0..g.n {
                spend.add_mul(t[i] / period, &x[i]);
            }
            budget_margin
        }
    };
    // A floor that spends the whole budget (power_w_min = P̄) keeps its own
    // spend: the margin must not make the all-floor answer infeasible. The
    // spend is a float sum of up to 1440 products, a few ulps from the exact
    // one the certificate computes: raised by a relative 1e-12 (far above
    // 1440·ε, far inside the checker's 1e-9) so that the floor point meets
    // the row exactly.
    let floor: Vec<f64> = (0..lp.len()).map(|j| lp.bounds(j).0).collect();
    let floor_spend = lp.eval(&spend, &floor);
    let side = if floor_spend > budget {
        floor_spend * (1.0 + 1e-12)
    } else {
        budget
    };
    let row = lp.at_most("budget", spend, side);
    let full = match problem.lidar.power_accounting {
        PowerAccounting::Angle => TAU,
        PowerAccounting::Time => 1.0,
    };
    lp.relax_row(row, accepted(full).max(side));
}

/// `slew`: `|x_{i+1} − x_i| ≤ s·(Δ_i + Δ_{i+1})/2·side` around the circle
/// (`s` in W per degree, `side` from [`slew_side`]; `x` in units of
/// `p_mean`).
fn slew(lp: &mut Program, g: &Grid, x: &[LinearForm], s: f64, (p_mean, side): (f64, f64)) {
    for i in 0..g.n {
        let j = next_index(i, g.n);
        let lim = s * 0.5 * (g.width_deg[i] + g.width_deg[j]) / p_mean * side;
        let mut d = x[j].clone();
        d.add_mul(-1.0, &x[i]);
        let (upper, lower) = lp.between("slew", d, -lim, lim);
        let outer = accepted(s * 0.5 * (g.width_deg[i] + g.width_deg[j]) / p_mean).max(lim);
        lp.relax_row(upper, outer);
        lp.relax_row(lower, -outer);
    }
}

/// `slew_levels` (hardware levels under a slew limit): for each pair of
/// neighbours and each level `k` of one, `z_k ≤ Σ z_l` over the other's
/// levels `l` within the slew row's limit of `k` (a row only where some
/// level is out of reach). Every level choice that meets the `slew` rows
/// meets these (a level within the limit, compared with a relative 10⁻⁹ of
/// head-room, is always counted), so the MILP's points are unchanged; its
/// LP relaxation, which the aggregate `slew` rows let mix far-apart levels
/// into a ramp no level choice can follow, is tighter, and so is the
/// certificate's bound (the relaxation's duals).
fn slew_levels(lp: &mut Program, g: &Grid, x: &[LinearForm], s: f64, (p_mean, side): (f64, f64)) {
    // Per bin its (x level, binary), ordered by level then column.
    let levels: Vec<Vec<(f64, Variable)>> = x
        .iter()
        .map(|form| {
            let mut v: Vec<(f64, usize, Variable)> = form
                .linear_coefficients()
                .map(|(z, a)| (a, lp.col(z), z))
                .collect();
            v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            v.into_iter().map(|(a, _, z)| (a, z)).collect()
        })
        .collect();
    for i in 0..g.n {
        let j = next_index(i, g.n);
        let lim = s * 0.5 * (g.width_deg[i] + g.width_deg[j]) / p_mean * side;
        let reach = lim * (1.0 + 1e-9);
        for (a, b) in [(i, j), (j, i)] {
            for &(xa, za) in &levels[a] {
                let near: Vec<Variable> = levels[b]
                    .iter()
                    .filter(|(xb, _)| (xb - xa).abs() <= reach)
                    .map(|&(_, z)| z)
                    .collect();
                if near.len() == levels[b].len() {
                    continue;
                }
                let mut e = Expression::default();
                e.add_mul(1.0, za);
                for z in near {
                    e.add_mul(-1.0, z);
                }
                lp.at_most("slew_levels", e, 0.0);
            }
        }
    }
}

/// `eye_cuts`: every cut of the pool on more than one bin as a row
/// `Σ n_b·x_b·P̄ / (f_p·limit) ≤ cut_rhs` (single-bin cuts are column
/// bounds, see [`eye_caps`]).
fn eye_cuts(
    lp: &mut Program,
    problem: &Problem,
    e: &Eye,
    pool: &[Cut],
    factor: &[f64; 2],
    x: &[LinearForm],
) -> Result<(), OptError> {
    let l = &problem.lidar.limits;
    let p_mean = problem.lidar.average_power_w;
    for c in pool.iter().filter(|c| c.pulses.len() > 1) {
        let mut row = Expression::default();
        let f = factor[cut_class(c)];
        let limit = c.limit_j / f;
        for &(b, n) in &c.pulses {
            row.add_mul(n * p_mean / (e.pulse_rate_hz * limit), &x[b]);
        }
        // A floor alone at more than the row's side (but within the bare
        // limit: checked below) keeps its own value.
        let at_floor: f64 = c.pulses.iter().map(|&(_, n)| n).sum::<f64>() * l.power_w_min
            / (e.pulse_rate_hz * limit);
        if at_floor > f {
            return Err(Infeasible::EyeWindowAtFloor {
                wavelength_nm: l.eye_safety.as_ref().map_or(0.0, |p| p.wavelength_nm),
                power_w_min: l.power_w_min,
                ratio: at_floor / f,
                azimuth_deg: c.azimuth_deg,
                rule: format!("{:?}", c.rule),
            }
            .into());
        }
        let side = cut_rhs().max(at_floor * (1.0 + 1e-12));
        let row = lp.at_most("eye_cuts", row, side);
        // A certified profile meets every cut at its bare limit (a cut is
        // one concrete exposure, at most the bound's worst case, which
        // `check` holds to 1): the row's value is the exposure's ratio
        // times `f`. A relative 1e-9 covers the rounding of the row's
        // coefficients.
        lp.relax_row(row, (f * (1.0 + 1e-9)).max(side));
    }
    Ok(())
}

/// The powers (W) of a solved power step: levels as chosen, continuous
/// powers clamped into their bounds and trimmed to the budget exactly
/// (lower powers never break a cut: every cut has nonnegative
/// coefficients).
fn powers(problem: &Problem, g: &Grid, t: &[f64], program: &PowerProgram, sol: &[f64]) -> Vec<f64> {
    let (bins, x) = (&program.bins, &program.x);
    let lid = &problem.lidar;
    let l = &lid.limits;
    let p_mean = lid.average_power_w;
    let period: f64 = t.iter().sum();
    let eval = |form: &LinearForm| program.lp.eval(form, sol);
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
/// rows, `|p_j − p_i| ≤ s·(Δ_i + Δ_j)/2·(1 − S.margin)`, a few ulps inside:
/// each power becomes the least over all bins of that bin's power plus the
/// slew allowance along the circle between them (sweeps both ways until
/// nothing moves). HiGHS meets those rows only to its absolute tolerance
/// (1e-7 of `P̄`), more than the limit itself when the limit is tiny or 0
/// (a 0 W/deg limit gave a profile the checker rejected). Lowering never breaks the budget or an eye-safety cut (their
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
                * (1.0 - S.margin)
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
    /// `lp` with the user's limits as `check` accepts them in place of the
    /// margins (`Program::outer_view`): the program the certificate's bound
    /// is for and the one exported.
    outer: LinearProgram,
    bins: Vec<PowerBin>,
    /// The largest factor an eye-safety cut was tightened by, if any.
    pub(super) tightening: Option<f64>,
    /// The column fixed at 1 that carries the utilities' constants.
    one: Option<usize>,
    p_mean: f64,
    floor_w: f64,
    y: Vec<f64>,
    solver_dual_bound: Option<f64>,
    /// The `budget` row's multiplier (objective per unit of `Σ w_i x_i`,
    /// `w_i` the bin's share of the frame under time accounting), 0 when
    /// the row does not bind or there is none.
    budget_price: f64,
}

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
    pub(super) fn certify(&self, p: &[f64]) -> Result<(Certified, Vec<f64>), CertificateError> {
        let floor = self.floor_w;
        let mut q = p.to_vec();
        for k in 0..S.repair_tries {
            let v = self.point(&q).ok_or(CertificateError::NotALevel)?;
            // The point meets the solved program (the margins inside the
            // limits) exactly; its bound is the user's problem's.
            let inner = if super::certificate::primal_feasible(&self.lp, &v) {
                Ok(())
            } else {
                Err(CertificateError::NotFeasible(
                    "the power step's point breaks a row or bound of its solved program".into(),
                ))
            };
            match inner.and_then(|()| {
                Certified::new(
                    Step::Power,
                    self.outer.clone(),
                    v,
                    self.y.clone(),
                    self.solver_dual_bound,
                )
            }) {
                Ok(c) => return Ok((c, q)),
                Err(e)
                    if k + 1 == S.repair_tries
                        || self.bins.iter().any(|b| matches!(b, PowerBin::Levels(_))) =>
                {
                    return Err(e)
                }
                Err(_) => {}
            }
            let shrink = 1.0 - f64::EPSILON * f64::from(1u32 << k.min(30));
            for qi in &mut q {
                let toward_floor = floor + (*qi - floor).max(0.0) * shrink;
                // A floor within a few ulps of the power (a floor at the
                // budget): shrinking the excess over it moves nothing, so
                // the power itself shrinks, never below the floor.
                *qi = if toward_floor < *qi {
                    toward_floor
                } else {
                    (*qi * shrink).max(floor)
                };
            }
        }
        Err(CertificateError::PowerStep)
    }
}

/// A dwell step's answer: the dwell (s), and its program's exact
/// certificate or why there is none.
pub(super) struct DwellStep {
    t: Vec<f64>,
    cert: Result<Certified, CertificateError>,
}

/// Dwell step: power `p` fixed; `current` is the iterate for linearisation.
///
/// Eye safety: the cuts `binding` at `(p, current)` (concrete exposures at
/// their limit, found by the power step before) linearised in dwell — the
/// pulses a cut counts from bin `b` scaled by `t_b/t_b⁰` (a pass over `b`
/// holds pulses in proportion to its time there), the limits held at the
/// iterate's — inside a trust region of ±`settings::trust` on the bins they touch.
/// Exact at the iterate, first order around it; the bound decides after
/// (the power step that follows restores certified powers; without one the
/// move is shortened until the bound certifies, see [`solve`]).
///
/// Certificate (`specs/optimizer.md`, "The dwell step's certificate"):
/// HiGHS solves the program at `settings::dwell_feasibility_tol`; its point, with
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
    energy_price: f64,
) -> Result<DwellStep, OptError> {
    let mut d = dwell_program(problem, g, binding, pulse_rate_hz, p, current, false)?;
    if energy_price > 0.0 {
        price_energy(&mut d, p, problem.lidar.average_power_w, energy_price);
    }
    // Under time accounting the `budget` row `Σ τ_i·p_i/P̄ ≤ N` holds
    // whenever `Σ τ_i ≤ N / max_i(p_i/P̄)`: the heuristic's band ends there
    // too (the frame band alone reaches above `N`).
    let spend = (problem.lidar.power_accounting == PowerAccounting::Time)
        .then(|| p.iter().fold(0.0_f64, |m, &pi| m.max(pi)) / problem.lidar.average_power_w);
    let choice = SetPointChoice::new(&d, g, spend);
    let solved = d.lp.solve_with(
        "dwell",
        &SolveOptions {
            initial: Some(&d.start),
            primal_feasibility_tolerance: S.dwell_feasibility_tol,
            heuristic: choice.as_ref().map(|c| c as &dyn Heuristic),
            presolve: true,
        },
    )?;
    let view = d.lp.view();
    let x = view.clamped(&solved.x);
    let t = dwell_answer(problem, g, &d, &x);
    let cert = Certified::new(
        Step::Dwell,
        view.widened(2.0 * S.dwell_feasibility_tol),
        x,
        solved.y,
        solved.solver_dual_bound,
    )
    .map_err(|e| CertificateError::DwellStep(Box::new(e)));
    Ok(DwellStep { t, cert })
}

/// The certificate of a `resolution`-mode answer whose dwell `answer` (s,
/// per bin) is no program's point: the spin rebuilt continuous under an
/// acceleration limit, or the move shortened for eye safety. Its program is
/// the dwell step's linearised at the answer (no eye-safety cuts, the
/// trust region around the answer, the acceleration rows at least the
/// answer's own slowness steps, every box widened to hold the answer), so
/// the answer, filled into the utility's segments, is a point of it; the
/// multipliers are HiGHS's row duals of that program, and the point and
/// bound are checked exactly on its rows widened by twice the dwell
/// step's tolerance, as every dwell step's.
fn answer_dwell_certificate(
    problem: &Problem,
    g: &Grid,
    p: &[f64],
    answer: &[f64],
) -> Result<Certified, CertificateError> {
    let f_p = problem.lidar.pulse_rate_hz;
    let solver = |e: OptError| CertificateError::AnswerProgram(e.to_string());
    let d = dwell_program(problem, g, &[], f_p, p, answer, true).map_err(solver)?;
    let solved =
        d.lp.solve_with(
            "dwell",
            &SolveOptions {
                initial: Some(&d.start),
                primal_feasibility_tolerance: S.dwell_feasibility_tol,
                ..SolveOptions::default()
            },
        )
        .map_err(solver)?;
    Certified::new(
        Step::Dwell,
        d.lp.view().widened(2.0 * S.dwell_feasibility_tol),
        d.start,
        solved.y,
        solved.solver_dual_bound,
    )
    .map_err(|e| CertificateError::DwellStep(Box::new(e)))
}

/// The dwell step's program and how each bin's dwell reads from it.
struct DwellProgram {
    lp: Program,
    /// `τ_i = t_i / unit` as a linear form over the columns.
    tau: Vec<LinearForm>,
    /// Per bin with set-points, (spin, binary column) per set-point.
    sp_cols: Vec<Vec<(f64, usize)>>,
    /// The hot start, one value per column.
    start: Vec<f64>,
    /// `T / N`, s.
    unit: f64,
}

/// Builds the dwell step's program: per bin its columns and utility (with
/// set-points: the `levels` family, one binary per set-point and a one-hot
/// row), then the constraint families in a fixed order — `frame`,
/// `budget` (time accounting), `accel`, `eye_cuts` (linearised).
/// `contain`: the program is linearised at an answer `current` and must
/// contain it (see [`answer_dwell_certificate`]): its boxes and
/// acceleration rows are widened to the answer where it lies outside them.
fn dwell_program(
    problem: &Problem,
    g: &Grid,
    binding: &[Cut],
    pulse_rate_hz: f64,
    p: &[f64],
    current: &[f64],
    contain: bool,
) -> Result<DwellProgram, OptError> {
    let l = &problem.lidar.limits;
    let setpoints = &problem.levels.spin_rad_s;
    let allowed: Vec<f64> = setpoints
        .iter()
        .copied()
        .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max)
        .collect();
    if !setpoints.is_empty() && allowed.is_empty() {
        return Err(Infeasible::NoSetPointFits.into());
    }
    let mut touched = vec![false; g.n];
    for c in binding {
        for &(b, _) in &c.pulses {
            touched[b] = true;
        }
    }
    let mut d = DwellProgram {
        lp: Program::default(),
        tau: Vec::with_capacity(g.n),
        sp_cols: Vec::new(),
        start: Vec::new(),
        unit: 1.0 / problem.lidar.frame_rate_hz / g.n as f64,
    };
    let mut utility_constant = 0.0;
    for i in 0..g.n {
        if setpoints.is_empty() {
            let trust = l.spin_accel_rad_s2_max.is_some() || touched[i];
            utility_constant += dwell_column(&mut d, problem, g, i, current[i], (trust, contain));
        } else {
            spin_levels(&mut d, problem, g, i, &allowed);
        }
    }
    // The utilities' constants Σ c·√r_0 as one column fixed at 1 (as the
    // power step's), so the program's objective is the chord model's value
    // of the profile, comparable with `exact_objective`.
    if utility_constant != 0.0 {
        d.lp.column(1.0, 1.0, utility_constant, false);
        d.start.push(1.0);
    }
    frame(&mut d, g.n);
    if problem.lidar.power_accounting == PowerAccounting::Time {
        dwell_budget(&mut d, p, problem.lidar.average_power_w, g.n);
    }
    if let Some(a_max) = l.spin_accel_rad_s2_max {
        accel(&mut d, g, current, a_max, contain);
    }
    linearised_eye_cuts(&mut d, binding, pulse_rate_hz, p, current);
    Ok(d)
}

/// Bin `i`'s continuous dwell column `τ_i` (boxed by the spin limits and,
/// where `trust`, the trust region around the iterate `current_s`; where
/// `contain`, widened to hold `current_s`) and its density utility's
/// segments; returns the utility's constant.
fn dwell_column(
    d: &mut DwellProgram,
    problem: &Problem,
    g: &Grid,
    i: usize,
    current_s: f64,
    (trust, contain): (bool, bool),
) -> f64 {
    let l = &problem.lidar.limits;
    let period = 1.0 / problem.lidar.frame_rate_hz;
    let unit = d.unit;
    let th = g.theta[i];
    let (mut lo, mut hi) = dwell_box(l, th, unit);
    if trust {
        lo = lo.max(current_s / unit * (1.0 - S.trust));
        hi = hi.min(current_s / unit * (1.0 + S.trust)).max(lo);
    }
    if contain {
        lo = lo.min(current_s / unit);
        hi = hi.max(current_s / unit);
    }
    let t0 = (current_s / unit).max(lo).min(hi);
    let ti = d.lp.column(lo, hi, 0.0, false);
    d.start.push(t0);
    // Density ratio r = t·2π/(θ·T) = τ · (unit·2π/(θ·T)).
    let k = unit * TAU / (th * period);
    let w_mean = problem.lidar.mean_spin_rad_s();
    let r_lo = w_mean / l.spin_rad_s_max;
    let r_hi = if l.spin_rad_s_min > 0.0 {
        w_mean / l.spin_rad_s_min
    } else {
        1e3
    };
    // The utility as boxed segment columns on the densities this column
    // reaches (its box: the spin limits, and the trust region where it
    // applies), Σ δ ≤ k·τ − r_0 (see `utility`; its constant does not move
    // the optimum).
    let r_0 = r_lo.max(k * lo);
    let chords = if trust {
        S.trust_region_segments
    } else {
        super::UTILITY_SEGMENTS
    };
    let shape = sqrt_segments_n(r_0, r_hi.min(k * hi).max(r_0), chords);
    let c = problem.objective.resolution_weight * th * g.weight[i];
    shape.add_to(&mut d.lp, ti, k, r_0, c);
    d.start.extend(shape.fill(r_0, k * t0));
    d.tau.push(ti.into());
    c * shape.base
}

/// The box of a bin's `τ` from the spin limits, with the margin; where the
/// margins cross (spin limits within 2e-6 of each other, e.g. equal: a
/// fixed spin), the limits themselves.
fn dwell_box(l: &crate::model::lidar::Limits, th: f64, unit: f64) -> (f64, f64) {
    let lo = th / l.spin_rad_s_max / unit * (1.0 + S.margin);
    let hi = if l.spin_rad_s_min > 0.0 {
        th / l.spin_rad_s_min / unit * (1.0 - S.margin)
    } else {
        1e9
    };
    if lo <= hi {
        (lo, hi)
    } else {
        let bare = |w: f64| th / w / unit;
        (
            bare(l.spin_rad_s_max),
            bare(l.spin_rad_s_min).max(bare(l.spin_rad_s_max)),
        )
    }
}

/// `levels` for the spin: one binary per allowed set-point `w` (cost
/// `c·√(ω̄/w)`) and the one-hot row `Σ y = 1`; `τ_i = Σ (θ_i/w)/unit · y_w`.
fn spin_levels(d: &mut DwellProgram, problem: &Problem, g: &Grid, i: usize, allowed: &[f64]) {
    let th = g.theta[i];
    let w_mean = problem.lidar.mean_spin_rad_s();
    let lam = problem.objective.resolution_weight;
    let ys: Vec<(f64, Variable)> = allowed
        .iter()
        .map(|&w| {
            let cost = lam * th * g.weight[i] * (w_mean / w).sqrt();
            d.start.push(0.0);
            (w, d.lp.column(0.0, 1.0, cost, true))
        })
        .collect();
    d.lp.equal("levels", ys.iter().map(|&(_, y)| y).sum(), 1.0);
    let unit = d.unit;
    let mut tau = Expression::with_capacity(ys.len());
    for &(w, y) in &ys {
        tau.add_mul(th / w / unit, y);
    }
    d.tau.push(tau);
    let cols = ys.iter().map(|&(w, y)| (w, d.lp.col(y))).collect();
    d.sp_cols.push(cols);
}

/// `frame`: `Σ τ_i = N` (one turn per frame period); with spin set-points
/// the band `N·(1 ± setpoint_frame_tol)` (the checker's tolerance, see
/// `settings`), two rows.
fn frame(d: &mut DwellProgram, n: usize) {
    let n = n as f64;
    let mut turn = Expression::default();
    for form in &d.tau {
        turn.add_mul(1.0, form);
    }
    if d.sp_cols.is_empty() {
        d.lp.equal("frame", turn, n);
    } else {
        let tol = S.setpoint_frame_tol;
        d.lp.between("frame", turn, n * (1.0 - tol), n * (1.0 + tol));
    }
}

/// The dwell step's set-point choice on equal bins, for the primal
/// heuristic: a composition (bins per set-point) near the relaxation's
/// counts that meets the `frame` band ([`super::setpoints::best_composition`]),
/// its set-points given to the bins by their objective coefficients (the
/// slowest set-point to the bins that gain most from it: with costs
/// `C_i·v_k` the rearrangement inequality makes this the best assignment
/// of those counts). The caller checks the point exactly against every
/// row (budget, acceleration, eye-safety cuts included).
struct SetPointChoice {
    /// Per bin, its set-points' columns (the set-points' order).
    cols: Vec<Vec<usize>>,
    /// Per bin and set-point, the objective coefficient.
    cost: Vec<Vec<f64>>,
    /// Per set-point, its `τ` on every bin (equal bins).
    r: Vec<f64>,
    /// The `frame` band.
    band: (f64, f64),
    columns: usize,
}

impl SetPointChoice {
    /// `None` unless every bin has the same set-points' `τ` (equal bins)
    /// and the program's columns are the set-points' binaries. With
    /// `spend` (the largest `p_i/P̄` of a time-accounted budget row), the
    /// band's top is also `N/spend`, lowered by a relative 10⁻¹² (the float
    /// sums' rounding and the row coefficients' `r_k·p_i/P̄` products, some
    /// 10⁻¹³, stay inside it), so the point meets the budget row exactly.
    fn new(d: &DwellProgram, g: &Grid, spend: Option<f64>) -> Option<Self> {
        let n = g.n;
        if d.sp_cols.len() != n || n == 0 || !equal_bins(g) {
            return None;
        }
        let r: Vec<f64> = d.sp_cols[0]
            .iter()
            .map(|&(w, _)| g.theta[0] / w / d.unit)
            .collect();
        let cols: Vec<Vec<usize>> = d
            .sp_cols
            .iter()
            .map(|b| b.iter().map(|c| c.1).collect())
            .collect();
        if cols.iter().any(|c| c.len() != r.len()) || d.lp.len() != n * r.len() {
            return None;
        }
        let cost = cols
            .iter()
            .map(|c| c.iter().map(|&j| d.lp.cost(j)).collect())
            .collect();
        let tol = S.setpoint_frame_tol;
        let nf = n as f64;
        Some(Self {
            cols,
            cost,
            r,
            band: (
                nf * (1.0 - tol * 0.5),
                match spend {
                    Some(q) if q > 0.0 => (nf * (1.0 + tol * 0.5)).min(nf / q * (1.0 - 1e-12)),
                    _ => nf * (1.0 + tol * 0.5),
                },
            ),
            columns: d.lp.len(),
        })
    }

    /// Bins by their gain from the slowest set-point over the fastest,
    /// most first, and set-points by `τ`, slowest first: the assignment of
    /// counts `c` gives the first `c` of the bins to the slowest set-point,
    /// and so on. Bins of equal gain (the bins outside the focus under a
    /// box acuity, say) are taken in bit-reversed order of their index, so
    /// that every set-point's bins among them are spread over the circle
    /// rather than side by side (the objective is the same for any order of
    /// ties; the eye-safety bound, which [`spread_setpoints`] checks next,
    /// sees the slow set-points' exposure spread out).
    fn orders(&self) -> (Vec<usize>, Vec<usize>) {
        let k = self.r.len();
        let mut sp: Vec<usize> = (0..k).collect();
        sp.sort_by(|&a, &b| self.r[b].total_cmp(&self.r[a]).then(a.cmp(&b)));
        let (slow, fast) = (sp[0], sp[k - 1]);
        let n = self.cols.len();
        let mut bins: Vec<usize> = (0..n).collect();
        let gain = |i: usize| self.cost[i][slow] - self.cost[i][fast];
        let spread = |i: usize| bit_reversed(i, n);
        bins.sort_by(|&a, &b| {
            gain(b)
                .total_cmp(&gain(a))
                .then(spread(a).cmp(&spread(b)))
                .then(a.cmp(&b))
        });
        (bins, sp)
    }

    /// Per bin its set-point under counts `c`.
    fn assign(&self, c: &[usize], (bins, sp): (&[usize], &[usize])) -> Vec<usize> {
        let mut out = vec![0; bins.len()];
        let mut at = 0;
        for &k in sp {
            for &i in &bins[at..at + c[k]] {
                out[i] = k;
            }
            at += c[k];
        }
        out
    }
}

impl Heuristic for SetPointChoice {
    fn start(&self, relaxed: &[f64], _duals: &[f64]) -> Option<Vec<f64>> {
        if relaxed.len() != self.columns {
            return None;
        }
        let k = self.r.len();
        let near: Vec<f64> = (0..k)
            .map(|j| self.cols.iter().map(|c| relaxed[c[j]]).sum())
            .collect();
        let (bins, sp) = self.orders();
        let score = |c: &[usize]| -> f64 {
            let a = self.assign(c, (&bins, &sp));
            a.iter().enumerate().map(|(i, &j)| self.cost[i][j]).sum()
        };
        let c = super::setpoints::best_composition(
            &self.r,
            self.cols.len(),
            self.band,
            &near,
            &score,
            S.setpoint_heuristic_steps,
        )?;
        let mut x = vec![0.0; self.columns];
        for (i, j) in self.assign(&c, (&bins, &sp)).into_iter().enumerate() {
            x[self.cols[i][j]] = 1.0;
        }
        Some(x)
    }

    fn accept_gap(&self) -> f64 {
        S.setpoint_heuristic_gap
    }
}

/// `i` with its bits reversed over the `⌈log₂ n⌉` bits that count `0..n`
/// (the van der Corput order: any first few of `0..n` taken by it lie
/// spread over the range).
fn bit_reversed(i: usize, n: usize) -> usize {
    let bits = usize::BITS - n.saturating_sub(1).leading_zeros();
    if bits == 0 {
        0
    } else {
        i.reverse_bits() >> (usize::BITS - bits)
    }
}

/// The energy a dwell spends, priced into the dwell step's objective:
/// `− price·Σ τ_i·p_i/P̄` (the `budget` row's form). At the power step's
/// `budget` multiplier, the dwell step weighs the density it buys against
/// the range the next power step would buy with the energy it frees.
fn price_energy(d: &mut DwellProgram, p: &[f64], p_mean: f64, price: f64) {
    for (form, &pi) in d.tau.iter().zip(p) {
        for (v, a) in form.linear_coefficients() {
            let j = d.lp.col(v);
            d.lp.add_cost(j, -price * a * pi / p_mean);
        }
    }
}

/// `budget` under time accounting at the fixed powers `p`:
/// `Σ τ_i·p_i/P̄ ≤ N`. No margin here: with uniform P̄ the budget is exactly
/// tight. The power step that ends every joint solve trims the budget
/// exactly.
fn dwell_budget(d: &mut DwellProgram, p: &[f64], p_mean: f64, n: usize) {
    let mut spend = Expression::default();
    for (form, &pi) in d.tau.iter().zip(p) {
        for (v, a) in form.linear_coefficients() {
            spend.add_mul(a * pi / p_mean, v);
        }
    }
    d.lp.at_most("budget", spend, n as f64);
}

/// `accel`: the change of slowness `s = t/θ` between neighbours,
/// `|Δs| ≤ accel_share·a·Δθ·(1−trust)³/ω̃³`, linearised at the iterate;
/// where `contain`, at least the iterate's own `|Δs|`.
fn accel(d: &mut DwellProgram, g: &Grid, current: &[f64], a_max: f64, contain: bool) {
    let unit = d.unit;
    for i in 0..g.n {
        let j = next_index(i, g.n);
        let w_cur = (g.theta[i] / current[i]).max(g.theta[j] / current[j]);
        let dtheta = 0.5 * (g.theta[i] + g.theta[j]);
        let mut ds = S.accel_share * a_max * dtheta * (1.0 - S.trust).powi(3) / w_cur.powi(3);
        // s = t/θ = τ·unit/θ.
        let (ki, kj) = (unit / g.theta[i], unit / g.theta[j]);
        if contain {
            let own = (kj * (current[j] / unit) - ki * (current[i] / unit)).abs();
            ds = ds.max(own * (1.0 + 1e-9));
        }
        let mut diff = Expression::default();
        diff.add_mul(kj, &d.tau[j]);
        diff.add_mul(-ki, &d.tau[i]);
        d.lp.between("accel", diff, -ds, ds);
    }
}

/// `eye_cuts` linearised in dwell: the pulses a binding cut counts from bin
/// `b` scaled by `τ_b/τ_b⁰`, the limits held at the iterate's.
fn linearised_eye_cuts(
    d: &mut DwellProgram,
    binding: &[Cut],
    pulse_rate_hz: f64,
    p: &[f64],
    current: &[f64],
) {
    for c in binding {
        let mut en = Expression::default();
        for &(b, cnt) in &c.pulses {
            let tau0 = current[b] / d.unit;
            let k = cnt * p[b] / (pulse_rate_hz * c.limit_j) / tau0;
            en.add_mul(k, &d.tau[b]);
        }
        d.lp.at_most("eye_cuts", en, cut_rhs());
    }
}

/// The dwell (s) of the solved point `x`: continuous columns rescaled to
/// the exact frame period, or each bin's chosen set-point.
fn dwell_answer(problem: &Problem, g: &Grid, d: &DwellProgram, x: &[f64]) -> Vec<f64> {
    if !problem.levels.spin_rad_s.is_empty() {
        return d
            .sp_cols
            .iter()
            .zip(&g.theta)
            .map(|(ys, th)| {
                let w = ys
                    .iter()
                    .max_by(|a, b| x[a.1].total_cmp(&x[b.1]))
                    .map_or(0.0, |&(w, _)| w);
                th / w
            })
            .collect();
    }
    let mut t: Vec<f64> = d
        .tau
        .iter()
        .map(|form| d.lp.eval(form, x) * d.unit)
        .collect();
    // Exact frame period.
    let period = 1.0 / problem.lidar.frame_rate_hz;
    let s: f64 = t.iter().sum();
    for ti in &mut t {
        *ti *= period / s;
    }
    t
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

/// Whether every bin of `spins` ramps within the acceleration limit
/// (the profile's constant acceleration, [`BinMotion::accel_rad_s2`]) to
/// half the checker's relative tolerance: what passes here the checker
/// accepts, and a ramp the checker would accept is not thrown away for
/// being a hair above the limit.
fn meets_accel(g: &Grid, spins: &[(f64, f64)], limit: Option<f64>) -> bool {
    use crate::profile::kinematics::BinMotion;
    let Some(a_max) = limit else {
        return true;
    };
    let top = a_max + 0.5 * crate::checker::REL_TOL * a_max.abs().max(f64::MIN_POSITIVE);
    // The power does not move the acceleration.
    segs(g, spins, &vec![0.0; g.n])
        .iter()
        .all(|s| s.accel_rad_s2().abs() <= top)
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
    pub(super) last: Result<Certified, CertificateError>,
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
            last: Err(CertificateError::NoProgram),
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

/// Solves and builds the (uncertified) profile, with the programs'
/// certificates: block-coordinate ascent from the uniform baseline as named
/// steps — the mode's rounds ([`range_rounds`], [`resolution_rounds`],
/// [`joint_rounds`]), the final power step on a smoothed spin, the
/// eye-safety shortening of a resolution-mode move, the profile.
pub(super) fn solve(problem: &Problem, gaze_deg: f64) -> Result<Solution, OptError> {
    let g = grid(problem, gaze_deg)?;
    let lid = &problem.lidar;
    let eye = eye(problem)?;
    prechecks(problem, eye.as_ref())?;
    let w_mean = lid.mean_spin_rad_s();
    let t_base: Vec<f64> = g.theta.iter().map(|th| th / w_mean).collect();
    let p_start = lid
        .average_power_w
        .clamp(lid.limits.power_w_min, lid.limits.power_w_max);
    let mut it = Iterate {
        p: vec![p_start; g.n],
        t: t_base.clone(),
        last: None,
        dwell: None,
    };
    let ctx = Ctx {
        problem,
        g: &g,
        eye: eye.as_ref(),
        gaze_deg,
    };
    let mode = problem.objective.mode;
    match mode {
        Mode::Baseline => {}
        Mode::Range => range_rounds(&ctx, &mut it)?,
        Mode::Resolution => resolution_rounds(&ctx, &mut it)?,
        Mode::Joint => joint_rounds(&ctx, &mut it)?,
    }
    let smooth = lid.limits.spin_accel_rad_s2_max.is_some() && mode.controls_resolution();
    let mut spins = spins_of(&g, &it.t, smooth, lid.frame_rate_hz);
    if smooth && !meets_accel(&g, &spins, lid.limits.spin_accel_rad_s2_max) {
        // The sequential LP's rows are linearised (and the rebuilt spin is
        // rescaled to the frame period): under a limit too small for any
        // modulation the ramps it leaves can exceed it. The uniform spin
        // meets every limit the rounds started from.
        spins = vec![(w_mean, w_mean); g.n];
        it.t = dwell_of(&g, &spins);
    }
    if smooth && mode.controls_range() {
        // Final power step on the exact spin of the rebuilt profile.
        let mut pool = ctx.warm(&spins, &it.p);
        let (pp, plp) = power_step(problem, &g, ctx.eye, &spins, &mut pool)?;
        it.p = pp;
        it.last = Some(plp);
    }
    let mut shortened = false;
    if let (Some(e), Mode::Resolution) = (ctx.eye, mode) {
        if !smooth && !problem.levels.spin_rad_s.is_empty() {
            if let Some((t, cert)) = spread_setpoints(&ctx, e, &it)? {
                spins = spins_of(&g, &t, false, lid.frame_rate_hz);
                it.t = t;
                if let Some(d) = it.dwell.as_mut() {
                    d.last = cert;
                }
            }
        }
        (spins, shortened) = shorten_for_eye_safety(&ctx, e, &it, &t_base, spins, smooth)?;
    }
    let profile = build_profile(problem, &g, gaze_deg, &it.p, &spins);
    if let Some(d) = it.dwell.as_mut() {
        d.is_answer = mode == Mode::Resolution && !smooth && !shortened;
        if mode == Mode::Resolution && (smooth || shortened) && problem.levels.spin_rad_s.is_empty()
        {
            // The answer's dwell is no program's point: its own program.
            d.last = answer_dwell_certificate(problem, &g, &it.p, &dwell_of(&g, &spins));
            d.programs += 1;
            d.is_answer = true;
        }
    }
    Ok(Solution {
        profile,
        power: it.last,
        dwell: it.dwell,
    })
}

/// What every step of [`solve`] reads.
struct Ctx<'a> {
    problem: &'a Problem,
    g: &'a Grid,
    eye: Option<&'a Eye>,
    gaze_deg: f64,
}

impl Ctx<'_> {
    /// The cuts of new spins, found at the powers before the step (a warm
    /// start: valid whatever the powers).
    fn warm(&self, spins: &[(f64, f64)], p: &[f64]) -> Vec<Cut> {
        self.eye.map_or_else(Vec::new, |e| {
            e.cuts(&segs(self.g, spins, p), &[], S.binding)
        })
    }

    /// The binding cuts of an iterate, found afresh (a function of the
    /// iterate alone, not of the loop's path).
    fn binding(&self, spins: &[(f64, f64)], p: &[f64]) -> Vec<Cut> {
        let f_p = self.problem.lidar.pulse_rate_hz;
        self.warm(spins, p)
            .into_iter()
            .filter(|c| c.ratio(p, f_p) >= S.binding)
            .collect()
    }

    /// Step spins of dwell `t` (one spin per bin).
    fn steps(&self, t: &[f64]) -> Vec<(f64, f64)> {
        spins_of(self.g, t, false, self.problem.lidar.frame_rate_hz)
    }

    /// Dwell-step rounds: the sequential LP's with a finite acceleration
    /// limit, else one.
    fn spin_rounds(&self) -> usize {
        if self.problem.lidar.limits.spin_accel_rad_s2_max.is_some() {
            S.slp_rounds
        } else {
            1
        }
    }

    /// A power step on `spins` from the iterate's powers.
    fn power(&self, it: &mut Iterate, spins: &[(f64, f64)]) -> Result<(), OptError> {
        let mut pool = self.warm(spins, &it.p);
        let (pp, plp) = power_step(self.problem, self.g, self.eye, spins, &mut pool)?;
        it.p = pp;
        it.last = Some(plp);
        Ok(())
    }
}

/// The block-coordinate iterate: powers (W), dwell (s), the last power
/// step's program and the dwell steps' certificates.
struct Iterate {
    p: Vec<f64>,
    t: Vec<f64>,
    last: Option<PowerLp>,
    dwell: Option<DwellCertificates>,
}

/// `range`: one power step on the uniform spin.
fn range_rounds(ctx: &Ctx<'_>, it: &mut Iterate) -> Result<(), OptError> {
    let sp = ctx.steps(&it.t);
    ctx.power(it, &sp)
}

/// `resolution`: dwell steps at the fixed power until settled.
fn resolution_rounds(ctx: &Ctx<'_>, it: &mut Iterate) -> Result<(), OptError> {
    let f_p = ctx.problem.lidar.pulse_rate_hz;
    for round in 0..ctx.spin_rounds() {
        let step = match dwell_step(ctx.problem, ctx.g, &[], f_p, &it.p, &it.t, 0.0) {
            // See `joint_rounds`.
            Err(OptError::Infeasible(_)) if round > 0 => break,
            r => r?,
        };
        let next = DwellCertificates::push(&mut it.dwell, step);
        let settled = settled(&next, &it.t);
        it.t = next;
        if settled {
            break;
        }
    }
    Ok(())
}

/// `joint`: alternating dwell and power steps until a fixed point, the
/// sequential LP settles, or the rounds run out.
fn joint_rounds(ctx: &Ctx<'_>, it: &mut Iterate) -> Result<(), OptError> {
    let f_p = ctx.problem.lidar.pulse_rate_hz;
    let smooth_spin = ctx.problem.lidar.limits.spin_accel_rad_s2_max.is_some();
    let rounds = ctx.spin_rounds().max(2);
    let mut binding: Vec<Cut> = Vec::new();
    for round in 0..rounds {
        let step = match dwell_step(ctx.problem, ctx.g, &binding, f_p, &it.p, &it.t, 0.0) {
            // A later round's program (re-linearised acceleration rows,
            // trust region, the budget at the new powers) can have no point
            // even though the iterate is a certified profile's (seen at
            // 10⁴ rad/s²): the sequential LP cannot move from
            // it, so it stops there.
            Err(OptError::Infeasible(_)) if round > 0 => break,
            r => r?,
        };
        let next = DwellCertificates::push(&mut it.dwell, step);
        if it.last.is_some() && next == it.t {
            // A fixed point: both steps are deterministic functions of
            // (p, t) (the binding cuts are found afresh from them), so every
            // further round repeats this one.
            break;
        }
        let settled = smooth_spin && settled(&next, &it.t);
        it.t = next;
        if smooth_spin && (settled || round + 1 == rounds) {
            // The last dwell of a smoothed spin: the final power step in
            // `solve`, on the rebuilt spin, replaces this round's power
            // step on the step spins.
            break;
        }
        let sp = ctx.steps(&it.t);
        ctx.power(it, &sp)?;
        binding = ctx.binding(&sp, &it.p);
    }
    if !smooth_spin && ctx.problem.lidar.power_accounting == PowerAccounting::Time {
        priced_rounds(ctx, it, binding)?;
    }
    Ok(())
}

/// Under time accounting the budget couples the steps (a bin's energy is
/// its power times its dwell), and the loop above stops where neither
/// step moves: the dwell step, the power fixed, has no reason to free
/// energy. From there each round prices the energy in the dwell step at
/// the last power step's `budget` multiplier ([`price_energy`]; the power
/// step's row `Σ (t_i/T)·x_i ≤ 1` is the dwell step's `Σ τ_i·x_i ≤ N`
/// over `N`), then runs the power step at the new dwell; a round is kept
/// only if it raises the model objective (the exact utilities), and the
/// first that does not ends the search. Every kept round is a dwell step
/// and a power step like any other, with their certificates.
fn priced_rounds(ctx: &Ctx<'_>, it: &mut Iterate, mut binding: Vec<Cut>) -> Result<(), OptError> {
    let f_p = ctx.problem.lidar.pulse_rate_hz;
    let n = ctx.g.n as f64;
    let score = |p: &[f64], t: &[f64]| -> Result<f64, OptError> {
        let sp = ctx.steps(t);
        let profile = build_profile(ctx.problem, ctx.g, ctx.gaze_deg, p, &sp);
        super::exact_objective(ctx.problem, ctx.gaze_deg, &profile)
    };
    let mut best = score(&it.p, &it.t)?;
    for _ in 0..S.priced_rounds {
        let price = it.last.as_ref().map_or(0.0, |l| l.budget_price) / n;
        if !(price > 0.0 && price.is_finite()) {
            break;
        }
        let Ok(step) = dwell_step(ctx.problem, ctx.g, &binding, f_p, &it.p, &it.t, price) else {
            break;
        };
        let sp = ctx.steps(&step.t);
        let mut pool = ctx.warm(&sp, &it.p);
        let Ok((p, plp)) = power_step(ctx.problem, ctx.g, ctx.eye, &sp, &mut pool) else {
            break;
        };
        let j = score(&p, &step.t)?;
        if j.is_nan() || j <= best * (1.0 + S.priced_gain) {
            break;
        }
        best = j;
        let t = DwellCertificates::push(&mut it.dwell, step);
        it.t = t;
        it.p = p;
        it.last = Some(plp);
        binding = ctx.binding(&sp, &it.p);
    }
    Ok(())
}

/// `resolution` with eye safety: no power step follows the dwell steps, so
/// the move from the uniform spin is shortened until the bound certifies
/// (the uniform spin itself is the last resort, and the checker has the
/// last word). Returns the spins and whether the move was shortened.
fn shorten_for_eye_safety(
    ctx: &Ctx<'_>,
    e: &Eye,
    it: &Iterate,
    t_base: &[f64],
    mut spins: Vec<(f64, f64)>,
    smooth: bool,
) -> Result<(Vec<(f64, f64)>, bool), OptError> {
    let g = ctx.g;
    let p = &it.p;
    let safe = |sp: &[(f64, f64)]| -> Result<bool, OptError> {
        Ok(e.verdict(&segs(g, sp, p))?.0 <= eye_accept(ctx.problem))
    };
    let mut shortened = false;
    if !ctx.problem.levels.spin_rad_s.is_empty() && !safe(&spins)? {
        // A shortened move leaves the set-points (the hardware cannot run
        // it): the request is infeasible as posed.
        let (ratio, at_deg) = e.verdict(&segs(g, &spins, p))?;
        return Err(Infeasible::EyeAtSetPoints { ratio, at_deg }.into());
    }
    let mut alpha = 1.0;
    while !safe(&spins)? && alpha > 0.0 {
        shortened = true;
        alpha = if alpha > 1.0 / 64.0 { alpha / 2.0 } else { 0.0 };
        let ta: Vec<f64> = t_base
            .iter()
            .zip(&it.t)
            .map(|(b, x)| b + alpha * (x - b))
            .collect();
        spins = spins_of(g, &ta, smooth, ctx.problem.lidar.frame_rate_hz);
    }
    let (ratio, at) = e.verdict(&segs(g, &spins, p))?;
    if ratio > eye_accept(ctx.problem) {
        return Err(Infeasible::EyeAtUniformSpin {
            power_w: p[0],
            ratio,
            at_deg: at,
        }
        .into());
    }
    Ok((spins, shortened))
}

/// What [`spread_setpoints`] found: the dwell (s) and its certificate.
type Spread = Option<(Vec<f64>, Result<Certified, CertificateError>)>;

/// `resolution` mode with spin set-points whose answer the eye-safety bound
/// refuses: the answer's set-points moved between bins, the count of each
/// kept (so the frame period is the answer's), until the bound certifies.
/// Each swap takes the slowest bin of the binding exposure's bins (the
/// bound's worst azimuth, the concrete exposure there) and trades its
/// set-point for a faster one's in a bin outside them whose neighbourhood
/// (as many bins) is left cooler than the exposure's, the trade that loses
/// the least objective first; at most `setpoint_spread_swaps` swaps.
/// `None` when the answer already certifies, when its program is not the
/// plain set-point one (one binary per set-point and bin), or when no swap
/// is left; otherwise the new dwell (s) and its certificate: the point of
/// the last dwell program with the bins' binaries moved, checked exactly
/// with that program's multipliers (the bound stands: the program is the
/// same).
fn spread_setpoints(ctx: &Ctx<'_>, e: &Eye, it: &Iterate) -> Result<Spread, OptError> {
    let (g, p, problem) = (ctx.g, &it.p, ctx.problem);
    let l = &problem.lidar.limits;
    let allowed: Vec<f64> = (problem.levels.spin_rad_s.iter().copied())
        .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max)
        .collect();
    let Some(Ok(cert)) = it.dwell.as_ref().map(|d| &d.last) else {
        return Ok(None);
    };
    let (n, kk) = (g.n, allowed.len());
    if kk < 2 || cert.lp.cost.len() != n * kk || cert.x.len() != n * kk {
        return Ok(None);
    }
    let col = |i: usize, k: usize| i * kk + k;
    let mut k_of: Vec<usize> = (0..n)
        .map(|i| {
            (0..kk)
                .max_by(|&a, &b| cert.x[col(i, a)].total_cmp(&cert.x[col(i, b)]))
                .unwrap_or(0)
        })
        .collect();
    let accept = eye_accept(problem);
    let dwell = |i: usize, k: usize| g.theta[i] / allowed[k];
    let spins_at = |k_of: &[usize]| -> Vec<(f64, f64)> {
        k_of.iter().map(|&k| (allowed[k], allowed[k])).collect()
    };
    let first = e.verdict(&segs(g, &spins_at(&k_of), p))?;
    if first.0 <= accept {
        return Ok(None);
    }
    for _ in 0..S.setpoint_spread_swaps {
        let sg = segs(g, &spins_at(&k_of), p);
        let (ratio, at) = e.verdict(&sg)?;
        if ratio <= accept {
            let mut x = vec![0.0; n * kk];
            for (i, &k) in k_of.iter().enumerate() {
                x[col(i, k)] = 1.0;
            }
            let t = (0..n).map(|i| dwell(i, k_of[i])).collect();
            let c = Certified::new(
                Step::Dwell,
                cert.lp.clone(),
                x,
                cert.y.clone(),
                cert.solver_dual_bound,
            );
            return Ok(Some((t, c)));
        }
        // The bins around the worst azimuth (the bound's windows there span
        // a few degrees; the single-pulse cuts name one bin each).
        let i0 = g.start_deg.partition_point(|&s0| s0 <= wrap_deg(at)).max(1) - 1;
        let reach = (S.setpoint_spread_window_deg / g.width_deg[i0])
            .round()
            .max(1.0) as usize;
        let reach = reach.min((n - 1) / 2);
        let hot: Vec<usize> = (0..=2 * reach).map(|o| (i0 + n + o - reach) % n).collect();
        let in_hot = |i: usize| hot.contains(&i);
        // Slowest first, then nearest the worst azimuth (`hot` is
        // centred on it).
        let Some(&j) = hot
            .iter()
            .enumerate()
            .max_by(|(oa, &a), (ob, &b)| {
                dwell(a, k_of[a])
                    .total_cmp(&dwell(b, k_of[b]))
                    .then(oa.abs_diff(reach).cmp(&ob.abs_diff(reach)).reverse())
            })
            .map(|(_, j)| j)
        else {
            break;
        };
        let (a, dj) = (k_of[j], dwell(j, k_of[j]));
        let half = hot.len() / 2;
        let hot_sum: f64 = hot.iter().map(|&i| dwell(i, k_of[i])).sum();
        let near_sum = |q: usize| -> f64 {
            (0..=2 * half)
                .map(|o| (q + n + o - half) % n)
                .map(|i| dwell(i, k_of[i]))
                .sum()
        };
        let cost = |i: usize, k: usize| cert.lp.cost[col(i, k)];
        let pick = (0..n)
            .filter(|&q| !in_hot(q) && allowed[k_of[q]] > allowed[a])
            .filter(|&q| {
                let moved = dj - dwell(q, k_of[q]);
                near_sum(q) + moved < hot_sum - moved
            })
            .map(|q| {
                let b = k_of[q];
                (q, cost(j, a) + cost(q, b) - cost(j, b) - cost(q, a))
            })
            .min_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        let Some((q, _)) = pick else {
            break;
        };
        k_of.swap(j, q);
    }
    Ok(None)
}

/// The (uncertified) profile of powers `p` and `spins`.
fn build_profile(
    problem: &Problem,
    g: &Grid,
    gaze_deg: f64,
    p: &[f64],
    spins: &[(f64, f64)],
) -> Profile {
    let lid = &problem.lidar;
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
    Profile {
        format: PROFILE_FORMAT.to_owned(),
        frame_rate_hz: lid.frame_rate_hz,
        pulse_rate_hz: lid.pulse_rate_hz,
        average_power_w: lid.average_power_w,
        power_accounting: lid.power_accounting,
        gaze_deg: Some(wrap_deg(gaze_deg)),
        limits: lid.limits.clone(),
        bins,
        mode: Some(format!("optimized {}", problem.objective.mode.name())),
        summary: None,
        optimality: None,
    }
}

#[cfg(test)]
mod tests {
    use super::bit_reversed;

    /// The tie order is a total order (distinct keys) on every bin count,
    /// and on a power of two its first half is every other bin.
    #[test]
    fn bit_reversal_orders_ties_spread_out() {
        for n in 1..=1024usize {
            let mut keys: Vec<usize> = (0..n).map(|i| bit_reversed(i, n)).collect();
            keys.sort_unstable();
            keys.dedup();
            assert_eq!(keys.len(), n, "{n} bins");
        }
        for n in [2usize, 8, 256, 512] {
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by_key(|&i| bit_reversed(i, n));
            let mut first: Vec<usize> = order[..n / 2].to_vec();
            first.sort_unstable();
            assert_eq!(first, (0..n).step_by(2).collect::<Vec<_>>(), "{n} bins");
        }
    }
}
