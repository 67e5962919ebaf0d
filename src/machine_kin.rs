//! Kinematics of the whole VERNE machine (AIM 2007, section III): the parallel module plus the
//! two-axis tilting table. Inverse kinematics from a tool pose in the workpiece frame R_t to
//! (rho1, rho2, rho3, theta1, theta2), forward kinematics back, and a path helper that picks one
//! branch per row continuously.
//!
//! Model (see docs/conventions-machine.md):
//! - eq. (7), AIM 2007: bT_t = trans(z, d_a) rot(x, theta1) trans(z, d_t) rot(x, pi) rot(z, theta2);
//! - eq. (8): tT_pl = trans(X, Y, Z) rot(z, phi2) rot(x, pi + phi1) trans(z, -Delta);
//! - eq. (1): bT_pl = trans(xp, yp, zp) rot(x, alpha);
//! - bT_t tT_pl = bT_pl holds iff theta2 = -phi2 (eq. (9)) and alpha = theta1 + phi1 (eq. (14));
//! - eq. (26) gives the tool pose in R_t from (xp, yp, zp, alpha, theta1, theta2).
//!
//! Inverse kinematics (re-derived; eqs. (10)-(13) and (17) are not printed in the paper). With
//! theta2 = -phi2, the platform point in the frame after the tilting axis is a constant vector
//! w = trans(z, d_t) rot(x, pi) rot(z, theta2) (U + Delta a), a the tool axis, so that
//! P(theta1) = (w_x, c w_y - s w_z, d_a + s w_y + c w_z), c, s = cos, sin theta1. Eliminating rho1
//! between eqs. (3) and (4) (their difference is eq. (14) of IFToMM 2007, their half-sum eq. (10))
//! gives eq. (15) along the path P(theta1), alpha = theta1 + phi1:
//!
//!   F(theta1) = R1^2 sin^2(alpha) (u^2 - K1) + yp^2 (R1^2 + r1^2 - 2 R1 r1 cos alpha) = 0,
//!
//! u = xp + D1 - d1, K1 = L1^2 - R1^2 - r1^2 + 2 R1 r1 cos alpha: a trigonometric polynomial of
//! degree 3 in theta1, i.e. the paper's degree-6 polynomial in tan(theta1/2). Its real roots are
//! isolated directly on the circle by [`Trig::roots_sin_cos`] (the forward kinematics' method:
//! complete by construction, no half-angle chart, so theta1 = pi is an ordinary root). Each root
//! is polished by Newton on the unsquared leg-I pair (eqs. (10) and (14) of IFToMM 2007) in
//! (theta1, rho1), its sine and cosine carried along the steps; where sin(alpha) ~ 0 (there F has
//! a double root, one per sign of rho1 - zp, Table II of IFToMM 2007) both signs are tried. rho2
//! and rho3 follow from eqs. (12)-(13), both signs each.

use std::f64::consts::PI;

use arrayvec::ArrayVec;
use nalgebra::{Matrix2, Matrix4, Vector2, Vector3, Vector4};

use crate::branches::{Config, Reason, Verdict, cos_tilt_max, leg_state, listed_in_order};
use crate::certificate::{Certificate, Certified};
use crate::leg1_certify;
use crate::machine::{Machine, TableGeometry};
use crate::module_geometry::{ModulePose, Sliders, residual_mm_sc};
use crate::module_ik::{Leg1, posture_branches, wrap_angle};
use crate::orientation::{
    AxisAngles, AxisError, ToolAngles, ToolOrientation, axis_angles, phi1_at, unit_axis,
};
use crate::tolerance::{
    ACCEPT_RESIDUAL_MM, LIMIT_SLACK, NEWTON_MAX_ITER, NEWTON_STEP_STOP, SAME_SOLUTION_MM,
    SAME_SOLUTION_RAD,
};
use crate::trig::{Trig, sin_cos_after_step};

/// |sin(alpha)| (dimensionless) below which both signs of rho1 - zp are tried at a root of F:
/// there F has a double root or two very close ones and the sign from eq. (14) is unreliable.
/// Trying both signs more often than needed only costs a Newton polish and a duplicate check.
pub const BOTH_SIGNS_SIN_ALPHA: f64 = 1e-4;

/// F at sin(alpha) = 0, relative to its largest coefficient, below which that angle is also
/// polished as a seed (a double root of F there, within rounding, or nearly one). Above it the
/// seed only costs Newton runs that end on roots already found (a quarter of the IK's time).
pub const ALPHA_ZERO_SEED_REL: f64 = 1e-8;

/// Most real (theta1, rho1) pairs: the six roots of the degree-6 polynomial in tan(theta1/2)
/// (a double root at sin(alpha) = 0 is two pairs, one per sign of rho1 - zp).
pub const MAX_THETA1_SOLUTIONS: usize = 6;

