//! Open readings of the standard: profiles the checker certifies whose Class 1
//! ratio, computed by hand from IEC 60825-1:2014's definitions, exceeds 1
//! under a stated reading of the standard. Ignored so the suite stays green
//! until the reading is settled against a licensed copy of the standard.

use gaze_lidar_core::eye_safety::evaluate_profile;
use gaze_lidar_core::testing::eye_cases::load;

/// 905 nm, 6 µs pulses (longer than T_i = 5 µs, shorter than 0.25 s),
/// 7812.5 Hz, one bin of 1.62 mW at a uniform 125.66 rad/s (20 Hz), 8 mm beam.
///
/// By hand: E = 1.62e-3 / 7812.5 = 2.0736e-7 J per pulse; C4 = 10^(0.002·205)
/// = 2.5704; AEL(6 µs) = 7e-4 · C4 · (6e-6)^0.75 = 2.1813e-7 J. Pass =
/// (7 + 8) mm / 100 mm = 0.15 rad = 1.194 ms at 125.66 rad/s: at most 10
/// pulses per pass; ⌊(10 s + pass)/50 ms⌋ + 1 = 201 passes within T2, so
/// N = 2010 pulses within T2 and C5 = 5 · 2010^−0.25 = 0.7467.
/// The checker takes C5 = 1 for pulses longer than T_i (ratio 0.951 for the
/// single pulse; it certifies at 0.995, bound by the within-pass envelope).
/// If C5 applies to every pulse duration below 0.25 s, as the reading "C5 is
/// only applicable to pulse durations shorter than 0.25 s" has it, the
/// single-pulse ratio is 2.0736e-7 / (2.1813e-7 · 0.7467) = 1.273.
#[test]
#[ignore = "open reading: depends on C5 for T_i < τ < 0.25 s (checker: C5 = 1); settle against the standard"]
fn c5_for_pulses_longer_than_ti_905() {
    let p = load("breaker_c5_pulse_longer_than_ti_905.json");
    let params = p.limits.eye_safety.clone().expect("eye-safety parameters");
    let r = evaluate_profile(&p, &params).expect("evaluates");
    let by_hand = 1.62e-3
        / 7812.5
        / (7e-4 * 10f64.powf(0.002 * 205.0) * 6e-6f64.powf(0.75) * 5.0 * 2010f64.powf(-0.25));
    assert!(by_hand > 1.27, "hand figure {by_hand}");
    assert!(
        r.worst_ratio >= by_hand,
        "checker {} below the hand figure {by_hand} (C5 applied to a 6 µs pulse)",
        r.worst_ratio
    );
}
