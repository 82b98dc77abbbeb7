//! `gaze-lidar replay` on a bag written here with the mcap crate
//! (no Python needed), read back with the mcap crate.

use crate::common;
use crate::independent;

use std::collections::BTreeMap;
use std::io::Cursor;
use std::process::Command;

use gaze_lidar::checker::certify;
use gaze_lidar::pointcloud::{keep_mask, CloudFrame, CloudOptions};
use gaze_lidar::profile::Profile;
use gaze_lidar::replay::cdr::{self, datatype, Header, PointCloud2, Vector3Stamped};
use gaze_lidar::replay::schemas;
use mcap::records::MessageHeader;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const GAZE: &str = "/dms/gaze";
const CLOUD: &str = "/lidar/points";
const OTHER: &str = "/chatter";

/// A cloud of `n` points, float32 x, y, z and a float32 intensity (16-byte
/// points), some beyond the rated range.
fn cloud_msg(sec: i32, nanosec: u32, seed: u64, n: usize) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut data = Vec::with_capacity(16 * n);
    for _ in 0..n {
        let az = rng.random::<f64>() * std::f64::consts::TAU;
        let r = 1.0 + rng.random::<f64>() * 130.0;
        for v in [r * az.cos(), r * az.sin(), rng.random::<f64>() - 0.5, 7.0] {
            data.extend_from_slice(&(v as f32).to_le_bytes());
        }
    }
    let mut w = cdr::Writer::new(data.len() + 128);
    Header {
        sec,
        nanosec,
        frame_id: "lidar",
    }
    .write(&mut w);
    w.u32(1);
    w.u32(n as u32);
    w.u32(4);
    for (i, name) in ["x", "y", "z", "intensity"].iter().enumerate() {
        w.string(name);
        w.u32(4 * i as u32);
        w.u8(datatype::FLOAT32);
        w.u32(1);
    }
    w.u8(0);
    w.u32(16);
    w.u32(16 * n as u32);
    w.bytes_from(data.len(), std::iter::once(&data[..]));
    w.u8(1);
    w.finish()
}

/// A channel on `topic` of the ROS 2 message type `ty` (its `ros2msg`
/// schema, CDR encoding, no metadata).
fn channel<W: std::io::Write + std::io::Seek>(
    w: &mut mcap::Writer<W>,
    topic: &str,
    ty: &str,
) -> u16 {
    let s = w
        .add_schema(
            ty,
            schemas::ROS2MSG,
            schemas::ros2msg(ty).unwrap().as_bytes(),
        )
        .unwrap();
    w.add_channel(s, topic, schemas::CDR, &BTreeMap::new())
        .unwrap()
}

/// Clouds at 10 Hz for 3 s, gaze at 100 Hz looking left with a gap from
/// 1.0 s to 1.5 s, an unrelated topic at 2 Hz; one gaze sample written out
/// of order and one duplicate timestamp.
fn bag(compression: Option<mcap::Compression>) -> Vec<u8> {
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .compression(compression)
        .chunk_size(Some(64 * 1024))
        .profile("ros2")
        .create(Cursor::new(&mut buf))
        .unwrap();
    let g = channel(&mut w, GAZE, schemas::VECTOR3_STAMPED);
    let c = channel(&mut w, CLOUD, schemas::POINT_CLOUD2);
    let o = channel(&mut w, OTHER, schemas::STRING);
    let t0: u64 = 1_700_000_000_000_000_000;
    let mut msgs: Vec<(u64, u16, Vec<u8>)> = Vec::new();
    for k in 0..300u64 {
        let t = k * 10_000_000;
        if (100..150).contains(&k) {
            continue;
        }
        let v = Vector3Stamped {
            header: Header {
                sec: ((t0 + t) / 1_000_000_000) as i32,
                nanosec: ((t0 + t) % 1_000_000_000) as u32,
                frame_id: "base_link",
            },
            xyz: [0.0, 1.0, 0.01 * (k % 3) as f64],
        };
        msgs.push((t0 + t, g, v.encode()));
    }
    for k in 0..30u64 {
        let t = t0 + k * 100_000_000 + 3_000_000;
        msgs.push((
            t,
            c,
            cloud_msg(
                (t / 1_000_000_000) as i32,
                (t % 1_000_000_000) as u32,
                k,
                3000,
            ),
        ));
    }
    for k in 0..6u64 {
        let mut s = cdr::Writer::new(16);
        s.string(&format!("hello {k}"));
        msgs.push((t0 + k * 500_000_000, o, s.finish()));
    }
    msgs.sort_by_key(|m| m.0);
    // Out of order (by 30 ms, inside the reorder window) and a duplicate time.
    msgs.swap(20, 23);
    let dup = msgs[40].clone();
    msgs.insert(41, (dup.0, dup.1, dup.2));
    for (seq, (t, ch, data)) in msgs.iter().enumerate() {
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: *ch,
                sequence: seq as u32,
                log_time: *t,
                publish_time: *t,
            },
            data,
        )
        .unwrap();
    }
    w.finish().unwrap();
    drop(w);
    buf
}

struct Msg {
    topic: String,
    schema: String,
    encoding: String,
    log_time: u64,
    data: Vec<u8>,
}

fn read_all(bytes: &[u8]) -> Vec<Msg> {
    mcap::MessageStream::new(bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            Msg {
                topic: m.channel.topic.clone(),
                schema: m
                    .channel
                    .schema
                    .as_ref()
                    .map_or(String::new(), |s| format!("{} {}", s.encoding, s.name)),
                encoding: m.channel.message_encoding.clone(),
                log_time: m.log_time,
                data: m.data.into_owned(),
            }
        })
        .collect()
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gaze-lidar"))
}

/// The gaze and cloud topics of [`bag`].
const TOPICS: [&str; 4] = ["--gaze-topic", GAZE, "--cloud-topic", CLOUD];
/// The topics of [`tf_bag`]: the gaze is a yaw on `/yaw`.
const YAW_TOPICS: [&str; 5] = [
    "--gaze-topic",
    "/yaw",
    "--gaze-yaw-deg",
    "--cloud-topic",
    CLOUD,
];

/// `gaze-lidar replay INPUT ARGS… EXTRA… --out OUT`, run to its end.
fn replay_with(
    input: &std::path::Path,
    args: &[&str],
    extra: &[&str],
    out: impl AsRef<std::ffi::OsStr>,
) -> std::process::Output {
    bin()
        .arg("replay")
        .arg(input)
        .args(args)
        .args(extra)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn replay_copies_every_message_adapts_every_cloud_and_fails_safe_through_the_gap() {
    let dir = tempfile::tempdir().unwrap();
    for (name, compression) in [
        ("plain", None),
        ("lz4", Some(mcap::Compression::Lz4)),
        ("zstd", Some(mcap::Compression::Zstd)),
    ] {
        let input = dir.path().join(format!("{name}.mcap"));
        let out = dir.path().join(format!("{name}-out.mcap"));
        let bag = bag(compression);
        std::fs::write(&input, &bag).unwrap();
        let o = run_replay(&input, &out, &[]);
        common::no_panic(&o, "replay");
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let inp = read_all(&bag);
        let got = read_all(&std::fs::read(&out).unwrap());
        // Every input message, byte for byte, on its topic and time.
        let key = |m: &Msg| (m.topic.clone(), m.log_time, m.data.clone());
        let mut want: Vec<_> = inp.iter().map(key).collect();
        let mut have: Vec<_> = got
            .iter()
            .filter(|m| [GAZE, CLOUD, OTHER].contains(&m.topic.as_str()))
            .map(key)
            .collect();
        want.sort();
        have.sort();
        assert_eq!(want, have);
        // Schemas embedded.
        for m in &got {
            match m.topic.as_str() {
                "/gaze_lidar/profile" => {
                    assert_eq!(m.schema, "ros2msg std_msgs/msg/String");
                    assert_eq!(m.encoding, "cdr");
                }
                "/gaze_lidar/scene" => {
                    assert_eq!(m.schema, "ros2msg visualization_msgs/msg/MarkerArray");
                    assert_eq!(m.encoding, "cdr");
                    // Two markers; the first (a triangle list) has points.
                    assert_eq!(&m.data[4..8], &2u32.to_le_bytes());
                    assert!(m.data.len() > 1000, "{}", m.data.len());
                }
                t => {
                    assert!(m.schema.starts_with("ros2msg "), "{t}: {}", m.schema);
                    assert_eq!(m.encoding, "cdr");
                }
            }
        }
        // Profiles: each certified again, fail-safe through the gap.
        let profiles: Vec<(u64, gaze_lidar::checker::CertifiedProfile)> = got
            .iter()
            .filter(|m| m.topic == "/gaze_lidar/profile")
            .map(|m| {
                let p =
                    Profile::from_json(cdr::decode_string(&m.data).unwrap(), "profile").unwrap();
                assert!(independent::recheck(&p).is_empty());
                (m.log_time, certify(p).unwrap())
            })
            .collect();
        let t0 = inp.iter().map(|m| m.log_time).min().unwrap();
        let at = |s: f64| t0 + (s * 1e9) as u64;
        assert!(profiles.len() >= 55, "{} frames", profiles.len());
        let gaze_of = |lo: f64, hi: f64| {
            profiles
                .iter()
                .filter(|(t, _)| *t >= at(lo) && *t < at(hi))
                .map(|(_, p)| p.profile().gaze_deg)
                .collect::<Vec<_>>()
        };
        let before = gaze_of(0.3, 0.95);
        assert!(
            !before.is_empty()
                && before
                    .iter()
                    .all(|g| g.is_some_and(|g| (g - 90.0).abs() < 1.0))
        );
        let gap = gaze_of(1.15, 1.5);
        assert!(
            !gap.is_empty() && gap.iter().all(Option::is_none),
            "{gap:?}"
        );
        assert!(gaze_of(1.8, 2.9).iter().all(Option::is_some));
        // One adapted cloud per input cloud, a subset in order, the rule's mask.
        let clouds_in: Vec<&Msg> = inp.iter().filter(|m| m.topic == CLOUD).collect();
        let adapted: Vec<&Msg> = got
            .iter()
            .filter(|m| m.topic == "/lidar/points/adapted")
            .collect();
        assert_eq!(adapted.len(), clouds_in.len());
        let mut thinned = 0;
        for (k, (a, c)) in adapted.iter().zip(&clouds_in).enumerate() {
            assert_eq!(a.log_time, c.log_time);
            assert_eq!(a.schema, format!("ros2msg {}", schemas::POINT_CLOUD2));
            let src = PointCloud2::decode(&c.data).unwrap();
            let sl = src.xyz().unwrap();
            let dst = PointCloud2::decode(&a.data).unwrap();
            let dl = dst.xyz().unwrap();
            let (_, profile) = profiles
                .iter()
                .rev()
                .find(|(t, _)| *t <= a.log_time)
                .unwrap();
            let pts: Vec<[f64; 3]> = (0..sl.len())
                .map(|i| sl.xyz(sl.point(src.data, i)))
                .collect();
            let mut opts = CloudOptions::new(100.0);
            opts.frame = CloudFrame::Iso8855;
            opts.seed = k as u64;
            let mask = keep_mask(profile, pts.iter().copied(), &opts).unwrap();
            let want: Vec<&[u8]> = (0..sl.len())
                .filter(|&i| mask[i])
                .map(|i| sl.point(src.data, i))
                .collect();
            let have: Vec<&[u8]> = (0..dl.len()).map(|i| dl.point(dst.data, i)).collect();
            assert_eq!(want, have, "cloud {k}");
            assert!(have.len() < sl.len());
            thinned += sl.len() - have.len();
        }
        assert!(thinned > 0);
    }
}

#[test]
fn a_truncated_or_corrupt_bag_is_exit_2_naming_the_offset_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bag = bag(None);
    let out = dir.path().join("out.mcap");
    std::fs::write(&out, b"old").unwrap();
    let input = dir.path().join("cut.mcap");
    std::fs::write(&input, &bag[..bag.len() / 2]).unwrap();
    let o = run_replay(&input, &out, &[]);
    common::no_panic(&o, "truncated");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("at byte "), "{err}");
    assert!(
        err.contains(&format!("truncated after {} bytes", bag.len() / 2)),
        "{err}"
    );
    assert_eq!(std::fs::read(&out).unwrap(), b"old");
    // A flipped byte inside the data: a CRC or parse error, exit 2.
    let mut bad = bag.clone();
    let mid = bag.len() / 3;
    bad[mid] ^= 0xFF;
    std::fs::write(&input, &bad).unwrap();
    let o = run_replay(&input, &out, &[]);
    common::no_panic(&o, "corrupt");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("at byte "), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), b"old");
    // No temporary file left beside the output.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with(".gaze-lidar-replay"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // Not an MCAP at all.
    std::fs::write(&input, b"hello").unwrap();
    let o = run_replay(&input, &out, &[]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_topic_of_the_wrong_type_is_exit_2_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let out = dir.path().join("out.mcap");
    let o = replay_with(
        &input,
        &["--gaze-topic", CLOUD, "--cloud-topic", GAZE],
        &[],
        &out,
    );
    common::no_panic(&o, "wrong type");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("/lidar/points") || err.contains("/dms/gaze"),
        "{err}"
    );
    assert!(!out.exists());
    // --out is the input.
    let o = run_replay(&input, &input, &[]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn replay_is_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(Some(mcap::Compression::Lz4))).unwrap();
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    assert_eq!(run_replay(&input, &a, &[]).status.code(), Some(0));
    assert_eq!(run_replay(&input, &b, &[]).status.code(), Some(0));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // Compressed output (zstd, lz4): the same messages, deterministic too.
    let plain = read_all(&std::fs::read(&a).unwrap());
    for c in ["zstd", "lz4"] {
        let runs: Vec<Vec<u8>> = (0..2)
            .map(|k| {
                let out = dir.path().join(format!("{c}{k}.mcap"));
                let o = run_replay(&input, &out, &["--compression", c]);
                assert_eq!(
                    o.status.code(),
                    Some(0),
                    "{}",
                    String::from_utf8_lossy(&o.stderr)
                );
                std::fs::read(&out).unwrap()
            })
            .collect();
        assert_eq!(runs[0], runs[1], "{c}");
        assert_ne!(runs[0], std::fs::read(&a).unwrap(), "{c}: not compressed");
        let got = read_all(&runs[0]);
        let key = |m: &Msg| (m.topic.clone(), m.log_time, m.data.clone());
        assert_eq!(
            got.iter().map(key).collect::<Vec<_>>(),
            plain.iter().map(key).collect::<Vec<_>>(),
            "{c}"
        );
    }
}

