//! The optimizer: power and spin profiles derived from the driver's acuity
//! function, with HiGHS (every program's answer certified exactly).
//!
//! # Formulation
//!
//! `N` equal bins of width `θ_i`; per bin a power `p_i` and a dwell `t_i`
//! (mean spin `θ_i / t_i`). Weights `w_i = (1 − V(e_i)/V(0)) + priors(β_i)`
//! (the driver's deficit at the bin centre, plus static priors), and a small
//! floor `ε` so that budget nobody needs still goes somewhere sensible.
//!
//! Objective (maximise):
//! `λ_R Σ θ_i (w_i + ε) U_R(p_i/P̄) + λ_ρ Σ θ_i (w_i + ε) U_ρ(r_i)`
//! - `U_R`: range utility, concave: range ∝ √P (range equation, clear air),
//!   made piecewise-linear from below with [`UTILITY_SEGMENTS`] chords;
//! - `U_ρ`: resolution utility of the density ratio `r_i = t_i·2π/(θ_i·T)`,
//!   √r piecewise-linear likewise (diminishing returns of extra points).
//!
//! Constraints: frame period `Σ t_i = T`; budget `Σ θ_i p_i <= 2π P̄`
//! (angle) or `Σ t_i p_i <= P̄ T` (time); `p_i ∈ [P_min, P_max]`;
//! `t_i ∈ [θ_i/ω_max, θ_i/ω_min]`; slew `|p_{i+1} − p_i| <= s·(Δ_i+Δ_{i+1})/2`;
//! acceleration (linearised, see below); eye safety as cuts from the core's
//! sound bound (`gaze_lidar_core::eye_safety::cuts`): the power step adds
//! the concrete exposures its answer breaks until the bound certifies
//! (`specs/optimizer.md`, "Eye safety as cuts").
//!
//! Power × dwell is bilinear under time accounting and in the eye-safety
//! rules, so the problem is solved by **block-coordinate ascent**: a power
//! step (dwell fixed: an LP, or a MILP with `K` hardware power levels) and a
//! dwell step (power fixed: an LP, or a MILP with spin set-points), starting
//! from the uniform baseline and ending with a power step. Every program's
//! answer carries a certificate checked in exact rational arithmetic
//! ([`certificate`]; `optimality` and `optimality.dwell_step` in the
//! profile), and [`global`] bounds the joint problem's optimum from a
//! relaxation (`optimality.global`): block-coordinate ascent stops at a
//! stationary point, and the global gap says how far it can be.
//!
//! Acceleration: with a finite motor limit the dwell step bounds the change
//! of slowness `s = t/θ` between neighbours, `|Δs| <= a·Δθ·(1−ρ)³/ω̃³`
//! linearised around the current iterate ω̃ with a trust region `ρ`
//! (sequential LP); the continuous spin profile is then built from node
//! spins between bins and rescaled so the frame period is exact. The
//! checker has the last word: a solution that fails it is an error.

pub mod certificate;
pub mod config;
pub mod detection;
pub mod error;
mod exact;
pub mod fast;
pub mod figures;
pub mod global;
mod level_choice;
mod lp;
pub mod program;
mod setpoints;
pub mod settings;
mod utility;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::checker::{certify, CertifiedProfile, Rejected};
use crate::model::acuity::FocusModel;
use crate::model::lidar::{LidarSpec, PowerAccounting};
use crate::model::Mode;

pub use config::OptimizerConfig;
pub use detection::{Detection, ObjectiveKind};
pub use error::{CertificateError, Infeasible, SpinLimit};
pub use settings::OptimizerSettings;

/// Chords of the piecewise-linear utilities ([`OptimizerSettings::utility_segments`]).
pub const UTILITY_SEGMENTS: usize = OptimizerSettings::DEFAULT.utility_segments;

/// A static prior: extra weight on a sector (e.g. cross-traffic directions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Prior {
    /// Sector start, degrees.
    pub start_deg: f64,
    /// Sector width, degrees.
    pub width_deg: f64,
    /// Weight added to the deficit inside the sector (>= 0).
    pub weight: f64,
}

/// What to maximise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Objective {
    /// Which blocks move: `range` (power), `resolution` (spin) or `joint`.
    pub mode: Mode,
    /// λ_R: value of range (1 = the baseline's range over the whole turn).
    pub range_weight: f64,
    /// λ_ρ: value of resolution (1 = the baseline's density over the whole turn).
    pub resolution_weight: f64,
    /// ε: weight everywhere, so spare budget is spread rather than wasted.
    pub floor_weight: f64,
    /// Static priors.
    pub priors: Vec<Prior>,
    /// The power step's per-bin value: `sqrt` (default) or `detection`.
    pub kind: ObjectiveKind,
    /// The detection objective's target and conditions (`kind = "detection"`).
    pub detection: Detection,
}

