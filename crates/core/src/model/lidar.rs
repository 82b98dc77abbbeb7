//! The LiDAR: its nominal operating point, its hardware limits and how its
//! power budget is accounted.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

use crate::eye_safety::EyeSafetyParams;

pub use super::accounting::PowerAccounting;

/// The limits a profile is built and checked against. Serialized as the
/// `limits` object of `gaze-lidar/profile@1`, with exactly these keys.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Lowest laser power allowed in any bin, W.
    pub power_w_min: f64,
    /// Highest laser power allowed in any bin, W.
    pub power_w_max: f64,
    /// Slowest spin allowed anywhere, rad/s.
    pub spin_rad_s_min: f64,
    /// Fastest spin allowed anywhere, rad/s.
    pub spin_rad_s_max: f64,
    /// Motor angular-acceleration limit, rad/s²; `None` = unlimited (steps allowed).
    #[serde(deserialize_with = "required")]
    pub spin_accel_rad_s2_max: Option<f64>,
    /// Power slew limit between neighbouring bin centres, W/deg; `None` = unlimited.
    #[serde(deserialize_with = "required")]
    pub power_slew_w_per_deg_max: Option<f64>,
    /// Laser and optics parameters for the eye-safety check; `None` = not evaluated.
    #[serde(deserialize_with = "required")]
    pub eye_safety: Option<EyeSafetyParams>,
}

/// Deserializes an `Option` field that must be present (possibly `null`).
fn required<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    Option::<T>::deserialize(d)
}

/// A spinning LiDAR's nominal operating point (the uniform baseline) and limits.
///
/// `power` is the laser's mean optical output while it scans (pulse energy ×
/// pulse rate) for **one channel**: the 2D simulator and the eye-safety check
/// both look at a single beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarSpec {
    /// Human-readable name.
    pub name: String,
    /// Nominal revolutions per second; the frame period is `1 / frame_rate_hz`.
    pub frame_rate_hz: f64,
    /// Laser firing rate per channel (points per second per channel).
    pub pulse_rate_hz: f64,
    /// Number of channels (vertical beams); informational for the 2D model.
    pub channels: u32,
    /// Average power budget per channel `P̄`, W.
    pub average_power_w: f64,
    /// Rated range on `reference_reflectivity` in clear air, m.
    pub rated_range_m: f64,
    /// Lambertian reflectivity at which `rated_range_m` is specified.
    pub reference_reflectivity: f64,
    /// How the power budget is accounted.
    pub power_accounting: PowerAccounting,
    /// Limits every profile must respect.
    pub limits: Limits,
}

impl LidarSpec {
    /// Nominal (mean) spin `ω̄ = 2π · frame_rate_hz`, rad/s.
    #[must_use]
    pub fn mean_spin_rad_s(&self) -> f64 {
        TAU * self.frame_rate_hz
    }

    /// Frame period `T = 1 / frame_rate_hz`, s.
    #[must_use]
    pub fn frame_period_s(&self) -> f64 {
        1.0 / self.frame_rate_hz
    }

    /// Points per channel per revolution at the nominal spin.
    #[must_use]
    pub fn points_per_turn(&self) -> f64 {
        self.pulse_rate_hz / self.frame_rate_hz
    }
}
