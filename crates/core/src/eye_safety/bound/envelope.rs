//! The envelope `P̄(t) = max P over [t − Δ, t]` over one frame period, as
//! pieces with prefix integrals, extended periodically: every pulse's
//! energy is at most `∫ P̄` over the `Δ` after it, and these cells are
//! disjoint, so any time set `S` receives at most `∫ P̄` over `S ⊕ [0, Δ]`
//! (`specs/eye_safety.md`, "Envelope").

use super::order::{sort_runs, split_index, wrap_index};
use super::seg::Seg;
use super::sliding::Queue;
use crate::profile::kinematics::{split_periods, Compensated, Timeline};

/// The max-filtered power `P̄` over one period, as pieces `[t_k, t_{k+1})`
/// with prefix integrals, extended periodically.
pub(super) struct Envelope {
    /// Piece starts in `[0, T_f)`, then `T_f`.
    t_s: Vec<f64>,
    /// `P̄` on each piece, W.
    pub(super) p_w: Vec<f64>,
    /// `∫ P̄` from 0 to each piece start, then the period's total.
    cum_j: Vec<f64>,
    pub(super) frame_s: f64,
}

impl Envelope {
    pub(super) fn new(tl: &Timeline<'_, Seg>, delta_s: f64) -> Self {
        let segs = tl.bins();
        let n = segs.len();
        let frame_s = tl.period_s();
        let p_max = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
        if delta_s >= frame_s {
            return Self {
                t_s: vec![0.0, frame_s],
                p_w: vec![p_max],
                cum_j: vec![0.0, p_max * frame_s],
                frame_s,
            };
        }
        // Candidate breakpoints: bin starts and bin starts + Δ (wrapped).
        let mut cand: Vec<f64> = Vec::with_capacity(2 * n + 1);
        cand.extend((0..n).map(|i| tl.bin_start_time_s(i)));
        cand.extend((0..n).map(|i| {
            let s = tl.bin_start_time_s(i) + delta_s;
            if s >= frame_s {
                s - frame_s
            } else {
                s
            }
        }));
        // Increasing runs (the second wraps once): a merge, linear.
        let mut cand = sort_runs(cand, &[0, n, 2 * n]);
        if cand[0] > 0.0 {
            cand.insert(0, 0.0);
        }
        // Sliding-window maximum over the unrolled bins (3 periods: bin
        // index k covers [cum(k mod n) + (k div n − 1)·T_f, ...)).
        // The deque holds (power, end time) of the bins in it.
        let (mut turn, mut bin) = (0usize, 0usize); // next bin to push, as k div n, k mod n
        let offset = |turn: usize| (turn as f64 - 1.0) * frame_s;
        let mut deque: Queue<(f64, f64)> = Queue::default();
        // The bins of the period before that end by the first piece's
        // window (`c_0 − Δ`) never count: they would be pushed and popped
        // again at the first piece (they come first, and a bin only pops
        // earlier ones), so they are skipped.
        while turn == 0 && tl.bin_start_time_s(bin + 1) + offset(turn) <= cand[0] - delta_s {
            bin += 1;
            if bin == n {
                (turn, bin) = (turn + 1, 0);
            }
        }
        let m = cand.len();
        let mut p_w = Vec::with_capacity(m);
        for j in 0..m {
            let lo = cand[j] - delta_s;
            let hi = if j + 1 < m { cand[j + 1] } else { frame_s };
            // On the open piece (c_j, c_{j+1}), P̄ is the max over bins
            // meeting [t − Δ, t]: those starting before c_{j+1} and ending
            // after c_j − Δ.
            while turn < 3 && tl.bin_start_time_s(bin) + offset(turn) < hi {
                let p = segs[bin].power_w;
                while deque.back().is_some_and(|&(q, _)| q <= p) {
                    deque.pop_back();
                }
                deque.push_back((p, tl.bin_start_time_s(bin + 1) + offset(turn)));
                bin += 1;
                if bin == n {
                    (turn, bin) = (turn + 1, 0);
                }
            }
            while deque.front().is_some_and(|&(_, end)| end <= lo) {
                deque.pop_front();
            }
            p_w.push(deque.front().map_or(p_max, |&(p, _)| p));
        }
        let mut t_s = cand;
        t_s.push(frame_s);
        let mut cum_j = Vec::with_capacity(m + 1);
        // Compensated (see `Compensated`): within a few `u` of the total
        // whatever the number of pieces (`count::time_rounding_s`).
        let mut e = Compensated::default();
        cum_j.push(0.0);
        for j in 0..m {
            e.add(p_w[j] * (t_s[j + 1] - t_s[j]));
            cum_j.push(e.value());
        }
        Self {
            t_s,
            p_w,
            cum_j,
            frame_s,
        }
    }

