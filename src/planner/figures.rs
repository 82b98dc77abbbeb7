//! A profile in units people use: the range (m) and the point density
//! (points per degree) inside the driver's region of focus and outside it,
//! next to the paper's closed form's for the same gaze.
//!
//! What each figure is and how a per-bin figure aggregates over a region
//! is stated once, on [`UnitFigures`] (profile@1's `optimality.figures`)
//! and in `specs/optimizer.md`. The range comes from the one range
//! equation ([`crate::model::range`]); the dwell from the core's
//! kinematics ([`crate::profile::Bin::dwell_time_s`]).

use crate::checker::CertifiedProfile;
use crate::model::acuity::FocusModel;
use crate::model::angle::CircularSet;
use crate::model::lidar::LidarSpec;
use crate::model::presets::Preset;
use crate::model::range::RangeEquation;
use crate::planner::{closed_form, Mode};
use crate::profile::{Aggregate, Bin, Profile, RegionFigure, RegionFigures, UnitFigures};

/// The sensor's range at `power_w` on its reference reflectivity in clear
/// air, m (the range equation calibrated so `average_power_w` reaches
/// `rated_range_m`).
#[must_use]
pub fn range_m(lidar: &LidarSpec, power_w: f64) -> f64 {
    RangeEquation::rated(lidar.rated_range_m, lidar.reference_reflectivity)
        .rated_conditions_range_m(power_w / lidar.average_power_w)
}

/// Points per degree per channel and revolution in `bin`:
/// `pulse_rate_hz · dwell / width` (the pulse rate over the bin's mean
/// spin in deg/s).
#[must_use]
pub fn points_per_deg(pulse_rate_hz: f64, bin: &Bin) -> f64 {
    pulse_rate_hz * bin.dwell_time_s() / bin.width_deg
}

/// Running angle-weighted sum, min and max of one figure.
#[derive(Clone, Copy)]
struct Running {
    sum: f64,
    min: f64,
    max: f64,
}

impl Default for Running {
    fn default() -> Self {
        Self {
            sum: 0.0,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
        }
    }
}

impl Running {
    fn push(&mut self, width_deg: f64, v: f64) {
        self.sum += width_deg * v;
        self.min = self.min.min(v);
        self.max = self.max.max(v);
    }
}

/// One region's running figures.
#[derive(Default)]
struct Acc {
    bins: usize,
    width_deg: f64,
    range: Running,
    density: Running,
}

impl Acc {
    fn add(&mut self, width_deg: f64, range_m: f64, points_per_deg: f64) {
        self.bins += 1;
        self.width_deg += width_deg;
        self.range.push(width_deg, range_m);
        self.density.push(width_deg, points_per_deg);
    }

    fn finish(self) -> Option<RegionFigure> {
        let agg = |r: Running| Aggregate {
            mean: r.sum / self.width_deg,
            min: r.min,
            max: r.max,
        };
        (self.bins > 0).then(|| RegionFigure {
            width_deg: self.width_deg,
            range_m: agg(self.range),
            points_per_deg: agg(self.density),
        })
    }
}

/// `profile`'s figures on `lidar` with the region of focus of `focus` at
/// the profile's gaze (none for a gaze-free profile: every bin is in the
/// region of interest). A bin belongs to the region containing its centre.
#[must_use]
pub fn region_figures(profile: &Profile, lidar: &LidarSpec, focus: &FocusModel) -> RegionFigures {
    let rof = profile
        .gaze_deg
        .map_or_else(CircularSet::empty, |g| focus.regions(g).rof);
    let (mut inside, mut outside) = (Acc::default(), Acc::default());
    for b in &profile.bins {
        let acc = if rof.contains(b.center_deg()) {
            &mut inside
        } else {
            &mut outside
        };
        acc.add(
            b.width_deg,
            range_m(lidar, b.power_w),
            points_per_deg(profile.pulse_rate_hz, b),
        );
    }
    RegionFigures {
        rof: inside.finish(),
        roi: outside.finish(),
    }
}

