//! The independent checker: recomputes every limit of a profile from the
//! profile alone (its bins and its declared `limits`), trusting nothing a
//! planner or solver said.
//!
//! [`CertifiedProfile`] can only be built by [`certify`], so every profile
//! the library hands out has passed this check.
//!
//! Tolerances: relative [`REL_TOL`] on physical quantities and
//! [`ANGLE_TOL_DEG`] on bin edges — far below any hardware resolution, large
//! enough for `f64` sums over 36,000 bins.

// Negated comparisons (`!(x <= limit)`) are deliberate throughout: a NaN
// must fail every check, which `x > limit` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod verdict;
pub use verdict::Verdict;

use serde::Serialize;
use std::fmt;
use thiserror::Error;

use crate::eye_safety::{self, ExposureReport};
use crate::model::angle::{next_index, FULL_TURN_DEG};
use crate::model::lidar::{laser_mismatches, no_looser, LidarSpec, LimitSide, PowerAccounting};
use crate::model::valid;
use crate::profile::{Profile, Region, Summary, PROFILE_FORMAT};

/// Relative tolerance on power, spin, time and acceleration comparisons.
pub const REL_TOL: f64 = 1e-9;
/// Absolute tolerance on bin edges, degrees.
pub const ANGLE_TOL_DEG: f64 = 1e-9;
/// Largest number of bins the checker accepts.
pub const MAX_PROFILE_BINS: usize = 1_000_000;

/// `value <= limit` with the relative tolerance.
fn le_tol(value: f64, limit: f64) -> bool {
    value <= limit + REL_TOL * limit.abs().max(f64::MIN_POSITIVE)
}

/// `value >= limit` with the relative tolerance.
fn ge_tol(value: f64, limit: f64) -> bool {
    value >= limit - REL_TOL * limit.abs().max(f64::MIN_POSITIVE)
}

