//! The branch that continues the previous joints, for a controller that asks for the inverse
//! kinematics once per servo period: the complete solve's choice ([`choose_continuation`]: every
//! branch of the pose by [`machine_ik`](super::machine_ik), then the one of the machine's kind
//! nearest the previous joints), answered from the previous joints alone when that can be proved
//! ([`continue_locally`]), by the complete solve otherwise ([`continue_branch`]).
//!
//! A branch stands on a leg-I posture x = (theta1, rho1): a solution of the leg-I equations
//! along the tool pose, G(x) = (g1, g2) = 0 with g1 = u^2 + yp^2 + (zp - rho1)^2 - K1 (eq. (10),
//! IFToMM 2007) and g2 = yp (R1 cos a - r1) + R1 sin a (zp - rho1) (eq. (14)), P(theta1) from
//! eqs. (7)-(9) and alpha = theta1 + phi1 (eq. (14)), AIM 2007; theta1 is a root of the theta1
//! equation (15) and rho1 goes with it. The continuation runs Newton on G = 0 from the previous
//! joints' (theta1, rho1) until a step is below [`NEWTON_DONE_MM`]: the point x0 that step starts
//! from is the centre of the proof, the point x* it reaches is the posture. It builds x*'s branch
//! of the machine's kind B* by the steps the complete solve takes (eqs. (12)-(13)), and proves
//! that no other posture is as near the previous joints p as B* is:
//!
//! - Variables t = S theta1 (S = [`JOINT_DISTANCE_MM_PER_RAD`]) and rho1, both in mm, with the
//!   max norm; the distance of a branch from the previous joints (largest slider travel plus S
//!   |d theta1|) is at least the norm of its posture's offset from p.
//! - With beta = |J(x0)^-1| and L a Lipschitz constant of J on the ball B(x0, R), any two
//!   solutions x, y in the ball satisfy |y - x| <= beta L (|x - x0| + |y - x0|) / 2 |y - x|
//!   (G(y) - G(x) = J(x0) (y - x) + the integral of (J - J(x0)) (y - x)). Newton's step from x0
//!   is at most eta (the residuals' rounding included): by Kantorovich's theorem (beta L eta <=
//!   1/2) an exact posture lies within 2 eta of x0, and x* within beta L eta^2 of it (at most
//!   [`NEWTON_TAIL_MM`]). So when beta L (R + 2 eta) < 2, it is the only posture in the ball.
//! - R = |x* - p| + |x* - x0| + D + [`POSTURE_SLACK_MM`], D the distance of B*: every other
//!   posture is then farther than D + slack from p, and so is every branch on it. The other
//!   branches on x* itself have another configuration, not the machine's.
//!
//! So B* is the branch of the machine's kind nearest the previous joints among all of the pose's
//! branches: the one [`choose_continuation`] picks from the complete solve. The region is a ball
//! in (theta1, rho1), not an interval of theta1: it also separates the posture from its mirror at
//! the same theta1 (the other sign of rho1 - zp, where the theta1 equation has a double root,
//! Table II of IFToMM 2007: the VERNE's home pose, tool vertical at the table centre, is one),
//! which no interval of theta1 does. L comes from bounds on the second derivatives of g1 and g2
//! over the ball, with the rows of G weighted so that both rows' bounds are equal (the product
//! beta L does not depend on the equations' units).
//!
//! When the proof does not hold (no posture near the previous joints, a branch not of the
//! machine's kind or not working there, another posture within reach: a jump of the pose, a
//! singularity of leg I or of the theta1 equation nearby), [`continue_branch`] runs the complete
//! solve and says why ([`Fallback`]). The answer is the same either way, with one difference: the
//! continuation needs no proof that the pose's list of branches is complete, so where the
//! complete solve cannot prove its list (`Uncertified`), the continuation may still answer.

use nalgebra::{Matrix2, Vector2};

