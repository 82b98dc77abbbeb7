//! The optimizer at the edges of its input: degenerate objectives, limits
//! met exactly. Each test names the wrong answer it rules out.
#![cfg(feature = "solver")]

mod common;

use common::run;
use gaze_lidar::optimizer::certificate::{check, LinearProgram, Row};
use gaze_lidar::optimizer::{optimize, OptimizerConfig};

/// The bins' powers of the optimizer's answer for a config text.
fn powers(toml: &str, gaze_deg: f64) -> Vec<f64> {
    let problem = OptimizerConfig::from_toml(toml, "t.toml")
        .unwrap()
        .problem()
        .unwrap();
    optimize(&problem, gaze_deg)
        .unwrap()
        .profile()
        .bins
        .iter()
        .map(|b| b.power_w)
        .collect()
}

/// A Gaussian acuity whose `σ²` underflows gave `V(0) = NaN`: an all-zero
/// profile "proven optimal" in range mode, a hang in joint mode. Refused
/// by name as bad input (exit 2), in every mode, without solving.
#[test]
fn an_acuity_too_narrow_for_doubles_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    for mode in ["range", "joint", "resolution"] {
        for (model, key) in [("gaussian", "sigma_deg"), ("levi_e2", "e2_deg")] {
            for v in ["1e-300", "5e-324", "1e-10"] {
                let cfg = dir.path().join("t.toml");
                std::fs::write(
                    &cfg,
                    format!(
                        "bins = 36\n[objective]\nmode = \"{mode}\"\n[focus]\nthreshold = 0.5\nacuity = {{ model = \"{model}\", {key} = {v} }}\n"
                    ),
                )
                .unwrap();
                let out = dir.path().join("o.json");
                let o = run(
                    &[
                        "profile",
                        "--config",
                        cfg.to_str().unwrap(),
                        "--gaze-deg",
                        "90",
                        "--out",
                        out.to_str().unwrap(),
                    ],
                    None,
                );
                common::expect(&o, 2, &[key], &format!("{mode} {model} {v}"));
                assert!(!out.exists(), "{mode} {model} {v}: an output was written");
            }
        }
    }
}

/// The exact checker refuses a program with a NaN or infinite cost or
/// coefficient: NaN costs were once certified with a made-up exact value.
#[test]
fn the_exact_checker_refuses_a_non_finite_program() {
    let base = LinearProgram {
        cost: vec![1.0, 2.0],
        col_lo: vec![0.0, 0.0],
        col_hi: vec![1.0, 1.0],
        integer: vec![false, false],
        rows: vec![Row {
            coefs: vec![(0, 1.0), (1, 1.0)],
            lo: f64::NEG_INFINITY,
            hi: 1.0,
        }],
    };
    let (x, y) = (vec![0.0, 1.0], vec![2.0]);
    assert!(check(&base, &x, &y).primal_feasible);
    let mut nan_cost = base.clone();
    nan_cost.cost[0] = f64::NAN;
    let mut inf_cost = base.clone();
    inf_cost.cost[1] = f64::INFINITY;
    let mut nan_coef = base.clone();
    nan_coef.rows[0].coefs[0].1 = f64::NAN;
    let mut nan_rhs = base.clone();
    nan_rhs.rows[0].hi = f64::NAN;
    let mut nan_bound = base.clone();
    nan_bound.col_hi[0] = f64::NAN;
    for (what, lp) in [
        ("NaN cost", nan_cost),
        ("infinite cost", inf_cost),
        ("NaN coefficient", nan_coef),
        ("NaN right-hand side", nan_rhs),
        ("NaN column bound", nan_bound),
    ] {
        let e = check(&lp, &x, &y);
        assert!(!e.primal_feasible, "{what}: certified");
        assert!(e.violation.is_some(), "{what}");
    }
}

/// Weights are relative: the range step's answer is the same for
/// `range_weight` 1, 1e-6 and 1e-9 (small costs once read as zero under
/// HiGHS's absolute dual tolerance: 63 % and then 0 % of the budget used).
#[test]
fn the_answer_does_not_depend_on_the_weights_scale() {
    let cfg = |w: &str| format!("bins = 36\n[objective]\nmode = \"range\"\nrange_weight = {w}\n");
    let reference = powers(&cfg("1.0"), 90.0);
    let spent: f64 = reference.iter().sum();
    assert!(spent > 0.0);
    for w in ["1e-6", "1e-9"] {
        let p = powers(&cfg(w), 90.0);
        for (k, (a, b)) in p.iter().zip(&reference).enumerate() {
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1e-6),
                "range_weight {w}, bin {k}: {a} W, against {b} W at weight 1"
            );
        }
    }
}

/// Fog weights are relative: `[1e308, 1e308]` (each accepted, their sum
/// overflows) is `[1, 1]`, not an all-zero objective "proven optimal".
#[test]
fn fog_weights_whose_sum_overflows_are_still_relative() {
    let cfg = |w: &str| {
        format!(
            "bins = 36\n[objective]\nmode = \"range\"\nkind = \"detection\"\n[objective.detection]\nfog_pct = [0, 25]\nfog_weight = [{w}, {w}]\n"
        )
    };
    let a = powers(&cfg("1.0"), 90.0);
    let b = powers(&cfg("1e308"), 90.0);
    assert!(a.iter().sum::<f64>() > 0.0);
    assert_eq!(a, b);
}
