//! Gaze behaviour from the stream: `simulate --gaze FILE` (a recorded trace
//! in any format `stream` reads) or `simulate --gaze-behaviour NAME[:k=v,…]`
//! (a named, seeded behaviour) drives the sensor's profile frame by frame
//! through the same pipeline as `stream` ([`GazeStream`]: the I-VT filter,
//! the fail-safe machine and the frame clock), and each trial runs, in each
//! of its frames, the profile the stream decided at the latest frame start at
//! or before that frame's start — planned from the gaze available then.
//!
//! Timing: trial time 0 is when the cars start hidden (as in every trial);
//! the gaze starts [`WARMUP_S`] earlier so the filter and the fail-safe are
//! settled when the trial starts. The named behaviours are sampled at
//! [`SAMPLE_RATE_HZ`], the eye moving between fixation targets at
//! [`SACCADE_DEG_S`] (so the filter sees saccades, not jumps it would drop as
//! outliers), with a per-trial phase drawn from `(seed, trial)`. A recorded
//! trace repeats end to end (its length plus its last sample interval per
//! repetition) and each trial starts at a point of it drawn from
//! `(seed, trial)`.
//!
//! The driver sees (the hybrid TTA) with the gaze of the newest sample at or
//! before each frame start, and sees nothing while that sample is invalid
//! (a blink, tracking lost). In a fail-safe frame the RoI points are counted
//! against the scenario's nominal `gaze_deg`. Only the `physical` return
//! model and the closed-form variants are driven (the `argus` model's
//! resolution variant decimates by a fixed keep ratio, not a per-frame
//! profile; the `optimized` variant plans with the optimizer).

use std::collections::HashMap;
use std::sync::Mutex;

use rayon::prelude::*;
use serde::Serialize;

use crate::checker::CertifiedProfile;
use crate::gaze::{Format, GazeError, GazeSample, Parser, State};
use crate::model::acuity::Regions;
use crate::model::presets::Preset;
use crate::pipeline::{
    ClosedFormPlanner, Frame, FramePlanner, GazeStream, PipelineConfig, PipelineError,
};
use crate::planner::Mode;
use crate::profile::kinematics::Timeline;

use super::trial::{self, mix64, FrameView};
use super::{
    draw, rows_of, FogLevel, Geometry, GridResult, ModelKind, ReturnModel, SimConfig, SimError,
    TrialRecord,
};

/// Sample rate of the named behaviours, Hz (a typical head-mounted tracker).
pub const SAMPLE_RATE_HZ: f64 = 200.0;
/// Angular speed of the named behaviours' saccades, °/s (assumed: human
/// saccades peak at ≈ 400–700 °/s; above the filter's 30 °/s I-VT
/// threshold, below its 1000 °/s outlier limit).
pub const SACCADE_DEG_S: f64 = 400.0;
/// Gaze before trial time 0, s (filter and fail-safe settled at the start).
pub const WARMUP_S: f64 = 1.0;

/// A named gaze behaviour (angles: azimuth CCW from straight ahead, left
/// positive, degrees).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "behaviour", rename_all = "kebab-case")]
pub enum Behaviour {
    /// Fixate `gaze_deg` throughout.
    Fixate {
        /// Direction, degrees (default: the scenario's `gaze_deg`).
        gaze_deg: f64,
    },
    /// Scan both ways between `left_deg` and `right_deg`: fixations every
    /// `step_deg`, `rate_hz` round trips per second, saccades between.
    Scan {
        /// One end, degrees (default 90).
        left_deg: f64,
        /// Other end, degrees (default −90).
        right_deg: f64,
        /// Round trips per second (default 0.25).
        rate_hz: f64,
        /// Spacing of the fixations, degrees (default 30).
        step_deg: f64,
    },
    /// Fixate `gaze_deg`, glancing at a mirror at `mirror_deg` for
    /// `glance_s` every `every_s`.
    Mirror {
        /// Direction between glances (default: the scenario's `gaze_deg`).
        gaze_deg: f64,
        /// Mirror direction, degrees (default −25: the interior mirror of a
        /// left-hand-drive car, assumed).
        mirror_deg: f64,
        /// Glance period, s (default 5).
        every_s: f64,
        /// Glance length, s (default 0.8, assumed from typical mirror glances).
        glance_s: f64,
    },
    /// Fixate `gaze_deg`, blinking (invalid samples) for `blink_s` every `every_s`.
    Blink {
        /// Direction (default: the scenario's `gaze_deg`).
        gaze_deg: f64,
        /// Blink period, s (default 4: 15 blinks a minute).
        every_s: f64,
        /// Blink length, s (default 0.15).
        blink_s: f64,
    },
}

