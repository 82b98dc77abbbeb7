//! The global bound under `objective.kind = "detection"` (a Lagrangian on
//! a grid of cells).
//!
//! Model objective: `J = Σ θ_i w_i (λ_R u(x_i, τ_i) + λ_ρ √(k_i τ_i))`, with
//! `u` the detection value ([`super::super::detection::value`]: the
//! probability-weighted detection range of the simulator's return models)
//! and the rest as for `√` (module docs of [`super`]). `u` is not concave
//! (the `argus` threshold, the knee of `P_D`), so no tangent bounds it; but
//! it is **nondecreasing** in the power ratio `x` and in the dwell `τ` (more
//! power, more returns; more dwell, a finer pulse spacing, more pulses on
//! the target: tested in `detection.rs` and below), and that is all the
//! bound uses.
//!
//! **Rows kept**: the budget (`Σ θ_i x_i ≤ 2π` or, under time accounting,
//! the exact product `Σ τ_i x_i ≤ N`) and the frame's upper side
//! `Σ τ_i ≤ N`, both widened by the checker's tolerance, and the boxes of
//! [`super::Boxes`] (levels' and set-points' hull, the acceleration box,
//! the Rule 1 cap). **Dropped** (a relaxation may drop rows): the frame's
//! lower side, the slew rows, the acceleration limit beyond its box, eye
//! safety beyond the Rule 1 cap, the levels' gaps.
//!
//! **Weak duality**: for every `μ ≥ 0` (budget) and `ν ≥ 0` (frame), every
//! point meeting the kept rows has
//! `J ≤ μ·B + ν·N + Σ_i max_box (J_i(x, τ) − μ a_i(τ) x − ν τ)`
//! (`a_i = θ_i`, or `τ` under time accounting). Each bin's maximum is
//! bounded cell by cell on a grid of its box (power nodes evenly spaced in
//! `√x`, dwell nodes evenly spaced in `τ`): on the cell
//! `[x_k, x_{k+1}] × [τ_l, τ_{l+1}]`, since `u`, `√` are nondecreasing and
//! `x, τ, μ, ν ≥ 0`, `J_i ≤ J_i(x_{k+1}, τ_{l+1})` and
//! `μ a_i(τ) x + ν τ ≥ μ a_i(τ_l) x_k + ν τ_l`. Any multipliers are valid;
//! they are searched (golden section, coordinate-wise, on a coarser grid)
//! because the function is convex in them.
//!
//! **Rounding**: `u` at a node is a proven upper bound
//! ([`detection::value_upper`]): per condition a range beyond which the
//! model's expected returns, evaluated with outward margins
//! ([`crate::model::returns::ReturnModel::expected_returns_upper`]), stay
//! below `detect`. The sum is raised by `1e-12 + 2·(terms)·ε` of its terms'
//! magnitudes, as the `√` Lagrangians. The same cells, nodes and
//! multipliers are exported as a certificate checked in exact rational
//! arithmetic ([`super::detection_certificate`]).

use std::collections::HashMap;
use std::f64::consts::TAU;
use std::sync::OnceLock;

use rayon::prelude::*;

use super::super::detection;
use super::super::lp::Grid;
use super::super::settings::S;
use super::super::Problem;
use super::{golden, Boxes};
use crate::model::lidar::PowerAccounting;

/// Power cells of the finest grid (nodes evenly spaced in `√x`).
pub(super) const POWER_CELLS: usize = 1024;
/// Dwell cells of the finest grid where the dwell moves (evenly in `τ`).
pub(super) const DWELL_CELLS: usize = 32;
/// The coarse grid (the multiplier search's, and where each bin's
/// refinement starts) takes every `COARSE.0`-th power node and every
/// `COARSE.1`-th dwell node.
const COARSE: (usize, usize) = (16, 4);
/// The multiplier search's grid (every `.0`-th power node, every `.1`-th
/// dwell node).
const SEARCH_STRIDE: (usize, usize) = (64, 8);
/// A bin's refinement stops when its best cell's bound is within this
/// share of the bin's weight of the best value found, or after
/// [`MAX_SPLITS`] splits (either way the bound stays valid).
const REFINE_TOL: f64 = 1e-6;
const MAX_SPLITS: usize = 64;

