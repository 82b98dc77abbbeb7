//! A lightweight 2D ray-cast simulator of the paper's T-intersection
//! experiment (section IV): the time-to-arrival (TTA) at which the car from
//! the unwatched side is detected, and the point density in the LiDAR's
//! region of interest, per LiDAR variant and fog level.
//!
//! - [`scene`]: the intersection and its geometry;
//! - [`returns`]: the `argus` and `physical` return models and the fog table;
//! - [`trial`]: one trial, every pulse ray-cast at its firing time;
//! - [`stats`]: bootstrap intervals, modes and paired tests;
//! - [`plots`] and [`report`]: figures and the reproduction report.
//!
//! Trials are independent and seeded by `(seed, trial index)` only, so every
//! variant and fog level sees the same draws (paired comparison), and the
//! results are bit-identical whatever the number of threads.

pub mod carla;
pub mod gaze_drive;
#[cfg(feature = "cli")]
pub mod plots;
pub mod report;
/// The return models live in [`crate::model::returns`] (the optimizer's
/// detection objective calls them too); re-exported here.
pub use crate::model::returns;
pub mod scene;
pub mod stats;
pub mod sweep;
pub mod table;
pub mod trial;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;

use crate::checker::CertifiedProfile;
use crate::model::presets::{self, Preset};
use crate::planner::{closed_form, Mode, PlanError};

pub use carla::Sampling;
pub use returns::{FogLevel, ModelKind, ReturnModel, FOG_LEVELS_PCT};
pub use scene::Scenario;
pub use trial::{KOfN, TrialDraw, TrialOutcome};

/// Errors from a simulation run.
#[derive(Debug, Error)]
pub enum SimError {
    /// Scenario invalid.
    #[error(transparent)]
    Scenario(#[from] scene::ScenarioError),
    /// Fog level unsupported.
    #[error(transparent)]
    Fog(#[from] returns::BadFog),
    /// A variant's profile could not be planned or certified.
    #[error("variant {variant}: {source}")]
    Plan {
        /// Variant.
        variant: &'static str,
        /// Cause.
        #[source]
        source: PlanError,
    },
    /// A closed-form variant the sensor's limits reject (the sensor cannot
    /// run it): the first violated limit and how many more.
    #[error("variant {variant} (model {model}, gaze {gaze_deg}°): infeasible on this sensor: the closed form violates its limits: {first}{}", more_text(*.more))]
    ClosedFormRejected {
        /// Variant.
        variant: &'static str,
        /// Return model (`argus` runs resolution and joint on the paper
        /// code's faster spin).
        model: ModelKind,
        /// The gaze it was planned for, degrees.
        gaze_deg: f64,
        /// The first violated limit.
        first: String,
        /// How many more violations.
        more: usize,
    },
    /// Bad argument.
    #[error("{0}")]
    Argument(String),
    /// Options of the run that do not go together.
    #[error(transparent)]
    Conflict(#[from] Conflict),
    /// The optimized variant's problem is invalid (`input`) or infeasible.
    #[error("optimized variant: {message}")]
    Optimizer {
        /// What is wrong (names the key or the limit).
        message: String,
        /// A configuration (input) fault rather than infeasibility.
        input: bool,
    },
}

/// Options of a run that do not go together, named as [`SimConfig`]'s
/// fields and the scenario's keys (a front end words them as its own options).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum Conflict {
    /// The ARGUS detector outside the `carla` geometry.
    #[error(
        "detector argus needs geometry carla (ARGUS's road mask is built from ground returns)"
    )]
    DetectorNeedsCarla,
    /// False alarms per frame in the `carla` geometry.
    #[error("scenario.false_alarms_per_frame needs geometry planar (the carla geometry has no frame-based detector)")]
    FalseAlarmsNeedPlanar,
    /// A sampling other than `drift` outside the `carla` geometry.
    #[error(
        "sampling {0} needs geometry carla (the planar geometry has only the drift pulse clock)"
    )]
    SamplingNeedsCarla(Sampling),
    /// A gaze-driven run outside the planar geometry.
    #[error("a gaze-driven run: only the planar geometry is driven by the gaze stream")]
    GazeNeedsPlanar,
    /// A gaze-driven run with the `argus` return model.
    #[error("a gaze-driven run: only model physical is driven (the argus model's resolution variant is a fixed decimation, not a per-frame profile)")]
    GazeNeedsPhysical,
    /// A gaze-driven run with the optimized variant.
    #[error("a gaze-driven run: only the closed-form variants (baseline, range, resolution, joint) are driven")]
    GazeNeedsClosedForm,
}

impl SimError {
    /// An input fault rather than infeasibility.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        match self {
            Self::Plan { source, .. } => source.is_input_error(),
            Self::ClosedFormRejected { .. } => false,
            Self::Optimizer { input, .. } => *input,
            _ => true,
        }
    }
}

#[cfg(feature = "solver")]
impl From<crate::optimizer::OptError> for SimError {
    fn from(e: crate::optimizer::OptError) -> Self {
        Self::Optimizer {
            input: e.is_input_error(),
            message: e.to_string(),
        }
    }
}

/// " (and N more)", or nothing for none.
fn more_text(more: usize) -> String {
    match more {
        0 => String::new(),
        n => format!(" (and {n} more)"),
    }
}

/// A closed-form variant's planning error: a checker rejection becomes
/// [`SimError::ClosedFormRejected`] (one line, the first violated limit).
fn closed_form_error(
    variant: &'static str,
    model: ModelKind,
    gaze_deg: f64,
    source: PlanError,
) -> SimError {
    match source {
        PlanError::Rejected(r) => SimError::ClosedFormRejected {
            variant,
            model,
            gaze_deg,
            first: r
                .violations
                .first()
                .map_or_else(String::new, ToString::to_string),
            more: r.violations.len().saturating_sub(1),
        },
        source => SimError::Plan { variant, source },
    }
}

