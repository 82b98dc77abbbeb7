//! Firmware tables (`gaze-lidar/firmware@1`): a certified profile quantized
//! to integer timer ticks and DAC power codes, with integer limits that the
//! [`check`] module re-verifies exactly.
//!
//! Quantization is exact and conservative:
//! - `frame_ticks = round(tick_hz / frame_rate_hz)`; each bin's dwell is its
//!   real dwell rounded up or down (so within one tick of it) and within the
//!   tick bounds implied by the spin limits, and the dwells sum to
//!   `frame_ticks` exactly ([`quantize::apportion`]);
//! - power codes are rounded down: never above the certified power, within
//!   one code of it ([`quantize::floor_code`]);
//! - the integer limits are derived conservatively from the float limits
//!   (codes floored, eye-safety caps at the worst-case C5 and over windows
//!   that cover any aperture pass), and the built table must pass
//!   [`check::check_table`] or no table is returned.
//!
//! Spin acceleration is a property of the float profile (certified there);
//! a table stores dwell per bin and the motor controller ramps between them.

pub mod binary;
pub mod check;
pub mod quantize;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::checker::CertifiedProfile;
use crate::eye_safety::ael::{self, APERTURE_DISTANCE_MM, T2_S, TIME_BASE_S};
use crate::model::lidar::PowerAccounting;

pub use check::{check_table, FwViolation};
pub use quantize::{apportion, floor_code, QuantizeError, TickTarget};

/// The value of the `format` field.
pub const FIRMWARE_FORMAT: &str = "gaze-lidar/firmware@1";
/// A full turn in millidegrees (Ouster's `azimuth_window` unit).
pub const FULL_TURN_MDEG: u32 = 360_000;
/// Most bins a table may have.
pub const MAX_TABLE_BINS: usize = 36_000;

/// Quantization settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FirmwareConfig {
    /// Timer frequency, Hz (e.g. an 80 MHz timer).
    pub tick_hz: u64,
    /// DAC step, W per code; `None`: `power_w_max / 4095` (a 12-bit DAC).
    pub power_w_per_code: Option<f64>,
}

impl Default for FirmwareConfig {
    fn default() -> Self {
        Self {
            tick_hz: 80_000_000,
            power_w_per_code: None,
        }
    }
}

/// Integer limits of a table.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntLimits {
    /// `floor(power_w_min / step)`.
    pub power_code_min: u32,
    /// `floor(power_w_max / step)`.
    pub power_code_max: u32,
    /// Energy budget: `Σ code·ticks` (time accounting) or `Σ code·width_mdeg`
    /// (angle accounting) must not exceed it.
    pub energy_budget: u64,
    /// Consecutive bins that cover any aperture pass (eye safety).
    pub window_bins: u32,
    /// Largest `Σ code·ticks` over any `window_bins` consecutive bins.
    pub window_energy_max: u64,
}

/// One bin of a table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FwBin {
    /// Start azimuth, degrees (informational).
    pub start_deg: f64,
    /// Width in millidegrees (Σ = 360,000).
    pub width_mdeg: u32,
    /// Dwell, timer ticks.
    pub dwell_ticks: u64,
    /// DAC power code.
    pub power_code: u32,
    /// Smallest dwell the spin limit allows, ticks.
    pub dwell_ticks_min: u64,
    /// Largest dwell the spin limit allows, ticks.
    pub dwell_ticks_max: u64,
    /// Largest code the eye-safety single-pulse rule allows in this bin
    /// (C5 at this bin's own pulse count, from the certified evaluation).
    pub power_code_cap: u32,
}

/// A firmware table, `gaze-lidar/firmware@1`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FirmwareTable {
    /// [`FIRMWARE_FORMAT`].
    pub format: String,
    /// Timer frequency, Hz.
    pub tick_hz: u64,
    /// Ticks per revolution.
    pub frame_ticks: u64,
    /// DAC step, W per code.
    pub power_w_per_code: f64,
    /// Accounting of the energy budget.
    pub power_accounting: PowerAccounting,
    /// Integer limits.
    pub limits: IntLimits,
    /// Bins in azimuth order.
    pub bins: Vec<FwBin>,
}

