//! Unit tests of the CDR codec and the gaze conversion.

use super::cdr::{self, datatype, Header, PointCloud2, PointField, Vector3Stamped};
use super::*;

#[test]
fn vector3_stamped_round_trips_and_matches_hand_encoded_bytes() {
    let v = Vector3Stamped {
        header: Header {
            sec: 7,
            nanosec: 9,
            frame_id: "ab",
        },
        xyz: [1.0, -2.0, 0.5],
    };
    let b = v.encode();
    // Header 4, sec 4, nanosec 4, len 4, "ab\0" 3, pad to 8 (rel 15 → 16), 3 × 8.
    assert_eq!(b.len(), 4 + 4 + 4 + 4 + 3 + 1 + 24);
    assert_eq!(&b[..4], &[0, 1, 0, 0]);
    assert_eq!(&b[12..16], &3u32.to_le_bytes());
    assert_eq!(&b[16..19], b"ab\0");
    assert_eq!(&b[20..28], &1.0f64.to_le_bytes());
    assert_eq!(Vector3Stamped::decode(&b).unwrap(), v);
    // Big-endian input decodes too.
    let mut be = vec![0, 0, 0, 0];
    be.extend_from_slice(&7i32.to_be_bytes());
    be.extend_from_slice(&9u32.to_be_bytes());
    be.extend_from_slice(&3u32.to_be_bytes());
    be.extend_from_slice(b"ab\0\0");
    for x in [1.0f64, -2.0, 0.5] {
        be.extend_from_slice(&x.to_be_bytes());
    }
    assert_eq!(Vector3Stamped::decode(&be).unwrap(), v);
    // Truncated: names the field.
    let e = Vector3Stamped::decode(&b[..25]).unwrap_err().to_string();
    assert!(e.starts_with("vector.x"), "{e}");
    assert!(Vector3Stamped::decode(&[0, 2, 0, 0]).is_err());
}

#[test]
fn float64_round_trips() {
    assert_eq!(
        cdr::decode_float64(&cdr::encode_float64(-12.5)).unwrap(),
        -12.5
    );
    assert_eq!(cdr::encode_float64(1.0).len(), 12);
}

fn cloud_bytes(big: bool, wide: bool, step: u32, pts: &[[f64; 3]]) -> Vec<u8> {
    // Written by hand (not by `encode_subset`): fields x, y, z at 0, s, 2s
    // and an intensity after them, padding to `step`.
    let s = if wide { 8 } else { 4 };
    let mut data = Vec::new();
    for p in pts {
        let start = data.len();
        for v in p {
            if wide {
                data.extend_from_slice(&if big {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                });
            } else {
                let f = *v as f32;
                data.extend_from_slice(&if big {
                    f.to_be_bytes()
                } else {
                    f.to_le_bytes()
                });
            }
        }
        data.resize(start + step as usize, 0xAB);
    }
    let mut w = cdr::Writer::new(64);
    Header {
        sec: 1,
        nanosec: 2,
        frame_id: "lidar",
    }
    .write(&mut w);
    w.u32(1);
    w.u32(pts.len() as u32);
    w.u32(4);
    for (name, off, t) in [
        (
            "x",
            0,
            if wide {
                datatype::FLOAT64
            } else {
                datatype::FLOAT32
            },
        ),
        (
            "y",
            s,
            if wide {
                datatype::FLOAT64
            } else {
                datatype::FLOAT32
            },
        ),
        (
            "z",
            2 * s,
            if wide {
                datatype::FLOAT64
            } else {
                datatype::FLOAT32
            },
        ),
        ("intensity", 3 * s, datatype::UINT8),
    ] {
        w.string(name);
        w.u32(off);
        w.u8(t);
        w.u32(1);
    }
    w.u8(u8::from(big));
    w.u32(step);
    w.u32(step * pts.len() as u32);
    w.bytes_from(data.len(), std::iter::once(&data[..]));
    w.u8(0);
    w.finish()
}

#[test]
fn point_cloud2_reads_every_layout_and_keeps_a_subset_byte_for_byte() {
    let pts = [[1.0, 2.0, 3.0], [-4.5, 0.25, 8.0], [f64::NAN, 0.0, 0.0]];
    for (big, wide, step) in [
        (false, false, 16),
        (true, false, 13),
        (false, true, 32),
        (true, true, 25),
    ] {
        let b = cloud_bytes(big, wide, step, &pts);
        let c = PointCloud2::decode(&b).unwrap();
        assert_eq!(c.fields.len(), 4);
        assert_eq!(
            c.fields[3],
            PointField {
                name: "intensity",
                offset: if wide { 24 } else { 12 },
                datatype: datatype::UINT8,
                count: 1
            }
        );
        let l = c.xyz().unwrap();
        assert_eq!(l.len(), 3);
        assert_eq!(l.xyz(l.point(c.data, 1)), [-4.5, 0.25, 8.0]);
        assert!(l.xyz(l.point(c.data, 2))[0].is_nan());
        let sub = cdr::encode_subset(&c, &l, &[false, true, false], true);
        let s = PointCloud2::decode(&sub).unwrap();
        assert_eq!((s.height, s.width, s.point_step), (1, 1, step));
        assert_eq!(s.row_step, step);
        assert_eq!(s.data, l.point(c.data, 1));
        assert_eq!(s.header, c.header);
        assert_eq!(s.fields, c.fields);
        assert_eq!(s.is_bigendian, big);
        assert!(s.is_dense);
    }
}

