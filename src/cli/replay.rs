//! `gaze-lidar replay`: a rosbag2 MCAP through the gaze pipeline, written
//! back as an MCAP with the adapted clouds, the profiles and a Foxglove
//! picture (see [`gaze_lidar::replay`]).
//!
//! The output is written to a temporary file beside `--out` and renamed
//! over it only when the whole replay succeeded: a failure leaves any old
//! `--out` as it was and no partial file.

use std::path::{Path, PathBuf};

use gaze_lidar::replay::{replay, Compression, GazeKind, ReplayError, ReplayOptions};
use gaze_lidar::sim::returns::ModelKind;

use super::args::finite_between;
use super::gaze_args::{FilterArgs, PlanArgs};
use super::CliError;

/// Output chunk compression.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CompressionArg {
    /// Uncompressed chunks.
    None,
    /// LZ4 chunks.
    Lz4,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input bag (a rosbag2 MCAP file: uncompressed or LZ4 chunks).
    input: PathBuf,
    /// Gaze topic: geometry_msgs/msg/Vector3Stamped, the gaze direction in
    /// the vehicle frame (ISO 8855: x forward, y left, z up; azimuth
    /// atan2(y, x)); with --gaze-yaw-deg, std_msgs/msg/Float64 yaw in degrees.
    #[arg(long)]
    gaze_topic: String,
    /// The gaze topic is std_msgs/msg/Float64: the gaze yaw, degrees
    /// counter-clockwise from straight ahead.
    #[arg(long)]
    gaze_yaw_deg: bool,
    /// Cloud topic: sensor_msgs/msg/PointCloud2 (x, y, z FLOAT32 or FLOAT64).
    #[arg(long)]
    cloud_topic: String,
    /// Output MCAP (replaced only when the replay succeeds).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    plan: PlanArgs,
    /// The cloud frame's x axis, degrees counter-clockwise (ISO 8855) from
    /// the vehicle's: a point at azimuth β in the cloud is at β + yaw in the
    /// vehicle frame of the gaze and the profile.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    sensor_yaw_deg: f64,
    /// Range of the uniform baseline on the reference target in clear air, m
    /// [default: the preset's rated range].
    #[arg(long, allow_hyphen_values = true)]
    rated_range_m: Option<f64>,
    /// Return model that turns power into range.
    #[arg(long, value_enum, default_value_t = ModelKind::Physical)]
    model: ModelKind,
    /// Fog as a meteorological optical range, m (default clear air).
    #[arg(long, allow_hyphen_values = true)]
    fog_mor_m: Option<f64>,
    /// Seed of the density thinning; cloud k (from 0) uses seed + k.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Spin the clouds were recorded at, rad/s [default: the profile's
    /// uniform spin, 2π × frame rate].
    #[arg(long, allow_hyphen_values = true)]
    cloud_spin_rad_s: Option<f64>,
    #[command(flatten)]
    filter: FilterArgs,
    /// Messages are put in log-time order within this window, ms (0..=60000).
    #[arg(long, default_value_t = 200.0, allow_hyphen_values = true)]
    reorder_window_ms: f64,
    /// Topic of the adapted clouds [default: <cloud-topic>/adapted].
    #[arg(long)]
    adapted_topic: Option<String>,
    /// Topic of the per-frame profile@1 documents (JSON).
    #[arg(long, default_value = "/gaze_lidar/profile")]
    profile_topic: String,
    /// Topic of the per-frame foxglove.SceneUpdate picture (JSON).
    #[arg(long, default_value = "/gaze_lidar/scene")]
    scene_topic: String,
    /// Output chunk compression.
    #[arg(long, value_enum, default_value_t = CompressionArg::None)]
    compression: CompressionArg,
}

fn replay_error(e: ReplayError) -> CliError {
    if e.is_input_error() {
        CliError::input(e.to_string())
    } else {
        CliError::output(e.to_string())
    }
}

