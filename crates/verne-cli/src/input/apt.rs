//! Reader of APT cutter-location (CL) files: the tool-tip positions and tool axes of `GOTO` and
//! `FROM` records, streamed from a `BufRead` with one reused line buffer and one reused record
//! buffer (no allocation per row).
//!
//! Accepted syntax (ANSI X3.37 / ISO 3592 style, as written by CAM post-processors):
//! - one record per line, `NAME/arg,arg,...` or `NAME`; a line whose content ends with `$`
//!   continues on the next line (the `$` is dropped); `$$` starts a comment that runs to the end
//!   of the line;
//! - `GOTO/x,y,z` and, with `MULTAX` on, `GOTO/x,y,z,i,j,k`: (i, j, k) is the tool axis, from the
//!   tip towards the spindle, in the workpiece frame. With `MULTAX` off a GOTO has 3 values, or
//!   6 (the axis is then taken as given); with it on, exactly 6;
//! - `MULTAX`, `MULTAX/ON` switch the 6-value mode on, `MULTAX/OFF` off;
//! - `FROM/x,y,z[,i,j,k]`: the start point. It is returned as a row (kind [`MotionKind::From`]):
//!   the machine has to stand there, so its joints must exist and the path's branch choice
//!   starts from it. A caller that does not want it can skip rows of that kind;
//! - `PARTNO`, `PPRINT`, `REMARK`, `INSERT`: the rest of the line is free text (never continued);
//! - `FINI` ends the program: anything after it is not read;
//! - every other record (`UNITS`, `LOADTL`, `FEDRAT`, `RAPID`, `SPINDL`, `CUTTER`, ...) is
//!   skipped and counted per record name in [`AptSummary::skipped`].
//!
//! Errors carry the 1-based line and column and what was expected: a bad number, a missing
//! field, too many fields, an unterminated continuation at the end of the file.

use std::collections::BTreeMap;
use std::fmt;
use std::io::BufRead;

use nalgebra::Vector3;

/// Records whose argument is free text, not continued and not parsed.
const TEXT_RECORDS: [&str; 4] = ["PARTNO", "PPRINT", "REMARK", "INSERT"];

/// Names of the values of a GOTO or FROM, in order.
const FIELD_NAMES: [&str; 6] = ["x", "y", "z", "i", "j", "k"];

/// Which record produced a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    /// `FROM/...`: the start point.
    From,
    /// `GOTO/...`: a point of the tool path.
    Goto,
}

/// One tool position read from the file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AptRow {
    /// The record kind.
    pub kind: MotionKind,
    /// 1-based line of the record's first line.
    pub line: usize,
    /// Tool tip (x, y, z) in the workpiece frame (file units).
    pub tip: Vector3<f64>,
    /// Tool axis (i, j, k) as written (not normalised), None for a 3-value record.
    pub axis: Option<Vector3<f64>>,
}

/// What the reader saw besides the rows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AptSummary {
    /// GOTO rows returned.
    pub goto_rows: usize,
    /// FROM rows returned.
    pub from_rows: usize,
    /// Lines that held only a `$$` comment.
    pub comment_lines: usize,
    /// Skipped records per record name (upper case), free-text records included.
    pub skipped: BTreeMap<String, usize>,
    /// 1-based line of `FINI`, if it was reached.
    pub fini_line: Option<usize>,
}

/// What went wrong in a CL file.
#[derive(Debug, Clone, PartialEq)]
pub enum AptErrorKind {
    /// Reading failed (I/O error or invalid UTF-8).
    Io(String),
    /// A value of a GOTO/FROM is not a finite decimal number.
    BadNumber {
        /// Which value (x, y, z, i, j, k).
        field: &'static str,
        /// The text found.
        found: String,
    },
    /// Too few values.
    MissingField {
        /// The first missing value.
        field: &'static str,
        /// How many values the record needs.
        expected: &'static str,
        /// How many it has.
        found: usize,
    },
    /// Too many values.
    TooManyFields {
        /// How many values the record may have.
        expected: &'static str,
        /// How many it has.
        found: usize,
    },
    /// MULTAX with an argument other than ON or OFF.
    BadMultax {
        /// The argument found.
        found: String,
    },
    /// The file ends on a line continued with `$`.
    UnterminatedContinuation,
}