/// A LiDAR variant of the experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// Uniform (the non-adaptive LiDAR).
    Baseline,
    /// Range control (closed form).
    Range,
    /// Resolution control (closed form; in `argus`, the paper code's variant).
    Resolution,
    /// Both (closed form).
    Joint,
    /// The optimizer's profile (needs the `solver` feature): by default the
    /// paper's sensor with Levi's E2 acuity (60° region of focus), joint,
    /// continuous levels; or `SimConfig::optimizer`.
    Optimized,
}

impl Variant {
    /// The paper's four.
    pub const PAPER: [Variant; 4] = [
        Variant::Baseline,
        Variant::Range,
        Variant::Resolution,
        Variant::Joint,
    ];

    /// The closed-form controller, if any.
    #[must_use]
    pub fn mode(self) -> Option<Mode> {
        match self {
            Self::Baseline => Some(Mode::Baseline),
            Self::Range => Some(Mode::Range),
            Self::Resolution => Some(Mode::Resolution),
            Self::Joint => Some(Mode::Joint),
            Self::Optimized => None,
        }
    }
}

/// The sensor geometry of the simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Geometry {
    /// One horizontal channel in a top view, scaled by the channel count
    /// (the lightweight default).
    #[default]
    Planar,
    /// CARLA's 3D ray-cast LiDAR: every channel over the vertical field of
    /// view, a mount above a flat road, boxes with heights, CARLA's drop-off.
    Carla,
}

/// When the car from the right counts as detected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detector {
    /// Any returned point on the car (k-of-n frames; `carla`: ticks).
    #[default]
    FirstReturn,
    /// ARGUS's rule: road mask from ground returns, a vehicle point above a
    /// road cell in its region (`carla` geometry only).
    Argus,
}

/// When a car arrives (TTA is measured to this moment).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Arrival {
    /// Its front reaches |y| = `conflict_half_width_m`.
    #[default]
    Front,
    /// Its centre reaches |y| = `conflict_half_width_m` (ARGUS: the
    /// actor's location reaching world x ≤ 1.75 m).
    ArgusCentre,
}

crate::names::named_enum!(Variant {
    Baseline => "baseline", "Uniform (the non-adaptive LiDAR)";
    Range => "range", "Range control (closed form)";
    Resolution => "resolution", "Resolution control (closed form; in `argus`, the paper code's variant)";
    Joint => "joint", "Both (closed form)";
    Optimized => "optimized", "The optimizer's profile (needs the `solver` feature): by default the paper's sensor with Levi's E2 acuity (60° region of focus), joint, continuous levels; or `SimConfig::optimizer`";
});

crate::names::named_enum!(Geometry {
    Planar => "planar", "One horizontal channel in a top view, scaled by the channel count (the lightweight default)";
    Carla => "carla", "CARLA's 3D ray-cast LiDAR: every channel over the vertical field of view, a mount above a flat road, boxes with heights, CARLA's drop-off";
});

crate::names::named_enum!(Detector {
    FirstReturn => "first-return", "Any returned point on the car (k-of-n frames; `carla`: ticks)";
    Argus => "argus", "ARGUS's rule: road mask from ground returns, a vehicle point above a road cell in its region (`carla` geometry only)";
});

crate::names::named_enum!(Arrival {
    Front => "front", "Its front reaches |y| = `conflict_half_width_m`";
    ArgusCentre => "argus-centre", "Its centre reaches |y| = `conflict_half_width_m` (ARGUS: the actor's location reaching world x ≤ 1.75 m)";
});

impl Arrival {
    /// Distance the car travels after its front reaches the conflict line
    /// before it arrives, m.
    #[must_use]
    pub fn extra_distance_m(self, vehicle_length_m: f64) -> f64 {
        match self {
            Self::Front => 0.0,
            Self::ArgusCentre => 0.5 * vehicle_length_m,
        }
    }
}

/// Whether a configuration is the paper's own pipeline (CARLA geometry,
/// ARGUS's detector and arrival).
#[must_use]
pub fn is_paper_pipeline(geometry: Geometry, detector: Detector, arrival: Arrival) -> bool {
    geometry == Geometry::Carla && detector == Detector::Argus && arrival == Arrival::ArgusCentre
}

impl SimConfig {
    /// The sampling this run uses.
    #[must_use]
    pub fn sampling(&self) -> Sampling {
        self.sampling.unwrap_or(match self.geometry {
            Geometry::Carla => Sampling::Carla,
            Geometry::Planar => Sampling::Drift,
        })
    }
}

