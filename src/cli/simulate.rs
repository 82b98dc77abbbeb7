//! `gaze-lidar simulate`: the paper's intersection experiment.

use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use gaze_lidar::sim::{
    self, Arrival, Detector, Geometry, KOfN, ModelKind, Sampling, Scenario, SimConfig, Variant,
    FOG_LEVELS_PCT,
};

use super::io::{read_text, validate_paths, warn, Outputs, MAX_CONFIG_BYTES};
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
    #[arg(long, allow_negative_numbers = true)]
    fog: Vec<u32>,
    /// Trials per cell.
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    trials: i64,
    /// Master seed (same seed → identical output).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    seed: u64,
    /// Scenario TOML (defaults: the paper's scene).
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// Sensor geometry: `planar` (one horizontal channel, the lightweight
    /// default) or `carla` (CARLA's 64-channel 3D ray-cast LiDAR over a road).
    #[arg(long, value_enum, default_value_t = Geometry::Planar)]
    geometry: Geometry,
    /// Detector of the car from the right: `first-return` (any point on it)
    /// or `argus` (the paper code's road-mask rule; needs `--geometry carla`).
    #[arg(long, value_enum, default_value_t = Detector::FirstReturn)]
    detector: Detector,
    /// Arrival: `front` (the front reaches the conflict line) or
    /// `argus-centre` (the centre does, as the paper's code).
    #[arg(long, value_enum, default_value_t = Arrival::Front)]
    arrival: Arrival,
    /// How the LiDAR fires (`--geometry carla` only; default `carla`):
    /// `carla` (CARLA's fixed tick: round(rate·tick) points per laser per
    /// tick over the tick's rotation), `carla-async` (the same with each
    /// tick's length jittered by `[carla] async_tick_jitter_frac`, assumed)
    /// or `drift` (pulses at k / pulse rate, the planar geometry's clock).
    #[arg(long, value_enum)]
    sampling: Option<Sampling>,
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
    /// With `--report`: also run the paper's pipeline (`--geometry carla
    /// --detector argus --arrival argus-centre --model argus`, the paper's
    /// four variants and fog levels) with this many trials per cell and add
    /// its column and section to the report (0: none).
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    paper_pipeline_trials: i64,
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

/// Reads and validates the optimizer configuration (exit 2 for a bad file
/// or key, 1 when the limits are infeasible — as `profile --config`).
#[cfg(feature = "solver")]
fn optimizer_problem(path: &Path) -> Result<gaze_lidar::optimizer::Problem, CliError> {
    use gaze_lidar::optimizer::OptimizerConfig;
    let text = read_text(path, MAX_CONFIG_BYTES)?;
    OptimizerConfig::from_toml(&text, &path.display().to_string())
        .and_then(|c| c.problem())
        .map_err(|e| {
            if e.is_input_error() {
                CliError::input(e.to_string())
            } else {
                CliError::infeasible(e.to_string())
            }
        })
}

