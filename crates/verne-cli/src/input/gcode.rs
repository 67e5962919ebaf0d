//! G-code programs in the CLI (the reader is the `verne-gcode` crate; the rules are in
//! docs/gcode.md). The machine file's `[gcode]` table gives the words their meaning:
//!
//! - a *tool-centre program* (`verne ik PROGRAM.ngc`, `verne verify --path PROGRAM.ngc`): X Y Z
//!   the tool tip in the workpiece frame, the orientation as two angle words (phi1, phi2) or as
//!   I J K ([`TcpRows`]);
//! - a *joint program* (`verne verify --joints POST.ngc`): one letter per joint
//!   ([`JointProgram`]).
//!
//! A word the program's kind does not use is an error at its line, never ignored.

use std::io::{BufRead, Write};
use std::sync::{Arc, Mutex};

use nalgebra::Vector3;
use verne::machine::orientation::{tool_axis, unit_axis};
use verne::parallel_module::equations::Sliders;
use verne::spec::gcode::{GcodeOrientation, GcodeWords, JOINT_KEYS};
use verne::verify::{Item, JointSource, Joints, PathPoint, RowSource};
use verne_gcode::{AXES, Axis, GcodeError, Motion, Options, Reader, Row, Summary};

use crate::error::VerneError;
use crate::input::resample::{PathPose, PoseStream};
use crate::input::rows::{FieldRow, FieldRows, invalid_data};

/// A G-code reader over a boxed input, as the CLI reads files and stdin alike.
pub type GcodeReader = Reader<Box<dyn BufRead + Send>>;

/// A G-code error as the CLI's input error: file, line, column, what was expected.
pub fn gcode_error(file: &str, e: &GcodeError) -> VerneError {
    let line = (e.line > 0).then_some(e.line);
    let column = e.column.map(|c| c.to_string());
    VerneError::input(file, line, column.as_deref(), e.message.clone())
}

/// The letters of a mask, e.g. `U V`.
fn letters(mask: u16) -> String {
    let v: Vec<String> = AXES
        .iter()
        .filter(|a| mask & a.bit() != 0)
        .map(|a| a.letter().to_string())
        .collect();
    v.join(" ")
}

/// `is not a word of` or `are not words of`, for the letters of a mask.
fn not_words(mask: u16) -> &'static str {
    if mask.count_ones() == 1 {
        "is not a word of"
    } else {
        "are not words of"
    }
}

fn axis_of(letter: char) -> Axis {
    // The machine file's letters are validated (X Y Z A B C U V W).
    Axis::from_letter(letter as u8).unwrap_or(Axis::X)
}

/// Prints what the reader saw besides the rows to stderr, prefixed `verne CMD: NAME:`.
pub fn report_summary(cmd: &str, name: &str, s: &Summary) {
    if crate::verbosity() == 0 {
        return;
    }
    let mut err = std::io::stderr().lock();
    crate::input::write_warnings(&mut err, cmd, name, &s.warnings, s.warnings_dropped);
    let mut line = format!(
        "verne {cmd}: {name}: {} rows from {} blocks (G-code, {}, axes {})",
        s.rows,
        s.blocks,
        s.units.as_str(),
        s.axes_used_letters()
    );
    if !s.ignored.is_empty() {
        line.push_str("; codes that do not move the machine: ");
        line.push_str(&s.ignored_line());
    }
    let _ = writeln!(err, "{line}");
    if s.lines_after_end > 0 {
        let _ = writeln!(
            err,
            "verne {cmd}: {name}: {} lines after the program's end (line {}) not read",
            s.lines_after_end,
            s.end_line.unwrap_or(0)
        );
    }
}

/// A tool pose of a tool-centre program.
pub struct TcpPose {
    pub row: Row,
    pub tip: [f64; 3],
    pub axis: [f64; 3],
    /// The angle words (phi1, phi2) in rad, for a program that gives the orientation by them.
    pub angles: Option<(f64, f64)>,
}

/// The poses of a tool-centre program.
pub struct TcpRows {
    reader: GcodeReader,
    name: String,
    orientation: GcodeOrientation,
    allowed: u16,
    summary: Arc<Mutex<Summary>>,
}

impl TcpRows {
    /// The tool-centre program read by `reader`, with the machine's words.
    pub fn new(reader: GcodeReader, name: &str, words: &GcodeWords) -> TcpRows {
        let xyz = Axis::X.bit() | Axis::Y.bit() | Axis::Z.bit();
        let allowed = match words.orientation {
            GcodeOrientation::Angles { phi1, phi2 } => {
                xyz | axis_of(phi1).bit() | axis_of(phi2).bit()
            }
            GcodeOrientation::Vector => xyz,
        };
        let summary = Arc::new(Mutex::new(reader.summary().clone()));
        TcpRows {
            reader,
            name: name.to_string(),
            orientation: words.orientation,
            allowed,
            summary,
        }
    }

    /// The reader's summary, shared (complete once the rows are read to their end).
    pub fn summary(&self) -> Arc<Mutex<Summary>> {
        self.summary.clone()
    }

