//! The optimizer on a random family of configurations generated from a
//! seed (`specs/optimizer.md`, "The random family"): presets, acuity
//! models, hardware power levels, spin set-points, slew and acceleration
//! limits, both power accountings, every mode, 36–720 bins. Every request
//! runs the real binary with `--certificate`; every answer must be
//! certified (the checker accepts the profile, which carries an
//! `optimality` block) and its exported certificate must check exactly
//! (`problem.mps` read by the tests' own reader, `certificate.json`
//! recomputed in rationals); every refusal must be exit 1 with one line,
//! and a set-point request whose set-points cannot make one turn take the
//! frame period (decided here by plain enumeration) must say so.
//!
//! `cargo test --release --test optimizer_family` runs a 10-member subset;
//! `GAZE_LIDAR_FAMILY=all` runs all 70 (`GAZE_LIDAR_FAMILY_SEED` changes
//! the seed). Each request's CPU time (the child's user + system time) and
//! wall time are printed. The test asserts every request's CPU time
//! within 2 s times a slack factor for a loaded machine
//! (`GAZE_LIDAR_FAMILY_CPU_SLACK`, default 1.5: on a shared 2-core machine
//! the same request's CPU time varied 1.5× between runs at load 1.5 and
//! 16, cache and frequency contention), every certificate's relative gap within 1 %
//! (`GAZE_LIDAR_FAMILY_MAX_GAP`, default 0.01), and a generous wall bound
//! (`GAZE_LIDAR_FAMILY_MAX_WALL_S`, default 20 s).
//! `GAZE_LIDAR_FAMILY_ONLY=K` runs member `K` alone and prints its file.
//! `GAZE_LIDAR_FAMILY_BIN=PATH` runs another build of the binary instead
//! (a baseline in the same run).
#![cfg(feature = "solver")]

use crate::common;
use crate::mps;

use common::{run, stderr};
use gaze_lidar::model::presets;
use mps::{exact_figures, parse_rational, q, read_mps};
use num_traits::Signed;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::time::Instant;

const MEMBERS: usize = 70;
const DEFAULT_SEED: u64 = 30;

/// One generated request.
#[derive(Debug, Clone)]
struct Member {
    index: usize,
    toml: String,
    gaze_deg: f64,
    bins: usize,
    mode: &'static str,
    milp: bool,
    /// Spin set-points given and the mode moves the spin.
    setpoints: Option<Vec<f64>>,
    frame_rate_hz: f64,
    summary: String,
}

fn pick<'a, T>(rng: &mut ChaCha8Rng, xs: &'a [T]) -> &'a T {
    &xs[rng.random_range(0..xs.len())]
}

/// The acuity model and threshold, as a `[focus]` section.
fn focus(rng: &mut ChaCha8Rng) -> (String, &'static str) {
    match rng.random_range(0..3) {
        0 => (
            format!(
                "[focus]\nthreshold = 0.5\nacuity = {{ model = \"box\", half_width_deg = {:.1} }}\n",
                rng.random_range(15.0..45.0)
            ),
            "box",
        ),
        1 => (
            format!(
                "[focus]\nthreshold = {:.4}\nacuity = {{ model = \"levi_e2\", e2_deg = {:.2} }}\n",
                rng.random_range(0.05..0.2),
                rng.random_range(2.0..4.0)
            ),
            "levi_e2",
        ),
        _ => (
            format!(
                "[focus]\nthreshold = {:.3}\nacuity = {{ model = \"gaussian\", sigma_deg = {:.1} }}\n",
                rng.random_range(0.1..0.6),
                rng.random_range(5.0..25.0)
            ),
            "gaussian",
        ),
    }
}

