//! Workspace of the VERNE machine sampled on a grid (AIM 2007, section IV): the points reachable
//! by the platform point P, by the tool tip (eq. (27), AIM 2007) or by the tool tip in the table
//! frame with the table following the platform (eq. (26), AIM 2007, with theta1 = alpha and
//! theta2 = phi1 = phi2 = 0), in the machine's configuration s = (-1, -1, -1), with the
//! constraints (i)-(v) reported separately.
//!
//! Per grid point q:
//! - `platform`: the inverse kinematics of P = q ([`crate::parallel_module::ik::solve`]).
//! - `tool`, `manufacturing`: P depends on the unknown alpha, P(alpha) =
//!   (x, a0 + a_s sin(alpha) + a_c cos(alpha), b0 + b_s sin(alpha) + b_c cos(alpha))
//!   (eqs. (26)-(27) solved for P).
//!   Substituting into the leg-I coupling eq. (15), AIM 2007, and t = tan(alpha/2) gives a
//!   polynomial of degree 6 in t (the paper's "six-degree characteristic polynomial in
//!   tan(theta1/2)"), whose real roots are isolated in two charts (|t| <= 1 and |1/t| <= 1); each
//!   root gives P and the inverse-kinematics branches of P with that alpha.
//!
//! Among the branches with s = (-1, -1, -1) (the slider attachments above the platform
//! attachments), each constraint is checked; a point is inside when one branch satisfies all.
//! Otherwise the *reference branch* is the one failing the fewest constraints (then the smallest
//! |alpha|), and the *binding constraint* is its first failure in the order of [`Constraint::ALL`]:
//! (i) leg-I rods cross, (ii) rod tilt, (iii) singularity distance, (iv) actuator stroke,
//! (v) tilting-axis range. A point with no real s = (-1, -1, -1) branch is `out_of_reach`.
//!
//! Grid points are classified independently (in parallel with rayon, one z layer at a time,
//! collected in order); every reduction is sequential and in integers, so the summary is
//! identical whatever the thread count.
//!
//! The files: `grid.rs` (the box sampled and its grid, [`grid_for`]), `classify.rs` (one point:
//! its branches and the binding constraint, [`classify()`]), `largest_box.rs` (the largest box
//! inside, [`largest_box()`]), `adaptive.rs` (the workspace at a fine step refined where the
//! boundary passes, [`compute_adaptive`]), `refined_box.rs` (its largest box); here, the types
//! of a result and the run over the grid ([`compute`]).

mod adaptive;
mod classify;
mod grid;
mod largest_box;
mod refined_box;

use nalgebra::Vector3;

use crate::par::*;
use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::spec::Machine;

pub use adaptive::{
    AdaptiveSummary, BOUNDARY_SAMPLES, DEFAULT_COARSE_FACTOR, EXACT_BOX_POINTS,
    SAMPLED_CONFIDENCE_DELTA, compute_adaptive, compute_adaptive_with,
};
pub use classify::{ALPHA_MATCH_RAD, classify, grid_point_of, manufacturing_tip, tool_tip};
pub use grid::{Bounds, Grid, GridBox, MAX_GRID_POINTS, default_bounds, grid_for, round_bounds};
pub use largest_box::{BoxMeasure, cube_in, largest_box, largest_box_by, largest_cube};

/// Bounds on the velocity amplification factors (constraint (iii)): the comparative study's
/// 1/3 < lambda_i < 3 (Wenger, Gosselin, Chablat 2001, eq. (4)).
pub const PAPER_LAMBDA_BOUNDS: [f64; 2] = [1.0 / 3.0, 3.0];

/// Which point's workspace is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Of {
    /// The platform point P, in the base frame (AIM 2007, Fig. 7).
    Platform,
    /// The tool tip U = P + Delta (0, -sin(alpha), cos(alpha)), eq. (27), in the base frame.
    Tool,
    /// The tool tip in the table frame R_t with theta1 = alpha, theta2 = phi1 = phi2 = 0:
    /// eq. (26), the tool axis stays perpendicular to the part (AIM 2007, Fig. 8).
    Manufacturing,
}

impl Of {
    pub fn name(self) -> &'static str {
        match self {
            Of::Platform => "platform",
            Of::Tool => "tool",
            Of::Manufacturing => "manufacturing",
        }
    }

    /// The frame the grid coordinates are expressed in.
    pub fn frame(self) -> &'static str {
        match self {
            Of::Platform | Of::Tool => "base frame R_b (z down)",
            Of::Manufacturing => "table frame R_t (theta1 = alpha, theta2 = 0)",
        }
    }
}