/// One violated requirement: where, the value found and the limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Violation {
    /// `format` is not profile@1.
    Format {
        /// What the file said.
        found: String,
    },
    /// A top-level number is invalid.
    Header {
        /// Field name.
        field: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
    /// A limit is itself invalid (NaN, negative, min above max …).
    BadLimit {
        /// Key in `limits`.
        field: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
    /// No bins, or too many.
    BinCount {
        /// Number of bins.
        count: usize,
    },
    /// A per-bin number is invalid.
    BinField {
        /// Bin index.
        bin: usize,
        /// Field name.
        field: &'static str,
        /// Value.
        value: f64,
        /// Why.
        reason: &'static str,
    },
    /// A bin does not start where the previous one ended (gap or overlap).
    Coverage {
        /// Bin index.
        bin: usize,
        /// Where it should start, degrees.
        expected_start_deg: f64,
        /// Where it starts, degrees.
        start_deg: f64,
    },
    /// The bins do not end at 360°.
    CoverageEnd {
        /// Where the last bin ends, degrees.
        end_deg: f64,
    },
    /// Σ dwell ≠ 1 / frame_rate_hz.
    FramePeriod {
        /// Σ dwell, s.
        period_s: f64,
        /// 1 / frame_rate_hz, s.
        expected_s: f64,
    },
    /// Average power over budget.
    AveragePower {
        /// Declared accounting.
        accounting: PowerAccounting,
        /// Average found, W.
        average_w: f64,
        /// `average_power_w`, W.
        budget_w: f64,
    },
    /// Power below `power_w_min`.
    PowerMin {
        /// Bin.
        bin: usize,
        /// Power, W.
        power_w: f64,
        /// Limit, W.
        limit_w: f64,
    },
    /// Power above `power_w_max`.
    PowerMax {
        /// Bin.
        bin: usize,
        /// Power, W.
        power_w: f64,
        /// Limit, W.
        limit_w: f64,
    },
    /// Spin below `spin_rad_s_min`.
    SpinMin {
        /// Bin.
        bin: usize,
        /// Spin, rad/s.
        spin_rad_s: f64,
        /// Limit, rad/s.
        limit_rad_s: f64,
    },
    /// Spin above `spin_rad_s_max`.
    SpinMax {
        /// Bin.
        bin: usize,
        /// Spin, rad/s.
        spin_rad_s: f64,
        /// Limit, rad/s.
        limit_rad_s: f64,
    },
    /// Spin jumps at a bin edge while the acceleration limit is finite.
    SpinStep {
        /// Bin whose end is compared.
        bin: usize,
        /// Its `spin_end_rad_s`.
        end_rad_s: f64,
        /// The next bin's `spin_start_rad_s`.
        next_start_rad_s: f64,
        /// The acceleration limit, rad/s².
        limit_rad_s2: f64,
    },
    /// |angular acceleration| above `spin_accel_rad_s2_max`.
    SpinAccel {
        /// Bin.
        bin: usize,
        /// |a|, rad/s².
        accel_rad_s2: f64,
        /// Limit.
        limit_rad_s2: f64,
    },
    /// Power slew between neighbouring bin centres above its limit.
    PowerSlew {
        /// First bin of the pair (the other is the next, cyclically).
        bin: usize,
        /// Slew, W/deg.
        slew_w_per_deg: f64,
        /// Limit.
        limit_w_per_deg: f64,
    },
    /// An eye-safety rule fails at some azimuth.
    EyeSafety {
        /// Azimuth of the worst aperture position, degrees.
        azimuth_deg: f64,
        /// Which rule binds.
        rule: crate::eye_safety::Rule,
        /// Exposure / limit (> 1 fails).
        ratio: f64,
    },
    /// Eye-safety parameters unusable (wavelength out of band …).
    EyeSafetyParams {
        /// What is wrong.
        reason: String,
    },
    /// `limits.eye_safety` is null: the file is not Class 1 evidence.
    EyeSafetyMissing,
    /// A declared limit is looser than the sensor's own.
    LooserThanSensor {
        /// The `limits` key.
        field: &'static str,
        /// The file's value (`None` = unlimited).
        declared: Option<f64>,
        /// The sensor's value (`None` = unlimited).
        sensor: Option<f64>,
    },
    /// A header value differs from the sensor's (pulse rate, frame rate,
    /// accounting, eye-safety parameters).
    SensorMismatch {
        /// The key.
        field: &'static str,
        /// What differs.
        detail: String,
    },
}

impl Violation {
    /// The profile key or limit this violation is about.
    #[must_use]
    pub fn limit_key(&self) -> &'static str {
        match self {
            Self::Format { .. } => "format",
            Self::Header { field, .. } | Self::BinField { field, .. } => field,
            Self::BadLimit { field, .. } => field,
            Self::BinCount { .. } | Self::Coverage { .. } | Self::CoverageEnd { .. } => "bins",
            Self::FramePeriod { .. } => "frame_rate_hz",
            Self::AveragePower { .. } => "average_power_w",
            Self::PowerMin { .. } => "power_w_min",
            Self::PowerMax { .. } => "power_w_max",
            Self::SpinMin { .. } => "spin_rad_s_min",
            Self::SpinMax { .. } => "spin_rad_s_max",
            Self::SpinStep { .. } | Self::SpinAccel { .. } => "spin_accel_rad_s2_max",
            Self::PowerSlew { .. } => "power_slew_w_per_deg_max",
            Self::EyeSafety { .. } | Self::EyeSafetyParams { .. } | Self::EyeSafetyMissing => {
                "eye_safety"
            }
            Self::LooserThanSensor { field, .. } | Self::SensorMismatch { field, .. } => field,
        }
    }
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Format { found } => write!(f, "format: '{found}' is not '{PROFILE_FORMAT}'"),
            Self::Header {
                field,
                value,
                reason,
            } => write!(f, "{field} = {value}: {reason}", value = crate::text::Num(*value)),
            Self::BadLimit {
                field,
                value,
                reason,
            } => write!(f, "limits.{field} = {value}: {reason}", value = crate::text::Num(*value)),
            Self::BinCount { count } => write!(
                f,
                "bins: {count} bins; a profile needs 1 to {MAX_PROFILE_BINS}"
            ),
            Self::BinField {
                bin,
                field,
                value,
                reason,
            } => write!(f, "bins[{bin}].{field} = {value}: {reason}", value = crate::text::Num(*value)),
            Self::Coverage {
                bin,
                expected_start_deg,
                start_deg,
            } => write!(
                f,
                "bins[{bin}].start_deg = {start_deg}: bins must cover [0, 360) contiguously, expected {expected_start_deg}"
            , expected_start_deg = crate::text::Num(*expected_start_deg), start_deg = crate::text::Num(*start_deg)),
            Self::CoverageEnd { end_deg } => {
                write!(f, "bins: the last bin ends at {end_deg}°, not 360°", end_deg = crate::text::Num(*end_deg))
            }
            Self::FramePeriod {
                period_s,
                expected_s,
            } => write!(
                f,
                "frame period: the bins' dwell times sum to {period_s} s, but 1/frame_rate_hz = {expected_s} s"
            , period_s = crate::text::Num(*period_s), expected_s = crate::text::Num(*expected_s)),
            Self::AveragePower {
                accounting,
                average_w,
                budget_w,
            } => write!(
                f,
                "average_power_w: {accounting}-averaged power {average_w} W exceeds the budget {budget_w} W"
            , average_w = crate::text::Num(*average_w), budget_w = crate::text::Num(*budget_w)),
            Self::PowerMin {
                bin,
                power_w,
                limit_w,
            } => write!(
                f,
                "bins[{bin}].power_w = {power_w} W is below limits.power_w_min {limit_w} W"
            , power_w = crate::text::Num(*power_w), limit_w = crate::text::Num(*limit_w)),
            Self::PowerMax {
                bin,
                power_w,
                limit_w,
            } => write!(
                f,
                "bins[{bin}].power_w = {power_w} W exceeds limits.power_w_max {limit_w} W"
            , power_w = crate::text::Num(*power_w), limit_w = crate::text::Num(*limit_w)),
            Self::SpinMin {
                bin,
                spin_rad_s,
                limit_rad_s,
            } => write!(
                f,
                "bins[{bin}] spin {spin_rad_s} rad/s is below limits.spin_rad_s_min {limit_rad_s} rad/s"
            , spin_rad_s = crate::text::Num(*spin_rad_s), limit_rad_s = crate::text::Num(*limit_rad_s)),
            Self::SpinMax {
                bin,
                spin_rad_s,
                limit_rad_s,
            } => write!(
                f,
                "bins[{bin}] spin {spin_rad_s} rad/s exceeds limits.spin_rad_s_max {limit_rad_s} rad/s"
            , spin_rad_s = crate::text::Num(*spin_rad_s), limit_rad_s = crate::text::Num(*limit_rad_s)),
            Self::SpinStep {
                bin,
                end_rad_s,
                next_start_rad_s,
                limit_rad_s2,
            } => write!(
                f,
                "bins[{bin}] spin steps from {end_rad_s} to {next_start_rad_s} rad/s at its end edge: a step is an infinite acceleration, limits.spin_accel_rad_s2_max is {limit_rad_s2} rad/s²"
            , end_rad_s = crate::text::Num(*end_rad_s), next_start_rad_s = crate::text::Num(*next_start_rad_s), limit_rad_s2 = crate::text::Num(*limit_rad_s2)),
            Self::SpinAccel {
                bin,
                accel_rad_s2,
                limit_rad_s2,
            } => write!(
                f,
                "bins[{bin}] needs |acceleration| {accel_rad_s2} rad/s², above limits.spin_accel_rad_s2_max {limit_rad_s2} rad/s²"
            , limit_rad_s2 = crate::text::Num(*limit_rad_s2), accel_rad_s2 = crate::text::Num(*accel_rad_s2)),
            Self::PowerSlew {
                bin,
                slew_w_per_deg,
                limit_w_per_deg,
            } => write!(
                f,
                "bins[{bin}]→next power slew {slew_w_per_deg} W/deg exceeds limits.power_slew_w_per_deg_max {limit_w_per_deg} W/deg"
            , slew_w_per_deg = crate::text::Num(*slew_w_per_deg), limit_w_per_deg = crate::text::Num(*limit_w_per_deg)),
            Self::EyeSafety {
                azimuth_deg,
                rule,
                ratio,
            } => write!(
                f,
                "eye_safety: at azimuth {azimuth_deg:.3}° the {rule} is {} % of the Class 1 limit (margin {}×)",
                crate::text::Fixed(ratio * 100.0, 1),
                crate::text::Fixed(1.0 / ratio, 3)
            ),
            Self::EyeSafetyParams { reason } => write!(f, "limits.eye_safety: {reason}"),
            Self::EyeSafetyMissing => write!(
                f,
                "limits.eye_safety is null: eye safety is not evaluated, so the file is not Class 1 evidence (opt out explicitly to check the rest)"
            ),
            Self::LooserThanSensor {
                field,
                declared,
                sensor,
            } => {
                write!(
                    f,
                    "limits.{field} = {} is looser than the sensor's {}",
                    crate::text::Limit(*declared),
                    crate::text::Limit(*sensor)
                )
            }
            Self::SensorMismatch { field, detail } => write!(f, "{field}: {detail}"),
        }
    }
}

