//! `gaze-lidar stream`: gaze samples in, one certified profile per frame out.

use std::io::{BufRead, Write};
use std::path::PathBuf;

use gaze_lidar::gaze::{
    ClosedFormPlanner, FailSafeConfig, FilterConfig, Format, FramePlanner, GazeStream, Parser,
};
use gaze_lidar::model::presets;
use gaze_lidar::planner::Mode;

use super::CliError;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// LiDAR preset (closed-form controllers).
    #[arg(long, default_value = "paper")]
    preset: String,
    /// Controller for the closed form (default range); with --config, overrides the objective mode.
    #[arg(long, value_enum)]
    mode: Option<Mode>,
    /// Equal bins.
    #[arg(long, default_value_t = 360)]
    bins: usize,
    /// Optimizer configuration (TOML): plan with the optimizer's fast path.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Input format.
    #[arg(long, value_enum, default_value_t = Format::Jsonl)]
    format: Format,
    /// Read a recorded file instead of stdin (a malformed line is then an error).
    #[arg(long)]
    input: Option<PathBuf>,
    /// Gaze older than this at a frame start is stale (fail-safe), ms.
    #[arg(long, default_value_t = 100.0)]
    timeout_ms: f64,
    /// Consecutive valid samples needed to leave fail-safe.
    #[arg(long, default_value_t = 4)]
    recover_samples: u32,
    /// I-VT saccade threshold, °/s.
    #[arg(long, default_value_t = 30.0)]
    saccade_deg_s: f64,
    /// Pace the output by the wall clock (live use); default: as fast as input comes.
    #[arg(long)]
    realtime: bool,
}

fn planner(a: &Args) -> Result<Box<dyn FramePlanner>, CliError> {
    if let Some(path) = &a.config {
        return optimizer_planner(a, path);
    }
    let preset =
        presets::preset(&a.preset).map_err(|e| CliError::input(format!("--preset: {e}")))?;
    if !(gaze_lidar::model::angle::MIN_BINS..=gaze_lidar::model::angle::MAX_BINS).contains(&a.bins)
    {
        return Err(CliError::input(format!(
            "--bins: {} must lie in [4, 36000]",
            a.bins
        )));
    }
    Ok(Box::new(ClosedFormPlanner {
        preset,
        mode: a.mode.unwrap_or(Mode::Range),
        bins: a.bins,
    }))
}

#[cfg(feature = "solver")]
fn optimizer_planner(a: &Args, path: &std::path::Path) -> Result<Box<dyn FramePlanner>, CliError> {
    use gaze_lidar::optimizer::OptimizerConfig;
    let mut problem = OptimizerConfig::read(path)
        .and_then(|c| c.problem())
        .map_err(|e| CliError::input(e.to_string()))?;
    if let Some(m) = a.mode {
        problem.objective.mode = m;
    }
    let p = gaze_lidar::gaze::OptimizerPlanner::new(problem).map_err(CliError::infeasible)?;
    Ok(Box::new(p))
}

#[cfg(not(feature = "solver"))]
fn optimizer_planner(
    _a: &Args,
    _path: &std::path::Path,
) -> Result<Box<dyn FramePlanner>, CliError> {
    Err(CliError::input(
        "--config: this build has no solver (enable the `solver` feature)",
    ))
}

struct Boxed(Box<dyn FramePlanner>);

impl FramePlanner for Boxed {
    fn plan(
        &mut self,
        gaze_deg: Option<f64>,
    ) -> Result<gaze_lidar::checker::CertifiedProfile, String> {
        self.0.plan(gaze_deg)
    }
    fn frame_rate_hz(&self) -> f64 {
        self.0.frame_rate_hz()
    }
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    if !(a.timeout_ms.is_finite() && a.timeout_ms > 0.0 && a.timeout_ms < 1e7) {
        return Err(CliError::input(format!(
            "--timeout-ms: {} must be finite and > 0",
            a.timeout_ms
        )));
    }
    if !(a.saccade_deg_s.is_finite() && a.saccade_deg_s > 0.0) {
        return Err(CliError::input(format!(
            "--saccade-deg-s: {} must be finite and > 0",
            a.saccade_deg_s
        )));
    }
    let planner = Boxed(planner(a)?);
    let filter = FilterConfig {
        saccade_deg_s: a.saccade_deg_s,
        ..FilterConfig::default()
    };
    let failsafe = FailSafeConfig {
        timeout_us: (a.timeout_ms * 1000.0) as u64,
        recover_samples: a.recover_samples,
    };
    let mut stream = GazeStream::new(planner, filter, failsafe);
    let (reader, origin, strict): (Box<dyn BufRead>, String, bool) = match &a.input {
        Some(path) => {
            let f = std::fs::File::open(path)
                .map_err(|e| CliError::input(format!("{}: {e}", path.display())))?;
            (
                Box::new(std::io::BufReader::new(f)),
                path.display().to_string(),
                true,
            )
        }
        None => (
            Box::new(std::io::stdin().lock()),
            "<stdin>".to_owned(),
            false,
        ),
    };
    let mut parser = Parser::new(a.format);
    let mut out = std::io::stdout().lock();
    let wall0 = std::time::Instant::now();
    let mut first_t: Option<f64> = None;
    for (k, line) in reader.lines().enumerate() {
        let line_no = k + 1;
        let line = match line {
            Ok(l) => l,
            Err(e) => return Err(CliError::input(format!("{origin}:{line_no}: {e}"))),
        };
        let sample = match parser.line(&line) {
            Ok(Some(s)) => s,
            Ok(None) => continue,
            Err(e) if strict => return Err(CliError::input(format!("{origin}:{line_no}: {e}"))),
            Err(e) => {
                eprintln!("gaze-lidar: {origin}:{line_no}: skipped: {e}");
                continue;
            }
        };
        let frames = stream.push(&sample).map_err(CliError::infeasible)?;
        for f in frames {
            if a.realtime {
                let t0 = *first_t.get_or_insert(f.t_s);
                let due = std::time::Duration::from_secs_f64((f.t_s - t0).max(0.0));
                if let Some(wait) = due.checked_sub(wall0.elapsed()) {
                    std::thread::sleep(wait);
                }
            }
            let line = serde_json::to_string(&f).map_err(|e| CliError::input(e.to_string()))?;
            if writeln!(out, "{line}").is_err() {
                // Downstream closed the pipe: stop quietly.
                return Ok(0);
            }
        }
    }
    let _ = out.flush();
    let s = stream.stats();
    eprintln!(
        "gaze-lidar: {} samples ({} invalid, {} outliers) → {} frames, {} in fail-safe",
        s.samples, s.invalid, s.outliers, s.frames, s.fail_safe_frames
    );
    Ok(0)
}
