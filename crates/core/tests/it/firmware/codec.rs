//! Core-level tests of `firmware::quantize` and `firmware::binary` (found by
//! `cargo mutants`): the harnesses check properties (sums, bounds, round
//! trips, no panics); these pin the exact values, worked out by hand, and
//! every decode error at its edge.

use gaze_lidar_core::firmware::binary::{decode, encode, DecodeError, HEADER_LEN, RECORD_LEN};
use gaze_lidar_core::firmware::{
    apportion, floor_code, FirmwareTable, FwBin, IntLimits, QuantizeError, TickTarget,
    FIRMWARE_FORMAT, MAX_TABLE_BINS,
};
use gaze_lidar_core::model::lidar::PowerAccounting;

const HALF: u32 = 1 << 31;

fn tt(floor: u64, frac: u32, min: u64, max: u64) -> TickTarget {
    TickTarget {
        floor,
        frac,
        min,
        max,
    }
}

#[test]
fn tick_target_roundings_by_hand() {
    // (target, low, high, ceil)
    let cases = [
        (tt(5, HALF, 0, 10), Some(5), Some(6), Some(6)),
        (tt(5, 0, 0, 10), Some(5), Some(5), Some(5)),
        // Bounds exactly at floor and ceil.
        (tt(5, HALF, 5, 6), Some(5), Some(6), Some(6)),
        // Floor below the minimum: only the ceil.
        (tt(5, HALF, 6, 10), Some(6), Some(6), Some(6)),
        // Ceil above the maximum: only the floor.
        (tt(5, HALF, 0, 5), Some(5), Some(5), Some(6)),
        // Neither.
        (tt(5, HALF, 7, 9), None, None, Some(6)),
        (tt(5, HALF, 0, 4), None, None, Some(6)),
        (tt(5, 0, 6, 9), None, None, Some(5)),
        // The ceil overflows.
        (tt(u64::MAX, 1, 0, u64::MAX), None, None, None),
        (
            tt(u64::MAX, 0, 0, u64::MAX),
            Some(u64::MAX),
            Some(u64::MAX),
            Some(u64::MAX),
        ),
    ];
    for (t, low, high, ceil) in cases {
        assert_eq!(t.low(), low, "{t:?}");
        assert_eq!(t.high(), high, "{t:?}");
        assert_eq!(t.ceil(), ceil, "{t:?}");
    }
}

#[test]
fn apportion_by_hand() {
    // Floors 2 + 2 + 3 + 1 = 8, frame 10: the two largest remainders
    // (0.78 and 0.67 of a tick) round up.
    let f = |x: f64| (x * 4_294_967_296.0) as u32;
    let t = [
        tt(2, f(0.78), 0, 9),
        tt(2, f(0.22), 0, 9),
        tt(3, f(0.33), 0, 9),
        tt(1, f(0.67), 0, 9),
    ];
    assert_eq!(apportion(&t, 10), Ok(vec![3, 2, 3, 2]));
    assert_eq!(apportion(&t, 8), Ok(vec![2, 2, 3, 1]));
    assert_eq!(apportion(&t, 12), Ok(vec![3, 3, 4, 2]));
    // Equal remainders: lower index first.
    let e = [tt(4, HALF, 0, 9), tt(4, HALF, 0, 9), tt(4, HALF, 0, 9)];
    assert_eq!(apportion(&e, 13), Ok(vec![5, 4, 4]));
    assert_eq!(apportion(&e, 14), Ok(vec![5, 5, 4]));
    // A bin bounded to its floor is not flexible, however large its
    // remainder; a bin bounded above its floor starts at its ceil.
    let b = [
        tt(5, f(0.9), 0, 5),
        tt(5, f(0.1), 0, 10),
        tt(5, f(0.5), 6, 10),
    ];
    assert_eq!(apportion(&b, 16), Ok(vec![5, 5, 6]));
    assert_eq!(apportion(&b, 17), Ok(vec![5, 6, 6]));
    // Reachable range: low 5 + 5 + 6 = 16, high 5 + 6 + 6 = 17.
    assert_eq!(
        apportion(&b, 15),
        Err(QuantizeError::Total {
            total: 15,
            low: 16,
            high: 17
        })
    );
    assert_eq!(
        apportion(&b, 18),
        Err(QuantizeError::Total {
            total: 18,
            low: 16,
            high: 17
        })
    );
    // The first bin without an admissible rounding is named.
    let bad = [tt(5, HALF, 0, 9), tt(5, HALF, 7, 9), tt(5, HALF, 8, 9)];
    assert_eq!(
        apportion(&bad, 10),
        Err(QuantizeError::BinBounds { bin: 1 })
    );
    assert_eq!(apportion(&[], 0), Ok(vec![]));
}

