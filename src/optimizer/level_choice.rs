//! Hardware power levels: the power step's level choice as a ring of
//! multiple-choice bins (one level per bin, a budget row, under a slew
//! limit only neighbouring levels within reach), solved by dynamic
//! programming over (bin, level) — `O(N·L²)` per pass.
//!
//! Two uses, neither trusted by the certificate:
//!
//! - [`Ring::probe`]: a level no budget-feasible ring passes through (the
//!   cheapest ring through it, by dynamic programming, overspends the
//!   budget by more than a relative `PROBE_MARGIN`) is dropped from its
//!   bin before the program is built, as a level above an eye-safety cap
//!   is: no level choice the program allows is lost (tested against
//!   enumeration). The LP relaxation can no longer mix it in, which is
//!   what makes its bound (the certificate's) tight where the slew limit
//!   ties neighbours' levels together.
//! - [`Ring::heuristic`]: a feasible level choice near the relaxation's
//!   optimum (the Lagrangian of the budget maximised exactly over the ring
//!   by dynamic programming, its multiplier bisected until the budget
//!   holds, then single-bin upgrades while the budget allows, and the
//!   relaxation's own point rounded down, whichever scores more). The
//!   program's caller checks it exactly like any other point; the bound
//!   still comes from the relaxation's duals.

// The dynamic programmes index several per-bin, per-level tables by the
// same (bin, level); indices read like the recursion.
#![allow(clippy::needless_range_loop)]

/// Relative margin by which the cheapest ring through a level must
/// overspend the budget before the level is dropped: far above the
/// rounding of a float sum of at most `max_bins` nonnegative terms
/// (`N·ε ≈ 3·10⁻¹³`).
pub(super) const PROBE_MARGIN: f64 = 1e-9;

/// One allowed level of a bin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Level {
    /// `x = p/P̄` (the level's coefficient in the slew rows).
    pub x: f64,
    /// Its coefficient in the budget row.
    pub spend: f64,
    /// Its objective coefficient.
    pub value: f64,
}

/// The ring: per bin its allowed levels, the budget row's side and, under
/// a slew limit, how far each bin's level may be from the next bin's.
#[derive(Debug, Clone)]
pub(super) struct Ring {
    /// Per bin, its levels (column order).
    pub bins: Vec<Vec<Level>>,
    /// The budget row's right-hand side.
    pub budget: f64,
    /// Per bin `i`, the largest `|x_next − x_i|` the slew rows allow
    /// (compared with a relative 10⁻⁹ of head-room, so a pair the rows
    /// accept is always compatible); `None` without a slew limit.
    pub reach: Option<Vec<f64>>,
}

const NONE: usize = usize::MAX;

impl Ring {
    fn n(&self) -> usize {
        self.bins.len()
    }

    /// Whether level `a` of bin `i` and level `b` of the next bin may
    /// follow each other.
    fn compatible(&self, i: usize, a: usize, b: usize) -> bool {
        let Some(reach) = &self.reach else {
            return true;
        };
        let j = (i + 1) % self.n();
        (self.bins[j][b].x - self.bins[i][a].x).abs() <= reach[i]
    }

