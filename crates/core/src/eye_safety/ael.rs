//! Class 1 accessible emission limits (AEL) of IEC 60825-1:2014 for the bands
//! LiDARs use, as functions of wavelength and exposure duration.
//!
//! **Check before relying on these.** The constants come from the standard's
//! Table 3 (Class 1 / 1M, C6 = 1) and Table 9/10 (correction factors,
//! breakpoints, measurement conditions) as quoted by public
//! re-implementations of the 2014 tables; they have not been compared with a
//! licensed copy of the standard. A vendor must verify them before use.
//!
//! Supported: 700–1050 nm (retinal thermal hazard, where 850–940 nm LiDARs
//! sit) and 1400–1800 nm (corneal, 1550 nm LiDARs). Small source
//! (α ≤ α_min = 1.5 mrad, C6 = 1) throughout: a collimated beam seen from
//! 100 mm.

use serde::Serialize;
use thiserror::Error;

/// Errors from the AEL functions.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AelError {
    /// Wavelength outside the supported bands.
    #[error("wavelength_nm = {}: supported bands are 700–1050 nm and 1400–1800 nm", crate::text::Num(*.0))]
    Wavelength(f64),
    /// Exactly on a band edge whose other column (1050–1400 nm) the model
    /// does not have: the stricter of the two columns cannot be taken.
    #[error("wavelength_nm = {}: exactly on the edge of the 1050–1400 nm column of Table 3, which this model does not cover; at a band edge the stricter of the two columns applies, so it cannot be evaluated (use a wavelength inside 700–1050 nm or 1400–1800 nm)", crate::text::Num(*.0))]
    UnmodelledEdge(f64),
    /// Duration out of the tabulated domain.
    #[error("{what} = {} s: {reason}", crate::text::Num(*.value))]
    Duration {
        /// Which duration.
        what: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
}

/// Spectral band, selecting the rows of Table 3.
///
/// **Band edges take the stricter column** ([`Band::of`]): at exactly
/// 1500 nm and 1800 nm the wavelength belongs to two columns of Table 3 and
/// the model takes the stricter, [`Band::Ir1400`]'s rows (the 1800–2600 nm
/// column has the same rows and `T_i` as 1400–1500 nm: 8·10⁻⁴ J to 1 ms,
/// `4.4·10⁻³·t^0.25` J to 0.35 s, `10⁻²·t` J to 10 s, 10 mW beyond; they are
/// at most the 1500–1800 nm rows at every duration, the aperture is the
/// same, C5 = 1 in both). At exactly 1050 nm and 1400 nm the other column
/// is 1050–1400 nm, which the model does not have: refused
/// ([`AelError::UnmodelledEdge`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Band {
    /// 700–1050 nm, retinal hazard region (thermal).
    RetinalNir,
    /// 1400–1500 nm, corneal (its rows also at exactly 1500 nm and
    /// 1800 nm: the stricter column there).
    Ir1400,
    /// 1500–1800 nm (exclusive of both ends), corneal.
    Ir1500,
}

/// Minimum angular subtense α_min, rad (Table 9 note; small source below it).
pub const ALPHA_MIN_RAD: f64 = 1.5e-3;
/// Time base for Class 1 when intentional long-term viewing is not intended, s (clause 4.3 e).
pub const TIME_BASE_S: f64 = 100.0;
/// Condition 3 aperture for 400–1400 nm: 7 mm (Table 10).
pub const APERTURE_RETINAL_MM: f64 = 7.0;
/// Condition 3 aperture the bound uses for 1400–4000 nm, mm: the largest of
/// Table 10's apertures over every exposure duration (the conservative
/// choice: a wider aperture meets every pass for longer and holds every pulse
/// a narrower one holds). Table 10 gives 1 mm to 0.35 s, `1.5·t^0.375` mm
/// from 0.35 s to 10 s and 3.5 mm from 10 s on ([`table10_aperture_mm`]);
/// `1.5·t^0.375` exceeds 3.5 mm from 9.578 s and tends to
/// `1.5·10^0.375` = 3.5571 mm at 10 s, its supremum. The bound takes one
/// pass arc for every window, so it takes that supremum for every duration
/// (following the table by duration would need a pass arc per window
/// length; it would be tighter below 0.35 s, never looser).
pub const APERTURE_IR_MM: f64 = 3.557_060_558_492_482_4;
/// Table 10's Condition 3 aperture for 1400–4000 nm at 10 s and beyond, mm.
pub const APERTURE_IR_LONG_MM: f64 = 3.5;
/// Condition 3 distance from the reference point (scan mirror): 100 mm (Table 10).
pub const APERTURE_DISTANCE_MM: f64 = 100.0;

