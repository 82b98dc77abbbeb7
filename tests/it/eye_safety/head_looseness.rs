//! How loose the head bound is on the real heads' presets: for each preset
//! with a head and each of its closed-form profiles (uniform, range,
//! resolution, joint) at a few gazes, the checker's head figure over the
//! figure of the head reference written from the definitions
//! (`head_oracle_defs`: explicit pulses of every channel by forward
//! kinematics, the aperture disc against each beam's cone, C5 over T2,
//! windows up to the time base), at an azimuth × height set of aperture
//! positions: every bin edge and middle of the hottest bins, where channels
//! pass while the head is there and the bound's own worst azimuth, × a
//! height grid plus every height where a channel's footprint touches the
//! aperture's edge.
//!
//! The bound is a sound upper bound, the reference a concrete exposure: the
//! quotient is at least 1 (minus rounding, 1e-12) and, per preset, at most
//! a stated ceiling, so a change that loosens the bound fails here. The
//! table in `specs/eye_safety.md` ("The head", Looseness per preset) is this
//! test's output:
//!
//! ```text
//! cargo test --release --test it eye_safety::head_looseness -- --nocapture
//! # every gaze, more phases, window starts and positions (minutes):
//! GAZE_LIDAR_HEAD_LOOSENESS_LONG=1 cargo test --release --test it \
//!     eye_safety::head_looseness -- --nocapture
//! ```

use crate::head_oracle_defs::{Effort, Interval, OBin, OScan, OWorst, Oracle, Pos};

use gaze_lidar::eye_safety::evaluate_profile;
use gaze_lidar::model::presets::preset;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;
use gaze_lidar::profile::Profile;

/// Per preset: the largest bound/reference quotient this test accepts (the
/// measured largest, rounded up with a few percent of room for the
/// reference's sampling). A tightening lowers these; a loosening fails.
const CEILINGS: [(&str, f64); 3] = [("vls128", 1.3), ("vlp16", 1.15), ("os1-128", 1.37)];

fn long_run() -> bool {
    std::env::var_os("GAZE_LIDAR_HEAD_LOOSENESS_LONG").is_some()
}

fn scan_of(p: &Profile) -> OScan {
    let e = p.limits.eye_safety.as_ref().unwrap();
    OScan {
        bins: p
            .bins
            .iter()
            .map(|b| OBin {
                start_deg: b.start_deg,
                width_deg: b.width_deg,
                power_w: b.power_w,
                w0: b.spin_start_rad_s,
                w1: b.spin_end_rad_s,
            })
            .collect(),
        lambda_nm: e.wavelength_nm,
        pulse_s: e.pulse_duration_s,
    }
}

/// Aperture azimuths: the bound's worst azimuth (± a quarter of the pass),
/// the hottest bins' starts, middles and ends, and where a few channels
/// pass while the head is in the hottest bin.
fn azimuths(o: &Oracle, p: &Profile, worst_deg: f64, long: bool) -> Vec<f64> {
    let pass_deg = (o.aperture_mm + o.head.exit_diameter_mm) / o.head.aperture_distance_mm * 180.0
        / std::f64::consts::PI;
    let mut az = vec![worst_deg];
    for k in [-0.25, 0.25] {
        az.push((worst_deg + k * pass_deg).rem_euclid(360.0));
    }
    let p_max = p.bins.iter().map(|b| b.power_w).fold(0.0, f64::max);
    let hot: Vec<_> = p
        .bins
        .iter()
        .filter(|b| b.power_w >= p_max * (1.0 - 1e-9))
        .collect();
    let pick = if long { hot.len() } else { 1 };
    for k in 0..pick.min(hot.len()) {
        let b = hot[k * hot.len() / pick.min(hot.len())];
        az.push(b.start_deg + 0.5 * b.width_deg);
    }
    let n = o.head.channels.len();
    let chans = if long { 8 } else { 1 };
    let b = hot[hot.len() / 2];
    for k in 0..chans {
        let c = k * n / chans;
        az.push(o.pass_azimuth_deg(c, b.start_deg + 0.5 * b.width_deg));
    }
    az.sort_by(f64::total_cmp);
    az.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    az
}