/// The constraints of section IV, AIM 2007, in the order used to name the binding one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Constraint {
    /// (i) interference: the two rods of leg I cross, R1 cos(alpha) <= r1 (section III.C).
    RodsCross,
    /// (ii) mechanical limits of the passive joints: a rod tilted beyond `rod_tilt_max` from
    /// its slider axis.
    RodTilt,
    /// (iii) distance to serial and parallel singularities: a velocity amplification factor
    /// outside [lambda_lo, lambda_hi].
    Singularity,
    /// (iv) actuator stroke: a slider outside [rho_min, rho_max].
    Stroke,
    /// (v) tilting-axis range (manufacturing workspace only): theta1 = alpha outside
    /// [theta1_min, theta1_max].
    Theta1Range,
}

impl Constraint {
    pub const ALL: [Constraint; 5] = [
        Constraint::RodsCross,
        Constraint::RodTilt,
        Constraint::Singularity,
        Constraint::Stroke,
        Constraint::Theta1Range,
    ];

    pub fn code(self) -> &'static str {
        match self {
            Constraint::RodsCross => "rods_cross",
            Constraint::RodTilt => "rod_tilt",
            Constraint::Singularity => "singularity",
            Constraint::Stroke => "stroke",
            Constraint::Theta1Range => "theta1_range",
        }
    }

    /// The paper's numbering and a short description, for summaries and legends.
    pub fn label(self) -> &'static str {
        match self {
            Constraint::RodsCross => "(i) leg-I rods cross",
            Constraint::RodTilt => "(ii) rod tilt",
            Constraint::Singularity => "(iii) singularity distance",
            Constraint::Stroke => "(iv) actuator stroke",
            Constraint::Theta1Range => "(v) tilting-axis range",
        }
    }

    fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

/// A set of failed constraints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct Fails(u8);

impl Fails {
    pub fn none(self) -> bool {
        self.0 == 0
    }
    pub fn has(self, c: Constraint) -> bool {
        self.0 & c.bit() != 0
    }
    pub fn add(&mut self, c: Constraint) {
        self.0 |= c.bit();
    }
    pub fn count(self) -> u32 {
        self.0.count_ones()
    }
    /// The first failed constraint in the order of [`Constraint::ALL`].
    pub fn first(self) -> Option<Constraint> {
        Constraint::ALL.into_iter().find(|c| self.has(*c))
    }
    pub fn iter(self) -> impl Iterator<Item = Constraint> {
        Constraint::ALL.into_iter().filter(move |c| self.has(*c))
    }
}

/// What a grid point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Outcome {
    Inside,
    /// Outside, the reference branch's first failed constraint.
    Bound(Constraint),
    /// No real inverse-kinematics branch with s = (-1, -1, -1).
    OutOfReach,
}

impl Outcome {
    /// Every outcome, in the order of summaries and legends.
    pub const ALL: [Outcome; 7] = [
        Outcome::Inside,
        Outcome::Bound(Constraint::RodsCross),
        Outcome::Bound(Constraint::RodTilt),
        Outcome::Bound(Constraint::Singularity),
        Outcome::Bound(Constraint::Stroke),
        Outcome::Bound(Constraint::Theta1Range),
        Outcome::OutOfReach,
    ];

    pub fn code(self) -> &'static str {
        match self {
            Outcome::Inside => "inside",
            Outcome::Bound(c) => c.code(),
            Outcome::OutOfReach => "out_of_reach",
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Outcome::Inside => "inside",
            Outcome::Bound(c) => c.label(),
            Outcome::OutOfReach => "no s=(-1,-1,-1) branch",
        }
    }

    /// Position in [`Outcome::ALL`].
    pub fn index(self) -> usize {
        match self {
            Outcome::Inside => 0,
            Outcome::Bound(c) => 1 + c as usize,
            Outcome::OutOfReach => 6,
        }
    }
}

/// How to sample a workspace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorkspaceOptions {
    pub of: Of,
    /// Tool length Delta (mm), eqs. (26)-(27); ignored for [`Of::Platform`].
    pub tool_length: f64,
    /// Grid step (mm), the same along the three axes.
    pub step: f64,
    /// Box sampled; `None`: [`default_bounds`] rounded outward to multiples of the step.
    pub bounds: Option<Bounds>,
    /// Bounds on the amplification factors, constraint (iii).
    pub lambda: [f64; 2],
}

