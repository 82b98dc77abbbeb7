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
//! Acceleration, bit-identical to casting every ray against everything and
//! deciding every hit in every cell (`brute_force`, the plain reference
//! loop `PulseCtx::reference`; tested on both models, all variants, fog
//! levels, both detectors and scenes that turn the shortcuts off): a
//! pulse's rays are handled as channel sets (`Chans`, one word for
//! up to 64 channels). A box is tested only if the channel's ray can reach
//! its height band inside its horizontal distance band before the trace ends
//! or meets the ground ([`geometry::channel_may_reach`]) and the azimuth lies
//! in its angular extent (cars: per tick); a ray that can meet no box meets
//! the ground at its channel's ring (a level mount: the same distance at
//! every azimuth), whose verdict each cell has per distinct power ratio.
//! CARLA's general drop-off is drawn once per trial and pulse rate
//! ([`TrialRays`]); box hits take the raw intensity from a per-range-bucket
//! floor unless the drop-off or the ARGUS model near its threshold needs it
//! exactly, and the physical model skips `erfc` where a per-bucket amplitude
//! bound proves `P_D = 1` (`Saturation`). ARGUS's detector is fed only
//! while its verdict can still change, and takes the ground points' road
//! cells lazily (`World::lazy_road`); pulses whose points nothing counts
//! are skipped.

pub mod argus;
mod chans;
pub mod geometry;
pub mod params;
pub mod sampling;

use nalgebra::{Point3, Vector3};

use crate::model::acuity::Regions;
use crate::model::angle::Arc;
use crate::profile::kinematics::Timeline;
use crate::profile::Profile;

use super::returns::{ReturnModel, Saturation, ARGUS_RANGE_M, RANGE_BUCKET_M};
use super::scene::{Aabb, Scenario};
use super::trial::{cull_arc, mix64, KOfN, TrialDraw, TrialOutcome};
use super::{Arrival, Detector};
use argus::ArgusDetector;
use chans::Chans;
pub use sampling::Sampling;

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
    /// When the LiDAR fires and where it points.
    pub sampling: Sampling,
}