/// Behaviour names.
pub const BEHAVIOURS: [&str; 4] = ["fixate", "scan", "mirror", "blink"];

impl Behaviour {
    /// Parses `NAME[:key=value,…]` (keys as the fields, e.g.
    /// `scan:rate_hz=0.5,step_deg=20`); `gaze_deg` defaults to `default_gaze_deg`.
    pub fn parse(spec: &str, default_gaze_deg: f64) -> Result<Self, String> {
        let (name, params) = spec.split_once(':').unwrap_or((spec, ""));
        let mut b = match name.trim() {
            "fixate" => Self::Fixate {
                gaze_deg: default_gaze_deg,
            },
            "scan" => Self::Scan {
                left_deg: 90.0,
                right_deg: -90.0,
                rate_hz: 0.25,
                step_deg: 30.0,
            },
            "mirror" => Self::Mirror {
                gaze_deg: default_gaze_deg,
                mirror_deg: -25.0,
                every_s: 5.0,
                glance_s: 0.8,
            },
            "blink" => Self::Blink {
                gaze_deg: default_gaze_deg,
                every_s: 4.0,
                blink_s: 0.15,
            },
            other => return Err(format!("'{other}' is not one of {}", BEHAVIOURS.join(", "))),
        };
        for kv in params.split(',').filter(|s| !s.trim().is_empty()) {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| format!("'{kv}' is not key=value"))?;
            let (k, v) = (k.trim(), v.trim());
            let x: f64 = v
                .parse()
                .ok()
                .filter(|x: &f64| x.is_finite())
                .ok_or_else(|| format!("{k} = '{v}' is not a finite number"))?;
            let slot = match (&mut b, k) {
                (Self::Fixate { gaze_deg }, "gaze_deg")
                | (Self::Mirror { gaze_deg, .. }, "gaze_deg")
                | (Self::Blink { gaze_deg, .. }, "gaze_deg") => gaze_deg,
                (Self::Scan { left_deg, .. }, "left_deg") => left_deg,
                (Self::Scan { right_deg, .. }, "right_deg") => right_deg,
                (Self::Scan { rate_hz, .. }, "rate_hz") => rate_hz,
                (Self::Scan { step_deg, .. }, "step_deg") => step_deg,
                (Self::Mirror { mirror_deg, .. }, "mirror_deg") => mirror_deg,
                (Self::Mirror { every_s, .. } | Self::Blink { every_s, .. }, "every_s") => every_s,
                (Self::Mirror { glance_s, .. }, "glance_s") => glance_s,
                (Self::Blink { blink_s, .. }, "blink_s") => blink_s,
                _ => return Err(format!("{name} has no parameter '{k}'")),
            };
            *slot = x;
        }
        b.validate()?;
        Ok(b)
    }

    fn validate(&self) -> Result<(), String> {
        let bad = |k: &str, v: f64, why: &str| Err(format!("{k} = {v}: {why}"));
        let angle = |k: &str, v: f64| {
            if v.abs() > 360.0 {
                bad(k, v, "must lie within ±360°")
            } else {
                Ok(())
            }
        };
        match *self {
            Self::Fixate { gaze_deg } => angle("gaze_deg", gaze_deg),
            Self::Scan {
                left_deg,
                right_deg,
                rate_hz,
                step_deg,
            } => {
                angle("left_deg", left_deg)?;
                angle("right_deg", right_deg)?;
                if !(rate_hz > 0.0 && rate_hz <= 10.0) {
                    return bad("rate_hz", rate_hz, "must lie in (0, 10]");
                }
                if !(1.0..=360.0).contains(&step_deg) {
                    return bad("step_deg", step_deg, "must lie in [1, 360]");
                }
                Ok(())
            }
            Self::Mirror {
                gaze_deg,
                mirror_deg,
                every_s,
                glance_s,
            } => {
                angle("gaze_deg", gaze_deg)?;
                angle("mirror_deg", mirror_deg)?;
                if !(glance_s > 0.0 && glance_s < every_s && every_s <= 1e4) {
                    return bad(
                        "glance_s",
                        glance_s,
                        "must lie in (0, every_s), every_s <= 1e4",
                    );
                }
                Ok(())
            }
            Self::Blink {
                gaze_deg,
                every_s,
                blink_s,
            } => {
                angle("gaze_deg", gaze_deg)?;
                if !(blink_s > 0.0 && blink_s < every_s && every_s <= 1e4) {
                    return bad(
                        "blink_s",
                        blink_s,
                        "must lie in (0, every_s), every_s <= 1e4",
                    );
                }
                Ok(())
            }
        }
    }

    /// Length of one cycle of the behaviour, s (the per-trial phase is drawn in it).
    #[must_use]
    pub fn cycle_s(&self) -> f64 {
        match *self {
            Self::Fixate { .. } => 1.0,
            Self::Scan { rate_hz, .. } => 1.0 / rate_hz,
            Self::Mirror { every_s, .. } | Self::Blink { every_s, .. } => every_s,
        }
    }

    /// Where the eye is headed at behaviour time `t` (`None`: eyes closed).
    #[must_use]
    pub fn target(&self, t: f64) -> Option<f64> {
        match *self {
            Self::Fixate { gaze_deg } => Some(gaze_deg),
            Self::Scan {
                left_deg,
                right_deg,
                rate_hz,
                step_deg,
            } => {
                let n = ((right_deg - left_deg).abs() / step_deg).ceil().max(1.0) as u64;
                let dwell = 1.0 / (rate_hz * 2.0 * n as f64);
                let idx = ((t / dwell).floor() as i64).rem_euclid(2 * n as i64) as u64;
                let i = if idx <= n { idx } else { 2 * n - idx };
                Some(left_deg + (right_deg - left_deg) * i as f64 / n as f64)
            }
            Self::Mirror {
                gaze_deg,
                mirror_deg,
                every_s,
                glance_s,
            } => Some(if t.rem_euclid(every_s) < glance_s {
                mirror_deg
            } else {
                gaze_deg
            }),
            Self::Blink {
                gaze_deg,
                every_s,
                blink_s,
            } => (t.rem_euclid(every_s) >= blink_s).then_some(gaze_deg),
        }
    }

    /// Samples at [`SAMPLE_RATE_HZ`] over `[t0_s, t1_s]` (trial time), the
    /// behaviour shifted by `phase_s`.
    #[must_use]
    pub fn samples(&self, phase_s: f64, t0_s: f64, t1_s: f64) -> Vec<GazeSample> {
        let dt = 1.0 / SAMPLE_RATE_HZ;
        let step = SACCADE_DEG_S * dt;
        let mut out = Vec::new();
        let mut eye: Option<f64> = None;
        let mut k = 0u64;
        loop {
            let t = t0_s + k as f64 * dt;
            if t > t1_s {
                break;
            }
            k += 1;
            let target = self.target(t + phase_s);
            match target {
                Some(g) => {
                    let e = eye.get_or_insert(g);
                    *e += (g - *e).clamp(-step, step);
                    out.push(GazeSample {
                        t_s: t,
                        gaze_deg: *e,
                        valid: true,
                    });
                }
                None => out.push(GazeSample {
                    t_s: t,
                    gaze_deg: eye.unwrap_or(f64::NAN),
                    valid: false,
                }),
            }
        }
        out
    }
}

