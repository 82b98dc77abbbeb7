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
//!   0, in the order written: `log_time`) is thinned with seed `seed + k`
//!   (wrapping).
//! - every message is copied to the output unchanged, on its own topic,
//!   with its sequence number; every channel and schema (one without a
//!   single message too), attachments and metadata records too.
//!
//! The output adds, with their schemas embedded (all `ros2msg` + CDR): the
//! adapted cloud (the kept points' bytes, same header, fields and point
//! step, one row) on [`ReplayOptions::adapted_topic`]; one
//! `gaze-lidar/profile@1` JSON document per frame, as a
//! `std_msgs/msg/String`, on [`ReplayOptions::profile_topic`] (`log_time`
//! the frame start); and a `visualization_msgs/msg/MarkerArray` per frame
//! on [`ReplayOptions::scene_topic`]: a ring around the sensor, one sector
//! per run of equal power, coloured and sized by `P/P̄`, drawn in the
//! cloud's frame ([`scene`]).

pub mod cdr;
mod chunk;
pub mod scene;
pub mod schemas;
pub mod tf;

use std::collections::{BTreeMap, BinaryHeap, HashMap, VecDeque};
use std::io::{Read, Seek, Write};

use mcap::records::MessageHeader;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use thiserror::Error;

use crate::checker::CertifiedProfile;
use crate::gaze::{GazeSample, State};
use crate::pipeline::{Frame, FramePlanner, GazeStream, Notice, PipelineError, StreamStats};
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
    /// The static transforms tilt the cloud frame's z axis from the
    /// vehicle's beyond the yaw-only mounting's tolerance (roll and pitch).
    /// Giving the sensor's yaw explicitly ([`ReplayOptions::sensor_yaw_deg`])
    /// replaces the transform.
    #[error("{topic}: {reason}{met_at}")]
    MountTilt {
        /// The transform topic.
        topic: String,
        /// Which frames and how far they tilt.
        reason: String,
        /// Empty, or ` (met at …)`: the message that needed the transform.
        met_at: String,
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
    Pipeline(#[from] PipelineError),
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
    /// Bad input rather than an infeasible request or an output failure.
    #[must_use]
    pub fn is_input_error(&self) -> bool {
        match self {
            Self::Mcap { .. }
            | Self::Message { .. }
            | Self::Topic { .. }
            | Self::MountTilt { .. }
            | Self::Config { .. }
            | Self::Read { .. }
            | Self::Cloud(_) => true,
            Self::Pipeline(e) => e.is_input_error(),
            Self::Write(_) => false,
        }
    }
}

/// A write error with its cause (the mcap crate's I/O error says only
/// "I/O error from writing"; the system's reason is its source).
fn write_err(e: impl std::error::Error) -> ReplayError {
    match e.source() {
        Some(cause) => ReplayError::Write(format!("{e}: {cause}")),
        None => ReplayError::Write(e.to_string()),
    }
}

/// The gaze topic's message type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GazeKind {
    /// `geometry_msgs/msg/Vector3Stamped`: the gaze direction (vehicle frame).
    Vector3,
    /// `std_msgs/msg/Float64`: the gaze yaw, degrees counter-clockwise from ahead.
    YawDeg,
}

/// The zstd level of [`Compression::Zstd`] output.
pub const ZSTD_LEVEL: u32 = 1;

/// Output compression of the MCAP chunks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Compression {
    /// None (the default, as rosbag2 records).
    None,
    /// LZ4.
    Lz4,
    /// Zstandard, level [`ZSTD_LEVEL`].
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
    /// Topic of the per-frame picture (`visualization_msgs/msg/MarkerArray`).
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
    /// older than the window's clock, ns: the older of the gaze and cloud
    /// topics' newest `log_time`s, so no stamp on another topic moves it,
    /// and a far-future stamp on one of the two is held back by the other
    /// (at most 32 MiB are held, each message counted with its
    /// bookkeeping). A message later than that is processed late (a late
    /// gaze sample is dropped, a late cloud gets the profile of the frame
    /// it fell in, or the baseline).
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

pub use crate::pipeline::PipelineConfig;

/// What a replay did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
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
    /// Gaze vectors in a frame (`header.frame_id`, not empty) other than
    /// the vehicle frame that no static transform read so far linked to it
    /// (used as if in the vehicle frame).
    pub gaze_without_tf: u64,
    /// The first such frame.
    pub gaze_frame_without_tf: Option<String>,
    /// Static transforms read.
    pub transforms: u64,
    /// Attachments copied.
    pub attachments: u64,
    /// Metadata records copied.
    pub metadata: u64,
    /// Frames whose adaptive profile could not be certified (or planned):
    /// they ran the baseline, as `stream` warns.
    pub plan_fallbacks: u64,
    /// Gaze clock jumps (or steps back): one fail-safe frame each, the
    /// frame clock restarted, the gaze history discarded.
    pub resyncs: u64,
    /// The gaze pipeline's counters.
    pub stream: StreamStats,
}

/// One message waiting in the reorder window.
struct Pending {
    log_time: u64,
    /// Order read (ties on `log_time` keep file order).
    seq: u64,
    /// Where its record is: the top-level record's byte offset, and the
    /// record's index when that is a chunk.
    at: RecordAt,
    msg: mcap::Message<'static>,
}

/// Where a record is in the input file.
#[derive(Debug, Clone, Copy)]
struct RecordAt {
    /// Byte offset of the top-level record (the message, or its chunk).
    offset: u64,
    /// Index of the record inside the chunk, for a chunk.
    in_chunk: Option<usize>,
}

impl std::fmt::Display for RecordAt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.in_chunk {
            None => write!(f, "at byte {}", self.offset),
            Some(k) => write!(f, "in the chunk at byte {}, record {k}", self.offset),
        }
    }
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