use super::ToolPose;
use super::ik::{
    Leg1Path, MachineIkBranch, MachineIkBranches, PathPoint, machine_ik_into, platform_at,
    posture_branches_each, tilt_frame_platform_sc,
};
use super::path::JOINT_DISTANCE_MM_PER_RAD;
use crate::parallel_module::branches::{WORKING_CONFIG, cos_tilt_max};
use crate::parallel_module::equations::Sliders;
use crate::parallel_module::ik::wrap_angle;
use crate::spec::Machine;
use crate::tolerance::{ACCEPT_RESIDUAL_MM, NEWTON_MAX_ITER};

/// Largest product beta L (R + 2 eta) the continuation accepts, as a fraction of the 2 its proof
/// needs: the other half is room for the rounding of beta, L and the distances.
pub const ISOLATION_FRACTION: f64 = 0.5;

/// How far (mm, in the variables (S theta1, rho1) of the module documentation) the complete
/// solve's polished postures may lie from the exact ones: it accepts a posture whose residuals
/// of eqs. (10) and (14), as lengths along the rod, are at most [`ACCEPT_RESIDUAL_MM`], which
/// moves it by about beta 2 L1 [`ACCEPT_RESIDUAL_MM`] (beta of order 1e-2 per mm on the VERNE:
/// 2e-5 mm). The isolation covers this much beyond the distance of the continued branch, so that
/// a posture the complete solve lists is never nearer the previous joints than the one
/// continued.
pub const POSTURE_SLACK_MM: f64 = 1e-3;

/// The continuation's Newton stops once its step is below this (mm, in the variables (S theta1,
/// rho1) of the module documentation) and takes that last step without evaluating G again: the
/// step after it would be below beta L 1e-14 / 2 (beta L about 2e-2 per mm on the VERNE), far
/// below rounding. Proved for each answer: [`NEWTON_TAIL_MM`].
pub const NEWTON_DONE_MM: f64 = 1e-7;

/// Largest bound (mm, in (S theta1, rho1)) on the distance from the continued posture to the
/// exact one that the continuation accepts: that posture is then the complete solve's to its
/// last units (the complete solve's Newton polish stops at [`crate::tolerance::NEWTON_STEP_STOP`]).
pub const NEWTON_TAIL_MM: f64 = 1e-14;

/// The joints a continuation starts from: what the choice of a branch reads (theta2 is the
/// caller's to unwrap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreviousJoints {
    /// Slider positions (mm).
    pub rho: Sliders,
    /// Tilting axis (rad).
    pub theta1: f64,
}

/// The distance (mm) that chooses the continuation: the largest slider travel plus the table's
/// rotation at [`JOINT_DISTANCE_MM_PER_RAD`], theta1 the short way round.
#[inline]
pub fn joint_distance(b: &MachineIkBranch, prev: &PreviousJoints) -> f64 {
    (b.rho - prev.rho).amax() + JOINT_DISTANCE_MM_PER_RAD * wrap_angle(b.theta1 - prev.theta1).abs()
}

/// The branches of the machine's kind: every slider attachment above its platform attachment and
/// the rods of leg I not crossing, whatever the limits say.
#[inline]
pub fn machine_kind(b: &MachineIkBranch) -> bool {
    b.working() || b.verdict.only_limits()
}

/// Why no branch continues the previous joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoBranch {
    /// The complete solve could not prove its list of branches complete.
    Uncertified,
    /// No real branch reaches the pose.
    Unreachable,
    /// The branch of the machine's kind nearest the previous joints is outside the limits, and
    /// another one is inside: continuing would be a jump to another branch.
    BranchLost,
    /// No branch of the machine's kind is inside the limits.
    Limits,
}

