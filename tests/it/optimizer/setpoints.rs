//! A request whose spin set-points cannot make one turn
//! take the frame period on N equal bins is refused before any solve with
//! `Infeasible::FrameUnreachable { limit: SpinLimit::SetPoints { .. } }`,
//! whose message names the frame period; every other request of the family
//! is solved and certified.
//!
//! The family is generated from a seed: the paper preset (20 Hz), 24–72
//! equal bins, two to four set-points drawn in the spin limits, resolution
//! or joint mode, and half of the requests made reachable by construction
//! (one set-point at the mean spin). Each request is judged independently
//! by enumerating every composition of the bins over the set-points (a
//! plain reference: the frame period the checker accepts, within 1e-9).
//! `cargo test` runs 16 requests; `GAZE_SETPOINT_FAMILY=N` runs N.
#![cfg(feature = "solver")]

use gaze_lidar::optimizer::{
    optimize_with_certificate, Infeasible, OptError, OptimizerConfig, SpinLimit,
};
use rand::{Rng, SeedableRng};

fn config(sp: &[f64], bins: usize, mode: &str) -> String {
    format!(
        "bins = {bins}\n[lidar]\npreset = \"paper\"\n[limits]\nspin_rad_s_min = 20.0\nspin_rad_s_max = 600.0\n[levels]\nspin_rad_s = [{}]\n[objective]\nmode = \"{mode}\"\n",
        sp.iter()
            .map(|w| format!("{w:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// Whether some composition of `n` bins over the set-points `sp` (rad/s)
/// makes the frame period `period_s` within 1e-9 relative (every
/// composition enumerated, the period summed bin by bin).
fn reachable(sp: &[f64], n: usize, period_s: f64) -> bool {
    let dwell: Vec<f64> = sp
        .iter()
        .map(|w| std::f64::consts::TAU / n as f64 / w)
        .collect();
    fn rec(d: &[f64], m: usize, t: f64, period_s: f64) -> bool {
        if d.len() == 1 {
            return (t + m as f64 * d[0] - period_s).abs() <= 1e-9 * period_s;
        }
        (0..=m).any(|c| rec(&d[1..], m - c, t + c as f64 * d[0], period_s))
    }
    rec(&dwell, n, 0.0, period_s)
}

#[test]
fn setpoints_that_miss_the_frame_name_the_frame_period() {
    let count: usize = std::env::var("GAZE_SETPOINT_FAMILY")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(16);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(30);
    let (mut refused, mut solved) = (0, 0);
    for k in 0..count {
        let bins = [24usize, 36, 72][rng.random_range(0..3)];
        let kinds = rng.random_range(2..=4);
        let mut sp: Vec<f64> = (0..kinds).map(|_| rng.random_range(60.0..400.0)).collect();
        if k % 2 == 0 {
            // Reachable by construction: the mean spin (40π rad/s) itself.
            sp[0] = 40.0 * std::f64::consts::PI;
        }
        let mode = if rng.random_bool(0.5) {
            "resolution"
        } else {
            "joint"
        };
        let text = config(&sp, bins, mode);
        let problem = OptimizerConfig::from_toml(&text, "family")
            .unwrap()
            .problem()
            .unwrap();
        let want = reachable(&sp, bins, 1.0 / problem.lidar.frame_rate_hz);
        let gaze = rng.random_range(0.0..360.0);
        match optimize_with_certificate(&problem, gaze) {
            Err(OptError::Infeasible(e @ Infeasible::FrameUnreachable { .. })) => {
                assert!(
                    !want,
                    "{k}: {text}: refused, but a composition meets the frame: {e}"
                );
                assert!(
                    matches!(
                        e,
                        Infeasible::FrameUnreachable {
                            limit: SpinLimit::SetPoints { bins: b, .. },
                            ..
                        } if b == bins
                    ),
                    "{k}: {e:?}"
                );
                let msg = e.to_string();
                assert!(
                    msg.contains("frame period 1/frame_rate_hz = 0.050000000 s"),
                    "{k}: {msg}"
                );
                refused += 1;
            }
            Err(e) => panic!("{k}: {text}: {e}"),
            Ok((profile, cert)) => {
                assert!(
                    want,
                    "{k}: {text}: solved, but no composition meets the frame"
                );
                assert!(cert.is_ok(), "{k}: {text}: {:?}", cert.err());
                assert!(profile.profile().bins.len() == bins);
                solved += 1;
            }
        }
    }
    // Both kinds occur in the default family.
    assert!(
        count < 8 || (refused > 0 && solved > 0),
        "{refused} {solved}"
    );
}

/// Under time accounting the dwell step's `budget` row (`Σ τ_i·p_i/P̄ ≤ N`)
/// is tighter than the set-points' frame band (`N·(1 ± 0.495·10⁻⁹)`): the
/// set-point heuristic's point must meet it too. A `vlp16` request with the
/// mean spin among its set-points (every bin at it is the uniform profile)
/// at 720 bins was refused as infeasible after about 37 s of branch and
/// bound: the heuristic's composition summed to `N + 4.5·10⁻⁸`, above the
/// budget. It is solved and certified, with its exact certificate.
#[test]
fn a_time_accounted_budget_caps_the_set_point_heuristic() {
    let text = "bins = 720\n[lidar]\npreset = \"vlp16\"\npower_accounting = \"time\"\n[limits]\nspin_accel_rad_s2_max = \"unlimited\"\n[levels]\nspin_rad_s = [60.645036, 62.83185307179586, 64.823745, 80.599347]\n[objective]\nmode = \"resolution\"\n";
    let problem = super::problem_from_toml(text);
    let (profile, cert) = optimize_with_certificate(&problem, 145.16).unwrap();
    assert!(cert.is_ok(), "{:?}", cert.err());
    assert_eq!(profile.profile().bins.len(), 720);
}
