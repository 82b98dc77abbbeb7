//! Figures: TTA and density box plots laid out like the paper's figures 3
//! and 4 (one panel per fog level, one box per variant), and a polar view of
//! the four profiles. Each is written as SVG and PNG; text uses the DejaVu
//! Sans font embedded in the binary, so no system fonts are needed.

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

use super::sweep::{figure_stem, short_name, Sweep};
use super::{GridResult, ModelKind, SimConfig};
use crate::model::presets;
use crate::planner::{closed_form, Mode};

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The embedded file is a valid TTF (checked by the plot tests).
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Plotting failed.
#[derive(Debug, thiserror::Error)]
#[error("plot {path}: {message}")]
pub struct PlotError {
    /// File.
    pub path: String,
    /// Cause.
    pub message: String,
}

const COLORS: [RGBColor; 4] = [
    RGBColor(90, 90, 90),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
];

type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// Box plots of `metric` for one model: one panel per fog level.
fn draw_boxes<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    result: &GridResult,
    config: &SimConfig,
    model: ModelKind,
    metric: Metric,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let title = format!(
        "{} — {} ({} model)",
        metric.title(),
        metric.subtitle(),
        model.name()
    );
    let root = root.titled(&title, ("sans-serif", 22))?;
    let panels = root.split_evenly((1, config.fog_pcts.len()));
    // Shared y range over the model so panels compare.
    let all: Vec<f32> = config
        .fog_pcts
        .iter()
        .flat_map(|&f| {
            config
                .variants
                .iter()
                .flat_map(move |v| metric.values(result, model, v.name(), f))
        })
        .collect();
    let (lo, hi) = all
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
    let pad = ((hi - lo) * 0.08).max(0.05);
    let y_range = (lo - pad).max(0.0)..(hi + pad);
    for (panel, &fog) in panels.iter().zip(&config.fog_pcts) {
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("fog {fog} %"), ("sans-serif", 18))
            .margin(8)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                -0.5f32..(config.variants.len() as f32 - 0.5),
                y_range.clone(),
            )?;
        let names: Vec<&str> = config.variants.iter().map(|v| v.name()).collect();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(names.len())
            .x_label_formatter(&|x| {
                let i = x.round();
                if (x - i).abs() < 1e-3 && i >= 0.0 {
                    names
                        .get(i as usize)
                        .map_or(String::new(), |s| (*s).to_owned())
                } else {
                    String::new()
                }
            })
            .y_desc(metric.axis())
            .label_style(("sans-serif", 13))
            .draw()?;
        for (i, v) in config.variants.iter().enumerate() {
            let values = metric.values(result, model, v.name(), fog);
            if values.is_empty() {
                continue;
            }
            let q = Quartiles::new(&values);
            let color = COLORS[i % COLORS.len()];
            chart.draw_series(std::iter::once(
                Boxplot::new_vertical(i as f32, &q)
                    .width(28)
                    .whisker_width(0.5)
                    .style(color),
            ))?;
            // The bootstrap 95 % interval of the median, right of the box.
            if let Some((lo, hi)) = result
                .row(model, v.name(), fog)
                .and_then(|row| metric.interval(&row.stats))
            {
                let x = i as f32 + 0.3;
                let (lo, hi) = (lo as f32, hi as f32);
                let style = BLACK.stroke_width(2);
                chart.draw_series([
                    PathElement::new(vec![(x, lo), (x, hi)], style),
                    PathElement::new(vec![(x - 0.05, lo), (x + 0.05, lo)], style),
                    PathElement::new(vec![(x - 0.05, hi), (x + 0.05, hi)], style),
                ])?;
            }
        }
    }
    Ok(())
}

#[derive(Debug, Clone, Copy)]
enum Metric {
    Tta,
    Density,
}

impl Metric {
    /// The 95 % interval of the cell's median.
    fn interval(self, s: &super::stats::CellStats) -> Option<(f64, f64)> {
        match self {
            Self::Tta => s.tta_ci_lo_s.zip(s.tta_ci_hi_s),
            Self::Density => s.density_ci_lo_pts_per_deg.zip(s.density_ci_hi_pts_per_deg),
        }
    }

    fn title(self) -> &'static str {
        match self {
            Self::Tta => "Time to arrival at detection",
            Self::Density => "Point density in the LiDAR's region of interest",
        }
    }
    fn subtitle(self) -> &'static str {
        match self {
            Self::Tta => "car from the right",
            Self::Density => "accumulated, 64-channel scale",
        }
    }
    fn axis(self) -> &'static str {
        match self {
            Self::Tta => "TTA at detection [s]",
            Self::Density => "points per degree",
        }
    }
    fn values(self, r: &GridResult, model: ModelKind, variant: &str, fog: u32) -> Vec<f32> {
        r.cell(model, variant, fog)
            .filter_map(|t| match self {
                Self::Tta => t.outcome.tta_s[1],
                Self::Density => {
                    Some(t.outcome.density_pts_per_deg_s() * 64.0 * t.outcome.duration_s)
                }
            })
            .map(|x| x as f32)
            .collect()
    }
}