    /// For every (bin, level), the least budget spend of a compatible ring
    /// through it (`+∞` where none closes).
    #[must_use]
    pub fn cheapest_through(&self) -> Vec<Vec<f64>> {
        let n = self.n();
        let spend = |i: usize, k: usize| self.bins[i][k].spend;
        if self.reach.is_none() || n == 0 {
            let least: Vec<f64> = self
                .bins
                .iter()
                .map(|b| b.iter().map(|l| l.spend).fold(f64::INFINITY, f64::min))
                .collect();
            let total: f64 = least.iter().sum();
            return (0..n)
                .map(|i| {
                    (0..self.bins[i].len())
                        .map(|k| total - least[i] + spend(i, k))
                        .collect()
                })
                .collect();
        }
        let mut best: Vec<Vec<f64>> = self
            .bins
            .iter()
            .map(|b| vec![f64::INFINITY; b.len()])
            .collect();
        for s in 0..self.bins[0].len() {
            // Forward: cheapest path from (0, s) to (i, k), both spends in.
            let mut fwd: Vec<Vec<f64>> = Vec::with_capacity(n);
            fwd.push(
                (0..self.bins[0].len())
                    .map(|k| if k == s { spend(0, s) } else { f64::INFINITY })
                    .collect(),
            );
            for i in 1..n {
                let row = (0..self.bins[i].len())
                    .map(|b| {
                        let prev = (0..self.bins[i - 1].len())
                            .filter(|&a| self.compatible(i - 1, a, b))
                            .map(|a| fwd[i - 1][a])
                            .fold(f64::INFINITY, f64::min);
                        prev + spend(i, b)
                    })
                    .collect();
                fwd.push(row);
            }
            // Backward: cheapest rest of the ring after (i, k), back to
            // (0, s), its own spend out.
            let mut back: Vec<f64> = (0..self.bins[n - 1].len())
                .map(|k| {
                    if self.compatible(n - 1, k, s) {
                        0.0
                    } else {
                        f64::INFINITY
                    }
                })
                .collect();
            for i in (0..n).rev() {
                for k in 0..self.bins[i].len() {
                    let through = fwd[i][k] + back[k];
                    if through < best[i][k] {
                        best[i][k] = through;
                    }
                }
                if i == 0 {
                    break;
                }
                back = (0..self.bins[i - 1].len())
                    .map(|a| {
                        (0..self.bins[i].len())
                            .filter(|&b| self.compatible(i - 1, a, b))
                            .map(|b| spend(i, b) + back[b])
                            .fold(f64::INFINITY, f64::min)
                    })
                    .collect();
            }
        }
        best
    }

    /// Per bin, which levels some ring within the budget may pass through
    /// (all of them where dropping would leave a bin with none: the
    /// program then decides).
    #[must_use]
    pub fn probe(&self) -> Vec<Vec<bool>> {
        let cheapest = self.cheapest_through();
        let limit = self.budget + PROBE_MARGIN * self.budget.abs();
        let keep: Vec<Vec<bool>> = cheapest
            .iter()
            .map(|b| b.iter().map(|&c| c <= limit).collect())
            .collect();
        if keep.iter().any(|b| !b.iter().any(|&k| k)) {
            return self.bins.iter().map(|b| vec![true; b.len()]).collect();
        }
        keep
    }

    /// Without a slew limit, the LP relaxation's multipliers in closed
    /// form (the multiple-choice knapsack's greedy, Sinha and Zoltners
    /// 1979): per bin the upper concave hull of its levels' (spend, value),
    /// every bin at its cheapest hull level, then the hull's increments by
    /// value per extra spend, best first, while the budget holds; the
    /// budget's multiplier `λ` is the rate of the first increment that does
    /// not fit (0 if all do), and bin `i`'s one-hot multiplier is
    /// `u_i = max_k (value − λ·spend)`. Every level's reduced cost is then
    /// `≤ 0` and `Σ u_i + λ·budget` is the relaxation's optimum (the
    /// Lagrangian dual of the budget row is tight for a linear program);
    /// any `λ ≥ 0` gives a valid bound, so rounding only loosens it by as
    /// much. Returns `(λ, u)`; `None` under a slew limit or where even the
    /// cheapest levels overspend (the program decides).
    #[must_use]
    pub fn relaxation(&self) -> Option<(f64, Vec<f64>)> {
        if self.reach.is_some() || self.bins.iter().any(Vec::is_empty) {
            return None;
        }
        let mut base = 0.0;
        // (rate, extra spend) of every hull increment.
        let mut steps: Vec<(f64, f64)> = Vec::new();
        for b in &self.bins {
            let mut pts: Vec<(f64, f64)> = b.iter().map(|l| (l.spend, l.value)).collect();
            // By spend, the higher value first among equal spends.
            pts.sort_by(|a, c| a.0.total_cmp(&c.0).then(c.1.total_cmp(&a.1)));
            let mut hull: Vec<(f64, f64)> = Vec::with_capacity(pts.len());
            for p in pts {
                if hull.last().is_some_and(|h| p.1 <= h.1) {
                    continue; // no more value for at least the spend
                }
                while hull.len() >= 2 {
                    let (a, c) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                    // `c` on or below the chord from `a` to `p`: not a vertex.
                    if (c.1 - a.1) * (p.0 - a.0) <= (p.1 - a.1) * (c.0 - a.0) {
                        hull.pop();
                    } else {
                        break;
                    }
                }
                hull.push(p);
            }
            base += hull[0].0;
            for w in hull.windows(2) {
                let extra = w[1].0 - w[0].0;
                steps.push(((w[1].1 - w[0].1) / extra, extra));
            }
        }
        // (A NaN spend refuses too.)
        if base.partial_cmp(&self.budget).is_none_or(|o| o.is_gt()) {
            return None;
        }
        steps.sort_by(|a, c| c.0.total_cmp(&a.0));
        let mut spent = base;
        let mut lambda = 0.0;
        for (rate, extra) in steps {
            if spent + extra > self.budget {
                lambda = rate;
                break;
            }
            spent += extra;
        }
        let u = self
            .bins
            .iter()
            .map(|b| {
                b.iter()
                    .map(|l| l.value - lambda * l.spend)
                    .fold(f64::NEG_INFINITY, f64::max)
            })
            .collect();
        Some((lambda, u))
    }

