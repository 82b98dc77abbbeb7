//! The optimizer's typed errors: why a request cannot be met
//! ([`Infeasible`]) and why a program's answer carries no exact
//! certificate ([`CertificateError`]). Their messages are the ones the
//! command line prints.

use thiserror::Error;

/// Which spin limit cannot meet the frame period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpinLimit {
    /// `limits.spin_rad_s_max` is below the mean spin the frame needs.
    Max,
    /// `limits.spin_rad_s_min` is above it.
    Min,
    /// No choice of the spin set-points (`levels.spin_rad_s`, those within
    /// the spin limits) on `bins` equal bins makes one turn take the frame
    /// period (within the checker's 10⁻⁹).
    SetPoints {
        /// The bins.
        bins: usize,
        /// The set-points within the spin limits.
        count: usize,
        /// The nearest frame period below it that a choice reaches, s.
        below_s: Option<f64>,
        /// The nearest above it, s.
        above_s: Option<f64>,
    },
}

/// Why the limits cannot all be met.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Infeasible {
    /// One turn per frame period needs a mean spin the spin limits exclude.
    #[error("{}", frame_unreachable(*.limit, *.spin_rad_s, *.mean_spin_rad_s, *.frame_rate_hz))]
    FrameUnreachable {
        /// The limit that excludes it.
        limit: SpinLimit,
        /// Its value, rad/s.
        spin_rad_s: f64,
        /// The mean spin one turn per frame needs, rad/s.
        mean_spin_rad_s: f64,
        /// The frame rate, Hz.
        frame_rate_hz: f64,
    },
    /// The power floor alone spends more than the average power budget.
    #[error("power_w_min {power_w_min:.4e} W alone exceeds the average power budget {average_power_w:.4e} W")]
    FloorOverBudget {
        /// `limits.power_w_min`, W.
        power_w_min: f64,
        /// The average power budget, W.
        average_power_w: f64,
    },
    /// Every hardware power level within the limits is above the average
    /// power budget: any profile of them spends more.
    #[error("every power level within [power_w_min, power_w_max] (levels.power_w; the lowest {level_w:.4e} W) exceeds the average power budget {average_power_w:.4e} W")]
    LevelsOverBudget {
        /// The lowest level within the limits, W.
        level_w: f64,
        /// The average power budget, W.
        average_power_w: f64,
    },
    /// A bin's single-pulse eye-safety cap (at its spin) is below the power floor.
    #[error("eye-safety cap {cap_w:.4e} W at {wavelength_nm} nm in bin {bin} (the single-pulse limit at this spin) is below power_w_min {power_w_min:.4e} W")]
    EyeCapBelowFloor {
        /// The cap, W.
        cap_w: f64,
        /// Wavelength, nm.
        wavelength_nm: f64,
        /// The bin.
        bin: usize,
        /// `limits.power_w_min`, W.
        power_w_min: f64,
    },
    /// The power floor everywhere at the mean spin is over the Class 1 limit.
    #[error("eye safety: power_w_min {power_w_min:.4e} W everywhere at the mean spin is {} % of the Class 1 limit (worst at {at_deg:.3}°) at {wavelength_nm} nm", over_pct(*.ratio))]
    EyeFloorOverLimit {
        /// `limits.power_w_min`, W.
        power_w_min: f64,
        /// The bound's ratio to the limit.
        ratio: f64,
        /// Where it binds, degrees.
        at_deg: f64,
        /// Wavelength, nm.
        wavelength_nm: f64,
    },
    /// The power floor in every bin breaks a window's limit.
    #[error("eye safety at {wavelength_nm} nm: power_w_min {power_w_min:.4e} W in every bin is {ratio:.4} of the limit of a window at {azimuth_deg:.3}° ({rule})")]
    EyeWindowAtFloor {
        /// Wavelength, nm.
        wavelength_nm: f64,
        /// `limits.power_w_min`, W.
        power_w_min: f64,
        /// The floor's ratio to the window's (tightened) limit.
        ratio: f64,
        /// The window's azimuth, degrees.
        azimuth_deg: f64,
        /// The rule of the window (its `Debug` name).
        rule: String,
    },
    /// Resolution mode: the fixed power is over the limit even at the uniform spin.
    #[error("eye safety: the power ({power_w:.4e} W in every bin; resolution mode does not move it) is {} % of the Class 1 limit at {at_deg:.3}° even at the uniform spin", over_pct(*.ratio))]
    EyeAtUniformSpin {
        /// The power, W.
        power_w: f64,
        /// The bound's ratio to the limit.
        ratio: f64,
        /// Where it binds, degrees.
        at_deg: f64,
    },
    /// Resolution mode with spin set-points: the set-point answer is over
    /// the limit, a move shortened for eye safety would leave the
    /// set-points, and the swaps of bins' set-points found no arrangement
    /// under it (not a proof that none exists).
    #[error("eye safety: the spin set-points' answer (levels.spin_rad_s; resolution mode does not move the power) is {:.4} % of the Class 1 limit at {at_deg:.3}°; a shorter move would leave the set-points, and no rearrangement of them over the bins (each set-point's count kept, so the frame period) was found under the limit", 100.0 * .ratio)]
    EyeAtSetPoints {
        /// The bound's ratio to the limit.
        ratio: f64,
        /// Where it binds, degrees.
        at_deg: f64,
    },
    /// The eye-safety bound refused the bins (its own error).
    #[error("eye safety: {0}")]
    EyeSafety(String),
    /// No hardware power level fits a bin's power range.
    #[error("no power level lies within [power_w_min, min(power_w_max, the bin's eye-safety cut)] = [{power_w_min:.4e}, {hi_w:.4e}] W in bin {bin}")]
    NoLevelFits {
        /// `limits.power_w_min`, W.
        power_w_min: f64,
        /// The bin's highest allowed power, W.
        hi_w: f64,
        /// The bin.
        bin: usize,
    },
    /// No spin set-point lies within the spin limits.
    #[error("no spin set-point lies within [spin_rad_s_min, spin_rad_s_max]")]
    NoSetPointFits,
    /// The power step's cuts leave no powers.
    #[error("the power step has no solution within the limits: {cuts} eye-safety cuts (concrete exposures at the Class 1 limit) leave no powers within power_w_min/max, the budget and the slew limit")]
    CutsLeaveNoPower {
        /// Cuts in the program.
        cuts: usize,
    },
    /// HiGHS proved a step's program infeasible.
    #[error("the {step} step has no solution within the limits (power_w_min/max, the budget, spin limits, slew, acceleration and eye safety together)")]
    Step {
        /// `power`, `dwell` or `global`.
        step: String,
    },
    /// A MILP's search found no point within its node limit.
    #[error("the {step} step found no point meeting every limit within {nodes} branch-and-bound nodes (hardware levels or spin set-points that cannot meet the budget or the frame period exactly, with the other limits)")]
    NoIncumbent {
        /// `power` or `dwell`.
        step: String,
        /// The node limit.
        nodes: i32,
    },
    /// The global relaxation's power or spin box is empty.
    #[error("empty power or spin box")]
    EmptyBox,
}