/// Joins the first few items' messages, with a count of the rest.
#[must_use]
pub fn summarize_list<T: fmt::Display>(items: &[T]) -> String {
    const SHOWN: usize = 5;
    let mut s = items
        .iter()
        .take(SHOWN)
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("; ");
    if items.len() > SHOWN {
        s.push_str(&format!("; … and {} more", items.len() - SHOWN));
    }
    s
}

/// A profile failed the checker; every violation is listed.
#[derive(Debug, Clone, Error, PartialEq)]
#[error("profile rejected: {} violation(s); first: {}", violations.len(), violations.first().map(ToString::to_string).unwrap_or_default())]
pub struct Rejected {
    /// Every violation found, in the order checked.
    pub violations: Vec<Violation>,
    /// The eye-safety evaluation the verdict rests on, when it ran (what
    /// the head met and how far the powers must come down).
    pub eye_safety: Option<Box<ExposureReport>>,
}

/// A profile that has passed [`certify`]. Only the checker can build one.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct CertifiedProfile {
    profile: Profile,
    /// The eye-safety evaluation that certified it (`None` only when the
    /// caller opted out of eye safety and the file has no parameters).
    #[serde(skip)]
    eye_safety: Option<ExposureReport>,
}

impl CertifiedProfile {
    /// The certified profile (its `summary` is the checker's).
    #[must_use]
    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    /// The checker's summary.
    #[must_use]
    pub fn summary(&self) -> &Summary {
        // certify() always sets the summary before constructing Self.
        self.profile
            .summary
            .as_ref()
            .expect("certify() sets the summary")
    }

