//! Cartesian workspace of one working mode of a glider sampled on a grid (section 2.6, Wenger
//! 2001): joint ranges, the t-connected singularity-free region containing a seed, the
//! kinetostatic bound of eq. (4), and the largest rectangle (criterion S of section 3.2) and
//! largest square inside it.
//!
//! The grid may be rotated by `frame_angle` from the mechanism frame; rectangles are
//! axis-aligned in the grid frame. Every node is classified (uniform sampling), or only the
//! nodes near the boundaries between classes ([`super::adaptive`], the default on fine grids),
//! in parallel with rayon, collected in order; then the flood fill and the rectangle search run
//! sequentially, so the result is identical whatever the thread count. The region's area comes
//! with a bracket (the cells with all four corners in the region, and those with any) and an
//! estimate from one pseudo-random point in each cell between, bounded by Hoeffding's
//! inequality.

use crate::math::sampling::{hoeffding_half_width, unit_offsets};
use crate::par::*;
use nalgebra::{Point2, Rotation2, Vector2};

use super::adaptive::{COARSE_FACTOR, MIN_COARSE_CELLS, classify_adaptive};
use super::jacobian::{amplification, is_parallel_singular, is_serial_singular};
use super::kinematics::{
    Branch, WorkingMode, assembly_of, forward_kinematics_in_mode, inverse_kinematics_in_mode,
    strut_root,
};
use super::spec::GliderSpec;

/// The kinetostatic bound of eq. (4), Wenger 2001: 1/3 < lambda_i < 3.
pub const PAPER_LAMBDA_BOUNDS: [f64; 2] = [1.0 / 3.0, 3.0];

/// Samples per joint when the window of the grid is taken from the image of the joint box.
const WINDOW_JOINT_SAMPLES: usize = 129;

/// Margin added on each side of that window, as a fraction of its larger extent.
const WINDOW_MARGIN_REL: f64 = 0.03;

/// Which nodes of the grid are classified.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Sampling {
    /// Adaptive when the coarse grid ([`COARSE_FACTOR`] steps) has at least
    /// [`MIN_COARSE_CELLS`] cells along the window's longer side (801 nodes do), else uniform.
    #[default]
    Auto,
    /// Every node.
    Uniform,
    /// A coarse grid of [`COARSE_FACTOR`] steps refined where the class or the binding
    /// constraint changes ([`super::adaptive`]).
    Adaptive,
}

impl Sampling {
    /// Whether a grid of `nodes` along its longer side is sampled adaptively.
    pub fn is_adaptive(self, nodes: usize) -> bool {
        match self {
            Sampling::Auto => nodes.saturating_sub(1) >= COARSE_FACTOR * MIN_COARSE_CELLS,
            Sampling::Uniform => false,
            Sampling::Adaptive => true,
        }
    }
}

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
    /// Which nodes are classified.
    pub sampling: Sampling,
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
            sampling: Sampling::Auto,
        }
    }
}

/// Why a grid node is, or is not, in the workspace; checked in this order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
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
    /// The coarse step of an adaptive grid; `None` for a uniform one.
    pub coarse_step: Option<f64>,
    /// Points classified: the nodes classified (all of them on a uniform grid), plus those of
    /// the refinement past the window, plus the area's sample points.
    pub classified: usize,
    /// The region's area bracketed and estimated from its boundary cells.
    pub region_estimate: AreaEstimate,
}

/// The area of the t-connected region from the cells of the grid (squares of four nodes).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AreaEstimate {
    /// Area of the cells whose four corners are in the region, and of those with any corner in
    /// it: the true area lies between wherever no feature hides inside a cell.
    pub lo: f64,
    pub hi: f64,
    /// Cells with some corners in the region and some not.
    pub boundary_cells: usize,
    /// `lo` plus the boundary cells' area times the share of them whose pseudo-random point
    /// (one a cell, placed by a hash of the cell) is admissible (taken as in the region: the
    /// cell touches it); and the half-width of its 99.7 % confidence interval (Hoeffding).
    pub sampled: f64,
    pub half_width: f64,
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
    classify_binding(spec, p, opts).0
}

