//! The gaze fail-safe state machine (specified in `specs/failsafe.md`).
//!
//! Integer core: times in microseconds, counters saturate, no floats.
//!
//! - `FailSafe` → the LiDAR runs the uniform baseline (no sector is
//!   under-scanned on stale information). Initial state.
//! - `Adaptive` → the LiDAR runs the gaze-adapted profile.
//!
//! Transitions:
//! - an invalid sample (tracker lost the eyes, NaN, outlier) → `FailSafe`
//!   at once and the run of valid samples restarts at 0;
//! - at a frame boundary `t`, if the newest valid sample is older than the
//!   timeout (or there is none) → `FailSafe`;
//! - at a frame boundary, from `FailSafe`, with a fresh valid sample and at
//!   least `recover_samples` consecutive valid samples → `Adaptive`
//!   (hysteresis: one good sample after a loss is not enough).

/// Settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FailSafeConfig {
    /// Gaze older than this at a frame boundary is stale, µs (default 100 ms).
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

/// The machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FailSafe {
    config: FailSafeConfig,
    state: State,
    valid_run: u32,
    last_valid_us: Option<u64>,
}

impl FailSafe {
    /// Starts in `FailSafe`.
    #[must_use]
    pub fn new(config: FailSafeConfig) -> Self {
        Self {
            config,
            state: State::FailSafe,
            valid_run: 0,
            last_valid_us: None,
        }
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

    /// Feeds one sample at `t_us` (valid or not).
    pub fn on_sample(&mut self, t_us: u64, valid: bool) {
        if valid {
            self.valid_run = self.valid_run.saturating_add(1);
            self.last_valid_us = Some(t_us);
        } else {
            self.valid_run = 0;
            self.state = State::FailSafe;
        }
    }

    /// Whether the newest valid sample is fresh at `t_us`.
    #[must_use]
    pub fn fresh_at(&self, t_us: u64) -> bool {
        self.last_valid_us
            .is_some_and(|lv| t_us.saturating_sub(lv) <= self.config.timeout_us)
    }

    /// Evaluates the state at a frame boundary `t_us`.
    pub fn at_frame(&mut self, t_us: u64) -> State {
        if !self.fresh_at(t_us) {
            self.state = State::FailSafe;
        } else if self.state == State::FailSafe && self.valid_run >= self.config.recover_samples {
            self.state = State::Adaptive;
        }
        self.state
    }
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::cover;

    /// REQ-FS-1: the machine is adaptive at a frame only with fresh gaze and
    /// enough consecutive valid samples; any invalid sample forces fail-safe
    /// until recovery; times never overflow.
    #[cfg_attr(kani, kani::proof, kani::unwind(7))]
    #[cfg_attr(not(kani), test)]
    fn adaptive_only_with_fresh_recovered_gaze() {
        bolero::check!()
            .with_type::<([(u16, bool, bool); 6], u16, u8, u64)>()
            .cloned()
            .for_each(|(events, timeout, recover, start)| {
                let config = FailSafeConfig {
                    timeout_us: u64::from(timeout),
                    recover_samples: u32::from(recover % 6),
                };
                let mut m = FailSafe::new(config);
                let mut t = start;
                let mut run = 0u32;
                let mut last_valid: Option<u64> = None;
                for &(dt, valid, frame) in &events {
                    // Time never goes backwards; saturates instead of wrapping.
                    t = t.saturating_add(u64::from(dt));
                    if frame {
                        let s = m.at_frame(t);
                        let fresh = last_valid.is_some_and(|lv| t - lv <= config.timeout_us);
                        if s == State::Adaptive {
                            cover!(true, "adaptive at a frame");
                            assert!(fresh, "adaptive on stale gaze");
                            assert!(run >= config.recover_samples);
                        }
                        if !fresh {
                            cover!(last_valid.is_some(), "stale gaze forces fail-safe");
                            assert_eq!(s, State::FailSafe);
                        }
                    } else {
                        m.on_sample(t, valid);
                        if valid {
                            run = run.saturating_add(1);
                            last_valid = Some(t);
                        } else {
                            cover!(true, "invalid sample");
                            run = 0;
                            assert_eq!(m.state(), State::FailSafe);
                        }
                    }
                    assert_eq!(m.valid_run(), run);
                }
            });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&[
            "adaptive at a frame",
            "stale gaze forces fail-safe",
            "invalid sample",
        ]);
    }

    /// REQ-FS-2: with fresh gaze and a long enough valid run, the machine
    /// does return to adaptive (the fail-safe is not a trap).
    #[cfg_attr(kani, kani::proof, kani::unwind(10))]
    #[cfg_attr(not(kani), test)]
    fn recovers_after_enough_valid_samples() {
        bolero::check!()
            .with_type::<(u8, u16, u64)>()
            .cloned()
            .for_each(|(recover, step, start)| {
                let recover = u32::from(recover % 8);
                let step = u64::from(step % 1000) + 1;
                let config = FailSafeConfig {
                    timeout_us: 1000,
                    recover_samples: recover,
                };
                let mut m = FailSafe::new(config);
                let mut t = start;
                m.on_sample(t, false);
                for _ in 0..recover.max(1) {
                    t = t.saturating_add(step);
                    m.on_sample(t, true);
                }
                cover!(recover > 1, "multi-sample hysteresis");
                assert_eq!(m.at_frame(t), State::Adaptive);
            });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["multi-sample hysteresis"]);
    }
}
