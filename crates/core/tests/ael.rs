//! Core-level tests of `eye_safety::ael` (found by `cargo mutants`): the
//! Table 3 / Table 9 / Table 10 figures at points inside every row, on the row
//! edges and at the domain ends, against values worked out by hand from the
//! formulas quoted in the module's doc comments (not from the functions under
//! test).

use approx::assert_relative_eq;
use gaze_lidar_core::eye_safety::ael::{self, ael_j, c4, c5, table3_j, AelError, Band, Row};

/// C4 at 905 nm: 10^(0.002·205) = 10^0.41.
const C4_905: f64 = 2.570_395_782_768_864;

#[test]
fn c4_c6_c7_by_hand() {
    assert_relative_eq!(c4(905.0), C4_905, max_relative = 1e-12);
    // 10^(0.002·150) = 10^0.3.
    assert_relative_eq!(c4(850.0), 1.995_262_314_968_879_5, max_relative = 1e-12);
    assert_eq!(c4(700.0), 1.0);
    assert_relative_eq!(c4(1050.0), 10f64.powf(0.7), max_relative = 1e-12);
    assert_eq!(c4(1550.0), 1.0);
    assert_eq!(ael::c6(), 1.0);
    assert_eq!(ael::c7(905.0), 1.0);
}

#[test]
fn band_constants_by_hand() {
    // Table 10 Condition 3 apertures.
    assert_eq!(Band::RetinalNir.aperture_mm(), 7.0);
    assert_eq!(Band::Ir1400.aperture_mm(), 3.5);
    assert_eq!(Band::Ir1500.aperture_mm(), 3.5);
    // First row of Table 3 per band.
    assert_eq!(Band::RetinalNir.min_duration_s(), 1e-11);
    assert_eq!(Band::Ir1400.min_duration_s(), 1e-9);
    assert_eq!(Band::Ir1500.min_duration_s(), 1e-9);
    // T_i (Table 9 / clause 4.3 f).
    assert_eq!(Band::RetinalNir.t_i_s(), 5e-6);
    assert_eq!(Band::Ir1400.t_i_s(), 1e-3);
    assert_eq!(Band::Ir1500.t_i_s(), 10.0);
    assert_eq!(Band::of(1499.9).unwrap(), Band::Ir1400);
    assert_eq!(Band::of(1500.0).unwrap(), Band::Ir1500);
    assert_eq!(Band::of(905.0).unwrap(), Band::RetinalNir);
    assert_eq!(Band::of(699.9), Err(AelError::Wavelength(699.9)));
    assert_eq!(Band::of(1200.0), Err(AelError::Wavelength(1200.0)));
}

/// `(wavelength, t, AEL by hand)`: one point inside each row and the row edges
/// (where the smaller of the two rows applies).
#[test]
fn table3_values_by_hand() {
    let cases = [
        // 700–1050 nm, row 1: 7.7e-8·C4 J (the 0.198 µJ of a 905 nm pulse).
        (905.0, 1e-9, 7.7e-8 * C4_905),
        (905.0, 1e-11, 7.7e-8 * C4_905),
        // Row 2: 7e-4·C4·t^0.75; (1e-3)^0.75 = 10^-2.25 = 5.623413251903491e-3.
        (905.0, 1e-3, 7e-4 * C4_905 * 5.623_413_251_903_491e-3),
        // Edge 5 µs: 7e-4·(5e-6)^0.75 = 7.401598844e-8 < 7.7e-8.
        (905.0, 5e-6, 7.401_598_844_083_949e-8 * C4_905),
        // Edge T2 = 10 s: 3.9e-4·10 = 3.9e-3 < 7e-4·10^0.75 = 3.936e-3.
        (905.0, 10.0, 3.9e-3 * C4_905),
        // Row 3: 3.9e-4·C4 W (≈ 1.0 mW at 905 nm).
        (905.0, 100.0, 3.9e-2 * C4_905),
        (905.0, 3e4, 3.9e-4 * 3e4 * C4_905),
        (700.0, 1.0, 7e-4),
        // 1400–1500 nm.
        (1450.0, 1e-9, 8e-4),
        (1450.0, 1e-6, 8e-4),
        // Edge 1 ms: 4.4e-3·(1e-3)^0.25 = 7.824429404e-4 < 8e-4.
        (1450.0, 1e-3, 7.824_429_404_171_262e-4),
        // 4.4e-3·0.01^0.25 = 4.4e-3·0.316227766.
        (1450.0, 0.01, 1.391_402_170_474_087e-3),
        // Edge 0.35 s: 4.4e-3·0.35^0.25 = 3.3843e-3 < 1e-2·0.35.
        (1450.0, 0.35, 3.384_306_496_179_218_5e-3),
        (1450.0, 1.0, 1e-2),
        (1450.0, 100.0, 1.0),
        (1450.0, 3e4, 300.0),
        // 1500–1800 nm.
        (1550.0, 1e-9, 8e-3),
        (1550.0, 0.1, 8e-3),
        // Edge 0.35 s: 8e-3 < 1.8e-2·0.35^0.75 = 8.19e-3.
        (1550.0, 0.35, 8e-3),
        (1550.0, 1.0, 1.8e-2),
        // 1.8e-2·5^0.75 = 1.8e-2·3.343701525.
        (1550.0, 5.0, 6.018_662_744_787_798e-2),
        // Edge 10 s: 1e-2·10 = 0.1 < 1.8e-2·10^0.75.
        (1550.0, 10.0, 0.1),
        (1550.0, 100.0, 1.0),
        (1800.0, 3e4, 300.0),
    ];
    for (lambda, t, want) in cases {
        let got = ael_j(lambda, t).unwrap();
        assert_relative_eq!(got, want, max_relative = 1e-12);
        let band = Band::of(lambda).unwrap();
        assert_relative_eq!(table3_j(band, c4(lambda), t), want, max_relative = 1e-12);
    }
}

