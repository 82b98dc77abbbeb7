//! Sensor files: a LiDAR described in TOML, with exactly the fields of a
//! preset's `lidar` ([`LidarSpec`]), read through the one numeric boundary
//! ([`LidarSpec::validate`]) and written from any preset.
//!
//! ```toml
//! name = "paper: CARLA 64-channel, 20 Hz, 500k points/s, 100 m (one channel)"
//! frame_rate_hz = 20.0
//! pulse_rate_hz = 7812.5
//! channels = 64
//! average_power_w = 0.001
//! rated_range_m = 100.0
//! reference_reflectivity = 0.1
//! power_accounting = "angle"          # or "time"
//!
//! [limits]
//! power_w_min = 0.0
//! power_w_max = 0.00125
//! spin_rad_s_min = 31.41592653589793
//! spin_rad_s_max = 628.3185307179587
//! spin_accel_rad_s2_max = "unlimited" # a number, or "unlimited" (steps allowed)
//! power_slew_w_per_deg_max = "unlimited"
//!
//! [limits.eye_safety]                 # required: a sensor has a laser
//! wavelength_nm = 905.0
//! pulse_duration_s = 5e-9
//! beam_diameter_mm = 8.0
//!
//! [limits.eye_safety.head]            # optional: absent means one channel
//! cycle_s = 5.5296e-5                 # every channel fires once a cycle
//! origin_radius_mm = 41.91            # (pulse_rate_hz must be 1/cycle_s,
//! origin_height_mm = 0.0              #  channels the head's count)
//! exit_diameter_mm = 10.0
//! divergence_mrad = 3.0
//! aperture_distance_mm = 100.0
//!
//! [[limits.eye_safety.head.channels]] # one table per channel
//! id = 0
//! elevation_deg = -15.0
//! azimuth_offset_deg = 0.0
//! slot_s = 0.0
//! power_scale = 1.0
//! ```
//!
//! "Unlimited" is spelled as in the optimizer's configuration files (TOML
//! has no `null`); every key is required (but the head's defaults:
//! `origin_height_mm` 0, `aperture_distance_mm` 100, `power_scale` 1),
//! none may be added. Numbers are
//! written with Rust's shortest round-trip formatting, so a preset written
//! out and read back is the same sensor, bit for bit.

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::eye_safety::EyeSafetyParams;
use crate::model::lidar::{LidarSpec, Limits, PowerAccounting, SpecError};

/// The word for "no limit".
pub const UNLIMITED: &str = "unlimited";

/// A sensor file could not be read.
#[derive(Debug, Error)]
pub enum SensorError {
    /// Not TOML, or not the schema (unknown or missing key, wrong type).
    #[error("{origin}:{line}:{column}: {message}")]
    Toml {
        /// The file.
        origin: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong (one line).
        message: String,
    },
    /// Parsed, but not a sensor (NaN, negative, subnormal, inverted …).
    #[error("{origin}: {error}")]
    Invalid {
        /// The file.
        origin: String,
        /// Which key and why.
        error: SpecError,
    },
    /// A sensor without eye-safety parameters cannot be written as a file.
    #[error("{0}: a sensor file needs limits.eye_safety")]
    NoEyeSafety(String),
    /// TOML serialization failed.
    #[error("sensor file: {0}")]
    Write(#[from] toml::ser::Error),
}

impl SensorError {
    /// The sensor key the error names, when it names one.
    #[must_use]
    pub fn field(&self) -> Option<&str> {
        match self {
            Self::Invalid { error, .. } => Some(&error.field),
            _ => None,
        }
    }
}

/// `Option<f64>` as a number or [`UNLIMITED`].
mod limit {
    use super::UNLIMITED;
    use serde::{Deserialize, Deserializer, Serializer};

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Raw {
        Number(f64),
        Word(String),
    }

    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(x) => s.serialize_f64(*x),
            None => s.serialize_str(UNLIMITED),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        match Raw::deserialize(d) {
            Ok(Raw::Number(x)) => Ok(Some(x)),
            Ok(Raw::Word(w)) if w == UNLIMITED => Ok(None),
            _ => Err(serde::de::Error::custom(format!(
                "expected a number or \"{UNLIMITED}\""
            ))),
        }
    }
}

/// The file's `[limits]`: a preset's limits, "unlimited" for none.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileLimits {
    power_w_min: f64,
    power_w_max: f64,
    spin_rad_s_min: f64,
    spin_rad_s_max: f64,
    #[serde(with = "limit")]
    spin_accel_rad_s2_max: Option<f64>,
    #[serde(with = "limit")]
    power_slew_w_per_deg_max: Option<f64>,
    eye_safety: EyeSafetyParams,
}

