//! Every figure of the eye-safety evaluation, frozen bit for bit: a seeded
//! family of heads and profiles is evaluated
//! (`evaluate_segments_at_declared_distance`: a head on its declared
//! surface, the bound at any distance) and each report — every ratio, the
//! worst aperture position, the binding rule, the head's overlap figures —
//! is compared with the recorded file
//! `tests/data/head_golden/figures.txt`, every `f64` as the hex of its bits.
//! A change that makes the evaluation faster must leave every line as it is
//! (the long differential run of the bound against its reference stays
//! valid only for the same figures).
//!
//! The family:
//! - random heads of 1–128 channels (firing groups, azimuth offsets,
//!   origins off the axis, divergence, power scales), at 850–1550 nm (1500 nm: a band edge), on
//!   random 1–6-bin profiles (some accelerating) and 72-bin profiles;
//! - the three real presets' heads (`vls128`, `vlp16`, `os1-128`, their
//!   eye-safety parameters as `gaze-lidar sensor --preset P` writes them,
//!   in `tests/data/head_golden/presets.json`) on a 360-bin accelerating
//!   profile and on random profiles inside the preset's spin limits;
//! - one channel (no head): every committed eye-safety profile
//!   (`tests/data/eye_safety/`, `tests/data/optimizer/`: the
//!   counterexamples, the AEL step-down and regression profiles), each also
//!   with the 1-channel head of the single-channel shape, and random
//!   single-channel profiles of 1–200 bins.
//!
//! Errors are recorded too (their message). Inputs are built with
//! arithmetic only (no library trigonometry), so they are the same bits on
//! every platform.
//!
//! Run: `cargo test --release -p gaze-lidar-core --test head_figures_golden`.
//! Regenerate the file (only when a figure is meant to change, saying why in
//! the commit): `GAZE_LIDAR_GOLDEN_REGENERATE=1` with the same command.

use gaze_lidar_core::testing::eye_cases;

use gaze_lidar_core::eye_safety::bound::Seg;
use gaze_lidar_core::eye_safety::exposure::evaluate_segments_at_declared_distance;
use gaze_lidar_core::eye_safety::head::{Channel, Head};
use gaze_lidar_core::eye_safety::EyeSafetyParams;
use gaze_lidar_core::profile::Profile;
use serde_json::Value;
use std::path::PathBuf;

/// Environment variable that rewrites the recorded file from the current code.
const REGENERATE: &str = "GAZE_LIDAR_GOLDEN_REGENERATE";

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/head_golden")
}

/// Deterministic generator (SplitMix64).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

struct Case {
    name: String,
    segs: Vec<Seg>,
    params: EyeSafetyParams,
    f_p: f64,
}

/// `n` bins covering the circle with random widths, powers in
/// `[p_lo, p_hi]` and spins in `[w_lo, w_hi]` (accelerating inside the bins
/// when `accel`).
fn random_profile(
    rng: &mut Rng,
    n: usize,
    (p_lo, p_hi): (f64, f64),
    (w_lo, w_hi): (f64, f64),
    accel: bool,
) -> Vec<Seg> {
    let mut widths: Vec<f64> = (0..n).map(|_| rng.range(0.2, 1.0)).collect();
    let total: f64 = widths.iter().sum();
    for w in &mut widths {
        *w *= 360.0 / total;
    }
    let spins: Vec<f64> = (0..n).map(|_| rng.range(w_lo, w_hi)).collect();
    let mut start = 0.0;
    (0..n)
        .map(|i| {
            let s = Seg {
                start_deg: start,
                width_deg: widths[i],
                power_w: rng.range(p_lo, p_hi),
                spin_start_rad_s: spins[i],
                spin_end_rad_s: if accel { spins[(i + 1) % n] } else { spins[i] },
            };
            start += widths[i];
            s
        })
        .collect()
}

