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
#[path = "../benches/common/planned.rs"]
mod planned;

use planned::planned_profiles;
fn main() {
    // `distinct` (second argument): no two bins alike, nothing merges.
    let distinct = std::env::args().nth(2).is_some_and(|s| s == "distinct");
    let ps = planned_profiles(distinct);
    let n: usize = std::env::args().nth(1).map_or(300, |s| s.parse().unwrap());
    let mut k = 0;
    for i in 0..n {
        k += check(std::hint::black_box(&ps[i % 3])).len();
    }
    println!("{k}");
}