/// The branch reported for a grid point (the reference branch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointBranch {
    pub pose: ModulePose,
    pub rho: Sliders,
    /// Velocity amplification factors, largest first.
    pub lambda: [f64; 3],
}

/// The classification of one grid point: one row of the points CSV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointResult {
    /// Grid point: P, the tool tip, or the tool tip in the table frame, per [`Of`].
    pub q: Vector3<f64>,
    pub outcome: Outcome,
    /// Every constraint the reference branch fails.
    pub fails: Fails,
    pub branch: Option<PointBranch>,
}

/// The outcome of every grid point, x fastest, then y, then z.
#[derive(Debug, Clone, PartialEq)]
pub struct OutcomeGrid {
    pub grid: Grid,
    pub of: Of,
    pub tool_length: f64,
    pub outcome: Vec<Outcome>,
}

impl OutcomeGrid {
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> Outcome {
        self.outcome[self.grid.index(i, j, k)]
    }
}

/// The summary of one workspace.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkspaceSummary {
    pub of: Of,
    pub tool_length: f64,
    pub lambda: [f64; 2],
    pub grid: Grid,
    pub points: u64,
    pub inside: u64,
    /// inside x step^3 (mm^3): each grid point stands for the cube of side `step` around it.
    pub volume_mm3: f64,
    /// The same count on the grid of step 2h made of the points with even indices (mm^3).
    pub volume_double_step_mm3: f64,
    /// Bounding box of the inside grid points.
    pub bbox: Option<Bounds>,
    /// Largest axis-aligned box whose grid points are all inside (corners are grid points).
    pub largest_box: Option<GridBox>,
    /// Largest axis-aligned cube whose grid points are all inside.
    pub largest_cube: Option<GridBox>,
    /// True when an inside point lies on the outer faces of the grid: the bounds cut the
    /// workspace and the volume is a lower bound.
    pub touches_bounds: bool,
    /// Points per outcome, in the order of [`Outcome::ALL`].
    pub binding: [u64; 7],
    /// Points whose reference branch fails each constraint, in the order of
    /// [`Constraint::ALL`] (a point counts once for each failure).
    pub failures: [u64; 5],
}

impl WorkspaceSummary {
    pub fn volume_litres(&self) -> f64 {
        self.volume_mm3 * 1e-6
    }

    /// Discretization error estimate: |V(h) - V(2h)| (mm^3), the change when the step was
    /// last halved (V(2h) from the even-index subgrid of the same run).
    pub fn volume_error_mm3(&self) -> f64 {
        (self.volume_mm3 - self.volume_double_step_mm3).abs()
    }

    /// Size (mm) and volume (mm^3) of the largest inside box.
    pub fn largest_box_size(&self) -> Option<(Bounds, f64)> {
        self.box_size(self.largest_box)
    }

    /// Size (mm) and volume (mm^3) of the largest inside cube.
    pub fn largest_cube_size(&self) -> Option<(Bounds, f64)> {
        self.box_size(self.largest_cube)
    }

    fn box_size(&self, b: Option<GridBox>) -> Option<(Bounds, f64)> {
        b.map(|b| {
            let g = &self.grid;
            let lo = g.point(b.lo[0], b.lo[1], b.lo[2]);
            let hi = g.point(b.hi[0], b.hi[1], b.hi[2]);
            let e = hi - lo;
            (Bounds { min: lo, max: hi }, e.x * e.y * e.z)
        })
    }
}

/// A computed workspace: the summary and every point's outcome (for pictures).
#[derive(Debug, Clone, PartialEq)]
pub struct Workspace {
    pub summary: WorkspaceSummary,
    pub map: OutcomeGrid,
}

