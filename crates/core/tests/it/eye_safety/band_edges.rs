//! Exact wavelength band edges take the stricter of the two adjacent
//! columns of Table 3 (`ael::Band::of`, `specs/eye_safety.md`, "T3-3"):
//! 1500.0 nm and 1800.0 nm the 1400–1500 nm rows (the 1800–2600 nm column
//! has the same rows), 1050.0 nm and 1400.0 nm refused (their other column,
//! 1050–1400 nm, is not modelled). Every caller of `Band::of` — the bound,
//! the `ael` report, the firmware integer limits — sees the same band.

use gaze_lidar_core::eye_safety::ael::{self, ael_j, Band, APERTURE_IR_MM};
use gaze_lidar_core::eye_safety::bound::Seg;
use gaze_lidar_core::eye_safety::{ael_report, evaluate_segments};
use std::f64::consts::TAU;

use gaze_lidar_core::testing::params_at as params;

/// The assumption behind taking the 1400–1500 nm rows at 1500.0 and
/// 1800.0 nm: they are at most the 1500–1800 nm rows at every duration of
/// the table (a dense log grid plus every row edge and its neighbours), so
/// they are the stricter column; same aperture; C5 = 1 in both.
#[test]
fn the_1400_rows_are_at_most_the_1500_rows_everywhere() {
    let mut ts: Vec<f64> = (0..=1300)
        .map(|i| 1e-9 * 10f64.powf(f64::from(i) / 100.0))
        .filter(|&t| t <= ael::T_MAX_TABLE_S)
        .collect();
    for band in [Band::Ir1400, Band::Ir1500] {
        for row in ael::rows(band, 1.0) {
            for e in [row.t_lo_s, row.t_hi_s] {
                ts.extend([
                    e * (1.0 - 1e-9),
                    e,
                    (e * (1.0 + 1e-9)).min(ael::T_MAX_TABLE_S),
                ]);
            }
        }
    }
    for t in ts {
        let a = ael::table3_j(Band::Ir1400, 1.0, t);
        let b = ael::table3_j(Band::Ir1500, 1.0, t);
        assert!(a <= b, "{t} s: 1400–1500 nm {a} J above 1500–1800 nm {b} J");
    }
    assert_eq!(Band::Ir1400.aperture_mm(), Band::Ir1500.aperture_mm());
    assert_eq!(ael::c5(Band::Ir1400, 1e6, 10.0), 1.0);
}

#[test]
fn exact_band_edges_take_the_stricter_column_or_are_refused() {
    assert_eq!(Band::of(1500.0), Ok(Band::Ir1400));
    assert_eq!(Band::of(1800.0), Ok(Band::Ir1400));
    assert_eq!(Band::of(1500.0 + 1e-9), Ok(Band::Ir1500));
    assert_eq!(Band::of(1800.0 - 1e-9), Ok(Band::Ir1500));
    // 1500.0 nm reads the 1400–1500 nm rows: 8e-4 J (not 8e-3 J) at 1 µs.
    assert_eq!(ael_j(1500.0, 1e-6).unwrap(), 8e-4);
    assert_eq!(ael_j(1800.0, 1e-6).unwrap(), 8e-4);
    assert_eq!(ael_j(1550.0, 1e-6).unwrap(), 8e-3);
    // The `ael` report too (T_i = 1 ms, the per-pulse AEL of the stricter row).
    let r = ael_report(1500.0, 1e-6, Some(1e3)).unwrap();
    assert_eq!(r.t_i_s, 1e-3);
    for lambda in [1050.0, 1400.0] {
        let e = Band::of(lambda).unwrap_err().to_string();
        assert!(
            e.contains("wavelength_nm") && e.contains("1050–1400 nm"),
            "{e}"
        );
        let e = evaluate_segments(&scanner(1.0), &params(lambda, 1.0), 1e5).unwrap_err();
        assert!(e.to_string().contains("1050–1400 nm"), "{e}");
        assert!(ael_report(lambda, 1e-8, None).is_err());
    }
    // Just inside the supported bands they are evaluated as before.
    assert_eq!(Band::of(1050.0 - 1e-9), Ok(Band::RetinalNir));
    assert_eq!(Band::of(1400.0 + 1e-9), Ok(Band::Ir1400));
}

/// A uniform scanner at 1 Hz (2π rad/s), one bin.
fn scanner(power_w: f64) -> Vec<Seg> {
    vec![Seg {
        start_deg: 0.0,
        width_deg: 360.0,
        power_w,
        spin_start_rad_s: TAU,
        spin_end_rad_s: TAU,
    }]
}

/// A uniform 1 Hz, 100 kHz scanner whose beam makes the pass arc exactly
/// 5 mm / 100 mm = 0.05 rad (beam 5 − 3.5571 mm): the pass lasts
/// `0.05/2π` = 7.9577 ms and holds at most `⌊795.77⌋ + 1` = 796 pulses.
/// At 0.99497 W (9.9497 µJ a pulse) the 1500–1800 nm column gives
/// `796 · 9.9497e-6 J / 8e-3 J` = 0.990 (8 mJ flat to 0.35 s; the
/// multi-pass windows, 11 passes in 10 s against 0.1 J, are 0.871): the
/// checker certified it at exactly 1500.0 nm. The 1400–1500 nm column (the
/// stricter, taken at the edge): 796 pulses span 795 spacings = 7.95 ms,
/// against `4.4e-3 · (7.95e-3)^0.25` = 1.31381e-3 J (the row grows to its
/// 0.35 s edge, 3.384e-3 J, and the next row is above): true ratio
/// `7.91996e-3 / 1.31381e-3` = **6.028**.
#[test]
fn uniform_scanner_at_1500_and_1800_nm_is_rejected_at_the_stricter_figure() {
    let beam = 5.0 - APERTURE_IR_MM;
    let (p, f_p) = (0.99497, 1e5);
    let segs = scanner(p);
    let e_pulse = p / f_p;
    let truth = 796.0 * e_pulse / (4.4e-3 * (795.0 / f_p).powf(0.25));
    assert!((truth - 6.028).abs() < 1e-3, "{truth}");
    for lambda in [1500.0, 1800.0] {
        let r = evaluate_segments(&segs, &params(lambda, beam), f_p).unwrap();
        assert!(
            r.worst_ratio >= truth,
            "{lambda} nm: {} below {truth}",
            r.worst_ratio
        );
        assert!(
            r.worst_ratio < truth * 1.01,
            "{lambda} nm: {}",
            r.worst_ratio
        );
    }
    // Inside 1500–1800 nm the looser column applies: 0.990, certified.
    for lambda in [1500.0 + 1e-9, 1550.0, 1800.0 - 1e-9] {
        let r = evaluate_segments(&segs, &params(lambda, beam), f_p).unwrap();
        let by_hand = 796.0 * e_pulse / 8e-3;
        assert!(
            (r.worst_ratio / by_hand - 1.0).abs() < 1e-6,
            "{lambda} nm: {}",
            r.worst_ratio
        );
        assert!(r.worst_ratio < 1.0);
    }
}