/// Why a table could not be built.
#[derive(Debug, Error)]
pub enum FirmwareError {
    /// A setting is invalid.
    #[error("{field}: {reason}")]
    Config {
        /// Setting.
        field: &'static str,
        /// Why.
        reason: String,
    },
    /// Dwell rounding impossible.
    #[error("dwell quantization: {0}")]
    Quantize(#[from] QuantizeError),
    /// The built table fails its own integer check (never handed out).
    #[error("the quantized table violates its integer limits: {}", crate::checker::summarize_list(.0))]
    Rejected(Vec<FwViolation>),
}

fn u64_of(x: f64, field: &'static str) -> Result<u64, FirmwareError> {
    if (0.0..1.8e19).contains(&x) {
        Ok(x as u64)
    } else {
        Err(FirmwareError::Config {
            field,
            reason: format!("{x} does not fit an unsigned 64-bit tick count"),
        })
    }
}

impl FirmwareTable {
    /// Quantizes a certified profile.
    pub fn from_certified(
        certified: &CertifiedProfile,
        cfg: &FirmwareConfig,
    ) -> Result<Self, FirmwareError> {
        let p = certified.profile();
        let l = &p.limits;
        if cfg.tick_hz == 0 || cfg.tick_hz > 10_000_000_000 {
            return Err(FirmwareError::Config {
                field: "tick_hz",
                reason: format!("{} must lie in 1..=1e10", cfg.tick_hz),
            });
        }
        let f = cfg.tick_hz as f64;
        let step = cfg.power_w_per_code.unwrap_or(l.power_w_max / 4095.0);
        if !(step.is_finite() && step > 0.0) {
            return Err(FirmwareError::Config {
                field: "power_w_per_code",
                reason: format!(
                    "{step} must be finite and > 0 (power_w_max must be > 0 for the default)"
                ),
            });
        }
        let frame_ticks = u64_of((f / p.frame_rate_hz).round(), "frame_ticks")?;
        if p.bins.len() > MAX_TABLE_BINS {
            return Err(FirmwareError::Config {
                field: "bins",
                reason: format!(
                    "{} bins; a table holds at most {MAX_TABLE_BINS}",
                    p.bins.len()
                ),
            });
        }
        // Widths in millidegrees from rounded starts: they sum to 360,000 exactly.
        let starts: Vec<u32> = p
            .bins
            .iter()
            .map(|b| (b.start_deg * 1000.0).round() as u32)
            .collect();
        let mut targets = Vec::with_capacity(p.bins.len());
        let mut bounds = Vec::with_capacity(p.bins.len());
        for b in &p.bins {
            let ideal = b.dwell_time_s() * f;
            let floor = ideal.floor();
            let frac = ((ideal - floor) * 4_294_967_296.0)
                .floor()
                .min(4_294_967_295.0) as u32;
            let theta = b.width_deg.to_radians();
            // Certified spins meet their limits within the checker's REL_TOL.
            let tol = 1.0 + crate::checker::REL_TOL;
            let min = u64_of(
                (theta * f / (l.spin_rad_s_max * tol)).ceil(),
                "dwell_ticks_min",
            )?;
            let max = if l.spin_rad_s_min > 0.0 {
                u64_of(
                    (theta * f * tol / l.spin_rad_s_min).floor(),
                    "dwell_ticks_max",
                )?
            } else {
                u64::MAX
            };
            targets.push(TickTarget {
                floor: u64_of(floor, "dwell_ticks")?,
                frac,
                min,
                max,
            });
            bounds.push((min, max));
        }
        let ticks = apportion(&targets, frame_ticks)?;
        let codes: Vec<u32> = p
            .bins
            .iter()
            .map(|b| {
                floor_code(b.power_w, step).ok_or_else(|| FirmwareError::Config {
                    field: "power_w_per_code",
                    reason: format!(
                        "power {} W / step {step} W does not fit a u32 code",
                        b.power_w
                    ),
                })
            })
            .collect::<Result<_, _>>()?;
        let (window_bins, window_energy_max) = eye_safety_limits(certified, step, f)?;
        let caps = pulse_code_caps(certified, step)?;
        let max_code = floor_code(l.power_w_max, step).unwrap_or(u32::MAX);
        // Budget in code units per tick (time) or per millidegree (angle):
        // floor(P̄/step) exactly (as the codes are rounded), plus the
        // remainder's share, so a uniform profile at P̄ always fits.
        let weight_total = match p.power_accounting {
            PowerAccounting::Time => frame_ticks,
            PowerAccounting::Angle => u64::from(FULL_TURN_MDEG),
        };
        let q = floor_code(p.average_power_w, step).ok_or_else(|| FirmwareError::Config {
            field: "power_w_per_code",
            reason: format!(
                "average_power_w {} W / step {step} W does not fit a u32 code",
                p.average_power_w
            ),
        })?;
        let rem = ((p.average_power_w - f64::from(q) * step) / step).clamp(0.0, 1.0);
        let energy_budget = u64::from(q)
            .checked_mul(weight_total)
            .and_then(|b| b.checked_add((rem * weight_total as f64).floor() as u64))
            .ok_or_else(|| FirmwareError::Config {
                field: "energy_budget",
                reason: "overflows u64: use a coarser power_w_per_code or a slower tick".into(),
            })?;
        let n = p.bins.len();
        let bins = (0..n)
            .map(|i| {
                let next = if i + 1 < n {
                    starts[i + 1]
                } else {
                    FULL_TURN_MDEG
                };
                FwBin {
                    start_deg: p.bins[i].start_deg,
                    width_mdeg: next.saturating_sub(starts[i]),
                    dwell_ticks: ticks[i],
                    power_code: codes[i],
                    dwell_ticks_min: bounds[i].0,
                    dwell_ticks_max: bounds[i].1,
                    power_code_cap: caps[i],
                }
            })
            .collect();
        let table = Self {
            format: FIRMWARE_FORMAT.to_owned(),
            tick_hz: cfg.tick_hz,
            frame_ticks,
            power_w_per_code: step,
            power_accounting: p.power_accounting,
            limits: IntLimits {
                power_code_min: floor_code(l.power_w_min, step).unwrap_or(0),
                power_code_max: max_code,
                energy_budget,
                window_bins,
                window_energy_max,
            },
            bins,
        };
        let v = check_table(&table);
        if v.is_empty() {
            Ok(table)
        } else {
            Err(FirmwareError::Rejected(v))
        }
    }

