//! [`SweepError`]: every way an episode's evaluation or a sweep can fail, with the
//! [`Context`] extension that names what was being done (`reading grid.toml: …`).
//!
//! A contextual error displays its own message; its cause is its `source()`, so a
//! front end that prints the chain (`{e:#}` through `anyhow`) prints
//! `what was being done: why`.

use std::fmt::Display;

/// Boxed cause of an error.
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// An error of nbv-sweep.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// What was being done, and the error that stopped it.
    #[error("{context}")]
    Context {
        /// What was being done.
        context: String,
        /// Why it failed.
        #[source]
        source: BoxError,
    },
    /// Bad input or a state the sweep cannot go on from (the message says which).
    #[error("{0}")]
    Invalid(String),
    /// A scene failed to load, validate or generate.
    #[error(transparent)]
    Scene(#[from] nbv_scenes::SceneError),
    /// A scene override or a scene name is bad.
    #[error(transparent)]
    Override(#[from] nbv_scenes::overrides::OverrideError),
    /// A picture could not be drawn.
    #[error(transparent)]
    Render(#[from] nbv_sim::render::RenderError),
    /// The CSV writer failed.
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// JSON (de)serialisation.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// The pipeline failed.
    #[error(transparent)]
    Explore(#[from] nbv_core::pipeline::PipelineError),
    /// The next-best-view parameters are bad.
    #[error(transparent)]
    Nbv(#[from] nbv_core::nbv::NbvError),
    /// The rig failed.
    #[error(transparent)]
    Rig(#[from] nbv_core::rig::RigError),
    /// A registration could not be applied to its views (an object's model).
    #[error("an object's model: {0}")]
    Registration(#[from] nbv_core::registration::RegistrationError),
    /// A point cloud could not be written.
    #[error(transparent)]
    Cloud(#[from] nbv_core::cloud::io::CloudIoError),
    /// Another library's error.
    #[error(transparent)]
    Other(BoxError),
}

impl From<std::string::FromUtf8Error> for SweepError {
    fn from(e: std::string::FromUtf8Error) -> Self {
        Self::Other(Box::new(e))
    }
}

/// `Result` of nbv-sweep.
pub type Result<T, E = SweepError> = std::result::Result<T, E>;

/// Adds what was being done to an error.
pub trait Context<T> {
    /// Wraps the error with `context`.
    fn context<C: Display>(self, context: C) -> Result<T>;
    /// Wraps the error with the context `f` makes (only on failure).
    fn with_context<C: Display, F: FnOnce() -> C>(self, f: F) -> Result<T>;
}

impl<T, E: Into<BoxError>> Context<T> for std::result::Result<T, E> {
    fn context<C: Display>(self, context: C) -> Result<T> {
        self.map_err(|e| SweepError::Context {
            context: context.to_string(),
            source: e.into(),
        })
    }

    fn with_context<C: Display, F: FnOnce() -> C>(self, f: F) -> Result<T> {
        self.map_err(|e| SweepError::Context {
            context: f().to_string(),
            source: e.into(),
        })
    }
}

impl<T> Context<T> for Option<T> {
    fn context<C: Display>(self, context: C) -> Result<T> {
        self.ok_or_else(|| SweepError::Invalid(context.to_string()))
    }

    fn with_context<C: Display, F: FnOnce() -> C>(self, f: F) -> Result<T> {
        self.ok_or_else(|| SweepError::Invalid(f().to_string()))
    }
}

/// Returns early with [`SweepError::Invalid`] of a formatted message.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err($crate::error::SweepError::Invalid(format!($($arg)*)))
    };
}
pub(crate) use bail;

/// A [`SweepError::Invalid`] of a formatted message.
macro_rules! invalid {
    ($($arg:tt)*) => {
        $crate::error::SweepError::Invalid(format!($($arg)*))
    };
}
pub(crate) use invalid;
