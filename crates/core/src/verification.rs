//! Support for the proof harnesses.
//!
//! Every harness is one function body run two ways: as a Kani proof over
//! symbolic inputs (`#[cfg_attr(kani, kani::proof)]`, machine-checked only
//! where Kani is installed — it is not on the machines this crate is
//! developed on) and as an ordinary test over random inputs (bolero, under
//! `cargo test`). See `specs/verification.md`.
//!
//! [`for_all!`](crate::for_all) draws the harness input: `kani::any()` under
//! Kani, `bolero::check!()` otherwise. bolero is a dev-dependency, so it is
//! named only in the `cfg(not(kani))` branch: plain `cargo kani -p
//! gaze-lidar-core` (which builds the library, without dev-dependencies)
//! resolves, and so does `cargo kani --tests`.
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

/// Runs a harness body on one input (the Kani branch of [`for_all!`]; a
/// function so that the closure's argument type is inferred from `T`).
#[doc(hidden)]
pub fn run_once<T, F: FnOnce(T)>(input: T, body: F) {
    body(input)
}

/// Random inputs each harness body runs on under `cargo test`: a count, not
/// bolero's default of one second of wall time, so a loaded machine runs as
/// many as an idle one and a cover that a test asserts hit is not missed for
/// lack of time (it was, about one run in twenty, under load).
#[doc(hidden)]
pub const FOR_ALL_ITERATIONS: usize = 20_000;

/// `for_all!(T, |x| body)`: the body for every `x: T`. Under Kani `x` is
/// `kani::any()` (symbolic: the proof covers every value); under `cargo
/// test` bolero feeds [`FOR_ALL_ITERATIONS`] random values (bolero is a
/// dev-dependency and is named only in this branch).
#[macro_export]
macro_rules! for_all {
    ($ty:ty, $body:expr $(,)?) => {{
        #[cfg(kani)]
        $crate::verification::run_once::<$ty, _>(kani::any(), $body);
        #[cfg(not(kani))]
        bolero::check!()
            .with_type::<$ty>()
            .with_iterations($crate::verification::FOR_ALL_ITERATIONS)
            .cloned()
            .for_each($body);
    }};
}
pub use crate::for_all;
