//! Kinetostatics of the parallel module: the Jacobians of constraints (3)-(6) (IFToMM 2007),
//! A dX + B drho = 0, and the measures `verne workspace` and `verne verify` bound.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use verne::parallel_module::equations::{ModulePose, Sliders, jacobian_pose, jacobian_sliders};
use verne::parallel_module::kinetostatics::{Kinetostatics, kinetostatics as measures};

use crate::machine::PyMachine;
use crate::rows;

/// The rows of `poses[N, 4]` and `sliders[N, 3]`, one slider triple per pose.
fn poses_and_sliders(
    poses: &PyReadonlyArray2<'_, f64>,
    sliders: &PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<(ModulePose, Sliders)>> {
    let p = rows::<4>(poses, "poses")?;
    let s = rows::<3>(sliders, "sliders")?;
    if p.len() != s.len() {
        return Err(PyValueError::new_err(format!(
            "poses and sliders: {} and {} rows; expected one slider triple per pose",
            p.len(),
            s.len()
        )));
    }
    Ok(p.iter()
        .zip(&s)
        .map(|(p, s)| {
            (
                ModulePose {
                    p: nalgebra::Vector3::new(p[0], p[1], p[2]),
                    alpha: p[3],
                },
                Sliders::from(*s),
            )
        })
        .collect())
}

/// The Jacobians of the parallel module's constraints (3)-(6) at each configuration:
/// `poses[N, 4]` = (xp, yp, zp in mm, alpha in rad) with its `sliders[N, 3]` (mm), a branch of
/// `module_ik` or a mode of `module_fk`. Returns `(A[N, 4, 4], B[N, 4, 3])` with
/// A dX + B drho = 0, X = (xp, yp, zp, alpha), unscaled (each row is d/dX of one constraint).
///
/// >>> P = np.array([[-240.0, -86.0, 1000.0]])
/// >>> s, alpha, _ = verne.module_ik_working(m, P)
/// >>> A, B = verne.jacobian(m, np.c_[P, alpha], s)
/// >>> A.shape, B.shape
/// ((1, 4, 4), (1, 4, 3))
#[pyfunction]
fn jacobian<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    poses: PyReadonlyArray2<'py, f64>,
    sliders: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let rows = poses_and_sliders(&poses, &sliders)?;
    let g = &machine.inner.module;
    let n = rows.len();
    let (a, b) = py.allow_threads(|| {
        let mut a = Array3::<f64>::zeros((n, 4, 4));
        let mut b = Array3::<f64>::zeros((n, 4, 3));
        for (i, (pose, rho)) in rows.iter().enumerate() {
            let ja = jacobian_pose(g, pose, rho);
            let jb = jacobian_sliders(g, pose, rho);
            for r in 0..4 {
                for c in 0..4 {
                    a[[i, r, c]] = ja[(r, c)];
                }
                for c in 0..3 {
                    b[[i, r, c]] = jb[(r, c)];
                }
            }
        }
        (a, b)
    });
    pyo3::types::PyTuple::new(
        py,
        [a.into_pyarray(py).into_any(), b.into_pyarray(py).into_any()],
    )
}

/// Kinetostatic measures of each configuration (`poses[N, 4]`, `sliders[N, 3]`, as
/// `jacobian`), the ones `verne verify` and `verne workspace` bound. Returns a dict of arrays:
/// `det_a[N]` (det A, rows scaled by 1 / 2 L_i, mm; 0 at a parallel singularity),
/// `parallel_margin[N]` (inverse condition number of the dimensionless A, 0..1),
/// `serial_margin[N]` (smallest |cos| between a rod and its slider, 0 at a serial
/// singularity), `amplification[N, 3]` (velocity amplification factors, largest first, inf at
/// a parallel singularity), `rotation_rate[N, 3]` (d alpha / d rho, rad/mm).
///
/// >>> P = np.array([[-240.0, -86.0, 1000.0]])
/// >>> s, alpha, _ = verne.module_ik_working(m, P)
/// >>> verne.kinetostatics(m, np.c_[P, alpha], s)["amplification"].round(3).tolist()
/// [[1.45, 1.286, 0.545]]
#[pyfunction]
fn kinetostatics<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    poses: PyReadonlyArray2<'py, f64>,
    sliders: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let rows = poses_and_sliders(&poses, &sliders)?;
    let g = &machine.inner.module;
    let k: Vec<Kinetostatics> = py.allow_threads(|| {
        rows.par_iter()
            .map(|(pose, rho)| measures(g, pose, rho))
            .collect()
    });
    let n = k.len();
    let column = |f: &dyn Fn(&Kinetostatics) -> f64| Array1::from_iter(k.iter().map(f));
    let mut amplification = Array2::<f64>::zeros((n, 3));
    let mut rotation_rate = Array2::<f64>::zeros((n, 3));
    for (i, x) in k.iter().enumerate() {
        for j in 0..3 {
            amplification[[i, j]] = x.amplification[j];
            rotation_rate[[i, j]] = x.rotation_rate[j];
        }
    }
    let d = PyDict::new(py);
    d.set_item("det_a", column(&|x| x.det_a).into_pyarray(py))?;
    d.set_item(
        "parallel_margin",
        column(&|x| x.parallel_margin).into_pyarray(py),
    )?;
    d.set_item(
        "serial_margin",
        column(&|x| x.serial_margin).into_pyarray(py),
    )?;
    d.set_item("amplification", amplification.into_pyarray(py))?;
    d.set_item("rotation_rate", rotation_rate.into_pyarray(py))?;
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(kinetostatics, m)?)?;
    Ok(())
}
