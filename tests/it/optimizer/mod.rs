//! The optimizer (HiGHS): solves, certificates, the global bound, cuts, set-points, the random family and golden outputs.

mod certificate;
mod detection_certificate;
mod detection_global;
mod dwell_certificate;
mod dwell_certificate_adversarial;
mod edge_cases;
mod eye_cuts;
mod eye_cuts_adversarial;
mod family;
mod global_adversarial;
mod golden;
mod head;
mod perturb;
mod setpoints;
mod solve;
mod units;

/// The problem of an optimizer config's text (a test's own config, so any
/// error is the test's: unwrapped).
pub(super) fn problem_from_toml(text: &str) -> gaze_lidar::optimizer::Problem {
    gaze_lidar::optimizer::OptimizerConfig::from_toml(text, "test.toml")
        .unwrap()
        .problem()
        .unwrap()
}
