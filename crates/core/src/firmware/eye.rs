//! Class 1 eye safety of a firmware table **as it will run**, in exact
//! integer arithmetic (no floating point: builds without `std`).
//!
//! The table runs bin `i` at constant spin: it sweeps `width_mdeg[i]` in
//! exactly `dwell_ticks[i] / tick_hz` seconds at code `power_code[i]`. A pulse
//! fired at code `c` carries `c · q` joules, `q = power_w_per_code / f_p` (the
//! *energy quantum*), so every energy below is an integer number of quanta and
//! every limit is an integer number of quanta **rounded down**
//! ([`IntEyeLimits`], derived once from the one eye-safety model by
//! [`IntEyeLimits::derive`], `std` only). The argument is in
//! `specs/eye_safety.md` ("Firmware tables: the integer check").
//!
//! Per aperture *cell* (azimuths between consecutive breakpoints, where a pass
//! edge meets a bin edge; breakpoints are integer millidegrees):
//! - every bin the pass can touch gets an integer cap on the pulses it can
//!   contribute, `⌊τ_k · f⌋ + 1` with `τ_k` its largest exact rational dwell
//!   inside the pass over the cell; the pass holds at most `K = ⌊τ · f⌋ + 1`
//!   pulses, `τ` the largest exact rational pass duration over the cell
//!   (linear on a cell, so at a cell end); `f` is the pulse rate rounded up
//!   to a millihertz;
//! - `G(k)`, the most quanta any `k` pulses of the pass can carry, is the
//!   greedy sum of the hottest capped bins (an upper bound of any `k`
//!   consecutive pulses, whatever the clock phase);
//! - rule 1: the hottest code `≤ pulse_code_max`; rule 2 within a pass:
//!   `G(k) ≤` the limit of the `k`-pulse bucket; several passes: `G(K) ≤
//!   pass_energy_max`. All sums are `u128`.
//!
//! With a head the limits hold the single channel's windows of length `T`
//! to `AEL(T)/W*(T)`, `W*` the smallest channel weight any candidate of the
//! float head bound proves for that length (derived on the host), or, for
//! the windows up to some `T*`, by the head's instantaneous power when every
//! code is small enough ([`InstantLimit`]: alternative limit sets, the
//! smallest worst ratio reported); a head declared at another distance than
//! 100 mm adds the second surface's limits ([`IntEyeLimits::other_surface`]),
//! and the table must pass both.

use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use super::{FirmwareTable, FULL_TURN_MDEG, MAX_TABLE_BINS};

/// Largest `tick_hz` the integer evaluation accepts (2^34 Hz ≈ 17 GHz).
pub const MAX_TICK_HZ: u64 = 1 << 34;
/// Largest `frame_ticks` the integer evaluation accepts (2^44 ≈ 1.8·10^13).
pub const MAX_FRAME_TICKS: u64 = 1 << 44;
/// Largest pulse rate the integer evaluation accepts, millihertz (2^40 mHz ≈ 1.1 GHz).
pub const MAX_PULSE_RATE_MILLIHZ: u64 = 1 << 40;
/// Most pulses one turn may hold (`frame_ticks · f / tick_hz`): keeps every
/// pulse count within `u64` (2^40 ≈ 1.1·10^12).
pub const MAX_PULSES_PER_TURN: u64 = 1 << 40;
/// Millihertz per hertz.
pub const MILLIHZ_PER_HZ: u64 = 1000;

/// The rule an integer check belongs to: the float bound's
/// [`Rule`](crate::eye_safety::Rule) (one type for both checkers).
pub use crate::eye_safety::Rule as IntRule;

/// The energy limit of windows holding `pulses_from ..` pulses of one pass
/// (up to the next bucket's `pulses_from`, exclusive).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct TrainLimit {
    /// Fewest pulses in the bucket (the first bucket starts at 1).
    pub pulses_from: u64,
    /// Most quanta any window holding that many pulses may receive:
    /// `⌊AEL_inf((pulses_from − 1)/f_p) / q⌋`.
    pub energy_max_quanta: u64,
}

/// The head's instantaneous-power candidate at one window length `T*`
/// (`specs/eye_safety.md`, "The head in the integer check"): the head
/// receives at most `W_inst · P̂` at any instant, so when every code of the
/// table is at most `code_max` every window up to `T*` is within its AEL,
/// and a window holding `k` pulses of one pass need only be held to the
/// limit of the windows from `T*` on: at least `energy_floor_quanta`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct InstantLimit {
    /// Largest code of any bin for the candidate to apply:
    /// `⌊AEL(T)/(W_inst · power_w_per_code · (T + Δ))⌋` over `T ≤ T*`.
    pub code_max: u64,
    /// Every within-pass bucket's limit is raised to at least this:
    /// `⌊inf AEL(T)/W*(T)⌋` over `T ≥ T*`, in quanta.
    pub energy_floor_quanta: u64,
}

/// Integer Class 1 limits of a table's timing, in energy quanta
/// (`power_w_per_code / pulse_rate_hz` joules). The table is checked against
/// them by [`evaluate`]; they are valid for a table whose timing they were
/// derived for (tick rate, frame, pass arc, pulse rate) and whose passes are no
/// longer and hold no more pulses than stated here — [`evaluate`] checks that.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct IntEyeLimits {
    /// Timer frequency, Hz.
    pub tick_hz: u64,
    /// Ticks per revolution.
    pub frame_ticks: u64,
    /// Pulse rate rounded up, millihertz (for pulse counts).
    pub pulse_rate_millihz_ceil: u64,
    /// Pass arc (aperture + beam seen from 100 mm) rounded up, millidegrees.
    pub pass_arc_mdeg: u32,
    /// Longest pass the limits allow, ticks.
    pub pass_ticks_max: u64,
    /// Most pulses in one pass the limits allow (C5 is taken at this count).
    pub pulses_per_pass_max: u64,
    /// Largest code of any pulse (rule 1, C5 and `T_i` groups included).
    pub pulse_code_max: u64,
    /// Within-pass buckets by pulse count, increasing, the first at 1 pulse.
    pub train: Vec<TrainLimit>,
    /// Most quanta one pass may carry so that every window over several
    /// passes, up to the time base, stays within its AEL.
    pub pass_energy_max_quanta: u64,
    /// The rule binding `pass_energy_max_quanta`.
    pub pass_energy_rule: IntRule,
    /// The head's instantaneous-power alternatives, one per `T*` (empty
    /// without a head of several channels meeting one height): the table
    /// passes when it passes the limits above alone or with any one of
    /// them ([`evaluate`] reports the smallest worst ratio).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub instant: Vec<InstantLimit>,
    /// The limits of the next aperture surface the table must also pass
    /// (with a head: the 100 mm cylinder's limits hold the 100 mm sphere's;
    /// a head declaring `aperture_distance_mm` other than 100 mm adds its
    /// declared distance's cylinder and sphere); a chain of at most
    /// [`SURFACES_MAX`] sets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other_surface: Option<alloc::boxed::Box<IntEyeLimits>>,
}

impl IntEyeLimits {
    /// The largest code any pulse may have under Rule 1 on every surface
    /// the limits hold (`pulse_code_max`, and the other surface's).
    #[must_use]
    pub fn pulse_code_cap(&self) -> u64 {
        self.other_surface
            .as_ref()
            .map_or(self.pulse_code_max, |o| {
                self.pulse_code_max.min(o.pulse_code_cap())
            })
    }
}

/// Why a table could not be evaluated (it is then not Class 1 evidence).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum IntEyeError {
    /// A value is outside the bounds the integer evaluation is proved for.
    #[error("{field} = {value}: {reason}")]
    Bounds {
        /// Field.
        field: &'static str,
        /// Value.
        value: u64,
        /// Why.
        reason: &'static str,
    },
    /// The limits were derived for another timing, or for shorter passes.
    #[error(
        "eye-safety limits do not apply to this table: {field} is {found}, limits allow {allowed}"
    )]
    Mismatch {
        /// Field.
        field: &'static str,
        /// Table's value.
        found: u64,
        /// Limits' value.
        allowed: u64,
    },
    /// An intermediate did not fit `u128` (cannot happen within the bounds;
    /// see the `eye_sums_never_overflow_within_format_bounds` harness).
    #[error("integer overflow in the eye-safety evaluation")]
    Overflow,
}

/// The verdict of [`evaluate`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[non_exhaustive]
pub struct IntEyeReport {
    /// Largest energy / limit over every check, parts per million, rounded up
    /// (≤ 1,000,000 is Class 1).
    pub worst_ratio_ppm: u64,
    /// The rule of the worst check.
    pub rule: IntRule,
    /// Aperture azimuth (centre of the pass arc) of the worst check, millidegrees.
    pub azimuth_mdeg: u32,
    /// Whether every check holds (energy ≤ limit everywhere).
    pub class1: bool,
}