#[test]
fn floor_code_by_hand() {
    assert_eq!(floor_code(7.0, 2.0), Some(3));
    assert_eq!(floor_code(6.0, 2.0), Some(3));
    assert_eq!(floor_code(0.0, 1.0), Some(0));
    assert_eq!(floor_code(1e-4, 2e-6), Some(50));
    // 0.35 / 0.005 rounds to 70.0, but 70 × 0.005 > 0.35 in floating point.
    assert!(std::hint::black_box(70.0f64) * 0.005 > 0.35);
    assert_eq!(floor_code(0.35, 0.005), Some(69));
    // 0.29 / 0.005 rounds to 57.99…, but 58 × 0.005 ≤ 0.29.
    let (c, v) = (std::hint::black_box(58.0f64), std::hint::black_box(0.29f64));
    assert!(c * 0.005 <= v && (v / 0.005).floor() == 57.0);
    assert_eq!(floor_code(0.29, 0.005), Some(58));
    // The largest code, and one past it.
    let max = f64::from(u32::MAX);
    assert_eq!(floor_code(max, 1.0), Some(u32::MAX));
    assert_eq!(floor_code(max + 0.5, 1.0), Some(u32::MAX));
    assert_eq!(floor_code(max + 1.0, 1.0), None);
    for (v, s) in [
        (f64::NAN, 1.0),
        (1.0, f64::NAN),
        (f64::INFINITY, 1.0),
        (1.0, f64::INFINITY),
        (-1.0, 1.0),
        (1.0, 0.0),
        (0.0, 0.0),
        (1.0, -1.0),
    ] {
        assert_eq!(floor_code(v, s), None, "{v} / {s}");
    }
}

fn table(bins: &[(u32, u64, u32)], eye: bool) -> FirmwareTable {
    FirmwareTable {
        format: FIRMWARE_FORMAT.to_owned(),
        tick_hz: 0x0102_0304_0506_0708,
        frame_ticks: 0x1112_1314_1516_1718,
        power_w_per_code: 0.25,
        power_accounting: PowerAccounting::Angle,
        pulse_rate_hz: 20_000.0,
        eye_safety: eye.then(gaze_lidar_core::testing::params),
        limits: IntLimits {
            power_code_min: 0x2122_2324,
            power_code_max: 0x3132_3334,
            energy_budget: 0x4142_4344_4546_4748,
            window_bins: 0x5152_5354,
            window_energy_max: 0x6162_6364_6566_6768,
        },
        bins: bins
            .iter()
            .map(|&(width_mdeg, dwell_ticks, power_code)| FwBin {
                start_deg: 0.0,
                width_mdeg,
                dwell_ticks,
                power_code,
                dwell_ticks_min: dwell_ticks / 2,
                dwell_ticks_max: dwell_ticks * 2,
                power_code_cap: 7,
            })
            .collect(),
    }
}

