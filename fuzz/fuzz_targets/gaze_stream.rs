//! Gaze lines in every format through the parser, the filter, the fail-safe
//! machine and the closed-form planner: never panics; every frame emitted is
//! certified and is the baseline whenever it is fail-safe.
#![no_main]

use gaze_lidar::gaze::{FailSafeConfig, FilterConfig, Format, Parser, State};
use gaze_lidar::model::presets;
use gaze_lidar::pipeline::{ClosedFormPlanner, GazeStream};
use gaze_lidar::planner::Mode;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    let format = [Format::Jsonl, Format::Csv, Format::Varjo, Format::Neon][usize::from(selector % 4)];
    let mut parser = Parser::new(format);
    let planner = ClosedFormPlanner { preset: presets::paper(), mode: Mode::Joint, bins: 36 };
    let mut stream = GazeStream::new(planner, FilterConfig::default(), FailSafeConfig::default());
    let mut frames = 0;
    for line in text.lines().take(64) {
        let Ok(Some(sample)) = parser.line(line) else {
            continue;
        };
        // Bound the frames a fuzzed timestamp can ask for.
        if !(0.0..1e3).contains(&sample.t_s) {
            continue;
        }
        if let Ok(out) = stream.push(&sample) {
            for f in out {
                frames += 1;
                if f.state == State::FailSafe {
                    assert!(f.profile.profile().gaze_deg.is_none());
                }
                if frames > 20_000 {
                    return;
                }
            }
        }
    }
});