fn frame_unreachable(
    limit: SpinLimit,
    spin_rad_s: f64,
    mean_spin_rad_s: f64,
    frame_rate_hz: f64,
) -> String {
    match limit {
        SpinLimit::Max => format!(
            "spin_rad_s_max {spin_rad_s:.3} rad/s cannot meet the frame period: one turn in 1/frame_rate_hz = {:.4} s needs a mean spin of {mean_spin_rad_s:.3} rad/s",
            1.0 / frame_rate_hz
        ),
        SpinLimit::Min => format!(
            "spin_rad_s_min {spin_rad_s:.3} rad/s is above the mean spin {mean_spin_rad_s:.3} rad/s that frame_rate_hz {frame_rate_hz} requires"
        ),
        SpinLimit::SetPoints {
            bins,
            count,
            below_s,
            above_s,
        } => {
            // The offset too: a period 10⁻⁸ off prints as the frame's at 9 digits.
            let side = |v: Option<f64>| {
                v.map_or_else(
                    || "none".to_owned(),
                    |t| format!("{t:.9} s ({:+.3e} relative)", t * frame_rate_hz - 1.0),
                )
            };
            format!(
                "levels.spin_rad_s: no choice of the {count} spin set-points on {bins} equal bins makes one turn take the frame period 1/frame_rate_hz = {:.9} s (mean spin {mean_spin_rad_s:.3} rad/s); the nearest periods they reach are {} below and {} above; change the set-points, bins or frame_rate_hz",
                1.0 / frame_rate_hz,
                side(below_s),
                side(above_s),
            )
        }
    }
}

