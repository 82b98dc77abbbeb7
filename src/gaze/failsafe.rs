//! The gaze fail-safe state machine and the frame clock (specified in
//! `specs/failsafe.md`).
//!
//! Integer core: times in microseconds on the frame clock, counters
//! saturate, no floats.
//!
//! - `FailSafe` → the LiDAR runs the uniform baseline (no sector is
//!   under-scanned on stale information). Initial state.
//! - `Adaptive` → the LiDAR runs the gaze-adapted profile.
//!
//! Transitions:
//! - an invalid sample (tracker lost the eyes, NaN or absurd gaze) →
//!   `FailSafe` at once, the run of valid samples restarts at 0 and the held
//!   fixation is forgotten;
//! - a fixation sample refreshes the gaze (its time becomes the gaze time);
//!   a saccade sample counts as valid (the tracker has the eyes) but does
//!   **not** refresh it: the estimate holds the last fixation, which ages;
//! - at a frame decided at time `t`, if the newest fixation is older than
//!   the timeout (or there is none) → `FailSafe`, and the run of valid
//!   samples restarts at 0: the gaze was lost, so recovery starts over;
//! - a sample arriving when the held fixation is already older than the
//!   timeout likewise → `FailSafe` and restarts the run before it is
//!   counted (a loss no frame happened to observe still needs a full
//!   recovery);
//! - at a frame, from `FailSafe`, with a fresh fixation and at least
//!   `recover_samples` consecutive valid samples → `Adaptive` (hysteresis:
//!   one good sample after a loss is not enough).
//!
//! The frame clock ([`FrameClock`]) emits one frame per period whatever the
//! samples do; when a sample makes more than `max_gap_frames + 1` frames due
//! at once (a gap of more than `max_gap_frames` periods without samples: a
//! timestamp jump) it reports a jump instead, and the stream resynchronizes.

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FailSafeConfig {
    /// A fixation older than this when a frame is decided is stale, µs
    /// (default 100 ms).
    pub timeout_us: u64,
    /// Consecutive valid samples needed to leave fail-safe (default 4: 20 ms at 200 Hz).
    pub recover_samples: u32,
}

impl Default for FailSafeConfig {
    fn default() -> Self {
        Self {
            timeout_us: 100_000,
            recover_samples: 4,
        }
    }
}

/// The two states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    /// Uniform baseline.
    FailSafe,
    /// Gaze-adapted profile.
    Adaptive,
}

/// What one sample was, as far as the fail-safe is concerned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampleKind {
    /// Valid and part of a fixation: the gaze estimate now includes it.
    Fixation,
    /// Valid but part of a saccade: the estimate holds the last fixation.
    Saccade,
    /// The tracker has no (usable) gaze.
    Invalid,
}

/// The machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FailSafe {
    config: FailSafeConfig,
    state: State,
    valid_run: u32,
    last_fixation_us: Option<u64>,
}

impl FailSafe {
    /// Starts in `FailSafe`.
    #[must_use]
    pub fn new(config: FailSafeConfig) -> Self {
        Self {
            config,
            state: State::FailSafe,
            valid_run: 0,
            last_fixation_us: None,
        }
    }

    /// Settings.
    #[must_use]
    pub fn config(&self) -> FailSafeConfig {
        self.config
    }

    /// Current state.
    #[must_use]
    pub fn state(&self) -> State {
        self.state
    }

    /// Consecutive valid samples so far.
    #[must_use]
    pub fn valid_run(&self) -> u32 {
        self.valid_run
    }

    /// Time of the newest fixation sample (the gaze the estimate rests on).
    #[must_use]
    pub fn last_fixation_us(&self) -> Option<u64> {
        self.last_fixation_us
    }

    /// Feeds one sample at `t_us`.
    pub fn on_sample(&mut self, t_us: u64, kind: SampleKind) {
        if self.last_fixation_us.is_some() && !self.fresh_at(t_us) {
            // The gaze went stale before this sample (a loss no frame
            // observed): fail-safe, and a new run starts here.
            self.valid_run = 0;
            self.state = State::FailSafe;
        }
        match kind {
            SampleKind::Fixation => {
                self.valid_run = self.valid_run.saturating_add(1);
                // Never moves the gaze time backwards.
                self.last_fixation_us = Some(self.last_fixation_us.map_or(t_us, |l| l.max(t_us)));
            }
            SampleKind::Saccade => self.valid_run = self.valid_run.saturating_add(1),
            SampleKind::Invalid => {
                self.valid_run = 0;
                self.last_fixation_us = None;
                self.state = State::FailSafe;
            }
        }
    }

    /// Whether the newest fixation is fresh at `t_us`.
    #[must_use]
    pub fn fresh_at(&self, t_us: u64) -> bool {
        self.last_fixation_us
            .is_some_and(|lf| t_us.saturating_sub(lf) <= self.config.timeout_us)
    }

