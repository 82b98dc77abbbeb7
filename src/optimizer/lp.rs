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

use super::certificate::{Certified, LinearProgram};
use super::utility::{sqrt_segments, SqrtSegments};
use good_lp::solvers::highs::highs;
use good_lp::{
    constraint, variable, Expression, ProblemVariables, Solution, SolverModel, Variable,
};
use std::f64::consts::TAU;

use super::{OptError, Problem};
use crate::eye_safety::ael::{T2_S, TIME_BASE_S};
use crate::eye_safety::bound::{max_pulses_in, passes_in_window, Laser, PassFigures};
use crate::eye_safety::exposure;
use crate::model::angle::{next_index, wrap_deg, Arc, Binning, CircularSet};
use crate::model::lidar::PowerAccounting;
use crate::planner::Mode;
use crate::profile::{Bin, Profile, Region, PROFILE_FORMAT};

/// Relative margin kept from continuous bounds, budget and caps.
const MARGIN: f64 = 1e-6;
/// Relative slack on the budget row of a level (MILP) power step: a few
/// ulps of rounding in `Σ θ_i·level_i`, 1,000× inside the checker's
/// `REL_TOL` (1e-9).
const LEVEL_BUDGET_SLACK: f64 = 1e-12;
/// Tie-break added to the weights, growing with signed eccentricity: makes
/// the optimum unique where the acuity is symmetric about the gaze, and is
/// itself rotation-equivariant (a function of eccentricity only), so a
/// rotated problem has the rotated optimum.
const TIE_BREAK: f64 = 1e-3;
/// Trust region of the sequential LP for acceleration limits.
const TRUST: f64 = 0.3;
/// Share of the acceleration limit the linearised constraint may use.
const ACCEL_SHARE: f64 = 0.8;
/// Relative margin on eye-safety power caps (covers spin variation within a
/// bin once the continuous spin profile is rebuilt).
const CAP_MARGIN: f64 = 1e-3;
/// Relative margin below `K/f_p` for a dwell that holds at most `K` pulses
/// (well above the model's count margin, `bound::COUNT_MARGIN`).
const DWELL_COUNT_MARGIN: f64 = 1e-6;
/// Dwell-step iterations when the acceleration limit is finite.
const SLP_ROUNDS: usize = 5;

pub(super) struct Grid {
    pub(super) n: usize,
    pub(super) width_deg: Vec<f64>,
    pub(super) theta: Vec<f64>,
    start_deg: Vec<f64>,
    pub(super) weight: Vec<f64>,
    in_rof: Vec<bool>,
}

