//! Profile JSON parse + check: never panics; whatever certifies also
//! quantizes into a firmware table that passes the integer checker.
#![no_main]

use gaze_lidar::checker::certify;
use gaze_lidar::firmware::{check_table, FirmwareConfig, FirmwareTable};
use gaze_lidar::profile::Profile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(profile) = Profile::from_json(text, "fuzz") else {
        return;
    };
    if let Ok(c) = certify(profile) {
        if let Ok(t) = FirmwareTable::from_certified(&c, &FirmwareConfig::default()) {
            assert!(check_table(&t).is_empty());
        }
    }
});
