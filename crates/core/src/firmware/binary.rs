//! Fixed-size binary encoding of a firmware table (what a vendor flashes),
//! little-endian:
//!
//! | offset | size | field |
//! |---:|---:|---|
//! | 0 | 4 | magic `GLFW` |
//! | 4 | 2 | version = 2 |
//! | 6 | 1 | accounting: 0 time, 1 angle |
//! | 7 | 1 | eye-safety parameters: 0 absent (fields at 72–95 zero), 1 present without a head (one channel), 2 present with a head (the head section follows the records) |
//! | 8 | 8 | tick_hz |
//! | 16 | 8 | frame_ticks |
//! | 24 | 8 | power_w_per_code (IEEE-754 f64) |
//! | 32 | 4 | power_code_min |
//! | 36 | 4 | power_code_max |
//! | 40 | 8 | energy_budget |
//! | 48 | 4 | window_bins |
//! | 52 | 8 | window_energy_max |
//! | 60 | 4 | bin count n |
//! | 64 | 8 | pulse_rate_hz (f64) |
//! | 72 | 8 | eye_safety.wavelength_nm (f64) |
//! | 80 | 8 | eye_safety.pulse_duration_s (f64) |
//! | 88 | 8 | eye_safety.beam_diameter_mm (f64) |
//! | 96 | 36·n | records: width_mdeg u32, dwell_ticks u64, power_code u32, dwell_ticks_min u64, dwell_ticks_max u64, power_code_cap u32 |
//!
//!
//! The head section (only when byte 7 is 2; `m` channels), at `h = 96 + 36·n`:
//!
//! | offset | size | field |
//! |---:|---:|---|
//! | h + 0 | 4 | section magic `HEAD` |
//! | h + 4 | 2 | section version = 1 |
//! | h + 6 | 2 | reserved = 0 |
//! | h + 8 | 4 | channel count m (1..=512) |
//! | h + 12 | 4 | reserved = 0 |
//! | h + 16 | 8 | head.cycle_s (f64) |
//! | h + 24 | 8 | head.origin_radius_mm (f64) |
//! | h + 32 | 8 | head.origin_height_mm (f64) |
//! | h + 40 | 8 | head.exit_diameter_mm (f64) |
//! | h + 48 | 8 | head.divergence_mrad (f64) |
//! | h + 56 | 8 | head.aperture_distance_mm (f64) |
//! | h + 64 | 40·m | channels, in the table's order: id u32, reserved u32 = 0, elevation_deg f64, azimuth_offset_deg f64, slot_s f64, power_scale f64 |
//!
//! A table without a head encodes exactly as before heads existed (byte 7
//! is 0 or 1, nothing after the records), so every earlier binary decodes
//! unchanged; a decoder that predates heads refuses byte 7 = 2 instead of
//! silently dropping the head. The section carries its own version so it
//! can grow without touching the table's.
//!
//! [`decode`] never panics and rejects anything that is not exactly this
//! layout (so whatever decodes re-encodes to the same bytes). The numbers
//! themselves are validated where every table's are, by the checker
//! (`EyeSafetyParams::validate`, `head::Head::validate`).

use alloc::borrow::ToOwned;
use alloc::vec::Vec;

use thiserror::Error;

use super::{FirmwareTable, FwBin, IntLimits, FIRMWARE_FORMAT, MAX_TABLE_BINS};
use crate::model::accounting::PowerAccounting;

/// Header size, bytes.
pub const HEADER_LEN: usize = 96;
/// Record size, bytes.
pub const RECORD_LEN: usize = 36;
/// The first four bytes of every encoded table.
pub const MAGIC: &[u8; 4] = b"GLFW";
const VERSION: u16 = 2;
/// Head section: fixed part, bytes.
pub const HEAD_LEN: usize = 64;
/// Head section: one channel record, bytes.
pub const CHANNEL_LEN: usize = 40;
/// The first four bytes of the head section.
pub const HEAD_MAGIC: &[u8; 4] = b"HEAD";
const HEAD_VERSION: u16 = 1;