/// Most machine inverse-kinematics branches: six (theta1, rho1) pairs, two rho2, two rho3.
pub const MAX_MACHINE_IK_BRANCHES: usize = 4 * MAX_THETA1_SOLUTIONS;

/// Largest number of assembly modes returned by the forward kinematics (that of the module).
pub const MAX_MACHINE_FK_MODES: usize = crate::module_fk::MAX_FK_MODES;

/// Weight (mm per rad) that puts slider travel and table rotation on one scale when choosing the
/// branch nearest the previous row: 1 rad of table rotation counts as 1000 mm of slider travel,
/// about the size of the machine.
pub const JOINT_DISTANCE_MM_PER_RAD: f64 = 1000.0;

/// A tool pose in the workpiece frame R_t: the tool tip (TCP, mm) and the orientation angles
/// (rad) of eq. (8), AIM 2007.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    /// Tool tip U = (X, Y, Z) in R_t (mm).
    pub tip: Vector3<f64>,
    /// Tilt of the tool from the table normal (rad).
    pub phi1: f64,
    /// Azimuth of the tilt plane (rad).
    pub phi2: f64,
}

/// One inverse-kinematics branch of the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineIkBranch {
    /// Slider positions rho1, rho2, rho3 (mm).
    pub rho: Sliders,
    /// Tilting axis (rad, in (-pi, pi]).
    pub theta1: f64,
    /// Rotary axis (rad): -phi2 (eq. (9)), wrapped to (-pi, pi] by [`machine_ik`].
    pub theta2: f64,
    /// Platform rotation alpha = theta1 + phi1 (eq. (14)), in (-pi, pi].
    pub alpha: f64,
    /// Platform point P in the base frame (mm).
    pub platform: Vector3<f64>,
    /// Configuration indices (s1, s2, s3) of the module.
    pub config: Config,
    /// Module verdict plus [`Reason::Theta1Range`].
    pub verdict: Verdict,
}

impl MachineIkBranch {
    /// True when the machine can use this branch (every check passes).
    pub fn working(&self) -> bool {
        self.verdict.feasible()
    }
}

/// Every machine inverse-kinematics branch of one tool pose, with the certificate that says why
/// there are no others.
pub type MachineIkBranches = Certified<MachineIkBranch, MAX_MACHINE_IK_BRANCHES>;

/// How far (rad) the Newton polish may move theta1 from a proved root: the root is accurate to
/// rounding, so a posture farther than this is some other root's.
const ROOT_POLISH_RAD: f64 = 1e-6;

/// One assembly mode of the machine's forward kinematics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineFkMode {
    /// Tool tip and (phi1, phi2) = (alpha - theta1, -theta2), both wrapped to (-pi, pi].
    pub tool: ToolPose,
    /// Tool axis (i, j, k) in R_t, tip towards spindle.
    pub axis: Vector3<f64>,
    /// The module's pose (P in the base frame, alpha).
    pub module: ModulePose,
    /// Configuration indices of the module.
    pub config: Config,
    /// Module verdict plus [`Reason::Theta1Range`].
    pub verdict: Verdict,
}

impl MachineFkMode {
    /// True when the machine can be in this mode (every check passes).
    pub fn working(&self) -> bool {
        self.verdict.feasible()
    }
}

/// Every assembly mode of the machine for one set of joints, with the module's certificate.
pub type MachineFkModes = Certified<MachineFkMode, MAX_MACHINE_FK_MODES>;

fn trans(v: Vector3<f64>) -> Matrix4<f64> {
    Matrix4::new_translation(&v)
}

fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

/// bT_t of eq. (7), AIM 2007: the workpiece frame R_t in the base frame.
pub fn table_transform(table: &TableGeometry, theta1: f64, theta2: f64) -> Matrix4<f64> {
    trans(Vector3::new(0.0, 0.0, table.d_a))
        * rot_x(theta1)
        * trans(Vector3::new(0.0, 0.0, table.d_t))
        * rot_x(PI)
        * rot_z(theta2)
}

/// tT_pl of eq. (8), AIM 2007: the platform frame R_pl in the workpiece frame.
pub fn tool_transform(pose: &ToolPose, tool_length: f64) -> Matrix4<f64> {
    trans(pose.tip)
        * rot_z(pose.phi2)
        * rot_x(PI + pose.phi1)
        * trans(Vector3::new(0.0, 0.0, -tool_length))
}

/// bT_pl of eq. (1), AIM 2007: the platform frame in the base frame.
pub fn platform_transform(pose: &ModulePose) -> Matrix4<f64> {
    trans(pose.p) * rot_x(pose.alpha)
}