impl Band {
    /// The band of `wavelength_nm`: the column of Table 3 whose rows the
    /// model evaluates. At an exact band edge the stricter of the two
    /// adjacent columns (see [`Band`]): 1500.0 nm and 1800.0 nm take the
    /// 1400–1500 nm rows ([`Band::Ir1400`]), which are at most the
    /// 1500–1800 nm rows at every duration (tested over the whole table);
    /// 1050.0 nm and 1400.0 nm border the 1050–1400 nm column, which the
    /// model does not have, so they are refused by name.
    pub fn of(wavelength_nm: f64) -> Result<Self, AelError> {
        if !wavelength_nm.is_finite() {
            return Err(AelError::Wavelength(wavelength_nm));
        }
        if wavelength_nm == 1050.0 || wavelength_nm == 1400.0 {
            Err(AelError::UnmodelledEdge(wavelength_nm))
        } else if (700.0..1050.0).contains(&wavelength_nm) {
            Ok(Self::RetinalNir)
        } else if (1400.0..=1500.0).contains(&wavelength_nm) || wavelength_nm == 1800.0 {
            Ok(Self::Ir1400)
        } else if (1500.0..1800.0).contains(&wavelength_nm) {
            Ok(Self::Ir1500)
        } else {
            Err(AelError::Wavelength(wavelength_nm))
        }
    }

    /// Measurement aperture diameter of Condition 3 the bound uses, mm: Table
    /// 10's, the largest over every exposure duration (see
    /// [`APERTURE_IR_MM`]; 7 mm throughout 400–1400 nm).
    #[must_use]
    pub fn aperture_mm(self) -> f64 {
        match self {
            Self::RetinalNir => APERTURE_RETINAL_MM,
            Self::Ir1400 | Self::Ir1500 => APERTURE_IR_MM,
        }
    }

    /// Shortest duration Table 3 covers for the band, s.
    #[must_use]
    pub fn min_duration_s(self) -> f64 {
        match self {
            Self::RetinalNir => 1e-11,
            Self::Ir1400 | Self::Ir1500 => 1e-9,
        }
    }

    /// `T_i`, below which pulses are summed into one (Table 9 / clause 4.3 f), s:
    /// 5 µs for 400–1050 nm, 1 ms for 1400–1500 nm, 10 s for 1500–1800 nm.
    #[must_use]
    pub fn t_i_s(self) -> f64 {
        match self {
            Self::RetinalNir => 5e-6,
            Self::Ir1400 => 1e-3,
            Self::Ir1500 => 10.0,
        }
    }
}

/// Table 10's Condition 3 aperture diameter for an exposure of `t_s`, mm:
/// 7 mm for 400–1400 nm; for 1400–4000 nm 1 mm up to 0.35 s, `1.5·t^0.375`
/// mm for 0.35 s < t < 10 s, 3.5 mm from 10 s. [`Band::aperture_mm`] is its
/// supremum over `t` (tested over the whole duration range).
#[must_use]
pub fn table10_aperture_mm(band: Band, t_s: f64) -> f64 {
    match band {
        Band::RetinalNir => APERTURE_RETINAL_MM,
        Band::Ir1400 | Band::Ir1500 => {
            if t_s <= 0.35 {
                1.0
            } else if t_s < 10.0 {
                1.5 * t_s.powf(0.375)
            } else {
                APERTURE_IR_LONG_MM
            }
        }
    }
}

