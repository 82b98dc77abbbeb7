//! The laser's limit maths: the AEL of Table 3 at a duration (the smaller
//! row at a row edge), Rule 1 (C5 and the `T_i` groups), the multi-pass
//! rules A (envelope) and C (pass count) up to the time base, and the
//! [`Rule`]s a figure is reported under (`specs/eye_safety.md`, "Rule 1",
//! "Rule 2").

use super::count::{max_pulses_in, passes_in_window};
use crate::eye_safety::ael::{self, Band, Row};
pub use crate::eye_safety::rule::Rule;

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

/// The AEL infima ([`Laser::ael_inf_j`]) at both ends of the last segment
/// [`Laser::linear_capped_max_memo`] evaluated, for one `one_pass_s`: the
/// consecutive pieces of a window walk share an end, and the pruning bounds
/// of the walks share both, so these are looked up, not computed again
/// (the same values).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct AelEnds {
    one_pass_bits: u64,
    ends: [Option<(u64, f64)>; 2],
}

impl AelEnds {
    /// The kept AEL infimum of the longer window length (the `t1` of the
    /// last [`Laser::linear_capped_max_memo`] call), if any.
    pub(super) fn at_longest(&self) -> Option<f64> {
        self.ends[1].map(|(_, ael_j)| ael_j)
    }

    /// `laser.ael_inf_j(t_s, one_pass_s)`, looked up if kept.
    fn get(&self, laser: &Laser, t_s: f64, one_pass_s: f64) -> f64 {
        if self.one_pass_bits == one_pass_s.to_bits() {
            for (t_bits, ael_j) in self.ends.into_iter().flatten() {
                if t_bits == t_s.to_bits() {
                    return ael_j;
                }
            }
        }
        laser.ael_inf_j(t_s, one_pass_s)
    }
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
    pub(super) fn edges_within(&self, lo: f64, hi: f64) -> impl Iterator<Item = f64> {
        let rows = self.rows();
        let p = self.pulse_duration_s;
        rows.into_iter()
            .flat_map(|r| [r.t_lo_s, r.t_hi_s])
            .chain(std::iter::once(p))
            .filter(move |&t| t > lo && t < hi)
    }

    /// The smallest AEL over every exposure duration in `[lo_s, hi_s]`
    /// (`hi_s` below `lo_s` is `lo_s`), durations clamped as in
    /// [`Self::ael_j`]: the model's one AEL infimum, [`ael::ael_inf_j`]
    /// (Table 3 is not monotone in the duration: it steps down at 5 µs and
    /// 10 s in 700–1050 nm, at 1 ms in 1400–1500 nm and at 10 s in
    /// 1500–1800 nm). Every rule that bounds the pulses a window can hold
    /// compares them with this over every window length that holds them
    /// (`specs/eye_safety.md`, "The AEL infimum"); the firmware checker's
    /// limits and the optimizer use the same function.
    #[must_use]
    pub fn ael_inf_j(&self, lo_s: f64, hi_s: f64) -> f64 {
        let clamp = |t: f64| {
            t.max(self.pulse_duration_s)
                .max(self.band.min_duration_s())
                .min(ael::T_MAX_TABLE_S)
        };
        ael::ael_inf_j(self.band, self.c4, clamp(lo_s), clamp(hi_s))
    }

    /// The longest window that can still meet only one pass, s (capped at
    /// the time base): windows from `T_f − max(τ_max, Δ)` on can meet two
    /// and are bounded by the multi-pass rules ([`Self::multi_pass_ratio`],
    /// which starts there and takes the AEL at every window's own length),
    /// so a window holding the pulses of one pass and no more is at most
    /// this long, or is covered there. The within-pass rules take the AEL
    /// infimum up to it.
    #[must_use]
    pub(crate) fn one_pass_window_max_s(&self, frame_s: f64, tau_max_s: f64) -> f64 {
        let delta = 1.0 / self.pulse_rate_hz;
        (frame_s - tau_max_s.max(delta)).clamp(0.0, ael::TIME_BASE_S)
    }

