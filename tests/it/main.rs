//! The root crate's integration tests (library and binary): one binary, one
//! module per subject. A test of X goes in X's subject module (each opens with
//! a line saying what belongs there); a test that guards a fixed bug of the
//! command line goes in `regression`, citing what it guards. The fixtures
//! shared by several modules are the modules at the end; those shared with
//! the core's tests (and the brute-force eye-safety references) are
//! `gaze_lidar_core::testing`.

mod breakers;
mod checker;
mod cli_inputs;
mod eye_safety;
mod firmware;
mod layers;
mod optimizer;
mod regression;
#[cfg(feature = "cli")]
mod replay;
mod simulate;
mod stream;
mod traceability;

// Shared fixtures and independent re-computations.
#[path = "../../benches/common/big_profile.rs"]
mod big_profile;
mod common;
#[path = "../../crates/core/tests/it/head_oracle_defs.rs"]
mod head_oracle_defs;
mod independent;
mod mps;
