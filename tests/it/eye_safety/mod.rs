//! Eye safety through the root crate: AEL figures, exposures, the head presets and the references on the planner's profiles.

mod figures;
mod head_findings;
mod head_looseness;
mod head_presets;
mod reference;
