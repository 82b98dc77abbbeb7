//! Command-line interface: argument parsing, dispatch, exit codes.
//!
//! Exit codes: 0 success; 1 an infeasible request or a rejected profile
//! (the limit is named); 2 bad input (argument, file, field; with line and
//! column for files; an output path that cannot be written, names the
//! same file twice or names an input); 1 also for a write that fails once
//! started (a full disk, stdout on `/dev/full`). Errors are one line on
//! stderr; data goes to stdout or to output files, which are all checked
//! before any work and replaced together at the end (see [`output`]). A
//! closed stdout pipe (`| head`) ends the output quietly.

mod ael;
mod args;
mod check;
mod config;
mod gaze_args;
pub mod io;
pub mod output;
mod profile;
mod replay;
mod sensor;
mod simulate;
mod stream;
mod table;
mod verdict_format;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// An error with its exit code.
#[derive(Debug)]
pub struct CliError {
    /// 1 infeasible / rejected, 2 bad input.
    pub code: u8,
    /// One line.
    pub message: String,
}

impl CliError {
    /// Bad input (exit 2).
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            code: 2,
            message: message.into(),
        }
    }
    /// An output could not be written (exit 1).
    pub fn output(message: impl Into<String>) -> Self {
        Self {
            code: 1,
            message: message.into(),
        }
    }
    /// Infeasible or rejected (exit 1).
    pub fn infeasible(message: impl Into<String>) -> Self {
        Self {
            code: 1,
            message: message.into(),
        }
    }
}

impl From<gaze_lidar::planner::PlanError> for CliError {
    fn from(e: gaze_lidar::planner::PlanError) -> Self {
        if e.is_input_error() {
            Self::input(e.to_string())
        } else {
            Self::infeasible(e.to_string())
        }
    }
}

impl From<gaze_lidar::profile::IoError> for CliError {
    fn from(e: gaze_lidar::profile::IoError) -> Self {
        Self::input(e.to_string())
    }
}

/// The exit codes, as `--help` shows them (the README says the same).
const EXIT_CODES: &str = "Exit codes:
  0  success
  1  an infeasible request or a rejected profile (the limit is named; in a
     checked profile or firmware table, a field out of its range too); also a
     write that fails once started (a full disk, stdout on /dev/full): the
     outputs it was replacing are left as they were
  2  bad input: an argument, a file or a field that cannot be read (with
     line:column for files), a sensor file's out-of-range value, a firmware
     table's header numbers, or an output path that cannot be written, is given twice, or is one of
     the inputs (checked before any work; nothing is written)
Errors are one line on stderr.";

/// Turns a driver's gaze into a certified LiDAR scan schedule.
#[derive(Debug, Parser)]
#[command(name = "gaze-lidar", version, about, long_about = None, after_help = EXIT_CODES)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Build a certified power/spin profile for a gaze direction.
    Profile(profile::Args),
    /// Verify a profile@1 JSON file or a firmware table (firmware@1 JSON or
    /// binary) against its declared limits.
    Check(check::Args),
    /// Class 1 eye-safety limits (IEC 60825-1:2014) for a laser.
    Ael(ael::Args),
    /// Run the paper's T-intersection experiment (variants × fog × trials).
    Simulate(simulate::Args),
    /// Gaze samples on stdin → one certified profile per LiDAR frame (JSON lines).
    Stream(stream::Args),
    /// A rosbag2 MCAP (gaze and point-cloud topics) through the gaze
    /// pipeline → an MCAP with the adapted clouds, the profiles and a
    /// Foxglove picture.
    Replay(replay::Args),
    /// Write a preset's sensor as a sensor file (TOML) for `check --sensor`.
    Sensor(sensor::Args),
}

/// Writes `text` to stdout.
pub fn emit(text: &str) -> Result<(), CliError> {
    emit_bytes(text.as_bytes())
}

/// Writes `bytes` to stdout.
pub fn emit_bytes(bytes: &[u8]) -> Result<(), CliError> {
    let mut stdout = io::Stdout::new();
    stdout.bytes(bytes)?;
    stdout.finish()
}

/// clap's error as one line: the message with its indented continuation
/// (e.g. the names of the missing arguments), without usage and tips.
fn clap_line(e: &clap::Error) -> String {
    let rendered = e.render().to_string();
    let mut parts: Vec<&str> = Vec::new();
    for (i, line) in rendered.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with("Usage:") || t.starts_with("For more information") {
            break;
        }
        if i > 0 && !line.starts_with(' ') {
            break;
        }
        parts.push(t.trim_start_matches("error: "));
    }
    if parts.is_empty() {
        "invalid arguments".to_owned()
    } else {
        parts.join(" ")
    }
}

/// Entry point: parse, run, map errors to exit codes.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(
                e.kind(),
                ErrorKind::DisplayHelp
                    | ErrorKind::DisplayVersion
                    | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) {
                let text = e.render().to_string();
                let mut out = io::Stdout::new();
                return match out.bytes(text.as_bytes()).and_then(|()| out.finish()) {
                    Ok(()) => ExitCode::SUCCESS,
                    Err(e) => {
                        io::warn(format!("error: {}", e.message));
                        ExitCode::from(e.code)
                    }
                };
            }
            io::warn(clap_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Profile(a) => profile::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Ael(a) => ael::run(&a),
        Command::Simulate(a) => simulate::run(&a),
        Command::Stream(a) => stream::run(&a),
        Command::Replay(a) => replay::run(&a),
        Command::Sensor(a) => sensor::run(&a),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            io::warn(format!("error: {}", e.message));
            ExitCode::from(e.code)
        }
    }
}