/// An error at a place in a CL file.
#[derive(Debug, Clone, PartialEq)]
pub struct AptError {
    /// 1-based line.
    pub line: usize,
    /// 1-based column (bytes) within that line.
    pub column: usize,
    /// The record name (`GOTO`, `FROM`, `MULTAX`), empty when not known.
    pub record: &'static str,
    /// What went wrong.
    pub kind: AptErrorKind,
}

impl fmt::Display for AptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}, column {}: ", self.line, self.column)?;
        if !self.record.is_empty() {
            write!(f, "{}: ", self.record)?;
        }
        match &self.kind {
            AptErrorKind::Io(e) => write!(f, "cannot read: {e}"),
            AptErrorKind::BadNumber { field, found } => {
                if found.is_empty() {
                    write!(f, "empty value for {field}, expected a number")
                } else {
                    write!(
                        f,
                        "bad number `{found}` for {field}, expected a finite decimal number"
                    )
                }
            }
            AptErrorKind::MissingField {
                field,
                expected,
                found,
            } => write!(
                f,
                "missing value {field}: expected {expected} values, found {found}"
            ),
            AptErrorKind::TooManyFields { expected, found } => {
                write!(f, "expected {expected} values, found {found}")
            }
            AptErrorKind::BadMultax { found } => {
                write!(
                    f,
                    "expected MULTAX, MULTAX/ON or MULTAX/OFF, found `{found}`"
                )
            }
            AptErrorKind::UnterminatedContinuation => f.write_str(
                "the file ends inside a record continued with `$`: expected a continuation line",
            ),
        }
    }
}

impl std::error::Error for AptError {}

/// A piece of a logical record: where it starts in the record and in the file.
#[derive(Debug, Clone, Copy)]
struct Segment {
    record_start: usize,
    line: usize,
    /// 1-based column of the piece's first byte.
    column: usize,
}

/// Streaming CL reader; see the module documentation for the syntax.
pub struct AptReader<R> {
    input: R,
    line: String,
    record: String,
    segments: Vec<Segment>,
    line_no: usize,
    /// Where the pending continuation `$` is (line, column), when a record is continued.
    pending: Option<(usize, usize)>,
    multax: bool,
    done: bool,
    summary: AptSummary,
}

impl<R: BufRead> AptReader<R> {
    /// A reader over `input`, MULTAX off.
    pub fn new(input: R) -> AptReader<R> {
        AptReader {
            input,
            line: String::new(),
            record: String::new(),
            segments: Vec::new(),
            line_no: 0,
            pending: None,
            multax: false,
            done: false,
            summary: AptSummary::default(),
        }
    }

    /// What was seen so far besides the rows.
    pub fn summary(&self) -> &AptSummary {
        &self.summary
    }

    /// Whether MULTAX is on at this point of the file.
    pub fn multax(&self) -> bool {
        self.multax
    }

    /// The next GOTO or FROM row; None at FINI or at the end of the file.
    pub fn next_row(&mut self) -> Result<Option<AptRow>, AptError> {
        while !self.done {
            if !self.read_record()? {
                self.done = true;
                break;
            }
            if let Some(row) = self.process_record()? {
                match row.kind {
                    MotionKind::Goto => self.summary.goto_rows += 1,
                    MotionKind::From => self.summary.from_rows += 1,
                }
                return Ok(Some(row));
            }
        }
        Ok(None)
    }

    /// Reads one logical record into `self.record`; false at the end of the file.
    fn read_record(&mut self) -> Result<bool, AptError> {
        self.record.clear();
        self.segments.clear();
        self.pending = None;
        loop {
            self.line.clear();
            let n = self.input.read_line(&mut self.line).map_err(|e| AptError {
                line: self.line_no + 1,
                column: 1,
                record: "",
                kind: AptErrorKind::Io(e.to_string()),
            })?;
            if n == 0 {
                return match self.pending {
                    Some((line, column)) => Err(AptError {
                        line,
                        column,
                        record: "",
                        kind: AptErrorKind::UnterminatedContinuation,
                    }),
                    None => Ok(false),
                };
            }
            self.line_no += 1;
            let mut text = self.line.trim_end_matches(['\n', '\r']);
            let mut offset = 0;
            if self.line_no == 1
                && let Some(rest) = text.strip_prefix('\u{feff}')
            {
                text = rest;
                offset = '\u{feff}'.len_utf8();
            }
            let lead = text.len() - text.trim_start().len();
            let body = &text[lead..];
            if self.pending.is_none() {
                let name = record_name(body);
                if TEXT_RECORDS.iter().any(|t| name.eq_ignore_ascii_case(t)) {
                    count(&mut self.summary.skipped, name);
                    continue;
                }
            }
            // Strip a `$$` comment, then look for a continuation `$`.
            let content = match body.find("$$") {
                Some(i) => &body[..i],
                None => body,
            }
            .trim_end();
            let column = 1 + offset + lead;
            if let Some(head) = content.strip_suffix('$') {
                self.segments.push(Segment {
                    record_start: self.record.len(),
                    line: self.line_no,
                    column,
                });
                self.record.push_str(head);
                self.pending = Some((self.line_no, column + head.len()));
                continue;
            }
            if content.is_empty() {
                // A blank or comment-only line, also allowed between continued lines.
                if body.starts_with("$$") {
                    self.summary.comment_lines += 1;
                }
                continue;
            }
            self.segments.push(Segment {
                record_start: self.record.len(),
                line: self.line_no,
                column,
            });
            self.record.push_str(content);
            return Ok(true);
        }
    }