/// A recorded gaze trace.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    samples: Vec<GazeSample>,
    length_s: f64,
}

impl Trace {
    /// Parses a recording (`format` as `stream --format`); a malformed line
    /// is an error naming the file, line and field.
    pub fn parse(text: &str, format: Format, origin: &str) -> Result<Self, GazeError> {
        let mut parser = Parser::new(format);
        let mut samples = Vec::new();
        for (i, line) in text.lines().enumerate() {
            if let Some(s) = parser.line(line).map_err(|source| GazeError::Line {
                origin: origin.to_owned(),
                line: i + 1,
                source,
            })? {
                samples.push(s);
            }
        }
        let config = |reason: String| GazeError::Recording {
            origin: origin.to_owned(),
            reason,
        };
        let (Some(first), Some(last)) = (samples.first(), samples.last()) else {
            return Err(config("no samples".into()));
        };
        if samples.iter().any(|s| !s.t_s.is_finite()) {
            return Err(config("a timestamp is not finite".into()));
        }
        if samples.windows(2).any(|w| w[1].t_s < w[0].t_s) {
            return Err(config("timestamps must not decrease".into()));
        }
        let n = samples.len();
        let tail = if n >= 2 {
            samples[n - 1].t_s - samples[n - 2].t_s
        } else {
            1.0 / SAMPLE_RATE_HZ
        };
        let length_s = last.t_s - first.t_s + tail.max(1e-6);
        let t0 = first.t_s;
        for s in &mut samples {
            s.t_s -= t0;
        }
        Ok(Self { samples, length_s })
    }

