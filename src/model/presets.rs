//! Named presets: a LiDAR, a driver focus model and the adaptive levels of the
//! paper's closed-form controllers.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use thiserror::Error;

use super::acuity::FocusModel;
use super::lidar::{LidarSpec, Limits, PowerAccounting};
use crate::eye_safety::head::{Channel, Head};
use crate::eye_safety::EyeSafetyParams;

/// The levels of the paper's two-level controllers (section III).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveLevels {
    /// Range control: `P_low = rof_power_fraction · P̄` inside the RoF; `P_high`
    /// follows from the budget (eq. 4). The paper's code uses 0.5.
    pub rof_power_fraction: f64,
    /// Resolution control: `ω_high / ω_low`, i.e. how many times fewer points
    /// per degree inside the RoF; `ω_low` follows from eq. 6. Paper code: 5.4.
    pub spin_ratio: f64,
}

impl AdaptiveLevels {
    /// The paper code's levels (github fscari/ARGUS): 0.5 and 5.4.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            rof_power_fraction: 0.5,
            spin_ratio: 5.4,
        }
    }
}

/// A LiDAR, the driver's focus model and the adaptive levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    /// The sensor.
    pub lidar: LidarSpec,
    /// RoF model (acuity function and threshold).
    pub focus: FocusModel,
    /// Levels of the closed-form controllers.
    pub levels: AdaptiveLevels,
}

/// Unknown preset name.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
#[error("unknown preset '{0}' (known: {known})", known = PRESET_NAMES.join(", "))]
pub struct UnknownPreset(pub String);

/// Names accepted by [`preset`].
pub const PRESET_NAMES: &[&str] = &["paper", "vls128", "vlp16", "os1-128"];

/// Looks a preset up by name.
pub fn preset(name: &str) -> Result<Preset, UnknownPreset> {
    match name {
        "paper" => Ok(paper()),
        "vls128" => Ok(vls128()),
        "vlp16" => Ok(vlp16()),
        "os1-128" => Ok(os1_128()),
        other => Err(UnknownPreset(other.to_owned())),
    }
}

/// The paper's CARLA baseline, one channel of it for the 2D model.
///
/// - 64 channels, 20 Hz, ≈ 500,000 points/s (CARLA LiDAR as in the paper,
///   section III-C), hence 7,812.5 pulses/s per channel, 390.6 per turn;
///   100 m range.
/// - RoF: the paper's 60° box (η = 0.5); levels of the paper's code
///   (`P_low = 0.5 P̄`, `ω_high/ω_low = 5.4`); eq. 4 as printed (`angle`).
/// - Laser (not given by the paper; chosen so the baseline is Class 1):
///   905 nm, 5 ns pulses, 1.0 mW mean per channel (128 nJ per pulse,
///   25.6 W peak), 8 mm beam at 100 mm.
/// - Limits: no acceleration or slew limit (the paper steps), power up to
///   1.25 P̄, spin 5–100 Hz.
#[must_use]
pub fn paper() -> Preset {
    let average_power_w = 1.0e-3;
    Preset {
        lidar: LidarSpec {
            name: "paper: CARLA 64-channel, 20 Hz, 500k points/s, 100 m (one channel)".into(),
            frame_rate_hz: 20.0,
            pulse_rate_hz: 500_000.0 / 64.0,
            channels: 64,
            average_power_w,
            rated_range_m: 100.0,
            reference_reflectivity: 0.1,
            power_accounting: PowerAccounting::Angle,
            limits: Limits {
                power_w_min: 0.0,
                power_w_max: 1.25 * average_power_w,
                spin_rad_s_min: TAU * 5.0,
                spin_rad_s_max: TAU * 100.0,
                spin_accel_rad_s2_max: None,
                power_slew_w_per_deg_max: None,
                eye_safety: Some(EyeSafetyParams {
                    wavelength_nm: 905.0,
                    pulse_duration_s: 5e-9,
                    beam_diameter_mm: 8.0,
                    head: None,
                }),
            },
        },
        focus: FocusModel::paper(),
        levels: AdaptiveLevels::paper(),
    }
}

