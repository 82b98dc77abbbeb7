//! Step 3 of the head's argument: the head's figures per rule, from the
//! single-channel bound and the overlap weights (`specs/eye_safety.md`,
//! "The head").
//!
//! Every channel fires once per cycle, so the profile's `pulse_rate_hz` is
//! the per-channel rate (checked: `|pulse_rate_hz·cycle_s − 1| ≤ 1e-9`) and
//! one channel's pulses through the aperture are a single-channel train of
//! pulse energy `s_c·P(θ)/f_p`. The single-channel bound is evaluated once,
//! with the widest pass of the channels ([`HeadFigures::pass_angle_deg`]):
//! a narrower pass receives a subset of a wider one's pulses, at every
//! azimuth, clock phase and window.
//!
//! - **Energy rules** (windows within a pass, whole passes, several passes,
//!   the time base) are sums of pulse energies, linear in each channel's
//!   energies: at an aperture at height `z` only the channels whose height
//!   interval holds `z` can contribute, each at most `s_c ×` the
//!   single-channel energy of the same window, so the head's ratio is at
//!   most `W_v ×` the single-channel ratio ([`HeadFigures::weight_vertical`]).
//! - **Rule 1**: an effective pulse at one position is the pulses of the
//!   channels whose boxes share it, fired together (`W_sim`, compared with
//!   the AEL at the pulse duration) or within one grouping window (`W_g`,
//!   compared with the smallest AEL up to the window plus a pulse), each of
//!   energy at most `s_c·P̂/f_p`, and C5 taken at
//!   `N_head = min(K_v × N_single, S_v × N_union)` effective pulses (the most
//!   pulses one channel can put into one aperture within `T_max`, times the
//!   most channels that can meet one height; or the most distinct firing
//!   slots among those channels times one clock's instants inside the
//!   channels' union of passes, `k` widest passes long: pulses fired at one
//!   instant are one effective pulse; C5 is nonincreasing in N, so an upper
//!   bound of N is conservative).
//!   When at most one channel can meet any height (`K_v = 1`) and no
//!   grouping window puts two channels into one position, every effective
//!   pulse is one channel's: the single-channel Rule 1 figure times the
//!   largest `s_c`.
//!
//! A 1-channel head is the single-channel bound times 1.0: the same bits.

use serde::Serialize;
use std::sync::{Arc, Mutex, OnceLock};

use super::geometry::{footprints_on, Footprint, Surface};
use super::overlap;
use super::Head;
use crate::eye_safety::ael;
use crate::eye_safety::bound::{max_pulses_in, passes_in_window, Laser, RATIO_MARGIN};
use crate::eye_safety::{EyeSafetyError, EyeSafetyParams};

/// Tolerance of `pulse_rate_hz · cycle_s = 1`.
pub const RATE_CYCLE_TOLERANCE: f64 = 1e-9;

/// The head's overlap figures: how many channels, and how much power, can
/// meet one aperture position, over a sweep and at once.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeadFigures {
    /// The aperture surface these figures are for (serialized only for the
    /// sphere: a cylinder report reads as before surfaces were named).
    #[serde(skip_serializing_if = "Surface::is_cylinder")]
    pub surface: Surface,
    /// The surface's radius, mm: the Condition 3 100 mm, or the distance the
    /// head declares (serialized only when not 100 mm: a 100 mm report
    /// reads as before distances were named).
    #[serde(skip_serializing_if = "is_condition_3_distance")]
    pub aperture_distance_mm: f64,
    /// Channels of the head.
    pub channels: u32,
    /// Channels meeting the worst height (where `weight_vertical` is).
    pub channels_at_worst: u32,
    /// Height of the worst aperture position (energy rules), mm.
    pub worst_height_mm: f64,
    /// Head-frame azimuth of the worst position for Rule 1 (the largest
    /// group), deg.
    pub worst_azimuth_deg: f64,
    /// Height of that Rule 1 position, mm.
    pub group_height_mm: f64,
    /// `W_v`: the largest sum of `power_scale` over the channels that can
    /// meet one height during a sweep (multiplies the energy rules).
    pub weight_vertical: f64,
    /// `K_v`: the most channels that can meet one height.
    pub count_vertical: u32,
    /// `S_v`: the most distinct firing slots among the channels that can
    /// meet one height (pulses of one slot reach an aperture at one instant:
    /// one effective pulse for C5's count).
    pub slots_vertical: u32,
    /// `k`: the channels' passes over one aperture position lie inside one
    /// arc of head turn of at most `k` widest passes (the spread of the
    /// channels' hit angles plus the widest pass, over the widest pass,
    /// rounded up).
    pub union_passes: u32,
    /// `W_sim`: the largest sum of `power_scale` of channels fired together
    /// whose footprints share a point.
    pub weight_simultaneous: f64,
    /// Channels fired together that share that point.
    pub count_simultaneous: u32,
    /// `W_g`: the largest `Σ power_scale × pulses` one position receives
    /// within one grouping window (`group_window_s`), footprints widened by
    /// the head's turn over it at the fastest spin.
    pub weight_group: f64,
    /// Channels in that group.
    pub count_group: u32,
    /// Whether some position receives pulses fired at two different times
    /// within one grouping window.
    pub group_spans_time: bool,
    /// The grouping window, s: `T_i` in 700–1050 nm (pulses up to `T_i`
    /// long), else the pulse duration.
    pub group_window_s: f64,
    /// `W_inst`: the largest `Σ power_scale` of channels in their pass at
    /// one instant (boxes widened by the head's turn over one pulse
    /// spacing): the head's received power is at most `W_inst·P̂`.
    pub weight_instant: f64,
    /// `W_disc`: the largest sum of `power_scale` of channels whose
    /// footprints share a point (a stalled rotor: every channel's pulses).
    pub weight_stalled: f64,
    /// Channels sharing that point.
    pub count_stalled: u32,
    /// `W_g` with the head stopped (no widening).
    pub weight_stalled_group: f64,
    /// `W_sim` with the head stopped.
    pub weight_stalled_simultaneous: f64,
    /// Channels fired together sharing one point, the head stopped.
    pub count_stalled_simultaneous: u32,
    /// Whether a stopped head puts pulses of two times in one position
    /// within one grouping window.
    pub stalled_group_spans_time: bool,
    /// Widest footprint (beam only) at the aperture, mm.
    pub footprint_max_mm: f64,
    /// Widest pass angle of the channels (aperture plus footprint over
    /// `R·cos β`), deg, not clamped.
    pub pass_angle_deg: f64,
    /// The largest `power_scale`.
    pub power_scale_max: f64,
    /// Azimuth separations of the channels' passes (see [`energy_ratios`]):
    /// for a head turn of at most `angle_rad` within a window, the most
    /// weight of channels whose passes over one aperture position such a
    /// turn can reach.
    pub separations: Vec<Separation>,
    /// Windows shorter than one firing cycle, by the slots they can hold
    /// (see [`slot_windows`]); empty when at most one channel meets any
    /// height or the enumeration is over its budget.
    #[serde(skip)]
    pub slot_windows: Vec<SlotWindow>,
}

