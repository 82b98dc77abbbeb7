//! The T-intersection scene, top view, in the ego LiDAR's frame (ISO 8855:
//! x forward, y left; the LiDAR at the origin).
//!
//! ```text
//!          far-side buildings (x ≥ far_edge + sidewalk)
//!   ───────────────────────────────────────────────────  x = far edge
//!   ←── right car lane (from the right, drives +y)  ──  far lane
//!   ·····························································
//!   ── left car lane (from the left, drives −y) ──→     near lane
//!   ──────────────┐        ┌─────────────────────────  x = near edge
//!    corner block │  ego ▲ │ corner block
//!   (y ≤ −stem/2) │  LiDAR │ (y ≥ stem/2)
//! ```
//! The main road runs along y. Beyond `±bend_distance_m` it bends away
//! behind buildings; they are modelled as occluder blocks the cars drive out
//! of (a ray from the LiDAR into a block always hits its face first, so a
//! car inside one is never seen). Traffic keeps right: the car from the left
//! uses the near lane, the one from the right the far lane. Every object is
//! an axis-aligned box, so ray casts are exact slab tests.
//!
//! Calibration (documented in the reproduction report): the bend distance
//! sets where the right car first becomes visible; 82 m puts the clear-air
//! TTA of the paper's 50 km/h car at ≈ 5.8 s, the paper's median, while the
//! 100 m rated range is not the limit in clear air (as in the paper, where
//! all four LiDARs agree without fog).

use nalgebra::Point3;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::carla::geometry::StaticBox;
pub use super::carla::params::CarlaParams;

/// Slowest vehicle speed accepted, km/h.
pub const MIN_SPEED_KMH: f64 = 1.0;
/// Fastest vehicle speed accepted, km/h.
pub const MAX_SPEED_KMH: f64 = 500.0;
/// Longest simulated time of one trial, s (the paper's scene: ≈ 6.6 s; each
/// simulated second costs ≈ 10^4 ray casts per channel).
pub const MAX_SIMULATED_S: f64 = 120.0;

/// A `[lo, hi]` pair read as exactly two numbers: a third element is an
/// error, not silently dropped.
fn exact_pair<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    <[f64; 2]>::try_from(v.as_slice())
        .map_err(|_| serde::de::Error::invalid_length(v.len(), &"exactly 2 numbers [min, max]"))
}

/// Scenario parameters (TOML); defaults reproduce the paper's scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scenario {
    /// Distance from the LiDAR to the main road's near edge, m.
    pub near_edge_x_m: f64,
    /// Lane width, m (one lane per direction).
    pub lane_width_m: f64,
    /// Sidewalk width, m.
    pub sidewalk_m: f64,
    /// Width of the stem road the ego stands in, m.
    pub stem_width_m: f64,
    /// x of the corner buildings' front faces (≤ 0: the ego has crept out
    /// past the building line and sees along the main road), m.
    pub corner_front_x_m: f64,
    /// Where the main road bends away behind buildings, m from the stem axis.
    pub bend_distance_m: f64,
    /// Vehicle length, m.
    pub vehicle_length_m: f64,
    /// Vehicle width, m.
    pub vehicle_width_m: f64,
    /// Speed of both vehicles, km/h (paper: 50; 30 and 70 also studied).
    pub speed_kmh: f64,
    /// Half width of the conflict zone along the main road: a car "arrives"
    /// when its front reaches |y| = this (ARGUS: 1.75 m), m.
    pub conflict_half_width_m: f64,
    /// Each car starts hidden, its front this far beyond the bend: a range
    /// `[min, max]` drawn per trial, m (exactly two numbers).
    #[serde(deserialize_with = "exact_pair")]
    pub start_offset_m: [f64; 2],
    /// Driver's gaze azimuth, degrees (paper: fixed to the left, 90°).
    pub gaze_deg: f64,
    /// Standard deviation of the per-trial gaze jitter, degrees.
    pub gaze_jitter_deg: f64,
    /// Lambertian reflectivity of the vehicles.
    pub vehicle_reflectivity: f64,
    /// Lambertian reflectivity of the buildings.
    pub building_reflectivity: f64,
    /// The detector's false detections per frame: in each frame, one with
    /// this probability (`[0, 1]`; planar geometry only; default 0).
    pub false_alarms_per_frame: f64,
    /// The fog threshold: a factor on the `argus` return model's intensity
    /// thresholds in fog (the ARGUS code's 0.055 at code fog 50 and 0.0041
    /// at code fog 100; 1 = the code's values, 0 = no threshold). The
    /// physical model has no fog threshold and ignores it.
    pub argus_fog_threshold_scale: f64,
    /// The `carla` geometry's parameters (table `[carla]`; ignored by `planar`).
    pub carla: CarlaParams,
}

