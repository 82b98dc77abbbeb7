//! Units people use: every optimized profile reports the
//! range (m) and the points per degree inside the region of focus and
//! outside it, next to the paper's closed form's, in profile@1's
//! `optimality.figures` and in `profile --format text`. Checked here from
//! the outside: each figure is recomputed from the written bins by a plain
//! reference (a bisection on the range equation's signal, the dwell from
//! the constant-acceleration formula by hand, the region from the bin's
//! label), and the closed form's from the closed-form profile itself.
#![cfg(feature = "solver")]

use crate::common;

use common::{run, stderr, stdout};
use gaze_lidar::model::presets::Preset;
use gaze_lidar::model::range::RangeEquation;
use gaze_lidar::optimizer::OptimizerConfig;
use gaze_lidar::planner::closed_form;
use gaze_lidar::profile::{Profile, Region, RegionFigure, RegionFigures, UnitFigures};

const CONFIGS: [&str; 4] = ["paper", "multi_level", "smooth", "vls128_eye"];

fn config_path(name: &str) -> String {
    format!(
        "{}/examples/configs/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// Reference range: the largest `R` with signal `S(R) ≥ 1` (reference
/// reflectivity, clear air), by plain bisection on the model's signal.
fn reference_range_m(eq: &RangeEquation, power_ratio: f64) -> f64 {
    let ok = |r: f64| {
        eq.signal(
            1.0,
            power_ratio,
            eq.reference_reflectivity,
            1.0,
            r,
            eq.extinction_factor(eq.clear_extinction_per_m, r),
        ) >= 1.0
    };
    let (mut lo, mut hi) = (1e-6, 1e6);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Reference figures of `p`'s bins labelled `region`.
fn reference(
    p: &Profile,
    eq: &RangeEquation,
    average_power_w: f64,
    region: Region,
) -> RegionFigure {
    let mut width = 0.0;
    let (mut r_sum, mut r_min, mut r_max) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
    let (mut d_sum, mut d_min, mut d_max) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
    for b in p.bins.iter().filter(|b| b.region == Some(region)) {
        let r = reference_range_m(eq, b.power_w / average_power_w);
        // Constant angular acceleration: dwell = 2Δθ/(ω_start + ω_end).
        let dwell = 2.0 * b.width_deg.to_radians() / (b.spin_start_rad_s + b.spin_end_rad_s);
        let d = p.pulse_rate_hz * dwell / b.width_deg;
        width += b.width_deg;
        r_sum += b.width_deg * r;
        d_sum += b.width_deg * d;
        (r_min, r_max) = (r_min.min(r), r_max.max(r));
        (d_min, d_max) = (d_min.min(d), d_max.max(d));
    }
    let agg = |sum: f64, min, max| gaze_lidar::profile::Aggregate {
        mean: sum / width,
        min,
        max,
    };
    RegionFigure {
        width_deg: width,
        range_m: agg(r_sum, r_min, r_max),
        points_per_deg: agg(d_sum, d_min, d_max),
    }
}

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-9 * b.abs().max(1.0),
        "{what}: {a} vs reference {b}"
    );
}

fn same(got: &RegionFigure, want: &RegionFigure, what: &str) {
    close(got.width_deg, want.width_deg, &format!("{what} width"));
    for (g, w, k) in [
        (got.range_m, want.range_m, "range_m"),
        (got.points_per_deg, want.points_per_deg, "points_per_deg"),
    ] {
        close(g.mean, w.mean, &format!("{what} {k} mean"));
        close(g.min, w.min, &format!("{what} {k} min"));
        close(g.max, w.max, &format!("{what} {k} max"));
    }
}

fn same_regions(got: &RegionFigures, p: &Profile, eq: &RangeEquation, pbar: f64, what: &str) {
    same(
        got.rof.as_ref().expect("a region of focus"),
        &reference(p, eq, pbar, Region::Rof),
        &format!("{what} RoF"),
    );
    same(
        got.roi.as_ref().expect("a region of interest"),
        &reference(p, eq, pbar, Region::Roi),
        &format!("{what} RoI"),
    );
}

#[test]
fn shipped_configs_report_range_and_density_per_region_next_to_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    for name in CONFIGS {
        let out = dir.path().join(format!("{name}.json"));
        let o = run(
            &[
                "profile",
                "--config",
                &config_path(name),
                "--gaze-deg",
                "90",
                "--out",
                out.to_str().unwrap(),
            ],
            None,
        );
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        let p = Profile::from_json(&text, name).unwrap();
        let fig: UnitFigures = p
            .optimality
            .as_ref()
            .and_then(|o| o.figures.clone())
            .unwrap_or_else(|| panic!("{name}: no optimality.figures"));
        let config = OptimizerConfig::read(std::path::Path::new(&config_path(name))).unwrap();
        let problem = config.problem().unwrap();
        let lidar = &problem.lidar;
        let eq = RangeEquation::rated(lidar.rated_range_m, lidar.reference_reflectivity);
        // The split: the labels the optimizer wrote are the focus model's
        // region at each bin's centre, and the figures use the same bins.
        let rof = problem.focus.regions(90.0).rof;
        for b in &p.bins {
            let inside = rof.contains(b.start_deg + 0.5 * b.width_deg);
            assert_eq!(b.region == Some(Region::Rof), inside, "{name}: {b:?}");
        }
        same_regions(&fig.profile, &p, &eq, lidar.average_power_w, name);
        let (f_rof, f_roi) = (
            fig.profile.rof.as_ref().unwrap(),
            fig.profile.roi.as_ref().unwrap(),
        );
        assert_eq!(f_rof.width_deg + f_roi.width_deg, 360.0, "{name}");
        // By centre, each boundary moves the width by at most half a bin.
        let widest = p.bins.iter().map(|b| b.width_deg).fold(0.0, f64::max);
        assert!(
            (f_rof.width_deg - rof.measure_deg()).abs() <= widest,
            "{name}: RoF {} ° against the focus model's {} °",
            f_rof.width_deg,
            rof.measure_deg()
        );
        // The closed form of the same mode on the same sensor and driver.
        let preset = Preset {
            lidar: lidar.clone(),
            focus: problem.focus.clone(),
            levels: config.preset().unwrap().levels,
        };
        match closed_form(&preset, problem.objective.mode, Some(90.0), problem.bins) {
            Ok(c) => {
                assert!(fig.closed_form_rejected.is_none(), "{name}");
                let cf = fig.closed_form.as_ref().expect("closed-form figures");
                same_regions(
                    cf,
                    c.profile(),
                    &eq,
                    lidar.average_power_w,
                    &format!("{name} closed form"),
                );
            }
            Err(e) => {
                assert!(fig.closed_form.is_none(), "{name}");
                let why = fig.closed_form_rejected.as_deref().expect("a reason");
                assert!(why.contains(&e.to_string()), "{name}: {why}");
            }
        }
        eprintln!(
            "{name}: RoF range {:.2} m ({:.2}–{:.2}), {:.4} points/deg; RoI range {:.2} m ({:.2}–{:.2}), {:.4} points/deg; closed form RoF/RoI {}",
            f_rof.range_m.mean, f_rof.range_m.min, f_rof.range_m.max, f_rof.points_per_deg.mean,
            f_roi.range_m.mean, f_roi.range_m.min, f_roi.range_m.max, f_roi.points_per_deg.mean,
            fig.closed_form.as_ref().map_or("rejected".to_owned(), |c| format!(
                "{:.2} m {:.4}/deg, {:.2} m {:.4}/deg",
                c.rof.as_ref().unwrap().range_m.mean, c.rof.as_ref().unwrap().points_per_deg.mean,
                c.roi.as_ref().unwrap().range_m.mean, c.roi.as_ref().unwrap().points_per_deg.mean
            ))
        );
        // The checker accepts the file with its figures.
        let o = run(&["check", out.to_str().unwrap()], None);
        assert!(o.status.success(), "{name}: check: {}", stderr(&o));
    }
}

