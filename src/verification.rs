//! Support for the proof harnesses.
//!
//! Every harness in this crate is one function that is both a Kani proof
//! (`#[cfg_attr(kani, kani::proof)]`) and an ordinary test, written over
//! `bolero::check!()`: under `cargo kani --tests` its inputs are symbolic and
//! the property is proved for every input within the stated bounds; under
//! `cargo test` bolero feeds it random inputs. **Kani is not installed on
//! the machines this crate is developed on, so the proofs have been run as
//! tests, not machine-checked**; see `specs/verification.md`.
//!
//! [`cover!`] pairs every assumption with a reachability check: under Kani it
//! is `kani::cover!`; under `cargo test` it records hits so a harness can
//! assert that none of its properties held vacuously.

#[cfg(all(test, not(kani)))]
use std::collections::BTreeMap;
#[cfg(all(test, not(kani)))]
use std::sync::Mutex;

#[cfg(all(test, not(kani)))]
static HITS: Mutex<BTreeMap<&'static str, u64>> = Mutex::new(BTreeMap::new());

/// Records one evaluation of a cover condition (test builds).
#[cfg(all(test, not(kani)))]
pub fn record(message: &'static str, hit: bool) {
    let mut hits = HITS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    *hits.entry(message).or_insert(0) += u64::from(hit);
}

/// Asserts that each named cover condition held at least once (test builds).
#[cfg(all(test, not(kani)))]
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

/// `kani::cover!` under Kani; a recorded reachability check under `cargo test`.
macro_rules! cover {
    ($cond:expr, $msg:literal) => {{
        #[cfg(kani)]
        kani::cover!($cond, $msg);
        #[cfg(all(test, not(kani)))]
        $crate::verification::record($msg, $cond);
    }};
}
pub(crate) use cover;
