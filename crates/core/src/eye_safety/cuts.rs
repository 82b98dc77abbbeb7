//! Linear cuts for the optimizer: constraints linear in the bin powers
//! that every power vector the sound bound certifies meets
//! (`specs/optimizer.md`, "Eye safety as cuts").
//!
//! Fix the spin profile. Two kinds of cut, both `Σ_b n_b·p_b/f_p ≤ L` with
//! `n_b` and `L` functions of the spin alone:
//!
//! - **Concrete exposures** (Rule 2 within a pass, and over several passes
//!   up to the time base). One aperture azimuth
//!   `φ`, one pulse clock locked to the rotation (its phase chosen), one
//!   window: the pulses the aperture receives in it, `n_b` from bin `b`,
//!   carry `Σ n_b·p_b/f_p` J, against `L`, the smallest AEL over the
//!   window lengths that hold exactly those pulses (each is a window of its
//!   own; [`Laser::ael_inf_j`], the model's one AEL infimum). The true
//!   worst ratio is at least this exposure's, and the bound at least the
//!   true worst ratio.
//! - **The bound's Rule 1 figure at one aperture.** For every bin the
//!   closed pass arc at `φ` meets, one pulse (`n_b = 1`) against
//!   `1/`[`Laser::single_pulse_ratio_per_j`] at the counts of that pass's
//!   duration (`max_pulses_in`, `passes_in_window`, rounded up as the bound
//!   rounds them). The bound's Rule 1 figure is at least this at every
//!   aperture (each cell takes the largest power of the bins its passes
//!   meet, at the counts of its longest pass), so the cut holds wherever
//!   the bound certifies. It is the bound's own figure, not a concrete
//!   exposure: no one clock need reach its counts, which is what makes it
//!   tight where Rule 1 binds. Likewise Rule 1's `T_i` groups (700–1050
//!   nm): any `g` = [`Laser::group`] consecutive pulses against
//!   `C5(⌈K/g⌉·passes)·AEL(T_i)` at the bound's counts.
//!
//! So a cut never removes a certifiable profile, whatever powers it was
//! found at: a program with cuts in place of the bound is a relaxation of
//! "the bound certifies", and its optimum an upper bound of the best
//! certifiable objective. `tests/it/eye_safety/cuts.rs` checks every cut against the
//! bound on random profiles of every band.
//!
//! Nothing here decides that a profile is safe: a cut is a lower bound of
//! the bound's figure (a sample of it), the bound's opposite. Cuts
//! *separate*: they tell a program which linear constraint its current
//! powers break. [`cuts`] finds the ones at or above a threshold ratio for
//! the powers the bins carry: apertures at every bin edge `± h` (where pass
//! edges meet bin edges, the bound's cells) and at any extra azimuths asked
//! for (the bound's witness); three clock phases (the pulses pushed to the
//! start, the middle and the end of the pass's slack); and the windows:
//! every run of consecutive pulses of one pass (when a pass holds more than
//! [`ALL_RUNS_MAX_PULSES`], the runs from its first pulse to the last pulse
//! of each bin, and from the first pulse of each bin to its last), and `q`
//! whole passes up to the time base, `q` at the ends of every Table 3 row.
//!
//! Concrete counts are taken inside by a relative margin [`COUNT_INSIDE`]
//! (a pass that holds `x·f_p` on an integer gets the smaller count), and
//! window lengths are kept strictly between the pulses' span and the next
//! pulse: a concrete exposure with room to spare, never one that exists only
//! up to rounding.

use super::ael::{T2_S, TIME_BASE_S};
use super::bound::{max_pulses_in, passes_in_window, Laser, Rule, Seg};
use crate::profile::kinematics::{split_periods, Timeline};

/// Pulses of one pass up to which every run of consecutive pulses is a
/// window; beyond, the runs from the first pulse and to the last.
pub const ALL_RUNS_MAX_PULSES: usize = 32;

/// Relative margin by which counts and window lengths stay inside.
pub const COUNT_INSIDE: f64 = 1e-9;

/// A concrete exposure: the pulses one aperture receives from each bin in
/// one window, and the limit they are held to. Valid for every power
/// vector of the same spin profile (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    /// The rule whose limit this is.
    pub rule: Rule,
    /// Aperture azimuth, deg.
    pub azimuth_deg: f64,
    /// The window lengths that hold exactly these pulses, s: the limit is
    /// the smallest AEL over them ([`Laser::ael_inf_j`], the model's one AEL
    /// infimum; every one of them is a concrete window).
    pub window_s: (f64, f64),
    /// (bin, pulses received from it), bins ascending, counts ≥ 1.
    pub pulses: Vec<(usize, f64)>,
    /// The limit, J.
    pub limit_j: f64,
}

