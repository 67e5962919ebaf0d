//! Toolpaths as typed rows. Every reader of tool poses (a CSV of tool poses, a CL file, a
//! tool-centre G-code program, the command line's `--tool`) and every stage between a reader and
//! a writer (the look-ahead, resampling at the servo period) yields [`PoseRow`]s: each number is
//! parsed once, where it enters, and formatted once, by the writer that writes it.
//!
//! - [`columns`]: the one detector of a CSV's toolpath columns, and the one reader of its
//!   `motion`, `feed` and `dt` cells, shared by every command;
//! - [`csv`], [`cl`], [`gcode`], [`inline`]: the readers;
//! - [`open`]: an input opened once, its format told from the first bytes of the same buffer;
//! - [`lookahead`]: rows read ahead and replayed (the first decided orientation);
//! - [`resample`]: the poses at every servo period.

pub mod cl;
pub mod columns;
pub mod csv;
pub mod gcode;
pub mod inline;
pub mod lookahead;
pub mod open;
pub mod resample;

use ::csv::ByteRecord;
use nalgebra::Vector3;
use verne::machine::orientation::{ToolAngles, ToolOrientation, tool_axis, unit_axis};
use verne::verify::PathPoint;

use crate::error::VerneError;

/// How the machine moves to a pose.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Positioning at the machine's rapid rate (`G0`, `RAPID`): not along the straight line.
    Rapid,
    /// A cutting move at the programmed feed, along the straight line.
    Feed,
}

impl Motion {
    /// `rapid` or `feed`, as the `motion` column writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Rapid => "rapid",
            Motion::Feed => "feed",
        }
    }
}

/// A typed column of a toolpath: what a reader or a stage gives besides a CSV's own cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// The row's line in its own file.
    Line,
    /// A G-code program's `N` word.
    N,
    /// The record or block that produced the row (`GOTO`, `CIRCLE`, `G1`, ...).
    Kind,
    Motion,
    /// mm/min.
    Feed,
    /// The move's time as the input states it (s).
    Dt,
    /// The sample's time (s), for a resampled path.
    T,
    Tool,
    X,
    Y,
    Z,
    I,
    J,
    K,
    /// The tool angles (degrees unless `--radians`).
    Phi1,
    Phi2,
}

impl Field {
    /// The column's name.
    pub fn name(self) -> &'static str {
        match self {
            Field::Line => "line",
            Field::N => "n",
            Field::Kind => "kind",
            Field::Motion => "motion",
            Field::Feed => "feed",
            Field::Dt => "dt",
            Field::T => "t",
            Field::Tool => "tool",
            Field::X => "x",
            Field::Y => "y",
            Field::Z => "z",
            Field::I => "i",
            Field::J => "j",
            Field::K => "k",
            Field::Phi1 => "phi1",
            Field::Phi2 => "phi2",
        }
    }
}

/// One column a toolpath contributes to a CSV output: a CSV input's own cell, passed through as
/// it was, or a typed field. A CSV's pose columns are both: a row that is not the input's own
/// (a pose inserted between two rows) writes its typed value there.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    pub name: String,
    /// The cell of the input's record, for a CSV.
    pub cell: Option<usize>,
    /// The typed value, for a reader of another format, and for the pose columns of a CSV.
    pub field: Option<Field>,
}

impl Column {
    /// A typed column.
    pub fn typed(field: Field) -> Column {
        Column {
            name: field.name().to_string(),
            cell: None,
            field: Some(field),
        }
    }

    /// The typed columns `fields`, in order.
    pub fn typed_all(fields: &[Field]) -> Vec<Column> {
        fields.iter().map(|&f| Column::typed(f)).collect()
    }
}

/// One tool pose of a toolpath and the move to it.
#[derive(Debug, Clone)]
pub struct PoseRow {
    /// The row's line in its own file (the CSV record's, the CL record's, the G-code block's;
    /// the pose's place on the command line).
    pub line: u64,
    /// A G-code program's `N` word.
    pub n: Option<u64>,
    /// The record or block that produced the row, for a CL file or a program.
    pub kind: Option<&'static str>,
    /// How the machine moves to this pose, when the input says.
    pub motion: Option<Motion>,
    /// The programmed feed of the move (mm/min; degrees/min for a move of the rotary axes
    /// alone), when the input gives one.
    pub feed: Option<f64>,
    /// The move's time (s) as the input states it (a program's feed rule, `G93`; a `dt` cell).
    pub dt: Option<f64>,
    /// The sample's time (s) on a resampled path.
    pub t: Option<f64>,
    pub tool: Option<u32>,
    /// A CSV's `id` cell, for `verne verify`'s pairing.
    pub id: Option<String>,
    /// The tool tip (mm, workpiece frame).
    pub tip: Vector3<f64>,
    /// The tool orientation the inverse kinematics solves for: the axis `i,j,k` (both
    /// orientation solutions), or the angles `phi1,phi2` as given.
    pub orientation: ToolOrientation,
    /// The tool angles (phi1, phi2) (rad) as the input states them (a CSV's `phi1,phi2`, a
    /// program's angle words): a controller interpolates these.
    pub stated_angles: Option<(f64, f64)>,
    /// Why the pose cannot be used (an empty or non-finite cell): the row's status is then
    /// `invalid_input`.
    pub invalid: Option<String>,
    /// A CSV input's own cells, passed through to CSV output; empty for other readers.
    pub cells: ByteRecord,
    /// For a pose the post inserted (not a row of the input): the fraction of the move to the
    /// row of `line` it lies at.
    pub fraction: Option<f64>,
}

