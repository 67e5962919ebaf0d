//! Errors that stop a run of the command (exit code 2, or 1 for a row that failed), each naming the file, line and column
//! where it applies: the core's typed errors converted once, and the command's own (I/O, input
//! data, usage).

use std::fmt;

use verne::error::MachineError;
use verne::verify::PairingError;

/// A fatal error of a run.
#[derive(Debug)]
pub enum VerneError {
    /// Malformed input data: file, 1-based line and column (when known) and what was expected.
    Input {
        file: String,
        line: Option<u64>,
        column: Option<String>,
        message: String,
    },
    /// A machine file with one or more problems.
    Machine(MachineError),
    /// An operating-system error on a named file (or `<stdout>`).
    Io { file: String, error: std::io::Error },
    /// A bad command-line value.
    Usage(String),
    /// A row the output cannot do without has no answer (an unreachable pose in a joint
    /// program): the run stops there, writes nothing to a file, and exits 1 (a row failed), not
    /// 2. Its text is an [`VerneError::Input`]'s.
    RowFailed(Box<VerneError>),
}

impl VerneError {
    pub fn input(
        file: &str,
        line: Option<u64>,
        column: Option<&str>,
        message: impl Into<String>,
    ) -> Self {
        VerneError::Input {
            file: file.to_string(),
            line,
            column: column.map(str::to_string),
            message: message.into(),
        }
    }

    pub fn io(file: &str, error: std::io::Error) -> Self {
        VerneError::Io {
            file: file.to_string(),
            error,
        }
    }

    /// The exit code of the run it ends: 1 for a row that failed, 2 for the rest.
    pub fn exit_code(&self) -> u8 {
        match self {
            VerneError::RowFailed(_) => crate::cmd::EXIT_ROWS_FAILED,
            _ => crate::cmd::EXIT_FATAL,
        }
    }

    /// True for a write to a closed pipe (`verne ik ... | head`), which is not an error.
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, VerneError::Io { error, .. } if error.kind() == std::io::ErrorKind::BrokenPipe)
    }
}

impl fmt::Display for VerneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VerneError::Input {
                file,
                line,
                column,
                message,
            } => {
                write!(f, "{file}")?;
                if let Some(l) = line {
                    write!(f, ":{l}")?;
                }
                if let Some(c) = column {
                    write!(f, ": column {c}")?;
                }
                write!(f, ": {message}")
            }
            VerneError::Machine(e) => write!(f, "{e}"),
            VerneError::Io { file, error } => write!(f, "{file}: {error}"),
            VerneError::Usage(m) => f.write_str(m),
            VerneError::RowFailed(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for VerneError {}

impl From<MachineError> for VerneError {
    fn from(e: MachineError) -> Self {
        VerneError::Machine(e)
    }
}

impl From<PairingError> for VerneError {
    fn from(e: PairingError) -> Self {
        VerneError::input(e.file(), Some(e.line()), e.column(), e.to_string())
    }
}
