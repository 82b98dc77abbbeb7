//! Core-level tests of `eye_safety::exposure` (found by `cargo mutants`):
//! parameter validation, the pass angle and the report's derived fields,
//! against values constructed by hand.

use gaze_lidar_core::eye_safety::bound::Seg;
use gaze_lidar_core::eye_safety::exposure::{laser, pass_angle_deg, segments};
use gaze_lidar_core::eye_safety::{evaluate_profile, evaluate_segments, EyeSafetyParams};
use gaze_lidar_core::model::lidar::PowerAccounting;
use gaze_lidar_core::profile::{Bin, Profile, PROFILE_FORMAT};
use std::f64::consts::TAU;

use gaze_lidar_core::testing::{self, params, params_at};

/// `n` equal bins at 10 Hz; bin `i` at `power(i)`.
fn segs(n: usize, power: impl Fn(usize) -> f64) -> Vec<Seg> {
    let w = TAU * 10.0;
    (0..n)
        .map(|i| Seg {
            start_deg: 360.0 * i as f64 / n as f64,
            width_deg: 360.0 / n as f64,
            power_w: power(i),
            spin_start_rad_s: w,
            spin_end_rad_s: w,
        })
        .collect()
}

#[test]
fn laser_parameters_are_validated() {
    assert!(laser(&params(), 20_000.0).is_ok());
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = laser(&params(), bad).unwrap_err();
        assert!(e.to_string().contains("pulse_rate_hz"), "{bad}: {e}");
    }
    // Pulses overlap at rate × duration = 1 exactly; just below is fine.
    let e = laser(&params(), 2e8).unwrap_err();
    assert!(e.to_string().contains("overlap"), "{e}");
    assert!(laser(&params(), 1.999e8).is_ok());
    let bad = EyeSafetyParams {
        wavelength_nm: 1200.0,
        ..params()
    };
    assert!(laser(&bad, 20_000.0).is_err());
}

#[test]
fn pass_angle_is_aperture_plus_beam_over_100_mm() {
    let l = laser(&params(), 20_000.0).unwrap();
    // 905 nm: 7 mm aperture + 8 mm beam at 100 mm: the aperture centre within
    // 7.5 mm of the ray, 2·asin(0.075) = 8.6026° (the chord laid as an arc,
    // 15/100 rad = 8.5944°, is short).
    let expected = (2.0 * 0.075f64.asin()).to_degrees();
    assert!((pass_angle_deg(&params(), &l) - expected).abs() < 1e-10);
    assert!(pass_angle_deg(&params(), &l) > (15.0f64 / 100.0).to_degrees());
    let p1550 = params_at(1550.0, 1.5);
    let l = laser(&p1550, 20_000.0).unwrap();
    // 1550 nm: Table 10's largest aperture, 1.5·10^0.375 = 3.5571 mm, + 1.5 mm.
    let expected = (2.0 * ((1.5 * 10f64.powf(0.375) + 1.5) / 200.0).asin()).to_degrees();
    assert!((pass_angle_deg(&p1550, &l) - expected).abs() < 1e-10);
    // A beam wider than the circle is capped at a full turn.
    let huge = EyeSafetyParams {
        beam_diameter_mm: 999.0,
        head: None,
        ..params()
    };
    let l = laser(&huge, 20_000.0).unwrap();
    assert_eq!(pass_angle_deg(&huge, &l), 360.0);
}

#[test]
fn report_fields_follow_from_the_bound() {
    // One hot bin at 4× the rest.
    let s = segs(36, |i| if i == 9 { 4e-4 } else { 1e-4 });
    let r = evaluate_segments(&s, &params(), 20_000.0).unwrap();
    let pass = (2.0 * 0.075f64.asin()).to_degrees();
    assert!((r.pass_angle_deg - pass).abs() < 1e-10);
    assert_eq!(r.margin, 1.0 / r.worst_ratio);
    assert_eq!(
        r.worst_ratio,
        r.rule_ratios.iter().copied().fold(0.0, f64::max)
    );
    // Constant spin: every pass lasts pass / ω; the most pulses in it are
    // floor(T·f) + 1 for some clock phase (never fewer).
    let t_pass = pass.to_radians() / (TAU * 10.0);
    assert!((r.max_pass_duration_s - t_pass).abs() <= 1e-9 * t_pass);
    let k = (t_pass * 20_000.0).floor() + 1.0;
    assert!(
        r.max_pulses_per_pass >= k && r.max_pulses_per_pass <= k + 1.0,
        "{} vs {k}",
        r.max_pulses_per_pass
    );
    // The worst aperture sees the hot bin (90°..100°): within a pass of it.
    assert!(
        (90.0 - pass..=100.0 + pass).contains(&r.worst_azimuth_deg),
        "{}",
        r.worst_azimuth_deg
    );
    // The most energy one pass can deliver: at least the hot bin's power
    // over the pass (the pass fits in the 10° bin), at most one pulse more.
    let lo = 4e-4 * t_pass;
    assert!(
        r.max_pass_energy_j >= lo * (1.0 - 1e-9)
            && r.max_pass_energy_j <= lo + 4e-4 / 20_000.0 * 1.000001,
        "{} vs {lo}",
        r.max_pass_energy_j
    );
    // Stalled rotor: the top power, not the lowest, decides; and it is
    // linear in the power.
    let cold = evaluate_segments(&segs(36, |_| 1e-4), &params(), 20_000.0).unwrap();
    assert!(
        (r.stalled_rotor_ratio / cold.stalled_rotor_ratio - 4.0).abs() < 1e-9,
        "{} vs {}",
        r.stalled_rotor_ratio,
        cold.stalled_rotor_ratio
    );
    // Four times the power in one bin raises the worst ratio.
    assert!(r.worst_ratio > cold.worst_ratio * 2.0);
}