/// Whether two profiles put every pulse at the same azimuth (same pulse
/// rate and the same bins' extents and spins, bit for bit).
#[must_use]
pub fn same_timeline(a: &Profile, b: &Profile) -> bool {
    a.pulse_rate_hz.to_bits() == b.pulse_rate_hz.to_bits()
        && a.frame_rate_hz.to_bits() == b.frame_rate_hz.to_bits()
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
struct Cars<const W: usize> {
    boxes: [PosedBox; 2],
    arcs: [Arc; 2],
    /// The channels that can reach car `j` this tick.
    chans: [Chans<W>; 2],
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
struct World<'a, const W: usize> {
    sensor: Sensor,
    origin: Point3<f64>,
    statics: &'a [StaticBox],
    static_arcs: Vec<Arc>,
    /// The channels that can reach static box b.
    static_chans: Vec<Chans<W>>,
    /// Per static box, per channel: its z slab (level sensor: the same at
    /// every azimuth); `None`: the channel never lies in its height band.
    static_z: Vec<Vec<Option<(f64, f64)>>>,
    /// Per channel: the distance along the ray to the ground plane, at any
    /// distance (level sensor: the same at every azimuth).
    ground_t: Vec<Option<f64>>,
    /// Horizontal reach of each channel: trace end or ground, m.
    reach_m: Vec<f64>,
    tan_el: Vec<f64>,
    /// Per range bucket of [`RANGE_BUCKET_M`]: a lower bound of the raw
    /// intensity `e^(−rate·r)` over the bucket, padded far above `exp`'s
    /// error (empty if the rate is negative).
    raw_floor: Vec<f64>,
    /// Per channel: its ground return if the ground lies within the trace.
    ground: Vec<Option<GroundRing>>,
    /// The channels with a ground return.
    ground_chans: Chans<W>,
    /// The ground channels subject to the intensity drop-off.
    ground_dim: Chans<W>,
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

impl<'a, const W: usize> World<'a, W> {
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
        let static_z = statics
            .iter()
            .map(|b| {
                (0..n)
                    .map(|c| b.z_slab(&origin, sensor.direction(c, 1.0, 0.0).z))
                    .collect()
            })
            .collect();
        let ground_t = (0..n)
            .map(|c| {
                geometry::ground_hit(&origin, &sensor.direction(c, 1.0, 0.0)).map(|g| g.range_m)
            })
            .collect();
        let rate = p.atmosphere_attenuation_rate_per_m;
        let raw_floor = if rate >= 0.0 && rate.is_finite() && p.range_m.is_finite() {
            (0..(p.range_m / RANGE_BUCKET_M).ceil() as usize + 1)
                .map(|i| (-rate * ((i + 1) as f64 * RANGE_BUCKET_M)).exp() * (1.0 - 1e-12))
                .collect()
        } else {
            Vec::new()
        };
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
            static_chans,
            static_z,
            ground_t,
            raw_floor,
            reach_m,
            tan_el,
        }
    }

    fn cars(&self, boxes: [PosedBox; 2]) -> Cars<W> {
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

    /// Nearest hit of the ray from the sensor along `d` among everything
    /// (ground, every static, both cars), at any distance.
    fn nearest(&self, d: &Vector3<f64>, cars: &Cars<W>) -> Option<Hit> {
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
        // `geometry::ground_hit`'s point, with its distance known.
        let t = self.ground_t[ch].unwrap_or(f64::NAN);
        let o = &self.origin;
        let ps = self
            .sensor
            .to_sensor(&Point3::new(o.x + t * d.x, o.y + t * d.y, 0.0));
        (ps, grid.cell_of(ps.x, ps.y))
    }

    /// Nearest hit of the ray from the sensor towards `target` (all objects).
    fn line_of_sight(&self, target: &Point3<f64>, cars: &Cars<W>) -> Option<Hit> {
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
struct GroundLevel<const W: usize> {
    /// Channels whose ground hit always yields a point.
    always: Chans<W>,
    /// Channels whose ground hit yields a point when the noise draw is
    /// below `p_d[ch]` (physical, `0 < P_D < 1`).
    maybe: Chans<W>,
    p_d: Vec<f64>,
    /// ARGUS model: box hits in range buckets below this surely return
    /// (`power·floor·fog ≥ threshold` over the bucket, within 100 m).
    sure_bucket: usize,
}

/// Per-cell state of a trial.
struct CellState<const W: usize> {
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
    levels: Vec<GroundLevel<W>>,
    level_of_bin: Vec<usize>,
    /// Fast path, physical model: saturation of box hits.
    saturation: Option<Saturation>,
    /// Fast path, ARGUS's detector with lazy road cells: this tick's ground
    /// road points as (pulse slot of the tick, channels).
    deferred: Vec<(usize, Chans<W>)>,
}

impl<const W: usize> CellState<W> {
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
    fn plan_fast(&mut self, spec: &CellSpec<'_>, world: &World<'_, W>, sc: &Scenario) {
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
                let sure_bucket = match *spec.model {
                    ReturnModel::Argus {
                        fog_factor,
                        threshold,
                    } if power >= 0.0 && fog_factor >= 0.0 => {
                        let in_range = (ARGUS_RANGE_M / RANGE_BUCKET_M).floor() as usize;
                        world
                            .raw_floor
                            .iter()
                            .take(in_range)
                            .position(|&f| power * f * fog_factor < threshold)
                            .unwrap_or(in_range.min(world.raw_floor.len()))
                    }
                    _ => 0,
                };
                let mut level = GroundLevel {
                    always: Chans::EMPTY,
                    maybe: Chans::EMPTY,
                    p_d: vec![0.0; world.ground.len()],
                    sure_bucket,
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
struct Pulse<const W: usize> {
    k: u64,
    /// The channels surviving CARLA's general drop-off (fast path).
    survivors: Chans<W>,
    az: f64,
    bin: usize,
    cos_az: f64,
    sin_az: f64,
    /// In ARGUS's kept half-plane.
    half: bool,
    /// In ARGUS's density region.
    dens: bool,
}

/// What a cast ray meets nearest so far ([`PulseCtx::fast_rays`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Near {
    Nothing,
    Ground,
    Static(geometry::Entry),
    Car(Hit),
}

/// A box hit as the cells take it: range, incidence, reflectivity, surface
/// (0 building, 1 vehicle), range bucket, point (road frame).
#[derive(Debug, Clone, Copy, Default)]
struct BoxHit {
    range_m: f64,
    cos_incidence: f64,
    reflectivity: f64,
    surface: usize,
    bucket: usize,
    point: Point3<f64>,
}

/// A pulse's rays on the fast path: the channels returning from the
/// ground and from boxes (after CARLA's drop-off), those on each car, the
/// largest range bucket of the box hits, the tick slot (lazy road cells).
#[derive(Debug, Clone, Copy)]
struct PulseRays<const W: usize> {
    ground: Chans<W>,
    boxes: Chans<W>,
    car_hits: [Chans<W>; 2],
    box_max_bucket: usize,
    lazy_slot: Option<usize>,
}

/// Reusable per-pulse buffers of the fast path, one slot per channel (the
/// box-hit slots are this pulse's for the channels of `boxes`).
struct Scratch<const W: usize> {
    boxes: Chans<W>,
    /// This pulse's statics whose extent contains the azimuth.
    statics_here: Vec<usize>,
    /// Per box hit: what the cells need, and the raw intensity if computed.
    hits: Vec<BoxHit>,
    raw: Vec<f64>,
    noise: Vec<f64>,
    noise_drawn: Chans<W>,
    points: Vec<(Point3<f64>, Option<usize>)>,
    points_done: Chans<W>,
    /// Box hits whose raw intensity is computed (`raw`).
    raw_done: Chans<W>,
    tick: TickPulses<W>,
}

/// This tick's pulses in ARGUS's half-plane (lazy road cells): their
/// azimuths and, once asked for, their ground rings' cells (shared by the
/// cells of the group).
#[derive(Default)]
struct TickPulses<const W: usize> {
    azimuths: Vec<(f64, f64)>,
    cells: Vec<Option<usize>>,
    done: Vec<Chans<W>>,
}

impl<const W: usize> TickPulses<W> {
    /// A new pulse at azimuth `(cos, sin)`: its slot.
    fn push(&mut self, cos_az: f64, sin_az: f64) -> usize {
        self.azimuths.push((cos_az, sin_az));
        self.azimuths.len() - 1
    }

    /// The cell of ground ring `ch` at pulse `slot`.
    fn cell(
        &mut self,
        slot: usize,
        ch: usize,
        world: &World<'_, W>,
        grid: &ArgusDetector,
    ) -> Option<usize> {
        let n = world.ground.len();
        if self.done.len() < self.azimuths.len() {
            self.done.resize(self.azimuths.len(), Chans::EMPTY);
            self.cells.resize(self.azimuths.len() * n, None);
        }
        if !self.done[slot].contains(ch) {
            let (cos_az, sin_az) = self.azimuths[slot];
            self.cells[slot * n + ch] = world.ground_point(ch, cos_az, sin_az, grid).1;
            self.done[slot].insert(ch);
        }
        self.cells[slot * n + ch]
    }

    fn clear(&mut self) {
        self.azimuths.clear();
        self.cells.clear();
        self.done.clear();
    }
}

/// Runs one trial for every cell of a group; outcomes in the cells' order.
#[must_use]
pub fn run_group(setup: &GroupSetup<'_>, draw: &TrialDraw) -> Vec<TrialOutcome> {
    run_group_with(setup, draw, &mut TrialRays::default())
}

/// CARLA's general drop-off of one trial, for every pulse: the channels
/// whose rays survive it. Its draw depends only on the trial's seed, the
/// pulse index and the channel, so the groups of a trial with the same
/// pulse rate and channel count share it ([`run_group_with`]).
#[derive(Debug, Default)]
pub struct TrialRays {
    /// (pulse rate bits, channels, drop-off rate bits, seed) and the
    /// survivors per pulse.
    memo: Vec<([u64; 4], Vec<Chans<4>>)>,
}

impl TrialRays {
    /// The survivors of the first `n_pulses` pulses.
    fn survivors(
        &mut self,
        pulse_rate_hz: f64,
        channels: usize,
        rate: f64,
        seed: u64,
        n_pulses: u64,
    ) -> &[Chans<4>] {
        let key = [
            pulse_rate_hz.to_bits(),
            channels as u64,
            rate.to_bits(),
            seed,
        ];
        let i = match self.memo.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                self.memo.push((key, Vec::new()));
                self.memo.len() - 1
            }
        };
        let kept = &mut self.memo[i].1;
        let mut all = Chans::EMPTY;
        for ch in 0..channels {
            all.insert(ch);
        }
        for k in kept.len() as u64..n_pulses {
            kept.push(
                all.filter(|ch| !(rate > 0.0 && unit(seed ^ ray_key(k, channels, ch)) < rate)),
            );
        }
        &kept[..n_pulses as usize]
    }
}

/// [`run_group`] with the trial's general drop-off shared through `rays`
/// (the same outcomes).
#[must_use]
pub fn run_group_with(
    setup: &GroupSetup<'_>,
    draw: &TrialDraw,
    rays: &mut TrialRays,
) -> Vec<TrialOutcome> {
    // Channel sets of one word when they fit (the paper's 64 channels).
    if setup.scenario.carla.channels <= 64 {
        run::<1>(setup, draw, rays)
    } else {
        run::<4>(setup, draw, rays)
    }
}

/// [`run_group_with`] with channel sets of `W` words.
// Channel and car indices address several parallel arrays at once.
#[allow(clippy::needless_range_loop)]
fn run<const W: usize>(
    setup: &GroupSetup<'_>,
    draw: &TrialDraw,
    rays: &mut TrialRays,
) -> Vec<TrialOutcome> {
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
    let clearance = p.vehicle_ground_clearance_m;
    let size = Vector3::new(len, sc.vehicle_width_m, p.vehicle_height_m - clearance);
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
            PosedBox::above_road(
                lane_x[j],
                centre,
                clearance,
                dir[j] * std::f64::consts::FRAC_PI_2,
                size,
            )
        })
    };
    let (schedule, duration_s) = sampling::schedule(&sampling::ScheduleSpec {
        sampling: setup.sampling,
        pulse_rate_hz: pulse_rate,
        frame_rate_hz: first.profile.frame_rate_hz,
        period_s: period,
        channels: p.channels,
        tick_s: p.tick_s,
        jitter_frac: p.async_tick_jitter_frac,
        phase_frac: draw.phase_frac,
        seed: mix64(draw.noise_seed ^ 0x6361_726c_6174_6963),
        grid_phase_steps: p.grid_phase_steps,
        t_end_s: t_end,
    });
    let n_pulses = schedule.len() as u64;
    let ego_yaw = p.ego_yaw_deg;
    let seeds = Seeds {
        general: mix64(draw.noise_seed ^ 0x6361_726c_6167_656e),
        intensity: mix64(draw.noise_seed ^ 0x6361_726c_6169_6e74),
        noise: mix64(draw.noise_seed ^ 0x6361_726c_616e_6f69),
    };

    let mut cells: Vec<CellState<W>> = setup
        .cells
        .iter()
        .map(|c| CellState::new(c, setup))
        .collect();
    let fast = !setup.brute_force && world.level;
    let survivors: &[Chans<4>] = if fast {
        rays.survivors(
            pulse_rate,
            channels,
            p.dropoff_general_rate,
            seeds.general,
            n_pulses,
        )
    } else {
        &[]
    };
    if fast {
        for (st, spec) in cells.iter_mut().zip(setup.cells) {
            st.plan_fast(spec, &world, sc);
        }
    }
    let cell_grid = ArgusDetector::new(p);
    // Cells of one plan share its regions: each pulse tests them once.
    let region_of: Vec<usize> = setup
        .cells
        .iter()
        .enumerate()
        .map(|(i, c)| {
            setup.cells[..i]
                .iter()
                .position(|o| std::ptr::eq(o.regions, c.regions))
                .unwrap_or(i)
        })
        .collect();
    let mut in_regions = vec![(false, false); cells.len()];
    let mut scratch = Scratch {
        boxes: Chans::EMPTY,
        statics_here: Vec::new(),
        hits: vec![BoxHit::default(); channels],
        raw: vec![0.0; channels],
        noise: vec![0.0; channels],
        noise_drawn: Chans::EMPTY,
        points: vec![(Point3::origin(), None); channels],
        points_done: Chans::EMPTY,
        raw_done: Chans::EMPTY,
        tick: TickPulses::default(),
    };

    // Ends tick `tick` (state time `t`) for every cell.
    let end_tick = |cells: &mut [CellState<W>],
                    tick_pulses: &mut TickPulses<W>,
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
                        for ch in chans.iter() {
                            if let Some(cell) = tick_pulses.cell(slot, ch, &world, &cell_grid) {
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
    for (k, sched) in (0u64..).zip(&schedule) {
        let tick = sched.tick;
        if tick != current_tick {
            if current_tick != u64::MAX {
                end_tick(&mut cells, &mut scratch.tick, current_tick, t_state);
            }
            current_tick = tick;
            t_state = sched.tick_end_s;
            cars = world.cars(pose(t_state));
            // The driver: looks at each car's front centre at the tick.
            for (st, spec) in cells.iter_mut().zip(setup.cells) {
                for j in 0..2 {
                    if st.driver_at[j].is_some() || t_state > t_arrive[j] {
                        continue;
                    }
                    let front = front0[j] + dir[j] * v * t_state;
                    let target = Point3::new(lane_x[j], front, clearance + 0.5 * size.z);
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
        let (frame, tau) = (sched.frame, sched.tau_s);
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
            survivors: survivors
                .get(k as usize)
                .map_or(Chans::EMPTY, |&x| Chans::narrow(x)),
            az,
            bin,
            cos_az,
            sin_az,
            half,
            dens: half && argus::signed_deg(az) < gaze - 30.0,
        };
        for (i, (st, spec)) in cells.iter_mut().zip(setup.cells).enumerate() {
            let (roi, rof) = if region_of[i] < i {
                in_regions[region_of[i]]
            } else {
                (spec.regions.roi.contains(az), spec.regions.rof.contains(az))
            };
            in_regions[i] = (roi, rof);
            st.in_roi = roi;
            st.in_rof = spec.rof_keep < 1.0 && rof;
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
            first_return: setup.detector == Detector::FirstReturn,
        };
        if fast {
            ctx.fast(&pulse, &mut cells, &mut scratch);
        } else {
            ctx.reference(&pulse, &mut cells);
        }
    }
    if current_tick != u64::MAX {
        end_tick(&mut cells, &mut scratch.tick, current_tick, t_state);
    }

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
                fail_safe_frames: 0,
                detected_in_fail_safe: [None, None],
                false_alarms: 0,
                early_false_tta_s: None,
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
struct PulseCtx<'w, 'a, const W: usize> {
    scenario: &'w Scenario,
    world: &'w World<'a, W>,
    cars: &'w Cars<W>,
    specs: &'w [CellSpec<'w>],
    seeds: &'w Seeds,
    grid: &'w ArgusDetector,
    t_state: f64,
    t_arrive_right: f64,
    /// The first-return detector (car hits count anywhere).
    first_return: bool,
}

impl<const W: usize> PulseCtx<'_, '_, W> {
    /// The reference: every channel cast against everything, every cell
    /// deciding every hit on its own, one ray at a time.
    fn reference(&self, pulse: &Pulse<W>, cells: &mut [CellState<W>]) {
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
    fn fast(&self, pulse: &Pulse<W>, cells: &mut [CellState<W>], s: &mut Scratch<W>) {
        // A pulse none of whose points any cell counts, decimates, feeds to
        // ARGUS's detector or takes as a car hit (first-return) changes
        // nothing: skip its rays (their draws are keyed, not sequential).
        let matters = |st: &CellState<W>| {
            st.in_roi
                || st.in_rof
                || pulse.half && (pulse.dens || st.argus_live(self.t_state, self.t_arrive_right))
        };
        if !self.first_return && !cells.iter().any(matters) {
            return;
        }
        let rays = self.fast_rays(pulse, s);
        self.fast_cells(pulse, &rays, cells, s);
    }

    /// The fast path's rays of a pulse (shared by the cells): casts, CARLA's
    /// drop-off, box-hit data into `s`.
    #[inline(never)]
    fn fast_rays(&self, pulse: &Pulse<W>, s: &mut Scratch<W>) -> PulseRays<W> {
        let world = self.world;
        let sc = self.scenario;
        let p = &sc.carla;
        let channels = world.ground.len();
        let k = pulse.k;
        let (cos_az, sin_az) = (pulse.cos_az, pulse.sin_az);
        let o = &world.origin;
        let alpha = p.dropoff_zero_intensity / p.dropoff_intensity_limit;
        let beta = 1.0 - p.dropoff_zero_intensity;
        let pulse_mask = world.static_mask_at(pulse.az);
        let car_arc = [
            self.cars.arcs[0].contains(pulse.az),
            self.cars.arcs[1].contains(pulse.az),
        ];
        s.statics_here.clear();
        let mut cand = Chans::EMPTY;
        for (i, c) in world.static_chans.iter().enumerate() {
            if i >= 64 || pulse_mask >> i & 1 == 1 {
                cand |= *c;
                s.statics_here.push(i);
            }
        }
        for (&in_arc, &chans) in car_arc.iter().zip(&self.cars.chans) {
            if in_arc {
                cand |= chans;
            }
        }
        let cars_here = (0..2).filter(|&j| car_arc[j]);
        // A ray that can meet nothing returns nothing whatever its draws.
        let alive = pulse.survivors & (world.ground_chans | cand);
        let mut ground = alive & !cand;
        let mut boxes = Chans::EMPTY;
        let mut box_max_bucket = 0;
        let mut car_hits = [Chans::EMPTY; 2];
        s.raw_done = Chans::EMPTY;
        for ch in (alive & cand).iter() {
            let d = world.sensor.direction(ch, cos_az, sin_az);
            // [`World::nearest`] within the trace, object by object: ground,
            // statics in order, cars; a later object replaces an earlier one
            // only if strictly nearer. Objects the ray cannot reach are left out.
            let (mut r, mut near) = match world.ground_t[ch] {
                Some(t) => (t, Near::Ground),
                None => (f64::INFINITY, Near::Nothing),
            };
            for &i in &s.statics_here {
                if !world.static_chans[i].contains(ch) {
                    continue;
                }
                let Some(z) = world.static_z[i][ch] else {
                    continue;
                };
                if let Some(e) = world.statics[i].entry(o, &d, z) {
                    if near == Near::Nothing || e.range_m < r {
                        (r, near) = (e.range_m, Near::Static(e));
                    }
                }
            }
            for j in cars_here.clone() {
                let car = &self.cars.boxes[j];
                if !self.cars.chans[j].contains(ch) {
                    continue;
                }
                if let Some(h) = car.ray_hit(o, &d, Surface::Vehicle(j)) {
                    if near == Near::Nothing || h.range_m < r {
                        (r, near) = (h.range_m, Near::Car(h));
                    }
                }
            }
            if r > world.sensor.range_m {
                continue;
            }
            let hit = match near {
                Near::Nothing => continue,
                Near::Ground => {
                    ground.insert(ch);
                    continue;
                }
                Near::Static(e) => StaticBox::hit(o, &d, e),
                Near::Car(h) => h,
            };
            let bucket = (r * (1.0 / RANGE_BUCKET_M)) as usize;
            let raw_floor = world.raw_floor.get(bucket).copied();
            // The raw intensity is needed for the drop-off unless its floor
            // is above the limit (then the intensity is too).
            if !raw_floor.is_some_and(|f| f > p.dropoff_intensity_limit) {
                let raw = (-p.atmosphere_attenuation_rate_per_m * r).exp();
                if raw <= p.dropoff_intensity_limit
                    && unit(self.seeds.intensity ^ ray_key(k, channels, ch)) >= alpha * raw + beta
                {
                    continue;
                }
                s.raw[ch] = raw;
                s.raw_done.insert(ch);
            }
            boxes.insert(ch);
            box_max_bucket = box_max_bucket.max(bucket);
            let (surface, refl) = match hit.surface {
                Surface::Vehicle(j) => {
                    car_hits[j].insert(ch);
                    (1, sc.vehicle_reflectivity)
                }
                _ => (0, sc.building_reflectivity),
            };
            s.hits[ch] = BoxHit {
                range_m: r,
                cos_incidence: hit.cos_incidence,
                reflectivity: refl,
                surface,
                bucket,
                point: hit.point,
            };
        }
        let dimmed = (ground & world.ground_dim).filter(|ch| {
            let keep_below = world.ground[ch].and_then(|g| g.keep_below);
            keep_below.is_some_and(|x| unit(self.seeds.intensity ^ ray_key(k, channels, ch)) >= x)
        });
        ground = ground & !dimmed;
        s.boxes = boxes;
        s.noise_drawn = Chans::EMPTY;
        s.points_done = Chans::EMPTY;
        let lazy_slot =
            (pulse.half && world.lazy_road).then(|| s.tick.push(pulse.cos_az, pulse.sin_az));
        PulseRays {
            ground,
            boxes,
            car_hits,
            box_max_bucket,
            lazy_slot,
        }
    }

    /// The fast path's cells of a pulse, given its rays.
    #[inline(never)]
    fn fast_cells(
        &self,
        pulse: &Pulse<W>,
        rays: &PulseRays<W>,
        cells: &mut [CellState<W>],
        s: &mut Scratch<W>,
    ) {
        let world = self.world;
        let p = &self.scenario.carla;
        let channels = world.ground.len();
        let k = pulse.k;
        let PulseRays {
            ground,
            boxes,
            car_hits,
            box_max_bucket,
            lazy_slot,
        } = *rays;
        for (st, spec) in cells.iter_mut().zip(self.specs) {
            let level = &st.levels[st.level_of_bin[pulse.bin]];
            let mut ret = ground & level.always
                | (ground & level.maybe)
                    .filter(|ch| s.noise(ch, self.seeds.noise, k, channels) < level.p_d[ch]);
            let power = st.power_ratio[pulse.bin];
            ret |= match *spec.model {
                // Rounding is monotone: `power·floor·fog ≥ threshold` implies
                // `power·raw·fog ≥ threshold` (non-negative factors, floor
                // below raw): every bucket below `sure_bucket` returns.
                ReturnModel::Argus { .. } if box_max_bucket < level.sure_bucket => boxes,
                ReturnModel::Argus {
                    fog_factor,
                    threshold,
                } => boxes.filter(|ch| {
                    s.hits[ch].bucket < level.sure_bucket
                        || argus_returns(
                            power,
                            s.raw(ch, p.atmosphere_attenuation_rate_per_m),
                            s.hits[ch].range_m,
                            fog_factor,
                            threshold,
                        )
                }),
                ReturnModel::Physical { .. } => boxes.filter(|ch| {
                    let h = s.hits[ch];
                    st.saturation
                        .as_ref()
                        .is_some_and(|x| x.saturated(h.surface, h.bucket, power, h.cos_incidence))
                        || physical_returns(
                            spec.model.detection_probability(
                                power,
                                h.reflectivity,
                                h.cos_incidence,
                                h.range_m,
                            ),
                            || s.noise(ch, self.seeds.noise, k, channels),
                        )
                }),
            };
            if st.in_rof {
                let acc = &mut st.keep_acc;
                ret = ret.filter(|_| {
                    *acc += spec.rof_keep;
                    if *acc < 1.0 {
                        return false;
                    }
                    *acc -= 1.0;
                    true
                });
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

impl<const W: usize> Scratch<W> {
    /// The raw intensity of box hit `ch` (computed once per pulse).
    fn raw(&mut self, ch: usize, rate: f64) -> f64 {
        if !self.raw_done.contains(ch) {
            self.raw[ch] = (-rate * self.hits[ch].range_m).exp();
            self.raw_done.insert(ch);
        }
        self.raw[ch]
    }

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
        world: &World<'_, W>,
        pulse: &Pulse<W>,
        grid: &ArgusDetector,
    ) -> (Point3<f64>, Option<usize>) {
        if !self.points_done.contains(ch) {
            self.points[ch] = if self.boxes.contains(ch) {
                let ps = world.sensor.to_sensor(&self.hits[ch].point);
                (ps, grid.cell_of(ps.x, ps.y))
            } else {
                world.ground_point(ch, pulse.cos_az, pulse.sin_az, grid)
            };
            self.points_done.insert(ch);
        }
        self.points[ch]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::returns::{FogLevel, ModelKind};

    /// Uniform draws for the sweeps.
    fn draws(seed: u64, n: usize) -> impl Iterator<Item = f64> {
        (0..n as u64).map(move |i| unit(seed ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15)))
    }

    #[test]
    fn erfc_is_exactly_two_at_and_below_minus_six() {
        // What [`Saturation`] rests on (libm's erfc: 2 − ε with ε below
        // half an ulp of 2 from −6 down, 2 − 2^−1022 from −28 down).
        let mut x = -6.0;
        while x > -40.0 {
            assert_eq!(0.5 * libm::erfc(x), 1.0, "{x}");
            x -= 1.0 / 1024.0;
        }
        for x in draws(1, 100_000).map(|u| -6.0 - 50.0 * u) {
            assert_eq!(0.5 * libm::erfc(x), 1.0, "{x}");
        }
        assert_eq!(0.5 * libm::erfc(f64::NEG_INFINITY), 1.0);
        assert_eq!(0.5 * libm::erfc(-1e300), 1.0);
    }

    #[test]
    fn saturated_box_hits_have_p_d_exactly_one() {
        let sc = Scenario::default();
        let refl = [sc.building_reflectivity, sc.vehicle_reflectivity];
        let sensor = crate::model::presets::paper();
        let mut saturated = 0;
        for fog in [0, 25, 50] {
            let model = ReturnModel::new(
                ModelKind::Physical,
                FogLevel::of(fog).unwrap(),
                sensor.lidar.rated_range_m,
                sensor.lidar.reference_reflectivity,
            );
            let sat = Saturation::new(&model, refl, sc.carla.range_m).unwrap();
            let u: Vec<f64> = draws(fog.into(), 400_000).collect();
            for w in u.chunks(4) {
                let (power, cos, r) = (2.0 * w[0], w[1], sc.carla.range_m * w[2] + 1e-9);
                let surface = usize::from(w[3] < 0.5);
                let bucket = (r * (1.0 / RANGE_BUCKET_M)) as usize;
                if sat.saturated(surface, bucket, power, cos) {
                    saturated += 1;
                    let p_d = model.detection_probability(power, refl[surface], cos, r);
                    assert_eq!(p_d, 1.0, "fog {fog} power {power} cos {cos} r {r}");
                }
            }
        }
        assert!(saturated > 10_000, "{saturated}");
        let argus = ReturnModel::new(ModelKind::Argus, FogLevel::of(0).unwrap(), 100.0, 0.1);
        assert!(Saturation::new(&argus, refl, 100.0).is_none());
    }

    #[test]
    fn raw_floor_lies_below_the_raw_intensity_of_its_bucket() {
        let sc = Scenario::default();
        let statics = sc.carla_static_boxes();
        let world = World::<1>::new(&sc, &statics);
        let rate = sc.carla.atmosphere_attenuation_rate_per_m;
        for r in draws(7, 100_000).map(|u| u * sc.carla.range_m) {
            let floor = world.raw_floor[(r * (1.0 / RANGE_BUCKET_M)) as usize];
            assert!(floor < (-rate * r).exp(), "{r}");
        }
    }

    #[test]
    fn lazy_road_bounds_hold_on_the_default_mount() {
        // |y| of the ground points of one azimuth never grows with the
        // channel: the lowest and highest ground channel bound a set's y.
        let sc = Scenario::default();
        let statics = sc.carla_static_boxes();
        let world = World::<1>::new(&sc, &statics);
        let grid = ArgusDetector::new(&sc.carla);
        assert!(world.level && world.lazy_road);
        let rings: Vec<usize> = world.ground_chans.iter().collect();
        assert!(rings.len() > 30);
        for az in draws(3, 20_000).map(|u| 360.0 * u) {
            let (sin_az, cos_az) = az.to_radians().sin_cos();
            let y: Vec<f64> = rings
                .iter()
                .map(|&ch| world.ground_point(ch, cos_az, sin_az, &grid).0.y)
                .collect();
            assert!(y.windows(2).all(|w| w[1].abs() <= w[0].abs()), "{az}");
            // The ring's point is the cast's ground hit.
            for &ch in &rings {
                let d = world.sensor.direction(ch, cos_az, sin_az);
                let hit = geometry::ground_hit(&world.origin, &d).unwrap();
                let ps = world.sensor.to_sensor(&hit.point);
                assert_eq!(world.ground_point(ch, cos_az, sin_az, &grid).0, ps);
                assert_eq!(Some(hit.range_m), world.ground_t[ch]);
            }
        }
        // A mount below ARGUS's road threshold: no lazy cells.
        let mut low = sc.clone();
        low.carla.mount_height_m = 2.5;
        assert!(!World::<1>::new(&low, &statics).lazy_road);
    }
}
