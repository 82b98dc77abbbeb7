//! The `carla` geometry: CARLA's 3D ray-cast LiDAR (all channels, elevation
//! angles over the vertical field of view, a mount above a flat road) in the
//! T-intersection with buildings and vehicles as 3D boxes, CARLA's tick
//! semantics and drop-off, and ARGUS's detector ([`argus`]).
//!
//! One trial, per CARLA tick of `tick_s`: the cars are posed at the tick's
//! end (CARLA casts a tick's rays against the world after its physics step);
//! every pulse of the tick fires all channels at the profile's azimuth for
//! its time; a ray is dropped before casting with `dropoff_general_rate`,
//! cast against the ground plane, the buildings and the cars (nearest hit
//! within the trace length `range_m`, slant range), and a hit of raw
//! intensity `I = e^(−rate·r)` at or below `dropoff_intensity_limit` is kept
//! with probability `(1 − zero)·… ` as CARLA's `PostprocessDetection`:
//! `zero/limit · I + (1 − zero)`. The return model then decides per cell
//! (the `argus` model scales `I` by the profile's power ratio and the fog
//! factor, exactly as in the planar geometry). Detection happens at the end
//! of a tick (the callback): `first-return` on any returned point on a car,
//! `argus` by ARGUS's rule.
//!
//! Cells (model × variant × fog) whose profiles share the same timeline (the
//! same azimuth at every pulse) are evaluated on the same rays: geometry and
//! CARLA's drop-off are cast once per trial and timeline.
//!
//! Acceleration, bit-identical to casting every ray against everything
//! (`brute_force`; tested): a box is tested only if the channel's ray can
//! reach its height band inside its horizontal distance band before the
//! trace ends or meets the ground ([`geometry::channel_may_reach`]), and
//! only if the azimuth lies in the box's angular extent (cars: per tick).

pub mod argus;
pub mod geometry;
pub mod params;

use nalgebra::{Point3, Vector3};

use crate::model::acuity::Regions;
use crate::model::angle::Arc;
use crate::profile::kinematics::Timeline;
use crate::profile::Profile;

use super::returns::{ReturnModel, ARGUS_RANGE_M};
use super::scene::{Aabb, Scenario};
use super::trial::{cull_arc, mix64, KOfN, TrialDraw, TrialOutcome};
use super::{Arrival, Detector};
use argus::ArgusDetector;
use geometry::{channel_may_reach, footprint_distances, Hit, PosedBox, Sensor, StaticBox, Surface};

/// Padding of the culling bounds, m (far above `f64` rounding at 1 km).
pub const CULL_PAD_M: f64 = 1e-6;

/// One cell of a group: a (model, variant, fog) on this trial.
#[derive(Debug, Clone, Copy)]
pub struct CellSpec<'a> {
    /// The profile the LiDAR runs (its timeline is the group's).
    pub profile: &'a Profile,
    /// Fraction of RoF points kept.
    pub rof_keep: f64,
    /// Driver regions for this trial's gaze.
    pub regions: &'a Regions,
    /// Return model at this fog level.
    pub model: &'a ReturnModel,
    /// Driver's visual range in this fog, m.
    pub driver_range_m: f64,
}

/// Everything a group of cells needs besides the random draw.
#[derive(Debug, Clone, Copy)]
pub struct GroupSetup<'a> {
    /// Scene.
    pub scenario: &'a Scenario,
    /// Buildings.
    pub statics: &'a [StaticBox],
    /// The cells; all profiles share one timeline.
    pub cells: &'a [CellSpec<'a>],
    /// Detector.
    pub detector: Detector,
    /// Arrival rule.
    pub arrival: Arrival,
    /// k-of-n over ticks (`first-return`).
    pub detection: KOfN,
    /// Disable culling (reference path).
    pub brute_force: bool,
    /// This trial's gaze, degrees.
    pub gaze_deg: f64,
}

/// Whether two profiles put every pulse at the same azimuth (same pulse
/// rate and the same bins' extents and spins, bit for bit).
#[must_use]
pub fn same_timeline(a: &Profile, b: &Profile) -> bool {
    a.pulse_rate_hz.to_bits() == b.pulse_rate_hz.to_bits()
        && a.bins.len() == b.bins.len()
        && a.bins.iter().zip(&b.bins).all(|(x, y)| {
            x.start_deg.to_bits() == y.start_deg.to_bits()
                && x.width_deg.to_bits() == y.width_deg.to_bits()
                && x.spin_start_rad_s.to_bits() == y.spin_start_rad_s.to_bits()
                && x.spin_end_rad_s.to_bits() == y.spin_end_rad_s.to_bits()
        })
}

