//! The parallel module (IFToMM 2007): every branch of its inverse and forward kinematics,
//! padded or compact, and the machine's branch alone.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2};
use pyo3::prelude::*;
use rayon::prelude::*;

use verne::parallel_module::equations::Sliders;
use verne::parallel_module::fk::{self, MAX_FK_MODES};
use verne::parallel_module::ik::{self, MAX_IK_BRANCHES};
use verne::spec::Machine;

use crate::machine::PyMachine;
use crate::{CHUNK, INVALID_INPUT, NO_WORKING_BRANCH, OK, UNREACHABLE, rows};

type Branches<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<i8>>,
    Bound<'py, PyArray2<bool>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<bool>>,
);

/// One real branch (or assembly mode) of a row: its four values, configuration, working flag.
type Solution = ([f64; 4], [i8; 3], bool);

/// `module_ik_working`'s result: sliders, alpha, status.
type Working<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i8>>,
);

/// Every branch of every row, solved in parallel chunks into compact per-chunk lists:
/// the solutions in row order, and per row its count and certificate. `solve_chunk` solves a
/// chunk of rows, appending to the three lists.
fn solve_compact<T: Sync>(
    rows: &[T],
    solve_chunk: impl Fn(&[T], &mut Vec<Solution>, &mut Vec<usize>, &mut Vec<bool>) + Sync,
) -> (Vec<Solution>, Vec<usize>, Vec<bool>) {
    let chunks: Vec<(Vec<Solution>, Vec<usize>, Vec<bool>)> = rows
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut sols = Vec::with_capacity(chunk.len() * 8);
            let mut counts = Vec::with_capacity(chunk.len());
            let mut proved = Vec::with_capacity(chunk.len());
            solve_chunk(chunk, &mut sols, &mut counts, &mut proved);
            (sols, counts, proved)
        })
        .collect();
    let mut sols = Vec::with_capacity(chunks.iter().map(|c| c.0.len()).sum());
    let mut counts = Vec::with_capacity(rows.len());
    let mut proved = Vec::with_capacity(rows.len());
    for (s, c, p) in chunks {
        sols.extend(s);
        counts.extend(c);
        proved.extend(p);
    }
    (sols, counts, proved)
}

/// Every branch of a chunk of points, four at a time through the core's batched kernel
/// (`ik::solve_each`, the one `verne ik --all` runs).
fn ik_chunk(
    m: &Machine,
    chunk: &[[f64; 3]],
    sols: &mut Vec<Solution>,
    counts: &mut Vec<usize>,
    proved: &mut Vec<bool>,
) {
    let mut lists = vec![ik::IkBranches::default(); chunk.len()];
    ik::solve_each(
        m,
        chunk
            .iter()
            .map(|p| nalgebra::Vector3::from(*p))
            .zip(lists.iter_mut()),
    );
    for s in &lists {
        for br in s.iter() {
            sols.push((
                [br.rho.x, br.rho.y, br.rho.z, br.alpha],
                br.config,
                br.working(),
            ));
        }
        counts.push(s.len());
        proved.push(s.certificate.proved());
    }
}

/// Every assembly mode of a chunk of slider triples.
fn fk_chunk(
    m: &Machine,
    chunk: &[[f64; 3]],
    sols: &mut Vec<Solution>,
    counts: &mut Vec<usize>,
    proved: &mut Vec<bool>,
) {
    for r in chunk {
        let s = fk::solve(m, &Sliders::new(r[0], r[1], r[2]));
        for mode in s.iter() {
            let p = mode.pose.p;
            sols.push((
                [p.x, p.y, p.z, mode.pose.alpha],
                mode.config,
                mode.working(),
            ));
        }
        counts.push(s.len());
        proved.push(s.certificate.proved());
    }
}

