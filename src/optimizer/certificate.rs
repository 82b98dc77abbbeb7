//! Linear programs with an optimality certificate checked in exact rational
//! arithmetic, and their export (free MPS + `certificate.json`).
//!
//! A [`LinearProgram`] is `max cᵀx` subject to `r_lo ≤ A x ≤ r_hi` and
//! `x_lo ≤ x ≤ x_hi` (some columns integral): the exact-check view of a
//! good_lp [`Program`], read back from its constraints
//! ([`Program::view`]). HiGHS solves the program in floating point; nothing
//! it says is trusted. The certificate is built from:
//!
//! - **a primal point** `x` (HiGHS's, repaired by the caller to meet every
//!   bound and row): every number is converted *exactly* to a rational and
//!   every row and bound is checked exactly ([`check`]); its objective
//!   `cᵀx` is then an exact lower bound of the optimum;
//! - **row multipliers** `y` (HiGHS's row duals of the LP, or of the LP
//!   relaxation for a MILP). For *any* `y`, with the reduced costs
//!   `d = c − Aᵀy` computed exactly,
//!   `cᵀx = yᵀ(Ax) + dᵀx ≤ Σ_r max(y_r r_lo, y_r r_hi) + Σ_j max(d_j x_lo_j, d_j x_hi_j)`
//!   for every feasible `x` (each term is a linear function maximised over
//!   its interval), so the right-hand side, evaluated exactly, is an upper
//!   bound of the optimum (of the MILP too: its feasible set lies in the
//!   relaxation's). A multiplier whose sign would need an infinite row bound
//!   is set to 0 first (any `y` is allowed; this one only loosens nothing
//!   that was finite). Dual feasibility is therefore not an assumption but
//!   the finiteness of this sum; every column the optimizer builds is boxed,
//!   so the bound is always finite.
//!
//! `gap = upper_bound − objective ≥ 0` is exact; it is 0 only when the
//! floats happen to be exactly optimal, and otherwise states how far from
//! the optimum the answer can be.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};

use serde::Serialize;
use std::fmt::Write as _;

use super::error::CertificateError;
pub use super::program::{Program, SolveOptions, Solved};

/// One row: `lo ≤ Σ coef·x ≤ hi` (either side may be infinite).
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// (column, coefficient) pairs, one per column at most.
    pub coefs: Vec<(usize, f64)>,
    /// Lower bound (may be `-∞`).
    pub lo: f64,
    /// Upper bound (may be `+∞`).
    pub hi: f64,
}

/// `max cᵀx` s.t. rows and column bounds; some columns integral.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinearProgram {
    /// Objective coefficients `c`.
    pub cost: Vec<f64>,
    /// Column lower bounds.
    pub col_lo: Vec<f64>,
    /// Column upper bounds.
    pub col_hi: Vec<f64>,
    /// Integral columns.
    pub integer: Vec<bool>,
    /// Rows.
    pub rows: Vec<Row>,
}

impl LinearProgram {
    /// Adds a column to a view built by hand (tests of the checker and of
    /// the MPS export; the optimizer's views come from [`Program::view`]);
    /// returns its index.
    pub fn add_col(&mut self, lo: f64, hi: f64, cost: f64, integer: bool) -> usize {
        self.cost.push(cost);
        self.col_lo.push(lo);
        self.col_hi.push(hi);
        self.integer.push(integer);
        self.cost.len() - 1
    }

    /// Adds `lo ≤ Σ coefs ≤ hi` to a view built by hand (as
    /// [`Self::add_col`]); coefficients on one column are summed.
    pub fn add_row(&mut self, coefs: &[(usize, f64)], lo: f64, hi: f64) {
        let mut merged: Vec<(usize, f64)> = Vec::with_capacity(coefs.len());
        for &(j, a) in coefs {
            match merged.iter_mut().find(|e| e.0 == j) {
                Some(e) => e.1 += a,
                None => merged.push((j, a)),
            }
        }
        merged.retain(|e| e.1 != 0.0);
        self.rows.push(Row {
            coefs: merged,
            lo,
            hi,
        });
    }

