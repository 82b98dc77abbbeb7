//! The dwell step's certificates: every dwell program the optimizer
//! solves (continuous spin, spin set-points, acceleration limits, eye
//! safety's binding cuts, time accounting) comes with a certificate checked
//! in exact rational arithmetic (`optimality.dwell_step`), on problems
//! drawn over the shipped configs' variations, and in `resolution` mode
//! with spin steps the answer's own figures are that certificate's.
#![cfg(feature = "solver")]

use crate::common;

use gaze_lidar::optimizer::certificate::Step;
use gaze_lidar::optimizer::optimize_with_certificate;
use gaze_lidar::planner::Mode;
use proptest::prelude::*;

fn problem(name: &str, bins: usize, mode: Mode) -> gaze_lidar::optimizer::Problem {
    let mut p = common::shipped_problem(name, bins);
    p.objective.mode = mode;
    p
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn every_dwell_program_is_certified(
        name in prop::sample::select(vec!["paper", "multi_level", "smooth", "vls128_eye"]),
        bins in prop::sample::select(vec![12usize, 36, 90]),
        resolution in any::<bool>(),
        gaze in 0.0f64..360.0,
    ) {
        let mode = if resolution { Mode::Resolution } else { Mode::Joint };
        let p = problem(name, bins, mode);
        let smooth = p.lidar.limits.spin_accel_rad_s2_max.is_some();
        let (c, cert) = match optimize_with_certificate(&p, gaze) {
            Ok(r) => r,
            // A sensor the mode cannot serve is not this test's subject
            // (e.g. eye safety over the limit at the uniform spin).
            Err(e) => return Err(TestCaseError::reject(e.to_string())),
        };
        let profile = c.profile();
        let opt = profile.optimality.as_ref();
        let opt = opt.expect("an optimality block");
        let d = opt.dwell_step.as_ref().expect("every dwell program certified");
        prop_assert!(d.programs >= 1);
        prop_assert!(d.gap >= 0.0 && d.upper_bound >= d.objective);
        // The widening's price: HiGHS at 1e-9, rows widened by 2e-9·(1 + Σ|a|).
        // A smoothed spin in `resolution` mode is certified on the program
        // linearised at it, whose optimum it is not: its gap is larger.
        let tol = if resolution && smooth { 1e-3 } else { 1e-5 };
        prop_assert!(d.gap <= tol * d.objective.abs().max(1.0), "gap {}", d.gap);
        let cert = cert.expect("a certificate");
        if resolution {
            prop_assert_eq!(cert.step, Step::Dwell);
            prop_assert_eq!((opt.objective, opt.upper_bound, opt.gap), (d.objective, d.upper_bound, d.gap));
        } else {
            prop_assert_eq!(cert.step, Step::Power);
        }
    }
}

/// A dwell certificate is not a formality: the exported program's bound
/// must cover HiGHS's own optimum of the *nominal* program, and a point
/// moved off the frame by more than the stated width fails the exact check.
#[test]
fn the_dwell_certificate_bounds_the_nominal_program_and_rejects_points_off_the_frame() {
    use gaze_lidar::optimizer::certificate::check;
    let p = problem("smooth", 36, Mode::Resolution);
    let mut p = p;
    p.lidar.limits.spin_accel_rad_s2_max = None;
    let (_, cert) = optimize_with_certificate(&p, 90.0).unwrap();
    let cert = cert.unwrap();
    assert_eq!(cert.step, Step::Dwell);
    // The frame row is the one whose coefficients are all 1 over the τ
    // columns and whose range straddles N.
    let n = 36.0;
    let frame = cert
        .lp
        .rows
        .iter()
        .position(|r| r.lo < n && r.hi > n && r.coefs.len() == 36)
        .expect("the frame row, widened around N");
    let r = &cert.lp.rows[frame];
    let width = r.hi - r.lo;
    // 2·(2e-9·(1 + 36)), and no more than the rounding of sides near 36.
    assert!(
        (4e-9 * 37.0..=4e-9 * 37.0 * (1.0 + 1e-6)).contains(&width),
        "{width}"
    );
    // The nominal program (frame exactly N) re-solved: its optimum lies
    // under the certified bound.
    let mut nominal = cert.lp.clone();
    nominal.rows[frame].lo = n;
    nominal.rows[frame].hi = n;
    let s = nominal.solve("test").unwrap();
    let e = check(&cert.lp, &cert.x, &cert.y);
    let ub = e.upper_bound.unwrap();
    let nominal_obj: f64 = s.x.iter().zip(&nominal.cost).map(|(x, c)| x * c).sum();
    assert!(
        num_rational::BigRational::from_float(nominal_obj).unwrap()
            <= ub + num_rational::BigRational::from_float(1e-12).unwrap()
    );
    // Every τ column pushed up by a relative 1e-8: the frame sum leaves the
    // width and the exact check says so.
    let mut x = cert.x.clone();
    for &(j, _) in &r.coefs {
        x[j] *= 1.0 + 1e-8;
    }
    let e = check(&cert.lp, &x, &cert.y);
    assert!(!e.primal_feasible);
}

/// Hardware power levels in `joint` mode: once the dwell moves, the power
/// step's MILP is a multiple-choice knapsack with unequal weights, which
/// HiGHS took 66–82 s to close to a zero gap at 90 bins (and more than
/// 300 s at 360). The branch and bound now stops at a node count
/// (deterministic), and the answer states its exact gap.
#[test]
fn hardware_levels_in_joint_mode_solve_in_seconds_with_a_stated_gap() {
    let p = problem("multi_level", 90, Mode::Joint);
    let t0 = std::time::Instant::now();
    let (c, cert) = optimize_with_certificate(&p, 0.0).unwrap();
    let secs = t0.elapsed().as_secs_f64();
    assert!(secs < 30.0, "{secs} s");
    let o = c.profile().optimality.as_ref().unwrap();
    assert!(cert.unwrap().lp.is_mip());
    assert!(o.gap > 0.0 && o.gap <= 1e-3 * o.objective, "{o:?}");
    // Deterministic: the same answer again.
    let (again, _) = optimize_with_certificate(&p, 0.0).unwrap();
    assert_eq!(
        c.profile().to_json().unwrap(),
        again.profile().to_json().unwrap()
    );
}
