//! One trial: fire every pulse of a profile at the moving scene.
//!
//! Pulse `k` fires at `t_k = k / pulse_rate_hz` (trial time); the head's
//! azimuth follows the profile in time, starting at a random phase; the ray
//! is cast at `t_k` against the static boxes and both cars at their
//! positions at `t_k`. The nearest hit decides; the return model decides
//! whether it yields a point.
//!
//! Acceleration: each object is tested only if the pulse azimuth lies in
//! the object's angular extent (static: once; cars: swept over the frame,
//! padded by [`CULL_PAD_DEG`]). Rays outside an object's extent cannot hit it,
//! so results are bit-identical to testing everything (`brute_force = true`;
//! checked by tests). In a group ([`run_group`]) a bin whose static hit is
//! bounded for every azimuth it produces, with every cell's return decided
//! over those bounds, counts its pulses that cannot reach a car without a
//! cast (`static_hit_bounds`; the same results, checked against brute
//! force).

use crate::model::acuity::Regions;
use crate::model::angle::{diff_deg, wrap_deg, Arc, CircularSet};
use crate::profile::kinematics::Timeline;
use crate::profile::Profile;

use super::returns::{ArgusBuckets, ReturnModel, Saturation, RANGE_BUCKET_M};
use super::scene::{Aabb, Scenario};

/// Padding of the culling arcs, degrees (far above `f64` rounding of atan2).
pub const CULL_PAD_DEG: f64 = 1e-6;

/// k-of-n detection over consecutive frames (paper: 1 of 1, the first return).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct KOfN {
    /// Frames with a return needed.
    pub k: u32,
    /// Window of consecutive frames.
    pub n: u32,
}

impl Default for KOfN {
    fn default() -> Self {
        Self { k: 1, n: 1 }
    }
}

/// Per-trial randomness, drawn by the caller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrialDraw {
    /// LiDAR phase as a fraction of the frame period, `[0, 1)`.
    pub phase_frac: f64,
    /// Start offsets beyond the bend, m: [left car, right car].
    pub start_offset_m: [f64; 2],
    /// Driver's gaze this trial, degrees.
    pub gaze_deg: f64,
    /// Seed of the per-pulse detection noise.
    pub noise_seed: u64,
}

/// The two crossing cars of a trial: fronts at t = 0 (the left car drives
/// −y, the right car +y, each spawned `spawn_distance_m` plus its drawn
/// offset from the ego lane), driving directions, and the times they arrive
/// (front at the conflict line plus the arrival rule's extra distance).
pub(crate) struct Crossing {
    pub front0_m: [f64; 2],
    pub dir: [f64; 2],
    pub t_arrive_s: [f64; 2],
}

impl TrialDraw {
    /// The cars of this draw at `speed_m_s` (one model for both geometries).
    pub(crate) fn crossing(
        &self,
        spawn_distance_m: f64,
        conflict_half_width_m: f64,
        extra_distance_m: f64,
        speed_m_s: f64,
    ) -> Crossing {
        let front0_m = [
            spawn_distance_m + self.start_offset_m[0],
            -(spawn_distance_m + self.start_offset_m[1]),
        ];
        let ch = conflict_half_width_m;
        Crossing {
            front0_m,
            dir: [-1.0, 1.0],
            t_arrive_s: [
                (front0_m[0] - ch + extra_distance_m) / speed_m_s,
                (-ch - front0_m[1] + extra_distance_m) / speed_m_s,
            ],
        }
    }
}

/// What one trial measured. Index 0 is the car from the left, 1 from the right.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TrialOutcome {
    /// LiDAR TTA at detection, s (`None`: not detected before arrival).
    pub tta_s: [Option<f64>; 2],
    /// Hybrid TTA: the earlier of the driver seeing the car inside the RoF
    /// and the LiDAR detecting it, s.
    pub hybrid_tta_s: [Option<f64>; 2],
    /// Points returned from pulses inside the RoI.
    pub roi_points: u64,
    /// Pulses fired inside the RoI.
    pub roi_pulses: u64,
    /// RoI width, degrees.
    pub roi_width_deg: f64,
    /// Simulated duration, s.
    pub duration_s: f64,
    /// Frames simulated.
    pub frames: u64,
    /// ARGUS's density count: returned points in its kept half-plane at
    /// azimuths below gaze − 30° (all simulated channels, ground included).
    pub argus_roi_points: u64,
    /// Channels the simulation cast (planar: 1, standing for all).
    pub channels_simulated: u32,
    /// Frames the sensor ran in fail-safe (`simulate --gaze`; 0 otherwise).
    pub fail_safe_frames: u64,
    /// Whether each car was detected in a fail-safe frame (`simulate
    /// --gaze`; `None`: not detected, or no gaze drive).
    pub detected_in_fail_safe: [Option<bool>; 2],
    /// False detections over the trial (scenario `false_alarms_per_frame`).
    pub false_alarms: u64,
    /// "Early false": the TTA of the first false detection when it comes
    /// before the right car's true detection (or there is none) and before
    /// its arrival, s.
    pub early_false_tta_s: Option<f64>,
}

impl TrialOutcome {
    /// RoI points per degree per second (one channel).
    #[must_use]
    pub fn density_pts_per_deg_s(&self) -> f64 {
        self.roi_points as f64 / (self.roi_width_deg * self.duration_s)
    }
}

