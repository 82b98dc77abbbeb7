//! `gaze-lidar check` on a firmware table: `gaze-lidar/firmware@1` JSON or
//! its binary encoding (`profile --format firmware-bin`), certified as it
//! will run by the same evaluation as `firmware::check_table` (integer
//! rules and the integer Class 1 check on the quantized table), and against
//! a sensor as profiles are (`firmware::check_table_for_sensor`).

use std::path::Path;

use gaze_lidar::eye_safety::exposure::stalled_rotor_ratio;
use gaze_lidar::firmware::{
    binary, check_header, check_table_evaluated, check_table_for_sensor, FirmwareTable,
    FwViolation, FIRMWARE_FORMAT,
};
use gaze_lidar::model::lidar::LidarSpec;
use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::profile::PROFILE_FORMAT;

use super::io::{utf8, warn, Stdout};
use super::verdict_format::Format;
use super::CliError;

/// What `check` was given.
pub enum Input {
    /// Text that is not a firmware table (a profile, or to be refused as one).
    Text(String),
    /// A firmware table.
    Table(FirmwareTable),
}

/// Sorts the bytes of `check`'s input: the binary encoding by its magic;
/// anything else is text for the profile reader (a firmware@1 JSON is
/// recognised by [`table_json`] when the profile reader refuses it, so a
/// profile costs no second pass).
pub fn classify(bytes: Vec<u8>, path: &Path, origin: &str) -> Result<Input, CliError> {
    if bytes.starts_with(binary::MAGIC) {
        return binary::decode(&bytes)
            .map(Input::Table)
            .map_err(|e| CliError::input(format!("{origin}: firmware-bin: {e}")));
    }
    Ok(Input::Text(utf8(bytes, path)?))
}

/// A text the profile reader refused, read as a firmware@1 table if its
/// `format` says so (`None`: not a table; the profile's error stands).
pub fn table_json(text: &str, origin: &str) -> Option<Result<FirmwareTable, CliError>> {
    #[derive(serde::Deserialize)]
    struct Head {
        format: String,
    }
    let head = serde_json::from_str::<Head>(text).ok()?;
    if head.format == FIRMWARE_FORMAT {
        return Some(FirmwareTable::from_json(text, origin).map_err(CliError::from));
    }
    // A format this build does not read (`gaze-lidar/firmware@2`, a typo):
    // named as such, not as the first field the profile reader trips on.
    (head.format != PROFILE_FORMAT).then(|| {
        Err(CliError::input(format!(
            "{origin}: field 'format' is '{}': not a format this build reads ({PROFILE_FORMAT}, {FIRMWARE_FORMAT})",
            head.format
        )))
    })
}

/// The header numbers of a table at the one numeric boundary
/// (`firmware::check_header`): bad input (exit 2) whatever else is checked,
/// the same for the JSON and the binary encoding (whose decoder already
/// refuses a step that is not finite and > 0).
pub fn check_boundary(table: &FirmwareTable, origin: &str) -> Result<(), CliError> {
    let v = check_header(table);
    if v.is_empty() {
        return Ok(());
    }
    let list: Vec<String> = v.iter().map(ToString::to_string).collect();
    Err(CliError::input(format!("{origin}: {}", list.join("; "))))
}

fn summary(t: &FirmwareTable) -> serde_json::Value {
    let energy: u128 = t
        .bins
        .iter()
        .map(|b| {
            let w = match t.power_accounting {
                PowerAccounting::Time => u128::from(b.dwell_ticks),
                PowerAccounting::Angle => u128::from(b.width_mdeg),
            };
            u128::from(b.power_code) * w
        })
        .sum();
    let codes = t.bins.iter().map(|b| b.power_code);
    serde_json::json!({
        "bins": t.bins.len(),
        "tick_hz": t.tick_hz,
        "frame_ticks": t.frame_ticks,
        "frame_period_s": t.frame_ticks as f64 / t.tick_hz as f64,
        "power_accounting": t.power_accounting,
        "energy": energy.to_string(),
        "energy_budget": t.limits.energy_budget,
        "power_code_range": [codes.clone().min(), codes.max()],
    })
}

