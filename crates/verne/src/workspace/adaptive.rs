//! The workspace at a fine step by adaptive sampling: classify a coarse lattice, then refine
//! (halve, as an octree) only the cells whose eight corners disagree on inside or outside, and
//! their neighbours, down to the requested step. The cost grows with the boundary's area, not
//! the volume. Outside the workspace, a cell whose corners are all outside gives its points the
//! outcome of its first corner: the shares of the binding constraints are those of the corners
//! there, not of every point.
//!
//! The fine lattice is the uniform grid of [`super::compute`] at the same step and origin,
//! extended so that the coarse cells tile it (the extension lies beyond the default bounds,
//! outside the workspace). Every fine lattice point is owned by one leaf cell (half-open cells,
//! the last one closed): a cell whose corners agree gives its outcome to all its points without
//! classifying them; a cell of one step is a boundary cell, all its points classified. So the
//! count of inside points, and the volume `inside x step^3`, are the uniform grid's wherever no
//! feature hides inside a coarse cell with agreeing corners (the coarse step bounds the size of
//! what can hide; tests compare with the uniform grid).
//!
//! The error bound: the true volume lies between the volume of the cells whose corners are all
//! inside and that plus the volume of the boundary cells of one step (corners disagreeing),
//! under the same assumption; `error_bound_mm3` is that width. It counts every boundary cell as
//! wholly unknown, so it narrows only linearly with the step (about 1 % at 1 mm on the default
//! machine). The boundary cells are also sampled: a pseudo-random subset of them (chosen by a
//! hash of the cell's position, so the same whatever the threads), one point at a
//! pseudo-random place in each, classified. The share of those points inside estimates the
//! share of the boundary cells' volume inside, and Hoeffding's inequality bounds its error
//! with 99.7 % confidence, whatever the shape: `volume_sampled_mm3` +- `sampled_half_width_mm3`,
//! about 0.004 % of the volume at 1 mm on the default machine for [`BOUNDARY_SAMPLES`] points.

use crate::math::sampling::{hoeffding_half_width, splitmix64, unit_offsets};
use crate::par::*;
use crate::spec::Machine;

use super::GridBox;
use super::grid::{Bounds, default_bounds, round_bounds};
use super::refined_box::{SubLattice, exact_largest_box, refined_largest_box};
use super::{WorkspaceOptions, classify};

/// The coarse step is the requested step times this, by default (a power of two).
pub const DEFAULT_COARSE_FACTOR: usize = 8;

/// Boundary cells sampled, about (all of them when there are fewer).
pub const BOUNDARY_SAMPLES: u64 = 200_000;

pub use crate::math::sampling::SAMPLED_CONFIDENCE_DELTA;

/// Up to this many fine lattice points in the box of the inside points, the largest box and
/// cube are searched exhaustively on the fine lattice (exact, as on the uniform grid); above,
/// grown from those of the coarse lattice and of a lattice of every fourth point (coarse
/// factor 8) if it has at most twice this many, with bounds (`refined_box.rs`). On the default
/// machine's platform workspace: exact down to a 5 mm step (7 million points, 1 s), every
/// fourth point at 4, 2 and 1 mm (13.6 million at 1 mm, about 4 s).
pub const EXACT_BOX_POINTS: u64 = 8_000_000;