/// Same file (device and inode) — `--out` must not be the input.
fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let pipeline = a.filter.settings()?;
    if !(a.reorder_window_ms.is_finite() && (0.0..=60_000.0).contains(&a.reorder_window_ms)) {
        return Err(CliError::input(format!(
            "--reorder-window-ms: {} must lie in 0..=60000",
            a.reorder_window_ms
        )));
    }
    if !a.sensor_yaw_deg.is_finite() {
        return Err(CliError::input(format!(
            "--sensor-yaw-deg: {} is not a finite angle",
            a.sensor_yaw_deg
        )));
    }
    let (planner, preset_range_m) = a.plan.planner()?;
    let rated_range_m = match a.rated_range_m {
        Some(r) => finite_between("--rated-range-m", r, 0.0, 1e7)?,
        None => preset_range_m,
    };
    let mut opts = ReplayOptions::new(&a.gaze_topic, &a.cloud_topic, rated_range_m);
    if a.gaze_yaw_deg {
        opts.gaze_kind = GazeKind::YawDeg;
    }
    if let Some(t) = &a.adapted_topic {
        opts.adapted_topic.clone_from(t);
    }
    opts.profile_topic.clone_from(&a.profile_topic);
    opts.scene_topic.clone_from(&a.scene_topic);
    opts.sensor_yaw_deg = a.sensor_yaw_deg;
    opts.cloud.model = a.model;
    opts.cloud.fog_mor_m = a.fog_mor_m;
    opts.cloud.seed = a.seed;
    opts.cloud.cloud_spin_rad_s = a.cloud_spin_rad_s;
    opts.reorder_window_ns = (a.reorder_window_ms * 1e6).round() as u64;
    opts.compression = match a.compression {
        CompressionArg::None => Compression::None,
        CompressionArg::Lz4 => Compression::Lz4,
    };

    let input = std::fs::File::open(&a.input)
        .map_err(|e| CliError::input(format!("{}: {e}", a.input.display())))?;
    if same_file(&a.input, &a.out) {
        return Err(CliError::input(format!(
            "--out {}: is the input file",
            a.out.display()
        )));
    }
    if a.out.is_dir() {
        return Err(CliError::input(format!(
            "--out {}: is a directory",
            a.out.display()
        )));
    }
    let dir = match a.out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".gaze-lidar-replay.");
    // An ordinary output file (tempfile's default is 0600); an existing one
    // keeps its mode.
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&a.out)
            .map(|m| m.permissions().mode() & 0o7777)
            .unwrap_or(0o644);
        builder.permissions(std::fs::Permissions::from_mode(mode));
    }
    let tmp = builder
        .tempfile_in(&dir)
        .map_err(|e| CliError::input(format!("--out {}: {e}", a.out.display())))?;
    let origin = a.input.display().to_string();
    let reader = std::io::BufReader::with_capacity(1 << 20, input);
    let writer = std::io::BufWriter::with_capacity(1 << 20, tmp);
    let mut writer = writer;
    let stats =
        replay(reader, &origin, &mut writer, planner, pipeline, &opts).map_err(replay_error)?;
    let tmp = writer
        .into_inner()
        .map_err(|e| CliError::output(format!("--out {}: {}", a.out.display(), e.error())))?;
    tmp.as_file()
        .sync_all()
        .map_err(|e| CliError::output(format!("--out {}: {e}", a.out.display())))?;
    tmp.persist(&a.out)
        .map_err(|e| CliError::output(format!("--out {}: {}", a.out.display(), e.error)))?;
    let s = stats.stream;
    if s.samples == 0 {
        super::io::warn(format!(
            "warning: no message on the gaze topic {}: every frame is fail-safe (the uniform baseline)",
            a.gaze_topic
        ));
    }
    if stats.clouds == 0 {
        super::io::warn(format!(
            "warning: no message on the cloud topic {}: no adapted cloud written",
            a.cloud_topic
        ));
    }
    super::io::warn(format!(
        "{} messages, {} clouds ({} of {} points kept), {} gaze samples ({} invalid, {} outliers, {} late) → {} frames, {} in fail-safe{}",
        stats.messages,
        stats.clouds,
        stats.points_kept,
        stats.points_in,
        s.samples,
        s.invalid,
        s.outliers,
        stats.late_gaze,
        s.frames,
        s.fail_safe_frames,
        if stats.late_clouds > 0 {
            format!(", {} late clouds given the baseline", stats.late_clouds)
        } else {
            String::new()
        }
    ));
    Ok(0)
}
