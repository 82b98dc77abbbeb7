//! Tests that pin parts of `eye_safety/head/bound.rs` no other core test
//! reached (`specs/mutants.md`, "`eye_safety/head/*.rs`"). Each names the
//! mutant it kills and works its expected value out by hand.

use gaze_lidar_core::eye_safety::head::bound::{
    slot_windows, SlotWindow, SLOT_WINDOWS_BUDGET, SLOT_WINDOWS_MAX,
};
use gaze_lidar_core::eye_safety::head::geometry::Footprint;
use gaze_lidar_core::eye_safety::head::overlap::{SUM_MARGIN, TOUCH_MM};

/// A footprint at height `z_mm`, 10 mm tall (half-height 5 mm), on the
/// axis of a 100 mm surface.
fn fp(z_mm: f64) -> Footprint {
    Footprint {
        index: 0,
        psi_rad: 0.0,
        z_mm,
        slant_mm: 100.0,
        width_mm: 3.0,
        cos_beta: 1.0,
        half_arc_mm: 5.0,
        half_height_mm: 5.0,
        pass_angle_deg: 0.1f64.to_degrees(),
    }
}

/// `1e-9·cycle`, the early start of every range but the first.
fn eps(cycle_s: f64) -> f64 {
    1e-9 * cycle_s
}

/// Kills `head/bound.rs` `slot_windows`: `f.z_mm - f.half_height_mm -
/// overlap::TOUCH_MM` → `… + overlap::TOUCH_MM` (a height interval's lower
/// end) and `f.z_mm + f.half_height_mm + overlap::TOUCH_MM` → `… -
/// overlap::TOUCH_MM` (its upper end). Either narrows every interval by
/// `2·TOUCH_MM`, so two channels whose intervals miss by less than
/// `2·TOUCH_MM` (a rounding error of the geometry) no longer meet one
/// height: the weight of a window that holds both their slots falls from
/// two channels' to one's, lowering the short-window figure.
///
/// By hand: intervals `[−5, 5]` and `[5 + 1.5e-9, 15 + 1.5e-9]` mm (half
/// heights 5 mm) are 1.5e-9 mm apart, within the widening on both ends
/// (`5 + 1e-9 ≥ 5 + 1.5e-9 − 1e-9`): one height meets both. Slots 0 and
/// 10 µs of a 100 µs cycle: differences 0, 10 and 90 µs; ranges
/// `[0, 10 µs − ε)` (one channel: weight 1), `[10 µs − ε, 90 µs − ε)` and
/// `[90 µs − ε, cycle·(1 − 1e-9))` (both: `2·(1 + SUM_MARGIN)`). With the
/// intervals 3e-9 mm apart (beyond the widening) every range holds one.
#[test]
fn slot_windows_meet_within_the_touch_widening() {
    assert_eq!(TOUCH_MM, 1e-9);
    let cycle = 1e-4;
    let both = 2.0 * (1.0 + SUM_MARGIN);
    let w = slot_windows(
        &[fp(0.0), fp(10.0 + 1.5e-9)],
        &[1.0, 1.0],
        &[0.0, 1e-5],
        cycle,
    );
    let weights: Vec<f64> = w.iter().map(|r| r.weight).collect();
    assert_eq!(weights, [1.0, both, both], "{w:?}");
    // The widening is symmetric: the higher channel listed first.
    let w = slot_windows(
        &[fp(10.0 + 1.5e-9), fp(0.0)],
        &[1.0, 1.0],
        &[1e-5, 0.0],
        cycle,
    );
    let weights: Vec<f64> = w.iter().map(|r| r.weight).collect();
    assert_eq!(weights, [1.0, both, both], "{w:?}");
    let w = slot_windows(
        &[fp(0.0), fp(10.0 + 3e-9)],
        &[1.0, 1.0],
        &[0.0, 1e-5],
        cycle,
    );
    let weights: Vec<f64> = w.iter().map(|r| r.weight).collect();
    assert_eq!(weights, [1.0, 1.0, 1.0], "{w:?}");
}

