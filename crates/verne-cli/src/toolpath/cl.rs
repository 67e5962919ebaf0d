//! A CL file's tool poses (the `verne-cl` crate reads every dialect of docs/cl-dialects.md:
//! NX CLSF and listings, Creo, SolidWorks CAM, CATIA, generic APT; units, arcs, cycles, feeds,
//! tools), as typed rows in the columns `line,kind,motion,feed,tool,x,y,z,i,j,k`; the reader's
//! errors keep their line and column to the message.

use std::io::{BufRead, Seek, Write};

use nalgebra::Vector3;
use verne::machine::orientation::ToolOrientation;
use verne_cl::{ClError, Reader, Summary};

use super::{Column, Field, Motion, PoseRow, ReaderReport, ToolpathSource};
use crate::error::VerneError;

/// A CL error as the CLI's input error: file, line, column, what was expected (control bytes
/// of the file shown escaped, never written to the terminal).
pub fn cl_error(file: &str, e: &ClError) -> VerneError {
    let line = (e.line > 0).then_some(e.line);
    let column = e.column.map(|c| c.to_string());
    VerneError::input(
        file,
        line,
        column.as_deref(),
        verne::error::escape_controls(&e.kind.to_string()),
    )
}

/// A seekable buffered input: the reader decides a file's units by a first pass over its
/// records (docs/cl-dialects.md §4) and then reads from the start again.
pub trait SeekableInput: BufRead + Seek + Send {}
impl<T: BufRead + Seek + Send> SeekableInput for T {}

/// A CL reader over a boxed input, as the CLI reads files and streams alike.
pub type ClReader = Reader<Box<dyn SeekableInput>>;

/// The columns of a CL file's rows.
const CL_FIELDS: [Field; 11] = [
    Field::Line,
    Field::Kind,
    Field::Motion,
    Field::Feed,
    Field::Tool,
    Field::X,
    Field::Y,
    Field::Z,
    Field::I,
    Field::J,
    Field::K,
];

/// The tool poses of a CL file.
pub struct ClToolpath {
    reader: ClReader,
    name: String,
    columns: Vec<Column>,
}

impl ClToolpath {
    /// The rows of `reader`, reading the file `name`.
    pub fn new(reader: ClReader, name: &str) -> ClToolpath {
        ClToolpath {
            reader,
            name: name.to_string(),
            columns: Column::typed_all(&CL_FIELDS),
        }
    }

    /// What the reader saw so far (complete once the rows are read to the end).
    pub fn summary(&self) -> &Summary {
        self.reader.summary()
    }
}

impl ToolpathSource for ClToolpath {
    fn name(&self) -> &str {
        &self.name
    }

    fn columns(&self) -> &[Column] {
        &self.columns
    }

    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError> {
        match self.reader.next() {
            Some(Ok(r)) => {
                row.line = r.line;
                row.n = None;
                row.kind = Some(r.kind.as_str());
                row.motion = Some(match r.motion {
                    verne_cl::Motion::Rapid => Motion::Rapid,
                    verne_cl::Motion::Feed => Motion::Feed,
                });
                row.feed = r.feed_mm_min;
                row.dt = None;
                row.t = None;
                row.tool = r.tool;
                row.id = None;
                row.tip = Vector3::from(r.tip);
                row.orientation = ToolOrientation::Axis(Vector3::from(r.axis));
                row.stated_angles = None;
                row.invalid = None;
                row.cells.clear();
                row.fraction = None;
                Ok(true)
            }
            Some(Err(e)) => Err(cl_error(&self.name, &e)),
            None if self.reader.summary().rows == 0 => Err(VerneError::input(
                &self.name,
                None,
                None,
                "no motion record (GOTO, FROM, CIRCLE, GODLTA or a cycle): no tool pose to convert",
            )),
            None => Ok(false),
        }
    }

    fn report(&self) -> ReaderReport {
        ReaderReport::Cl(self.reader.summary().clone())
    }
}

/// Prints what a CL reader saw besides the rows to stderr, prefixed `verne CMD: NAME:`: every
/// warning, the rows, dialect and units, the records skipped (names only, one line, shortened
/// past `SKIPPED_SHOWN` kinds) and the tool changes. Nothing is dropped silently: a warning
/// or tool change the reader stopped keeping is counted.
/// `tool_length` is the length the joints were computed with: a tool length the file gives
/// (NX `TLDATA`) that differs from it is a warning, since it is not applied.
pub fn report_summary(cmd: &str, name: &str, s: &Summary, tool_length: f64) {
    if crate::verbosity() == 0 {
        return;
    }
    let mut err = std::io::stderr().lock();
    crate::input::write_warnings(&mut err, cmd, name, &s.warnings, s.warnings_dropped);
    let mut line = format!(
        "verne {cmd}: {name}: {} rows ({} dialect, {})",
        s.rows,
        s.dialect.as_str(),
        s.units.as_str(),
    );
    if !s.skipped.is_empty() {
        let skipped: Vec<String> = s.skipped.iter().map(|(k, n)| format!("{k} x{n}")).collect();
        line.push_str("; records skipped: ");
        line.push_str(&shortened(&skipped, SKIPPED_SHOWN));
    }
    let _ = writeln!(err, "{line}");
    if s.tools.len() > 1 || s.tools.iter().any(|t| t.length_mm.is_some()) {
        for t in &s.tools {
            let mut what = match (t.tool, &t.name) {
                (Some(n), Some(name)) => format!("tool {n} ({name})"),
                (Some(n), None) => format!("tool {n}"),
                (None, Some(name)) => format!("tool {name}"),
                (None, None) => "a tool".to_string(),
            };
            if let Some(l) = t.length_mm {
                // Inch files give lengths like 76.19999999999999: a micrometre is enough.
                let l = (l * 1e6).round() / 1e6;
                what.push_str(&format!(", length {l} mm in the file"));
                if (l - tool_length).abs() > 1e-6 {
                    let _ = writeln!(
                        err,
                        "verne {cmd}: {name}: warning: line {}: the file's tool length {l} mm is not the {tool_length} mm the joints were computed with (machine file or --tool-length)",
                        t.line
                    );
                }
            }
            let _ = writeln!(
                err,
                "verne {cmd}: {name}: line {}: {what}, rows from line {}",
                t.line, t.first_row_line
            );
        }
        if s.tools_dropped > 0 {
            let _ = writeln!(
                err,
                "verne {cmd}: {name}: {} more tool changes not shown",
                s.tools_dropped
            );
        }
    }
}

/// How many kinds of skipped record the summary line names before "and N more".
const SKIPPED_SHOWN: usize = 24;

/// `items` joined by commas, the first `n` of them and then "and K more".
fn shortened(items: &[String], n: usize) -> String {
    if items.len() <= n {
        return items.join(", ");
    }
    format!("{}, and {} more", items[..n].join(", "), items.len() - n)
}
