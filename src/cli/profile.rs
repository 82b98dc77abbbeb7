//! `gaze-lidar profile`: build a certified profile.

use clap::ValueEnum;
use std::path::PathBuf;

use gaze_lidar::model::lidar::PowerAccounting;
use gaze_lidar::model::presets;
use gaze_lidar::planner::{closed_form, Mode};

use gaze_lidar::firmware::{binary, FirmwareConfig, FirmwareError, FirmwareTable};

use gaze_lidar::checker::CertifiedProfile;
use gaze_lidar::model::angle::{MAX_BINS, MIN_BINS};
use gaze_lidar::model::presets::Preset;
use gaze_lidar::planner::figures;
use gaze_lidar::profile::{RegionFigure, RegionFigures};

use super::args::{finite, finite_positive, int_in};
use super::config::Overrides;
use super::output::Outputs;
use super::CliError;

/// Output format of a profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// `gaze-lidar/profile@1` JSON.
    Json,
    /// One row per bin.
    Csv,
    /// `gaze-lidar/firmware@1` JSON: integer ticks and DAC codes.
    Firmware,
    /// The firmware table's fixed-size binary encoding (needs --out).
    FirmwareBin,
    /// A readable summary: power, frame period, the optimizer's optimality
    /// figures, and the range (m) and points per degree inside and outside
    /// the region of focus (an optimized profile's next to the closed form's).
    Text,
}

/// Accounting override.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Accounting {
    /// Energy per frame / frame period.
    Time,
    /// Eq. 4 as printed: average over angle.
    Angle,
}

#[derive(Debug, clap::Args)]
pub struct Args {
    /// LiDAR preset: paper, vls128, vlp16, os1-128 [default: paper]; with --config, replaces
    /// the file's `[lidar] preset`.
    #[arg(long)]
    preset: Option<String>,
    /// Controller: the paper's closed forms (default range); with --optimize
    /// or --config, the optimizer's objective mode (replaces the file's).
    #[arg(long, value_parser = super::args::named::<Mode>())]
    mode: Option<Mode>,
    /// Derive the profile with the optimizer (HiGHS) instead of the closed form;
    /// with a preset: its paper-equivalent problem (two power levels, two spin set-points).
    #[arg(long)]
    optimize: bool,
    /// Optimizer configuration (TOML); implies --optimize. --preset, --bins,
    /// --accounting and --mode given with it replace the file's values.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Gaze azimuth, degrees CCW from straight ahead (ISO 8855). Omit for the baseline.
    #[arg(long, allow_hyphen_values = true)]
    gaze_deg: Option<f64>,
    /// Number of equal bins (4..=36000; with the optimizer 4..=1440) [default:
    /// 360, or the --config file's]; region boundaries are added as edges.
    #[arg(long, allow_hyphen_values = true)]
    bins: Option<i64>,
    /// Override the preset's (or the --config file's) power accounting.
    #[arg(long, value_enum)]
    accounting: Option<Accounting>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Json)]
    format: Format,
    /// Write to this file (atomically) instead of stdout (`-`: stdout).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Firmware timer frequency, Hz (1..=1e10) [default: 80000000]; firmware formats only.
    #[arg(long, allow_hyphen_values = true)]
    tick_hz: Option<i64>,
    /// Firmware DAC step, W per code (default: power_w_max / 4095); firmware formats only.
    #[arg(long, allow_hyphen_values = true)]
    power_w_per_code: Option<f64>,
    /// With the optimizer: write the final power step's program to
    /// DIR/problem.mps (free MPS) and its exact certificate to
    /// DIR/certificate.json; under objective.kind = "detection" also the
    /// global bound's exact certificate to DIR/detection_bound.json
    /// (created if missing; all files or none).
    #[arg(long, value_name = "DIR")]
    certificate: Option<PathBuf>,
}