/// Builds a head's channels from `(id, elevation_deg, azimuth_offset_deg,
/// slot_s)`, every channel at the profile's bin power (`power_scale` 1:
/// no public source gives per-channel pulse energies, so every channel is
/// assumed to carry the same power).
fn channels(table: impl Iterator<Item = (u32, f64, f64, f64)>) -> Vec<Channel> {
    table
        .map(|(id, elevation_deg, azimuth_offset_deg, slot_s)| Channel {
            id,
            elevation_deg,
            azimuth_offset_deg,
            slot_s,
            power_scale: 1.0,
        })
        .collect()
}

/// A head whose beams leave `origin_radius_mm` from the axis at the
/// reference height, as 10 mm exit beams (the OS1 datasheet's figure; the
/// assumption for the Velodyne heads), seen through the aperture at 100 mm
/// (Condition 3).
fn head(cycle_s: f64, origin_radius_mm: f64, divergence_mrad: f64, channels: Vec<Channel>) -> Head {
    Head {
        cycle_s,
        origin_radius_mm,
        origin_height_mm: 0.0,
        exit_diameter_mm: 10.0,
        divergence_mrad,
        aperture_distance_mm: 100.0,
        channels,
    }
}

/// What a 10 Hz sensor with its real head is beyond its laser: one channel
/// per head channel firing once per head cycle, 10 % reference
/// reflectivity, power by time (the physical energy budget), power within
/// 0.2–1.3 × the mean, spin 5–20 Hz with a 100 rad/s² motor (≈ 1e-3 kg·m²
/// inertia, 0.1 N·m spare torque: no step inside a turn), no slew limit;
/// the Levi E2 acuity model at a 60° RoF and the paper's levels.
struct HeadSensor {
    name: &'static str,
    average_power_w: f64,
    rated_range_m: f64,
    wavelength_nm: f64,
    pulse_duration_s: f64,
    beam_diameter_mm: f64,
    head: Head,
}

impl HeadSensor {
    fn preset(self) -> Preset {
        let average_power_w = self.average_power_w;
        Preset {
            lidar: LidarSpec {
                name: self.name.into(),
                frame_rate_hz: 10.0,
                pulse_rate_hz: 1.0 / self.head.cycle_s,
                channels: u32::try_from(self.head.channels.len()).unwrap_or(u32::MAX),
                average_power_w,
                rated_range_m: self.rated_range_m,
                reference_reflectivity: 0.1,
                power_accounting: PowerAccounting::Time,
                limits: Limits {
                    power_w_min: 0.2 * average_power_w,
                    power_w_max: 1.3 * average_power_w,
                    spin_rad_s_min: TAU * 5.0,
                    spin_rad_s_max: TAU * 20.0,
                    spin_accel_rad_s2_max: Some(100.0),
                    power_slew_w_per_deg_max: None,
                    eye_safety: Some(EyeSafetyParams {
                        wavelength_nm: self.wavelength_nm,
                        pulse_duration_s: self.pulse_duration_s,
                        beam_diameter_mm: self.beam_diameter_mm,
                        head: Some(self.head),
                    }),
                },
            },
            focus: FocusModel::levi_e2_with_width(60.0),
            levels: AdaptiveLevels::paper(),
        }
    }
}