/// Most bytes held in the reorder window, each message counted as its
/// data plus [`HELD_OVERHEAD_BYTES`]; past this the oldest message is
/// processed whatever its age (memory stays bounded, however small the
/// messages).
const MAX_WINDOW_BYTES: usize = 32 << 20;

/// What one held message costs besides its data, bytes: its entry in the
/// heap (twice over: the heap's vector grows by doubling) and the data's
/// allocation header, rounded up.
const HELD_OVERHEAD_BYTES: usize = 2 * std::mem::size_of::<Pending>() + 32;

/// The file's magic, bytes.
const MAGIC_BYTES: u64 = 8;

/// A record's opcode and length, bytes.
const RECORD_HEAD_BYTES: u64 = 9;

/// The reorder window: messages wait in a heap ordered by (`log_time`,
/// order read) and leave it, oldest first, once they are more than the
/// window older than the release clock, or when the held bytes pass
/// [`MAX_WINDOW_BYTES`].
///
/// The release clock is the older of the gaze and cloud topics' newest
/// `log_time`s (of those read so far; 0 before either): the two topics
/// that drive the output. Stamps on any other topic never move it, however
/// many and however far ahead; a far-future stamp on one of the two is
/// held back by the other. (A driving topic that stops holds the clock:
/// messages then leave by the byte bound, still oldest first.)
struct Window {
    heap: BinaryHeap<Pending>,
    window_ns: u64,
    held_bytes: usize,
    seq: u64,
    /// Newest `log_time` read on the gaze topic and on the cloud topic.
    newest: [Option<u64>; 2],
}

/// Which of the topics driving the output a message is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Drives {
    Gaze,
    Cloud,
    No,
}

impl Window {
    fn new(window_ns: u64) -> Self {
        Self {
            heap: BinaryHeap::new(),
            window_ns,
            held_bytes: 0,
            seq: 0,
            newest: [None; 2],
        }
    }

    fn cost(msg: &mcap::Message<'_>) -> usize {
        msg.data.len() + HELD_OVERHEAD_BYTES
    }

    fn push(&mut self, msg: mcap::Message<'static>, at: RecordAt, drives: Drives) {
        let t = msg.log_time;
        let slot = match drives {
            Drives::Gaze => Some(&mut self.newest[0]),
            Drives::Cloud => Some(&mut self.newest[1]),
            Drives::No => None,
        };
        if let Some(slot) = slot {
            *slot = Some(slot.map_or(t, |n| n.max(t)));
        }
        self.held_bytes += Self::cost(&msg);
        self.heap.push(Pending {
            log_time: t,
            seq: self.seq,
            at,
            msg,
        });
        self.seq += 1;
    }

    /// The release clock (see the type's documentation).
    fn clock(&self) -> u64 {
        self.newest.iter().flatten().copied().min().unwrap_or(0)
    }

    /// The oldest message, if it is due.
    fn pop_due(&mut self) -> Option<Pending> {
        let top = self.heap.peek()?;
        let old = self.clock().saturating_sub(top.log_time) > self.window_ns;
        if old || self.held_bytes > MAX_WINDOW_BYTES {
            self.pop()
        } else {
            None
        }
    }

    /// The oldest message.
    fn pop(&mut self) -> Option<Pending> {
        let p = self.heap.pop()?;
        self.held_bytes -= Self::cost(&p.msg);
        Some(p)
    }
}

/// Frames remembered for clouds that arrive late.
const FRAME_HISTORY: usize = 64;

/// Longest record read (a chunk packed or unpacked, an attachment), bytes:
/// 64 MiB.
const MAX_RECORD_BYTES: usize = 64 << 20;

/// Longest message, bytes: 32 MiB (a cloud of 1.5 million 22-byte points;
/// a 128-channel sensor's is some 5 MB). Held at most four times over
/// (the chunk read, the message, the output chunk, the adapted cloud), so
/// with the window peak memory stays under 200 MB.
const MAX_MESSAGE_BYTES: usize = 32 << 20;

/// Most bytes of schemas and channels (names, definitions, metadata) a bag
/// may declare: 16 MiB, held about three times over (read, output, its
/// summary).
const MAX_DECLARED_BYTES: usize = 16 << 20;

/// Input bytes read per call.
const READ_BYTES: usize = 1 << 20;

/// An iterator of a known length (the finite points of a cloud).
struct Counted<I> {
    inner: I,
    left: usize,
}

impl<I: Iterator> Iterator for Counted<I> {
    type Item = I::Item;

    fn next(&mut self) -> Option<I::Item> {
        let v = self.inner.next()?;
        self.left = self.left.saturating_sub(1);
        Some(v)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.left, Some(self.left))
    }
}

impl<I: Iterator> ExactSizeIterator for Counted<I> {}

