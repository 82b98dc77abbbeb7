//! Proof harnesses of the head's enumeration logic (`specs/verification.md`):
//! the channel sets that can meet one aperture position are found by
//! enumerating candidate points (every interval's lower end for
//! [`overlap::vertical`], every box's left end × lower end for
//! [`overlap::group`]), not by sampling. Each harness checks, for any small
//! head of three channels with whole-number geometry (exact in `f64`) and
//! any probe point, that the enumeration's maximum is at least the weight
//! and the count of the channels meeting the probe, and that the reported
//! worst position really holds the reported weight.
//!
//! Unwind bounds: the longest loop runs over the six height ends of three
//! boxes (the sorts of three left ends, three slots and six ends included),
//! so 7 suffices; the harnesses unwind 8.

use super::geometry::Footprint;
use super::overlap::{self, SUM_MARGIN, TOUCH_MM};
use crate::verification::{cover, for_all};

/// Channels of the harness heads.
const N: usize = 3;

fn footprint(index: usize, x: i8, z: i8, half_arc: u8, half_height: u8) -> Footprint {
    Footprint {
        index,
        // Circumference 2π below: the arc position is `psi_rad` exactly.
        psi_rad: f64::from(x % 24),
        z_mm: f64::from(z % 24),
        slant_mm: 100.0,
        width_mm: 1.0,
        cos_beta: 1.0,
        half_arc_mm: f64::from(half_arc % 16),
        half_height_mm: f64::from(half_height % 16),
        pass_angle_deg: 1.0,
    }
}

fn weight(w: u8) -> f64 {
    f64::from(w % 4 + 1)
}

/// `|v − c| ≤ half` with the module's touching widening.
fn meets(v: f64, c: f64, half: f64) -> bool {
    c - half - TOUCH_MM <= v && v <= c + half + TOUCH_MM
}

/// REQ-OVERLAP-1: `vertical` is the maximum over every height: at any
/// probe height (a half-millimetre grid, so probes fall on, between and
/// beyond the interval ends) the channels meeting it weigh at most the
/// reported weight and number at most the reported count; the reported
/// height holds the reported weight (before its rounding-up margin).
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
#[cfg_attr(not(kani), test)]
fn vertical_enumeration_is_the_maximum() {
    for_all!(([(i8, u8, u8); N], i8), |(chs, probe)| {
        let fps: Vec<Footprint> = chs
            .iter()
            .enumerate()
            .map(|(i, &(z, h, _))| footprint(i, 0, z, 0, h))
            .collect();
        let ws: Vec<f64> = chs.iter().map(|&(_, _, w)| weight(w)).collect();
        let m = overlap::vertical(&fps, &ws);
        let p = f64::from(probe) / 2.0;
        let at = |v: f64| {
            fps.iter()
                .zip(&ws)
                .filter(|(f, _)| meets(v, f.z_mm, f.half_height_mm))
                .fold((0.0, 0u32), |(w, n), (_, &wi)| (w + wi, n + 1))
        };
        let (w_p, n_p) = at(p);
        cover!(n_p == 3, "three channels meet one height");
        cover!(
            n_p == 2 && m.count_at_worst == 2,
            "two channels meet the worst height"
        );
        assert!(m.weight >= w_p, "a height outweighs the enumeration");
        assert!(m.count >= n_p, "a height holds more channels");
        assert!(m.count <= N as u32 && m.count_at_worst <= m.count);
        let (w_worst, n_worst) = at(m.height_mm);
        assert_eq!(n_worst, m.count_at_worst);
        let margin = if n_worst > 1 { 1.0 + SUM_MARGIN } else { 1.0 };
        assert_eq!(m.weight, w_worst * margin);
    });
    #[cfg(not(kani))]
    crate::verification::assert_covered(&[
        "three channels meet one height",
        "two channels meet the worst height",
    ]);
}

