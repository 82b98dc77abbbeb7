//! `gaze-lidar ael`: Class 1 accessible emission limits.

use clap::ValueEnum;
use std::fmt::Write as _;

use gaze_lidar::eye_safety::ael_report;
use gaze_lidar::eye_safety::exposure::scan_pass_angle_deg;
use gaze_lidar::eye_safety::head::geometry::Surface;
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

/// The laser the figures are for: the options, else the preset's.
struct Resolved {
    wavelength_nm: f64,
    pulse_duration_s: f64,
    pulse_rate_hz: Option<f64>,
    beam_diameter_mm: Option<f64>,
    format: Format,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Wavelength, nm (700–1050 or 1400–1800).
    #[arg(long, allow_hyphen_values = true, required_unless_present = "preset")]
    wavelength_nm: Option<f64>,
    /// Pulse duration, s.
    #[arg(long, allow_hyphen_values = true, required_unless_present = "preset")]
    pulse_duration_s: Option<f64>,
    /// Take the laser (wavelength, pulse duration, pulse rate, beam) from
    /// this preset's sensor, and show its head: the channels, the optics
    /// and the overlap figures the head's bound multiplies by. Options given
    /// with it replace the preset's values (and then no head is shown).
    #[arg(long)]
    preset: Option<String>,
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
    let sensor = match &a.preset {
        Some(name) => Some(
            gaze_lidar::model::presets::preset(name)
                .map_err(|e| CliError::input(format!("--preset: {e}")))?
                .lidar,
        ),
        None => None,
    };
    let es = sensor.as_ref().and_then(|s| s.limits.eye_safety.clone());
    let given = a.wavelength_nm.is_some()
        || a.pulse_duration_s.is_some()
        || a.pulse_rate_hz.is_some()
        || a.beam_diameter_mm.is_some();
    // Both are required by clap unless --preset is given, and every preset
    // has eye-safety parameters.
    let wavelength_nm = a
        .wavelength_nm
        .or(es.as_ref().map(|e| e.wavelength_nm))
        .unwrap_or(f64::NAN);
    let pulse_duration_s = a
        .pulse_duration_s
        .or(es.as_ref().map(|e| e.pulse_duration_s))
        .unwrap_or(f64::NAN);
    let pulse_rate_hz = a.pulse_rate_hz.or(sensor.as_ref().map(|s| s.pulse_rate_hz));
    let beam_diameter_mm = a
        .beam_diameter_mm
        .or(es.as_ref().map(|e| e.beam_diameter_mm));
    // The head of the preset, with its figures at the preset's fastest spin.
    let head = match (&sensor, &es) {
        (Some(s), Some(params)) if !given => match &params.head {
            Some(h) => {
                let laser = gaze_lidar::eye_safety::exposure::laser(params, s.pulse_rate_hz)
                    .map_err(|e| CliError::input(format!("--preset: {e}")))?;
                // Every surface the verdict covers (the 100 mm cylinder and
                // sphere for a preset's head).
                let surfaces = gaze_lidar::eye_safety::exposure::surfaces(h)
                    .map_err(|e| CliError::input(format!("--preset: {e}")))?;
                let f = surfaces
                    .iter()
                    .map(|(h, surface)| {
                        gaze_lidar::eye_safety::head::bound::head_figures_on(
                            h,
                            *surface,
                            params,
                            &laser,
                            s.limits.spin_rad_s_max,
                        )
                    })
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(|e| CliError::input(format!("--preset: {e}")))?;
                Some((h.clone(), f, s.limits.spin_rad_s_max))
            }
            None => None,
        },
        _ => None,
    };
    let a = &Resolved {
        wavelength_nm,
        pulse_duration_s,
        pulse_rate_hz,
        beam_diameter_mm,
        format: a.format,
    };
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
            if p >= 360.0 {
                return Err(CliError::input(format!(
                    "--beam-diameter-mm: {} mm reaches the aperture at every head angle (aperture {} mm + beam, half of it at least the {} mm distance: a scan pass of 360°): the beam cannot be that wide",
                    Num(d),
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
            if let (Some((h, f, spin)), Some(obj)) = (&head, v.as_object_mut()) {
                obj.insert(
                    "head".into(),
                    serde_json::json!({
                        "description": h, "figures": f.first(), "spin_rad_s_max": spin,
                        "figures_by_surface": f.iter().map(|f| serde_json::json!({
                            "surface": f.surface.name(),
                            "aperture_distance_mm": h.aperture_distance_mm,
                            "figures": f,
                        })).collect::<Vec<_>>(),
                    }),
                );
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
            match &head {
                Some((h, f, spin)) => {
                    o!(
                        "head                    {} channels, cycle {:e} s, crossing point {} mm from the axis, exit beam {} mm, divergence {:.3} mrad, aperture at {} mm",
                        h.channels.len(), h.cycle_s, h.origin_radius_mm, h.exit_diameter_mm, h.divergence_mrad, h.aperture_distance_mm
                    );
                    for f in f {
                        let on = match f.surface {
                            Surface::Cylinder => "cylinder around the spin axis",
                            Surface::Sphere => "sphere around the scan centre",
                        };
                        o!("head on the {on}:");
                        o!(
                            "  overlap               {} channels can meet one height (W_v = {:.3}, worst at {:.2} mm); a grouping window of {:e} s puts {} beam(s) in one position (W_g = {:.3}, W_sim = {:.3}) at up to {:.1} rad/s; stalled: {} beam(s) share one position",
                            f.count_vertical, f.weight_vertical, f.worst_height_mm, f.group_window_s, f.count_group, f.weight_group, f.weight_simultaneous, spin, f.count_stalled
                        );
                        o!(
                            "  pass angle            {:.3}° (the widest of its channels)",
                            f.pass_angle_deg
                        );
                    }
                }
                None if sensor.is_some() && !given => {
                    o!("head                    none: one channel");
                }
                None => {}
            }
            o!("note: figures from public re-implementations of the 2014 tables; verify against the standard");
        }
    }
    emit(&text)?;
    Ok(0)
}
