//! The concave piecewise-linear utilities of the steps, as *segments*.
//!
//! `√v` on `[lo, hi]` is approximated from below by its chords between
//! [`super::UTILITY_SEGMENTS`] + 1 nodes spread evenly in `√` ([`nodes`];
//! a box wider than [`super::OptimizerSettings::utility_dense_sqrt_span`]
//! in `√` keeps its geometric tail for the far end). A concave piecewise-linear
//! function `h` with nodes `v_0 = lo < v_1 < … < v_K = hi` and decreasing
//! slopes `a_k` is, for every `v ∈ [lo, hi]`,
//!
//! `h(v) = √lo + max { Σ_k a_k δ_k : 0 ≤ δ_k ≤ v_{k+1} − v_k, Σ_k δ_k ≤ v − lo }`
//!
//! (the maximum fills the steepest segments first, which is `h`; any other
//! fill is below it). So instead of one epigraph row `u ≤ a_k v + b_k` per
//! chord (`K` rows per bin), a program carries `K` boxed columns `δ_k`
//! (cost `c·a_k`) and **one** row `Σ δ_k − v ≤ −lo` per bin, plus the
//! constant `c·√lo`: the same optimum over `v`, with `K − 1` fewer rows per
//! bin (HiGHS's dual simplex handles boxed columns by bound flips, rows by
//! pivots; the rows were most of the power and dwell steps' programs).
//! Every slope is positive (√ grows), which is what makes the fill greedy.

use super::program::Program;
use good_lp::{Expression, Variable};

/// `√v` on `[lo, hi]` as segments: the value at `lo` and `(slope, length)`
/// per segment, slopes decreasing.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct SqrtSegments {
    /// `√lo`.
    pub(super) base: f64,
    /// `(slope, length)` of each segment, in order from `lo`.
    pub(super) segments: Vec<(f64, f64)>,
}

/// The chords of `√v` on `[lo, hi]` (nodes evenly spaced in `√`) as
/// segments. Empty when `hi <= lo`.
pub(super) fn sqrt_segments(lo: f64, hi: f64) -> SqrtSegments {
    sqrt_segments_n(lo, hi, super::UTILITY_SEGMENTS)
}

/// [`sqrt_segments`] with `k` chords.
pub(super) fn sqrt_segments_n(lo: f64, hi: f64, k: usize) -> SqrtSegments {
    let v = nodes(lo, hi, k);
    let segments = v
        .windows(2)
        .filter_map(|w| {
            let (x0, x1) = (w[0], w[1]);
            (x1 > x0).then(|| ((x1.sqrt() - x0.sqrt()) / (x1 - x0), x1 - x0))
        })
        .collect();
    SqrtSegments {
        base: lo.max(0.0).sqrt(),
        segments,
    }
}

/// The `k + 1` chord nodes of `[lo, hi]`, ascending from `lo` to
/// `max(lo, hi)`: evenly spaced in `√`, or, when the box spans more than
/// `utility_dense_sqrt_span` in `√` (and `k` leaves room), `k − tail`
/// chords evenly on that first span and `tail` geometric in `√` from its
/// end to `√hi` (every chord of `√` lies below it, wherever its nodes).
pub(super) fn nodes(lo: f64, hi: f64, k: usize) -> Vec<f64> {
    let s = &super::OptimizerSettings::DEFAULT;
    let (a, b) = (lo.max(0.0).sqrt(), hi.max(lo).sqrt());
    let tail = s.utility_tail_segments;
    let dense_end = a + s.utility_dense_sqrt_span;
    let roots: Vec<f64> = if b <= dense_end || k <= tail + 1 || dense_end <= 0.0 {
        (0..=k).map(|j| a + (b - a) * j as f64 / k as f64).collect()
    } else {
        let dense = k - tail;
        let ratio = (b / dense_end).powf(1.0 / tail as f64);
        (0..=dense)
            .map(|j| a + (dense_end - a) * j as f64 / dense as f64)
            .chain((1..=tail).map(|j| {
                if j == tail {
                    b
                } else {
                    dense_end * ratio.powi(j as i32)
                }
            }))
            .collect()
    };
    roots.iter().map(|r| r.powi(2)).collect()
}

/// Relative shortfall left when a fill is computed in floating point, so
/// that `Σ δ_k ≤ v − lo` holds *exactly* for the doubles handed to the
/// exact check: at most `K` roundings of a subtraction (half an ulp each)
/// and one of `v − lo` stay far inside `64·ε`.
const FILL_SHORTFALL: f64 = 64.0 * f64::EPSILON;

impl SqrtSegments {
    /// Adds the segment columns (cost `c·slope`, boxed by the lengths) and
    /// the row `Σ δ_k − k·v ≤ −lo` on column `v` (the utility of `k·v`);
    /// returns the columns. The constant `c·√lo` is the caller's.
    pub(super) fn add_to(
        &self,
        prog: &mut Program,
        v: Variable,
        k: f64,
        lo: f64,
        c: f64,
    ) -> Vec<Variable> {
        let deltas: Vec<Variable> = self
            .segments
            .iter()
            .map(|&(a, len)| prog.column(0.0, len, c * a, false))
            .collect();
        if !deltas.is_empty() {
            let mut row: Expression = deltas.iter().copied().sum();
            row.add_mul(-k, v);
            prog.at_most("utility", row, -lo);
        }
        deltas
    }

