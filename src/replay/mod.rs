//! Recorded drives: a ROS 2 bag (rosbag2's MCAP storage) replayed through
//! the gaze pipeline, written back as what the adaptive sensor would have
//! returned.
//!
//! [`replay`] reads an MCAP file as a stream (the `mcap` crate's sans-io
//! [`MessageReader`](mcap::sans_io::MessageReader): one chunk in memory at
//! a time), and for each message in log-time order (within a reorder
//! window, [`ReplayOptions::reorder_window_ns`]):
//!
//! - **gaze** (`--gaze-topic`): a `geometry_msgs/msg/Vector3Stamped` is the
//!   gaze direction in the vehicle frame (ISO 8855: x forward, y left, z up),
//!   azimuth `atan2(y, x)`; a vector with a zero or non-finite horizontal
//!   part is an invalid sample. Or a `std_msgs/msg/Float64`, the gaze yaw in
//!   degrees (counter-clockwise from ahead, [`GazeKind::YawDeg`]). Each
//!   sample goes through the same [`GazeStream`] as `gaze-lidar stream`
//!   (filter, fail-safe, certified planner), on the bag's clock: the
//!   message's `log_time`.
//! - **cloud** (`--cloud-topic`): a `sensor_msgs/msg/PointCloud2` with x, y,
//!   z as FLOAT32 or FLOAT64 at any offset, any point step and row step,
//!   either byte order. The frame clock is run up to the cloud's
//!   `log_time` (fail-safe frames through a gaze gap, as `stream` does);
//!   the profile of the frame running at that time is applied to the cloud
//!   by [`crate::pointcloud::keep_mask`] (frame ISO 8855, as ROS's REP 103;
//!   the cloud turned by its mounting yaw into the vehicle frame first:
//!   [`ReplayOptions::sensor_yaw_deg`] when given, else the static
//!   transforms read so far on `/tf_static` ([`tf`]), else none). Non-finite points (allowed when `is_dense` is false) are
//!   never returned and are not passed to the rule. The `k`-th cloud (from
//!   0) is thinned with seed `seed + k` (wrapping).
//! - every message is copied to the output unchanged, on its own topic.
//!
//! The output adds, with their schemas embedded: the adapted cloud (the kept
//! points' bytes, same header, fields and point step, one row) on
//! [`ReplayOptions::adapted_topic`]; one `gaze-lidar/profile@1` JSON
//! document per frame on [`ReplayOptions::profile_topic`] (`log_time` the
//! frame start); and a `foxglove.SceneUpdate` (JSON) per frame on
//! [`ReplayOptions::scene_topic`]: a ring around the sensor, one sector per
//! run of equal power, coloured and sized by `P/P̄`, drawn in the cloud's
//! frame.

pub mod cdr;
pub mod scene;
pub mod schemas;
pub mod tf;

use std::collections::{BTreeMap, BinaryHeap, HashMap, VecDeque};
use std::io::{Read, Seek, Write};

use mcap::records::MessageHeader;
use mcap::sans_io::{LinearReaderOptions, MessageReadEvent, MessageReader};
use thiserror::Error;

use crate::checker::CertifiedProfile;
use crate::gaze::{Frame, FramePlanner, GazeError, GazeSample, GazeStream, State, StreamStats};
use crate::pointcloud::{keep_mask, CloudError, CloudFrame, CloudOptions};

