//! The eye-safety tests that need the root crate: the pruned search against
//! the exhaustive one on the planner's closed-form profiles and on the
//! `check` benchmark's rough profile, and `gaze-lidar check` on the
//! constructed profiles. The references, the differential test and the
//! library-level regression cases live in the core crate
//! (`crates/core/tests/it/eye_safety/reference.rs`), where `cargo mutants -p
//! gaze-lidar-core` runs them.

use crate::big_profile;
use crate::common;
use gaze_lidar_core::testing::eye_cases;

use eye_cases::{ael_step_cases, constructed};
use gaze_lidar::eye_safety::bound::Search;
use gaze_lidar::eye_safety::exposure::evaluate_profile_with;
use gaze_lidar::eye_safety::EyeSafetyParams;
use gaze_lidar::profile::Profile;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

fn params_of(p: &Profile) -> EyeSafetyParams {
    p.limits.eye_safety.clone().expect("eye_safety params")
}

/// The same on the closed-form planner's profiles (the real-time path:
/// two levels of power and spin, so long runs of cells tie to the last
/// bit and the first one attaining the maximum decides the azimuth), for
/// random gazes, every controller, both presets and several bin counts.
#[test]
fn pruned_search_is_bit_identical_on_closed_form_profiles() {
    use gaze_lidar::model::presets;
    use gaze_lidar::planner::closed_form::build_profile;
    use gaze_lidar::planner::Mode;
    let mut runner = TestRunner::new(Config {
        cases: 120,
        ..Config::default()
    });
    let strategy = (
        -360.0f64..720.0,
        proptest::sample::select(Mode::ALL.to_vec()),
        any::<bool>(),
        proptest::sample::select(vec![36usize, 90, 360, 361, 720]),
    );
    runner
        .run(&strategy, |(gaze, mode, paper, bins)| {
            let preset = if paper {
                presets::paper()
            } else {
                presets::vls128()
            };
            let Ok(p) = build_profile(&preset, mode, Some(gaze), bins) else {
                return Ok(());
            };
            let params = params_of(&p);
            let a = evaluate_profile_with(&p, &params, Search::Pruned).unwrap();
            let b = evaluate_profile_with(&p, &params, Search::Exhaustive).unwrap();
            prop_assert_eq!(a.worst_ratio.to_bits(), b.worst_ratio.to_bits());
            prop_assert_eq!(a.binding_rule, b.binding_rule);
            prop_assert_eq!(a.worst_azimuth_deg.to_bits(), b.worst_azimuth_deg.to_bits());
            prop_assert_eq!(a, b);
            Ok(())
        })
        .unwrap();
}

/// The same on the `check` benchmark's rough workload (power ripple and
/// in-bin acceleration on every bin), where the pruning skips almost every
/// cell and walk.
#[test]
fn pruned_search_is_bit_identical_on_a_rough_5000_bin_profile() {
    let p = big_profile::big_profile(5000, big_profile::Roughness::Rough);
    let params = p.limits.eye_safety.clone().unwrap();
    let a = evaluate_profile_with(&p, &params, Search::Pruned).unwrap();
    let b = evaluate_profile_with(&p, &params, Search::Exhaustive).unwrap();
    assert_eq!(a.worst_ratio.to_bits(), b.worst_ratio.to_bits());
    assert_eq!(a, b);
}

#[test]
fn check_rejects_constructed_cases_naming_eye_safety() {
    let mut bad = Vec::new();
    for c in constructed() {
        let path = eye_cases::data_dir().join(c.name).display().to_string();
        let o = common::run(&["check", &path], None);
        let text = format!("{}{}", common::stdout(&o), common::stderr(&o)).to_lowercase();
        let names = text.contains("eye_safety") || text.contains("eye safety");
        // Only eye safety may be violated: no other limit is named.
        println!(
            "{}: exit {:?}, true ratio {:.4}",
            c.name,
            o.status.code(),
            c.truth
        );
        if o.status.code() != Some(1) || !names {
            bad.push(format!(
                "{} (true ratio {:.4}): exit {:?}: {}",
                c.name,
                c.truth,
                o.status.code(),
                text.lines().next().unwrap_or("")
            ));
        }
    }
    assert!(
        bad.is_empty(),
        "check must exit 1 naming eye safety on:\n{}",
        bad.join("\n")
    );
}

/// `gaze-lidar check` on the two AEL step-down profiles (a window longer than
/// the pulses it holds, across a step-down of Table 3): exit 1 naming eye
/// safety; their true ratios (by hand, `eye_cases::ael_step_cases`) are
/// over 1, where the AEL at the pulses' span put them below.
#[test]
fn check_rejects_windows_longer_than_their_pulses_naming_eye_safety() {
    for c in ael_step_cases() {
        let path = eye_cases::data_dir().join(c.name).display().to_string();
        let o = common::run(&["check", &path], None);
        let text = format!("{}{}", common::stdout(&o), common::stderr(&o)).to_lowercase();
        println!(
            "{}: exit {:?}, true ratio {:.6} (at the span {:.6}): {}",
            c.name,
            o.status.code(),
            c.truth,
            c.monotone,
            text.lines().next().unwrap_or("")
        );
        assert!(c.truth > 1.0 && c.monotone < 1.0);
        assert_eq!(o.status.code(), Some(1), "{}: {text}", c.name);
        assert!(
            text.contains("eye_safety") || text.contains("eye safety"),
            "{}: {text}",
            c.name
        );
    }
}