/// A bag with `/tf_static` (`base_link` → `roof` → `lidar`, given by
/// `mounts`: (parent, child, quaternion xyzw)), gaze as Float64 yaw 90° at
/// 100 Hz and clouds in the `lidar` frame at 10 Hz.
fn tf_bag(mounts: &[(&str, &str, [f64; 4])]) -> Vec<u8> {
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .create(Cursor::new(&mut buf))
        .unwrap();
    let tf = channel(&mut w, "/tf_static", schemas::TF_MESSAGE);
    let g = channel(&mut w, "/yaw", schemas::FLOAT64);
    let c = channel(&mut w, CLOUD, schemas::POINT_CLOUD2);
    let t0: u64 = 5_000_000_000;
    let transforms: Vec<cdr::TransformStamped> = mounts
        .iter()
        .map(|(parent, child, q)| cdr::TransformStamped {
            header: Header {
                sec: 5,
                nanosec: 0,
                frame_id: parent,
            },
            child_frame_id: child,
            translation: [1.0, 0.0, 1.8],
            rotation_xyzw: *q,
        })
        .collect();
    let header = |ch, k: u64, t| MessageHeader {
        channel_id: ch,
        sequence: k as u32,
        log_time: t,
        publish_time: t,
    };
    w.write_to_known_channel(&header(tf, 0, t0), &cdr::encode_tf_message(&transforms))
        .unwrap();
    for k in 0..60u64 {
        let t = t0 + k * 10_000_000;
        w.write_to_known_channel(&header(g, k, t), &cdr::encode_float64(90.0))
            .unwrap();
        if k % 10 == 5 {
            w.write_to_known_channel(&header(c, k, t), &cloud_msg(5, 0, k, 3000))
                .unwrap();
        }
    }
    w.finish().unwrap();
    drop(w);
    buf
}

/// A rotation of `deg` about the unit axis `a`, as a quaternion xyzw.
fn axis_angle(a: [f64; 3], deg: f64) -> [f64; 4] {
    let h = deg.to_radians() / 2.0;
    [a[0] * h.sin(), a[1] * h.sin(), a[2] * h.sin(), h.cos()]
}

/// Replays `bag` (`/yaw` gaze, `extra` options) and checks every adapted
/// cloud against the rule's mask on the cloud turned by `yaw_deg`.
fn check_mounting(bag: &[u8], extra: &[&str], yaw_deg: f64) -> String {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    std::fs::write(&input, bag).unwrap();
    let o = replay_with(&input, &YAW_TOPICS, extra, &out);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(0), "{err}");
    let got = read_all(&std::fs::read(&out).unwrap());
    let profiles: Vec<(u64, gaze_lidar::checker::CertifiedProfile)> = got
        .iter()
        .filter(|m| m.topic == "/gaze_lidar/profile")
        .map(|m| {
            let p = Profile::from_json(cdr::decode_string(&m.data).unwrap(), "p").unwrap();
            (m.log_time, certify(p).unwrap())
        })
        .collect();
    let clouds: Vec<&Msg> = got.iter().filter(|m| m.topic == CLOUD).collect();
    let adapted: Vec<&Msg> = got
        .iter()
        .filter(|m| m.topic == "/lidar/points/adapted")
        .collect();
    assert_eq!((clouds.len(), adapted.len()), (6, 6));
    let (s, c) = yaw_deg.to_radians().sin_cos();
    let mut adaptive = 0;
    for (k, (a, cl)) in adapted.iter().zip(&clouds).enumerate() {
        let src = PointCloud2::decode(&cl.data).unwrap();
        let sl = src.xyz().unwrap();
        let dst = PointCloud2::decode(&a.data).unwrap();
        let dl = dst.xyz().unwrap();
        let (_, profile) = profiles
            .iter()
            .rev()
            .find(|(t, _)| *t <= a.log_time)
            .unwrap();
        adaptive += usize::from(profile.profile().gaze_deg.is_some());
        let turned: Vec<[f64; 3]> = (0..sl.len())
            .map(|i| {
                let [x, y, z] = sl.xyz(sl.point(src.data, i));
                [c * x - s * y, s * x + c * y, z]
            })
            .collect();
        let mut opts = CloudOptions::new(100.0);
        opts.frame = CloudFrame::Iso8855;
        opts.seed = k as u64;
        let mask = keep_mask(profile, turned.iter().copied(), &opts).unwrap();
        let want: Vec<&[u8]> = (0..sl.len())
            .filter(|&i| mask[i])
            .map(|i| sl.point(src.data, i))
            .collect();
        let have: Vec<&[u8]> = (0..dl.len()).map(|i| dl.point(dst.data, i)).collect();
        assert_eq!(want, have, "cloud {k}, yaw {yaw_deg}");
    }
    assert!(adaptive >= 4, "{adaptive} adaptive clouds");
    err
}

#[test]
fn the_mounting_yaw_comes_from_tf_static_unless_given() {
    let z = [0.0, 0.0, 1.0];
    // base_link → roof: 60° yaw; roof → lidar: 30° yaw, then a 2° roll
    // about the lidar's own x axis.
    let roll = axis_angle([1.0, 0.0, 0.0], 2.0);
    let lidar = gaze_lidar::replay::tf::mul(axis_angle(z, 30.0), roll);
    let bag = tf_bag(&[
        ("base_link", "roof", axis_angle(z, 60.0)),
        ("roof", "lidar", lidar),
    ]);
    // The yaw of the lidar's x axis in base_link: 90° (the roll about it
    // leaves it where it is).
    check_mounting(&bag, &[], 90.0);
    // --sensor-yaw-deg wins over the bag.
    check_mounting(&bag, &["--sensor-yaw-deg", "0"], 0.0);
    check_mounting(&bag, &["--sensor-yaw-deg", "-45"], -45.0);
    // Another vehicle frame: the roof (lidar 30° from it).
    check_mounting(&bag, &["--vehicle-frame", "roof"], 30.0);
    // No transform to the vehicle frame: no yaw, and a warning naming it.
    let err = check_mounting(&bag, &["--vehicle-frame", "map"], 0.0);
    assert!(
        err.contains("6 clouds not in the vehicle frame \"map\""),
        "{err}"
    );
    // The transform given with its parent and child the other way round.
    let inv = axis_angle(z, -90.0);
    check_mounting(&tf_bag(&[("lidar", "base_link", inv)]), &[], 90.0);
}

