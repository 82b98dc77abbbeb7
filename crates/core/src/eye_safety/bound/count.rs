//! Counting, and every margin the bound rounds by.
//!
//! A closed interval of `len` s holds at most `⌊len·f_p⌋ + 1` pulses of a
//! clock of rate `f_p`, for any phase ([`max_pulses_in`]); a window of `T`
//! meets at most `⌊(T + τ)/T_f⌋ + 1` passes of at most `τ` each
//! ([`passes_in_window`]). Both floors are taken rounded up
//! ([`floor_up`]), and both are nondecreasing in their argument in floating
//! point too, which [`StepMemo`] relies on.
//!
//! **Margins.** Every constant below rounds towards safety; none of them is
//! a tolerance on the verdict (`ratio ≤ 1` is applied with none):
//!
//! | name | value | of what | where | covers |
//! |---|---|---|---|---|
//! | [`COUNT_MARGIN`] | 1e-9 | relative and absolute, on `x` | every floor count `⌊x(1 + m) + m⌋` | a count on an integer (`T2·f = 200`) is the larger one; input noise of 1e-12 cannot lower it |
//! | [`RATIO_MARGIN`] | 1e-9 | relative, on every ratio | `bound::evaluate`, last step | the float rounding of the bound's sums and of merged widths ([`coalesce`](super::seg)) |
//! | [`PRUNE_SLACK`] | 1e-12 | relative, of a turn's time or envelope energy | curved cells' bounds, whole-pass interpolations (`2·`), the pruning thresholds (`1 + s`) | the few ulps by which two evaluations of one difference of cumulative totals may differ |
//! | [`REACH_SLACK`] | 1e-9 | relative, of a turn's time | each walk's reach | the float inversions of the head's motion (time at an azimuth and back) |
//! | [`TOUCH_SNAP_DEG`] | 1e-9 | deg | the arc a cell's pulses come from (Rule 1, pulse caps) | the rounding of the cuts (an ulp of 360° is 5.7e-14°) |
//! | `firmware::eye::LIMIT_MARGIN` | 1e-9 | relative, on each integer limit before it is rounded down | `IntEyeLimits::derive` | the float rounding of the limits derived from this model |
//!
//! How they relate: each is at least a thousand times the float rounding it
//! covers (relative errors of a few units of `2⁻⁵³ ≈ 1.1e-16` per
//! operation, accumulated over at most ~10⁶ bins: `≤ ~2e-10`, below the
//! 1e-9 margins); [`PRUNE_SLACK`] only has to beat the rounding of the
//! *same* differences computed twice, so it is smaller; the slacks only
//! widen a set of candidates (a reach, an arc, a bound that prunes), so
//! they can make the bound looser but never lower; the two 1e-9 margins on
//! the result ([`COUNT_MARGIN`] on counts, [`RATIO_MARGIN`] on ratios) are
//! each far above the relative error of what they round, so no rounding in
//! between can land a count or a ratio below the exact one.

/// Relative margin by which every floor-count is rounded up (see module docs).
pub const COUNT_MARGIN: f64 = 1e-9;

/// Relative margin every rule's ratio is raised by before the verdict, so
/// float rounding in the bound can never land it below the true supremum.
pub const RATIO_MARGIN: f64 = 1e-9;

/// Slack, relative to a turn's time or envelope energy, added to the cheap
/// bounds of float differences (times, envelope integrals) so they stay
/// above the exact evaluation's rounding (a few units in the last place of
/// those totals).
pub(super) const PRUNE_SLACK: f64 = 1e-12;

/// Relative slack (of a turn's time) by which a walk's reach is widened, so
/// the float inversions of the head's motion stay above the exact reach.
pub(super) const REACH_SLACK: f64 = 1e-9;

/// Snap (deg) by which the arc a cell's pulses can come from is widened, so
/// bins touched at an edge count.
pub(super) const TOUCH_SNAP_DEG: f64 = 1e-9;

/// `⌊x⌋` rounded up when `x` is within [`COUNT_MARGIN`] of the next integer.
#[must_use]
pub fn floor_up(x: f64) -> f64 {
    floor(x * (1.0 + COUNT_MARGIN) + COUNT_MARGIN)
}

/// `x.floor()`, without a library call for `0 < x < 2⁵²` (the counts):
/// there the truncation to an integer is exact and equals the floor.
fn floor(x: f64) -> f64 {
    if x > 0.0 && x < 4_503_599_627_370_496.0 {
        (x as u64) as f64
    } else {
        x.floor()
    }
}

/// Greatest number of pulses of a clock of rate `f_p` in a closed interval
/// of `len_s` seconds, for any phase: `⌊len·f_p⌋ + 1` (rounded up).
#[must_use]
pub fn max_pulses_in(len_s: f64, f_p: f64) -> f64 {
    floor_up(len_s * f_p) + 1.0
}

/// Greatest number of passes (of up to `pass_s` each, one per frame of
/// `frame_s`) that meet a window of `window_s`: `⌊(T + τ)/T_f⌋ + 1`
/// (rounded up).
#[must_use]
pub fn passes_in_window(window_s: f64, pass_s: f64, frame_s: f64) -> f64 {
    floor_up((window_s + pass_s) / frame_s) + 1.0
}

/// A nondecreasing step function (a count of `τ`) memoized over the
/// interval of arguments seen with its last value: an argument inside it
/// has that value (monotonicity), so it is returned without a call. The
/// same value as a fresh call.
#[derive(Default)]
pub(super) struct StepMemo {
    /// `[lo, hi]` and the value there (none yet if `lo > hi`).
    range: Option<(f64, f64, f64)>,
}

impl StepMemo {
    pub(super) fn get(&mut self, x: f64, f: impl Fn(f64) -> f64) -> f64 {
        if let Some((lo, hi, v)) = self.range {
            if lo <= x && x <= hi {
                return v;
            }
        }
        let v = f(x);
        self.range = match self.range {
            Some((lo, hi, w)) if w == v && !x.is_nan() => Some((lo.min(x), hi.max(x), v)),
            _ if x.is_nan() => None,
            _ => Some((x, x, v)),
        };
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn floor_is_floor(x in prop_oneof![
            -1e20f64..1e20, 0.0f64..1e3, Just(0.0), Just(-0.0), Just(4_503_599_627_370_495.5),
            Just(4_503_599_627_370_496.0), Just(f64::NAN), Just(f64::INFINITY),
            Just(f64::MIN_POSITIVE), Just(0.999_999_999_999_999_9),
        ]) {
            prop_assert_eq!(floor(x).to_bits(), x.floor().to_bits());
        }

        #[test]
        fn step_memo_is_a_fresh_call(
            taus in proptest::collection::vec(prop_oneof![
                0.0f64..2e-3, 1e-3f64..1.0001e-3, Just(0.0), Just(-0.0), Just(f64::NAN),
            ], 1..200),
            f_p in 1e3f64..5e5,
            frame_s in 0.01f64..0.2,
        ) {
            let (mut a, mut b) = (StepMemo::default(), StepMemo::default());
            for tau in taus {
                let fresh = max_pulses_in(tau, f_p);
                prop_assert_eq!(a.get(tau, |t| max_pulses_in(t, f_p)).to_bits(), fresh.to_bits());
                let fresh = passes_in_window(10.0, tau, frame_s);
                let memo = b.get(tau, |t| passes_in_window(10.0, t, frame_s));
                prop_assert_eq!(memo.to_bits(), fresh.to_bits());
            }
        }
    }
}
