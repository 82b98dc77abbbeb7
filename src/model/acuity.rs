//! Visual-acuity models `V(e)` of eccentricity and the driver's region of focus.
//!
//! The paper (eq. 1) defines the driver's region of focus as
//! `RoF = {β : V(β − θ_g) > η}` and the LiDAR's region of interest as its
//! complement (eq. 2). [`FocusModel::regions`] computes both as exact
//! circular sets (see [`crate::model::angle`]).

use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::angle::{wrap_signed_deg, Arc, CircularSet, FULL_TURN_DEG};

/// Largest |gaze| accepted, degrees (anything beyond is surely a unit bug).
pub const MAX_ABS_GAZE_DEG: f64 = 3600.0;

/// Levi's E2 for letter acuity (Song, Levi & Pelli 2014), degrees.
pub const LEVI_E2_DEG: f64 = 2.72;

/// Smallest `e2_deg` / `sigma_deg` accepted, degrees: far below a bin
/// (at least 0.25°), and large enough that `σ²` and every weight computed
/// from the model stay normal doubles (a `σ²` that underflows makes
/// `V(0) = exp(−0/0)` NaN).
pub const MIN_ACUITY_WIDTH_DEG: f64 = 1e-9;

/// Errors in an acuity model or focus threshold.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AcuityError {
    /// A parameter is out of its domain.
    #[error("acuity {field} = {}: {reason}", crate::text::Num(*.value))]
    BadParameter {
        /// Parameter name as in the config.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A tabulated model is unusable.
    #[error("tabulated acuity: {0}")]
    BadTable(String),
}

/// One sample of a tabulated acuity function.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AcuitySample {
    /// Signed eccentricity in degrees, in `[-180, 180]`.
    pub eccentricity_deg: f64,
    /// Acuity at that eccentricity (non-negative, any scale).
    pub acuity: f64,
}

/// A visual-acuity function of (signed) eccentricity `e` in degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum AcuityModel {
    /// The paper's box: `V = 1` for `|e| <= half_width_deg`, else 0.
    Box {
        /// Half width of the box (paper: 30°, a 60° region of focus).
        half_width_deg: f64,
    },
    /// Levi's hyperbolic model `V = E2 / (|e| + E2)`.
    LeviE2 {
        /// Eccentricity at which acuity halves (2.72° letter acuity; Geisler & Perry use 2.3°).
        e2_deg: f64,
    },
    /// Gaussian fall-off `V = exp(−e² / 2σ²)`.
    Gaussian {
        /// Standard deviation in degrees.
        sigma_deg: f64,
    },
    /// User samples, linearly interpolated, constant beyond the ends. If every
    /// eccentricity is `>= 0` the table is mirrored (a symmetric field of view).
    Tabulated {
        /// Samples sorted by strictly increasing eccentricity.
        samples: Vec<AcuitySample>,
    },
}

impl AcuityModel {
    /// The paper's 60° box.
    #[must_use]
    pub fn paper_box() -> Self {
        Self::Box {
            half_width_deg: 30.0,
        }
    }

    /// Checks every parameter.
    pub fn validate(&self) -> Result<(), AcuityError> {
        let positive = |field, value: f64| {
            if value.is_finite() && (MIN_ACUITY_WIDTH_DEG..=FULL_TURN_DEG).contains(&value) {
                Ok(())
            } else {
                Err(AcuityError::BadParameter {
                    field,
                    value,
                    reason: "must be finite and in [1e-9, 360]",
                })
            }
        };
        match self {
            Self::Box { half_width_deg } => {
                if half_width_deg.is_finite() && (0.0..=180.0).contains(half_width_deg) {
                    Ok(())
                } else {
                    Err(AcuityError::BadParameter {
                        field: "half_width_deg",
                        value: *half_width_deg,
                        reason: "must lie in [0, 180]",
                    })
                }
            }
            Self::LeviE2 { e2_deg } => positive("e2_deg", *e2_deg),
            Self::Gaussian { sigma_deg } => positive("sigma_deg", *sigma_deg),
            Self::Tabulated { samples } => {
                if samples.len() < 2 {
                    return Err(AcuityError::BadTable("needs at least 2 samples".into()));
                }
                for (k, s) in samples.iter().enumerate() {
                    if !(s.eccentricity_deg.is_finite()
                        && (-180.0..=180.0).contains(&s.eccentricity_deg))
                    {
                        return Err(AcuityError::BadTable(format!(
                            "sample {k}: eccentricity_deg {} is not in [-180, 180]",
                            s.eccentricity_deg
                        )));
                    }
                    if !(s.acuity.is_finite() && s.acuity >= 0.0) {
                        return Err(AcuityError::BadTable(format!(
                            "sample {k}: acuity {} is not finite and >= 0",
                            s.acuity
                        )));
                    }
                }
                if samples
                    .windows(2)
                    .any(|w| w[1].eccentricity_deg <= w[0].eccentricity_deg)
                {
                    return Err(AcuityError::BadTable(
                        "eccentricity_deg must increase strictly".into(),
                    ));
                }
                if self.value(0.0) <= 0.0 {
                    return Err(AcuityError::BadTable("acuity at 0° must be > 0".into()));
                }
                Ok(())
            }
        }
    }

