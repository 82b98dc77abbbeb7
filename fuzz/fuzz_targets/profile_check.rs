//! Profile JSON parse + check: never panics; whatever certifies also
//! is within its limits by an independent recomputation, and a table it
//! quantizes into is within its integer limits, restated independently (not
//! `check_table`, which `from_certified` has already run).
#![no_main]

#[path = "../../tests/it/independent.rs"]
mod independent;

use gaze_lidar::checker::certify;
use gaze_lidar::firmware::{FirmwareConfig, FirmwareTable};
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
        let broken = independent::recheck(c.profile());
        assert!(broken.is_empty(), "{broken:?}");
        if let Ok(t) = FirmwareTable::from_certified(&c, &FirmwareConfig::default()) {
            let broken = independent::recheck_table(&t);
            assert!(broken.is_empty(), "{broken:?}");
        }
    }
});
