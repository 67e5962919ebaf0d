//! The 5-axis machine (AIM 2007): the path follower of `verne ik`, every branch of a tool
//! pose, and the forward kinematics.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use verne::machine::fk::MAX_MACHINE_FK_MODES;
use verne::machine::ik::MAX_MACHINE_IK_BRANCHES;
use verne::machine::orientation::ToolOrientation;
use verne::machine::{FirstRowChoice, PathError, machine_fk, path_candidates};
use verne::parallel_module::equations::Sliders;

use crate::machine::PyMachine;
use crate::{INVALID_INPUT, NO_WORKING_BRANCH, OK, UNREACHABLE, rows};

/// `ik_path`'s result: joints, orientation, status.
type PathJoints<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i8>>,
    Bound<'py, PyArray1<i8>>,
);

/// `machine_fk_working`'s result: tips, axes, status.
type ToolPoses<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i8>>,
);

/// The 5-axis machine along a toolpath, as `verne ik` follows it: for each row the tool tip
/// (mm) and tool axis (tip towards spindle, workpiece frame), the working branch nearest the
/// previous row over both orientation solutions, theta2 unwrapped.
///
/// `prefer` chooses on the first row: "smallest-theta1" (default), "orientation1",
/// "orientation2". Returns `(joints, orientation, status)`: `joints[N, 5]` = (rho1, rho2, rho3
/// in mm, theta1, theta2 in rad), NaN where the row has none; `orientation[N]` 1 or 2 (0 where
/// none); `status[N]` 0 ok, 1 unreachable (no real branch, proved), 2 no working branch (real
/// branches exist, none within the limits, or the list is not proved complete), 3 invalid
/// input (NaN, zero axis).
///
/// >>> tips = np.array([[80.0, 0.0, 30.0], [80.0, 5.0, 30.0]])
/// >>> axes = np.array([[0.342020, 0.0, 0.939693]] * 2)
/// >>> joints, orientation, status = verne.ik_path(m, tips, axes)
/// >>> joints[0].round(3).tolist(), status.tolist()
/// ([367.636, 320.864, 307.56, -0.355, -1.571], [0, 0])
#[pyfunction]
#[pyo3(signature = (machine, tips, axes, tool_length=None, prefer="smallest-theta1"))]
fn ik_path<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    tips: PyReadonlyArray2<'py, f64>,
    axes: PyReadonlyArray2<'py, f64>,
    tool_length: Option<f64>,
    prefer: &str,
) -> PyResult<PathJoints<'py>> {
    let (t, a) = tips_and_axes(&tips, &axes)?;
    let first = match prefer {
        "smallest-theta1" => FirstRowChoice::SmallestTheta1,
        "orientation1" => FirstRowChoice::Orientation1,
        "orientation2" => FirstRowChoice::Orientation2,
        other => {
            return Err(PyValueError::new_err(format!(
                "prefer={other:?}: expected \"smallest-theta1\", \"orientation1\" or \"orientation2\""
            )));
        }
    };
    let base = &machine.inner;
    let machine = base.with_tool_length(tool_length.unwrap_or(base.tool_length));
    let n = t.len();
    let (joints, orientation, status) = py.allow_threads(|| {
        let mut joints = Array2::<f64>::from_elem((n, 5), f64::NAN);
        let mut orientation = Array1::<i8>::zeros(n);
        let mut status = Array1::<i8>::zeros(n);
        let Some(m) = machine else {
            // A tool length that is not finite or is negative: no row can be solved.
            status.fill(INVALID_INPUT);
            return (joints, orientation, status);
        };
        let poses: Vec<_> = (0..n)
            .map(|i| {
                (
                    nalgebra::Vector3::from(t[i]),
                    ToolOrientation::Axis(nalgebra::Vector3::from(a[i])),
                )
            })
            .collect();
        // The path follower of `verne ik`, look-ahead at a vertical start included.
        for (i, row) in m.follow_path(&poses, first).into_iter().enumerate() {
            if !t[i].iter().chain(&a[i]).all(|v| v.is_finite()) {
                status[i] = INVALID_INPUT;
                continue;
            }
            match row {
                Ok(row) => {
                    for (j, v) in [row.rho.x, row.rho.y, row.rho.z, row.theta1, row.theta2]
                        .into_iter()
                        .enumerate()
                    {
                        joints[[i, j]] = v;
                    }
                    orientation[i] = row.orientation as i8;
                    status[i] = OK;
                }
                Err(PathError::Axis(_)) => status[i] = INVALID_INPUT,
                Err(PathError::NoWorkingBranch {
                    real_branches: 0,
                    proved: true,
                    ..
                }) => status[i] = UNREACHABLE,
                Err(_) => status[i] = NO_WORKING_BRANCH,
            }
        }
        (joints, orientation, status)
    });
    Ok((
        joints.into_pyarray(py),
        orientation.into_pyarray(py),
        status.into_pyarray(py),
    ))
}

