//! The integer checker for firmware tables: re-verifies a table against its
//! integer limits and Class 1 eye safety as it will run, with exact integer
//! arithmetic (u128 sums, no floats; builds without `std`).

use alloc::string::{String, ToString};
use alloc::vec::Vec;
use core::fmt;

use serde::Serialize;

use super::eye::{self, IntEyeLimits};
use super::{FirmwareTable, FULL_TURN_MDEG, MAX_TABLE_BINS};
use crate::model::accounting::PowerAccounting;
use crate::model::index::rotate_index;

/// One violated integer requirement.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FwViolation {
    /// No bins or too many.
    BinCount {
        /// Count.
        count: usize,
    },
    /// Σ dwell_ticks ≠ frame_ticks.
    FrameTicks {
        /// Sum found.
        sum: u128,
        /// frame_ticks.
        frame_ticks: u64,
    },
    /// Σ width_mdeg ≠ 360,000.
    Coverage {
        /// Sum found.
        sum: u128,
    },
    /// A dwell outside its bin's bounds (or bounds inverted).
    Dwell {
        /// Bin.
        bin: usize,
        /// Ticks.
        ticks: u64,
        /// Bounds.
        min: u64,
        /// Bounds.
        max: u64,
    },
    /// A power code outside `[power_code_min, power_code_max]`.
    PowerCode {
        /// Bin.
        bin: usize,
        /// Code.
        code: u32,
    },
    /// Energy budget exceeded (declared accounting, integer units).
    Budget {
        /// Σ found.
        energy: u128,
        /// Limit.
        limit: u64,
    },
    /// The table as it runs exceeds Class 1.
    EyeSafety {
        /// Worst ratio, parts per million (rounded up).
        ratio_ppm: u64,
        /// Aperture azimuth, millidegrees.
        azimuth_mdeg: u32,
        /// Binding rule.
        rule: crate::eye_safety::rule::Rule,
    },
    /// No eye-safety parameters: not Class 1 evidence.
    EyeSafetyMissing,
    /// Eye-safety parameters or pulse rate invalid.
    EyeSafetyParams {
        /// Why.
        reason: String,
    },
    /// A declared integer limit is looser than the sensor's own (quantized
    /// the way the table's own limits are).
    LooserThanSensor {
        /// The key (`limits.…` of the table).
        field: &'static str,
        /// The table's value.
        declared: u64,
        /// The sensor's value.
        sensor: u64,
    },
    /// The table does not run the sensor it is checked for (pulse rate,
    /// frame, accounting, eye-safety parameters, spin as run).
    SensorMismatch {
        /// The key.
        field: &'static str,
        /// What differs.
        detail: String,
    },
    /// A header number outside the one numeric boundary
    /// ([`model::valid`](crate::model::valid)): the timer, the frame, the
    /// DAC step or the pulse rate ([`check_header`]).
    Header {
        /// The key.
        field: &'static str,
        /// The value, as text (integers and floats alike).
        value: String,
        /// Why.
        reason: &'static str,
    },
    /// Energy in a window of consecutive bins above the eye-safety bound.
    Window {
        /// First bin of the window.
        bin: usize,
        /// Σ code·ticks found.
        energy: u128,
        /// Limit.
        limit: u64,
    },
}

