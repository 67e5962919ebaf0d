//! Errors and warnings of the CL reader.

use std::fmt;

use super::types::Units;

/// An error at a place in a CL file. Reading stops at the first error.
#[derive(Debug, Clone, PartialEq)]
pub struct ClError {
    /// 1-based line: the first line of the offending record (SPEC §1). 0 when the error is
    /// not about a line (the file cannot be opened, invalid options).
    pub line: u64,
    /// 1-based column (bytes) within that line, where meaningful (a bad field or name on the
    /// record's first line).
    pub column: Option<u64>,
    /// What went wrong; `Display` gives the message.
    pub kind: ClErrorKind,
}

impl ClError {
    pub(super) fn new(line: u64, column: Option<u64>, kind: ClErrorKind) -> ClError {
        ClError { line, column, kind }
    }

    pub(super) fn at(line: u64, kind: ClErrorKind) -> ClError {
        ClError {
            line,
            column: None,
            kind,
        }
    }
}

impl fmt::Display for ClError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "line {}", self.line)?;
            if let Some(c) = self.column {
                write!(f, ", column {c}")?;
            }
            f.write_str(": ")?;
        }
        fmt::Display::fmt(&self.kind, f)
    }
}

impl std::error::Error for ClError {}

/// What went wrong in a CL file.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ClErrorKind {
    /// Reading failed.
    Io(String),
    /// The reader's options are not usable (chord tolerance not positive, limits zero).
    InvalidOptions(&'static str),
    /// Neither the extension nor the first record says CL (SPEC §2).
    NotClFile,
    /// A physical line or a logical record is longer than the limit.
    RecordTooLong {
        /// The limit, bytes.
        limit: usize,
    },
    /// A carriage return that is not part of a line end (old Mac line ends).
    CarriageReturn,
    /// The file ends on a record continued with `$` (SPEC §3.6).
    ContinuationAtEof,
    /// The file ends on a comment continued with `$` (SPEC §3.7).
    CommentContinuationAtEof,
    /// A record name with characters other than letters, digits, `_`, `-` (SPEC §3.4).
    BadRecordName {
        /// The name found (cut).
        found: String,
    },
    /// A field that must be a number is empty or not a number.
    BadNumber {
        /// Record name.
        record: String,
        /// 1-based field number.
        field: usize,
        /// The text found (cut; empty for an empty field).
        found: String,
    },
    /// A number too large for a 64-bit float (or a length that overflows once converted).
    NumberOutOfRange {
        /// Record name.
        record: String,
    },
    /// Wrong number of values.
    FieldCount {
        /// Record name.
        record: String,
        /// What is expected, e.g. `3 or 6`.
        expected: &'static str,
        /// How many values the record has.
        found: usize,
    },
    /// A tool axis of length zero (SPEC §5.2).
    ZeroAxis {
        /// Record name.
        record: String,
    },
    /// A `TLAXIS` other than `TLAXIS/i,j,k` (SPEC §5.2a): a tool axis set from surfaces or
    /// angles, which a CL file does not carry.
    TlaxisForm {
        /// The field that is not a number (empty when the count is wrong).
        found: String,
        /// Number of fields of the record.
        fields: usize,
    },
    /// `UNITS` with a value other than `MM`, `INCHES`, `INCH` (SPEC §4).
    UnknownUnits {
        /// The value found.
        found: String,
    },
    /// `Information Units : …` with a value other than `in`/`inch`/`inches`/`mm`.
    UnknownListingUnits {
        /// The value found.
        found: String,
    },
    /// A `UNITS` record after motion that changes the units (SPEC §4).
    UnitsChanged {
        /// Units in force.
        from: Units,
        /// Units of the record.
        to: Units,
    },
    /// The file states other units than the caller (or than an earlier statement in the file).
    UnitsConflict {
        /// Units in force (stated by the caller, or by the file earlier).
        stated: Units,
        /// Units of this record or header line.
        found: Units,
    },
    /// No `UNITS` record and both inch and mm feed units (SPEC §4).
    UnitsUndecidable {
        /// First line with `IPM`/`IPR`.
        inch_line: u64,
        /// First line with `MMPM`/`MMPR`.
        mm_line: u64,
    },
    /// An APT geometric motion statement (`GOFWD`, `TLON,GOFWD/…`, …, SPEC §5.14).
    GeometricStatement {
        /// Record name.
        name: String,
    },
    /// NX `NURBS`/`KNOT`/`CNTRL` (SPEC §7.6).
    Nurbs {
        /// Record name.
        name: String,
    },
    /// `TRACUT` (other than `TRACUT/NOMORE`) or `COPY`: a CL-level transformation or repetition
    /// of the following records, not implemented.
    Transformation {
        /// Record name.
        name: String,
    },
    /// `MSYS` with 12 values (SPEC §6.1).
    Msys12,
    /// `MSYS` axes not unit and orthogonal within 1e-4.
    MsysNotOrthonormal,
    /// A non-identity `CSYS` without `TRNTYP/WORLD` (SPEC §6.2).
    CsysLocal,
    /// A second, different `$$-> CSYS` or `$$*CATIA0` frame (SPEC §6.3, §6.4).
    FrameChanged {
        /// `$$-> CSYS` or `$$*CATIA0`.
        what: &'static str,
        /// Line of the first frame.
        first_line: u64,
    },
    /// `$$-> CSYS` without 12 numbers.
    FrameMatrix {
        /// `$$-> CSYS`.
        what: &'static str,
    },
    /// `FEDRAT` without exactly one value.
    FedratValues {
        /// Number of values found.
        found: usize,
    },
    /// `FEDRAT` with an unknown word, or two unit words.
    FedratWord {
        /// The word.
        found: String,
    },
    /// A feed that is not positive.
    FeedNotPositive,
    /// A feed per revolution while no spindle speed is known (or `SPINDL/OFF`).
    PerRevWithoutSpindle {
        /// Line of the feed per revolution (`FEDRAT` or `CYCLE`).
        feed_line: u64,
    },
    /// A negative spindle speed.
    BadSpindle,
    /// `LOADTL`/`LOAD/TOOL` without a tool number (a non-negative integer).
    ToolNumber {
        /// Record name.
        record: String,
    },
    /// `RAPID` directly before `CIRCLE` (SPEC §5.5).
    RapidBeforeCircle,
    /// `CIRCLE` before any position.
    CircleBeforePosition,
    /// A record other than `GOTO`, `PAINT`, `FEDRAT` or comments between `CIRCLE` and its end
    /// point (SPEC §7.1).
    RecordAfterCircle {
        /// Record name.
        name: String,
    },
    /// The file ends (or `FINI`) after a `CIRCLE` without its end point.
    CircleWithoutEnd,
    /// Start and end radius of an arc differ by more than 0.005 mm (SPEC §7.1).
    ArcRadius {
        /// Start radius, mm.
        start: f64,
        /// End radius, mm.
        end: f64,
    },
    /// The radius written in `CIRCLE` does not match the start/end radius (SPEC §7.1).
    ArcRadiusGiven {
        /// Radius written, mm.
        given: f64,
        /// Start radius, mm.
        start: f64,
        /// End radius, mm.
        end: f64,
    },
    /// The arc's start is on its axis.
    ArcZeroRadius,
    /// The end of the arc is within 0.005 mm of its start but not on it, and the dialect's
    /// direction makes it almost a full turn: a full circle written with noise, or a tiny arc
    /// read the wrong way round. Refused rather than guessed.
    ArcAmbiguous {
        /// Distance between start and end, radially, mm.
        chord: f64,
    },
    /// A point given after `CIRCLE` (Creo) is not on the arc.
    ArcPointOff {
        /// Distance from the arc (radially or along the helix axis), mm.
        distance: f64,
    },
    /// A point given after `CIRCLE` (Creo) is not between the previous point and the end in
    /// the direction of travel.
    ArcPointOrder,
    /// The arc needs more rows than [`Options::max_arc_points`](super::Options::max_arc_points)
    /// at the chord tolerance.
    ArcTooManyPoints {
        /// Rows needed.
        needed: u64,
        /// The limit.
        limit: u64,
    },
    /// The tool axis turns by 180° along an arc: the interpolation plane is undefined.
    ArcAxisFlip,
    /// `CYCLE` without arguments.
    CycleEmpty,
    /// `CYCLE/ON` with no active cycle.
    CycleOnWithoutCycle,
    /// A positional `CYCLE/type,d,unit,f,c` that is incomplete.
    CyclePositional,
    /// A cycle without depth (`FEDTO`/`DEPTH`).
    CycleNoDepth,
    /// A cycle type that is not a straight in-and-out cycle along the tool axis.
    CycleType {
        /// The type found.
        found: String,
    },
    /// A cycle keyword (`FEDTO`, `DEPTH`, `RAPTO`, `RTRCTO`, a feed word) without its value.
    CycleKeyword {
        /// The keyword.
        word: String,
    },
    /// `GODLTA` before any position (SPEC §5.4).
    GodltaBeforePosition,
    /// A line of numbers that does not directly follow a `GOTO` (SPEC §3.10).
    BarePoint,
    /// The file has no motion record.
    NoMotion,
}

