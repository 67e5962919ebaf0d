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
use crate::parallel_module::ik::{Leg1, distinct_branches, posture_branches, wrap_angle};
use crate::parallel_module::leg1_certify;
use crate::parallel_module::reach::ReachBox;
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

/// The platform point in the frame that follows the tilting axis, w = trans(y, y_t) trans(z, d_t)
/// rot(x, pi) rot(z, -phi2) (U + Delta a): constant in theta1 (eqs. (7)-(9), AIM 2007; y_t = 0
/// in the paper).
pub(crate) fn tilt_frame_platform(
    table: &TableGeometry,
    pose: &ToolPose,
    tool_length: f64,
) -> Vector3<f64> {
    tilt_frame_platform_sc(table, pose, pose.phi1.sin_cos(), tool_length)
}

/// [`tilt_frame_platform`] with (sin, cos) of phi1 given.
pub(super) fn tilt_frame_platform_sc(
    table: &TableGeometry,
    pose: &ToolPose,
    (s1, c1): (f64, f64),
    tool_length: f64,
) -> Vector3<f64> {
    let (s2, c2) = pose.phi2.sin_cos();
    let u = pose.tip;
    // rot(z, -phi2) U + Delta rot(z, -phi2) a, with rot(z, -phi2) a = (0, -sin phi1, cos phi1).
    let q = Vector3::new(
        c2 * u.x + s2 * u.y,
        -s2 * u.x + c2 * u.y - tool_length * s1,
        u.z + tool_length * c1,
    );
    Vector3::new(q.x, table.y_t - q.y, table.d_t - q.z)
}

/// P(theta1) = trans(z, d_a) rot(x, theta1) w, and its derivative in theta1, from
/// (s, c) = sin, cos of theta1.
pub(super) fn platform_at(
    d_a: f64,
    w: &Vector3<f64>,
    s: f64,
    c: f64,
) -> (Vector3<f64>, Vector3<f64>) {
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
pub(super) struct PathPoint {
    pub(super) theta1: f64,
    pub(super) sin: f64,
    pub(super) cos: f64,
    pub(super) rho1: f64,
}

/// The leg-I equations along the path: g1 = u^2 + yp^2 + (zp - rho1)^2 - K1 (eq. (10), IFToMM
/// 2007) and g2 = yp (R1 cos a - r1) + R1 sin a (zp - rho1) (eq. (14)), and their Jacobian in
/// (theta1, rho1).
pub(super) struct Leg1Path<'a> {
    pub(super) m: &'a Machine,
    pub(super) w: Vector3<f64>,
    pub(super) sin_phi1: f64,
    pub(super) cos_phi1: f64,
}

