//! External files a model names (OBJ `mtllib` and `map_Kd`, glTF buffer and
//! image URIs): where they may be read from, and which were read.
//!
//! By default only files inside the model's folder (and its subfolders) are
//! read: a reference is resolved against the folder, symbolic links and
//! `..` included, and refused if the real file lies elsewhere — so a model
//! uploaded to a service cannot make it read (or leak) files it never meant
//! to open. [`ReadOptions::allow_external_paths`] lifts this. Whatever the
//! option, only regular files are read: a FIFO or a device named by a
//! model would hang the reader or never end.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// How files are read: one set of options for every reader
/// ([`crate::read_mesh`], [`crate::read_voxels`], [`crate::read_voxels_sparse`],
/// [`crate::read_voxels_bytes`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Read external files a model names wherever they are (absolute paths,
    /// `../` outside the model's folder, links leading out), and voxel
    /// folders through links leading out. Default: off.
    pub allow_external_paths: bool,
    /// The data's up axis: `.vox` and `.schem` files that record none are
    /// rotated back by it. Default: y.
    pub up: crate::orient::Up,
    /// Sparse reads: the attribute grids or arrays too. Default: off.
    pub attributes: bool,
}

/// The model's folder and the files read through it.
pub(crate) struct Resources {
    base: Option<PathBuf>,
    canonical_base: Option<PathBuf>,
    allow: bool,
    used: Mutex<Vec<PathBuf>>,
}

impl Resources {
    /// References resolve against `base`; `None` reads no external file.
    pub fn new(base: Option<&Path>, opts: &ReadOptions) -> Resources {
        let canonical_base = base.and_then(|b| std::fs::canonicalize(if b.as_os_str().is_empty() { Path::new(".") } else { b }).ok());
        Resources { base: base.map(Path::to_path_buf), canonical_base, allow: opts.allow_external_paths, used: Mutex::new(Vec::new()) }
    }

    /// The model's folder, if external files may be read at all.
    pub fn base(&self) -> Option<&Path> {
        self.base.as_deref()
    }

    /// The file a reference names (relative to the model's folder, or
    /// absolute), or why it may not be read. A file that does not exist is
    /// returned as is (reading it fails with its own message).
    pub fn resolve(&self, reference: &Path) -> Result<PathBuf, String> {
        let Some(base) = &self.base else {
            return Err(format!("{} is not read: the model was not read from a folder", reference.display()));
        };
        let joined = base.join(reference);
        let Ok(real) = std::fs::canonicalize(&joined) else {
            return Ok(joined);
        };
        if !self.allow && !self.canonical_base.as_ref().is_some_and(|b| real.starts_with(b)) {
            return Err(format!(
                "{} is outside the model's folder {} and is not read (--allow-external-paths reads it)",
                reference.display(),
                if base.as_os_str().is_empty() { Path::new(".") } else { base }.display()
            ));
        }
        // Only regular files: a FIFO would hang the read, a device such as
        // /dev/zero would never end.
        if std::fs::metadata(&real).is_ok_and(|m| !m.is_file()) {
            return Err(format!("{} is not a regular file (a device, a FIFO or a folder) and is not read", reference.display()));
        }
        self.used.lock().unwrap_or_else(|e| e.into_inner()).push(real.clone());
        Ok(real)
    }

    /// A URI of a glTF document as a path reference (percent-decoded), or
    /// `None` for embedded `data:` URIs.
    pub fn uri_path(uri: &str) -> Option<PathBuf> {
        if uri.starts_with("data:") {
            return None;
        }
        let bytes = uri.as_bytes();
        let mut out = Vec::with_capacity(bytes.len());
        let mut i = 0;
        while i < bytes.len() {
            if bytes[i] == b'%' && i + 2 < bytes.len() {
                if let Ok(v) = u8::from_str_radix(&uri[i + 1..i + 3], 16) {
                    out.push(v);
                    i += 3;
                    continue;
                }
            }
            out.push(bytes[i]);
            i += 1;
        }
        Some(PathBuf::from(String::from_utf8_lossy(&out).into_owned()))
    }

    /// The external files read so far.
    pub fn used(self) -> Vec<PathBuf> {
        self.used.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}
