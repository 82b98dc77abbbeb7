//! Helpers shared by the core's integration tests.

use gaze_lidar_core::eye_safety::EyeSafetyParams;
use gaze_lidar_core::firmware::{FirmwareTable, FwBin, IntLimits, FIRMWARE_FORMAT};
use gaze_lidar_core::model::PowerAccounting;

/// A time-accounted table of `(width_mdeg, dwell_ticks, code)` bins at
/// 1 mW per code, with open limits and unconstrained bins; frame = Σ dwell.
#[allow(dead_code)]
pub fn open_table(
    tick_hz: u64,
    pulse_rate_hz: f64,
    eye_safety: Option<EyeSafetyParams>,
    bins: &[(u32, u64, u32)],
) -> FirmwareTable {
    FirmwareTable {
        format: FIRMWARE_FORMAT.to_owned(),
        tick_hz,
        frame_ticks: bins.iter().map(|b| b.1).sum(),
        power_w_per_code: 1e-3,
        power_accounting: PowerAccounting::Time,
        pulse_rate_hz,
        eye_safety,
        limits: IntLimits {
            power_code_min: 0,
            power_code_max: u32::MAX,
            energy_budget: u64::MAX,
            window_bins: 1,
            window_energy_max: u64::MAX,
        },
        bins: bins
            .iter()
            .map(|&(width_mdeg, dwell_ticks, power_code)| FwBin {
                start_deg: 0.0,
                width_mdeg,
                dwell_ticks,
                power_code,
                dwell_ticks_min: 0,
                dwell_ticks_max: u64::MAX,
                power_code_cap: u32::MAX,
            })
            .collect(),
    }
}

/// Bins from `(share of the turn, power W, spin rad/s, accelerate into the
/// next bin's spin)`: the random profiles of the cut tests.
#[allow(dead_code)]
pub fn profile(bins: &[(f64, f64, f64, bool)]) -> Vec<gaze_lidar_core::eye_safety::bound::Seg> {
    let total: f64 = bins.iter().map(|b| b.0).sum();
    let n = bins.len();
    let mut start = 0.0;
    (0..n)
        .map(|i| {
            let (w, p, w0, accel) = bins[i];
            let width = 360.0 * w / total;
            let w1 = if accel { bins[(i + 1) % n].2 } else { w0 };
            let s = gaze_lidar_core::eye_safety::bound::Seg {
                start_deg: start,
                width_deg: width,
                power_w: p,
                spin_start_rad_s: w0,
                spin_end_rad_s: w1,
            };
            start += width;
            s
        })
        .collect()
}

/// Eye-safety parameters of one 5 ns beam at `lambda_nm`, `beam_mm` wide (no head).
#[allow(dead_code)]
pub fn params_at(lambda_nm: f64, beam_mm: f64) -> EyeSafetyParams {
    EyeSafetyParams {
        wavelength_nm: lambda_nm,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: beam_mm,
        head: None,
    }
}

/// The fixtures' usual beam: 905 nm, 5 ns pulses, 8 mm.
#[allow(dead_code)]
pub fn params() -> EyeSafetyParams {
    params_at(905.0, 8.0)
}
