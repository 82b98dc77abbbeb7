//! The real-time pipeline: gaze samples in, one certified profile per LiDAR
//! frame out. **The frame clock drives the fail-safe**: a frame is emitted on
//! every frame period whether or not samples arrive, and each frame is
//! decided from the samples received before it.
//!
//! - **Replay** ([`GazeStream::push_each`]): the frame clock runs on the
//!   sample clock, so a log replays deterministically. Frame `k` starts at
//!   `t0 + k·T` (`t0` the first sample's time, `T` the frame period rounded to
//!   a microsecond) and is decided when the first sample at or after its
//!   start arrives. A gap produces its frames in order (fail-safe once the
//!   held fixation is older than the timeout). When more than
//!   `max_gap_frames + 1` frames fall due at once (a timestamp jump), or time runs
//!   backwards by more than a period, the stream emits **one** fail-safe
//!   frame, reports a [`Notice::Resync`], discards the gaze history and
//!   restarts the frame clock at the sample: work and memory per sample are
//!   bounded whatever the timestamps.
//! - **Live** ([`GazeStream::run_live`]): the frame clock is the wall clock
//!   (from the call). Samples come through a channel; when none arrives the
//!   frames still go out on time, fail-safe once the gaze is stale. A sample's
//!   time on the frame clock is its arrival time, or earlier when its own
//!   timestamps show it was delayed on the way (the smallest observed
//!   latency, allowed to drift by 0.1 %): never later than its arrival, so
//!   the age of the gaze is never underestimated against the wall clock.
//!
//! Property (REQ-FS-1, REQ-FS-3): no adaptive frame is based on gaze older
//! than the timeout plus one frame — measured on the sample clock in replay
//! and on the wall clock live.

use std::sync::mpsc::{Receiver, RecvTimeoutError, TryRecvError};
use std::time::{Duration, Instant};

use serde::Serialize;

use super::{FramePlanner, PipelineError};
use crate::checker::CertifiedProfile;
use crate::gaze::failsafe::{Due, FailSafe, FailSafeConfig, FrameClock, SampleKind, State};
use crate::gaze::filter::{Class, FilterConfig, GazeFilter};
use crate::gaze::formats::GazeSample;
use crate::text::Num;

/// One emitted frame.
#[derive(Debug, Clone, Serialize)]
pub struct Frame {
    /// Frame start on the frame clock, s: the gaze clock in replay, seconds
    /// since the stream started when live.
    pub t_s: f64,
    /// State the frame ran in.
    pub state: State,
    /// The certified profile (`gaze_deg` null in fail-safe).
    #[serde(flatten)]
    pub profile: CertifiedProfile,
}

/// Stream settings beyond the filter and the fail-safe machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamConfig {
    /// Longest gap in replay, in frame periods without samples, whose frames
    /// are produced: a sample may make at most `max_gap_frames + 1` frames
    /// due; a larger jump emits one fail-safe frame and resynchronizes
    /// (default 200: 10 s at 20 Hz).
    pub max_gap_frames: u64,
}

/// The gaze pipeline's settings: the filter, the fail-safe and the frame
/// clock (`stream` and `replay` alike).
#[derive(Debug, Clone, Copy, Default)]
pub struct PipelineConfig {
    /// Gaze filter.
    pub filter: FilterConfig,
    /// Fail-safe machine.
    pub failsafe: FailSafeConfig,
    /// Stream settings.
    pub stream: StreamConfig,
}

impl Default for StreamConfig {
    fn default() -> Self {
        Self {
            max_gap_frames: 200,
        }
    }
}