impl fmt::Display for FwViolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BinCount { count } => write!(f, "bins: {count}; a table needs 1 to {MAX_TABLE_BINS}"),
            Self::FrameTicks { sum, frame_ticks } => {
                write!(f, "dwell_ticks sum to {sum}, frame_ticks is {frame_ticks}")
            }
            Self::Coverage { sum } => write!(f, "width_mdeg sum to {sum}, not {FULL_TURN_MDEG}"),
            Self::Dwell { bin, ticks, min, max } => {
                write!(f, "bins[{bin}].dwell_ticks = {ticks} outside [{min}, {max}] (spin limits)")
            }
            Self::PowerCode { bin, code } => {
                write!(f, "bins[{bin}].power_code = {code} outside [power_code_min, min(power_code_max, power_code_cap)]")
            }
            Self::Budget { energy, limit } => {
                write!(f, "energy {energy} exceeds limits.energy_budget {limit}")
            }
            Self::EyeSafety { ratio_ppm, azimuth_mdeg, rule } => write!(
                f,
                "eye_safety: as quantized, at azimuth {:.3}° the {rule} is {:.4} % of the Class 1 limit",
                f64::from(*azimuth_mdeg) / 1000.0,
                *ratio_ppm as f64 / 1e4
            ),
            Self::EyeSafetyMissing => write!(
                f,
                "eye_safety: the table has no eye-safety parameters (not Class 1 evidence)"
            ),
            Self::EyeSafetyParams { reason } => write!(f, "eye_safety: {reason}"),
            Self::LooserThanSensor { field, declared, sensor } => {
                write!(f, "{field} = {declared} is looser than the sensor's {sensor}")
            }
            Self::SensorMismatch { field, detail } => write!(f, "{field}: {detail}"),
            Self::Header { field, value, reason } => write!(f, "{field} = {value}: {reason}"),
            Self::Window { bin, energy, limit } => write!(
                f,
                "eye safety: energy {energy} in the window starting at bins[{bin}] exceeds limits.window_energy_max {limit}"
            ),
        }
    }
}

impl FwViolation {
    /// The table key or limit this violation is about.
    #[must_use]
    pub fn limit_key(&self) -> &'static str {
        match self {
            Self::BinCount { .. } | Self::Coverage { .. } => "bins",
            Self::FrameTicks { .. } => "frame_ticks",
            Self::Dwell { .. } => "dwell_ticks",
            Self::PowerCode { .. } => "power_code",
            Self::Budget { .. } => "energy_budget",
            Self::EyeSafety { .. } | Self::EyeSafetyMissing | Self::EyeSafetyParams { .. } => {
                "eye_safety"
            }
            Self::LooserThanSensor { field, .. }
            | Self::SensorMismatch { field, .. }
            | Self::Header { field, .. } => field,
            Self::Window { .. } => "window_energy_max",
        }
    }
}

/// Every violation of `table` as it will run: the integer rules of
/// [`check_integer`] and Class 1 eye safety evaluated **in integers on the
/// quantized table itself** ([`eye::evaluate`]: dwell from ticks, pulse
/// counts as maxima over every clock phase, energy from codes) against
/// integer limits derived once from the one eye-safety model and rounded
/// down ([`IntEyeLimits::derive`]). A table without eye-safety parameters is
/// rejected: it is not Class 1 evidence.
#[cfg(feature = "std")]
#[must_use]
pub fn check_table(table: &FirmwareTable) -> Vec<FwViolation> {
    check_table_evaluated(table).0
}

/// [`check_table`], keeping the integer eye-safety evaluation it ran
/// (`None` when the table could not be evaluated: no parameters, a timing
/// outside the integer bounds, no bins).
#[cfg(feature = "std")]
#[must_use]
pub fn check_table_evaluated(
    table: &FirmwareTable,
) -> (Vec<FwViolation>, Option<eye::IntEyeReport>) {
    let mut v = check_header(table);
    let header_ok = v.is_empty();
    v.extend(check_integer(table));
    // Eye safety reads the header's numbers: not evaluated on bad ones (a
    // table without parameters still says so).
    if !header_ok || v.iter().any(|x| matches!(x, FwViolation::BinCount { .. })) {
        if !header_ok && table.eye_safety.is_none() {
            v.push(FwViolation::EyeSafetyMissing);
        }
        return (v, None);
    }
    match IntEyeLimits::derive(table) {
        Ok(limits) => match eye::evaluate(table, &limits) {
            Ok(r) => {
                v.extend(report_violation(&r));
                (v, Some(r))
            }
            Err(e) => {
                v.push(FwViolation::EyeSafetyParams {
                    reason: e.to_string(),
                });
                (v, None)
            }
        },
        Err(eye::DeriveError::Missing) => {
            v.push(FwViolation::EyeSafetyMissing);
            (v, None)
        }
        Err(e) => {
            v.push(FwViolation::EyeSafetyParams {
                reason: e.to_string(),
            });
            (v, None)
        }
    }
}

