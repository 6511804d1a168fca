//! Errors of the command line, each with its exit status (see [`EXIT_STATUS`]).

/// The exit-status rule of every command, as `--help` and README.md state it.
pub const EXIT_STATUS: &str = "\
Exit status (every command):
  0    success; a study (compare, converge, stability, reproduce) that ran, even
       with failed or unstable variants (marked in its table)
  1    `run`: the run failed numerically or its verdict is UNSTABLE;
       a study with --strict and a failed or unstable variant
  2    bad input: usage, scene, mesh or option errors (nothing was run), or an
       output file that cannot be written
  130  interrupted (SIGINT/SIGTERM): `run` finishes the current step, writes its
       files and summary (marked interrupted); a second signal exits at once, as
       does the first during the set-up (before the first step); `compare` stops
       its runs after their step and prints the table of what ran
  141  `run`: standard output was closed by its reader (a broken pipe); the run
       stops quietly as on an interrupt";

/// What went wrong, sorted by who can fix it.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// Bad arguments or input files: exit status 2.
    #[error("{0}")]
    Input(String),
    /// A computation failed numerically or was judged unstable: exit status 1.
    #[error("{0}")]
    Numerical(String),
    /// Stopped by SIGINT or SIGTERM: exit status 130.
    #[error("interrupted")]
    Interrupted,
    /// The reader of standard output went away: exit status 141, no message.
    #[error("broken pipe")]
    BrokenPipe,
}

impl CliError {
    /// The process exit status for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Input(_) => 2,
            CliError::Numerical(_) => 1,
            CliError::Interrupted => 130,
            CliError::BrokenPipe => 141,
        }
    }

    /// Whether the error is reported on stderr (a closed pipe is not).
    pub fn quiet(&self) -> bool {
        matches!(self, CliError::BrokenPipe)
    }
}

/// The end of a study with `failed` of `total` variants failed or unstable: an error
/// (status 1) only with `--strict`.
pub fn study_verdict(strict: bool, failed: usize, total: usize) -> Result<(), CliError> {
    if strict && failed > 0 {
        Err(CliError::Numerical(format!(
            "--strict: {failed} of {total} variants failed or are unstable (see the table)"
        )))
    } else {
        Ok(())
    }
}
