//! Every input opened once. A file, a named pipe, `/dev/stdin` or standard input is opened one
//! time; what it is (a CL file, a G-code program, CSV) is told from its name or, failing that,
//! from its first [`verne_cl::SNIFF_BYTES`] bytes, read into a buffer that the reader then
//! consumes first: nothing is read twice, so a pipe works as a file does.

use std::fs::File;
use std::io::{BufRead, BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::Path;

use verne_cl::Reader as ClReader;

use super::cl::{ClToolpath, SeekableInput, cl_error};
use crate::error::VerneError;
use crate::input::gcode::{GcodeReader, gcode_error};
use crate::table::CsvSource;

/// How the readers of toolpaths are set up (`--units`, `--chord-tol`, the machine's `[gcode]`).
#[derive(Debug, Clone, Copy)]
pub struct ReadOptions {
    pub cl: verne_cl::Options,
    pub gcode: verne_gcode::Options,
    /// What the words of a G-code program mean (the machine file's `[gcode]` table).
    pub words: verne::spec::gcode::GcodeWords,
}

/// What an input is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Csv,
    /// A CL file (APT source and the CAM systems' dialects).
    Cl,
    /// A G-code program (RS274/NGC).
    Gcode,
}

/// The largest CL file read from a stream (a pipe, standard input): it is held in memory, since
/// the reader's units look-ahead reads it twice.
pub const MAX_STREAMED_CL_BYTES: u64 = 256 << 20;

/// Bytes buffered per read.
const READ_BUFFER: usize = 64 * 1024;

/// The opened input: a regular file at its start (it can be read again from there), or a
/// stream whose first bytes were read into a buffer that comes first.
enum Opened {
    File(BufReader<File>),
    Stream(Box<dyn BufRead + Send>),
}

/// An input, opened once, and what it is.
pub struct Input {
    pub name: String,
    pub format: Format,
    opened: Opened,
}

impl Input {
    /// Opens `path` (standard input for `None` or `-`). `force` decides the format when given;
    /// else `allowed` lists the formats the command reads: a CL or G-code extension, or the
    /// first bytes (a first record such as `TOOL PATH/`, `PARTNO`, `$$`, `GOTO/`; a first block
    /// such as `%`, `N10 G21`, `G0 X0`), else CSV. A format not in `allowed` reads as CSV.
    pub fn open(
        path: Option<&Path>,
        force: Option<Format>,
        allowed: &[Format],
    ) -> Result<Input, VerneError> {
        let file = path.filter(|p| p.as_os_str() != "-");
        let name = file.map_or("<stdin>".to_string(), |p| p.display().to_string());
        let io = |e: std::io::Error| VerneError::io(&name, e);
        let by_name = file.and_then(|p| {
            let n = p.to_string_lossy();
            if verne_cl::has_cl_extension(&n) {
                Some(Format::Cl)
            } else if verne_gcode::has_gcode_extension(&n) {
                Some(Format::Gcode)
            } else {
                None
            }
        });
        let known = force.or(by_name.filter(|f| allowed.contains(f)));
        let mut opened = match file {
            Some(p) => {
                let f = crate::files::open_input_file(p).map_err(io)?;
                let regular = f.metadata().is_ok_and(|m| m.is_file());
                let reader = BufReader::with_capacity(READ_BUFFER, f);
                if regular {
                    Opened::File(reader)
                } else {
                    Opened::Stream(Box::new(reader))
                }
            }
            None => Opened::Stream(Box::new(BufReader::with_capacity(
                READ_BUFFER,
                std::io::stdin(),
            ))),
        };
        let format = match known {
            Some(f) => f,
            None => {
                let mut head = Vec::with_capacity(verne_cl::SNIFF_BYTES);
                let r: &mut dyn BufRead = match &mut opened {
                    Opened::File(r) => r,
                    Opened::Stream(r) => r,
                };
                Read::take(r, verne_cl::SNIFF_BYTES as u64)
                    .read_to_end(&mut head)
                    .map_err(io)?;
                let sniffed = if verne_cl::sniff_content(&head) {
                    Format::Cl
                } else if verne_gcode::sniff_content(&head) {
                    Format::Gcode
                } else {
                    Format::Csv
                };
                // The bytes read come first again: a file from its start, a stream from the
                // buffer.
                match &mut opened {
                    Opened::File(r) => {
                        r.seek(SeekFrom::Start(0)).map_err(io)?;
                    }
                    Opened::Stream(r) => {
                        let rest = std::mem::replace(r, Box::new(std::io::empty()));
                        *r = Box::new(BufReader::with_capacity(
                            READ_BUFFER,
                            Cursor::new(head).chain(rest),
                        ));
                    }
                }
                if allowed.contains(&sniffed) {
                    sniffed
                } else {
                    Format::Csv
                }
            }
        };
        Ok(Input {
            name,
            format,
            opened,
        })
    }

    fn reader(self) -> Box<dyn BufRead + Send> {
        match self.opened {
            Opened::File(r) => Box::new(r),
            Opened::Stream(r) => r,
        }
    }

    /// The input as CSV.
    pub fn into_csv(self) -> Result<CsvSource, VerneError> {
        let name = self.name.clone();
        CsvSource::from_reader(Box::new(self.reader()), &name)
    }

    /// The input as a G-code program.
    pub fn into_gcode(self, options: verne_gcode::Options) -> Result<GcodeReader, VerneError> {
        let name = self.name.clone();
        verne_gcode::Reader::new(self.reader(), options).map_err(|e| gcode_error(&name, &e))
    }

    /// The input as a CL file: a regular file is read from its start again after the units
    /// look-ahead; a stream is held in memory (at most [`MAX_STREAMED_CL_BYTES`]).
    pub fn into_cl(self, options: verne_cl::Options) -> Result<ClToolpath, VerneError> {
        let name = self.name.clone();
        let input: Box<dyn SeekableInput> = match self.opened {
            Opened::File(r) => Box::new(r),
            Opened::Stream(r) => {
                let mut bytes = Vec::new();
                r.take(MAX_STREAMED_CL_BYTES + 1)
                    .read_to_end(&mut bytes)
                    .map_err(|e| VerneError::io(&name, e))?;
                if bytes.len() as u64 > MAX_STREAMED_CL_BYTES {
                    return Err(VerneError::input(
                        &name,
                        None,
                        None,
                        format!(
                            "a CL file from a pipe is held in memory and this one is larger than {} MiB: give it as a file (verne ik FILE): a file is streamed, not held",
                            MAX_STREAMED_CL_BYTES >> 20
                        ),
                    ));
                }
                Box::new(Cursor::new(bytes))
            }
        };
        let reader = ClReader::new(input, options).map_err(|e| cl_error(&name, &e))?;
        Ok(ClToolpath::new(reader, &name))
    }
}
