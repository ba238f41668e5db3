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

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Opens `path` for reading if it is a regular file (links followed), with
/// its length: a FIFO would block the read, a device such as `/dev/zero`
/// would never end, a folder cannot be read. Checked before opening (so a
/// FIFO never blocks the open) and again on the opened file.
pub fn open_regular(path: &Path) -> std::io::Result<(File, u64)> {
    let not_regular =
        || std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a regular file (a device, a FIFO, a socket or a folder)");
    if !std::fs::metadata(path)?.is_file() {
        return Err(not_regular());
    }
    let file = File::open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_regular());
    }
    Ok((file, meta.len()))
}

/// Reads a whole file the user named, refusing anything but a regular file
/// (see [`open_regular`]); never more bytes than it had when opened.
pub fn read_regular(path: &Path) -> std::io::Result<Vec<u8>> {
    let (file, len) = open_regular(path)?;
    read_at_most(file, len)
}

/// The first `len` bytes of `file` (fewer if it ends first).
fn read_at_most(file: File, len: u64) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::with_capacity(len as usize);
    std::io::Read::read_to_end(&mut std::io::Read::take(file, len), &mut out)?;
    Ok(out)
}

/// [`read_regular`], refusing before reading a file longer than the
/// memory a read may take (by the rule of the load estimate,
/// `load_estimate::refuse_past`).
pub(crate) fn read_regular_within(path: &Path, opts: &ReadOptions) -> Result<Vec<u8>, crate::ErrorKind> {
    let (file, len) = open_regular(path).map_err(crate::ErrorKind::Read)?;
    crate::load_estimate::refuse_past(len, || opts.read_limit())?;
    read_at_most(file, len).map_err(crate::ErrorKind::Read)
}

/// What a glTF URI names, by RFC 3986: data embedded in the URI, or a file.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum UriTarget {
    /// A `data:` URI (any case of the scheme), spelled as the `gltf` crate
    /// decodes it: `data:` + the rest. It names no file.
    Data(String),
    /// A file: a relative reference (percent-decoded), or a `file:` URI in
    /// any spelling (`file:/x`, `file:///x`, `file://localhost/x`, any case,
    /// percent-encoded) as its absolute path. Either is then read only as
    /// the folder rule allows, like any other reference.
    Path(PathBuf),
}

/// Parses a glTF buffer or image URI. Other schemes (`http:`, `ftp:`, a
/// `file:` URI naming another host) are refused: nothing is fetched.
pub(crate) fn uri_target(uri: &str) -> Result<UriTarget, String> {
    let shown = || crate::error::quoted(uri);
    let Some((scheme, rest)) = split_scheme(uri) else {
        return Ok(UriTarget::Path(percent_decoded(uri)));
    };
    match scheme.to_ascii_lowercase().as_str() {
        "data" => Ok(UriTarget::Data(format!("data:{rest}"))),
        "file" => {
            // file:/path, file:///path, file://localhost/path (RFC 8089).
            let path = match rest.strip_prefix("//") {
                None => rest,
                Some(auth) => {
                    let slash = auth.find('/').unwrap_or(auth.len());
                    let host = &auth[..slash];
                    if !host.is_empty() && !host.eq_ignore_ascii_case("localhost") {
                        return Err(format!(
                            "the URI {} names the host {}, and no file of another host is read",
                            shown(),
                            crate::error::quoted(host)
                        ));
                    }
                    &auth[slash..]
                }
            };
            let path = percent_decoded(path.split(['?', '#']).next().unwrap_or(""));
            if !path.has_root() {
                return Err(format!("the URI {} names no absolute path", shown()));
            }
            Ok(UriTarget::Path(path))
        }
        _ => Err(format!("the URI {} has the scheme {scheme:?}: only data: URIs and files are read", shown())),
    }
}

