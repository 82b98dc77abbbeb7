//! The LiDAR: its nominal operating point, its hardware limits and how its
//! power budget is accounted.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

use crate::eye_safety::EyeSafetyParams;
use crate::model::valid;

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

/// The side a limit bounds from: an upper limit (`power_w_max`) or a lower
/// one (`power_w_min`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimitSide {
    /// The value must not exceed the limit.
    Upper,
    /// The value must not fall below the limit.
    Lower,
}

/// Whether a declared limit is no looser than the sensor's: `declared <=
/// sensor` for an upper limit, `>=` for a lower one. Written so that a NaN
/// on either side is looser. The one comparison the profile checker and the
/// firmware-table checker both hold declared limits to (`u64` codes and
/// `f64` watts alike).
#[must_use]
pub fn no_looser<T: PartialOrd>(declared: T, sensor: T, side: LimitSide) -> bool {
    match side {
        LimitSide::Upper => declared <= sensor,
        LimitSide::Lower => declared >= sensor,
    }
}

/// What must be the same for a file to run on `sensor`, besides its
/// limits: the pulse clock (exactly: the schedule counts its pulses), the
/// power accounting and the laser's eye-safety parameters. Each mismatch as
/// `(field, detail)`; a NaN pulse rate never matches. `eye_safety` absent
/// is not a mismatch here: each checker names a missing parameter set in
/// its own way.
#[must_use]
pub fn laser_mismatches(
    pulse_rate_hz: f64,
    accounting: PowerAccounting,
    eye_safety: Option<&EyeSafetyParams>,
    sensor: &LidarSpec,
) -> Vec<(&'static str, String)> {
    let mut v = Vec::new();
    #[allow(clippy::float_cmp)]
    if !(pulse_rate_hz == sensor.pulse_rate_hz) {
        v.push((
            "pulse_rate_hz",
            format!(
                "{pulse_rate_hz} differs from the sensor's {}",
                sensor.pulse_rate_hz
            ),
        ));
    }
    if accounting != sensor.power_accounting {
        v.push((
            "power_accounting",
            format!(
                "'{accounting}' differs from the sensor's '{}'",
                sensor.power_accounting
            ),
        ));
    }
    if let (Some(x), Some(y)) = (eye_safety, &sensor.limits.eye_safety) {
        if x != y {
            v.push(("eye_safety", first_laser_difference(x, y)));
        }
    }
    v
}