/// Gaze azimuth (degrees, `[0, 360)`, never subnormal) of a direction
/// vector in the vehicle frame; `None` when a component is not finite or
/// the horizontal part is zero. The horizontal part is scaled by its larger
/// component first (as quaternions are), so every finite non-zero one, at
/// any scale, gives its azimuth; an angle below the smallest normal number
/// (a component some 10³⁰⁸ times the other) is 0.
#[must_use]
pub fn vector_azimuth_deg(v: [f64; 3]) -> Option<f64> {
    let [x, y, z] = v;
    if !(x.is_finite() && y.is_finite() && z.is_finite()) || (x == 0.0 && y == 0.0) {
        return None;
    }
    let m = x.abs().max(y.abs());
    let a = (y / m).atan2(x / m).to_degrees();
    let a = if a.abs() < f64::MIN_POSITIVE { 0.0 } else { a };
    Some(crate::model::angle::wrap_deg(a))
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
    fn channel_for(
        &mut self,
        ch: &mcap::Channel<'_>,
        opts: &ReplayOptions,
    ) -> Result<u16, ReplayError> {
        if let Some(&id) = self.channels.get(&ch.id) {
            return Ok(id);
        }
        if let Some(field) = opts.output_field(&ch.topic) {
            return Err(config(
                field,
                format!(
                    "{:?} is also a topic of the input bag: the output would hold two channels of it (replaying a replay's output needs new output topics)",
                    ch.topic
                ),
            ));
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

    /// A message on a channel this replay adds, numbered 1, 2, … per channel.
    fn write(
        &mut self,
        channel_id: u16,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), ReplayError> {
        let seq = self.sequences.entry(channel_id).or_insert(0);
        *seq = seq.wrapping_add(1);
        let sequence = *seq;
        self.write_as(channel_id, sequence, log_time, publish_time, data)
    }

    /// A message with its own sequence number (a copied one keeps the
    /// input's).
    fn write_as(
        &mut self,
        channel_id: u16,
        sequence: u32,
        log_time: u64,
        publish_time: u64,
        data: &[u8],
    ) -> Result<(), ReplayError> {
        self.mcap
            .write_to_known_channel(
                &MessageHeader {
                    channel_id,
                    sequence,
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
    /// `log_time` of the first gaze or cloud message processed: the gaze
    /// clock's zero (the frame times, seconds since it, stay small, so the
    /// stamps written back are exact to the nanosecond even when another
    /// topic starts at `log_time` 0).
    t0_ns: Option<u64>,
    /// The frame clock's origin: the time the gaze stream was given (s
    /// since t0) when it started or last resynchronized, and the same time
    /// in integer ns since t0. A frame starts a whole number of µs after
    /// it; its stamp is computed from the integer, never from seconds.
    origin: Option<(f64, u64)>,
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
}

impl<P: FramePlanner, W: Write + Seek> Replayer<'_, P, W> {
    /// ns since t0.
    fn rel_ns(&self, t_ns: u64) -> u64 {
        t_ns.saturating_sub(self.t0_ns.unwrap_or(t_ns))
    }

    fn rel_s(&self, t_ns: u64) -> f64 {
        self.rel_ns(t_ns) as f64 * 1e-9
    }

    /// Runs the gaze stream to the message at `t_ns` (`log_time`), with its
    /// gaze sample if it is one, and writes the frames that fell due.
    fn advance(&mut self, t_ns: u64, sample: Option<&GazeSample>) -> Result<(), ReplayError> {
        let rel_ns = self.rel_ns(t_ns);
        let t_s = self.rel_s(t_ns);
        let frames = match sample {
            Some(s) => self.stream.push(s)?,
            None => self.stream.tick(t_s)?,
        };
        // The stream's first call set its frame clock's origin here.
        self.origin.get_or_insert((t_s, rel_ns));
        // What `stream` tells the user, counted for the summary.
        for n in self.stream.take_notices() {
            match n {
                Notice::PlanFallback { .. } => self.stats.plan_fallbacks += 1,
                Notice::Resync { .. } => {
                    // The frame clock restarted at this call's time; every
                    // frame of the call is on the new clock (a jump is
                    // found before any frame is due).
                    self.stats.resyncs += 1;
                    self.origin = Some((t_s, rel_ns));
                }
                Notice::Late { .. } => {}
            }
        }
        self.emit(frames)
    }

    fn emit(&mut self, frames: Vec<Frame>) -> Result<(), ReplayError> {
        let t0 = self.t0_ns.unwrap_or(0);
        let (origin_s, origin_ns) = self.origin.unwrap_or((0.0, 0));
        for f in frames {
            // The stream's frame time is the origin plus whole µs; the µs
            // are recovered exactly (the rounding error of `t_s` is below
            // 0.5 µs for times below 2³³ s) and the stamp is integer ns.
            let start_us = ((f.t_s - origin_s) * 1e6).round().max(0.0) as u64;
            let start_ns = origin_ns.saturating_add(start_us.saturating_mul(1000));
            let t_ns = t0.saturating_add(start_ns);
            let json = f
                .profile
                .profile()
                .to_json()
                .map_err(|e| ReplayError::Write(e.to_string()))?;
            let profile_ch = self.out.profile;
            self.out
                .write(profile_ch, t_ns, t_ns, &cdr::encode_string(&json))?;
            let scene = scene::scene_update(
                f.profile.profile(),
                f.state,
                t_ns,
                &self.frame_id,
                self.yaw_deg,
            );
            let scene_ch = self.out.scene;
            self.out.write(scene_ch, t_ns, t_ns, &scene)?;
            if self.frames.len() == FRAME_HISTORY {
                self.frames.pop_front();
            }
            self.frames.push_back((start_ns, f.state, f.profile));
        }
        Ok(())
    }

    fn process(&mut self, p: Pending) -> Result<(), ReplayError> {
        self.stats.messages += 1;
        let topic = p.msg.channel.topic.as_str();
        if topic == self.opts.gaze_topic || topic == self.opts.cloud_topic {
            self.t0_ns.get_or_insert(p.log_time);
        }
        let ch_id = self.out.channel_for(&p.msg.channel, self.opts)?;
        self.out.write_as(
            ch_id,
            p.msg.sequence,
            p.msg.log_time,
            p.msg.publish_time,
            &p.msg.data,
        )?;
        let late = p.log_time < self.now_ns;
        if topic == self.opts.gaze_topic {
            let sample = self.gaze_sample(&p).map_err(|e| in_message(e, topic, &p))?;
            if late {
                self.stats.late_gaze += 1;
                return Ok(());
            }
            self.now_ns = p.log_time;
            self.advance(p.log_time, Some(&sample))?;
        } else if topic == self.opts.cloud_topic {
            if !late {
                self.now_ns = p.log_time;
                self.advance(p.log_time, None)?;
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
            return Err(ReplayError::MountTilt {
                topic: topic(),
                reason: format!(
                    "the transform from the cloud frame {frame:?} to the vehicle frame {vehicle:?} tilts its z axis {:.3}° from the vertical (roll and pitch), beyond the {}° tolerance of the yaw-only mounting",
                    m.tilt_deg, opts.max_mount_tilt_deg
                ),
                met_at: String::new(),
            });
        }
        Ok(m.yaw_deg)
    }

    /// A gaze vector in `frame` turned into the vehicle frame by the static
    /// transforms read so far (the whole rotation: a direction has no
    /// mounting tilt limit); as it is when `frame` is empty, the vehicle
    /// frame, or not linked to it (counted, the first such frame named).
    fn gaze_in_vehicle_frame(
        &mut self,
        frame: &str,
        xyz: [f64; 3],
    ) -> Result<[f64; 3], ReplayError> {
        let vehicle = self.opts.vehicle_frame.as_str();
        if frame.is_empty() || frame == vehicle {
            return Ok(xyz);
        }
        let q = self
            .tf
            .rotation(frame, vehicle)
            .map_err(|e| ReplayError::Topic {
                topic: self.opts.tf_topic.clone(),
                reason: e.to_string(),
            })?;
        match q.and_then(tf::normalized) {
            Some(q) => Ok(tf::rotate(q, xyz)),
            None => {
                self.stats.gaze_without_tf += 1;
                if self.stats.gaze_frame_without_tf.is_none() {
                    self.stats.gaze_frame_without_tf = Some(frame.to_owned());
                }
                Ok(xyz)
            }
        }
    }

    fn gaze_sample(&mut self, p: &Pending) -> Result<GazeSample, ReplayError> {
        check_schema(&p.msg.channel, self.opts.gaze_kind_schema())?;
        let t_s = self.rel_s(p.log_time);
        Ok(match self.opts.gaze_kind {
            GazeKind::Vector3 => {
                let v = cdr::Vector3Stamped::decode(&p.msg.data)?;
                let xyz = self
                    .gaze_in_vehicle_frame(v.header.frame_id, v.xyz)
                    .map_err(|e| found_at(e, &self.opts.gaze_topic, p))?;
                match vector_azimuth_deg(xyz) {
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
        let yaw_deg = self
            .mounting_yaw_deg(cloud.header.frame_id)
            .map_err(|e| found_at(e, &self.opts.cloud_topic, p))?;
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
        let turn = |[x, y, z]: [f64; 3]| match yaw {
            None => [x, y, z],
            Some((c, s)) => [c * x - s * y, s * x + c * y, z],
        };
        let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
        let mut opts = self.opts.cloud.clone();
        opts.frame = CloudFrame::Iso8855;
        opts.seed = opts.seed.wrapping_add(self.stats.clouds);
        // The points are decoded as the rule reads them (no copy of the
        // cloud: memory is the message, one byte per point and the output).
        let points = || layout.points(cloud.data);
        let finite_n = points().filter(finite).count();
        let keep = if finite_n == n {
            // Every point (a dense cloud): the mask is the rule's.
            keep_mask(&profile, points().map(turn), &opts)?
        } else {
            // Non-finite points are never returned and not passed to the rule.
            let mask = keep_mask(
                &profile,
                Counted {
                    inner: points().filter(finite).map(turn),
                    left: finite_n,
                },
                &opts,
            )?;
            let mut rule = mask.into_iter();
            points()
                .map(|p| finite(&p) && rule.next().unwrap_or(false))
                .collect()
        };
        let kept = keep.iter().filter(|&&k| k).count() as u64;
        let data = cdr::encode_subset(&cloud, &layout, &keep, true);
        let adapted = match self.out.adapted {
            Some(id) => id,
            None => {
                // The tool's own definition, whatever text the input's
                // schema held (its name and encoding were checked).
                let def = schemas::ros2msg(schemas::POINT_CLOUD2).unwrap_or_default();
                let schema_id = self
                    .out
                    .mcap
                    .add_schema(schemas::POINT_CLOUD2, schemas::ROS2MSG, def.as_bytes())
                    .map_err(write_err)?;
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

/// Largest reorder window, ns.
pub const MAX_REORDER_WINDOW_NS: u64 = 60_000_000_000;

/// A reorder window given in milliseconds, as
/// [`ReplayOptions::reorder_window_ns`] (rounded to the nearest
/// nanosecond): `ms` passes the one numeric boundary and lies in
/// `0..=60000` ([`MAX_REORDER_WINDOW_NS`]), else a [`ReplayError::Config`]
/// naming `reorder_window_ms`. The CLI and Python read the option through it.
pub fn reorder_window_ns(ms: f64) -> Result<u64, ReplayError> {
    let ms = in_range("reorder_window_ms", ms, 0.0, 60_000.0)?;
    Ok((ms * 1e6).round() as u64)
}

/// Most bins of a replayed profile: each frame's profile@1 document is
/// written to the output (about 240 bytes of JSON per bin: 1440 bins are
/// some 340 KB per frame, 3.4 MB/s at 10 Hz, already more than the
/// adapted clouds of a 32-channel sensor); the optimizer's limit too.
pub const MAX_BINS: usize = 1440;

fn config(field: &'static str, reason: impl Into<String>) -> ReplayError {
    ReplayError::Config {
        field,
        reason: reason.into(),
    }
}

/// `v` passes the one numeric boundary ([`crate::model::valid::finite`]:
/// finite, zero or normal) and lies in `lo..=hi`.
fn in_range(field: &'static str, v: f64, lo: f64, hi: f64) -> Result<f64, ReplayError> {
    if crate::model::valid::finite(v).is_ok() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(config(
            field,
            format!(
                "{} must be finite (not subnormal) and lie in {}..={}",
                crate::text::Num(v),
                crate::text::Num(lo),
                crate::text::Num(hi)
            ),
        ))
    }
}

/// `v` is normal (finite, not subnormal), `> 0` and `<= hi`.
fn positive_to(field: &'static str, v: f64, hi: f64) -> Result<f64, ReplayError> {
    if crate::model::valid::positive(v).is_ok() && v <= hi {
        Ok(v)
    } else {
        Err(config(
            field,
            format!(
                "{} must be finite (not subnormal), > 0 and <= {}",
                crate::text::Num(v),
                crate::text::Num(hi)
            ),
        ))
    }
}

impl ReplayOptions {
    /// Checks every option before anything is read, naming it by its
    /// field (the Python keyword; the CLI's flag is `--` and the field with
    /// `-` for `_`): angles finite and not subnormal (the mounting yaw
    /// within ±360°, the tilt tolerance 0..=90°), the rated range, fog MOR
    /// (m, `<= 1e7`) and the cloud spin (rad/s, `<= 1e4`) normal and
    /// positive, the reorder window at most 60 s, the topics non-empty and
    /// the three output topics distinct from each other and from the gaze,
    /// cloud and transform topics. An input channel on an output topic is
    /// refused when it is met ([`replay`]).
    pub fn validate(&self) -> Result<(), ReplayError> {
        if let Some(y) = self.sensor_yaw_deg {
            in_range("sensor_yaw_deg", y, -360.0, 360.0)?;
        }
        in_range("max_mount_tilt_deg", self.max_mount_tilt_deg, 0.0, 90.0)?;
        if self.vehicle_frame.is_empty() {
            return Err(config("vehicle_frame", "must not be empty"));
        }
        positive_to("rated_range_m", self.cloud.rated_range_m, 1e7)?;
        if let Some(m) = self.cloud.fog_mor_m {
            positive_to("fog_mor_m", m, 1e7)?;
        }
        if let Some(w) = self.cloud.cloud_spin_rad_s {
            positive_to("cloud_spin_rad_s", w, 1e4)?;
        }
        if self.reorder_window_ns > MAX_REORDER_WINDOW_NS {
            return Err(config(
                "reorder_window_ms",
                format!("{} ns is longer than 60 s", self.reorder_window_ns),
            ));
        }
        for (field, t) in [
            ("gaze_topic", &self.gaze_topic),
            ("cloud_topic", &self.cloud_topic),
            ("tf_topic", &self.tf_topic),
        ] {
            if t.is_empty() {
                return Err(config(field, "must not be empty"));
            }
        }
        if self.gaze_topic == self.cloud_topic {
            return Err(config(
                "cloud_topic",
                format!("{:?} is also the gaze topic", self.cloud_topic),
            ));
        }
        // The transform topic carries tf2 messages: it cannot be the gaze
        // or the cloud topic (their messages would be read as transforms).
        for (name, t) in [
            ("gaze topic", &self.gaze_topic),
            ("cloud topic", &self.cloud_topic),
        ] {
            if self.tf_topic == *t {
                return Err(config("tf_topic", format!("{t:?} is also the {name}")));
            }
        }
        let outputs = [
            ("adapted_topic", &self.adapted_topic),
            ("profile_topic", &self.profile_topic),
            ("scene_topic", &self.scene_topic),
        ];
        for (k, (field, t)) in outputs.iter().enumerate() {
            if t.is_empty() {
                return Err(config(field, "must not be empty"));
            }
            for (name, input) in [
                ("gaze topic", &self.gaze_topic),
                ("cloud topic", &self.cloud_topic),
                ("transform topic", &self.tf_topic),
            ] {
                if *t == input {
                    return Err(config(
                        field,
                        format!("{t:?} is the {name}: an output topic must be new"),
                    ));
                }
            }
            if let Some((other, _)) = outputs[..k].iter().find(|(_, o)| o == t) {
                return Err(config(
                    field,
                    format!(
                        "{t:?} is also the {}: each output needs its own topic",
                        other.replace('_', " ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The output option naming `topic`, if any.
    fn output_field(&self, topic: &str) -> Option<&'static str> {
        [
            ("adapted_topic", &self.adapted_topic),
            ("profile_topic", &self.profile_topic),
            ("scene_topic", &self.scene_topic),
        ]
        .into_iter()
        .find(|(_, t)| *t == topic)
        .map(|(f, _)| f)
    }

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

/// A topic the replay decodes must carry `want` by name, its schema in
/// `ros2msg` (a ROS 2 message definition) and its messages in CDR; anything
/// else (an IDL schema, a schemaless channel, JSON) is refused by name
/// rather than decoded as if it were `want`.
fn check_schema(ch: &mcap::Channel<'_>, want: &str) -> Result<(), ReplayError> {
    let name = ch.schema.as_ref().map_or("", |s| s.name.as_str());
    let encoding = ch.schema.as_ref().map_or("", |s| s.encoding.as_str());
    if !same_type(name, want) || encoding != schemas::ROS2MSG || ch.message_encoding != schemas::CDR
    {
        return Err(ReplayError::Topic {
            topic: ch.topic.clone(),
            reason: format!(
                "carries {} messages (schema encoding {encoding:?}, message encoding {:?}), not {want} (schema encoding \"{}\", message encoding \"{}\")",
                if name.is_empty() { "schemaless" } else { name },
                ch.message_encoding,
                schemas::ROS2MSG,
                schemas::CDR,
            ),
        });
    }
    Ok(())
}

/// A transform error (a tilt, a cycle) named by the byte offset of the
/// message that needed the transform, like other message errors.
fn found_at(e: ReplayError, topic: &str, p: &Pending) -> ReplayError {
    let met_at = format!(
        " (met at {topic}: message {} (sequence {}, log_time {} ns))",
        p.at, p.msg.sequence, p.log_time
    );
    match e {
        ReplayError::Topic { topic: t, reason } => ReplayError::Topic {
            topic: t,
            reason: format!("{reason}{met_at}"),
        },
        ReplayError::MountTilt { topic, reason, .. } => ReplayError::MountTilt {
            topic,
            reason,
            met_at,
        },
        e => e,
    }
}

/// Names the message a decoding error is in: its topic and where its
/// record is (the MCAP sequence field, which writers may leave 0 or repeat,
/// only as "sequence N").
fn in_message(e: ReplayError, topic: &str, p: &Pending) -> ReplayError {
    let named = |field: &str| {
        format!(
            "{topic}: message {} (sequence {}, log_time {} ns): {field}",
            p.at, p.msg.sequence, p.log_time
        )
    };
    match e {
        ReplayError::Message { field, reason } => ReplayError::Message {
            field: named(&field),
            reason,
        },
        ReplayError::Cloud(c) => ReplayError::Message {
            field: named(&c.field),
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
    opts.validate()?;
    // Fail early on bad cloud options (rated range, fog, model).
    crate::pointcloud::return_model(&opts.cloud).map_err(|c| {
        config(
            match c.field.as_str() {
                "rated_range_m" => "rated_range_m",
                "fog_mor_m" => "fog_mor_m",
                _ => "model",
            },
            c.reason,
        )
    })?;
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
        // zstd at level 1, its fastest positive level (the default, 3, is
        // about half as fast on point clouds; see the README for the size
        // cost); LZ4 at its default.
        .compression_level(if opts.compression == Compression::Zstd {
            ZSTD_LEVEL
        } else {
            0
        })
        // Single-threaded zstd: the same bytes on every machine.
        .compression_threads(0)
        .profile("ros2")
        .library(concat!("gaze-lidar ", env!("CARGO_PKG_VERSION")))
        .create(output)
        .map_err(write_err)?;
    // Both ros2msg + CDR (a JSON-schema channel makes rosbags refuse the
    // whole file): the profile@1 JSON inside a std_msgs/msg/String.
    let mut ros_channel = |ty: &str, topic: &str| {
        let def = schemas::ros2msg(ty).unwrap_or_default();
        let s = mcap
            .add_schema(ty, schemas::ROS2MSG, def.as_bytes())
            .map_err(write_err)?;
        mcap.add_channel(s, topic, schemas::CDR, &BTreeMap::new())
            .map_err(write_err)
    };
    let profile = ros_channel(schemas::STRING, &opts.profile_topic)?;
    let scene = ros_channel(schemas::MARKER_ARRAY, &opts.scene_topic)?;
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
        origin: None,
        now_ns: 0,
        frames: VecDeque::new(),
        period_ns,
        frame_id: "base_link".to_owned(),
        stats: ReplayStats::default(),
        tf: tf::TfTree::default(),
        yaw_deg: opts.sensor_yaw_deg.unwrap_or(0.0),
    };
    // Every CRC checked (a chunk's before any of its messages is used), no
    // byte after the end magic, and no record longer than
    // `MAX_RECORD_BYTES` (a corrupt length must not allocate without
    // bound). Chunks are read whole and unpacked here, so every error is
    // reported at the start of the top-level record it is in.
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(MAX_RECORD_BYTES),
    );
    // Start of the next top-level record (after the 8-byte magic).
    let mut next_record: u64 = MAGIC_BYTES;
    // The footer's start, and the end of the magic after it.
    let mut footer_end: Option<(u64, u64)> = None;
    let mut past_data_end = false;
    let mut messages_read: u64 = 0;
    // Bytes of the schemas and channels declared so far (their names,
    // definitions and metadata), bounded by `MAX_DECLARED_BYTES`.
    let mut declared_bytes: usize = 0;
    let check_declared = |bytes: usize, at: u64| {
        if bytes > MAX_DECLARED_BYTES {
            return Err(ReplayError::Mcap {
                path: path.to_owned(),
                offset: at,
                reason: format!(
                    "the schemas and channels declared so far take more than {} MiB (names, definitions and metadata; memory stays bounded)",
                    MAX_DECLARED_BYTES >> 20
                ),
            });
        }
        Ok(())
    };
    let mut links = mcap::read::ChannelAccumulator::<'static>::default();
    let mut window = Window::new(opts.reorder_window_ns);
    let input_bytes = std::cell::Cell::new(0u64);
    let mcap_err = |offset: u64, what: &str, e: mcap::McapError| {
        ReplayError::Mcap {
        path: path.to_owned(),
        offset,
        reason: format!(
            "{what}{}",
            match e {
                mcap::McapError::UnexpectedEof => format!(
                    "the file ends inside this record (truncated after {} bytes)",
                    input_bytes.get()
                ),
                mcap::McapError::UnsupportedCompression(c) => format!(
                    "a chunk is compressed with `{c}`; replay reads uncompressed, lz4 and zstd chunks"
                ),
                mcap::McapError::BytesAfterEndMagic => {
                    "data after the end magic (an MCAP file ends with its footer and the magic)"
                        .to_owned()
                }
                e => e.to_string(),
            }
        ),
    }
    };
    while let Some(event) = reader.next_event() {
        let event = event.map_err(|e| {
            // Always a byte inside the file: the start magic (a file
            // shorter than it, or not an MCAP file), the footer's start (a
            // file cut inside the end magic), the byte after the end magic
            // (data after it), else the start of the record being read.
            let at = match (&e, footer_end) {
                (mcap::McapError::BadMagic, _) if next_record == MAGIC_BYTES => 0,
                (mcap::McapError::UnexpectedEof, _) if input_bytes.get() < MAGIC_BYTES => 0,
                (mcap::McapError::UnexpectedEof, Some((footer_at, _))) => footer_at,
                (_, Some((_, end))) => end,
                _ => next_record,
            };
            mcap_err(at.min(input_bytes.get()), "", e)
        })?;
        match event {
            LinearReadEvent::ReadRequest(want) => {
                let buf = reader.insert(want.clamp(1, READ_BYTES));
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
                input_bytes.set(input_bytes.get() + n as u64);
                reader.notify_read(n);
            }
            LinearReadEvent::Record { opcode, data } => {
                let at = next_record;
                next_record += RECORD_HEAD_BYTES + data.len() as u64;
                if opcode == mcap::records::op::FOOTER {
                    // The end magic follows; anything after it is an error.
                    footer_end = Some((at, next_record + MAGIC_BYTES));
                }
                let record = mcap::parse_record(opcode, data).map_err(|e| mcap_err(at, "", e))?;
                if past_data_end {
                    // The summary repeats schemas, channels and indexes;
                    // its statistics must agree with what was read (a
                    // record whose opcode was corrupted is skipped as
                    // unknown, so only the count can tell).
                    if let mcap::records::Record::Statistics(s) = &record {
                        check_message_count(path, at, s.message_count, messages_read)?;
                    }
                    continue;
                }
                let chunked = matches!(record, mcap::records::Record::Chunk { .. });
                let records = match record {
                    // Written from the reader's buffer, never copied (an
                    // attachment is a top-level record, at most
                    // `MAX_RECORD_BYTES`).
                    mcap::records::Record::Attachment { header, data, .. } => {
                        r.out
                            .mcap
                            .attach(&mcap::Attachment {
                                log_time: header.log_time,
                                create_time: header.create_time,
                                name: header.name,
                                media_type: header.media_type,
                                data,
                            })
                            .map_err(write_err)?;
                        r.stats.attachments += 1;
                        continue;
                    }
                    mcap::records::Record::DataEnd(_) => {
                        past_data_end = true;
                        continue;
                    }
                    mcap::records::Record::Chunk { header, data } => {
                        if header.uncompressed_size > MAX_RECORD_BYTES as u64 {
                            return Err(mcap_err(
                                at,
                                "",
                                mcap::McapError::ChunkTooLarge(header.uncompressed_size),
                            ));
                        }
                        // Unpacked and its CRC checked before any of its
                        // messages is used.
                        chunk::unpack(&header, &data).map_err(|reason| ReplayError::Mcap {
                            path: path.to_owned(),
                            offset: at,
                            reason: format!("in this chunk: {reason}"),
                        })?
                    }
                    other => vec![other.into_owned()],
                };
                for (k, record) in records.into_iter().enumerate() {
                    let inside = |e| mcap_err(at, &format!("record {k} of this chunk: "), e);
                    match record {
                        mcap::records::Record::Schema { header, data } => {
                            declared_bytes += header.name.len() + data.len();
                            check_declared(declared_bytes, at)?;
                            links
                                .add_schema(header, std::borrow::Cow::Owned(data.into_owned()))
                                .map_err(inside)?;
                        }
                        mcap::records::Record::Channel(c) => {
                            // Copied when read: a channel without a single
                            // message (and its schema) is in the output too.
                            let id = c.id;
                            declared_bytes += c.topic.len()
                                + c.message_encoding.len()
                                + c.metadata
                                    .iter()
                                    .map(|(k, v)| k.len() + v.len())
                                    .sum::<usize>();
                            check_declared(declared_bytes, at)?;
                            links.add_channel(c).map_err(inside)?;
                            if let Some(channel) = links.get(id) {
                                r.out.channel_for(&channel, opts)?;
                            }
                        }
                        mcap::records::Record::Message { header, data } => {
                            messages_read += 1;
                            let Some(channel) = links.get(header.channel_id) else {
                                return Err(inside(mcap::McapError::UnknownChannel(
                                    header.sequence,
                                    header.channel_id,
                                )));
                            };
                            let record_at = RecordAt {
                                offset: at,
                                in_chunk: chunked.then_some(k),
                            };
                            if data.len() > MAX_MESSAGE_BYTES {
                                return Err(ReplayError::Message {
                                    field: format!(
                                        "{}: message {record_at} (sequence {}, log_time {} ns)",
                                        channel.topic, header.sequence, header.log_time
                                    ),
                                    reason: format!(
                                        "{} bytes, more than the {} MiB a message may have (memory stays bounded)",
                                        data.len(),
                                        MAX_MESSAGE_BYTES >> 20
                                    ),
                                });
                            }
                            let drives = if channel.topic == opts.gaze_topic {
                                Drives::Gaze
                            } else if channel.topic == opts.cloud_topic {
                                Drives::Cloud
                            } else {
                                Drives::No
                            };
                            window.push(
                                mcap::Message {
                                    channel,
                                    sequence: header.sequence,
                                    log_time: header.log_time,
                                    publish_time: header.publish_time,
                                    data: std::borrow::Cow::Owned(data.into_owned()),
                                },
                                record_at,
                                drives,
                            );
                            while let Some(p) = window.pop_due() {
                                r.process(p)?;
                            }
                        }
                        mcap::records::Record::Metadata(m) => {
                            r.out.mcap.write_metadata(&m).map_err(write_err)?;
                            r.stats.metadata += 1;
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    while let Some(p) = window.pop() {
        r.process(p)?;
    }
    r.out.mcap.finish().map_err(write_err)?;
    let mut stats = r.stats;
    stats.stream = r.stream.stats();
    Ok(stats)
}

/// The summary's message count against the messages the data section
/// held: a mismatch means records were lost (a corrupted opcode reads as an
/// unknown record, which MCAP readers skip) or the summary lies; either
/// way the bag is not what it says, and replaying the rest would silently
/// drop messages.
fn check_message_count(
    path: &str,
    offset: u64,
    declared: u64,
    read: u64,
) -> Result<(), ReplayError> {
    if declared == read {
        return Ok(());
    }
    Err(ReplayError::Mcap {
        path: path.to_owned(),
        offset,
        reason: format!(
            "the statistics record counts {declared} messages, the data section holds {read} (a record is corrupt or missing)"
        ),
    })
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
    replay_file_staged(input, output, planner, pipeline, opts, &Staging::default())
}

/// The path of the temporary file a [`replay_file_staged`] is writing, for
/// a signal handler to remove: set while it exists, `None` otherwise; held
/// locked while the file is renamed into place (a handler that takes the
/// lock then finds `None` and must remove nothing).
pub type Staging = std::sync::Mutex<Option<std::path::PathBuf>>;

/// [`replay_file`], publishing its temporary file in `staging` (see
/// [`Staging`]; `gaze-lidar replay` removes it on every catchable terminating signal).
pub fn replay_file_staged<P: FramePlanner>(
    input: &std::path::Path,
    output: &std::path::Path,
    planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
    staging: &Staging,
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
    // A folder that is missing or takes no new file is a bad --out (exit
    // 2), found before the input is read.
    match std::fs::metadata(&dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(refuse(&format!(
                "in {}, which is not a folder",
                dir.display()
            )))
        }
        Err(e) => {
            return Err(refuse(&format!(
                "in the folder {}, which cannot be used: {e}",
                dir.display()
            )))
        }
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".gaze-lidar-replay.");
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(output)
            .map(|m| m.permissions().mode() & 0o7777)
            .unwrap_or(0o644);
        builder.permissions(std::fs::Permissions::from_mode(mode));
    }
    let tmp = builder.tempfile_in(&dir).map_err(|e| {
        refuse(&format!(
            "in the folder {}, which takes no new file: {e}",
            dir.display()
        ))
    })?;
    let set = |p: Option<std::path::PathBuf>| {
        *staging
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = p;
    };
    set(Some(tmp.path().to_path_buf()));
    let written = (|| {
        let reader = std::io::BufReader::with_capacity(1 << 20, file);
        let mut writer = std::io::BufWriter::with_capacity(1 << 20, tmp);
        // A write that fails (a full disk) names the output file.
        let stats =
            replay(reader, &origin, &mut writer, planner, pipeline, opts).map_err(|e| match e {
                ReplayError::Write(m) => ReplayError::Write(format!("{}: {m}", output.display())),
                e => e,
            })?;
        let tmp = writer.into_inner().map_err(|e| out_err(e.error()))?;
        tmp.as_file().sync_all().map_err(|e| out_err(&e))?;
        Ok((stats, tmp))
    })();
    let mut staged = staging
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    // Renamed (or removed, on an error) with the lock held.
    let result = written.and_then(|(stats, tmp)| {
        tmp.persist(output).map_err(|e| out_err(&e.error))?;
        Ok(stats)
    });
    *staged = None;
    result
}

/// [`replay_file`] into a character device or FIFO, written in place (the
/// node is never replaced by a file), through [`replay_file_to`].
fn replay_into_special<P: FramePlanner>(
    input: std::fs::File,
    origin: &str,
    output: &std::path::Path,
    planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
) -> Result<ReplayStats, ReplayError> {
    let out_err = |e: std::io::Error| ReplayError::Write(format!("{}: {e}", output.display()));
    let stats = stage(input, origin, planner, pipeline, opts)?;
    let device = std::fs::OpenOptions::new()
        .write(true)
        .open(output)
        .map_err(out_err)?;
    stats.send(device).map_err(out_err)
}

/// A finished replay in an anonymous temporary file.
struct Staged {
    file: std::fs::File,
    stats: ReplayStats,
}

impl Staged {
    /// Copies the file to `out` in one stream; a reader that goes away
    /// (a closed pipe) is not an error.
    fn send(mut self, mut out: impl Write) -> Result<ReplayStats, std::io::Error> {
        use std::io::{Seek as _, SeekFrom};
        self.file.seek(SeekFrom::Start(0))?;
        match std::io::copy(&mut self.file, &mut out).and_then(|_| out.flush()) {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e),
            _ => Ok(self.stats),
        }
    }
}

/// The replay staged whole in an anonymous temporary file (the MCAP
/// writer seeks).
fn stage<P: FramePlanner>(
    input: std::fs::File,
    origin: &str,
    planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
) -> Result<Staged, ReplayError> {
    let out_err = |e: std::io::Error| ReplayError::Write(format!("temporary file: {e}"));
    let staged = tempfile::tempfile().map_err(|e| {
        ReplayError::Write(format!(
            "temporary file in {} (the folder TMPDIR names, else /tmp): {e}",
            std::env::temp_dir().display()
        ))
    })?;
    let reader = std::io::BufReader::with_capacity(1 << 20, input);
    let mut writer = std::io::BufWriter::with_capacity(1 << 20, staged);
    let stats = replay(reader, origin, &mut writer, planner, pipeline, opts)?;
    let file = writer.into_inner().map_err(|e| out_err(e.into_error()))?;
    Ok(Staged { file, stats })
}

/// [`replay`] from the file `input` to a stream (`gaze-lidar replay --out
/// -`: stdout): the replay is staged whole in an anonymous temporary file
/// and written out only when it succeeded, so a failure writes nothing; a
/// reader that goes away is not an error.
pub fn replay_file_to<P: FramePlanner>(
    input: &std::path::Path,
    out: impl Write,
    planner: P,
    pipeline: PipelineConfig,
    opts: &ReplayOptions,
) -> Result<ReplayStats, ReplayError> {
    let origin = input.display().to_string();
    let file = std::fs::File::open(input).map_err(|source| ReplayError::Read {
        path: origin.clone(),
        source,
    })?;
    stage(file, &origin, planner, pipeline, opts)?
        .send(out)
        .map_err(|e| ReplayError::Write(format!("stdout: {e}")))
}

#[cfg(test)]
mod tests;