/// A ratio to a limit as a percentage, one decimal, or as many more as
/// it takes for a ratio over the limit not to read as `100.0` (at most 12).
fn over_pct(ratio: f64) -> String {
    let pct = 100.0 * ratio;
    for d in 1..12 {
        let s = format!("{pct:.d$}");
        if ratio <= 1.0 || s.parse::<f64>().is_ok_and(|v| v > 100.0) {
            return s;
        }
    }
    format!("{pct:.12}")
}

/// Why a program's answer carries no exact certificate.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CertificateError {
    /// The exact check found the primal point outside the program.
    #[error("solver: the primal point is not exactly feasible: {0}")]
    NotFeasible(String),
    /// The multipliers give no finite bound.
    #[error("solver: the row duals give no finite bound (an unbounded column)")]
    Unbounded,
    /// A profile power that is not a hardware level.
    #[error("a power is not one of the hardware levels (the eye-safety fit scaled it)")]
    NotALevel,
    /// The power step's point stayed over a row after every repair.
    #[error("the power step's answer could not be certified exactly")]
    PowerStep,
    /// The dwell step's point failed the exact check.
    #[error("the dwell step's answer could not be certified exactly: {0}")]
    DwellStep(Box<CertificateError>),
    /// HiGHS failed on the program linearised at a `resolution`-mode answer.
    #[error("the dwell program at the answer could not be solved: {0}")]
    AnswerProgram(String),
    /// Resolution mode whose profile is not a program's answer.
    #[error("this mode has no power step, and the profile's dwell is not the dwell step's answer (smoothed spin, or the move shortened for eye safety)")]
    NoProgram,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The messages the command line printed before the errors were typed.
    #[test]
    fn messages_are_the_command_lines() {
        let e = Infeasible::FrameUnreachable {
            limit: SpinLimit::Max,
            spin_rad_s: 10.0,
            mean_spin_rad_s: 62.83185307179586,
            frame_rate_hz: 10.0,
        };
        assert_eq!(
            e.to_string(),
            "spin_rad_s_max 10.000 rad/s cannot meet the frame period: one turn in 1/frame_rate_hz = 0.1000 s needs a mean spin of 62.832 rad/s"
        );
        let e = Infeasible::EyeFloorOverLimit {
            power_w_min: 1e-3,
            ratio: 1.5,
            at_deg: 2.0,
            wavelength_nm: 905.0,
        };
        assert_eq!(
            e.to_string(),
            "eye safety: power_w_min 1.0000e-3 W everywhere at the mean spin is 150.0 % of the Class 1 limit (worst at 2.000°) at 905 nm"
        );
        let e = Infeasible::FrameUnreachable {
            limit: SpinLimit::SetPoints {
                bins: 24,
                count: 4,
                below_s: Some(0.099_999),
                above_s: None,
            },
            spin_rad_s: 209.0,
            mean_spin_rad_s: 62.83185307179586,
            frame_rate_hz: 10.0,
        };
        assert_eq!(
            e.to_string(),
            "levels.spin_rad_s: no choice of the 4 spin set-points on 24 equal bins makes one turn take the frame period 1/frame_rate_hz = 0.100000000 s (mean spin 62.832 rad/s); the nearest periods they reach are 0.099999000 s (-1.000e-5 relative) below and none above; change the set-points, bins or frame_rate_hz"
        );
        assert_eq!(
            CertificateError::DwellStep(Box::new(CertificateError::Unbounded)).to_string(),
            "the dwell step's answer could not be certified exactly: solver: the row duals give no finite bound (an unbounded column)"
        );
    }
}
