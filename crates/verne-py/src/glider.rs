//! `verne.Glider`: the planar glider mechanisms of the comparative study (Wenger, Gosselin,
//! Chablat 2001): every solution of their inverse and forward kinematics, their workspace and
//! the dimensioning of section 3.2. Lengths in the spec's unit, angles in radians.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use nalgebra::{Point2, Vector2};
use verne::glider::{
    self, Architecture, Branch, ForwardKinematics, GliderSpec, NodeClass, PAPER_LAMBDA_BOUNDS,
    PRESET_NAMES, Rectangle, WorkingMode,
};

use crate::rows;

/// A glider mechanism: two struts on two guides (section 3.1, Wenger 2001).
#[pyclass(name = "Glider", module = "verne", frozen)]
pub struct PyGlider {
    inner: GliderSpec,
}

fn spec_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

#[pymethods]
impl PyGlider {
    /// A preset of section 3.1: "biglide1", "biglide2" or "orthoglide" (L = 1).
    #[staticmethod]
    fn preset(name: &str) -> PyResult<Self> {
        GliderSpec::preset(name)
            .map(|inner| PyGlider { inner })
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "{name:?}: no such glider preset; expected one of {}",
                    PRESET_NAMES.join(", ")
                ))
            })
    }

    /// A glider file (TOML, `kind = "glider"`, angles in degrees); every problem is listed in
    /// the `ValueError`.
    #[staticmethod]
    fn from_file(path: &str) -> PyResult<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| PyOSError::new_err(format!("{path}: {e}")))?;
        GliderSpec::from_toml_str(&text, path)
            .map(|inner| PyGlider { inner })
            .map_err(spec_error)
    }

    /// A glider file's text.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        GliderSpec::from_toml_str(text, "<text>")
            .map(|inner| PyGlider { inner })
            .map_err(spec_error)
    }

    /// The mechanism "biglide1", "biglide2" or "orthoglide" dimensioned for strut length `l`
    /// by the rule of section 3.2 (both amplification factors within `lambda_bounds` on the
    /// guides' working range), as `verne design`.
    #[staticmethod]
    #[pyo3(signature = (architecture, l=1.0, lambda_bounds=None))]
    fn design(architecture: &str, l: f64, lambda_bounds: Option<(f64, f64)>) -> PyResult<Self> {
        let arch = Architecture::from_name(architecture).ok_or_else(|| {
            PyValueError::new_err(format!(
                "{architecture:?}: expected one of {}",
                PRESET_NAMES.join(", ")
            ))
        })?;
        let bounds = lambda_bounds.map_or(PAPER_LAMBDA_BOUNDS, |(lo, hi)| [lo, hi]);
        if !(l.is_finite() && l > 0.0 && 0.0 < bounds[0] && bounds[0] < bounds[1]) {
            return Err(PyValueError::new_err(format!(
                "l={l}, lambda_bounds={:?}: expected l > 0 and 0 < lo < hi",
                (bounds[0], bounds[1])
            )));
        }
        glider::architecture_spec(arch, l, bounds)
            .map(|inner| PyGlider { inner })
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "{architecture} has no dimensions meeting lambda_bounds={:?}",
                    (bounds[0], bounds[1])
                ))
            })
    }

    /// The glider as its TOML file (degrees).
    fn to_toml(&self) -> String {
        self.inner.to_toml_string()
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// The joint ranges ((rho1_min, rho1_max), (rho2_min, rho2_max)).
    #[getter]
    fn joint_ranges(&self) -> ((f64, f64), (f64, f64)) {
        let [a, b] = [self.inner.rho1_range, self.inner.rho2_range];
        ((a[0], a[1]), (b[0], b[1]))
    }

    fn __repr__(&self) -> String {
        format!("verne.Glider({:?})", self.inner.name)
    }
}

/// The signs of a working mode: +1, -1, 0 (a double root) per strut.
fn mode_signs(m: WorkingMode) -> [i8; 2] {
    [m.strut1.sign() as i8, m.strut2.sign() as i8]
}

/// `glider_ik`'s and `glider_fk`'s result: values, mode, assembly, ok, count.
type GliderSolutions<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<i8>>,
    Bound<'py, PyArray2<i8>>,
    Bound<'py, PyArray2<bool>>,
    Bound<'py, PyArray1<i64>>,
);

/// One solution: its two values, working mode signs, assembly sign, whether it is a pose of
/// the machine (working mode ++, assembly +, in range, not singular).
type GliderSolution = ([f64; 2], [i8; 2], i8, bool);

