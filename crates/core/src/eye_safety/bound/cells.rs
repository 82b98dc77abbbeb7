//! The azimuth cells and the sweep: the circle is cut where a pass edge
//! (or a pass edge shifted by `Δ` in time) meets a bin edge; inside a cell
//! both pass edges stay in fixed bins and fixed envelope pieces, so `τ(φ)`
//! and `E(φ)` have their maxima at the cell ends or at one stationary point
//! (`specs/eye_safety.md`, "Cells and spin extremes"). One sweep in azimuth
//! order gives every cell's end values, its Rule 1 figure and cheap upper
//! bounds for the branch and bound; [`Cells::exact`] evaluates one cell.

use super::count::{
    max_pulses_in, passes_in_window, time_rounding_s, StepMemo, PRUNE_SLACK, TOUCH_SNAP_DEG,
};
use super::envelope::Envelope;
use super::laser::{Laser, PerJouleCache};
use super::order::{sort_runs, wrap_index};
use super::seg::Seg;
use super::sliding::SlidingMax;
use crate::eye_safety::ael;
use crate::model::angle::wrap_deg;
use crate::profile::kinematics::{BinMotion, Timeline};

/// One cell's exact figures.
#[derive(Debug, Clone, Copy)]
pub(super) struct CellExact {
    /// Largest pass duration over the cell, s.
    pub(super) tau_s: f64,
    /// Smallest pass duration over the cell, s.
    pub(super) tau_min_s: f64,
    /// Largest pass energy (envelope and pulse-count bounds), J, and the
    /// azimuth (wrapped) where the envelope bound peaks.
    pub(super) e: (f64, f64),
    /// Largest envelope integral over a pass (not capped by the pulse
    /// count: the periodic bound of [`Laser::multi_pass_ratio`] needs it), J.
    pub(super) e_env: f64,
    /// Rule 1 ratio of the cell (before the margin).
    pub(super) single: f64,
}

/// The azimuth cells between consecutive breakpoints. One sweep in azimuth
/// order gives, per cell, the hottest bin touching its union arc, `τ` and
/// `E` at its ends, whether `τ` or `E` can have a stationary point inside
/// (a pass edge in a bin with angular acceleration), and a cheap upper bound
/// of each figure for the branch and bound.
pub(super) struct Cells<'a> {
    pub(super) tl: &'a Timeline<'a, Seg>,
    pub(super) env: &'a Envelope,
    pub(super) laser: &'a Laser,
    pub(super) h: f64,
    pub(super) delta: f64,
    cuts: Vec<f64>,
    /// `τ` and `E` at each cut, `[0, len]`.
    pub(super) tau_pt: Vec<f64>,
    pub(super) e_pt: Vec<f64>,
    /// Each cell's figures from the sweep.
    pub(super) rows: Vec<CellRow>,
    per_j: PerJouleCache,
    /// The rounding bound of every duration computed here
    /// ([`time_rounding_s`]: times are from 0°, so their error is relative
    /// to the frame), added to each before it is counted in pulses.
    pub(super) t_pad: f64,
}

/// A cell as the sweep leaves it.
#[derive(Debug, Clone, Copy)]
pub(super) struct CellRow {
    /// Highest power of the bins touching the cell's union arc, W.
    pub(super) p: f64,
    /// Whether a pass edge crosses a bin with angular acceleration.
    pub(super) curved: bool,
    /// Upper bounds of the cell's `tau_s`, `e.0`, `e_env` and `single`
    /// (the exact `tau_s`, `e_env` and `single` when it is not curved;
    /// `e.0` is then still capped per bin by the exact evaluation).
    pub(super) tau_ub: f64,
    pub(super) e_ub: f64,
    pub(super) env_ub: f64,
    pub(super) single_ub: f64,
    /// A lower bound of the cell's smallest pass duration (exact when the
    /// cell is not curved), s.
    pub(super) tau_lb: f64,
}

