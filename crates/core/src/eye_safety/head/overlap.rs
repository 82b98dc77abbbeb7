//! Step 2 of the head's argument: which channels can meet one aperture
//! position, found exactly by enumeration (`specs/eye_safety.md`, "The
//! head").
//!
//! - **Over a sweep** ([`vertical`]): the aperture at height `z` meets
//!   channel `c` at some head angle iff `|z_c − z| ≤ h_c` (the footprint
//!   box's half-height): closed intervals in `z`. The set of channels
//!   containing `z` changes only at interval ends, and a maximum of a sum of
//!   positive weights over closed intervals is attained at some interval's
//!   lower end: every lower end is evaluated.
//! - **At once** ([`group`]): the pulses fired within one window of
//!   `window_s` (channels fire at `slot_c + k·cycle`) whose footprint boxes,
//!   widened along the arc by the head's turn during the window
//!   (`smear_mm`), share a point. A maximum over points of a sum of positive
//!   weights of closed boxes is attained at a point whose arc coordinate is
//!   some box's left end and whose height is some box's lower end; a window
//!   can be slid later until it starts at a pulse without losing one, so
//!   windows starting at every distinct slot are every candidate.
//!
//! Sums are of positive weights and rounded up by [`SUM_MARGIN`] when they
//! hold more than one term (one term is exact).

use super::geometry::Footprint;

/// Relative rounding-up of a sum of more than one weight (`n` terms of a
/// float sum err by at most `n·2⁻⁵³` relative: 1e-12 covers 512 terms).
pub const SUM_MARGIN: f64 = 1e-12;

/// Absolute widening, mm, of every interval and box end: positions that
/// touch in exact arithmetic but miss by a rounding error still meet.
pub const TOUCH_MM: f64 = 1e-9;

/// The largest weight of channels meeting one position, and where.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Meet {
    /// Largest `Σ weight` over the channels (or pulses) that meet one
    /// position.
    pub weight: f64,
    /// Most channels meeting one position (not necessarily where the
    /// weight is largest).
    pub count: u32,
    /// Channels meeting the position of the largest weight.
    pub count_at_worst: u32,
    /// Height of that position, mm.
    pub height_mm: f64,
    /// Head-frame arc position of that position, mm (0 for [`vertical`]).
    pub arc_mm: f64,
}

fn round_sum(sum: f64, terms: u32) -> f64 {
    if terms > 1 {
        sum * (1.0 + SUM_MARGIN)
    } else {
        sum
    }
}

/// The most weight (`weights[i]` for footprint `i`) of channels whose height
/// intervals share a point: exact over every height.
#[must_use]
pub fn vertical(fps: &[Footprint], weights: &[f64]) -> Meet {
    let iv: Vec<(f64, f64)> = fps
        .iter()
        .map(|f| {
            (
                f.z_mm - f.half_height_mm - TOUCH_MM,
                f.z_mm + f.half_height_mm + TOUCH_MM,
            )
        })
        .collect();
    let mut best = Meet {
        weight: 0.0,
        count: 0,
        count_at_worst: 0,
        height_mm: 0.0,
        arc_mm: 0.0,
    };
    for &(z, _) in &iv {
        let (mut w, mut n) = (0.0, 0u32);
        for (i, &(lo, hi)) in iv.iter().enumerate() {
            if lo <= z && z <= hi {
                w += weights[i];
                n += 1;
            }
        }
        let w = round_sum(w, n);
        best.count = best.count.max(n);
        if w > best.weight {
            best.weight = w;
            best.count_at_worst = n;
            best.height_mm = z;
        }
    }
    best
}