impl Default for PoseRow {
    fn default() -> PoseRow {
        PoseRow {
            line: 0,
            n: None,
            kind: None,
            motion: None,
            feed: None,
            dt: None,
            t: None,
            tool: None,
            id: None,
            tip: Vector3::zeros(),
            orientation: ToolOrientation::Axis(Vector3::z()),
            stated_angles: None,
            invalid: None,
            cells: ByteRecord::new(),
            fraction: None,
        }
    }
}

impl PoseRow {
    /// True for a rapid move.
    pub fn rapid(&self) -> bool {
        self.motion == Some(Motion::Rapid)
    }

    /// The tool axis (unit) of the row's orientation, or why it has none.
    pub fn axis(&self) -> Result<Vector3<f64>, String> {
        match self.orientation {
            ToolOrientation::Axis(v) => unit_axis(&v).map_err(|e| e.to_string()),
            ToolOrientation::Angles(a) => Ok(tool_axis(a.phi1, a.phi2)),
        }
    }

    /// The row as a point of `verne verify`'s intended path (`offset` added to the tip), or why
    /// it is not one.
    pub fn path_point(&self, offset: &Vector3<f64>) -> Result<PathPoint, String> {
        if let Some(why) = &self.invalid {
            return Err(why.clone());
        }
        let axis = self.axis()?;
        Ok(PathPoint {
            tip: self.tip + offset,
            axis,
            rapid: self.rapid(),
            feed: self.feed.map(|f| f / 60.0),
            duration: self.dt,
            angles: self.stated_angles,
        })
    }

    /// The typed value of a field, for a writer; `None` for an empty cell.
    pub fn value(&self, field: Field, radians: bool) -> Option<Value> {
        let angle = |v: f64| Value::Num(if radians { v } else { v.to_degrees() });
        let (axis, angles) = match self.orientation {
            ToolOrientation::Axis(v) => (Some(v), self.stated_angles),
            ToolOrientation::Angles(ToolAngles { phi1, phi2 }) => (
                Some(tool_axis(phi1, phi2)),
                self.stated_angles.or(Some((phi1, phi2))),
            ),
        };
        match field {
            Field::Line => Some(Value::Int(self.line)),
            Field::N => self.n.map(|n| Value::Text(format!("N{n}"))),
            Field::Kind => self.kind.map(Value::Str),
            Field::Motion => self.motion.map(|m| Value::Str(m.as_str())),
            Field::Feed => self.feed.map(Value::Num),
            Field::Dt => self.dt.map(Value::Num),
            Field::T => self.t.map(Value::Time),
            Field::Tool => self.tool.map(|t| Value::Int(u64::from(t))),
            Field::X => Some(Value::Num(self.tip.x)),
            Field::Y => Some(Value::Num(self.tip.y)),
            Field::Z => Some(Value::Num(self.tip.z)),
            Field::I => axis.map(|a| Value::Num(a.x)),
            Field::J => axis.map(|a| Value::Num(a.y)),
            Field::K => axis.map(|a| Value::Num(a.z)),
            Field::Phi1 => angles.map(|a| angle(a.0)),
            Field::Phi2 => angles.map(|a| angle(a.1)),
        }
    }
}

/// A typed value as a writer formats it.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number in its shortest exact form (or the run's `--precision`).
    Num(f64),
    /// A time in seconds, written with microsecond resolution.
    Time(f64),
    Int(u64),
    Str(&'static str),
    Text(String),
}

/// What a reader saw besides its rows, for the summary on stderr: complete once its rows have
/// been read to the end.
#[derive(Debug, Clone)]
pub enum ReaderReport {
    /// A CSV or the command line: nothing besides the rows.
    Nothing,
    Cl(verne_cl::Summary),
    Gcode(verne_gcode::Summary),
}

/// A toolpath, read row by row.
pub trait ToolpathSource: Send {
    /// The input's name for messages (a file's path, `<stdin>`, `<command line>`).
    fn name(&self) -> &str;
    /// The columns the input gives a CSV output, in order.
    fn columns(&self) -> &[Column];
    /// Reads the next row into `row` (every field set); `Ok(false)` at the end. An error (a
    /// cell that is not a number, a reader's error) names the file, line and column.
    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError>;
    /// Whether every row states its tool angles (phi1,phi2 columns, a program's angle words).
    fn states_angles(&self) -> bool {
        false
    }
    /// What the reader saw besides the rows.
    fn report(&self) -> ReaderReport {
        ReaderReport::Nothing
    }
}

impl<S: ToolpathSource + ?Sized> ToolpathSource for Box<S> {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn columns(&self) -> &[Column] {
        (**self).columns()
    }
    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError> {
        (**self).next_row(row)
    }
    fn states_angles(&self) -> bool {
        (**self).states_angles()
    }
    fn report(&self) -> ReaderReport {
        (**self).report()
    }
}