#[test]
fn a_tilted_static_transform_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    // A 10° pitch under a 30° yaw: beyond the 5° default tolerance.
    let q = gaze_lidar::replay::tf::mul(
        axis_angle([0.0, 0.0, 1.0], 30.0),
        axis_angle([0.0, 1.0, 0.0], 10.0),
    );
    std::fs::write(&input, tf_bag(&[("base_link", "lidar", q)])).unwrap();
    let run = |extra: &[&str]| replay_with(&input, &YAW_TOPICS, extra, &out);
    let o = run(&[]);
    common::no_panic(&o, "tilted");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("/tf_static") && err.contains("\"lidar\""),
        "{err}"
    );
    assert!(err.contains("10.000°"), "{err}");
    assert!(err.contains(&format!("met at {CLOUD}: message")), "{err}");
    assert!(!out.exists());
    // A wider tolerance, or the yaw given, lets it through.
    assert_eq!(run(&["--max-mount-tilt-deg", "12"]).status.code(), Some(0));
    assert_eq!(run(&["--sensor-yaw-deg", "30"]).status.code(), Some(0));
    // A zero quaternion: exit 2 naming the transform.
    std::fs::write(&input, tf_bag(&[("base_link", "lidar", [0.0; 4])])).unwrap();
    let o = run(&[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("transform lidar in base_link"), "{err}");
}

/// `bag(None)` replayed from `dir/in.mcap` to `dir/out.mcap` under a
/// file-size limit (`ulimit -f`, SIGXFSZ ignored, so the write fails with
/// EFBIG as on a full disk): the output path and the run.
fn replay_past_the_file_size_limit(
    dir: &std::path::Path,
) -> (std::path::PathBuf, std::process::Output) {
    let input = dir.join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let out = dir.join("out.mcap");
    let o = Command::new("sh")
        .arg("-c")
        // 64 blocks of 512 or 1024 bytes: far less than the output.
        .arg("trap '' XFSZ; ulimit -f 64 && exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_gaze-lidar"))
        .arg("replay")
        .arg(&input)
        .args(["--gaze-topic", GAZE, "--cloud-topic", CLOUD, "--out"])
        .arg(&out)
        .output()
        .unwrap();
    (out, o)
}

/// A full disk (here: the file-size limit, `ulimit -f`, with SIGXFSZ
/// ignored so the write fails with EFBIG) is exit 1 with no output file
/// and no temporary file left.
#[test]
fn a_full_disk_leaves_no_partial_output() {
    let dir = tempfile::tempdir().unwrap();
    let (out, o) = replay_past_the_file_size_limit(dir.path());
    common::no_panic(&o, "full disk");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("output"), "{err}");
    assert!(!out.exists());
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n != "in.mcap")
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn float64_yaw_gaze_and_a_mounting_yaw() {
    // Gaze as std_msgs/Float64 yaw (90° = left) at 100 Hz, clouds at 10 Hz
    // from a sensor turned 90° left: a cloud point at sensor azimuth β is at
    // β + 90° for the profile.
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .create(Cursor::new(&mut buf))
        .unwrap();
    let g = channel(&mut w, "/yaw", schemas::FLOAT64);
    let c = channel(&mut w, CLOUD, schemas::POINT_CLOUD2);
    let t0: u64 = 5_000_000_000;
    for k in 0..100u64 {
        let t = t0 + k * 10_000_000;
        let header = |ch| MessageHeader {
            channel_id: ch,
            sequence: k as u32,
            log_time: t,
            publish_time: t,
        };
        w.write_to_known_channel(&header(g), &cdr::encode_float64(90.0))
            .unwrap();
        if k % 10 == 5 {
            w.write_to_known_channel(&header(c), &cloud_msg(5, 0, k, 3000))
                .unwrap();
        }
    }
    w.finish().unwrap();
    drop(w);
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    std::fs::write(&input, &buf).unwrap();
    let o = replay_with(
        &input,
        &YAW_TOPICS,
        &["--sensor-yaw-deg", "90", "--seed", "7"],
        &out,
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let got = read_all(&std::fs::read(&out).unwrap());
    let profiles: Vec<(u64, gaze_lidar::checker::CertifiedProfile)> = got
        .iter()
        .filter(|m| m.topic == "/gaze_lidar/profile")
        .map(|m| {
            let p = Profile::from_json(cdr::decode_string(&m.data).unwrap(), "p").unwrap();
            (m.log_time, certify(p).unwrap())
        })
        .collect();
    assert!(profiles
        .iter()
        .filter(|(t, _)| *t > t0 + 100_000_000)
        .all(|(_, p)| p.profile().gaze_deg == Some(90.0)));
    let clouds: Vec<&Msg> = got.iter().filter(|m| m.topic == CLOUD).collect();
    let adapted: Vec<&Msg> = got
        .iter()
        .filter(|m| m.topic == "/lidar/points/adapted")
        .collect();
    assert_eq!(clouds.len(), 10);
    assert_eq!(adapted.len(), 10);
    let (s, c) = 90f64.to_radians().sin_cos();
    for (k, (a, cl)) in adapted.iter().zip(&clouds).enumerate() {
        let src = PointCloud2::decode(&cl.data).unwrap();
        let sl = src.xyz().unwrap();
        let dst = PointCloud2::decode(&a.data).unwrap();
        let dl = dst.xyz().unwrap();
        let (_, profile) = profiles
            .iter()
            .rev()
            .find(|(t, _)| *t <= a.log_time)
            .unwrap();
        let turned: Vec<[f64; 3]> = (0..sl.len())
            .map(|i| {
                let [x, y, z] = sl.xyz(sl.point(src.data, i));
                [c * x - s * y, s * x + c * y, z]
            })
            .collect();
        let mut opts = CloudOptions::new(100.0);
        opts.frame = CloudFrame::Iso8855;
        opts.seed = 7 + k as u64;
        let mask = keep_mask(profile, turned.iter().copied(), &opts).unwrap();
        let want: Vec<&[u8]> = (0..sl.len())
            .filter(|&i| mask[i])
            .map(|i| sl.point(src.data, i))
            .collect();
        let have: Vec<&[u8]> = (0..dl.len()).map(|i| dl.point(dst.data, i)).collect();
        assert_eq!(want, have, "cloud {k}");
    }
}

#[test]
fn devices_fifos_and_symlinks_as_out_are_written_through_never_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let plain = dir.path().join("plain.mcap");
    let o = run_replay(&input, &plain, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let expected = std::fs::read(&plain).unwrap();

    // Character devices stay devices (private nodes, made where this user
    // may: a regression must not replace the system's /dev/null).
    let node = |name: &str, minor: &str| {
        let p = dir.path().join(name);
        let made = Command::new("mknod")
            .arg(&p)
            .args(["c", "1", minor])
            .output();
        made.is_ok_and(|m| m.status.success()).then_some(p)
    };
    if let Some(null) = node("null", "3") {
        let o = run_replay(&input, &null, &[]);
        common::no_panic(&o, "null device");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(std::fs::symlink_metadata(&null)
            .unwrap()
            .file_type()
            .is_char_device());
    }
    if let Some(full) = node("full", "7") {
        // A full device is an output error, exit 1.
        let o = run_replay(&input, &full, &[]);
        common::no_panic(&o, "full device");
        assert_eq!(
            o.status.code(),
            Some(1),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(std::fs::symlink_metadata(&full)
            .unwrap()
            .file_type()
            .is_char_device());
    }

    // A FIFO gets the same bytes as a file, and stays a FIFO.
    let fifo = dir.path().join("fifo");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let o = run_replay(&input, &fifo, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(reader.join().unwrap(), expected);
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());

    // A symbolic link is followed: the link stays, its target is replaced.
    let target = dir.path().join("target.mcap");
    std::fs::write(&target, b"old").unwrap();
    let link = dir.path().join("link.mcap");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let o = run_replay(&input, &link, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read(&target).unwrap(), expected);
}

#[test]
fn out_equal_to_the_config_file_is_exit_2_and_leaves_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let config = dir.path().join("cfg.toml");
    let text = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/configs/paper.toml"
    ))
    .unwrap();
    std::fs::write(&config, &text).unwrap();
    let o = bin()
        .arg("replay")
        .arg(&input)
        .args(["--gaze-topic", GAZE, "--cloud-topic", CLOUD, "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&config)
        .output()
        .unwrap();
    common::no_panic(&o, "out = config");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--config"), "{err}");
    assert_eq!(std::fs::read(&config).unwrap(), text);
}

/// `bag` read back and written again after `edit` changed its messages
/// (topic, schema name, log_time, data, sequence), with the attachments
/// and metadata records `extra` adds.
fn rewrite(
    bag: &[u8],
    edit: impl FnOnce(&mut Vec<mcap::Message<'static>>),
    extra: impl FnOnce(&mut mcap::Writer<Cursor<&mut Vec<u8>>>),
) -> Vec<u8> {
    let mut msgs: Vec<mcap::Message<'static>> = mcap::MessageStream::new(bag)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            mcap::Message {
                channel: std::sync::Arc::new(mcap::Channel {
                    id: m.channel.id,
                    topic: m.channel.topic.clone(),
                    schema: m.channel.schema.as_ref().map(|s| {
                        std::sync::Arc::new(mcap::Schema {
                            id: s.id,
                            name: s.name.clone(),
                            encoding: s.encoding.clone(),
                            data: std::borrow::Cow::Owned(s.data.to_vec()),
                        })
                    }),
                    message_encoding: m.channel.message_encoding.clone(),
                    metadata: m.channel.metadata.clone(),
                }),
                sequence: m.sequence,
                log_time: m.log_time,
                publish_time: m.publish_time,
                data: std::borrow::Cow::Owned(m.data.into_owned()),
            }
        })
        .collect();
    edit(&mut msgs);
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .chunk_size(Some(64 * 1024))
        .create(Cursor::new(&mut buf))
        .unwrap();
    extra(&mut w);
    for m in &msgs {
        w.write(m).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    buf
}

