//! The model of the paper (sections III–IV): angles and circular sets,
//! visual acuity and the driver's region of focus, the LiDAR and its limits,
//! presets.

pub mod acuity;
pub mod angle;
pub mod lidar;
pub mod presets;

pub use acuity::{AcuityModel, FocusModel, Regions};
pub use angle::{Arc, Binning, CircularSet};
pub use lidar::{LidarSpec, Limits, PowerAccounting};
pub use presets::{preset, Preset};