pub(super) fn grid(problem: &Problem, gaze_deg: f64) -> Result<Grid, OptError> {
    super::validate_bins(problem.bins, "bins")?;
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

/// Eye-safety windows for the LP: for every bin edge, the pass window
/// starting and ending there, as (bin, covered fraction) lists, with the
/// limits taken from the one eye-safety model ([`Laser`]): the LP's linear
/// constraints are that model's rules inverted at fixed counts, and the
/// solved profile is then fitted to the model's sound bound
/// (`fit_to_eye_safety_bound`) and certified by the checker.
struct Eye {
    windows: Vec<Vec<(usize, f64)>>,
    laser: Laser,
    frame_s: f64,
    /// Largest energy per pass the multi-pass rules (T2 train and time
    /// base) allow with every pass at that energy, J.
    pass_energy_max_j: f64,
}

fn eye(problem: &Problem, g: &Grid) -> Result<Option<Eye>, OptError> {
    let Some(params) = &problem.lidar.limits.eye_safety else {
        return Ok(None);
    };
    let laser =
        exposure::laser(params, problem.lidar.pulse_rate_hz).map_err(|e| OptError::Invalid {
            field: "limits.eye_safety".into(),
            reason: e.to_string(),
        })?;
    let pass_deg = exposure::pass_angle_deg(params, &laser);
    let frame_s = 1.0 / problem.lidar.frame_rate_hz;
    // Energy is linear in the pass energy, and no pass delivers more than
    // its energy whatever the power: the model's ratio at 1 J per pass with
    // an unbounded peak power inverts to the cap. The longest pass is the
    // pass arc at the slowest allowed spin.
    let slowest_pass_s = pass_deg.to_radians() / problem.lidar.limits.spin_rad_s_min;
    let pass = PassFigures {
        envelope_j: 1.0,
        pulses_j: 1.0,
        duration_s: if slowest_pass_s.is_finite() {
            slowest_pass_s.min(frame_s)
        } else {
            frame_s
        },
    };
    let (ratio_per_j, _) = laser.multi_pass_ratio(frame_s, pass, f64::MAX);
    let pass_energy_max_j = if ratio_per_j > 0.0 {
        1.0 / ratio_per_j
    } else {
        f64::INFINITY
    };
    let mut windows = Vec::with_capacity(2 * g.n);
    for &e in &g.start_deg {
        for start in [e, e - pass_deg] {
            let set = CircularSet::from_arcs([Arc {
                start_deg: wrap_deg(start),
                width_deg: pass_deg,
            }]);
            // Bins touched at an edge are in the window too (covered fraction
            // 0): their power counts for the single-pulse rule, as in the checker.
            let snap = crate::model::angle::EDGE_SNAP_DEG;
            let reach = CircularSet::from_arcs([Arc {
                start_deg: wrap_deg(start - snap),
                width_deg: (pass_deg + 2.0 * snap).min(360.0),
            }]);
            let w: Vec<(usize, f64)> = (0..g.n)
                .filter_map(|j| {
                    let lo = g.start_deg[j];
                    let touches = reach.overlap_deg(lo, lo + g.width_deg[j]) > 0.0;
                    let cover = set.overlap_deg(lo, lo + g.width_deg[j]) / g.width_deg[j];
                    touches.then_some((j, cover.clamp(0.0, 1.0)))
                })
                .collect();
            windows.push(w);
        }
    }
    Ok(Some(Eye {
        windows,
        laser,
        frame_s,
        pass_energy_max_j,
    }))
}

impl Eye {
    /// The model's single-pulse ratio per watt for a pass of dwell `t_w`:
    /// the most pulses such a pass holds, and the most passes meeting a
    /// T2 window ([`passes_in_window`]).
    fn single_ratio_per_w(&self, t_w: f64) -> f64 {
        let f_p = self.laser.pulse_rate_hz;
        self.laser.single_pulse_ratio(
            1.0 / f_p,
            max_pulses_in(t_w, f_p),
            passes_in_window(T2_S.min(TIME_BASE_S), t_w, self.frame_s),
        )
    }

    /// Per-bin power caps from the single-pulse rule at the given dwells, W.
    fn power_caps(&self, t: &[f64]) -> Vec<f64> {
        let mut cap = vec![f64::INFINITY; t.len()];
        for w in &self.windows {
            let t_w: f64 = w.iter().map(|&(j, f)| f * t[j]).sum();
            let allowed = (1.0 - CAP_MARGIN) / self.single_ratio_per_w(t_w);
            for &(j, _) in w {
                cap[j] = cap[j].min(allowed);
            }
        }
        cap
    }

    /// Largest window dwell at which the single-pulse rule holds for powers
    /// `p`, s: the most pulses per pass `K` the model allows at the window's
    /// highest power (the ratio grows with `K`: C5 falls and the T2 window
    /// meets more passes), found by bisection, as a dwell that cannot hold
    /// more than `K` pulses (`⌊t·f_p⌋ + 1 ≤ K` for `t < K/f_p`, less the
    /// model's count margin). Counts and passes are those
    /// [`Self::power_caps`] uses, so a dwell that met the caps meets this.
    fn window_dwell_max(&self, w: &[(usize, f64)], p: &[f64]) -> Result<f64, OptError> {
        let f_p = self.laser.pulse_rate_hz;
        let p_max = w.iter().map(|&(j, _)| p[j]).fold(0.0, f64::max);
        let dwell_of = |k: f64| k / f_p * (1.0 - DWELL_COUNT_MARGIN);
        let ratio = |k: f64| p_max * self.single_ratio_per_w(dwell_of(k));
        if ratio(1.0) > 1.0 {
            return Err(OptError::Infeasible(format!(
                "eye safety: {:.4e} W gives {:.3e} J per pulse, above the single-pulse limit at any spin",
                p_max,
                p_max / f_p,
            )));
        }
        let k_turn = max_pulses_in(self.frame_s, f_p);
        if ratio(k_turn) <= 1.0 {
            return Ok(f64::INFINITY);
        }
        let (mut lo, mut hi) = (1.0_f64, k_turn); // ratio(lo) ≤ 1 < ratio(hi)
        while hi - lo > 1.0 {
            let mid = ((lo + hi) / 2.0).floor();
            if ratio(mid) <= 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(dwell_of(lo))
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
        // The most lenient single-pulse cap: the fastest spin everywhere.
        let t_fast: Vec<f64> = vec![TAU / l.spin_rad_s_max / problem.bins as f64; problem.bins];
        let cap = e
            .power_caps(&t_fast)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        if cap < l.power_w_min {
            let wl = l.eye_safety.as_ref().map_or(0.0, |p| p.wavelength_nm);
            return Err(OptError::Infeasible(format!(
                "eye-safety cap {cap:.4e} W at {wl} nm (even at spin_rad_s_max) is below power_w_min {:.4e} W",
                l.power_w_min
            )));
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

/// HiGHS pinned for determinism (one thread, fixed seed), MILPs solved to
/// optimality (zero gap) so equal problems give equal answers.
fn configured(
    model: good_lp::solvers::highs::HighsProblem,
    cons: Vec<good_lp::Constraint>,
) -> good_lp::solvers::highs::HighsProblem {
    let mut m = model
        .set_threads(1)
        .set_option("random_seed", 0)
        .set_option("mip_rel_gap", 0.0)
        .set_option("mip_abs_gap", 1e-12);
    for c in cons {
        m = m.with(c);
    }
    m
}

fn solve_model<M: SolverModel<Error = good_lp::ResolutionError>>(
    model: M,
    what: &str,
) -> Result<M::Solution, OptError> {
    model.solve().map_err(|e| match e {
        good_lp::ResolutionError::Infeasible => OptError::Infeasible(format!(
            "the {what} step has no solution within the limits (power_w_min/max, the budget, spin limits, slew, acceleration and eye safety together)"
        )),
        other => OptError::Solver(format!("{what} step: {other}")),
    })
}

/// Solves the dwell step's program; with set-points (a MILP: the
/// binaries in `groups`) its LP relaxation first, whose optimum, when
/// integral, is the MILP's (the relaxation bounds it and contains this
/// point), so HiGHS's branch and bound runs only when it is not.
fn solve_relaxation_first(
    vars: ProblemVariables,
    objective: Expression,
    cons: Vec<good_lp::Constraint>,
    groups: &[Vec<(f64, Variable)>],
) -> Result<good_lp::solvers::highs::HighsSolution, OptError> {
    if !groups.is_empty() {
        let relaxed = configured(
            vars.clone().maximise(objective.clone()).using(highs),
            cons.clone(),
        )
        .set_option("solve_relaxation", true)
        .set_option("presolve", "off");
        let sol = solve_model(relaxed, "dwell")?;
        let integral = groups.iter().flatten().all(|&(_, y)| {
            let v = sol.value(y);
            (v - v.round()).abs() <= super::certificate::RELAXATION_INTEGRALITY_TOL
        });
        if integral {
            return Ok(sol);
        }
    }
    solve_model(
        configured(vars.maximise(objective).using(highs), cons),
        "dwell",
    )
}

/// The level a solved one-hot group of binaries picked.
fn chosen(sol: &impl Solution, group: &[(f64, Variable)]) -> f64 {
    group
        .iter()
        .max_by(|a, b| sol.value(a.1).total_cmp(&sol.value(b.1)))
        .map_or(0.0, |&(level, _)| level)
}

/// Power step: dwell `t` fixed.
fn power_step(
    problem: &Problem,
    g: &Grid,
    eye: Option<&Eye>,
    t: &[f64],
) -> Result<(Vec<f64>, PowerLp), OptError> {
    let lid = &problem.lidar;
    let l = &lid.limits;
    let p_mean = lid.average_power_w;
    let period: f64 = t.iter().sum();
    let caps = eye.map_or_else(|| vec![f64::INFINITY; g.n], |e| e.power_caps(t));
    let lam = problem.objective.range_weight;
    let levels = &problem.levels.power_w;
    let mut lp = LinearProgram::default();
    // x_i = p_i / P̄ as a linear form (a continuous column or Σ levels·z).
    let mut x: Vec<Vec<(usize, f64)>> = Vec::with_capacity(g.n);
    let mut bins: Vec<PowerBin> = Vec::with_capacity(g.n);
    let mut utility_constant = 0.0;
    for i in 0..g.n {
        let hi = l.power_w_max.min(caps[i]);
        if levels.is_empty() {
            let lo_x = l.power_w_min / p_mean;
            let hi_x = (hi / p_mean * (1.0 - MARGIN)).max(lo_x);
            let xi = lp.add_col(lo_x, hi_x, 0.0, false);
            // The utility as boxed segment columns (see `utility`).
            let c = lam * g.theta[i] * g.weight[i];
            let shape = sqrt_segments(lo_x, hi_x);
            let deltas = shape.add_to(&mut lp, xi, lo_x, c);
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
                    "no power level lies within [power_w_min, min(power_w_max, eye-safety cap)] = [{:.4e}, {:.4e}] W in bin {i}",
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
    lp.add_row(&spend, f64::NEG_INFINITY, budget);
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
    // Eye safety: energy per pass (T2 and time base).
    if let Some(e) = eye {
        for w in &e.windows {
            let mut en = Vec::new();
            for &(j, f) in w {
                scaled(f * t[j] * p_mean, &x[j], &mut en);
            }
            lp.add_row(&en, f64::NEG_INFINITY, e.pass_energy_max_j * (1.0 - MARGIN));
        }
    }
    let solved = lp.solve("power")?;
    let eval = |form: &[(usize, f64)]| form.iter().map(|&(j, a)| a * solved.x[j]).sum::<f64>();
    let mut p: Vec<f64> = bins
        .iter()
        .zip(&x)
        .map(|(b, form)| match b {
            PowerBin::Continuous { .. } => eval(form) * p_mean,
            PowerBin::Levels(zs) => zs
                .iter()
                .max_by(|a, b| solved.x[a.1].total_cmp(&solved.x[b.1]))
                .map_or(0.0, |&(level, _)| level),
        })
        .collect();
    if levels.is_empty() {
        for (i, pi) in p.iter_mut().enumerate() {
            *pi = pi.clamp(l.power_w_min, l.power_w_max.min(caps[i]));
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
    }
    Ok((
        p,
        PowerLp {
            lp,
            bins,
            one,
            p_mean,
            floor_w: l.power_w_min,
            y: solved.y,
            solver_dual_bound: solved.solver_dual_bound,
        },
    ))
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
            match Certified::new(self.lp.clone(), v, self.y.clone(), self.solver_dual_bound) {
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

/// Dwell step: power `p` fixed; `current` is the iterate for linearisation.
fn dwell_step(
    problem: &Problem,
    g: &Grid,
    eye: Option<&Eye>,
    p: &[f64],
    current: &[f64],
) -> Result<Vec<f64>, OptError> {
    let lid = &problem.lidar;
    let l = &lid.limits;
    let period = 1.0 / lid.frame_rate_hz;
    let unit = period / g.n as f64; // τ = t / unit
    let w_mean = lid.mean_spin_rad_s();
    let lam = problem.objective.resolution_weight;
    let setpoints = &problem.levels.spin_rad_s;
    let mut vars = ProblemVariables::new();
    let mut objective = Expression::from(0.0);
    let mut cons = Vec::new();
    let mut tau: Vec<Expression> = Vec::with_capacity(g.n);
    let mut sp_vars: Vec<Vec<(f64, Variable)>> = Vec::new();
    for i in 0..g.n {
        let th = g.theta[i];
        if setpoints.is_empty() {
            let lo = th / l.spin_rad_s_max / unit * (1.0 + MARGIN);
            let hi = if l.spin_rad_s_min > 0.0 {
                th / l.spin_rad_s_min / unit * (1.0 - MARGIN)
            } else {
                1e9
            };
            let (mut lo, mut hi) = (lo, hi.max(lo));
            if l.spin_accel_rad_s2_max.is_some() {
                lo = lo.max(current[i] / unit * (1.0 - TRUST));
                hi = hi.min(current[i] / unit * (1.0 + TRUST)).max(lo);
            }
            let t0 = (current[i] / unit).max(lo).min(hi);
            let ti = vars.add(variable().min(lo).max(hi).initial(t0));
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
            // The utility as boxed segment columns, Σ δ ≤ r − r_lo (see
            // `utility`; its constant does not move the optimum).
            let c = lam * th * g.weight[i];
            let mut fill = Expression::from(0.0);
            let shape = sqrt_segments(r_lo, r_hi);
            let f0 = shape.fill(r_lo, k * t0);
            for (&(a, len), &d0) in shape.segments.iter().zip(&f0) {
                let d = vars.add(variable().min(0.0).max(len).initial(d0));
                objective.add_mul(c * a, d);
                fill.add_mul(1.0, d);
            }
            cons.push(constraint!(fill <= k * ti - r_lo));
            tau.push(Expression::from(ti));
        } else {
            let allowed: Vec<f64> = setpoints
                .iter()
                .copied()
                .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max)
                .collect();
            if allowed.is_empty() {
                return Err(OptError::Infeasible(
                    "no spin set-point lies within [spin_rad_s_min, spin_rad_s_max]".into(),
                ));
            }
            let ys: Vec<(f64, Variable)> = allowed
                .iter()
                .map(|&w| (w, vars.add(variable().binary())))
                .collect();
            let mut te = Expression::from(0.0);
            let mut one = Expression::from(0.0);
            for &(w, y) in &ys {
                te.add_mul(th / w / unit, y);
                one.add_mul(1.0, y);
                objective.add_mul(lam * th * g.weight[i] * (w_mean / w).sqrt(), y);
            }
            cons.push(constraint!(one == 1.0));
            tau.push(te);
            sp_vars.push(ys);
        }
    }
    let mut frame = Expression::from(0.0);
    for te in &tau {
        frame += te.clone();
    }
    cons.push(constraint!(frame == g.n as f64));
    if lid.power_accounting == PowerAccounting::Time {
        let mut spend = Expression::from(0.0);
        for i in 0..g.n {
            spend += (p[i] / lid.average_power_w) * tau[i].clone();
        }
        // No margin here: with uniform P̄ the budget is exactly tight. The
        // power step that ends every joint solve trims the budget exactly.
        cons.push(constraint!(spend <= g.n as f64));
    }
    if let Some(a_max) = l.spin_accel_rad_s2_max {
        for i in 0..g.n {
            let j = next_index(i, g.n);
            let w_cur = (g.theta[i] / current[i]).max(g.theta[j] / current[j]);
            let dtheta = 0.5 * (g.theta[i] + g.theta[j]);
            let ds = ACCEL_SHARE * a_max * dtheta * (1.0 - TRUST).powi(3) / w_cur.powi(3);
            // s = t/θ = τ·unit/θ.
            let (ki, kj) = (unit / g.theta[i], unit / g.theta[j]);
            cons.push(constraint!(kj * tau[j].clone() - ki * tau[i].clone() <= ds));
            cons.push(constraint!(ki * tau[i].clone() - kj * tau[j].clone() <= ds));
        }
    }
    if let Some(e) = eye {
        for w in &e.windows {
            let t_max = e.window_dwell_max(w, p)?;
            let mut dwell = Expression::from(0.0);
            let mut en = Expression::from(0.0);
            for &(j, f) in w {
                dwell += (f * unit) * tau[j].clone();
                en += (f * unit * p[j]) * tau[j].clone();
            }
            if t_max.is_finite() {
                cons.push(constraint!(dwell <= t_max * (1.0 - MARGIN)));
            }
            cons.push(constraint!(en <= e.pass_energy_max_j * (1.0 - MARGIN)));
        }
    }
    let sol = solve_relaxation_first(vars, objective, cons, &sp_vars)?;
    let mut t: Vec<f64> = if setpoints.is_empty() {
        tau.iter().map(|te| sol.eval(te) * unit).collect()
    } else {
        sp_vars
            .iter()
            .zip(&g.theta)
            .map(|(ys, th)| th / chosen(&sol, ys))
            .collect()
    };
    if setpoints.is_empty() {
        // Exact frame period.
        let s: f64 = t.iter().sum();
        for ti in &mut t {
            *ti *= period / s;
        }
    }
    Ok(t)
}

/// Solves and builds the (uncertified) profile, with the final power
/// step's program (none when the power does not move).
pub(super) fn solve(
    problem: &Problem,
    gaze_deg: f64,
) -> Result<(Profile, Option<PowerLp>), OptError> {
    let g = grid(problem, gaze_deg)?;
    let lid = &problem.lidar;
    let eye = eye(problem, &g)?;
    prechecks(problem, eye.as_ref())?;
    let w_mean = lid.mean_spin_rad_s();
    let mut t: Vec<f64> = g.theta.iter().map(|th| th / w_mean).collect();
    let p_start = lid
        .average_power_w
        .clamp(lid.limits.power_w_min, lid.limits.power_w_max);
    let mut p: Vec<f64> = vec![p_start; g.n];
    let mode = problem.objective.mode;
    let mut last: Option<PowerLp> = None;
    let smooth_spin = lid.limits.spin_accel_rad_s2_max.is_some();
    let spin_rounds = if smooth_spin { SLP_ROUNDS } else { 1 };
    match mode {
        Mode::Baseline => {}
        Mode::Range => {
            let (pp, plp) = power_step(problem, &g, eye.as_ref(), &t)?;
            p = pp;
            last = Some(plp);
        }
        Mode::Resolution => {
            for _ in 0..spin_rounds {
                t = dwell_step(problem, &g, eye.as_ref(), &p, &t)?;
            }
        }
        Mode::Joint => {
            for _ in 0..spin_rounds.max(2) {
                let next = dwell_step(problem, &g, eye.as_ref(), &p, &t)?;
                if last.is_some() && next == t {
                    // A fixed point: both steps are deterministic functions
                    // of (p, t), so every further round repeats this one.
                    break;
                }
                t = next;
                let (pp, plp) = power_step(problem, &g, eye.as_ref(), &t)?;
                p = pp;
                last = Some(plp);
            }
        }
    }
    // Spin: steps when unlimited, else continuous node spins rescaled to the period.
    let spins: Vec<(f64, f64)> = if smooth_spin && mode.controls_resolution() {
        let s: Vec<f64> = t.iter().zip(&g.theta).map(|(t, th)| t / th).collect();
        let node: Vec<f64> = (0..g.n)
            .map(|i| 2.0 / (s[(i + g.n - 1) % g.n] + s[i]))
            .collect();
        let dwell: f64 = (0..g.n)
            .map(|i| 2.0 * g.theta[i] / (node[i] + node[next_index(i, g.n)]))
            .sum();
        let c = dwell * lid.frame_rate_hz;
        let spins: Vec<(f64, f64)> = (0..g.n)
            .map(|i| (node[i] * c, node[next_index(i, g.n)] * c))
            .collect();
        if mode.controls_range() {
            // Final power step on the exact dwell of the rebuilt spin.
            let exact: Vec<f64> = spins
                .iter()
                .zip(&g.theta)
                .map(|(w, th)| 2.0 * th / (w.0 + w.1))
                .collect();
            let (pp, plp) = power_step(problem, &g, eye.as_ref(), &exact)?;
            p = pp;
            last = Some(plp);
        }
        spins
    } else {
        t.iter()
            .zip(&g.theta)
            .map(|(t, th)| (th / t, th / t))
            .collect()
    };
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
    Ok((profile, last))
}
