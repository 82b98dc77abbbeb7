//! An optimum's figures (`optimality.figures`) against the paper's closed
//! form on the same sensor, driver model and bin count. Here, not in
//! `planner`, so that `planner` never reaches up into `optimizer`.

use crate::checker::CertifiedProfile;
use crate::model::presets::Preset;

/// The paper's closed forms on `problem`'s sensor and driver model with
/// `levels` (the preset's the configuration names): what an optimum's
/// figures are compared with.
#[must_use]
pub fn closed_form_basis(
    problem: &super::Problem,
    levels: crate::model::presets::AdaptiveLevels,
) -> Preset {
    Preset {
        lidar: problem.lidar.clone(),
        focus: problem.focus.clone(),
        levels,
    }
}

/// [`crate::planner::figures::attach`] for an optimum of `problem`: compared with the closed form
/// of its mode on its sensor, driver model and bin count.
#[must_use]
pub fn attach_to_optimum(
    certified: CertifiedProfile,
    problem: &super::Problem,
    levels: crate::model::presets::AdaptiveLevels,
) -> CertifiedProfile {
    crate::planner::figures::attach(
        certified,
        &closed_form_basis(problem, levels),
        problem.objective.mode,
        problem.bins,
    )
}