/// Nodes of the finest grid for one bin width, and the raised values of
/// `u` on them, computed when first asked for.
pub(super) struct Table<'a> {
    problem: &'a Problem,
    pub(super) theta: f64,
    unit: f64,
    /// `x` holds the hardware levels (each a cell of its own), not a grid.
    pub(super) discrete: bool,
    pub(super) x: Vec<f64>,
    pub(super) tau: Vec<f64>,
    /// The proven upper bound of `u` at `(x[k], tau[l])` and the ranges it
    /// rests on, row-major, each computed when first asked for (by any
    /// thread: the value is a function of the node alone).
    u: Vec<OnceLock<(f64, Vec<f64>)>>,
}

impl<'a> Table<'a> {
    fn new(problem: &'a Problem, b: &Boxes, theta: f64) -> Self {
        let (x, discrete) = match levels(problem, b) {
            Some(x) => (x, true),
            None => (
                nodes(b.x_lo.max(0.0), b.x_hi, POWER_CELLS, f64::sqrt, |s| s * s),
                false,
            ),
        };
        let (tl, th) = b.tau(theta);
        let tau = nodes(tl, th, DWELL_CELLS, |v| v, |v| v);
        let u = (0..x.len() * tau.len()).map(|_| OnceLock::new()).collect();
        Table {
            problem,
            theta,
            unit: b.unit,
            discrete,
            x,
            tau,
            u,
        }
    }

    fn u(&self, k: usize, l: usize) -> f64 {
        self.u[k * self.tau.len() + l]
            .get_or_init(|| {
                detection::value_upper(self.problem, self.theta, self.tau[l] * self.unit, self.x[k])
            })
            .0
    }

    /// Computes, on all threads, the bounds [`Lagrangian::search_cells`]
    /// reads at `stride` (each cell's upper node): the values are those
    /// [`Self::u`] would compute when first asked.
    fn prefetch(&self, stride: (usize, usize)) {
        let ks: Vec<usize> = if self.discrete {
            (0..self.x.len()).collect()
        } else {
            cells(self.x.len(), stride.0).iter().map(|c| c.1).collect()
        };
        let nodes: Vec<(usize, usize)> = cells(self.tau.len(), stride.1)
            .iter()
            .flat_map(|&(_, l)| ks.iter().map(move |&k| (k, l)))
            .collect();
        nodes.par_iter().for_each(|&(k, l)| {
            self.u(k, l);
        });
    }

    /// The nodes whose bound was computed: `(k, l, u, ranges)`.
    pub(super) fn points(&self) -> Vec<(usize, usize, f64, Vec<f64>)> {
        self.u
            .iter()
            .enumerate()
            .filter_map(|(i, c)| {
                c.get()
                    .filter(|(u, _)| !u.is_nan())
                    .map(|(u, ranges)| (i / self.tau.len(), i % self.tau.len(), *u, ranges.clone()))
            })
            .collect()
    }
}

/// The hardware power levels a moving power may take (power ratios, inside
/// the limits and under the box's Rule 1 cap), or `None` for a continuous
/// power: with levels the power part of each bin's maximum is exact.
pub(super) fn levels(problem: &Problem, b: &Boxes) -> Option<Vec<f64>> {
    let l = &problem.lidar.limits;
    let p_mean = problem.lidar.average_power_w;
    if !problem.objective.mode.controls_range() || problem.levels.power_w.is_empty() {
        return None;
    }
    let mut x: Vec<f64> = problem
        .levels
        .power_w
        .iter()
        .copied()
        .filter(|&v| v >= l.power_w_min && v <= l.power_w_max)
        .map(|v| v / p_mean)
        .filter(|&v| v <= b.x_hi && v >= 0.0)
        .collect();
    x.sort_by(f64::total_cmp);
    x.dedup();
    (!x.is_empty()).then_some(x)
}

/// `n` cells between `lo` and `hi` (one node if they meet), evenly spaced
/// in `f` (`finv` its inverse), ends exact.
fn nodes(lo: f64, hi: f64, n: usize, f: fn(f64) -> f64, finv: fn(f64) -> f64) -> Vec<f64> {
    if lo >= hi {
        return vec![hi];
    }
    let (a, b) = (f(lo), f(hi));
    let mut v: Vec<f64> = (0..=n)
        .map(|j| finv(a + (b - a) * j as f64 / n as f64))
        .collect();
    v[0] = lo;
    v[n] = hi;
    v
}

