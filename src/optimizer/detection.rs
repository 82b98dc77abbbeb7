//! The detection objective (`objective.kind = "detection"`).
//!
//! The value of a bin at power ratio `x = p/P̄` and dwell `t` is the
//! probability-weighted **detection range** it buys, relative to the rated
//! range `R₀`:
//!
//! `u(x, t) = Σ_c π_c · R_c(x, Δφ) / R₀`, `Δφ = θ/(f_p·t)`,
//!
//! over the configured conditions `c` (return model × fog level, weights
//! `π_c` summing to 1: the models equally, the fog levels by `fog_weight`),
//! with `R_c` the largest range at which a target `target_width_m` wide of
//! `reflectivity` gives at least `detect` expected returns per frame
//! ([`ReturnModel::detection_range_m`], the simulator's own return model:
//! `physical` with fog extinction and `P_D = ½·erfc((T − A)/√2)`, `argus`
//! with its intensity threshold and 100 m cap). `Δφ` is the bin's pulse
//! spacing (`f_p` pulses per second per channel over a dwell `t` across the
//! bin's `θ`). The bin's weight (driver's deficit plus priors, `+ ε`) and
//! `λ_R θ_i` multiply it as they multiply `√x` under `kind = "sqrt"`.
//!
//! **To the power step** `u(·, t_i)` (dwell fixed) goes as segments in the
//! shape of [`SqrtSegments`] (`base + Σ (slope, length)`), so the power
//! step takes it unchanged: the function is sampled at
//! [`SAMPLES`] + 1 nodes evenly spaced in `√x` on the bin's power box and the
//! upper concave hull of the samples is taken. Where `u` is concave every
//! sample is a hull vertex and the segments are **chords** (below `u`; the
//! concave runs are thinned to about [`super::UTILITY_SEGMENTS`] chords,
//! still chords); where `u` is not concave (the `argus` threshold below
//! which a bin detects nothing, the knee of `P_D`), the hull bridges it:
//! there the segments are the **concave envelope** of the samples, at or
//! above `u` at every sample (an over-estimate: the power step's optimum,
//! and its certificate's optimality claim, are relative to this envelope,
//! not to `u`). With hardware power levels, each level's binary carries
//! `u(level, t_i)` itself (no envelope needed).
//!
//! The dwell step keeps the `√r` resolution utility (`λ_ρ`); `u`'s
//! dependence on the density enters through the power step at the current
//! dwell. The global bound (`optimality.global`) under detection is a
//! Lagrangian on a grid of cells (`global::detection_bound`).

use std::cell::RefCell;
use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use super::utility::SqrtSegments;
use super::{OptError, Problem};
use crate::model::returns::{FogLevel, Guess, ModelKind, ReturnModel};

/// Samples of `u` on a bin's power box from which the segments are built.
pub const SAMPLES: usize = 64;

/// Which per-bin value the power step maximises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectiveKind {
    /// `√(p/P̄)`: range ∝ √P (range equation, clear air).
    #[default]
    Sqrt,
    /// The detection range the bin buys ([`Detection`]).
    Detection,
}

/// The target and conditions of the detection objective
/// (`[objective.detection]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Detection {
    /// Return models, weighted equally.
    pub models: Vec<ModelKind>,
    /// Fog levels, % (the paper's 0, 25, 50).
    pub fog_pct: Vec<u32>,
    /// Probability of each fog level (empty: equal).
    pub fog_weight: Vec<f64>,
    /// Target width seen by the LiDAR, m (the scenario's vehicle width).
    pub target_width_m: f64,
    /// Target reflectivity (the scenario's vehicle reflectivity).
    pub reflectivity: f64,
    /// Expected returns per frame that count as a detection.
    pub detect: f64,
}

impl Default for Detection {
    fn default() -> Self {
        Self {
            models: vec![ModelKind::Argus, ModelKind::Physical],
            fog_pct: vec![0, 25, 50],
            fog_weight: Vec::new(),
            target_width_m: 1.8,
            reflectivity: 0.1,
            detect: 1.0,
        }
    }
}

fn invalid(field: &str, reason: String) -> OptError {
    OptError::Invalid {
        field: format!("objective.detection.{field}"),
        reason,
    }
}

