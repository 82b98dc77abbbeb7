//! Issue 6 acceptance: firmware tables of the paper's profiles.

mod common;
mod independent;
mod reference;

use common::{run, stdout};
use gaze_lidar::firmware::{binary, check_table, FirmwareTable};
use gaze_lidar::profile::Profile;

/// The table as it will run, read by the reference evaluator: constant spin
/// over each bin's dwell (width / (ticks / tick_hz)), power = code · step.
fn as_run_scan(t: &FirmwareTable) -> reference::Scan {
    let es = t
        .eye_safety
        .as_ref()
        .expect("eye-safety params in the table");
    let mut start_deg = 0.0;
    let bins = t
        .bins
        .iter()
        .map(|b| {
            let width_deg = f64::from(b.width_mdeg) / 1000.0;
            let w = width_deg.to_radians() / (b.dwell_ticks as f64 / t.tick_hz as f64);
            let bin = reference::RBin {
                start_deg,
                width_deg,
                power_w: f64::from(b.power_code) * t.power_w_per_code,
                w0: w,
                w1: w,
            };
            start_deg += width_deg;
            bin
        })
        .collect();
    reference::Scan {
        bins,
        pulse_rate_hz: t.pulse_rate_hz,
        lambda_nm: es.wavelength_nm,
        pulse_s: es.pulse_duration_s,
        beam_mm: es.beam_diameter_mm,
    }
}

fn profile_and_table(mode: &str, gaze: &str) -> (Profile, FirmwareTable) {
    let t = run(
        &[
            "profile",
            "--preset",
            "paper",
            "--mode",
            mode,
            "--gaze-deg",
            gaze,
            "--format",
            "firmware",
        ],
        None,
    );
    assert_eq!(t.status.code(), Some(0), "{}", common::stderr(&t));
    (
        common::profile_from(&[
            "profile",
            "--preset",
            "paper",
            "--mode",
            mode,
            "--gaze-deg",
            gaze,
        ]),
        serde_json::from_str(&stdout(&t)).unwrap(),
    )
}

#[test]
fn paper_tables_are_exact_and_conservative() {
    for mode in ["range", "resolution", "joint"] {
        for gaze in ["90", "5"] {
            let (p, t) = profile_and_table(mode, gaze);
            assert_eq!(
                t.frame_ticks,
                (t.tick_hz as f64 / p.frame_rate_hz).round() as u64
            );
            assert_eq!(
                t.bins.iter().map(|b| b.dwell_ticks).sum::<u64>(),
                t.frame_ticks,
                "{mode} {gaze}"
            );
            assert_eq!(t.bins.len(), p.bins.len());
            for (b, fw) in p.bins.iter().zip(&t.bins) {
                let ideal = b.dwell_time_s() * t.tick_hz as f64;
                assert!(
                    (fw.dwell_ticks as f64 - ideal).abs() < 1.0,
                    "{mode} {gaze}: {} vs {ideal}",
                    fw.dwell_ticks
                );
                let code_w = f64::from(fw.power_code) * t.power_w_per_code;
                assert!(code_w <= b.power_w, "code above the certified power");
                assert!(
                    b.power_w - code_w < t.power_w_per_code,
                    "more than one code below"
                );
            }
            // Not `check_table` (the CLI only writes tables it accepts): the
            // integer limits restated independently, and the brute-force
            // reference finds no pulse train over Class 1 on the table as
            // it will run.
            let broken = independent::recheck_table(&t);
            assert!(broken.is_empty(), "{mode} {gaze}: {broken:?}");
            let found = reference::Reference::new(&as_run_scan(&t)).worst(&reference::Effort {
                phases: 4,
                ..reference::Effort::default()
            });
            assert!(found.ratio <= 1.0, "{mode} {gaze}: as run {found}");
        }
    }
}

#[test]
fn binary_tables_round_trip_and_tampering_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.bin");
    let o = run(
        &[
            "profile",
            "--mode",
            "joint",
            "--gaze-deg",
            "90",
            "--format",
            "firmware-bin",
            "--out",
            path.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0));
    let bytes = std::fs::read(&path).unwrap();
    let mut t = binary::decode(&bytes).unwrap();
    // The control of the tampering checks below: the decoded table is
    // accepted, so each rejection that follows is due to its one change.
    assert!(check_table(&t).is_empty());
    assert_eq!(binary::encode(&t), bytes);
    t.bins[3].dwell_ticks += 1;
    let v = check_table(&t);
    assert!(
        v.iter().any(|x| x.to_string().contains("frame_ticks")),
        "{v:?}"
    );
    t.bins[3].dwell_ticks -= 1;
    t.bins[200].power_code = t.bins[200].power_code_cap + 1;
    assert!(!check_table(&t).is_empty());
    assert!(binary::decode(&bytes[..bytes.len() - 1]).is_err());
}
