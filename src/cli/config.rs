//! `--config FILE.toml` (`--optimizer-config` in `simulate`): the optimizer
//! problem, read the same way by `profile`, `stream` and `simulate`.
//!
//! The rule for flags that the file also sets: **a flag given on the
//! command line overrides the file** — `--preset` its `[lidar] preset`,
//! `--bins` its `bins`, `--accounting` its `[lidar] power_accounting`,
//! `--mode` its `[objective] mode` — and is checked, and named in errors,
//! as the flag. A flag that cannot apply to the file is refused (exit 2,
//! naming both). Nothing given is silently ignored.

use std::path::Path;

use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::planner::Mode;

use super::io::{read_text, MAX_CONFIG_BYTES};
use super::CliError;

/// Command-line values that override the file's.
#[derive(Debug, Clone, Default)]
pub struct Overrides<'a> {
    /// `--preset`.
    pub preset: Option<&'a str>,
    /// `--bins`.
    pub bins: Option<usize>,
    /// `--accounting`.
    pub accounting: Option<PowerAccounting>,
    /// `--mode`.
    pub mode: Option<Mode>,
}

/// Checks `--bins` for the optimizer (4..=1440), naming the flag.
#[cfg(feature = "solver")]
pub fn optimizer_bins(bins: usize) -> Result<usize, CliError> {
    gaze_lidar::optimizer::validate_bins(bins, "--bins")
        .map(|()| bins)
        .map_err(|e| CliError::input(e.to_string()))
}

/// Reads and validates the file and applies `overrides`: exit 2 for a bad
/// file, key or flag; 1 when the limits are infeasible.
#[cfg(feature = "solver")]
pub fn optimizer_problem(
    path: &Path,
    overrides: &Overrides<'_>,
) -> Result<gaze_lidar::optimizer::Problem, CliError> {
    optimizer_problem_and_preset(path, overrides).map(|(p, _)| p)
}

/// [`optimizer_problem`] and the preset the file (or `--preset`) names,
/// before the file's overrides (its closed forms' levels).
#[cfg(feature = "solver")]
pub fn optimizer_problem_and_preset(
    path: &Path,
    overrides: &Overrides<'_>,
) -> Result<
    (
        gaze_lidar::optimizer::Problem,
        gaze_lidar::model::presets::Preset,
    ),
    CliError,
> {
    use gaze_lidar::optimizer::{OptError, OptimizerConfig};
    let err = |e: OptError| {
        if e.is_input_error() {
            CliError::input(e.to_string())
        } else {
            CliError::infeasible(e.to_string())
        }
    };
    let text = read_text(path, MAX_CONFIG_BYTES)?;
    let mut config = OptimizerConfig::from_toml(&text, &path.display().to_string()).map_err(err)?;
    if let Some(name) = overrides.preset {
        gaze_lidar::model::presets::preset(name)
            .map_err(|e| CliError::input(format!("--preset: {e}")))?;
        config.lidar.preset = Some(name.to_owned());
    }
    if let Some(bins) = overrides.bins {
        config.bins = Some(optimizer_bins(bins)?);
    }
    if let Some(acc) = overrides.accounting {
        config.lidar.power_accounting = Some(acc);
    }
    let mut problem = config.problem().map_err(|e| match e {
        OptError::Invalid { field, reason } => match locate(&text, &field) {
            Some((line, column)) => CliError::input(format!(
                "{}:{line}:{column}: {field}: {reason}",
                path.display()
            )),
            None => CliError::input(format!("{}: {field}: {reason}", path.display())),
        },
        other => err(other),
    })?;
    if let Some(m) = overrides.mode {
        if m == Mode::Baseline {
            return Err(CliError::input(format!(
                "--mode baseline and --config {}: the baseline has nothing to optimize (use range, resolution or joint, or drop --config)",
                path.display()
            )));
        }
        problem.objective.mode = m;
    }
    let preset = config.preset().map_err(err)?;
    Ok((problem, preset))
}

/// Where the key `field` (`a.b`, `a.b[2]`, as the optimizer's errors name
/// it) is written in `text`: the 1-based line and column of its value, or
/// of the deepest part of the path the file writes (a table); `None` when
/// the file writes none of it (a value from a preset or a flag).
#[cfg(feature = "solver")]
fn locate(text: &str, field: &str) -> Option<(usize, usize)> {
    use toml::de::{DeTable, DeValue};
    let doc = DeTable::parse(text).ok()?;
    let mut at: Option<usize> = None;
    let mut table: &DeTable<'_> = doc.get_ref();
    let mut parts = field.split('.').peekable();
    while let Some(part) = parts.next() {
        let (key, index) = match part.split_once('[') {
            Some((k, rest)) => (k, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (part, None),
        };
        let Some((_, v)) = table.iter().find(|(k, _)| k.get_ref().as_ref() == key) else {
            break;
        };
        at = Some(v.span().start);
        let mut v = v;
        if let (Some(i), DeValue::Array(a)) = (index, v.get_ref()) {
            match a.get(i) {
                Some(item) => {
                    at = Some(item.span().start);
                    v = item;
                }
                None => break,
            }
        }
        match v.get_ref() {
            DeValue::Table(t) if parts.peek().is_some() => table = t,
            _ => break,
        }
    }
    at.map(|o| gaze_lidar::text::line_column(text, o))
}

/// Without the solver there is no optimizer configuration.
#[cfg(not(feature = "solver"))]
pub fn no_solver(flag: &str) -> CliError {
    CliError::input(format!(
        "{flag}: this build has no solver (enable the `solver` feature)"
    ))
}
