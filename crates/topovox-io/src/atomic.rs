//! Writing outputs without ever losing what the user has.
//!
//! - A regular file (or a new one) is written to a temporary file beside
//!   it and renamed over it, so a failed write never leaves a half-written
//!   output. A symbolic link to a regular file is followed: the file it
//!   names is replaced, the link stays.
//! - Anything else that exists — `/dev/null`, `/dev/stdout`, a FIFO, a
//!   terminal — is written directly, as a careful Unix tool does: renaming
//!   over it would replace the device node or pipe with a regular file.
//!   Write errors are reported (`/dev/full`: no space left on device).
//! - `-` is standard output.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{ErrorKind, IoError};

/// Where [`write_atomically`] puts the bytes for `path`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// Standard output (`-`).
    Stdout,
    /// An existing file that is not a regular file (a device, a FIFO):
    /// written in place.
    Special(PathBuf),
    /// A regular file, new or existing (symbolic links resolved): a
    /// temporary file beside it, renamed over it.
    Regular(PathBuf),
}

/// How `path` will be written.
pub fn target(path: &Path) -> Target {
    if path.as_os_str() == "-" {
        return Target::Stdout;
    }
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => Target::Special(path.to_path_buf()),
        Ok(m) if m.is_file() => Target::Regular(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())),
        _ => Target::Regular(path.to_path_buf()),
    }
}

/// Writes `path` through `fill` as [`Target`] says: atomically for regular
/// files (on any error the temporary file is removed and `path` is
/// untouched), directly for special files and standard output.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<(), IoError> {
    let err = |e| IoError::new(path, ErrorKind::Write(e));
    match target(path) {
        Target::Stdout => {
            let out = std::io::stdout();
            let mut w = BufWriter::with_capacity(1 << 20, out.lock());
            fill(&mut w).and_then(|_| w.flush()).map_err(err)
        }
        Target::Special(p) => {
            let file = std::fs::OpenOptions::new().write(true).open(&p).map_err(err)?;
            let mut w = BufWriter::with_capacity(1 << 20, file);
            fill(&mut w).and_then(|_| w.flush()).map_err(err)
        }
        Target::Regular(real) => {
            let tmp = temp_path(&real);
            let file = File::create(&tmp).map_err(err)?;
            let mut w = BufWriter::with_capacity(1 << 20, file);
            let result = fill(&mut w).and_then(|_| w.flush());
            drop(w);
            let result = result.and_then(|_| std::fs::rename(&tmp, &real));
            if let Err(e) = result {
                let _ = std::fs::remove_file(&tmp);
                return Err(err(e));
            }
            Ok(())
        }
    }
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.topovox-tmp-{}", std::process::id()))
}

/// The same file by identity (device and inode on Unix; the resolved path
/// elsewhere), whatever the spelling: symbolic links, `./`, hard links.
/// `false` if either does not exist.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// Refuses to write `output` over any of `inputs` (the files a job reads:
/// a mesh, its material libraries and textures, a voxel file): one line
/// naming both.
pub fn refuse_overwriting_inputs(output: &Path, inputs: &[PathBuf]) -> Result<(), IoError> {
    for input in inputs {
        if same_file(output, input) {
            return Err(IoError::new(
                output,
                ErrorKind::Write(std::io::Error::other(format!(
                    "it is the same file as the input {}; refusing to overwrite it",
                    input.display()
                ))),
            ));
        }
    }
    Ok(())
}