/// What an adaptive run found.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveSummary {
    /// The fine step and the coarse step (mm).
    pub step: f64,
    pub coarse_step: f64,
    /// Lattice points along x, y, z (the extended fine lattice) and in all.
    pub lattice: [usize; 3],
    pub lattice_points: u64,
    /// Points classified (the cost).
    pub classified: u64,
    /// Fine lattice points inside (classified or given by an agreeing cell).
    pub inside_points: u64,
    /// `inside_points x step^3` (mm^3): the uniform grid's estimator.
    pub volume_mm3: f64,
    /// Volume of the cells with all corners inside, and that plus the boundary cells (mm^3).
    pub volume_lo_mm3: f64,
    pub volume_hi_mm3: f64,
    /// Boundary cells of one step (corners disagreeing).
    pub boundary_cells: u64,
    /// Boundary cells sampled (one point each) and those points found inside.
    pub sampled_cells: u64,
    pub sampled_inside: u64,
    /// The volume from the sampled boundary cells (mm^3): `volume_lo_mm3` plus the share of
    /// the sampled points inside times the boundary cells' volume; and the half-width of its
    /// 99.7 % confidence interval (Hoeffding) (mm^3).
    pub volume_sampled_mm3: f64,
    pub sampled_half_width_mm3: f64,
    /// Lattice points by outcome ([`Outcome::index`](super::Outcome::index)); an agreeing
    /// cell's points count as its first corner's (exact for `inside`, approximate for the
    /// binding constraints outside).
    pub binding: [u64; 7],
    /// The box of the inside points (mm), if any.
    pub bbox: Option<Bounds>,
    /// The largest axis-aligned box of fine lattice points found inside (mm) and its volume
    /// (mm^3): the coarse lattice's largest box grown face by face on the fine lattice
    /// (`refined_box.rs`); and a volume no box of the fine lattice exceeds (mm^3).
    pub largest_box: Option<Bounds>,
    pub largest_box_mm3: f64,
    pub largest_box_upper_mm3: f64,
    /// The largest cube found the same way (mm), its volume and its bound (mm^3).
    pub largest_cube: Option<Bounds>,
    pub largest_cube_mm3: f64,
    pub largest_cube_upper_mm3: f64,
    /// Fine points examined to grow the largest box and cube, or to search them exhaustively
    /// (in a leaf cell whose corners agree, or classified; not in `classified`).
    pub box_points_examined: u64,
    /// Whether the largest box and cube were searched exhaustively on the fine lattice (their
    /// bounds are then their volumes).
    pub box_exact: bool,
    /// The step (mm) of the finest lattice whose largest box and cube were grown, and that the
    /// bounds come from (the coarse lattice's too, the better kept): half the coarse step or
    /// the coarse step; the step itself when exact.
    pub box_lattice_step: f64,
    /// An inside point on the lattice's outer layer: the bounds may cut the workspace.
    pub touches_bounds: bool,
}

impl AdaptiveSummary {
    /// The width of the volume's bracket (mm^3).
    pub fn error_bound_mm3(&self) -> f64 {
        self.volume_hi_mm3 - self.volume_lo_mm3
    }
}

