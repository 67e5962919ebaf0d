//! The CL reader: records to rows (SPEC §4–§8), streaming.

use std::collections::VecDeque;
use std::io::{BufRead, Seek, SeekFrom};

use super::arc::{Arc, ArcRows};
use super::error::{ClError, ClErrorKind, Warning, WarningKind};
use super::geom::{Frame, V3, Xform, add, cross, dot, finite, norm, scale, sub, unit};
use super::lex::{Item, Lexer, is_blank, trim};
use super::number::{self, Num};
use super::types::{
    ArcRule, Dialect, Kind, MAX_TOOL_CHANGES, MM_PER_INCH, Motion, Options, Row, Summary,
    ToolChange, Units, UnitsSource, latin1_short,
};

/// APT geometric motion statements (SPEC §5.14).
const GEOMETRIC: [&[u8]; 12] = [
    b"GOFWD", b"GOLFT", b"GORGT", b"GOBACK", b"GOUP", b"GODOWN", b"GO", b"TLON", b"TLLFT",
    b"TLRGT", b"TLOFPS", b"TLONPS",
];

/// Cycle types expanded as a straight in-and-out move along the tool axis (SPEC §8).
const CYCLE_TYPES: [&[u8]; 10] = [
    b"DRILL", b"DEEP", b"DEEP2", b"BRKCHP", b"TAP", b"BORE", b"REAM", b"CSINK", b"FACE", b"SPOT",
];

/// Feed mode and value, in mm (SPEC §5.6).
#[derive(Debug, Clone, Copy, PartialEq)]
enum FeedMode {
    /// mm/min.
    PerMin(f64),
    /// mm per spindle revolution.
    PerRev(f64),
    /// Inverse time: moves per minute.
    Inverse(f64),
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Feed {
    mode: FeedMode,
    /// Line of the record that set it.
    line: u64,
}

/// A `CIRCLE` waiting for its end point.
#[derive(Debug, Clone, Copy)]
struct PendingCircle {
    line: u64,
    /// Column of the record's start, and of its radius field when it has one.
    column: Option<u64>,
    radius_column: Option<u64>,
    c: V3,
    axis: V3,
    radius: Option<f64>,
    rule: ArcRule,
}

/// An active canned cycle (SPEC §8), lengths in mm.
#[derive(Debug, Clone, Copy)]
struct Cycle {
    depth: Option<f64>,
    rapto: f64,
    retract: Option<f64>,
    feed: Option<Feed>,
}

/// A `$$*CATIA0` block being collected (SPEC §6.4).
#[derive(Debug, Clone, Copy)]
struct Catia {
    line: u64,
    vals: [f64; 12],
    n: usize,
}

/// What a record is, from its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rec {
    Goto,
    From,
    Godlta,
    Circle,
    Cycle,
    Fedrat,
    Rapid,
    Spindl,
    Loadtl,
    Load,
    Units,
    Msys,
    Csys,
    Trntyp,
    ToolPath,
    EndOfPath,
    Tldata,
    Fini,
    Nurbs,
    Geometric,
    Transform,
    Paint,
    Tlaxis,
    Other,
}

fn classify(name: &[u8]) -> Rec {
    match name {
        b"GOTO" => Rec::Goto,
        b"FROM" => Rec::From,
        b"GODLTA" => Rec::Godlta,
        b"CIRCLE" => Rec::Circle,
        b"CYCLE" => Rec::Cycle,
        b"FEDRAT" => Rec::Fedrat,
        b"RAPID" => Rec::Rapid,
        b"SPINDL" => Rec::Spindl,
        b"LOADTL" => Rec::Loadtl,
        b"LOAD" => Rec::Load,
        b"UNITS" | b"UNIT" => Rec::Units,
        b"MSYS" => Rec::Msys,
        b"CSYS" => Rec::Csys,
        b"TRNTYP" => Rec::Trntyp,
        b"TOOL PATH" => Rec::ToolPath,
        b"END-OF-PATH" => Rec::EndOfPath,
        b"TLDATA" => Rec::Tldata,
        b"FINI" => Rec::Fini,
        b"NURBS" | b"KNOT" | b"CNTRL" => Rec::Nurbs,
        b"TRACUT" | b"COPY" => Rec::Transform,
        b"PAINT" => Rec::Paint,
        b"TLAXIS" => Rec::Tlaxis,
        _ if name.contains(&b',') || GEOMETRIC.contains(&name) => Rec::Geometric,
        _ => Rec::Other,
    }
}

/// The motion records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mot {
    Goto,
    From,
    Godlta,
    /// A bare line of numbers continuing a `GOTO` (Creo).
    Point,
}

/// Units decided before reading (SPEC §4).
struct Decision {
    units: Units,
    source: UnitsSource,
    warning: Option<Warning>,
    error: Option<ClError>,
}

/// The look-ahead pass of SPEC §4 over the records up to `FINI`: the first `UNITS` before the
/// first motion record, else the first `Information Units` header line, else the feed unit
/// words of `FEDRAT` and `CYCLE` records. Stops early at a `UNITS` record before motion.
/// A lexical error ends the pass (the reading pass reports it when it gets there).
fn decide_units<R: BufRead>(lex: &mut Lexer<R>) -> Decision {
    let mut first_motion = false;
    let mut first_line: Option<u64> = None;
    let mut record: Option<(u64, Option<Units>)> = None;
    let mut header: Option<(u64, Units)> = None;
    let mut inch: Option<u64> = None;
    let mut mm: Option<u64> = None;
    while let Ok(Some(item)) = lex.next_item() {
        let line = lex.rec_line;
        match item {
            Item::Header(u) => {
                if let (Some(u), None) = (u, header) {
                    header = Some((line, u));
                }
                continue;
            }
            Item::Comment | Item::Text | Item::ListingEnd => {}
            Item::Point => first_motion = true,
            Item::Record => match classify(&lex.name) {
                Rec::Fini => break,
                Rec::Goto | Rec::From | Rec::Godlta => first_motion = true,
                Rec::Units if !first_motion => {
                    record = Some((line, units_word(lex)));
                    break;
                }
                Rec::Fedrat | Rec::Cycle => {
                    for i in 0..lex.nfields() {
                        let f = lex.field(i);
                        if f.eq_ignore_ascii_case(b"IPM") || f.eq_ignore_ascii_case(b"IPR") {
                            inch.get_or_insert(line);
                        } else if f.eq_ignore_ascii_case(b"MMPM") || f.eq_ignore_ascii_case(b"MMPR")
                        {
                            mm.get_or_insert(line);
                        }
                    }
                }
                _ => {}
            },
        }
        first_line.get_or_insert(line);
    }
    let d = |units, source| Decision {
        units,
        source,
        warning: None,
        error: None,
    };
    if let Some((line, u)) = record {
        // An unknown value is reported by the reading pass at that record, before any row.
        return d(u.unwrap_or(Units::Mm), UnitsSource::Record { line });
    }
    if let Some((line, u)) = header {
        return d(u, UnitsSource::ListingHeader { line });
    }
    match (inch, mm) {
        (Some(i), Some(m)) => Decision {
            units: Units::Mm,
            source: UnitsSource::Default,
            warning: None,
            error: Some(ClError::at(
                i.max(m),
                ClErrorKind::UnitsUndecidable {
                    inch_line: i,
                    mm_line: m,
                },
            )),
        },
        (Some(i), None) => Decision {
            units: Units::Inch,
            source: UnitsSource::FeedWords { line: i },
            warning: Some(Warning {
                line: i,
                kind: WarningKind::UnitsInferredInch,
            }),
            error: None,
        },
        (None, Some(m)) => d(Units::Mm, UnitsSource::FeedWords { line: m }),
        (None, None) => Decision {
            units: Units::Mm,
            source: UnitsSource::Default,
            warning: Some(Warning {
                line: first_line.unwrap_or(1),
                kind: WarningKind::UnitsAssumedMm,
            }),
            error: None,
        },
    }
}

