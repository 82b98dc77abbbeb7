//! `gaze_lidar.replay`: a rosbag2 MCAP replayed through the gaze pipeline,
//! by the same Rust code as `gaze-lidar replay`
//! ([`gaze_lidar::replay::replay_file`]), with the CLI's options.

use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use gaze_lidar::pipeline::PipelineOptions;
use gaze_lidar::replay::{
    reorder_window_ns, replay_file, Compression, GazeKind, ReplayError, ReplayOptions, MAX_BINS,
};

use super::{
    detached, frame_planner, guard, mode_of, model_of, pipeline_error, seed_of, value_error,
};

fn replay_error(py: Python<'_>, e: ReplayError) -> PyErr {
    match e {
        // Options are named by their keyword.
        ReplayError::Config {
            field: "out",
            reason,
        } => value_error(format!("out_path: {reason}")),
        ReplayError::MountTilt {
            topic,
            reason,
            met_at,
        } => value_error(format!(
            "{topic}: {reason} (give the yaw as sensor_yaw_deg to use it anyway){met_at}"
        )),
        ReplayError::Pipeline(g) => pipeline_error(py, g),
        ReplayError::Write(_) => PyOSError::new_err(e.to_string()),
        e => value_error(e.to_string()),
    }
}

/// `lo < v < hi`, `v` finite and not subnormal (the one numeric boundary).
fn in_range(field: &str, v: f64, lo: f64, hi: f64) -> PyResult<f64> {
    if gaze_lidar::model::valid::finite(v).is_ok() && v > lo && v < hi {
        Ok(v)
    } else {
        Err(value_error(format!(
            "{field}: {v} must be finite (not subnormal), > {lo} and < {hi}"
        )))
    }
}

