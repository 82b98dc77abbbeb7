//! Firmware tables (`gaze-lidar/firmware@1`): a certified profile quantized
//! to integer timer ticks and DAC power codes, with integer limits that the
//! [`check`] module re-verifies exactly.
//!
//! Quantization is exact and conservative:
//! - `frame_ticks = round(tick_hz / frame_rate_hz)`; each bin's dwell is its
//!   real dwell rounded up or down (so within one tick of it) and within the
//!   tick bounds implied by the spin limits, and the dwells sum to
//!   `frame_ticks` exactly ([`quantize::apportion`]);
//! - power codes are rounded down: never above the certified power, within
//!   one code of it (`quantize::floor_code`; a bin whose power lies within one
//!   code of `power_w_min` is raised to `power_code_min`, `power_w_min` rounded
//!   up to a code, so no bin runs below the minimum power: at most one code above
//!   its certified power, and the integer eye-safety check below decides on
//!   the table as it runs), then lowered further only if the
//!   table **as it will run** (quantized dwell, quantized codes) is over its
//!   energy budget as the integer checker reads it ([`lower_to_budget`]:
//!   rounding dwells to whole ticks can add a few code·ticks) or over the
//!   Class 1 limits in the integer eye-safety check ([`eye`]);
//! - the built table must pass [`check_table`] (integer rules and the
//!   integer eye-safety check) or no table is returned.
//!
//! Without `std` (feature off) this module keeps the table types, the
//! integer checker ([`check_integer`], [`check_table_with`] against integer
//! eye-safety limits derived on a host), [`apportion`] and the binary codec.
//!
//! Spin acceleration is a property of the float profile (certified there);
//! a table stores dwell per bin, and its eye safety is evaluated for each bin
//! swept at constant spin (`width_mdeg` in exactly `dwell_ticks`), which is
//! how the table runs: the motor controller must hold each bin's spin.

pub mod binary;
#[cfg(feature = "std")]
mod build;
pub mod check;
pub mod eye;
pub mod quantize;
#[cfg(feature = "std")]
pub mod sensor;

use alloc::string::String;
use alloc::vec::Vec;

use serde::{Deserialize, Serialize};

use crate::model::accounting::PowerAccounting;

#[cfg(feature = "std")]
pub use build::{
    as_run_segments, budget_weight_total, energy_budget, frame_ticks_for, table_exposure,
    FirmwareError,
};
pub use check::{check_header, check_integer, check_table_with, FwViolation, TICK_HZ_MAX};
#[cfg(feature = "std")]
pub use check::{check_table, check_table_evaluated};
pub use quantize::{apportion, lower_to_budget, QuantizeError, TickTarget};
#[cfg(feature = "std")]
pub use quantize::{ceil_code, floor_code};
#[cfg(feature = "std")]
pub use sensor::check_table_for_sensor;

/// The value of the `format` field.
pub const FIRMWARE_FORMAT: &str = "gaze-lidar/firmware@1";
/// A full turn in millidegrees (Ouster's `azimuth_window` unit).
pub const FULL_TURN_MDEG: u32 = 360_000;
/// Most bins a table may have.
pub const MAX_TABLE_BINS: usize = 36_000;

/// Quantization settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FirmwareConfig {
    /// Timer frequency, Hz (e.g. an 80 MHz timer).
    pub tick_hz: u64,
    /// DAC step, W per code; `None`: `power_w_max / 4095` (a 12-bit DAC).
    pub power_w_per_code: Option<f64>,
}

impl Default for FirmwareConfig {
    fn default() -> Self {
        Self {
            tick_hz: 80_000_000,
            power_w_per_code: None,
        }
    }
}

