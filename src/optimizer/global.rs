//! A global upper bound of the joint problem.
//!
//! Block-coordinate ascent stops at a stationary point of a bilinear
//! problem. This module bounds the true optimum from above with one LP, a
//! *relaxation*: every profile the checker accepts **for this problem as
//! the optimizer poses it** — on its grid of `N` equal bins, with its
//! hardware power levels and spin set-points (where it has them) and with
//! the block its mode does not move at its start value — is feasible for
//! it, and its objective is at least the model's. (The checker alone knows
//! none of the grid, the levels or the mode: a profile off them is another
//! problem's, `tests/it/optimizer/global_adversarial.rs`; [`model_objective`] refuses
//! another grid.)
//!
//! Model objective (the one the steps approximate from below with chords):
//! `J = λ_R Σ θ_i w_i √x_i + λ_ρ Σ θ_i w_i √r_i`, `x_i = p_i/P̄`, density
//! ratio `r_i = t_i·2π/(θ_i T)`. With `τ_i = t_i N/T`:
//! - `√` is concave, so every tangent lies above it; the minimum of the
//!   tangents over-estimates each utility. It enters the LP as segments
//!   (boxed columns, one fill row per utility, [`tangent_segments`]: the
//!   breakpoints at or after the tangents' intersections, so the segments
//!   stay above every tangent they follow) rather than one row per
//!   tangent: 3× fewer rows; with HiGHS's presolve off the LP solves ≈10×
//!   faster on `smooth` (measured; the bound moves by < 1e-12 relative);
//! - `x_i` lies in `[min, max]` of the allowed powers (levels or limits),
//!   `τ_i` in the spin limits' (set-points') box; a block the mode does not
//!   move is fixed at its start value; boxes from limits (not levels, which
//!   are exact) widened by the checker's tolerance;
//! - under a finite acceleration limit the spin box is the one the limit
//!   and the frame leave ([`accel_spin_box`]), below; it bounds `τ`, the
//!   McCormick rows and the Rule 1 cap's fastest spin;
//! - frame `Σ τ_i = N`; budget `Σ θ_i x_i ≤ 2π` (angle) or, under time
//!   accounting, `Σ τ_i x_i ≤ N`, bilinear: each product `w_i = τ_i x_i` is
//!   replaced by its McCormick under-estimators
//!   `w_i ≥ τ_lo x_i + x_lo τ_i − τ_lo x_lo`, `w_i ≥ τ_hi x_i + x_hi τ_i − τ_hi x_hi`
//!   (valid on the box), with `Σ w_i ≤ N`;
//! - slew `|x_j − x_i| ≤ s (Δ_i+Δ_j)/2 / P̄`;
//! - every row is widened by the checker's relative tolerance (1e-9), so
//!   whatever the checker accepts is inside;
//! - **dropped** (a relaxation may drop rows): eye safety beyond the Rule 1
//!   cap, and the acceleration limit beyond the spin box. Where they bind,
//!   the gap includes their price.
//!
//! **The acceleration box.** Assumptions (profile@1 and the core checker):
//! within a bin the acceleration is constant, so `ω²` is linear in the
//! angle between the bin's start and end spins; the checker accepts
//! `|ω_e² − ω_s²|/(2θ) ≤ a(1 + 1e-9)` (evaluated in floats: a few ε of
//! `ω_max²` more), adjacent bins meeting within `1e-9·max(ω, 1)` (so
//! `|Δω²| ≤ 2.2e-9·ω_max²` at an edge), every start and end spin in the
//! limits widened by 1e-9, and `Σ t` within 1e-9 of `T` (its float sum
//! inside 1.2e-9 for `N ≤ 10⁶`). Then if `ω² = W` somewhere, at angular
//! distance `d` along the circle `ω² ≥ W − 2a''d − J` with
//! `a'' = a(1 + 1.1e-9)` and `J = N(2.2e-9 + 8ε)ω_max²` (every edge and
//! rounding on the way), and `ω ≥ ω_min` (the floor, at the ends and so
//! in between). The frame's time `∫dθ/ω ≥ T(1 − 1.2e-9)` therefore needs
//! `F(W − J) ≥ T(1 − 1.2e-9)` with `F(W) = 2∫₀^π dθ/√max(W − 2a''θ, ω_min²)`
//! (closed form, decreasing in `W`); symmetrically the smallest `ω² = w`
//! needs `G(w + J) ≤ T(1 + 1.2e-9)` with
//! `G(w) = 2∫₀^π dθ/√min(w + 2a''θ, ω_max²)`. A bisection finds each
//! threshold, comparing the computed time with `T` moved by a relative
//! 1e-10 (far above the closed forms' rounding), so the point returned is
//! proven on the far side; four passes, each from the previous box (the
//! slack `J` and the clipping then use the tighter spins). The box is tight
//! up to `J` and the frame's tolerance: the triangle `ω² = W − 2a·d` is a
//! profile of ramps that meets it (tested against its closed form,
//! `ω_max,min = (2aπ/q ± q)/2`, `q = aT/2`). On `smooth` it is
//! `[113.16, 138.16]` rad/s against the limits' `[90, 200]`.
//!
//! **Coupled Lagrangian** (time accounting with both blocks moving: the
//! bilinear budget). McCormick's rows are the convex hull of one product
//! on its box, but with the concave utilities kept at the point's own
//! `(x, τ)` the LP may sit inside the hull and keep the full utility. So
//! the bound is also computed by weak duality over the frame, budget and
//! slew rows with the **exact** product and exact `√` per bin
//! ([`coupled_lagrangian`]): for multipliers `ν` (frame, either sign),
//! `μ ≥ 0` (budget), `y_r` (slew), every point meeting those rows has
//! `J ≤ Σ_r max(y_r lo_r, y_r hi_r) + Σ_i max_box(J_i − μτ_i x_i − ντ_i − σ_i x_i)`
//! (`σ_i` the slew multipliers on `x_i`). Each bin's maximum is bounded on
//! slices of its τ box (on a slice `μτx ≥ μ·τ_start·x` for `x ≥ 0`, leaving
//! two concave one-dimensional maxima in closed form). Multipliers: the
//! LP's duals, then one golden-section pass on `μ` and `ν` (any values are
//! valid; the function is convex in them). Floating point, raised by a
//! relative `1e-12 + 2·(terms)·ε` of the terms' magnitudes (as
//! `lagrangian_bound`). The answer is the smaller of this and the LP's
//! certified bound, both valid.
//!
//! (Separable problems skip the LP: see `lagrangian_bound`.) The LP's own bound is certified exactly ([`super::certificate::check`]),
//! so `upper_bound` is proven for the relaxation, hence for the problem.
//! `objective` is `J` of the profile handed out, evaluated in floating
//! point and lowered by a relative 1e-12 (a few ulps per term cover it);
//! the bound is raised by the same (the rows' constants are floats too;
//! tangent slopes are rounded up, so each row stays above its tangent).

