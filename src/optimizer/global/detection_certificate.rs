//! The detection bound's certificate (`detection_bound.json`) and its
//! exact check.
//!
//! The bound of [`super::detection_bound`] is a weak-duality sum over cells
//! of each bin's box. The certificate carries everything that sum needs,
//! and [`check`] recomputes it in exact rational arithmetic
//! (`num-rational`, every double converted exactly) from the problem
//! itself (its grid, boxes, budget and frame rows recomputed, not read):
//!
//! - the multipliers `μ` (budget) and `ν` (frame), both `≥ 0`;
//! - per bin width a table: power nodes `x` (or the hardware levels, each
//!   a cell of its own) and dwell nodes `τ` covering the bin's box, an
//!   upper bound `s_l ≥ √(k τ_l)` per dwell node (checked as `s_l² ≥ k τ_l`
//!   exactly), and **envelope points** `(k, l, U, ranges)`: `U ≥ u(x_k, τ_l)`
//!   because `R₀·U ≥ Σ_c π_c r_c` exactly and each `r_c` is a range beyond
//!   which condition `c` detects nothing
//!   ([`crate::model::returns::ReturnModel::detects_nothing_beyond`]);
//! - per class of bins (equal weight and width) the cells
//!   `[x_k0, x_k1] × [τ_l0, τ_l1]` (node indices), checked to cover the
//!   box (every elementary cell of the node grid painted), each bounded by
//!   `c·(λ_R U(k1, l1) + λ_ρ s_l1) − μ a x_k0 − ν τ_l0` (`u` and `√` are
//!   nondecreasing, `x, τ ≥ 0`; `a = θ`, or `τ_l0` under time accounting);
//! - the sum `μB + νF + Σ_i max_cells`, times `1 + objective_margin`, must
//!   equal `upper_bound_exact` and lie at or below `upper_bound` (the
//!   profile's `optimality.global.upper_bound`).
//!
//! **What rests on floating point**, with its margin: whether a range
//! detects nothing beyond it (one evaluation of the return model rounded
//! outward: `expected_returns_upper`'s stated margins, `libm::erfc` within
//! `ERFC_REL_ERR`); and the model's own constants as the optimizer computes
//! them (bin widths and weights, `k`, `π_c`, the dwell `τ·T/N`: a few ε
//! each), covered by `objective_margin` (1e-12 relative) as for `√`.
//! The model's premise, monotonicity of `u` in power and dwell, is tested
//! (`detection.rs`, `detection_bound.rs`).

use num_rational::BigRational;
use num_traits::Zero;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::detection_bound::{Classes, Table};
use super::{Boxes, Grid};
use crate::optimizer::certificate::rational_string;
use crate::optimizer::detection;
use crate::optimizer::settings::S;
use crate::optimizer::Problem;

/// The format string of `detection_bound.json`.
pub const FORMAT: &str = "gaze-lidar/detection-bound@1";

/// `detection_bound.json` (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DetectionCertificate {
    /// Always `gaze-lidar/detection-bound@1`.
    pub format: String,
    /// What the file proves, in one paragraph.
    pub claim: String,
    /// The gaze the bound is for, degrees.
    pub gaze_deg: f64,
    /// The budget row's multiplier `μ ≥ 0`.
    pub budget_multiplier: f64,
    /// The frame row's multiplier `ν ≥ 0`.
    pub frame_multiplier: f64,
    /// The stated bound (the profile's `optimality.global.upper_bound`).
    pub upper_bound: f64,
    /// The exact sum times `1 + objective_margin`, as `p/q`.
    pub upper_bound_exact: String,
    /// Per bin width.
    pub tables: Vec<TableCertificate>,
    /// Per class of bins.
    pub classes: Vec<ClassCertificate>,
    /// Per bin (in azimuth order): its class.
    pub bin_class: Vec<usize>,
}

/// One bin width's nodes and envelope points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableCertificate {
    /// The bin width, rad.
    pub theta_rad: f64,
    /// The power nodes are the hardware levels (each its own cell).
    pub levels: bool,
    /// Power nodes (ratios to the average power), increasing.
    pub power_ratio: Vec<f64>,
    /// Dwell nodes `τ = t·N/T`, increasing.
    pub tau: Vec<f64>,
    /// Per dwell node, `s ≥ √(k·τ)`.
    pub sqrt_up: Vec<f64>,
    /// Envelope points.
    pub points: Vec<EnvelopePoint>,
}

