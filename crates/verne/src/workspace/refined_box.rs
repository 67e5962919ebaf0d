//! The largest box of an adaptive run (`adaptive.rs`), on the fine lattice without classifying
//! it all: the largest box of the coarse lattice (every `s0`-th point), then grown face by face
//! one fine step at a time while every fine point of the new face is inside, until no face can
//! move; grown also from the box that bounds the rest and from the cubes below, the largest
//! result kept. A point of a new face is inside when it lies in a leaf cell of the octree's two
//! coarsest levels whose corners are all inside (most of a face, away from the boundary), and
//! is classified otherwise; the interior of the coarse box is taken from its coarse points:
//! both under the assumption the adaptive volume makes (a cell whose corners agree is all
//! inside or all outside).
//!
//! And a bound: no box of the fine lattice is larger. A fine box B spans fine indices [p, q]
//! along each axis; the coarse points in it form a box of the coarse lattice, all inside, whose
//! edge is at least (q - p) - 2 (s0 - 1) fine steps. So B's volume is at most the largest volume
//! of a coarse box grown by 2 (s0 - 1) fine steps along each edge ([`BoxMeasure::GrownVolume`],
//! exhaustive on the coarse lattice), or, when B holds no coarse point along some axis (its
//! extent there is at most s0 - 2 steps), a slab of that thickness across the inside points'
//! bounding box.
//!
//! The largest cube likewise: the coarse lattice's (at the first corner and at the middle of
//! the coarse box of the longest shortest edge, and of the one that bounds the rest), grown one
//! fine step along each axis at a time (the face of each axis that is not blocked), with the
//! bound of the coarse cubes grown by the same margin ([`BoxMeasure::GrownCube`]).

use crate::par::*;

use super::GridBox;
use super::largest_box::{BoxMeasure, cube_in, largest_box_by};

/// The largest box found and the bound, in fine lattice indices and fine steps^3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RefinedBox {
    /// The box found (fine indices) and its volume (steps^3).
    pub found: Option<(GridBox, f64)>,
    /// No box of the fine lattice has a larger volume (steps^3).
    pub upper: f64,
    /// The largest cube found (fine indices) and its volume, and the bound (steps^3).
    pub cube: Option<(GridBox, f64)>,
    pub cube_upper: f64,
    /// Fine points examined to grow the box and the cube.
    pub examined: u64,
}

impl RefinedBox {
    /// The larger box and cube of two searches of the same lattice, and the smaller bounds
    /// (both hold); the points examined added up.
    pub fn better(self, o: RefinedBox) -> RefinedBox {
        let larger = |a: Option<(GridBox, f64)>, b: Option<(GridBox, f64)>| match (a, b) {
            (Some(x), Some(y)) => Some(if y.1 > x.1 { y } else { x }),
            (x, y) => x.or(y),
        };
        RefinedBox {
            found: larger(self.found, o.found),
            upper: self.upper.min(o.upper),
            cube: larger(self.cube, o.cube),
            cube_upper: self.cube_upper.min(o.cube_upper),
            examined: self.examined + o.examined,
        }
    }
}

/// A coarser lattice of the fine one: its point `c` is the fine point `origin + step c`; `n`
/// points along each axis, `inside` x fastest.
pub(crate) struct SubLattice {
    pub origin: [usize; 3],
    pub step: usize,
    pub n: [usize; 3],
    pub inside: Vec<bool>,
}

impl SubLattice {
    /// Every `step`-th fine point of `bbox` (the fine index box of the inside points), and the
    /// next one past its upper end (outside: no inside point lies beyond `bbox`), examined
    /// with `inside_at`.
    pub fn of_box(
        bbox: GridBox,
        step: usize,
        inside_at: &(dyn Fn([usize; 3]) -> bool + Sync),
    ) -> SubLattice {
        let n = bbox.edges().map(|e| e.div_ceil(step) + 1);
        let inside = (0..n[2])
            .into_par_iter()
            .flat_map_iter(|k| {
                (0..n[1]).flat_map(move |j| {
                    (0..n[0]).map(move |i| {
                        let p = [i, j, k];
                        let f = [0, 1, 2].map(|d| bbox.lo[d] + step * p[d]);
                        (0..3).all(|d| f[d] <= bbox.hi[d]) && inside_at(f)
                    })
                })
            })
            .collect();
        SubLattice {
            origin: bbox.lo,
            step,
            n,
            inside,
        }
    }

    /// Its points, how many.
    pub fn len(&self) -> u64 {
        self.n.iter().map(|&v| v as u64).product()
    }
}