impl Default for Scenario {
    fn default() -> Self {
        Self {
            near_edge_x_m: 3.0,
            lane_width_m: 3.5,
            sidewalk_m: 2.0,
            stem_width_m: 7.0,
            corner_front_x_m: -0.5,
            bend_distance_m: 82.0,
            vehicle_length_m: 4.5,
            vehicle_width_m: 1.8,
            speed_kmh: 50.0,
            conflict_half_width_m: 1.75,
            start_offset_m: [2.0, 12.0],
            gaze_deg: 90.0,
            gaze_jitter_deg: 2.0,
            vehicle_reflectivity: 0.1,
            building_reflectivity: 0.3,
            false_alarms_per_frame: 0.0,
            argus_fog_threshold_scale: 1.0,
            carla: CarlaParams::default(),
        }
    }
}

/// A scenario file or value is invalid.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// TOML did not parse; the message names the key and line.
    #[error("{path}: {message}")]
    Toml {
        /// File.
        path: String,
        /// toml's message.
        message: String,
    },
    /// A value is out of range.
    #[error("scenario.{field} = {}: {reason}", crate::text::Num(*.value))]
    Value {
        /// Key.
        field: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
    /// A trial would simulate too long.
    #[error("scenario: a trial would simulate {seconds:.4e} s (bend_distance_m + start_offset_m[1] − conflict_half_width_m at speed_kmh), more than the {max} s maximum: raise speed_kmh or shorten the distances")]
    Duration {
        /// Simulated time of the slowest trial, s.
        seconds: f64,
        /// The maximum, s.
        max: f64,
    },
    /// File unreadable.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: String,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
}