/// The adaptive workspace of `opts` (its step is the fine step), coarse step = step x
/// `coarse_factor` (a power of two, at least 2). `progress` receives the points classified.
pub fn compute_adaptive(
    m: &Machine,
    opts: &WorkspaceOptions,
    coarse_factor: usize,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<AdaptiveSummary, String> {
    compute_adaptive_with(m, opts, coarse_factor, EXACT_BOX_POINTS, progress)
}

/// [`compute_adaptive`] with the largest box and cube searched exhaustively on the fine lattice
/// up to `exact_box_points` points in the inside points' box, grown from every (coarse factor /
/// 2)-th point of it up to twice as many (0: always grown from the coarse lattice's).
pub fn compute_adaptive_with(
    m: &Machine,
    opts: &WorkspaceOptions,
    coarse_factor: usize,
    exact_box_points: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<AdaptiveSummary, String> {
    if !(coarse_factor >= 2 && coarse_factor.is_power_of_two()) {
        return Err(format!(
            "the coarse factor must be a power of two >= 2, got {coarse_factor}"
        ));
    }
    let step = opts.step;
    if !(step.is_finite() && step > 0.0) {
        return Err(format!(
            "the step must be a positive number of mm, got {step}"
        ));
    }
    if !opts.tool_length.is_finite() {
        return Err("the tool length must be a finite number of mm".into());
    }
    let b = match opts.bounds {
        Some(b) => b,
        None => round_bounds(&default_bounds(m, opts.of, opts.tool_length), step),
    };
    let s0 = coarse_factor;
    let mut n = [0usize; 3];
    for (d, n_d) in n.iter_mut().enumerate() {
        let (lo, hi) = (b.min[d], b.max[d]);
        if !(lo.is_finite() && hi.is_finite()) || lo > hi {
            return Err(format!(
                "bounds: axis {d} range [{lo}, {hi}] is empty or not finite"
            ));
        }
        let cells = ((hi - lo) / step + 1e-9).floor();
        // Extended up to a whole number of coarse cells (at least one).
        let coarse = (cells / s0 as f64).ceil().max(1.0);
        if coarse * s0 as f64 > 1e7 {
            return Err(format!(
                "{} lattice steps along axis {d}: increase the step or narrow the bounds",
                coarse * s0 as f64
            ));
        }
        *n_d = coarse as usize * s0 + 1;
    }
    let lattice = Lattice { n };
    let point = |p: [usize; 3]| {
        b.min + nalgebra::Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64) * step
    };
    let mut summary = AdaptiveSummary {
        step,
        coarse_step: step * s0 as f64,
        lattice: n,
        lattice_points: (n[0] as u64) * (n[1] as u64) * (n[2] as u64),
        classified: 0,
        inside_points: 0,
        volume_mm3: 0.0,
        volume_lo_mm3: 0.0,
        volume_hi_mm3: 0.0,
        boundary_cells: 0,
        sampled_cells: 0,
        sampled_inside: 0,
        volume_sampled_mm3: 0.0,
        sampled_half_width_mm3: 0.0,
        binding: [0; 7],
        bbox: None,
        largest_box: None,
        largest_box_mm3: 0.0,
        largest_box_upper_mm3: 0.0,
        largest_cube: None,
        largest_cube_mm3: 0.0,
        largest_cube_upper_mm3: 0.0,
        box_points_examined: 0,
        box_exact: false,
        box_lattice_step: step,
        touches_bounds: false,
    };
    // A place in lattice units (a lattice point has whole coordinates).
    let classify_point = |p: [f64; 3]| {
        let at = b.min + nalgebra::Vector3::from(p) * step;
        classify(m, opts, &at).outcome.index() as u8
    };
    // Keys of 32 bits where the lattice allows (1 mm steps over the default machine's box do):
    // half the memory of the levels' lists.
    let refined = if summary.lattice_points <= u64::from(u32::MAX) {
        refine::<u32>(&lattice, s0, &classify_point, progress)
    } else {
        refine::<u64>(&lattice, s0, &classify_point, progress)
    };
    let (tally, classified) = (refined.tally, refined.classified);
    summary.classified = classified;
    summary.inside_points = tally.inside_points;
    summary.boundary_cells = tally.boundary_cells;
    summary.sampled_cells = tally.sampled_cells;
    summary.sampled_inside = tally.sampled_inside;
    summary.binding = tally.binding;
    let inside_cells = tally.inside_cells;
    let (lo, hi) = (tally.lo, tally.hi);
    let h3 = step * step * step;
    summary.volume_mm3 = summary.inside_points as f64 * h3;
    summary.volume_lo_mm3 = inside_cells as f64 * h3;
    summary.volume_hi_mm3 = (inside_cells + summary.boundary_cells) as f64 * h3;
    let boundary_mm3 = summary.boundary_cells as f64 * h3;
    summary.volume_sampled_mm3 = summary.volume_lo_mm3;
    if summary.sampled_cells > 0 {
        let share = summary.sampled_inside as f64 / summary.sampled_cells as f64;
        summary.volume_sampled_mm3 += share * boundary_mm3;
        summary.sampled_half_width_mm3 = hoeffding_half_width(summary.sampled_cells) * boundary_mm3;
    }
    if summary.inside_points > 0 {
        summary.bbox = Some(Bounds {
            min: point(lo),
            max: point(hi),
        });
        summary.touches_bounds = (0..3).any(|d| lo[d] == 0 || hi[d] == n[d] - 1);
        let coarse_n = n.map(|v| (v - 1) / s0 + 1);
        // A point in a leaf cell whose corners agree has their outcome (the volume's
        // assumption); others are classified.
        let in_leaf = |leaves: &[(usize, Vec<u64>)], p: [usize; 3]| {
            leaves.iter().any(|(size, keys)| {
                let cell = p.map(|v| v / size * size);
                keys.binary_search(&lattice.key::<u64>(cell)).is_ok()
            })
        };
        let inside_at = |p: [usize; 3]| {
            in_leaf(&refined.inside_leaves, p)
                || !in_leaf(&refined.outside_leaves, p)
                    && classify_point(p.map(|v| v as f64)) == INSIDE
        };
        let bbox = GridBox { lo, hi };
        // Every fine point of the box searched exhaustively when they are at most
        // `exact_box_points`; else the box and cube grown from the coarse lattice's and, when
        // it has at most twice as many points, from those of the lattice of every (s0 / 2)-th
        // fine point of the box (whose points lie mostly in the leaf cells of the two coarsest
        // levels, known without classifying them).
        let sub_points = |m: usize| -> u64 {
            bbox.edges()
                .iter()
                .map(|&e| e.div_ceil(m) as u64 + 1)
                .product()
        };
        let m = if sub_points(1) <= exact_box_points {
            1
        } else if s0 >= 4 && sub_points(s0 / 2) <= 2 * exact_box_points {
            s0 / 2
        } else {
            s0
        };
        summary.box_exact = m == 1;
        let r = if summary.box_exact {
            exact_largest_box(bbox, &inside_at)
        } else {
            let coarse = SubLattice {
                origin: [0; 3],
                step: s0,
                n: coarse_n,
                inside: refined.coarse_inside.clone(),
            };
            let mut r = refined_largest_box(&coarse, n, bbox, &inside_at);
            summary.box_lattice_step = step * s0 as f64;
            if m < s0 {
                // Both results hold: the larger boxes, the smaller bounds.
                let sub = SubLattice::of_box(bbox, m, &inside_at);
                r = r.better(refined_largest_box(&sub, n, bbox, &inside_at));
                r.examined += sub.len();
                summary.box_lattice_step = step * m as f64;
            }
            r
        };
        // (corners in mm, volume in mm^3) of a box of fine indices and steps^3.
        let in_mm = |found: Option<(GridBox, f64)>| {
            found.map_or((None, 0.0), |(g, v)| {
                let b = Bounds {
                    min: point(g.lo),
                    max: point(g.hi),
                };
                (Some(b), v * h3)
            })
        };
        (summary.largest_box, summary.largest_box_mm3) = in_mm(r.found);
        (summary.largest_cube, summary.largest_cube_mm3) = in_mm(r.cube);
        summary.largest_box_upper_mm3 = r.upper * h3;
        summary.largest_cube_upper_mm3 = r.cube_upper * h3;
        summary.box_points_examined = r.examined;
    }
    Ok(summary)
}

/// The octree, level by level from the coarse cells (size `s0`) down to cells of one step.
fn refine<K: Key>(
    lattice: &Lattice,
    s0: usize,
    classify_point: &(dyn Fn([f64; 3]) -> u8 + Sync),
    progress: &(dyn Fn(u64) + Sync),
) -> Refined {
    let n = lattice.n;
    let mut coarse_inside = Vec::new();
    let mut inside_leaves = Vec::new();
    let mut outside_leaves = Vec::new();
    let mut tally = Tally::empty();
    let mut classified = 0u64;
    // The cells of this level by their first corner's key, sorted; at first every coarse cell.
    let mut cells: Vec<K> = Vec::new();
    for k in (0..n[2] - 1).step_by(s0) {
        for j in (0..n[1] - 1).step_by(s0) {
            for i in (0..n[0] - 1).step_by(s0) {
                cells.push(lattice.key([i, j, k]));
            }
        }
    }
    // The outcomes of the previous level's corners: a level keeps only its own corners, so
    // memory follows the boundary, not every level's points.
    let mut known = Outcomes::<K>::default();
    let mut s = s0;
    loop {
        let (corners_here, new_points) =
            level_corners(lattice, &cells, s, &[&known], classify_point);
        classified += new_points;
        known = corners_here;
        progress(classified);
        if s == s0 {
            // Every coarse lattice point is a corner of the first level.
            for k in (0..n[2]).step_by(s0) {
                for j in (0..n[1]).step_by(s0) {
                    for i in (0..n[0]).step_by(s0) {
                        coarse_inside.push(known.at(lattice.key([i, j, k])) == INSIDE);
                    }
                }
            }
        }
        let (level, parents) = decide_level(lattice, &cells, s, &known);
        tally = tally.merge(&level);
        if s >= s0 / 2 && s >= 2 {
            // The leaf cells of the two coarsest levels (most of the interior and of the
            // outside), for the largest box: a point in one has its corners' outcome without
            // being classified.
            let leaves = |inside: bool| -> Vec<u64> {
                cells
                    .par_iter()
                    .filter(|&&c| {
                        parents.binary_search(&c).is_err() && (known.at(c) == INSIDE) == inside
                    })
                    .map(|&c| c.index() as u64)
                    .collect()
            };
            inside_leaves.push((s, leaves(true)));
            outside_leaves.push((s, leaves(false)));
        }
        drop(cells);
        if s == 2 {
            // The last level, cells of one step, slab by slab: it is most of the points. A cell
            // to halve gives about 4/3 boundary cells (1.33 to 1.35 on the default machine
            // from 8 to 1 mm): sample about BOUNDARY_SAMPLES of them.
            let expected = (parents.len() as u64 * 4 / 3).max(1);
            let sampler = Sampler {
                threshold: if expected <= BOUNDARY_SAMPLES {
                    u64::MAX
                } else {
                    (BOUNDARY_SAMPLES as f64 / expected as f64 * u64::MAX as f64) as u64
                },
                classify_point,
            };
            let (last, new_points) = finest_level(lattice, &parents, &known, &sampler, &|c| {
                progress(classified + c)
            });
            classified += new_points;
            tally = tally.merge(&last);
            break;
        }
        let h = s / 2;
        // Eight children a parent, written in place (no growing vector), then sorted.
        cells = vec![K::from_index(0); 8 * parents.len()];
        cells
            .par_chunks_mut(8)
            .zip(parents.par_iter())
            .for_each(|(out, &p)| {
                for (o, c) in out.iter_mut().zip(children(lattice, p, h)) {
                    *o = c;
                }
            });
        drop(parents);
        cells.par_sort_unstable();
        s = h;
        if cells.is_empty() {
            break;
        }
    }
    Refined {
        tally,
        classified,
        coarse_inside,
        inside_leaves,
        outside_leaves,
    }
}

/// What [`refine`] found.
struct Refined {
    /// What the leaf cells add up to.
    tally: Tally,
    /// Points classified.
    classified: u64,
    /// Which points of the coarse lattice (every `s0`-th fine point, x fastest) are inside.
    coarse_inside: Vec<bool>,
    /// For the two coarsest levels, the cell size and the sorted keys (64-bit) of the leaf
    /// cells whose corners are all inside, and of those whose corners are all outside.
    inside_leaves: Vec<(usize, Vec<u64>)>,
    outside_leaves: Vec<(usize, Vec<u64>)>,
}

/// A lattice point's key: its index `i + n0 (j + n1 k)`, in 32 or 64 bits.
trait Key: Copy + Ord + Send + Sync + Default {
    fn from_index(i: usize) -> Self;
    fn index(self) -> usize;
}

impl Key for u32 {
    fn from_index(i: usize) -> u32 {
        i as u32
    }
    fn index(self) -> usize {
        self as usize
    }
}

impl Key for u64 {
    fn from_index(i: usize) -> u64 {
        i as u64
    }
    fn index(self) -> usize {
        self as usize
    }
}

/// Cells of one step added up together in the last level (a slab: whole z planes of them).
const SLAB_CELLS: usize = 1 << 17;

/// Cells whose corners are listed together (their repeats dropped) before the lists are joined.
const CORNER_RUN: usize = 1 << 17;

/// Outcome index of an inside point ([`super::Outcome::index`]).
const INSIDE: u8 = 0;

/// The extended fine lattice: `n` points along each axis, a point's key `i + n0 (j + n1 k)`
/// (sorting keys sorts by z, then y, then x).
#[derive(Clone, Copy)]
struct Lattice {
    n: [usize; 3],
}

impl Lattice {
    fn key<K: Key>(&self, p: [usize; 3]) -> K {
        K::from_index(p[0] + self.n[0] * (p[1] + self.n[1] * p[2]))
    }

    fn at<K: Key>(&self, key: K) -> [usize; 3] {
        let k = key.index();
        [
            k % self.n[0],
            (k / self.n[0]) % self.n[1],
            k / (self.n[0] * self.n[1]),
        ]
    }

    /// The points a cell of size `s` at `c` owns along axis `d`: [c, c + s), and c + s too on
    /// the last cell.
    fn owned(&self, c: usize, s: usize, d: usize) -> usize {
        if c + s == self.n[d] - 1 { s + 1 } else { s }
    }
}

/// The outcomes of one level's points: sorted keys and [`super::Outcome::index`] values.
#[derive(Default)]
struct Outcomes<K> {
    keys: Vec<K>,
    outcome: Vec<u8>,
}

impl<K: Key> Outcomes<K> {
    fn get(&self, key: K) -> Option<u8> {
        self.keys.binary_search(&key).ok().map(|i| self.outcome[i])
    }

    /// The outcome of a corner of this level (every corner was classified or carried over).
    fn at(&self, key: K) -> u8 {
        self.get(key).unwrap_or(u8::MAX)
    }
}

/// What the leaf cells add up to: counts, and the box of the inside points (lattice indices).
#[derive(Clone, Copy)]
struct Tally {
    inside_points: u64,
    inside_cells: u64,
    boundary_cells: u64,
    sampled_cells: u64,
    sampled_inside: u64,
    binding: [u64; 7],
    lo: [usize; 3],
    hi: [usize; 3],
}

impl Tally {
    fn empty() -> Tally {
        Tally {
            inside_points: 0,
            inside_cells: 0,
            boundary_cells: 0,
            sampled_cells: 0,
            sampled_inside: 0,
            binding: [0; 7],
            lo: [usize::MAX; 3],
            hi: [0; 3],
        }
    }

    fn include(&mut self, lo: [usize; 3], hi: [usize; 3]) {
        for d in 0..3 {
            self.lo[d] = self.lo[d].min(lo[d]);
            self.hi[d] = self.hi[d].max(hi[d]);
        }
    }

    /// A cell of size `s` whose corners agree on `first`: its points take that outcome.
    fn agreeing_cell(&mut self, lattice: &Lattice, c: [usize; 3], s: usize, first: u8) {
        let e = [0, 1, 2].map(|d| lattice.owned(c[d], s, d));
        let count = (e[0] * e[1] * e[2]) as u64;
        self.binding[first as usize] += count;
        if first == INSIDE {
            self.inside_points += count;
            self.inside_cells += (s * s * s) as u64;
            self.include(c, [c[0] + e[0] - 1, c[1] + e[1] - 1, c[2] + e[2] - 1]);
        }
    }

    /// A cell of one step: agreeing, or a boundary cell whose owned points count each as
    /// classified (and that `sampler` may sample). `known` holds its corners.
    fn finest_cell<K: Key>(
        &mut self,
        lattice: &Lattice,
        c: [usize; 3],
        known: &Outcomes<K>,
        sampler: &Sampler<'_>,
    ) {
        let first = known.at(lattice.key(c));
        let agree = corners(c, 1)
            .iter()
            .all(|p| (known.at(lattice.key(*p)) == INSIDE) == (first == INSIDE));
        if agree {
            self.agreeing_cell(lattice, c, 1, first);
            return;
        }
        self.boundary_cells += 1;
        if let Some(inside) = sampler.sample(lattice.key::<u64>(c), c) {
            self.sampled_cells += 1;
            self.sampled_inside += u64::from(inside);
        }
        for dk in 0..lattice.owned(c[2], 1, 2) {
            for dj in 0..lattice.owned(c[1], 1, 1) {
                for di in 0..lattice.owned(c[0], 1, 0) {
                    let p = [c[0] + di, c[1] + dj, c[2] + dk];
                    let o = known.at(lattice.key(p));
                    self.binding[o as usize] += 1;
                    if o == INSIDE {
                        self.inside_points += 1;
                        self.include(p, p);
                    }
                }
            }
        }
    }

    fn merge(mut self, o: &Tally) -> Tally {
        self.inside_points += o.inside_points;
        self.inside_cells += o.inside_cells;
        self.boundary_cells += o.boundary_cells;
        self.sampled_cells += o.sampled_cells;
        self.sampled_inside += o.sampled_inside;
        for (a, b) in self.binding.iter_mut().zip(o.binding) {
            *a += b;
        }
        self.include(o.lo, o.hi);
        self
    }
}

/// The eight cells of size `h` that halve the cell of size `2 h` at `key`.
fn children<K: Key>(lattice: &Lattice, key: K, h: usize) -> impl Iterator<Item = K> + '_ {
    let c = lattice.at(key);
    (0..8).map(move |k| {
        lattice.key([
            c[0] + (k & 1) * h,
            c[1] + (k >> 1 & 1) * h,
            c[2] + (k >> 2 & 1) * h,
        ])
    })
}

