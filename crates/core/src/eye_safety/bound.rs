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
//! **Rounding.** Every count that is a floor is taken as
//! `⌊x·(1 + 1e-9) + 1e-9⌋`, so a count that sits on an integer is taken
//! as the larger one and a perturbation of the inputs by 1e-12 cannot
//! lower it ([`COUNT_MARGIN`]).

use super::ael::{self, Band, Row};

/// Relative margin by which every floor-count is rounded up (see module docs).
pub const COUNT_MARGIN: f64 = 1e-9;

/// Relative margin every rule's ratio is raised by before the verdict, so
/// float rounding in the bound can never land it below the true supremum.
pub const RATIO_MARGIN: f64 = 1e-9;

/// Envelope pieces a window walk visits before it falls back to the
/// `P̂`-slope bound (sound, looser); bounds the work on very fine profiles.
pub const WALK_MAX_PIECES: usize = 96;

/// `⌊x⌋` rounded up when `x` is within [`COUNT_MARGIN`] of the next integer.
#[must_use]
pub fn floor_up(x: f64) -> f64 {
    (x * (1.0 + COUNT_MARGIN) + COUNT_MARGIN).floor()
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
    /// pulses in any pass and `passes_t2` passes meeting any T2 window.
    #[must_use]
    pub fn single_pulse_ratio(&self, pulse_energy_j: f64, per_pass: f64, passes_t2: f64) -> f64 {
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
        let single = pulse_energy_j / (c5_of(n_pulses) * self.ael_j(self.pulse_duration_s));
        if g > 1.0 {
            // Greedy grouping from the first pulse: ⌈K/g⌉ groups per pass.
            let n_groups = (per_pass / g).ceil() * passes_t2;
            let group = g * pulse_energy_j / (c5_of(n_groups) * self.ael_j(self.band.t_i_s()));
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

    /// Rule 2 over windows spanning several passes (`T ≥ T_f − Δ`) up to the
    /// time base, with at most `e_pass_j` per pass and `p_hat_w` the highest
    /// power: returns (ratio, window duration).
    #[must_use]
    pub fn multi_pass_ratio(&self, frame_s: f64, e_pass_j: f64, p_hat_w: f64) -> (f64, f64) {
        let delta = 1.0 / self.pulse_rate_hz;
        let tb = ael::TIME_BASE_S;
        let t_start = (frame_s - delta).max(0.0);
        if e_pass_j <= 0.0 || t_start >= tb {
            return (0.0, t_start);
        }
        let r_star = if p_hat_w > 0.0 {
            (e_pass_j / p_hat_w).min(frame_s)
        } else {
            frame_s
        };
        // E(T) with L = T + Δ = q·T_f + r.
        let energy = |t: f64| {
            let l = t + delta;
            let q = (l / frame_s).floor();
            let r = (l - q * frame_s).max(0.0);
            q * e_pass_j + e_pass_j.min(p_hat_w * r)
        };
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
            // Family points T = q·T_f + r_f − Δ, r_f ∈ {0, r*}: first and last q in the row.
            for r_f in [0.0, r_star] {
                let q_lo = ((lo + delta - r_f) / frame_s).ceil().max(1.0);
                let q_hi = ((hi + delta - r_f) / frame_s).floor();
                for q in [q_lo, q_lo + 1.0, q_hi - 1.0, q_hi] {
                    if q >= 1.0 && q <= q_hi && q >= q_lo {
                        consider(q * frame_s + r_f - delta);
                    }
                }
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
/// spin² at its start (rad²/s²) and its constant angular acceleration.
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

impl Seg {
    fn accel(&self) -> f64 {
        (self.spin_end_rad_s.powi(2) - self.spin_start_rad_s.powi(2))
            / (2.0 * self.width_deg.to_radians())
    }

    fn dwell_s(&self) -> f64 {
        2.0 * self.width_deg.to_radians() / (self.spin_start_rad_s + self.spin_end_rad_s)
    }

    /// Time to advance `x_deg` into the bin (exact, constant acceleration).
    fn time_into_s(&self, x_deg: f64) -> f64 {
        let x = x_deg.clamp(0.0, self.width_deg).to_radians();
        if x <= 0.0 {
            return 0.0;
        }
        let w_x = (self.spin_start_rad_s.powi(2) + 2.0 * self.accel() * x)
            .max(0.0)
            .sqrt();
        2.0 * x / (self.spin_start_rad_s + w_x)
    }

    /// Angle (deg) advanced `t_s` after entering the bin.
    fn angle_after_deg(&self, t_s: f64) -> f64 {
        let t = t_s.clamp(0.0, self.dwell_s());
        let x = self.spin_start_rad_s * t + 0.5 * self.accel() * t * t;
        x.to_degrees().clamp(0.0, self.width_deg)
    }

    /// ω² at `x_deg` into the bin as `a + b·x_deg`.
    fn spin_sq_line(&self) -> (f64, f64) {
        (
            self.spin_start_rad_s.powi(2),
            2.0 * self.accel() * std::f64::consts::PI / 180.0,
        )
    }
}

/// The exact timeline of one revolution, extended periodically.
struct Clock<'a> {
    segs: &'a [Seg],
    cum_s: Vec<f64>,
    frame_s: f64,
}

impl<'a> Clock<'a> {
    fn new(segs: &'a [Seg]) -> Self {
        let mut cum_s = Vec::with_capacity(segs.len() + 1);
        let mut t = 0.0;
        cum_s.push(0.0);
        for s in segs {
            t += s.dwell_s();
            cum_s.push(t);
        }
        Self {
            segs,
            cum_s,
            frame_s: t,
        }
    }

    /// Bin containing the wrapped azimuth `a` in `[0, 360)`.
    fn bin_of(&self, a: f64) -> usize {
        self.segs
            .partition_point(|s| s.start_deg <= a)
            .saturating_sub(1)
            .min(self.segs.len() - 1)
    }

    /// Splits an unwrapped azimuth into (turns, bin, offset into bin in deg).
    fn locate(&self, theta_deg: f64) -> (f64, usize, f64) {
        let k = (theta_deg / 360.0).floor();
        let a = theta_deg - 360.0 * k;
        let i = self.bin_of(a);
        (k, i, a - self.segs[i].start_deg)
    }

    /// Time at which the head reaches the unwrapped azimuth `theta_deg`.
    fn time_at(&self, theta_deg: f64) -> f64 {
        let (k, i, x) = self.locate(theta_deg);
        k * self.frame_s + self.cum_s[i] + self.segs[i].time_into_s(x)
    }

    /// Unwrapped azimuth at unwrapped time `t_s`.
    fn angle_at(&self, t_s: f64) -> f64 {
        let k = (t_s / self.frame_s).floor();
        let t = t_s - k * self.frame_s;
        let i = self
            .cum_s
            .partition_point(|&c| c <= t)
            .saturating_sub(1)
            .min(self.segs.len() - 1);
        360.0 * k + self.segs[i].start_deg + self.segs[i].angle_after_deg(t - self.cum_s[i])
    }
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
    fn new(clock: &Clock<'_>, delta_s: f64) -> Self {
        let n = clock.segs.len();
        let frame_s = clock.frame_s;
        let p_max = clock.segs.iter().map(|s| s.power_w).fold(0.0, f64::max);
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
        for i in 0..n {
            cand.push(clock.cum_s[i]);
            let s = clock.cum_s[i] + delta_s;
            cand.push(if s >= frame_s { s - frame_s } else { s });
        }
        cand.sort_by(f64::total_cmp);
        cand.dedup();
        if cand[0] > 0.0 {
            cand.insert(0, 0.0);
        }
        // Sliding-window maximum over the unrolled bins (3 periods: bin
        // index k covers [cum(k mod n) + (k div n − 1)·T_f, ...)).
        let start_of = |k: usize| clock.cum_s[k % n] + ((k / n) as f64 - 1.0) * frame_s;
        let end_of = |k: usize| clock.cum_s[k % n + 1] + ((k / n) as f64 - 1.0) * frame_s;
        let power = |k: usize| clock.segs[k % n].power_w;
        let mut deque: std::collections::VecDeque<usize> = std::collections::VecDeque::new();
        let mut next_in = 0usize; // next bin to push
        let m = cand.len();
        let mut p_w = Vec::with_capacity(m);
        for j in 0..m {
            let lo = cand[j] - delta_s;
            let hi = if j + 1 < m { cand[j + 1] } else { frame_s };
            // On the open piece (c_j, c_{j+1}), P̄ is the max over bins
            // meeting [t − Δ, t]: those starting before c_{j+1} and ending
            // after c_j − Δ.
            while next_in < 3 * n && start_of(next_in) < hi {
                while deque.back().is_some_and(|&b| power(b) <= power(next_in)) {
                    deque.pop_back();
                }
                deque.push_back(next_in);
                next_in += 1;
            }
            while deque.front().is_some_and(|&b| end_of(b) <= lo) {
                deque.pop_front();
            }
            p_w.push(deque.front().map_or(p_max, |&b| power(b)));
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

    /// For unwrapped `t`: whole periods before it, its offset in the
    /// period, and the piece containing that offset.
    fn locate(&self, t: f64) -> (f64, f64, usize) {
        let k = (t / self.frame_s).floor();
        let r = t - k * self.frame_s;
        let j = self
            .t_s
            .partition_point(|&c| c <= r)
            .saturating_sub(1)
            .min(self.pieces() - 1);
        (k, r, j)
    }

    /// `∫₀^t P̄` for unwrapped `t`.
    fn integral_to(&self, t: f64) -> f64 {
        let (k, r, j) = self.locate(t);
        k * self.cum_j[self.pieces()] + self.cum_j[j] + self.p_w[j] * (r - self.t_s[j])
    }

    /// `P̄` on the piece containing unwrapped `t`.
    fn power_at(&self, t: f64) -> f64 {
        self.p_w[self.locate(t).2]
    }

    /// Unwrapped breakpoint `idx` (piece starts, periodic).
    fn bp(&self, idx: i64) -> f64 {
        let m = self.pieces() as i64;
        let k = idx.div_euclid(m);
        self.t_s[idx.rem_euclid(m) as usize] + k as f64 * self.frame_s
    }

    fn p_of(&self, idx: i64) -> f64 {
        self.p_w[idx.rem_euclid(self.pieces() as i64) as usize]
    }
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

/// Evaluates the bound for bins `segs` (validated: cover [0, 360) in order,
/// positive spins), half pass angle `half_deg`, and `laser`.
#[must_use]
pub fn evaluate(segs: &[Seg], half_deg: f64, laser: &Laser) -> Bound {
    let clock = Clock::new(segs);
    let n = segs.len();
    let delta = 1.0 / laser.pulse_rate_hz;
    let frame_s = clock.frame_s;
    let env = Envelope::new(&clock, delta);
    let h = half_deg.min(180.0);
    let p_hat = segs.iter().map(|s| s.power_w).fold(0.0, f64::max);

    // φ-cells: azimuths where a pass edge, or a pass edge shifted by Δ in
    // time, meets a bin edge.
    let mut cuts: Vec<f64> = Vec::with_capacity(4 * n + 1);
    let wrap = |a: f64| {
        let w = a.rem_euclid(360.0);
        if w >= 360.0 {
            0.0
        } else {
            w
        }
    };
    for (seg, &t) in segs.iter().zip(&clock.cum_s) {
        let a = seg.start_deg;
        cuts.push(wrap(a + h));
        cuts.push(wrap(a - h));
        cuts.push(wrap(clock.angle_at(t + delta) + h));
        cuts.push(wrap(clock.angle_at(t + frame_s - delta) - h));
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let tau = |phi: f64| clock.time_at(phi + h) - clock.time_at(phi - h);
    let energy = |phi: f64| {
        env.integral_to(clock.time_at(phi + h) + delta) - env.integral_to(clock.time_at(phi - h))
    };
    let passes_t2 = |tau_s: f64| passes_in_window(ael::T2_S.min(ael::TIME_BASE_S), tau_s, frame_s);

    let mut single = (0.0f64, 0.0f64); // (ratio, azimuth)
    let mut e_max = (0.0f64, 0.0f64); // (energy, azimuth)
    let mut tau_max = 0.0f64;
    let m = cuts.len();
    for c in 0..m {
        let u = cuts[c];
        let v = if c + 1 < m {
            cuts[c + 1]
        } else {
            cuts[0] + 360.0
        };
        // Stationary points of τ and E inside (u, v).
        let mid = 0.5 * (u + v);
        let (_, jr, _) = clock.locate(mid + h);
        let (_, jl, _) = clock.locate(mid - h);
        let (ar, br) = segs[jr].spin_sq_line();
        let (al, bl) = segs[jl].spin_sq_line();
        // ω²(φ ± h) as a + b·φ.
        let right = (
            ar + br * (mid + h - anchor(&clock, mid + h, jr)) - br * mid,
            br,
        );
        let left = (
            al + bl * (mid - h - anchor(&clock, mid - h, jl)) - bl * mid,
            bl,
        );
        let pr = env.power_at(clock.time_at(mid + h) + delta);
        let pl = env.power_at(clock.time_at(mid - h));
        let mut pts = vec![u, v];
        for (wr, wl) in [(1.0, 1.0), (pr, pl)] {
            // wr²·ω²(φ − h) = wl²·ω²(φ + h)
            let den = wr * wr * left.1 - wl * wl * right.1;
            if den != 0.0 {
                let phi = (wl * wl * right.0 - wr * wr * left.0) / den;
                if phi > u && phi < v {
                    pts.push(phi);
                }
            }
        }
        let mut cell_tau = 0.0f64;
        let mut cell_e = (0.0f64, u);
        for &phi in &pts {
            cell_tau = cell_tau.max(tau(phi));
            let e = energy(phi);
            if e > cell_e.0 {
                cell_e = (e, phi);
            }
        }
        tau_max = tau_max.max(cell_tau);
        // Rule 1 on the cell: the hottest bin touching the closed union arc.
        let p_cell = max_power_touching(&clock, u - h, v + h);
        let per_pass = max_pulses_in(cell_tau, laser.pulse_rate_hz);
        // A pass also holds at most `per_pass` pulses of at most `p_cell·Δ`.
        let e_cell = cell_e.0.min(per_pass * p_cell * delta);
        if e_cell > e_max.0 {
            e_max = (e_cell, wrap(cell_e.1));
        }
        let r = laser.single_pulse_ratio(p_cell * delta, per_pass, passes_t2(cell_tau));
        if r > single.0 {
            single = (r, wrap(mid));
        }
    }

    // Rule 2 within one revolution: window walks over envelope breakpoints.
    let (pass_ratio, pass_window) =
        within_pass(&env, laser, e_max.0, p_hat, (tau_max + delta).min(frame_s));
    // Rule 2 over several passes, up to the time base.
    let (multi_ratio, multi_window) = laser.multi_pass_ratio(frame_s, e_max.0, p_hat);
    let multi_rule = Rule::for_duration(multi_window, frame_s);
    let mut ratios = [single.0, pass_ratio, 0.0, 0.0];
    match multi_rule {
        Rule::TimeBase => ratios[3] = multi_ratio,
        _ => ratios[2] = multi_ratio,
    }
    // Also report the time-base figure itself (mean power over 100 s).
    let tb = ael::TIME_BASE_S;
    let l = tb + delta;
    let q = (l / frame_s).floor();
    let e_tb = q * e_max.0 + e_max.0.min(p_hat * (l - q * frame_s));
    ratios[3] = ratios[3].max(e_tb / laser.ael_j(tb));
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
        worst_azimuth_deg: if k_best == 0 { single.1 } else { e_max.1 },
        ratios,
        max_pass_duration_s: tau_max,
        max_pulses_per_pass: max_pulses_in(tau_max, laser.pulse_rate_hz),
        max_pass_energy_j: e_max.0,
        worst_window_s: if k_best == 1 {
            pass_window
        } else {
            multi_window
        },
    }
}

/// Azimuth of the start of bin `j` on the same turn as `theta`.
fn anchor(clock: &Clock<'_>, theta: f64, j: usize) -> f64 {
    let (k, _, _) = clock.locate(theta);
    360.0 * k + clock.segs[j].start_deg
}

/// Highest power of the bins meeting the closed unwrapped arc `[lo, hi]`
/// (bins touched at an edge included, within 1e-9°).
fn max_power_touching(clock: &Clock<'_>, lo: f64, hi: f64) -> f64 {
    let snap = 1e-9;
    let n = clock.segs.len();
    let (k, mut i, _) = clock.locate(lo - snap);
    let mut pos = 360.0 * k + clock.segs[i].start_deg;
    let mut p = 0.0f64;
    for _ in 0..=n {
        p = p.max(clock.segs[i].power_w);
        pos += clock.segs[i].width_deg;
        if pos > hi + snap {
            break;
        }
        i = if i + 1 == n { 0 } else { i + 1 };
    }
    p
}

/// Rule 2 for windows shorter than one revolution: the supremum of
/// `min(E⁺, ∫ P̄ over L)/AEL(T)`, `T = L − Δ`, over window starts at envelope
/// up-steps and window ends at down-steps (where the best placement of a
/// fixed-length window lies; one walk from the first breakpoint covers a
/// constant envelope), walking breakpoint to breakpoint up to `l_max` (a
/// pass plus one pulse spacing). Beyond the pass energy `E⁺` or `l_max`
/// the energy is at most `E⁺`.
fn within_pass(env: &Envelope, laser: &Laser, e_pass: f64, p_hat: f64, l_max: f64) -> (f64, f64) {
    let delta = 1.0 / laser.pulse_rate_hz;
    let frame_s = env.frame_s;
    let t_end = (frame_s - delta).max(0.0);
    let m = env.pieces() as i64;
    let mut best = (0.0f64, 0.0f64);
    let mut truncated_at = f64::INFINITY;
    let mut take = |r: (f64, f64)| {
        if r.0 > best.0 {
            best = r;
        }
    };
    for i in 0..m {
        let up = env.p_of(i) > env.p_of(i - 1);
        let down = env.p_of(i) < env.p_of(i - 1);
        let mut dirs: Vec<i64> = Vec::with_capacity(2);
        if up || i == 0 {
            dirs.push(1);
        }
        if down {
            dirs.push(-1);
        }
        for dir in dirs {
            let b0 = env.bp(i);
            let (mut e, mut l, mut steps, mut idx) = (0.0f64, 0.0f64, 0usize, i);
            loop {
                let (next_idx, piece_p) = if dir > 0 {
                    (idx + 1, env.p_of(idx))
                } else {
                    (idx - 1, env.p_of(idx - 1))
                };
                let seg_end = (env.bp(next_idx) - b0).abs().min(l_max);
                if seg_end > delta {
                    let l0 = l.max(delta);
                    let e0 = e + piece_p * (l0 - l);
                    take(laser.linear_capped_max(l0 - delta, seg_end - delta, e0, piece_p, e_pass));
                }
                e += piece_p * (seg_end - l);
                l = seg_end;
                steps += 1;
                if e >= e_pass || l >= l_max {
                    // From here on the window holds at most E⁺.
                    let t_c = if e >= e_pass && piece_p > 0.0 {
                        (l - (e - e_pass) / piece_p - delta).max(0.0)
                    } else {
                        (l - delta).max(0.0)
                    };
                    take(laser.linear_capped_max(t_c, t_end.max(t_c), e_pass, 0.0, e_pass));
                    break;
                }
                if steps >= WALK_MAX_PIECES {
                    truncated_at = truncated_at.min((l - delta).max(0.0));
                    break;
                }
                idx = next_idx;
            }
        }
    }
    if truncated_at.is_finite() {
        // Beyond a truncated walk: the slope bound min(E⁺, P̂·L) over all
        // longer windows (sound, looser).
        let t0 = truncated_at;
        take(laser.linear_capped_max(t0, t_end.max(t0), p_hat * (t0 + delta), p_hat, e_pass));
    }
    best
}