    /// Whether any column is integral.
    #[must_use]
    pub fn is_mip(&self) -> bool {
        self.integer.iter().any(|&b| b)
    }

    /// This program with every finite row side moved outwards by
    /// `tol·(1 + Σ_j |a_j|)`: what a point HiGHS returns at primal
    /// feasibility tolerance `tol` (on rows and column bounds), with its
    /// columns then clamped into their bounds, meets exactly when HiGHS
    /// kept its tolerance (a row is off by at most `tol`, and the clamp
    /// moves it by at most `tol·Σ|a_j|`). A relaxation of this program, so
    /// an upper bound of it bounds this program too. Integral columns
    /// rounded by the caller are covered as long as HiGHS's integrality
    /// tolerance (`settings::mip_feasibility_tol`, 1e-10) is at most `tol`.
    #[must_use]
    pub fn widened(&self, tol: f64) -> Self {
        let mut out = self.clone();
        for r in &mut out.rows {
            let w = tol * (1.0 + r.coefs.iter().map(|(_, a)| a.abs()).sum::<f64>());
            // Rounded outwards (the sum and product above are floats).
            let w = w * (1.0 + 1e-12);
            if r.lo.is_finite() {
                r.lo = -widen_up(-r.lo, w);
            }
            if r.hi.is_finite() {
                r.hi = widen_up(r.hi, w);
            }
        }
        out
    }

    /// `x` clamped into the column bounds, integral columns rounded.
    #[must_use]
    pub fn clamped(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(j, &v)| {
                let v = if self.integer[j] { v.round() } else { v };
                v.clamp(self.col_lo[j], self.col_hi[j])
            })
            .collect()
    }

    /// The program in free MPS (shortest round-trip numbers, so HiGHS reads
    /// back exactly these doubles). Columns `x0…`, rows `r0…` in index order;
    /// `OBJSENSE MAX`.
    #[must_use]
    pub fn to_mps(&self) -> String {
        self.to_mps_named("gaze_lidar_power_step")
    }

    /// [`Self::to_mps`] under the MPS `NAME` given.
    #[must_use]
    pub fn to_mps_named(&self, name: &str) -> String {
        let mut s = format!("NAME {name}\nOBJSENSE\n    MAX\nROWS\n N obj\n");
        for (i, r) in self.rows.iter().enumerate() {
            let kind = match (r.lo.is_finite(), r.hi.is_finite()) {
                (true, true) if r.lo == r.hi => 'E',
                (_, true) => 'L',
                (true, false) => 'G',
                (false, false) => 'N',
            };
            let _ = writeln!(s, " {kind} r{i}");
        }
        self.mps_columns(&mut s);
        self.mps_rhs_and_ranges(&mut s);
        self.mps_bounds(&mut s);
        s.push_str("ENDATA\n");
        s
    }

    /// The MPS `COLUMNS` section: column-wise entries, integral columns
    /// between `INTORG`/`INTEND` markers.
    fn mps_columns(&self, s: &mut String) {
        let mut by_col: Vec<Vec<(usize, f64)>> = vec![Vec::new(); self.cost.len()];
        for (i, r) in self.rows.iter().enumerate() {
            for &(j, a) in &r.coefs {
                by_col[j].push((i, a));
            }
        }
        s.push_str("COLUMNS\n");
        let mut in_int = false;
        for (j, entries) in by_col.iter().enumerate() {
            if self.integer[j] != in_int {
                let tag = if self.integer[j] { "INTORG" } else { "INTEND" };
                let _ = writeln!(s, " MARKER 'MARKER' '{tag}'");
                in_int = self.integer[j];
            }
            // Always name the column (a zero cost keeps empty columns listed).
            let _ = writeln!(s, " x{j} obj {:?}", self.cost[j]);
            for &(i, a) in entries {
                let _ = writeln!(s, " x{j} r{i} {a:?}");
            }
        }
        if in_int {
            s.push_str(" MARKER 'MARKER' 'INTEND'\n");
        }
    }

    /// The MPS `RHS` section and, for two-sided rows, `RANGES`.
    fn mps_rhs_and_ranges(&self, s: &mut String) {
        s.push_str("RHS\n");
        for (i, r) in self.rows.iter().enumerate() {
            let rhs = if r.hi.is_finite() { r.hi } else { r.lo };
            if rhs.is_finite() && rhs != 0.0 {
                let _ = writeln!(s, " rhs r{i} {rhs:?}");
            }
        }
        let ranged: Vec<(usize, f64)> = self
            .rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.lo.is_finite() && r.hi.is_finite() && r.lo != r.hi)
            .map(|(i, r)| (i, r.hi - r.lo))
            .collect();
        if !ranged.is_empty() {
            s.push_str("RANGES\n");
            for (i, w) in ranged {
                let _ = writeln!(s, " rng r{i} {w:?}");
            }
        }
    }

    /// The MPS `BOUNDS` section.
    fn mps_bounds(&self, s: &mut String) {
        s.push_str("BOUNDS\n");
        for j in 0..self.cost.len() {
            let (lo, hi) = (self.col_lo[j], self.col_hi[j]);
            if lo == hi {
                let _ = writeln!(s, " FX bnd x{j} {lo:?}");
                continue;
            }
            if lo.is_finite() {
                let _ = writeln!(s, " LO bnd x{j} {lo:?}");
            } else {
                let _ = writeln!(s, " MI bnd x{j}");
            }
            if hi.is_finite() {
                let _ = writeln!(s, " UP bnd x{j} {hi:?}");
            } else {
                let _ = writeln!(s, " PL bnd x{j}");
            }
        }
    }
}