impl Cut {
    /// Energy received with bin powers `power_w`, J.
    #[must_use]
    pub fn energy_j(&self, power_w: &[f64], pulse_rate_hz: f64) -> f64 {
        self.pulses
            .iter()
            .map(|&(b, n)| n * power_w[b])
            .sum::<f64>()
            / pulse_rate_hz
    }

    /// Energy over the limit with bin powers `power_w`.
    #[must_use]
    pub fn ratio(&self, power_w: &[f64], pulse_rate_hz: f64) -> f64 {
        self.energy_j(power_w, pulse_rate_hz) / self.limit_j
    }
}

/// The received pulses of one pass, one clock.
struct Pass {
    azimuth_deg: f64,
    /// The pass's duration, s.
    tau_s: f64,
    /// Pulse times from the first pulse, s.
    t_s: Vec<f64>,
    /// Bin of each pulse.
    bin: Vec<usize>,
}

/// The concrete exposures of the bins `segs` (validated: they cover
/// `[0, 360)` in order, spins positive) at a ratio of at least `threshold`
/// for their own powers, strongest first: at most one Rule 1 cut per bin
/// (its smallest limit), and no two cuts with the same pulses and limit.
/// `half_deg` is half the pass angle, `extra_azimuths_deg` apertures to try
/// besides every bin edge `± half_deg`.
#[must_use]
pub fn cuts(
    segs: &[Seg],
    half_deg: f64,
    laser: &Laser,
    extra_azimuths_deg: &[f64],
    threshold: f64,
) -> Vec<Cut> {
    cuts_with(
        segs,
        half_deg,
        laser,
        extra_azimuths_deg,
        threshold,
        threshold,
    )
}

/// [`cuts`] with its own threshold for the Rule 1 cuts on one bin (a
/// program takes those as column bounds, which cost it nothing: the
/// optimizer asks for all of them).
#[must_use]
pub fn cuts_with(
    segs: &[Seg],
    half_deg: f64,
    laser: &Laser,
    extra_azimuths_deg: &[f64],
    threshold: f64,
    rule_one_threshold: f64,
) -> Vec<Cut> {
    let tl = Timeline::from_bins(segs);
    let h = half_deg.min(180.0);
    let mut found: Vec<Cut> = Vec::new();
    let mut single: Vec<Option<Cut>> = vec![None; segs.len()];
    let azimuths = segs
        .iter()
        .flat_map(|s| [s.start_deg - h, s.start_deg + h])
        .chain(extra_azimuths_deg.iter().copied());
    let mut prune = Prune::new(laser, tl.period_s());
    let f_p = laser.pulse_rate_hz;
    let frame_s = tl.period_s();
    for phi in azimuths {
        let Some(ap) = aperture(&tl, laser, phi, h) else {
            continue;
        };
        let p_max = ap.met.iter().map(|&b| segs[b].power_w).fold(0.0, f64::max);
        // Rule 1, the bound's own figure at this aperture: every bin the
        // pass meets, at the counts of this pass's duration
        // (`max_pulses_in`, `passes_in_window`, rounded up as the bound
        // rounds them). The bound's Rule 1 figure is at least this for
        // every aperture (each cell takes its bins' largest power at counts
        // of its largest duration), so the cut holds wherever the bound
        // certifies; it is not a concrete exposure (the counts are the
        // bound's, which no one clock need reach).
        let per_pass = max_pulses_in(ap.tau_s, f_p);
        let passes = passes_in_window(T2_S.min(TIME_BASE_S), ap.tau_s, frame_s);
        let limit1 = 1.0 / laser.single_pulse_ratio_per_j(per_pass, passes);
        for &b in &ap.met {
            if segs[b].power_w / f_p / limit1 >= rule_one_threshold
                && single[b].as_ref().is_none_or(|c| limit1 < c.limit_j)
            {
                single[b] = Some(Cut {
                    rule: Rule::SinglePulse,
                    azimuth_deg: ap.azimuth_deg,
                    window_s: (laser.pulse_duration_s, laser.pulse_duration_s),
                    pulses: vec![(b, 1.0)],
                    limit_j: limit1,
                });
            }
        }
        // The windows and groups need the pulses; skip them where even the
        // hottest met bin in every pulse cannot reach the threshold.
        let k = ap.pulses as usize;
        let g = laser.group(per_pass);
        let limit_g = laser.c5((per_pass / g).ceil() * passes) * laser.ael_j(laser.band.t_i_s());
        let per_pulse = p_max / f_p;
        let reachable = threshold <= 0.0
            || per_pulse * prune.runs_up_to(k) >= threshold
            || per_pulse * ap.pulses * prune.passes >= threshold
            || (g > 1.0 && g * per_pulse / limit_g >= threshold);
        if !reachable {
            continue;
        }
        for phase in [1e-3, 0.5, 1.0 - 1e-3] {
            let pass = received(&tl, laser, &ap, phase);
            exposures(&pass, segs, &tl, laser, threshold, &mut prune, &mut found);
        }
    }
    found.extend(single.into_iter().flatten());
    let f_p = laser.pulse_rate_hz;
    let p: Vec<f64> = segs.iter().map(|s| s.power_w).collect();
    // Each cut's ratio once (a cut sums over all its pulses), not once per
    // comparison: the same keys, so the same order.
    let mut keyed: Vec<(f64, Cut)> = found.into_iter().map(|c| (c.ratio(&p, f_p), c)).collect();
    sort_strongest_first(&mut keyed);
    keyed.dedup_by(|(_, a), (_, b)| a.pulses == b.pulses && a.limit_j == b.limit_j);
    keyed.into_iter().map(|(_, c)| c).collect()
}

