//! Support for the proof harnesses.
//!
//! Every harness is one function body run two ways: as a Kani proof over
//! symbolic inputs (`#[cfg(kani)] #[kani::proof]`, machine-checked only
//! where Kani is installed — it is not on the machines this crate is
//! developed on) and as an ordinary test over random inputs (bolero, under
//! `cargo test`). See `specs/verification.md`.
//!
//! [`cover!`](crate::cover) pairs every assumption with a reachability check:
//! under Kani it is `kani::cover!`; under `cargo test` it records hits so a
//! harness can assert that none of its properties held vacuously.

#[cfg(all(feature = "std", not(kani)))]
use std::collections::BTreeMap;
#[cfg(all(feature = "std", not(kani)))]
use std::sync::Mutex;

#[cfg(all(feature = "std", not(kani)))]
static HITS: Mutex<BTreeMap<&'static str, u64>> = Mutex::new(BTreeMap::new());

/// Records one evaluation of a cover condition (test builds).
#[cfg(all(feature = "std", not(kani)))]
pub fn record(message: &'static str, hit: bool) {
    let mut hits = HITS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    *hits.entry(message).or_insert(0) += u64::from(hit);
}

/// Asserts that each named cover condition held at least once (test builds).
#[cfg(all(feature = "std", not(kani)))]
pub fn assert_covered(messages: &[&'static str]) {
    let hits = HITS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    for m in messages {
        assert!(
            hits.get(m).copied().unwrap_or(0) > 0,
            "cover never satisfied: {m}"
        );
    }
}

/// `kani::cover!` under Kani; a recorded reachability check under `cargo test`
/// (in the crate that expands it).
#[macro_export]
macro_rules! cover {
    ($cond:expr, $msg:literal) => {{
        #[cfg(kani)]
        kani::cover!($cond, $msg);
        #[cfg(all(test, not(kani)))]
        $crate::verification::record($msg, $cond);
    }};
}
pub use crate::cover;
