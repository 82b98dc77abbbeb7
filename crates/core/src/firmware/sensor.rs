//! A firmware table held against a sensor's own limits, as a profile is by
//! [`crate::checker::CheckOptions::for_sensor`]: every declared integer limit
//! no looser than the sensor's quantized the way the table's own limits are
//! ([`super::FirmwareTable::from_certified`]), and the table runs the
//! sensor's laser, pulse clock and frame (floating point: `std` only).

// Negated comparisons (`!(x <= limit)`) are deliberate: a NaN must fail.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::format;
use alloc::vec::Vec;

use super::build::{budget_weight_total, energy_budget, frame_ticks_for};
use super::{ceil_code, check_table_evaluated, eye, floor_code, FirmwareTable, FwViolation};
use crate::checker::REL_TOL;
use crate::model::lidar::{laser_mismatches, no_looser, LidarSpec, LimitSide};

/// Every violation of `table` as it will run ([`super::check_table`]) and
/// against `sensor`, with the integer eye-safety evaluation the verdict
/// rests on (`None` if the table could not be evaluated).
#[must_use]
pub fn check_table_for_sensor(
    table: &FirmwareTable,
    sensor: &LidarSpec,
) -> (Vec<FwViolation>, Option<eye::IntEyeReport>) {
    let (mut v, report) = check_table_evaluated(table);
    v.extend(against_sensor(table, sensor));
    (v, report)
}

/// The sensor comparisons alone. Every float comparison is written so that
/// NaN fails it.
#[must_use]
pub fn against_sensor(table: &FirmwareTable, sensor: &LidarSpec) -> Vec<FwViolation> {
    let mut v = Vec::new();
    let mismatch = |field, detail| FwViolation::SensorMismatch { field, detail };
    let s = &sensor.limits;
    // The laser and pulse clock, compared as for a profile (one comparator).
    // A table without parameters is already rejected by check_table.
    for (field, detail) in laser_mismatches(
        table.pulse_rate_hz,
        table.power_accounting,
        table.eye_safety.as_ref(),
        sensor,
    ) {
        v.push(mismatch(field, detail));
    }
    // The frame: the tick count the quantizer gives the sensor's frame rate.
    match frame_ticks_for(table.tick_hz, sensor.frame_rate_hz) {
        Ok(ft) if ft == table.frame_ticks => {}
        Ok(ft) => v.push(mismatch(
            "frame_ticks",
            format!(
                "{} ticks at {} Hz is not the sensor's frame ({ft} ticks at {} Hz)",
                table.frame_ticks, table.tick_hz, sensor.frame_rate_hz
            ),
        )),
        Err(e) => v.push(mismatch("frame_ticks", e.to_string())),
    }
    // Declared integer limits, quantized with the table's own DAC step.
    let step = table.power_w_per_code;
    let l = &table.limits;
    let mut looser =
        |field: &'static str, declared: u64, sensor: Option<u64>, side: LimitSide| match sensor {
            Some(x) if no_looser(declared, x, side) => {}
            Some(x) => v.push(FwViolation::LooserThanSensor {
                field,
                declared,
                sensor: x,
            }),
            None => v.push(mismatch(
                field,
                format!("the sensor's limit does not fit the table's DAC step {step} W per code"),
            )),
        };
    looser(
        "limits.power_code_max",
        u64::from(l.power_code_max),
        floor_code(s.power_w_max, step).map(u64::from),
        LimitSide::Upper,
    );
    looser(
        "limits.power_code_min",
        u64::from(l.power_code_min),
        // A lower limit rounds up: the table's least code must reach the
        // sensor's minimum power (within `REL_TOL`, as a profile's power).
        ceil_code(s.power_w_min * (1.0 - REL_TOL), step).map(u64::from),
        LimitSide::Lower,
    );
    let weight = budget_weight_total(table.power_accounting, table.frame_ticks);
    looser(
        "limits.energy_budget",
        l.energy_budget,
        energy_budget(sensor.average_power_w, step, weight).ok(),
        LimitSide::Upper,
    );
    // Spin as the table runs it: bin i sweeps width_mdeg in dwell_ticks.
    // One violation per limit, at the bin furthest past it (with a count).
    let tick_hz = table.tick_hz as f64;
    let spins = table
        .bins
        .iter()
        .enumerate()
        .filter(|(_, b)| b.width_mdeg > 0)
        .map(|(i, b)| {
            let deg = f64::from(b.width_mdeg) / 1000.0;
            (i, deg.to_radians() * tick_hz / b.dwell_ticks as f64)
        });
    let hi = s.spin_rad_s_max * (1.0 + REL_TOL);
    let lo = s.spin_rad_s_min * (1.0 - REL_TOL);
    for (field, outside, worse) in [
        (
            "spin_rad_s_max",
            (|x: f64, lim: f64| !(x <= lim)) as fn(f64, f64) -> bool,
            (|a: f64, b: f64| !(a <= b)) as fn(f64, f64) -> bool,
        ),
        ("spin_rad_s_min", |x, lim| !(x >= lim), |a, b| !(a >= b)),
    ] {
        let (lim, sensor_lim) = if field == "spin_rad_s_max" {
            (hi, s.spin_rad_s_max)
        } else {
            (lo, s.spin_rad_s_min)
        };
        let mut count = 0usize;
        let mut worst: Option<(usize, f64)> = None;
        for (i, spin) in spins.clone().filter(|&(_, x)| outside(x, lim)) {
            count += 1;
            if worst.is_none_or(|(_, w)| worse(spin, w)) {
                worst = Some((i, spin));
            }
        }
        if let Some((i, spin)) = worst {
            v.push(mismatch(
                field,
                format!(
                    "bins[{i}] runs at {spin} rad/s as the table runs it ({} mdeg in {} ticks), past the sensor's {sensor_lim} rad/s ({count} bin(s) past it)",
                    table.bins[i].width_mdeg, table.bins[i].dwell_ticks
                ),
            ));
        }
    }
    v
}
