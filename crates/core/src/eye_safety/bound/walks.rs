//! Rule 2 within one pass: the window walks from the envelope's steps
//! (`specs/eye_safety.md`, "Walks"), each followed piece by piece up to its
//! reach, in decreasing order of their bound when pruned.

use super::count::{time_rounding_s, AEL_LB_SLACK, PRUNE_SLACK, REACH_SLACK};
use super::envelope::Envelope;
use super::laser::{AelEnds, Laser};
use super::search::Best;
use super::seg::Seg;
use super::sliding::SlidingMax;
use super::Search;
use crate::profile::kinematics::Timeline;

/// Envelope pieces a window walk visits before it continues with the slope
/// of the hottest piece within its reach (sound, looser); bounds the work on
/// very fine profiles.
pub const WALK_MAX_PIECES: usize = 96;

/// Rule 2 for windows shorter than one revolution (see [`Walks::search`]).
pub(super) struct Walks<'a> {
    pub(super) env: &'a Envelope,
    pub(super) tl: &'a Timeline<'a, Seg>,
    pub(super) laser: &'a Laser,
    /// The pass angle `2h`, deg.
    pub(super) two_h_deg: f64,
    /// The largest pass energy `E⁺`, J.
    pub(super) e_pass: f64,
    /// Longest window a walk follows: a pass plus one pulse spacing, s.
    pub(super) l_max: f64,
    /// The longest window that meets only one pass
    /// ([`Laser::one_pass_window_max_s`]): a walk's window of `T` is
    /// compared with the smallest AEL over `[T, one_pass_s]`, the lengths of
    /// every window that holds its pulses and no other pass's.
    pub(super) one_pass_s: f64,
}