impl Detection {
    /// Checks every field (the first offending one is named).
    pub fn validate(&self) -> Result<(), OptError> {
        if self.models.is_empty() {
            return Err(invalid("models", "needs at least one return model".into()));
        }
        if self.fog_pct.is_empty() {
            return Err(invalid("fog_pct", "needs at least one fog level".into()));
        }
        for (k, &f) in self.fog_pct.iter().enumerate() {
            FogLevel::of(f).map_err(|e| invalid(&format!("fog_pct[{k}]"), e.to_string()))?;
        }
        if !self.fog_weight.is_empty() {
            if self.fog_weight.len() != self.fog_pct.len() {
                return Err(invalid(
                    "fog_weight",
                    format!(
                        "{} weights for {} fog levels",
                        self.fog_weight.len(),
                        self.fog_pct.len()
                    ),
                ));
            }
            for (k, &w) in self.fog_weight.iter().enumerate() {
                if !(w.is_finite() && w >= 0.0) {
                    return Err(invalid(
                        &format!("fog_weight[{k}]"),
                        format!("{w} must be finite and >= 0"),
                    ));
                }
            }
            if self.fog_weight.iter().sum::<f64>() <= 0.0 {
                return Err(invalid("fog_weight", "the weights sum to 0".into()));
            }
        }
        let positive = |name: &str, v: f64, max: f64| {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err(invalid(name, format!("{v} must lie in (0, {max}]")))
            }
        };
        positive("target_width_m", self.target_width_m, 100.0)?;
        positive("reflectivity", self.reflectivity, 1.0)?;
        positive("detect", self.detect, 1e6)
    }

    /// The conditions `(weight, model)`, weights summing to 1.
    fn conditions(&self, problem: &Problem) -> Vec<(f64, ReturnModel)> {
        let spec = &problem.lidar;
        // Relative weights, divided by the largest first so that their sum
        // cannot overflow (`[1e308, 1e308]` is `[1, 1]`).
        let fog_w: Vec<f64> = if self.fog_weight.is_empty() {
            vec![1.0; self.fog_pct.len()]
        } else {
            let top = self.fog_weight.iter().fold(0.0_f64, |m, &w| m.max(w));
            self.fog_weight.iter().map(|&w| w / top).collect()
        };
        let total: f64 = fog_w.iter().sum::<f64>() * self.models.len() as f64;
        let mut out = Vec::new();
        for &kind in &self.models {
            for (&f, &w) in self.fog_pct.iter().zip(&fog_w) {
                if let Ok(fog) = FogLevel::of(f) {
                    let m = ReturnModel::new(
                        kind,
                        fog,
                        spec.rated_range_m,
                        spec.reference_reflectivity,
                    );
                    out.push((w / total, m));
                }
            }
        }
        out
    }
}

/// `u(x, t)` of a bin `theta_rad` wide dwelt on `dwell_s` (module docs).
/// Remembered per problem, pulse spacing and power: bins of one width and
/// dwell (every bin of a `range`-mode problem) at one hardware level share
/// it, and the power step, the exact objective and the global bound ask
/// for the same values.
pub fn value(problem: &Problem, theta_rad: f64, dwell_s: f64, power_ratio: f64) -> f64 {
    let spacing = spacing_rad(problem, theta_rad, dwell_s);
    let key = (
        problem_key(problem),
        [spacing.to_bits(), power_ratio.to_bits(), 0, 0],
    );
    if let Some(v) = VALUES.with(|c| c.borrow().get(&key).copied()) {
        return v;
    }
    let v = value_at_spacing(problem, spacing, power_ratio);
    VALUES.with(|c| {
        let mut c = c.borrow_mut();
        if c.len() > 1 << 16 {
            c.clear();
        }
        c.insert(key, v);
    });
    v
}

/// [`value`] computed, at the pulse spacing `spacing`.
fn value_at_spacing(problem: &Problem, spacing: f64, power_ratio: f64) -> f64 {
    let d = &problem.objective.detection;
    let r0 = problem.lidar.rated_range_m;
    d.conditions(problem)
        .iter()
        .map(|(w, m)| {
            w * m.detection_range_m(
                power_ratio,
                d.reflectivity,
                d.target_width_m,
                spacing,
                d.detect,
            ) / r0
        })
        .sum()
}

