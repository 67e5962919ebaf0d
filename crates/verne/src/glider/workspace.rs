//! Cartesian workspace of one working mode of a glider sampled on a grid (section 2.6, Wenger
//! 2001): joint ranges, the t-connected singularity-free region containing a seed, the
//! kinetostatic bound of eq. (4), and the largest rectangle (criterion S of section 3.2) and
//! largest square inside it.
//!
//! The grid may be rotated by `frame_angle` from the mechanism frame; rectangles are
//! axis-aligned in the grid frame. Every node is classified independently (in parallel with
//! rayon, collected in order), then the flood fill and the rectangle search run sequentially, so
//! the result is identical whatever the thread count.

use std::collections::VecDeque;

use crate::par::*;
use nalgebra::{Point2, Rotation2, Vector2};

use super::jacobian::{amplification, is_parallel_singular, is_serial_singular};
use super::kinematics::{
    Branch, WorkingMode, assembly_of, forward_kinematics_in_mode, inverse_kinematics_in_mode,
};
use super::spec::GliderSpec;

/// The kinetostatic bound of eq. (4), Wenger 2001: 1/3 < lambda_i < 3.
pub const PAPER_LAMBDA_BOUNDS: [f64; 2] = [1.0 / 3.0, 3.0];

/// Samples per joint when the window of the grid is taken from the image of the joint box.
const WINDOW_JOINT_SAMPLES: usize = 129;

/// Margin added on each side of that window, as a fraction of its larger extent.
const WINDOW_MARGIN_REL: f64 = 0.03;

/// How to sample a workspace.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkspaceOptions {
    /// Working mode sampled (the paper's figures use `++`, docs/gliders.md).
    pub mode: WorkingMode,
    /// Assembly mode of the t-connected region (sign of det A; the paper's figures use `+`).
    pub assembly: Branch,
    /// Bounds [lo, hi] on both amplification factors, eq. (4); `None` for no kinetostatic bound.
    pub lambda_bounds: Option<[f64; 2]>,
    /// Grid nodes along the longer side of the window (the step is the same along both axes).
    pub nodes: usize,
    /// Rotation (rad) of the grid axes, and so of the rectangles, from the mechanism frame.
    pub frame_angle: f64,
    /// A point of the wanted t-connected region; `None`: the forward kinematics, in `assembly`,
    /// of the centre of the joint box.
    pub seed: Option<Point2<f64>>,
}

impl Default for WorkspaceOptions {
    fn default() -> Self {
        WorkspaceOptions {
            mode: WorkingMode::new(Branch::Plus, Branch::Plus),
            assembly: Branch::Plus,
            lambda_bounds: Some(PAPER_LAMBDA_BOUNDS),
            nodes: 801,
            frame_angle: 0.0,
            seed: None,
        }
    }
}

/// Why a grid node is, or is not, in the workspace; checked in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NodeClass {
    /// The working mode cannot reach the point (a strut does not reach its guide).
    Unreachable,
    /// Reached, but with a joint outside its range.
    OutOfRange,
    /// On a serial or parallel singularity (sections 2.4-2.5).
    Singular,
    /// In the other assembly mode (det A of the other sign).
    OtherAssembly,
    /// Violates the amplification bounds of eq. (4).
    OutOfBounds,
    /// In the workspace.
    Admissible,
}

/// A sampled workspace.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkspaceGrid {
    /// Grid frame: node (i, j) is at R(frame_angle) (origin + step (i, j)) in the mechanism frame.
    pub frame_angle: f64,
    /// Grid-frame position of node (0, 0).
    pub origin: Point2<f64>,
    /// Node spacing along both grid axes (length unit of the spec).
    pub step: f64,
    pub nx: usize,
    pub ny: usize,
    /// Class of each node, row-major (index j nx + i).
    pub class: Vec<NodeClass>,
    /// The t-connected region: admissible nodes 4-connected to the seed, row-major.
    pub region: Vec<bool>,
    /// The seed node, if the seed fell on an admissible node.
    pub seed: Option<(usize, usize)>,
}

/// A rectangle, axis-aligned in a frame rotated by `angle` from the mechanism frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rectangle {
    /// Centre in the mechanism frame.
    pub centre: Point2<f64>,
    /// Side along the rotated x axis.
    pub width: f64,
    /// Side along the rotated y axis.
    pub height: f64,
    /// Rotation (rad) of its sides from the mechanism frame.
    pub angle: f64,
}

impl Rectangle {
    pub fn area(&self) -> f64 {
        self.width * self.height
    }

    /// Corners in the mechanism frame, counter-clockwise from the one at (-w/2, -h/2).
    pub fn corners(&self) -> [Point2<f64>; 4] {
        let r = Rotation2::new(self.angle);
        let (w, h) = (0.5 * self.width, 0.5 * self.height);
        [(-w, -h), (w, -h), (w, h), (-w, h)].map(|(x, y)| self.centre + r * Vector2::new(x, y))
    }
}

