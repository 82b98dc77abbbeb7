//! What a sensor running a certified profile would return, applied to a
//! point cloud recorded with a uniform sensor (e.g. CARLA's
//! `sensor.lidar.ray_cast`): the per-azimuth **range** from the profile's
//! power and the per-azimuth **density** from its spin.
//!
//! For each point (x, y, z) in the cloud:
//! - its azimuth β in the crate's convention ([`crate::model::angle`]: ISO
//!   8855, x forward, y left, z up, counter-clockwise from straight ahead in
//!   `[0, 360)`); CARLA's sensor frame is left-handed (x forward, **y
//!   right**, z up), so `β = atan2(−y, x)` there ([`CloudFrame::Carla`]) and
//!   `atan2(y, x)` in a right-handed frame ([`CloudFrame::Iso8855`]);
//! - **range**: the point is kept if it lies within the range at which a
//!   pulse of the profile's power at β, `P(β)/P̄`, detects a
//!   normal-incidence target of the reference reflectivity with `P_D ≥ ½`
//!   ([`ReturnModel::max_range_m`], once per power level): `physical`
//!   (range equation, fog extinction from the meteorological optical range,
//!   calibrated so the uniform baseline reaches `rated_range_m` in clear
//!   air) or `argus` (the paper code's intensity model, hard 100 m). The
//!   distance is `√(x²+y²+z²)`; a cloud carries no reflectivity, so every
//!   point is taken as the reference target;
//! - **density**: points per degree are `pulse_rate / ω(β)`; relative to the
//!   cloud's own spin `ω_c` (default the profile's uniform baseline
//!   `2π · frame_rate_hz`) the point survives with probability
//!   `min(1, ω_c / ω(β))` (seeded draws, one per point in order). Where the
//!   profile spins slower than the cloud, the cloud holds fewer points than
//!   the sensor would return and all are kept: record the cloud at the
//!   profile's slowest spin to see that gain.
//!
//! Nothing here is physics of its own: the return model is
//! [`ReturnModel`], ω(β) is profile@1's constant-acceleration law
//! ([`BinMotion::spin_into_rad_s`], the core's kinematics).

use std::f64::consts::TAU;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use thiserror::Error;

use crate::checker::CertifiedProfile;
use crate::model::angle::wrap_deg;
use crate::profile::kinematics::BinMotion;
use crate::sim::returns::{FogLevel, ModelKind, ReturnModel, FOG_LEVELS_PCT};

/// The coordinate frame of a cloud's x, y, z.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudFrame {
    /// CARLA / Unreal sensor frame: x forward, y right, z up (left-handed).
    Carla,
    /// ISO 8855 (the crate's): x forward, y left, z up.
    Iso8855,
}

impl CloudFrame {
    /// Azimuth of (x, y) in the crate's convention, degrees in `[0, 360)`.
    #[must_use]
    pub fn azimuth_deg(self, x: f64, y: f64) -> f64 {
        let y_left = match self {
            Self::Carla => -y,
            Self::Iso8855 => y,
        };
        wrap_deg(y_left.atan2(x).to_degrees())
    }
}

/// How to apply a profile to a cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudOptions {
    /// Range on the reference reflectivity at which the uniform baseline
    /// detects with `P_D = ½` in clear air, m (`physical` only; `argus` has
    /// the paper code's hard 100 m).
    pub rated_range_m: f64,
    /// Return model.
    pub model: ModelKind,
    /// Fog as a meteorological optical range, m; `None` is clear air
    /// (20 km). `argus` knows only the paper's levels: 200 m and 100 m.
    pub fog_mor_m: Option<f64>,
    /// Seed of the density thinning.
    pub seed: u64,
    /// Frame of the points.
    pub frame: CloudFrame,
    /// Spin the cloud was recorded at, rad/s; `None`: the profile's
    /// uniform baseline `2π · frame_rate_hz`.
    pub cloud_spin_rad_s: Option<f64>,
}

impl CloudOptions {
    /// Physical model, clear air, CARLA frame, seed 0.
    #[must_use]
    pub fn new(rated_range_m: f64) -> Self {
        Self {
            rated_range_m,
            model: ModelKind::Physical,
            fog_mor_m: None,
            seed: 0,
            frame: CloudFrame::Carla,
            cloud_spin_rad_s: None,
        }
    }
}

/// A bad argument or point; names it.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{field}: {reason}")]
pub struct CloudError {
    /// The argument (or `points[i]`).
    pub field: String,
    /// What is wrong.
    pub reason: String,
}

