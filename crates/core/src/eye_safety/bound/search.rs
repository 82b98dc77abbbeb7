//! The branch and bound: the maxima over cells (Rule 1, pass duration,
//! envelope integral, pass energy), each with the first cell attaining it,
//! evaluating only the cells whose bound can still change the result, and
//! [`Best`], the order-independent best window (`specs/eye_safety.md`,
//! "Search").

use super::cells::{CellRow, Cells};
use super::Search;
use crate::model::angle::wrap_deg;
use core::cmp::Ordering;
use std::collections::BinaryHeap;

/// The maxima over cells: Rule 1 (ratio, azimuth), pass energy
/// (J, azimuth), envelope integral over a pass (J), pass duration (s).
pub(super) struct CellBest {
    pub(super) single: (f64, f64),
    pub(super) e_max: (f64, f64),
    pub(super) e_env_max: f64,
    pub(super) tau_max: f64,
}

impl Cells<'_> {
    /// The three maxima, each with the first cell (in azimuth order)
    /// attaining it.
    pub(super) fn search(&self, search: Search) -> CellBest {
        let mid_of = |c: usize| wrap_deg(0.5 * (self.cut(c) + self.cut(c + 1)));
        match search {
            Search::Exhaustive => {
                let mut best = CellBest {
                    single: (0.0, 0.0),
                    e_max: (0.0, 0.0),
                    e_env_max: 0.0,
                    tau_max: 0.0,
                };
                for c in 0..self.len() {
                    let x = self.exact(c);
                    best.tau_max = best.tau_max.max(x.tau_s);
                    best.e_env_max = best.e_env_max.max(x.e_env);
                    let e = self.e_refined(c, &x);
                    if e > best.e_max.0 {
                        best.e_max = (e, x.e.1);
                    }
                    if x.single > best.single.0 {
                        best.single = (x.single, mid_of(c));
                    }
                }
                best
            }
            Search::Pruned => {
                // Each cell is evaluated at most once: `slot[c]` indexes
                // its figures in `done` (`u32::MAX`: not yet).
                let memo = std::cell::RefCell::new((vec![u32::MAX; self.len()], Vec::new()));
                let eval = |c: usize| {
                    let mut memo = memo.borrow_mut();
                    let (slot, done) = &mut *memo;
                    if let Some(x) = done.get(slot[c] as usize) {
                        return *x;
                    }
                    let x = self.exact(c);
                    slot[c] = u32::try_from(done.len()).unwrap_or(u32::MAX);
                    done.push(x);
                    x
                };
                let rows = &self.rows;
                // One scan for the figures whose bound is exact on the
                // cells that are not curved (Rule 1, pass duration,
                // envelope integral).
                let mut scans = [ExactScan::default(); 3];
                for (c, row) in rows.iter().enumerate() {
                    scans[0].take(row, row.single_ub, c);
                    scans[1].take(row, row.tau_ub, c);
                    scans[2].take(row, row.env_ub, c);
                }
                let single = first_max_from(rows, |r| r.single_ub, scans[0], |c| eval(c).single);
                let tau = first_max_from(rows, |r| r.tau_ub, scans[1], |c| eval(c).tau_s);
                let e_env = first_max_from(rows, |r| r.env_ub, scans[2], |c| eval(c).e_env);
                // The pass energy's bound is not exact on any cell (the
                // exact evaluation caps it per bin): the plain branch and
                // bound, over the same bounds in the same order.
                // Two levels: the sweep's bound orders the cells, the
                // single-arc cap of `exact` skips a cell before the split
                // caps are computed.
                let e = first_max_sorted(
                    rows.len(),
                    |c| rows[c].e_ub,
                    |c| eval(c).e.0,
                    |c| self.e_refined(c, &eval(c)),
                );
                CellBest {
                    single: single.map_or((0.0, 0.0), |(r, c)| (r, mid_of(c))),
                    e_max: e.map_or((0.0, 0.0), |(e, c)| (e, eval(c).e.1)),
                    e_env_max: e_env.map_or(0.0, |x| x.0),
                    tau_max: tau.map_or(0.0, |x| x.0),
                }
            }
        }
    }
}

/// The best of the cells whose bound is exact (not curved), in index
/// order (strictly larger values only, so the first of equal ones stays),
/// whether any bound is NaN, and the curved cell with the largest bound.
#[derive(Debug, Clone, Copy, Default)]
struct ExactScan {
    best: Option<(f64, usize)>,
    nan: bool,
    top_curved: Option<(f64, usize)>,
}

impl ExactScan {
    fn take(&mut self, row: &CellRow, u: f64, c: usize) {
        self.nan |= u.is_nan();
        let slot = if row.curved {
            &mut self.top_curved
        } else {
            &mut self.best
        };
        if slot.is_none_or(|b| u > b.0) {
            *slot = Some((u, c));
        }
    }
}