impl WorkspaceGrid {
    /// Node (i, j) in the mechanism frame.
    pub fn node(&self, i: usize, j: usize) -> Point2<f64> {
        let q = self.origin + Vector2::new(i as f64, j as f64) * self.step;
        Rotation2::new(self.frame_angle) * q
    }

    /// Number of admissible nodes times the area of one cell (an estimate of the area of the
    /// whole admissible set, all components).
    pub fn admissible_area(&self) -> f64 {
        let n = self
            .class
            .iter()
            .filter(|&&c| c == NodeClass::Admissible)
            .count();
        n as f64 * self.step * self.step
    }

    /// Number of region nodes times the area of one cell.
    pub fn region_area(&self) -> f64 {
        self.region.iter().filter(|&&r| r).count() as f64 * self.step * self.step
    }

    /// The rectangle spanned by nodes i0..=i1, j0..=j1.
    fn rectangle(&self, i0: usize, i1: usize, j0: usize, j1: usize) -> Rectangle {
        let q0 = self.origin + Vector2::new(i0 as f64, j0 as f64) * self.step;
        let q1 = self.origin + Vector2::new(i1 as f64, j1 as f64) * self.step;
        Rectangle {
            centre: Rotation2::new(self.frame_angle) * Point2::from((q0.coords + q1.coords) * 0.5),
            width: q1.x - q0.x,
            height: q1.y - q0.y,
            angle: self.frame_angle,
        }
    }
}

/// Classifies one point of the mechanism frame.
pub fn classify(spec: &GliderSpec, p: Point2<f64>, opts: &WorkspaceOptions) -> NodeClass {
    let Some(rho) = inverse_kinematics_in_mode(spec, p, opts.mode) else {
        return NodeClass::Unreachable;
    };
    if !spec.within_limits(rho) {
        return NodeClass::OutOfRange;
    }
    if is_serial_singular(spec, p, rho) || is_parallel_singular(spec, p, rho) {
        return NodeClass::Singular;
    }
    if assembly_of(spec, p, rho) != opts.assembly {
        return NodeClass::OtherAssembly;
    }
    if let Some([lo, hi]) = opts.lambda_bounds {
        match amplification(spec, p, rho) {
            Some(a) if a.within(lo, hi) => {}
            _ => return NodeClass::OutOfBounds,
        }
    }
    NodeClass::Admissible
}

/// Bounding box, in the frame rotated by `frame_angle`, of the forward kinematics in one
/// assembly mode of `samples` x `samples` points of the joint box; `None` if none assembles.
pub fn joint_box_image_bounds(
    spec: &GliderSpec,
    assembly: Branch,
    frame_angle: f64,
    samples: usize,
) -> Option<(Point2<f64>, Point2<f64>)> {
    let inv = Rotation2::new(-frame_angle);
    let n = samples.max(2);
    let lerp = |[lo, hi]: [f64; 2], k: usize| lo + (hi - lo) * k as f64 / (n - 1) as f64;
    let points: Vec<Point2<f64>> = (0..n)
        .into_par_iter()
        .flat_map_iter(|a| {
            (0..n).filter_map(move |b| {
                let rho = Vector2::new(lerp(spec.rho1_range, a), lerp(spec.rho2_range, b));
                forward_kinematics_in_mode(spec, rho, assembly).map(|p| inv * p)
            })
        })
        .collect();
    let first = *points.first()?;
    Some(points.iter().fold((first, first), |(lo, hi), p| {
        (
            Point2::new(lo.x.min(p.x), lo.y.min(p.y)),
            Point2::new(hi.x.max(p.x), hi.y.max(p.y)),
        )
    }))
}