/// What to run.
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// Return models.
    pub models: Vec<ModelKind>,
    /// LiDAR variants.
    pub variants: Vec<Variant>,
    /// The optimizer problem of the `optimized` variant (`None`: the default).
    #[cfg(feature = "solver")]
    pub optimizer: Option<crate::optimizer::Problem>,
    /// Fog levels, % (paper labels).
    pub fog_pcts: Vec<u32>,
    /// Trials per cell.
    pub trials: usize,
    /// Master seed.
    pub seed: u64,
    /// Scene.
    pub scenario: Scenario,
    /// Detection rule.
    pub detection: KOfN,
    /// Disable culling (reference path).
    pub brute_force: bool,
    /// Planar geometry: cast every cell alone (the reference of the shared
    /// casts; the same results, slower).
    pub per_cell: bool,
    /// Sensor geometry.
    pub geometry: Geometry,
    /// Detector of the car from the right.
    pub detector: Detector,
    /// Arrival rule.
    pub arrival: Arrival,
    /// How the LiDAR is sampled (`None`: the geometry's own — `carla` for
    /// the `carla` geometry, `drift` for `planar`, which has only that).
    pub sampling: Option<Sampling>,
    /// Bins of the closed-form profiles.
    pub bins: usize,
    /// The sensor and driver model of the closed-form variants (regions,
    /// rated range, reference reflectivity, channels); the `optimized`
    /// variant uses its problem's sensor and focus model.
    pub sensor: Preset,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            models: vec![ModelKind::Argus, ModelKind::Physical],
            variants: Variant::PAPER.to_vec(),
            #[cfg(feature = "solver")]
            optimizer: None,
            fog_pcts: FOG_LEVELS_PCT.to_vec(),
            trials: 100,
            seed: 1,
            scenario: Scenario::default(),
            detection: KOfN::default(),
            brute_force: false,
            per_cell: false,
            geometry: Geometry::Planar,
            detector: Detector::FirstReturn,
            arrival: Arrival::Front,
            sampling: None,
            bins: 360,
            sensor: presets::paper(),
        }
    }
}

/// Points per second of the ARGUS resolution variant (all channels).
pub const ARGUS_RESOLUTION_POINTS_PER_S: f64 = 687_500.0;
/// Spin of the ARGUS baseline, Hz.
pub const ARGUS_BASELINE_FRAME_HZ: f64 = 20.0;
/// Spin of the ARGUS resolution variant, Hz.
pub const ARGUS_RESOLUTION_FRAME_HZ: f64 = 27.5;
/// The ARGUS resolution variant keeps 1 in 5.4 points inside the RoF.
pub const ARGUS_ROF_KEEP: f64 = 1.0 / 5.4;

/// How a variant is realised in a model: the profile and the RoF point
/// decimation.
///
/// - `physical`: the paper's equations — closed-form profiles (eq. 3–6) of
///   the `paper` preset; no decimation.
/// - `argus`: the paper's code — baseline and range as the closed forms
///   (they coincide with the code: ×0.5 / ×1.1); resolution as the code
///   does it: a uniform 27.5 Hz spin at 687,500 points/s (25,000 per turn,
///   as the baseline) keeping 1 in 5.4 points in the RoF; joint = both.
///   Note that this raises the frame rate and the point rate by 37.5 %,
///   which eq. 5–6 do not.
pub fn variant_profile(
    model: ModelKind,
    variant: Mode,
    gaze_deg: f64,
    bins: usize,
) -> Result<(CertifiedProfile, f64), PlanError> {
    variant_profile_for(&presets::paper(), model, variant, gaze_deg, bins)
}

/// [`variant_profile`] for any sensor: the `argus` resolution variant
/// scales the sensor's spin and point rate by 27.5 / 20 (the paper code's
/// ratio; for the paper's sensor exactly its 27.5 Hz and 687,500 points/s).
pub fn variant_profile_for(
    sensor: &Preset,
    model: ModelKind,
    variant: Mode,
    gaze_deg: f64,
    bins: usize,
) -> Result<(CertifiedProfile, f64), PlanError> {
    let paper = sensor.clone();
    match (model, variant) {
        (ModelKind::Argus, Mode::Resolution | Mode::Joint) => {
            let mut p: Preset = paper;
            let ratio = ARGUS_RESOLUTION_FRAME_HZ / ARGUS_BASELINE_FRAME_HZ;
            p.lidar.frame_rate_hz *= ratio;
            p.lidar.pulse_rate_hz *= ratio;
            let mode = if variant == Mode::Joint {
                Mode::Range
            } else {
                Mode::Baseline
            };
            let gaze = (mode != Mode::Baseline).then_some(gaze_deg);
            Ok((closed_form(&p, mode, gaze, bins)?, ARGUS_ROF_KEEP))
        }
        (_, Mode::Baseline) => Ok((closed_form(&paper, Mode::Baseline, None, bins)?, 1.0)),
        (_, m) => Ok((closed_form(&paper, m, Some(gaze_deg), bins)?, 1.0)),
    }
}

/// The random draw of trial `trial` under `seed`.
#[must_use]
pub fn draw(seed: u64, trial: usize, scenario: &Scenario) -> TrialDraw {
    let mut rng = ChaCha8Rng::seed_from_u64(trial::mix64(seed ^ trial::mix64(trial as u64)));
    let phase_frac: f64 = rng.random();
    let [lo, hi] = scenario.start_offset_m;
    let mut offset = || {
        if hi > lo {
            rng.random_range(lo..hi)
        } else {
            lo
        }
    };
    let start_offset_m = [offset(), offset()];
    let jitter = if scenario.gaze_jitter_deg > 0.0 {
        Normal::new(0.0, scenario.gaze_jitter_deg)
            .map(|n| n.sample(&mut rng))
            .unwrap_or(0.0)
    } else {
        0.0
    };
    TrialDraw {
        phase_frac,
        start_offset_m,
        gaze_deg: scenario.gaze_deg + jitter,
        noise_seed: rng.random(),
    }
}

/// One trial of one cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrialRecord {
    /// Model.
    pub model: ModelKind,
    /// Variant.
    pub variant: &'static str,
    /// Fog, %.
    pub fog_pct: u32,
    /// Trial index.
    pub trial: usize,
    /// Outcome.
    #[serde(flatten)]
    pub outcome: TrialOutcome,
}

/// Median and quartiles (linear interpolation between order statistics).
#[must_use]
pub fn quartiles(values: &[f64]) -> Option<[f64; 3]> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let x = p * (v.len() - 1) as f64;
        let i = x.floor() as usize;
        let j = (i + 1).min(v.len() - 1);
        v[i] + (v[j] - v[i]) * (x - i as f64)
    };
    Some([q(0.25), q(0.5), q(0.75)])
}

