//! Inverse kinematics of the whole machine (AIM 2007, section III.C): from a tool pose in the
//! workpiece frame R_t to every real (rho1, rho2, rho3, theta1, theta2).
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
use nalgebra::{Matrix2, Vector2, Vector3};

use super::{ToolPose, theta1_in_limits};
use crate::certificate::{Certificate, Certified};
use crate::math::trig::{Trig, sin_cos_after_step};
use crate::parallel_module::branches::{
    Config, Reason, Verdict, cos_tilt_max, leg_state, listed_in_order,
};
use crate::parallel_module::equations::{ModulePose, Sliders, residual_mm_sc};
use crate::parallel_module::ik::{Leg1, posture_branches, wrap_angle};
use crate::parallel_module::leg1_certify;
use crate::spec::{Machine, TableGeometry};
use crate::tolerance::{
    ACCEPT_RESIDUAL_MM, NEWTON_MAX_ITER, NEWTON_STEP_STOP, SAME_SOLUTION_MM, SAME_SOLUTION_RAD,
};

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

#[cfg(test)]
mod tests {
    use super::*;

    /// The leg-I path of a tool pose on the default machine.
    fn path(m: &Machine, phi1: f64, phi2: f64) -> Leg1Path<'_> {
        let pose = ToolPose {
            tip: Vector3::new(20.0, -35.0, 40.0),
            phi1,
            phi2,
        };
        let (sin_phi1, cos_phi1) = phi1.sin_cos();
        Leg1Path {
            m,
            w: tilt_frame_platform(&m.table, &pose, m.tool_length),
            sin_phi1,
            cos_phi1,
        }
    }

    fn point(theta1: f64, rho1: f64) -> PathPoint {
        let (sin, cos) = theta1.sin_cos();
        PathPoint {
            theta1,
            sin,
            cos,
            rho1,
        }
    }

    /// The Jacobian of (g1, g2) in (theta1, rho1) that Newton's polish uses is the derivative
    /// of the equations: central differences agree to 1e-6 of the largest entry, at poses on
    /// and off the solutions.
    #[test]
    fn the_leg1_jacobian_is_the_derivative_of_its_equations() {
        let m = Machine::default_verne();
        for (phi1, phi2) in [(0.3, 0.2), (-0.7, 2.5), (1e-3, -1.0)] {
            let p = path(&m, phi1, phi2);
            for (theta1, rho1) in [(0.1, 300.0), (-0.6, 650.0), (2.8, -100.0)] {
                let (_, j) = p.eval(&point(theta1, rho1));
                let (h_t, h_r) = (1e-6, 1e-3);
                let d_theta1 = (p.eval(&point(theta1 + h_t, rho1)).0
                    - p.eval(&point(theta1 - h_t, rho1)).0)
                    / (2.0 * h_t);
                let d_rho1 = (p.eval(&point(theta1, rho1 + h_r)).0
                    - p.eval(&point(theta1, rho1 - h_r)).0)
                    / (2.0 * h_r);
                let numeric = Matrix2::from_columns(&[d_theta1, d_rho1]);
                let scale = j.amax();
                assert!(
                    (j - numeric).amax() <= 1e-6 * scale,
                    "phi1 {phi1}, theta1 {theta1}: {j} vs {numeric}"
                );
            }
        }
    }

    /// A tool pose with a value that is not finite has no branch, whichever value it is.
    #[test]
    fn a_pose_that_is_not_finite_has_no_branch() {
        let m = Machine::default_verne();
        let good = ToolPose {
            tip: Vector3::new(20.0, -35.0, 40.0),
            phi1: 0.3,
            phi2: 0.2,
        };
        assert!(!machine_ik(&m, &good, m.tool_length).is_empty());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in 0..6 {
                let mut pose = good;
                let mut tool_length = m.tool_length;
                match k {
                    0..=2 => pose.tip[k] = bad,
                    3 => pose.phi1 = bad,
                    4 => pose.phi2 = bad,
                    _ => tool_length = bad,
                }
                let out = machine_ik(&m, &pose, tool_length);
                assert!(out.is_empty(), "{bad} at {k}: {out:?}");
            }
        }
    }

    /// Table II's double root (IFToMM 2007): a platform point with yp = 0 and alpha = 0 has
    /// two leg-I postures, rho1 = zp +- h, at one theta1, where F has a double root. The
    /// machine's inverse kinematics of the tool pose built on it has both, each once (a
    /// posture found from two seeds is merged, two postures are not).
    #[test]
    fn both_postures_of_table_ii_s_double_root_are_found_once() {
        let m = Machine::default_verne();
        let g = &m.module;
        for (x, z, theta1, theta2) in [(30.0, 700.0, 0.2, 0.5), (-60.0, 820.0, -0.4, -2.0)] {
            let module = ModulePose {
                p: Vector3::new(x, 0.0, z),
                alpha: 0.0,
            };
            let tool =
                crate::machine::tool_pose_eq26(&m.table, &module, theta1, theta2, m.tool_length);
            let u = x + g.dx1;
            let h = (g.l1 * g.l1 - (g.r_big1 - g.r_small1).powi(2) - u * u).sqrt();
            let ik = machine_ik(&m, &tool, m.tool_length);
            assert!(ik.certificate.proved(), "{:?}", ik.certificate);
            let at: Vec<&MachineIkBranch> = ik
                .iter()
                .filter(|b| wrap_angle(b.theta1 - theta1).abs() < 1e-9)
                .collect();
            for rho1 in [z + h, z - h] {
                assert!(
                    at.iter().any(|b| (b.rho.x - rho1).abs() < 1e-6),
                    "rho1 = {rho1} missing: {at:?}"
                );
            }
            for (k, a) in at.iter().enumerate() {
                for b in &at[k + 1..] {
                    assert!((a.rho - b.rho).amax() > 1e-6, "twice: {a:?}");
                }
            }
        }
    }
}