/// Whether `r_mm` is Condition 3's 100 mm (for serialization).
#[allow(clippy::float_cmp, clippy::trivially_copy_pass_by_ref)]
fn is_condition_3_distance(r_mm: &f64) -> bool {
    *r_mm == 100.0
}

/// The channels a window shorter than one firing cycle can receive, by its
/// length: every window of length `T` in `[lo_s, hi_s)` receives pulses of
/// total `power_scale` at most `weight`, one pulse per channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlotWindow {
    /// Shortest window length of the range, s.
    pub lo_s: f64,
    /// The range's end (excluded), s.
    pub hi_s: f64,
    /// The most `Σ power_scale` of channels meeting one height whose slots
    /// a window of that length can hold.
    pub weight: f64,
}

/// Most window-length ranges of [`slot_windows`].
pub const SLOT_WINDOWS_MAX: usize = 64;

/// Most `heights × window starts × channels` steps [`slot_windows`] takes
/// (beyond it the candidate is not formed: a looser bound, never an
/// unsound one).
pub const SLOT_WINDOWS_BUDGET: usize = 1 << 22;

/// The slot-window figures of a head (`specs/eye_safety.md`, "The head",
/// Short windows): a window shorter than the cycle holds at most one pulse
/// of each channel; the channels the aperture at height `z` can receive
/// are those whose height interval holds `z` (any head angle, so no turn
/// needs widening); slid to start at one of its pulses (channel `a`, an
/// instant `slot_a + k·cycle`), a window of length `T` holds the channels
/// with `(slot_c − slot_a) mod cycle ≤ T`. With `B` the sorted distinct
/// differences (those within ε/4 of the previous one dropped, subsampled to
/// at most [`SLOT_WINDOWS_MAX`]) and `ε` =
/// 1e-9 cycle, every `T` in `[B_j − ε, B_{j+1} − ε)` holds only channels
/// whose computed difference is below `B_{j+1} − ε/2` (the differences err
/// by a few ulps of the cycle), so its weight is the most `Σ s_c` of those
/// over every height lower end and every start; the last range ends at
/// `cycle·(1 − 1e-9)`, below which no channel fires twice.
#[must_use]
pub fn slot_windows(
    fps: &[Footprint],
    scales: &[f64],
    slots: &[f64],
    cycle_s: f64,
) -> Vec<SlotWindow> {
    let iv: Vec<(f64, f64)> = fps
        .iter()
        .map(|f| {
            (
                f.z_mm - f.half_height_mm - overlap::TOUCH_MM,
                f.z_mm + f.half_height_mm + overlap::TOUCH_MM,
            )
        })
        .collect();
    let n = iv.len();
    let mut distinct: Vec<f64> = slots.to_vec();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    if n.saturating_mul(n).saturating_mul(distinct.len()) > SLOT_WINDOWS_BUDGET {
        return Vec::new();
    }
    let diff = |c: f64, a: f64| {
        let d = c - a;
        if d < 0.0 {
            d + cycle_s
        } else {
            d
        }
    };
    let mut b: Vec<f64> = Vec::new();
    for &a in &distinct {
        for &c in &distinct {
            b.push(diff(c, a));
        }
    }
    b.sort_by(f64::total_cmp);
    // Differences one rounding apart are one (the first kept): the ranges
    // hold for any increasing `B` from 0, only their tightness needs the
    // differences.
    let eps = 1e-9 * cycle_s;
    b.dedup_by(|later, kept| *later - *kept <= 0.25 * eps);
    if b.len() > SLOT_WINDOWS_MAX {
        let m = b.len();
        b = (0..SLOT_WINDOWS_MAX)
            .map(|k| b[k * (m - 1) / (SLOT_WINDOWS_MAX - 1)])
            .collect();
    }
    let t_cut = cycle_s * (1.0 - 1e-9);
    // Range j: [B_j − ε, B_{j+1} − ε) (the first from 0, the last to t_cut),
    // holding differences below `below_j` = B_{j+1} − ε/2 (+∞ for the last).
    let mut ranges: Vec<(f64, f64, f64)> = Vec::new();
    for j in 0..b.len() {
        let lo = if j == 0 { 0.0 } else { b[j] - eps };
        let (hi, below) = if j + 1 < b.len() {
            (b[j + 1] - eps, b[j + 1] - 0.5 * eps)
        } else {
            (t_cut, f64::INFINITY)
        };
        if lo < hi.min(t_cut) {
            ranges.push((lo, hi.min(t_cut), below));
        }
    }
    let mut weight = vec![0.0f64; ranges.len()];
    let mut at: Vec<(f64, f64, usize)> = Vec::with_capacity(n);
    // The channels meeting each height lower end; a set met at several
    // heights gives the same weights, so each set is taken once (the
    // weights are a maximum over sets).
    let mut sets: Vec<Vec<usize>> = iv
        .iter()
        .map(|&(z, _)| (0..n).filter(|&i| iv[i].0 <= z && z <= iv[i].1).collect())
        .collect();
    sets.sort_unstable();
    sets.dedup();
    let mut by_slot: Vec<usize> = Vec::with_capacity(n);
    for members in &sets {
        // The members by slot (then index): from a start `a` the slots at
        // or after it, then those before it, are the differences in order
        // (the sort below then only confirms a sorted run); differences in
        // ascending order, ties by index (as a stable sort of the members in
        // index order gives them).
        by_slot.clear();
        by_slot.extend_from_slice(members);
        by_slot.sort_by(|&i, &j| slots[i].total_cmp(&slots[j]).then(i.cmp(&j)));
        let mut starts: Vec<f64> = by_slot.iter().map(|&i| slots[i]).collect();
        starts.dedup();
        for &a in &starts {
            let first = by_slot.partition_point(|&i| slots[i] < a);
            at.clear();
            at.extend(
                by_slot[first..]
                    .iter()
                    .chain(&by_slot[..first])
                    .map(|&i| (diff(slots[i], a), scales[i], i)),
            );
            at.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
            let (mut k, mut sum, mut terms) = (0usize, 0.0f64, 0u32);
            for (j, r) in ranges.iter().enumerate() {
                while k < at.len() && at[k].0 < r.2 {
                    sum += at[k].1;
                    terms += 1;
                    k += 1;
                }
                let w = if terms > 1 {
                    sum * (1.0 + overlap::SUM_MARGIN)
                } else {
                    sum
                };
                weight[j] = weight[j].max(w);
            }
        }
    }
    ranges
        .iter()
        .zip(weight)
        .map(|(r, weight)| SlotWindow {
            lo_s: r.0,
            hi_s: r.1,
            weight,
        })
        .collect()
}