/// `U ≥ u(x_k, τ_l)`, and the per-condition ranges it rests on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopePoint {
    /// Power node index.
    pub k: usize,
    /// Dwell node index.
    pub l: usize,
    /// The upper bound of `u`.
    pub value: f64,
    /// Per condition (models × fog levels, in the config's order), m.
    pub range_m: Vec<f64>,
}

/// The cells of one class of bins (equal weight and width).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassCertificate {
    /// Its table.
    pub table: usize,
    /// `c = θ·w` of its bins.
    pub weight: f64,
    /// Cells `[k0, k1, l0, l1]` (node indices).
    pub cells: Vec<[usize; 4]>,
}

/// Why a detection certificate is rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DetectionCertificateError {
    /// A field is malformed or fails its check.
    #[error("detection certificate: {field}: {reason}")]
    Rejected {
        /// The field (JSON path).
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// The problem has no detection bound (another objective, or a bound
    /// that is not finite).
    #[error("detection certificate: {0}")]
    NoBound(String),
}

fn reject(field: impl Into<String>, reason: impl Into<String>) -> DetectionCertificateError {
    DetectionCertificateError::Rejected {
        field: field.into(),
        reason: reason.into(),
    }
}

fn q(v: f64) -> BigRational {
    BigRational::from_float(v).unwrap_or_else(BigRational::zero)
}

const CLAIM: &str = "For every profile the checker accepts for this problem (its grid, levels and mode), the detection objective J = sum_i theta_i w_i (range_weight u(x_i, tau_i) + resolution_weight sqrt(k_i tau_i)) is at most upper_bound: weak duality over the budget and the frame's upper row with the multipliers given, each bin's maximum bounded cell by cell (u and sqrt nondecreasing, the gain at a cell's upper corner, the cost at its lower), u at a node bounded by the envelope point's ranges (beyond each, its condition detects nothing). Checked in exact rationals; the sum times (1 + objective_margin) is upper_bound_exact.";

/// The certificate of the bound `solve` computed (its tables, multipliers
/// and cells), its exact figure filled in by [`exact_bound`].
pub(super) fn build(
    problem: &Problem,
    g: &Grid,
    b: &Boxes,
    gaze_deg: f64,
    (tables, mu, nu, classes): (&[Table], f64, f64, &Classes),
) -> Result<DetectionCertificate, DetectionCertificateError> {
    let table_index = |theta: f64| {
        tables
            .iter()
            .position(|t| t.theta.to_bits() == theta.to_bits())
            .unwrap_or(0)
    };
    let mut cert = DetectionCertificate {
        format: FORMAT.into(),
        claim: CLAIM.into(),
        gaze_deg,
        budget_multiplier: mu,
        frame_multiplier: nu,
        upper_bound: classes.bound,
        upper_bound_exact: String::new(),
        tables: tables
            .iter()
            .map(|t| {
                let k = b.k(t.theta);
                TableCertificate {
                    theta_rad: t.theta,
                    levels: t.discrete,
                    power_ratio: t.x.clone(),
                    tau: t.tau.clone(),
                    sqrt_up: t.tau.iter().map(|&v| sqrt_up(k, v)).collect(),
                    points: t
                        .points()
                        .into_iter()
                        .map(|(k, l, value, range_m)| EnvelopePoint {
                            k,
                            l,
                            value,
                            range_m,
                        })
                        .collect(),
                }
            })
            .collect(),
        classes: classes
            .cells
            .iter()
            .map(|(i, cells)| ClassCertificate {
                table: table_index(g.theta[*i]),
                weight: g.theta[*i] * g.weight[*i],
                cells: cells.iter().map(|&(a, b, c, d)| [a, b, c, d]).collect(),
            })
            .collect(),
        bin_class: classes.of_bin.clone(),
    };
    let exact = exact_bound(problem, g, b, &cert)?;
    cert.upper_bound_exact = rational_string(&exact);
    Ok(cert)
}