/// Branch and bound for the largest positive `exact(c)` and the first cell
/// attaining it, given `bound(row c) ≥ exact(c)` for every cell, with
/// equality where the cell is not curved (`None` if nothing is positive).
/// One scan in index order takes the best of the cells whose bound is exact
/// ([`ExactScan`]) and the curved cell with the largest bound is evaluated
/// (so that the best value is a tight threshold also when every cell is
/// curved); the curved cells whose bound can still beat it are then
/// evaluated in decreasing order of their bound (ties by index) until the
/// next bound can neither exceed the best value nor tie it at a smaller
/// index. The result is the maximum in the order (value, then smaller
/// index), whatever the order of evaluation; with a NaN in sight, the plain
/// branch and bound ([`first_max_sorted`]) decides, as before.
#[cfg(test)]
fn first_max(
    rows: &[CellRow],
    bound: impl Fn(&CellRow) -> f64,
    exact: impl FnMut(usize) -> f64,
) -> Option<(f64, usize)> {
    let mut scan = ExactScan::default();
    for (c, row) in rows.iter().enumerate() {
        scan.take(row, bound(row), c);
    }
    first_max_from(rows, bound, scan, exact)
}

/// [`first_max`] after its scan.
fn first_max_from(
    rows: &[CellRow],
    bound: impl Fn(&CellRow) -> f64,
    scan: ExactScan,
    mut exact: impl FnMut(usize) -> f64,
) -> Option<(f64, usize)> {
    let beats = |x: f64, c: usize, best: (f64, usize)| x > best.0 || (x == best.0 && c < best.1);
    let ub = |c: usize| bound(&rows[c]);
    let ExactScan {
        mut best,
        mut nan,
        top_curved,
    } = scan;
    if let (false, Some((u, c))) = (nan, top_curved) {
        if best.is_none_or(|b| beats(u, c, b)) {
            let x = exact(c);
            nan |= x.is_nan();
            if best.is_none_or(|b| beats(x, c, b)) {
                best = Some((x, c));
            }
        }
    }
    if !nan && top_curved.is_some() {
        let mut order: Vec<usize> = (0..rows.len())
            .filter(|&c| rows[c].curved && best.is_none_or(|b| beats(ub(c), c, b)))
            .collect();
        order.sort_unstable_by(|&a, &b| ub(b).total_cmp(&ub(a)).then(a.cmp(&b)));
        for c in order {
            if best.is_some_and(|b| !beats(ub(c), c, b)) {
                break;
            }
            let x = exact(c);
            nan |= x.is_nan();
            if best.is_none_or(|b| beats(x, c, b)) {
                best = Some((x, c));
            }
        }
    }
    if nan {
        return first_max_sorted(rows.len(), |c| bound(&rows[c]), |c| bound(&rows[c]), exact);
    }
    best.filter(|b| b.0 > 0.0)
}

/// The plain branch and bound behind [`first_max`]: cells are evaluated in
/// decreasing order of their bound (ties by index) until the next bound can
/// neither exceed the best value nor tie it at a smaller index. `mid`, a
/// bound between the two (`exact ≤ mid ≤ ub`), skips a cell before its
/// exact value is computed.
fn first_max_sorted(
    len: usize,
    ub: impl Fn(usize) -> f64,
    mut mid: impl FnMut(usize) -> f64,
    mut exact: impl FnMut(usize) -> f64,
) -> Option<(f64, usize)> {
    let top = (0..len).max_by(|&a, &b| ub(a).total_cmp(&ub(b)).then(b.cmp(&a)))?;
    let mut best = (exact(top), top);
    let beats = |x: f64, c: usize, best: (f64, usize)| x > best.0 || (x == best.0 && c < best.1);
    // The candidates in decreasing order of their bound (ties by index: a
    // strict total order, so a heap pops them in exactly the order a full
    // sort gives), popped only as far as the search goes.
    let mut order: BinaryHeap<ByBound> = (0..len)
        .filter(|&c| beats(ub(c), c, best))
        .map(|c| ByBound(ub(c), c))
        .collect();
    while let Some(ByBound(_, c)) = order.pop() {
        if !beats(ub(c), c, best) {
            break;
        }
        if !beats(mid(c), c, best) {
            continue;
        }
        let x = exact(c);
        if beats(x, c, best) {
            best = (x, c);
        }
    }
    (best.0 > 0.0).then_some(best)
}

/// A cell and its bound, ordered by the bound (`total_cmp`), then by the
/// smaller index: the max-heap of [`first_max_sorted`] pops the largest
/// bound first and, among equal bounds, the first cell.
struct ByBound(f64, usize);

impl PartialEq for ByBound {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for ByBound {}

impl PartialOrd for ByBound {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ByBound {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0).then(other.1.cmp(&self.1))
    }
}

