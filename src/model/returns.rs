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
//!   `A ∝ P·ρ·cos θ·e^(−2αR)/R²` (the range equation of
//!   [`crate::model::range`], the one model of it), detection probability
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

use serde::Serialize;
use thiserror::Error;

use crate::model::range::{self, RangeEquation};

/// The two return models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// The paper code's intensity model (reproduces the published setup).
    Argus,
    /// Range equation with fog extinction and SNR detection.
    Physical,
}

crate::names::named_enum!(ModelKind {
    Argus => "argus", "The paper code's intensity model (reproduces the published setup)";
    Physical => "physical", "Range equation with fog extinction and SNR detection";
});

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
            0 => (0.0, range::CLEAR_AIR_MOR_M),
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
        range::extinction_per_m(self.mor_m)
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

impl PhysicalParams {
    /// The range equation these constants calibrate.
    #[must_use]
    pub fn equation(&self) -> RangeEquation {
        RangeEquation {
            rated_range_m: self.rated_range_m,
            reference_reflectivity: self.reference_reflectivity,
            clear_extinction_per_m: self.clear_extinction_per_m,
        }
    }
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
        self.detection_probability_with(power_ratio, reflectivity, cos_incidence, range_m, || {
            self.range_factor(range_m)
        })
    }

    /// [`Self::detection_probability`] with the range factor supplied
    /// (`factor()` returns `range_factor(range_m)`, e.g. shared by cells;
    /// not called beyond the `argus` model's 100 m).
    #[must_use]
    pub fn detection_probability_with(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        cos_incidence: f64,
        range_m: f64,
        factor: impl FnOnce() -> f64,
    ) -> f64 {
        if let Self::Argus { .. } = self {
            if range_m > ARGUS_RANGE_M {
                return 0.0;
            }
        }
        self.detection_probability_from(power_ratio, reflectivity, cos_incidence, range_m, factor())
    }

    /// The factor of [`Self::detection_probability`] that depends on the
    /// range alone: `argus` CARLA's `e^(−0.004·r)` (the same in every fog),
    /// `physical` the extinction `e^(−2αR + 2α₀R₀)` (the same for every
    /// power): cells that share [`Self::range_factor_key`] share it.
    #[must_use]
    pub fn range_factor(&self, range_m: f64) -> f64 {
        match *self {
            Self::Argus { .. } => (-CARLA_ATTENUATION_PER_M * range_m).exp(),
            Self::Physical {
                params,
                extinction_per_m,
            } => params
                .equation()
                .extinction_factor(extinction_per_m, range_m),
        }
    }

    /// Models with equal keys have the same [`Self::range_factor`].
    #[must_use]
    pub fn range_factor_key(&self) -> [u64; 4] {
        match *self {
            Self::Argus { .. } => [0; 4],
            Self::Physical {
                params,
                extinction_per_m,
            } => [
                1,
                extinction_per_m.to_bits(),
                params.clear_extinction_per_m.to_bits(),
                params.rated_range_m.to_bits(),
            ],
        }
    }

    /// [`Self::detection_probability`] given `factor = range_factor(range_m)`
    /// and, for `argus`, `range_m` within its 100 m.
    /// `P_D = ½·erfc(x)` is exactly 1 for `x ≤ −6` (libm's `erfc` is within
    /// half an ulp of 2 there; tested in `sim::carla`), so `erfc` is skipped.
    #[must_use]
    fn detection_probability_from(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        cos_incidence: f64,
        range_m: f64,
        factor: f64,
    ) -> f64 {
        match *self {
            Self::Argus {
                fog_factor,
                threshold,
            } => {
                let intensity = power_ratio * factor * fog_factor;
                if intensity >= threshold {
                    1.0
                } else {
                    0.0
                }
            }
            Self::Physical { params, .. } => {
                let a = self.amplitude_sigma_from(
                    power_ratio,
                    reflectivity,
                    cos_incidence,
                    range_m,
                    factor,
                );
                let x = (params.threshold_sigma - a) / std::f64::consts::SQRT_2;
                if x <= -6.0 {
                    1.0
                } else {
                    0.5 * libm::erfc(x)
                }
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
        self.amplitude_sigma_from(
            power_ratio,
            reflectivity,
            cos_incidence,
            range_m,
            self.range_factor(range_m),
        )
    }

    /// [`Self::amplitude_sigma`] given `extinction = range_factor(range_m)`.
    fn amplitude_sigma_from(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        cos_incidence: f64,
        range_m: f64,
        extinction: f64,
    ) -> f64 {
        match *self {
            Self::Argus { .. } => 0.0,
            Self::Physical { params, .. } => params.equation().signal(
                params.threshold_sigma,
                power_ratio,
                reflectivity,
                cos_incidence,
                range_m,
                extinction,
            ),
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

impl ReturnModel {
    /// Expected returns per frame from a normal-incidence target `width_m`
    /// wide at `range_m`, scanned with an angular spacing of `spacing_rad`
    /// between pulses: `W/(R·Δφ)` pulses meet it (the expectation over the
    /// scan's phase), each a point with [`Self::detection_probability`].
    #[must_use]
    pub fn expected_returns(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        width_m: f64,
        spacing_rad: f64,
        range_m: f64,
    ) -> f64 {
        let pulses = width_m / (range_m * spacing_rad);
        pulses * self.detection_probability(power_ratio, reflectivity, 1.0, range_m)
    }

    /// Detection range: the largest range at which a normal-incidence target
    /// `width_m` wide of `reflectivity`, scanned at `spacing_rad`, gives at
    /// least `detect` expected returns per frame ([`Self::expected_returns`]),
    /// m; 0 when even 1 cm is short. Both factors fall with the range (the
    /// pulses across the target as `1/R`; `P_D` as the amplitude, or the
    /// `argus` intensity, falls), so the set of ranges that detect is an
    /// interval from 0 and bisection finds its end, to a relative 1e-12.
    /// The bracket is `[0.01, R_max]` m, `R_max` the least of 10⁴ m, the
    /// range where even `P_D = 1` leaves fewer than `detect` pulses on the
    /// target (`W/(Δφ·detect)`), and `argus`'s 100 m: beyond each, no range
    /// detects.
    ///
    /// The bisection's midpoints are decided without evaluating the model
    /// where [`narrow`] has shown the end lies elsewhere: it brackets the
    /// end first by a few regula falsi steps (evaluated, so the answer is
    /// the plain bisection's, bit for bit; tested against it), and only the
    /// bisection's midpoints within a relative 1e-12 of the end (one or
    /// two) cost an evaluation.
    #[must_use]
    pub fn detection_range_m(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        width_m: f64,
        spacing_rad: f64,
        detect: f64,
    ) -> f64 {
        self.detection_range_near_m(
            power_ratio,
            reflectivity,
            width_m,
            spacing_rad,
            detect,
            Guess::NONE,
        )
    }

    /// [`Self::detection_range_m`], bit for bit, with [`narrow`]'s bracket
    /// walked out from `guess` (e.g. the detection ranges at neighbouring
    /// powers, extrapolated) instead of started from the whole `[0.01,
    /// R_max]`: the guess decides only where the evaluations fall, never
    /// the answer (a wrong guess costs evaluations). Under `argus` a guess
    /// of its own is used when none is given: the range where the
    /// intensity meets the threshold, `ln(x·fog_factor/threshold)/0.004`
    /// (the end of the detecting ranges whenever the pulses' cap is not
    /// reached first).
    #[must_use]
    pub fn detection_range_near_m(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        width_m: f64,
        spacing_rad: f64,
        detect: f64,
        guess: Guess,
    ) -> f64 {
        let returns =
            |r: f64| self.expected_returns(power_ratio, reflectivity, width_m, spacing_rad, r);
        let mut hi = (width_m / (spacing_rad * detect)).min(10_000.0);
        if let Self::Argus { .. } = self {
            hi = hi.min(ARGUS_RANGE_M);
        }
        let mut lo = 0.01;
        if hi.is_nan() || hi <= lo {
            return 0.0;
        }
        let guess = match *self {
            Self::Argus {
                fog_factor,
                threshold,
            } if !guess.range_m.is_finite() && threshold > 0.0 => Guess {
                range_m: (power_ratio * fog_factor / threshold).ln() / CARLA_ATTENUATION_PER_M,
                rel_err: 1e-13,
            },
            _ => guess,
        };
        let (yes, no) = step_out(&returns, detect, (lo, hi), guess);
        // The bracket's ends are evaluated only where the guess found no
        // range strictly inside them on that side (`END_GAP`): a detecting
        // range `a > lo` means `lo` detects, a failing `b < hi` that `hi`
        // fails, and the answer is the plain bisection's either way.
        let a = match yes {
            Some(p) if p.0 >= lo * (1.0 + END_GAP) => p,
            _ => {
                let at_lo = returns(lo);
                if at_lo < detect || at_lo.is_nan() {
                    return 0.0;
                }
                yes.unwrap_or((lo, at_lo))
            }
        };
        let b = match no {
            Some(p) if p.0 <= hi * (1.0 - END_GAP) => p,
            _ => {
                let at_hi = returns(hi);
                if at_hi >= detect {
                    return hi;
                }
                no.unwrap_or((hi, at_hi))
            }
        };
        let (yes, no) = narrow(&returns, detect, (lo, hi), a, b);
        let ok = |r: f64| returns(r) >= detect;
        for _ in 0..100 {
            if hi - lo <= 1e-12 * hi {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if mid <= yes || (mid < no && ok(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

/// How far inside `[lo, hi]` (relative) a range found by [`step_out`] must
/// lie to decide that end without evaluating it: the returns fall at
/// least as `1/R` (the pulses across the target), so `10⁻⁹` apart they
/// differ by far more than the model's rounding (some `10⁻¹⁴`).
const END_GAP: f64 = 1e-9;

/// The ranges found by stepping out from `guess` inside `(lo, hi)`: the
/// highest that detects and the lowest that does not, each with its
/// returns (`None`: none found on that side). The step starts at the
/// guess's relative error and grows eightfold until the end of the
/// detecting ranges is crossed.
#[allow(clippy::type_complexity)]
fn step_out(
    returns: &impl Fn(f64) -> f64,
    detect: f64,
    (lo, hi): (f64, f64),
    guess: Guess,
) -> (Option<(f64, f64)>, Option<(f64, f64)>) {
    let (mut yes, mut no) = (None, None);
    let g = guess.range_m;
    if !(g > lo && g < hi) {
        return (yes, no);
    }
    let (mut a, mut b) = (lo, hi);
    let at_g = returns(g);
    let up = at_g >= detect;
    if up {
        a = g;
        yes = Some((g, at_g));
    } else {
        b = g;
        no = Some((g, at_g));
    }
    let mut step = guess.rel_err.max(1e-13);
    while step < 1.0 {
        let r = if up {
            g * (1.0 + step)
        } else {
            g * (1.0 - step)
        };
        if !(r > a && r < b) {
            break;
        }
        let at_r = returns(r);
        if at_r >= detect {
            a = r;
            yes = Some((r, at_r));
        } else {
            b = r;
            no = Some((r, at_r));
        }
        if (at_r >= detect) != up {
            break;
        }
        step *= 8.0;
    }
    (yes, no)
}

/// A bracket `(yes, no)` of the end of the detecting ranges inside
/// `[lo, hi]` (`returns(lo) ≥ detect > returns(hi)`, `returns` falling):
/// `returns(yes) ≥ detect > returns(no)`, each end a relative
/// [`NARROW_MARGIN`] away from the regula falsi bracket it widens, so that
/// every range at or below `yes` detects and none at or above `no` does —
/// in floating point as in real numbers, since the model's rounding moves
/// the end by some 1e-14 relative. Illinois steps on
/// `ln returns − ln detect` against `R` (a bisection step where either
/// side's value is not finite), each side decided by `returns ≥ detect` as
/// the caller decides it. Where the widened ends do not check, `(lo, hi)`:
/// the caller evaluates every midpoint.
///
/// The regula falsi starts from `(a, at_a)` (a detecting range, at or
/// above `lo`) and `(b, at_b)` (a failing one, at or below `hi`) with
/// their returns: `lo` and `hi`, or the ranges [`step_out`] found.
fn narrow(
    returns: &impl Fn(f64) -> f64,
    detect: f64,
    (lo, hi): (f64, f64),
    (mut a, at_a): (f64, f64),
    (mut b, at_b): (f64, f64),
) -> (f64, f64) {
    let ln_detect = detect.ln();
    let (mut ga, mut gb) = (
        (at_a.ln() - ln_detect).max(0.0),
        (at_b.ln() - ln_detect).min(0.0),
    );
    // −1: `a` moved last, +1: `b` did.
    let mut last = 0;
    for _ in 0..NARROW_STEPS {
        if b - a <= NARROW_MARGIN * b {
            break;
        }
        let secant = a + (b - a) * (ga / (ga - gb));
        let mut r = if ga.is_finite() && gb.is_finite() && ga > gb {
            secant
        } else {
            0.5 * (a + b)
        };
        if !(r > a && r < b) {
            r = 0.5 * (a + b);
            if !(r > a && r < b) {
                break;
            }
        }
        let f = returns(r);
        let g = f.ln() - ln_detect;
        if f >= detect {
            (a, ga) = (r, g.max(0.0));
            if last == -1 {
                gb *= 0.5;
            }
            last = -1;
        } else {
            (b, gb) = (r, g.min(0.0));
            if last == 1 {
                ga *= 0.5;
            }
            last = 1;
        }
    }
    let yes = (a * (1.0 - NARROW_MARGIN)).max(lo);
    let no = (b * (1.0 + NARROW_MARGIN)).min(hi);
    if returns(yes) >= detect && returns(no) < detect {
        (yes, no)
    } else {
        (lo, hi)
    }
}

/// Where [`ReturnModel::detection_range_near_m`] starts looking: a range
/// and its relative error (the first step out from it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guess {
    /// The guessed end of the detecting ranges, m (not finite: no guess).
    pub range_m: f64,
    /// How far off it may be, relative.
    pub rel_err: f64,
}

impl Guess {
    /// No guess: the bracket starts from `[0.01, R_max]`.
    pub const NONE: Self = Self {
        range_m: f64::NAN,
        rel_err: 0.0,
    };
}

/// [`narrow`]'s widening of its bracket, relative: 100 times the model's
/// rounding of the end (at most about 1e-14 of the range: the returns'
/// relative rounding, some 200ε where `erfc` is steepest, over their slope
/// in `ln R`, at least 1 and there some 40), and as wide as the bisection's
/// last interval (a relative 1e-12 of its first `hi`), so that at most one
/// or two of its midpoints fall inside the widened bracket and are evaluated.
const NARROW_MARGIN: f64 = 1e-12;

/// [`narrow`]'s most regula falsi steps (it stops once its bracket is a
/// relative [`NARROW_MARGIN`] wide: a narrower bracket would save no
/// bisection midpoint, since its ends are widened by that much anyway).
const NARROW_STEPS: usize = 40;

/// Relative error allowed for `libm::erfc` in [`ReturnModel::expected_returns_upper`]:
/// musl's `erfc` (which `libm` ports) is accurate to about one ulp
/// (1.1e-16); the margin is 10⁴ times that, tested against 40-digit values
/// (mpmath) from `z = −5.9` to `26.5`.
pub const ERFC_REL_ERR: f64 = 1e-12;

impl ReturnModel {
    /// An upper bound of the real-number value of
    /// [`Self::expected_returns`] at `range_m` (the model evaluated without
    /// rounding), from one floating-point evaluation rounded outward:
    /// - the pulses `W/(R·Δφ)` (two divisions, each within ε) raised by a
    ///   relative 1e-12 (which also covers the final product's rounding and
    ///   the few ε by which a caller's `Δφ = θ/(f_p·t)` misses its exact value);
    /// - `physical`: the amplitude `A` raised by a relative
    ///   `1e-12 + 16ε·(|2αR| + |2α₀R₀| + 8)` (the exponent's absolute
    ///   rounding is at most `4ε` of its terms' magnitudes, which `exp`
    ///   turns into a relative error; six products and `exp`'s own ulp on
    ///   top), then `P_D = ½·erfc(z)` at `z = (T − A)/√2` lowered by
    ///   `1e-12·(|T| + A)` (erfc falls, so a lower `z` is a higher `P_D`),
    ///   raised by [`ERFC_REL_ERR`] and by `f64::MIN_POSITIVE` (erfc's
    ///   subnormal results carry an absolute error below it), capped at 1;
    /// - `argus`: 1 where the intensity raised by a relative 1e-12 reaches
    ///   the threshold within 100 m, else 0.
    #[must_use]
    pub fn expected_returns_upper(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        width_m: f64,
        spacing_rad: f64,
        range_m: f64,
    ) -> f64 {
        let pulses = width_m / (range_m * spacing_rad) * (1.0 + 1e-12);
        let p = match *self {
            Self::Argus {
                fog_factor,
                threshold,
            } => {
                let intensity = power_ratio * self.range_factor(range_m) * fog_factor;
                if range_m <= ARGUS_RANGE_M && intensity * (1.0 + 1e-12) >= threshold {
                    1.0
                } else {
                    0.0
                }
            }
            Self::Physical {
                params,
                extinction_per_m,
            } => {
                let exponent = (2.0 * extinction_per_m * range_m).abs()
                    + (2.0 * params.clear_extinction_per_m * params.rated_range_m).abs();
                let rel = 1e-12 + 16.0 * f64::EPSILON * (exponent + 8.0);
                let a = self.amplitude_sigma(power_ratio, reflectivity, 1.0, range_m) * (1.0 + rel);
                let t = params.threshold_sigma;
                let z = (t - a) / std::f64::consts::SQRT_2 - 1e-12 * (t.abs() + a.abs());
                (0.5 * libm::erfc(z) * (1.0 + ERFC_REL_ERR) + f64::MIN_POSITIVE).min(1.0)
            }
        };
        // No return at all is none at any pulse count (at `R = 0` too).
        if p == 0.0 {
            0.0
        } else {
            pulses * p
        }
    }

    /// Whether no range beyond `range_m` detects in the real-number model of
    /// [`Self::detection_range_m`] (so its detection range is at most
    /// `range_m`): `range_m` is at or beyond one of its caps (10⁴ m,
    /// `argus`'s 100 m, or `W/(Δφ·detect)` raised by a relative 1e-12,
    /// where even `P_D = 1` leaves fewer than `detect` pulses), or
    /// [`Self::expected_returns_upper`] there is below `detect` (the expected
    /// returns fall with the range, so every farther range detects less).
    #[must_use]
    pub fn detects_nothing_beyond(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        width_m: f64,
        spacing_rad: f64,
        detect: f64,
        range_m: f64,
    ) -> bool {
        let cap = width_m / (spacing_rad * detect) * (1.0 + 1e-12);
        range_m >= 10_000.0
            || (matches!(self, Self::Argus { .. }) && range_m >= ARGUS_RANGE_M)
            || range_m >= cap
            || self.expected_returns_upper(power_ratio, reflectivity, width_m, spacing_rad, range_m)
                < detect
    }

    /// A proven upper bound of the detection range (of the real-number
    /// model and of [`Self::detection_range_m`]'s floating-point answer):
    /// 0 where no range at all detects (`argus` below its threshold at
    /// `R = 0`), else from that answer (at least 1 cm), stepped up by a
    /// relative 1e-9, 4e-9, 1.6e-8, … until
    /// [`Self::detects_nothing_beyond`] holds.
    #[must_use]
    pub fn detection_range_upper_m(
        &self,
        power_ratio: f64,
        reflectivity: f64,
        width_m: f64,
        spacing_rad: f64,
        detect: f64,
    ) -> f64 {
        let found = self.detection_range_m(power_ratio, reflectivity, width_m, spacing_rad, detect);
        let holds = |r: f64| {
            self.detects_nothing_beyond(power_ratio, reflectivity, width_m, spacing_rad, detect, r)
        };
        if found == 0.0 && holds(0.0) {
            return 0.0;
        }
        let mut r = found.max(0.01);
        let mut step = 1e-9;
        while !holds(r) {
            r *= 1.0 + step;
            step *= 4.0;
        }
        r
    }
}

/// Width of the range buckets of [`Saturation`], m (a power of two: the
/// bucket index `⌊r / w⌋` is exact).
pub(crate) const RANGE_BUCKET_M: f64 = 0.25;

/// The physical model's saturation on box hits (both geometries): `P_D = ½·erfc((T − A)/√2)`
/// is exactly 1 once `(T − A)/√2 ≤ −6` (libm's `erfc` returns `2 − ε`
/// with `ε < erfc(6) ≈ 2e-17`, below half an ulp of 2, or `2 − 2^−1022`;
/// tested), i.e. `A ≥ T + 6√2`. The amplitude
/// `A = T·P·(ρ/ρ0)·cos·(r0/R)²·e^(−2αR + 2α0·r0)` falls with `R` (α ≥ 0),
/// so each range bucket has a lower bound of `A / (P·cos)`; a hit whose
/// bound clears the limit (padded far above rounding) returns without
/// evaluating `erfc`.
#[derive(Debug, Clone)]
pub(crate) struct Saturation {
    /// Per surface (0 building, 1 vehicle), per bucket: the lower bound.
    rows: [Vec<f64>; 2],
    /// `(T + 6√2)·(1 + 1e-9)`.
    limit: f64,
}

impl Saturation {
    pub(crate) fn new(model: &ReturnModel, reflectivity: [f64; 2], range_m: f64) -> Option<Self> {
        let ReturnModel::Physical {
            params,
            extinction_per_m,
        } = *model
        else {
            return None;
        };
        let ok = |x: f64| x.is_finite() && x > 0.0;
        if !(extinction_per_m >= 0.0
            && ok(params.rated_range_m)
            && ok(params.reference_reflectivity)
            && params.clear_extinction_per_m.is_finite()
            && extinction_per_m.is_finite()
            && range_m.is_finite())
        {
            return None;
        }
        let buckets = (range_m / RANGE_BUCKET_M).ceil() as usize + 1;
        let eq = params.equation();
        let rows = reflectivity.map(|rho| {
            (0..buckets)
                .map(|i| {
                    let r_hi = (i + 1) as f64 * RANGE_BUCKET_M;
                    // `T·S` at power ratio 1 and normal incidence (the
                    // factors of 1 are exact: the same bits as `P·cos` = 1).
                    let bound = eq.signal(
                        params.threshold_sigma,
                        1.0,
                        rho,
                        1.0,
                        r_hi,
                        eq.extinction_factor(extinction_per_m, r_hi),
                    );
                    bound * (1.0 - 1e-12)
                })
                .collect()
        });
        Some(Self {
            rows,
            limit: (params.threshold_sigma + 6.0 * std::f64::consts::SQRT_2) * (1.0 + 1e-9),
        })
    }

    /// Whether a hit on `surface` (0 building, 1 vehicle) in range bucket
    /// `bucket` at power ratio `power` and incidence `cos` surely has `P_D = 1`.
    pub(crate) fn saturated(&self, surface: usize, bucket: usize, power: f64, cos: f64) -> bool {
        self.rows[surface]
            .get(bucket)
            .is_some_and(|&l| power * cos * l >= self.limit)
    }

    /// Whether [`Self::saturated`] holds for every hit on `surface` in a
    /// range bucket of `buckets` (inclusive) with incidence cosine at least
    /// `cos_lo`: each bucket's bound clears the limit at `cos_lo`, and
    /// `(power·cos)·l` only grows with `cos` (non-negative factors; rounding
    /// is monotone).
    pub(crate) fn saturated_over(
        &self,
        surface: usize,
        buckets: (usize, usize),
        power: f64,
        cos_lo: f64,
    ) -> bool {
        power >= 0.0
            && cos_lo >= 0.0
            && buckets.0 <= buckets.1
            && (buckets.0..=buckets.1).all(|b| {
                self.rows[surface]
                    .get(b)
                    .is_some_and(|&l| l >= 0.0 && power * cos_lo * l >= self.limit)
            })
    }
}

/// The `argus` model's range factor `e^(−0.004·r)` bounded per range
/// bucket `[i·w, (i + 1)·w)` up to its 100 m: the factor falls with `r`,
/// so the value at the bucket's far end (less a relative 1e-12, far above
/// libm's half-ulp rounding) bounds it from below and the value at its near
/// end (plus 1e-12) from above. Floating-point products are monotone in
/// each factor, so `P·lower·fog ≥ threshold` proves the model's
/// `(P·factor)·fog ≥ threshold` (`P_D = 1`) and `P·upper·fog < threshold`
/// proves `P_D = 0`, without the `exp`; between the two the caller
/// evaluates the model.
#[derive(Debug, Clone)]
pub(crate) struct ArgusBuckets {
    /// Per bucket: (lower, upper) bound of the range factor.
    bounds: Vec<(f64, f64)>,
}

impl ArgusBuckets {
    /// The table (computed once).
    pub(crate) fn get() -> &'static Self {
        static TABLE: std::sync::OnceLock<ArgusBuckets> = std::sync::OnceLock::new();
        TABLE.get_or_init(Self::new)
    }

    pub(crate) fn new() -> Self {
        let factor = |r: f64| (-CARLA_ATTENUATION_PER_M * r).exp();
        let buckets = (ARGUS_RANGE_M / RANGE_BUCKET_M).ceil() as usize + 1;
        Self {
            bounds: (0..buckets)
                .map(|i| {
                    let (near, far) = (i as f64 * RANGE_BUCKET_M, (i + 1) as f64 * RANGE_BUCKET_M);
                    (factor(far) * (1.0 - 1e-12), factor(near) * (1.0 + 1e-12))
                })
                .collect(),
        }
    }

    /// `P_D` of `model` (an `argus` model; `None` for another) at power ratio
    /// `power` for a hit at `range_m` in range bucket `bucket` (`⌊r / w⌋`),
    /// if the bucket decides it: the value
    /// [`ReturnModel::detection_probability`] returns, bit for bit.
    pub(crate) fn decided(
        &self,
        model: &ReturnModel,
        range_m: f64,
        bucket: usize,
        power: f64,
    ) -> Option<f64> {
        let ReturnModel::Argus {
            fog_factor,
            threshold,
        } = *model
        else {
            return None;
        };
        if range_m > ARGUS_RANGE_M {
            return Some(0.0);
        }
        let &(lower, upper) = self.bounds.get(bucket)?;
        if power * lower * fog_factor >= threshold {
            Some(1.0)
        } else if power * upper * fog_factor < threshold {
            Some(0.0)
        } else {
            None
        }
    }

    /// [`Self::decided`]'s value if it is the same for every hit at a range
    /// in `range_m` (inclusive) and its buckets `buckets` (inclusive):
    /// beyond the 100 m all are 0; within them each bucket decides alone
    /// (the range enters only through the 100 m test).
    pub(crate) fn decided_over(
        &self,
        model: &ReturnModel,
        range_m: (f64, f64),
        buckets: (usize, usize),
        power: f64,
    ) -> Option<f64> {
        let ReturnModel::Argus { .. } = *model else {
            return None;
        };
        if range_m.0 > ARGUS_RANGE_M {
            return Some(0.0);
        }
        if range_m.1.is_nan() || range_m.1 > ARGUS_RANGE_M || buckets.0 > buckets.1 {
            return None;
        }
        let mut out = None;
        for b in buckets.0..=buckets.1 {
            // Any range within the 100 m stands for all of them here.
            let p = self.decided(model, range_m.1, b, power)?;
            if out.is_some_and(|o| o != p) {
                return None;
            }
            out = Some(p);
        }
        out
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
    fn decisions_over_a_range_hold_at_every_range_in_it() {
        // Ranges [lo, hi] across the tables (and beyond the argus 100 m):
        // a decision over the range is the pointwise decision at ranges
        // inside it (edges included), for cosines at or above the bound.
        let table = ArgusBuckets::new();
        let step = |k: u32| f64::from(k) * 0.37 + 0.05;
        let (mut argus_decided, mut saturated) = (0, 0);
        for fog in FOG_LEVELS_PCT {
            let argus = model(ModelKind::Argus, fog);
            let physical = model(ModelKind::Physical, fog);
            let sat = Saturation::new(&physical, [0.3, 0.6], 400.0).unwrap();
            for power in [0.25, 0.9, 1.0, 2.0] {
                for k in 0..300u32 {
                    for width in [0.0, 0.1, 1.0, 4.0] {
                        let range = (step(k), step(k) + width);
                        let buckets = (
                            (range.0 * (1.0 / RANGE_BUCKET_M)) as usize,
                            (range.1 * (1.0 / RANGE_BUCKET_M)) as usize,
                        );
                        let inside = (0..=16).map(|i| range.0 + width * f64::from(i) / 16.0);
                        let inside: Vec<f64> = inside.chain([range.1]).collect();
                        if let Some(p) = table.decided_over(&argus, range, buckets, power) {
                            argus_decided += 1;
                            for &r in &inside {
                                let b = (r * (1.0 / RANGE_BUCKET_M)) as usize;
                                assert_eq!(table.decided(&argus, r, b, power), Some(p), "{r}");
                            }
                        }
                        for cos_lo in [0.2, 0.7, 1.0] {
                            if sat.saturated_over(0, buckets, power, cos_lo) {
                                saturated += 1;
                                for &r in &inside {
                                    let b = (r * (1.0 / RANGE_BUCKET_M)) as usize;
                                    for cos in [cos_lo, 0.5 * (cos_lo + 1.0), 1.0] {
                                        assert!(sat.saturated(0, b, power, cos), "{r} {cos}");
                                        assert_eq!(
                                            physical.detection_probability(power, 0.3, cos, r),
                                            1.0
                                        );
                                    }
                                }
                            }
                        }
                    }
                }
            }
            assert_eq!(table.decided_over(&physical, (1.0, 2.0), (4, 8), 1.0), None);
        }
        assert!(
            argus_decided > 5_000 && saturated > 1_000,
            "{argus_decided} {saturated}"
        );
    }

    #[test]
    fn argus_buckets_decide_as_the_model_does() {
        // Every fog level, powers of the closed forms and between, ranges
        // across every bucket (their edges included) and beyond 100 m.
        let table = ArgusBuckets::new();
        let mut decided = 0;
        for fog in FOG_LEVELS_PCT {
            let m = model(ModelKind::Argus, fog);
            for power in [0.0, 0.25, 0.5, 0.9, 1.0, 1.1, 1.2, 2.0] {
                for k in 0..=41_000u32 {
                    let r = f64::from(k) * (101.0 / 41_000.0) + 1e-3;
                    let bucket = (r * (1.0 / RANGE_BUCKET_M)) as usize;
                    let exact = m.detection_probability(power, 0.3, 0.7, r);
                    if let Some(p) = table.decided(&m, r, bucket, power) {
                        assert_eq!(p.to_bits(), exact.to_bits(), "fog {fog} P {power} r {r}");
                        decided += 1;
                    }
                }
                for i in 0..=400u32 {
                    let r = f64::from(i) * RANGE_BUCKET_M;
                    let bucket = (r * (1.0 / RANGE_BUCKET_M)) as usize;
                    for r in [r, r.next_up(), (r + RANGE_BUCKET_M).next_down()] {
                        let exact = m.detection_probability(power, 0.3, 0.7, r);
                        if let Some(p) = table.decided(&m, r, bucket, power) {
                            assert_eq!(p.to_bits(), exact.to_bits(), "fog {fog} P {power} r {r}");
                        }
                    }
                }
            }
        }
        // It decides nearly everything (the undecided: ranges near a
        // threshold crossing).
        assert!(decided > 3 * 8 * 40_000, "{decided}");
        let physical = model(ModelKind::Physical, 0);
        assert_eq!(table.decided(&physical, 10.0, 40, 1.0), None);
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

    /// `libm::erfc` against 40-digit values (mpmath 1.3,
    /// `erfc(mpf(z))` at the double `z`): within [`ERFC_REL_ERR`] (in fact
    /// within a few ulp), the premise of the enclosure.
    #[test]
    // The oracle's 20 digits as printed (the compiler rounds each to the
    // nearest double).
    #[allow(clippy::excessive_precision)]
    fn erfc_is_within_its_stated_error() {
        let table = [
            (-5.9, 1.999_999_999_999_999_928_1),
            (-3.5, 1.999_999_256_901_627_658_6),
            (-1.25, 1.922_900_128_256_458_230_1),
            (-0.3, 1.328_626_759_459_127_416_2),
            (0.0, 1.0),
            (0.4, 5.716_076_449_533_315_235_5e-1),
            (1.0, 1.572_992_070_502_851_306_6e-1),
            (1.7, 1.620_954_140_922_543_915_9e-2),
            (2.5, 4.069_520_174_449_589_395_6e-4),
            (3.3, 3.057_709_796_438_165_198_8e-6),
            (4.2, 2.855_494_179_592_184_240_2e-9),
            (5.0, 1.537_459_794_428_034_850_2e-12),
            (6.5, 3.842_148_327_120_647_469_9e-20),
            (8.0, 1.122_429_717_298_292_708e-29),
            (10.5, 7.035_928_090_177_522_686_7e-50),
            (13.0, 1.739_557_315_466_724_521_8e-75),
            (16.0, 2.328_485_751_571_530_693_4e-113),
            (19.5, 2.090_954_147_922_729_460_5e-167),
            (23.0, 4.441_265_948_088_057_244_1e-232),
            (26.0, 5.663_192_408_856_142_846_5e-296),
            (26.5, 2.210_907_664_263_734_275_9e-307),
        ];
        for (z, want) in table {
            let got = libm::erfc(z);
            let rel = (got - want).abs() / want;
            assert!(rel <= 1e-15, "erfc({z}) = {got:e}, want {want:e} ({rel:e})");
            assert!(rel * 1e3 <= ERFC_REL_ERR);
        }
    }

    /// The enclosure against the plain model, and the proven range against
    /// the bisection: above both, and only a little.
    #[test]
    fn the_upper_range_is_above_the_model_and_proven() {
        for kind in [ModelKind::Argus, ModelKind::Physical] {
            for fog in [0, 25, 50] {
                let m = model(kind, fog);
                for (x, spacing) in [(0.3, 1e-3), (1.0, 3e-3), (1.7, 1e-4), (0.05, 1e-2)] {
                    for r in [0.5, 7.0, 40.0, 99.0, 150.0] {
                        let e = m.expected_returns(x, 0.1, 1.8, spacing, r);
                        let up = m.expected_returns_upper(x, 0.1, 1.8, spacing, r);
                        assert!(up >= e && up <= e * (1.0 + 1e-9) + 1e-300, "{up} vs {e}");
                    }
                    let found = m.detection_range_m(x, 0.1, 1.8, spacing, 1.0);
                    let up = m.detection_range_upper_m(x, 0.1, 1.8, spacing, 1.0);
                    assert!(
                        up >= found && up <= found.max(0.01) * (1.0 + 1e-6),
                        "{up} {found}"
                    );
                    assert!(m.detects_nothing_beyond(x, 0.1, 1.8, spacing, 1.0, up));
                    // A brute-force scan beyond it finds no detecting range.
                    for j in 1..=200 {
                        let r = up.max(1e-3) * (1.0 + f64::from(j) * 0.01);
                        assert!(m.expected_returns(x, 0.1, 1.8, spacing, r) < 1.0 || r > 10_000.0);
                    }
                }
            }
        }
    }

    /// [`ReturnModel::detection_range_m`] as plain bisection: every
    /// midpoint evaluated.
    fn plain_detection_range(m: &ReturnModel, x: f64, rho: f64, w: f64, s: f64, d: f64) -> f64 {
        let ok = |r: f64| m.expected_returns(x, rho, w, s, r) >= d;
        let mut hi = (w / (s * d)).min(10_000.0);
        if let ReturnModel::Argus { .. } = m {
            hi = hi.min(ARGUS_RANGE_M);
        }
        let mut lo = 0.01;
        if !(hi > lo && ok(lo)) {
            return 0.0;
        }
        if ok(hi) {
            return hi;
        }
        for _ in 0..100 {
            if hi - lo <= 1e-12 * hi {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if ok(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    proptest::prop_compose! {
        /// One detection-range question over the whole domain the optimizer
        /// asks: either model at every fog level, relative power `x`,
        /// reflectivity, target width (m), beam spacing (rad, log-uniform)
        /// and the returns needed.
        fn detection_case()(
            physical in proptest::bool::ANY,
            fog_i in 0usize..3,
            x in 0.0f64..3.0,
            rho in 0.02f64..1.0,
            w in 0.3f64..5.0,
            log_s in -5.0f64..-1.0,
            d in 0.5f64..20.0,
        ) -> (ReturnModel, f64, f64, f64, f64, f64) {
            let kind = if physical { ModelKind::Physical } else { ModelKind::Argus };
            (model(kind, FOG_LEVELS_PCT[fog_i]), x, rho, w, 10f64.powf(log_s), d)
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(4000))]
        /// The narrowed bisection gives the plain bisection's answer, bit
        /// for bit, on both models at every fog level.
        #[test]
        fn the_narrowed_detection_range_is_the_plain_bisection(
            (m, x, rho, w, s, d) in detection_case(),
        ) {
            let got = m.detection_range_m(x, rho, w, s, d);
            let want = plain_detection_range(&m, x, rho, w, s, d);
            proptest::prop_assert_eq!(got.to_bits(), want.to_bits(), "{} vs {}", got, want);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2000))]
        /// A guess, good or bad, moves only where the model is evaluated:
        /// the answer is the plain bisection's, bit for bit.
        #[test]
        fn a_guessed_detection_range_is_the_plain_bisection(
            (m, x, rho, w, s, d) in detection_case(),
            off in -1.0f64..1.0,
            log_err in -14.0f64..0.0,
        ) {
            let want = plain_detection_range(&m, x, rho, w, s, d);
            // Guesses near the answer (off by up to ±10^log_err), and far.
            let near = want * (1.0 + off * 10f64.powf(log_err));
            for range_m in [near, 1.0 + 200.0 * off.abs(), 0.0, f64::INFINITY] {
                let guess = Guess { range_m, rel_err: 10f64.powf(log_err) };
                let got = m.detection_range_near_m(x, rho, w, s, d, guess);
                proptest::prop_assert_eq!(got.to_bits(), want.to_bits(), "{} vs {} (guess {})", got, want, range_m);
            }
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