    /// The compatible ring maximising `Σ (value − λ·spend)` (ties to the
    /// lower level index), as one level index per bin; `None` if no ring
    /// closes.
    fn lagrangian(&self, lambda: f64) -> Option<Vec<usize>> {
        let n = self.n();
        let score = |i: usize, k: usize| {
            let l = &self.bins[i][k];
            l.value - lambda * l.spend
        };
        if self.reach.is_none() {
            return Some(
                (0..n)
                    .map(|i| {
                        let mut best = 0;
                        for k in 1..self.bins[i].len() {
                            if score(i, k) > score(i, best) {
                                best = k;
                            }
                        }
                        best
                    })
                    .collect(),
            );
        }
        let mut best: Option<(f64, Vec<usize>)> = None;
        let mut from: Vec<Vec<usize>> = self.bins.iter().map(|b| vec![NONE; b.len()]).collect();
        for s in 0..self.bins[0].len() {
            let mut val: Vec<f64> = (0..self.bins[0].len())
                .map(|k| {
                    if k == s {
                        score(0, s)
                    } else {
                        f64::NEG_INFINITY
                    }
                })
                .collect();
            for i in 1..n {
                val = (0..self.bins[i].len())
                    .map(|b| {
                        let mut arg = NONE;
                        let mut top = f64::NEG_INFINITY;
                        for a in 0..self.bins[i - 1].len() {
                            if val[a] > top && self.compatible(i - 1, a, b) {
                                top = val[a];
                                arg = a;
                            }
                        }
                        from[i][b] = arg;
                        top + score(i, b)
                    })
                    .collect();
            }
            let mut end = NONE;
            let mut top = f64::NEG_INFINITY;
            for a in 0..self.bins[n - 1].len() {
                if val[a] > top && self.compatible(n - 1, a, s) {
                    top = val[a];
                    end = a;
                }
            }
            if end == NONE || best.as_ref().is_some_and(|b| b.0 >= top) {
                continue;
            }
            let mut choice = vec![0; n];
            choice[n - 1] = end;
            for i in (1..n).rev() {
                choice[i - 1] = if i == 1 { s } else { from[i][choice[i]] };
            }
            choice[0] = s;
            best = Some((top, choice));
        }
        best.map(|b| b.1)
    }

    /// Budget spend of a choice, rounded up (a float sum of nonnegative
    /// terms raised by its error bound).
    fn spent(&self, choice: &[usize]) -> f64 {
        let s: f64 = choice
            .iter()
            .enumerate()
            .map(|(i, &k)| self.bins[i][k].spend)
            .sum();
        s * (1.0 + 2.0 * (self.n() as f64 + 1.0) * f64::EPSILON)
    }

    fn value(&self, choice: &[usize]) -> f64 {
        choice
            .iter()
            .enumerate()
            .map(|(i, &k)| self.bins[i][k].value)
            .sum()
    }

    /// Whether a choice meets the budget and every neighbour pair.
    #[must_use]
    pub fn feasible(&self, choice: &[usize]) -> bool {
        let n = self.n();
        self.spent(choice) <= self.budget
            && (0..n).all(|i| self.compatible(i, choice[i], choice[(i + 1) % n]))
    }

