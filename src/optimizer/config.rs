//! TOML configuration of an optimization problem.
//!
//! ```toml
//! bins = 360                       # equal bins (4..=1440, MAX_OPTIMIZER_BINS)
//!
//! [lidar]                          # a preset, then overrides of its fields
//! preset = "paper"                 # "paper", "vls128", "vlp16" or "os1-128"
//! average_power_w = 1.0e-3
//! power_accounting = "time"        # or "angle"
//!
//! [limits]                         # overrides of the preset's limits
//! power_w_max = 1.3e-3
//! spin_accel_rad_s2_max = 400.0    # or "unlimited"
//! power_slew_w_per_deg_max = "unlimited"
//! # [limits.eye_safety] replaces the preset's laser figures; without a
//! # `head` key of its own it keeps the preset's multi-beam head
//!
//! [focus]                          # region of focus: acuity model and η
//! threshold = 0.083
//! acuity = { model = "levi_e2", e2_deg = 2.72 }
//!
//! [levels]                         # hardware levels; omit for continuous
//! power_w = [0.5e-3, 0.8e-3, 1.1e-3]
//!
//! [objective]
//! mode = "joint"                   # range | resolution | joint
//! range_weight = 1.0
//! resolution_weight = 1.0
//! floor_weight = 0.001
//! priors = [{ start_deg = 250.0, width_deg = 40.0, weight = 0.5 }]
//! kind = "detection"               # or "sqrt" (default): the power step's value
//!
//! [objective.detection]            # kind = "detection" (super::detection)
//! models = ["argus", "physical"]   # return models, weighted equally
//! fog_pct = [0, 25, 50]            # the paper's fog levels
//! fog_weight = [1.0, 1.0, 1.0]     # their probabilities (omit: equal)
//! target_width_m = 1.8
//! reflectivity = 0.1
//! detect = 1.0                     # expected returns per frame
//! ```

use serde::Deserialize;
use std::path::Path;

use super::{Levels, Objective, OptError, Problem};
use crate::eye_safety::EyeSafetyParams;
use crate::model::acuity::FocusModel;
use crate::model::lidar::PowerAccounting;
use crate::model::presets;
use crate::text::Num;

/// A limit value in TOML: a number, or the word `"unlimited"`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum LimitValue {
    /// A finite limit.
    Value(f64),
    /// `"unlimited"`.
    Word(String),
}

/// `[lidar]`: a preset and overrides.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LidarSection {
    /// Base preset (default `paper`).
    pub preset: Option<String>,
    /// Overrides.
    pub frame_rate_hz: Option<f64>,
    /// Overrides.
    pub pulse_rate_hz: Option<f64>,
    /// Overrides.
    pub average_power_w: Option<f64>,
    /// Overrides.
    pub power_accounting: Option<PowerAccounting>,
}

/// `[limits]`: overrides.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LimitsSection {
    /// Override.
    pub power_w_min: Option<f64>,
    /// Override.
    pub power_w_max: Option<f64>,
    /// Override.
    pub spin_rad_s_min: Option<f64>,
    /// Override.
    pub spin_rad_s_max: Option<f64>,
    /// Override (`"unlimited"` allowed).
    pub spin_accel_rad_s2_max: Option<LimitValue>,
    /// Override (`"unlimited"` allowed).
    pub power_slew_w_per_deg_max: Option<LimitValue>,
    /// Override of the laser/optics parameters.
    pub eye_safety: Option<EyeSafetyParams>,
}

/// The most `lidar.average_power_w` may exceed `limits.power_w_max` by
/// (a factor). The programs measure power in units of the budget
/// (`x = p/P̄`, HiGHS's tolerances being absolute, 1e-7): a budget 10⁶
/// times the highest power puts every power below that tolerance, and the
/// answer was 0 W "optimal"; at 10³ the answers are still right. A budget
/// above the highest power never binds anyway.
pub const MAX_BUDGET_OVER_POWER_MAX: f64 = 1e3;

/// `lidar.average_power_w` within [`MAX_BUDGET_OVER_POWER_MAX`] of
/// `limits.power_w_max`.
fn budget_in_scale(lid: &crate::model::lidar::LidarSpec) -> Result<(), OptError> {
    let (p, hi) = (lid.average_power_w, lid.limits.power_w_max);
    if p > hi * MAX_BUDGET_OVER_POWER_MAX {
        return Err(OptError::Invalid {
            field: "lidar.average_power_w".into(),
            reason: format!(
                "{} W is more than {} times limits.power_w_max ({} W): the budget cannot bind, and powers in units of it fall below the solver's tolerance; lower it to at most that",
                Num(p),
                Num(MAX_BUDGET_OVER_POWER_MAX),
                Num(hi)
            ),
        });
    }
    Ok(())
}