/// 360 one-degree bins: power `scale·(1 + tri(3x)/2)` and spin
/// `mid + amp·tri(x)` (`tri` a triangle wave in [−1, 1]), accelerating
/// inside the bins.
fn ramp_profile(scale: f64, mid: f64, amp: f64) -> Vec<Seg> {
    let tri = |x: f64, period: f64| {
        let u = (x / period).fract();
        if u < 0.5 {
            4.0 * u - 1.0
        } else {
            3.0 - 4.0 * u
        }
    };
    (0..360)
        .map(|i| {
            let x = f64::from(i);
            Seg {
                start_deg: x,
                width_deg: 1.0,
                power_w: scale * (1.0 + 0.5 * tri(x, 120.0)),
                spin_start_rad_s: mid + amp * tri(x, 360.0),
                spin_end_rad_s: mid + amp * tri(x + 1.0, 360.0),
            }
        })
        .collect()
}

fn random_head(rng: &mut Rng, n_ch: usize, cycle_s: f64) -> Head {
    let groups = 1 + rng.below(n_ch.min(16));
    let group_slots: Vec<f64> = (0..groups).map(|_| rng.range(0.0, cycle_s)).collect();
    let spread_el = rng.range(0.2, 15.0);
    let spread_az = if rng.below(3) == 0 {
        0.0
    } else {
        rng.range(0.0, 25.0)
    };
    let channels = (0..n_ch)
        .map(|i| Channel {
            id: i as u32,
            elevation_deg: if rng.below(8) == 0 {
                0.0
            } else {
                rng.range(-spread_el, spread_el)
            },
            azimuth_offset_deg: if spread_az == 0.0 {
                0.0
            } else {
                rng.range(-spread_az, spread_az)
            },
            slot_s: group_slots[rng.below(groups)],
            power_scale: if rng.below(2) == 0 {
                1.0
            } else {
                rng.range(0.3, 1.0)
            },
        })
        .collect();
    Head {
        cycle_s,
        origin_radius_mm: if rng.below(4) == 0 {
            0.0
        } else {
            rng.range(0.0, 60.0)
        },
        origin_height_mm: rng.range(-5.0, 5.0),
        exit_diameter_mm: rng.range(0.5, 10.0),
        divergence_mrad: if rng.below(3) == 0 {
            0.0
        } else {
            rng.range(0.0, 3.0)
        },
        aperture_distance_mm: if rng.below(5) == 0 {
            rng.range(80.0, 200.0)
        } else {
            100.0
        },
        channels,
    }
}

fn random_head_cases(out: &mut Vec<Case>) {
    let mut rng = Rng(0x6865_6164_5f67_6f6c);
    for i in 0..240 {
        let n_ch = match rng.below(6) {
            0 => 64 + rng.below(65),
            1 => 13 + rng.below(51),
            _ => 1 + rng.below(12),
        };
        let cycle_s = if rng.below(4) == 0 {
            rng.range(5.5e-6, 1e-5)
        } else {
            rng.range(1e-5, 8e-5)
        };
        let head = random_head(&mut rng, n_ch, cycle_s);
        let wavelength_nm = [850.0, 905.0, 905.0, 1000.0, 1450.0, 1550.0][rng.below(6)];
        let pulse_duration_s = if rng.below(5) == 0 { 1e-7 } else { 5e-9 };
        let params = EyeSafetyParams {
            wavelength_nm,
            pulse_duration_s,
            beam_diameter_mm: head.exit_diameter_mm,
            head: Some(head),
        };
        let bins = if rng.below(4) == 0 {
            72
        } else {
            1 + rng.below(6)
        };
        let accel = rng.below(2) == 0;
        let segs = random_profile(&mut rng, bins, (1e-4, 0.05), (20.0, 600.0), accel);
        out.push(Case {
            name: format!("random_head_{i:03}_{n_ch}ch_{bins}bins"),
            segs,
            params,
            f_p: 1.0 / cycle_s,
        });
    }
}

