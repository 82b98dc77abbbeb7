//! Arbitrary gaze, bin count, mode, accounting and acuity model through the
//! closed-form planner: never panics; whatever it returns is within every
//! declared limit by an independent recomputation (not a second run of the
//! checker that has just certified it).
#![no_main]

#[path = "../../tests/it/independent.rs"]
mod independent;

use gaze_lidar::model::acuity::{AcuityModel, AcuitySample};
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if data.len() < 20 {
        return;
    }
    let f = |i: usize| f64::from_le_bytes(data[i..i + 8].try_into().unwrap_or([0; 8]));
    let gaze = f(0);
    let param = f(8);
    // Up to 2051 bins keeps runs fast; 0..=3 exercises the bin-count errors.
    let bins = usize::from(u16::from_le_bytes([data[16], data[17]]) % 2052);
    let mode = Mode::ALL[usize::from(data[18]) % 4];
    let mut p = presets::paper();
    p.focus.threshold = (f64::from(data[19]) / 255.0).max(0.0);
    p.focus.acuity = match data[19] % 4 {
        0 => AcuityModel::Box { half_width_deg: param },
        1 => AcuityModel::LeviE2 { e2_deg: param },
        2 => AcuityModel::Gaussian { sigma_deg: param },
        _ => AcuityModel::Tabulated {
            samples: data[20..]
                .chunks(2)
                .map(|c| AcuitySample {
                    eccentricity_deg: f64::from(c[0]) - 128.0,
                    acuity: f64::from(*c.get(1).unwrap_or(&0)) / 255.0,
                })
                .collect(),
        },
    };
    if let Ok(c) = closed_form(&p, mode, Some(gaze), bins) {
        let broken = independent::recheck(c.profile());
        assert!(broken.is_empty(), "{broken:?}");
    }
});