/// One row of the results table: a (model, variant, fog) cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// Return model.
    pub model: ModelKind,
    /// Variant.
    pub variant: &'static str,
    /// Fog, % (paper label).
    pub fog_pct: u32,
    /// Sensor geometry.
    pub geometry: Geometry,
    /// Detector.
    pub detector: Detector,
    /// Arrival rule.
    pub arrival: Arrival,
    /// Sampling (`carla` geometry only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampling: Option<Sampling>,
    /// Trials.
    pub trials: usize,
    /// Trials where the right car was detected before arrival.
    pub detected: usize,
    /// Right car: median TTA at detection, s.
    pub tta_median_s: Option<f64>,
    /// First quartile, s.
    pub tta_q1_s: Option<f64>,
    /// Third quartile, s.
    pub tta_q3_s: Option<f64>,
    /// RoI density accumulated as the paper plots it: points per degree
    /// over the trial, scaled to all channels (single-channel points per
    /// degree per second × channels × trial duration); median.
    pub density_median_pts_per_deg: f64,
    /// RoI points per degree per second of the simulated channel; median.
    pub density_median_pts_per_deg_s: f64,
    /// Left car (inside the driver's focus): median LiDAR TTA, s.
    pub left_tta_median_s: Option<f64>,
    /// Left car detected count.
    pub left_detected: usize,
    /// Right car: median hybrid TTA (driver or LiDAR), s.
    pub hybrid_tta_median_s: Option<f64>,
    /// Left car: median hybrid TTA, s.
    pub left_hybrid_tta_median_s: Option<f64>,
    /// ARGUS's density metric: points per trial in its kept half-plane at
    /// azimuths below gaze − 30° (all channels, ground included; planar:
    /// the simulated channel × channels); median.
    pub argus_density_points: f64,
    /// False detections per frame over the cell's trials (scenario
    /// `false_alarms_per_frame`; 0 without).
    pub false_alarms_per_frame: f64,
    /// Trials whose right-car TTA was "early false" (a false detection first).
    pub early_false: usize,
    /// Share of frames the sensor ran in fail-safe (`simulate --gaze`; 0 otherwise).
    pub fail_safe_frame_share: f64,
    /// Uncertainty of this cell's numbers (bootstrap intervals, modes,
    /// the paired test against the baseline): [`stats::CellStats`]. The
    /// JSON and CSV renderers (`table`) add its fields to the row's.
    #[serde(skip)]
    pub stats: stats::CellStats,
}

/// All rows and per-trial records.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GridResult {
    /// Cells.
    pub rows: Vec<Row>,
    /// Every trial.
    #[serde(skip)]
    pub trials: Vec<TrialRecord>,
}

impl GridResult {
    /// The per-trial values of a cell.
    pub fn cell(
        &self,
        model: ModelKind,
        variant: &str,
        fog_pct: u32,
    ) -> impl Iterator<Item = &TrialRecord> {
        let variant = variant.to_owned();
        self.trials
            .iter()
            .filter(move |r| r.model == model && r.variant == variant && r.fog_pct == fog_pct)
    }

    /// Finds a row.
    #[must_use]
    pub fn row(&self, model: ModelKind, variant: &str, fog_pct: u32) -> Option<&Row> {
        self.rows
            .iter()
            .find(|r| r.model == model && r.variant == variant && r.fog_pct == fog_pct)
    }
}

/// Plans the trial's profile for any variant.
fn plan_variant(
    sensor: &Preset,
    model: ModelKind,
    variant: Variant,
    gaze_deg: f64,
    bins: usize,
    table: Option<&OptTable>,
) -> Result<(CertifiedProfile, f64), SimError> {
    match (variant.mode(), table) {
        (Some(m), _) => variant_profile_for(sensor, model, m, gaze_deg, bins)
            .map_err(|source| closed_form_error(variant.name(), model, gaze_deg, source)),
        (None, Some(t)) => t.plan(gaze_deg),
        (None, None) => Err(SimError::Argument(
            "the optimized variant needs the `solver` feature".into(),
        )),
    }
}

/// The optimized variant's shared solutions.
#[cfg(feature = "solver")]
struct OptTable {
    table: crate::optimizer::fast::PhaseTable,
    /// The problem's sensor and focus model.
    sensor: Preset,
}

#[cfg(feature = "solver")]
impl OptTable {
    fn plan(&self, gaze_deg: f64) -> Result<(CertifiedProfile, f64), SimError> {
        self.table
            .plan(gaze_deg)
            .map(|c| (c, 1.0))
            .map_err(SimError::from)
    }

    /// The sensor and driver model of the optimized variant.
    fn sensor(&self, _base: &Preset) -> Preset {
        self.sensor.clone()
    }

    fn build(config: &SimConfig) -> Result<Option<Self>, SimError> {
        if !config.variants.contains(&Variant::Optimized) {
            return Ok(None);
        }
        let problem = match &config.optimizer {
            Some(p) => p.clone(),
            None => default_optimized_problem_for(&config.sensor, config.bins),
        };
        let gazes: Vec<f64> = (0..config.trials)
            .map(|t| draw(config.seed, t, &config.scenario).gaze_deg)
            .collect();
        let sensor =
            crate::optimizer::figures::closed_form_basis(&problem, config.sensor.levels.clone());
        crate::optimizer::fast::PhaseTable::build(&problem, &gazes)
            .map(|table| Some(Self { table, sensor }))
            .map_err(SimError::from)
    }
}

/// The default problem of the `optimized` variant.
#[cfg(feature = "solver")]
#[must_use]
pub fn default_optimized_problem(bins: usize) -> crate::optimizer::Problem {
    default_optimized_problem_for(&presets::paper(), bins)
}

