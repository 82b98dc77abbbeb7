//! The gaze pipeline's options, shared by `stream` and `replay`: the planner
//! that turns a fixation into a certified profile (`--preset`, `--mode`,
//! `--bins`, `--config`) and the filter and fail-safe settings.

use std::path::{Path, PathBuf};

use gaze_lidar::model::angle::{MAX_BINS, MIN_BINS};
use gaze_lidar::model::presets;
use gaze_lidar::pipeline::{
    ClosedFormPlanner, FramePlanner, PipelineConfig, PipelineError, PipelineOptions,
};
use gaze_lidar::planner::Mode;

use super::args::int_in;
use super::CliError;

/// Which planner decides each frame's profile.
#[derive(Debug, clap::Args)]
pub struct PlanArgs {
    /// LiDAR preset (closed-form controllers) [default: paper]; with
    /// --config, replaces the file's `[lidar] preset`.
    #[arg(long)]
    pub preset: Option<String>,
    /// Controller for the closed form (default range); with --config, replaces the file's objective mode.
    #[arg(long, value_parser = super::args::named::<Mode>())]
    pub mode: Option<Mode>,
    /// Equal bins (4..=36000; with --config 4..=1440) [default: 360, or the
    /// --config file's].
    #[arg(long, allow_hyphen_values = true)]
    pub bins: Option<i64>,
    /// Optimizer configuration (TOML): plan with the optimizer's fast path.
    /// --preset, --bins and --mode given with it replace the file's values.
    #[arg(long)]
    pub config: Option<PathBuf>,
}

/// The gaze filter, the fail-safe and the frame clock's gap rule.
#[derive(Debug, clap::Args)]
pub struct FilterArgs {
    /// A fixation older than this when a frame is decided is stale (fail-safe), ms (0 < T < 1e7).
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    pub timeout_ms: f64,
    /// Consecutive valid samples needed to leave fail-safe (1..=100000).
    #[arg(long, default_value_t = 4, allow_hyphen_values = true)]
    pub recover_samples: i64,
    /// I-VT saccade threshold, °/s (0 < v < 1e6).
    #[arg(long, default_value_t = 30.0, allow_hyphen_values = true)]
    pub saccade_deg_s: f64,
    /// A gaze timestamp jump making more than this many frames (plus the one
    /// at the sample) due at once emits one fail-safe frame, a warning, and
    /// restarts the frame clock (0..=1000000). `stream --realtime --input`:
    /// a gap longer than this many frames (plus one) in the file is not
    /// waited for.
    #[arg(long, default_value_t = 200, allow_hyphen_values = true)]
    pub max_gap_frames: i64,
}

impl FilterArgs {
    /// Every option through its range check.
    pub fn settings(&self) -> Result<PipelineConfig, CliError> {
        PipelineOptions {
            timeout_ms: self.timeout_ms,
            saccade_deg_s: self.saccade_deg_s,
            recover_samples: self.recover_samples,
            max_gap_frames: self.max_gap_frames,
        }
        .config()
        .map_err(gaze_error)
    }
}

impl PlanArgs {
    /// `--bins`, range-checked (with `--config` the optimizer's range
    /// applies, checked with the file).
    fn bins(&self) -> Result<Option<usize>, CliError> {
        Ok(match self.bins {
            Some(b) if self.config.is_some() => Some(int_in("--bins", b, 0, i64::MAX)?),
            Some(b) => Some(int_in("--bins", b, MIN_BINS as i64, MAX_BINS as i64)?),
            None => None,
        })
    }

    /// The planner and the rated range of its sensor, m.
    pub fn planner(&self) -> Result<(Box<dyn FramePlanner>, f64), CliError> {
        let bins = self.bins()?;
        if let Some(path) = &self.config {
            return self.optimizer_planner(bins, path);
        }
        let preset = presets::preset(self.preset.as_deref().unwrap_or("paper"))
            .map_err(|e| CliError::input(format!("--preset: {e}")))?;
        let rated = preset.lidar.rated_range_m;
        Ok((
            Box::new(ClosedFormPlanner {
                preset,
                mode: self.mode.unwrap_or(Mode::Range),
                bins: bins.unwrap_or(360),
            }),
            rated,
        ))
    }

    #[cfg(feature = "solver")]
    fn optimizer_planner(
        &self,
        bins: Option<usize>,
        path: &Path,
    ) -> Result<(Box<dyn FramePlanner>, f64), CliError> {
        let overrides = super::config::Overrides {
            preset: self.preset.as_deref(),
            bins,
            accounting: None,
            mode: self.mode,
        };
        let problem = super::config::optimizer_problem(path, &overrides)?;
        let rated = problem.lidar.rated_range_m;
        let p = gaze_lidar::pipeline::OptimizerPlanner::new(problem).map_err(gaze_error)?;
        Ok((Box::new(p), rated))
    }

    #[cfg(not(feature = "solver"))]
    fn optimizer_planner(
        &self,
        _bins: Option<usize>,
        _path: &Path,
    ) -> Result<(Box<dyn FramePlanner>, f64), CliError> {
        Err(super::config::no_solver("--config"))
    }
}

/// A gaze pipeline error: bad input (exit 2) or infeasible (exit 1); a
/// setting is named by its flag.
pub fn gaze_error(e: impl Into<PipelineError>) -> CliError {
    let e = e.into();
    if let PipelineError::Config { field, reason } = &e {
        return CliError::input(format!("--{}: {reason}", field.replace('_', "-")));
    }
    if e.is_input_error() {
        CliError::input(e.to_string())
    } else {
        CliError::infeasible(e.to_string())
    }
}