    /// Length of one repetition, s.
    #[must_use]
    pub fn length_s(&self) -> f64 {
        self.length_s
    }

    /// The trace repeated over `[t0_s, t1_s]` (trial time), starting
    /// `offset_s` into it.
    #[must_use]
    pub fn samples(&self, offset_s: f64, t0_s: f64, t1_s: f64) -> Vec<GazeSample> {
        let mut out = Vec::new();
        let mut rep = 0u64;
        loop {
            let base = t0_s - offset_s + rep as f64 * self.length_s;
            if base > t1_s {
                break;
            }
            rep += 1;
            for s in &self.samples {
                let t = base + s.t_s;
                if (t0_s..=t1_s).contains(&t) {
                    out.push(GazeSample { t_s: t, ..*s });
                }
            }
        }
        out
    }
}

/// Where the gaze comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum GazeSource {
    /// A named behaviour.
    Behaviour(Behaviour),
    /// A recorded trace.
    Trace(Trace),
}

/// The gaze drive of a run: the source and the pipeline's settings.
#[derive(Debug, Clone)]
pub struct GazeDrive {
    /// Source.
    pub source: GazeSource,
    /// Filter, fail-safe and frame clock (as `stream`'s options).
    pub pipeline: PipelineConfig,
}

fn unit(key: u64) -> f64 {
    (mix64(key) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

impl GazeDrive {
    /// The gaze samples of trial `trial` over `[−WARMUP_S, t_end_s]`.
    #[must_use]
    pub fn samples(&self, seed: u64, trial: usize, t_end_s: f64) -> Vec<GazeSample> {
        let u = unit(seed ^ mix64(trial as u64 ^ 0x6A5E_D21E));
        match &self.source {
            GazeSource::Behaviour(b) => b.samples(u * b.cycle_s(), -WARMUP_S, t_end_s),
            GazeSource::Trace(t) => t.samples(u * t.length_s(), -WARMUP_S, t_end_s),
        }
    }
}

/// A closed-form planner whose profiles are shared by every trial of a run
/// (the same gaze → the same profile; the closed forms are deterministic).
struct SharedPlanner<'a> {
    inner: ClosedFormPlanner,
    cache: &'a Mutex<HashMap<Option<u64>, CertifiedProfile>>,
}

impl FramePlanner for SharedPlanner<'_> {
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, PipelineError> {
        let key = gaze_deg.map(f64::to_bits);
        if let Some(p) = self.cache.lock().ok().and_then(|c| c.get(&key).cloned()) {
            return Ok(p);
        }
        let p = self.inner.plan(gaze_deg)?;
        if let Ok(mut c) = self.cache.lock() {
            c.insert(key, p.clone());
        }
        Ok(p)
    }

    fn frame_rate_hz(&self) -> f64 {
        self.inner.frame_rate_hz()
    }
}