use std::f64::consts::TAU;

mod detection_bound;
mod detection_certificate;

pub use detection_certificate::{
    ClassCertificate, DetectionCertificate, DetectionCertificateError, EnvelopePoint,
    TableCertificate,
};

use super::certificate::{check, next_down, to_f64_up};
use super::lp::{grid, Grid};
use super::program::Program;
use super::settings::S;
use super::{OptError, Problem};
use crate::model::angle::next_index;
use crate::model::lidar::PowerAccounting;
use crate::profile::{GlobalOptimality, Profile};
use good_lp::{Expression, Variable};

/// Tangent rows `u ≤ √a + (k·v − a)/(2√a)` of `√(k·v)` for `v ∈ [lo, hi]`,
/// as (slope in v, intercept) pairs; points spread evenly in `√`.
fn tangents(k: f64, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    let (a, b) = ((k * lo).max(0.0).sqrt(), (k * hi).max(0.0).sqrt());
    (0..=S.global_tangents)
        .filter_map(|j| {
            let s = a + (b - a) * j as f64 / S.global_tangents as f64;
            // Slope rounded up (v ≥ 0): the line stays above the tangent.
            (s > 0.0).then(|| (-next_down(-(k / (2.0 * s))), s / 2.0))
        })
        .collect()
}

/// The lower envelope of the [`tangents`] lines (each above `√(k·v)` for
/// `v ≥ 0`) on `[lo, hi]` as segments: `(g0, [(slope, length)])` with
/// `g(v) = g0 + Σ_j slope_j·clip_j(v − lo)` (segments filled in order).
/// Sound by construction, whatever the rounding: `g0 ≥ L_0(lo)`; segment
/// `j` follows line `L_j` from its start `E_j` (where `g(E_j) ≥ L_j(E_j)`),
/// so `g ≥ L_j ≥ √` on it; the next segment starts at or after the
/// intersection of `L_j` and `L_{j+1}`, where `L_j ≥ L_{j+1}` (smaller
/// slope after), so `g(E_{j+1}) ≥ L_{j+1}(E_{j+1})`; the lengths sum to at
/// least `hi − lo`. Each intersection `(b₁ − b₀)/(a₀ − a₁)` of two exact
/// doubles' lines is computed with three correctly rounded operations
/// (relative error ≤ 3ε) and moved later by a relative 1e-12; each length
/// is rounded up, so the exact partial sums of the lengths (what the
/// program adds up) reach every computed start. Lines whose slope does not
/// fall are dropped (fewer lines: a higher minimum, still above `√`).
fn tangent_segments(k: f64, lo: f64, hi: f64) -> (f64, Vec<(f64, f64)>) {
    let up = |v: f64| -next_down(-v);
    let later = |v: f64| up(v + v.abs() * 1e-12);
    let mut lines: Vec<(f64, f64)> = Vec::new();
    for (a, b) in tangents(k, lo, hi) {
        if lines.last().is_none_or(|&(a0, _)| a < a0) {
            lines.push((a, b));
        }
    }
    let Some(&(a0, b0)) = lines.first() else {
        return (up(up((k * hi).max(0.0).sqrt())), Vec::new());
    };
    let g0 = later(b0 + a0 * lo);
    let mut start = lo;
    let mut segments = Vec::with_capacity(lines.len());
    for (j, &(a, b)) in lines.iter().enumerate() {
        let end = match lines.get(j + 1) {
            Some(&(a1, b1)) => later((b1 - b) / (a - a1)).max(start),
            None => hi,
        };
        if end >= hi || j + 1 == lines.len() {
            segments.push((a, up(hi - start).max(0.0)));
            break;
        }
        segments.push((a, up(end - start)));
        start = end;
    }
    (g0, segments)
}

/// Adds `√(k·v)`'s over-estimator on column `v ∈ [lo, hi]` with weight
/// `c ≥ 0`: segment columns (cost `c·slope` rounded up) and the row
/// `Σ δ − v ≤ −lo`; returns `c·g0` (rounded up), the caller's constant.
fn add_concave_bound(lp: &mut Program, v: Variable, k: f64, lo: f64, hi: f64, c: f64) -> f64 {
    let up = |x: f64| -next_down(-x);
    let (g0, segments) = tangent_segments(k, lo, hi);
    let deltas: Vec<Variable> = segments
        .iter()
        .map(|&(a, len)| lp.column(0.0, len, up(c * a), false))
        .collect();
    if !deltas.is_empty() {
        let mut row: Expression = deltas.into_iter().sum();
        row.add_mul(-1.0, v);
        lp.at_most("utility", row, -lo);
    }
    up(c * g0)
}

/// One separable term `c·√(s·v)` with `v ∈ [lo, hi]` and weight `a` in
/// its single row.
struct Term {
    c: f64,
    s: f64,
    a: f64,
    lo: f64,
    hi: f64,
}

impl Term {
    /// The maximiser of `c√(s v) − m·a·v` over the box.
    fn argmax(&self, m: f64) -> f64 {
        if m <= 0.0 || self.c <= 0.0 {
            return if m <= 0.0 { self.hi } else { self.lo };
        }
        let v = (self.c * self.s.sqrt() / (2.0 * m * self.a)).powi(2);
        v.clamp(self.lo, self.hi)
    }
}

/// Weak duality for `max Σ c_i√(s_i v_i)` s.t. `Σ a_i v_i ≤ b`, boxes
/// (`a_i > 0`): for every `m ≥ 0`, the optimum is at most
/// `m·b + Σ_i max_{v∈box} (c_i√(s_i v) − m a_i v)`. `m` is found by
/// bisection (any `m` is valid; this one makes it tight: the problem is
/// concave, so the bound meets the optimum); each inner maximum is taken at
/// its (clamped) stationary point, and the sum is raised by a relative 1e-12
/// of its terms' magnitudes (float evaluation; the maximiser's own rounding
/// costs second order). `None` if the row cannot be met at the boxes' floor.
fn lagrangian_bound(terms: &[Term], b: f64) -> Option<f64> {
    let used = |m: f64| terms.iter().map(|t| t.a * t.argmax(m)).sum::<f64>();
    if terms.iter().map(|t| t.a * t.lo).sum::<f64>() > b {
        return None;
    }
    let m = if used(0.0) <= b {
        0.0
    } else {
        let mut hi = 1.0;
        let mut k = 0;
        while used(hi) > b && k < 2000 {
            hi *= 2.0;
            k += 1;
        }
        let mut lo = 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if used(mid) > b {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    };
    let mut total = m * b;
    let mut magnitude = total.abs();
    for t in terms {
        let v = t.argmax(m);
        let gain = t.c * (t.s * v).sqrt();
        let cost = m * t.a * v;
        total += gain - cost;
        magnitude += gain.abs() + cost.abs();
    }
    total.is_finite().then_some(total + 1e-12 * magnitude)
}

/// Bisection between `a`, where `keep(a)` holds, and `b`, where it is
/// expected not to (either order): returns the last `b`, a point where
/// `keep` failed unless `b` never moved (callers check it again).
fn bisect(a: f64, b: f64, keep: impl Fn(f64) -> bool) -> f64 {
    let (mut a, mut b) = (a, b);
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if mid == a || mid == b {
            break;
        }
        if keep(mid) {
            a = mid;
        } else {
            b = mid;
        }
    }
    b
}