    pub(super) fn pieces(&self) -> usize {
        self.p_w.len()
    }

    /// `∫ P̄` over one period, J.
    pub(super) fn total_j(&self) -> f64 {
        self.cum_j[self.pieces()]
    }

    /// For unwrapped `t`: whole periods before it, its offset in the
    /// period, and the piece containing that offset.
    fn locate(&self, t: f64) -> (f64, f64, usize) {
        let (k, r) = split_periods(t, self.frame_s);
        (k, r, self.piece_of(r))
    }

    /// As [`Self::locate`], searching forward from piece `*hint` (the piece
    /// of an earlier offset in the same period): the same piece, in amortised
    /// constant time for increasing times.
    #[inline]
    pub(super) fn locate_from(&self, t: f64, hint: &mut usize) -> (f64, f64, usize) {
        let (k, r) = split_periods(t, self.frame_s);
        let m = self.pieces();
        let mut j = (*hint).min(m - 1);
        if self.t_s[j] > r {
            j = self.piece_of(r);
        } else {
            while j + 1 < m && self.t_s[j + 1] <= r {
                j += 1;
            }
        }
        *hint = j;
        (k, r, j)
    }

    fn piece_of(&self, r: f64) -> usize {
        self.t_s
            .partition_point(|&c| c <= r)
            .saturating_sub(1)
            .min(self.pieces() - 1)
    }

    #[inline]
    pub(super) fn integral_at(&self, (k, r, j): (f64, f64, usize)) -> f64 {
        k * self.total_j() + self.cum_j[j] + self.p_w[j] * (r - self.t_s[j])
    }

    /// `∫₀^t P̄` for unwrapped `t`.
    pub(super) fn integral_to(&self, t: f64) -> f64 {
        self.integral_at(self.locate(t))
    }

    /// `P̄` on the piece containing unwrapped `t`.
    pub(super) fn power_at(&self, t: f64) -> f64 {
        self.p_w[self.locate(t).2]
    }

    /// Unwrapped breakpoint `idx` (piece starts, periodic).
    pub(super) fn bp(&self, idx: i64) -> f64 {
        let m = self.pieces() as i64;
        let (k, j) = split_index(idx, m);
        self.t_s[j] + k as f64 * self.frame_s
    }

    /// Unwrapped index of the piece containing unwrapped `t`.
    pub(super) fn unwrapped_piece(&self, t: f64, hint: &mut usize) -> i64 {
        let (k, _, j) = self.locate_from(t, hint);
        k as i64 * self.pieces() as i64 + j as i64
    }

    pub(super) fn p_of(&self, idx: i64) -> f64 {
        self.p_w[wrap_index(idx, self.pieces() as i64)]
    }