fn run_replay(
    input: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> std::process::Output {
    let mut args = TOPICS.to_vec();
    args.extend(["--preset", "paper", "--mode", "range"]);
    let o = replay_with(input, &args, extra, out);
    common::no_panic(&o, "replay");
    o
}

/// The messages a replay adds (adapted clouds, profiles, scenes): (topic,
/// log_time, data), in the order written.
fn added(out: &[u8]) -> Vec<(String, u64, Vec<u8>)> {
    read_all(out)
        .into_iter()
        .filter(|m| ![GAZE, CLOUD, OTHER].contains(&m.topic.as_str()))
        .map(|m| (m.topic, m.log_time, m.data))
        .collect()
}

/// stderr without the program's `gaze-lidar: error: ` prefix.
fn message(o: &std::process::Output) -> String {
    let e = String::from_utf8_lossy(&o.stderr);
    e.strip_prefix("gaze-lidar: error: ")
        .unwrap_or(&e)
        .to_owned()
}

#[test]
fn output_topics_that_collide_with_inputs_or_each_other_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let (once, twice) = (dir.path().join("once.mcap"), dir.path().join("twice.mcap"));
    assert_eq!(run_replay(&input, &once, &[]).status.code(), Some(0));
    // Replaying the output again: its adapted, profile and scene topics are
    // input topics now; refused (exit 2) naming the option.
    let o = run_replay(&once, &twice, &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.starts_with(
            "--profile-topic: \"/gaze_lidar/profile\" is also a topic of the input bag"
        ) || err.starts_with("--adapted-topic: \"/lidar/points/adapted\" is also a topic")
            || err.starts_with("--scene-topic: \"/gaze_lidar/scene\" is also a topic"),
        "{err}"
    );
    assert!(!twice.exists());
    // With new output topics it runs, and no topic has two channels.
    let new_topics = [
        "--adapted-topic",
        "/a2",
        "--profile-topic",
        "/p2",
        "--scene-topic",
        "/s2",
    ];
    let o = run_replay(&once, &twice, &new_topics);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let bytes = std::fs::read(&twice).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut topics: Vec<&str> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    let n = topics.len();
    topics.sort_unstable();
    topics.dedup();
    assert_eq!(topics.len(), n, "{topics:?}");
    // Output topics equal to each other or to an input topic.
    for (args, flag) in [
        (
            &["--profile-topic", "/gaze_lidar/scene"][..],
            "--scene-topic",
        ),
        (
            &["--adapted-topic", "/x", "--scene-topic", "/x"][..],
            "--scene-topic",
        ),
        (&["--adapted-topic", GAZE][..], "--adapted-topic"),
        (&["--profile-topic", "/tf_static"][..], "--profile-topic"),
        // The transform topic may not be an input topic either.
        (&["--tf-topic", CLOUD][..], "--tf-topic"),
        (&["--tf-topic", GAZE][..], "--tf-topic"),
    ] {
        let o = run_replay(&input, &twice, args);
        let err = message(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.starts_with(flag), "{args:?}: {err}");
    }
}

#[test]
fn out_dash_is_stdout_and_a_missing_folder_is_exit_2_naming_out() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let file = dir.path().join("file.mcap");
    assert_eq!(run_replay(&input, &file, &[]).status.code(), Some(0));
    let o = bin()
        .current_dir(dir.path())
        .arg("replay")
        .arg(&input)
        .args(["--gaze-topic", GAZE, "--cloud-topic", CLOUD])
        .args(["--preset", "paper", "--mode", "range", "--out", "-"])
        .output()
        .unwrap();
    common::no_panic(&o, "stdout");
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(o.stdout, std::fs::read(&file).unwrap());
    assert!(!dir.path().join("-").exists());
    // A bad input writes nothing to stdout.
    std::fs::write(&input, b"not an mcap").unwrap();
    let o = replay_with(&input, &TOPICS, &[], "-");
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    // A missing output folder: bad input, named.
    std::fs::write(&input, bag(None)).unwrap();
    let o = run_replay(&input, &dir.path().join("no/such/dir/out.mcap"), &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.starts_with("--out: "), "{err}");
    assert!(err.contains("no/such/dir"), "{err}");
}

#[test]
fn a_far_future_stamp_or_reordered_clouds_do_not_change_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let plain = bag(None);
    let t0 = read_all(&plain).iter().map(|m| m.log_time).min().unwrap();
    let clouds = |msgs: &[mcap::Message<'static>]| -> Vec<usize> {
        (0..msgs.len())
            .filter(|&i| msgs[i].channel.topic == CLOUD)
            .collect()
    };
    // Two clouds 100 ms apart written in the other order (inside the
    // 200 ms window), and one message on an unrelated topic stamped a
    // thousand seconds ahead, early in the file.
    let shuffled = rewrite(
        &plain,
        |m| {
            let c = clouds(m);
            m.swap(c[3], c[4]);
            m.swap(c[10], c[11]);
            let mut far = m.iter().find(|x| x.channel.topic == OTHER).unwrap().clone();
            far.log_time = t0 + 1_000_000_000_000;
            m.insert(5, far);
        },
        |_| {},
    );
    let reference = rewrite(
        &plain,
        |m| {
            let mut far = m.iter().find(|x| x.channel.topic == OTHER).unwrap().clone();
            far.log_time = t0 + 1_000_000_000_000;
            m.push(far);
        },
        |_| {},
    );
    let run = |name: &str, bytes: &[u8]| {
        let (i, o) = (
            dir.path().join(format!("{name}.mcap")),
            dir.path().join(format!("{name}-out.mcap")),
        );
        std::fs::write(&i, bytes).unwrap();
        let r = run_replay(&i, &o, &[]);
        assert_eq!(
            r.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&r.stderr)
        );
        added(&std::fs::read(&o).unwrap())
    };
    let want = run("reference", &reference);
    let have = run("shuffled", &shuffled);
    assert!(
        want.iter()
            .filter(|m| m.0 == "/lidar/points/adapted")
            .count()
            == 30
    );
    assert_eq!(want.len(), have.len());
    for (k, (w, h)) in want.iter().zip(&have).enumerate() {
        assert_eq!((&w.0, w.1), (&h.0, h.1), "message {k}");
        assert!(w.2 == h.2, "message {k} on {} differs", w.0);
    }
}

/// Start offsets of the top-level records of an MCAP file.
fn record_starts(b: &[u8]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= b.len() {
        out.push(at);
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap()) as usize;
        let footer = b[at] == 0x02;
        at += 9 + len;
        if footer {
            break;
        }
    }
    out
}

#[test]
fn corruption_is_reported_at_the_bad_records_start_and_data_after_the_footer_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    // Larger than one 1 MiB read, so how far the reader got is not the
    // record's start.
    let bag = rewrite(
        &bag(None),
        |m| {
            let more: Vec<_> = m.clone();
            for (k, mut x) in more.into_iter().enumerate() {
                x.log_time += 4_000_000_000;
                x.sequence = k as u32;
                m.push(x);
            }
        },
        |_| {},
    );
    assert!(bag.len() > 2 << 20, "{}", bag.len());
    let starts = record_starts(&bag);
    let containing = |at: usize| *starts.iter().rev().find(|&&s| s <= at).unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    for frac in [0.2, 0.45, 0.7] {
        let at = (bag.len() as f64 * frac) as usize;
        let mut bad = bag.clone();
        bad[at] ^= 0x5A;
        std::fs::write(&input, &bad).unwrap();
        let o = run_replay(&input, &out, &[]);
        let err = message(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("at byte {}:", containing(at))),
            "flipped byte {at}, record at {}: {err}",
            containing(at)
        );
        // Truncated there.
        std::fs::write(&input, &bag[..at]).unwrap();
        let o = run_replay(&input, &out, &[]);
        let err = message(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("at byte {}:", containing(at))),
            "{err}"
        );
        assert!(
            err.contains(&format!("truncated after {at} bytes")),
            "{err}"
        );
    }
    // Bytes after the end magic.
    let mut long = bag.clone();
    long.extend_from_slice(b"trailing");
    std::fs::write(&input, &long).unwrap();
    let o = run_replay(&input, &out, &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(&format!("at byte {}:", bag.len())), "{err}");
    assert!(err.contains("after the end magic"), "{err}");
    assert!(!out.exists());
}

