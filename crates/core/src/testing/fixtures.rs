//! Fixtures: the values the tests build their cases from. Each is plain
//! data with its numbers stated in its doc; a test that needs another value
//! overrides a field (`Limits { eye_safety: None, ..limits(..) }`).

use crate::eye_safety::bound::Seg;
use crate::eye_safety::EyeSafetyParams;
use crate::firmware::{FirmwareTable, FwBin, IntLimits, FIRMWARE_FORMAT};
use crate::model::lidar::{Limits, PowerAccounting};
use crate::profile::{Bin, Profile, PROFILE_FORMAT};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

/// Eye-safety parameters of one 5 ns beam at `wavelength_nm`,
/// `beam_mm` wide at the aperture, no multi-beam head.
pub fn params_at(wavelength_nm: f64, beam_mm: f64) -> EyeSafetyParams {
    EyeSafetyParams {
        wavelength_nm,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: beam_mm,
        head: None,
    }
}

/// The fixtures' usual beam: 905 nm, 5 ns pulses, 8 mm.
pub fn params() -> EyeSafetyParams {
    params_at(905.0, 8.0)
}

/// Limits with power in `power_w` = `(min, max)` W and spin in
/// `spin_rad_s` = `(min, max)` rad/s, no acceleration or slew limit, and
/// the eye safety of [`params`].
pub fn limits(power_w: (f64, f64), spin_rad_s: (f64, f64)) -> Limits {
    Limits {
        power_w_min: power_w.0,
        power_w_max: power_w.1,
        spin_rad_s_min: spin_rad_s.0,
        spin_rad_s_max: spin_rad_s.1,
        spin_accel_rad_s2_max: None,
        power_slew_w_per_deg_max: None,
        eye_safety: Some(params()),
    }
}

/// A profile of bins of `widths_deg` (summing to 360, the first starting at
/// 0°), each at `power_w` and the constant spin `2π·frame_rate_hz` (one turn
/// per frame); 20 kHz pulses, average power `power_w`, no regions, no
/// dwell, no summary.
pub fn profile_of_widths(
    widths_deg: &[f64],
    frame_rate_hz: f64,
    power_w: f64,
    accounting: PowerAccounting,
    limits: Limits,
) -> Profile {
    let spin_rad_s = TAU * frame_rate_hz;
    let mut start_deg = 0.0;
    let bins = widths_deg
        .iter()
        .map(|&width_deg| {
            let b = Bin {
                start_deg,
                width_deg,
                power_w,
                spin_start_rad_s: spin_rad_s,
                spin_end_rad_s: spin_rad_s,
                region: None,
                dwell_s: None,
            };
            start_deg += width_deg;
            b
        })
        .collect();
    Profile {
        format: PROFILE_FORMAT.to_owned(),
        frame_rate_hz,
        pulse_rate_hz: 20_000.0,
        average_power_w: power_w,
        power_accounting: accounting,
        gaze_deg: None,
        limits,
        bins,
        mode: None,
        summary: None,
        optimality: None,
    }
}

/// [`profile_of_widths`] with `bins` bins of `360/bins` degrees each.
pub fn uniform(
    bins: usize,
    frame_rate_hz: f64,
    power_w: f64,
    accounting: PowerAccounting,
    limits: Limits,
) -> Profile {
    let widths_deg = vec![360.0 / bins as f64; bins];
    profile_of_widths(&widths_deg, frame_rate_hz, power_w, accounting, limits)
}

/// A time-accounted table of `(width_mdeg, dwell_ticks, code)` bins at
/// 1 mW per code, with open limits and unconstrained bins; frame = Σ dwell.
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

/// Segments from `(share of the turn, power W, spin rad/s, accelerate into
/// the next bin's spin)`: the random profiles of the cut tests. Shares are
/// scaled to 360° in total; the first segment starts at 0°.
pub fn segments(bins: &[(f64, f64, f64, bool)]) -> Vec<Seg> {
    let total: f64 = bins.iter().map(|b| b.0).sum();
    let n = bins.len();
    let mut start_deg = 0.0;
    (0..n)
        .map(|i| {
            let (share, power_w, w0, accel) = bins[i];
            let width_deg = 360.0 * share / total;
            let w1 = if accel { bins[(i + 1) % n].2 } else { w0 };
            let s = Seg {
                start_deg,
                width_deg,
                power_w,
                spin_start_rad_s: w0,
                spin_end_rad_s: w1,
            };
            start_deg += width_deg;
            s
        })
        .collect()
}

/// The workspace's committed test data, `tests/data/` at the repository
/// root (the same directory from either crate's tests).
pub fn data_dir() -> PathBuf {
    let core = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = core
        .ancestors()
        .nth(2)
        .expect("the core lives at crates/core");
    root.join("tests/data")
}

/// The file or directory `rel` below [`data_dir`].
pub fn data_path(rel: &str) -> PathBuf {
    data_dir().join(rel)
}

/// Head figures of `count_vertical` channels of weight 1 each meeting one
/// height, of `slots_vertical` distinct slots, on the cylinder: no two at
/// once, no group, one channel stalled on any one point, 5 mm beams, a 6°
/// pass, one pass's arc; a test that needs another figure overrides a
/// field.
pub fn head_figures(
    count_vertical: u32,
    slots_vertical: u32,
) -> crate::eye_safety::head::HeadFigures {
    crate::eye_safety::head::HeadFigures {
        surface: crate::eye_safety::head::geometry::Surface::Cylinder,
        aperture_distance_mm: 100.0,
        channels: count_vertical,
        channels_at_worst: count_vertical,
        worst_height_mm: 0.0,
        worst_azimuth_deg: 0.0,
        group_height_mm: 0.0,
        weight_vertical: f64::from(count_vertical),
        count_vertical,
        slots_vertical,
        union_passes: 1,
        weight_simultaneous: 1.0,
        count_simultaneous: 1,
        weight_group: 1.0,
        count_group: 1,
        group_spans_time: false,
        group_window_s: 5e-6,
        weight_instant: 1.0,
        weight_stalled: 1.0,
        count_stalled: 1,
        weight_stalled_group: 1.0,
        weight_stalled_simultaneous: 1.0,
        count_stalled_simultaneous: 1,
        stalled_group_spans_time: false,
        footprint_max_mm: 5.0,
        pass_angle_deg: 6.0,
        power_scale_max: 1.0,
        separations: Vec::new(),
        slot_windows: Vec::new(),
    }
}