/// The corners of `cells` (size `s`), each once, with their outcomes: taken from `sources`
/// where one knows it, classified (in parallel) otherwise; and how many were classified.
fn level_corners<K: Key>(
    lattice: &Lattice,
    cells: &[K],
    s: usize,
    sources: &[&Outcomes<K>],
    classify_point: &(dyn Fn([f64; 3]) -> u8 + Sync),
) -> (Outcomes<K>, u64) {
    // Neighbouring cells share corners: each run of cells (consecutive keys) drops its repeats
    // before the runs are joined, so the list never holds eight per cell.
    let mut keys: Vec<K> = cells
        .par_chunks(CORNER_RUN)
        .flat_map_iter(|run| {
            let mut k: Vec<K> = run
                .iter()
                .flat_map(|&c| corners(lattice.at(c), s).map(|p| lattice.key(p)))
                .collect();
            k.sort_unstable();
            k.dedup();
            k
        })
        .collect();
    keys.par_sort_unstable();
    keys.dedup();
    let looked_up = |k: K| sources.iter().find_map(|o| o.get(k));
    let outcome: Vec<u8> = keys
        .par_iter()
        .map(|&k| looked_up(k).unwrap_or_else(|| classify_point(lattice.at(k).map(|v| v as f64))))
        .collect();
    let new_points = keys.par_iter().filter(|&&k| looked_up(k).is_none()).count();
    (Outcomes { keys, outcome }, new_points as u64)
}