/// The tool pose in R_t from the module pose and the table angles: eq. (26), AIM 2007, as
/// printed (phi1 = alpha - theta1, phi2 = -theta2, both wrapped to (-pi, pi]).
pub fn tool_pose_eq26(
    table: &TableGeometry,
    module: &ModulePose,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> ToolPose {
    let (xp, yp, zp) = (module.p.x, module.p.y, module.p.z);
    let (s1, c1) = theta1.sin_cos();
    let (s2, c2) = theta2.sin_cos();
    let d = module.alpha - theta1;
    let v1 = tool_length * d.sin() - c1 * yp - s1 * (zp - table.d_a);
    let v2 = table.d_t - c1 * zp + table.d_a * c1 - tool_length * d.cos();
    ToolPose {
        tip: Vector3::new(c2 * xp + v1 * s2, -s2 * xp + v1 * c2, s1 * yp + v2),
        phi1: wrap_angle(d),
        phi2: wrap_angle(-theta2),
    }
}

/// The platform point in the frame that follows the tilting axis, w = trans(z, d_t) rot(x, pi)
/// rot(z, -phi2) (U + Delta a): constant in theta1 (eqs. (7)-(9), AIM 2007).
fn tilt_frame_platform(table: &TableGeometry, pose: &ToolPose, tool_length: f64) -> Vector3<f64> {
    let (s2, c2) = pose.phi2.sin_cos();
    let (s1, c1) = pose.phi1.sin_cos();
    let u = pose.tip;
    // rot(z, -phi2) U + Delta rot(z, -phi2) a, with rot(z, -phi2) a = (0, -sin phi1, cos phi1).
    let q = Vector3::new(
        c2 * u.x + s2 * u.y,
        -s2 * u.x + c2 * u.y - tool_length * s1,
        u.z + tool_length * c1,
    );
    Vector3::new(q.x, -q.y, table.d_t - q.z)
}

/// P(theta1) = trans(z, d_a) rot(x, theta1) w, and its derivative in theta1, from
/// (s, c) = sin, cos of theta1.
fn platform_at(d_a: f64, w: &Vector3<f64>, s: f64, c: f64) -> (Vector3<f64>, Vector3<f64>) {
    let y = c * w.y - s * w.z;
    let z = s * w.y + c * w.z;
    (Vector3::new(w.x, y, d_a + z), Vector3::new(0.0, -z, y))
}

/// The eliminated equation F(theta1) of the module documentation (eq. (15) along the tool pose),
/// a trigonometric polynomial of degree 3 in theta1 (mm^4). With t = tan(theta1/2),
/// (1 + t^2)^3 F is the paper's degree-6 polynomial.
pub fn theta1_equation(m: &Machine, pose: &ToolPose, tool_length: f64) -> Trig {
    let g = &m.module;
    let w = tilt_frame_platform(&m.table, pose, tool_length);
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = w.x + g.dx1;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    let (sp, cp) = pose.phi1.sin_cos();
    let yp = Trig::linear(0.0, w.y, -w.z);
    let ca = Trig::linear(0.0, cp, -sp);
    let sa = Trig::linear(0.0, sp, cp);
    // u^2 - K1 and R1^2 + r1^2 - 2 R1 r1 cos(alpha).
    let u2_k1 = Trig::linear(u * u - k0, 0.0, 0.0).add(&ca.scale(-2.0 * r * rr));
    let n1 = Trig::linear(r * r + rr * rr, 0.0, 0.0).add(&ca.scale(-2.0 * r * rr));
    // Degrees 1 + 1 + 1 and 1 + 1 + 1 (loops fixed at compile time).
    sa.mul_deg::<1, 1>(&sa)
        .mul_deg::<2, 1>(&u2_k1)
        .scale(r * r)
        .add(&yp.mul_deg::<1, 1>(&yp).mul_deg::<2, 1>(&n1))
}

/// A tilting-axis angle with its sine and cosine (carried along Newton's steps, so that the
/// polish needs no `sin_cos` per step), and the slider-1 position that goes with it.
#[derive(Debug, Clone, Copy)]
struct PathPoint {
    theta1: f64,
    sin: f64,
    cos: f64,
    rho1: f64,
}

/// The leg-I equations along the path: g1 = u^2 + yp^2 + (zp - rho1)^2 - K1 (eq. (10), IFToMM
/// 2007) and g2 = yp (R1 cos a - r1) + R1 sin a (zp - rho1) (eq. (14)), and their Jacobian in
/// (theta1, rho1).
struct Leg1Path<'a> {
    m: &'a Machine,
    w: Vector3<f64>,
    sin_phi1: f64,
    cos_phi1: f64,
}

