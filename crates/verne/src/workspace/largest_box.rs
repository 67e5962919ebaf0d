//! The largest axis-aligned box of grid points all inside a workspace.

use super::{GridBox, Outcome, OutcomeGrid};

/// Largest axis-aligned box of grid points all inside, by volume (edges counted in steps,
/// corners on grid points), searched within the index box [lo, hi] of the inside points.
///
/// Exhaustive over every pair of z layers k0 <= k1: the AND of the layers' inside masks, then
/// the largest rectangle of that 2D mask by the histogram-and-stack method (every maximal
/// rectangle is visited, so any objective increasing in width and height is maximised; here
/// (w - 1)(h - 1) points-to-edges). O(nz^2 nx ny) at worst, pruned: once the mask's count times
/// the remaining height cannot beat the best box, the inner loop stops. Sequential, first best
/// kept: deterministic. `None` when no box has positive volume.
pub fn largest_box(map: &OutcomeGrid, lo: [usize; 3], hi: [usize; 3]) -> Option<GridBox> {
    if lo.iter().zip(&hi).any(|(l, h)| l > h) {
        return None;
    }
    let nx = hi[0] - lo[0] + 1;
    let ny = hi[1] - lo[1] + 1;
    let layer = |k: usize| -> Vec<bool> {
        let mut v = Vec::with_capacity(nx * ny);
        for j in lo[1]..=hi[1] {
            for i in lo[0]..=hi[0] {
                v.push(map.at(i, j, k) == Outcome::Inside);
            }
        }
        v
    };
    let layers: Vec<Vec<bool>> = (lo[2]..=hi[2]).map(layer).collect();
    let nz = layers.len();
    let mut best = 0u64;
    let mut best_box = None;
    let mut heights = vec![0usize; nx];
    let mut stack: Vec<(usize, usize)> = Vec::with_capacity(nx + 1);
    for k0 in 0..nz {
        let mut mask = layers[k0].clone();
        for (k1, layer) in layers.iter().enumerate().skip(k0) {
            if k1 > k0 {
                for (a, b) in mask.iter_mut().zip(layer) {
                    *a &= *b;
                }
            }
            let count = mask.iter().filter(|&&b| b).count() as u64;
            if count == 0 || count * (nz - 1 - k0) as u64 <= best {
                break;
            }
            let dz = (k1 - k0) as u64;
            if dz == 0 || count * dz <= best {
                continue;
            }
            // Largest (w - 1)(h - 1) rectangle of the mask.
            heights.iter_mut().for_each(|h| *h = 0);
            let mut best2 = 0u64;
            let mut rect = [0usize; 4];
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
                            let val = ((i - s - 1) * (sh - 1)) as u64;
                            if val > best2 {
                                best2 = val;
                                rect = [s, i - 1, j + 1 - sh, j];
                            }
                        }
                        start = s;
                    }
                    stack.push((start, h));
                }
            }
            let vol = best2 * dz;
            if vol > best {
                best = vol;
                best_box = Some(GridBox {
                    lo: [lo[0] + rect[0], lo[1] + rect[2], lo[2] + k0],
                    hi: [lo[0] + rect[1], lo[1] + rect[3], lo[2] + k1],
                });
            }
        }
    }
    best_box
}
