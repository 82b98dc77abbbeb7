//! `gaze-lidar replay`: a rosbag2 MCAP through the gaze pipeline, written
//! back as an MCAP with the adapted clouds, the profiles and a Foxglove
//! picture (see [`gaze_lidar::replay`]).
//!
//! The output is written to a temporary file beside `--out` and renamed
//! over it only when the whole replay succeeded: a failure leaves any old
//! `--out` as it was and no partial file.

use std::path::PathBuf;

use gaze_lidar::replay::{
    reorder_window_ns, replay_file_staged, replay_file_to, Compression, GazeKind, ReplayError,
    ReplayOptions, Staging,
};
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
    /// Zstandard chunks.
    Zstd,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The input bag (a rosbag2 MCAP file: uncompressed, LZ4 or zstd chunks).
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
    /// Output MCAP (replaced only when the replay succeeds); `-`: stdout
    /// (the whole file, written once the replay succeeded).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    plan: PlanArgs,
    /// The cloud frame's x axis, degrees counter-clockwise (ISO 8855) from
    /// the vehicle's: a point at azimuth β in the cloud is at β + yaw in the
    /// vehicle frame of the gaze and the profile. Given, it wins over the
    /// bag; else the yaw comes from the static transforms on --tf-topic
    /// between the cloud's header.frame_id and --vehicle-frame (none when
    /// the frames are the same or no transform links them).
    #[arg(long, allow_hyphen_values = true)]
    sensor_yaw_deg: Option<f64>,
    /// The vehicle frame (of the gaze and the profile) in the bag's transforms.
    #[arg(long, default_value = "base_link")]
    vehicle_frame: String,
    /// Topic of the static transforms (tf2_msgs/msg/TFMessage).
    #[arg(long, default_value = "/tf_static")]
    tf_topic: String,
    /// Largest roll/pitch tilt of the cloud frame in a transform from the
    /// bag, degrees (beyond it the replay stops: the mounting is a yaw).
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    max_mount_tilt_deg: f64,
    /// Range of the uniform baseline on the reference target in clear air, m
    /// [default: the preset's rated range].
    #[arg(long, allow_hyphen_values = true)]
    rated_range_m: Option<f64>,
    /// Return model that turns power into range.
    #[arg(long, value_parser = super::args::named::<ModelKind>(), default_value_t = ModelKind::Physical)]
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
    /// Topic of the per-frame profile@1 documents (JSON in a std_msgs/msg/String).
    #[arg(long, default_value = "/gaze_lidar/profile")]
    profile_topic: String,
    /// Topic of the per-frame picture (visualization_msgs/msg/MarkerArray).
    #[arg(long, default_value = "/gaze_lidar/scene")]
    scene_topic: String,
    /// Output chunk compression.
    #[arg(long, value_enum, default_value_t = CompressionArg::None)]
    compression: CompressionArg,
}

/// [`gaze_lidar::replay::MAX_BINS`], as `--bins` is read.
pub const MAX_REPLAY_BINS: i64 = gaze_lidar::replay::MAX_BINS as i64;

fn replay_error(e: ReplayError) -> CliError {
    // An option is named by its flag.
    if let ReplayError::Config { field, reason } = &e {
        return CliError::input(format!("--{}: {reason}", field.replace('_', "-")));
    }
    if let ReplayError::MountTilt {
        topic,
        reason,
        met_at,
    } = &e
    {
        return CliError::input(format!(
            "{topic}: {reason} (give the yaw with --sensor-yaw-deg to use it anyway){met_at}"
        ));
    }
    if e.is_input_error() {
        CliError::input(e.to_string())
    } else {
        CliError::output(e.to_string())
    }
}

/// On every catchable signal whose default action ends the process (INT,
/// TERM, HUP, QUIT, USR1, USR2, ALRM, XFSZ, XCPU, VTALRM, PROF, IO, SYS), a
/// thread removes the temporary output file named in the returned
/// [`Staging`] (if any) and exits 128 + the signal (130 for INT, 143 for
/// TERM, 138 for USR1), as a shell reports a process the signal ended. PIPE
/// is ignored (a closed stdout is a write error); TRAP is left to debuggers;
/// a signal ignored at start stays ignored. (Devices, FIFOs and
/// stdout are staged in an anonymous temporary file, which the system
/// removes with the process.)
fn remove_on_signal() -> Result<&'static Staging, CliError> {
    use signal_hook::consts::signal::{
        SIGALRM, SIGHUP, SIGINT, SIGIO, SIGPROF, SIGQUIT, SIGSYS, SIGTERM, SIGUSR1, SIGUSR2,
        SIGVTALRM, SIGXCPU, SIGXFSZ,
    };
    static STAGING: Staging = std::sync::Mutex::new(None);
    // A signal ignored when the program started stays ignored (as `nohup`
    // and a shell's `trap '' XFSZ` mean it: with XFSZ ignored, a write past
    // the file-size limit fails and is reported as a failed write).
    let ignored = ignored_signals();
    let wanted = [
        SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGXFSZ, SIGXCPU, SIGVTALRM,
        SIGPROF, SIGIO, SIGSYS,
    ]
    .into_iter()
    .filter(|&s| (1..=64).contains(&s) && ignored & (1u64 << (s - 1)) == 0);
    let mut signals = signal_hook::iterator::Signals::new(wanted)
        .map_err(|e| CliError::output(format!("installing the signal handler: {e}")))?;
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            let staged = STAGING
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            if let Some(path) = staged.as_ref() {
                let _ = std::fs::remove_file(path);
            }
            std::process::exit(128 + sig);
        }
    });
    Ok(&STAGING)
}