/// The spin box `[ω_lo, ω_hi]` every start and end spin of a profile the
/// checker accepts lies in, given the acceleration limit `a` and the frame
/// (module docs, "acceleration"): `lo`/`hi` are the limits' box (already
/// widened), `n` the bins. Returns `(lo, hi)` unchanged where no bound is
/// tighter.
fn accel_spin_box(a: f64, period: f64, n: usize, lo: f64, hi: f64) -> (f64, f64) {
    // Each pass starts from the previous box (valid for every accepted
    // profile), so its jump slack and clipping use the tighter spins.
    let mut b = (lo, hi);
    for _ in 0..4 {
        b = accel_spin_box_once(a, period, n, b.0, b.1);
    }
    b
}

/// One pass of [`accel_spin_box`].
fn accel_spin_box_once(a: f64, period: f64, n: usize, lo: f64, hi: f64) -> (f64, f64) {
    use std::f64::consts::PI;
    // ω² changes by at most 2a''·(angle) plus J over the circle (jumps at
    // edges within the checker's tolerance, and its float rounding).
    let a2 = a * (1.0 + 1.1e-9);
    let j_all = n as f64 * (2.2e-9 + 8.0 * f64::EPSILON) * hi.max(1.0).powi(2);
    // The frame the checker accepts: Σ t within REL_TOL of T, the float
    // sum's rounding (n·ε ≤ 1.1e-10 for n ≤ 10⁶) inside 1.2e-9.
    let t_lo = period * (1.0 - 1.2e-9);
    let t_hi = period * (1.0 + 1.2e-9);
    if a2 <= 0.0 || !(lo >= 0.0 && hi > lo) {
        return (lo, hi);
    }
    // Slowest profile with ω² = W at some point: ω(d)² ≥ max(W − 2a''d, f²),
    // its time 2∫₀^π dθ/ω, decreasing in W; F written without cancellation.
    let f = lo;
    let time_slowest = |w: f64| -> f64 {
        if w <= f * f {
            return TAU / f;
        }
        let c = (w - f * f) / (2.0 * a2);
        if c >= PI {
            2.0 * TAU / (w.sqrt() + (w - 2.0 * a2 * PI).max(0.0).sqrt())
        } else {
            4.0 * c / (w.sqrt() + f) + 2.0 * (PI - c) / f
        }
    };
    // Fastest profile with ω² = w at some point: ω(d)² ≤ min(w + 2a''d, c²).
    let top = hi;
    let time_fastest = |w: f64| -> f64 {
        if w >= top * top {
            return TAU / top;
        }
        let c = (top * top - w) / (2.0 * a2);
        if c >= PI {
            2.0 * TAU / ((w + 2.0 * a2 * PI).sqrt() + w.max(0.0).sqrt())
        } else {
            4.0 * c / (top + w.max(0.0).sqrt()) + 2.0 * (PI - c) / top
        }
    };
    // Every feasible W − J has true time ≥ t_lo, so computed time ≥
    // t_lo(1 − 1e-13); the bisection's `hi` end has computed time below
    // t_lo(1 − 1e-10), so the true time there is below t_lo: every W − J
    // at or above it is infeasible.
    let w_cap = bisect(0.0, top * top, |w| time_slowest(w) > t_lo * (1.0 - 1e-10));
    let new_hi = if time_slowest(w_cap) <= t_lo * (1.0 - 1e-10) {
        ((w_cap + j_all) * (1.0 + 1e-12)).sqrt() * (1.0 + 4.0 * f64::EPSILON)
    } else {
        hi
    };
    // Symmetric: feasible w + J has true time ≤ t_hi; the bisection's
    // `lo` end has computed time above t_hi(1 + 1e-10), so every w + J at
    // or below it is infeasible.
    let w_floor = bisect(top * top, 0.0, |w| time_fastest(w) < t_hi * (1.0 + 1e-10));
    let new_lo = if time_fastest(w_floor) >= t_hi * (1.0 + 1e-10) {
        ((w_floor - j_all) * (1.0 - 1e-12)).max(0.0).sqrt() * (1.0 - 4.0 * f64::EPSILON)
    } else {
        lo
    };
    let (l2, h2) = (new_lo.max(lo), new_hi.min(hi));
    if l2 <= h2 {
        (l2, h2)
    } else {
        (lo, hi)
    }
}

/// The model objective `J` of a profile (floating point).
fn objective_of(problem: &Problem, g: &Grid, profile: &Profile) -> f64 {
    let o = &problem.objective;
    profile
        .bins
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let (range, res) = super::utilities(problem, g.theta[i], b);
            let range = if o.kind == super::ObjectiveKind::Detection {
                let dwell = crate::profile::kinematics::BinMotion::dwell_s(b);
                let x = b.power_w / problem.lidar.average_power_w;
                super::detection::exact_range_utility(problem, g.theta[i], dwell, x)
            } else {
                range
            };
            g.theta[i] * g.weight[i] * (o.range_weight * range + o.resolution_weight * res)
        })
        .sum()
}

/// The global figures for `profile` (the optimizer's answer for `gaze_deg`)
/// against `upper_bound`, the problem's [`upper_bound`] (which does not
/// depend on the profile, so the caller may compute it alongside the solve).
pub(super) fn bound(
    problem: &Problem,
    gaze_deg: f64,
    profile: &Profile,
    upper_bound: f64,
) -> Result<GlobalOptimality, OptError> {
    let j = model_objective(problem, gaze_deg, profile)?;
    let objective = j - S.objective_margin * j.abs();
    Ok(GlobalOptimality {
        objective,
        upper_bound,
        gap: upper_bound - objective,
    })
}