/// Timing of a table that the limits depend on: the longest pass and the
/// most pulses in one pass, over every aperture azimuth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PassTiming {
    /// Longest pass, ticks, rounded up.
    pub pass_ticks_max: u64,
    /// Most pulses in one pass.
    pub pulses_per_pass_max: u64,
}

/// An exact non-negative rational `num / den` (den > 0).
#[derive(Debug, Clone, Copy)]
struct Ratio {
    num: u128,
    den: u128,
}

impl Ratio {
    fn add_int(self, x: u128) -> Result<Self, IntEyeError> {
        let num = x
            .checked_mul(self.den)
            .and_then(|v| v.checked_add(self.num))
            .ok_or(IntEyeError::Overflow)?;
        Ok(Self { num, den: self.den })
    }

    fn add_frac(self, num: u128, den: u128) -> Result<Self, IntEyeError> {
        let a = self.num.checked_mul(den).ok_or(IntEyeError::Overflow)?;
        let b = num.checked_mul(self.den).ok_or(IntEyeError::Overflow)?;
        Ok(Self {
            num: a.checked_add(b).ok_or(IntEyeError::Overflow)?,
            den: self.den.checked_mul(den).ok_or(IntEyeError::Overflow)?,
        })
    }

    fn max(self, o: Self) -> Result<Self, IntEyeError> {
        let l = self.num.checked_mul(o.den).ok_or(IntEyeError::Overflow)?;
        let r = o.num.checked_mul(self.den).ok_or(IntEyeError::Overflow)?;
        Ok(if l >= r { self } else { o })
    }

    fn ceil(self) -> u128 {
        self.num.div_ceil(self.den)
    }
}

/// The pulse-rate and tick constants of the counting: `⌊τ_ticks · f_mHz / (1000 · tick_hz)⌋ + 1`.
#[derive(Debug, Clone, Copy)]
struct Clock {
    millihz: u128,
    tick_hz: u128,
}

impl Clock {
    /// Most pulses in a closed interval of `t.num / t.den` ticks, any phase.
    fn pulses_in(self, t: Ratio) -> Result<u128, IntEyeError> {
        let num = t
            .num
            .checked_mul(self.millihz)
            .ok_or(IntEyeError::Overflow)?;
        let den = t
            .den
            .checked_mul(u128::from(MILLIHZ_PER_HZ) * self.tick_hz)
            .ok_or(IntEyeError::Overflow)?;
        Ok(num / den + 1)
    }
}

/// One aperture cell: the positions `[a0, a1]` (integer millidegrees) of
/// the start of the pass arc.
struct Cell<'a> {
    a0: i64,
    /// Largest pass duration over the cell, ticks.
    tau: Ratio,
    /// Most pulses in a pass over the cell.
    pulses: u128,
    /// Hottest code of any bin the pass can touch over the cell.
    hottest: u32,
    /// `Σ code × pulse cap` over the bins the pass can touch.
    energy_all: u128,
    /// `(code, pulse cap)` of the touched bins not wholly inside the pass
    /// at both cell ends (at most a few).
    edge_bins: &'a [(u32, u128)],
    /// `(code, pulse cap)` of the touched bins wholly inside the pass at
    /// both cell ends (their cap is all of their dwell).
    middle_bins: &'a [(u32, u128)],
}
/// Validates the bounds under which every intermediate fits `u128`.
fn check_bounds(table: &FirmwareTable, millihz: u64, arc_mdeg: u32) -> Result<(), IntEyeError> {
    let b = |field, value, reason| {
        Err(IntEyeError::Bounds {
            field,
            value,
            reason,
        })
    };
    let n = table.bins.len();
    if n == 0 || n > MAX_TABLE_BINS {
        return b("bins", n as u64, "a table holds 1 to 36,000 bins");
    }
    if table.tick_hz == 0 || table.tick_hz > MAX_TICK_HZ {
        return b("tick_hz", table.tick_hz, "must lie in 1..=2^34");
    }
    if table.frame_ticks == 0 || table.frame_ticks > MAX_FRAME_TICKS {
        return b("frame_ticks", table.frame_ticks, "must lie in 1..=2^44");
    }
    if millihz == 0 || millihz > MAX_PULSE_RATE_MILLIHZ {
        return b(
            "pulse_rate_hz (mHz)",
            millihz,
            "must lie in 1 mHz..=2^40 mHz",
        );
    }
    let per_turn = u128::from(table.frame_ticks) * u128::from(millihz)
        / (u128::from(MILLIHZ_PER_HZ) * u128::from(table.tick_hz));
    if per_turn >= u128::from(MAX_PULSES_PER_TURN) {
        return b(
            "pulses per turn",
            u64::try_from(per_turn).unwrap_or(u64::MAX),
            "a turn may hold fewer than 2^40 pulses",
        );
    }
    if arc_mdeg == 0 || arc_mdeg >= FULL_TURN_MDEG / 2 {
        return b(
            "pass arc (mdeg)",
            u64::from(arc_mdeg),
            "the aperture pass must be shorter than half a turn",
        );
    }
    let ticks: u128 = table.bins.iter().map(|x| u128::from(x.dwell_ticks)).sum();
    if ticks != u128::from(table.frame_ticks) {
        return b(
            "dwell_ticks",
            u64::try_from(ticks).unwrap_or(u64::MAX),
            "must sum to frame_ticks (the table's timing is undefined otherwise)",
        );
    }
    let width: u128 = table.bins.iter().map(|x| u128::from(x.width_mdeg)).sum();
    if width != u128::from(FULL_TURN_MDEG) {
        return b(
            "width_mdeg",
            u64::try_from(width).unwrap_or(u64::MAX),
            "must sum to 360,000",
        );
    }
    if table
        .bins
        .iter()
        .any(|x| x.width_mdeg > 0 && x.dwell_ticks == 0)
    {
        return b("dwell_ticks", 0, "a bin with width needs a positive dwell");
    }
    Ok(())
}