/// Compact solutions as NaN-padded `[N, K, ...]` arrays.
fn padded<'py>(
    py: Python<'py>,
    (sols, counts, proved): (Vec<Solution>, Vec<usize>, Vec<bool>),
    k: usize,
) -> Branches<'py> {
    let n = counts.len();
    let mut b = Array3::<f64>::from_elem((n, k, 4), f64::NAN);
    let mut c = Array3::<i8>::zeros((n, k, 3));
    let mut w = Array2::<bool>::from_elem((n, k), false);
    let mut next = 0;
    for (i, &count) in counts.iter().enumerate() {
        for (slot, (v, config, working)) in sols[next..next + count].iter().enumerate() {
            for j in 0..4 {
                b[[i, slot, j]] = v[j];
            }
            for j in 0..3 {
                c[[i, slot, j]] = config[j];
            }
            w[[i, slot]] = *working;
        }
        next += count;
    }
    let count = Array1::from_iter(counts.iter().map(|&c| c as i64));
    (
        b.into_pyarray(py),
        c.into_pyarray(py),
        w.into_pyarray(py),
        count.into_pyarray(py),
        Array1::from_vec(proved).into_pyarray(py),
    )
}

type Compact<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<i8>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<bool>>,
);

/// Compact solutions: one row per real branch, as the CLI's `--all` rows.
fn compact<'py>(
    py: Python<'py>,
    (sols, counts, proved): (Vec<Solution>, Vec<usize>, Vec<bool>),
) -> Compact<'py> {
    let m = sols.len();
    let mut b = Array2::<f64>::zeros((m, 4));
    let mut c = Array2::<i8>::zeros((m, 3));
    let mut w = Array1::<bool>::from_elem(m, false);
    for (r, (v, config, working)) in sols.iter().enumerate() {
        for j in 0..4 {
            b[[r, j]] = v[j];
        }
        for j in 0..3 {
            c[[r, j]] = config[j];
        }
        w[r] = *working;
    }
    let mut index = Vec::with_capacity(m);
    let mut offsets = Vec::with_capacity(counts.len() + 1);
    offsets.push(0i64);
    for (i, &count) in counts.iter().enumerate() {
        index.extend(std::iter::repeat_n(i as i64, count));
        offsets.push(offsets[i] + count as i64);
    }
    (
        b.into_pyarray(py),
        c.into_pyarray(py),
        w.into_pyarray(py),
        Array1::from_vec(index).into_pyarray(py),
        Array1::from_vec(offsets).into_pyarray(py),
        Array1::from_vec(proved).into_pyarray(py),
    )
}

/// Every real branch of the parallel module's inverse kinematics (IFToMM 2007, section V) for
/// each platform point P = (xp, yp, zp) (mm, base frame).
///
/// Returns `(branches, config, working, count, proved)`: `branches[N, 24, 4]` = (rho1, rho2,
/// rho3 in mm, alpha in rad), NaN past `count[i]`; `config[N, 24, 3]` the configuration
/// indices (s1, s2, s3), 0 past the count; `working[N, 24]` whether the machine can be in that
/// branch (configuration (-1,-1,-1), strokes, rod tilts, no crossing); `proved[N]` whether the
/// list is certified complete. For large batches, `module_ik_compact`.
#[pyfunction]
fn module_ik<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Branches<'py>> {
    let pts = rows::<3>(&points, "points")?;
    let m = &machine.inner;
    let solved = py.allow_threads(|| solve_compact(&pts, |c, s, n, p| ik_chunk(m, c, s, n, p)));
    Ok(padded(py, solved, MAX_IK_BRANCHES))
}

/// `module_ik` in compact form, one row per real branch (as `verne ik --all`): returns
/// `(branches[M, 4], config[M, 3], working[M], point[M], offsets[N + 1], proved[N])`, the
/// branches of point i in rows `offsets[i]..offsets[i + 1]` (`point` says the same per row).
#[pyfunction]
fn module_ik_compact<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Compact<'py>> {
    let pts = rows::<3>(&points, "points")?;
    let m = &machine.inner;
    let solved = py.allow_threads(|| solve_compact(&pts, |c, s, n, p| ik_chunk(m, c, s, n, p)));
    Ok(compact(py, solved))
}

