//! Range checks of numeric options. Every numeric option is declared with
//! `allow_hyphen_values` and a signed (or float) type, so `-1` or `-inf`
//! reaches these checks and the message names the option, its value and
//! its range (never clap's "unexpected argument '-1' found"). Every float
//! goes through the one numeric boundary (`model::valid`).

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use gaze_lidar::model::valid;
use gaze_lidar::names::{self, Named};
use gaze_lidar::text::Num;

use super::CliError;

/// The value parser of an option whose values are a library enum's names:
/// its possible values and their help come from the enum's one table
/// ([`Named::TABLE`]), as a `ValueEnum` derive would list them.
pub fn named<T: Named + Clone + Send + Sync>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(
        T::TABLE
            .iter()
            .map(|&(_, name, help)| PossibleValue::new(name).help(help)),
    )
    .try_map(|name| names::parse::<T>(&name))
}

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

/// A float option within `(lo, hi)` (bounds exclusive) that passes the one
/// numeric boundary (`model::valid::finite`: finite, zero or normal — a
/// subnormal such as `5e-324` is no physical size and is refused).
pub fn finite_between(flag: &str, value: f64, lo: f64, hi: f64) -> Result<f64, CliError> {
    if valid::finite(value).is_ok() && value > lo && value < hi {
        Ok(value)
    } else {
        Err(CliError::input(format!(
            "{flag}: {} must be finite (not subnormal), > {} and < {}",
            Num(value),
            Num(lo),
            Num(hi)
        )))
    }
}

/// A float option, `> 0` at the one numeric boundary
/// (`model::valid::positive`: finite, normal).
pub fn finite_positive(flag: &str, value: f64) -> Result<f64, CliError> {
    valid::positive(value)
        .map_err(|reason| CliError::input(format!("{flag}: {} {reason}", Num(value))))
}

/// A rate option, Hz, at the one numeric boundary (`model::valid::rate_hz`).
pub fn rate(flag: &str, value: f64) -> Result<f64, CliError> {
    valid::rate_hz(value)
        .map_err(|reason| CliError::input(format!("{flag}: {} {reason}", Num(value))))
}

/// A float option of any sign at the one numeric boundary
/// (`model::valid::finite`).
pub fn finite(flag: &str, value: f64) -> Result<f64, CliError> {
    valid::finite(value)
        .map_err(|reason| CliError::input(format!("{flag}: {} {reason}", Num(value))))
}
