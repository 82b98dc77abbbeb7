//! The model of the paper (sections III–IV): angles and circular sets,
//! visual acuity and the driver's region of focus, the LiDAR and its limits,
//! presets, the range equation and the return models. Angles and the LiDAR's limits belong to the trusted core
//! ([`gaze_lidar_core::model`]) and are re-exported here.

pub mod acuity;
pub use gaze_lidar_core::model::{angle, lidar, valid};
pub mod mode;
pub mod presets;
pub mod range;
pub mod returns;
pub mod sensor;

pub use acuity::{AcuityModel, FocusModel, Regions};
pub use angle::{Arc, Binning, CircularSet};
pub use lidar::{LidarSpec, Limits, PowerAccounting};
pub use mode::Mode;
pub use presets::{preset, Preset};