/// The class of a point and which constraint binds there, a bit set: for `Unreachable`, the
/// struts that do not reach (1, 2); for `OutOfRange`, the limits passed (rho1 below, above,
/// rho2 below, above: 1, 2, 4, 8); for `OutOfBounds`, lambda_min below LO (1), lambda_max above
/// HI (2), no factors (4); 0 otherwise. The adaptive grid refines a cell whose corners differ
/// in either: the thin wedge of the joint box's image between two limits lies in cells whose
/// corners are all out of range, each past another limit.
fn classify_binding(spec: &GliderSpec, p: Point2<f64>, opts: &WorkspaceOptions) -> (NodeClass, u8) {
    let Some(rho) = inverse_kinematics_in_mode(spec, p, opts.mode) else {
        let misses = |o, u, l, branch| u8::from(strut_root(o, u, l, p, branch).is_none());
        return (
            NodeClass::Unreachable,
            misses(spec.a(), spec.u1(), spec.l1, opts.mode.strut1)
                | misses(spec.b(), spec.u2(), spec.l2, opts.mode.strut2) << 1,
        );
    };
    let passed = spec.limits_passed(rho);
    if passed != 0 {
        return (NodeClass::OutOfRange, passed);
    }
    if is_serial_singular(spec, p, rho) || is_parallel_singular(spec, p, rho) {
        return (NodeClass::Singular, 0);
    }
    if assembly_of(spec, p, rho) != opts.assembly {
        return (NodeClass::OtherAssembly, 0);
    }
    if let Some([lo, hi]) = opts.lambda_bounds {
        match amplification(spec, p, rho) {
            Some(a) if a.within(lo, hi) => {}
            Some(a) => {
                let (below, above) = a.outside(lo, hi);
                return (
                    NodeClass::OutOfBounds,
                    u8::from(below) | u8::from(above) << 1,
                );
            }
            None => return (NodeClass::OutOfBounds, 4),
        }
    }
    (NodeClass::Admissible, 0)
}

/// A node's class and binding constraints in one byte (class in the low three bits), for the
/// adaptive grid; [`node_class_of_key`] takes the class back.
fn refinement_key(spec: &GliderSpec, p: Point2<f64>, opts: &WorkspaceOptions) -> u8 {
    let (class, binding) = classify_binding(spec, p, opts);
    class as u8 | binding << 3
}

fn node_class_of_key(key: u8) -> NodeClass {
    const CLASSES: [NodeClass; 6] = [
        NodeClass::Unreachable,
        NodeClass::OutOfRange,
        NodeClass::Singular,
        NodeClass::OtherAssembly,
        NodeClass::OutOfBounds,
        NodeClass::Admissible,
    ];
    CLASSES[(key & 7) as usize]
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
/// margin), the nodes are classified (every one, or adaptively: [`Sampling`]), then the
/// t-connected region of the seed is flood-filled (4-connectivity through admissible nodes)
/// and its area estimated ([`AreaEstimate`]).
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
        coarse_step: None,
        classified: 0,
        region_estimate: AreaEstimate::default(),
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
    let (class, classified, coarse_step) = if opts.sampling.is_adaptive(nodes) {
        let key = |i: usize, j: usize| refinement_key(spec, g.node(i, j), opts);
        let (keys, n) = classify_adaptive(nx, ny, COARSE_FACTOR, &key);
        let class = keys.into_iter().map(node_class_of_key).collect();
        (class, n, Some(step * COARSE_FACTOR as f64))
    } else {
        let class = (0..ny)
            .into_par_iter()
            .flat_map_iter(|j| (0..nx).map(move |i| classify(spec, g.node(i, j), opts)))
            .collect();
        (class, nx * ny, None)
    };
    (grid.class, grid.classified, grid.coarse_step) = (class, classified, coarse_step);

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
    let (estimate, sampled) = estimate_region_area(spec, &grid, opts);
    grid.region_estimate = estimate;
    grid.classified += sampled;
    grid
}

/// The region's [`AreaEstimate`], and the points classified for it (one a boundary cell).
fn estimate_region_area(
    spec: &GliderSpec,
    grid: &WorkspaceGrid,
    opts: &WorkspaceOptions,
) -> (AreaEstimate, usize) {
    let (nx, ny) = (grid.nx, grid.ny);
    if nx < 2 || ny < 2 {
        return (AreaEstimate::default(), 0);
    }
    let rotation = Rotation2::new(grid.frame_angle);
    // Per row of cells: (cells all in the region, boundary cells, their points admissible).
    let (full, boundary, admissible) = (0..ny - 1)
        .into_par_iter()
        .map(|j| {
            let mut counts = (0usize, 0usize, 0usize);
            for i in 0..nx - 1 {
                let k = j * nx + i;
                let inside = [k, k + 1, k + nx, k + nx + 1]
                    .iter()
                    .filter(|&&c| grid.region[c])
                    .count();
                match inside {
                    4 => counts.0 += 1,
                    0 => {}
                    _ => {
                        counts.1 += 1;
                        let mut state = k as u64;
                        let [u, v] = unit_offsets::<2>(&mut state);
                        let q = grid.origin + Vector2::new(i as f64 + u, j as f64 + v) * grid.step;
                        if classify(spec, rotation * q, opts) == NodeClass::Admissible {
                            counts.2 += 1;
                        }
                    }
                }
            }
            counts
        })
        .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    let cell = grid.step * grid.step;
    let mut e = AreaEstimate {
        lo: full as f64 * cell,
        hi: (full + boundary) as f64 * cell,
        boundary_cells: boundary,
        sampled: full as f64 * cell,
        half_width: 0.0,
    };
    if boundary > 0 {
        let share = admissible as f64 / boundary as f64;
        e.sampled += share * boundary as f64 * cell;
        e.half_width = hoeffding_half_width(boundary as u64) * boundary as f64 * cell;
    }
    (e, boundary)
}