/// Replays the ROS 2 bag (MCAP) at in_path through the gaze pipeline and
/// writes out_path: every input message copied, one adapted cloud per
/// cloud on adapted_topic (default cloud_topic + "/adapted"), one
/// profile@1 document per frame on profile_topic (std_msgs/msg/String) and
/// a visualization_msgs/msg/MarkerArray per frame on scene_topic (the options and rules of `gaze-lidar replay`;
/// out_path is replaced only when the replay succeeds; input messages keep
/// their sequence numbers, attachments and metadata are copied). Returns
/// the counters (messages, clouds, points_in, points_kept, attachments,
/// metadata, frames, …).
///
/// Raises ValueError for a bad option or a bad bag (truncated, corrupt,
/// wrong topic type: the message names the byte offset or the field),
/// Infeasible when the planner cannot meet the request, OSError when the
/// output cannot be written. Runs with the GIL released: bags may be
/// replayed from several threads at once.
#[pyfunction]
#[pyo3(signature = (
    in_path, out_path, *, gaze_topic, cloud_topic, preset="paper", mode="range", bins=360,
    config_toml=None, gaze_yaw_deg=false, sensor_yaw_deg=None, vehicle_frame="base_link",
    tf_topic="/tf_static", max_mount_tilt_deg=5.0, rated_range_m=None, model="physical",
    fog_mor_m=None, seed=0, cloud_spin_rad_s=None, timeout_ms=100.0, recover_samples=4,
    saccade_deg_s=30.0, max_gap_frames=200, reorder_window_ms=200.0, adapted_topic=None,
    profile_topic="/gaze_lidar/profile", scene_topic="/gaze_lidar/scene", compression="none"
))]
#[allow(clippy::too_many_arguments)]
pub fn replay<'py>(
    py: Python<'py>,
    in_path: std::path::PathBuf,
    out_path: std::path::PathBuf,
    gaze_topic: &str,
    cloud_topic: &str,
    preset: &str,
    mode: &str,
    bins: i64,
    config_toml: Option<&str>,
    gaze_yaw_deg: bool,
    sensor_yaw_deg: Option<f64>,
    vehicle_frame: &str,
    tf_topic: &str,
    max_mount_tilt_deg: f64,
    rated_range_m: Option<f64>,
    model: &str,
    fog_mor_m: Option<f64>,
    seed: i128,
    cloud_spin_rad_s: Option<f64>,
    timeout_ms: f64,
    recover_samples: i64,
    saccade_deg_s: f64,
    max_gap_frames: i64,
    reorder_window_ms: f64,
    adapted_topic: Option<&str>,
    profile_topic: &str,
    scene_topic: &str,
    compression: &str,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let mode = mode_of(mode)?;
        let (planner, preset_range_m) = frame_planner(
            py,
            preset,
            mode,
            bins,
            MAX_BINS,
            " for replay (each frame's profile is written to the output, ~240 bytes per bin)",
            config_toml,
        )?;
        let pipeline = PipelineOptions {
            timeout_ms,
            saccade_deg_s,
            recover_samples,
            max_gap_frames,
        }
        .config()
        .map_err(|e| pipeline_error(py, e))?;
        let window_ns = reorder_window_ns(reorder_window_ms).map_err(|e| replay_error(py, e))?;
        let rated_range_m = match rated_range_m {
            Some(r) => in_range("rated_range_m", r, 0.0, 1e7)?,
            None => preset_range_m,
        };
        let mut opts = ReplayOptions::new(gaze_topic, cloud_topic, rated_range_m);
        if gaze_yaw_deg {
            opts.gaze_kind = GazeKind::YawDeg;
        }
        if let Some(t) = adapted_topic {
            t.clone_into(&mut opts.adapted_topic);
        }
        profile_topic.clone_into(&mut opts.profile_topic);
        scene_topic.clone_into(&mut opts.scene_topic);
        opts.sensor_yaw_deg = sensor_yaw_deg;
        vehicle_frame.clone_into(&mut opts.vehicle_frame);
        tf_topic.clone_into(&mut opts.tf_topic);
        opts.max_mount_tilt_deg = max_mount_tilt_deg;
        opts.cloud.model = model_of(model)?;
        opts.cloud.fog_mor_m = fog_mor_m;
        opts.cloud.seed = seed_of(seed)?;
        opts.cloud.cloud_spin_rad_s = cloud_spin_rad_s;
        opts.reorder_window_ns = window_ns;
        opts.compression = match compression {
            "none" => Compression::None,
            "lz4" => Compression::Lz4,
            "zstd" => Compression::Zstd,
            other => {
                return Err(value_error(format!(
                    "compression: '{other}' is not one of none, lz4, zstd"
                )))
            }
        };
        opts.validate().map_err(|e| replay_error(py, e))?;
        let stats = detached(py, || {
            replay_file(&in_path, &out_path, planner, pipeline, &opts)
        })?
        .map_err(|e| replay_error(py, e))?;
        let d = PyDict::new(py);
        d.set_item("messages", stats.messages)?;
        d.set_item("clouds", stats.clouds)?;
        d.set_item("points_in", stats.points_in)?;
        d.set_item("points_kept", stats.points_kept)?;
        d.set_item("late_clouds", stats.late_clouds)?;
        d.set_item("late_gaze", stats.late_gaze)?;
        d.set_item("clouds_without_tf", stats.clouds_without_tf)?;
        d.set_item("transforms", stats.transforms)?;
        d.set_item("attachments", stats.attachments)?;
        d.set_item("metadata", stats.metadata)?;
        d.set_item("plan_fallbacks", stats.plan_fallbacks)?;
        d.set_item("resyncs", stats.resyncs)?;
        let s = stats.stream;
        d.set_item("samples", s.samples)?;
        d.set_item("invalid", s.invalid)?;
        d.set_item("outliers", s.outliers)?;
        d.set_item("frames", s.frames)?;
        d.set_item("fail_safe_frames", s.fail_safe_frames)?;
        Ok(d)
    })
}
