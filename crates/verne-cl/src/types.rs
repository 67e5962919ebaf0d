//! The reader's public value types: options, rows, units, the summary.

use std::collections::BTreeMap;
use std::fmt;

use super::error::Warning;

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// Default chord tolerance for the interpolation of arcs, in mm (SPEC §7.3: "spacing chosen by
/// the reader"; the issue asks for 0.005 mm by default).
pub const DEFAULT_CHORD_TOL_MM: f64 = 0.005;

/// Default limit of a physical line and of a logical record (all its continuation lines
/// joined), in bytes: 16 MiB.
pub const DEFAULT_MAX_RECORD_BYTES: usize = 16 * 1024 * 1024;

/// Default limit of the number of rows one `CIRCLE` may be interpolated into.
pub const DEFAULT_MAX_ARC_POINTS: u64 = 100_000;

/// Units of the lengths written in a CL file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Units {
    /// Millimetres (`UNITS/MM`, `UNIT/MM`).
    Mm,
    /// Inches (`UNITS/INCHES`, `UNITS/INCH`): every length and feed is multiplied by 25.4.
    Inch,
}

impl Units {
    /// Millimetres per file length unit: 1 or 25.4.
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

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How the reader is set up. `Options::default()` is what the CLI uses without flags.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Chord tolerance of the interpolation of `CIRCLE` records, mm (> 0). Every chord between
    /// two consecutive rows of an arc stays within this distance of the arc.
    pub chord_tol_mm: f64,
    /// Units stated by the caller (`--units`). `None`: decided from the file (SPEC §4, needs a
    /// look-ahead pass, see [`Reader::new`](super::Reader::new)). `Some(u)`: used for the whole
    /// file; a `UNITS` record or an `Information Units` header line that says otherwise is an
    /// error at its line.
    pub units: Option<Units>,
    /// Longest physical line and longest logical record (continuations joined), in bytes.
    /// Longer input is an error naming the line and the limit.
    pub max_record_bytes: usize,
    /// Most rows one arc may be interpolated into; an arc that needs more at
    /// `chord_tol_mm` is an error (raise the tolerance).
    pub max_arc_points: u64,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            chord_tol_mm: DEFAULT_CHORD_TOL_MM,
            units: None,
            max_record_bytes: DEFAULT_MAX_RECORD_BYTES,
            max_arc_points: DEFAULT_MAX_ARC_POINTS,
        }
    }
}

/// Which record produced a row (SPEC §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// `FROM`: the start position.
    From,
    /// `GOTO`, a bare point line continuing a `GOTO` (Creo), or `GODLTA`.
    Goto,
    /// A point on an arc (`CIRCLE` + end `GOTO`); the last row of an arc is its end point.
    Circle,
    /// A move of an expanded canned cycle (`CYCLE` + cycle point `GOTO`).
    Cycle,
}

impl Kind {
    /// `FROM`, `GOTO`, `CIRCLE` or `CYCLE`, as in the corpus files.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::From => "FROM",
            Kind::Goto => "GOTO",
            Kind::Circle => "CIRCLE",
            Kind::Cycle => "CYCLE",
        }
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Rapid or feed motion of a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motion {
    /// Positioning move (`RAPID` one-shot, `FROM`, the rapid moves of a cycle).
    Rapid,
    /// Cutting move at the current feed.
    Feed,
}

impl Motion {
    /// `rapid` or `feed`, as in the corpus files.
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Rapid => "rapid",
            Motion::Feed => "feed",
        }
    }
}

impl fmt::Display for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One tool position, in file order (SPEC §1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// 1-based line of the first line of the record that produced the row (for arcs: of the
    /// `CIRCLE` record; for cycles: of the cycle point `GOTO`).
    pub line: u64,
    /// Which record produced the row.
    pub kind: Kind,
    /// Rapid or feed.
    pub motion: Motion,
    /// Feed in mm/min for feed rows; `None` for rapid rows and for feed rows before any feed
    /// is known. Per-revolution feeds are multiplied by the spindle speed, inverse-time feeds
    /// by the length of the move (SPEC §5.6).
    pub feed_mm_min: Option<f64>,
    /// Tool number of the last `LOADTL/n` or `LOAD/TOOL,n`, if any.
    pub tool: Option<u32>,
    /// Tool tip, mm, in the output (workpiece) frame (SPEC §6).
    pub tip: [f64; 3],
    /// Tool axis, unit vector from the tip towards the spindle, in the output frame.
    pub axis: [f64; 3],
}