impl Leg1Path<'_> {
    /// sin and cos of alpha = theta1 + phi1 (eq. (14), AIM 2007) by the angle-sum formulas.
    fn alpha_sin_cos(&self, q: &PathPoint) -> (f64, f64) {
        (
            q.sin * self.cos_phi1 + q.cos * self.sin_phi1,
            q.cos * self.cos_phi1 - q.sin * self.sin_phi1,
        )
    }

    fn eval(&self, q: &PathPoint) -> (Vector2<f64>, Matrix2<f64>) {
        let g = &self.m.module;
        let (r, rr) = (g.r_big1, g.r_small1);
        let (p, dp) = platform_at(self.m.table.d_a, &self.w, q.sin, q.cos);
        let (sa, ca) = self.alpha_sin_cos(q);
        let u = p.x + g.dx1;
        let dz = p.z - q.rho1;
        let k1 = g.l1 * g.l1 - r * r - rr * rr + 2.0 * r * rr * ca;
        let f = Vector2::new(
            u * u + p.y * p.y + dz * dz - k1,
            p.y * (r * ca - rr) + r * sa * dz,
        );
        let j = Matrix2::new(
            2.0 * p.y * dp.y + 2.0 * dz * dp.z + 2.0 * r * rr * sa,
            -2.0 * dz,
            dp.y * (r * ca - rr) - p.y * r * sa + r * ca * dz + r * sa * dp.z,
            -r * sa,
        );
        (f, j)
    }

    /// Newton from `start`: the best iterate (smallest residual), theta1 wrapped to (-pi, pi],
    /// with its residuals (g1, g2).
    fn polish(&self, start: PathPoint) -> (PathPoint, Vector2<f64>) {
        let mut cur = start;
        let (mut f, mut j) = self.eval(&cur);
        let mut best = (cur, f);
        for _ in 0..NEWTON_MAX_ITER {
            let Some(step) = j.try_inverse().map(|inv| inv * f) else {
                break;
            };
            if !step.iter().all(|v| v.is_finite()) {
                break;
            }
            let theta1 = cur.theta1 - step.x;
            let (sin, cos) = sin_cos_after_step(cur.sin, cur.cos, theta1, step.x);
            cur = PathPoint {
                theta1,
                sin,
                cos,
                rho1: cur.rho1 - step.y,
            };
            (f, j) = self.eval(&cur);
            if f.amax() <= best.1.amax() {
                best = (cur, f);
            }
            if step.x.abs() < NEWTON_STEP_STOP
                && step.y.abs() < NEWTON_STEP_STOP * (1.0 + cur.rho1.abs())
            {
                break;
            }
        }
        best.0.theta1 = wrap_angle(best.0.theta1);
        best
    }
}

fn theta1_in_limits(m: &Machine, theta1: f64) -> bool {
    theta1 >= m.limits.theta1_min - LIMIT_SLACK && theta1 <= m.limits.theta1_max + LIMIT_SLACK
}

/// Every real inverse-kinematics branch of the machine for a tool pose in R_t (AIM 2007, section
/// III.C), ordered by theta1 then by (s1, s2, s3). theta2 = -phi2 wrapped to (-pi, pi]. Empty
/// when the pose is unreachable by any real branch (never because of a convergence failure: the
/// theta1 roots come from a certified isolation).
pub fn machine_ik(m: &Machine, pose: &ToolPose, tool_length: f64) -> MachineIkBranches {
    let mut out = MachineIkBranches::new();
    machine_ik_into(m, pose, tool_length, &mut out);
    out
}