/// Spin set-points inside the limits: half of them reach the frame period
/// by construction (the low set-point solved from the high one and a
/// count), half drawn freely.
fn setpoints(rng: &mut ChaCha8Rng, n: usize, f_hz: f64, w_lo: f64, w_hi: f64) -> Vec<f64> {
    let mean = std::f64::consts::TAU * f_hz;
    if rng.random_bool(0.5) {
        let th = std::f64::consts::TAU / n as f64;
        let period = 1.0 / f_hz;
        for _ in 0..20 {
            let high = rng.random_range(mean * 1.2..(mean * 4.0).min(w_hi));
            let n_low = rng.random_range(1..n);
            let rest = period - (n - n_low) as f64 * th / high;
            let low = n_low as f64 * th / rest;
            if rest > 0.0 && low >= w_lo && low < mean {
                return vec![low, high];
            }
        }
    }
    let k = rng.random_range(2..=3);
    let mut w: Vec<f64> = (0..k)
        .map(|_| rng.random_range(w_lo.max(mean * 0.3)..w_hi.min(mean * 4.0)))
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

fn member(rng: &mut ChaCha8Rng, index: usize) -> Member {
    let preset_name = *pick(rng, &["paper", "paper", "vls128", "vlp16", "os1-128"]);
    let preset = presets::preset(preset_name).unwrap();
    let lid = &preset.lidar;
    let p_mean = lid.average_power_w;
    let bins = *pick(rng, &[36, 72, 90, 120, 180, 360, 360, 720, 720]);
    let mode = *pick(rng, &["range", "resolution", "joint"]);
    let accounting = *pick(rng, &["angle", "time"]);
    let mut toml = String::new();
    let mut summary = format!("{preset_name} {mode} {accounting} {bins} bins");
    writeln!(toml, "bins = {bins}\n\n[lidar]\npreset = \"{preset_name}\"\npower_accounting = \"{accounting}\"\n").unwrap();
    // Limits: the power box around P̄, spin limits, slew, acceleration.
    let floor = p_mean * rng.random_range(0.0..0.4);
    let ceiling = p_mean * rng.random_range(1.1..1.5);
    let (w_lo, w_hi) = (lid.limits.spin_rad_s_min, lid.limits.spin_rad_s_max);
    let slew = rng
        .random_bool(0.4)
        .then(|| p_mean * rng.random_range(0.002..0.05));
    let accel = rng
        .random_bool(0.4)
        .then(|| *pick(rng, &[100.0, 300.0, 1000.0, 3000.0]));
    writeln!(
        toml,
        "[limits]\npower_w_min = {floor:e}\npower_w_max = {ceiling:e}"
    )
    .unwrap();
    match slew {
        Some(s) => writeln!(toml, "power_slew_w_per_deg_max = {s:e}").unwrap(),
        None => writeln!(toml, "power_slew_w_per_deg_max = \"unlimited\"").unwrap(),
    }
    match accel {
        Some(a) => writeln!(toml, "spin_accel_rad_s2_max = {a:e}").unwrap(),
        None => writeln!(toml, "spin_accel_rad_s2_max = \"unlimited\"").unwrap(),
    }
    toml.push('\n');
    let (focus, acuity) = focus(rng);
    toml.push_str(&focus);
    summary += &format!(" {acuity}");
    if slew.is_some() {
        summary += " slew";
    }
    if let Some(a) = accel {
        summary += &format!(" accel {a}");
    }
    // Hardware power levels (a MILP), spin set-points (only without an
    // acceleration limit: steps).
    let mut levels = String::new();
    let milp = rng.random_bool(0.4);
    if milp {
        let k = rng.random_range(2..=6);
        let low = p_mean * rng.random_range(0.3..0.9);
        let mut lv: Vec<f64> = (0..k)
            .map(|_| p_mean * rng.random_range(0.2..1.3))
            .chain([low])
            .collect();
        lv.sort_by(f64::total_cmp);
        writeln!(levels, "power_w = {:?}", lv).unwrap();
        summary += &format!(" {} levels", lv.len());
    }
    let moves_spin = mode != "range";
    let sp = (accel.is_none() && rng.random_bool(0.3))
        .then(|| setpoints(rng, bins, lid.frame_rate_hz, w_lo, w_hi));
    if let Some(w) = &sp {
        writeln!(levels, "spin_rad_s = {w:?}").unwrap();
        summary += &format!(" {} set-points", w.len());
    }
    if !levels.is_empty() {
        toml.push_str("\n[levels]\n");
        toml.push_str(&levels);
    }
    let kind = if rng.random_bool(0.15) {
        "detection"
    } else {
        "sqrt"
    };
    writeln!(
        toml,
        "\n[objective]\nmode = \"{mode}\"\nrange_weight = 1.0\nresolution_weight = {:.3}\nkind = \"{kind}\"",
        rng.random_range(0.2..1.5)
    )
    .unwrap();
    if rng.random_bool(0.2) {
        writeln!(
            toml,
            "priors = [{{ start_deg = {:.1}, width_deg = 40.0, weight = 0.5 }}]",
            rng.random_range(0.0..360.0)
        )
        .unwrap();
        summary += " priors";
    }
    summary += &format!(" {kind}");
    Member {
        index,
        toml,
        gaze_deg: (rng.random_range(0.0..360.0f64) * 100.0).round() / 100.0,
        bins,
        mode,
        milp,
        setpoints: sp.filter(|_| moves_spin),
        frame_rate_hz: lid.frame_rate_hz,
        summary,
    }
}

fn family(seed: u64) -> Vec<Member> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..MEMBERS).map(|i| member(&mut rng, i)).collect()
}

