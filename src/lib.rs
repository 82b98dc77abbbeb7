//! # gaze-lidar
//!
//! Turns a driver's gaze into a **certified scan schedule** for a spinning
//! LiDAR: an azimuthal profile of laser power (range) and spin rate
//! (resolution) that moves the sensor's budget to where the driver is *not*
//! looking, while staying inside the power budget, the frame rate, the
//! hardware limits and the eye-safety limits (Scarì et al., "Hybrid
//! Human-Machine Perception via Adaptive LiDAR for ADAS").
//!
//! The trusted core — profile and firmware types, limits, the eye-safety
//! model, the checker and the integer firmware code — is the separate crate
//! [`gaze_lidar_core`], re-exported here; everything in this crate depends on
//! it and it depends on nothing here.
//!
//! Data flows one way:
//! gaze → [`model`] (regions) → [`planner`] → [`profile`] → [`checker`]
//! (certify, with [`eye_safety`]) → outputs. In real time, [`gaze`] (pure
//! input: formats, filter, fail-safe) feeds [`pipeline`], which asks a
//! planner for each frame's certified profile.
//!
//! ```
//! use gaze_lidar::model::presets;
//! use gaze_lidar::planner::{closed_form, Mode};
//!
//! // The paper's LiDAR, driver looking left (90°), range control, 360 bins.
//! let preset = presets::paper();
//! let certified = closed_form(&preset, Mode::Range, Some(90.0), 360).unwrap();
//! let s = certified.summary();
//! // Eq. 4: a 60° region of focus at half power leaves 1.1 × P̄ for the rest.
//! assert!((s.power_w_range[1] / preset.lidar.average_power_w - 1.1).abs() < 1e-9);
//! assert!((s.average_power_angle_w - preset.lidar.average_power_w).abs() < 1e-15);
//! let json = certified.profile().to_json().unwrap();
//! assert!(json.contains("gaze-lidar/profile@1"));
//! ```

#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use gaze_lidar_core::{checker, eye_safety, firmware};
pub mod gaze;
pub mod model;
pub mod names;
#[cfg(feature = "solver")]
pub mod optimizer;
pub mod pipeline;
pub mod planner;
pub mod pointcloud;
pub mod profile;
#[cfg(feature = "replay")]
pub mod replay;
pub mod sim;
pub mod text;
#[cfg(any(test, kani))]
pub(crate) use gaze_lidar_core::verification;

/// The README's examples, compiled and run as doctests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
