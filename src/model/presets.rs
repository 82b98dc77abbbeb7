//! Named presets: a LiDAR, a driver focus model and the adaptive levels of the
//! paper's closed-form controllers.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use thiserror::Error;

use super::acuity::FocusModel;
use super::lidar::{LidarSpec, Limits, PowerAccounting};
use crate::eye_safety::EyeSafetyParams;

/// The levels of the paper's two-level controllers (section III).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveLevels {
    /// Range control: `P_low = rof_power_fraction · P̄` inside the RoF; `P_high`
    /// follows from the budget (eq. 4). The paper's code uses 0.5.
    pub rof_power_fraction: f64,
    /// Resolution control: `ω_high / ω_low`, i.e. how many times fewer points
    /// per degree inside the RoF; `ω_low` follows from eq. 6. Paper code: 5.4.
    pub spin_ratio: f64,
}

impl AdaptiveLevels {
    /// The paper code's levels (github fscari/ARGUS): 0.5 and 5.4.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            rof_power_fraction: 0.5,
            spin_ratio: 5.4,
        }
    }
}

/// A LiDAR, the driver's focus model and the adaptive levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    /// The sensor.
    pub lidar: LidarSpec,
    /// RoF model (acuity function and threshold).
    pub focus: FocusModel,
    /// Levels of the closed-form controllers.
    pub levels: AdaptiveLevels,
}

/// Unknown preset name.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[error("unknown preset '{0}' (known: {known})", known = PRESET_NAMES.join(", "))]
pub struct UnknownPreset(pub String);

/// Names accepted by [`preset`].
pub const PRESET_NAMES: &[&str] = &["paper", "vls128"];

/// Looks a preset up by name.
pub fn preset(name: &str) -> Result<Preset, UnknownPreset> {
    match name {
        "paper" => Ok(paper()),
        "vls128" => Ok(vls128()),
        other => Err(UnknownPreset(other.to_owned())),
    }
}

/// The paper's CARLA baseline, one channel of it for the 2D model.
///
/// - 64 channels, 20 Hz, ≈ 500,000 points/s (CARLA LiDAR as in the paper,
///   section III-C), hence 7,812.5 pulses/s per channel, 390.6 per turn;
///   100 m range.
/// - RoF: the paper's 60° box (η = 0.5); levels of the paper's code
///   (`P_low = 0.5 P̄`, `ω_high/ω_low = 5.4`); eq. 4 as printed (`angle`).
/// - Laser (not given by the paper; chosen so the baseline is Class 1):
///   905 nm, 5 ns pulses, 1.0 mW mean per channel (128 nJ per pulse,
///   25.6 W peak), 8 mm beam at 100 mm.
/// - Limits: no acceleration or slew limit (the paper steps), power up to
///   1.25 P̄, spin 5–100 Hz.
#[must_use]
pub fn paper() -> Preset {
    let average_power_w = 1.0e-3;
    Preset {
        lidar: LidarSpec {
            name: "paper: CARLA 64-channel, 20 Hz, 500k points/s, 100 m (one channel)".into(),
            frame_rate_hz: 20.0,
            pulse_rate_hz: 500_000.0 / 64.0,
            channels: 64,
            average_power_w,
            rated_range_m: 100.0,
            reference_reflectivity: 0.1,
            power_accounting: PowerAccounting::Angle,
            limits: Limits {
                power_w_min: 0.0,
                power_w_max: 1.25 * average_power_w,
                spin_rad_s_min: TAU * 5.0,
                spin_rad_s_max: TAU * 100.0,
                spin_accel_rad_s2_max: None,
                power_slew_w_per_deg_max: None,
                eye_safety: Some(EyeSafetyParams {
                    wavelength_nm: 905.0,
                    pulse_duration_s: 5e-9,
                    beam_diameter_mm: 8.0,
                    head: None,
                }),
            },
        },
        focus: FocusModel::paper(),
        levels: AdaptiveLevels::paper(),
    }
}

/// A sensor resembling the Velodyne VLS-128 run at 10 Hz.
///
/// - 903 nm, 128 lasers each firing every 53.3 µs (18,761 Hz per channel,
///   2.4 M points/s in all), 5–20 Hz in 60 RPM steps (datasheet), 10 Hz here.
/// - Laser (assumed, Class 1): 3 ns pulses, 1.5 mW mean per channel (80 nJ per
///   pulse), 8 mm beam at 100 mm. Rated range 245 m at 10 % reflectivity
///   (vendor figure for the VLS-128 class).
/// - Motor: a real spinning head cannot step its speed inside a turn; the
///   limit here is 100 rad/s² (≈ 1e-3 kg·m² inertia, 0.1 N·m spare torque),
///   so closed-form resolution control (a step) is rejected and spin
///   modulation needs the optimizer's smooth ramps.
/// - Power accounting by time (the physical energy budget); the levels of
///   the paper's controllers and the Levi E2 acuity model at a 60° RoF.
#[must_use]
pub fn vls128() -> Preset {
    let average_power_w = 1.5e-3;
    Preset {
        lidar: LidarSpec {
            name: "vls128: VLS-128-like, 903 nm, 10 Hz, 128 channels".into(),
            frame_rate_hz: 10.0,
            pulse_rate_hz: 1.0 / 53.3e-6,
            channels: 128,
            average_power_w,
            rated_range_m: 245.0,
            reference_reflectivity: 0.1,
            power_accounting: PowerAccounting::Time,
            limits: Limits {
                power_w_min: 0.2 * average_power_w,
                power_w_max: 1.3 * average_power_w,
                spin_rad_s_min: TAU * 5.0,
                spin_rad_s_max: TAU * 20.0,
                spin_accel_rad_s2_max: Some(100.0),
                power_slew_w_per_deg_max: None,
                eye_safety: Some(EyeSafetyParams {
                    wavelength_nm: 903.0,
                    pulse_duration_s: 3e-9,
                    beam_diameter_mm: 8.0,
                    head: None,
                }),
            },
        },
        focus: FocusModel::levi_e2_with_width(60.0),
        levels: AdaptiveLevels::paper(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_resolve_and_validate() {
        for name in PRESET_NAMES {
            let p = preset(name).unwrap();
            p.focus.validate().unwrap();
            assert!(p.lidar.limits.power_w_max >= p.lidar.average_power_w);
        }
        let e = preset("nope").unwrap_err().to_string();
        assert!(e.contains("paper") && e.contains("nope"));
    }
}