#[test]
fn float_flags_are_range_checked_by_name_before_the_bag_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("cut.mcap");
    // A truncated bag: an option error must come first.
    let b = bag(None);
    std::fs::write(&input, &b[..b.len() / 2]).unwrap();
    let out = dir.path().join("out.mcap");
    for (flag, values) in [
        ("--fog-mor-m", &["5e-324", "0", "-1", "1e300", "inf"][..]),
        ("--cloud-spin-rad-s", &["5e-324", "0", "-3", "1e9"][..]),
        ("--sensor-yaw-deg", &["5e-324", "1e9", "nan"][..]),
        ("--rated-range-m", &["5e-324", "0", "1.0000001e7"][..]),
        ("--max-mount-tilt-deg", &["5e-324", "91"][..]),
        ("--reorder-window-ms", &["5e-324", "-1", "1e9"][..]),
        ("--timeout-ms", &["5e-324"][..]),
        ("--saccade-deg-s", &["5e-324"][..]),
        ("--bins", &["36000", "1441"][..]),
    ] {
        for v in values {
            let o = run_replay(&input, &out, &[flag, v]);
            let err = message(&o);
            assert_eq!(o.status.code(), Some(2), "{flag} {v}: {err}");
            assert!(err.starts_with(&format!("{flag}: ")), "{flag} {v}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
        }
    }
    // The argus model's fog levels: named by the flag too.
    let o = run_replay(&input, &out, &["--model", "argus", "--fog-mor-m", "150"]);
    let err = message(&o);
    assert!(err.starts_with("--fog-mor-m: "), "{err}");
    // 1440 bins and a rated range of exactly 10⁷ m (the README's upper
    // end, inclusive) are fine.
    std::fs::write(&input, &b).unwrap();
    for args in [&["--bins", "1440"][..], &["--rated-range-m", "1e7"][..]] {
        let o = run_replay(&input, &out, args);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn sequences_attachments_and_metadata_are_copied_and_stamps_are_exact() {
    let dir = tempfile::tempdir().unwrap();
    let plain = bag(None);
    let t0 = read_all(&plain).iter().map(|m| m.log_time).min().unwrap();
    // Sequence numbers of its own, an attachment, a metadata record, and
    // one message on an unrelated topic at log_time 0.
    let rich = rewrite(
        &plain,
        |m| {
            for (k, x) in m.iter_mut().enumerate() {
                x.sequence = 1000 + 7 * k as u32;
            }
            let mut zero = m.iter().find(|x| x.channel.topic == OTHER).unwrap().clone();
            zero.log_time = 0;
            zero.publish_time = 0;
            zero.sequence = 5;
            m.insert(0, zero);
        },
        |w| {
            w.attach(&mcap::Attachment {
                log_time: t0,
                create_time: t0 + 1,
                name: "calibration.yaml".into(),
                media_type: "application/yaml".into(),
                data: std::borrow::Cow::Borrowed(b"lidar: {yaw: 0}\n"),
            })
            .unwrap();
            w.write_metadata(&mcap::records::Metadata {
                name: "rosbag2".into(),
                metadata: BTreeMap::from([("vehicle".to_owned(), "car 7".to_owned())]),
            })
            .unwrap();
        },
    );
    let (i, o) = (
        dir.path().join("rich.mcap"),
        dir.path().join("rich-out.mcap"),
    );
    std::fs::write(&i, &rich).unwrap();
    let r = run_replay(&i, &o, &[]);
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    let got = std::fs::read(&o).unwrap();
    // Sequences kept.
    let seq = |b: &[u8]| -> Vec<(String, u64, u32)> {
        let mut v: Vec<_> = mcap::MessageStream::new(b)
            .unwrap()
            .map(|m| m.unwrap())
            .filter(|m| [GAZE, CLOUD, OTHER].contains(&m.channel.topic.as_str()))
            .map(|m| (m.channel.topic.clone(), m.log_time, m.sequence))
            .collect();
        v.sort();
        v
    };
    assert_eq!(seq(&got), seq(&rich));
    // Attachment and metadata copied.
    let summary = mcap::Summary::read(&got).unwrap().unwrap();
    assert_eq!(summary.attachment_indexes.len(), 1);
    let a = mcap::read::attachment(&got, &summary.attachment_indexes[0]).unwrap();
    assert_eq!(
        (
            a.name.as_str(),
            a.media_type.as_str(),
            &a.data[..],
            a.log_time
        ),
        (
            "calibration.yaml",
            "application/yaml",
            &b"lidar: {yaw: 0}\n"[..],
            t0
        )
    );
    assert_eq!(summary.metadata_indexes.len(), 1);
    let m = mcap::read::metadata(&got, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(m.name, "rosbag2");
    assert_eq!(m.metadata.get("vehicle").map(String::as_str), Some("car 7"));
    // The profile stamps are those of the bag without the message at 0,
    // to the nanosecond.
    let (pi, po) = (
        dir.path().join("plain.mcap"),
        dir.path().join("plain-out.mcap"),
    );
    std::fs::write(&pi, &plain).unwrap();
    assert_eq!(run_replay(&pi, &po, &[]).status.code(), Some(0));
    let stamps = |b: &[u8]| -> Vec<u64> {
        read_all(b)
            .iter()
            .filter(|m| m.topic == "/gaze_lidar/profile")
            .map(|m| m.log_time)
            .collect()
    };
    let want = stamps(&std::fs::read(&po).unwrap());
    assert_eq!(stamps(&got), want);
    // On the frame grid: whole microseconds from the first.
    assert!(want.iter().all(|t| (t - want[0]) % 1000 == 0), "{want:?}");
}

#[path = "../../benches/common/bag.rs"]
#[allow(dead_code)]
mod drive;

/// SIGINT, SIGTERM and SIGHUP during a replay: the temporary output is
/// removed and the exit status is 128 + the signal; an old output stays as
/// it was.
#[test]
fn a_signal_removes_the_temporary_output() {
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("drive.mcap");
    // Six seconds of drive (≈ 300 MB of clouds): the replay runs far longer
    // than the wait for its first output bytes below, even on a free machine.
    drive::write_bag(std::fs::File::create(&input).unwrap(), 6).unwrap();
    let out = dir.path().join("out.mcap");
    std::fs::write(&out, b"old").unwrap();
    let temps = || -> Vec<String> {
        std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with(".gaze-lidar-replay"))
            .collect()
    };
    for (sig, code) in [
        ("INT", 130),
        ("TERM", 143),
        ("HUP", 129),
        ("QUIT", 131),
        ("USR1", 138),
        ("USR2", 140),
        ("ALRM", 142),
        ("XFSZ", 153),
        ("VTALRM", 154),
    ] {
        let mut cmd = bin();
        cmd.arg("replay")
            .arg(&input)
            .args([
                "--gaze-topic",
                "/dms/gaze",
                "--cloud-topic",
                "/lidar/points",
            ])
            .args(["--preset", "vls128", "--out"])
            .arg(&out)
            .stderr(std::process::Stdio::piped());
        // A runner that started these tests with a signal ignored (a
        // non-interactive shell's background job ignores INT and QUIT) passes
        // that on, and the replay keeps a signal ignored at start: the child
        // starts with every tested signal at its default action, so the test
        // is of the replay's handler whoever runs it.
        let tested: Vec<i32> = [
            libc::SIGINT,
            libc::SIGTERM,
            libc::SIGHUP,
            libc::SIGQUIT,
            libc::SIGUSR1,
            libc::SIGUSR2,
            libc::SIGALRM,
            libc::SIGXFSZ,
            libc::SIGVTALRM,
        ]
        .to_vec();
        // SAFETY: the closure runs in the forked child before exec and only
        // calls `signal`, which is async-signal-safe.
        unsafe {
            cmd.pre_exec(move || {
                for &s in &tested {
                    libc::signal(s, libc::SIG_DFL);
                }
                Ok(())
            });
        }
        let mut child = cmd.spawn().unwrap();
        // Wait for the temporary file and for some output in it.
        let start = std::time::Instant::now();
        let written = || {
            temps()
                .iter()
                .any(|n| std::fs::metadata(dir.path().join(n)).is_ok_and(|m| m.len() > 0))
        };
        while !written() {
            assert!(
                start.elapsed().as_secs() < 60,
                "no output in a temporary file"
            );
            assert!(child.try_wait().unwrap().is_none(), "finished too early");
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        assert!(
            child.try_wait().unwrap().is_none(),
            "finished before the signal"
        );
        let k = Command::new("kill")
            .args([format!("-{sig}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(k.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "SIG{sig}: {status:?}");
        assert!(temps().is_empty(), "SIG{sig}: {:?}", temps());
        assert_eq!(std::fs::read(&out).unwrap(), b"old");
    }
}

/// One corrupted opcode byte turns a chunk (or a message) into an
/// "unknown" record, which MCAP readers skip: the replay must not drop its
/// messages and succeed. The summary's statistics count them, so the bag
/// is refused (exit 2) at the statistics record, with no output. The data
/// section's CRC is zeroed ("not computed", as some writers leave it), so
/// only the count can tell.
#[test]
fn a_record_lost_to_a_corrupted_opcode_is_exit_2_not_a_silent_drop() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = bag(None);
    // Top-level records after the 8-byte magic: opcode, u64 length, data.
    let (mut at, mut chunks, mut corrupted) = (8usize, 0, false);
    while at + 9 <= b.len() {
        let op = b[at];
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap()) as usize;
        match op {
            // The second chunk (or the second top-level message).
            0x06 | 0x05 if !corrupted => {
                chunks += 1;
                if chunks == 2 {
                    b[at] = 0xEE;
                    corrupted = true;
                }
            }
            // Data End: its CRC of the data section, zeroed.
            0x0F => b[at + 9..at + 13].fill(0),
            0x02 => break, // the footer
            _ => {}
        }
        at += 9 + len;
    }
    assert!(corrupted, "the fixture has at least two chunks");
    let input = dir.path().join("opcode.mcap");
    std::fs::write(&input, &b).unwrap();
    let out = dir.path().join("out.mcap");
    let o = run_replay(&input, &out, &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("statistics record counts"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out.exists());
}

/// Frames whose adaptive profile cannot be certified run the baseline:
/// `stream` warns per frame, and `replay` says how many in one line (it
/// said nothing, and every frame was fail-safe). The vls128 preset's
/// resolution closed form steps its spin, which the sensor's acceleration
/// limit forbids, so no frame's adaptive profile certifies.
#[test]
fn frames_that_fall_back_to_the_baseline_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let out = dir.path().join("out.mcap");
    let vls = ["--preset", "vls128", "--mode", "resolution"];
    let o = replay_with(&input, &TOPICS, &vls, &out);
    common::no_panic(&o, "replay");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("had no certified adaptive profile for their gaze and ran the baseline"),
        "{err}"
    );
    // The paper preset plans every gaze: no such line.
    let o = run_replay(&input, &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("ran the baseline instead"), "{err}");
}

/// The messages a replay adds, whatever the input's other topics.
fn added_only(out: &[u8]) -> Vec<(String, u64, Vec<u8>)> {
    read_all(out)
        .into_iter()
        .filter(|m| m.topic.starts_with("/gaze_lidar/") || m.topic == "/lidar/points/adapted")
        .map(|m| (m.topic, m.log_time, m.data))
        .collect()
}

/// `m` moved onto a topic of its own (a new channel, the same schema).
fn on_topic(m: &mcap::Message<'static>, id: u16, topic: &str) -> mcap::Message<'static> {
    let mut m = m.clone();
    m.channel = std::sync::Arc::new(mcap::Channel {
        id,
        topic: topic.to_owned(),
        schema: m.channel.schema.clone(),
        message_encoding: m.channel.message_encoding.clone(),
        metadata: BTreeMap::new(),
    });
    m
}

/// Any number of far-future `log_time`s, each on an unrelated topic of its
/// own, early in the file: the reorder window still puts two pairs of
/// swapped clouds back in order, so the output is the one without them.
#[test]
fn any_number_of_far_future_stamps_on_unrelated_topics_do_not_change_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let plain = bag(None);
    let t0 = read_all(&plain).iter().map(|m| m.log_time).min().unwrap();
    let run = |name: &str, bytes: &[u8]| {
        let (i, o) = (
            dir.path().join(format!("{name}.mcap")),
            dir.path().join(format!("{name}-out.mcap")),
        );
        std::fs::write(&i, bytes).unwrap();
        let r = run_replay(&i, &o, &[]);
        assert_eq!(r.status.code(), Some(0), "{}", message(&r));
        added_only(&std::fs::read(&o).unwrap())
    };
    let want = run("plain", &plain);
    assert_eq!(
        want.iter()
            .filter(|m| m.0 == "/lidar/points/adapted")
            .count(),
        30
    );
    for n in [1usize, 2, 5] {
        let far = rewrite(
            &plain,
            |m| {
                let clouds: Vec<usize> = (0..m.len())
                    .filter(|&i| m[i].channel.topic == CLOUD)
                    .collect();
                m.swap(clouds[3], clouds[4]);
                m.swap(clouds[10], clouds[11]);
                let other = m.iter().find(|x| x.channel.topic == OTHER).unwrap().clone();
                for k in 0..n {
                    let mut x = on_topic(&other, 100 + k as u16, &format!("/far/{k}"));
                    x.log_time = t0 + 1_000_000_000_000 * (k as u64 + 1);
                    m.insert(5 + 3 * k, x);
                }
            },
            |_| {},
        );
        let have = run(&format!("far{n}"), &far);
        assert_eq!(want.len(), have.len(), "{n} far-future stamps");
        for (k, (w, h)) in want.iter().zip(&have).enumerate() {
            assert!(
                w == h,
                "{n} far-future stamps: message {k} on {} differs",
                w.0
            );
        }
    }
}

/// `--out -` into a pipe whose reader has gone: the reader left, so
/// nothing is owed to it; as every command of the CLI does (the stdout
/// rule), exit 0, and no panic.
#[test]
fn out_dash_into_a_closed_pipe_is_exit_0() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let mut child = bin()
        .arg("replay")
        .arg(&input)
        .args(["--gaze-topic", GAZE, "--cloud-topic", CLOUD, "--out", "-"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    common::no_panic(&o, "closed pipe");
    assert_eq!(o.status.code(), Some(0), "{}", message(&o));
}

/// A bag written without chunks (each message a top-level record).
fn unchunked(bag: &[u8]) -> Vec<u8> {
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .use_chunks(false)
        .create(Cursor::new(&mut buf))
        .unwrap();
    for m in mcap::MessageStream::new(bag).unwrap() {
        w.write(&m.unwrap()).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    buf
}

/// A bad message is named by its topic and the byte offset of its record
/// (the sequence field, which writers may leave 0 or repeat, only as
/// "sequence N"); in a chunk, by the chunk's offset and the record's index.
#[test]
fn a_bad_message_is_named_by_its_offset_and_topic() {
    let dir = tempfile::tempdir().unwrap();
    let plain = bag(None);
    // Every sequence 0; the 30th gaze message cut short.
    let broken = rewrite(
        &plain,
        |m| {
            for x in m.iter_mut() {
                x.sequence = 0;
            }
            let g = (0..m.len())
                .filter(|&i| m[i].channel.topic == GAZE)
                .nth(30)
                .unwrap();
            m[g].data = std::borrow::Cow::Owned(m[g].data[..20].to_vec());
        },
        |_| {},
    );
    let flat = unchunked(&broken);
    // The record of the cut message: the 31st gaze message record.
    let starts = record_starts(&flat);
    let gaze_id = mcap::Summary::read(&flat)
        .unwrap()
        .unwrap()
        .channels
        .values()
        .find(|c| c.topic == GAZE)
        .unwrap()
        .id;
    let at = starts
        .iter()
        .copied()
        .filter(|&s| flat[s] == 0x05 && u16::from_le_bytes([flat[s + 9], flat[s + 10]]) == gaze_id)
        .nth(30)
        .unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    std::fs::write(&input, &flat).unwrap();
    let o = run_replay(&input, &out, &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.starts_with(&format!(
            "{GAZE}: message at byte {at} (sequence 0, log_time "
        )),
        "record at {at}: {err}"
    );
    assert!(!err.contains("message 0 "), "{err}");
    // Chunked: the chunk's offset and the record's index in it.
    std::fs::write(&input, &broken).unwrap();
    let o = run_replay(&input, &out, &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let chunk_at: usize = err
        .strip_prefix(&format!("{GAZE}: message in the chunk at byte "))
        .and_then(|r| r.split(',').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{err}"));
    assert!(record_starts(&broken).contains(&chunk_at), "{err}");
    assert_eq!(broken[chunk_at], 0x06, "{err}");
    assert!(err.contains(", record "), "{err}");
    assert!(!out.exists());
}

/// A small chunked bag: 40 gaze samples, 4 clouds of 30 points, 2 other
/// messages, with a summary.
fn small_bag() -> Vec<u8> {
    let plain = bag(None);
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .chunk_size(Some(1024))
        .compression(None)
        .create(Cursor::new(&mut buf))
        .unwrap();
    let (mut g, mut c, mut o) = (0, 0, 0);
    for m in mcap::MessageStream::new(&plain).unwrap() {
        let mut m = m.unwrap();
        let keep = match m.channel.topic.as_str() {
            GAZE => {
                g += 1;
                g <= 40
            }
            CLOUD => {
                c += 1;
                let t = m.log_time;
                m.data = std::borrow::Cow::Owned(cloud_msg(
                    (t / 1_000_000_000) as i32,
                    (t % 1_000_000_000) as u32,
                    c,
                    30,
                ));
                c <= 4
            }
            _ => {
                o += 1;
                o <= 2
            }
        };
        if keep {
            w.write(&m).unwrap();
        }
    }
    w.finish().unwrap();
    drop(w);
    buf
}

/// A file cut at every 97th byte: exit 2, and the offset named is inside
/// the file (at most its size).
#[test]
fn truncated_files_name_an_offset_inside_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let full = small_bag();
    assert!(full.len() > 5000, "{}", full.len());
    let (input, out) = (dir.path().join("cut.mcap"), dir.path().join("out.mcap"));
    let mut cut = 1;
    while cut < full.len() {
        std::fs::write(&input, &full[..cut]).unwrap();
        let o = run_replay(&input, &out, &[]);
        let err = message(&o);
        assert_eq!(o.status.code(), Some(2), "cut at {cut}: {err}");
        let at: usize = err
            .split("at byte ")
            .nth(1)
            .and_then(|r| r.split(':').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("cut at {cut}: {err}"));
        assert!(at <= cut, "cut at {cut}: {err}");
        assert!(!out.exists());
        cut += 97;
    }
}

/// A write that fails (the file-size limit here, as a full disk would)
/// names `--out`'s path.
#[test]
fn a_failed_write_names_the_output_path() {
    let dir = tempfile::tempdir().unwrap();
    let (out, o) = replay_past_the_file_size_limit(dir.path());
    let err = message(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(&format!("output: {}: ", out.display())),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// A channel (and its schema) without a single message is copied too.
#[test]
fn a_channel_without_messages_is_copied() {
    let dir = tempfile::tempdir().unwrap();
    // The bag's messages, and a channel /imu that has none.
    let mut with_empty = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .create(Cursor::new(&mut with_empty))
        .unwrap();
    let s = w
        .add_schema(
            "sensor_msgs/msg/Imu",
            schemas::ROS2MSG,
            b"std_msgs/Header header\n",
        )
        .unwrap();
    let mut meta = BTreeMap::new();
    meta.insert("offered_qos_profiles".to_owned(), "- history: 3".to_owned());
    w.add_channel(s, "/imu", schemas::CDR, &meta).unwrap();
    let mut ids: BTreeMap<u16, u16> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bag(None)).unwrap() {
        let m = m.unwrap();
        let id = match ids.get(&m.channel.id) {
            Some(&id) => id,
            None => {
                let sc = m.channel.schema.as_ref().unwrap();
                let s = w.add_schema(&sc.name, &sc.encoding, &sc.data).unwrap();
                let id = w
                    .add_channel(
                        s,
                        &m.channel.topic,
                        &m.channel.message_encoding,
                        &BTreeMap::new(),
                    )
                    .unwrap();
                ids.insert(m.channel.id, id);
                id
            }
        };
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: id,
                sequence: m.sequence,
                log_time: m.log_time,
                publish_time: m.publish_time,
            },
            &m.data,
        )
        .unwrap();
    }
    w.finish().unwrap();
    drop(w);
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    std::fs::write(&input, &with_empty).unwrap();
    let o = run_replay(&input, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", message(&o));
    let got = std::fs::read(&out).unwrap();
    let summary = mcap::Summary::read(&got).unwrap().unwrap();
    let imu = summary
        .channels
        .values()
        .find(|c| c.topic == "/imu")
        .expect("the /imu channel is in the output");
    assert_eq!(imu.message_encoding, schemas::CDR);
    assert_eq!(
        imu.metadata.get("offered_qos_profiles").map(String::as_str),
        Some("- history: 3")
    );
    let s = imu.schema.as_ref().expect("its schema");
    assert_eq!(
        (s.name.as_str(), s.encoding.as_str(), &s.data[..]),
        (
            "sensor_msgs/msg/Imu",
            schemas::ROS2MSG,
            &b"std_msgs/Header header\n"[..]
        )
    );
}

/// A cloud whose x field has `count` 0 holds no x: refused by name.
#[test]
fn a_point_field_with_count_0_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let zero = rewrite(
        &bag(None),
        |m| {
            let c = (0..m.len()).find(|&i| m[i].channel.topic == CLOUD).unwrap();
            let mut d = m[c].data.to_vec();
            // The first field's count: the u32 after "x\0", its offset and
            // its datatype (header 4 + stamp 8 + "lidar" 4+6 → 24 (pad),
            // height, width, field count 4+4+4 → 36, name 4+2 → 42, pad
            // 44, offset → 48, datatype → 49, pad → 52).
            assert_eq!(&d[40..42], b"x\0");
            assert_eq!(u32::from_le_bytes(d[52..56].try_into().unwrap()), 1);
            d[52..56].copy_from_slice(&0u32.to_le_bytes());
            m[c].data = std::borrow::Cow::Owned(d);
        },
        |_| {},
    );
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    std::fs::write(&input, &zero).unwrap();
    let o = run_replay(&input, &out, &[]);
    let err = message(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("fields: field x has count 0"), "{err}");
    assert!(!out.exists());
}

/// A first gaze sample at `log_time` 0 (the clock then jumps to the real
/// stamps, far from it): the frames after the jump start exactly where the
/// bag without that sample has them, to the nanosecond, and every adapted
/// cloud's header stamp is its input's.
#[test]
fn stamps_are_exact_when_the_first_gaze_is_at_log_time_0() {
    let dir = tempfile::tempdir().unwrap();
    // Stamps off the microsecond grid, so a rounding shows.
    let shifted = rewrite(
        &bag(None),
        |m| {
            for x in m.iter_mut() {
                x.log_time += 123_456_789;
                x.publish_time = x.log_time;
            }
        },
        |_| {},
    );
    let zero = rewrite(
        &shifted,
        |m| {
            let mut g = m.iter().find(|x| x.channel.topic == GAZE).unwrap().clone();
            g.log_time = 0;
            g.publish_time = 0;
            m.insert(0, g);
        },
        |_| {},
    );
    let run = |name: &str, bytes: &[u8]| {
        let (i, o) = (
            dir.path().join(format!("{name}.mcap")),
            dir.path().join(format!("{name}-out.mcap")),
        );
        std::fs::write(&i, bytes).unwrap();
        let r = run_replay(&i, &o, &[]);
        assert_eq!(r.status.code(), Some(0), "{}", message(&r));
        std::fs::read(&o).unwrap()
    };
    let (want, have) = (run("shifted", &shifted), run("zero", &zero));
    let t_first = read_all(&shifted).iter().map(|m| m.log_time).min().unwrap();
    let stamps = |b: &[u8]| -> Vec<u64> {
        read_all(b)
            .iter()
            .filter(|m| m.topic == "/gaze_lidar/profile" && m.log_time >= t_first)
            .map(|m| m.log_time)
            .collect()
    };
    assert_eq!(stamps(&have), stamps(&want));
    assert!(stamps(&want).len() > 20);
    let headers = |b: &[u8], topic: &str| -> Vec<(i32, u32, u64)> {
        read_all(b)
            .iter()
            .filter(|m| m.topic == topic)
            .map(|m| {
                let c = PointCloud2::decode(&m.data).unwrap();
                (c.header.sec, c.header.nanosec, m.log_time)
            })
            .collect()
    };
    let input = headers(&zero, CLOUD);
    assert_eq!(input.len(), 30);
    assert_eq!(headers(&have, "/lidar/points/adapted"), input);
}

/// The variable that makes [`rss_probe_helper`] run a replay: the
/// arguments, separated by the byte 0x1F (unit separator).
const RSS_ARGS: &str = "GAZE_LIDAR_TEST_RSS_ARGS";

/// Not a test of its own: with [`RSS_ARGS`] set, runs `gaze-lidar` with
/// those arguments, its stderr into the file `GAZE_LIDAR_TEST_RSS_ERR`,
/// and prints `rss <bytes> code <exit code>` (`wait4`'s `ru_maxrss` of that
/// child alone). A fresh process does it because a child's peak memory
/// counts the memory of the process it was spawned from (Linux carries the
/// old memory's peak across `exec`), and the test process holds the bags.
#[test]
fn rss_probe_helper() {
    let Some(args) = std::env::var_os(RSS_ARGS) else {
        return;
    };
    use std::os::unix::ffi::OsStrExt;
    let args: Vec<std::ffi::OsString> = args
        .as_bytes()
        .split(|&b| b == 0x1f)
        .map(|a| std::ffi::OsStr::from_bytes(a).to_owned())
        .collect();
    let err = std::fs::File::create(std::env::var_os("GAZE_LIDAR_TEST_RSS_ERR").unwrap()).unwrap();
    // Reaped by `wait4` below (which `Child::wait` cannot replace: it
    // gives no resource usage).
    #[allow(clippy::zombie_processes)]
    let child = bin()
        .args(&args)
        .stdout(std::process::Stdio::null())
        .stderr(err)
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: a zeroed rusage is valid; wait4 fills it for our own child.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut ru) };
    assert_eq!(r, pid);
    let code = if libc::WIFEXITED(status) {
        libc::WEXITSTATUS(status)
    } else {
        -1
    };
    println!("rss {} code {code}", ru.ru_maxrss as u64 * 1024);
}

/// Runs `gaze-lidar args` through [`rss_probe_helper`] in a fresh test
/// process; returns (exit code, stderr, peak resident memory in bytes).
fn run_measured(args: &[&std::ffi::OsStr]) -> (i32, String, u64) {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let err = dir.path().join("stderr");
    let joined: Vec<u8> = args
        .iter()
        .map(|a| a.as_bytes())
        .collect::<Vec<_>>()
        .join(&0x1fu8);
    // The helper's full test name: this module's path without the crate's.
    let module = module_path!().split_once("::").map_or("", |(_, m)| m);
    let helper = format!("{module}::rss_probe_helper");
    let o = Command::new(std::env::current_exe().unwrap())
        .args([
            helper.as_str(),
            "--exact",
            "--nocapture",
            "--test-threads",
            "1",
        ])
        .env(RSS_ARGS, std::ffi::OsStr::from_bytes(&joined))
        .env("GAZE_LIDAR_TEST_RSS_ERR", &err)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    let line = out
        .lines()
        .find_map(|l| l.find("rss ").map(|k| &l[k..]))
        .unwrap_or_else(|| panic!("{out}{}", String::from_utf8_lossy(&o.stderr)));
    let f: Vec<&str> = line.split(' ').collect();
    let stderr = std::fs::read_to_string(&err).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    (f[3].parse().unwrap(), stderr, f[1].parse().unwrap())
}

fn replay_measured(input: &std::path::Path, out: &std::path::Path) -> (i32, String, u64) {
    let mut args: Vec<&std::ffi::OsStr> = vec!["replay".as_ref(), input.as_os_str()];
    for a in ["--gaze-topic", GAZE, "--cloud-topic", CLOUD] {
        args.push(a.as_ref());
    }
    for a in ["--preset", "paper", "--mode", "range", "--out"] {
        args.push(a.as_ref());
    }
    args.push(out.as_os_str());
    run_measured(&args)
}

/// stderr without the program's `gaze-lidar: error: ` prefix.
fn strip(e: &str) -> String {
    e.strip_prefix("gaze-lidar: error: ")
        .unwrap_or(e)
        .to_owned()
}

/// Peak memory, as the issue bounds it.
const PEAK_BYTES: u64 = 200 << 20;

/// The bag with its 6th cloud replaced by one of `n` points.
fn bag_with_a_huge_cloud(n: usize) -> Vec<u8> {
    rewrite(
        &bag(None),
        |m| {
            let c = (0..m.len())
                .filter(|&i| m[i].channel.topic == CLOUD)
                .nth(5)
                .unwrap();
            let t = m[c].log_time;
            m[c].data = std::borrow::Cow::Owned(cloud_msg(
                (t / 1_000_000_000) as i32,
                (t % 1_000_000_000) as u32,
                5,
                n,
            ));
        },
        |_| {},
    )
}

/// One huge cloud: up to 32 MiB it is replayed in under 200 MB; beyond,
/// it is refused by its topic and offset (exit 2, no output).
#[test]
fn one_huge_message_is_replayed_in_bounded_memory_or_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    // 31 MiB of points (16 bytes each).
    std::fs::write(&input, bag_with_a_huge_cloud(31 << 16)).unwrap();
    let (code, err, peak) = replay_measured(&input, &out);
    assert_eq!(code, 0, "{err}");
    assert!(peak <= PEAK_BYTES, "peak {} MiB", peak >> 20);
    eprintln!("one 31 MiB cloud: peak {} MiB", peak >> 20);
    std::fs::remove_file(&out).unwrap();
    // 40 MiB: refused, naming the topic and where the message is.
    let big = bag_with_a_huge_cloud(40 << 16);
    std::fs::write(&input, &big).unwrap();
    let (code, err, peak) = replay_measured(&input, &out);
    let err = strip(&err);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.starts_with(&format!("{CLOUD}: message in the chunk at byte ")),
        "{err}"
    );
    assert!(
        err.contains("more than the 32 MiB a message may have"),
        "{err}"
    );
    assert!(peak <= PEAK_BYTES, "peak {} MiB", peak >> 20);
    assert!(!out.exists());
}

/// A 60 MiB attachment is copied in under 200 MB; one past the 64 MiB a
/// record may have is refused at its offset.
#[test]
fn a_large_attachment_is_copied_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    let with = |bytes: usize| {
        rewrite(
            &bag(None),
            |_| {},
            |w| {
                w.attach(&mcap::Attachment {
                    log_time: 1,
                    create_time: 2,
                    name: "video.bin".into(),
                    media_type: "application/octet-stream".into(),
                    data: std::borrow::Cow::Owned(vec![7u8; bytes]),
                })
                .unwrap();
            },
        )
    };
    std::fs::write(&input, with(60 << 20)).unwrap();
    let (code, err, peak) = replay_measured(&input, &out);
    assert_eq!(code, 0, "{err}");
    eprintln!("one 60 MiB attachment: peak {} MiB", peak >> 20);
    assert!(peak <= PEAK_BYTES, "peak {} MiB", peak >> 20);
    let got = std::fs::read(&out).unwrap();
    let summary = mcap::Summary::read(&got).unwrap().unwrap();
    let a = mcap::read::attachment(&got, &summary.attachment_indexes[0]).unwrap();
    assert_eq!((a.name.as_str(), a.data.len()), ("video.bin", 60 << 20));
    std::fs::remove_file(&out).unwrap();
    let bag = with(65 << 20);
    std::fs::write(&input, &bag).unwrap();
    let (code, err, peak) = replay_measured(&input, &out);
    let err = strip(&err);
    assert_eq!(code, 2, "{err}");
    let at = record_starts(&bag)
        .into_iter()
        .find(|&s| bag[s] == 0x09)
        .unwrap();
    assert!(err.contains(&format!("at byte {at}:")), "{err}");
    assert!(peak <= PEAK_BYTES, "peak {} MiB", peak >> 20);
    assert!(!out.exists());
}