    /// The eye-safety evaluation the certificate rests on (the one the
    /// checker ran; `None` when eye safety was opted out of and the file
    /// has no parameters).
    #[must_use]
    pub fn eye_safety(&self) -> Option<&ExposureReport> {
        self.eye_safety.as_ref()
    }

    /// Replaces the informational `optimality` block: the checker neither
    /// reads nor checks it, so the certificate stands.
    pub fn set_optimality(&mut self, optimality: Option<crate::profile::Optimality>) {
        self.profile.optimality = optimality;
    }

    /// Gives the profile back (it stays certified only as long as unchanged).
    #[must_use]
    pub fn into_inner(self) -> Profile {
        self.profile
    }
}

/// Derived figures of a structurally valid profile.
#[must_use]
pub fn summarize(profile: &Profile) -> Summary {
    let n = profile.bins.len();
    let mut energy = 0.0;
    let mut power_angle = 0.0;
    let mut period = 0.0;
    let mut max_accel: f64 = 0.0;
    let mut rof = 0.0;
    let mut p_range = [f64::INFINITY, f64::NEG_INFINITY];
    let mut s_range = [f64::INFINITY, f64::NEG_INFINITY];
    for (i, b) in profile.bins.iter().enumerate() {
        let t = b.dwell_time_s();
        energy += b.power_w * t;
        power_angle += b.power_w * b.width_deg;
        period += t;
        max_accel = max_accel.max(b.spin_accel_rad_s2().abs());
        let next = &profile.bins[next_index(i, n)];
        if n > 1 && b.spin_end_rad_s != next.spin_start_rad_s {
            max_accel = f64::INFINITY;
        }
        if b.region == Some(Region::Rof) {
            rof += b.width_deg;
        }
        p_range = [p_range[0].min(b.power_w), p_range[1].max(b.power_w)];
        let lo = b.spin_start_rad_s.min(b.spin_end_rad_s);
        let hi = b.spin_start_rad_s.max(b.spin_end_rad_s);
        s_range = [s_range[0].min(lo), s_range[1].max(hi)];
    }
    Summary {
        average_power_angle_w: power_angle / FULL_TURN_DEG,
        average_power_time_w: energy / period,
        energy_per_frame_j: energy,
        frame_period_s: period,
        max_spin_accel_rad_s2: max_accel.is_finite().then_some(max_accel),
        rof_width_deg: rof,
        power_w_range: p_range,
        spin_rad_s_range: s_range,
    }
}