/// The value of a `UNITS` record: `None` when unknown.
fn units_word<R>(lex: &Lexer<R>) -> Option<Units> {
    if lex.nfields() == 0 {
        return None;
    }
    let w = lex.field(0);
    if w.eq_ignore_ascii_case(b"MM") {
        Some(Units::Mm)
    } else if w.eq_ignore_ascii_case(b"INCHES") || w.eq_ignore_ascii_case(b"INCH") {
        Some(Units::Inch)
    } else {
        None
    }
}

/// Streaming CL reader: an iterator of rows.
///
/// Memory is constant in the file size (one line buffer, one record buffer, a queue of at most
/// three cycle rows, the state of one arc), except for the summary's bounded lists and the
/// points written after one `CIRCLE` (bounded by [`Options::max_arc_points`]).
/// After an error the iterator ends.
pub struct Reader<R> {
    lex: Lexer<R>,
    opts: Options,
    stated: Option<Units>,
    units: Units,
    /// mm per file unit.
    unit: f64,
    first_error: Option<ClError>,
    // motion state (SPEC §5.1)
    pos: Option<V3>,
    axis: V3,
    rapid: bool,
    feed: Option<Feed>,
    rpm: Option<f64>,
    tool: Option<u32>,
    motion_seen: bool,
    /// A bare line of numbers may come now (directly after a GOTO or such a line).
    point_ok: bool,
    nx_seen: bool,
    // frames (SPEC §6)
    frame: Frame,
    out_frame: Option<Frame>,
    xf: Xform,
    world: bool,
    frame_comment: Option<([f64; 12], u64)>,
    catia: Option<Catia>,
    // arcs and cycles
    circle: Option<PendingCircle>,
    arc_points: Vec<(u64, V3, V3)>,
    cycle: Option<Cycle>,
    // tools
    tool_line: u64,
    tool_name: Option<String>,
    tool_length: Option<f64>,
    tool_gen: u64,
    tool_gen_seen: u64,
    // output
    queue: VecDeque<Row>,
    arc_rows: Option<(ArcRows, Row)>,
    held: Option<Item>,
    next_index: u64,
    input_done: bool,
    done: bool,
    summary: Summary,
}

fn check_options(o: &Options) -> Result<(), ClError> {
    let bad = |what| Err(ClError::at(0, ClErrorKind::InvalidOptions(what)));
    if !(o.chord_tol_mm.is_finite() && o.chord_tol_mm > 0.0) {
        return bad("the chord tolerance must be a positive number of mm");
    }
    if o.max_record_bytes < 64 {
        return bad("the record size limit must be at least 64 bytes");
    }
    if o.max_arc_points == 0 {
        return bad("the arc point limit must be at least 1");
    }
    Ok(())
}

impl<R: BufRead + Seek> Reader<R> {
    /// A reader over a seekable input (a file, a `Cursor`), from its current position.
    ///
    /// When `options.units` is `None`, the units are decided as SPEC §4 says: this needs a
    /// look-ahead, done here as a first pass over the records (up to the first `UNITS`
    /// record before motion, else to `FINI` or the end), after which the input is sought
    /// back. A file with a `UNITS` record near its top costs almost nothing; an NX CLSF
    /// (no `UNITS`) is lexed twice. With stated units there is no first pass.
    pub fn new(mut input: R, options: Options) -> Result<Reader<R>, ClError> {
        check_options(&options)?;
        if let Some(u) = options.units {
            return Ok(Reader::build(input, options, stated(u)));
        }
        let io = |e: std::io::Error| ClError::at(0, ClErrorKind::Io(e.to_string()));
        let start = input.stream_position().map_err(io)?;
        let decision = {
            let mut lex = Lexer::new(&mut input, options.max_record_bytes);
            decide_units(&mut lex)
        };
        input.seek(SeekFrom::Start(start)).map_err(io)?;
        Ok(Reader::build(input, options, decision))
    }
}

fn stated(u: Units) -> Decision {
    Decision {
        units: u,
        source: UnitsSource::Stated,
        warning: None,
        error: None,
    }
}

impl<R: BufRead> Reader<R> {
    /// A reader over any input (standard input, a pipe) with the units stated by the caller:
    /// one pass, no look-ahead. `units` overrides `options.units`. A `UNITS` record or an
    /// `Information Units` line that says otherwise is an error at its line.
    pub fn with_units(input: R, units: Units, options: Options) -> Result<Reader<R>, ClError> {
        check_options(&options)?;
        let options = Options {
            units: Some(units),
            ..options
        };
        Ok(Reader::build(input, options, stated(units)))
    }