impl Scenario {
    /// Parses a scenario TOML (missing keys take the defaults).
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, ScenarioError> {
        let s: Self = toml::from_str(text).map_err(|e| ScenarioError::Toml {
            path: origin.to_owned(),
            message: crate::text::toml_error(text, &e),
        })?;
        s.validate()?;
        Ok(s)
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let positive: [(&'static str, f64); 9] = [
            ("lane_width_m", self.lane_width_m),
            ("stem_width_m", self.stem_width_m),
            ("bend_distance_m", self.bend_distance_m),
            ("vehicle_length_m", self.vehicle_length_m),
            ("vehicle_width_m", self.vehicle_width_m),
            ("speed_kmh", self.speed_kmh),
            ("conflict_half_width_m", self.conflict_half_width_m),
            ("vehicle_reflectivity", self.vehicle_reflectivity),
            ("building_reflectivity", self.building_reflectivity),
        ];
        for (field, value) in positive {
            if !(value.is_finite() && value > 0.0 && value < 1e5) {
                return Err(ScenarioError::Value {
                    field,
                    value,
                    reason: "must be finite, > 0 and < 1e5",
                });
            }
        }
        let finite: [(&'static str, f64); 5] = [
            ("near_edge_x_m", self.near_edge_x_m),
            ("sidewalk_m", self.sidewalk_m),
            ("corner_front_x_m", self.corner_front_x_m),
            ("gaze_deg", self.gaze_deg),
            ("gaze_jitter_deg", self.gaze_jitter_deg),
        ];
        for (field, value) in finite {
            if !value.is_finite() || value.abs() > 1e4 {
                return Err(ScenarioError::Value {
                    field,
                    value,
                    reason: "must be finite and within ±1e4",
                });
            }
        }
        let bad = |field, value, reason| {
            Err(ScenarioError::Value {
                field,
                value,
                reason,
            })
        };
        if self.near_edge_x_m <= 0.0 {
            return bad(
                "near_edge_x_m",
                self.near_edge_x_m,
                "the LiDAR must stand before the main road (> 0)",
            );
        }
        if self.sidewalk_m < 0.0 || self.gaze_jitter_deg < 0.0 {
            return bad(
                "sidewalk_m",
                self.sidewalk_m.min(self.gaze_jitter_deg),
                "must be >= 0 (also gaze_jitter_deg)",
            );
        }
        if self.corner_front_x_m >= self.near_edge_x_m {
            return bad(
                "corner_front_x_m",
                self.corner_front_x_m,
                "must be before the main road's near edge",
            );
        }
        if self.vehicle_reflectivity > 1.0 || self.building_reflectivity > 1.0 {
            return bad(
                "vehicle_reflectivity",
                self.vehicle_reflectivity.max(self.building_reflectivity),
                "reflectivities must be <= 1",
            );
        }
        if !(0.0..=1.0).contains(&self.false_alarms_per_frame) {
            return bad(
                "false_alarms_per_frame",
                self.false_alarms_per_frame,
                "must be a probability per frame in [0, 1]",
            );
        }
        if !(0.0..=100.0).contains(&self.argus_fog_threshold_scale) {
            return bad(
                "argus_fog_threshold_scale",
                self.argus_fog_threshold_scale,
                "must lie in [0, 100] (1: the ARGUS code's thresholds)",
            );
        }
        if self.vehicle_width_m >= self.lane_width_m {
            return bad(
                "vehicle_width_m",
                self.vehicle_width_m,
                "must be narrower than lane_width_m",
            );
        }
        let [lo, hi] = self.start_offset_m;
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi && hi < 1e4) {
            return bad(
                "start_offset_m",
                lo,
                "must be [min, max] with 0 <= min <= max < 1e4",
            );
        }
        if self.bend_distance_m
            <= self.conflict_half_width_m + self.stem_width_m / 2.0 + self.sidewalk_m
        {
            return bad(
                "bend_distance_m",
                self.bend_distance_m,
                "must lie beyond the corner buildings",
            );
        }
        if !(MIN_SPEED_KMH..=MAX_SPEED_KMH).contains(&self.speed_kmh) {
            return bad(
                "speed_kmh",
                self.speed_kmh,
                "must lie in [1, 500] km/h (a slower car makes a trial simulate hours of pulses)",
            );
        }
        self.carla
            .validate()
            .or_else(|(field, value, reason)| bad(field, value, reason))?;
        if self.carla.spawn_distance_m <= self.conflict_half_width_m + self.vehicle_length_m {
            return bad(
                "carla.spawn_distance_m",
                self.carla.spawn_distance_m,
                "must exceed conflict_half_width_m + vehicle_length_m",
            );
        }
        let t = self.max_duration_s();
        if t.is_nan() || t > MAX_SIMULATED_S {
            return Err(ScenarioError::Duration {
                seconds: t,
                max: MAX_SIMULATED_S,
            });
        }
        Ok(())
    }

    /// The longest simulated time of a trial: until the later car, starting
    /// at the far end of `start_offset_m` beyond the bend, reaches the
    /// conflict zone at `speed_kmh`, s.
    #[must_use]
    pub fn max_duration_s(&self) -> f64 {
        (self.bend_distance_m + self.start_offset_m[1] - self.conflict_half_width_m)
            / self.speed_m_s()
    }

    /// Checks the `carla` geometry's trial length (checked only when that
    /// geometry runs, so planar scenarios validate as before).
    pub fn validate_carla(&self) -> Result<(), ScenarioError> {
        let t = self.carla_max_duration_s();
        if t.is_nan() || t > MAX_SIMULATED_S {
            return Err(ScenarioError::Duration {
                seconds: t,
                max: MAX_SIMULATED_S,
            });
        }
        Ok(())
    }

    /// The longest simulated time of a `carla` trial (front arrival, or the
    /// centre's, half a length later), s.
    #[must_use]
    pub fn carla_max_duration_s(&self) -> f64 {
        (self.carla.spawn_distance_m + self.start_offset_m[1] + 0.5 * self.vehicle_length_m
            - self.conflict_half_width_m)
            / self.speed_m_s()
    }

    /// The static boxes of the `carla` geometry: the corner blocks (and,
    /// with `carla.far_side_buildings`, a far-side frontage) as buildings
    /// `carla.building_height_m` tall, lining the main road to
    /// `carla.road_half_length_m`; no bend, no occluder.
    #[must_use]
    pub fn carla_static_boxes(&self) -> Vec<StaticBox> {
        let far_edge = self.near_edge_x_m + 2.0 * self.lane_width_m;
        let half_stem = 0.5 * self.stem_width_m + self.sidewalk_m;
        let l = self.carla.road_half_length_m;
        let h = self.carla.building_height_m;
        let depth = 40.0;
        let b = |x0: f64, x1: f64, y0: f64, y1: f64| StaticBox {
            min: Point3::new(x0.min(x1), y0.min(y1), 0.0),
            max: Point3::new(x0.max(x1), y0.max(y1), h),
        };
        let mut boxes = vec![
            b(
                self.corner_front_x_m - depth,
                self.corner_front_x_m,
                half_stem,
                l,
            ),
            b(
                self.corner_front_x_m - depth,
                self.corner_front_x_m,
                -l,
                -half_stem,
            ),
        ];
        if self.carla.far_side_buildings {
            boxes.push(b(
                far_edge + self.sidewalk_m,
                far_edge + self.sidewalk_m + depth,
                -l,
                l,
            ));
        }
        boxes
    }

    /// Vehicle speed, m/s.
    #[must_use]
    pub fn speed_m_s(&self) -> f64 {
        self.speed_kmh / 3.6
    }

    /// Lane centre x of the car from the left (near lane) and from the right (far lane).
    #[must_use]
    pub fn lane_x_m(&self) -> [f64; 2] {
        [
            self.near_edge_x_m + 0.5 * self.lane_width_m,
            self.near_edge_x_m + 1.5 * self.lane_width_m,
        ]
    }

    /// The static boxes: corner blocks, far-side frontage, bend occluders.
    #[must_use]
    pub fn static_boxes(&self) -> Vec<Aabb> {
        let far_edge = self.near_edge_x_m + 2.0 * self.lane_width_m;
        let half_stem = 0.5 * self.stem_width_m + self.sidewalk_m;
        let l = self.bend_distance_m;
        let depth = 40.0;
        vec![
            // Corner blocks either side of the stem.
            Aabb::new(
                self.corner_front_x_m - depth,
                self.corner_front_x_m,
                half_stem,
                l + depth,
            ),
            Aabb::new(
                self.corner_front_x_m - depth,
                self.corner_front_x_m,
                -(l + depth),
                -half_stem,
            ),
            // Frontage across the main road.
            Aabb::new(
                far_edge + self.sidewalk_m,
                far_edge + self.sidewalk_m + depth,
                -l,
                l,
            ),
            // Bend occluders the cars emerge from.
            Aabb::new(
                self.corner_front_x_m,
                far_edge + self.sidewalk_m + depth,
                l,
                l + depth,
            ),
            Aabb::new(
                self.corner_front_x_m,
                far_edge + self.sidewalk_m + depth,
                -(l + depth),
                -l,
            ),
        ]
    }
}

/// An axis-aligned box `[x0, x1] × [y0, y1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Min x.
    pub x0: f64,
    /// Max x.
    pub x1: f64,
    /// Min y.
    pub y0: f64,
    /// Max y.
    pub y1: f64,
}