impl<'a> Cells<'a> {
    pub(super) fn new(
        tl: &'a Timeline<'a, Seg>,
        env: &'a Envelope,
        h: f64,
        laser: &'a Laser,
    ) -> Self {
        let segs = tl.bins();
        let n = segs.len();
        let delta = 1.0 / laser.pulse_rate_hz;
        let frame_s = tl.period_s();
        // φ-cells: azimuths where a pass edge, or a pass edge shifted by Δ in
        // time, meets a bin edge.
        let mut cuts: Vec<f64> = Vec::with_capacity(4 * n + 1);
        cuts.extend(segs.iter().map(|s| wrap_deg(s.start_deg + h)));
        cuts.extend(segs.iter().map(|s| wrap_deg(s.start_deg - h)));
        let mut hint = 0;
        cuts.extend((0..n).map(|i| {
            let t = tl.bin_start_time_s(i) + delta;
            wrap_deg(tl.azimuth_at_unwrapped_from_deg(t, &mut hint) + h)
        }));
        let mut hint = 0;
        cuts.extend((0..n).map(|i| {
            let t = tl.bin_start_time_s(i) + frame_s - delta;
            wrap_deg(tl.azimuth_at_unwrapped_from_deg(t, &mut hint) - h)
        }));
        // Four runs, each increasing but for one wrap: a merge, linear.
        let cuts = sort_runs(cuts, &[0, n, 2 * n, 3 * n, 4 * n]);
        let mut cells = Self {
            tl,
            env,
            laser,
            h,
            delta,
            cuts,
            tau_pt: Vec::new(),
            e_pt: Vec::new(),
            rows: Vec::new(),
            per_j: PerJouleCache::default(),
            t_pad: time_rounding_s(frame_s),
        };
        cells.sweep();
        cells
    }

    pub(super) fn len(&self) -> usize {
        self.cuts.len()
    }

    /// Cut `c` for `c` in `[0, len]`, the last one a turn after the first.
    pub(super) fn cut(&self, c: usize) -> f64 {
        cut_of(&self.cuts, c)
    }