/// The leaf cells of one level (size `s` >= 2) added up, and the cells to halve: those whose
/// corners disagree and, a guard against features thinner than a cell that reach out of the
/// boundary, the cells next to them. `known` holds every corner of `cells`.
fn decide_level<K: Key>(
    lattice: &Lattice,
    cells: &[K],
    s: usize,
    known: &Outcomes<K>,
) -> (Tally, Vec<K>) {
    let n = lattice.n;
    let inside = |p: [usize; 3]| known.at(lattice.key(p)) == INSIDE;
    let agree = |c: [usize; 3]| {
        let first = inside(c);
        corners(c, s).iter().all(|p| inside(*p) == first)
    };
    let mixed: Vec<K> = cells
        .par_iter()
        .filter(|&&c| !agree(lattice.at(c)))
        .copied()
        .collect();
    let near_mixed = |c: [usize; 3]| {
        let step = s as isize;
        (-1isize..=1).any(|dk| {
            (-1isize..=1).any(|dj| {
                (-1isize..=1).any(|di| {
                    let q = [
                        c[0] as isize + di * step,
                        c[1] as isize + dj * step,
                        c[2] as isize + dk * step,
                    ];
                    (0..3).all(|d| q[d] >= 0 && (q[d] as usize) < n[d])
                        && mixed
                            .binary_search(&lattice.key(q.map(|v| v as usize)))
                            .is_ok()
                })
            })
        })
    };
    cells
        .par_iter()
        .fold(
            || (Tally::empty(), Vec::new()),
            |(mut t, mut halve), &key| {
                let c = lattice.at(key);
                if agree(c) && !near_mixed(c) {
                    t.agreeing_cell(lattice, c, s, known.at(key));
                } else {
                    halve.push(key);
                }
                (t, halve)
            },
        )
        .reduce(
            || (Tally::empty(), Vec::new()),
            |(a, mut ha), (b, hb)| {
                ha.extend(hb);
                (a.merge(&b), ha)
            },
        )
}