/// Why a replay stopped.
#[derive(Debug, Error)]
pub enum ReplayError {
    /// The input is not a readable MCAP file (truncated, corrupt).
    #[error("{path}: not a readable MCAP file at byte {offset}: {reason}")]
    Mcap {
        /// Input file.
        path: String,
        /// Bytes of the file read when the error was found (the bad record
        /// ends at or before it; for a truncated file, the file's length).
        offset: u64,
        /// The mcap crate's error.
        reason: String,
    },
    /// A message on the gaze or cloud topic could not be decoded.
    #[error("{field}: {reason}")]
    Message {
        /// Field (`header.frame_id`, `fields`, …), prefixed by the topic and
        /// message once known.
        field: String,
        /// What is wrong.
        reason: String,
    },
    /// A topic named in the options has another type than expected.
    #[error("{topic}: {reason}")]
    Topic {
        /// The topic.
        topic: String,
        /// What is wrong.
        reason: String,
    },
    /// An option is out of range.
    #[error("{field}: {reason}")]
    Config {
        /// The option.
        field: &'static str,
        /// Why.
        reason: String,
    },
    /// The gaze pipeline failed (planner).
    #[error("{0}")]
    Gaze(#[from] GazeError),
    /// Applying a profile to a cloud failed.
    #[error("{0}")]
    Cloud(#[from] CloudError),
    /// Reading the input failed.
    #[error("{path}: {source}")]
    Read {
        /// Input file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// Writing the output failed.
    #[error("output: {0}")]
    Write(String),
}

impl ReplayError {
    /// Bad input (exit 2) rather than an infeasible request or an output
    /// failure (exit 1).
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        match self {
            Self::Mcap { .. }
            | Self::Message { .. }
            | Self::Topic { .. }
            | Self::Config { .. }
            | Self::Read { .. }
            | Self::Cloud(_) => true,
            Self::Gaze(e) => e.is_input_error(),
            Self::Write(_) => false,
        }
    }
}

fn write_err(e: impl std::fmt::Display) -> ReplayError {
    ReplayError::Write(e.to_string())
}

/// The gaze topic's message type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GazeKind {
    /// `geometry_msgs/msg/Vector3Stamped`: the gaze direction (vehicle frame).
    Vector3,
    /// `std_msgs/msg/Float64`: the gaze yaw, degrees counter-clockwise from ahead.
    YawDeg,
}

/// Output compression of the MCAP chunks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// None (the default, as rosbag2 records).
    None,
    /// LZ4.
    Lz4,
    /// Zstandard.
    Zstd,
}

/// What to replay and how.
#[derive(Debug, Clone)]
pub struct ReplayOptions {
    /// Topic of the gaze messages.
    pub gaze_topic: String,
    /// Their type.
    pub gaze_kind: GazeKind,
    /// Topic of the input clouds.
    pub cloud_topic: String,
    /// Topic of the adapted clouds (default: the cloud topic + `/adapted`).
    pub adapted_topic: String,
    /// Topic of the per-frame profile@1 documents.
    pub profile_topic: String,
    /// Topic of the per-frame `foxglove.SceneUpdate` picture.
    pub scene_topic: String,
    /// The cloud frame's x axis, degrees counter-clockwise (ISO 8855) from
    /// the vehicle's: a point at azimuth β in the cloud is at β + yaw in
    /// the vehicle frame the gaze and the profile are in. `None`: read
    /// from the static transforms on [`ReplayOptions::tf_topic`] between
    /// the cloud's `header.frame_id` and [`ReplayOptions::vehicle_frame`]
    /// (no yaw when the two frames are the same, or when no transform
    /// links them: [`ReplayStats::clouds_without_tf`]). `Some` wins over
    /// the bag's transforms.
    pub sensor_yaw_deg: Option<f64>,
    /// The vehicle frame (the gaze's and the profile's), for the transforms.
    pub vehicle_frame: String,
    /// Topic of the static transforms (`tf2_msgs/msg/TFMessage`).
    pub tf_topic: String,
    /// Largest tilt of the cloud frame's z axis from the vehicle's (roll
    /// and pitch together) in a transform from the bag, degrees: beyond it
    /// the yaw-only mounting model does not hold and the replay stops.
    pub max_mount_tilt_deg: f64,
    /// How a profile is applied to a cloud (`frame` is ignored: ROS clouds
    /// are ISO 8855, REP 103).
    pub cloud: CloudOptions,
    /// Messages are processed in `log_time` order once they are this much
    /// older than the newest message read, ns; a message later than that is
    /// processed late (a late gaze sample is dropped, a late cloud gets the
    /// profile of the frame it fell in, or the baseline).
    pub reorder_window_ns: u64,
    /// Output compression.
    pub compression: Compression,
}

impl ReplayOptions {
    /// Defaults for the two topics: Vector3Stamped gaze, `<cloud>/adapted`,
    /// `/gaze_lidar/profile`, `/gaze_lidar/scene`, no mounting yaw, the
    /// physical return model at `rated_range_m`, seed 0, a 200 ms reorder
    /// window, uncompressed chunks; the mounting yaw from `/tf_static`
    /// to `base_link`, at most 5° of tilt.
    #[must_use]
    pub fn new(gaze_topic: &str, cloud_topic: &str, rated_range_m: f64) -> Self {
        let mut cloud = CloudOptions::new(rated_range_m);
        cloud.frame = CloudFrame::Iso8855;
        Self {
            gaze_topic: gaze_topic.to_owned(),
            gaze_kind: GazeKind::Vector3,
            cloud_topic: cloud_topic.to_owned(),
            adapted_topic: format!("{cloud_topic}/adapted"),
            profile_topic: "/gaze_lidar/profile".to_owned(),
            scene_topic: "/gaze_lidar/scene".to_owned(),
            sensor_yaw_deg: None,
            vehicle_frame: "base_link".to_owned(),
            tf_topic: "/tf_static".to_owned(),
            max_mount_tilt_deg: 5.0,
            cloud,
            reorder_window_ns: 200_000_000,
            compression: Compression::None,
        }
    }
}