/// [`value`] at each of `xs` (ascending power ratios), bit for bit: each
/// condition's detection range at `xs[j]` starts its search from the
/// ranges at `xs[j - 1]` and `xs[j - 2]` extrapolated linearly
/// ([`ReturnModel::detection_range_near_m`]; the guess moves only where
/// the model is evaluated, never the range found).
pub fn values_at(problem: &Problem, theta_rad: f64, dwell_s: f64, xs: &[f64]) -> Vec<f64> {
    let spacing = spacing_rad(problem, theta_rad, dwell_s);
    values_near(problem, spacing, xs, None).0
}

/// [`values_at`] at the pulse spacing `spacing`, bit for bit, and each
/// condition's ranges at `xs`. With `near`, each condition's ranges at the
/// same `xs` but another spacing (a neighbouring bin's), a `physical`
/// condition's range at `xs[j]` is guessed as `near[j]` moved by the
/// difference found at `xs[j - 1]` (bins of a smooth spin differ little:
/// the guess is far closer than the extrapolation along `xs`); the guess
/// still moves only where the model is evaluated.
pub fn values_near(
    problem: &Problem,
    spacing: f64,
    xs: &[f64],
    near: Option<&[Vec<f64>]>,
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let d = &problem.objective.detection;
    let r0 = problem.lidar.rated_range_m;
    let mut sum = vec![0.0; xs.len()];
    let mut all = Vec::new();
    for (c, (w, m)) in d.conditions(problem).into_iter().enumerate() {
        let mut ranges = vec![0.0; xs.len()];
        let near = near
            .and_then(|n| n.get(c))
            .filter(|n| n.len() == xs.len() && matches!(m, ReturnModel::Physical { .. }));
        for (j, &x) in xs.iter().enumerate() {
            let guess = match near {
                Some(p) => across(p, &ranges, j),
                None => along(&ranges, j),
            };
            ranges[j] = m.detection_range_near_m(
                x,
                d.reflectivity,
                d.target_width_m,
                spacing,
                d.detect,
                guess,
            );
        }
        for (s, r) in sum.iter_mut().zip(&ranges) {
            *s += w * r / r0;
        }
        all.push(ranges);
    }
    (sum, all)
}

/// The guess at node `j` from the ranges at the nodes below it,
/// extrapolated linearly, its error the last extrapolation's miss.
fn along(ranges: &[f64], j: usize) -> Guess {
    match j {
        0 => Guess::NONE,
        1 => Guess {
            range_m: ranges[0],
            rel_err: 1e-2,
        },
        _ => {
            let (r1, r2) = (ranges[j - 1], ranges[j - 2]);
            let range_m = 2.0 * r1 - r2;
            let rel_err = if j >= 3 {
                // The last extrapolation's miss.
                ((2.0 * r2 - ranges[j - 3] - r1) / range_m).abs()
            } else {
                1e-3
            };
            Guess {
                range_m,
                rel_err: rel_err.clamp(1e-9, 1e-1),
            }
        }
    }
}

/// The guess at node `j` from another spacing's ranges `near` at the same
/// nodes, moved by the difference at node `j - 1`; its error twice the
/// same guess's miss at `j - 1`.
fn across(near: &[f64], ranges: &[f64], j: usize) -> Guess {
    if j == 0 {
        return Guess {
            range_m: near[0],
            rel_err: 1e-3,
        };
    }
    let shift = ranges[j - 1] - near[j - 1];
    let range_m = near[j] + shift;
    let miss = if j >= 2 {
        ranges[j - 1] - (near[j - 1] + ranges[j - 2] - near[j - 2])
    } else {
        shift
    };
    Guess {
        range_m,
        rel_err: (2.0 * (miss / range_m).abs()).clamp(1e-10, 1e-1),
    }
}

