//! I/O of the command line: size-limited input, stdout that is quiet on a
//! closed pipe and loud on any other failure. Output files:
//! [`output`](super::output).

use std::fs::File;
use std::io::{self, ErrorKind, Read, Write};
use std::path::Path;

use super::CliError;

/// Largest profile JSON accepted (a 10^6-bin profile is ≈ 200 MB pretty-printed).
pub const MAX_PROFILE_BYTES: u64 = 512 << 20;
/// Largest TOML configuration accepted (scenario, optimizer).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The UTF-8 byte-order mark: refused by name at the start of a text file
/// (JSON and TOML are BOM-less UTF-8; a parser would only say "1:1").
pub const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// Reads `path` (`-` for stdin) as UTF-8 text of at most `limit` bytes
/// (see [`read_bytes`]; a leading byte-order mark is refused by name).
pub fn read_text(path: &Path, limit: u64) -> Result<String, CliError> {
    utf8(read_bytes(path, limit)?, path)
}

fn input_name(path: &Path) -> String {
    if path.as_os_str() == "-" {
        "<stdin>".to_owned()
    } else {
        path.display().to_string()
    }
}

/// The bytes read from `path` as UTF-8 text: a leading byte-order mark is
/// refused by name, an invalid byte by its offset.
pub fn utf8(bytes: Vec<u8>, path: &Path) -> Result<String, CliError> {
    if bytes.starts_with(UTF8_BOM) {
        return Err(CliError::input(format!(
            "{}: starts with a UTF-8 byte-order mark (bytes EF BB BF): save the file without a BOM",
            input_name(path)
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        CliError::input(format!(
            "{}: not UTF-8 text (invalid byte at offset {})",
            input_name(path),
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Reads `path` (`-` for stdin): at most `limit` bytes.
///
/// A regular file larger than the limit is refused before it is read; any
/// other input (stdin, a FIFO, a character device such as `/dev/zero`) is
/// read up to the limit and refused past it, so an endless input ends.
pub fn read_bytes(path: &Path, limit: u64) -> Result<Vec<u8>, CliError> {
    let name = input_name(path);
    let fail = |e: io::Error| CliError::input(format!("{name}: {e}"));
    let too_big = || {
        CliError::input(format!(
            "{name}: larger than the {limit}-byte limit for this input"
        ))
    };
    let mut bytes = Vec::new();
    if path.as_os_str() == "-" {
        io::stdin()
            .lock()
            .take(limit + 1)
            .read_to_end(&mut bytes)
            .map_err(fail)?;
    } else {
        let file = File::open(path).map_err(fail)?;
        let meta = file.metadata().map_err(fail)?;
        if meta.is_dir() {
            return Err(CliError::input(format!("{name}: is a directory")));
        }
        if meta.is_file() && meta.len() > limit {
            return Err(too_big());
        }
        file.take(limit + 1).read_to_end(&mut bytes).map_err(fail)?;
    }
    if bytes.len() as u64 > limit {
        return Err(too_big());
    }
    Ok(bytes)
}

/// Standard output for a command's data: locked, quiet once the reader has
/// gone (a closed pipe ends the output, not the command), any other write
/// error is an error (exit 1).
pub struct Stdout {
    inner: io::StdoutLock<'static>,
    closed: bool,
}

impl Default for Stdout {
    fn default() -> Self {
        Self::new()
    }
}

impl Stdout {
    /// Locks stdout.
    pub fn new() -> Self {
        Self {
            inner: io::stdout().lock(),
            closed: false,
        }
    }

    /// Writes bytes (no-op once the pipe is closed).
    pub fn bytes(&mut self, b: &[u8]) -> Result<(), CliError> {
        if self.closed {
            return Ok(());
        }
        let r = self.inner.write_all(b);
        self.check(r)
    }

    /// Writes a line.
    pub fn line(&mut self, s: impl std::fmt::Display) -> Result<(), CliError> {
        if self.closed {
            return Ok(());
        }
        let r = writeln!(self.inner, "{s}");
        self.check(r)
    }

    /// Flushes; call before returning success.
    pub fn finish(mut self) -> Result<(), CliError> {
        if self.closed {
            return Ok(());
        }
        let r = self.inner.flush();
        self.check(r)
    }

    fn check(&mut self, r: io::Result<()>) -> Result<(), CliError> {
        match r {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == ErrorKind::BrokenPipe => {
                self.closed = true;
                Ok(())
            }
            Err(e) => {
                // Do not let the runtime retry the flush at exit.
                self.closed = true;
                Err(CliError::output(format!("stdout: {e}")))
            }
        }
    }
}

/// A line on stderr (a closed or failing stderr is ignored: never a panic).
pub fn warn(s: impl std::fmt::Display) {
    let _ = writeln!(io::stderr().lock(), "gaze-lidar: {s}");
}