/// The smallest double `s ≥ 0` found with `s² ≥ k·v` exactly (the float
/// root, stepped up by ulps while its square falls short).
fn sqrt_up(k: f64, v: f64) -> f64 {
    let target = q(k) * q(v.max(0.0));
    let mut s = (k * v).max(0.0).sqrt();
    while q(s) * q(s) < target {
        s = -crate::optimizer::certificate::next_down(-s);
    }
    s
}

/// Checks `cert` for the problem exactly (module docs); returns the exact
/// bound (the sum times `1 + objective_margin`).
pub(super) fn check(
    problem: &Problem,
    g: &Grid,
    b: &Boxes,
    cert: &DetectionCertificate,
) -> Result<BigRational, DetectionCertificateError> {
    if cert.format != FORMAT {
        return Err(reject("format", format!("not {FORMAT}")));
    }
    let exact = exact_bound(problem, g, b, cert)?;
    if rational_string(&exact) != cert.upper_bound_exact {
        return Err(reject(
            "upper_bound_exact",
            format!(
                "the certificate's sum is {}, not the stated {}",
                rational_string(&exact),
                cert.upper_bound_exact
            ),
        ));
    }
    if !(cert.upper_bound.is_finite() && q(cert.upper_bound) >= exact) {
        return Err(reject(
            "upper_bound",
            format!("{} is below the exact sum", cert.upper_bound),
        ));
    }
    Ok(exact)
}

/// The exact bound of `cert`'s multipliers, nodes and cells, after checking
/// each (module docs).
fn exact_bound(
    problem: &Problem,
    g: &Grid,
    b: &Boxes,
    cert: &DetectionCertificate,
) -> Result<BigRational, DetectionCertificateError> {
    let (mu, nu) = (cert.budget_multiplier, cert.frame_multiplier);
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(reject("budget_multiplier", format!("{mu} is not >= 0")));
    }
    if !(nu.is_finite() && nu >= 0.0) {
        return Err(reject("frame_multiplier", format!("{nu} is not >= 0")));
    }
    if cert.bin_class.len() != g.n {
        return Err(reject(
            "bin_class",
            format!("{} bins, the problem has {}", cert.bin_class.len(), g.n),
        ));
    }
    let o = &problem.objective;
    let time = problem.lidar.power_accounting == crate::model::lidar::PowerAccounting::Time;
    let widen = 1.0 + S.global_widen;
    let budget = if time { b.n } else { std::f64::consts::TAU } * widen;
    let frame = b.n * widen;
    let (mu_q, nu_q) = (q(mu), q(nu));
    let (range_w, res_w) = (o.range_weight, o.resolution_weight);
    if !(range_w.is_finite() && range_w >= 0.0 && res_w.is_finite() && res_w >= 0.0) {
        return Err(DetectionCertificateError::NoBound(
            "the objective's weights must be >= 0 (the cells' gain is taken at the upper corner)"
                .into(),
        ));
    }
    let tables: Vec<CheckedTable> = cert
        .tables
        .iter()
        .enumerate()
        .map(|(t, table)| check_table(problem, b, table, &format!("tables[{t}]")))
        .collect::<Result<_, _>>()?;
    let mut class_max: Vec<Option<BigRational>> = vec![None; cert.classes.len()];
    let mut total = &mu_q * q(budget) + &nu_q * q(frame);
    for (i, &class) in cert.bin_class.iter().enumerate() {
        let field = format!("bin_class[{i}]");
        let c = cert
            .classes
            .get(class)
            .ok_or_else(|| reject(&field, "no such class"))?;
        let table = cert
            .tables
            .get(c.table)
            .ok_or_else(|| reject(format!("classes[{class}].table"), "no such table"))?;
        if table.theta_rad.to_bits() != g.theta[i].to_bits() {
            return Err(reject(&field, "its table is for another bin width"));
        }
        if c.weight.to_bits() != (g.theta[i] * g.weight[i]).to_bits() {
            return Err(reject(&field, "its class has another weight"));
        }
        if class_max[class].is_none() {
            let checked = &tables[c.table];
            let cost_a = if time { None } else { Some(table.theta_rad) };
            let m = class_bound(
                c,
                checked,
                (mu, nu),
                (range_w, res_w),
                cost_a,
                &format!("classes[{class}]"),
            )?;
            class_max[class] = Some(m);
        }
        total += class_max[class].as_ref().expect("set above");
    }
    Ok(total * (q(1.0) + q(S.objective_margin)))
}