/// `v + w` rounded up (`v` finite, `w ≥ 0`): at least the exact sum.
fn widen_up(v: f64, w: f64) -> f64 {
    let s = v + w;
    -next_down(-s)
}

/// The exact verdict on a primal point and row multipliers.
#[derive(Debug, Clone, PartialEq)]
pub struct Exact {
    /// Every bound, row and integrality holds exactly.
    pub primal_feasible: bool,
    /// The first bound, row or integrality that does not (column or row index).
    pub violation: Option<String>,
    /// `cᵀx`, exact.
    pub objective: BigRational,
    /// The dual bound from `y` (see the module docs), exact; `None` when it
    /// is infinite (a needed column bound is infinite).
    pub upper_bound: Option<BigRational>,
}

impl Exact {
    /// `upper_bound − objective`, exact.
    #[must_use]
    pub fn gap(&self) -> Option<BigRational> {
        self.upper_bound.as_ref().map(|u| u - &self.objective)
    }
}

fn q(v: f64) -> BigRational {
    // Every finite double is a dyadic rational: exact conversion.
    BigRational::from_float(v).unwrap_or_else(BigRational::zero)
}

/// Checks `x` and `y` for `lp` in exact rational arithmetic (every sum of
/// products of doubles in a long fixed-point accumulator, [`super::exact`]).
#[must_use]
pub fn check(lp: &LinearProgram, x: &[f64], y: &[f64]) -> Exact {
    use super::exact::Sum;
    let n = lp.cost.len();
    let finite = x.len() == n && x.iter().all(|v| v.is_finite()) && y.iter().all(|v| v.is_finite());
    // The program's own numbers: a NaN or infinite cost or coefficient, or
    // a NaN bound, has no exact value (an infinite bound is "none").
    let program_finite = lp.cost.iter().all(|c| c.is_finite())
        && lp.col_lo.iter().chain(&lp.col_hi).all(|b| !b.is_nan())
        && lp
            .rows
            .iter()
            .all(|r| !r.lo.is_nan() && !r.hi.is_nan() && r.coefs.iter().all(|t| t.1.is_finite()));
    if !finite || !program_finite {
        return Exact {
            primal_feasible: false,
            violation: Some(
                "a value is not finite, or x has the wrong length, or the program has a non-finite cost, bound or coefficient"
                    .into(),
            ),
            objective: BigRational::zero(),
            upper_bound: None,
        };
    }
    let mut violation = primal_violation(lp, x, y);
    let mut objective = Sum::default();
    for (&c, &xj) in lp.cost.iter().zip(x) {
        objective.add_product(c, xj);
    }
    let (ub, mut ub_finite) = dual_bound(lp, y);
    if objective.overflowed() || ub.overflowed() {
        violation.get_or_insert_with(|| "a sum left the exact accumulator's range".to_owned());
        ub_finite = false;
    }
    Exact {
        primal_feasible: violation.is_none(),
        violation,
        objective: objective.rational(),
        upper_bound: ub_finite.then(|| ub.rational()),
    }
}