    /// Samples over `[-180, 180]` as a piecewise-linear function (tabulated only).
    fn table_points(samples: &[AcuitySample]) -> Vec<(f64, f64)> {
        let symmetric = samples.iter().all(|s| s.eccentricity_deg >= 0.0);
        let mut pts: Vec<(f64, f64)> = Vec::with_capacity(2 * samples.len() + 2);
        if symmetric {
            pts.extend(
                samples
                    .iter()
                    .rev()
                    .filter(|s| s.eccentricity_deg > 0.0)
                    .map(|s| (-s.eccentricity_deg, s.acuity)),
            );
        }
        pts.extend(samples.iter().map(|s| (s.eccentricity_deg, s.acuity)));
        if let Some(&(e, v)) = pts.first() {
            if e > -180.0 {
                pts.insert(0, (-180.0, v));
            }
        }
        if let Some(&(e, v)) = pts.last() {
            if e < 180.0 {
                pts.push((180.0, v));
            }
        }
        pts
    }

    /// Acuity at eccentricity `e` (any real; wrapped into `(-180, 180]`).
    #[must_use]
    pub fn value(&self, eccentricity_deg: f64) -> f64 {
        let e = wrap_signed_deg(eccentricity_deg);
        match self {
            Self::Box { half_width_deg } => {
                if e.abs() <= *half_width_deg {
                    1.0
                } else {
                    0.0
                }
            }
            Self::LeviE2 { e2_deg } => e2_deg / (e.abs() + e2_deg),
            Self::Gaussian { sigma_deg } => (-(e * e) / (2.0 * sigma_deg * sigma_deg)).exp(),
            Self::Tabulated { samples } => {
                let pts = Self::table_points(samples);
                let k = pts.partition_point(|p| p.0 <= e).clamp(1, pts.len() - 1);
                let (e0, v0) = pts[k - 1];
                let (e1, v1) = pts[k];
                if e1 == e0 {
                    v0
                } else {
                    v0 + (v1 - v0) * (e - e0) / (e1 - e0)
                }
            }
        }
    }

    /// Peak acuity `V(0)`.
    #[must_use]
    pub fn peak(&self) -> f64 {
        self.value(0.0)
    }

    /// Driver's deficit at eccentricity `e`: `1 − V(e)/V(0)`, in `[0, 1]` for
    /// models peaking at 0 (used as an optimizer weight).
    #[must_use]
    pub fn deficit(&self, eccentricity_deg: f64) -> f64 {
        let peak = self.peak();
        if peak <= 0.0 {
            return 1.0;
        }
        (1.0 - self.value(eccentricity_deg) / peak).clamp(0.0, 1.0)
    }

    /// Eccentricity ranges `(lo, hi)` within `[-180, 180]` where `V(e) > η`.
    fn focus_eccentricities(&self, threshold: f64) -> Vec<(f64, f64)> {
        let symmetric = |half: f64| -> Vec<(f64, f64)> {
            if half <= 0.0 {
                vec![]
            } else {
                let h = half.min(180.0);
                vec![(-h, h)]
            }
        };
        match self {
            Self::Box { half_width_deg } => {
                if (0.0..1.0).contains(&threshold) {
                    symmetric(*half_width_deg)
                } else if threshold < 0.0 {
                    symmetric(180.0)
                } else {
                    vec![]
                }
            }
            Self::LeviE2 { e2_deg } => {
                if threshold <= 0.0 {
                    symmetric(180.0)
                } else {
                    symmetric(e2_deg * (1.0 / threshold - 1.0))
                }
            }
            Self::Gaussian { sigma_deg } => {
                if threshold <= 0.0 {
                    symmetric(180.0)
                } else if threshold >= 1.0 {
                    vec![]
                } else {
                    symmetric(sigma_deg * (-2.0 * threshold.ln()).sqrt())
                }
            }
            Self::Tabulated { samples } => {
                let pts = Self::table_points(samples);
                let mut out = Vec::new();
                for w in pts.windows(2) {
                    let ((e0, v0), (e1, v1)) = (w[0], w[1]);
                    let above0 = v0 > threshold;
                    let above1 = v1 > threshold;
                    let cross = || e0 + (threshold - v0) / (v1 - v0) * (e1 - e0);
                    let piece = match (above0, above1) {
                        (true, true) => Some((e0, e1)),
                        (true, false) => Some((e0, cross())),
                        (false, true) => Some((cross(), e1)),
                        (false, false) => None,
                    };
                    if let Some(p) = piece {
                        out.push(p);
                    }
                }
                out
            }
        }
    }
}

/// An acuity model with the threshold η that defines the region of focus.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FocusModel {
    /// The acuity function.
    pub acuity: AcuityModel,
    /// Threshold η of eq. 1 (same scale as the acuity values).
    pub threshold: f64,
}