pub use crate::gaze::PipelineConfig;

/// What a replay did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ReplayStats {
    /// Messages read (all topics).
    pub messages: u64,
    /// Clouds adapted.
    pub clouds: u64,
    /// Points in them (finite and non-finite).
    pub points_in: u64,
    /// Points kept.
    pub points_kept: u64,
    /// Clouds that arrived after the reorder window, outside every
    /// remembered frame: the baseline was applied.
    pub late_clouds: u64,
    /// Gaze samples that arrived after the reorder window (dropped).
    pub late_gaze: u64,
    /// Clouds in a frame other than the vehicle frame that no static
    /// transform read so far linked to it (no mounting yaw was applied).
    pub clouds_without_tf: u64,
    /// Static transforms read.
    pub transforms: u64,
    /// The gaze pipeline's counters.
    pub stream: StreamStats,
}

/// One message waiting in the reorder window.
struct Pending {
    log_time: u64,
    /// Order read (ties on `log_time` keep file order).
    seq: u64,
    msg: mcap::Message<'static>,
}

impl PartialEq for Pending {
    fn eq(&self, o: &Self) -> bool {
        (self.log_time, self.seq) == (o.log_time, o.seq)
    }
}
impl Eq for Pending {}
impl PartialOrd for Pending {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Pending {
    // Reversed: `BinaryHeap` is a max-heap, the oldest message comes first.
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        (o.log_time, o.seq).cmp(&(self.log_time, self.seq))
    }
}

/// Most bytes of message data held in the reorder window; past this the
/// oldest message is processed whatever its age (memory stays bounded).
const MAX_WINDOW_BYTES: usize = 96 << 20;

/// Frames remembered for clouds that arrive late.
const FRAME_HISTORY: usize = 64;

/// Longest record (or chunk) read, bytes: 256 MiB, a cloud of ten million
/// points.
const MAX_RECORD_BYTES: usize = 256 << 20;

/// Input bytes read per call.
const READ_BYTES: usize = 1 << 20;

/// Gaze azimuth (degrees, `[0, 360)`) of a direction vector in the vehicle
/// frame; `None` when its horizontal part is zero or not finite.
#[must_use]
pub fn vector_azimuth_deg(v: [f64; 3]) -> Option<f64> {
    let [x, y, z] = v;
    if !(x.is_finite() && y.is_finite() && z.is_finite()) || (x == 0.0 && y == 0.0) {
        return None;
    }
    Some(crate::model::angle::wrap_deg(y.atan2(x).to_degrees()))
}

struct Out<W: Write + Seek> {
    mcap: mcap::Writer<W>,
    schemas: HashMap<u16, u16>,
    channels: HashMap<u16, u16>,
    adapted: Option<u16>,
    profile: u16,
    scene: u16,
    sequences: HashMap<u16, u32>,
}

impl<W: Write + Seek> Out<W> {
    fn channel_for(&mut self, ch: &mcap::Channel<'_>) -> Result<u16, ReplayError> {
        if let Some(&id) = self.channels.get(&ch.id) {
            return Ok(id);
        }
        let schema_id = match &ch.schema {
            None => 0,
            Some(s) => match self.schemas.get(&s.id) {
                Some(&id) => id,
                None => {
                    let id = self
                        .mcap
                        .add_schema(&s.name, &s.encoding, &s.data)
                        .map_err(write_err)?;
                    self.schemas.insert(s.id, id);
                    id
                }
            },
        };
        let id = self
            .mcap
            .add_channel(schema_id, &ch.topic, &ch.message_encoding, &ch.metadata)
            .map_err(write_err)?;
        self.channels.insert(ch.id, id);
        Ok(id)
    }

    fn write(
        &mut self,
        channel_id: u16,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), ReplayError> {
        let seq = self.sequences.entry(channel_id).or_insert(0);
        *seq = seq.wrapping_add(1);
        self.mcap
            .write_to_known_channel(
                &MessageHeader {
                    channel_id,
                    sequence: *seq,
                    log_time,
                    publish_time,
                },
                data,
            )
            .map_err(write_err)
    }
}

