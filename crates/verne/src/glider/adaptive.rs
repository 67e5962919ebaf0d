//! A glider's workspace grid by adaptive sampling (a quadtree): classify a coarse grid, then
//! halve only the cells whose four corners differ in class or in the constraint that binds (a
//! refinement key a node, one byte) and, a guard against features thinner than a cell that
//! reach out of a boundary, the cells next to them, down to cells of one step. A cell whose
//! corners agree gives its key to the nodes it owns without classifying them. The
//! classification's cost grows with the boundaries' length, not the area; the grid of classes
//! is whole (one byte a node), so the flood fill, the area and the largest rectangle and square
//! run on it exactly as on the uniform grid, whose classes it reproduces wherever no feature
//! hides inside a coarse cell with agreeing corners (the coarse step bounds what can hide;
//! tests compare with the uniform grid).
//!
//! The fine grid is extended to a whole number of coarse cells for the refinement (nodes past
//! the window, outside the image of the joint box), then cut back to the window.

use crate::par::*;

/// The coarse step is the fine step times this (a power of two).
pub const COARSE_FACTOR: usize = 8;

/// Fewest coarse cells along the longer side of the window for an adaptive grid: below this
/// ([`Sampling::Auto`](super::workspace::Sampling)), the grid is sampled uniformly.
pub const MIN_COARSE_CELLS: usize = 64;

/// Marks a node not classified yet (no refinement key is this).
const UNKNOWN: u8 = u8::MAX;

