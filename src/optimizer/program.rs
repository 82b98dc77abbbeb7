//! The optimizer's programs as good_lp models, solved by HiGHS.
//!
//! A [`Program`] holds good_lp variables (boxed, some integral), the
//! objective (maximised) and named good_lp [`Constraint`]s, each one-sided
//! or an equality (good_lp's constraints are; a two-sided family such as
//! `slew` or `accel` is two rows, `≤` then `≥`). HiGHS gets the model
//! through good_lp's `highs` solver (`HighsProblem::try_into_inner`, so the
//! options, the hot start, the row duals and the MIP dual bound stay
//! reachable), one row per constraint in the order they were added.
//!
//! The exact certificate never sees anything but these constraints:
//! [`Program::view`] reads every constraint back through good_lp's
//! accessors (`Constraint::expression`, `is_equality`) into the
//! [`LinearProgram`] that [`super::certificate::check`] checks, row for row
//! the rows HiGHS solved (a `≥` constraint, stored by good_lp as
//! `lo − a·x ≤ 0`, as `a·x ≥ lo`, the row HiGHS got), so HiGHS's row duals
//! are the certificate's multipliers as they are.

use std::collections::HashMap;

use good_lp::solvers::highs::highs;
use good_lp::{
    variable, Constraint, Expression, IntoAffineExpression, ProblemVariables, SolverModel, Variable,
};

use super::certificate::{LinearProgram, Row};
use super::error::Infeasible;
use super::settings::S;
use super::OptError;

/// How a constraint was written (good_lp stores every inequality as
/// `expression ≤ 0`; the row HiGHS gets keeps the written direction).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sense {
    AtMost,
    AtLeast,
    Equal,
}

/// One boxed column.
#[derive(Debug, Clone, Copy)]
struct Column {
    lo: f64,
    hi: f64,
    cost: f64,
    integer: bool,
}

/// A good_lp model: `max cᵀx` subject to named constraints and column boxes.
#[derive(Clone, Default)]
pub struct Program {
    columns: Vec<Column>,
    /// Where the variables come from (their definitions are `columns`).
    names: ProblemVariables,
    vars: Vec<Variable>,
    index: HashMap<Variable, usize>,
    constraints: Vec<(Constraint, Sense)>,
    /// Rows whose finite side the user's problem puts further out than
    /// the program HiGHS solves (see [`Self::relax_row`]): row → side.
    outer_rows: HashMap<usize, f64>,
    /// Columns whose box the user's problem puts further out: column →
    /// (lo, hi).
    outer_cols: HashMap<usize, (f64, f64)>,
}

impl Program {
    /// Adds a column `lo ≤ x ≤ hi` of objective coefficient `cost`.
    pub fn column(&mut self, lo: f64, hi: f64, cost: f64, integer: bool) -> Variable {
        // Variables are indices: the same definitions in the same order
        // give the same variables in the `ProblemVariables` HiGHS gets.
        let v = self.names.add(variable());
        self.index.insert(v, self.vars.len());
        self.vars.push(v);
        self.columns.push(Column {
            lo,
            hi,
            cost,
            integer,
        });
        v
    }

    /// The column index of `v` (a variable of this program).
    #[must_use]
    pub fn col(&self, v: Variable) -> usize {
        self.index[&v]
    }

    /// Number of columns.
    #[must_use]
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    /// No columns.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }

    /// The box of column `j`.
    #[must_use]
    pub fn bounds(&self, j: usize) -> (f64, f64) {
        (self.columns[j].lo, self.columns[j].hi)
    }

    /// The objective coefficient of column `j`.
    #[must_use]
    pub fn cost(&self, j: usize) -> f64 {
        self.columns[j].cost
    }

    /// Adds `c` to the objective coefficient of column `j`.
    pub fn add_cost(&mut self, j: usize, c: f64) {
        self.columns[j].cost += c;
    }

    /// Number of constraints (rows) so far: the next one's index.
    #[must_use]
    pub fn rows(&self) -> usize {
        self.constraints.len()
    }

    /// Whether any column is integral.
    #[must_use]
    pub fn is_mip(&self) -> bool {
        self.columns.iter().any(|c| c.integer)
    }

    fn push(&mut self, name: &str, c: Constraint, sense: Sense) -> usize {
        self.constraints.push((c.set_name(name.to_owned()), sense));
        self.constraints.len() - 1
    }

    /// `e ≤ hi`, named; returns its row.
    pub fn at_most(&mut self, name: &str, e: Expression, hi: f64) -> usize {
        self.push(name, nonzero(e).leq(hi), Sense::AtMost)
    }

    /// `e ≥ lo`, named; returns its row.
    pub fn at_least(&mut self, name: &str, e: Expression, lo: f64) -> usize {
        self.push(name, nonzero(e).geq(lo), Sense::AtLeast)
    }