/// [`machine_ik`] into an existing list (cleared first), so that a caller that keeps one does
/// not copy it.
pub fn machine_ik_into(
    m: &Machine,
    pose: &ToolPose,
    tool_length: f64,
    out: &mut MachineIkBranches,
) {
    out.reset();
    let mut certificate = Certificate::Double;
    let finite = pose.tip.iter().all(|v| v.is_finite())
        && pose.phi1.is_finite()
        && pose.phi2.is_finite()
        && tool_length.is_finite();
    if !finite {
        return;
    }
    let g = &m.module;
    let (r, rr) = (g.r_big1, g.r_small1);
    let (sin_phi1, cos_phi1) = pose.phi1.sin_cos();
    let path = Leg1Path {
        m,
        w: tilt_frame_platform(&m.table, pose, tool_length),
        sin_phi1,
        cos_phi1,
    };
    let f = theta1_equation(m, pose, tool_length);
    let iso = f.roots_certified(leg1_certify::equation_error(m, &path.w, sin_phi1, cos_phi1));
    // One leg-I posture (theta1, rho1) per proved root of F: F = h+ h- (leg1_certify), a
    // simple root belongs to one factor, whose sign of rho1 - zp is that of eq. (14), IFToMM
    // 2007, or where sin(alpha) is too small to tell, the factor's own.
    let mut proved: ArrayVec<(f64, f64), 12> = ArrayVec::new();
    let mut forms = None;
    for root in &iso.roots {
        let seed = PathPoint {
            theta1: root.x,
            sin: root.sin,
            cos: root.cos,
            rho1: 0.0,
        };
        let (p, _) = platform_at(m.table.d_a, &path.w, root.sin, root.cos);
        let (sa, ca) = path.alpha_sin_cos(&seed);
        let rho1 = if sa.abs() >= BOTH_SIGNS_SIN_ALPHA {
            Some(p.z + p.y * (r * ca - rr) / (r * sa))
        } else {
            let f64_forms = forms.get_or_insert_with(|| {
                leg1_certify::path_forms::<f64>(m, &path.w, sin_phi1, cos_phi1)
            });
            leg1_certify::posture_rho1(f64_forms, root.x)
        };
        match rho1 {
            Some(rho1) => {
                let _ = proved.try_push((root.x, rho1));
            }
            None => certificate = Certificate::Unproved,
        }
    }
    // Other seeds, which the proof does not predict: near the roots' two values where
    // sin(alpha) = 0 when F is small there (its double roots, both signs of rho1 - zp, Table II
    // of IFToMM 2007). A posture they find that no proved root gave makes the result unproved.
    let mut others: ArrayVec<(f64, f64), 12> = ArrayVec::new();
    let mut allowed: ArrayVec<(f64, f64), 12> = ArrayVec::new();
    if !iso.ambiguous.is_empty() {
        let resolution = leg1_certify::resolve(
            m,
            &path.w,
            (sin_phi1, cos_phi1),
            &iso.ambiguous,
            &mut proved,
            &mut allowed,
            &mut others,
        );
        certificate = certificate.max(Certificate::from(resolution));
    }
    let f_scale = f
        .cos
        .iter()
        .chain(&f.sin)
        .fold(0.0f64, |m, a| m.max(a.abs()));
    for th in [-pose.phi1, PI - pose.phi1] {
        let (sin, cos) = th.sin_cos();
        if f.eval_sc(sin, cos) <= ALPHA_ZERO_SEED_REL * f_scale {
            let (p, _) = platform_at(m.table.d_a, &path.w, sin, cos);
            let (sa, ca) = path.alpha_sin_cos(&PathPoint {
                theta1: th,
                sin,
                cos,
                rho1: 0.0,
            });
            let u = p.x + g.dx1;
            let k1 = g.l1 * g.l1 - r * r - rr * rr + 2.0 * r * rr * ca;
            let h = (k1 - u * u - p.y * p.y).max(0.0).sqrt();
            let _ = sa;
            for rho1 in [p.z + h, p.z - h] {
                let _ = others.try_push((th, rho1));
            }
        }
    }
    let n_proved = proved.len();
    let n_expected = n_proved + allowed.len();
    let mut pairs: ArrayVec<PathPoint, MAX_THETA1_SOLUTIONS> = ArrayVec::new();
    for (k, &(theta1, rho1)) in proved.iter().chain(&allowed).chain(&others).enumerate() {
        let (sin, cos) = theta1.sin_cos();
        let (q, fv) = path.polish(PathPoint {
            theta1,
            sin,
            cos,
            rho1,
        });
        // Residuals of (10) and (14) as lengths along the rod (mm).
        let res = (fv.x / (2.0 * g.l1)).abs().max((fv.y / r).abs());
        if res.is_nan() || res > ACCEPT_RESIDUAL_MM {
            if k < n_proved {
                certificate = Certificate::Unproved;
            }
            continue;
        }
        if k < n_proved && wrap_angle(q.theta1 - theta1).abs() > ROOT_POLISH_RAD {
            certificate = Certificate::Unproved;
        }
        let dup = pairs.iter().any(|o| {
            wrap_angle(o.theta1 - q.theta1).abs() < SAME_SOLUTION_RAD
                && (o.rho1 - q.rho1).abs() < SAME_SOLUTION_MM * (1.0 + q.rho1.abs())
        });
        if dup {
            continue;
        }
        if k >= n_expected || pairs.is_full() {
            certificate = Certificate::Unproved;
            if pairs.is_full() {
                continue;
            }
        }
        pairs.push(q);
    }
    let theta2 = wrap_angle(-pose.phi2);
    let cos_tilt = cos_tilt_max(m);
    for q in &pairs {
        let (p, _) = platform_at(m.table.d_a, &path.w, q.sin, q.cos);
        let (sin, cos) = path.alpha_sin_cos(q);
        let leg1 = Leg1 {
            alpha: wrap_angle(q.theta1 + pose.phi1),
            rho1: q.rho1,
            sin,
            cos,
        };
        // The module's four branches on this posture: legs II and III by eqs. (12)-(13).
        let l1 = leg_state(m, 0, &p, sin, cos, q.rho1, cos_tilt).check();
        let Some(four) = posture_branches(m, &p, &leg1, l1, cos_tilt) else {
            continue;
        };
        let mut table = Verdict::default();
        if !theta1_in_limits(m, q.theta1) {
            table.add(Reason::Theta1Range);
        }
        let module = ModulePose {
            p,
            alpha: leg1.alpha,
        };
        for b in four {
            if residual_mm_sc(g, &module, &b.rho, sin, cos) > ACCEPT_RESIDUAL_MM {
                continue;
            }
            if !out.is_full() {
                out.push(MachineIkBranch {
                    rho: b.rho,
                    theta1: q.theta1,
                    theta2,
                    alpha: leg1.alpha,
                    platform: p,
                    config: b.config,
                    verdict: b.verdict.with(table),
                });
            }
        }
    }
    out.certificate = certificate;
    out.mark_unproved(|b| &mut b.verdict);
    // Usually in order already (roots by increasing theta1, a posture's four branches by
    // (s2, s3)): sorted only when that check fails.
    let in_order = out
        .windows(2)
        .all(|w| listed_in_order((w[0].theta1, w[0].config), (w[1].theta1, w[1].config)));
    if !in_order {
        out.sort_by(|a, b| a.theta1.total_cmp(&b.theta1).then(a.config.cmp(&b.config)));
    }
}