/// The driver's region of focus and the LiDAR's region of interest for one gaze.
#[derive(Debug, Clone, PartialEq)]
pub struct Regions {
    /// Gaze azimuth θ_g in degrees.
    pub gaze_deg: f64,
    /// RoF (eq. 1).
    pub rof: CircularSet,
    /// RoI = complement of RoF (eq. 2).
    pub roi: CircularSet,
}

impl FocusModel {
    /// The paper's: 60° box with η = 0.5.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            acuity: AcuityModel::paper_box(),
            threshold: 0.5,
        }
    }

    /// Levi's E2 model with the threshold that gives a region of focus of
    /// `width_deg` (η = E2 / (width/2 + E2); 60° → η ≈ 0.083).
    #[must_use]
    pub fn levi_e2_with_width(width_deg: f64) -> Self {
        Self {
            acuity: AcuityModel::LeviE2 {
                e2_deg: LEVI_E2_DEG,
            },
            threshold: LEVI_E2_DEG / (width_deg / 2.0 + LEVI_E2_DEG),
        }
    }

    /// Checks the model and the threshold.
    pub fn validate(&self) -> Result<(), AcuityError> {
        self.acuity.validate()?;
        if !self.threshold.is_finite() {
            return Err(AcuityError::BadParameter {
                field: "threshold",
                value: self.threshold,
                reason: "must be finite",
            });
        }
        Ok(())
    }

    /// RoF and RoI for gaze `gaze_deg` (eq. 1 and 2), exactly.
    #[must_use]
    pub fn regions(&self, gaze_deg: f64) -> Regions {
        let arcs = self
            .acuity
            .focus_eccentricities(self.threshold)
            .into_iter()
            .filter(|(lo, hi)| hi > lo)
            .map(|(lo, hi)| Arc {
                start_deg: super::angle::wrap_deg(gaze_deg + lo),
                width_deg: (hi - lo).min(FULL_TURN_DEG),
            });
        let rof = CircularSet::from_arcs(arcs);
        let roi = rof.complement();
        Regions { gaze_deg, rof, roi }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn levi_values_match_design_table() {
        let m = AcuityModel::LeviE2 {
            e2_deg: LEVI_E2_DEG,
        };
        for (e, v) in [
            (0.0, 1.0),
            (5.0, 0.35),
            (10.0, 0.21),
            (30.0, 0.083),
            (60.0, 0.043),
        ] {
            assert!((m.value(e) - v).abs() < 0.006, "V({e}) = {}", m.value(e));
        }
    }

    #[test]
    fn paper_box_gives_60_deg() {
        let r = FocusModel::paper().regions(90.0);
        assert_eq!(r.rof.arcs(), vec![Arc::new(60.0, 60.0).unwrap()]);
        assert_eq!(r.roi.measure_deg(), 300.0);
    }

    #[test]
    fn levi_width_threshold_matches_box() {
        let r = FocusModel::levi_e2_with_width(60.0).regions(10.0);
        assert_relative_eq!(r.rof.measure_deg(), 60.0, epsilon = 1e-9);
        assert!(r.rof.contains(341.0) && r.rof.contains(39.0) && !r.rof.contains(41.0));
    }

    #[test]
    fn gaussian_threshold() {
        let f = FocusModel {
            acuity: AcuityModel::Gaussian { sigma_deg: 20.0 },
            threshold: (-0.5f64).exp(),
        };
        assert_relative_eq!(f.regions(0.0).rof.measure_deg(), 40.0, epsilon = 1e-9);
    }

    #[test]
    fn tabulated_asymmetric_and_mirrored() {
        let table = |pts: &[(f64, f64)]| AcuityModel::Tabulated {
            samples: pts
                .iter()
                .map(|&(e, a)| AcuitySample {
                    eccentricity_deg: e,
                    acuity: a,
                })
                .collect(),
        };
        let sym = table(&[(0.0, 1.0), (40.0, 0.0)]);
        sym.validate().unwrap();
        let f = FocusModel {
            acuity: sym,
            threshold: 0.5,
        };
        let r = f.regions(0.0);
        assert_relative_eq!(r.rof.measure_deg(), 40.0, epsilon = 1e-12);
        let asym = table(&[(-20.0, 0.0), (0.0, 1.0), (60.0, 0.0)]);
        asym.validate().unwrap();
        let f = FocusModel {
            acuity: asym,
            threshold: 0.5,
        };
        let r = f.regions(100.0);
        assert_eq!(r.rof.arcs(), vec![Arc::new(90.0, 40.0).unwrap()]);
        assert!(table(&[(0.0, 1.0)]).validate().is_err());
        assert!(table(&[(0.0, 1.0), (0.0, 0.5)]).validate().is_err());
    }

    #[test]
    fn deficit_is_zero_at_gaze() {
        let m = AcuityModel::LeviE2 { e2_deg: 2.3 };
        assert_eq!(m.deficit(0.0), 0.0);
        assert!(m.deficit(90.0) > 0.9);
    }
}