/// Checks a table and reports as `check` does for a profile.
pub fn check(
    table: &FirmwareTable,
    origin: &str,
    sensor: Option<&LidarSpec>,
    format: Format,
    no_eye_safety: bool,
) -> Result<u8, CliError> {
    check_boundary(table, origin)?;
    let (mut violations, report) = match sensor {
        Some(s) => check_table_for_sensor(table, s),
        None => check_table_evaluated(table),
    };
    if no_eye_safety && table.eye_safety.is_none() {
        violations.retain(|v| !matches!(v, FwViolation::EyeSafetyMissing));
    }
    let mut out = Stdout::new();
    let head_channels = table
        .eye_safety
        .as_ref()
        .and_then(|e| e.head.as_ref())
        .map(|h| h.channels.len());
    if violations.is_empty() {
        // The stalled-rotor figure at the table's hottest code, as a
        // profile's report carries it (the same float head figures).
        let stalled = table.eye_safety.as_ref().and_then(|params| {
            let code_max = table.bins.iter().map(|b| b.power_code).max().unwrap_or(0);
            let power_max_w = f64::from(code_max) * table.power_w_per_code;
            stalled_rotor_ratio(params, table.pulse_rate_hz, power_max_w).ok()
        });
        let eye = report.as_ref().map(|r| {
            let ratio = r.worst_ratio_ppm as f64 / 1e6;
            (
                f64::from(r.azimuth_mdeg) / 1000.0,
                r.rule.to_string(),
                ratio,
            )
        });
        match format {
            Format::Json => out.line(serde_json::json!({
                "certified": true, "violations": [], "summary": summary(table),
                "eye_safety_evaluated": eye.is_some(),
                "sensor": sensor.map(|s| s.name.clone()),
                "eye_safety": eye.as_ref().map(|(az, rule, ratio)| serde_json::json!({
                    "worst_azimuth_deg": az, "binding_rule": rule,
                    "worst_ratio": ratio, "margin": 1.0 / ratio,
                    "stalled_rotor_ratio": stalled,
                    "evaluated_for": if head_channels.is_some() { "head" } else { "one channel" },
                    "channels_evaluated": head_channels.unwrap_or(1),
                })),
            }))?,
            Format::Text => {
                out.line(format_args!(
                    "certified: {origin}: firmware table, {} bins; frame {} ticks at {} Hz; energy budget {} ({})",
                    table.bins.len(), table.frame_ticks, table.tick_hz,
                    table.limits.energy_budget, table.power_accounting
                ))?;
                match &eye {
                    Some((az, rule, ratio)) => out.line(format_args!(
                        "eye safety: Class 1 at every azimuth as the table runs (integer check); worst {az:.3}° ({rule}), {:.4} % of the limit (margin {:.2}×)",
                        100.0 * ratio,
                        1.0 / ratio
                    ))
                    .and_then(|()| {
                        out.line(match head_channels {
                            Some(n) => format!("head: {n} channels evaluated (eye_safety.head), integer check"),
                            None => super::check::one_channel_line("eye_safety.head"),
                        })
                    })?,
                    None => out.line("eye safety: NOT evaluated (--no-eye-safety; the table has no eye-safety parameters): this verdict is not Class 1 evidence")?,
                }
            }
        }
        out.finish()?;
        if eye.is_some() {
            if let Some(ratio) = stalled {
                super::check::stalled_rotor_warning(ratio);
            }
        }
        return Ok(0);
    }
    match format {
        Format::Json => out.line(serde_json::json!({
            "certified": false,
            "violations": violations.iter().map(|v| serde_json::json!({
                "limit": v.limit_key(), "message": v.to_string(),
                // A u128 sum past u64 is not a JSON number here: its text.
                "detail": serde_json::to_value(v).unwrap_or_else(|_| v.to_string().into()),
            })).collect::<Vec<_>>(),
            "summary": summary(table),
        }))?,
        Format::Text => {
            for v in &violations {
                out.line(format_args!("violation: {v}"))?;
            }
        }
    }
    out.finish()?;
    warn(format_args!(
        "{origin}: rejected, {} violation(s)",
        violations.len()
    ));
    Ok(1)
}
