//! `gaze-lidar stream`: gaze samples in, one certified profile per frame out.
//!
//! Replay (default): the frame clock runs on the samples' timestamps.
//! `--realtime`: the frame clock is the wall clock; a reader thread feeds the
//! samples and frames go out (one flushed line each) whether or not samples
//! arrive — fail-safe once the gaze is stale. Output errors: a closed pipe
//! ends the stream quietly (exit 0); any other write error is one line, exit 1.

use std::io::{BufRead, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

use gaze_lidar::gaze::{Format, GazeError, GazeSample, LineError, Parser};
use gaze_lidar::pipeline::{
    Frame, FramePlanner, GazeStream, Input, Notice, PipelineConfig, PipelineError, StreamStats,
    LIVE_DRAIN_MAX,
};
use gaze_lidar::text::Num;

use super::gaze_args::{gaze_error, FilterArgs, PlanArgs};
use super::io::warn;
use super::CliError;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    plan: PlanArgs,
    /// Input format.
    #[arg(long, value_parser = super::args::named::<Format>(), default_value_t = Format::Jsonl)]
    format: Format,
    /// Read a recorded file instead of stdin (a malformed line is then an
    /// error; on stdin it is reported with its number and skipped).
    #[arg(long)]
    input: Option<PathBuf>,
    #[command(flatten)]
    filter: FilterArgs,
    /// Live: frames on the wall clock (t_s = seconds since start), fail-safe
    /// frames while no fresh gaze arrives, one flushed line per frame. With
    /// --input, the file is fed at the pace of its timestamps.
    #[arg(long)]
    realtime: bool,
}

fn report(notices: Vec<Notice>, max_gap_frames: u64, live: bool) {
    for n in notices {
        match n {
            // Live, the frame clock is the wall clock: it never restarts
            // and no extra frame is emitted; only the gaze history goes.
            Notice::Resync { from_s, to_s, .. } if live => warn(format!(
                "warning: gaze clock ran backwards from {} s to {} s: gaze history discarded (fail-safe until the gaze recovers)",
                Num(from_s),
                Num(to_s)
            )),
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
                warn(format!(
                    "warning: gaze clock jumped from {} s to {} s and {why}: one fail-safe frame, frame clock restarted at {} s, gaze history discarded",
                    Num(from_s),
                    Num(to_s),
                    Num(to_s)
                ));
            }
            Notice::PlanFallback { gaze_deg, error } => warn(format!(
                "warning: no certified adaptive profile for gaze {}°, baseline instead: {error}",
                Num(gaze_deg)
            )),
            Notice::Late { frames } => warn(format!(
                "warning: output ran late, {frames} frame(s) skipped"
            )),
        }
    }
}

