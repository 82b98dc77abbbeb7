//! The report format of a verdict, shared by `check` on a profile and on a
//! firmware table (`table`), so neither module reaches into the other for it.

use clap::ValueEnum;

/// Report format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// One line per violation (or a certified summary).
    Text,
    /// `{"certified": bool, "violations": [...], "summary": {...}}`.
    Json,
}
