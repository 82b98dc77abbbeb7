//! The sound exposure bound: an upper bound of the true worst Class 1 ratio
//! of a scanned beam over every aperture azimuth, every pulse-clock phase,
//! every window placement and every window duration.
//!
//! The argument, rule by rule, is written down in `specs/eye_safety.md`;
//! the names below follow it.
//!
//! **Envelope.** Pulses are fired every `Δ = 1/f_p` s; a pulse fired at `t`
//! carries `P(t)·Δ` J. With `P̄(t) = max P` over `[t − Δ, t]` (the max
//! filter), every pulse's energy is at most `∫ P̄` over the `Δ` after it, and
//! these cells are disjoint: the energy of the pulses an aperture receives in
//! any time set `S` is at most `∫ P̄` over `S ⊕ [0, Δ]`, whatever the phase of
//! the pulse clock (free-running or locked to the rotation).
//!
//! **Passes.** The aperture at azimuth φ receives the pulses fired while the
//! head is in the closed arc `[φ − h, φ + h]`: a time interval `I_φ` of
//! length `τ(φ)` once per turn. The received envelope is periodic in the frame
//! period `T_f`, so a window of length `T` (`L = T + Δ = q·T_f + r`) holds at
//! most `q·E(φ) + min(E(φ), P̂·r)` J, where `E(φ) = ∫ P̄` over `I_φ ⊕ [0, Δ]`
//! and `P̂ = max P`.
//!
//! **Breakpoints.** `τ(φ)` and `E(φ)` are smooth between the azimuths where
//! a pass edge (or a pass edge shifted by `Δ` in time) meets a bin edge; on
//! each such cell both are `p_r·t(φ + h) − p_l·t(φ − h) + c` with `t` the
//! exact time along a constant-acceleration bin, whose one stationary point
//! solves a linear equation in φ (ω² is linear in angle). The maximum over a
//! cell is at a cell end or that point: every one is evaluated.
//!
//! **Windows.** For a fixed window start, the window energy is piecewise
//! linear in `T`, and on every row of Table 3 the AEL is `c·T^p` with
//! `0 ≤ p ≤ 1`: the ratio `(α + βT)/(c·T^p)` has no interior maximum, so the
//! supremum over all `T` is attained at window ends on envelope breakpoints,
//! at AEL row edges, or where the energy reaches the pass energy. Across
//! passes the same argument in the number of passes `q` leaves the first and
//! last `q` of each row.
//!
//! **Search.** The checker finds the same supremum by branch and bound
//! ([`Search::Pruned`]): linear sweeps give every cell's end values and a
//! cheap upper bound of its figures, and every window walk an upper bound of
//! its ratio; only cells and walks whose bound can still change the result
//! are evaluated exactly. [`Search::Exhaustive`] evaluates everything and is
//! tested bit-identical (`specs/eye_safety.md`, "Search"). Every shortcut
//! of the sweeps (merges for sorts, cached per-bin constants, memoized
//! monotone counts, cheaper `floor` and wrap) computes the same values as
//! the plain operation, and is tested so.
//!
//! **Rounding.** Every count that is a floor is taken as
//! `⌊x·(1 + 1e-9) + 1e-9⌋`, so a count that sits on an integer is taken
//! as the larger one and a perturbation of the inputs by 1e-12 cannot
//! lower it ([`COUNT_MARGIN`]).

use super::ael::{self, Band, Row};
use crate::profile::kinematics::{BinMotion, Timeline};

/// Relative margin by which every floor-count is rounded up (see module docs).
pub const COUNT_MARGIN: f64 = 1e-9;

/// Relative margin every rule's ratio is raised by before the verdict, so
/// float rounding in the bound can never land it below the true supremum.
pub const RATIO_MARGIN: f64 = 1e-9;

/// Envelope pieces a window walk visits before it continues with the slope
/// of the hottest piece within its reach (sound, looser); bounds the work on
/// very fine profiles.
pub const WALK_MAX_PIECES: usize = 96;

/// `(idx div m, idx mod m)` (Euclidean, `m > 0`) without an integer
/// division for the indices the sweeps use (within a period of `[0, m)`).
fn split_index(idx: i64, m: i64) -> (i64, usize) {
    if (0..m).contains(&idx) {
        (0, idx as usize)
    } else if (-m..0).contains(&idx) {
        (-1, (idx + m) as usize)
    } else if (m..2 * m).contains(&idx) {
        (1, (idx - m) as usize)
    } else {
        (idx.div_euclid(m), idx.rem_euclid(m) as usize)
    }
}

/// `idx mod m` in `[0, m)` (see [`split_index`]).
fn wrap_index(idx: i64, m: i64) -> usize {
    split_index(idx, m).1
}

/// The key `f64::total_cmp` orders by, as an integer (the same transform).
fn total_key(x: f64) -> i64 {
    let k = x.to_bits() as i64;
    k ^ (((k >> 63) as u64) >> 1) as i64
}

/// The inverse of [`total_key`].
fn of_total_key(k: i64) -> f64 {
    f64::from_bits((k ^ (((k >> 63) as u64) >> 1) as i64) as u64)
}

/// The runs `v[bounds[k]..bounds[k + 1]]`, each nondecreasing but for at
/// most one wrap (a single descent), sorted by `f64::total_cmp` and
/// deduplicated: the same vector as `sort_by(total_cmp)` then `dedup`
/// (the sorted order of a total order is unique), in linear time (merges of
/// the rotated runs, in two buffers). Falls back to the sort if a run has
/// two descents or a NaN. The runs must cover `v` (`bounds` from 0 to its
/// length).
fn sort_runs(mut v: Vec<f64>, bounds: &[usize]) -> Vec<f64> {
    debug_assert!(bounds.first() == Some(&0) && bounds.last() == Some(&v.len()));
    if v.iter().any(|x| x.is_nan()) {
        v.sort_by(f64::total_cmp);
        v.dedup();
        return v;
    }
    let keys: Vec<i64> = v.iter().map(|&x| total_key(x)).collect();
    // Each run rotated at its descent (if any) into `merged`.
    let mut merged: Vec<i64> = Vec::with_capacity(keys.len());
    for w in bounds.windows(2) {
        let run = &keys[w[0]..w[1]];
        let (mut descents, mut at) = (0usize, 0usize);
        for i in 1..run.len() {
            if run[i - 1] > run[i] {
                descents += 1;
                at = i;
            }
        }
        if descents > 1 || (descents == 1 && run[run.len() - 1] > run[0]) {
            v.sort_by(f64::total_cmp);
            v.dedup();
            return v;
        }
        merged.extend_from_slice(&run[at..]);
        merged.extend_from_slice(&run[..at]);
    }
    // Bottom-up: merge neighbouring runs pairwise until one is left.
    let mut other = keys;
    let mut starts: Vec<usize> = bounds.to_vec();
    while starts.len() > 2 {
        let mut next = Vec::with_capacity(starts.len() / 2 + 2);
        for k in (0..starts.len() - 1).step_by(2) {
            let (lo, mid) = (starts[k], starts[k + 1]);
            let hi = starts.get(k + 2).copied().unwrap_or(mid);
            next.push(lo);
            merge_keys(&merged[lo..mid], &merged[mid..hi], &mut other[lo..hi]);
        }
        next.push(merged.len());
        starts = next;
        std::mem::swap(&mut merged, &mut other);
    }
    v.clear();
    for &k in &merged {
        let x = of_total_key(k);
        if v.last() != Some(&x) {
            v.push(x);
        }
    }
    v
}

/// The stable merge of the sorted keys `a` and `b` (no `i64::MAX` or
/// `i64::MIN`, the keys of NaNs) into `out` (of their total length), built
/// from both ends at once: the front takes the smaller head (`a` on ties),
/// the back the larger tail (`b` on ties), so they fill the merged order's
/// two halves without branches on the data and as two independent chains.
fn merge_keys(a: &[i64], b: &[i64], out: &mut [i64]) {
    let n = a.len() + b.len();
    debug_assert_eq!(out.len(), n);
    let (mut i, mut j) = (0usize, 0usize);
    let (mut ie, mut je) = (a.len(), b.len());
    for k in 0..n / 2 {
        let av = if i < a.len() { a[i] } else { i64::MAX };
        let bv = if j < b.len() { b[j] } else { i64::MAX };
        let take_b = bv < av;
        out[k] = if take_b { bv } else { av };
        j += usize::from(take_b);
        i += usize::from(!take_b);
        let av = if ie > 0 { a[ie - 1] } else { i64::MIN };
        let bv = if je > 0 { b[je - 1] } else { i64::MIN };
        let take_a = av > bv;
        out[n - 1 - k] = if take_a { av } else { bv };
        ie -= usize::from(take_a);
        je -= usize::from(!take_a);
    }
    if n % 2 == 1 {
        let av = if i < a.len() { a[i] } else { i64::MAX };
        let bv = if j < b.len() { b[j] } else { i64::MAX };
        out[n / 2] = av.min(bv);
    }
}

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

