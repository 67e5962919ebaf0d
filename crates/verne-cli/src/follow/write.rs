//! The writers of a followed path: a CSV table (the input's columns, then the joints), a
//! halstreamer joint list for LinuxCNC, and a joint program in G-code. Each formats the typed
//! values it is given, once.

use std::io::Write;
use std::path::Path;

use arrayvec::ArrayVec;
use csv::ByteRecord;
use verne::spec::gcode::GcodeWords;

use super::{Followed, RowResult, RowSink};
use crate::engine::pipeline::{Cell, HALSTREAMER_COLUMNS, Units, write_cell};
use crate::error::VerneError;
use crate::files::Sink;
use crate::table::encode_field;
use crate::toolpath::{Column, PoseRow, Value};

/// The computed columns of a path followed on one branch.
pub const PATH_COLUMNS: [&str; 8] = [
    "rho1",
    "rho2",
    "rho3",
    "theta1",
    "theta2",
    "orientation",
    "flags",
    "status",
];

/// The computed columns of every branch of each row (`--all`).
pub const ALL_COLUMNS: [&str; 12] = [
    "branch",
    "orientation",
    "rho1",
    "rho2",
    "rho3",
    "theta1",
    "theta2",
    "s1",
    "s2",
    "s3",
    "working",
    "status",
];

/// Appends a typed input value as the reader states it (the shortest form that reads back to
/// the same number; a sample time with microsecond resolution).
fn write_value(out: &mut Vec<u8>, delimiter: u8, first: bool, value: Option<Value>) {
    if !first {
        out.push(delimiter);
    }
    match value {
        None => {}
        Some(Value::Num(v)) => {
            let _ = write!(out, "{v}");
        }
        Some(Value::Time(t)) => {
            let _ = write!(out, "{t:.6}");
        }
        Some(Value::Int(i)) => {
            let _ = write!(out, "{i}");
        }
        Some(Value::Str(s)) => encode_field(out, delimiter, true, s.as_bytes()),
        Some(Value::Text(s)) => encode_field(out, delimiter, true, s.as_bytes()),
    }
}

/// The computed cells of a row, one output row each (every branch under `--all`); `n` is the
/// number of computed columns.
fn computed_rows(f: &Followed, n: usize, mut row: impl FnMut(&[Cell])) {
    let mut cells = ArrayVec::<Cell, 16>::new();
    match &f.result {
        RowResult::Joints(r) => {
            let flags = match (
                r.near_rotary_singularity,
                r.switched,
                f.row.fraction.is_some(),
            ) {
                (_, _, true) if r.near_rotary_singularity => "inserted;near_rotary_singularity",
                (_, _, true) => "inserted",
                (true, true, false) => "near_rotary_singularity;orientation_switch",
                (true, false, false) => "near_rotary_singularity",
                (false, true, false) => "orientation_switch",
                (false, false, false) => "",
            };
            cells.extend([
                Cell::Num(r.rho.x),
                Cell::Num(r.rho.y),
                Cell::Num(r.rho.z),
                Cell::Angle(r.theta1),
                Cell::Angle(r.theta2),
                Cell::Int(r.orientation.into()),
                Cell::Str(flags),
                Cell::Str("ok"),
            ]);
            row(&cells);
        }
        RowResult::Branches(branches, _) if !branches.is_empty() => {
            for (k, (b, orientation, theta2)) in branches.iter().enumerate() {
                cells.clear();
                cells.extend([
                    Cell::Int(k as i64 + 1),
                    Cell::Int((*orientation).into()),
                    Cell::Num(b.rho.x),
                    Cell::Num(b.rho.y),
                    Cell::Num(b.rho.z),
                    Cell::Angle(b.theta1),
                    Cell::Angle(*theta2),
                ]);
                cells.extend(b.config.iter().map(|&s| Cell::Int(s.into())));
                cells.push(Cell::Bool(b.verdict.feasible()));
                cells.push(Cell::Verdict(b.verdict));
                row(&cells);
            }
        }
        RowResult::Branches(..) | RowResult::NotOk(_) => {
            cells.extend(std::iter::repeat_n(Cell::Empty, n - 1));
            cells.push(f.status());
            row(&cells);
        }
    }
}

