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
use crate::model::lidar::PowerAccounting;

pub use check::{check_integer, check_table, FwViolation};
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
    /// Laser firing rate, Hz (eye safety of the table as it runs).
    #[serde(default)]
    pub pulse_rate_hz: f64,
    /// Laser and optics parameters; a table without them is not Class 1
    /// evidence and fails [`check_table`].
    #[serde(default)]
    pub eye_safety: Option<crate::eye_safety::EyeSafetyParams>,
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
                    power_code_cap: max_code,
                }
            })
            .collect();
        let table = Self {
            format: FIRMWARE_FORMAT.to_owned(),
            tick_hz: cfg.tick_hz,
            frame_ticks,
            power_w_per_code: step,
            power_accounting: p.power_accounting,
            pulse_rate_hz: p.pulse_rate_hz,
            eye_safety: l.eye_safety.clone(),
            limits: IntLimits {
                power_code_min: floor_code(l.power_w_min, step).unwrap_or(0),
                power_code_max: max_code,
                energy_budget,
                // The window sums are superseded by the eye-safety bound
                // evaluated on the table as it runs (see `check_table`).
                window_bins: 1,
                window_energy_max: u64::MAX,
            },
            bins,
        };
        let mut table = table;
        lower_codes_for_eye_safety(&mut table)?;
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

/// Lowers the codes of a quantized table until the table *as it will run*
/// (quantized dwell, quantized codes) meets Class 1: each round scales every
/// code by `1/ratio` (rounded down), which the bound's linearity in power
/// makes sufficient but for the pulse-count rounding; a few rounds settle it.
/// Codes never go below `power_code_min`; if that is not enough the table is
/// rejected by [`check_table`].
fn lower_codes_for_eye_safety(table: &mut FirmwareTable) -> Result<(), FirmwareError> {
    for _ in 0..16 {
        let Some(report) = table_exposure(table) else {
            return Ok(());
        };
        let report = report.map_err(|e| FirmwareError::Config {
            field: "eye_safety",
            reason: e.to_string(),
        })?;
        if report.worst_ratio <= 1.0 {
            return Ok(());
        }
        let scale = (1.0 - 1e-6) / report.worst_ratio;
        let min = table.limits.power_code_min;
        for b in &mut table.bins {
            let lowered = (f64::from(b.power_code) * scale).floor() as u32;
            b.power_code = lowered
                .max(min)
                .min(b.power_code.saturating_sub(1).max(min));
        }
    }
    Ok(())
}

/// The bins of a table as it will run: bin `i` swept at constant spin in
/// exactly `dwell_ticks / tick_hz` seconds, at `power_code · power_w_per_code`.
/// Zero-width bins are left out; `None` when a bin has width but no dwell.
#[must_use]
pub fn as_run_segments(table: &FirmwareTable) -> Option<Vec<crate::eye_safety::bound::Seg>> {
    let mut segs = Vec::with_capacity(table.bins.len());
    let mut start_mdeg: u64 = 0;
    for b in &table.bins {
        if b.width_mdeg == 0 {
            continue;
        }
        if b.dwell_ticks == 0 || table.tick_hz == 0 {
            return None;
        }
        let width_deg = f64::from(b.width_mdeg) / 1000.0;
        let spin = width_deg.to_radians() * table.tick_hz as f64 / b.dwell_ticks as f64;
        segs.push(crate::eye_safety::bound::Seg {
            start_deg: start_mdeg as f64 / 1000.0,
            width_deg,
            power_w: f64::from(b.power_code) * table.power_w_per_code,
            spin_start_rad_s: spin,
            spin_end_rad_s: spin,
        });
        start_mdeg += u64::from(b.width_mdeg);
    }
    Some(segs)
}

/// The eye-safety evaluation of a table as it will run; `None` without
/// eye-safety parameters.
#[must_use]
pub fn table_exposure(
    table: &FirmwareTable,
) -> Option<Result<crate::eye_safety::ExposureReport, crate::eye_safety::EyeSafetyError>> {
    let params = table.eye_safety.as_ref()?;
    Some(match as_run_segments(table) {
        Some(segs) if !segs.is_empty() => {
            crate::eye_safety::evaluate_segments(&segs, params, table.pulse_rate_hz)
        }
        _ => Err(crate::eye_safety::EyeSafetyError::Param {
            field: "bins",
            value: 0.0,
            reason: "a table needs at least one bin with width and dwell",
        }),
    })
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::verification::{cover, for_all};

    /// REQ-FW-6: whatever the quantizer returns passes the integer checker's
    /// frame and dwell rules (quantizer and checker agree).
    #[cfg_attr(kani, kani::proof, kani::unwind(6))]
    #[cfg_attr(not(kani), test)]
    fn quantizer_output_passes_integer_frame_and_dwell_checks() {
        for_all!(([(u8, u8, u8, u8); 4], u8, u16), |(raw, n, total)| {
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
                pulse_rate_hz: 0.0,
                eye_safety: None,
                limits: IntLimits {
                    power_code_min: 0,
                    power_code_max: 0,
                    energy_budget: 0,
                    window_bins: 1,
                    window_energy_max: 0,
                },
                bins,
            };
            assert!(
                check_integer(&table).is_empty(),
                "{:?}",
                check_integer(&table)
            );
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["apportioned table checked"]);
    }
}
