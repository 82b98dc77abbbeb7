//! The pulse caps of a pass: at most `K = ⌊τ·f_p⌋ + 1` pulses per pass and
//! at most `⌊t_b·f_p⌋ + 1` in bin `b`, hottest bins first
//! (`specs/eye_safety.md`, "Envelope", the cap `E⁺`), over a cell's union
//! arc and over its sub-cells.

use super::cells::{unwrapped_bin, CellExact, Cells};
use super::count::{max_pulses_in, TOUCH_SNAP_DEG};

/// Most bins a cell's union arc may touch for the per-bin pulse cap of a
/// pass to be evaluated (beyond, the cap `K·P_max·Δ` is used).
pub(crate) const PULSE_CAP_MAX_BINS: i64 = 64;

/// Sub-cells per cell for the per-bin pulse caps (`Cells::pulse_capped_split`).
const PULSE_CAP_SPLIT: usize = 8;

impl Cells<'_> {
    /// The most energy the pulses of one pass over cell `c` can carry,
    /// counted per bin: for every φ in the cell, the pass holds at most
    /// `per_pass` pulses, and bin `b` at most `⌊t_b·f_p⌋ + 1` of them, where
    /// `t_b` (the head's time in `b ∩ [u − h, v + h]`, the cell's union
    /// arc) is at least the time the pass at φ spends in `b`. The hottest
    /// bins first (a knapsack of unit weights: greedy is optimal) gives the
    /// maximum of `Σ P_b·n_b·Δ` under both caps. Tighter than
    /// `per_pass · P_max · Δ` where a narrow hot bin holds fewer pulses than
    /// the pass. `None` when the arc touches more than
    /// [`PULSE_CAP_MAX_BINS`] bins (the caller keeps the coarser cap).
    pub(super) fn pulse_capped_j(&self, u: f64, v: f64, per_pass: f64) -> Option<f64> {
        let tl = self.tl;
        let segs = tl.bins();
        let n = segs.len() as i64;
        let (lo_deg, hi_deg) = (u - self.h - TOUCH_SNAP_DEG, v + self.h + TOUCH_SNAP_DEG);
        // From the last bin: a binary search for the first end (a forward
        // search from bin 0 would step through every bin before it), then
        // forward to the second; the same bins either way.
        let mut hint = usize::MAX;
        let lo = unwrapped_bin(tl, lo_deg, &mut hint);
        let hi = unwrapped_bin(tl, hi_deg, &mut hint).max(lo);
        if hi - lo + 1 > PULSE_CAP_MAX_BINS {
            return None;
        }
        let f_p = self.laser.pulse_rate_hz;
        // (power, pulse cap) of each bin, on the stack (at most
        // `PULSE_CAP_MAX_BINS`); the times by forward searches (the same
        // values as fresh ones).
        let mut buf = [(0.0f64, 0.0f64); PULSE_CAP_MAX_BINS as usize];
        let bins = &mut buf[..(hi - lo + 1) as usize];
        let first = lo.rem_euclid(n) as usize;
        let (mut ha, mut hb) = (first, first);
        for (slot, k) in bins.iter_mut().zip(lo..=hi) {
            let seg = &segs[k.rem_euclid(n) as usize];
            let start = 360.0 * k.div_euclid(n) as f64 + seg.start_deg;
            let a = start.max(lo_deg);
            let b = (start + seg.width_deg).min(hi_deg);
            let t_b = (tl.time_at_unwrapped_from_s(b, &mut hb)
                - tl.time_at_unwrapped_from_s(a, &mut ha))
            .max(0.0);
            *slot = (seg.power_w, max_pulses_in(t_b + self.t_pad, f_p));
        }
        bins.sort_unstable_by(|x, y| y.0.total_cmp(&x.0));
        let mut left = per_pass;
        let mut e = 0.0;
        for &(p_w, cap) in bins.iter() {
            if left <= 0.0 {
                break;
            }
            let k = cap.min(left);
            e += p_w * k * self.delta;
            left -= k;
        }
        Some(e)
    }

    /// [`Self::pulse_capped_j`] over cell `c` = `[u, v]` taken as the
    /// largest over [`PULSE_CAP_SPLIT`] equal sub-cells, each with its own
    /// union arc and pulse count (the counts of a sub-cell are at most the
    /// cell's `per_pass`). Every azimuth of the cell lies in a sub-cell, so
    /// the largest is an upper bound over the cell; it is tighter because
    /// one union arc lets the pulses of one end of the cell sit in the
    /// bins of the other (a hot bin's neighbours: one slow, one fast). Off
    /// the curved cells `τ` is affine, so a sub-cell's count is the larger
    /// of its ends'; on a curved cell every sub-cell keeps `per_pass`.
    fn pulse_capped_split(&self, c: usize, u: f64, v: f64, per_pass: f64) -> Option<f64> {
        let f_p = self.laser.pulse_rate_hz;
        let curved = self.rows[c].curved;
        let tau_at = |phi: f64| self.time_at(phi + self.h) - self.time_at(phi - self.h);
        let k = PULSE_CAP_SPLIT as f64;
        let mut best: Option<f64> = None;
        let (mut a, mut tau_a) = (u, self.tau_pt[c]);
        for i in 1..=PULSE_CAP_SPLIT {
            let (b, tau_b) = if i == PULSE_CAP_SPLIT {
                (v, self.tau_pt[c + 1])
            } else {
                let b = u + (v - u) * (i as f64 / k);
                (b, tau_at(b))
            };
            let n = if curved {
                per_pass
            } else {
                max_pulses_in(tau_a.max(tau_b) + self.t_pad, f_p).min(per_pass)
            };
            let e = self.pulse_capped_j(a, b, n)?;
            best = Some(best.map_or(e, |x: f64| x.max(e)));
            (a, tau_a) = (b, tau_b);
        }
        best
    }

    /// Cell `c`'s pass energy `x.e.0` (of [`Self::exact`]) capped further by
    /// [`Self::pulse_capped_split`]: never above `x.e.0`, so `x.e.0` bounds
    /// it in the branch and bound.
    pub(super) fn e_refined(&self, c: usize, x: &CellExact) -> f64 {
        let per_pass = max_pulses_in(x.tau_s + self.t_pad, self.laser.pulse_rate_hz);
        let (u, v) = (self.cut(c), self.cut(c + 1));
        self.pulse_capped_split(c, u, v, per_pass)
            .map_or(x.e.0, |e| e.min(x.e.0))
    }
}