    /// Pretty JSON with a trailing newline.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        let mut s = serde_json::to_string_pretty(self)?;
        s.push('\n');
        Ok(s)
    }
}

/// Relative margin on the per-bin pulse cap: quantized dwell differs from
/// the certified one by at most one tick, which moves C5 by far less.
const CAP_MARGIN: f64 = 1e-4;

/// Per-bin integer cap from the single-pulse rule: at each aperture position
/// the certified evaluation gives the largest power the rule allows
/// (`p_max / ratio`, the rule being linear in power); a bin's cap is the
/// smallest over the positions whose pass covers it.
fn pulse_code_caps(certified: &CertifiedProfile, step: f64) -> Result<Vec<u32>, FirmwareError> {
    let p = certified.profile();
    let n = p.bins.len();
    let Some(params) = &p.limits.eye_safety else {
        return Ok(vec![u32::MAX; n]);
    };
    let report =
        crate::eye_safety::evaluate_profile(p, params).map_err(|e| FirmwareError::Config {
            field: "eye_safety",
            reason: e.to_string(),
        })?;
    let tl = crate::profile::kinematics::Timeline::new(p);
    let half = 0.5 * report.pass_angle_deg;
    let mut cap_w = vec![f64::INFINITY; n];
    for pos in &report.positions {
        let p_max = tl.max_power_in(pos.azimuth_deg - half, report.pass_angle_deg);
        let allowed = if pos.ratios[0] > 0.0 {
            p_max / pos.ratios[0]
        } else {
            f64::INFINITY
        };
        for i in tl.bins_touching(pos.azimuth_deg - half, report.pass_angle_deg) {
            cap_w[i] = cap_w[i].min(allowed);
        }
    }
    Ok(cap_w
        .into_iter()
        .map(|w| {
            if w.is_finite() {
                floor_code(w * (1.0 - CAP_MARGIN), step).unwrap_or(u32::MAX)
            } else {
                u32::MAX
            }
        })
        .collect())
}