#[test]
fn point_cloud2_layout_errors_name_the_field() {
    let b = cloud_bytes(false, false, 16, &[[1.0, 2.0, 3.0]]);
    let mut c = PointCloud2::decode(&b).unwrap();
    c.point_step = 8;
    assert!(c.xyz().unwrap_err().to_string().starts_with("fields"));
    let mut c = PointCloud2::decode(&b).unwrap();
    c.width = 2;
    assert!(c.xyz().unwrap_err().to_string().starts_with("row_step"));
    let mut c = PointCloud2::decode(&b).unwrap();
    c.height = 2;
    assert!(c.xyz().unwrap_err().to_string().starts_with("data"));
    let mut c = PointCloud2::decode(&b).unwrap();
    c.fields.retain(|f| f.name != "z");
    assert!(c
        .xyz()
        .unwrap_err()
        .to_string()
        .contains("no field named z"));
    assert!(PointCloud2::decode(&b[..b.len() - 3]).is_err());
}

#[test]
fn ambiguous_point_layouts_are_refused_by_name() {
    let b = cloud_bytes(false, false, 16, &[[1.0, 2.0, 3.0]]);
    let c = PointCloud2::decode(&b).unwrap();
    assert!(c.xyz().is_ok());
    // A second x.
    let mut d = c.clone();
    let mut x2 = d.fields[0].clone();
    x2.offset = 12;
    d.fields.push(x2);
    let e = d.xyz().unwrap_err().to_string();
    assert!(
        e.starts_with("fields") && e.contains("x is given more than once"),
        "{e}"
    );
    // x, y and z at one offset (a 4-byte point).
    let mut d = c.clone();
    for f in &mut d.fields {
        f.offset = 0;
    }
    let e = d.xyz().unwrap_err().to_string();
    assert!(e.starts_with("fields") && e.contains("overlaps"), "{e}");
    // y straddling x's last bytes.
    let mut d = c.clone();
    d.fields[1].offset = 2;
    assert!(d.xyz().unwrap_err().to_string().contains("overlaps field"));
    // Another field inside z.
    let mut d = c.clone();
    d.fields[3].offset = 9;
    let e = d.xyz().unwrap_err().to_string();
    assert!(
        e.contains("z (bytes 8..12) overlaps field intensity"),
        "{e}"
    );
    // Adjacent is fine.
    let mut d = c;
    d.fields[3].offset = 12;
    assert!(d.xyz().is_ok());
}

#[test]
fn vector_azimuth_follows_iso_8855() {
    assert_eq!(vector_azimuth_deg([1.0, 0.0, 0.0]), Some(0.0));
    assert_eq!(vector_azimuth_deg([0.0, 1.0, 0.0]), Some(90.0));
    assert_eq!(vector_azimuth_deg([0.0, -2.0, 5.0]), Some(270.0));
    assert_eq!(vector_azimuth_deg([0.0, 0.0, 1.0]), None);
    assert_eq!(vector_azimuth_deg([0.0, 0.0, 0.0]), None);
    assert_eq!(vector_azimuth_deg([f64::NAN, 1.0, 0.0]), None);
    assert_eq!(vector_azimuth_deg([1.0, f64::INFINITY, 0.0]), None);
}