/// The first column bound, integrality or row that `x` breaks exactly (or a
/// `y` of the wrong length).
/// Whether `x` meets every bound, integrality and row of `lp` exactly.
#[must_use]
pub fn primal_feasible(lp: &LinearProgram, x: &[f64]) -> bool {
    x.len() == lp.cost.len() && primal_violation(lp, x, &vec![0.0; lp.rows.len()]).is_none()
}

fn primal_violation(lp: &LinearProgram, x: &[f64], y: &[f64]) -> Option<String> {
    use super::exact::Sum;
    use std::cmp::Ordering::{Greater, Less};
    let mut violation = (y.len() != lp.rows.len()).then(|| "y has the wrong length".to_owned());
    for (j, &xj) in x.iter().enumerate() {
        if xj < lp.col_lo[j] || xj > lp.col_hi[j] || (lp.integer[j] && xj.fract() != 0.0) {
            violation.get_or_insert_with(|| format!("column x{j} = {xj:?}"));
        }
    }
    for (i, r) in lp.rows.iter().enumerate() {
        let mut ax = Sum::default();
        for &(j, a) in &r.coefs {
            ax.add_product(a, x[j]);
        }
        if ax.overflowed()
            || (r.lo.is_finite() && ax.cmp_f64(r.lo) == Less)
            || (r.hi.is_finite() && ax.cmp_f64(r.hi) == Greater)
        {
            violation.get_or_insert_with(|| {
                format!(
                    "row r{i} (≈ {:?} in [{:?}, {:?}])",
                    rat_to_f64(&ax.rational()),
                    r.lo,
                    r.hi
                )
            });
        }
    }
    violation
}

/// The dual bound of `y` (module docs), exactly, and whether it is finite.
fn dual_bound(lp: &LinearProgram, y: &[f64]) -> (super::exact::Wide, bool) {
    use super::exact::{Sum, Wide};
    use std::cmp::Ordering::{Equal, Greater, Less};
    // Reduced costs d = c − Aᵀy, exactly, with y repaired to finite sides;
    // the bound Σ_r max(y_r lo_r, y_r hi_r) + Σ_j max(d_j lo_j, d_j hi_j).
    // Column by column (the rows' terms gathered per column first), so one
    // accumulator is reused instead of one per column (each is hundreds of
    // bytes: a vector of them for thousands of columns is megabytes).
    let n = lp.cost.len();
    let mut ub = Wide::default();
    let mut ub_finite = true;
    let mut start = vec![0usize; n + 1];
    let used = |r: &Row, yr: f64| {
        // A multiplier on an infinite side counts as 0.
        let usable = (yr <= 0.0 || r.hi.is_finite()) && (yr >= 0.0 || r.lo.is_finite());
        usable && yr != 0.0
    };
    for (r, &yr) in lp.rows.iter().zip(y) {
        if !used(r, yr) {
            continue;
        }
        for &(j, _) in &r.coefs {
            start[j + 1] += 1;
        }
        ub.add_product(yr, if yr > 0.0 { r.hi } else { r.lo });
    }
    for j in 0..n {
        start[j + 1] += start[j];
    }
    let mut next = start.clone();
    let mut terms = vec![(0.0f64, 0.0f64); start[n]];
    for (r, &yr) in lp.rows.iter().zip(y) {
        if !used(r, yr) {
            continue;
        }
        for &(j, a) in &r.coefs {
            terms[next[j]] = (-yr, a);
            next[j] += 1;
        }
    }
    for j in 0..n {
        let mut dj = Sum::default();
        dj.add(lp.cost[j]);
        for &(m, a) in &terms[start[j]..start[j + 1]] {
            dj.add_product(m, a);
        }
        let side = match dj.signum() {
            Equal => continue,
            Greater => lp.col_hi[j],
            Less => lp.col_lo[j],
        };
        if side.is_finite() {
            ub.add_scaled(&dj, side);
        } else {
            ub_finite = false;
        }
    }
    (ub, ub_finite)
}