/// The most distinct firing slots (`slots_s`, compared exactly) among the
/// channels whose height intervals share a point: exact over every height
/// (the set of channels holding `z` is a subset of the set at the largest
/// lower end at or below `z`, and a count of distinct slots only grows
/// with the set, so every lower end is evaluated).
#[must_use]
pub fn vertical_slots(fps: &[Footprint], slots_s: &[f64]) -> u32 {
    let iv: Vec<(f64, f64)> = fps
        .iter()
        .map(|f| {
            (
                f.z_mm - f.half_height_mm - TOUCH_MM,
                f.z_mm + f.half_height_mm + TOUCH_MM,
            )
        })
        .collect();
    let mut best = 0u32;
    let mut at: Vec<f64> = Vec::with_capacity(iv.len());
    for &(z, _) in &iv {
        at.clear();
        for (i, &(lo, hi)) in iv.iter().enumerate() {
            if lo <= z && z <= hi {
                at.push(slots_s[i]);
            }
        }
        at.sort_by(f64::total_cmp);
        at.dedup();
        best = best.max(at.len() as u32);
    }
    best
}

/// Pulses of a clock of period `cycle_s` at phase `slot_s` inside the
/// closed window `[t0_s, t0_s + window_s]` (`0 ≤ t0_s, slot_s < cycle_s`),
/// rounded up at touching ends.
#[must_use]
pub fn pulses_in(slot_s: f64, t0_s: f64, window_s: f64, cycle_s: f64) -> u32 {
    let eps = 1e-9 * cycle_s;
    let first = if slot_s + eps >= t0_s {
        slot_s - t0_s
    } else {
        slot_s + cycle_s - t0_s
    };
    let first = first.max(0.0);
    if first > window_s + eps {
        return 0;
    }
    let more = crate::eye_safety::bound::floor_up((window_s - first).max(0.0) / cycle_s);
    // Counts of a window of at most 1 s at a cycle of at least 1e-12 s fit.
    (more as u32).saturating_add(1)
}

/// Boxes: `(x_lo, x_hi, z_lo, z_hi, weight)`.
type Box5 = (f64, f64, f64, f64, f64);

/// The boxes' distinct left ends, sorted, and every box's height ends,
/// sorted (stably: pushed in box order, lower end first), as
/// [`boxes_max_sorted`] takes them.
fn sorted_ends(boxes: &[Box5]) -> (Vec<f64>, Vec<(f64, bool, usize)>) {
    let mut xs: Vec<f64> = boxes.iter().map(|b| b.0).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let mut all_ends: Vec<(f64, bool, usize)> = Vec::with_capacity(2 * boxes.len());
    for (i, b) in boxes.iter().enumerate() {
        all_ends.push((b.2, false, i));
        all_ends.push((b.3, true, i));
    }
    all_ends.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    (xs, all_ends)
}

/// The most weight of boxes sharing a point ([`boxes_max_sorted`] with
/// the boxes' own [`sorted_ends`]).
#[cfg(test)]
fn boxes_max(boxes: &[Box5]) -> Meet {
    let (xs, all_ends) = sorted_ends(boxes);
    boxes_max_sorted(boxes, &xs, &all_ends)
}

