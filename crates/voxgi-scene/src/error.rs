use std::path::PathBuf;

/// Why a scene could not be loaded or used.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read or parsed; `reason` says what was wrong with it.
    #[error("{}: {reason}", path.display())]
    Load { path: PathBuf, reason: String },
    /// The scene's data breaks an invariant (indices out of range, non-finite values, ...).
    #[error("invalid scene: {0}")]
    Invalid(String),
    /// An unknown built-in scene name.
    #[error("unknown built-in scene '{name}' (available: {available})")]
    UnknownBuiltin { name: String, available: String },
}

impl SceneError {
    pub fn load(path: impl Into<PathBuf>, reason: impl std::fmt::Display) -> Self {
        SceneError::Load {
            path: path.into(),
            reason: reason.to_string(),
        }
    }

    /// Attaches a file name to an `Invalid` error found while validating that file's scene.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            SceneError::Invalid(reason) => SceneError::Load {
                path: path.into(),
                reason,
            },
            other => other,
        }
    }
}