#[test]
fn row_values_by_hand() {
    let row = |coef, exponent| Row {
        t_lo_s: 0.0,
        t_hi_s: 1.0,
        coef,
        exponent,
    };
    assert_eq!(row(3.0, 0.0).value_j(4.0), 3.0);
    assert_eq!(row(3.0, 1.0).value_j(4.0), 12.0);
    assert_eq!(row(3.0, 0.5).value_j(4.0), 6.0);
    assert_eq!(row(3.0, 0.25).value_j(16.0), 6.0);
}

#[test]
fn duration_errors_by_hand() {
    let err = |value, reason| AelError::Duration {
        what: "duration",
        value,
        reason,
    };
    assert_eq!(ael_j(905.0, 0.0), Err(err(0.0, "must be finite and > 0")));
    assert_eq!(ael_j(905.0, -1.0), Err(err(-1.0, "must be finite and > 0")));
    assert!(ael_j(905.0, f64::INFINITY).is_err());
    let short = "is shorter than the shortest tabulated duration for this band";
    assert_eq!(ael_j(905.0, 9e-12), Err(err(9e-12, short)));
    assert_eq!(ael_j(1450.0, 9e-10), Err(err(9e-10, short)));
    let long = "exceeds 3·10⁴ s, beyond Table 3";
    assert_eq!(ael_j(905.0, 3.0001e4), Err(err(3.0001e4, long)));
    assert_eq!(ael_j(1550.0, 1e5), Err(err(1e5, long)));
    // The domain ends are inside.
    assert!(ael_j(905.0, 1e-11).is_ok() && ael_j(1550.0, 1e-9).is_ok());
    assert!(ael_j(1450.0, 3e4).is_ok());
    assert_eq!(ael_j(1200.0, 1.0), Err(AelError::Wavelength(1200.0)));
}

#[test]
fn c5_by_hand() {
    // T_max just above 0.25 s and N > 600: 5·N^−0.25; 5·10⁴^−0.25 = 0.5.
    assert_relative_eq!(c5(Band::RetinalNir, 1e4, 0.26), 0.5, max_relative = 1e-12);
    // 5·(1.5625e4)^−0.25 = 5/11.180339887 = 0.4472135955.
    assert_relative_eq!(
        c5(Band::RetinalNir, 15_625.0, 10.0),
        0.447_213_595_499_957_9,
        max_relative = 1e-12
    );
    // Floor 0.4 (N ≥ 15625·(0.5/0.4)^4 ≈ 39063).
    assert_eq!(c5(Band::RetinalNir, 1e5, 10.0), 0.4);
    // T_max ≤ 0.25 s (inclusive) or N ≤ 600 (inclusive): 1.
    assert_eq!(c5(Band::RetinalNir, 1e4, 0.25), 1.0);
    assert_eq!(c5(Band::RetinalNir, 600.0, 100.0), 1.0);
    // Never above 1: 5·601^−0.25 = 1.0098 and 5·625^−0.25 = 1 exactly; the
    // first count where the formula is below 1 is 626 (5/626^0.25 = 0.99960).
    assert_eq!(c5(Band::RetinalNir, 601.0, 10.0), 1.0);
    assert_eq!(c5(Band::RetinalNir, 624.0, 10.0), 1.0);
    assert_relative_eq!(
        c5(Band::RetinalNir, 626.0, 10.0),
        0.999_600_6,
        max_relative = 1e-6
    );
    // Corneal bands: 1 whatever N.
    assert_eq!(c5(Band::Ir1400, 1e4, 10.0), 1.0);
    assert_eq!(c5(Band::Ir1500, 1e4, 10.0), 1.0);
}