/// The model objective `J` of a profile on this problem's bins (floating
/// point, not lowered).
pub fn model_objective(
    problem: &Problem,
    gaze_deg: f64,
    profile: &Profile,
) -> Result<f64, OptError> {
    let g = grid(problem, gaze_deg)?;
    if profile.bins.len() != g.n {
        return Err(OptError::Invalid {
            field: "bins".into(),
            reason: format!("{} bins, the problem has {}", profile.bins.len(), g.n),
        });
    }
    // The bound is over the problem's own grid (narrower bins
    // elsewhere can score above it); a profile on another grid is refused.
    for (i, b) in profile.bins.iter().enumerate() {
        if (b.start_deg - g.start_deg[i]).abs() > 1e-9
            || (b.width_deg - g.width_deg[i]).abs() > 1e-9
        {
            return Err(OptError::Invalid {
                field: format!("bins[{i}]"),
                reason: format!(
                    "[{}, +{}]° is not the problem's bin [{}, +{}]°",
                    b.start_deg, b.width_deg, g.start_deg[i], g.width_deg[i]
                ),
            });
        }
    }
    Ok(objective_of(problem, &g, profile))
}

/// A proven upper bound (rounded up) of `J` over every profile of this
/// problem (its grid, levels and mode; see the module docs) the checker
/// accepts, from the relaxation in the module docs. Named steps: the
/// boxes (`boxes`), the separable Lagrangian where it applies
/// (`separable_bound`), the relaxation's LP (`relaxation`: utilities, then
/// `frame`, `budget`, `slew`), its exact dual bound, and for the coupled
/// case the Lagrangian of `coupled_bound`.
pub fn upper_bound(problem: &Problem, gaze_deg: f64) -> Result<f64, OptError> {
    let g = grid(problem, gaze_deg)?;
    let b = boxes(problem, &g)?;
    if problem.objective.kind == super::ObjectiveKind::Detection {
        return detection_bound::bound(problem, &g, &b).ok_or_else(|| {
            OptError::Solver("global bound: the detection Lagrangian has no finite value".into())
        });
    }
    let mode = problem.objective.mode;
    let slew_moves =
        mode.controls_range() && problem.lidar.limits.power_slew_w_per_deg_max.is_some();
    let coupled = problem.lidar.power_accounting == PowerAccounting::Time
        && mode.controls_range()
        && mode.controls_resolution();
    if !slew_moves && !coupled {
        if let Some(bound) = separable_bound(problem, &g, &b) {
            return Ok(bound);
        }
    }
    let r = relaxation(problem, &g, &b);
    let solved = r.lp.solve("global bound")?;
    let exact = check(&r.lp.view(), &solved.x, &solved.y);
    let ub = exact
        .upper_bound
        .ok_or_else(|| OptError::Solver("global bound: no finite dual bound".into()))?;
    // Raised by objective_margin: covers the float evaluation of the model's
    // constants (k, √ of a fixed block) the rows were built from.
    let lp_bound = to_f64_up(&ub) * (1.0 + S.objective_margin);
    // The Lagrangian's slices need x ≥ 0 (powers are never negative).
    if !coupled || r.xs.iter().any(|&(_, lo, _)| lo.is_nan() || lo < 0.0) {
        return Ok(lp_bound);
    }
    let lag = coupled_bound(problem, &g, &b, &r, &solved.y);
    // The smaller of two valid bounds (the Lagrangian's constants are the
    // same floats the rows were built from: objective_margin as above).
    Ok(lp_bound.min(lag * (1.0 + S.objective_margin)))
}

/// The certificate of the detection bound ([`upper_bound`] under
/// `objective.kind = "detection"`): its multipliers, nodes, envelope points
/// and cells, its sum checked exactly ([`check_detection_certificate`]).
pub fn detection_certificate(
    problem: &Problem,
    gaze_deg: f64,
) -> Result<DetectionCertificate, DetectionCertificateError> {
    let (g, b) = detection_setup(problem, gaze_deg)?;
    detection_bound::solve(problem, &g, &b, |tables, mu, nu, classes| {
        detection_certificate::build(problem, &g, &b, gaze_deg, (tables, mu, nu, classes))
    })
    .unwrap_or_else(|| {
        Err(DetectionCertificateError::NoBound(
            "the detection Lagrangian has no finite value".into(),
        ))
    })
}

/// Checks a detection certificate for `problem` at `gaze_deg` in exact
/// rational arithmetic (the grid, boxes and rows recomputed from the
/// problem); returns the exact bound it proves.
pub fn check_detection_certificate(
    problem: &Problem,
    gaze_deg: f64,
    cert: &DetectionCertificate,
) -> Result<num_rational::BigRational, DetectionCertificateError> {
    let (g, b) = detection_setup(problem, gaze_deg)?;
    if cert.gaze_deg.to_bits() != gaze_deg.to_bits() {
        return Err(DetectionCertificateError::Rejected {
            field: "gaze_deg".into(),
            reason: format!("{} is not the gaze checked, {gaze_deg}", cert.gaze_deg),
        });
    }
    detection_certificate::check(problem, &g, &b, cert)
}

/// The grid and boxes of a detection problem.
fn detection_setup(
    problem: &Problem,
    gaze_deg: f64,
) -> Result<(Grid, Boxes), DetectionCertificateError> {
    if problem.objective.kind != super::ObjectiveKind::Detection {
        return Err(DetectionCertificateError::NoBound(
            "objective.kind is not \"detection\"".into(),
        ));
    }
    let no = |e: OptError| DetectionCertificateError::NoBound(e.to_string());
    let g = grid(problem, gaze_deg).map_err(no)?;
    let b = boxes(problem, &g).map_err(no)?;
    Ok((g, b))
}

/// The relaxation's boxes: normalised power `x ∈ [x_lo, x_hi]` and spin
/// `ω ∈ [w_lo, w_hi]` (rad/s), widened by the checker's tolerance where a
/// limit (not a level) bounds them, the spin box narrowed by the
/// acceleration limit and the power box by the eye-safety Rule 1 cap.
struct Boxes {
    x_lo: f64,
    x_hi: f64,
    w_lo: f64,
    w_hi: f64,
    n: f64,
    period: f64,
    unit: f64,
}

impl Boxes {
    /// τ = t/unit with t = 2θ/(ω_start + ω_end), both in the spin box;
    /// rounded outward where the spin moves (a few ulps).
    fn tau(&self, theta: f64) -> (f64, f64) {
        let outward = if self.w_lo < self.w_hi {
            4.0 * f64::EPSILON
        } else {
            0.0
        };
        let t_lo = theta / self.w_hi / self.unit * (1.0 - outward);
        let t_hi = if self.w_lo > 0.0 {
            (theta / self.w_lo / self.unit * (1.0 + outward)).min(self.n)
        } else {
            self.n
        };
        (t_lo, t_hi)
    }

    /// `r = k·τ`, `k = unit·2π/(θ·T)`.
    fn k(&self, theta: f64) -> f64 {
        self.unit * TAU / (theta * self.period)
    }
}