pub fn run(a: &Args) -> Result<u8, CliError> {
    // Outputs first: nothing is computed for a path that cannot be written
    // or that would replace the configuration.
    let mut outputs = Outputs::default();
    outputs
        .input_opt("--config", a.config.as_deref())
        .file_opt("--out", a.out.as_deref());
    if let Some(dir) = &a.certificate {
        outputs.folder(
            "--certificate",
            dir,
            &["problem.mps".to_owned(), "certificate.json".to_owned()],
        );
    }
    outputs.check()?;
    let firmware_format = matches!(a.format, Format::Firmware | Format::FirmwareBin);
    for (given, flag) in [
        (a.tick_hz.is_some(), "--tick-hz"),
        (a.power_w_per_code.is_some(), "--power-w-per-code"),
    ] {
        if given && !firmware_format {
            return Err(CliError::input(format!(
                "{flag} applies to --format firmware or firmware-bin only"
            )));
        }
    }
    let tick_hz: u64 = match a.tick_hz {
        Some(t) => int_in("--tick-hz", t, 1, 10_000_000_000_i64)?,
        None => FirmwareConfig::default().tick_hz,
    };
    if let Some(w) = a.power_w_per_code {
        finite_positive("--power-w-per-code", w)?;
    }
    if a.format == Format::FirmwareBin && a.out.is_none() {
        return Err(CliError::input(
            "--format firmware-bin writes binary: give --out FILE",
        ));
    }
    let bins: Option<usize> = match a.bins {
        Some(b) => Some(int_in("--bins", b, MIN_BINS as i64, MAX_BINS as i64)?),
        None => None,
    };
    let preset_name = a.preset.as_deref().unwrap_or("paper");
    let mut preset =
        presets::preset(preset_name).map_err(|e| CliError::input(format!("--preset: {e}")))?;
    let accounting = a.accounting.map(|acc| match acc {
        Accounting::Time => PowerAccounting::Time,
        Accounting::Angle => PowerAccounting::Angle,
    });
    if let Some(acc) = accounting {
        preset.lidar.power_accounting = acc;
    }
    let mode = a.mode.unwrap_or(Mode::Range);
    if a.gaze_deg.is_none() && a.config.is_some() && a.mode.is_none() {
        // The file's mode decides, not the closed forms' default.
        return Err(CliError::input(
            "--gaze-deg is required with --config (the optimizer builds a profile for a gaze)",
        ));
    }
    if a.gaze_deg.is_none() && mode != Mode::Baseline {
        return Err(CliError::input(format!(
            "--gaze-deg is required for --mode {}",
            mode.name()
        )));
    }
    let gaze = if mode == Mode::Baseline {
        None
    } else {
        a.gaze_deg
    };
    if let Some(g) = a.gaze_deg {
        finite("--gaze-deg", g)?;
        gaze_lidar::planner::validate_gaze(g).map_err(|e| CliError::input(format!("--{e}")))?;
    }
    if a.certificate.is_some() && !(a.optimize || a.config.is_some()) {
        return Err(CliError::input(
            "--certificate: only the optimizer (--optimize or --config) solves a program to certify",
        ));
    }
    let mut extra = Vec::new();
    // The sensor, driver model and closed-form levels the figures use.
    let mut basis = Basis {
        preset: preset.clone(),
        mode,
        bins: bins.unwrap_or(360),
        optimized: false,
    };
    // A `detection_bound.json` this run does not write is another
    // problem's: removed once this run's files are in place.
    let mut stale = None;
    let certified = if a.optimize || a.config.is_some() {
        let overrides = Overrides {
            preset: a.preset.as_deref(),
            bins,
            accounting,
            mode: a.mode,
        };
        let (c, cert, b, detection) = optimized(a, &preset, gaze, &overrides)?;
        basis = b;
        if let Some(dir) = &a.certificate {
            extra = certificate_files(dir, cert)?;
            if let Some(json) = detection {
                // Declared once known (a detection objective only); the
                // commit checks it with the rest.
                let path = dir.join("detection_bound.json");
                outputs.file_opt("--certificate", Some(&path));
                extra.push((path, json?.into_bytes()));
            } else {
                stale = Some(dir.join("detection_bound.json"));
            }
        }
        c
    } else {
        closed_form(&preset, mode, gaze, bins.unwrap_or(360)).map_err(|e| match e {
            gaze_lidar::planner::PlanError::InvalidInput { field, reason } => {
                CliError::input(format!("--{field}: {reason}"))
            }
            gaze_lidar::planner::PlanError::Rejected(r) => {
                closed_form_rejected(&r, a, preset_name, mode)
            }
            other => CliError::from(other),
        })?
    };
    let firmware = || {
        let cfg = FirmwareConfig {
            tick_hz,
            power_w_per_code: a.power_w_per_code,
        };
        FirmwareTable::from_certified(&certified, &cfg).map_err(|e| match e {
            FirmwareError::Config {
                field: "power_w_per_code",
                reason,
            } if a.power_w_per_code.is_some() => {
                CliError::input(format!("--power-w-per-code: {reason}"))
            }
            FirmwareError::Config { .. } => CliError::input(format!("firmware: {e}")),
            other => CliError::infeasible(format!("firmware: {other}")),
        })
    };
    let bytes = match a.format {
        Format::Json => certified.profile().to_json()?.into_bytes(),
        Format::Csv => gaze_lidar::profile::to_csv(certified.profile())?.into_bytes(),
        Format::Firmware => firmware()?
            .to_json()
            .map_err(|e| CliError::input(e.to_string()))?
            .into_bytes(),
        Format::FirmwareBin => binary::encode(&firmware()?),
        Format::Text => text_summary(&certified, &basis).into_bytes(),
    };
    for (path, b) in extra {
        outputs.set(&path, b);
    }
    match &a.out {
        Some(path) => outputs.set(path, bytes),
        None => outputs.stdout(bytes),
    }
    outputs.commit()?;
    if let Some(path) = stale {
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(CliError::output(format!(
                    "{}: a previous run's file that this run's certificate does not include: {e}",
                    path.display()
                )));
            }
            _ => {}
        }
    }
    Ok(0)
}