/// The fast paths ([`cdr::XyzLayout::decode_all`], the merged runs of
/// [`cdr::encode_subset`]) against the plain per-point reads, on clouds of
/// several rows with padded rows, every coordinate layout and random
/// subsets.
#[test]
fn decode_all_and_kept_ranges_match_the_per_point_reference() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for case in 0..64 {
        let (big, wide) = (case % 2 == 1, case % 4 >= 2);
        let size = if wide { 8 } else { 4 };
        let step = 3 * size + rng.random_range(0..7usize);
        let (height, width) = (rng.random_range(1..5usize), rng.random_range(0..40usize));
        let row = width * step + rng.random_range(0..9usize);
        let data: Vec<u8> = (0..height * row).map(|_| rng.random()).collect();
        let t = if wide {
            datatype::FLOAT64
        } else {
            datatype::FLOAT32
        };
        // x, y, z in a shuffled order in the point.
        let perm = [[0, 1, 2], [2, 0, 1], [1, 2, 0]][case % 3];
        let fields: Vec<PointField> = ["x", "y", "z"]
            .iter()
            .zip(perm)
            .map(|(name, k)| PointField {
                name,
                offset: (k * size) as u32,
                datatype: t,
                count: 1,
            })
            .collect();
        let c = PointCloud2 {
            header: Header {
                sec: 0,
                nanosec: 0,
                frame_id: "l",
            },
            height: height as u32,
            width: width as u32,
            fields,
            is_bigendian: big,
            point_step: step as u32,
            row_step: row as u32,
            data: &data,
            is_dense: false,
        };
        let l = c.xyz().unwrap();
        let mut all = Vec::new();
        l.decode_all(c.data, &mut all);
        let want: Vec<[f64; 3]> = (0..l.len()).map(|i| l.xyz(l.point(c.data, i))).collect();
        // Bitwise (NaN payloads included).
        let bits =
            |v: &[[f64; 3]]| -> Vec<[u64; 3]> { v.iter().map(|p| p.map(f64::to_bits)).collect() };
        assert_eq!(bits(&all), bits(&want), "case {case}");
        let streamed: Vec<[f64; 3]> = l.points(c.data).collect();
        assert_eq!(l.points(c.data).len(), l.len());
        assert_eq!(bits(&streamed), bits(&want), "case {case}");
        let keep: Vec<bool> = (0..l.len()).map(|_| rng.random_bool(0.6)).collect();
        let sub = cdr::encode_subset(&c, &l, &keep, true);
        let s = PointCloud2::decode(&sub).unwrap();
        let naive: Vec<u8> = (0..l.len())
            .filter(|&i| keep[i])
            .flat_map(|i| l.point(c.data, i).to_vec())
            .collect();
        assert_eq!(s.data, &naive[..], "case {case}");
        assert_eq!(s.width as usize, keep.iter().filter(|&&k| k).count());
    }
}

fn empty_message(
    channel: &std::sync::Arc<mcap::Channel<'static>>,
    t: u64,
) -> mcap::Message<'static> {
    mcap::Message {
        channel: channel.clone(),
        sequence: 0,
        log_time: t,
        publish_time: t,
        data: std::borrow::Cow::Owned(Vec::new()),
    }
}

fn channel(id: u16, topic: &str) -> std::sync::Arc<mcap::Channel<'static>> {
    std::sync::Arc::new(mcap::Channel {
        id,
        topic: topic.to_owned(),
        schema: None,
        message_encoding: "cdr".to_owned(),
        metadata: std::collections::BTreeMap::new(),
    })
}

#[test]
fn the_window_bounds_many_empty_messages_by_their_bookkeeping() {
    // Two million empty messages at one time: none is old, so only the
    // byte bound releases them, and it must count them although their
    // data is empty.
    let ch = channel(1, "/empty");
    let mut w = super::Window::new(200_000_000);
    let mut released = 0u64;
    for _ in 0..2_000_000u64 {
        w.push(empty_message(&ch, 5), AT, super::Drives::No);
        while w.pop_due().is_some() {
            released += 1;
        }
        assert!(w.held_bytes <= super::MAX_WINDOW_BYTES + super::HELD_OVERHEAD_BYTES);
    }
    let cap = super::MAX_WINDOW_BYTES / super::HELD_OVERHEAD_BYTES + 1;
    assert!(w.heap.len() <= cap, "{} held", w.heap.len());
    assert!(released >= 2_000_000 - cap as u64);
}

const AT: super::RecordAt = super::RecordAt {
    offset: 8,
    in_chunk: None,
};

#[test]
fn far_future_stamps_do_not_move_the_windows_clock() {
    use super::Drives::{Cloud, Gaze, No};
    let (g, c, x, y) = (
        channel(1, "/gaze"),
        channel(2, "/cloud"),
        channel(3, "/x"),
        channel(4, "/y"),
    );
    let mut w = super::Window::new(200_000_000);
    w.push(empty_message(&g, 1_000_000_000), AT, Gaze);
    assert_eq!(w.clock(), 1_000_000_000);
    // Far-future stamps on other topics, any number: the clock stays.
    w.push(empty_message(&x, u64::MAX / 2), AT, No);
    w.push(empty_message(&y, u64::MAX / 3), AT, No);
    assert_eq!(w.clock(), 1_000_000_000);
    w.push(empty_message(&c, 1_100_000_000), AT, Cloud);
    assert_eq!(w.clock(), 1_000_000_000);
    // A far-future stamp on the cloud topic: held back by the gaze's.
    w.push(empty_message(&c, u64::MAX / 4), AT, Cloud);
    assert!(w.pop_due().is_none());
    w.push(empty_message(&g, 1_350_000_000), AT, Gaze);
    assert_eq!(w.clock(), 1_350_000_000);
    // The clock is 1.35 s: the messages at 1.0 and 1.1 s are more than
    // 200 ms older, due; the far ones are released only at the end.
    assert_eq!(w.pop_due().map(|p| p.log_time), Some(1_000_000_000));
    assert_eq!(w.pop_due().map(|p| p.log_time), Some(1_100_000_000));
    assert!(w.pop_due().is_none());
    assert_eq!(w.pop().map(|p| p.log_time), Some(1_350_000_000));
    assert_eq!(w.pop().map(|p| p.log_time), Some(u64::MAX / 4));
    assert_eq!(w.pop().map(|p| p.log_time), Some(u64::MAX / 3));
    assert_eq!(w.pop().map(|p| p.log_time), Some(u64::MAX / 2));
}