/// SplitMix64 finaliser: a counter-based generator, so per-pulse noise is
/// the same whatever the thread schedule.
#[must_use]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform in `[0, 1)` from a key.
fn unit(key: u64) -> f64 {
    (mix64(key) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A detector's false detections: in each frame of the trial, one with
/// probability `p_per_frame` at a uniform time in the frame (both drawn
/// from `noise_seed` and the frame index, so every variant of a trial sees
/// the same false alarms). Frame `f` spans `[f·T − phase, (f+1)·T − phase)`
/// clipped to `[0, t_end_s)`. Returns the count and the early-false TTA of
/// the right car: `t_arrive_s − t` of the first false detection at `t` if it
/// comes no later than the arrival and before the true detection (at
/// `t_arrive_s − tta_s`; `None`: never detected).
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn false_alarms(
    noise_seed: u64,
    p_per_frame: f64,
    frames: u64,
    period_s: f64,
    phase_s: f64,
    t_end_s: f64,
    t_arrive_s: f64,
    tta_s: Option<f64>,
) -> (u64, Option<f64>) {
    if p_per_frame <= 0.0 {
        return (0, None);
    }
    let mut count = 0u64;
    let mut first: Option<f64> = None;
    for f in 0..frames {
        let key = noise_seed ^ mix64(f ^ 0xFA15_E000_0000_0000);
        if unit(key) >= p_per_frame {
            continue;
        }
        let start = (f as f64 * period_s - phase_s).max(0.0);
        let end = ((f + 1) as f64 * period_s - phase_s).min(t_end_s);
        if end <= start {
            continue;
        }
        let t = start + unit(key ^ 0x5EED) * (end - start);
        count += 1;
        first.get_or_insert(t);
    }
    let detected_at = tta_s.map(|x| t_arrive_s - x);
    let early = first
        .filter(|&t| t <= t_arrive_s && detected_at.is_none_or(|d| t < d))
        .map(|t| t_arrive_s - t);
    (count, early)
}

/// `arc.contains(az_deg)`, inlined into the pulse loop for an azimuth in
/// `[0, 360)` (a pulse's): the same arithmetic as [`Arc::contains`] and
/// [`wrap_deg`] on that domain (`az − start` lies in `(−360, 360)`).
#[inline]
fn arc_contains(arc: &Arc, az_deg: f64) -> bool {
    if arc.width_deg >= 360.0 || !(0.0..360.0).contains(&az_deg) {
        return arc.contains(az_deg);
    }
    let off = az_deg - arc.start_deg;
    let off = if off >= 0.0 {
        off
    } else {
        let w = off + 360.0;
        if w >= 360.0 {
            0.0
        } else {
            w
        }
    };
    off < arc.width_deg
}

/// The smallest arc containing the directions to `points` (none may be the origin).
fn arc_of(points: &[(f64, f64)]) -> Arc {
    let angles: Vec<f64> = points
        .iter()
        .map(|&(x, y)| y.atan2(x).to_degrees())
        .collect();
    let reference = angles[0];
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for &a in &angles[1..] {
        let d = diff_deg(a, reference);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let width = (hi - lo + 2.0 * CULL_PAD_DEG).min(360.0);
    Arc {
        start_deg: wrap_deg(reference + lo - CULL_PAD_DEG),
        width_deg: width,
    }
}

/// An object's culling arc; a box around the origin gets the full circle.
pub(crate) fn cull_arc(boxes: &[Aabb]) -> Arc {
    if boxes.iter().any(Aabb::contains_origin) {
        return Arc {
            start_deg: 0.0,
            width_deg: 360.0,
        };
    }
    let corners: Vec<(f64, f64)> = boxes.iter().flat_map(|b| b.corners()).collect();
    arc_of(&corners)
}

/// Everything a trial needs besides its random draw.
#[derive(Debug, Clone, Copy)]
pub struct TrialSetup<'a> {
    /// Scene.
    pub scenario: &'a Scenario,
    /// Static boxes (from the scenario).
    pub statics: &'a [Aabb],
    /// The certified profile the LiDAR runs.
    pub profile: &'a Profile,
    /// Fraction of RoF points kept (the ARGUS resolution variant: 1/5.4).
    pub rof_keep: f64,
    /// Driver regions for this trial's gaze.
    pub regions: &'a Regions,
    /// Return model at this fog level.
    pub model: &'a ReturnModel,
    /// Driver's visual range in this fog (MOR), m.
    pub driver_range_m: f64,
    /// Detection rule.
    pub detection: KOfN,
    /// Disable culling (reference path for tests).
    pub brute_force: bool,
    /// When a car arrives.
    pub arrival: super::Arrival,
    /// ARGUS's half-plane: the ego's world yaw, degrees.
    pub ego_yaw_deg: f64,
    /// This trial's gaze, degrees (ARGUS's density region).
    pub gaze_deg: f64,
}

/// What the sensor runs in one frame and what the driver sees then.
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    /// The certified profile of the frame.
    pub profile: &'a Profile,
    /// Its timeline (`Timeline::new(profile)`).
    pub timeline: &'a Timeline<'a>,
    /// The profile's regions (RoI point count, RoF decimation).
    pub regions: &'a Regions,
    /// The driver's regions at the frame start (`None`: eyes closed or gaze unknown: the driver sees nothing).
    pub driver: Option<&'a Regions>,
    /// Gaze of ARGUS's density region, degrees.
    pub gaze_deg: f64,
}

/// Runs one trial.
#[must_use]
pub fn run_trial(setup: &TrialSetup<'_>, draw: &TrialDraw) -> TrialOutcome {
    let tl = Timeline::new(setup.profile);
    let view = FrameView {
        profile: setup.profile,
        timeline: &tl,
        regions: setup.regions,
        driver: Some(setup.regions),
        gaze_deg: setup.gaze_deg,
    };
    run_trial_frames(setup, draw, &|_| view).0
}

/// The two cars of one trial as every ray cast sees them: where each
/// starts, which way it drives, when it reaches the conflict zone, and its
/// box at any time (one straight run at the scenario's speed).
#[derive(Debug, Clone, Copy)]
struct Traffic {
    /// Speed of both cars, m/s.
    v_m_s: f64,
    /// Lane centre of each car, m.
    lane_x_m: [f64; 2],
    /// Half the vehicle width, m.
    half_w_m: f64,
    /// Vehicle length, m.
    len_m: f64,
    /// Front position of each car at t = 0, m.
    front0_m: [f64; 2],
    /// Direction of travel of each car along its lane (±1).
    dir: [f64; 2],
    /// When each car reaches the conflict zone, s.
    t_conflict: [f64; 2],
    /// When the later of the two does, s: the trial ends there.
    t_end: f64,
}

impl Traffic {
    fn of(setup: &TrialSetup<'_>, draw: &TrialDraw) -> Self {
        let sc = setup.scenario;
        let v_m_s = sc.speed_m_s();
        let len_m = sc.vehicle_length_m;
        let Crossing {
            front0_m,
            dir,
            t_arrive_s: t_conflict,
        } = draw.crossing(
            sc.bend_distance_m,
            sc.conflict_half_width_m,
            setup.arrival.extra_distance_m(len_m),
            v_m_s,
        );
        Self {
            v_m_s,
            lane_x_m: sc.lane_x_m(),
            half_w_m: 0.5 * sc.vehicle_width_m,
            len_m,
            front0_m,
            dir,
            t_conflict,
            t_end: t_conflict[0].max(t_conflict[1]),
        }
    }

    /// Car `j`'s front centre (x, y) at time `t` (s), m.
    fn front_centre(&self, j: usize, t: f64) -> (f64, f64) {
        (self.lane_x_m[j], self.front_m(j, t))
    }

    /// Car `j`'s front position along its lane at time `t` (s), m.
    fn front_m(&self, j: usize, t: f64) -> f64 {
        self.front0_m[j] + self.dir[j] * self.v_m_s * t
    }

    /// Car `j`'s box at time `t` (s).
    fn car_box(&self, j: usize, t: f64) -> Aabb {
        let front = self.front_m(j, t);
        let back = front - self.dir[j] * self.len_m;
        Aabb::new(
            self.lane_x_m[j] - self.half_w_m,
            self.lane_x_m[j] + self.half_w_m,
            front,
            back,
        )
    }
}

impl TrialSetup<'_> {
    /// The culling arc of each static box, in `statics` order.
    fn static_arcs(&self) -> Vec<Arc> {
        self.statics
            .iter()
            .map(|b| cull_arc(std::slice::from_ref(b)))
            .collect()
    }
}