fn preset_cases(out: &mut Vec<Case>) {
    let text = std::fs::read_to_string(data_dir().join("presets.json")).unwrap();
    let presets: Value = serde_json::from_str(&text).unwrap();
    let mut rng = Rng(0x0070_7265_7365_7473);
    for name in ["vls128", "vlp16", "os1-128"] {
        let p = &presets[name];
        let f_p = p["pulse_rate_hz"].as_f64().unwrap();
        let (w_lo, w_hi) = (
            p["spin_rad_s_min"].as_f64().unwrap(),
            p["spin_rad_s_max"].as_f64().unwrap(),
        );
        let p_max = p["power_w_max"].as_f64().unwrap();
        let params: EyeSafetyParams = serde_json::from_value(p["eye_safety"].clone()).unwrap();
        let single = EyeSafetyParams {
            head: None,
            ..params.clone()
        };
        let mid = 0.5 * (w_lo + w_hi);
        let amp = 0.25 * (w_hi - w_lo);
        for (tag, prm) in [("head", &params), ("one_channel", &single)] {
            out.push(Case {
                name: format!("preset_{name}_{tag}_ramp360"),
                segs: ramp_profile(p_max, mid, amp),
                params: prm.clone(),
                f_p,
            });
        }
        for k in 0..4 {
            let bins = [1, 8, 90, 360][k];
            let segs = random_profile(
                &mut rng,
                bins,
                (0.1 * p_max, p_max),
                (w_lo, w_hi),
                k % 2 == 1,
            );
            out.push(Case {
                name: format!("preset_{name}_head_random_{bins}bins"),
                segs,
                params: params.clone(),
                f_p,
            });
        }
    }
}

/// The 1-channel head of the single-channel model (radial, flat, from the
/// axis, no divergence, exit diameter = the beam at the aperture).
fn trivial_head(params: &EyeSafetyParams, pulse_rate_hz: f64) -> Head {
    Head {
        cycle_s: 1.0 / pulse_rate_hz,
        origin_radius_mm: 0.0,
        origin_height_mm: 0.0,
        exit_diameter_mm: params.beam_diameter_mm,
        divergence_mrad: 0.0,
        aperture_distance_mm: 100.0,
        channels: vec![Channel {
            id: 0,
            elevation_deg: 0.0,
            azimuth_offset_deg: 0.0,
            slot_s: 0.0,
            power_scale: 1.0,
        }],
    }
}

fn single_channel_cases(out: &mut Vec<Case>) {
    for dir in [
        eye_cases::data_dir(),
        eye_cases::data_dir().join("../optimizer"),
    ] {
        let mut paths: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        paths.sort();
        for path in paths {
            let text = std::fs::read_to_string(&path).unwrap();
            let p = Profile::from_json(&text, &path.display().to_string()).unwrap();
            let Some(params) = p.limits.eye_safety.clone() else {
                continue;
            };
            let stem = path.file_stem().unwrap().to_string_lossy().to_string();
            let segs = gaze_lidar_core::eye_safety::exposure::segments(&p);
            let with_head = EyeSafetyParams {
                head: Some(trivial_head(&params, p.pulse_rate_hz)),
                ..params.clone()
            };
            out.push(Case {
                name: format!("profile_{stem}"),
                segs: segs.clone(),
                params,
                f_p: p.pulse_rate_hz,
            });
            out.push(Case {
                name: format!("profile_{stem}_one_channel_head"),
                segs,
                params: with_head,
                f_p: p.pulse_rate_hz,
            });
        }
    }
    let mut rng = Rng(0x6f6e_655f_6368);
    for i in 0..80 {
        let wavelength_nm = [850.0, 905.0, 905.0, 1000.0, 1500.0, 1550.0][rng.below(6)];
        let params = EyeSafetyParams {
            wavelength_nm,
            pulse_duration_s: if rng.below(5) == 0 { 1e-7 } else { 5e-9 },
            beam_diameter_mm: rng.range(0.5, 12.0),
            head: None,
        };
        let f_p = rng.range(5e3, 5e5);
        let bins = [1, 2, 5, 17, 60, 200][rng.below(6)];
        let accel = rng.below(2) == 0;
        let segs = random_profile(&mut rng, bins, (1e-4, 0.05), (5.0, 600.0), accel);
        out.push(Case {
            name: format!("one_channel_{i:03}_{bins}bins"),
            segs,
            params,
            f_p,
        });
    }
}

fn cases() -> Vec<Case> {
    let mut out = Vec::new();
    random_head_cases(&mut out);
    preset_cases(&mut out);
    single_channel_cases(&mut out);
    out
}

