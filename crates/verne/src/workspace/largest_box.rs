//! The largest axis-aligned box of grid points all inside a workspace, for any measure of a
//! box that does not decrease when an edge grows (its volume, the largest cube it holds; the
//! same grown by a margin, which bound the boxes of a finer lattice, see `refined_box.rs`).

use std::sync::atomic::{AtomicU64, Ordering};

use crate::par::*;

use super::{GridBox, Outcome, OutcomeGrid};

/// Largest axis-aligned box of grid points all inside, by volume (edges counted in steps,
/// corners on grid points), searched within the index box [lo, hi] of the inside points.
/// `None` when no box has positive volume.
pub fn largest_box(map: &OutcomeGrid, lo: [usize; 3], hi: [usize; 3]) -> Option<GridBox> {
    let inside = |i: usize, j: usize, k: usize| map.at(i, j, k) == Outcome::Inside;
    largest_box_by(&inside, lo, hi, BoxMeasure::Volume).map(|(b, _)| b)
}

/// Largest axis-aligned cube of grid points all inside (edge counted in steps, corners on grid
/// points), searched within [lo, hi]. `None` when no cube has a positive edge.
pub fn largest_cube(map: &OutcomeGrid, lo: [usize; 3], hi: [usize; 3]) -> Option<GridBox> {
    let inside = |i: usize, j: usize, k: usize| map.at(i, j, k) == Outcome::Inside;
    largest_box_by(&inside, lo, hi, BoxMeasure::Cube).map(|(b, _)| cube_in(&b))
}

/// The cube of a box's shortest edge at the box's first corner.
pub fn cube_in(b: &GridBox) -> GridBox {
    let e = b.edges().into_iter().min().unwrap_or(0);
    GridBox {
        lo: b.lo,
        hi: b.lo.map(|v| v + e),
    }
}

/// What makes one box larger than another: a measure of its edges (in steps) that does not
/// decrease when an edge grows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoxMeasure {
    /// The volume, in cubic steps.
    Volume,
    /// The volume of the box grown by `margin` steps along each edge: (a + m)(b + m)(c + m).
    /// A box of one point or a plane of points counts (its grown volume is positive).
    GrownVolume(f64),
    /// The volume of the largest cube inside the box: its shortest edge, cubed.
    Cube,
    /// The volume of that cube grown by `margin` steps along each edge.
    GrownCube(f64),
}

impl BoxMeasure {
    fn of(self, edges: [usize; 3]) -> f64 {
        let [a, b, c] = edges.map(|e| e as f64);
        match self {
            BoxMeasure::Volume => a * b * c,
            BoxMeasure::GrownVolume(m) => (a + m) * (b + m) * (c + m),
            BoxMeasure::Cube => a.min(b).min(c).powi(3),
            BoxMeasure::GrownCube(m) => (a.min(b).min(c) + m).powi(3),
        }
    }

    /// A bound on the measure of any box whose layer holds `count` points in a rectangle of
    /// at most `nx` x `ny` points, with `dz` steps along z.
    fn bound(self, count: u64, nx: usize, ny: usize, dz: usize) -> f64 {
        let dz = dz as f64;
        match self {
            // (a)(b) edges <= (points along x - 1)(points along y - 1) < count.
            BoxMeasure::Volume => count as f64 * dz,
            // (a + m)(b + m) = ab + m (a + b) + m^2 with ab < count, a < nx, b < ny.
            BoxMeasure::GrownVolume(m) => (count as f64 + m * (nx + ny) as f64 + m * m) * (dz + m),
            // min(a, b)^2 <= ab < count.
            BoxMeasure::Cube => (count as f64).sqrt().min(dz).powi(3),
            BoxMeasure::GrownCube(m) => ((count as f64).sqrt().min(dz) + m).powi(3),
        }
    }
}

