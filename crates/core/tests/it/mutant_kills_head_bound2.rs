//! Tests that pin the head's Rule 1 and stalled-rotor figures of
//! `eye_safety/head/bound.rs` (`stalled_ratio`, `power_scale_to_certify`) where
//! no other core test reached them (`specs/mutants.md`, "`eye_safety/head/*.rs`").
//! Each names the mutant it kills and works its expected value out by hand.

use gaze_lidar_core::eye_safety::ael::Band;
use gaze_lidar_core::eye_safety::bound::{Laser, RATIO_MARGIN};
use gaze_lidar_core::eye_safety::head::bound::stalled_ratio;
use gaze_lidar_core::eye_safety::head::{power_scale_to_certify, HeadFigures};

/// 905 nm, 5 ns pulses at `f_p`.
fn laser905(f_p: f64) -> Laser {
    Laser {
        band: Band::RetinalNir,
        c4: 1.0,
        pulse_duration_s: 5e-9,
        pulse_rate_hz: f_p,
    }
}

/// Figures of a head whose `count` channels meet one aperture with the
/// rotor stalled, each at its own instant (no two at once, no group), of
/// `slots` distinct slots at one height, and of total weight `weight`.
fn stalled_figures(count: u32, slots: u32, weight: f64) -> HeadFigures {
    HeadFigures {
        aperture_distance_mm: 100.0,
        weight_vertical: weight,
        weight_stalled: weight,
        count_stalled: count,
        ..gaze_lidar_core::testing::head_figures(count, slots)
    }
}

/// Kills `head/bound.rs` `stalled_ratio`: `n = min(K_s, S_v) ·
/// max_pulses_in(T2, f_p)` → `min(K_s, S_v) + max_pulses_in(T2, f_p)` (the
/// pulse count of the stalled head's Rule 1). The sum undercounts the
/// pulses of two or more slots, and a smaller count is a larger C5, a lower
/// figure.
///
/// By hand: at 1 kHz a T2 window of 10 s holds `⌊10⁴⌋ + 1` = 10001 pulses
/// of one channel. Two channels of half power each (weight 1) at their own
/// slots: `N = 2 · 10001` = 20002, `C5 = 5·N^(−1/4)`
/// (`600 < N < 24414`: neither 1 nor the 0.4 floor). At most one channel
/// at any point (`power_scale_max` 1): the Rule 1 term is `E/(C5(20002)·AEL)`,
/// against the single channel's `E/(C5(10001)·AEL)` (its own Rule 1 binds at
/// 905 nm and 1 kHz: per pulse `1/(0.5·7.7e-8)` J⁻¹ against 10⁴ pulses over
/// the 3.9e-3 J of the 10 s AEL), so the figure is `2^(1/4)` times the
/// single channel's (the weight 1 is the same on both sides). With the sum,
/// `N` = 10003 and the ratio `(10003/10001)^(1/4)` ≈ 1.00005. Of one slot
/// (`S_v` = 1: the two channels' pulses fall at the same instants,
/// `N` = 10001) the figure is the single channel's.
#[test]
fn stalled_rule1_counts_every_slot_s_pulses() {
    let laser = laser905(1000.0);
    let p = 2.0;
    let one = stalled_ratio(&stalled_figures(1, 1, 1.0), &laser, p);
    assert!(one > 0.0 && one.is_finite(), "{one}");
    let two_slots = stalled_ratio(&stalled_figures(2, 2, 1.0), &laser, p);
    let want = 2f64.powf(0.25) * (1.0 + RATIO_MARGIN);
    assert!(
        (two_slots / one / want - 1.0).abs() < 1e-9,
        "{two_slots} / {one} = {}, want {want}",
        two_slots / one
    );
    let one_slot = stalled_ratio(&stalled_figures(2, 1, 1.0), &laser, p);
    assert!(
        (one_slot / one / (1.0 + RATIO_MARGIN) - 1.0).abs() < 1e-9,
        "{one_slot} / {one}"
    );
}

/// Kills `head/bound.rs` `power_scale_to_certify`: `worst_ratio > 0.0` →
/// `worst_ratio >= 0.0`. A bound of zero certifies at every scale
/// (`+∞`), whichever the sign of the zero (that a profile's worst ratio
/// can come out as `-0.0` is not shown; `bound::binding` keeps the first of
/// equal ratios, so it is not excluded either). With `>=`, `-0.0` takes the
/// quotient branch: `(1 − 10⁻⁹)/(−0) = −∞`, no scale at all.
///
/// By hand: `+0` and `−0` give `+∞`; 2 gives `(1 − 10⁻⁹)/2`, which times
/// 2 is below 1; a ratio of 1 gives `1 − 10⁻⁹`.
#[test]
fn a_zero_bound_of_either_sign_certifies_at_every_scale() {
    assert_eq!(power_scale_to_certify(0.0), f64::INFINITY);
    assert_eq!(power_scale_to_certify(-0.0), f64::INFINITY);
    assert_eq!(power_scale_to_certify(2.0), (1.0 - 1e-9) / 2.0);
    assert!(2.0 * power_scale_to_certify(2.0) < 1.0);
    assert_eq!(power_scale_to_certify(1.0), 1.0 - 1e-9);
}