/// The largest box and cube of the fine lattice (`fine_n` points along each axis) grown from
/// those of the sub-lattice `sub`, with the bounds. `bbox` is the fine index box of the inside
/// points.
pub(crate) fn refined_largest_box(
    sub: &SubLattice,
    fine_n: [usize; 3],
    bbox: GridBox,
    inside_at: &(dyn Fn([usize; 3]) -> bool + Sync),
) -> RefinedBox {
    let (coarse_n, s0) = (sub.n, sub.step);
    let at = |i: usize, j: usize, k: usize| sub.inside[i + coarse_n[0] * (j + coarse_n[1] * k)];
    let hi = coarse_n.map(|v| v - 1);
    let s = s0 as f64;
    // The bound first (it needs no fine point).
    let margin = 2.0 * (s - 1.0) / s;
    let grown_best = largest_box_by(&at, [0; 3], hi, BoxMeasure::GrownVolume(margin));
    let grown = grown_best.map_or(0.0, |(_, v)| v * s * s * s);
    let extent = bbox.edges().map(|e| e as f64);
    let thin = (0..3)
        .map(|d| (s - 2.0).max(0.0) * extent[(d + 1) % 3] * extent[(d + 2) % 3])
        .fold(0.0f64, f64::max);
    let grown_cube_best = largest_box_by(&at, [0; 3], hi, BoxMeasure::GrownCube(margin));
    let grown_cube = grown_cube_best.map_or(0.0, |(_, v)| v * s * s * s);
    let mut result = RefinedBox {
        found: None,
        upper: grown.max(thin),
        cube: None,
        cube_upper: grown_cube.max((s - 2.0).max(0.0).powi(3)),
        examined: 0,
    };
    // A box of the sub-lattice as fine indices, cut to the fine lattice (a sub-lattice point
    // past it is outside, so no box found reaches one).
    let to_fine = |b: GridBox| GridBox {
        lo: [0, 1, 2].map(|d| (sub.origin[d] + b.lo[d] * s0).min(fine_n[d] - 1)),
        hi: [0, 1, 2].map(|d| (sub.origin[d] + b.hi[d] * s0).min(fine_n[d] - 1)),
    };
    // The cube: grown from the cubes at the first corner and at the middle of the coarse box
    // of the longest shortest edge and of the one that bounds the rest; the largest kept.
    let mut cube_starts: Vec<GridBox> = [
        largest_box_by(&at, [0; 3], hi, BoxMeasure::Cube),
        grown_cube_best,
    ]
    .into_iter()
    .flatten()
    .flat_map(|(b, _)| {
        let c = cube_in(&b);
        let e = c.edges()[0];
        let middle = GridBox {
            lo: [0, 1, 2].map(|d| b.lo[d] + (b.hi[d] - b.lo[d] - e) / 2),
            hi: [0, 1, 2].map(|d| b.lo[d] + (b.hi[d] - b.lo[d] - e) / 2 + e),
        };
        [c, middle]
    })
    .map(to_fine)
    .collect();
    cube_starts.sort_by_key(|c| (c.lo, c.hi));
    cube_starts.dedup();
    let mut cubes = Vec::new();
    for start in cube_starts {
        let (cube, examined) = grow_cube(start, fine_n, inside_at);
        result.examined += examined;
        cubes.push(cube);
        let v = (cube.edges()[0] as f64).powi(3);
        if result.cube.is_none_or(|(_, best)| v > best) {
            result.cube = Some((cube, v));
        }
    }
    // The box: grown from the coarse lattice's largest box, the coarse box that could grow
    // the most (the bound's) and the cubes grown (a cube is a box); the largest kept.
    let mut starts: Vec<GridBox> = [
        largest_box_by(&at, [0; 3], hi, BoxMeasure::Volume).map(|(b, _)| to_fine(b)),
        grown_best.map(|(b, _)| to_fine(b)),
    ]
    .into_iter()
    .flatten()
    .chain(cubes)
    .collect();
    starts.sort_by_key(|c| (c.lo, c.hi));
    starts.dedup();
    for start in starts {
        let (grown_box, examined) = grow(start, fine_n, inside_at);
        result.examined += examined;
        let e = grown_box.edges().map(|v| v as f64);
        let volume = e[0] * e[1] * e[2];
        if result.found.is_none_or(|(_, v)| volume > v) {
            result.found = Some((grown_box, volume));
        }
    }
    result
}