/// The azimuth of `v` by the reference rule: the horizontal part scaled by
/// a power of two (exact) until its larger component lies in [1, 2), then
/// `atan2`; a subnormal angle is 0.
fn reference_azimuth_deg(v: [f64; 3]) -> f64 {
    let (mut x, mut y) = (v[0], v[1]);
    while x.abs().max(y.abs()) < 1.0 {
        x *= 2.0;
        y *= 2.0;
    }
    while x.abs().max(y.abs()) >= 2.0 {
        x *= 0.5;
        y *= 0.5;
    }
    let a = y.atan2(x).to_degrees();
    crate::model::angle::wrap_deg(if a.abs() < f64::MIN_POSITIVE { 0.0 } else { a })
}

#[test]
fn a_tiny_component_still_gives_a_valid_azimuth() {
    for v in [
        [1.0, 1e-320, 0.0],
        [1.0, -1e-320, 0.0],
        [-1.0, 1e-320, 0.0],
        [1e-320, 1e-320, 0.0],
        [5e-324, 0.0, 1.0],
        [f64::MAX, f64::MAX, 0.0],
        [1e-310, 1.0, 0.0],
    ] {
        let a = vector_azimuth_deg(v).unwrap_or_else(|| panic!("{v:?} is a valid direction"));
        assert!(crate::model::valid::finite(a).is_ok(), "{v:?}: {a:e}");
        assert!((0.0..360.0).contains(&a), "{v:?}: {a}");
        assert_eq!(a, reference_azimuth_deg(v), "{v:?}");
    }
}

proptest::proptest! {
    /// Every finite vector with a non-zero horizontal part, at any scale,
    /// gives the azimuth the reference gives: finite, not subnormal, in
    /// [0, 360).
    #[test]
    fn scaled_vectors_keep_their_azimuth(
        az_deg in 0.0f64..360.0,
        z in -10.0f64..10.0,
        exp in -1074i32..=1023,
    ) {
        let (s, c) = az_deg.to_radians().sin_cos();
        let scale = 2f64.powi(exp);
        let v = [c * scale, s * scale, z * scale];
        proptest::prop_assume!(v.iter().all(|x| x.is_finite()) && (v[0] != 0.0 || v[1] != 0.0));
        let a = vector_azimuth_deg(v);
        proptest::prop_assert!(a.is_some(), "{:?}", v);
        let a = a.unwrap_or(f64::NAN);
        proptest::prop_assert!(crate::model::valid::finite(a).is_ok(), "{:?}: {:e}", v, a);
        proptest::prop_assert!((0.0..360.0).contains(&a), "{:?}: {}", v, a);
        let want = reference_azimuth_deg(v);
        let d = (a - want).abs();
        proptest::prop_assert!(d.min(360.0 - d) <= 1e-9, "{:?}: {} vs {}", v, a, want);
        // Where the scaled vector kept its bits, the azimuth is the unscaled one.
        if exp > -1000 && exp < 1000 {
            let d = (a - reference_azimuth_deg([c, s, z])).abs();
            proptest::prop_assert!(d.min(360.0 - d) <= 1e-9, "{:?}", v);
        }
    }
}

#[test]
fn marker_stamps_past_2038_saturate_both_fields() {
    use super::scene::ros_time;
    assert_eq!(ros_time(0), (0, 0));
    assert_eq!(ros_time(1_500_000_001), (1, 500_000_001));
    let last = i32::MAX as u64 * 1_000_000_000 + 999_999_999;
    assert_eq!(ros_time(last), (i32::MAX, 999_999_999));
    // One nanosecond later and beyond: the last stamp, never a mix of a
    // capped sec and the true nanosec.
    assert_eq!(ros_time(last + 1), (i32::MAX, 999_999_999));
    assert_eq!(ros_time(last + 123_456_790), (i32::MAX, 999_999_999));
    assert_eq!(ros_time(u64::MAX), (i32::MAX, 999_999_999));
}