/// The whole file.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OptimizerConfig {
    /// Bins (default 360).
    pub bins: Option<usize>,
    /// Sensor.
    pub lidar: LidarSection,
    /// Limits.
    pub limits: LimitsSection,
    /// Driver model (default: the preset's).
    pub focus: Option<FocusModel>,
    /// Hardware levels.
    pub levels: Levels,
    /// Objective.
    pub objective: Objective,
}

fn limit(field: &str, v: &LimitValue) -> Result<Option<f64>, OptError> {
    match v {
        LimitValue::Value(x) if x.is_finite() && *x >= 0.0 => Ok(Some(*x)),
        LimitValue::Word(w) if w == "unlimited" => Ok(None),
        other => Err(OptError::Invalid {
            field: format!("limits.{field}"),
            reason: match other {
                LimitValue::Value(x) => format!(
                    "{} is neither a finite number >= 0 nor \"unlimited\"",
                    Num(*x)
                ),
                LimitValue::Word(w) => {
                    format!("{w:?} is neither a finite number >= 0 nor \"unlimited\"")
                }
            },
        }),
    }
}

/// A normal number `> 0` (a subnormal, such as `5e-324`, has no physical
/// size and reached the solver as an "optimized" profile that violates
/// its own limits).
fn positive(field: &str, v: f64) -> Result<f64, OptError> {
    if v.is_normal() && v > 0.0 {
        Ok(v)
    } else {
        Err(OptError::Invalid {
            field: field.into(),
            reason: format!("{} must be finite, normal and > 0", Num(v)),
        })
    }
}

/// A rate within the crate's one rate range ([`crate::model::valid::rate_hz`]).
fn rate(field: &str, v: f64) -> Result<f64, OptError> {
    crate::model::valid::rate_hz(v).map_err(|reason| OptError::Invalid {
        field: field.into(),
        reason: format!("{} {reason}", Num(v)),
    })
}

/// Zero or a normal number `> 0` (see [`positive`]).
fn nonneg(field: &str, v: f64) -> Result<f64, OptError> {
    if v == 0.0 || (v.is_normal() && v > 0.0) {
        Ok(v)
    } else {
        Err(OptError::Invalid {
            field: field.into(),
            reason: format!("{} must be finite and zero or normal and > 0", Num(v)),
        })
    }
}

/// Largest objective weight accepted. Weights are relative (only their
/// ratios move the optimum), and they become the programs' coefficients:
/// HiGHS fails on coefficients near 1e19, so a weight
/// beyond any sensible ratio is refused as bad input instead.
pub const MAX_WEIGHT: f64 = 1e6;

/// A weight: finite, in `[0, MAX_WEIGHT]`.
pub(super) fn weight(field: &str, v: f64) -> Result<f64, OptError> {
    nonneg(field, v)?;
    if v > MAX_WEIGHT {
        return Err(OptError::Invalid {
            field: field.into(),
            reason: format!(
                "{} exceeds {MAX_WEIGHT:e}: weights are relative, scale them down together",
                Num(v)
            ),
        });
    }
    Ok(v)
}

impl OptimizerConfig {
    /// Parses TOML; `origin` names the file in errors (toml names key and line).
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, OptError> {
        toml::from_str(text).map_err(|e| OptError::Invalid {
            field: origin.to_owned(),
            reason: crate::text::toml_error(text, &e),
        })
    }