/// A table's nodes and envelope values, as given (checked) and as
/// rationals.
struct CheckedTable {
    x: Vec<f64>,
    tau: Vec<f64>,
    levels: bool,
    /// Per node `(k, l)` (row-major), the point's `U` if given.
    u: Vec<Option<f64>>,
    sqrt_up: Vec<f64>,
}

fn increasing(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1])
}

fn check_table(
    problem: &Problem,
    b: &Boxes,
    t: &TableCertificate,
    field: &str,
) -> Result<CheckedTable, DetectionCertificateError> {
    let f = |name: &str| format!("{field}.{name}");
    if !(t.theta_rad.is_finite() && t.theta_rad > 0.0) {
        return Err(reject(f("theta_rad"), "not a bin width"));
    }
    if t.power_ratio.is_empty() || !increasing(&t.power_ratio) || t.power_ratio[0] < 0.0 {
        return Err(reject(f("power_ratio"), "not increasing, finite and >= 0"));
    }
    if t.tau.is_empty() || !increasing(&t.tau) || t.tau[0] < 0.0 {
        return Err(reject(f("tau"), "not increasing, finite and >= 0"));
    }
    // The box: the levels themselves, or nodes from its floor to its top.
    match super::detection_bound::levels(problem, b) {
        Some(levels) => {
            if !t.levels || t.power_ratio != levels {
                return Err(reject(f("power_ratio"), "not the problem's power levels"));
            }
        }
        None => {
            let last = t.power_ratio[t.power_ratio.len() - 1];
            if t.levels || t.power_ratio[0] > b.x_lo.max(0.0) || last < b.x_hi {
                return Err(reject(f("power_ratio"), "does not cover the power box"));
            }
        }
    }
    let (tl, th) = b.tau(t.theta_rad);
    if t.tau[0] > tl || t.tau[t.tau.len() - 1] < th {
        return Err(reject(f("tau"), "does not cover the dwell box"));
    }
    let k = q(b.k(t.theta_rad));
    if t.sqrt_up.len() != t.tau.len() {
        return Err(reject(f("sqrt_up"), "one per dwell node"));
    }
    for (l, (&s, &v)) in t.sqrt_up.iter().zip(&t.tau).enumerate() {
        let s_q = q(s);
        if !(s.is_finite() && s >= 0.0 && &s_q * &s_q >= &k * q(v)) {
            return Err(reject(format!("{field}.sqrt_up[{l}]"), "below √(k·τ)"));
        }
    }
    let weights: Vec<BigRational> = detection::condition_weights(problem)
        .into_iter()
        .map(q)
        .collect();
    let r0 = q(problem.lidar.rated_range_m);
    let (nx, nt) = (t.power_ratio.len(), t.tau.len());
    let mut u = vec![None; nx * nt];
    for (j, p) in t.points.iter().enumerate() {
        let pf = format!("{field}.points[{j}]");
        if p.k >= nx || p.l >= nt {
            return Err(reject(pf, "node index out of range"));
        }
        let (x, tau) = (t.power_ratio[p.k], t.tau[p.l]);
        if !detection::value_upper_holds(problem, t.theta_rad, tau * b.unit, x, &p.range_m) {
            return Err(reject(
                format!("{pf}.range_m"),
                "a range beyond which the model may still detect",
            ));
        }
        let sum: BigRational = weights.iter().zip(&p.range_m).map(|(w, &r)| w * q(r)).sum();
        if !(p.value.is_finite() && p.value >= 0.0 && &r0 * q(p.value) >= sum) {
            return Err(reject(
                format!("{pf}.value"),
                "below the weighted ranges over the rated range",
            ));
        }
        u[p.k * nt + p.l] = Some(p.value);
    }
    Ok(CheckedTable {
        x: t.power_ratio.clone(),
        tau: t.tau.clone(),
        levels: t.levels,
        u,
        sqrt_up: t.sqrt_up.clone(),
    })
}

