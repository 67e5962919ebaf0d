//! Python bindings of the verne kinematics core (`import verne`): NumPy arrays in, NumPy arrays
//! out, lengths in mm and angles in radians. Every real branch of the parallel module's inverse
//! and forward kinematics (IFToMM 2007), the 5-axis machine's path follower and forward
//! kinematics (AIM 2007), with the completeness certificate of each row. Long calls release
//! the GIL and run on the core's threads. Bad shapes raise `ValueError`; a row that cannot be
//! solved (NaN input, unreachable) is an answer in its status, never an exception.

use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

mod five_axis;
mod glider;
mod kinetostatics;
mod machine;
mod module;
mod verify;
mod workspace;

/// The rows of an `[N, cols]` float64 array, or a `ValueError` naming the expected shape.
pub(crate) fn rows<const C: usize>(
    a: &PyReadonlyArray2<f64>,
    what: &str,
) -> PyResult<Vec<[f64; C]>> {
    let v = a.as_array();
    if v.ncols() != C {
        return Err(PyValueError::new_err(format!(
            "{what}: expected an array of shape (N, {C}), found {:?}",
            v.shape()
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

/// Rows per parallel chunk.
pub(crate) const CHUNK: usize = 4096;

/// Status codes of `ik_path` and `machine_fk` rows.
pub(crate) const OK: i8 = 0;
pub(crate) const UNREACHABLE: i8 = 1;
pub(crate) const NO_WORKING_BRANCH: i8 = 2;
pub(crate) const INVALID_INPUT: i8 = 3;

/// The native module; `verne/__init__.py` re-exports it.
#[pymodule]
fn _verne(m: &Bound<'_, PyModule>) -> PyResult<()> {
    machine::register(m)?;
    module::register(m)?;
    five_axis::register(m)?;
    kinetostatics::register(m)?;
    verify::register(m)?;
    workspace::register(m)?;
    glider::register(m)?;
    m.add("OK", OK)?;
    m.add("UNREACHABLE", UNREACHABLE)?;
    m.add("NO_WORKING_BRANCH", NO_WORKING_BRANCH)?;
    m.add("INVALID_INPUT", INVALID_INPUT)?;
    Ok(())
}
