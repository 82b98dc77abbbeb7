//! The profile timeline (trusted core) on a closed-form profile.

use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};
use gaze_lidar::profile::kinematics::Timeline;

#[test]
fn windows_touching_a_bin_edge_include_it() {
    let c = closed_form(&presets::paper(), Mode::Range, Some(90.0), 360).unwrap();
    let tl = Timeline::new(c.profile());
    let (p_low, p_high) = (0.5e-3, 1.1e-3);
    // RoF is [60, 120): a window [120 − 1e-13, 125) only touches it.
    let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
    // RoF is [60, 120) at P_low; windows that touch it include it.
    assert!(close(tl.max_power_in(120.0, 5.0), p_high));
    assert!(close(tl.max_power_in(115.0, 5.0), p_high));
    assert!(close(tl.max_power_in(55.0, 5.0 - 1e-13), p_high));
    assert!((tl.max_power_in(60.5, 2.0) - p_low).abs() < 1e-18);
    assert_eq!(tl.bins_touching(60.0, 2.0), vec![59, 60, 61, 62]);
    assert_eq!(tl.bins_touching(359.0, 2.0), vec![358, 359, 0, 1]);
    let (t, e) = tl.window(350.0, 20.0);
    assert!((t - 20f64.to_radians() / presets::paper().lidar.mean_spin_rad_s()).abs() < 1e-15);
    assert!(e > 0.0);
    let (az, bin) = tl.azimuth_at(0.0125);
    assert!((az - 90.0).abs() < 1e-9 && bin == 90);
    for k in 0..500 {
        let t = f64::from(k) * 1e-4;
        for hint in [0, 17, 359] {
            assert_eq!(tl.azimuth_at_from(t, hint), tl.azimuth_at(t));
        }
    }
}
