//! The scan profile and its interchange formats: `gaze-lidar/profile@1` JSON
//! and a one-row-per-bin CSV.
//!
//! A [`Profile`] is plain data and may be anything a file says; only a
//! [`crate::checker::CertifiedProfile`] is known to respect its limits.

use serde::{Deserialize, Serialize};
use std::path::Path;
use thiserror::Error;

pub mod kinematics;

use crate::model::lidar::{Limits, PowerAccounting};

/// The value of the `format` field.
pub const PROFILE_FORMAT: &str = "gaze-lidar/profile@1";

/// Which region a bin belongs to (informational).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Region {
    /// Driver's region of focus.
    Rof,
    /// LiDAR region of interest (outside the driver's focus).
    Roi,
}

/// One azimuth bin of a profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bin {
    /// Start azimuth, degrees.
    pub start_deg: f64,
    /// Angular width, degrees.
    pub width_deg: f64,
    /// Laser power (mean optical output while scanning this bin), W.
    pub power_w: f64,
    /// Spin at the bin's start, rad/s.
    pub spin_start_rad_s: f64,
    /// Spin at the bin's end, rad/s (constant angular acceleration in between).
    pub spin_end_rad_s: f64,
    /// Region (informational; not trusted by the checker).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<Region>,
    /// Dwell time in the bin, s (informational; the checker recomputes it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dwell_s: Option<f64>,
}

impl Bin {
    /// Dwell time `t = 2Δθ / (ω_start + ω_end)` (constant acceleration), s.
    #[must_use]
    pub fn dwell_time_s(&self) -> f64 {
        kinematics::BinMotion::dwell_s(self)
    }

    /// Angular acceleration `a = (ω_end² − ω_start²) / (2Δθ)`, rad/s².
    #[must_use]
    pub fn spin_accel_rad_s2(&self) -> f64 {
        kinematics::BinMotion::accel_rad_s2(self)
    }

    /// Centre azimuth, degrees.
    #[must_use]
    pub fn center_deg(&self) -> f64 {
        self.start_deg + 0.5 * self.width_deg
    }
}

/// Figures derived from the bins; written by the checker on certified output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Summary {
    /// `Σ P_i Δθ_i / 360°`, W (eq. 4 as printed).
    pub average_power_angle_w: f64,
    /// Energy per frame / frame period, W.
    pub average_power_time_w: f64,
    /// Energy per frame, J.
    pub energy_per_frame_j: f64,
    /// Sum of the bins' dwell times, s.
    pub frame_period_s: f64,
    /// Largest |angular acceleration| the profile needs, rad/s²; `null` when
    /// the spin steps at a bin edge (an infinite acceleration).
    pub max_spin_accel_rad_s2: Option<f64>,
    /// Total width of bins marked `rof`, degrees.
    pub rof_width_deg: f64,
    /// Lowest and highest power, W.
    pub power_w_range: [f64; 2],
    /// Lowest and highest spin, rad/s.
    pub spin_rad_s_range: [f64; 2],
}

/// A scan profile in the `gaze-lidar/profile@1` layout (README, "The profile format").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// Always [`PROFILE_FORMAT`].
    pub format: String,
    /// Nominal revolutions per second.
    pub frame_rate_hz: f64,
    /// Laser firing rate per channel, Hz.
    pub pulse_rate_hz: f64,
    /// The average power budget the profile was built for, W.
    pub average_power_w: f64,
    /// How the budget is accounted.
    pub power_accounting: PowerAccounting,
    /// Gaze azimuth used; `null` for a gaze-free profile.
    #[serde(deserialize_with = "required_f64")]
    pub gaze_deg: Option<f64>,
    /// Limits the profile was built and is checked against.
    pub limits: Limits,
    /// Bins in azimuth order covering `[0, 360)`.
    pub bins: Vec<Bin>,
    /// How it was made (e.g. `closed-form range`); informational.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// Derived figures; informational on input (the checker recomputes them).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub summary: Option<Summary>,
    /// How close to optimal an optimized profile is; informational (the
    /// checker neither needs nor checks it; `specs/optimizer.md` says what
    /// each figure proves).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optimality: Option<Optimality>,
}