    /// (line, column) of a byte offset in the current record.
    fn place(&self, offset: usize) -> (usize, usize) {
        let seg = self
            .segments
            .iter()
            .rev()
            .find(|s| s.record_start <= offset)
            .or(self.segments.first())
            .copied()
            .unwrap_or(Segment {
                record_start: 0,
                line: self.line_no,
                column: 1,
            });
        (
            seg.line,
            seg.column + offset.saturating_sub(seg.record_start),
        )
    }

    fn error(&self, offset: usize, record: &'static str, kind: AptErrorKind) -> AptError {
        let (line, column) = self.place(offset);
        AptError {
            line,
            column,
            record,
            kind,
        }
    }

    /// Interprets the record in `self.record`: a row, or None for a skipped record.
    fn process_record(&mut self) -> Result<Option<AptRow>, AptError> {
        let rec = self.record.as_str();
        let (name, args_at) = match rec.find('/') {
            Some(i) => (rec[..i].trim(), Some(i + 1)),
            None => (rec.trim(), None),
        };
        let kind = if name.eq_ignore_ascii_case("GOTO") {
            MotionKind::Goto
        } else if name.eq_ignore_ascii_case("FROM") {
            MotionKind::From
        } else if name.eq_ignore_ascii_case("MULTAX") {
            let arg = args_at.map(|i| rec[i..].trim()).unwrap_or("");
            if arg.is_empty() || arg.eq_ignore_ascii_case("ON") {
                self.multax = true;
            } else if arg.eq_ignore_ascii_case("OFF") {
                self.multax = false;
            } else {
                let s = args_at.unwrap_or(rec.len());
                let at = s + (rec[s..].len() - rec[s..].trim_start().len());
                return Err(self.error(
                    at,
                    "MULTAX",
                    AptErrorKind::BadMultax {
                        found: arg.to_string(),
                    },
                ));
            }
            return Ok(None);
        } else if name.eq_ignore_ascii_case("FINI") {
            self.summary.fini_line = Some(self.segments.first().map_or(self.line_no, |s| s.line));
            self.done = true;
            return Ok(None);
        } else {
            count(&mut self.summary.skipped, name);
            return Ok(None);
        };
        let record: &'static str = match kind {
            MotionKind::Goto => "GOTO",
            MotionKind::From => "FROM",
        };
        let expected: &'static str = match (kind, self.multax) {
            (MotionKind::Goto, true) => "6 (x,y,z,i,j,k: MULTAX is on)",
            _ => "3 or 6 (x,y,z[,i,j,k])",
        };
        let Some(start) = args_at else {
            return Err(self.error(
                rec.len(),
                record,
                AptErrorKind::MissingField {
                    field: "x",
                    expected,
                    found: 0,
                },
            ));
        };
        let mut values = [0.0f64; 6];
        let mut found = 0;
        let mut at = start;
        for field in rec[start..].split(',') {
            if found == 6 {
                return Err(self.error(
                    at,
                    record,
                    AptErrorKind::TooManyFields {
                        expected,
                        found: rec[start..].split(',').count(),
                    },
                ));
            }
            let lead = field.len() - field.trim_start().len();
            let text = field.trim();
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => values[found] = v,
                _ => {
                    return Err(self.error(
                        at + lead,
                        record,
                        AptErrorKind::BadNumber {
                            field: FIELD_NAMES[found],
                            found: text.to_string(),
                        },
                    ));
                }
            }
            found += 1;
            at += field.len() + 1;
        }
        let need_six = kind == MotionKind::Goto && self.multax;
        if found < 3 || (found < 6 && (need_six || found > 3)) {
            return Err(self.error(
                rec.trim_end().len(),
                record,
                AptErrorKind::MissingField {
                    field: FIELD_NAMES[found],
                    expected,
                    found,
                },
            ));
        }
        let line = self.segments.first().map_or(self.line_no, |s| s.line);
        Ok(Some(AptRow {
            kind,
            line,
            tip: Vector3::new(values[0], values[1], values[2]),
            axis: (found == 6).then(|| Vector3::new(values[3], values[4], values[5])),
        }))
    }
}