/// [`run_trial`] with the profile chosen per frame: `view_of(frame)` is
/// what the sensor runs in frame `frame` (numbered from the trial's first,
/// 0, which starts `phase_frac` of a period before t = 0). Every view's
/// timeline must have the period of `view_of(0)`'s; `setup.profile`,
/// `setup.regions` and `setup.gaze_deg` are ignored. Also returns the frame
/// in which each car was detected.
#[must_use]
pub fn run_trial_frames<'v>(
    setup: &TrialSetup<'_>,
    draw: &TrialDraw,
    view_of: &dyn Fn(u64) -> FrameView<'v>,
) -> (TrialOutcome, [Option<u64>; 2]) {
    let sc = setup.scenario;
    let mut view = view_of(0);
    let period = view.timeline.period_s();
    let pulse_rate = view.profile.pulse_rate_hz;
    let traffic = Traffic::of(setup, draw);
    let Traffic {
        t_conflict, t_end, ..
    } = traffic;
    let car_box = |j: usize, t: f64| traffic.car_box(j, t);
    let static_arcs = setup.static_arcs();
    let phase = draw.phase_frac * period;

    let mut detected_at: [Option<f64>; 2] = [None, None];
    let mut detected_frame: [Option<u64>; 2] = [None, None];
    let mut driver_at: [Option<f64>; 2] = [None, None];
    let mut hit_frames: [Vec<u64>; 2] = [Vec::new(), Vec::new()];
    let mut roi_points = 0u64;
    let mut roi_pulses = 0u64;
    let mut argus_roi_points = 0u64;
    let mut keep_acc = 0.0f64;
    let mut current_frame = u64::MAX;
    let mut car_arcs = [static_arcs[0]; 2];
    let n_pulses = (t_end * pulse_rate).floor() as u64;
    let mut frames = 0u64;
    let mut bin_hint = 0usize;

    // Nearest hit among statics and cars: (range, cos, reflectivity, car index).
    let cast = |c: f64,
                s: f64,
                az: f64,
                t: f64,
                car_arcs: &[Arc; 2]|
     -> Option<(f64, f64, f64, Option<usize>)> {
        let mut best: Option<(f64, f64, f64, Option<usize>)> = None;
        for (b, arc) in setup.statics.iter().zip(&static_arcs) {
            if setup.brute_force || arc.contains(az) {
                if let Some(h) = b.ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence, sc.building_reflectivity, None));
                    }
                }
            }
        }
        for (j, arc) in car_arcs.iter().enumerate() {
            if setup.brute_force || arc.contains(az) {
                if let Some(h) = car_box(j, t).ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence, sc.vehicle_reflectivity, Some(j)));
                    }
                }
            }
        }
        best
    };

    for k in 0..n_pulses {
        let t = k as f64 / pulse_rate;
        let tau_total = t + phase;
        let frame = (tau_total / period).floor() as u64;
        let tau = (tau_total - frame as f64 * period).clamp(0.0, period);
        if frame != current_frame {
            current_frame = frame;
            frames += 1;
            bin_hint = 0;
            view = view_of(frame);
            let t0 = (frame as f64 * period - phase).max(0.0);
            let t1 = (frame + 1) as f64 * period - phase;
            for (j, arc) in car_arcs.iter_mut().enumerate() {
                *arc = cull_arc(&[car_box(j, t0), car_box(j, t1)]);
            }
            // The driver: looks at each car's front centre at the frame start.
            for j in 0..2 {
                if driver_at[j].is_none() && t0 <= t_conflict[j] {
                    let (x, y) = traffic.front_centre(j, t0);
                    let az = y.atan2(x).to_degrees();
                    let dist = x.hypot(y);
                    if view.driver.is_some_and(|r| r.rof.contains(az))
                        && dist <= setup.driver_range_m
                    {
                        let (c, s) = (x / dist, y / dist);
                        let all = [
                            Arc {
                                start_deg: 0.0,
                                width_deg: 360.0,
                            },
                            Arc {
                                start_deg: 0.0,
                                width_deg: 360.0,
                            },
                        ];
                        if let Some((_, _, _, Some(hit))) = cast(c, s, wrap_deg(az), t0, &all) {
                            if hit == j {
                                driver_at[j] = Some(t0);
                            }
                        }
                    }
                }
            }
        }
        let (az, bin) = view.timeline.azimuth_at_from(tau, bin_hint);
        bin_hint = bin;
        let in_roi = view.regions.roi.contains(az);
        roi_pulses += u64::from(in_roi);
        let rad = az.to_radians();
        let (s, c) = rad.sin_cos();
        let Some((range, cos_i, refl, car)) = cast(c, s, az, t, &car_arcs) else {
            continue;
        };
        let power_ratio = view.profile.bins[bin].power_w / view.profile.average_power_w;
        let p_d = setup
            .model
            .detection_probability(power_ratio, refl, cos_i, range);
        let returned = p_d >= 1.0
            || (p_d > 0.0 && unit(draw.noise_seed ^ k.wrapping_mul(0xD1B5_4A32_D192_ED03)) < p_d);
        if !returned {
            continue;
        }
        if setup.rof_keep < 1.0 && view.regions.rof.contains(az) {
            keep_acc += setup.rof_keep;
            if keep_acc < 1.0 {
                continue;
            }
            keep_acc -= 1.0;
        }
        roi_points += u64::from(in_roi);
        argus_roi_points += u64::from(super::carla::argus::in_density_region(
            az,
            view.gaze_deg,
            setup.ego_yaw_deg,
        ));
        if let Some(j) = car {
            if detected_at[j].is_none() && t <= t_conflict[j] {
                let frames_hit = &mut hit_frames[j];
                if frames_hit.last() != Some(&frame) {
                    frames_hit.push(frame);
                }
                let window_start = frame.saturating_sub(u64::from(setup.detection.n) - 1);
                let recent = frames_hit
                    .iter()
                    .rev()
                    .take_while(|&&f| f >= window_start)
                    .count();
                if recent as u32 >= setup.detection.k {
                    detected_at[j] = Some(t);
                    detected_frame[j] = Some(frame);
                }
            }
        }
    }

    let tta = |j: usize, t: Option<f64>| t.map(|t| t_conflict[j] - t).filter(|x| *x >= 0.0);
    let tta_s = [tta(0, detected_at[0]), tta(1, detected_at[1])];
    let (false_alarms, early_false_tta_s) = false_alarms(
        draw.noise_seed,
        sc.false_alarms_per_frame,
        frames,
        period,
        phase,
        n_pulses as f64 / pulse_rate,
        t_conflict[1],
        tta_s[1],
    );
    let driver_tta = [tta(0, driver_at[0]), tta(1, driver_at[1])];
    let hybrid = |j: usize| match (tta_s[j], driver_tta[j]) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    let outcome = TrialOutcome {
        tta_s,
        hybrid_tta_s: [hybrid(0), hybrid(1)],
        roi_points,
        roi_pulses,
        roi_width_deg: view.regions.roi.measure_deg(),
        duration_s: n_pulses as f64 / pulse_rate,
        frames,
        argus_roi_points,
        channels_simulated: 1,
        fail_safe_frames: 0,
        detected_in_fail_safe: [None, None],
        false_alarms,
        early_false_tta_s,
    };
    (outcome, detected_frame)
}

/// Margin of [`BinFacts`], degrees: far above the rounding of a bin's
/// azimuth `wrap(start + x)` (`x` within the bin's width) and of an arc's end.
const BIN_FACT_PAD_DEG: f64 = 1e-6;