/// The nearest double at or below `v` (a conservative rendering of an
/// exact figure that is reported as a float).
#[must_use]
pub fn to_f64_down(v: &BigRational) -> f64 {
    let f = rat_to_f64(v);
    if q(f) > *v {
        next_down(f)
    } else {
        f
    }
}

/// The nearest double at or above `v`.
#[must_use]
pub fn to_f64_up(v: &BigRational) -> f64 {
    let f = rat_to_f64(v);
    if q(f) < *v {
        -next_down(-f)
    } else {
        f
    }
}

/// The largest double below finite `f` (`f64::next_down`, stable only
/// since Rust 1.86; the crate supports 1.85).
#[must_use]
pub fn next_down(f: f64) -> f64 {
    if f == 0.0 {
        return -f64::from_bits(1);
    }
    let b = f.to_bits();
    f64::from_bits(if f > 0.0 { b - 1 } else { b + 1 })
}

fn rat_to_f64(v: &BigRational) -> f64 {
    use num_traits::ToPrimitive;
    v.to_f64()
        .unwrap_or(if v.is_negative() { f64::MIN } else { f64::MAX })
}

/// The exact rational as `"numerator/denominator"` (lowest terms).
#[must_use]
pub fn rational_string(v: &BigRational) -> String {
    let (n, d): (&BigInt, &BigInt) = (v.numer(), v.denom());
    format!("{n}/{d}")
}

/// `certificate.json`: the exported power-step LP's answer and its bound.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CertificateFile {
    /// Always `gaze-lidar/certificate@1`.
    pub format: String,
    /// What `problem.mps` is.
    pub problem: String,
    /// `maximise`.
    pub sense: String,
    /// How `y` is signed.
    pub dual_sign_convention: String,
    /// `cᵀx`, rounded down to a double (the exact value is `objective_exact`).
    pub objective: f64,
    /// The dual bound, rounded up to a double.
    pub upper_bound: f64,
    /// `upper_bound − objective` exact, rounded up.
    pub gap: f64,
    /// Exact `cᵀx` as `p/q`.
    pub objective_exact: String,
    /// Exact dual bound as `p/q`.
    pub upper_bound_exact: String,
    /// Exact gap as `p/q`.
    pub gap_exact: String,
    /// HiGHS's own MIP dual bound (a MILP only; not checked).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solver_dual_bound: Option<f64>,
    /// Primal values in the MPS column order (`x0`, `x1`, …).
    pub x: Vec<f64>,
    /// Row multipliers in the MPS row order (`r0`, `r1`, …).
    pub y: Vec<f64>,
}

/// Which step of the block-coordinate ascent a program belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The power step (dwell fixed).
    Power,
    /// The dwell step (power fixed).
    Dwell,
}

impl Step {
    /// `power` / `dwell`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Power => "power",
            Self::Dwell => "dwell",
        }
    }
}

