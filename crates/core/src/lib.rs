//! # gaze-lidar-core — the trusted core of gaze-lidar
//!
//! Everything that decides whether a scan profile or a firmware table may
//! run on a laser, and nothing else:
//!
//! - [`model`]: circular index and angle arithmetic ([`model::angle`]), the
//!   sensor's limits and power accounting ([`model::lidar`]);
//! - [`profile`]: the `gaze-lidar/profile@1` types and their exact kinematics;
//! - [`eye_safety`]: **the one eye-safety model** — IEC 60825-1:2014 Class 1
//!   AEL tables and a sound upper bound of the exposure of a scanned beam;
//! - [`checker`]: certification of a profile against its declared limits or
//!   against a sensor's own limits ([`checker::certify_for_sensor`]);
//! - [`firmware`]: the integer firmware table (`gaze-lidar/firmware@1`), its
//!   conservative quantizer, its integer checker (eye safety evaluated on the
//!   quantized table itself) and its binary codec.
//!
//! No solver, no CLI, no plotting: a vendor who wants the checker compiles
//! this crate and its three dependencies (serde, thiserror, serde_json behind
//! the `json` feature). The planner, optimizer, gaze pipeline, simulator and
//! CLI live in the `gaze-lidar` crate, which depends on this one.
//!
//! Features: `std` (everything but the integer firmware checker and codec),
//! `json` (profile@1 and firmware@1 files) and `optimizer` (`eye_safety::cuts`,
//! the linear constraints the optimizer builds from the bound); all on by
//! default. A vendor who only certifies takes `default-features = false,
//! features = ["json"]`; without `std` the firmware checker builds `no_std`.
//! A fourth feature, `testing`, off by default and enabled only by the
//! tests' dev-dependencies, adds the shared test fixtures and brute-force
//! references (`testing`); no certifying build contains them.
//!
//! ## Start here
//!
//! A vendor needs the names re-exported at this root: read a profile
//! ([`Profile`], e.g. `Profile::from_json` with the `json` feature), describe
//! the sensor ([`LidarSpec`]), and certify: [`certify`] against the
//! profile's own declared limits, [`certify_for_sensor`] against a sensor's
//! limits, [`certify_with`] with [`CheckOptions`]. Success is a
//! [`CertifiedProfile`] (only the checker can build one); failure is
//! [`Rejected`], listing every [`Violation`] and, for eye safety, the
//! binding [`Rule`] and the [`ExposureReport`] it rests on. [`Verdict`]
//! is either outcome as serialisable data (what `gaze-lidar check --format
//! json` prints and Python's `Verdict` holds), built with `Verdict::of`.
//!
//! Proofs: Kani harnesses live beside the code they verify (`mod
//! verification` in each module); every harness body also runs as a test.
//! They are machine-checked only where Kani is installed (see
//! `specs/verification.md`).

#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

extern crate alloc;

#[cfg(feature = "std")]
pub mod checker;
pub mod eye_safety;
pub mod firmware;
pub mod model;
#[cfg(feature = "std")]
pub mod profile;
#[cfg(feature = "testing")]
pub mod testing;
pub mod text;
#[doc(hidden)]
pub mod verification;

#[cfg(feature = "std")]
pub use checker::{
    certify, certify_for_sensor, certify_with, CertifiedProfile, CheckOptions, Rejected, Verdict,
    Violation,
};
pub use eye_safety::rule::Rule;
#[cfg(feature = "std")]
pub use eye_safety::ExposureReport;
#[cfg(feature = "std")]
pub use model::lidar::LidarSpec;
#[cfg(feature = "std")]
pub use profile::Profile;