/// The pipeline's settings as a user gives them (`stream`'s and `replay`'s
/// options, Python's keywords), before their range checks; the defaults
/// are those of [`PipelineConfig::default`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PipelineOptions {
    /// A fixation older than this when a frame is decided is stale
    /// (fail-safe), ms, in `(0, 1e7)`.
    pub timeout_ms: f64,
    /// I-VT saccade threshold, °/s, in `(0, 1e6)`.
    pub saccade_deg_s: f64,
    /// Consecutive valid samples needed to leave fail-safe, `1..=100000`.
    pub recover_samples: i64,
    /// [`StreamConfig::max_gap_frames`], `0..=1000000`.
    pub max_gap_frames: i64,
}

impl Default for PipelineOptions {
    fn default() -> Self {
        let c = PipelineConfig::default();
        Self {
            timeout_ms: c.failsafe.timeout_us as f64 / 1000.0,
            saccade_deg_s: c.filter.saccade_deg_s,
            recover_samples: i64::from(c.failsafe.recover_samples),
            max_gap_frames: c.stream.max_gap_frames as i64,
        }
    }
}

/// `value` in `(lo, hi)` at the one numeric boundary
/// ([`crate::model::valid::finite`]: finite, zero or normal).
fn between(field: &'static str, value: f64, lo: f64, hi: f64) -> Result<f64, PipelineError> {
    if crate::model::valid::finite(value).is_ok() && value > lo && value < hi {
        Ok(value)
    } else {
        Err(PipelineError::Config {
            field,
            reason: format!(
                "{} must be finite (not subnormal), > {} and < {}",
                Num(value),
                Num(lo),
                Num(hi)
            ),
        })
    }
}

/// `value` in `lo..=hi`, as `T`.
fn int_in<T: TryFrom<i64>>(
    field: &'static str,
    value: i64,
    lo: i64,
    hi: i64,
) -> Result<T, PipelineError> {
    (lo..=hi)
        .contains(&value)
        .then(|| T::try_from(value).ok())
        .flatten()
        .ok_or_else(|| PipelineError::Config {
            field,
            reason: format!("{value} must lie in {lo}..={hi}"),
        })
}

impl PipelineOptions {
    /// Every setting through its range check (the first failing one named
    /// by its field, in the order of the fields); the timeout rounds to
    /// the nearest microsecond, at least one.
    pub fn config(&self) -> Result<PipelineConfig, PipelineError> {
        let timeout_ms = between("timeout_ms", self.timeout_ms, 0.0, 1e7)?;
        let saccade_deg_s = between("saccade_deg_s", self.saccade_deg_s, 0.0, 1e6)?;
        let recover_samples = int_in("recover_samples", self.recover_samples, 1, 100_000)?;
        let max_gap_frames = int_in("max_gap_frames", self.max_gap_frames, 0, 1_000_000)?;
        Ok(PipelineConfig {
            filter: FilterConfig {
                saccade_deg_s,
                ..FilterConfig::default()
            },
            failsafe: FailSafeConfig {
                timeout_us: (timeout_ms * 1000.0).round().max(1.0) as u64,
                recover_samples,
            },
            stream: StreamConfig { max_gap_frames },
        })
    }
}

/// Something the caller should tell the user (the library does not print).
#[derive(Debug, Clone, PartialEq)]
pub enum Notice {
    /// The gaze clock jumped: one fail-safe frame, the frame clock restarted
    /// at `to_s` and the gaze history was discarded.
    Resync {
        /// Previous sample time, s.
        from_s: f64,
        /// The sample that jumped, s.
        to_s: f64,
        /// Frames that fell due at once (0 when time ran backwards).
        frames: u64,
    },
    /// Planning the adaptive profile failed: the frame fell back to the
    /// baseline (fail-safe).
    PlanFallback {
        /// The gaze that could not be planned.
        gaze_deg: f64,
        /// Why.
        error: String,
    },
    /// Live: frames were not emitted on time (the output or the planner was
    /// too slow); the clock skipped them.
    Late {
        /// Frames skipped.
        frames: u64,
    },
}

