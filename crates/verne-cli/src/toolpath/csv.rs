//! A CSV of tool poses: `x,y,z` with `i,j,k` or `phi1,phi2` (workpiece frame), and when present
//! `motion`, `feed` (mm/min), `dt` (s), `tool` and `id`; every other column is passed through.

use nalgebra::Vector3;
use verne::error::shown;
use verne::machine::orientation::{ToolAngles, ToolOrientation};

use super::columns::{OrientationColumns, parse_motion, parse_positive_cell};
use super::{Column, Field, PoseRow, ToolpathSource};
use crate::error::VerneError;
use crate::table::{CellError, CsvSource, parse_number};

/// The tool poses of a CSV.
pub struct CsvToolpath {
    src: CsvSource,
    orientation: OrientationColumns,
    /// x, y, z, then i, j, k or phi1, phi2.
    pose: Vec<usize>,
    motion: Option<usize>,
    feed: Option<usize>,
    dt: Option<usize>,
    tool: Option<usize>,
    id: Option<usize>,
    radians: bool,
    columns: Vec<Column>,
}

impl CsvToolpath {
    /// The tool poses of `src`, whose header has `x,y,z` ([`OrientationColumns::detect`] decides
    /// the orientation, the same way for every command); angle columns in radians when
    /// `radians`, else degrees.
    pub fn new(src: CsvSource, radians: bool) -> Result<CsvToolpath, VerneError> {
        let orientation = OrientationColumns::detect(|c| src.column(c).is_some())
            .map_err(|m| VerneError::input(src.name(), Some(1), None, m))?;
        let mut names = vec!["x", "y", "z"];
        names.extend_from_slice(orientation.names());
        let pose = src.require(&names)?;
        let fields: &[Field] = match orientation {
            OrientationColumns::Axis => {
                &[Field::X, Field::Y, Field::Z, Field::I, Field::J, Field::K]
            }
            OrientationColumns::Angles => &[Field::X, Field::Y, Field::Z, Field::Phi1, Field::Phi2],
        };
        let columns = src
            .headers()
            .iter()
            .enumerate()
            .map(|(i, h)| Column {
                name: String::from_utf8_lossy(h).into_owned(),
                cell: Some(i),
                field: pose.iter().position(|&p| p == i).map(|k| fields[k]),
            })
            .collect();
        Ok(CsvToolpath {
            orientation,
            motion: src.column("motion"),
            feed: src.column("feed"),
            dt: src.column("dt"),
            tool: src.column("tool"),
            id: src.column("id"),
            pose,
            radians,
            columns,
            src,
        })
    }

    /// An error at a cell of the current record.
    fn cell_error(&self, line: u64, column: &str, message: String) -> VerneError {
        VerneError::input(self.src.name(), Some(line), Some(column), message)
    }
}

impl ToolpathSource for CsvToolpath {
    fn name(&self) -> &str {
        self.src.name()
    }

    fn columns(&self) -> &[Column] {
        &self.columns
    }

    fn states_angles(&self) -> bool {
        self.orientation == OrientationColumns::Angles
    }

    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError> {
        let mut rec = std::mem::take(&mut row.cells);
        if !self.src.read(&mut rec)? {
            row.cells = rec;
            return Ok(false);
        }
        let line = rec.position().map_or(0, |p| p.line());
        let cell = |i: usize| rec.get(i).unwrap_or(b"");
        let mut values = [0.0; 6];
        let mut invalid = None;
        let angles = self.orientation == OrientationColumns::Angles;
        for (k, &i) in self.pose.iter().enumerate() {
            let name = self.columns[i].name.as_str();
            match parse_number(cell(i)) {
                Ok(v) => values[k] = v,
                Err(CellError::NotFinite) => {
                    invalid.get_or_insert_with(|| {
                        format!("{name} is empty or not finite (`{}`)", shown(cell(i)))
                    });
                }
                Err(CellError::NotANumber) => {
                    let unit = match (k < 3, angles, self.radians) {
                        (true, _, _) => "mm",
                        (false, false, _) => "a unit vector component",
                        (false, true, true) => "radians",
                        (false, true, false) => "degrees",
                    };
                    return Err(self.cell_error(
                        line,
                        name,
                        format!("expected a number ({unit}), found `{}`", shown(cell(i))),
                    ));
                }
            }
        }
        let optional = |i: Option<usize>, what: &str| -> Result<Option<f64>, VerneError> {
            i.map_or(Ok(None), |i| {
                parse_positive_cell(cell(i), what)
                    .map_err(|m| self.cell_error(line, &self.columns[i].name, m))
            })
        };
        row.motion = match self.motion {
            Some(i) => parse_motion(cell(i))
                .map_err(|m| self.cell_error(line, &self.columns[i].name, m))?,
            None => None,
        };
        // A rapid moves at the machine's rate: its feed cell, if any, is not read.
        row.feed = if row.rapid() {
            None
        } else {
            optional(self.feed, "a feed in mm/min")?
        };
        row.dt = optional(self.dt, "a time in s")?;
        row.tool = match self.tool {
            Some(i) if !cell(i).is_empty() => Some(
                std::str::from_utf8(cell(i))
                    .ok()
                    .and_then(|t| t.parse::<u32>().ok())
                    .ok_or_else(|| {
                        self.cell_error(
                            line,
                            &self.columns[i].name,
                            format!("expected a tool number, found `{}`", shown(cell(i))),
                        )
                    })?,
            ),
            _ => None,
        };
        row.id = self
            .id
            .map(|i| String::from_utf8_lossy(cell(i)).into_owned());
        row.line = line;
        row.n = None;
        row.kind = None;
        row.t = None;
        row.tip = Vector3::new(values[0], values[1], values[2]);
        let to_rad = |v: f64| if self.radians { v } else { v.to_radians() };
        (row.orientation, row.stated_angles) = match self.orientation {
            OrientationColumns::Axis => (
                ToolOrientation::Axis(Vector3::new(values[3], values[4], values[5])),
                None,
            ),
            OrientationColumns::Angles => {
                let (phi1, phi2) = (to_rad(values[3]), to_rad(values[4]));
                (
                    ToolOrientation::Angles(ToolAngles { phi1, phi2 }),
                    Some((phi1, phi2)),
                )
            }
        };
        row.invalid = invalid;
        row.cells = rec;
        row.fraction = None;
        Ok(true)
    }
}