/// A closed form the sensor's limits reject: one line naming the first
/// violated limit, the count of the rest and the command that would work
/// (the optimizer, which meets the limits by construction).
fn closed_form_rejected(
    r: &gaze_lidar::checker::Rejected,
    a: &Args,
    preset: &str,
    mode: Mode,
) -> CliError {
    let first = r
        .violations
        .first()
        .map_or_else(String::new, ToString::to_string);
    let rest = match r.violations.len().saturating_sub(1) {
        0 => String::new(),
        n => format!(" (and {n} more)"),
    };
    let head = format!(
        "the {} closed form on --preset {preset} violates the sensor's limits: {first}{rest}",
        mode.name()
    );
    let Some(gaze) = a.gaze_deg.filter(|_| mode != Mode::Baseline) else {
        return CliError::infeasible(head);
    };
    let mut cmd = format!(
        "gaze-lidar profile --preset {preset} --mode {} --gaze-deg {gaze}",
        mode.name()
    );
    if let Some(b) = a.bins {
        cmd.push_str(&format!(" --bins {b}"));
    }
    if let Some(acc) = a.accounting {
        cmd.push_str(&format!(
            " --accounting {}",
            acc.to_possible_value()
                .map(|v| v.get_name().to_owned())
                .unwrap_or_default()
        ));
    }
    CliError::infeasible(format!(
        "{head}; the optimizer meets them: {cmd} --optimize"
    ))
}

/// `DIR/problem.mps` and `DIR/certificate.json` (the directory is created).
#[cfg(feature = "solver")]
fn certificate_files(
    dir: &std::path::Path,
    cert: Result<
        gaze_lidar::optimizer::certificate::Certified,
        gaze_lidar::optimizer::CertificateError,
    >,
) -> Result<Vec<(PathBuf, Vec<u8>)>, CliError> {
    let cert = cert.map_err(|e| CliError::input(format!("--certificate: {e}")))?;
    let json = serde_json::to_string_pretty(&cert.file())
        .map_err(|e| CliError::output(format!("certificate.json: {e}")))?;
    Ok(vec![
        (dir.join("problem.mps"), cert.mps().into_bytes()),
        (dir.join("certificate.json"), (json + "\n").into_bytes()),
    ])
}

#[cfg(not(feature = "solver"))]
fn certificate_files(
    _dir: &std::path::Path,
    _cert: Result<(), String>,
) -> Result<Vec<(PathBuf, Vec<u8>)>, CliError> {
    Err(CliError::input("--certificate: this build has no solver"))
}

/// The optimizer's answer: the profile, the final step's certificate, the
/// figures' basis and, for a detection objective under `--certificate`,
/// `detection_bound.json`.
#[cfg(feature = "solver")]
type Optimized = (
    CertifiedProfile,
    Result<gaze_lidar::optimizer::certificate::Certified, gaze_lidar::optimizer::CertificateError>,
    Basis,
    Option<Result<String, CliError>>,
);

