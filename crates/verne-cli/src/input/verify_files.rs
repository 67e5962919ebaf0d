//! The inputs of `verne verify`: the postprocessor's joint table (a CSV or a G-code joint
//! program) and the intended path (a toolpath: CSV, CL file or tool-centre program), read row by
//! row for the core's checks ([`verne::verify::RowSource`]), with file/line/column errors for
//! malformed cells.

use std::path::Path;

use csv::ByteRecord;
use nalgebra::Vector3;
use verne::error::shown;
use verne::parallel_module::equations::Sliders;
use verne::verify::{Item, JOINT_NAMES, JointSource, Joints, PathPoint, RowSource};

use crate::error::VerneError;
use crate::input::gcode::JointProgram;
use crate::table::{CellError, CsvSource, parse_number};
use crate::toolpath::columns::{parse_motion, parse_positive_cell};
use crate::toolpath::csv::CsvToolpath;
use crate::toolpath::gcode::TcpToolpath;
use crate::toolpath::open::{Format, Input, ReadOptions};
use crate::toolpath::{PoseRow, ReaderReport, ToolpathSource};

/// Reads a cell as a number; a non-number is fatal (file, line, column), an empty or non-finite
/// cell makes the row invalid.
fn cell(
    src_name: &str,
    rec: &ByteRecord,
    i: usize,
    col: &str,
    unit: &str,
) -> Result<Result<f64, String>, VerneError> {
    let field = rec.get(i).unwrap_or(b"");
    match parse_number(field) {
        Ok(v) => Ok(Ok(v)),
        Err(CellError::NotFinite) => Ok(Err(format!(
            "{col} is empty or not finite (`{}`)",
            shown(field)
        ))),
        Err(CellError::NotANumber) => Err(VerneError::input(
            src_name,
            rec.position().map(|p| p.line()),
            Some(col),
            format!("expected a number ({unit}), found `{}`", shown(field)),
        )),
    }
}

/// The postprocessor's joint table: `rho1,rho2,rho3` (mm), `theta1,theta2` (deg); optional `id`,
/// `t` (s), `feed` (mm/min).
pub struct JointReader {
    src: CsvSource,
    cols: [usize; 5],
    id: Option<usize>,
    t: Option<usize>,
    feed: Option<usize>,
    /// `dt`: the time of the move to the row (s).
    dt: Option<usize>,
    /// `motion` (`rapid` or `feed`, as `verne ik` writes it from a CL file or a program).
    motion: Option<usize>,
    rec: ByteRecord,
    index: u64,
}

impl JointReader {
    pub fn new(src: CsvSource) -> Result<JointReader, VerneError> {
        let c = src.require(&JOINT_NAMES)?;
        Ok(JointReader {
            cols: [c[0], c[1], c[2], c[3], c[4]],
            id: src.column("id"),
            t: src.column("t"),
            feed: src.column("feed"),
            dt: src.column("dt"),
            motion: src.column("motion"),
            src,
            rec: ByteRecord::new(),
            index: 0,
        })
    }
}

/// The intended path: a CSV of tool poses, a CL file or a tool-centre program, read as a
/// toolpath ([`crate::toolpath`]: the same readers and the same column detector as `verne ik`).
pub struct PathReader {
    source: Box<dyn ToolpathSource>,
    index: u64,
    /// Where the part sits on the table (mm): added to every tip.
    offset: Vector3<f64>,
    has_id: bool,
    row: PoseRow,
}

impl PathReader {
    /// Opens a path file: a CL file or a G-code program (by its extension or its first record
    /// or block) or a CSV of tool poses (angles in degrees). `offset` (mm) is added to every
    /// tip.
    pub fn open(
        path: &Path,
        options: &ReadOptions,
        offset: Vector3<f64>,
    ) -> Result<PathReader, VerneError> {
        let input = Input::open(Some(path), None, &[Format::Csv, Format::Cl, Format::Gcode])?;
        let source: Box<dyn ToolpathSource> = match input.format {
            Format::Cl => Box::new(input.into_cl(options.cl)?),
            Format::Gcode => {
                let name = input.name.clone();
                let reader = input.into_gcode(options.gcode)?;
                Box::new(TcpToolpath::new(reader, &name, &options.words))
            }
            Format::Csv => {
                let csv = input.into_csv()?;
                csv.require(&["x", "y", "z"])?;
                Box::new(CsvToolpath::new(csv, false)?)
            }
        };
        Ok(Self::new(source, offset))
    }

    /// The intended path read from `source`.
    pub fn new(source: Box<dyn ToolpathSource>, offset: Vector3<f64>) -> PathReader {
        let has_id = source
            .columns()
            .iter()
            .any(|c| c.name.eq_ignore_ascii_case("id"));
        PathReader {
            source,
            index: 0,
            offset,
            has_id,
            row: PoseRow::default(),
        }
    }

    /// What the reader saw besides the rows (complete once the rows are read).
    pub fn report(&self) -> ReaderReport {
        self.source.report()
    }
}

impl RowSource for JointReader {
    type Row = Joints;
    type Error = VerneError;

    fn name(&self) -> &str {
        self.src.name()
    }

    fn has_id(&self) -> bool {
        self.id.is_some()
    }