/// A proven upper bound of `u(x, t)` (of the real-number model and of
/// [`value`]'s floating-point answer) and the ranges it rests on: per
/// condition (in [`condition_weights`]' order) a range beyond which nothing
/// detects ([`ReturnModel::detection_range_upper_m`]), and their weighted
/// sum over `R₀` rounded up (a relative 1e-12, far above the few ε of the
/// sum). [`value_upper_holds`] re-checks both.
pub fn value_upper(
    problem: &Problem,
    theta_rad: f64,
    dwell_s: f64,
    power_ratio: f64,
) -> (f64, Vec<f64>) {
    let d = &problem.objective.detection;
    let spacing = spacing_rad(problem, theta_rad, dwell_s);
    let conditions = d.conditions(problem);
    let ranges: Vec<f64> = conditions
        .iter()
        .map(|(_, m)| {
            m.detection_range_upper_m(
                power_ratio,
                d.reflectivity,
                d.target_width_m,
                spacing,
                d.detect,
            )
        })
        .collect();
    let sum: f64 = conditions
        .iter()
        .zip(&ranges)
        .map(|((w, _), r)| w * r)
        .sum();
    (sum / problem.lidar.rated_range_m * (1.0 + 1e-12), ranges)
}

/// Whether every range of `ranges` bounds its condition's detection range
/// at `(x, t)` ([`ReturnModel::detects_nothing_beyond`]: a floating-point
/// evaluation with its stated outward margins). The caller checks the sum.
pub fn value_upper_holds(
    problem: &Problem,
    theta_rad: f64,
    dwell_s: f64,
    power_ratio: f64,
    ranges: &[f64],
) -> bool {
    let d = &problem.objective.detection;
    let spacing = spacing_rad(problem, theta_rad, dwell_s);
    let conditions = d.conditions(problem);
    conditions.len() == ranges.len()
        && conditions.iter().zip(ranges).all(|((_, m), &r)| {
            r.is_finite()
                && m.detects_nothing_beyond(
                    power_ratio,
                    d.reflectivity,
                    d.target_width_m,
                    spacing,
                    d.detect,
                    r,
                )
        })
}

/// The conditions' weights `π_c` (summing to 1 up to rounding), in the
/// order of [`value_upper`]'s ranges.
pub fn condition_weights(problem: &Problem) -> Vec<f64> {
    let d = &problem.objective.detection;
    d.conditions(problem).iter().map(|(w, _)| *w).collect()
}

/// Pulse spacing in a bin, rad: `θ/(f_p·t)`.
fn spacing_rad(problem: &Problem, theta_rad: f64, dwell_s: f64) -> f64 {
    theta_rad / (problem.lidar.pulse_rate_hz * dwell_s)
}

/// The power step's per-bin utility on `[lo, hi]` (power ratios) as
/// segments: `√` chords ([`super::utility::sqrt_segments`]) or the
/// detection value's chords/envelope ([`hull_segments`] of [`values_at`] at
/// [`nodes`]).
pub(super) fn range_segments(
    problem: &Problem,
    theta_rad: f64,
    dwell_s: f64,
    lo: f64,
    hi: f64,
) -> SqrtSegments {
    match problem.objective.kind {
        ObjectiveKind::Sqrt => super::utility::sqrt_segments(lo, hi),
        ObjectiveKind::Detection => cached(problem, theta_rad, dwell_s, lo, hi),
    }
}

/// The power step's utility of one hardware level `x` (power ratio).
pub(super) fn level_value(problem: &Problem, theta_rad: f64, dwell_s: f64, x: f64) -> f64 {
    match problem.objective.kind {
        ObjectiveKind::Sqrt => x.sqrt(),
        ObjectiveKind::Detection => value(problem, theta_rad, dwell_s, x),
    }
}

/// The range utility [`super::exact_objective`] scores a bin with: `√x`,
/// or `u(x, t)` itself (not its segments).
pub(super) fn exact_range_utility(problem: &Problem, theta_rad: f64, dwell_s: f64, x: f64) -> f64 {
    level_value(problem, theta_rad, dwell_s, x.max(0.0))
}

/// Everything [`value`] depends on but the bin: the problem's part
/// ([`problem_key`]) and four numbers (the spacing, the power or box, ...).
type Key = (Vec<u64>, [u64; 4]);

