//! The `[carla]` table of a scenario: the 3D sensor, the heights of things,
//! where the cars spawn, CARLA's drop-off and ARGUS's detector thresholds.
//!
//! Sources (see `docs/reproduction.md`, "literal or assumed"):
//! - CARLA `sensor.lidar.ray_cast` defaults (FLidarDescription): upper/lower
//!   FoV 10°/−30°, `atmosphere_attenuation_rate` 0.004 /m,
//!   `dropoff_general_rate` 0.45, `dropoff_intensity_limit` 0.8,
//!   `dropoff_zero_intensity` 0.4; ARGUS sets `channels` 64 and `range` 100 m
//!   (`lidar2.py`, `lidar_setup`).
//! - ARGUS's detector (`lidar2.py`, `preprocess_lidar.py`, `grid.py`): road
//!   points below z = −2.8 m in the sensor frame, vehicle points at
//!   z ≥ −2.6 m in a 1 m road cell, right of y = −10 m with one beyond
//!   x = 8 m; the kept half-plane follows the ego's world yaw.
//! - Assumed: the mount height (ARGUS mounts at z = 2.5 m above the ego
//!   actor's origin, which is not the road; its road threshold needs the road
//!   more than 2.8 m below the sensor and its road-extent check expects road
//!   cells out to |y| = 78 m, which CARLA's channel spacing reaches only from
//!   2.81 m up: we take 3.0 m), heights, spawn distance, tick length.

use serde::{Deserialize, Serialize};

/// Parameters of the `carla` geometry (ignored by `planar`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CarlaParams {
    /// Channels (ARGUS: 64).
    pub channels: u32,
    /// Upper edge of the vertical field of view, degrees (CARLA default 10).
    pub upper_fov_deg: f64,
    /// Lower edge of the vertical field of view, degrees (CARLA default −30).
    pub lower_fov_deg: f64,
    /// Trace length, m (ARGUS: 100).
    pub range_m: f64,
    /// LiDAR height above the road, m (assumed; see the module docs).
    pub mount_height_m: f64,
    /// CARLA's `atmosphere_attenuation_rate`: raw intensity `e^(−rate·r)`, 1/m.
    pub atmosphere_attenuation_rate_per_m: f64,
    /// CARLA's `dropoff_general_rate`: fraction of rays dropped before casting.
    pub dropoff_general_rate: f64,
    /// CARLA's `dropoff_intensity_limit`: above it no intensity drop-off.
    pub dropoff_intensity_limit: f64,
    /// CARLA's `dropoff_zero_intensity`: drop probability at zero intensity.
    pub dropoff_zero_intensity: f64,
    /// Simulation tick, s: the scene is frozen per tick and the LiDAR's
    /// points of a tick arrive together (one CARLA sensor callback).
    pub tick_s: f64,
    /// Vehicle height, m (CARLA's Audi A2, the paper's car: ≈ 1.55).
    pub vehicle_height_m: f64,
    /// Height of a car's body above the road, m: the box spans
    /// `[clearance, vehicle_height_m]` and rays pass beneath it (wheels are
    /// not modelled). Assumed 0.15 m, a typical passenger car's ground
    /// clearance; neither ARGUS nor CARLA's code states the A2 mesh's. At
    /// 0 the lowest 0.2 m of a car's face lies below ARGUS's road threshold
    /// (z < −2.8 m at the 3.0 m mount) and counts as road.
    pub vehicle_ground_clearance_m: f64,
    /// CARLA's asynchronous mode (`--sampling carla-async`): each tick's
    /// length is drawn uniformly from `tick_s · [1 − j, 1 + j]`. Assumed
    /// 0.2: the spread of the server's frame times is not known.
    pub async_tick_jitter_frac: f64,
    /// The azimuth phase of CARLA's scan grid at the trial's first tick, in
    /// steps of the grid (`[0, 1)`; one step = 360°·f·dt / points per laser
    /// per tick): added to the start angle CARLA's rule gives (`--sampling
    /// carla` and `carla-async`; `drift` draws its phase per trial). Assumed
    /// 0: CARLA's angle is 0 at spawn, but how the sensor's first tick lines
    /// up with the scene is not in ARGUS's code.
    pub grid_phase_steps: f64,
    /// Building height, m.
    pub building_height_m: f64,
    /// Reflectivity of the road (physical model).
    pub ground_reflectivity: f64,
    /// Each car's front starts this far from the stem axis plus the
    /// scenario's `start_offset_m` draw, m (beyond the trace length: hidden
    /// by range, no occluder).
    pub spawn_distance_m: f64,
    /// Buildings line the main road to this distance either side, m.
    pub road_half_length_m: f64,
    /// A building frontage across the main road (behind the far sidewalk).
    /// Off by default: ARGUS's rule takes a wall's foot (below the road
    /// threshold) for road and the wall above it for a vehicle, so a wall in
    /// its detection region fires at once; the paper's map had none there.
    pub far_side_buildings: bool,
    /// ARGUS: road points lie below this z in the sensor frame, m.
    pub argus_road_z_m: f64,
    /// ARGUS: vehicle points lie at or above this z in the sensor frame, m.
    pub argus_vehicle_z_m: f64,
    /// ARGUS: road-mask cell size, m.
    pub argus_cell_m: f64,
    /// ARGUS: vehicle points count right of this y (y <), m.
    pub argus_y_max_m: f64,
    /// ARGUS: one vehicle point must lie beyond this x (x >), m.
    pub argus_x_min_m: f64,
    /// ARGUS: the ego's world yaw, degrees; the detector keeps points whose
    /// azimuth θ satisfies |wrap(θ − yaw − 90°)| ≤ 90° (yaw −90°: x ≥ 0).
    pub ego_yaw_deg: f64,
}

