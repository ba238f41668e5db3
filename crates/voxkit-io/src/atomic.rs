//! Write-to-temporary-then-rename, so a failed write never leaves a
//! half-written output.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{ErrorKind, IoError};

/// Creates a temporary file beside `path`, lets `fill` write into it, then
/// renames it onto `path`. On any error the temporary file is removed and
/// `path` is untouched.
pub fn write_atomically(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<(), IoError> {
    let err = |e| IoError::new(path, ErrorKind::Write(e));
    let tmp = temp_path(path);
    let file = File::create(&tmp).map_err(err)?;
    let mut w = BufWriter::with_capacity(1 << 20, file);
    let result = fill(&mut w).and_then(|_| w.flush());
    drop(w);
    let result = result.and_then(|_| std::fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(err(e));
    }
    Ok(())
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.voxkit-tmp-{}", std::process::id()))
}
