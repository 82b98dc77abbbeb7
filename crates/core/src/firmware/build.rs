//! Building a table from a certified profile (floating point: `std` only).

use super::{
    apportion, ceil_code, check_table, eye, floor_code, lower_to_budget, FirmwareConfig,
    FirmwareTable, FwBin, FwViolation, IntLimits, QuantizeError, TickTarget, FIRMWARE_FORMAT,
    FULL_TURN_MDEG, MAX_TABLE_BINS,
};
use crate::checker::CertifiedProfile;
use crate::model::accounting::PowerAccounting;
use thiserror::Error;

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

/// Ticks per revolution at `frame_rate_hz`: `round(tick_hz / frame_rate_hz)`.
pub fn frame_ticks_for(tick_hz: u64, frame_rate_hz: f64) -> Result<u64, FirmwareError> {
    u64_of((tick_hz as f64 / frame_rate_hz).round(), "frame_ticks")
}

/// A table's energy budget for an average power of `average_power_w`, in
/// code units per tick (time accounting) or per millidegree (angle), over
/// `weight_total` ticks or millidegrees: `floor(P̄/step)` per unit exactly
/// (as the codes are rounded), plus the remainder's share rounded down, so a
/// uniform profile at P̄ always fits and no more than P̄ does.
pub fn energy_budget(
    average_power_w: f64,
    step: f64,
    weight_total: u64,
) -> Result<u64, FirmwareError> {
    let q = floor_code(average_power_w, step).ok_or_else(|| FirmwareError::Config {
        field: "power_w_per_code",
        reason: format!(
            "average_power_w {average_power_w} W / step {step} W does not fit a u32 code"
        ),
    })?;
    let rem = ((average_power_w - f64::from(q) * step) / step).clamp(0.0, 1.0);
    u64::from(q)
        .checked_mul(weight_total)
        .and_then(|b| b.checked_add((rem * weight_total as f64).floor() as u64))
        .ok_or_else(|| FirmwareError::Config {
            field: "energy_budget",
            reason: "overflows u64: use a coarser power_w_per_code or a slower tick".into(),
        })
}

/// The energy budget's weight total: `frame_ticks` (time accounting) or a
/// full turn in millidegrees (angle).
#[must_use]
pub fn budget_weight_total(accounting: PowerAccounting, frame_ticks: u64) -> u64 {
    match accounting {
        PowerAccounting::Time => frame_ticks,
        PowerAccounting::Angle => u64::from(FULL_TURN_MDEG),
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
        if crate::model::valid::positive(step).is_err() {
            return Err(FirmwareError::Config {
                field: "power_w_per_code",
                reason: format!(
                    "{} must be finite and > 0, not subnormal (power_w_max must be > 0 for the default)",
                    crate::text::Num(step)
                ),
            });
        }
        let frame_ticks = frame_ticks_for(cfg.tick_hz, p.frame_rate_hz)?;
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
        // A step that rounds every bin's power down to code 0 gives a table
        // that keeps the laser off (certifiable, but never what was asked).
        let p_top = p.bins.iter().map(|b| b.power_w).fold(0.0, f64::max);
        if p_top > 0.0 && codes.iter().all(|&c| c == 0) {
            return Err(FirmwareError::Config {
                field: "power_w_per_code",
                reason: format!(
                    "{} W per code rounds every bin's power (the largest {} W) down to code 0: the table would keep the laser off; give a step of at most the largest bin power",
                    crate::text::Num(step),
                    crate::text::Num(p_top)
                ),
            });
        }
        let max_code = floor_code(l.power_w_max, step).unwrap_or(u32::MAX);
        // No bin below the minimum power: the least code at or above it.
        // (Within the checker's `REL_TOL`, as the profile's own comparison.)
        let min_code = ceil_code(l.power_w_min * (1.0 - crate::checker::REL_TOL), step)
            .unwrap_or(0)
            .min(max_code);
        let codes: Vec<u32> = codes.into_iter().map(|c| c.max(min_code)).collect();
        // Budget in code units per tick (time) or per millidegree (angle):
        // floor(P̄/step) exactly (as the codes are rounded), plus the
        // remainder's share, so a uniform profile at P̄ always fits.
        let weight_total = budget_weight_total(p.power_accounting, frame_ticks);
        let energy_budget = energy_budget(p.average_power_w, step, weight_total)?;
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
                power_code_min: min_code,
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
        lower_codes_to_budget(&mut table);
        lower_codes_for_eye_safety(&mut table);
        let v = check_table(&table);
        if v.is_empty() {
            Ok(table)
        } else {
            Err(FirmwareError::Rejected(v))
        }
    }

    /// Parses firmware@1 JSON; `origin` names the source in errors (line
    /// and column, the field serde names).
    #[cfg(feature = "json")]
    pub fn from_json(text: &str, origin: &str) -> Result<Self, crate::profile::IoError> {
        use crate::profile::IoError;
        let t: Self = serde_json::from_str(text).map_err(|e| IoError::Json {
            path: origin.to_owned(),
            line: e.line(),
            column: e.column(),
            message: crate::profile::strip_position(&e.to_string()),
        })?;
        if t.format != FIRMWARE_FORMAT {
            return Err(IoError::Json {
                path: origin.to_owned(),
                line: 1,
                column: 1,
                message: format!(
                    "field 'format' is '{}', expected '{FIRMWARE_FORMAT}'",
                    t.format
                ),
            });
        }
        Ok(t)
    }

    /// Pretty JSON with a trailing newline.
    #[cfg(feature = "json")]
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        let mut s = serde_json::to_string_pretty(self)?;
        s.push('\n');
        Ok(s)
    }
}

