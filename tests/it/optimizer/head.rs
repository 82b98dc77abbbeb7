//! Head-aware cuts: the optimizer's eye-safety cuts come from the head's
//! bound (`eye_safety::cuts::cuts_for`), so an optimized profile for a
//! sensor with a head is certified **as that head** by `gaze-lidar check`,
//! for every preset with a head and every mode, and for a configuration
//! whose head bound binds. The optimality figures are those of the program
//! with head cuts (sound, maybe not tight): where no valid cut separates,
//! the loop tightens and says so (`optimality.eye_safety_tightening`).

use crate::common;

use common::{run, stderr, stdout};
use gaze_lidar::profile::Profile;

const HEADS: [(&str, u32); 3] = [("vls128", 128), ("vlp16", 16), ("os1-128", 128)];

/// `gaze-lidar check FILE` on `json`: exit 0 and its verdict names the head
/// with its channel count.
fn check_names_the_head(json: &str, what: &str, channels: u32) {
    let dir = std::env::temp_dir().join(format!("gaze-lidar-head-optimize-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{}.json", what.replace([' ', '/'], "_")));
    std::fs::write(&path, json).unwrap();
    let o = run(&["check", path.to_str().unwrap()], None);
    assert_eq!(o.status.code(), Some(0), "{what}: {}", stderr(&o));
    let out = stdout(&o);
    assert!(out.starts_with("certified:"), "{what}: {out}");
    assert!(
        out.contains(&format!("head: {channels} channels evaluated")),
        "{what}: the verdict does not name the head: {out}"
    );
    std::fs::remove_file(&path).unwrap();
}

/// `paper` has no head: its optimized profiles in every mode are certified
/// with eye safety evaluated for its one channel.
#[test]
fn optimized_paper_preset_certifies_in_every_mode() {
    for mode in ["range", "resolution", "joint"] {
        let o = run(
            &[
                "profile",
                "--preset",
                "paper",
                "--mode",
                mode,
                "--optimize",
                "--gaze-deg",
                "90",
                "--bins",
                "72",
            ],
            None,
        );
        assert_eq!(o.status.code(), Some(0), "paper {mode}: {}", stderr(&o));
        let p = Profile::from_json(&stdout(&o), "out").unwrap();
        let c = gaze_lidar::checker::certify(p).unwrap_or_else(|e| panic!("paper {mode}: {e}"));
        let es = c.eye_safety().expect("paper: eye safety evaluated");
        assert!(es.head.is_none() && es.worst_ratio <= 1.0, "paper {mode}");
    }
}

#[test]
fn optimized_presets_with_a_head_certify_as_the_head_in_every_mode() {
    for (name, channels) in HEADS {
        for mode in ["range", "resolution", "joint"] {
            let what = format!("{name} {mode}");
            let o = run(
                &[
                    "profile",
                    "--preset",
                    name,
                    "--mode",
                    mode,
                    "--optimize",
                    "--gaze-deg",
                    "90",
                    "--bins",
                    "72",
                ],
                None,
            );
            assert_eq!(o.status.code(), Some(0), "{what}: {}", stderr(&o));
            let json = stdout(&o);
            let p = Profile::from_json(&json, "out").unwrap();
            assert!(
                p.limits.eye_safety.as_ref().unwrap().head.is_some(),
                "{what}"
            );
            // Where the power step ran, its optimality figures are the
            // head-cut program's: an upper bound at or above the objective.
            if let Some(opt) = &p.optimality {
                assert!(opt.upper_bound >= opt.objective, "{what}");
            }
            check_names_the_head(&json, &what, channels);
        }
    }
}

/// `profile --config C --gaze-deg 90` for a configuration whose head binds
/// (the `vls128` head at a budget its eye safety cannot carry everywhere) on
/// `bins` bins: its JSON output, read back.
fn head_binding_profile(bins: usize) -> (String, Profile) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("head_binds.toml");
    std::fs::write(
        &cfg,
        format!(
            "bins = {bins}\n[lidar]\npreset = \"vls128\"\naverage_power_w = 6.0e-5\n\
             [limits]\npower_w_min = 2.4e-6\npower_w_max = 1.0e-3\n\
             spin_accel_rad_s2_max = \"unlimited\"\n[objective]\nmode = \"range\"\n"
        ),
    )
    .unwrap();
    let o = run(
        &[
            "profile",
            "--config",
            cfg.to_str().unwrap(),
            "--gaze-deg",
            "90",
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let json = stdout(&o);
    let p = Profile::from_json(&json, "out").unwrap();
    (json, p)
}

/// The head-binding configuration at 72 bins: the answer sits at the
/// head's limit, `check` certifies it as the head, and since the head cuts
/// (single-channel cuts scaled by the head's weights) do not reach the
/// head's figure here, the loop's tightening is stated.
#[test]
fn a_config_whose_head_binds_is_certified_as_the_head() {
    let (json, p) = head_binding_profile(72);
    let c = gaze_lidar::checker::certify(p.clone()).unwrap();
    let es = c.eye_safety().unwrap();
    assert_eq!(es.head.as_ref().unwrap().channels, 128);
    assert!(
        es.worst_ratio > 0.99 && es.worst_ratio <= 1.0,
        "{}",
        es.worst_ratio
    );
    let opt = p.optimality.as_ref().unwrap();
    assert!(opt.upper_bound >= opt.objective);
    assert!(opt.eye_safety_tightening.is_some_and(|f| f > 1.0));
    check_names_the_head(&json, "vls128 head binds", 128);
}

/// The same configuration at 360 bins, where the head's short-window
/// candidate binds: with each energy cut scaled by its own factor (a 1-pulse
/// cut by the short windows' 24.6, not `W_v` = 123) the cuts reach the
/// head's figure, so the loop needs at most a small tightening (1.0011;
/// 1.2965 with one factor for every cut, whose answer's exact objective was
/// 5.2655 against 5.9255 now) and ends at the head's limit.
#[test]
fn per_cut_head_factors_reach_the_head_limit_without_a_large_tightening() {
    let (_, p) = head_binding_profile(360);
    let c = gaze_lidar::checker::certify(p.clone()).unwrap();
    let es = c.eye_safety().unwrap();
    assert!(
        es.worst_ratio > 0.999 && es.worst_ratio <= 1.0,
        "{}",
        es.worst_ratio
    );
    let opt = p.optimality.as_ref().unwrap();
    let f = opt.eye_safety_tightening.unwrap_or(1.0);
    assert!(f < 1.01, "tightened by {f}");
    assert!(opt.objective > 5.9, "{}", opt.objective);
}
