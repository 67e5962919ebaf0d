//! CSV tables: the only place that builds csv readers and writers. Reading checks headers once
//! and parses numbers with file/line/column errors; writing goes to stdout or to a temporary file
//! beside the target that is renamed into place only when the run succeeds.

use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use csv::ByteRecord;

use verne::error::shown;

use crate::error::VerneError;

/// A table input with a header: CSV text (a file or stdin), or numbers given on the command
/// line (`--pose`, `--joints`, `--machine-joints`), which stay numbers.
pub struct CsvSource {
    records: Records,
    name: String,
    headers: ByteRecord,
}

/// Rows of numbers, each with its line: the command line's, or another reader's.
pub type NumberRows = Box<dyn Iterator<Item = Result<(u64, Vec<f64>), VerneError>> + Send>;

/// One row of a table as read: a CSV record's cells, or the numbers of a command-line row.
#[derive(Debug, Default, Clone)]
pub struct TableRow {
    /// The CSV record (its cells and its place in the file).
    pub record: ByteRecord,
    /// The row's numbers, in the columns' order, when the row was given as numbers; empty for
    /// CSV text.
    pub numbers: Vec<f64>,
    /// The row's line: in the CSV text, or its place among the command line's rows (1-based).
    pub line: u64,
}

/// Where the records of a [`CsvSource`] come from.
enum Records {
    Text {
        reader: csv::Reader<Box<dyn Read + Send>>,
        /// The record as read, before its fields are trimmed into the caller's record.
        raw: ByteRecord,
    },
    Numbers {
        /// Each row's line and numbers.
        rows: NumberRows,
    },
}

impl CsvSource {
    /// Opens `path`; `None` or `-` reads standard input.
    pub fn open(path: Option<&Path>) -> Result<CsvSource, VerneError> {
        match path {
            None => Self::from_reader(Box::new(io::stdin()), "<stdin>"),
            Some(p) if p.as_os_str() == "-" => Self::from_reader(Box::new(io::stdin()), "<stdin>"),
            Some(p) => {
                let name = p.display().to_string();
                let f = open_input_file(p).map_err(|e| VerneError::io(&name, e))?;
                Self::from_reader(Box::new(io::BufReader::with_capacity(1 << 16, f)), &name)
            }
        }
    }

    /// Reads CSV text from any reader; `name` is used in error messages. Line ends are made
    /// `\n` first ([`LfLines`]), so that every line number in a message is the file's line,
    /// whether it ends lines with LF, CRLF or CR.
    pub fn from_reader(r: Box<dyn Read + Send>, name: &str) -> Result<CsvSource, VerneError> {
        let r: Box<dyn Read + Send> = Box::new(LfLines::new(r));
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            // Fields are trimmed by `read` without the per-record allocation of Trim::All.
            .trim(csv::Trim::Headers)
            .comment(None)
            .buffer_capacity(1 << 16)
            .from_reader(r);
        let headers = match reader.byte_headers() {
            Ok(h) => h.clone(),
            Err(e) => return Err(csv_error(name, e)),
        };
        if headers.is_empty() || (headers.len() == 1 && headers[0].is_empty()) {
            return Err(VerneError::input(
                name,
                Some(1),
                None,
                "empty input: expected a CSV header line",
            ));
        }
        let mut headers_clean = ByteRecord::new();
        for (i, h) in headers.iter().enumerate() {
            // A UTF-8 byte-order mark before the first name is accepted and dropped.
            let h = if i == 0 {
                h.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(h)
            } else {
                h
            };
            headers_clean.push_field(h);
        }
        let src = CsvSource {
            records: Records::Text {
                reader,
                raw: ByteRecord::new(),
            },
            name: name.to_string(),
            headers: headers_clean,
        };
        src.check_duplicate_headers()?;
        Ok(src)
    }

    /// Rows of numbers given on the command line, under the column names `header`.
    pub fn from_numbers(header: &[&str], rows: Vec<Vec<f64>>, name: &str) -> CsvSource {
        let rows = rows
            .into_iter()
            .enumerate()
            .map(|(k, r)| Ok((k as u64 + 1, r)));
        CsvSource::from_number_rows(header, Box::new(rows), name)
    }

    /// Rows of numbers from another reader (a G-code joint program's joints), each with its
    /// line, under the column names `header`.
    pub fn from_number_rows(header: &[&str], rows: NumberRows, name: &str) -> CsvSource {
        CsvSource {
            records: Records::Numbers { rows },
            name: name.to_string(),
            headers: ByteRecord::from(header.to_vec()),
        }
    }