/// The replay state between messages.
struct Replayer<'o, P: FramePlanner, W: Write + Seek> {
    opts: &'o ReplayOptions,
    stream: GazeStream<P>,
    baseline: CertifiedProfile,
    out: Out<W>,
    /// `log_time` of the first message processed: the gaze clock's zero.
    t0_ns: Option<u64>,
    /// Newest `log_time` processed (the frame clock is never run backwards).
    now_ns: u64,
    /// Recent frames: (start, ns since t0; state; profile).
    frames: VecDeque<(u64, State, CertifiedProfile)>,
    period_ns: u64,
    frame_id: String,
    stats: ReplayStats,
    /// Static transforms read so far.
    tf: tf::TfTree,
    /// The mounting yaw of the last cloud, degrees (for the picture).
    yaw_deg: f64,
    /// The last cloud's points (kept to reuse the allocation).
    xyz_buf: Vec<[f64; 3]>,
}

impl<P: FramePlanner, W: Write + Seek> Replayer<'_, P, W> {
    fn rel_s(&self, t_ns: u64) -> f64 {
        t_ns.saturating_sub(self.t0_ns.unwrap_or(t_ns)) as f64 * 1e-9
    }

    fn emit(&mut self, frames: Vec<Frame>) -> Result<(), ReplayError> {
        let t0 = self.t0_ns.unwrap_or(0);
        for f in frames {
            let start_ns = (f.t_s.max(0.0) * 1e9).round() as u64;
            let t_ns = t0.saturating_add(start_ns);
            let json = f
                .profile
                .profile()
                .to_json()
                .map_err(|e| ReplayError::Write(e.to_string()))?;
            let profile_ch = self.out.profile;
            self.out.write(profile_ch, t_ns, t_ns, json.as_bytes())?;
            let scene = scene::scene_update(
                f.profile.profile(),
                f.state,
                t_ns,
                &self.frame_id,
                self.yaw_deg,
            );
            let scene_ch = self.out.scene;
            self.out.write(scene_ch, t_ns, t_ns, scene.as_bytes())?;
            if self.frames.len() == FRAME_HISTORY {
                self.frames.pop_front();
            }
            self.frames.push_back((start_ns, f.state, f.profile));
        }
        Ok(())
    }

    fn process(&mut self, p: Pending) -> Result<(), ReplayError> {
        self.stats.messages += 1;
        self.t0_ns.get_or_insert(p.log_time);
        let ch_id = self.out.channel_for(&p.msg.channel)?;
        self.out
            .write(ch_id, p.msg.log_time, p.msg.publish_time, &p.msg.data)?;
        let topic = p.msg.channel.topic.as_str();
        let late = p.log_time < self.now_ns;
        if topic == self.opts.gaze_topic {
            let sample = self.gaze_sample(&p).map_err(|e| in_message(e, topic, &p))?;
            if late {
                self.stats.late_gaze += 1;
                return Ok(());
            }
            self.now_ns = p.log_time;
            let frames = self.stream.push(&sample)?;
            self.emit(frames)?;
        } else if topic == self.opts.cloud_topic {
            if !late {
                self.now_ns = p.log_time;
                let frames = self.stream.tick(self.rel_s(p.log_time))?;
                self.emit(frames)?;
            }
            self.cloud(&p).map_err(|e| in_message(e, topic, &p))?;
        } else {
            if topic == self.opts.tf_topic && self.opts.sensor_yaw_deg.is_none() {
                self.transforms(&p).map_err(|e| in_message(e, topic, &p))?;
            }
            if !late {
                self.now_ns = p.log_time;
            }
        }
        Ok(())
    }

    fn transforms(&mut self, p: &Pending) -> Result<(), ReplayError> {
        check_schema(&p.msg.channel, schemas::TF_MESSAGE)?;
        for t in cdr::decode_tf_message(&p.msg.data)? {
            self.tf
                .insert(t.header.frame_id, t.child_frame_id, t.rotation_xyzw)
                .map_err(|e| ReplayError::Message {
                    field: format!("transform {} in {}", t.child_frame_id, t.header.frame_id),
                    reason: e.to_string(),
                })?;
            self.stats.transforms += 1;
        }
        Ok(())
    }

    /// The mounting yaw of clouds in `frame`, degrees (see
    /// [`ReplayOptions::sensor_yaw_deg`]).
    fn mounting_yaw_deg(&mut self, frame: &str) -> Result<f64, ReplayError> {
        if let Some(y) = self.opts.sensor_yaw_deg {
            return Ok(y);
        }
        let opts = self.opts;
        let vehicle = opts.vehicle_frame.as_str();
        if frame == vehicle {
            return Ok(0.0);
        }
        let topic = || opts.tf_topic.clone();
        let q = self
            .tf
            .rotation(frame, vehicle)
            .map_err(|e| ReplayError::Topic {
                topic: topic(),
                reason: e.to_string(),
            })?;
        let Some(q) = q else {
            self.stats.clouds_without_tf += 1;
            return Ok(0.0);
        };
        let m = tf::mounting(q);
        if m.tilt_deg > self.opts.max_mount_tilt_deg {
            return Err(ReplayError::Topic {
                topic: topic(),
                reason: format!(
                    "the transform from the cloud frame {frame:?} to the vehicle frame {vehicle:?} tilts its z axis {:.3}° from the vertical (roll and pitch), beyond the {}° tolerance of the yaw-only mounting (give the yaw with --sensor-yaw-deg to use it anyway)",
                    m.tilt_deg, opts.max_mount_tilt_deg
                ),
            });
        }
        Ok(m.yaw_deg)
    }

    fn gaze_sample(&self, p: &Pending) -> Result<GazeSample, ReplayError> {
        check_schema(&p.msg.channel, self.opts.gaze_kind_schema())?;
        let t_s = self.rel_s(p.log_time);
        Ok(match self.opts.gaze_kind {
            GazeKind::Vector3 => {
                let v = cdr::Vector3Stamped::decode(&p.msg.data)?;
                match vector_azimuth_deg(v.xyz) {
                    Some(g) => GazeSample {
                        t_s,
                        gaze_deg: g,
                        valid: true,
                    },
                    None => GazeSample {
                        t_s,
                        gaze_deg: f64::NAN,
                        valid: false,
                    },
                }
            }
            GazeKind::YawDeg => {
                let g = cdr::decode_float64(&p.msg.data)?;
                GazeSample {
                    t_s,
                    gaze_deg: g,
                    valid: g.is_finite(),
                }
            }
        })
    }

    /// The profile running at `t_ns` (since t0): the newest remembered
    /// frame starting at or before it, within one period; else the baseline.
    fn profile_at(&self, t_ns: u64) -> Option<&CertifiedProfile> {
        let newest = self.frames.back()?;
        if newest.0 <= t_ns {
            // The frame running now (the clock was just run up to `t_ns`).
            return Some(&newest.2);
        }
        let (start, _, p) = self.frames.iter().rev().find(|(s, _, _)| *s <= t_ns)?;
        (t_ns - start < self.period_ns.max(1)).then_some(p)
    }

    fn cloud(&mut self, p: &Pending) -> Result<(), ReplayError> {
        check_schema(&p.msg.channel, schemas::POINT_CLOUD2)?;
        let cloud = cdr::PointCloud2::decode(&p.msg.data)?;
        let layout = cloud.xyz()?;
        if self.frame_id != cloud.header.frame_id {
            cloud.header.frame_id.clone_into(&mut self.frame_id);
        }
        let yaw_deg = self.mounting_yaw_deg(cloud.header.frame_id)?;
        self.yaw_deg = yaw_deg;
        let yaw = (yaw_deg != 0.0).then(|| {
            let r = yaw_deg.to_radians();
            (r.cos(), r.sin())
        });
        let rel_ns = p.log_time.saturating_sub(self.t0_ns.unwrap_or(p.log_time));
        let profile = match self.profile_at(rel_ns) {
            Some(pr) => pr.clone(),
            None => {
                self.stats.late_clouds += u64::from(!self.frames.is_empty());
                self.baseline.clone()
            }
        };
        let n = layout.len();
        let mut xyz = std::mem::take(&mut self.xyz_buf);
        xyz.clear();
        layout.decode_all(cloud.data, &mut xyz);
        let turn = |[x, y, z]: [f64; 3]| match yaw {
            None => [x, y, z],
            Some((c, s)) => [c * x - s * y, s * x + c * y, z],
        };
        let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
        let mut opts = self.opts.cloud.clone();
        opts.frame = CloudFrame::Iso8855;
        opts.seed = opts.seed.wrapping_add(self.stats.clouds);
        let keep = if xyz.iter().all(finite) {
            // Every point (a dense cloud): the mask is the rule's.
            keep_mask(&profile, xyz.iter().map(|&p| turn(p)), &opts)?
        } else {
            // Non-finite points are never returned and not passed to the rule.
            let index: Vec<usize> = (0..n).filter(|&i| finite(&xyz[i])).collect();
            let mask = keep_mask(&profile, index.iter().map(|&i| turn(xyz[i])), &opts)?;
            let mut keep = vec![false; n];
            for (&i, &k) in index.iter().zip(&mask) {
                keep[i] = k;
            }
            keep
        };
        self.xyz_buf = xyz;
        let kept = keep.iter().filter(|&&k| k).count() as u64;
        let data = cdr::encode_subset(&cloud, &layout, &keep, true);
        let adapted = match self.out.adapted {
            Some(id) => id,
            None => {
                let schema_id = match &p.msg.channel.schema {
                    Some(s) => self
                        .out
                        .mcap
                        .add_schema(&s.name, &s.encoding, &s.data)
                        .map_err(write_err)?,
                    None => 0,
                };
                let id = self
                    .out
                    .mcap
                    .add_channel(
                        schema_id,
                        &self.opts.adapted_topic,
                        schemas::CDR,
                        &BTreeMap::new(),
                    )
                    .map_err(write_err)?;
                self.out.adapted = Some(id);
                id
            }
        };
        self.out
            .write(adapted, p.msg.log_time, p.msg.publish_time, &data)?;
        self.stats.clouds += 1;
        self.stats.points_in += n as u64;
        self.stats.points_kept += kept;
        Ok(())
    }
}