/// VLS-128 / Alpha Prime laser elevations by laser id, deg: ros-drivers/velodyne
/// `velodyne_pointcloud/params/VLS128.yaml` (`vert_correction`, in rad
/// there; same in valgur/velodyne_decoder `src/calib_db.cpp`, "AlphaPrime",
/// and tier4/nebula `calibration/VLS128.yaml`), as tabulated in docs/heads.md
/// Appendix A.
// Laser 26's −6.280° is a calibration value that happens to read like −τ.
#[allow(clippy::approx_constant)]
const VLS128_ELEVATION_DEG: [f64; 128] = [
    -11.742, -1.990, 3.400, -5.290, -0.780, 4.610, -4.080, 1.310, //
    -6.500, -1.110, 4.280, -4.410, 0.100, 6.480, -3.200, 2.190, //
    -3.860, 1.530, -9.244, -1.770, 2.740, -5.950, -0.560, 4.830, //
    -2.980, 2.410, -6.280, -0.890, 3.620, -5.070, 0.320, 7.580, //
    -0.340, 5.180, -3.640, 1.750, -25.000, -2.430, 2.960, -5.730, //
    0.540, 9.700, -2.760, 2.630, -7.650, -1.550, 3.840, -4.850, //
    3.180, -5.510, -0.120, 5.730, -4.300, 1.090, -16.042, -2.210, //
    4.060, -4.630, 0.760, 15.000, -3.420, 1.970, -6.850, -1.330, //
    -5.620, -0.230, 5.430, -3.530, 0.980, -19.582, -2.320, 3.070, //
    -4.740, 0.650, 11.750, -2.650, 1.860, -7.150, -1.440, 3.950, //
    -2.100, 3.290, -5.400, -0.010, 4.500, -4.190, 1.200, -13.565, //
    -1.220, 4.170, -4.520, 0.870, 6.080, -3.310, 2.080, -6.650, //
    1.420, -10.346, -1.880, 3.510, -6.060, -0.670, 4.720, -3.970, //
    2.300, -6.390, -1.000, 4.390, -5.180, 0.210, 6.980, -3.090, //
    4.980, -3.750, 1.640, -8.352, -2.540, 2.850, -5.840, -0.450, //
    8.430, -2.870, 2.520, -6.170, -1.660, 3.730, -4.960, 0.430, //
];

/// VLS-128 azimuth offset of laser `id`, by `id mod 8`, deg
/// (`rot_correction` of `VLS128.yaml`, docs/heads.md §1): eight columns, one
/// laser of each firing group in each.
const VLS128_AZIMUTH_DEG: [f64; 8] = [-6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354];

/// One VLS-128 firing group, s (VLS-128 user manual p.49; ros-drivers
/// `rawdata.h`).
const VLS128_GROUP_S: f64 = 2.665e-6;
/// The VLS-128 firing cycle, s: 16 groups, a 2.665 µs maintenance period
/// after the 8th group and a 7.995 µs one after the 16th
/// (16·2.665 + 2.665 + 7.995 = 53.3 µs; manual p.49).
const VLS128_CYCLE_S: f64 = 53.3e-6;

/// A sensor resembling the Velodyne VLS-128 run at 10 Hz, with its real
/// 128-channel head.
///
/// - 903 nm, 128 lasers each firing once per 53.3 µs cycle (18,761 Hz per
///   channel, 2.4 M points/s in all), 5–20 Hz in 60 RPM steps (datasheet),
///   10 Hz here.
/// - Head (public): elevations per laser id and the eight azimuth columns
///   (`id mod 8`) from `VLS128.yaml` (docs/heads.md Appendix A); groups of eight
///   (`id / 8`) fire together, group `g` at `2.665·g` µs for `g < 8` and
///   `2.665·(g + 1)` µs after the first maintenance period (manual p.49);
///   the beams cross 58.63 mm from the axis (valgur `calib_db.cpp`);
///   divergence 3.0 mrad, the larger (horizontal) axis (manual p.115).
/// - Not public, assumed: the exit beam diameter, 10 mm (the only stated
///   exit diameter of a comparable head, Ouster OS1's; the upper end of
///   the 5–10 mm bracket of docs/heads.md §6, which counts more beams as
///   meeting the aperture); the crossing point at the reference height
///   (the aperture height is searched anyway); 3 ns pulses; every channel
///   at the same power.
/// - Laser power (assumed, per channel): 18 µW mean (0.96 nJ per pulse).
///   **Rescaled for the head**: this preset carried 1.5 mW per channel
///   (80 nJ) when it was certified as one channel; as a head, a uniform
///   profile at `power_w_max` (1.3 × the mean, the hottest profile of the
///   preset's limits at the mean spin) reaches 74.2 × the Class 1 limit at
///   1.5 mW (123 beams can cross one aperture height over a sweep, 8 of
///   one firing group at once), so every power is scaled by 0.012 (÷ 83):
///   that uniform profile was at 0.89 of the limit (10 % head-room for the
///   bound's rounding and later tightening); the head bound's short windows
///   (by firing slots) put it at 0.38, the power kept. The rated range stays the
///   vendor's (it is the range at the preset's mean power, whatever that
///   unpublished power is).
/// - `beam_diameter_mm` (the one-channel figure) is the exit beam grown by
///   the divergence over the 41.37 mm to the aperture, rounded up.
///   Rated range 245 m at 10 % reflectivity (vendor figure for the VLS-128
///   class).
/// - Motor: a real spinning head cannot step its speed inside a turn; the
///   limit here is 100 rad/s² (≈ 1e-3 kg·m² inertia, 0.1 N·m spare torque),
///   so closed-form resolution control (a step) is rejected and spin
///   modulation needs the optimizer's smooth ramps.
/// - Power accounting by time (the physical energy budget); the levels of
///   the paper's controllers and the Levi E2 acuity model at a 60° RoF.
#[must_use]
pub fn vls128() -> Preset {
    let channels = channels((0..128u32).map(|id| {
        let group = id / 8;
        let slots = if group < 8 { group } else { group + 1 };
        (
            id,
            VLS128_ELEVATION_DEG[id as usize],
            VLS128_AZIMUTH_DEG[(id % 8) as usize],
            VLS128_GROUP_S * f64::from(slots),
        )
    }));
    HeadSensor {
        name: "vls128: VLS-128-like, 903 nm, 10 Hz, 128 channels",
        average_power_w: 18e-6,
        rated_range_m: 245.0,
        wavelength_nm: 903.0,
        pulse_duration_s: 3e-9,
        beam_diameter_mm: 10.2,
        head: head(VLS128_CYCLE_S, 58.63, 3.0, channels),
    }
    .preset()
}