/// One head-turn bound of the channels a window can reach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Separation {
    /// Head turn, rad (just below a gap between two channels' passes).
    pub angle_rad: f64,
    /// `W(L)`: the largest `Σ power_scale` of channels meeting one height
    /// whose passes over one position a turn of `angle_rad` reaches.
    pub weight: f64,
    /// Channels there.
    pub count: u32,
}

/// Most separations evaluated (the largest gaps, evenly sampled).
pub const SEPARATIONS_MAX: usize = 8;

fn separations(fps: &[Footprint], scales: &[f64], r_mm: f64, cycle_s: f64) -> Vec<Separation> {
    let circ = core::f64::consts::TAU * r_mm;
    let x = |f: &Footprint| f.psi_rad * r_mm;
    let mut gaps: Vec<f64> = Vec::new();
    for c in fps {
        for d in fps {
            let z_meet = (c.z_mm - d.z_mm).abs() <= c.half_height_mm + d.half_height_mm;
            let g = (x(d) - d.half_arc_mm) - (x(c) + c.half_arc_mm);
            if z_meet && g > 0.0 {
                gaps.push(g / r_mm);
            }
        }
    }
    gaps.sort_by(f64::total_cmp);
    gaps.dedup();
    let picked: Vec<f64> = if gaps.len() <= SEPARATIONS_MAX {
        gaps
    } else {
        (0..SEPARATIONS_MAX)
            .map(|k| gaps[(k * (gaps.len() - 1)) / (SEPARATIONS_MAX - 1)])
            .collect()
    };
    let zeros = vec![0.0; fps.len()];
    picked
        .into_iter()
        .map(|g| {
            let angle_rad = g * (1.0 - 1e-9);
            let smear = r_mm * angle_rad * (1.0 + overlap::SUM_MARGIN);
            let (m, _) = overlap::group(fps, scales, &zeros, cycle_s, 0.0, smear, circ);
            Separation {
                angle_rad,
                weight: m.weight,
                count: m.count,
            }
        })
        .collect()
}

/// The head's energy-rule ratios (within a pass, several passes, the time
/// base; indices 1–3 of the rule order), from the single-channel ratios
/// `single` (margin applied) at the head's widest pass.
///
/// Every window holds at most the channels meeting one height, each at
/// most its single-channel energy: `W_v ×` each figure. Tighter, for a head
/// turn `L` ([`Separation`]): a window no longer than `L/ω_max` turns the
/// head by at most `L`, so only the channels whose passes a turn of `L`
/// reaches contribute (`W(L) ×` each single-channel figure), and every
/// longer window is bounded by `W_v ×` the multi-pass bounds from
/// `L/ω_max` on (`Laser::windows_from_ratio`). The smallest of these
/// maxima over the separations is returned, with the longer windows'
/// figure reported under the rule of its duration.
#[must_use]
pub fn energy_ratios(
    h: &HeadFigures,
    laser: &Laser,
    single: [f64; 4],
    pass: crate::eye_safety::bound::PassFigures,
    frame_s: f64,
    power_max_w: f64,
    spin_max_rad_s: f64,
) -> [f64; 4] {
    let w = h.weight_vertical;
    let mut best = [0.0, w * single[1], w * single[2], w * single[3]];
    let peak = |r: &[f64; 4]| r[1].max(r[2]).max(r[3]);
    for sep in &h.separations {
        if sep.weight >= w || spin_max_rad_s <= 0.0 {
            continue;
        }
        let t_sep = sep.angle_rad / spin_max_rad_s * (1.0 - 1e-12);
        let (r_long, t_long) = laser.windows_from_ratio(frame_s, pass, power_max_w, t_sep);
        let mut cand = [
            0.0,
            sep.weight * single[1],
            sep.weight * single[2],
            sep.weight * single[3],
        ];
        let k = match crate::eye_safety::Rule::for_duration(t_long, frame_s) {
            crate::eye_safety::Rule::PassTrain | crate::eye_safety::Rule::SinglePulse => 1,
            crate::eye_safety::Rule::T2Train => 2,
            crate::eye_safety::Rule::TimeBase => 3,
        };
        cand[k] = cand[k].max(w * r_long * (1.0 + RATIO_MARGIN));
        if peak(&cand) < peak(&best) {
            best = cand;
        }
    }
    // Windows shorter than a cycle by the slots they can hold (one pulse
    // of at most `s_c·P̂/f_p` per channel, `SlotWindow::weight` of them
    // against the smallest AEL of the range), longer ones by `W_v ×` the
    // multi-pass bounds from the last range's end.
    if h.count_vertical > 1 && power_max_w > 0.0 {
        if let Some(last) = h.slot_windows.last() {
            let e_pulse = power_max_w / laser.pulse_rate_hz;
            let short = h
                .slot_windows
                .iter()
                .map(|r| r.weight * e_pulse / laser.ael_inf_j(r.lo_s, r.hi_s))
                .fold(0.0, f64::max)
                * (1.0 + RATIO_MARGIN);
            let (r_long, t_long) = laser.windows_from_ratio(frame_s, pass, power_max_w, last.hi_s);
            let mut cand = [0.0, short, 0.0, 0.0];
            let k = match crate::eye_safety::Rule::for_duration(t_long, frame_s) {
                crate::eye_safety::Rule::PassTrain | crate::eye_safety::Rule::SinglePulse => 1,
                crate::eye_safety::Rule::T2Train => 2,
                crate::eye_safety::Rule::TimeBase => 3,
            };
            cand[k] = cand[k].max(w * r_long * (1.0 + RATIO_MARGIN));
            if peak(&cand) < peak(&best) {
                best = cand;
            }
        }
    }
    // The head's received power is at most `W_inst·P̂` at any instant, so a
    // window of `T` holds at most `W_inst·P̂·(T + Δ)` (each pulse's energy
    // in the pulse spacing after it, disjoint per channel); windows up to
    // `T*` by that, longer ones by `W_v ×` the multi-pass bounds from `T*`.
    if h.count_vertical > 1 && power_max_w > 0.0 {
        let delta = 1.0 / laser.pulse_rate_hz;
        let tau = pass.duration_s.max(delta);
        for m in [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 64.0] {
            let t_star = m * tau;
            if t_star >= frame_s {
                break;
            }
            // sup over T ≤ T* of (T + Δ)/AEL(T).
            let short = laser.instant_window_factor(t_star);
            let short = h.weight_instant * power_max_w * short * (1.0 + RATIO_MARGIN);
            let (r_long, t_long) = laser.windows_from_ratio(frame_s, pass, power_max_w, t_star);
            let mut cand = [0.0, short, 0.0, 0.0];
            let k = match crate::eye_safety::Rule::for_duration(t_long, frame_s) {
                crate::eye_safety::Rule::PassTrain | crate::eye_safety::Rule::SinglePulse => 1,
                crate::eye_safety::Rule::T2Train => 2,
                crate::eye_safety::Rule::TimeBase => 3,
            };
            cand[k] = cand[k].max(w * r_long * (1.0 + RATIO_MARGIN));
            if peak(&cand) < peak(&best) {
                best = cand;
            }
        }
    }
    best
}