impl ReplayOptions {
    fn gaze_kind_schema(&self) -> &'static str {
        match self.gaze_kind {
            GazeKind::Vector3 => schemas::VECTOR3_STAMPED,
            GazeKind::YawDeg => schemas::FLOAT64,
        }
    }
}

/// `pkg/msg/Type` and `pkg/Type` name the same ROS type.
fn same_type(a: &str, b: &str) -> bool {
    a == b || a.replacen("/msg/", "/", 1) == b.replacen("/msg/", "/", 1)
}

fn check_schema(ch: &mcap::Channel<'_>, want: &str) -> Result<(), ReplayError> {
    let name = ch.schema.as_ref().map_or("", |s| s.name.as_str());
    if !same_type(name, want) || ch.message_encoding != schemas::CDR {
        return Err(ReplayError::Topic {
            topic: ch.topic.clone(),
            reason: format!(
                "carries {} messages encoded as {:?}, not {want} in cdr",
                if name.is_empty() { "schemaless" } else { name },
                ch.message_encoding
            ),
        });
    }
    Ok(())
}

fn in_message(e: ReplayError, topic: &str, p: &Pending) -> ReplayError {
    match e {
        ReplayError::Message { field, reason } => ReplayError::Message {
            field: format!(
                "{topic}: message {} (log_time {} ns): {field}",
                p.msg.sequence, p.log_time
            ),
            reason,
        },
        ReplayError::Cloud(c) => ReplayError::Message {
            field: format!(
                "{topic}: message {} (log_time {} ns): {}",
                p.msg.sequence, p.log_time, c.field
            ),
            reason: c.reason,
        },
        e => e,
    }
}