/// The laser and band constants every rule needs.
#[derive(Debug, Clone, Copy)]
pub struct Laser {
    /// Band.
    pub band: Band,
    /// C4.
    pub c4: f64,
    /// Pulse duration, s.
    pub pulse_duration_s: f64,
    /// Pulse rate, Hz.
    pub pulse_rate_hz: f64,
}

impl Laser {
    /// AEL for an exposure of `t_s` (clamped to the pulse duration below and
    /// the table's end above), restrictive at row edges.
    #[must_use]
    pub fn ael_j(&self, t_s: f64) -> f64 {
        let t = t_s
            .max(self.pulse_duration_s)
            .max(self.band.min_duration_s())
            .min(ael::T_MAX_TABLE_S);
        ael::table3_j(self.band, self.c4, t)
    }

    /// Table 3 rows of the band.
    #[must_use]
    pub fn rows(&self) -> [Row; 4] {
        ael::rows(self.band, self.c4)
    }

    /// AEL row edges (and the pulse duration) inside `(lo, hi)`.
    fn edges_within(&self, lo: f64, hi: f64) -> impl Iterator<Item = f64> {
        let rows = self.rows();
        let p = self.pulse_duration_s;
        rows.into_iter()
            .flat_map(|r| [r.t_lo_s, r.t_hi_s])
            .chain(std::iter::once(p))
            .filter(move |&t| t > lo && t < hi)
    }

    /// The smallest AEL over `[lo_s, hi_s]`: the AEL grows within each row
    /// of Table 3 but may fall at a row edge (905 nm at 5 µs, where
    /// [`Self::ael_j`] takes the smaller row), so the ends and the edges
    /// between are every candidate.
    fn min_ael_over(&self, lo_s: f64, hi_s: f64) -> f64 {
        let mut a = self.ael_j(lo_s).min(self.ael_j(hi_s));
        for t in self.edges_within(lo_s, hi_s) {
            a = a.min(self.ael_j(t));
        }
        a
    }

    /// `sup τ/AEL(τ)` over `0 < τ ≤ tau_hi_s`: on every row of Table 3 the
    /// AEL is `c·τ^p` with `0 ≤ p ≤ 1`, so `τ/AEL(τ)` is nondecreasing
    /// within a row (and below the clamp at the pulse duration, where the
    /// AEL is constant), and the supremum is at `tau_hi_s` or at a row edge
    /// below it (where [`Self::ael_j`] takes the smaller row). Bounds
    /// `E/AEL(τ) ≤ (E/τ)·K` for every `τ ≤ tau_hi_s`.
    fn mean_power_factor(&self, tau_hi_s: f64) -> f64 {
        let mut k = tau_hi_s / self.ael_j(tau_hi_s);
        for t in self.edges_within(0.0, tau_hi_s) {
            k = k.max(t / self.ael_j(t));
        }
        k
    }

    /// Pulses grouped into one effective pulse (summed within `T_i`, 700–1050 nm):
    /// the most pulses a closed `T_i` window holds, at most `per_pass`.
    #[must_use]
    pub fn group(&self, per_pass: f64) -> f64 {
        if self.band == Band::RetinalNir && self.pulse_duration_s <= self.band.t_i_s() {
            max_pulses_in(self.band.t_i_s(), self.pulse_rate_hz).min(per_pass.max(1.0))
        } else {
            1.0
        }
    }

    /// Rule 1 ratio for pulses (or groups) of at most `pulse_energy_j` each
    /// (one pulse; the group is applied here), with at most `per_pass`
    /// pulses in any pass and `passes_t2` passes meeting any T2 window:
    /// `pulse_energy_j ×` [`Self::single_pulse_ratio_per_j`].
    #[must_use]
    pub fn single_pulse_ratio(&self, pulse_energy_j: f64, per_pass: f64, passes_t2: f64) -> f64 {
        pulse_energy_j * self.single_pulse_ratio_per_j(per_pass, passes_t2)
    }

    /// Rule 1 ratio per joule of pulse energy. Nondecreasing in both counts:
    /// C5 falls as the pulse count grows, and the `T_i` group grows with the
    /// pulses per pass until it reaches its cap, after which the number of
    /// groups grows.
    #[must_use]
    pub fn single_pulse_ratio_per_j(&self, per_pass: f64, passes_t2: f64) -> f64 {
        let t_max = ael::T2_S.min(ael::TIME_BASE_S);
        let g = self.group(per_pass);
        // C5 = 1 for pulses longer than T_i (2014 small-source rule).
        let c5_of = |n: f64| {
            if self.pulse_duration_s > self.band.t_i_s() {
                1.0
            } else {
                ael::c5(self.band, n, t_max)
            }
        };
        let n_pulses = per_pass * passes_t2;
        let single = 1.0 / (c5_of(n_pulses) * self.ael_j(self.pulse_duration_s));
        if g > 1.0 {
            // Greedy grouping from the first pulse: ⌈K/g⌉ groups per pass.
            let n_groups = (per_pass / g).ceil() * passes_t2;
            let group = g / (c5_of(n_groups) * self.ael_j(self.band.t_i_s()));
            single.max(group)
        } else {
            single
        }
    }

    /// The largest ratio `min(cap_j, e0_j + slope_w·(T − t0))/AEL(T)` over
    /// `T ∈ [t0, t1]`, the energy being linear until it reaches `cap_j`
    /// and flat after: evaluated at the segment ends, at the cap and at every
    /// AEL row edge in between (the ratio has no interior maximum).
    fn linear_capped_max(
        &self,
        t0: f64,
        t1: f64,
        e0_j: f64,
        slope_w: f64,
        cap_j: f64,
    ) -> (f64, f64) {
        if t1.is_nan() || t0.is_nan() || t1 < t0 {
            return (0.0, t0);
        }
        let energy = |t: f64| (e0_j + slope_w * (t - t0)).min(cap_j);
        let mut best = (0.0, t0);
        let mut consider = |t: f64| {
            let r = energy(t) / self.ael_j(t);
            if r > best.0 {
                best = (r, t);
            }
        };
        consider(t0);
        consider(t1);
        if slope_w > 0.0 && e0_j < cap_j {
            let t_cap = t0 + (cap_j - e0_j) / slope_w;
            if t_cap > t0 && t_cap < t1 {
                consider(t_cap);
            }
        }
        for t in self.edges_within(t0, t1) {
            consider(t);
        }
        best
    }

    /// Rule 2 over windows spanning several passes, up to the time base:
    /// returns (ratio, window duration). Windows from
    /// `T_f − max(τ, Δ)` on (where a window can first meet two passes) are
    /// bounded two ways, each valid for every window, and the smaller
    /// supremum is returned (`sup min(A, C) ≤ min(sup A, sup C)`):
    ///
    /// - **A, envelope:** `q·E + min(E, P̂·r)` with `L = T + Δ = q·T_f + r`
    ///   and `E` = [`PassFigures::envelope_j`], the integral of the received
    ///   envelope over one period (see the module docs);
    /// - **C, pass count:** at most [`passes_in_window`] passes meet a window,
    ///   each carrying at most [`PassFigures::pulses_j`].
    ///
    /// A must use the envelope integral, not the pulse-capped pass energy:
    /// the pulses of a pass sit anywhere in it, so `m` capped passes can fit
    /// in `(m − 1)·T_f + r` with `P̂·r` below one capped pass (found by the
    /// differential test: 9 passes of 3 pulses at 2049 Hz in 0.3563 s).
    #[must_use]
    pub fn multi_pass_ratio(&self, frame_s: f64, pass: PassFigures, p_hat_w: f64) -> (f64, f64) {
        let delta = 1.0 / self.pulse_rate_hz;
        let tb = ael::TIME_BASE_S;
        let t_start = (frame_s - pass.duration_s.max(delta)).max(0.0);
        if pass.envelope_j <= 0.0 || pass.pulses_j <= 0.0 || t_start >= tb {
            return (0.0, t_start);
        }
        let a = self.envelope_family_max(frame_s, pass.envelope_j, p_hat_w, t_start);
        let c = self.pass_count_max(frame_s, pass, t_start);
        if a.0 <= c.0 {
            a
        } else {
            c
        }
    }