/// Every assembly mode of the machine for the joints (AIM 2007, section III.D): the module's
/// forward kinematics, then eq. (26) for the tool pose in R_t. Ordered as the module's modes.
pub fn machine_fk(
    m: &Machine,
    rho: &Sliders,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> MachineFkModes {
    let mut out = MachineFkModes::new();
    if !(theta1.is_finite() && theta2.is_finite() && tool_length.is_finite()) {
        return out;
    }
    let modes = crate::module_fk::solve(m, rho);
    out.certificate = modes.certificate;
    for mode in modes {
        let tool = tool_pose_eq26(&m.table, &mode.pose, theta1, theta2, tool_length);
        let mut verdict = mode.verdict;
        if !theta1_in_limits(m, theta1) {
            verdict.add(Reason::Theta1Range);
        }
        out.push(MachineFkMode {
            tool,
            axis: crate::orientation::tool_axis(tool.phi1, tool.phi2),
            module: mode.pose,
            config: mode.config,
            verdict,
        });
    }
    out
}

/// The first-row choice of [`PathState`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FirstRowChoice {
    /// The working branch with the smallest |theta1| over both orientation solutions.
    #[default]
    SmallestTheta1,
    /// Orientation solution 1, (phi1 >= 0, phi2) (see `orientation::AxisAngles`), if it has a
    /// working branch; otherwise the other one, and the row is flagged `switched`.
    Orientation1,
    /// Orientation solution 2, (-phi1, phi2 + pi); same fallback.
    Orientation2,
}

/// The branch chosen for one row of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathRow {
    /// Slider positions (mm).
    pub rho: Sliders,
    /// Tilting axis (rad).
    pub theta1: f64,
    /// Rotary axis (rad), unwrapped: the turn nearest the previous row's theta2.
    pub theta2: f64,
    /// The orientation angles used (rad): phi2 = -theta2 up to whole turns.
    pub angles: ToolAngles,
    /// Which orientation solution: 1 = (phi1 >= 0, phi2), 2 = (-phi1, phi2 + pi); 1 for angle
    /// input and inside the rotary-singularity cone.
    pub orientation: u8,
    /// Platform rotation alpha (rad) and point P (mm, base frame).
    pub module: ModulePose,
    /// True when the continuation of the previous row's branch left the limits and another
    /// working branch was taken (or, on the first row, when the preferred orientation had none).
    pub switched: bool,
    /// True when the tool axis lies inside the rotary-singularity cone
    /// (`orientation::ROTARY_SINGULAR_CONE_RAD`); for axis input theta2 was then kept from the
    /// previous row (0 on the first row) and phi1 fitted to it.
    pub near_rotary_singularity: bool,
    /// Number of real branches over the orientation solutions considered.
    pub real_branches: usize,
}

/// Why a row of a path has no branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathError {
    /// The tool axis vector is invalid.
    Axis(AxisError),
    /// No working branch. `nearest` is the branch of the machine's kind (configuration
    /// (-1, -1, -1), rods not crossing) nearest the previous row, or with the smallest |theta1|,
    /// whose verdict says which limits fail; None when no such branch is real.
    NoWorkingBranch {
        /// Number of real branches.
        real_branches: usize,
        /// False when the solver could not prove the branches complete (status `uncertified`).
        proved: bool,
        /// See above.
        nearest: Option<MachineIkBranch>,
    },
}

impl std::fmt::Display for PathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PathError::Axis(e) => e.fmt(f),
            PathError::NoWorkingBranch {
                real_branches,
                proved,
                nearest,
            } => {
                write!(f, "no working branch ({real_branches} real branches")?;
                if !proved {
                    f.write_str(", not proved complete")?;
                }
                if let Some(b) = nearest {
                    write!(
                        f,
                        "; nearest: theta1 = {:.6} deg, rho = ({:.4}, {:.4}, {:.4}) mm, fails {}",
                        b.theta1.to_degrees(),
                        b.rho.x,
                        b.rho.y,
                        b.rho.z,
                        b.verdict
                    )?;
                }
                f.write_str(")")
            }
        }
    }
}

impl std::error::Error for PathError {}

/// Row-by-row branch choice along a tool path (pure: no I/O). Keeps the previous row's joints.
#[derive(Debug, Clone, Default)]
pub struct PathState {
    first: FirstRowChoice,
    prev: Option<PathRow>,
}

