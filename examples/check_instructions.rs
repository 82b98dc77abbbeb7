//! The checker on the closed-form planner's 360-bin profiles (three gazes),
//! N times: a probe for instruction counts, which do not depend on the
//! machine's load the way timings do (`benches/gaze.rs` has the timings).
//!
//! ```text
//! cargo build --release --example check_instructions
//! valgrind --tool=callgrind target/release/examples/check_instructions 3
//! valgrind --tool=callgrind target/release/examples/check_instructions 33
//! # instructions per check = (second total − first total) / 30
//! ```
use gaze_lidar::checker::check;
use gaze_lidar::model::presets;
use gaze_lidar::planner::closed_form::build_profile;
use gaze_lidar::planner::Mode;
fn main() {
    let preset = presets::paper();
    let ps: Vec<_> = [90.0, 130.0, 170.0]
        .iter()
        .map(|&g| build_profile(&preset, Mode::Joint, Some(g), 360).unwrap())
        .collect();
    let n: usize = std::env::args().nth(1).map_or(300, |s| s.parse().unwrap());
    let mut k = 0;
    for i in 0..n {
        k += check(std::hint::black_box(&ps[i % 3])).len();
    }
    println!("{k}");
}