/// Uniform in `[0, 1)` from a key.
fn unit(key: u64) -> f64 {
    (mix64(key) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The world of one tick: cars posed, with their culling data.
struct Cars {
    boxes: [PosedBox; 2],
    arcs: [Arc; 2],
    /// `may[j][ch]`: channel `ch` can reach car `j` this tick.
    may: [Vec<bool>; 2],
}

/// The static world and the sensor, with per-channel culling data.
struct World<'a> {
    sensor: Sensor,
    origin: Point3<f64>,
    statics: &'a [StaticBox],
    static_arcs: Vec<Arc>,
    /// `static_may[ch]`: bit b set if channel `ch` can reach box b.
    static_may: Vec<u64>,
    /// Horizontal reach of each channel: trace end or ground, m.
    reach_m: Vec<f64>,
    tan_el: Vec<f64>,
    /// Per channel: the ground's distance along the ray if within the trace.
    ground_t: Vec<Option<f64>>,
    brute_force: bool,
}

impl<'a> World<'a> {
    fn new(sc: &Scenario, statics: &'a [StaticBox], brute_force: bool) -> Self {
        let p = &sc.carla;
        let sensor = Sensor::new(
            p.mount_height_m,
            geometry::carla_elevations_deg(p.channels, p.upper_fov_deg, p.lower_fov_deg),
            p.range_m,
        );
        let origin = sensor.origin();
        let h = origin.z;
        let n = sensor.elevations_deg.len();
        let tan_el: Vec<f64> = (0..n)
            .map(|c| sensor.sin_el[c] / sensor.cos_el[c])
            .collect();
        let reach_m: Vec<f64> = (0..n)
            .map(|c| {
                let trace = p.range_m * sensor.cos_el[c];
                if tan_el[c] < 0.0 {
                    trace.min(h / -tan_el[c])
                } else {
                    trace
                }
            })
            .collect();
        let static_arcs = statics
            .iter()
            .map(|b| {
                let [x0, x1, y0, y1] = b.footprint();
                cull_arc(&[Aabb::new(x0, x1, y0, y1)])
            })
            .collect();
        let static_may = (0..n)
            .map(|c| {
                if statics.len() > 64 {
                    return u64::MAX;
                }
                statics.iter().enumerate().fold(0u64, |m, (i, b)| {
                    let dist = footprint_distances(b.footprint());
                    let ok =
                        channel_may_reach(h, tan_el[c], b.heights(), dist, reach_m[c], CULL_PAD_M);
                    m | (u64::from(ok) << i)
                })
            })
            .collect();
        let ground_t = (0..n)
            .map(|c| {
                let d = sensor.direction(c, 1.0, 0.0);
                geometry::ground_hit(&origin, &d)
                    .map(|h| h.range_m)
                    .filter(|&t| t <= p.range_m)
            })
            .collect();
        Self {
            sensor,
            origin,
            ground_t,
            statics,
            static_arcs,
            static_may,
            reach_m,
            tan_el,
            brute_force,
        }
    }

    fn cars(&self, boxes: [PosedBox; 2]) -> Cars {
        let n = self.tan_el.len();
        let h = self.origin.z;
        let mut arcs = [self.static_arcs.first().copied().unwrap_or(Arc {
            start_deg: 0.0,
            width_deg: 360.0,
        }); 2];
        let mut may = [vec![true; n], vec![true; n]];
        for j in 0..2 {
            let (f, z) = boxes[j].bounds();
            arcs[j] = cull_arc(&[Aabb::new(f[0], f[1], f[2], f[3])]);
            let dist = footprint_distances(f);
            for (c, m) in may[j].iter_mut().enumerate() {
                *m = channel_may_reach(h, self.tan_el[c], z, dist, self.reach_m[c], CULL_PAD_M);
            }
        }
        Cars { boxes, arcs, may }
    }

    /// Bits of the statics whose angular extent contains `az`.
    fn static_mask_at(&self, az: f64) -> u64 {
        if self.brute_force || self.statics.len() > 64 {
            return u64::MAX;
        }
        self.static_arcs
            .iter()
            .enumerate()
            .fold(0u64, |m, (i, a)| m | (u64::from(a.contains(az)) << i))
    }

    /// Nearest hit of channel `ch`'s ray at azimuth `az` (direction `d`).
    fn cast(
        &self,
        ch: usize,
        d: &Vector3<f64>,
        az: f64,
        pulse_mask: u64,
        cars: &Cars,
    ) -> Option<Hit> {
        let o = &self.origin;
        let mut best = geometry::ground_hit(o, d);
        let mask = if self.brute_force {
            u64::MAX
        } else {
            self.static_may[ch] & pulse_mask
        };
        for (i, b) in self.statics.iter().enumerate() {
            if i < 64 && mask & (1 << i) == 0 {
                continue;
            }
            if let Some(h) = b.ray_hit(o, d) {
                if best.is_none_or(|x| h.range_m < x.range_m) {
                    best = Some(h);
                }
            }
        }
        for j in 0..2 {
            if !(self.brute_force || cars.may[j][ch] && cars.arcs[j].contains(az)) {
                continue;
            }
            if let Some(h) = cars.boxes[j].ray_hit(o, d, Surface::Vehicle(j)) {
                if best.is_none_or(|x| h.range_m < x.range_m) {
                    best = Some(h);
                }
            }
        }
        best.filter(|h| h.range_m <= self.sensor.range_m)
    }

    /// Nearest hit of the ray from the sensor towards `target` (all objects).
    fn line_of_sight(&self, target: &Point3<f64>, cars: &Cars) -> Option<Hit> {
        let d = (target - self.origin).normalize();
        let o = &self.origin;
        let mut best = geometry::ground_hit(o, &d);
        for b in self.statics {
            if let Some(h) = b.ray_hit(o, &d) {
                if best.is_none_or(|x| h.range_m < x.range_m) {
                    best = Some(h);
                }
            }
        }
        for j in 0..2 {
            if let Some(h) = cars.boxes[j].ray_hit(o, &d, Surface::Vehicle(j)) {
                if best.is_none_or(|x| h.range_m < x.range_m) {
                    best = Some(h);
                }
            }
        }
        best
    }
}

/// Per-cell state of a trial.
struct CellState {
    detected_at: [Option<f64>; 2],
    driver_at: [Option<f64>; 2],
    hit_ticks: [Vec<u64>; 2],
    tick_hit: [bool; 2],
    roi_points: u64,
    roi_pulses: u64,
    argus_roi_points: u64,
    keep_acc: f64,
    argus: Option<ArgusDetector>,
    /// Power ratio `P/P̄` per bin.
    power_ratio: Vec<f64>,
    in_roi: bool,
    in_rof: bool,
    /// Physical model: last `P_D` per channel and the inputs it was for
    /// (range, power, cosine bits): ground hits repeat them exactly.
    pd_cache: Vec<([u64; 3], f64)>,
}

/// Runs one trial for every cell of a group; outcomes in the cells' order.
#[must_use]
// Channel and car indices address several parallel arrays at once.
#[allow(clippy::needless_range_loop)]
pub fn run_group(setup: &GroupSetup<'_>, draw: &TrialDraw) -> Vec<TrialOutcome> {
    let sc = setup.scenario;
    let p = &sc.carla;
    let Some(first) = setup.cells.first() else {
        return Vec::new();
    };
    let tl = Timeline::new(first.profile);
    let period = tl.period_s();
    let pulse_rate = first.profile.pulse_rate_hz;
    let world = World::new(sc, setup.statics, setup.brute_force);
    let channels = world.sensor.elevations_deg.len();
    let v = sc.speed_m_s();
    let lane_x = sc.lane_x_m();
    let len = sc.vehicle_length_m;
    let size = Vector3::new(len, sc.vehicle_width_m, p.vehicle_height_m);
    let ch_half = sc.conflict_half_width_m;
    let super::trial::Crossing {
        front0_m: front0,
        dir,
        t_arrive_s: t_arrive,
    } = draw.crossing(
        p.spawn_distance_m,
        ch_half,
        setup.arrival.extra_distance_m(len),
        v,
    );
    let t_end = t_arrive[0].max(t_arrive[1]);
    let pose = |t: f64| -> [PosedBox; 2] {
        std::array::from_fn(|j| {
            let centre = front0[j] + dir[j] * (v * t - 0.5 * len);
            PosedBox::on_road(
                lane_x[j],
                centre,
                dir[j] * std::f64::consts::FRAC_PI_2,
                size,
            )
        })
    };
    let phase = draw.phase_frac * period;
    let n_pulses = (t_end * pulse_rate).floor() as u64;
    let tick_s = p.tick_s;
    let ego_yaw = p.ego_yaw_deg;
    let alpha = p.dropoff_zero_intensity / p.dropoff_intensity_limit;
    let beta = 1.0 - p.dropoff_zero_intensity;
    let seed_general = mix64(draw.noise_seed ^ 0x6361_726c_6167_656e);
    let seed_intensity = mix64(draw.noise_seed ^ 0x6361_726c_6169_6e74);
    let seed_noise = mix64(draw.noise_seed ^ 0x6361_726c_616e_6f69);

    let mut cells: Vec<CellState> = setup
        .cells
        .iter()
        .map(|c| CellState {
            detected_at: [None, None],
            driver_at: [None, None],
            hit_ticks: [Vec::new(), Vec::new()],
            tick_hit: [false, false],
            roi_points: 0,
            roi_pulses: 0,
            argus_roi_points: 0,
            keep_acc: 0.0,
            argus: (setup.detector == Detector::Argus).then(|| ArgusDetector::new(p)),
            power_ratio: c
                .profile
                .bins
                .iter()
                .map(|b| b.power_w / c.profile.average_power_w)
                .collect(),
            in_roi: false,
            in_rof: false,
            pd_cache: vec![([u64::MAX; 3], 0.0); channels],
        })
        .collect();
    let any_argus = cells.iter().any(|c| c.argus.is_some());
    let cell_grid = ArgusDetector::new(p);
    // Raw intensity per channel, cached on the range's bits.
    let mut raw_cache: Vec<(u64, f64)> = vec![(u64::MAX, 0.0); channels];

    // Ends tick `tick` (state time `t`) for every cell.
    let end_tick = |cells: &mut [CellState], tick: u64, t: f64| {
        for st in cells.iter_mut() {
            for j in 0..2 {
                if !std::mem::take(&mut st.tick_hit[j]) || setup.detector != Detector::FirstReturn {
                    continue;
                }
                if st.detected_at[j].is_some() || t > t_arrive[j] {
                    continue;
                }
                st.hit_ticks[j].push(tick);
                let window_start = tick.saturating_sub(u64::from(setup.detection.n) - 1);
                let recent = st.hit_ticks[j]
                    .iter()
                    .rev()
                    .take_while(|&&f| f >= window_start)
                    .count();
                if recent as u32 >= setup.detection.k {
                    st.detected_at[j] = Some(t);
                }
            }
            if let Some(det) = st.argus.as_mut() {
                if det.end_tick() && st.detected_at[1].is_none() && t <= t_arrive[1] {
                    st.detected_at[1] = Some(t);
                }
            }
        }
    };

    let mut current_tick = u64::MAX;
    let mut t_state = 0.0;
    let mut cars = world.cars(pose(0.0));
    let mut current_frame = u64::MAX;
    let mut frames = 0u64;
    let mut bin_hint = 0usize;
    let gaze = setup.gaze_deg;
    let origin = world.origin;
    for k in 0..n_pulses {
        let t = k as f64 / pulse_rate;
        let tick = (t / tick_s).floor() as u64;
        if tick != current_tick {
            if current_tick != u64::MAX {
                end_tick(&mut cells, current_tick, t_state);
            }
            current_tick = tick;
            t_state = (tick + 1) as f64 * tick_s;
            cars = world.cars(pose(t_state));
            // The driver: looks at each car's front centre at the tick.
            for (st, spec) in cells.iter_mut().zip(setup.cells) {
                for j in 0..2 {
                    if st.driver_at[j].is_some() || t_state > t_arrive[j] {
                        continue;
                    }
                    let front = front0[j] + dir[j] * v * t_state;
                    let target = Point3::new(lane_x[j], front, 0.5 * p.vehicle_height_m);
                    let az = target.y.atan2(target.x).to_degrees();
                    let dist = (target - origin).norm();
                    if spec.regions.rof.contains(az) && dist <= spec.driver_range_m {
                        if let Some(h) = world.line_of_sight(&target, &cars) {
                            if h.surface == Surface::Vehicle(j) {
                                st.driver_at[j] = Some(t_state);
                            }
                        }
                    }
                }
            }
        }
        let tau_total = t + phase;
        let frame = (tau_total / period).floor() as u64;
        let tau = (tau_total - frame as f64 * period).clamp(0.0, period);
        if frame != current_frame {
            current_frame = frame;
            frames += 1;
            bin_hint = 0;
        }
        let (az, bin) = tl.azimuth_at_from(tau, bin_hint);
        bin_hint = bin;
        let (sa, ca) = az.to_radians().sin_cos();
        let half = argus::in_half_plane(az, ego_yaw);
        let dens = half && argus::signed_deg(az) < gaze - 30.0;
        for (st, spec) in cells.iter_mut().zip(setup.cells) {
            st.in_roi = spec.regions.roi.contains(az);
            st.in_rof = spec.rof_keep < 1.0 && spec.regions.rof.contains(az);
            st.roi_pulses += u64::from(st.in_roi) * channels as u64;
        }
        let pulse_mask = world.static_mask_at(az);
        let car_arc = [cars.arcs[0].contains(az), cars.arcs[1].contains(az)];
        for ch in 0..channels {
            // A ray that can meet nothing (no ground within its trace, no
            // box in reach) returns nothing whatever its draws: skip it.
            if !world.brute_force
                && world.ground_t[ch].is_none()
                && world.static_may[ch] & pulse_mask == 0
                && !(car_arc[0] && cars.may[0][ch])
                && !(car_arc[1] && cars.may[1][ch])
            {
                continue;
            }
            let idx = k.wrapping_mul(channels as u64).wrapping_add(ch as u64);
            let key = idx.wrapping_mul(0xD1B5_4A32_D192_ED03);
            if p.dropoff_general_rate > 0.0 && unit(seed_general ^ key) < p.dropoff_general_rate {
                continue;
            }
            let d = world.sensor.direction(ch, ca, sa);
            let Some(hit) = world.cast(ch, &d, az, pulse_mask, &cars) else {
                continue;
            };
            let r = hit.range_m;
            let raw = {
                let c = &mut raw_cache[ch];
                if c.0 != r.to_bits() {
                    *c = (
                        r.to_bits(),
                        (-p.atmosphere_attenuation_rate_per_m * r).exp(),
                    );
                }
                c.1
            };
            if raw <= p.dropoff_intensity_limit && unit(seed_intensity ^ key) >= alpha * raw + beta
            {
                continue;
            }
            let (refl, car) = match hit.surface {
                Surface::Ground => (p.ground_reflectivity, None),
                Surface::Building => (sc.building_reflectivity, None),
                Surface::Vehicle(j) => (sc.vehicle_reflectivity, Some(j)),
            };
            // The point in the sensor frame and its road-mask cell (ARGUS).
            let (ps, cell) = if any_argus && half {
                let ps = world.sensor.to_sensor(&hit.point);
                (ps, cell_grid.cell_of(ps.x, ps.y))
            } else {
                (hit.point, None)
            };
            let mut u_noise = None;
            for (st, spec) in cells.iter_mut().zip(setup.cells) {
                let power = st.power_ratio[bin];
                let returned = match *spec.model {
                    ReturnModel::Argus {
                        fog_factor,
                        threshold,
                    } => r <= ARGUS_RANGE_M && power * raw * fog_factor >= threshold,
                    ReturnModel::Physical { .. } => {
                        let pd_key = [r.to_bits(), power.to_bits(), hit.cos_incidence.to_bits()];
                        let cache = &mut st.pd_cache[ch];
                        if cache.0 != pd_key || hit.surface != Surface::Ground {
                            *cache = (
                                pd_key,
                                spec.model
                                    .detection_probability(power, refl, hit.cos_incidence, r),
                            );
                        }
                        let p_d = cache.1;
                        p_d >= 1.0
                            || (p_d > 0.0
                                && *u_noise.get_or_insert_with(|| unit(seed_noise ^ key)) < p_d)
                    }
                };
                if !returned {
                    continue;
                }
                if st.in_rof {
                    st.keep_acc += spec.rof_keep;
                    if st.keep_acc < 1.0 {
                        continue;
                    }
                    st.keep_acc -= 1.0;
                }
                st.roi_points += u64::from(st.in_roi);
                st.argus_roi_points += u64::from(dens);
                if let Some(j) = car {
                    st.tick_hit[j] = true;
                }
                if half {
                    if let Some(det) = st.argus.as_mut() {
                        det.point_in_cell(ps.x, ps.y, ps.z, cell);
                    }
                }
            }
        }
    }
    if current_tick != u64::MAX {
        end_tick(&mut cells, current_tick, t_state);
    }

    let duration_s = n_pulses as f64 / pulse_rate;
    cells
        .iter()
        .zip(setup.cells)
        .map(|(st, spec)| {
            let tta = |j: usize, t: Option<f64>| t.map(|t| t_arrive[j] - t).filter(|x| *x >= 0.0);
            let tta_s = [tta(0, st.detected_at[0]), tta(1, st.detected_at[1])];
            let driver = [tta(0, st.driver_at[0]), tta(1, st.driver_at[1])];
            let hybrid = |j: usize| match (tta_s[j], driver[j]) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            };
            TrialOutcome {
                tta_s,
                hybrid_tta_s: [hybrid(0), hybrid(1)],
                roi_points: st.roi_points,
                roi_pulses: st.roi_pulses,
                roi_width_deg: spec.regions.roi.measure_deg(),
                duration_s,
                frames,
                argus_roi_points: st.argus_roi_points,
                channels_simulated: channels as u32,
            }
        })
        .collect()
}
