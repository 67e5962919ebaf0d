//! Errors and warnings of the G-code reader.

use std::fmt;

/// An error at a place in a G-code file. Reading stops at the first error.
#[derive(Debug, Clone, PartialEq)]
pub struct GcodeError {
    /// 1-based line of the block; 0 when the error is not about a line (the file cannot be
    /// read).
    pub line: u64,
    /// 1-based column (bytes) of the offending word within the line, where there is one.
    pub column: Option<u64>,
    /// What went wrong and what was expected.
    pub message: String,
}

impl GcodeError {
    pub(crate) fn new(line: u64, column: Option<u64>, message: impl Into<String>) -> GcodeError {
        GcodeError {
            line,
            column,
            message: message.into(),
        }
    }
}

impl fmt::Display for GcodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "line {}", self.line)?;
            if let Some(c) = self.column {
                write!(f, ", column {c}")?;
            }
            f.write_str(": ")?;
        }
        f.write_str(&self.message)
    }
}

impl std::error::Error for GcodeError {}

/// Something the reader did that the user should know, with the line it concerns.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// 1-based line (0: the whole file).
    pub line: u64,
    /// The message.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "line {}: ", self.line)?;
        }
        f.write_str(&self.message)
    }
}