    fn next_item(&mut self) -> Result<Option<Item<Joints>>, VerneError> {
        if !self.src.read(&mut self.rec)? {
            return Ok(None);
        }
        self.index += 1;
        let name = self.src.name().to_string();
        let line = self.rec.position().map(|p| p.line()).unwrap_or(0);
        let mut v = [0.0; 5];
        let mut bad = None;
        for k in 0..5 {
            let unit = if k < 3 { "mm" } else { "degrees" };
            match cell(&name, &self.rec, self.cols[k], JOINT_NAMES[k], unit)? {
                Ok(x) => v[k] = if k < 3 { x } else { x.to_radians() },
                Err(e) => {
                    bad.get_or_insert(e);
                }
            }
        }
        // A time or feed column, once present, must hold a finite number on every row: a row
        // whose time cannot be read is an `input` finding, never a segment left unchecked.
        let mut optional =
            |i: Option<usize>, col: &str, unit: &str| -> Result<Option<f64>, VerneError> {
                match i {
                    None => Ok(None),
                    Some(i) => match cell(&name, &self.rec, i, col, unit)? {
                        Ok(x) => Ok(Some(x)),
                        Err(e) => {
                            bad.get_or_insert(e);
                            Ok(None)
                        }
                    },
                }
            };
        let t = optional(self.t, "t", "s")?;
        // `motion`, `feed` and `dt` are read as `verne ik` reads them (one reader of each).
        let column_error = |i: usize, m: String| {
            VerneError::input(&name, Some(line), Some(&self.src.header_name(i)), m)
        };
        let rec = &self.rec;
        let motion = match self.motion {
            Some(i) => parse_motion(rec.get(i).unwrap_or(b"")).map_err(|m| column_error(i, m))?,
            None => None,
        };
        let rapid = motion == Some(crate::toolpath::Motion::Rapid);
        // A rapid row has no feed (the machine's rapid rate); a feed row before the path's
        // first feed (as NX writes) has none either: the segment is then untimed.
        let feed = match self.feed {
            Some(i) if !rapid => parse_positive_cell(rec.get(i).unwrap_or(b""), "a feed in mm/min")
                .map_err(|m| column_error(i, m))?
                .map(|f| f / 60.0),
            _ => None,
        };
        let duration = match self.dt {
            Some(i) => parse_positive_cell(rec.get(i).unwrap_or(b""), "a time in s")
                .map_err(|m| column_error(i, m))?,
            None => None,
        };
        let id = self
            .id
            .map(|i| String::from_utf8_lossy(self.rec.get(i).unwrap_or(b"")).into_owned());
        let value = match bad {
            Some(e) => Err(e),
            None => Ok(Joints {
                rho: Sliders::new(v[0], v[1], v[2]),
                theta1: v[3],
                theta2: v[4],
                t,
                feed,
                duration,
                rapid,
            }),
        };
        Ok(Some(Item {
            index: self.index,
            line,
            id,
            value,
            tag: None,
        }))
    }
}

impl JointSource for JointReader {
    /// True when velocities can be checked.
    fn timed(&self) -> bool {
        self.t.is_some() || self.feed.is_some() || self.dt.is_some()
    }
}

impl RowSource for PathReader {
    type Row = PathPoint;
    type Error = VerneError;

    fn name(&self) -> &str {
        self.source.name()
    }

    fn has_id(&self) -> bool {
        self.has_id
    }

    fn next_item(&mut self) -> Result<Option<Item<PathPoint>>, VerneError> {
        if !self.source.next_row(&mut self.row)? {
            return Ok(None);
        }
        self.index += 1;
        let r = &self.row;
        Ok(Some(Item {
            index: self.index,
            line: r.line,
            id: r.id.clone(),
            value: r.path_point(&self.offset),
            tag: None,
        }))
    }
}

/// The joint table of `verne verify`: a CSV, or a G-code joint program (by its extension or
/// its first block; `[gcode]` of the machine file names the joints).
#[allow(clippy::large_enum_variant)] // one per run
pub enum JointInput {
    Csv(JointReader),
    Gcode(JointProgram),
}

impl JointInput {
    /// Opens `path` as a G-code joint program or a CSV joint table.
    pub fn open(path: &Path, options: &ReadOptions) -> Result<JointInput, VerneError> {
        let input = Input::open(Some(path), None, &[Format::Csv, Format::Gcode])?;
        match input.format {
            Format::Gcode => {
                let name = input.name.clone();
                let reader = input.into_gcode(options.gcode)?;
                Ok(JointInput::Gcode(JointProgram::new(
                    reader,
                    &name,
                    &options.words,
                )))
            }
            _ => Ok(JointInput::Csv(JointReader::new(input.into_csv()?)?)),
        }
    }

    /// What the G-code reader saw besides the rows, for a G-code joint program.
    pub fn gcode_summary(&self) -> Option<(&str, &verne_gcode::Summary)> {
        match self {
            JointInput::Gcode(p) => Some((p.name(), p.summary())),
            JointInput::Csv(_) => None,
        }
    }
}

impl RowSource for JointInput {
    type Row = Joints;
    type Error = VerneError;

    fn name(&self) -> &str {
        match self {
            JointInput::Csv(r) => r.name(),
            JointInput::Gcode(p) => p.name(),
        }
    }

    fn has_id(&self) -> bool {
        match self {
            JointInput::Csv(r) => r.has_id(),
            JointInput::Gcode(p) => p.has_id(),
        }
    }

    fn next_item(&mut self) -> Result<Option<Item<Joints>>, VerneError> {
        match self {
            JointInput::Csv(r) => r.next_item(),
            JointInput::Gcode(p) => p.next_item(),
        }
    }
}

impl JointSource for JointInput {
    fn timed(&self) -> bool {
        match self {
            JointInput::Csv(r) => r.timed(),
            JointInput::Gcode(p) => p.timed(),
        }
    }

    fn starts_at_rest(&self) -> bool {
        match self {
            JointInput::Csv(r) => r.starts_at_rest(),
            JointInput::Gcode(p) => p.starts_at_rest(),
        }
    }
}