/// The cells `(lower node, upper node)` of `len` nodes, every `stride`-th
/// node (the last always).
fn cells(len: usize, stride: usize) -> Vec<(usize, usize)> {
    if len == 1 {
        return vec![(0, 0)];
    }
    let mut idx: Vec<usize> = (0..len).step_by(stride).collect();
    if *idx.last().unwrap() != len - 1 {
        idx.push(len - 1);
    }
    idx.windows(2).map(|w| (w[0], w[1])).collect()
}

/// One bin: its weight `c = θ w`, width, density factor `k`, and table.
struct Bin<'t, 'a> {
    c: f64,
    theta: f64,
    k: f64,
    table: &'t Table<'a>,
}

/// A cell of one bin: node ranges `[k0, k1] × [l0, l1]`.
pub(super) type Cell = (usize, usize, usize, usize);

struct Lagrangian<'t, 'a> {
    bins: Vec<Bin<'t, 'a>>,
    time: bool,
    range_weight: f64,
    resolution_weight: f64,
    budget: f64,
    frame: f64,
}

impl Lagrangian<'_, '_> {
    /// `J_i − μ a x − ν τ` with the gain at `(kg, lg)` and the cost at
    /// `(kc, lc)`: at the cell's upper and lower corners a bound of the
    /// cell, at one node the function's value there. (value, magnitude)
    fn value(
        &self,
        b: &Bin,
        mu: f64,
        nu: f64,
        (kg, lg): (usize, usize),
        (kc, lc): (usize, usize),
    ) -> (f64, f64) {
        let t = b.table;
        let gain = b.c
            * (self.range_weight * t.u(kg, lg)
                + self.resolution_weight * (b.k * t.tau[lg]).max(0.0).sqrt());
        let a = if self.time { t.tau[lc] } else { b.theta };
        let cost = mu * a * t.x[kc] + nu * t.tau[lc];
        (gain - cost, gain.abs() + cost.abs())
    }

    fn cell_bound(&self, b: &Bin, mu: f64, nu: f64, (k0, k1, l0, l1): Cell) -> (f64, f64) {
        self.value(b, mu, nu, (k1, l1), (k0, l0))
    }

    /// One bin's maximum bounded over the coarse cells, each refined (best
    /// bound first) if `refine`: (bound, magnitude, the cells covering the
    /// box).
    fn bin_bound(&self, b: &Bin, mu: f64, nu: f64, refine: bool) -> (f64, f64, Vec<Cell>) {
        let t = b.table;
        let mut leaves: Vec<(f64, f64, Cell)> = Vec::new();
        for &(l0, l1) in &cells(t.tau.len(), COARSE.1) {
            let xs = if t.discrete {
                (0..t.x.len()).map(|k| (k, k)).collect()
            } else {
                cells(t.x.len(), COARSE.0)
            };
            for &(k0, k1) in &xs {
                let (v, m) = self.cell_bound(b, mu, nu, (k0, k1, l0, l1));
                leaves.push((v, m, (k0, k1, l0, l1)));
            }
        }
        let top = |leaves: &[(f64, f64, Cell)]| {
            (0..leaves.len())
                .max_by(|&i, &j| leaves[i].0.total_cmp(&leaves[j].0))
                .unwrap()
        };
        if refine {
            let mut found = f64::NEG_INFINITY;
            for _ in 0..MAX_SPLITS {
                let i = top(&leaves);
                let (v, _, (k0, k1, l0, l1)) = leaves[i];
                found = found.max(self.value(b, mu, nu, (k0, l0), (k0, l0)).0);
                if v - found <= REFINE_TOL * b.c || (k1 - k0 <= 1 && l1 - l0 <= 1) {
                    break;
                }
                leaves.swap_remove(i);
                let (km, lm) = ((k0 + k1) / 2, (l0 + l1) / 2);
                let ks: &[(usize, usize)] = if k1 - k0 > 1 {
                    &[(k0, km), (km, k1)]
                } else {
                    &[(k0, k1)]
                };
                let ls: &[(usize, usize)] = if l1 - l0 > 1 {
                    &[(l0, lm), (lm, l1)]
                } else {
                    &[(l0, l1)]
                };
                for &(a0, a1) in ks {
                    for &(c0, c1) in ls {
                        let (v, m) = self.cell_bound(b, mu, nu, (a0, a1, c0, c1));
                        leaves.push((v, m, (a0, a1, c0, c1)));
                    }
                }
            }
        }
        let i = top(&leaves);
        let (v, m) = (leaves[i].0, leaves[i].1);
        (v, m, leaves.into_iter().map(|l| l.2).collect())
    }