fn check_header(p: &Profile, v: &mut Vec<Violation>) {
    if p.format != PROFILE_FORMAT {
        v.push(Violation::Format {
            found: p.format.clone(),
        });
    }
    // The one numeric boundary (`model::valid`): rates finite and of
    // physical size (a subnormal rate's period overflows to infinity), every
    // other number finite, zero or normal; each rule fails on NaN.
    for (field, value) in [
        ("frame_rate_hz", p.frame_rate_hz),
        ("pulse_rate_hz", p.pulse_rate_hz),
    ] {
        if let Err(reason) = valid::rate_hz(value) {
            v.push(Violation::Header {
                field,
                value,
                reason,
            });
        }
    }
    if let Err(reason) = valid::magnitude(p.average_power_w) {
        v.push(Violation::Header {
            field: "average_power_w",
            value: p.average_power_w,
            reason,
        });
    }
    if let Some(g) = p.gaze_deg {
        if valid::finite(g).is_err() {
            v.push(Violation::Header {
                field: "gaze_deg",
                value: g,
                reason: "must be finite or null",
            });
        }
    }
    let l = &p.limits;
    let mut nonneg = |field, value: f64| {
        if let Err(reason) = valid::magnitude(value) {
            v.push(Violation::BadLimit {
                field,
                value,
                reason,
            });
        }
    };
    nonneg("power_w_min", l.power_w_min);
    nonneg("power_w_max", l.power_w_max);
    nonneg("spin_rad_s_min", l.spin_rad_s_min);
    nonneg("spin_rad_s_max", l.spin_rad_s_max);
    if let Some(a) = l.spin_accel_rad_s2_max {
        nonneg("spin_accel_rad_s2_max", a);
    }
    if let Some(s) = l.power_slew_w_per_deg_max {
        nonneg("power_slew_w_per_deg_max", s);
    }
    // Inverted limits (a NaN is already reported above; not twice).
    if !valid::ordered(l.power_w_min, l.power_w_max)
        && !l.power_w_min.is_nan()
        && !l.power_w_max.is_nan()
    {
        v.push(Violation::BadLimit {
            field: "power_w_min",
            value: l.power_w_min,
            reason: "is above power_w_max",
        });
    }
    if !valid::ordered(l.spin_rad_s_min, l.spin_rad_s_max)
        && !l.spin_rad_s_min.is_nan()
        && !l.spin_rad_s_max.is_nan()
    {
        v.push(Violation::BadLimit {
            field: "spin_rad_s_min",
            value: l.spin_rad_s_min,
            reason: "is above spin_rad_s_max",
        });
    }
}