#[cfg(test)]
mod tests {
    use super::super::cells::with_cells;
    use super::super::seg::{seg, Seg};
    use super::*;

    /// `10` rev/s: 3600 °/s.
    const SPIN_10_HZ: f64 = 20.0 * std::f64::consts::PI;

    /// The per-bin pulse cap counts a bin that only touches the union arc
    /// `[u − h, v + h]` at an edge (one pulse at most: no time inside),
    /// on either side. At 100 kHz and 3600 °/s a degree holds 27.8
    /// pulses, so the one cool bin inside holds all the rest.
    #[test]
    fn pulse_caps_count_bins_touched_at_the_arc_edges() {
        let w = SPIN_10_HZ;
        let segs = [
            seg(0.0, 10.0, 10.0, w, w), // hot, ends at 10
            seg(10.0, 10.0, 1.0, w, w),
            seg(20.0, 10.0, 5.0, w, w), // warm, starts at 20
            seg(30.0, 330.0, 2.0, w, w),
        ];
        let f_p = 1e5;
        let delta = 1.0 / f_p;
        with_cells(&segs, 1.0, f_p, |cells| {
            let close = |got: Option<f64>, want: f64| {
                let got = got.expect("a cap");
                assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
            };
            // Arc [10, 16]: one pulse of the hot bin, four of bin 1.
            close(cells.pulse_capped_j(11.0, 15.0, 5.0), (10.0 + 4.0) * delta);
            // Arc [11, 20]: one pulse of the warm bin, four of bin 1.
            close(cells.pulse_capped_j(12.0, 19.0, 5.0), (5.0 + 4.0) * delta);
            // Arc [11, 19.5]: bin 1 only.
            close(cells.pulse_capped_j(12.0, 18.5, 5.0), 5.0 * delta);
        });
    }

