//! Output files of a command, all or nothing, never over an input.
//!
//! A command declares every path it reads ([`Outputs::input`]) and every
//! path it writes ([`Outputs::file`], [`Outputs::folder`] for a folder of
//! known file names) before it does any work; [`Outputs::check`] then
//! refuses (exit 2, naming the options) an output that
//!
//! - cannot be written (a directory, a missing or read-only folder, a
//!   dangling link, a socket or block device),
//! - is the same file as another output (plot file names included), or
//! - is the same file as an input — through symbolic or hard links too:
//!   files are compared by device and inode, paths that do not exist yet by
//!   their canonical folder.
//!
//! - is a folder of outputs and also another output's path (or lies
//!   inside it): `--certificate nx --out nx`, or
//! - is `-` where stdout is not free: `-` means stdout for a file output
//!   (one output at most, and not when the command prints its own data
//!   there, [`Outputs::claim_stdout`]); a folder cannot be `-`.
//!
//! At the end, [`Outputs::commit`] checks again, creates the missing
//! folders, writes every regular file to a temporary file in its own
//! folder, then the command's stdout data ([`Outputs::stdout`]) and any
//! device or FIFO output (in place), and only when all of that is written
//! renames the files into place (keeping a hard-linked backup of each file
//! it replaces, restored if a later rename fails). A failure before the
//! renames (a full disk, stdout or an output on a full device) leaves every
//! old output as it was, no temporary file and no folder this run created.

use std::fs::OpenOptions;
use std::io::{self, ErrorKind, Write};
use std::path::{Component, Path, PathBuf};

use super::CliError;

/// What an output path is.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Target {
    /// A regular file (existing or new): replaced atomically. The path is
    /// the final one (symbolic links resolved, so a link is kept).
    Regular(PathBuf),
    /// A character device or a FIFO: written in place.
    Special(PathBuf),
}

/// The identity of a file: (device, inode) when it exists, else its
/// normalized absolute path.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Key {
    Node(u64, u64),
    Path(PathBuf),
}

fn out_err(path: &Path, msg: impl std::fmt::Display) -> CliError {
    CliError::input(format!("{}: {msg}", path.display()))
}

/// `path` made absolute with its longest existing ancestor canonicalized
/// and the rest of it resolved lexically.
fn normalized(path: &Path) -> PathBuf {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()
            .unwrap_or_else(|_| PathBuf::from("/"))
            .join(path)
    };
    let mut base = abs.as_path();
    let mut rest: Vec<Component<'_>> = Vec::new();
    loop {
        if let Ok(c) = std::fs::canonicalize(base) {
            let mut out = c;
            for comp in rest.iter().rev() {
                match comp {
                    Component::CurDir => {}
                    Component::ParentDir => {
                        out.pop();
                    }
                    other => out.push(other.as_os_str()),
                }
            }
            return out;
        }
        match (base.parent(), base.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                base = parent;
            }
            _ => return abs,
        }
    }
}

fn key_of(path: &Path) -> Key {
    match std::fs::metadata(path) {
        Ok(m) => node_key(&m).unwrap_or_else(|| Key::Path(normalized(path))),
        Err(_) => Key::Path(normalized(path)),
    }
}