/// Where the file's units came from (SPEC §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitsSource {
    /// Stated by the caller ([`Options::units`]).
    Stated,
    /// A `UNITS`/`UNIT` record before the first motion, at this line.
    Record {
        /// Line of the record.
        line: u64,
    },
    /// An NX listing header line `Information Units : …`, at this line.
    ListingHeader {
        /// Line of the header line.
        line: u64,
    },
    /// No `UNITS`: the feed unit words (`IPM`/`IPR` or `MMPM`/`MMPR`), first seen at this line.
    FeedWords {
        /// First line with a feed unit word.
        line: u64,
    },
    /// Nothing says: millimetres assumed (with a warning).
    Default,
}

/// The CAM system whose output the file looks like. Informational only: the one decision
/// that depends on the dialect, the direction of `CIRCLE`, follows the rule of SPEC §7.2
/// ([`ArcRule`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// Siemens NX CLSF (`TOOL PATH`, `TLDATA`, `MSYS`, `END-OF-PATH`).
    NxClsf,
    /// An NX information listing of a tool path (header lines, SPEC §3.9).
    NxListing,
    /// PTC Creo / Pro/ENGINEER Pro/CLfile (`$$->` directives, `$$* Pro/CLfile`).
    Creo,
    /// SolidWorks CAM / CAMWorks (`UNIT/`, `TRNTYP`, `CSI_SET_*`).
    SolidWorks,
    /// CATIA V5 APT source (`$$*CATIA0`).
    Catia,
    /// Generic APT source (nothing more specific seen).
    Apt,
}

impl Dialect {
    /// A short name for display.
    pub fn as_str(self) -> &'static str {
        match self {
            Dialect::NxClsf => "NX CLSF",
            Dialect::NxListing => "NX information listing",
            Dialect::Creo => "Creo Pro/CLfile",
            Dialect::SolidWorks => "SolidWorks CAM",
            Dialect::Catia => "CATIA V5 APT",
            Dialect::Apt => "generic APT",
        }
    }
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Direction of travel of `CIRCLE` records (SPEC §7.2), decided at the first `CIRCLE`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArcRule {
    /// NX CLSF: the tool moves clockwise about the written axis (a `TOOL PATH`, `TLDATA`,
    /// `MSYS` or `END-OF-PATH` came before the first `CIRCLE`).
    ClockwiseAboutAxis,
    /// Everyone else: counter-clockwise about the written axis (right-hand rule).
    RightHand,
}

/// A change of the tool in use, listed so that the CLI can print it and use the tool length.
///
/// An entry is made at the first row after the tool number (`LOADTL`, `LOAD/TOOL`), the NX
/// tool name (`TOOL PATH/…,TOOL,name`) or the `TLDATA` length changed; loading the same tool
/// again makes no entry.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolChange {
    /// Line of the record that set the tool (the latest of `LOADTL`/`LOAD/TOOL`, `TLDATA`,
    /// `TOOL PATH` before the first row with it).
    pub line: u64,
    /// Line of the first row made with this tool.
    pub first_row_line: u64,
    /// 0-based index of the first row made with this tool, in the reader's output.
    pub first_row_index: u64,
    /// Tool number, if the file gives one.
    pub tool: Option<u32>,
    /// NX tool name from `TOOL PATH/op,TOOL,name`, if any.
    pub name: Option<String>,
    /// Tool length in mm from the third number of NX `TLDATA/MILL` (or `TLDATA/DRILL,MILL`) of
    /// the current tool path: information only (SPEC §5.9); the machine file or a
    /// `--tool-length` flag should take precedence.
    pub length_mm: Option<f64>,
}