    /// Evaluates the state for a frame decided at `t_us`.
    pub fn at_frame(&mut self, t_us: u64) -> State {
        if !self.fresh_at(t_us) {
            self.state = State::FailSafe;
            if self.last_fixation_us.is_some() {
                // The gaze went stale (a loss): recovery needs a new run.
                self.valid_run = 0;
            }
        } else if self.state == State::FailSafe && self.valid_run >= self.config.recover_samples {
            self.state = State::Adaptive;
        }
        self.state
    }
}

/// What the frame clock says is due.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Due {
    /// Nothing before this time.
    Nothing,
    /// The frame starting at this time (µs on the frame clock) is due.
    Frame(u64),
    /// More than `max_gap_frames + 1` frames are due at once: the caller emits
    /// one fail-safe frame and resynchronizes (bounded work and memory
    /// whatever the timestamps).
    Jump {
        /// Frames that fell due (saturating).
        frames: u64,
    },
}

/// Frame `k` starts at `k · period_us`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameClock {
    period_us: u64,
    max_gap_frames: u64,
    next: u64,
}

impl FrameClock {
    /// A clock whose first frame starts at 0. `period_us` is at least 1.
    #[must_use]
    pub fn new(period_us: u64, max_gap_frames: u64) -> Self {
        Self {
            period_us: period_us.max(1),
            max_gap_frames,
            next: 0,
        }
    }

    /// The period, µs.
    #[must_use]
    pub fn period_us(&self) -> u64 {
        self.period_us
    }

    /// Start of the next frame, µs (saturating).
    #[must_use]
    pub fn next_start_us(&self) -> u64 {
        self.next.saturating_mul(self.period_us)
    }

    /// The next frame that starts at or before `now_us`, or a jump. Call
    /// until it returns `Nothing`.
    pub fn due(&mut self, now_us: u64) -> Due {
        let start = self.next_start_us();
        if start > now_us {
            return Due::Nothing;
        }
        // Frames with start ≤ now: indices next ..= now / period.
        let Some(behind) = (now_us / self.period_us).checked_sub(self.next) else {
            return Due::Nothing;
        };
        let frames = behind.saturating_add(1);
        if frames > self.max_gap_frames.saturating_add(1) {
            return Due::Jump { frames };
        }
        self.next = self.next.saturating_add(1);
        Due::Frame(start)
    }
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::{cover, for_all};

    fn kind(k: u8) -> SampleKind {
        match k % 3 {
            0 => SampleKind::Fixation,
            1 => SampleKind::Saccade,
            _ => SampleKind::Invalid,
        }
    }