    /// The sweep (all positions nondecrease with the cell, so every lookup
    /// is a forward step: linear time overall). A cell whose pass edges both
    /// cross bins of constant spin has its exact figures here (at its ends).
    /// Otherwise (curved), over `φ ∈ [u, v]`:
    /// `dτ/dφ = 1/ω(φ + h) − 1/ω(φ − h)` and
    /// `dE/dφ = P̄_r/ω(φ + h) − P̄_l/ω(φ − h)`, with the envelope pieces
    /// `P̄_r`, `P̄_l` fixed over the cell's inside (bounded by their values
    /// at the midpoint and at both ends) and `ω` monotone along each edge's
    /// bin (`ω²` is linear there), so each figure exceeds the larger of its
    /// end values by at most the cell width times the smaller of its
    /// largest forward and backward slopes: the bounds. Rule 1 grows with
    /// the pulse and pass counts (C5 falls with the count).
    ///
    /// Two passes: the pass edges' times and envelope integrals at every
    /// cut, then the cells. Without a bin with angular acceleration no cell
    /// is curved, and the bins under the edges are not looked up.
    fn sweep(&mut self) {
        let tl = self.tl;
        let env = self.env;
        let segs = tl.bins();
        let n = segs.len() as i64;
        let (h, delta) = (self.h, self.delta);
        let frame_s = tl.period_s();
        let f_p = self.laser.pulse_rate_hz;
        let t2 = ael::T2_S.min(ael::TIME_BASE_S);
        let e_slack = PRUNE_SLACK * env.total_j();
        let t_slack = PRUNE_SLACK * frame_s;
        let t_pad = self.t_pad;
        // Bins with angular acceleration (`ω²` not constant); with none, no
        // cell is curved and the edges' bins need not be looked up.
        let bin_curved: Vec<bool> = segs.iter().map(|s| s.spin_sq_line_deg().1 != 0.0).collect();
        let any_curved = bin_curved.contains(&true);
        let cuts = &self.cuts;
        let m = cuts.len();
        // At every cut: the pass edges' times, the envelope integrals there
        // and (for the curved cells' bounds) the envelope's power at the
        // left and the right edge.
        let mut edge_p: Vec<(f64, f64)> = Vec::with_capacity(if any_curved { m + 1 } else { 0 });
        let (mut h0, mut h1, mut h2, mut h3) = (0usize, 0usize, 0usize, 0usize);
        let (mut tau_pt, mut e_pt) = (Vec::with_capacity(m + 1), Vec::with_capacity(m + 1));
        for c in 0..=m {
            let theta = cut_of(cuts, c);
            let t_lo = tl.time_at_unwrapped_from_s(theta - h, &mut h0);
            let t_hi = tl.time_at_unwrapped_from_s(theta + h, &mut h1);
            let at_lo = env.locate_from(t_lo, &mut h2);
            let at_hi = env.locate_from(t_hi + delta, &mut h3);
            tau_pt.push(t_hi - t_lo);
            e_pt.push(env.integral_at(at_hi) - env.integral_at(at_lo));
            if any_curved {
                edge_p.push((env.p_w[at_lo.2], env.p_w[at_hi.2]));
            }
        }
        // Rule 1 near a cut (`touch`): the azimuths within `2s` of cut `c`
        // (`s` = TOUCH_SNAP_DEG) send passes into the arc
        // `[θ_c − h − 3s, θ_c + h + 3s]` (one `s` for the rounding of the
        // cut), and their duration exceeds `τ(θ_c)` by at most `2s` times
        // the largest rate `|dτ/dφ| ≤ 2/ω_min` (`tau_touch`, doubled, plus
        // the rounding slack); the inside of a cell, `[u + 2s, v − 2s]`,
        // sends them into `(u − h + s, v + h − s)`. Off the curved cells
        // this lets Rule 1 pair each end's hottest touched bin with that
        // end's own counts instead of the cell's largest ones.
        let spin_min = segs
            .iter()
            .map(|s| s.spin_start_rad_s.min(s.spin_end_rad_s))
            .fold(f64::INFINITY, f64::min);
        let tau_touch = 8.0 * TOUCH_SNAP_DEG.to_radians() / spin_min + t_slack;
        // The hottest bin near each cut, on demand (forward queries).
        let mut near = SlidingMax::new();
        let (mut ha, mut hb) = (0usize, 0usize);
        let mut p_near = |c: usize| {
            let theta = cut_of(cuts, c);
            let lo = unwrapped_bin(tl, theta - h - 3.0 * TOUCH_SNAP_DEG, &mut ha);
            let hi = unwrapped_bin(tl, theta + h + 3.0 * TOUCH_SNAP_DEG, &mut hb);
            near.max_over(lo, hi.max(lo), |k| segs[wrap_index(k, n)].power_w)
        };
        // Unwrapped bin `k`'s start, deg.
        let start_of = |k: i64| 360.0 * k.div_euclid(n) as f64 + segs[wrap_index(k, n)].start_deg;
        let mut inside = SlidingMax::new();
        // Per cell. The counts are nondecreasing functions of `τ` (products
        // by positive constants, sums and floors are monotone in floating
        // point too), so a value between two arguments of one count has it.
        let mut window = SlidingMax::new();
        let (mut h4, mut h5, mut h6, mut h7) = (0usize, 0usize, 0usize, 0usize);
        let (mut h8, mut h9) = (0usize, 0usize);
        let mut per_pass_of = StepMemo::default();
        let mut passes_of = StepMemo::default();
        let mut rows = Vec::with_capacity(m);
        for c in 0..m {
            let (u, v) = (cut_of(cuts, c), cut_of(cuts, c + 1));
            let lo = unwrapped_bin(tl, u - h - TOUCH_SNAP_DEG, &mut h4);
            let hi = unwrapped_bin(tl, v + h + TOUCH_SNAP_DEG, &mut h5);
            let p = window.max_over(lo, hi.max(lo), |k| segs[wrap_index(k, n)].power_w);
            let mid = 0.5 * (u + v);
            let edges = any_curved
                .then(|| {
                    let right = tl.locate_unwrapped_from(mid + h, &mut h6);
                    let left = tl.locate_unwrapped_from(mid - h, &mut h7);
                    (right, left)
                })
                .filter(|(right, left)| bin_curved[right.1] || bin_curved[left.1]);
            // `ends(..)`'s two values, without the azimuth.
            let ends_tau = 0.0f64.max(tau_pt[c]).max(tau_pt[c + 1]);
            let ends_tau_min = tau_pt[c].min(tau_pt[c + 1]);
            let mut ends_e = 0.0f64;
            for x in [e_pt[c], e_pt[c + 1]] {
                if x > ends_e {
                    ends_e = x;
                }
            }
            let (tau, e, tau_lb) = if let Some((right, left)) = edges {
                let (seg_r, seg_l) = (&segs[right.1], &segs[left.1]);
                // ω at both ends of each edge's arc, on that edge's bin.
                let spin = |seg: &Seg, k: f64, theta: f64| {
                    let (a, b) = seg.spin_sq_line_deg();
                    let x = (theta - (360.0 * k + seg.start_deg)).clamp(0.0, seg.width_deg);
                    (a + b * x).max(0.0).sqrt()
                };
                let (wr_u, wr_v) = (spin(seg_r, right.0, u + h), spin(seg_r, right.0, v + h));
                let (wl_u, wl_v) = (spin(seg_l, left.0, u - h), spin(seg_l, left.0, v - h));
                let (wr_min, wr_max) = (wr_u.min(wr_v), wr_u.max(wr_v));
                let (wl_min, wl_max) = (wl_u.min(wl_v), wl_u.max(wl_v));
                // The envelope's power under each edge: the cell's inside is
                // one piece of each (every breakpoint is a cut), sampled at
                // the midpoint, and the ends' pieces. The ends alone do not
                // do: a cut computed from a breakpoint lands a rounding
                // either side of it, so both ends of a cell between two
                // breakpoints of one edge can sample the neighbouring pieces
                // and miss the inside's (found by `cell_figures_bound_a_dense_scan`:
                // a bound 1.9 % under the scanned energy).
                // (`time_at_located` of the bins located above is
                // `time_at_unwrapped_s(mid ± h)`, and `locate_from` finds
                // the piece `power_at` finds: the same values.)
                let (t_r, t_l) = (tl.time_at_located(right) + delta, tl.time_at_located(left));
                let pr_mid = env.p_w[env.locate_from(t_r, &mut h8).2];
                let pl_mid = env.p_w[env.locate_from(t_l, &mut h9).2];
                let ((pl_u, pr_u), (pl_v, pr_v)) = (edge_p[c], edge_p[c + 1]);
                let (pr_min, pr_max) = (pr_u.min(pr_v).min(pr_mid), pr_u.max(pr_v).max(pr_mid));
                let (pl_min, pl_max) = (pl_u.min(pl_v).min(pl_mid), pl_u.max(pl_v).max(pl_mid));
                let width_rad = (v - u).to_radians();
                let rise = |fwd: f64, back: f64| width_rad * fwd.max(0.0).min(back.max(0.0));
                // τ falls below its smaller end value by at most the same
                // (the smaller of its largest descent either way).
                let tau_rise = rise(1.0 / wr_min - 1.0 / wl_max, 1.0 / wl_min - 1.0 / wr_max);
                let tau = ends_tau + tau_rise + t_slack;
                let tau_lb = ends_tau_min - tau_rise - t_slack;
                let e = ends_e
                    + rise(
                        pr_max / wr_min - pl_min / wl_max,
                        pl_max / wl_min - pr_min / wr_max,
                    )
                    + e_slack;
                (tau, e, tau_lb)
            } else {
                (ends_tau, ends_e, ends_tau_min)
            };
            let per_pass = per_pass_of.get(tau, |t| max_pulses_in(t + t_pad, f_p));
            let passes = passes_of.get(tau, |t| passes_in_window(t2, t + t_pad, frame_s));
            let per_j = self.per_j.get(self.laser, per_pass, passes);
            let mut single = p * delta * per_j;
            if edges.is_none() {
                // Rule 1 off the curved cells, tighter: the cell's largest
                // counts with the bins the passes of its inside meet, and
                // each end's counts with the bins its passes touch (see
                // `touch`).
                // The union arc's bins `[lo, hi]` but a first one that
                // ends, or a last one that starts, within `s` of the inside
                // (a superset of the inside's bins).
                let lo_in = if start_of(lo + 1) <= u - h + TOUCH_SNAP_DEG {
                    lo + 1
                } else {
                    lo
                };
                let hi_in = if start_of(hi) >= v + h - TOUCH_SNAP_DEG && hi > lo_in {
                    hi - 1
                } else {
                    hi
                };
                // With the hottest bin inside, the first figure below is
                // `single` itself: nothing to gain.
                let p_in = if (lo_in, hi_in) == (lo, hi) {
                    p
                } else {
                    inside.max_over(lo_in, hi_in.max(lo_in), |k| segs[wrap_index(k, n)].power_w)
                };
                if p_in < p {
                    let mut at = |p_w: f64, tau_s: f64| {
                        let k = max_pulses_in(tau_s + t_pad, f_p);
                        let q = passes_in_window(t2, tau_s + t_pad, frame_s);
                        p_w * delta * self.per_j.get(self.laser, k, q)
                    };
                    single = at(p_in, tau)
                        .max(at(p_near(c), tau_pt[c] + tau_touch))
                        .max(at(p_near(c + 1), tau_pt[c + 1] + tau_touch))
                        .min(single);
                }
            }
            rows.push(CellRow {
                p,
                curved: edges.is_some(),
                tau_ub: tau,
                e_ub: e.min(per_pass * p * delta),
                env_ub: e,
                single_ub: single,
                tau_lb,
            });
        }
        self.tau_pt = tau_pt;
        self.e_pt = e_pt;
        self.rows = rows;
    }

