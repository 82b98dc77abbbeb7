//! The one numeric input boundary: what a number read from a profile, a
//! sensor file, a firmware table or a command-line flag must be before any
//! limit is compared with it.
//!
//! Every rule is written so that NaN fails it (`!(x >= lo)`, never `x < lo`):
//! a comparison with NaN is false, so a rule stated as "refuse when `x < lo`"
//! would let NaN through.
//!
//! - a **rate** (Hz) is finite and lies in [`RATE_HZ_MIN`, `RATE_HZ_MAX`]: a
//!   physical clock, so its reciprocal (a period, s) is a normal float too.
//!   This refuses subnormal rates such as `5e-324`, whose period `1/f`
//!   overflows to infinity (and an infinite period would match any sum of
//!   dwell times within a relative tolerance);
//! - a **magnitude** (power, spin, acceleration, slew, range …) is finite and
//!   either zero or a normal float: a subnormal (below `f64::MIN_POSITIVE ≈
//!   2.2e-308`) is not a physical size of anything this crate handles, and
//!   dividing by one overflows;
//! - a **positive magnitude** is a magnitude `> 0`.

/// Slowest rate accepted anywhere, Hz (a period of 31.7 years).
pub const RATE_HZ_MIN: f64 = 1e-9;
/// Fastest rate accepted anywhere, Hz (a period of 1 ps).
pub const RATE_HZ_MAX: f64 = 1e12;

/// Why a number was refused (a static phrase for an error message).
pub type Reason = &'static str;

/// A rate in Hz (see the module docs).
pub fn rate_hz(x: f64) -> Result<f64, Reason> {
    // `contains` is false on NaN (both of its comparisons are).
    if (RATE_HZ_MIN..=RATE_HZ_MAX).contains(&x) {
        Ok(x)
    } else {
        Err("must be a finite rate within 1e-9..=1e12 Hz")
    }
}

/// A non-negative magnitude: finite, `>= 0`, zero or normal (not subnormal).
pub fn magnitude(x: f64) -> Result<f64, Reason> {
    if x == 0.0 || (x.is_normal() && x > 0.0) {
        // `x == 0.0` also accepts -0.0, which is zero.
        Ok(x.abs())
    } else {
        Err("must be finite and >= 0 (and not subnormal)")
    }
}

/// A positive magnitude: finite, `> 0` and normal.
pub fn positive(x: f64) -> Result<f64, Reason> {
    if x.is_normal() && x > 0.0 {
        Ok(x)
    } else {
        Err("must be finite and > 0 (and not subnormal)")
    }
}

/// A finite number of any sign that is zero or normal (an angle, a start).
pub fn finite(x: f64) -> Result<f64, Reason> {
    if x == 0.0 || x.is_normal() {
        Ok(x)
    } else {
        Err("must be finite (and not subnormal)")
    }
}

/// `lo <= hi`, false when either is NaN.
#[must_use]
pub fn ordered(lo: f64, hi: f64) -> bool {
    lo <= hi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every class of f64 against each rule, from the IEEE-754 definitions
    /// (not from the functions): NaN, ±inf, ±0, the subnormal extremes, the
    /// normal extremes and the rate range's edges.
    #[test]
    fn rules_refuse_nan_infinities_and_subnormals() {
        let sub_min = f64::from_bits(1); // 4.9e-324
        let sub_max = f64::from_bits(0x000f_ffff_ffff_ffff); // just below MIN_POSITIVE
        for x in [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            sub_min,
            sub_max,
            4e-309,
            5e-324,
        ] {
            assert!(rate_hz(x).is_err(), "{x}");
            assert!(magnitude(x).is_err(), "{x}");
            assert!(positive(x).is_err(), "{x}");
            assert!(finite(x).is_err(), "{x}");
        }
        for x in [-1.0, -f64::MIN_POSITIVE, -1e300] {
            assert!(magnitude(x).is_err() && positive(x).is_err() && rate_hz(x).is_err());
            assert!(finite(x).is_ok());
        }
        assert_eq!(magnitude(0.0), Ok(0.0));
        assert_eq!(magnitude(-0.0).map(f64::to_bits), Ok(0));
        assert!(positive(0.0).is_err() && rate_hz(0.0).is_err());
        for x in [f64::MIN_POSITIVE, 1.0, f64::MAX] {
            assert_eq!(magnitude(x), Ok(x));
            assert_eq!(positive(x), Ok(x));
        }
        // Rates: the edges are in, their neighbours out; 1/f is normal
        // across the whole range.
        for (x, ok) in [
            (RATE_HZ_MIN, true),
            (RATE_HZ_MAX, true),
            (RATE_HZ_MIN * (1.0 - f64::EPSILON), false),
            (RATE_HZ_MAX * (1.0 + f64::EPSILON), false),
            (1e-300, false),
            (20.0, true),
        ] {
            assert_eq!(rate_hz(x).is_ok(), ok, "{x}");
            if ok {
                assert!((1.0 / x).is_normal());
            }
        }
        assert!(!ordered(f64::NAN, 1.0) && !ordered(1.0, f64::NAN) && ordered(1.0, 1.0));
    }
}
