//! Rendering the results: text table, JSON rows, CSV rows and per-trial CSV.

use serde::Serialize;
use std::fmt::Write;

use super::stats::CellStats;
use super::{GridResult, Row};

/// `4.580:0.620;5.970:0.380` → `4.58: 62%, 5.97: 38%` (the first three).
fn modes_short(modes: &str) -> String {
    if modes.is_empty() {
        return "—".to_owned();
    }
    let parts: Vec<String> = modes
        .split(';')
        .take(3)
        .filter_map(|m| {
            let (t, share) = m.split_once(':')?;
            let t: f64 = t.parse().ok()?;
            let share: f64 = share.parse().ok()?;
            Some(format!("{t:.2}: {:.0}%", share * 100.0))
        })
        .collect();
    let more = modes.split(';').count().saturating_sub(3);
    if more > 0 {
        format!("{} +{more}", parts.join(", "))
    } else {
        parts.join(", ")
    }
}

/// A p-value in 3 significant digits (`—` when absent).
fn pval(p: Option<f64>) -> String {
    match p {
        None => "—".to_owned(),
        Some(p) if p < 1e-4 => format!("{p:.0e}"),
        Some(p) => format!("{p:.3}"),
    }
}

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "—".to_owned(), |v| format!("{v:.2}"))
}

/// The aligned text table (one line per model × variant × fog cell).
#[must_use]
pub fn render_table(r: &GridResult) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<9} {:<11} {:>4} {:>6} {:>8} {:>8} {:>15} {:>11} {:>9} {:>9} {:>9} {:>13} {:<23} {:>7} {:>8} {:>8}",
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
        "hybrid L",
        "TTA 95% CI",
        "TTA modes (s: share)",
        "Δ base",
        "p (W)",
        "p (sign)"
    );
    for row in &r.rows {
        let q = match (row.tta_q1_s, row.tta_q3_s) {
            (Some(a), Some(b)) => format!("{a:.2}–{b:.2}"),
            _ => "—".to_owned(),
        };
        let st = &row.stats;
        let ci = match (st.tta_ci_lo_s, st.tta_ci_hi_s) {
            (Some(a), Some(b)) => format!("{a:.2}–{b:.2}"),
            _ => "—".to_owned(),
        };
        let _ = writeln!(
            s,
            "{:<9} {:<11} {:>4} {:>6} {:>8} {:>8} {:>15} {:>11.0} {:>9} {:>9} {:>9} {:>13} {:<23} {:>7} {:>8} {:>8}",
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
            ci,
            modes_short(&st.tta_modes),
            st.vs_baseline_median_diff_s
                .map_or_else(|| "—".to_owned(), |d| format!("{d:+.2}")),
            pval(st.vs_baseline_wilcoxon_p),
            pval(st.vs_baseline_sign_p),
        );
    }
    let _ = writeln!(
        s,
        "TTA in s for the car from the right (outside the driver's focus); density: RoI points per degree accumulated over the trial, scaled to 64 channels (median)."
    );
    let _ = writeln!(
        s,
        "TTA 95% CI: percentile bootstrap of the median ({} resamples, seeded from --seed); modes: the TTAs split at gaps > {} s; Δ base: median paired TTA difference from the baseline (same model, fog and trials; both detected), p: two-sided Wilcoxon signed-rank and sign tests.",
        super::stats::BOOTSTRAP_RESAMPLES,
        super::stats::MODE_GAP_S
    );
    s
}

/// A row with its uncertainty fields after its own.
#[derive(Serialize)]
struct FullRow<'a> {
    #[serde(flatten)]
    row: &'a Row,
    #[serde(flatten)]
    stats: &'a CellStats,
}

/// `{"rows": [...]}` with a trailing newline; each row carries its
/// [`CellStats`] fields after its own.
pub fn render_json(r: &GridResult) -> Result<String, serde_json::Error> {
    #[derive(Serialize)]
    struct Out<'a> {
        rows: Vec<FullRow<'a>>,
    }
    let rows = r
        .rows
        .iter()
        .map(|row| FullRow {
            row,
            stats: &row.stats,
        })
        .collect();
    let mut s = serde_json::to_string_pretty(&Out { rows })?;
    s.push('\n');
    Ok(s)
}

/// The CSV lines (header first) of `items`.
fn csv_lines<T: Serialize>(items: impl Iterator<Item = T>) -> Result<Vec<String>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for item in items {
        w.serialize(item)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| csv::Error::from(e.into_error()))?;
    Ok(String::from_utf8_lossy(&bytes)
        .lines()
        .map(str::to_owned)
        .collect())
}

/// One CSV row per cell: the row's fields, then its [`CellStats`] fields
/// (no field holds a line break, so the two halves join line by line).
pub fn render_csv(r: &GridResult) -> Result<String, csv::Error> {
    let own = csv_lines(r.rows.iter())?;
    let stats = csv_lines(r.rows.iter().map(|row| &row.stats))?;
    let mut s = String::new();
    for (a, b) in own.iter().zip(&stats) {
        s.push_str(a);
        s.push(',');
        s.push_str(b);
        s.push('\n');
    }
    Ok(s)
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