    fn check_duplicate_headers(&self) -> Result<(), VerneError> {
        // A set, not a pairwise comparison: a header of 100,000 names is checked at once.
        let mut seen = std::collections::HashSet::with_capacity(self.headers.len());
        for h in self.headers.iter() {
            // Names are matched ignoring case, so `x` and `X` are the same column.
            if !seen.insert(h.to_ascii_lowercase()) {
                return Err(VerneError::input(
                    &self.name,
                    Some(1),
                    Some(&shown(h)),
                    format!(
                        "column `{}` appears twice in the header (names are matched ignoring case); expected unique column names",
                        shown(h)
                    ),
                ));
            }
        }
        Ok(())
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// The name of column `i`, for a message.
    pub fn header_name(&self, i: usize) -> String {
        shown(self.headers.get(i).unwrap_or(b""))
    }

    pub fn headers(&self) -> &ByteRecord {
        &self.headers
    }

    /// Index of a column by name, ignoring ASCII case (`X,Y,Z,I,J,K` as CAM exports write it).
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers
            .iter()
            .position(|h| h.eq_ignore_ascii_case(name.as_bytes()))
    }

    /// Indices of the required columns, or an error naming the missing ones and the header found.
    pub fn require(&self, names: &[&str]) -> Result<Vec<usize>, VerneError> {
        let missing: Vec<&str> = names
            .iter()
            .copied()
            .filter(|n| self.column(n).is_none())
            .collect();
        if missing.is_empty() {
            return Ok(names.iter().map(|n| self.column(n).unwrap_or(0)).collect());
        }
        Err(VerneError::input(
            &self.name,
            Some(1),
            None,
            format!(
                "missing column{} {}; expected a header with {}, found `{}`{}{INPUT_SHAPES}",
                if missing.len() > 1 { "s" } else { "" },
                missing
                    .iter()
                    .map(|m| format!("`{m}`"))
                    .collect::<Vec<_>>()
                    .join(", "),
                names.join(","),
                self.header_text(),
                if self.headers.len() == 1 && self.header_text().contains(';') {
                    " (the file looks separated by `;`; verne reads comma-separated values)"
                } else {
                    ""
                }
            ),
        ))
    }

    /// The header as text for a message, shortened to [`MESSAGE_CHARS`](verne::error::MESSAGE_CHARS).
    pub fn header_text(&self) -> String {
        let joined: Vec<u8> = self.headers.iter().collect::<Vec<_>>().join(&b","[..]);
        shown(&joined)
    }

    /// Reads the next row; false at the end of the input. Every field of CSV text has its
    /// surrounding ASCII white space removed.
    pub fn read_row(&mut self, row: &mut TableRow) -> Result<bool, VerneError> {
        match &mut self.records {
            Records::Numbers { rows } => {
                let Some(next) = rows.next() else {
                    return Ok(false);
                };
                let (line, numbers) = next?;
                row.record.clear();
                row.numbers = numbers;
                row.line = line;
                Ok(true)
            }
            Records::Text { .. } => {
                row.numbers.clear();
                let more = self.read(&mut row.record)?;
                row.line = row.record.position().map_or(0, |p| p.line());
                Ok(more)
            }
        }
    }

    /// Reads the next record of CSV text into `rec`; false at the end of the input (and for
    /// rows of numbers, which [`CsvSource::read_row`] reads). Every field has its surrounding
    /// ASCII white space removed.
    pub fn read(&mut self, rec: &mut ByteRecord) -> Result<bool, VerneError> {
        let Records::Text { reader, raw } = &mut self.records else {
            return Ok(false);
        };
        match reader.read_byte_record(raw) {
            Ok(true) => {}
            Ok(false) => return Ok(false),
            Err(e) => return Err(csv_error(&self.name, e)),
        }
        let padded = |f: &[u8]| {
            f.first().is_some_and(u8::is_ascii_whitespace)
                || f.last().is_some_and(u8::is_ascii_whitespace)
        };
        if raw.iter().any(padded) {
            rec.clear();
            rec.set_position(raw.position().cloned());
            for f in raw.iter() {
                rec.push_field(f.trim_ascii());
            }
        } else {
            std::mem::swap(rec, raw);
        }
        Ok(true)
    }
}

