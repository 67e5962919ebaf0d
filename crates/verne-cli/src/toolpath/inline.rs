//! Tool poses given on the command line (`verne ik --tool X,Y,Z,I,J,K`, repeatable: the rows
//! of one path), as typed rows in the columns `x,y,z,i,j,k`.

use nalgebra::Vector3;
use verne::machine::orientation::ToolOrientation;

use super::{Column, Field, PoseRow, ToolpathSource};
use crate::error::VerneError;

/// The name of the rows given on the command line (`--pose`, `--tool`, `--joints`, ...).
pub const INLINE_SOURCE: &str = "<command line>";

/// Tool poses from the command line; each row's line is its place among them (1-based).
pub struct InlineToolpath {
    poses: Vec<[f64; 6]>,
    next: usize,
    columns: Vec<Column>,
}

impl InlineToolpath {
    pub fn new(poses: &[[f64; 6]]) -> InlineToolpath {
        InlineToolpath {
            poses: poses.to_vec(),
            next: 0,
            columns: Column::typed_all(&[
                Field::X,
                Field::Y,
                Field::Z,
                Field::I,
                Field::J,
                Field::K,
            ]),
        }
    }
}

impl ToolpathSource for InlineToolpath {
    fn name(&self) -> &str {
        INLINE_SOURCE
    }

    fn columns(&self) -> &[Column] {
        &self.columns
    }

    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError> {
        let Some(p) = self.poses.get(self.next) else {
            return Ok(false);
        };
        self.next += 1;
        *row = PoseRow {
            line: self.next as u64,
            tip: Vector3::new(p[0], p[1], p[2]),
            orientation: ToolOrientation::Axis(Vector3::new(p[3], p[4], p[5])),
            invalid: (!p.iter().all(|v| v.is_finite()))
                .then(|| "a value is not finite".to_string()),
            cells: std::mem::take(&mut row.cells),
            ..PoseRow::default()
        };
        row.cells.clear();
        Ok(true)
    }
}