thread_local! {
    /// Segments already built: a power step's bins mostly share their
    /// dwell, and the block-coordinate loop solves many power steps.
    static CACHE: RefCell<HashMap<Key, SqrtSegments>> = RefCell::new(HashMap::new());
    /// Values already computed ([`value`]).
    static VALUES: RefCell<HashMap<Key, f64>> = RefCell::new(HashMap::new());
    /// The ranges of the last segments built, and the problem and box
    /// they were built for.
    #[allow(clippy::type_complexity)]
    static LAST: RefCell<Option<((Vec<u64>, [u64; 2]), Vec<Vec<f64>>)>> =
        const { RefCell::new(None) };
}

/// The fields of `problem` that [`value`] reads besides the bin's spacing
/// and power, as bits: the detection objective's target and conditions
/// and the LiDAR's rating and pulse rate.
fn problem_key(problem: &Problem) -> Vec<u64> {
    let d = &problem.objective.detection;
    let l = &problem.lidar;
    let mut key = vec![
        d.models.len() as u64,
        d.fog_pct.len() as u64,
        d.fog_weight.len() as u64,
    ];
    key.extend(d.models.iter().map(|&m| match m {
        ModelKind::Argus => 0,
        ModelKind::Physical => 1,
    }));
    key.extend(d.fog_pct.iter().map(|&f| u64::from(f)));
    key.extend(d.fog_weight.iter().map(|w| w.to_bits()));
    key.extend(
        [
            d.target_width_m,
            d.reflectivity,
            d.detect,
            l.rated_range_m,
            l.reference_reflectivity,
            l.pulse_rate_hz,
        ]
        .map(f64::to_bits),
    );
    key
}

fn cached(problem: &Problem, theta_rad: f64, dwell_s: f64, lo: f64, hi: f64) -> SqrtSegments {
    let key: Key = (
        problem_key(problem),
        [
            spacing_rad(problem, theta_rad, dwell_s).to_bits(),
            lo.to_bits(),
            hi.to_bits(),
            0,
        ],
    );
    if let Some(s) = CACHE.with(|c| c.borrow().get(&key).cloned()) {
        return s;
    }
    let v = nodes(lo, hi);
    // The last bin built on the same box (the same nodes) guesses the
    // ranges ([`values_near`]).
    let same = (key.0.clone(), [key.1[1], key.1[2]]);
    let near = LAST.with(|l| l.borrow_mut().take().filter(|(k, _)| *k == same));
    let spacing = spacing_rad(problem, theta_rad, dwell_s);
    let (y, ranges) = values_near(problem, spacing, &v, near.as_ref().map(|n| &n.1[..]));
    LAST.with(|l| *l.borrow_mut() = Some((same, ranges)));
    let s = hull_segments(&v, &y, super::UTILITY_SEGMENTS);
    CACHE.with(|c| {
        let mut c = c.borrow_mut();
        if c.len() > 4096 {
            c.clear();
        }
        c.insert(key, s.clone());
    });
    s
}

/// The sample nodes of `[lo, hi]`: [`SAMPLES`] + 1, evenly spaced in `√`.
pub fn nodes(lo: f64, hi: f64) -> Vec<f64> {
    let (a, b) = (lo.max(0.0).sqrt(), hi.max(lo).sqrt());
    (0..=SAMPLES)
        .map(|j| {
            if j == 0 {
                lo
            } else if j == SAMPLES {
                hi.max(lo)
            } else {
                (a + (b - a) * j as f64 / SAMPLES as f64).powi(2)
            }
        })
        .collect()
}

/// [`hull_segments`] of a nondecreasing `f` sampled at [`nodes`].
#[cfg(test)]
pub(super) fn detection_segments(
    f: impl Fn(f64) -> f64,
    lo: f64,
    hi: f64,
    k: usize,
) -> SqrtSegments {
    let v = nodes(lo, hi);
    let y: Vec<f64> = v.iter().map(|&x| f(x)).collect();
    hull_segments(&v, &y, k)
}