fn csv_error(name: &str, e: csv::Error) -> VerneError {
    let line = e.position().map(|p| p.line());
    match e.into_kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => VerneError::input(
            name,
            line,
            None,
            format!(
                "row has {len} field{}; expected {expected_len} like the header (an unterminated quote also reads to the end of the file)",
                if len == 1 { "" } else { "s" }
            ),
        ),
        csv::ErrorKind::Io(io) => VerneError::io(name, io),
        other => VerneError::input(name, line, None, format!("malformed CSV: {other:?}")),
    }
}

/// A number cell could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellError {
    /// Not a number at all (text, units, decimal comma): the file is malformed.
    NotANumber,
    /// Empty, NaN or infinite: the row is invalid, the run goes on.
    NotFinite,
}

/// Parses a numeric cell (surrounding spaces already trimmed by the reader).
#[inline]
pub fn parse_number(field: &[u8]) -> Result<f64, CellError> {
    if field.is_empty() {
        return Err(CellError::NotFinite);
    }
    let s = std::str::from_utf8(field).map_err(|_| CellError::NotANumber)?;
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(CellError::NotFinite),
        Err(_) => Err(CellError::NotANumber),
    }
}

/// Appends one field of a CSV record: after a `delimiter` unless it is the first, quoted only
/// where needed, as the csv crate's writer does (a field holding the delimiter, a quote, CR or
/// LF; quotes inside doubled).
#[inline]
pub fn encode_field(out: &mut Vec<u8>, delimiter: u8, first: bool, field: &[u8]) {
    if !first {
        out.push(delimiter);
    }
    // Bytes above b'"' other than the delimiter never need quotes: one comparison per byte.
    let special = |b: u8| b <= b'"' && (b == b'"' || b == b'\n' || b == b'\r' || b == delimiter);
    if !field.iter().any(|&b| special(b) || b == delimiter) {
        out.extend_from_slice(field);
        return;
    }
    out.push(b'"');
    for &b in field {
        if b == b'"' {
            out.push(b'"');
        }
        out.push(b);
    }
    out.push(b'"');
}

/// Where output goes: stdout, or a file written atomically. Records are CSV-encoded by
/// [`encode_field`]; a caller may also hand over text it encoded itself ([`Sink::write_encoded`]).
pub struct Sink {
    writer: Box<dyn Write + Send>,
    delimiter: u8,
    scratch: Vec<u8>,
    target: Option<(PathBuf, PathBuf)>,
    name: String,
}

impl Sink {
    /// `None` or `-` is stdout; a path is written through a temporary file in the same directory.
    pub fn create(path: Option<&Path>) -> Result<Sink, VerneError> {
        Sink::create_delimited(path, b',')
    }

    /// As [`Sink::create`], with another field delimiter (b' ' for halstreamer).
    pub fn create_delimited(path: Option<&Path>, delimiter: u8) -> Result<Sink, VerneError> {
        let (writer, target, name): (Box<dyn Write + Send>, _, String) = match path {
            Some(p) if p.as_os_str() != "-" => {
                let name = p.display().to_string();
                check_output_target(p).map_err(|e| VerneError::io(&name, e))?;
                let dest = output_destination(p);
                if dest.in_place {
                    let f = std::fs::OpenOptions::new()
                        .write(true)
                        .open(&dest.path)
                        .map_err(|e| VerneError::io(&name, e))?;
                    (Box::new(BufWriter::with_capacity(1 << 16, f)), None, name)
                } else {
                    remove_stale_temps(&dest.path);
                    let tmp = temp_path_for(&dest.path, "");
                    let f = File::create(&tmp).map_err(|e| {
                        VerneError::io(
                            &name,
                            io::Error::new(
                                e.kind(),
                                format!(
                                    "cannot create the temporary file {} beside it (the output is written there, then renamed): {e}",
                                    tmp.display()
                                ),
                            ),
                        )
                    })?;
                    (
                        Box::new(BufWriter::with_capacity(1 << 16, f)),
                        Some((tmp, dest.path)),
                        name,
                    )
                }
            }
            _ => (
                Box::new(BufWriter::with_capacity(1 << 16, io::stdout())),
                None,
                "<stdout>".to_string(),
            ),
        };
        if let Some((tmp, _)) = &target {
            crate::table::register_temp(tmp);
        }
        Ok(Sink {
            writer,
            delimiter,
            scratch: Vec::new(),
            target,
            name,
        })
    }

    /// A sink over any writer (tests, fuzzing, in-memory output).
    pub fn from_writer(w: Box<dyn Write + Send>, name: &str) -> Sink {
        Sink {
            writer: w,
            delimiter: b',',
            scratch: Vec::new(),
            target: None,
            name: name.to_string(),
        }
    }