    fn build(input: R, opts: Options, d: Decision) -> Reader<R> {
        let mut summary = Summary::new(d.units, d.source);
        if let Some(w) = d.warning {
            summary.warn(w);
        }
        Reader {
            lex: Lexer::new(input, opts.max_record_bytes),
            opts,
            stated: opts.units,
            units: d.units,
            unit: d.units.mm_per_unit(),
            first_error: d.error,
            pos: None,
            axis: [0.0, 0.0, 1.0],
            rapid: false,
            feed: None,
            rpm: None,
            tool: None,
            motion_seen: false,
            point_ok: false,
            nx_seen: false,
            frame: Frame::IDENTITY,
            out_frame: None,
            xf: Xform::IDENTITY,
            world: false,
            frame_comment: None,
            catia: None,
            circle: None,
            arc_points: Vec::new(),
            cycle: None,
            tool_line: 0,
            tool_name: None,
            tool_length: None,
            tool_gen: 0,
            tool_gen_seen: 0,
            queue: VecDeque::with_capacity(4),
            arc_rows: None,
            held: None,
            next_index: 0,
            input_done: false,
            done: false,
            summary,
        }
    }

    /// What was seen so far; complete once the iterator has returned `None`.
    pub fn summary(&self) -> &Summary {
        &self.summary
    }

    /// The summary, taking the reader.
    pub fn into_summary(self) -> Summary {
        self.summary
    }

    /// The units the file is read in (known from the start; a second `UNITS` record before
    /// the first motion may still change it).
    pub fn units(&self) -> Units {
        self.units
    }

    /// Gives the input back.
    pub fn into_inner(self) -> R {
        self.lex.into_inner()
    }

    fn fail(&mut self, e: ClError) -> Option<Result<Row, ClError>> {
        self.done = true;
        self.summary.lines = self.lex.line_no;
        Some(Err(e))
    }

    /// The next row, or `None` at the end (or after an error).
    fn next_row(&mut self) -> Option<Result<Row, ClError>> {
        loop {
            if self.done {
                return None;
            }
            if let Some(e) = self.first_error.take() {
                return self.fail(e);
            }
            if let Some(r) = self.queue.pop_front() {
                self.summary.rows += 1;
                self.summary.lines = self.lex.line_no;
                return Some(Ok(r));
            }
            if let Some((rows, tpl)) = &mut self.arc_rows {
                if let Some((tip, axis)) = rows.next_point() {
                    self.summary.rows += 1;
                    return Some(Ok(Row { tip, axis, ..*tpl }));
                }
                self.arc_rows = None;
            }
            if self.input_done {
                self.done = true;
                self.summary.lines = self.lex.line_no;
                return None;
            }
            let r = match self.held.take() {
                Some(item) => self.step(item),
                None => match self.lex.next_item() {
                    Ok(Some(item)) => {
                        for w in self.lex.warnings.drain(..) {
                            self.summary.warn(w);
                        }
                        if self.arc_waiting() && !matches!(item, Item::Point | Item::Header(_)) {
                            // the arc ends at the last point: its rows come first
                            self.held = Some(item);
                            self.finish_arc()
                        } else {
                            self.step(item)
                        }
                    }
                    Ok(None) => self.end_of_input(),
                    Err(e) => Err(e),
                },
            };
            if let Err(e) = r {
                return self.fail(e);
            }
        }
    }

    fn arc_waiting(&self) -> bool {
        self.circle.is_some() && !self.arc_points.is_empty()
    }

    fn end_of_input(&mut self) -> Result<(), ClError> {
        self.input_done = true;
        self.summary.lines = self.lex.line_no;
        if self.arc_waiting() {
            self.finish_arc()?;
        }
        if let Some(c) = self.circle {
            return Err(ClError::at(c.line, ClErrorKind::CircleWithoutEnd));
        }
        self.end_catia();
        if !self.motion_seen {
            let line = self.summary.fini_line.unwrap_or(self.lex.line_no.max(1));
            return Err(ClError::at(line, ClErrorKind::NoMotion));
        }
        Ok(())
    }

    fn dialect(&mut self, d: Dialect) {
        let cur = self.summary.dialect;
        if cur == Dialect::Apt || (cur == Dialect::NxClsf && d == Dialect::NxListing) {
            self.summary.dialect = d;
        }
    }

    fn step(&mut self, item: Item) -> Result<(), ClError> {
        if self.catia.is_some() && !matches!(item, Item::Comment | Item::Header(_)) {
            self.end_catia();
        }
        match item {
            Item::Header(units) => {
                self.dialect(Dialect::NxListing);
                if let Some(u) = units {
                    let stated = self.stated.unwrap_or(self.units);
                    if u != stated {
                        return Err(ClError::at(
                            self.lex.rec_line,
                            ClErrorKind::UnitsConflict { stated, found: u },
                        ));
                    }
                }
                Ok(())
            }
            Item::ListingEnd => {
                self.point_ok = false;
                self.dialect(Dialect::NxListing);
                self.summary.count_skipped(b"TOOL PATH LISTING");
                Ok(())
            }
            Item::Comment => {
                self.point_ok = false;
                self.comment()
            }
            Item::Text => {
                self.point_ok = false;
                self.summary.count_skipped(&self.lex.name);
                Ok(())
            }
            Item::Point => {
                if !self.point_ok {
                    return Err(self.lex.err(ClErrorKind::BarePoint));
                }
                self.motion(Mot::Point)
            }
            Item::Record => {
                self.point_ok = false;
                self.record()
            }
        }
    }