/// As [`check_table`] against integer eye-safety limits given by the caller
/// (a sensor's firmware holds the limits of its own laser, derived on a host
/// with [`IntEyeLimits::derive`]); no floating point.
#[must_use]
pub fn check_table_with(table: &FirmwareTable, limits: &IntEyeLimits) -> Vec<FwViolation> {
    let mut v = check_header(table);
    let header_ok = v.is_empty();
    v.extend(check_integer(table));
    if !header_ok || v.iter().any(|x| matches!(x, FwViolation::BinCount { .. })) {
        return v;
    }
    v.extend(eye_violation(table, limits));
    v
}

fn eye_violation(table: &FirmwareTable, limits: &IntEyeLimits) -> Option<FwViolation> {
    match eye::evaluate(table, limits) {
        Ok(r) => report_violation(&r),
        Err(e) => Some(FwViolation::EyeSafetyParams {
            reason: e.to_string(),
        }),
    }
}

/// The violation an integer eye-safety report implies, if any.
fn report_violation(r: &eye::IntEyeReport) -> Option<FwViolation> {
    (!r.class1).then_some(FwViolation::EyeSafety {
        ratio_ppm: r.worst_ratio_ppm,
        azimuth_mdeg: r.azimuth_mdeg,
        rule: r.rule,
    })
}

/// Fastest timer a table may declare, Hz (the quantizer's `--tick-hz` range).
pub const TICK_HZ_MAX: u64 = 10_000_000_000;

/// The header numbers of `table` against the one numeric boundary
/// ([`model::valid`](crate::model::valid)), as a profile's are checked:
/// `tick_hz` within `1..=`[`TICK_HZ_MAX`]; `frame_ticks >= 1` with a frame
/// rate `tick_hz / frame_ticks` that is a rate; `power_w_per_code` finite,
/// `> 0` and normal; `pulse_rate_hz` a rate. Whatever else is checked or
/// skipped (`--no-eye-safety` skips only the eye-safety rules), a table
/// passes this boundary: every other rule reads these numbers.
#[must_use]
pub fn check_header(table: &FirmwareTable) -> Vec<FwViolation> {
    use crate::model::valid;
    use crate::text::Num;
    use alloc::format;
    let mut v = Vec::new();
    let tick_ok = (1..=TICK_HZ_MAX).contains(&table.tick_hz);
    if !tick_ok {
        v.push(FwViolation::Header {
            field: "tick_hz",
            value: table.tick_hz.to_string(),
            reason: "must lie in 1..=10000000000 Hz",
        });
    }
    if table.frame_ticks == 0 {
        v.push(FwViolation::Header {
            field: "frame_ticks",
            value: "0".to_string(),
            reason: "must be >= 1 (a frame lasts at least one tick)",
        });
    } else if tick_ok && valid::rate_hz(table.tick_hz as f64 / table.frame_ticks as f64).is_err() {
        v.push(FwViolation::Header {
            field: "frame_ticks",
            value: table.frame_ticks.to_string(),
            reason: "gives a frame rate tick_hz / frame_ticks outside 1e-9..=1e12 Hz",
        });
    }
    if let Err(reason) = valid::positive(table.power_w_per_code) {
        v.push(FwViolation::Header {
            field: "power_w_per_code",
            value: format!("{}", Num(table.power_w_per_code)),
            reason,
        });
    }
    if let Err(reason) = valid::rate_hz(table.pulse_rate_hz) {
        v.push(FwViolation::Header {
            field: "pulse_rate_hz",
            value: format!("{}", Num(table.pulse_rate_hz)),
            reason,
        });
    }
    v
}