/// The head's overlap figures for `params` (band from `laser`) at spins up
/// to `spin_max_rad_s`.
///
/// Everything but the two enumerations whose boxes widen with the fastest
/// spin (`W_g` and `W_inst`) depends on the head, the band's aperture and
/// the grouping window alone: it is computed once per head
/// ([`HeadOverlaps`], kept for the last [`MEMO_HEADS`] heads, shared by all threads)
/// and the same for every profile.
pub fn head_figures(
    head: &Head,
    params: &EyeSafetyParams,
    laser: &Laser,
    spin_max_rad_s: f64,
) -> Result<HeadFigures, EyeSafetyError> {
    head_figures_on(head, Surface::Cylinder, params, laser, spin_max_rad_s)
}

/// [`head_figures`] for the aperture positions on `surface`.
pub fn head_figures_on(
    head: &Head,
    surface: Surface,
    params: &EyeSafetyParams,
    laser: &Laser,
    spin_max_rad_s: f64,
) -> Result<HeadFigures, EyeSafetyError> {
    head.validate()?;
    let _ = params;
    let f_p = laser.pulse_rate_hz;
    let off = (f_p * head.cycle_s - 1.0).abs();
    if off.is_nan() || off > RATE_CYCLE_TOLERANCE {
        return Err(EyeSafetyError::Param {
            field: "pulse_rate_hz",
            value: f_p,
            reason: "must be 1 / head.cycle_s: every channel of the head fires once per cycle",
        });
    }
    let t_g = group_window_s(laser);
    let o = head_overlaps(head, surface, laser.band.aperture_mm(), t_g);
    let r = head.aperture_distance_mm;
    let smear = r * spin_max_rad_s * t_g * (1.0 + overlap::SUM_MARGIN);
    let (g, spans) = o.group_plan.max(smear);
    let turn_per_pulse = r * spin_max_rad_s * head.cycle_s * (1.0 + overlap::SUM_MARGIN);
    let (inst, _) = o.instant_plan.max(turn_per_pulse);
    let (v, sim, disc) = (o.vertical, o.simultaneous, o.stalled);
    let (g0, spans0) = o.stalled_group;
    Ok(HeadFigures {
        surface,
        aperture_distance_mm: head.aperture_distance_mm,
        channels: head.channels.len() as u32,
        channels_at_worst: v.count_at_worst,
        worst_height_mm: v.height_mm,
        worst_azimuth_deg: (g.arc_mm / r).to_degrees(),
        group_height_mm: g.height_mm,
        weight_vertical: v.weight,
        count_vertical: v.count,
        slots_vertical: o.slots_vertical,
        union_passes: o.union_passes,
        weight_simultaneous: sim.weight,
        count_simultaneous: sim.count,
        weight_group: g.weight,
        count_group: g.count,
        group_spans_time: spans,
        group_window_s: t_g,
        weight_instant: inst.weight,
        weight_stalled: disc.weight,
        count_stalled: disc.count,
        weight_stalled_group: g0.weight,
        weight_stalled_simultaneous: sim.weight,
        count_stalled_simultaneous: sim.count,
        stalled_group_spans_time: spans0,
        footprint_max_mm: o.footprint_max_mm,
        pass_angle_deg: o.pass_angle_deg,
        power_scale_max: o.power_scale_max,
        separations: o.separations.clone(),
        slot_windows: o.slot_windows.clone(),
    })
}

