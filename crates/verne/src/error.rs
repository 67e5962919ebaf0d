//! The core's errors: the problems of a machine file, every one with its line, reported at once,
//! and how a piece of user input is quoted in a message ([`shown`]).
//! (Errors of the other modules are typed where they arise: [`crate::machine::PathError`],
//! [`crate::machine::orientation::AxisError`], [`crate::verify::PairingError`],
//! [`crate::glider::GliderSpecError`].)

use std::fmt;

/// One problem found in a machine file.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// 1-based line in the file, when the problem can be placed on one.
    pub line: Option<usize>,
    /// The dotted key concerned (`module.R1`), empty for a syntax error.
    pub key: String,
    pub message: String,
}

/// Every problem found in one machine file.
#[derive(Debug, Clone, PartialEq)]
pub struct MachineError {
    /// The file name as the user gave it (or `<default>`).
    pub source: String,
    pub problems: Vec<Problem>,
}

impl fmt::Display for MachineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.problems.len();
        write!(
            f,
            "invalid machine file {}: {} problem{}",
            self.source,
            n,
            if n == 1 { "" } else { "s" }
        )?;
        for p in &self.problems {
            write!(f, "\n  {}", self.source)?;
            if let Some(line) = p.line {
                write!(f, ":{line}")?;
            }
            if p.key.is_empty() {
                write!(f, ": {}", p.message)?;
            } else {
                write!(f, ": {}: {}", p.key, p.message)?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for MachineError {}

/// Longest piece of input quoted in a message (characters).
pub const MESSAGE_CHARS: usize = 120;

/// Text with its control characters (NUL, BEL, ESC, ...) escaped (`\u{1b}`), so that input
/// quoted in a message is never echoed raw to a terminal. Every message that quotes input
/// goes through it ([`shown`] too).
pub fn escape_controls(text: &str) -> String {
    if !text.chars().any(char::is_control) {
        return text.to_string();
    }
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// Input bytes as they may be quoted in a message: control characters and invalid UTF-8
/// escaped, long text shortened.
pub fn shown(bytes: &[u8]) -> String {
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => escape_controls(t),
        Err(_) => bytes.escape_ascii().to_string(),
    };
    if text.chars().count() > MESSAGE_CHARS {
        let head: String = text.chars().take(MESSAGE_CHARS).collect();
        format!("{head}... ({} bytes)", bytes.len())
    } else {
        text
    }
}
