//! A tool-centre G-code program's tool poses (`verne ik PROGRAM.ngc`, `verne verify --path
//! PROGRAM.ngc`): X Y Z the tool tip in the workpiece frame, the orientation as two angle words
//! (phi1, phi2) or as I J K, as the machine file's `[gcode]` table says. The reader is the
//! `verne-gcode` crate (docs/gcode.md); a word the program's kind does not use is an error at its
//! line, never ignored.

use nalgebra::Vector3;
use verne::machine::orientation::{ToolAngles, ToolOrientation, tool_axis};
use verne::spec::gcode::{GcodeOrientation, GcodeWords};
use verne_gcode::{Axis, Motion as GcodeMotion};

use super::{Column, Field, Motion, PoseRow, ReaderReport, ToolpathSource};
use crate::error::VerneError;
use crate::input::gcode::{GcodeReader, axis_of, gcode_error, letters, not_words};

/// The columns of a tool-centre program's rows.
const TCP_FIELDS: [Field; 13] = [
    Field::Line,
    Field::N,
    Field::Kind,
    Field::Motion,
    Field::Feed,
    Field::Dt,
    Field::Tool,
    Field::X,
    Field::Y,
    Field::Z,
    Field::I,
    Field::J,
    Field::K,
];

/// The tool poses of a tool-centre program.
pub struct TcpToolpath {
    reader: GcodeReader,
    name: String,
    orientation: GcodeOrientation,
    /// The axis words a tool-centre program may write.
    allowed: u16,
    columns: Vec<Column>,
}

impl TcpToolpath {
    /// The tool-centre program read by `reader`, with the machine's words.
    pub fn new(reader: GcodeReader, name: &str, words: &GcodeWords) -> TcpToolpath {
        let xyz = Axis::X.bit() | Axis::Y.bit() | Axis::Z.bit();
        let allowed = match words.orientation {
            GcodeOrientation::Angles { phi1, phi2 } => {
                xyz | axis_of(phi1).bit() | axis_of(phi2).bit()
            }
            GcodeOrientation::Vector => xyz,
        };
        TcpToolpath {
            reader,
            name: name.to_string(),
            orientation: words.orientation,
            allowed,
            columns: Column::typed_all(&TCP_FIELDS),
        }
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
}

impl ToolpathSource for TcpToolpath {
    fn name(&self) -> &str {
        &self.name
    }

    fn columns(&self) -> &[Column] {
        &self.columns
    }

    fn states_angles(&self) -> bool {
        matches!(self.orientation, GcodeOrientation::Angles { .. })
    }

    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError> {
        let r = match self.reader.next() {
            None if self.reader.summary().rows == 0 => {
                return Err(VerneError::input(
                    &self.name,
                    None,
                    None,
                    "no move (G0, G1, G2, G3 or a cycle): no tool pose to convert",
                ));
            }
            None => return Ok(false),
            Some(Err(e)) => return Err(gcode_error(&self.name, &e)),
            Some(Ok(r)) => r,
        };
        let fail = |m: String| Err(VerneError::input(&self.name, Some(r.line), None, m));
        let stray = r.written & !self.allowed;
        if stray != 0 {
            return fail(format!(
                "{} {} a tool-centre program ({}; the machine file's [gcode] table): is this a joint program? check it with verne verify --joints",
                letters(stray),
                not_words(stray),
                self.words()
            ));
        }
        let missing = self.allowed & !r.known;
        let (axis, angles) = match self.orientation {
            GcodeOrientation::Angles { phi1, phi2 } => {
                let (p1, p2) = (
                    r.get(axis_of(phi1)).to_radians(),
                    r.get(axis_of(phi2)).to_radians(),
                );
                (Some(tool_axis(p1, p2)), Some((p1, p2)))
            }
            GcodeOrientation::Vector => (r.tool_vector.map(Vector3::from), None),
        };
        let axis = match axis {
            Some(a) if missing == 0 && a.iter().all(|v| v.is_finite()) => a,
            _ => {
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
        };
        row.line = r.line;
        row.n = r.n;
        row.kind = Some(r.kind.as_str());
        row.motion = Some(match r.motion {
            GcodeMotion::Rapid => Motion::Rapid,
            GcodeMotion::Feed => Motion::Feed,
        });
        row.feed = r.feed_per_min.filter(|_| r.motion == GcodeMotion::Feed);
        // The time of the move as the program states it (its feed rule, G93), s.
        row.dt = r.duration_s;
        row.t = None;
        row.tool = r.tool;
        row.id = None;
        row.tip = Vector3::new(r.get(Axis::X), r.get(Axis::Y), r.get(Axis::Z));
        // The program's angles as it states them (the controller of a tool-centre program
        // moves them), else its axis.
        row.orientation = match angles {
            Some((phi1, phi2)) => ToolOrientation::Angles(ToolAngles { phi1, phi2 }),
            None => ToolOrientation::Axis(axis),
        };
        row.stated_angles = angles;
        row.invalid = None;
        row.cells.clear();
        row.fraction = None;
        Ok(true)
    }

    fn report(&self) -> ReaderReport {
        ReaderReport::Gcode(self.reader.summary().clone())
    }
}