/// VLP-16 laser elevations by laser id, deg (ros-drivers/velodyne
/// `velodyne_pointcloud/params/VLP16db.yaml`; valgur `calib_db.cpp`;
/// docs/heads.md Appendix A): −15, 1, −13, 3, …, −1, 15 (interleaved).
const VLP16_ELEVATION_DEG: [f64; 16] = [
    -15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0,
];
/// VLP-16 firing: laser `k` at `2.304·k` µs, one at a time, in a 55.296 µs
/// cycle (16 firings and an 18.43 µs recharge): VLP-16 user manual 63-9243
/// Rev D p.62; ros-drivers `rawdata.h` (`VLP16_DSR_TOFFSET`,
/// `VLP16_FIRING_TOFFSET`).
const VLP16_FIRING_S: f64 = 2.304e-6;
const VLP16_CYCLE_S: f64 = 55.296e-6;

/// A sensor resembling the Velodyne VLP-16 run at 10 Hz, with its real
/// 16-channel head.
///
/// - 903 nm (VLP-16 manual's channel definition, docs/heads.md §4), 16 lasers
///   each firing once per 55.296 µs cycle (18,084 Hz per channel), 10 Hz
///   (5–20 Hz, 300–1200 RPM, datasheet).
/// - Head (public): the elevations of `VLP16db.yaml`, no azimuth offsets;
///   sequential firing 2.304 µs apart; the beams cross 41.91 mm from the
///   axis ("distance from the sensor center to the focal point where all
///   laser beams intersect", valgur `calib_db.cpp`).
/// - Not public, assumed: the exit beam diameter, 10 mm (as for `vls128`);
///   the divergence, 3.0 mrad (the VLS-128's stated horizontal figure; the
///   OpenPLX model's 2.25 mrad is lower authority and smaller, so less
///   safe); 4 ns pulses (HELIOS++ model, and "typically 4 nanoseconds" in
///   Velodyne's HDL-64E material); every channel at the same power;
///   100 m range at 10 % reflectivity (datasheet "up to 100 m"; the
///   reflectivity is not stated there).
/// - Laser power (assumed, per channel): 240 µW mean (13 nJ per pulse).
///   Scaled for the head from 1.5 mW by 0.16 (÷ 6.25): at 1.5 mW a uniform
///   profile at `power_w_max` (1.3 × the mean) reaches 5.61 × the Class 1
///   limit as a head (9 beams can cross one aperture height over a sweep,
///   3 within one `T_i`); at 240 µW it was at 0.90, 0.69 with the head
///   bound's short windows (by firing slots), the power kept.
/// - Motor, accounting, focus and levels as `vls128`.
#[must_use]
pub fn vlp16() -> Preset {
    let channels = channels((0..16u32).map(|id| {
        (
            id,
            VLP16_ELEVATION_DEG[id as usize],
            0.0,
            VLP16_FIRING_S * f64::from(id),
        )
    }));
    HeadSensor {
        name: "vlp16: VLP-16-like, 903 nm, 10 Hz, 16 channels",
        average_power_w: 240e-6,
        rated_range_m: 100.0,
        wavelength_nm: 903.0,
        pulse_duration_s: 4e-9,
        beam_diameter_mm: 10.2,
        head: head(VLP16_CYCLE_S, 41.91, 3.0, channels),
    }
    .preset()
}