/// Walks every aperture cell of the table, in azimuth order, calling `visit`.
///
/// Bins wholly inside the pass at both cell ends are summed through prefix
/// sums (their dwell and `code × cap`) and their hottest code through a
/// sliding-window maximum, so a cell costs O(1) beyond its few edge bins.
fn for_each_cell(
    table: &FirmwareTable,
    clock: Clock,
    arc_mdeg: u32,
    mut visit: impl FnMut(&Cell<'_>) -> Result<(), IntEyeError>,
) -> Result<(), IntEyeError> {
    let w_turn = i64::from(FULL_TURN_MDEG);
    let h = i64::from(arc_mdeg);
    let n = table.bins.len();
    // Bin intervals on the unrolled line, three turns: [-W, 2W).
    let mut iv: Vec<(i64, i64, usize)> = Vec::with_capacity(3 * n);
    let mut starts: Vec<i64> = Vec::with_capacity(2 * n);
    for turn in -1..=1i64 {
        let mut s = 0i64;
        for (k, b) in table.bins.iter().enumerate() {
            let e = s + i64::from(b.width_mdeg);
            iv.push((s + turn * w_turn, e + turn * w_turn, k));
            if turn == 0 {
                starts.push(s);
                starts.push((s - h).rem_euclid(w_turn));
            }
            s = e;
        }
    }
    starts.sort_unstable();
    starts.dedup();
    let full_cap: Vec<u128> = table
        .bins
        .iter()
        .map(|b| {
            clock.pulses_in(Ratio {
                num: u128::from(b.dwell_ticks),
                den: 1,
            })
        })
        .collect::<Result<_, _>>()?;
    // Per unrolled entry: (code, full cap); prefix sums of dwell and code × cap.
    let full: Vec<(u32, u128)> = iv
        .iter()
        .map(|&(_, _, k)| (table.bins[k].power_code, full_cap[k]))
        .collect();
    let mut pre_ticks: Vec<u128> = Vec::with_capacity(iv.len() + 1);
    let mut pre_energy: Vec<u128> = Vec::with_capacity(iv.len() + 1);
    pre_ticks.push(0);
    pre_energy.push(0);
    for (i, &(_, _, k)) in iv.iter().enumerate() {
        let t = pre_ticks[i] + u128::from(table.bins[k].dwell_ticks);
        let e = u128::from(full[i].0)
            .checked_mul(full[i].1)
            .and_then(|x| x.checked_add(pre_energy[i]))
            .ok_or(IntEyeError::Overflow)?;
        pre_ticks.push(t);
        pre_energy.push(e);
    }
    let m = starts.len();
    // starts holds 0 and W − h ≠ 0, so m ≥ 2 and every cell is shorter than a turn.
    let (mut lo, mut hi, mut mid_lo, mut mid_hi) = (0usize, 0usize, 0usize, 0usize);
    // Sliding maximum of the code over the touched entries [lo, hi).
    let mut hot: alloc::collections::VecDeque<usize> = alloc::collections::VecDeque::new();
    let mut edges: Vec<(u32, u128)> = Vec::new();
    for j in 0..m {
        let a0 = starts[j];
        let a1 = if j + 1 < m { starts[j + 1] } else { w_turn };
        let reach = a1 + h;
        while lo < iv.len() && iv[lo].1 < a0 {
            lo += 1;
        }
        while hi < iv.len() && iv[hi].0 <= reach {
            while hot.back().is_some_and(|&b| full[b].0 <= full[hi].0) {
                hot.pop_back();
            }
            hot.push_back(hi);
            hi += 1;
        }
        while hot.front().is_some_and(|&f| f < lo) {
            hot.pop_front();
        }
        // Wholly inside at both ends: start ≥ a1 and end ≤ a0 + h.
        while mid_lo < iv.len() && iv[mid_lo].0 < a1 {
            mid_lo += 1;
        }
        while mid_hi < iv.len() && iv[mid_hi].1 <= a0 + h {
            mid_hi += 1;
        }
        let mid_start = mid_lo.clamp(lo, hi);
        let mid_end = mid_hi.clamp(mid_start, hi);
        let mut tau0 = Ratio { num: 0, den: 1 };
        let mut tau1 = Ratio { num: 0, den: 1 };
        let mid_ticks = pre_ticks[mid_end] - pre_ticks[mid_start];
        tau0 = tau0.add_int(mid_ticks)?;
        tau1 = tau1.add_int(mid_ticks)?;
        let mut energy_all = pre_energy[mid_end] - pre_energy[mid_start];
        edges.clear();
        for &(s, e, k) in iv[lo..mid_start].iter().chain(&iv[mid_end..hi]) {
            let b = &table.bins[k];
            let d = u128::from(b.dwell_ticks);
            let w = e - s;
            let overlap = |a: i64| (e.min(a + h) - s.max(a)).max(0);
            let inside = |a: i64| s <= a + h && e >= a;
            // Largest overlap at a cell end (the overlap is linear on a cell).
            let mut x_max: Option<i64> = None;
            for (a, tau) in [(a0, &mut tau0), (a1, &mut tau1)] {
                if !inside(a) {
                    continue;
                }
                let x = overlap(a);
                x_max = Some(x_max.map_or(x, |m| m.max(x)));
                if w == 0 || x == w {
                    *tau = tau.add_int(d)?;
                } else if x > 0 {
                    *tau = tau.add_frac((x as u128) * d, w as u128)?;
                }
            }
            // Pulses this bin can contribute: all of its dwell, a part, or
            // one (touched at an edge: the code at a boundary instant is
            // ambiguous). A bin touched only strictly inside the cell cannot
            // occur (the touched set is constant on a cell); it would get one.
            let cap = match x_max {
                Some(x) if w == 0 || x == w => full_cap[k],
                Some(x) if x > 0 => clock.pulses_in(Ratio {
                    num: (x as u128) * d,
                    den: w as u128,
                })?,
                _ => 1,
            };
            energy_all = u128::from(b.power_code)
                .checked_mul(cap)
                .and_then(|x| x.checked_add(energy_all))
                .ok_or(IntEyeError::Overflow)?;
            edges.push((b.power_code, cap));
        }
        let tau = tau0.max(tau1)?;
        visit(&Cell {
            a0,
            tau,
            pulses: clock.pulses_in(tau)?,
            hottest: hot.front().map_or(0, |&f| full[f].0),
            energy_all,
            edge_bins: &edges,
            middle_bins: &full[mid_start..mid_end],
        })?;
    }
    Ok(())
}

fn clock_of(table: &FirmwareTable, millihz: u64) -> Clock {
    Clock {
        millihz: u128::from(millihz),
        tick_hz: u128::from(table.tick_hz),
    }
}

/// The longest pass and the most pulses in one pass, over every aperture
/// azimuth, for a pass arc of `arc_mdeg` and a pulse rate of `millihz`
/// (rounded up) — what [`IntEyeLimits::derive`] needs from the table.
pub fn pass_timing(
    table: &FirmwareTable,
    millihz: u64,
    arc_mdeg: u32,
) -> Result<PassTiming, IntEyeError> {
    check_bounds(table, millihz, arc_mdeg)?;
    let mut t = PassTiming {
        pass_ticks_max: 0,
        pulses_per_pass_max: 0,
    };
    for_each_cell(table, clock_of(table, millihz), arc_mdeg, |c| {
        let ticks = u64::try_from(c.tau.ceil()).map_err(|_| IntEyeError::Overflow)?;
        let pulses = u64::try_from(c.pulses).map_err(|_| IntEyeError::Overflow)?;
        t.pass_ticks_max = t.pass_ticks_max.max(ticks);
        t.pulses_per_pass_max = t.pulses_per_pass_max.max(pulses);
        Ok(())
    })?;
    Ok(t)
}

/// `⌈energy · 10^6 / limit⌉`, saturating.
fn ratio_ppm(energy: u128, limit: u64) -> u64 {
    if energy == 0 {
        return 0;
    }
    if limit == 0 {
        return u64::MAX;
    }
    energy.checked_mul(1_000_000).map_or(u64::MAX, |x| {
        u64::try_from(x.div_ceil(u128::from(limit))).unwrap_or(u64::MAX)
    })
}

/// Evaluates `table` as it will run against `limits`, in integers.
///
/// Every bin touching a pass is capped by its own pulse count, the pass by
/// its total; `G(k)` takes the hottest pulses first, so it bounds the energy
/// of any `k` pulses of the pass (see the module docs). Errors when the
/// table is outside the integer bounds or the limits were derived for
/// another timing.
///
/// With [`IntEyeLimits::instant`] each surface is evaluated against its
/// plain limits and against each instantaneous alternative (its code cap on
/// the table's hottest code, every within-pass bucket raised to its floor),
/// and reports the smallest exact worst ratio: Class 1 when any one accepts.
///
/// With [`IntEyeLimits::other_surface`] the table is evaluated against both
/// limit sets: Class 1 when both accept, the report the worse one's (ties
/// take the first set's).
pub fn evaluate(table: &FirmwareTable, limits: &IntEyeLimits) -> Result<IntEyeReport, IntEyeError> {
    let mut worse = evaluate_surface(table, limits)?;
    let mut class1 = worse.class1;
    let mut next = limits.other_surface.as_deref();
    let mut depth = 1;
    while let Some(other) = next {
        depth += 1;
        if depth > SURFACES_MAX {
            return Err(IntEyeError::Bounds {
                field: "other_surface",
                value: depth as u64,
                reason: "the limits hold at most four aperture surfaces",
            });
        }
        let report = evaluate_surface(table, other)?;
        class1 &= report.class1;
        if report.worst_ratio_ppm > worse.worst_ratio_ppm {
            worse = report;
        }
        next = other.other_surface.as_deref();
    }
    worse.class1 = class1;
    Ok(worse)
}

/// Most aperture surfaces one chain of limits holds: the cylinder and the
/// sphere at 100 mm and at a declared other distance.
pub const SURFACES_MAX: usize = 4;

/// [`evaluate`] against one limit set (one aperture surface).
fn evaluate_surface(
    table: &FirmwareTable,
    limits: &IntEyeLimits,
) -> Result<IntEyeReport, IntEyeError> {
    let mismatch = |field, found, allowed| IntEyeError::Mismatch {
        field,
        found,
        allowed,
    };
    if table.tick_hz != limits.tick_hz {
        return Err(mismatch("tick_hz", table.tick_hz, limits.tick_hz));
    }
    if table.frame_ticks != limits.frame_ticks {
        return Err(mismatch(
            "frame_ticks",
            table.frame_ticks,
            limits.frame_ticks,
        ));
    }
    check_bounds(table, limits.pulse_rate_millihz_ceil, limits.pass_arc_mdeg)?;
    if limits.train.first().map(|t| t.pulses_from) != Some(1)
        || limits.train.windows(2).any(|w| {
            w[0].pulses_from >= w[1].pulses_from || w[0].energy_max_quanta > w[1].energy_max_quanta
        })
    {
        return Err(IntEyeError::Bounds {
            field: "train",
            value: limits.train.len() as u64,
            reason: "buckets must start at 1 pulse, their counts increase and their limits never decrease",
        });
    }
    let (mut best, mut worst) = evaluate_candidate(table, limits, None)?;
    if limits.instant.is_empty() {
        return Ok(best);
    }
    // The hottest bin of the table (its centre's azimuth) for the
    // instantaneous candidates: `P̂` is the table's largest power.
    let mut hottest = (0u64, 0u32);
    let mut start = 0u32;
    for b in &table.bins {
        if u64::from(b.power_code) > hottest.0 {
            hottest = (u64::from(b.power_code), start + b.width_mdeg / 2);
        }
        start += b.width_mdeg;
    }
    for inst in &limits.instant {
        // This candidate's worst is at least its own code check: skip it
        // when that alone cannot beat the best so far.
        if !ratio_greater(worst, (u128::from(hottest.0), inst.code_max)) {
            continue;
        }
        let (r, w) = evaluate_candidate(table, limits, Some((inst, hottest)))?;
        if ratio_greater(worst, w) {
            (best, worst) = (r, w);
        }
    }
    Ok(best)
}

/// The walk of [`evaluate_surface`] over every cell against `limits`, with
/// one instantaneous candidate or none: `(code_max, floor)` and the table's
/// hottest `(code, azimuth)`. Returns the report and its exact worst
/// `(energy, limit)`.
fn evaluate_candidate(
    table: &FirmwareTable,
    limits: &IntEyeLimits,
    instant: Option<(&InstantLimit, (u64, u32))>,
) -> Result<(IntEyeReport, (u128, u64)), IntEyeError> {
    let mismatch = |field, found, allowed| IntEyeError::Mismatch {
        field,
        found,
        allowed,
    };
    let clock = clock_of(table, limits.pulse_rate_millihz_ceil);
    let half = limits.pass_arc_mdeg / 2;
    let mut t = Tracker {
        worst: (0, 1),
        report: IntEyeReport {
            worst_ratio_ppm: 0,
            rule: IntRule::SinglePulse,
            azimuth_mdeg: 0,
            class1: true,
        },
    };
    // With an instantaneous candidate: every window up to its `T*` holds
    // at most `W_inst · P̂ · (T + Δ)` (checked here once, on the hottest
    // code), and every longer one's limit is at least its floor.
    let floor = instant.map_or(0, |(inst, (code, azimuth))| {
        t.note(azimuth, u128::from(code), inst.code_max, IntRule::PassTrain);
        inst.energy_floor_quanta
    });
    let mut sorted: Vec<(u32, u128)> = Vec::new();
    for_each_cell(table, clock, limits.pass_arc_mdeg, |c| {
        if c.tau.num > u128::from(limits.pass_ticks_max) * c.tau.den {
            return Err(mismatch(
                "pass duration (ticks)",
                u64::try_from(c.tau.ceil()).unwrap_or(u64::MAX),
                limits.pass_ticks_max,
            ));
        }
        if c.pulses > u128::from(limits.pulses_per_pass_max) {
            return Err(mismatch(
                "pulses per pass",
                u64::try_from(c.pulses).unwrap_or(u64::MAX),
                limits.pulses_per_pass_max,
            ));
        }
        let azimuth = (c.a0 + i64::from(half)).rem_euclid(i64::from(FULL_TURN_MDEG)) as u32;
        t.note(
            azimuth,
            u128::from(c.hottest),
            limits.pulse_code_max,
            IntRule::SinglePulse,
        );
        let k_max = c.pulses;
        // The bucket ends `to` of every train check, then the pass.
        let buckets = limits
            .train
            .iter()
            .enumerate()
            .take_while(|(_, t)| u128::from(t.pulses_from) <= k_max)
            .map(|(j, t)| {
                let to = limits
                    .train
                    .get(j + 1)
                    .map_or(k_max, |n| (u128::from(n.pulses_from) - 1).min(k_max));
                (to, t.energy_max_quanta.max(floor))
            });
        // A quick upper bound first: G(k) ≤ min(Σ code × cap, k × hottest).
        // If no check can beat the worst ratio so far with it, the exact
        // greedy cannot either (it is never larger), and the cell is done.
        let hot = u128::from(c.hottest);
        let loose = |k: u128| c.energy_all.min(k.saturating_mul(hot));
        let mut loose_worst = (loose(k_max), limits.pass_energy_max_quanta);
        for (to, lim) in buckets.clone() {
            if ratio_greater((loose(to), lim), loose_worst) {
                loose_worst = (loose(to), lim);
            }
        }
        if !ratio_greater(loose_worst, t.worst) {
            return Ok(());
        }
        sorted.clear();
        sorted.extend_from_slice(c.edge_bins);
        sorted.extend_from_slice(c.middle_bins);
        sorted.sort_unstable_by_key(|x| core::cmp::Reverse(x.0));
        // G(k) by a walk over the hottest-first bins.
        let mut walk = Greedy {
            bins: &sorted,
            at: 0,
            used_in_bin: 0,
            pulses: 0,
            energy: 0,
        };
        for (to, lim) in buckets {
            let g = walk.energy_up_to(to)?;
            t.note(azimuth, g, lim, IntRule::PassTrain);
            if walk.exhausted() && g <= u128::from(lim) {
                // G is flat from here and the limits only grow.
                break;
            }
        }
        let e_pass = walk.energy_up_to(k_max)?;
        t.note(
            azimuth,
            e_pass,
            limits.pass_energy_max_quanta,
            limits.pass_energy_rule,
        );
        Ok(())
    })?;
    t.report.worst_ratio_ppm = ratio_ppm(t.worst.0, t.worst.1);
    Ok((t.report, t.worst))
}

/// The worst check so far: `(energy, limit)` compared exactly by
/// cross-multiplication, with its rule and azimuth.
struct Tracker {
    worst: (u128, u64),
    report: IntEyeReport,
}

impl Tracker {
    fn note(&mut self, azimuth_mdeg: u32, energy: u128, limit: u64, rule: IntRule) {
        if energy > u128::from(limit) {
            self.report.class1 = false;
        }
        if ratio_greater((energy, limit), self.worst) {
            self.worst = (energy, limit);
            self.report.rule = rule;
            self.report.azimuth_mdeg = azimuth_mdeg;
        }
    }
}

/// Whether `a.0 / a.1 > b.0 / b.1` (a zero limit with energy is infinite).
fn ratio_greater(a: (u128, u64), b: (u128, u64)) -> bool {
    let ((ea, la), (eb, lb)) = (a, b);
    if ea == 0 {
        return false;
    }
    if la == 0 {
        return !(lb == 0 && eb > 0);
    }
    if eb == 0 {
        return true;
    }
    if lb == 0 {
        return false;
    }
    match (
        ea.checked_mul(u128::from(lb)),
        eb.checked_mul(u128::from(la)),
    ) {
        (Some(x), Some(y)) => x > y,
        _ => ratio_ppm(ea, la) > ratio_ppm(eb, lb),
    }
}

/// `G(k)`: the most quanta `k` pulses can carry when bin `i` (hottest
/// first) holds at most `cap_i` pulses at its code; `k` only grows.
struct Greedy<'a> {
    bins: &'a [(u32, u128)],
    at: usize,
    used_in_bin: u128,
    pulses: u128,
    energy: u128,
}