/// Integer window limits: enough consecutive bins to cover any aperture
/// pass, and the largest energy such a window may hold under the T2 and
/// time-base rules, in code·tick units.
fn eye_safety_limits(
    certified: &CertifiedProfile,
    step: f64,
    tick_hz: f64,
) -> Result<(u32, u64), FirmwareError> {
    let p = certified.profile();
    let n = p.bins.len();
    let Some(params) = &p.limits.eye_safety else {
        return Ok((n as u32, u64::MAX));
    };
    let band = params.validate().map_err(|e| FirmwareError::Config {
        field: "eye_safety",
        reason: e.to_string(),
    })?;
    let ael_err = |e: ael::AelError| FirmwareError::Config {
        field: "eye_safety",
        reason: e.to_string(),
    };
    let lambda = params.wavelength_nm;
    let pass_deg =
        ((band.aperture_mm() + params.beam_diameter_mm) / APERTURE_DISTANCE_MM).to_degrees();
    let passes = |t: f64| (t * p.frame_rate_hz).floor() + 1.0;
    // Bins covering any pass: the longest run needed from any start, plus one.
    let mut window_bins = 1usize;
    for i in 0..n {
        let (mut covered, mut k) = (0.0, 0usize);
        while covered < pass_deg && k < n {
            covered += p.bins[(i + k) % n].width_deg;
            k += 1;
        }
        window_bins = window_bins.max(k + 1);
    }
    let window_bins = window_bins.min(n);
    let e_pass_max_j = (ael::ael_j(lambda, T2_S).map_err(ael_err)? / passes(T2_S))
        .min(ael::ael_j(lambda, TIME_BASE_S).map_err(ael_err)? / passes(TIME_BASE_S));
    let units = e_pass_max_j / (step / tick_hz);
    let window_energy_max = if units >= 1.8e19 {
        u64::MAX
    } else {
        units.floor() as u64
    };
    Ok((window_bins as u32, window_energy_max))
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::cover;

    /// REQ-FW-6: whatever the quantizer returns passes the integer checker's
    /// frame and dwell rules (quantizer and checker agree).
    #[cfg_attr(kani, kani::proof, kani::unwind(6))]
    #[cfg_attr(not(kani), test)]
    fn quantizer_output_passes_integer_frame_and_dwell_checks() {
        bolero::check!()
            .with_type::<([(u8, u8, u8, u8); 4], u8, u16)>()
            .cloned()
            .for_each(|(raw, n, total)| {
                let n = 1 + usize::from(n % 4);
                let targets: Vec<TickTarget> = raw[..n]
                    .iter()
                    .map(|&(floor, frac, min, span)| TickTarget {
                        floor: u64::from(floor),
                        frac: u32::from(frac) << 24,
                        min: u64::from(min),
                        max: u64::from(min) + u64::from(span),
                    })
                    .collect();
                let Ok(ticks) = apportion(&targets, u64::from(total % 1100)) else {
                    return;
                };
                cover!(true, "apportioned table checked");
                let bins = targets
                    .iter()
                    .zip(&ticks)
                    .enumerate()
                    .map(|(i, (t, &d))| FwBin {
                        start_deg: 0.0,
                        width_mdeg: if i == 0 { FULL_TURN_MDEG } else { 0 },
                        dwell_ticks: d,
                        power_code: 0,
                        dwell_ticks_min: t.min,
                        dwell_ticks_max: t.max,
                        power_code_cap: 0,
                    })
                    .collect();
                let table = FirmwareTable {
                    format: FIRMWARE_FORMAT.to_owned(),
                    tick_hz: 1,
                    frame_ticks: u64::from(total % 1100),
                    power_w_per_code: 1.0,
                    power_accounting: PowerAccounting::Time,
                    limits: IntLimits {
                        power_code_min: 0,
                        power_code_max: 0,
                        energy_budget: 0,
                        window_bins: 1,
                        window_energy_max: 0,
                    },
                    bins,
                };
                assert!(check_table(&table).is_empty(), "{:?}", check_table(&table));
            });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["apportioned table checked"]);
    }
}