/// Checks bin fields and coverage; returns false if the bins are too broken
/// for the physical checks to mean anything.
fn check_structure(p: &Profile, v: &mut Vec<Violation>) -> bool {
    let n = p.bins.len();
    if n == 0 || n > MAX_PROFILE_BINS {
        v.push(Violation::BinCount { count: n });
        return false;
    }
    let before = v.len();
    let mut expected = 0.0;
    for (i, b) in p.bins.iter().enumerate() {
        let fields = [
            ("start_deg", b.start_deg),
            ("width_deg", b.width_deg),
            ("power_w", b.power_w),
            ("spin_start_rad_s", b.spin_start_rad_s),
            ("spin_end_rad_s", b.spin_end_rad_s),
        ];
        for (field, value) in fields {
            if let Err(reason) = valid::finite(value) {
                v.push(Violation::BinField {
                    bin: i,
                    field,
                    value,
                    reason,
                });
            }
        }
        if !(b.width_deg > 0.0) {
            v.push(Violation::BinField {
                bin: i,
                field: "width_deg",
                value: b.width_deg,
                reason: "must be > 0",
            });
        }
        for (field, value) in [
            ("spin_start_rad_s", b.spin_start_rad_s),
            ("spin_end_rad_s", b.spin_end_rad_s),
        ] {
            if !(value > 0.0) {
                v.push(Violation::BinField {
                    bin: i,
                    field,
                    value,
                    reason: "must be > 0 (the head must turn)",
                });
            }
        }
        if !((b.start_deg - expected).abs() <= ANGLE_TOL_DEG) {
            v.push(Violation::Coverage {
                bin: i,
                expected_start_deg: expected,
                start_deg: b.start_deg,
            });
        }
        expected = b.start_deg + b.width_deg;
    }
    if !((expected - FULL_TURN_DEG).abs() <= ANGLE_TOL_DEG) {
        v.push(Violation::CoverageEnd { end_deg: expected });
    }
    v.len() == before
}

fn check_limits(p: &Profile, s: &Summary, v: &mut Vec<Violation>) {
    let l = &p.limits;
    let n = p.bins.len();
    let expected_s = 1.0 / p.frame_rate_hz;
    if !((s.frame_period_s - expected_s).abs() <= REL_TOL * expected_s) {
        v.push(Violation::FramePeriod {
            period_s: s.frame_period_s,
            expected_s,
        });
    }
    // Average power is judged against the nominal frame period for `time`.
    let average_w = match p.power_accounting {
        PowerAccounting::Angle => s.average_power_angle_w,
        PowerAccounting::Time => s.energy_per_frame_j * p.frame_rate_hz,
    };
    if !le_tol(average_w, p.average_power_w) {
        v.push(Violation::AveragePower {
            accounting: p.power_accounting,
            average_w,
            budget_w: p.average_power_w,
        });
    }
    for (i, b) in p.bins.iter().enumerate() {
        if !ge_tol(b.power_w, l.power_w_min) {
            v.push(Violation::PowerMin {
                bin: i,
                power_w: b.power_w,
                limit_w: l.power_w_min,
            });
        }
        if !le_tol(b.power_w, l.power_w_max) {
            v.push(Violation::PowerMax {
                bin: i,
                power_w: b.power_w,
                limit_w: l.power_w_max,
            });
        }
        let lo = b.spin_start_rad_s.min(b.spin_end_rad_s);
        let hi = b.spin_start_rad_s.max(b.spin_end_rad_s);
        if !ge_tol(lo, l.spin_rad_s_min) {
            v.push(Violation::SpinMin {
                bin: i,
                spin_rad_s: lo,
                limit_rad_s: l.spin_rad_s_min,
            });
        }
        if !le_tol(hi, l.spin_rad_s_max) {
            v.push(Violation::SpinMax {
                bin: i,
                spin_rad_s: hi,
                limit_rad_s: l.spin_rad_s_max,
            });
        }
        let next = &p.bins[next_index(i, n)];
        if let Some(a_max) = l.spin_accel_rad_s2_max {
            let a = b.spin_accel_rad_s2().abs();
            if !le_tol(a, a_max) {
                v.push(Violation::SpinAccel {
                    bin: i,
                    accel_rad_s2: a,
                    limit_rad_s2: a_max,
                });
            }
            let jump = (b.spin_end_rad_s - next.spin_start_rad_s).abs();
            if !(jump <= REL_TOL * b.spin_end_rad_s.abs().max(1.0)) {
                v.push(Violation::SpinStep {
                    bin: i,
                    end_rad_s: b.spin_end_rad_s,
                    next_start_rad_s: next.spin_start_rad_s,
                    limit_rad_s2: a_max,
                });
            }
        }
        if let Some(slew_max) = l.power_slew_w_per_deg_max {
            if n > 1 {
                let slew =
                    (next.power_w - b.power_w).abs() / (0.5 * (b.width_deg + next.width_deg));
                if !le_tol(slew, slew_max) {
                    v.push(Violation::PowerSlew {
                        bin: i,
                        slew_w_per_deg: slew,
                        limit_w_per_deg: slew_max,
                    });
                }
            }
        }
    }
}