/// The signals this process ignores (bit n-1 for signal n), from the
/// `SigIgn` mask in `/proc/self/status`; none where that cannot be read.
fn ignored_signals() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("SigIgn:"))
                .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
        })
        .unwrap_or(0)
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let pipeline = a.filter.settings()?;
    let window_ns = reorder_window_ns(a.reorder_window_ms).map_err(replay_error)?;
    if let Some(b) = a.plan.bins.filter(|&b| b > MAX_REPLAY_BINS) {
        return Err(CliError::input(format!(
            "--bins: {b} is more than replay's {MAX_REPLAY_BINS} (each frame's profile is written to the output, ~240 bytes per bin)"
        )));
    }
    if let Some(config) = &a.plan.config {
        std::fs::metadata(config)
            .map_err(|e| CliError::input(format!("--config: {}: {e}", config.display())))?;
    }
    let (planner, preset_range_m) = a.plan.planner()?;
    let rated_range_m = match a.rated_range_m {
        // (0, 10⁷] as the library and the README have it: 10⁷ itself is fine.
        Some(r) if r == 1e7 => r,
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
    opts.vehicle_frame.clone_from(&a.vehicle_frame);
    opts.tf_topic.clone_from(&a.tf_topic);
    opts.max_mount_tilt_deg = a.max_mount_tilt_deg;
    opts.cloud.model = a.model;
    opts.cloud.fog_mor_m = a.fog_mor_m;
    opts.cloud.seed = a.seed;
    opts.cloud.cloud_spin_rad_s = a.cloud_spin_rad_s;
    opts.reorder_window_ns = window_ns;
    opts.compression = match a.compression {
        CompressionArg::None => Compression::None,
        CompressionArg::Lz4 => Compression::Lz4,
        CompressionArg::Zstd => Compression::Zstd,
    };

    if let Some(config) = &a.plan.config {
        if gaze_lidar::replay::same_file(config, &a.out) {
            return Err(CliError::input(format!(
                "--out: {} is the --config file",
                a.out.display()
            )));
        }
    }
    // Every option checked before anything is read.
    opts.validate().map_err(replay_error)?;
    // `/dev/stdout` (and fd 1's other names) is stdout, whatever it is (a
    // pipe's link names nothing a path can reach).
    let to_stdout = ["-", "/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"]
        .iter()
        .any(|s| a.out.as_os_str() == *s);
    let stats = if to_stdout {
        replay_file_to(&a.input, std::io::stdout().lock(), planner, pipeline, &opts)
    } else {
        let staging = remove_on_signal()?;
        replay_file_staged(&a.input, &a.out, planner, pipeline, &opts, staging)
    }
    .map_err(replay_error)?;
    let s = stats.stream;
    if stats.late_gaze > 0 || stats.late_clouds > 0 {
        super::io::warn(format!(
            "warning: messages more than --reorder-window-ms ({2} ms) behind newer ones in the file's record order: {0} gaze sample(s) dropped, {1} cloud(s) outside the remembered frames given the baseline (the data section is read in record order; sort the bag by log_time or widen the window)",
            stats.late_gaze, stats.late_clouds, a.reorder_window_ms
        ));
    }
    if let Some(frame) = &stats.gaze_frame_without_tf {
        super::io::warn(format!(
            "warning: {} gaze vector(s) in frame {frame:?} (the first such frame), which no transform on {} links to the vehicle frame {:?}: used as if in the vehicle frame",
            stats.gaze_without_tf, a.tf_topic, a.vehicle_frame
        ));
    }
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
    if stats.clouds_without_tf > 0 {
        super::io::warn(format!(
            "warning: {} clouds not in the vehicle frame {:?} and not linked to it by a transform on {}: no mounting yaw applied (give --sensor-yaw-deg)",
            stats.clouds_without_tf, a.vehicle_frame, a.tf_topic
        ));
    }
    if stats.plan_fallbacks > 0 {
        super::io::warn(format!(
            "warning: {} frame(s) had no certified adaptive profile for their gaze and ran the baseline instead (fail-safe; `stream` names each)",
            stats.plan_fallbacks
        ));
    }
    if stats.resyncs > 0 {
        super::io::warn(format!(
            "warning: the gaze clock jumped or ran backwards {} time(s): one fail-safe frame each, frame clock restarted, gaze history discarded",
            stats.resyncs
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