/// The last level: the cells of one step that halve `parents` (cells of two steps, sorted),
/// added up slab by slab along z (so that only one slab's points are held), each slab's cells
/// in parallel. A corner's outcome comes from `known` (the level above), from the previous slab
/// (the plane two slabs share), or is classified. Returns the tally and the points classified.
fn finest_level<K: Key>(
    lattice: &Lattice,
    parents: &[K],
    known: &Outcomes<K>,
    sampler: &Sampler<'_>,
    progress: &dyn Fn(u64),
) -> (Tally, u64) {
    let plane = lattice.n[0] * lattice.n[1];
    let mut tally = Tally::empty();
    let mut classified = 0u64;
    let mut previous = Outcomes::<K>::default();
    let mut start = 0;
    while start < parents.len() {
        // Whole planes of parents (z of the parents' first corners), at least SLAB_CELLS.
        let mut end = (start + SLAB_CELLS).min(parents.len());
        while end < parents.len()
            && parents[end].index() / plane == parents[end - 1].index() / plane
        {
            end += 1;
        }
        let cells: Vec<K> = parents[start..end]
            .par_iter()
            .flat_map_iter(|&p| children(lattice, p, 1))
            .collect();
        let (here, new_points) = level_corners(
            lattice,
            &cells,
            1,
            &[known, &previous],
            sampler.classify_point,
        );
        classified += new_points;
        progress(classified);
        let slab = cells
            .par_iter()
            .fold(Tally::empty, |mut t, &key| {
                t.finest_cell(lattice, lattice.at(key), &here, sampler);
                t
            })
            .reduce(Tally::empty, |a, b| a.merge(&b));
        tally = tally.merge(&slab);
        previous = here;
        start = end;
    }
    (tally, classified)
}