    /// Bin `i`'s best single-bin move at spend `spent`: of its levels of
    /// higher value that the budget and the neighbours allow, the best
    /// value per extra spend (a free move first of all; ties to the lower
    /// level), as (rate, level).
    fn best_move(&self, choice: &[usize], i: usize, spent: f64) -> Option<(f64, usize)> {
        let n = self.n();
        let cur = self.bins[i][choice[i]];
        let prev = (i + n - 1) % n;
        let mut best: Option<(f64, usize)> = None;
        for (k, l) in self.bins[i].iter().enumerate() {
            let gain = l.value - cur.value;
            let extra = l.spend - cur.spend;
            if gain <= 0.0
                || spent + extra.max(0.0) * (1.0 + 1e-12) > self.budget
                || !self.compatible(prev, choice[prev], k)
                || !self.compatible(i, k, choice[(i + 1) % n])
            {
                continue;
            }
            let rate = if extra <= 0.0 {
                f64::INFINITY
            } else {
                gain / extra
            };
            if best.is_none_or(|b| rate > b.0) {
                best = Some((rate, k));
            }
        }
        best
    }

    /// Single-bin moves to a level of higher value while the budget and
    /// the neighbours allow, the best value per extra spend first (a free
    /// move first of all; ties to the lower bin, then the lower level),
    /// until none is left.
    ///
    /// Each bin's best move is kept between moves and found again only
    /// where it may have changed: in the bin moved and, under a slew limit,
    /// its neighbours; everywhere when the spend fell (more moves fit);
    /// where the kept move no longer fits when it rose (a rising spend only
    /// removes moves, the float test `spent + extra ≤ budget` being monotone
    /// in `spent`, so a kept move that still fits is still its bin's best).
    fn improve(&self, choice: &mut [usize]) {
        let n = self.n();
        let mut spent = self.spent(choice);
        let mut best_of: Vec<Option<(f64, usize)>> =
            (0..n).map(|i| self.best_move(choice, i, spent)).collect();
        for _ in 0..4 * self.bins.iter().map(Vec::len).sum::<usize>() {
            let mut best: Option<(f64, usize, usize)> = None;
            for (i, m) in best_of.iter().enumerate() {
                if let Some((rate, k)) = *m {
                    if best.is_none_or(|b| rate > b.0) {
                        best = Some((rate, i, k));
                    }
                }
            }
            let Some((_, i, k)) = best else {
                return;
            };
            choice[i] = k;
            let next = self.spent(choice);
            let fell = next < spent;
            spent = next;
            for j in 0..n {
                let near =
                    j == i || (self.reach.is_some() && ((j + 1) % n == i || (i + 1) % n == j));
                let lost = best_of[j].is_some_and(|(_, m)| {
                    let extra = self.bins[j][m].spend - self.bins[j][choice[j]].spend;
                    spent + extra.max(0.0) * (1.0 + 1e-12) > self.budget
                });
                if fell || near || lost {
                    best_of[j] = self.best_move(choice, j, spent);
                }
            }
        }
    }