/// The optimizer's optimality figures for the LP (or MILP) of its final
/// step — the power step's, or in `resolution` mode (no power step) the
/// dwell step's — in the objective's units: `objective` of the profile's
/// point and an `upper_bound` of that program's optimum, both checked in
/// exact rational arithmetic (`objective` rounded down, `upper_bound` and
/// `gap` rounded up to doubles).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Optimality {
    /// Objective of the answer (a feasible point, exact, rounded down).
    pub objective: f64,
    /// Proven upper bound of the optimum (rounded up).
    pub upper_bound: f64,
    /// `upper_bound − objective` (exact difference, rounded up).
    pub gap: f64,
    /// Whether the exact gap is 0 (the answer is proven optimal).
    pub exact: bool,
    /// The joint problem's figures (power × dwell, a global bound from a
    /// McCormick relaxation; `specs/optimizer.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub global: Option<GlobalOptimality>,
    /// The answer in units people use — range (m) and point density
    /// (points per degree) inside and outside the region of focus — next
    /// to the paper's closed form's for the same gaze.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub figures: Option<UnitFigures>,
    /// Where the eye-safety bound exceeds every valid cut (its conservatism
    /// in the multi-pass or window rules), the power step tightens the
    /// cuts that bind there until the bound certifies: the largest factor
    /// a limit was divided by (> 1). `objective`/`upper_bound` are then
    /// for the tightened program, and the answer may be below the best
    /// certifiable one by up to that factor's share (`specs/optimizer.md`,
    /// "Eye safety as cuts"). Absent when every cut is valid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eye_safety_tightening: Option<f64>,
    /// The dwell steps' programs (`joint` and `resolution` modes): every
    /// one was certified exactly, and these are the last one's figures.
    /// Absent when no dwell step ran or one could not be certified.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dwell_step: Option<StepOptimality>,
}

/// One step's program's exact figures (as [`Optimality`]'s), and how many
/// programs of that step the solve certified.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepOptimality {
    /// Objective of the program's point (exact, rounded down).
    pub objective: f64,
    /// Proven upper bound of the program's optimum (rounded up).
    pub upper_bound: f64,
    /// `upper_bound − objective` (exact difference, rounded up).
    pub gap: f64,
    /// Whether the exact gap is 0.
    pub exact: bool,
    /// Programs of this step solved and certified in this solve.
    pub programs: usize,
}

/// A profile's figures in units people use, next to the paper's closed
/// form's (same sensor, driver model, mode, gaze and bin count).
///
/// Per bin: **range** `range_m` on the sensor's reference reflectivity in
/// clear air, from the range equation calibrated at its rated range (`P̄`
/// reaches `rated_range_m`; `gaze_lidar::model::range`); **point density**
/// `points_per_deg = pulse_rate_hz · dwell_s / width_deg`, per channel and
/// revolution (the pulse rate over the bin's mean spin in deg/s).
///
/// Per region: a bin belongs to the region of focus when its centre lies
/// in it (the rule both planners label bins `rof` with), else to the
/// region of interest. Each figure aggregates over the region's bins as
/// an **angle-weighted mean** `Σ Δθ_i f_i / Σ Δθ_i` (for the density that
/// is the region's points over its degrees) with the **min** and **max**
/// over its bins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitFigures {
    /// This profile's.
    pub profile: RegionFigures,
    /// The closed form's; absent when the closed form cannot be certified
    /// on this sensor (`closed_form_rejected` says why).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_form: Option<RegionFigures>,
    /// Why there is no closed form to compare with (one line).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_form_rejected: Option<String>,
}

/// Figures inside the driver's region of focus and outside it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionFigures {
    /// Region of focus (`null` when no bin's centre lies in it).
    pub rof: Option<RegionFigure>,
    /// Region of interest, the rest (`null` when empty).
    pub roi: Option<RegionFigure>,
}

/// One region's figures ([`UnitFigures`] says how they aggregate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionFigure {
    /// Total width of the region's bins, degrees.
    pub width_deg: f64,
    /// Range on the reference reflectivity in clear air, m.
    pub range_m: Aggregate,
    /// Points per degree per channel and revolution.
    pub points_per_deg: Aggregate,
}

/// A per-bin figure over a region: angle-weighted mean, min and max.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Aggregate {
    /// `Σ Δθ_i f_i / Σ Δθ_i` over the region's bins.
    pub mean: f64,
    /// Smallest over the region's bins.
    pub min: f64,
    /// Largest over the region's bins.
    pub max: f64,
}

/// Global figures: `objective` of the answer under the model objective
/// (the true √ utilities, floating point, lowered by a relative 1e-12) and
/// an `upper_bound` of every certifiable profile's, from a relaxation whose
/// bound is checked in exact arithmetic (rounded up).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GlobalOptimality {
    /// Model objective of the answer.
    pub objective: f64,
    /// Upper bound of the optimum.
    pub upper_bound: f64,
    /// `upper_bound − objective`.
    pub gap: f64,
}