    /// The largest total variation of `P̄` over any closed window of
    /// `len_s` (the sum of `|ΔP̄|` over the breakpoints inside it), W: a
    /// time error `δ` at every breakpoint moves an integral over such a
    /// window by at most this times `δ` (the errors telescope to the
    /// jumps), plus `P̂·δ` at each end. Two pointers over the breakpoints of
    /// one period and the next: linear.
    pub(super) fn max_variation_within(&self, len_s: f64) -> f64 {
        let m = self.pieces() as i64;
        let jump = |i: i64| (self.p_of(i) - self.p_of(i - 1)).abs();
        if len_s >= self.frame_s {
            let total: f64 = (0..m).map(jump).sum();
            return total * ((len_s / self.frame_s).floor() + 1.0);
        }
        let (mut best, mut sum, mut r) = (0.0f64, 0.0f64, 0i64);
        for i in 0..m {
            if r < i {
                r = i;
                sum = 0.0;
            }
            while r < i + m && self.bp(r) <= self.bp(i) + len_s {
                sum += jump(r);
                r += 1;
            }
            best = best.max(sum);
            sum -= jump(i);
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye_safety::bound::seg::seg;
    use proptest::prelude::*;

    /// `A = [0, 180)` at 2 W and π rad/s (1 s), `B = [180, 360)` at 1 W and
    /// 2π rad/s (0.5 s): `T_f = 1.5 s`; with `Δ = 0.1 s`, `P̄` is 2 W on
    /// `[0, 1.1)` (A, and A's power for one `Δ` into B) and 1 W on
    /// `[1.1, 1.5)`: 2.6 J a period.
    fn two_bins() -> [Seg; 2] {
        let pi = std::f64::consts::PI;
        [
            seg(0.0, 180.0, 2.0, pi, pi),
            seg(180.0, 180.0, 1.0, 2.0 * pi, 2.0 * pi),
        ]
    }

    fn close(got: f64, want: f64) {
        assert!((got - want).abs() <= 1e-12, "{got} vs {want}");
    }

    proptest! {
        /// `max_variation_within` against a plain double loop: for every
        /// breakpoint of two periods, the sum of `|ΔP̄|` over the
        /// breakpoints in the closed window from it, the largest; and every
        /// window's variation is at most it.
        #[test]
        fn max_variation_is_the_largest_over_every_window(
            bins in proptest::collection::vec((0.05f64..1.0, 0.0f64..2.0, 1.0f64..50.0), 1..30),
            delta in 1e-4f64..0.05,
            frac in 0.0f64..1.5,
        ) {
            let total: f64 = bins.iter().map(|b| b.0).sum();
            let mut start = 0.0;
            let segs: Vec<Seg> = bins
                .iter()
                .map(|&(w, p, om)| {
                    let width = 360.0 * w / total;
                    let s = seg(start, width, p, om, om);
                    start += width;
                    s
                })
                .collect();
            let tl = Timeline::from_bins(&segs);
            let env = Envelope::new(&tl, delta);
            let len = frac * env.frame_s;
            let got = env.max_variation_within(len);
            let m = env.pieces() as i64;
            let jump = |i: i64| (env.p_of(i) - env.p_of(i - 1)).abs();
            let mut want = 0.0f64;
            for i in 0..2 * m {
                let mut v = 0.0;
                let mut r = i;
                while r < i + 3 * m && env.bp(r) <= env.bp(i) + len {
                    v += jump(r);
                    r += 1;
                }
                want = want.max(v);
            }
            prop_assert!(got >= want * (1.0 - 1e-12), "got {got}, want {want}");
            if len < env.frame_s {
                prop_assert!(got <= want * (1.0 + 1e-12) + 1e-300, "got {got}, want {want}");
            }
        }
    }

    /// Mutants 804:9 (`Envelope::locate` replaced by a constant) and 856:9
    /// (`Envelope::power_at` → 0) of the old `bound.rs` (11a69c7): the
    /// curved cells' exact figures read the envelope through them, and no
    /// core test did. Values by hand (see [`two_bins`]), in three periods.
    #[test]
    fn locate_power_and_integral_by_hand() {
        let segs = two_bins();
        let tl = Timeline::from_bins(&segs);
        let env = Envelope::new(&tl, 0.1);
        close(env.total_j(), 2.6);
        // (whole periods, offset, piece): pieces start at 0, 0.1, 1.0, 1.1.
        for (t, k, r, j) in [
            (0.5, 0.0, 0.5, 1usize),
            (1.3, 0.0, 1.3, 3),
            (2.0, 1.0, 0.5, 1),
            (-0.2, -1.0, 1.3, 3),
            (3.05, 2.0, 0.05, 0),
        ] {
            let (gk, gr, gj) = env.locate(t);
            assert_eq!((gk, gj), (k, j), "locate({t})");
            close(gr, r);
            assert_eq!(env.locate_from(t, &mut 0), (gk, gr, gj));
        }
        for (t, p) in [
            (0.5, 2.0),
            (1.3, 1.0),
            (2.0, 2.0),
            (-0.2, 1.0),
            (3.05, 2.0),
            (1.05, 2.0),
        ] {
            assert_eq!(env.power_at(t), p, "power_at({t})");
        }
        // ∫₀^t P̄: 2 W to 1.1 s, then 1 W.
        for (t, e) in [
            (0.5, 1.0),
            (1.3, 2.4),
            (2.0, 3.6),
            (-0.2, -0.2),
            (3.05, 5.3),
        ] {
            close(env.integral_to(t), e);
        }
    }

    /// `P̄` by its definition: the largest power of the bins the head is in
    /// at some time of `[t − Δ − w, t]` (the windows ending in `[t − w, t]`;
    /// bins of the periods before and after included).
    fn envelope_by_scan(tl: &Timeline<'_, Seg>, w: f64, delta: f64, t: f64) -> f64 {
        let n = tl.bins().len();
        let frame = tl.period_s();
        let mut p = 0.0f64;
        for turn in -2i32..=1 {
            for i in 0..n {
                let a = tl.bin_start_time_s(i) + f64::from(turn) * frame;
                let b = tl.bin_start_time_s(i + 1) + f64::from(turn) * frame;
                if a <= t && b > t - delta - w {
                    p = p.max(tl.bins()[i].power_w);
                }
            }
        }
        p
    }

    proptest! {
        /// The envelope (a merge of sorted runs and a monotone-deque
        /// sliding maximum) against its definition by a scan of the bins,
        /// on every piece, and its total against a plain sum.
        #[test]
        fn envelope_is_the_max_filter_by_scan(
            bins in proptest::collection::vec((0.1f64..1.0, 0.0f64..3.0, 1.0f64..20.0, 1.0f64..20.0), 1..12),
            delta_frac in prop_oneof![1e-4f64..0.3, 0.3f64..1.2],
        ) {
            let total: f64 = bins.iter().map(|b| b.0).sum();
            let mut start = 0.0;
            let segs: Vec<Seg> = bins
                .iter()
                .map(|&(w, p, w0, w1)| {
                    let width = 360.0 * w / total;
                    let s = seg(start, width, p, w0, w1);
                    start += width;
                    s
                })
                .collect();
            let tl = Timeline::from_bins(&segs);
            let delta = delta_frac * tl.period_s();
            let env = Envelope::new(&tl, delta);
            let mut e = 0.0;
            for j in 0..env.pieces() {
                let (a, b) = (env.t_s[j], env.t_s[j + 1]);
                prop_assert!(a < b);
                let mid = 0.5 * (a + b);
                // At least the largest power the window `[t − Δ, t]` meets
                // at the piece's middle (sound), at most the largest over
                // the closed piece widened by the rounding of `c ± Δ` (a bin
                // ending on `c_j − Δ` may count: looser, never lower).
                let tol = 1e-12 * tl.period_s();
                let p_mid = envelope_by_scan(&tl, 0.0, delta, mid);
                let p_closed = envelope_by_scan(&tl, b - a + tol, delta + tol, b);
                prop_assert!(p_mid <= env.p_w[j] && env.p_w[j] <= p_closed, "piece {} [{}, {}]: {} not in [{}, {}]", j, a, b, env.p_w[j], p_mid, p_closed);
                prop_assert_eq!(env.power_at(mid), env.p_w[j]);
                e += env.p_w[j] * (b - a);
            }
            prop_assert!((env.total_j() - e).abs() <= 1e-12 * e.max(1.0));
        }
    }
}