/// The machine's branch of the parallel module's inverse kinematics for each platform point,
/// without solving the others where a certified shortcut is sure of it (what `verne ik` does).
///
/// Returns `(sliders, alpha, status)`: `sliders[N, 3]` (mm) and `alpha[N]` (rad), NaN where the
/// point has no working branch; `status[N]` 0 ok, 1 unreachable (no real branch, proved), 2 no
/// working branch, 3 invalid input.
#[pyfunction]
fn module_ik_working<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Working<'py>> {
    let pts = rows::<3>(&points, "points")?;
    let m = &machine.inner;
    let n = pts.len();
    let mut sliders = Array2::<f64>::from_elem((n, 3), f64::NAN);
    let mut alpha = Array1::<f64>::from_elem(n, f64::NAN);
    let mut status = Array1::<i8>::zeros(n);
    let solved: Vec<(Option<[f64; 4]>, i8)> = py.allow_threads(|| {
        pts.par_chunks(CHUNK)
            .flat_map_iter(|chunk| {
                // The core's batched kernel (`verne ik`'s): the working branch four points at a
                // time, every branch where its shortcut is not sure.
                let mut lists = vec![ik::IkBranches::default(); chunk.len()];
                let finite: Vec<bool> = chunk
                    .iter()
                    .map(|p| p.iter().all(|v| v.is_finite()))
                    .collect();
                ik::solve_working_each(
                    m,
                    chunk
                        .iter()
                        .zip(&finite)
                        .zip(lists.iter_mut())
                        .filter(|((_, ok), _)| **ok)
                        .map(|((p, _), l)| (nalgebra::Vector3::from(*p), l)),
                );
                lists
                    .into_iter()
                    .zip(finite)
                    .map(|(out, ok)| {
                        if !ok {
                            return (None, INVALID_INPUT);
                        }
                        match ik::working(&out) {
                            Some(b) => (Some([b.rho.x, b.rho.y, b.rho.z, b.alpha]), OK),
                            None if out.is_empty() && out.certificate.proved() => {
                                (None, UNREACHABLE)
                            }
                            None => (None, NO_WORKING_BRANCH),
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    });
    for (i, (v, st)) in solved.into_iter().enumerate() {
        status[i] = st;
        if let Some(v) = v {
            for j in 0..3 {
                sliders[[i, j]] = v[j];
            }
            alpha[i] = v[3];
        }
    }
    Ok((
        sliders.into_pyarray(py),
        alpha.into_pyarray(py),
        status.into_pyarray(py),
    ))
}

/// Every real assembly mode of the parallel module's forward kinematics (IFToMM 2007, section
/// VI) for each slider triple (rho1, rho2, rho3) (mm).
///
/// Returns `(modes, config, working, count, proved)`: `modes[N, 16, 4]` = (xp, yp, zp in mm,
/// alpha in rad), NaN past `count[i]`; the rest as in `module_ik`.
#[pyfunction]
fn module_fk<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    sliders: PyReadonlyArray2<'py, f64>,
) -> PyResult<Branches<'py>> {
    let rhos = rows::<3>(&sliders, "sliders")?;
    let m = &machine.inner;
    let solved = py.allow_threads(|| solve_compact(&rhos, |c, s, n, p| fk_chunk(m, c, s, n, p)));
    Ok(padded(py, solved, MAX_FK_MODES))
}

/// `module_fk` in compact form, one row per real assembly mode: as `module_ik_compact`.
#[pyfunction]
fn module_fk_compact<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    sliders: PyReadonlyArray2<'py, f64>,
) -> PyResult<Compact<'py>> {
    let rhos = rows::<3>(&sliders, "sliders")?;
    let m = &machine.inner;
    let solved = py.allow_threads(|| solve_compact(&rhos, |c, s, n, p| fk_chunk(m, c, s, n, p)));
    Ok(compact(py, solved))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(module_ik, m)?)?;
    m.add_function(wrap_pyfunction!(module_ik_working, m)?)?;
    m.add_function(wrap_pyfunction!(module_fk, m)?)?;
    m.add_function(wrap_pyfunction!(module_ik_compact, m)?)?;
    m.add_function(wrap_pyfunction!(module_fk_compact, m)?)?;
    Ok(())
}