fn bad(field: impl Into<String>, reason: impl Into<String>) -> CloudError {
    CloudError {
        field: field.into(),
        reason: reason.into(),
    }
}

/// The return model the options ask for.
pub fn return_model(opts: &CloudOptions) -> Result<ReturnModel, CloudError> {
    if !(opts.rated_range_m.is_finite() && opts.rated_range_m > 0.0) {
        return Err(bad(
            "rated_range_m",
            format!("{} must be finite and > 0", opts.rated_range_m),
        ));
    }
    let clear = FogLevel::of(0).map_err(|e| bad("fog_mor_m", e.to_string()))?;
    let fog = match opts.fog_mor_m {
        None => clear,
        Some(m) if !(m.is_finite() && m > 0.0) => {
            return Err(bad("fog_mor_m", format!("{m} must be finite and > 0")))
        }
        Some(m) => match opts.model {
            // Only the extinction α = 2.996 / MOR is read from it.
            ModelKind::Physical => FogLevel { mor_m: m, ..clear },
            ModelKind::Argus => FOG_LEVELS_PCT
                .iter()
                .filter_map(|&p| FogLevel::of(p).ok())
                .find(|f| f.mor_m == m)
                .ok_or_else(|| {
                    bad(
                        "fog_mor_m",
                        format!(
                            "{m} m: the argus model knows only the paper's fog levels, MOR 20000 (clear), 200 and 100 m"
                        ),
                    )
                })?,
        },
    };
    // Every point is a target of the reference reflectivity: pass 1 for both.
    Ok(ReturnModel::new(opts.model, fog, opts.rated_range_m, 1.0))
}

/// Bin lookup on a sorted key in `[0, span)`: a table of 4096 equal cells,
/// each holding the last bin starting at or before the cell's start; a short
/// scan finishes (exact, whatever the bin widths).
struct BinLookup {
    cells: Vec<usize>,
    per_unit: f64,
}

impl BinLookup {
    const CELLS: usize = 4096;

    fn new(starts: &[f64], span: f64) -> Self {
        let cells = (0..Self::CELLS)
            .map(|c| {
                let at = c as f64 * (span / Self::CELLS as f64);
                starts.partition_point(|&s| s <= at).saturating_sub(1)
            })
            .collect();
        Self {
            cells,
            per_unit: Self::CELLS as f64 / span,
        }
    }

    /// The last bin whose start is at or before `key` (0 if none).
    #[inline]
    fn index(&self, starts: &[f64], key: f64) -> usize {
        let c = ((key * self.per_unit) as usize).min(Self::CELLS - 1);
        // The cell's own start may round above the key: step back if needed.
        let mut k = self.cells[c];
        while k > 0 && starts[k] > key {
            k -= 1;
        }
        while k + 1 < starts.len() && starts[k + 1] <= key {
            k += 1;
        }
        k
    }
}

/// A monotone stand-in for the azimuth of (x, y_left) in `[0, 4)` (0 ahead,
/// 1 left, 2 behind, 3 right): orders directions as `atan2` does, for a
/// division instead of a transcendental call.
#[inline]
fn pseudo_azimuth(x: f64, y_left: f64) -> f64 {
    let d = x.abs() + y_left.abs();
    if d == 0.0 {
        return 0.0;
    }
    let p = y_left / d;
    if x >= 0.0 {
        if p >= 0.0 {
            p
        } else {
            (4.0 + p).min(PSEUDO_BELOW_4)
        }
    } else {
        2.0 - p
    }
}

/// The largest `f64` below 4.
const PSEUDO_BELOW_4: f64 = 3.999_999_999_999_999_6;