/// The 5-axis machine's forward kinematics (AIM 2007) on its working assembly mode, for each
/// row of joints (rho1, rho2, rho3 in mm, theta1, theta2 in rad).
///
/// Returns `(tips, axes, status)`: `tips[N, 3]` the tool tip (mm) and `axes[N, 3]` the tool
/// axis in the workpiece frame, NaN where the row has no working mode; `status[N]` as in
/// `ik_path`.
///
/// >>> tips, axes, status = verne.machine_fk_working(m, np.array([[367.636, 320.864, 307.560, -0.355, -1.5708]]))
/// >>> tips.round(1).tolist(), status.tolist()
/// ([[80.0, 0.0, 30.0]], [0])
#[pyfunction]
#[pyo3(signature = (machine, joints, tool_length=None))]
fn machine_fk_working<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    joints: PyReadonlyArray2<'py, f64>,
    tool_length: Option<f64>,
) -> PyResult<ToolPoses<'py>> {
    let q = rows::<5>(&joints, "joints")?;
    let m = &machine.inner;
    let length = tool_length.unwrap_or(m.tool_length);
    type Row = (Option<([f64; 3], [f64; 3])>, i8);
    let solved: Vec<Row> = py.allow_threads(|| {
        q.par_iter()
            .map(|j| {
                if !j.iter().all(|v| v.is_finite()) {
                    return (None, INVALID_INPUT);
                }
                let modes = machine_fk(m, &Sliders::new(j[0], j[1], j[2]), j[3], j[4], length);
                match modes.iter().find(|md| md.working()) {
                    Some(md) => {
                        let (t, a) = (md.tool.tip, md.axis);
                        (Some(([t.x, t.y, t.z], [a.x, a.y, a.z])), OK)
                    }
                    None if modes.is_empty() && modes.certificate.proved() => (None, UNREACHABLE),
                    None => (None, NO_WORKING_BRANCH),
                }
            })
            .collect()
    });
    let n = q.len();
    let mut tips = Array2::<f64>::from_elem((n, 3), f64::NAN);
    let mut axes = Array2::<f64>::from_elem((n, 3), f64::NAN);
    let mut status = Array1::<i8>::zeros(n);
    for (i, (pose, st)) in solved.into_iter().enumerate() {
        status[i] = st;
        if let Some((t, a)) = pose {
            for j in 0..3 {
                tips[[i, j]] = t[j];
                axes[[i, j]] = a[j];
            }
        }
    }
    Ok((
        tips.into_pyarray(py),
        axes.into_pyarray(py),
        status.into_pyarray(py),
    ))
}

/// `machine_ik`'s result: joints, orientation, config, working, count, proved.
type MachineBranches<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray2<i8>>,
    Bound<'py, PyArray3<i8>>,
    Bound<'py, PyArray2<bool>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<bool>>,
);

/// Branches over both orientation solutions.
const MAX_POSE_BRANCHES: usize = 2 * MAX_MACHINE_IK_BRANCHES;

/// One real branch of a tool pose: joints, orientation solution, configuration, working.
type PoseBranch = ([f64; 5], i8, [i8; 3], bool);

