//! Inverse kinematics (four working modes) and forward kinematics (two assembly modes) of a
//! glider (section 2.3, Wenger 2001), each solution labelled with its modes.
//!
//! Labels (docs/gliders.md): the working mode of strut i is the sign of (p - c_i).u_i, the
//! diagonal entry of B in section 2.3 (P ahead of its slider along the guide: `+`); the assembly
//! mode is the sign of det A = (p - c) x (p - d) (P to the left of C->D: `+`). A double root,
//! where the two signs meet, is labelled `0`: a serial (strut) or parallel (assembly) singularity.

use std::fmt;

use arrayvec::ArrayVec;
use nalgebra::{Point2, Vector2};

use super::spec::GliderSpec;
use super::tolerance::{
    COINCIDENT_REL, DOUBLE_ROOT_REL, PARALLEL_SINGULAR_SIN, SERIAL_SINGULAR_COS,
};

/// Which root of a quadratic a solution is: the `+` or `-` sign, or the double root where both
/// meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Branch {
    Plus,
    Minus,
    Double,
}

impl Branch {
    /// `+`, `-` or `0`.
    pub fn symbol(self) -> char {
        match self {
            Branch::Plus => '+',
            Branch::Minus => '-',
            Branch::Double => '0',
        }
    }

    /// The branch of a signed quantity, `Double` when |value| <= tol.
    pub fn of(value: f64, tol: f64) -> Branch {
        if value > tol {
            Branch::Plus
        } else if value < -tol {
            Branch::Minus
        } else {
            Branch::Double
        }
    }

    /// +1, -1 or 0.
    pub fn sign(self) -> f64 {
        match self {
            Branch::Plus => 1.0,
            Branch::Minus => -1.0,
            Branch::Double => 0.0,
        }
    }
}

/// Working mode: the branch of each strut (sign of (p - c).u1 and (p - d).u2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct WorkingMode {
    pub strut1: Branch,
    pub strut2: Branch,
}

impl WorkingMode {
    /// The four regular working modes, in the order `++`, `+-`, `-+`, `--`.
    pub const ALL: [WorkingMode; 4] = [
        WorkingMode::new(Branch::Plus, Branch::Plus),
        WorkingMode::new(Branch::Plus, Branch::Minus),
        WorkingMode::new(Branch::Minus, Branch::Plus),
        WorkingMode::new(Branch::Minus, Branch::Minus),
    ];

    pub const fn new(strut1: Branch, strut2: Branch) -> WorkingMode {
        WorkingMode { strut1, strut2 }
    }

    /// Parses `++`, `+-`, `-+`, `--` (and `0` for a double root).
    pub fn parse(label: &str) -> Option<WorkingMode> {
        let b = |c| match c {
            '+' => Some(Branch::Plus),
            '-' => Some(Branch::Minus),
            '0' => Some(Branch::Double),
            _ => None,
        };
        let mut chars = label.chars();
        let (c1, c2) = (chars.next()?, chars.next()?);
        if chars.next().is_some() {
            return None;
        }
        Some(WorkingMode::new(b(c1)?, b(c2)?))
    }
}

impl fmt::Display for WorkingMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}", self.strut1.symbol(), self.strut2.symbol())
    }
}

/// One inverse-kinematics solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    pub mode: WorkingMode,
    /// Joint values (rho1, rho2).
    pub rho: Vector2<f64>,
    /// Assembly mode of (P, rho): sign of det A.
    pub assembly: Branch,
    /// Whether rho is inside the joint ranges of the spec.
    pub within_limits: bool,
}

/// One forward-kinematics solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FkSolution {
    /// Assembly mode: sign of det A (`Double` at a parallel singularity, where both meet).
    pub assembly: Branch,
    pub p: Point2<f64>,
    /// Working mode the solution lies in.
    pub mode: WorkingMode,
}

/// The forward kinematics of one joint vector.
#[derive(Debug, Clone, PartialEq)]
pub enum ForwardKinematics {
    /// Every real solution: 0, 1 (double root at a parallel singularity) or 2.
    Isolated(Vec<FkSolution>),
    /// C = D with l1 = l2 (structural singularity, Fig. 5, Wenger 2001): P can be anywhere on
    /// the circle of radius l1 about C.
    StructuralSingularity { centre: Point2<f64>, radius: f64 },
}

impl ForwardKinematics {
    /// The isolated solutions (empty for a structural singularity).
    pub fn solutions(&self) -> &[FkSolution] {
        match self {
            ForwardKinematics::Isolated(v) => v,
            ForwardKinematics::StructuralSingularity { .. } => &[],
        }
    }
}

/// Roots rho of |p - (o + rho u)| = l for a unit u, labelled by the sign of (p - c).u:
/// rho = (p - o).u -/+ sqrt(l^2 - ((p - o) x u)^2) (section 2.3, Wenger 2001).
/// Returns the `+` root then the `-` root, or one `Double` root, or nothing.
pub fn strut_roots(
    o: Point2<f64>,
    u: Vector2<f64>,
    l: f64,
    p: Point2<f64>,
) -> ArrayVec<(Branch, f64), 2> {
    let w = p - o;
    let along = w.dot(&u);
    let across = (w.x * u.y - w.y * u.x).abs();
    // (l - |x|)(l + |x|) keeps its accuracy near tangency, where l^2 - x^2 would cancel.
    let disc = (l - across) * (l + across);
    let tol = DOUBLE_ROOT_REL * l * l;
    let mut roots = ArrayVec::new();
    match disc {
        d if d < -tol => {}
        d if d <= tol => roots.push((Branch::Double, along)),
        d => {
            let r = d.sqrt();
            roots.extend([(Branch::Plus, along - r), (Branch::Minus, along + r)]);
        }
    }
    roots
}