    /// Unwrapped time of the head at unwrapped azimuth `theta`.
    pub(super) fn time_at(&self, theta: f64) -> f64 {
        self.tl.time_at_unwrapped_s(theta)
    }

    /// `ω²(φ + off)` over the cell containing `mid + off`, as `a + b·φ`.
    fn spin_sq_at(&self, mid: f64, off: f64) -> (f64, f64) {
        let (k, j, _) = self.tl.locate_unwrapped(mid + off);
        let seg = &self.tl.bins()[j];
        let (a, b) = seg.spin_sq_line_deg();
        let anchor = 360.0 * k + seg.start_deg;
        (a + b * (off - anchor), b)
    }

    /// The exact figures of cell `c`: `τ` and `E` at the cell ends and at
    /// their stationary points inside (see the module docs), the pulse count
    /// from the cell's largest `τ`, and Rule 1.
    pub(super) fn exact(&self, c: usize) -> CellExact {
        let (u, v) = (self.cut(c), self.cut(c + 1));
        let CellExact {
            tau_s: mut cell_tau,
            tau_min_s: mut cell_tau_min,
            e: mut cell_e,
            ..
        } = ends(&self.cuts, &self.tau_pt, &self.e_pt, c);
        if self.rows[c].curved {
            let mid = 0.5 * (u + v);
            let right = self.spin_sq_at(mid, self.h);
            let left = self.spin_sq_at(mid, -self.h);
            let pr = self.env.power_at(self.time_at(mid + self.h) + self.delta);
            let pl = self.env.power_at(self.time_at(mid - self.h));
            for (wr, wl) in [(1.0, 1.0), (pr, pl)] {
                // wr²·ω²(φ − h) = wl²·ω²(φ + h)
                let den = wr * wr * left.1 - wl * wl * right.1;
                if den != 0.0 {
                    let phi = (wl * wl * right.0 - wr * wr * left.0) / den;
                    if phi > u && phi < v {
                        let t_lo = self.time_at(phi - self.h);
                        let t_hi = self.time_at(phi + self.h);
                        cell_tau = cell_tau.max(t_hi - t_lo);
                        cell_tau_min = cell_tau_min.min(t_hi - t_lo);
                        let e =
                            self.env.integral_to(t_hi + self.delta) - self.env.integral_to(t_lo);
                        if e > cell_e.0 {
                            cell_e = (e, phi);
                        }
                    }
                }
            }
        }
        let p = self.rows[c].p;
        let per_pass = max_pulses_in(cell_tau + self.t_pad, self.laser.pulse_rate_hz);
        let passes = passes_in_window(
            ael::T2_S.min(ael::TIME_BASE_S),
            cell_tau + self.t_pad,
            self.tl.period_s(),
        );
        // A pass also holds at most `per_pass` pulses of at most `p·Δ`, and
        // at most the pulses each bin's share of it holds (`pulse_capped`).
        // The per-bin sum can round one ulp above `per_pass·p·Δ` (the
        // sweep's bound `e_ub`, same operations): take the smaller, so the
        // exact value never exceeds its bound and the pruned search finds
        // what the exhaustive one finds.
        let coarse = per_pass * p * self.delta;
        let cap = self
            .pulse_capped_j(u, v, per_pass)
            .map_or(coarse, |e| e.min(coarse));
        CellExact {
            tau_s: cell_tau,
            tau_min_s: cell_tau_min,
            e: (cell_e.0.min(cap), wrap_deg(cell_e.1)),
            e_env: cell_e.0,
            // Off the curved cells the sweep's Rule 1 figure is exact.
            single: if self.rows[c].curved {
                p * self.delta * self.per_j.peek(self.laser, per_pass, passes)
            } else {
                self.rows[c].single_ub
            },
        }
    }
}