/// The ranges of `m` channels at one height, slot `i·cycle/m` each: the
/// differences are `k·cycle/m`, `k = 0 … m − 1`.
fn evenly_slotted(m: usize, cycle_s: f64) -> Vec<SlotWindow> {
    let fps = vec![fp(0.0); m];
    let scales = vec![1.0; m];
    let slots: Vec<f64> = (0..m).map(|i| i as f64 * cycle_s / m as f64).collect();
    slot_windows(&fps, &scales, &slots, cycle_s)
}

/// Kills the subsampling of `head/bound.rs` `slot_windows` (`if b.len() >
/// SLOT_WINDOWS_MAX { … b[k * (m - 1) / (SLOT_WINDOWS_MAX - 1)] … }`): its
/// comparison and index arithmetic. A subsample that drops the last
/// difference, repeats or reorders differences, or keeps more than
/// `SLOT_WINDOWS_MAX`, gives other ranges and weights than these.
///
/// By hand: 100 channels at one height, slot `i` µs of a 100 µs cycle:
/// differences `0, 1, …, 99` µs (100 > 64), subsampled to `d_k =
/// ⌊99·k/63⌋` µs, `k = 0 … 63` (0 and 99 kept). Range `k` starts at
/// `d_k − ε` (0 for the first), ends at `d_{k+1} − ε` and holds the
/// differences below `d_{k+1}`: `d_{k+1}` channels from any start (every
/// start sees the same differences), weight `d_{k+1}·(1 + SUM_MARGIN)`
/// (1 for the first, `d_1 = 1`); the last ends at `cycle·(1 − 1e-9)` and
/// holds all 100. With 64 channels (64 differences, not over the maximum)
/// every difference is kept: range `k` starts at `k·cycle/64 − ε` and
/// holds `k + 1` channels.
#[test]
fn slot_windows_subsample_keeps_the_first_and_last_evenly() {
    assert_eq!(SLOT_WINDOWS_MAX, 64);
    let cycle = 1e-4;
    for (m, want_d) in [
        (
            100usize,
            (0..64).map(|k| 99 * k / 63).collect::<Vec<usize>>(),
        ),
        (64, (0..64).collect()),
    ] {
        let w = evenly_slotted(m, cycle);
        assert_eq!(w.len(), 64, "{m}: {w:?}");
        for (k, (r, &d)) in w.iter().zip(&want_d).enumerate() {
            let lo = if k == 0 {
                0.0
            } else {
                d as f64 * cycle / m as f64 - eps(cycle)
            };
            assert!((r.lo_s - lo).abs() < 1e-18, "{m}: range {k}: {r:?}");
            // Up to the next kept difference, excluded (all for the last).
            let n = want_d.get(k + 1).copied().unwrap_or(m);
            let weight = if n == 1 {
                1.0
            } else {
                n as f64 * (1.0 + SUM_MARGIN)
            };
            assert!(
                (r.weight - weight).abs() <= 1e-12 * weight,
                "{m}: range {k}: {r:?}, want {weight}"
            );
        }
        for p in w.windows(2) {
            assert_eq!(p[0].hi_s, p[1].lo_s, "{m}");
        }
        assert_eq!(w.last().unwrap().hi_s, cycle * (1.0 - 1e-9), "{m}");
    }
}

/// Kills `head/bound.rs` `slot_windows`: `n.saturating_mul(n)
/// .saturating_mul(distinct.len()) > SLOT_WINDOWS_BUDGET` → `>=` and → `==`
/// (the enumeration formed at exactly the budget is refused, or formed
/// beyond it).
///
/// By hand: 256 channels at one height, 64 distinct slots (four channels
/// each, slot `j` µs of a 100 µs cycle): `256² · 64 = 2²²`, exactly the
/// budget: the ranges are formed (the differences mod the cycle are `0 …
/// 99` µs, subsampled to 64 ranges; the last holds all 256 channels). 257
/// channels (one more at slot 0): over it, no ranges.
#[test]
fn slot_windows_budget_is_inclusive() {
    assert_eq!(SLOT_WINDOWS_BUDGET, 1 << 22);
    let cycle = 1e-4;
    let slots: Vec<f64> = (0..256).map(|i| (i % 64) as f64 * 1e-6).collect();
    assert_eq!(256 * 256 * 64, SLOT_WINDOWS_BUDGET);
    let w = slot_windows(&vec![fp(0.0); 256], &vec![1.0; 256], &slots, cycle);
    assert_eq!(w.len(), 64);
    let last = w.last().unwrap().weight;
    assert!((last - 256.0 * (1.0 + SUM_MARGIN)).abs() < 1e-9, "{last}");
    let mut more = slots.clone();
    more.push(0.0);
    let w = slot_windows(&vec![fp(0.0); 257], &vec![1.0; 257], &more, cycle);
    assert!(w.is_empty(), "{w:?}");
}

