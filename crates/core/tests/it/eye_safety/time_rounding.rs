//! Pass durations on near-stopped frames (`bound::count`, "Times from 0°"):
//! every time the bound computes is a time from 0° of the frame, so its
//! rounding is relative to the frame period `T_f`, not to the pass. On a
//! frame of 2.29·10⁶ s a 20-pulse pass was counted 19 (905 nm, certified
//! at 0.9914, true 1.0021) and a 2-pulse pass 1 (1550 nm, certified at
//! 0.990, true 1.98). The pulse counts here are exact: rational arithmetic
//! on the profile's own numbers (every `f64` is a rational), independent of
//! the bound's floating point.

use gaze_lidar_core::eye_safety::ael::APERTURE_IR_MM;
use gaze_lidar_core::eye_safety::bound::Seg;
use gaze_lidar_core::eye_safety::{evaluate_segments, Rule};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::ToPrimitive;

const C4_905: f64 = 2.570395782768864; // 10^(0.002·205)

fn q(x: f64) -> BigRational {
    BigRational::from_float(x).unwrap()
}

use gaze_lidar_core::testing::params_at as params;

fn seg(start_deg: f64, width_deg: f64, power_w: f64, spin_rad_s: f64) -> Seg {
    Seg {
        start_deg,
        width_deg,
        power_w,
        spin_start_rad_s: spin_rad_s,
        spin_end_rad_s: spin_rad_s,
    }
}

/// Where the hot 20° sector sits: from 0°, up to 360° (its times are then
/// ≈ `T_f` from 0°) or across 0°.
#[derive(Debug, Clone, Copy)]
enum At {
    First,
    Last,
    Across,
}

/// A hot sector of 20° at `fast` rad/s and `power_w`, the other 340° dark
/// at `slow` rad/s.
fn near_stopped(at: At, power_w: f64, fast: f64, slow: f64) -> Vec<Seg> {
    match at {
        At::First => vec![seg(0.0, 20.0, power_w, fast), seg(20.0, 340.0, 0.0, slow)],
        At::Last => vec![seg(0.0, 340.0, 0.0, slow), seg(340.0, 20.0, power_w, fast)],
        At::Across => vec![
            seg(0.0, 10.0, power_w, fast),
            seg(10.0, 340.0, 0.0, slow),
            seg(350.0, 10.0, power_w, fast),
        ],
    }
}

/// The exact number of pulses the longest pass over the hot sector can
/// hold: `⌊τ·f⌋ + 1` with `τ = ((aperture + beam)/100 mm)/ω` (the pass
/// angle in radians over the spin), in rationals.
fn exact_pulses(aperture_mm: f64, beam_mm: f64, fast: f64, f_p: f64) -> u64 {
    let x = (q(aperture_mm) + q(beam_mm)) / q(100.0) * q(f_p) / q(fast);
    (x.floor().to_integer() + BigInt::from(1)).to_u64().unwrap()
}

/// The true ratio of `k` pulses of `e_j` within a window of their span
/// `(k − 1)/f_p`, against Table 3 written out here: 905 nm,
/// `7e-4·C4·t^0.75` for 5 µs < t < 9.9 s (the smallest AEL over every
/// window length up to 100 s: the row grows, its 10 s edge value
/// `3.9e-3·C4` is above it there); 1550 nm, 8e-3 J up to 0.35 s (every
/// later row and edge is above).
fn true_ratio(lambda_nm: f64, k: u64, e_j: f64, f_p: f64) -> f64 {
    let span = (k - 1) as f64 / f_p;
    let ael = if lambda_nm < 1000.0 {
        assert!(span > 5e-6 && span < 9.9, "span {span}");
        7e-4 * C4_905 * span.powf(0.75)
    } else {
        assert!(span < 0.35);
        8e-3
    };
    k as f64 * e_j / ael
}

/// Two near-stopped profiles. 905 nm, 152 kHz, 16.2 mW at 600 rad/s
/// over 20°, the rest at 2.6e-6 rad/s (`T_f` = 2.28·10⁶ s), 0.5 mm beam:
/// the pass is `0.075 rad / 600 rad/s` = 1.25·10⁻⁴ s = exactly 19 pulse
/// spacings, so 20 pulses fit (closed interval) for some phase:
/// `20 · 1.0658e-7 J / (7e-4·C4·(1.25e-4)^0.75)` = 1.0021. Before, with the
/// sector at the end of the frame, the checker counted 19 and gave 0.9914.
/// (The slow dark sector's passes also put Rule 1 over: their pulse count
/// takes C5 to 0.4; the test is on the pass train, which must be ≥ the
/// truth.) 1550 nm, 20 kHz, 158 W, the pass exactly one spacing long: two
/// pulses, `2 · 7.9e-3 J / 8e-3 J` = 1.975.
#[test]
fn near_stopped_frames_are_rejected_at_their_true_ratio() {
    // 905 nm.
    let (f_p, p, fast) = (152e3, 16.2e-3, 600.0);
    let k = exact_pulses(7.0, 0.5, fast, f_p);
    assert_eq!(k, 20);
    let truth = true_ratio(905.0, k, p / f_p, f_p);
    assert!((truth - 1.0021).abs() < 1e-4, "{truth}");
    for at in [At::First, At::Last, At::Across] {
        let segs = near_stopped(at, p, fast, 2.6e-6);
        let r = evaluate_segments(&segs, &params(905.0, 0.5), f_p).unwrap();
        assert!(
            r.worst_ratio > 1.0,
            "{at:?}: certified at {}",
            r.worst_ratio
        );
        assert!(
            r.rule_ratios[1] >= truth,
            "{at:?}: pass train {} below the true {truth}",
            r.rule_ratios[1]
        );
    }
    // 1550 nm: the spin that makes the pass exactly one spacing long.
    let (f_p, beam) = (20e3, 0.5);
    let two_h = (APERTURE_IR_MM + beam) / 100.0;
    let fast = two_h * f_p;
    let k = exact_pulses(APERTURE_IR_MM, beam, fast, f_p);
    let p = 158.0;
    let truth = true_ratio(1550.0, k, p / f_p, f_p);
    for at in [At::First, At::Last, At::Across] {
        let segs = near_stopped(at, p, fast, 2.6e-6);
        let r = evaluate_segments(&segs, &params(1550.0, beam), f_p).unwrap();
        assert!(
            r.worst_ratio > 1.0,
            "{at:?}: certified at {}",
            r.worst_ratio
        );
        assert!(
            r.worst_ratio >= truth,
            "{at:?}: {} below the true {truth} ({k} pulses)",
            r.worst_ratio
        );
        if k == 2 {
            assert_eq!(r.binding_rule, Rule::PassTrain);
        }
    }
}

