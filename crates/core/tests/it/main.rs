//! The core's integration tests: one binary, one module per subject. A test
//! of X goes in X's subject module (each opens with a line saying what
//! belongs there); the fixtures and brute-force references it shares with
//! other modules are the modules at the end (fixtures and references both
//! crates' tests share are in `gaze_lidar_core::testing`).

mod checker;
mod eye_safety;
mod firmware;
mod mutant_kills;
mod mutant_kills_head_bound;
mod mutant_kills_head_bound2;
mod profile;

// Definitions references only this crate's tests use.
mod head_oracle_defs;
mod reference_defs;