/// The default problem of the `optimized` variant for a sensor.
#[cfg(feature = "solver")]
#[must_use]
pub fn default_optimized_problem_for(sensor: &Preset, bins: usize) -> crate::optimizer::Problem {
    crate::optimizer::Problem {
        lidar: sensor.lidar.clone(),
        focus: crate::model::acuity::FocusModel::levi_e2_with_width(60.0),
        levels: crate::optimizer::Levels::default(),
        objective: crate::optimizer::Objective::default(),
        bins,
    }
}

#[cfg(not(feature = "solver"))]
struct OptTable;

#[cfg(not(feature = "solver"))]
impl OptTable {
    fn plan(&self, _gaze_deg: f64) -> Result<(CertifiedProfile, f64), SimError> {
        Err(SimError::Argument(
            "the optimized variant needs the `solver` feature".into(),
        ))
    }

    fn sensor(&self, base: &Preset) -> Preset {
        base.clone()
    }

    fn build(config: &SimConfig) -> Result<Option<Self>, SimError> {
        if config.variants.contains(&Variant::Optimized) {
            return Err(SimError::Argument(
                "the optimized variant needs the `solver` feature".into(),
            ));
        }
        Ok(None)
    }
}

/// The sensor and driver model a variant runs with.
fn sensor_for<'a>(variant: Variant, optimized: Option<&'a Preset>, base: &'a Preset) -> &'a Preset {
    match (variant, optimized) {
        (Variant::Optimized, Some(s)) => s,
        _ => base,
    }
}

struct Job {
    model: ModelKind,
    variant: Variant,
    fog: FogLevel,
    trial: usize,
}

/// Runs the grid; `tick` is called once per finished trial (progress bars).
pub fn run(config: &SimConfig, tick: &(dyn Fn() + Sync)) -> Result<GridResult, SimError> {
    if config.per_cell && config.geometry == Geometry::Planar {
        let prep = Prepared::new(config)?;
        let sensor_of = |v: Variant| prep.sensor_of(v);
        let records =
            run_planar_per_cell(config, &prep.fogs, prep.table.as_ref(), &sensor_of, tick)?;
        let rows = rows_of(config, &records, &sensor_of);
        return Ok(GridResult {
            rows,
            trials: records,
        });
    }
    let mut results = run_many(std::slice::from_ref(config), tick)?;
    Ok(results.remove(0))
}

/// Runs several grids (a sweep's values) at once, each result identical to
/// [`run`]'s: trial by trial, every configuration in turn, so the work that
/// does not depend on the swept value is shared — the pulses' azimuths and
/// ray directions (planar, [`trial::PulseCache`]) and CARLA's drop-off
/// draws ([`carla::TrialRays`]). `tick` is called once per finished trial
/// and cell of any configuration.
pub fn run_many(
    configs: &[SimConfig],
    tick: &(dyn Fn() + Sync),
) -> Result<Vec<GridResult>, SimError> {
    let preps = configs
        .iter()
        .map(Prepared::new)
        .collect::<Result<Vec<_>, _>>()?;
    let most = configs.iter().map(|c| c.trials).max().unwrap_or(0);
    let per_trial: Vec<Result<Vec<Vec<TrialRecord>>, SimError>> = (0..most)
        .into_par_iter()
        .map_init(trial::PulseCache::default, |pulses, trial| {
            // The pulses' allocations are reused from trial to trial.
            pulses.clear();
            let mut rays = carla::TrialRays::default();
            preps
                .iter()
                .map(|prep| {
                    if trial >= prep.config.trials {
                        return Ok(Vec::new());
                    }
                    match prep.config.geometry {
                        Geometry::Planar => planar_trial(prep, trial, pulses, tick),
                        Geometry::Carla => carla_trial(prep, trial, &mut rays, tick),
                    }
                })
                .collect()
        })
        .collect();
    let per_trial = per_trial.into_iter().collect::<Result<Vec<_>, _>>()?;
    let mut by_config: Vec<Vec<Vec<TrialRecord>>> = vec![Vec::new(); preps.len()];
    for trial in per_trial {
        for (i, records) in trial.into_iter().enumerate() {
            by_config[i].push(records);
        }
    }
    preps
        .iter()
        .zip(by_config)
        .map(|(prep, per_trial)| {
            let records = in_planar_order(prep.config, Ok(per_trial))?;
            let sensor_of = |v: Variant| prep.sensor_of(v);
            let rows = rows_of(prep.config, &records, &sensor_of);
            Ok(GridResult {
                rows,
                trials: records,
            })
        })
        .collect()
}

/// The return model of `kind` at `fog` for `sensor` in `scenario`: the
/// scenario's `argus_fog_threshold_scale` multiplies the `argus` model's
/// intensity threshold (the physical model has no fog threshold).
#[must_use]
pub fn return_model(
    scenario: &Scenario,
    kind: ModelKind,
    fog: FogLevel,
    sensor: &Preset,
) -> ReturnModel {
    let mut m = ReturnModel::new(
        kind,
        fog,
        sensor.lidar.rated_range_m,
        sensor.lidar.reference_reflectivity,
    );
    if let ReturnModel::Argus { threshold, .. } = &mut m {
        if scenario.argus_fog_threshold_scale != 1.0 {
            *threshold *= scenario.argus_fog_threshold_scale;
        }
    }
    m
}

/// A configuration checked and set up for its trials.
struct Prepared<'c> {
    config: &'c SimConfig,
    fogs: Vec<FogLevel>,
    table: Option<OptTable>,
    opt_sensor: Option<Preset>,
    /// Planar geometry: the static boxes.
    statics: Vec<scene::Aabb>,
    /// Carla geometry: the static boxes.
    carla_statics: Vec<carla::geometry::StaticBox>,
    /// Planar geometry: the physical model's saturation bounds, once per
    /// distinct model (building and vehicle hits, to the farthest a planar
    /// ray can reach).
    saturations: Vec<(ReturnModel, Option<returns::Saturation>)>,
}

