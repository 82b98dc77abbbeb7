//! Firmware binary decode + integer check: never panics; decoded tables
//! re-encode to the same bytes; `check_table`'s verdict agrees with the
//! integer restatement of the specification (`within_integer_limits`): the
//! integer rules accept exactly the tables within their limits, every
//! integer violation is in `check_table`'s list, and `check_table` certifies
//! only tables within their integer limits that carry eye-safety parameters.
#![no_main]

use gaze_lidar::firmware::check::within_integer_limits;
use gaze_lidar::firmware::{binary, check_integer, check_table, FwViolation};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(t) = binary::decode(data) {
        let within = within_integer_limits(&t);
        let integer = check_integer(&t);
        assert_eq!(integer.is_empty(), within, "{integer:?}");
        let full = check_table(&t);
        assert!(integer.iter().all(|v| full.contains(v)), "{full:?}");
        if full.is_empty() {
            assert!(within && t.eye_safety.is_some());
        }
        if t.eye_safety.is_none() {
            assert!(full.contains(&FwViolation::EyeSafetyMissing));
        }
        assert_eq!(binary::encode(&t), data);
    }
});
