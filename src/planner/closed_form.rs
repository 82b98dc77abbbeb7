//! The paper's closed-form controllers (section III, eq. 3–6).
//!
//! - **Range** (eq. 3–4): `P = P_low` on the RoF, `P_high` on the RoI, with
//!   the average power equal to `P̄` under the preset's accounting.
//! - **Resolution** (eq. 5–6): `ω = ω_high` on the RoF, `ω_low` on the RoI,
//!   with `Δ_RoF/ω_high + Δ_RoI/ω_low = 2π/ω̄` (same frame period).
//! - **Joint**: both; under `time` accounting `P_high` is solved with the
//!   dwell times of the resolution profile (energy per frame = `P̄ · T`).
//!
//! The bin grid is `bins` equal bins with the region boundaries inserted as
//! extra edges, so the RoF is exact (e.g. exactly ±30° about the gaze, also
//! when it wraps through 0°).

use super::{validate_gaze, Mode, PlanError};
use crate::checker::{certify, CertifiedProfile};
use crate::model::acuity::Regions;
use crate::model::angle::{Binning, FULL_TURN_DEG};
use crate::model::lidar::PowerAccounting;
use crate::model::presets::Preset;
use crate::profile::{Bin, Profile, Region, PROFILE_FORMAT};

/// The levels a closed-form controller chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Levels {
    /// Power in the RoF and the RoI, W.
    pub power_w: [f64; 2],
    /// Spin in the RoF and the RoI, rad/s.
    pub spin_rad_s: [f64; 2],
}

/// Solves eq. 4 and eq. 6 for the region widths `rof_deg`, `roi_deg`.
pub fn levels(
    preset: &Preset,
    mode: Mode,
    rof_deg: f64,
    roi_deg: f64,
) -> Result<Levels, PlanError> {
    let lidar = &preset.lidar;
    let p_mean = lidar.average_power_w;
    let w_mean = lidar.mean_spin_rad_s();
    let k = preset.levels.spin_ratio;
    let frac = preset.levels.rof_power_fraction;
    if !(k.is_finite() && k >= 1.0) {
        return Err(PlanError::InvalidInput {
            field: "levels.spin_ratio",
            reason: format!("{k} must be finite and >= 1"),
        });
    }
    if !(frac.is_finite() && frac >= 0.0) {
        return Err(PlanError::InvalidInput {
            field: "levels.rof_power_fraction",
            reason: format!("{frac} must be finite and >= 0"),
        });
    }
    let adaptive = rof_deg > 0.0;
    // Eq. 6: Δ_RoF/(k ω_low) + Δ_RoI/ω_low = 360°/ω̄.
    let spin_rad_s = if mode.controls_resolution() && adaptive {
        let w_low = w_mean * (rof_deg / k + roi_deg) / FULL_TURN_DEG;
        [k * w_low, w_low]
    } else {
        [w_mean, w_mean]
    };
    let power_w = if mode.controls_range() && adaptive {
        if roi_deg <= 0.0 {
            return Err(PlanError::Infeasible(
                "the driver's region of focus covers the full circle: there is no region of interest to move power to".into(),
            ));
        }
        let p_low = frac * p_mean;
        // Weights of each region in the average: angle (eq. 4) or time.
        let (w_rof, w_roi) = match lidar.power_accounting {
            PowerAccounting::Angle => (rof_deg, roi_deg),
            PowerAccounting::Time => (rof_deg / spin_rad_s[0], roi_deg / spin_rad_s[1]),
        };
        let p_high = (p_mean * (w_rof + w_roi) - p_low * w_rof) / w_roi;
        [p_low, p_high]
    } else {
        [p_mean, p_mean]
    };
    Ok(Levels {
        power_w,
        spin_rad_s,
    })
}