/// Lowers codes until the table's energy as the integer checker reads it
/// (`Σ code · dwell_ticks`, or `· width_mdeg` under angle accounting) fits
/// `limits.energy_budget` ([`lower_to_budget`]): rounding dwells to whole
/// ticks can leave it a few units over.
fn lower_codes_to_budget(table: &mut FirmwareTable) {
    let weights: Vec<u64> = table
        .bins
        .iter()
        .map(|b| match table.power_accounting {
            PowerAccounting::Time => b.dwell_ticks,
            PowerAccounting::Angle => u64::from(b.width_mdeg),
        })
        .collect();
    let mut codes: Vec<u32> = table.bins.iter().map(|b| b.power_code).collect();
    lower_to_budget(
        &mut codes,
        &weights,
        table.limits.power_code_min,
        table.limits.energy_budget,
    );
    for (b, c) in table.bins.iter_mut().zip(codes) {
        b.power_code = c;
    }
}

/// Lowers the codes of a quantized table until the table *as it will run*
/// meets the integer Class 1 check ([`eye::evaluate`]). The limits depend on
/// the table's timing only, and every energy the check compares is a sum of
/// `code × count` with counts fixed by the timing, so scaling every code by
/// `10^6 / worst_ratio_ppm` (rounded down; the ratio is rounded up) brings
/// every sum within its limit in one round; a second round is a safety net.
/// Codes never go below `power_code_min`; if that is not enough the table is
/// rejected by [`check_table`].
fn lower_codes_for_eye_safety(table: &mut FirmwareTable) {
    let limits = match eye::IntEyeLimits::derive(table) {
        Ok(l) => l,
        // No parameters, or a timing outside the integer bounds: nothing to
        // lower against; `check_table` rejects the table and says why.
        Err(_) => return,
    };
    for _ in 0..2 {
        let Ok(report) = eye::evaluate(table, &limits) else {
            return;
        };
        if report.class1 {
            break;
        }
        let ppm = u128::from(report.worst_ratio_ppm.max(1_000_001));
        let min = table.limits.power_code_min;
        for b in &mut table.bins {
            let lowered = u128::from(b.power_code) * 1_000_000 / ppm;
            b.power_code = u32::try_from(lowered).unwrap_or(u32::MAX).max(min);
        }
    }
    // Each bin's cap: rule 1 of the integer check (what a sensor may clamp to).
    let cap = u32::try_from(limits.pulse_code_cap()).unwrap_or(u32::MAX);
    for b in &mut table.bins {
        b.power_code_cap = b.power_code_cap.min(cap);
    }
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
