//! CL (cutter-location / APT source) files in the CLI: the reader is the `verne-cl` crate
//! (every dialect of `docs/cl-dialects.md`: NX CLSF and listings, Creo, SolidWorks CAM, CATIA,
//! generic APT; units, arcs, cycles, feeds, tools). Here: opening a file or stdin with the
//! file's name on every error, the rows as CSV text for the row engine of `verne ik`, and the
//! summary (warnings, skipped records) on stderr.

use std::io::{BufRead, Read, Seek, Write};
use std::path::Path;
use std::sync::{Arc, Mutex};

use verne_cl::{ClError, Options, Reader, Summary};

use crate::error::VerneError;

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

/// Opens `path` (or stdin for `None` or `-`) as a CL file: the caller decided it is one (by
/// its name, `verne_cl::has_cl_extension`, or `--input-format apt`); a file that is not is
/// refused by the reader at its first unknown line. Stdin is read into memory first (the
/// units look-ahead reads the records twice).
pub fn open_cl(path: Option<&Path>, options: Options) -> Result<(ClReader, String), VerneError> {
    let (input, name): (Box<dyn SeekableInput>, String) = match path {
        Some(p) if p.as_os_str() != "-" => {
            let name = p.display().to_string();
            let f = std::fs::File::open(p).map_err(|e| VerneError::io(&name, e))?;
            (
                Box::new(std::io::BufReader::with_capacity(64 * 1024, f)),
                name,
            )
        }
        _ => {
            let name = "<stdin>".to_string();
            let mut text = Vec::new();
            std::io::stdin()
                .lock()
                .read_to_end(&mut text)
                .map_err(|e| VerneError::io(&name, e))?;
            (Box::new(std::io::Cursor::new(text)), name)
        }
    };
    let reader = Reader::new(input, options).map_err(|e| cl_error(&name, &e))?;
    Ok((reader, name))
}

/// Prints what the reader saw besides the rows to stderr, prefixed `verne CMD: NAME:`: the
/// units and where they came from, every warning, the records skipped. Nothing is dropped
/// silently: a warning the reader stopped keeping is counted.
pub fn report_summary(cmd: &str, name: &str, s: &Summary) {
    let mut err = std::io::stderr().lock();
    for w in &s.warnings {
        let _ = writeln!(err, "verne {cmd}: {name}: warning: {w}");
    }
    if s.warnings_dropped > 0 {
        let _ = writeln!(
            err,
            "verne {cmd}: {name}: {} more warnings not shown",
            s.warnings_dropped
        );
    }
    if !s.skipped.is_empty() {
        let skipped: Vec<String> = s.skipped.iter().map(|(k, n)| format!("{k} x{n}")).collect();
        let _ = writeln!(
            err,
            "verne {cmd}: {name}: {} rows ({} dialect, {}); records skipped: {}",
            s.rows,
            s.dialect.as_str(),
            s.units.as_str(),
            skipped.join(", ")
        );
    }
}

/// A CL file read as CSV text (`line,kind,motion,feed,tool,x,y,z,i,j,k`, mm, unit axis), so
/// that `verne ik` streams it through the same row engine as a CSV file. The reader's summary
/// is shared through `summary` and complete once the text has been read to its end.
pub struct ClAsCsv {
    reader: ClReader,
    buf: Vec<u8>,
    pos: usize,
    header_done: bool,
    finished: bool,
    summary: Arc<Mutex<Summary>>,
}

impl ClAsCsv {
    /// The CSV view of `reader`.
    pub fn new(reader: ClReader) -> ClAsCsv {
        let summary = Arc::new(Mutex::new(reader.summary().clone()));
        ClAsCsv {
            reader,
            buf: Vec::with_capacity(256),
            pos: 0,
            header_done: false,
            finished: false,
            summary,
        }
    }

    /// The reader's summary, shared.
    pub fn summary(&self) -> Arc<Mutex<Summary>> {
        self.summary.clone()
    }

    fn refill(&mut self) -> std::io::Result<()> {
        self.buf.clear();
        self.pos = 0;
        if !self.header_done {
            self.header_done = true;
            self.buf
                .extend_from_slice(b"line,kind,motion,feed,tool,x,y,z,i,j,k\n");
            return Ok(());
        }
        if self.finished {
            return Ok(());
        }
        match self.reader.next() {
            Some(Ok(r)) => {
                let (t, a) = (r.tip, r.axis);
                write!(self.buf, "{},{},{},", r.line, r.kind, r.motion.as_str())?;
                if let Some(f) = r.feed_mm_min {
                    write!(self.buf, "{f}")?;
                }
                self.buf.push(b',');
                if let Some(n) = r.tool {
                    write!(self.buf, "{n}")?;
                }
                writeln!(
                    self.buf,
                    ",{},{},{},{},{},{}",
                    t[0], t[1], t[2], a[0], a[1], a[2]
                )
            }
            Some(Err(e)) => {
                self.finished = true;
                Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    e.to_string(),
                ))
            }
            None => {
                self.finished = true;
                if let Ok(mut s) = self.summary.lock() {
                    *s = self.reader.summary().clone();
                }
                Ok(())
            }
        }
    }
}

impl std::io::Read for ClAsCsv {
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