/// Unwrapped index (`turn·n + bin`) of the bin holding unwrapped `theta`.
pub(super) fn unwrapped_bin(tl: &Timeline<'_, Seg>, theta: f64, hint: &mut usize) -> i64 {
    let (k, i, _) = tl.locate_unwrapped_from(theta, hint);
    k as i64 * tl.bins().len() as i64 + i as i64
}

/// Cut `c` for `c` in `[0, len]`, the last one a turn after the first.
fn cut_of(cuts: &[f64], c: usize) -> f64 {
    let m = cuts.len();
    if c < m {
        cuts[c]
    } else {
        cuts[c - m] + 360.0
    }
}

/// `τ` and the envelope `E` (with its azimuth, the first maximum) over the
/// two ends of cell `c`, from their values at the cuts.
#[inline]
fn ends(cuts: &[f64], tau_pt: &[f64], e_pt: &[f64], c: usize) -> CellExact {
    let mut tau = 0.0f64;
    let mut tau_min = f64::INFINITY;
    let mut e = (0.0f64, cut_of(cuts, c));
    for k in [c, c + 1] {
        tau = tau.max(tau_pt[k]);
        tau_min = tau_min.min(tau_pt[k]);
        if e_pt[k] > e.0 {
            e = (e_pt[k], cut_of(cuts, k));
        }
    }
    CellExact {
        tau_s: tau,
        tau_min_s: tau_min,
        e,
        e_env: e.0,
        single: 0.0,
    }
}