/// The refinement keys of the nodes of an `nx` x `ny` grid, row-major (index `j nx + i`), and
/// how many nodes were classified. `classify(i, j)` gives node (i, j)'s key (not [`UNKNOWN`]),
/// also past the grid (`i >= nx` or `j >= ny`) where the refinement extends it. `factor` is a
/// power of two >= 2.
pub(super) fn classify_adaptive(
    nx: usize,
    ny: usize,
    factor: usize,
    classify: &(dyn Fn(usize, usize) -> u8 + Sync),
) -> (Vec<u8>, usize) {
    assert!(factor >= 2 && factor.is_power_of_two() && nx >= 1 && ny >= 1);
    let extend = |n: usize| (n - 1).div_ceil(factor).max(1) * factor + 1;
    let (ex, ey) = (extend(nx), extend(ny));
    let mut known = vec![UNKNOWN; ex * ey];
    let mut classified = 0;
    // The cells of this level by their first corner's index `j ex + i`, sorted.
    let mut cells: Vec<usize> = (0..ey - 1)
        .step_by(factor)
        .flat_map(|j| (0..ex - 1).step_by(factor).map(move |i| j * ex + i))
        .collect();
    // Cells of two steps or more whose corners agree, with their size.
    let mut leaves: Vec<(usize, usize)> = Vec::new();
    let mut s = factor;
    while !cells.is_empty() {
        let corners = |c: usize| [c, c + s, c + s * ex, c + s * ex + s];
        let mut todo: Vec<usize> = cells
            .iter()
            .flat_map(|&c| corners(c))
            .filter(|&k| known[k] == UNKNOWN)
            .collect();
        todo.sort_unstable();
        todo.dedup();
        let found: Vec<u8> = todo.par_iter().map(|&k| classify(k % ex, k / ex)).collect();
        classified += todo.len();
        for (&k, c) in todo.iter().zip(found) {
            known[k] = c;
        }
        if s == 1 {
            break;
        }
        let agree = |c: usize| corners(c).iter().all(|&k| known[k] == known[c]);
        let mixed: Vec<usize> = cells.iter().copied().filter(|&c| !agree(c)).collect();
        let near_mixed = |c: usize| {
            let (i, j) = ((c % ex) as isize, (c / ex) as isize);
            let step = s as isize;
            (-1..=1).any(|dj| {
                (-1..=1).any(|di| {
                    let (a, b) = (i + di * step, j + dj * step);
                    a >= 0
                        && b >= 0
                        && (a as usize) < ex - 1
                        && (b as usize) < ey - 1
                        && mixed.binary_search(&(b as usize * ex + a as usize)).is_ok()
                })
            })
        };
        let h = s / 2;
        let mut halves = Vec::new();
        for &c in &cells {
            if agree(c) && !near_mixed(c) {
                leaves.push((c, s));
            } else {
                halves.extend([c, c + h, c + h * ex, c + h * ex + h]);
            }
        }
        halves.sort_unstable();
        cells = halves;
        s = h;
    }
    // A leaf's class to the nodes it owns ([i, i + s) x [j, j + s), closed on the last cell of
    // a row or column) that no finer cell classified.
    for &(c, s) in &leaves {
        let (i0, j0) = (c % ex, c / ex);
        let last = |v: usize, n: usize| if v + s == n - 1 { v + s + 1 } else { v + s };
        let (i1, j1) = (last(i0, ex), last(j0, ey));
        let class = known[c];
        for j in j0..j1 {
            for slot in &mut known[j * ex + i0..j * ex + i1] {
                if *slot == UNKNOWN {
                    *slot = class;
                }
            }
        }
    }
    // Cut back to the window, row by row in place (a row moves to a lower index).
    for j in 0..ny {
        known.copy_within(j * ex..j * ex + nx, j * nx);
    }
    known.truncate(nx * ny);
    // Every node is owned by one leaf or one cell of one step, so none is left unknown; a node
    // that were would be classified here.
    for (k, key) in known.iter_mut().enumerate() {
        if *key == UNKNOWN {
            classified += 1;
            *key = classify(k % nx, k / nx);
        }
    }
    (known, classified)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glider::NodeClass;

    /// A made-up field of classes: a disc admissible, a ring out of bounds, a thin stripe
    /// singular, the rest unreachable; the adaptive grid gives every node the class the
    /// uniform grid gives it, for grids whose sides are and are not whole coarse cells.
    #[test]
    fn reproduces_a_field_with_curved_and_thin_features() {
        let field = |i: usize, j: usize| {
            let (x, y) = (i as f64 - 70.0, j as f64 - 52.0);
            let r = (x * x + y * y).sqrt();
            (if (x - 0.3 * y - 11.0).abs() < 1.2 && r < 40.0 {
                NodeClass::Singular
            } else if r < 30.0 {
                NodeClass::Admissible
            } else if r < 40.0 {
                NodeClass::OutOfBounds
            } else {
                NodeClass::Unreachable
            }) as u8
        };
        for (nx, ny) in [(161, 121), (150, 107), (9, 9), (2, 3)] {
            let uniform: Vec<u8> = (0..ny)
                .flat_map(|j| (0..nx).map(move |i| field(i, j)))
                .collect();
            for factor in [2, 8, 16] {
                let (class, classified) = classify_adaptive(nx, ny, factor, &field);
                assert_eq!(class, uniform, "{nx} x {ny}, factor {factor}");
                if (nx, ny) == (161, 121) && factor == 8 {
                    // Fewer than half the nodes: the boundaries, not the area.
                    assert!(classified < nx * ny / 2, "{classified}");
                }
            }
        }
    }

    /// A wedge admissible between two limits, thinner than a step at its tip and reaching
    /// several coarse cells beyond the last coarse node inside it: the cells around the tip
    /// have all corners out of range, but past different limits, so they are refined and the
    /// tip is found as on the uniform grid. With the class alone as the key it is cut short.
    #[test]
    fn a_thin_wedge_between_two_limits_is_followed_by_the_binding_constraint() {
        let (below, left) = (1u8 << 3, 2u8 << 3);
        let out = NodeClass::OutOfRange as u8;
        let field = |i: usize, j: usize| {
            // Above the line y = 0.02 x + 3 and below y = 0.06 x + 2.9 (they meet near x < 0).
            let (x, y) = (i as f64, j as f64);
            let (under_top, over_bottom) = (y < 0.06 * x + 2.9, y > 0.02 * x + 3.0);
            match (under_top, over_bottom) {
                (true, true) => NodeClass::Admissible as u8,
                (true, false) => out | below,
                (false, true) => out | left,
                (false, false) => out | below | left,
            }
        };
        let (nx, ny) = (201, 25);
        let uniform: Vec<u8> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| field(i, j)))
            .collect();
        let (keys, _) = classify_adaptive(nx, ny, 8, &field);
        assert_eq!(keys, uniform);
        let class_only = |i: usize, j: usize| field(i, j) & 7;
        let (classes, _) = classify_adaptive(nx, ny, 8, &class_only);
        let uniform_classes: Vec<u8> = uniform.iter().map(|k| k & 7).collect();
        assert_ne!(classes, uniform_classes, "the class alone misses the tip");
    }

    /// A feature inside one coarse cell whose corners agree, and not next to a mixed cell, is
    /// missed: the assumption the coarse step bounds, shown so the guard's limit is known.
    #[test]
    fn a_feature_inside_one_agreeing_coarse_cell_is_missed() {
        let field = |i: usize, j: usize| {
            (if (i, j) == (20, 20) {
                NodeClass::Singular
            } else {
                NodeClass::Admissible
            }) as u8
        };
        let (class, classified) = classify_adaptive(41, 41, 8, &field);
        assert!(class.iter().all(|&c| c == NodeClass::Admissible as u8));
        assert_eq!(classified, 36, "the 6 x 6 coarse nodes only");
    }
}
