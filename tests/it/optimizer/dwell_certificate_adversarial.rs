//! Attacks on the dwell step's certificate,
//! the MILP node limit and `--certificate` export (`specs/optimizer.md`,
//! "The dwell step's certificate", "MILPs: a node limit, not a time
//! limit"). Each `#[ignore = "finding: …"]` test is a minimal reproducer of
//! a claim that does not hold; the others pin claims that held under attack.
#![cfg(feature = "solver")]

use crate::common;

use std::path::Path;

/// HiGHS reads `path` (free MPS) with its own reader and solves it afresh
/// at tight tolerances (as `tests/it/optimizer/certificate.rs` does); the objective.
fn highs_objective_of_file(path: &Path) -> f64 {
    let run = common::highs_solve_file(
        path,
        &[
            "primal_feasibility_tolerance",
            "dual_feasibility_tolerance",
            "mip_feasibility_tolerance",
        ],
    );
    assert!(run.run_status >= 0, "HiGHS solved {}", path.display());
    assert_eq!(
        run.model_status,
        7,
        "HiGHS model status optimal (7) for {}",
        path.display()
    );
    run.objective
}

/// Exploration helper, not a test of a claim: for every certificate
/// directory named in `GAZE_LIDAR_CERT_DIRS` (whitespace separated), HiGHS
/// re-solves `problem.mps` at 1e-10 and the result is printed beside the
/// certified `objective` and `upper_bound`.
#[test]
#[ignore = "exploration helper (GAZE_LIDAR_CERT_DIRS)"]
fn explore_resolve_exported_programs() {
    let Ok(dirs) = std::env::var("GAZE_LIDAR_CERT_DIRS") else {
        return;
    };
    for d in dirs.split_whitespace() {
        let d = Path::new(d);
        let c: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("certificate.json")).unwrap())
                .unwrap();
        let fresh = highs_objective_of_file(&d.join("problem.mps"));
        let ub = c["upper_bound"].as_f64().unwrap();
        let obj = c["objective"].as_f64().unwrap();
        println!(
            "{} fresh {fresh:.17e} obj {obj:.17e} ub {ub:.17e} fresh-ub {:.3e} (rel {:.3e})",
            d.display(),
            fresh - ub,
            (fresh - ub) / ub.abs()
        );
    }
}

use gaze_lidar::optimizer::{optimize_with_certificate, OptError, OptimizerConfig};

use super::problem_from_toml;

/// Three spin set-points of the paper preset (20 Hz, mean spin 40π rad/s)
/// chosen so that 100 bins at the first, 130 at the second and 130 at the
/// third of 360 equal bins meet the frame period (to rounding): the
/// slownesses `w̄/ω` are √2·0.7, π/3.3 and the third solved from the frame.
fn three_setpoints_360() -> (Vec<f64>, [usize; 3]) {
    let n = [100usize, 130, 130];
    let w_mean = 2.0 * std::f64::consts::PI * 20.0;
    let (r1, r2) = (2f64.sqrt() * 0.7, std::f64::consts::PI / 3.3);
    let r3 = (360.0 - n[0] as f64 * r1 - n[1] as f64 * r2) / n[2] as f64;
    (vec![w_mean / r1, w_mean / r2, w_mean / r3], n)
}