    fn record(&mut self) -> Result<(), ClError> {
        let rec = classify(&self.lex.name);
        if self.circle.is_some() && !matches!(rec, Rec::Goto | Rec::Paint | Rec::Fedrat | Rec::Fini)
        {
            let name = self.lex.name_str();
            return Err(self.lex.err(ClErrorKind::RecordAfterCircle { name }));
        }
        match rec {
            Rec::Goto => self.motion(Mot::Goto),
            Rec::From => self.motion(Mot::From),
            Rec::Godlta => self.motion(Mot::Godlta),
            Rec::Circle => self.circle(),
            Rec::Cycle => self.cycle(),
            Rec::Fedrat => self.fedrat(),
            Rec::Rapid => {
                self.rapid = true;
                Ok(())
            }
            Rec::Spindl => self.spindl(),
            Rec::Loadtl => {
                self.tool = Some(self.tool_number(0)?);
                self.tool_changed();
                Ok(())
            }
            Rec::Load => {
                if self.lex.is_word(0, b"TOOL") {
                    self.tool = Some(self.tool_number(1)?);
                    self.tool_changed();
                } else {
                    self.summary.count_skipped(&self.lex.name);
                }
                Ok(())
            }
            Rec::Units => self.units_record(),
            Rec::Msys => self.msys(),
            Rec::Csys => self.csys(),
            Rec::Trntyp => {
                self.dialect(Dialect::SolidWorks);
                self.world = self.lex.is_word(0, b"WORLD");
                self.summary.count_skipped(&self.lex.name);
                Ok(())
            }
            Rec::ToolPath => {
                self.nx_seen = true;
                self.dialect(Dialect::NxClsf);
                self.tool_name = (self.lex.is_word(1, b"TOOL") && self.lex.nfields() > 2)
                    .then(|| latin1_short(self.lex.field(2), 64));
                self.tool_length = None;
                self.tool_changed();
                Ok(())
            }
            Rec::EndOfPath => {
                self.nx_seen = true;
                self.dialect(Dialect::NxClsf);
                self.rapid = false;
                self.cycle = None;
                self.feed = None;
                Ok(())
            }
            Rec::Tldata => {
                self.nx_seen = true;
                self.dialect(Dialect::NxClsf);
                self.tldata();
                self.summary.count_skipped(&self.lex.name);
                Ok(())
            }
            Rec::Fini => {
                self.summary.fini_line = Some(self.lex.rec_line);
                self.end_of_input()
            }
            Rec::Nurbs => {
                let name = self.lex.name_str();
                Err(self.lex.err(ClErrorKind::Nurbs { name }))
            }
            Rec::Geometric => {
                let name = self.lex.name_str();
                Err(self.lex.err(ClErrorKind::GeometricStatement { name }))
            }
            Rec::Transform => {
                if self.lex.name == b"TRACUT" && self.lex.is_word(0, b"NOMORE") {
                    self.summary.count_skipped(&self.lex.name);
                    return Ok(());
                }
                let name = self.lex.name_str();
                Err(self.lex.err(ClErrorKind::Transformation { name }))
            }
            Rec::Tlaxis => self.tlaxis(),
            Rec::Paint | Rec::Other => {
                if self.lex.name == b"UNIT" || self.lex.name.starts_with(b"CSI_SET_") {
                    self.dialect(Dialect::SolidWorks);
                }
                self.summary.count_skipped(&self.lex.name);
                Ok(())
            }
        }
    }

    // ------------------------------------------------------------------ units (SPEC §4)

    fn units_record(&mut self) -> Result<(), ClError> {
        if self.lex.name == b"UNIT" {
            self.dialect(Dialect::SolidWorks);
        }
        let Some(u) = units_word(&self.lex) else {
            let found = if self.lex.nfields() == 0 {
                String::new()
            } else {
                latin1_short(self.lex.field(0), 40)
            };
            return Err(self.lex.err_field(0, ClErrorKind::UnknownUnits { found }));
        };
        if let Some(s) = self.stated {
            if u != s {
                return Err(self.lex.err_field(
                    0,
                    ClErrorKind::UnitsConflict {
                        stated: s,
                        found: u,
                    },
                ));
            }
            return Ok(());
        }
        if self.motion_seen {
            if u != self.units {
                return Err(self.lex.err_field(
                    0,
                    ClErrorKind::UnitsChanged {
                        from: self.units,
                        to: u,
                    },
                ));
            }
            return Ok(());
        }
        self.units = u;
        self.unit = u.mm_per_unit();
        self.summary.units = u;
        self.summary.units_source = UnitsSource::Record {
            line: self.lex.rec_line,
        };
        Ok(())
    }

    // ------------------------------------------------------------------ tools (SPEC §5.8, §5.9)

    fn tool_number(&self, i: usize) -> Result<u32, ClError> {
        let err = || {
            self.lex.err_field(
                i,
                ClErrorKind::ToolNumber {
                    record: self.lex.name_str(),
                },
            )
        };
        if i >= self.lex.nfields() {
            return Err(err());
        }
        match self.lex.num(i) {
            Num::Value(v) if v >= 0.0 && v.fract() == 0.0 && v <= u32::MAX as f64 => Ok(v as u32),
            _ => Err(err()),
        }
    }

    fn tool_changed(&mut self) {
        self.tool_line = self.lex.rec_line;
        self.tool_gen += 1;
    }

    /// `TLDATA/MILL,D,R,L,…` or `TLDATA/DRILL,MILL,D,R,L,…`: `L` as information.
    fn tldata(&mut self) {
        let idx = if self.lex.is_word(0, b"MILL") {
            Some(3)
        } else if self.lex.is_word(0, b"DRILL") && self.lex.is_word(1, b"MILL") {
            Some(4)
        } else {
            None
        };
        let len = idx
            .filter(|&i| i < self.lex.nfields())
            .and_then(|i| match self.lex.num(i) {
                Num::Value(v) if v > 0.0 && (v * self.unit).is_finite() => Some(v * self.unit),
                _ => None,
            });
        self.tool_length = len;
        self.tool_changed();
    }

    /// Records a tool change before the row with this line and index, if the tool changed.
    fn note_tool(&mut self, line: u64, index: u64) {
        if self.tool_gen == self.tool_gen_seen {
            return;
        }
        self.tool_gen_seen = self.tool_gen;
        let same = match self.summary.tools.last() {
            Some(t) => {
                t.tool == self.tool && t.name == self.tool_name && t.length_mm == self.tool_length
            }
            None => self.tool.is_none() && self.tool_name.is_none() && self.tool_length.is_none(),
        };
        if same {
            return;
        }
        if self.summary.tools.len() >= MAX_TOOL_CHANGES {
            self.summary.tools_dropped += 1;
            return;
        }
        self.summary.tools.push(ToolChange {
            line: self.tool_line,
            first_row_line: line,
            first_row_index: index,
            tool: self.tool,
            name: self.tool_name.clone(),
            length_mm: self.tool_length,
        });
    }

    // ------------------------------------------------------------------ feeds (SPEC §5.6, §5.7)

