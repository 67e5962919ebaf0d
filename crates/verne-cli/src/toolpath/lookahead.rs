//! A toolpath read ahead and replayed: the rows a decision needs are read once, kept, and then
//! handed on in order, so that an input is never opened or read twice (a pipe cannot be).

use std::collections::VecDeque;

use nalgebra::Vector3;
use verne::machine::orientation::ToolOrientation;

use super::{Column, PoseRow, ReaderReport, ToolpathSource};
use crate::error::VerneError;

/// Most rows read ahead.
pub const MAX_LOOKAHEAD_ROWS: usize = 100_000;

/// A toolpath whose first rows were read ahead.
pub struct Lookahead<S> {
    inner: S,
    buffered: VecDeque<PoseRow>,
    /// The error that ended the look-ahead, returned when the replay reaches it.
    error: Option<VerneError>,
}

impl<S: ToolpathSource> Lookahead<S> {
    /// Reads ahead from `inner` while `decide` consumes the poses (tip plus `offset`, and
    /// orientation) of its rows, up to the first row that is not usable (an invalid cell), a
    /// reader's error or [`MAX_LOOKAHEAD_ROWS`]; returns the decision and the toolpath, which
    /// replays every row read.
    pub fn read<T>(
        mut inner: S,
        offset: Vector3<f64>,
        decide: impl FnOnce(&mut dyn Iterator<Item = (Vector3<f64>, ToolOrientation)>) -> T,
    ) -> (T, Lookahead<S>) {
        let mut buffered = VecDeque::new();
        let mut error = None;
        let decision = decide(&mut std::iter::from_fn(|| {
            if buffered.len() >= MAX_LOOKAHEAD_ROWS || error.is_some() {
                return None;
            }
            let mut row = PoseRow::default();
            match inner.next_row(&mut row) {
                Ok(true) => {
                    let pose = row
                        .invalid
                        .is_none()
                        .then_some((row.tip + offset, row.orientation));
                    buffered.push_back(row);
                    pose
                }
                Ok(false) => None,
                Err(e) => {
                    error = Some(e);
                    None
                }
            }
        }));
        (
            decision,
            Lookahead {
                inner,
                buffered,
                error,
            },
        )
    }
}

impl<S: ToolpathSource> ToolpathSource for Lookahead<S> {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn columns(&self) -> &[Column] {
        self.inner.columns()
    }

    fn states_angles(&self) -> bool {
        self.inner.states_angles()
    }

    fn next_row(&mut self, row: &mut PoseRow) -> Result<bool, VerneError> {
        if let Some(r) = self.buffered.pop_front() {
            *row = r;
            return Ok(true);
        }
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.inner.next_row(row)
    }

    fn report(&self) -> ReaderReport {
        self.inner.report()
    }
}