/// What holds for every azimuth a profile bin can produce: the RoI and
/// RoF membership if it is the same over the whole bin (`None`: test the
/// azimuth), and the statics whose culling arc may contain it (a superset:
/// testing a box whose arc does not contain the azimuth finds no hit, as
/// the brute-force path shows).
#[derive(Debug, Clone, Copy)]
struct BinFacts {
    roi: Option<bool>,
    rof: Option<bool>,
    statics: u64,
}

/// The bin `[lo, lo + width]` widened by the margin, or `None` if it
/// reaches 0° or 360° (the wrap: no shortcut there).
fn padded_bin(start_deg: f64, width_deg: f64) -> Option<(f64, f64)> {
    let (lo, hi) = (
        start_deg - BIN_FACT_PAD_DEG,
        start_deg + width_deg + BIN_FACT_PAD_DEG,
    );
    (lo >= 0.0 && hi < 360.0).then_some((lo, hi))
}

/// Membership of `set` over `[lo, hi]` (inside `(0, 360)`) if no edge of its
/// arcs falls in it (then it is constant there).
fn constant_membership(set: &CircularSet, arcs: &[Arc], lo: f64, hi: f64) -> Option<bool> {
    for a in arcs {
        if a.width_deg >= 360.0 {
            return Some(set.contains(lo));
        }
        for edge in [a.start_deg, wrap_deg(a.start_deg + a.width_deg)] {
            if lo - BIN_FACT_PAD_DEG <= edge && edge <= hi + BIN_FACT_PAD_DEG {
                return None;
            }
        }
    }
    Some(set.contains(0.5 * (lo + hi)))
}

/// The facts of every bin of `profile`.
fn bin_facts(profile: &Profile, regions: &Regions, static_arcs: &[Arc]) -> Vec<BinFacts> {
    let roi_arcs = regions.roi.arcs();
    let rof_arcs = regions.rof.arcs();
    let all = if static_arcs.len() >= 62 {
        (1u64 << 62) - 1
    } else {
        (1u64 << static_arcs.len()) - 1
    };
    profile
        .bins
        .iter()
        .map(|b| match padded_bin(b.start_deg, b.width_deg) {
            None => BinFacts {
                roi: None,
                rof: None,
                statics: all,
            },
            Some((lo, hi)) => BinFacts {
                roi: constant_membership(&regions.roi, &roi_arcs, lo, hi),
                rof: constant_membership(&regions.rof, &rof_arcs, lo, hi),
                statics: if static_arcs.len() >= 62 {
                    all
                } else {
                    static_arcs.iter().enumerate().fold(0, |m, (i, a)| {
                        // The arc meets [lo, hi] iff it contains lo or
                        // starts inside it.
                        let meets = a.contains(lo)
                            || (lo <= a.start_deg && a.start_deg <= hi)
                            || a.width_deg >= 360.0;
                        m | (u64::from(meets) << i)
                    })
                },
            },
        })
        .collect()
}

/// Margin of [`direction_bounds`] on a ray's direction cosines: far above
/// libm's error on `sin`/`cos` (under an ulp, 1.1e-16) and the rounding of
/// the bounds' own endpoints.
const DIR_PAD: f64 = 1e-9;

/// Bounds of `(cos θ, sin θ)` over `θ ∈ [t0, t1]` (radians, inside
/// `[0, 2π)`), each padded by [`DIR_PAD`]: the values at the ends, widened
/// to ±1 where the interval holds an extremum (cos: 0, π, 2π; sin: π/2,
/// 3π/2); between extrema both are monotone.
fn direction_bounds(t0: f64, t1: f64) -> ((f64, f64), (f64, f64)) {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let has = |x: f64| t0 - DIR_PAD <= x && x <= t1 + DIR_PAD;
    let span = |a: f64, b: f64, max_at: &[f64], min_at: &[f64]| {
        let hi = if max_at.iter().any(|&x| has(x)) {
            1.0
        } else {
            a.max(b)
        };
        let lo = if min_at.iter().any(|&x| has(x)) {
            -1.0
        } else {
            a.min(b)
        };
        (lo - DIR_PAD, hi + DIR_PAD)
    };
    (
        span(t0.cos(), t1.cos(), &[0.0, TAU], &[PI]),
        span(t0.sin(), t1.sin(), &[FRAC_PI_2], &[3.0 * FRAC_PI_2]),
    )
}

/// Bounds of a slab's entry and exit parameters (as [`Aabb::ray_hit`]'s
/// slab computes them) for every direction component `d` in `[d.0, d.1]`;
/// `None` if the ray may run parallel outside the slab (a miss there).
/// Off zero `x / d` is monotone in `d` (and its rounding monotone), so the
/// ends bound it; across zero the entry is at most 0 and the exit at least
/// the nearer end's.
#[allow(clippy::type_complexity)]
fn slab_bounds(lo: f64, hi: f64, d: (f64, f64)) -> Option<((f64, f64), (f64, f64))> {
    let (d0, d1) = d;
    if d0 > 0.0 || d1 < 0.0 {
        let ends = |x: f64| {
            let (a, b) = (x / d0, x / d1);
            (a.min(b), a.max(b))
        };
        let (at_lo, at_hi) = (ends(lo), ends(hi));
        // d > 0: entry lo/d, exit hi/d; d < 0 the other way round.
        Some(if d0 > 0.0 {
            (at_lo, at_hi)
        } else {
            (at_hi, at_lo)
        })
    } else if lo <= 0.0 && 0.0 <= hi {
        let mut exit_lo = f64::INFINITY;
        if d1 > 0.0 {
            exit_lo = exit_lo.min(hi / d1);
        }
        if d0 < 0.0 {
            exit_lo = exit_lo.min(lo / d0);
        }
        Some(((f64::NEG_INFINITY, 0.0), (exit_lo, f64::INFINITY)))
    } else {
        None
    }
}

/// What a ray cast does for every direction of a bin.
#[derive(Debug, Clone, Copy, PartialEq)]
enum HitBound {
    /// Not decided: cast the ray.
    Unknown,
    /// Never a hit.
    Miss,
    /// Always a hit at a range in `range_m` (inclusive) with an incidence
    /// cosine of at least `cos_lo`.
    Hit { range_m: (f64, f64), cos_lo: f64 },
}

/// [`Aabb::ray_hit`] for every direction with `cos` in `c`, `sin` in `s`.
fn box_bound(b: &Aabb, c: (f64, f64), s: (f64, f64)) -> HitBound {
    let (Some((x_in, x_out)), Some((y_in, y_out))) =
        (slab_bounds(b.x0, b.x1, c), slab_bounds(b.y0, b.y1, s))
    else {
        return HitBound::Unknown;
    };
    let t_in = (x_in.0.max(y_in.0), x_in.1.max(y_in.1));
    let t_out = (x_out.0.min(y_out.0), x_out.1.min(y_out.1));
    if t_in.1 <= 0.0 || t_in.0 > t_out.1 {
        return HitBound::Miss;
    }
    if !(t_in.0 > 0.0 && t_in.1 <= t_out.0) {
        return HitBound::Unknown;
    }
    let abs_lo = |(a, b): (f64, f64)| {
        if a <= 0.0 && 0.0 <= b {
            0.0
        } else {
            a.abs().min(b.abs())
        }
    };
    // The face entered: x when its entry is the later (`tx0 >= ty0`).
    let cos_lo = if x_in.0 >= y_in.1 {
        abs_lo(c)
    } else if x_in.1 < y_in.0 {
        abs_lo(s)
    } else {
        abs_lo(c).min(abs_lo(s))
    };
    HitBound::Hit {
        range_m: t_in,
        cos_lo,
    }
}