/// The complete solve's continuation: of every branch of the pose, the one of the machine's kind
/// nearest the previous joints ([`joint_distance`], the first of equals in the list's order),
/// when it is working.
pub fn choose_continuation(
    branches: &MachineIkBranches,
    prev: &PreviousJoints,
) -> Result<MachineIkBranch, NoBranch> {
    if !branches.certificate.proved() {
        return Err(NoBranch::Uncertified);
    }
    if branches.is_empty() {
        return Err(NoBranch::Unreachable);
    }
    let nearest = |ok: &dyn Fn(&MachineIkBranch) -> bool| {
        branches
            .iter()
            .filter(|b| ok(b))
            .min_by(|x, y| joint_distance(x, prev).total_cmp(&joint_distance(y, prev)))
            .copied()
    };
    match nearest(&machine_kind) {
        Some(b) if b.working() => Ok(b),
        Some(_) if nearest(&|b| b.working()).is_some() => Err(NoBranch::BranchLost),
        _ => Err(NoBranch::Limits),
    }
}

/// Why [`continue_locally`] did not answer (the complete solve then does).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fallback {
    /// A value of the pose, the tool length or the previous joints is not finite.
    NotFinite,
    /// Newton from the previous joints reached no leg-I posture: its steps did not come below
    /// [`NEWTON_DONE_MM`] within [`NEWTON_MAX_ITER`], or the residual there is above
    /// [`ACCEPT_RESIDUAL_MM`].
    NoPosture,
    /// The posture reached has no working branch of the machine's kind (a limit, the rods of leg
    /// I crossing, another sign of rho1 - zp): the complete solve says which case it is.
    NotWorking,
    /// The posture is not proved to be the only one within reach of the previous joints, or
    /// not proved to its last units ([`NEWTON_TAIL_MM`]).
    NotIsolated,
}

/// The branch of the machine's kind nearest the previous joints, proved from them alone (the
/// module documentation), or why not. Allocates nothing and solves no equation but the leg-I
/// posture's.
pub fn continue_locally(
    m: &Machine,
    pose: &ToolPose,
    tool_length: f64,
    prev: &PreviousJoints,
) -> Result<MachineIkBranch, Fallback> {
    let finite = pose
        .tip
        .iter()
        .chain(prev.rho.iter())
        .all(|v| v.is_finite())
        && [pose.phi1, pose.phi2, tool_length, prev.theta1]
            .iter()
            .all(|v| v.is_finite());
    if !finite {
        return Err(Fallback::NotFinite);
    }
    if m.has_zeros() {
        // The previous joints as the equations' variables, the answer as the joints read it.
        let model_prev = PreviousJoints {
            rho: m.model_sliders(&prev.rho),
            theta1: prev.theta1 + m.table.theta_zero[0],
        };
        return continue_locally(&m.model(), pose, tool_length, &model_prev)
            .map(|b| super::ik::joints_of_branch(m, &b));
    }
    let g = &m.module;
    let (sin_phi1, cos_phi1) = pose.phi1.sin_cos();
    let path = Leg1Path {
        m,
        w: tilt_frame_platform_sc(&m.table, pose, (sin_phi1, cos_phi1), tool_length),
        sin_phi1,
        cos_phi1,
    };
    let (sin, cos) = prev.theta1.sin_cos();
    let Some(newton) = newton_from(
        &path,
        PathPoint {
            theta1: prev.theta1,
            sin,
            cos,
            rho1: prev.rho.x,
        },
    ) else {
        return Err(Fallback::NoPosture);
    };
    // Residuals of (10) and (14) as lengths along the rod (mm), as the complete solve accepts
    // its postures.
    let res = (newton.f.x / (2.0 * g.l1))
        .abs()
        .max((newton.f.y / g.r_big1).abs());
    if res.is_nan() || res > ACCEPT_RESIDUAL_MM {
        return Err(Fallback::NoPosture);
    }
    let q = newton.next;
    let mut found = None;
    posture_branches_each(
        &path,
        &q,
        pose.phi1,
        wrap_angle(-pose.phi2),
        cos_tilt_max(m),
        |config| config == WORKING_CONFIG,
        |b| found = Some(b),
    );
    let Some(b) = found.filter(MachineIkBranch::working) else {
        return Err(Fallback::NotWorking);
    };
    // The ball is centred on the last iterate evaluated, one Newton step (below
    // NEWTON_DONE_MM) from the posture of the branch.
    let d = joint_distance(&b, prev);
    let s = JOINT_DISTANCE_MM_PER_RAD;
    let offset = (q.rho1 - prev.rho.x)
        .abs()
        .max(s * wrap_angle(q.theta1 - prev.theta1).abs());
    let radius = offset + newton.step_norm + d + POSTURE_SLACK_MM;
    match isolation(&path, &newton.at, (&newton.f, &newton.j), radius) {
        Some(iso) if iso.product <= 2.0 * ISOLATION_FRACTION && iso.tail <= NEWTON_TAIL_MM => Ok(b),
        _ => Err(Fallback::NotIsolated),
    }
}

