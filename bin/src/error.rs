//! Errors of the command line, each with its exit status.

/// What went wrong, sorted by who can fix it.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad arguments or input files: exit status 2.
    #[error("{0}")]
    Input(String),
    /// A computation failed numerically: exit status 1.
    #[error("{0}")]
    Numerical(String),
}

impl CliError {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Numerical(_) => 1,
        }
    }
}