/// Which boundary cells are sampled, and where: a hash of the cell's key decides both, so the
/// sample is the same whatever the threads and the order of the slabs.
struct Sampler<'a> {
    /// A cell is sampled when its hash is below this (`u64::MAX`: every cell).
    threshold: u64,
    /// Classifies a place in lattice units.
    classify_point: &'a (dyn Fn([f64; 3]) -> u8 + Sync),
}

impl Sampler<'_> {
    /// Whether a pseudo-random point of the cell of one step at `c` (key `key`) is inside,
    /// if the cell is sampled.
    fn sample(&self, key: u64, c: [usize; 3]) -> Option<bool> {
        let mut state = key;
        if splitmix64(&mut state) > self.threshold {
            return None;
        }
        let u = unit_offsets::<3>(&mut state);
        let p = [0, 1, 2].map(|d| c[d] as f64 + u[d]);
        Some((self.classify_point)(p) == INSIDE)
    }
}

/// The eight corners of the cell of size `s` at `c`.
fn corners(c: [usize; 3], s: usize) -> [[usize; 3]; 8] {
    std::array::from_fn(|k| {
        [
            c[0] + (k & 1) * s,
            c[1] + ((k >> 1) & 1) * s,
            c[2] + ((k >> 2) & 1) * s,
        ]
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::workspace::{Of, PAPER_LAMBDA_BOUNDS};

    /// The 64-bit keys (lattices of 2^32 points or more, never reached by the tests through
    /// `compute_adaptive`) give what the 32-bit keys give, level for level.
    #[test]
    fn both_key_widths_refine_alike() {
        let m = Machine::default_verne();
        let opts = WorkspaceOptions {
            of: Of::Platform,
            tool_length: 0.0,
            step: 20.0,
            bounds: None,
            lambda: PAPER_LAMBDA_BOUNDS,
        };
        let b = round_bounds(&default_bounds(&m, opts.of, 0.0), opts.step);
        let n = [0, 1, 2].map(|d| {
            let cells = ((b.max[d] - b.min[d]) / opts.step + 1e-9).floor();
            (cells / 8.0).ceil().max(1.0) as usize * 8 + 1
        });
        let lattice = Lattice { n };
        let classify_point = |p: [f64; 3]| {
            let at = b.min + nalgebra::Vector3::from(p) * opts.step;
            classify(&m, &opts, &at).outcome.index() as u8
        };
        let r32 = refine::<u32>(&lattice, 8, &classify_point, &|_| {});
        let r64 = refine::<u64>(&lattice, 8, &classify_point, &|_| {});
        let (t32, c32, t64, c64) = (r32.tally, r32.classified, r64.tally, r64.classified);
        assert_eq!(c32, c64);
        assert_eq!(r32.coarse_inside, r64.coarse_inside);
        assert_eq!(r32.inside_leaves, r64.inside_leaves);
        assert_eq!(r32.outside_leaves, r64.outside_leaves);
        assert!(t32.inside_points > 0);
        assert_eq!(
            (
                t32.inside_points,
                t32.inside_cells,
                t32.boundary_cells,
                t32.sampled_inside,
                t32.binding,
                t32.lo,
                t32.hi
            ),
            (
                t64.inside_points,
                t64.inside_cells,
                t64.boundary_cells,
                t64.sampled_inside,
                t64.binding,
                t64.lo,
                t64.hi
            )
        );
        // And what compute_adaptive reports (it takes the 32-bit keys here).
        let a = compute_adaptive(&m, &opts, 8, &|_| {}).unwrap();
        assert_eq!((a.inside_points, a.classified), (t64.inside_points, c64));
    }
}