impl Greedy<'_> {
    fn energy_up_to(&mut self, k: u128) -> Result<u128, IntEyeError> {
        while self.pulses < k && self.at < self.bins.len() {
            let (code, cap) = self.bins[self.at];
            let take = (cap - self.used_in_bin).min(k - self.pulses);
            self.energy = u128::from(code)
                .checked_mul(take)
                .and_then(|e| e.checked_add(self.energy))
                .ok_or(IntEyeError::Overflow)?;
            self.pulses += take;
            self.used_in_bin += take;
            if self.used_in_bin == cap {
                self.at += 1;
                self.used_in_bin = 0;
            }
        }
        Ok(self.energy)
    }

    fn exhausted(&self) -> bool {
        self.at >= self.bins.len()
    }
}

/// Deriving the integer limits from the one eye-safety model (floating
/// point, once per table timing; every limit rounded down).
#[cfg(feature = "std")]
mod derive {
    use super::{
        pass_timing, InstantLimit, IntEyeError, IntEyeLimits, IntRule, TrainLimit, MILLIHZ_PER_HZ,
    };
    use crate::eye_safety::ael::{T2_S, TIME_BASE_S};
    use crate::eye_safety::bound::Laser;
    use crate::eye_safety::exposure::{laser, pass_angle_deg, surfaces};
    use crate::eye_safety::head::bound::{
        head_figures_on, single_pulse_ratio as single_pulse_ratio_head, HeadFigures, SingleFigures,
    };
    use crate::eye_safety::head::geometry::Surface;
    use crate::eye_safety::head::Head;
    use crate::eye_safety::{EyeSafetyError, EyeSafetyParams};
    use crate::firmware::FirmwareTable;
    use alloc::boxed::Box;
    use alloc::vec::Vec;

    /// Relative head-room every limit loses before it is rounded down, so
    /// float rounding in the AEL and the quotient can never raise it.
    pub const LIMIT_MARGIN: f64 = 1e-9;