/// `profile`'s figures on `preset`'s sensor and driver model, next to
/// those of the paper's closed form `mode` (with `preset`'s levels) for
/// the profile's gaze on `bins` bins.
#[must_use]
pub fn unit_figures(profile: &Profile, preset: &Preset, mode: Mode, bins: usize) -> UnitFigures {
    let own = region_figures(profile, &preset.lidar, &preset.focus);
    let (closed, rejected) = match closed_form(preset, mode, profile.gaze_deg, bins) {
        Ok(c) => (
            Some(region_figures(c.profile(), &preset.lidar, &preset.focus)),
            None,
        ),
        Err(e) => (None, Some(format!("closed-form {}: {e}", mode.name()))),
    };
    UnitFigures {
        profile: own,
        closed_form: closed,
        closed_form_rejected: rejected,
    }
}

/// Writes [`unit_figures`] into `certified`'s `optimality` block (a
/// profile without one is returned unchanged); the block is informational,
/// so the certificate stands.
#[must_use]
pub fn attach(
    mut certified: CertifiedProfile,
    preset: &Preset,
    mode: Mode,
    bins: usize,
) -> CertifiedProfile {
    if let Some(mut opt) = certified.profile().optimality.clone() {
        opt.figures = Some(unit_figures(certified.profile(), preset, mode, bins));
        certified.set_optimality(Some(opt));
    }
    certified
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::{paper, vls128};
    use crate::profile::Region;
    use approx::assert_relative_eq;

    #[test]
    fn hand_worked_bin_figures() {
        let p = paper();
        // Paper preset: 7,812.5 pulses/s per channel. A 1° bin at a steady
        // 20 Hz (7,200 °/s): 7812.5 / 7200 = 1.0850694 points/deg.
        let bin = Bin {
            start_deg: 0.0,
            width_deg: 1.0,
            power_w: 1.1e-3,
            spin_start_rad_s: 40.0 * std::f64::consts::PI,
            spin_end_rad_s: 40.0 * std::f64::consts::PI,
            region: None,
            dwell_s: None,
        };
        assert_relative_eq!(
            points_per_deg(p.lidar.pulse_rate_hz, &bin),
            1.085_069_444,
            epsilon = 1e-9
        );
        // Ramping 10 → 30 Hz over 2°: dwell 2·2°/(3600 + 10800 °/s)
        // = 2.7778e-4 s, so 7812.5 · 2.7778e-4 / 2 = 1.0850694: the same
        // density as a steady 20 Hz (the time-mean spin is 20 Hz).
        let ramp = Bin {
            width_deg: 2.0,
            spin_start_rad_s: 20.0 * std::f64::consts::PI,
            spin_end_rad_s: 60.0 * std::f64::consts::PI,
            ..bin.clone()
        };
        assert_relative_eq!(
            points_per_deg(p.lidar.pulse_rate_hz, &ramp),
            1.085_069_444,
            epsilon = 1e-9
        );
        // Range at 1.1 P̄ on the paper's 100 m rating, clear air: 104.8054 m
        // (worked in `model::range`'s tests); at P̄ the rated 100 m; VLS-128
        // (245 m at its mean power) at half of it: 245·√0.5 = 173.24 m, and clear air
        // (α₀ = 1.498e-4 /m) lengthens it: R = 173.2412·e^(−α₀(R − 245)):
        // e^(α₀·71.759) = 1.010808 → 175.113; e^(α₀·69.887) = 1.010524 →
        // 175.064; e^(α₀·69.936) = 1.010532 → 175.066 m.
        assert_relative_eq!(range_m(&p.lidar, 1.1e-3), 104.8054, epsilon = 1e-3);
        assert_eq!(range_m(&p.lidar, 1.0e-3), 100.0);
        let half = 0.5 * vls128().lidar.average_power_w;
        assert_relative_eq!(range_m(&vls128().lidar, half), 175.066, epsilon = 2e-3);
    }

    #[test]
    fn closed_form_split_matches_its_levels_and_labels() {
        let preset = paper();
        for mode in [Mode::Range, Mode::Resolution, Mode::Joint] {
            let c = closed_form(&preset, mode, Some(90.0), 360).unwrap();
            let f = region_figures(c.profile(), &preset.lidar, &preset.focus);
            let (rof, roi) = (f.rof.unwrap(), f.roi.unwrap());
            // The paper's 60° box about 90°: [60°, 120°).
            assert_eq!((rof.width_deg, roi.width_deg), (60.0, 300.0));
            for b in &c.profile().bins {
                let inside = (60.0..120.0).contains(&b.center_deg());
                assert_eq!(b.region == Some(Region::Rof), inside, "{b:?}");
            }
            let lv = crate::planner::closed_form::levels(&preset, mode, 60.0, 300.0).unwrap();
            for (r, k) in [(&rof, 0), (&roi, 1)] {
                let range = range_m(&preset.lidar, lv.power_w[k]);
                let density = preset.lidar.pulse_rate_hz / lv.spin_rad_s[k].to_degrees();
                for a in [r.range_m, r.points_per_deg] {
                    assert!(a.min <= a.mean * (1.0 + 1e-12) && a.mean <= a.max * (1.0 + 1e-12));
                }
                assert_relative_eq!(r.range_m.min, range, max_relative = 1e-12);
                assert_relative_eq!(r.range_m.max, range, max_relative = 1e-12);
                assert_relative_eq!(r.range_m.mean, range, max_relative = 1e-12);
                assert_relative_eq!(r.points_per_deg.mean, density, max_relative = 1e-9);
            }
        }
    }

    #[test]
    fn unequal_bins_aggregate_by_angle() {
        // Gaze 90°: the paper's RoF is [60°, 120°). RoI bins: [0, 60) at P̄
        // (100 m) spinning 40 Hz (14,400 °/s: 7812.5/14400 = 0.5425 points/deg),
        // [120, 350) at 0 W (0 m) and [350, 360) at P̄ (100 m), both 20 Hz
        // (1.0851 points/deg). Angle-weighted over 300°:
        // range (60·100 + 230·0 + 10·100)/300 = 23.333 m (unweighted: 66.7);
        // density 7812.5·(60/14400 + 240/7200)/300 = 0.9765625 (the RoI's
        // points per turn over its degrees; unweighted: 0.9494).
        let preset = paper();
        let mut profile = closed_form(&preset, Mode::Range, Some(90.0), 360)
            .unwrap()
            .into_inner();
        let hz = |f: f64| f * std::f64::consts::TAU;
        let bin = |start_deg: f64, end_deg: f64, power_w: f64, spin_rad_s: f64| Bin {
            start_deg,
            width_deg: end_deg - start_deg,
            power_w,
            spin_start_rad_s: spin_rad_s,
            spin_end_rad_s: spin_rad_s,
            region: None,
            dwell_s: None,
        };
        profile.bins = vec![
            bin(0.0, 60.0, 1e-3, hz(40.0)),
            bin(60.0, 120.0, 0.0, hz(20.0)),
            bin(120.0, 350.0, 0.0, hz(20.0)),
            bin(350.0, 360.0, 1e-3, hz(20.0)),
        ];
        let f = region_figures(&profile, &preset.lidar, &preset.focus);
        let (rof, roi) = (f.rof.unwrap(), f.roi.unwrap());
        assert_eq!(rof.width_deg, 60.0);
        assert_eq!((rof.range_m.min, rof.range_m.max), (0.0, 0.0));
        assert_eq!(roi.width_deg, 300.0);
        assert_relative_eq!(roi.range_m.mean, 70.0 / 3.0, max_relative = 1e-12);
        assert_eq!((roi.range_m.min, roi.range_m.max), (0.0, 100.0));
        assert_relative_eq!(roi.points_per_deg.mean, 0.976_562_5, max_relative = 1e-12);
        assert_relative_eq!(
            roi.points_per_deg.min,
            7812.5 / 14400.0,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            roi.points_per_deg.max,
            7812.5 / 7200.0,
            max_relative = 1e-12
        );
    }

    #[test]
    fn gaze_free_profile_is_all_roi() {
        let preset = paper();
        let c = closed_form(&preset, Mode::Baseline, None, 360).unwrap();
        let f = region_figures(c.profile(), &preset.lidar, &preset.focus);
        assert!(f.rof.is_none());
        let roi = f.roi.unwrap();
        assert_eq!(roi.width_deg, 360.0);
        assert_eq!(roi.range_m.mean, 100.0);
    }
}
