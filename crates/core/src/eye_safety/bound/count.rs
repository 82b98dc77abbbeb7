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
//! | [`AEL_LB_SLACK`] | 1e-9 | relative, down, on an AEL infimum | a window walk's lower bound of the AEL of its longer windows (a piece is skipped only if its energy over that bound is below the best) | the few ulps by which two evaluations of the infimum at increasing lengths may fail to increase |
//! | [`REACH_SLACK`] | 1e-9 | relative, of a turn's time | each walk's reach | the float inversions of the head's motion (time at an azimuth and back) |
//! | [`TOUCH_SNAP_DEG`] | 1e-9 | deg | the arc a cell's pulses come from (Rule 1, pulse caps) | the rounding of the cuts (an ulp of 360° is 5.7e-14°) |
//! | [`TIME_ROUNDING`] | 64·ε (ε = 2⁻⁵² = 2u) | of the frame period `T_f`, absolute, on every duration | every pulse count of a pass or of a bin's share of it (`Cells`, pulse caps), as `⌊(τ + time_rounding_s)·f⌋ + 1`; the multi-pass rules' `τ`; every within-pass window (walks, whole passes) takes the AEL of a window `time_rounding_s` shorter | the rounding of a time *from 0°*: see "Times from 0°" below |
//! | [`energy_rounding_j`] | `(V + 2P̂)·time_rounding_s + 32ε·E_turn` | J, absolute, on every pass and window energy | `bound::evaluate`: added to the pass figures of the multi-pass rules and, over the smallest AEL of a window, to the within-pass ratio | the same rounding in the envelope integrals |
//! | `firmware::eye::LIMIT_MARGIN` | 1e-9 | relative, on each integer limit before it is rounded down | `IntEyeLimits::derive` | the float rounding of the limits derived from this model |
//! | (literal in `firmware::eye`) | 1e-12 | relative, up, on the pass arc in mdeg before its `ceil` | `IntEyeLimits::derive` | an arc that is an integer mdeg up to rounding is not taken one mdeg short |
//! | (literals in `firmware::eye`) | 1e-12 | relative, down, on the shortest span of `k` pulses or `m` passes before its AEL | `IntEyeLimits::derive` | a span rounded up would read a larger AEL; shorter spans are the conservative side |
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
//! between can land a count or a ratio below the exact one. The firmware's
//! three 1e-12 literals are still literals in `firmware::eye::derive`
//! (that code is being reworked for the AEL infimum; they are listed here so
//! the table is complete).
//!
//! **Times from 0°.** Every time the bound computes is a time from 0° of
//! the frame (`Timeline::time_at_unwrapped_s`: `k·T_f + cum_i + t_into`,
//! `|k| ≤ 2`; the envelope's breakpoints are such times, or such times plus
//! `Δ`), and every duration is a difference of two of them. So its
//! rounding error is relative to the *frame*, not to the duration: about
//! `u·T_f` where the relative margins above assume a few `u·τ`. On a frame
//! of 2.29·10⁶ s whose fastest pass lasts 1.25·10⁻⁴ s the difference is
//! ≈ 4·10⁻⁶ of the pass, 4000 times [`COUNT_MARGIN`] (a 20-pulse pass was
//! counted 19). The bound adds the error's bound instead:
//! - the cumulative times are compensated sums (`kinematics::Compensated`,
//!   within `2u·T_f + O(n·u²)·T_f`); each dwell is within `4u` of its
//!   exact value (a quotient, a sum, a product: `≤ 4u·T_f` summed over the
//!   bins); the time into a bin within `6u` of its dwell; `k·T_f` and the
//!   two sums `k·T_f + cum_i + t_into` (`|k| ≤ 2`, so every partial value
//!   is below `3T_f`) at most `3·u·3T_f`. In all `< 32u·T_f = 16ε·T_f` per
//!   time (the `O(n·u²)` term is below `u·T_f` for `n < 2⁵⁰` bins), so a
//!   duration is within `32ε·T_f` of the difference of the exact times:
//!   [`time_rounding_s`] is **twice that**, `64ε·T_f` per duration, and
//!   every pulse count takes `τ + time_rounding_s` (an envelope piece is
//!   `Δ` wider on one side: the same bound), and every within-pass window
//!   (walks, whole passes) is compared with the AEL of a window that much
//!   shorter (within a row the AEL grows with the length, and across a
//!   row edge that steps up a window just past the edge would otherwise
//!   read the upper row). The rounding of an azimuth
//!   (`φ ± h`, `≤ u·720°`) is not a time error: it evaluates the pass of an
//!   aperture within `u·720°` of the intended one, covered by the cells'
//!   ends and [`TOUCH_SNAP_DEG`] as before.
//! - An envelope integral between two such times is off by at most
//!   `(V + 2P̂)·δ` (`δ` the time error, `V` the variation of `P̄` inside:
//!   the errors of the breakpoints telescope to the jumps) plus the
//!   compensated prefix sums' `≤ 16ε·E_turn` (`E_turn = ∫ P̄` over a frame)
//!   at each end: [`energy_rounding_j`].
//!
//! On an ordinary profile both are far below the relative margins (a
//! 0.1 s frame: `time_rounding_s` = 1.4·10⁻¹⁵ s); they decide only where
//! the frame is many orders of magnitude longer than a pass.