impl Default for Objective {
    fn default() -> Self {
        Self {
            mode: Mode::Joint,
            range_weight: 1.0,
            resolution_weight: 1.0,
            floor_weight: 1e-3,
            priors: Vec::new(),
            kind: ObjectiveKind::Sqrt,
            detection: Detection::default(),
        }
    }
}

/// Hardware levels: empty = continuous.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Levels {
    /// Allowed laser powers, W (K levels → MILP).
    pub power_w: Vec<f64>,
    /// Allowed spin set-points, rad/s (→ MILP; steps, so no acceleration limit).
    pub spin_rad_s: Vec<f64>,
}

/// Most bins the optimizer accepts ([`OptimizerSettings::max_bins`], which
/// gives the reason).
pub const MAX_OPTIMIZER_BINS: usize = OptimizerSettings::DEFAULT.max_bins;

/// Checks the optimizer's bin count (`field` names it in the error).
pub fn validate_bins(bins: usize, field: &str) -> Result<(), OptError> {
    if (crate::model::angle::MIN_BINS..=MAX_OPTIMIZER_BINS).contains(&bins) {
        Ok(())
    } else {
        Err(OptError::Invalid {
            field: field.into(),
            reason: format!(
                "{bins} must lie in [{}, {MAX_OPTIMIZER_BINS}] for the optimizer (its solve time grows faster than linearly with the bin count)",
                crate::model::angle::MIN_BINS
            ),
        })
    }
}

/// A complete optimization problem (everything but the gaze).
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The sensor and its limits.
    pub lidar: LidarSpec,
    /// Driver model.
    pub focus: FocusModel,
    /// Hardware levels.
    pub levels: Levels,
    /// Objective.
    pub objective: Objective,
    /// Number of equal bins.
    pub bins: usize,
}