/// Samples the workspace of one working mode: the window is the image of the joint box (plus a
/// margin), every node is classified, then the t-connected region of the seed is flood-filled
/// (4-connectivity through admissible nodes).
pub fn sample_workspace(spec: &GliderSpec, opts: &WorkspaceOptions) -> WorkspaceGrid {
    let empty = WorkspaceGrid {
        frame_angle: opts.frame_angle,
        origin: Point2::origin(),
        step: 0.0,
        nx: 0,
        ny: 0,
        class: Vec::new(),
        region: Vec::new(),
        seed: None,
    };
    let Some((lo, hi)) =
        joint_box_image_bounds(spec, opts.assembly, opts.frame_angle, WINDOW_JOINT_SAMPLES)
    else {
        return empty;
    };
    let extent = (hi.x - lo.x).max(hi.y - lo.y);
    let margin = WINDOW_MARGIN_REL * if extent > 0.0 { extent } else { spec.l1 };
    let (lo, hi) = (lo - Vector2::repeat(margin), hi + Vector2::repeat(margin));
    let nodes = opts.nodes.max(2);
    let step = (hi.x - lo.x).max(hi.y - lo.y) / (nodes - 1) as f64;
    let nx = ((hi.x - lo.x) / step).ceil() as usize + 1;
    let ny = ((hi.y - lo.y) / step).ceil() as usize + 1;
    let mut grid = WorkspaceGrid {
        origin: lo,
        step,
        nx,
        ny,
        ..empty
    };
    let g = &grid;
    grid.class = (0..ny)
        .into_par_iter()
        .flat_map_iter(|j| (0..nx).map(move |i| classify(spec, g.node(i, j), opts)))
        .collect();

    let seed_point = opts.seed.or_else(|| {
        let centre = Vector2::new(
            0.5 * (spec.rho1_range[0] + spec.rho1_range[1]),
            0.5 * (spec.rho2_range[0] + spec.rho2_range[1]),
        );
        forward_kinematics_in_mode(spec, centre, opts.assembly)
    });
    grid.region = vec![false; nx * ny];
    if let Some(p) = seed_point {
        let q = Rotation2::new(-opts.frame_angle) * p - grid.origin;
        let (fi, fj) = ((q.x / step).round(), (q.y / step).round());
        if fi >= 0.0 && fj >= 0.0 && (fi as usize) < nx && (fj as usize) < ny {
            let (i, j) = (fi as usize, fj as usize);
            if grid.class[j * nx + i] == NodeClass::Admissible {
                grid.seed = Some((i, j));
                flood_fill(&mut grid, i, j);
            }
        }
    }
    grid
}

fn flood_fill(grid: &mut WorkspaceGrid, i: usize, j: usize) {
    let (nx, ny) = (grid.nx, grid.ny);
    let mut queue = VecDeque::from([(i, j)]);
    grid.region[j * nx + i] = true;
    while let Some((i, j)) = queue.pop_front() {
        let neighbours = [
            (i.wrapping_sub(1), j),
            (i + 1, j),
            (i, j.wrapping_sub(1)),
            (i, j + 1),
        ];
        for (a, b) in neighbours {
            if a < nx && b < ny {
                let k = b * nx + a;
                if !grid.region[k] && grid.class[k] == NodeClass::Admissible {
                    grid.region[k] = true;
                    queue.push_back((a, b));
                }
            }
        }
    }
}

/// The largest rectangle, axis-aligned in the grid frame, whose grid nodes all lie in the
/// t-connected region (criterion S, section 3.2, Wenger 2001). A rectangle of k x m nodes has
/// sides (k - 1) step and (m - 1) step. Largest-rectangle-in-histogram sweep over the rows;
/// ties keep the first found (lowest row, then lowest column). `None` if the region is empty.
pub fn largest_rectangle(grid: &WorkspaceGrid) -> Option<Rectangle> {
    let (nx, ny) = (grid.nx, grid.ny);
    let mut heights = vec![0usize; nx];
    // (objective, i0, i1, j0, j1) with objective = (width - 1)(height - 1) in nodes.
    let mut best: Option<(usize, usize, usize, usize, usize)> = None;
    let mut stack: Vec<(usize, usize)> = Vec::with_capacity(nx + 1);
    for j in 0..ny {
        for (h, &inside) in heights.iter_mut().zip(&grid.region[j * nx..(j + 1) * nx]) {
            *h = if inside { *h + 1 } else { 0 };
        }
        stack.clear();
        // A zero-height sentinel column at c = nx flushes the stack.
        for (c, &h) in heights.iter().chain(std::iter::once(&0)).enumerate() {
            let mut start = c;
            while let Some(&(s, hh)) = stack.last() {
                if hh < h {
                    break;
                }
                stack.pop();
                if hh > 0 {
                    let objective = (c - s - 1) * (hh - 1);
                    if best.is_none_or(|b| objective > b.0) {
                        best = Some((objective, s, c - 1, j + 1 - hh, j));
                    }
                }
                start = s;
            }
            stack.push((start, h));
        }
    }
    best.map(|(_, i0, i1, j0, j1)| grid.rectangle(i0, i1, j0, j1))
}

/// The largest square, axis-aligned in the grid frame, whose grid nodes all lie in the
/// t-connected region (dynamic programming on the side ending at each node; ties keep the
/// first found). `None` if the region is empty.
pub fn largest_square(grid: &WorkspaceGrid) -> Option<Rectangle> {
    let (nx, ny) = (grid.nx, grid.ny);
    let mut side = vec![0usize; nx * ny];
    let mut best: Option<(usize, usize, usize)> = None; // (side in nodes, i1, j1)
    for j in 0..ny {
        for i in 0..nx {
            let k = j * nx + i;
            if !grid.region[k] {
                continue;
            }
            side[k] = if i == 0 || j == 0 {
                1
            } else {
                1 + side[k - 1].min(side[k - nx]).min(side[k - nx - 1])
            };
            if best.is_none_or(|b| side[k] > b.0) {
                best = Some((side[k], i, j));
            }
        }
    }
    best.map(|(s, i1, j1)| grid.rectangle(i1 + 1 - s, i1, j1 + 1 - s, j1))
}