/// Checks that the plots folder exists and accepts files, or can be created.
fn validate_plots_dir(dir: &Path) -> Result<(), CliError> {
    let bad = |m: String| CliError::input(format!("--plots {}: {m}", dir.display()));
    let mut probe = dir;
    loop {
        match std::fs::metadata(probe) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => return Err(bad(format!("{} is not a directory", probe.display()))),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                probe = match probe.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p,
                    _ => Path::new("."),
                };
            }
            Err(e) => return Err(bad(e.to_string())),
        }
    }
    tempfile::Builder::new()
        .prefix(".gaze-lidar-check")
        .tempdir_in(probe)
        .map(drop)
        .map_err(|e| bad(format!("cannot create files in {}: {e}", probe.display())))
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let scenario = match &a.scenario {
        Some(path) => {
            let text = read_text(path, MAX_CONFIG_BYTES)?;
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
    let detection = parse_k_of_n(&a.detect)?;
    if !(0..=100_000).contains(&a.paper_pipeline_trials) {
        return Err(CliError::input(format!(
            "--paper-pipeline-trials: {} must lie in 0..=100000",
            a.paper_pipeline_trials
        )));
    }
    if a.detector == Detector::Argus && a.geometry != Geometry::Carla {
        return Err(CliError::input(
            "--detector argus needs --geometry carla (ARGUS's road mask is built from ground returns)",
        ));
    }
    let variants = if a.variant.is_empty() {
        Variant::PAPER.to_vec()
    } else {
        a.variant.clone()
    };
    #[cfg(feature = "solver")]
    let optimizer = match &a.optimizer_config {
        Some(path) => {
            if !variants.contains(&Variant::Optimized) {
                return Err(CliError::input(
                    "--optimizer-config configures the optimized variant: add --variant optimized",
                ));
            }
            Some(optimizer_problem(path)?)
        }
        None => None,
    };
    #[cfg(not(feature = "solver"))]
    if a.optimizer_config.is_some() {
        return Err(CliError::input(
            "--optimizer-config: this build has no solver (enable the `solver` feature)",
        ));
    }
    // Every output path is checked before the run: a bad one fails now,
    // and nothing is replaced.
    let files: Vec<&Path> = [&a.export_json, &a.export_csv, &a.trials_csv, &a.report]
        .into_iter()
        .filter_map(|p| p.as_deref())
        .collect();
    validate_paths(files.iter().copied())?;
    if let Some(dir) = &a.plots {
        validate_plots_dir(dir)?;
    }
    let config = SimConfig {
        models: if a.model.is_empty() {
            vec![ModelKind::Argus, ModelKind::Physical]
        } else {
            a.model.clone()
        },
        variants,
        fog_pcts: if a.fog.is_empty() {
            FOG_LEVELS_PCT.to_vec()
        } else {
            a.fog.clone()
        },
        trials: a.trials as usize,
        seed: a.seed,
        scenario,
        detection,
        brute_force: a.brute_force,
        geometry: a.geometry,
        detector: a.detector,
        arrival: a.arrival,
        sampling: a.sampling,
        #[cfg(feature = "solver")]
        optimizer,
        ..SimConfig::default()
    };
    let total =
        (config.models.len() * config.variants.len() * config.fog_pcts.len() * config.trials)
            as u64;
    let bar = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(total);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} simulating [{bar:40}] {pos}/{len} trials ({eta})",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let result = sim::run(&config, &|| bar.inc(1)).map_err(|e| {
        if e.is_input_error() {
            CliError::input(e.to_string())
        } else {
            CliError::infeasible(e.to_string())
        }
    });
    bar.finish_and_clear();
    let result = result?;
    let render = |e: csv::Error| CliError::input(e.to_string());
    let text = match a.format {
        Format::Table => sim::table::render_table(&result),
        Format::Json => {
            sim::table::render_json(&result).map_err(|e| CliError::input(e.to_string()))?
        }
        Format::Csv => sim::table::render_csv(&result).map_err(render)?,
    };
    // Everything is rendered and staged before anything is replaced.
    let mut outputs = Outputs::default();
    if let Some(path) = &a.export_json {
        let json = sim::table::render_json(&result).map_err(|e| CliError::input(e.to_string()))?;
        outputs.add(path, json);
    }
    if let Some(path) = &a.export_csv {
        outputs.add(path, sim::table::render_csv(&result).map_err(render)?);
    }
    if let Some(path) = &a.trials_csv {
        outputs.add(
            path,
            sim::table::render_trials_csv(&result).map_err(render)?,
        );
    }
    if let Some(path) = &a.report {
        let pipeline = if a.paper_pipeline_trials > 0 {
            let pc = SimConfig {
                models: vec![ModelKind::Argus],
                variants: Variant::PAPER.to_vec(),
                fog_pcts: FOG_LEVELS_PCT.to_vec(),
                trials: a.paper_pipeline_trials as usize,
                geometry: Geometry::Carla,
                detector: Detector::Argus,
                arrival: Arrival::ArgusCentre,
                ..config.clone()
            };
            let r = sim::run(&pc, &|| {}).map_err(|e| CliError::input(e.to_string()))?;
            // Clear air under the other samplings, and the fog-25 % baseline
            // with cars above ARGUS's road threshold, for the comparisons.
            let mut extras = Vec::new();
            for other in [Sampling::Carla, Sampling::Drift, Sampling::CarlaAsync] {
                if other != pc.sampling() {
                    extras.push(SimConfig {
                        fog_pcts: vec![0],
                        variants: vec![Variant::Baseline],
                        sampling: Some(other),
                        ..pc.clone()
                    });
                }
            }
            let mut lifted = SimConfig {
                fog_pcts: vec![25],
                variants: vec![Variant::Baseline],
                ..pc.clone()
            };
            let c = &mut lifted.scenario.carla;
            c.vehicle_ground_clearance_m =
                (c.mount_height_m + c.argus_road_z_m + 0.05).clamp(0.0, 0.49 * c.vehicle_height_m);
            extras.push(lifted);
            let runs = extras
                .into_iter()
                .map(|c| sim::run(&c, &|| {}).map(|r| (r, c)))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| CliError::input(e.to_string()))?;
            Some(((r, pc), runs))
        } else {
            None
        };
        let runs: &[(sim::GridResult, SimConfig)] = pipeline.as_ref().map_or(&[], |(_, r)| r);
        let others: Vec<(&sim::GridResult, &SimConfig)> = runs
            .iter()
            .filter(|(_, c)| c.fog_pcts == [0])
            .map(|(r, c)| (r, c))
            .collect();
        let lifted = runs
            .iter()
            .find(|(_, c)| c.fog_pcts == [25])
            .map(|(r, c)| (r, c));
        let md = sim::report::render_with_pipelines(
            &result,
            &config,
            pipeline.as_ref().map(|((r, c), _)| (r, c)),
            &sim::report::PipelineExtras {
                other_samplings: &others,
                lifted,
            },
        );
        outputs.add(path, md);
    }
    let plots = match &a.plots {
        Some(dir) => Some(stage_plots(&result, &config, dir)?),
        None => None,
    };
    emit(&text, None)?;
    outputs.commit()?;
    if let Some(path) = &a.report {
        warn(format_args!("wrote {}", path.display()));
    }
    if let (Some(dir), Some((staging, names))) = (&a.plots, plots) {
        std::fs::create_dir_all(dir)
            .map_err(|e| CliError::output(format!("--plots {}: {e}", dir.display())))?;
        for name in names {
            let dest = dir.join(&name);
            std::fs::rename(staging.path().join(&name), &dest)
                .map_err(|e| CliError::output(format!("{}: {e}", dest.display())))?;
            warn(format_args!("wrote {}", dest.display()));
        }
    }
    Ok(0)
}

/// Renders the plots into a temporary folder beside `dir` (moved in at the end).
fn stage_plots(
    result: &sim::GridResult,
    config: &SimConfig,
    dir: &Path,
) -> Result<(tempfile::TempDir, Vec<std::ffi::OsString>), CliError> {
    let mut base = dir;
    while !base.is_dir() {
        base = match base.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
    }
    let staging = tempfile::Builder::new()
        .prefix(".gaze-lidar-plots")
        .tempdir_in(base)
        .map_err(|e| CliError::input(format!("--plots {}: {e}", dir.display())))?;
    let written = sim::plots::write_all(result, config, staging.path())
        .map_err(|e| CliError::output(e.to_string()))?;
    let names = written
        .iter()
        .filter_map(|p| p.file_name().map(std::ffi::OsStr::to_os_string))
        .collect();
    Ok((staging, names))
}