    /// Relative widening of every float the derivation rounds towards
    /// safety (far above the few ulps of one product or quotient): the pass
    /// arc is widened before it is rounded up to whole millidegrees, and the
    /// shortest durations that can hold `k` pulses or `m` passes are
    /// shortened before the AEL infimum is taken over them, so a rounding
    /// in `pass_angle_deg` or in a tick-to-seconds quotient can never narrow
    /// the arc or lengthen a window (which could raise its smallest AEL).
    pub const WIDEN: f64 = 1e-12;
    /// Within-pass buckets hold one pulse count each up to this count, then
    /// grow by `1/EXACT_PULSE_BUCKETS` of their start (≤ 0.4 % looser).
    pub const EXACT_PULSE_BUCKETS: u64 = 256;
    /// Most multi-pass window counts the derivation walks (frame periods
    /// shorter than 100 s / 10^7 are refused).
    pub const MAX_PASS_WINDOWS: u64 = 10_000_000;
    /// The instantaneous candidate's window lengths `T*`, in multiples of
    /// the longest pass (at least a pulse spacing), below the frame: the
    /// float head bound's ladder (`head::bound::energy_ratios`).
    pub const INSTANT_T_STAR_PASSES: [f64; 7] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 64.0];

    /// Why integer limits could not be derived.
    #[derive(Debug, Clone, PartialEq, thiserror::Error)]
    #[non_exhaustive]
    pub enum DeriveError {
        /// The table has no eye-safety parameters.
        #[error("the table has no eye-safety parameters (not Class 1 evidence)")]
        Missing,
        /// The parameters or the pulse rate are invalid.
        #[error(transparent)]
        Params(#[from] EyeSafetyError),
        /// The table is outside the integer evaluation's bounds.
        #[error(transparent)]
        Int(#[from] IntEyeError),
        /// A derived quantity is out of range.
        #[error("{field}: {reason}")]
        Range {
            /// Which quantity.
            field: &'static str,
            /// Why.
            reason: &'static str,
        },
    }

    /// `⌈f · 1000⌉` exactly for a finite positive `f` (the residual of the
    /// product is exact through a fused multiply-add).
    pub fn millihz_ceil(f_hz: f64) -> Option<u64> {
        let x = f_hz * MILLIHZ_PER_HZ as f64;
        if !(x.is_finite() && x > 0.0 && x < 1.8e19) {
            return None;
        }
        let residual = f_hz.mul_add(MILLIHZ_PER_HZ as f64, -x);
        let c = x.ceil();
        let c = if c == x && residual > 0.0 { c + 1.0 } else { c };
        Some(c as u64)
    }

    /// The limit sets as one chain, the first at the top (each holds the
    /// next in [`IntEyeLimits::other_surface`]); a set equal to an earlier
    /// one is left out (a flat channel from the axis meets the sphere where
    /// it meets the cylinder: one set).
    fn chain(sets: Vec<IntEyeLimits>) -> Result<IntEyeLimits, DeriveError> {
        let mut distinct: Vec<IntEyeLimits> = Vec::with_capacity(sets.len());
        for set in sets {
            if !distinct.contains(&set) {
                distinct.push(set);
            }
        }
        let mut next: Option<Box<IntEyeLimits>> = None;
        for mut set in distinct.into_iter().rev() {
            set.other_surface = next;
            next = Some(Box::new(set));
        }
        next.map(|top| *top).ok_or(DeriveError::Range {
            field: "eye_safety.head",
            reason: "no aperture surface to evaluate",
        })
    }

    impl IntEyeLimits {
        /// Derives the integer limits of `table`'s timing from the one
        /// eye-safety model (`eye_safety::bound::Laser`: Table 3 rows, C5 and
        /// `T_i` groups of rule 1): every limit is the model's AEL for the
        /// shortest window that can hold the counted pulses, divided by the
        /// energy quantum and rounded down after a `LIMIT_MARGIN` cut.
        pub fn derive(table: &FirmwareTable) -> Result<Self, DeriveError> {
            let params = table.eye_safety.as_ref().ok_or(DeriveError::Missing)?;
            match &params.head {
                // A certificate covers both 100 mm surfaces, the cylinder
                // and the sphere; a declared other distance is evaluated
                // too, as the float checker does
                // (`exposure::evaluate_head`): a chain of limit sets, every
                // one must accept ([`evaluate`]).
                Some(h) => {
                    // The surfaces' one owner: `exposure::surfaces` (it
                    // refuses a crossing point with no 100 mm surface
                    // outside it, here named as the table's field).
                    let surfaces = surfaces(h).map_err(|e| match e {
                        EyeSafetyError::Param {
                            field: "head.origin_radius_mm",
                            reason,
                            ..
                        } => DeriveError::Range {
                            field: "eye_safety.head.origin_radius_mm",
                            reason,
                        },
                        e => DeriveError::Params(e),
                    })?;
                    let sets = surfaces
                        .iter()
                        .map(|(h, surface)| Self::derive_at(table, params, Some(h), *surface))
                        .collect::<Result<Vec<_>, _>>()?;
                    chain(sets)
                }
                None => Self::derive_at(table, params, None, Surface::Cylinder),
            }
        }

        /// The limits of one aperture surface (`head.aperture_distance_mm`
        /// from the spin axis; one channel without a head).
        fn derive_at(
            table: &FirmwareTable,
            params: &EyeSafetyParams,
            head: Option<&Head>,
            surface: Surface,
        ) -> Result<Self, DeriveError> {
            let f_p = table.pulse_rate_hz;
            let laser = laser(params, f_p)?;
            let millihz = millihz_ceil(f_p).ok_or(DeriveError::Range {
                field: "pulse_rate_hz",
                reason: "must be finite and > 0",
            })?;
            // The head (absent: one channel): its figures at the table's
            // fastest spin (rounded up: a faster spin only widens the
            // grouping footprints and shortens the windows a separation
            // bounds), its widest pass, and the factors its bound puts on
            // the single-channel figures.
            let tick_hz_f = table.tick_hz as f64;
            let spin_max = table
                .bins
                .iter()
                .filter(|b| b.width_mdeg > 0 && b.dwell_ticks > 0)
                .map(|b| {
                    (f64::from(b.width_mdeg) / 1000.0).to_radians() * tick_hz_f
                        / b.dwell_ticks as f64
                })
                .fold(0.0, f64::max)
                * (1.0 + WIDEN);
            let head = match head {
                None => None,
                Some(h) => Some(head_figures_on(h, surface, params, &laser, spin_max)?),
            };
            let pass_deg = head.as_ref().map_or_else(
                || pass_angle_deg(params, &laser),
                |hf| hf.pass_angle_deg.min(360.0),
            );
            let arc = (pass_deg * 1000.0 * (1.0 + WIDEN)).ceil();
            if !(arc >= 1.0 && arc < f64::from(u32::MAX)) {
                return Err(DeriveError::Range {
                    field: "pass arc",
                    reason: "out of range",
                });
            }
            let arc_mdeg = arc as u32;
            let timing = pass_timing(table, millihz, arc_mdeg)?;
            let step = table.power_w_per_code;
            if let Err(reason) = crate::model::valid::positive(step) {
                return Err(DeriveError::Range {
                    field: "power_w_per_code",
                    reason,
                });
            }
            let quantum_j = step / f_p;
            let to_quanta = |energy_j: f64| -> u64 {
                let x = energy_j / quantum_j * (1.0 - LIMIT_MARGIN);
                if x >= 1.8e19 {
                    u64::MAX
                } else if x > 0.0 {
                    x.floor() as u64
                } else {
                    0
                }
            };
            let k_max = timing.pulses_per_pass_max;
            let tick_hz = table.tick_hz as f64;
            // Rule 1: C5 at the most pulses any T2 window can meet.
            let t2_ticks = (T2_S * tick_hz).ceil() as u128;
            let passes_t2 =
                (t2_ticks + u128::from(timing.pass_ticks_max)) / u128::from(table.frame_ticks) + 1;
            let per_code_one = laser.single_pulse_ratio(quantum_j, k_max as f64, passes_t2 as f64);
            // The head's Rule 1 is `a·r₁ + b·E` (`cuts::HeadScale`): `a`
            // on the single-channel figure, `b` per joule of the hottest
            // pulse, at counts of the longest pass (widened) and the frame
            // (shortened): more pulses, a smaller C5, a larger figure.
            let per_code = match &head {
                None => per_code_one,
                Some(hf) => {
                    let rule_one = |single_pulse_ratio: f64, power_max_w: f64| {
                        single_pulse_ratio_head(
                            hf,
                            &laser,
                            SingleFigures {
                                single_pulse_ratio,
                                pass_duration_s: timing.pass_ticks_max as f64 / tick_hz
                                    * (1.0 + WIDEN),
                                frame_s: table.frame_ticks as f64 / tick_hz * (1.0 - WIDEN),
                                power_max_w,
                            },
                        )
                    };
                    // A pulse of one quantum is `step` W at `f_p`.
                    rule_one(1.0, 0.0) * per_code_one + rule_one(0.0, step)
                }
            };
            // The energy rules: a window of length `T` holds channels of
            // total `power_scale` at most `W*(T)`, the smallest weight any
            // candidate of the head bound (`head::bound::energy_ratios`)
            // proves for that length (`weight_steps`: `W_v`, a separation's
            // `W(L)` up to `L/ω_max`, the firing slots' weights below one
            // cycle), each channel at most the single-channel energy of the
            // window; so the single channel is held to `AEL(T)/W*(T)`.
            let w_v = head.as_ref().map_or(1.0, |hf| hf.weight_vertical);
            let steps = head
                .as_ref()
                .map_or_else(Vec::new, |hf| weight_steps(hf, spin_max));
            let per_weight = PerWeight::new(&laser, &steps, w_v);
            let pulse_code_max = if per_code > 0.0 {
                let x = (1.0 - LIMIT_MARGIN) / per_code;
                if x >= 1.8e19 {
                    u64::MAX
                } else {
                    x.floor() as u64
                }
            } else {
                u64::MAX
            };
            // Rule 2 within a pass: k pulses span at least (k − 1)/f_p, so a
            // window holding them is held to `inf AEL(T)/W*(T)` over
            // `T ≥ (k − 1)/f_p` (shortened).
            let mut train = Vec::new();
            let mut k: u64 = 1;
            loop {
                let t = (k - 1) as f64 / f_p * (1.0 - WIDEN);
                train.push(TrainLimit {
                    pulses_from: k,
                    energy_max_quanta: to_quanta(per_weight.inf_from(t)),
                });
                if k >= k_max {
                    break;
                }
                k += if k < EXACT_PULSE_BUCKETS {
                    1
                } else {
                    k / EXACT_PULSE_BUCKETS
                };
            }
            // Nondecreasing (as `evaluate` requires): each limit lowered to
            // the smallest of the later ones (lowering is the safe side).
            let mut later = u64::MAX;
            for b in train.iter_mut().rev() {
                b.energy_max_quanta = b.energy_max_quanta.min(later);
                later = b.energy_max_quanta;
            }
            // The head's instantaneous-power candidate (`W_inst`, as
            // `head::bound::energy_ratios` takes it, at its `T*` ladder): a
            // code `c` puts at most `W_inst·c·step·(T + Δ)` into a window of
            // `T` (each pulse's energy over the spacing after it), within
            // `AEL(T)` for every `T ≤ T*` (widened) when
            // `c·W_inst·step·S(T*) ≤ 1`; the windows from `T*` (shortened)
            // on are held to `inf AEL(T)/W*(T)` there. Kept where it
            // raises the first bucket (else it cannot loosen anything).
            let mut instant = Vec::new();
            if let Some(hf) = head
                .as_ref()
                .filter(|hf| hf.count_vertical > 1 && hf.weight_instant > 0.0)
            {
                let delta = 1.0 / f_p;
                let tau = (timing.pass_ticks_max as f64 / tick_hz * (1.0 + WIDEN)).max(delta);
                let frame_s = table.frame_ticks as f64 / tick_hz;
                let first = train[0].energy_max_quanta;
                for m in INSTANT_T_STAR_PASSES {
                    let t_star = m * tau;
                    if t_star >= frame_s {
                        break;
                    }
                    let per_code = hf.weight_instant
                        * step
                        * laser.instant_window_factor(t_star * (1.0 + WIDEN));
                    let code_max = if per_code > 0.0 {
                        let x = (1.0 - LIMIT_MARGIN) / per_code;
                        if x >= 1.8e19 {
                            u64::MAX
                        } else {
                            x.floor() as u64
                        }
                    } else {
                        u64::MAX
                    };
                    let energy_floor_quanta =
                        to_quanta(per_weight.inf_from(t_star * (1.0 - WIDEN)));
                    if code_max > 0 && energy_floor_quanta > first {
                        instant.push(InstantLimit {
                            code_max,
                            energy_floor_quanta,
                        });
                    }
                }
            }
            let to_quanta = |energy_j: f64| to_quanta(energy_j / w_v);
            // Rule 2 over m ≥ 2 passes: such a window lasts at least
            // (m − 1)·T_f − τ_max and receives at most m pass energies.
            let frame = u128::from(table.frame_ticks);
            let tau = u128::from(timing.pass_ticks_max);
            let tb_ticks = (TIME_BASE_S * tick_hz).ceil() as u128;
            let m_last = (tb_ticks + tau) / frame + 2;
            if m_last > u128::from(MAX_PASS_WINDOWS) {
                return Err(DeriveError::Range {
                    field: "frame_ticks",
                    reason: "frame period too short for the multi-pass evaluation (over 10^7 passes in 100 s)",
                });
            }
            let mut pass_energy_max_quanta = u64::MAX;
            let mut pass_energy_rule = IntRule::TimeBase;
            for m in 2..=m_last {
                let span = ((m - 1) * frame).saturating_sub(tau);
                let t = span as f64 / tick_hz * (1.0 - WIDEN);
                if t > TIME_BASE_S {
                    break;
                }
                let per_pass = to_quanta(laser.ael_inf_j(t, TIME_BASE_S)) / (m as u64);
                if per_pass < pass_energy_max_quanta {
                    pass_energy_max_quanta = per_pass;
                    pass_energy_rule = if t <= T2_S {
                        IntRule::T2Train
                    } else {
                        IntRule::TimeBase
                    };
                }
            }
            Ok(Self {
                tick_hz: table.tick_hz,
                frame_ticks: table.frame_ticks,
                pulse_rate_millihz_ceil: millihz,
                pass_arc_mdeg: arc_mdeg,
                pass_ticks_max: timing.pass_ticks_max,
                pulses_per_pass_max: k_max,
                pulse_code_max,
                train,
                pass_energy_max_quanta,
                pass_energy_rule,
                instant,
                other_surface: None,
            })
        }
    }

    /// The head's channel weight by window length, as pieces
    /// `(lo_s, hi_s, weight)`: every window whose length lies in
    /// `[lo_s, hi_s)` receives channels of total `power_scale` at most
    /// `weight` (a window of any length at most `W_v`). From the head
    /// bound's candidates (`head::bound::energy_ratios`), the same figures:
    /// - the firing slots (`HeadFigures::slot_windows`): a window shorter
    ///   than one cycle holds one pulse per channel, of the channels of the
    ///   range's weight; the last range ends at `cycle·(1 − 1e-9)`, and a
    ///   longer window is left to `W_v`;
    /// - a separation `L` (`HeadFigures::separations`): a window up to
    ///   `L/ω_max` (shortened by 1e-12, as the float bound does) turns the
    ///   head by at most `L`, so it reaches channels of `W(L)`; `ω_max` is
    ///   the table's fastest spin as it runs, rounded up.
    fn weight_steps(hf: &HeadFigures, spin_max_rad_s: f64) -> Vec<(f64, f64, f64)> {
        let mut steps: Vec<(f64, f64, f64)> = hf
            .slot_windows
            .iter()
            .map(|r| (r.lo_s, r.hi_s, r.weight))
            .collect();
        if spin_max_rad_s > 0.0 {
            for sep in &hf.separations {
                let t_sep = sep.angle_rad / spin_max_rad_s * (1.0 - 1e-12);
                if t_sep.is_finite() && t_sep > 0.0 {
                    // Windows of exactly `t_sep` fall in the next cell
                    // (`W_v`): the safe side.
                    steps.push((0.0, t_sep, sep.weight));
                }
            }
        }
        steps.retain(|&(lo, hi, w)| lo.is_finite() && hi.is_finite() && lo < hi && w >= 0.0);
        steps
    }

    /// `inf AEL(T)/W*(T)` over the window lengths from a given one, with
    /// `W*(T)` the smallest weight of the pieces holding `T` and `W_v`
    /// (`weight_steps`): `W*` is a step function on the pieces' ends, so
    /// the infimum is the smallest of `AEL_inf` over each elementary
    /// interval (closed: its end is also the next one's start) divided by
    /// its weight, and `AEL_inf` from the last end to the time base over
    /// `W_v`.
    struct PerWeight {
        /// Elementary intervals `(lo_s, hi_s, W*)`, increasing.
        cells: Vec<(f64, f64, f64)>,
        /// `AEL_inf(lo, hi)/W*` of each cell, then the suffix minimum.
        suffix: Vec<f64>,
        /// Where `W_v` alone holds on (the last end; 0 without pieces).
        tail_s: f64,
        w_v: f64,
        laser: Laser,
    }

    impl PerWeight {
        fn new(laser: &Laser, steps: &[(f64, f64, f64)], w_v: f64) -> Self {
            let mut ends: Vec<f64> = steps.iter().flat_map(|&(lo, hi, _)| [lo, hi]).collect();
            ends.push(0.0);
            ends.retain(|x| *x >= 0.0);
            ends.sort_by(f64::total_cmp);
            ends.dedup();
            let cells: Vec<(f64, f64, f64)> = ends
                .windows(2)
                .map(|e| {
                    let (lo, hi) = (e[0], e[1]);
                    // A piece holds the whole half-open cell [lo, hi).
                    let w = steps
                        .iter()
                        .filter(|&&(a, b, _)| a <= lo && hi <= b)
                        .map(|&(_, _, w)| w)
                        .fold(w_v, f64::min);
                    (lo, hi, w)
                })
                .collect();
            let tail_s = ends.last().copied().unwrap_or(0.0);
            let mut suffix: Vec<f64> = cells
                .iter()
                .map(|&(lo, hi, w)| laser.ael_inf_j(lo, hi) / w)
                .collect();
            let mut later = f64::INFINITY;
            for x in suffix.iter_mut().rev() {
                *x = x.min(later);
                later = *x;
            }
            Self {
                cells,
                suffix,
                tail_s,
                w_v,
                laser: *laser,
            }
        }

        /// `inf AEL(T)/W*(T)` over `T ≥ t_s`, J per unit weight.
        fn inf_from(&self, t_s: f64) -> f64 {
            let tail = self.laser.ael_inf_j(t_s.max(self.tail_s), TIME_BASE_S) / self.w_v;
            // The first cell reaching past `t_s`: it is cut at `t_s`, every
            // later cell is whole (its suffix minimum).
            match self.cells.iter().position(|&(_, hi, _)| hi >= t_s) {
                None => tail,
                Some(i) => {
                    let (lo, hi, w) = self.cells[i];
                    let first = self.laser.ael_inf_j(lo.max(t_s), hi) / w;
                    let rest = self.suffix.get(i + 1).copied().unwrap_or(f64::INFINITY);
                    first.min(rest).min(tail)
                }
            }
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        /// Limits told apart by their tick rate alone.
        fn set(tick_hz: u64) -> IntEyeLimits {
            IntEyeLimits {
                tick_hz,
                frame_ticks: 1,
                pulse_rate_millihz_ceil: 1,
                pass_arc_mdeg: 1,
                pass_ticks_max: 1,
                pulses_per_pass_max: 1,
                pulse_code_max: 1,
                train: alloc::vec![TrainLimit {
                    pulses_from: 1,
                    energy_max_quanta: 1,
                }],
                pass_energy_max_quanta: 1,
                pass_energy_rule: IntRule::TimeBase,
                instant: Vec::new(),
                other_surface: None,
            }
        }

        /// The tick rates of a chain, top first.
        fn ticks(top: &IntEyeLimits) -> Vec<u64> {
            let mut out = alloc::vec![top.tick_hz];
            let mut at = top.other_surface.as_deref();
            while let Some(l) = at {
                out.push(l.tick_hz);
                at = l.other_surface.as_deref();
            }
            out
        }

        /// `chain` links the distinct sets in their order (a set equal to
        /// an earlier one left out) and refuses an empty list.
        #[test]
        fn a_chain_holds_each_distinct_set_once_in_order() {
            let got = chain(alloc::vec![set(1), set(2), set(1), set(3), set(2)]).unwrap();
            assert_eq!(ticks(&got), [1, 2, 3]);
            assert_eq!(ticks(&chain(alloc::vec![set(7), set(7)]).unwrap()), [7]);
            assert_eq!(
                chain(Vec::new()),
                Err(DeriveError::Range {
                    field: "eye_safety.head",
                    reason: "no aperture surface to evaluate",
                })
            );
        }
    }
}

#[cfg(feature = "std")]
pub use derive::{millihz_ceil, DeriveError, EXACT_PULSE_BUCKETS, LIMIT_MARGIN};

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::firmware::{FwBin, IntLimits, FIRMWARE_FORMAT};
    use crate::model::accounting::PowerAccounting;
    use crate::verification::cover;
    use alloc::borrow::ToOwned;

    /// Most bins a harness table has.
    const HARNESS_BINS: usize = 3;
    /// The unwind bound of the harnesses below. The longest loops of
    /// `for_each_cell` and `evaluate` run once per entry of the bins unrolled
    /// over three turns (`3 · n` ≤ 9: the interval list, its prefix sums, the
    /// `lo`/`hi`/`mid` sweeps and the greedy walk over the touched entries);
    /// the cell loop runs over at most `2 · n` ≤ 6 breakpoints, the train
    /// buckets are 2. Kani needs one more unwinding than the most iterations
    /// (`harness_unwind_covers_the_loops` checks the attributes against it).
    const HARNESS_UNWIND: usize = 3 * HARNESS_BINS + 1;

    /// Up to three raw bins: (width, dwell, code).
    type RawBins = [(u32, u64, u32); HARNESS_BINS];

    /// A table within the format's and the evaluation's bounds: widths sum to
    /// 360,000 mdeg, dwells (each ≥ 1) to `frame_ticks ≤ MAX_FRAME_TICKS`.
    fn table(raw: &RawBins, n: usize, tick_hz: u64, frame_ticks: u64) -> FirmwareTable {
        let mut width_left = FULL_TURN_MDEG;
        let mut ticks_left = frame_ticks;
        let bins = (0..n)
            .map(|i| {
                let (w, d, code) = raw[i];
                let last = i + 1 == n;
                let bins_after = (n - 1 - i) as u64;
                let width_mdeg = if last {
                    width_left
                } else {
                    w % (width_left + 1)
                };
                let dwell_ticks = if last {
                    ticks_left
                } else {
                    1 + d % (ticks_left - bins_after)
                };
                width_left -= width_mdeg;
                ticks_left -= dwell_ticks;
                FwBin {
                    start_deg: 0.0,
                    width_mdeg,
                    dwell_ticks,
                    power_code: code,
                    dwell_ticks_min: 0,
                    dwell_ticks_max: u64::MAX,
                    power_code_cap: u32::MAX,
                }
            })
            .collect();
        FirmwareTable {
            format: FIRMWARE_FORMAT.to_owned(),
            tick_hz,
            frame_ticks,
            power_w_per_code: 1.0,
            power_accounting: PowerAccounting::Time,
            pulse_rate_hz: 1.0,
            eye_safety: None,
            limits: IntLimits {
                power_code_min: 0,
                power_code_max: u32::MAX,
                energy_budget: u64::MAX,
                window_bins: 1,
                window_energy_max: u64::MAX,
            },
            bins,
        }
    }

    fn limits(
        t: &FirmwareTable,
        millihz: u64,
        arc_mdeg: u32,
        l: (u64, u64, u64, u64),
    ) -> IntEyeLimits {
        let (code_max, e1, split, e_pass) = l;
        IntEyeLimits {
            tick_hz: t.tick_hz,
            frame_ticks: t.frame_ticks,
            pulse_rate_millihz_ceil: millihz,
            pass_arc_mdeg: arc_mdeg,
            pass_ticks_max: u64::MAX,
            pulses_per_pass_max: u64::MAX,
            pulse_code_max: code_max,
            train: alloc::vec![
                TrainLimit {
                    pulses_from: 1,
                    energy_max_quanta: e1,
                },
                TrainLimit {
                    pulses_from: 2 + split,
                    energy_max_quanta: e1.saturating_add(split),
                },
            ],
            pass_energy_max_quanta: e_pass,
            pass_energy_rule: IntRule::T2Train,
            // One instantaneous alternative (its code cap at the Rule 1
            // cap, its floor above the second bucket): the walk with a
            // floor and the choice of the smaller worst are exercised too.
            instant: alloc::vec![InstantLimit {
                code_max,
                energy_floor_quanta: e1.saturating_add(split).saturating_add(1),
            }],
            other_surface: None,
        }
    }

    /// `sets` as one chain of limits, the first at the top (each holds the
    /// next in `other_surface`), equal sets kept.
    fn chained(sets: &[IntEyeLimits]) -> IntEyeLimits {
        let mut next: Option<alloc::boxed::Box<IntEyeLimits>> = None;
        for set in sets.iter().rev() {
            let mut set = set.clone();
            set.other_surface = next;
            next = Some(alloc::boxed::Box::new(set));
        }
        *next.expect("at least one set")
    }

    /// [`evaluate`] over a chain of limit sets (a head's aperture surfaces):
    /// Class 1 only when every set accepts, in either order; the report is
    /// the set's with the largest worst ratio, the first one's on a tie (two
    /// sets whose binding pass-energy rule is named differently); a chain of
    /// [`SURFACES_MAX`] sets is evaluated, a longer one refused naming
    /// `other_surface`.
    #[test]
    fn a_chain_of_surfaces_takes_every_set_and_reports_the_worst() {
        let t = table(
            &[(120_000, 10, 5), (120_000, 10, 5), (120_000, 10, 5)],
            3,
            1_000,
            30,
        );
        let (millihz, arc) = (1_000_000, 10_000);
        let accepts = limits(&t, millihz, arc, (100, 1_000, 1, 1_000_000));
        // Code 5 over a Rule 1 cap of 4.
        let rejects = limits(&t, millihz, arc, (4, 1_000, 1, 1_000_000));
        let alone = |l: &IntEyeLimits| evaluate(&t, l).unwrap();
        let (ok, bad) = (alone(&accepts), alone(&rejects));
        assert!(ok.class1 && !bad.class1, "{ok:?} {bad:?}");
        assert!(bad.worst_ratio_ppm > ok.worst_ratio_ppm);
        for sets in [
            [accepts.clone(), rejects.clone()],
            [rejects.clone(), accepts.clone()],
        ] {
            let r = evaluate(&t, &chained(&sets)).unwrap();
            assert_eq!(r, bad, "{sets:?}");
        }
        let both = evaluate(&t, &chained(&[accepts.clone(), accepts.clone()])).unwrap();
        assert_eq!(both, ok);
        // A tie: the pass energy binds both sets at one ratio, their rules
        // named apart.
        let t2 = limits(&t, millihz, arc, (100, 1_000, 1, 1));
        let mut tb = t2.clone();
        tb.pass_energy_rule = IntRule::TimeBase;
        let (r2, rb) = (alone(&t2), alone(&tb));
        assert_eq!(r2.worst_ratio_ppm, rb.worst_ratio_ppm);
        assert_eq!((r2.rule, rb.rule), (IntRule::T2Train, IntRule::TimeBase));
        assert_eq!(
            evaluate(&t, &chained(&[t2.clone(), tb.clone()])).unwrap(),
            r2
        );
        assert_eq!(evaluate(&t, &chained(&[tb, t2])).unwrap(), rb);
        // The chain's length.
        let most = alloc::vec![accepts.clone(); SURFACES_MAX];
        assert_eq!(evaluate(&t, &chained(&most)).unwrap(), ok);
        let over = alloc::vec![accepts; SURFACES_MAX + 1];
        match evaluate(&t, &chained(&over)) {
            Err(IntEyeError::Bounds { field, value, .. }) => {
                assert_eq!((field, value), ("other_surface", SURFACES_MAX as u64 + 1));
            }
            r => panic!("a chain of {} sets: {r:?}", SURFACES_MAX + 1),
        }
    }

    type OverflowInput = (RawBins, u8, u64, u64, u64, u32, u8, (u64, u64, u64, u64));

    /// Evaluates one table at the bounds; returns (extreme three-bin table, class 1).
    fn no_overflow(input: OverflowInput) -> (bool, bool) {
        let (raw, n, tick, frame, millihz, arc, extreme, l) = input;
        let n = 1 + usize::from(n) % HARNESS_BINS;
        // Bounds of the evaluation (`check_bounds`): every value within them.
        let mut tick_hz = 1 + tick % MAX_TICK_HZ;
        let mut frame_ticks = n as u64 + frame % (MAX_FRAME_TICKS - n as u64 + 1);
        let mut millihz = 1 + millihz % MAX_PULSE_RATE_MILLIHZ;
        let mut raw = raw;
        if extreme % 2 == 1 {
            // The corner that maximizes every product: the fastest tick,
            // the longest frame, the fastest pulse clock, the largest codes.
            tick_hz = MAX_TICK_HZ;
            frame_ticks = MAX_FRAME_TICKS;
            millihz = MAX_PULSE_RATE_MILLIHZ;
            for r in &mut raw {
                r.2 = u32::MAX;
            }
        }
        // The joint bound: fewer than MAX_PULSES_PER_TURN pulses per turn.
        let allowed =
            (u128::from(MAX_PULSES_PER_TURN) * u128::from(MILLIHZ_PER_HZ) * u128::from(tick_hz)
                - 1)
                / u128::from(frame_ticks);
        // ≥ 62 mHz even at 1 Hz ticks and the longest frame.
        let drawn = millihz;
        millihz = millihz
            .min(u64::try_from(allowed).unwrap_or(u64::MAX))
            .max(1);
        // The assumption "fewer than 2^40 pulses per turn" is active (the
        // clamp lowered the drawn rate), so the corner it bounds is reached.
        cover!(millihz < drawn, "pulse rate clamped to the per-turn bound");
        let arc_mdeg = 1 + arc % (FULL_TURN_MDEG / 2 - 1);
        let t = table(&raw, n, tick_hz, frame_ticks);
        let lim = limits(&t, millihz, arc_mdeg, l);
        let class1 = match evaluate(&t, &lim) {
            Ok(r) => r.class1,
            Err(e) => panic!("a table within the bounds must evaluate: {e}"),
        };
        let timing = pass_timing(&t, millihz, arc_mdeg);
        assert!(timing.is_ok(), "{timing:?}");
        (extreme % 2 == 1 && n == 3, class1)
    }

    /// REQ-FW-5: the integer eye-safety sums (rational pass durations,
    /// pulse counts, `code × count` window sums in `u128`) never overflow for
    /// any table within the format's bounds: 1–36,000 bins (the evaluation
    /// is per cell, so three bins exercise every product), any `u32` code,
    /// `frame_ticks ≤ 2^44`, `tick_hz ≤ 2^34`, pulse rate ≤ 2^40 mHz and
    /// fewer than 2^40 pulses per turn.
    #[cfg_attr(kani, kani::proof, kani::unwind(10))]
    #[cfg_attr(not(kani), test)]
    fn eye_sums_never_overflow_within_format_bounds() {
        crate::for_all!(OverflowInput, |x| {
            let (extreme3, class1) = no_overflow(x);
            cover!(extreme3, "extreme three-bin table evaluated");
            cover!(!class1, "a table over its limits evaluated");
            cover!(class1, "a table within its limits evaluated");
        });
        #[cfg(not(kani))]
        {
            crate::verification::assert_covered(&[
                "pulse rate clamped to the per-turn bound",
                "extreme three-bin table evaluated",
                "a table over its limits evaluated",
                "a table within its limits evaluated",
            ]);
        }
    }

    type RotationInput = ([(u16, u16, u16); 3], u8, u8, u16, u16, (u16, u16, u8, u16));

    /// Returns (non-zero shift, three bins, class 1).
    fn rotation_keeps_verdict(input: RotationInput) -> (bool, bool, bool) {
        let (raw, n, shift, millihz, arc, (code_max, e1, split, e_pass)) = input;
        let n = 1 + usize::from(n) % HARNESS_BINS;
        let raw3: RawBins = [0, 1, 2].map(|i| {
            (
                u32::from(raw[i].0) * 8,
                u64::from(raw[i].1),
                u32::from(raw[i].2 % 64),
            )
        });
        let t = table(&raw3, n, 1000, 3 + 100 * n as u64);
        let millihz = 1_000 + u64::from(millihz) * 100;
        let arc_mdeg = 1 + u32::from(arc) * 2;
        let l = (
            u64::from(code_max % 80),
            u64::from(e1 % 400),
            u64::from(split % 8),
            u64::from(e_pass % 2000),
        );
        let mut rotated = t.clone();
        rotated.bins.rotate_left(usize::from(shift) % n);
        let a = evaluate(&t, &limits(&t, millihz, arc_mdeg, l)).expect("within bounds");
        let b = evaluate(&rotated, &limits(&rotated, millihz, arc_mdeg, l)).expect("within bounds");
        assert_eq!(a.class1, b.class1);
        assert_eq!(a.worst_ratio_ppm, b.worst_ratio_ppm);
        (usize::from(shift) % n != 0, n == 3, a.class1)
    }

    /// REQ-FW-5: a cyclic rotation of a table (where the turn starts) keeps
    /// the integer eye-safety verdict and its worst ratio: the aperture cells
    /// are the same arcs, shifted.
    #[cfg_attr(kani, kani::proof, kani::unwind(10))]
    #[cfg_attr(not(kani), test)]
    fn rotation_keeps_integer_verdict() {
        crate::for_all!(RotationInput, |x| {
            let (shifted, three, class1) = rotation_keeps_verdict(x);
            cover!(shifted, "a table rotated by a non-zero shift");
            cover!(!class1 && three, "a rejected three-bin table rotated");
            cover!(class1 && three, "an accepted three-bin table rotated");
        });
        #[cfg(not(kani))]
        {
            crate::verification::assert_covered(&[
                "a table rotated by a non-zero shift",
                "a rejected three-bin table rotated",
                "an accepted three-bin table rotated",
            ]);
        }
    }

    /// The harnesses' unwind bounds cover their loops: each is at least
    /// `HARNESS_UNWIND` (one more than the `3 · HARNESS_BINS` iterations of
    /// the longest loop), and the tables they build never have more bins.
    #[test]
    fn harness_unwind_covers_the_loops() {
        let src = include_str!("eye.rs");
        for name in [
            "eye_sums_never_overflow_within_format_bounds",
            "rotation_keeps_integer_verdict",
        ] {
            let at = src.find(&alloc::format!("fn {name}()")).expect(name);
            let attr = src[..at].rfind("kani::unwind(").expect(name) + "kani::unwind(".len();
            let bound: usize = src[attr..]
                .split(')')
                .next()
                .and_then(|x| x.parse().ok())
                .expect(name);
            assert!(
                bound >= HARNESS_UNWIND,
                "{name}: unwind({bound}) < {HARNESS_UNWIND}"
            );
        }
        // The unrolled loop really is 3·n long for the largest harness table.
        let t = table(&[(1, 1, 1); HARNESS_BINS], HARNESS_BINS, 1000, 3 * 100);
        assert_eq!(t.bins.len(), HARNESS_BINS);
        let mut cells = 0usize;
        for_each_cell(&t, clock_of(&t, 1000), 10, |_| {
            cells += 1;
            Ok(())
        })
        .unwrap();
        assert!(cells <= 2 * HARNESS_BINS && 3 * HARNESS_BINS < HARNESS_UNWIND);
    }
}
