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
mod chans;
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
use chans::Chans;
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

/// The per-ray key of channel `ch` at pulse `k` (drop-off and noise draws).
fn ray_key(k: u64, channels: usize, ch: usize) -> u64 {
    k.wrapping_mul(channels as u64)
        .wrapping_add(ch as u64)
        .wrapping_mul(0xD1B5_4A32_D192_ED03)
}

/// The world of one tick: cars posed, with their culling data.
struct Cars {
    boxes: [PosedBox; 2],
    arcs: [Arc; 2],
    /// The channels that can reach car `j` this tick.
    chans: [Chans; 2],
}

/// A channel's ground return: the same for every azimuth (a level mount:
/// the direction's vertical component is the channel's `sin` whatever the
/// azimuth, so the plane's hit distance is too).
#[derive(Debug, Clone, Copy)]
struct GroundRing {
    range_m: f64,
    cos_incidence: f64,
    /// CARLA's raw intensity `e^(−rate·r)`.
    raw: f64,
    /// `Some(alpha·raw + beta)` if the intensity drop-off applies
    /// (`raw ≤ limit`): the ray is dropped if its draw is at or above it.
    keep_below: Option<f64>,
}

/// The static world and the sensor, with per-channel culling data.
struct World<'a> {
    sensor: Sensor,
    origin: Point3<f64>,
    statics: &'a [StaticBox],
    static_arcs: Vec<Arc>,
    /// `static_may[ch]`: bit b set if channel `ch` can reach box b.
    static_may: Vec<u64>,
    /// The channels that can reach static box b.
    static_chans: Vec<Chans>,
    /// Horizontal reach of each channel: trace end or ground, m.
    reach_m: Vec<f64>,
    tan_el: Vec<f64>,
    /// Per channel: its ground return if the ground lies within the trace.
    ground: Vec<Option<GroundRing>>,
    /// The channels with a ground return.
    ground_chans: Chans,
    /// The ground channels subject to the intensity drop-off.
    ground_dim: Chans,
    /// The mount is level ([`Sensor::is_level`]): the fast path's ground
    /// rings hold (else every group takes the reference path).
    level: bool,
    /// ARGUS's detector may take the ground points' cells lazily: they are
    /// road points, and over the ground channels in ascending order the
    /// distance and the `cos` of the elevation never grow, so `|y|` of the
    /// ground points of one azimuth never grows either (products of
    /// non-negative factors round monotonically): the lowest and highest
    /// channel of a set bound its `y`.
    lazy_road: bool,
}

impl<'a> World<'a> {
    fn new(sc: &Scenario, statics: &'a [StaticBox]) -> Self {
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
        let may = |c: usize, b: &StaticBox| {
            let dist = footprint_distances(b.footprint());
            channel_may_reach(h, tan_el[c], b.heights(), dist, reach_m[c], CULL_PAD_M)
        };
        let static_may = (0..n)
            .map(|c| {
                if statics.len() > 64 {
                    return u64::MAX;
                }
                statics
                    .iter()
                    .enumerate()
                    .fold(0u64, |m, (i, b)| m | (u64::from(may(c, b)) << i))
            })
            .collect();
        let static_chans = statics
            .iter()
            .map(|b| {
                let mut s = Chans::EMPTY;
                for c in (0..n).filter(|&c| may(c, b)) {
                    s.insert(c);
                }
                s
            })
            .collect();
        let alpha = p.dropoff_zero_intensity / p.dropoff_intensity_limit;
        let beta = 1.0 - p.dropoff_zero_intensity;
        let ground: Vec<Option<GroundRing>> = (0..n)
            .map(|c| {
                let d = sensor.direction(c, 1.0, 0.0);
                let hit = geometry::ground_hit(&origin, &d).filter(|g| g.range_m <= p.range_m)?;
                let raw = (-p.atmosphere_attenuation_rate_per_m * hit.range_m).exp();
                Some(GroundRing {
                    range_m: hit.range_m,
                    cos_incidence: hit.cos_incidence,
                    raw,
                    keep_below: (raw <= p.dropoff_intensity_limit).then_some(alpha * raw + beta),
                })
            })
            .collect();
        let level = sensor.is_level();
        let ground_z = sensor.to_sensor(&Point3::origin()).z;
        let rings: Vec<(usize, GroundRing)> = ground
            .iter()
            .enumerate()
            .filter_map(|(c, g)| g.map(|g| (c, g)))
            .collect();
        let lazy_road = level
            && ground_z < p.argus_road_z_m
            && rings.windows(2).all(|w| {
                let ((a, ga), (b, gb)) = (w[0], w[1]);
                gb.range_m <= ga.range_m && sensor.cos_el[b] <= sensor.cos_el[a]
            });
        let mut ground_chans = Chans::EMPTY;
        let mut ground_dim = Chans::EMPTY;
        for (c, g) in ground.iter().enumerate() {
            if let Some(g) = g {
                ground_chans.insert(c);
                if g.keep_below.is_some() {
                    ground_dim.insert(c);
                }
            }
        }
        Self {
            sensor,
            origin,
            ground,
            ground_chans,
            ground_dim,
            level,
            lazy_road,
            statics,
            static_arcs,
            static_may,
            static_chans,
            reach_m,
            tan_el,
        }
    }