#[test]
fn empty_or_too_slow_scans_are_errors() {
    let e = evaluate_segments(&[], &params(), 20_000.0).unwrap_err();
    assert!(e.to_string().contains("bins"), "{e}");
    // A pass longer than 3·10⁴ s: the spin is far too slow for Table 3.
    let mut s = segs(4, |_| 1e-4);
    for x in &mut s {
        x.spin_start_rad_s = 1e-9;
        x.spin_end_rad_s = 1e-9;
    }
    let e = evaluate_segments(&s, &params(), 20_000.0).unwrap_err();
    assert!(e.to_string().contains("pass duration"), "{e}");
}

#[test]
fn a_profile_is_read_as_its_segments_at_its_pulse_rate() {
    let s = segs(12, |i| 1e-4 * (1.0 + i as f64));
    let p = Profile {
        format: PROFILE_FORMAT.to_owned(),
        frame_rate_hz: 10.0,
        pulse_rate_hz: 50_000.0,
        average_power_w: 1.0,
        power_accounting: PowerAccounting::Angle,
        gaze_deg: None,
        limits: testing::limits((0.0, 1.0), (0.0, 1e3)),
        bins: s
            .iter()
            .map(|x| Bin {
                start_deg: x.start_deg,
                width_deg: x.width_deg,
                power_w: x.power_w,
                spin_start_rad_s: x.spin_start_rad_s,
                spin_end_rad_s: x.spin_end_rad_s,
                region: None,
                dwell_s: None,
            })
            .collect(),
        mode: None,
        summary: None,
        optimality: None,
    };
    let back = segments(&p);
    assert_eq!(back.len(), s.len());
    for (a, b) in back.iter().zip(&s) {
        assert_eq!(
            (
                a.start_deg,
                a.width_deg,
                a.power_w,
                a.spin_start_rad_s,
                a.spin_end_rad_s
            ),
            (
                b.start_deg,
                b.width_deg,
                b.power_w,
                b.spin_start_rad_s,
                b.spin_end_rad_s
            )
        );
    }
    let from_profile = evaluate_profile(&p, &params()).unwrap();
    assert_eq!(
        from_profile,
        evaluate_segments(&s, &params(), 50_000.0).unwrap()
    );
    assert_ne!(
        from_profile,
        evaluate_segments(&s, &params(), 20_000.0).unwrap()
    );
}

/// A pass holds at most `⌊t_b·f_p⌋ + 1` pulses of each bin it crosses: a
/// lone hot 1° bin that the head crosses in 1.5 pulse spacings gives at most
/// two hot pulses per pass, whatever the clock phase — 2·P·Δ, where the
/// envelope alone allows (1.5 + 1)·P·Δ and the pass-wide count
/// `K·P_max·Δ` thirteen pulses.
#[test]
fn pass_energy_is_capped_per_bin() {
    // 360 bins of 1° at 10 Hz: 1/3600 s per bin = 1.5 Δ at 5400 Hz.
    let f_p = 5400.0;
    let s = segs(360, |i| if i == 100 { 1.0 } else { 0.0 });
    let r = evaluate_segments(&s, &params(), f_p).unwrap();
    let two_pulses = 2.0 / f_p;
    assert!(
        (r.max_pass_energy_j - two_pulses).abs() <= 1e-12 * two_pulses,
        "pass energy {} J, two hot pulses {} J",
        r.max_pass_energy_j,
        two_pulses
    );
}

/// `EyeSafetyParams::validate` (found by `cargo mutants` on `eye_safety/mod.rs`):
/// the band of each wavelength, and the beam diameter's open range `(0, 1000)` mm
/// at both edges, negative, NaN and infinite.
#[test]
fn eye_safety_params_are_validated_at_their_edges() {
    use gaze_lidar_core::eye_safety::ael::Band;
    use gaze_lidar_core::eye_safety::EyeSafetyError;
    let with = params_at;
    // Bands by Table 3's wavelength ranges.
    assert_eq!(with(905.0, 8.0).validate(), Ok(Band::RetinalNir));
    assert_eq!(with(1450.0, 8.0).validate(), Ok(Band::Ir1400));
    assert_eq!(with(1550.0, 8.0).validate(), Ok(Band::Ir1500));
    assert!(matches!(
        with(1200.0, 8.0).validate(),
        Err(EyeSafetyError::Ael(_))
    ));
    // Beam diameter: inside the open range is accepted, right up to its edges.
    for ok in [1e-9, 0.5, 999.999] {
        assert_eq!(with(905.0, ok).validate(), Ok(Band::RetinalNir), "{ok}");
    }
    for bad in [
        0.0,
        -0.0,
        -1.0,
        -1e6,
        1000.0,
        1e6,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ] {
        match with(905.0, bad).validate() {
            Err(EyeSafetyError::Param { field, value, .. }) => {
                assert_eq!(field, "beam_diameter_mm", "{bad}");
                assert!(value.to_bits() == bad.to_bits(), "{bad}");
            }
            other => panic!("beam_diameter_mm = {bad}: {other:?}"),
        }
    }
    // A pulse duration outside Table 3 is named as such.
    for bad in [0.0, -5e-9, f64::NAN, 3.1e4] {
        let p = EyeSafetyParams {
            pulse_duration_s: bad,
            ..with(905.0, 8.0)
        };
        match p.validate() {
            Err(EyeSafetyError::Param { field, .. }) => assert_eq!(field, "pulse_duration_s"),
            other => panic!("pulse_duration_s = {bad}: {other:?}"),
        }
    }
}
