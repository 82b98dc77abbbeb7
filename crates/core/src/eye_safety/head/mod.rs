//! The multi-beam head: every channel a spinning head fires, where its beam
//! leaves and where it points, when it fires and how much of the bin power
//! it carries.
//!
//! A profile, a sensor file or a firmware table without a head describes
//! **one channel** (the historic meaning of every file written before heads
//! existed). With a head, eye safety is evaluated for every channel that can
//! reach the measurement aperture, summed, as the head fires them
//! (`specs/eye_safety.md`, "The head").
//!
//! Conventions (the head's own frame, rotating with it):
//! - `elevation_deg`: the channel's far-field elevation above the plane
//!   normal to the spin axis (positive up).
//! - `azimuth_offset_deg`: the channel's far-field azimuth relative to the
//!   head's encoder azimuth (positive counter-clockwise seen from above,
//!   the sense of increasing azimuth).
//! - `slot_s`: the time of the channel's firing within one firing cycle;
//!   channels with the same slot fire together.
//! - `power_scale`: the channel's power relative to the bin power of the
//!   profile (a channel's average power while the head is in bin `b` is
//!   `power_scale · P_b`).
//! - the beams leave from one crossing point (`origin_radius_mm` from the
//!   spin axis along the head's encoder direction, `origin_height_mm` above
//!   the reference plane), with an exit beam diameter `exit_diameter_mm`
//!   (1/e², the largest of its horizontal and vertical sizes) growing by
//!   the full divergence angle `divergence_mrad` (the larger axis).
//! - the measurement aperture stands `aperture_distance_mm` from the spin
//!   axis (default 100 mm).

#[cfg(feature = "std")]
pub mod bound;
#[cfg(feature = "std")]
pub mod geometry;
#[cfg(feature = "std")]
pub mod overlap;
#[cfg(all(feature = "std", any(kani, test)))]
mod verification;

#[cfg(feature = "std")]
pub use bound::{head_figures, power_scale_to_certify, HeadFigures};

use alloc::vec::Vec;
use serde::{Deserialize, Serialize};

/// Most channels a head may declare.
pub const CHANNELS_MAX: usize = 512;
/// Default distance of the measurement aperture from the spin axis, mm.
pub const APERTURE_DISTANCE_MM_DEFAULT: f64 = 100.0;

fn one() -> f64 {
    1.0
}

fn aperture_distance_default() -> f64 {
    APERTURE_DISTANCE_MM_DEFAULT
}

/// One channel (laser) of a head.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Channel {
    /// Channel id (unique within the head; the vendor's laser id).
    pub id: u32,
    /// Far-field elevation, deg (positive up).
    pub elevation_deg: f64,
    /// Far-field azimuth offset from the encoder azimuth, deg.
    pub azimuth_offset_deg: f64,
    /// Firing time within the firing cycle, s (`0 ≤ slot_s < cycle_s`).
    pub slot_s: f64,
    /// Power relative to the profile's bin power (default 1).
    #[serde(default = "one")]
    pub power_scale: f64,
}

/// A multi-beam head: its channels, its firing cycle and its optics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Head {
    /// The firing cycle, s: every channel fires once per cycle, at its slot
    /// (time-triggered firing; `1/cycle_s` is the sensor's per-channel
    /// `pulse_rate_hz`).
    pub cycle_s: f64,
    /// Distance of the beams' crossing point from the spin axis, mm.
    pub origin_radius_mm: f64,
    /// Height of the crossing point above the reference plane, mm.
    #[serde(default)]
    pub origin_height_mm: f64,
    /// Exit beam diameter (1/e², larger axis), mm.
    pub exit_diameter_mm: f64,
    /// Full divergence angle (larger axis), mrad.
    pub divergence_mrad: f64,
    /// Distance of the measurement aperture from the spin axis, mm.
    #[serde(default = "aperture_distance_default")]
    pub aperture_distance_mm: f64,
    /// The channels.
    pub channels: Vec<Channel>,
}

/// Why a head was refused: the field (a path such as `channels[3].slot_s`),
/// the value written there and the reason.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("head.{field} = {}: {reason}", crate::text::Num(*.value))]
pub struct HeadError {
    /// The field, relative to `head` (e.g. `channels[3].slot_s`).
    pub field: alloc::string::String,
    /// The value written (a count for `channels`, the repeated id for a
    /// duplicate).
    pub value: f64,
    /// Why.
    pub reason: &'static str,
}

