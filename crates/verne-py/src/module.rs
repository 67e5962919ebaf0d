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

/// `module_ik_working`'s result: sliders, alpha, status.
type Working<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i8>>,
);

/// The real branches (or assembly modes) of a chunk of rows, in row order: per branch its four
/// values, configuration and working flag, per row its count and certificate.
#[derive(Default)]
struct Solved {
    values: Vec<[f64; 4]>,
    config: Vec<[i8; 3]>,
    working: Vec<bool>,
    counts: Vec<usize>,
    proved: Vec<bool>,
}

impl Solved {
    fn push(&mut self, values: [f64; 4], config: [i8; 3], working: bool) {
        self.values.push(values);
        self.config.push(config);
        self.working.push(working);
    }
}

/// Points whose branch lists are solved together inside a chunk: the lists (about 1.3 KB each)
/// are reused from batch to batch and stay in cache.
const LIST_BATCH: usize = 64;

/// Every branch of every row, solved in parallel chunks of [`CHUNK`] rows, one [`Solved`] per
/// chunk in order. `solve_chunk` solves a chunk of rows into its `Solved`.
fn solve_chunks<T: Sync>(
    rows: &[T],
    solve_chunk: impl Fn(&[T], &mut Solved) + Sync,
) -> Vec<Solved> {
    rows.par_chunks(CHUNK)
        .map(|chunk| {
            let mut out = Solved {
                values: Vec::with_capacity(chunk.len() * 16),
                config: Vec::with_capacity(chunk.len() * 16),
                working: Vec::with_capacity(chunk.len() * 16),
                counts: Vec::with_capacity(chunk.len()),
                proved: Vec::with_capacity(chunk.len()),
            };
            solve_chunk(chunk, &mut out);
            out
        })
        .collect()
}

/// Every branch of a chunk of points, four at a time through the core's batched kernel
/// (`ik::solve_each`, the one `verne ik --all` runs).
fn ik_chunk(m: &Machine, chunk: &[[f64; 3]], out: &mut Solved) {
    let mut lists = vec![ik::IkBranches::default(); LIST_BATCH.min(chunk.len())];
    for points in chunk.chunks(LIST_BATCH) {
        ik::solve_each(
            m,
            points
                .iter()
                .map(|p| nalgebra::Vector3::from(*p))
                .zip(lists.iter_mut()),
        );
        for s in &lists[..points.len()] {
            for br in s.iter() {
                out.push(
                    [br.rho.x, br.rho.y, br.rho.z, br.alpha],
                    br.config,
                    br.working(),
                );
            }
            out.counts.push(s.len());
            out.proved.push(s.certificate.proved());
        }
    }
}

/// Every assembly mode of a chunk of slider triples.
fn fk_chunk(m: &Machine, chunk: &[[f64; 3]], out: &mut Solved) {
    for r in chunk {
        let s = fk::solve(m, &Sliders::new(r[0], r[1], r[2]));
        for mode in s.iter() {
            let p = mode.pose.p;
            out.push(
                [p.x, p.y, p.z, mode.pose.alpha],
                mode.config,
                mode.working(),
            );
        }
        out.counts.push(s.len());
        out.proved.push(s.certificate.proved());
    }
}

/// `slice` cut into consecutive pieces of the given lengths.
fn split_by<T>(mut slice: &mut [T], lens: impl Iterator<Item = usize>) -> Vec<&mut [T]> {
    let mut pieces = Vec::new();
    for len in lens {
        let (piece, rest) = std::mem::take(&mut slice).split_at_mut(len);
        pieces.push(piece);
        slice = rest;
    }
    pieces
}

/// Every branch as NaN-padded `[N, K, ...]` arrays, before they are handed to Python.
type PaddedArrays = (
    Array3<f64>,
    Array3<i8>,
    Array2<bool>,
    Array1<i64>,
    Array1<bool>,
);

/// The chunks' solutions as padded arrays, each chunk written into its rows in parallel (the
/// arrays start zeroed by the allocator, so only the written pages are touched twice).
fn padded(chunks: Vec<Solved>, n: usize, k: usize) -> PaddedArrays {
    let mut b = Array3::<f64>::zeros((n, k, 4));
    let mut c = Array3::<i8>::zeros((n, k, 3));
    let mut w = Array2::<bool>::from_elem((n, k), false);
    let mut count = Array1::<i64>::zeros(n);
    let mut proved = Array1::<bool>::from_elem(n, false);
    let rows_of = |s: &Solved| s.counts.len();
    let bs = split_by(
        b.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(|s| rows_of(s) * k * 4),
    );
    let cs = split_by(
        c.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(|s| rows_of(s) * k * 3),
    );
    let ws = split_by(
        w.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(|s| rows_of(s) * k),
    );
    let ns = split_by(
        count.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(rows_of),
    );
    let ps = split_by(
        proved.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(rows_of),
    );
    bs.into_par_iter()
        .zip(cs)
        .zip(ws)
        .zip(ns)
        .zip(ps)
        .zip(&chunks)
        .for_each(|(((((b, c), w), n), p), s)| {
            b.fill(f64::NAN);
            let mut next = 0;
            for (i, &count) in s.counts.iter().enumerate() {
                for slot in 0..count {
                    let (row, at) = (next + slot, i * k + slot);
                    b[4 * at..4 * at + 4].copy_from_slice(&s.values[row]);
                    c[3 * at..3 * at + 3].copy_from_slice(&s.config[row]);
                    w[at] = s.working[row];
                }
                n[i] = count as i64;
                next += count;
            }
            p.copy_from_slice(&s.proved);
        });
    (b, c, w, count, proved)
}