/// What [`head_figures`] takes from the head alone (with the band's
/// aperture and the grouping window): the footprints and every overlap
/// enumeration that does not depend on the spin.
#[derive(Debug)]
pub struct HeadOverlaps {
    /// `W_g`'s enumeration (the pulses within the grouping window) but the
    /// smear, which grows with the spin.
    group_plan: overlap::GroupPlan,
    /// `W_inst`'s (every channel at one slot, window 0) but the smear.
    instant_plan: overlap::GroupPlan,
    /// `W_v`, `K_v` and the worst height.
    vertical: overlap::Meet,
    slots_vertical: u32,
    union_passes: u32,
    /// `W_sim` (the channels fired together sharing a point; the same with
    /// the head stopped).
    simultaneous: overlap::Meet,
    /// `W_disc`: every channel sharing a point, the head stopped.
    stalled: overlap::Meet,
    /// `W_g` with the head stopped, and whether it spans two times.
    stalled_group: (overlap::Meet, bool),
    separations: Vec<Separation>,
    slot_windows: Vec<SlotWindow>,
    footprint_max_mm: f64,
    pass_angle_deg: f64,
    power_scale_max: f64,
}

impl HeadOverlaps {
    /// The profile-independent figures of `head` for an aperture of
    /// `aperture_mm` on `surface` and the grouping window `group_window_s`.
    #[must_use]
    pub fn new(head: &Head, surface: Surface, aperture_mm: f64, group_window_s: f64) -> Self {
        let fps = footprints_on(head, aperture_mm, surface);
        let scales: Vec<f64> = head.channels.iter().map(|c| c.power_scale).collect();
        let slots: Vec<f64> = head.channels.iter().map(|c| c.slot_s).collect();
        let zeros = vec![0.0; slots.len()];
        let r = head.aperture_distance_mm;
        let circ = core::f64::consts::TAU * r;
        let t_g = group_window_s;
        let vertical = overlap::vertical(&fps, &scales);
        let (simultaneous, _) = overlap::group(&fps, &scales, &slots, head.cycle_s, 0.0, 0.0, circ);
        let group_plan = overlap::GroupPlan::new(&fps, &scales, &slots, head.cycle_s, t_g, circ);
        let instant_plan = overlap::GroupPlan::new(&fps, &scales, &zeros, head.cycle_s, 0.0, circ);
        let (stalled, _) = instant_plan.max(0.0);
        let stalled_group = group_plan.max(0.0);
        let fold = |f: fn(&Footprint) -> f64| fps.iter().map(f).fold(0.0, f64::max);
        let pass_angle_deg = fold(|f| f.pass_angle_deg);
        Self {
            slots_vertical: overlap::vertical_slots(&fps, &slots),
            union_passes: union_passes(&fps, pass_angle_deg),
            separations: if vertical.count > 1 {
                separations(&fps, &scales, r, head.cycle_s)
            } else {
                Vec::new()
            },
            slot_windows: if vertical.count > 1 {
                slot_windows(&fps, &scales, &slots, head.cycle_s)
            } else {
                Vec::new()
            },
            footprint_max_mm: fold(|f| f.width_mm),
            pass_angle_deg,
            power_scale_max: scales.iter().copied().fold(0.0, f64::max),
            group_plan,
            instant_plan,
            vertical,
            simultaneous,
            stalled,
            stalled_group,
        }
    }
}

/// Heads whose [`HeadOverlaps`] are kept (the most recently asked for).
pub const MEMO_HEADS: usize = 8;

/// A kept head: its inputs, compared bit for bit, and its figures.
struct Memo {
    head: Head,
    surface: Surface,
    aperture_bits: u64,
    group_window_bits: u64,
    overlaps: Arc<OnceLock<Arc<HeadOverlaps>>>,
}

/// The kept heads, shared by every thread. The list's lock is held only to
/// find or add an entry; the entry's figures are computed once, outside
/// it, by the first thread that asks (a thread asking for a head another
/// is computing waits for that one, not for other heads): the optimizer
/// certifies profiles and bounds the problem on two threads at once.
static MEMO: Mutex<Vec<Memo>> = Mutex::new(Vec::new());

/// Whether two heads are the same bits (`==` would take `-0.0` for `0.0`).
fn same_bits(a: &Head, b: &Head) -> bool {
    let f = |x: f64, y: f64| x.to_bits() == y.to_bits();
    f(a.cycle_s, b.cycle_s)
        && f(a.origin_radius_mm, b.origin_radius_mm)
        && f(a.origin_height_mm, b.origin_height_mm)
        && f(a.exit_diameter_mm, b.exit_diameter_mm)
        && f(a.divergence_mrad, b.divergence_mrad)
        && f(a.aperture_distance_mm, b.aperture_distance_mm)
        && a.channels.len() == b.channels.len()
        && a.channels.iter().zip(&b.channels).all(|(c, d)| {
            c.id == d.id
                && f(c.elevation_deg, d.elevation_deg)
                && f(c.azimuth_offset_deg, d.azimuth_offset_deg)
                && f(c.slot_s, d.slot_s)
                && f(c.power_scale, d.power_scale)
        })
}

/// [`HeadOverlaps::new`], kept: a head evaluated again (every frame of a
/// stream, every profile of an optimizer run, on any thread) reuses its
/// figures, the same values as computing them again.
fn head_overlaps(
    head: &Head,
    surface: Surface,
    aperture_mm: f64,
    group_window_s: f64,
) -> Arc<HeadOverlaps> {
    let (aperture_bits, group_window_bits) = (aperture_mm.to_bits(), group_window_s.to_bits());
    let entry = {
        // The list is whole between statements, so a lock poisoned by a
        // panic elsewhere is taken over.
        let mut memo = MEMO
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let found = memo.iter().find(|m| {
            m.aperture_bits == aperture_bits
                && m.surface == surface
                && m.group_window_bits == group_window_bits
                && same_bits(&m.head, head)
        });
        match found {
            Some(m) => Arc::clone(&m.overlaps),
            None => {
                if memo.len() >= MEMO_HEADS {
                    memo.remove(0);
                }
                let overlaps = Arc::new(OnceLock::new());
                memo.push(Memo {
                    head: head.clone(),
                    surface,
                    aperture_bits,
                    group_window_bits,
                    overlaps: Arc::clone(&overlaps),
                });
                overlaps
            }
        }
    };
    Arc::clone(entry.get_or_init(|| {
        Arc::new(HeadOverlaps::new(
            head,
            surface,
            aperture_mm,
            group_window_s,
        ))
    }))
}