/// Counts for the end-of-stream summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamStats {
    /// Samples read.
    pub samples: u64,
    /// Samples the tracker marked invalid (or with unusable gaze).
    pub invalid: u64,
    /// Outliers dropped.
    pub outliers: u64,
    /// Frames emitted.
    pub frames: u64,
    /// Frames in fail-safe.
    pub fail_safe_frames: u64,
    /// Clock resynchronizations (timestamp jumps).
    pub resyncs: u64,
    /// Adaptive frames that fell back to the baseline because planning failed.
    pub plan_fallbacks: u64,
    /// Live frames skipped because emission ran late.
    pub late_frames: u64,
}

/// At most this many notices wait for [`GazeStream::take_notices`]; the
/// counters in [`StreamStats`] keep counting.
const MAX_PENDING_NOTICES: usize = 64;

/// Live drift allowance of the latency estimate (0.1 %: far above crystal
/// drift, far below a growing backlog worth noticing).
const LATENCY_DRIFT: f64 = 1e-3;

/// Live: most messages absorbed after a frame's due time before it is
/// decided (a feeder should bound its channel to this size).
pub const LIVE_DRAIN_MAX: usize = 1025;

/// A live input event.
#[derive(Debug)]
pub enum Input {
    /// A parsed sample and the instant it was read.
    Sample(GazeSample, Instant),
    /// The reader failed (e.g. a malformed line in a recorded file): stop.
    Error(crate::gaze::GazeError),
}

/// The pipeline.
pub struct GazeStream<P: FramePlanner> {
    planner: P,
    filter: GazeFilter,
    failsafe: FailSafe,
    config: StreamConfig,
    clock: FrameClock,
    origin_s: Option<f64>,
    last_t_s: Option<f64>,
    stats: StreamStats,
    notices: Vec<Notice>,
    // Live: latency estimate (s) and the arrival it was updated at (s).
    latency: Option<(f64, f64)>,
}

/// Seconds → whole microseconds (saturating; negative → 0).
fn to_us(t_s: f64) -> u64 {
    // `as` saturates and maps NaN to 0.
    (t_s.max(0.0) * 1e6).round() as u64
}

impl<P: FramePlanner> GazeStream<P> {
    /// A pipeline around `planner` with the default [`StreamConfig`].
    pub fn new(planner: P, filter: FilterConfig, failsafe: FailSafeConfig) -> Self {
        Self::with_config(planner, filter, failsafe, StreamConfig::default())
    }

    /// A pipeline around `planner`.
    pub fn with_config(
        planner: P,
        filter: FilterConfig,
        failsafe: FailSafeConfig,
        config: StreamConfig,
    ) -> Self {
        let rate = planner.frame_rate_hz();
        let period_us = if rate.is_finite() && rate > 0.0 {
            to_us(1.0 / rate).max(1)
        } else {
            1
        };
        Self {
            planner,
            filter: GazeFilter::new(filter),
            failsafe: FailSafe::new(failsafe),
            config,
            clock: FrameClock::new(period_us, config.max_gap_frames),
            origin_s: None,
            last_t_s: None,
            stats: StreamStats::default(),
            notices: Vec::new(),
            latency: None,
        }
    }

    /// Counters so far.
    #[must_use]
    pub fn stats(&self) -> StreamStats {
        self.stats
    }

    /// The frame period on the frame clock, µs.
    #[must_use]
    pub fn period_us(&self) -> u64 {
        self.clock.period_us()
    }

    /// Notices since the last call (at most 64 are kept).
    pub fn take_notices(&mut self) -> Vec<Notice> {
        std::mem::take(&mut self.notices)
    }

    fn notice(&mut self, n: Notice) {
        if self.notices.len() < MAX_PENDING_NOTICES {
            self.notices.push(n);
        }
    }

    /// Forgets the gaze (a clock discontinuity): back to fail-safe.
    fn discard_history(&mut self) {
        self.filter.reset();
        self.failsafe = FailSafe::new(self.failsafe.config());
    }