/// Where a CSV output column comes from.
#[derive(Debug, Clone, Copy)]
enum Slot {
    /// The input's column.
    Input(usize),
    /// A computed column.
    Computed(usize),
}

/// A CSV table: every input column in order (a computed column replaces an input column of the
/// same name in place), then the other computed columns.
pub struct CsvRows {
    sink: Sink,
    units: Units,
    computed: &'static [&'static str],
    columns: Vec<Column>,
    slots: Vec<Slot>,
    buf: Vec<u8>,
}

impl CsvRows {
    /// A CSV table to `path` (stdout for `None` or `-`), of the followed branch or of every
    /// branch (`all`).
    pub fn create(path: Option<&Path>, units: Units, all: bool) -> Result<CsvRows, VerneError> {
        Ok(CsvRows {
            sink: Sink::create(path)?,
            units,
            computed: if all { &ALL_COLUMNS } else { &PATH_COLUMNS },
            columns: Vec::new(),
            slots: Vec::new(),
            buf: Vec::with_capacity(1 << 16),
        })
    }

    /// A CSV table into any writer (fuzzing, tests).
    pub fn to_writer(w: Box<dyn Write + Send>, all: bool) -> CsvRows {
        CsvRows {
            sink: Sink::from_writer(w, "<writer>"),
            units: Units::default(),
            computed: if all { &ALL_COLUMNS } else { &PATH_COLUMNS },
            columns: Vec::new(),
            slots: Vec::new(),
            buf: Vec::new(),
        }
    }

    fn encode(&mut self, f: &Followed) {
        let PoseRow { cells, .. } = &f.row;
        let (columns, slots, units, buf) = (&self.columns, &self.slots, self.units, &mut self.buf);
        let n = self.computed.len();
        computed_rows(f, n, |computed| {
            for (k, slot) in slots.iter().enumerate() {
                match *slot {
                    Slot::Input(c) => {
                        let column = &columns[c];
                        let cell = column.cell.and_then(|i| cells.get(i));
                        // A pose the post inserted writes its own pose, the rest as its row's.
                        let cell =
                            cell.filter(|_| f.row.fraction.is_none() || column.field.is_none());
                        match (cell, column.field) {
                            (Some(cell), _) => encode_field(buf, b',', k == 0, cell),
                            (None, Some(field)) => {
                                write_value(buf, b',', k == 0, f.row.value(field, units.radians))
                            }
                            (None, None) => write_value(buf, b',', k == 0, None),
                        }
                    }
                    Slot::Computed(j) => {
                        if k > 0 {
                            buf.push(b',');
                        }
                        write_cell(buf, computed[j], units);
                    }
                }
            }
            buf.push(b'\n');
        });
    }
}

impl RowSink for CsvRows {
    fn begin(&mut self, columns: &[Column]) -> Result<(), VerneError> {
        self.columns = columns.to_vec();
        let mut header = ByteRecord::new();
        for (i, c) in columns.iter().enumerate() {
            match self
                .computed
                .iter()
                .position(|o| o.eq_ignore_ascii_case(&c.name))
            {
                Some(k) => self.slots.push(Slot::Computed(k)),
                None => self.slots.push(Slot::Input(i)),
            }
            header.push_field(c.name.as_bytes());
        }
        for (k, o) in self.computed.iter().enumerate() {
            if !columns.iter().any(|c| c.name.eq_ignore_ascii_case(o)) {
                self.slots.push(Slot::Computed(k));
                header.push_field(o.as_bytes());
            }
        }
        self.sink.write(&header)
    }

    fn write(&mut self, rows: &[Followed]) -> Result<(), VerneError> {
        self.buf.clear();
        for f in rows {
            self.encode(f);
        }
        self.sink.write_encoded(&self.buf)
    }

    fn finish(self: Box<Self>) -> Result<(), VerneError> {
        self.sink.finish()
    }

    fn discard(&mut self) {
        self.sink.discard();
    }
}

/// A joint list for LinuxCNC's halstreamer: `rho1 rho2 rho3 theta1 theta2` per row, no header;
/// a row without joints stops the run.
pub struct Halstreamer {
    sink: Sink,
    units: Units,
    buf: Vec<u8>,
}