/// The box of [`BoxMeasure`] largest among the boxes whose grid points are all inside (by
/// `inside(i, j, k)`), searched within [lo, hi]; with its measure. `None` when no box has a
/// positive measure.
///
/// Exhaustive over every pair of z layers k0 <= k1: the AND of the layers' inside masks, then
/// the best rectangle of that 2D mask by the histogram-and-stack method (every maximal
/// rectangle is visited, so any measure that does not decrease with width and height is
/// maximised). O(nz^2 nx ny) at worst, pruned: once the measure's bound for the mask's count
/// and the tallest box left cannot beat the best box, the inner loop stops. The first layers k0
/// in parallel, the first best kept: the same box whatever the threads.
pub fn largest_box_by(
    inside: &dyn Fn(usize, usize, usize) -> bool,
    lo: [usize; 3],
    hi: [usize; 3],
    measure: BoxMeasure,
) -> Option<(GridBox, f64)> {
    if lo.iter().zip(&hi).any(|(l, h)| l > h) {
        return None;
    }
    let nx = hi[0] - lo[0] + 1;
    let ny = hi[1] - lo[1] + 1;
    let layer = |k: usize| -> Vec<bool> {
        let mut v = Vec::with_capacity(nx * ny);
        for j in lo[1]..=hi[1] {
            for i in lo[0]..=hi[0] {
                v.push(inside(i, j, k));
            }
        }
        v
    };
    let layers: Vec<Vec<bool>> = (lo[2]..=hi[2]).map(layer).collect();
    let nz = layers.len();
    // The best measure any k0 has found so far (the bits of a non-negative f64 order as the
    // numbers do): a k0 stops where it cannot reach it. Strictly below it, so a k0 is never cut
    // short of a box as large as the best: each k0's own best is the same whatever the
    // threads, and the first k0 of the largest measure wins, as in a sequential search.
    let shared = AtomicU64::new(0f64.to_bits());
    let per_k0: Vec<(f64, Option<GridBox>)> = (0..nz)
        .into_par_iter()
        .map(|k0| {
            let reached = || f64::from_bits(shared.load(Ordering::Relaxed));
            let mut best = 0.0f64;
            let mut best_box = None;
            let mut heights = vec![0usize; nx];
            let mut stack: Vec<(usize, usize)> = Vec::with_capacity(nx + 1);
            let mut mask = layers[k0].clone();
            for (k1, layer) in layers.iter().enumerate().skip(k0) {
                if k1 > k0 {
                    for (a, b) in mask.iter_mut().zip(layer) {
                        *a &= *b;
                    }
                }
                let count = mask.iter().filter(|&&b| b).count() as u64;
                let tallest = measure.bound(count, nx, ny, nz - 1 - k0);
                if count == 0 || tallest <= best || tallest < reached() {
                    break;
                }
                let dz = k1 - k0;
                let here = measure.bound(count, nx, ny, dz);
                if here <= best || here < reached() {
                    continue;
                }
                // The best rectangle of the mask.
                heights.iter_mut().for_each(|h| *h = 0);
                let mut best2 = best;
                let mut rect = None;
                for j in 0..ny {
                    for (h, &m) in heights.iter_mut().zip(&mask[j * nx..(j + 1) * nx]) {
                        *h = if m { *h + 1 } else { 0 };
                    }
                    stack.clear();
                    for i in 0..=nx {
                        let h = heights.get(i).copied().unwrap_or(0);
                        let mut start = i;
                        while let Some(&(s, sh)) = stack.last() {
                            if sh < h {
                                break;
                            }
                            stack.pop();
                            if sh >= 1 {
                                let val = measure.of([i - s - 1, sh - 1, dz]);
                                if val > best2 {
                                    best2 = val;
                                    rect = Some([s, i - 1, j + 1 - sh, j]);
                                }
                            }
                            start = s;
                        }
                        stack.push((start, h));
                    }
                }
                if let Some(r) = rect {
                    best = best2;
                    shared.fetch_max(best.to_bits(), Ordering::Relaxed);
                    best_box = Some(GridBox {
                        lo: [lo[0] + r[0], lo[1] + r[2], lo[2] + k0],
                        hi: [lo[0] + r[1], lo[1] + r[3], lo[2] + k1],
                    });
                }
            }
            (best, best_box)
        })
        .collect();
    // The first k0 of the largest measure.
    let mut best: Option<(GridBox, f64)> = None;
    for (v, b) in per_k0 {
        if let Some(b) = b
            && best.is_none_or(|(_, bv)| v > bv)
        {
            best = Some((b, v));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every box of a small random set against the search, by brute force over all corner
    /// pairs, for both measures.
    #[test]
    fn the_search_finds_the_brute_force_best() {
        let mut state = 12345u64;
        for trial in 0..60 {
            let n = [5 + trial % 3, 4 + trial % 4, 3 + trial % 5];
            let cells: Vec<bool> = (0..n[0] * n[1] * n[2])
                .map(|_| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (state >> 33) % 10 < 8
                })
                .collect();
            let inside = |i: usize, j: usize, k: usize| cells[i + n[0] * (j + n[1] * k)];
            let hi = n.map(|v| v - 1);
            for measure in [
                BoxMeasure::Volume,
                BoxMeasure::GrownVolume(1.5),
                BoxMeasure::Cube,
                BoxMeasure::GrownCube(0.75),
            ] {
                let mut brute = 0.0f64;
                for lo in itertools3(n) {
                    for up in itertools3(n) {
                        if (0..3).any(|d| up[d] < lo[d]) {
                            continue;
                        }
                        let all = (lo[2]..=up[2]).all(|k| {
                            (lo[1]..=up[1]).all(|j| (lo[0]..=up[0]).all(|i| inside(i, j, k)))
                        });
                        if all {
                            brute = brute.max(measure.of([0, 1, 2].map(|d| up[d] - lo[d])));
                        }
                    }
                }
                let found = largest_box_by(&inside, [0; 3], hi, measure);
                match found {
                    None => assert_eq!(brute, 0.0, "trial {trial} {measure:?}"),
                    Some((b, v)) => {
                        assert_eq!(v, brute, "trial {trial} {measure:?}");
                        assert_eq!(measure.of(b.edges()), v);
                        for k in b.lo[2]..=b.hi[2] {
                            for j in b.lo[1]..=b.hi[1] {
                                for i in b.lo[0]..=b.hi[0] {
                                    assert!(inside(i, j, k), "trial {trial}: {b:?}");
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// Sets with many boxes of the largest measure (a full block with notches): the box kept
    /// is the one the search meets first in (k0, k1, row, column) order, found by brute force
    /// in that order, whatever the threads.
    #[test]
    fn ties_keep_the_first_box_whatever_the_threads() {
        let n = [9, 8, 12];
        let notched = |i: usize, j: usize, k: usize| !((i + 2 * j + 3 * k) % 7 == 0 && k % 4 == 1);
        let hi = n.map(|v| v - 1);
        for measure in [BoxMeasure::Volume, BoxMeasure::Cube] {
            let run = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| largest_box_by(&notched, [0; 3], hi, measure))
            };
            let one = run(1);
            for threads in [2, 3, 8] {
                assert_eq!(run(threads), one, "{measure:?} with {threads} threads");
            }
            // The first in the search's order: lowest k0, then k1, then the rectangle's last
            // row j1, then its column i1 + 1 (where the stack pops it), among the largest.
            let (b, v) = one.unwrap();
            let mut first: Option<([usize; 4], GridBox)> = None;
            for lo in itertools3(n) {
                for up in itertools3(n) {
                    if (0..3).any(|d| up[d] < lo[d])
                        || measure.of([0, 1, 2].map(|d| up[d] - lo[d])) != v
                    {
                        continue;
                    }
                    let all = (lo[2]..=up[2]).all(|k| {
                        (lo[1]..=up[1]).all(|j| (lo[0]..=up[0]).all(|i| notched(i, j, k)))
                    });
                    let order = [lo[2], up[2], up[1], up[0]];
                    if all && first.is_none_or(|(o, _)| order < o) {
                        first = Some((order, GridBox { lo, hi: up }));
                    }
                }
            }
            let (_, expected) = first.unwrap();
            assert_eq!(b.lo[2], expected.lo[2], "{measure:?}: the first k0");
            assert_eq!(b.hi[2], expected.hi[2], "{measure:?}: the first k1");
        }
    }

    fn itertools3(n: [usize; 3]) -> impl Iterator<Item = [usize; 3]> {
        (0..n[2]).flat_map(move |k| (0..n[1]).flat_map(move |j| (0..n[0]).map(move |i| [i, j, k])))
    }
}