/// Newton's steps on G = 0 from `start` until a step is below [`NEWTON_DONE_MM`] (within
/// [`NEWTON_MAX_ITER`] steps): the last iterate evaluated with G and J there, the size of the step
/// from it, and the point it reaches (theta1 wrapped to (-pi, pi]). None when J is singular or
/// the steps do not come down.
#[inline(always)]
fn newton_from(path: &Leg1Path, start: PathPoint) -> Option<Newton> {
    let mut at = start;
    for _ in 0..=NEWTON_MAX_ITER {
        let (f, j) = path.eval(&at);
        // J^-1 f by Cramer's rule.
        let k = 1.0 / (j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)]);
        let step = Vector2::new(
            (j[(1, 1)] * f.x - j[(0, 1)] * f.y) * k,
            (j[(0, 0)] * f.y - j[(1, 0)] * f.x) * k,
        );
        let step_norm = step.y.abs().max(JOINT_DISTANCE_MM_PER_RAD * step.x.abs());
        if !step_norm.is_finite() {
            return None;
        }
        let mut next = at.stepped(&step);
        if step_norm <= NEWTON_DONE_MM {
            next.theta1 = wrap_angle(next.theta1);
            return Some(Newton {
                at,
                f,
                j,
                step_norm,
                next,
            });
        }
        at = next;
    }
    None
}

/// What [`newton_from`] returns.
struct Newton {
    /// The last iterate evaluated, with G and J there.
    at: PathPoint,
    f: Vector2<f64>,
    j: Matrix2<f64>,
    /// The size of Newton's step from `at` (mm, in (S theta1, rho1), max norm).
    step_norm: f64,
    /// `at` minus that step: the posture.
    next: PathPoint,
}

/// What [`isolation`] computes.
struct Isolation {
    /// beta L (R + 2 eta): the posture is the only one in the ball when below 2.
    product: f64,
    /// beta L eta^2: a bound on the distance (mm) from Newton's next iterate to the exact
    /// posture (Kantorovich's theorem gives eta - t* <= beta L eta^2 / 2 for the step, with
    /// beta L eta <= 1/2).
    tail: f64,
}

