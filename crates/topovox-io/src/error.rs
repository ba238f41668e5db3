//! The one error type of topovox-io: the file, and what is wrong with it.

use std::path::{Path, PathBuf};

/// A failure reading or writing a file: `"{path}: {kind}"`.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", path.display())]
pub struct IoError {
    /// The file concerned.
    pub path: PathBuf,
    /// What went wrong.
    pub kind: ErrorKind,
}

impl IoError {
    /// Attaches a path to an error kind.
    pub fn new(path: &Path, kind: ErrorKind) -> IoError {
        IoError { path: path.to_path_buf(), kind }
    }
}

/// What went wrong, without the file name.
#[derive(Debug, thiserror::Error)]
pub enum ErrorKind {
    /// The file could not be read.
    #[error("cannot read: {0}")]
    Read(std::io::Error),
    /// The file could not be written.
    #[error("cannot write: {0}")]
    Write(std::io::Error),
    /// The extension names no supported format.
    #[error("unknown file extension {ext:?} (expected one of: {expected})")]
    UnknownFormat {
        /// The extension found.
        ext: String,
        /// The supported ones.
        expected: &'static str,
    },
    /// The content does not follow the format.
    #[error("malformed {format} file: {detail}")]
    Malformed {
        /// Format name.
        format: &'static str,
        /// What is wrong and where.
        detail: String,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate ({value})")]
    NonFinite {
        /// Vertex index (0-based).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A vertex coordinate lies past ±[`topovox::COORDINATE_LIMIT`].
    #[error("vertex {index} has the coordinate {value:e}, past ±2^100 (1.27e30), the range topovox computes in; scale the mesh first")]
    OutOfRange {
        /// Vertex index (0-based).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {index}, but there are only {count} vertices")]
    IndexOutOfRange {
        /// Face index (0-based, after triangulation).
        face: usize,
        /// The index found.
        index: i64,
        /// Number of vertices.
        count: usize,
    },
    /// A segment refers to a vertex that does not exist.
    #[error("segment {line} refers to vertex {index}, but there are only {count} vertices")]
    SegmentIndexOutOfRange {
        /// Segment index (0-based, after splitting polylines).
        line: usize,
        /// The index found.
        index: i64,
        /// Number of vertices.
        count: usize,
    },
    /// The file holds no triangles (and no line segments).
    #[error("contains no triangles or line segments")]
    Empty,
    /// The data is valid but uses something topovox does not support.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The file describes a grid whose dense storage does not fit in memory
    /// (a few bytes can claim billions of voxels).
    #[error("its {dims:?} grid needs {need} of memory, but only {available} is available")]
    TooLarge {
        /// The grid's dims.
        dims: [u32; 3],
        /// Bytes needed, human-readable.
        need: String,
        /// Bytes available, human-readable.
        available: String,
    },
    /// Reading the mesh would hold more memory than a read may take
    /// (counted from the file before parsing).
    #[error("reading it needs about {need} of memory, more than the {available} a read may take; raise --max-memory or simplify the mesh")]
    TooLargeToRead {
        /// Bytes needed, human-readable.
        need: String,
        /// Bytes a read may take, human-readable.
        available: String,
    },
}

impl ErrorKind {
    /// A malformed-file error; multi-line messages from parsers are folded
    /// onto one line.
    pub(crate) fn malformed(format: &'static str, detail: impl std::fmt::Display) -> ErrorKind {
        let detail = detail.to_string().split('\n').map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join("; ");
        // A file's content never makes a message long (a 100 MB header line).
        ErrorKind::Malformed { format, detail: cut(&detail, MAX_MESSAGE) }
    }
}

/// The most characters of a message or warning that quotes a file's content.
pub(crate) const MAX_MESSAGE: usize = 300;

/// `s`, cut to `max` characters with `…` where it was cut.
pub(crate) fn cut(s: &str, max: usize) -> String {
    match s.char_indices().nth(max) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

/// Text from a file or a user, quoted for a message: at most 40
/// characters of it (and its length when cut).
pub fn quoted(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{:?}… ({} bytes)", &s[..i], s.len()),
        None => format!("{s:?}"),
    }
}
