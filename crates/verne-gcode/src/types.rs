//! The reader's public value types: options, axes, rows, the summary.

use std::collections::BTreeMap;
use std::fmt;

use super::error::Warning;

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// The nine axis words of RS274/NGC, in LinuxCNC's order. A row's position is indexed by
/// `Axis as usize`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Axis {
    /// X (mm).
    X,
    /// Y (mm).
    Y,
    /// Z (mm).
    Z,
    /// A (degrees).
    A,
    /// B (degrees).
    B,
    /// C (degrees).
    C,
    /// U (mm).
    U,
    /// V (mm).
    V,
    /// W (mm).
    W,
}

/// Every axis, in order.
pub const AXES: [Axis; 9] = [
    Axis::X,
    Axis::Y,
    Axis::Z,
    Axis::A,
    Axis::B,
    Axis::C,
    Axis::U,
    Axis::V,
    Axis::W,
];

impl Axis {
    /// The axis of a letter (either case), if it is one.
    pub fn from_letter(c: u8) -> Option<Axis> {
        Some(match c.to_ascii_uppercase() {
            b'X' => Axis::X,
            b'Y' => Axis::Y,
            b'Z' => Axis::Z,
            b'A' => Axis::A,
            b'B' => Axis::B,
            b'C' => Axis::C,
            b'U' => Axis::U,
            b'V' => Axis::V,
            b'W' => Axis::W,
            _ => return None,
        })
    }

    /// The letter, upper case.
    pub fn letter(self) -> char {
        b"XYZABCUVW"[self as usize] as char
    }

    /// True for A, B, C (degrees, never scaled by G20).
    pub fn is_rotary(self) -> bool {
        matches!(self, Axis::A | Axis::B | Axis::C)
    }

    /// The bit of this axis in a [`Row::written`] or [`Summary::axes_used`] mask.
    pub fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.letter())
    }
}

/// Units of the lengths written in a program (`G20`/`G21`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Units {
    /// Millimetres (`G21`).
    Mm,
    /// Inches (`G20`): every length and feed is multiplied by 25.4 (angles are not).
    Inch,
}

impl Units {
    /// Millimetres per program length unit: 1 or 25.4.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => MM_PER_INCH,
        }
    }

    /// `mm` or `inch`.
    pub fn as_str(self) -> &'static str {
        match self {
            Units::Mm => "mm",
            Units::Inch => "inch",
        }
    }
}

/// How the reader is set up. `Options::default()` is what the CLI uses without flags.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Chord tolerance of the interpolation of arcs (`G2`/`G3`), mm (> 0): every chord between
    /// two consecutive rows of an arc stays within this distance of the arc.
    pub chord_tol_mm: f64,
    /// Most rows one arc may be interpolated into; an arc that needs more is an error.
    pub max_arc_points: u64,
    /// Units stated by the caller (`--units`): used until the program's first `G20`/`G21`,
    /// which must agree (a conflict is an error at its line). `None`: millimetres until the
    /// program says otherwise, with a warning when it never says.
    pub units: Option<Units>,
    /// Longest line, in bytes; a longer line is an error naming the line and the limit.
    pub max_line_bytes: usize,
    /// `I J K` on a straight move (`G0`/`G1`) are the tool-axis vector (the tool-centre
    /// programs of 5-axis posts, `G43.5`/ORIVECT form) instead of an error; on arcs they stay
    /// the centre offsets.
    pub ijk_tool_vector: bool,
}

/// Default chord tolerance of arcs, mm (as the CL reader).
pub const DEFAULT_CHORD_TOL_MM: f64 = 0.005;
/// Default limit of the rows of one arc.
pub const DEFAULT_MAX_ARC_POINTS: u64 = 100_000;
/// Default limit of a line: 1 MiB (a G-code block is short; a longer line is not G-code).
pub const DEFAULT_MAX_LINE_BYTES: usize = 1 << 20;

impl Default for Options {
    fn default() -> Options {
        Options {
            chord_tol_mm: DEFAULT_CHORD_TOL_MM,
            max_arc_points: DEFAULT_MAX_ARC_POINTS,
            units: None,
            max_line_bytes: DEFAULT_MAX_LINE_BYTES,
            ijk_tool_vector: false,
        }
    }
}

/// What produced a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// A straight move, `G0` or `G1`: one row at its end.
    Line,
    /// A point of an arc (`G2`/`G3`); the last row of an arc is its end point.
    Arc,
    /// A move of an expanded canned cycle (`G73`, `G81`-`G86`, `G89`).
    Cycle,
}

impl Kind {
    /// `line`, `arc` or `cycle`.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Line => "line",
            Kind::Arc => "arc",
            Kind::Cycle => "cycle",
        }
    }
}

/// Rapid or feed motion of a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motion {
    /// `G0`, and the rapid moves of a cycle.
    Rapid,
    /// A move at the programmed feed.
    Feed,
}

impl Motion {
    /// `rapid` or `feed`.
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Rapid => "rapid",
            Motion::Feed => "feed",
        }
    }
}