    /// `e = v`, named; returns its row.
    pub fn equal(&mut self, name: &str, e: Expression, v: f64) -> usize {
        self.push(name, nonzero(e).eq(v), Sense::Equal)
    }

    /// `lo ≤ e ≤ hi` as two rows (`≤` then `≥`); returns both.
    pub fn between(&mut self, name: &str, e: Expression, lo: f64, hi: f64) -> (usize, usize) {
        let upper = self.at_most(name, e.clone(), hi);
        let lower = self.at_least(name, e, lo);
        (upper, lower)
    }

    /// Records that the user's problem holds row `row` only to `side` (its
    /// finite side, in the orientation [`Self::view`] gives: the `hi` of a
    /// `≤` row, the `lo` of a `≥` row), further out than the side HiGHS
    /// gets: the margins the program keeps inside the limits.
    /// [`Self::outer_view`] is the program with these sides, a relaxation
    /// of the solved one whose dual bound bounds every point the limits
    /// (as the checker accepts them) allow.
    pub fn relax_row(&mut self, row: usize, side: f64) {
        self.outer_rows.insert(row, side);
    }

    /// As [`Self::relax_row`] for column `j`'s box.
    pub fn relax_col(&mut self, j: usize, lo: f64, hi: f64) {
        self.outer_cols.insert(j, (lo, hi));
    }

    /// [`Self::view`] with the sides and boxes of [`Self::relax_row`] and
    /// [`Self::relax_col`] (only ever further out).
    #[must_use]
    pub fn outer_view(&self) -> LinearProgram {
        let mut lp = self.view();
        for (&k, &side) in &self.outer_rows {
            let r = &mut lp.rows[k];
            if r.hi.is_finite() && r.lo.is_infinite() {
                r.hi = r.hi.max(side);
            } else if r.lo.is_finite() && r.hi.is_infinite() {
                r.lo = r.lo.min(side);
            }
        }
        for (&j, &(lo, hi)) in &self.outer_cols {
            lp.col_lo[j] = lp.col_lo[j].min(lo);
            lp.col_hi[j] = lp.col_hi[j].max(hi);
        }
        lp
    }

    /// The constraints' names, row order.
    #[must_use]
    pub fn names(&self) -> Vec<&str> {
        self.constraints
            .iter()
            .map(|(c, _)| c.name().unwrap_or(""))
            .collect()
    }

    /// `e` at the point `x` (one value per column), floating point.
    #[must_use]
    pub fn eval(&self, e: &Expression, x: &[f64]) -> f64 {
        let mut terms: Vec<(usize, f64)> = e
            .linear_coefficients()
            .map(|(v, a)| (self.col(v), a))
            .collect();
        // Column order: the same sum every run.
        terms.sort_by_key(|t| t.0);
        terms.iter().map(|&(j, a)| a * x[j]).sum::<f64>() + IntoAffineExpression::constant(e)
    }

    /// The exact-check view, read back from the good_lp constraints: per
    /// constraint one row over its coefficients (column order, exact zeros
    /// dropped), the row HiGHS solved.
    #[must_use]
    pub fn view(&self) -> LinearProgram {
        let rows = self
            .constraints
            .iter()
            .map(|(c, sense)| {
                let e = c.expression();
                let mut coefs: Vec<(usize, f64)> = e
                    .linear_coefficients()
                    .map(|(v, a)| (self.col(v), a))
                    .filter(|t| t.1 != 0.0)
                    .collect();
                coefs.sort_by_key(|t| t.0);
                // `e ≤ 0` (or `= 0`) with `e = a·x + k`: `a·x ≤ −k`; a `≥`
                // row was stored negated: `(−a)·x ≥ k`.
                let k = IntoAffineExpression::constant(e);
                let (lo, hi) = match sense {
                    Sense::AtMost => (f64::NEG_INFINITY, -k),
                    Sense::Equal => (-k, -k),
                    Sense::AtLeast => {
                        for t in &mut coefs {
                            t.1 = -t.1;
                        }
                        (k, f64::INFINITY)
                    }
                };
                Row { coefs, lo, hi }
            })
            .collect();
        LinearProgram {
            cost: self.columns.iter().map(|c| c.cost).collect(),
            col_lo: self.columns.iter().map(|c| c.lo).collect(),
            col_hi: self.columns.iter().map(|c| c.hi).collect(),
            integer: self.columns.iter().map(|c| c.integer).collect(),
            rows,
        }
    }