/// Integer limits of a table.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntLimits {
    /// `ceil(power_w_min·(1 − REL_TOL) / step)`: no bin runs below the
    /// minimum power (within the checker's tolerance).
    pub power_code_min: u32,
    /// `floor(power_w_max / step)`.
    pub power_code_max: u32,
    /// Energy budget: `Σ code·ticks` (time accounting) or `Σ code·width_mdeg`
    /// (angle accounting) must not exceed it.
    pub energy_budget: u64,
    /// Consecutive bins that cover any aperture pass (eye safety).
    pub window_bins: u32,
    /// Largest `Σ code·ticks` over any `window_bins` consecutive bins.
    pub window_energy_max: u64,
}

/// One bin of a table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FwBin {
    /// Start azimuth, degrees (informational).
    pub start_deg: f64,
    /// Width in millidegrees (Σ = 360,000).
    pub width_mdeg: u32,
    /// Dwell, timer ticks.
    pub dwell_ticks: u64,
    /// DAC power code.
    pub power_code: u32,
    /// Smallest dwell the spin limit allows, ticks.
    pub dwell_ticks_min: u64,
    /// Largest dwell the spin limit allows, ticks.
    pub dwell_ticks_max: u64,
    /// Largest code this bin may hold: `power_code_max`, and the integer
    /// eye-safety check's rule-1 limit on every surface (`eye::IntEyeLimits::pulse_code_cap`).
    pub power_code_cap: u32,
}

/// A firmware table, `gaze-lidar/firmware@1`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FirmwareTable {
    /// [`FIRMWARE_FORMAT`].
    pub format: String,
    /// Timer frequency, Hz.
    pub tick_hz: u64,
    /// Ticks per revolution.
    pub frame_ticks: u64,
    /// DAC step, W per code.
    pub power_w_per_code: f64,
    /// Accounting of the energy budget.
    pub power_accounting: PowerAccounting,
    /// Laser firing rate, Hz (eye safety of the table as it runs).
    #[serde(default)]
    pub pulse_rate_hz: f64,
    /// Laser and optics parameters; a table without them is not Class 1
    /// evidence and fails [`check_table`].
    #[serde(default)]
    pub eye_safety: Option<crate::eye_safety::EyeSafetyParams>,
    /// Integer limits.
    pub limits: IntLimits,
    /// Bins in azimuth order.
    pub bins: Vec<FwBin>,
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::{cover, for_all};

    /// REQ-FW-1: whatever the quantizer returns passes the integer checker's
    /// frame and dwell rules (quantizer and checker agree).
    #[cfg_attr(kani, kani::proof, kani::unwind(6))]
    #[cfg_attr(not(kani), test)]
    fn quantizer_output_passes_integer_frame_and_dwell_checks() {
        for_all!(([(u8, u8, u8, u8); 4], u8, u16, bool), |(
            raw,
            n,
            total,
            shaped,
        )| {
            let n = 1 + usize::from(n % 4);
            let (targets, frame_ticks) =
                quantize::verification::targets_and_total(&raw[..n], total, shaped);
            let Ok(ticks) = apportion(&targets, frame_ticks) else {
                return;
            };
            cover!(true, "apportioned table checked");
            let bins = targets
                .iter()
                .zip(&ticks)
                .enumerate()
                .map(|(i, (t, &d))| FwBin {
                    start_deg: 0.0,
                    width_mdeg: if i == 0 { FULL_TURN_MDEG } else { 0 },
                    dwell_ticks: d,
                    power_code: 0,
                    dwell_ticks_min: t.min,
                    dwell_ticks_max: t.max,
                    power_code_cap: 0,
                })
                .collect();
            let table = FirmwareTable {
                format: FIRMWARE_FORMAT.to_owned(),
                tick_hz: 1,
                frame_ticks,
                power_w_per_code: 1.0,
                power_accounting: PowerAccounting::Time,
                pulse_rate_hz: 0.0,
                eye_safety: None,
                limits: IntLimits {
                    power_code_min: 0,
                    power_code_max: 0,
                    energy_budget: 0,
                    window_bins: 1,
                    window_energy_max: 0,
                },
                bins,
            };
            assert!(
                check_integer(&table).is_empty(),
                "{:?}",
                check_integer(&table)
            );
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["apportioned table checked"]);
    }
}
