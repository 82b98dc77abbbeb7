//! The parts of the model the trusted core needs: angles, circular sets and
//! cyclic index arithmetic ([`angle`]) and the sensor's limits ([`lidar`]).

pub mod accounting;
#[cfg(feature = "std")]
pub mod angle;
pub mod index;
#[cfg(feature = "std")]
pub mod lidar;
pub mod valid;

pub use accounting::PowerAccounting;
#[cfg(feature = "std")]
pub use angle::{Arc, Binning, CircularSet};
#[cfg(feature = "std")]
pub use lidar::{LidarSpec, Limits};