    /// Without a slew limit: the best pair of single-bin moves in two
    /// different bins that fits the budget's slack together and gains
    /// value (one bin down, another up), applied; whether one was found.
    /// Moves sorted by extra spend, each paired with the best partner of
    /// spend within what is left (prefix maxima, two bins deep).
    fn exchange(&self, choice: &mut [usize]) -> bool {
        if self.reach.is_some() {
            return false;
        }
        // (extra spend, gain, bin, level) of every move.
        let mut moves: Vec<(f64, f64, usize, usize)> = Vec::new();
        for (i, b) in self.bins.iter().enumerate() {
            let cur = b[choice[i]];
            for (k, l) in b.iter().enumerate() {
                if k != choice[i] {
                    moves.push((l.spend - cur.spend, l.value - cur.value, i, k));
                }
            }
        }
        moves.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)).then(a.3.cmp(&b.3)));
        // Per prefix, the best gain and the best gain of another bin.
        type Top = Option<(f64, usize)>;
        let mut tops: Vec<(Top, Top)> = Vec::with_capacity(moves.len());
        let (mut t1, mut t2): (Top, Top) = (None, None);
        for (p, m) in moves.iter().enumerate() {
            if t1.is_none_or(|t| m.1 > moves[t.1].1) {
                if t1.is_some_and(|t| moves[t.1].2 != m.2) {
                    t2 = t1;
                }
                t1 = Some((m.1, p));
            } else if m.2 != moves[t1.map_or(0, |t| t.1)].2 && t2.is_none_or(|t| m.1 > t.0) {
                t2 = Some((m.1, p));
            }
            tops.push((t1, t2));
        }
        let slack = self.budget - self.spent(choice);
        let scale = self.value(choice).abs().max(f64::MIN_POSITIVE);
        let mut best: Option<(f64, usize, usize)> = None;
        for (a, m) in moves.iter().enumerate() {
            let room = slack - m.0;
            let end = moves.partition_point(|x| x.0 * (1.0 + 1e-12) <= room);
            if end == 0 {
                continue;
            }
            let (t1, t2) = tops[end - 1];
            let partner = match t1 {
                Some(t) if moves[t.1].2 != m.2 => Some(t),
                _ => t2,
            };
            let Some((gain, b)) = partner else { continue };
            let total = m.1 + gain;
            if total > 1e-14 * scale && best.is_none_or(|x| total > x.0) {
                best = Some((total, a, b));
            }
        }
        let Some((_, a, b)) = best else {
            return false;
        };
        let mut next = choice.to_vec();
        next[moves[a].2] = moves[a].3;
        next[moves[b].2] = moves[b].3;
        if !self.feasible(&next) || self.value(&next) <= self.value(choice) {
            return false;
        }
        choice.copy_from_slice(&next);
        true
    }

    /// A feasible level choice of high value (module docs), one level
    /// index per bin; `lambda` is the relaxation's budget multiplier and
    /// `rounded` the relaxation's point rounded per bin (its largest
    /// binary), both only starting points.
    #[must_use]
    pub fn heuristic(&self, lambda: f64, rounded: Option<Vec<usize>>) -> Option<Vec<usize>> {
        let mut best: Option<(f64, Vec<usize>)> = None;
        let offer = |mut c: Vec<usize>, best: &mut Option<(f64, Vec<usize>)>| {
            if !self.feasible(&c) {
                return;
            }
            self.improve(&mut c);
            for _ in 0..4 * self.n() {
                if !self.exchange(&mut c) {
                    break;
                }
                self.improve(&mut c);
            }
            let v = self.value(&c);
            if best.as_ref().is_none_or(|b| v > b.0) {
                *best = Some((v, c));
            }
        };
        if let Some(c) = rounded {
            offer(c, &mut best);
        }
        // Bisect the budget's multiplier: `lo` overspends, `hi` does not.
        let at = |l: f64| self.lagrangian(l);
        let lambda = if lambda.is_finite() {
            lambda.max(0.0)
        } else {
            0.0
        };
        let mut lo = 0.0;
        let mut hi = lambda;
        let mut feasible_hi = at(hi).filter(|c| self.feasible(c));
        if feasible_hi.is_none() {
            lo = hi;
            let scale = self
                .bins
                .iter()
                .flatten()
                .map(|l| l.value.abs() / l.spend.abs().max(f64::MIN_POSITIVE))
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            hi = lambda.max(scale * 1e-9);
            for _ in 0..80 {
                hi *= 2.0;
                feasible_hi = at(hi).filter(|c| self.feasible(c));
                if feasible_hi.is_some() {
                    break;
                }
                lo = hi;
            }
        }
        let c = feasible_hi?;
        offer(c, &mut best);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if !(mid > lo && mid < hi) {
                break;
            }
            match at(mid) {
                Some(c) if self.feasible(&c) => {
                    hi = mid;
                    offer(c, &mut best);
                }
                _ => lo = mid,
            }
        }
        best.map(|b| b.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Every choice of one level per bin (plain enumeration).
    fn every_choice(r: &Ring) -> Vec<Vec<usize>> {
        let mut out = vec![vec![]];
        for b in &r.bins {
            out = out
                .into_iter()
                .flat_map(|c| {
                    (0..b.len()).map(move |k| {
                        let mut c = c.clone();
                        c.push(k);
                        c
                    })
                })
                .collect();
        }
        out
    }

    prop_compose! {
        fn ring()(n in 1usize..6, l in 1usize..4, slew in any::<bool>())(
            xs in proptest::collection::vec(proptest::collection::vec(0.1f64..2.0, l), n),
            values in proptest::collection::vec(proptest::collection::vec(0.0f64..3.0, l), n),
            weights in proptest::collection::vec(0.5f64..1.5, n),
            reach in proptest::collection::vec(0.0f64..1.0, n),
            budget in 0.5f64..1.5,
            slew in Just(slew),
        ) -> Ring {
            Ring {
                bins: xs.iter().zip(&values).zip(&weights).map(|((x, v), w)| {
                    x.iter().zip(v).map(|(&x, &value)| Level { x, spend: w * x, value }).collect()
                }).collect(),
                budget: budget * xs.len() as f64,
                reach: slew.then_some(reach),
            }
        }
    }

    /// [`Ring::improve`] written plainly: every move of every bin scanned
    /// for each move made.
    fn improve_plain(r: &Ring, choice: &mut [usize]) {
        let n = r.n();
        let mut spent = r.spent(choice);
        for _ in 0..4 * r.bins.iter().map(Vec::len).sum::<usize>() {
            let mut best: Option<(f64, usize, usize)> = None;
            for i in 0..n {
                let cur = r.bins[i][choice[i]];
                let prev = (i + n - 1) % n;
                for (k, l) in r.bins[i].iter().enumerate() {
                    let gain = l.value - cur.value;
                    let extra = l.spend - cur.spend;
                    if gain <= 0.0
                        || spent + extra.max(0.0) * (1.0 + 1e-12) > r.budget
                        || !r.compatible(prev, choice[prev], k)
                        || !r.compatible(i, k, choice[(i + 1) % n])
                    {
                        continue;
                    }
                    let rate = if extra <= 0.0 {
                        f64::INFINITY
                    } else {
                        gain / extra
                    };
                    if best.is_none_or(|b| rate > b.0) {
                        best = Some((rate, i, k));
                    }
                }
            }
            let Some((_, i, k)) = best else {
                return;
            };
            choice[i] = k;
            spent = r.spent(choice);
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// The dynamic programme's cheapest ring through each level is the
        /// enumeration's, and probing drops no level of a feasible choice.
        #[test]
        fn probing_keeps_every_feasible_choice(r in ring()) {
            let all = every_choice(&r);
            let cheapest = r.cheapest_through();
            let n = r.bins.len();
            let closes = |c: &[usize]| (0..n).all(|i| r.compatible(i, c[i], c[(i + 1) % n]));
            for i in 0..n {
                for k in 0..r.bins[i].len() {
                    let plain = all.iter().filter(|c| c[i] == k && closes(c))
                        .map(|c| c.iter().enumerate().map(|(b, &m)| r.bins[b][m].spend).sum::<f64>())
                        .fold(f64::INFINITY, f64::min);
                    prop_assert!((cheapest[i][k] - plain).abs() <= 1e-12 * plain.abs().max(1.0)
                        || (cheapest[i][k].is_infinite() && plain.is_infinite()));
                }
            }
            let keep = r.probe();
            for c in all.iter().filter(|c| r.feasible(c)) {
                for (i, &k) in c.iter().enumerate() {
                    prop_assert!(keep[i][k], "level {k} of bin {i} dropped but used by {c:?}");
                }
            }
        }

        /// Differential: the kept-best-moves `improve` makes the plain
        /// one's moves, from any start (levels on a coarse grid, so equal
        /// rates and ties occur).
        #[test]
        fn improve_matches_the_plain_scan(
            r in ring(),
            grid in any::<bool>(),
            start in proptest::collection::vec(0usize..4, 6),
        ) {
            let mut r = r;
            if grid {
                for b in &mut r.bins {
                    for l in b.iter_mut() {
                        l.x = (l.x * 4.0).round() / 4.0;
                        l.spend = l.x;
                        l.value = (l.value * 2.0).round() / 2.0;
                    }
                }
            }
            let mut a: Vec<usize> = (0..r.n()).map(|i| start[i] % r.bins[i].len()).collect();
            let mut b = a.clone();
            r.improve(&mut a);
            improve_plain(&r, &mut b);
            prop_assert_eq!(a, b);
        }

        /// Differential: without a slew limit, the closed-form multipliers'
        /// bound `Σ u + λ·budget` is the LP relaxation's optimum as HiGHS
        /// finds it, and no level choice within the budget beats it.
        #[test]
        fn the_closed_form_relaxation_is_the_lp_optimum(r in ring(), grid in any::<bool>()) {
            use crate::optimizer::certificate::{LinearProgram, Row};
            let mut r = r;
            r.reach = None;
            if grid {
                for b in &mut r.bins {
                    for l in b.iter_mut() {
                        l.x = (l.x * 4.0).round() / 4.0;
                        l.spend = l.x;
                        l.value = (l.value * 2.0).round() / 2.0;
                    }
                }
            }
            let cols: Vec<(usize, Level)> = r.bins.iter().enumerate()
                .flat_map(|(i, b)| b.iter().map(move |&l| (i, l))).collect();
            let mut rows: Vec<Row> = (0..r.n()).map(|i| Row {
                coefs: cols.iter().enumerate().filter(|(_, c)| c.0 == i).map(|(j, _)| (j, 1.0)).collect(),
                lo: 1.0,
                hi: 1.0,
            }).collect();
            rows.push(Row {
                coefs: cols.iter().enumerate().map(|(j, c)| (j, c.1.spend)).filter(|t| t.1 != 0.0).collect(),
                lo: f64::NEG_INFINITY,
                hi: r.budget,
            });
            let lp = LinearProgram {
                cost: cols.iter().map(|c| c.1.value).collect(),
                col_lo: vec![0.0; cols.len()],
                col_hi: vec![1.0; cols.len()],
                integer: vec![false; cols.len()],
                rows,
            };
            let solved = lp.solve("relaxation");
            match r.relaxation() {
                Some((lambda, u)) => {
                    prop_assert!(lambda >= 0.0);
                    let bound = u.iter().sum::<f64>() + lambda * r.budget;
                    let s = solved.expect("the cheapest levels fit: feasible");
                    prop_assert!((bound - s.solver_objective).abs() <= 1e-7 * bound.abs().max(1.0),
                        "closed form {bound}, HiGHS {}", s.solver_objective);
                    for c in every_choice(&r).iter().filter(|c| r.feasible(c)) {
                        prop_assert!(r.value(c) <= bound + 1e-12 * bound.abs().max(1.0));
                    }
                }
                None => prop_assert!(solved.is_err(), "closed form refused a feasible relaxation"),
            }
        }

        /// The heuristic's choice is feasible, and no worse than the
        /// Lagrangian's at the multiplier it was given when that one fits.
        #[test]
        fn the_heuristic_is_feasible(r in ring(), lambda in 0.0f64..3.0) {
            let all = every_choice(&r);
            let best = all.iter().filter(|c| r.feasible(c)).map(|c| r.value(c))
                .fold(f64::NEG_INFINITY, f64::max);
            match r.heuristic(lambda, None) {
                Some(c) => {
                    prop_assert!(r.feasible(&c));
                    prop_assert!(r.value(&c) <= best + 1e-12);
                }
                None => prop_assert!(best == f64::NEG_INFINITY, "no choice, but {best} is feasible"),
            }
        }
    }

    /// A slew limit that ties every bin to its neighbour's level: the
    /// levels whose uniform ring overspends are dropped, the others kept.
    #[test]
    fn a_tied_ring_keeps_the_levels_it_can_afford() {
        let lv = |x: f64| Level {
            x,
            spend: x,
            value: x.sqrt(),
        };
        let r = Ring {
            bins: vec![vec![lv(0.5), lv(1.0), lv(1.5)]; 4],
            budget: 4.0 * 1.2,
            reach: Some(vec![0.1; 4]),
        };
        assert_eq!(r.probe(), vec![vec![true, true, false]; 4]);
        assert_eq!(r.heuristic(0.0, None), Some(vec![1; 4]));
    }
}