    /// The words of a tool-centre program, for messages.
    fn words(&self) -> String {
        match self.orientation {
            GcodeOrientation::Angles { phi1, phi2 } => {
                format!("X Y Z the tool tip, {phi1} = phi1 and {phi2} = phi2")
            }
            GcodeOrientation::Vector => "X Y Z the tool tip and I J K the tool axis".into(),
        }
    }

    /// The next pose; errors carry the file's name, line and what was expected.
    pub fn next_pose(&mut self) -> Option<Result<TcpPose, VerneError>> {
        let row = match self.reader.next() {
            None => {
                if let Ok(mut s) = self.summary.lock() {
                    *s = self.reader.summary().clone();
                }
                return None;
            }
            Some(Err(e)) => return Some(Err(gcode_error(&self.name, &e))),
            Some(Ok(r)) => r,
        };
        let fail = |m: String| Some(Err(VerneError::input(&self.name, Some(row.line), None, m)));
        let stray = row.written & !self.allowed;
        if stray != 0 {
            return fail(format!(
                "{} {} a tool-centre program ({}; the machine file's [gcode] table): is this a joint program? check it with verne verify --joints",
                letters(stray),
                not_words(stray),
                self.words()
            ));
        }
        let tip = [row.get(Axis::X), row.get(Axis::Y), row.get(Axis::Z)];
        let mut angles = None;
        let axis = match self.orientation {
            GcodeOrientation::Angles { phi1, phi2 } => {
                let (p1, p2) = (row.get(axis_of(phi1)), row.get(axis_of(phi2)));
                angles = Some((p1.to_radians(), p2.to_radians()));
                let v = tool_axis(p1.to_radians(), p2.to_radians());
                [v.x, v.y, v.z]
            }
            GcodeOrientation::Vector => row.tool_vector.unwrap_or([f64::NAN; 3]),
        };
        let missing = self.allowed & !row.known;
        if missing != 0 || axis.iter().any(|v| v.is_nan()) {
            let what = if missing != 0 {
                letters(missing)
            } else {
                "I J K".to_string()
            };
            return fail(format!(
                "the tool pose is not known yet ({what} not given): a tool-centre program gives {} by its first move",
                self.words()
            ));
        }
        Some(Ok(TcpPose {
            row,
            tip,
            axis,
            angles,
        }))
    }
}

impl FieldRows for TcpRows {
    fn header(&self) -> &'static [&'static str] {
        &[
            "line", "n", "kind", "motion", "feed", "dt", "tool", "x", "y", "z", "i", "j", "k",
        ]
    }

    fn next_row(&mut self, row: &mut FieldRow<'_>) -> std::io::Result<bool> {
        let Some(p) = self.next_pose_or_end()? else {
            return Ok(false);
        };
        let r = &p.row;
        row.field(r.line);
        match r.n {
            Some(n) => row.field(format_args!("N{n}")),
            None => row.optional(None::<u64>),
        }
        row.field(r.kind.as_str());
        row.field(r.motion.as_str());
        row.optional(r.feed_per_min.filter(|_| r.motion == Motion::Feed));
        // The time of the move as the program states it (its feed, G93), s.
        row.optional(r.duration_s);
        row.optional(r.tool);
        for v in p.tip.iter().chain(&p.axis) {
            row.field(v);
        }
        Ok(true)
    }
}

impl TcpRows {
    /// The next pose, `None` at the end; an error as the row engine reports it (it names
    /// the file itself), and a program without a move is an error.
    fn next_pose_or_end(&mut self) -> std::io::Result<Option<TcpPose>> {
        match self.next_pose() {
            None => {
                if self.reader.summary().rows == 0 {
                    return Err(invalid_data(
                        "no move (G0, G1, G2, G3 or a cycle): no tool pose to convert".into(),
                    ));
                }
                Ok(None)
            }
            Some(Err(e)) => Err(invalid_data(match e {
                VerneError::Input {
                    line: Some(line),
                    column,
                    message,
                    ..
                } => match column {
                    Some(c) => format!("line {line}, column {c}: {message}"),
                    None => format!("line {line}: {message}"),
                },
                other => other.to_string(),
            })),
            Some(Ok(p)) => Ok(Some(p)),
        }
    }
}

/// A tool-centre program read by the `--period` resampler directly: the program's angle
/// words go with each pose, so the stream turns the rotary axes as the controller does.
impl PoseStream for TcpRows {
    fn states_angles(&self) -> bool {
        matches!(self.orientation, GcodeOrientation::Angles { .. })
    }

    fn next_pose(&mut self) -> std::io::Result<Option<PathPose>> {
        let Some(p) = self.next_pose_or_end()? else {
            return Ok(None);
        };
        let r = &p.row;
        let axis = Vector3::from(p.axis);
        let n = axis.norm();
        if n.is_nan() || n <= 1e-12 {
            return Err(invalid_data(format!(
                "line {}: the tool axis is zero",
                r.line
            )));
        }
        Ok(Some(PathPose {
            tip: Vector3::from(p.tip),
            axis: axis / n,
            angles: p.angles,
            line: r.line.to_string(),
            rapid: r.motion == Motion::Rapid,
            feed_mm_min: r.feed_per_min.filter(|_| r.motion == Motion::Feed),
            dt: r.duration_s,
        }))
    }
}