fn check_eye_safety(
    p: &Profile,
    opts: &CheckOptions<'_>,
    v: &mut Vec<Violation>,
) -> Option<ExposureReport> {
    let Some(params) = &p.limits.eye_safety else {
        if !opts.allow_missing_eye_safety {
            v.push(Violation::EyeSafetyMissing);
        }
        return None;
    };
    if let Err(e) = params.check_pulse_rate(p.pulse_rate_hz) {
        v.push(Violation::EyeSafetyParams {
            reason: e.to_string(),
        });
        return None;
    }
    match eye_safety::evaluate_profile(p, params) {
        Ok(report) => {
            v.extend(eye_safety_violation(&report));
            Some(report)
        }
        Err(e) => {
            v.push(Violation::EyeSafetyParams {
                reason: e.to_string(),
            });
            None
        }
    }
}

/// The violation an exposure report implies, if any. The report is already
/// an upper bound with its counts rounded towards safety, so the limit is
/// applied exactly: no tolerance above 1.
fn eye_safety_violation(r: &ExposureReport) -> Option<Violation> {
    (r.worst_ratio.is_nan() || r.worst_ratio > 1.0).then_some(Violation::EyeSafety {
        azimuth_deg: r.worst_azimuth_deg,
        rule: r.binding_rule,
        ratio: r.worst_ratio,
    })
}

/// What a check holds a profile against besides its own declared limits.
#[derive(Debug, Clone, Copy, Default)]
#[non_exhaustive]
pub struct CheckOptions<'a> {
    /// The sensor the profile is meant for: every declared limit must be at
    /// least as strict as the sensor's, and the pulse rate, frame rate,
    /// accounting and eye-safety parameters must match it.
    pub sensor: Option<&'a LidarSpec>,
    /// Accept a profile without eye-safety parameters (its verdict then says
    /// nothing about Class 1). Off by default.
    pub allow_missing_eye_safety: bool,
}

impl<'a> CheckOptions<'a> {
    /// Against the profile's declared limits, eye safety required.
    #[must_use]
    pub fn declared() -> Self {
        Self::default()
    }

    /// Against `sensor`'s own limits too.
    #[must_use]
    pub fn for_sensor(sensor: &'a LidarSpec) -> Self {
        Self {
            sensor: Some(sensor),
            ..Self::default()
        }
    }

    /// Accepts a profile without eye-safety parameters.
    #[must_use]
    pub fn allow_missing_eye_safety(mut self, allow: bool) -> Self {
        self.allow_missing_eye_safety = allow;
        self
    }
}

fn check_against_sensor(p: &Profile, sensor: &LidarSpec, v: &mut Vec<Violation>) {
    let (d, s) = (&p.limits, &sensor.limits);
    // The comparison is `lidar::no_looser`, false on NaN (the sensor's limits
    // are validated where they are read, but this must not rest on that).
    let mut looser =
        |field: &'static str, declared: Option<f64>, sensor: Option<f64>, side: LimitSide| {
            let bad = match (declared, sensor) {
                (_, None) => false,
                (None, Some(_)) => true,
                (Some(x), Some(y)) => !no_looser(x, y, side),
            };
            if bad {
                v.push(Violation::LooserThanSensor {
                    field,
                    declared,
                    sensor,
                });
            }
        };
    use LimitSide::{Lower, Upper};
    looser(
        "power_w_min",
        Some(d.power_w_min),
        Some(s.power_w_min),
        Lower,
    );
    looser(
        "power_w_max",
        Some(d.power_w_max),
        Some(s.power_w_max),
        Upper,
    );
    looser(
        "spin_rad_s_min",
        Some(d.spin_rad_s_min),
        Some(s.spin_rad_s_min),
        Lower,
    );
    looser(
        "spin_rad_s_max",
        Some(d.spin_rad_s_max),
        Some(s.spin_rad_s_max),
        Upper,
    );
    looser(
        "spin_accel_rad_s2_max",
        d.spin_accel_rad_s2_max,
        s.spin_accel_rad_s2_max,
        Upper,
    );
    looser(
        "power_slew_w_per_deg_max",
        d.power_slew_w_per_deg_max,
        s.power_slew_w_per_deg_max,
        Upper,
    );
    looser(
        "average_power_w",
        Some(p.average_power_w),
        Some(sensor.average_power_w),
        Upper,
    );
    #[allow(clippy::float_cmp)]
    if !(p.frame_rate_hz == sensor.frame_rate_hz) {
        v.push(Violation::SensorMismatch {
            field: "frame_rate_hz",
            detail: format!(
                "{} differs from the sensor's {}",
                p.frame_rate_hz, sensor.frame_rate_hz
            ),
        });
    }
    for (field, detail) in laser_mismatches(
        p.pulse_rate_hz,
        p.power_accounting,
        d.eye_safety.as_ref(),
        sensor,
    ) {
        v.push(Violation::SensorMismatch { field, detail });
    }
    if d.eye_safety.is_none() && s.eye_safety.is_some() {
        v.push(Violation::EyeSafetyMissing);
    }
}