/// Boxes: `(x_lo, x_hi, z_lo, z_hi, weight)`; the most weight sharing a
/// point, exactly (candidate points: every box's left end × lower end; at
/// each left end a sweep over the active boxes' height ends, lower ends
/// first at a tie, so touching boxes meet; a left end whose active boxes
/// all reach the next left end is skipped, its set being a subset of the
/// next one's). `xs` and `all_ends` are the boxes' [`sorted_ends`]: they
/// depend on the left and height ends only, not on the right ends. The
/// sweep's running sum adds and subtracts: its rounding error is at most
/// `2·m·ε·Σ w` for `m` ends, added to the result when there is more than
/// one box.
fn boxes_max_sorted(boxes: &[Box5], xs: &[f64], all_ends: &[(f64, bool, usize)]) -> Meet {
    let mut best = Meet {
        weight: 0.0,
        count: 0,
        count_at_worst: 0,
        height_mm: 0.0,
        arc_mm: 0.0,
    };
    // Every box's height ends sorted once: the ends of the boxes active at
    // one left end, in this order, are exactly the stable sort of those
    // boxes' ends alone, so the sweep below adds and subtracts in the same
    // order (the same bits) as sorting each active set on its own.
    let mut is_active = vec![false; boxes.len()];
    let mut err = 0.0f64;
    for (k, &x) in xs.iter().enumerate() {
        // The boxes active here stay active up to the next left end unless
        // one closes before it: then this set is a subset of the next one's
        // (positive weights: no larger maximum) and is skipped.
        let active = || boxes.iter().filter(|b| b.0 <= x && x <= b.1);
        if let Some(&next) = xs.get(k + 1) {
            if active().all(|b| b.1 >= next) {
                continue;
            }
        }
        let (mut total, mut n_ends) = (0.0, 0usize);
        for (i, b) in boxes.iter().enumerate() {
            is_active[i] = b.0 <= x && x <= b.1;
            if is_active[i] {
                total += b.4;
                n_ends += 2;
            }
        }
        err = err.max(2.0 * n_ends as f64 * f64::EPSILON * total);
        let (mut w, mut n) = (0.0f64, 0u32);
        for &(z, close, i) in all_ends {
            if !is_active[i] {
                continue;
            }
            let wi = boxes[i].4;
            if close {
                w -= wi;
                n -= 1;
                continue;
            }
            w += wi;
            n += 1;
            best.count = best.count.max(n);
            if w > best.weight {
                best.weight = w;
                best.count_at_worst = n;
                best.height_mm = z;
                best.arc_mm = x;
            }
        }
    }
    if boxes.len() > 1 {
        best.weight = best.weight * (1.0 + SUM_MARGIN) + err;
    }
    best
}

/// The most weight of pulses one aperture position can receive within one
/// window of `window_s`: channel `c` contributes `weights[c]` per pulse it
/// fires in the window (slots `slots_s`, period `cycle_s`); its footprint box
/// is widened along the arc by `smear_mm` (the head's turn during the
/// window, at the aperture radius). `count` is the most channels.
///
/// Also returns whether some position can receive pulses fired at two
/// different times within one window (a channel firing twice, or two
/// channels with different slots).
#[must_use]
pub fn group(
    fps: &[Footprint],
    weights: &[f64],
    slots_s: &[f64],
    cycle_s: f64,
    window_s: f64,
    smear_mm: f64,
    circumference_mm: f64,
) -> (Meet, bool) {
    GroupPlan::new(fps, weights, slots_s, cycle_s, window_s, circumference_mm).max(smear_mm)
}

/// [`group`] for one head, window and aperture circle with everything that
/// does not depend on the smear done once: per window start (a distinct
/// slot) the channels firing in the window, their boxes but the smeared
/// right end, and the boxes' sorted left and height ends (neither depends
/// on the smear; boxes that wrap the circle have one left end, −∞).
/// [`Self::max`] at a smear is [`group`] at it, the same bits.
#[derive(Debug, Clone)]
pub struct GroupPlan {
    circumference_mm: f64,
    starts: Vec<StartPlan>,
}

/// One window start of a [`GroupPlan`].
#[derive(Debug, Clone)]
struct StartPlan {
    /// `(x_lo, x + half_arc, z_lo, z_hi, weight)` per channel firing in the
    /// window: the right end before the smear and the touch widening.
    boxes: Vec<Box5>,
    /// `(slot, pulses in the window)` per box.
    slot_of: Vec<(f64, u32)>,
    /// The boxes' [`sorted_ends`] (not wrapped).
    xs: Vec<f64>,
    all_ends: Vec<(f64, bool, usize)>,
}