/// The elementary units a cell's node range `[a, b]` covers on an axis of
/// `len` nodes: points (`points`, or one node) or intervals.
fn units(a: usize, b: usize, len: usize, points: bool) -> Option<std::ops::Range<usize>> {
    if b >= len || a > b {
        return None;
    }
    if points || len == 1 {
        (a == b).then_some(a..a + 1)
    } else {
        (a < b).then_some(a..b)
    }
}

/// One class's bound: its cells cover the box's node grid, and the maximum
/// of their bounds (module docs), exactly. Each cell's bound
/// `c·(λ_R U + λ_ρ s) − μ a x − ν τ` is first evaluated in floating point:
/// the gain and the cost are sums of products of non-negative doubles (four
/// and three roundings), so the float value is within
/// `4·2⁻⁵³·(gain + cost)` of the exact one (`1e-15·(gain + cost)` plus
/// `1e-300` for subnormals is taken). A cell whose float value plus that
/// error is below the largest float value minus its error cannot hold the
/// exact maximum; every other cell is evaluated in rationals, and the
/// maximum is theirs.
fn class_bound(
    c: &ClassCertificate,
    t: &CheckedTable,
    (mu, nu): (f64, f64),
    (range_w, res_w): (f64, f64),
    angle_a: Option<f64>,
    field: &str,
) -> Result<BigRational, DetectionCertificateError> {
    let (nx, nt) = (t.x.len(), t.tau.len());
    let ux = if t.levels || nx == 1 { nx } else { nx - 1 };
    let ut = if nt == 1 { 1 } else { nt - 1 };
    let mut painted = vec![false; ux * ut];
    if !(c.weight.is_finite() && c.weight >= 0.0) {
        return Err(reject(format!("{field}.weight"), "not >= 0"));
    }
    // Per cell: (float value, its error bound, u at the upper corner).
    let mut floats: Vec<(f64, f64, f64)> = Vec::with_capacity(c.cells.len());
    for (j, &[k0, k1, l0, l1]) in c.cells.iter().enumerate() {
        let cf = format!("{field}.cells[{j}]");
        let (Some(rx), Some(rt)) = (units(k0, k1, nx, t.levels), units(l0, l1, nt, false)) else {
            return Err(reject(cf, "not a cell of the node grid"));
        };
        for a in rx {
            for bb in rt.clone() {
                painted[a * ut + bb] = true;
            }
        }
        let u = t.u[k1 * nt + l1]
            .ok_or_else(|| reject(&cf, "no envelope point at its upper corner"))?;
        let gain = c.weight * (range_w * u + res_w * t.sqrt_up[l1]);
        let cost = mu * angle_a.unwrap_or(t.tau[l0]) * t.x[k0] + nu * t.tau[l0];
        floats.push((gain - cost, 1e-15 * (gain + cost) + 1e-300, u));
    }
    if let Some(i) = painted.iter().position(|p| !p) {
        return Err(reject(
            format!("{field}.cells"),
            format!(
                "do not cover the box (power unit {}, dwell unit {})",
                i / ut,
                i % ut
            ),
        ));
    }
    let floor = floats
        .iter()
        .map(|&(v, e, _)| v - e)
        .fold(f64::NEG_INFINITY, f64::max);
    if !floor.is_finite() {
        return Err(reject(format!("{field}.cells"), "empty or not finite"));
    }
    let (mu_q, nu_q) = (q(mu), q(nu));
    let (weight, range_w, res_w) = (q(c.weight), q(range_w), q(res_w));
    let mut best: Option<BigRational> = None;
    for (&[k0, _, l0, l1], &(v, e, u)) in c.cells.iter().zip(&floats) {
        if v + e < floor {
            continue;
        }
        let gain = &weight * (&range_w * q(u) + &res_w * q(t.sqrt_up[l1]));
        let a = q(angle_a.unwrap_or(t.tau[l0]));
        let cost = &mu_q * a * q(t.x[k0]) + &nu_q * q(t.tau[l0]);
        let v = gain - cost;
        if best.as_ref().is_none_or(|b| v > *b) {
            best = Some(v);
        }
    }
    best.ok_or_else(|| reject(format!("{field}.cells"), "no cell reaches the maximum"))
}