/// Kills `head/bound.rs` `head_figures`: the margins on the turns that
/// widen the boxes of `W_g` (`smear = r·ω·t_g·(1 + SUM_MARGIN)`) and of
/// `W_inst` (`turn_per_pulse = r·ω·cycle·(1 + SUM_MARGIN)`), each →
/// `r·ω·t·(1 − SUM_MARGIN)` or `r·ω·t / (1 + SUM_MARGIN)`. The margin covers
/// the rounding of the product (a few ulps); without it the turn can fall
/// below the exact `r·ω·t`, so two channels whose boxes that turn joins are
/// counted apart and the weight (every rule's factor) falls from two
/// channels' to one's.
///
/// By hand: two radial channels (origin on the axis, `ψ` = the azimuth
/// offset) 10° apart at one height and one slot, on a 100 mm surface: their
/// boxes `[x − h − TOUCH, x + h + turn + TOUCH]` (`x = ψ·r`, `h` the half
/// arc) meet when the turn reaches `need = (x₁ − h₁) − (x₀ + h₀) −
/// 2·TOUCH_MM` (≈ 10 mm). At a spin whose exact turn is `need·(1 −
/// 0.5e-12)` the margin lifts it to `need·(1 + 0.5e-12)`: both channels
/// (weight `2·(1 + SUM_MARGIN)`); at `need·(1 − 3e-12)` it does not reach:
/// one (weight 1, within rounding). Both for the grouping window (`weight_group`) and one cycle
/// (`weight_instant`). The margins are 5e-12 mm, the rounding of the
/// products about 1e-15 mm.
#[test]
fn head_turns_carry_their_margin() {
    use gaze_lidar_core::eye_safety::exposure::laser;
    use gaze_lidar_core::eye_safety::head::bound::{head_figures, HeadFigures};
    use gaze_lidar_core::eye_safety::head::geometry::footprints;
    use gaze_lidar_core::eye_safety::head::{Channel, Head};
    use gaze_lidar_core::eye_safety::EyeSafetyParams;
    let params = EyeSafetyParams {
        wavelength_nm: 905.0,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: 5.0,
        head: None,
    };
    let head = Head {
        cycle_s: 1e-4,
        origin_radius_mm: 0.0,
        origin_height_mm: 0.0,
        exit_diameter_mm: 5.0,
        divergence_mrad: 0.0,
        aperture_distance_mm: 100.0,
        channels: [0.0, 10.0]
            .iter()
            .zip(0..)
            .map(|(&azimuth_offset_deg, id)| Channel {
                id,
                elevation_deg: 0.0,
                azimuth_offset_deg,
                slot_s: 0.0,
                power_scale: 1.0,
            })
            .collect(),
    };
    let l = laser(&params, 1e4).unwrap();
    let r = head.aperture_distance_mm;
    let fps = footprints(&head, l.band.aperture_mm());
    let x = |i: usize| fps[i].psi_rad * r;
    let need = (x(1) - fps[1].half_arc_mm) - (x(0) + fps[0].half_arc_mm) - 2.0 * TOUCH_MM;
    assert!(need > 5.0 && need < 15.0, "{need}");
    let at = |spin: f64| head_figures(&head, &params, &l, spin).unwrap();
    let still = at(0.0);
    // One channel's weight, two channels', each within rounding.
    let (one, two) = (1.0, 2.0 * (1.0 + SUM_MARGIN));
    let near = |w: f64, want: f64| (w - want).abs() < 1e-9;
    assert!(
        near(still.weight_group, one) && near(still.weight_instant, one),
        "{still:?}"
    );
    for (t_s, group) in [(still.group_window_s, true), (head.cycle_s, false)] {
        let weight = |f: &HeadFigures| {
            if group {
                f.weight_group
            } else {
                f.weight_instant
            }
        };
        let name = if group {
            "weight_group"
        } else {
            "weight_instant"
        };
        // The spin whose exact turn in `t_s` is `need·k`.
        let spin = |k: f64| need * k / (r * t_s);
        let f = at(spin(1.0 - 0.5e-12));
        assert!(near(weight(&f), two), "{name}: {f:?}");
        let f = at(spin(1.0 - 3e-12));
        assert!(near(weight(&f), one), "{name}: {f:?}");
    }
}