impl Halstreamer {
    pub fn create(path: Option<&Path>, units: Units) -> Result<Halstreamer, VerneError> {
        Ok(Halstreamer {
            sink: Sink::create_delimited(path, b' ')?,
            units,
            buf: Vec::with_capacity(1 << 16),
        })
    }
}

impl RowSink for Halstreamer {
    fn begin(&mut self, _: &[Column]) -> Result<(), VerneError> {
        debug_assert_eq!(HALSTREAMER_COLUMNS.len(), 5);
        Ok(())
    }

    fn every_row_needed(&self) -> Option<&'static str> {
        Some("a halstreamer joint list")
    }

    fn write(&mut self, rows: &[Followed]) -> Result<(), VerneError> {
        self.buf.clear();
        for f in rows {
            if let RowResult::Joints(r) = &f.result {
                let cells = [
                    Cell::Num(r.rho.x),
                    Cell::Num(r.rho.y),
                    Cell::Num(r.rho.z),
                    Cell::Angle(r.theta1),
                    Cell::Angle(r.theta2),
                ];
                for (k, c) in cells.into_iter().enumerate() {
                    if k > 0 {
                        self.buf.push(b' ');
                    }
                    write_cell(&mut self.buf, c, self.units);
                }
                self.buf.push(b'\n');
            }
        }
        self.sink.write_encoded(&self.buf)
    }

    fn finish(self: Box<Self>) -> Result<(), VerneError> {
        self.sink.finish()
    }

    fn discard(&mut self) {
        self.sink.discard();
    }
}

/// Joint words are written with this many decimals (mm and degrees): 1 nm, 1e-6 degree.
pub const DECIMALS: usize = 6;

/// Significant digits of a feed word (inverse time): its block's time to 1 part in 1e9.
const FEED_DIGITS: i32 = 9;

/// A joint program: one G-code block per pose, the five joints by the letters of the machine
/// file's `[gcode]` table, `G0` for rapids and for feed moves `G93` inverse time: each block
/// takes the time the post scheduled for it (within the drives' limits and the path's feeds,
/// [`super::post`]). Every block has its own `N` word, and a comment naming the toolpath line
/// it leads to (with the fraction of that move, for a pose the post inserted): `verne verify
/// --joints` pairs the blocks with the path by it.
pub struct GcodeProgram {
    sink: Sink,
    words: GcodeWords,
    source: String,
    /// Blocks written.
    blocks: u64,
    block: Vec<u8>,
}

impl GcodeProgram {
    /// A program to `path` (stdout for `None` or `-`) from the path `source`.
    pub fn create(
        path: Option<&Path>,
        words: GcodeWords,
        source: &str,
    ) -> Result<GcodeProgram, VerneError> {
        Ok(GcodeProgram {
            sink: Sink::create(path)?,
            words,
            source: source.to_string(),
            blocks: 0,
            block: Vec::with_capacity(1 << 16),
        })
    }

    /// Appends the block of one row.
    fn block(&mut self, f: &Followed) -> Result<(), VerneError> {
        let RowResult::Joints(r) = &f.result else {
            return Ok(());
        };
        let row = &f.row;
        let joints = [
            r.rho.x,
            r.rho.y,
            r.rho.z,
            r.theta1.to_degrees(),
            r.theta2.to_degrees(),
        ];
        let out = &mut self.block;
        self.blocks += 1;
        let _ = write!(out, "N{} ", self.blocks);
        out.extend_from_slice(if f.time.is_some() { b"G1" } else { b"G0" });
        for (w, v) in self.words.joints.iter().zip(joints) {
            let _ = write!(out, " {}{}", w.letter, number(w.word(v)));
        }
        if let Some(seconds) = f.time {
            let feed = feed_word(60.0 / seconds).ok_or_else(|| {
                VerneError::input(
                    &self.source,
                    Some(row.line),
                    None,
                    format!("the move takes {seconds:e} s: more than G93's inverse time can state (a feed too small?)"),
                )
            })?;
            let _ = write!(out, " F{feed}");
        }
        match row.fraction {
            Some(s) => {
                let _ = write!(
                    out,
                    " (path row {} at {} line {})",
                    f.path_row,
                    fraction_text(s),
                    row.line
                );
            }
            None => {
                let _ = write!(out, " (path row {} line {})", f.path_row, row.line);
            }
        }
        out.push(b'\n');
        Ok(())
    }
}