/// `profile --config examples/configs/paper.toml --gaze-deg 90`'s JSON.
fn paper_optimum_json() -> String {
    let o = run(
        &[
            "profile",
            "--config",
            &config_path("paper"),
            "--gaze-deg",
            "90",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    stdout(&o)
}

#[test]
fn the_paper_problem_reads_as_its_closed_form() {
    // paper.toml's optimum is the closed form (its comment): so are its
    // figures — 0.5 P̄ and ω_high in the RoF, 1.1 P̄ and ω_low outside.
    let p = Profile::from_json(&paper_optimum_json(), "paper").unwrap();
    let fig = p.optimality.unwrap().figures.unwrap();
    let cf = fig.closed_form.unwrap();
    for (a, b, what) in [
        (&fig.profile.rof, &cf.rof, "RoF"),
        (&fig.profile.roi, &cf.roi, "RoI"),
    ] {
        same(a.as_ref().unwrap(), b.as_ref().unwrap(), what);
    }
    // By hand: 71.02 m at 0.5 P̄ and 104.81 m at 1.1 P̄ (model::range's
    // tests); ω_low = 2π·20·(60/5.4 + 300)/360 rad/s = 108.598 rad/s
    // = 6222.2 °/s, so 7812.5/6222.2 = 1.2556 points/deg outside and
    // 5.4 times fewer, 0.2325, inside.
    let rof = fig.profile.rof.unwrap();
    let roi = fig.profile.roi.unwrap();
    assert!(
        (rof.range_m.mean - 71.018).abs() < 1e-3,
        "{}",
        rof.range_m.mean
    );
    assert!(
        (roi.range_m.mean - 104.805).abs() < 1e-3,
        "{}",
        roi.range_m.mean
    );
    assert!((roi.points_per_deg.mean - 1.25558).abs() < 1e-4);
    assert!((rof.points_per_deg.mean - 1.25558 / 5.4).abs() < 1e-4);
}

#[test]
fn profile_files_with_and_without_figures_read_back() {
    let text = paper_optimum_json();
    let p = Profile::from_json(&text, "new").unwrap();
    assert_eq!(p.to_json().unwrap(), text, "round trip");
    // An older file: no `figures` in its optimality block.
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["optimality"]
        .as_object_mut()
        .unwrap()
        .remove("figures")
        .unwrap();
    let old = Profile::from_json(&v.to_string(), "old").unwrap();
    assert!(old.optimality.unwrap().figures.is_none());
    // Unknown keys inside the block are named, and the informational block
    // is dropped (the profile itself reads; `check` warns with the note).
    let mut w: serde_json::Value = serde_json::from_str(&text).unwrap();
    w["optimality"]["figures"]["profile"]["rof"]["range_ft"] = 1.into();
    let (p, notes) = Profile::from_json_with_notes(&w.to_string(), "bad").unwrap();
    assert!(p.optimality.is_none());
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].starts_with("optimality: not read"), "{notes:?}");
    assert!(notes[0].contains("range_ft"), "{notes:?}");
    // A field outside the informational blocks that does not read is still
    // the error, with its line and column.
    w["bins"][0]["power_w"] = "high".into();
    let e = Profile::from_json(&w.to_string(), "bad").unwrap_err();
    assert!(
        e.to_string().contains("invalid type: string \"high\""),
        "{e}"
    );
    assert!(e.to_string().starts_with("bad:1:"), "{e}");
}

