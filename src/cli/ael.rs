//! `gaze-lidar ael`: Class 1 accessible emission limits.

use clap::ValueEnum;
use std::fmt::Write as _;

use gaze_lidar::eye_safety::ael_report;
use gaze_lidar::eye_safety::exposure::scan_pass_angle_deg;
use gaze_lidar::text::Num;

use super::args::{finite, finite_positive, rate};
use super::{emit, CliError};

/// Output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// JSON object.
    Json,
    /// Aligned text.
    Table,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Wavelength, nm (700–1050 or 1400–1800).
    #[arg(long, allow_hyphen_values = true)]
    wavelength_nm: f64,
    /// Pulse duration, s.
    #[arg(long, allow_hyphen_values = true)]
    pulse_duration_s: f64,
    /// Pulse rate, Hz: adds the figures for a stationary (stalled) beam.
    #[arg(long, allow_hyphen_values = true)]
    pulse_rate_hz: Option<f64>,
    /// Beam diameter at 100 mm, mm: adds the scan pass angle.
    #[arg(long, allow_hyphen_values = true)]
    beam_diameter_mm: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    finite("--wavelength-nm", a.wavelength_nm)?;
    finite_positive("--pulse-duration-s", a.pulse_duration_s)?;
    if let Some(r) = a.pulse_rate_hz {
        finite_positive("--pulse-rate-hz", r)?;
        // Pulses of this duration at this rate would overlap: not a pulse train.
        if r * a.pulse_duration_s >= 1.0 {
            return Err(CliError::input(format!(
                "--pulse-rate-hz: {r:e} Hz × --pulse-duration-s {:e} s = {:e} >= 1: the pulses would overlap (the period must exceed the pulse duration)",
                a.pulse_duration_s,
                r * a.pulse_duration_s
            )));
        }
        rate("--pulse-rate-hz", r)?;
    }
    if let Some(d) = a.beam_diameter_mm {
        finite_positive("--beam-diameter-mm", d)?;
    }
    let r = ael_report(a.wavelength_nm, a.pulse_duration_s, a.pulse_rate_hz).map_err(|e| {
        let msg = e.to_string();
        if msg.starts_with("wavelength") {
            CliError::input(format!("--wavelength-nm: {msg}"))
        } else {
            CliError::input(format!("--pulse-duration-s: {msg}"))
        }
    })?;
    let pass = match a.beam_diameter_mm {
        Some(d) => {
            let p = scan_pass_angle_deg(r.band, d);
            if p > 360.0 {
                return Err(CliError::input(format!(
                    "--beam-diameter-mm: {} mm gives a scan pass angle of {}° (aperture {} mm + beam, at {} mm), more than a turn (> 360°): the beam cannot be that wide",
                    Num(d),
                    Num(p),
                    Num(r.aperture_diameter_mm),
                    Num(r.aperture_distance_mm)
                )));
            }
            Some(p)
        }
        None => None,
    };
    let mut text = String::new();
    // Writing into a String cannot fail.
    macro_rules! o {
        ($($t:tt)*) => {{
            let _ = writeln!(text, $($t)*);
        }};
    }
    match a.format {
        Format::Json => {
            let mut v = serde_json::to_value(&r).map_err(|e| CliError::input(e.to_string()))?;
            if let (Some(p), Some(obj)) = (pass, v.as_object_mut()) {
                obj.insert("scan_pass_angle_deg".into(), serde_json::json!(p));
            }
            o!("{v}");
        }
        Format::Table => {
            o!(
                "IEC 60825-1:2014 Class 1, small source (C6 = 1), time base {} s",
                r.time_base_s
            );
            o!(
                "wavelength              {} nm ({:?})",
                r.wavelength_nm,
                r.band
            );
            o!("pulse duration          {:e} s", r.pulse_duration_s);
            o!("single-pulse AEL        {:.4e} J", r.single_pulse_ael_j);
            o!("average-power AEL       {:.4e} W", r.average_power_ael_w);
            o!("C4 / C6 / C7            {:.4} / {} / {}", r.c4, r.c6, r.c7);
            o!("T2 / T_i                {} s / {:e} s", r.t2_s, r.t_i_s);
            o!(
                "aperture (Condition 3)  {} mm at {} mm",
                r.aperture_diameter_mm,
                r.aperture_distance_mm
            );
            if let Some(s) = &r.stationary_beam {
                o!("stationary beam         {} Hz: N = {:.0} in T2, C5 = {:.4}, per-pulse AEL {:.4e} J, max mean power {:.4e} W",
                    s.pulse_rate_hz, s.pulses_in_t_max, s.c5, s.per_pulse_ael_j, s.max_average_power_w);
            }
            if let Some(p) = pass {
                o!("scan pass angle         {p:.3}°");
            }
            o!("note: figures from public re-implementations of the 2014 tables; verify against the standard");
        }
    }
    emit(&text)?;
    Ok(0)
}