/// The smallest relative mismatch `|Σ t − T|/T` over every assignment of
/// the set-points to the `n` equal bins (plain enumeration of the counts).
fn best_frame_mismatch(w: &[f64], n: usize, frame_rate_hz: f64) -> f64 {
    let th = std::f64::consts::TAU / n as f64;
    let period = 1.0 / frame_rate_hz;
    let mut best = f64::INFINITY;
    let mut counts = vec![0usize; w.len()];
    fn go(k: usize, left: usize, counts: &mut [usize], f: &mut dyn FnMut(&[usize])) {
        if k + 1 == counts.len() {
            counts[k] = left;
            f(counts);
            return;
        }
        for c in 0..=left {
            counts[k] = c;
            go(k + 1, left - c, counts, f);
        }
    }
    go(0, n, &mut counts, &mut |c: &[usize]| {
        let t: f64 = c.iter().zip(w).map(|(&m, &wk)| m as f64 * th / wk).sum();
        best = best.min((t - period).abs() / period);
    });
    best
}

/// The child processes' CPU time so far (user + system), s.
fn children_cpu_s() -> f64 {
    // SAFETY: getrusage writes into the struct we own.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

/// The binary under test, or `GAZE_LIDAR_FAMILY_BIN` (another build of
/// it, to compare in the same run).
fn run_profile(args: &[&str]) -> std::process::Output {
    match std::env::var("GAZE_LIDAR_FAMILY_BIN") {
        Ok(bin) => std::process::Command::new(bin)
            .args(args)
            .stdin(std::process::Stdio::null())
            .output()
            .expect("run GAZE_LIDAR_FAMILY_BIN"),
        Err(_) => run(args, None),
    }
}

/// What one request gave.
enum Outcome {
    Certified { gap: f64, objective: f64 },
    Infeasible(String),
}

/// Runs one member; `Err` names what is wrong.
fn run_member(m: &Member) -> Result<(Outcome, f64, f64), String> {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("c.toml");
    std::fs::write(&config, &m.toml).unwrap();
    let cert_dir = dir.path().join("cert");
    let out = dir.path().join("profile.json");
    let gaze = m.gaze_deg.to_string();
    let cpu0 = children_cpu_s();
    let t0 = Instant::now();
    let o = run_profile(&[
        "profile",
        "--config",
        config.to_str().unwrap(),
        "--gaze-deg",
        &gaze,
        "--certificate",
        cert_dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let wall = t0.elapsed().as_secs_f64();
    let cpu = children_cpu_s() - cpu0;
    let err = stderr(&o);
    match o.status.code() {
        Some(0) => {}
        Some(1) => {
            let line = err.trim().to_owned();
            if line.lines().count() != 1 || line.contains("panicked") {
                return Err(format!("exit 1 without one clear line: {line}"));
            }
            if out.exists() || cert_dir.join("problem.mps").exists() {
                return Err("exit 1 left an output file".into());
            }
            return Ok((Outcome::Infeasible(line), cpu, wall));
        }
        c => return Err(format!("exit {c:?}: {}", err.trim())),
    }
    // The checker accepts the profile, which carries its optimality block.
    let c = run(&["check", out.to_str().unwrap()], None);
    if !c.status.success() {
        return Err(format!("check refused the profile: {}", stderr(&c).trim()));
    }
    let p: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    if p["optimality"].is_null() {
        return Err("no optimality block".into());
    }
    // The exported certificate, checked exactly from the outside.
    let mps = read_mps(&std::fs::read_to_string(cert_dir.join("problem.mps")).unwrap());
    let cj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cert_dir.join("certificate.json")).unwrap())
            .unwrap();
    let nums = |k: &str| -> Vec<f64> {
        cj[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let (feasible, obj, bound) = exact_figures(&mps, &nums("x"), &nums("y"));
    let bound = bound.ok_or("the certificate's bound is infinite")?;
    let exact = |k: &str| parse_rational(cj[k].as_str().unwrap());
    if !feasible {
        return Err("the certificate's x is not exactly feasible".into());
    }
    if obj != exact("objective_exact") || bound != exact("upper_bound_exact") {
        return Err("the certificate's exact figures differ from the recomputed ones".into());
    }
    let gap = &bound - &obj;
    if gap.is_negative() || gap != exact("gap_exact") {
        return Err("the certificate's gap is wrong".into());
    }
    let f = |k: &str| cj[k].as_f64().unwrap();
    if !(q(f("objective")) <= obj && q(f("upper_bound")) >= bound && q(f("gap")) >= gap) {
        return Err("the rounded figures do not bracket the exact ones".into());
    }
    let opt = &p["optimality"];
    if opt["objective"].as_f64() != Some(f("objective")) || opt["gap"].as_f64() != Some(f("gap")) {
        return Err("the profile's optimality block differs from the certificate".into());
    }
    Ok((
        Outcome::Certified {
            gap: f("gap"),
            objective: f("objective"),
        },
        cpu,
        wall,
    ))
}

/// The members run: all with `every` (`GAZE_LIDAR_FAMILY=all`), else
/// every 7th.
fn selected(all: &[Member], every: bool) -> Vec<&Member> {
    all.iter().filter(|m| every || m.index % 7 == 0).collect()
}

#[test]
fn the_random_family_is_answered_certified_and_fast() {
    let seed = std::env::var("GAZE_LIDAR_FAMILY_SEED")
        .ok()
        .map_or(DEFAULT_SEED, |s| s.parse().expect("GAZE_LIDAR_FAMILY_SEED"));
    let max_wall_s: f64 = std::env::var("GAZE_LIDAR_FAMILY_MAX_WALL_S")
        .ok()
        .map_or(20.0, |s| s.parse().expect("GAZE_LIDAR_FAMILY_MAX_WALL_S"));
    let cpu_slack: f64 = std::env::var("GAZE_LIDAR_FAMILY_CPU_SLACK")
        .ok()
        .map_or(1.5, |s| s.parse().expect("GAZE_LIDAR_FAMILY_CPU_SLACK"));
    let max_gap: f64 = std::env::var("GAZE_LIDAR_FAMILY_MAX_GAP")
        .ok()
        .map_or(0.01, |s| s.parse().expect("GAZE_LIDAR_FAMILY_MAX_GAP"));
    let all = family(seed);
    let mut failures = Vec::new();
    let mut cpus = Vec::new();
    let every = std::env::var("GAZE_LIDAR_FAMILY").is_ok_and(|v| v == "all");
    let only: Option<usize> = std::env::var("GAZE_LIDAR_FAMILY_ONLY")
        .ok()
        .map(|s| s.parse().expect("GAZE_LIDAR_FAMILY_ONLY"));
    for m in selected(&all, every || only.is_some()) {
        if only.is_some_and(|k| k != m.index) {
            continue;
        }
        if only.is_some() {
            eprintln!("{}", m.toml);
        }
        let (outcome, cpu, wall) = match run_member(m) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("#{:02} FAIL {}: {e}", m.index, m.summary);
                failures.push(format!("#{} ({}): {e}\n{}", m.index, m.summary, m.toml));
                continue;
            }
        };
        cpus.push(cpu);
        let verdict = match &outcome {
            Outcome::Certified { gap, objective } => format!(
                "certified, gap {gap:.3e} (relative {:.3e})",
                gap / objective.abs().max(1e-300)
            ),
            Outcome::Infeasible(line) => format!("infeasible: {line}"),
        };
        eprintln!(
            "#{:02} cpu {cpu:.3} s wall {wall:.3} s  {} gaze {} (milp {}): {verdict}",
            m.index, m.summary, m.gaze_deg, m.milp
        );
        if wall > max_wall_s {
            failures.push(format!("#{} ({}): wall {wall:.1} s", m.index, m.summary));
        }
        if cpu > 2.0 * cpu_slack {
            failures.push(format!(
                "#{} ({}): CPU {cpu:.2} s, over 2 s × {cpu_slack}",
                m.index, m.summary
            ));
        }
        if let Outcome::Certified { gap, objective } = &outcome {
            let rel = gap / objective.abs().max(1e-300);
            if rel > max_gap {
                failures.push(format!(
                    "#{} ({}): relative gap {rel:.3e} over {max_gap}",
                    m.index, m.summary
                ));
            }
        }
        // Set-points that cannot meet the frame period: the refusal names it.
        if let Some(w) = &m.setpoints {
            let miss = best_frame_mismatch(w, m.bins, m.frame_rate_hz);
            let names_frame =
                matches!(&outcome, Outcome::Infeasible(l) if l.contains("frame period"));
            if miss > 1e-6 && !names_frame {
                failures.push(format!(
                    "#{} ({}): set-points miss the frame period by {miss:.2e} at best, the answer does not say so",
                    m.index, m.summary
                ));
            }
            if miss < 1e-12 && names_frame {
                failures.push(format!(
                    "#{} ({}): set-points reach the frame period (mismatch {miss:.1e}) but the refusal blames it",
                    m.index, m.summary
                ));
            }
        }
    }
    cpus.sort_by(f64::total_cmp);
    if let Some(&max) = cpus.last() {
        eprintln!(
            "{} requests: CPU median {:.3} s, max {max:.3} s; {} over 2 s",
            cpus.len(),
            cpus[cpus.len() / 2],
            cpus.iter().filter(|&&c| c > 2.0).count()
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The outside tester's many-level and set-point requests: 100 and 300
/// hardware power levels on 360 bins (joint, time accounting), 300 levels
/// on 720 bins, and 8 and 12 spin set-points on 360 bins (resolution).
/// Every one is answered certified (the checker accepts it and its
/// exported certificate checks exactly), with a relative gap within 1 %;
/// each took under 2 s of CPU when measured (printed here), and the test
/// holds the wall time under a loose 10 s so a loaded machine does not
/// fail it.
#[test]
fn many_levels_and_setpoints_are_certified_in_seconds() {
    let levels = |k: usize| -> String {
        (0..k)
            .map(|i| format!("{:?}", 1e-4 + i as f64 * (1.15e-3 - 1e-4) / (k - 1) as f64))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let setpoints = |k: usize| -> String {
        (0..k)
            .map(|i| format!("{:?}", 60.123 + i as f64 * 240.0 / (k - 1) as f64))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let lv = |k: usize, bins: usize, mode: &str| {
        format!("bins = {bins}\n[lidar]\npower_accounting = \"time\"\n[levels]\npower_w = [{}]\n[objective]\nmode = \"{mode}\"\n", levels(k))
    };
    let sp = |k: usize| {
        format!(
            "bins = 360\n[levels]\nspin_rad_s = [{}]\n[objective]\nmode = \"resolution\"\n",
            setpoints(k)
        )
    };
    let cases = [
        ("100 levels, 360 bins, joint", lv(100, 360, "joint")),
        ("300 levels, 360 bins, joint", lv(300, 360, "joint")),
        ("300 levels, 720 bins, joint", lv(300, 720, "joint")),
        ("8 set-points, 360 bins", sp(8)),
        ("12 set-points, 360 bins", sp(12)),
    ];
    let mut failures = Vec::new();
    for (index, (name, toml)) in cases.into_iter().enumerate() {
        let m = Member {
            index,
            toml,
            gaze_deg: 90.0,
            bins: 360,
            mode: "joint",
            milp: true,
            setpoints: None,
            frame_rate_hz: 20.0,
            summary: name.to_owned(),
        };
        match run_member(&m) {
            Ok((Outcome::Certified { gap, objective }, cpu, wall)) => {
                let rel = gap / objective.abs().max(1e-300);
                eprintln!("{name}: cpu {cpu:.3} s wall {wall:.3} s, relative gap {rel:.3e}");
                if rel > 0.01 {
                    failures.push(format!("{name}: relative gap {rel:.3e}"));
                }
                if wall > 10.0 {
                    failures.push(format!("{name}: wall {wall:.1} s"));
                }
            }
            Ok((Outcome::Infeasible(line), ..)) => failures.push(format!("{name}: {line}")),
            Err(e) => failures.push(format!("{name}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The generator covers what the family is for: every mode, both
/// accountings, MILPs with a slew limit at 360–720 bins, set-points,
/// acceleration limits and 36 and 720 bins.
#[test]
fn the_family_covers_its_dimensions() {
    let all = family(DEFAULT_SEED);
    let has = |f: &dyn Fn(&Member) -> bool| all.iter().any(f);
    for mode in ["range", "resolution", "joint"] {
        assert!(has(&|m| m.mode == mode), "{mode}");
    }
    for acc in ["\"angle\"", "\"time\""] {
        assert!(has(&|m| m.toml.contains(acc)), "{acc}");
    }
    assert!(has(&|m| m.milp
        && m.bins >= 360
        && m.summary.contains("slew")));
    assert!(has(&|m| m.setpoints.is_some()));
    assert!(has(
        &|m| m.summary.contains("accel") && m.mode == "resolution"
    ));
    assert!(has(&|m| m.bins == 36) && has(&|m| m.bins == 720));
    for a in ["box", "levi_e2", "gaussian"] {
        assert!(has(&|m| m.summary.contains(a)), "{a}");
    }
    assert_eq!(selected(&all, false).len(), 10);
    assert_eq!(selected(&all, true).len(), MEMBERS);
}

/// The enumeration reference knows a hand-made case: 4 bins at 2 and 4
/// rad/s make one turn in 2·(π/2)/2 + 2·(π/2)/4 = 3π/4 s.
#[test]
fn the_frame_reference_enumerates() {
    let f = 1.0 / (0.75 * std::f64::consts::PI);
    assert!(best_frame_mismatch(&[2.0, 4.0], 4, f) < 1e-15);
    assert!(best_frame_mismatch(&[2.0, 4.0], 4, f * 1.01) > 1e-3);
}
