//! The core's integration tests: one binary, one module per subject. A test
//! of X goes in X's subject module (each opens with a line saying what
//! belongs there); the fixtures and brute-force references it shares with
//! other modules are the modules at the end.

mod checker;
mod eye_safety;
mod firmware;
mod mutant_kills;
mod profile;

// Shared fixtures and brute-force references.
mod common;
mod eye_cases;
mod head_oracle_defs;
mod reference;
mod reference_defs;