/// The nearest static hit of every azimuth of each bin of `profile`, over
/// the statics of the bin's mask (`facts`), as the pulse loop casts it
/// (`sin_cos` of `az.to_radians()`, the boxes in order, the nearest kept):
/// the nearest range lies between the least lower and the least upper
/// bound, and its cosine is at least that of any box that may be nearest.
fn static_hit_bounds(profile: &Profile, statics: &[Aabb], facts: &[BinFacts]) -> Vec<HitBound> {
    profile
        .bins
        .iter()
        .zip(facts)
        .map(|(b, f)| {
            let Some((lo, hi)) = padded_bin(b.start_deg, b.width_deg) else {
                return HitBound::Unknown;
            };
            // `to_radians` is one rounded product: monotone.
            let (c, s) = direction_bounds(lo.to_radians(), hi.to_radians());
            let mut hits: Vec<((f64, f64), f64)> = Vec::new();
            for (i, bx) in statics.iter().enumerate().take(62) {
                if f.statics >> i & 1 == 0 {
                    continue;
                }
                match box_bound(bx, c, s) {
                    HitBound::Unknown => return HitBound::Unknown,
                    HitBound::Miss => {}
                    HitBound::Hit { range_m, cos_lo } => hits.push((range_m, cos_lo)),
                }
            }
            let near_hi = hits.iter().map(|h| h.0 .1).fold(f64::INFINITY, f64::min);
            let near_lo = hits.iter().map(|h| h.0 .0).fold(f64::INFINITY, f64::min);
            let cos_lo = hits
                .iter()
                .filter(|h| h.0 .0 <= near_hi)
                .map(|h| h.1)
                .fold(f64::INFINITY, f64::min);
            if hits.is_empty() {
                HitBound::Miss
            } else {
                HitBound::Hit {
                    range_m: (near_lo, near_hi),
                    cos_lo,
                }
            }
        })
        .collect()
}

/// Whether `cell` surely returns (or surely not) a static hit within
/// `range_m` with an incidence cosine of at least `cos_lo` at power ratio
/// `power`: the pulse loop's decision ([`Saturation::saturated`], then
/// [`ArgusBuckets::decided`]) taken over the whole range; `None` if it
/// may differ, or needs the model.
fn sure_static_return(
    cell: &GroupCell<'_>,
    argus: &ArgusBuckets,
    power: f64,
    range_m: (f64, f64),
    cos_lo: f64,
) -> Option<bool> {
    let buckets = (
        (range_m.0 * (1.0 / RANGE_BUCKET_M)) as usize,
        (range_m.1 * (1.0 / RANGE_BUCKET_M)) as usize,
    );
    match cell.saturation {
        Some(sat) => sat
            .saturated_over(0, buckets, power, cos_lo)
            .then_some(true),
        None => argus
            .decided_over(cell.model, range_m, buckets, power)
            .map(|p| p >= 1.0),
    }
}

/// One cell of a planar group: what differs between cells that share a
/// trial, a timeline and the driver's regions.
#[derive(Debug, Clone, Copy)]
pub struct GroupCell<'a> {
    /// The certified profile the LiDAR runs (its timeline is the group's).
    pub profile: &'a Profile,
    /// Fraction of RoF points kept.
    pub rof_keep: f64,
    /// Return model at this fog level.
    pub model: &'a ReturnModel,
    /// Driver's visual range in this fog (MOR), m.
    pub driver_range_m: f64,
    /// The physical model's saturation bound of this model (building,
    /// vehicle reflectivity of the scene): hits it proves have `P_D = 1`
    /// skip the model.
    pub(crate) saturation: Option<&'a Saturation>,
}

/// Per-cell state of [`run_group`].
struct GroupState {
    power_ratio: Vec<f64>,
    detected_at: [Option<f64>; 2],
    driver_at: [Option<f64>; 2],
    hit_frames: [Vec<u64>; 2],
    roi_points: u64,
    argus_roi_points: u64,
    keep_acc: f64,
}

impl GroupState {
    /// Counts a returned point of a pulse (RoI, ARGUS's density); `false`
    /// if the RoF decimation drops it.
    fn keep(&mut self, rof_keep: f64, in_rof: bool, in_roi: bool, dens: bool) -> bool {
        if rof_keep < 1.0 && in_rof {
            self.keep_acc += rof_keep;
            if self.keep_acc < 1.0 {
                return false;
            }
            self.keep_acc -= 1.0;
        }
        self.roi_points += u64::from(in_roi);
        self.argus_roi_points += u64::from(dens);
        true
    }
}

/// [`run_trial`] for several cells at once, bit-identical to running each
/// alone: `setup`'s profile, regions, scene and rules are the group's
/// (every cell's profile must put every pulse at the same azimuth —
/// [`super::carla::same_timeline`] — and share the regions), and
/// `setup.model`, `rof_keep`, `driver_range_m` are ignored in favour of the
/// cells'. A pulse's azimuth, region tests and ray cast are computed once;
/// each cell then decides its own return (its power and model), in the
/// order [`run_trial`] does. Outcomes in the cells' order.
#[must_use]
pub fn run_group(
    setup: &TrialSetup<'_>,
    cells: &[GroupCell<'_>],
    draw: &TrialDraw,
) -> Vec<TrialOutcome> {
    run_group_with(setup, cells, draw, &mut PulseCache::default())
}

/// One pulse of a trial: its frame, azimuth, bin and (once a ray was cast
/// along it) the ray's direction `(sin, cos)`.
#[derive(Debug, Clone, Copy)]
struct Pulse {
    frame: u64,
    az_deg: f64,
    bin: usize,
    dir: Option<(f64, f64)>,
}

/// The pulses of a trial, shared by every [`run_group_with`] call over the
/// same timeline and phase (the values of a sweep): where the head points
/// at each pulse does not depend on the scene, so it is computed once.
/// The key holds every bit the pulses depend on (pulse and frame rate, the
/// bins' extents and spins, the trial's phase), so a cached pulse equals
/// the one computed afresh, bit for bit.
#[derive(Debug, Default)]
pub struct PulseCache {
    /// Key, pulses; entries from `live` on are spare (allocations kept).
    memo: Vec<(Vec<u64>, Vec<Pulse>)>,
    live: usize,
}

impl PulseCache {
    /// Forgets every entry but keeps the allocations (for the next trial).
    pub fn clear(&mut self) {
        self.live = 0;
    }

    /// The first `n` pulses of `profile`'s timeline starting `phase_s`
    /// into its turn.
    fn pulses(
        &mut self,
        profile: &Profile,
        tl: &Timeline<'_>,
        phase_s: f64,
        n: u64,
    ) -> &mut Vec<Pulse> {
        let mut key = Vec::with_capacity(3 + 4 * profile.bins.len());
        key.extend([
            profile.pulse_rate_hz.to_bits(),
            profile.frame_rate_hz.to_bits(),
            phase_s.to_bits(),
        ]);
        for b in &profile.bins {
            key.extend([
                b.start_deg.to_bits(),
                b.width_deg.to_bits(),
                b.spin_start_rad_s.to_bits(),
                b.spin_end_rad_s.to_bits(),
            ]);
        }
        let i = match self.memo[..self.live].iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                if self.live == self.memo.len() {
                    self.memo.push((Vec::new(), Vec::new()));
                }
                let slot = &mut self.memo[self.live];
                slot.0 = key;
                slot.1.clear();
                self.live += 1;
                self.live - 1
            }
        };
        let pulses = &mut self.memo[i].1;
        let period = tl.period_s();
        let pulse_rate = profile.pulse_rate_hz;
        let mut k = pulses.len() as u64;
        let (mut current_frame, mut bin_hint) =
            pulses.last().map_or((u64::MAX, 0), |p| (p.frame, p.bin));
        while k < n {
            let t = k as f64 / pulse_rate;
            let tau_total = t + phase_s;
            let q = tau_total / period;
            // `⌊q⌋` without the libm call while the frame lasts (frame
            // numbers are exact in `f64`).
            let frame = if current_frame != u64::MAX
                && current_frame as f64 <= q
                && q < (current_frame + 1) as f64
            {
                current_frame
            } else {
                q.floor() as u64
            };
            let tau = (tau_total - frame as f64 * period).clamp(0.0, period);
            if frame != current_frame {
                current_frame = frame;
                bin_hint = 0;
            }
            let (az_deg, bin) = tl.azimuth_at_from(tau, bin_hint);
            bin_hint = bin;
            pulses.push(Pulse {
                frame,
                az_deg,
                bin,
                dir: None,
            });
            k += 1;
        }
        pulses
    }
}