/// What the footprint's ellipse would give the energy rules at most: the
/// largest (over a 0.01 mm height grid, so a sample) `Σ s_c · chord_c(z) /
/// chord_max` of the channels meeting height `z`, where `chord_c(z)` is the
/// arc chord of channel `c`'s reception ellipse at that height (the set the
/// box holds: centre chord `ρ_c/sqrt(1 − cos²ε_c·sin²β_c)`, shrinking as
/// `sqrt(1 − (Δz/h_c)²)`), against `W_v`, which counts every box whole at
/// the widest pass. A pass figure grows at most linearly with the pass, so
/// `W_v` over this is the most the chords could take off the energy rules.
fn chord_weight(head: &gaze_lidar_core::eye_safety::head::Head, aperture_mm: f64) -> (f64, f64) {
    use gaze_lidar_core::eye_safety::head::geometry::footprints;
    let fps = footprints(head, aperture_mm);
    let half: Vec<(f64, f64, f64, f64)> = fps
        .iter()
        .map(|f| {
            let c = &head.channels[f.index];
            let rho = 0.5 * (aperture_mm + f.width_mm);
            let sin_beta = (1.0 - f.cos_beta * f.cos_beta).max(0.0).sqrt();
            let ux = c.elevation_deg.to_radians().cos() * sin_beta;
            (
                f.z_mm,
                f.half_height_mm,
                rho / (1.0 - ux * ux).sqrt(),
                c.power_scale,
            )
        })
        .collect();
    let c_max = fps.iter().map(|f| f.half_arc_mm).fold(0.0, f64::max);
    let lo = half.iter().map(|h| h.0 - h.1).fold(f64::INFINITY, f64::min);
    let hi = half
        .iter()
        .map(|h| h.0 + h.1)
        .fold(f64::NEG_INFINITY, f64::max);
    let (mut best, mut w_v) = (0.0f64, 0.0f64);
    let n = ((hi - lo) / 0.01).ceil() as usize;
    for k in 0..=n {
        let z = lo + 0.01 * k as f64;
        let (mut s, mut w) = (0.0, 0.0);
        for &(zc, h, c0, sc) in &half {
            let d = (z - zc) / h;
            if d.abs() <= 1.0 {
                s += sc * c0 * (1.0 - d * d).sqrt() / c_max;
                w += sc;
            }
        }
        best = best.max(s);
        w_v = w_v.max(w);
    }
    (best, w_v)
}

/// The reference's worst over `positions`: every position's proxy (one
/// turn and a half at phase 0), then the rules in full on the `top_k`
/// positions of each proxy at `effort.phases` clock phases, on a train
/// complete over T2 and two turns (C5 counted over T2; the time base's
/// windows only in the long run, which takes the oracle's full horizon).
/// Any subset of positions, phases and windows keeps a lower bound.
fn worst(o: &Oracle, positions: &[Pos], effort: &Effort, long: bool) -> OWorst {
    let mut ivs: Vec<(f64, Vec<Vec<Interval>>)> = Vec::new();
    let mut idx = Vec::with_capacity(positions.len());
    for p in positions {
        let k = match ivs.iter().position(|(a, _)| *a == p.azimuth_deg) {
            Some(k) => k,
            None => {
                ivs.push((
                    p.azimuth_deg,
                    o.intervals(p.azimuth_deg, effort.scan_step_deg),
                ));
                ivs.len() - 1
            }
        };
        idx.push(k);
    }
    let clock = std::time::Instant::now();
    let proxies: Vec<[f64; 3]> = positions
        .iter()
        .zip(&idx)
        .map(|(&p, &k)| o.proxy(p, &ivs[k].1))
        .collect();
    let mut chosen: Vec<usize> = Vec::new();
    for key in [0, 1, 2] {
        let mut order: Vec<usize> = (0..positions.len()).collect();
        order.sort_by(|&a, &b| proxies[b][key].total_cmp(&proxies[a][key]));
        chosen.extend(order.into_iter().take(effort.top_k));
    }
    chosen.sort_unstable();
    chosen.dedup();
    if std::env::var_os("HEAD_ORACLE_TIMING").is_some() {
        eprintln!(
            "  proxies of {} positions: {:?}",
            positions.len(),
            clock.elapsed()
        );
    }
    let horizon = if long {
        o.full_horizon_s()
    } else {
        2.0 * o.motion.period_s + gaze_lidar_core::eye_safety::ael::T2_S + 1e-6
    };
    let mut best: Option<OWorst> = None;
    for &pi in &chosen {
        for ph in 0..effort.phases {
            let t0 = (ph as f64 + 0.31) / effort.phases as f64 * o.head.cycle_s;
            let tr = o.train(positions[pi], t0, horizon, &ivs[idx[pi]].1);
            let w = o.evaluate(&tr, positions[pi], t0, effort.starts_max);
            if best.is_none_or(|b| w.ratio > b.ratio) {
                best = Some(w);
            }
        }
    }
    best.expect("at least one position")
}

struct Row {
    preset: &'static str,
    mode: Mode,
    gaze: Option<f64>,
    bound: f64,
    rule: String,
    worst: (f64, f64),
    reference: f64,
    reference_at: String,
}

