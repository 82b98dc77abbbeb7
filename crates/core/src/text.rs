//! Numbers in messages: [`Num`] prints a value a user typed (or a limit)
//! compactly — `1e300`, not 301 digits — and exactly (the shortest text that
//! reads back as the same `f64`).

use core::fmt;

/// An `f64` for a message: plain decimal when that is short
/// (`1e-4 <= |x| < 1e7`, and 0), scientific otherwise (`1e300`, `2.5e-9`);
/// `NaN`, `inf` and `-inf` as such. Both forms are Rust's shortest
/// round-trip representation, so the value is never rounded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let magnitude = if x < 0.0 { -x } else { x };
        if !x.is_finite() || x == 0.0 || (1e-4..1e7).contains(&magnitude) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// [`Num`] of an optional limit: `unlimited` for `None`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limit(pub Option<f64>);

impl fmt::Display for Limit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(x) => Num(x).fmt(f),
            None => f.write_str("unlimited"),
        }
    }
}

/// An `f64` for a message with `.1` decimals (`Fixed(x, 1)`): `{:.1}`
/// while that is short and shows the value (`1e-N <= |x| < 1e7`, and 0),
/// `{:.1e}` otherwise — never 300 digits, never a misleading `0.0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed(pub f64, pub usize);

impl fmt::Display for Fixed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (x, prec) = (self.0, self.1);
        let magnitude = if x < 0.0 { -x } else { x };
        let mut smallest = 1.0;
        for _ in 0..prec {
            smallest /= 10.0;
        }
        if !x.is_finite() || x == 0.0 || (smallest..1e7).contains(&magnitude) {
            write!(f, "{x:.prec$}")
        } else {
            write!(f, "{x:.prec$e}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::string::ToString;

    proptest::proptest! {
        /// Over the whole f64 range (every bit pattern): never longer than
        /// 24 characters, and it reads back as the same value.
        #[test]
        fn compact_and_exact_over_the_whole_range(bits in proptest::prelude::any::<u64>()) {
            let x = f64::from_bits(bits);
            let s = Num(x).to_string();
            proptest::prop_assert!(s.len() <= 24, "{:e} → {}", x, s);
            let back: f64 = s.parse().unwrap();
            proptest::prop_assert!(back == x || (x.is_nan() && back.is_nan()), "{:e} → {}", x, s);
        }
    }

    #[test]
    fn chosen_forms() {
        for (x, want) in [
            (1e300, "1e300"),
            (-1e300, "-1e300"),
            (1000.0, "1000"),
            (0.001, "0.001"),
            (2.5e-9, "2.5e-9"),
            (1e7, "1e7"),
            (9999999.5, "9999999.5"),
            (0.0, "0"),
            (f64::INFINITY, "inf"),
            (f64::NEG_INFINITY, "-inf"),
            (f64::MAX, "1.7976931348623157e308"),
            (f64::MIN_POSITIVE, "2.2250738585072014e-308"),
        ] {
            assert_eq!(Num(x).to_string(), want);
        }
        assert_eq!(Limit(None).to_string(), "unlimited");
        assert_eq!(Fixed(12.345, 1).to_string(), "12.3");
        assert_eq!(Fixed(8.6e302, 1).to_string(), "8.6e302");
        assert_eq!(Fixed(1.2e-5, 3).to_string(), "1.200e-5");
        assert_eq!(Fixed(0.0, 3).to_string(), "0.000");
        for x in [1e300, -1e300, 1e-300, 123.456, f64::MAX] {
            assert!(Fixed(x, 3).to_string().len() <= 16, "{x:e}");
        }
        assert_eq!(Limit(Some(1e300)).to_string(), "1e300");
    }
}
