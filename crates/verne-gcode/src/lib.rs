//! Reader of G-code for the VERNE machine: RS274/NGC as LinuxCNC reads it, with the common
//! words of Fanuc-style controls, as a stream of canonical positions ([`Row`]): every axis
//! word (X Y Z A B C U V W) made absolute in mm and degrees, arcs interpolated within a chord
//! tolerance, canned cycles expanded, rapid or feed, the time of each move at its feed, the
//! line and `N` word of the block that made it.
//!
//! The reader does not know what the axis letters mean: the CLI maps them to the machine's
//! joints (a joint program) or to the tool tip and orientation (a tool-centre program) from
//! the machine file's `[gcode]` table. Whatever it cannot read exactly (parameters,
//! expressions, o-word control, work offsets other than G54, tool length and cutter radius
//! compensation, homing moves) is refused with its line and column, never skipped. The rules
//! are in `docs/gcode.md`.
//!
//! ```
//! use verne_gcode::{Axis, Options, read_all};
//! let program = "G21 G90\nG0 X0 Y0 Z10\nG1 Z0 F300\nG2 X10 Y0 I5 J0\nM2\n";
//! let (rows, summary) = read_all(program.as_bytes(), &Options::default()).unwrap();
//! assert_eq!(rows[1].duration_s, Some(2.0)); // 10 mm at 300 mm/min
//! let end = rows.last().unwrap();
//! assert_eq!((end.get(Axis::X), end.get(Axis::Y)), (10.0, 0.0));
//! assert_eq!(summary.end_line, Some(5));
//! ```

#![deny(missing_docs)]
#![forbid(unsafe_code)]

mod arc;
mod block;
mod cycle;
mod error;
mod reader;
mod types;

use std::io::{BufRead, Cursor};

pub use arc::RADIUS_TOLERANCE_MM;
pub use block::MAX_WORDS;
pub use cycle::PECK_CLEARANCE_MM;
pub use error::{GcodeError, Warning};
pub use reader::Reader;
pub use types::{
    AXES, Axis, DEFAULT_CHORD_TOL_MM, DEFAULT_MAX_ARC_POINTS, DEFAULT_MAX_LINE_BYTES, Kind,
    MAX_WARNINGS, MM_PER_INCH, Motion, NOTE_BYTES, Note, Options, Row, Summary, Units,
};

/// File extensions of G-code programs (compared ignoring case).
pub const EXTENSIONS: &[&str] = &[
    "ngc", "nc", "gcode", "gco", "gc", "tap", "cnc", "iso", "mpf", "eia",
];

/// True when the file name ends with a G-code extension ([`EXTENSIONS`]).
pub fn has_gcode_extension(name: &str) -> bool {
    let Some((_, ext)) = name.rsplit_once('.') else {
        return false;
    };
    EXTENSIONS.iter().any(|e| e.eq_ignore_ascii_case(ext))
}

/// True when the first lines of a file look like G-code: the first line that is not blank or
/// a comment is `%`, a program number `O123`, or a block that begins (after an optional `/`
/// and `N` word) with a G, M, T, F, S or axis word and its number. A CSV header (`x,y,z`) or
/// a CL record (`GOTO/`, `PARTNO`, `$$`) is not.
pub fn sniff_content(head: &[u8]) -> bool {
    let head = head.strip_prefix(b"\xef\xbb\xbf").unwrap_or(head);
    for raw in head.split(|&b| b == b'\n') {
        let mut t: &[u8] = raw.trim_ascii();
        if t.is_empty() || t.starts_with(b";") {
            continue;
        }
        if t.starts_with(b"(") {
            match t.iter().position(|&b| b == b')') {
                Some(end) if t[end + 1..].trim_ascii().is_empty() => continue,
                Some(end) => t = t[end + 1..].trim_ascii(),
                None => return false,
            }
        }
        if t == b"%" || t.starts_with(b"%") && t[1..].trim_ascii().starts_with(b"(") {
            return true;
        }
        let t = t.strip_prefix(b"/").unwrap_or(t);
        let word = |t: &[u8], letters: &[u8]| -> Option<usize> {
            let c = t.first()?.to_ascii_uppercase();
            if !letters.contains(&c) {
                return None;
            }
            let mut i = 1;
            while i < t.len() && t[i] == b' ' {
                i += 1;
            }
            let d = *t.get(i)?;
            let mut j = i;
            if matches!(d, b'-' | b'+' | b'.') {
                j += 1;
            }
            if !t.get(j)?.is_ascii_digit() {
                return None;
            }
            while j < t.len() && (t[j].is_ascii_digit() || t[j] == b'.') {
                j += 1;
            }
            Some(j)
        };
        if let Some(j) = word(t, b"O") {
            return t[j..].iter().all(|&b| b != b',');
        }
        let t = match word(t, b"N") {
            Some(j) => t[j..].trim_ascii_start(),
            None => t,
        };
        return word(t, b"GMTFSXYZABCUVW").is_some() && !t.contains(&b',');
    }
    false
}

/// Reads a whole program held in memory. Returns the rows and the summary, or the first error.
pub fn read_all(bytes: &[u8], options: &Options) -> Result<(Vec<Row>, Summary), GcodeError> {
    let mut reader = Reader::new(Cursor::new(bytes), *options)?;
    let mut rows = Vec::new();
    for r in reader.by_ref() {
        rows.push(r?);
    }
    Ok((rows, reader.into_summary()))
}

/// Reads every row of `input`, discarding them: the rows counted in the summary.
pub fn count<R: BufRead>(input: R, options: &Options) -> Result<Summary, GcodeError> {
    let mut reader = Reader::new(input, *options)?;
    for r in reader.by_ref() {
        r?;
    }
    Ok(reader.into_summary())
}

/// Fuzzing entry point: reads `bytes` in several set-ups and checks the invariants of the
/// output (lines increasing, known axes finite, unit tool vectors, non-negative durations).
/// It must never panic, whatever the bytes; it panics only if an invariant is broken.
pub fn fuzz_read(bytes: &[u8]) {
    let _ = sniff_content(bytes);
    let small = Options {
        chord_tol_mm: 0.01,
        max_arc_points: 2000,
        units: None,
        max_line_bytes: 4096,
        ijk_tool_vector: false,
    };
    for opts in [
        small,
        Options {
            ijk_tool_vector: true,
            units: Some(Units::Inch),
            ..small
        },
    ] {
        let Ok(mut reader) = Reader::new(Cursor::new(bytes), opts) else {
            continue;
        };
        let mut last_line = 0;
        let mut n = 0u64;
        for r in reader.by_ref() {
            let Ok(row) = r else { break };
            n += 1;
            assert!(row.line >= last_line && row.line >= 1, "line order {row:?}");
            last_line = row.line;
            for a in AXES {
                if row.known & a.bit() != 0 {
                    assert!(
                        row.get(a).is_finite() || row.get(a).is_nan(),
                        "axis {row:?}"
                    );
                }
            }
            if let Some(v) = row.tool_vector {
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                assert!((len - 1.0).abs() < 1e-9, "vector {row:?}");
            }
            if let Some(d) = row.duration_s {
                assert!(d >= 0.0 || d.is_nan(), "duration {row:?}");
            }
        }
        assert_eq!(reader.summary().rows, n, "row count");
    }
}