/// C4 = 10^(0.002(λ − 700)) for 700–1050 nm (Table 9); 1 elsewhere here.
#[must_use]
pub fn c4(wavelength_nm: f64) -> f64 {
    if (700.0..=1050.0).contains(&wavelength_nm) {
        10f64.powf(0.002 * (wavelength_nm - 700.0))
    } else {
        1.0
    }
}

/// C7 = 1 for 700–1150 nm (Table 9).
#[must_use]
pub fn c7(_wavelength_nm: f64) -> f64 {
    1.0
}

/// C6 = 1 for a small source, α ≤ α_min (Table 9).
#[must_use]
pub fn c6() -> f64 {
    1.0
}

/// T2 = 10 s for α ≤ α_min, 400–1400 nm (Table 9).
pub const T2_S: f64 = 10.0;

/// C5, the repetitive-pulse correction (clause 4.3 f, 2014 rules), for pulses
/// no longer than `T_i`, a small source, and `n_pulses` effective pulses
/// within `T_max = min(T2, time base)`:
/// 1 if `T_max <= 0.25 s` or `N <= 600`, else `max(0.4, 5 · N^−0.25)`,
/// and never above 1: `5·N^−0.25` exceeds 1 for 601 ≤ N ≤ 624 (1.0098 at
/// 601), which would raise the limit as the pulse count grows past 600 and
/// break "C5 does not rise with N", which the bound's pulse counts rely on.
/// Capping at 1 is the conservative reading (C5 is a reduction).
/// Applies to 400–1400 nm only; the corneal bands sum pulses within `T_i`.
#[must_use]
pub fn c5(band: Band, n_pulses: f64, t_max_s: f64) -> f64 {
    if band != Band::RetinalNir || t_max_s <= 0.25 || n_pulses <= 600.0 {
        1.0
    } else {
        (5.0 * n_pulses.powf(-0.25)).clamp(0.4, 1.0)
    }
}

fn check_duration(what: &'static str, t: f64, min: f64) -> Result<(), AelError> {
    if !(t.is_finite() && t > 0.0) {
        return Err(AelError::Duration {
            what,
            value: t,
            reason: "must be finite and > 0",
        });
    }
    if t < min {
        return Err(AelError::Duration {
            what,
            value: t,
            reason: "is shorter than the shortest tabulated duration for this band",
        });
    }
    if t > 3e4 {
        return Err(AelError::Duration {
            what,
            value: t,
            reason: "exceeds 3·10⁴ s, beyond Table 3",
        });
    }
    Ok(())
}

/// Class 1 AEL (J) for a single exposure of duration `t_s` (Table 3, C6 = 1),
/// without C5.
///
/// - 700–1050 nm, 1e-11 ≤ t < 5e-6 s: 7.7e-8 · C4 J (905 nm: 0.198 µJ)
///   (Table 3, row "10⁻¹¹ to 5·10⁻⁶ s", 700–1050 nm column).
/// - 700–1050 nm, 5e-6 < t ≤ T2 = 10 s: 7e-4 · C4 · t^0.75 J (row "5·10⁻⁶ to T2").
/// - 700–1050 nm, t > T2: 3.9e-4 · C4 · C7 W · t (905 nm: 1.0 mW) (row "T2 to 3·10⁴ s").
/// - 1400–1500 nm: 8e-4 J to 1e-3 s; 4.4e-3 · t^0.25 J to 0.35 s;
///   1e-2 · t J from 0.35 s to 10 s; 1e-2 W beyond (Table 3, 1400–1500 nm
///   column: the 0.35–10 s row is 1e-2·t J — *not* the 1500–1800 nm row
///   1.8e-2·t^0.75 J, which an earlier version used: continuity at both ends
///   and the MPE × aperture product agree on 1e-2·t).
/// - 1500–1800 nm: 8e-3 J for 1e-9 ≤ t ≤ 0.35 s; 1.8e-2 · t^0.75 J to 10 s;
///   1e-2 W beyond (Table 3, 1500–1800 nm column).
///
/// Exactly on a row edge the more restrictive of the two rows applies (the
/// table steps down by ≈ 4 % at 5 µs in 700–1050 nm).
pub fn ael_j(wavelength_nm: f64, t_s: f64) -> Result<f64, AelError> {
    let band = Band::of(wavelength_nm)?;
    check_duration("duration", t_s, band.min_duration_s())?;
    Ok(table3_j(band, c4(wavelength_nm), t_s))
}