    /// Passes everything written through `wrap` (a writer that turns the CSV into another
    /// format, such as [`crate::follow::write::GcodeProgram`]); call before the first write.
    pub fn wrap(&mut self, wrap: impl FnOnce(Box<dyn Write + Send>) -> Box<dyn Write + Send>) {
        let inner = std::mem::replace(&mut self.writer, Box::new(io::sink()));
        self.writer = wrap(inner);
    }

    /// The field delimiter of the records this sink writes.
    pub fn delimiter(&self) -> u8 {
        self.delimiter
    }

    /// Writes one record.
    pub fn write(&mut self, rec: &ByteRecord) -> Result<(), VerneError> {
        self.scratch.clear();
        if rec.len() == 1 && rec[0].is_empty() {
            // A lone empty field is written quoted, or the line would read as no record.
            self.scratch.extend_from_slice(b"\"\"");
        } else {
            for (i, f) in rec.iter().enumerate() {
                encode_field(&mut self.scratch, self.delimiter, i == 0, f);
            }
        }
        self.scratch.push(b'\n');
        let Sink {
            writer,
            scratch,
            name,
            ..
        } = self;
        writer
            .write_all(scratch)
            .map_err(|e| VerneError::io(name, e))
    }

    /// Writes records already encoded (with [`encode_field`] and this sink's delimiter, each
    /// ended by a line feed).
    pub fn write_encoded(&mut self, bytes: &[u8]) -> Result<(), VerneError> {
        self.writer
            .write_all(bytes)
            .map_err(|e| VerneError::io(&self.name, e))
    }

    /// Flushes and, for a file, renames the temporary file into place.
    pub fn finish(mut self) -> Result<(), VerneError> {
        let flushed = self
            .writer
            .flush()
            .map_err(|e| VerneError::io(&self.name, e));
        if let Err(e) = flushed {
            self.discard();
            return Err(e);
        }
        if let Some((tmp, dest)) = self.target.take() {
            // Close the file before renaming.
            drop(std::mem::replace(&mut self.writer, Box::new(io::sink())));
            let renamed = keep_attributes(&dest, &tmp).and_then(|_| std::fs::rename(&tmp, &dest));
            unregister_temp(&tmp);
            if let Err(e) = renamed {
                let _ = std::fs::remove_file(&tmp);
                return Err(VerneError::io(&self.name, e));
            }
        }
        Ok(())
    }

    /// Abandons the output: the temporary file is removed, the target is left untouched.
    pub fn discard(&mut self) {
        if let Some((tmp, _)) = self.target.take() {
            let _ = std::fs::remove_file(&tmp);
            unregister_temp(&tmp);
        }
    }
}

impl Drop for Sink {
    fn drop(&mut self) {
        self.discard();
    }
}

/// Where an output file is written ([`output_destination`]).
pub struct OutputDestination {
    /// The file to write or to rename into place (a symlink's target).
    pub path: PathBuf,
    /// Written directly, not through a temporary file renamed into place.
    pub in_place: bool,
}

/// Where output named `path` goes. A device, a FIFO or a socket (`/dev/null`, `/dev/stdout`, a
/// named pipe) is written in place: renaming a file over it would replace the node itself (and
/// `/dev/null` with it, for root). Anything else goes through a temporary file beside the
/// final file, renamed into place on success; a symlink is followed, so that it keeps pointing
/// at the output.
pub fn output_destination(path: &Path) -> OutputDestination {
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => OutputDestination {
            path: path.to_path_buf(),
            in_place: true,
        },
        Ok(_) if path.is_symlink() => OutputDestination {
            path: std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
            in_place: false,
        },
        // A symlink to a file not there yet: the file is created where the link points.
        Err(_) if path.is_symlink() => OutputDestination {
            path: match std::fs::read_link(path) {
                Ok(t) if t.is_relative() => path.parent().map_or(t.clone(), |d| d.join(&t)),
                Ok(t) => t,
                Err(_) => path.to_path_buf(),
            },
            in_place: false,
        },
        _ => OutputDestination {
            path: path.to_path_buf(),
            in_place: false,
        },
    }
}

