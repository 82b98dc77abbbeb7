//! The real-time pipeline: gaze samples in, one certified profile per LiDAR
//! frame out. Frames are driven by the gaze timestamps (not the wall clock),
//! so a log replays deterministically: frame `k` starts at `t0 + k·T`
//! (`t0` the first sample's time) and is decided when the first sample at
//! or after its start arrives, from the samples before it.

use serde::Serialize;

use super::failsafe::{FailSafe, FailSafeConfig, State};
use super::filter::{Class, FilterConfig, GazeFilter};
use super::formats::GazeSample;
use crate::checker::CertifiedProfile;

/// Something that turns a gaze (or none: fail-safe) into a certified profile.
pub trait FramePlanner {
    /// The profile for `gaze_deg`; `None` asks for the uniform baseline.
    fn plan(&mut self, gaze_deg: Option<f64>) -> Result<CertifiedProfile, String>;
    /// Nominal frame rate, Hz.
    fn frame_rate_hz(&self) -> f64;
}

/// One emitted frame.
#[derive(Debug, Clone, Serialize)]
pub struct Frame {
    /// Frame start (gaze clock), s.
    pub t_s: f64,
    /// State the frame ran in.
    pub state: State,
    /// The certified profile (`gaze_deg` null in fail-safe).
    #[serde(flatten)]
    pub profile: CertifiedProfile,
}

/// Counts for the end-of-stream summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamStats {
    /// Samples read.
    pub samples: u64,
    /// Samples the tracker marked invalid.
    pub invalid: u64,
    /// Outliers dropped.
    pub outliers: u64,
    /// Frames emitted.
    pub frames: u64,
    /// Frames in fail-safe.
    pub fail_safe_frames: u64,
}

/// The pipeline.
pub struct GazeStream<P: FramePlanner> {
    planner: P,
    filter: GazeFilter,
    failsafe: FailSafe,
    period_s: f64,
    t0: Option<f64>,
    next_frame: u64,
    stats: StreamStats,
}

fn to_us(t_s: f64) -> u64 {
    // Times are relative to the first sample, so non-negative and small.
    (t_s.max(0.0) * 1e6).round() as u64
}

impl<P: FramePlanner> GazeStream<P> {
    /// A pipeline around `planner`.
    pub fn new(planner: P, filter: FilterConfig, failsafe: FailSafeConfig) -> Self {
        let period_s = 1.0 / planner.frame_rate_hz();
        Self {
            planner,
            filter: GazeFilter::new(filter),
            failsafe: FailSafe::new(failsafe),
            period_s,
            t0: None,
            next_frame: 0,
            stats: StreamStats::default(),
        }
    }

    /// Counters so far.
    #[must_use]
    pub fn stats(&self) -> StreamStats {
        self.stats
    }

    /// Feeds one sample; returns the frames that start at or before it.
    pub fn push(&mut self, sample: &GazeSample) -> Result<Vec<Frame>, String> {
        let t0 = *self.t0.get_or_insert(sample.t_s);
        let rel = sample.t_s - t0;
        let mut frames = Vec::new();
        loop {
            let start = self.next_frame as f64 * self.period_s;
            if start > rel + 1e-12 {
                break;
            }
            let state = self.failsafe.at_frame(to_us(start));
            let gaze = match state {
                State::Adaptive => self.filter.estimate(),
                State::FailSafe => None,
            };
            // Adaptive with no estimate (e.g. only saccades so far) is fail-safe too.
            let state = if gaze.is_none() {
                State::FailSafe
            } else {
                state
            };
            let profile = self.planner.plan(gaze)?;
            self.stats.frames += 1;
            self.stats.fail_safe_frames += u64::from(state == State::FailSafe);
            frames.push(Frame {
                t_s: t0 + start,
                state,
                profile,
            });
            self.next_frame += 1;
        }
        self.stats.samples += 1;
        match self.filter.push(sample) {
            Class::Invalid => {
                self.stats.invalid += 1;
                self.failsafe.on_sample(to_us(rel), false);
            }
            Class::Outlier => self.stats.outliers += 1,
            Class::Fixation | Class::Saccade => self.failsafe.on_sample(to_us(rel), true),
        }
        Ok(frames)
    }
}
