//! Return models: does a pulse that hits a surface produce a point?
//!
//! - [`ReturnModel::Argus`]: the paper's own code (github fscari/ARGUS,
//!   `lidar2.py`) taken literally: CARLA's ray-cast intensity `e^(−0.004 d)`,
//!   a hard 100 m range, fog as a *constant* factor
//!   `e^(−(0.004 + 5.4·fog/100))`, points dropped below an intensity
//!   threshold (0.055 at code fog 50, 0.0041 at code fog 100, none at 0);
//!   range control multiplies intensity by the profile's `P(β)/P̄`
//!   (0.5 in the RoF, 1.1 outside, as the code's `adjust_intensity`).
//! - [`ReturnModel::Physical`]: extended Lambertian target,
//!   `A ∝ P·ρ·cos θ·e^(−2αR)/R²`, detection probability
//!   `P_D = ½·erfc((T − A)/(σ√2))`, calibrated so the baseline detects its
//!   reference reflectivity at its rated range in clear air with `P_D = ½`.
//!
//! Fog levels carry the paper's labels 0/25/50 %. [`FogLevel`] maps them to
//! the ARGUS code's 0/50/100 (its GUI takes 0/50/100 while the paper reports
//! 0/25/50; the mapping is undocumented, we take the proportional one) and to
//! a meteorological optical range (MOR) for the physical model and for the
//! driver: 20 km (clear), 200 m, 100 m, with `α = 2.996 / MOR` (2 % contrast
//! would give 3.912 / V, Koschmieder). Fog extinction is nearly
//! wavelength-independent for V < 0.5 km, so one α serves 905 nm.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The two return models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// The paper code's intensity model (reproduces the published setup).
    Argus,
    /// Range equation with fog extinction and SNR detection.
    Physical,
}

impl ModelKind {
    /// Lower-case name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Argus => "argus",
            Self::Physical => "physical",
        }
    }
}

/// The paper's fog levels.
pub const FOG_LEVELS_PCT: [u32; 3] = [0, 25, 50];

/// Unsupported fog level.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[error("fog level {0} % is not one of the paper's levels 0, 25, 50")]
pub struct BadFog(pub u32);

/// One fog level and what it means in each model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FogLevel {
    /// The paper's label, %.
    pub fog_pct: u32,
    /// The ARGUS code's `fog_density`.
    pub argus_code_fog: f64,
    /// Meteorological optical range, m.
    pub mor_m: f64,
}

impl FogLevel {
    /// The documented mapping (module docs).
    pub fn of(fog_pct: u32) -> Result<Self, BadFog> {
        let (argus_code_fog, mor_m) = match fog_pct {
            0 => (0.0, 20_000.0),
            25 => (50.0, 200.0),
            50 => (100.0, 100.0),
            other => return Err(BadFog(other)),
        };
        Ok(Self {
            fog_pct,
            argus_code_fog,
            mor_m,
        })
    }

    /// Extinction coefficient α = 2.996 / MOR, 1/m.
    #[must_use]
    pub fn extinction_per_m(&self) -> f64 {
        2.996 / self.mor_m
    }
}

/// CARLA's default `atmosphere_attenuation_rate`, 1/m.
pub const CARLA_ATTENUATION_PER_M: f64 = 0.004;
/// The ARGUS code's fog coefficient (`5.4 · fog / 100`).
pub const ARGUS_FOG_COEFF: f64 = 5.4;
/// CARLA LiDAR range in the paper, m.
pub const ARGUS_RANGE_M: f64 = 100.0;

/// Physical model constants.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhysicalParams {
    /// Detection threshold T in noise-σ units (false alarms on noise alone
    /// `½·erfc(5/√2) ≈ 3e-7` per pulse).
    pub threshold_sigma: f64,
    /// Rated range on the reference reflectivity, clear air, m.
    pub rated_range_m: f64,
    /// Reference reflectivity.
    pub reference_reflectivity: f64,
    /// Clear-air extinction used in the calibration, 1/m.
    pub clear_extinction_per_m: f64,
}

/// A return model for one fog level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReturnModel {
    /// See module docs.
    Argus {
        /// Constant fog factor `e^(−(0.004 + 5.4·fog/100))`.
        fog_factor: f64,
        /// Intensity threshold.
        threshold: f64,
    },
    /// See module docs.
    Physical {
        /// Constants.
        params: PhysicalParams,
        /// Extinction at this fog level, 1/m.
        extinction_per_m: f64,
    },
}