fn padded<'py>(py: Python<'py>, rows: &[Vec<GliderSolution>], k: usize) -> GliderSolutions<'py> {
    let n = rows.len();
    let mut v = Array3::<f64>::from_elem((n, k, 2), f64::NAN);
    let mut mode = Array3::<i8>::zeros((n, k, 2));
    let mut assembly = Array2::<i8>::zeros((n, k));
    let mut ok = Array2::<bool>::from_elem((n, k), false);
    let mut count = Array1::<i64>::zeros(n);
    for (i, sols) in rows.iter().enumerate() {
        count[i] = sols.len() as i64;
        for (s, (x, md, a, o)) in sols.iter().enumerate() {
            for j in 0..2 {
                v[[i, s, j]] = x[j];
                mode[[i, s, j]] = md[j];
            }
            assembly[[i, s]] = *a;
            ok[[i, s]] = *o;
        }
    }
    (
        v.into_pyarray(py),
        mode.into_pyarray(py),
        assembly.into_pyarray(py),
        ok.into_pyarray(py),
        count.into_pyarray(py),
    )
}

/// Every real solution of the glider's inverse kinematics for each point `points[N, 2]`
/// (x, y), as `verne ik -m GLIDER --all`: returns `(rho[N, 4, 2], mode[N, 4, 2], assembly[N,
/// 4], ok[N, 4], count[N])`: the joints (rho1, rho2), NaN past `count[i]`; the working mode as
/// strut signs (+1, -1, 0 at a double root); the assembly mode (sign of det A); `ok` where the
/// solution is a pose of the machine (working mode ++, assembly +, within the joint ranges, not
/// singular). A row with NaN has no solution.
///
/// >>> g = verne.Glider.preset("orthoglide")
/// >>> rho, mode, assembly, ok, count = verne.glider_ik(g, np.array([[0.897184, 1.192878]]))
/// >>> int(count[0]), rho[0][ok[0]].round(4).tolist()
/// (4, [[0.5, 0.6]])
#[pyfunction]
fn glider_ik<'py>(
    py: Python<'py>,
    glider: &PyGlider,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<GliderSolutions<'py>> {
    let pts = rows::<2>(&points, "points")?;
    let spec = &glider.inner;
    let solved: Vec<Vec<GliderSolution>> = py.allow_threads(|| {
        pts.par_iter()
            .map(|p| {
                if !p.iter().all(|v| v.is_finite()) {
                    return Vec::new();
                }
                let p = Point2::new(p[0], p[1]);
                glider::inverse_kinematics(spec, p)
                    .into_iter()
                    .map(|s| {
                        let ok = glider::verdict(spec, p, s.rho, s.mode, s.assembly).ok();
                        (
                            s.rho.into(),
                            mode_signs(s.mode),
                            s.assembly.sign() as i8,
                            ok,
                        )
                    })
                    .collect()
            })
            .collect()
    });
    Ok(padded(py, &solved, 4))
}

/// Every real solution of the glider's forward kinematics for each joint pair `rho[N, 2]`, as
/// `verne fk -m GLIDER --all`: returns `(points[N, 2, 2], mode, assembly, ok, count)` as
/// `glider_ik`, and `structural[N]`, True where the joints put the mechanism on a structural
/// singularity (C = D with equal struts: P anywhere on a circle, count 0).
///
/// >>> g = verne.Glider.preset("orthoglide")
/// >>> (points, mode, assembly, ok, count), structural = verne.glider_fk(g, np.array([[0.5, 0.6]]))
/// >>> int(count[0]), points[0][ok[0]].round(4).tolist()
/// (2, [[0.8972, 1.1929]])
#[pyfunction]
fn glider_fk<'py>(
    py: Python<'py>,
    glider: &PyGlider,
    rho: PyReadonlyArray2<'py, f64>,
) -> PyResult<(GliderSolutions<'py>, Bound<'py, PyArray1<bool>>)> {
    let joints = rows::<2>(&rho, "rho")?;
    let spec = &glider.inner;
    let solved: Vec<(Vec<GliderSolution>, bool)> = py.allow_threads(|| {
        joints
            .par_iter()
            .map(|r| {
                if !r.iter().all(|v| v.is_finite()) {
                    return (Vec::new(), false);
                }
                let rho = Vector2::new(r[0], r[1]);
                match glider::forward_kinematics(spec, rho) {
                    ForwardKinematics::StructuralSingularity { .. } => (Vec::new(), true),
                    ForwardKinematics::Isolated(sols) => (
                        sols.into_iter()
                            .map(|s| {
                                let ok = glider::verdict(spec, s.p, rho, s.mode, s.assembly).ok();
                                (
                                    [s.p.x, s.p.y],
                                    mode_signs(s.mode),
                                    s.assembly.sign() as i8,
                                    ok,
                                )
                            })
                            .collect(),
                        false,
                    ),
                }
            })
            .collect()
    });
    let structural = Array1::from_iter(solved.iter().map(|(_, s)| *s));
    let solved: Vec<Vec<GliderSolution>> = solved.into_iter().map(|(v, _)| v).collect();
    Ok((padded(py, &solved, 2), structural.into_pyarray(py)))
}