/// Kills `head/bound.rs` `union_passes`: `x = 1 + spread/pass·(1 + 1e-12)` →
/// `spread/pass·(1 − 1e-12)`, the spread's share rounded down instead of
/// up before the ceiling. The channels' passes lie inside an arc of
/// `spread + pass`, at most `k = ⌈1 + spread/pass⌉` passes; the share is
/// computed in floats (the difference, the conversion, the division), so at
/// a whole number of passes it may come out a few ulps low and the ceiling
/// one pass short. The stated rounding counts one pass more there; the
/// mutant one fewer (a smaller union, fewer pulses counted for C5, a larger
/// C5, a lower figure).
///
/// By hand: two radial channels (origin on the axis, `ψ` = the azimuth
/// offset) on a 100 mm surface, 7 mm aperture, 5 mm beam: the pass is
/// `2·asin(6/100)` = 6.8797° (rounded up by the geometry's 1e-12). Offsets 0 and two passes: share 2 (within
/// rounding), `⌈1 + 2·(1 + 1e-12)⌉ = 4`; 0 and 1.5 passes: `⌈2.5⌉ = 3`.
#[test]
fn union_passes_rounds_a_whole_share_up() {
    use gaze_lidar_core::eye_safety::exposure::laser;
    use gaze_lidar_core::eye_safety::head::bound::head_figures;
    use gaze_lidar_core::eye_safety::head::geometry::footprints;
    use gaze_lidar_core::eye_safety::head::{Channel, Head};
    use gaze_lidar_core::eye_safety::EyeSafetyParams;
    let params = EyeSafetyParams {
        wavelength_nm: 905.0,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: 5.0,
        head: None,
    };
    let l = laser(&params, 1e4).unwrap();
    let head = |offsets: &[f64]| Head {
        cycle_s: 1e-4,
        origin_radius_mm: 0.0,
        origin_height_mm: 0.0,
        exit_diameter_mm: 5.0,
        divergence_mrad: 0.0,
        aperture_distance_mm: 100.0,
        channels: offsets
            .iter()
            .zip(0..)
            .map(|(&azimuth_offset_deg, id)| Channel {
                id,
                elevation_deg: 0.0,
                azimuth_offset_deg,
                slot_s: 0.0,
                power_scale: 1.0,
            })
            .collect(),
    };
    let pass_deg = (2.0 * 0.06f64.asin()).to_degrees() * (1.0 + 1e-12);
    for (share, k) in [(2.0, 4), (1.5, 3)] {
        let h = head(&[0.0, share * pass_deg]);
        let fps = footprints(&h, l.band.aperture_mm());
        // The share as the code sees it: within rounding of the intended.
        let pass = fps[0].pass_angle_deg.max(fps[1].pass_angle_deg);
        assert!((pass - pass_deg).abs() < 1e-12, "{pass}");
        let seen = (fps[1].psi_rad - fps[0].psi_rad).to_degrees() / pass;
        assert!((seen - share).abs() < 1e-14, "{seen}");
        let f = head_figures(&h, &params, &l, 100.0).unwrap();
        assert_eq!(f.union_passes, k, "share {share}: {f:?}");
    }
}