impl ReturnModel {
    /// The model `kind` at `fog`, for a LiDAR rated `rated_range_m` on `reference_reflectivity`.
    #[must_use]
    pub fn new(
        kind: ModelKind,
        fog: FogLevel,
        rated_range_m: f64,
        reference_reflectivity: f64,
    ) -> Self {
        match kind {
            ModelKind::Argus => {
                let code = fog.argus_code_fog;
                let threshold = if code >= 100.0 {
                    0.0041
                } else if code >= 50.0 {
                    0.055
                } else {
                    0.0
                };
                Self::Argus {
                    fog_factor: (-(CARLA_ATTENUATION_PER_M + ARGUS_FOG_COEFF * code / 100.0)).exp(),
                    threshold,
                }
            }
            ModelKind::Physical => Self::Physical {
                params: PhysicalParams {
                    threshold_sigma: 5.0,
                    rated_range_m,
                    reference_reflectivity,
                    clear_extinction_per_m: FogLevel::of(0)
                        .map(|f| f.extinction_per_m())
                        .unwrap_or(0.0),
                },
                extinction_per_m: fog.extinction_per_m(),
            },
        }
    }

    /// Probability that a pulse with relative power `power_ratio = P/P̄`
    /// hitting a surface of `reflectivity` at `range_m` with incidence
    /// cosine `cos_incidence` yields a point (0 or 1 for `Argus`).
    #[must_use]
    pub fn detection_probability(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        cos_incidence: f64,
        range_m: f64,
    ) -> f64 {
        match *self {
            Self::Argus {
                fog_factor,
                threshold,
            } => {
                if range_m > ARGUS_RANGE_M {
                    return 0.0;
                }
                let intensity =
                    power_ratio * (-CARLA_ATTENUATION_PER_M * range_m).exp() * fog_factor;
                if intensity >= threshold {
                    1.0
                } else {
                    0.0
                }
            }
            Self::Physical { params, .. } => {
                let a = self.amplitude_sigma(power_ratio, reflectivity, cos_incidence, range_m);
                0.5 * libm::erfc((params.threshold_sigma - a) / std::f64::consts::SQRT_2)
            }
        }
    }

    /// Physical signal amplitude in noise-σ units (0 for `Argus`).
    #[must_use]
    pub fn amplitude_sigma(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        cos_incidence: f64,
        range_m: f64,
    ) -> f64 {
        match *self {
            Self::Argus { .. } => 0.0,
            Self::Physical {
                params,
                extinction_per_m,
            } => {
                let r0 = params.rated_range_m;
                let geometric = (r0 / range_m).powi(2);
                let extinction = (-2.0 * extinction_per_m * range_m
                    + 2.0 * params.clear_extinction_per_m * r0)
                    .exp();
                params.threshold_sigma
                    * power_ratio
                    * (reflectivity / params.reference_reflectivity)
                    * cos_incidence
                    * geometric
                    * extinction
            }
        }
    }

    /// Largest range at which a normal-incidence target of `reflectivity`
    /// reaches `P_D ≥ ½` (argus: the intensity threshold), m; by bisection.
    #[must_use]
    pub fn max_range_m(&self, power_ratio: f64, reflectivity: f64) -> f64 {
        let ok = |r: f64| self.detection_probability(power_ratio, reflectivity, 1.0, r) >= 0.5;
        let (mut lo, mut hi) = (0.01, 10_000.0);
        if !ok(lo) {
            return 0.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if ok(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn model(kind: ModelKind, fog: u32) -> ReturnModel {
        ReturnModel::new(kind, FogLevel::of(fog).unwrap(), 100.0, 0.1)
    }

    #[test]
    fn argus_ranges_match_the_design_brief() {
        // ≈ 100 m, 50 m, 24 m baseline; ≈ 74 m / 48 m with 1.1× power.
        for (fog, power, range, tol) in [
            (0, 1.0, 100.0, 1e-4),
            (25, 1.0, 49.0, 1.5),
            (50, 1.0, 23.5, 1.5),
            (25, 1.1, 73.0, 1.5),
            (50, 1.1, 47.0, 1.5),
        ] {
            let r = model(ModelKind::Argus, fog).max_range_m(power, 0.1);
            assert!(
                (r - range).abs() <= tol,
                "fog {fog} %, power {power}: {r} m"
            );
        }
    }

    #[test]
    fn physical_calibration_and_fog() {
        let clear = model(ModelKind::Physical, 0);
        assert_relative_eq!(clear.max_range_m(1.0, 0.1), 100.0, max_relative = 1e-6);
        // 1.2 P̄ (the eq. 4 maximum for a 60° RoF) buys < 10 % range in clear air.
        let r12 = clear.max_range_m(1.2, 0.1);
        assert!(r12 > 100.0 && r12 < 109.6, "{r12}");
        let fog = model(ModelKind::Physical, 50);
        let r_base = fog.max_range_m(1.0, 0.1);
        let r_range = fog.max_range_m(1.1, 0.1);
        assert!(
            r_base < 40.0 && r_range > r_base && r_range - r_base < 2.0,
            "{r_base} {r_range}"
        );
        assert!(FogLevel::of(10).is_err());
    }
}
