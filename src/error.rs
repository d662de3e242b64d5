//! The crate's one error type. Every fallible public function returns `Result<_, Error>`.
//!
//! Messages are written for the person at the machine: they name the record or line that is
//! wrong, the value found and what was expected, so the input can be fixed without reading
//! the source.

use thiserror::Error;

/// Everything that can go wrong in tspath, by the stage that found it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Error {
    /// A model file could not be parsed. `location` names the line or record.
    #[error("{format} parse error at {location}: {message}")]
    Parse {
        format: &'static str,
        location: String,
        message: String,
    },

    /// The file parsed, but the T-mesh it describes is not valid.
    #[error("invalid T-mesh: {0}")]
    InvalidMesh(String),

    /// The geometry is valid but a feature of it is not supported by this version.
    #[error("unsupported model: {0}")]
    Unsupported(String),

    /// A user-supplied option is out of its meaningful range.
    #[error("invalid parameter `{name}`: {message}")]
    InvalidParameter { name: &'static str, message: String },

    /// A computation failed on degenerate geometry (zero-length derivative, singular
    /// normal, ...). `location` says where on the model.
    #[error("degenerate geometry at {location}: {message}")]
    Degenerate { location: String, message: String },

    /// A machine cannot do what the path asks (axis travel, unreachable tool axis, a rotary
    /// jump forced by limits). `location` names the move.
    #[error("machine error at {location}: {message}")]
    Machine { location: String, message: String },

    /// No sample model of that name exists.
    #[error("unknown sample model `{0}` (see `tspath sample --list`)")]
    UnknownSample(String),

    /// The operation was cancelled by the caller.
    #[error("cancelled")]
    Cancelled,

    /// Reading or writing a file failed (command-line front end only).
    #[error("{0}")]
    Io(String),
}

impl Error {
    /// Shorthand for a parse error.
    pub fn parse(
        format: &'static str,
        location: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse {
            format,
            location: location.into(),
            message: message.into(),
        }
    }

    /// Shorthand for an invalid-parameter error.
    pub fn param(name: &'static str, message: impl Into<String>) -> Self {
        Error::InvalidParameter {
            name,
            message: message.into(),
        }
    }
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, Error>;