impl Walks<'_> {
    /// The supremum of `min(E⁺, ∫ P̄ over J)/AEL_inf(T)` over the windows that
    /// fit in one pass (`AEL_inf(T)`: the smallest AEL over `[T, one_pass_s]`,
    /// every length of a window holding the same pulses), after `best` (the whole-pass windows,
    /// [`Cells::full_pass`]).
    ///
    /// A window `W` of duration `T` meets the pass `I_φ = [a, a + τ(φ)]` of
    /// aperture `φ` in pulses whose envelope cells lie in
    /// `J = (W ⊕ [0, Δ]) ∩ (I_φ ⊕ [0, Δ]) = [u, u + ℓ]`, `ℓ ≤ T + Δ`; the
    /// head is at `θ(u) ≥ φ − h` at `u`, so the pass ends by
    /// `t(θ(u) + 2h)` and `ℓ ≤ R(u) = t(θ(u) + 2h) + Δ − u`. The ratio is at
    /// most `g(u, ℓ) = min(E⁺, ∫_J P̄)/AEL_inf(ℓ − Δ)` over `0 < ℓ ≤ R(u)`
    /// (`T ≥ ℓ − Δ`, and `T < one_pass_s` or the window is the multi-pass
    /// rules'; not `AEL(ℓ − Δ)`: Table 3 is not monotone). For a
    /// fixed `ℓ`, `∫_J P̄` is piecewise linear in `u` and its maxima over
    /// each interval of feasible `u` lie where `u` is an up-step of `P̄` or
    /// `u + ℓ` a down-step (the walks: forward from up-steps up to `R(u)`,
    /// backward from down-steps `b` up to `b − t(θ(b − Δ) − 2h)`, the same
    /// condition), or at the interval's ends, where `ℓ = R(u)`: `J` is then
    /// the whole pass of `θ(u) + h` (the `best` given).
    ///
    /// Pruned: a walk's windows hold at most `min(E⁺, p·L)` with `p` the
    /// highest `P̄` it can reach, so its ratio is at most
    /// `G(p) = sup_T min(E⁺, p·(T + Δ))/AEL_inf(T)` (over `T` up to `l_max`),
    /// nondecreasing in `p`; walks are followed in decreasing `p` until
    /// `G(p)` falls below the best.
    pub(super) fn search(&self, search: Search, mut best: Best) -> Best {
        let laser = self.laser;
        let delta = 1.0 / laser.pulse_rate_hz;
        let t_walk = self.l_max - delta;
        // Window lengths are differences of times from 0°: each is compared
        // with the AEL of a window `time_rounding_s` shorter (the same
        // energies, every length shifted down by it), as in the walks.
        let pad = time_rounding_s(self.env.frame_s);
        if t_walk <= 0.0 {
            return best;
        }
        let walks = self.walks();
        match search {
            Search::Exhaustive => {
                for &w in &walks {
                    self.walk(w, &mut best);
                }
            }
            Search::Pruned => {
                let mut order: Vec<usize> = (0..walks.len()).collect();
                order.sort_unstable_by(|&a, &b| {
                    walks[b].p_span.total_cmp(&walks[a].p_span).then(a.cmp(&b))
                });
                let mut g = (f64::NAN, 0.0);
                let mut ends = AelEnds::default();
                for k in order {
                    let w = walks[k];
                    if g.0 != w.p_span {
                        let (r, _) = laser.linear_capped_max_memo(
                            -pad,
                            t_walk - pad,
                            w.p_span * delta,
                            w.p_span,
                            self.e_pass,
                            self.one_pass_s,
                            &mut ends,
                        );
                        g = (w.p_span, r * (1.0 + PRUNE_SLACK));
                    }
                    if g.1 < best.0 {
                        break;
                    }
                    self.walk(w, &mut best);
                }
            }
        }
        best
    }

    /// Every walk: its start piece, direction, reach (the longest `ℓ` it
    /// follows, widened by [`REACH_SLACK`]) and the highest `P̄` within it.
    /// Walks start only at steps of `P̄` (and at the first piece, so a
    /// constant envelope has one). The reaches' far ends are made monotone
    /// in the walk order (widened: a running maximum forward, a running
    /// minimum from the end backward) for the sliding maxima.
    fn walks(&self) -> Vec<WalkSpec> {
        let env = self.env;
        let tl = self.tl;
        let delta = 1.0 / self.laser.pulse_rate_hz;
        let slack = REACH_SLACK * env.frame_s;
        let m = env.pieces() as i64;
        // (start piece, far end of the reach) of each forward and backward walk.
        let mut fwd_ends: Vec<(i64, f64)> = Vec::new();
        let mut back_starts: Vec<(i64, f64)> = Vec::new();
        let (mut ha, mut hb, mut hc, mut hd) = (0usize, 0usize, 0usize, 0usize);
        let mut p_prev = env.p_of(-1);
        for i in 0..m {
            let p_i = env.p_w[i as usize];
            let up = p_i > p_prev;
            let down = p_i < p_prev;
            p_prev = p_i;
            let b0 = env.bp(i);
            if up || i == 0 {
                let theta = tl.azimuth_at_unwrapped_from_deg(b0, &mut ha);
                let end =
                    tl.time_at_unwrapped_from_s(theta + self.two_h_deg, &mut hb) + delta + slack;
                let end = end.min(b0 + self.l_max);
                let end = fwd_ends.last().map_or(end, |&(_, e)| end.max(e));
                fwd_ends.push((i, end));
            }
            if down {
                let theta = tl.azimuth_at_unwrapped_from_deg(b0 - delta, &mut hc);
                let start = tl.time_at_unwrapped_from_s(theta - self.two_h_deg, &mut hd) - slack;
                back_starts.push((i, start.max(b0 - self.l_max)));
            }
        }
        for k in (0..back_starts.len().saturating_sub(1)).rev() {
            back_starts[k].1 = back_starts[k].1.min(back_starts[k + 1].1);
        }
        let mut out = Vec::with_capacity(fwd_ends.len() + back_starts.len());
        let (mut fwd, mut back) = (SlidingMax::new(), SlidingMax::new());
        let (mut h_fwd, mut h_back) = (0usize, 0usize);
        for &(i, end) in &fwd_ends {
            let b0 = env.bp(i);
            let j = env.unwrapped_piece(end, &mut h_fwd).max(i);
            out.push(WalkSpec {
                start: i,
                dir: 1,
                reach_s: end - b0,
                p_span: fwd.max_over(i, j, |k| env.p_of(k)),
            });
        }
        for &(i, start) in &back_starts {
            let b0 = env.bp(i);
            let j = env.unwrapped_piece(start, &mut h_back).min(i - 1);
            out.push(WalkSpec {
                start: i,
                dir: -1,
                reach_s: b0 - start,
                p_span: back.max_over(j, i - 1, |k| env.p_of(k)),
            });
        }
        out
    }

    /// One walk: the window energy is linear in `L` between breakpoints, up
    /// to the walk's reach; after `WALK_MAX_PIECES` pieces it is bounded by
    /// the slope `p_span` (the highest `P̄` within the reach).
    fn walk(&self, w: WalkSpec, best: &mut Best) {
        let env = self.env;
        let laser = self.laser;
        let delta = 1.0 / laser.pulse_rate_hz;
        let e_pass = self.e_pass;
        let reach = w.reach_s;
        let t_reach = reach - delta;
        // Every length below is a difference of times from 0°: the AEL is
        // taken at a window `pad` shorter (`count::time_rounding_s`).
        let pad = time_rounding_s(env.frame_s);
        let b0 = env.bp(w.start);
        let (mut e, mut l, mut idx) = (0.0f64, 0.0f64, w.start);
        // Consecutive pieces share a window length: its AEL is kept.
        let mut ends = AelEnds::default();
        // A lower bound of `AEL_inf` of every window length from the last
        // evaluated piece's end on (0: none yet), see below.
        let mut ael_lb = 0.0f64;
        for _ in 0..WALK_MAX_PIECES {
            let (next_idx, piece_p) = if w.dir > 0 {
                (idx + 1, env.p_of(idx))
            } else {
                (idx - 1, env.p_of(idx - 1))
            };
            let seg_end = (env.bp(next_idx) - b0).abs().min(reach);
            if seg_end > delta {
                let l0 = l.max(delta);
                let e0 = e + piece_p * (l0 - l);
                let (t0, t1) = (l0 - delta - pad, seg_end - delta - pad);
                // Skipped when it cannot raise `best`: the piece's energy is
                // at most its value at `t1` (the same expression
                // `linear_capped_max_memo` evaluates, nondecreasing in `t`),
                // and every AEL it would divide by is at least `ael_lb`
                // (the infimum over `[t, one_pass_s]` grows with `t` up to
                // `one_pass_s`, and window lengths grow along the walk; past
                // `one_pass_s` it is Table 3 at `t` alone, which steps down,
                // so such pieces are never skipped). Strictly below: the
                // piece's ratios are all below `best`, which keeps it.
                let e1 = (e0 + piece_p * (t1 - t0)).min(e_pass);
                let skip = ael_lb > 0.0 && t1 <= self.one_pass_s && e1 / ael_lb < best.0;
                if !skip {
                    best.take(laser.linear_capped_max_memo(
                        t0,
                        t1,
                        e0,
                        piece_p,
                        e_pass,
                        self.one_pass_s,
                        &mut ends,
                    ));
                    if let Some(a) = ends.at_longest() {
                        ael_lb = a / (1.0 + AEL_LB_SLACK);
                    }
                }
            }
            e += piece_p * (seg_end - l);
            l = seg_end;
            if e >= e_pass {
                // From here on the window holds at most E⁺: the ratio is
                // largest where it gets there.
                let t_c = if piece_p > 0.0 {
                    (l - (e - e_pass) / piece_p - delta).max(0.0)
                } else {
                    (l - delta).max(0.0)
                };
                best.take(laser.linear_capped_max_memo(
                    t_c - pad,
                    t_reach.max(t_c) - pad,
                    e_pass,
                    0.0,
                    e_pass,
                    self.one_pass_s,
                    &mut ends,
                ));
                return;
            }
            if l >= reach {
                return;
            }
            idx = next_idx;
        }
        // Truncated: longer windows gain at most `p_span` per second.
        let l0 = l.max(delta);
        let e0 = e + w.p_span * (l0 - l);
        best.take(laser.linear_capped_max_memo(
            l0 - delta - pad,
            t_reach - pad,
            e0,
            w.p_span,
            e_pass,
            self.one_pass_s,
            &mut ends,
        ));
    }
}

/// One window walk of [`Walks`].
#[derive(Debug, Clone, Copy)]
struct WalkSpec {
    /// Envelope breakpoint it starts at (unwrapped piece index).
    start: i64,
    /// +1 forward (window starts there), −1 backward (window ends there).
    dir: i64,
    /// The longest window span `L` it follows, s.
    reach_s: f64,
    /// Highest `P̄` within the reach, W.
    p_span: f64,
}
