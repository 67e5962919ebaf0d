//! CSV tables: the only place that builds csv readers and encodes CSV fields. Reading checks
//! headers once and parses numbers with file/line/column errors; the encoded records go to a
//! [`crate::files::Sink`].

use std::io::{self, Read, Write};
use std::path::Path;

use csv::ByteRecord;

use verne::error::shown;

use crate::error::VerneError;
use crate::files::open_input_file;
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
    use crate::files::Sink;

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
                let mut sink =
                    Sink::from_writer(Box::new(buf.clone()), "t").with_delimiter(delimiter);
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