/// Polar view of the paper's four profiles at gaze 90° (forward up, left left).
fn draw_profiles<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(
        "Paper profiles, gaze 90° (left): top view, forward up",
        ("sans-serif", 22),
    )?;
    let panels = root.split_evenly((1, 2));
    let preset = presets::paper();
    let p_mean = preset.lidar.average_power_w;
    let w_mean = preset.lidar.mean_spin_rad_s();
    for (k, panel) in panels.iter().enumerate() {
        let (caption, max_r) = if k == 0 {
            ("power P/P̄", 1.3)
        } else {
            ("spin ω/ω̄ (log scale: 1 + log₅ ratio)", 2.2)
        };
        let mut chart = ChartBuilder::on(panel)
            .caption(caption, ("sans-serif", 18))
            .margin(10)
            .build_cartesian_2d(-max_r..max_r, -max_r..max_r)?;
        for (i, mode) in Mode::ALL.iter().enumerate() {
            let gaze = (*mode != Mode::Baseline).then_some(90.0);
            let c = closed_form(&preset, *mode, gaze, 720)?;
            let pts: Vec<(f64, f64)> = c
                .profile()
                .bins
                .iter()
                .flat_map(|b| [b.start_deg, b.start_deg + b.width_deg].map(|a| (a, b)))
                .map(|(a, b)| {
                    let r = if k == 0 {
                        b.power_w / p_mean
                    } else {
                        1.0 + (b.spin_start_rad_s / w_mean).log(5.0)
                    };
                    let rad = a.to_radians();
                    (-r * rad.sin(), r * rad.cos())
                })
                .collect();
            let color = COLORS[i % COLORS.len()];
            // Wider strokes first, so curves that coincide stay visible.
            let width = 8 - 2 * i as u32;
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(width)))?
                .label(mode.name())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(3))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()?;
    }
    Ok(())
}

/// Draws one figure with `$draw(&root)` into `$stem.svg` and `$stem.png`.
macro_rules! svg_and_png {
    ($dir:expr, $stem:expr, $size:expr, $written:expr, $draw:expr) => {{
        let svg = $dir.join(format!("{}.svg", $stem));
        let png = $dir.join(format!("{}.png", $stem));
        let fail = |path: &Path, e: &dyn std::fmt::Display| PlotError {
            path: path.display().to_string(),
            message: e.to_string(),
        };
        {
            let root = SVGBackend::new(&svg, $size).into_drawing_area();
            $draw(&root).map_err(|e| fail(&svg, &e))?;
            root.present().map_err(|e| fail(&svg, &e))?;
        }
        {
            let root = BitMapBackend::new(&png, $size).into_drawing_area();
            $draw(&root).map_err(|e| fail(&png, &e))?;
            root.present().map_err(|e| fail(&png, &e))?;
        }
        $written.push(svg);
        $written.push(png);
    }};
}

/// The stems of the figures [`write_all`] draws, in order.
fn stems(config: &SimConfig) -> Vec<String> {
    let mut stems = Vec::new();
    for &model in &config.models {
        for stem in ["tta", "density"] {
            stems.push(format!("{stem}_{}", model.name()));
        }
    }
    stems.push("profiles_polar".to_owned());
    stems
}

/// The file names [`write_all`] writes for `config` (an SVG and a PNG per
/// figure), known before the run so a caller can check them up front.
#[must_use]
pub fn file_names(config: &SimConfig) -> Vec<String> {
    stems(config)
        .into_iter()
        .flat_map(|stem| [format!("{stem}.svg"), format!("{stem}.png")])
        .collect()
}

