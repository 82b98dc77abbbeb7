//! The eye-safety model (`eye_safety::*`): AEL tables, exposures, the bound and the head, the cuts, their brute-force references and frozen figures.

mod ael;
mod band_edges;
mod break_beam;
mod break_head;
mod break_sphere;
#[cfg(feature = "optimizer")]
mod cuts;
#[cfg(feature = "optimizer")]
mod cuts_adversarial;
#[cfg(feature = "optimizer")]
mod cuts_reference;
mod exposure;
mod head;
mod head_figures_golden;
mod head_oracle;
pub(crate) mod head_reference;
mod head_surface;
mod open_readings;
mod reference;
mod report;
mod time_rounding;