/// The certified answer of one LP (or MILP).
#[derive(Debug, Clone, PartialEq)]
pub struct Certified {
    /// Whose program.
    pub step: Step,
    /// The program.
    pub lp: LinearProgram,
    /// The primal point (exactly feasible).
    pub x: Vec<f64>,
    /// The row multipliers.
    pub y: Vec<f64>,
    /// The exact figures.
    pub exact: Exact,
    /// HiGHS's MIP dual bound, if a MILP.
    pub solver_dual_bound: Option<f64>,
}

impl Certified {
    /// Checks `x`, `y` exactly; an error if `x` is not exactly feasible or
    /// the bound is infinite (neither happens for the optimizer's programs).
    pub fn new(
        step: Step,
        lp: LinearProgram,
        x: Vec<f64>,
        y: Vec<f64>,
        solver_dual_bound: Option<f64>,
    ) -> Result<Self, CertificateError> {
        let exact = check(&lp, &x, &y);
        if let Some(v) = &exact.violation {
            return Err(CertificateError::NotFeasible(v.clone()));
        }
        if exact.upper_bound.is_none() {
            return Err(CertificateError::Unbounded);
        }
        Ok(Self {
            step,
            lp,
            x,
            y,
            exact,
            solver_dual_bound,
        })
    }

    /// The program in free MPS, named after its step.
    #[must_use]
    pub fn mps(&self) -> String {
        self.lp
            .to_mps_named(&format!("gaze_lidar_{}_step", self.step.name()))
    }

    /// The step's figures (objective rounded down, bound and gap up).
    #[must_use]
    pub fn step_figures(&self, programs: usize) -> crate::profile::StepOptimality {
        let o = self.optimality();
        crate::profile::StepOptimality {
            objective: o.objective,
            upper_bound: o.upper_bound,
            gap: o.gap,
            exact: o.exact,
            programs,
        }
    }

    /// The `optimality` figures (objective rounded down, bound and gap up).
    #[must_use]
    pub fn optimality(&self) -> crate::profile::Optimality {
        let ub = self.exact.upper_bound.clone().unwrap_or_default();
        let gap = self.exact.gap().unwrap_or_default();
        crate::profile::Optimality {
            objective: to_f64_down(&self.exact.objective),
            upper_bound: to_f64_up(&ub),
            gap: to_f64_up(&gap),
            exact: gap.is_zero(),
            global: None,
            figures: None,
            eye_safety_tightening: None,
            dwell_step: None,
        }
    }

