//! `verne.workspace`: the machine's workspaces (AIM 2007, section IV), uniform or adaptive, as
//! `verne workspace` computes them.

use numpy::IntoPyArray;
use numpy::ndarray::{Array1, Array2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use verne::workspace::{
    self as ws, Bounds, DEFAULT_COARSE_FACTOR, Of, Outcome, PAPER_LAMBDA_BOUNDS, WorkspaceOptions,
};

use crate::machine::PyMachine;

/// Below this step (mm) a workspace is sampled adaptively unless told otherwise (as the CLI).
const ADAPTIVE_BELOW_MM: f64 = 5.0;

/// The outcome codes of a grid point, in the order of `verne.OUTCOMES`.
pub(crate) fn outcome_codes() -> Vec<&'static str> {
    Outcome::ALL.iter().map(|o| o.code()).collect()
}

fn bounds_tuple(b: &Bounds) -> ([f64; 3], [f64; 3]) {
    (b.min.into(), b.max.into())
}

fn counts<'py>(
    py: Python<'py>,
    codes: impl Iterator<Item = &'static str>,
    n: &[u64],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (code, count) in codes.zip(n) {
        d.set_item(code, count)?;
    }
    Ok(d)
}

/// The workspace of the platform point P (`of="platform"`), of the tool tip (`"tool"`) or of
/// the tool tip in the table frame with the tool perpendicular to the part
/// (`"manufacturing"`), sampled on a grid of `step` mm inside `bounds` ((xmin, xmax, ymin,
/// ymax, zmin, zmax), default: a box proved to contain it), with the amplification factors
/// bounded by `lambda_bounds`, as `verne workspace`.
///
/// `adaptive` (default: below 5 mm) classifies a coarse lattice and refines only the cells the
/// boundary crosses: the volume with a bracket `volume_lo_mm3 .. volume_hi_mm3` for the
/// cost of the boundary, and from one pseudo-random point in each of about 200,000 boundary
/// cells `volume_sampled_mm3` +- `sampled_half_width_mm3` (99.7 % confidence). Uniform sampling gives every point: `points=True` adds
/// `grid_points[N, 3]` (mm) and `outcome[N]` (int8, index into `verne.OUTCOMES`, x fastest).
/// Returns a dict: the volume, its error, the bounding box, the largest box and cube (adaptive:
/// found on the fine lattice, with `upper_bound_mm3`, a volume none of it exceeds; `box_exact`
/// when the box of the inside points was small enough to search exhaustively, the bound then
/// the volume), the points per outcome and per failed constraint.
///
/// >>> w = verne.workspace(m, step=40)
/// >>> w["method"], w["inside"], round(w["volume_litres"], 1)
/// ('uniform', 7061, 451.9)
#[pyfunction]
#[pyo3(signature = (machine, of="platform", step=10.0, tool_length=None, bounds=None, lambda_bounds=None, adaptive=None, points=false))]
#[allow(clippy::too_many_arguments)]
fn workspace<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    of: &str,
    step: f64,
    tool_length: Option<f64>,
    bounds: Option<[f64; 6]>,
    lambda_bounds: Option<(f64, f64)>,
    adaptive: Option<bool>,
    points: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &machine.inner;
    let of = match of {
        "platform" => Of::Platform,
        "tool" => Of::Tool,
        "manufacturing" => Of::Manufacturing,
        other => {
            return Err(PyValueError::new_err(format!(
                "of={other:?}: expected \"platform\", \"tool\" or \"manufacturing\""
            )));
        }
    };
    if !(step.is_finite() && step > 0.0) {
        return Err(PyValueError::new_err(format!(
            "step={step}: expected a positive grid step (mm)"
        )));
    }
    let lambda = lambda_bounds.map_or(PAPER_LAMBDA_BOUNDS, |(lo, hi)| [lo, hi]);
    if !(lambda[0].is_finite() && lambda[1].is_finite() && 0.0 < lambda[0] && lambda[0] < lambda[1])
    {
        return Err(PyValueError::new_err(format!(
            "lambda_bounds={:?}: expected 0 < lo < hi",
            (lambda[0], lambda[1])
        )));
    }
    let bounds = match bounds {
        None => None,
        Some(b) if b.iter().all(|v| v.is_finite()) && b[0] < b[1] && b[2] < b[3] && b[4] < b[5] => {
            Some(Bounds {
                min: nalgebra::Vector3::new(b[0], b[2], b[4]),
                max: nalgebra::Vector3::new(b[1], b[3], b[5]),
            })
        }
        Some(b) => {
            return Err(PyValueError::new_err(format!(
                "bounds={b:?}: expected (xmin, xmax, ymin, ymax, zmin, zmax) with min < max"
            )));
        }
    };
    let opts = WorkspaceOptions {
        of,
        tool_length: tool_length.unwrap_or(m.tool_length),
        step,
        bounds,
        lambda,
    };
    let adaptive = adaptive.unwrap_or(step < ADAPTIVE_BELOW_MM);
    let d = PyDict::new(py);
    d.set_item("of", of.name())?;
    d.set_item("frame", of.frame())?;
    d.set_item("step", step)?;
    d.set_item("tool_length", opts.tool_length)?;
    d.set_item("lambda_bounds", (lambda[0], lambda[1]))?;
    if adaptive {
        if points {
            return Err(PyValueError::new_err(
                "points=True needs every grid point: adaptive sampling classifies only the points near the boundary (adaptive=False)",
            ));
        }
        let a = py
            .allow_threads(|| ws::compute_adaptive(m, &opts, DEFAULT_COARSE_FACTOR, &|_| {}))
            .map_err(PyValueError::new_err)?;
        d.set_item("method", "adaptive")?;
        d.set_item("coarse_step", a.coarse_step)?;
        d.set_item("lattice_points", a.lattice_points)?;
        d.set_item("classified", a.classified)?;
        d.set_item("inside", a.inside_points)?;
        d.set_item("volume_mm3", a.volume_mm3)?;
        d.set_item("volume_litres", a.volume_mm3 * 1e-6)?;
        d.set_item("volume_lo_mm3", a.volume_lo_mm3)?;
        d.set_item("volume_hi_mm3", a.volume_hi_mm3)?;
        d.set_item("error_bound_mm3", a.error_bound_mm3())?;
        d.set_item("boundary_cells", a.boundary_cells)?;
        d.set_item("sampled_cells", a.sampled_cells)?;
        d.set_item("volume_sampled_mm3", a.volume_sampled_mm3)?;
        d.set_item("sampled_half_width_mm3", a.sampled_half_width_mm3)?;
        d.set_item("bbox", a.bbox.as_ref().map(bounds_tuple))?;
        for (key, found, volume, upper) in [
            (
                "largest_box",
                a.largest_box,
                a.largest_box_mm3,
                a.largest_box_upper_mm3,
            ),
            (
                "largest_cube",
                a.largest_cube,
                a.largest_cube_mm3,
                a.largest_cube_upper_mm3,
            ),
        ] {
            let item = found
                .map(|b| box_dict(py, &b, volume, Some(upper)))
                .transpose()?;
            d.set_item(key, item)?;
        }
        d.set_item("box_exact", a.box_exact)?;
        d.set_item("touches_bounds", a.touches_bounds)?;
        d.set_item(
            "binding",
            counts(py, outcome_codes().into_iter(), &a.binding)?,
        )?;
        return Ok(d);
    }
    let mut q: Vec<[f64; 3]> = Vec::new();
    let mut outcome: Vec<i8> = Vec::new();
    let run = py.allow_threads(|| {
        ws::compute(m, &opts, &|_| {}, |p| {
            if points {
                q.push(p.q.into());
                outcome.push(p.outcome.index() as i8);
            }
            Ok::<(), std::convert::Infallible>(())
        })
    });
    let w = match run {
        Ok(Ok(w)) => w.summary,
        Ok(Err(e)) => return Err(PyValueError::new_err(e)),
        Err(never) => match never {},
    };
    d.set_item("method", "uniform")?;
    d.set_item("points", w.points)?;
    d.set_item("inside", w.inside)?;
    d.set_item("volume_mm3", w.volume_mm3)?;
    d.set_item("volume_litres", w.volume_litres())?;
    d.set_item("volume_double_step_mm3", w.volume_double_step_mm3)?;
    d.set_item("error_estimate_mm3", w.volume_error_mm3())?;
    d.set_item("bbox", w.bbox.as_ref().map(bounds_tuple))?;
    for (key, found) in [
        ("largest_box", w.largest_box_size()),
        ("largest_cube", w.largest_cube_size()),
    ] {
        let item = found
            .map(|(b, volume)| box_dict(py, &b, volume, None))
            .transpose()?;
        d.set_item(key, item)?;
    }
    d.set_item("touches_bounds", w.touches_bounds)?;
    d.set_item(
        "binding",
        counts(py, outcome_codes().into_iter(), &w.binding)?,
    )?;
    d.set_item(
        "failures",
        counts(
            py,
            ws::Constraint::ALL.iter().map(|c| c.code()),
            &w.failures,
        )?,
    )?;
    if points {
        let n = q.len();
        let mut grid = Array2::<f64>::zeros((n, 3));
        for (i, p) in q.iter().enumerate() {
            for j in 0..3 {
                grid[[i, j]] = p[j];
            }
        }
        d.set_item("grid_points", grid.into_pyarray(py))?;
        d.set_item("outcome", Array1::from_vec(outcome).into_pyarray(py))?;
    }
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(workspace, m)?)?;
    m.add("OUTCOMES", outcome_codes())?;
    Ok(())
}

/// A box inside as a dict: `min`, `max` (mm), `volume_mm3`, and for an adaptive run
/// `upper_bound_mm3` (no box of the lattice is larger).
fn box_dict<'py>(
    py: Python<'py>,
    b: &Bounds,
    volume_mm3: f64,
    upper_bound_mm3: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("min", <[f64; 3]>::from(b.min))?;
    d.set_item("max", <[f64; 3]>::from(b.max))?;
    d.set_item("volume_mm3", volume_mm3)?;
    if let Some(u) = upper_bound_mm3 {
        d.set_item("upper_bound_mm3", u)?;
    }
    Ok(d)
}