/// A generated family of near-stopped frames: the hot sector first, last
/// or across 0°; its spin set so the pass holds `n` spacings up to the
/// rounding of the spin (the exact count, from rationals, is `n` or
/// `n + 1` pulses); the dark sector from 2.6e-6 rad/s up to 1 rad/s. The
/// checker's pass-train ratio is never below the exact truth (600
/// profiles: the passes whose exact count is one pulse are skipped).
#[test]
fn near_stopped_family_never_below_the_exact_truth() {
    let mut cases = 0;
    for &(lambda, f_p, beam) in &[(905.0, 152e3, 0.5), (905.0, 50e3, 1.0), (1550.0, 20e3, 0.5)] {
        let aperture = if lambda < 1000.0 { 7.0 } else { APERTURE_IR_MM };
        let two_h = (aperture + beam) / 100.0;
        for n in [1u32, 2, 3, 7, 19, 50] {
            for nudge in [-1e-12, 0.0, 1e-12] {
                let fast = two_h * f_p / f64::from(n) * (1.0 + nudge);
                let k = exact_pulses(aperture, beam, fast, f_p);
                if k < 2 || (lambda < 1000.0 && (k - 1) as f64 / f_p <= 5e-6) {
                    continue;
                }
                // A power that puts the truth at 1.001.
                let e_unit = true_ratio(lambda, k, 1.0, f_p);
                let p = 1.001 / e_unit * f_p;
                let truth = true_ratio(lambda, k, p / f_p, f_p);
                let slow_min = two_h / 2.9e4;
                for slow in [slow_min, 1e-5, 1e-3, 1.0] {
                    for at in [At::First, At::Last, At::Across] {
                        let segs = near_stopped(at, p, fast, slow.max(slow_min));
                        let r = evaluate_segments(&segs, &params(lambda, beam), f_p).unwrap();
                        assert!(
                            r.rule_ratios[1] >= truth && r.worst_ratio > 1.0,
                            "{lambda} nm, {f_p} Hz, n {n} (exact {k} pulses), slow {slow}, {at:?}: \
                             pass train {} below the true {truth}",
                            r.rule_ratios[1]
                        );
                        cases += 1;
                    }
                }
            }
        }
    }
    assert_eq!(cases, 600);
}

/// The two profiles as files would hold them, through the certifying
/// checker: rejected, and for eye safety alone (every other limit holds).
#[test]
fn near_stopped_profiles_are_rejected_naming_eye_safety() {
    use gaze_lidar_core::checker::{check, Violation};
    use gaze_lidar_core::model::lidar::{Limits, PowerAccounting};
    use gaze_lidar_core::profile::{Bin, Profile, PROFILE_FORMAT};
    let two_h_1550 = (APERTURE_IR_MM + 0.5) / 100.0;
    for (lambda, f_p, p, fast) in [
        (905.0, 152e3, 16.2e-3, 600.0),
        (1550.0, 20e3, 158.0, two_h_1550 * 20e3),
    ] {
        let segs = near_stopped(At::Last, p, fast, 2.6e-6);
        let bins: Vec<Bin> = segs
            .iter()
            .map(|s| Bin {
                start_deg: s.start_deg,
                width_deg: s.width_deg,
                power_w: s.power_w,
                spin_start_rad_s: s.spin_start_rad_s,
                spin_end_rad_s: s.spin_end_rad_s,
                region: None,
                dwell_s: None,
            })
            .collect();
        let dwell = |b: &Bin| b.width_deg.to_radians() / b.spin_start_rad_s;
        let frame_s: f64 = bins.iter().map(dwell).sum();
        let energy: f64 = bins.iter().map(|b| dwell(b) * b.power_w).sum();
        let profile = Profile {
            format: PROFILE_FORMAT.to_owned(),
            frame_rate_hz: 1.0 / frame_s,
            pulse_rate_hz: f_p,
            average_power_w: energy / frame_s,
            power_accounting: PowerAccounting::Time,
            gaze_deg: None,
            limits: Limits {
                eye_safety: Some(params(lambda, 0.5)),
                ..gaze_lidar_core::testing::limits((0.0, 2.0 * p), (1e-6, 2.0 * fast))
            },
            bins,
            mode: None,
            summary: None,
            optimality: None,
        };
        let v = check(&profile);
        assert!(
            matches!(v.as_slice(), [Violation::EyeSafety { .. }]),
            "{lambda} nm: {v:?}"
        );
        assert!(v[0].to_string().contains("eye"), "{}", v[0]);
    }
}
