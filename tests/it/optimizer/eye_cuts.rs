//! The optimizer's eye-safety constraints are the core's cuts, and its
//! power step is optimal under the bound that decides
//! (`specs/optimizer.md`, "Eye safety as cuts").

use gaze_lidar::checker::certify;
use gaze_lidar::eye_safety::{
    cuts::{cuts, cuts_for},
    exposure,
};
use gaze_lidar::optimizer::{exact_objective, optimize, Levels, OptimizerConfig, Problem};
use gaze_lidar::profile::Profile;

fn shipped(name: &str) -> Problem {
    let path = format!(
        "{}/examples/configs/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    OptimizerConfig::read(std::path::Path::new(&path))
        .and_then(|c| c.problem())
        .expect("shipped config")
}

/// `vls128_eye` as it was before the `vls128` preset gained its 128-channel
/// head: one channel, an 8 mm beam, a 1.5 mW budget, limits
/// 0.2–4.5 mW. The tests below pin the single-channel optimizer's answers
/// and its exact optimality under the bound; with the head, the bound's
/// energy rules are a minimum over candidate channel weights (not linear
/// in the powers), so the cuts scale by the smallest weight and the power
/// step is no longer exactly optimal: `tests/it/eye_safety/head_presets.rs` certifies the
/// head's optimized profiles instead.
fn vls128_eye_one_channel() -> Problem {
    let mut p = shipped("vls128_eye");
    let es = p.lidar.limits.eye_safety.as_mut().unwrap();
    es.head = None;
    es.beam_diameter_mm = 8.0;
    p.lidar.channels = 128;
    p.lidar.average_power_w = 1.5e-3;
    p.lidar.limits.power_w_min = 2e-4;
    p.lidar.limits.power_w_max = 4.5e-3;
    p
}

/// Where eye safety binds, the answer the checker certifies is at least as
/// good (exact √ utilities) as the surrogate-cap method's: an LP with caps
/// 0.1 % under the single-pulse limit, rescaled uniformly onto the bound
/// (its answers recorded while the optimizer still had that method).
#[test]
fn vls128_eye_beats_the_rescaled_answer_and_certifies() {
    let problem = vls128_eye_one_channel();
    let new = optimize(&problem, 90.0).expect("vls128_eye solves");
    let text = std::fs::read_to_string(format!(
        "{}/tests/data/optimizer/vls128_eye_gaze90_rescaled_a9ed401.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let old: Profile = serde_json::from_str(&text).unwrap();
    let old = certify(old).expect("the old answer certified too");
    let (o_new, o_old) = (
        exact_objective(&problem, 90.0, new.profile()).unwrap(),
        exact_objective(&problem, 90.0, old.profile()).unwrap(),
    );
    eprintln!("vls128_eye exact objective: new {o_new} old {o_old}");
    assert!(o_new >= o_old, "new {o_new} < old {o_old}");
    let r = exposure::evaluate_profile(
        new.profile(),
        new.profile().limits.eye_safety.as_ref().unwrap(),
    )
    .unwrap();
    // On the limit (eye safety binds), within the head-room.
    assert!(
        r.worst_ratio <= 1.0 && r.worst_ratio > 1.0 - 1e-5,
        "{}",
        r.worst_ratio
    );
}

/// No cut removes a profile the bound certifies: on optimized profiles of
/// every shipped config (and one with eye safety binding), every cut's
/// ratio is at most the bound's worst ratio.
#[test]
fn cuts_never_exceed_the_bound_on_optimized_profiles() {
    for name in ["paper", "multi_level", "vls128_eye", "smooth"] {
        let problem = shipped(name);
        let c = optimize(&problem, 90.0).unwrap();
        let p = c.profile();
        let Some(params) = p.limits.eye_safety.as_ref() else {
            continue;
        };
        let laser = exposure::laser(params, p.pulse_rate_hz).unwrap();
        let half = 0.5 * exposure::pass_angle_deg(params, &laser);
        let segs = exposure::segments(p);
        let pw: Vec<f64> = segs.iter().map(|s| s.power_w).collect();
        let b = exposure::evaluate_profile(p, params).unwrap().worst_ratio;
        let all = cuts(&segs, half, &laser, &[], 0.0);
        assert!(!all.is_empty());
        for cut in &all {
            assert!(
                cut.ratio(&pw, p.pulse_rate_hz) <= b,
                "{name}: {cut:?} above {b}"
            );
        }
        // With a head, the head's cuts (each energy cut scaled by its own
        // factor) are at most the head's bound too.
        if params.head.is_some() {
            let head = cuts_for(&segs, params, &laser, &[], 0.0, 0.0).unwrap();
            assert!(!head.is_empty());
            for cut in &head {
                assert!(
                    cut.ratio(&pw, p.pulse_rate_hz) <= b,
                    "{name}: head cut {cut:?} above {b}"
                );
            }
        }
    }
}

/// Brute force on a small instance: `vls128_eye` at 12 bins with four
/// hardware power levels (one above the single-pulse limit). Every
/// assignment of levels to bins that meets the budget and beats the power
/// step's objective is put to the checker: none certifies. The MILP's
/// objective is the exact √ utility of its levels, so the comparison has
/// no chord in it. 4¹² = 16.8 M assignments.
#[test]
fn brute_force_finds_nothing_better_than_the_power_step() {
    let mut problem = vls128_eye_one_channel();
    problem.bins = 12;
    let p_mean = problem.lidar.average_power_w;
    let levels = [0.4 * p_mean, 0.9 * p_mean, 1.45 * p_mean, 2.0 * p_mean];
    problem.levels = Levels {
        power_w: levels.to_vec(),
        spin_rad_s: Vec::new(),
    };
    let best = optimize(&problem, 90.0).expect("solves");
    let o_best = exact_objective(&problem, 90.0, best.profile()).unwrap();
    // Per-bin utility of each level (exact_objective of a one-hot profile
    // minus the floor's, by linearity: the objective is a sum over bins).
    let n = problem.bins;
    let mut base = best.profile().clone();
    let util: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            levels
                .iter()
                .map(|&lv| {
                    let mut q = base.clone();
                    q.bins[i].power_w = lv;
                    let mut r = base.clone();
                    r.bins[i].power_w = 0.0;
                    exact_objective(&problem, 90.0, &q).unwrap()
                        - exact_objective(&problem, 90.0, &r).unwrap()
                })
                .collect()
        })
        .collect();
    let budget = p_mean * n as f64 * (1.0 + 1e-12);
    let mut checked = 0usize;
    let mut better_and_safe = Vec::new();
    let total = 4usize.pow(n as u32);
    for code in 0..total {
        let (mut c, mut obj, mut spend) = (code, 0.0, 0.0);
        let mut pick = [0usize; 12];
        for (i, slot) in pick.iter_mut().enumerate() {
            *slot = c % 4;
            c /= 4;
            obj += util[i][*slot];
            spend += levels[*slot];
        }
        if spend > budget || obj <= o_best * (1.0 + 1e-12) {
            continue;
        }
        for (i, &k) in pick.iter().enumerate() {
            base.bins[i].power_w = levels[k];
        }
        base.summary = None;
        checked += 1;
        if certify(base.clone()).is_ok() {
            better_and_safe.push((obj, pick));
        }
    }
    eprintln!(
        "brute force: {total} assignments, {checked} better within budget put to the checker"
    );
    assert!(
        checked > 0,
        "the instance must have better assignments the checker rejects"
    );
    assert!(
        better_and_safe.is_empty(),
        "{better_and_safe:?} beat {o_best}"
    );
}

/// Every mode that moves the spin ends certified where eye safety binds:
/// `joint` (its last power step runs the exact loop at the final spin) and
/// `resolution` (no power step: the move from the uniform spin is shortened
/// until the bound certifies), on `vls128_eye` with a faster-spinning
/// periphery allowed.
#[test]
fn joint_and_resolution_modes_certify_where_eye_safety_binds() {
    use gaze_lidar::planner::Mode;
    for mode in [Mode::Joint, Mode::Resolution] {
        let mut problem = vls128_eye_one_channel();
        problem.objective.mode = mode;
        let c = optimize(&problem, 90.0).unwrap_or_else(|e| panic!("{mode:?}: {e}"));
        let p = c.profile();
        let r = exposure::evaluate_profile(p, p.limits.eye_safety.as_ref().unwrap()).unwrap();
        assert!(r.worst_ratio <= 1.0 - 1e-6, "{mode:?}: {}", r.worst_ratio);
        let spins: Vec<f64> = p.bins.iter().map(|b| b.spin_start_rad_s).collect();
        let (lo, hi) = spins
            .iter()
            .fold((f64::MAX, 0.0f64), |(a, b), &w| (a.min(w), b.max(w)));
        assert!(hi > 1.5 * lo, "{mode:?}: the spin moved ({lo}..{hi})");
        if mode == Mode::Joint {
            // The power step binds eye safety at the final spin.
            assert!(r.worst_ratio > 1.0 - 1e-5, "{}", r.worst_ratio);
        }
    }
}

/// `resolution` mode at a power where slowing the spin anywhere crosses the
/// limit (uniform 2.2 mW is 98 % of the Rule 1 limit at the mean spin: more
/// pulses per pass lower C5): the shortened move still certifies.
#[test]
fn resolution_mode_shortens_a_move_the_bound_rejects() {
    use gaze_lidar::planner::Mode;
    let mut problem = vls128_eye_one_channel();
    problem.objective.mode = Mode::Resolution;
    problem.lidar.average_power_w = 2.2e-3;
    let c = optimize(&problem, 90.0).expect("the uniform spin at least");
    let p = c.profile();
    let r = exposure::evaluate_profile(p, p.limits.eye_safety.as_ref().unwrap()).unwrap();
    assert!(r.worst_ratio <= 1.0 - 1e-6, "{}", r.worst_ratio);
    // Where eye safety does not bind the same move goes further: it was
    // shortened.
    let spread = |prof: &Profile| {
        let w: Vec<f64> = prof.bins.iter().map(|b| b.spin_start_rad_s).collect();
        w.iter().fold(0.0f64, |a, &x| a.max(x)) / w.iter().fold(f64::MAX, |a, &x| a.min(x))
    };
    let mut free = problem.clone();
    // 1550 nm: limits thousands of times higher, never binding here.
    if let Some(e) = free.lidar.limits.eye_safety.as_mut() {
        e.wavelength_nm = 1550.0;
    }
    let f = optimize(&free, 90.0).unwrap();
    assert!(
        spread(p) < spread(f.profile()) * (1.0 - 1e-3),
        "{} vs {}",
        spread(p),
        spread(f.profile())
    );
}
