//! The per-frame picture: a `foxglove.SceneUpdate` (JSON) drawing the
//! profile as a flat ring around the sensor, in the cloud's frame.
//!
//! One sector per run of bins of equal power (split into arcs of at most
//! 5°); a sector spans radii `1 m` to `1 m + 4 m · P/P̄` and is coloured from
//! blue (`P/P̄ ≤ 0.5`) to red (`P/P̄ ≥ 1.5`); its opacity is `ω_c/ω` clamped to
//! `[0.3, 1]` (a slower spin, a denser scan, is drawn more opaque). A text
//! above the sensor says the state and the gaze. The entity keeps one id, so
//! each frame replaces the last.

use serde_json::{json, Value};

use crate::gaze::State;
use crate::profile::Profile;

const R_IN_M: f64 = 1.0;
const R_SCALE_M: f64 = 4.0;
const MAX_ARC_DEG: f64 = 5.0;

fn colour(ratio: f64, alpha: f64) -> Value {
    let t = ((ratio - 0.5) / 1.0).clamp(0.0, 1.0);
    json!({"r": t, "g": 0.2, "b": 1.0 - t, "a": alpha})
}

/// The `foxglove.SceneUpdate` JSON for one frame at `t_ns`, drawn in
/// `frame_id` (the cloud's frame, whose x axis is `sensor_yaw_deg`
/// counter-clockwise of the vehicle's).
#[must_use]
pub fn scene_update(
    profile: &Profile,
    state: State,
    t_ns: u64,
    frame_id: &str,
    sensor_yaw_deg: f64,
) -> String {
    let p_avg = profile.average_power_w;
    let spin_uniform = std::f64::consts::TAU * profile.frame_rate_hz;
    let mut points: Vec<Value> = Vec::new();
    let mut colors: Vec<Value> = Vec::new();
    let bins = &profile.bins;
    let mut i = 0;
    while i < bins.len() {
        // A run of equal power.
        let mut j = i + 1;
        while j < bins.len() && bins[j].power_w == bins[i].power_w {
            j += 1;
        }
        let start = bins[i].start_deg;
        let end = bins[j - 1].start_deg + bins[j - 1].width_deg;
        let ratio = if p_avg > 0.0 {
            bins[i].power_w / p_avg
        } else {
            1.0
        };
        let spin = 0.5 * (bins[i].spin_start_rad_s + bins[i].spin_end_rad_s);
        let alpha = if spin > 0.0 {
            (spin_uniform / spin).clamp(0.3, 1.0)
        } else {
            1.0
        };
        let r_out = R_IN_M + R_SCALE_M * ratio.max(0.0);
        let arcs = ((end - start) / MAX_ARC_DEG).ceil().max(1.0) as usize;
        let c = colour(ratio, alpha);
        for a in 0..arcs {
            let a0 = start + (end - start) * a as f64 / arcs as f64 - sensor_yaw_deg;
            let a1 = start + (end - start) * (a + 1) as f64 / arcs as f64 - sensor_yaw_deg;
            let at = |deg: f64, r: f64| {
                let (s, c) = deg.to_radians().sin_cos();
                json!({"x": r * c, "y": r * s, "z": 0.0})
            };
            let (p0, p1, p2, p3) = (at(a0, R_IN_M), at(a0, r_out), at(a1, r_out), at(a1, R_IN_M));
            for v in [p0.clone(), p1, p2.clone(), p0, p2, p3] {
                points.push(v);
                colors.push(c.clone());
            }
        }
        i = j;
    }
    let stamp = json!({"sec": t_ns / 1_000_000_000, "nsec": t_ns % 1_000_000_000});
    let pose = json!({"position": {"x": 0.0, "y": 0.0, "z": 0.0},
                      "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}});
    let label = match (state, profile.gaze_deg) {
        (State::Adaptive, Some(g)) => format!("adaptive, gaze {g:.1}°"),
        _ => "fail-safe (uniform baseline)".to_owned(),
    };
    json!({
        "deletions": [],
        "entities": [{
            "timestamp": stamp,
            "frame_id": frame_id,
            "id": "gaze_lidar/profile",
            "lifetime": {"sec": 0, "nsec": 0},
            "frame_locked": false,
            "metadata": [{"key": "state", "value": label.clone()}],
            "triangles": [{"pose": pose.clone(), "points": points, "color": colour(1.0, 1.0), "colors": colors, "indices": []}],
            "texts": [{"pose": {"position": {"x": 0.0, "y": 0.0, "z": 2.0},
                                "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}},
                       "billboard": true, "font_size": 14.0, "scale_invariant": true,
                       "color": {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0}, "text": label}]
        }]
    })
    .to_string()
}