    fn cars(&self, boxes: [PosedBox; 2]) -> Cars {
        let h = self.origin.z;
        let mut arcs = [Arc {
            start_deg: 0.0,
            width_deg: 360.0,
        }; 2];
        let mut chans = [Chans::EMPTY; 2];
        for j in 0..2 {
            let (f, z) = boxes[j].bounds();
            arcs[j] = cull_arc(&[Aabb::new(f[0], f[1], f[2], f[3])]);
            let dist = footprint_distances(f);
            for (c, &tan_el) in self.tan_el.iter().enumerate() {
                if channel_may_reach(h, tan_el, z, dist, self.reach_m[c], CULL_PAD_M) {
                    chans[j].insert(c);
                }
            }
        }
        Cars { boxes, arcs, chans }
    }

    /// Bits of the statics whose angular extent contains `az`.
    fn static_mask_at(&self, az: f64) -> u64 {
        if self.statics.len() > 64 {
            return u64::MAX;
        }
        self.static_arcs
            .iter()
            .enumerate()
            .fold(0u64, |m, (i, a)| m | (u64::from(a.contains(az)) << i))
    }

    /// Nearest hit of channel `ch`'s ray (direction `d`) among the ground,
    /// the statics of `pulse_mask` this channel can reach and the cars whose
    /// extent contains the azimuth (`car_arc`) and that it can reach.
    fn cast(
        &self,
        ch: usize,
        d: &Vector3<f64>,
        pulse_mask: u64,
        car_arc: [bool; 2],
        cars: &Cars,
    ) -> Option<Hit> {
        let o = &self.origin;
        let mut best = geometry::ground_hit(o, d);
        let mask = self.static_may[ch] & pulse_mask;
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
        for (j, &in_arc) in car_arc.iter().enumerate() {
            if !(in_arc && cars.chans[j].contains(ch)) {
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

    /// Nearest hit of the ray from the sensor along `d` among everything
    /// (ground, every static, both cars), at any distance.
    fn nearest(&self, d: &Vector3<f64>, cars: &Cars) -> Option<Hit> {
        let o = &self.origin;
        let mut best = geometry::ground_hit(o, d);
        for b in self.statics {
            if let Some(h) = b.ray_hit(o, d) {
                if best.is_none_or(|x| h.range_m < x.range_m) {
                    best = Some(h);
                }
            }
        }
        for j in 0..2 {
            if let Some(h) = cars.boxes[j].ray_hit(o, d, Surface::Vehicle(j)) {
                if best.is_none_or(|x| h.range_m < x.range_m) {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The sensor-frame point where channel `ch` (a ground ring) meets the
    /// ground at azimuth `(cos, sin)`, and its ARGUS cell: as the cast finds it.
    fn ground_point(
        &self,
        ch: usize,
        cos_az: f64,
        sin_az: f64,
        grid: &ArgusDetector,
    ) -> (Point3<f64>, Option<usize>) {
        let d = self.sensor.direction(ch, cos_az, sin_az);
        let point = geometry::ground_hit(&self.origin, &d)
            .expect("a ground ring meets the ground at every azimuth")
            .point;
        let ps = self.sensor.to_sensor(&point);
        (ps, grid.cell_of(ps.x, ps.y))
    }

    /// Nearest hit of the ray from the sensor towards `target` (all objects).
    fn line_of_sight(&self, target: &Point3<f64>, cars: &Cars) -> Option<Hit> {
        self.nearest(&(target - self.origin).normalize(), cars)
    }
}

/// Whether the ARGUS model returns a hit (the cast is within the trace).
fn argus_returns(power: f64, raw: f64, r: f64, fog_factor: f64, threshold: f64) -> bool {
    r <= ARGUS_RANGE_M && power * raw * fog_factor >= threshold
}

/// Whether a detection probability yields a point with noise draw `u`
/// (drawn only when `0 < p_d < 1`).
fn physical_returns(p_d: f64, u: impl FnOnce() -> f64) -> bool {
    p_d >= 1.0 || (p_d > 0.0 && u() < p_d)
}

/// A cell's verdict on the ground rings at one power level.
#[derive(Debug, Clone)]
struct GroundLevel {
    /// Channels whose ground hit always yields a point.
    always: Chans,
    /// Channels whose ground hit yields a point when the noise draw is
    /// below `p_d[ch]` (physical, `0 < P_D < 1`).
    maybe: Chans,
    p_d: Vec<f64>,
}

/// Width of the range buckets of [`Saturation`], m (a power of two: the
/// bucket index `⌊r / w⌋` is exact).
const RANGE_BUCKET_M: f64 = 0.25;

/// The physical model's saturation on box hits: `P_D = ½·erfc((T − A)/√2)`
/// is exactly 1 once `(T − A)/√2 ≤ −6` (libm's `erfc` returns `2 − ε`
/// with `ε < erfc(6) ≈ 2e-17`, below half an ulp of 2, or `2 − 2^−1022`;
/// tested), i.e. `A ≥ T + 6√2`. The amplitude
/// `A = T·P·(ρ/ρ0)·cos·(r0/R)²·e^(−2αR + 2α0·r0)` falls with `R` (α ≥ 0),
/// so each range bucket has a lower bound of `A / (P·cos)`; a hit whose
/// bound clears the limit (padded far above rounding) returns without
/// evaluating `erfc`.
#[derive(Debug, Clone)]
struct Saturation {
    /// Per surface (0 building, 1 vehicle), per bucket: the lower bound.
    rows: [Vec<f64>; 2],
    /// `(T + 6√2)·(1 + 1e-9)`.
    limit: f64,
}

impl Saturation {
    fn new(model: &ReturnModel, reflectivity: [f64; 2], range_m: f64) -> Option<Self> {
        let ReturnModel::Physical {
            params,
            extinction_per_m,
        } = *model
        else {
            return None;
        };
        let ok = |x: f64| x.is_finite() && x > 0.0;
        if !(extinction_per_m >= 0.0
            && ok(params.rated_range_m)
            && ok(params.reference_reflectivity)
            && params.clear_extinction_per_m.is_finite()
            && extinction_per_m.is_finite()
            && range_m.is_finite())
        {
            return None;
        }
        let buckets = (range_m / RANGE_BUCKET_M).ceil() as usize + 1;
        let r0 = params.rated_range_m;
        let rows = reflectivity.map(|rho| {
            (0..buckets)
                .map(|i| {
                    let r_hi = (i + 1) as f64 * RANGE_BUCKET_M;
                    let bound = params.threshold_sigma
                        * (rho / params.reference_reflectivity)
                        * (r0 / r_hi).powi(2)
                        * (-2.0 * extinction_per_m * r_hi
                            + 2.0 * params.clear_extinction_per_m * r0)
                            .exp();
                    bound * (1.0 - 1e-12)
                })
                .collect()
        });
        Some(Self {
            rows,
            limit: (params.threshold_sigma + 6.0 * std::f64::consts::SQRT_2) * (1.0 + 1e-9),
        })
    }

    /// Whether a hit on `surface` (0 building, 1 vehicle) in range bucket
    /// `bucket` at power ratio `power` and incidence `cos` surely has `P_D = 1`.
    fn saturated(&self, surface: usize, bucket: usize, power: f64, cos: f64) -> bool {
        self.rows[surface]
            .get(bucket)
            .is_some_and(|&l| power * cos * l >= self.limit)
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
    /// Fast path: the ground verdicts per distinct power ratio and the
    /// level of each bin.
    levels: Vec<GroundLevel>,
    level_of_bin: Vec<usize>,
    /// Fast path, physical model: saturation of box hits.
    saturation: Option<Saturation>,
    /// Fast path, ARGUS's detector with lazy road cells: this tick's ground
    /// road points as (pulse slot of the tick, channels).
    deferred: Vec<(usize, Chans)>,
}

impl CellState {
    fn new(spec: &CellSpec<'_>, setup: &GroupSetup<'_>) -> Self {
        let p = &setup.scenario.carla;
        Self {
            detected_at: [None, None],
            driver_at: [None, None],
            hit_ticks: [Vec::new(), Vec::new()],
            tick_hit: [false, false],
            roi_points: 0,
            roi_pulses: 0,
            argus_roi_points: 0,
            keep_acc: 0.0,
            argus: (setup.detector == Detector::Argus).then(|| ArgusDetector::new(p)),
            power_ratio: spec
                .profile
                .bins
                .iter()
                .map(|b| b.power_w / spec.profile.average_power_w)
                .collect(),
            in_roi: false,
            in_rof: false,
            levels: Vec::new(),
            level_of_bin: Vec::new(),
            saturation: None,
            deferred: Vec::new(),
        }
    }

    /// Fills the fast path's ground verdicts (one per distinct power ratio)
    /// and box-hit saturation.
    fn plan_fast(&mut self, spec: &CellSpec<'_>, world: &World<'_>, sc: &Scenario) {
        let ground_reflectivity = sc.carla.ground_reflectivity;
        self.saturation = Saturation::new(
            spec.model,
            [sc.building_reflectivity, sc.vehicle_reflectivity],
            world.sensor.range_m,
        );
        let mut distinct: Vec<u64> = self.power_ratio.iter().map(|x| x.to_bits()).collect();
        distinct.sort_unstable();
        distinct.dedup();
        self.level_of_bin = self
            .power_ratio
            .iter()
            .map(|x| distinct.binary_search(&x.to_bits()).unwrap_or(0))
            .collect();
        self.levels = distinct
            .iter()
            .map(|&bits| {
                let power = f64::from_bits(bits);
                let mut level = GroundLevel {
                    always: Chans::EMPTY,
                    maybe: Chans::EMPTY,
                    p_d: vec![0.0; world.ground.len()],
                };
                for (ch, g) in world.ground.iter().enumerate() {
                    let Some(g) = g else { continue };
                    match *spec.model {
                        ReturnModel::Argus {
                            fog_factor,
                            threshold,
                        } => {
                            if argus_returns(power, g.raw, g.range_m, fog_factor, threshold) {
                                level.always.insert(ch);
                            }
                        }
                        ReturnModel::Physical { .. } => {
                            let p_d = spec.model.detection_probability(
                                power,
                                ground_reflectivity,
                                g.cos_incidence,
                                g.range_m,
                            );
                            level.p_d[ch] = p_d;
                            if p_d >= 1.0 {
                                level.always.insert(ch);
                            } else if p_d > 0.0 {
                                level.maybe.insert(ch);
                            }
                        }
                    }
                }
                level
            })
            .collect();
    }

    /// Whether the ARGUS detector's points can still change an outcome:
    /// the right car is not yet detected and the tick ending at `t_state`
    /// is not past its arrival.
    fn argus_live(&self, t_state: f64, t_arrive: f64) -> bool {
        self.argus.is_some() && self.detected_at[1].is_none() && t_state <= t_arrive
    }
}

/// One pulse of the group: where the head points.
#[derive(Debug, Clone, Copy)]
struct Pulse {
    k: u64,
    az: f64,
    bin: usize,
    cos_az: f64,
    sin_az: f64,
    /// In ARGUS's kept half-plane.
    half: bool,
    /// In ARGUS's density region.
    dens: bool,
}

/// Reusable per-pulse buffers of the fast path, one slot per channel (the
/// box-hit slots are this pulse's for the channels of `boxes`).
struct Scratch {
    boxes: Chans,
    /// Box hits: range, raw intensity, incidence, reflectivity, surface
    /// (0 building, 1 vehicle), range bucket, point.
    range: Vec<f64>,
    raw: Vec<f64>,
    cos: Vec<f64>,
    refl: Vec<f64>,
    surface: Vec<usize>,
    bucket: Vec<usize>,
    hit_point: Vec<Point3<f64>>,
    noise: Vec<f64>,
    noise_drawn: Chans,
    points: Vec<(Point3<f64>, Option<usize>)>,
    points_done: Chans,
    /// This tick's pulses in ARGUS's half-plane: `(cos, sin)` of the azimuth.
    tick_pulses: Vec<(f64, f64)>,
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
    let world = World::new(sc, setup.statics);
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
    let seeds = Seeds {
        general: mix64(draw.noise_seed ^ 0x6361_726c_6167_656e),
        intensity: mix64(draw.noise_seed ^ 0x6361_726c_6169_6e74),
        noise: mix64(draw.noise_seed ^ 0x6361_726c_616e_6f69),
    };

    let mut cells: Vec<CellState> = setup
        .cells
        .iter()
        .map(|c| CellState::new(c, setup))
        .collect();
    let fast = !setup.brute_force && world.level;
    if fast {
        for (st, spec) in cells.iter_mut().zip(setup.cells) {
            st.plan_fast(spec, &world, sc);
        }
    }
    let cell_grid = ArgusDetector::new(p);
    let mut scratch = Scratch {
        boxes: Chans::EMPTY,
        range: vec![0.0; channels],
        raw: vec![0.0; channels],
        cos: vec![0.0; channels],
        refl: vec![0.0; channels],
        surface: vec![0; channels],
        bucket: vec![0; channels],
        hit_point: vec![Point3::origin(); channels],
        noise: vec![0.0; channels],
        noise_drawn: Chans::EMPTY,
        points: vec![(Point3::origin(), None); channels],
        points_done: Chans::EMPTY,
        tick_pulses: Vec::new(),
    };

    // Ends tick `tick` (state time `t`) for every cell.
    let end_tick = |cells: &mut [CellState],
                    tick_pulses: &mut Vec<(f64, f64)>,
                    tick: u64,
                    t: f64| {
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
                let deferred = &st.deferred;
                let found = det.end_tick_with(|insert| {
                    for &(slot, chans) in deferred {
                        let (cos_az, sin_az) = tick_pulses[slot];
                        for ch in chans.iter() {
                            if let (_, Some(cell)) =
                                world.ground_point(ch, cos_az, sin_az, &cell_grid)
                            {
                                insert(cell);
                            }
                        }
                    }
                });
                st.deferred.clear();
                if found && st.detected_at[1].is_none() && t <= t_arrive[1] {
                    st.detected_at[1] = Some(t);
                }
            }
        }
        tick_pulses.clear();
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
                end_tick(&mut cells, &mut scratch.tick_pulses, current_tick, t_state);
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
        let (sin_az, cos_az) = az.to_radians().sin_cos();
        let half = argus::in_half_plane(az, ego_yaw);
        let pulse = Pulse {
            k,
            az,
            bin,
            cos_az,
            sin_az,
            half,
            dens: half && argus::signed_deg(az) < gaze - 30.0,
        };
        for (st, spec) in cells.iter_mut().zip(setup.cells) {
            st.in_roi = spec.regions.roi.contains(az);
            st.in_rof = spec.rof_keep < 1.0 && spec.regions.rof.contains(az);
            st.roi_pulses += u64::from(st.in_roi) * channels as u64;
        }
        let ctx = PulseCtx {
            scenario: sc,
            world: &world,
            cars: &cars,
            specs: setup.cells,
            seeds: &seeds,
            grid: &cell_grid,
            t_state,
            t_arrive_right: t_arrive[1],
        };
        if fast {
            ctx.fast(&pulse, &mut cells, &mut scratch);
        } else {
            ctx.reference(&pulse, &mut cells);
        }
    }
    if current_tick != u64::MAX {
        end_tick(&mut cells, &mut scratch.tick_pulses, current_tick, t_state);
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

/// The trial's draw seeds.
struct Seeds {
    /// CARLA's general drop-off.
    general: u64,
    /// CARLA's intensity drop-off.
    intensity: u64,
    /// The physical model's detection noise.
    noise: u64,
}

/// What a pulse's rays need besides the pulse and the cells.
struct PulseCtx<'w, 'a> {
    scenario: &'w Scenario,
    world: &'w World<'a>,
    cars: &'w Cars,
    specs: &'w [CellSpec<'w>],
    seeds: &'w Seeds,
    grid: &'w ArgusDetector,
    t_state: f64,
    t_arrive_right: f64,
}

impl PulseCtx<'_, '_> {
    /// The reference: every channel cast against everything, every cell
    /// deciding every hit on its own, one ray at a time.
    fn reference(&self, pulse: &Pulse, cells: &mut [CellState]) {
        let world = self.world;
        let p = &self.scenario.carla;
        let channels = world.sensor.elevations_deg.len();
        let alpha = p.dropoff_zero_intensity / p.dropoff_intensity_limit;
        let beta = 1.0 - p.dropoff_zero_intensity;
        let any_argus = cells.iter().any(|c| c.argus.is_some());
        for ch in 0..channels {
            let key = ray_key(pulse.k, channels, ch);
            if p.dropoff_general_rate > 0.0
                && unit(self.seeds.general ^ key) < p.dropoff_general_rate
            {
                continue;
            }
            let d = world.sensor.direction(ch, pulse.cos_az, pulse.sin_az);
            let Some(hit) = world
                .nearest(&d, self.cars)
                .filter(|h| h.range_m <= world.sensor.range_m)
            else {
                continue;
            };
            let r = hit.range_m;
            let raw = (-p.atmosphere_attenuation_rate_per_m * r).exp();
            if raw <= p.dropoff_intensity_limit
                && unit(self.seeds.intensity ^ key) >= alpha * raw + beta
            {
                continue;
            }
            let (refl, car) = match hit.surface {
                Surface::Ground => (p.ground_reflectivity, None),
                Surface::Building => (self.scenario.building_reflectivity, None),
                Surface::Vehicle(j) => (self.scenario.vehicle_reflectivity, Some(j)),
            };
            let (ps, cell) = if any_argus && pulse.half {
                let ps = world.sensor.to_sensor(&hit.point);
                (ps, self.grid.cell_of(ps.x, ps.y))
            } else {
                (hit.point, None)
            };
            for (st, spec) in cells.iter_mut().zip(self.specs) {
                let power = st.power_ratio[pulse.bin];
                let returned = match *spec.model {
                    ReturnModel::Argus {
                        fog_factor,
                        threshold,
                    } => argus_returns(power, raw, r, fog_factor, threshold),
                    ReturnModel::Physical { .. } => physical_returns(
                        spec.model
                            .detection_probability(power, refl, hit.cos_incidence, r),
                        || unit(self.seeds.noise ^ key),
                    ),
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
                st.argus_roi_points += u64::from(pulse.dens);
                if let Some(j) = car {
                    st.tick_hit[j] = true;
                }
                if pulse.half {
                    if let Some(det) = st.argus.as_mut() {
                        det.point_in_cell(ps.x, ps.y, ps.z, cell);
                    }
                }
            }
        }
    }

    /// The fast path, bit-identical to [`Self::reference`]: a pulse's rays
    /// as channel sets. Only rays that may meet a box (statics and cars
    /// whose extent contains the azimuth, channels that can reach them) are
    /// cast; every other ray that can return meets the ground at its
    /// channel's ring ([`GroundRing`]), whose verdict each cell has per
    /// power level ([`GroundLevel`]). Each cell then takes its returned
    /// channels in ascending order (the reference's order for its own
    /// state). ARGUS's detector is fed only while its verdict can still
    /// change, and with lazy road cells ([`World::lazy_road`]) it takes the
    /// ground points' extent from their lowest and highest channel and their
    /// cells only if the tick updates the mask.
    fn fast(&self, pulse: &Pulse, cells: &mut [CellState], s: &mut Scratch) {
        let world = self.world;
        let sc = self.scenario;
        let p = &sc.carla;
        let channels = world.ground.len();
        let k = pulse.k;
        let alpha = p.dropoff_zero_intensity / p.dropoff_intensity_limit;
        let beta = 1.0 - p.dropoff_zero_intensity;
        let pulse_mask = world.static_mask_at(pulse.az);
        let car_arc = [
            self.cars.arcs[0].contains(pulse.az),
            self.cars.arcs[1].contains(pulse.az),
        ];
        let mut cand = Chans::EMPTY;
        for (i, c) in world.static_chans.iter().enumerate() {
            if i >= 64 || pulse_mask >> i & 1 == 1 {
                cand |= *c;
            }
        }
        for (&in_arc, &chans) in car_arc.iter().zip(&self.cars.chans) {
            if in_arc {
                cand |= chans;
            }
        }
        // A ray that can meet nothing returns nothing whatever its draws.
        let mut alive = Chans::EMPTY;
        for ch in (world.ground_chans | cand).iter() {
            let dropped = p.dropoff_general_rate > 0.0
                && unit(self.seeds.general ^ ray_key(k, channels, ch)) < p.dropoff_general_rate;
            alive.put(ch, !dropped);
        }
        let mut ground = alive & !cand;
        let mut boxes = Chans::EMPTY;
        let mut car_hits = [Chans::EMPTY; 2];
        for ch in (alive & cand).iter() {
            let d = world.sensor.direction(ch, pulse.cos_az, pulse.sin_az);
            let Some(hit) = world.cast(ch, &d, pulse_mask, car_arc, self.cars) else {
                continue;
            };
            if hit.surface == Surface::Ground {
                debug_assert_eq!(
                    world.ground[ch].map(|g| g.range_m.to_bits()),
                    Some(hit.range_m.to_bits())
                );
                ground.insert(ch);
                continue;
            }
            let r = hit.range_m;
            let raw = (-p.atmosphere_attenuation_rate_per_m * r).exp();
            if raw <= p.dropoff_intensity_limit
                && unit(self.seeds.intensity ^ ray_key(k, channels, ch)) >= alpha * raw + beta
            {
                continue;
            }
            boxes.insert(ch);
            let (surface, refl) = match hit.surface {
                Surface::Vehicle(j) => {
                    car_hits[j].insert(ch);
                    (1, sc.vehicle_reflectivity)
                }
                _ => (0, sc.building_reflectivity),
            };
            s.range[ch] = r;
            s.raw[ch] = raw;
            s.cos[ch] = hit.cos_incidence;
            s.refl[ch] = refl;
            s.surface[ch] = surface;
            s.bucket[ch] = (r / RANGE_BUCKET_M) as usize;
            s.hit_point[ch] = hit.point;
        }
        for ch in (ground & world.ground_dim).iter() {
            let keep_below = world.ground[ch].and_then(|g| g.keep_below);
            if keep_below
                .is_some_and(|x| unit(self.seeds.intensity ^ ray_key(k, channels, ch)) >= x)
            {
                ground.remove(ch);
            }
        }
        s.boxes = boxes;
        s.noise_drawn = Chans::EMPTY;
        s.points_done = Chans::EMPTY;
        let lazy_slot = (pulse.half && world.lazy_road).then(|| {
            s.tick_pulses.push((pulse.cos_az, pulse.sin_az));
            s.tick_pulses.len() - 1
        });
        for (st, spec) in cells.iter_mut().zip(self.specs) {
            let level = &st.levels[st.level_of_bin[pulse.bin]];
            let mut ret = ground & level.always;
            for ch in (ground & level.maybe).iter() {
                if s.noise(ch, self.seeds.noise, k, channels) < level.p_d[ch] {
                    ret.insert(ch);
                }
            }
            let power = st.power_ratio[pulse.bin];
            for ch in boxes.iter() {
                let returned = match *spec.model {
                    ReturnModel::Argus {
                        fog_factor,
                        threshold,
                    } => argus_returns(power, s.raw[ch], s.range[ch], fog_factor, threshold),
                    ReturnModel::Physical { .. } => {
                        st.saturation.as_ref().is_some_and(|x| {
                            x.saturated(s.surface[ch], s.bucket[ch], power, s.cos[ch])
                        }) || physical_returns(
                            spec.model.detection_probability(
                                power,
                                s.refl[ch],
                                s.cos[ch],
                                s.range[ch],
                            ),
                            || s.noise(ch, self.seeds.noise, k, channels),
                        )
                    }
                };
                ret.put(ch, returned);
            }
            if st.in_rof {
                let mut kept = Chans::EMPTY;
                for ch in ret.iter() {
                    st.keep_acc += spec.rof_keep;
                    if st.keep_acc < 1.0 {
                        continue;
                    }
                    st.keep_acc -= 1.0;
                    kept.insert(ch);
                }
                ret = kept;
            }
            let n = ret.len();
            st.roi_points += u64::from(st.in_roi) * n;
            st.argus_roi_points += u64::from(pulse.dens) * n;
            for (hit, &chans) in st.tick_hit.iter_mut().zip(&car_hits) {
                if !(ret & chans).is_empty() {
                    *hit = true;
                }
            }
            if !(pulse.half && st.argus_live(self.t_state, self.t_arrive_right)) {
                continue;
            }
            let Some(det) = st.argus.as_mut() else {
                continue;
            };
            let one_by_one = match lazy_slot {
                Some(slot) => {
                    let road = ret & !boxes;
                    if let (Some(lo), Some(hi)) = (road.first(), road.last()) {
                        det.road_y(s.point(lo, world, pulse, self.grid).0.y);
                        det.road_y(s.point(hi, world, pulse, self.grid).0.y);
                        st.deferred.push((slot, road));
                    }
                    ret & boxes
                }
                None => ret,
            };
            for ch in one_by_one.iter() {
                let (ps, cell) = s.point(ch, world, pulse, self.grid);
                det.point_in_cell(ps.x, ps.y, ps.z, cell);
            }
        }
    }
}

impl Scratch {
    /// The physical model's noise draw of channel `ch` at pulse `k` (drawn once per pulse).
    fn noise(&mut self, ch: usize, seed: u64, k: u64, channels: usize) -> f64 {
        if !self.noise_drawn.contains(ch) {
            self.noise[ch] = unit(seed ^ ray_key(k, channels, ch));
            self.noise_drawn.insert(ch);
        }
        self.noise[ch]
    }

    /// The sensor-frame point of channel `ch`'s hit and its ARGUS cell
    /// (found once per pulse): the box hit, else the ground ring's point.
    fn point(
        &mut self,
        ch: usize,
        world: &World<'_>,
        pulse: &Pulse,
        grid: &ArgusDetector,
    ) -> (Point3<f64>, Option<usize>) {
        if !self.points_done.contains(ch) {
            self.points[ch] = if self.boxes.contains(ch) {
                let ps = world.sensor.to_sensor(&self.hit_point[ch]);
                (ps, grid.cell_of(ps.x, ps.y))
            } else {
                world.ground_point(ch, pulse.cos_az, pulse.sin_az, grid)
            };
            self.points_done.insert(ch);
        }
        self.points[ch]
    }
}