    /// The search grid's cells of one bin's table (every
    /// [`SEARCH_STRIDE`]`.0`-th power node, every `.1`-th dwell node) as
    /// `(g, a·x₀, τ₀)`: the cell's bound at `(μ, ν)` is
    /// `c·g − μ·a·x₀ − ν·τ₀` with `g = λ_R u(x₁, τ₁) + λ_ρ √(k τ₁)`.
    fn search_cells(&self, b: &Bin, stride: (usize, usize)) -> Vec<(f64, f64, f64)> {
        let t = b.table;
        let xs = if t.discrete {
            (0..t.x.len()).map(|k| (k, k)).collect()
        } else {
            cells(t.x.len(), stride.0)
        };
        let mut out = Vec::new();
        for &(l0, l1) in &cells(t.tau.len(), stride.1) {
            let res = self.resolution_weight * (b.k * t.tau[l1]).max(0.0).sqrt();
            let a = if self.time { t.tau[l0] } else { b.theta };
            for &(k0, k1) in &xs {
                out.push((
                    self.range_weight * t.u(k1, l1) + res,
                    a * t.x[k0],
                    t.tau[l0],
                ));
            }
        }
        out
    }

    /// The bound at `(mu, nu)` on the search grid (`cells` per bin from
    /// [`Self::search_cells`]).
    fn at_search(&self, cells: &[Vec<(f64, f64, f64)>], mu: f64, nu: f64) -> f64 {
        let mut total = mu * self.budget + nu * self.frame;
        let mut magnitude = total.abs();
        for (b, cs) in self.bins.iter().zip(cells) {
            let (mut best, mut mag) = (f64::NEG_INFINITY, 0.0);
            for &(g, ax, tau) in cs {
                let v = b.c * g - mu * ax - nu * tau;
                if v > best {
                    best = v;
                    mag = b.c * g.abs() + mu * ax + nu * tau;
                }
            }
            total += best;
            magnitude += mag;
        }
        let terms = (self.bins.len() + 2) as f64;
        total + (1e-12 + 2.0 * terms * f64::EPSILON) * magnitude
    }

    /// The bound at `(mu, nu)`, refined, and its cells: per class of bins
    /// (equal weight and width: equal maxima) the index of its first bin
    /// and its cells, and per bin its class.
    fn at(&self, mu: f64, nu: f64) -> Classes {
        let mut total = mu * self.budget + nu * self.frame;
        let mut magnitude = total.abs();
        let mut seen: HashMap<(u64, u64), usize> = HashMap::new();
        let mut first: Vec<usize> = Vec::new();
        let of_bin: Vec<usize> = (0..self.bins.len())
            .map(|i| {
                let b = &self.bins[i];
                *seen
                    .entry((b.c.to_bits(), b.theta.to_bits()))
                    .or_insert_with(|| {
                        first.push(i);
                        first.len() - 1
                    })
            })
            .collect();
        // Each class's maximum on a thread of its own; summed in bin order.
        let classes: Vec<(usize, f64, f64, Vec<Cell>)> = first
            .par_iter()
            .map(|&i| {
                let (v, m, cells) = self.bin_bound(&self.bins[i], mu, nu, true);
                (i, v, m, cells)
            })
            .collect();
        for &class in &of_bin {
            total += classes[class].1;
            magnitude += classes[class].2;
        }
        let terms = (self.bins.len() + 2) as f64;
        Classes {
            bound: total + (1e-12 + 2.0 * terms * f64::EPSILON) * magnitude,
            cells: classes.into_iter().map(|(i, _, _, c)| (i, c)).collect(),
            of_bin,
        }
    }
}

/// [`Lagrangian::at`]'s answer.
pub(super) struct Classes {
    /// The bound (floating point, raised as the module docs say).
    pub(super) bound: f64,
    /// Per class: its first bin and its cells `(k0, k1, l0, l1)`.
    pub(super) cells: Vec<(usize, Vec<Cell>)>,
    /// Per bin: its class.
    pub(super) of_bin: Vec<usize>,
}