impl<'c> Prepared<'c> {
    fn new(config: &'c SimConfig) -> Result<Self, SimError> {
        config.scenario.validate()?;
        if config.trials == 0 || config.trials > 100_000 {
            return Err(SimError::Argument(format!(
                "trials: {} must lie in 1..=100000",
                config.trials
            )));
        }
        if config.detector == Detector::Argus && config.geometry != Geometry::Carla {
            return Err(Conflict::DetectorNeedsCarla.into());
        }
        if config.geometry == Geometry::Carla && config.scenario.false_alarms_per_frame > 0.0 {
            return Err(Conflict::FalseAlarmsNeedPlanar.into());
        }
        if config.geometry == Geometry::Carla {
            config.scenario.validate_carla()?;
        } else if config.sampling() != Sampling::Drift {
            return Err(Conflict::SamplingNeedsCarla(config.sampling()).into());
        }
        let fogs: Vec<FogLevel> = config
            .fog_pcts
            .iter()
            .map(|&f| FogLevel::of(f))
            .collect::<Result<_, _>>()?;
        // Plan every variant once up front so a bad one fails before any work.
        for &m in &config.models {
            for v in config.variants.iter().filter_map(|v| v.mode()) {
                let gaze = config.scenario.gaze_deg;
                variant_profile_for(&config.sensor, m, v, gaze, config.bins)
                    .map_err(|source| closed_form_error(v.name(), m, gaze, source))?;
            }
        }
        let table = OptTable::build(config)?;
        let opt_sensor = table.as_ref().map(|t| t.sensor(&config.sensor));
        let mut prep = Self {
            config,
            fogs,
            table,
            opt_sensor,
            statics: Vec::new(),
            carla_statics: Vec::new(),
            saturations: Vec::new(),
        };
        match config.geometry {
            Geometry::Planar => {
                prep.statics = config.scenario.static_boxes();
                let reflectivity = [
                    config.scenario.building_reflectivity,
                    config.scenario.vehicle_reflectivity,
                ];
                let mut saturations: Vec<(ReturnModel, Option<returns::Saturation>)> = Vec::new();
                for &model in &config.models {
                    for &variant in &config.variants {
                        let sensor = prep.sensor_of(variant);
                        for &fog in &prep.fogs {
                            let m = return_model(&config.scenario, model, fog, sensor);
                            if !saturations.iter().any(|(x, _)| *x == m) {
                                let sat = returns::Saturation::new(
                                    &m,
                                    reflectivity,
                                    PLANAR_SATURATION_RANGE_M,
                                );
                                saturations.push((m, sat));
                            }
                        }
                    }
                }
                prep.saturations = saturations;
            }
            Geometry::Carla => prep.carla_statics = config.scenario.carla_static_boxes(),
        }
        Ok(prep)
    }

    /// The sensor and driver model a variant runs with.
    fn sensor_of(&self, variant: Variant) -> &Preset {
        sensor_for(variant, self.opt_sensor.as_ref(), &self.config.sensor)
    }

    fn saturation_of(&self, m: &ReturnModel) -> Option<&returns::Saturation> {
        self.saturations
            .iter()
            .find(|(x, _)| x == m)
            .and_then(|(_, s)| s.as_ref())
    }
}

impl Prepared<'_> {
    /// Trial `trial`'s draw and every cell's plan for its gaze.
    fn trial_plans(&self, trial: usize) -> Result<(TrialDraw, Vec<Plan>), SimError> {
        let config = self.config;
        let d = draw(config.seed, trial, &config.scenario);
        let sensor_of = |v: Variant| self.sensor_of(v);
        let plans = plan_trial(
            config,
            &self.fogs,
            self.table.as_ref(),
            &sensor_of,
            d.gaze_deg,
        )?;
        Ok((d, plans))
    }
}

/// One record per cell key and its outcome, in key order, ticking once each.
fn push_records(
    out: &mut Vec<TrialRecord>,
    keys: Vec<(ModelKind, Variant, u32)>,
    outcomes: Vec<TrialOutcome>,
    trial: usize,
    tick: &(dyn Fn() + Sync),
) {
    for ((model, variant, fog_pct), outcome) in keys.into_iter().zip(outcomes) {
        tick();
        out.push(TrialRecord {
            model,
            variant: variant.name(),
            fog_pct,
            trial,
            outcome,
        });
    }
}

/// Range of the planar saturation tables, m (hits beyond take the model).
const PLANAR_SATURATION_RANGE_M: f64 = 400.0;