    /// The power of two HiGHS's objective is multiplied by: 1 unless every
    /// cost is below [`S`]`.objective_scale_below` in magnitude, then the
    /// one that brings the largest into `[1, 2)`. HiGHS's dual feasibility
    /// tolerance is absolute (1e-7): costs of that size (small objective
    /// weights: weights are relative) would read as zero, and the answer
    /// would depend on the weights' scale. A power of two scales exactly.
    fn objective_scale(&self) -> f64 {
        let top = self
            .columns
            .iter()
            .fold(0.0_f64, |m, c| m.max(c.cost.abs()));
        if !(top.is_normal() && top < S.objective_scale_below) {
            return 1.0;
        }
        let e = top.log2().floor();
        2.0_f64.powi(-(e as i32))
    }

    /// Every cost, bound and coefficient a number HiGHS and the exact
    /// checker can take (costs and coefficients finite, bounds not NaN):
    /// a NaN from a degenerate model is an internal error, never an
    /// "optimal" answer.
    fn check_finite(&self, what: &str) -> Result<(), OptError> {
        let bad_column = self
            .columns
            .iter()
            .position(|c| !c.cost.is_finite() || c.lo.is_nan() || c.hi.is_nan());
        if let Some(j) = bad_column {
            let c = self.columns[j];
            return Err(OptError::Solver(format!(
                "{what} step: column {j} has cost {} and bounds [{}, {}]: not a finite program",
                c.cost, c.lo, c.hi
            )));
        }
        for (k, (c, _)) in self.constraints.iter().enumerate() {
            let e = c.expression();
            let k0 = IntoAffineExpression::constant(e);
            if k0.is_nan() || e.linear_coefficients().any(|(_, a)| !a.is_finite()) {
                return Err(OptError::Solver(format!(
                    "{what} step: row {k} has a non-finite coefficient: not a finite program"
                )));
            }
        }
        Ok(())
    }

    /// The program as a HiGHS model through good_lp (integrality dropped
    /// when `relax`); HiGHS refusing it (a coefficient or a bound it cannot
    /// take, e.g. from limits of no physical size) is a solver error, never
    /// a panic.
    fn highs_model(
        &self,
        relax: bool,
        nodes: i32,
        what: &str,
        opts: &SolveOptions<'_>,
    ) -> Result<highs::Model, OptError> {
        let mut vars = ProblemVariables::new();
        let mut objective = Expression::with_capacity(self.columns.len());
        let scale = self.objective_scale();
        for (c, &v) in self.columns.iter().zip(&self.vars) {
            let def = variable().min(c.lo).max(c.hi);
            let added = vars.add(if c.integer && !relax {
                def.integer()
            } else {
                def
            });
            debug_assert_eq!(added, v);
            objective.add_mul(c.cost * scale, v);
        }
        let mut pb = vars.maximise(objective).using(highs);
        for (c, _) in &self.constraints {
            pb.add_constraint(c.clone());
        }
        let mut m = pb.try_into_inner().map_err(|e| {
            OptError::Solver(format!("{what} step: HiGHS refused the program ({e})"))
        })?;
        // Pinned for determinism (one thread, fixed seed); MILPs to optimality.
        m.set_option("threads", 1);
        m.set_option("random_seed", 0);
        m.set_option("mip_rel_gap", 0.0);
        m.set_option("mip_abs_gap", 1e-12);
        if !relax && self.is_mip() {
            // A primal heuristic only (the search still closes the gap to
            // zero): measured, it costs more than it saves on the power
            // steps' multiple-choice programs.
            m.set_option("mip_heuristic_run_feasibility_jump", false);
            // A deterministic work limit (nodes, not seconds): see
            // `settings::mip_max_nodes`.
            m.set_option("mip_max_nodes", nodes);
            m.set_option("mip_detect_symmetry", false);
            // HiGHS accepts a MILP's rows (and integrality) to this
            // tolerance, absolute; its default, 1e-6, lets a level choice
            // overspend the budget by far more than the checker's relative
            // 1e-9. Its minimum.
            m.set_option("mip_feasibility_tolerance", S.mip_feasibility_tol);
        }
        // Measured on the shipped configs' power steps and global bound
        // (360 bins): HiGHS's presolve costs more than it saves on these
        // programs (boxed segment columns, few rows): 1.9× (power) to 3×
        // (global bound) faster without it; and on the power steps' MILPs
        // (`multi_level`, one-hot levels and eye-safety column bounds)
        // 1.45× whole process, same answers (the search still closes the
        // gap to zero). The dwell steps' programs (`smooth`: the
        // acceleration rows between neighbouring bins) are the other way:
        // 1.3× faster with it, the same answers; they ask for it.
        m.set_option("presolve", if opts.presolve { "on" } else { "off" });
        m.set_option(
            "primal_feasibility_tolerance",
            opts.primal_feasibility_tolerance,
        );
        if let Some(x0) = opts.initial {
            // A hot start (HiGHS's `setSolution`): a wrong length is the
            // caller's bug, refused by HiGHS, and only costs the hot start.
            let _ = m.try_set_solution(Some(x0), None, None, None);
        }
        Ok(m)
    }

