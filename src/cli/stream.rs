//! `gaze-lidar stream`: gaze samples in, one certified profile per frame out.
//!
//! Replay (default): the frame clock runs on the samples' timestamps.
//! `--realtime`: the frame clock is the wall clock; a reader thread feeds the
//! samples and frames go out (one flushed line each) whether or not samples
//! arrive — fail-safe once the gaze is stale. Output errors: a closed pipe
//! ends the stream quietly (exit 0); any other write error is one line, exit 1.

use std::io::{BufRead, Read, Write};
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use gaze_lidar::gaze::{
    ClosedFormPlanner, FailSafeConfig, FilterConfig, Format, Frame, FramePlanner, GazeError,
    GazeStream, Input, Notice, Parser, StreamConfig,
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
    /// A fixation older than this when a frame is decided is stale (fail-safe), ms.
    #[arg(long, default_value_t = 100.0, allow_negative_numbers = true)]
    timeout_ms: f64,
    /// Consecutive valid samples needed to leave fail-safe.
    #[arg(long, default_value_t = 4)]
    recover_samples: u32,
    /// I-VT saccade threshold, °/s.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    saccade_deg_s: f64,
    /// Replay: a timestamp jump making more than this many frames (plus the
    /// one at the sample) due at once emits one fail-safe frame, a warning,
    /// and restarts the frame clock.
    #[arg(long, default_value_t = 200)]
    max_gap_frames: u64,
    /// Live: frames on the wall clock (t_s = seconds since start), fail-safe
    /// frames while no fresh gaze arrives, one flushed line per frame. With
    /// --input, the file is fed at the pace of its timestamps.
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

fn cli_error(e: GazeError) -> CliError {
    if e.is_input_error() {
        CliError::input(e.to_string())
    } else {
        CliError::infeasible(e.to_string())
    }
}

#[cfg(feature = "solver")]
fn optimizer_planner(a: &Args, path: &std::path::Path) -> Result<Box<dyn FramePlanner>, CliError> {
    use gaze_lidar::optimizer::OptimizerConfig;
    let mut problem = OptimizerConfig::read(path)
        .and_then(|c| c.problem())
        .map_err(|e| cli_error(e.into()))?;
    if let Some(m) = a.mode {
        problem.objective.mode = m;
    }
    let p = gaze_lidar::gaze::OptimizerPlanner::new(problem).map_err(cli_error)?;
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

/// One line on stderr; a failing stderr is not worth dying for.
fn warn(message: &str) {
    let _ = writeln!(std::io::stderr().lock(), "gaze-lidar: {message}");
}

fn report(notices: Vec<Notice>, max_gap_frames: u64) {
    for n in notices {
        match n {
            Notice::Resync {
                from_s,
                to_s,
                frames,
            } => {
                let why = if frames == 0 {
                    "ran backwards".to_owned()
                } else {
                    format!("made {frames} frames due (more than --max-gap-frames {max_gap_frames} + 1)")
                };
                warn(&format!(
                    "warning: gaze clock jumped from {from_s} s to {to_s} s and {why}: one fail-safe frame, frame clock restarted at {to_s} s, gaze history discarded"
                ));
            }
            Notice::PlanFallback { gaze_deg, error } => warn(&format!(
                "warning: no certified adaptive profile for gaze {gaze_deg}°, baseline instead: {error}"
            )),
            Notice::Late { frames } => warn(&format!(
                "warning: output ran late, {frames} frame(s) skipped"
            )),
        }
    }
}

fn write_frame(out: &mut dyn Write, f: &Frame, flush: bool) -> Result<(), GazeError> {
    let mut line = serde_json::to_string(f)
        .map_err(|e| GazeError::Output(std::io::Error::other(e.to_string())))?;
    line.push('\n');
    out.write_all(line.as_bytes()).map_err(GazeError::Output)?;
    if flush {
        out.flush().map_err(GazeError::Output)?;
    }
    Ok(())
}

fn validate(a: &Args) -> Result<(), CliError> {
    if !(a.timeout_ms.is_finite() && a.timeout_ms > 0.0 && a.timeout_ms < 1e7) {
        return Err(CliError::input(format!(
            "--timeout-ms: {} must be finite, > 0 and < 1e7",
            a.timeout_ms
        )));
    }
    if !(a.saccade_deg_s.is_finite() && a.saccade_deg_s > 0.0) {
        return Err(CliError::input(format!(
            "--saccade-deg-s: {} must be finite and > 0",
            a.saccade_deg_s
        )));
    }
    if a.max_gap_frames > 1_000_000 {
        return Err(CliError::input(format!(
            "--max-gap-frames: {} must be at most 1000000",
            a.max_gap_frames
        )));
    }
    Ok(())
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    validate(a)?;
    let planner = planner(a)?;
    let filter = FilterConfig {
        saccade_deg_s: a.saccade_deg_s,
        ..FilterConfig::default()
    };
    let failsafe = FailSafeConfig {
        timeout_us: (a.timeout_ms * 1000.0) as u64,
        recover_samples: a.recover_samples,
    };
    let config = StreamConfig {
        max_gap_frames: a.max_gap_frames,
    };
    let stream = GazeStream::with_config(planner, filter, failsafe, config);
    let (reader, origin, strict): (Box<dyn BufRead + Send>, String, bool) = match &a.input {
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
            Box::new(std::io::BufReader::new(std::io::stdin())),
            "<stdin>".to_owned(),
            false,
        ),
    };
    let source = Source {
        reader,
        origin,
        strict,
        parser: Parser::new(a.format),
        line_no: 0,
    };
    let result = if a.realtime {
        live(a, stream, source)
    } else {
        replay(a, stream, source)
    };
    match result {
        Ok(stats) => {
            warn(&format!(
                "{} samples ({} invalid, {} outliers) → {} frames, {} in fail-safe{}",
                stats.samples,
                stats.invalid,
                stats.outliers,
                stats.frames,
                stats.fail_safe_frames,
                if stats.resyncs > 0 {
                    format!(", {} clock resynchronizations", stats.resyncs)
                } else {
                    String::new()
                }
            ));
            Ok(0)
        }
        // Downstream closed the pipe (`| head`): stop quietly.
        Err(GazeError::Output(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(0),
        Err(GazeError::Output(e)) => Err(CliError::infeasible(format!("stdout: {e}"))),
        Err(e) => Err(cli_error(e)),
    }
}

/// Longest input line accepted (a gaze sample is well under 1 KiB).
const MAX_LINE_BYTES: u64 = 64 * 1024;

struct Source {
    reader: Box<dyn BufRead + Send>,
    origin: String,
    strict: bool,
    parser: Parser,
    line_no: usize,
}

impl Source {
    /// The next sample, `Ok(None)` at the end of the input.
    fn next(&mut self) -> Result<Option<gaze_lidar::gaze::GazeSample>, GazeError> {
        let mut line = String::new();
        loop {
            line.clear();
            self.line_no += 1;
            let read_error = |line_no, source| GazeError::Read {
                origin: self.origin.clone(),
                line: line_no,
                source,
            };
            let n = self
                .reader
                .by_ref()
                .take(MAX_LINE_BYTES + 1)
                .read_line(&mut line)
                .map_err(|e| read_error(self.line_no, e))?;
            if n == 0 {
                return Ok(None);
            }
            if n as u64 > MAX_LINE_BYTES {
                return Err(read_error(
                    self.line_no,
                    std::io::Error::other(format!(
                        "line longer than {MAX_LINE_BYTES} bytes (not a gaze sample)"
                    )),
                ));
            }
            match self.parser.line(&line) {
                Ok(Some(s)) => return Ok(Some(s)),
                Ok(None) => {}
                Err(source) if self.strict => {
                    return Err(GazeError::Line {
                        origin: self.origin.clone(),
                        line: self.line_no,
                        source,
                    })
                }
                Err(e) => warn(&format!("{}:{}: skipped: {e}", self.origin, self.line_no)),
            }
        }
    }
}

type Stats = gaze_lidar::gaze::StreamStats;

fn replay(
    a: &Args,
    mut stream: GazeStream<Box<dyn FramePlanner>>,
    mut source: Source,
) -> Result<Stats, GazeError> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut emit = |f: Frame| write_frame(&mut out, &f, false);
    while let Some(sample) = source.next()? {
        let r = stream.push_each(&sample, &mut emit);
        report(stream.take_notices(), a.max_gap_frames);
        r?;
    }
    out.flush().map_err(GazeError::Output)?;
    Ok(stream.stats())
}

fn live(
    a: &Args,
    mut stream: GazeStream<Box<dyn FramePlanner>>,
    mut source: Source,
) -> Result<Stats, GazeError> {
    // Bounded: a reader far ahead of the frames (a file piped in) waits
    // instead of holding the whole input in memory.
    let (tx, rx) = mpsc::sync_channel(gaze_lidar::gaze::stream::LIVE_DRAIN_MAX - 1);
    let pace = a.input.is_some();
    let max_wait = Duration::from_micros(stream.period_us().saturating_mul(a.max_gap_frames));
    let start = Instant::now();
    // The reader thread blocks on the input; it ends with the input (closing
    // the channel) or with the process.
    std::thread::spawn(move || {
        // (sample time, wall instant) the pacing of a recorded file is anchored at.
        let mut anchor: Option<(f64, Instant)> = None;
        loop {
            match source.next() {
                Ok(Some(s)) => {
                    if pace {
                        let (t0, w0) = *anchor.get_or_insert((s.t_s, Instant::now()));
                        let ahead = s.t_s - t0;
                        match Duration::try_from_secs_f64(ahead) {
                            Ok(d) if d <= max_wait + (Instant::now() - w0) => {
                                let due = w0 + d;
                                std::thread::sleep(due.saturating_duration_since(Instant::now()));
                            }
                            // A jump or time running backwards: re-anchor, no wait.
                            _ => anchor = Some((s.t_s, Instant::now())),
                        }
                    }
                    if tx.send(Input::Sample(s, Instant::now())).is_err() {
                        return;
                    }
                }
                Ok(None) => return,
                Err(e) => {
                    let _ = tx.send(Input::Error(e));
                    return;
                }
            }
        }
    });
    let mut out = std::io::stdout().lock();
    let max_gap = a.max_gap_frames;
    stream.run_live(
        &rx,
        start,
        &mut |f: Frame| write_frame(&mut out, &f, true),
        &mut |n| report(vec![n], max_gap),
    )?;
    Ok(stream.stats())
}