/// `k` of [`HeadFigures::union_passes`]: channel `c` meets an aperture at
/// head-frame azimuth `φ` while the head angle is within `φ − ψ_c ±` half
/// its pass, so every channel's pass lies inside an arc of
/// `(ψ_max − ψ_min) + pass_max`, at most `k` arcs of `pass_max`
/// (`k = ⌈1 + spread/pass_max⌉`, the spread's share rounded up by 1e-12
/// before the ceiling; 1 without spread, at least 2 with any).
fn union_passes(fps: &[Footprint], pass_max_deg: f64) -> u32 {
    if fps.len() <= 1 || pass_max_deg <= 0.0 {
        return 1;
    }
    let lo = fps.iter().map(|f| f.psi_rad).fold(f64::INFINITY, f64::min);
    let hi = fps
        .iter()
        .map(|f| f.psi_rad)
        .fold(f64::NEG_INFINITY, f64::max);
    if hi <= lo {
        // Every hit at one angle: the union is one pass.
        return 1;
    }
    // The spread's share rounded up by 1e-12 (a few ulps of error in the
    // difference, the conversion and the division), added to one pass;
    // any spread at all is at least two passes (no spread rounds away).
    let x = 1.0 + (hi - lo).to_degrees() / pass_max_deg * (1.0 + 1e-12);
    // ψ lies in (−90°, 90°) (offsets and the crossing point inside the
    // aperture's distance): x < 1 + 180/pass, a small count.
    (x.ceil().min(f64::from(u32::MAX)) as u32).max(2)
}

/// The most effective pulses (pulses, or pulses of several channels fired at
/// one instant) the channels meeting one height put into one aperture
/// within `T_max` (`t2_s`): at most `K_v ×` one channel's (`n1`), and at
/// most `S_v ×` one clock's instants inside the channels' union of passes:
/// every pass of that union lasts at most `k·τ` (`k` arcs, each no wider
/// than the widest pass, each crossed in at most the longest pass `τ`) and
/// at most `⌊(T + k·τ)/T_f⌋ + 1` of them meet a window of `T`. C5 is
/// nonincreasing in the count: the smaller upper bound is the tighter
/// conservative one.
fn head_pulse_count(
    h: &HeadFigures,
    n1: f64,
    t2_s: f64,
    pass_s: f64,
    frame_s: f64,
    f_p: f64,
) -> f64 {
    let by_channels = f64::from(h.count_vertical) * n1;
    let union_s = f64::from(h.union_passes) * pass_s * (1.0 + 1e-12);
    let by_slots = f64::from(h.slots_vertical)
        * max_pulses_in(union_s, f_p)
        * passes_in_window(t2_s, union_s, frame_s);
    by_channels.min(by_slots)
}

/// The window within which pulses are one effective pulse for Rule 1:
/// `T_i` in 700–1050 nm for pulses up to `T_i` (as the single-channel
/// grouping), else the pulse duration (pulses that overlap in time).
#[must_use]
pub fn group_window_s(laser: &Laser) -> f64 {
    if laser.band == ael::Band::RetinalNir && laser.pulse_duration_s <= laser.band.t_i_s() {
        laser.band.t_i_s()
    } else {
        laser.pulse_duration_s
    }
}

/// What the single-channel bound found that the head's Rule 1 needs.
#[derive(Debug, Clone, Copy)]
pub struct SingleFigures {
    /// The single-channel Rule 1 ratio (margin applied).
    pub single_pulse_ratio: f64,
    /// Longest pass, s.
    pub pass_duration_s: f64,
    /// Frame period, s.
    pub frame_s: f64,
    /// Largest bin power, W.
    pub power_max_w: f64,
}

/// The head's Rule 1 ratio (margin applied).
#[must_use]
pub fn single_pulse_ratio(h: &HeadFigures, laser: &Laser, s: SingleFigures) -> f64 {
    let t2 = ael::T2_S.min(ael::TIME_BASE_S);
    let n1 = max_pulses_in(s.pass_duration_s, laser.pulse_rate_hz)
        * passes_in_window(t2, s.pass_duration_s, s.frame_s);
    rule1(
        h.count_vertical,
        h.count_group,
        h.weight_vertical,
        s.single_pulse_ratio,
        Weights {
            single_max: h.power_scale_max,
            simultaneous: h.weight_simultaneous,
            simultaneous_count: h.count_simultaneous,
            group: h.weight_group,
            spans_time: h.group_spans_time,
            window_s: h.group_window_s,
        },
        head_pulse_count(h, n1, t2, s.pass_duration_s, s.frame_s, laser.pulse_rate_hz),
        s.power_max_w / laser.pulse_rate_hz,
        laser,
    )
}

struct Weights {
    single_max: f64,
    simultaneous: f64,
    simultaneous_count: u32,
    group: f64,
    spans_time: bool,
    window_s: f64,
}

#[allow(clippy::too_many_arguments)]
fn rule1(
    count_vertical: u32,
    count_group: u32,
    weight_single: f64,
    single_ratio: f64,
    w: Weights,
    n_head: f64,
    pulse_energy_j: f64,
    laser: &Laser,
) -> f64 {
    if count_vertical <= 1 && count_group <= 1 {
        return weight_single * single_ratio;
    }
    let c5 = laser.c5(n_head);
    let tp = laser.pulse_duration_s;
    // Pulses of several channels fired together are one pulse of the
    // pulse's duration; compared, conservatively, with the smallest AEL up
    // to the grouping window (they may also be read as a group).
    let group_ael = laser.ael_inf_j(tp, w.window_s + tp);
    let a = if w.simultaneous_count <= 1 {
        // At most one channel at any point: its own weight, exactly.
        w.single_max * pulse_energy_j / (c5 * laser.ael_j(tp))
    } else {
        w.simultaneous * pulse_energy_j / (c5 * group_ael)
    };
    let b = if w.spans_time {
        w.group * pulse_energy_j / (c5 * group_ael)
    } else {
        0.0
    };
    a.max(b) * (1.0 + RATIO_MARGIN)
}