#[test]
fn encoding_layout_by_hand() {
    let t = table(&[(90_000, 250, 2), (270_000, 500, 4)], true);
    let b = encode(&t);
    assert_eq!(b.len(), 96 + 2 * 36);
    assert_eq!((HEADER_LEN, RECORD_LEN), (96, 36));
    assert_eq!(&b[0..4], b"GLFW");
    assert_eq!(&b[4..6], &[2, 0]);
    assert_eq!(b[6], 1); // angle
    assert_eq!(b[7], 1); // parameters present
    assert_eq!(&b[8..16], &[8, 7, 6, 5, 4, 3, 2, 1]);
    assert_eq!(
        &b[16..24],
        &[0x18, 0x17, 0x16, 0x15, 0x14, 0x13, 0x12, 0x11]
    );
    assert_eq!(&b[24..32], &0.25f64.to_bits().to_le_bytes());
    assert_eq!(&b[32..36], &[0x24, 0x23, 0x22, 0x21]);
    assert_eq!(&b[36..40], &[0x34, 0x33, 0x32, 0x31]);
    assert_eq!(
        &b[40..48],
        &[0x48, 0x47, 0x46, 0x45, 0x44, 0x43, 0x42, 0x41]
    );
    assert_eq!(&b[48..52], &[0x54, 0x53, 0x52, 0x51]);
    assert_eq!(
        &b[52..60],
        &[0x68, 0x67, 0x66, 0x65, 0x64, 0x63, 0x62, 0x61]
    );
    assert_eq!(&b[60..64], &[2, 0, 0, 0]);
    assert_eq!(&b[64..72], &20_000.0f64.to_bits().to_le_bytes());
    assert_eq!(&b[72..80], &905.0f64.to_bits().to_le_bytes());
    assert_eq!(&b[80..88], &5e-9f64.to_bits().to_le_bytes());
    assert_eq!(&b[88..96], &8.0f64.to_bits().to_le_bytes());
    // Second record at 132: width 270,000 = 0x41EB0, dwell 500 = 0x1F4,
    // code 4, min 250, max 1000 = 0x3E8, cap 7.
    let r = &b[132..168];
    assert_eq!(&r[0..4], &[0xB0, 0x1E, 0x04, 0]);
    assert_eq!(&r[4..12], &[0xF4, 0x01, 0, 0, 0, 0, 0, 0]);
    assert_eq!(&r[12..16], &[4, 0, 0, 0]);
    assert_eq!(&r[16..24], &[250, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(&r[24..32], &[0xE8, 0x03, 0, 0, 0, 0, 0, 0]);
    assert_eq!(&r[32..36], &[7, 0, 0, 0]);
    // Without parameters: flag 0, fields zero.
    let b0 = encode(&table(&[(360_000, 250, 2)], false));
    assert_eq!(b0[7], 0);
    assert!(b0[72..96].iter().all(|&x| x == 0));
    assert_eq!(b0[6], 1);
}

#[test]
fn decoding_by_hand() {
    let t = table(&[(90_000, 250, 2), (0, 0, 9), (270_000, 500, 4)], true);
    let d = decode(&encode(&t)).expect("decodes");
    // Starts rebuilt from the widths: 0°, 90°, 90°.
    let starts: Vec<f64> = d.bins.iter().map(|b| b.start_deg).collect();
    assert_eq!(starts, [0.0, 90.0, 90.0]);
    let mut want = t.clone();
    for (b, s) in want.bins.iter_mut().zip([0.0, 90.0, 90.0]) {
        b.start_deg = s;
    }
    assert_eq!(d, want);
    let t0 = table(&[(360_000, 250, 2)], false);
    assert_eq!(decode(&encode(&t0)), Ok(t0));
}

#[test]
fn decode_errors_at_their_edges() {
    let good = encode(&table(&[(360_000, 250, 2)], true));
    assert!(decode(&good).is_ok());
    let with = |at: usize, bytes: &[u8]| {
        let mut b = good.clone();
        b[at..at + bytes.len()].copy_from_slice(bytes);
        decode(&b)
    };
    assert_eq!(decode(&good[..95]), Err(DecodeError::Short(95)));
    assert_eq!(decode(&[]), Err(DecodeError::Short(0)));
    // Exactly a header: long enough to read, but one record is missing.
    assert_eq!(
        decode(&good[..96]),
        Err(DecodeError::Length {
            found: 96,
            expected: 132
        })
    );
    let mut longer = good.clone();
    longer.push(0);
    assert_eq!(
        decode(&longer),
        Err(DecodeError::Length {
            found: 133,
            expected: 132
        })
    );
    assert_eq!(with(0, b"GLFX"), Err(DecodeError::Magic));
    assert_eq!(with(4, &[1, 0]), Err(DecodeError::Version(1)));
    assert_eq!(with(4, &[2, 1]), Err(DecodeError::Version(258)));
    assert_eq!(with(6, &[2]), Err(DecodeError::Accounting(2)));
    assert_eq!(
        with(6, &[0]).map(|t| t.power_accounting),
        Ok(PowerAccounting::Time)
    );
    // Flag 2 announces a head section after the records: none here.
    assert_eq!(
        with(7, &[2]),
        Err(DecodeError::Length {
            found: 132,
            expected: 132 + 64
        })
    );
    assert_eq!(with(7, &[3]), Err(DecodeError::Reserved(3)));
    // Flag clear but parameter bytes present.
    assert_eq!(with(7, &[0]), Err(DecodeError::Reserved(0)));
    for step in [0.0f64, -0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(
            with(24, &step.to_bits().to_le_bytes()),
            Err(DecodeError::Step),
            "{step}"
        );
    }
    assert_eq!(
        with(24, &f64::MIN_POSITIVE.to_bits().to_le_bytes()).map(|t| t.power_w_per_code),
        Ok(f64::MIN_POSITIVE)
    );
    assert_eq!(with(60, &[0, 0, 0, 0]), Err(DecodeError::Count(0)));
    let n = u32::try_from(MAX_TABLE_BINS).unwrap();
    assert_eq!(
        with(60, &(n + 1).to_le_bytes()),
        Err(DecodeError::Count(n + 1))
    );
    // The most bins a table holds decodes.
    let mut big = good[..HEADER_LEN].to_vec();
    big[60..64].copy_from_slice(&n.to_le_bytes());
    for _ in 0..MAX_TABLE_BINS {
        big.extend_from_slice(&good[HEADER_LEN..]);
    }
    let d = decode(&big).expect("36,000 bins decode");
    assert_eq!(d.bins.len(), MAX_TABLE_BINS);
    assert_eq!(d.bins[1].start_deg, 360.0);
}