/// `n` channels on topics of their own, each with `meta` bytes of
/// metadata and one message, besides the bag's.
fn bag_with_channels(n: usize, meta: usize) -> Vec<u8> {
    let mut buf = Vec::new();
    let mut w = mcap::WriteOptions::new()
        .create(Cursor::new(&mut buf))
        .unwrap();
    let s = w
        .add_schema(
            schemas::STRING,
            schemas::ROS2MSG,
            schemas::ros2msg(schemas::STRING).unwrap().as_bytes(),
        )
        .unwrap();
    let mut meta_map = BTreeMap::new();
    meta_map.insert("offered_qos_profiles".to_owned(), "q".repeat(meta));
    for k in 0..n {
        let ch = w
            .add_channel(s, &format!("/many/{k}"), schemas::CDR, &meta_map)
            .unwrap();
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: ch,
                sequence: 0,
                log_time: 1_700_000_000_000_000_000 + k as u64,
                publish_time: 0,
            },
            &cdr::encode_string("x"),
        )
        .unwrap();
    }
    let mut ids: BTreeMap<u16, u16> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bag(None)).unwrap() {
        let m = m.unwrap();
        let id = *ids.entry(m.channel.id).or_insert_with(|| {
            let sc = m.channel.schema.as_ref().unwrap();
            let s = w.add_schema(&sc.name, &sc.encoding, &sc.data).unwrap();
            w.add_channel(
                s,
                &m.channel.topic,
                &m.channel.message_encoding,
                &BTreeMap::new(),
            )
            .unwrap()
        });
        w.write_to_known_channel(
            &MessageHeader {
                channel_id: id,
                sequence: m.sequence,
                log_time: m.log_time,
                publish_time: m.publish_time,
            },
            &m.data,
        )
        .unwrap();
    }
    w.finish().unwrap();
    drop(w);
    buf
}