/// Why no certified profile came out.
#[derive(Debug, Error)]
pub enum OptError {
    /// Bad configuration or argument: an input fault.
    #[error("{field}: {reason}")]
    Invalid {
        /// Key.
        field: String,
        /// Why.
        reason: String,
    },
    /// The limits cannot all be met (infeasible); says which.
    #[error("infeasible: {0}")]
    Infeasible(#[from] Infeasible),
    /// HiGHS failed.
    #[error("solver: {0}")]
    Solver(String),
    /// The solution failed the checker (never handed out).
    #[error("the optimized profile violates its limits: {}", crate::checker::summarize_list(&.0.violations))]
    Rejected(#[from] Rejected),
}

impl OptError {
    /// An input fault rather than infeasibility.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        matches!(self, Self::Invalid { .. })
    }
}

impl Problem {
    /// The paper-equivalent problem for a preset: box acuity, the paper's two
    /// power levels (`P_low`, and `P_high` from eq. 4) and two spin
    /// set-points (eq. 6), no smoothing. Its optimum is the closed form.
    pub fn paper_equivalent(
        preset: &crate::model::presets::Preset,
        mode: Mode,
        bins: usize,
    ) -> Result<Self, OptError> {
        let rof = preset.focus.regions(0.0).rof.measure_deg();
        let lv = crate::planner::closed_form::levels(preset, Mode::Joint, rof, 360.0 - rof)
            .map_err(|e| OptError::Invalid {
                field: "levels".into(),
                reason: e.to_string(),
            })?;
        let power = crate::planner::closed_form::levels(preset, Mode::Range, rof, 360.0 - rof)
            .map_err(|e| OptError::Invalid {
                field: "levels".into(),
                reason: e.to_string(),
            })?
            .power_w;
        let mut power_w = power.to_vec();
        if preset.lidar.power_accounting == PowerAccounting::Time && mode == Mode::Joint {
            power_w = lv.power_w.to_vec();
        }
        Ok(Self {
            lidar: preset.lidar.clone(),
            focus: preset.focus.clone(),
            levels: Levels {
                power_w,
                spin_rad_s: lv.spin_rad_s.to_vec(),
            },
            objective: Objective {
                mode,
                ..Objective::default()
            },
            bins,
        })
    }
}

impl Problem {
    /// Drops the spin set-points when a finite acceleration limit forbids
    /// the spin steps between them and the mode moves the spin (the
    /// optimizer then ramps the spin); returns the set-points dropped.
    pub fn drop_forbidden_setpoints(&mut self) -> Option<Vec<f64>> {
        let forbidden = !self.levels.spin_rad_s.is_empty()
            && self.lidar.limits.spin_accel_rad_s2_max.is_some()
            && self.objective.mode.controls_resolution();
        forbidden.then(|| std::mem::take(&mut self.levels.spin_rad_s))
    }
}

/// Optimizes for `gaze_deg` and certifies the result; its `optimality`
/// block states the final power step's exact gap (see [`certificate`]).
pub fn optimize(problem: &Problem, gaze_deg: f64) -> Result<CertifiedProfile, OptError> {
    optimize_with_certificate(problem, gaze_deg).map(|(c, _)| c)
}

/// [`optimize`] without the optimality figures (no certificate, no global
/// bound): for the fast path's canonical solutions, whose rotated copies
/// carry none anyway.
pub(crate) fn optimize_unrated(
    problem: &Problem,
    gaze_deg: f64,
) -> Result<CertifiedProfile, OptError> {
    crate::planner::validate_gaze(gaze_deg).map_err(|e| OptError::Invalid {
        field: "gaze-deg".into(),
        reason: e.to_string(),
    })?;
    Ok(certify(lp::solve(problem, gaze_deg)?.profile)?)
}

/// [`optimize`], also handing out the final step's program and its exact
/// certificate (the power step's; in `resolution` mode with spin steps the
/// dwell step's), or why there is none.
pub fn optimize_with_certificate(
    problem: &Problem,
    gaze_deg: f64,
) -> Result<
    (
        CertifiedProfile,
        Result<certificate::Certified, CertificateError>,
    ),
    OptError,
> {
    crate::planner::validate_gaze(gaze_deg).map_err(|e| OptError::Invalid {
        field: "gaze-deg".into(),
        reason: e.to_string(),
    })?;
    // The global bound does not depend on the answer: it is computed
    // alongside the solve (its threads fill the solve's serial HiGHS
    // phases); both are deterministic, so the output is the same bits.
    let (solved, upper_bound) = rayon::join(
        || lp::solve(problem, gaze_deg),
        || global::upper_bound(problem, gaze_deg),
    );
    let lp::Solution {
        mut profile,
        power,
        dwell,
    } = solved?;
    let dwell_figures = dwell
        .as_ref()
        .and_then(|d| d.last.as_ref().ok().map(|c| c.step_figures(d.programs)));
    let cert = match power {
        None => match dwell {
            Some(lp::DwellCertificates {
                last: Ok(c),
                is_answer: true,
                ..
            }) => {
                profile.optimality = Some(c.optimality());
                Ok(c)
            }
            Some(lp::DwellCertificates { last: Err(e), .. }) => Err(e),
            _ => Err(CertificateError::NoProgram),
        },
        Some(plp) => {
            let p: Vec<f64> = profile.bins.iter().map(|b| b.power_w).collect();
            plp.certify(&p).map(|(c, q)| {
                for (b, qi) in profile.bins.iter_mut().zip(q) {
                    b.power_w = qi;
                }
                let mut o = c.optimality();
                o.eye_safety_tightening = plp.tightening;
                profile.optimality = Some(o);
                c
            })
        }
    };
    if let Some(o) = profile.optimality.as_mut() {
        o.dwell_step = dwell_figures;
    }
    if profile.optimality.is_some() {
        let global = upper_bound
            .and_then(|ub| global::bound(problem, gaze_deg, &profile, ub))
            .ok();
        if let Some(opt) = profile.optimality.as_mut() {
            opt.global = global;
        }
    }
    Ok((certify(profile)?, cert))
}

/// The objective with the exact utilities (√ of the power and density
/// ratios, not the programs' chords) of `profile` for `problem` at
/// `gaze_deg`: what the chords approximate from below, comparable across
/// programs whose chords differ.
pub fn exact_objective(
    problem: &Problem,
    gaze_deg: f64,
    profile: &crate::profile::Profile,
) -> Result<f64, OptError> {
    let g = lp::grid(problem, gaze_deg)?;
    if profile.bins.len() != g.n {
        return Err(OptError::Invalid {
            field: "bins".into(),
            reason: format!("{} bins, the problem has {}", profile.bins.len(), g.n),
        });
    }
    let o = &problem.objective;
    Ok(profile
        .bins
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let (range, res) = utilities(problem, g.theta[i], b);
            let range = if o.kind == ObjectiveKind::Detection {
                let dwell = crate::profile::kinematics::BinMotion::dwell_s(b);
                let x = b.power_w / problem.lidar.average_power_w;
                detection::exact_range_utility(problem, g.theta[i], dwell, x)
            } else {
                range
            };
            let range = if o.mode.controls_range() {
                o.range_weight * range
            } else {
                0.0
            };
            let res = if o.mode.controls_resolution() {
                o.resolution_weight * res
            } else {
                0.0
            };
            g.theta[i] * g.weight[i] * (range + res)
        })
        .sum())
}

/// A bin's exact utilities: `√(p/P̄)` and `√r`, the density ratio
/// `r = t·2π/(θ·T)` with the bin's dwell `t` from its spins (the
/// kinematics, never the informational `dwell_s` field). The one
/// definition [`exact_objective`] and the global bound's objective use.
pub(crate) fn utilities(
    problem: &Problem,
    theta_rad: f64,
    bin: &crate::profile::Bin,
) -> (f64, f64) {
    let period = 1.0 / problem.lidar.frame_rate_hz;
    let dwell = crate::profile::kinematics::BinMotion::dwell_s(bin);
    let r = dwell * std::f64::consts::TAU / (theta_rad * period);
    (
        (bin.power_w / problem.lidar.average_power_w)
            .max(0.0)
            .sqrt(),
        r.max(0.0).sqrt(),
    )
}