/// Before a temporary file replaces `dest`: the mode and owner (owner only as root) of an
/// existing `dest` are given to the temporary file, so that the output keeps them. A hard link to `dest` keeps the
/// old content: the new file replaces the name, not the inode (docs/csv.md).
fn keep_attributes(dest: &Path, tmp: &Path) -> io::Result<()> {
    use std::os::unix::fs::MetadataExt;
    use std::os::unix::fs::PermissionsExt;
    let Ok(m) = std::fs::metadata(dest) else {
        return Ok(());
    };
    if !m.is_file() {
        return Ok(());
    }
    std::fs::set_permissions(tmp, std::fs::Permissions::from_mode(m.permissions().mode()))?;
    // Only root can give a file away; for anyone else the owner is already theirs.
    let _ = std::os::unix::fs::chown(tmp, Some(m.uid()), Some(m.gid()));
    Ok(())
}

/// The files this run reads (device and inode), so that no output replaces one of them.
static INPUT_FILES: std::sync::Mutex<Vec<(u64, u64)>> = std::sync::Mutex::new(Vec::new());

/// Opens an input file for reading and remembers it as an input of this run (see
/// `check_output_target`). Every command opens its input files through here.
pub fn open_input_file(path: &Path) -> io::Result<File> {
    let f = File::open(path)?;
    if let Ok(m) = f.metadata()
        && m.is_file()
        && let Ok(mut v) = INPUT_FILES.lock()
    {
        use std::os::unix::fs::MetadataExt;
        v.push((m.dev(), m.ino()));
    }
    Ok(f)
}

/// The largest machine file read (a complete one is a few kB).
pub const MAX_INPUT_FILE_BYTES: u64 = 16 << 20;

/// Reads a whole input file (a machine file), remembered as [`open_input_file`] does; a file
/// larger than [`MAX_INPUT_FILE_BYTES`] (or endless, `/dev/zero`) is an error, not a read until
/// memory runs out.
pub fn read_input_file(path: &Path) -> io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    open_input_file(path)?
        .take(MAX_INPUT_FILE_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_FILE_BYTES {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "larger than {} MiB: expected a machine file (TOML or key,value CSV)",
                MAX_INPUT_FILE_BYTES >> 20
            ),
        ));
    }
    Ok(bytes)
}

/// Checks an output file before anything is computed or written: one of this run's input files
/// (the same file under any name: a hard or symbolic link too) is refused, since the run would
/// replace what it reads; so is an existing file without any write permission (root could
/// otherwise replace it).
/// `check_output_target`, and the directory the file goes to exists: checked before a
/// command computes anything, so a bad output path fails at once.
pub fn check_output_path(path: &Path) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(io::Error::new(
            io::ErrorKind::NotFound,
            format!("the directory {} does not exist", dir.display()),
        ));
    }
    check_output_target(path)
}

fn check_output_target(path: &Path) -> io::Result<()> {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let Ok(m) = std::fs::metadata(path) else {
        return Ok(());
    };
    if m.is_file() && m.permissions().mode() & 0o222 == 0 {
        return Err(io::Error::new(
            io::ErrorKind::PermissionDenied,
            "the file is read-only: refusing to replace it (make it writable, or name another file)",
        ));
    }
    let same = INPUT_FILES
        .lock()
        .map(|v| v.contains(&(m.dev(), m.ino())))
        .unwrap_or(false);
    if same && m.is_file() {
        return Err(io::Error::other(
            "is an input of this run: refusing to overwrite it with the output (name another file)",
        ));
    }
    Ok(())
}

/// What an output is, to tell two of one run apart: standard output, an existing file (device
/// and inode: the same file under any name), or a file to be (its folder resolved).
#[derive(Debug, PartialEq)]
enum OutputIdentity {
    Stdout,
    Inode(u64, u64),
    Path(PathBuf),
}