/// Ouster OS1-128 beam elevations by row, deg: ouster-sdk
/// `tests/pcaps/OS-1-128_v2.3.0_1024x10.json` (`beam_altitude_angles`,
/// one unit, firmware 2.3.0; read at commit bdcfa68c).
const OS1_128_ELEVATION_DEG: [f64; 128] = [
    20.95, 20.67, 20.36, 20.03, 19.73, 19.41, 19.11, 18.76, 18.47, 18.14, 17.82, 17.5, 17.19,
    16.86, 16.53, 16.2, 15.89, 15.56, 15.23, 14.9, 14.57, 14.23, 13.9, 13.57, 13.25, 12.91, 12.57,
    12.22, 11.9, 11.55, 11.2, 10.87, 10.54, 10.18, 9.84, 9.51, 9.15, 8.81, 8.47, 8.11, 7.78, 7.43,
    7.08, 6.74, 6.39, 6.04, 5.7, 5.34, 4.98, 4.64, 4.29, 3.93, 3.58, 3.24, 2.88, 2.53, 2.17, 1.82,
    1.47, 1.12, 0.78, 0.41, 0.07, -0.28, -0.64, -0.99, -1.35, -1.7, -2.07, -2.4, -2.75, -3.11,
    -3.46, -3.81, -4.15, -4.5, -4.86, -5.22, -5.57, -5.9, -6.27, -6.61, -6.97, -7.3, -7.67, -8.01,
    -8.35, -8.69, -9.05, -9.38, -9.71, -10.07, -10.42, -10.76, -11.09, -11.43, -11.78, -12.12,
    -12.46, -12.78, -13.15, -13.46, -13.8, -14.12, -14.48, -14.79, -15.11, -15.46, -15.79, -16.12,
    -16.45, -16.76, -17.11, -17.44, -17.74, -18.06, -18.39, -18.72, -19.02, -19.32, -19.67, -19.99,
    -20.27, -20.57, -20.92, -21.22, -21.54, -21.82,
];
/// Ouster OS1-128 beam azimuth offsets by row, deg (`beam_azimuth_angles`
/// of the same file): four columns by `row mod 4`, ≈ +4.21, +1.41, −1.40,
/// −4.21. Taken with the file's sign; a mirrored head has the same exposure.
const OS1_128_AZIMUTH_DEG: [f64; 128] = [
    4.21, 1.41, -1.4, -4.22, 4.22, 1.41, -1.4, -4.23, 4.21, 1.4, -1.42, -4.2, 4.22, 1.41, -1.4,
    -4.23, 4.21, 1.41, -1.41, -4.21, 4.22, 1.4, -1.41, -4.2, 4.22, 1.42, -1.4, -4.2, 4.22, 1.41,
    -1.42, -4.21, 4.22, 1.41, -1.4, -4.21, 4.2, 1.4, -1.4, -4.22, 4.21, 1.41, -1.41, -4.21, 4.22,
    1.41, -1.4, -4.21, 4.21, 1.41, -1.4, -4.21, 4.2, 1.41, -1.4, -4.21, 4.2, 1.4, -1.41, -4.21,
    4.22, 1.4, -1.4, -4.21, 4.22, 1.42, -1.4, -4.2, 4.2, 1.42, -1.4, -4.22, 4.22, 1.41, -1.4, -4.2,
    4.23, 1.41, -1.4, -4.2, 4.21, 1.41, -1.4, -4.21, 4.21, 1.41, -1.4, -4.21, 4.22, 1.41, -1.39,
    -4.21, 4.23, 1.41, -1.39, -4.22, 4.23, 1.4, -1.4, -4.2, 4.21, 1.41, -1.41, -4.2, 4.22, 1.42,
    -1.39, -4.22, 4.24, 1.41, -1.41, -4.22, 4.23, 1.41, -1.39, -4.21, 4.23, 1.41, -1.39, -4.2,
    4.23, 1.4, -1.39, -4.2, 4.22, 1.42, -1.39, -4.2,
];
/// One OS1 column period in 1024×10 mode, s: 1/(1024 columns · 10 Hz)
/// (ouster-sdk `using-the-api.rst`, "each column contains measurements
/// taken at a single timestamp"; docs/heads.md §2).
const OS1_128_CYCLE_S: f64 = 1.0 / 10_240.0;