/// One position of the program, in block order: the end of a straight move, a point of an
/// arc, or a move of a cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// 1-based line of the block.
    pub line: u64,
    /// The block's `N` word, if any.
    pub n: Option<u64>,
    /// What produced the row.
    pub kind: Kind,
    /// Rapid or feed.
    pub motion: Motion,
    /// The programmed feed in mm/min (or degrees/min for a move of rotary axes only) for feed
    /// rows under `G94`/`G95`; `None` for rapids and under `G93`.
    pub feed_per_min: Option<f64>,
    /// Time of the move from the previous row to this one, s, as the controller plans it at
    /// the programmed feed (LinuxCNC's rule: the feed applies to X Y Z when they move, else to
    /// U V W, else to A B C in degrees/min; `G93`: the block takes 1/F minutes). `None` for
    /// rapids (the machine's rapid rate) and where no feed is known.
    pub duration_s: Option<f64>,
    /// Tool number of the last `T` word made active by `M6`, if any.
    pub tool: Option<u32>,
    /// Absolute position of every axis (mm, degrees); `NaN` where the program has not yet
    /// given the axis a value (see [`Row::known`]).
    pub position: [f64; 9],
    /// Mask of the axes with a value so far ([`Axis::bit`]).
    pub known: u16,
    /// Mask of the axes written in this block.
    pub written: u16,
    /// The tool-axis vector (`I J K`, normalised), when [`Options::ijk_tool_vector`] is set and
    /// the program has given one.
    pub tool_vector: Option<[f64; 3]>,
    /// The first comment of a straight move's block, trimmed (a post's note on the block, such
    /// as the toolpath line a joint program's block leads to); `None` for arcs and cycles.
    pub comment: Option<Note>,
}

/// The start of a block's comment: its first [`NOTE_BYTES`] bytes, kept inline so that rows
/// stay `Copy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Note {
    bytes: [u8; NOTE_BYTES],
    len: u8,
}

/// Bytes of a comment a [`Note`] keeps.
pub const NOTE_BYTES: usize = 40;

impl Note {
    /// The note of a comment's text (its first [`NOTE_BYTES`] bytes, cut at a character).
    pub fn new(text: &str) -> Note {
        let mut end = text.len().min(NOTE_BYTES);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let mut bytes = [0u8; NOTE_BYTES];
        bytes[..end].copy_from_slice(&text.as_bytes()[..end]);
        Note {
            bytes,
            len: end as u8,
        }
    }

    /// The note's text.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or("")
    }
}

impl Row {
    /// The position of one axis (`NaN` if not known yet).
    pub fn get(&self, axis: Axis) -> f64 {
        self.position[axis as usize]
    }
}

/// Most warnings kept; further ones are only counted.
pub const MAX_WARNINGS: usize = 1000;

/// What the reader saw besides the rows; complete when the iterator has returned `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Rows returned.
    pub rows: u64,
    /// Blocks (lines holding at least one word) read.
    pub blocks: u64,
    /// Physical lines read.
    pub lines: u64,
    /// Units in force at the end.
    pub units: Units,
    /// Line of the first `G20`/`G21`, if any.
    pub units_line: Option<u64>,
    /// Mask of the axes written anywhere in the program.
    pub axes_used: u16,
    /// Lines skipped by block delete (`/` at the start of the block).
    pub block_deleted: u64,
    /// Codes read that do not move the machine, counted by code (`M3`, `G64`, `S`, `T`, ...).
    pub ignored: BTreeMap<String, u64>,
    /// Line of the `M2`/`M30` (or the closing `%`) that ended the program, if any.
    pub end_line: Option<u64>,
    /// Lines after the end of the program (not read).
    pub lines_after_end: u64,
    /// Warnings, in order (at most [`MAX_WARNINGS`]).
    pub warnings: Vec<Warning>,
    /// Warnings beyond [`MAX_WARNINGS`].
    pub warnings_dropped: u64,
    /// True once a `G93` block was read.
    pub inverse_time_seen: bool,
}

impl Summary {
    pub(crate) fn new(units: Units) -> Summary {
        Summary {
            rows: 0,
            blocks: 0,
            lines: 0,
            units,
            units_line: None,
            axes_used: 0,
            block_deleted: 0,
            ignored: BTreeMap::new(),
            end_line: None,
            lines_after_end: 0,
            warnings: Vec::new(),
            warnings_dropped: 0,
            inverse_time_seen: false,
        }
    }

    pub(crate) fn warn(&mut self, line: u64, message: impl Into<String>) {
        if self.warnings.len() < MAX_WARNINGS {
            self.warnings.push(Warning {
                line,
                message: message.into(),
            });
        } else {
            self.warnings_dropped += 1;
        }
    }

    pub(crate) fn count(&mut self, code: &str) {
        if let Some(n) = self.ignored.get_mut(code) {
            *n += 1;
        } else if self.ignored.len() < 256 {
            self.ignored.insert(code.to_string(), 1);
        }
    }

    /// The letters of the axes the program writes, e.g. `XYZAC`.
    pub fn axes_used_letters(&self) -> String {
        AXES.iter()
            .filter(|a| self.axes_used & a.bit() != 0)
            .map(|a| a.letter())
            .collect()
    }

    /// The codes read that do not move the machine, on one line: `M3 x1, S x2`.
    pub fn ignored_line(&self) -> String {
        let v: Vec<String> = self
            .ignored
            .iter()
            .map(|(k, n)| format!("{k} x{n}"))
            .collect();
        v.join(", ")
    }
}