    /// `sup τ/AEL_inf(τ)` over `0 < τ ≤ tau_hi_s`, `AEL_inf(τ)` the
    /// smallest AEL over `[τ, one_pass_s]` ([`Self::ael_inf_j`]): on every
    /// row of Table 3 the AEL is `c·τ^p` with `0 ≤ p ≤ 1`, so `τ/AEL(τ)` is
    /// nondecreasing within a row (and below the clamp at the pulse
    /// duration, where the AEL is constant), and `τ/m` is increasing where
    /// the infimum is a later edge's value `m` (constant between edges); so
    /// the supremum is at `tau_hi_s` or at a row edge below it (where the
    /// table takes the smaller row, below both sides' limits). Bounds
    /// `E/AEL_inf(τ) ≤ (E/τ)·K` for every `τ ≤ tau_hi_s`.
    pub(super) fn mean_power_factor(&self, tau_hi_s: f64, one_pass_s: f64) -> f64 {
        let mut k = tau_hi_s / self.ael_inf_j(tau_hi_s, one_pass_s);
        for t in self.edges_within(0.0, tau_hi_s) {
            k = k.max(t / self.ael_inf_j(t, one_pass_s));
        }
        k
    }

    /// `S(t) = sup_{T ≤ t} (T + Δ)/AEL(T)`, s/J (`Δ = 1/f_p`): what a
    /// received power of one watt, each pulse's energy spread over the
    /// pulse spacing after it, puts into a window of length up to `t`, per
    /// joule of its AEL. On a row of Table 3 (`c·T^p`, `0 ≤ p ≤ 1`)
    /// `(T + Δ)/T^p` has no interior maximum, so `t`, the row edges below
    /// it and the pulse duration (below which the AEL is constant) are
    /// every candidate (the AEL at an edge is the smaller row's). The head's
    /// instantaneous-power candidate (`head::bound::energy_ratios`) takes
    /// this supremum.
    #[must_use]
    pub fn instant_window_factor(&self, t_s: f64) -> f64 {
        let delta = 1.0 / self.pulse_rate_hz;
        let mut s = (t_s + delta) / self.ael_j(t_s);
        for row in self.rows() {
            for e in [row.t_lo_s, row.t_hi_s, self.pulse_duration_s] {
                if e > 0.0 && e < t_s {
                    s = s.max((e + delta) / self.ael_j(e));
                }
            }
        }
        s
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

    /// C5 for `n_pulses` effective pulses within `T_max = min(T2, time
    /// base)` ([`ael::c5`]); 1 for pulses longer than `T_i` (2014
    /// small-source rule). Nonincreasing in `n_pulses`.
    #[must_use]
    pub fn c5(&self, n_pulses: f64) -> f64 {
        if self.pulse_duration_s > self.band.t_i_s() {
            1.0
        } else {
            ael::c5(self.band, n_pulses, ael::T2_S.min(ael::TIME_BASE_S))
        }
    }

    /// Rule 1 ratio for pulses (or groups) of at most `pulse_energy_j` each
    /// (one pulse; the group is applied here), with at most `per_pass`
    /// pulses in any pass and `passes_t2` passes meeting any T2 window:
    /// `pulse_energy_j ×` [`Self::single_pulse_ratio_per_j`].
    #[must_use]
    pub(crate) fn single_pulse_ratio(
        &self,
        pulse_energy_j: f64,
        per_pass: f64,
        passes_t2: f64,
    ) -> f64 {
        pulse_energy_j * self.single_pulse_ratio_per_j(per_pass, passes_t2)
    }

    /// Rule 1 ratio per joule of pulse energy. Nondecreasing in both counts:
    /// C5 falls as the pulse count grows, and the `T_i` group grows with the
    /// pulses per pass until it reaches its cap, after which the number of
    /// groups grows.
    #[must_use]
    pub fn single_pulse_ratio_per_j(&self, per_pass: f64, passes_t2: f64) -> f64 {
        let g = self.group(per_pass);
        let c5_of = |n: f64| self.c5(n);
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

    /// The largest ratio `min(cap_j, e0_j + slope_w·(T − t0))/AEL_inf(T)`
    /// over `T ∈ [t0, t1]`, the energy being linear until it reaches
    /// `cap_j` and flat after, `AEL_inf(T)` the smallest AEL over
    /// `[T, one_pass_s]` ([`Self::ael_inf_j`]: the pulses a window of `T`
    /// holds are held by every longer window up to `one_pass_s` too; pass
    /// `one_pass_s ≤ t0` for the AEL at `T` itself). Evaluated at the
    /// segment ends, at the cap, at `one_pass_s` and at every AEL row edge
    /// in between: between two of these the energy is `α + βT` (`β ≥ 0`)
    /// and `AEL_inf(T) = min(c·T^p, m)` with `m` constant (the later edges'
    /// and `one_pass_s`'s values), so the ratio is the larger of
    /// `(α + βT)/(c·T^p)` (no interior maximum, `0 ≤ p ≤ 1`) and
    /// `(α + βT)/m` (largest at the right end, where `AEL_inf` is at most
    /// `m`).
    pub(super) fn linear_capped_max(
        &self,
        t0: f64,
        t1: f64,
        e0_j: f64,
        slope_w: f64,
        cap_j: f64,
        one_pass_s: f64,
    ) -> (f64, f64) {
        self.linear_capped_max_memo(
            t0,
            t1,
            e0_j,
            slope_w,
            cap_j,
            one_pass_s,
            &mut AelEnds::default(),
        )
    }

    /// [`Self::linear_capped_max`], the AEL infima at `t0` and `t1` looked
    /// up in `ends` when an earlier call computed them (and left there).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn linear_capped_max_memo(
        &self,
        t0: f64,
        t1: f64,
        e0_j: f64,
        slope_w: f64,
        cap_j: f64,
        one_pass_s: f64,
        ends: &mut AelEnds,
    ) -> (f64, f64) {
        if t1.is_nan() || t0.is_nan() || t1 < t0 {
            return (0.0, t0);
        }
        let energy = |t: f64| (e0_j + slope_w * (t - t0)).min(cap_j);
        let mut best = (0.0, t0);
        let mut consider_with = |t: f64, ael_j: f64| {
            let r = energy(t) / ael_j;
            if r > best.0 {
                best = (r, t);
            }
        };
        let ael_t0 = ends.get(self, t0, one_pass_s);
        let ael_t1 = ends.get(self, t1, one_pass_s);
        *ends = AelEnds {
            one_pass_bits: one_pass_s.to_bits(),
            ends: [Some((t0.to_bits(), ael_t0)), Some((t1.to_bits(), ael_t1))],
        };
        consider_with(t0, ael_t0);
        consider_with(t1, ael_t1);
        let mut consider = |t: f64| consider_with(t, self.ael_inf_j(t, one_pass_s));
        if slope_w > 0.0 && e0_j < cap_j {
            let t_cap = t0 + (cap_j - e0_j) / slope_w;
            if t_cap > t0 && t_cap < t1 {
                consider(t_cap);
            }
        }
        if one_pass_s > t0 && one_pass_s < t1 {
            consider(one_pass_s);
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
    pub(crate) fn multi_pass_ratio(
        &self,
        frame_s: f64,
        pass: PassFigures,
        p_hat_w: f64,
    ) -> (f64, f64) {
        let delta = 1.0 / self.pulse_rate_hz;
        let tb = ael::TIME_BASE_S;
        let t_start = (frame_s - pass.duration_s.max(delta)).max(0.0);
        debug_assert_eq!(
            t_start.min(tb),
            self.one_pass_window_max_s(frame_s, pass.duration_s)
        );
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

    /// `sup min(A, C)(T)/AEL(T)` over windows `T ∈ [t_start_s, T_b]` (the
    /// two multi-pass bounds of [`Self::multi_pass_ratio`], each valid for
    /// every window length, at the AEL of the window's own length), from
    /// any start: below `T_f − τ` bound A is `min(E, P̂·(T + Δ))` and bound C
    /// one pass, whose pieces' ends are among the candidates. Used by the
    /// head's bound for the windows long enough to reach two azimuth
    /// columns of channels. Returns (ratio, window duration); 0 when no
    /// window of the range is within the time base.
    #[must_use]
    pub(crate) fn windows_from_ratio(
        &self,
        frame_s: f64,
        pass: PassFigures,
        p_hat_w: f64,
        t_start_s: f64,
    ) -> (f64, f64) {
        let t_start = t_start_s.max(0.0);
        if pass.envelope_j <= 0.0 || pass.pulses_j <= 0.0 || t_start > ael::TIME_BASE_S {
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
    pub(crate) fn time_base_ratio(&self, frame_s: f64, pass: PassFigures, p_hat_w: f64) -> f64 {
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
    pub(crate) fn stationary_ratio(&self, power_w: f64) -> (f64, Rule) {
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
            // Every window length is evaluated: the AEL at its own.
            0.0,
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
    pub(crate) fn envelope_energy(
        &self,
        t_s: f64,
        frame_s: f64,
        delta_s: f64,
        p_hat_w: f64,
    ) -> f64 {
        let l = t_s + delta_s;
        let q = (l / frame_s).floor();
        let r = (l - q * frame_s).max(0.0);
        q * self.envelope_j + self.envelope_j.min(p_hat_w * r)
    }

    /// Bound C: at most [`passes_in_window`] passes meet a window of `t_s`,
    /// each with at most [`Self::pulses_j`].
    #[must_use]
    pub(crate) fn count_energy(&self, t_s: f64, frame_s: f64) -> f64 {
        passes_in_window(t_s, self.duration_s.max(0.0), frame_s) * self.pulses_j
    }
}

/// [`Laser::single_pulse_ratio_per_j`] for the few distinct (pulse count,
/// pass count) pairs a profile has (a memo: the same value as a fresh call).
#[derive(Default)]
pub(super) struct PerJouleCache {
    last: Option<((f64, f64), f64)>,
    map: std::collections::HashMap<(u64, u64), f64>,
}

impl PerJouleCache {
    pub(super) fn get(&mut self, laser: &Laser, per_pass: f64, passes: f64) -> f64 {
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
    pub(super) fn peek(&self, laser: &Laser, per_pass: f64, passes: f64) -> f64 {
        self.map
            .get(&(per_pass.to_bits(), passes.to_bits()))
            .copied()
            .unwrap_or_else(|| laser.single_pulse_ratio_per_j(per_pass, passes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kept AEL ends change nothing: a chain of segments sharing ends
    /// (as a walk's pieces), the same segment again (as the pruning bounds)
    /// and a change of `one_pass_s`, every band and row edge crossed, give
    /// the bits of the plain evaluation.
    #[test]
    fn kept_ael_ends_are_the_plain_evaluation() {
        for (band, c4) in [
            (Band::RetinalNir, 2.5),
            (Band::Ir1400, 1.0),
            (Band::Ir1500, 1.0),
        ] {
            let laser = Laser {
                band,
                c4,
                pulse_duration_s: 5e-9,
                pulse_rate_hz: 1e5,
            };
            let mut ends = AelEnds::default();
            let mut t = 1e-7;
            for k in 0..400 {
                let one_pass_s = if k % 50 < 25 { 0.2 } else { 40.0 };
                let t1 = t * (1.0 + 0.05 * (k % 7) as f64) + 1e-7;
                let (e0, slope, cap) = (1e-6 * (k % 5) as f64, 1e-3 * (k % 3) as f64, 2e-5);
                let plain = laser.linear_capped_max(t, t1, e0, slope, cap, one_pass_s);
                let kept =
                    laser.linear_capped_max_memo(t, t1, e0, slope, cap, one_pass_s, &mut ends);
                assert_eq!(plain.0.to_bits(), kept.0.to_bits(), "{band:?} {k}");
                assert_eq!(plain.1.to_bits(), kept.1.to_bits(), "{band:?} {k}");
                let again =
                    laser.linear_capped_max_memo(t, t1, e0, slope, cap, one_pass_s, &mut ends);
                assert_eq!(plain.0.to_bits(), again.0.to_bits());
                t = if t1 > 50.0 { 1e-7 } else { t1 };
            }
        }
    }

    /// Mutant 475:32 of the old `bound.rs` (11a69c7): `pass_count_max`'s
    /// candidates `k·T_f − τ` (where a window first meets `k + 1` passes)
    /// taken as `k·T_f + τ`. By hand, 1400–1500 nm, `T_f` = 10 ms, `τ` =
    /// 1 ms, 0.1 mJ a pass: on the row 1 ms–0.35 s (`4.4e-3·T^0.25`) the
    /// ratio `(k + 1)·E/AEL(k·T_f − τ)` grows with `k`, largest at the last
    /// step, `T = 0.349 s` with 36 passes: `3.6e-3/(4.4e-3·0.349^0.25)` =
    /// 1.06450. The row edge 0.35 s gives 1.0637 and the next row
    /// (`1e-2·T`, first step 0.359 s, 37 passes) 1.0306.
    #[test]
    fn pass_count_max_takes_the_step_k_frames_less_a_pass() {
        let laser = Laser {
            band: Band::Ir1400,
            c4: 1.0,
            pulse_duration_s: 1e-9,
            pulse_rate_hz: 1e5,
        };
        let pass = PassFigures {
            envelope_j: 1e-4,
            pulses_j: 1e-4,
            duration_s: 1e-3,
        };
        let (r, t) = laser.pass_count_max(0.01, pass, 0.009);
        let want = 36.0 * 1e-4 / (4.4e-3 * 0.349f64.powf(0.25));
        assert!((r - want).abs() <= 1e-12 * want, "{r} vs {want}");
        assert!((t - 0.349).abs() <= 1e-12, "{t}");
        assert!((r - 1.0645).abs() < 1e-4, "{r}");
    }
}