/// One row of Table 3 for a band: `AEL(t) = coef · t^exponent` J on
/// `[t_lo_s, t_hi_s]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Start of the row, s.
    pub t_lo_s: f64,
    /// End of the row, s.
    pub t_hi_s: f64,
    /// Coefficient, J·s^−exponent (C4 included).
    pub coef: f64,
    /// Exponent of t (0, 0.25, 0.75 or 1).
    pub exponent: f64,
}

impl Row {
    /// `coef · t^exponent`, J.
    #[must_use]
    pub fn value_j(&self, t_s: f64) -> f64 {
        if self.exponent == 0.0 {
            self.coef
        } else if self.exponent == 1.0 {
            self.coef * t_s
        } else {
            self.coef * t_s.powf(self.exponent)
        }
    }
}

/// Longest duration Table 3 covers, s.
pub const T_MAX_TABLE_S: f64 = 3e4;

/// The rows of Table 3 for `band` with C4 = `c4`, in time order, covering
/// `[band.min_duration_s(), 3·10⁴ s]`. Every rule of the exposure bound
/// evaluates the AEL through these rows.
#[must_use]
pub fn rows(band: Band, c4: f64) -> [Row; 4] {
    let r = |t_lo_s, t_hi_s, coef, exponent| Row {
        t_lo_s,
        t_hi_s,
        coef,
        exponent,
    };
    match band {
        Band::RetinalNir => [
            r(1e-11, 5e-6, 7.7e-8 * c4 * c6(), 0.0),
            r(5e-6, T2_S, 7e-4 * c4 * c6(), 0.75),
            // C7 = 1 throughout 700–1050 nm.
            r(T2_S, T_MAX_TABLE_S, 3.9e-4 * c4 * c7(0.0), 1.0),
            r(T_MAX_TABLE_S, T_MAX_TABLE_S, 3.9e-4 * c4, 1.0),
        ],
        Band::Ir1400 => [
            r(1e-9, 1e-3, 8e-4, 0.0),
            r(1e-3, 0.35, 4.4e-3, 0.25),
            r(0.35, 10.0, 1e-2, 1.0),
            r(10.0, T_MAX_TABLE_S, 1e-2, 1.0),
        ],
        Band::Ir1500 => [
            r(1e-9, 0.35, 8e-3, 0.0),
            r(0.35, 10.0, 1.8e-2, 0.75),
            r(10.0, T_MAX_TABLE_S, 1e-2, 1.0),
            r(T_MAX_TABLE_S, T_MAX_TABLE_S, 1e-2, 1.0),
        ],
    }
}

/// Table 3 without validation, for hot loops whose inputs were validated
/// once: `band` and `c4` of the wavelength, `t_s` within the band's domain
/// (shorter durations take the first row). On a row edge the smaller of the
/// two rows' values (the more restrictive reading).
#[must_use]
pub fn table3_j(band: Band, c4: f64, t_s: f64) -> f64 {
    let rows = rows(band, c4);
    let mut v = f64::INFINITY;
    for (k, row) in rows.iter().enumerate() {
        let inside = (t_s >= row.t_lo_s || k == 0) && t_s <= row.t_hi_s;
        if inside {
            v = v.min(row.value_j(t_s));
        }
    }
    if v.is_finite() {
        v
    } else {
        rows[3].value_j(t_s)
    }
}