/// A candidate branch with the orientation it came from and its theta2.
#[derive(Clone, Copy)]
struct Candidate {
    branch: MachineIkBranch,
    angles: ToolAngles,
    orientation: u8,
    theta2: f64,
}

/// theta2 + 2 k pi nearest `reference`.
fn unwrap_near(theta2: f64, reference: f64) -> f64 {
    reference + wrap_angle(theta2 - reference)
}

/// Every branch of one path row over the orientation solutions, before the choice that
/// depends on the previous row (so rows can be solved in parallel and chosen in order).
#[derive(Clone, Default)]
pub struct PathCandidates {
    options: ArrayVec<(ToolAngles, u8), 2>,
    all: ArrayVec<Candidate, { 2 * MAX_MACHINE_IK_BRANCHES }>,
    near_singular: bool,
    needs_previous: bool,
    /// The weakest certificate of the orientation solutions' branch lists.
    pub certificate: Certificate,
}

impl PathCandidates {
    /// True for an axis inside the rotary-singularity cone: the candidates were computed with
    /// theta2 = 0 and must be recomputed with the previous row's theta2.
    pub fn needs_previous(&self) -> bool {
        self.needs_previous
    }

    /// Every branch with its orientation solution (1 or 2) and theta2 (rad, in (-pi, pi]).
    pub fn iter(&self) -> impl Iterator<Item = (MachineIkBranch, u8, f64)> + '_ {
        self.all.iter().map(|c| (c.branch, c.orientation, c.theta2))
    }

    /// Number of real branches.
    pub fn len(&self) -> usize {
        self.all.len()
    }

    pub fn is_empty(&self) -> bool {
        self.all.is_empty()
    }
}

/// The candidates of one row: both orientation solutions of an axis (or the given angles), every
/// machine IK branch of each, theta2 = -phi2 wrapped to (-pi, pi]. Inside the rotary cone, phi2 is
/// taken from `prev_theta2` (0 when None) and phi1 fitted to it.
pub fn path_candidates(
    m: &Machine,
    tip: &Vector3<f64>,
    orientation: &ToolOrientation,
    tool_length: f64,
    prev_theta2: Option<f64>,
) -> Result<PathCandidates, PathError> {
    let mut out = PathCandidates::default();
    path_candidates_into(m, tip, orientation, tool_length, prev_theta2, &mut out)?;
    Ok(out)
}

/// [`path_candidates`] into an existing set (cleared first), so that a caller that keeps one (a
/// batch's row) does not copy it; on error the set is left empty.
pub fn path_candidates_into(
    m: &Machine,
    tip: &Vector3<f64>,
    orientation: &ToolOrientation,
    tool_length: f64,
    prev_theta2: Option<f64>,
    out: &mut PathCandidates,
) -> Result<(), PathError> {
    out.options.clear();
    out.all.clear();
    out.near_singular = false;
    out.needs_previous = false;
    out.certificate = Certificate::Double;
    match orientation {
        ToolOrientation::Angles(a) => {
            out.near_singular = a.phi1.sin().abs() < crate::orientation::ROTARY_SINGULAR_CONE_RAD;
            out.options.push((*a, 1));
        }
        ToolOrientation::Axis(v) => match axis_angles(v).map_err(PathError::Axis)? {
            AxisAngles::Regular(sols) => {
                out.options.push((sols[0], 1));
                out.options.push((sols[1], 2));
            }
            AxisAngles::NearRotary { .. } => {
                let a = unit_axis(v).map_err(PathError::Axis)?;
                out.near_singular = true;
                out.needs_previous = true;
                let phi2 = -prev_theta2.unwrap_or(0.0);
                out.options.push((
                    ToolAngles {
                        phi1: phi1_at(&a, phi2),
                        phi2,
                    },
                    1,
                ));
            }
        },
    }
    let mut branches = MachineIkBranches::new();
    for &(angles, label) in &out.options {
        let pose = ToolPose {
            tip: *tip,
            phi1: angles.phi1,
            phi2: angles.phi2,
        };
        machine_ik_into(m, &pose, tool_length, &mut branches);
        out.certificate = out.certificate.max(branches.certificate);
        for &branch in &branches {
            out.all.push(Candidate {
                branch,
                angles,
                orientation: label,
                theta2: wrap_angle(-angles.phi2),
            });
        }
    }
    Ok(())
}

impl PathState {
    /// A new path; `first` says how to choose on the first row.
    pub fn new(first: FirstRowChoice) -> PathState {
        PathState { first, prev: None }
    }

    /// The last row chosen, if any.
    pub fn previous(&self) -> Option<&PathRow> {
        self.prev.as_ref()
    }

