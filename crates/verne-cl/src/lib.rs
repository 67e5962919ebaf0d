//! Reader of CL (cutter-location / APT source) files for the VERNE machine: the tool-tip
//! positions and tool axes of NX CLSF files and information listings, Creo/Pro-E `.ncl`,
//! SolidWorks CAM `.apt`, CATIA V5 APT source and generic APT, as rows in mm in the workpiece
//! frame. Every feature is read as its dialect means it, or refused with the line.
//!
//! The rules are those of `docs/cl-dialects.md` (the CL dialect specification; section numbers,
//! e.g. SPEC §4, refer to it). In short:
//!
//! - [`sniff`]: is a file a CL file (extension, or first record)? (SPEC §2)
//! - [`Reader`]: streaming iterator of [`Row`]s, errors as [`ClError`] (line, column, kind),
//!   warnings and tool changes in the [`Summary`];
//! - [`read_all`] and [`open`]: conveniences; [`fuzz_read`]: an entry point that must never
//!   panic.
//!
//! ```
//! use verne_cl::{Options, read_all};
//! let cl = "UNITS/MM\nRAPID\nGOTO/0,0,50\nFEDRAT/MMPM,500\nGOTO/0,0,0,0,0,1\nFINI\n";
//! let (rows, summary) = read_all("part.cl", cl.as_bytes(), &Options::default()).unwrap();
//! assert_eq!(rows.len(), 2);
//! assert_eq!(rows[1].feed_mm_min, Some(500.0));
//! assert!(summary.warnings.is_empty());
//! ```

#![deny(missing_docs)]
#![forbid(unsafe_code)]

mod arc;
mod error;
mod geom;
mod lex;
mod number;
mod reader;
mod sniff;
mod types;

use std::fs::File;
use std::io::{BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::Path;

pub use error::{ClError, ClErrorKind, Warning, WarningKind};
pub use reader::Reader;
pub use sniff::{SNIFF_BYTES, has_cl_extension, sniff, sniff_content};
pub use types::{
    ArcRule, DEFAULT_CHORD_TOL_MM, DEFAULT_MAX_ARC_POINTS, DEFAULT_MAX_RECORD_BYTES, Dialect, Kind,
    MAX_SKIPPED_NAMES, MAX_TOOL_CHANGES, MAX_WARNINGS, MM_PER_INCH, Motion, OTHER_RECORDS, Options,
    Row, Summary, ToolChange, Units, UnitsSource,
};

/// Opens a file for reading as CL: checks it with [`sniff`] (its name and first
/// [`SNIFF_BYTES`] bytes) and returns a [`Reader`] from its start. A file that is not a CL
/// file is an error at line 1 ([`ClErrorKind::NotClFile`]); a file that cannot be opened, an
/// error at line 0.
pub fn open(path: &Path, options: Options) -> Result<Reader<BufReader<File>>, ClError> {
    let io = |e: std::io::Error| ClError {
        line: 0,
        column: None,
        kind: ClErrorKind::Io(format!("{}: {e}", path.display())),
    };
    let mut f = File::open(path).map_err(io)?;
    let mut head = Vec::with_capacity(SNIFF_BYTES);
    (&mut f)
        .take(SNIFF_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(io)?;
    let name = path.to_string_lossy();
    if !sniff(&name, &head) {
        return Err(ClError {
            line: 1,
            column: None,
            kind: ClErrorKind::NotClFile,
        });
    }
    f.seek(SeekFrom::Start(0)).map_err(io)?;
    Reader::new(BufReader::with_capacity(64 * 1024, f), options)
}

/// Reads a whole CL file held in memory: [`sniff`] with `path_name`, then every row.
/// Returns the rows and the summary, or the first error.
pub fn read_all(
    path_name: &str,
    bytes: &[u8],
    options: &Options,
) -> Result<(Vec<Row>, Summary), ClError> {
    let head = &bytes[..bytes.len().min(SNIFF_BYTES)];
    if !sniff(path_name, head) {
        return Err(ClError {
            line: 1,
            column: None,
            kind: ClErrorKind::NotClFile,
        });
    }
    let mut reader = Reader::new(Cursor::new(bytes), *options)?;
    let mut rows = Vec::new();
    for r in reader.by_ref() {
        rows.push(r?);
    }
    Ok((rows, reader.into_summary()))
}

/// Fuzzing entry point: reads `bytes` as a CL file in several set-ups and checks the
/// invariants of the output (finite numbers, unit axes, positive lines, non-negative feeds).
/// It must never panic, whatever the bytes; it panics only if an invariant is broken.
pub fn fuzz_read(bytes: &[u8]) {
    let _ = sniff("fuzz.txt", bytes);
    let _ = sniff("fuzz.cls", bytes);
    let small = Options {
        chord_tol_mm: 0.01,
        units: None,
        max_record_bytes: 4096,
        max_arc_points: 2000,
    };
    let setups = [
        small,
        Options {
            units: Some(Units::Inch),
            ..small
        },
    ];
    for opts in setups {
        let Ok(reader) = Reader::new(Cursor::new(bytes), opts) else {
            continue;
        };
        check_rows(reader);
    }
    if let Ok(reader) = Reader::with_units(bytes, Units::Mm, small) {
        check_rows(reader);
    }
    let _ = read_all("fuzz.cl", bytes, &small);
}

fn check_rows<R: std::io::BufRead>(mut reader: Reader<R>) {
    let mut n = 0u64;
    for r in reader.by_ref() {
        match r {
            Ok(row) => {
                n += 1;
                assert!(row.line >= 1, "row line");
                assert!(row.tip.iter().all(|x| x.is_finite()), "tip {row:?}");
                let len = row.axis.iter().map(|x| x * x).sum::<f64>().sqrt();
                assert!((len - 1.0).abs() < 1e-6, "axis {row:?}");
                if let Some(f) = row.feed_mm_min {
                    assert!(f.is_finite() && f >= 0.0, "feed {row:?}");
                }
                if row.motion == Motion::Rapid {
                    assert!(row.feed_mm_min.is_none(), "rapid with feed {row:?}");
                }
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
    let s = reader.summary();
    assert_eq!(s.rows, n, "row count");
    let _ = s.skipped_line();
    for w in &s.warnings {
        let _ = w.to_string();
    }
}