impl Lagrangian<'_, '_> {}

/// Golden-section minimum of a convex `f` on `[0, ∞)`: bracketed by
/// doubling from `start`, then 40 steps.
fn minimise(f: impl Fn(f64) -> f64, start: f64) -> f64 {
    let f0 = f(0.0);
    let mut hi = start;
    let mut f_hi = f(hi);
    let mut lo = 0.0;
    if f_hi < f0 {
        let mut k = 0;
        loop {
            let next = 2.0 * hi;
            let f_next = f(next);
            if f_next >= f_hi || k > 80 {
                hi = next;
                break;
            }
            lo = 0.5 * hi;
            hi = next;
            f_hi = f_next;
            k += 1;
        }
    }
    let m = golden(&f, lo, hi, 40);
    if f(m) <= f0 {
        m
    } else {
        0.0
    }
}

/// `b` if `f(b) <= f(a)`, else `a`.
fn keep_better(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    if f(b) <= f(a) {
        b
    } else {
        a
    }
}

/// The bound (module docs), or `None` if it is not finite.
pub(super) fn bound(problem: &Problem, g: &Grid, b: &Boxes) -> Option<f64> {
    solve(problem, g, b, |_, _, _, classes| classes.bound)
}

/// The tables of a grid: one per distinct bin width (by its bits), in the
/// order first met.
pub(super) fn tables<'a>(problem: &'a Problem, g: &Grid, b: &Boxes) -> Vec<Table<'a>> {
    let mut out: Vec<Table> = Vec::new();
    for &theta in &g.theta {
        if !out.iter().any(|t| t.theta.to_bits() == theta.to_bits()) {
            out.push(Table::new(problem, b, theta));
        }
    }
    out
}

