//! How long calls run: interruptible (Ctrl-C reaches them within
//! [`POLL`]) and fork-safe (no global thread pool).
//!
//! The work runs on a worker thread of its own while the calling thread,
//! every [`POLL`], takes the GIL and runs `PyErr_CheckSignals` (which only
//! acts on the main thread, where Python's signal handlers run). Parallel
//! work gets a rayon pool of its own, built for the call and dropped after
//! it: rayon's global pool is a set of threads that a `fork`ed child does
//! not inherit, so a child that used it after the parent had would wait
//! forever for threads that do not exist (a `ProcessPoolExecutor`
//! with the `fork` start method).
//!
//! On a signal the call raises at once and sets the work's [`Cancel`]
//! flag. Work that checks it ([`Cancel::check`], the simulator's per-trial
//! tick) stops there: each of its threads parks for good at its next check,
//! so no further trial starts (an unwinding panic would not do: rayon still
//! starts every queued trial, each running to its first check). The parked
//! threads (the pool's and the worker) stay idle until the process exits.
//! Work without checks (one checker run, one solver call) finishes in the
//! background and its result is dropped.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

use pyo3::prelude::*;

use crate::{panic_error, InternalError};

/// How often a waiting call checks for signals.
pub const POLL: Duration = Duration::from_millis(50);

/// Set when the caller was interrupted.
#[derive(Default)]
pub struct Cancel(AtomicBool);

impl Cancel {
    /// Parks the calling thread for good once cancelled (see the module docs).
    pub fn check(&self) {
        while self.0.load(Ordering::Relaxed) {
            std::thread::park();
        }
    }
}

/// Waits up to [`POLL`] for the worker's answer with the GIL released.
fn wait<T: Send>(py: Python<'_>, rx: Receiver<T>) -> (Receiver<T>, Result<T, RecvTimeoutError>) {
    py.detach(move || {
        let r = rx.recv_timeout(POLL);
        (rx, r)
    })
}

/// Runs `f` on a worker thread (with `parallel`, on a fresh rayon pool:
/// work that uses rayon) and waits for it, checking for signals every
/// [`POLL`]. On a signal (KeyboardInterrupt), sets the [`Cancel`] flag and
/// raises the signal's exception at once. A panic in `f` is an
/// [`InternalError`].
pub fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    parallel: bool,
    f: impl FnOnce(&Cancel) -> T + Send + 'static,
) -> PyResult<T> {
    let cancel = Arc::new(Cancel::default());
    let (tx, mut rx) = mpsc::channel();
    let flag = Arc::clone(&cancel);
    std::thread::Builder::new()
        .name("gaze-lidar-call".into())
        .spawn(move || {
            let out = catch_unwind(AssertUnwindSafe(|| {
                if !parallel {
                    return Ok(f(&flag));
                }
                rayon::ThreadPoolBuilder::new()
                    .thread_name(|i| format!("gaze-lidar-{i}"))
                    .build()
                    .map(|pool| pool.install(|| f(&flag)))
            }));
            // The caller may have stopped listening (interrupted).
            let _ = tx.send(out);
        })
        .map_err(|e| InternalError::new_err(format!("internal error: no worker thread: {e}")))?;
    loop {
        let (back, got) = wait(py, rx);
        rx = back;
        match got {
            Ok(Ok(Ok(v))) => return Ok(v),
            Ok(Ok(Err(e))) => {
                return Err(InternalError::new_err(format!(
                    "internal error: no thread pool: {e}"
                )))
            }
            Ok(Err(p)) => return Err(panic_error(p)),
            Err(RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    cancel.0.store(true, Ordering::Relaxed);
                    return Err(e);
                }
            }
            Err(RecvTimeoutError::Disconnected) => {
                return Err(InternalError::new_err(
                    "internal error: the worker thread ended without an answer",
                ))
            }
        }
    }
}