/// The first field where two unequal laser parameter sets differ, in one
/// line: `limits.eye_safety.head.channels[3].power_scale: 0.5 differs from
/// the sensor's 1`. Fields are compared with `!=` in declaration order, as
/// the derived `PartialEq` compares them, so two unequal sets always name
/// one.
fn first_laser_difference(x: &EyeSafetyParams, y: &EyeSafetyParams) -> String {
    use crate::text::Num;
    let differs = |path: &str, a: String, b: String| {
        format!(
            "limits.eye_safety.{path}: {a} differs from the sensor's {b} (a file's laser parameters must be the sensor's exactly)"
        )
    };
    let num = |path: &str, a: f64, b: f64| {
        #[allow(clippy::float_cmp)]
        let same = a == b;
        (!same).then(|| differs(path, Num(a).to_string(), Num(b).to_string()))
    };
    let top = num("wavelength_nm", x.wavelength_nm, y.wavelength_nm)
        .or_else(|| num("pulse_duration_s", x.pulse_duration_s, y.pulse_duration_s))
        .or_else(|| num("beam_diameter_mm", x.beam_diameter_mm, y.beam_diameter_mm));
    if let Some(d) = top {
        return d;
    }
    let (hx, hy) = match (&x.head, &y.head) {
        (Some(hx), Some(hy)) => (hx, hy),
        (a, b) => {
            let shown = |h: &Option<crate::eye_safety::head::Head>| match h {
                Some(h) => format!("a head of {} channels", h.channels.len()),
                None => "no head (one channel)".to_owned(),
            };
            return differs("head", shown(a), shown(b));
        }
    };
    let head = num("head.cycle_s", hx.cycle_s, hy.cycle_s)
        .or_else(|| {
            num(
                "head.origin_radius_mm",
                hx.origin_radius_mm,
                hy.origin_radius_mm,
            )
        })
        .or_else(|| {
            num(
                "head.origin_height_mm",
                hx.origin_height_mm,
                hy.origin_height_mm,
            )
        })
        .or_else(|| {
            num(
                "head.exit_diameter_mm",
                hx.exit_diameter_mm,
                hy.exit_diameter_mm,
            )
        })
        .or_else(|| {
            num(
                "head.divergence_mrad",
                hx.divergence_mrad,
                hy.divergence_mrad,
            )
        })
        .or_else(|| {
            num(
                "head.aperture_distance_mm",
                hx.aperture_distance_mm,
                hy.aperture_distance_mm,
            )
        });
    if let Some(d) = head {
        return d;
    }
    if hx.channels.len() != hy.channels.len() {
        return differs(
            "head.channels",
            format!("{} channels", hx.channels.len()),
            format!("{}", hy.channels.len()),
        );
    }
    for (i, (a, b)) in hx.channels.iter().zip(&hy.channels).enumerate() {
        let f = |name: &str| format!("head.channels[{i}].{name}");
        if a.id != b.id {
            return differs(&f("id"), a.id.to_string(), b.id.to_string());
        }
        let d = num(&f("elevation_deg"), a.elevation_deg, b.elevation_deg)
            .or_else(|| {
                num(
                    &f("azimuth_offset_deg"),
                    a.azimuth_offset_deg,
                    b.azimuth_offset_deg,
                )
            })
            .or_else(|| num(&f("slot_s"), a.slot_s, b.slot_s))
            .or_else(|| num(&f("power_scale"), a.power_scale, b.power_scale));
        if let Some(d) = d {
            return d;
        }
    }
    // Unreachable for unequal sets (every field compared above).
    "limits.eye_safety: differs from the sensor's".to_owned()
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

/// A sensor description that cannot be a sensor: the key (as written in a
/// sensor file, e.g. `limits.power_w_max`), its value and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field} = {value}: {reason}")]
pub struct SpecError {
    /// The key, dotted from the top of the sensor description.
    pub field: String,
    /// The value found (NaN when the key is not a number).
    pub value: f64,
    /// Why it is refused.
    pub reason: String,
}

impl LidarSpec {
    /// Checks every number of the sensor at the one numeric boundary
    /// ([`valid`]): rates of physical size, magnitudes finite and not
    /// subnormal, budgets and maxima `> 0`, no inverted pair, eye-safety
    /// parameters present and valid. Every rule fails on NaN. The first
    /// offending key is named.
    pub fn validate(&self) -> Result<(), SpecError> {
        let err = |field: &str, value: f64, reason: &str| SpecError {
            field: field.to_owned(),
            value,
            reason: reason.to_owned(),
        };
        let check = |field: &str, value: f64, rule: fn(f64) -> Result<f64, valid::Reason>| {
            rule(value).map(drop).map_err(|r| err(field, value, r))
        };
        check("frame_rate_hz", self.frame_rate_hz, valid::rate_hz)?;
        check("pulse_rate_hz", self.pulse_rate_hz, valid::rate_hz)?;
        if self.channels == 0 {
            return Err(err("channels", 0.0, "must be >= 1"));
        }
        check("average_power_w", self.average_power_w, valid::positive)?;
        check("rated_range_m", self.rated_range_m, valid::positive)?;
        check(
            "reference_reflectivity",
            self.reference_reflectivity,
            valid::positive,
        )?;
        if !valid::ordered(self.reference_reflectivity, 1.0) {
            return Err(err(
                "reference_reflectivity",
                self.reference_reflectivity,
                "must be <= 1 (a Lambertian reflectivity)",
            ));
        }
        let l = &self.limits;
        check("limits.power_w_min", l.power_w_min, valid::magnitude)?;
        check("limits.power_w_max", l.power_w_max, valid::positive)?;
        check("limits.spin_rad_s_min", l.spin_rad_s_min, valid::magnitude)?;
        check("limits.spin_rad_s_max", l.spin_rad_s_max, valid::positive)?;
        if let Some(a) = l.spin_accel_rad_s2_max {
            check("limits.spin_accel_rad_s2_max", a, valid::magnitude)?;
        }
        if let Some(s) = l.power_slew_w_per_deg_max {
            check("limits.power_slew_w_per_deg_max", s, valid::magnitude)?;
        }
        if !valid::ordered(l.power_w_min, l.power_w_max) {
            return Err(err(
                "limits.power_w_min",
                l.power_w_min,
                "is above limits.power_w_max",
            ));
        }
        if !valid::ordered(l.spin_rad_s_min, l.spin_rad_s_max) {
            return Err(err(
                "limits.spin_rad_s_min",
                l.spin_rad_s_min,
                "is above limits.spin_rad_s_max",
            ));
        }
        if let Some(head) = l.eye_safety.as_ref().and_then(|e| e.head.as_ref()) {
            if self.channels as usize != head.channels.len() {
                return Err(err(
                    "channels",
                    f64::from(self.channels),
                    &format!(
                        "must equal the number of channels of limits.eye_safety.head ({})",
                        head.channels.len()
                    ),
                ));
            }
        }
        match &l.eye_safety {
            None => Err(err(
                "limits.eye_safety",
                f64::NAN,
                "missing: a sensor's laser and optics parameters are needed for Class 1",
            )),
            Some(params) => params
                .validate()
                .map(drop)
                .and_then(|()| params.check_pulse_rate(self.pulse_rate_hz))
                .map_err(|e| match e {
                crate::eye_safety::EyeSafetyError::Param {
                    field,
                    value,
                    reason,
                } => err(&format!("limits.eye_safety.{field}"), value, reason),
                crate::eye_safety::EyeSafetyError::Head(h) => err(
                    &format!("limits.eye_safety.head.{}", h.field),
                    h.value,
                    h.reason,
                ),
                crate::eye_safety::EyeSafetyError::PulseRate { expected_hz, .. } => err(
                    "pulse_rate_hz",
                    self.pulse_rate_hz,
                    &format!(
                        "must be 1/limits.eye_safety.head.cycle_s = {} within 1e-9 with a head (every channel fires once per cycle)",
                        crate::text::Num(expected_hz)
                    ),
                ),
                crate::eye_safety::EyeSafetyError::Ael(_) => err(
                    "limits.eye_safety.wavelength_nm",
                    params.wavelength_nm,
                    "outside the supported bands (700–1050 nm, 1400–1800 nm)",
                ),
            }),
        }
    }
}