    /// Solves with HiGHS; for a MILP also solves the LP relaxation for the
    /// row multipliers of the certificate.
    pub fn solve(&self, what: &str) -> Result<Solved, OptError> {
        self.solve_with(what, &SolveOptions::default())
    }

    /// One HiGHS run; `Ok(None)`: the node limit came without an incumbent.
    fn run(
        &self,
        relax: bool,
        nodes: i32,
        what: &str,
        opts: &SolveOptions<'_>,
    ) -> Result<Option<highs::SolvedModel>, OptError> {
        self.finish(self.highs_model(relax, nodes, what, opts)?, relax, what)
    }

    /// Solves `model` (this program's, integrality dropped when `relax`)
    /// and reads HiGHS's status: an optimum, a MILP's incumbent at the node
    /// limit (`Ok(None)` when there is none), or why not.
    fn finish(
        &self,
        model: highs::Model,
        relax: bool,
        what: &str,
    ) -> Result<Option<highs::SolvedModel>, OptError> {
        let solved = model
            .try_solve()
            .map_err(|e| OptError::Solver(format!("{what} step: {e:?}")))?;
        match solved.status() {
            highs::HighsModelStatus::Optimal => Ok(Some(solved)),
            // The node limit of a MILP's branch and bound, with an
            // incumbent: a feasible point (checked exactly like any other);
            // its gap is stated, not assumed zero. Without one, the search
            // goes on without the limit.
            highs::HighsModelStatus::ReachedSolutionLimit if !relax && self.is_mip() => Ok((solved
                .primal_solution_status()
                == highs::HighsSolutionStatus::Feasible)
                .then_some(solved)),
            highs::HighsModelStatus::Infeasible => Err(Infeasible::Step {
                step: what.to_owned(),
            }
            .into()),
            s => Err(OptError::Solver(format!("{what} step: HiGHS status {s:?}"))),
        }
    }

    /// [`Self::run`] under the node limit, then without it when the limit
    /// came without an incumbent.
    fn run_limited(
        &self,
        relax: bool,
        what: &str,
        opts: &SolveOptions<'_>,
    ) -> Result<highs::SolvedModel, OptError> {
        match self.run(relax, S.mip_max_nodes, what, opts)? {
            Some(solved) => Ok(solved),
            None => self
                .run(relax, S.mip_max_nodes_without_incumbent, what, opts)?
                .ok_or_else(|| {
                    Infeasible::NoIncumbent {
                        step: what.to_owned(),
                        nodes: S.mip_max_nodes_without_incumbent,
                    }
                    .into()
                }),
        }
    }

