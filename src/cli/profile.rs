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
    /// Controller: the paper's closed forms (default range); with --optimize
    /// or --config, the optimizer's objective mode.
    #[arg(long, value_enum)]
    mode: Option<Mode>,
    /// Derive the profile with the optimizer (HiGHS) instead of the closed form;
    /// with a preset: its paper-equivalent problem (two power levels, two spin set-points).
    #[arg(long)]
    optimize: bool,
    /// Optimizer configuration (TOML); implies --optimize.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Gaze azimuth, degrees CCW from straight ahead (ISO 8855). Omit for the baseline.
    #[arg(long, allow_hyphen_values = true)]
    gaze_deg: Option<f64>,
    /// Number of equal bins (4..=36000; with the optimizer 4..=1440); region boundaries are added as edges.
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
    #[arg(long, default_value_t = 80_000_000, allow_negative_numbers = true)]
    tick_hz: u64,
    /// Firmware DAC step, W per code (default: power_w_max / 4095).
    #[arg(long, allow_hyphen_values = true)]
    power_w_per_code: Option<f64>,
    /// With the optimizer: write the final power step's program to
    /// DIR/problem.mps (free MPS) and its exact certificate to
    /// DIR/certificate.json (created if missing; all files or none).
    #[arg(long, value_name = "DIR")]
    certificate: Option<PathBuf>,
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
    let mode = a.mode.unwrap_or(Mode::Range);
    if a.gaze_deg.is_none() && mode != Mode::Baseline {
        return Err(CliError::input(format!(
            "--gaze-deg is required for --mode {}",
            mode.name()
        )));
    }
    let gaze = if mode == Mode::Baseline {
        None
    } else {
        a.gaze_deg
    };
    if let Some(g) = a.gaze_deg {
        gaze_lidar::planner::validate_gaze(g).map_err(|e| CliError::input(format!("--{e}")))?;
    }
    if a.certificate.is_some() && !(a.optimize || a.config.is_some()) {
        return Err(CliError::input(
            "--certificate: only the optimizer (--optimize or --config) solves a program to certify",
        ));
    }
    let mut extra = Vec::new();
    let certified = if a.optimize || a.config.is_some() {
        let (c, cert) = optimized(a, &preset, gaze)?;
        if let Some(dir) = &a.certificate {
            extra = certificate_files(dir, cert)?;
        }
        c
    } else {
        closed_form(&preset, mode, gaze, a.bins).map_err(|e| match e {
            gaze_lidar::planner::PlanError::InvalidInput { field, reason } => {
                CliError::input(format!("--{field}: {reason}"))
            }
            other => CliError::from(other),
        })?
    };
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
        Format::Csv => gaze_lidar::profile::to_csv(certified.profile())?.into_bytes(),
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
    if extra.is_empty() {
        emit_bytes(&bytes, a.out.as_deref())?;
    } else {
        let mut outs = super::io::Outputs::default();
        for (path, b) in extra {
            outs.add(&path, b);
        }
        if let Some(out) = &a.out {
            outs.add(out, bytes.clone());
        }
        outs.commit()?;
        if a.out.is_none() {
            emit_bytes(&bytes, None)?;
        }
    }
    Ok(0)
}

/// `DIR/problem.mps` and `DIR/certificate.json` (the directory is created).
#[cfg(feature = "solver")]
fn certificate_files(
    dir: &std::path::Path,
    cert: Result<gaze_lidar::optimizer::certificate::Certified, String>,
) -> Result<Vec<(PathBuf, Vec<u8>)>, CliError> {
    let cert = cert.map_err(|e| CliError::input(format!("--certificate: {e}")))?;
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::output(format!("--certificate {}: {e}", dir.display())))?;
    let json = serde_json::to_string_pretty(&cert.file())
        .map_err(|e| CliError::output(format!("certificate.json: {e}")))?;
    Ok(vec![
        (dir.join("problem.mps"), cert.lp.to_mps().into_bytes()),
        (dir.join("certificate.json"), (json + "\n").into_bytes()),
    ])
}

#[cfg(not(feature = "solver"))]
fn certificate_files(
    _dir: &std::path::Path,
    _cert: Result<(), String>,
) -> Result<Vec<(PathBuf, Vec<u8>)>, CliError> {
    Err(CliError::input("--certificate: this build has no solver"))
}

#[cfg(feature = "solver")]
fn optimized(
    a: &Args,
    preset: &gaze_lidar::model::presets::Preset,
    gaze: Option<f64>,
) -> Result<
    (
        gaze_lidar::checker::CertifiedProfile,
        Result<gaze_lidar::optimizer::certificate::Certified, String>,
    ),
    CliError,
> {
    use gaze_lidar::optimizer::{optimize_with_certificate, OptError, OptimizerConfig, Problem};
    let err = |e: OptError| {
        if e.is_input_error() {
            CliError::input(e.to_string())
        } else {
            CliError::infeasible(e.to_string())
        }
    };
    let Some(gaze) = gaze else {
        return Err(CliError::input(
            "--optimize needs --gaze-deg (the baseline has nothing to optimize)",
        ));
    };
    let mut problem = match &a.config {
        Some(path) => {
            let text = super::io::read_text(path, super::io::MAX_CONFIG_BYTES)?;
            OptimizerConfig::from_toml(&text, &path.display().to_string())
                .and_then(|c| c.problem())
                .map_err(err)?
        }
        None => {
            Problem::paper_equivalent(preset, a.mode.unwrap_or(Mode::Range), a.bins).map_err(err)?
        }
    };
    if let Some(m) = a.mode {
        problem.objective.mode = m;
    }
    optimize_with_certificate(&problem, gaze).map_err(err)
}

#[cfg(not(feature = "solver"))]
fn optimized(
    _a: &Args,
    _preset: &gaze_lidar::model::presets::Preset,
    _gaze: Option<f64>,
) -> Result<(gaze_lidar::checker::CertifiedProfile, Result<(), String>), CliError> {
    Err(CliError::input(
        "--optimize/--config: this build has no solver (enable the `solver` feature)",
    ))
}
