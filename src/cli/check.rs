//! `gaze-lidar check`: verify a profile@1 file or a firmware table.

use std::path::PathBuf;

use gaze_lidar::checker::verdict::worst_position;
use gaze_lidar::checker::{certify_with, CheckOptions, Verdict, Violation};
use gaze_lidar::eye_safety::exposure::ExposureReport;
use gaze_lidar::eye_safety::head::bound::power_scale_to_certify;
use gaze_lidar::eye_safety::head::geometry::Surface;
use gaze_lidar::model::lidar::LidarSpec;
use gaze_lidar::profile::Profile;

use super::io::{read_bytes, warn, Stdout, MAX_PROFILE_BYTES};
use super::verdict_format::Format;
use super::CliError;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Profile JSON, firmware@1 JSON or binary firmware table (`-` for stdin).
    file: PathBuf,
    /// Report format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Also certify against this preset's sensor: any declared limit looser
    /// than the sensor's, and any laser parameter (pulse rate, accounting,
    /// eye-safety parameters and head) not exactly the sensor's, is
    /// rejected, naming the key.
    #[arg(long, conflicts_with = "sensor")]
    preset: Option<String>,
    /// Also certify against a sensor described in TOML: exactly the fields
    /// of a preset's `lidar` (name, frame_rate_hz, pulse_rate_hz, channels,
    /// average_power_w, rated_range_m, reference_reflectivity,
    /// power_accounting, [limits] with "unlimited" for no limit,
    /// [limits.eye_safety]); `gaze-lidar sensor --preset P` writes one.
    #[arg(long, value_name = "FILE.toml")]
    sensor: Option<PathBuf>,
    /// Accept a file without eye-safety parameters (`limits.eye_safety:
    /// null`); the verdict then says nothing about Class 1, and says so.
    #[arg(long)]
    no_eye_safety: bool,
}

fn sensor_of(a: &Args) -> Result<Option<LidarSpec>, CliError> {
    if let Some(name) = &a.preset {
        let p = gaze_lidar::model::presets::preset(name)
            .map_err(|e| CliError::input(format!("--preset: {e}")))?;
        return Ok(Some(p.lidar));
    }
    if let Some(path) = &a.sensor {
        return super::sensor::read(path).map(Some);
    }
    Ok(None)
}

/// The verdict as one line of JSON.
fn verdict_json(v: &Verdict) -> Result<serde_json::Value, CliError> {
    serde_json::to_value(v).map_err(|e| CliError::output(format!("verdict as JSON: {e}")))
}

/// One line naming what was evaluated: the head (channels, the worst
/// aperture position and the surface it is on, the beams meeting it, the
/// binding rule, and the declared distance when the head declares one other
/// than 100 mm) or one channel.
fn head_line(r: &ExposureReport, profile: &Profile) -> String {
    match &r.head {
        Some(h) => {
            let (height_mm, beams) = worst_position(r.binding_rule, h);
            let declared_mm = profile
                .limits
                .eye_safety
                .as_ref()
                .and_then(|e| e.head.as_ref())
                .map_or(100.0, |h| h.aperture_distance_mm);
            #[allow(clippy::float_cmp)]
            let surfaces = if declared_mm == 100.0 {
                String::new()
            } else {
                format!(
                    "; evaluated on the 100 mm Condition 3 surfaces and on the declared {} mm ones (the worst is the verdict)",
                    gaze_lidar::text::Num(declared_mm)
                )
            };
            let surface = match h.surface {
                Surface::Cylinder => "the cylinder around the spin axis",
                Surface::Sphere => "the sphere around the scan centre",
            };
            #[allow(clippy::float_cmp)]
            let at = if h.aperture_distance_mm == 100.0 {
                " (100 mm)".to_owned()
            } else {
                format!(
                    " at the declared {} mm",
                    gaze_lidar::text::Num(h.aperture_distance_mm)
                )
            };
            format!(
                "head: {} channels evaluated; worst aperture position {:.3}° azimuth, {:.2} mm height on {surface}{at}; {} beam(s) meet it; binding rule: {}{surfaces}",
                h.channels, r.worst_azimuth_deg, height_mm, beams, r.binding_rule
            )
        }
        None => one_channel_line("limits.eye_safety.head"),
    }
}

/// The warning (stderr) of a certified input whose stalled rotor is over
/// Class 1: the product needs a stall interlock.
pub(super) fn stalled_rotor_warning(ratio: f64) {
    if ratio > 1.0 {
        warn(format_args!(
            "warning: a stalled rotor with the laser firing reaches {:.0} % of the Class 1 limit: the product needs a stall interlock",
            100.0 * ratio
        ));
    }
}

