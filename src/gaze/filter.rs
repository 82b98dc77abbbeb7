//! Gaze filtering: outlier rejection, I-VT fixation/saccade classification
//! and smoothing.
//!
//! - **Invalid**: the tracker's own flag, a non-finite gaze, or |gaze| beyond
//!   [`MAX_ABS_GAZE_DEG`](crate::model::acuity::MAX_ABS_GAZE_DEG) (3600°, the bound
//!   `profile --gaze-deg` enforces: anything larger is a unit bug, not an
//!   azimuth). The estimate is forgotten.
//! - **Outliers**: a sample implying an angular velocity above
//!   `outlier_deg_s` (default 1000°/s, beyond the fastest human saccades
//!   ≈ 700°/s) or a timestamp that does not advance is dropped (it neither
//!   refreshes nor invalidates the gaze).
//! - **I-VT** (Salvucci & Goldberg 2000; Tobii's default threshold 30°/s):
//!   a sample faster than `saccade_deg_s` from its predecessor is a saccade.
//!   During a saccade vision is suppressed, so the estimate holds the last
//!   fixation; a new fixation restarts the smoothing window.
//! - **Smoothing**: the circular mean of the last `smooth_samples` fixation
//!   samples. Added latency: the mean lags a moving gaze by
//!   `(smooth_samples − 1)/2` samples (10 ms at 200 Hz with the default 5),
//!   plus one sample for the velocity test.

use std::collections::VecDeque;

use super::formats::GazeSample;
use crate::model::angle::{diff_deg, wrap_deg};

/// Filter settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterConfig {
    /// I-VT saccade threshold, °/s.
    pub saccade_deg_s: f64,
    /// Outlier threshold, °/s.
    pub outlier_deg_s: f64,
    /// Fixation samples averaged.
    pub smooth_samples: usize,
}

impl Default for FilterConfig {
    fn default() -> Self {
        Self {
            saccade_deg_s: 30.0,
            outlier_deg_s: 1000.0,
            smooth_samples: 5,
        }
    }
}

/// What a sample was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// Part of a fixation.
    Fixation,
    /// Part of a saccade.
    Saccade,
    /// Rejected as an outlier.
    Outlier,
    /// The tracker reported no gaze.
    Invalid,
}

/// The filter.
#[derive(Debug, Clone)]
pub struct GazeFilter {
    config: FilterConfig,
    last: Option<(f64, f64)>,
    window: VecDeque<f64>,
    estimate: Option<f64>,
}

impl GazeFilter {
    /// A filter.
    #[must_use]
    pub fn new(config: FilterConfig) -> Self {
        Self {
            config,
            last: None,
            window: VecDeque::new(),
            estimate: None,
        }
    }

    /// The current gaze estimate, degrees.
    #[must_use]
    pub fn estimate(&self) -> Option<f64> {
        self.estimate
    }

    /// Forgets everything (a clock discontinuity).
    pub fn reset(&mut self) {
        self.last = None;
        self.window.clear();
        self.estimate = None;
    }

    /// Classifies and absorbs a sample.
    pub fn push(&mut self, s: &GazeSample) -> Class {
        if !s.usable() {
            self.reset();
            return Class::Invalid;
        }
        if !s.t_s.is_finite() {
            return Class::Outlier;
        }
        let g = wrap_deg(s.gaze_deg);
        let class = match self.last {
            None => Class::Fixation,
            Some((t0, g0)) => {
                let dt = s.t_s - t0;
                if dt.is_nan() || dt <= 0.0 {
                    return Class::Outlier;
                }
                let v = diff_deg(g, g0).abs() / dt;
                if v > self.config.outlier_deg_s {
                    return Class::Outlier;
                }
                if v > self.config.saccade_deg_s {
                    Class::Saccade
                } else {
                    Class::Fixation
                }
            }
        };
        self.last = Some((s.t_s, g));
        match class {
            Class::Saccade => self.window.clear(),
            _ => {
                self.window.push_back(g);
                while self.window.len() > self.config.smooth_samples.max(1) {
                    self.window.pop_front();
                }
                // Circular mean around the newest sample.
                let mean = self.window.iter().map(|&x| diff_deg(x, g)).sum::<f64>()
                    / self.window.len() as f64;
                self.estimate = Some(wrap_deg(g + mean));
            }
        }
        class
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(t: f64, g: f64) -> GazeSample {
        GazeSample {
            t_s: t,
            gaze_deg: g,
            valid: true,
        }
    }

    #[test]
    fn ivt_smoothing_and_outliers() {
        let mut f = GazeFilter::new(FilterConfig::default());
        assert_eq!(f.push(&s(0.000, 359.0)), Class::Fixation);
        assert_eq!(
            f.push(&s(0.005, 1.0)),
            Class::Saccade,
            "2° in 5 ms = 400°/s"
        );
        assert_eq!(f.estimate(), Some(359.0), "held through the saccade");
        assert_eq!(f.push(&s(0.010, 1.05)), Class::Fixation);
        assert_eq!(f.push(&s(0.015, 0.95)), Class::Fixation);
        assert!(
            diff_deg(f.estimate().unwrap(), 1.0).abs() < 1e-9,
            "mean across 0°"
        );
        assert_eq!(f.push(&s(0.020, 90.0)), Class::Outlier, "89° in 5 ms");
        assert_eq!(
            f.push(&s(0.015, 1.0)),
            Class::Outlier,
            "time did not advance"
        );
        assert_eq!(
            f.push(&GazeSample {
                t_s: 0.03,
                gaze_deg: f64::NAN,
                valid: true
            }),
            Class::Invalid
        );
        assert_eq!(f.estimate(), None);
        assert_eq!(f.push(&s(0.04, 90.0)), Class::Fixation);
        assert_eq!(f.push(&s(0.045, 1e300)), Class::Invalid, "absurd gaze");
        assert_eq!(f.estimate(), None);
        assert_eq!(
            f.push(&s(0.05, -3600.0)),
            Class::Fixation,
            "bound inclusive"
        );
        assert_eq!(f.push(&s(0.055, 3600.5)), Class::Invalid);
    }
}