#[test]
fn text_format_shows_both_regions_next_to_the_closed_form() {
    let o = run(
        &[
            "profile",
            "--config",
            &config_path("vls128_eye"),
            "--gaze-deg",
            "90",
            "--format",
            "text",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let t = stdout(&o);
    for needle in [
        "RoF (60°)",
        "RoI (300°)",
        "optimized ",
        "closed-form range ",
        "points/deg",
        "rated 245 m",
        "optimality (final power step)",
    ] {
        assert!(t.contains(needle), "missing {needle:?} in:\n{t}");
    }
    // The closed form's RoF line: 0.5 P̄ on the 245 m rating is 175.07 m.
    assert!(t.contains("range 175.07 m [175.07, 175.07]"), "{t}");
    // A closed-form profile reads its own figures, with nothing to compare.
    let o = run(
        &[
            "profile",
            "--mode",
            "range",
            "--gaze-deg",
            "90",
            "--format",
            "text",
        ],
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let t = stdout(&o);
    assert!(
        t.contains("this profile           range 71.02 m [71.02, 71.02]"),
        "{t}"
    );
    assert!(
        t.contains("this profile           range 104.81 m [104.81, 104.81]"),
        "{t}"
    );
    assert!(
        !t.contains("optimality") && !t.contains("closed-form range "),
        "{t}"
    );
}