impl fmt::Display for ClErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use ClErrorKind::*;
        match self {
            Io(e) => write!(f, "cannot read: {e}"),
            InvalidOptions(what) => write!(f, "invalid reader options: {what}"),
            NotClFile => f.write_str("not a CL file (extension and first record not recognised)"),
            RecordTooLong { limit } => write!(
                f,
                "record longer than the limit of {limit} bytes ({} MiB)",
                limit / (1024 * 1024)
            ),
            CarriageReturn => f.write_str(
                "carriage return inside a line: expected LF or CRLF line ends (old Mac CR line ends are not supported)",
            ),
            ContinuationAtEof => f.write_str(
                "continuation ($) at the end of the file: expected a continuation line",
            ),
            CommentContinuationAtEof => f.write_str(
                "continued comment ($) at the end of the file: expected a continuation line",
            ),
            BadRecordName { found } => write!(
                f,
                "bad record name `{found}`: expected letters, digits, `_` or `-` before `/` (or a `$$` comment)"
            ),
            BadNumber {
                record,
                field,
                found,
            } => {
                if found.is_empty() {
                    write!(f, "{record} has an empty field {field}: expected a number")
                } else {
                    write!(
                        f,
                        "{record} has a non-numeric field {field} `{found}`: expected a number"
                    )
                }
            }
            NumberOutOfRange { record } => write!(f, "{record}: number out of range"),
            FieldCount {
                record,
                expected,
                found,
            } => write!(f, "{record} needs {expected} values, has {found}"),
            ZeroAxis { record } => write!(f, "{record} tool axis is zero"),
            TlaxisForm { found, fields } => {
                if found.is_empty() {
                    write!(
                        f,
                        "TLAXIS needs 3 values i,j,k (a fixed tool axis), has {fields}"
                    )
                } else {
                    write!(
                        f,
                        "TLAXIS with `{found}`: only TLAXIS/i,j,k (a fixed tool axis) can be read; its other forms set the axis from surfaces or angles, which the CL file does not carry"
                    )
                }
            }
            UnknownUnits { found } => write!(
                f,
                "unknown UNITS value '{found}' (MM, INCHES or INCH expected)"
            ),
            UnknownListingUnits { found } => write!(
                f,
                "unknown Information Units value '{found}' (in or mm expected)"
            ),
            UnitsChanged { from, to } => {
                write!(f, "UNITS changes after motion (from {from} to {to})")
            }
            UnitsConflict { stated, found } => write!(
                f,
                "the file says {found} here but the units are {stated} (stated earlier)"
            ),
            UnitsUndecidable { inch_line, mm_line } => write!(
                f,
                "no UNITS record and both inch and mm feed units (inch at line {inch_line}, mm at line {mm_line}): units undecidable; state the units"
            ),
            GeometricStatement { name } => write!(
                f,
                "APT geometric motion statement {name} not supported (it needs surface intersection; output the path as GOTOs)"
            ),
            Nurbs { name } => write!(
                f,
                "{name}: NX NURBS tool path output is not supported (its CLSF layout is not established; output the path as GOTOs)"
            ),
            Transformation { name } => write!(
                f,
                "{name}: CL-level transformation or copy of records is not supported"
            ),
            Msys12 => f.write_str("MSYS with 12 values: layout not established (NX writes 9)"),
            MsysNotOrthonormal => f.write_str(
                "MSYS axes are not orthonormal (X and Y must be unit and orthogonal within 1e-4)",
            ),
            CsysLocal => f.write_str(
                "CSYS without TRNTYP/WORLD: whether the following points are local or world coordinates is not established",
            ),
            FrameChanged { what, first_line } => write!(
                f,
                "second, different {what} frame (the first is at line {first_line}): the relation between the two operation frames is not established"
            ),
            FrameMatrix { what } => write!(f, "{what} needs 12 numbers"),
            FedratValues { found } => {
                write!(f, "FEDRAT needs exactly one value, has {found}")
            }
            FedratWord { found } => write!(
                f,
                "unknown or repeated FEDRAT word {found} (MMPM, IPM, MMPR, IPR, PERMIN, PERREV or INVERS expected)"
            ),
            FeedNotPositive => f.write_str("feed value must be positive"),
            PerRevWithoutSpindle { feed_line } => write!(
                f,
                "feed per revolution (set at line {feed_line}) with no spindle speed"
            ),
            BadSpindle => f.write_str("SPINDL speed must not be negative"),
            ToolNumber { record } => write!(
                f,
                "{record} without a tool number (a non-negative integer expected)"
            ),
            RapidBeforeCircle => f.write_str("RAPID before CIRCLE: an arc is a feed move"),
            CircleBeforePosition => f.write_str("CIRCLE before any position"),
            RecordAfterCircle { name } => write!(
                f,
                "{name} after CIRCLE: the arc end point (GOTO) is missing"
            ),
            CircleWithoutEnd => f.write_str("CIRCLE without end point"),
            ArcRadius { start, end } => write!(
                f,
                "arc start radius {start:.4} and end radius {end:.4} differ by more than 0.005 mm"
            ),
            ArcRadiusGiven { given, start, end } => write!(
                f,
                "arc radius {given:.4} does not match start/end ({start:.4}/{end:.4}) within 0.005 mm"
            ),
            ArcZeroRadius => f.write_str("arc start point is on the arc's axis (radius zero)"),
            ArcAmbiguous { chord } => write!(
                f,
                "arc end is {chord:.6} mm from its start: read in this dialect's direction it is almost a full turn (a full circle or a tiny arc?); refused"
            ),
            ArcPointOff { distance } => write!(
                f,
                "point after CIRCLE is {distance:.4} mm off the arc (0.005 mm allowed)"
            ),
            ArcPointOrder => f.write_str(
                "point after CIRCLE is not between the previous point and the end in the direction of travel",
            ),
            ArcTooManyPoints { needed, limit } if *needed == u64::MAX => write!(
                f,
                "arc needs more than 1e18 points at the chord tolerance (the limit is {limit}): raise the tolerance"
            ),
            ArcTooManyPoints { needed, limit } => write!(
                f,
                "arc needs {needed} points at the chord tolerance, more than the limit {limit}: raise the tolerance"
            ),
            ArcAxisFlip => f.write_str("tool axis turns by 180 degrees along the arc"),
            CycleEmpty => f.write_str("CYCLE without arguments"),
            CycleOnWithoutCycle => f.write_str("CYCLE/ON with no cycle defined"),
            CyclePositional => f.write_str(
                "CYCLE positional form is CYCLE/type,depth,IPM|MMPM|IPR|MMPR,feed,clearance",
            ),
            CycleNoDepth => f.write_str("CYCLE without depth (FEDTO/DEPTH)"),
            CycleType { found } => write!(
                f,
                "CYCLE/{found} is not supported (DRILL, DEEP, DEEP2, BRKCHP, TAP, BORE, REAM, CSINK, FACE, SPOT expected)"
            ),
            CycleKeyword { word } => write!(f, "CYCLE: {word} needs a value"),
            GodltaBeforePosition => f.write_str("GODLTA before any position"),
            BarePoint => f.write_str("line of numbers that does not continue a GOTO"),
            NoMotion => f.write_str("no motion record (GOTO, FROM, GODLTA) in the file"),
        }
    }
}