/// beta L (R + 2 eta) of the module documentation for the posture `q` (G and J there: `f`,
/// `j`) and the ball of radius `radius` (mm) around it, in the variables (S theta1, rho1) with
/// the max norm and the rows of G weighted to equal Lipschitz bounds, and the bound on Newton's
/// next iterate's error; None where J is singular, a value is not finite, or Kantorovich's
/// condition beta L eta <= 1/2 fails.
fn isolation(
    path: &Leg1Path,
    q: &PathPoint,
    (f, j): (&Vector2<f64>, &Matrix2<f64>),
    radius: f64,
) -> Option<Isolation> {
    let m = path.m;
    let g = &m.module;
    let (r, rr) = (g.r_big1, g.r_small1);
    let inv_s = 1.0 / JOINT_DISTANCE_MM_PER_RAD;
    let [h1, h2] = lipschitz_rows(path, q, radius);
    // Weight row 2 by h1 / h2: then L = h1 for both rows.
    let (lipschitz, inv_weight) = if h2 > 0.0 && h1 > 0.0 {
        (h1, h2 / h1)
    } else {
        (h1.max(h2), 1.0)
    };
    // J in t: the theta1 column divided by S; its inverse by cofactors.
    let (j11, j12, j21, j22) = (j[(0, 0)] * inv_s, j[(0, 1)], j[(1, 0)] * inv_s, j[(1, 1)]);
    let k = 1.0 / (j11 * j22 - j12 * j21);
    let inv = [[j22 * k, -j12 * k], [-j21 * k, j11 * k]];
    // beta = |J_w^-1| (max norm), J_w = diag(1, weight) J: column 2 of J^-1 divided by weight.
    let beta = (inv[0][0].abs() + inv[0][1].abs() * inv_weight)
        .max(inv[1][0].abs() + inv[1][1].abs() * inv_weight);
    // Newton's step from the posture, with the residuals raised by their rounding: a few
    // operations on terms at most the sizes below (yp and zp - d_a within a, zp - rho1 within
    // |zp| + |rho1|).
    let (p, _) = platform_at(m.table.d_a, &path.w, q.sin, q.cos);
    let (sa, ca) = path.alpha_sin_cos(q);
    let (u, wf) = (p.x + g.dx1, r * ca - rr);
    let a = (path.w.y * path.w.y + path.w.z * path.w.z).sqrt();
    let (yb, zb) = (p.y.abs() + a, p.z.abs() + q.rho1.abs() + a);
    let e1 = 16.0 * f64::EPSILON * (u * u + yb * yb + zb * zb + g.l1 * g.l1 + 2.0 * r * rr);
    let e2 = 16.0 * f64::EPSILON * (yb * (wf.abs() + r) + r * zb + r * (sa * zb).abs());
    let (f1, f2) = (f.x.abs() + e1, f.y.abs() + e2);
    let eta = (inv[0][0].abs() * f1 + inv[0][1].abs() * f2)
        .max(inv[1][0].abs() * f1 + inv[1][1].abs() * f2);
    let kantorovich = beta * lipschitz * eta;
    let product = beta * lipschitz * (radius + 2.0 * eta);
    (product.is_finite() && kantorovich <= 0.5).then_some(Isolation {
        product,
        tail: kantorovich * eta,
    })
}

/// Lipschitz bounds of the rows of J over the ball of radius `radius` (mm) around the posture
/// `q`, in the variables t = S theta1 and rho1 with the max norm: for each row, the sum over
/// (j, k) of bounds on |d^2 g_i / dx_j dx_k| there. From g1 = u^2 + yp^2 + (zp - rho1)^2 - K1
/// and g2 = yp wf + R1 sa (zp - rho1) (IFToMM 2007 eqs. (10), (14); wf = R1 cos a - r1,
/// sa = sin a) with yp'' = -yp, zp'' = -(zp - d_a), sa'' = -sa, wf' = -R1 sa, K1'' = -2 R1 r1
/// cos a. In the ball |d theta1| <= delta = radius / S and |d rho1| <= radius; yp and zp - d_a
/// are sinusoids of theta1 of amplitude a = |(w_y, w_z)| (eq. (7), AIM 2007), so are their
/// derivatives, and each moves by at most a delta; sin and cos of alpha by at most delta.
fn lipschitz_rows(path: &Leg1Path, q: &PathPoint, radius: f64) -> [f64; 2] {
    let m = path.m;
    let g = &m.module;
    let (r, rr) = (g.r_big1, g.r_small1);
    let inv_s = 1.0 / JOINT_DISTANCE_MM_PER_RAD;
    let (p, dp) = platform_at(m.table.d_a, &path.w, q.sin, q.cos);
    let (sa, ca) = path.alpha_sin_cos(q);
    let delta = radius * inv_s;
    let a = (path.w.y * path.w.y + path.w.z * path.w.z).sqrt();
    let near = |v: f64, amplitude: f64| (v.abs() + amplitude * delta).min(amplitude);
    let y = near(p.y, a);
    let yd = near(dp.y, a);
    let z0 = near(p.z - m.table.d_a, a);
    let zd = near(dp.z, a);
    let dz = (p.z - q.rho1).abs() + a * delta + radius;
    let (sab, cab) = (near(sa, 1.0), near(ca, 1.0));
    let wf = (r * ca - rr).abs() + r * delta;
    let g1_tt = 2.0 * (yd * yd + y * y) + 2.0 * (zd * zd + dz * z0) + 2.0 * r * rr * cab;
    let g1_tr = 2.0 * zd;
    let g1_rr = 2.0;
    let g2_tt =
        y * wf + 2.0 * yd * r * sab + y * r * cab + r * (sab * dz + 2.0 * cab * zd + sab * z0);
    let g2_tr = r * cab;
    // d/dt = d/dtheta1 / S; the mixed derivative counts twice.
    [
        g1_tt * inv_s * inv_s + 2.0 * g1_tr * inv_s + g1_rr,
        g2_tt * inv_s * inv_s + 2.0 * g2_tr * inv_s,
    ]
}