#[test]
fn head_bound_over_the_reference_per_preset() {
    let long = long_run();
    let gazes: &[f64] = if long { &[0.0, 90.0, 200.0] } else { &[90.0] };
    let effort = if long {
        Effort::default()
    } else {
        Effort {
            phases: 1,
            starts_max: 60,
            scan_step_deg: 0.05,
            top_k: 1,
        }
    };
    let mut rows: Vec<Row> = Vec::new();
    let only = std::env::var("GAZE_LIDAR_HEAD_LOOSENESS_ONLY").ok();
    for (name, ceiling) in CEILINGS {
        let pre = preset(name).unwrap();
        {
            let e = pre.lidar.limits.eye_safety.as_ref().unwrap();
            let band = gaze_lidar_core::eye_safety::ael::Band::of(e.wavelength_nm).unwrap();
            let (chords, w_v) = chord_weight(e.head.as_ref().unwrap(), band.aperture_mm());
            eprintln!(
                "{name}: W_v (sampled) {w_v:.2}, chord-weighted {chords:.2}: the chords could take \
                 the energy rules down by at most {:.3}x",
                w_v / chords
            );
        }
        let modes: &[Mode] = if long {
            &[Mode::Baseline, Mode::Range, Mode::Resolution, Mode::Joint]
        } else {
            &[Mode::Baseline, Mode::Range]
        };
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        for &mode in modes {
            let gz: Vec<Option<f64>> = if mode == Mode::Baseline {
                vec![None]
            } else {
                gazes.iter().map(|&g| Some(g)).collect()
            };
            for gaze in gz {
                let t = std::time::Instant::now();
                // A finite acceleration limit refuses the closed form's
                // spin steps: no profile to measure.
                let Ok(profile) = build_profile(&pre, mode, gaze, 360) else {
                    continue;
                };
                let params = profile.limits.eye_safety.clone().unwrap();
                let head = params.head.clone().expect("a preset with a head");
                let report = evaluate_profile(&profile, &params).unwrap();
                let hf = report.head.clone().unwrap();
                let o = Oracle::new(&head, &scan_of(&profile));
                let heights: Vec<f64> = vec![hf.worst_height_mm, hf.group_height_mm];
                let az = azimuths(&o, &profile, report.worst_azimuth_deg, long);
                let positions: Vec<Pos> = o.positions(&az, &heights);
                let w = worst(&o, &positions, &effort, long);
                let q = report.worst_ratio / w.ratio;
                if std::env::var_os("HEAD_ORACLE_TIMING").is_some() {
                    let mut one = params.clone();
                    one.head = None;
                    let single = evaluate_profile(&profile, &one).unwrap();
                    eprintln!(
                        "  head rule ratios {:?}, window {:.3e} s; single channel {:.5} ({:?}) \
                         rule ratios {:?}, window {:.3e} s; W_v {:.2}, W_inst {:.2}, W_g {:.2}, \
                         W_sim {:.2}, separations {:?}",
                        report.rule_ratios,
                        report.worst_window_s,
                        single.worst_ratio,
                        single.binding_rule,
                        single.rule_ratios,
                        single.worst_window_s,
                        hf.weight_vertical,
                        hf.weight_instant,
                        hf.weight_group,
                        hf.weight_simultaneous,
                        hf.separations
                    );
                }
                eprintln!(
                    "{name} {mode:?} {gaze:?}: bound {:.5} ({:?}) at {:.2}°, {:.2} mm; \
                     reference {w}; bound/reference {q:.4}; {} positions, {:.1} s",
                    report.worst_ratio,
                    report.binding_rule,
                    report.worst_azimuth_deg,
                    hf.worst_height_mm,
                    positions.len(),
                    t.elapsed().as_secs_f64()
                );
                assert!(
                    q >= 1.0 - 1e-12,
                    "{name} {mode:?} {gaze:?}: bound {} below the reference {w}",
                    report.worst_ratio
                );
                assert!(
                    q <= ceiling,
                    "{name} {mode:?} {gaze:?}: bound/reference {q} above the stated ceiling {ceiling}"
                );
                rows.push(Row {
                    preset: name,
                    mode,
                    gaze,
                    bound: report.worst_ratio,
                    rule: format!("{:?}", report.binding_rule),
                    worst: (report.worst_azimuth_deg, hf.worst_height_mm),
                    reference: w.ratio,
                    reference_at: format!(
                        "{} at {:.2}°, {:.2} mm",
                        w.rule, w.pos.azimuth_deg, w.pos.height_mm
                    ),
                });
            }
        }
    }
    println!("| preset | profile | gaze | bound | binding rule | bound's worst (az, h) | reference | reference's worst | bound/reference |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {:?} | {} | {:.4} | {} | {:.1}°, {:.2} mm | {:.4} | {} | {:.3} |",
            r.preset,
            r.mode,
            r.gaze.map_or("—".to_string(), |g| format!("{g}°")),
            r.bound,
            r.rule,
            r.worst.0,
            r.worst.1,
            r.reference,
            r.reference_at,
            r.bound / r.reference
        );
    }
    for (name, _) in CEILINGS {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let qs: Vec<f64> = rows
            .iter()
            .filter(|r| r.preset == name)
            .map(|r| r.bound / r.reference)
            .collect();
        assert!(!qs.is_empty(), "{name}: no closed-form profile measured");
        println!(
            "{name}: bound/reference in [{:.4}, {:.4}] over {} profiles",
            qs.iter().cloned().fold(f64::INFINITY, f64::min),
            qs.iter().cloned().fold(0.0, f64::max),
            qs.len()
        );
    }
}
