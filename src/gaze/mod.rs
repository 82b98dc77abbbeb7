//! Gaze input: formats ([`formats`]), filtering ([`filter`]) and the
//! fail-safe state machine ([`failsafe`]). Pure input: nothing here plans or
//! certifies a profile; the real-time driver that turns this input into one
//! certified profile per frame is [`crate::pipeline`].

pub mod failsafe;
pub mod filter;
pub mod formats;

pub use failsafe::{Due, FailSafe, FailSafeConfig, FrameClock, SampleKind, State};
pub use filter::{FilterConfig, GazeFilter};
pub use formats::{Format, GazeSample, LineError, Parser};

/// Gaze input that cannot be used: a malformed line, a read failure or an
/// unusable recording. Always bad input.
#[derive(Debug, thiserror::Error)]
pub enum GazeError {
    /// A malformed line in a recorded file (`origin:line: field …`).
    #[error("{origin}:{line}: {source}")]
    Line {
        /// File name or `<stdin>`.
        origin: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong with it.
        source: LineError,
    },
    /// The input could not be read.
    #[error("{origin}:{line}: {source}")]
    Read {
        /// File name or `<stdin>`.
        origin: String,
        /// 1-based line number.
        line: usize,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A recording whose lines parse but that is unusable as a whole (no
    /// samples, timestamps that decrease).
    #[error("{origin}: {reason}")]
    Recording {
        /// File name.
        origin: String,
        /// What is wrong with it.
        reason: String,
    },
}