/// The smallest and largest of `values`.
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    })
}

/// See [`Boxes`].
fn boxes(problem: &Problem, g: &Grid) -> Result<Boxes, OptError> {
    let lid = &problem.lidar;
    let l = &lid.limits;
    let p_mean = lid.average_power_w;
    let n = g.n as f64;
    let period = 1.0 / lid.frame_rate_hz;
    let mode = problem.objective.mode;
    let levels = &problem.levels;
    let (x_lo, x_hi) = if !mode.controls_range() {
        let p0 = p_mean.clamp(l.power_w_min, l.power_w_max) / p_mean;
        (p0, p0)
    } else if levels.power_w.is_empty() {
        (l.power_w_min / p_mean, l.power_w_max / p_mean)
    } else {
        let allowed = levels
            .power_w
            .iter()
            .copied()
            .filter(|&v| v >= l.power_w_min && v <= l.power_w_max);
        let (lo, hi) = span(allowed);
        (lo / p_mean, hi / p_mean)
    };
    let (w_lo, w_hi) = if !mode.controls_resolution() {
        (lid.mean_spin_rad_s(), lid.mean_spin_rad_s())
    } else if levels.spin_rad_s.is_empty() {
        (l.spin_rad_s_min, l.spin_rad_s_max)
    } else {
        span(
            levels
                .spin_rad_s
                .iter()
                .copied()
                .filter(|&w| w >= l.spin_rad_s_min && w <= l.spin_rad_s_max),
        )
    };
    if !(x_lo <= x_hi && w_lo <= w_hi && w_hi > 0.0) {
        return Err(super::error::Infeasible::EmptyBox.into());
    }
    // Limits (not levels, which are exact) are met to the checker's
    // tolerance: the boxes widened by it.
    let (x_lo, x_hi) = if mode.controls_range() && levels.power_w.is_empty() {
        (x_lo * (1.0 - S.global_widen), x_hi * (1.0 + S.global_widen))
    } else {
        (x_lo, x_hi)
    };
    let accel = l
        .spin_accel_rad_s2_max
        .filter(|a| mode.controls_resolution() && a.is_finite() && *a >= 0.0);
    let (w_lo, w_hi) = if mode.controls_resolution() && levels.spin_rad_s.is_empty() {
        let (lo, hi) = (w_lo * (1.0 - S.global_widen), w_hi * (1.0 + S.global_widen));
        match accel {
            Some(a) => accel_spin_box(a, period, g.n, lo, hi),
            None => (lo, hi),
        }
    } else {
        (w_lo, w_hi)
    };
    let x_hi = eye_capped(problem, x_lo, x_hi, w_hi, period)?;
    Ok(Boxes {
        x_lo,
        x_hi,
        w_lo,
        w_hi,
        n,
        period,
        unit: period / n,
    })
}

/// Eye safety: no bin of a certifiable profile carries more than the
/// bound's Rule 1 cap at the fastest spin the box allows (the core's
/// `rule_one_cap_w`, valid for every spin profile in the box).
fn eye_capped(
    problem: &Problem,
    x_lo: f64,
    x_hi: f64,
    w_hi: f64,
    period: f64,
) -> Result<f64, OptError> {
    let lid = &problem.lidar;
    match &lid.limits.eye_safety {
        Some(params) if problem.objective.mode.controls_range() => {
            let laser =
                crate::eye_safety::exposure::laser(params, lid.pulse_rate_hz).map_err(|e| {
                    OptError::Invalid {
                        field: "limits.eye_safety".into(),
                        reason: e.to_string(),
                    }
                })?;
            let cap = crate::eye_safety::cuts::rule_one_cap_for(params, &laser, w_hi, period);
            Ok(x_hi.min(cap / lid.average_power_w).max(x_lo))
        }
        _ => Ok(x_hi),
    }
}

/// Separable case (no slew, not time-coupled): power against one budget
/// row, dwell against the frame, each bounded by its Lagrangian.
fn separable_bound(problem: &Problem, g: &Grid, b: &Boxes) -> Option<f64> {
    let lid = &problem.lidar;
    let o = &problem.objective;
    let n = b.n;
    let power: Vec<Term> = (0..g.n)
        .map(|i| Term {
            c: o.range_weight * g.theta[i] * g.weight[i],
            s: 1.0,
            a: match lid.power_accounting {
                PowerAccounting::Angle => g.theta[i],
                // τ fixed here (time accounting is not coupled).
                PowerAccounting::Time => b.tau(g.theta[i]).1,
            },
            lo: b.x_lo,
            hi: b.x_hi,
        })
        .collect();
    let budget = match lid.power_accounting {
        PowerAccounting::Angle => TAU,
        PowerAccounting::Time => n,
    } * (1.0 + S.global_widen);
    let dwell: Vec<Term> = (0..g.n)
        .map(|i| {
            let (lo, hi) = b.tau(g.theta[i]);
            Term {
                c: o.resolution_weight * g.theta[i] * g.weight[i],
                s: b.unit * TAU / (g.theta[i] * b.period),
                a: 1.0,
                lo,
                hi,
            }
        })
        .collect();
    // The dwell part's row is the frame, an equality: Σ τ ≥ N(1−widen) is
    // dropped (a relaxation), Σ τ ≤ N(1+widen) kept; its multiplier is ≥ 0
    // because the utility grows with τ.
    let bp = lagrangian_bound(&power, budget)?;
    let bd = lagrangian_bound(&dwell, n * (1.0 + S.global_widen))?;
    Some((bp + bd) * (1.0 + S.objective_margin))
}

/// The relaxation's LP and where its rows are.
struct Relaxation {
    lp: Program,
    /// Per bin (column, lo, hi) of `x` and of `τ`.
    xs: Vec<(Variable, f64, f64)>,
    taus: Vec<(Variable, f64, f64)>,
    /// The frame's two rows (`≤`, `≥`).
    frame_rows: (usize, usize),
    budget_row: usize,
    /// ((`≤` row, `≥` row), i, j, limit) per slew pair of rows.
    slews: Vec<((usize, usize), usize, usize, f64)>,
}