/// The frames the stream emits for `samples`, up to `t_end_s`.
fn stream_frames(
    planner: SharedPlanner<'_>,
    pipeline: &PipelineConfig,
    samples: &[GazeSample],
    t_end_s: f64,
) -> Result<Vec<Frame>, PipelineError> {
    let mut stream =
        GazeStream::with_config(planner, pipeline.filter, pipeline.failsafe, pipeline.stream);
    let mut frames = Vec::new();
    let mut emit = |f: Frame| {
        frames.push(f);
        Ok(())
    };
    for s in samples {
        stream.push_each(s, &mut emit)?;
    }
    stream.tick_each(t_end_s, &mut emit)?;
    Ok(frames)
}

/// Runs the grid (planar geometry, `physical` model, closed-form variants)
/// with the sensor's profile driven by `gaze`. Rows and records as [`super::run`];
/// each record's outcome carries `fail_safe_frames` and `detected_in_fail_safe`.
pub fn run(
    config: &SimConfig,
    gaze: &GazeDrive,
    tick: &(dyn Fn() + Sync),
) -> Result<GridResult, SimError> {
    config.scenario.validate()?;
    if config.trials == 0 || config.trials > 100_000 {
        return Err(SimError::Argument(format!(
            "trials: {} must lie in 1..=100000",
            config.trials
        )));
    }
    if config.geometry != Geometry::Planar {
        return Err(super::Conflict::GazeNeedsPlanar.into());
    }
    if config.models.iter().any(|&m| m != ModelKind::Physical) {
        return Err(super::Conflict::GazeNeedsPhysical.into());
    }
    let modes: Vec<Mode> = config
        .variants
        .iter()
        .map(|v| {
            v.mode()
                .ok_or_else(|| SimError::from(super::Conflict::GazeNeedsClosedForm))
        })
        .collect::<Result<_, _>>()?;
    let fogs: Vec<FogLevel> = config
        .fog_pcts
        .iter()
        .map(|&f| FogLevel::of(f))
        .collect::<Result<_, _>>()?;
    let sensor: &Preset = &config.sensor;
    let caches: Vec<Mutex<HashMap<Option<u64>, CertifiedProfile>>> =
        modes.iter().map(|_| Mutex::new(HashMap::new())).collect();
    let statics = config.scenario.static_boxes();
    let models: Vec<ReturnModel> = fogs
        .iter()
        .map(|&fog| super::return_model(&config.scenario, ModelKind::Physical, fog, sensor))
        .collect();
    let nominal = sensor.focus.regions(config.scenario.gaze_deg);
    let per_trial: Result<Vec<Vec<TrialRecord>>, SimError> = (0..config.trials)
        .into_par_iter()
        .map(|trial| {
            let d = draw(config.seed, trial, &config.scenario);
            let t_end = d
                .crossing(
                    config.scenario.bend_distance_m,
                    config.scenario.conflict_half_width_m,
                    config
                        .arrival
                        .extra_distance_m(config.scenario.vehicle_length_m),
                    config.scenario.speed_m_s(),
                )
                .t_arrive_s
                .into_iter()
                .fold(0.0f64, f64::max);
            let samples = gaze.samples(config.seed, trial, t_end);
            let mut out = Vec::new();
            for (vi, (&mode, cache)) in modes.iter().zip(&caches).enumerate() {
                let planner = SharedPlanner {
                    inner: ClosedFormPlanner {
                        preset: sensor.clone(),
                        mode,
                        bins: config.bins,
                    },
                    cache,
                };
                let frames = stream_frames(planner, &gaze.pipeline, &samples, t_end)
                    .map_err(|e| SimError::Argument(format!("gaze stream: {e}")))?;
                let records = run_driven(
                    config, &statics, &models, &fogs, &nominal, &d, &frames, &samples,
                )?;
                for (fi, outcome) in records.into_iter().enumerate() {
                    tick();
                    out.push((
                        fi,
                        vi,
                        TrialRecord {
                            model: ModelKind::Physical,
                            variant: config.variants[vi].name(),
                            fog_pct: fogs[fi].fog_pct,
                            trial,
                            outcome,
                        },
                    ));
                }
            }
            // Planar order within the trial: variant, then fog.
            out.sort_by_key(|(fi, vi, _)| (*vi, *fi));
            Ok(out.into_iter().map(|(_, _, r)| r).collect())
        })
        .collect();
    let per_trial = per_trial?;
    // Records in the planar order: model, variant, fog, trial.
    let cells = per_trial.first().map_or(0, Vec::len);
    let mut records = Vec::with_capacity(cells * config.trials);
    for c in 0..cells {
        for t in &per_trial {
            records.push(t[c].clone());
        }
    }
    let sensor_of = |_| sensor;
    let rows = rows_of(config, &records, &sensor_of);
    Ok(GridResult {
        rows,
        trials: records,
    })
}