/// Which points of `points` (x, y, z in `opts.frame`, metres) a sensor
/// running `profile` would return; see the module docs. Deterministic for a
/// given seed; one pass, no allocation but the mask.
pub fn keep_mask<I>(
    profile: &CertifiedProfile,
    points: I,
    opts: &CloudOptions,
) -> Result<Vec<bool>, CloudError>
where
    I: IntoIterator<Item = [f64; 3]>,
    I::IntoIter: ExactSizeIterator,
{
    let model = return_model(opts)?;
    let p = profile.profile();
    let cloud_spin = opts.cloud_spin_rad_s.unwrap_or(TAU * p.frame_rate_hz);
    if !(cloud_spin.is_finite() && cloud_spin > 0.0) {
        return Err(bad(
            "cloud_spin_rad_s",
            format!("{cloud_spin} must be finite and > 0"),
        ));
    }
    let bins = &p.bins;
    let starts: Vec<f64> = bins.iter().map(|b| b.start_deg).collect();
    // The return model's detection predicate is monotone in range, so each
    // power level has one maximum range: the crate's `max_range_m` (P_D ≥ ½
    // on the reference target at normal incidence), computed once per level.
    let mut levels: Vec<(u64, f64)> = Vec::new();
    let max_range2_m2: Vec<f64> = bins
        .iter()
        .map(|b| {
            let ratio = b.power_w / p.average_power_w;
            let key = ratio.to_bits();
            let r = match levels.iter().find(|(k, _)| *k == key) {
                Some(&(_, r)) => r,
                None => {
                    let r = model.max_range_m(ratio, 1.0);
                    levels.push((key, r));
                    r
                }
            };
            r * r
        })
        .collect();
    // Bins are found by the pseudo-azimuth of their start edge; the exact
    // azimuth (atan2) is needed only inside a bin whose spin ramps.
    let pseudo_starts: Vec<f64> = starts
        .iter()
        .map(|s| {
            let a = s.to_radians();
            if *s == 0.0 {
                0.0
            } else {
                pseudo_azimuth(a.cos(), a.sin())
            }
        })
        .collect();
    let lut = BinLookup::new(&pseudo_starts, 4.0);
    let y_sign = match opts.frame {
        CloudFrame::Carla => -1.0,
        CloudFrame::Iso8855 => 1.0,
    };
    let points = points.into_iter();
    let mut mask = Vec::with_capacity(points.len());
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    for (i, [x, y, z]) in points.enumerate() {
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(bad(
                format!("points[{i}]"),
                format!("({x}, {y}, {z}) is not a finite point"),
            ));
        }
        let u: f64 = rng.random();
        let k = lut.index(&pseudo_starts, pseudo_azimuth(x, y_sign * y));
        let b = &bins[k];
        let in_range = x * x + y * y + z * z <= max_range2_m2[k];
        let spin = if b.spin_start_rad_s == b.spin_end_rad_s {
            b.spin_start_rad_s
        } else {
            let az = opts.frame.azimuth_deg(x, y);
            b.spin_into_rad_s((az - b.start_deg).to_radians())
        };
        mask.push(in_range && u * spin < cloud_spin);
    }
    Ok(mask)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::paper;
    use crate::planner::{closed_form, Mode};

    fn at(az_deg: f64, r: f64) -> [f64; 3] {
        let a = az_deg.to_radians();
        // CARLA frame: y to the right.
        [r * a.cos(), -r * a.sin(), 0.0]
    }

    #[test]
    fn azimuth_conventions() {
        assert_eq!(CloudFrame::Carla.azimuth_deg(1.0, 0.0), 0.0);
        assert!((CloudFrame::Carla.azimuth_deg(0.0, -1.0) - 90.0).abs() < 1e-12);
        assert!((CloudFrame::Carla.azimuth_deg(0.0, 1.0) - 270.0).abs() < 1e-12);
        assert!((CloudFrame::Iso8855.azimuth_deg(0.0, 1.0) - 90.0).abs() < 1e-12);
        assert!((CloudFrame::Carla.azimuth_deg(-1.0, -1e-300) - 180.0).abs() < 1e-12);
    }

    #[test]
    fn baseline_keeps_exactly_the_rated_range_and_range_control_reaches_further_outside() {
        let base = closed_form(&paper(), Mode::Baseline, None, 360).unwrap();
        let opts = CloudOptions::new(100.0);
        let pts = [
            at(10.0, 99.9),
            at(200.0, 100.1),
            at(90.0, 50.0),
            at(0.0, 0.0),
        ];
        assert_eq!(
            keep_mask(&base, pts, &opts).unwrap(),
            [true, false, true, true]
        );
        let range = closed_form(&paper(), Mode::Range, Some(90.0), 360).unwrap();
        // RoF (gaze 90° ± 30°) at half power, RoI at 1.1 P̄.
        let pts = [at(90.0, 90.0), at(270.0, 102.0), at(270.0, 110.0)];
        assert_eq!(keep_mask(&range, pts, &opts).unwrap(), [false, true, false]);
    }

    #[test]
    fn bin_lookup_matches_a_binary_search() {
        // Uneven bins, edges closer than a lookup cell, and cell starts.
        let starts = [0.0, 0.01, 0.02, 1.0, 90.0, 90.0 + 1e-9, 179.5, 359.999];
        let lut = BinLookup::new(&starts, 360.0);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let probes = (0..4096)
            .map(|c| c as f64 * 360.0 / 4096.0)
            .chain(starts)
            .chain((0..20_000).map(|_| rng.random::<f64>() * 360.0));
        for az in probes {
            let want = starts.partition_point(|&s| s <= az).saturating_sub(1);
            assert_eq!(lut.index(&starts, az), want, "{az}");
        }
    }

    #[test]
    fn pseudo_azimuth_orders_directions_as_atan2() {
        // The bin found through the pseudo-azimuth is the bin of the exact
        // azimuth, on random directions and on uneven bins.
        let starts = [
            0.0, 0.5, 45.0, 89.9, 90.0, 135.0, 180.0, 181.0, 269.99, 270.0, 359.0,
        ];
        let pseudo: Vec<f64> = starts
            .iter()
            .map(|s: &f64| {
                let a = s.to_radians();
                if *s == 0.0 {
                    0.0
                } else {
                    pseudo_azimuth(a.cos(), a.sin())
                }
            })
            .collect();
        assert!(pseudo.windows(2).all(|w| w[0] < w[1]), "{pseudo:?}");
        let lut = BinLookup::new(&pseudo, 4.0);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..100_000 {
            let (x, y) = (rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
            let az = CloudFrame::Iso8855.azimuth_deg(x, y);
            let want = starts.partition_point(|&s| s <= az).saturating_sub(1);
            assert_eq!(
                lut.index(&pseudo, pseudo_azimuth(x, y)),
                want,
                "({x}, {y}) at {az}°"
            );
        }
        for (x, y, p) in [
            (1.0, 0.0, 0.0),
            (0.0, 1.0, 1.0),
            (-1.0, 0.0, 2.0),
            (0.0, -1.0, 3.0),
            (0.0, 0.0, 0.0),
        ] {
            assert_eq!(pseudo_azimuth(x, y), p);
        }
        assert!(pseudo_azimuth(1.0, -1e-300) < 4.0);
    }

    #[test]
    fn resolution_control_thins_the_rof_by_the_spin_ratio() {
        let res = closed_form(&paper(), Mode::Resolution, Some(90.0), 360).unwrap();
        let (hi, lo) = (
            res.profile().bins[90].spin_start_rad_s,
            res.profile().bins[270].spin_start_rad_s,
        );
        let n = 20_000;
        let rof: Vec<[f64; 3]> = (0..n)
            .map(|i| at(61.0 + 58.0 * i as f64 / n as f64, 10.0))
            .collect();
        let roi: Vec<[f64; 3]> = (0..n)
            .map(|i| at(200.0 + 100.0 * i as f64 / n as f64, 10.0))
            .collect();
        let opts = CloudOptions::new(100.0);
        let kept = |pts: &[[f64; 3]]| {
            keep_mask(&res, pts.iter().copied(), &opts)
                .unwrap()
                .iter()
                .filter(|&&k| k)
                .count() as f64
                / pts.len() as f64
        };
        let want = TAU * 20.0 / hi;
        let sigma = (want * (1.0 - want) / n as f64).sqrt();
        assert!(
            (kept(&rof) - want).abs() < 4.0 * sigma,
            "{} vs {want}",
            kept(&rof)
        );
        assert!(lo < TAU * 20.0);
        assert_eq!(kept(&roi), 1.0);
    }

    #[test]
    fn errors_name_the_field() {
        let base = closed_form(&paper(), Mode::Baseline, None, 36).unwrap();
        let e = keep_mask(&base, [[0.0, f64::NAN, 0.0]], &CloudOptions::new(100.0)).unwrap_err();
        assert_eq!(e.field, "points[0]");
        let e = keep_mask(&base, [], &CloudOptions::new(-1.0)).unwrap_err();
        assert_eq!(e.field, "rated_range_m");
        let mut o = CloudOptions::new(100.0);
        o.model = ModelKind::Argus;
        o.fog_mor_m = Some(150.0);
        assert_eq!(keep_mask(&base, [], &o).unwrap_err().field, "fog_mor_m");
        o.fog_mor_m = Some(100.0);
        assert!(keep_mask(&base, [], &o).is_ok());
    }
}