/// The smallest AEL (Table 3, as [`table3_j`]) over every exposure duration
/// in `[lo_s, hi_s]` (`hi_s` below `lo_s` is taken as `lo_s`): **the one AEL
/// infimum** of the model. A window that holds a given set of pulses can be
/// any length from the pulses' span up to where it must meet more pulses,
/// and Table 3 is *not* monotone in the duration (it steps down at 5 µs in
/// 700–1050 nm, at 1 ms in 1400–1500 nm, at 10 s in 700–1050 nm and in
/// 1500–1800 nm), so every rule compares the pulses a window can hold with
/// this infimum over every length that holds them, never with the AEL at
/// their span. Each row is `coef·t^exponent` with `coef > 0`,
/// `exponent ≥ 0`: nondecreasing within the row, so the infimum over an
/// interval is at its ends or at a row edge inside it, where [`table3_j`]
/// takes the smaller of the two rows (the limit of the left row at its end
/// is never below that). So it is the smallest of the AEL at `lo_s` and at
/// every row edge in `(lo_s, hi_s]`; the AEL at `hi_s` itself is never
/// smaller (it is at least its row's value at the row's first edge, or,
/// with no edge in between, at least the AEL at `lo_s`, in the same row).
/// Durations below the band's first row take the first row, as
/// [`table3_j`] does.
#[must_use]
pub fn ael_inf_j(band: Band, c4: f64, lo_s: f64, hi_s: f64) -> f64 {
    let mut v = table3_j(band, c4, lo_s);
    for row in rows(band, c4) {
        let e = row.t_hi_s;
        if e > lo_s && e <= hi_s {
            v = v.min(table3_j(band, c4, e));
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn breakpoints_are_continuous() {
        // 700–1050 nm at 5 µs and at T2; 1500 nm at 0.35 s and 10 s. The
        // table itself steps by ≈ 4 % at 5 µs (7.7e-8 vs 7e-4·(5e-6)^0.75).
        for (lambda, t) in [
            (905.0, 5e-6),
            (905.0, 10.0),
            (1550.0, 0.35),
            (1550.0, 10.0),
            (1450.0, 1e-3),
        ] {
            let lo = ael_j(lambda, t * (1.0 - 1e-9)).unwrap();
            let hi = ael_j(lambda, t * (1.0 + 1e-9)).unwrap();
            assert_relative_eq!(lo, hi, max_relative = 0.05);
        }
    }

    #[test]
    fn band_edges_and_errors() {
        assert_eq!(Band::of(700.0).unwrap(), Band::RetinalNir);
        assert_eq!(Band::of(1049.99).unwrap(), Band::RetinalNir);
        // Exact band edges: the stricter column, or refused where the
        // other column (1050–1400 nm) is not modelled.
        assert_eq!(Band::of(1050.0), Err(AelError::UnmodelledEdge(1050.0)));
        assert_eq!(Band::of(1400.0), Err(AelError::UnmodelledEdge(1400.0)));
        assert_eq!(Band::of(1500.0).unwrap(), Band::Ir1400);
        assert_eq!(Band::of(1800.0).unwrap(), Band::Ir1400);
        assert_eq!(Band::of(1400.01).unwrap(), Band::Ir1400);
        assert_eq!(Band::of(1500.01).unwrap(), Band::Ir1500);
        assert_eq!(Band::of(1799.99).unwrap(), Band::Ir1500);
        assert!(Band::of(1051.0).is_err());
        assert!(Band::of(1800.1).is_err() && Band::of(f64::NAN).is_err());
        assert!(ael_j(905.0, 0.0).is_err());
        assert!(ael_j(905.0, 1e-12).is_err());
        assert!(ael_j(905.0, f64::NAN).is_err());
        assert!(ael_j(1550.0, 1e-10).is_err());
    }

    #[test]
    fn c5_rules() {
        assert_eq!(c5(Band::RetinalNir, 600.0, 10.0), 1.0);
        assert_eq!(c5(Band::RetinalNir, 1e6, 0.2), 1.0);
        assert_relative_eq!(c5(Band::RetinalNir, 10_000.0, 10.0), 0.5);
        assert_eq!(c5(Band::RetinalNir, 1e9, 10.0), 0.4);
        assert_eq!(c5(Band::Ir1500, 1e9, 10.0), 1.0);
    }
}