fn write_frame(out: &mut dyn Write, f: &Frame, flush: bool) -> Result<(), PipelineError> {
    let mut line = serde_json::to_string(f)
        .map_err(|e| PipelineError::Output(std::io::Error::other(e.to_string())))?;
    line.push('\n');
    out.write_all(line.as_bytes())
        .map_err(PipelineError::Output)?;
    if flush {
        out.flush().map_err(PipelineError::Output)?;
    }
    Ok(())
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let settings = a.filter.settings()?;
    let (planner, _) = a.plan.planner()?;
    let stream =
        GazeStream::with_config(planner, settings.filter, settings.failsafe, settings.stream);
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
    let skipped = Arc::new(AtomicU64::new(0));
    let source = Source {
        reader,
        origin,
        strict,
        parser: Parser::new(a.format),
        line_no: 0,
        buf: Vec::new(),
        skipped: Arc::clone(&skipped),
    };
    let result = if a.realtime {
        live(a, &settings, stream, source)
    } else {
        replay(&settings, stream, source)
    };
    match result {
        Ok(stats) => {
            let skipped = skipped.load(Ordering::Relaxed);
            warn(format!(
                "{} samples ({} invalid, {} outliers) → {} frames, {} in fail-safe{}{}",
                stats.samples,
                stats.invalid,
                stats.outliers,
                stats.frames,
                stats.fail_safe_frames,
                if stats.resyncs > 0 {
                    format!(", {} clock resynchronizations", stats.resyncs)
                } else {
                    String::new()
                },
                if skipped > 0 {
                    format!(", {skipped} malformed lines skipped")
                } else {
                    String::new()
                }
            ));
            Ok(0)
        }
        // Downstream closed the pipe (`| head`): stop quietly.
        Err(PipelineError::Output(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(0),
        Err(PipelineError::Output(e)) => Err(CliError::output(format!("stdout: {e}"))),
        Err(e) => Err(gaze_error(e)),
    }
}

/// Longest input line accepted (a gaze sample is well under 1 KiB).
const MAX_LINE_BYTES: usize = 64 * 1024;

struct Source {
    reader: Box<dyn BufRead + Send>,
    origin: String,
    strict: bool,
    parser: Parser,
    line_no: usize,
    /// The current line's bytes (at most `MAX_LINE_BYTES`).
    buf: Vec<u8>,
    /// Lines reported and skipped (live input only).
    skipped: Arc<AtomicU64>,
}

/// One line of input, read as bytes.
enum RawLine {
    /// The end of the input.
    End,
    /// A whole line (newline included, if any) of at most `MAX_LINE_BYTES`.
    Line,
    /// A line longer than `MAX_LINE_BYTES`: its first bytes are kept, the
    /// rest was read and dropped up to its newline (memory stays bounded).
    TooLong,
}

impl Source {
    /// Reads one line into `buf` as bytes, never holding more than
    /// `MAX_LINE_BYTES` of it.
    fn read_raw(&mut self) -> std::io::Result<RawLine> {
        self.buf.clear();
        let mut any = false;
        let mut too_long = false;
        loop {
            let available = match self.reader.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if available.is_empty() {
                break;
            }
            any = true;
            let (n, newline) = match available.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (available.len(), false),
            };
            if !too_long {
                if self.buf.len() + n > MAX_LINE_BYTES {
                    too_long = true;
                } else {
                    self.buf.extend_from_slice(&available[..n]);
                }
            }
            self.reader.consume(n);
            if newline {
                break;
            }
        }
        Ok(match (any, too_long) {
            (false, _) => RawLine::End,
            (true, false) => RawLine::Line,
            (true, true) => RawLine::TooLong,
        })
    }

    /// The next sample, `Ok(None)` at the end of the input. A line that is
    /// not a sample (too long, not UTF-8, a byte-order mark, malformed) is
    /// an error in a recorded file and a skipped line, reported with its
    /// number, on stdin.
    fn next(&mut self) -> Result<Option<GazeSample>, GazeError> {
        loop {
            self.line_no += 1;
            let raw = self.read_raw().map_err(|source| GazeError::Read {
                origin: self.origin.clone(),
                line: self.line_no,
                source,
            })?;
            let parsed = match raw {
                RawLine::End => return Ok(None),
                RawLine::TooLong => Err(LineError::Bytes(format!(
                    "line longer than {MAX_LINE_BYTES} bytes (not a gaze sample)"
                ))),
                RawLine::Line => self.parse_line(),
            };
            match parsed {
                Ok(Some(s)) => return Ok(Some(s)),
                Ok(None) => {}
                Err(source) if self.strict => {
                    return Err(GazeError::Line {
                        origin: self.origin.clone(),
                        line: self.line_no,
                        source,
                    })
                }
                Err(e) => {
                    self.skipped.fetch_add(1, Ordering::Relaxed);
                    warn(format!("{}:{}: skipped: {e}", self.origin, self.line_no));
                }
            }
        }
    }

    fn parse_line(&mut self) -> Result<Option<GazeSample>, LineError> {
        if self.line_no == 1 && self.buf.starts_with(super::io::UTF8_BOM) {
            return Err(LineError::Bytes(
                "starts with a UTF-8 byte-order mark (bytes EF BB BF): send the data without a BOM"
                    .into(),
            ));
        }
        match std::str::from_utf8(&self.buf) {
            Ok(text) => self.parser.line(text),
            Err(e) => Err(LineError::Bytes(format!(
                "not UTF-8 text (invalid byte 0x{:02X} at column {})",
                self.buf[e.valid_up_to()],
                e.valid_up_to() + 1
            ))),
        }
    }
}

type Stats = StreamStats;

fn replay(
    s: &PipelineConfig,
    mut stream: GazeStream<Box<dyn FramePlanner>>,
    mut source: Source,
) -> Result<Stats, PipelineError> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut emit = |f: Frame| write_frame(&mut out, &f, false);
    while let Some(sample) = source.next()? {
        let r = stream.push_each(&sample, &mut emit);
        report(stream.take_notices(), s.stream.max_gap_frames, false);
        r?;
    }
    out.flush().map_err(PipelineError::Output)?;
    Ok(stream.stats())
}

fn live(
    a: &Args,
    s: &PipelineConfig,
    mut stream: GazeStream<Box<dyn FramePlanner>>,
    mut source: Source,
) -> Result<Stats, PipelineError> {
    // Bounded: a reader far ahead of the frames (a file piped in) waits
    // instead of holding the whole input in memory.
    let (tx, rx) = mpsc::sync_channel(LIVE_DRAIN_MAX - 1);
    let pace = a.input.is_some();
    // A recorded file is fed at the pace of its timestamps; a gap longer
    // than a replay jump (max_gap_frames + 1 periods) is not waited for.
    let max_wait = Duration::from_micros(
        stream
            .period_us()
            .saturating_mul(s.stream.max_gap_frames.saturating_add(1)),
    );
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
    let max_gap = s.stream.max_gap_frames;
    stream.run_live(
        &rx,
        start,
        &mut |f: Frame| write_frame(&mut out, &f, true),
        &mut |n| report(vec![n], max_gap, true),
    )?;
    Ok(stream.stats())
}