    /// The time-base figure: the smaller of the two multi-pass energy
    /// bounds over a window of the time base, over its AEL.
    #[must_use]
    pub fn time_base_ratio(&self, frame_s: f64, pass: PassFigures, p_hat_w: f64) -> f64 {
        let delta = 1.0 / self.pulse_rate_hz;
        let tb = ael::TIME_BASE_S;
        let e = pass
            .envelope_energy(tb, frame_s, delta, p_hat_w)
            .min(pass.count_energy(tb, frame_s));
        e / self.ael_j(tb)
    }

    /// `sup A(T)/AEL(T)` over `[t_start, T_b]` (see [`Self::multi_pass_ratio`]):
    /// within a row of Table 3 (`c·T^p`, `0 ≤ p ≤ 1`) the ratio has no
    /// interior maximum on a linear piece of `A`, and over the family of
    /// piece ends `T = q·T_f + r_f − Δ` it is quasi-convex in `q`, so the
    /// row edges, `t_start`, `T_b` and the first and last two `q` of each
    /// row and family are every candidate.
    fn envelope_family_max(
        &self,
        frame_s: f64,
        e_j: f64,
        p_hat_w: f64,
        t_start: f64,
    ) -> (f64, f64) {
        let delta = 1.0 / self.pulse_rate_hz;
        let r_star = if p_hat_w > 0.0 {
            (e_j / p_hat_w).min(frame_s)
        } else {
            frame_s
        };
        let fig = PassFigures {
            envelope_j: e_j,
            pulses_j: e_j,
            duration_s: 0.0,
        };
        self.row_sup(
            t_start,
            |t| fig.envelope_energy(t, frame_s, delta, p_hat_w),
            |lo, hi| {
                // Family points T = q·T_f + r_f − Δ, r_f ∈ {0, r*}: first and last q in the row.
                let mut ts = Vec::with_capacity(8);
                for r_f in [0.0, r_star] {
                    let q_lo = ((lo + delta - r_f) / frame_s).ceil().max(0.0);
                    let q_hi = ((hi + delta - r_f) / frame_s).floor();
                    for q in [q_lo, q_lo + 1.0, q_hi - 1.0, q_hi] {
                        if q >= 0.0 && q <= q_hi && q >= q_lo {
                            ts.push(q * frame_s + r_f - delta);
                        }
                    }
                }
                ts
            },
        )
    }

    /// `sup C(T)/AEL(T)` over `[t_start, T_b]`: `C` steps up at
    /// `T_k = k·T_f − τ` (to `k + 1` passes) and is flat between, where the
    /// ratio is largest at the step or at a row edge; over the steps of one
    /// row, `(k + 1)·e/(c·(k·T_f − τ)^p)` is quasi-convex in `k`, so the
    /// first and last two steps of each row are every candidate.
    fn pass_count_max(&self, frame_s: f64, pass: PassFigures, t_start: f64) -> (f64, f64) {
        let tau = pass.duration_s.max(0.0);
        self.row_sup(
            t_start,
            |t| pass.count_energy(t, frame_s),
            |lo, hi| {
                let k_lo = ((lo + tau) / frame_s).ceil().max(1.0);
                let k_hi = ((hi + tau) / frame_s).floor();
                [k_lo, k_lo + 1.0, k_hi - 1.0, k_hi]
                    .into_iter()
                    .filter(|&k| k >= 1.0 && k >= k_lo && k <= k_hi)
                    .map(|k| k * frame_s - tau)
                    .collect()
            },
        )
    }

    /// The largest `energy(T)/AEL(T)` over `T ∈ [t_start, T_b]` among
    /// `t_start`, `T_b`, every row's edges and the row's own candidates
    /// `inner(lo, hi)`: (ratio, duration).
    fn row_sup(
        &self,
        t_start: f64,
        energy: impl Fn(f64) -> f64,
        inner: impl Fn(f64, f64) -> Vec<f64>,
    ) -> (f64, f64) {
        let tb = ael::TIME_BASE_S;
        let mut best = (0.0, t_start);
        let mut consider = |t: f64| {
            if t >= t_start && t <= tb {
                let r = energy(t) / self.ael_j(t);
                if r > best.0 {
                    best = (r, t);
                }
            }
        };
        consider(t_start);
        consider(tb);
        for row in self.rows() {
            let lo = row.t_lo_s.max(t_start);
            let hi = row.t_hi_s.min(tb);
            if lo > hi {
                continue;
            }
            consider(lo);
            consider(hi);
            for t in inner(lo, hi) {
                consider(t);
            }
        }
        best
    }

    /// Ratio of a stationary beam (every pulse enters the aperture: a
    /// stalled rotor, or the `ael` report) of power `power_w`.
    #[must_use]
    pub fn stationary_ratio(&self, power_w: f64) -> (f64, Rule) {
        let delta = 1.0 / self.pulse_rate_hz;
        let t2 = ael::T2_S.min(ael::TIME_BASE_S);
        // All pulses of T2 in one "pass".
        let per_pass = max_pulses_in(t2, self.pulse_rate_hz);
        let single = self.single_pulse_ratio(power_w * delta, per_pass, 1.0);
        let (train, t) = self.linear_capped_max(
            self.pulse_duration_s,
            ael::TIME_BASE_S,
            power_w * (self.pulse_duration_s + delta),
            power_w,
            f64::INFINITY,
        );
        if single >= train {
            (single, Rule::SinglePulse)
        } else {
            (train, Rule::for_duration(t, f64::INFINITY))
        }
    }
}

/// What the multi-pass rules know of one aperture's passes, as maxima over
/// every aperture azimuth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassFigures {
    /// Largest integral of the received envelope over one pass widened by a
    /// pulse spacing (`E(φ)` of the module docs), J.
    pub envelope_j: f64,
    /// Largest energy the pulses of one pass can carry (the envelope capped
    /// by the pass's pulse count), J; at most `envelope_j`.
    pub pulses_j: f64,
    /// Longest pass, s.
    pub duration_s: f64,
}

impl PassFigures {
    /// Bound A: the energy of the pulses an aperture receives in any window
    /// of `t_s`, from the envelope's periodicity: `q·E + min(E, P̂·r)`,
    /// `L = T + Δ = q·T_f + r`.
    #[must_use]
    pub fn envelope_energy(&self, t_s: f64, frame_s: f64, delta_s: f64, p_hat_w: f64) -> f64 {
        let l = t_s + delta_s;
        let q = (l / frame_s).floor();
        let r = (l - q * frame_s).max(0.0);
        q * self.envelope_j + self.envelope_j.min(p_hat_w * r)
    }

    /// Bound C: at most [`passes_in_window`] passes meet a window of `t_s`,
    /// each with at most [`Self::pulses_j`].
    #[must_use]
    pub fn count_energy(&self, t_s: f64, frame_s: f64) -> f64 {
        passes_in_window(t_s, self.duration_s.max(0.0), frame_s) * self.pulses_j
    }
}

/// An eye-safety rule, by the window it bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Rule {
    /// Each pulse (or `T_i` group) against the C5-corrected single-pulse AEL.
    SinglePulse,
    /// Pulse-train energy in windows shorter than one revolution (within a pass).
    PassTrain,
    /// Pulse-train energy in windows of one revolution up to T2 = 10 s.
    T2Train,
    /// Pulse-train energy in windows beyond T2 up to the 100 s time base
    /// (the average-power rule).
    TimeBase,
}

impl Rule {
    /// The rule whose windows contain duration `t_s` (frame period `frame_s`).
    #[must_use]
    pub fn for_duration(t_s: f64, frame_s: f64) -> Self {
        if t_s < frame_s {
            Self::PassTrain
        } else if t_s <= ael::T2_S {
            Self::T2Train
        } else {
            Self::TimeBase
        }
    }
}

impl std::fmt::Display for Rule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::SinglePulse => "single-pulse energy (C5-corrected)",
            Self::PassTrain => "pulse-train energy within one pass",
            Self::T2Train => "pulse-train energy over several passes (up to T2 = 10 s)",
            Self::TimeBase => "average power over the 100 s time base",
        })
    }
}

/// A bin as the bound sees it: start angle (deg), width (deg), power (W),
/// and the spin at its two edges (constant angular acceleration between;
/// the kinematics are [`BinMotion`]'s, shared with profile bins).
#[derive(Debug, Clone, Copy)]
pub struct Seg {
    /// Start azimuth, deg.
    pub start_deg: f64,
    /// Width, deg.
    pub width_deg: f64,
    /// Power, W.
    pub power_w: f64,
    /// Spin at the start, rad/s.
    pub spin_start_rad_s: f64,
    /// Spin at the end, rad/s.
    pub spin_end_rad_s: f64,
}