/// The head's stalled-rotor ratio: every pulse of every channel whose
/// footprint meets one aperture, the head stopped at the highest-power
/// azimuth (`power_w`).
#[must_use]
pub fn stalled_ratio(h: &HeadFigures, laser: &Laser, power_w: f64) -> f64 {
    let (one, _) = laser.stationary_ratio(power_w);
    if h.count_stalled <= 1 {
        return h.weight_stalled * one;
    }
    let t2 = ael::T2_S.min(ael::TIME_BASE_S);
    // The channels sharing one point meet one height: at most `S_v`
    // distinct instants per cycle.
    let n =
        f64::from(h.count_stalled.min(h.slots_vertical)) * max_pulses_in(t2, laser.pulse_rate_hz);
    let r1 = rule1(
        h.count_stalled,
        h.count_stalled,
        h.weight_stalled,
        one,
        Weights {
            single_max: h.power_scale_max,
            simultaneous: h.weight_stalled_simultaneous,
            simultaneous_count: h.count_stalled_simultaneous,
            group: h.weight_stalled_group,
            spans_time: h.stalled_group_spans_time,
            window_s: h.group_window_s,
        },
        n,
        power_w / laser.pulse_rate_hz,
        laser,
    );
    (h.weight_stalled * one * (1.0 + RATIO_MARGIN)).max(r1)
}

