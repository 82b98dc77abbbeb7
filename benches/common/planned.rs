//! The closed-form planner's 360-bin joint profiles (paper preset) for the
//! three gazes of the gaze benchmark's trace (90°, 130°, 170°), shared by
//! `benches/gaze.rs` and `examples/check_instructions.rs`.
//!
//! With `distinct`, every bin's power is lowered by a different tiny
//! fraction, so no two neighbours are alike and the bound cannot merge the
//! closed form's runs of equal bins: the cost of a profile whose 360 bins
//! all differ (a smooth optimizer profile, say).

use gaze_lidar::model::presets;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;
use gaze_lidar::profile::Profile;

pub fn planned_profiles(distinct: bool) -> Vec<Profile> {
    let preset = presets::paper();
    [90.0, 130.0, 170.0]
        .iter()
        .map(|&g| {
            let mut p = build_profile(&preset, Mode::Joint, Some(g), 360).unwrap();
            if distinct {
                for (i, b) in p.bins.iter_mut().enumerate() {
                    b.power_w *= 1.0 - 1e-6 * (i + 1) as f64;
                }
            }
            p
        })
        .collect()
}