    /// `certificate.json`'s content.
    #[must_use]
    pub fn file(&self) -> CertificateFile {
        let ub = self.exact.upper_bound.clone().unwrap_or_default();
        let gap = self.exact.gap().unwrap_or_default();
        CertificateFile {
            format: "gaze-lidar/certificate@1".into(),
            problem: match (self.step, self.lp.is_mip()) {
                (Step::Power, true) => "the final power step (a MILP over hardware power levels) with the user's limits as the checker accepts them (the answer also meets the solved program's rows, which keep margins inside them); y are the row duals of the solved program's LP relaxation, so upper_bound bounds the MILP too".into(),
                (Step::Power, false) => "the final power step (an LP) with the user's limits as the checker accepts them (the answer also meets the solved program's rows, which keep margins inside them and may divide eye-safety limits by eye_safety_tightening); y are the solved program's row duals".into(),
                (Step::Dwell, true) => "the final dwell step (a MILP over spin set-points; rows widened by HiGHS's feasibility tolerance, specs/optimizer.md); y are the row duals of its LP relaxation, so upper_bound bounds the MILP too".into(),
                (Step::Dwell, false) => "the final dwell step (an LP; rows widened by HiGHS's feasibility tolerance, specs/optimizer.md)".into(),
            },
            sense: "maximise".into(),
            dual_sign_convention: "HiGHS's: reduced costs d = c - A^T y; for every feasible x, c^T x <= sum_r max(y_r*lo_r, y_r*hi_r) + sum_j max(d_j*lo_j, d_j*hi_j) = upper_bound (a multiplier whose side has an infinite bound counts as 0)".into(),
            objective: to_f64_down(&self.exact.objective),
            upper_bound: to_f64_up(&ub),
            gap: to_f64_up(&gap),
            objective_exact: rational_string(&self.exact.objective),
            upper_bound_exact: rational_string(&ub),
            gap_exact: rational_string(&gap),
            solver_dual_bound: self.solver_dual_bound,
            x: self.x.clone(),
            y: self.y.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn q(v: f64) -> BigRational {
        BigRational::from_float(v).unwrap()
    }

    /// The check written plainly in rationals (the reference): every row
    /// and bound compared exactly, the bound of the module docs summed
    /// term by term.
    fn reference(
        lp: &LinearProgram,
        x: &[f64],
        y: &[f64],
    ) -> (bool, BigRational, Option<BigRational>) {
        let mut feasible = true;
        for (j, &xj) in x.iter().enumerate() {
            feasible &= xj >= lp.col_lo[j] && xj <= lp.col_hi[j];
            feasible &= !lp.integer[j] || xj.fract() == 0.0;
        }
        for r in &lp.rows {
            let ax: BigRational = r.coefs.iter().map(|&(j, a)| q(a) * q(x[j])).sum();
            let below = r.lo.is_finite() && ax < q(r.lo);
            let above = r.hi.is_finite() && ax > q(r.hi);
            feasible &= !below && !above;
        }
        let objective: BigRational = lp.cost.iter().zip(x).map(|(&c, &v)| q(c) * q(v)).sum();
        let mut d: Vec<BigRational> = lp.cost.iter().map(|&c| q(c)).collect();
        let mut ub = Some(q(0.0));
        for (r, &yr) in lp.rows.iter().zip(y) {
            let usable = (yr <= 0.0 || r.hi.is_finite()) && (yr >= 0.0 || r.lo.is_finite());
            if !usable || yr == 0.0 {
                continue;
            }
            for &(j, a) in &r.coefs {
                d[j] -= q(yr) * q(a);
            }
            let side = if yr > 0.0 { r.hi } else { r.lo };
            ub = ub.map(|u| u + q(yr) * q(side));
        }
        for (j, dj) in d.iter().enumerate() {
            let zero = q(0.0);
            if *dj == zero {
                continue;
            }
            let side = if *dj > zero {
                lp.col_hi[j]
            } else {
                lp.col_lo[j]
            };
            ub = if side.is_finite() {
                ub.map(|u| u + dj * q(side))
            } else {
                None
            };
        }
        (feasible, objective, ub)
    }

    /// Values over a wide range of magnitudes (exponents far apart, so
    /// sums need many bits), both signs, and small integers (ties, exact
    /// feasibility at the bound).
    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            (-3i32..=3).prop_map(f64::from),
            (-1e3f64..1e3),
            (any::<bool>(), 0.5f64..2.0, -300i32..300)
                .prop_map(|(n, m, e)| if n { -m } else { m } * 2f64.powi(e)),
        ]
    }

    fn bound() -> impl Strategy<Value = f64> {
        prop_oneof![4 => value(), 1 => Just(f64::INFINITY), 1 => Just(f64::NEG_INFINITY)]
    }

    prop_compose! {
        fn program()(n in 1usize..6, m in 0usize..6)(
            cost in proptest::collection::vec(value(), n),
            bounds in proptest::collection::vec((bound(), bound()), n),
            rows in proptest::collection::vec(
                (proptest::collection::vec((0..n, value()), 1..5), bound(), bound()), m),
            x in proptest::collection::vec(value(), n),
            y in proptest::collection::vec(value(), m),
        ) -> (LinearProgram, Vec<f64>, Vec<f64>) {
            let mut lp = LinearProgram::default();
            for (&c, &(a, b)) in cost.iter().zip(&bounds) {
                lp.add_col(a.min(b), a.max(b), c, false);
            }
            for (coefs, a, b) in rows {
                lp.add_row(&coefs, a.min(b), a.max(b));
            }
            (lp, x, y)
        }
    }

