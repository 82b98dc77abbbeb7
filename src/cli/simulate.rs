//! `gaze-lidar simulate`: the paper's intersection experiment.

use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

use gaze_lidar::sim::{
    self, Arrival, Detector, Geometry, KOfN, ModelKind, Sampling, Scenario, SimConfig, Variant,
    FOG_LEVELS_PCT,
};

use super::args::int_in;
use super::io::{read_text, warn, MAX_CONFIG_BYTES};
use super::output::Outputs;
use super::CliError;

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
    #[arg(long, value_parser = super::args::named::<ModelKind>())]
    model: Vec<ModelKind>,
    /// Variants; default the paper's four (`optimized` adds the optimizer's profile).
    #[arg(long, value_parser = super::args::named::<Variant>())]
    variant: Vec<Variant>,
    /// Optimizer configuration (TOML) for the `optimized` variant; the
    /// closed-form variants then run on its sensor, limits and driver model
    /// too (with the levels of the preset it names), the basis
    /// `profile --config FILE --format text` compares with.
    #[arg(long)]
    optimizer_config: Option<PathBuf>,
    /// LiDAR preset of the closed-form variants: paper, vls128, vlp16,
    /// os1-128 [default: paper]; with --optimizer-config, replaces the
    /// file's `[lidar] preset`.
    #[arg(long)]
    preset: Option<String>,
    /// Fog levels in % (paper labels 0, 25, 50); default all.
    #[arg(long, allow_hyphen_values = true)]
    fog: Vec<i64>,
    /// Trials per cell (1..=100000).
    #[arg(long, default_value_t = 100, allow_hyphen_values = true)]
    trials: i64,
    /// Master seed, 0..=18446744073709551615 (same seed → identical output).
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: i128,
    /// Scenario TOML (defaults: the paper's scene).
    #[arg(long)]
    scenario: Option<PathBuf>,
    /// Sensor geometry: `planar` (one horizontal channel, the lightweight
    /// default) or `carla` (CARLA's 64-channel 3D ray-cast LiDAR over a road).
    #[arg(long, value_parser = super::args::named::<Geometry>(), default_value_t = Geometry::Planar)]
    geometry: Geometry,
    /// Detector of the car from the right: `first-return` (any point on it)
    /// or `argus` (the paper code's road-mask rule; needs `--geometry carla`).
    #[arg(long, value_parser = super::args::named::<Detector>(), default_value_t = Detector::FirstReturn)]
    detector: Detector,
    /// Arrival: `front` (the front reaches the conflict line) or
    /// `argus-centre` (the centre does, as the paper's code).
    #[arg(long, value_parser = super::args::named::<Arrival>(), default_value_t = Arrival::Front)]
    arrival: Arrival,
    /// How the LiDAR fires (`--geometry carla` only; default `carla`):
    /// `carla` (CARLA's fixed tick: round(rate·tick) points per laser per
    /// tick over the tick's rotation), `carla-async` (the same with each
    /// tick's length jittered by `[carla] async_tick_jitter_frac`, assumed)
    /// or `drift` (pulses at k / pulse rate, the planar geometry's clock).
    #[arg(long, value_parser = super::args::named::<Sampling>())]
    sampling: Option<Sampling>,
    /// Detection rule k-of-n frames, e.g. `2/3` (paper: first return, `1/1`).
    #[arg(long, default_value = "1/1", allow_hyphen_values = true)]
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
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    paper_pipeline_trials: i64,
    /// Also write the rows as JSON (`{"rows": [...]}`) to this file.
    #[arg(long)]
    export_json: Option<PathBuf>,
    /// Also write the rows as CSV to this file.
    #[arg(long)]
    export_csv: Option<PathBuf>,
    /// Sensitivity sweep `KEY=V1,V2,…` (repeatable, one table per key): any
    /// numeric scenario key (`speed_kmh`, `carla.mount_height_m`, …) or the
    /// aliases `mount_height`, `tick` (`carla.tick_s`), `spawn_distance`,
    /// `grid_phase` (`carla.grid_phase_steps`, the scan grid's azimuth phase
    /// in steps) and `fog_threshold` (`argus_fog_threshold_scale`); the
    /// whole grid is run once per value and printed as tables (`--format
    /// json`: `{"sweeps": [...]}`); with `--gaze`/`--gaze-behaviour` every
    /// value's grid is driven by the gaze.
    /// With `--plots DIR`: one figure per key (`sweep_KEY.svg`/`.png`).
    /// With `--report`: the sweeps run the paper's pipeline (needs
    /// `--paper-pipeline-trials`) and make the report's sensitivity section.
    #[arg(long)]
    sweep: Vec<String>,
    /// With `--report` and `--sweep`: trials per cell of each swept value
    /// (default: `--paper-pipeline-trials`).
    #[arg(long, allow_hyphen_values = true)]
    sweep_trials: Option<i64>,
    /// With `--report`: also run this scenario file (repeatable; the
    /// `physical` model, the paper's four variants, every fog level,
    /// `--trials` and `--seed`) and tabulate it in the report's "Other
    /// scenarios" section, with intervals, modes and paired tests.
    #[arg(long)]
    report_scenario: Vec<PathBuf>,
    /// With `--report`: also drive the sensor from this named gaze
    /// behaviour (repeatable; as `--gaze-behaviour`) and tabulate it in the
    /// report's gaze section (the paper's scene, the `physical` model, the
    /// four variants at the run's fog levels, `--trials` and `--seed`).
    #[arg(long)]
    report_gaze_behaviour: Vec<String>,
    /// With `--report`: also drive the sensor from this recorded gaze trace,
    /// given as `FORMAT=PATH` (repeatable; FORMAT as `--gaze-format`), and
    /// tabulate it in the report's gaze section.
    #[arg(long)]
    report_gaze: Vec<String>,
    /// Disable ray culling (reference path; results are identical).
    #[arg(long, hide = true)]
    brute_force: bool,
    /// Drive the sensor's profile frame by frame from this recorded gaze
    /// file (format: --gaze-format) through `stream`'s filter and fail-safe.
    #[arg(long, conflicts_with = "gaze_behaviour")]
    gaze: Option<PathBuf>,
    /// Format of --gaze.
    #[arg(long, value_parser = super::args::named::<gaze_lidar::gaze::Format>(), default_value_t = gaze_lidar::gaze::Format::Jsonl)]
    gaze_format: gaze_lidar::gaze::Format,
    /// Drive the profile from a named gaze behaviour, seeded per trial:
    /// `fixate[:gaze_deg=G]`, `scan[:left_deg=L,right_deg=R,rate_hz=F,step_deg=S]`,
    /// `mirror[:gaze_deg=G,mirror_deg=M,every_s=P,glance_s=D]`,
    /// `blink[:gaze_deg=G,every_s=P,blink_s=D]`.
    #[arg(long)]
    gaze_behaviour: Option<String>,
    #[command(flatten)]
    filter: super::gaze_args::FilterArgs,
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
    let mut outputs = Outputs::default();
    outputs
        .input_opt("--scenario", a.scenario.as_deref())
        .input_opt("--gaze", a.gaze.as_deref())
        .input_opt("--optimizer-config", a.optimizer_config.as_deref());
    for path in &a.report_scenario {
        outputs.input_opt("--report-scenario", Some(path));
    }
    let report_gaze_paths: Vec<(String, PathBuf)> = a
        .report_gaze
        .iter()
        .map(|spec| {
            spec.split_once('=')
                .map(|(f, p)| (f.trim().to_owned(), PathBuf::from(p)))
                .ok_or_else(|| {
                    CliError::input(format!(
                        "--report-gaze: '{spec}' is not FORMAT=PATH (e.g. csv=gaze.csv)"
                    ))
                })
        })
        .collect::<Result<_, _>>()?;
    for (_, path) in &report_gaze_paths {
        outputs.input_opt("--report-gaze", Some(path));
    }
    let scenario = match &a.scenario {
        Some(path) => {
            let text = read_text(path, MAX_CONFIG_BYTES)?;
            Scenario::from_toml(&text, &path.display().to_string())
                .map_err(|e| CliError::input(e.to_string()))?
        }
        None => Scenario::default(),
    };
    let trials: usize = int_in("--trials", a.trials, 1, 100_000)?;
    let seed: u64 = int_in("--seed", a.seed, 0, u64::MAX)?;
    let mut fog_pcts: Vec<u32> = Vec::new();
    for &f in &a.fog {
        match u32::try_from(f) {
            Ok(f) if FOG_LEVELS_PCT.contains(&f) => fog_pcts.push(f),
            _ => {
                return Err(CliError::input(format!(
                    "--fog: {f} is not one of the paper's levels 0, 25, 50"
                )))
            }
        }
    }
    let detection = parse_k_of_n(&a.detect)?;
    let paper_pipeline_trials: usize = int_in(
        "--paper-pipeline-trials",
        a.paper_pipeline_trials,
        0,
        100_000,
    )?;
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
    #[cfg_attr(not(feature = "solver"), allow(unused_mut))]
    let mut sensor = gaze_lidar::model::presets::preset(a.preset.as_deref().unwrap_or("paper"))
        .map_err(|e| CliError::input(format!("--preset: {e}")))?;
    #[cfg(feature = "solver")]
    let optimizer = match &a.optimizer_config {
        Some(path) => {
            if !variants.contains(&Variant::Optimized) {
                return Err(CliError::input(
                    "--optimizer-config configures the optimized variant: add --variant optimized",
                ));
            }
            let overrides = super::config::Overrides {
                preset: a.preset.as_deref(),
                ..super::config::Overrides::default()
            };
            let (problem, named) = super::config::optimizer_problem_and_preset(path, &overrides)?;
            sensor = gaze_lidar::optimizer::figures::closed_form_basis(&problem, named.levels);
            Some(problem)
        }
        None => None,
    };
    #[cfg(not(feature = "solver"))]
    if a.optimizer_config.is_some() {
        return Err(super::config::no_solver("--optimizer-config"));
    }
    let gaze = gaze_drive(a, &scenario)?;
    let config = SimConfig {
        models: if a.model.is_empty() {
            if gaze.is_some() {
                vec![ModelKind::Physical]
            } else {
                vec![ModelKind::Argus, ModelKind::Physical]
            }
        } else {
            a.model.clone()
        },
        variants,
        fog_pcts: if fog_pcts.is_empty() {
            FOG_LEVELS_PCT.to_vec()
        } else {
            fog_pcts
        },
        trials,
        seed,
        scenario,
        detection,
        brute_force: a.brute_force,
        geometry: a.geometry,
        detector: a.detector,
        arrival: a.arrival,
        sampling: a.sampling,
        #[cfg(feature = "solver")]
        optimizer,
        sensor,
        ..SimConfig::default()
    };
    if !a.sweep.is_empty() && a.report.is_none() {
        return run_sweeps(a, &config, gaze.as_ref());
    }
    // With --report, the sweeps make the sensitivity section (on the
    // paper's pipeline): parsed and validated before anything runs.
    let sweeps = parse_sweeps(&a.sweep)?;
    let sweep_trials: usize = match a.sweep_trials {
        Some(n) => int_in("--sweep-trials", n, 1, 100_000)?,
        None => paper_pipeline_trials,
    };
    if !sweeps.is_empty() && paper_pipeline_trials == 0 {
        return Err(CliError::input(
            "--sweep with --report: the sensitivity section sweeps the paper's pipeline: add --paper-pipeline-trials N",
        ));
    }
    if a.sweep_trials.is_some() && sweeps.is_empty() {
        return Err(CliError::input("--sweep-trials needs --sweep"));
    }
    if !a.report_scenario.is_empty() && a.report.is_none() {
        return Err(CliError::input(
            "--report-scenario adds a scenario to the report: add --report FILE (or run it with --scenario)",
        ));
    }
    // The report's scenario files: read and checked before anything runs.
    let mut report_scenarios = Vec::new();
    for path in &a.report_scenario {
        let text = read_text(path, MAX_CONFIG_BYTES)?;
        let shown = path.display().to_string();
        let scenario = Scenario::from_toml(&text, &shown)
            .map_err(|e| CliError::input(format!("--report-scenario: {e}")))?;
        let name = path
            .file_stem()
            .map_or_else(|| shown.clone(), |s| s.to_string_lossy().into_owned());
        let sc_config = SimConfig {
            models: vec![ModelKind::Physical],
            variants: Variant::PAPER.to_vec(),
            fog_pcts: FOG_LEVELS_PCT.to_vec(),
            trials,
            seed,
            scenario,
            ..SimConfig::default()
        };
        report_scenarios.push((
            name,
            shown,
            sim::report::scenario_description(&text),
            sc_config,
        ));
    }
    if (!a.report_gaze.is_empty() || !a.report_gaze_behaviour.is_empty()) && a.report.is_none() {
        return Err(CliError::input(
            "--report-gaze/--report-gaze-behaviour add gaze runs to the report: add --report FILE (or run one with --gaze/--gaze-behaviour)",
        ));
    }
    // The report's gaze sources: read and checked before anything runs.
    let report_gaze = report_gaze_sources(a, &report_gaze_paths)?;
    // Every output path is checked before the run — against the others
    // (the plots' file names included) and against the inputs: a bad one
    // fails now, and nothing is replaced.
    outputs
        .claim_stdout("the results table")
        .file_opt("--export-json", a.export_json.as_deref())
        .file_opt("--export-csv", a.export_csv.as_deref())
        .file_opt("--trials-csv", a.trials_csv.as_deref())
        .file_opt("--report", a.report.as_deref());
    let mut plot_names = sim::plots::file_names(&config);
    for sw in &sweeps {
        plot_names.extend(sim::plots::sweep_file_names(sw));
    }
    if let Some(dir) = &a.plots {
        outputs.folder("--plots", dir, &plot_names);
    }
    outputs.check()?;
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
    let result = match &gaze {
        Some(g) => sim::gaze_drive::run(&config, g, &|| bar.inc(1)),
        None => sim::run(&config, &|| bar.inc(1)),
    }
    .map_err(sim_error);
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
    // Everything is rendered before anything is replaced.
    if let Some(path) = &a.export_json {
        let json = sim::table::render_json(&result).map_err(|e| CliError::input(e.to_string()))?;
        outputs.set(path, json);
    }
    if let Some(path) = &a.export_csv {
        outputs.set(path, sim::table::render_csv(&result).map_err(render)?);
    }
    if let Some(path) = &a.trials_csv {
        outputs.set(
            path,
            sim::table::render_trials_csv(&result).map_err(render)?,
        );
    }
    if let Some(path) = &a.report {
        let pipeline = if paper_pipeline_trials > 0 {
            let pc = SimConfig {
                models: vec![ModelKind::Argus],
                variants: Variant::PAPER.to_vec(),
                fog_pcts: FOG_LEVELS_PCT.to_vec(),
                trials: paper_pipeline_trials,
                geometry: Geometry::Carla,
                detector: Detector::Argus,
                arrival: Arrival::ArgusCentre,
                ..config.clone()
            };
            let r = sim::run(&pc, &|| {}).map_err(|e| CliError::input(sim_message(&e)))?;
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
            // The sensitivity section: every swept value of the pipeline.
            let mut swept = Vec::new();
            for sw in &sweeps {
                let configs = sweep_configs(
                    sw,
                    &SimConfig {
                        trials: sweep_trials,
                        ..pc.clone()
                    },
                )?;
                let results = sim::run_many(&configs, &|| {}).map_err(sim_error)?;
                swept.push((sw.clone(), results, configs.into_iter().next()));
            }
            let runs = extras
                .into_iter()
                .map(|c| sim::run(&c, &|| {}).map(|r| (r, c)))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| CliError::input(sim_message(&e)))?;
            Some(((r, pc), runs, swept))
        } else {
            None
        };
        let runs: &[(sim::GridResult, SimConfig)] = pipeline.as_ref().map_or(&[], |(_, r, _)| r);
        let sensitivity: Vec<sim::report::SweepRun<'_>> = pipeline
            .as_ref()
            .map(|(_, _, swept)| {
                swept
                    .iter()
                    .filter_map(|(sw, results, config)| {
                        Some(sim::report::SweepRun {
                            sweep: sw,
                            results,
                            config: config.as_ref()?,
                        })
                    })
                    .collect()
            })
            .unwrap_or_default();
        let others: Vec<(&sim::GridResult, &SimConfig)> = runs
            .iter()
            .filter(|(_, c)| c.fog_pcts == [0])
            .map(|(r, c)| (r, c))
            .collect();
        let lifted = runs
            .iter()
            .find(|(_, c)| c.fog_pcts == [25])
            .map(|(r, c)| (r, c));
        let scenario_results = report_scenarios
            .iter()
            .map(|(_, path, _, c)| {
                sim::run(c, &|| {}).map_err(|e| {
                    let message = format!("--report-scenario {path}: {e}");
                    if e.is_input_error() {
                        CliError::input(message)
                    } else {
                        CliError::infeasible(message)
                    }
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let scenario_runs: Vec<sim::report::ScenarioRun<'_>> = report_scenarios
            .iter()
            .zip(&scenario_results)
            .map(
                |((name, path, description, config), result)| sim::report::ScenarioRun {
                    name,
                    path,
                    description,
                    result,
                    config,
                },
            )
            .collect();
        let gaze_config = SimConfig {
            models: vec![ModelKind::Physical],
            variants: Variant::PAPER.to_vec(),
            fog_pcts: config.fog_pcts.clone(),
            trials,
            seed,
            ..SimConfig::default()
        };
        let gaze_results = report_gaze
            .iter()
            .map(|(args, drive)| {
                sim::gaze_drive::run(&gaze_config, drive, &|| {}).map_err(|e| {
                    let message = format!("{args}: {}", sim_message(&e));
                    if e.is_input_error() {
                        CliError::input(message)
                    } else {
                        CliError::infeasible(message)
                    }
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let gaze_runs: Vec<sim::report::GazeRun<'_>> = report_gaze
            .iter()
            .zip(&gaze_results)
            .map(|((args, _), result)| sim::report::GazeRun {
                args,
                result,
                config: &gaze_config,
            })
            .collect();
        let md = sim::report::render_with_pipelines(
            &result,
            &config,
            pipeline.as_ref().map(|((r, c), _, _)| (r, c)),
            &sim::report::PipelineExtras {
                other_samplings: &others,
                lifted,
                sensitivity: &sensitivity,
                scenarios: &scenario_runs,
                gaze: &gaze_runs,
            },
        );
        outputs.set(path, md);
        if let (Some(dir), Some((_, _, swept))) = (&a.plots, &pipeline) {
            for (sw, results, config) in swept {
                if let Some(config) = config {
                    for (name, bytes) in render_sweep_plot(sw, results, config)? {
                        outputs.set(&dir.join(name), bytes);
                    }
                }
            }
        }
    }
    if let Some(dir) = &a.plots {
        for (name, bytes) in render_plots(&result, &config, &sim::plots::file_names(&config))? {
            outputs.set(&dir.join(name), bytes);
        }
    }
    outputs.stdout(text);
    outputs.commit()?;
    if let Some(path) = &a.report {
        warn(format_args!("wrote {}", path.display()));
    }
    if let Some(dir) = &a.plots {
        for name in &plot_names {
            warn(format_args!("wrote {}", dir.join(name).display()));
        }
    }
    Ok(0)
}

/// The gaze drive of `--gaze` / `--gaze-behaviour`, if either is given.
fn gaze_drive(
    a: &Args,
    scenario: &Scenario,
) -> Result<Option<sim::gaze_drive::GazeDrive>, CliError> {
    use gaze_lidar::gaze::GazeError;
    use sim::gaze_drive::{Behaviour, GazeDrive, GazeSource, Trace};
    let source = match (&a.gaze, &a.gaze_behaviour) {
        (Some(path), _) => {
            // Recordings are larger than configurations: 256 MiB.
            let text = read_text(path, 256 << 20)?;
            GazeSource::Trace(
                Trace::parse(&text, a.gaze_format, &path.display().to_string()).map_err(
                    |e| match e {
                        GazeError::Recording { .. } => CliError::input(format!("--gaze: {e}")),
                        e => super::gaze_args::gaze_error(e),
                    },
                )?,
            )
        }
        (None, Some(spec)) => GazeSource::Behaviour(
            Behaviour::parse(spec, scenario.gaze_deg)
                .map_err(|e| CliError::input(format!("--gaze-behaviour: {e}")))?,
        ),
        (None, None) => return Ok(None),
    };
    if a.report.is_some() || (a.plots.is_some() && a.sweep.is_empty()) {
        return Err(CliError::input(
            "--gaze/--gaze-behaviour: --report and --plots describe the paper's grid (--plots draws a --sweep's figures); use --format, --export-json/--export-csv or --trials-csv",
        ));
    }
    Ok(Some(GazeDrive {
        source,
        pipeline: a.filter.settings()?,
    }))
}

/// The report's gaze sources (`--report-gaze-behaviour`, then
/// `--report-gaze`), each with the options that give it to `simulate`.
fn report_gaze_sources(
    a: &Args,
    paths: &[(String, PathBuf)],
) -> Result<Vec<(String, sim::gaze_drive::GazeDrive)>, CliError> {
    use sim::gaze_drive::{Behaviour, GazeDrive, GazeSource, Trace};
    let pipeline = a.filter.settings()?;
    let default_gaze_deg = Scenario::default().gaze_deg;
    let mut out = Vec::new();
    for spec in &a.report_gaze_behaviour {
        let b = Behaviour::parse(spec, default_gaze_deg)
            .map_err(|e| CliError::input(format!("--report-gaze-behaviour: {e}")))?;
        out.push((
            format!("--gaze-behaviour {spec}"),
            GazeDrive {
                source: GazeSource::Behaviour(b),
                pipeline,
            },
        ));
    }
    for (format, path) in paths {
        let fmt: gaze_lidar::gaze::Format = format
            .parse()
            .map_err(|e| CliError::input(format!("--report-gaze {format}=…: {e}")))?;
        let text = read_text(path, 256 << 20)?;
        let trace = Trace::parse(&text, fmt, &path.display().to_string())
            .map_err(super::gaze_args::gaze_error)?;
        out.push((
            format!("--gaze {} --gaze-format {format}", path.display()),
            GazeDrive {
                source: GazeSource::Trace(trace),
                pipeline,
            },
        ));
    }
    Ok(out)
}

/// Renders the plots (in a private temporary folder) and returns their
/// bytes by file name, in the order of `names`.
fn render_plots(
    result: &sim::GridResult,
    config: &SimConfig,
    names: &[String],
) -> Result<Vec<(String, Vec<u8>)>, CliError> {
    let staging = tempfile::Builder::new()
        .prefix("gaze-lidar-plots")
        .tempdir()
        .map_err(|e| CliError::output(format!("--plots: temporary folder: {e}")))?;
    sim::plots::write_all(result, config, staging.path())
        .map_err(|e| CliError::output(e.to_string()))?;
    names
        .iter()
        .map(|name| {
            let path = staging.path().join(name);
            std::fs::read(&path)
                .map(|b| (name.clone(), b))
                .map_err(|e| CliError::output(format!("--plots: {}: {e}", path.display())))
        })
        .collect()
}

/// A simulation error as the CLI reports it (input: exit 2; else exit 1).
fn sim_error(e: sim::SimError) -> CliError {
    if e.is_input_error() {
        CliError::input(sim_message(&e))
    } else {
        CliError::infeasible(sim_message(&e))
    }
}

/// A simulation error's message, with options that do not go together
/// named by their flags.
fn sim_message(e: &sim::SimError) -> String {
    use sim::Conflict as C;
    const GAZE: &str = "--gaze/--gaze-behaviour: only";
    match e {
        sim::SimError::Conflict(c) => match c {
            C::DetectorNeedsCarla => "--detector argus needs --geometry carla (ARGUS's road mask is built from ground returns)".to_owned(),
            C::FalseAlarmsNeedPlanar => "scenario.false_alarms_per_frame needs --geometry planar (the carla geometry has no frame-based detector)".to_owned(),
            C::SamplingNeedsCarla(s) => format!("--sampling {s} needs --geometry carla (the planar geometry has only the drift pulse clock)"),
            C::GazeNeedsPlanar => format!("{GAZE} the planar geometry is driven by the gaze stream (the carla geometry plans one profile and one region of focus per trial, not per frame)"),
            C::GazeNeedsPhysical => format!("{GAZE} --model physical is driven (the argus model's resolution variant is a fixed decimation, not a per-frame profile)"),
            C::GazeNeedsClosedForm => format!("{GAZE} the closed-form variants (baseline, range, resolution, joint) are driven"),
        },
        e => e.to_string(),
    }
}

/// Parses every `--sweep` (a bad one: exit 2 naming it).
fn parse_sweeps(specs: &[String]) -> Result<Vec<sim::sweep::Sweep>, CliError> {
    specs
        .iter()
        .map(|s| sim::sweep::parse(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(sweep_error)
}

/// A sweep error as the CLI words it: `--sweep: …`, or `--sweep KEY=V: …`
/// for a value.
fn sweep_error(e: sim::sweep::SweepError) -> CliError {
    match e {
        sim::sweep::SweepError::Value { .. } => CliError::input(format!("--sweep {e}")),
        _ => CliError::input(format!("--sweep: {e}")),
    }
}

/// One configuration per value of `sweep` (every value validated).
fn sweep_configs(
    sweep: &sim::sweep::Sweep,
    config: &SimConfig,
) -> Result<Vec<SimConfig>, CliError> {
    sweep
        .values
        .iter()
        .map(|&v| {
            let scenario =
                sim::sweep::apply(&config.scenario, &sweep.key, v).map_err(sweep_error)?;
            Ok(SimConfig {
                scenario,
                ..config.clone()
            })
        })
        .collect()
}

/// Renders a sweep's figure (in a private temporary folder) and returns
/// its files' bytes by name.
fn render_sweep_plot(
    sweep: &sim::sweep::Sweep,
    results: &[sim::GridResult],
    config: &SimConfig,
) -> Result<Vec<(String, Vec<u8>)>, CliError> {
    let staging = tempfile::Builder::new()
        .prefix("gaze-lidar-plots")
        .tempdir()
        .map_err(|e| CliError::output(format!("--plots: temporary folder: {e}")))?;
    sim::plots::write_sweep(sweep, results, config, staging.path())
        .map_err(|e| CliError::output(e.to_string()))?;
    sim::plots::sweep_file_names(sweep)
        .into_iter()
        .map(|name| {
            let path = staging.path().join(&name);
            std::fs::read(&path)
                .map(|b| (name, b))
                .map_err(|e| CliError::output(format!("--plots: {}: {e}", path.display())))
        })
        .collect()
}

/// `--sweep` without `--report`: the grid once per value of each key
/// (the values of a key run together, [`sim::run_many`]); tables (or JSON)
/// on stdout, with `--plots DIR` one figure per key.
/// With a gaze drive, every value's grid is driven by it.
fn run_sweeps(
    a: &Args,
    config: &SimConfig,
    gaze: Option<&sim::gaze_drive::GazeDrive>,
) -> Result<u8, CliError> {
    if a.trials_csv.is_some() || a.export_json.is_some() || a.export_csv.is_some() {
        return Err(CliError::input(
            "--sweep prints its tables on stdout: --trials-csv, --export-json and --export-csv are not available with it",
        ));
    }
    if a.sweep_trials.is_some() {
        return Err(CliError::input(
            "--sweep-trials sets the trials of the report's sweeps: use --trials without --report",
        ));
    }
    let sweeps = parse_sweeps(&a.sweep)?;
    for sw in &sweeps {
        if let Some(why) = sim::sweep::inert(&sw.key, config) {
            return Err(CliError::input(format!("--sweep {}: {why}", sw.key)));
        }
    }
    // Every value is validated before anything runs.
    let configs = sweeps
        .iter()
        .map(|sw| sweep_configs(sw, config))
        .collect::<Result<Vec<_>, _>>()?;
    let mut outputs = Outputs::default();
    outputs.claim_stdout("the sweep tables");
    if let Some(dir) = &a.plots {
        let names: Vec<String> = sweeps
            .iter()
            .flat_map(sim::plots::sweep_file_names)
            .collect();
        outputs.folder("--plots", dir, &names);
    }
    outputs.check()?;
    let mut text = String::new();
    let mut json = Vec::new();
    for (sw, per_value) in sweeps.iter().zip(&configs) {
        let results = match gaze {
            Some(g) => per_value
                .iter()
                .map(|c| sim::gaze_drive::run(c, g, &|| {}))
                .collect::<Result<Vec<_>, _>>(),
            None => sim::run_many(per_value, &|| {}),
        }
        .map_err(sim_error)?;
        if let Some(dir) = &a.plots {
            for (name, bytes) in render_sweep_plot(sw, &results, config)? {
                outputs.set(&dir.join(name), bytes);
            }
        }
        match a.format {
            Format::Json => {
                let values = sw
                    .values
                    .iter()
                    .zip(&results)
                    .map(|(v, r)| {
                        let rows: serde_json::Value =
                            serde_json::from_str(&sim::table::render_json(r)?)?;
                        Ok(serde_json::json!({"value": v, "rows": rows["rows"]}))
                    })
                    .collect::<Result<Vec<_>, serde_json::Error>>()
                    .map_err(|e| CliError::input(e.to_string()))?;
                json.push(serde_json::json!({"key": sw.key, "values": values}));
            }
            _ => {
                text.push_str(&sim::sweep::render_table(sw, &results));
                text.push('\n');
            }
        }
    }
    if a.format == Format::Json {
        text = serde_json::to_string_pretty(&serde_json::json!({ "sweeps": json }))
            .map_err(|e| CliError::input(e.to_string()))?;
        text.push('\n');
    }
    outputs.stdout(text);
    outputs.commit()?;
    if let Some(dir) = &a.plots {
        for sw in &sweeps {
            for name in sim::plots::sweep_file_names(sw) {
                warn(format_args!("wrote {}", dir.join(name).display()));
            }
        }
    }
    Ok(0)
}