impl BinMotion for Seg {
    fn start_deg(&self) -> f64 {
        self.start_deg
    }
    fn width_deg(&self) -> f64 {
        self.width_deg
    }
    fn spin_start_rad_s(&self) -> f64 {
        self.spin_start_rad_s
    }
    fn spin_end_rad_s(&self) -> f64 {
        self.spin_end_rad_s
    }
    fn power_w(&self) -> f64 {
        self.power_w
    }
}

/// Whether `b` continues `a` as the same emission: equal power and one
/// constant spin across both (no acceleration in either).
fn same_run(a: &Seg, b: &Seg) -> bool {
    a.power_w == b.power_w
        && a.spin_start_rad_s == a.spin_end_rad_s
        && b.spin_start_rad_s == b.spin_end_rad_s
        && a.spin_start_rad_s == b.spin_start_rad_s
}

/// `segs` with every run of consecutive bins of one power and one constant
/// spin merged into one bin (not across 0°). The head's motion and the
/// emitted power are the same functions of time, so every quantity the
/// bound bounds (pass durations, pulse counts, envelope integrals) is the
/// same; only edges where nothing changes are dropped, and with them the
/// cells, walks and per-bin pulse caps they would cost (a pulse cap over a
/// merged bin is at most the sum of its parts' caps). The merged width is
/// the sum of the parts' (the times differ from the parts' sum by float
/// rounding only, far inside [`RATIO_MARGIN`]). Borrowed when nothing
/// merges. Piecewise-constant profiles (the closed forms: three runs in
/// 360 bins) cost their runs, not their bins.
fn coalesce(segs: &[Seg]) -> std::borrow::Cow<'_, [Seg]> {
    if !segs.windows(2).any(|w| same_run(&w[0], &w[1])) {
        return std::borrow::Cow::Borrowed(segs);
    }
    let mut out: Vec<Seg> = Vec::with_capacity(segs.len());
    for s in segs {
        match out.last_mut() {
            Some(last) if same_run(last, s) => last.width_deg += s.width_deg,
            _ => out.push(*s),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// `ω²` at `x_deg` into `seg` as `a + b·x_deg` (linear: constant acceleration).
fn spin_sq_line(seg: &Seg) -> (f64, f64) {
    (
        seg.spin_start_rad_s.powi(2),
        2.0 * seg.accel_rad_s2() * std::f64::consts::PI / 180.0,
    )
}

/// The max-filtered power `P̄` over one period, as pieces `[t_k, t_{k+1})`
/// with prefix integrals, extended periodically.
struct Envelope {
    /// Piece starts in `[0, T_f)`, then `T_f`.
    t_s: Vec<f64>,
    /// `P̄` on each piece, W.
    p_w: Vec<f64>,
    /// `∫ P̄` from 0 to each piece start, then the period's total.
    cum_j: Vec<f64>,
    frame_s: f64,
}

impl Envelope {
    fn new(tl: &Timeline<'_, Seg>, delta_s: f64) -> Self {
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
        let mut e = 0.0;
        cum_j.push(0.0);
        for j in 0..m {
            e += p_w[j] * (t_s[j + 1] - t_s[j]);
            cum_j.push(e);
        }
        Self {
            t_s,
            p_w,
            cum_j,
            frame_s,
        }
    }

    fn pieces(&self) -> usize {
        self.p_w.len()
    }

    /// `∫ P̄` over one period, J.
    fn total_j(&self) -> f64 {
        self.cum_j[self.pieces()]
    }

    /// For unwrapped `t`: whole periods before it, its offset in the
    /// period, and the piece containing that offset.
    fn locate(&self, t: f64) -> (f64, f64, usize) {
        let (k, r) = self.split(t);
        (k, r, self.piece_of(r))
    }

    /// As [`Self::locate`], searching forward from piece `*hint` (the piece
    /// of an earlier offset in the same period): the same piece, in amortised
    /// constant time for increasing times.
    #[inline]
    fn locate_from(&self, t: f64, hint: &mut usize) -> (f64, f64, usize) {
        let (k, r) = self.split(t);
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

    #[inline]
    fn split(&self, t: f64) -> (f64, f64) {
        if (0.0..self.frame_s).contains(&t) {
            // The common case, without a call to `floor` (same result).
            return (0.0, t);
        }
        let k = (t / self.frame_s).floor();
        (k, t - k * self.frame_s)
    }

    fn piece_of(&self, r: f64) -> usize {
        self.t_s
            .partition_point(|&c| c <= r)
            .saturating_sub(1)
            .min(self.pieces() - 1)
    }

    #[inline]
    fn integral_at(&self, (k, r, j): (f64, f64, usize)) -> f64 {
        k * self.total_j() + self.cum_j[j] + self.p_w[j] * (r - self.t_s[j])
    }

    /// `∫₀^t P̄` for unwrapped `t`.
    fn integral_to(&self, t: f64) -> f64 {
        self.integral_at(self.locate(t))
    }

    /// `P̄` on the piece containing unwrapped `t`.
    fn power_at(&self, t: f64) -> f64 {
        self.p_w[self.locate(t).2]
    }

    /// Unwrapped breakpoint `idx` (piece starts, periodic).
    fn bp(&self, idx: i64) -> f64 {
        let m = self.pieces() as i64;
        let (k, j) = split_index(idx, m);
        self.t_s[j] + k as f64 * self.frame_s
    }

    /// Unwrapped index of the piece containing unwrapped `t`.
    fn unwrapped_piece(&self, t: f64, hint: &mut usize) -> i64 {
        let (k, _, j) = self.locate_from(t, hint);
        k as i64 * self.pieces() as i64 + j as i64
    }

    fn p_of(&self, idx: i64) -> f64 {
        self.p_w[wrap_index(idx, self.pieces() as i64)]
    }
}

/// Popped items a [`Queue`] keeps before it compacts.
const QUEUE_COMPACT_MIN: usize = 4096;

/// A double-ended queue for the monotone-deque maxima, where items are
/// pushed only at the back: a vector and the index of its front (popping
/// the front advances the index; nothing is wrapped, and the popped front is dropped once it is over half the vector).
struct Queue<T> {
    items: Vec<T>,
    head: usize,
}

impl<T> Default for Queue<T> {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            head: 0,
        }
    }
}

impl<T: Copy> Queue<T> {
    fn front(&self) -> Option<&T> {
        self.items.get(self.head)
    }

    fn back(&self) -> Option<&T> {
        self.items.last().filter(|_| self.items.len() > self.head)
    }

    fn pop_front(&mut self) {
        if self.head < self.items.len() {
            self.head += 1;
        }
    }

    fn pop_back(&mut self) {
        if self.items.len() > self.head {
            self.items.pop();
        }
    }

    /// Pushes `x`; when the popped front is over half the vector (and at
    /// least [`QUEUE_COMPACT_MIN`] items), it is dropped first, so memory
    /// stays within twice the live items (amortised constant time: each
    /// item is moved at most once per compaction that halves the vector).
    fn push_back(&mut self, x: T) {
        if self.head >= QUEUE_COMPACT_MIN && 2 * self.head >= self.items.len() {
            self.items.drain(..self.head);
            self.head = 0;
        }
        self.items.push(x);
    }
}

/// Maximum of a periodic sequence over index windows `[lo, hi]` whose ends
/// never decrease from one query to the next (monotone deque): amortised
/// constant time per query.
struct SlidingMax {
    /// (index, value) of the candidates, values decreasing.
    deque: Queue<(i64, f64)>,
    next: Option<i64>,
}

impl SlidingMax {
    fn new() -> Self {
        Self {
            deque: Queue::default(),
            next: None,
        }
    }

    /// `max value(k)` for `k` in `[lo, hi]` (`lo ≤ hi`; both ends at least
    /// those of the previous query).
    fn max_over(&mut self, lo: i64, hi: i64, value: impl Fn(i64) -> f64) -> f64 {
        while self.deque.front().is_some_and(|&(k, _)| k < lo) {
            self.deque.pop_front();
        }
        let mut next = self.next.map_or(lo, |n| n.max(lo));
        while next <= hi {
            let v = value(next);
            while self.deque.back().is_some_and(|&(_, w)| w <= v) {
                self.deque.pop_back();
            }
            self.deque.push_back((next, v));
            next += 1;
        }
        self.next = Some(next);
        self.deque.front().map_or(0.0, |&(_, v)| v)
    }
}

/// Which cells and window walks [`evaluate_with`] evaluates exactly.
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Search {
    /// Branch and bound: a cell or walk is evaluated only while its cheap
    /// upper bound could still change the result (the default).
    Pruned,
    /// Every cell and every walk (the reference the pruned search is
    /// tested bit-identical against).
    Exhaustive,
}

/// The result of the bound.
#[derive(Debug, Clone, PartialEq)]
pub struct Bound {
    /// Worst ratio over every rule (≤ 1 is Class 1).
    pub worst_ratio: f64,
    /// Rule binding there.
    pub binding_rule: Rule,
    /// Azimuth of the aperture where it binds (for window rules: the
    /// aperture with the largest pass energy), deg.
    pub worst_azimuth_deg: f64,
    /// Each rule's ratio, in [`Rule`] order.
    pub ratios: [f64; 4],
    /// Largest pass duration over all azimuths, s.
    pub max_pass_duration_s: f64,
    /// Largest pulse count per pass, any clock phase.
    pub max_pulses_per_pass: f64,
    /// Largest pass energy (envelope), J.
    pub max_pass_energy_j: f64,
    /// Window duration where the worst train rule binds, s.
    pub worst_window_s: f64,
}

/// Slack, relative to a turn's time or envelope energy, added to the cheap
/// bounds of float differences (times, envelope integrals) so they stay
/// above the exact evaluation's rounding (a few units in the last place of
/// those totals).
const PRUNE_SLACK: f64 = 1e-12;

/// Evaluates the bound for bins `segs` (validated: cover [0, 360) in order,
/// positive spins), half pass angle `half_deg`, and `laser`.
#[must_use]
pub fn evaluate(segs: &[Seg], half_deg: f64, laser: &Laser) -> Bound {
    evaluate_with(segs, half_deg, laser, Search::Pruned)
}

/// [`evaluate`] with a choice of search; both searches return bit-identical
/// results (the pruned one skips only what provably cannot change them).
#[doc(hidden)]
#[must_use]
pub fn evaluate_with(segs: &[Seg], half_deg: f64, laser: &Laser, search: Search) -> Bound {
    let runs = coalesce(segs);
    let segs: &[Seg] = &runs;
    let tl = Timeline::from_bins(segs);
    let delta = 1.0 / laser.pulse_rate_hz;
    let frame_s = tl.period_s();
    let env = Envelope::new(&tl, delta);
    let p_hat = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
    let cells = Cells::new(&tl, &env, half_deg.min(180.0), laser);
    let best = cells.search(search);

    // Rule 2 within one revolution: the whole-pass windows, then window
    // walks over envelope breakpoints within one pass.
    let l_max = (best.tau_max + delta).min(frame_s);
    let walks = Walks {
        env: &env,
        tl: &tl,
        laser,
        two_h_deg: 2.0 * half_deg.min(180.0),
        e_pass: best.e_max.0,
        l_max,
    };
    // Windows of a whole pass or more hold at most `E⁺` (not above the
    // whole-pass bound below, a cheap first threshold for the pruning).
    let t0 = best.tau_max;
    let first = Best(best.e_max.0 / laser.ael_j(t0), t0);
    let within = walks.search(search, first);
    let Best(pass_ratio, pass_window) =
        cells.full_pass_max(search, best.e_max.0, best.tau_max, within);
    // Rule 2 over several passes, up to the time base.
    let pass = PassFigures {
        envelope_j: best.e_env_max,
        pulses_j: best.e_max.0,
        duration_s: best.tau_max,
    };
    let (multi_ratio, multi_window) = laser.multi_pass_ratio(frame_s, pass, p_hat);
    let multi_rule = Rule::for_duration(multi_window, frame_s);
    let mut ratios = [best.single.0, pass_ratio, 0.0, 0.0];
    match multi_rule {
        Rule::TimeBase => ratios[3] = multi_ratio,
        _ => ratios[2] = multi_ratio,
    }
    // Also report the time-base figure itself (mean power over 100 s).
    ratios[3] = ratios[3].max(laser.time_base_ratio(frame_s, pass, p_hat));
    for r in &mut ratios {
        *r *= 1.0 + RATIO_MARGIN;
    }
    let rules = [
        Rule::SinglePulse,
        Rule::PassTrain,
        Rule::T2Train,
        Rule::TimeBase,
    ];
    let (mut k_best, mut r_best) = (0, ratios[0]);
    for (k, &r) in ratios.iter().enumerate().skip(1) {
        if r > r_best {
            (k_best, r_best) = (k, r);
        }
    }
    Bound {
        worst_ratio: r_best,
        binding_rule: rules[k_best],
        worst_azimuth_deg: if k_best == 0 {
            best.single.1
        } else {
            best.e_max.1
        },
        ratios,
        max_pass_duration_s: best.tau_max,
        max_pulses_per_pass: max_pulses_in(best.tau_max, laser.pulse_rate_hz),
        max_pass_energy_j: best.e_max.0,
        worst_window_s: if k_best == 1 {
            pass_window
        } else {
            multi_window
        },
    }
}

/// `a` wrapped into `[0, 360)`.
fn wrap360(a: f64) -> f64 {
    // `rem_euclid` takes `r = a % 360` (exact), then `r + 360` if `r < 0`.
    // Within a turn of `[0, 360)`, `a % 360` is `a` (`|a| < 360`) or
    // `a − 360` (`360 ≤ a < 720`, a subtraction that is exact by Sterbenz's
    // lemma): the same value without the library's `fmod`.
    let w = if (0.0..360.0).contains(&a) {
        a
    } else if a > -360.0 && a < 0.0 {
        a + 360.0
    } else if (360.0..720.0).contains(&a) {
        a - 360.0
    } else {
        a.rem_euclid(360.0)
    };
    if w >= 360.0 {
        0.0
    } else {
        w
    }
}

/// Most bins a cell's union arc may touch for the per-bin pulse cap of a
/// pass to be evaluated (beyond, the cap `K·P_max·Δ` is used).
pub const PULSE_CAP_MAX_BINS: i64 = 64;

/// Sub-cells per cell for the per-bin pulse caps (`Cells::pulse_capped_split`).
const PULSE_CAP_SPLIT: usize = 8;

/// Snap (deg) by which the arc a cell's pulses can come from is widened, so
/// bins touched at an edge count.
const TOUCH_SNAP_DEG: f64 = 1e-9;

/// One cell's exact figures.
#[derive(Debug, Clone, Copy)]
struct CellExact {
    /// Largest pass duration over the cell, s.
    tau_s: f64,
    /// Smallest pass duration over the cell, s.
    tau_min_s: f64,
    /// Largest pass energy (envelope and pulse-count bounds), J, and the
    /// azimuth (wrapped) where the envelope bound peaks.
    e: (f64, f64),
    /// Largest envelope integral over a pass (not capped by the pulse
    /// count: the periodic bound of [`Laser::multi_pass_ratio`] needs it), J.
    e_env: f64,
    /// Rule 1 ratio of the cell (before the margin).
    single: f64,
}

/// The azimuth cells between consecutive breakpoints. One sweep in azimuth
/// order gives, per cell, the hottest bin touching its union arc, `τ` and
/// `E` at its ends, whether `τ` or `E` can have a stationary point inside
/// (a pass edge in a bin with angular acceleration), and a cheap upper bound
/// of each figure for the branch and bound.
struct Cells<'a> {
    tl: &'a Timeline<'a, Seg>,
    env: &'a Envelope,
    laser: &'a Laser,
    h: f64,
    delta: f64,
    cuts: Vec<f64>,
    /// `τ` and `E` at each cut, `[0, len]`.
    tau_pt: Vec<f64>,
    e_pt: Vec<f64>,
    /// Each cell's figures from the sweep.
    rows: Vec<CellRow>,
    per_j: PerJouleCache,
}

