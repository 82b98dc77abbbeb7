//! Certifying profiles through the library and the binary: the closed-form profiles, their properties and their timelines.

mod closed_form_profiles;
mod kinematics;
mod properties;