impl Default for CarlaParams {
    fn default() -> Self {
        Self {
            channels: 64,
            upper_fov_deg: 10.0,
            lower_fov_deg: -30.0,
            range_m: 100.0,
            mount_height_m: 3.0,
            atmosphere_attenuation_rate_per_m: 0.004,
            dropoff_general_rate: 0.45,
            dropoff_intensity_limit: 0.8,
            dropoff_zero_intensity: 0.4,
            tick_s: 0.05,
            vehicle_height_m: 1.55,
            vehicle_ground_clearance_m: 0.15,
            async_tick_jitter_frac: 0.2,
            grid_phase_steps: 0.0,
            building_height_m: 10.0,
            ground_reflectivity: 0.15,
            spawn_distance_m: 100.0,
            road_half_length_m: 200.0,
            far_side_buildings: false,
            argus_road_z_m: -2.8,
            argus_vehicle_z_m: -2.6,
            argus_cell_m: 1.0,
            argus_y_max_m: -10.0,
            argus_x_min_m: 8.0,
            ego_yaw_deg: -90.0,
        }
    }
}

/// A bad value: (field, value, reason).
pub type Bad = (&'static str, f64, &'static str);

impl CarlaParams {
    /// Checks every value; the error names the key (`carla.<key>`).
    pub fn validate(&self) -> Result<(), Bad> {
        if !(1..=256).contains(&self.channels) {
            return Err((
                "carla.channels",
                f64::from(self.channels),
                "must lie in 1..=256",
            ));
        }
        let finite: [(&'static str, f64, f64, f64); 23] = [
            ("carla.upper_fov_deg", self.upper_fov_deg, -89.0, 89.0),
            ("carla.lower_fov_deg", self.lower_fov_deg, -89.0, 89.0),
            ("carla.range_m", self.range_m, 1.0, 1000.0),
            ("carla.mount_height_m", self.mount_height_m, 0.1, 100.0),
            (
                "carla.atmosphere_attenuation_rate_per_m",
                self.atmosphere_attenuation_rate_per_m,
                0.0,
                1.0,
            ),
            (
                "carla.dropoff_general_rate",
                self.dropoff_general_rate,
                0.0,
                0.99,
            ),
            (
                "carla.dropoff_intensity_limit",
                self.dropoff_intensity_limit,
                1e-6,
                1.0,
            ),
            (
                "carla.dropoff_zero_intensity",
                self.dropoff_zero_intensity,
                0.0,
                1.0,
            ),
            ("carla.tick_s", self.tick_s, 1e-3, 1.0),
            ("carla.vehicle_height_m", self.vehicle_height_m, 0.1, 10.0),
            (
                "carla.vehicle_ground_clearance_m",
                self.vehicle_ground_clearance_m,
                0.0,
                1.0,
            ),
            (
                "carla.async_tick_jitter_frac",
                self.async_tick_jitter_frac,
                0.0,
                0.9,
            ),
            ("carla.grid_phase_steps", self.grid_phase_steps, 0.0, 1.0),
            (
                "carla.building_height_m",
                self.building_height_m,
                0.1,
                1000.0,
            ),
            (
                "carla.ground_reflectivity",
                self.ground_reflectivity,
                1e-6,
                1.0,
            ),
            ("carla.spawn_distance_m", self.spawn_distance_m, 1.0, 1e4),
            (
                "carla.road_half_length_m",
                self.road_half_length_m,
                1.0,
                1e4,
            ),
            ("carla.argus_road_z_m", self.argus_road_z_m, -100.0, 100.0),
            (
                "carla.argus_vehicle_z_m",
                self.argus_vehicle_z_m,
                -100.0,
                100.0,
            ),
            ("carla.argus_cell_m", self.argus_cell_m, 0.05, 100.0),
            ("carla.argus_y_max_m", self.argus_y_max_m, -1e4, 1e4),
            ("carla.argus_x_min_m", self.argus_x_min_m, -1e4, 1e4),
            ("carla.ego_yaw_deg", self.ego_yaw_deg, -360.0, 360.0),
        ];
        for (field, v, lo, hi) in finite {
            if !(v.is_finite() && lo <= v && v <= hi) {
                return Err((field, v, "out of range (see the [carla] table's docs)"));
            }
        }
        if self.grid_phase_steps >= 1.0 {
            return Err((
                "carla.grid_phase_steps",
                self.grid_phase_steps,
                "must lie in [0, 1) (a fraction of one azimuth step)",
            ));
        }
        if self.vehicle_ground_clearance_m >= 0.5 * self.vehicle_height_m {
            return Err((
                "carla.vehicle_ground_clearance_m",
                self.vehicle_ground_clearance_m,
                "must be below half of vehicle_height_m",
            ));
        }
        if self.lower_fov_deg > self.upper_fov_deg {
            return Err((
                "carla.lower_fov_deg",
                self.lower_fov_deg,
                "must not exceed upper_fov_deg",
            ));
        }
        Ok(())
    }
}