/// A tool-centre program as the intended path of `verne verify`.
pub struct TcpPath {
    rows: TcpRows,
    index: u64,
    offset: Vector3<f64>,
}

impl TcpPath {
    pub fn new(rows: TcpRows, offset: Vector3<f64>) -> TcpPath {
        TcpPath {
            rows,
            index: 0,
            offset,
        }
    }

    /// What the reader saw besides the rows.
    pub fn summary(&self) -> Summary {
        self.rows.reader.summary().clone()
    }
}

impl RowSource for TcpPath {
    type Row = PathPoint;
    type Error = VerneError;

    fn name(&self) -> &str {
        &self.rows.name
    }

    fn has_id(&self) -> bool {
        false
    }

    fn next_item(&mut self) -> Result<Option<Item<PathPoint>>, VerneError> {
        let Some(pose) = self.rows.next_pose() else {
            return Ok(None);
        };
        let p = pose?;
        self.index += 1;
        let value = unit_axis(&Vector3::from(p.axis))
            .map(|axis| PathPoint {
                tip: Vector3::from(p.tip) + self.offset,
                axis,
                rapid: p.row.motion == Motion::Rapid,
                feed: p.row.feed_per_min.map(|f| f / 60.0),
                duration: p.row.duration_s,
                angles: p.angles,
            })
            .map_err(|e| e.to_string());
        Ok(Some(Item {
            index: self.index,
            line: p.row.line,
            id: p.row.n.map(|n| format!("N{n}")),
            value,
        }))
    }
}

/// A joint program (the output of a post for the machine) as the joint table of `verne
/// verify`: one row per block, the joints from the `[gcode]` letters, the time of each move
/// from the program's feeds, `G0` moves rapid. Rows are labelled by their `N` word when they
/// have one.
pub struct JointProgram {
    reader: GcodeReader,
    name: String,
    words: GcodeWords,
    allowed: u16,
    index: u64,
}

impl JointProgram {
    pub fn new(reader: GcodeReader, name: &str, words: &GcodeWords) -> JointProgram {
        let allowed = words
            .joints
            .iter()
            .fold(0, |m, w| m | axis_of(w.letter).bit());
        JointProgram {
            reader,
            name: name.to_string(),
            words: *words,
            allowed,
            index: 0,
        }
    }

    /// What the reader saw besides the rows.
    pub fn summary(&self) -> &Summary {
        self.reader.summary()
    }

    fn joint_words(&self) -> String {
        let v: Vec<String> = JOINT_KEYS
            .iter()
            .zip(&self.words.joints)
            .map(|(k, w)| format!("{} = {k}", w.letter))
            .collect();
        v.join(", ")
    }
}

impl RowSource for JointProgram {
    type Row = Joints;
    type Error = VerneError;

    fn name(&self) -> &str {
        &self.name
    }

    fn has_id(&self) -> bool {
        false
    }

    fn next_item(&mut self) -> Result<Option<Item<Joints>>, VerneError> {
        let row = match self.reader.next() {
            None => return Ok(None),
            Some(r) => r.map_err(|e| gcode_error(&self.name, &e))?,
        };
        let fail = |m: String| Err(VerneError::input(&self.name, Some(row.line), None, m));
        let stray = row.written & !self.allowed;
        if stray != 0 {
            return fail(format!(
                "{} {} a joint program of the machine ({}; the machine file's [gcode] table): is this a tool-centre program? give it with --path",
                letters(stray),
                not_words(stray),
                self.joint_words()
            ));
        }
        let missing = self.allowed & !row.known;
        if missing != 0 {
            return fail(format!(
                "the joints are not all known yet ({} not given): a joint program gives every joint ({}) by its first move",
                letters(missing),
                self.joint_words()
            ));
        }
        self.index += 1;
        let v: [f64; 5] = std::array::from_fn(|j| {
            let w = self.words.joints[j];
            let x = w.joint(row.get(axis_of(w.letter)));
            if j < 3 { x } else { x.to_radians() }
        });
        Ok(Some(Item {
            index: self.index,
            line: row.line,
            id: row.n.map(|n| format!("N{n}")),
            value: Ok(Joints {
                rho: Sliders::new(v[0], v[1], v[2]),
                theta1: v[3],
                theta2: v[4],
                t: None,
                feed: None,
                duration: row.duration_s,
                rapid: row.motion == Motion::Rapid,
            }),
        }))
    }
}

impl JointSource for JointProgram {
    /// A program's feed moves are timed by its feeds.
    fn timed(&self) -> bool {
        true
    }
}

/// The reader's options from the command line's and the machine's.
pub fn options(
    chord_tol_mm: f64,
    units: Option<verne_gcode::Units>,
    words: &GcodeWords,
) -> Options {
    Options {
        chord_tol_mm,
        units,
        ijk_tool_vector: words.orientation == GcodeOrientation::Vector,
        ..Options::default()
    }
}