fn required_f64<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    Option::<f64>::deserialize(d)
}

/// Errors reading or writing profiles and other output files.
#[derive(Debug, Error)]
pub enum IoError {
    /// Could not read or write a file.
    #[error("{path}: {source}")]
    File {
        /// The file.
        path: String,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
    /// JSON did not parse or did not match the format; names line and column.
    #[error("{path}:{line}:{column}: {message}")]
    Json {
        /// The file (or `-` for stdin).
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// serde's message (names the field).
        message: String,
    },
    /// The `format` field is not `gaze-lidar/profile@1`.
    #[error("{path}: field 'format' is '{found}', expected '{PROFILE_FORMAT}'")]
    Format {
        /// The file.
        path: String,
        /// What it said.
        found: String,
    },
    /// JSON encoding failed.
    #[cfg(feature = "json")]
    #[error("json: {0}")]
    Encode(#[from] serde_json::Error),
    /// Encoding to another format (CSV, in the `gaze-lidar` crate) failed.
    #[error("{format}: {message}")]
    Encoding {
        /// The format.
        format: &'static str,
        /// What went wrong.
        message: String,
    },
}

#[cfg(feature = "json")]
/// serde_json appends " at line L column C"; the error prints them already.
pub(crate) fn strip_position(msg: &str) -> String {
    match msg.rfind(" at line ") {
        Some(i) => msg[..i].to_owned(),
        None => msg.to_owned(),
    }
}

/// The blocks of a profile that are informational on input: the checker
/// recomputes or ignores them.
#[cfg(feature = "json")]
const INFORMATIONAL: [&str; 2] = ["summary", "optimality"];

#[cfg(feature = "json")]
impl Profile {
    /// Parses profile@1 JSON; `origin` names the source in errors. An
    /// informational block (`summary`, `optimality`) that does not read
    /// (e.g. a field a newer writer added) is dropped, not an error: the
    /// verdict never depends on it ([`Self::from_json_with_notes`] says why
    /// each was dropped).
    pub fn from_json(text: &str, origin: &str) -> Result<Self, IoError> {
        Self::from_json_with_notes(text, origin).map(|(p, _)| p)
    }

    /// [`Self::from_json`], with one line per informational block dropped
    /// (`"optimality: not read (unknown field `x`, …)"`). Everything else
    /// is read strictly: an error there is the error, with its line and
    /// column.
    pub fn from_json_with_notes(text: &str, origin: &str) -> Result<(Self, Vec<String>), IoError> {
        let strict = match serde_json::from_str::<Self>(text) {
            Ok(p) => return p.of_format(origin).map(|p| (p, Vec::new())),
            Err(e) => IoError::Json {
                path: origin.to_owned(),
                line: e.line(),
                column: e.column(),
                message: strip_position(&e.to_string()),
            },
        };
        let Ok(serde_json::Value::Object(mut fields)) = serde_json::from_str(text) else {
            return Err(strict);
        };
        let mut notes = Vec::new();
        for key in INFORMATIONAL {
            let Some(block) = fields.get(key) else {
                continue;
            };
            let unread = match key {
                "summary" => Option::<Summary>::deserialize(block).err(),
                _ => Option::<Optimality>::deserialize(block).err(),
            };
            if let Some(e) = unread {
                notes.push(format!(
                    "{key}: not read ({}); informational, the verdict does not depend on it",
                    strip_position(&e.to_string())
                ));
                fields.remove(key);
            }
        }
        if notes.is_empty() {
            return Err(strict);
        }
        match Self::deserialize(serde_json::Value::Object(fields)) {
            Ok(p) => p.of_format(origin).map(|p| (p, notes)),
            Err(_) => Err(strict),
        }
    }

    /// `self` if its `format` is [`PROFILE_FORMAT`].
    fn of_format(self, origin: &str) -> Result<Self, IoError> {
        if self.format != PROFILE_FORMAT {
            return Err(IoError::Format {
                path: origin.to_owned(),
                found: self.format,
            });
        }
        Ok(self)
    }

    /// Reads a profile@1 JSON file.
    pub fn read_json(path: &Path) -> Result<Self, IoError> {
        let text = std::fs::read_to_string(path).map_err(|source| IoError::File {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_json(&text, &path.display().to_string())
    }

    /// Pretty JSON with a trailing newline.
    pub fn to_json(&self) -> Result<String, IoError> {
        let mut s = serde_json::to_string_pretty(self)?;
        s.push('\n');
        Ok(s)
    }
}
