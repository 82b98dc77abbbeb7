//! Test fixtures and brute-force references shared by the integration tests
//! of this crate and of `gaze-lidar` (compiled only with the `testing`
//! feature, which only the two crates' dev-dependencies enable; no build
//! that certifies anything contains this module).
//!
//! - [`fixtures`]: the usual beam, sensor limits, uniform profiles, open
//!   firmware tables and segment lists the tests build their cases from,
//!   and the paths of the committed test data;
//! - [`reference`]: the slow, plain brute-force evaluator of the Class 1
//!   rules of a scanned beam, written independently of [`crate::eye_safety`]
//!   (it uses nothing of the crate but the profile@1 types it reads);
//! - [`eye_cases`]: the constructed eye-safety profiles of
//!   `tests/data/eye_safety/` with their true ratios worked out by hand.
//!
//! The references live here rather than in one test crate because both
//! crates' tests compare against them (the core's differential tests and
//! the CLI's `check` tests); one copy, reached by an ordinary path.

pub mod eye_cases;
pub mod fixtures;
pub mod reference;

pub use fixtures::*;