/// Runs the bound and hands `finish` the tables, the multipliers and the
/// refined answer (`None` if the bound is not finite).
pub(super) fn solve<R>(
    problem: &Problem,
    g: &Grid,
    b: &Boxes,
    finish: impl FnOnce(&[Table], f64, f64, &Classes) -> R,
) -> Option<R> {
    let o = &problem.objective;
    let tables = tables(problem, g, b);
    let table_of = |theta: f64| {
        tables
            .iter()
            .find(|t| t.theta.to_bits() == theta.to_bits())
            .expect("a table per width")
    };
    let bins = (0..g.n)
        .map(|i| Bin {
            c: g.theta[i] * g.weight[i],
            theta: g.theta[i],
            k: b.unit * TAU / (g.theta[i] * b.period),
            table: table_of(g.theta[i]),
        })
        .collect();
    let widen = 1.0 + S.global_widen;
    let time = problem.lidar.power_accounting == PowerAccounting::Time;
    let lag = Lagrangian {
        bins,
        time,
        range_weight: o.range_weight,
        resolution_weight: o.resolution_weight,
        budget: if time { b.n } else { TAU } * widen,
        frame: b.n * widen,
    };
    let dwell_moves = b.w_lo < b.w_hi;
    // Scales: a unit of budget or frame is worth about the objective per
    // unit of it.
    tables.par_iter().for_each(|t| t.prefetch(SEARCH_STRIDE));
    let search: Vec<_> = lag
        .bins
        .iter()
        .map(|b| lag.search_cells(b, SEARCH_STRIDE))
        .collect();
    let scale = (lag.at_search(&search, 0.0, 0.0) / b.n).max(1e-12);
    let (mut mu, mut nu) = (0.0, 0.0);
    for _ in 0..if dwell_moves { 2 } else { 1 } {
        mu = minimise(|m| lag.at_search(&search, m, nu), scale);
        if dwell_moves {
            nu = minimise(|v| lag.at_search(&search, mu, v), scale);
        }
    }
    // Then once on the refinement's starting grid, near the coarse optimum.
    tables.par_iter().for_each(|t| t.prefetch(COARSE));
    let search: Vec<_> = lag
        .bins
        .iter()
        .map(|b| lag.search_cells(b, COARSE))
        .collect();
    let at = |m: f64, v: f64| lag.at_search(&search, m, v);
    mu = keep_better(
        |m| at(m, nu),
        mu,
        golden(|m| at(m, nu), 0.7 * mu, 1.4 * mu, 20),
    );
    if dwell_moves {
        nu = keep_better(
            |v| at(mu, v),
            nu,
            golden(|v| at(mu, v), 0.7 * nu, 1.4 * nu, 20),
        );
    }
    let mut classes = lag.at(mu, nu);
    if !classes.bound.is_finite() {
        return None;
    }
    classes.bound *= 1.0 + S.objective_margin;
    Some(finish(&tables, mu, nu, &classes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimizer::config::OptimizerConfig;
    use rand::{Rng, SeedableRng};

    fn shipped(name: &str, bins: usize) -> Problem {
        let dir = format!("{}/examples/configs", env!("CARGO_MANIFEST_DIR"));
        let path = std::path::PathBuf::from(format!("{dir}/{name}.toml"));
        let mut problem = OptimizerConfig::read(&path).unwrap().problem().unwrap();
        problem.bins = bins;
        problem.objective.kind = detection::ObjectiveKind::Detection;
        problem
    }

    /// The detection value is nondecreasing in power and in dwell at the
    /// nodes the bound uses (the premise of its cells).
    #[test]
    fn the_value_is_nondecreasing_on_the_bound_s_nodes() {
        for name in ["paper", "smooth", "multi_level", "vls128_eye"] {
            let problem = shipped(name, 360);
            let g = super::super::grid(&problem, 90.0).unwrap();
            let b = super::super::boxes(&problem, &g).unwrap();
            let t = Table::new(&problem, &b, g.theta[0]);
            for k in (0..t.x.len()).step_by(7) {
                for l in 0..t.tau.len() {
                    if k > 0 {
                        assert!(t.u(k, l) >= t.u(k - 1, l), "{name} x {k} {l}");
                    }
                    if l > 0 {
                        assert!(t.u(k, l) >= t.u(k, l - 1), "{name} tau {k} {l}");
                    }
                }
            }
        }
    }

    /// Each bin's bounded maximum (coarse and refined) against the plain
    /// function at random points of its box, evaluated directly through the
    /// return model (no table), with random multipliers: never above.
    #[test]
    fn a_bin_s_bound_is_above_the_function_at_random_points() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(30);
        for name in ["paper", "smooth", "multi_level", "vls128_eye"] {
            let problem = shipped(name, 24);
            let o = &problem.objective;
            let g = super::super::grid(&problem, 90.0).unwrap();
            let b = super::super::boxes(&problem, &g).unwrap();
            let t = Table::new(&problem, &b, g.theta[0]);
            let time = problem.lidar.power_accounting == PowerAccounting::Time;
            let lag = Lagrangian {
                bins: Vec::new(),
                time,
                range_weight: o.range_weight,
                resolution_weight: o.resolution_weight,
                budget: 0.0,
                frame: 0.0,
            };
            let (tl, th) = b.tau(g.theta[0]);
            for i in 0..g.n {
                let bin = Bin {
                    c: g.theta[i] * g.weight[i],
                    theta: g.theta[i],
                    k: b.unit * TAU / (g.theta[i] * b.period),
                    table: &t,
                };
                let scale = bin.c * 4.0;
                let mu = rng.random_range(0.0..scale);
                let nu = rng.random_range(0.0..scale);
                let coarse = lag.bin_bound(&bin, mu, nu, false).0;
                let fine = lag.bin_bound(&bin, mu, nu, true).0;
                assert!(
                    fine <= coarse + 1e-12 * coarse.abs(),
                    "{name}: refining raised it: {fine} over {coarse}"
                );
                for _ in 0..40 {
                    let x = if t.discrete {
                        t.x[rng.random_range(0..t.x.len())]
                    } else {
                        rng.random_range(b.x_lo.max(0.0)..=b.x_hi)
                    };
                    let tau = if tl < th {
                        rng.random_range(tl..=th)
                    } else {
                        th
                    };
                    let f = bin.c
                        * (o.range_weight * detection::value(&problem, bin.theta, tau * b.unit, x)
                            + o.resolution_weight * (bin.k * tau).sqrt())
                        - mu * if time { tau } else { bin.theta } * x
                        - nu * tau;
                    assert!(
                        f <= fine,
                        "{name} bin {i}: f({x}, {tau}) = {f} above {fine}"
                    );
                }
            }
        }
    }
}