/// Every violation of `profile` against its declared limits, eye safety
/// required (see [`check_with`]).
#[must_use]
pub fn check(profile: &Profile) -> Vec<Violation> {
    check_with(profile, &CheckOptions::declared())
}

/// Every violation of `profile`, recomputed from the profile alone, against
/// its declared limits and whatever `opts` adds.
#[must_use]
pub fn check_with(profile: &Profile, opts: &CheckOptions<'_>) -> Vec<Violation> {
    check_and_evaluate(profile, opts).0
}

/// [`check_with`], keeping the eye-safety evaluation it ran and the
/// summary it computed (`None` if the bins were too broken for either).
fn check_and_evaluate(
    profile: &Profile,
    opts: &CheckOptions<'_>,
) -> (Vec<Violation>, Option<ExposureReport>, Option<Summary>) {
    let mut v = Vec::new();
    check_header(profile, &mut v);
    if let Some(sensor) = opts.sensor {
        check_against_sensor(profile, sensor, &mut v);
    }
    let mut report = None;
    let mut summary = None;
    if check_structure(profile, &mut v) && !v.iter().any(is_structural) {
        let s = summarize(profile);
        check_limits(profile, &s, &mut v);
        report = check_eye_safety(profile, opts, &mut v);
        summary = Some(s);
    }
    (v, report, summary)
}

/// Violations after which the profile cannot be evaluated further.
fn is_structural(v: &Violation) -> bool {
    !matches!(
        v,
        Violation::LooserThanSensor { .. }
            | Violation::SensorMismatch { .. }
            | Violation::EyeSafetyMissing
    )
}

/// Certifies `profile` for `sensor`: its declared limits and the sensor's.
pub fn certify_for_sensor(
    profile: Profile,
    sensor: &LidarSpec,
) -> Result<CertifiedProfile, Rejected> {
    certify_with(profile, &CheckOptions::for_sensor(sensor))
}

/// Certifies against its declared limits and whatever `opts` adds.
pub fn certify_with(
    mut profile: Profile,
    opts: &CheckOptions<'_>,
) -> Result<CertifiedProfile, Rejected> {
    let (violations, eye_safety, summary) = check_and_evaluate(&profile, opts);
    if !violations.is_empty() {
        return Err(Rejected {
            violations,
            eye_safety: eye_safety.map(Box::new),
        });
    }
    // No violation: the bins were checked, so the summary was computed (of
    // this very profile; `summarize` is a function of the bins).
    profile.summary = Some(summary.unwrap_or_else(|| summarize(&profile)));
    Ok(CertifiedProfile {
        profile,
        eye_safety,
    })
}

/// Certifies a profile: the only way to obtain a [`CertifiedProfile`].
/// The checker's own [`Summary`] replaces any the input carried.
pub fn certify(profile: Profile) -> Result<CertifiedProfile, Rejected> {
    certify_with(profile, &CheckOptions::declared())
}