/// A ray hit: distance and the cosine of the incidence angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance from the origin, m.
    pub range_m: f64,
    /// |cos| of the angle between the ray and the face normal.
    pub cos_incidence: f64,
}

impl Aabb {
    /// A box from its bounds (sorted).
    #[must_use]
    pub fn new(x0: f64, x1: f64, y0: f64, y1: f64) -> Self {
        Self {
            x0: x0.min(x1),
            x1: x0.max(x1),
            y0: y0.min(y1),
            y1: y0.max(y1),
        }
    }

    /// First hit of the ray from the origin along the unit vector `(c, s)`,
    /// if it enters the box at a positive distance (slab method; exact).
    #[must_use]
    pub fn ray_hit(&self, c: f64, s: f64) -> Option<Hit> {
        // Entry/exit parameters per axis; a zero component means the ray is
        // parallel to that slab: inside it (any t) or never.
        let (tx0, tx1) = slab(self.x0, self.x1, c)?;
        let (ty0, ty1) = slab(self.y0, self.y1, s)?;
        let t_in = tx0.max(ty0);
        let t_out = tx1.min(ty1);
        if t_in > t_out || t_in <= 0.0 {
            return None;
        }
        // The face entered is the one whose slab entry is later.
        let cos_incidence = if tx0 >= ty0 { c.abs() } else { s.abs() };
        Some(Hit {
            range_m: t_in,
            cos_incidence,
        })
    }

