//! Planners turn a gaze into a certified profile. [`closed_form`] implements
//! the paper's two-level controllers (eq. 3–6).

pub mod closed_form;
pub mod figures;

use thiserror::Error;

use crate::checker::Rejected;
use crate::model::acuity::AcuityError;
use crate::model::angle::AngleError;

pub use closed_form::closed_form;

/// Which controller (moved to [`crate::model::mode`]; re-exported here so
/// callers keep `planner::Mode`).
pub use crate::model::mode::Mode;

/// Why a planner could not produce a certified profile.
#[derive(Debug, Error)]
pub enum PlanError {
    /// The request itself is malformed (bad argument).
    #[error("{field}: {reason}")]
    InvalidInput {
        /// The argument or config key.
        field: &'static str,
        /// What is wrong.
        reason: String,
    },
    /// The request is well-formed but cannot be met.
    #[error("infeasible: {0}")]
    Infeasible(String),
    /// The planned profile failed the checker: never handed out.
    #[error("the planned profile violates its limits: {}", crate::checker::summarize_list(&.0.violations))]
    Rejected(#[from] Rejected),
}

impl From<AngleError> for PlanError {
    fn from(e: AngleError) -> Self {
        Self::InvalidInput {
            field: "bins",
            reason: e.to_string(),
        }
    }
}

impl From<AcuityError> for PlanError {
    fn from(e: AcuityError) -> Self {
        Self::InvalidInput {
            field: "acuity",
            reason: e.to_string(),
        }
    }
}

impl PlanError {
    /// Whether the fault is in the input rather than infeasibility.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        matches!(self, Self::InvalidInput { .. })
    }
}

pub use crate::model::acuity::MAX_ABS_GAZE_DEG;

/// Validates a gaze angle argument.
pub fn validate_gaze(gaze_deg: f64) -> Result<(), PlanError> {
    if !gaze_deg.is_finite() || gaze_deg.abs() > MAX_ABS_GAZE_DEG {
        return Err(PlanError::InvalidInput {
            field: "gaze-deg",
            reason: format!(
                "{gaze_deg:e} is not a finite azimuth within ±{MAX_ABS_GAZE_DEG} degrees"
            ),
        });
    }
    Ok(())
}
