//! I/O of the command line: size-limited input, stdout that is quiet on a
//! closed pipe and loud on any other failure, and outputs that never destroy
//! data (atomic over regular files, direct onto devices and FIFOs, every
//! path of a multi-output command checked and staged before anything is
//! replaced).

use std::fs::{File, OpenOptions};
use std::io::{self, ErrorKind, Read, Write};
use std::path::{Path, PathBuf};

use super::CliError;

/// Largest profile JSON accepted (a 10^6-bin profile is ≈ 200 MB pretty-printed).
pub const MAX_PROFILE_BYTES: u64 = 512 << 20;
/// Largest TOML configuration accepted (scenario, optimizer).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// Reads `path` (`-` for stdin) as UTF-8 text of at most `limit` bytes
/// (see [`read_bytes`]).
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

/// The bytes read from `path` as UTF-8 text (an error names the offset).
pub fn utf8(bytes: Vec<u8>, path: &Path) -> Result<String, CliError> {
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

/// What an output path is.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Target {
    /// A regular file (existing or new): replaced atomically. The path is
    /// the final one (symbolic links resolved, so a link is kept).
    Regular(PathBuf),
    /// A character device or a FIFO: written in place.
    Special(PathBuf),
}

fn out_err(path: &Path, msg: impl std::fmt::Display) -> CliError {
    CliError::input(format!("{}: {msg}", path.display()))
}

/// Classifies `path` and checks that it can be written, without changing
/// anything: an existing regular file must be writable; a new file's folder
/// must exist and accept a new file; directories, sockets and block devices
/// are refused.
fn classify(path: &Path) -> Result<Target, CliError> {
    if path.as_os_str().is_empty() {
        return Err(CliError::input("output path is empty"));
    }
    match std::fs::metadata(path) {
        Ok(meta) => {
            let ft = meta.file_type();
            if ft.is_dir() {
                return Err(out_err(path, "is a directory"));
            }
            if ft.is_file() {
                // Opening for writing without truncation changes nothing.
                OpenOptions::new()
                    .write(true)
                    .open(path)
                    .map_err(|e| out_err(path, e))?;
                let real = std::fs::canonicalize(path).map_err(|e| out_err(path, e))?;
                check_dir_writable(path, real.parent().unwrap_or(Path::new("/")))?;
                return Ok(Target::Regular(real));
            }
            #[cfg(unix)]
            {
                use std::os::unix::fs::FileTypeExt;
                if ft.is_char_device() || ft.is_fifo() {
                    return Ok(Target::Special(path.to_path_buf()));
                }
                if ft.is_block_device() {
                    return Err(out_err(
                        path,
                        "is a block device; refusing to write a report over it",
                    ));
                }
                if ft.is_socket() {
                    return Err(out_err(path, "is a socket; cannot write to it"));
                }
            }
            Err(out_err(path, "is not a regular file, device or FIFO"))
        }
        Err(e) if e.kind() == ErrorKind::NotFound => {
            if std::fs::symlink_metadata(path).is_ok() {
                return Err(out_err(path, "is a dangling symbolic link"));
            }
            let dir = match path.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            match std::fs::metadata(dir) {
                Ok(m) if m.is_dir() => {}
                Ok(_) => return Err(out_err(path, "parent is not a directory")),
                Err(e) => {
                    return Err(out_err(
                        path,
                        format!("parent folder {}: {e}", dir.display()),
                    ))
                }
            }
            check_dir_writable(path, dir)?;
            Ok(Target::Regular(path.to_path_buf()))
        }
        Err(e) => Err(out_err(path, e)),
    }
}

/// The folder must accept a new (temporary) file: creates one and removes it.
fn check_dir_writable(path: &Path, dir: &Path) -> Result<(), CliError> {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    tempfile::Builder::new()
        .prefix(".gaze-lidar-check")
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| {
            out_err(
                path,
                format!("cannot create a file in {}: {e}", dir.display()),
            )
        })
}

/// Checks that every path can be written (see [`Outputs`]); nothing changes.
pub fn validate_paths<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<(), CliError> {
    let mut seen: Vec<PathBuf> = Vec::new();
    for p in paths {
        let t = classify(p)?;
        let key = match t {
            Target::Regular(p) | Target::Special(p) => p,
        };
        if seen.contains(&key) {
            return Err(out_err(p, "given for two outputs"));
        }
        seen.push(key);
    }
    Ok(())
}

/// Several outputs of one command, all or nothing: every path is checked,
/// every regular file is written to a temporary file next to it, and only
/// when all of them are ready are they renamed into place (and devices and
/// FIFOs written). A failure before that point replaces nothing.
#[derive(Default)]
pub struct Outputs {
    items: Vec<(PathBuf, Vec<u8>)>,
}

impl Outputs {
    /// Queues `bytes` for `path`.
    pub fn add(&mut self, path: &Path, bytes: impl Into<Vec<u8>>) {
        self.items.push((path.to_path_buf(), bytes.into()));
    }

    /// Writes them all.
    pub fn commit(self) -> Result<(), CliError> {
        let mut staged = Vec::new();
        let mut special = Vec::new();
        let mut seen: Vec<PathBuf> = Vec::new();
        for (path, bytes) in self.items {
            let target = classify(&path)?;
            let key = match &target {
                Target::Regular(p) | Target::Special(p) => p.clone(),
            };
            if seen.contains(&key) {
                return Err(out_err(&path, "given for two outputs"));
            }
            seen.push(key);
            match target {
                Target::Regular(real) => {
                    let tmp = stage(&path, &real, &bytes)?;
                    staged.push((path, real, tmp));
                }
                Target::Special(p) => special.push((p, bytes)),
            }
        }
        for (path, real, tmp) in staged {
            tmp.persist(&real).map_err(|e| out_err(&path, e.error))?;
        }
        for (path, bytes) in special {
            write_special(&path, &bytes)?;
        }
        Ok(())
    }
}

fn stage(path: &Path, real: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile, CliError> {
    let dir = match real.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".gaze-lidar-out");
    // Ordinary output files: readable by others (tempfile defaults to 0600);
    // an existing file keeps its mode.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(real)
            .map(|m| m.permissions().mode() & 0o7777)
            .unwrap_or(0o644);
        builder.permissions(std::fs::Permissions::from_mode(mode));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(|e| out_err(path, e))?;
    let write_err = |e: io::Error| CliError::output(format!("{}: {e}", path.display()));
    tmp.write_all(bytes).map_err(write_err)?;
    tmp.as_file().sync_all().map_err(write_err)?;
    Ok(tmp)
}

fn write_special(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let mut f = OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| out_err(path, e))?;
    match f.write_all(bytes).and_then(|()| f.flush()) {
        Ok(()) => Ok(()),
        // The reader of a FIFO went away: as on stdout, not an error.
        Err(e) if e.kind() == ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(CliError::output(format!("{}: {e}", path.display()))),
    }
}

/// Writes one output (see [`Outputs`]).
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let mut o = Outputs::default();
    o.add(path, bytes);
    o.commit()
}