/// Why bytes are not a table.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum DecodeError {
    /// Too short for the header.
    #[error("{0} bytes: shorter than the {HEADER_LEN}-byte header")]
    Short(usize),
    /// Wrong magic.
    #[error("not a gaze-lidar firmware table (bad magic)")]
    Magic,
    /// Unknown version.
    #[error("unsupported version {0}")]
    Version(u16),
    /// Bad accounting byte.
    #[error("accounting byte {0} is neither 0 (time) nor 1 (angle)")]
    Accounting(u8),
    /// Bin count out of range.
    #[error("bin count {0} outside 1..={MAX_TABLE_BINS}")]
    Count(u32),
    /// Length does not match the bin count.
    #[error("length {found} bytes, expected {expected} for the bin count")]
    Length {
        /// Found.
        found: usize,
        /// Expected.
        expected: usize,
    },
    /// The reserved header byte is not zero.
    #[error("reserved header byte is {0}, must be 0")]
    Reserved(u8),
    /// The DAC step is not a positive finite number.
    #[error("power_w_per_code is not finite and > 0")]
    Step,
    /// The head section is malformed.
    #[error("head section: {0}")]
    Head(&'static str),
}

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}
fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}
fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// Encodes a table.
#[must_use]
pub fn encode(t: &FirmwareTable) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + RECORD_LEN * t.bins.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.push(match t.power_accounting {
        PowerAccounting::Time => 0,
        PowerAccounting::Angle => 1,
    });
    let head = t.eye_safety.as_ref().and_then(|e| e.head.as_ref());
    out.push(match (&t.eye_safety, head) {
        (None, _) => 0,
        (Some(_), None) => 1,
        (Some(_), Some(_)) => 2,
    });
    out.extend_from_slice(&t.tick_hz.to_le_bytes());
    out.extend_from_slice(&t.frame_ticks.to_le_bytes());
    out.extend_from_slice(&t.power_w_per_code.to_le_bytes());
    out.extend_from_slice(&t.limits.power_code_min.to_le_bytes());
    out.extend_from_slice(&t.limits.power_code_max.to_le_bytes());
    out.extend_from_slice(&t.limits.energy_budget.to_le_bytes());
    out.extend_from_slice(&t.limits.window_bins.to_le_bytes());
    out.extend_from_slice(&t.limits.window_energy_max.to_le_bytes());
    out.extend_from_slice(&(t.bins.len() as u32).to_le_bytes());
    out.extend_from_slice(&t.pulse_rate_hz.to_le_bytes());
    let es = t.eye_safety.as_ref();
    for x in [
        es.map_or(0.0, |e| e.wavelength_nm),
        es.map_or(0.0, |e| e.pulse_duration_s),
        es.map_or(0.0, |e| e.beam_diameter_mm),
    ] {
        out.extend_from_slice(&x.to_le_bytes());
    }
    for b in &t.bins {
        out.extend_from_slice(&b.width_mdeg.to_le_bytes());
        out.extend_from_slice(&b.dwell_ticks.to_le_bytes());
        out.extend_from_slice(&b.power_code.to_le_bytes());
        out.extend_from_slice(&b.dwell_ticks_min.to_le_bytes());
        out.extend_from_slice(&b.dwell_ticks_max.to_le_bytes());
        out.extend_from_slice(&b.power_code_cap.to_le_bytes());
    }
    if let Some(h) = head {
        out.extend_from_slice(HEAD_MAGIC);
        out.extend_from_slice(&HEAD_VERSION.to_le_bytes());
        out.extend_from_slice(&0u16.to_le_bytes());
        // More than u32::MAX channels cannot be validated (at most 512), so
        // the saturation never decodes: the decoder refuses the count.
        out.extend_from_slice(
            &u32::try_from(h.channels.len())
                .unwrap_or(u32::MAX)
                .to_le_bytes(),
        );
        out.extend_from_slice(&0u32.to_le_bytes());
        for x in [
            h.cycle_s,
            h.origin_radius_mm,
            h.origin_height_mm,
            h.exit_diameter_mm,
            h.divergence_mrad,
            h.aperture_distance_mm,
        ] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        for c in &h.channels {
            out.extend_from_slice(&c.id.to_le_bytes());
            out.extend_from_slice(&0u32.to_le_bytes());
            for x in [
                c.elevation_deg,
                c.azimuth_offset_deg,
                c.slot_s,
                c.power_scale,
            ] {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
    out
}

/// Decodes the head section at `at`, which must run exactly to the end of
/// `bytes`.
fn decode_head(bytes: &[u8], at: usize) -> Result<crate::eye_safety::head::Head, DecodeError> {
    use crate::eye_safety::head::{Channel, Head, CHANNELS_MAX};
    let length = |expected: usize| DecodeError::Length {
        found: bytes.len(),
        expected,
    };
    let fixed_end = at + HEAD_LEN;
    if bytes.len() < fixed_end {
        return Err(length(fixed_end));
    }
    if bytes.get(at..at + 4) != Some(&HEAD_MAGIC[..]) {
        return Err(DecodeError::Head("bad magic (expected HEAD)"));
    }
    if u16_at(bytes, at + 4) != Some(HEAD_VERSION) {
        return Err(DecodeError::Head("unsupported section version"));
    }
    if u16_at(bytes, at + 6) != Some(0) || u32_at(bytes, at + 12) != Some(0) {
        return Err(DecodeError::Head("reserved bytes must be 0"));
    }
    let m = u32_at(bytes, at + 8).ok_or(length(fixed_end))? as usize;
    if m == 0 || m > CHANNELS_MAX {
        return Err(DecodeError::Head("channel count outside 1..=512"));
    }
    let expected = fixed_end + CHANNEL_LEN * m;
    if bytes.len() != expected {
        return Err(length(expected));
    }
    let f = |k: usize| u64_at(bytes, k).map(f64::from_bits).ok_or(length(expected));
    let mut channels = Vec::with_capacity(m);
    for k in 0..m {
        let c = fixed_end + CHANNEL_LEN * k;
        if u32_at(bytes, c + 4) != Some(0) {
            return Err(DecodeError::Head("reserved bytes must be 0"));
        }
        channels.push(Channel {
            id: u32_at(bytes, c).ok_or(length(expected))?,
            elevation_deg: f(c + 8)?,
            azimuth_offset_deg: f(c + 16)?,
            slot_s: f(c + 24)?,
            power_scale: f(c + 32)?,
        });
    }
    Ok(Head {
        cycle_s: f(at + 16)?,
        origin_radius_mm: f(at + 24)?,
        origin_height_mm: f(at + 32)?,
        exit_diameter_mm: f(at + 40)?,
        divergence_mrad: f(at + 48)?,
        aperture_distance_mm: f(at + 56)?,
        channels,
    })
}

/// Decodes a table; never panics. Bin start azimuths are rebuilt from the widths.
pub fn decode(bytes: &[u8]) -> Result<FirmwareTable, DecodeError> {
    let short = || DecodeError::Short(bytes.len());
    if bytes.len() < HEADER_LEN {
        return Err(short());
    }
    if bytes.get(0..4) != Some(&MAGIC[..]) {
        return Err(DecodeError::Magic);
    }
    let version = u16_at(bytes, 4).ok_or_else(short)?;
    if version != VERSION {
        return Err(DecodeError::Version(version));
    }
    let accounting = match bytes.get(6).copied().ok_or_else(short)? {
        0 => PowerAccounting::Time,
        1 => PowerAccounting::Angle,
        other => return Err(DecodeError::Accounting(other)),
    };
    let (has_eye_safety, has_head) = match bytes.get(7).copied().ok_or_else(short)? {
        0 => (false, false),
        1 => (true, false),
        2 => (true, true),
        other => return Err(DecodeError::Reserved(other)),
    };
    let f64_at = |at: usize| u64_at(bytes, at).map(f64::from_bits);
    let pulse_rate_hz = f64_at(64).ok_or_else(short)?;
    let es = [f64_at(72), f64_at(80), f64_at(88)];
    let mut eye_safety = if has_eye_safety {
        Some(crate::eye_safety::EyeSafetyParams {
            wavelength_nm: es[0].ok_or_else(short)?,
            pulse_duration_s: es[1].ok_or_else(short)?,
            beam_diameter_mm: es[2].ok_or_else(short)?,
            head: None,
        })
    } else {
        // Absent means all-zero bytes (so -0.0 is not accepted: it would
        // re-encode differently).
        if es.iter().any(|x| x.map(f64::to_bits) != Some(0)) {
            return Err(DecodeError::Reserved(0));
        }
        None
    };
    let step = f64::from_bits(u64_at(bytes, 24).ok_or_else(short)?);
    if !(step.is_finite() && step > 0.0) {
        return Err(DecodeError::Step);
    }
    let n = u32_at(bytes, 60).ok_or_else(short)?;
    if n == 0 || n as usize > MAX_TABLE_BINS {
        return Err(DecodeError::Count(n));
    }
    let expected = HEADER_LEN + RECORD_LEN * n as usize;
    if has_head {
        let head = decode_head(bytes, expected)?;
        if let Some(e) = eye_safety.as_mut() {
            e.head = Some(head);
        }
    } else if bytes.len() != expected {
        return Err(DecodeError::Length {
            found: bytes.len(),
            expected,
        });
    }
    let mut bins = Vec::with_capacity(n as usize);
    let mut start_mdeg: u64 = 0;
    for k in 0..n as usize {
        let at = HEADER_LEN + RECORD_LEN * k;
        let width_mdeg = u32_at(bytes, at).ok_or_else(short)?;
        bins.push(FwBin {
            start_deg: start_mdeg as f64 / 1000.0,
            width_mdeg,
            dwell_ticks: u64_at(bytes, at + 4).ok_or_else(short)?,
            power_code: u32_at(bytes, at + 12).ok_or_else(short)?,
            dwell_ticks_min: u64_at(bytes, at + 16).ok_or_else(short)?,
            dwell_ticks_max: u64_at(bytes, at + 24).ok_or_else(short)?,
            power_code_cap: u32_at(bytes, at + 32).ok_or_else(short)?,
        });
        start_mdeg += u64::from(width_mdeg);
    }
    Ok(FirmwareTable {
        format: FIRMWARE_FORMAT.to_owned(),
        tick_hz: u64_at(bytes, 8).ok_or_else(short)?,
        frame_ticks: u64_at(bytes, 16).ok_or_else(short)?,
        power_w_per_code: step,
        power_accounting: accounting,
        pulse_rate_hz,
        eye_safety,
        limits: IntLimits {
            power_code_min: u32_at(bytes, 32).ok_or_else(short)?,
            power_code_max: u32_at(bytes, 36).ok_or_else(short)?,
            energy_budget: u64_at(bytes, 40).ok_or_else(short)?,
            window_bins: u32_at(bytes, 48).ok_or_else(short)?,
            window_energy_max: u64_at(bytes, 52).ok_or_else(short)?,
        },
        bins,
    })
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::{cover, for_all};

    /// REQ-FW-4, REQ-IN-1: decoding any byte string never panics; whatever decodes
    /// has a consistent length.
    #[cfg_attr(kani, kani::proof, kani::unwind(4))]
    #[cfg_attr(not(kani), test)]
    fn decode_never_panics() {
        for_all!(([u8; 136], u8), |(raw, len)| {
            let mut bytes = raw.to_vec();
            // Make the valid-header path reachable from random bytes.
            if len % 2 == 0 {
                bytes[0..4].copy_from_slice(MAGIC);
                bytes[4..6].copy_from_slice(&VERSION.to_le_bytes());
                bytes[6] %= 2;
                bytes[7] = 0;
                bytes[24..32].copy_from_slice(&1.0f64.to_le_bytes());
                bytes[60..64].copy_from_slice(&1u32.to_le_bytes());
                // Eye-safety fields absent: all zero (flag byte 7 is 0).
                bytes[72..96].fill(0);
            }
            let len = usize::from(len) % (bytes.len() + 1);
            match decode(&bytes[..len]) {
                Ok(t) => {
                    cover!(true, "a record decodes");
                    assert_eq!(HEADER_LEN + RECORD_LEN * t.bins.len(), len);
                    // Only the exact layout decodes: re-encoding gives the input back.
                    assert_eq!(encode(&t), &bytes[..len]);
                }
                Err(_) => cover!(true, "garbage is rejected"),
            }
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["a record decodes", "garbage is rejected"]);
    }

    /// REQ-FW-4: encode then decode is the identity on the integer content.
    #[cfg_attr(kani, kani::proof, kani::unwind(4))]
    #[cfg_attr(not(kani), test)]
    fn encode_decode_round_trip() {
        for_all!(([(u32, u64, u32); 3], u8, u64, bool), |(
            raw,
            n,
            frame_ticks,
            angle,
        )| {
            let n = 1 + usize::from(n % 3);
            let bins: Vec<FwBin> = raw[..n]
                .iter()
                .map(|&(w, ticks, code)| FwBin {
                    start_deg: 0.0,
                    width_mdeg: w % 1_000_000,
                    dwell_ticks: ticks,
                    power_code: code,
                    dwell_ticks_min: ticks / 2,
                    dwell_ticks_max: ticks,
                    power_code_cap: code / 3,
                })
                .collect();
            let t = FirmwareTable {
                format: FIRMWARE_FORMAT.to_owned(),
                tick_hz: 80_000_000,
                frame_ticks,
                power_w_per_code: 0.25,
                power_accounting: if angle {
                    PowerAccounting::Angle
                } else {
                    PowerAccounting::Time
                },
                pulse_rate_hz: 0.0,
                eye_safety: None,
                limits: IntLimits {
                    power_code_min: 1,
                    power_code_max: 4095,
                    energy_budget: frame_ticks,
                    window_bins: 2,
                    window_energy_max: 7,
                },
                bins,
            };
            let back = decode(&encode(&t)).expect("an encoded table decodes");
            cover!(n == 3, "three records");
            assert_eq!(back.limits, t.limits);
            assert_eq!(back.frame_ticks, t.frame_ticks);
            assert_eq!(back.power_accounting, t.power_accounting);
            for (a, b) in back.bins.iter().zip(&t.bins) {
                assert_eq!(
                    (
                        a.width_mdeg,
                        a.dwell_ticks,
                        a.power_code,
                        a.dwell_ticks_min,
                        a.dwell_ticks_max,
                        a.power_code_cap
                    ),
                    (
                        b.width_mdeg,
                        b.dwell_ticks,
                        b.power_code,
                        b.dwell_ticks_min,
                        b.dwell_ticks_max,
                        b.power_code_cap
                    )
                );
            }
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["three records"]);
    }

    /// A table with a head, three channels, every head field distinct.
    #[cfg(not(kani))]
    fn table_with_head() -> FirmwareTable {
        use crate::eye_safety::head::{Channel, Head};
        let channels = (0..3u32)
            .map(|k| Channel {
                id: 7 + 2 * k,
                elevation_deg: -11.742 + f64::from(k),
                azimuth_offset_deg: -6.354 + 1.5 * f64::from(k),
                slot_s: 2.665e-6 * f64::from(k),
                power_scale: 1.0 - 0.25 * f64::from(k),
            })
            .collect();
        FirmwareTable {
            format: FIRMWARE_FORMAT.to_owned(),
            tick_hz: 80_000_000,
            frame_ticks: 8_000_000,
            power_w_per_code: 1e-6,
            power_accounting: PowerAccounting::Time,
            pulse_rate_hz: 1.0 / 53.3e-6,
            eye_safety: Some(crate::eye_safety::EyeSafetyParams {
                wavelength_nm: 903.0,
                pulse_duration_s: 3e-9,
                beam_diameter_mm: 8.0,
                head: Some(Head {
                    cycle_s: 53.3e-6,
                    origin_radius_mm: 58.63,
                    origin_height_mm: -1.5,
                    exit_diameter_mm: 8.0,
                    divergence_mrad: 3.0,
                    aperture_distance_mm: 100.0,
                    channels,
                }),
            }),
            limits: IntLimits {
                power_code_min: 1,
                power_code_max: 4095,
                energy_budget: 1 << 40,
                window_bins: 2,
                window_energy_max: 7,
            },
            bins: (0..2)
                .map(|k| FwBin {
                    start_deg: 180.0 * f64::from(k),
                    width_mdeg: 180_000,
                    dwell_ticks: 4_000_000,
                    power_code: 1500,
                    dwell_ticks_min: 3_000_000,
                    dwell_ticks_max: 5_000_000,
                    power_code_cap: 2000,
                })
                .collect(),
        }
    }

    /// The head section round-trips field for field, and a table without a
    /// head encodes exactly as before (nothing after the records).
    #[cfg(not(kani))]
    #[test]
    fn head_section_round_trips() {
        let t = table_with_head();
        let bytes = encode(&t);
        assert_eq!(bytes[7], 2);
        assert_eq!(
            bytes.len(),
            HEADER_LEN + 2 * RECORD_LEN + HEAD_LEN + 3 * CHANNEL_LEN
        );
        let back = decode(&bytes).unwrap();
        assert_eq!(back, t);
        assert_eq!(encode(&back), bytes);
        let mut one = t.clone();
        one.eye_safety.as_mut().unwrap().head = None;
        let plain = encode(&one);
        assert_eq!(plain[7], 1);
        assert_eq!(plain.len(), HEADER_LEN + 2 * RECORD_LEN);
        assert_eq!(plain[..7], bytes[..7]);
        assert_eq!(plain[8..], bytes[8..plain.len()]);
        assert_eq!(decode(&plain).unwrap(), one);
    }

    /// Decoding the head section is strict: every truncation, any extra
    /// byte, and every field outside the layout is refused.
    #[cfg(not(kani))]
    #[test]
    fn head_section_is_decoded_strictly() {
        let bytes = encode(&table_with_head());
        let h = HEADER_LEN + 2 * RECORD_LEN;
        for len in 0..bytes.len() {
            assert!(decode(&bytes[..len]).is_err(), "truncated to {len}");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(decode(&longer), Err(DecodeError::Length { .. })));
        let patched = |at: usize, with: &[u8]| {
            let mut b = bytes.clone();
            b[at..at + with.len()].copy_from_slice(with);
            decode(&b)
        };
        assert_eq!(
            patched(h, b"HEAX"),
            Err(DecodeError::Head("bad magic (expected HEAD)"))
        );
        assert_eq!(
            patched(h + 4, &2u16.to_le_bytes()),
            Err(DecodeError::Head("unsupported section version"))
        );
        assert_eq!(
            patched(h + 6, &[1]),
            Err(DecodeError::Head("reserved bytes must be 0"))
        );
        assert_eq!(
            patched(h + 12, &[1]),
            Err(DecodeError::Head("reserved bytes must be 0"))
        );
        assert_eq!(
            patched(h + HEAD_LEN + 4, &[1]),
            Err(DecodeError::Head("reserved bytes must be 0"))
        );
        assert_eq!(
            patched(h + 8, &0u32.to_le_bytes()),
            Err(DecodeError::Head("channel count outside 1..=512"))
        );
        assert_eq!(
            patched(h + 8, &513u32.to_le_bytes()),
            Err(DecodeError::Head("channel count outside 1..=512"))
        );
        assert!(matches!(
            patched(h + 8, &2u32.to_le_bytes()),
            Err(DecodeError::Length { .. })
        ));
        assert!(matches!(
            patched(h + 8, &4u32.to_le_bytes()),
            Err(DecodeError::Length { .. })
        ));
        // Flag 1 with a section after the records: the length is wrong.
        assert!(matches!(patched(7, &[1]), Err(DecodeError::Length { .. })));
        // Flag 2 without a section; flag 3 is reserved.
        let mut plain = bytes[..h].to_vec();
        assert!(matches!(decode(&plain), Err(DecodeError::Length { .. })));
        plain[7] = 3;
        assert_eq!(decode(&plain), Err(DecodeError::Reserved(3)));
    }

    /// Found by the fuzz smoke: with the eye-safety flag clear, a -0.0 in
    /// the parameter fields decoded, then re-encoded as +0.0.
    #[cfg(not(kani))]
    #[test]
    fn absent_eye_safety_fields_must_be_zero_bytes() {
        let mut bytes = vec![0u8; HEADER_LEN + RECORD_LEN];
        bytes[0..4].copy_from_slice(MAGIC);
        bytes[4..6].copy_from_slice(&VERSION.to_le_bytes());
        bytes[24..32].copy_from_slice(&1.0f64.to_le_bytes());
        bytes[60..64].copy_from_slice(&1u32.to_le_bytes());
        let t = decode(&bytes).unwrap();
        assert_eq!(encode(&t), bytes);
        bytes[80..88].copy_from_slice(&(-0.0f64).to_le_bytes());
        assert!(decode(&bytes).is_err());
    }
}