/// Every real branch of the 5-axis machine's inverse kinematics (AIM 2007) for each tool pose,
/// over both orientation solutions of the axis (as `verne ik --all` and `verne modes --tool`;
/// inside the rotary-singularity cone theta2 = 0).
///
/// Returns `(joints, orientation, config, working, count, proved)`: `joints[N, 48, 5]` = (rho1,
/// rho2, rho3 in mm, theta1, theta2 in rad, theta2 in (-pi, pi]), NaN past `count[i]`;
/// `orientation[N, 48]` 1 or 2; `config[N, 48, 3]` the parallel module's configuration indices;
/// `working[N, 48]` whether the machine can be in that branch; `proved[N]` whether the list is
/// certified complete (False for an invalid row: NaN, zero axis).
///
/// >>> q, orientation, config, working, count, proved = verne.machine_ik(m, np.array([[80.0, 0.0, 30.0]]), np.array([[0.342020, 0.0, 0.939693]]))
/// >>> int(count[0]), int(working[0].sum()), sorted(set(orientation[0, :32].tolist()))
/// (32, 2, [1, 2])
#[pyfunction]
#[pyo3(signature = (machine, tips, axes, tool_length=None))]
fn machine_ik<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    tips: PyReadonlyArray2<'py, f64>,
    axes: PyReadonlyArray2<'py, f64>,
    tool_length: Option<f64>,
) -> PyResult<MachineBranches<'py>> {
    let (t, a) = tips_and_axes(&tips, &axes)?;
    let m = &machine.inner;
    let length = tool_length.unwrap_or(m.tool_length);
    let solved: Vec<(Vec<PoseBranch>, bool)> = py.allow_threads(|| {
        t.par_iter()
            .zip(&a)
            .map(|(tip, axis)| {
                if !(tip.iter().chain(axis).all(|v| v.is_finite()) && length.is_finite()) {
                    return (Vec::new(), false);
                }
                let orientation = ToolOrientation::Axis(nalgebra::Vector3::from(*axis));
                match path_candidates(
                    m,
                    &nalgebra::Vector3::from(*tip),
                    &orientation,
                    length,
                    None,
                ) {
                    Ok(c) => (
                        c.iter()
                            .map(|(b, o, theta2)| {
                                (
                                    [b.rho.x, b.rho.y, b.rho.z, b.theta1, theta2],
                                    o as i8,
                                    b.config,
                                    b.working(),
                                )
                            })
                            .collect(),
                        c.certificate.proved(),
                    ),
                    Err(_) => (Vec::new(), false),
                }
            })
            .collect()
    });
    let n = solved.len();
    let k = MAX_POSE_BRANCHES;
    let mut joints = Array3::<f64>::from_elem((n, k, 5), f64::NAN);
    let mut orientation = Array2::<i8>::zeros((n, k));
    let mut config = Array3::<i8>::zeros((n, k, 3));
    let mut working = Array2::<bool>::from_elem((n, k), false);
    let (count, proved) = spread(solved, |i, slot, (q, o, c, w): PoseBranch| {
        for j in 0..5 {
            joints[[i, slot, j]] = q[j];
        }
        for j in 0..3 {
            config[[i, slot, j]] = c[j];
        }
        orientation[[i, slot]] = o;
        working[[i, slot]] = w;
    });
    Ok((
        joints.into_pyarray(py),
        orientation.into_pyarray(py),
        config.into_pyarray(py),
        working.into_pyarray(py),
        count.into_pyarray(py),
        proved.into_pyarray(py),
    ))
}

/// `machine_fk`'s result: tips, axes, config, working, count, proved.
type MachineModes<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<i8>>,
    Bound<'py, PyArray2<bool>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<bool>>,
);

/// One assembly mode of a joint row: tip, axis, configuration, working.
type ToolMode = ([f64; 3], [f64; 3], [i8; 3], bool);