/// One answer of [`continue_branch`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Continued {
    /// The branch that continues the previous joints, or why there is none.
    pub answer: Result<MachineIkBranch, NoBranch>,
    /// None when [`continue_locally`] answered; otherwise why it did not, and the complete solve
    /// answered.
    pub fallback: Option<Fallback>,
    /// The branches the answer was chosen from: 1 when continued, every real branch of the pose
    /// when solved completely.
    pub branches: usize,
}

/// The branch that continues the previous joints: [`continue_locally`] where its proof holds,
/// else [`choose_continuation`] of the complete solve (`scratch` holds its list: keep one to
/// allocate nothing). The same branch either way (see the module documentation for the
/// `Uncertified` case).
#[inline]
pub fn continue_branch(
    m: &Machine,
    pose: &ToolPose,
    tool_length: f64,
    prev: &PreviousJoints,
    scratch: &mut MachineIkBranches,
) -> Continued {
    match continue_locally(m, pose, tool_length, prev) {
        Ok(b) => Continued {
            answer: Ok(b),
            fallback: None,
            branches: 1,
        },
        Err(why) => {
            machine_ik_into(m, pose, tool_length, scratch);
            Continued {
                answer: choose_continuation(scratch, prev),
                fallback: Some(why),
                branches: scratch.len(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::*;
    use crate::machine::machine_ik;
    use crate::math::test_rng::lcg;

    /// A tool pose of the default machine's workspace: tip within 60 mm of (0, 0, 40), tilt up
    /// to 25 degrees, any azimuth.
    fn pose_from(unit: &mut impl FnMut() -> f64) -> ToolPose {
        ToolPose {
            tip: Vector3::new(
                120.0 * unit() - 60.0,
                120.0 * unit() - 60.0,
                120.0 * unit() - 20.0,
            ),
            phi1: (50.0 * unit() - 25.0f64).to_radians(),
            phi2: std::f64::consts::TAU * unit(),
        }
    }

    fn joints_of(b: &MachineIkBranch) -> PreviousJoints {
        PreviousJoints {
            rho: b.rho,
            theta1: b.theta1,
        }
    }

    /// The working branch the complete solve continues from `seed` joints at `pose`.
    fn complete(m: &Machine, pose: &ToolPose, prev: &PreviousJoints) -> Option<MachineIkBranch> {
        choose_continuation(&machine_ik(m, pose, m.tool_length), prev).ok()
    }

    /// Largest difference of two branches' joints: sliders in mm, theta1 in degrees.
    fn joint_gap(a: &MachineIkBranch, b: &MachineIkBranch) -> f64 {
        (a.rho - b.rho)
            .amax()
            .max(wrap_angle(a.theta1 - b.theta1).abs().to_degrees())
    }

    /// The Lipschitz bounds of J's rows ([`lipschitz_rows`]) hold: for pairs of points anywhere
    /// in balls of 0.1 to 300 mm around continued postures, each row of J (in t = S theta1 and
    /// rho1) changes by at most its bound times the max-norm distance. J from the equations'
    /// own Jacobian, which `ik`'s tests check against central differences.
    #[test]
    fn the_lipschitz_bounds_hold_over_the_ball() {
        let m = Machine::default_verne();
        let mut unit = lcg(0x11b5_c0de_0000_0001);
        let s = JOINT_DISTANCE_MM_PER_RAD;
        let mut tightest = 0.0f64;
        let mut checked = 0;
        while checked < 40 {
            let pose = pose_from(&mut unit);
            let Some(b) = machine_ik(&m, &pose, m.tool_length)
                .iter()
                .copied()
                .find(MachineIkBranch::working)
            else {
                continue;
            };
            checked += 1;
            let (sin_phi1, cos_phi1) = pose.phi1.sin_cos();
            let path = Leg1Path {
                m: &m,
                w: tilt_frame_platform_sc(&m.table, &pose, (sin_phi1, cos_phi1), m.tool_length),
                sin_phi1,
                cos_phi1,
            };
            let at = |theta1: f64, rho1: f64| {
                let (sin, cos) = theta1.sin_cos();
                PathPoint {
                    theta1,
                    sin,
                    cos,
                    rho1,
                }
            };
            let q = at(b.theta1, b.rho.x);
            for radius in [0.1, 3.0, 30.0, 300.0] {
                let h = lipschitz_rows(&path, &q, radius);
                for _ in 0..200 {
                    let mut point = || {
                        let (dt, dr) = (2.0 * unit() - 1.0, 2.0 * unit() - 1.0);
                        (q.theta1 + radius * dt / s, q.rho1 + radius * dr)
                    };
                    let (pa, pb) = (point(), point());
                    let (_, ja) = path.eval(&at(pa.0, pa.1));
                    let (_, jb) = path.eval(&at(pb.0, pb.1));
                    let dist = (s * (pa.0 - pb.0)).abs().max((pa.1 - pb.1).abs());
                    for (i, hi) in h.iter().enumerate() {
                        let change =
                            ((ja[(i, 0)] - jb[(i, 0)]) / s).abs() + (ja[(i, 1)] - jb[(i, 1)]).abs();
                        // Rounding of J's entries (about 1e6 at most) is far below the bound.
                        assert!(
                            change <= hi * dist + 1e-6,
                            "row {i}, radius {radius}: {change} > {hi} x {dist}"
                        );
                        tightest = tightest.max(change / (hi * dist));
                    }
                }
            }
        }
        // The bounds are not vacuous: some pair comes within a factor 20 of one.
        assert!(tightest > 0.05, "{tightest}");
    }

    /// From the joints of the previous pose, a pose moved by a servo period's step (0.2 mm,
    /// 0.1 degree) or a hundred times that is continued without the complete solve, to the
    /// joints of the complete solve's choice within 1e-12 (mm, degrees).
    #[test]
    fn a_step_is_continued_to_the_complete_solve_s_branch() {
        let m = Machine::default_verne();
        let mut unit = lcg(0x5e4f_0000_0000_0002);
        let mut continued = 0;
        for k in 0..400 {
            let pose = pose_from(&mut unit);
            let Some(start) = complete(
                &m,
                &pose,
                &PreviousJoints {
                    rho: Vector3::new(300.0, 250.0, 250.0),
                    theta1: 0.0,
                },
            ) else {
                continue;
            };
            let scale = if k % 2 == 0 { 1.0 } else { 100.0 };
            let mut next = pose;
            next.tip += Vector3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 0.4 * scale;
            next.phi1 += (unit() - 0.5) * 0.2f64.to_radians() * scale;
            next.phi2 += (unit() - 0.5) * 0.4f64.to_radians() * scale;
            let prev = joints_of(&start);
            let want = complete(&m, &next, &prev);
            match continue_locally(&m, &next, m.tool_length, &prev) {
                Ok(b) => {
                    continued += 1;
                    let want = want.expect("the complete solve continues too");
                    assert!(joint_gap(&b, &want) <= 1e-12, "{b:?} vs {want:?}");
                    assert_eq!(b.config, want.config);
                    assert_eq!(b.verdict, want.verdict);
                }
                Err(why) => assert!(scale > 1.0, "a servo step fell back: {why:?} at {next:?}"),
            }
        }
        assert!(continued >= 300, "{continued}");
    }

    /// The home pose of the LinuxCNC simulation, X0 Y0 Z100 A0 C0, has its platform point at
    /// yp = 0, alpha = 0: a double root of the theta1 equation (Table II of IFToMM 2007), two
    /// postures at theta1 = 0. The continuation tells them apart by rho1 and continues the
    /// machine's, there and 0.01 mm away, to the complete solve's joints.
    #[test]
    fn the_double_root_at_home_is_continued() {
        let m = Machine::default_verne();
        let home = ToolPose {
            tip: Vector3::new(0.0, 0.0, 100.0),
            phi1: 0.0,
            phi2: 0.0,
        };
        let all = machine_ik(&m, &home, m.tool_length);
        let at_zero = all.iter().filter(|b| b.theta1.abs() < 1e-12).count();
        assert_eq!(at_zero, 8, "two postures at theta1 = 0: {all:?}");
        let seed = PreviousJoints {
            rho: Vector3::new(300.0, 250.0, 250.0),
            theta1: 0.0,
        };
        let start = complete(&m, &home, &seed).unwrap();
        for pose in [
            home,
            ToolPose {
                tip: Vector3::new(0.01, 0.0, 100.0),
                ..home
            },
            ToolPose {
                tip: Vector3::new(0.0, -0.01, 100.0),
                ..home
            },
        ] {
            let prev = joints_of(&start);
            let b = continue_locally(&m, &pose, m.tool_length, &prev).expect("continued");
            let want = complete(&m, &pose, &prev).unwrap();
            assert!(joint_gap(&b, &want) <= 1e-12, "{b:?} vs {want:?}");
        }
    }

    /// Where the proof cannot be made the continuation says why, and `continue_branch` answers
    /// as the complete solve does: a pose that is not finite; previous joints on the other
    /// sign of rho1 - zp (Newton reaches that posture, whose branch is not the machine's); a
    /// jump of 300 mm (the ball that would have to be empty holds other postures).
    #[test]
    fn what_is_not_proved_falls_back_to_the_complete_solve() {
        let m = Machine::default_verne();
        let pose = ToolPose {
            tip: Vector3::new(10.0, -20.0, 5.0),
            phi1: 12f64.to_radians(),
            phi2: 30f64.to_radians(),
        };
        let all = machine_ik(&m, &pose, m.tool_length);
        let working = *all.iter().find(|b| b.working()).unwrap();
        // The other sign of rho1 - zp: the posture of the nearby root of the theta1 equation
        // (h- of `leg1_certify`'s factors where the working one is a root of h+).
        let inverted = *all
            .iter()
            .filter(|b| b.config == [1, -1, -1])
            .min_by(|x, y| {
                let d = |b: &MachineIkBranch| wrap_angle(b.theta1 - working.theta1).abs();
                d(x).total_cmp(&d(y))
            })
            .unwrap();
        let mut nan = pose;
        nan.phi1 = f64::NAN;
        let far = ToolPose {
            tip: Vector3::new(-150.0, 150.0, -100.0),
            phi1: -20f64.to_radians(),
            phi2: 200f64.to_radians(),
        };
        let cases = [
            (nan, joints_of(&working), Fallback::NotFinite),
            (pose, joints_of(&inverted), Fallback::NotWorking),
            (far, joints_of(&working), Fallback::NotIsolated),
        ];
        let mut scratch = MachineIkBranches::new();
        for (p, prev, why) in cases {
            assert_eq!(continue_locally(&m, &p, m.tool_length, &prev), Err(why));
            let c = continue_branch(&m, &p, m.tool_length, &prev, &mut scratch);
            assert_eq!(c.fallback, Some(why));
            let want = choose_continuation(&machine_ik(&m, &p, m.tool_length), &prev);
            assert_eq!(c.answer, want, "{why:?}");
            assert_eq!(c.branches, machine_ik(&m, &p, m.tool_length).len());
        }
    }
}