/// [`run_group`] with the trial's pulses shared through `cache`.
#[must_use]
pub fn run_group_with(
    setup: &TrialSetup<'_>,
    cells: &[GroupCell<'_>],
    draw: &TrialDraw,
    cache: &mut PulseCache,
) -> Vec<TrialOutcome> {
    let sc = setup.scenario;
    let tl = Timeline::new(setup.profile);
    let period = tl.period_s();
    let pulse_rate = setup.profile.pulse_rate_hz;
    let traffic = Traffic::of(setup, draw);
    let Traffic {
        t_conflict, t_end, ..
    } = traffic;
    let car_box = |j: usize, t: f64| traffic.car_box(j, t);
    let static_arcs = setup.static_arcs();
    let phase = draw.phase_frac * period;
    let mut states: Vec<GroupState> = cells
        .iter()
        .map(|c| GroupState {
            power_ratio: c
                .profile
                .bins
                .iter()
                .map(|b| b.power_w / c.profile.average_power_w)
                .collect(),
            detected_at: [None, None],
            driver_at: [None, None],
            hit_frames: [Vec::new(), Vec::new()],
            roi_points: 0,
            argus_roi_points: 0,
            keep_acc: 0.0,
        })
        .collect();
    let any_decimates = cells.iter().any(|c| c.rof_keep < 1.0);
    let argus = ArgusBuckets::get();
    // Cells sharing a model's range factor share its value per pulse.
    let mut factor_keys: Vec<[u64; 4]> = Vec::new();
    let factor_slot: Vec<usize> = cells
        .iter()
        .map(|c| {
            let key = c.model.range_factor_key();
            factor_keys
                .iter()
                .position(|k| *k == key)
                .unwrap_or_else(|| {
                    factor_keys.push(key);
                    factor_keys.len() - 1
                })
        })
        .collect();
    let mut factors: Vec<Option<f64>> = vec![None; factor_keys.len()];
    // Culling masks: bit i for static i (all statics if more than 62),
    // bits 62 and 63 for the cars.
    let statics_masked = setup.statics.len() <= 62;
    let facts = bin_facts(setup.profile, setup.regions, &static_arcs);
    // Per bin, the cells that surely return its static hit (bit i: cell
    // i), when every cell's return is decided for every azimuth of the bin
    // ([`static_hit_bounds`], [`sure_static_return`]): a pulse there that
    // cannot reach a car needs no ray (its counts are the same).
    let sure: Vec<Option<u64>> =
        if setup.brute_force || !statics_masked || cells.len() > 64 {
            vec![None; facts.len()]
        } else {
            static_hit_bounds(setup.profile, setup.statics, &facts)
                .iter()
                .enumerate()
                .map(|(bin, hit)| match *hit {
                    HitBound::Unknown => None,
                    HitBound::Miss => Some(0),
                    HitBound::Hit { range_m, cos_lo } => states
                        .iter()
                        .zip(cells)
                        .enumerate()
                        .try_fold(0u64, |bits, (i, (st, cell))| {
                            let power = st.power_ratio[bin];
                            sure_static_return(cell, argus, power, range_m, cos_lo)
                                .map(|r| bits | u64::from(r) << i)
                        }),
                })
                .collect()
        };
    let mut roi_pulses = 0u64;
    let mut current_frame = u64::MAX;
    let mut car_arcs = [static_arcs[0]; 2];
    let n_pulses = (t_end * pulse_rate).floor() as u64;
    let mut frames = 0u64;
    let pulses = cache.pulses(setup.profile, &tl, phase, n_pulses);

    let cast = |c: f64,
                s: f64,
                az: f64,
                t: f64,
                car_arcs: &[Arc; 2]|
     -> Option<(f64, f64, f64, Option<usize>)> {
        let mut best: Option<(f64, f64, f64, Option<usize>)> = None;
        for (b, arc) in setup.statics.iter().zip(&static_arcs) {
            if setup.brute_force || arc.contains(az) {
                if let Some(h) = b.ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence, sc.building_reflectivity, None));
                    }
                }
            }
        }
        for (j, arc) in car_arcs.iter().enumerate() {
            if setup.brute_force || arc.contains(az) {
                if let Some(h) = car_box(j, t).ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence, sc.vehicle_reflectivity, Some(j)));
                    }
                }
            }
        }
        best
    };
    let full = Arc {
        start_deg: 0.0,
        width_deg: 360.0,
    };
    // [`cast`] over the objects of `mask` (in the same order).
    let cast_masked = |c: f64, s: f64, t: f64, mask: u64| {
        let mut best: Option<(f64, f64, f64, Option<usize>)> = None;
        for (i, b) in setup.statics.iter().enumerate() {
            if mask >> i.min(61) & 1 == 1 {
                if let Some(h) = b.ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence, sc.building_reflectivity, None));
                    }
                }
            }
        }
        for j in 0..2 {
            if mask >> (62 + j) & 1 == 1 {
                if let Some(h) = car_box(j, t).ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence, sc.vehicle_reflectivity, Some(j)));
                    }
                }
            }
        }
        best
    };

    for k in 0..n_pulses {
        let pulse = &mut pulses[k as usize];
        let frame = pulse.frame;
        if frame != current_frame {
            current_frame = frame;
            frames += 1;
            let t0 = (frame as f64 * period - phase).max(0.0);
            let t1 = (frame + 1) as f64 * period - phase;
            for (j, arc) in car_arcs.iter_mut().enumerate() {
                *arc = cull_arc(&[car_box(j, t0), car_box(j, t1)]);
            }
            // The driver: looks at each car's front centre at the frame start.
            for (j, &t_conflict_j) in t_conflict.iter().enumerate() {
                if t0 > t_conflict_j {
                    continue;
                }
                let (x, y) = traffic.front_centre(j, t0);
                let az = y.atan2(x).to_degrees();
                let dist = x.hypot(y);
                if !setup.regions.rof.contains(az) {
                    continue;
                }
                let mut sees: Option<bool> = None;
                for (st, cell) in states.iter_mut().zip(cells) {
                    if st.driver_at[j].is_some() || dist > cell.driver_range_m {
                        continue;
                    }
                    let seen = *sees.get_or_insert_with(|| {
                        let (c, s) = (x / dist, y / dist);
                        matches!(cast(c, s, wrap_deg(az), t0, &[full, full]), Some((_, _, _, Some(hit))) if hit == j)
                    });
                    if seen {
                        st.driver_at[j] = Some(t0);
                    }
                }
            }
        }
        let (az, bin) = (pulse.az_deg, pulse.bin);
        let fact = facts[bin];
        let in_roi = fact.roi.unwrap_or_else(|| setup.regions.roi.contains(az));
        roi_pulses += u64::from(in_roi);
        // The objects whose extent may contain the azimuth ([`run_trial`]'s
        // culling); none: no hit, no cast.
        let mut mask = if setup.brute_force || !statics_masked {
            (1u64 << 62) - 1
        } else {
            fact.statics
        };
        for (j, arc) in car_arcs.iter().enumerate() {
            mask |= u64::from(setup.brute_force || arc_contains(arc, az)) << (62 + j);
        }
        if mask == 0 {
            continue;
        }
        let in_rof = any_decimates && fact.rof.unwrap_or_else(|| setup.regions.rof.contains(az));
        let dens = super::carla::argus::in_density_region(az, setup.gaze_deg, setup.ego_yaw_deg);
        // A pulse that cannot reach a car changes a cell only through its
        // RoI count, ARGUS's density count or the RoF decimation: outside
        // all three its return is never looked at, so it is not cast (the
        // brute-force path casts it all the same).
        if !setup.brute_force && mask >> 62 == 0 && !in_roi && !dens && !in_rof {
            continue;
        }
        if mask >> 62 == 0 {
            if let Some(returns) = sure[bin] {
                for (i, (st, cell)) in states.iter_mut().zip(cells).enumerate() {
                    if returns >> i & 1 == 1 {
                        st.keep(cell.rof_keep, in_rof, in_roi, dens);
                    }
                }
                continue;
            }
        }
        // The pulse's time (needed from here on only).
        let t = k as f64 / pulse_rate;
        let (s, c) = *pulse.dir.get_or_insert_with(|| az.to_radians().sin_cos());
        let Some((range, cos_i, refl, car)) = cast_masked(c, s, t, mask) else {
            continue;
        };
        factors.iter_mut().for_each(|f| *f = None);
        let surface = usize::from(car.is_some());
        let bucket = (range * (1.0 / RANGE_BUCKET_M)) as usize;
        let mut noise: Option<f64> = None;
        for ((st, cell), &slot) in states.iter_mut().zip(cells).zip(&factor_slot) {
            let power = st.power_ratio[bin];
            let p_d = if cell
                .saturation
                .is_some_and(|x| x.saturated(surface, bucket, power, cos_i))
            {
                1.0
            } else if let Some(p) = argus.decided(cell.model, range, bucket, power) {
                p
            } else {
                cell.model
                    .detection_probability_with(power, refl, cos_i, range, || {
                        *factors[slot].get_or_insert_with(|| cell.model.range_factor(range))
                    })
            };
            let returned = p_d >= 1.0
                || (p_d > 0.0
                    && *noise.get_or_insert_with(|| {
                        unit(draw.noise_seed ^ k.wrapping_mul(0xD1B5_4A32_D192_ED03))
                    }) < p_d);
            if !returned || !st.keep(cell.rof_keep, in_rof, in_roi, dens) {
                continue;
            }
            if let Some(j) = car {
                if st.detected_at[j].is_none() && t <= t_conflict[j] {
                    let frames_hit = &mut st.hit_frames[j];
                    if frames_hit.last() != Some(&frame) {
                        frames_hit.push(frame);
                    }
                    let window_start = frame.saturating_sub(u64::from(setup.detection.n) - 1);
                    let recent = frames_hit
                        .iter()
                        .rev()
                        .take_while(|&&f| f >= window_start)
                        .count();
                    if recent as u32 >= setup.detection.k {
                        st.detected_at[j] = Some(t);
                    }
                }
            }
        }
    }

    let tta = |j: usize, t: Option<f64>| t.map(|t| t_conflict[j] - t).filter(|x| *x >= 0.0);
    states
        .iter()
        .map(|st| {
            let tta_s = [tta(0, st.detected_at[0]), tta(1, st.detected_at[1])];
            let (false_alarms, early_false_tta_s) = false_alarms(
                draw.noise_seed,
                sc.false_alarms_per_frame,
                frames,
                period,
                phase,
                n_pulses as f64 / pulse_rate,
                t_conflict[1],
                tta_s[1],
            );
            let driver_tta = [tta(0, st.driver_at[0]), tta(1, st.driver_at[1])];
            let hybrid = |j: usize| match (tta_s[j], driver_tta[j]) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            };
            TrialOutcome {
                tta_s,
                hybrid_tta_s: [hybrid(0), hybrid(1)],
                roi_points: st.roi_points,
                roi_pulses,
                roi_width_deg: setup.regions.roi.measure_deg(),
                duration_s: n_pulses as f64 / pulse_rate,
                frames,
                argus_roi_points: st.argus_roi_points,
                channels_simulated: 1,
                fail_safe_frames: 0,
                detected_in_fail_safe: [None, None],
                false_alarms,
                early_false_tta_s,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::planner::{closed_form, Mode};

    #[test]
    fn arc_contains_is_arc_contains() {
        let mut key = 0u64;
        let mut next = || {
            key += 1;
            unit(key)
        };
        let edges = [
            0.0,
            1e-300,
            59.999_999_999_999_99,
            60.0,
            180.0,
            359.999_999_999_999_94,
        ];
        for _ in 0..20_000 {
            let start = wrap_deg(next() * 360.0);
            let width = [next() * 360.0, 360.0, 0.0, 1e-9][(next() * 4.0) as usize];
            let arc = Arc {
                start_deg: start,
                width_deg: width,
            };
            let az = wrap_deg(next() * 360.0);
            let near = [
                az,
                start,
                wrap_deg(start + width),
                wrap_deg(start + width).next_down(),
            ];
            for a in near.into_iter().chain(edges).chain([360.0, -1.0, f64::NAN]) {
                assert_eq!(arc_contains(&arc, a), arc.contains(a), "{arc:?} {a}");
            }
        }
    }

    /// The pulse loop's cast of a static-only pulse, plainly: every box of
    /// `mask` in order, the nearest kept.
    fn cast_statics(statics: &[Aabb], mask: u64, az: f64) -> Option<(f64, f64)> {
        let (s, c) = az.to_radians().sin_cos();
        let mut best: Option<(f64, f64)> = None;
        for (i, b) in statics.iter().enumerate() {
            if mask >> i & 1 == 1 {
                if let Some(h) = b.ray_hit(c, s) {
                    if best.is_none_or(|x| h.range_m < x.0) {
                        best = Some((h.range_m, h.cos_incidence));
                    }
                }
            }
        }
        best
    }

    /// Scenes around the paper's: corners, edges and the bend moved,
    /// including a corner block in front of the sensor and boxes through
    /// the axes.
    fn scenes() -> Vec<Scenario> {
        let mut out = vec![Scenario::default()];
        for (corner, near, bend, stem) in [
            (0.0, 3.0, 82.0, 7.0),
            (0.5, 1.0, 30.0, 3.0),
            (-3.0, 8.0, 150.0, 12.0),
            (-0.5, 0.5, 10.0, 1.0),
        ] {
            out.push(Scenario {
                corner_front_x_m: corner,
                near_edge_x_m: near,
                bend_distance_m: bend,
                stem_width_m: stem,
                ..Scenario::default()
            });
        }
        out
    }

    #[test]
    fn static_hit_bounds_hold_for_every_azimuth_of_their_bin() {
        // The paper's profiles at several gazes and bin counts, in several
        // scenes: azimuths across each bin (its padded edges and their
        // neighbours included) cast plainly land inside the bin's bound.
        let preset = presets::paper();
        let (mut hits, mut misses, mut cast) = (0, 0, 0);
        for sc in scenes() {
            let statics = sc.static_boxes();
            let static_arcs: Vec<Arc> = statics
                .iter()
                .map(|b| cull_arc(std::slice::from_ref(b)))
                .collect();
            for gaze in [0.0, 90.0, 181.0, 300.3] {
                for (mode, bins) in [(Mode::Joint, 360), (Mode::Resolution, 97), (Mode::Range, 7)] {
                    let c = closed_form(&preset, mode, Some(gaze), bins).unwrap();
                    let regions = preset.focus.regions(gaze);
                    let facts = bin_facts(c.profile(), &regions, &static_arcs);
                    let bounds = static_hit_bounds(c.profile(), &statics, &facts);
                    for ((b, f), bound) in c.profile().bins.iter().zip(&facts).zip(&bounds) {
                        if *bound == HitBound::Unknown {
                            continue;
                        }
                        let (lo, hi) = padded_bin(b.start_deg, b.width_deg).unwrap();
                        let samples = (0..=64)
                            .map(|i| lo + (hi - lo) * f64::from(i) / 64.0)
                            .chain([lo, lo.next_up(), hi.next_down(), hi]);
                        for az in samples {
                            let got = cast_statics(&statics, f.statics, az);
                            cast += 1;
                            match (*bound, got) {
                                (HitBound::Miss, None) => misses += 1,
                                (HitBound::Hit { range_m, cos_lo }, Some((r, cos))) => {
                                    assert!(
                                        range_m.0 <= r && r <= range_m.1,
                                        "{az} {r} {range_m:?}"
                                    );
                                    assert!(cos >= cos_lo, "{az} {cos} {cos_lo}");
                                    hits += 1;
                                }
                                (bound, got) => panic!("{az}: {bound:?} but {got:?}"),
                            }
                        }
                    }
                }
            }
        }
        assert!(hits > 50_000 && misses > 1_000, "{hits} {misses} of {cast}");
    }

    #[test]
    fn decided_bins_are_bit_identical_to_brute_force_in_every_scene() {
        // The whole planar grid (both models, every variant and fog) in
        // each scene, the decided bins against the brute-force casts.
        for scenario in scenes() {
            let config = |brute_force| crate::sim::SimConfig {
                trials: 2,
                seed: 7,
                brute_force,
                scenario: scenario.clone(),
                ..crate::sim::SimConfig::default()
            };
            let fast = crate::sim::run(&config(false), &|| {}).unwrap();
            let slow = crate::sim::run(&config(true), &|| {}).unwrap();
            assert_eq!(fast.trials, slow.trials, "{scenario:?}");
        }
    }

    #[test]
    fn slab_bounds_hold_across_zero() {
        // Direction components through zero: a slab around the origin has
        // entry ≤ 0 and an exit beyond the nearer end; one beside it may be
        // parallel (undecided).
        let d = (-0.01, 0.02);
        let ((e0, e1), (x0, x1)) = slab_bounds(-2.0, 3.0, d).unwrap();
        assert_eq!((e0, e1, x1), (f64::NEG_INFINITY, 0.0, f64::INFINITY));
        assert_eq!(x0, 150.0);
        assert!(slab_bounds(1.0, 3.0, d).is_none());
        for i in 0..300 {
            let v = -0.01 + 0.0001 * f64::from(i);
            let hit = Aabb::new(-2.0, 3.0, 1.0, 50.0).ray_hit(v, 1.0);
            if v.abs() > 0.0 {
                let (a, b) = (-2.0 / v, 3.0 / v);
                assert!(a.min(b) <= 0.0 && a.max(b) >= x0, "{v}");
            }
            assert!(hit.is_some(), "{v}");
        }
    }

    #[test]
    fn bin_facts_hold_for_every_azimuth_of_their_bin() {
        // Every bin of the paper's profiles at several gazes and bin counts
        // (RoI edges inside bins and on their edges): azimuths across each
        // bin, its edges included, agree with the facts.
        let preset = presets::paper();
        let sc = Scenario::default();
        let statics = sc.static_boxes();
        let static_arcs: Vec<Arc> = statics
            .iter()
            .map(|b| cull_arc(std::slice::from_ref(b)))
            .collect();
        let mut decided = 0;
        for gaze in [0.0, 37.25, 90.0, 90.5, 181.0, 300.3] {
            for (mode, bins) in [(Mode::Joint, 360), (Mode::Resolution, 97), (Mode::Range, 7)] {
                let c = closed_form(&preset, mode, Some(gaze), bins).unwrap();
                let regions = preset.focus.regions(gaze);
                let facts = bin_facts(c.profile(), &regions, &static_arcs);
                for (b, f) in c.profile().bins.iter().zip(&facts) {
                    for i in 0..=64 {
                        let az = wrap_deg(b.start_deg + b.width_deg * f64::from(i) / 64.0);
                        if let Some(x) = f.roi {
                            assert_eq!(x, regions.roi.contains(az), "{gaze} {az}");
                            decided += 1;
                        }
                        if let Some(x) = f.rof {
                            assert_eq!(x, regions.rof.contains(az), "{gaze} {az}");
                        }
                        for (j, a) in static_arcs.iter().enumerate() {
                            if a.contains(az) {
                                assert_eq!(f.statics >> j & 1, 1, "{gaze} {az} {j}");
                            }
                        }
                    }
                }
            }
        }
        assert!(decided > 10_000, "{decided}");
    }
}
