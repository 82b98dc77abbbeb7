//! The per-frame picture: a `visualization_msgs/msg/MarkerArray` (CDR)
//! drawing the profile as a flat ring around the sensor, in the cloud's
//! frame. Foxglove's 3D panel and RViz draw it; rosbags and
//! `mcap-ros2-support` decode it from the embedded `ros2msg` schema.
//!
//! Two markers in namespace `gaze_lidar`: id 0, a `TRIANGLE_LIST` with one
//! sector per run of bins of equal power (split into arcs of at most 5°); a
//! sector spans radii `1 m` to `1 m + 4 m · P/P̄` and is coloured from blue
//! (`P/P̄ ≤ 0.5`) to red (`P/P̄ ≥ 1.5`), its opacity `ω_c/ω` clamped to
//! `[0.3, 1]` (a slower spin, a denser scan, is drawn more opaque); id 1, a
//! `TEXT_VIEW_FACING` label 2 m above the sensor saying the state and the
//! gaze. The ids stay the same, so each frame replaces the last.

use super::cdr::{Header, Writer};
use crate::gaze::State;
use crate::profile::Profile;

const R_IN_M: f64 = 1.0;
const R_SCALE_M: f64 = 4.0;
const MAX_ARC_DEG: f64 = 5.0;
/// Height of the label's letters, m (`scale.z` of a text marker).
const TEXT_HEIGHT_M: f64 = 0.5;

/// `visualization_msgs/Marker` types and actions used.
const TEXT_VIEW_FACING: i32 = 9;
const TRIANGLE_LIST: i32 = 11;
const ADD: i32 = 0;

/// `std_msgs/ColorRGBA`.
type Rgba = [f32; 4];

fn colour(ratio: f64, alpha: f64) -> Rgba {
    let t = ((ratio - 0.5) / 1.0).clamp(0.0, 1.0);
    [t as f32, 0.2, (1.0 - t) as f32, alpha as f32]
}

/// One `visualization_msgs/Marker`, its pose the identity.
struct Marker<'a> {
    header: &'a Header<'a>,
    id: i32,
    kind: i32,
    position: [f64; 3],
    scale: [f64; 3],
    color: Rgba,
    points: &'a [[f64; 3]],
    colors: &'a [Rgba],
    text: &'a str,
}

impl Marker<'_> {
    fn write(&self, w: &mut Writer) {
        self.header.write(w);
        w.string("gaze_lidar");
        w.i32(self.id);
        w.i32(self.kind);
        w.i32(ADD);
        for v in self.position {
            w.f64(v);
        }
        for v in [0.0, 0.0, 0.0, 1.0] {
            w.f64(v);
        }
        for v in self.scale {
            w.f64(v);
        }
        for v in self.color {
            w.f32(v);
        }
        // lifetime 0: until replaced.
        w.i32(0);
        w.u32(0);
        w.u8(0); // frame_locked
        w.u32(u32::try_from(self.points.len()).unwrap_or(u32::MAX));
        for p in self.points {
            for v in p {
                w.f64(*v);
            }
        }
        w.u32(u32::try_from(self.colors.len()).unwrap_or(u32::MAX));
        for c in self.colors {
            for v in c {
                w.f32(*v);
            }
        }
        w.string(self.text);
        w.string(""); // mesh_resource
        w.u8(0); // mesh_use_embedded_materials
    }
}

/// The label of a frame.
#[must_use]
pub fn label(profile: &Profile, state: State) -> String {
    match (state, profile.gaze_deg) {
        (State::Adaptive, Some(g)) => format!("adaptive, gaze {g:.1}°"),
        _ => "fail-safe (uniform baseline)".to_owned(),
    }
}

/// `t_ns` as `builtin_interfaces/Time` (sec, nanosec). Stamps past 2038
/// saturate, both fields together, to the last nanosecond the message
/// holds (its `sec` is an i32).
#[must_use]
pub fn ros_time(t_ns: u64) -> (i32, u32) {
    match i32::try_from(t_ns / 1_000_000_000) {
        Ok(sec) => (sec, (t_ns % 1_000_000_000) as u32),
        Err(_) => (i32::MAX, 999_999_999),
    }
}

/// The `visualization_msgs/msg/MarkerArray` (CDR) for one frame at `t_ns`,
/// drawn in `frame_id` (the cloud's frame, whose x axis is
/// `sensor_yaw_deg` counter-clockwise of the vehicle's).
#[must_use]
pub fn scene_update(
    profile: &Profile,
    state: State,
    t_ns: u64,
    frame_id: &str,
    sensor_yaw_deg: f64,
) -> Vec<u8> {
    let p_avg = profile.average_power_w;
    let spin_uniform = std::f64::consts::TAU * profile.frame_rate_hz;
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut colors: Vec<Rgba> = Vec::new();
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
                [r * c, r * s, 0.0]
            };
            let (p0, p1, p2, p3) = (at(a0, R_IN_M), at(a0, r_out), at(a1, r_out), at(a1, R_IN_M));
            for v in [p0, p1, p2, p0, p2, p3] {
                points.push(v);
                colors.push(c);
            }
        }
        i = j;
    }
    let (sec, nanosec) = ros_time(t_ns);
    let header = Header {
        sec,
        nanosec,
        frame_id,
    };
    let text = label(profile, state);
    let mut w = Writer::new(points.len() * 40 + 512);
    w.u32(2);
    Marker {
        header: &header,
        id: 0,
        kind: TRIANGLE_LIST,
        position: [0.0; 3],
        scale: [1.0; 3],
        color: colour(1.0, 1.0),
        points: &points,
        colors: &colors,
        text: "",
    }
    .write(&mut w);
    Marker {
        header: &header,
        id: 1,
        kind: TEXT_VIEW_FACING,
        position: [0.0, 0.0, 2.0],
        scale: [0.0, 0.0, TEXT_HEIGHT_M],
        color: [1.0; 4],
        points: &[],
        colors: &[],
        text: &text,
    }
    .write(&mut w);
    w.finish()
}