/// The verdict's line for a file without a head (`field` the absent head's
/// path in the file's format): one channel was evaluated, not the sensor.
pub(super) fn one_channel_line(field: &str) -> String {
    format!("head: none given, evaluated for one channel ({field} absent: the sensor's other channels are not counted)")
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    let bytes = read_bytes(&a.file, MAX_PROFILE_BYTES)?;
    let origin = a.file.display().to_string();
    let text = match super::table::classify(bytes, &a.file, &origin)? {
        super::table::Input::Table(t) => {
            let sensor = sensor_of(a)?;
            return super::table::check(&t, &origin, sensor.as_ref(), a.format, a.no_eye_safety);
        }
        super::table::Input::Text(text) => text,
    };
    let name = if a.file.as_os_str() == "-" {
        "<stdin>"
    } else {
        origin.as_str()
    };
    let profile = match Profile::from_json_with_notes(&text, name) {
        Ok((p, notes)) => {
            for note in notes {
                warn(format_args!("warning: {name}: {note}"));
            }
            p
        }
        Err(e) => {
            let Some(table) = super::table::table_json(&text, name) else {
                return Err(e.into());
            };
            let sensor = sensor_of(a)?;
            return super::table::check(
                &table?,
                &origin,
                sensor.as_ref(),
                a.format,
                a.no_eye_safety,
            );
        }
    };
    drop(text);
    let sensor = sensor_of(a)?;
    let mut opts = CheckOptions::declared().allow_missing_eye_safety(a.no_eye_safety);
    if let Some(s) = &sensor {
        opts = CheckOptions::for_sensor(s).allow_missing_eye_safety(a.no_eye_safety);
    }
    let mut out = Stdout::new();
    let result = certify_with(profile.clone(), &opts);
    // One verdict, built from the checker's own evaluation (what Python's
    // `Verdict` holds too).
    let verdict = Verdict::of(&result, &profile, sensor.as_ref());
    match result {
        Ok(c) => {
            // The evaluation the checker certified with (not a second run).
            let eye = c.eye_safety();
            match a.format {
                Format::Json => out.line(verdict_json(&verdict)?)?,
                Format::Text => {
                    let s = c.summary();
                    out.line(format_args!(
                        "certified: {origin}: {} bins; average power {:.6e} W (angle) / {:.6e} W (time) of budget {:.6e} W ({}); frame period {:.9} s; max |spin accel| {} rad/s²",
                        profile.bins.len(), s.average_power_angle_w, s.average_power_time_w,
                        profile.average_power_w, profile.power_accounting, s.frame_period_s, s.max_spin_accel_rad_s2.map_or("∞ (steps)".to_owned(), |a| format!("{a:.4e}"))
                    ))?;
                    match eye {
                        Some(r) => {
                            out.line(format_args!(
                                "eye safety: Class 1 at every azimuth; worst {:.3}° ({}), {:.1} % of the limit (margin {:.2}×)",
                                r.worst_azimuth_deg, r.binding_rule, 100.0 * r.worst_ratio, r.margin
                            ))?;
                            out.line(head_line(r, &profile))?;
                        }
                        None => out.line("eye safety: NOT evaluated (--no-eye-safety; limits.eye_safety is null): this verdict is not Class 1 evidence")?,
                    }
                }
            }
            out.finish()?;
            if let Some(r) = eye {
                stalled_rotor_warning(r.stalled_rotor_ratio);
            }
            Ok(0)
        }
        Err(rej) => {
            match a.format {
                Format::Json => out.line(verdict_json(&verdict)?)?,
                Format::Text => {
                    // One line per violation; the eye-safety one also names
                    // what was evaluated and the power scale that certifies.
                    let eye = rej.eye_safety.as_deref();
                    for v in &rej.violations {
                        match eye.filter(|_| matches!(v, Violation::EyeSafety { .. })) {
                            Some(r) => out.line(format_args!(
                                "violation: {v}; {}; to certify: scale every bin power by at most {:.6} (the largest uniform power scale at which the {} certifies)",
                                head_line(r, &profile),
                                power_scale_to_certify(r.worst_ratio),
                                if r.head.is_some() { "head" } else { "channel" }
                            ))?,
                            None => out.line(format_args!("violation: {v}"))?,
                        }
                    }
                }
            }
            out.finish()?;
            warn(format_args!(
                "{origin}: rejected, {} violation(s)",
                rej.violations.len()
            ));
            Ok(1)
        }
    }
}
