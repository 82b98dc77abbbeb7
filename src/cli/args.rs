//! Range checks of numeric options. Every numeric option is declared with
//! `allow_hyphen_values` and a signed (or float) type, so `-1` or `-inf`
//! reaches these checks and the message names the option, its value and
//! its range (never clap's "unexpected argument '-1' found").

use gaze_lidar::text::Num;

use super::CliError;

/// An integer option within `lo..=hi`.
pub fn int_in<T: TryFrom<i128>>(
    flag: &str,
    value: impl Into<i128>,
    lo: impl Into<i128>,
    hi: impl Into<i128>,
) -> Result<T, CliError> {
    let (value, lo, hi) = (value.into(), lo.into(), hi.into());
    if (lo..=hi).contains(&value) {
        if let Ok(v) = T::try_from(value) {
            return Ok(v);
        }
    }
    Err(CliError::input(format!(
        "{flag}: {value} must lie in {lo}..={hi}"
    )))
}

/// A float option, finite and within `(lo, hi)` (bounds exclusive).
pub fn finite_between(flag: &str, value: f64, lo: f64, hi: f64) -> Result<f64, CliError> {
    if value.is_finite() && value > lo && value < hi {
        Ok(value)
    } else {
        Err(CliError::input(format!(
            "{flag}: {} must be finite, > {} and < {}",
            Num(value),
            Num(lo),
            Num(hi)
        )))
    }
}

/// A float option, finite and > 0.
pub fn finite_positive(flag: &str, value: f64) -> Result<f64, CliError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(CliError::input(format!(
            "{flag}: {} must be finite and > 0",
            Num(value)
        )))
    }
}