    /// Absorbs one sample at `t_us` on the frame clock.
    fn absorb(&mut self, sample: &GazeSample, t_us: u64) {
        self.stats.samples += 1;
        let kind = match self.filter.push(sample) {
            Class::Invalid => {
                self.stats.invalid += 1;
                SampleKind::Invalid
            }
            Class::Outlier => {
                self.stats.outliers += 1;
                return;
            }
            Class::Fixation => SampleKind::Fixation,
            Class::Saccade => SampleKind::Saccade,
        };
        self.failsafe.on_sample(t_us, kind);
    }

    /// Decides and plans the frame starting at `t_s`, deciding staleness at
    /// `decide_us` on the frame clock.
    fn frame(&mut self, t_s: f64, decide_us: u64) -> Result<Frame, PipelineError> {
        let state = self.failsafe.at_frame(decide_us);
        let gaze = match state {
            State::Adaptive => self.filter.estimate(),
            State::FailSafe => None,
        };
        let (state, profile) = match gaze {
            Some(g) => match self.planner.plan(Some(g)) {
                Ok(p) => (State::Adaptive, p),
                Err(e) => {
                    // The LiDAR must still get a certified frame: the baseline.
                    self.stats.plan_fallbacks += 1;
                    self.notice(Notice::PlanFallback {
                        gaze_deg: g,
                        error: e.to_string(),
                    });
                    (State::FailSafe, self.planner.plan(None)?)
                }
            },
            // Adaptive with no estimate (e.g. only saccades so far) is fail-safe too.
            None => (State::FailSafe, self.planner.plan(None)?),
        };
        self.stats.frames += 1;
        self.stats.fail_safe_frames += u64::from(state == State::FailSafe);
        Ok(Frame {
            t_s,
            state,
            profile,
        })
    }

    fn resync(&mut self, to_s: f64, frames: u64) {
        self.stats.resyncs += 1;
        self.notice(Notice::Resync {
            from_s: self.last_t_s.unwrap_or(to_s),
            to_s,
            frames,
        });
        self.origin_s = Some(to_s);
        self.clock = FrameClock::new(self.clock.period_us(), self.config.max_gap_frames);
        self.discard_history();
    }

    /// Replay: runs the frame clock up to `t_s` on the gaze clock, handing
    /// `emit` every frame that starts at or before it (each decided from the
    /// samples absorbed so far). Returns `t_s` on the frame clock (µs), or
    /// `None` when `t_s` lies before the clock's origin by less than a period.
    fn advance(
        &mut self,
        t_s: f64,
        emit: &mut dyn FnMut(Frame) -> Result<(), PipelineError>,
    ) -> Result<Option<u64>, PipelineError> {
        let period_s = self.clock.period_us() as f64 * 1e-6;
        let origin = *self.origin_s.get_or_insert(t_s);
        let mut rel = t_s - origin;
        if rel < -period_s || !rel.is_finite() {
            // Time ran backwards (a clock reset): restart at this time.
            self.resync(t_s, 0);
            rel = 0.0;
        } else if rel < 0.0 {
            // Before the clock's origin (reordered by less than a period).
            return Ok(None);
        }
        let mut now_us = to_us(rel);
        loop {
            match self.clock.due(now_us) {
                Due::Nothing => break,
                Due::Frame(start_us) => {
                    let origin = self.origin_s.unwrap_or(t_s);
                    let f = self.frame(origin + start_us as f64 * 1e-6, start_us)?;
                    emit(f)?;
                }
                Due::Jump { frames } => {
                    self.resync(t_s, frames);
                    now_us = 0;
                }
            }
        }
        Ok(Some(now_us))
    }

