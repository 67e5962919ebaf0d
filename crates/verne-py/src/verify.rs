//! `verne.verify`: a joint table checked against the intended tool poses, with the checks of
//! `verne verify` (the core's engine, the same findings and summary).

use numpy::PyReadonlyArray1;
use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use verne::verify::{
    Item, JointSource, Joints, PairingError, PathPoint, RowSource, Summary, Thresholds,
    VerifyOptions, Violation, verify as verify_rows,
};

use crate::five_axis::tips_and_axes;
use crate::machine::PyMachine;
use crate::rows;

/// The joint rows, in memory.
struct JointRows {
    rows: Vec<Joints>,
    next: usize,
    timed: bool,
}

impl RowSource for JointRows {
    type Row = Joints;
    type Error = PairingError;
    fn name(&self) -> &str {
        "joints"
    }
    fn has_id(&self) -> bool {
        false
    }
    fn next_item(&mut self) -> Result<Option<Item<Joints>>, PairingError> {
        Ok(next_item(&self.rows, &mut self.next, |q| {
            let finite = [q.rho.x, q.rho.y, q.rho.z, q.theta1, q.theta2]
                .iter()
                .all(|v| v.is_finite());
            match (finite, q.t, q.feed) {
                (false, ..) => Err("a joint value is not a finite number".to_string()),
                (true, Some(t), _) if !t.is_finite() => Err(format!("t = {t}: not a finite time")),
                (true, _, Some(f)) if !f.is_finite() => {
                    Err(format!("feed = {f}: not a finite feed"))
                }
                _ => Ok(*q),
            }
        }))
    }
}

impl JointSource for JointRows {
    fn timed(&self) -> bool {
        self.timed
    }
}

/// The intended tool poses, in memory.
struct PathRows {
    rows: Vec<PathPoint>,
    next: usize,
}

impl RowSource for PathRows {
    type Row = PathPoint;
    type Error = PairingError;
    fn name(&self) -> &str {
        "path"
    }
    fn has_id(&self) -> bool {
        false
    }
    fn next_item(&mut self) -> Result<Option<Item<PathPoint>>, PairingError> {
        Ok(next_item(&self.rows, &mut self.next, |p| {
            if p.tip.iter().chain(p.axis.iter()).all(|v| v.is_finite()) {
                Ok(*p)
            } else {
                Err("a tip or axis value is not a finite number".to_string())
            }
        }))
    }
}

/// Row `next` (1-based index and "line" = the row number), checked by `usable`.
fn next_item<T>(
    rows: &[T],
    next: &mut usize,
    usable: impl Fn(&T) -> Result<T, String>,
) -> Option<Item<T>> {
    let row = rows.get(*next)?;
    *next += 1;
    Some(Item {
        index: *next as u64,
        line: *next as u64,
        id: None,
        value: usable(row),
        tag: None,
    })
}

/// One finding as a dict: row (1-based, as a string like the CLI's report), check, value,
/// limit (NaN where the check has none), detail, severity (value over limit).
fn finding<'py>(py: Python<'py>, v: &Violation) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("row", &v.row)?;
    d.set_item("check", v.check.code())?;
    d.set_item("value", v.value)?;
    d.set_item("limit", v.limit)?;
    d.set_item("detail", &v.detail)?;
    d.set_item("severity", v.severity)?;
    Ok(d)
}

/// The summary as a dict: rows, segments, segments_skipped, timed, clean, and per check its
/// number of findings and worst finding (or, for a check that passed, its closest approach).
fn summary_dict<'py>(py: Python<'py>, s: &Summary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("rows", s.rows)?;
    d.set_item("segments", s.segments)?;
    d.set_item("segments_skipped", s.segments_skipped)?;
    d.set_item("timed", s.timed)?;
    d.set_item("clean", s.clean())?;
    let checks = PyDict::new(py);
    for (check, stats) in &s.checks {
        let c = PyDict::new(py);
        c.set_item("count", stats.count)?;
        match &stats.worst {
            Some(w) => c.set_item("worst", finding(py, w)?)?,
            None => c.set_item("worst", py.None())?,
        }
        checks.set_item(check.code(), c)?;
    }
    d.set_item("checks", checks)?;
    Ok(d)
}