    fn fedrat(&mut self) -> Result<(), ClError> {
        let mut value = None;
        let mut values = 0;
        let mut word: Option<usize> = None;
        for i in 0..self.lex.nfields() {
            if self.lex.field(i).is_empty() {
                continue;
            }
            match self.lex.num(i) {
                Num::Value(v) => {
                    values += 1;
                    value = Some((i, v));
                }
                Num::OutOfRange => return Err(self.lex.number(i).unwrap_err()),
                Num::NotNumber => {
                    const WORDS: [&[u8]; 7] = [
                        b"MMPM", b"IPM", b"MMPR", b"IPR", b"PERMIN", b"PERREV", b"INVERS",
                    ];
                    let f = self.lex.field(i);
                    let known = WORDS.iter().position(|w| w.eq_ignore_ascii_case(f));
                    match (known, word) {
                        (Some(k), None) => word = Some(k),
                        _ => {
                            let found = latin1_short(f, 40);
                            return Err(self.lex.err_field(i, ClErrorKind::FedratWord { found }));
                        }
                    }
                }
            }
        }
        let Some((vi, v)) = value.filter(|_| values == 1) else {
            return Err(self.lex.err(ClErrorKind::FedratValues { found: values }));
        };
        if v <= 0.0 {
            return Err(self.lex.err_field(vi, ClErrorKind::FeedNotPositive));
        }
        let u = self.unit;
        let mode = match word {
            None | Some(4) => FeedMode::PerMin(v * u),
            Some(0) => FeedMode::PerMin(v),
            Some(1) => FeedMode::PerMin(v * MM_PER_INCH),
            Some(2) => FeedMode::PerRev(v),
            Some(3) => FeedMode::PerRev(v * MM_PER_INCH),
            Some(5) => FeedMode::PerRev(v * u),
            _ => FeedMode::Inverse(v),
        };
        let scaled = match mode {
            FeedMode::PerMin(x) | FeedMode::PerRev(x) | FeedMode::Inverse(x) => x,
        };
        if !scaled.is_finite() {
            return Err(self.lex.err_field(
                vi,
                ClErrorKind::NumberOutOfRange {
                    record: "FEDRAT".into(),
                },
            ));
        }
        self.feed = Some(Feed {
            mode,
            line: self.lex.rec_line,
        });
        Ok(())
    }

    fn spindl(&mut self) -> Result<(), ClError> {
        self.summary.count_skipped(&self.lex.name);
        let n = self.lex.nfields();
        if (0..n).any(|i| self.lex.is_word(i, b"OFF")) {
            self.rpm = Some(0.0);
            return Ok(());
        }
        if (0..n).any(|i| self.lex.is_word(i, b"SFM") || self.lex.is_word(i, b"SMM")) {
            // surface speed: the rpm depends on the diameter, not known here
            self.rpm = None;
            return Ok(());
        }
        for i in 0..n {
            match self.lex.num(i) {
                Num::Value(v) => {
                    if v < 0.0 {
                        return Err(self.lex.err_field(i, ClErrorKind::BadSpindle));
                    }
                    self.rpm = Some(v);
                    return Ok(());
                }
                Num::OutOfRange => return Err(self.lex.number(i).unwrap_err()),
                Num::NotNumber => {}
            }
        }
        Ok(())
    }

    /// The feed in mm/min of a feed move of `length` mm, at `line`.
    fn feed_value(
        &self,
        feed: Option<Feed>,
        line: u64,
        length: impl Fn() -> f64,
    ) -> Result<Option<f64>, ClError> {
        let Some(f) = feed else {
            return Ok(None);
        };
        let v = match f.mode {
            FeedMode::PerMin(v) => v,
            FeedMode::PerRev(v) => match self.rpm {
                Some(rpm) if rpm > 0.0 => v * rpm,
                _ => {
                    return Err(ClError::at(
                        line,
                        ClErrorKind::PerRevWithoutSpindle { feed_line: f.line },
                    ));
                }
            },
            FeedMode::Inverse(v) => v * length(),
        };
        if !v.is_finite() {
            return Err(ClError::at(
                line,
                ClErrorKind::NumberOutOfRange {
                    record: "FEDRAT".into(),
                },
            ));
        }
        Ok(Some(v))
    }

    // ------------------------------------------------------------------ frames (SPEC §6)

