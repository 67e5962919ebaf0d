//! Workspace of the VERNE machine sampled on a grid (AIM 2007, section IV): the points reachable
//! by the platform point P, by the tool tip (eq. (27), AIM 2007) or by the tool tip in the table
//! frame with the table following the platform (eq. (26), AIM 2007, with theta1 = alpha and
//! theta2 = phi1 = phi2 = 0), in the machine's configuration s = (-1, -1, -1), with the
//! constraints (i)-(v) reported separately.
//!
//! Per grid point q:
//! - `platform`: the inverse kinematics of P = q ([`ik::solve`]).
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

use std::f64::consts::PI;

use crate::par::*;
use nalgebra::Vector3;

use crate::math::trig::{MAX_TRIG_ROOTS, Trig};
use crate::parallel_module::branches::{Reason, WORKING_CONFIG};
use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::parallel_module::ik::{self, IkBranch, wrap_angle};
use crate::parallel_module::kinetostatics::kinetostatics;
use crate::spec::{Machine, ModuleGeometry, TableGeometry};
use crate::tolerance::LIMIT_SLACK;

/// Bounds on the velocity amplification factors (constraint (iii)): the comparative study's
/// 1/3 < lambda_i < 3 (Wenger, Gosselin, Chablat 2001, eq. (4)).
pub const PAPER_LAMBDA_BOUNDS: [f64; 2] = [1.0 / 3.0, 3.0];

/// An inverse-kinematics branch of P(alpha_root) belongs to the root alpha_root when their
/// angles differ by less than this (rad). The root of the degree-6 polynomial and the branch's
/// alpha (polished on eqs. (3)-(6)) agree to about 1e-12 rad at a simple root.
pub const ALPHA_MATCH_RAD: f64 = 1e-7;

/// Most grid points of one run (a guard against a typo in `--step`): 2^31.
pub const MAX_GRID_POINTS: u64 = 1 << 31;

/// Samples of the tilting angle used to bound the manufacturing workspace's default box; the
/// box is widened by the largest distance a corner moves between two samples.
const MANUFACTURING_BOUND_SAMPLES: usize = 64;

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

/// An axis-aligned box [min, max] (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub min: Vector3<f64>,
    pub max: Vector3<f64>,
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

/// A regular grid: points origin + step (i, j, k), 0 <= i < `n[0]`, ...
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub origin: Vector3<f64>,
    pub step: f64,
    pub n: [usize; 3],
}

impl Grid {
    /// The grid from `b.min` with the given step, up to `b.max` (the last point is the largest
    /// one not beyond `b.max`, within a part in 1e9 of the step).
    pub fn new(b: &Bounds, step: f64) -> Result<Grid, String> {
        if !(step.is_finite() && step > 0.0) {
            return Err(format!(
                "the step must be a positive number of mm, got {step}"
            ));
        }
        let mut n = [0usize; 3];
        for (d, name) in ["x", "y", "z"].iter().enumerate() {
            let (lo, hi) = (b.min[d], b.max[d]);
            if !(lo.is_finite() && hi.is_finite()) || lo > hi {
                return Err(format!(
                    "bounds: {name} range [{lo}, {hi}] is empty or not finite"
                ));
            }
            n[d] = ((hi - lo) / step + 1e-9).floor() as usize + 1;
        }
        let total = n.iter().map(|&v| v as u64).product::<u64>();
        if total > MAX_GRID_POINTS {
            return Err(format!(
                "{} x {} x {} = {total} grid points is more than {MAX_GRID_POINTS}: increase the step or narrow the bounds",
                n[0], n[1], n[2]
            ));
        }
        Ok(Grid {
            origin: b.min,
            step,
            n,
        })
    }

    pub fn len(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.n[1] + j) * self.n[0] + i
    }

    #[inline]
    pub fn point(&self, i: usize, j: usize, k: usize) -> Vector3<f64> {
        self.origin + Vector3::new(i as f64, j as f64, k as f64) * self.step
    }

    /// Coordinate of index `i` along axis `d`.
    #[inline]
    pub fn coord(&self, d: usize, i: usize) -> f64 {
        self.origin[d] + i as f64 * self.step
    }

    /// The last grid point.
    pub fn max(&self) -> Vector3<f64> {
        self.point(self.n[0] - 1, self.n[1] - 1, self.n[2] - 1)
    }
}