/// The cells of `segs` (bins used as they are, not coalesced) for half
/// pass angle `h`, a laser of `f_p` Hz, handed to `f`.
#[cfg(test)]
pub(super) fn with_cells<R>(segs: &[Seg], h: f64, f_p: f64, f: impl FnOnce(&Cells<'_>) -> R) -> R {
    let laser = Laser {
        band: ael::Band::RetinalNir,
        c4: 1.0,
        pulse_duration_s: 5e-9,
        pulse_rate_hz: f_p,
    };
    let tl = Timeline::from_bins(segs);
    let env = Envelope::new(&tl, 1.0 / f_p);
    let cells = Cells::new(&tl, &env, h, &laser);
    f(&cells)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye_safety::bound::seg::seg;
    use proptest::prelude::*;

    /// `ω` rises from `w` at 0° to `2w` at 180° (constant acceleration,
    /// `ω² = w²(1 + x/60)` with `x` in degrees) and falls back to `w` at
    /// 360°, mirrored: the head is slowest at 0°.
    const W: f64 = 2.0 * std::f64::consts::PI;

    fn mirrored(p_a: f64, p_b: f64) -> [Seg; 2] {
        [
            seg(0.0, 180.0, p_a, W, 2.0 * W),
            seg(180.0, 180.0, p_b, 2.0 * W, W),
        ]
    }

    /// Time from 0° to `d` degrees into the accelerating bin (and, mirrored,
    /// from `360 − d` to 360°): `2x/(ω_s + ω(x))`, by hand.
    fn t_of(d: f64) -> f64 {
        2.0 * d.to_radians() / (W + W * (1.0 + d / 60.0).sqrt())
    }

    /// The cell `[350°, 370°]` (cuts at `360 − h` and `0 + h`, h = 10°) is
    /// curved, and its pass duration `τ(360 + y) = t(10 − y) + t(10 + y)` is
    /// largest inside it, at `y = 0` (`t` is concave): the ends give less.
    /// Its pass energy, with A 5 % hotter than B, `E(y) = P_B·t(10 − y) +
    /// P_A·(t(10 + y) + Δ)`, is largest where
    /// `ω(10 + y)/ω(10 − y) = P_A/P_B`: `(70 + y)/(70 − y) = 1.05²`,
    /// `y = 7.175/2.1025 = 3.4126…°`. Mutants 1358:89 (the sweep's `ω` at
    /// the right edge's far end taken at `v − h`: the bound of `τ` falls
    /// below the interior maximum) and 1467:57 (the envelope power at the
    /// right edge read at `mid − h`: `E`'s stationary point becomes `τ`'s)
    /// of the old `bound.rs` (11a69c7).
    #[test]
    fn curved_cell_takes_its_interior_maxima_by_hand() {
        let (p_a, p_b) = (1.05e-3, 1e-3);
        let f_p = 1e5;
        let delta = 1.0 / f_p;
        let segs = mirrored(p_a, p_b);
        with_cells(&segs, 10.0, f_p, |cells| {
            let c = (0..cells.len())
                .find(|&c| cells.cut(c) == 350.0)
                .expect("a cut at 350°");
            assert_eq!(cells.cut(c + 1), 370.0);
            assert!(cells.rows[c].curved);
            let x = cells.exact(c);
            let tau = 2.0 * t_of(10.0);
            assert!((x.tau_s - tau).abs() <= 1e-12 * tau, "{} vs {tau}", x.tau_s);
            // Both ends are shorter (by 3.5 %: `t(20) < 2·t(10)`), so the maximum is inside.
            assert!(cells.tau_pt[c].max(cells.tau_pt[c + 1]) < tau * 0.999);
            let y = 70.0 * (1.05f64.powi(2) - 1.0) / (1.05f64.powi(2) + 1.0);
            let e = p_b * t_of(10.0 - y) + p_a * (t_of(10.0 + y) + delta);
            assert!((x.e_env - e).abs() <= 1e-12 * e, "{} vs {e}", x.e_env);
            let e_mid = p_b * t_of(10.0) + p_a * (t_of(10.0) + delta);
            assert!(
                e > e_mid * (1.0 + 1e-6),
                "the maximum is off the cell's middle"
            );
            // The sweep's bounds are above the exact values.
            let row = cells.rows[c];
            assert!(row.tau_ub >= x.tau_s && row.env_ub >= x.e_env && row.e_ub >= x.e.0);
            assert!(row.tau_lb <= x.tau_min_s && row.single_ub >= x.single);
        });
    }

    /// Rule 1 pairs a hot bin touched only at a cell's end with that end's
    /// own pulse count. Bins: H `[0, 10)` at 10 mW and S `[10, 11)` at 1 mW,
    /// both at 200 rad/s, F `[11, 360)` at 1 mW and 10 rad/s; h = 5°, 10 kHz
    /// (the `Δ`-shifted cuts land beyond 16°). On the cell `[15, 16]` (cuts
    /// `H_end + h`, `S_end + h`) the left pass edge runs through S and the
    /// right one through F, so `τ` grows from `1°/200 + 9°/10` = 15.80 ms
    /// (158 pulses) to `10°/10` = 17.45 ms (175 pulses); 17 passes meet a
    /// 10 s window (`T_f` = 0.610 s). H is touched by the pass at 15° alone:
    /// the figure is H's power with 158 pulses, `P_H·Δ/(C5(158·17)·AEL)`,
    /// not with 175 (`C5 = 5·N^−¼`: `(175/158)^¼` = 1.026 times more).
    /// Mutant 1394:49 of the old `bound.rs` (11a69c7), `lo_in`'s `<=` →
    /// `>`, keeps H in the cell's inside and pairs it with 175 pulses.
    #[test]
    fn rule_one_pairs_a_bin_touched_at_one_end_with_that_end_s_count() {
        let f_p = 1e4;
        let segs = [
            seg(0.0, 10.0, 10e-3, 200.0, 200.0),
            seg(10.0, 1.0, 1e-3, 200.0, 200.0),
            seg(11.0, 349.0, 1e-3, 10.0, 10.0),
        ];
        with_cells(&segs, 5.0, f_p, |cells| {
            let c = (0..cells.len())
                .find(|&c| cells.cut(c) == 15.0)
                .expect("a cut at 15°");
            assert_eq!(cells.cut(c + 1), 16.0);
            let row = cells.rows[c];
            assert!(!row.curved);
            let frame = cells.tl.period_s();
            assert_eq!(max_pulses_in(cells.tau_pt[c], f_p), 158.0);
            assert_eq!(max_pulses_in(cells.tau_pt[c + 1], f_p), 175.0);
            for tau in [cells.tau_pt[c], cells.tau_pt[c + 1]] {
                assert_eq!(passes_in_window(10.0, tau, frame), 17.0);
            }
            let laser = cells.laser;
            let want = 10e-3 / f_p * laser.single_pulse_ratio_per_j(158.0, 17.0);
            assert!(
                (row.single_ub - want).abs() <= 1e-12 * want,
                "{} vs {want}",
                row.single_ub
            );
            let loose = 10e-3 / f_p * laser.single_pulse_ratio_per_j(175.0, 17.0);
            assert!((loose / want - (175.0f64 / 158.0).powf(0.25)).abs() < 1e-9);
            assert_eq!(cells.exact(c).single, row.single_ub);
        });
    }

    proptest! {
        /// On every cell of profiles with in-bin acceleration: the sweep's
        /// bounds are at least the exact figures (which the branch and
        /// bound relies on), and the exact `τ` and `E` are at least their
        /// values on a dense grid of azimuths of the cell (`τ(φ) =
        /// t(φ + h) − t(φ − h)`, `E(φ) = ∫ P̄` over `[t(φ − h), t(φ + h) + Δ]`,
        /// restated from the timeline and the envelope). Spins down to
        /// 0.005 rad/s: below 1 rad/s a slope `P/ω` exceeds `P·ω` (sampled
        /// mutants `cells.rs:258:32` `/` → `*`, `%` survived spins ≥ 2).
        #[test]
        fn cell_figures_bound_a_dense_scan(
            bins in proptest::collection::vec(
                (0.2f64..1.0, 0.0f64..5e-3, prop_oneof![2.0f64..60.0, 0.005f64..1.0]),
                2..8,
            ),
            h in 0.2f64..20.0,
            f_p in prop_oneof![Just(1e3), 1e4f64..3e5],
        ) {
            let total: f64 = bins.iter().map(|b| b.0).sum();
            let n = bins.len();
            let mut start = 0.0;
            let segs: Vec<Seg> = (0..n)
                .map(|i| {
                    let (w, p, w0) = bins[i];
                    let width = 360.0 * w / total;
                    let s = seg(start, width, p, w0, bins[(i + 1) % n].2);
                    start += width;
                    s
                })
                .collect();
            let delta = 1.0 / f_p;
            with_cells(&segs, h, f_p, |cells| {
                for c in 0..cells.len() {
                    let x = cells.exact(c);
                    let row = cells.rows[c];
                    let tol_t = 1e-12 * cells.tl.period_s();
                    let tol_e = 1e-12 * cells.env.total_j();
                    prop_assert!(row.tau_ub >= x.tau_s, "cell {c}: {row:?} {x:?}");
                    prop_assert!(row.env_ub >= x.e_env, "cell {c}: {row:?} {x:?}");
                    prop_assert!(row.e_ub >= x.e.0, "cell {c}: {row:?} {x:?}");
                    prop_assert!(row.single_ub >= x.single, "cell {c}: {row:?} {x:?}");
                    prop_assert!(row.tau_lb <= x.tau_min_s, "cell {c}: {row:?} {x:?}");
                    let (u, v) = (cells.cut(c), cells.cut(c + 1));
                    for k in 0..=32 {
                        let phi = u + (v - u) * f64::from(k) / 32.0;
                        let t_lo = cells.time_at(phi - h);
                        let t_hi = cells.time_at(phi + h);
                        let e = cells.env.integral_to(t_hi + delta) - cells.env.integral_to(t_lo);
                        prop_assert!(x.tau_s >= t_hi - t_lo - tol_t, "cell {c} at {phi}");
                        prop_assert!(x.tau_min_s <= t_hi - t_lo + tol_t, "cell {c} at {phi}");
                        prop_assert!(x.e_env >= e - tol_e, "cell {c} at {phi}");
                    }
                }
                Ok(())
            })?;
        }
    }

    /// The seed `cell_figures_bound_a_dense_scan` found (kept in
    /// `proptest-regressions` too): a cell between two envelope breakpoints
    /// of its left edge (bin 0's start + Δ, bin 1's start), whose ends both
    /// sampled the neighbouring pieces (4.23 and 4.79 mW) and not the
    /// inside's (2.14 mW): the sweep's energy bound was 2.644e-4 J, a scan of
    /// the cell reaches 2.6948e-4 J (at 27.25°).
    #[test]
    fn a_curved_cell_between_two_breakpoints_of_one_edge_bounds_its_inside() {
        let bins = [
            (
                0.216_423_918_213_016_87,
                0.002_137_857_961_070_370_4,
                11.848_426_476_105_562,
            ),
            (
                0.345_059_705_405_227_5,
                0.004_792_426_840_779_289,
                0.055_312_167_366_383_405,
            ),
            (0.741_841_315_111_670_3, 0.0, 42.939_562_223_284_45),
            (0.490_046_221_318_891_7, 0.0, 2.0),
            (0.469_064_531_219_561_76, 0.0, 2.0),
            (0.2, 0.004_226_853_972_167_895, 2.0),
        ];
        let (h, f_p) = (18.123_557_479_575_098, 278_025.953_227_064_9);
        let total: f64 = bins.iter().map(|b| b.0).sum();
        let mut start = 0.0;
        let segs: Vec<Seg> = (0..bins.len())
            .map(|i| {
                let (w, p, w0) = bins[i];
                let width = 360.0 * w / total;
                let s = seg(start, width, p, w0, bins[(i + 1) % bins.len()].2);
                start += width;
                s
            })
            .collect();
        with_cells(&segs, h, f_p, |cells| {
            let c = (0..cells.len())
                .find(|&c| (cells.cut(c) - 18.126).abs() < 1e-3)
                .expect("the cell at 18.126°");
            let (u, v) = (cells.cut(c), cells.cut(c + 1));
            assert!(cells.rows[c].curved);
            let mut scan = 0.0f64;
            for k in 0..=2000 {
                let phi = u + (v - u) * f64::from(k) / 2000.0;
                let t_lo = cells.time_at(phi - h);
                let t_hi = cells.time_at(phi + h);
                scan = scan
                    .max(cells.env.integral_to(t_hi + cells.delta) - cells.env.integral_to(t_lo));
            }
            assert!(scan > 2.69e-4, "{scan}");
            assert!(
                cells.rows[c].env_ub >= scan,
                "{:?} vs {scan}",
                cells.rows[c]
            );
            assert!(cells.rows[c].env_ub >= cells.exact(c).e_env);
        });
    }
}
