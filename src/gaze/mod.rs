//! Gaze input and the real-time pipeline: formats ([`formats`]), filtering
//! ([`filter`]), the fail-safe state machine ([`failsafe`]) and the
//! frame-by-frame stream ([`stream`]).

pub mod failsafe;
pub mod filter;
pub mod formats;
pub mod stream;

pub use failsafe::{FailSafe, FailSafeConfig, State};
pub use filter::{FilterConfig, GazeFilter};
pub use formats::{Format, GazeSample, Parser};
pub use stream::{Frame, FramePlanner, GazeStream};

use crate::checker::CertifiedProfile;
use crate::model::presets::Preset;
use crate::planner::{closed_form, Mode};

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
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, String> {
        let mode = if gaze_deg.is_some() {
            self.mode
        } else {
            Mode::Baseline
        };
        closed_form(&self.preset, mode, gaze_deg, self.bins).map_err(|e| e.to_string())
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
    pub fn new(problem: crate::optimizer::Problem) -> Result<Self, String> {
        let preset = Preset {
            lidar: problem.lidar.clone(),
            focus: problem.focus.clone(),
            levels: crate::model::presets::AdaptiveLevels::paper(),
        };
        let baseline =
            closed_form(&preset, Mode::Baseline, None, problem.bins).map_err(|e| e.to_string())?;
        Ok(Self {
            fast: crate::optimizer::fast::FastPlanner::new(problem),
            baseline,
        })
    }
}

#[cfg(feature = "solver")]
impl FramePlanner for OptimizerPlanner {
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, String> {
        match gaze_deg {
            Some(g) => self.fast.plan(g).map_err(|e| e.to_string()),
            None => Ok(self.baseline.clone()),
        }
    }

    fn frame_rate_hz(&self) -> f64 {
        self.fast.problem().lidar.frame_rate_hz
    }
}