/// REQ-OVERLAP-1: `group` with a window of 0 (pulses fired together) is
/// the maximum over every point and every firing slot: at any probe point
/// (arc × height, half-millimetre grid) the channels of any one slot whose
/// boxes hold it weigh at most the reported weight and number at most the
/// reported count; channels of different slots never add up (no window
/// holds two slots), and a probe of two slots is reported as such only
/// when the window is widened to hold both.
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
#[cfg_attr(not(kani), test)]
fn group_enumeration_is_the_maximum() {
    for_all!(([(i8, i8, u8, u8, u8, u8); N], (i8, i8, u8, bool)), |(
        chs,
        (px, pz, ps, steer),
    )| {
        let cycle_s = 1.0;
        let fps: Vec<Footprint> = chs
            .iter()
            .enumerate()
            .map(|(i, &(x, z, ha, hh, _, _))| footprint(i, x, z, ha, hh))
            .collect();
        let ws: Vec<f64> = chs.iter().map(|c| weight(c.4)).collect();
        // Slots 0, 0.25 or 0.5 of the cycle (exact). `steer` (random
        // testing only reaches three boxes sharing a point of one slot
        // rarely): one slot, the probe at channel 0's centre.
        let slot_of = |k: u8| if steer { 0.0 } else { f64::from(k % 3) * 0.25 };
        let slots: Vec<f64> = chs.iter().map(|c| slot_of(c.5)).collect();
        let circ = core::f64::consts::TAU;
        let (m, spans) = overlap::group(&fps, &ws, &slots, cycle_s, 0.0, 0.0, circ);
        let (x, z) = if steer {
            (fps[0].psi_rad, fps[0].z_mm)
        } else {
            (f64::from(px) / 2.0, f64::from(pz) / 2.0)
        };
        let slot = slot_of(ps);
        let (w_p, n_p) = fps
            .iter()
            .zip(&ws)
            .zip(&slots)
            .filter(|((f, _), &s)| {
                s == slot
                    && meets(x, f.psi_rad, f.half_arc_mm)
                    && meets(z, f.z_mm, f.half_height_mm)
            })
            .fold((0.0, 0u32), |(w, n), ((_, &wi), _)| (w + wi, n + 1));
        cover!(n_p == 3, "three channels fired together meet one point");
        cover!(
            n_p == 1 && m.count >= 2,
            "a lone pulse where a pair exists elsewhere"
        );
        assert!(m.weight >= w_p, "a point outweighs the enumeration");
        assert!(m.count >= n_p, "a point holds more channels");
        assert!(m.count <= N as u32 && m.count_at_worst <= m.count);
        // Window 0: every pulse is alone in its time, no channel twice.
        assert!(!spans, "a window of 0 spans two times");
        // The same heads with a window holding every slot: every channel
        // meeting the probe counts, whatever its slot.
        let (all, spans_all) = overlap::group(&fps, &ws, &slots, cycle_s, 0.6, 0.0, circ);
        let n_any = fps
            .iter()
            .filter(|f| meets(x, f.psi_rad, f.half_arc_mm) && meets(z, f.z_mm, f.half_height_mm))
            .count() as u32;
        let mut at_probe: Vec<f64> = fps
            .iter()
            .zip(&slots)
            .filter(|(f, _)| {
                meets(x, f.psi_rad, f.half_arc_mm) && meets(z, f.z_mm, f.half_height_mm)
            })
            .map(|(_, &s)| s)
            .collect();
        at_probe.sort_by(f64::total_cmp);
        at_probe.dedup();
        assert!(all.count >= n_any);
        cover!(
            at_probe.len() >= 2,
            "a widened window holds two slots at one point"
        );
        if at_probe.len() >= 2 {
            assert!(spans_all, "two slots meet one point, not reported");
        }
        if spans_all {
            let distinct = slots.iter().any(|&s| s != slots[0]);
            assert!(distinct, "one slot reported as two times");
        }
    });
    #[cfg(not(kani))]
    crate::verification::assert_covered(&[
        "three channels fired together meet one point",
        "a lone pulse where a pair exists elsewhere",
        "a widened window holds two slots at one point",
    ]);
}