/// Samples the workspace. `on_point` sees every grid point in grid order (x fastest, then y,
/// then z) and may stop the run by returning an error; `progress` receives the number of points
/// done after each z layer.
pub fn compute<E>(
    m: &Machine,
    opts: &WorkspaceOptions,
    progress: &(dyn Fn(u64) + Sync),
    mut on_point: impl FnMut(&PointResult) -> Result<(), E>,
) -> Result<Result<Workspace, String>, E> {
    let grid = match grid_for(m, opts) {
        Ok(g) => g,
        Err(e) => return Ok(Err(e)),
    };
    let [nx, ny, nz] = grid.n;
    let mut outcome = Vec::with_capacity(grid.len());
    let mut binding = [0u64; 7];
    let mut failures = [0u64; 5];
    let mut inside = 0u64;
    let mut inside_even = 0u64;
    let mut touches = false;
    let mut lo = [usize::MAX; 3];
    let mut hi = [0usize; 3];
    for k in 0..nz {
        let layer: Vec<PointResult> = (0..ny)
            .into_par_iter()
            .flat_map_iter(|j| (0..nx).map(move |i| classify(m, opts, &grid.point(i, j, k))))
            .collect();
        for (idx, r) in layer.iter().enumerate() {
            let (i, j) = (idx % nx, idx / nx);
            on_point(r)?;
            binding[r.outcome.index()] += 1;
            for c in r.fails.iter() {
                failures[c as usize] += 1;
            }
            if r.outcome == Outcome::Inside {
                inside += 1;
                if i % 2 == 0 && j % 2 == 0 && k % 2 == 0 {
                    inside_even += 1;
                }
                for (d, v) in [i, j, k].into_iter().enumerate() {
                    lo[d] = lo[d].min(v);
                    hi[d] = hi[d].max(v);
                    if v == 0 || v + 1 == grid.n[d] {
                        touches = true;
                    }
                }
            }
            outcome.push(r.outcome);
        }
        progress(((k + 1) * nx * ny) as u64);
    }
    let map = OutcomeGrid {
        grid,
        of: opts.of,
        tool_length: opts.tool_length,
        outcome,
    };
    let h3 = grid.step.powi(3);
    let bbox = (inside > 0).then(|| Bounds {
        min: grid.point(lo[0], lo[1], lo[2]),
        max: grid.point(hi[0], hi[1], hi[2]),
    });
    let largest_box = (inside > 0).then(|| largest_box(&map, lo, hi)).flatten();
    let largest_cube = (inside > 0).then(|| largest_cube(&map, lo, hi)).flatten();
    let summary = WorkspaceSummary {
        of: opts.of,
        tool_length: opts.tool_length,
        lambda: opts.lambda,
        grid,
        points: grid.len() as u64,
        inside,
        volume_mm3: inside as f64 * h3,
        volume_double_step_mm3: inside_even as f64 * 8.0 * h3,
        bbox,
        largest_box,
        largest_cube,
        touches_bounds: touches,
        binding,
        failures,
    };
    Ok(Ok(Workspace { summary, map }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_ik_point_is_inside_the_platform_workspace() {
        let m = Machine::default_verne();
        let opts = WorkspaceOptions {
            of: Of::Platform,
            tool_length: 0.0,
            step: 10.0,
            bounds: None,
            lambda: [0.0, f64::INFINITY],
        };
        let r = classify(&m, &opts, &Vector3::new(-240.0, -86.0, 1000.0));
        let b = r.branch.unwrap();
        assert!((b.pose.alpha - 0.052204524).abs() < 1e-8);
        assert!((b.rho - Sliders::new(368.354796, 84.956547, 179.032689)).amax() < 1e-5);
        // Every working point of a tool workspace with Delta = 0 is the platform's.
        let tool = classify(
            &m,
            &WorkspaceOptions {
                of: Of::Tool,
                ..opts
            },
            &Vector3::new(-240.0, -86.0, 1000.0),
        );
        assert_eq!(tool.outcome, r.outcome);
        assert!((tool.branch.unwrap().rho - b.rho).amax() < 1e-6);
    }

    #[test]
    fn largest_box_of_a_known_shape() {
        // An L-shaped region: a 5x4x3 block plus a 2x2x6 column.
        let grid = Grid {
            origin: Vector3::zeros(),
            step: 1.0,
            n: [8, 8, 8],
        };
        let mut outcome = vec![Outcome::OutOfReach; grid.len()];
        for k in 0..3 {
            for j in 0..4 {
                for i in 0..5 {
                    outcome[grid.index(i + 1, j + 2, k)] = Outcome::Inside;
                }
            }
        }
        for k in 0..7 {
            for j in 0..2 {
                for i in 0..2 {
                    outcome[grid.index(i + 5, j, k)] = Outcome::Inside;
                }
            }
        }
        let map = OutcomeGrid {
            grid,
            of: Of::Platform,
            tool_length: 0.0,
            outcome,
        };
        let b = largest_box(&map, [0; 3], [7; 3]).unwrap();
        assert_eq!(b.lo, [1, 2, 0]);
        assert_eq!(b.hi, [5, 5, 2]);
        assert_eq!(b.edges(), [4, 3, 2]);
    }
}
