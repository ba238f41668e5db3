//! Errors as the Python exceptions the package documents, with the CLI's
//! one-line messages in Python's terms: `ValueError` for bad arguments and
//! arrays, `OSError` subclasses for files (`FileNotFoundError`,
//! `PermissionError`, `FileFormatError` for malformed content),
//! `RuntimeError` for failures while running, `KeyboardInterrupt`.

use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyIsADirectoryError, PyKeyboardInterrupt, PyNotADirectoryError, PyOSError, PyPermissionError,
    PyRuntimeError, PyValueError,
};
use pyo3::PyErr;
use topovox_job::JobError;

pyo3::create_exception!(_topovox, FileFormatError, PyOSError, "A file's content does not follow its format (the message names the file).");
/// A message in Python's terms: the command line's `--voxel-size` is the
/// keyword `voxel_size`.
pub(crate) fn python_terms(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let flag = &rest[at + 2..];
        let end = flag.find(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).unwrap_or(flag.len());
        // A flag starts a word ("give --voxel-size"); a "--" inside a word
        // (a file name such as "a--b.obj") is left as it is.
        let starts_word = out.chars().last().is_none_or(|c| !(c.is_alphanumeric() || "-_./\\".contains(c)));
        if end > 0 && flag.as_bytes()[0].is_ascii_lowercase() && starts_word {
            out.push_str(&flag[..end].replace('-', "_"));
        } else {
            out.push_str("--");
            out.push_str(&flag[..end]);
        }
        rest = &flag[end..];
    }
    out.push_str(rest);
    out
}

/// A [`JobError`] as the Python exception the package documents.
pub(crate) fn py_err(e: JobError) -> PyErr {
    match e {
        JobError::Invalid(m) => PyValueError::new_err(python_terms(&m)),
        JobError::Failed(m) => PyRuntimeError::new_err(m),
        JobError::Io(io) => io_err(io),
        JobError::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
    }
}

pub(crate) fn io_err(e: topovox_io::IoError) -> PyErr {
    use std::io::ErrorKind as K;
    let msg = e.to_string();
    match &e.kind {
        topovox_io::ErrorKind::Read(x) | topovox_io::ErrorKind::Write(x) => match x.kind() {
            K::NotFound => PyFileNotFoundError::new_err(msg),
            K::PermissionDenied => PyPermissionError::new_err(msg),
            K::IsADirectory => PyIsADirectoryError::new_err(msg),
            K::NotADirectory => PyNotADirectoryError::new_err(msg),
            K::AlreadyExists => PyFileExistsError::new_err(msg),
            _ => PyOSError::new_err(msg),
        },
        topovox_io::ErrorKind::TooLargeToRead { .. } => pyo3::exceptions::PyMemoryError::new_err(msg),
        _ => FileFormatError::new_err(msg),
    }
}

pub(crate) fn value_err(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}