/// The upper concave hull of the samples `y` of a nondecreasing function at
/// the nodes `v`, as segments: chords where it is concave (runs of
/// consecutive samples thinned to about `k` chords), the envelope where it
/// is not.
fn hull_segments(v: &[f64], y: &[f64], k: usize) -> SqrtSegments {
    // Monotone chain: the upper hull of (v_j, y_j), as sample indices.
    let mut hull: Vec<usize> = Vec::new();
    for j in 0..v.len() {
        if j > 0 && v[j] <= v[j - 1] {
            continue;
        }
        while hull.len() >= 2 {
            let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
            // Drop b when it is on or below the line from a to j.
            let cross = (v[b] - v[a]) * (y[j] - y[a]) - (y[b] - y[a]) * (v[j] - v[a]);
            if cross >= 0.0 {
                hull.pop();
            } else {
                break;
            }
        }
        hull.push(j);
    }
    // Keep the ends of every bridge (an edge over more than one sample
    // interval: the envelope) and every `step`-th vertex inside runs of
    // consecutive samples (chords of chords of a concave run stay below it).
    let step = (v.len() - 1).div_ceil(k.max(1)).max(1);
    let last = hull.len() - 1;
    let keep: Vec<usize> = (0..hull.len())
        .filter(|&h| {
            h == 0
                || h == last
                || hull[h] % step == 0
                || hull[h] - hull[h - 1] > 1
                || hull[h + 1] - hull[h] > 1
        })
        .map(|h| hull[h])
        .collect();
    let segments = keep
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (w[0], w[1]);
            let len = v[b] - v[a];
            (len > 0.0).then(|| (((y[b] - y[a]) / len).max(0.0), len))
        })
        .collect();
    SqrtSegments {
        base: y[0],
        segments,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn problem() -> Problem {
        let mut p = Problem::paper_equivalent(
            &crate::model::presets::paper(),
            crate::model::Mode::Range,
            360,
        )
        .unwrap();
        p.objective.kind = ObjectiveKind::Detection;
        p
    }

    /// Brute force: the detection range of one condition by a slow loop
    /// over ranges (1 cm steps), independent of the bisection.
    fn brute_range(m: &ReturnModel, x: f64, rho: f64, w: f64, s: f64, detect: f64) -> f64 {
        let mut best = 0.0;
        let mut r = 0.01;
        while r <= 400.0 {
            let pulses = w / (r * s);
            if pulses * m.detection_probability(x, rho, 1.0, r) >= detect {
                best = r;
            }
            r += 0.01;
        }
        best
    }

    fn brute_value(p: &Problem, theta: f64, dwell: f64, x: f64) -> f64 {
        let d = &p.objective.detection;
        let s = theta / (p.lidar.pulse_rate_hz * dwell);
        let n = (d.models.len() * d.fog_pct.len()) as f64;
        let mut sum = 0.0;
        for &kind in &d.models {
            for &f in &d.fog_pct {
                let m = ReturnModel::new(
                    kind,
                    FogLevel::of(f).unwrap(),
                    p.lidar.rated_range_m,
                    p.lidar.reference_reflectivity,
                );
                sum += brute_range(&m, x, d.reflectivity, d.target_width_m, s, d.detect) / n;
            }
        }
        sum / p.lidar.rated_range_m
    }

    /// A remembered value is the value of the problem asked about: a
    /// changed target is computed afresh.
    #[test]
    fn a_remembered_value_is_the_problems() {
        let mut p = problem();
        let theta = std::f64::consts::TAU / 360.0;
        let dwell = p.lidar.frame_period_s() / 360.0;
        let s = spacing_rad(&p, theta, dwell);
        let first = value(&p, theta, dwell, 0.8);
        assert_eq!(first.to_bits(), value_at_spacing(&p, s, 0.8).to_bits());
        assert_eq!(first.to_bits(), value(&p, theta, dwell, 0.8).to_bits());
        p.objective.detection.reflectivity *= 2.0;
        let second = value(&p, theta, dwell, 0.8);
        assert_eq!(second.to_bits(), value_at_spacing(&p, s, 0.8).to_bits());
        assert!(second > first, "{second} vs {first}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The value against the slow loop over ranges (1 cm grid: the
        /// loop's answer is within 1 cm below the true range).
        #[test]
        fn value_matches_the_brute_force(x in 0.05f64..2.0, density in 0.2f64..5.0) {
            let p = problem();
            let theta = std::f64::consts::TAU / 360.0;
            let dwell = density * p.lidar.frame_period_s() / 360.0;
            let fast = value(&p, theta, dwell, x);
            let slow = brute_value(&p, theta, dwell, x);
            let tol = 0.0101 / p.lidar.rated_range_m;
            prop_assert!(fast >= slow - 1e-12 && fast <= slow + tol, "{x} {density}: {fast} vs {slow}");
        }

        /// The chained search along a bin's nodes gives every node's value
        /// bit for bit (the guesses move only where the model is evaluated).
        #[test]
        fn values_at_the_nodes_are_the_values(
            lo in 0.0f64..0.6, width in 0.01f64..4.0, density in 0.2f64..5.0,
        ) {
            let p = problem();
            let theta = std::f64::consts::TAU / 360.0;
            let dwell = density * p.lidar.frame_period_s() / 360.0;
            let v = nodes(lo, lo + width);
            let chained = values_at(&p, theta, dwell, &v);
            for (&x, y) in v.iter().zip(&chained) {
                let one = value(&p, theta, dwell, x);
                prop_assert_eq!(y.to_bits(), one.to_bits(), "{} at {}", y, x);
            }
        }

        /// Guessed from a neighbouring spacing's ranges, the values are
        /// still every node's value bit for bit.
        #[test]
        fn values_near_another_spacing_are_the_values(
            lo in 0.0f64..0.6, width in 0.01f64..4.0, density in 0.2f64..5.0, step in -0.3f64..0.3,
        ) {
            let p = problem();
            let theta = std::f64::consts::TAU / 360.0;
            let dwell = density * p.lidar.frame_period_s() / 360.0;
            let v = nodes(lo, lo + width);
            let near = values_near(&p, spacing_rad(&p, theta, dwell * (1.0 + step)), &v, None).1;
            let (got, _) = values_near(&p, spacing_rad(&p, theta, dwell), &v, Some(&near));
            for (&x, y) in v.iter().zip(&got) {
                let one = value_at_spacing(&p, spacing_rad(&p, theta, dwell), x);
                prop_assert_eq!(y.to_bits(), one.to_bits(), "{} at {}", y, x);
            }
        }

        /// More power or more density never detects less.
        #[test]
        fn value_is_monotone(x in 0.05f64..2.0, density in 0.2f64..5.0, up in 1.0f64..1.5) {
            let p = problem();
            let theta = std::f64::consts::TAU / 360.0;
            let dwell = density * p.lidar.frame_period_s() / 360.0;
            let v = value(&p, theta, dwell, x);
            prop_assert!(value(&p, theta, dwell, x * up) >= v);
            prop_assert!(value(&p, theta, dwell * up, x) >= v);
        }

        /// The segments are concave, start at `u(lo)`, and never fall below
        /// `u` at a sample where they bridge (envelope) nor rise above it
        /// between samples where `u` is concave (chords).
        #[test]
        fn segments_are_concave_chords_or_envelope(
            lo in 0.0f64..0.6, width in 0.1f64..1.5, density in 0.2f64..5.0,
        ) {
            let p = problem();
            let theta = std::f64::consts::TAU / 360.0;
            let dwell = density * p.lidar.frame_period_s() / 360.0;
            let hi = lo + width;
            let f = |x: f64| value(&p, theta, dwell, x);
            let s = detection_segments(f, lo, hi, crate::optimizer::UTILITY_SEGMENTS);
            prop_assert_eq!(s.base, f(lo));
            for w in s.segments.windows(2) {
                prop_assert!(w[0].0 >= w[1].0, "slopes decrease: {:?}", s.segments);
            }
            let total: f64 = s.segments.iter().map(|x| x.1).sum();
            prop_assert!((total - (hi - lo)).abs() <= 1e-12 * hi.max(1.0));
            let h = |x: f64| {
                let mut rem = x - lo;
                let mut acc = s.base;
                for &(a, len) in &s.segments {
                    let d = len.min(rem.max(0.0));
                    acc += a * d;
                    rem -= d;
                }
                acc
            };
            let v = nodes(lo, hi);
            let y: Vec<f64> = v.iter().map(|&x| f(x)).collect();
            // Where three consecutive samples are concave, `u` is taken as
            // concave there and the segments must not rise above it (fine
            // grid); every sample must be at or below the segments'
            // envelope unless it lies in a concave run (chords).
            for j in 1..v.len() - 1 {
                let concave_here = (y[j] - y[j - 1]) / (v[j] - v[j - 1])
                    >= (y[j + 1] - y[j]) / (v[j + 1] - v[j]) - 1e-12;
                if !concave_here {
                    // A convex kink: the envelope covers this sample.
                    prop_assert!(h(v[j]) >= y[j] - 1e-9, "envelope below u at {}", v[j]);
                }
            }
            // Chords: at every sample the segments are within the hull
            // (≤ the hull, which is ≥ every sample only where it bridges);
            // in a fully concave run they are below `u` at fine points.
            for j in 0..v.len() - 1 {
                let concave_run = (j.saturating_sub(1)..(j + 2).min(v.len() - 1)).all(|m| {
                    m == 0 || m + 1 >= v.len()
                        || (y[m] - y[m - 1]) / (v[m] - v[m - 1])
                            >= (y[m + 1] - y[m]) / (v[m + 1] - v[m]) - 1e-12
                });
                if concave_run && h(v[j]) <= y[j] + 1e-9 && h(v[j + 1]) <= y[j + 1] + 1e-9 {
                    for q in 1..8 {
                        let x = v[j] + (v[j + 1] - v[j]) * f64::from(q) / 8.0;
                        prop_assert!(h(x) <= f(x) + 1e-9, "chord above u at {x}");
                    }
                }
            }
        }
    }

    /// End to end on continuous power (the paper sensor, range mode): the
    /// detection objective's optimum certifies, and scores at least as
    /// high on the detection value as the `√` optimum does (both scored by
    /// `exact_objective` with `u` itself, not its segments), strictly higher
    /// at some gaze.
    #[test]
    fn the_detection_optimum_beats_the_sqrt_optimum_on_detection() {
        let mut det = problem();
        det.levels = crate::optimizer::Levels::default();
        det.focus = crate::model::acuity::FocusModel::levi_e2_with_width(60.0);
        let mut sqrt = det.clone();
        sqrt.objective.kind = ObjectiveKind::Sqrt;
        let mut strictly = 0;
        for gaze in [0.0, 90.0, 200.0] {
            let a = crate::optimizer::optimize(&det, gaze).unwrap();
            let b = crate::optimizer::optimize(&sqrt, gaze).unwrap();
            let score = |c: &crate::checker::CertifiedProfile| {
                crate::optimizer::exact_objective(&det, gaze, c.profile()).unwrap()
            };
            let (ja, jb) = (score(&a), score(&b));
            assert!(
                ja >= jb * (1.0 - 1e-3),
                "gaze {gaze}: detection {ja} < sqrt {jb}"
            );
            strictly += usize::from(ja > jb * (1.0 + 1e-3));
        }
        // And the objective does move the optimum.
        assert!(strictly > 0, "the detection optimum is the √ one's");
    }

    #[test]
    fn argus_fog_threshold_is_bridged_by_the_envelope() {
        // argus at code fog 50 (paper 25 %): nothing below x ≈ 0.82, then
        // a logarithm: not concave at the threshold; the envelope covers it.
        let mut p = problem();
        p.objective.detection.models = vec![ModelKind::Argus];
        p.objective.detection.fog_pct = vec![25];
        let theta = std::f64::consts::TAU / 360.0;
        let dwell = p.lidar.frame_period_s() / 360.0;
        let f = |x: f64| value(&p, theta, dwell, x);
        assert_eq!(f(0.5), 0.0);
        assert!(f(1.1) > 0.5, "{}", f(1.1));
        let s = detection_segments(f, 0.2, 1.3, crate::optimizer::UTILITY_SEGMENTS);
        // The first segment starts at 0 and climbs: the envelope is above
        // u(0.5) = 0.
        assert!(s.segments[0].0 > 0.0);
        assert!(s.base == 0.0);
    }
}
