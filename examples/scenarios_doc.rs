//! Writes `docs/scenarios.md` to stdout: every scenario file under
//! `examples/scenarios/` and `simulate --gaze` on recorded traces and on
//! each named gaze behaviour, with bootstrap intervals, TTA modes and paired
//! tests against the baseline (`sim::stats`).
//! `cargo run --release --example scenarios_doc -- TRIALS` (what
//! `scripts/scenarios.sh` runs).

use std::fmt::Write as _;
use std::path::Path;

use gaze_lidar::gaze::{Format, PipelineConfig};
use gaze_lidar::sim::gaze_drive::{self, Behaviour, GazeDrive, GazeSource, Trace};
use gaze_lidar::sim::{self, stats, GridResult, ModelKind, Scenario, SimConfig, Variant};

const SEED: u64 = 1;

fn fail(message: &str) -> ! {
    eprintln!("scenarios_doc: {message}");
    std::process::exit(2);
}

fn num(x: Option<f64>) -> String {
    x.map_or_else(|| "–".to_owned(), |x| format!("{x:.2}"))
}

/// `median [lo, hi]` of `values` with a bootstrap interval seeded by the cell's label.
fn interval(values: &[f64], label: &str) -> String {
    match stats::bootstrap_median(
        values,
        stats::BOOTSTRAP_RESAMPLES,
        stats::derive_seed(SEED, label),
    ) {
        Some(m) => format!("{:.2} [{:.2}, {:.2}]", m.median, m.lo, m.hi),
        None => "–".to_owned(),
    }
}

/// Modes of a TTA sample: `share × median` per mode.
fn modes(values: &[f64]) -> String {
    let m = stats::modes(values, stats::MODE_GAP_S);
    if m.len() <= 1 {
        return "1".to_owned();
    }
    m.iter()
        .map(|x| format!("{:.0} % at {:.2}", 100.0 * x.share, x.median))
        .collect::<Vec<_>>()
        .join("; ")
}

/// Right-car TTA per trial of one cell, in trial order.
fn tta(r: &GridResult, variant: &str, fog: u32, car: usize) -> Vec<Option<f64>> {
    r.trials
        .iter()
        .filter(|t| t.variant == variant && t.fog_pct == fog)
        .map(|t| t.outcome.tta_s[car])
        .collect()
}

/// Paired comparison with the baseline over trials detected by both.
fn paired(variant: &[Option<f64>], baseline: &[Option<f64>]) -> String {
    let (a, b): (Vec<f64>, Vec<f64>) = variant
        .iter()
        .zip(baseline)
        .filter_map(|(a, b)| Some(((*a)?, (*b)?)))
        .unzip();
    match stats::paired(&a, &b) {
        Some(p) if p.median_difference != 0.0 || p.rank_biserial != 0.0 => format!(
            "{:+.2} s, p = {:.2e}, r = {:+.2}",
            p.median_difference, p.wilcoxon.p_value, p.rank_biserial
        ),
        Some(_) => "identical".to_owned(),
        None => "–".to_owned(),
    }
}

fn flat(v: &[Option<f64>]) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

fn scenario_table(out: &mut String, name: &str, r: &GridResult) {
    out.push_str(
        "| variant | fog % | detected | TTA median [95 % CI], s | modes | vs baseline (Δ median, Wilcoxon p, r) | watched side: detected, TTA [CI] | hybrid TTA, s | false alarms / frame | early false |\n",
    );
    out.push_str("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for row in &r.rows {
        let right = tta(r, row.variant, row.fog_pct, 1);
        let left = tta(r, row.variant, row.fog_pct, 0);
        let base = tta(r, "baseline", row.fog_pct, 1);
        let label = format!("{name}/{}/{}", row.variant, row.fog_pct);
        let _ = writeln!(
            out,
            "| {} | {} | {}/{} | {} | {} | {} | {}, {} | {} | {:.4} | {} |",
            row.variant,
            row.fog_pct,
            row.detected,
            row.trials,
            interval(&flat(&right), &label),
            modes(&flat(&right)),
            if row.variant == "baseline" {
                "–".to_owned()
            } else {
                paired(&right, &base)
            },
            row.left_detected,
            interval(&flat(&left), &format!("{label}/left")),
            num(row.hybrid_tta_median_s),
            row.false_alarms_per_frame,
            row.early_false,
        );
    }
}

fn gaze_table(out: &mut String, name: &str, r: &GridResult) {
    out.push_str(
        "| variant | detected | TTA median [95 % CI], s | modes | vs baseline (Δ median, Wilcoxon p, r) | hybrid TTA, s | fail-safe frames | detected in a fail-safe frame |\n",
    );
    out.push_str("| --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for row in &r.rows {
        let right = tta(r, row.variant, row.fog_pct, 1);
        let base = tta(r, "baseline", row.fog_pct, 1);
        let in_fail_safe = r
            .trials
            .iter()
            .filter(|t| t.variant == row.variant && t.fog_pct == row.fog_pct)
            .filter(|t| t.outcome.detected_in_fail_safe[1] == Some(true))
            .count();
        let _ = writeln!(
            out,
            "| {} | {}/{} | {} | {} | {} | {} | {:.1} % | {} |",
            row.variant,
            row.detected,
            row.trials,
            interval(&flat(&right), &format!("{name}/{}", row.variant)),
            modes(&flat(&right)),
            if row.variant == "baseline" {
                "–".to_owned()
            } else {
                paired(&right, &base)
            },
            num(row.hybrid_tta_median_s),
            100.0 * row.fail_safe_frame_share,
            in_fail_safe,
        );
    }
}