/// Checks a joint table against the intended tool poses, as `verne verify --joints J --path P`
/// (rows paired in order): tip and axis of fk(joints), branch, joint limits, singularities,
/// chordal error and joint jumps between rows, theta2 flips, and with `t` (s) or `feed`
/// (mm/min) per row the joint velocities and accelerations.
///
/// `joints[N, 5]` = (rho1, rho2, rho3 in mm, theta1, theta2 in rad), `tips[N, 3]` (mm) and
/// `axes[N, 3]` (tip towards spindle) in the workpiece frame. `thresholds` overrides the
/// machine file's `[verify]` values by name (`{"tip_error_mm": 0.001}`; the names and units of
/// `verne verify --help`). Returns `(findings, summary)`: a list of dicts (row, check, value,
/// limit, detail, severity; values in the threshold's unit) in row order, and the summary dict
/// (`summary["clean"]` True when no check failed). A row with NaN is an `input` finding.
///
/// >>> tips = np.array([[80.0, 0.0, 30.0], [80.0, 5.0, 30.0]])
/// >>> axes = np.array([[0.342020, 0.0, 0.939693]] * 2)
/// >>> joints, _, _ = verne.ik_path(m, tips, axes)
/// >>> findings, summary = verne.verify(m, joints, tips, axes)
/// >>> findings, summary["clean"]
/// ([], True)
/// >>> joints[1, 0] += 0.5                       # slider 1 of row 2 off by 0.5 mm
/// >>> [(f["row"], f["check"]) for f in verne.verify(m, joints, tips, axes)[0]][:1]
/// [('2', 'tip_error')]
#[pyfunction]
#[pyo3(signature = (machine, joints, tips, axes, t=None, feed=None, thresholds=None, tool_length=None))]
#[allow(clippy::too_many_arguments)]
fn verify<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    joints: PyReadonlyArray2<'py, f64>,
    tips: PyReadonlyArray2<'py, f64>,
    axes: PyReadonlyArray2<'py, f64>,
    t: Option<PyReadonlyArray1<'py, f64>>,
    feed: Option<PyReadonlyArray1<'py, f64>>,
    thresholds: Option<&Bound<'py, PyDict>>,
    tool_length: Option<f64>,
) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyDict>)> {
    let m = &machine.inner;
    let q = rows::<5>(&joints, "joints")?;
    let (tip_rows, axis_rows) = tips_and_axes(&tips, &axes)?;
    if q.len() != tip_rows.len() {
        return Err(PyValueError::new_err(format!(
            "joints and tips: {} and {} rows; expected one intended pose per joint row",
            q.len(),
            tip_rows.len()
        )));
    }
    let column =
        |c: &Option<PyReadonlyArray1<'py, f64>>, what: &str| -> PyResult<Option<Vec<f64>>> {
            match c {
                None => Ok(None),
                Some(a) if a.len()? == q.len() => Ok(Some(a.as_array().to_vec())),
                Some(a) => Err(PyValueError::new_err(format!(
                    "{what}: {} values for {} joint rows; expected one per row",
                    a.len()?,
                    q.len()
                ))),
            }
        };
    let (t, feed) = (column(&t, "t")?, column(&feed, "feed")?);
    if t.is_some() && feed.is_some() {
        return Err(PyValueError::new_err(
            "t and feed: give one of them (the time of each row, or the feed of the move to it)",
        ));
    }
    let mut limits = Thresholds::from_machine(m, &m.name).map_err(crate::machine::machine_error)?;
    if let Some(d) = thresholds {
        for (k, v) in d.iter() {
            let name: String = k.extract()?;
            let value: f64 = v.extract().map_err(|_| {
                PyValueError::new_err(format!("thresholds[{name:?}]: expected a number"))
            })?;
            limits
                .set(&name, value)
                .map_err(|e| PyValueError::new_err(format!("thresholds[{name:?}]: {e}")))?;
        }
    }
    limits
        .check()
        .map_err(|e| PyValueError::new_err(format!("thresholds: {e}")))?;
    let mut joint_rows = JointRows {
        rows: q
            .iter()
            .enumerate()
            .map(|(i, j)| Joints {
                rho: nalgebra::Vector3::new(j[0], j[1], j[2]),
                theta1: j[3],
                theta2: j[4],
                t: t.as_ref().map(|t| t[i]),
                // The joint table's feed column is mm/min; the core's is mm/s.
                feed: feed.as_ref().map(|f| f[i] / 60.0),
                duration: None,
                rapid: false,
            })
            .collect(),
        next: 0,
        timed: t.is_some() || feed.is_some(),
    };
    let mut path_rows = PathRows {
        rows: tip_rows
            .iter()
            .zip(&axis_rows)
            .map(|(tip, axis)| PathPoint::new((*tip).into(), (*axis).into()))
            .collect(),
        next: 0,
    };
    let opt = VerifyOptions {
        thresholds: limits,
        tool_length: tool_length.unwrap_or(m.tool_length),
    };
    let (found, summary) = py.allow_threads(|| {
        let mut found = Vec::new();
        let summary = verify_rows(m, &opt, &mut joint_rows, &mut path_rows, &mut |v| {
            found.push(v.clone());
            Ok::<(), PairingError>(())
        });
        (found, summary)
    });
    // Equal row counts are checked above: pairing in order cannot fail.
    let summary = summary.map_err(|e| PyValueError::new_err(e.to_string()))?;
    let list = PyList::empty(py);
    for v in &found {
        list.append(finding(py, v)?)?;
    }
    Ok((list, summary_dict(py, &summary)?))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(verify, m)?)?;
    Ok(())
}
