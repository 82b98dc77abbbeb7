//! What turns a gaze into a frame's certified profile: the [`FramePlanner`]
//! trait, the paper's closed forms ([`ClosedFormPlanner`]) and the
//! optimizer's fast path (`OptimizerPlanner`, with the `solver` feature).
//! Both plan the uniform baseline when there is no gaze (fail-safe).

use super::PipelineError;
use crate::checker::CertifiedProfile;
use crate::model::presets::Preset;
use crate::planner::{closed_form, Mode};

/// Something that turns a gaze (or none: fail-safe) into a certified profile.
pub trait FramePlanner {
    /// The profile for `gaze_deg`; `None` asks for the uniform baseline.
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, PipelineError>;
    /// Nominal frame rate, Hz.
    fn frame_rate_hz(&self) -> f64;
}

impl<P: FramePlanner + ?Sized> FramePlanner for Box<P> {
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, PipelineError> {
        (**self).plan(gaze_deg)
    }
    fn frame_rate_hz(&self) -> f64 {
        (**self).frame_rate_hz()
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
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, PipelineError> {
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
    pub fn new(problem: crate::optimizer::Problem) -> Result<Self, PipelineError> {
        let preset = crate::optimizer::figures::closed_form_basis(
            &problem,
            crate::model::presets::AdaptiveLevels::paper(),
        );
        let baseline = closed_form(&preset, Mode::Baseline, None, problem.bins)?;
        Ok(Self {
            fast: crate::optimizer::fast::FastPlanner::new(problem),
            baseline,
        })
    }
}

#[cfg(feature = "solver")]
impl FramePlanner for OptimizerPlanner {
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, PipelineError> {
        match gaze_deg {
            Some(g) => Ok(self.fast.plan(g)?),
            None => Ok(self.baseline.clone()),
        }
    }

    fn frame_rate_hz(&self) -> f64 {
        self.fast.problem().lidar.frame_rate_hz
    }
}