    /// REQ-FS-1: a frame is adaptive only if a fixation no older than the
    /// timeout when the frame is decided (so no older than timeout + one
    /// frame while the frame runs) and enough consecutive valid samples
    /// since the gaze was last lost (invalid or stale) precede it; saccade
    /// samples never refresh a held fixation; any invalid sample forces
    /// fail-safe until recovery; times never overflow.
    #[cfg_attr(kani, kani::proof, kani::unwind(7))]
    #[cfg_attr(not(kani), test)]
    fn adaptive_only_with_fresh_recovered_gaze() {
        for_all!(([(u16, u8, bool); 6], u16, u8, u64), |(
            events,
            timeout,
            recover,
            start,
        )| {
            let config = FailSafeConfig {
                timeout_us: u64::from(timeout),
                recover_samples: u32::from(recover % 6),
            };
            let mut m = FailSafe::new(config);
            let mut t = start;
            let mut run = 0u32;
            let mut last_fix: Option<u64> = None;
            for &(dt, k, frame) in &events {
                // Time never goes backwards; saturates instead of wrapping.
                t = t.saturating_add(u64::from(dt));
                let fresh = last_fix.is_some_and(|lf| t - lf <= config.timeout_us);
                if frame {
                    let s = m.at_frame(t);
                    if s == State::Adaptive {
                        cover!(true, "adaptive at a frame");
                        assert!(fresh, "adaptive on stale gaze");
                        assert!(run >= config.recover_samples);
                    }
                    if !fresh {
                        cover!(last_fix.is_some(), "stale gaze forces fail-safe");
                        assert_eq!(s, State::FailSafe);
                        if last_fix.is_some() {
                            // A loss: the recovery run starts over.
                            cover!(run > 0, "staleness resets a valid run");
                            run = 0;
                        }
                    }
                } else {
                    if last_fix.is_some() && !fresh {
                        cover!(run > 0, "a sample after a silent loss restarts the run");
                        run = 0;
                    }
                    m.on_sample(t, kind(k));
                    match kind(k) {
                        SampleKind::Fixation => {
                            run = run.saturating_add(1);
                            last_fix = Some(t);
                        }
                        SampleKind::Saccade => {
                            cover!(last_fix.is_some(), "saccade holds a fixation");
                            run = run.saturating_add(1);
                        }
                        SampleKind::Invalid => {
                            cover!(true, "invalid sample");
                            run = 0;
                            last_fix = None;
                            assert_eq!(m.state(), State::FailSafe);
                        }
                    }
                }
                assert_eq!(m.valid_run(), run);
                assert_eq!(m.last_fixation_us(), last_fix);
            }
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&[
            "adaptive at a frame",
            "stale gaze forces fail-safe",
            "staleness resets a valid run",
            "a sample after a silent loss restarts the run",
            "saccade holds a fixation",
            "invalid sample",
        ]);
    }

    /// REQ-FS-2: with a fresh fixation and a long enough valid run, the
    /// machine does return to adaptive (the fail-safe is not a trap).
    #[cfg_attr(kani, kani::proof, kani::unwind(10))]
    #[cfg_attr(not(kani), test)]
    fn recovers_after_enough_valid_samples() {
        for_all!((u8, u16, u64), |(recover, step, start)| {
            let recover = u32::from(recover % 8);
            let step = u64::from(step % 1000) + 1;
            let config = FailSafeConfig {
                timeout_us: 1000,
                recover_samples: recover,
            };
            let mut m = FailSafe::new(config);
            let mut t = start;
            m.on_sample(t, SampleKind::Invalid);
            for _ in 0..recover.max(1) {
                t = t.saturating_add(step);
                m.on_sample(t, SampleKind::Fixation);
            }
            cover!(recover > 1, "multi-sample hysteresis");
            assert_eq!(m.at_frame(t), State::Adaptive);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["multi-sample hysteresis"]);
    }

    /// REQ-FS-3: the frame clock drives the fail-safe. Replaying samples at
    /// arbitrary times (the stream's replay loop: frames due at or before a
    /// sample are decided before it is absorbed), every period gets exactly
    /// one frame, in order, unless more than `max_gap_frames + 1` fall due at
    /// once; then one fail-safe frame is emitted and the clock restarts at
    /// the sample with the gaze history discarded. At most
    /// `max_gap_frames + 1` frames follow one sample (bounded work and
    /// memory), and no adaptive frame rests on a fixation older than the
    /// timeout plus one frame at any instant of the frame.
    #[cfg_attr(kani, kani::proof, kani::unwind(8))]
    #[cfg_attr(not(kani), test)]
    fn frame_clock_bounds_gaze_age_and_work() {
        for_all!(([(u16, u8); 6], u16, u8, u8, u8), |(
            samples,
            period,
            timeout,
            gap,
            recover,
        )| {
            let period = u64::from(period % 200) + 1;
            let timeout = u64::from(timeout);
            let max_gap = u64::from(gap % 4);
            let config = FailSafeConfig {
                timeout_us: timeout,
                recover_samples: u32::from(recover % 3),
            };
            let mut m = FailSafe::new(config);
            let mut clock = FrameClock::new(period, max_gap);
            // The sample clock, relative to the current origin.
            let mut origin = 0u64;
            let mut t = 0u64;
            let mut last_start: Option<u64> = None;
            for &(dt, k) in &samples {
                // Gaps from none to several periods (jumps beyond max_gap).
                t = t.saturating_add(u64::from(dt % 1024));
                let mut rel = t - origin;
                let mut emitted = 0u64;
                loop {
                    match clock.due(rel) {
                        Due::Nothing => break,
                        Due::Frame(start) => {
                            assert!(start <= rel);
                            if let Some(prev) = last_start {
                                assert_eq!(start, prev + period, "a period without a frame");
                            }
                            last_start = Some(start);
                            emitted += 1;
                            if m.at_frame(start) == State::Adaptive {
                                cover!(true, "adaptive frame on the clock");
                                let lf = m.last_fixation_us().unwrap();
                                // Age at the frame's end.
                                assert!(start + period - lf <= timeout + period);
                            }
                        }
                        Due::Jump { frames } => {
                            cover!(true, "timestamp jump");
                            assert!(frames > max_gap + 1);
                            // One fail-safe frame, then resynchronize.
                            m = FailSafe::new(config);
                            clock = FrameClock::new(period, max_gap);
                            origin = t;
                            rel = 0;
                            last_start = None;
                            emitted = 0;
                        }
                    }
                }
                cover!(emitted > 1, "a gap produces its frames");
                assert!(emitted <= max_gap + 1);
                m.on_sample(rel, kind(k));
            }
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&[
            "adaptive frame on the clock",
            "timestamp jump",
            "a gap produces its frames",
        ]);
    }
}