/// Every `f64` of `v` as `0x` and the hex of its bits (integers and strings
/// as they are).
fn hex_floats(v: Value) -> Value {
    match v {
        Value::Number(n) if n.is_f64() => {
            Value::String(format!("0x{:016x}", n.as_f64().unwrap().to_bits()))
        }
        Value::Array(a) => Value::Array(a.into_iter().map(hex_floats).collect()),
        Value::Object(o) => Value::Object(o.into_iter().map(|(k, x)| (k, hex_floats(x))).collect()),
        other => other,
    }
}

/// One line per case: its name, a tab, the report (or the error) as JSON
/// with every float as its bits.
fn record(case: &Case) -> String {
    let figures = match evaluate_segments_at_declared_distance(&case.segs, &case.params, case.f_p) {
        Ok(report) => hex_floats(serde_json::to_value(&report).unwrap()),
        Err(e) => serde_json::json!({ "error": e.to_string() }),
    };
    format!(
        "{}\t{}",
        case.name,
        serde_json::to_string(&figures).unwrap()
    )
}

/// The first field where two recorded reports differ, with both values.
fn first_difference(path: &str, a: &Value, b: &Value) -> Option<String> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for (k, va) in x {
                let vb = y.get(k).unwrap_or(&Value::Null);
                if let Some(d) = first_difference(&format!("{path}.{k}"), va, vb) {
                    return Some(d);
                }
            }
            y.keys()
                .find(|k| !x.contains_key(*k))
                .map(|k| format!("{path}.{k}: only in the recorded file"))
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (va, vb))| first_difference(&format!("{path}[{i}]"), va, vb)),
        _ if a == b => None,
        _ => {
            let show = |v: &Value| match v.as_str().and_then(|s| s.strip_prefix("0x")) {
                Some(h) => match u64::from_str_radix(h, 16) {
                    Ok(bits) => format!("{v} ({:e})", f64::from_bits(bits)),
                    Err(_) => v.to_string(),
                },
                None => v.to_string(),
            };
            Some(format!("{path}: now {}, recorded {}", show(a), show(b)))
        }
    }
}

#[test]
fn every_figure_is_bit_identical_to_the_recorded_file() {
    let path = data_dir().join("figures.txt");
    let now: Vec<String> = cases().iter().map(record).collect();
    assert!(now.len() >= 300, "{} cases", now.len());
    if std::env::var_os(REGENERATE).is_some() {
        std::fs::write(&path, now.join("\n") + "\n").unwrap();
        eprintln!("wrote {} cases to {}", now.len(), path.display());
        return;
    }
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (record it with {REGENERATE}=1)", path.display()));
    let recorded: Vec<&str> = text.lines().collect();
    assert_eq!(
        recorded.len(),
        now.len(),
        "the recorded file has {} cases, the family {}",
        recorded.len(),
        now.len()
    );
    let mut differ = Vec::new();
    for (line, old) in now.iter().zip(&recorded) {
        if line == old {
            continue;
        }
        let (name, a) = line.split_once('\t').unwrap();
        let (old_name, b) = old.split_once('\t').unwrap();
        assert_eq!(name, old_name, "the family's order changed");
        let (a, b): (Value, Value) = (
            serde_json::from_str(a).unwrap(),
            serde_json::from_str(b).unwrap(),
        );
        differ.push(format!(
            "{name}: {}",
            first_difference("", &a, &b).unwrap_or_else(|| "the line's text".into())
        ));
    }
    assert!(
        differ.is_empty(),
        "{} of {} cases differ from the recorded figures:\n{}",
        differ.len(),
        now.len(),
        differ.join("\n")
    );
}

/// The comparison can fail: one flipped bit of one recorded figure is found
/// and named.
#[test]
fn a_changed_bit_is_named() {
    let a: Value =
        serde_json::json!({"worst_ratio": "0x3fef000000000000", "rule_ratios": ["0x0", "0x1"]});
    let b: Value =
        serde_json::json!({"worst_ratio": "0x3fef000000000000", "rule_ratios": ["0x0", "0x3"]});
    let d = first_difference("", &a, &b).unwrap();
    assert!(d.starts_with(".rule_ratios[1]: now"), "{d}");
    assert_eq!(first_difference("", &a, &a), None);
    assert_eq!(
        hex_floats(serde_json::json!(1.0)),
        Value::String("0x3ff0000000000000".into())
    );
}