impl GroupPlan {
    /// The plan of [`group`] for these arguments (all but the smear).
    #[must_use]
    pub fn new(
        fps: &[Footprint],
        weights: &[f64],
        slots_s: &[f64],
        cycle_s: f64,
        window_s: f64,
        circumference_mm: f64,
    ) -> Self {
        let mut t0s: Vec<f64> = slots_s.to_vec();
        t0s.sort_by(f64::total_cmp);
        t0s.dedup();
        let mut starts = Vec::with_capacity(t0s.len());
        for &t0 in &t0s {
            let mut boxes = Vec::with_capacity(fps.len());
            let mut slot_of = Vec::with_capacity(fps.len());
            for (i, f) in fps.iter().enumerate() {
                let k = pulses_in(slots_s[i], t0, window_s, cycle_s);
                if k == 0 {
                    continue;
                }
                let x = f.psi_rad * (circumference_mm / core::f64::consts::TAU);
                boxes.push((
                    x - f.half_arc_mm - TOUCH_MM,
                    x + f.half_arc_mm,
                    f.z_mm - f.half_height_mm - TOUCH_MM,
                    f.z_mm + f.half_height_mm + TOUCH_MM,
                    weights[i] * f64::from(k),
                ));
                slot_of.push((slots_s[i], k));
            }
            if boxes.is_empty() {
                continue;
            }
            let (xs, all_ends) = sorted_ends(&boxes);
            starts.push(StartPlan {
                boxes,
                slot_of,
                xs,
                all_ends,
            });
        }
        Self {
            circumference_mm,
            starts,
        }
    }

    /// [`group`] with the boxes widened along the arc by `smear_mm`.
    #[must_use]
    pub fn max(&self, smear_mm: f64) -> (Meet, bool) {
        let wraps = smear_mm >= 0.5 * self.circumference_mm;
        let mut best = Meet {
            weight: 0.0,
            count: 0,
            count_at_worst: 0,
            height_mm: 0.0,
            arc_mm: 0.0,
        };
        let mut multi_time = false;
        let mut boxes = Vec::new();
        for sp in &self.starts {
            boxes.clear();
            boxes.extend(sp.boxes.iter().map(|&(x_lo, x_hi, z_lo, z_hi, w)| {
                if wraps {
                    (f64::NEG_INFINITY, f64::INFINITY, z_lo, z_hi, w)
                } else {
                    (x_lo, x_hi + smear_mm + TOUCH_MM, z_lo, z_hi, w)
                }
            }));
            let m = if wraps {
                boxes_max_sorted(&boxes, &[f64::NEG_INFINITY], &sp.all_ends)
            } else {
                boxes_max_sorted(&boxes, &sp.xs, &sp.all_ends)
            };
            if !multi_time {
                multi_time = multi_time_overlap(&boxes, &sp.slot_of);
            }
            best.count = best.count.max(m.count);
            if m.weight > best.weight {
                best = Meet {
                    count: best.count,
                    ..m
                };
            }
        }
        (best, multi_time)
    }
}