impl Leg1Path<'_> {
    /// sin and cos of alpha = theta1 + phi1 (eq. (14), AIM 2007) by the angle-sum formulas.
    pub(super) fn alpha_sin_cos(&self, q: &PathPoint) -> (f64, f64) {
        (
            q.sin * self.cos_phi1 + q.cos * self.sin_phi1,
            q.cos * self.cos_phi1 - q.sin * self.sin_phi1,
        )
    }

    pub(super) fn eval(&self, q: &PathPoint) -> (Vector2<f64>, Matrix2<f64>) {
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
    pub(super) fn polish(&self, start: PathPoint) -> (PathPoint, Vector2<f64>) {
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
            cur = cur.stepped(&step);
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

impl PathPoint {
    /// The point minus `step` (theta1, rho1), its sine and cosine carried along.
    #[inline(always)]
    pub(super) fn stepped(&self, step: &Vector2<f64>) -> PathPoint {
        let theta1 = self.theta1 - step.x;
        let (sin, cos) = sin_cos_after_step(self.sin, self.cos, theta1, step.x);
        PathPoint {
            theta1,
            sin,
            cos,
            rho1: self.rho1 - step.y,
        }
    }
}

/// Seeds (theta1, rho1) at the two angles where sin(alpha) = 0, theta1 = -phi1 and pi - phi1,
/// when F is small there: both signs of rho1 - zp, rho1 = zp +- h from eq. (10) of IFToMM 2007
/// (at a double root of F, Table II, the two postures themselves). A safety net behind the
/// certified isolation, which predicts none of them.
fn alpha_zero_seeds(
    m: &Machine,
    pose: &ToolPose,
    path: &Leg1Path,
    f: &Trig,
) -> ArrayVec<(f64, f64), 4> {
    let g = &m.module;
    let (r, rr) = (g.r_big1, g.r_small1);
    let f_scale = f
        .cos
        .iter()
        .chain(&f.sin)
        .fold(0.0f64, |m, a| m.max(a.abs()));
    let mut seeds = ArrayVec::new();
    for th in [-pose.phi1, PI - pose.phi1] {
        let (sin, cos) = th.sin_cos();
        if f.eval_sc(sin, cos) <= ALPHA_ZERO_SEED_REL * f_scale {
            let (p, _) = platform_at(m.table.d_a, &path.w, sin, cos);
            let (_, ca) = path.alpha_sin_cos(&PathPoint {
                theta1: th,
                sin,
                cos,
                rho1: 0.0,
            });
            let u = p.x + g.dx1;
            let k1 = g.l1 * g.l1 - r * r - rr * rr + 2.0 * r * rr * ca;
            let h = (k1 - u * u - p.y * p.y).max(0.0).sqrt();
            seeds.push((th, p.z + h));
            seeds.push((th, p.z - h));
        }
    }
    seeds
}

/// A posture already found is `q` again: theta1 within [`SAME_SOLUTION_RAD`] (either side of
/// pi) and rho1 within [`SAME_SOLUTION_MM`] (1 + L1 + |rho1|), |rho1| `q`'s. Scaled by the
/// machine's size (L1), not only by |rho1|, which depends on where the slider's zero is: where
/// leg I is stretched (a fold of eq. (10)), Newton stops a few 1e-6 mm from the posture, which
/// the rounding fixes only to sqrt(eps) L1.
#[inline]
fn same_posture(l1: f64, found: &PathPoint, q: &PathPoint) -> bool {
    wrap_angle(found.theta1 - q.theta1).abs() < SAME_SOLUTION_RAD
        && (found.rho1 - q.rho1).abs() < SAME_SOLUTION_MM * (1.0 + l1 + q.rho1.abs())
}

/// The leg-I postures polished by Newton from three lists of seeds (theta1, rho1), duplicates
/// merged: `proved`, one per proved root of F, each of which must polish to a posture within
/// [`ROOT_POLISH_RAD`] of its theta1; `allowed`, postures an ambiguous interval's resolution
/// allows, which may fail; `others`, seeds no proof predicts. The certificate becomes
/// [`Certificate::Unproved`] when a proved seed fails or drifts, when a posture comes from
/// `others` alone, or when there are more postures than F has roots.
fn polish_postures(
    path: &Leg1Path,
    proved: &[(f64, f64)],
    allowed: &[(f64, f64)],
    others: &[(f64, f64)],
    certificate: &mut Certificate,
) -> ArrayVec<PathPoint, MAX_THETA1_SOLUTIONS> {
    let g = &path.m.module;
    let n_proved = proved.len();
    let n_expected = n_proved + allowed.len();
    let mut pairs: ArrayVec<PathPoint, MAX_THETA1_SOLUTIONS> = ArrayVec::new();
    for (k, &(theta1, rho1)) in proved.iter().chain(allowed).chain(others).enumerate() {
        let (sin, cos) = theta1.sin_cos();
        let (q, fv) = path.polish(PathPoint {
            theta1,
            sin,
            cos,
            rho1,
        });
        // Residuals of (10) and (14) as lengths along the rod (mm).
        let res = (fv.x / (2.0 * g.l1)).abs().max((fv.y / g.r_big1).abs());
        if res.is_nan() || res > ACCEPT_RESIDUAL_MM {
            if k < n_proved {
                *certificate = Certificate::Unproved;
            }
            continue;
        }
        if k < n_proved && wrap_angle(q.theta1 - theta1).abs() > ROOT_POLISH_RAD {
            *certificate = Certificate::Unproved;
        }
        if pairs.iter().any(|o| same_posture(g.l1, o, &q)) {
            continue;
        }
        if k >= n_expected || pairs.is_full() {
            *certificate = Certificate::Unproved;
            if pairs.is_full() {
                continue;
            }
        }
        pairs.push(q);
    }
    pairs
}

/// The machine's branches on one leg-I posture `q` of the tool pose (phi1, theta2 = -phi2
/// wrapped): legs II and III by eqs. (12)-(13), both signs each, labelled with the table's
/// verdict, passed to `each` in order (s2, s3 = -1 before +1) when their configuration is
/// `wanted` and their residual of eqs. (3)-(6) is within [`ACCEPT_RESIDUAL_MM`]. What
/// [`machine_ik`] does for each posture, and the continuation for its one posture
/// (`machine::continuation`): the same operations, so the same branch bit for bit.
#[inline(always)]
pub(super) fn posture_branches_each(
    path: &Leg1Path,
    q: &PathPoint,
    phi1: f64,
    theta2: f64,
    cos_tilt: f64,
    wanted: impl Fn(Config) -> bool,
    mut each: impl FnMut(MachineIkBranch),
) {
    let m = path.m;
    let (p, _) = platform_at(m.table.d_a, &path.w, q.sin, q.cos);
    let (sin, cos) = path.alpha_sin_cos(q);
    let leg1 = Leg1 {
        alpha: wrap_angle(q.theta1 + phi1),
        rho1: q.rho1,
        sin,
        cos,
    };
    let l1 = leg_state(m, 0, &p, sin, cos, q.rho1, cos_tilt).check();
    let Some(four) = posture_branches(m, &p, &leg1, l1, cos_tilt) else {
        return;
    };
    let mut table = Verdict::default();
    if !theta1_in_limits(m, q.theta1) {
        table.add(Reason::Theta1Range);
    }
    let module = ModulePose {
        p,
        alpha: leg1.alpha,
    };
    let (four, n) = distinct_branches(four);
    for b in &four[..n] {
        if !wanted(b.config)
            || residual_mm_sc(&m.module, &module, &b.rho, sin, cos) > ACCEPT_RESIDUAL_MM
        {
            continue;
        }
        each(MachineIkBranch {
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

/// A branch of [`Machine::model`] as `m`'s joints read it: the sliders less their zero offsets,
/// the table's angles less theirs (wrapped to (-pi, pi]); the one place the machine's inverse
/// kinematics leaves the equations' variables.
pub(crate) fn joints_of_branch(m: &Machine, b: &MachineIkBranch) -> MachineIkBranch {
    let [z1, z2] = m.table.theta_zero;
    MachineIkBranch {
        rho: m.joint_sliders(&b.rho),
        theta1: wrap_angle(b.theta1 - z1),
        theta2: wrap_angle(b.theta2 - z2),
        ..*b
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
    if m.has_zeros() {
        // Solved on the equations' variables, then given as the joints read them.
        machine_ik_into(&m.model(), pose, tool_length, out);
        for b in out.iter_mut() {
            *b = joints_of_branch(m, b);
        }
        if !out
            .windows(2)
            .all(|w| listed_in_order((w[0].theta1, w[0].config), (w[1].theta1, w[1].config)))
        {
            out.sort_by(|a, b| a.theta1.total_cmp(&b.theta1).then(a.config.cmp(&b.config)));
        }
        return;
    }
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
    let w = tilt_frame_platform_sc(&m.table, pose, (sin_phi1, cos_phi1), tool_length);
    // Every platform point of the pose beyond the rods' reach from the strokes: no branch
    // within them, proved before F's coefficients lose their digits to the pose's size.
    if ReachBox::of(m).circle_beyond(w.x, m.table.d_a, w.y, w.z) {
        return;
    }
    let path = Leg1Path {
        m,
        w,
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
    // Intervals the isolation left ambiguous (two roots closer than F's rounding): proved
    // postures, postures allowed, and best-effort ones where nothing could be proved. Then the
    // seeds the proof does not predict, at sin(alpha) = 0; a posture only they find makes the
    // result unproved.
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
    for seed in alpha_zero_seeds(m, pose, &path, &f) {
        let _ = others.try_push(seed);
    }
    let pairs = polish_postures(&path, &proved, &allowed, &others, &mut certificate);
    let theta2 = wrap_angle(-pose.phi2);
    let cos_tilt = cos_tilt_max(m);
    for q in &pairs {
        posture_branches_each(
            &path,
            q,
            pose.phi1,
            theta2,
            cos_tilt,
            |_| true,
            |b| {
                if !out.is_full() {
                    out.push(b);
                }
            },
        );
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

    /// [`same_posture`] merges a posture within [`SAME_SOLUTION_MM`] (1 + L1 + |rho1|) in rho1
    /// and [`SAME_SOLUTION_RAD`] in theta1, also across pi, and no further: each checked at 0.99
    /// and 1.01 of its tolerance, either side, with rho1 at -1e4, 0 and 250 mm and L1 at 1 and
    /// 1e3 mm.
    #[test]
    fn same_posture_is_within_both_tolerances() {
        use std::f64::consts::PI;
        for l1 in [1.0, 1e3] {
            for rho1 in [-1e4, 0.0, 250.0] {
                for theta1 in [0.3, PI - 0.4 * SAME_SOLUTION_RAD] {
                    let q = point(theta1, rho1);
                    let tol = SAME_SOLUTION_MM * (1.0 + l1 + rho1.abs());
                    for (f, same) in [(0.99, true), (1.01, false)] {
                        for sign in [1.0, -1.0] {
                            let moved = point(theta1, rho1 + sign * f * tol);
                            assert_eq!(same_posture(l1, &moved, &q), same, "{moved:?} {q:?}");
                            let turned =
                                point(wrap_angle(theta1 + sign * f * SAME_SOLUTION_RAD), rho1);
                            assert_eq!(same_posture(l1, &turned, &q), same, "{turned:?} {q:?}");
                        }
                    }
                }
            }
        }
    }

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

    /// Platform points (x, z) with yp = 0 and alpha = 0, and the table angles of their tool
    /// poses (theta1, theta2).
    const TABLE_II_POSES: [(f64, f64, f64, f64); 2] =
        [(30.0, 700.0, 0.2, 0.5), (-60.0, 820.0, -0.4, -2.0)];

    /// The tool pose whose platform point is (x, yp, z) at alpha = 0 with the table at
    /// (theta1, theta2), and h, the half-distance of its two leg-I postures at yp = 0
    /// (rho1 = z +- h, Table II of IFToMM 2007: K1 = L1^2 - (R1 - r1)^2 at alpha = 0).
    fn table_ii_pose(
        m: &Machine,
        x: f64,
        yp: f64,
        z: f64,
        theta1: f64,
        theta2: f64,
    ) -> (ToolPose, f64) {
        let g = &m.module;
        let module = ModulePose {
            p: Vector3::new(x, yp, z),
            alpha: 0.0,
        };
        let tool = crate::machine::tool_pose_eq26(&m.table, &module, theta1, theta2, m.tool_length);
        let u = x + g.dx1;
        let h = (g.l1 * g.l1 - (g.r_big1 - g.r_small1).powi(2) - u * u).sqrt();
        (tool, h)
    }

    /// The leg-I path of a tool pose.
    fn path_of<'a>(m: &'a Machine, pose: &ToolPose) -> Leg1Path<'a> {
        let (sin_phi1, cos_phi1) = pose.phi1.sin_cos();
        Leg1Path {
            m,
            w: tilt_frame_platform(&m.table, pose, m.tool_length),
            sin_phi1,
            cos_phi1,
        }
    }

    /// Table II's double root (IFToMM 2007): a platform point with yp = 0 and alpha = 0 has
    /// two leg-I postures, rho1 = zp +- h, at one theta1, where F has a double root. The
    /// machine's inverse kinematics of the tool pose built on it has both, each once (a
    /// posture found from two seeds is merged, two postures are not).
    #[test]
    fn both_postures_of_table_ii_s_double_root_are_found_once() {
        let m = Machine::default_verne();
        for (x, z, theta1, theta2) in TABLE_II_POSES {
            let (tool, h) = table_ii_pose(&m, x, 0.0, z, theta1, theta2);
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

    /// The seeds at sin(alpha) = 0 of Table II's double root are its two postures themselves,
    /// rho1 = z +- h at the pose's theta1, before any polish. At the other angle, theta1 + pi
    /// (alpha = pi), F vanishes too (yp = 0 there as well): its seeds are that platform point's
    /// z' = 2 d_a - z plus and minus h' = sqrt(L1^2 - (R1 + r1)^2 - u^2), or z' twice where
    /// leg I does not reach.
    #[test]
    fn the_alpha_zero_seeds_of_table_ii_s_double_root_are_its_postures() {
        let m = Machine::default_verne();
        let g = &m.module;
        for (x, z, theta1, theta2) in TABLE_II_POSES {
            let (tool, h) = table_ii_pose(&m, x, 0.0, z, theta1, theta2);
            let f = theta1_equation(&m, &tool, m.tool_length);
            let seeds = alpha_zero_seeds(&m, &tool, &path_of(&m, &tool), &f);
            let u = x + g.dx1;
            let h_pi = (g.l1 * g.l1 - (g.r_big1 + g.r_small1).powi(2) - u * u)
                .max(0.0)
                .sqrt();
            let z_pi = 2.0 * m.table.d_a - z;
            let expected = [
                (theta1, z + h),
                (theta1, z - h),
                (theta1 + PI, z_pi + h_pi),
                (theta1 + PI, z_pi - h_pi),
            ];
            assert_eq!(seeds.len(), 4, "{seeds:?}");
            for ((th, rho1), (th_e, rho1_e)) in seeds.iter().zip(expected) {
                assert!(
                    wrap_angle(th - th_e).abs() < 1e-12 && (rho1 - rho1_e).abs() < 1e-8,
                    "seed ({th}, {rho1}), expected ({th_e}, {rho1_e})"
                );
            }
        }
    }

    /// Seeds at sin(alpha) = 0 only where F is small there: there F = yp^2 (R1 -+ r1)^2, so a
    /// platform point yp off the plane y = 0 gives them while that value is below
    /// [`ALPHA_ZERO_SEED_REL`] of F's largest coefficient (a quarter of it at alpha = 0), and
    /// not at four times it; a generic pose gives none.
    #[test]
    fn alpha_zero_seeds_only_where_f_is_small() {
        let m = Machine::default_verne();
        let g = &m.module;
        let (x, z, theta1, theta2) = TABLE_II_POSES[0];
        let (tool, _) = table_ii_pose(&m, x, 0.0, z, theta1, theta2);
        let f = theta1_equation(&m, &tool, m.tool_length);
        let scale = f
            .cos
            .iter()
            .chain(&f.sin)
            .fold(0.0f64, |a, c| a.max(c.abs()));
        let (rm, rp) = (g.r_big1 - g.r_small1, g.r_big1 + g.r_small1);
        for (ratio, seeds_at_zero) in [(0.25, true), (4.0, false)] {
            let yp = (ratio * ALPHA_ZERO_SEED_REL * scale).sqrt() / rm;
            let (tool, _) = table_ii_pose(&m, x, yp, z, theta1, theta2);
            let f = theta1_equation(&m, &tool, m.tool_length);
            let seeds = alpha_zero_seeds(&m, &tool, &path_of(&m, &tool), &f);
            let at_zero: Vec<f64> = seeds
                .iter()
                .filter(|s| wrap_angle(s.0 - theta1).abs() < 1e-12)
                .map(|s| s.1)
                .collect();
            assert_eq!(
                at_zero.len(),
                if seeds_at_zero { 2 } else { 0 },
                "{ratio}: {seeds:?}"
            );
            // Off y = 0 the seeds are rho1 = z +- h with h^2 = L1^2 - (R1 - r1)^2 - u^2 - yp^2
            // (eq. (10) of IFToMM 2007 at alpha = 0): yp counts, by about 1e-6 mm here.
            let u = x + g.dx1;
            let h = (g.l1 * g.l1 - rm * rm - u * u - yp * yp).sqrt();
            for (rho1, expected) in at_zero.iter().zip([z + h, z - h]) {
                assert!((rho1 - expected).abs() < 1e-9, "{rho1} vs {expected}");
            }
            // At alpha = pi, F = yp^2 (R1 + r1)^2: seeds there too only if that is small.
            let at_pi = (yp * rp).powi(2) <= ALPHA_ZERO_SEED_REL * scale;
            assert_eq!(
                seeds.len(),
                2 * (seeds_at_zero as usize + at_pi as usize),
                "{ratio}"
            );
        }
        let generic = ToolPose {
            tip: Vector3::new(20.0, -35.0, 40.0),
            phi1: 0.3,
            phi2: 0.2,
        };
        let f = theta1_equation(&m, &generic, m.tool_length);
        assert!(alpha_zero_seeds(&m, &generic, &path_of(&m, &generic), &f).is_empty());
    }

    /// The leg-I postures of a generic tool pose, (theta1, rho1), from its branches.
    fn postures(m: &Machine, pose: &ToolPose) -> Vec<(f64, f64)> {
        let mut out: Vec<(f64, f64)> = Vec::new();
        for b in machine_ik(m, pose, m.tool_length).iter() {
            if !out.iter().any(|&(t, r)| t == b.theta1 && r == b.rho.x) {
                out.push((b.theta1, b.rho.x));
            }
        }
        out
    }

    /// What the polish of the seeds does to the certificate, with seeds injected as a failing
    /// proof would give them: every proved seed found keeps it; a posture found only by a seed
    /// no proof predicted, a proved seed that fails or that polishes to a posture more than
    /// 1e-6 rad away make it unproved; allowed seeds count as expected, and one that fails
    /// proves nothing missing.
    #[test]
    fn the_polish_of_the_seeds_keeps_the_certificate_only_when_the_proof_holds() {
        let m = Machine::default_verne();
        let pose = ToolPose {
            tip: Vector3::new(20.0, -35.0, 40.0),
            phi1: 0.3,
            phi2: 0.2,
        };
        let path = path_of(&m, &pose);
        let all = postures(&m, &pose);
        assert!(all.len() >= 2, "{all:?}");
        let (last, rest) = all.split_last().unwrap();
        let nan = (f64::NAN, f64::NAN);
        let off = (all[0].0 + 1e-3, all[0].1);
        let run = |proved: &[(f64, f64)], allowed: &[(f64, f64)], others: &[(f64, f64)]| {
            let mut certificate = Certificate::Double;
            let found = polish_postures(&path, proved, allowed, others, &mut certificate);
            let mut found: Vec<(f64, f64)> = found.iter().map(|q| (q.theta1, q.rho1)).collect();
            found.sort_by(|a, b| a.0.total_cmp(&b.0));
            assert_eq!(found.len(), all.len(), "{found:?} vs {all:?}");
            for (a, b) in found.iter().zip(&all) {
                assert!(
                    (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-6,
                    "{a:?} vs {b:?}"
                );
            }
            certificate
        };
        let double = Certificate::Double;
        let unproved = Certificate::Unproved;
        assert_eq!(run(&all, &[], &[]), double);
        assert_eq!(run(&all, &[], &all), double, "others that repeat the proof");
        assert_eq!(
            run(rest, &[], &[*last]),
            unproved,
            "a posture only others found"
        );
        assert_eq!(run(&all[..1], &all[1..], &[]), double, "the rest allowed");
        assert_eq!(run(&all, &[nan], &[]), double, "an allowed seed that fails");
        let mut failing = all.clone();
        failing.push(nan);
        assert_eq!(
            run(&failing, &[], &[]),
            unproved,
            "a proved seed that fails"
        );
        let mut drifting = all.clone();
        drifting.push(off);
        assert_eq!(
            run(&drifting, &[], &[]),
            unproved,
            "a proved seed that drifts"
        );
    }
}
