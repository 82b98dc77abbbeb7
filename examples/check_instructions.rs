//! The checker on the closed-form planner's 360-bin profiles (three gazes),
//! N times: a probe for instruction counts, which do not depend on the
//! machine's load the way timings do (`benches/gaze.rs` has the timings).
//!
//! ```text
//! cargo build --release --example check_instructions
//! valgrind --tool=callgrind target/release/examples/check_instructions 3
//! valgrind --tool=callgrind target/release/examples/check_instructions 33
//! # instructions per check = (second total − first total) / 30
//! # the same with `3 distinct` and `33 distinct`: no two bins alike
//! ```
use gaze_lidar::checker::check;
use gaze_lidar::model::presets;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;
fn main() {
    let preset = presets::paper();
    // `distinct` (second argument): every bin's power lowered by a
    // different tiny fraction, so that no two neighbours are alike and
    // nothing merges (as `benches/gaze.rs`).
    let distinct = std::env::args().nth(2).is_some_and(|s| s == "distinct");
    let ps: Vec<_> = [90.0, 130.0, 170.0]
        .iter()
        .map(|&g| {
            let mut p = build_profile(&preset, Mode::Joint, Some(g), 360).unwrap();
            if distinct {
                for (i, b) in p.bins.iter_mut().enumerate() {
                    b.power_w *= 1.0 - 1e-6 * (i + 1) as f64;
                }
            }
            p
        })
        .collect();
    let n: usize = std::env::args().nth(1).map_or(300, |s| s.parse().unwrap());
    let mut k = 0;
    for i in 0..n {
        k += check(std::hint::black_box(&ps[i % 3])).len();
    }
    println!("{k}");
}