/// Marks the admissible nodes 4-connected to (i, j) as the region, a row's run of them at a
/// time (scanline fill: each run is marked once, then the rows above and below are searched
/// for runs that touch it), so the cost follows the region's rows, in memory order.
fn flood_fill(grid: &mut WorkspaceGrid, i: usize, j: usize) {
    let nx = grid.nx;
    let open = |g: &WorkspaceGrid, k: usize| !g.region[k] && g.class[k] == NodeClass::Admissible;
    let mut seeds = vec![(i, j)];
    while let Some((i, j)) = seeds.pop() {
        let row = j * nx;
        if !open(grid, row + i) {
            continue;
        }
        let (mut lo, mut hi) = (i, i);
        while lo > 0 && open(grid, row + lo - 1) {
            lo -= 1;
        }
        while hi + 1 < nx && open(grid, row + hi + 1) {
            hi += 1;
        }
        grid.region[row + lo..=row + hi].fill(true);
        // One seed per run of open nodes in the rows next to this run.
        for next in [j.wrapping_sub(1), j + 1] {
            if next >= grid.ny {
                continue;
            }
            let mut in_run = false;
            for a in lo..=hi {
                let here = open(grid, next * nx + a);
                if here && !in_run {
                    seeds.push((a, next));
                }
                in_run = here;
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
    // The side ending at each node of the previous row and of this one.
    let (mut above, mut side) = (vec![0usize; nx], vec![0usize; nx]);
    let mut best: Option<(usize, usize, usize)> = None; // (side in nodes, i1, j1)
    for j in 0..ny {
        for i in 0..nx {
            side[i] = if !grid.region[j * nx + i] {
                0
            } else if i == 0 || j == 0 {
                1
            } else {
                1 + side[i - 1].min(above[i]).min(above[i - 1])
            };
            if side[i] > 0 && best.is_none_or(|b| side[i] > b.0) {
                best = Some((side[i], i, j));
            }
        }
        std::mem::swap(&mut above, &mut side);
    }
    best.map(|(s, i1, j1)| grid.rectangle(i1 + 1 - s, i1, j1 + 1 - s, j1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::test_rng::lcg;

    /// The scanline fill marks what a breadth-first search through 4-neighbours marks, on
    /// random mazes (spirals, pockets, runs that touch several runs above and below).
    #[test]
    fn scanline_fill_equals_breadth_first_search() {
        let mut rand = lcg(7);
        for (nx, ny, open_share) in [
            (1, 1, 1.0),
            (7, 1, 0.8),
            (1, 9, 0.8),
            (40, 30, 0.6),
            (97, 61, 0.55),
        ] {
            for _ in 0..20 {
                let class: Vec<NodeClass> = (0..nx * ny)
                    .map(|_| {
                        if rand() < open_share {
                            NodeClass::Admissible
                        } else {
                            NodeClass::OutOfBounds
                        }
                    })
                    .collect();
                let (i, j) = ((rand() * nx as f64) as usize, (rand() * ny as f64) as usize);
                let mut grid = WorkspaceGrid {
                    frame_angle: 0.0,
                    origin: Point2::origin(),
                    step: 1.0,
                    nx,
                    ny,
                    class,
                    region: vec![false; nx * ny],
                    seed: None,
                    coarse_step: None,
                    classified: 0,
                    region_estimate: AreaEstimate::default(),
                };
                let mut expected = vec![false; nx * ny];
                if grid.class[j * nx + i] == NodeClass::Admissible {
                    flood_fill(&mut grid, i, j);
                    let mut queue = std::collections::VecDeque::from([(i, j)]);
                    expected[j * nx + i] = true;
                    while let Some((a, b)) = queue.pop_front() {
                        for (c, d) in [
                            (a.wrapping_sub(1), b),
                            (a + 1, b),
                            (a, b.wrapping_sub(1)),
                            (a, b + 1),
                        ] {
                            if c < nx
                                && d < ny
                                && !expected[d * nx + c]
                                && grid.class[d * nx + c] == NodeClass::Admissible
                            {
                                expected[d * nx + c] = true;
                                queue.push_back((c, d));
                            }
                        }
                    }
                }
                assert_eq!(grid.region, expected, "{nx} x {ny} from ({i}, {j})");
            }
        }
    }
}
