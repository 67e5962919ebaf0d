//! Rows made by a reader of another format (a CL file, a G-code program, a path resampled at
//! the servo period), handed to the row engine field by field: the columns a CSV of the same
//! path would have, with no CSV text written and parsed again in between
//! ([`crate::table::CsvSource::from_rows`]).

use std::fmt::Display;
use std::io::{self, Write};

use csv::ByteRecord;

/// The rows of an input, one record at a time.
pub trait FieldRows: Send {
    /// The column names, in order; the first is `line`, each row's line in its own file.
    fn header(&self) -> &'static [&'static str];
    /// Writes the next row's fields; `Ok(false)` at the end. An error (a reader's, with its
    /// line) ends the stream.
    fn next_row(&mut self, row: &mut FieldRow<'_>) -> io::Result<bool>;
}

/// The fields of one row, written in the order of the header.
pub struct FieldRow<'a> {
    record: &'a mut ByteRecord,
    text: &'a mut Vec<u8>,
}

impl<'a> FieldRow<'a> {
    /// An empty row writing into `record`; `text` is scratch space for formatting.
    pub fn new(record: &'a mut ByteRecord, text: &'a mut Vec<u8>) -> FieldRow<'a> {
        record.clear();
        FieldRow { record, text }
    }

    /// The next field: `value` as `Display` writes it (numbers in the shortest form that
    /// reads back to the same `f64`).
    pub fn field(&mut self, value: impl Display) {
        self.text.clear();
        // Writing into a vector cannot fail.
        let _ = write!(self.text, "{value}");
        self.record.push_field(self.text);
    }

    /// The next field, empty for `None`.
    pub fn optional(&mut self, value: Option<impl Display>) {
        match value {
            Some(v) => self.field(v),
            None => self.record.push_field(b""),
        }
    }
}

/// An error of a reader, reported with the input's name as an I/O error of that input.
pub fn invalid_data(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, message)
}