/// A warning: reading goes on. Warnings are values; the reader prints nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// 1-based line the warning is about.
    pub line: u64,
    /// What; `Display` gives the message.
    pub kind: WarningKind,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.kind)
    }
}

/// What a warning is about.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum WarningKind {
    /// No `UNITS` record; inch from the inch feed unit at this line (SPEC §4).
    UnitsInferredInch,
    /// No `UNITS` record and no feed unit: millimetres assumed (SPEC §4).
    UnitsAssumedMm,
    /// A comment continued with `$` (SPEC §3.7) takes this line, which looks like a record,
    /// as comment text.
    CommentTakesRecord {
        /// The record name the line starts with.
        name: String,
    },
    /// A `$$*CATIA0` block without three lines of four numbers: its frame is not recorded.
    CatiaBlockIncomplete,
    /// Lines after an NX listing's last line (`Tool Path Listing has N lines.`, SPEC §3.9):
    /// this one and the rest up to a new listing header are not read.
    AfterListingEnd {
        /// Line of the listing's last line.
        end_line: u64,
    },
}

impl fmt::Display for WarningKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WarningKind::UnitsInferredInch => {
                f.write_str("no UNITS record: inch assumed from the inch feed unit")
            }
            WarningKind::UnitsAssumedMm => {
                f.write_str("no UNITS record and no feed unit: millimetres assumed")
            }
            WarningKind::CommentTakesRecord { name } => write!(
                f,
                "this line continues a comment (the comment line before ends with `$`) although it looks like a {name} record: read as comment text"
            ),
            WarningKind::CatiaBlockIncomplete => f.write_str(
                "$$*CATIA0 block without three lines of four numbers: its frame is not recorded",
            ),
            WarningKind::AfterListingEnd { end_line } => write!(
                f,
                "after the end of the NX listing at line {end_line} (`Tool Path Listing has ... lines`): this line and the rest up to a new listing header are ignored"
            ),
        }
    }
}