impl RowSink for GcodeProgram {
    fn begin(&mut self, _: &[Column]) -> Result<(), VerneError> {
        let w = &self.words.joints;
        let text = format!(
            "%\n(joint program for the VERNE machine, written by verne ik --format gcode from {})\n({} = rho1, {} = rho2, {} = rho3 in mm; {} = theta1, {} = theta2 in degrees: the machine file's [gcode] table)\n(each block: its number N, and the path row and line it leads to, with the fraction of that move for a pose inserted by the post)\n(G93: each feed block takes its time within the drives' limits and the path's feeds)\nG21 G90 G17 G40 G49 G80 G93\n",
            comment_safe(&self.source),
            w[0].letter,
            w[1].letter,
            w[2].letter,
            w[3].letter,
            w[4].letter
        );
        self.sink.write_encoded(text.as_bytes())
    }

    fn every_row_needed(&self) -> Option<&'static str> {
        Some("a joint program")
    }

    fn write(&mut self, rows: &[Followed]) -> Result<(), VerneError> {
        self.block.clear();
        for f in rows {
            self.block(f)?;
        }
        self.sink.write_encoded(&self.block)
    }

    fn finish(mut self: Box<Self>) -> Result<(), VerneError> {
        self.sink.write_encoded(b"M2\n%\n")?;
        self.sink.finish()
    }

    fn discard(&mut self) {
        self.sink.discard();
    }
}

/// An inverse-time feed word with [`FEED_DIGITS`] significant digits, rounded down (the block
/// takes no less than its time), trailing zeros dropped; `None` when it would read 0.
fn feed_word(f: f64) -> Option<String> {
    if !(f.is_finite() && f > 0.0) {
        return None;
    }
    let e = f.log10().floor() as i32;
    let decimals = (FEED_DIGITS - 1 - e).clamp(0, 12);
    let scale = 10f64.powi(decimals);
    let down = (f * scale).floor() / scale;
    if down <= 0.0 {
        return None;
    }
    let s = format!("{down:.*}", decimals as usize);
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    Some(s.to_string())
}

/// A fraction of a move, as short as it reads back within 1e-6.
fn fraction_text(s: f64) -> String {
    let t = format!("{s:.6}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A number with [`DECIMALS`] decimals, trailing zeros dropped (`12.5`, `-0.000001`, `3`).
fn number(v: f64) -> String {
    let s = format!("{v:.DECIMALS$}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// Text that can stand inside a G-code comment: no parentheses, printable ASCII.
fn comment_safe(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '(' | ')' => '_',
            c if c.is_ascii_graphic() || c == ' ' => c,
            _ => '?',
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feed_words_round_down_to_nine_digits() {
        assert_eq!(feed_word(1234.56789012).as_deref(), Some("1234.56789"));
        assert_eq!(
            feed_word(0.000123456789123).as_deref(),
            Some("0.000123456789")
        );
        assert_eq!(feed_word(60.0).as_deref(), Some("60"));
        assert_eq!(feed_word(1e-14), None);
        assert_eq!(feed_word(0.0), None);
        for f in [1.0 / 3.0, 2.0f64.sqrt() * 1e5, 7.77e-3] {
            let w: f64 = feed_word(f).unwrap().parse().unwrap();
            assert!(w <= f && w > f * (1.0 - 1e-8), "{f} -> {w}");
        }
    }

    #[test]
    fn numbers_and_comments() {
        assert_eq!(number(12.5), "12.5");
        assert_eq!(number(-1e-7), "0");
        assert_eq!(number(3.0), "3");
        assert_eq!(comment_safe("a(b).cl"), "a_b_.cl");
    }

    /// Every field of a typed row has its column's name.
    #[test]
    fn field_names_are_the_columns() {
        use crate::toolpath::Field;
        for (f, n) in [
            (Field::Line, "line"),
            (Field::Phi2, "phi2"),
            (Field::Dt, "dt"),
        ] {
            assert_eq!(f.name(), n);
        }
    }
}