/// The best (ratio, window duration) seen: larger ratio, ties to the
/// shorter window, so the result does not depend on evaluation order.
#[derive(Debug, Clone, Copy)]
pub(super) struct Best(pub(super) f64, pub(super) f64);

impl Best {
    pub(super) fn take(&mut self, (r, t): (f64, f64)) {
        if r > self.0 || (r == self.0 && t < self.1) {
            *self = Self(r, t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The plain branch and bound with a middle bound (`exact ≤ mid ≤
        /// ub`, on a coarse grid: many ties) finds the first largest exact
        /// value, as a scan of every cell does.
        #[test]
        fn first_max_sorted_with_a_middle_bound_is_a_full_scan(
            cells in proptest::collection::vec((0u8..5, 0u8..3, 0u8..3), 1..60),
        ) {
            let exact = |c: usize| f64::from(cells[c].0);
            let mid = |c: usize| exact(c) + f64::from(cells[c].1);
            let ub = |c: usize| mid(c) + f64::from(cells[c].2);
            let mut scan: Option<(f64, usize)> = None;
            for c in 0..cells.len() {
                if scan.is_none_or(|b| exact(c) > b.0) {
                    scan = Some((exact(c), c));
                }
            }
            let scan = scan.filter(|b| b.0 > 0.0);
            prop_assert_eq!(first_max_sorted(cells.len(), ub, mid, exact), scan);
        }

        /// The one-scan branch and bound against the plain one (which
        /// evaluates in decreasing order of the bound), on bounds with many
        /// ties: the same maximum and first cell.
        #[test]
        fn first_max_is_the_plain_branch_and_bound(
            cells in proptest::collection::vec(
                (0u8..6, any::<bool>(), 0u8..4),
                1..60,
            ),
        ) {
            // Values on a coarse grid (ties); a curved cell's exact value
            // is at most its bound.
            let rows: Vec<CellRow> = cells
                .iter()
                .map(|&(u, curved, _)| CellRow {
                    p: 1.0,
                    curved,
                    tau_ub: f64::from(u) - 1.0,
                    e_ub: f64::from(u) - 1.0,
                    env_ub: f64::from(u) - 1.0,
                    single_ub: f64::from(u) - 1.0,
                    tau_lb: 0.0,
                })
                .collect();
            let exact = |c: usize| {
                let (u, curved, d) = cells[c];
                let ub = f64::from(u) - 1.0;
                if curved { ub - f64::from(d) } else { ub }
            };
            let ub: Vec<f64> = rows.iter().map(|r| r.single_ub).collect();
            prop_assert_eq!(
                first_max(&rows, |r| r.single_ub, exact),
                first_max_sorted(ub.len(), |c| ub[c], |c| ub[c], exact)
            );
        }
    }

    #[test]
    fn first_max_with_a_nan_is_the_plain_branch_and_bound() {
        let rows: Vec<CellRow> = [(1.0, false), (f64::NAN, true), (2.0, false), (2.0, true)]
            .iter()
            .map(|&(u, curved)| CellRow {
                p: 1.0,
                curved,
                tau_ub: u,
                e_ub: u,
                env_ub: u,
                single_ub: u,
                tau_lb: 0.0,
            })
            .collect();
        let ub: Vec<f64> = rows.iter().map(|r| r.tau_ub).collect();
        for exact in [
            |c: usize| [1.0, f64::NAN, 2.0, 1.5][c],
            |c: usize| [1.0, 0.5, 2.0, 2.0][c],
        ] {
            assert_eq!(
                first_max(&rows, |r| r.tau_ub, exact),
                first_max_sorted(ub.len(), |c| ub[c], |c| ub[c], exact)
            );
        }
    }

    /// Mutant 2011:14 of the old `bound.rs` (11a69c7), `Best::take`'s
    /// `r > self.0` (to `>=`, `<` or `==`): the larger ratio wins, a tie
    /// goes to the shorter window only, a smaller ratio never replaces.
    #[test]
    fn best_takes_the_larger_ratio_then_the_shorter_window() {
        let mut b = Best(0.0, 0.0);
        b.take((1.0, 2.0));
        assert_eq!((b.0, b.1), (1.0, 2.0));
        b.take((0.5, 1.0)); // smaller: kept out
        assert_eq!((b.0, b.1), (1.0, 2.0));
        b.take((1.0, 3.0)); // tie, longer window: kept out
        assert_eq!((b.0, b.1), (1.0, 2.0));
        b.take((1.0, 1.5)); // tie, shorter window: taken
        assert_eq!((b.0, b.1), (1.0, 1.5));
        b.take((2.0, 9.0)); // larger, whatever its window
        assert_eq!((b.0, b.1), (2.0, 9.0));
        b.take((f64::NAN, 0.0)); // never a NaN
        assert_eq!((b.0, b.1), (2.0, 9.0));
    }
}