/// One trial under the stream's frames, once per fog level.
#[allow(clippy::too_many_arguments)]
fn run_driven(
    config: &SimConfig,
    statics: &[super::scene::Aabb],
    models: &[ReturnModel],
    fogs: &[FogLevel],
    nominal: &Regions,
    d: &trial::TrialDraw,
    frames: &[Frame],
    samples: &[GazeSample],
) -> Result<Vec<super::TrialOutcome>, SimError> {
    let Some(first) = frames.first() else {
        return Err(SimError::Argument("gaze stream: no frame".into()));
    };
    let focus = &config.sensor.focus;
    let timelines: Vec<Timeline<'_>> = frames
        .iter()
        .map(|f| Timeline::new(f.profile.profile()))
        .collect();
    let period = timelines[0].period_s();
    if timelines
        .iter()
        .any(|t| (t.period_s() - period).abs() > 1e-9 * period)
    {
        return Err(SimError::Argument(
            "gaze stream: the profiles' frame periods differ".into(),
        ));
    }
    let regions: Vec<Regions> = frames
        .iter()
        .map(|f| match (f.state, f.profile.profile().gaze_deg) {
            (State::Adaptive, Some(g)) => focus.regions(g),
            _ => nominal.clone(),
        })
        .collect();
    // Sensor frame j starts at j·T − phase: the stream frame decided at the
    // latest start at or before it (1 ns of slack for the µs frame clock).
    let phase = d.phase_frac * period;
    let t_end = samples.last().map_or(0.0, |s| s.t_s);
    let n_frames = ((t_end + phase) / period).ceil() as usize + 2;
    let mut stream_of = Vec::with_capacity(n_frames);
    let mut driver: Vec<Option<Regions>> = Vec::with_capacity(n_frames);
    for j in 0..n_frames {
        let start = j as f64 * period - phase;
        let k = frames
            .partition_point(|f| f.t_s <= start + 1e-9)
            .saturating_sub(1);
        stream_of.push(k);
        let s = samples.partition_point(|s| s.t_s <= start).checked_sub(1);
        driver.push(
            s.map(|i| samples[i])
                .filter(GazeSample::usable)
                .map(|s| focus.regions(s.gaze_deg)),
        );
    }
    let _ = first;
    let views: Vec<FrameView<'_>> = (0..n_frames)
        .map(|j| {
            let k = stream_of[j];
            FrameView {
                profile: frames[k].profile.profile(),
                timeline: &timelines[k],
                regions: &regions[k],
                driver: driver[j].as_ref(),
                gaze_deg: frames[k]
                    .profile
                    .profile()
                    .gaze_deg
                    .unwrap_or(config.scenario.gaze_deg),
            }
        })
        .collect();
    let view_of = |f: u64| views[(f as usize).min(views.len() - 1)];
    let mut out = Vec::new();
    for (model, fog) in models.iter().zip(fogs) {
        let setup = trial::TrialSetup {
            scenario: &config.scenario,
            statics,
            profile: views[0].profile,
            rof_keep: 1.0,
            regions: views[0].regions,
            model,
            driver_range_m: fog.mor_m,
            detection: config.detection,
            brute_force: config.brute_force,
            arrival: config.arrival,
            ego_yaw_deg: config.scenario.carla.ego_yaw_deg,
            gaze_deg: views[0].gaze_deg,
        };
        let (mut outcome, detected) = trial::run_trial_frames(&setup, d, &view_of);
        let fail_safe =
            |j: u64| frames[stream_of[(j as usize).min(n_frames - 1)]].state == State::FailSafe;
        outcome.fail_safe_frames = (0..outcome.frames).filter(|&j| fail_safe(j)).count() as u64;
        outcome.detected_in_fail_safe = detected.map(|f| f.map(fail_safe));
        out.push(outcome);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn behaviours_follow_their_definitions() {
        let scan = Behaviour::parse("scan:rate_hz=0.5,step_deg=90", 0.0).unwrap();
        // left 90, right −90, 2 steps each way: 4 fixations per 2 s cycle.
        let at = |t: f64| scan.target(t).unwrap();
        assert_eq!(
            [at(0.1), at(0.6), at(1.1), at(1.6), at(2.1)],
            [90.0, 0.0, -90.0, 0.0, 90.0]
        );
        let blink = Behaviour::parse("blink:every_s=2,blink_s=0.25", 45.0).unwrap();
        assert_eq!(blink.target(0.1), None);
        assert_eq!(blink.target(0.3), Some(45.0));
        assert_eq!(blink.target(-1.9), None, "periodic before 0 too");
        let mirror = Behaviour::parse("mirror", 90.0).unwrap();
        assert_eq!(mirror.target(0.5), Some(-25.0));
        assert_eq!(mirror.target(1.0), Some(90.0));
    }

    #[test]
    fn samples_move_at_saccade_speed_and_blinks_are_invalid() {
        let scan = Behaviour::parse("scan", 0.0).unwrap();
        let s = scan.samples(0.0, -1.0, 4.0);
        assert_eq!(s.len(), 1001);
        let step = SACCADE_DEG_S / SAMPLE_RATE_HZ;
        for w in s.windows(2) {
            assert!((w[1].gaze_deg - w[0].gaze_deg).abs() <= step + 1e-9);
        }
        let b = Behaviour::parse("blink", 90.0)
            .unwrap()
            .samples(0.0, 0.0, 4.0);
        let invalid = b.iter().filter(|s| !s.valid).count();
        // 0.15 s of 4 s at 200 Hz, twice (t = 0 and t = 4 both start a blink).
        assert!((30..=32).contains(&invalid), "{invalid}");
    }

    #[test]
    fn parse_names_the_bad_part() {
        for (spec, needle) in [
            ("wink", "'wink'"),
            ("scan:rate", "not key=value"),
            ("scan:rate_hz=x", "rate_hz"),
            ("scan:rate_hz=0", "rate_hz"),
            ("fixate:gaze_deg=1000", "gaze_deg"),
            ("mirror:glance_s=6", "glance_s"),
            ("blink:mirror_deg=3", "no parameter 'mirror_deg'"),
        ] {
            let e = Behaviour::parse(spec, 90.0).unwrap_err();
            assert!(e.contains(needle), "{spec}: {e}");
        }
    }

    #[test]
    fn a_trace_repeats_end_to_end() {
        let text = "t_s,gaze_deg,valid\n10.0,1,true\n10.5,2,true\n11.0,3,false\n";
        let t = Trace::parse(text, Format::Csv, "x").unwrap();
        assert_eq!(t.length_s(), 1.5);
        let s = t.samples(0.5, 0.0, 3.0);
        let times: Vec<f64> = s.iter().map(|s| s.t_s).collect();
        assert_eq!(times, [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]);
        let gaze: Vec<f64> = s.iter().map(|s| s.gaze_deg).collect();
        assert_eq!(gaze, [2.0, 3.0, 1.0, 2.0, 3.0, 1.0, 2.0]);
        assert!(!s[1].valid);
        let e = Trace::parse("t_s,gaze_deg\n", Format::Csv, "y").unwrap_err();
        assert!(e.to_string().contains("no samples"), "{e}");
        let e = Trace::parse("t_s,gaze_deg\n1,2\n0,2\n", Format::Csv, "z").unwrap_err();
        assert!(e.to_string().contains("decrease"), "{e}");
    }
}