/// A URI's scheme and the rest, if it has one (`ALPHA *(ALPHA / DIGIT /
/// "+" / "-" / ".") ":"` before any `/`, `?` or `#`). One letter before a
/// colon is a Windows drive (`C:/x`), not a scheme.
fn split_scheme(uri: &str) -> Option<(&str, &str)> {
    let colon = uri.find(':')?;
    let scheme = &uri[..colon];
    let mut chars = scheme.chars();
    let first_ok = chars.next().is_some_and(|c| c.is_ascii_alphabetic());
    let rest_ok = chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    (first_ok && rest_ok && scheme.len() > 1).then(|| (scheme, &uri[colon + 1..]))
}

/// Percent-decodes a URI path into a path (bytes kept as they are on Unix).
fn percent_decoded(s: &str) -> PathBuf {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok()).and_then(|h| u8::from_str_radix(h, 16).ok());
        match (bytes[i], hex) {
            (b'%', Some(v)) => {
                out.push(v);
                i += 3;
            }
            (b, _) => {
                out.push(b);
                i += 1;
            }
        }
    }
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStringExt;
        PathBuf::from(std::ffi::OsString::from_vec(out))
    }
    #[cfg(not(unix))]
    {
        PathBuf::from(String::from_utf8_lossy(&out).into_owned())
    }
}

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
    /// The memory a read may take (`--max-memory`): a mesh whose reading
    /// would hold more is refused before it is parsed. Default: nine
    /// tenths of the available memory.
    pub max_memory: Option<u64>,
}

impl ReadOptions {
    /// The memory a read may take: `max_memory`, else nine tenths of the
    /// available memory (at most the process-wide cap, see
    /// [`crate::set_dense_read_budget`]).
    pub fn read_limit(&self) -> u64 {
        self.max_memory.unwrap_or_else(crate::read_limit)
    }
}

/// The model's folder and the files read through it.
pub(crate) struct Resources {
    base: Option<PathBuf>,
    canonical_base: Option<PathBuf>,
    opts: ReadOptions,
    used: Mutex<Vec<PathBuf>>,
}

impl Resources {
    /// References resolve against `base`; `None` reads no external file.
    pub fn new(base: Option<&Path>, opts: &ReadOptions) -> Resources {
        let canonical_base = base.and_then(|b| std::fs::canonicalize(if b.as_os_str().is_empty() { Path::new(".") } else { b }).ok());
        Resources { base: base.map(Path::to_path_buf), canonical_base, opts: *opts, used: Mutex::new(Vec::new()) }
    }

    /// The memory a read may take (see [`ReadOptions::read_limit`]).
    pub fn read_limit(&self) -> u64 {
        self.opts.read_limit()
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
        if !self.opts.allow_external_paths && !self.canonical_base.as_ref().is_some_and(|b| real.starts_with(b)) {
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

    /// The bytes of a file a model names, read as [`resolve`](Self::resolve)
    /// allows: exactly `len` bytes where the format declares the length (a
    /// glTF buffer's `byteLength`; a shorter file is an error), else the
    /// file as long as it was when opened. Never a byte past either, so a
    /// file that grows (or a `/proc` file, which reports no length) cannot
    /// make the read unbounded. Messages name the reference, never its bytes.
    pub fn read(&self, reference: &Path, len: Option<u64>) -> Result<Vec<u8>, String> {
        let path = self.resolve(reference)?;
        let shown = reference.display();
        let (file, size) = open_regular(&path).map_err(|e| format!("{shown} could not be read ({e})"))?;
        let want = len.unwrap_or(size);
        if want > size {
            return Err(format!("{shown} holds {size} bytes, fewer than the {want} its reference declares"));
        }
        let limit = self.read_limit();
        if want > limit {
            return Err(format!("{shown} is {} long, more than the {} a read may take", crate::bytes(want), crate::bytes(limit)));
        }
        let out = read_at_most(file, want).map_err(|e| format!("{shown} could not be read ({e})"))?;
        if (out.len() as u64) < want {
            return Err(format!("{shown} ended after {} of its {want} bytes", out.len()));
        }
        Ok(out)
    }

    /// The external files read so far.
    pub fn used(self) -> Vec<PathBuf> {
        self.used.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}