/// The largest box and cube of the fine lattice searched exhaustively within `bbox` (the fine
/// index box of the inside points): every point of it examined with `inside_at`, then
/// [`largest_box_by`] as on the uniform grid; the bounds are the volumes found.
pub(crate) fn exact_largest_box(
    bbox: GridBox,
    inside_at: &(dyn Fn([usize; 3]) -> bool + Sync),
) -> RefinedBox {
    let n = bbox.edges().map(|e| e + 1);
    let map: Vec<bool> = (0..n[2])
        .into_par_iter()
        .flat_map_iter(|k| {
            (0..n[1]).flat_map(move |j| {
                (0..n[0]).map(move |i| inside_at([bbox.lo[0] + i, bbox.lo[1] + j, bbox.lo[2] + k]))
            })
        })
        .collect();
    let at = |i: usize, j: usize, k: usize| map[i + n[0] * (j + n[1] * k)];
    let hi = n.map(|v| v - 1);
    let shifted = |b: GridBox| GridBox {
        lo: [0, 1, 2].map(|d| b.lo[d] + bbox.lo[d]),
        hi: [0, 1, 2].map(|d| b.hi[d] + bbox.lo[d]),
    };
    let found = largest_box_by(&at, [0; 3], hi, BoxMeasure::Volume).map(|(b, v)| (shifted(b), v));
    let cube =
        largest_box_by(&at, [0; 3], hi, BoxMeasure::Cube).map(|(b, v)| (shifted(cube_in(&b)), v));
    RefinedBox {
        found,
        upper: found.map_or(0.0, |(_, v)| v),
        cube,
        cube_upper: cube.map_or(0.0, |(_, v)| v),
        examined: map.len() as u64,
    }
}

/// Grows the box `b` of the fine lattice (`fine_n` points along each axis) one face and one
/// step at a time while the new face's points are all inside, until no face moves; with the
/// points examined. A face that cannot move never can again (the box only grows, so its next
/// plane only widens), so it is not tried twice.
fn grow(
    mut b: GridBox,
    fine_n: [usize; 3],
    inside_at: &(dyn Fn([usize; 3]) -> bool + Sync),
) -> (GridBox, u64) {
    let mut examined = 0u64;
    let mut blocked = [false; 6];
    while blocked.iter().any(|&x| !x) {
        for (face, blocked) in blocked.iter_mut().enumerate() {
            if !*blocked && !try_face(&mut b, face, fine_n, inside_at, &mut examined) {
                *blocked = true;
            }
        }
    }
    (b, examined)
}

/// Grows the cube `b` one fine step along each axis at a time (by the face of each axis not
/// yet blocked, the upper one first), until an axis has both faces blocked.
fn grow_cube(
    mut b: GridBox,
    fine_n: [usize; 3],
    inside_at: &(dyn Fn([usize; 3]) -> bool + Sync),
) -> (GridBox, u64) {
    let mut examined = 0u64;
    let mut blocked = [false; 6];
    loop {
        let before = b;
        for d in 0..3 {
            let grown = [2 * d + 1, 2 * d].into_iter().any(|face| {
                let ok = !blocked[face] && try_face(&mut b, face, fine_n, inside_at, &mut examined);
                if !ok {
                    blocked[face] = true;
                }
                ok
            });
            if !grown {
                return (before, examined);
            }
        }
    }
}

/// Moves `face` (2 d for the lower face along axis d, 2 d + 1 for the upper) of `b` one step out
/// if the lattice goes on and every point of the new plane within `b` is inside; whether it
/// moved. Each row of the plane is examined up to its first point outside (the same points
/// whatever the threads), counted in `examined`.
fn try_face(
    b: &mut GridBox,
    face: usize,
    fine_n: [usize; 3],
    inside_at: &(dyn Fn([usize; 3]) -> bool + Sync),
    examined: &mut u64,
) -> bool {
    let (d, up) = (face / 2, face % 2 == 1);
    let plane = match up {
        true if b.hi[d] + 1 < fine_n[d] => b.hi[d] + 1,
        false if b.lo[d] > 0 => b.lo[d] - 1,
        _ => return false,
    };
    let (e1, e2) = ((d + 1) % 3, (d + 2) % 3);
    let (lo1, cols) = (b.lo[e1], b.hi[e1] - b.lo[e1] + 1);
    let (n, outside) = (b.lo[e2]..=b.hi[e2])
        .into_par_iter()
        .map(|row| {
            let mut p = [0usize; 3];
            p[d] = plane;
            p[e2] = row;
            for c in 0..cols {
                p[e1] = lo1 + c;
                if !inside_at(p) {
                    return (c as u64 + 1, 1u64);
                }
            }
            (cols as u64, 0)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    *examined += n;
    if outside > 0 {
        return false;
    }
    if up {
        b.hi[d] = plane;
    } else {
        b.lo[d] = plane;
    }
    true
}