/// Replays the MCAP read from `input` (named `path` in errors) through
/// `planner`, writing the output MCAP to `output`. See the module docs.
pub fn replay<R: Read, W: Write + Seek, P: FramePlanner>(
    mut input: R,
    path: &str,
    output: W,
    mut planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
) -> Result<ReplayStats, ReplayError> {
    if let Some(y) = opts.sensor_yaw_deg.filter(|y| !y.is_finite()) {
        return Err(ReplayError::Config {
            field: "sensor_yaw_deg",
            reason: format!("{y} is not a finite angle"),
        });
    }
    if !(opts.max_mount_tilt_deg.is_finite() && (0.0..=90.0).contains(&opts.max_mount_tilt_deg)) {
        return Err(ReplayError::Config {
            field: "max_mount_tilt_deg",
            reason: format!("{} must lie in 0..=90", opts.max_mount_tilt_deg),
        });
    }
    if opts.vehicle_frame.is_empty() {
        return Err(ReplayError::Config {
            field: "vehicle_frame",
            reason: "must not be empty".to_owned(),
        });
    }
    for (field, t) in [
        ("adapted_topic", &opts.adapted_topic),
        ("profile_topic", &opts.profile_topic),
        ("scene_topic", &opts.scene_topic),
    ] {
        if t == &opts.gaze_topic || t == &opts.cloud_topic || t.is_empty() {
            return Err(ReplayError::Config {
                field,
                reason: format!("{t:?} must be a new, non-empty topic"),
            });
        }
    }
    // Fail early on bad cloud options (rated range, fog, model).
    crate::pointcloud::return_model(&opts.cloud)?;
    let baseline = planner.plan(None)?;
    let stream =
        GazeStream::with_config(planner, pipeline.filter, pipeline.failsafe, pipeline.stream);
    let period_ns = stream.period_us().saturating_mul(1000);
    let compression = match opts.compression {
        Compression::None => None,
        Compression::Lz4 => Some(mcap::Compression::Lz4),
        Compression::Zstd => Some(mcap::Compression::Zstd),
    };
    let mut mcap = mcap::WriteOptions::new()
        .compression(compression)
        // Single-threaded zstd: the same bytes on every machine.
        .compression_threads(0)
        .profile("ros2")
        .library(concat!("gaze-lidar ", env!("CARGO_PKG_VERSION")))
        .create(output)
        .map_err(write_err)?;
    let ps = mcap
        .add_schema(
            schemas::PROFILE,
            schemas::JSONSCHEMA,
            schemas::PROFILE_JSONSCHEMA.as_bytes(),
        )
        .map_err(write_err)?;
    let profile = mcap
        .add_channel(ps, &opts.profile_topic, schemas::JSON, &BTreeMap::new())
        .map_err(write_err)?;
    let ss = mcap
        .add_schema(
            schemas::SCENE_UPDATE,
            schemas::JSONSCHEMA,
            schemas::SCENE_UPDATE_JSONSCHEMA.as_bytes(),
        )
        .map_err(write_err)?;
    let scene = mcap
        .add_channel(ss, &opts.scene_topic, schemas::JSON, &BTreeMap::new())
        .map_err(write_err)?;
    let mut r = Replayer {
        opts,
        stream,
        baseline,
        out: Out {
            mcap,
            schemas: HashMap::new(),
            channels: HashMap::new(),
            adapted: None,
            profile,
            scene,
            sequences: HashMap::new(),
        },
        t0_ns: None,
        now_ns: 0,
        frames: VecDeque::new(),
        period_ns,
        frame_id: "base_link".to_owned(),
        stats: ReplayStats::default(),
        tf: tf::TfTree::default(),
        yaw_deg: opts.sensor_yaw_deg.unwrap_or(0.0),
        xyz_buf: Vec::new(),
    };
    // Every CRC checked (a chunk before any of its messages is used), and
    // no record longer than `MAX_RECORD_BYTES` (a corrupt length must not
    // allocate without bound).
    let mut reader = MessageReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_record_length_limit(MAX_RECORD_BYTES),
    );
    let mut offset: u64 = 0;
    let mut heap: BinaryHeap<Pending> = BinaryHeap::new();
    let mut held_bytes = 0usize;
    let mut newest = 0u64;
    let mut seq = 0u64;
    let mcap_err = |offset: u64, e: mcap::McapError| ReplayError::Mcap {
        path: path.to_owned(),
        offset,
        reason: match e {
            mcap::McapError::UnexpectedEof => {
                "the file ends inside a record (truncated)".to_owned()
            }
            mcap::McapError::UnsupportedCompression(c) => format!(
                "a chunk is compressed with `{c}`; replay reads uncompressed, lz4 and zstd chunks"
            ),
            e => e.to_string(),
        },
    };
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| mcap_err(offset, e))? {
            MessageReadEvent::ReadRequest(_) => {
                let buf = reader.insert(READ_BYTES);
                let n = loop {
                    match input.read(buf) {
                        Ok(n) => break n,
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                        Err(source) => {
                            return Err(ReplayError::Read {
                                path: path.to_owned(),
                                source,
                            })
                        }
                    }
                };
                offset += n as u64;
                reader.notify_read(n);
            }
            MessageReadEvent::Message(msg) => {
                newest = newest.max(msg.log_time);
                held_bytes += msg.data.len();
                heap.push(Pending {
                    log_time: msg.log_time,
                    seq,
                    msg,
                });
                seq += 1;
                while let Some(top) = heap.peek() {
                    let old = newest.saturating_sub(top.log_time) > opts.reorder_window_ns;
                    if !(old || held_bytes > MAX_WINDOW_BYTES) {
                        break;
                    }
                    let p = heap.pop().expect("peeked");
                    held_bytes -= p.msg.data.len();
                    r.process(p)?;
                }
            }
        }
    }
    while let Some(p) = heap.pop() {
        r.process(p)?;
    }
    r.out.mcap.finish().map_err(write_err)?;
    let mut stats = r.stats;
    stats.stream = r.stream.stats();
    Ok(stats)
}

