//! Firmware binary decode + integer check: never panics; decoded tables
//! re-encode to the same bytes.
#![no_main]

use gaze_lidar::firmware::{binary, check_table};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(t) = binary::decode(data) {
        let _ = check_table(&t);
        assert_eq!(binary::encode(&t), data);
    }
});
