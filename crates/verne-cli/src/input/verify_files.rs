//! The inputs of `verne verify`: the postprocessor's joint table (CSV) and the intended path (CSV
//! or APT CL), read row by row for the core's checks ([`verne::verify::RowSource`]), with
//! file/line/column errors for malformed cells.

use std::path::Path;

use csv::ByteRecord;
use nalgebra::Vector3;
use verne::error::shown;
use verne::machine::orientation::{tool_axis, unit_axis};
use verne::parallel_module::equations::Sliders;
use verne::verify::{Item, JOINT_NAMES, JointSource, Joints, PathPoint, RowSource};

use crate::error::VerneError;
use crate::input::cl::{ClReader, PathInput, ReadOptions, cl_error, open_path_input};
use crate::input::gcode::{JointProgram, TcpPath, TcpRows};
use crate::table::{CellError, CsvSource, parse_number};

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
            motion: src.column("motion"),
            src,
            rec: ByteRecord::new(),
            index: 0,
        })
    }
}

#[allow(clippy::large_enum_variant)] // one per run
enum PathKind {
    Csv {
        src: CsvSource,
        xyz: [usize; 3],
        /// i,j,k or phi1,phi2 (then the third is unused).
        orient: [usize; 3],
        angles: bool,
        id: Option<usize>,
        rec: ByteRecord,
    },
    Cl {
        reader: Box<ClReader>,
    },
    Gcode(TcpPath),
}

/// The intended path: a CSV (`x,y,z` and `i,j,k` or `phi1,phi2` in degrees, optional `id`) or a
/// CL file (its rows in file order, with rapid/feed and the feed of each move).
pub struct PathReader {
    kind: PathKind,
    name: String,
    index: u64,
    /// Where the part sits on the table (mm): added to every tip.
    offset: Vector3<f64>,
}

impl PathReader {
    /// Opens a path file: a CL file (by its extension or its first record, any dialect of
    /// `docs/cl-dialects.md`) or CSV. `offset` (mm) is added to every tip.
    pub fn open(
        path: &Path,
        options: &ReadOptions,
        offset: Vector3<f64>,
    ) -> Result<PathReader, VerneError> {
        let mut reader = match open_path_input(Some(path), None, options)? {
            PathInput::Cl(reader, name) => PathReader {
                kind: PathKind::Cl { reader },
                name,
                index: 0,
                offset,
            },
            PathInput::Gcode(reader, name) => PathReader {
                kind: PathKind::Gcode(TcpPath::new(
                    TcpRows::new(*reader, &name, &options.words),
                    offset,
                )),
                name,
                index: 0,
                offset,
            },
            PathInput::Csv(src) => Self::from_csv(src)?,
        };
        reader.offset = offset;
        Ok(reader)
    }

    /// What the CL reader saw besides the rows (complete once the rows are read), and the
    /// file's name; `None` for a CSV path.
    pub fn cl_summary(&self) -> Option<(&str, &verne_cl::Summary)> {
        match &self.kind {
            PathKind::Cl { reader } => Some((&self.name, reader.summary())),
            _ => None,
        }
    }

    /// What the G-code reader saw besides the rows, and the file's name; `None` for other
    /// paths.
    pub fn gcode_summary(&self) -> Option<(&str, verne_gcode::Summary)> {
        match &self.kind {
            PathKind::Gcode(p) => Some((&self.name, p.summary())),
            _ => None,
        }
    }

    /// A CSV path from an opened source.
    pub fn from_csv(src: CsvSource) -> Result<PathReader, VerneError> {
        let xyz = src.require(&["x", "y", "z"])?;
        let (orient, angles) = if src.column("i").is_some() || src.column("phi1").is_none() {
            let c = src.require(&["x", "y", "z", "i", "j", "k"])?;
            ([c[3], c[4], c[5]], false)
        } else {
            let c = src.require(&["x", "y", "z", "phi1", "phi2"])?;
            ([c[3], c[4], c[4]], true)
        };
        Ok(PathReader {
            name: src.name().to_string(),
            kind: PathKind::Csv {
                xyz: [xyz[0], xyz[1], xyz[2]],
                orient,
                angles,
                id: src.column("id"),
                src,
                rec: ByteRecord::new(),
            },
            index: 0,
            offset: Vector3::zeros(),
        })
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
        // A rapid row has no feed (the machine's rapid rate): its empty feed cell is no gap.
        let rapid = self.motion.is_some_and(|i| {
            self.rec
                .get(i)
                .is_some_and(|m| m.eq_ignore_ascii_case(b"rapid"))
        });
        let feed_column = if rapid { None } else { self.feed };
        let feed = optional(feed_column, "feed", "mm/min")?.map(|f| f / 60.0);
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
                duration: None,
                rapid,
            }),
        };
        Ok(Some(Item {
            index: self.index,
            line,
            id,
            value,
        }))
    }
}

