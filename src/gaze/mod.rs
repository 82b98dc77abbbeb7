//! Gaze input and the real-time pipeline: formats ([`formats`]), filtering
//! ([`filter`]), the fail-safe state machine ([`failsafe`]) and the
//! frame-by-frame stream ([`stream`]).

pub mod failsafe;
pub mod filter;
pub mod formats;
pub mod stream;

pub use failsafe::{Due, FailSafe, FailSafeConfig, FrameClock, SampleKind, State};
pub use filter::{FilterConfig, GazeFilter};
pub use formats::{Format, GazeSample, LineError, Parser};
pub use stream::{
    Frame, FramePlanner, GazeStream, Input, Notice, PipelineConfig, StreamConfig, StreamStats,
};

use crate::checker::CertifiedProfile;
use crate::model::presets::Preset;
use crate::planner::{closed_form, Mode, PlanError};

/// Why the gaze pipeline stopped. [`GazeError::is_input_error`] separates bad
/// input (exit 2) from an infeasible or rejected request (exit 1), as
/// everywhere else in the crate.
#[derive(Debug, thiserror::Error)]
pub enum GazeError {
    /// The closed-form planner refused or failed.
    #[error("{0}")]
    Plan(#[from] PlanError),
    /// The optimizer refused or failed.
    #[cfg(feature = "solver")]
    #[error("{0}")]
    Optimizer(#[from] crate::optimizer::OptError),
    /// A malformed line in a recorded file (`origin:line: field …`).
    #[error("{origin}:{line}: {source}")]
    Line {
        /// File name or `<stdin>`.
        origin: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        source: LineError,
    },
    /// The input could not be read.
    #[error("{origin}:{line}: {source}")]
    Read {
        /// File name or `<stdin>`.
        origin: String,
        /// 1-based line number.
        line: usize,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A setting is out of range.
    #[error("{field}: {reason}")]
    Config {
        /// Option or key.
        field: &'static str,
        /// Why.
        reason: String,
    },
    /// Writing a frame failed.
    #[error("output: {0}")]
    Output(#[source] std::io::Error),
}

impl GazeError {
    /// Bad input (exit 2) rather than infeasible, rejected or an output
    /// failure (exit 1).
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        match self {
            Self::Plan(e) => e.is_input_error(),
            #[cfg(feature = "solver")]
            Self::Optimizer(e) => e.is_input_error(),
            Self::Line { .. } | Self::Read { .. } | Self::Config { .. } => true,
            Self::Output(_) => false,
        }
    }
}

/// The paper's closed forms as a frame planner (baseline in fail-safe).
#[derive(Debug, Clone)]
pub struct ClosedFormPlanner {
    /// Preset.
    pub preset: Preset,
    /// Controller.
    pub mode: Mode,
    /// Bins.
    pub bins: usize,
}

impl FramePlanner for ClosedFormPlanner {
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, GazeError> {
        let mode = if gaze_deg.is_some() {
            self.mode
        } else {
            Mode::Baseline
        };
        Ok(closed_form(&self.preset, mode, gaze_deg, self.bins)?)
    }

    fn frame_rate_hz(&self) -> f64 {
        self.preset.lidar.frame_rate_hz
    }
}

/// The optimizer's fast path as a frame planner (baseline in fail-safe).
#[cfg(feature = "solver")]
pub struct OptimizerPlanner {
    /// The cached planner.
    pub fast: crate::optimizer::fast::FastPlanner,
    /// Baseline profile (computed once).
    pub baseline: CertifiedProfile,
}

#[cfg(feature = "solver")]
impl OptimizerPlanner {
    /// Wraps a problem.
    pub fn new(problem: crate::optimizer::Problem) -> Result<Self, GazeError> {
        let preset = Preset {
            lidar: problem.lidar.clone(),
            focus: problem.focus.clone(),
            levels: crate::model::presets::AdaptiveLevels::paper(),
        };
        let baseline = closed_form(&preset, Mode::Baseline, None, problem.bins)?;
        Ok(Self {
            fast: crate::optimizer::fast::FastPlanner::new(problem),
            baseline,
        })
    }
}

#[cfg(feature = "solver")]
impl FramePlanner for OptimizerPlanner {
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, GazeError> {
        match gaze_deg {
            Some(g) => Ok(self.fast.plan(g)?),
            None => Ok(self.baseline.clone()),
        }
    }

    fn frame_rate_hz(&self) -> f64 {
        self.fast.problem().lidar.frame_rate_hz
    }
}