#[cfg(unix)]
fn node_key(m: &std::fs::Metadata) -> Option<Key> {
    use std::os::unix::fs::MetadataExt;
    Some(Key::Node(m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn node_key(_m: &std::fs::Metadata) -> Option<Key> {
    None
}

/// Classifies `path` and checks that it can be written, without changing
/// anything: an existing regular file must be writable; a new file's folder
/// must exist (or be `pending`: a folder this command creates, normalized) and accept
/// a new file; directories, sockets and block devices are refused.
fn classify(path: &Path, pending: &[PathBuf]) -> Result<Target, CliError> {
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
            let dir = parent_of(path);
            if pending.iter().any(|p| *p == normalized(dir)) {
                // The folder is created at commit; it was checked as a folder.
                return Ok(Target::Regular(path.to_path_buf()));
            }
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

fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
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

/// A folder of outputs: it exists and accepts files, or its nearest
/// existing ancestor is a folder that does. Returns whether it must be
/// created.
fn check_folder(label: &str, dir: &Path) -> Result<bool, CliError> {
    let bad = |m: String| CliError::input(format!("{label} {}: {m}", dir.display()));
    let mut probe = dir;
    let mut missing = false;
    loop {
        match std::fs::metadata(probe) {
            Ok(m) if m.is_dir() => break,
            Ok(_) => return Err(bad(format!("{} is not a directory", probe.display()))),
            Err(e) if matches!(e.kind(), ErrorKind::NotFound | ErrorKind::NotADirectory) => {
                missing = true;
                probe = parent_of(probe);
            }
            Err(e) => return Err(bad(e.to_string())),
        }
    }
    tempfile::Builder::new()
        .prefix(".gaze-lidar-check")
        .tempdir_in(probe)
        .map(drop)
        .map_err(|e| bad(format!("cannot create files in {}: {e}", probe.display())))?;
    Ok(missing)
}

/// One declared output file.
struct Declared {
    /// The option that names it (`--out`, `--plots DIR`).
    label: String,
    path: PathBuf,
    bytes: Option<Vec<u8>>,
}

/// The outputs of one command (see the module documentation).
#[derive(Default)]
pub struct Outputs {
    inputs: Vec<(String, PathBuf)>,
    folders: Vec<(String, PathBuf)>,
    files: Vec<Declared>,
    /// Who writes to stdout: the command itself (a description) or a file
    /// option given `-`, in the order they were declared.
    stdout_claims: Vec<String>,
    /// The bytes for stdout, written after staging and before the renames.
    stdout: Option<Vec<u8>>,
}

/// The path that means stdout for an output option.
fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// A checked output, ready to stage.
struct Checked {
    index: usize,
    target: Target,
}

impl Outputs {
    /// Declares a file the command reads (`-`, stdin, is ignored).
    pub fn input(&mut self, label: &str, path: &Path) -> &mut Self {
        if path.as_os_str() != "-" {
            self.inputs.push((label.to_owned(), path.to_path_buf()));
        }
        self
    }

    /// Declares an optional input.
    pub fn input_opt(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.input(label, p);
        }
        self
    }

    /// Declares that the command prints its own data on stdout (`what`,
    /// e.g. "the results table"): no output option may then be `-`.
    pub fn claim_stdout(&mut self, what: &str) -> &mut Self {
        self.stdout_claims.push(what.to_owned());
        self
    }

    /// The command's stdout data, written with the files (see the module
    /// documentation); also what a file option given `-` receives.
    pub fn stdout(&mut self, bytes: impl Into<Vec<u8>>) {
        self.stdout = Some(bytes.into());
    }

    /// Declares an output file (`-`: stdout).
    pub fn file(&mut self, label: &str, path: &Path) -> &mut Self {
        if is_stdout(path) {
            self.stdout_claims.push(format!("{label} -"));
            return self;
        }
        self.files.push(Declared {
            label: label.to_owned(),
            path: path.to_path_buf(),
            bytes: None,
        });
        self
    }

    /// Declares an optional output file.
    pub fn file_opt(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.file(label, p);
        }
        self
    }

    /// Declares a folder of output files with these names (created if missing).
    pub fn folder(&mut self, label: &str, dir: &Path, names: &[String]) -> &mut Self {
        self.folders.push((label.to_owned(), dir.to_path_buf()));
        for name in names {
            self.files.push(Declared {
                label: label.to_owned(),
                path: dir.join(name),
                bytes: None,
            });
        }
        self
    }

    /// The contents of a declared output.
    ///
    /// # Panics
    /// If `path` was not declared (a bug in the command).
    pub fn set(&mut self, path: &Path, bytes: impl Into<Vec<u8>>) {
        if is_stdout(path) {
            self.stdout(bytes);
            return;
        }
        let d = self
            .files
            .iter_mut()
            .find(|d| d.path == path)
            .expect("output declared before it is set");
        d.bytes = Some(bytes.into());
    }

    /// Checks every declared output (see the module documentation);
    /// changes nothing.
    pub fn check(&self) -> Result<(), CliError> {
        self.checked().map(drop)
    }

    fn checked(&self) -> Result<(Vec<Checked>, Vec<PathBuf>), CliError> {
        if let [first, second, ..] = self.stdout_claims.as_slice() {
            return Err(CliError::input(format!(
                "{second}: stdout already carries {first}: give a file"
            )));
        }
        let mut create = Vec::new();
        for (label, dir) in &self.folders {
            if is_stdout(dir) {
                return Err(CliError::input(format!(
                    "{label} -: a folder of files cannot go to stdout: give a folder"
                )));
            }
            if check_folder(label, dir)? {
                create.push(dir.clone());
            }
        }
        // A folder of outputs is no other output's path, nor inside one
        // (`--certificate nx --out nx`): compared as normalized paths, so
        // through links too.
        for (label, dir) in &self.folders {
            let folder = normalized(dir);
            for d in &self.files {
                if d.label == *label && d.path.parent() == Some(dir.as_path()) {
                    continue;
                }
                let file = normalized(&d.path);
                if folder.starts_with(&file) {
                    return Err(CliError::input(format!(
                        "{label} {}: the same path as {} {}: given for two outputs",
                        dir.display(),
                        d.label,
                        d.path.display()
                    )));
                }
            }
        }
        let pending: Vec<PathBuf> = create.iter().map(|d| normalized(d)).collect();
        let inputs: Vec<(&str, &Path, Key)> = self
            .inputs
            .iter()
            .filter(|(_, p)| std::fs::metadata(p).is_ok_and(|m| m.is_file()))
            .map(|(l, p)| (l.as_str(), p.as_path(), key_of(p)))
            .collect();
        let mut seen: Vec<(usize, Key)> = Vec::new();
        let mut checked = Vec::new();
        for (index, d) in self.files.iter().enumerate() {
            let target = classify(&d.path, &pending)?;
            let key = key_of(&d.path);
            if let Some((j, _)) = seen.iter().find(|(_, k)| *k == key) {
                let other = &self.files[*j];
                return Err(CliError::input(format!(
                    "{} {}: the same file as {} {}: given for two outputs",
                    d.label,
                    d.path.display(),
                    other.label,
                    other.path.display()
                )));
            }
            if matches!(target, Target::Regular(_)) {
                if let Some((label, path, _)) = inputs.iter().find(|(_, _, k)| *k == key) {
                    return Err(CliError::input(format!(
                        "{} {}: the same file as the input {label} {}: an output never replaces an input",
                        d.label,
                        d.path.display(),
                        path.display()
                    )));
                }
            }
            seen.push((index, key));
            checked.push(Checked { index, target });
        }
        Ok((checked, create))
    }

    /// Writes them all, or none (see the module documentation).
    ///
    /// # Panics
    /// If an output was declared but not [`set`](Self::set) (a bug).
    pub fn commit(self) -> Result<(), CliError> {
        let (checked, create) = self.checked()?;
        let mut created: Vec<PathBuf> = Vec::new();
        let result = self.stage_and_replace(&checked, &create, &mut created);
        if result.is_err() {
            // Folders this run created, if still empty.
            for dir in created.iter().rev() {
                let _ = std::fs::remove_dir(dir);
            }
        }
        result
    }

    fn stage_and_replace(
        &self,
        checked: &[Checked],
        create: &[PathBuf],
        created: &mut Vec<PathBuf>,
    ) -> Result<(), CliError> {
        for dir in create {
            // Every missing ancestor, outermost first, so each can be removed.
            let mut missing: Vec<&Path> = Vec::new();
            let mut p = dir.as_path();
            while std::fs::metadata(p).is_err() {
                missing.push(p);
                p = parent_of(p);
            }
            for m in missing.into_iter().rev() {
                std::fs::create_dir(m)
                    .map_err(|e| CliError::output(format!("{}: {e}", m.display())))?;
                created.push(m.to_path_buf());
            }
        }
        let mut staged = Vec::new();
        let mut special = Vec::new();
        for c in checked {
            let d = &self.files[c.index];
            let bytes = d
                .bytes
                .as_deref()
                .expect("every declared output is set before commit");
            match &c.target {
                Target::Regular(real) => staged.push((d, real, stage(&d.path, real, bytes)?)),
                Target::Special(p) => special.push((p, bytes)),
            }
        }
        // Stdout, devices and FIFOs after staging, before any rename: a
        // failure here (stdout or `--out /dev/full` on a full device) leaves
        // every file as it was.
        if let Some(bytes) = &self.stdout {
            let mut out = super::io::Stdout::new();
            out.bytes(bytes)?;
            out.finish()?;
        }
        for (path, bytes) in special {
            write_special(path, bytes)?;
        }
        // Replace: keep a hard-linked backup of each replaced file until
        // every rename has succeeded.
        let mut done: Vec<(&Path, Previous)> = Vec::new();
        for (d, real, tmp) in staged {
            let previous = backup_of(real);
            if let Err(e) = tmp.persist(real) {
                let err = CliError::output(format!("{}: {}", d.path.display(), e.error));
                for (path, previous) in done.into_iter().rev() {
                    previous.restore(path);
                }
                return Err(err);
            }
            done.push((real, previous));
        }
        drop(done);
        Ok(())
    }
}

/// What a replaced output was.
enum Previous {
    /// No file: the new one is removed on rollback.
    None,
    /// A hard link to the old file (removed when dropped).
    Saved(tempfile::TempPath),
    /// A file that could not be linked (a file system without hard links):
    /// it cannot be put back.
    Lost,
}

impl Previous {
    /// Puts the old file back (best effort: the error being reported is
    /// the original one).
    fn restore(self, real: &Path) {
        match self {
            Self::None => {
                let _ = std::fs::remove_file(real);
            }
            Self::Saved(backup) => {
                let _ = backup.persist(real);
            }
            Self::Lost => {}
        }
    }
}

/// A hard link to `real` under a fresh temporary name in its folder.
fn backup_of(real: &Path) -> Previous {
    if !std::fs::symlink_metadata(real).is_ok_and(|m| m.is_file()) {
        return Previous::None;
    }
    let link = || -> Option<tempfile::TempPath> {
        // A fresh unique name: create it, remove it, link to it.
        let name = tempfile::Builder::new()
            .prefix(".gaze-lidar-backup")
            .tempfile_in(parent_of(real))
            .ok()?
            .into_temp_path();
        let path = name.to_path_buf();
        name.close().ok()?;
        std::fs::hard_link(real, &path).ok()?;
        tempfile::TempPath::try_from_path(path).ok()
    };
    link().map_or(Previous::Lost, Previous::Saved)
}

fn stage(path: &Path, real: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile, CliError> {
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
    let mut tmp = builder
        .tempfile_in(parent_of(real))
        .map_err(|e| out_err(path, e))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_resolves_missing_tails_lexically() {
        let dir = tempfile::tempdir().unwrap();
        let real = std::fs::canonicalize(dir.path()).unwrap();
        assert_eq!(normalized(&dir.path().join("a/./b/../c")), real.join("a/c"));
        assert_eq!(normalized(dir.path()), real);
    }
}