    /// Replay: feeds one sample, handing `emit` the frames that start at or
    /// before it (decided from the samples before it), in order. At most
    /// `max_gap_frames + 1` frames per sample.
    pub fn push_each(
        &mut self,
        sample: &GazeSample,
        emit: &mut dyn FnMut(Frame) -> Result<(), PipelineError>,
    ) -> Result<(), PipelineError> {
        if !sample.t_s.is_finite() {
            self.stats.samples += 1;
            self.stats.outliers += 1;
            return Ok(());
        }
        let now_us = self.advance(sample.t_s, emit)?;
        self.last_t_s = Some(sample.t_s);
        match now_us {
            Some(now_us) => self.absorb(sample, now_us),
            None => {
                // Too old for any frame still to come.
                self.stats.samples += 1;
                self.stats.outliers += 1;
            }
        }
        Ok(())
    }

    /// Replay without a sample: the frame clock reads `now_s` (gaze clock),
    /// and every frame that starts at or before it is handed to `emit`, as
    /// [`push_each`](Self::push_each) would for a sample at `now_s` — so a
    /// silent tracker still gets one frame per period, fail-safe once the
    /// held fixation is older than the timeout. The first call (before any
    /// sample) starts the frame clock at `now_s`. `now_s` must be finite.
    pub fn tick_each(
        &mut self,
        now_s: f64,
        emit: &mut dyn FnMut(Frame) -> Result<(), PipelineError>,
    ) -> Result<(), PipelineError> {
        if !now_s.is_finite() {
            return Err(PipelineError::Config {
                field: "now_s",
                reason: format!("{now_s} is not a finite time in seconds"),
            });
        }
        if self.advance(now_s, emit)?.is_some() {
            self.last_t_s = Some(now_s);
        }
        Ok(())
    }

    /// Replay: [`tick_each`](Self::tick_each) collecting the frames (at most
    /// `max_gap_frames + 1`).
    pub fn tick(&mut self, now_s: f64) -> Result<Vec<Frame>, PipelineError> {
        let mut frames = Vec::new();
        self.tick_each(now_s, &mut |f| {
            frames.push(f);
            Ok(())
        })?;
        Ok(frames)
    }

    /// Replay: [`push_each`](Self::push_each) collecting the frames (at most
    /// `max_gap_frames + 1`).
    pub fn push(&mut self, sample: &GazeSample) -> Result<Vec<Frame>, PipelineError> {
        let mut frames = Vec::new();
        self.push_each(sample, &mut |f| {
            frames.push(f);
            Ok(())
        })?;
        Ok(frames)
    }

    /// Live: absorbs a sample that arrived at `arrival_s` on the frame clock.
    fn absorb_live(&mut self, sample: &GazeSample, arrival_s: f64) {
        if !sample.t_s.is_finite() {
            self.stats.samples += 1;
            self.stats.outliers += 1;
            return;
        }
        let period_s = self.clock.period_us() as f64 * 1e-6;
        if self
            .last_t_s
            .is_some_and(|last| sample.t_s < last - period_s)
        {
            // The tracker's clock ran backwards: its history means nothing now.
            self.resync(sample.t_s, 0);
            self.latency = None;
        }
        self.last_t_s = Some(sample.t_s);
        let observed = arrival_s - sample.t_s;
        let latency = match self.latency {
            Some((l, at)) => observed.min(l + LATENCY_DRIFT * (arrival_s - at).max(0.0)),
            None => observed,
        };
        self.latency = Some((latency, arrival_s));
        let t = sample.t_s + latency;
        // Never later than the arrival (rounding included).
        let t_us = if t.is_finite() {
            to_us(t).min(to_us(arrival_s))
        } else {
            0
        };
        self.absorb(sample, t_us);
    }