#[cfg(feature = "solver")]
fn optimized(
    a: &Args,
    preset: &gaze_lidar::model::presets::Preset,
    gaze: Option<f64>,
    overrides: &Overrides<'_>,
) -> Result<Optimized, CliError> {
    use gaze_lidar::optimizer::{optimize_with_certificate, OptError, Problem};
    let err = |e: OptError| {
        if e.is_input_error() {
            CliError::input(e.to_string())
        } else {
            CliError::infeasible(e.to_string())
        }
    };
    let Some(gaze) = gaze else {
        return Err(CliError::input(if a.gaze_deg.is_some() {
            "--optimize and --mode baseline: the baseline has nothing to optimize (use range, resolution or joint)"
        } else {
            "--optimize needs --gaze-deg (the baseline has nothing to optimize)"
        }));
    };
    let (problem, named) = match &a.config {
        Some(path) => super::config::optimizer_problem_and_preset(path, overrides)?,
        None => {
            let bins = super::config::optimizer_bins(overrides.bins.unwrap_or(360))?;
            let mut p = Problem::paper_equivalent(preset, a.mode.unwrap_or(Mode::Range), bins)
                .map_err(err)?;
            if let Some(m) = a.mode {
                p.objective.mode = m;
            }
            if let Some(dropped) = p.drop_forbidden_setpoints() {
                eprintln!(
                    "note: --preset {}: spin_accel_rad_s2_max {} rad/s² forbids spin steps, so the optimizer ramps the spin instead of using the closed form's set-points {dropped:?} rad/s",
                    preset_label(a),
                    p.lidar.limits.spin_accel_rad_s2_max.unwrap_or(f64::INFINITY),
                );
            }
            (p, preset.clone())
        }
    };
    let (c, cert) = optimize_with_certificate(&problem, gaze).map_err(err)?;
    let detection = (a.certificate.is_some()
        && problem.objective.kind == gaze_lidar::optimizer::ObjectiveKind::Detection)
        .then(|| detection_bound_file(&problem, gaze));
    let c = gaze_lidar::optimizer::figures::attach_to_optimum(c, &problem, named.levels.clone());
    let basis = Basis {
        preset: gaze_lidar::optimizer::figures::closed_form_basis(&problem, named.levels),
        mode: problem.objective.mode,
        bins: problem.bins,
        optimized: true,
    };
    Ok((c, cert, basis, detection))
}

/// `detection_bound.json`: the detection bound's certificate, checked
/// exactly before it is written.
#[cfg(feature = "solver")]
fn detection_bound_file(
    problem: &gaze_lidar::optimizer::Problem,
    gaze: f64,
) -> Result<String, CliError> {
    use gaze_lidar::optimizer::global::{check_detection_certificate, detection_certificate};
    let fail = |e: gaze_lidar::optimizer::global::DetectionCertificateError| {
        CliError::infeasible(format!("--certificate: {e}"))
    };
    let cert = detection_certificate(problem, gaze).map_err(fail)?;
    check_detection_certificate(problem, gaze, &cert).map_err(fail)?;
    let json = serde_json::to_string(&cert)
        .map_err(|e| CliError::output(format!("detection_bound.json: {e}")))?;
    Ok(json + "\n")
}

#[cfg(not(feature = "solver"))]
fn optimized(
    _a: &Args,
    _preset: &gaze_lidar::model::presets::Preset,
    _gaze: Option<f64>,
    _overrides: &Overrides<'_>,
) -> Result<
    (
        CertifiedProfile,
        Result<(), String>,
        Basis,
        Option<Result<String, CliError>>,
    ),
    CliError,
> {
    Err(super::config::no_solver("--optimize/--config"))
}

/// What a profile's figures are computed on: the sensor and driver model
/// (and the closed forms' levels) of `preset`, the controller `mode` and
/// the bin count; `optimized` profiles are compared with the closed form.
struct Basis {
    preset: Preset,
    mode: Mode,
    bins: usize,
    optimized: bool,
}

/// The preset's name as given (the default is `paper`).
#[cfg(feature = "solver")]
fn preset_label(a: &Args) -> &str {
    a.preset.as_deref().unwrap_or("paper")
}

