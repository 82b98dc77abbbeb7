//! `gaze-lidar sensor`: write a preset out as a sensor file; and reading a
//! sensor file for `check --sensor` (exit 2 naming the key when it is not
//! a sensor).

use std::path::{Path, PathBuf};

use gaze_lidar::model::lidar::LidarSpec;
use gaze_lidar::model::{presets, sensor};

use super::io::{read_text, MAX_CONFIG_BYTES};
use super::output::Outputs;
use super::CliError;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The preset to write: paper, vls128, vlp16, os1-128.
    #[arg(long)]
    preset: String,
    /// Write to this file (atomically) instead of stdout (`-`: stdout).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let p = presets::preset(&a.preset).map_err(|e| CliError::input(format!("--preset: {e}")))?;
    let mut outputs = Outputs::default();
    outputs.file_opt("--out", a.out.as_deref());
    outputs.check()?;
    let text = sensor::to_toml(&p.lidar).map_err(|e| CliError::input(e.to_string()))?;
    match &a.out {
        Some(path) => outputs.set(path, text),
        None => outputs.stdout(text),
    }
    outputs.commit()?;
    Ok(0)
}

/// Reads and validates a sensor file (`--sensor FILE`).
pub fn read(path: &Path) -> Result<LidarSpec, CliError> {
    let text = read_text(path, MAX_CONFIG_BYTES)?;
    sensor::from_toml(&text, &format!("--sensor {}", path.display()))
        .map_err(|e| CliError::input(e.to_string()))
}