/// Every integer violation of `table` (frame, coverage, dwell bounds, codes,
/// energy budget, window sums), in exact integer arithmetic.
#[must_use]
pub fn check_integer(table: &FirmwareTable) -> Vec<FwViolation> {
    let mut v = Vec::new();
    let n = table.bins.len();
    if n == 0 || n > MAX_TABLE_BINS {
        v.push(FwViolation::BinCount { count: n });
        return v;
    }
    let l = &table.limits;
    let ticks_sum: u128 = table.bins.iter().map(|b| u128::from(b.dwell_ticks)).sum();
    if ticks_sum != u128::from(table.frame_ticks) {
        v.push(FwViolation::FrameTicks {
            sum: ticks_sum,
            frame_ticks: table.frame_ticks,
        });
    }
    let width_sum: u128 = table.bins.iter().map(|b| u128::from(b.width_mdeg)).sum();
    if width_sum != u128::from(FULL_TURN_MDEG) {
        v.push(FwViolation::Coverage { sum: width_sum });
    }
    for (i, b) in table.bins.iter().enumerate() {
        if !(b.dwell_ticks_min <= b.dwell_ticks && b.dwell_ticks <= b.dwell_ticks_max) {
            v.push(FwViolation::Dwell {
                bin: i,
                ticks: b.dwell_ticks,
                min: b.dwell_ticks_min,
                max: b.dwell_ticks_max,
            });
        }
        if !(l.power_code_min <= b.power_code
            && b.power_code <= l.power_code_max.min(b.power_code_cap))
        {
            v.push(FwViolation::PowerCode {
                bin: i,
                code: b.power_code,
            });
        }
    }
    let energy: u128 = table
        .bins
        .iter()
        .map(|b| {
            let weight = match table.power_accounting {
                PowerAccounting::Time => u128::from(b.dwell_ticks),
                PowerAccounting::Angle => u128::from(b.width_mdeg),
            };
            u128::from(b.power_code) * weight
        })
        .sum();
    if energy > u128::from(l.energy_budget) {
        v.push(FwViolation::Budget {
            energy,
            limit: l.energy_budget,
        });
    }
    let w = (l.window_bins as usize).min(n);
    for i in 0..n {
        let e = window_energy(table, i, w);
        if e > u128::from(l.window_energy_max) {
            v.push(FwViolation::Window {
                bin: i,
                energy: e,
                limit: l.window_energy_max,
            });
        }
    }
    v
}

/// Σ code·ticks over the `w` consecutive bins starting at `start` (cyclic).
#[must_use]
pub fn window_energy(table: &FirmwareTable, start: usize, w: usize) -> u128 {
    let n = table.bins.len();
    (0..w)
        .map(|k| {
            let b = &table.bins[rotate_index(start, k, n)];
            u128::from(b.power_code) * u128::from(b.dwell_ticks)
        })
        .sum()
}

/// [`check_integer`]'s specification, restated as directly as possible
/// (plain loops, no prefix sums, no shared helper): `true` exactly when the
/// table is within its integer limits. The oracle of the
/// `integer_checker_accepts_exactly_tables_within_limits` harness and of the
/// `firmware_check` fuzz target; not used by the checker.
#[doc(hidden)]
#[must_use]
pub fn within_integer_limits(t: &FirmwareTable) -> bool {
    let n = t.bins.len();
    if n == 0 || n > MAX_TABLE_BINS {
        return false;
    }
    let mut ticks: u128 = 0;
    let mut width: u128 = 0;
    let mut energy: u128 = 0;
    for b in &t.bins {
        ticks += u128::from(b.dwell_ticks);
        width += u128::from(b.width_mdeg);
        let weight = if t.power_accounting == PowerAccounting::Angle {
            b.width_mdeg as u128
        } else {
            b.dwell_ticks as u128
        };
        energy += b.power_code as u128 * weight;
        if b.dwell_ticks < b.dwell_ticks_min || b.dwell_ticks > b.dwell_ticks_max {
            return false;
        }
        if b.power_code < t.limits.power_code_min
            || b.power_code > t.limits.power_code_max
            || b.power_code > b.power_code_cap
        {
            return false;
        }
    }
    let w = (t.limits.window_bins as usize).min(n);
    for s in 0..n {
        let mut e: u128 = 0;
        for k in 0..w {
            let b = &t.bins[(s + k) % n];
            e += b.power_code as u128 * b.dwell_ticks as u128;
        }
        if e > t.limits.window_energy_max as u128 {
            return false;
        }
    }
    ticks == t.frame_ticks as u128
        && width == u128::from(FULL_TURN_MDEG)
        && energy <= t.limits.energy_budget as u128
}

#[cfg(any(kani, test))]
mod verification {
    use super::*;
    use crate::firmware::{FwBin, IntLimits, FIRMWARE_FORMAT};
    use crate::verification::{cover, for_all};