    /// [`Self::solve`] with options (a hot start, a feasibility tolerance).
    pub fn solve_with(&self, what: &str, opts: &SolveOptions<'_>) -> Result<Solved, OptError> {
        self.check_finite(what)?;
        // HiGHS solved `max (s·c)ᵀx`: its objective, bound and row duals
        // are `s` times this program's (`s` a power of two: exact).
        let s = self.objective_scale();
        let unscale = |v: Vec<f64>| -> Vec<f64> { v.into_iter().map(|y| y / s).collect() };
        if !self.is_mip() {
            let main = self.run_limited(false, what, opts)?;
            let sol = main.get_solution();
            return Ok(Solved {
                x: sol.columns().to_vec(),
                y: unscale(sol.dual_rows().to_vec()),
                solver_objective: main.objective_value() / s,
                solver_dual_bound: None,
            });
        }
        // A MILP: its LP relaxation first (its row duals are the
        // certificate's multipliers anyway). When the relaxation's optimum
        // is integral (within `relaxation_integrality_tol`), it is the
        // MILP's optimum (the relaxation bounds the MILP and this point is
        // a MILP point), so the branch and bound is skipped; the point is
        // still checked exactly by the certificate. Otherwise HiGHS's MIP
        // solver runs.
        if let Some(done) = self.closed_form_relaxation(opts) {
            return Ok(done);
        }
        let relaxed = self.run_limited(true, what, opts)?;
        let rsol = relaxed.get_solution();
        let y = unscale(rsol.dual_rows().to_vec());
        let integral = rsol
            .columns()
            .iter()
            .zip(&self.columns)
            .all(|(v, c)| !c.integer || (v - v.round()).abs() <= S.relaxation_integrality_tol);
        let (x, solver_objective, solver_dual_bound) = if integral {
            let x = rsol
                .columns()
                .iter()
                .zip(&self.columns)
                .map(|(&v, c)| if c.integer { v.round() } else { v })
                .collect();
            let obj = relaxed.objective_value() / s;
            (x, obj, Some(obj))
        } else {
            let bound = relaxed.objective_value() / s;
            // A primal heuristic's point, kept only if it meets every bound,
            // row and integrality exactly.
            let start = opts
                .heuristic
                .and_then(|h| h.start(rsol.columns(), &y))
                .filter(|x0| super::certificate::primal_feasible(&self.view(), x0))
                .map(|x0| {
                    let obj: f64 = x0.iter().zip(&self.columns).map(|(v, c)| v * c.cost).sum();
                    (x0, obj)
                });
            match start {
                // Within `mip_heuristic_gap` of the relaxation's optimum (a
                // bound of the MILP's): no branch and bound could improve
                // it by more.
                Some((x0, obj))
                    if bound - obj
                        <= opts
                            .heuristic
                            .map_or(S.mip_heuristic_gap, |h| h.accept_gap())
                            * bound.abs().max(f64::MIN_POSITIVE) =>
                {
                    (x0, obj, Some(bound))
                }
                start => {
                    // HiGHS's search, from the heuristic's point when there
                    // is one; the better of the two.
                    let with_start = SolveOptions {
                        initial: start.as_ref().map(|s| &s.0[..]).or(opts.initial),
                        ..*opts
                    };
                    let main = self.run_limited(false, what, &with_start)?;
                    let found = (
                        main.get_solution().columns().to_vec(),
                        main.objective_value() / s,
                        main.double_info_value(c"mip_dual_bound")
                            .ok()
                            .map(|b| b / s),
                    );
                    match start {
                        Some((x0, obj)) if obj > found.1 => (x0, obj, found.2),
                        _ => found,
                    }
                }
            }
        };
        Ok(Solved {
            x,
            y,
            solver_objective,
            solver_dual_bound,
        })
    }
}

/// A HiGHS model kept from one solve of a cutting-plane loop to the next
/// ([`Program::solve_warm`]): the model as HiGHS left it (its optimal
/// basis), the view of the program it holds, its objective scale and
/// feasibility tolerance, and a handle per column.
#[derive(Default)]
pub struct Warm {
    kept: Option<Kept>,
    /// Solves that re-used the held model.
    reused: usize,
}

struct Kept {
    model: highs::Model,
    view: LinearProgram,
    scale: f64,
    tolerance: f64,
    cols: Vec<highs::Col>,
}

impl Kept {
    /// Whether `view` is the held program with rows appended and costs or
    /// column boxes changed (the same columns, the held rows as its first
    /// rows, no integral column): what a cutting-plane round makes.
    fn extends_to(&self, view: &LinearProgram, scale: f64, tolerance: f64) -> bool {
        let held = &self.view;
        scale == self.scale
            && tolerance == self.tolerance
            && held.cost.len() == view.cost.len()
            && !view.integer.iter().any(|&i| i)
            && held.rows.len() <= view.rows.len()
            && held.rows[..] == view.rows[..held.rows.len()]
    }

    /// Brings the held model to `view` (which [`Self::extends_to`] it):
    /// changed costs and boxes, then the new rows. HiGHS keeps its basis
    /// (the new rows basic), so the next solve starts from the last optimum.
    fn patch(&mut self, view: &LinearProgram) -> Result<(), highs::HighsStatus> {
        for j in 0..view.cost.len() {
            if view.cost[j] != self.view.cost[j] {
                self.model
                    .change_column_cost(self.cols[j], view.cost[j] * self.scale);
            }
            if view.col_lo[j] != self.view.col_lo[j] || view.col_hi[j] != self.view.col_hi[j] {
                self.model
                    .change_column_bounds(self.cols[j], view.col_lo[j]..=view.col_hi[j]);
            }
        }
        for r in &view.rows[self.view.rows.len()..] {
            let factors = r.coefs.iter().map(|&(j, a)| (self.cols[j], a));
            self.model.try_add_row(r.lo..=r.hi, factors)?;
        }
        Ok(())
    }
}

/// HiGHS's handles of columns `0..n` (a column handle is its index; the
/// `highs` crate makes them only as columns are added, so they are taken
/// from a scratch problem of `n` columns).
fn col_handles(n: usize) -> Vec<highs::Col> {
    let mut scratch = highs::RowProblem::default();
    (0..n).map(|_| scratch.add_column(0.0, 0.0..=0.0)).collect()
}