fn main() {
    let trials: usize = match std::env::args().nth(1).map(|s| s.parse()) {
        Some(Ok(n)) if (1..=100_000).contains(&n) => n,
        _ => fail("usage: scenarios_doc TRIALS (1..=100000)"),
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = String::new();
    let _ = write!(
        out,
        "# Scenarios\n\n\
         Generated by `bash scripts/scenarios.sh` ({trials} trials per cell, seed {SEED};\n\
         planar geometry, `physical` return model, first-return detector, the paper's\n\
         four variants); do not edit. TTA: time to arrival at the first detection of\n\
         the mover from the unwatched (right) side, with the median's 95 % percentile\n\
         bootstrap interval ({} resamples, `sim::stats`); *modes*: the TTA sample's\n\
         peaks (cut at gaps > {} s) with their shares, `1` when single-peaked;\n\
         *vs baseline*: the paired difference from the baseline on the same draws\n\
         (trials both detect), Wilcoxon signed-rank p-value and rank-biserial r;\n\
         *hybrid*: the earlier of the driver (inside the region of focus, within\n\
         the fog's visual range) and the LiDAR, median. Each table's command line\n\
         gives the same rows (`--format json` for every column).\n\n",
        stats::BOOTSTRAP_RESAMPLES,
        stats::MODE_GAP_S,
    );
    let dir = root.join("examples/scenarios");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| fail(&format!("{}: {e}", dir.display())))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    for path in &files {
        let name = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| fail(&format!("{name}: {e}")));
        let scenario = Scenario::from_toml(&text, &name).unwrap_or_else(|e| fail(&e.to_string()));
        let config = SimConfig {
            models: vec![ModelKind::Physical],
            variants: Variant::PAPER.to_vec(),
            trials,
            seed: SEED,
            scenario,
            ..SimConfig::default()
        };
        let r = sim::run(&config, &|| {}).unwrap_or_else(|e| fail(&e.to_string()));
        let _ = writeln!(out, "## {name}\n");
        for line in text.lines().filter_map(|l| l.strip_prefix('#')) {
            let line = line.trim();
            if !line.is_empty() && !line.starts_with("`gaze-lidar") {
                let _ = writeln!(out, "{line}");
            }
        }
        let _ = writeln!(
            out,
            "\n`gaze-lidar simulate --scenario examples/scenarios/{name}.toml --model physical --trials {trials} --seed {SEED}`\n"
        );
        scenario_table(&mut out, &name, &r);
        out.push('\n');
    }
    out.push_str(
        "## Gaze behaviour from the stream\n\n\
         The sensor's profile is planned frame by frame from the gaze, through\n\
         `stream`'s filter and fail-safe (defaults: 100 ms timeout, 4 samples to\n\
         recover, 30 °/s saccade threshold); each frame runs the profile decided at\n\
         the latest frame start at or before its own start. The gaze starts 1 s\n\
         before the trial; the named behaviours are sampled at 200 Hz with saccades\n\
         at 400 °/s (assumed) and a per-trial phase from the seed; a recorded trace\n\
         repeats end to end from a per-trial starting point. The driver sees nothing\n\
         during a blink. Paper scene, clear air; *fail-safe frames*: the share of\n\
         frames that ran the uniform baseline because the gaze was lost or stale.\n\n",
    );
    let config = SimConfig {
        models: vec![ModelKind::Physical],
        variants: Variant::PAPER.to_vec(),
        fog_pcts: vec![0],
        trials,
        seed: SEED,
        ..SimConfig::default()
    };
    let mut sources: Vec<(String, GazeSource)> = Vec::new();
    for spec in [
        "fixate",
        "scan",
        "mirror",
        "blink",
        "blink:every_s=1,blink_s=0.5",
    ] {
        let b = Behaviour::parse(spec, config.scenario.gaze_deg).unwrap_or_else(|e| fail(&e));
        sources.push((format!("--gaze-behaviour {spec}"), GazeSource::Behaviour(b)));
    }
    for (file, format, fmt_name) in [
        ("right.csv", Format::Csv, "csv"),
        ("varjo_base.csv", Format::Varjo, "varjo"),
        ("neon_gaze.csv", Format::Neon, "neon"),
    ] {
        let rel = format!("tests/data/gaze/{file}");
        let text = std::fs::read_to_string(root.join(&rel))
            .unwrap_or_else(|e| fail(&format!("{rel}: {e}")));
        let trace = Trace::parse(&text, format, &rel).unwrap_or_else(|e| fail(&e.to_string()));
        sources.push((
            format!("--gaze {rel} --gaze-format {fmt_name}"),
            GazeSource::Trace(trace),
        ));
    }
    for (args, source) in sources {
        let drive = GazeDrive {
            source,
            pipeline: PipelineConfig::default(),
        };
        let r = gaze_drive::run(&config, &drive, &|| {}).unwrap_or_else(|e| fail(&e.to_string()));
        let _ = writeln!(
            out,
            "### `{args}`\n\n`gaze-lidar simulate {args} --fog 0 --trials {trials} --seed {SEED}`\n"
        );
        gaze_table(&mut out, &args, &r);
        out.push('\n');
    }
    print!("{out}");
}