    /// A small symbolic table: up to 4 bins with small values.
    fn table(
        raw: &[(u8, u8, u8, u8)],
        frame: u16,
        limits: (u8, u8, u16, u8, u16),
        angle: bool,
    ) -> FirmwareTable {
        let n = raw.len();
        let bins = raw
            .iter()
            .enumerate()
            .map(|(i, &(ticks, code, min, span))| FwBin {
                start_deg: 0.0,
                // Widths sum to 360,000 exactly (the last takes the rest).
                width_mdeg: if i + 1 == n {
                    FULL_TURN_MDEG - 90_000 * (n as u32 - 1)
                } else {
                    90_000
                },
                dwell_ticks: u64::from(ticks),
                power_code: u32::from(code),
                dwell_ticks_min: u64::from(min),
                dwell_ticks_max: u64::from(min) + u64::from(span),
                power_code_cap: u32::from(span) * 2,
            })
            .collect();
        FirmwareTable {
            format: FIRMWARE_FORMAT.to_owned(),
            tick_hz: 1000,
            frame_ticks: u64::from(frame),
            power_w_per_code: 1.0,
            power_accounting: if angle {
                PowerAccounting::Angle
            } else {
                PowerAccounting::Time
            },
            pulse_rate_hz: 0.0,
            eye_safety: None,
            limits: IntLimits {
                power_code_min: u32::from(limits.0),
                power_code_max: u32::from(limits.1),
                energy_budget: u64::from(limits.2) * 1000,
                window_bins: u32::from(limits.3 % 5),
                window_energy_max: u64::from(limits.4),
            },
            bins,
        }
    }

    /// REQ-FW-3: the integer checker accepts exactly the tables within their limits.
    #[cfg_attr(kani, kani::proof, kani::unwind(6))]
    #[cfg_attr(not(kani), test)]
    fn integer_checker_accepts_exactly_tables_within_limits() {
        for_all!(
            (
                [(u8, u8, u8, u8); 4],
                u8,
                u16,
                (u8, u8, u16, u8, u16),
                bool,
                bool
            ),
            |(mut raw, n, frame, limits, angle, consistent)| {
                let n = 1 + usize::from(n % 4);
                // Arbitrary tables almost never sum to their frame: half the
                // inputs are made consistent (dwell within its minimum, frame
                // = the sum), so that accepted tables are reachable by random
                // testing too, not only by the symbolic proof.
                let frame = if consistent {
                    for r in raw.iter_mut() {
                        r.2 = r.2.min(r.0);
                    }
                    raw[..n].iter().map(|r| u16::from(r.0)).sum()
                } else {
                    frame
                };
                let t = table(&raw[..n], frame, limits, angle);
                let accepted = check_integer(&t).is_empty();
                cover!(accepted, "a table is accepted");
                cover!(!accepted, "a table is rejected");
                assert_eq!(accepted, within_integer_limits(&t));
            }
        );
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["a table is accepted", "a table is rejected"]);
    }

    /// REQ-FW-3: window sums never overflow and equal the naive cyclic sum,
    /// for every start and window length.
    #[cfg_attr(kani, kani::proof, kani::unwind(6))]
    #[cfg_attr(not(kani), test)]
    fn window_sum_matches_naive_and_never_overflows() {
        for_all!(([(u8, u8, u8, u8); 4], u8, u8, u8), |(raw, n, start, w)| {
            let n = 1 + usize::from(n % 4);
            let mut t = table(&raw[..n], 0, (0, 255, 0, 0, 0), false);
            for b in &mut t.bins {
                // Extremes: the largest codes and tick counts a table can hold.
                b.power_code = u32::MAX - b.power_code;
                b.dwell_ticks = u64::MAX - b.dwell_ticks;
            }
            let start = usize::from(start) % n;
            let w = usize::from(w) % (n + 1);
            cover!(w == n && start > 0, "full wrap-around window");
            let naive: u128 = (0..w)
                .map(|k| {
                    let b = &t.bins[(start + k) % n];
                    u128::from(b.power_code) * u128::from(b.dwell_ticks)
                })
                .sum();
            assert_eq!(window_energy(&t, start, w), naive);
        });
        #[cfg(not(kani))]
        crate::verification::assert_covered(&["full wrap-around window"]);
    }
}