fn output_identity(path: &Path) -> OutputIdentity {
    use std::os::unix::fs::MetadataExt;
    if path.as_os_str() == "-" || path == Path::new("/dev/stdout") {
        return OutputIdentity::Stdout;
    }
    if let Ok(m) = std::fs::metadata(path) {
        return OutputIdentity::Inode(m.dev(), m.ino());
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    OutputIdentity::Path(dir.join(path.file_name().unwrap_or_default()))
}

/// Refuses, before any work, two outputs of one run that are the same file (the same path once
/// resolved, or the same inode) or that both write standard output: one would replace or mix
/// with the other. `outputs` are (option, path) pairs.
pub fn check_distinct_outputs(outputs: &[(&str, &Path)]) -> Result<(), VerneError> {
    let ids: Vec<OutputIdentity> = outputs.iter().map(|(_, p)| output_identity(p)).collect();
    for i in 0..outputs.len() {
        for j in i + 1..outputs.len() {
            if ids[i] != ids[j] {
                continue;
            }
            let ((a, pa), (b, pb)) = (outputs[i], outputs[j]);
            return Err(VerneError::Usage(if ids[i] == OutputIdentity::Stdout {
                format!("{a} and {b} both write standard output: give one of them a file")
            } else {
                format!(
                    "{a} {} and {b} {} are the same file: each output of a run needs a file of its own",
                    pa.display(),
                    pb.display()
                )
            }));
        }
    }
    Ok(())
}

/// Writes `bytes` as the output file `path`, as [`Sink`] does: through a temporary file beside
/// it, renamed into place (nothing is left behind on an error), or in place for a device or a
/// FIFO ([`output_destination`]).
pub fn write_output(path: &Path, bytes: &[u8]) -> io::Result<()> {
    check_output_target(path)?;
    let dest = output_destination(path);
    if dest.in_place {
        return std::fs::write(&dest.path, bytes);
    }
    remove_stale_temps(&dest.path);
    let tmp = temp_path_for(&dest.path, "");
    std::fs::write(&tmp, bytes)
        .and_then(|_| keep_attributes(&dest.path, &tmp))
        .and_then(|_| std::fs::rename(&tmp, &dest.path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// The longest file name the usual file systems take (bytes).
const NAME_MAX_BYTES: usize = 255;

/// The temporary file an output is written to before it is renamed into place:
/// `dir/.NAME.verne-PID.tmpEXT` beside the target (`ext`, e.g. `.png`, keeps the bitmap
/// encoder's format), or `dir/.verne-PID-HASH.tmpEXT` when that name would pass NAME_MAX. A run
/// killed by SIGKILL leaves it behind; the next run to the same target removes those of dead
/// processes ([`remove_stale_temps`]).
pub fn temp_path_for(p: &Path, ext: &str) -> PathBuf {
    let file = p
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let pid = std::process::id();
    let mut tmp = format!(".{file}.verne-{pid}.tmp{ext}");
    if tmp.len() > NAME_MAX_BYTES {
        tmp = format!(".verne-{pid}-{:016x}.tmp{ext}", name_hash(&file));
    }
    match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

/// A stable hash of a file name (FNV-1a), for the shortened temporary name.
fn name_hash(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Removes the temporary files of the target `p` left by runs that no longer exist (killed by
/// SIGKILL, which no handler sees): `.NAME.verne-PID.tmp*` (or the shortened form) whose PID is
/// not a running process. Another live run's file is left alone.
pub fn remove_stale_temps(p: &Path) {
    let file = p
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let long = format!(".{file}.verne-");
    let short = format!("-{:016x}.tmp", name_hash(&file));
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let pid = if let Some(rest) = name.strip_prefix(&long) {
            rest.split(".tmp")
                .next()
                .and_then(|p| p.parse::<u32>().ok())
        } else if let Some(rest) = name.strip_prefix(".verne-")
            && rest.contains(&short)
        {
            rest.split('-').next().and_then(|p| p.parse::<u32>().ok())
        } else {
            None
        };
        if let Some(pid) = pid
            && pid != std::process::id()
            && !Path::new(&format!("/proc/{pid}")).exists()
        {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

static TEMP_FILES: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn register_temp(p: &Path) {
    if let Ok(mut v) = TEMP_FILES.lock() {
        v.push(p.to_path_buf());
    }
}

fn unregister_temp(p: &Path) {
    if let Ok(mut v) = TEMP_FILES.lock() {
        v.retain(|q| q != p);
    }
}

/// Removes every temporary output file still open (for a signal handler or a fatal exit).
pub fn remove_temp_files() {
    if let Ok(v) = TEMP_FILES.lock() {
        for p in v.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// Appends a number to `out`: shortest round-trip form, or a fixed number of decimals.
#[inline]
pub fn format_number(out: &mut Vec<u8>, v: f64, decimals: Option<usize>) {
    let v = if v == 0.0 { 0.0 } else { v }; // no "-0"
    match decimals {
        None => {
            let mut buf = ryu::Buffer::new();
            let s = buf.format(v);
            let s = s.strip_suffix(".0").unwrap_or(s);
            out.extend_from_slice(s.as_bytes());
        }
        Some(d) => {
            let start = out.len();
            let _ = write!(out, "{v:.d$}");
            // A small negative number rounds to "-0.000": written "0.000", as -0 is "0".
            if out[start] == b'-' && out[start + 1..].iter().all(|&b| b == b'0' || b == b'.') {
                out.remove(start);
            }
        }
    }
}

/// CSV text with its line ends made `\n`: CRLF and a lone CR outside quoted fields become one
/// LF (inside quotes they are data and pass through). The csv crate counts lines by LF only,
/// one too few after each CRLF record and none in a CR-only file; after this, its line numbers
/// are the file's. Text without CR or quotes passes through untouched (one memchr2 per read).
///
/// It also bounds memory: a line longer than [`MAX_LINE_BYTES`] (`/dev/zero`, a binary file) is
/// an error naming the line, before the csv crate would buffer all of it.
pub struct LfLines<R> {
    inner: R,
    /// Inside a quoted field (an escaped `""` toggles twice).
    quoted: bool,
    /// The last byte was a CR turned into LF: an LF right after it belongs to it.
    after_cr: bool,
    /// Bytes of the current line so far, and its 1-based number.
    line_bytes: usize,
    line: u64,
}

/// The longest line of CSV text read (a header or a row of numbers is far shorter).
pub const MAX_LINE_BYTES: usize = 16 << 20;

impl<R: Read> LfLines<R> {
    pub fn new(inner: R) -> LfLines<R> {
        LfLines {
            inner,
            quoted: false,
            after_cr: false,
            line_bytes: 0,
            line: 1,
        }
    }

    /// Rewrites `buf` in place; returns its new length.
    fn convert(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len();
        let mut r = 0;
        if self.after_cr && n > 0 {
            self.after_cr = false;
            if buf[0] == b'\n' {
                r = 1;
            }
        }
        let mut w = 0;
        while r < n {
            // Copy up to the next byte that matters.
            let next = memchr::memchr2(b'\r', b'"', &buf[r..]).map_or(n, |k| r + k);
            if w != r {
                buf.copy_within(r..next, w);
            }
            w += next - r;
            r = next;
            if r == n {
                break;
            }
            match buf[r] {
                b'"' => {
                    self.quoted = !self.quoted;
                    buf[w] = b'"';
                }
                _ if self.quoted => buf[w] = b'\r',
                _ => {
                    buf[w] = b'\n';
                    if r + 1 < n {
                        if buf[r + 1] == b'\n' {
                            r += 1;
                        }
                    } else {
                        self.after_cr = true;
                    }
                }
            }
            w += 1;
            r += 1;
        }
        w
    }
}

impl<R: Read> Read for LfLines<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        loop {
            let n = self.inner.read(out)?;
            if n == 0 {
                return Ok(0);
            }
            let w = self.convert(&mut out[..n]);
            let text = &out[..w];
            match memchr::memrchr(b'\n', text) {
                None => self.line_bytes += w,
                Some(k) => {
                    self.line += memchr::memchr_iter(b'\n', text).count() as u64;
                    self.line_bytes = w - k - 1;
                }
            }
            if self.line_bytes > MAX_LINE_BYTES {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!(
                        "line {} is longer than {} MiB: expected CSV text (a header, then rows of numbers)",
                        self.line,
                        MAX_LINE_BYTES >> 20
                    ),
                ));
            }
            if w > 0 {
                return Ok(w);
            }
        }
    }
}

/// Appended to a missing-columns message: the input shapes verne reads (docs/csv.md).
const INPUT_SHAPES: &str = ". Inputs verne reads (column names in any case): tool poses x,y,z with i,j,k or phi1,phi2; platform points xp,yp,zp; machine joints rho1,rho2,rho3,theta1,theta2; slider rows rho1,rho2,rho3";

#[cfg(test)]
pub(crate) mod tests {
    /// Every split of the input into reads gives the same text: LF, CRLF and CR lines alike,
    /// quoted CR and CRLF kept.
    #[test]
    fn lf_lines_normalizes_line_ends_outside_quotes() {
        use std::io::Read;
        let cases: [(&[u8], &[u8]); 5] = [
            (b"a,b\r\n1,2\r\n", b"a,b\n1,2\n"),
            (b"a,b\r1,2\r3,4", b"a,b\n1,2\n3,4"),
            (b"a\n\r\n\r\rb", b"a\n\n\n\nb"),
            (b"\"x\r\ny\"\r\n\"q\"\"\r\"\r", b"\"x\r\ny\"\n\"q\"\"\r\"\n"),
            (b"no line end", b"no line end"),
        ];
        /// A reader that hands out at most `k` bytes a call.
        struct Chunks<'a>(&'a [u8], usize);
        impl Read for Chunks<'_> {
            fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
                let n = self.0.len().min(self.1).min(out.len());
                out[..n].copy_from_slice(&self.0[..n]);
                self.0 = &self.0[n..];
                Ok(n)
            }
        }
        for (input, want) in cases {
            for k in 1..=input.len() {
                let mut got = Vec::new();
                super::LfLines::new(Chunks(input, k))
                    .read_to_end(&mut got)
                    .unwrap();
                assert_eq!(
                    got,
                    want,
                    "{:?} in reads of {k}",
                    String::from_utf8_lossy(input)
                );
            }
        }
    }

    use super::*;

    /// The sink's encoding is byte for byte the csv crate's writer's, on random records of
    /// random bytes (delimiters, quotes, CR, LF, spaces, non-ASCII) for both delimiters.
    #[test]
    fn encoding_matches_the_csv_writer() {
        let alphabet = b"a1,;\" \r\n.\t-\xC3\xA9e";
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        for delimiter in [b',', b' '] {
            for _ in 0..20_000 {
                let fields = 1 + next(5);
                let mut rec = ByteRecord::new();
                for _ in 0..fields {
                    let len = next(6);
                    let f: Vec<u8> = (0..len).map(|_| alphabet[next(alphabet.len())]).collect();
                    rec.push_field(&f);
                }
                let buf = SharedBuf::default();
                let mut sink = Sink::from_writer(Box::new(buf.clone()), "t");
                sink.delimiter = delimiter;
                sink.write(&rec).unwrap();
                drop(sink);
                let ours = buf.0.lock().unwrap().clone();
                let mut theirs = csv::WriterBuilder::new()
                    .delimiter(delimiter)
                    .from_writer(Vec::new());
                theirs.write_byte_record(&rec).unwrap();
                let theirs = theirs.into_inner().unwrap();
                assert_eq!(
                    String::from_utf8_lossy(&ours),
                    String::from_utf8_lossy(&theirs),
                    "{rec:?}"
                );
            }
        }
    }

    /// A writer into a Vec the test keeps (the sink takes a boxed 'static writer).
    #[derive(Clone, Default)]
    pub(crate) struct SharedBuf(pub(crate) std::sync::Arc<std::sync::Mutex<Vec<u8>>>);
    impl Write for SharedBuf {
        fn write(&mut self, b: &[u8]) -> io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn two_outputs_of_one_run_are_different_files() {
        let dir = std::env::temp_dir().join(format!("verne-outputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = dir.join("a.csv");
        std::fs::write(&a, "x").unwrap();
        let link = dir.join("b.csv");
        let _ = std::fs::remove_file(&link);
        std::fs::hard_link(&a, &link).unwrap();
        let dotted = dir.join(".").join("c.csv");
        let plain = dir.join("c.csv");
        let same = [
            (a.as_path(), a.as_path()),
            (a.as_path(), link.as_path()),
            (dotted.as_path(), plain.as_path()),
            (Path::new("-"), Path::new("/dev/stdout")),
        ];
        for (p, q) in same {
            assert!(
                check_distinct_outputs(&[("-o", p), ("--plot", q)]).is_err(),
                "{p:?} {q:?}"
            );
        }
        assert!(
            check_distinct_outputs(&[("-o", a.as_path()), ("--plot", plain.as_path())]).is_ok()
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn numbers_parse_and_classify() {
        assert_eq!(parse_number(b"1.5"), Ok(1.5));
        assert_eq!(parse_number(b"-2e3"), Ok(-2000.0));
        assert_eq!(parse_number(b"NaN"), Err(CellError::NotFinite));
        assert_eq!(parse_number(b"inf"), Err(CellError::NotFinite));
        assert_eq!(parse_number(b""), Err(CellError::NotFinite));
        assert_eq!(parse_number(b"1,5"), Err(CellError::NotANumber));
        assert_eq!(parse_number(b"12mm"), Err(CellError::NotANumber));
        assert_eq!(parse_number(b"\xff"), Err(CellError::NotANumber));
    }

    #[test]
    fn numbers_format_round_trip() {
        for v in [0.1, -0.0, 368.354796, 1e-7, 123456.0, -2.5e-12] {
            let mut out = Vec::new();
            format_number(&mut out, v, None);
            let s = String::from_utf8(out).unwrap();
            assert_eq!(
                s.parse::<f64>().unwrap(),
                if v == 0.0 { 0.0 } else { v },
                "{s}"
            );
            assert!(!s.starts_with("-0") || v != 0.0);
        }
        let mut out = Vec::new();
        format_number(&mut out, 2.0, None);
        assert_eq!(out, b"2");
    }
}