fn padded_to_python(py: Python<'_>, (b, c, w, n, p): PaddedArrays) -> Branches<'_> {
    (
        b.into_pyarray(py),
        c.into_pyarray(py),
        w.into_pyarray(py),
        n.into_pyarray(py),
        p.into_pyarray(py),
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

/// One row per real branch, before the arrays are handed to Python.
type CompactArrays = (
    Array2<f64>,
    Array2<i8>,
    Array1<bool>,
    Array1<i64>,
    Array1<i64>,
    Array1<bool>,
);

/// The chunks' solutions as compact arrays, one row per real branch (as the CLI's `--all`
/// rows), each chunk copied into its rows in parallel.
fn compact(chunks: Vec<Solved>, n: usize) -> CompactArrays {
    let total: usize = chunks.iter().map(|s| s.values.len()).sum();
    let mut b = Array2::<f64>::zeros((total, 4));
    let mut c = Array2::<i8>::zeros((total, 3));
    let mut w = Array1::<bool>::from_elem(total, false);
    let mut index = Array1::<i64>::zeros(total);
    let mut offsets = Array1::<i64>::zeros(n + 1);
    let mut proved = Array1::<bool>::from_elem(n, false);
    let sols = |s: &Solved| s.values.len();
    let rows = |s: &Solved| s.counts.len();
    let bs = split_by(
        b.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(|s| 4 * sols(s)),
    );
    let cs = split_by(
        c.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(|s| 3 * sols(s)),
    );
    let ws = split_by(
        w.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(sols),
    );
    let is = split_by(
        index.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(sols),
    );
    let ps = split_by(
        proved.as_slice_mut().expect("a new array is contiguous"),
        chunks.iter().map(rows),
    );
    bs.into_par_iter()
        .zip(cs)
        .zip(ws)
        .zip(is)
        .zip(ps)
        .zip(&chunks)
        .enumerate()
        .for_each(|(k, (((((b, c), w), idx), p), s))| {
            b.copy_from_slice(s.values.as_flattened());
            c.copy_from_slice(s.config.as_flattened());
            w.copy_from_slice(&s.working);
            p.copy_from_slice(&s.proved);
            let first = k * CHUNK;
            let mut next = 0;
            for (i, &count) in s.counts.iter().enumerate() {
                idx[next..next + count].fill((first + i) as i64);
                next += count;
            }
        });
    let mut at = 0i64;
    for (o, count) in offsets
        .iter_mut()
        .skip(1)
        .zip(chunks.iter().flat_map(|s| s.counts.iter()))
    {
        at += *count as i64;
        *o = at;
    }
    (b, c, w, index, offsets, proved)
}

fn compact_to_python(py: Python<'_>, (b, c, w, i, o, p): CompactArrays) -> Compact<'_> {
    (
        b.into_pyarray(py),
        c.into_pyarray(py),
        w.into_pyarray(py),
        i.into_pyarray(py),
        o.into_pyarray(py),
        p.into_pyarray(py),
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
///
/// >>> b, config, working, count, proved = verne.module_ik(m, np.array([[-240.0, -86.0, 1000.0]]))
/// >>> int(count[0]), bool(proved[0]), int(working[0].sum())
/// (16, True, 1)
#[pyfunction]
fn module_ik<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Branches<'py>> {
    let pts = rows::<3>(&points, "points")?;
    let m = &machine.inner;
    let n = pts.len();
    let arrays = py.allow_threads(|| {
        padded(
            solve_chunks(&pts, |c, out| ik_chunk(m, c, out)),
            n,
            MAX_IK_BRANCHES,
        )
    });
    Ok(padded_to_python(py, arrays))
}

/// `module_ik` in compact form, one row per real branch (as `verne ik --all`): returns
/// `(branches[M, 4], config[M, 3], working[M], point[M], offsets[N + 1], proved[N])`, the
/// branches of point i in rows `offsets[i]..offsets[i + 1]` (`point` says the same per row).
///
/// >>> b, config, working, point, offsets, proved = verne.module_ik_compact(m, np.array([[-240.0, -86.0, 1000.0]]))
/// >>> b.shape, offsets.tolist()
/// ((16, 4), [0, 16])
#[pyfunction]
fn module_ik_compact<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Compact<'py>> {
    let pts = rows::<3>(&points, "points")?;
    let m = &machine.inner;
    let n = pts.len();
    let arrays = py.allow_threads(|| compact(solve_chunks(&pts, |c, out| ik_chunk(m, c, out)), n));
    Ok(compact_to_python(py, arrays))
}

/// The machine's branch of the parallel module's inverse kinematics for each platform point,
/// without solving the others where a certified shortcut is sure of it (what `verne ik` does).
///
/// Returns `(sliders, alpha, status)`: `sliders[N, 3]` (mm) and `alpha[N]` (rad), NaN where the
/// point has no working branch; `status[N]` 0 ok, 1 unreachable (no real branch, proved), 2 no
/// working branch, 3 invalid input.
///
/// >>> sliders, alpha, status = verne.module_ik_working(m, np.array([[-240.0, -86.0, 1000.0]]))
/// >>> sliders.round(3).tolist(), status.tolist()
/// ([[368.355, 84.957, 179.033]], [0])
#[pyfunction]
fn module_ik_working<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Working<'py>> {
    let pts = rows::<3>(&points, "points")?;
    let m = &machine.inner;
    let n = pts.len();
    let (sliders, alpha, status) = py.allow_threads(|| {
        let mut sliders = Array2::<f64>::zeros((n, 3));
        let mut alpha = Array1::<f64>::zeros(n);
        let mut status = Array1::<i8>::zeros(n);
        let contiguous = "a new array is contiguous";
        sliders
            .as_slice_mut()
            .expect(contiguous)
            .par_chunks_mut(3 * CHUNK)
            .zip(
                alpha
                    .as_slice_mut()
                    .expect(contiguous)
                    .par_chunks_mut(CHUNK),
            )
            .zip(
                status
                    .as_slice_mut()
                    .expect(contiguous)
                    .par_chunks_mut(CHUNK),
            )
            .zip(pts.par_chunks(CHUNK))
            .for_each(|(((sl, al), st), chunk)| {
                // The core's batched kernel (`verne ik`'s): the working branch four points at
                // a time, every branch where its shortcut is not sure; the lists reused batch
                // by batch so that they stay in cache.
                let mut lists = vec![ik::IkBranches::default(); LIST_BATCH.min(chunk.len())];
                for (b, points) in chunk.chunks(LIST_BATCH).enumerate() {
                    let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
                    ik::solve_working_each(
                        m,
                        points
                            .iter()
                            .zip(lists.iter_mut())
                            .filter(|(p, _)| finite(p))
                            .map(|(p, l)| (nalgebra::Vector3::from(*p), l)),
                    );
                    for (k, (p, out)) in points.iter().zip(&lists).enumerate() {
                        let i = b * LIST_BATCH + k;
                        let (v, code) = if !finite(p) {
                            (None, INVALID_INPUT)
                        } else {
                            match ik::working(out) {
                                Some(b) => (Some([b.rho.x, b.rho.y, b.rho.z, b.alpha]), OK),
                                None if out.is_empty() && out.certificate.proved() => {
                                    (None, UNREACHABLE)
                                }
                                None => (None, NO_WORKING_BRANCH),
                            }
                        };
                        let v = v.unwrap_or([f64::NAN; 4]);
                        sl[3 * i..3 * i + 3].copy_from_slice(&v[..3]);
                        al[i] = v[3];
                        st[i] = code;
                    }
                }
            });
        (sliders, alpha, status)
    });
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
///
/// >>> modes, config, working, count, proved = verne.module_fk(m, np.array([[674.0, 685.0, 250.0]]))
/// >>> int(count[0]), verne.working(modes, working).round(3).tolist()
/// (4, [[-199.799, 355.845, 1242.023, -0.227]])
#[pyfunction]
fn module_fk<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    sliders: PyReadonlyArray2<'py, f64>,
) -> PyResult<Branches<'py>> {
    let rhos = rows::<3>(&sliders, "sliders")?;
    let m = &machine.inner;
    let n = rhos.len();
    let arrays = py.allow_threads(|| {
        padded(
            solve_chunks(&rhos, |c, out| fk_chunk(m, c, out)),
            n,
            MAX_FK_MODES,
        )
    });
    Ok(padded_to_python(py, arrays))
}

/// `module_fk` in compact form, one row per real assembly mode: as `module_ik_compact`.
///
/// >>> modes, config, working, point, offsets, proved = verne.module_fk_compact(m, np.array([[674.0, 685.0, 250.0]]))
/// >>> offsets.tolist(), int(working.sum())
/// ([0, 4], 1)
#[pyfunction]
fn module_fk_compact<'py>(
    py: Python<'py>,
    machine: &PyMachine,
    sliders: PyReadonlyArray2<'py, f64>,
) -> PyResult<Compact<'py>> {
    let rhos = rows::<3>(&sliders, "sliders")?;
    let m = &machine.inner;
    let n = rhos.len();
    let arrays = py.allow_threads(|| compact(solve_chunks(&rhos, |c, out| fk_chunk(m, c, out)), n));
    Ok(compact_to_python(py, arrays))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(module_ik, m)?)?;
    m.add_function(wrap_pyfunction!(module_ik_working, m)?)?;
    m.add_function(wrap_pyfunction!(module_fk, m)?)?;
    m.add_function(wrap_pyfunction!(module_ik_compact, m)?)?;
    m.add_function(wrap_pyfunction!(module_fk_compact, m)?)?;
    Ok(())
}
