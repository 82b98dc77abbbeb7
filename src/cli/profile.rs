//! `gaze-lidar profile`: build a certified profile.

use clap::ValueEnum;
use std::path::PathBuf;

use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};

use gaze_lidar::firmware::{binary, FirmwareConfig, FirmwareError, FirmwareTable};

use super::{emit_bytes, CliError};

/// Output format of a profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// `gaze-lidar/profile@1` JSON.
    Json,
    /// One row per bin.
    Csv,
    /// `gaze-lidar/firmware@1` JSON: integer ticks and DAC codes.
    Firmware,
    /// The firmware table's fixed-size binary encoding (needs --out).
    FirmwareBin,
}

/// Accounting override.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Accounting {
    /// Energy per frame / frame period.
    Time,
    /// Eq. 4 as printed: average over angle.
    Angle,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// LiDAR preset: paper, vls128.
    #[arg(long, default_value = "paper")]
    preset: String,
    /// Controller: the paper's closed forms.
    #[arg(long, value_enum, default_value_t = Mode::Range)]
    mode: Mode,
    /// Gaze azimuth, degrees CCW from straight ahead (ISO 8855). Omit for the baseline.
    #[arg(long, allow_negative_numbers = true)]
    gaze_deg: Option<f64>,
    /// Number of equal bins (4..=36000); region boundaries are added as edges.
    #[arg(long, default_value_t = 360, allow_negative_numbers = true)]
    bins: usize,
    /// Override the preset's power accounting.
    #[arg(long, value_enum)]
    accounting: Option<Accounting>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Json)]
    format: Format,
    /// Write to this file (atomically) instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Firmware timer frequency, Hz.
    #[arg(long, default_value_t = 80_000_000)]
    tick_hz: u64,
    /// Firmware DAC step, W per code (default: power_w_max / 4095).
    #[arg(long)]
    power_w_per_code: Option<f64>,
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let mut preset =
        presets::preset(&a.preset).map_err(|e| CliError::input(format!("--preset: {e}")))?;
    if let Some(acc) = a.accounting {
        preset.lidar.power_accounting = match acc {
            Accounting::Time => PowerAccounting::Time,
            Accounting::Angle => PowerAccounting::Angle,
        };
    }
    if a.gaze_deg.is_none() && a.mode != Mode::Baseline {
        return Err(CliError::input(format!(
            "--gaze-deg is required for --mode {}",
            a.mode.name()
        )));
    }
    let gaze = if a.mode == Mode::Baseline {
        None
    } else {
        a.gaze_deg
    };
    if let Some(g) = a.gaze_deg {
        gaze_lidar::planner::validate_gaze(g).map_err(|e| CliError::input(format!("--{e}")))?;
    }
    let certified = closed_form(&preset, a.mode, gaze, a.bins).map_err(|e| match e {
        gaze_lidar::planner::PlanError::InvalidInput { field, reason } => {
            CliError::input(format!("--{field}: {reason}"))
        }
        other => CliError::from(other),
    })?;
    let firmware = || {
        let cfg = FirmwareConfig {
            tick_hz: a.tick_hz,
            power_w_per_code: a.power_w_per_code,
        };
        FirmwareTable::from_certified(&certified, &cfg).map_err(|e| match e {
            FirmwareError::Config { .. } => CliError::input(format!("firmware: {e}")),
            other => CliError::infeasible(format!("firmware: {other}")),
        })
    };
    let bytes = match a.format {
        Format::Json => certified.profile().to_json()?.into_bytes(),
        Format::Csv => certified.profile().to_csv()?.into_bytes(),
        Format::Firmware => firmware()?
            .to_json()
            .map_err(|e| CliError::input(e.to_string()))?
            .into_bytes(),
        Format::FirmwareBin => {
            if a.out.is_none() {
                return Err(CliError::input(
                    "--format firmware-bin writes binary: give --out FILE",
                ));
            }
            binary::encode(&firmware()?)
        }
    };
    emit_bytes(&bytes, a.out.as_deref())?;
    Ok(0)
}