/// Many channels: 12,000 with 1 KB of metadata each are copied in under
/// 200 MB; a bag declaring more than 16 MiB of schemas and channels is
/// refused (exit 2) at the record that passes it.
#[test]
fn many_channels_are_copied_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.mcap"), dir.path().join("out.mcap"));
    std::fs::write(&input, bag_with_channels(12_000, 1000)).unwrap();
    let (code, err, peak) = replay_measured(&input, &out);
    assert_eq!(code, 0, "{err}");
    eprintln!("12,000 channels: peak {} MiB", peak >> 20);
    assert!(peak <= PEAK_BYTES, "peak {} MiB", peak >> 20);
    let got = std::fs::read(&out).unwrap();
    let summary = mcap::Summary::read(&got).unwrap().unwrap();
    assert_eq!(summary.channels.len(), 12_000 + 3 + 3);
    std::fs::remove_file(&out).unwrap();
    std::fs::write(&input, bag_with_channels(9_000, 2000)).unwrap();
    let (code, err, peak) = replay_measured(&input, &out);
    let err = strip(&err);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("schemas and channels declared so far take more than 16 MiB"),
        "{err}"
    );
    assert!(peak <= PEAK_BYTES, "peak {} MiB", peak >> 20);
    assert!(!out.exists());
}