impl JointSource for JointReader {
    /// True when velocities can be checked.
    fn timed(&self) -> bool {
        self.t.is_some() || self.feed.is_some()
    }
}

impl RowSource for PathReader {
    type Row = PathPoint;
    type Error = VerneError;

    fn name(&self) -> &str {
        &self.name
    }

    fn has_id(&self) -> bool {
        matches!(&self.kind, PathKind::Csv { id: Some(_), .. })
    }

    fn next_item(&mut self) -> Result<Option<Item<PathPoint>>, VerneError> {
        match &mut self.kind {
            PathKind::Gcode(p) => p.next_item(),
            PathKind::Cl { reader } => {
                let row = match reader.next() {
                    None => return Ok(None),
                    Some(r) => r.map_err(|e| cl_error(&self.name, &e))?,
                };
                self.index += 1;
                let axis = Vector3::from(row.axis);
                let value = unit_axis(&axis)
                    .map(|axis| PathPoint {
                        tip: Vector3::from(row.tip) + self.offset,
                        axis,
                        rapid: row.motion == verne_cl::Motion::Rapid,
                        feed: row.feed_mm_min.map(|f| f / 60.0),
                        duration: None,
                        angles: None,
                    })
                    .map_err(|e| format!("{} at line {}: {e}", row.kind, row.line));
                Ok(Some(Item {
                    index: self.index,
                    line: row.line,
                    id: None,
                    value,
                }))
            }
            PathKind::Csv {
                src,
                xyz,
                orient,
                angles,
                id,
                rec,
            } => {
                if !src.read(rec)? {
                    return Ok(None);
                }
                self.index += 1;
                let name = src.name().to_string();
                let line = rec.position().map(|p| p.line()).unwrap_or(0);
                let names: [&str; 6] = if *angles {
                    ["x", "y", "z", "phi1", "phi2", "phi2"]
                } else {
                    ["x", "y", "z", "i", "j", "k"]
                };
                let cols = [xyz[0], xyz[1], xyz[2], orient[0], orient[1], orient[2]];
                let mut v = [0.0; 6];
                let mut bad = None;
                for k in 0..6 {
                    let unit = if k < 3 {
                        "mm"
                    } else if *angles {
                        "degrees"
                    } else {
                        "unit vector component"
                    };
                    match cell(&name, rec, cols[k], names[k], unit)? {
                        Ok(x) => v[k] = x,
                        Err(e) => {
                            bad.get_or_insert(e);
                        }
                    }
                }
                let id =
                    id.map(|i| String::from_utf8_lossy(rec.get(i).unwrap_or(b"")).into_owned());
                let tip = Vector3::new(v[0], v[1], v[2]) + self.offset;
                let value = match bad {
                    Some(e) => Err(e),
                    None if *angles => {
                        let (p1, p2) = (v[3].to_radians(), v[4].to_radians());
                        Ok(PathPoint {
                            angles: Some((p1, p2)),
                            ..PathPoint::new(tip, tool_axis(p1, p2))
                        })
                    }
                    None => unit_axis(&Vector3::new(v[3], v[4], v[5]))
                        .map(|axis| PathPoint::new(tip, axis))
                        .map_err(|e| e.to_string()),
                };
                Ok(Some(Item {
                    index: self.index,
                    line,
                    id,
                    value,
                }))
            }
        }
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
        let name = path.display().to_string();
        let gcode = verne_gcode::has_gcode_extension(&name) || {
            use std::io::Read;
            let mut head = Vec::with_capacity(verne_cl::SNIFF_BYTES);
            if path.as_os_str() != "-" {
                let f =
                    crate::table::open_input_file(path).map_err(|e| VerneError::io(&name, e))?;
                f.take(verne_cl::SNIFF_BYTES as u64)
                    .read_to_end(&mut head)
                    .map_err(|e| VerneError::io(&name, e))?;
            }
            verne_gcode::sniff_content(&head)
        };
        if !gcode {
            return Ok(JointInput::Csv(JointReader::new(CsvSource::open(Some(
                path,
            ))?)?));
        }
        let f = crate::table::open_input_file(path).map_err(|e| VerneError::io(&name, e))?;
        let input: Box<dyn std::io::BufRead + Send> =
            Box::new(std::io::BufReader::with_capacity(64 * 1024, f));
        let reader = verne_gcode::Reader::new(input, options.gcode)
            .map_err(|e| crate::input::gcode::gcode_error(&name, &e))?;
        let program = JointProgram::new(reader, &name, &options.words);
        Ok(JointInput::Gcode(program))
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
}