/// Whether two boxes of pulses fired at different times share a point, or a
/// box holds two pulses (a channel firing twice in the window).
fn multi_time_overlap(boxes: &[Box5], slot_of: &[(f64, u32)]) -> bool {
    if slot_of.iter().any(|&(_, k)| k > 1) {
        return true;
    }
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            if slot_of[i].0 != slot_of[j].0 {
                let (a, b) = (boxes[i], boxes[j]);
                if a.0 <= b.1 && b.0 <= a.1 && a.2 <= b.3 && b.2 <= a.3 {
                    return true;
                }
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fp(psi_deg: f64, z: f64, half: f64) -> Footprint {
        Footprint {
            index: 0,
            psi_rad: psi_deg.to_radians(),
            z_mm: z,
            slant_mm: 100.0,
            width_mm: 2.0 * half - 7.0,
            cos_beta: 1.0,
            half_arc_mm: half,
            half_height_mm: half,
            pass_angle_deg: (2.0 * half / 100.0).to_degrees(),
        }
    }

    /// Intervals [−5, 5], [3, 13], [12, 22] (half-height 5): at most two
    /// share a point (z ∈ [3, 5] or [12, 13]); weights 1, 2, 4: the worst is
    /// 6 at z = 12.
    #[test]
    fn vertical_by_hand() {
        let f = [fp(0.0, 0.0, 5.0), fp(0.0, 8.0, 5.0), fp(0.0, 17.0, 5.0)];
        let m = vertical(&f, &[1.0, 2.0, 4.0]);
        assert_eq!(m.count, 2);
        assert!((m.weight - 6.0).abs() < 1e-9);
        assert!((m.height_mm - 12.0).abs() < 1e-6);
        // Touching intervals meet.
        let f = [fp(0.0, 0.0, 5.0), fp(0.0, 10.0, 5.0)];
        assert_eq!(vertical(&f, &[1.0, 1.0]).count, 2);
        let f = [fp(0.0, 0.0, 5.0), fp(0.0, 10.001, 5.0)];
        assert_eq!(vertical(&f, &[1.0, 1.0]).count, 1);
    }

    /// Intervals [−5, 5], [3, 13], [12, 22], [4, 14] with slots 0, 1, 1, 2:
    /// at z ∈ [4, 5] the first, second and fourth (slots 0, 1, 2: three);
    /// at [12, 13] the second, third and fourth (slots 1, 1, 2: two).
    #[test]
    fn vertical_slots_by_hand() {
        let f = [
            fp(0.0, 0.0, 5.0),
            fp(0.0, 8.0, 5.0),
            fp(0.0, 17.0, 5.0),
            fp(0.0, 9.0, 5.0),
        ];
        assert_eq!(vertical_slots(&f, &[0.0, 1.0, 1.0, 2.0]), 3);
        assert_eq!(vertical_slots(&f, &[0.0, 1.0, 1.0, 1.0]), 2);
        assert_eq!(vertical_slots(&f, &[0.0, 0.0, 0.0, 0.0]), 1);
        assert_eq!(vertical_slots(&f[..1], &[0.5]), 1);
    }

    /// Pulse counts in closed windows: cycle 10, slot 3, window [0, 5]: one
    /// (t = 3); window [4, 14]: one (13) — touching ends count: [3, 13] two.
    #[test]
    fn pulses_in_by_hand() {
        assert_eq!(pulses_in(3.0, 0.0, 5.0, 10.0), 1);
        assert_eq!(pulses_in(3.0, 4.0, 10.0, 10.0), 1);
        assert_eq!(pulses_in(3.0, 4.0, 8.0, 10.0), 0);
        assert_eq!(pulses_in(3.0, 3.0, 10.0, 10.0), 2);
        assert_eq!(pulses_in(3.0, 3.0, 25.0, 10.0), 3);
    }

    /// Two channels at one slot whose boxes overlap, a third 20° away at
    /// another slot: the group is the first two; with a window holding both
    /// slots and a smear reaching the third, all three.
    #[test]
    fn group_by_hand() {
        let f = [fp(0.0, 0.0, 6.0), fp(1.0, 0.0, 6.0), fp(20.0, 0.0, 6.0)];
        let w = [1.0, 1.0, 1.0];
        let circ = core::f64::consts::TAU * 100.0;
        let (m, multi) = group(&f, &w, &[0.0, 0.0, 1.0], 10.0, 0.5, 0.0, circ);
        assert_eq!(m.count, 2);
        assert!(!multi);
        assert!((m.weight - 2.0).abs() < 1e-9);
        let (m, multi) = group(&f, &w, &[0.0, 0.0, 1.0], 10.0, 1.0, 40.0, circ);
        assert_eq!(m.count, 3);
        assert!(multi);
    }

    /// The sweep as it was before the height ends were sorted once (each
    /// active set's ends sorted on their own), kept to show the change
    /// keeps every result bit for bit.
    fn boxes_max_per_set_sort(boxes: &[(f64, f64, f64, f64, f64)]) -> Meet {
        let mut best = Meet {
            weight: 0.0,
            count: 0,
            count_at_worst: 0,
            height_mm: 0.0,
            arc_mm: 0.0,
        };
        let mut xs: Vec<f64> = boxes.iter().map(|b| b.0).collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        let mut err = 0.0f64;
        for (k, &x) in xs.iter().enumerate() {
            let active = || boxes.iter().filter(|b| b.0 <= x && x <= b.1);
            if let Some(&next) = xs.get(k + 1) {
                if active().all(|b| b.1 >= next) {
                    continue;
                }
            }
            let mut ends: Vec<(f64, bool, f64)> = Vec::new();
            let mut total = 0.0;
            for b in active() {
                ends.push((b.2, false, b.4));
                ends.push((b.3, true, b.4));
                total += b.4;
            }
            ends.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            err = err.max(2.0 * ends.len() as f64 * f64::EPSILON * total);
            let (mut w, mut n) = (0.0f64, 0u32);
            for &(z, close, wi) in &ends {
                if close {
                    w -= wi;
                    n -= 1;
                    continue;
                }
                w += wi;
                n += 1;
                best.count = best.count.max(n);
                if w > best.weight {
                    best.weight = w;
                    best.count_at_worst = n;
                    best.height_mm = z;
                    best.arc_mm = x;
                }
            }
        }
        if boxes.len() > 1 {
            best.weight = best.weight * (1.0 + SUM_MARGIN) + err;
        }
        best
    }

    /// Sorting the height ends once gives the same bits as sorting each
    /// active set's ends: random boxes with many ties (integer ends) and
    /// equal weights, where the order of the additions matters.
    #[test]
    fn boxes_sweep_sorted_once_is_bit_identical() {
        use proptest::prelude::*;
        use proptest::test_runner::{Config, TestRunner};
        let mut runner = TestRunner::new(Config::with_cases(500));
        let bx = (0u8..12, 0u8..6, 0u8..12, 0u8..6, 0.1f64..2.0);
        runner
            .run(&proptest::collection::vec(bx, 1..40), |v| {
                let boxes: Vec<_> = v
                    .iter()
                    .map(|&(x, wx, z, wz, w)| {
                        let (x, z) = (f64::from(x), f64::from(z));
                        (x, x + f64::from(wx), z, z + f64::from(wz), w)
                    })
                    .collect();
                let (a, b) = (boxes_max(&boxes), boxes_max_per_set_sort(&boxes));
                prop_assert_eq!(a.weight.to_bits(), b.weight.to_bits());
                prop_assert_eq!(a, b);
                Ok(())
            })
            .unwrap();
    }

    /// The sweep (with skipped subsets) against the plain maximum over
    /// every left end × lower end, summing every box that holds the point:
    /// never below it, and within the stated rounding above it; the same
    /// most-channels count.
    #[test]
    fn boxes_sweep_is_the_plain_maximum() {
        use proptest::prelude::*;
        use proptest::test_runner::{Config, TestRunner};
        let mut runner = TestRunner::new(Config::with_cases(300));
        let bx = (
            0.0f64..20.0,
            0.1f64..6.0,
            0.0f64..20.0,
            0.1f64..6.0,
            0.1f64..2.0,
        );
        runner
            .run(&proptest::collection::vec(bx, 1..24), |v| {
                let boxes: Vec<_> = v
                    .iter()
                    .map(|&(x, wx, z, wz, w)| (x.round(), x.round() + wx.round(), z, z + wz, w))
                    .collect();
                let (mut plain, mut count) = (0.0f64, 0u32);
                for &(x, ..) in &boxes {
                    for &(_, _, z, ..) in &boxes {
                        let inside = boxes
                            .iter()
                            .filter(|b| b.0 <= x && x <= b.1 && b.2 <= z && z <= b.3);
                        plain = plain.max(inside.clone().map(|b| b.4).sum());
                        count = count.max(inside.count() as u32);
                    }
                }
                let m = boxes_max(&boxes);
                prop_assert!(m.weight >= plain * (1.0 - 1e-15), "{} < {plain}", m.weight);
                prop_assert!(
                    m.weight <= plain * (1.0 + 1e-9) + 1e-9,
                    "{} > {plain}",
                    m.weight
                );
                prop_assert_eq!(m.count, count);
                Ok(())
            })
            .unwrap();
    }
}