/// The whole file: the fields of [`LidarSpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SensorFile {
    name: String,
    frame_rate_hz: f64,
    pulse_rate_hz: f64,
    channels: u32,
    average_power_w: f64,
    rated_range_m: f64,
    reference_reflectivity: f64,
    power_accounting: PowerAccounting,
    limits: FileLimits,
}

/// Reads a sensor file: the schema (exactly a preset's `lidar`), then every
/// number through [`LidarSpec::validate`]. `origin` names the file.
pub fn from_toml(text: &str, origin: &str) -> Result<LidarSpec, SensorError> {
    let file: SensorFile = toml::from_str(text).map_err(|e| {
        let (line, column) = e
            .span()
            .map_or((1, 1), |s| crate::text::line_column(text, s.start));
        SensorError::Toml {
            origin: origin.to_owned(),
            line,
            column,
            message: crate::text::toml_message(&e),
        }
    })?;
    let l = file.limits;
    let spec = LidarSpec {
        name: file.name,
        frame_rate_hz: file.frame_rate_hz,
        pulse_rate_hz: file.pulse_rate_hz,
        channels: file.channels,
        average_power_w: file.average_power_w,
        rated_range_m: file.rated_range_m,
        reference_reflectivity: file.reference_reflectivity,
        power_accounting: file.power_accounting,
        limits: Limits {
            power_w_min: l.power_w_min,
            power_w_max: l.power_w_max,
            spin_rad_s_min: l.spin_rad_s_min,
            spin_rad_s_max: l.spin_rad_s_max,
            spin_accel_rad_s2_max: l.spin_accel_rad_s2_max,
            power_slew_w_per_deg_max: l.power_slew_w_per_deg_max,
            eye_safety: Some(l.eye_safety),
        },
    };
    spec.validate().map_err(|error| SensorError::Invalid {
        origin: origin.to_owned(),
        error,
    })?;
    Ok(spec)
}

/// Writes `spec` as a sensor file (it must have eye-safety parameters).
pub fn to_toml(spec: &LidarSpec) -> Result<String, SensorError> {
    let l = &spec.limits;
    let eye_safety = l
        .eye_safety
        .clone()
        .ok_or_else(|| SensorError::NoEyeSafety(spec.name.clone()))?;
    let file = SensorFile {
        name: spec.name.clone(),
        frame_rate_hz: spec.frame_rate_hz,
        pulse_rate_hz: spec.pulse_rate_hz,
        channels: spec.channels,
        average_power_w: spec.average_power_w,
        rated_range_m: spec.rated_range_m,
        reference_reflectivity: spec.reference_reflectivity,
        power_accounting: spec.power_accounting,
        limits: FileLimits {
            power_w_min: l.power_w_min,
            power_w_max: l.power_w_max,
            spin_rad_s_min: l.spin_rad_s_min,
            spin_rad_s_max: l.spin_rad_s_max,
            spin_accel_rad_s2_max: l.spin_accel_rad_s2_max,
            power_slew_w_per_deg_max: l.power_slew_w_per_deg_max,
            eye_safety,
        },
    };
    Ok(toml::to_string(&file)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::{preset, PRESET_NAMES};

    #[test]
    fn every_preset_round_trips_bit_for_bit() {
        for name in PRESET_NAMES {
            let spec = preset(name).unwrap().lidar;
            let text = to_toml(&spec).unwrap();
            assert_eq!(from_toml(&text, "x.toml").unwrap(), spec, "{name}:\n{text}");
        }
        // The paper preset has both optional limits unlimited, spelled out.
        let text = to_toml(&preset("paper").unwrap().lidar).unwrap();
        assert!(
            text.contains("spin_accel_rad_s2_max = \"unlimited\""),
            "{text}"
        );
        assert!(
            text.contains("power_slew_w_per_deg_max = \"unlimited\""),
            "{text}"
        );
    }

    #[test]
    fn schema_errors_name_line_and_key() {
        let text = to_toml(&preset("paper").unwrap().lidar).unwrap();
        // A key left out, a key added, a wrong word.
        let missing = text.replace("power_slew_w_per_deg_max = \"unlimited\"\n", "");
        let e = from_toml(&missing, "s.toml").unwrap_err().to_string();
        assert!(
            e.contains("power_slew_w_per_deg_max") && e.starts_with("s.toml:"),
            "{e}"
        );
        let extra = text.replace("channels = 64", "channels = 64\nchanels = 3");
        let e = from_toml(&extra, "s.toml").unwrap_err().to_string();
        assert!(e.contains("chanels"), "{e}");
        let word = text.replace(
            "spin_accel_rad_s2_max = \"unlimited\"",
            "spin_accel_rad_s2_max = \"none\"",
        );
        let e = from_toml(&word, "s.toml").unwrap_err();
        assert!(matches!(e, SensorError::Toml { .. }), "{e}");
        assert!(e.to_string().contains("unlimited"), "{e}");
    }
}