impl<R: BufRead> Iterator for AptReader<R> {
    type Item = Result<AptRow, AptError>;

    /// Rows until FINI or the end of the file; after an error, None.
    fn next(&mut self) -> Option<Self::Item> {
        match self.next_row() {
            Ok(Some(row)) => Some(Ok(row)),
            Ok(None) => None,
            Err(e) => {
                self.done = true;
                Some(Err(e))
            }
        }
    }
}

/// The record name: the text before `/` (or before the first blank for free-text records).
fn record_name(body: &str) -> &str {
    let end = body
        .find(|c: char| c == '/' || c.is_whitespace() || c == ',')
        .unwrap_or(body.len());
    &body[..end]
}

/// Counts a skipped record, allocating only for a name not seen before.
fn count(map: &mut BTreeMap<String, usize>, name: &str) {
    let name = name.trim();
    if let Some(n) = map.get_mut(name) {
        *n += 1;
    } else {
        *map.entry(name.to_ascii_uppercase()).or_insert(0) += 1;
    }
}

/// A CL file read as CSV text (`line,kind,x,y,z,i,j,k`), so that `verne ik` streams it through
/// the same row engine as a CSV file. A 3-value GOTO gets the axis (0, 0, 1). The reader's
/// summary (skipped records) is shared through `summary`.
pub struct AptAsCsv<R> {
    reader: AptReader<R>,
    buf: Vec<u8>,
    pos: usize,
    header_done: bool,
    finished: bool,
    summary: std::sync::Arc<std::sync::Mutex<AptSummary>>,
}

impl<R: BufRead> AptAsCsv<R> {
    pub fn new(input: R) -> AptAsCsv<R> {
        AptAsCsv {
            reader: AptReader::new(input),
            buf: Vec::with_capacity(256),
            pos: 0,
            header_done: false,
            finished: false,
            summary: Default::default(),
        }
    }

    /// The reader's summary, updated as rows are read.
    pub fn summary(&self) -> std::sync::Arc<std::sync::Mutex<AptSummary>> {
        self.summary.clone()
    }

    fn refill(&mut self) -> std::io::Result<()> {
        use std::io::Write;
        self.buf.clear();
        self.pos = 0;
        if !self.header_done {
            self.header_done = true;
            self.buf.extend_from_slice(b"line,kind,x,y,z,i,j,k\n");
            return Ok(());
        }
        if self.finished {
            return Ok(());
        }
        let row = self.reader.next_row();
        if let Ok(mut s) = self.summary.lock() {
            *s = self.reader.summary().clone();
        }
        match row {
            Ok(Some(r)) => {
                let a = r.axis.unwrap_or(Vector3::new(0.0, 0.0, 1.0));
                let kind = match r.kind {
                    MotionKind::From => "FROM",
                    MotionKind::Goto => "GOTO",
                };
                writeln!(
                    self.buf,
                    "{},{kind},{},{},{},{},{},{}",
                    r.line, r.tip.x, r.tip.y, r.tip.z, a.x, a.y, a.z
                )
            }
            Ok(None) => {
                self.finished = true;
                Ok(())
            }
            Err(e) => {
                self.finished = true;
                Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    e.to_string(),
                ))
            }
        }
    }
}

impl<R: BufRead> std::io::Read for AptAsCsv<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        while self.pos >= self.buf.len() {
            if self.finished && self.header_done {
                return Ok(0);
            }
            self.refill()?;
        }
        let n = out.len().min(self.buf.len() - self.pos);
        out[..n].copy_from_slice(&self.buf[self.pos..self.pos + n]);
        self.pos += n;
        Ok(n)
    }
}