/// One trial of the planar geometry: every cell planned, cells sharing a
/// timeline and the driver's regions cast together ([`trial::run_group`]);
/// the records bit-identical to [`run_planar_per_cell`]'s.
fn planar_trial(
    prep: &Prepared<'_>,
    trial: usize,
    pulses: &mut trial::PulseCache,
    tick: &(dyn Fn() + Sync),
) -> Result<Vec<TrialRecord>, SimError> {
    let config = prep.config;
    let (d, plans) = prep.trial_plans(trial)?;
    // Group the plans by timeline and regions (first-seen order).
    let groups = group_plans(&plans, |a, b| a.regions == b.regions);
    let mut out = Vec::new();
    for g in &groups {
        let mut cells = Vec::new();
        let mut keys = Vec::new();
        for &i in g {
            let plan = &plans[i];
            for (fog, model) in &plan.models {
                cells.push(trial::GroupCell {
                    profile: plan.profile.profile(),
                    rof_keep: plan.rof_keep,
                    model,
                    driver_range_m: fog.mor_m,
                    saturation: prep.saturation_of(model),
                });
                keys.push((plan.model, plan.variant, fog.fog_pct));
            }
        }
        let first = &plans[g[0]];
        let setup = trial::TrialSetup {
            scenario: &config.scenario,
            statics: &prep.statics,
            profile: first.profile.profile(),
            rof_keep: first.rof_keep,
            regions: &first.regions,
            model: cells[0].model,
            driver_range_m: cells[0].driver_range_m,
            detection: config.detection,
            brute_force: config.brute_force,
            arrival: config.arrival,
            ego_yaw_deg: config.scenario.carla.ego_yaw_deg,
            gaze_deg: d.gaze_deg,
        };
        let outcomes = trial::run_group_with(&setup, &cells, &d, pulses);
        push_records(&mut out, keys, outcomes, trial, tick);
    }
    Ok(out)
}

/// The planar geometry one job per (model, variant, fog, trial), each cast
/// alone ([`trial::run_trial`]): the reference of [`run_planar`].
fn run_planar_per_cell<'s>(
    config: &SimConfig,
    fogs: &[FogLevel],
    table: Option<&OptTable>,
    sensor_of: &(dyn Fn(Variant) -> &'s Preset + Sync),
    tick: &(dyn Fn() + Sync),
) -> Result<Vec<TrialRecord>, SimError> {
    let mut jobs = Vec::new();
    for &model in &config.models {
        for &variant in &config.variants {
            for &fog in fogs {
                for trial in 0..config.trials {
                    jobs.push(Job {
                        model,
                        variant,
                        fog,
                        trial,
                    });
                }
            }
        }
    }
    let statics = config.scenario.static_boxes();
    jobs.par_iter()
        .map(|job| {
            let d = draw(config.seed, job.trial, &config.scenario);
            let sensor = sensor_of(job.variant);
            let (profile, rof_keep) = plan_variant(
                &config.sensor,
                job.model,
                job.variant,
                d.gaze_deg,
                config.bins,
                table,
            )?;
            let regions = sensor.focus.regions(d.gaze_deg);
            let model = return_model(&config.scenario, job.model, job.fog, sensor);
            let setup = trial::TrialSetup {
                scenario: &config.scenario,
                statics: &statics,
                profile: profile.profile(),
                rof_keep,
                regions: &regions,
                model: &model,
                driver_range_m: job.fog.mor_m,
                detection: config.detection,
                brute_force: config.brute_force,
                arrival: config.arrival,
                ego_yaw_deg: config.scenario.carla.ego_yaw_deg,
                gaze_deg: d.gaze_deg,
            };
            let outcome = trial::run_trial(&setup, &d);
            tick();
            Ok(TrialRecord {
                model: job.model,
                variant: job.variant.name(),
                fog_pct: job.fog.fog_pct,
                trial: job.trial,
                outcome,
            })
        })
        .collect()
}

/// One (model, variant) plan of a trial: its certified profile and one
/// return model per fog level.
struct Plan {
    model: ModelKind,
    variant: Variant,
    profile: CertifiedProfile,
    rof_keep: f64,
    regions: crate::model::acuity::Regions,
    models: Vec<(FogLevel, ReturnModel)>,
}

/// Every (model, variant) plan of a trial whose driver looks at `gaze_deg`,
/// in the configuration's order (shared by the planar and carla geometries).
fn plan_trial<'s>(
    config: &SimConfig,
    fogs: &[FogLevel],
    table: Option<&OptTable>,
    sensor_of: &(dyn Fn(Variant) -> &'s Preset + Sync),
    gaze_deg: f64,
) -> Result<Vec<Plan>, SimError> {
    let mut plans = Vec::new();
    for &model in &config.models {
        for &variant in &config.variants {
            let sensor = sensor_of(variant);
            let (profile, rof_keep) =
                plan_variant(&config.sensor, model, variant, gaze_deg, config.bins, table)?;
            let models = fogs
                .iter()
                .map(|&fog| (fog, return_model(&config.scenario, model, fog, sensor)))
                .collect();
            plans.push(Plan {
                model,
                variant,
                profile,
                rof_keep,
                regions: sensor.focus.regions(gaze_deg),
                models,
            });
        }
    }
    Ok(plans)
}

