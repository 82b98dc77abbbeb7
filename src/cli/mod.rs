//! Command-line interface: argument parsing, dispatch, exit codes.
//!
//! Exit codes: 0 success; 1 an infeasible request or a rejected profile
//! (the limit is named); 2 bad input (argument, file, field; with line and
//! column for files). Errors are one line on stderr; data goes to stdout or
//! `--out` (written atomically: never a partial file).

mod ael;
mod check;
mod profile;
mod simulate;
mod stream;

use clap::{Parser, Subcommand};
use std::path::Path;
use std::process::ExitCode;

use gaze_lidar::profile::write_atomic;

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

/// Turns a driver's gaze into a certified LiDAR scan schedule.
#[derive(Debug, Parser)]
#[command(name = "gaze-lidar", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Build a certified power/spin profile for a gaze direction.
    Profile(profile::Args),
    /// Verify a profile@1 JSON file against its declared limits.
    Check(check::Args),
    /// Class 1 eye-safety limits (IEC 60825-1:2014) for a laser.
    Ael(ael::Args),
    /// Run the paper's T-intersection experiment (variants × fog × trials).
    Simulate(simulate::Args),
    /// Gaze samples on stdin → one certified profile per LiDAR frame (JSON lines).
    Stream(stream::Args),
}

/// Writes `text` to `out` atomically, or to stdout.
pub fn emit(text: &str, out: Option<&Path>) -> Result<(), CliError> {
    emit_bytes(text.as_bytes(), out)
}

/// Writes `bytes` to `out` atomically, or to stdout.
pub fn emit_bytes(bytes: &[u8], out: Option<&Path>) -> Result<(), CliError> {
    match out {
        Some(path) => write_atomic(path, bytes).map_err(|e| CliError::input(e.to_string())),
        None => {
            use std::io::Write;
            let mut stdout = std::io::stdout().lock();
            // A closed pipe (e.g. `| head`) is not an error worth a message.
            let _ = stdout.write_all(bytes);
            let _ = stdout.flush();
            Ok(())
        }
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
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            let rendered = e.render().to_string();
            let line = rendered.lines().next().unwrap_or("invalid arguments");
            eprintln!("gaze-lidar: {}", line.trim_start_matches("error: "));
            return ExitCode::from(2);
        }
    };
    let result = match cli.command {
        Command::Profile(a) => profile::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Ael(a) => ael::run(&a),
        Command::Simulate(a) => simulate::run(&a),
        Command::Stream(a) => stream::run(&a),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("gaze-lidar: error: {}", e.message);
            ExitCode::from(e.code)
        }
    }
}
