//! Scenario TOML parse + validation + ray casts against the built scene:
//! never panics.
#![no_main]

use gaze_lidar::sim::Scenario;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(s) = Scenario::from_toml(text, "fuzz") else {
        return;
    };
    for b in s.static_boxes() {
        for k in 0..16 {
            let a = f64::from(k) * std::f64::consts::TAU / 16.0;
            if let Some(h) = b.ray_hit(a.cos(), a.sin()) {
                assert!(h.range_m > 0.0 && h.cos_incidence <= 1.0);
            }
        }
    }
});