/// The plans grouped by one timeline (and whatever else `also` requires),
/// in first-seen order: the indices of each group.
fn group_plans(plans: &[Plan], also: impl Fn(&Plan, &Plan) -> bool) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, plan) in plans.iter().enumerate() {
        let same = groups.iter_mut().find(|g| {
            let first = &plans[g[0]];
            carla::same_timeline(first.profile.profile(), plan.profile.profile())
                && also(first, plan)
        });
        match same {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
}

/// One trial of the `carla` geometry: every cell planned, cells sharing a
/// timeline cast together ([`carla::run_group`]).
fn carla_trial(
    prep: &Prepared<'_>,
    trial: usize,
    rays: &mut carla::TrialRays,
    tick: &(dyn Fn() + Sync),
) -> Result<Vec<TrialRecord>, SimError> {
    let config = prep.config;
    let (d, plans) = prep.trial_plans(trial)?;
    // Group the plans by timeline (first-seen order).
    let groups = group_plans(&plans, |_, _| true);
    let mut out = Vec::new();
    for g in &groups {
        let mut specs = Vec::new();
        let mut keys = Vec::new();
        for &i in g {
            let plan = &plans[i];
            for (fog, model) in &plan.models {
                specs.push(carla::CellSpec {
                    profile: plan.profile.profile(),
                    rof_keep: plan.rof_keep,
                    regions: &plan.regions,
                    model,
                    driver_range_m: fog.mor_m,
                });
                keys.push((plan.model, plan.variant, fog.fog_pct));
            }
        }
        let setup = carla::GroupSetup {
            scenario: &config.scenario,
            statics: &prep.carla_statics,
            cells: &specs,
            detector: config.detector,
            arrival: config.arrival,
            detection: config.detection,
            brute_force: config.brute_force,
            gaze_deg: d.gaze_deg,
            sampling: config.sampling(),
        };
        let outcomes = carla::run_group_with(&setup, &d, rays);
        push_records(&mut out, keys, outcomes, trial, tick);
    }
    Ok(out)
}

/// The records of every trial in the planar order: model, variant, fog, trial.
fn in_planar_order(
    config: &SimConfig,
    per_trial: Result<Vec<Vec<TrialRecord>>, SimError>,
) -> Result<Vec<TrialRecord>, SimError> {
    let rank = |r: &TrialRecord| {
        let m = config.models.iter().position(|&x| x == r.model);
        let v = config.variants.iter().position(|x| x.name() == r.variant);
        let f = config.fog_pcts.iter().position(|&x| x == r.fog_pct);
        (m, v, f, r.trial)
    };
    let mut records: Vec<TrialRecord> = per_trial?.into_iter().flatten().collect();
    records.sort_by_key(rank);
    Ok(records)
}

/// The rows of the table from the records (in the planar order).
fn rows_of<'s>(
    config: &SimConfig,
    records: &[TrialRecord],
    sensor_of: &(dyn Fn(Variant) -> &'s Preset + Sync),
) -> Vec<Row> {
    let mut rows = Vec::new();
    let mut dens_by_row = Vec::new();
    for chunk in records.chunks(config.trials) {
        let first = &chunk[0];
        let variant = if first.variant == Variant::Optimized.name() {
            Variant::Optimized
        } else {
            Variant::Baseline
        };
        // Planar: one channel stands for all; carla: every channel is cast.
        let scale = match config.geometry {
            Geometry::Planar => f64::from(sensor_of(variant).lidar.channels),
            Geometry::Carla => 1.0,
        };
        let right: Vec<f64> = chunk.iter().filter_map(|r| r.outcome.tta_s[1]).collect();
        let left: Vec<f64> = chunk.iter().filter_map(|r| r.outcome.tta_s[0]).collect();
        let hybrid_r: Vec<f64> = chunk
            .iter()
            .filter_map(|r| r.outcome.hybrid_tta_s[1])
            .collect();
        let hybrid_l: Vec<f64> = chunk
            .iter()
            .filter_map(|r| r.outcome.hybrid_tta_s[0])
            .collect();
        let dens_s: Vec<f64> = chunk
            .iter()
            .map(|r| r.outcome.density_pts_per_deg_s())
            .collect();
        let dens_acc: Vec<f64> = chunk
            .iter()
            .map(|r| r.outcome.density_pts_per_deg_s() * scale * r.outcome.duration_s)
            .collect();
        let argus_dens: Vec<f64> = chunk
            .iter()
            .map(|r| r.outcome.argus_roi_points as f64 * scale)
            .collect();
        let q = quartiles(&right);
        let frames: u64 = chunk.iter().map(|r| r.outcome.frames).sum();
        let per_frame = |n: u64| {
            if frames > 0 {
                n as f64 / frames as f64
            } else {
                0.0
            }
        };
        rows.push(Row {
            model: first.model,
            variant: first.variant,
            fog_pct: first.fog_pct,
            geometry: config.geometry,
            detector: config.detector,
            arrival: config.arrival,
            sampling: (config.geometry == Geometry::Carla).then(|| config.sampling()),
            trials: chunk.len(),
            detected: right.len(),
            tta_median_s: q.map(|q| q[1]),
            tta_q1_s: q.map(|q| q[0]),
            tta_q3_s: q.map(|q| q[2]),
            density_median_pts_per_deg: quartiles(&dens_acc).map_or(0.0, |q| q[1]),
            density_median_pts_per_deg_s: quartiles(&dens_s).map_or(0.0, |q| q[1]),
            left_tta_median_s: quartiles(&left).map(|q| q[1]),
            left_detected: left.len(),
            hybrid_tta_median_s: quartiles(&hybrid_r).map(|q| q[1]),
            left_hybrid_tta_median_s: quartiles(&hybrid_l).map(|q| q[1]),
            argus_density_points: quartiles(&argus_dens).map_or(0.0, |q| q[1]),
            false_alarms_per_frame: per_frame(chunk.iter().map(|r| r.outcome.false_alarms).sum()),
            early_false: chunk
                .iter()
                .filter(|r| r.outcome.early_false_tta_s.is_some())
                .count(),
            fail_safe_frame_share: per_frame(
                chunk.iter().map(|r| r.outcome.fail_safe_frames).sum(),
            ),
            stats: stats::CellStats::default(),
        });
        dens_by_row.push(dens_acc);
    }
    stats::annotate(config.seed, config.trials, records, &dens_by_row, &mut rows);
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quartiles_interpolate() {
        assert_eq!(quartiles(&[]), None);
        assert_eq!(quartiles(&[3.0]), Some([3.0, 3.0, 3.0]));
        assert_eq!(quartiles(&[4.0, 1.0, 3.0, 2.0, 5.0]), Some([2.0, 3.0, 4.0]));
    }

    #[test]
    fn draws_are_reproducible_and_differ_by_trial() {
        let s = Scenario::default();
        assert_eq!(draw(7, 3, &s), draw(7, 3, &s));
        assert_ne!(draw(7, 3, &s), draw(7, 4, &s));
        assert_ne!(draw(7, 3, &s), draw(8, 3, &s));
    }
}