/// Cuts keyed by their ratio, strongest first: the largest ratio, then the
/// smallest limit, then the pulse list, so that equal ratios keep one order
/// and the program built from the cuts is deterministic.
fn sort_strongest_first(keyed: &mut [(f64, Cut)]) {
    keyed.sort_by(|(ra, a), (rb, b)| {
        rb.total_cmp(ra)
            .then_with(|| a.limit_j.total_cmp(&b.limit_j))
            .then_with(|| {
                a.pulses
                    .partial_cmp(&b.pulses)
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
    });
}

/// One aperture's pass: its azimuth, when it starts (unwrapped), how long
/// it lasts, how many pulses fit strictly inside it, and the bins it meets.
struct Aperture {
    azimuth_deg: f64,
    t_a_s: f64,
    tau_s: f64,
    /// Pulses strictly inside the pass, with room: `(K − 1)·Δ < τ`.
    pulses: f64,
    /// Every bin the closed pass arc meets.
    met: Vec<usize>,
}

/// The pass of the aperture at `phi` (half pass angle `h`); `None` for an
/// empty pass or more than 10⁶ pulses in it.
fn aperture(tl: &Timeline<'_, Seg>, laser: &Laser, phi: f64, h: f64) -> Option<Aperture> {
    let f_p = laser.pulse_rate_hz;
    let t_a = tl.time_at_unwrapped_s(phi - h);
    let t_b = tl.time_at_unwrapped_s(phi + h);
    let tau = (t_b - t_a).min(tl.period_s());
    if tau.is_nan() || tau <= 0.0 {
        return None;
    }
    let k = (tau * f_p * (1.0 - COUNT_INSIDE)).floor() + 1.0;
    let slack = tau - (k - 1.0) / f_p;
    if slack.is_nan() || slack <= 0.0 || k > 1e6 {
        return None;
    }
    Some(Aperture {
        azimuth_deg: crate::model::angle::wrap_deg(phi),
        t_a_s: t_a,
        tau_s: tau,
        pulses: k,
        met: tl.bins_touching(phi - h, 2.0 * h),
    })
}

/// The pulses the aperture receives in one pass under a clock locked to the
/// rotation whose first pulse sits `phase` of the way through the pass's
/// slack (the time the pass has beyond its pulses' span).
fn received(tl: &Timeline<'_, Seg>, laser: &Laser, ap: &Aperture, phase: f64) -> Pass {
    let delta = 1.0 / laser.pulse_rate_hz;
    let slack = ap.tau_s - (ap.pulses - 1.0) * delta;
    let t0 = ap.t_a_s + phase * slack;
    let period = tl.period_s();
    let n = ap.pulses as usize;
    let mut t_s = Vec::with_capacity(n);
    let mut bin = Vec::with_capacity(n);
    for j in 0..n {
        let dt = j as f64 * delta;
        let (_, t) = split_periods(t0 + dt, period);
        t_s.push(dt);
        bin.push(tl.azimuth_at(t).1);
    }
    Pass {
        azimuth_deg: ap.azimuth_deg,
        tau_s: ap.tau_s,
        t_s,
        bin,
    }
}

/// Pulses of `pass[i..=k]`, per bin, times `q` (bins ascending).
fn tally(pass: &Pass, i: usize, k: usize, q: f64) -> Vec<(usize, f64)> {
    // The pulses meet the bins in runs (the head moves on): count the runs.
    let mut out: Vec<(usize, f64)> = Vec::new();
    for &b in &pass.bin[i..=k] {
        match out.last_mut() {
            Some(last) if last.0 == b => last.1 += q,
            _ => out.push((b, q)),
        }
    }
    out.sort_by_key(|e| e.0);
    let mut merged: Vec<(usize, f64)> = Vec::with_capacity(out.len());
    for (b, c) in out {
        match merged.last_mut() {
            Some(last) if last.0 == b => last.1 += c,
            _ => merged.push((b, c)),
        }
    }
    merged
}

/// Upper bounds of the window cuts' ratios per joule, so that apertures
/// whose windows cannot reach the threshold skip them (a cut skipped is
/// only a cut not offered: the loop asks again if the bound still
/// rejects).
struct Prune {
    /// `g[ℓ − 1]` = the largest `ℓ'/AEL_inf` over runs of `ℓ' ≤ ℓ` pulses:
    /// a run of `ℓ'` pulses spans `(ℓ' − 1)·Δ` and ends within the frame,
    /// so its limit is at least the smallest AEL over
    /// `[(ℓ' − 1)·Δ, T_f]` (a wider range, a smaller infimum).
    runs: Vec<f64>,
    /// The largest `q/AEL_inf` over `q` whole passes: each spans at least
    /// `(q − 1)·T_f` and less than `q·T_f`; infinite when there are more
    /// than [`Prune::MAX_PASSES`] candidates (no pruning).
    passes: f64,
    laser: Laser,
    frame_s: f64,
}

impl Prune {
    const MAX_PASSES: f64 = 4096.0;

    fn new(laser: &Laser, frame_s: f64) -> Self {
        let low = 1.0 - 1e-12;
        let q_max = (TIME_BASE_S / frame_s).floor() + 1.0;
        let passes = if q_max > Self::MAX_PASSES {
            f64::INFINITY
        } else {
            let mut best: f64 = 0.0;
            let mut q = 2.0;
            while q <= q_max {
                let lo = ((q - 1.0) * frame_s * low).max(laser.pulse_duration_s);
                best = best.max(q / laser.ael_inf_j(lo, (q * frame_s).max(lo)));
                q += 1.0;
            }
            best
        };
        Self {
            runs: Vec::new(),
            passes,
            laser: *laser,
            frame_s,
        }
    }

    /// The largest `ℓ/AEL_inf` over runs of at most `len` pulses.
    fn runs_up_to(&mut self, len: usize) -> f64 {
        let delta = 1.0 / self.laser.pulse_rate_hz;
        while self.runs.len() < len {
            let l = self.runs.len() + 1;
            let lo = ((l as f64 - 1.0) * delta * (1.0 - 1e-12)).max(self.laser.pulse_duration_s);
            let g = l as f64 / self.laser.ael_inf_j(lo, self.frame_s.max(lo));
            let prev = self.runs.last().copied().unwrap_or(0.0);
            self.runs.push(prev.max(g));
        }
        self.runs[len - 1]
    }
}

#[allow(clippy::too_many_arguments)]
fn exposures(
    pass: &Pass,
    segs: &[Seg],
    tl: &Timeline<'_, Seg>,
    laser: &Laser,
    threshold: f64,
    prune: &mut Prune,
    found: &mut Vec<Cut>,
) {
    let f_p = laser.pulse_rate_hz;
    let frame_s = tl.period_s();
    let k_n = pass.t_s.len();
    let span = pass.t_s[k_n - 1];
    let energy_of = |j: usize| segs[pass.bin[j]].power_w / f_p;
    let mut prefix = Vec::with_capacity(k_n + 1);
    prefix.push(0.0);
    for j in 0..k_n {
        prefix.push(prefix[j] + energy_of(j));
    }
    let e_pass = prefix[k_n];
    let inside = 1.0 + COUNT_INSIDE;
    let below = 1.0 - COUNT_INSIDE;

    let tau = pass.tau_s;
    // Rule 1's T_i groups (700–1050 nm), as the bound counts them: at most
    // g = `Laser::group` pulses (a closed T_i window) in one group, ⌈K/g⌉
    // groups a pass at the bound's counts K and passes, against
    // C5(groups)·AEL(T_i). Any g consecutive pulses of this pass carry at
    // most g times the hottest met bin's pulse, which the bound's group
    // figure charges at these counts or larger ones: a cut under the bound.
    let per_pass = max_pulses_in(tau, f_p);
    let g = laser.group(per_pass);
    if g > 1.0 {
        let passes = passes_in_window(T2_S.min(TIME_BASE_S), tau, frame_s);
        let n_groups = (per_pass / g).ceil() * passes;
        let limit_g = laser.c5(n_groups) * laser.ael_j(laser.band.t_i_s());
        let len = (g as usize).min(k_n);
        for i in 0..=(k_n - len) {
            let k = i + len - 1;
            if k > i && (prefix[k + 1] - prefix[i]) / limit_g >= threshold {
                found.push(Cut {
                    rule: Rule::SinglePulse,
                    azimuth_deg: pass.azimuth_deg,
                    window_s: (laser.band.t_i_s(), laser.band.t_i_s()),
                    pulses: tally(pass, i, k, 1.0),
                    limit_j: limit_g,
                });
            }
        }
    }

    // Rule 2 within a pass: runs i..=k of consecutive pulses, every window
    // length from just over their span to just under the next pulse.
    let next_after = |k: usize| {
        if k + 1 < k_n {
            pass.t_s[k + 1]
        } else {
            frame_s
        }
    };
    let p_max = pass
        .bin
        .iter()
        .map(|&b| segs[b].power_w)
        .fold(0.0, f64::max);
    let reachable = threshold <= 0.0 || p_max / f_p * prune.runs_up_to(k_n) >= threshold;
    let runs: Vec<(usize, usize)> = if !reachable {
        Vec::new()
    } else if k_n <= ALL_RUNS_MAX_PULSES {
        (0..k_n)
            .flat_map(|i| (i..k_n).map(move |k| (i, k)))
            .collect()
    } else {
        // From the first pulse to the last of each bin's run of pulses,
        // and from the first of each run to the last pulse.
        let firsts = (0..k_n).filter(|&j| j == 0 || pass.bin[j] != pass.bin[j - 1]);
        let lasts = (0..k_n).filter(|&j| j + 1 == k_n || pass.bin[j] != pass.bin[j + 1]);
        lasts
            .map(|k| (0, k))
            .chain(firsts.filter(|&i| i > 0).map(|i| (i, k_n - 1)))
            .collect()
    };
    for (i, k) in runs {
        let e = prefix[k + 1] - prefix[i];
        let lo = ((pass.t_s[k] - pass.t_s[i]) * inside).max(laser.pulse_duration_s);
        let hi = ((next_after(k) - pass.t_s[i]) * below).min(TIME_BASE_S);
        let limit = laser.ael_inf_j(lo, hi);
        if e / limit >= threshold {
            found.push(Cut {
                rule: Rule::for_duration(lo, frame_s),
                azimuth_deg: pass.azimuth_deg,
                window_s: (lo, hi.max(lo)),
                pulses: tally(pass, i, k, 1.0),
                limit_j: limit,
            });
        }
    }

    // Several passes: q whole passes, every length from just over
    // (q − 1)·T_f + span to just under q·T_f (the next pass's first pulse),
    // up to the time base; q at the ends of every Table 3 row.
    if threshold > 0.0 && e_pass * prune.passes < threshold {
        return;
    }
    let whole = tally(pass, 0, k_n - 1, 1.0);
    let q_max = ((TIME_BASE_S / inside - span) / frame_s).floor() + 1.0;
    let mut qs: Vec<f64> = vec![2.0, 3.0, q_max - 1.0, q_max];
    for row in laser.rows() {
        for t in [row.t_lo_s, row.t_hi_s] {
            let q = ((t - span) / frame_s).floor() + 1.0;
            qs.extend([q - 1.0, q, q + 1.0, q + 2.0]);
        }
    }
    qs.retain(|&q| q >= 2.0 && q <= q_max);
    qs.sort_by(f64::total_cmp);
    qs.dedup();
    for q in qs {
        let lo = ((q - 1.0) * frame_s + span) * inside;
        let hi = (q * frame_s * below).min(TIME_BASE_S);
        if lo > hi {
            continue;
        }
        let limit = laser.ael_inf_j(lo, hi);
        if q * e_pass / limit >= threshold {
            found.push(Cut {
                rule: Rule::for_duration(lo, frame_s),
                azimuth_deg: pass.azimuth_deg,
                window_s: (lo, hi),
                pulses: whole.iter().map(|&(b, n)| (b, n * q)).collect(),
                limit_j: limit,
            });
        }
    }
}

/// The largest power any bin can carry in a profile the bound certifies,
/// over every spin profile that never turns faster than `spin_max_rad_s`
/// with frame period `frame_s`: Rule 1 at the counts of the shortest pass
/// such a profile can have. Every aperture's pass lasts at least
/// `2h/spin_max` (capped at the frame), the bound's Rule 1 figure charges
/// every bin a pass meets at the counts of that pass or larger ones, and
/// its ratio per joule never falls as the counts grow: so a bin above this
/// power makes the bound exceed 1 whatever the spin. A column bound for
/// programs whose spin moves (the global relaxation), W.
#[must_use]
pub fn rule_one_cap_w(laser: &Laser, half_deg: f64, spin_max_rad_s: f64, frame_s: f64) -> f64 {
    let tau_min = (2.0 * half_deg.min(180.0)).to_radians() / spin_max_rad_s;
    let tau_min = tau_min.min(frame_s);
    let f_p = laser.pulse_rate_hz;
    let per_j = laser.single_pulse_ratio_per_j(
        max_pulses_in(tau_min, f_p),
        passes_in_window(T2_S.min(TIME_BASE_S), tau_min, frame_s),
    );
    f_p / per_j
}

/// How the head's bound scales the single-channel figures
/// (`specs/optimizer.md`, "With a head: what is proved optimal").
///
/// **Rule 1** is `a·r₁ + b·E` with `r₁` the single-channel Rule 1 figure
/// and `E` the largest pulse energy (J); only one of `a`, `b` is nonzero
/// (`head::bound::single_pulse_ratio` is linear in the single-channel
/// Rule 1 ratio when no two channels share an aperture position, else
/// linear in the largest pulse energy).
///
/// **The energy rules** are the smallest of several candidates' peaks
/// (`head::bound::energy_ratios`): a minimum, so a cut scaled by some
/// factor stays a relaxation of "the head bound certifies" only if it is at
/// most *every* candidate's peak, for every power vector of the spin. Take
/// a single-channel energy cut (a concrete exposure at the head's widest
/// pass) of `n` pulses, limit `L` and window lengths from `lo`; `r` its
/// single-channel ratio, at most each single-channel energy figure. Each
/// candidate charges it at least `F_c·r`:
///
/// - `W_v ×` the single-channel figures: `F = W_v`.
/// - A separation (`W(L) ×` the single-channel figures, and from
///   `t_sep = L/ω_max` on `W_v ×` the multi-pass bounds, which bound every
///   single-channel window from `t_sep` on, the cut's too when
///   `lo ≥ t_sep`): `F = W(L)`, or `W_v` when `lo ≥ t_sep`.
/// - The short windows by firing slots (`SlotWindow`: at least
///   `max_j W_j/AEL_inf_j · P̂/f_p`, and `W_v ×` the multi-pass bounds
///   from the last range's end): a cut carries at most `n·P̂/f_p`, so
///   `F = L·max_j(W_j/AEL_inf_j)/n`, or at least `W_v` when `lo` is past
///   the last range.
/// - The instantaneous overlap (for each `T*` the bound takes: at least
///   `W_inst·P̂·sup_{T ≤ T*} (T + Δ)/AEL(T)`, and `W_v ×` the multi-pass
///   bounds from `T*`): every `T*` above `lo` charges at least
///   `W_inst·P̂·S(lo)` with `S(lo) = sup_{T ≤ lo} (T + Δ)/AEL(T)`, every
///   `T*` at or below it `W_v ×` the cut, so `F = min(W_v, L·W_inst·f_p·S(lo)/n)`
///   whichever `T*` the bound takes.
///
/// The cut's factor is the smallest of these ([`HeadScale::energy_factor`]):
/// the cut scaled by it is at most every candidate's peak, so at most the
/// head's energy figure, and the scaled cuts are a relaxation of the head
/// bound whichever candidate binds. A 1-pulse cut on one bin is then
/// exactly the slot candidate's short-window figure at that bin's power,
/// so where that candidate binds the cuts reach it.
#[derive(Debug, Clone)]
pub struct HeadScale {
    /// `W_v`: the largest factor (the vertical candidate puts it on every
    /// window).
    pub weight_vertical: f64,
    /// The other candidates of the head's energy figure.
    pub energy: Vec<EnergyCandidate>,
    /// `W_inst · f_p` (0 without the instantaneous candidate): its factor
    /// on a cut is `L·W_inst·f_p·S(lo)/n`.
    pub instant_per_j: f64,
    /// Rule 1's factor on the single-channel Rule 1 figure.
    pub rule_one_single: f64,
    /// Rule 1's ratio per joule of the largest pulse energy.
    pub rule_one_per_j: f64,
    /// Half the head's widest pass angle, deg (the bound's `half_deg`).
    pub half_deg: f64,
    laser: Laser,
}

/// One candidate of the head's energy figure as the factor it allows on a
/// single-channel energy cut of `n` pulses, limit `L` and shortest window
/// `lo`: `max(weight, L·short_per_j/n)`, and at least `W_v` when
/// `lo ≥ long_from_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyCandidate {
    /// The candidate's weight on every single-channel energy figure.
    pub weight: f64,
    /// The candidate's figure per joule of the largest pulse energy
    /// (`P̂/f_p`), 1/J.
    pub short_per_j: f64,
    /// Windows from this length on are charged `W_v ×` the single-channel
    /// multi-pass bounds, s.
    pub long_from_s: f64,
}

/// Relative margin by which every head factor is lowered (and the head's
/// Rule 1 per-joule limit raised): a cut and the head's figure are computed
/// by different float operations (a product of the factor and the cut's sum
/// against the bound's own products and maxima), a few ulps apart, so the
/// scaled cut stays at or below the figure for every power vector, not only
/// up to rounding. Far below the optimizer's head-room (1e-9).
pub const HEAD_FACTOR_MARGIN: f64 = 1e-12;

/// Relative margin by which a separation's window length is raised before
/// a cut's shortest window is compared with it (the cut then takes `W_v`
/// only when surely past it).
const SEPARATION_MARGIN: f64 = 1e-9;

impl HeadScale {
    /// The scales of the head bound for the spins of `segs` (the head's
    /// figures at their fastest spin, Rule 1's counts at their longest pass,
    /// both as the checker takes them: [`super::exposure::evaluate_segments`]).
    pub fn of(
        segs: &[Seg],
        params: &super::EyeSafetyParams,
        laser: &Laser,
    ) -> Result<Option<Self>, super::EyeSafetyError> {
        if params.head.is_none() {
            return Ok(None);
        }
        let report = super::exposure::evaluate_segments(segs, params, laser.pulse_rate_hz)?;
        let Some(hf) = report.head else {
            return Ok(None);
        };
        let frame_s = Timeline::from_bins(segs).period_s();
        let rule_one = |single_pulse_ratio: f64, power_max_w: f64| {
            super::head::bound::single_pulse_ratio(
                &hf,
                laser,
                super::head::bound::SingleFigures {
                    single_pulse_ratio,
                    pass_duration_s: report.max_pass_duration_s,
                    frame_s,
                    power_max_w,
                },
            )
        };
        // The head bound's fastest spin, as it takes it.
        let spin_max = segs
            .iter()
            .map(|s| s.spin_start_rad_s.max(s.spin_end_rad_s))
            .fold(0.0, f64::max);
        let w = hf.weight_vertical;
        let mut energy = Vec::new();
        for sep in &hf.separations {
            if sep.weight < w && spin_max > 0.0 {
                energy.push(EnergyCandidate {
                    weight: sep.weight,
                    short_per_j: 0.0,
                    long_from_s: sep.angle_rad / spin_max * (1.0 + SEPARATION_MARGIN),
                });
            }
        }
        let several = hf.count_vertical > 1;
        if let (true, Some(last)) = (several, hf.slot_windows.last()) {
            let per_j = hf
                .slot_windows
                .iter()
                .map(|r| r.weight / laser.ael_inf_j(r.lo_s, r.hi_s))
                .fold(0.0, f64::max);
            energy.push(EnergyCandidate {
                weight: 0.0,
                short_per_j: per_j,
                long_from_s: last.hi_s,
            });
        }
        Ok(Some(Self {
            weight_vertical: w,
            energy,
            instant_per_j: if several {
                hf.weight_instant * laser.pulse_rate_hz
            } else {
                0.0
            },
            rule_one_single: rule_one(1.0, 0.0),
            // Power `f_p` W is a pulse of 1 J.
            rule_one_per_j: rule_one(0.0, laser.pulse_rate_hz),
            half_deg: 0.5 * report.pass_angle_deg,
            laser: *laser,
        }))
    }

    /// The factor of a single-channel energy cut (its limit not yet
    /// divided): the smallest over the head's energy candidates (see the
    /// type's docs), at most `W_v`.
    #[must_use]
    pub fn energy_factor(&self, cut: &Cut) -> f64 {
        let w = self.weight_vertical;
        let n: f64 = cut.pulses.iter().map(|&(_, k)| k).sum();
        if n <= 0.0 {
            return w;
        }
        let lo = cut.window_s.0;
        let mut f = self
            .energy
            .iter()
            .map(|c| {
                let f = c.weight.max(cut.limit_j * c.short_per_j / n);
                if lo >= c.long_from_s {
                    f.max(w)
                } else {
                    f
                }
            })
            .fold(w, f64::min);
        if self.instant_per_j > 0.0 {
            f = f.min(cut.limit_j * self.instant_per_j * self.instant_short(lo) / n);
        }
        f
    }

    /// `S(t) = sup_{T ≤ t} (T + Δ)/AEL(T)`, s/J
    /// ([`Laser::instant_window_factor`], the head bound's own argument for
    /// its instantaneous candidate).
    fn instant_short(&self, t: f64) -> f64 {
        self.laser.instant_window_factor(t)
    }
}

/// [`cuts_with`] for the bound `params` describe: the single-channel cuts
/// without a head; with one, the cuts of the head's bound (still linear in
/// the bin powers): every energy cut's limit divided by its own factor
/// ([`HeadScale::energy_factor`]: the smallest any candidate of the head's
/// energy figure puts on a window of the cut's lengths), and Rule 1 either
/// the single-channel Rule 1 cuts divided by its factor or, where channels
/// share an aperture position, one cut per bin against the head's Rule 1
/// per joule. Each is at most the head bound's figure of its rule, so the
/// cuts stay a relaxation of "the head bound certifies"; the head cuts come
/// strongest first (their head ratios at the powers of `segs`).
pub fn cuts_for(
    segs: &[Seg],
    params: &super::EyeSafetyParams,
    laser: &Laser,
    extra_azimuths_deg: &[f64],
    threshold: f64,
    rule_one_threshold: f64,
) -> Result<Vec<Cut>, super::EyeSafetyError> {
    let Some(s) = HeadScale::of(segs, params, laser)? else {
        let half = 0.5 * super::exposure::pass_angle_deg(params, laser);
        return Ok(cuts_with(
            segs,
            half,
            laser,
            extra_azimuths_deg,
            threshold,
            rule_one_threshold,
        ));
    };
    // A cut's head ratio is its single-channel ratio times its factor, at
    // most `W_v` (Rule 1: its one factor), so a head threshold `t` asks for
    // the single-channel cuts at or above `t / W_v` and keeps those whose
    // head ratio reaches `t` (a zero factor: the rule cannot bind, no cut).
    let below = |t: f64, factor: f64| {
        if factor > 0.0 {
            t / factor
        } else {
            f64::INFINITY
        }
    };
    let rule_one_factor = if s.rule_one_per_j > 0.0 {
        0.0
    } else {
        s.rule_one_single * (1.0 - HEAD_FACTOR_MARGIN)
    };
    let found = cuts_with(
        segs,
        s.half_deg,
        laser,
        extra_azimuths_deg,
        below(threshold, s.weight_vertical),
        below(rule_one_threshold, rule_one_factor),
    );
    let f_p = laser.pulse_rate_hz;
    let p: Vec<f64> = segs.iter().map(|s| s.power_w).collect();
    let mut keyed: Vec<(f64, Cut)> = Vec::with_capacity(found.len());
    for mut c in found {
        let (factor, t) = if c.rule == Rule::SinglePulse {
            (rule_one_factor, rule_one_threshold)
        } else {
            (s.energy_factor(&c) * (1.0 - HEAD_FACTOR_MARGIN), threshold)
        };
        if factor <= 0.0 {
            continue;
        }
        c.limit_j /= factor;
        let r = c.ratio(&p, f_p);
        if r >= t {
            keyed.push((r, c));
        }
    }
    if s.rule_one_per_j > 0.0 {
        let limit_j = (1.0 + HEAD_FACTOR_MARGIN) / s.rule_one_per_j;
        for (b, seg) in segs.iter().enumerate() {
            let r = seg.power_w / f_p / limit_j;
            if r >= rule_one_threshold {
                keyed.push((
                    r,
                    Cut {
                        rule: Rule::SinglePulse,
                        azimuth_deg: seg.start_deg + 0.5 * seg.width_deg,
                        window_s: (laser.pulse_duration_s, laser.pulse_duration_s),
                        pulses: vec![(b, 1.0)],
                        limit_j,
                    },
                ));
            }
        }
    }
    sort_strongest_first(&mut keyed);
    Ok(keyed.into_iter().map(|(_, c)| c).collect())
}

/// [`rule_one_cap_w`] for the bound `params` describe. With a head, no cap
/// (`+∞`): the head's Rule 1 takes its weights at each profile's fastest
/// spin and changes form where channels start to share a position, so no
/// single figure is proved to hold for every spin profile of a box; an
/// absent column bound only weakens the relaxation, never cuts a
/// certifiable profile.
#[must_use]
pub fn rule_one_cap_for(
    params: &super::EyeSafetyParams,
    laser: &Laser,
    spin_max_rad_s: f64,
    frame_s: f64,
) -> f64 {
    if params.head.is_some() {
        return f64::INFINITY;
    }
    let half = 0.5 * super::exposure::pass_angle_deg(params, laser);
    rule_one_cap_w(laser, half, spin_max_rad_s, frame_s)
}
