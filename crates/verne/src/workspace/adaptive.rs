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
//! under the same assumption; `error_bound_mm3` is that width.

use std::collections::HashMap;

use crate::par::*;
use crate::spec::Machine;

use super::grid::{Bounds, default_bounds, round_bounds};
use super::{Outcome, WorkspaceOptions, classify};

/// The coarse step is the requested step times this, by default (a power of two).
pub const DEFAULT_COARSE_FACTOR: usize = 8;

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
    /// Lattice points by outcome ([`Outcome::index`]); an agreeing cell's points count as its
    /// first corner's (exact for `inside`, approximate for the binding constraints outside).
    pub binding: [u64; 7],
    /// The box of the inside points (mm), if any.
    pub bbox: Option<Bounds>,
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
    let key = |p: [usize; 3]| (p[0] + n[0] * (p[1] + n[1] * p[2])) as u64;
    let point = |p: [usize; 3]| {
        b.min + nalgebra::Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64) * step
    };
    let mut known: HashMap<u64, Outcome> = HashMap::new();
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
        binding: [0; 7],
        bbox: None,
        touches_bounds: false,
    };
    let mut lo = [usize::MAX; 3];
    let mut hi = [0usize; 3];
    let mut inside_cells = 0u64;
    let mut cells: Vec<[usize; 3]> = Vec::new();
    for k in (0..n[2] - 1).step_by(s0) {
        for j in (0..n[1] - 1).step_by(s0) {
            for i in (0..n[0] - 1).step_by(s0) {
                cells.push([i, j, k]);
            }
        }
    }
    let mut s = s0;
    // The points a cell owns along one axis: [c, c + s), and c + s too on the last cell.
    let owned = |c: usize, s: usize, d: usize| if c + s == n[d] - 1 { s + 1 } else { s };
    while !cells.is_empty() {
        // Classify the corners not known yet, in parallel.
        let mut needed: Vec<[usize; 3]> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for c in &cells {
            for corner in corners(*c, s) {
                let kk = key(corner);
                if !known.contains_key(&kk) && seen.insert(kk) {
                    needed.push(corner);
                }
            }
        }
        let classified: Vec<(u64, Outcome)> = needed
            .par_iter()
            .map(|p| (key(*p), classify(m, opts, &point(*p)).outcome))
            .collect();
        summary.classified += classified.len() as u64;
        known.extend(classified);
        progress(summary.classified);
        // Cells whose corners disagree, and (a guard against features thinner than a cell
        // that reach out of the boundary) the cells next to them, are refined.
        let inside = |p: &[usize; 3]| known[&key(*p)] == Outcome::Inside;
        let agree = |c: &[usize; 3]| {
            let first = inside(c);
            corners(*c, s).iter().all(|p| inside(p) == first)
        };
        let mixed: std::collections::HashSet<[usize; 3]> =
            cells.iter().filter(|c| !agree(c)).copied().collect();
        let near_mixed = |c: &[usize; 3]| {
            let step = s as isize;
            (-1isize..=1).any(|dk| {
                (-1isize..=1).any(|dj| {
                    (-1isize..=1).any(|di| {
                        let q = [
                            c[0] as isize + di * step,
                            c[1] as isize + dj * step,
                            c[2] as isize + dk * step,
                        ];
                        q.iter().all(|v| *v >= 0)
                            && mixed.contains(&[q[0] as usize, q[1] as usize, q[2] as usize])
                    })
                })
            })
        };
        let mut next = Vec::new();
        for c in &cells {
            let first = known[&key(*c)];
            let settled = s == 1 || !near_mixed(c);
            if agree(c) && settled {
                // An agreeing cell: its points take the corners' outcome.
                let e = [owned(c[0], s, 0), owned(c[1], s, 1), owned(c[2], s, 2)];
                let count = (e[0] * e[1] * e[2]) as u64;
                summary.binding[first.index()] += count;
                if first == Outcome::Inside {
                    summary.inside_points += count;
                    inside_cells += (s * s * s) as u64;
                    for d in 0..3 {
                        lo[d] = lo[d].min(c[d]);
                        hi[d] = hi[d].max(c[d] + e[d] - 1);
                    }
                }
            } else if s == 1 {
                // A boundary cell of one step: its owned points, each as classified.
                summary.boundary_cells += 1;
                for dk in 0..owned(c[2], 1, 2) {
                    for dj in 0..owned(c[1], 1, 1) {
                        for di in 0..owned(c[0], 1, 0) {
                            let p = [c[0] + di, c[1] + dj, c[2] + dk];
                            let o = known[&key(p)];
                            summary.binding[o.index()] += 1;
                            if o == Outcome::Inside {
                                summary.inside_points += 1;
                                for d in 0..3 {
                                    lo[d] = lo[d].min(p[d]);
                                    hi[d] = hi[d].max(p[d]);
                                }
                            }
                        }
                    }
                }
            } else {
                let h = s / 2;
                for dk in [0, h] {
                    for dj in [0, h] {
                        for di in [0, h] {
                            next.push([c[0] + di, c[1] + dj, c[2] + dk]);
                        }
                    }
                }
            }
        }
        // The points of the finer cells' corners that are already known stay; the others of
        // this level are no longer needed once no cell of the next level touches them.
        cells = next;
        s /= 2;
        if s == 0 {
            break;
        }
    }
    let h3 = step * step * step;
    summary.volume_mm3 = summary.inside_points as f64 * h3;
    summary.volume_lo_mm3 = inside_cells as f64 * h3;
    summary.volume_hi_mm3 = (inside_cells + summary.boundary_cells) as f64 * h3;
    if summary.inside_points > 0 {
        summary.bbox = Some(Bounds {
            min: point(lo),
            max: point(hi),
        });
        summary.touches_bounds = (0..3).any(|d| lo[d] == 0 || hi[d] == n[d] - 1);
    }
    Ok(summary)
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