fn setpoint_config(sp: &[f64], mode: &str) -> String {
    format!(
        "bins = 360\n[lidar]\npreset = \"paper\"\n[limits]\nspin_rad_s_min = 20.0\nspin_rad_s_max = 600.0\n[levels]\nspin_rad_s = [{}]\n[objective]\nmode = \"{mode}\"\n",
        sp.iter()
            .map(|w| format!("{w:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// Claim 3 ("a node-limited answer is a feasible incumbent checked
/// exactly"): a node-limited MILP may end with *no* incumbent. Here a
/// certifiable profile that uses only the three set-points exists (built
/// below and accepted by the checker), but the dwell step's branch and
/// bound stops at `MIP_MAX_NODES` = 100 before it finds one (an equality
/// knapsack: the frame row), and the solve fails with
/// `solver: dwell step: HiGHS status ReachedSolutionLimit`.
#[test]
// Fixed (was: node limit turns a feasible set-point problem into a solver error (ReachedSolutionLimit without an incumbent)).
fn a_feasible_setpoint_problem_is_solved_despite_the_node_limit() {
    let (sp, n) = three_setpoints_360();
    // A certifiable profile on the set-points: n[k] one-degree bins at sp[k].
    let text = setpoint_config(&sp, "resolution");
    let problem = problem_from_toml(&text);
    let mut bins = Vec::new();
    let mut k = 0;
    for (idx, &count) in n.iter().enumerate() {
        for _ in 0..count {
            bins.push(serde_json::json!({
                "start_deg": k as f64, "width_deg": 1.0, "power_w": 0.001,
                "spin_start_rad_s": sp[idx], "spin_end_rad_s": sp[idx],
            }));
            k += 1;
        }
    }
    let doc = serde_json::json!({
        "format": "gaze-lidar/profile@1",
        "frame_rate_hz": problem.lidar.frame_rate_hz,
        "pulse_rate_hz": problem.lidar.pulse_rate_hz,
        "average_power_w": problem.lidar.average_power_w,
        "power_accounting": "angle",
        "gaze_deg": null,
        "limits": serde_json::to_value(&problem.lidar.limits).unwrap(),
        "bins": bins,
    });
    let profile = gaze_lidar::profile::Profile::from_json(&doc.to_string(), "by hand").unwrap();
    gaze_lidar::checker::certify(profile).expect("a profile on the set-points certifies");
    // The optimizer's dwell step cannot find it within 100 nodes.
    match optimize_with_certificate(&problem, 90.0) {
        Ok(_) => {}
        Err(e) => panic!("{e}"),
    }
}

/// The same node limit without any feasible assignment: the answer should
/// say *infeasible* (the set-points cannot meet the frame period), not
/// report a solver status. Four set-points that no composition of 24 bins
/// brings within 4e-4 of the frame (enumerated: the best is 21 bins at
/// the first and 3 at the last, 4.1e-4 off in units of a bin's mean dwell).
#[test]
// Fixed (was: set-points that cannot meet the frame give 'solver: … ReachedSolutionLimit' instead of an infeasibility message).
fn setpoints_that_cannot_meet_the_frame_are_reported_infeasible() {
    let sp = [
        118.8631000948167,
        174.2955077230426,
        204.56011000022755,
        209.66075882411533,
    ];
    let text = setpoint_config(&sp, "resolution").replace("bins = 360", "bins = 24");
    let problem = problem_from_toml(&text);
    match optimize_with_certificate(&problem, 53.694) {
        Err(OptError::Infeasible(_)) => {}
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("no composition of the set-points meets the frame"),
    }
}

/// A profile@1 of equal bins with the given powers (W) and step spins
/// (rad/s), the problem's sensor and limits, certified by the checker.
fn certify_by_hand(
    problem: &gaze_lidar::optimizer::Problem,
    power_w: &[f64],
    spin_rad_s: &[f64],
) -> Result<gaze_lidar::checker::CertifiedProfile, gaze_lidar::checker::Rejected> {
    let n = power_w.len();
    let width = 360.0 / n as f64;
    let bins: Vec<serde_json::Value> = (0..n)
        .map(|i| {
            serde_json::json!({
                "start_deg": i as f64 * width, "width_deg": width, "power_w": power_w[i],
                "spin_start_rad_s": spin_rad_s[i], "spin_end_rad_s": spin_rad_s[i],
            })
        })
        .collect();
    let doc = serde_json::json!({
        "format": "gaze-lidar/profile@1",
        "frame_rate_hz": problem.lidar.frame_rate_hz,
        "pulse_rate_hz": problem.lidar.pulse_rate_hz,
        "average_power_w": problem.lidar.average_power_w,
        "power_accounting": serde_json::to_value(problem.lidar.power_accounting).unwrap(),
        "gaze_deg": null,
        "limits": serde_json::to_value(&problem.lidar.limits).unwrap(),
        "bins": bins,
    });
    let profile = gaze_lidar::profile::Profile::from_json(&doc.to_string(), "by hand").unwrap();
    gaze_lidar::checker::certify(profile)
}

/// Claim 3/4 ("a node-limited answer is a feasible incumbent checked
/// exactly"; "the answers pass check"): the power step's MILP accepts
/// HiGHS's level choice at HiGHS's own tolerance (its MIP feasibility
/// tolerance is 1e-6, the budget row's slack 1e-12 relative), and nothing
/// repairs a level choice. Two levels, 0.5·P̄ and 1.5·P̄·(1 + 3.3e-8):
/// six high bins of twelve overspend the budget by 5e-8 relative; HiGHS
/// takes them, the exact check fails (no `optimality`), and the checker
/// rejects the profile: exit 1 "the optimized profile violates its
/// limits: average_power_w …" although five high bins (or all low ones,
/// certified below) are an answer.
#[test]
// Fixed (was: power-level MILP answer overspends the budget within HiGHS's MIP tolerance; the checker rejects it (error instead of answer)).
fn hardware_levels_a_hair_over_the_budget_still_give_an_answer() {
    for mode in ["range", "joint"] {
        let text = format!(
            "bins = 12\n[lidar]\npreset = \"paper\"\npower_accounting = \"angle\"\naverage_power_w = 0.0005\n[limits]\npower_w_max = 0.001\n[levels]\npower_w = [0.00025, 0.00075000005]\n[objective]\nmode = \"{mode}\"\n"
        );
        let problem = problem_from_toml(&text);
        let w = problem.lidar.mean_spin_rad_s();
        certify_by_hand(&problem, &[0.00025; 12], &[w; 12]).expect("all low levels certify");
        let mut five_high = [0.00025; 12];
        five_high[..5].fill(0.00075000005);
        certify_by_hand(&problem, &five_high, &[w; 12]).expect("five high levels certify");
        match optimize_with_certificate(&problem, 90.0) {
            Ok((c, cert)) => {
                assert!(cert.is_ok(), "{mode}: the power step certified");
                assert!(c.profile().optimality.is_some(), "{mode}");
            }
            Err(e) => panic!("{mode}: {e}"),
        }
    }
}

/// The dwell step's twin: three set-points, ω̄/1.5, ω̄/(1 + 2.5e-8) and
/// ω̄/0.75. Four bins at ω̄/1.5 and eight at ω̄/0.75 meet the frame exactly (certified
/// below); the dwell MILP instead takes a choice that misses the frame by
/// ~1e-8 relative (inside HiGHS's MIP tolerance, outside the widened frame
/// row `4e-9·(1 + Σ|a|)` and the checker's 1e-9): no certificate, and the
/// checker rejects the profile (exit 1, "frame period: the bins' dwell
/// times sum to 0.0500000009375 s").
#[test]
// Fixed (was: set-point MILP answer misses the frame within HiGHS's MIP tolerance; the checker rejects it (error instead of answer)).
fn setpoints_a_hair_off_the_frame_still_give_an_answer() {
    let w_mean = 2.0 * std::f64::consts::PI * 20.0;
    let sp = [w_mean / 1.5, w_mean / (1.0 + 2.5e-8), w_mean / 0.75];
    let text = setpoint_config(&sp, "resolution").replace("bins = 360", "bins = 12");
    let text = text.replace("spin_rad_s_min = 20.0\nspin_rad_s_max = 600.0\n", "");
    let problem = problem_from_toml(&text);
    let p = problem.lidar.average_power_w;
    let mut spins = [sp[2]; 12];
    spins[..4].fill(sp[0]);
    certify_by_hand(&problem, &[p; 12], &spins).expect("4 slow + 8 fast meet the frame");
    match optimize_with_certificate(&problem, 90.0) {
        Ok((c, cert)) => {
            assert!(cert.is_ok());
            assert!(c.profile().optimality.is_some());
        }
        Err(e) => panic!("{e}"),
    }
}

/// Claim 4 ("infeasible exit 1"): a feasible joint problem reported
/// infeasible. The paper preset at 20 Hz under time accounting, spin
/// 1–1000 rad/s, a generous acceleration limit (10⁴ rad/s²), `joint`: the
/// uniform baseline certifies (below), but the solve ends with
/// `infeasible: the dwell step has no solution within the limits` (exit 1)
/// at every bin count tried (36–360) and gaze. Likely cause (not proven):
/// a later round of the sequential LP has no dwell within the trust region
/// (±30 %) that meets the acceleration rows re-linearised at the faster
/// iterate (their width shrinks as ω̃⁻³) together with the frame and the
/// time-accounting budget row at the power step's powers (tight, no
/// margin). The same sensor solves under angle accounting (no budget row
/// in the dwell step), with 3·10³ or 3·10⁴ rad/s², and in `resolution`
/// mode.
#[test]
// Fixed (was: joint mode with a finite acceleration limit reports a feasible problem infeasible (a later SLP dwell step is infeasible)).
fn a_generous_acceleration_limit_is_not_infeasible_in_joint_mode() {
    let text = "bins = 36\n[lidar]\npreset = \"paper\"\npower_accounting = \"time\"\nframe_rate_hz = 20\n[limits]\nspin_rad_s_min = 1.0\nspin_rad_s_max = 1000.0\nspin_accel_rad_s2_max = 10000\n[focus]\nthreshold = 0.0831\nacuity = { model = \"levi_e2\", e2_deg = 2.72 }\n[objective]\nmode = \"joint\"\nresolution_weight = 3.0\n";
    let problem = problem_from_toml(text);
    let w = problem.lidar.mean_spin_rad_s();
    let p = problem.lidar.average_power_w;
    certify_by_hand(&problem, &[p; 36], &[w; 36]).expect("the uniform baseline certifies");
    if let Err(e) = optimize_with_certificate(&problem, 90.0) {
        panic!("{e}");
    }
}

/// Claim 4 ("infeasible exit 1"): a spin fixed by its limits
/// (`spin_rad_s_min = spin_rad_s_max` = the mean spin the frame needs,
/// which the prechecks accept) is feasible — the uniform spin certifies —
/// but the dwell step's box keeps a relative `MARGIN` (1e-6) inside both
/// limits, so its lower side exceeds its upper one, the column is fixed at
/// `1 + 1e-6` and the frame row cannot hold: `infeasible: the dwell step
/// has no solution within the limits` in `resolution` and `joint` modes.
#[test]
// Fixed (was: spin_rad_s_min = spin_rad_s_max = the mean spin is reported infeasible (the dwell box's MARGIN)).
fn a_spin_fixed_by_its_limits_is_not_infeasible() {
    for mode in ["resolution", "joint"] {
        let w = 2.0 * std::f64::consts::PI * 20.0;
        let text = format!(
            "bins = 24\n[lidar]\npreset = \"paper\"\n[limits]\nspin_rad_s_min = {w:?}\nspin_rad_s_max = {w:?}\n[objective]\nmode = \"{mode}\"\n"
        );
        let problem = problem_from_toml(&text);
        let p = problem.lidar.average_power_w;
        certify_by_hand(&problem, &[p; 24], &[w; 24]).expect("the uniform spin certifies");
        if let Err(e) = optimize_with_certificate(&problem, 10.0) {
            panic!("{mode}: {e}");
        }
    }
}

/// Bad input names its field (exit 2): an objective weight HiGHS cannot
/// take (≥ its infinite cost, 1e20 less the chords' factors) ends as
/// `solver: dwell step: Error` (an `OptError::Solver`, exit 1) instead of
/// naming `objective.resolution_weight`.
#[test]
// Fixed (was: objective.resolution_weight = 1e19 gives 'solver: dwell step: Error' (exit 1), not a bad-input error naming the field).
fn a_huge_objective_weight_is_bad_input_naming_the_field() {
    let text = "bins = 24\n[lidar]\npreset = \"paper\"\n[objective]\nmode = \"joint\"\nresolution_weight = 1e19\n";
    // From a config file: refused as bad input naming the key.
    let e = OptimizerConfig::from_toml(text, "attack")
        .unwrap()
        .problem()
        .unwrap_err();
    assert!(
        e.is_input_error() && e.to_string().contains("resolution_weight"),
        "{e}"
    );
    // A `Problem` built in code: the same refusal from the optimizer.
    let mut problem =
        problem_from_toml(&text.replace("resolution_weight = 1e19", "resolution_weight = 1"));
    problem.objective.resolution_weight = 1e19;
    match optimize_with_certificate(&problem, 10.0) {
        Ok(_) => {}
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            assert!(e.to_string().contains("resolution_weight"), "{e}");
        }
    }
}

/// Claim 3 (the node limit bounds the work): the limit is per MILP and
/// counts branch-and-bound nodes, not the root node's work (cuts,
/// heuristics) nor the number of MILPs a solve runs. `joint` mode with
/// `multi_level.toml`'s six power levels and `paper.toml`'s two spin
/// set-points under time accounting at 720 bins: the level-choice probe
/// and primal heuristic (`optimizer::level_choice`) answer it in about
/// 0.2 s of CPU; the 30 s bound leaves room for a loaded machine.
#[test]
fn levels_and_setpoints_at_720_bins_solve_within_30_s() {
    let text = "bins = 720\n[lidar]\npreset = \"paper\"\npower_accounting = \"time\"\n[limits]\npower_w_min = 0.0002\npower_w_max = 0.0013\n[focus]\nthreshold = 0.0831\nacuity = { model = \"levi_e2\", e2_deg = 2.72 }\n[levels]\npower_w = [0.0002, 0.0005, 0.0008, 0.001, 0.0011, 0.0012]\nspin_rad_s = [108.59826456853607, 586.4306286700948]\n[objective]\nmode = \"joint\"\n";
    let problem = problem_from_toml(text);
    let t0 = std::time::Instant::now();
    let r = optimize_with_certificate(&problem, 33.0);
    let secs = t0.elapsed().as_secs_f64();
    assert!(r.is_ok(), "{:?}", r.err());
    assert!(secs < 30.0, "{secs:.1} s");
}

/// Claim 2 (the top-level figures are the dwell program's and describe the
/// answer): the dwell program drops its utilities' constants
/// (`λ_ρ θ_i w_i √r_0`, "its constant does not move the optimum"), while
/// the power step keeps them on a column fixed at 1. So in `resolution`
/// mode `optimality.objective` is not the profile's objective: with spin
/// limits 125.66–125.67 rad/s (20 Hz: the mean spin 125.664 inside) it is
/// 3.09e-4 while the profile's exact objective (`exact_objective`) is
/// 10.49 (`optimality.global.objective`, which also counts the range term,
/// 15.74), and the stated gap 2.0e-7 reads as 6.5e-4 relative where it is
/// 2e-8 of the objective.
#[test]
// Fixed (was: resolution-mode optimality.objective omits the dwell utilities' constants (3.1e-4 vs the profile's 10.49; relative gap inflated ~3e4x)).
fn resolution_mode_objective_is_the_profiles_objective() {
    let text = "bins = 90\n[lidar]\npreset = \"paper\"\npower_accounting = \"time\"\n[limits]\nspin_rad_s_min = 125.66\nspin_rad_s_max = 125.67\n[objective]\nmode = \"resolution\"\nresolution_weight = 2.0\n";
    let problem = problem_from_toml(text);
    let (c, cert) = optimize_with_certificate(&problem, 77.0).unwrap();
    assert!(cert.is_ok());
    let o = c.profile().optimality.clone().expect("optimality");
    let exact = gaze_lidar::optimizer::exact_objective(&problem, 77.0, c.profile()).unwrap();
    // Chords from below: the program's objective is at most the exact one
    // and close to it, as the power step's (which keeps its constants) is.
    assert!(
        o.objective <= exact && o.objective >= exact * (1.0 - 1e-3),
        "optimality.objective {} vs the profile's exact objective {exact}",
        o.objective
    );
}

/// Claim 4 (the answers pass `check`): `power_slew_w_per_deg_max = 0`
/// (constant power; accepted as a limit ≥ 0) or 1e-15 W/deg. The uniform
/// power certifies, but the power step's LP meets its slew rows (sides
/// ~1e-15/P̄ or 0) only to HiGHS's absolute tolerance and nothing repairs
/// the powers for the slew (the trim is for the budget): the checker
/// rejects the answer, exit 1 "bins[…]→next power slew 1.4e-20 W/deg
/// exceeds limits.power_slew_w_per_deg_max 0 W/deg" (`joint`; `range`
/// passes at 0 but fails at 1e-15: "slew 1.00001e-15 W/deg exceeds … 1e-15").
#[test]
// Fixed (was: a zero (or 1e-15 W/deg) power slew limit gives a profile the checker rejects (error instead of the uniform answer)).
fn a_zero_power_slew_limit_gives_an_answer() {
    for (slew, mode) in [("0.0", "range"), ("0.0", "joint"), ("1e-15", "range")] {
        let text = format!(
            "bins = 24\n[lidar]\npreset = \"paper\"\npower_accounting = \"time\"\n[limits]\npower_slew_w_per_deg_max = {slew}\n[objective]\nmode = \"{mode}\"\n"
        );
        let problem = problem_from_toml(&text);
        let w = problem.lidar.mean_spin_rad_s();
        let p = problem.lidar.average_power_w;
        certify_by_hand(&problem, &[p; 24], &[w; 24]).expect("the uniform power certifies");
        if let Err(e) = optimize_with_certificate(&problem, 10.0) {
            panic!("{slew} {mode}: {e}");
        }
    }
}