impl Program {
    /// [`Self::solve_with`] for the programs of a cutting-plane loop: when
    /// this LP extends the one `warm` holds (the same columns, its rows
    /// first, costs or boxes changed — a round that added cuts), HiGHS
    /// re-solves the held model with the difference applied, from its last
    /// optimal basis (the dual simplex from a dual-feasible start), instead
    /// of from scratch; otherwise (a MILP, a hot start asked, a program of
    /// another shape) a fresh model as [`Self::solve_with`]. Either way
    /// the answer is HiGHS's optimum of this program, checked as every
    /// other; a warm start may end at another optimal vertex where the
    /// optimum is not unique. `warm` then holds this program's model.
    pub fn solve_warm(
        &self,
        what: &str,
        opts: &SolveOptions<'_>,
        warm: &mut Warm,
    ) -> Result<Solved, OptError> {
        if self.is_mip() || opts.initial.is_some() {
            warm.kept = None;
            return self.solve_with(what, opts);
        }
        self.check_finite(what)?;
        let view = self.view();
        let s = self.objective_scale();
        let tolerance = opts.primal_feasibility_tolerance;
        let held = warm
            .kept
            .take()
            .filter(|k| k.extends_to(&view, s, tolerance))
            .and_then(|mut k| k.patch(&view).is_ok().then_some(k));
        warm.reused += usize::from(held.is_some());
        let (model, cols) = match held {
            Some(k) => (k.model, k.cols),
            None => (
                self.highs_model(false, S.mip_max_nodes, what, opts)?,
                col_handles(view.cost.len()),
            ),
        };
        let solved = self.finish(model, false, what)?.ok_or_else(|| {
            OptError::Solver(format!("{what} step: HiGHS stopped without an answer"))
        })?;
        let sol = solved.get_solution();
        let out = Solved {
            x: sol.columns().to_vec(),
            y: sol.dual_rows().iter().map(|y| y / s).collect(),
            solver_objective: solved.objective_value() / s,
            solver_dual_bound: None,
        };
        warm.kept = Some(Kept {
            model: highs::Model::from(solved),
            view,
            scale: s,
            tolerance,
            cols,
        });
        Ok(out)
    }
}

impl Program {
    /// A MILP whose heuristic knows the relaxation's multipliers in closed
    /// form ([`Heuristic::duals`]): their bound (the relaxation's optimum,
    /// in floating point) and the heuristic's point, when the point meets
    /// every row exactly and is within `mip_heuristic_gap` of the bound;
    /// else `None` and HiGHS solves the relaxation as for any MILP.
    fn closed_form_relaxation(&self, opts: &SolveOptions<'_>) -> Option<Solved> {
        let h = opts.heuristic?;
        let y = h.duals(self.rows())?;
        let view = self.view();
        let bound = float_dual_bound(&view, &y)?;
        let x0 = h.start(&[], &y)?;
        if !super::certificate::primal_feasible(&view, &x0) {
            return None;
        }
        let obj: f64 = x0.iter().zip(&self.columns).map(|(v, c)| v * c.cost).sum();
        (bound - obj <= h.accept_gap() * bound.abs().max(f64::MIN_POSITIVE)).then_some(Solved {
            x: x0,
            y,
            solver_objective: obj,
            solver_dual_bound: Some(bound),
        })
    }
}

/// The dual bound of `y` over `lp` (the certificate's formula, in floating
/// point: only to compare with a heuristic's point; the certificate
/// computes it exactly); `None` where a side it needs is infinite.
fn float_dual_bound(lp: &LinearProgram, y: &[f64]) -> Option<f64> {
    if y.len() != lp.rows.len() {
        return None;
    }
    let mut d = lp.cost.clone();
    let mut ub = 0.0;
    for (r, &yr) in lp.rows.iter().zip(y) {
        if yr == 0.0 {
            continue;
        }
        let side = if yr > 0.0 { r.hi } else { r.lo };
        if !side.is_finite() {
            return None;
        }
        for &(j, a) in &r.coefs {
            d[j] -= yr * a;
        }
        ub += yr * side;
    }
    for (j, &dj) in d.iter().enumerate() {
        let side = if dj > 0.0 { lp.col_hi[j] } else { lp.col_lo[j] };
        if dj != 0.0 {
            if !side.is_finite() {
                return None;
            }
            ub += dj * side;
        }
    }
    Some(ub)
}