/// Builds the (uncertified) closed-form profile.
pub fn build_profile(
    preset: &Preset,
    mode: Mode,
    gaze_deg: Option<f64>,
    bins: usize,
) -> Result<Profile, PlanError> {
    preset.focus.validate()?;
    let lidar = &preset.lidar;
    let regions = match gaze_deg {
        Some(g) => {
            validate_gaze(g)?;
            Some(preset.focus.regions(g))
        }
        None => None,
    };
    let breaks = regions
        .as_ref()
        .map(|r: &Regions| r.rof.boundaries_deg())
        .unwrap_or_default();
    let grid = Binning::uniform_with_breaks(bins, &breaks)?;
    let in_rof: Vec<bool> = (0..grid.len())
        .map(|i| {
            regions
                .as_ref()
                .is_some_and(|r| r.rof.contains(grid.center_deg(i)))
        })
        .collect();
    let rof_deg: f64 = (0..grid.len())
        .filter(|&i| in_rof[i])
        .map(|i| grid.width_deg(i))
        .sum();
    let roi_deg: f64 = (0..grid.len())
        .filter(|&i| !in_rof[i])
        .map(|i| grid.width_deg(i))
        .sum();
    let lv = levels(preset, mode, rof_deg, roi_deg)?;
    let bins = (0..grid.len())
        .map(|i| {
            let r = usize::from(!in_rof[i]);
            let spin = lv.spin_rad_s[r];
            Bin {
                start_deg: grid.start_deg(i),
                width_deg: grid.width_deg(i),
                power_w: lv.power_w[r],
                spin_start_rad_s: spin,
                spin_end_rad_s: spin,
                region: regions
                    .as_ref()
                    .map(|_| if in_rof[i] { Region::Rof } else { Region::Roi }),
                dwell_s: Some(grid.width_deg(i).to_radians() / spin),
            }
        })
        .collect();
    Ok(Profile {
        format: PROFILE_FORMAT.to_owned(),
        frame_rate_hz: lidar.frame_rate_hz,
        pulse_rate_hz: lidar.pulse_rate_hz,
        average_power_w: lidar.average_power_w,
        power_accounting: lidar.power_accounting,
        gaze_deg: gaze_deg.map(crate::model::angle::wrap_deg),
        limits: lidar.limits.clone(),
        bins,
        mode: Some(format!("closed-form {}", mode.name())),
        summary: None,
        optimality: None,
    })
}

/// The paper's controller `mode` for `gaze_deg` (`None`: the uniform
/// baseline) on `bins` bins, certified.
pub fn closed_form(
    preset: &Preset,
    mode: Mode,
    gaze_deg: Option<f64>,
    bins: usize,
) -> Result<CertifiedProfile, PlanError> {
    let profile = build_profile(preset, mode, gaze_deg, bins)?;
    Ok(certify(profile)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::{paper, vls128};
    use approx::assert_relative_eq;

    #[test]
    fn paper_levels() {
        let p = paper();
        let lv = levels(&p, Mode::Range, 60.0, 300.0).unwrap();
        assert_relative_eq!(lv.power_w[0], 0.5e-3);
        assert_relative_eq!(lv.power_w[1], 1.1e-3, max_relative = 1e-12);
        let lv = levels(&p, Mode::Resolution, 60.0, 300.0).unwrap();
        assert_relative_eq!(
            lv.spin_rad_s[0] / lv.spin_rad_s[1],
            5.4,
            max_relative = 1e-12
        );
        let period = 60f64.to_radians() / lv.spin_rad_s[0] + 300f64.to_radians() / lv.spin_rad_s[1];
        assert_relative_eq!(period, 0.05, max_relative = 1e-12);
    }

    #[test]
    fn time_accounting_joint_keeps_energy() {
        let mut p = paper();
        p.lidar.power_accounting = PowerAccounting::Time;
        let c = closed_form(&p, Mode::Joint, Some(90.0), 360).unwrap();
        let s = c.summary();
        assert_relative_eq!(s.average_power_time_w, 1e-3, max_relative = 1e-9);
        assert!(s.average_power_angle_w < 1e-3 * 1.03);
    }

    #[test]
    fn vls_resolution_step_is_rejected_by_motor_limit() {
        let e = closed_form(&vls128(), Mode::Resolution, Some(90.0), 360).unwrap_err();
        assert!(e.to_string().contains("spin_accel_rad_s2_max"), "{e}");
        closed_form(&vls128(), Mode::Range, Some(90.0), 360).unwrap();
    }

    #[test]
    fn full_circle_focus_is_infeasible_for_range() {
        let mut p = paper();
        p.focus.acuity = crate::model::acuity::AcuityModel::Box {
            half_width_deg: 180.0,
        };
        assert!(matches!(
            closed_form(&p, Mode::Range, Some(0.0), 360),
            Err(PlanError::Infeasible(_))
        ));
    }
}
