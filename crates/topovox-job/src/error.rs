//! One error type for jobs: what the caller got wrong, what the files
//! said, and what failed while running.

/// Why a job could not run.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// An option or a combination of options is invalid (a bad argument).
    #[error("{0}")]
    Invalid(String),
    /// Reading or writing a file failed; the error names the file.
    #[error(transparent)]
    Io(#[from] topovox_io::IoError),
    /// The job was valid but could not be carried out (no GPU, not enough
    /// memory, a device error).
    #[error("{0}")]
    Failed(String),
    /// The caller asked the job to stop ([`topovox::voxelize::Stop`]);
    /// whatever it had done was discarded, nothing was written.
    #[error("interrupted")]
    Interrupted,
}

impl JobError {
    /// An [`JobError::Invalid`] with this message.
    pub fn invalid(msg: impl Into<String>) -> JobError {
        JobError::Invalid(msg.into())
    }

    /// A [`JobError::Failed`] with this message.
    pub fn failed(msg: impl Into<String>) -> JobError {
        JobError::Failed(msg.into())
    }
}

/// Result of a job step.
pub type Result<T> = std::result::Result<T, JobError>;

/// Returns early with [`JobError::Invalid`] and a formatted message.
#[macro_export]
macro_rules! invalid {
    ($($t:tt)*) => { return Err($crate::JobError::Invalid(format!($($t)*))) };
}

impl From<topovox::choice::UnknownChoice> for JobError {
    fn from(e: topovox::choice::UnknownChoice) -> JobError {
        JobError::Invalid(e.to_string())
    }
}