/// Writes every figure into `dir` (created if missing); returns the files
/// (those of [`file_names`], in that order).
pub fn write_all(
    result: &GridResult,
    config: &SimConfig,
    dir: &Path,
) -> Result<Vec<PathBuf>, PlotError> {
    register_font();
    std::fs::create_dir_all(dir).map_err(|e| PlotError {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut written = Vec::new();
    let mut stems = stems(config).into_iter();
    let mut next = || stems.next().unwrap_or_default();
    for &model in &config.models {
        for metric in [Metric::Tta, Metric::Density] {
            let stem = next();
            svg_and_png!(dir, stem, (1200, 460), written, |root| {
                draw_boxes(root, result, config, model, metric)
            });
        }
    }
    let stem = next();
    svg_and_png!(dir, stem, (1000, 520), written, |root| {
        draw_profiles(root)
    });
    debug_assert_eq!(
        written
            .iter()
            .filter_map(|p| p.file_name()?.to_str().map(str::to_owned))
            .collect::<Vec<_>>(),
        file_names(config)
    );
    Ok(written)
}

/// The file names [`write_sweep`] writes (an SVG and a PNG).
#[must_use]
pub fn sweep_file_names(sweep: &Sweep) -> Vec<String> {
    let stem = figure_stem(sweep);
    vec![format!("{stem}.svg"), format!("{stem}.png")]
}

/// One sweep's figure: a panel per (model, fog level), the median TTA of
/// the car from the right per variant against the key's values, each with
/// its bootstrap 95 % interval as an error bar (variants drawn slightly
/// apart along x so the bars stay visible).
fn draw_sweep<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    sweep: &Sweep,
    results: &[GridResult],
    config: &SimConfig,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let title = format!(
        "Sensitivity to {} — median TTA at detection, car from the right (95 % interval)",
        short_name(&sweep.key)
    );
    let root = root.titled(&title, ("sans-serif", 20))?;
    let panels = root.split_evenly((config.models.len(), config.fog_pcts.len()));
    let xs: Vec<f64> = sweep.values.clone();
    let (x_lo, x_hi) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let span = if x_hi > x_lo { x_hi - x_lo } else { 1.0 };
    let x_range = (x_lo - 0.08 * span)..(x_hi + 0.08 * span);
    let dx = 0.012 * span;
    for (m, &model) in config.models.iter().enumerate() {
        // One y range per model so its panels compare.
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for r in results {
            for row in r.rows.iter().filter(|x| x.model == model) {
                for y in [
                    row.stats.tta_ci_lo_s,
                    row.tta_median_s,
                    row.stats.tta_ci_hi_s,
                ]
                .into_iter()
                .flatten()
                {
                    lo = lo.min(y);
                    hi = hi.max(y);
                }
            }
        }
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
        let pad = ((hi - lo) * 0.08).max(0.05);
        let y_range = (lo - pad).max(0.0)..(hi + pad);
        for (f, &fog) in config.fog_pcts.iter().enumerate() {
            let panel = &panels[m * config.fog_pcts.len() + f];
            let mut chart = ChartBuilder::on(panel)
                .caption(
                    format!("{} model, fog {fog} %", model.name()),
                    ("sans-serif", 16),
                )
                .margin(8)
                .x_label_area_size(36)
                .y_label_area_size(56)
                .build_cartesian_2d(x_range.clone(), y_range.clone())?;
            chart
                .configure_mesh()
                .x_desc(short_name(&sweep.key))
                .y_desc("median TTA [s]")
                .label_style(("sans-serif", 12))
                .draw()?;
            let nv = config.variants.len() as f64;
            for (i, v) in config.variants.iter().enumerate() {
                let color = COLORS[i % COLORS.len()];
                let off = (i as f64 - 0.5 * (nv - 1.0)) * dx;
                let points: Vec<(f64, &super::Row)> = xs
                    .iter()
                    .zip(results)
                    .filter_map(|(&x, r)| Some((x + off, r.row(model, v.name(), fog)?)))
                    .collect();
                let line: Vec<(f64, f64)> = points
                    .iter()
                    .filter_map(|(x, row)| Some((*x, row.tta_median_s?)))
                    .collect();
                let series =
                    chart.draw_series(LineSeries::new(line.clone(), color.stroke_width(2)))?;
                if m == 0 && f == 0 {
                    series.label(v.name()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(3))
                    });
                }
                chart.draw_series(line.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
                for (x, row) in &points {
                    if let (Some(a), Some(b)) = (row.stats.tta_ci_lo_s, row.stats.tta_ci_hi_s) {
                        let style = color.stroke_width(1);
                        let w = 0.4 * dx;
                        chart.draw_series([
                            PathElement::new(vec![(*x, a), (*x, b)], style),
                            PathElement::new(vec![(x - w, a), (x + w, a)], style),
                            PathElement::new(vec![(x - w, b), (x + w, b)], style),
                        ])?;
                    }
                }
            }
            if m == 0 && f == 0 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::LowerLeft)
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 12))
                    .draw()?;
            }
        }
    }
    Ok(())
}

/// Writes a sweep's figure into `dir` (created if missing); returns the
/// files (those of [`sweep_file_names`]). `results` holds one grid per
/// value of `sweep`, each run with `config` (but for the swept key).
pub fn write_sweep(
    sweep: &Sweep,
    results: &[GridResult],
    config: &SimConfig,
    dir: &Path,
) -> Result<Vec<PathBuf>, PlotError> {
    register_font();
    std::fs::create_dir_all(dir).map_err(|e| PlotError {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let mut written = Vec::new();
    let stem = figure_stem(sweep);
    let height = 60 + 300 * config.models.len() as u32;
    svg_and_png!(dir, stem, (1200, height), written, |root| {
        draw_sweep(root, sweep, results, config)
    });
    Ok(written)
}