    prop_compose! {
        /// A program, a point HiGHS might return at tolerance `tol` (each
        /// column within `tol` of its box, each row within `tol` of its
        /// sides), and `tol`.
        fn near_feasible()(n in 1usize..6, m in 1usize..6, e in -12i32..-3)(
            boxes in proptest::collection::vec((-1e3f64..1e3, 0.0f64..1e3), n),
            coefs in proptest::collection::vec(
                proptest::collection::vec((0..n, value()), 1..5), m),
            at in proptest::collection::vec(0.0f64..=1.0, n),
            out in proptest::collection::vec(-1.0f64..=1.0, n),
            sides in proptest::collection::vec((-1.0f64..=1.0, 0.0f64..10.0, any::<bool>()), m),
            tol in Just(10f64.powi(e)),
        ) -> (LinearProgram, Vec<f64>, f64) {
            let mut lp = LinearProgram::default();
            let mut x = Vec::with_capacity(boxes.len());
            for (j, &(lo, w)) in boxes.iter().enumerate() {
                lp.add_col(lo, lo + w, 0.0, false);
                // Inside the box, or past a bound by at most tol.
                let v = lo + w * at[j];
                x.push(if out[j] > 0.5 { lo + w + tol * out[j] } else if out[j] < -0.5 { lo + tol * out[j] } else { v });
            }
            for (c, &(off, w, eq)) in coefs.iter().zip(&sides) {
                lp.add_row(c, 0.0, 0.0);
                let r = lp.rows.last_mut().unwrap();
                let ax: f64 = r.coefs.iter().map(|&(j, a)| a * x[j]).sum();
                // The point is off the row by at most tol·|off| (< tol,
                // less a float's rounding of `ax`, covered below).
                let lo = ax + 0.9 * tol * off;
                r.lo = lo;
                r.hi = if eq { lo } else { lo + w };
            }
            (lp, x, tol)
        }
    }

    proptest! {
        // Rejects: generated points whose rows miss the premise exactly
        // (about two in three at large activities and small `tol`).
        #![proptest_config(ProptestConfig { max_global_rejects: 20_000, ..ProptestConfig::with_cases(500) })]

        /// `widened`'s claim: a point within `tol` of every row and bound,
        /// clamped, meets the program widened by `tol` exactly; and the
        /// widened program contains the original.
        #[test]
        fn a_near_feasible_point_clamped_meets_the_widened_program_exactly(
            (lp, x, tol) in near_feasible()
        ) {
            // The claim's premise, exactly: the point is within `tol` of
            // every row (a generated row edge is a double near `a·x`, which
            // can miss it by more than `tol` when `|a·x|` is large).
            for r in &lp.rows {
                let ax: BigRational = r.coefs.iter().map(|&(j, a)| q(a) * q(x[j])).sum();
                prop_assume!(ax >= q(r.lo) - q(tol) && ax <= q(r.hi) + q(tol));
            }
            let wide = lp.widened(tol);
            for (r, w) in lp.rows.iter().zip(&wide.rows) {
                prop_assert!(w.lo <= r.lo && w.hi >= r.hi);
                let need = q(tol) * (q(1.0) + r.coefs.iter().map(|&(_, a)| q(a.abs())).sum::<BigRational>());
                prop_assert!(q(r.lo) - q(w.lo) >= need && q(w.hi) - q(r.hi) >= need);
            }
            let e = check(&wide, &lp.clamped(&x), &vec![0.0; lp.rows.len()]);
            prop_assert!(e.primal_feasible, "{:?}", e.violation);
        }

        #[test]
        fn check_agrees_with_plain_rationals((lp, x, y) in program()) {
            let e = check(&lp, &x, &y);
            let (feasible, objective, ub) = reference(&lp, &x, &y);
            prop_assert_eq!(e.primal_feasible, feasible);
            prop_assert_eq!(e.objective, objective);
            prop_assert_eq!(e.upper_bound, ub);
        }
    }
}