/// The reason given for a refused finite subnormal value: it meets every
/// other rule's wording (finite, `>= 0`, inside the range), so the rule it
/// breaks is named instead.
const SUBNORMAL: &str =
    "is subnormal (below 2.2e-308, not a physical size): must be zero or a normal float";

impl Head {
    /// Validates the head at the one numeric boundary: 1–512 channels,
    /// every angle finite, every slot inside the cycle, no duplicate ids,
    /// sizes positive (or zero where zero is a size), the crossing point
    /// inside the aperture's distance.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn validate(&self) -> Result<(), HeadError> {
        use crate::model::valid;
        use alloc::format;
        let err = |field: &str, value: f64, reason: &'static str| HeadError {
            field: field.into(),
            value,
            reason: if value.is_subnormal() {
                SUBNORMAL
            } else {
                reason
            },
        };
        if self.channels.is_empty() || self.channels.len() > CHANNELS_MAX {
            return Err(err(
                "channels",
                self.channels.len() as f64,
                "must hold 1 to 512 channels",
            ));
        }
        if valid::positive(self.cycle_s).is_err() || !(self.cycle_s <= 1.0) {
            return Err(err(
                "cycle_s",
                self.cycle_s,
                "must be finite, > 0 (not subnormal) and <= 1 s",
            ));
        }
        if valid::positive(self.aperture_distance_mm).is_err()
            || !(self.aperture_distance_mm <= 10_000.0)
        {
            return Err(err(
                "aperture_distance_mm",
                self.aperture_distance_mm,
                "must be finite, > 0 and <= 10000 mm",
            ));
        }
        if valid::magnitude(self.origin_radius_mm).is_err()
            || !(self.origin_radius_mm < self.aperture_distance_mm)
        {
            return Err(err(
                "origin_radius_mm",
                self.origin_radius_mm,
                "must be finite, >= 0 and less than aperture_distance_mm",
            ));
        }
        if valid::finite(self.origin_height_mm).is_err() || !(self.origin_height_mm.abs() <= 1e4) {
            return Err(err(
                "origin_height_mm",
                self.origin_height_mm,
                "must be finite and within ±10000 mm",
            ));
        }
        if valid::positive(self.exit_diameter_mm).is_err() || !(self.exit_diameter_mm < 1000.0) {
            return Err(err(
                "exit_diameter_mm",
                self.exit_diameter_mm,
                "must be finite, > 0 and < 1000 mm",
            ));
        }
        if valid::magnitude(self.divergence_mrad).is_err() || !(self.divergence_mrad <= 1000.0) {
            return Err(err(
                "divergence_mrad",
                self.divergence_mrad,
                "must be finite, >= 0 and <= 1000 mrad",
            ));
        }
        let mut ids: Vec<u32> = Vec::with_capacity(self.channels.len());
        for (i, c) in self.channels.iter().enumerate() {
            let f = |name: &str| format!("channels[{i}].{name}");
            if valid::finite(c.elevation_deg).is_err() || !(c.elevation_deg.abs() < 90.0) {
                return Err(err(
                    &f("elevation_deg"),
                    c.elevation_deg,
                    "must be finite and within (-90, 90) deg",
                ));
            }
            if valid::finite(c.azimuth_offset_deg).is_err() || !(c.azimuth_offset_deg.abs() < 90.0)
            {
                return Err(err(
                    &f("azimuth_offset_deg"),
                    c.azimuth_offset_deg,
                    "must be finite and within (-90, 90) deg",
                ));
            }
            if valid::magnitude(c.slot_s).is_err() || !(c.slot_s < self.cycle_s) {
                return Err(err(
                    &f("slot_s"),
                    c.slot_s,
                    "must be finite, >= 0 and inside the cycle (< cycle_s)",
                ));
            }
            if valid::magnitude(c.power_scale).is_err() || !(c.power_scale <= 1e3) {
                return Err(err(
                    &f("power_scale"),
                    c.power_scale,
                    "must be finite, >= 0 and <= 1000",
                ));
            }
            ids.push(c.id);
        }
        ids.sort_unstable();
        if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
            return Err(HeadError {
                field: format!("channels (id {})", w[0]),
                value: f64::from(w[0]),
                reason: "duplicate channel id",
            });
        }
        Ok(())
    }
}