    /// Chooses the branch for the next row. On error the state is unchanged, so the next row
    /// continues from the last successful one.
    pub fn next_row(
        &mut self,
        m: &Machine,
        tip: &Vector3<f64>,
        orientation: &ToolOrientation,
        tool_length: f64,
    ) -> Result<PathRow, PathError> {
        let prev_theta2 = self.prev.map(|p| p.theta2);
        let candidates = path_candidates(m, tip, orientation, tool_length, prev_theta2)?;
        self.choose(&candidates)
    }

    /// Chooses among the candidates of one row (from [`path_candidates`], computed with this
    /// state's previous theta2 when [`PathCandidates::needs_previous`] says so).
    pub fn choose(&mut self, candidates: &PathCandidates) -> Result<PathRow, PathError> {
        let options = &candidates.options;
        let near_singular = candidates.near_singular;
        // theta2 unwrapped next to the previous row's, once per orientation solution (every
        // branch of one has the same theta2; an `fmod` once the rotary axis has turned more than
        // once); the candidates are read with it, not copied.
        let unwrapped: ArrayVec<(u8, f64), 2> = options
            .iter()
            .map(|&(angles, label)| {
                let t = wrap_angle(-angles.phi2);
                (label, self.prev.map_or(t, |p| unwrap_near(t, p.theta2)))
            })
            .collect();
        let theta2 = |c: &Candidate| {
            unwrapped
                .iter()
                .find(|(label, _)| *label == c.orientation)
                .map_or(c.theta2, |&(_, t)| t)
        };
        let with_unwrapped = |c: &Candidate| Candidate {
            theta2: theta2(c),
            ..*c
        };
        let all = &candidates.all;
        let machine_kind = |c: &&Candidate| c.branch.working() || c.branch.verdict.only_limits();
        let (chosen, switched) = match self.prev {
            Some(prev) => {
                let dist = |c: &Candidate| {
                    (c.branch.rho - prev.rho).amax() / JOINT_DISTANCE_MM_PER_RAD
                        + (c.branch.theta1 - prev.theta1).abs()
                        + (theta2(c) - prev.theta2).abs()
                };
                let nearest = |ok: &dyn Fn(&Candidate) -> bool| {
                    all.iter()
                        .filter(|c| ok(c))
                        .min_by(|a, b| dist(a).total_cmp(&dist(b)))
                        .map(with_unwrapped)
                };
                let continuation = nearest(&|c| machine_kind(&c));
                match continuation {
                    Some(c) if c.branch.working() => (c, false),
                    cont => match nearest(&|c| c.branch.working()) {
                        Some(c) => (c, true),
                        None => {
                            return Err(PathError::NoWorkingBranch {
                                real_branches: all.len(),
                                proved: candidates.certificate.proved(),
                                nearest: cont.map(|c| c.branch),
                            });
                        }
                    },
                }
            }
            None => {
                let smallest = |ok: &dyn Fn(&Candidate) -> bool| {
                    all.iter()
                        .filter(|c| ok(c))
                        .min_by(|a, b| a.branch.theta1.abs().total_cmp(&b.branch.theta1.abs()))
                        .map(with_unwrapped)
                };
                let wanted = match self.first {
                    FirstRowChoice::SmallestTheta1 => None,
                    FirstRowChoice::Orientation1 => Some(1),
                    FirstRowChoice::Orientation2 => Some(2),
                };
                let preferred = match wanted {
                    Some(o) if options.len() == 2 => {
                        smallest(&|c| c.branch.working() && c.orientation == o)
                    }
                    _ => smallest(&|c| c.branch.working()),
                };
                match preferred {
                    Some(c) => (c, false),
                    None => match smallest(&|c| c.branch.working()) {
                        Some(c) => (c, true),
                        None => {
                            return Err(PathError::NoWorkingBranch {
                                real_branches: all.len(),
                                proved: candidates.certificate.proved(),
                                nearest: smallest(&|c| machine_kind(&c)).map(|c| c.branch),
                            });
                        }
                    },
                }
            }
        };
        let row = PathRow {
            rho: chosen.branch.rho,
            theta1: chosen.branch.theta1,
            theta2: chosen.theta2,
            angles: chosen.angles,
            orientation: chosen.orientation,
            module: ModulePose {
                p: chosen.branch.platform,
                alpha: chosen.branch.alpha,
            },
            switched,
            near_rotary_singularity: near_singular,
            real_branches: all.len(),
        };
        self.prev = Some(row);
        Ok(row)
    }
}

/// The tool tip in R_t of a platform pose and table angles, by the transforms (eq. (25), AIM
/// 2007): tU = bT_t^-1 bT_pl (0, 0, Delta, 1). Used to check eq. (26).
pub fn tool_tip_by_transforms(
    table: &TableGeometry,
    module: &ModulePose,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> Vector3<f64> {
    let t = table_transform(table, theta1, theta2);
    let inv = t.try_inverse().unwrap_or_else(Matrix4::zeros);
    let u = inv * platform_transform(module) * Vector4::new(0.0, 0.0, tool_length, 1.0);
    Vector3::new(u.x, u.y, u.z)
}