    /// Reads a TOML file.
    pub fn read(path: &Path) -> Result<Self, OptError> {
        let text = std::fs::read_to_string(path).map_err(|e| OptError::Invalid {
            field: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// The preset the file names (`[lidar] preset`, default `paper`),
    /// before the file's overrides: its `levels` are the closed forms' that
    /// `planner::figures` compares the optimum with.
    pub fn preset(&self) -> Result<presets::Preset, OptError> {
        let name = self.lidar.preset.as_deref().unwrap_or("paper");
        presets::preset(name).map_err(|e| OptError::Invalid {
            field: "lidar.preset".into(),
            reason: e.to_string(),
        })
    }

    /// Builds and validates the problem.
    pub fn problem(&self) -> Result<Problem, OptError> {
        let mut preset = self.preset()?;
        self.apply_lidar(&mut preset.lidar)?;
        self.apply_limits(&mut preset.lidar.limits)?;
        // A head fires every channel once per cycle: a rate the config sets
        // against its head is the config's inconsistency, named here.
        if let Some(params) = &preset.lidar.limits.eye_safety {
            params
                .check_pulse_rate(preset.lidar.pulse_rate_hz)
                .map_err(|e| OptError::Invalid {
                    field: "lidar.pulse_rate_hz".into(),
                    reason: e.to_string(),
                })?;
        }
        budget_in_scale(&preset.lidar)?;
        let focus = self.focus.clone().unwrap_or(preset.focus);
        focus.validate().map_err(|e| OptError::Invalid {
            field: "focus".into(),
            reason: e.to_string(),
        })?;
        // η of eq. 1 on the acuity's scale (V(0) = 1): at or outside [0, 1]
        // the region of focus is everything or nothing.
        if !(focus.threshold > 0.0 && focus.threshold < 1.0) {
            return Err(OptError::Invalid {
                field: "focus.threshold".into(),
                reason: format!(
                    "{} must lie strictly between 0 and 1 (the acuity's scale: V(0) = 1)",
                    Num(focus.threshold)
                ),
            });
        }
        self.validate_objective()?;
        let bins = self.bins.unwrap_or(360);
        super::validate_bins(bins, "bins")?;
        let problem = Problem {
            lidar: preset.lidar,
            focus,
            levels: self.levels.clone(),
            objective: self.objective.clone(),
            bins,
        };
        // Named as bad input here, with the file (the solve checks again).
        super::lp::levels_valid(&problem)?;
        Ok(problem)
    }

    /// `[lidar]`'s overrides onto the preset's sensor.
    fn apply_lidar(&self, lid: &mut crate::model::lidar::LidarSpec) -> Result<(), OptError> {
        if let Some(v) = self.lidar.frame_rate_hz {
            lid.frame_rate_hz = rate("lidar.frame_rate_hz", positive("lidar.frame_rate_hz", v)?)?;
        }
        if let Some(v) = self.lidar.pulse_rate_hz {
            // Named here, as written: the eye-safety model refuses it later
            // under its own name.
            lid.pulse_rate_hz = rate("lidar.pulse_rate_hz", positive("lidar.pulse_rate_hz", v)?)?;
        }
        if let Some(v) = self.lidar.average_power_w {
            lid.average_power_w = positive("lidar.average_power_w", v)?;
        }
        if let Some(v) = self.lidar.power_accounting {
            lid.power_accounting = v;
        }
        Ok(())
    }

    /// `[limits]`'s overrides onto the preset's limits, then the ranges
    /// checked.
    fn apply_limits(&self, lim: &mut crate::model::lidar::Limits) -> Result<(), OptError> {
        let l = &self.limits;
        if let Some(v) = l.power_w_min {
            lim.power_w_min = nonneg("limits.power_w_min", v)?;
        }
        if let Some(v) = l.power_w_max {
            lim.power_w_max = positive("limits.power_w_max", v)?;
        }
        if let Some(v) = l.spin_rad_s_min {
            lim.spin_rad_s_min = nonneg("limits.spin_rad_s_min", v)?;
        }
        if let Some(v) = l.spin_rad_s_max {
            lim.spin_rad_s_max = positive("limits.spin_rad_s_max", v)?;
        }
        if let Some(v) = &l.spin_accel_rad_s2_max {
            lim.spin_accel_rad_s2_max = limit("spin_accel_rad_s2_max", v)?;
        }
        if let Some(v) = &l.power_slew_w_per_deg_max {
            lim.power_slew_w_per_deg_max = limit("power_slew_w_per_deg_max", v)?;
        }
        // Ranges that contradict themselves are a bad file, not an
        // infeasible request (whichever of the two the file sets).
        if lim.power_w_min > lim.power_w_max {
            return Err(OptError::Invalid {
                field: "limits.power_w_min".into(),
                reason: format!(
                    "{} W is above limits.power_w_max {} W",
                    Num(lim.power_w_min),
                    Num(lim.power_w_max)
                ),
            });
        }
        if lim.spin_rad_s_min > lim.spin_rad_s_max {
            return Err(OptError::Invalid {
                field: "limits.spin_rad_s_min".into(),
                reason: format!(
                    "{} rad/s is above limits.spin_rad_s_max {} rad/s",
                    Num(lim.spin_rad_s_min),
                    Num(lim.spin_rad_s_max)
                ),
            });
        }
        if let Some(v) = &l.eye_safety {
            v.validate().map_err(|e| OptError::Invalid {
                field: "limits.eye_safety".into(),
                reason: e.to_string(),
            })?;
            // The table overrides what it names: a preset's multi-beam
            // head stays unless the table gives its own.
            let head = v
                .head
                .clone()
                .or_else(|| lim.eye_safety.as_ref().and_then(|e| e.head.clone()));
            lim.eye_safety = Some(EyeSafetyParams { head, ..v.clone() });
        }
        Ok(())
    }

    /// `[objective]`: weights, priors, the detection target, the mode.
    fn validate_objective(&self) -> Result<(), OptError> {
        let o = &self.objective;
        weight("objective.range_weight", o.range_weight)?;
        weight("objective.resolution_weight", o.resolution_weight)?;
        weight("objective.floor_weight", o.floor_weight)?;
        for (k, p) in o.priors.iter().enumerate() {
            weight(&format!("objective.priors[{k}].weight"), p.weight)?;
            if !(p.start_deg.is_finite()
                && p.width_deg.is_finite()
                && (0.0..=360.0).contains(&p.width_deg))
            {
                return Err(OptError::Invalid {
                    field: format!("objective.priors[{k}]"),
                    reason: "start_deg must be finite and width_deg in [0, 360]".into(),
                });
            }
        }
        o.detection.validate()?;
        if o.kind == super::ObjectiveKind::Sqrt && o.detection != super::Detection::default() {
            return Err(OptError::Invalid {
                field: "objective.detection".into(),
                reason: "is given but objective.kind is \"sqrt\" (the default), which does not read it; set kind = \"detection\" or drop the table".into(),
            });
        }
        if o.mode == crate::model::Mode::Baseline {
            return Err(OptError::Invalid {
                field: "objective.mode".into(),
                reason: "baseline has nothing to optimize; use range, resolution or joint".into(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_key() {
        let e = OptimizerConfig::from_toml("[objective]\nmode = \"warp\"\n", "c.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.toml") && e.contains("mode"), "{e}");
        let e =
            OptimizerConfig::from_toml("[limits]\nspin_accel_rad_s2_max = \"fast\"\n", "c.toml")
                .unwrap()
                .problem()
                .unwrap_err()
                .to_string();
        assert!(e.contains("limits.spin_accel_rad_s2_max"), "{e}");
        let e = OptimizerConfig::from_toml("[lidar]\naverage_power_w = -1.0\n", "c.toml")
            .unwrap()
            .problem()
            .unwrap_err()
            .to_string();
        assert!(e.contains("lidar.average_power_w"), "{e}");
        let e = OptimizerConfig::from_toml("[limts]\n", "c.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("limts"), "{e}");
    }

    #[test]
    fn detection_objective_parses_and_names_bad_fields() {
        let p = OptimizerConfig::from_toml(
            "[objective]\nkind = \"detection\"\n[objective.detection]\nmodels = [\"physical\"]\nfog_pct = [25, 50]\nfog_weight = [3.0, 1.0]\ndetect = 2.0\n",
            "c.toml",
        )
        .unwrap()
        .problem()
        .unwrap();
        assert_eq!(p.objective.kind, super::super::ObjectiveKind::Detection);
        let d = &p.objective.detection;
        assert_eq!(d.models, vec![crate::model::returns::ModelKind::Physical]);
        assert_eq!((d.fog_pct.clone(), d.detect), (vec![25, 50], 2.0));
        assert_eq!(d.target_width_m, 1.8);
        // The default stays `sqrt`.
        let p = OptimizerConfig::from_toml("", "c.toml")
            .unwrap()
            .problem()
            .unwrap();
        assert_eq!(p.objective.kind, super::super::ObjectiveKind::Sqrt);
        for (body, field) in [
            ("fog_pct = [10]", "objective.detection.fog_pct[0]"),
            ("fog_weight = [1.0]", "objective.detection.fog_weight"),
            (
                "fog_weight = [1.0, -1.0, 1.0]",
                "objective.detection.fog_weight[1]",
            ),
            ("models = []", "objective.detection.models"),
            ("target_width_m = 0.0", "objective.detection.target_width_m"),
            ("reflectivity = 1.5", "objective.detection.reflectivity"),
            ("detect = nan", "objective.detection.detect"),
        ] {
            let e = OptimizerConfig::from_toml(
                &format!("[objective]\nkind = \"detection\"\n[objective.detection]\n{body}\n"),
                "c.toml",
            )
            .unwrap()
            .problem()
            .unwrap_err()
            .to_string();
            assert!(e.contains(field), "{body}: {e}");
        }
        let e = OptimizerConfig::from_toml("[objective]\nkind = \"closest\"\n", "c.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("kind"), "{e}");
    }
}
