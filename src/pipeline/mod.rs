//! The real-time pipeline: gaze input ([`crate::gaze`]) in, one certified
//! profile per LiDAR frame out. [`GazeStream`] runs the filter, the
//! fail-safe machine and the frame clock, and asks a [`FramePlanner`]
//! ([`ClosedFormPlanner`], or the optimizer's fast path) for each frame's
//! profile. `gaze-lidar stream`, `simulate --gaze`, `replay` and Python's
//! `GazeStream` all drive this one pipeline.

pub mod planners;
pub mod stream;

#[cfg(feature = "solver")]
pub use planners::OptimizerPlanner;
pub use planners::{ClosedFormPlanner, FramePlanner};
pub use stream::{
    Frame, GazeStream, Input, Notice, PipelineConfig, PipelineOptions, StreamConfig, StreamStats,
    LIVE_DRAIN_MAX,
};

use crate::gaze::GazeError;
use crate::planner::PlanError;

/// Why the pipeline stopped. [`PipelineError::is_input_error`] separates
/// bad input from an infeasible or rejected request and an output failure.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The gaze input is unusable.
    #[error(transparent)]
    Input(#[from] GazeError),
    /// The closed-form planner refused or failed.
    #[error("{0}")]
    Plan(#[from] PlanError),
    /// The optimizer refused or failed.
    #[cfg(feature = "solver")]
    #[error("{0}")]
    Optimizer(#[from] crate::optimizer::OptError),
    /// An argument is out of range.
    #[error("{field}: {reason}")]
    Config {
        /// Argument.
        field: &'static str,
        /// Why.
        reason: String,
    },
    /// Writing a frame failed.
    #[error("output: {0}")]
    Output(#[source] std::io::Error),
}

impl PipelineError {
    /// Bad input rather than infeasible, rejected or an output failure.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        match self {
            Self::Plan(e) => e.is_input_error(),
            #[cfg(feature = "solver")]
            Self::Optimizer(e) => e.is_input_error(),
            Self::Input(_) | Self::Config { .. } => true,
            Self::Output(_) => false,
        }
    }
}