/// A cell as the sweep leaves it.
#[derive(Debug, Clone, Copy)]
struct CellRow {
    /// Highest power of the bins touching the cell's union arc, W.
    p: f64,
    /// Whether a pass edge crosses a bin with angular acceleration.
    curved: bool,
    /// Upper bounds of the cell's `tau_s`, `e.0`, `e_env` and `single`
    /// (the exact `tau_s`, `e_env` and `single` when it is not curved;
    /// `e.0` is then still capped per bin by the exact evaluation).
    tau_ub: f64,
    e_ub: f64,
    env_ub: f64,
    single_ub: f64,
    /// A lower bound of the cell's smallest pass duration (exact when the
    /// cell is not curved), s.
    tau_lb: f64,
}

/// The maxima over cells: Rule 1 (ratio, azimuth), pass energy
/// (J, azimuth), envelope integral over a pass (J), pass duration (s).
struct CellBest {
    single: (f64, f64),
    e_max: (f64, f64),
    e_env_max: f64,
    tau_max: f64,
}

impl<'a> Cells<'a> {
    fn new(tl: &'a Timeline<'a, Seg>, env: &'a Envelope, h: f64, laser: &'a Laser) -> Self {
        let segs = tl.bins();
        let n = segs.len();
        let delta = 1.0 / laser.pulse_rate_hz;
        let frame_s = tl.period_s();
        // φ-cells: azimuths where a pass edge, or a pass edge shifted by Δ in
        // time, meets a bin edge.
        let mut cuts: Vec<f64> = Vec::with_capacity(4 * n + 1);
        cuts.extend(segs.iter().map(|s| wrap360(s.start_deg + h)));
        cuts.extend(segs.iter().map(|s| wrap360(s.start_deg - h)));
        let mut hint = 0;
        cuts.extend((0..n).map(|i| {
            let t = tl.bin_start_time_s(i) + delta;
            wrap360(tl.azimuth_at_unwrapped_from_deg(t, &mut hint) + h)
        }));
        let mut hint = 0;
        cuts.extend((0..n).map(|i| {
            let t = tl.bin_start_time_s(i) + frame_s - delta;
            wrap360(tl.azimuth_at_unwrapped_from_deg(t, &mut hint) - h)
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
        };
        cells.sweep();
        cells
    }

    fn len(&self) -> usize {
        self.cuts.len()
    }

    /// Cut `c` for `c` in `[0, len]`, the last one a turn after the first.
    fn cut(&self, c: usize) -> f64 {
        cut_of(&self.cuts, c)
    }

    /// The sweep (all positions nondecrease with the cell, so every lookup
    /// is a forward step: linear time overall). A cell whose pass edges both
    /// cross bins of constant spin has its exact figures here (at its ends).
    /// Otherwise (curved), over `φ ∈ [u, v]`:
    /// `dτ/dφ = 1/ω(φ + h) − 1/ω(φ − h)` and
    /// `dE/dφ = P̄_r/ω(φ + h) − P̄_l/ω(φ − h)`, with the envelope pieces
    /// `P̄_r`, `P̄_l` fixed over the cell and `ω` monotone along each edge's
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
        // Bins with angular acceleration (`ω²` not constant); with none, no
        // cell is curved and the edges' bins need not be looked up.
        let bin_curved: Vec<bool> = segs.iter().map(|s| spin_sq_line(s).1 != 0.0).collect();
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
                    let (a, b) = spin_sq_line(seg);
                    let x = (theta - (360.0 * k + seg.start_deg)).clamp(0.0, seg.width_deg);
                    (a + b * x).max(0.0).sqrt()
                };
                let (wr_u, wr_v) = (spin(seg_r, right.0, u + h), spin(seg_r, right.0, v + h));
                let (wl_u, wl_v) = (spin(seg_l, left.0, u - h), spin(seg_l, left.0, v - h));
                let (wr_min, wr_max) = (wr_u.min(wr_v), wr_u.max(wr_v));
                let (wl_min, wl_max) = (wl_u.min(wl_v), wl_u.max(wl_v));
                let ((pl_u, pr_u), (pl_v, pr_v)) = (edge_p[c], edge_p[c + 1]);
                let (pr_min, pr_max) = (pr_u.min(pr_v), pr_u.max(pr_v));
                let (pl_min, pl_max) = (pl_u.min(pl_v), pl_u.max(pl_v));
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
            let per_pass = per_pass_of.get(tau, |t| max_pulses_in(t, f_p));
            let passes = passes_of.get(tau, |t| passes_in_window(t2, t, frame_s));
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
                        let k = max_pulses_in(tau_s, f_p);
                        let q = passes_in_window(t2, tau_s, frame_s);
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
    fn time_at(&self, theta: f64) -> f64 {
        self.tl.time_at_unwrapped_s(theta)
    }

    /// `ω²(φ + off)` over the cell containing `mid + off`, as `a + b·φ`.
    fn spin_sq_at(&self, mid: f64, off: f64) -> (f64, f64) {
        let (k, j, _) = self.tl.locate_unwrapped(mid + off);
        let seg = &self.tl.bins()[j];
        let (a, b) = spin_sq_line(seg);
        let anchor = 360.0 * k + seg.start_deg;
        (a + b * (off - anchor), b)
    }

    /// The exact figures of cell `c`: `τ` and `E` at the cell ends and at
    /// their stationary points inside (see the module docs), the pulse count
    /// from the cell's largest `τ`, and Rule 1.
    fn exact(&self, c: usize) -> CellExact {
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
        let per_pass = max_pulses_in(cell_tau, self.laser.pulse_rate_hz);
        let passes = passes_in_window(
            ael::T2_S.min(ael::TIME_BASE_S),
            cell_tau,
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
            e: (cell_e.0.min(cap), wrap360(cell_e.1)),
            e_env: cell_e.0,
            // Off the curved cells the sweep's Rule 1 figure is exact.
            single: if self.rows[c].curved {
                p * self.delta * self.per_j.peek(self.laser, per_pass, passes)
            } else {
                self.rows[c].single_ub
            },
        }
    }

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
    fn pulse_capped_j(&self, u: f64, v: f64, per_pass: f64) -> Option<f64> {
        let tl = self.tl;
        let segs = tl.bins();
        let n = segs.len() as i64;
        let (lo_deg, hi_deg) = (u - self.h - TOUCH_SNAP_DEG, v + self.h + TOUCH_SNAP_DEG);
        let mut hint = 0;
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
            *slot = (seg.power_w, max_pulses_in(t_b, f_p));
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
                max_pulses_in(tau_a.max(tau_b), f_p).min(per_pass)
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
    fn e_refined(&self, c: usize, x: &CellExact) -> f64 {
        let per_pass = max_pulses_in(x.tau_s, self.laser.pulse_rate_hz);
        let (u, v) = (self.cut(c), self.cut(c + 1));
        self.pulse_capped_split(c, u, v, per_pass)
            .map_or(x.e.0, |e| e.min(x.e.0))
    }

    /// Rule 2 over the windows that hold one whole pass (the boundary of
    /// the walks' reach, see [`Walks::search`]): an upper bound of
    /// `min(E(φ), E⁺)/AEL(τ(φ))` over the azimuths `φ` of cell `c`, with the
    /// `τ` where it is taken. Off the curved cells `E` and `τ` are affine in
    /// `φ` (both pass edges in bins of constant spin, the envelope pieces
    /// fixed), so on each row of Table 3 `E/AEL(τ) = (e₀ + e₁x)/(c·(τ₀ +
    /// t₁x)^p)` has a derivative whose sign is that of
    /// `e₁τ − p·t₁·E`, affine in `x` with slope `(1 − p)·e₁·t₁`: positive
    /// throughout when `e₁·t₁ < 0` (or its mirror), and crossing zero at
    /// most once upwards otherwise, so the ratio is largest at the cell ends
    /// or where `τ` meets a row edge (with the smaller row there); capped at
    /// `E⁺`, also where `E` reaches `E⁺` (on each side of it the capped
    /// ratio is one of the two forms above). On a curved cell: the largest
    /// `E` (capped) over the smallest AEL between its smallest and largest
    /// `τ` (all exact, see [`Self::exact`]; the AEL may fall at a row
    /// edge).
    fn full_pass(&self, c: usize, e_cap: f64) -> (f64, f64) {
        let laser = self.laser;
        if self.rows[c].curved {
            let x = self.exact(c);
            let r = x.e_env.min(e_cap) / laser.min_ael_over(x.tau_min_s, x.tau_s);
            return (r, x.tau_min_s);
        }
        let (tu, tv) = (self.tau_pt[c], self.tau_pt[c + 1]);
        let (eu, ev) = (self.e_pt[c], self.e_pt[c + 1]);
        let mut best = Best(0.0, 0.0);
        let mut take = |e: f64, t: f64| best.take((e.min(e_cap) / laser.ael_j(t), t));
        take(eu, tu);
        take(ev, tv);
        // Along the cell `E` is affine in `τ`. Interpolations are widened by
        // the error of the values at the cuts (`PRUNE_SLACK` of a turn's
        // time and envelope energy) amplified by the division.
        let t_err = 2.0 * PRUNE_SLACK * self.tl.period_s();
        let e_err = 2.0 * PRUNE_SLACK * self.env.total_j();
        let (lo, hi) = (tu.min(tv), tu.max(tv));
        let (de, dt) = (ev - eu, tv - tu);
        for t in laser.edges_within(lo, hi) {
            let w = ((t - tu) / dt).clamp(0.0, 1.0);
            let spread = (t_err / (hi - lo)).min(1.0);
            let e = eu + de * w + de.abs() * spread + e_err;
            // (Affine: never above the larger end.)
            take(e.min(eu.max(ev)), t);
        }
        // Where `E` reaches `E⁺` (the cap's kink): `E⁺` over the `τ` there.
        if eu.min(ev) < e_cap && e_cap < eu.max(ev) {
            let w = ((e_cap - eu) / de).clamp(0.0, 1.0);
            let spread = (e_err / de.abs()).min(1.0);
            let t = tu + dt * w - dt.abs() * spread - t_err;
            // (Affine: never below the smaller end.)
            take(e_cap, t.max(lo));
        }
        (best.0, best.1)
    }

    /// The largest [`Self::full_pass`] over the cells and `best`. Pruned: a cell is
    /// evaluated only if `min(E_ub, E⁺)/τ_lb · K` ([`Laser::mean_power_factor`]
    /// up to the longest pass), then `min(E_ub, E⁺)` over the smallest AEL
    /// between `τ_lb` and `τ_ub`, both upper bounds of its value, can reach
    /// the best so far.
    fn full_pass_max(&self, search: Search, e_cap: f64, tau_max: f64, mut best: Best) -> Best {
        match search {
            Search::Exhaustive => {
                for c in 0..self.len() {
                    best.take(self.full_pass(c, e_cap));
                }
            }
            Search::Pruned => {
                let laser = self.laser;
                let k = laser.mean_power_factor(tau_max) * (1.0 + PRUNE_SLACK);
                for (c, row) in self.rows.iter().enumerate() {
                    // (A NaN bound never prunes; a bound `τ_lb ≤ 0` only
                    // through the AEL, which clamps it.)
                    let e = row.env_ub.min(e_cap);
                    if row.tau_lb > 0.0 && e / row.tau_lb * k < best.0 {
                        continue;
                    }
                    let ael = laser.min_ael_over(row.tau_lb, row.tau_ub);
                    if e / ael * (1.0 + PRUNE_SLACK) < best.0 {
                        continue;
                    }
                    best.take(self.full_pass(c, e_cap));
                }
            }
        }
        best
    }

    /// The three maxima, each with the first cell (in azimuth order)
    /// attaining it.
    fn search(&self, search: Search) -> CellBest {
        let mid_of = |c: usize| wrap360(0.5 * (self.cut(c) + self.cut(c + 1)));
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

/// Unwrapped index (`turn·n + bin`) of the bin holding unwrapped `theta`.
fn unwrapped_bin(tl: &Timeline<'_, Seg>, theta: f64, hint: &mut usize) -> i64 {
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
    let mut order: Vec<usize> = (0..len).filter(|&c| beats(ub(c), c, best)).collect();
    order.sort_unstable_by(|&a, &b| ub(b).total_cmp(&ub(a)).then(a.cmp(&b)));
    for c in order {
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

/// A nondecreasing step function (a count of `τ`) memoized over the
/// interval of arguments seen with its last value: an argument inside it
/// has that value (monotonicity), so it is returned without a call. The
/// same value as a fresh call.
#[derive(Default)]
struct StepMemo {
    /// `[lo, hi]` and the value there (none yet if `lo > hi`).
    range: Option<(f64, f64, f64)>,
}

impl StepMemo {
    fn get(&mut self, x: f64, f: impl Fn(f64) -> f64) -> f64 {
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

/// [`Laser::single_pulse_ratio_per_j`] for the few distinct (pulse count,
/// pass count) pairs a profile has (a memo: the same value as a fresh call).
#[derive(Default)]
struct PerJouleCache {
    last: Option<((f64, f64), f64)>,
    map: std::collections::HashMap<(u64, u64), f64>,
}

impl PerJouleCache {
    fn get(&mut self, laser: &Laser, per_pass: f64, passes: f64) -> f64 {
        if let Some((key, v)) = self.last {
            if key == (per_pass, passes) {
                return v;
            }
        }
        let v = *self
            .map
            .entry((per_pass.to_bits(), passes.to_bits()))
            .or_insert_with(|| laser.single_pulse_ratio_per_j(per_pass, passes));
        self.last = Some(((per_pass, passes), v));
        v
    }

    /// As [`Self::get`] without memoizing a new pair.
    fn peek(&self, laser: &Laser, per_pass: f64, passes: f64) -> f64 {
        self.map
            .get(&(per_pass.to_bits(), passes.to_bits()))
            .copied()
            .unwrap_or_else(|| laser.single_pulse_ratio_per_j(per_pass, passes))
    }
}

/// The best (ratio, window duration) seen: larger ratio, ties to the
/// shorter window, so the result does not depend on evaluation order.
#[derive(Debug, Clone, Copy)]
struct Best(f64, f64);

impl Best {
    fn take(&mut self, (r, t): (f64, f64)) {
        if r > self.0 || (r == self.0 && t < self.1) {
            *self = Self(r, t);
        }
    }
}

/// Relative slack (of a turn's time) by which a walk's reach is widened, so
/// the float inversions of the head's motion stay above the exact reach.
const REACH_SLACK: f64 = 1e-9;

/// Rule 2 for windows shorter than one revolution (see [`Walks::search`]).
struct Walks<'a> {
    env: &'a Envelope,
    tl: &'a Timeline<'a, Seg>,
    laser: &'a Laser,
    /// The pass angle `2h`, deg.
    two_h_deg: f64,
    /// The largest pass energy `E⁺`, J.
    e_pass: f64,
    /// Longest window a walk follows: a pass plus one pulse spacing, s.
    l_max: f64,
}

impl Walks<'_> {
    /// The supremum of `min(E⁺, ∫ P̄ over J)/AEL(T)` over the windows that
    /// fit in one pass, after `best` (the whole-pass windows,
    /// [`Cells::full_pass`]).
    ///
    /// A window `W` of duration `T` meets the pass `I_φ = [a, a + τ(φ)]` of
    /// aperture `φ` in pulses whose envelope cells lie in
    /// `J = (W ⊕ [0, Δ]) ∩ (I_φ ⊕ [0, Δ]) = [u, u + ℓ]`, `ℓ ≤ T + Δ`; the
    /// head is at `θ(u) ≥ φ − h` at `u`, so the pass ends by
    /// `t(θ(u) + 2h)` and `ℓ ≤ R(u) = t(θ(u) + 2h) + Δ − u`. The ratio is at
    /// most `g(u, ℓ) = min(E⁺, ∫_J P̄)/AEL(ℓ − Δ)` over `0 < ℓ ≤ R(u)`. For a
    /// fixed `ℓ`, `∫_J P̄` is piecewise linear in `u` and its maxima over
    /// each interval of feasible `u` lie where `u` is an up-step of `P̄` or
    /// `u + ℓ` a down-step (the walks: forward from up-steps up to `R(u)`,
    /// backward from down-steps `b` up to `b − t(θ(b − Δ) − 2h)`, the same
    /// condition), or at the interval's ends, where `ℓ = R(u)`: `J` is then
    /// the whole pass of `θ(u) + h` (the `best` given).
    ///
    /// Pruned: a walk's windows hold at most `min(E⁺, p·L)` with `p` the
    /// highest `P̄` it can reach, so its ratio is at most
    /// `G(p) = sup_T min(E⁺, p·(T + Δ))/AEL(T)` (over `T` up to `l_max`),
    /// nondecreasing in `p`; walks are followed in decreasing `p` until
    /// `G(p)` falls below the best.
    fn search(&self, search: Search, mut best: Best) -> Best {
        let laser = self.laser;
        let delta = 1.0 / laser.pulse_rate_hz;
        let t_walk = self.l_max - delta;
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
                for k in order {
                    let w = walks[k];
                    if g.0 != w.p_span {
                        let (r, _) = laser.linear_capped_max(
                            0.0,
                            t_walk,
                            w.p_span * delta,
                            w.p_span,
                            self.e_pass,
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
        let b0 = env.bp(w.start);
        let (mut e, mut l, mut idx) = (0.0f64, 0.0f64, w.start);
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
                best.take(laser.linear_capped_max(
                    l0 - delta,
                    seg_end - delta,
                    e0,
                    piece_p,
                    e_pass,
                ));
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
                best.take(laser.linear_capped_max(t_c, t_reach.max(t_c), e_pass, 0.0, e_pass));
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
        best.take(laser.linear_capped_max(l0 - delta, t_reach, e0, w.p_span, e_pass));
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

#[cfg(test)]
mod tests {
    //! The helpers the search is made fast with compute the same values as
    //! the plain operations they replace, bit for bit.
    use super::*;
    use proptest::prelude::*;

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn sorted(mut v: Vec<f64>) -> Vec<f64> {
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    }

    /// A run increasing but for one wrap: `xs` (sorted) rotated by `r`.
    fn wrapped_run(mut xs: Vec<f64>, r: usize) -> Vec<f64> {
        xs.sort_by(f64::total_cmp);
        let r = if xs.is_empty() { 0 } else { r % xs.len() };
        xs.rotate_left(r);
        xs
    }

    proptest! {
        #[test]
        fn sort_runs_is_sort_and_dedup(
            runs in proptest::collection::vec(
                (proptest::collection::vec(prop_oneof![
                    0.0f64..360.0,
                    Just(0.0), Just(-0.0), Just(90.0), Just(359.999_999_999),
                ], 0..40), 0usize..40),
                1..5,
            ),
            extra in proptest::option::of((0usize..4, 0usize..40, prop_oneof![
                Just(f64::NAN), Just(-1.0), Just(1e300), Just(5.0),
            ])),
        ) {
            let mut v = Vec::new();
            let mut bounds = vec![0];
            for (k, (xs, r)) in runs.into_iter().enumerate() {
                let mut run = wrapped_run(xs, r);
                // Sometimes a second descent, or a NaN: the fallback.
                if let Some((j, at, x)) = extra {
                    if j == k && !run.is_empty() {
                        let at = at % run.len();
                        run[at] = x;
                    }
                }
                v.extend(run);
                bounds.push(v.len());
            }
            let expected = sorted(v.clone());
            prop_assert_eq!(bits(&sort_runs(v, &bounds)), bits(&expected));
        }

        #[test]
        fn wrap360_is_rem_euclid(a in prop_oneof![
            -1e4f64..1e4, -720.0f64..720.0, -1e-12f64..1e-12,
            Just(-360.0), Just(-0.0), Just(0.0), Just(360.0), Just(720.0),
            Just(-1e-300), Just(359.999_999_999_999_94), Just(f64::NAN), Just(f64::INFINITY),
        ]) {
            let w = a.rem_euclid(360.0);
            let expected = if w >= 360.0 { 0.0 } else { w };
            prop_assert_eq!(wrap360(a).to_bits(), expected.to_bits());
        }

        #[test]
        fn floor_is_floor(x in prop_oneof![
            -1e20f64..1e20, 0.0f64..1e3, Just(0.0), Just(-0.0), Just(4_503_599_627_370_495.5),
            Just(4_503_599_627_370_496.0), Just(f64::NAN), Just(f64::INFINITY),
            Just(f64::MIN_POSITIVE), Just(0.999_999_999_999_999_9),
        ]) {
            prop_assert_eq!(floor(x).to_bits(), x.floor().to_bits());
        }

        /// The queue (with its compaction) is a `VecDeque` used at both
        /// ends, pushed at the back: the same front and back after every
        /// operation, over runs long enough to compact many times.
        #[test]
        fn queue_is_a_deque(ops in proptest::collection::vec(0u8..4, 0..40_000)) {
            let mut q: Queue<u32> = Queue::default();
            let mut d = std::collections::VecDeque::new();
            for (k, op) in ops.into_iter().enumerate() {
                match op {
                    0 => { q.pop_front(); d.pop_front(); }
                    1 => { q.pop_back(); d.pop_back(); }
                    _ => { q.push_back(k as u32); d.push_back(k as u32); }
                }
                prop_assert_eq!(q.front(), d.front());
                prop_assert_eq!(q.back(), d.back());
                prop_assert!(q.items.len() - q.head == d.len());
                // After a push, the popped front is at most half the vector.
                prop_assert!(op < 2 || q.head < QUEUE_COMPACT_MIN || 2 * q.head < q.items.len());
            }
        }

        #[test]
        fn split_index_is_euclidean(idx in -10_000i64..10_000, m in 1i64..500) {
            let (k, j) = split_index(idx, m);
            prop_assert_eq!((k, j as i64), (idx.div_euclid(m), idx.rem_euclid(m)));
            prop_assert_eq!(wrap_index(idx, m) as i64, idx.rem_euclid(m));
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

    /// A sliding window over a long stream (push one, pop one) keeps at
    /// most `2·QUEUE_COMPACT_MIN` items: it compacts (it kept every item
    /// before, 565–612 MB at 10⁶ bins against 490 MB).
    #[test]
    fn queue_compacts_a_sliding_window() {
        let mut q: Queue<u64> = Queue::default();
        for k in 0..100_000u64 {
            q.push_back(k);
            if k >= 10 {
                q.pop_front();
            }
            let oldest = if k >= 10 { k - 9 } else { 0 };
            assert_eq!(q.front(), Some(&oldest));
        }
        assert!(q.items.len() <= 2 * QUEUE_COMPACT_MIN, "{}", q.items.len());
    }

    /// A bin of `width` degrees from `start` at `power`, spinning from
    /// `w0` to `w1` rad/s.
    fn seg(start: f64, width: f64, power: f64, w0: f64, w1: f64) -> Seg {
        Seg {
            start_deg: start,
            width_deg: width,
            power_w: power,
            spin_start_rad_s: w0,
            spin_end_rad_s: w1,
        }
    }

    fn fields(s: &Seg) -> [f64; 5] {
        [
            s.start_deg,
            s.width_deg,
            s.power_w,
            s.spin_start_rad_s,
            s.spin_end_rad_s,
        ]
    }

    /// Runs of one power and one constant spin merge (widths summed, the
    /// first bin's start kept); a change of power, an acceleration in
    /// either bin or a change of spin ends a run. Expected lists by hand.
    #[test]
    fn coalesce_merges_runs_of_one_power_and_constant_spin() {
        let segs = [
            seg(0.0, 90.0, 1.0, 10.0, 10.0),
            seg(90.0, 45.0, 1.0, 10.0, 10.0),
            seg(135.0, 45.0, 1.0, 10.0, 10.0), // three of a run: 0..180
            seg(180.0, 45.0, 2.0, 10.0, 10.0), // power changes
            seg(225.0, 45.0, 2.0, 10.0, 10.0), // run: 180..270
            seg(270.0, 30.0, 2.0, 10.0, 12.0), // accelerates
            seg(300.0, 30.0, 2.0, 12.0, 12.0), // follows an accelerating bin
            seg(330.0, 30.0, 2.0, 11.0, 11.0), // another spin
        ];
        let expected = [
            seg(0.0, 180.0, 1.0, 10.0, 10.0),
            seg(180.0, 90.0, 2.0, 10.0, 10.0),
            segs[5],
            segs[6],
            segs[7],
        ];
        let out = coalesce(&segs);
        assert!(matches!(out, std::borrow::Cow::Owned(_)));
        assert_eq!(out.len(), expected.len());
        for (got, want) in out.iter().zip(&expected) {
            assert_eq!(fields(got), fields(want));
        }
        // Nothing to merge (each pair differs in one respect only): the
        // same slice, borrowed.
        let apart = [
            seg(0.0, 90.0, 1.0, 10.0, 10.0),
            seg(90.0, 90.0, 2.0, 10.0, 10.0),  // power
            seg(180.0, 90.0, 2.0, 10.0, 11.0), // accelerates
            seg(270.0, 90.0, 2.0, 11.0, 11.0), // after an acceleration
        ];
        let out = coalesce(&apart);
        assert!(matches!(out, std::borrow::Cow::Borrowed(s) if std::ptr::eq(s, &apart[..])));
        // The first and last bins alike: 0° stays an edge.
        let ring = [
            seg(0.0, 180.0, 1.0, 10.0, 10.0),
            seg(180.0, 90.0, 2.0, 10.0, 10.0),
            seg(270.0, 90.0, 1.0, 10.0, 10.0),
        ];
        assert!(matches!(coalesce(&ring), std::borrow::Cow::Borrowed(_)));
        // Same power and spin but one of two accelerating: no merge.
        assert!(!same_run(&apart[2], &apart[3]));
        assert!(!same_run(
            &seg(0.0, 1.0, 1.0, 11.0, 11.0),
            &seg(1.0, 1.0, 1.0, 11.0, 12.0)
        ));
        assert!(!same_run(
            &seg(0.0, 1.0, 1.0, 11.0, 11.0),
            &seg(1.0, 1.0, 1.0, 12.0, 12.0)
        ));
        assert!(same_run(
            &seg(0.0, 1.0, 1.0, 11.0, 11.0),
            &seg(1.0, 1.0, 1.0, 11.0, 11.0)
        ));
    }

    /// The cells of `segs` (bins used as they are, not coalesced) for half
    /// pass angle `h`, a laser of `f_p` Hz, handed to `f`.
    fn with_cells<R>(segs: &[Seg], h: f64, f_p: f64, f: impl FnOnce(&Cells<'_>) -> R) -> R {
        let laser = Laser {
            band: Band::RetinalNir,
            c4: 1.0,
            pulse_duration_s: 5e-9,
            pulse_rate_hz: f_p,
        };
        let tl = Timeline::from_bins(segs);
        let env = Envelope::new(&tl, 1.0 / f_p);
        let cells = Cells::new(&tl, &env, h, &laser);
        f(&cells)
    }

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
}