/// Whether two paths name one existing file (device and inode; links
/// followed).
pub fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => false,
    }
}

/// [`replay`] from the file `input` to the file `output`, as `gaze-lidar
/// replay` and Python's `gaze_lidar.replay` run it: the output is written
/// to a temporary file beside `output` and renamed over it only when the
/// whole replay succeeded (flushed and synced), so a failure (a bad input,
/// a full disk) leaves any old `output` as it was and no partial file.
/// A new output file gets mode 0644, an existing one keeps its mode.
pub fn replay_file<P: FramePlanner>(
    input: &std::path::Path,
    output: &std::path::Path,
    planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
) -> Result<ReplayStats, ReplayError> {
    let origin = input.display().to_string();
    let out_err =
        |e: &dyn std::fmt::Display| ReplayError::Write(format!("{}: {e}", output.display()));
    let file = std::fs::File::open(input).map_err(|source| ReplayError::Read {
        path: origin.clone(),
        source,
    })?;
    if same_file(input, output) {
        return Err(ReplayError::Config {
            field: "out",
            reason: format!("{} is the input file", output.display()),
        });
    }
    if output.is_dir() {
        return Err(ReplayError::Config {
            field: "out",
            reason: format!("{} is a directory", output.display()),
        });
    }
    // A device or FIFO is written in place (never replaced by a file); a
    // symbolic link is followed, so the file it names is the one replaced.
    let refuse = |what: &str| ReplayError::Config {
        field: "out",
        reason: format!("{} is {what}", output.display()),
    };
    let resolved;
    let output = match std::fs::symlink_metadata(output) {
        Ok(link) if link.file_type().is_symlink() => {
            resolved =
                std::fs::canonicalize(output).map_err(|_| refuse("a symbolic link to nothing"))?;
            resolved.as_path()
        }
        _ => output,
    };
    if let Ok(meta) = std::fs::metadata(output) {
        use std::os::unix::fs::FileTypeExt;
        let ft = meta.file_type();
        if ft.is_char_device() || ft.is_fifo() {
            return replay_into_special(file, &origin, output, planner, pipeline, opts);
        }
        if ft.is_block_device() || ft.is_socket() {
            return Err(refuse(
                "a block device or socket; refusing to write over it",
            ));
        }
    }
    let dir = match output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".gaze-lidar-replay.");
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(output)
            .map(|m| m.permissions().mode() & 0o7777)
            .unwrap_or(0o644);
        builder.permissions(std::fs::Permissions::from_mode(mode));
    }
    let tmp = builder.tempfile_in(&dir).map_err(|e| out_err(&e))?;
    let reader = std::io::BufReader::with_capacity(1 << 20, file);
    let mut writer = std::io::BufWriter::with_capacity(1 << 20, tmp);
    let stats = replay(reader, &origin, &mut writer, planner, pipeline, opts)?;
    let tmp = writer.into_inner().map_err(|e| out_err(e.error()))?;
    tmp.as_file().sync_all().map_err(|e| out_err(&e))?;
    tmp.persist(output).map_err(|e| out_err(&e.error))?;
    Ok(stats)
}