/// The root of one strut on one branch, if it exists (a `Double` request only matches a double
/// root, and a `Plus`/`Minus` request does not match one).
pub fn strut_root(
    o: Point2<f64>,
    u: Vector2<f64>,
    l: f64,
    p: Point2<f64>,
    branch: Branch,
) -> Option<f64> {
    strut_roots(o, u, l, p)
        .into_iter()
        .find(|&(b, _)| b == branch)
        .map(|(_, r)| r)
}

/// Working mode of a pose: signs of (p - c).u1 / l1 and (p - d).u2 / l2, `Double` below
/// [`SERIAL_SINGULAR_COS`].
pub fn working_mode_of(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> WorkingMode {
    let (c, d) = spec.sliders(rho);
    WorkingMode::new(
        Branch::of((p - c).dot(&spec.u1()) / spec.l1, SERIAL_SINGULAR_COS),
        Branch::of((p - d).dot(&spec.u2()) / spec.l2, SERIAL_SINGULAR_COS),
    )
}

/// Assembly mode of a pose: sign of det A / (l1 l2), `Double` below [`PARALLEL_SINGULAR_SIN`].
pub fn assembly_of(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> Branch {
    let (c, d) = spec.sliders(rho);
    let (pc, pd) = (p - c, p - d);
    Branch::of(
        (pc.x * pd.y - pc.y * pd.x) / (spec.l1 * spec.l2),
        PARALLEL_SINGULAR_SIN,
    )
}

/// Every real inverse-kinematics solution at P: up to four, one per working mode (fewer when a
/// strut cannot reach its guide or touches it tangentially). Solutions outside the joint ranges
/// are kept and flagged.
pub fn inverse_kinematics(spec: &GliderSpec, p: Point2<f64>) -> Vec<IkSolution> {
    let r1 = strut_roots(spec.a(), spec.u1(), spec.l1, p);
    let r2 = strut_roots(spec.b(), spec.u2(), spec.l2, p);
    let mut out = Vec::with_capacity(r1.len() * r2.len());
    for &(b1, rho1) in &r1 {
        for &(b2, rho2) in &r2 {
            let rho = Vector2::new(rho1, rho2);
            out.push(IkSolution {
                mode: WorkingMode::new(b1, b2),
                rho,
                assembly: assembly_of(spec, p, rho),
                within_limits: spec.within_limits(rho),
            });
        }
    }
    out
}

/// The joint values of P in one working mode, if that mode reaches P.
pub fn inverse_kinematics_in_mode(
    spec: &GliderSpec,
    p: Point2<f64>,
    mode: WorkingMode,
) -> Option<Vector2<f64>> {
    let rho1 = strut_root(spec.a(), spec.u1(), spec.l1, p, mode.strut1)?;
    let rho2 = strut_root(spec.b(), spec.u2(), spec.l2, p, mode.strut2)?;
    Some(Vector2::new(rho1, rho2))
}

/// Every real forward-kinematics solution for rho: the intersections of the circle of radius l1
/// about C with the circle of radius l2 about D (section 2.3, Wenger 2001). Computed as
/// P = C + a e + h n with e = (D - C)/|D - C|, n = e rotated by +90 deg, a = (|CD|^2 + l1^2 -
/// l2^2) / (2 |CD|), h^2 = (l1 - a)(l1 + a); the `+` assembly mode is h > 0 (det A = h |CD| > 0).
/// Near tangency (|h^2| <= [`DOUBLE_ROOT_REL`] l1^2) the two modes merge into one double root.
pub fn forward_kinematics(spec: &GliderSpec, rho: Vector2<f64>) -> ForwardKinematics {
    let (c, d) = spec.sliders(rho);
    let v = d - c;
    let dist = v.norm();
    let (l1, l2) = (spec.l1, spec.l2);
    if dist <= COINCIDENT_REL * l1 {
        return if (l1 - l2).abs() <= COINCIDENT_REL * l1 {
            ForwardKinematics::StructuralSingularity {
                centre: c,
                radius: l1,
            }
        } else {
            ForwardKinematics::Isolated(Vec::new())
        };
    }
    let e = v / dist;
    let n = Vector2::new(-e.y, e.x);
    let a = (dist * dist + (l1 - l2) * (l1 + l2)) / (2.0 * dist);
    let h2 = (l1 - a) * (l1 + a);
    let tol = DOUBLE_ROOT_REL * l1 * l1;
    let mut out = Vec::with_capacity(2);
    let mut push = |assembly: Branch, p: Point2<f64>| {
        out.push(FkSolution {
            assembly,
            p,
            mode: working_mode_of(spec, p, rho),
        })
    };
    if h2 < -tol {
        // The circles do not meet: no assembly.
    } else if h2 <= tol {
        push(Branch::Double, c + e * a);
    } else {
        let h = h2.sqrt();
        push(Branch::Plus, c + e * a + n * h);
        push(Branch::Minus, c + e * a - n * h);
    }
    ForwardKinematics::Isolated(out)
}

/// The forward-kinematics solution in one assembly mode, if it exists.
pub fn forward_kinematics_in_mode(
    spec: &GliderSpec,
    rho: Vector2<f64>,
    assembly: Branch,
) -> Option<Point2<f64>> {
    forward_kinematics(spec, rho)
        .solutions()
        .iter()
        .find(|s| s.assembly == assembly)
        .map(|s| s.p)
}