/// The largest uniform power scale (every bin power times it) at which a
/// profile whose bound is `worst_ratio` certifies: every figure is
/// positively homogeneous of degree 1 in the bin powers (energies are
/// linear in them; the counts and C5 depend on the spins and the pulse
/// rate only), so the bound at `λ·P` is `λ` times the bound at `P`; the
/// quotient is rounded down by 1e-9 for the floating-point evaluation.
#[must_use]
pub fn power_scale_to_certify(worst_ratio: f64) -> f64 {
    if worst_ratio > 0.0 {
        (1.0 - 1e-9) / worst_ratio
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eye_safety::head::geometry::footprints;
    use crate::eye_safety::head::{Channel, Head};

    fn column(slots: &[f64], offsets_deg: &[f64]) -> Head {
        Head {
            cycle_s: 1e-4,
            origin_radius_mm: 0.0,
            origin_height_mm: 0.0,
            exit_diameter_mm: 5.0,
            divergence_mrad: 0.0,
            aperture_distance_mm: 100.0,
            channels: slots
                .iter()
                .zip(offsets_deg)
                .enumerate()
                .map(|(i, (&slot_s, &az))| Channel {
                    id: i as u32,
                    elevation_deg: 0.1 * i as f64,
                    azimuth_offset_deg: az,
                    slot_s,
                    power_scale: 1.0,
                })
                .collect(),
        }
    }

    /// By hand: a cycle of 100 µs, slots 0, 10 and 30 µs on three channels
    /// 0.1° apart (one height meets all three), a fourth at 30° elevation
    /// (58 mm up: meets none of them) at slot 50 µs. Differences among all
    /// slots mod the cycle: 0, 10, 20, 30, 40, 50, 60, 70, 80, 90 µs (every
    /// one of them, since 50 adds 50 − 30 = 20, 50 − 10 = 40, …). A window
    /// shorter than 10 µs holds one channel; from 10 µs, 0 and 10 (or 10
    /// and 30 from 20 µs): 2; from 30 µs, all three of the column: 3; the
    /// fourth never joins them (its height interval holds none of theirs).
    /// Ranges start 1e-9·cycle = 1e-13 s early and the last ends at
    /// `cycle·(1 − 1e-9)`.
    #[test]
    fn slot_windows_by_hand() {
        let mut h = column(&[0.0, 1e-5, 3e-5], &[0.0, 0.0, 0.0]);
        h.channels.push(Channel {
            id: 3,
            elevation_deg: 30.0,
            azimuth_offset_deg: 0.0,
            slot_s: 5e-5,
            power_scale: 1.0,
        });
        let fps = footprints(&h, 7.0);
        let scales = [1.0; 4];
        let slots: Vec<f64> = h.channels.iter().map(|c| c.slot_s).collect();
        let w = slot_windows(&fps, &scales, &slots, h.cycle_s);
        let eps = 1e-13;
        let lo: Vec<f64> = w.iter().map(|r| r.lo_s).collect();
        let want_lo: Vec<f64> = (0..10)
            .map(|k| if k == 0 { 0.0 } else { k as f64 * 1e-5 - eps })
            .collect();
        assert_eq!(lo.len(), 10, "{w:?}");
        for (a, b) in lo.iter().zip(&want_lo) {
            assert!((a - b).abs() < 1e-18, "{w:?}");
        }
        let weights: Vec<f64> = w.iter().map(|r| (r.weight * 1e6).round() / 1e6).collect();
        assert_eq!(
            weights,
            [1.0, 2.0, 2.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0, 3.0],
            "{w:?}"
        );
        assert_eq!(w.last().unwrap().hi_s, 1e-4 * (1.0 - 1e-9));
        for p in w.windows(2) {
            assert_eq!(p[0].hi_s, p[1].lo_s);
        }
        // Sums of more than one weight are rounded up, one is exact.
        assert_eq!(w[0].weight, 1.0);
        assert!(w[1].weight > 2.0);
    }

    /// By hand: from the axis (`r0 = 0`) every ray is radial, `ψ_c = φ_c`;
    /// a 7 mm aperture and a 5 mm beam give a pass of 12/100 rad = 6.8755°.
    /// Offsets 0 and 6°: (6 + 6.8755)/6.8755 = 1.87, two passes; offsets
    /// −10° and 10°: (20 + 6.8755)/6.8755 = 3.91, four; one offset: one.
    #[test]
    fn union_passes_by_hand() {
        let pass = (12.0f64 / 100.0).to_degrees();
        for (offsets, k) in [
            (&[0.0, 0.0][..], 1),
            (&[0.0, 6.0][..], 2),
            (&[-10.0, 10.0][..], 4),
        ] {
            let h = column(&[0.0, 0.0], offsets);
            let fps = footprints(&h, 7.0);
            assert_eq!(union_passes(&fps, pass), k, "{offsets:?}");
        }
        let h = column(&[0.0], &[30.0]);
        assert_eq!(union_passes(&footprints(&h, 7.0), pass), 1);
    }

    /// The kept figures are the computed ones: more heads than are kept,
    /// each evaluated again after the others pushed it out and again while
    /// kept, give the same bits as the first evaluation; a head that
    /// differs in one bit (`-0.0` for `0.0`, one `power_scale`) is not
    /// taken for a kept one.
    #[test]
    fn kept_head_figures_are_the_computed_ones() {
        let params = EyeSafetyParams {
            wavelength_nm: 905.0,
            pulse_duration_s: 5e-9,
            beam_diameter_mm: 5.0,
            head: None,
        };
        let laser = crate::eye_safety::exposure::laser(&params, 1e4).unwrap();
        let heads: Vec<Head> = (0..MEMO_HEADS + 2)
            .map(|k| {
                let n = 2 + k;
                let slots: Vec<f64> = (0..n).map(|i| 1e-5 * (i % 3) as f64).collect();
                let offsets: Vec<f64> = (0..n).map(|i| 0.7 * (i + k) as f64).collect();
                column(&slots, &offsets)
            })
            .collect();
        let bits =
            |h: &Head, spin: f64| format!("{:?}", head_figures(h, &params, &laser, spin).unwrap());
        let first: Vec<String> = heads.iter().map(|h| bits(h, 300.0)).collect();
        for round in 0..2 {
            for (h, want) in heads.iter().zip(&first).rev() {
                assert_eq!(&bits(h, 300.0), want, "round {round}");
                assert_eq!(bits(h, 300.0), *want, "kept");
            }
        }
        // The spin-dependent figures follow the spin of each call.
        // (Two beams 10° apart, 5.5 mm between their boxes: a head turn of
        // 10 mm per pulse spacing puts both in one instant's box.)
        let apart = column(&[0.0, 0.0], &[0.0, 10.0]);
        let (slow, fast) = (bits(&apart, 30.0), bits(&apart, 1000.0));
        assert_ne!(slow, fast);
        assert_eq!(bits(&apart, 30.0), slow);
        let mut scaled = heads[0].clone();
        scaled.channels[1].power_scale = 0.5;
        assert!(!same_bits(&scaled, &heads[0]));
        assert_ne!(bits(&scaled, 300.0), first[0]);
        let mut signed = heads[0].clone();
        signed.origin_height_mm = -0.0;
        assert_eq!(signed, heads[0]);
        assert!(!same_bits(&signed, &heads[0]));
        assert!(same_bits(&heads[0].clone(), &heads[0]));
    }

    /// A head is kept for every thread: two threads asking for it at once
    /// get one computation (the same figures, not two equal copies), and a
    /// thread asking later gets that one too. (Kept per thread, each would
    /// compute its own.) Other tests running at the same time add heads and
    /// may push this one out between two calls, so the check may take a few
    /// tries; kept per thread, no try passes.
    #[test]
    fn two_threads_share_one_kept_head() {
        // Offsets no other test uses, so the head is this test's own.
        let head = column(&[0.0, 2e-5, 4e-5], &[0.31, 1.77, 2.93]);
        let t_g = 1e-3;
        let shared = |surface: Surface| {
            let barrier = std::sync::Barrier::new(2);
            let ask = || {
                barrier.wait();
                head_overlaps(&head, surface, 7.0, t_g)
            };
            let (a, b) = std::thread::scope(|s| {
                let (one, two) = (s.spawn(ask), s.spawn(ask));
                (one.join().unwrap(), two.join().unwrap())
            });
            let later = std::thread::scope(|s| {
                s.spawn(|| head_overlaps(&head, surface, 7.0, t_g))
                    .join()
                    .unwrap()
            });
            Arc::ptr_eq(&a, &b) && Arc::ptr_eq(&a, &later)
        };
        for surface in [Surface::Cylinder, Surface::Sphere] {
            assert!(
                (0..8).any(|_| shared(surface)),
                "{surface:?}: every try computed the head more than once"
            );
        }
        // Another surface is another entry.
        let (c, s) = (
            head_overlaps(&head, Surface::Cylinder, 7.0, t_g),
            head_overlaps(&head, Surface::Sphere, 7.0, t_g),
        );
        assert!(!Arc::ptr_eq(&c, &s));
    }

    fn figures(count_vertical: u32, slots_vertical: u32, union_passes: u32) -> HeadFigures {
        HeadFigures {
            aperture_distance_mm: 100.0,
            union_passes,
            ..crate::testing::head_figures(count_vertical, slots_vertical)
        }
    }

    /// By hand: a pass of 2.7 ms at 20 kHz holds at most ⌊54⌋ + 1 = 55
    /// pulses, and a 10 s window meets ⌊(10 + 0.0027)/0.1⌋ + 1 = 101 passes
    /// of a 10 Hz frame: `N_single` = 5555. 34 channels of one slot whose
    /// passes lie in two passes' arc (5.4 ms: 109 pulses, 101 passes):
    /// min(34 · 5555, 1 · 109 · 101) = 11009. Every channel at its own slot
    /// (`S_v = K_v`): the channels' count, 34 · 5555. The count never drops
    /// below one channel's.
    #[test]
    fn head_pulse_count_by_hand() {
        let (t2, tau, frame, f_p) = (10.0, 2.7e-3, 0.1, 20_000.0);
        let n1 = max_pulses_in(tau, f_p) * passes_in_window(t2, tau, frame);
        assert_eq!(n1, 55.0 * 101.0);
        let one_slot = head_pulse_count(&figures(34, 1, 2), n1, t2, tau, frame, f_p);
        assert_eq!(one_slot, 109.0 * 101.0);
        let own_slots = head_pulse_count(&figures(34, 34, 2), n1, t2, tau, frame, f_p);
        assert_eq!(own_slots, 34.0 * n1);
        for k in 1..6 {
            assert!(head_pulse_count(&figures(34, 1, k), n1, t2, tau, frame, f_p) >= n1);
        }
    }
}
