//! Eye safety (IEC 60825-1:2014, Class 1) for a pulsed, scanned beam.
//!
//! - [`ael`]: the accessible emission limits and correction factors.
//! - [`bound`]: the sound bound every rule is evaluated by.
//! - [`report`]: the figures of the `ael` command, from the same model.
//! - `cuts` (feature `optimizer`, on by default): concrete exposures as
//!   linear constraints on the bin powers, for the optimizer (lower bounds
//!   of the true ratio, never a verdict).
//! - [`exposure`]: the exposure of a stationary measurement aperture placed
//!   at every azimuth around a spinning head running a profile, against
//!   those limits. Concentrating power or slowing the spin in a sector raises
//!   the exposure there, so the limits are checked **per azimuth**.
//!
//! The figures must be checked against the standard by a vendor before use
//! (see [`ael`]).

#[cfg(feature = "std")]
pub mod ael;
#[cfg(feature = "std")]
pub mod bound;
#[cfg(feature = "optimizer")]
pub mod cuts;
#[cfg(feature = "std")]
pub mod exposure;
pub mod head;
#[cfg(feature = "std")]
pub mod report;
pub mod rule;

use serde::{Deserialize, Serialize};
#[cfg(feature = "std")]
use thiserror::Error;

#[cfg(feature = "std")]
pub use ael::AelError;
#[cfg(feature = "std")]
pub use exposure::{evaluate_profile, evaluate_segments, ExposureReport};
#[cfg(feature = "std")]
pub use report::{ael_report, AelReport, StationaryBeam};
pub use rule::Rule;

/// Laser and optics parameters the eye-safety check needs; stored in a
/// profile's `limits.eye_safety` so any tool can re-check a profile from the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EyeSafetyParams {
    /// Emission wavelength, nm.
    pub wavelength_nm: f64,
    /// Pulse duration (FWHM), s.
    pub pulse_duration_s: f64,
    /// Beam diameter at the measurement aperture (100 mm from the scan centre), mm.
    pub beam_diameter_mm: f64,
    /// The multi-beam head (absent: one channel, the beam above). With a
    /// head, the beam at the aperture is the head's (`head::Head`) and
    /// `beam_diameter_mm` is not used by the bound.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub head: Option<head::Head>,
}

/// Errors evaluating eye safety.
#[cfg(feature = "std")]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EyeSafetyError {
    /// From the AEL tables.
    #[error(transparent)]
    Ael(#[from] AelError),
    /// The head is invalid.
    #[error("eye_safety.{0}")]
    Head(#[from] head::HeadError),
    /// With a head, the pulse rate is not the head's `1/cycle_s`.
    #[error(
        "pulse_rate_hz = {}: with limits.eye_safety.head it must be 1/head.cycle_s = {} within 1e-9 (every channel fires once per cycle)",
        crate::text::Num(*.pulse_rate_hz),
        crate::text::Num(*.expected_hz)
    )]
    PulseRate {
        /// The rate found, Hz.
        pulse_rate_hz: f64,
        /// `1/cycle_s`, Hz.
        expected_hz: f64,
    },
    /// A parameter is invalid.
    #[error("eye_safety.{field} = {}: {reason}", crate::text::Num(*.value))]
    Param {
        /// Field.
        field: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
}

#[cfg(feature = "std")]
impl EyeSafetyParams {
    /// Validates the parameters (band, durations, beam size).
    pub fn validate(&self) -> Result<ael::Band, EyeSafetyError> {
        let band = ael::Band::of(self.wavelength_nm)?;
        ael::ael_j(self.wavelength_nm, self.pulse_duration_s).map_err(|_| {
            EyeSafetyError::Param {
                field: "pulse_duration_s",
                value: self.pulse_duration_s,
                reason: "must be finite, > 0 and within Table 3's durations for the band",
            }
        })?;
        if !(crate::model::valid::positive(self.beam_diameter_mm).is_ok()
            && self.beam_diameter_mm < 1000.0)
        {
            return Err(EyeSafetyError::Param {
                field: "beam_diameter_mm",
                value: self.beam_diameter_mm,
                reason: "must be finite, > 0 (not subnormal) and < 1000",
            });
        }
        if let Some(head) = &self.head {
            head.validate()?;
        }
        Ok(band)
    }

    /// With a head, every channel fires once per firing cycle, so the
    /// per-channel `pulse_rate_hz` of the profile, sensor or table carrying
    /// these parameters must be `1/cycle_s`: the head bound's own rule
    /// (`|pulse_rate_hz · cycle_s − 1| ≤` [`head::bound::RATE_CYCLE_TOLERANCE`],
    /// NaN failing), checked here at the boundary so a sensor file or a
    /// profile is refused by name before any evaluation. Without a head
    /// there is nothing to compare.
    pub fn check_pulse_rate(&self, pulse_rate_hz: f64) -> Result<(), EyeSafetyError> {
        let Some(h) = &self.head else {
            return Ok(());
        };
        if !(h.cycle_s.is_finite() && h.cycle_s > 0.0) {
            // No rate matches such a cycle: name the cycle, not the rate.
            h.validate()?;
        }
        let off = (pulse_rate_hz * h.cycle_s - 1.0).abs();
        if off.is_nan() || off > head::bound::RATE_CYCLE_TOLERANCE {
            return Err(EyeSafetyError::PulseRate {
                pulse_rate_hz,
                expected_hz: 1.0 / h.cycle_s,
            });
        }
        Ok(())
    }
}