impl LinearProgram {
    /// Solves a view built by hand (tests of the checker and of the
    /// export) through a good_lp [`Program`] of the same columns and rows
    /// (a ranged row as its two one-sided rows, whose multipliers are summed
    /// back into the row's: the same bound, row for row).
    pub fn solve(&self, what: &str) -> Result<Solved, OptError> {
        let mut prog = Program::default();
        let vars: Vec<Variable> = (0..self.cost.len())
            .map(|j| {
                prog.column(
                    self.col_lo[j],
                    self.col_hi[j],
                    self.cost[j],
                    self.integer[j],
                )
            })
            .collect();
        let mut rows_of = Vec::with_capacity(self.rows.len());
        for r in &self.rows {
            let mut e = Expression::with_capacity(r.coefs.len());
            for &(j, a) in &r.coefs {
                e.add_mul(a, vars[j]);
            }
            rows_of.push(match (r.lo.is_finite(), r.hi.is_finite()) {
                (true, true) if r.lo == r.hi => vec![prog.equal("row", e, r.lo)],
                (true, true) => {
                    let (u, l) = prog.between("row", e, r.lo, r.hi);
                    vec![u, l]
                }
                (false, true) => vec![prog.at_most("row", e, r.hi)],
                (true, false) => vec![prog.at_least("row", e, r.lo)],
                (false, false) => vec![],
            });
        }
        let mut solved = prog.solve(what)?;
        solved.y = rows_of
            .iter()
            .map(|rows| rows.iter().map(|&k| solved.y[k]).sum())
            .collect();
        Ok(solved)
    }
}

/// `e` without its exact-zero coefficients (HiGHS gets no zero entries).
fn nonzero(e: Expression) -> Expression {
    if (&e).linear_coefficients().all(|(_, a)| a != 0.0) {
        return e;
    }
    let mut out = Expression::with_capacity(0);
    for (v, a) in (&e).linear_coefficients() {
        if a != 0.0 {
            out.add_mul(a, v);
        }
    }
    out + IntoAffineExpression::constant(&e)
}

/// A MILP's primal heuristic: from the LP relaxation's point and row
/// duals, a point of the MILP (one value per column), or `None`.
pub trait Heuristic {
    /// The point; the caller checks it exactly before using it. `relaxed`
    /// is empty when the relaxation was not solved by HiGHS (see
    /// [`Heuristic::duals`]).
    fn start(&self, relaxed: &[f64], duals: &[f64]) -> Option<Vec<f64>>;

    /// The LP relaxation's row multipliers (one per row of a program of
    /// `rows` rows) when the heuristic knows them in closed form, else
    /// `None` (HiGHS solves the relaxation). Only a bound: the certificate
    /// checks them exactly like HiGHS's.
    fn duals(&self, rows: usize) -> Option<Vec<f64>> {
        let _ = rows;
        None
    }

    /// The relative distance from the relaxation's optimum within which the
    /// heuristic's point is taken without a branch and bound (default
    /// `mip_heuristic_gap`); the gap is stated either way.
    fn accept_gap(&self) -> f64 {
        S.mip_heuristic_gap
    }
}

/// How HiGHS is run on a program.
#[derive(Clone, Copy)]
pub struct SolveOptions<'a> {
    /// A starting point (one value per column), passed as a hot start.
    pub initial: Option<&'a [f64]>,
    /// HiGHS's `primal_feasibility_tolerance` (its default is 1e-7).
    pub primal_feasibility_tolerance: f64,
    /// A MILP's primal heuristic, run when the relaxation is fractional.
    pub heuristic: Option<&'a dyn Heuristic>,
    /// HiGHS's presolve (off unless asked: see [`Program::solve_with`]'s
    /// model).
    pub presolve: bool,
}

impl std::fmt::Debug for SolveOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolveOptions")
            .field("initial", &self.initial)
            .field(
                "primal_feasibility_tolerance",
                &self.primal_feasibility_tolerance,
            )
            .field("heuristic", &self.heuristic.is_some())
            .field("presolve", &self.presolve)
            .finish()
    }
}

impl Default for SolveOptions<'_> {
    fn default() -> Self {
        Self {
            initial: None,
            presolve: false,
            primal_feasibility_tolerance: S.primal_feasibility_tol,
            heuristic: None,
        }
    }
}

/// HiGHS's floating-point answer (untrusted).
#[derive(Debug, Clone, PartialEq)]
pub struct Solved {
    /// Primal values, column order.
    pub x: Vec<f64>,
    /// Row duals in HiGHS's convention (`c − Aᵀy` are its reduced costs),
    /// of the LP relaxation for a MILP.
    pub y: Vec<f64>,
    /// HiGHS's objective value.
    pub solver_objective: f64,
    /// HiGHS's MIP dual bound (a MILP only; a float, not checked): the
    /// relaxation's optimum when that was integral and no branch and bound
    /// ran.
    pub solver_dual_bound: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimizer::certificate::check;