/// The absolute rounding slack of every duration the bound computes, per
/// second of frame period (see "Times from 0°" in the module docs):
/// `64·ε`, twice the proven `32·ε`.
pub(crate) const TIME_ROUNDING: f64 = 64.0 * f64::EPSILON;

/// The bound on the rounding of any duration the bound computes on a frame
/// of `frame_s`, s: [`TIME_ROUNDING`]` · T_f`.
#[must_use]
pub(crate) fn time_rounding_s(frame_s: f64) -> f64 {
    TIME_ROUNDING * frame_s
}

/// The bound on the rounding of any envelope integral over a window the
/// bound computes, J: `(V + 2P̂)·time_rounding_s + 32ε·E_turn`, `V` the
/// largest variation of `P̄` within the window (its breakpoints' errors
/// telescope to the jumps), `P̂` the highest power (the two ends),
/// `E_turn` the envelope's integral over one frame (the compensated prefix
/// sums at both ends). Raised by [`COUNT_MARGIN`] for the rounding of this
/// very expression.
#[must_use]
pub(crate) fn energy_rounding_j(frame_s: f64, variation_w: f64, p_hat_w: f64, turn_j: f64) -> f64 {
    let e = (variation_w + 2.0 * p_hat_w) * time_rounding_s(frame_s) + 32.0 * f64::EPSILON * turn_j;
    e * (1.0 + COUNT_MARGIN)
}

/// Relative margin by which every floor-count is rounded up (see module docs).
pub(crate) const COUNT_MARGIN: f64 = 1e-9;

/// Relative margin every rule's ratio is raised by before the verdict, so
/// float rounding in the bound can never land it below the true supremum.
pub const RATIO_MARGIN: f64 = 1e-9;

/// Slack, relative to a turn's time or envelope energy, added to the cheap
/// bounds of float differences (times, envelope integrals) so they stay
/// above the exact evaluation's rounding (a few units in the last place of
/// those totals).
pub(super) const PRUNE_SLACK: f64 = 1e-12;

/// Relative slack by which a window walk lowers the AEL infimum it kept
/// before it uses it as a lower bound for longer windows: the infimum over
/// `[t, one_pass_s]` is nondecreasing in `t`, and two float evaluations of
/// it (Table 3's powers, a few ulps each) can only break that by a few ulps.
pub(super) const AEL_LB_SLACK: f64 = 1e-9;

/// Relative slack (of a turn's time) by which a walk's reach is widened, so
/// the float inversions of the head's motion stay above the exact reach.
pub(super) const REACH_SLACK: f64 = 1e-9;

/// Snap (deg) by which the arc a cell's pulses can come from is widened, so
/// bins touched at an edge count.
pub(super) const TOUCH_SNAP_DEG: f64 = 1e-9;

/// `⌊x⌋` rounded up when `x` is within [`COUNT_MARGIN`] of the next integer.
#[must_use]
pub(crate) fn floor_up(x: f64) -> f64 {
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