    /// Corners, for angular bounds.
    #[must_use]
    pub fn corners(&self) -> [(f64, f64); 4] {
        [
            (self.x0, self.y0),
            (self.x1, self.y0),
            (self.x1, self.y1),
            (self.x0, self.y1),
        ]
    }

    /// Whether the origin lies inside (then every direction may hit).
    #[must_use]
    pub fn contains_origin(&self) -> bool {
        self.x0 <= 0.0 && 0.0 <= self.x1 && self.y0 <= 0.0 && 0.0 <= self.y1
    }
}

fn slab(lo: f64, hi: f64, d: f64) -> Option<(f64, f64)> {
    if d == 0.0 {
        if lo <= 0.0 && 0.0 <= hi {
            Some((f64::NEG_INFINITY, f64::INFINITY))
        } else {
            None
        }
    } else {
        let a = lo / d;
        let b = hi / d;
        Some((a.min(b), a.max(b)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_hits_and_incidence() {
        let b = Aabb::new(10.0, 12.0, -1.0, 1.0);
        let h = b.ray_hit(1.0, 0.0).unwrap();
        assert_eq!(h.range_m, 10.0);
        assert_eq!(h.cos_incidence, 1.0);
        assert!(b.ray_hit(-1.0, 0.0).is_none());
        assert!(b.ray_hit(0.0, 1.0).is_none());
        let d = 45f64.to_radians();
        let b = Aabb::new(-1.0, 1.0, 5.0, 6.0);
        let h = b.ray_hit(d.cos(), d.sin()).unwrap_or(Hit {
            range_m: 0.0,
            cos_incidence: 0.0,
        });
        assert_eq!(h.range_m, 0.0, "ray at 45° passes x=1 before y=5: misses");
        let h = b.ray_hit(0.0, 1.0).unwrap();
        assert_eq!((h.range_m, h.cos_incidence), (5.0, 1.0));
    }

    #[test]
    fn default_scenario_is_valid_and_round_trips() {
        let s = Scenario::default();
        s.validate().unwrap();
        let text = toml::to_string(&s).unwrap();
        assert_eq!(Scenario::from_toml(&text, "x").unwrap(), s);
        let e = Scenario::from_toml("speed_kmh = -3.0", "f.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("speed_kmh"), "{e}");
        let e = Scenario::from_toml("sped_kmh = 3.0", "f.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("sped_kmh") && e.contains("f.toml"), "{e}");
    }
}