/// Every real assembly mode of the 5-axis machine's forward kinematics (AIM 2007) for each row
/// of joints (rho1, rho2, rho3 in mm, theta1, theta2 in rad), as `verne fk --all`.
///
/// Returns `(tips, axes, config, working, count, proved)`: `tips[N, 16, 3]` the tool tip (mm)
/// and `axes[N, 16, 3]` the tool axis in the workpiece frame, NaN past `count[i]`; the rest as
/// in `machine_ik`. `machine_fk_working` gives the working mode alone.
///
/// >>> tips, axes, config, working, count, proved = verne.machine_fk(m, np.array([[500.0, 600.0, 400.0, 0.2, 0.3]]))
/// >>> int(count[0]), int(working[0].sum()), bool(proved[0])
/// (4, 1, True)
#[pyfunction(name = "machine_fk")]
#[pyo3(signature = (machine, joints, tool_length=None))]
fn machine_fk_all<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    joints: PyReadonlyArray2<'py, f64>,
    tool_length: Option<f64>,
) -> PyResult<MachineModes<'py>> {
    let q = rows::<5>(&joints, "joints")?;
    let m = &machine.inner;
    let length = tool_length.unwrap_or(m.tool_length);
    let solved: Vec<(Vec<ToolMode>, bool)> = py.allow_threads(|| {
        q.par_iter()
            .map(|j| {
                if !(j.iter().all(|v| v.is_finite()) && length.is_finite()) {
                    return (Vec::new(), false);
                }
                let modes = machine_fk(m, &Sliders::new(j[0], j[1], j[2]), j[3], j[4], length);
                let list = modes
                    .iter()
                    .map(|md| {
                        let (t, a) = (md.tool.tip, md.axis);
                        ([t.x, t.y, t.z], [a.x, a.y, a.z], md.config, md.working())
                    })
                    .collect();
                (list, modes.certificate.proved())
            })
            .collect()
    });
    let n = solved.len();
    let k = MAX_MACHINE_FK_MODES;
    let mut tips = Array3::<f64>::from_elem((n, k, 3), f64::NAN);
    let mut axes = Array3::<f64>::from_elem((n, k, 3), f64::NAN);
    let mut config = Array3::<i8>::zeros((n, k, 3));
    let mut working = Array2::<bool>::from_elem((n, k), false);
    let (count, proved) = spread(solved, |i, slot, (t, a, c, w): ToolMode| {
        for j in 0..3 {
            tips[[i, slot, j]] = t[j];
            axes[[i, slot, j]] = a[j];
            config[[i, slot, j]] = c[j];
        }
        working[[i, slot]] = w;
    });
    Ok((
        tips.into_pyarray(py),
        axes.into_pyarray(py),
        config.into_pyarray(py),
        working.into_pyarray(py),
        count.into_pyarray(py),
        proved.into_pyarray(py),
    ))
}

/// Tool tips and axes, row by row.
type TipsAndAxes = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// The rows of `tips[N, 3]` and `axes[N, 3]`, one axis per tip.
pub(crate) fn tips_and_axes(
    tips: &PyReadonlyArray2<'_, f64>,
    axes: &PyReadonlyArray2<'_, f64>,
) -> PyResult<TipsAndAxes> {
    let t = rows::<3>(tips, "tips")?;
    let a = rows::<3>(axes, "axes")?;
    if t.len() != a.len() {
        return Err(PyValueError::new_err(format!(
            "tips and axes: {} and {} rows; expected one axis per tip",
            t.len(),
            a.len()
        )));
    }
    Ok((t, a))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(ik_path, m)?)?;
    m.add_function(wrap_pyfunction!(machine_fk_working, m)?)?;
    m.add_function(wrap_pyfunction!(machine_ik, m)?)?;
    m.add_function(wrap_pyfunction!(machine_fk_all, m)?)?;
    Ok(())
}

/// Each row's solutions written into padded arrays by `write(row, slot, solution)`; returns
/// the rows' counts and certificates.
fn spread<T>(
    rows: Vec<(Vec<T>, bool)>,
    mut write: impl FnMut(usize, usize, T),
) -> (Array1<i64>, Array1<bool>) {
    let mut count = Array1::<i64>::zeros(rows.len());
    let mut proved = Array1::<bool>::from_elem(rows.len(), false);
    for (i, (solutions, p)) in rows.into_iter().enumerate() {
        count[i] = solutions.len() as i64;
        proved[i] = p;
        for (slot, solution) in solutions.into_iter().enumerate() {
            write(i, slot, solution);
        }
    }
    (count, proved)
}
