//! A stream of rows made by a reader of another format (CL, G-code), seen as CSV text, so that
//! `verne ik` streams it through the same row engine as a CSV file.

use std::io;

/// The rows of an input, one CSV line at a time.
pub trait CsvRows: Send {
    /// The header line, with its line feed.
    fn header(&self) -> &'static [u8];
    /// Appends the next row (with its line feed) to `out`; `Ok(false)` at the end. An error
    /// (a reader's, with its line) ends the stream.
    fn next_row(&mut self, out: &mut Vec<u8>) -> io::Result<bool>;
}

/// [`CsvRows`] as a [`io::Read`]er of CSV text.
pub struct AsCsv<R: CsvRows> {
    rows: R,
    buf: Vec<u8>,
    pos: usize,
    header_done: bool,
    finished: bool,
}

impl<R: CsvRows> AsCsv<R> {
    /// The CSV view of `rows`.
    pub fn new(rows: R) -> AsCsv<R> {
        AsCsv {
            rows,
            buf: Vec::with_capacity(256),
            pos: 0,
            header_done: false,
            finished: false,
        }
    }

    fn refill(&mut self) -> io::Result<()> {
        self.buf.clear();
        self.pos = 0;
        if !self.header_done {
            self.header_done = true;
            self.buf.extend_from_slice(self.rows.header());
            return Ok(());
        }
        if self.finished {
            return Ok(());
        }
        match self.rows.next_row(&mut self.buf) {
            Ok(true) => Ok(()),
            Ok(false) => {
                self.finished = true;
                Ok(())
            }
            Err(e) => {
                self.finished = true;
                Err(e)
            }
        }
    }
}

impl<R: CsvRows> io::Read for AsCsv<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
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

/// An error of a reader as the error of the CSV text.
pub fn invalid_data(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, message)
}