/// The node classes of `glider_workspace`, in the order of its `class` codes.
const NODE_CLASSES: [(NodeClass, &str); 6] = [
    (NodeClass::Admissible, "admissible"),
    (NodeClass::Unreachable, "unreachable"),
    (NodeClass::OutOfRange, "out_of_range"),
    (NodeClass::Singular, "singular"),
    (NodeClass::OtherAssembly, "other_assembly"),
    (NodeClass::OutOfBounds, "out_of_bounds"),
];

fn rectangle_dict<'py>(py: Python<'py>, r: Option<Rectangle>) -> PyResult<PyObject> {
    let Some(r) = r else {
        return Ok(py.None());
    };
    let d = PyDict::new(py);
    d.set_item("centre", (r.centre.x, r.centre.y))?;
    d.set_item("width", r.width)?;
    d.set_item("height", r.height)?;
    d.set_item("angle", r.angle)?;
    d.set_item("area", r.area())?;
    d.set_item("corners", r.corners().map(|c| (c.x, c.y)).to_vec())?;
    Ok(d.into_any().unbind())
}

/// The workspace of the glider (section 3.2): a grid of `nodes` along the longer side of the
/// window, each node classified, the t-connected region of the working mode `mode` and
/// assembly mode `assembly` (sign "+" or "-"), with both amplification factors within
/// `lambda_bounds` (None: the paper's 1/3 .. 3; `False`: no bound), as `verne workspace -m
/// GLIDER`; the largest rectangle and square with their sides at each of `shape_angles` (rad;
/// default 0 and pi/4, as the CLI), the larger kept. `sampling`: "auto" (adaptive from 513
/// nodes), "uniform" (every node classified) or "adaptive" (a coarse grid refined where the
/// class or the binding constraint changes: the same grid wherever no feature hides inside a
/// coarse cell, at a cost that grows with the boundary). Returns a dict: `step`, `origin`,
/// `class[ny, nx]` (int8, index into `verne.GLIDER_NODE_CLASSES`), `region[ny, nx]` (bool),
/// `x[ny, nx]`, `y[ny, nx]` (node positions), `admissible_area`, `region_area`,
/// `region_area_bounds` (the cells all in the region, and those touching it),
/// `region_area_sampled` and `region_area_half_width` (one pseudo-random point a boundary
/// cell, 99.7 % Hoeffding), `classified` (points classified), `coarse_step` (None when
/// uniform), `largest_square` and `largest_rectangle` (dicts with centre, width, height,
/// angle, area, corners; None when the region is empty).
///
/// >>> w = verne.glider_workspace(verne.Glider.preset("orthoglide"), nodes=201)
/// >>> round(w["region_area"], 2), w["class"].shape == w["region"].shape
/// (1.23, True)
/// >>> lo, hi = w["region_area_bounds"]
/// >>> bool(lo <= w["region_area_sampled"] <= hi), w["coarse_step"] is None
/// (True, True)
#[pyfunction]
#[pyo3(signature = (glider, nodes=801, mode="++", assembly="+", lambda_bounds=None, shape_angles=None, sampling="auto"))]
#[allow(clippy::too_many_arguments)]
fn glider_workspace<'py>(
    py: Python<'py>,
    glider: &PyGlider,
    nodes: usize,
    mode: &str,
    assembly: &str,
    lambda_bounds: Option<&Bound<'py, PyAny>>,
    shape_angles: Option<Vec<f64>>,
    sampling: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let sampling = match sampling {
        "auto" => glider::Sampling::Auto,
        "uniform" => glider::Sampling::Uniform,
        "adaptive" => glider::Sampling::Adaptive,
        other => {
            return Err(PyValueError::new_err(format!(
                "sampling={other:?}: expected \"auto\", \"uniform\" or \"adaptive\""
            )));
        }
    };
    let mode = WorkingMode::parse(mode)
        .filter(|m| m.strut1 != Branch::Double && m.strut2 != Branch::Double)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "mode={mode:?}: expected \"++\", \"+-\", \"-+\" or \"--\""
            ))
        })?;
    let assembly = match assembly {
        "+" => Branch::Plus,
        "-" => Branch::Minus,
        other => {
            return Err(PyValueError::new_err(format!(
                "assembly={other:?}: expected \"+\" or \"-\""
            )));
        }
    };
    let lambda_bounds = match lambda_bounds {
        None => Some(PAPER_LAMBDA_BOUNDS),
        Some(b) if b.is_instance_of::<pyo3::types::PyBool>() && !b.extract::<bool>()? => None,
        Some(b) => {
            let (lo, hi): (f64, f64) = b.extract().map_err(|_| {
                PyValueError::new_err("lambda_bounds: expected (lo, hi), None or False")
            })?;
            if !(lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi) {
                return Err(PyValueError::new_err(format!(
                    "lambda_bounds={:?}: expected 0 < lo < hi",
                    (lo, hi)
                )));
            }
            Some([lo, hi])
        }
    };
    // The sides of the largest rectangle and square: 0 and 45 deg by default, as `verne
    // workspace` (the two orientations symmetric about the mechanisms' axis, docs/gliders.md).
    let angles = shape_angles.unwrap_or_else(|| vec![0.0, std::f64::consts::FRAC_PI_4]);
    if !(2..=20_001).contains(&nodes) || angles.is_empty() || !angles.iter().all(|a| a.is_finite())
    {
        return Err(PyValueError::new_err(format!(
            "nodes={nodes}, shape_angles={angles:?}: expected 2 <= nodes <= 20001 and finite angles"
        )));
    }
    let opts = glider::WorkspaceOptions {
        mode,
        assembly,
        lambda_bounds,
        nodes,
        frame_angle: 0.0,
        seed: None,
        sampling,
    };
    let spec = &glider.inner;
    let (grid, square, rectangle) = py.allow_threads(|| {
        let grid = glider::sample_workspace(spec, &opts);
        let (mut square, mut rectangle): (Option<Rectangle>, Option<Rectangle>) = (None, None);
        let larger = |best: &mut Option<Rectangle>, r: Option<Rectangle>| {
            if let Some(r) = r
                && best.is_none_or(|b| r.area() > b.area())
            {
                *best = Some(r);
            }
        };
        for &angle in &angles {
            let turned;
            let g = if angle == 0.0 {
                &grid
            } else {
                turned = glider::sample_workspace(
                    spec,
                    &glider::WorkspaceOptions {
                        frame_angle: angle,
                        ..opts.clone()
                    },
                );
                &turned
            };
            larger(&mut square, glider::largest_square(g));
            larger(&mut rectangle, glider::largest_rectangle(g));
        }
        (grid, square, rectangle)
    });
    let (nx, ny) = (grid.nx, grid.ny);
    let class = Array2::from_shape_fn((ny, nx), |(j, i)| {
        let c = grid.class[j * nx + i];
        NODE_CLASSES.iter().position(|(k, _)| *k == c).unwrap_or(0) as i8
    });
    let region = Array2::from_shape_fn((ny, nx), |(j, i)| grid.region[j * nx + i]);
    let x = Array2::from_shape_fn((ny, nx), |(j, i)| grid.node(i, j).x);
    let y = Array2::from_shape_fn((ny, nx), |(j, i)| grid.node(i, j).y);
    let d = PyDict::new(py);
    d.set_item("step", grid.step)?;
    d.set_item("origin", (grid.origin.x, grid.origin.y))?;
    d.set_item("class", class.into_pyarray(py))?;
    d.set_item("region", region.into_pyarray(py))?;
    d.set_item("x", x.into_pyarray(py))?;
    d.set_item("y", y.into_pyarray(py))?;
    d.set_item("admissible_area", grid.admissible_area())?;
    d.set_item("region_area", grid.region_area())?;
    let e = grid.region_estimate;
    d.set_item("region_area_bounds", (e.lo, e.hi))?;
    d.set_item("region_area_sampled", e.sampled)?;
    d.set_item("region_area_half_width", e.half_width)?;
    d.set_item("classified", grid.classified)?;
    d.set_item("coarse_step", grid.coarse_step)?;
    d.set_item("largest_square", rectangle_dict(py, square)?)?;
    d.set_item("largest_rectangle", rectangle_dict(py, rectangle)?)?;
    Ok(d)
}