/// The relaxation's LP: per bin `x`, `τ` and the utilities' concave
/// over-estimators, then the constraint families `frame`, `budget`
/// (McCormick envelopes under time accounting), `slew`.
fn relaxation(problem: &Problem, g: &Grid, b: &Boxes) -> Relaxation {
    let o = &problem.objective;
    let mut lp = Program::default();
    let mut xs = Vec::with_capacity(g.n);
    let mut taus = Vec::with_capacity(g.n);
    let mut constant = 0.0;
    let (x_lo, x_hi) = (b.x_lo, b.x_hi);
    for i in 0..g.n {
        let (t_lo, t_hi) = b.tau(g.theta[i]);
        let x = lp.column(x_lo, x_hi, 0.0, false);
        let tau = lp.column(t_lo, t_hi, 0.0, false);
        let cw = g.theta[i] * g.weight[i];
        // A fixed block needs no tangents: its utility is a box bound
        // (√ rounded up by a relative 1e-15, above the true root).
        let up = |v: f64| v.sqrt() * (1.0 + 1e-15);
        if x_lo < x_hi {
            constant += add_concave_bound(&mut lp, x, 1.0, x_lo, x_hi, o.range_weight * cw);
        } else {
            lp.column(0.0, up(x_hi), o.range_weight * cw, false);
        }
        let k = b.k(g.theta[i]);
        if t_lo < t_hi {
            constant += add_concave_bound(&mut lp, tau, k, t_lo, t_hi, o.resolution_weight * cw);
        } else {
            lp.column(0.0, up(k * t_hi), o.resolution_weight * cw, false);
        }
        xs.push((x, x_lo, x_hi));
        taus.push((tau, t_lo, t_hi));
    }
    // The over-estimators' constants on one column fixed at 1: a sum of at
    // most 2N non-negative doubles, each rounded up, raised by a relative
    // 1e-12 (far above the 2N·ε its rounding can lose).
    if constant > 0.0 {
        lp.column(1.0, 1.0, constant * (1.0 + 1e-12), false);
    }
    let mut r = Relaxation {
        lp,
        xs,
        taus,
        frame_rows: (0, 0),
        budget_row: 0,
        slews: Vec::new(),
    };
    relaxed_frame(&mut r, b.n);
    relaxed_budget(&mut r, problem, g, b.n);
    let l = &problem.lidar.limits;
    if let (Some(s), true) = (l.power_slew_w_per_deg_max, o.mode.controls_range()) {
        relaxed_slew(&mut r, g, s, problem.lidar.average_power_w);
    }
    r
}

/// `frame`: `N(1−widen) ≤ Σ τ ≤ N(1+widen)` (two rows).
fn relaxed_frame(r: &mut Relaxation, n: f64) {
    let frame: Expression = r.taus.iter().map(|&(t, _, _)| t).sum();
    r.frame_rows = r.lp.between(
        "frame",
        frame,
        n * (1.0 - S.global_widen),
        n * (1.0 + S.global_widen),
    );
    r.budget_row = r.frame_rows.0;
}

/// `budget`: `Σ θ x ≤ 2π(1+widen)` (angle), or under time accounting
/// `Σ w ≤ N(1+widen)` with `w ≥ x·τ` by its McCormick under-estimators.
fn relaxed_budget(r: &mut Relaxation, problem: &Problem, g: &Grid, n: f64) {
    match problem.lidar.power_accounting {
        PowerAccounting::Angle => {
            let mut spend = Expression::with_capacity(g.n);
            for i in 0..g.n {
                spend.add_mul(g.theta[i], r.xs[i].0);
            }
            r.lp.at_most("budget", spend, TAU * (1.0 + S.global_widen));
        }
        PowerAccounting::Time => {
            let mut spend = Expression::with_capacity(g.n);
            for i in 0..g.n {
                let (x, xl, xh) = r.xs[i];
                let (t, tl, th) = r.taus[i];
                let w = r.lp.column(xl * tl, xh * th, 0.0, false);
                // w ≥ tl·x + xl·τ − tl·xl and w ≥ th·x + xh·τ − th·xh.
                r.lp.at_least("mccormick", w - tl * x - xl * t, -tl * xl);
                r.lp.at_least("mccormick", w - th * x - xh * t, -th * xh);
                spend.add_mul(1.0, w);
            }
            r.budget_row = r.lp.at_most("budget", spend, n * (1.0 + S.global_widen));
        }
    }
}

/// `slew`: `|x_j − x_i| ≤ s·(Δ_i+Δ_j)/2/P̄·(1+widen)` around the circle.
fn relaxed_slew(r: &mut Relaxation, g: &Grid, s: f64, p_mean: f64) {
    for i in 0..g.n {
        let j = next_index(i, g.n);
        let lim = s * 0.5 * (g.width_deg[i] + g.width_deg[j]) / p_mean * (1.0 + S.global_widen);
        let rows = r.lp.between("slew", r.xs[j].0 - r.xs[i].0, -lim, lim);
        r.slews.push((rows, i, j, lim));
    }
}

/// The coupled case's Lagrangian bound at the LP's multipliers `y`,
/// improved by a coordinate search.
fn coupled_bound(problem: &Problem, g: &Grid, b: &Boxes, r: &Relaxation, y: &[f64]) -> f64 {
    let o = &problem.objective;
    let n = b.n;
    let bins: Vec<Bilinear> = (0..g.n)
        .map(|i| {
            let cw = g.theta[i] * g.weight[i];
            Bilinear {
                cx: o.range_weight * cw,
                ct: o.resolution_weight * cw,
                k: b.k(g.theta[i]),
                x: (r.xs[i].1, r.xs[i].2),
                t: (r.taus[i].1, r.taus[i].2),
            }
        })
        .collect();
    let duals = Duals {
        // A two-sided family's multiplier: the sum of its two rows'.
        frame: (
            y[r.frame_rows.0] + y[r.frame_rows.1],
            n * (1.0 - S.global_widen),
            n * (1.0 + S.global_widen),
        ),
        budget: (y[r.budget_row].max(0.0), n * (1.0 + S.global_widen)),
        slews: r
            .slews
            .iter()
            .map(|&((hi, lo), i, j, lim)| (y[hi] + y[lo], i, j, lim))
            .collect(),
    };
    let duals = improve_multipliers(&bins, duals);
    coupled_lagrangian(&bins, &duals, S.lagrangian_slices)
}