    /// Live: emits one frame per period on the wall clock from `start` until
    /// the channel closes (or `emit` fails), each decided from the samples
    /// received before it. Staleness is evaluated when the frame is actually
    /// decided (at or after its nominal start), so a late frame is judged
    /// late. A frame more than one period late is skipped ([`Notice::Late`]).
    /// Notices go to `notify` as they happen.
    pub fn run_live(
        &mut self,
        rx: &Receiver<Input>,
        start: Instant,
        emit: &mut dyn FnMut(Frame) -> Result<(), PipelineError>,
        notify: &mut dyn FnMut(Notice),
    ) -> Result<(), PipelineError> {
        let period_us = self.clock.period_us();
        let since_start = |at: Instant| at.saturating_duration_since(start);
        let mut k: u64 = 0;
        loop {
            let due = start + Duration::from_micros(k.saturating_mul(period_us));
            // Absorb everything that arrives before the frame is due.
            let mut closed = false;
            // Past the due time, take only what a bounded channel can hold
            // (a flood must not starve the frames).
            let mut late_budget = LIVE_DRAIN_MAX;
            loop {
                let now = Instant::now();
                let msg = if now < due {
                    match rx.recv_timeout(due - now) {
                        Ok(m) => Some(m),
                        Err(RecvTimeoutError::Timeout) => None,
                        // The input closed before the frame was due: done.
                        Err(RecvTimeoutError::Disconnected) => return Ok(()),
                    }
                } else if late_budget == 0 {
                    None
                } else {
                    late_budget -= 1;
                    match rx.try_recv() {
                        Ok(m) => Some(m),
                        Err(TryRecvError::Empty) => None,
                        // Closed, but this frame is due: emit it, then stop.
                        Err(TryRecvError::Disconnected) => {
                            closed = true;
                            None
                        }
                    }
                };
                match msg {
                    None => break,
                    Some(Input::Error(e)) => return Err(e.into()),
                    Some(Input::Sample(s, arrival)) => {
                        self.absorb_live(&s, since_start(arrival).as_secs_f64());
                    }
                }
            }
            let now_us = u64::try_from(since_start(Instant::now()).as_micros()).unwrap_or(u64::MAX);
            let current = now_us / period_us;
            if current > k {
                self.stats.late_frames += current - k;
                self.notice(Notice::Late {
                    frames: current - k,
                });
                k = current;
            }
            let start_us = k.saturating_mul(period_us);
            let f = self.frame(start_us as f64 * 1e-6, now_us.max(start_us))?;
            emit(f)?;
            for n in self.take_notices() {
                notify(n);
            }
            if closed {
                return Ok(());
            }
            k = k.saturating_add(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::pipeline::ClosedFormPlanner;
    use crate::planner::Mode;

    fn stream() -> GazeStream<ClosedFormPlanner> {
        GazeStream::new(
            ClosedFormPlanner {
                preset: presets::paper(),
                mode: Mode::Range,
                bins: 36,
            },
            FilterConfig::default(),
            FailSafeConfig::default(),
        )
    }

    fn s(t_s: f64, gaze_deg: f64) -> GazeSample {
        GazeSample {
            t_s,
            gaze_deg,
            valid: true,
        }
    }

    #[test]
    fn tick_runs_the_frame_clock_through_silence() {
        // Ticks at the frame rate after 100 ms of fixations: adaptive frames
        // until the fixation is older than the timeout, then fail-safe; the
        // same frames as one late sample would have produced.
        let feed = |st: &mut GazeStream<ClosedFormPlanner>| {
            let mut frames = Vec::new();
            for k in 0..21 {
                frames.extend(st.push(&s(f64::from(k) * 0.005, 90.0)).unwrap());
            }
            frames
        };
        let mut ticked = stream();
        let mut frames = feed(&mut ticked);
        for k in 1..=10 {
            frames.extend(ticked.tick(0.1 + f64::from(k) * 0.05).unwrap());
        }
        let mut pushed = stream();
        let mut reference = feed(&mut pushed);
        reference.extend(pushed.push(&s(0.6, 90.0)).unwrap());
        let states = |f: &[Frame]| f.iter().map(|f| (f.t_s, f.state)).collect::<Vec<_>>();
        assert_eq!(states(&frames), states(&reference));
        assert_eq!(frames.len(), 13, "frames at 0, 0.05, …, 0.6");
        assert_eq!(
            frames[3].state,
            State::Adaptive,
            "0.15 s: fixation 50 ms old"
        );
        assert_eq!(
            frames[4].state,
            State::Adaptive,
            "0.20 s: 100 ms, not older"
        );
        assert_eq!(frames[5].state, State::FailSafe, "0.25 s: stale");
        assert!(frames[5..].iter().all(|f| f.state == State::FailSafe));
        assert!(frames[5].profile.profile().gaze_deg.is_none());
        assert!(ticked.tick(f64::NAN).is_err());
        // A tick before any sample starts the clock: one fail-safe frame.
        let f = stream().tick(3.0).unwrap();
        assert_eq!(states(&f), vec![(3.0, State::FailSafe)]);
    }

    #[test]
    fn a_gap_produces_its_frames_and_goes_fail_safe() {
        let mut st = stream();
        let mut frames = Vec::new();
        for k in 0..21 {
            frames.extend(st.push(&s(f64::from(k) * 0.005, 90.0)).unwrap());
        }
        // 2 s of silence, then one sample: every frame in between, in order.
        frames.extend(st.push(&s(2.1, 90.0)).unwrap());
        assert_eq!(frames.len(), 43, "frames at 0, 0.05, …, 2.1");
        for w in frames.windows(2) {
            assert!((w[1].t_s - w[0].t_s - 0.05).abs() < 1e-9);
        }
        // Last fixation at 0.1 s: adaptive at most until 0.2 s (timeout 100 ms).
        for f in &frames {
            if f.t_s > 0.2 + 1e-9 {
                assert_eq!(f.state, State::FailSafe, "t = {}", f.t_s);
            }
        }
        assert!(frames
            .iter()
            .any(|f| f.state == State::Adaptive && f.t_s > 0.09));
        assert!(st.take_notices().is_empty());
    }

    #[test]
    fn a_jump_emits_one_fail_safe_frame_and_resynchronizes() {
        let mut st = stream();
        for k in 0..21 {
            st.push(&s(f64::from(k) * 0.005, 90.0)).unwrap();
        }
        let f = st.push(&s(1e9, 90.0)).unwrap();
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].state, State::FailSafe);
        assert_eq!(f[0].t_s, 1e9);
        assert!(matches!(
            st.take_notices()[..],
            [Notice::Resync { frames, .. }] if frames > 200
        ));
        // Recovers on the new clock.
        let mut adaptive = 0;
        for k in 1..40 {
            adaptive += st
                .push(&s(1e9 + f64::from(k) * 0.005, 90.0))
                .unwrap()
                .iter()
                .filter(|f| f.state == State::Adaptive)
                .count();
        }
        assert!(adaptive >= 2);
        // Backwards by a second: resync too.
        let f = st.push(&s(1e9 - 1.0, 90.0)).unwrap();
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].state, State::FailSafe);
        assert_eq!(st.stats().resyncs, 2);
    }

    #[test]
    fn saccades_do_not_refresh_a_held_fixation() {
        let mut st = stream();
        let mut worst: f64 = 0.0;
        for k in 0..600 {
            let t = f64::from(k) * 0.005;
            let truth = 90.0 + 60.0 * t;
            for f in st.push(&s(t, truth)).unwrap() {
                if f.state == State::Adaptive {
                    let g = f.profile.profile().gaze_deg.unwrap();
                    let true_at_frame_end = 90.0 + 60.0 * (f.t_s + 0.05);
                    worst = worst.max(crate::model::angle::diff_deg(g, true_at_frame_end).abs());
                }
            }
        }
        // Held fixation at most timeout + one frame old: 60°/s · 0.15 s.
        assert!(worst <= 9.0 + 1e-9, "{worst}");
        assert!(st.stats().fail_safe_frames >= 55);
    }

    #[test]
    fn live_samples_are_never_younger_than_their_arrival() {
        // Samples 5 ms apart by their timestamps, but the last ones arrive
        // 0.4 s late (a backlog upstream): their gaze is 0.4 s old.
        let mut st = stream();
        for k in 0..10 {
            st.absorb_live(&s(f64::from(k) * 0.005, 90.0), f64::from(k) * 0.005);
        }
        for k in 10..20 {
            st.absorb_live(&s(f64::from(k) * 0.005, 90.0), 0.4 + f64::from(k) * 0.005);
        }
        // 95 ms by its timestamp, plus the 0.1 % drift allowance over 0.5 s.
        let lf = st.failsafe.last_fixation_us().unwrap();
        assert!((95_000..=95_500).contains(&lf), "{lf}");
        assert_eq!(st.frame(0.5, 500_000).unwrap().state, State::FailSafe);
        // A tracker clock jumping ahead: the arrival bounds the sample's time.
        let mut st = stream();
        st.absorb_live(&s(0.0, 90.0), 0.0);
        st.absorb_live(&s(1000.0, 90.0), 0.01);
        assert_eq!(st.failsafe.last_fixation_us(), Some(10_000));
        // Running backwards: history discarded, latency re-anchored.
        st.absorb_live(&s(5.0, 90.0), 0.02);
        assert_eq!(st.stats().resyncs, 1);
        assert_eq!(st.failsafe.last_fixation_us(), Some(20_000));
    }

    #[test]
    fn options_check_every_setting_by_name() {
        // The defaults are the configuration's defaults.
        let c = PipelineOptions::default().config().unwrap();
        let d = PipelineConfig::default();
        assert_eq!(c.failsafe, d.failsafe);
        assert_eq!(c.stream, d.stream);
        assert_eq!(c.filter, d.filter);
        // The timeout rounds to the nearest microsecond, at least one.
        let timeout_us = |timeout_ms| {
            PipelineOptions {
                timeout_ms,
                ..PipelineOptions::default()
            }
            .config()
            .unwrap()
            .failsafe
            .timeout_us
        };
        assert_eq!(timeout_us(0.0015), 2);
        assert_eq!(timeout_us(1e-6), 1);
        assert_eq!(timeout_us(250.0), 250_000);
        let bad = |o: PipelineOptions| match o.config() {
            Err(PipelineError::Config { field, reason }) => (field, reason),
            other => panic!("{other:?}"),
        };
        let o = PipelineOptions::default();
        for (field, options, reason) in [
            (
                "timeout_ms",
                PipelineOptions {
                    timeout_ms: 0.0,
                    ..o
                },
                "0 must be finite (not subnormal), > 0 and < 1e7",
            ),
            (
                "timeout_ms",
                PipelineOptions {
                    timeout_ms: f64::NAN,
                    ..o
                },
                "must be finite",
            ),
            (
                "saccade_deg_s",
                PipelineOptions {
                    saccade_deg_s: 5e-324,
                    ..o
                },
                "not subnormal",
            ),
            (
                "recover_samples",
                PipelineOptions {
                    recover_samples: 0,
                    ..o
                },
                "0 must lie in 1..=100000",
            ),
            (
                "max_gap_frames",
                PipelineOptions {
                    max_gap_frames: -1,
                    ..o
                },
                "-1 must lie in 0..=1000000",
            ),
        ] {
            let (f, r) = bad(options);
            assert_eq!(f, field);
            assert!(r.contains(reason), "{field}: {r}");
        }
        // The first bad setting, in the order of the fields, is named.
        let (f, _) = bad(PipelineOptions {
            timeout_ms: -1.0,
            max_gap_frames: -1,
            ..o
        });
        assert_eq!(f, "timeout_ms");
    }

    #[test]
    fn absurd_gaze_is_invalid() {
        let mut st = stream();
        for k in 0..10 {
            st.push(&s(f64::from(k) * 0.005, 1e300)).unwrap();
        }
        assert_eq!(st.stats().invalid, 10);
    }
}
