//! Rendering the results: text table, JSON rows, CSV rows and per-trial CSV.

use serde::Serialize;
use std::fmt::Write;

use super::{GridResult, Row};

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "—".to_owned(), |v| format!("{v:.2}"))
}

/// The aligned text table (one line per model × variant × fog cell).
#[must_use]
pub fn render_table(r: &GridResult) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<9} {:<11} {:>4} {:>6} {:>8} {:>8} {:>15} {:>11} {:>9} {:>9} {:>9}",
        "model",
        "variant",
        "fog%",
        "trials",
        "detected",
        "TTA med",
        "TTA q1–q3",
        "density",
        "left TTA",
        "hybrid R",
        "hybrid L"
    );
    for row in &r.rows {
        let q = match (row.tta_q1_s, row.tta_q3_s) {
            (Some(a), Some(b)) => format!("{a:.2}–{b:.2}"),
            _ => "—".to_owned(),
        };
        let _ = writeln!(
            s,
            "{:<9} {:<11} {:>4} {:>6} {:>8} {:>8} {:>15} {:>11.0} {:>9} {:>9} {:>9}",
            row.model.name(),
            row.variant,
            row.fog_pct,
            row.trials,
            row.detected,
            opt(row.tta_median_s),
            q,
            row.density_median_pts_per_deg,
            opt(row.left_tta_median_s),
            opt(row.hybrid_tta_median_s),
            opt(row.left_hybrid_tta_median_s),
        );
    }
    let _ = writeln!(
        s,
        "TTA in s for the car from the right (outside the driver's focus); density: RoI points per degree accumulated over the trial, scaled to 64 channels (median)."
    );
    s
}

/// `{"rows": [...]}` with a trailing newline.
pub fn render_json(r: &GridResult) -> Result<String, serde_json::Error> {
    #[derive(Serialize)]
    struct Out<'a> {
        rows: &'a [Row],
    }
    let mut s = serde_json::to_string_pretty(&Out { rows: &r.rows })?;
    s.push('\n');
    Ok(s)
}

/// One CSV row per cell.
pub fn render_csv(r: &GridResult) -> Result<String, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in &r.rows {
        w.serialize(row)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| csv::Error::from(e.into_error()))?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// One CSV row per trial.
pub fn render_trials_csv(r: &GridResult) -> Result<String, csv::Error> {
    #[derive(Serialize)]
    struct T<'a> {
        model: &'a str,
        variant: &'a str,
        fog_pct: u32,
        trial: usize,
        tta_right_s: Option<f64>,
        tta_left_s: Option<f64>,
        hybrid_right_s: Option<f64>,
        hybrid_left_s: Option<f64>,
        roi_points: u64,
        roi_pulses: u64,
        duration_s: f64,
        density_pts_per_deg_s: f64,
        fail_safe_frames: u64,
        detected_in_fail_safe: Option<bool>,
        false_alarms: u64,
        early_false_tta_s: Option<f64>,
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    for t in &r.trials {
        let o = &t.outcome;
        w.serialize(T {
            model: t.model.name(),
            variant: t.variant,
            fog_pct: t.fog_pct,
            trial: t.trial,
            tta_right_s: o.tta_s[1],
            tta_left_s: o.tta_s[0],
            hybrid_right_s: o.hybrid_tta_s[1],
            hybrid_left_s: o.hybrid_tta_s[0],
            roi_points: o.roi_points,
            roi_pulses: o.roi_pulses,
            duration_s: o.duration_s,
            density_pts_per_deg_s: o.density_pts_per_deg_s(),
            fail_safe_frames: o.fail_safe_frames,
            detected_in_fail_safe: o.detected_in_fail_safe[1],
            false_alarms: o.false_alarms,
            early_false_tta_s: o.early_false_tta_s,
        })?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| csv::Error::from(e.into_error()))?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}
