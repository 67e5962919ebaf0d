//! CL (cutter-location / APT source) files in the CLI: the reader is the `verne-cl` crate
//! (every dialect of `docs/cl-dialects.md`: NX CLSF and listings, Creo, SolidWorks CAM, CATIA,
//! generic APT; units, arcs, cycles, feeds, tools). Here: opening a file or stdin with the
//! file's name on every error, the rows in CSV columns for the row engine of `verne ik`, and the
//! summary (warnings, skipped records) on stderr.

use std::io::{BufRead, Read, Seek, Write};
use std::path::Path;
use std::sync::{Arc, Mutex};

use verne_cl::{ClError, Options, Reader, Summary};

use crate::cli::InputFormat;
use crate::error::VerneError;
use crate::input::gcode::{GcodeReader, gcode_error};
use crate::input::rows::{FieldRow, FieldRows, invalid_data};
use crate::table::CsvSource;

/// A CL error as the CLI's input error: file, line, column, what was expected.
pub fn cl_error(file: &str, e: &ClError) -> VerneError {
    let line = (e.line > 0).then_some(e.line);
    let column = e.column.map(|c| c.to_string());
    VerneError::input(file, line, column.as_deref(), e.kind.to_string())
}

/// A seekable buffered input: the reader decides a file's units by a first pass over its
/// records (docs/cl-dialects.md §4) and then reads from the start again.
pub trait SeekableInput: BufRead + Seek + Send {}
impl<T: BufRead + Seek + Send> SeekableInput for T {}

/// A CL reader over a boxed input, as the CLI reads files and stdin alike.
pub type ClReader = Reader<Box<dyn SeekableInput>>;

/// An input of `verne ik` or `verne verify --path`, opened as what it is.
pub enum PathInput {
    /// A CL file, with its name for messages.
    Cl(Box<ClReader>, String),
    /// A G-code program, with its name.
    Gcode(Box<GcodeReader>, String),
    /// Anything else: CSV.
    Csv(CsvSource),
}

/// How the readers of toolpaths are set up (`--units`, `--chord-tol`, the machine's `[gcode]`).
#[derive(Debug, Clone, Copy)]
pub struct ReadOptions {
    pub cl: Options,
    pub gcode: verne_gcode::Options,
    /// What the words of a G-code program mean (the machine file's `[gcode]` table).
    pub words: verne::spec::gcode::GcodeWords,
}

/// What a file is, from its name: a CL or G-code extension.
fn format_by_name(name: &str) -> Option<InputFormat> {
    if verne_cl::has_cl_extension(name) {
        Some(InputFormat::Apt)
    } else if verne_gcode::has_gcode_extension(name) {
        Some(InputFormat::Gcode)
    } else {
        None
    }
}

/// What a file is, from its first bytes: a CL record, a G-code block, else CSV.
fn format_by_content(head: &[u8]) -> InputFormat {
    if verne_cl::sniff_content(head) {
        InputFormat::Apt
    } else if verne_gcode::sniff_content(head) {
        InputFormat::Gcode
    } else {
        InputFormat::Csv
    }
}