/// Golden-section minimum of a convex `f` on `[lo, hi]` in `steps` steps:
/// the midpoint of the last bracket. On a tie (`f(c) = f(d)`) the bracket
/// keeps its lower part: for a convex `f` a minimiser lies in `[c, d]`, so
/// either side is valid, and the lower one prefers the smaller multiplier.
/// The one search of the global bounds (`√` coupled and detection).
fn golden(f: impl Fn(f64) -> f64, lo: f64, hi: f64, steps: usize) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo, hi);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..steps {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

/// Lowers the Lagrangian over the frame's and the budget's multipliers
/// (convex in them: a sum of maxima of affine functions), by coordinate
/// golden-section searches on a coarse slicing; any multipliers are valid,
/// this only tightens.
fn improve_multipliers(bins: &[Bilinear], mut d: Duals) -> Duals {
    // Measured on `smooth` (bound 8.91687 at the LP's multipliers): one
    // round 8.91094 in 4 ms, three 8.91085 in 15 ms.
    let start = (
        d.budget.0,
        d.frame.0,
        coupled_lagrangian(bins, &d, S.multiplier_pieces),
    );
    for _ in 0..S.multiplier_rounds {
        let (mu, nu) = (d.budget.0, d.frame.0);
        let span = mu.abs() + nu.abs() + 1e-6;
        d.budget.0 = golden(
            |m| coupled_lagrangian_at(bins, &d, m, nu, S.multiplier_pieces),
            0.0,
            mu + span,
            40,
        );
        let mu = d.budget.0;
        d.frame.0 = golden(
            |v| coupled_lagrangian_at(bins, &d, mu, v, S.multiplier_pieces),
            nu - span,
            nu + span,
            40,
        );
    }
    // Keep the start where the search did not improve on it.
    let after = coupled_lagrangian(bins, &d, S.multiplier_pieces);
    if after.is_nan() || after > start.2 {
        (d.budget.0, d.frame.0) = (start.0, start.1);
    }
    d
}

/// One bin of the coupled problem: `cx·√x + ct·√(k·τ)` on the box.
struct Bilinear {
    cx: f64,
    ct: f64,
    k: f64,
    x: (f64, f64),
    t: (f64, f64),
}

/// Multipliers of the coupled problem's rows: frame `(ν, lo, hi)`, budget
/// `(μ ≥ 0, hi)` of `Σ τ_i x_i ≤ hi`, slew `(y, i, j, lim)` of
/// `−lim ≤ x_j − x_i ≤ lim`.
struct Duals {
    frame: (f64, f64, f64),
    budget: (f64, f64),
    slews: Vec<(f64, usize, usize, f64)>,
}

/// Weak duality for the coupled problem with the **exact** product
/// `τ_i x_i` (module docs, "coupled Lagrangian"): for the multipliers `d`,
/// `Σ_rows max(y·lo, y·hi) + Σ_i max_box (J_i − μ τ x − ν τ − σ_i x)`,
/// each bin's maximum bounded over `pieces` slices of its τ box (on a
/// slice `μτx ≥ μ·τ_start·x`, so the slice's bound is the x-part at
/// `τ_start` plus the τ-part's own maximum, both concave closed forms).
/// Floating point, raised by a relative 1e-12 of the terms' magnitudes.
fn coupled_lagrangian(bins: &[Bilinear], d: &Duals, pieces: usize) -> f64 {
    coupled_lagrangian_at(bins, d, d.budget.0, d.frame.0, pieces)
}

/// [`coupled_lagrangian`] with the budget's multiplier `mu ≥ 0` and the
/// frame's `nu` in place of `d`'s.
fn coupled_lagrangian_at(bins: &[Bilinear], d: &Duals, mu: f64, nu: f64, pieces: usize) -> f64 {
    let (_, f_lo, f_hi) = d.frame;
    let (_, b_hi) = d.budget;
    let mut sigma = vec![0.0; bins.len()];
    let mut total = (nu * f_lo).max(nu * f_hi) + mu * b_hi;
    let mut magnitude = total.abs();
    for &(y, i, j, lim) in &d.slews {
        sigma[j] += y;
        sigma[i] -= y;
        total += y.abs() * lim;
        magnitude += y.abs() * lim;
    }
    // max over v ∈ [lo, hi] of c√(s·v) − m·v (c ≥ 0), value and magnitude.
    let concave = |c: f64, s: f64, m: f64, lo: f64, hi: f64| -> (f64, f64) {
        let v = Term {
            c,
            s,
            a: 1.0,
            lo,
            hi,
        }
        .argmax(m);
        let (gain, cost) = (c * (s * v).max(0.0).sqrt(), m * v);
        (gain - cost, gain.abs() + cost.abs())
    };
    for (b, &sg) in bins.iter().zip(&sigma) {
        let (tl, th) = b.t;
        let mut best = f64::NEG_INFINITY;
        let mut best_mag = 0.0;
        for p in 0..pieces {
            let a = tl + (th - tl) * p as f64 / pieces as f64;
            let e = if p + 1 == pieces {
                th
            } else {
                tl + (th - tl) * (p + 1) as f64 / pieces as f64
            };
            let (vx, mx) = concave(b.cx, 1.0, mu * a + sg, b.x.0, b.x.1);
            let (vt, mt) = concave(b.ct, b.k, nu, a, e);
            if vx + vt > best {
                best = vx + vt;
                best_mag = mx + mt;
            }
        }
        total += best;
        magnitude += best_mag;
    }
    // Each term to a few ε, the sum to (terms)·ε of the magnitudes.
    let terms = (bins.len() + d.slews.len() + 2) as f64;
    total + (1e-12 + 2.0 * terms * f64::EPSILON) * magnitude
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_rational::BigRational;

    fn q(v: f64) -> BigRational {
        BigRational::from_float(v).unwrap()
    }

    /// `g(v)` of the segments, exactly: `g0 + Σ slope·clip(v − E_j)` with
    /// the exact partial sums `E_j` of the lengths (what the program adds).
    fn g_exact(g0: f64, segments: &[(f64, f64)], lo: f64, v: &BigRational) -> BigRational {
        let zero = q(0.0);
        let mut start = q(lo);
        let mut g = q(g0);
        for &(a, len) in segments {
            let room = (v - &start).max(zero.clone()).min(q(len));
            g += q(a) * room;
            start += q(len);
        }
        g
    }

    #[test]
    fn tangent_segments_stay_above_the_root_exactly_and_follow_the_tangents() {
        let cases = [
            (1.0, 0.0, 1.3),
            (1.0, 0.2, 4.5),
            (1.0, 0.153_846_153_846, 1.230_769_230_769),
            (0.45, 0.5, 1.111),
            (3.3e-3, 1e-2, 7.5e2),
            (1.0, 0.999_999_9, 1.0),
        ];
        for (k, lo, hi) in cases {
            let (g0, segments) = tangent_segments(k, lo, hi);
            let total = segments.iter().fold(q(0.0), |acc, s| acc + q(s.1));
            assert!(
                q(lo) + total >= q(hi),
                "{k} {lo} {hi}: the segments reach hi"
            );
            let lines = tangents(k, lo, hi);
            // Dense grid plus both sides of every segment start.
            let mut vs: Vec<f64> = (0..=400)
                .map(|j| lo + (hi - lo) * f64::from(j) / 400.0)
                .collect();
            // The tangent points, where the lines touch the root.
            vs.extend(lines.iter().map(|&(_, b)| (2.0 * b).powi(2) / k));
            let mut e = lo;
            for &(_, len) in &segments {
                e += len;
                vs.extend([next_down(e), e, -next_down(-e)]);
            }
            for v in vs.into_iter().filter(|v| (lo..=hi).contains(v)) {
                let g = g_exact(g0, &segments, lo, &q(v));
                assert!(&g * &g >= q(k) * q(v), "{k} {lo} {hi}: g({v}) below √(k·v)");
                // Not looser than the tangent rows it replaces, beyond the
                // stated 1e-12 margins.
                let m = lines
                    .iter()
                    .map(|&(a, b)| b + a * v)
                    .fold(f64::INFINITY, f64::min);
                let gf = rat(&g);
                assert!(
                    gf <= m * (1.0 + 1e-10) + 1e-14,
                    "{k} {lo} {hi} {v}: {gf} vs {m}"
                );
            }
        }
    }

    proptest::proptest! {
        /// The spin box against the closed form of its extreme profile:
        /// ω² linear in the distance from one point at slope 2a (reachable
        /// exactly by ramps, so the box cannot be tighter), meeting the
        /// frame: with q = aT/2, √W_max − √(W_max − 2aπ) = q, i.e.
        /// ω_max = (2aπ/q + q)/2 and ω_min = (2aπ/q − q)/2. The box holds
        /// both (sound) and is within its stated slack of them (tight); with limits
        /// inside, the limits.
        #[test]
        fn the_acceleration_box_meets_its_closed_form(
            a in 1.0f64..1e4,
            rate in 5.0f64..50.0,
            n in 1usize..2000,
        ) {
            use std::f64::consts::PI;
            let period = 1.0 / rate;
            let q = a * period / 2.0;
            let (hi, lo) = ((2.0 * a * PI / q + q) / 2.0, (2.0 * a * PI / q - q) / 2.0);
            // The extreme profile above the floor (else it is clipped).
            proptest::prop_assume!(lo > 1.5);
            let (b_lo, b_hi) = accel_spin_box(a, period, n, 1.0, 1e5);
            // Tight up to the stated slack: the checker's edge tolerance
            // summed over the n edges (n·2.2e-9·ω_max² in ω²) and the
            // frame's 1.2e-9, relative to the smaller ω².
            let tight = (1e-7 + n as f64 * 1.5e-9) * (hi / lo).powi(2);
            proptest::prop_assert!(b_hi >= hi && b_hi <= hi * (1.0 + tight), "{b_hi} vs {hi}");
            proptest::prop_assert!(b_lo <= lo && b_lo >= lo * (1.0 - tight), "{b_lo} vs {lo}");
            // Limits inside the extreme profile's range are kept.
            let mid = 2.0 * PI / period;
            let (c_lo, c_hi) = accel_spin_box(a, period, n, mid * 0.999, mid * 1.001);
            proptest::prop_assert!(c_lo >= mid * 0.999 && c_hi <= mid * 1.001);
        }
    }

    proptest::proptest! {
        /// Weak duality of the coupled Lagrangian against plain evaluation:
        /// for random bins, multipliers (either sign where the row allows)
        /// and slew rows, at random points of the boxes the Lagrangian
        /// function `Σ_rows max(y·lo, y·hi) + Σ_i (J_i − μτx − ντ − σ_i x)`
        /// never exceeds `coupled_lagrangian` (so every feasible point's
        /// `J` is below it), and a fine grid of one bin's own maximum
        /// comes within the slicing's stated error of it.
        #[test]
        fn the_coupled_lagrangian_bounds_every_point(
            seed in 0u64..u64::MAX,
            n in 1usize..7,
        ) {
            use rand::{Rng, SeedableRng};
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let bins: Vec<Bilinear> = (0..n)
                .map(|_| {
                    let xl = rng.random_range(0.0..1.0);
                    let tl = rng.random_range(0.1..2.0);
                    Bilinear {
                        cx: rng.random_range(0.0..2.0),
                        ct: rng.random_range(0.0..2.0),
                        k: rng.random_range(0.1..3.0),
                        x: (xl, xl + rng.random_range(0.0..2.0)),
                        t: (tl, tl * rng.random_range(1.0..2.0)),
                    }
                })
                .collect();
            let slews: Vec<(f64, usize, usize, f64)> = (0..n)
                .map(|i| (rng.random_range(-1.0..1.0), i, (i + 1) % n, rng.random_range(0.0..0.5)))
                .collect();
            let d = Duals {
                frame: (rng.random_range(-1.0..1.0), n as f64 * 0.9, n as f64 * 1.1),
                budget: (rng.random_range(0.0..2.0), n as f64),
                slews,
            };
            let bound = coupled_lagrangian(&bins, &d, 64);
            let (mu, nu) = (d.budget.0, d.frame.0);
            let rows = (nu * d.frame.1).max(nu * d.frame.2)
                + mu * d.budget.1
                + d.slews.iter().map(|s| s.0.abs() * s.3).sum::<f64>();
            let mut sigma = vec![0.0; n];
            for &(y, i, j, _) in &d.slews {
                sigma[j] += y;
                sigma[i] -= y;
            }
            let term = |b: &Bilinear, s: f64, x: f64, t: f64| {
                b.cx * x.sqrt() + b.ct * (b.k * t).sqrt() - mu * t * x - nu * t - s * x
            };
            for _ in 0..200 {
                let value: f64 = rows
                    + bins
                        .iter()
                        .zip(&sigma)
                        .map(|(b, &s)| {
                            let x = rng.random_range(b.x.0..=b.x.1);
                            let t = rng.random_range(b.t.0..=b.t.1);
                            term(b, s, x, t)
                        })
                        .sum::<f64>();
                proptest::prop_assert!(value <= bound, "{value} above {bound}");
            }
            // Not loose beyond the slicing: one bin, grid maximum.
            let b = &bins[0];
            let one = Duals { frame: (nu, 0.0, 0.0), budget: (mu, 0.0), slews: Vec::new() };
            let bound1 = coupled_lagrangian(std::slice::from_ref(b), &one, 64);
            let grid = (0..=300)
                .flat_map(|i| (0..=300).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let x = b.x.0 + (b.x.1 - b.x.0) * f64::from(i) / 300.0;
                    let t = b.t.0 + (b.t.1 - b.t.0) * f64::from(j) / 300.0;
                    term(b, 0.0, x, t)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            let slicing = mu * (b.t.1 - b.t.0) / 64.0 * b.x.1;
            proptest::prop_assert!(grid <= bound1, "{grid} above {bound1}");
            proptest::prop_assert!(bound1 <= grid + slicing + 1e-3, "{bound1} vs grid {grid} + {slicing}");
        }
    }

    fn rat(v: &BigRational) -> f64 {
        use num_traits::ToPrimitive;
        v.to_f64().unwrap()
    }
}