    /// max x + 2y s.t. x + y ≤ 4, x − y ≥ −1, x + 3y = 6 (the names kept),
    /// 0 ≤ x, y ≤ 10: the view has the rows HiGHS solved (a `≥` row with
    /// its written coefficients) and HiGHS's duals certify the optimum.
    #[test]
    fn the_view_is_the_rows_highs_solved() {
        let mut p = Program::default();
        let x = p.column(0.0, 10.0, 1.0, false);
        let y = p.column(0.0, 10.0, 2.0, false);
        p.at_most("budget", x + y, 4.0);
        p.at_least("slew", x - y, -1.0);
        p.equal("frame", x + 3.0 * y, 6.0);
        let (hi, lo) = p.between("accel", 2.0 * x - y, -5.0, 5.0);
        assert_eq!((hi, lo), (3, 4));
        assert_eq!(p.names(), ["budget", "slew", "frame", "accel", "accel"]);
        let v = p.view();
        type Side = (Vec<(usize, f64)>, f64, f64);
        let rows: Vec<Side> = v
            .rows
            .iter()
            .map(|r| (r.coefs.clone(), r.lo, r.hi))
            .collect();
        let inf = f64::INFINITY;
        assert_eq!(
            rows,
            vec![
                (vec![(0, 1.0), (1, 1.0)], -inf, 4.0),
                (vec![(0, 1.0), (1, -1.0)], -1.0, inf),
                (vec![(0, 1.0), (1, 3.0)], 6.0, 6.0),
                (vec![(0, 2.0), (1, -1.0)], -inf, 5.0),
                (vec![(0, 2.0), (1, -1.0)], -5.0, inf),
            ]
        );
        let s = p.solve("test").unwrap();
        // x + 3y = 6 and x + y ≤ 4: x = 3, y = 1 (objective 5).
        assert_eq!(s.x, vec![3.0, 1.0]);
        let e = check(&v, &s.x, &s.y);
        assert!(e.primal_feasible);
        // HiGHS's duals (½, ½ on `budget` and `frame`) to the last bits.
        let gap = e.gap().unwrap();
        let tiny = num_rational::BigRational::new(1.into(), (1_i64 << 50).into());
        assert!(gap >= num_rational::BigRational::from_integer(0.into()) && gap < tiny);
        assert_eq!(p.eval(&(x + 3.0 * y), &s.x), 6.0);
    }

    /// A cutting-plane sequence solved warm (each program the last one with
    /// rows appended, a cost and a box changed) gives each program's
    /// optimum, certified by its own view, as a fresh solve does; a program
    /// of another shape (a row changed) is solved fresh. Random 2–6-column
    /// programs, three rounds each.
    #[test]
    fn a_warm_solve_is_the_programs_optimum() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for case in 0..40 {
            let n = rng.random_range(2..=6);
            let mut cols: Vec<(f64, f64, f64)> = (0..n)
                .map(|_| (0.0, rng.random_range(1.0..10.0), rng.random_range(0.1..3.0)))
                .collect();
            let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
            let mut warm = Warm::default();
            for round in 0..4 {
                for _ in 0..rng.random_range(1..=3) {
                    let a: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..2.0)).collect();
                    rows.push((a, rng.random_range(2.0..12.0)));
                }
                let j = rng.random_range(0..n);
                cols[j].1 = rng.random_range(1.0..10.0);
                cols[j].2 = rng.random_range(0.1..3.0);
                if round == 3 {
                    // Another shape: the first row changed.
                    rows[0].1 += 1.0;
                }
                let mut p = Program::default();
                let vars: Vec<Variable> = cols
                    .iter()
                    .map(|&(lo, hi, c)| p.column(lo, hi, c, false))
                    .collect();
                for (a, b) in &rows {
                    let e: Expression = vars.iter().zip(a).map(|(&v, &k)| k * v).sum();
                    p.at_most("cut", e, *b);
                }
                let opts = SolveOptions::default();
                let w = p.solve_warm("test", &opts, &mut warm).unwrap();
                let f = p.solve("test").unwrap();
                let scale = 1.0 + f.solver_objective.abs();
                assert!(
                    (w.solver_objective - f.solver_objective).abs() <= 1e-9 * scale,
                    "case {case} round {round}: {} vs {}",
                    w.solver_objective,
                    f.solver_objective
                );
                let e = check(&p.view(), &w.x, &w.y);
                // HiGHS's vertex meets the rows to its tolerance (the
                // optimizer's programs keep margins for the exact check).
                for (a, b) in &rows {
                    let v: f64 = a.iter().zip(&w.x).map(|(k, x)| k * x).sum();
                    assert!(v <= b + 1e-9 * (1.0 + b.abs()), "case {case} round {round}");
                }
                let gap = e.gap().unwrap();
                let tol = num_rational::BigRational::from_float(1e-7 * scale).unwrap();
                assert!(gap <= tol, "case {case} round {round}: gap {gap}");
            }
            // The second and third solves extended the held model; the
            // fourth (a changed row) did not.
            assert_eq!(warm.reused, 2, "case {case}");
        }
    }
}