/// Opens `path` (or stdin for `None` or `-`) as a CL file, a G-code program or CSV. `force`
/// (`--input-format`) decides when given; else a CL or G-code extension or, failing that, the
/// first [`verne_cl::SNIFF_BYTES`] bytes (a first record such as `TOOL PATH/`, `PARTNO`, `$$`,
/// `GOTO/`; a first block such as `%`, `N10 G21`, `G0 X0`), so that neither is ever parsed as
/// CSV. A CL file on stdin is read into memory (the units look-ahead reads it twice); G-code
/// and CSV are streamed.
pub fn open_path_input(
    path: Option<&Path>,
    force: Option<InputFormat>,
    options: &ReadOptions,
) -> Result<PathInput, VerneError> {
    let file = path.filter(|p| p.as_os_str() != "-");
    let name = file.map_or("<stdin>".to_string(), |p| p.display().to_string());
    if let Some(p) = file {
        let format = match force.or_else(|| format_by_name(&p.to_string_lossy())) {
            Some(f) => f,
            None => {
                let mut head = Vec::with_capacity(verne_cl::SNIFF_BYTES);
                let f = crate::table::open_input_file(p).map_err(|e| VerneError::io(&name, e))?;
                f.take(verne_cl::SNIFF_BYTES as u64)
                    .read_to_end(&mut head)
                    .map_err(|e| VerneError::io(&name, e))?;
                format_by_content(&head)
            }
        };
        return match format {
            InputFormat::Apt => open_cl_file(p, &name, options.cl),
            InputFormat::Gcode => {
                let f = crate::table::open_input_file(p).map_err(|e| VerneError::io(&name, e))?;
                let input: Box<dyn BufRead + Send> =
                    Box::new(std::io::BufReader::with_capacity(64 * 1024, f));
                let reader = verne_gcode::Reader::new(input, options.gcode)
                    .map_err(|e| gcode_error(&name, &e))?;
                Ok(PathInput::Gcode(Box::new(reader), name))
            }
            InputFormat::Csv => Ok(PathInput::Csv(CsvSource::open(path)?)),
        };
    }
    // Stdin: look at its start, then read on as whichever it is.
    let mut stdin = std::io::stdin().lock();
    let mut head = Vec::with_capacity(verne_cl::SNIFF_BYTES);
    (&mut stdin)
        .take(verne_cl::SNIFF_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(|e| VerneError::io(&name, e))?;
    match force.unwrap_or_else(|| format_by_content(&head)) {
        InputFormat::Csv => {
            drop(stdin);
            let rest = std::io::Cursor::new(head).chain(std::io::stdin());
            return Ok(PathInput::Csv(CsvSource::from_reader(
                Box::new(rest),
                &name,
            )?));
        }
        InputFormat::Gcode => {
            drop(stdin);
            let rest = std::io::Cursor::new(head).chain(std::io::stdin());
            let input: Box<dyn BufRead + Send> =
                Box::new(std::io::BufReader::with_capacity(64 * 1024, rest));
            let reader = verne_gcode::Reader::new(input, options.gcode)
                .map_err(|e| gcode_error(&name, &e))?;
            return Ok(PathInput::Gcode(Box::new(reader), name));
        }
        InputFormat::Apt => {}
    }
    (&mut stdin)
        .take(MAX_STDIN_CL_BYTES + 1)
        .read_to_end(&mut head)
        .map_err(|e| VerneError::io(&name, e))?;
    if head.len() as u64 > MAX_STDIN_CL_BYTES {
        return Err(VerneError::input(
            &name,
            None,
            None,
            format!(
                "a CL file on stdin is held in memory and this one is larger than {} MiB: give it by name (verne ik FILE): a file is streamed, not held",
                MAX_STDIN_CL_BYTES >> 20
            ),
        ));
    }
    let input: Box<dyn SeekableInput> = Box::new(std::io::Cursor::new(head));
    let reader = Reader::new(input, options.cl).map_err(|e| cl_error(&name, &e))?;
    Ok(PathInput::Cl(Box::new(reader), name))
}

/// The largest CL file read from stdin (held in memory for the units look-ahead).
pub const MAX_STDIN_CL_BYTES: u64 = 256 << 20;

fn open_cl_file(path: &Path, name: &str, options: Options) -> Result<PathInput, VerneError> {
    let f = crate::table::open_input_file(path).map_err(|e| VerneError::io(name, e))?;
    let input: Box<dyn SeekableInput> = Box::new(std::io::BufReader::with_capacity(64 * 1024, f));
    let reader = Reader::new(input, options).map_err(|e| cl_error(name, &e))?;
    Ok(PathInput::Cl(Box::new(reader), name.to_string()))
}

/// Prints what the reader saw besides the rows to stderr, prefixed `verne CMD: NAME:`: every
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

/// A CL file's rows in the columns `line,kind,motion,feed,tool,x,y,z,i,j,k` (mm, unit axis), so
/// that `verne ik` streams it through the same row engine as a CSV file. The reader's summary
/// is shared through [`ClRows::summary`] and complete once the text has been read to its end.
pub struct ClRows {
    reader: ClReader,
    summary: Arc<Mutex<Summary>>,
}

impl ClRows {
    /// The rows of `reader`.
    pub fn new(reader: ClReader) -> ClRows {
        let summary = Arc::new(Mutex::new(reader.summary().clone()));
        ClRows { reader, summary }
    }

    /// The reader's summary, shared.
    pub fn summary(&self) -> Arc<Mutex<Summary>> {
        self.summary.clone()
    }
}

impl FieldRows for ClRows {
    fn header(&self) -> &'static [&'static str] {
        &[
            "line", "kind", "motion", "feed", "tool", "x", "y", "z", "i", "j", "k",
        ]
    }

    fn next_row(&mut self, row: &mut FieldRow<'_>) -> std::io::Result<bool> {
        match self.reader.next() {
            Some(Ok(r)) => {
                row.field(r.line);
                row.field(r.kind);
                row.field(r.motion.as_str());
                row.optional(r.feed_mm_min);
                row.optional(r.tool);
                for v in r.tip.iter().chain(&r.axis) {
                    row.field(v);
                }
                Ok(true)
            }
            Some(Err(e)) => Err(invalid_data(e.to_string())),
            None => {
                if let Ok(mut s) = self.summary.lock() {
                    *s = self.reader.summary().clone();
                }
                if self.reader.summary().rows == 0 {
                    // As an empty CSV is: nothing to convert is not a success.
                    return Err(invalid_data(
                        "no motion record (GOTO, FROM, CIRCLE, GODLTA or a cycle): no tool pose to convert".into(),
                    ));
                }
                Ok(false)
            }
        }
    }
}