/// Tables 1 and 2 of the comparative study (Wenger, Gosselin, Chablat 2001), computed beside
/// the paper's values, as `verne design`: each architecture dimensioned for strut length L = 1
/// under `lambda_bounds` (default 1/3 .. 3), its workspace sampled on `nodes` along the longer
/// side. Returns `{"table1": [...], "table2": [...]}`, one dict per row with the CLI's columns
/// (`*_paper` None where the paper printed nothing; relative differences (computed - paper) /
/// paper).
///
/// >>> t = verne.design_tables(nodes=201)
/// >>> [r["mechanism"] for r in t["table1"]], len(t["table2"])
/// (['biglide1', 'biglide2', 'orthoglide'], 6)
#[pyfunction]
#[pyo3(signature = (lambda_bounds=None, nodes=1201, target_area=1.0))]
fn design_tables<'py>(
    py: Python<'py>,
    lambda_bounds: Option<(f64, f64)>,
    nodes: usize,
    target_area: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let bounds = lambda_bounds.map_or(PAPER_LAMBDA_BOUNDS, |(lo, hi)| [lo, hi]);
    let bounds_ok =
        bounds[0].is_finite() && bounds[1].is_finite() && 0.0 < bounds[0] && bounds[0] < bounds[1];
    let area_ok = target_area.is_finite() && target_area > 0.0;
    if !(bounds_ok && area_ok && (2..=20_001).contains(&nodes)) {
        return Err(PyValueError::new_err(format!(
            "lambda_bounds={:?}, nodes={nodes}, target_area={target_area}: expected 0 < lo < hi, 2 <= nodes <= 20001, a positive area",
            (bounds[0], bounds[1])
        )));
    }
    let opts = glider::DesignOptions {
        bounds,
        nodes,
        target_area,
        ..glider::DesignOptions::default()
    };
    let (t1, t2) = py.allow_threads(|| {
        let t1 = glider::table1(&opts);
        let t2 = glider::table2(&t1, target_area);
        (t1, t2)
    });
    let rows1 = t1
        .iter()
        .map(|r| {
            let d = PyDict::new(py);
            d.set_item("mechanism", &r.mechanism)?;
            for (k, v) in [
                ("l0_paper", r.l0_paper),
                ("l0", r.l0),
                ("l0_rel_diff", r.l0_rel_diff),
                ("delta_rho_paper", r.delta_rho_paper),
                ("delta_rho", r.delta_rho),
                ("delta_rho_rel_diff", r.delta_rho_rel_diff),
                ("s_paper", r.s_paper),
                ("s", r.s),
                ("s_rel_diff", r.s_rel_diff),
                ("s_width", r.s_width),
                ("s_height", r.s_height),
                ("s_angle_deg", r.s_angle_deg),
                ("square", r.square),
                ("square_angle_deg", r.square_angle_deg),
                ("envelope", r.envelope),
            ] {
                d.set_item(k, v)?;
            }
            Ok(d)
        })
        .collect::<PyResult<Vec<_>>>()?;
    let rows2 = t2
        .iter()
        .map(|r| {
            let d = PyDict::new(py);
            d.set_item("mechanism", &r.mechanism)?;
            d.set_item("target", r.target.name())?;
            for (k, v) in [
                ("l0_paper", r.l0_paper),
                ("l0_rel_diff", r.l0_rel_diff),
                ("l_paper", r.l_paper),
                ("l_rel_diff", r.l_rel_diff),
                ("delta_rho_paper", r.delta_rho_paper),
                ("delta_rho_rel_diff", r.delta_rho_rel_diff),
                ("envelope_paper", r.envelope_paper),
                ("envelope_rel_diff", r.envelope_rel_diff),
            ] {
                d.set_item(k, v)?;
            }
            for (k, v) in [
                ("l0", r.l0),
                ("l", r.l),
                ("delta_rho", r.delta_rho),
                ("envelope", r.envelope),
            ] {
                d.set_item(k, v)?;
            }
            Ok(d)
        })
        .collect::<PyResult<Vec<_>>>()?;
    let d = PyDict::new(py);
    d.set_item("table1", rows1)?;
    d.set_item("table2", rows2)?;
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyGlider>()?;
    m.add_function(wrap_pyfunction!(design_tables, m)?)?;
    m.add_function(wrap_pyfunction!(glider_ik, m)?)?;
    m.add_function(wrap_pyfunction!(glider_fk, m)?)?;
    m.add_function(wrap_pyfunction!(glider_workspace, m)?)?;
    m.add(
        "GLIDER_NODE_CLASSES",
        NODE_CLASSES.iter().map(|(_, n)| *n).collect::<Vec<_>>(),
    )?;
    Ok(())
}
