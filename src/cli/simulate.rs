//! `gaze-lidar simulate`: the paper's intersection experiment.

use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;

use gaze_lidar::sim::{self, KOfN, ModelKind, Scenario, SimConfig, Variant, FOG_LEVELS_PCT};

use super::{emit, CliError};

/// Output format of the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Aligned text table.
    Table,
    /// `{"rows": [...]}`.
    Json,
    /// One row per cell.
    Csv,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Return model(s); default both.
    #[arg(long, value_enum)]
    model: Vec<ModelKind>,
    /// Variants; default the paper's four (`optimized` adds the optimizer's profile).
    #[arg(long, value_enum)]
    variant: Vec<Variant>,
    /// Optimizer configuration (TOML) for the `optimized` variant (no priors).
    #[arg(long)]
    optimizer_config: Option<PathBuf>,
    /// Fog levels in % (paper labels 0, 25, 50); default all.
    #[arg(long)]
    fog: Vec<u32>,
    /// Trials per cell.
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    trials: i64,
    /// Master seed (same seed → identical output).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Scenario TOML (defaults: the paper's scene).
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// Detection rule k-of-n frames, e.g. `2/3` (paper: first return, `1/1`).
    #[arg(long, default_value = "1/1")]
    detect: String,
    /// Table format on stdout.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Write the plots (SVG and PNG) into this folder.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Write the per-trial records as CSV to this file.
    #[arg(long)]
    trials_csv: Option<PathBuf>,
    /// Write the reproduction report (Markdown) to this file.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Also write the rows as JSON (`{"rows": [...]}`) to this file.
    #[arg(long)]
    export_json: Option<PathBuf>,
    /// Also write the rows as CSV to this file.
    #[arg(long)]
    export_csv: Option<PathBuf>,
    /// Disable ray culling (reference path; results are identical).
    #[arg(long, hide = true)]
    brute_force: bool,
}

fn parse_k_of_n(s: &str) -> Result<KOfN, CliError> {
    let bad = || {
        CliError::input(format!(
            "--detect: '{s}' is not k/n with 1 <= k <= n <= 100"
        ))
    };
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let k: u32 = k.trim().parse().map_err(|_| bad())?;
    let n: u32 = n.trim().parse().map_err(|_| bad())?;
    if k == 0 || k > n || n > 100 {
        return Err(bad());
    }
    Ok(KOfN { k, n })
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let scenario = match &a.scenario {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
            Scenario::from_toml(&text, &path.display().to_string())
                .map_err(|e| CliError::input(e.to_string()))?
        }
        None => Scenario::default(),
    };
    if a.trials < 1 || a.trials > 100_000 {
        return Err(CliError::input(format!(
            "--trials: {} must lie in 1..=100000",
            a.trials
        )));
    }
    for f in &a.fog {
        if !FOG_LEVELS_PCT.contains(f) {
            return Err(CliError::input(format!(
                "--fog: {f} is not one of the paper's levels 0, 25, 50"
            )));
        }
    }
    let config = SimConfig {
        models: if a.model.is_empty() {
            vec![ModelKind::Argus, ModelKind::Physical]
        } else {
            a.model.clone()
        },
        variants: if a.variant.is_empty() {
            Variant::PAPER.to_vec()
        } else {
            a.variant.clone()
        },
        fog_pcts: if a.fog.is_empty() {
            FOG_LEVELS_PCT.to_vec()
        } else {
            a.fog.clone()
        },
        trials: a.trials as usize,
        seed: a.seed,
        scenario,
        detection: parse_k_of_n(&a.detect)?,
        brute_force: a.brute_force,
        ..SimConfig::default()
    };
    let total =
        (config.models.len() * config.variants.len() * config.fog_pcts.len() * config.trials)
            as u64;
    // Hidden automatically when stderr is not a terminal.
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{spinner} simulating [{bar:40}] {pos}/{len} trials ({eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let result = sim::run(&config, &|| bar.inc(1)).map_err(|e| match e {
        sim::SimError::Plan { .. } => CliError::infeasible(e.to_string()),
        other => CliError::input(other.to_string()),
    })?;
    bar.finish_and_clear();
    let text = match a.format {
        Format::Table => sim::table::render_table(&result),
        Format::Json => {
            sim::table::render_json(&result).map_err(|e| CliError::input(e.to_string()))?
        }
        Format::Csv => {
            sim::table::render_csv(&result).map_err(|e| CliError::input(e.to_string()))?
        }
    };
    emit(&text, None)?;
    if let Some(path) = &a.export_json {
        let json = sim::table::render_json(&result).map_err(|e| CliError::input(e.to_string()))?;
        emit(&json, Some(path))?;
    }
    if let Some(path) = &a.export_csv {
        let csv = sim::table::render_csv(&result).map_err(|e| CliError::input(e.to_string()))?;
        emit(&csv, Some(path))?;
    }
    if let Some(path) = &a.trials_csv {
        let csv =
            sim::table::render_trials_csv(&result).map_err(|e| CliError::input(e.to_string()))?;
        emit(&csv, Some(path))?;
    }
    if let Some(dir) = &a.plots {
        let written = sim::plots::write_all(&result, &config, dir)
            .map_err(|e| CliError::input(e.to_string()))?;
        for p in written {
            eprintln!("gaze-lidar: wrote {}", p.display());
        }
    }
    if let Some(path) = &a.report {
        let md = sim::report::render(&result, &config);
        emit(&md, Some(path))?;
        eprintln!("gaze-lidar: wrote {}", path.display());
    }
    Ok(0)
}