/// [`replay_file`] into a character device or FIFO, written in place (the
/// node is never replaced by a file): the MCAP writer needs to seek, so the
/// replay goes to an anonymous temporary file first, then is copied in one
/// stream; a reader that goes away is not an error, as on stdout.
fn replay_into_special<P: FramePlanner>(
    input: std::fs::File,
    origin: &str,
    output: &std::path::Path,
    planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
) -> Result<ReplayStats, ReplayError> {
    use std::io::{Seek as _, SeekFrom};
    let out_err = |e: std::io::Error| ReplayError::Write(format!("{}: {e}", output.display()));
    let staged = tempfile::tempfile().map_err(out_err)?;
    let reader = std::io::BufReader::with_capacity(1 << 20, input);
    let mut writer = std::io::BufWriter::with_capacity(1 << 20, staged);
    let stats = replay(reader, origin, &mut writer, planner, pipeline, opts)?;
    let mut staged = writer.into_inner().map_err(|e| out_err(e.into_error()))?;
    staged.seek(SeekFrom::Start(0)).map_err(out_err)?;
    let mut device = std::fs::OpenOptions::new()
        .write(true)
        .open(output)
        .map_err(out_err)?;
    match std::io::copy(&mut staged, &mut device).and_then(|_| device.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(out_err(e)),
        _ => Ok(stats),
    }
}

#[cfg(test)]
mod tests;