/// A box of grid points, index ranges inclusive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridBox {
    pub lo: [usize; 3],
    pub hi: [usize; 3],
}

impl GridBox {
    /// Edge lengths in steps.
    pub fn edges(&self) -> [usize; 3] {
        [0, 1, 2].map(|d| self.hi[d] - self.lo[d])
    }
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
        self.largest_box.map(|b| {
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

/// Tool tip U = bT_pl (0, 0, Delta): eq. (27), AIM 2007.
pub fn tool_tip(p: &Vector3<f64>, alpha: f64, delta: f64) -> Vector3<f64> {
    let (s, c) = alpha.sin_cos();
    Vector3::new(p.x, p.y - delta * s, p.z + delta * c)
}

/// Tool tip in the table frame with theta1 = alpha, theta2 = phi1 = phi2 = 0: eq. (26),
/// AIM 2007, X_u = xp, Y_u = V1, Z_u = sin(theta1) yp + V2 with
/// V1 = Delta sin(alpha - theta1) - cos(theta1) yp - sin(theta1) (zp - d_a),
/// V2 = d_t - cos(theta1) zp + d_a cos(theta1) - Delta cos(alpha - theta1).
pub fn manufacturing_tip(
    t: &TableGeometry,
    p: &Vector3<f64>,
    alpha: f64,
    delta: f64,
) -> Vector3<f64> {
    let theta1 = alpha;
    let (s, c) = theta1.sin_cos();
    let v1 = delta * (alpha - theta1).sin() - c * p.y - s * (p.z - t.d_a);
    let v2 = t.d_t - c * p.z + t.d_a * c - delta * (alpha - theta1).cos();
    Vector3::new(p.x, v1, s * p.y + v2)
}

/// The grid point of a platform pose for the chosen workspace.
pub fn grid_point_of(
    m: &Machine,
    of: Of,
    delta: f64,
    p: &Vector3<f64>,
    alpha: f64,
) -> Vector3<f64> {
    match of {
        Of::Platform => *p,
        Of::Tool => tool_tip(p, alpha, delta),
        Of::Manufacturing => manufacturing_tip(&m.table, p, alpha, delta),
    }
}

/// P as a function of alpha for a fixed grid point: (x, a0 + a_s s + a_c c, b0 + b_s s + b_c c),
/// eqs. (26)-(27) solved for P.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PlatformOfAlpha {
    x: f64,
    /// [a0, a_s, a_c]
    a: [f64; 3],
    /// [b0, b_s, b_c]
    b: [f64; 3],
}

impl PlatformOfAlpha {
    fn new(of: Of, t: &TableGeometry, delta: f64, q: &Vector3<f64>) -> Self {
        match of {
            Of::Platform => PlatformOfAlpha {
                x: q.x,
                a: [q.y, 0.0, 0.0],
                b: [q.z, 0.0, 0.0],
            },
            // eq. (27): yp = y_U + Delta sin(alpha), zp = z_U - Delta cos(alpha).
            Of::Tool => PlatformOfAlpha {
                x: q.x,
                a: [q.y, delta, 0.0],
                b: [q.z, 0.0, -delta],
            },
            // eq. (26) with theta1 = alpha: (Y, Z') = -R(alpha) (yp, zp - d_a) with
            // Z' = Z - d_t + Delta and R = [[c, s], [-s, c]], so yp = -c Y + s Z',
            // zp = d_a - s Y - c Z'.
            Of::Manufacturing => {
                let zq = q.z - t.d_t + delta;
                PlatformOfAlpha {
                    x: q.x,
                    a: [0.0, zq, -q.y],
                    b: [t.d_a, -q.y, -zq],
                }
            }
        }
    }

    fn at(&self, alpha: f64) -> Vector3<f64> {
        let (s, c) = alpha.sin_cos();
        Vector3::new(
            self.x,
            self.a[0] + self.a[1] * s + self.a[2] * c,
            self.b[0] + self.b[1] * s + self.b[2] * c,
        )
    }

    /// Eq. (15), AIM 2007, at P(alpha): a trigonometric polynomial of degree 3 in alpha (the
    /// paper's degree-6 polynomial in tan(alpha/2)),
    ///
    /// G = R1^2 sin^2(alpha) (u^2 - L1^2 + K) + K yp^2, K = R1^2 + r1^2 - 2 R1 r1 cos(alpha),
    /// u = xp + D1 - d1, yp = a0 + a_s sin(alpha) + a_c cos(alpha).
    fn coupling_equation(&self, g: &ModuleGeometry) -> Trig {
        let (r, rr, l) = (g.r_big1, g.r_small1, g.l1);
        let u = self.x + g.dx1;
        let k = Trig::linear(r * r + rr * rr, -2.0 * r * rr, 0.0);
        let yp = Trig::linear(self.a[0], self.a[2], self.a[1]);
        let sin = Trig::linear(0.0, 0.0, 1.0);
        sin.mul_deg::<1, 1>(&sin)
            .mul_deg::<2, 1>(&k.add(&Trig::linear(u * u - l * l, 0.0, 0.0)))
            .scale(r * r)
            .add(&k.mul_deg::<1, 2>(&yp.mul_deg::<1, 1>(&yp)))
    }
}

/// Every real alpha in (-pi, pi] with G(alpha) = 0, sorted: isolated on the circle by
/// [`Trig::roots`] (complete by construction; a double root or a pair too close to separate is
/// one candidate, which the inverse kinematics at P(alpha) then decides).
fn coupling_roots(g: &Trig) -> arrayvec::ArrayVec<f64, MAX_TRIG_ROOTS> {
    let mut out: arrayvec::ArrayVec<f64, MAX_TRIG_ROOTS> =
        g.roots().into_iter().map(wrap_angle).collect();
    out.sort_by(f64::total_cmp);
    out
}

/// Constraints (i)-(v) for one branch with s = (-1, -1, -1).
fn branch_fails(
    m: &Machine,
    of: Of,
    lambda: [f64; 2],
    b: &IkBranch,
    p: &Vector3<f64>,
) -> (Fails, [f64; 3]) {
    let mut f = Fails::default();
    if b.verdict.has(Reason::RodsCross) {
        f.add(Constraint::RodsCross);
    }
    if b.verdict.has(Reason::RodTilt) {
        f.add(Constraint::RodTilt);
    }
    let pose = ModulePose {
        p: *p,
        alpha: b.alpha,
    };
    let k = kinetostatics(&m.module, &pose, &b.rho);
    if !k.amplification_within(lambda[0], lambda[1]) {
        f.add(Constraint::Singularity);
    }
    if b.verdict.has(Reason::Rho1Stroke)
        || b.verdict.has(Reason::Rho2Stroke)
        || b.verdict.has(Reason::Rho3Stroke)
    {
        f.add(Constraint::Stroke);
    }
    if of == Of::Manufacturing
        && (b.alpha < m.limits.theta1_min - LIMIT_SLACK
            || b.alpha > m.limits.theta1_max + LIMIT_SLACK)
    {
        f.add(Constraint::Theta1Range);
    }
    (f, k.amplification)
}

/// Classifies one grid point.
pub fn classify(m: &Machine, opts: &WorkspaceOptions, q: &Vector3<f64>) -> PointResult {
    let mut best: Option<(Fails, PointBranch)> = None;
    let mut consider = |b: &IkBranch, p: &Vector3<f64>| {
        if b.config != WORKING_CONFIG {
            return;
        }
        let (fails, lambda) = branch_fails(m, opts.of, opts.lambda, b, p);
        let better = match &best {
            None => true,
            Some((bf, bb)) => {
                (fails.count(), b.alpha.abs(), b.alpha).partial_cmp(&(
                    bf.count(),
                    bb.pose.alpha.abs(),
                    bb.pose.alpha,
                )) == Some(std::cmp::Ordering::Less)
            }
        };
        if better {
            best = Some((
                fails,
                PointBranch {
                    pose: ModulePose {
                        p: *p,
                        alpha: b.alpha,
                    },
                    rho: b.rho,
                    lambda,
                },
            ));
        }
    };
    match opts.of {
        Of::Platform => {
            for b in ik::solve(m, q) {
                consider(&b, q);
            }
        }
        Of::Tool | Of::Manufacturing => {
            let map = PlatformOfAlpha::new(opts.of, &m.table, opts.tool_length, q);
            let coupling = map.coupling_equation(&m.module);
            for alpha in coupling_roots(&coupling) {
                let p = map.at(alpha);
                for b in ik::solve(m, &p) {
                    if wrap_angle(b.alpha - alpha).abs() < ALPHA_MATCH_RAD {
                        consider(&b, &p);
                    }
                }
            }
        }
    }
    match best {
        None => PointResult {
            q: *q,
            outcome: Outcome::OutOfReach,
            fails: Fails::default(),
            branch: None,
        },
        Some((fails, branch)) => PointResult {
            q: *q,
            outcome: fails.first().map_or(Outcome::Inside, Outcome::Bound),
            fails,
            branch: Some(branch),
        },
    }
}

/// A box that contains every point of the workspace (a proven superset), before rounding.
///
/// Platform: with a rod tilt of at most `rod_tilt_max` = tau from its slider axis (z), a rod's
/// horizontal extent is at most L sin(tau) and its vertical extent, slider above platform
/// (s = -1), between L max(cos(tau), 0) and L (for tau >= 90 degrees, L and 0). With the
/// platform attachments at most R from P vertically, and eqs. (3)-(6):
/// - x: |xp + D1 - d1| <= L1 sin(tau), |xp + D2 - d2| <= L2 sin(tau) and L3 sin(tau);
/// - y: |yp| <= L1 sin(tau) (both leg-I rods), yp in [-r4 - R2 - L2 sin(tau), r4 + R2 + ...]
///   per leg II and III;
/// - z: zp in [rho_min + L cos(tau) - R, rho_max + L + R] for every leg.
///
/// Tool: that box widened by Delta in y and z (eq. (27)). Manufacturing: the platform box's
/// (y, z) rectangle mapped by eq. (26) for theta1 sampled over [theta1_min, theta1_max],
/// widened by the largest distance a corner moves between two samples.
pub fn default_bounds(m: &Machine, of: Of, tool_length: f64) -> Bounds {
    let g = &m.module;
    let lim = &m.limits;
    let tau = lim.rod_tilt_max;
    let hs = if tau < PI / 2.0 { tau.sin() } else { 1.0 };
    let vc = tau.cos().max(0.0);
    let legs = [
        (g.dx1, g.l1, g.r_big1, 0),
        (g.dx2, g.l2, g.r_big2, 1),
        (g.dx2, g.l3, g.r_big2, 2),
    ];
    let mut min = Vector3::repeat(f64::NEG_INFINITY);
    let mut max = Vector3::repeat(f64::INFINITY);
    for (dx, l, r, i) in legs {
        min.x = min.x.max(-dx - l * hs);
        max.x = max.x.min(-dx + l * hs);
        min.z = min.z.max(lim.rho_min[i] + l * vc - r);
        max.z = max.z.min(lim.rho_max[i] + l + r);
    }
    min.y = (-g.l1 * hs)
        .max(-g.r4 - g.r_big2 - g.l2 * hs)
        .max(g.r4 - g.r_big2 - g.l3 * hs);
    max.y = (g.l1 * hs)
        .min(-g.r4 + g.r_big2 + g.l2 * hs)
        .min(g.r4 + g.r_big2 + g.l3 * hs);
    // An empty intersection (a machine that cannot move) still gives a one-point box.
    for d in 0..3 {
        if min[d] > max[d] {
            let mid = 0.5 * (min[d] + max[d]);
            min[d] = mid;
            max[d] = mid;
        }
    }
    let d = tool_length.abs();
    match of {
        Of::Platform => Bounds { min, max },
        Of::Tool => Bounds {
            min: min - Vector3::new(0.0, d, d),
            max: max + Vector3::new(0.0, d, d),
        },
        Of::Manufacturing => {
            let (lo, hi) = (lim.theta1_min.max(-PI), lim.theta1_max.min(PI));
            let n = MANUFACTURING_BOUND_SAMPLES;
            let dth = (hi - lo) / n as f64;
            let mut bmin = Vector3::new(min.x, f64::INFINITY, f64::INFINITY);
            let mut bmax = Vector3::new(max.x, f64::NEG_INFINITY, f64::NEG_INFINITY);
            let mut radius: f64 = 0.0;
            for k in 0..=n {
                let th = lo + dth * k as f64;
                for (y, z) in [
                    (min.y, min.z),
                    (min.y, max.z),
                    (max.y, min.z),
                    (max.y, max.z),
                ] {
                    let p = Vector3::new(0.0, y, z);
                    let q = manufacturing_tip(&m.table, &p, th, tool_length);
                    radius = radius.max(y.hypot(z - m.table.d_a));
                    for dd in 1..3 {
                        bmin[dd] = bmin[dd].min(q[dd]);
                        bmax[dd] = bmax[dd].max(q[dd]);
                    }
                }
            }
            let margin = radius * dth / 2.0;
            bmin.y -= margin;
            bmin.z -= margin;
            bmax.y += margin;
            bmax.z += margin;
            Bounds {
                min: bmin,
                max: bmax,
            }
        }
    }
}

/// `b` rounded outward to multiples of `step`.
pub fn round_bounds(b: &Bounds, step: f64) -> Bounds {
    Bounds {
        min: b.min.map(|v| (v / step).floor() * step),
        max: b.max.map(|v| (v / step).ceil() * step),
    }
}

/// The grid a run with these options samples.
pub fn grid_for(m: &Machine, opts: &WorkspaceOptions) -> Result<Grid, String> {
    let bounds = match opts.bounds {
        Some(b) => b,
        None => round_bounds(&default_bounds(m, opts.of, opts.tool_length), opts.step),
    };
    if !(opts.lambda[0] <= opts.lambda[1] && opts.lambda[0] >= 0.0) {
        return Err(format!(
            "lambda bounds [{}, {}]: need 0 <= LO <= HI",
            opts.lambda[0], opts.lambda[1]
        ));
    }
    if !opts.tool_length.is_finite() {
        return Err("the tool length must be a finite number of mm".into());
    }
    Grid::new(&bounds, opts.step)
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
        touches_bounds: touches,
        binding,
        failures,
    };
    Ok(Ok(Workspace { summary, map }))
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::{platform_transform, table_transform};
    use crate::parallel_module::equations::ModulePose;
    use nalgebra::Vector4;

    #[test]
    fn eq_26_and_27_match_the_matrix_products() {
        let m = Machine::default_verne();
        let t = m.table;
        for (p, alpha, delta) in [
            (Vector3::new(-240.0, -86.0, 1000.0), 0.0522, 50.0),
            (Vector3::new(120.0, 300.0, 1400.0), -0.4, 150.0),
            (Vector3::new(0.0, 0.0, 800.0), 0.0, 0.0),
        ] {
            // bT_pl = trans(P) rot(x, alpha), eq. (1); tool tip (0, 0, Delta) in R_pl.
            let b_t_pl = platform_transform(&ModulePose { p, alpha });
            let u = b_t_pl * Vector4::new(0.0, 0.0, delta, 1.0);
            let tip = tool_tip(&p, alpha, delta);
            assert!((u.xyz() - tip).amax() < 1e-9, "{u} vs {tip}");
            // bT_t = trans(z, d_a) rot(x, theta1) trans(z, d_t) rot(x, pi) rot(z, theta2),
            // eq. (7), with theta1 = alpha, theta2 = 0; tU = bT_t^-1 bU, eq. (25).
            let b_t_t = table_transform(&t, alpha, 0.0);
            let t_u = b_t_t.try_inverse().unwrap() * u;
            let mt = manufacturing_tip(&t, &p, alpha, delta);
            assert!((t_u.xyz() - mt).amax() < 1e-9, "{t_u} vs {mt}");
            // The inverse maps used by the grid search.
            for (of, q) in [(Of::Tool, tip), (Of::Manufacturing, mt)] {
                let back = PlatformOfAlpha::new(of, &t, delta, &q).at(alpha);
                assert!((back - p).amax() < 1e-9, "{of:?}: {back} vs {p}");
            }
        }
    }

    #[test]
    fn coupling_equation_is_eq_15() {
        let m = Machine::default_verne();
        let g = m.module;
        let map = PlatformOfAlpha::new(
            Of::Tool,
            &m.table,
            70.0,
            &Vector3::new(-200.0, 40.0, 1100.0),
        );
        let coupling = map.coupling_equation(&g);
        for alpha in [-2.5, -0.7, -0.1, 0.0, 0.3, 1.2, 2.9, PI] {
            let (s, co) = f64::sin_cos(alpha);
            let p = map.at(alpha);
            let k =
                g.r_big1 * g.r_big1 + g.r_small1 * g.r_small1 - 2.0 * g.r_big1 * g.r_small1 * co;
            let r2s2 = g.r_big1 * g.r_big1 * s * s;
            let u = p.x + g.dx1;
            let eq15 = r2s2 * u * u + k * p.y * p.y - r2s2 * (g.l1 * g.l1 - k);
            let got = coupling.eval(alpha);
            assert!(
                (got - eq15).abs() < 1e-9 * (1.0 + eq15.abs()),
                "{alpha}: {got} vs {eq15}"
            );
        }
    }

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