/// A sensor resembling the Ouster OS1-128 (Rev 6/7) in 1024×10 mode, with
/// its real 128-channel head.
///
/// - 865 nm ("operate in the 865nm band", OS0/OS1 manual; docs/heads.md §4);
///   all 128 beams of a column flash at one timestamp, once per 97.656 µs
///   column period (10,240 Hz per channel, 1.3 M points/s in all).
/// - Head (public): elevations and the four azimuth columns of ouster-sdk
///   `OS-1-128_v2.3.0_1024x10.json`; every beam leaves from one beam
///   origin `lidar_origin_to_beam_origin_mm` = 15.806 mm from the axis
///   (same file); 10 mm exit beam ("Beam Diameter Exiting Sensor 10 mm")
///   and 0.18° divergence (128-channel, FWHM) from the OS1 datasheet
///   (docs/heads.md §3). The head takes 1/e² sizes: the FWHM angle is widened
///   by `1/√(ln 2 / 2)` ≈ 1.699 (a Gaussian beam's 1/e² to FWHM ratio) to
///   5.34 mrad; the 10 mm exit diameter is taken as 1/e² (not stated).
/// - Assumed: the head fires on the encoder (1024 columns a turn); the
///   model's head is time-triggered, so the 10 Hz column period is kept at
///   every spin; 5 ns pulses; every channel at the same power; 45 m range
///   at 10 % reflectivity; spin 5–20 Hz for the 2D model (the product runs
///   at 10 or 20 Hz).
/// - Laser power (assumed, per channel): 13 µW mean (1.3 nJ per pulse).
///   Scaled for the head from 1.5 mW by 0.0087 (÷ 115): at 1.5 mW a uniform
///   profile at `power_w_max` (1.3 × the mean) reaches 108 × the Class 1
///   limit as a head (36 beams of one column, fired at once, share one
///   aperture position; one channel alone would already be at 1.70); at
///   13 µW it is at 0.94.
/// - Motor, accounting, focus and levels as `vls128`.
#[must_use]
pub fn os1_128() -> Preset {
    let channels = channels((0..128u32).map(|id| {
        (
            id,
            OS1_128_ELEVATION_DEG[id as usize],
            OS1_128_AZIMUTH_DEG[id as usize],
            0.0,
        )
    }));
    // The FWHM divergence widened to 1/e².
    let divergence_mrad = 0.18_f64.to_radians() * 1000.0 / (core::f64::consts::LN_2 / 2.0).sqrt();
    HeadSensor {
        name: "os1-128: OS1-128-like, 865 nm, 1024x10, 128 channels",
        average_power_w: 13e-6,
        rated_range_m: 45.0,
        wavelength_nm: 865.0,
        pulse_duration_s: 5e-9,
        beam_diameter_mm: 10.3,
        head: head(OS1_128_CYCLE_S, 15.806, divergence_mrad, channels),
    }
    .preset()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_resolve_and_validate() {
        for name in PRESET_NAMES {
            let p = preset(name).unwrap();
            p.focus.validate().unwrap();
            p.lidar.validate().unwrap();
            assert!(p.lidar.limits.power_w_max >= p.lidar.average_power_w);
        }
        let e = preset("nope").unwrap_err().to_string();
        assert!(e.contains("vlp16") && e.contains("os1-128"), "{e}");
        assert!(e.contains("paper") && e.contains("nope"));
    }

    /// The heads carry the public tables: channel counts, firing groups,
    /// cycles, crossing points (docs/heads.md §1–3), and `paper` stays one channel.
    #[test]
    fn heads_carry_the_public_tables() {
        let head = |name: &str| preset(name).unwrap().lidar.limits.eye_safety.unwrap().head;
        assert!(head("paper").is_none());
        // VLS-128: 16 groups of 8, one laser per azimuth column, the last
        // group at 16·2.665 µs, then the 7.995 µs maintenance period.
        let h = head("vls128").unwrap();
        assert_eq!(h.channels.len(), 128);
        assert_eq!(h.origin_radius_mm, 58.63);
        let mut slots: Vec<f64> = h.channels.iter().map(|c| c.slot_s).collect();
        slots.dedup();
        assert_eq!(slots.len(), 16);
        for g in h.channels.chunks(8) {
            assert!(g.iter().all(|c| c.slot_s == g[0].slot_s));
            let mut az: Vec<i64> = g
                .iter()
                .map(|c| (c.azimuth_offset_deg * 1000.0).round() as i64)
                .collect();
            az.dedup();
            assert_eq!(az.len(), 8, "one laser per column");
        }
        assert!((slots[8] - slots[7] - 2.0 * 2.665e-6).abs() < 1e-15);
        assert!((h.cycle_s - slots[15] - 2.665e-6 - 7.995e-6).abs() < 1e-15);
        assert_eq!(h.channels[36].elevation_deg, -25.0);
        assert_eq!(h.channels[59].elevation_deg, 15.0);
        // VLP-16: sequential, 2.304 µs apart, no azimuth offsets.
        let h = head("vlp16").unwrap();
        assert_eq!(h.channels.len(), 16);
        assert_eq!(h.origin_radius_mm, 41.91);
        for (k, c) in h.channels.iter().enumerate() {
            assert!((c.slot_s - 2.304e-6 * k as f64).abs() < 1e-18);
            assert_eq!(c.azimuth_offset_deg, 0.0);
        }
        let el: f64 = h.channels.iter().map(|c| c.elevation_deg).sum();
        assert_eq!(el, 0.0, "±1 … ±15");
        // OS1-128: one timestamp per column, rows from +20.95 to −21.82°,
        // four azimuth columns by row mod 4.
        let h = head("os1-128").unwrap();
        assert_eq!(h.channels.len(), 128);
        assert!(h.channels.iter().all(|c| c.slot_s == 0.0));
        assert_eq!(h.channels[0].elevation_deg, 20.95);
        assert_eq!(h.channels[127].elevation_deg, -21.82);
        assert!(h
            .channels
            .windows(2)
            .all(|w| w[1].elevation_deg < w[0].elevation_deg));
        for c in &h.channels {
            let column = [4.21, 1.41, -1.40, -4.21][(c.id % 4) as usize];
            assert!((c.azimuth_offset_deg - column).abs() <= 0.031, "{c:?}");
        }
        assert!((h.divergence_mrad - 5.336).abs() < 1e-3);
    }

    /// With a head, the sensor's per-channel pulse rate is the head's
    /// `1/cycle_s` and its channel count the head's: anything else is
    /// refused by name.
    #[test]
    fn a_head_fixes_the_pulse_rate_and_channel_count() {
        for name in ["vls128", "vlp16", "os1-128"] {
            let mut spec = preset(name).unwrap().lidar;
            spec.pulse_rate_hz *= 1.0 + 1e-8;
            let e = spec.validate().unwrap_err();
            assert_eq!(e.field, "pulse_rate_hz", "{name}");
            assert!(e.reason.contains("1/limits.eye_safety.head.cycle_s"), "{e}");
            let mut spec = preset(name).unwrap().lidar;
            spec.channels += 1;
            assert_eq!(spec.validate().unwrap_err().field, "channels", "{name}");
        }
        // Without a head, any rate of physical size.
        let mut spec = preset("paper").unwrap().lidar;
        spec.pulse_rate_hz *= 1.5;
        spec.validate().unwrap();
    }
}