    /// The per-bin pulse cap is taken over at most `PULSE_CAP_MAX_BINS`
    /// bins: an arc over exactly 64 one-degree bins has it (the hottest
    /// bin, half a degree of it inside: 13.9 pulses at 100 kHz and
    /// 3600 °/s, holds all 3), one over 65 has none.
    #[test]
    fn pulse_caps_stop_beyond_64_bins() {
        assert_eq!(PULSE_CAP_MAX_BINS, 64);
        let w = SPIN_10_HZ;
        let segs: Vec<Seg> = (0..360)
            .map(|i| {
                let p = if i == 68 {
                    50.0
                } else {
                    1.0 + f64::from(i % 5)
                };
                seg(f64::from(i), 1.0, p, w, w)
            })
            .collect();
        let f_p = 1e5;
        with_cells(&segs, 31.5, f_p, |cells| {
            // [68.5, 131.5]: bins 68..=131.
            let got = cells
                .pulse_capped_j(100.0, 100.0, 3.0)
                .expect("64 bins: a cap");
            let want = 3.0 * 50.0 / f_p;
            assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
            // [68.5, 132.5]: bins 68..=132.
            assert_eq!(cells.pulse_capped_j(100.0, 101.0, 3.0), None);
        });
    }

    /// The split cap takes each sub-cell's own pulse count. Bins: A
    /// `[0, 100)` at 1800 °/s, M `[100, 115)` and the hot B `[115, 360)` at
    /// 3600 °/s; half pass angle 10°. Cell `[105, 110]` (cuts B − h and
    /// M + h): a pass at φ covers `(110 − φ)/1800 + 15/3600 + (φ − 105)/3600
    /// = (130 − φ)/3600` s, falling with φ, and B's share grows with φ.
    /// At 7560 Hz (2.1 pulses per 1/3600 s): 53 pulses over the cell, 44 at
    /// most in the last sub-cell `[109.375, 110]` (20.625·2.1 = 43.3), whose
    /// union arc `[99.375, 120]` holds at most 11 pulses of B (5°: 10.5),
    /// 32 of M (15°: 31.5) and 3 of A (0.625° at half speed: 2.6). That
    /// sub-cell is the largest (B's share is largest there and B is 100
    /// times hotter): `11·100 + 33` pulse-watts. With the cell's 53 pulses
    /// it would be `11·100 + 35` (M and A full).
    #[test]
    fn pulse_caps_split_take_each_sub_cell_s_pulse_count() {
        let (slow, fast) = (SPIN_10_HZ / 2.0, SPIN_10_HZ);
        let segs = [
            seg(0.0, 100.0, 1.0, slow, slow),
            seg(100.0, 15.0, 1.0, fast, fast),
            seg(115.0, 245.0, 100.0, fast, fast),
        ];
        let f_p = 7560.0;
        with_cells(&segs, 10.0, f_p, |cells| {
            let c = (0..cells.len())
                .find(|&c| cells.cut(c) == 105.0)
                .expect("cut at 105");
            assert_eq!(cells.cut(c + 1), 110.0);
            assert!(!cells.rows[c].curved);
            let got = cells
                .pulse_capped_split(c, 105.0, 110.0, 53.0)
                .expect("a cap");
            let want = (11.0 * 100.0 + 33.0) / f_p;
            assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
        });
    }
}
