//! A synthetic drive as a rosbag2 MCAP (shared by `benches/replay.rs` and
//! `examples/make_bag.rs`): 128-channel clouds at 10 Hz (Velodyne layout:
//! x, y, z, intensity float32, ring uint16, time float32; 22-byte points,
//! 1800 columns × 128 rings = 230,400 points per cloud, 2.3 M points/s),
//! gaze (`Vector3Stamped`) at 100 Hz with a 0.5 s gap every 5 s, and an
//! unrelated topic at 1 Hz. Written as it is generated: memory stays one
//! cloud whatever the length.

use std::collections::BTreeMap;
use std::io::{Seek, Write};

use gaze_lidar::replay::cdr::{self, datatype, Header, Vector3Stamped};
use gaze_lidar::replay::schemas;
use mcap::records::MessageHeader;

/// Points per cloud.
pub const POINTS: usize = 1800 * 128;
/// Bytes per point.
pub const STEP: usize = 22;

fn header(t_ns: u64, frame_id: &str) -> Header<'_> {
    Header {
        sec: (t_ns / 1_000_000_000) as i32,
        nanosec: (t_ns % 1_000_000_000) as u32,
        frame_id,
    }
}

/// One cloud at `t_ns`.
pub fn cloud(t_ns: u64, k: u64) -> Vec<u8> {
    let mut data = Vec::with_capacity(POINTS * STEP);
    for col in 0..1800u32 {
        let az = f64::from(col) * std::f64::consts::TAU / 1800.0;
        for ring in 0..128u16 {
            // A range that varies with the column, the ring and the frame.
            let r = 2.0 + ((u64::from(col) * 7 + u64::from(ring) * 13 + k) % 280) as f64;
            let el = (f64::from(ring) - 64.0) * 0.2f64.to_radians();
            let (x, y, z) = (
                r * el.cos() * az.cos(),
                r * el.cos() * az.sin(),
                r * el.sin(),
            );
            for v in [x as f32, y as f32, z as f32, 10.0] {
                data.extend_from_slice(&v.to_le_bytes());
            }
            data.extend_from_slice(&ring.to_le_bytes());
            data.extend_from_slice(&(col as f32 * 5.5e-5).to_le_bytes());
        }
    }
    let mut w = cdr::Writer::new(data.len() + 256);
    header(t_ns, "velodyne").write(&mut w);
    w.u32(1);
    w.u32(POINTS as u32);
    let fields = [
        ("x", 0, datatype::FLOAT32),
        ("y", 4, datatype::FLOAT32),
        ("z", 8, datatype::FLOAT32),
        ("intensity", 12, datatype::FLOAT32),
        ("ring", 16, datatype::UINT16),
        ("time", 18, datatype::FLOAT32),
    ];
    w.u32(fields.len() as u32);
    for (name, off, t) in fields {
        w.string(name);
        w.u32(off);
        w.u8(t);
        w.u32(1);
    }
    w.u8(0);
    w.u32(STEP as u32);
    w.u32((POINTS * STEP) as u32);
    w.bytes_from(data.len(), std::iter::once(&data[..]));
    w.u8(1);
    w.finish()
}

/// Writes `seconds` of the drive to `out`.
pub fn write_bag<W: Write + Seek>(out: W, seconds: u64) -> mcap::McapResult<()> {
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .profile("ros2")
        .create(out)?;
    let chan = |w: &mut mcap::Writer<W>, topic: &str, ty: &str| -> mcap::McapResult<u16> {
        let s = w.add_schema(
            ty,
            schemas::ROS2MSG,
            schemas::ros2msg(ty).unwrap_or_default().as_bytes(),
        )?;
        w.add_channel(s, topic, schemas::CDR, &BTreeMap::new())
    };
    let g = chan(&mut w, "/dms/gaze", schemas::VECTOR3_STAMPED)?;
    let c = chan(&mut w, "/lidar/points", schemas::POINT_CLOUD2)?;
    let o = chan(&mut w, "/chatter", schemas::STRING)?;
    let t0: u64 = 1_700_000_000_000_000_000;
    let mut seq = 0u32;
    let mut put = |w: &mut mcap::Writer<W>, ch: u16, t: u64, data: &[u8]| {
        seq += 1;
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: ch,
                sequence: seq,
                log_time: t,
                publish_time: t,
            },
            data,
        )
    };
    // 10 ms ticks: gaze every tick, a cloud every 10th, chatter every 100th.
    for k in 0..seconds * 100 {
        let t = t0 + k * 10_000_000;
        if k % 500 >= 50 {
            let yaw = (k / 150 % 3) as f64 * 40.0 + 60.0;
            let (s, cs) = yaw.to_radians().sin_cos();
            let v = Vector3Stamped {
                header: header(t, "base_link"),
                xyz: [cs, s, 0.0],
            };
            put(&mut w, g, t, &v.encode())?;
        }
        if k % 10 == 5 {
            put(&mut w, c, t, &cloud(t, k / 10))?;
        }
        if k % 100 == 0 {
            let mut s = cdr::Writer::new(16);
            s.string("hello");
            put(&mut w, o, t, &s.finish())?;
        }
    }
    w.finish()?;
    Ok(())
}