/// Most distinct names kept in [`Summary::skipped`]; further names are counted under
/// [`OTHER_RECORDS`].
pub const MAX_SKIPPED_NAMES: usize = 256;
/// Key of [`Summary::skipped`] that counts the records beyond [`MAX_SKIPPED_NAMES`] names.
pub const OTHER_RECORDS: &str = "(other)";
/// Most warnings kept; further ones are only counted in [`Summary::warnings_dropped`].
pub const MAX_WARNINGS: usize = 1000;
/// Most tool changes kept; further ones are only counted in [`Summary::tools_dropped`].
pub const MAX_TOOL_CHANGES: usize = 100_000;

/// What the reader saw besides the rows. Filled as the rows are read; complete when the
/// iterator has returned `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Rows returned.
    pub rows: u64,
    /// Physical lines read.
    pub lines: u64,
    /// Records read but not turned into motion, per record name (upper case; names only, no
    /// free text), e.g. `PAINT`, `COOLNT`, `PPRINT`, `SPINDL`, unknown records (SPEC §5.12–5.13).
    pub skipped: BTreeMap<String, u64>,
    /// Warnings, in the order given (at most [`MAX_WARNINGS`]).
    pub warnings: Vec<Warning>,
    /// Warnings beyond [`MAX_WARNINGS`].
    pub warnings_dropped: u64,
    /// Tool changes (at most [`MAX_TOOL_CHANGES`]).
    pub tools: Vec<ToolChange>,
    /// Tool changes beyond [`MAX_TOOL_CHANGES`].
    pub tools_dropped: u64,
    /// Units the file was read in.
    pub units: Units,
    /// Where [`Summary::units`] came from.
    pub units_source: UnitsSource,
    /// What the file looks like (informational).
    pub dialect: Dialect,
    /// Direction rule of arcs, once a `CIRCLE` was read.
    pub arc_rule: Option<ArcRule>,
    /// Line of `FINI`, if reading stopped there.
    pub fini_line: Option<u64>,
}

impl Summary {
    pub(super) fn new(units: Units, units_source: UnitsSource) -> Summary {
        Summary {
            rows: 0,
            lines: 0,
            skipped: BTreeMap::new(),
            warnings: Vec::new(),
            warnings_dropped: 0,
            tools: Vec::new(),
            tools_dropped: 0,
            units,
            units_source,
            dialect: Dialect::Apt,
            arc_rule: None,
            fini_line: None,
        }
    }

    /// The skipped records on one line, most frequent first: `PAINT 12, COOLNT 2, PPRINT 1`
    /// (empty when nothing was skipped).
    pub fn skipped_line(&self) -> String {
        let mut v: Vec<(&String, &u64)> = self.skipped.iter().collect();
        v.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let parts: Vec<String> = v.iter().map(|(k, n)| format!("{k} {n}")).collect();
        parts.join(", ")
    }

    pub(super) fn count_skipped(&mut self, name: &[u8]) {
        // Names are validated by the lexer (letters, digits, `_`, `-`, `TOOL PATH`): no free
        // text can get here. Long names are cut to 32 bytes.
        let name = &name[..name.len().min(32)];
        let key = std::str::from_utf8(name).unwrap_or("?");
        if let Some(n) = self.skipped.get_mut(key) {
            *n += 1;
        } else if self.skipped.len() < MAX_SKIPPED_NAMES {
            self.skipped.insert(key.to_string(), 1);
        } else {
            *self.skipped.entry(OTHER_RECORDS.to_string()).or_insert(0) += 1;
        }
    }

    pub(super) fn warn(&mut self, w: Warning) {
        if self.warnings.len() < MAX_WARNINGS {
            self.warnings.push(w);
        } else {
            self.warnings_dropped += 1;
        }
    }
}

/// Latin-1 text for a message: at most `max` characters of the input, `…` appended when cut.
/// Control characters (NUL, BEL, ESC, DEL and the C1 range 0x80-0x9F, CSI among them) are
/// escaped as Rust writes them (`\0`, `\u{7}`, `\u{1b}`), as the core's `verne::error::shown`
/// does: bytes of a file are never echoed raw to a terminal.
pub(super) fn latin1_short(b: &[u8], max: usize) -> String {
    let mut s = String::with_capacity(b.len().min(max));
    for c in b.iter().take(max).map(|&c| c as char) {
        if c.is_control() {
            s.extend(c.escape_default());
        } else {
            s.push(c);
        }
    }
    if b.len() > max {
        s.push('…');
    }
    s
}