/// A gap labelled: absolute, and relative to the upper bound.
fn labelled_gap(gap: f64, upper_bound: f64) -> String {
    if upper_bound.abs() > 0.0 {
        format!(
            "{gap:.3e} absolute ({:.3e} relative to the bound)",
            gap / upper_bound.abs()
        )
    } else {
        format!("{gap:.3e} absolute")
    }
}

/// `--format text`: the checker's figures, the optimizer's optimality
/// figures and the range and point density per region (`planner::figures`).
fn text_summary(c: &CertifiedProfile, basis: &Basis) -> String {
    use std::fmt::Write as _;
    let p = c.profile();
    let s = c.summary();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} bins, gaze {}; average power {:.6e} W (angle) / {:.6e} W (time) of budget {:.6e} W ({}); frame period {:.9} s",
        p.mode.as_deref().unwrap_or("profile"),
        p.bins.len(),
        p.gaze_deg.map_or("none".to_owned(), |g| format!("{g}°")),
        s.average_power_angle_w,
        s.average_power_time_w,
        p.average_power_w,
        p.power_accounting,
        s.frame_period_s,
    );
    if let Some(o) = &p.optimality {
        let _ = write!(
            out,
            "optimality (final power step): objective {:.9} ≤ upper bound {:.9}, gap {}{}",
            o.objective,
            o.upper_bound,
            labelled_gap(o.gap, o.upper_bound),
            if o.exact && o.eye_safety_tightening.is_none() {
                " (proven optimal)"
            } else {
                ""
            }
        );
        if let Some(f) = o.eye_safety_tightening {
            // The answer meets eye-safety limits divided by up to `f`; the
            // upper bound is the user's problem's (the true limits).
            let _ = write!(
                out,
                " (the answer meets eye-safety limits divided by up to {f:.4}; the upper bound is for the true limits)"
            );
        }
        if let Some(g) = &o.global {
            let _ = write!(
                out,
                "; global: objective {:.9} ≤ upper bound {:.9}, gap {}",
                g.objective,
                g.upper_bound,
                labelled_gap(g.gap, g.upper_bound)
            );
        }
        out.push('\n');
    }
    let lidar = &basis.preset.lidar;
    let _ = writeln!(
        out,
        "range on {} % reflectivity in clear air (rated {} m at {:e} W) and points per degree per channel and turn; each the angle-weighted mean [min, max] over the region's bins:",
        100.0 * lidar.reference_reflectivity,
        lidar.rated_range_m,
        lidar.average_power_w,
    );
    let units = if basis.optimized {
        p.optimality
            .as_ref()
            .and_then(|o| o.figures.clone())
            .unwrap_or_else(|| figures::unit_figures(p, &basis.preset, basis.mode, basis.bins))
    } else {
        gaze_lidar::profile::UnitFigures {
            profile: figures::region_figures(p, lidar, &basis.preset.focus),
            closed_form: None,
            closed_form_rejected: None,
        }
    };
    let mut rows: Vec<(&str, &RegionFigures)> = vec![(
        if basis.optimized {
            "optimized"
        } else {
            "this profile"
        },
        &units.profile,
    )];
    let closed_name = format!("closed-form {}", basis.mode.name());
    if let Some(cf) = &units.closed_form {
        rows.push((closed_name.as_str(), cf));
    }
    let cell = |f: Option<&RegionFigure>| match f {
        None => "(empty)".to_owned(),
        Some(f) => format!(
            "range {:.2} m [{:.2}, {:.2}]  {:.4} points/deg [{:.4}, {:.4}]",
            f.range_m.mean,
            f.range_m.min,
            f.range_m.max,
            f.points_per_deg.mean,
            f.points_per_deg.min,
            f.points_per_deg.max
        ),
    };
    for (name, pick) in [
        (
            "RoF",
            (|r: &RegionFigures| r.rof.clone()) as fn(&RegionFigures) -> Option<RegionFigure>,
        ),
        ("RoI", |r: &RegionFigures| r.roi.clone()),
    ] {
        let width = pick(&units.profile).map_or(0.0, |f| f.width_deg);
        let _ = writeln!(out, "  {name} ({width}°):");
        for (label, r) in &rows {
            let _ = writeln!(out, "    {label:<22} {}", cell(pick(r).as_ref()));
        }
    }
    if let Some(why) = &units.closed_form_rejected {
        let _ = writeln!(out, "  no closed form to compare with: {why}");
    }
    out
}