    fn msys(&mut self) -> Result<(), ClError> {
        self.nx_seen = true;
        self.dialect(Dialect::NxClsf);
        let n = self.lex.nfields();
        if n == 12 {
            return Err(self.lex.err(ClErrorKind::Msys12));
        }
        if n != 9 {
            return Err(self.lex.err(ClErrorKind::FieldCount {
                record: "MSYS".into(),
                expected: "9 (origin, X axis, Y axis)",
                found: n,
            }));
        }
        let mut v = [0.0; 9];
        self.lex.numbers(&mut v)?;
        let o = scale([v[0], v[1], v[2]], self.unit);
        let x = [v[3], v[4], v[5]];
        let y = [v[6], v[7], v[8]];
        let tol = 1e-4;
        if !finite(o)
            || (norm(x) - 1.0).abs() > tol
            || (norm(y) - 1.0).abs() > tol
            || dot(x, y).abs() > tol
        {
            return Err(self.lex.err(ClErrorKind::MsysNotOrthonormal));
        }
        let x = unit(x, 0.5).unwrap_or(x);
        let y = unit(sub(y, scale(x, dot(x, y))), 0.5).unwrap_or(y);
        let z = cross(x, y);
        self.frame = Frame {
            o,
            r: [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]],
        };
        if self.out_frame.is_none() && !self.motion_seen {
            self.out_frame = Some(self.frame);
        }
        if let Some(of) = &self.out_frame {
            self.xf = Xform::between(&self.frame, of);
        }
        Ok(())
    }

    fn csys(&mut self) -> Result<(), ClError> {
        let n = self.lex.nfields();
        if n != 12 {
            return Err(self.lex.err(ClErrorKind::FieldCount {
                record: "CSYS".into(),
                expected: "12",
                found: n,
            }));
        }
        let mut v = [0.0; 12];
        self.lex.numbers(&mut v)?;
        if self.world {
            // SolidWorks CAM: with TRNTYP/WORLD the points are world coordinates (SPEC §6.2)
            return Ok(());
        }
        const ID: [f64; 12] = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.];
        if v.iter().zip(ID).any(|(a, b)| (a - b).abs() > 1e-9) {
            return Err(self.lex.err(ClErrorKind::CsysLocal));
        }
        Ok(())
    }

    fn comment(&mut self) -> Result<(), ClError> {
        let line = self.lex.rec_line;
        if self.summary.dialect == Dialect::Apt {
            let t = &self.lex.content;
            if t.starts_with(b"$$->") || contains_ci(t, b"PRO/CLFILE") {
                self.dialect(Dialect::Creo);
            } else if contains_ci(t, b"CATIA") {
                self.dialect(Dialect::Catia);
            }
        }
        let t = &self.lex.content;
        if let Some(rest) = t.strip_prefix(b"$$->") {
            let rest = trim(rest);
            if rest.len() >= 4 && rest[..4].eq_ignore_ascii_case(b"CSYS") {
                let after = trim(&rest[4..]);
                if let Some(args) = after.strip_prefix(b"/") {
                    let mut vals = [0.0; 12];
                    let mut n = 0;
                    for f in args.split(|&c| c == b',') {
                        match number::parse(trim(f)) {
                            Num::Value(v) if n < 12 => vals[n] = v,
                            _ => n = 99,
                        }
                        n += 1;
                    }
                    if n != 12 {
                        return Err(ClError::at(
                            line,
                            ClErrorKind::FrameMatrix { what: "$$-> CSYS" },
                        ));
                    }
                    return self.frame_comment(line, vals, "$$-> CSYS");
                }
            }
            return Ok(());
        }
        let catia0 = t.len() >= 9
            && t[..9].eq_ignore_ascii_case(b"$$*CATIA0")
            && t.get(9)
                .is_none_or(|&c| !(c.is_ascii_alphanumeric() || c == b'_'));
        if catia0 {
            self.end_catia();
            self.catia = Some(Catia {
                line,
                vals: [0.0; 12],
                n: 0,
            });
            return Ok(());
        }
        if let Some(mut c) = self.catia {
            // a matrix line is `$$` and four numbers
            let body = &t[2..];
            let mut row = [0.0; 4];
            let mut k = 0;
            for tok in body.split(|&b| is_blank(b)).filter(|s| !s.is_empty()) {
                match number::parse(tok) {
                    Num::Value(v) if k < 4 => row[k] = v,
                    _ => k = 99,
                }
                k += 1;
            }
            if k == 4 {
                c.vals[c.n..c.n + 4].copy_from_slice(&row);
                c.n += 4;
                if c.n == 12 {
                    self.catia = None;
                    return self.frame_comment(c.line, c.vals, "$$*CATIA0");
                }
                self.catia = Some(c);
            } else if c.n > 0 {
                self.end_catia();
            }
        }
        Ok(())
    }

    fn end_catia(&mut self) {
        let Some(c) = self.catia.take() else {
            return;
        };
        if c.n < 12 {
            self.summary.warn(Warning {
                line: c.line,
                kind: WarningKind::CatiaBlockIncomplete,
            });
        }
    }

    /// A Creo `$$-> CSYS` or CATIA `$$*CATIA0` frame: the first is recorded, not applied; a
    /// different one later is refused (SPEC §6.3, §6.4).
    fn frame_comment(
        &mut self,
        line: u64,
        vals: [f64; 12],
        what: &'static str,
    ) -> Result<(), ClError> {
        match &self.frame_comment {
            None => {
                self.frame_comment = Some((vals, line));
                Ok(())
            }
            Some((first, first_line)) => {
                if vals.iter().zip(first).any(|(a, b)| (a - b).abs() > 1e-6) {
                    return Err(ClError::at(
                        line,
                        ClErrorKind::FrameChanged {
                            what,
                            first_line: *first_line,
                        },
                    ));
                }
                Ok(())
            }
        }
    }

    // ------------------------------------------------------------------ motion (SPEC §5.2–5.5)

    fn motion(&mut self, m: Mot) -> Result<(), ClError> {
        let line = self.lex.rec_line;
        let (p, a) = if m == Mot::Godlta {
            let Some(pos) = self.pos else {
                return Err(self.lex.err(ClErrorKind::GodltaBeforePosition));
            };
            let d = match self.lex.nfields() {
                1 => scale(self.axis, self.lex.number(0)? * self.unit),
                3 => {
                    let mut v = [0.0; 3];
                    self.lex.numbers(&mut v)?;
                    self.xf.vector(scale(v, self.unit))
                }
                n => {
                    return Err(self.lex.err(ClErrorKind::FieldCount {
                        record: "GODLTA".into(),
                        expected: "1 or 3",
                        found: n,
                    }));
                }
            };
            (add(pos, d), self.axis)
        } else {
            let n = self.lex.nfields();
            if n != 3 && n != 6 {
                return Err(self.lex.err(ClErrorKind::FieldCount {
                    record: self.lex.name_str(),
                    expected: "3 or 6",
                    found: n,
                }));
            }
            let mut v = [0.0; 6];
            match self.lex.all_numbers() {
                Some(x) => v[..n].copy_from_slice(x),
                None => self.lex.numbers(&mut v[..n])?,
            }
            if self.out_frame.is_none() {
                self.out_frame = Some(self.frame);
                self.xf = Xform::IDENTITY;
            }
            let p = self.xf.point(scale([v[0], v[1], v[2]], self.unit));
            let a = if n == 6 {
                let raw = [v[3], v[4], v[5]];
                let zero = || {
                    self.lex.err_field(
                        3,
                        ClErrorKind::ZeroAxis {
                            record: self.lex.name_str(),
                        },
                    )
                };
                if norm(raw).is_nan() || norm(raw) < 1e-9 {
                    return Err(zero());
                }
                unit(self.xf.vector(raw), 1e-300).ok_or_else(zero)?
            } else {
                self.axis
            };
            (p, a)
        };
        if !finite(p) {
            return Err(self.lex.err(ClErrorKind::NumberOutOfRange {
                record: self.lex.name_str(),
            }));
        }
        self.motion_seen = true;
        if m == Mot::From {
            // a start position, not a cut; does not consume a pending RAPID (SPEC §5.3)
            self.emit(line, Kind::From, Motion::Rapid, None, p, a);
            self.pos = Some(p);
            self.axis = a;
            return Ok(());
        }
        if self.circle.is_some() {
            if self.arc_points.len() as u64 >= self.opts.max_arc_points {
                return Err(ClError::at(
                    line,
                    ClErrorKind::ArcTooManyPoints {
                        needed: self.arc_points.len() as u64 + 1,
                        limit: self.opts.max_arc_points,
                    },
                ));
            }
            self.arc_points.push((line, p, a));
            self.point_ok = true;
            return Ok(());
        }
        if let (Some(c), true) = (self.cycle, m != Mot::Godlta) {
            self.cycle_point(line, c, p, a)?;
            self.point_ok = true;
            return Ok(());
        }
        if self.rapid {
            self.rapid = false;
            self.emit(line, Kind::Goto, Motion::Rapid, None, p, a);
        } else {
            let pos = self.pos;
            let f = self.feed_value(self.feed, line, || pos.map_or(0.0, |q| norm(sub(p, q))))?;
            self.emit(line, Kind::Goto, Motion::Feed, f, p, a);
        }
        self.pos = Some(p);
        self.axis = a;
        self.point_ok = m != Mot::Godlta;
        Ok(())
    }

    /// `TLAXIS/i,j,k`: the tool axis of the following motion records that give none (3-value
    /// `GOTO`, `FROM`, cycle points, `GODLTA/d`), in the file's frame like a `GOTO`'s axis
    /// (SPEC §5.2a). Any other form is refused at its field.
    fn tlaxis(&mut self) -> Result<(), ClError> {
        let n = self.lex.nfields();
        // A word (or an empty field) names the form; else the count is wrong at the 4th field
        // or at the end.
        let odd = match (0..n).find(|&i| matches!(self.lex.num(i), Num::NotNumber)) {
            // an empty field: the lexer's message for it
            Some(i) if self.lex.field(i).is_empty() => return self.lex.number(i).map(|_| ()),
            Some(i) => Some((i, latin1_short(self.lex.field(i), 40))),
            None => (n != 3).then(|| (n.min(3), String::new())),
        };
        if let Some((i, found)) = odd {
            return Err(self
                .lex
                .err_field(i, ClErrorKind::TlaxisForm { found, fields: n }));
        }
        let mut raw = [0.0; 3];
        self.lex.numbers(&mut raw)?;
        let zero = || {
            self.lex.err_field(
                0,
                ClErrorKind::ZeroAxis {
                    record: "TLAXIS".into(),
                },
            )
        };
        if norm(raw).is_nan() || norm(raw) < 1e-9 {
            return Err(zero());
        }
        // Like a motion record, the axis fixes the output frame if nothing has (SPEC §6).
        if self.out_frame.is_none() {
            self.out_frame = Some(self.frame);
            self.xf = Xform::IDENTITY;
        }
        self.axis = unit(self.xf.vector(raw), 1e-300).ok_or_else(zero)?;
        Ok(())
    }

    fn emit(
        &mut self,
        line: u64,
        kind: Kind,
        motion: Motion,
        feed: Option<f64>,
        tip: V3,
        axis: V3,
    ) {
        self.note_tool(line, self.next_index);
        self.next_index += 1;
        self.queue.push_back(Row {
            line,
            kind,
            motion,
            feed_mm_min: feed,
            tool: self.tool,
            tip,
            axis,
        });
    }

    // ------------------------------------------------------------------ arcs (SPEC §7)

    fn circle(&mut self) -> Result<(), ClError> {
        if self.rapid {
            return Err(self.lex.err(ClErrorKind::RapidBeforeCircle));
        }
        let n = self.lex.nfields();
        if n < 6 {
            return Err(self.lex.err(ClErrorKind::FieldCount {
                record: "CIRCLE".into(),
                expected: "at least 6 (centre, axis[, radius, …])",
                found: n,
            }));
        }
        let mut v = [0.0; 6];
        self.lex.numbers(&mut v)?;
        let radius = if n > 6 {
            match self.lex.num(6) {
                Num::Value(r) => Some(r * self.unit),
                Num::OutOfRange => return Err(self.lex.number(6).unwrap_err()),
                Num::NotNumber => None,
            }
        } else {
            None
        };
        let raw_axis = [v[3], v[4], v[5]];
        if norm(raw_axis).is_nan() || norm(raw_axis) < 1e-12 {
            return Err(self.lex.err_field(
                3,
                ClErrorKind::ZeroAxis {
                    record: "CIRCLE".into(),
                },
            ));
        }
        if self.pos.is_none() {
            return Err(self.lex.err(ClErrorKind::CircleBeforePosition));
        }
        let rule = *self.summary.arc_rule.get_or_insert(if self.nx_seen {
            ArcRule::ClockwiseAboutAxis
        } else {
            ArcRule::RightHand
        });
        let c = self.xf.point(scale([v[0], v[1], v[2]], self.unit));
        let axis = unit(self.xf.vector(raw_axis), 1e-300).unwrap_or([0.0, 0.0, 1.0]);
        if !finite(c) || radius.is_some_and(|r| !r.is_finite()) {
            return Err(self.lex.err(ClErrorKind::NumberOutOfRange {
                record: "CIRCLE".into(),
            }));
        }
        self.circle = Some(PendingCircle {
            line: self.lex.rec_line,
            column: Some(self.lex.record_column()),
            radius_column: radius.and(self.lex.field_column(6)),
            c,
            axis,
            radius,
            rule,
        });
        self.arc_points.clear();
        Ok(())
    }

    /// The arc is complete (its last point was read): checks it and starts its rows.
    fn finish_arc(&mut self) -> Result<(), ClError> {
        let Some(c) = self.circle.take() else {
            return Ok(());
        };
        let at = |k: ClErrorKind| {
            let column = match k {
                ClErrorKind::ArcRadiusGiven { .. } => c.radius_column.or(c.column),
                _ => c.column,
            };
            ClError::new(c.line, column, k)
        };
        let start = self
            .pos
            .ok_or_else(|| at(ClErrorKind::CircleBeforePosition))?;
        let &(_, end, a_end) = self
            .arc_points
            .last()
            .ok_or_else(|| at(ClErrorKind::CircleWithoutEnd))?;
        let arc = Arc::new(c.c, c.axis, c.radius, c.rule, start, end).map_err(at)?;
        if !arc.finite() {
            return Err(at(ClErrorKind::NumberOutOfRange {
                record: "CIRCLE".into(),
            }));
        }
        let mut prev = 0.0;
        for &(line, q, _) in &self.arc_points[..self.arc_points.len() - 1] {
            prev = arc.check_point(q, prev).map_err(|k| ClError::at(line, k))?;
        }
        let feed = self.feed_value(self.feed, c.line, || arc.length())?;
        let n = arc.segments(self.opts.chord_tol_mm);
        if n > self.opts.max_arc_points as f64 {
            return Err(at(ClErrorKind::ArcTooManyPoints {
                needed: if n < 1e18 { n as u64 } else { u64::MAX },
                limit: self.opts.max_arc_points,
            }));
        }
        let n = n as u64;
        let rows = ArcRows::new(arc, n, end, self.axis, a_end).map_err(at)?;
        self.note_tool(c.line, self.next_index);
        self.next_index += n;
        let tpl = Row {
            line: c.line,
            kind: Kind::Circle,
            motion: Motion::Feed,
            feed_mm_min: feed,
            tool: self.tool,
            tip: end,
            axis: a_end,
        };
        self.arc_rows = Some((rows, tpl));
        self.pos = Some(end);
        self.axis = a_end;
        self.arc_points.clear();
        Ok(())
    }

    // ------------------------------------------------------------------ cycles (SPEC §8)

    fn cycle(&mut self) -> Result<(), ClError> {
        let n = self.lex.nfields();
        if n == 0 {
            return Err(self.lex.err(ClErrorKind::CycleEmpty));
        }
        if self.lex.is_word(0, b"OFF") {
            self.cycle = None;
            return Ok(());
        }
        if self.lex.is_word(0, b"INIT") {
            return Ok(());
        }
        if self.lex.is_word(0, b"ON") {
            let Some(mut c) = self.cycle else {
                return Err(self.lex.err(ClErrorKind::CycleOnWithoutCycle));
            };
            self.cycle_params(1, &mut c)?;
            self.cycle = Some(c);
            return Ok(());
        }
        let t = self.lex.field(0);
        if !CYCLE_TYPES.iter().any(|w| w.eq_ignore_ascii_case(t)) {
            let found = latin1_short(t, 40);
            return Err(self.lex.err_field(0, ClErrorKind::CycleType { found }));
        }
        let mut c = Cycle {
            depth: None,
            rapto: 0.0,
            retract: None,
            feed: None,
        };
        if n > 1 && number::is_number(self.lex.field(1)) {
            // positional APT form: CYCLE/type, depth, unit, feed, clearance[, …]
            let word = (n >= 5).then(|| self.feed_word(2)).flatten();
            let Some(word) = word else {
                return Err(self.lex.err(ClErrorKind::CyclePositional));
            };
            let depth = self.lex.number(1)?;
            let f = self.lex.number(3)?;
            let clear = self.lex.number(4)?;
            c.depth = Some(depth.abs() * self.unit);
            c.feed = Some(self.cycle_feed(3, word, f)?);
            c.rapto = clear * self.unit;
            c.retract = Some(c.rapto);
        } else {
            self.cycle_params(1, &mut c)?;
        }
        if c.depth.is_none() {
            return Err(self.lex.err(ClErrorKind::CycleNoDepth));
        }
        self.cycle = Some(c);
        Ok(())
    }

    /// Index 0..4 of a feed unit word `MMPM`, `IPM`, `MMPR`, `IPR` at field `i`.
    fn feed_word(&self, i: usize) -> Option<usize> {
        const W: [&[u8]; 4] = [b"MMPM", b"IPM", b"MMPR", b"IPR"];
        if i >= self.lex.nfields() {
            return None;
        }
        let f = self.lex.field(i);
        W.iter().position(|w| w.eq_ignore_ascii_case(f))
    }

    fn cycle_feed(&self, i: usize, word: usize, v: f64) -> Result<Feed, ClError> {
        if v <= 0.0 {
            return Err(self.lex.err_field(i, ClErrorKind::FeedNotPositive));
        }
        let mode = match word {
            0 => FeedMode::PerMin(v),
            1 => FeedMode::PerMin(v * MM_PER_INCH),
            2 => FeedMode::PerRev(v),
            _ => FeedMode::PerRev(v * MM_PER_INCH),
        };
        Ok(Feed {
            mode,
            line: self.lex.rec_line,
        })
    }

    /// Keyword couplets of a cycle from field `from` on (SPEC §8).
    fn cycle_params(&self, from: usize, c: &mut Cycle) -> Result<(), ClError> {
        let n = self.lex.nfields();
        let mut i = from;
        while i < n {
            let w = self.lex.field(i);
            let up = |s: &[u8]| w.eq_ignore_ascii_case(s);
            let need = |i: usize| -> Result<f64, ClError> {
                if i + 1 >= n || self.lex.field(i + 1).is_empty() {
                    return Err(self.lex.err_field(
                        i,
                        ClErrorKind::CycleKeyword {
                            word: latin1_short(self.lex.field(i), 20),
                        },
                    ));
                }
                self.lex.number(i + 1)
            };
            if up(b"FEDTO") || up(b"DEPTH") {
                c.depth = Some(need(i)?.abs() * self.unit);
                i += 2;
            } else if up(b"RAPTO") {
                c.rapto = need(i)? * self.unit;
                i += 2;
            } else if up(b"RTRCTO") {
                if self.lex.is_word(i + 1, b"AUTO") {
                    c.retract = None;
                } else {
                    c.retract = Some(need(i)? * self.unit);
                }
                i += 2;
            } else if let Some(k) = self.feed_word(i) {
                let v = need(i)?;
                c.feed = Some(self.cycle_feed(i + 1, k, v)?);
                i += 2;
            } else if !w.is_empty()
                && !number::is_number(w)
                && i + 1 < n
                && number::is_number(self.lex.field(i + 1))
            {
                // another couplet: STEP, CLEAR, DWELL, 1STPECK, SUBPECK, …
                i += 2;
            } else {
                i += 1;
            }
        }
        Ok(())
    }

    fn cycle_point(&mut self, line: u64, c: Cycle, p: V3, a: V3) -> Result<(), ClError> {
        let depth = c.depth.unwrap_or(0.0);
        let r = add(p, scale(a, c.rapto));
        let b = sub(p, scale(a, depth));
        let q = add(p, scale(a, c.retract.unwrap_or(c.rapto)));
        if !(finite(r) && finite(b) && finite(q)) {
            return Err(ClError::at(
                line,
                ClErrorKind::NumberOutOfRange {
                    record: "CYCLE".into(),
                },
            ));
        }
        let feed = self.feed_value(c.feed.or(self.feed), line, || norm(sub(b, r)))?;
        self.rapid = false;
        self.emit(line, Kind::Cycle, Motion::Rapid, None, r, a);
        self.emit(line, Kind::Cycle, Motion::Feed, feed, b, a);
        self.emit(line, Kind::Cycle, Motion::Rapid, None, q, a);
        self.pos = Some(q);
        self.axis = a;
        Ok(())
    }
}

fn contains_ci(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len())
        .any(|w| w.eq_ignore_ascii_case(needle))
}

impl<R: BufRead> Iterator for Reader<R> {
    type Item = Result<Row, ClError>;

    /// The next row; `None` at the end of the file, after `FINI`, or after an error.
    fn next(&mut self) -> Option<Self::Item> {
        self.next_row()
    }
}