/// Single-byte corruptions of a zstd and an lz4 bag (every k-th byte, some
/// 150 positions each): exit 0, 1 or 2, never a signal (an abort on a huge
/// allocation from a corrupt inner length was one), never a leftover
/// temporary file, and no output unless the exit is 0.
#[test]
fn single_byte_corruptions_of_compressed_bags_never_abort_or_leave_a_temp_file() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    let out = dir.path().join("out.mcap");
    for compression in [mcap::Compression::Zstd, mcap::Compression::Lz4] {
        let good = bag(Some(compression));
        let step = (good.len() / 150).max(1);
        // Offsets spread over the whole file, shifted so that not only the
        // multiples of `step` are hit.
        for (n, at) in (8..good.len() - 8).step_by(step).enumerate() {
            let mut b = good.clone();
            b[at] ^= [0xff, 0x01, 0x80, 0x55][n % 4];
            std::fs::write(&input, &b).unwrap();
            let _ = std::fs::remove_file(&out);
            let o = run_replay(&input, &out, &[]);
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert!(
                matches!(o.status.code(), Some(0..=2)),
                "{compression:?} byte {at}: {:?} (signal {:?}): {stderr}",
                o.status,
                o.status.signal()
            );
            assert!(!stderr.contains("panicked"), "byte {at}: {stderr}");
            let left: Vec<String> = std::fs::read_dir(dir.path())
                .unwrap()
                .map(|e| e.unwrap().file_name().into_string().unwrap())
                .filter(|n| n != "in.mcap" && n != "out.mcap")
                .collect();
            assert!(left.is_empty(), "{compression:?} byte {at}: {left:?}");
            if o.status.code() != Some(0) {
                assert!(!out.exists(), "{compression:?} byte {at}: output left");
                assert_eq!(stderr.lines().count(), 1, "byte {at}: {stderr}");
            }
        }
    }
}

/// The cloud topic with its schema replaced by (name, encoding, text).
fn with_cloud_schema(name: &str, encoding: &str, text: &str) -> Vec<u8> {
    rewrite(
        &bag(None),
        |msgs| {
            let mut channel: Option<std::sync::Arc<mcap::Channel<'static>>> = None;
            for m in msgs.iter_mut().filter(|m| m.channel.topic == CLOUD) {
                let c = channel.get_or_insert_with(|| {
                    std::sync::Arc::new(mcap::Channel {
                        schema: Some(std::sync::Arc::new(mcap::Schema {
                            id: 40,
                            name: name.to_owned(),
                            encoding: encoding.to_owned(),
                            data: std::borrow::Cow::Owned(text.as_bytes().to_vec()),
                        })),
                        ..(*m.channel).clone()
                    })
                });
                m.channel = c.clone();
            }
        },
        |_| {},
    )
}

/// A cloud topic whose schema is not PointCloud2 in `ros2msg` (an IDL
/// schema, another type, no schema) is refused by name, exit 2; one that
/// is PointCloud2 in `ros2msg` with an empty or wrong text is decoded, and
/// the adapted topic carries the tool's own PointCloud2 definition, which
/// the schema's readers can parse.
#[test]
fn a_cloud_schema_that_is_not_point_cloud2_in_ros2msg_is_refused_and_adapted_clouds_carry_the_tools_definition(
) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    let out = dir.path().join("out.mcap");
    for (name, encoding, text) in [
        (
            schemas::POINT_CLOUD2,
            "ros2idl",
            "module sensor_msgs { module msg { struct PointCloud2 { long x; }; }; };",
        ),
        ("sensor_msgs/msg/Image", schemas::ROS2MSG, "uint32 height\n"),
        ("", "", ""),
    ] {
        std::fs::write(&input, with_cloud_schema(name, encoding, text)).unwrap();
        let o = run_replay(&input, &out, &[]);
        let m = message(&o);
        assert_eq!(o.status.code(), Some(2), "{name} {encoding}: {m}");
        assert!(m.contains(CLOUD), "{m}");
        assert!(m.contains(&format!("{encoding:?}")), "{m}");
        assert!(m.contains(schemas::POINT_CLOUD2), "{m}");
        assert!(!out.exists());
    }
    let def = schemas::ros2msg(schemas::POINT_CLOUD2).unwrap();
    for text in ["", "int32 foo\n"] {
        std::fs::write(
            &input,
            with_cloud_schema(schemas::POINT_CLOUD2, schemas::ROS2MSG, text),
        )
        .unwrap();
        let o = run_replay(&input, &out, &[]);
        assert_eq!(o.status.code(), Some(0), "{text:?}: {}", message(&o));
        let bytes = std::fs::read(&out).unwrap();
        let adapted = format!("{CLOUD}/adapted");
        let mut seen = 0;
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            if m.channel.topic == adapted {
                let s = m.channel.schema.as_ref().unwrap();
                assert_eq!(s.name, schemas::POINT_CLOUD2);
                assert_eq!(s.encoding, schemas::ROS2MSG);
                assert_eq!(&*s.data, def.as_bytes(), "{text:?}");
                seen += 1;
            }
        }
        assert_eq!(seen, 30, "{text:?}");
    }
}

/// MCAP does not require a sorted data section and replay reads it in
/// record order: messages more than the reorder window behind newer ones
/// are late, and a one-line warning names how many (all clouds stored
/// before all gaze: most gaze is dropped).
#[test]
fn messages_late_in_record_order_are_named_in_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    let out = dir.path().join("out.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let o = run_replay(&input, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", message(&o));
    assert!(
        !message(&o).contains("behind newer ones"),
        "{}",
        message(&o)
    );
    let clouds_first = rewrite(
        &bag(None),
        |msgs| msgs.sort_by_key(|m| m.channel.topic != CLOUD),
        |_| {},
    );
    std::fs::write(&input, clouds_first).unwrap();
    let o = run_replay(&input, &out, &[]);
    let m = message(&o);
    assert_eq!(o.status.code(), Some(0), "{m}");
    let line = m
        .lines()
        .find(|l| l.contains("behind newer ones in the file's record order"))
        .unwrap_or_else(|| panic!("no warning: {m}"));
    assert!(line.contains("gaze sample(s) dropped"), "{line}");
    assert!(!line.contains(" 0 gaze sample(s)"), "{line}");
}

/// The gaze vector's `header.frame_id`: a frame linked to the vehicle
/// frame by a static transform is turned into it (the same output as the
/// vehicle-frame gaze); an unlinked frame is named in a warning.
#[test]
fn gaze_in_another_frame_is_turned_by_tf_static_or_named_in_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    let (base, cam) = (dir.path().join("base.mcap"), dir.path().join("cam.mcap"));
    std::fs::write(&input, bag(None)).unwrap();
    let o = run_replay(&input, &base, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", message(&o));
    // The camera frame's x axis is the vehicle's y axis (yaw 90°): the
    // vehicle's (x, y, z) is the camera's (y, -x, z).
    let in_cam = |with_tf: bool| {
        rewrite(
            &bag(None),
            |msgs| {
                for m in msgs.iter_mut().filter(|m| m.channel.topic == GAZE) {
                    let v = Vector3Stamped::decode(&m.data).unwrap();
                    let [x, y, z] = v.xyz;
                    let turned = Vector3Stamped {
                        header: Header {
                            frame_id: "cam",
                            ..v.header
                        },
                        xyz: [y, -x, z],
                    }
                    .encode();
                    m.data = std::borrow::Cow::Owned(turned);
                }
                if with_tf {
                    let tf = cdr::encode_tf_message(&[cdr::TransformStamped {
                        header: Header {
                            sec: 0,
                            nanosec: 0,
                            frame_id: "base_link",
                        },
                        child_frame_id: "cam",
                        translation: [0.0; 3],
                        rotation_xyzw: axis_angle([0.0, 0.0, 1.0], 90.0),
                    }]);
                    let channel = std::sync::Arc::new(mcap::Channel {
                        id: 50,
                        topic: "/tf_static".to_owned(),
                        schema: Some(std::sync::Arc::new(mcap::Schema {
                            id: 51,
                            name: schemas::TF_MESSAGE.to_owned(),
                            encoding: schemas::ROS2MSG.to_owned(),
                            data: std::borrow::Cow::Owned(
                                schemas::ros2msg(schemas::TF_MESSAGE).unwrap().into_bytes(),
                            ),
                        })),
                        message_encoding: schemas::CDR.to_owned(),
                        metadata: BTreeMap::new(),
                    });
                    let t = msgs[0].log_time;
                    msgs.insert(
                        0,
                        mcap::Message {
                            channel,
                            sequence: 0,
                            log_time: t,
                            publish_time: t,
                            data: std::borrow::Cow::Owned(tf),
                        },
                    );
                }
            },
            |_| {},
        )
    };
    std::fs::write(&input, in_cam(true)).unwrap();
    let o = run_replay(&input, &cam, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", message(&o));
    assert!(!message(&o).contains("gaze vector"), "{}", message(&o));
    let adapted = |p: &std::path::Path| -> Vec<Vec<u8>> {
        added(&std::fs::read(p).unwrap())
            .into_iter()
            .filter(|(t, _, _)| t == &format!("{CLOUD}/adapted"))
            .map(|(_, _, d)| d)
            .collect()
    };
    let want = adapted(&base);
    assert_eq!(want.len(), 30);
    assert!(adapted(&cam) == want, "turned gaze gives other clouds");
    std::fs::write(&input, in_cam(false)).unwrap();
    let o = run_replay(&input, &cam, &[]);
    let m = message(&o);
    assert_eq!(o.status.code(), Some(0), "{m}");
    assert!(
        m.lines()
            .any(|l| l.contains("gaze vector(s) in frame \"cam\"") && l.contains("/tf_static")),
        "{m}"
    );
}

/// Messages for misused outputs and options: `/dev/stdout` into a pipe is
/// stdout; a missing `--config` names the flag; a missing TMPDIR names the
/// folder and the variable.
#[test]
fn dev_stdout_missing_config_and_missing_tmpdir_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.mcap");
    std::fs::write(&input, bag(None)).unwrap();
    let file = dir.path().join("file.mcap");
    assert_eq!(run_replay(&input, &file, &[]).status.code(), Some(0));
    let args = |out: &str| -> Vec<String> {
        [
            "replay",
            input.to_str().unwrap(),
            "--gaze-topic",
            GAZE,
            "--cloud-topic",
            CLOUD,
            "--preset",
            "paper",
            "--mode",
            "range",
            "--out",
            out,
        ]
        .map(str::to_owned)
        .to_vec()
    };
    let o = bin().args(args("/dev/stdout")).output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", message(&o));
    assert_eq!(o.stdout, std::fs::read(&file).unwrap());
    let o = run_replay(
        &input,
        &dir.path().join("o.mcap"),
        &["--config", "nonexist.toml"],
    );
    let m = message(&o);
    assert_eq!(o.status.code(), Some(2), "{m}");
    assert!(m.starts_with("--config: nonexist.toml"), "{m}");
    let o = bin()
        .env("TMPDIR", "/nonexistent-tmpdir")
        .args(args("-"))
        .output()
        .unwrap();
    let m = message(&o);
    assert_eq!(o.status.code(), Some(1), "{m}");
    assert!(
        m.contains("/nonexistent-tmpdir") && m.contains("TMPDIR"),
        "{m}"
    );
    assert!(o.stdout.is_empty());
}