    /// The greedy fill for `v` (the maximiser above, shortened by a
    /// relative [`FILL_SHORTFALL`] so that it is exactly feasible).
    pub(super) fn fill(&self, lo: f64, v: f64) -> Vec<f64> {
        let mut rem = ((v - lo) * (1.0 - FILL_SHORTFALL)).max(0.0);
        self.segments
            .iter()
            .map(|&(_, len)| {
                let d = len.min(rem);
                rem = (rem - d).max(0.0);
                d
            })
            .collect()
    }

    /// `h(v)` by the fill (floating point).
    #[cfg(test)]
    fn value(&self, lo: f64, v: f64) -> f64 {
        self.base
            + self
                .fill(lo, v)
                .iter()
                .zip(&self.segments)
                .map(|(d, (a, _))| d * a)
                .sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chords as lines, written independently of the segments: the
    /// minimum of the lines through consecutive nodes.
    fn chord_min(lo: f64, hi: f64, v: f64) -> f64 {
        let x = nodes(lo, hi, crate::optimizer::UTILITY_SEGMENTS);
        x.windows(2)
            .filter(|w| w[1] > w[0])
            .map(|w| {
                let s = (w[1].sqrt() - w[0].sqrt()) / (w[1] - w[0]);
                w[0].sqrt() + s * (v - w[0])
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn segments_are_the_chords_and_lie_below_the_root() {
        for &(lo, hi) in &[
            (0.0, 1.0),
            (0.2, 4.5),
            (0.05, 1.3),
            (0.4, 0.400001),
            (3.0, 3.0),
            (0.0, 12_500.0),
            (0.3, 125.0),
            (2.0, 9.5),
        ] {
            let s = sqrt_segments(lo, hi);
            for w in s.segments.windows(2) {
                assert!(w[0].0 > w[1].0, "slopes decrease");
            }
            let total: f64 = s.segments.iter().map(|x| x.1).sum();
            assert!((total - (hi - lo)).abs() <= 1e-12 * hi.max(1.0));
            for k in 0..=200 {
                let v = lo + (hi - lo) * f64::from(k) / 200.0;
                let h = s.value(lo, v);
                assert!(h <= v.sqrt() + 1e-12, "{lo} {hi} {v}: {h} above √");
                if hi > lo {
                    let c = chord_min(lo, hi, v);
                    assert!(
                        (h - c).abs() <= 1e-12 * c.abs().max(1.0),
                        "{lo} {hi} {v}: {h} vs chords {c}"
                    );
                }
            }
        }
    }

    /// A box far wider than the budget's mean (`power_w_max` 12,500 ×
    /// the mean) keeps chords near the mean: the utility at 0.25–4 × the
    /// mean within 1.2 % of `√` (evenly over the box, the first chord ran
    /// to 48.8 and gave 0.14 at the mean). Its nodes rise and end at `hi`;
    /// a box up to 4 × the mean keeps the even nodes.
    #[test]
    fn a_wide_box_keeps_its_chords_near_the_mean() {
        let s = sqrt_segments(0.0, 12_500.0);
        for v in [0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0] {
            let h = s.value(0.0, v);
            assert!(h >= 0.988 * v.sqrt(), "{v}: {h}");
        }
        let x = nodes(0.0, 12_500.0, 16);
        assert_eq!(x.len(), 17);
        assert!(x.windows(2).all(|w| w[1] > w[0]));
        assert!((x[16] - 12_500.0).abs() <= 1e-9 * 12_500.0);
        assert_eq!(x[12], 4.0);
        let even = |lo: f64, hi: f64| -> Vec<f64> {
            let (a, b) = (lo.sqrt(), hi.sqrt());
            (0..=16)
                .map(|j| (a + (b - a) * f64::from(j) / 16.0).powi(2))
                .collect()
        };
        for (lo, hi) in [(0.0, 4.0), (0.2, 1.25), (0.5, 3.0), (1.0, 9.0)] {
            assert_eq!(nodes(lo, hi, 16), even(lo, hi), "[{lo}, {hi}]");
        }
        assert_ne!(nodes(0.0, 4.01, 16), even(0.0, 4.01));
    }

    #[test]
    fn the_fill_never_exceeds_the_room_exactly() {
        use num_rational::BigRational;
        let q = |v: f64| BigRational::from_float(v).unwrap();
        for &(lo, hi) in &[(0.0, 1.0), (0.2, 4.5), (0.153_846, 1.3), (1e-3, 1e3)] {
            let s = sqrt_segments(lo, hi);
            for k in 0..=500 {
                let v = lo + (hi - lo) * f64::from(k) / 500.0;
                let d = s.fill(lo, v);
                let sum = d.iter().fold(q(0.0), |acc, &x| acc + q(x));
                assert!(sum <= q(v) - q(lo), "{lo} {hi} {v}");
                for (x, &(_, len)) in d.iter().zip(&s.segments) {
                    assert!(*x >= 0.0 && *x <= len);
                }
            }
        }
    }
}
