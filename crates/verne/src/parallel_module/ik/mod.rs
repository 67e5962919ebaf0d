//! Inverse kinematics of the parallel module (IFToMM 2007, section V): for a point P, every real
//! (alpha, rho1, rho2, rho3).
//!
//! alpha comes from the cubic in cos(alpha) of eq. (9), rho1 from eq. (14) (both signs of eq. (11)
//! where sin(alpha) = 0, Table II), rho2 and rho3 from eqs. (12)-(13) with both signs.
//!
//! The root of (9) a feasible branch can stand on (R1 cos(alpha) > r1) comes, when certified
//! alone, from Chebyshev steps on leg I's equations (10) and (14) from an estimate, without
//! isolating the cubic (the section on the certificate at the end). Many points are solved side
//! by side ([`solve_each`], [`solve_working_each`]; [`LANES`] at a time), each alone all the
//! same, so that the processor overlaps their chains of square roots and divisions.

mod branch;
#[cfg(target_arch = "x86_64")]
mod lanes;

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::certificate::Certificate;
use crate::math::certify::{self, DdVerdict};
use crate::math::cpu;
use crate::math::cubic::{cubic_roots_in, cubic_roots_in_with_error, deflated_roots_in};
use crate::math::dd::Tracked;
use crate::math::scalar::Mag;
use crate::math::trig::{SMALL_ANGLE, sin_cos_after_step, sin_cos_small};
use crate::parallel_module::branches::{
    Verdict, WORKING_CONFIG, cos_tilt_max, leg_state, outer_leg_labels, outer_leg_states,
    rods_cross, stroke_verdict,
};
use crate::parallel_module::equations::Sliders;
use crate::spec::{Machine, ModuleGeometry};
use crate::tolerance::ACCEPT_RESIDUAL_MM;
use crate::tolerance::{
    NEWTON_MAX_ITER, NEWTON_STEP_STOP, SAME_SOLUTION_RAD, SIN_ALPHA_ZERO, SQRT_ARG_REL,
};

pub use branch::{IkBranch, IkBranches, MAX_IK_BRANCHES};
pub(crate) use branch::{Leg1, distinct_branches, posture_order, push_distinct};

/// The cubic eq. (9) in cos(alpha) for the point, normalised, lowest degree first; None for a
/// point that is not finite, and when the cubic is degenerate (every coefficient zero) or
/// overflows.
pub fn cubic_eq9(g: &ModuleGeometry, p: &Vector3<f64>) -> Option<[f64; 4]> {
    if !p.iter().all(|v| v.is_finite()) {
        return None;
    }
    let c = eq9_coefficients(g, p);
    let scale = c.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    Some(c.map(|a| a / scale))
}

/// The coefficients of eq. (9), lowest degree first, as they come (not normalised).
#[inline]
pub fn eq9_coefficients(g: &ModuleGeometry, p: &Vector3<f64>) -> [f64; 4] {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let y = p.y;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    // eq. (9): p1 c^3 + p2 c^2 + p3 c + p4 = 0.
    let p1 = 2.0 * r * r * r * rr;
    let p2 = r * r * k0 - r * r * u * u;
    let p3 = -2.0 * r * r * r * rr - 2.0 * r * rr * y * y;
    let p4 = r * r * u * u + (r * r + rr * rr) * y * y - r * r * k0;
    [p4, p3, p2, p1]
}

/// Rounded operations on any path from an input to a coefficient of eq. (9) (about 8): a
/// generous count.
const EQ9_OPS: f64 = 16.0;

/// Bounds on the errors of [`eq9_coefficients`] (lowest degree first), from the magnitudes of
/// their formulas ([`Mag`]).
fn eq9_errors(g: &ModuleGeometry, p: &Vector3<f64>) -> [f64; 4] {
    let (r, rr) = (Mag::from(g.r_big1), Mag::from(g.r_small1));
    let u = Mag::from(p.x) + Mag::from(g.dx1);
    let y = Mag::from(p.y);
    let two = Mag::from(2.0);
    let k0 = Mag::from(g.l1) * Mag::from(g.l1) + r * r + rr * rr;
    let mags = [
        r * r * u * u + (r * r + rr * rr) * y * y + r * r * k0,
        two * r * r * r * rr + two * r * rr * y * y,
        r * r * k0 + r * r * u * u,
        two * r * r * r * rr,
    ];
    mags.map(|m| EQ9_OPS * f64::EPSILON * m.0)
}

/// |rho1 - zp| from eq. (11) at cos(alpha) = c, squared (negative when leg I cannot reach).
fn leg1_height_sq(g: &ModuleGeometry, p: &Vector3<f64>, c: f64) -> f64 {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let k1 = g.l1 * g.l1 - r * r - rr * rr + 2.0 * r * rr * c;
    k1 - u * u - p.y * p.y
}

/// The roots of eq. (9) in cos(alpha) other than the certified one (`certified`: the point's
/// [`certified_lanes`] posture, when it has one), in increasing order: all of them without it.
/// With it, the others are all below r1/R1: from the cubic divided by the known root (no
/// isolation), unless that is a close call. Empty when the cubic is degenerate. A root where
/// the cubic touches zero within its error (two roots too close to separate, a double root, or
/// none) comes as `touching`: [`leg1_postures_into`] decides it.
#[inline(always)]
fn other_roots(g: &ModuleGeometry, p: &Vector3<f64>, certified: Option<Leg1>) -> OtherRoots {
    let all_roots = |lo: f64, hi: f64| {
        let mut out = OtherRoots::default();
        let c = eq9_coefficients(g, p);
        let scale = c.iter().fold(0.0f64, |m, a| m.max(a.abs()));
        if scale == 0.0 || !scale.is_finite() {
            return out;
        }
        let err = eq9_errors(g, p).map(|e| e / scale);
        for r in cubic_roots_in_with_error(&c.map(|a| a / scale), &err, lo, hi) {
            if r.touching {
                let _ = out.touching.try_push(r.x);
            } else {
                let _ = out.roots.try_push(r.x);
            }
        }
        out
    };
    match certified {
        // The certificate saw finite coefficients with c3 > 0, and the division's thresholds
        // are relative to the coefficients' size: no normalisation needed.
        Some(leg1) => {
            let hi = g.r_small1 / g.r_big1 - FAST_MARGIN_RAD;
            match deflated_roots_in(&eq9_coefficients(g, p), leg1.cos, -1.0, hi) {
                Some(roots) => OtherRoots {
                    roots,
                    touching: ArrayVec::new(),
                },
                None => all_roots(-1.0, hi),
            }
        }
        None => all_roots(-1.0, 1.0),
    }
}

/// The roots of (9) from [`other_roots`].
#[derive(Debug, Clone, Default)]
pub(crate) struct OtherRoots {
    /// Proved simple roots, in increasing order.
    pub roots: ArrayVec<f64, 8>,
    /// Critical points where the cubic touches zero within its error.
    pub touching: ArrayVec<f64, 4>,
}

/// Every real leg-I posture (alpha, rho1) for the point into `out`: those of `roots` (from
/// [`other_roots`]) by eqs. (11) and (14), polished by Newton on eqs. (10) and (14) (the
/// half-sum and half-difference of (3) and (4)), then the certified one; each with its mirror
/// image, or where sin(alpha) = 0 both signs of eq. (11) (Table II). A posture met before is
/// left out.
#[inline(always)]
fn leg1_postures_into(
    g: &ModuleGeometry,
    p: &Vector3<f64>,
    roots: &OtherRoots,
    certified: Option<Leg1>,
    out: &mut ArrayVec<Leg1, 6>,
) -> Certificate {
    let mut certificate = Certificate::Double;
    out.clear();
    let mut push = |l: Leg1| {
        let dup = out.iter().any(|o: &Leg1| {
            (o.rho1 - l.rho1).abs() < 1e-7 && angle_diff(o.alpha, l.alpha).abs() < SAME_SOLUTION_RAD
        });
        if !dup && !out.is_full() {
            out.push(l);
        }
    };
    if !roots.touching.is_empty() {
        certificate = touching_postures(g, p, &roots.touching, &mut push);
    }
    for &root in &roots.roots {
        postures_at_root(g, p, root, &mut push);
    }
    // Last, as the root with the largest cos(alpha) (postures come out by increasing cos).
    if let Some(leg1) = certified {
        push(leg1);
        push(mirror(p, leg1));
    }
    certificate
}

/// The leg-I postures at a root c = cos(alpha) of (9): alpha = acos(c) with rho1 from eqs. (11)
/// and (14), polished, and its mirror image; where sin(alpha) = 0 both signs of eq. (11)
/// (Table II). None where leg I cannot reach.
fn postures_at_root(g: &ModuleGeometry, p: &Vector3<f64>, root: f64, push: &mut impl FnMut(Leg1)) {
    let (r, rr) = (g.r_big1, g.r_small1);
    let c = root.clamp(-1.0, 1.0);
    let sin_a = ((1.0 - c) * (1.0 + c)).sqrt();
    let h2 = leg1_height_sq(g, p, c);
    let h = if h2 >= -SQRT_ARG_REL * g.l1 * g.l1 {
        h2.max(0.0).sqrt()
    } else {
        return;
    };
    if sin_a < SIN_ALPHA_ZERO {
        // alpha in {0, pi}: eq. (14) is 0 = 0, both signs of eq. (11) (Table II).
        let a0 = if c > 0.0 { 0.0 } else { std::f64::consts::PI };
        let (sin, cos) = a0.sin_cos();
        for rho1 in [p.z + h, p.z - h] {
            push(polish_leg1(
                g,
                p,
                Leg1 {
                    alpha: a0,
                    rho1,
                    sin,
                    cos,
                },
            ));
        }
        return;
    }
    // sgn(rho1 - zp) from eq. (14): y (R1 cos a - r1) = R1 sin a (rho1 - zp), R1 sin a > 0.
    let q = p.y * (r * c - rr);
    let rho1 = if q == 0.0 { p.z } else { p.z + q.signum() * h };
    let polished = polish_leg1(
        g,
        p,
        Leg1 {
            alpha: libm::acos(c),
            rho1,
            sin: sin_a,
            cos: c,
        },
    );
    push(polished);
    push(mirror(p, polished));
}

/// The coefficients of eq. (9) (lowest degree first) in double-double from the exact inputs.
fn eq9_tracked(g: &ModuleGeometry, p: &Vector3<f64>) -> [Tracked; 4] {
    let t = Tracked::exact;
    let (r, rr) = (t(g.r_big1), t(g.r_small1));
    let u = t(p.x) + t(g.dx1);
    let y = t(p.y);
    let two = t(2.0);
    let k0 = t(g.l1) * t(g.l1) - r * r - rr * rr;
    [
        r * r * u * u + (r * r + rr * rr) * y * y - r * r * k0,
        -(two * r * r * r * rr) - two * r * rr * y * y,
        r * r * k0 - r * r * u * u,
        two * r * r * r * rr,
    ]
}

/// The residual of leg I's equations (10) and (14) at a posture, as a length (mm).
fn leg1_residual_mm(g: &ModuleGeometry, p: &Vector3<f64>, l: &Leg1) -> f64 {
    let (f, _) = Leg1Equations::new(g, p).residuals(l);
    (f[0] / (2.0 * g.l1)).abs().max((f[1] / g.r_big1).abs())
}

/// The postures at roots where the cubic (9) touches zero within its error: on the interval of
/// alpha where it can be that close to zero, the two factors of leg I's equation
/// ([`crate::parallel_module::leg1_certify`]) prove each posture (or that there is none); where they cannot,
/// the touching point is taken as a root, as the cubic's routine gives it, and the result is
/// unproved.
#[cold]
#[inline(never)]
fn touching_postures(
    g: &ModuleGeometry,
    p: &Vector3<f64>,
    touching: &[f64],
    push: &mut impl FnMut(Leg1),
) -> Certificate {
    let mut certificate = Certificate::Factored;
    let c = eq9_coefficients(g, p);
    let scale = c.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    let err = eq9_errors(g, p).iter().sum::<f64>() / scale;
    let c = c.map(|a| a / scale);
    for &ct in touching {
        let (c_lo, c_hi) = touching_interval(&c, err, ct);
        match crate::parallel_module::leg1_certify::postures_in(
            g,
            p,
            libm::acos(c_hi),
            libm::acos(c_lo),
        ) {
            Ok(found) => {
                for (alpha, rho1) in found {
                    let (sin, cos) = alpha.sin_cos();
                    let l = with_wrapped_alpha(Leg1 {
                        alpha,
                        rho1,
                        sin,
                        cos,
                    });
                    push(l);
                    push(mirror(p, l));
                }
            }
            Err(()) => {
                // Two postures of one sign about to merge: the cubic in double-double.
                let found = certify::poly_roots(&eq9_tracked(g, p), c_lo, c_hi);
                match certify::dd_verdict(found, c_lo, c_hi) {
                    DdVerdict::Decided { roots, undecided } => {
                        certificate = certificate.max(Certificate::Extended);
                        for c in roots {
                            postures_at_root(g, p, c, push);
                        }
                        // At most one root in each (the same solution): taken where leg I's
                        // equations hold at it.
                        for (_, middle) in undecided {
                            postures_at_root(g, p, middle, &mut |l: Leg1| {
                                if leg1_residual_mm(g, p, &l) <= ACCEPT_RESIDUAL_MM {
                                    push(l);
                                }
                            });
                        }
                    }
                    DdVerdict::Unproved { .. } => {
                        certificate = Certificate::Unproved;
                        unproved_touching_postures(g, p, ct, push);
                    }
                }
            }
        }
    }
    certificate
}

/// The last resort for a touching root `ct` of eq. (9) that neither proof decides (no input is
/// known to reach it): the postures at `ct` itself (clamped to [-1, 1]), with both signs of
/// eq. (11)'s square root, each polished, and their mirror images.
fn unproved_touching_postures(
    g: &ModuleGeometry,
    p: &Vector3<f64>,
    ct: f64,
    push: &mut impl FnMut(Leg1),
) {
    let cc = ct.clamp(-1.0, 1.0);
    let alpha = libm::acos(cc);
    let h2 = leg1_height_sq(g, p, cc).max(0.0);
    for rho1 in [p.z + h2.sqrt(), p.z - h2.sqrt()] {
        let l = polish_leg1(
            g,
            p,
            Leg1 {
                alpha,
                rho1,
                sin: alpha.sin(),
                cos: cc,
            },
        );
        push(l);
        push(mirror(p, l));
    }
}

/// The interval of cos(alpha) about a critical point `ct` of the cubic (9) `c` (normalised)
/// where a cubic within `err` of it (the sum of its coefficients' errors, which bounds the error
/// of its value on [-1, 1]) can have its roots near `ct`, within [-1, 1]. Near `ct` the cubic is
/// about its second derivative p2 times (x - ct)^2 / 2, so it comes within its error of zero
/// only for |x - ct| below about sqrt(2 err / |p2|) (sqrt(2) times that where its value at `ct`
/// is itself up to err off zero); four times that, plus rounding, covers the cubic term too
/// (`touching_interval_holds_every_root_the_error_allows`: the roots reach 0.37 of it).
fn touching_interval(c: &[f64; 4], err: f64, ct: f64) -> (f64, f64) {
    let p2 = (6.0 * c[3] * ct + 2.0 * c[2]).abs();
    let dc = 4.0 * (2.0 * err / p2.max(f64::MIN_POSITIVE)).sqrt() + 1e-12;
    ((ct - dc).max(-1.0), (ct + dc).min(1.0))
}

/// Eqs. (10) and (14) are unchanged by (alpha, z - rho1) -> (-alpha, rho1 - z): the posture at
/// -alpha is the mirror image of `l`, as exact, and needs no polish.
fn mirror(p: &Vector3<f64>, l: Leg1) -> Leg1 {
    with_wrapped_alpha(Leg1 {
        alpha: -l.alpha,
        rho1: p.z + (p.z - l.rho1),
        sin: -l.sin,
        cos: l.cos,
    })
}

/// A leg-I polish also stops when Newton's next step is predicted below this fraction of
/// [`NEWTON_STEP_STOP`] (relative for rho1): the rounding of the result, so the step left out
/// changes nothing.
const PREDICTED_STEP_FRACTION: f64 = 1e-3;

/// Newton on g1 = u^2 + y^2 + (z - rho1)^2 - K1(alpha) (eq. (10)) and
/// g2 = y (R1 cos a - r1) + R1 sin a (z - rho1) (eq. (14)), unknowns (alpha, rho1), from a
/// posture whose sin and cos are given, until converged (residuals at rounding level, or
/// Newton's last or next step below [`NEWTON_STEP_STOP`]); the best posture met when it runs
/// out of iterations or meets a singular Jacobian. The result carries the sin and cos of its
/// alpha.
#[inline(always)]
fn polish_leg1(g: &ModuleGeometry, p: &Vector3<f64>, start: Leg1) -> Leg1 {
    let eqs = Leg1Equations::new(g, p);
    let amax = |f: [f64; 2]| f[0].abs().max(f[1].abs());
    let mut cur = start;
    let (mut f, mut dz) = eqs.residuals(&cur);
    if eqs.at_rounding(&cur, f, dz) {
        return with_wrapped_alpha(cur);
    }
    let mut best = (cur, amax(f));
    for _ in 0..NEWTON_MAX_ITER {
        if amax(f) == 0.0 {
            break;
        }
        let Some(step) = eqs.newton_step(&cur, f, dz) else {
            break;
        };
        cur = step.leg1;
        if step.settled {
            return with_wrapped_alpha(cur);
        }
        (f, dz) = eqs.residuals(&cur);
        if amax(f) <= best.1 {
            best = (cur, amax(f));
        }
    }
    with_wrapped_alpha(best.0)
}

/// One step of [`Leg1Equations::corrected_step`] or [`Leg1Equations::newton_step`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Leg1Step {
    pub leg1: Leg1,
    /// Converged to rounding (see [`Leg1Equations::corrected_step`]).
    pub settled: bool,
    /// False when the Jacobian was singular, the step not finite, or longer than the series
    /// of sin and cos allow ([`SMALL_ANGLE`]): `leg1` is then meaningless.
    pub usable: bool,
    /// The step's prediction of the error left in (alpha, rho1) (rad, mm): the leading term of
    /// its error, bounded term by term; `settled` compares it with the stopping rule (read
    /// otherwise only by the tests of the prediction). Zero when Newton's step settled on its
    /// own size (no prediction made).
    #[cfg_attr(not(test), allow(dead_code))]
    pub left: [f64; 2],
}

/// Eqs. (10) and (14) of leg I for one point, as g1 = u^2 + y^2 + (z - rho1)^2 - K1(alpha) and
/// g2 = y (R1 cos a - r1) + R1 sin a (z - rho1), unknowns (alpha, rho1).
struct Leg1Equations {
    r: f64,
    rr: f64,
    y: f64,
    z: f64,
    /// u^2 + y^2 - (L1^2 - R1^2 - r1^2).
    uy_k0: f64,
    /// u^2 + y^2 + |L1^2 - R1^2 - r1^2|, for the rounding of g1.
    uy_k0_abs: f64,
}

impl Leg1Equations {
    #[inline]
    fn new(g: &ModuleGeometry, p: &Vector3<f64>) -> Leg1Equations {
        let (r, rr) = (g.r_big1, g.r_small1);
        let u = p.x + g.dx1;
        let k0 = g.l1 * g.l1 - r * r - rr * rr;
        let uy = u * u + p.y * p.y;
        Leg1Equations {
            r,
            rr,
            y: p.y,
            z: p.z,
            uy_k0: uy - k0,
            uy_k0_abs: uy + k0.abs(),
        }
    }

    /// (g1, g2) and z - rho1.
    #[inline]
    fn residuals(&self, l: &Leg1) -> ([f64; 2], f64) {
        let (r, rr, y) = (self.r, self.rr, self.y);
        let dz = self.z - l.rho1;
        let f = [
            self.uy_k0 + dz * dz - 2.0 * r * rr * l.cos,
            y * (r * l.cos - rr) + r * l.sin * dz,
        ];
        (f, dz)
    }

    /// Residuals already at the rounding level of their terms: no step can improve the posture.
    #[inline]
    fn at_rounding(&self, l: &Leg1, f: [f64; 2], dz: f64) -> bool {
        let (r, rr, y) = (self.r, self.rr, self.y);
        let rounding = [
            self.uy_k0_abs + dz * dz + (2.0 * r * rr * l.cos).abs(),
            (y * r * l.cos).abs() + (y * rr).abs() + (r * l.sin * dz).abs(),
        ];
        f[0].abs() <= 4.0 * f64::EPSILON * rounding[0]
            && f[1].abs() <= 4.0 * f64::EPSILON * rounding[1]
    }

    /// The Newton step from `cur` (residuals f, dz = z - rho1), and whether it settles the
    /// posture; None on a singular Jacobian.
    #[inline(always)]
    fn newton_step(&self, cur: &Leg1, f: [f64; 2], dz: f64) -> Option<Leg1Step> {
        let (r, rr, y) = (self.r, self.rr, self.y);
        // Jacobian of (g1, g2) in (alpha, rho1), solved by Cramer's rule.
        let (s, c) = (cur.sin, cur.cos);
        let (j11, j12, j21, j22) = (2.0 * r * rr * s, -2.0 * dz, -y * r * s + r * c * dz, -r * s);
        let det = j11 * j22 - j12 * j21;
        let step = [
            (j22 * f[0] - j12 * f[1]) / det,
            (j11 * f[1] - j21 * f[0]) / det,
        ];
        if det == 0.0 || !(step[0].is_finite() && step[1].is_finite()) {
            return None;
        }
        let alpha = cur.alpha - step[0];
        let (sin, cos) = sin_cos_after_step(cur.sin, cur.cos, alpha, step[0]);
        let next = Leg1 {
            alpha,
            rho1: cur.rho1 - step[1],
            sin,
            cos,
        };
        let rho_stop = NEWTON_STEP_STOP * (1.0 + next.rho1.abs());
        // A step this small came from residuals at rounding level (Newton converges
        // quadratically).
        if step[0].abs() < NEWTON_STEP_STOP && step[1].abs() < rho_stop {
            return Some(Leg1Step {
                leg1: next,
                settled: true,
                usable: true,
                left: [0.0; 2],
            });
        }
        // Otherwise Newton's error after this step is J^-1 times what the linear model missed,
        // (1/2) H[step, step] (H: second derivatives of g1, g2, which are quadratic in rho1 and
        // trigonometric in alpha). Once that is far below the step stop, so is the next step.
        let (da, dr) = (step[0].abs(), step[1].abs());
        let miss1 = (r * rr * c).abs() * da * da + dr * dr;
        let miss2 = 0.5 * (y * r * c + r * s * dz).abs() * da * da + (r * c).abs() * da * dr;
        let next_alpha = j22.abs() * miss1 + j12.abs() * miss2;
        let next_rho1 = j21.abs() * miss1 + j11.abs() * miss2;
        let settled = next_alpha <= PREDICTED_STEP_FRACTION * NEWTON_STEP_STOP * det.abs()
            && next_rho1 <= PREDICTED_STEP_FRACTION * rho_stop * det.abs();
        Some(Leg1Step {
            leg1: next,
            settled,
            usable: true,
            left: [next_alpha / det.abs(), next_rho1 / det.abs()],
        })
    }
}

impl Leg1Equations {
    /// Chebyshev's step from `cur`: Newton's step d = J^-1 g corrected by the curvature of
    /// (g1, g2), J^-1 (g + H[d, d] / 2) (H: their second derivatives), third order where
    /// Newton is second; without a branch, so that [`working_lanes`] can run points side by side.
    /// Settled when the step, or the error it predicts is left, is below [`NEWTON_STEP_STOP`]
    /// (the latter by a factor [`PREDICTED_STEP_FRACTION`]: the rounding of the result).
    #[inline(always)]
    pub(crate) fn corrected_step(&self, cur: &Leg1) -> Leg1Step {
        let (r, rr, y) = (self.r, self.rr, self.y);
        let (f, dz) = self.residuals(cur);
        let (s, c) = (cur.sin, cur.cos);
        // Jacobian of (g1, g2) in (alpha, rho1), solved by Cramer's rule.
        let (j11, j12, j21, j22) = (2.0 * r * rr * s, -2.0 * dz, -y * r * s + r * c * dz, -r * s);
        let det = j11 * j22 - j12 * j21;
        let inv = 1.0 / det;
        let solve = |b: [f64; 2]| {
            [
                (j22 * b[0] - j12 * b[1]) * inv,
                (j11 * b[1] - j21 * b[0]) * inv,
            ]
        };
        let d = solve(f);
        // Second derivatives: g1_aa = 2 R1 r1 cos a, g1_rr = 2; g2_aa = -y R1 cos a - R1 sin a
        // (z - rho1), g2_ar = -R1 cos a.
        let g2_aa = -y * r * c - r * s * dz;
        let step = solve([
            f[0] + r * rr * c * d[0] * d[0] + d[1] * d[1],
            f[1] + 0.5 * g2_aa * d[0] * d[0] - r * c * d[0] * d[1],
        ]);
        let (sd, cd) = sin_cos_small(step[0]);
        let leg1 = Leg1 {
            alpha: cur.alpha - step[0],
            rho1: cur.rho1 - step[1],
            sin: s * cd - c * sd,
            cos: c * cd + s * sd,
        };
        let usable = (step[0].abs() < SMALL_ANGLE) & step[1].is_finite();
        let rho_stop = NEWTON_STEP_STOP * (1.0 + leg1.rho1.abs());
        // What is left is J^-1 (H[d, k] - T[d, d, d] / 6), k = step - d the correction, T the
        // third derivatives (g1_aaa = -2 R1 r1 sin a; g2_aaa = y R1 sin a - R1 cos a (z - rho1),
        // g2_aar = R1 sin a), bounded term by term.
        let (da, dr) = (d[0].abs(), d[1].abs());
        let (ka, kr) = ((step[0] - d[0]).abs(), (step[1] - d[1]).abs());
        let da3 = da * da * da;
        let left1 =
            2.0 * (r * rr * c).abs() * da * ka + 2.0 * dr * kr + (r * rr * s).abs() * da3 / 3.0;
        let left2 = g2_aa.abs() * da * ka
            + (r * c).abs() * (da * kr + dr * ka)
            + ((y * r * s).abs() + (r * c * dz).abs()) * da3 / 6.0
            + 0.5 * (r * s).abs() * da * da * dr;
        let left_alpha = (j22.abs() * left1 + j12.abs() * left2) * inv.abs();
        let left_rho1 = (j21.abs() * left1 + j11.abs() * left2) * inv.abs();
        let small_step = (step[0].abs() < NEWTON_STEP_STOP) & (step[1].abs() < rho_stop);
        let small_left = (left_alpha <= PREDICTED_STEP_FRACTION * NEWTON_STEP_STOP)
            & (left_rho1 <= PREDICTED_STEP_FRACTION * rho_stop);
        Leg1Step {
            leg1,
            settled: small_step | small_left,
            usable,
            left: [left_alpha, left_rho1],
        }
    }
}

/// The posture with alpha in (-pi, pi] (sin and cos recomputed if it moved).
fn with_wrapped_alpha(mut l: Leg1) -> Leg1 {
    let wrapped = wrap_angle(l.alpha);
    if wrapped != l.alpha {
        l.alpha = wrapped;
        (l.sin, l.cos) = wrapped.sin_cos();
    }
    l
}

/// Angle in (-pi, pi].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::PI;
    let tau = std::f64::consts::TAU;
    if a > -PI && a <= PI {
        return a;
    }
    // One turn out (sums and differences of wrapped angles): a -/+ 2 pi is exact there (Sterbenz)
    // and equals the remainder below (but -2 pi gives +0, not -0), without its division loop.
    if a > PI && a <= 3.0 * PI {
        return a - tau;
    }
    if a <= -PI && a > -3.0 * PI {
        return a + tau;
    }
    let mut w = a.rem_euclid(tau);
    if w > PI {
        w -= tau;
    }
    w
}

fn angle_diff(a: f64, b: f64) -> f64 {
    wrap_angle(a - b)
}

/// The square root of eqs. (12)-(13) for one leg, sqrt(L^2 - dx^2 - dy^2); None when the leg
/// cannot reach (the argument below zero beyond rounding).
#[inline]
pub(crate) fn leg_root(l: f64, dx: f64, dy: f64) -> Option<f64> {
    let arg = l * l - dx * dx - dy * dy;
    if arg < -SQRT_ARG_REL * l * l || !arg.is_finite() {
        return None;
    }
    Some(arg.max(0.0).sqrt())
}

/// Every real inverse-kinematics branch of the parallel module for point `p`, ordered by alpha
/// then by (s1, s2, s3), each with its configuration and verdict. Empty when unreachable.
pub fn solve(m: &Machine, p: &Vector3<f64>) -> IkBranches {
    let mut out = IkBranches::new();
    solve_into(m, p, &mut out);
    out
}

/// [`solve`] into an existing list (cleared first), so a caller that keeps one avoids copying it.
pub fn solve_into(m: &Machine, p: &Vector3<f64>, out: &mut IkBranches) {
    if m.has_zeros() {
        solve_into(&m.model(), p, out);
        return joints_of(m, out);
    }
    let ([leg1], [certified]) = certified_lanes(m, &[*p]);
    let certified = certified.then_some(leg1);
    let g = &m.module;
    let roots = other_roots(g, p, certified);
    let mut legs1 = ArrayVec::<Leg1, 6>::new();
    let certificate = leg1_postures_into(g, p, &roots, certified, &mut legs1);
    branches_into(m, p, &legs1, out);
    out.certificate = certificate;
    out.mark_unproved(|b| &mut b.verdict);
}

/// [`solve_into`] for each point of `rows` into its list, [`LANES`] points at a time: the
/// certified root of (9) side by side (`certified_lanes`), then each point's other roots, its
/// postures, its branches, phase by phase (each point alone all the same: the lists are what
/// [`solve_into`] gives). Built with AVX2 where the processor has it ([`crate::math::cpu`]).
pub fn solve_each<'a>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    if m.has_zeros() {
        let mut rows: Vec<_> = rows.into_iter().collect();
        each_in_lanes::<true>(&m.model(), rows.iter_mut().map(|(p, o)| (*p, &mut **o)));
        return rows.into_iter().for_each(|(_, o)| joints_of(m, o));
    }
    each_in_lanes::<true>(m, rows)
}

/// [`solve_each`] built for the x86-64 baseline whatever the processor has: the same lists, bit
/// for bit.
#[doc(hidden)]
pub fn solve_each_baseline<'a>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    if m.has_zeros() {
        let mut rows: Vec<_> = rows.into_iter().collect();
        each_in_lanes_baseline::<true>(&m.model(), rows.iter_mut().map(|(p, o)| (*p, &mut **o)));
        return rows.into_iter().for_each(|(_, o)| joints_of(m, o));
    }
    each_in_lanes_baseline::<true>(m, rows)
}

/// [`solve_working_into`] for each point of `rows` into its list, [`LANES`] points at a time
/// through [`working_lanes`] (each point alone all the same: the lists are what
/// [`solve_working_into`] gives, in the same order). Built with AVX2 where the processor has it
/// ([`crate::math::cpu`]).
pub fn solve_working_each<'a>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    if m.has_zeros() {
        let mut rows: Vec<_> = rows.into_iter().collect();
        each_in_lanes::<false>(&m.model(), rows.iter_mut().map(|(p, o)| (*p, &mut **o)));
        return rows.into_iter().for_each(|(_, o)| joints_of(m, o));
    }
    each_in_lanes::<false>(m, rows)
}

/// [`solve_working_each`] built for the x86-64 baseline whatever the processor has: the same
/// lists, bit for bit.
#[doc(hidden)]
pub fn solve_working_each_baseline<'a>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    if m.has_zeros() {
        let mut rows: Vec<_> = rows.into_iter().collect();
        each_in_lanes_baseline::<false>(&m.model(), rows.iter_mut().map(|(p, o)| (*p, &mut **o)));
        return rows.into_iter().for_each(|(_, o)| joints_of(m, o));
    }
    each_in_lanes_baseline::<false>(m, rows)
}

/// The branches of a point solved on [`Machine::model`] with the sliders as `m`'s joints read
/// them (the equations' rho less the zero offsets): the one place the inverse kinematics
/// leaves the equations' variables.
fn joints_of(m: &Machine, out: &mut IkBranches) {
    for b in out.iter_mut() {
        b.rho = m.joint_sliders(&b.rho);
    }
}

/// [`solve_each`] (`EVERY`) or [`solve_working_each`], built with AVX2 when the processor has it.
fn each_in_lanes<'a, const EVERY: bool>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    #[cfg(target_arch = "x86_64")]
    if cpu::has_avx2() {
        // SAFETY: the processor has AVX2 (checked just above).
        return unsafe { each_in_lanes_avx2::<EVERY>(m, rows) };
    }
    each_in_lanes_baseline::<EVERY>(m, rows)
}

fn each_in_lanes_baseline<'a, const EVERY: bool>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    each_in_lanes_built::<false, EVERY>(m, rows)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn each_in_lanes_avx2<'a, const EVERY: bool>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    each_in_lanes_built::<true, EVERY>(m, rows)
}

/// The body of [`each_in_lanes`], inlined into each build: every branch ([`solve_into`]) when
/// `EVERY`, else what `verne ik` needs ([`solve_working_into`]). `AVX2` only tells the builds
/// apart: each then has its own copy of the closures below (one shared copy would be built for
/// the baseline and called from both).
#[inline(always)]
fn each_in_lanes_built<'a, const AVX2: bool, const EVERY: bool>(
    m: &Machine,
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
) {
    if !EVERY {
        return in_lanes(
            rows,
            |pts, outs| {
                let found = working_lanes(m, pts);
                for (k, out) in outs.enumerate() {
                    // Where the lanes were not sure, the cubic (not the lanes again).
                    let working = found[k].or_else(|| working_by_cubic(m, &pts[k]));
                    working_or_all_into(m, &pts[k], working, out);
                }
            },
            |p, out| solve_working_into(m, p, out),
        );
    }
    in_lanes(
        rows,
        |pts, outs| {
            let (legs, certified) = certified_lanes(m, pts);
            let certified: [Option<Leg1>; LANES] =
                std::array::from_fn(|k| certified[k].then_some(legs[k]));
            let g = &m.module;
            let mut roots: [OtherRoots; LANES] = Default::default();
            for k in 0..LANES {
                roots[k] = other_roots(g, &pts[k], certified[k]);
            }
            let mut postures: [ArrayVec<Leg1, 6>; LANES] = Default::default();
            let mut certificates = [Certificate::Double; LANES];
            for k in 0..LANES {
                certificates[k] =
                    leg1_postures_into(g, &pts[k], &roots[k], certified[k], &mut postures[k]);
            }
            for (k, out) in outs.enumerate() {
                // Four postures (two roots of (9) and their mirror images, as on most points):
                // their labels side by side in the AVX2 build.
                #[cfg(target_arch = "x86_64")]
                if AVX2 {
                    if let Ok(four) = <&[Leg1; 4]>::try_from(postures[k].as_slice()) {
                        // SAFETY: `AVX2` is set only in the build that runs where the
                        // processor has AVX2 (`each_in_lanes`).
                        unsafe { lanes::branches_into(m, &pts[k], four, out) };
                        out.certificate = certificates[k];
                        out.mark_unproved(|b| &mut b.verdict);
                        continue;
                    }
                }
                branches_into(m, &pts[k], &postures[k], out);
                out.certificate = certificates[k];
                out.mark_unproved(|b| &mut b.verdict);
            }
        },
        |p, out| solve_into(m, p, out),
    );
}

/// Groups `rows` by [`LANES`] for `group` (the points and their lists, in order), the last few
/// one by one for `single`.
fn in_lanes<'a>(
    rows: impl IntoIterator<Item = (Vector3<f64>, &'a mut IkBranches)>,
    mut group: impl FnMut(&[Vector3<f64>; LANES], &mut dyn Iterator<Item = &'a mut IkBranches>),
    mut single: impl FnMut(&Vector3<f64>, &mut IkBranches),
) {
    let mut pts = [Vector3::zeros(); LANES];
    let mut outs = ArrayVec::<&'a mut IkBranches, LANES>::new();
    for (p, out) in rows {
        pts[outs.len()] = p;
        outs.push(out);
        if outs.is_full() {
            group(&pts, &mut outs.drain(..));
        }
    }
    for (k, out) in outs.drain(..).enumerate() {
        single(&pts[k], out);
    }
}

/// Every branch on the leg-I postures `legs1` of `p` into `out` (cleared first), ordered and
/// labelled as [`solve`] gives them.
#[inline(always)]
fn branches_into(m: &Machine, p: &Vector3<f64>, legs1: &ArrayVec<Leg1, 6>, out: &mut IkBranches) {
    out.reset();
    if !p.iter().all(|v| v.is_finite()) {
        return;
    }
    let cos_tilt = cos_tilt_max(m);
    // Leg I's label per posture; legs II and III once per cos(alpha): a posture and its mirror
    // image (next to each other in `legs1`) share them.
    let mut checks = [(0i8, Verdict::default()); 6];
    let mut outer = [None; 6];
    for (k, l) in legs1.iter().enumerate() {
        checks[k] = leg_state(m, 0, p, l.sin, l.cos, l.rho1, cos_tilt).check();
        outer[k] = if k > 0 && l.cos == legs1[k - 1].cos {
            outer[k - 1]
        } else {
            outer_legs(m, p, l.cos, cos_tilt)
        };
    }
    let s1: [i8; 6] = std::array::from_fn(|k| checks[k].0);
    let (order, n) = posture_order(legs1, &s1);
    for &k in &order[..n] {
        if let Some(o) = &outer[k] {
            let pushed = push_distinct(out, four_branches(m, p, &legs1[k], checks[k], o));
            debug_assert!(pushed, "six postures of four branches fit MAX_IK_BRANCHES");
        }
    }
}

/// Legs II and III at a leg-I posture as far as they depend on its cos(alpha) alone (a posture
/// and its mirror image share them): the square roots of eqs. (12)-(13) and each root's label
/// and verdict but the stroke.
#[derive(Debug, Clone, Copy)]
struct OuterLegs {
    /// sqrt(L2^2 - (xp + D2 - d2)^2 - (yp - R2 cos a + r4)^2) and its eq. (13) counterpart.
    h: [f64; 2],
    /// [leg II, leg III][lower root, upper root].
    labels: [[(i8, Verdict); 2]; 2],
}

/// [`OuterLegs`] of `p` at cos(alpha) = `c`; None when leg II or III cannot reach.
#[inline(always)]
fn outer_legs(m: &Machine, p: &Vector3<f64>, c: f64, cos_tilt: f64) -> Option<OuterLegs> {
    let g = &m.module;
    let dx2 = p.x + g.dx2;
    // eq. (12): rho2 = zp - R2 sin a + s2 sqrt(L2^2 - (xp + D2 - d2)^2 - (yp - R2 cos a + r4)^2)
    let dy2 = p.y - g.r_big2 * c + g.r4;
    let h2 = leg_root(g.l2, dx2, dy2)?;
    // eq. (13): rho3 = zp + R2 sin a + s3 sqrt(L3^2 - (xp + D2 - d2)^2 - (yp + R2 cos a - r4)^2)
    let dy3 = p.y + g.r_big2 * c - g.r4;
    let h3 = leg_root(g.l3, dx2, dy3)?;
    Some(OuterLegs {
        h: [h2, h3],
        labels: [
            outer_leg_labels(1, (dx2, dy2, h2), cos_tilt),
            outer_leg_labels(2, (dx2, dy3, h3), cos_tilt),
        ],
    })
}

/// The four branches of `p` on the leg-I posture `leg1` (s2, s3 = -1 before +1: the roots of
/// (12)-(13) in increasing order), labelled. `l1` is leg I's label and verdict at the posture,
/// `outer` the posture's [`outer_legs`].
#[inline(always)]
fn four_branches(
    m: &Machine,
    p: &Vector3<f64>,
    leg1: &Leg1,
    l1: (i8, Verdict),
    outer: &OuterLegs,
) -> [IkBranch; 4] {
    let g = &m.module;
    let (off2, off3) = (p.z - g.r_big2 * leg1.sin, p.z + g.r_big2 * leg1.sin);
    let [h2, h3] = outer.h;
    let (r2, r3) = ([off2 - h2, off2 + h2], [off3 - h3, off3 + h3]);
    let leg = |i: usize, rho: [f64; 2]| {
        let [a, b] = outer.labels[i - 1];
        [
            (a.0, a.1.with(stroke_verdict(m, i, rho[0]))),
            (b.0, b.1.with(stroke_verdict(m, i, rho[1]))),
        ]
    };
    let (l2, l3) = (leg(1, r2), leg(2, r3));
    let v1 = l1.1.with(rods_cross(m, leg1.cos));
    let branch = |k2: usize, k3: usize| IkBranch {
        alpha: leg1.alpha,
        rho: Sliders::new(leg1.rho1, r2[k2], r3[k3]),
        config: [l1.0, l2[k2].0, l3[k3].0],
        verdict: v1.with(l2[k2].1).with(l3[k3].1),
    };
    [branch(0, 0), branch(0, 1), branch(1, 0), branch(1, 1)]
}

/// The four branches of `p` on the leg-I posture `leg1` ([`four_branches`]); None when leg II or
/// III cannot reach. `l1` is leg I's label and verdict at the posture, `cos_tilt`
/// [`cos_tilt_max`].
#[inline(always)]
pub(crate) fn posture_branches(
    m: &Machine,
    p: &Vector3<f64>,
    leg1: &Leg1,
    l1: (i8, Verdict),
    cos_tilt: f64,
) -> Option<[IkBranch; 4]> {
    let outer = outer_legs(m, p, leg1.cos, cos_tilt)?;
    Some(four_branches(m, p, leg1, l1, &outer))
}

/// How far (mm) a configuration sign or a square root must be from zero, and (rad) two candidate
/// angles from each other, for [`working_fast`] to decide alone; closer calls go to [`solve`].
pub(crate) const FAST_MARGIN_MM: f64 = 1e-6;
pub(crate) const FAST_MARGIN_RAD: f64 = 1e-6;

/// The working branch alone, without building the others, when the decision is clear-cut; None
/// when unsure or when there is no feasible branch (the caller then runs [`solve`], which also
/// says why). First [`working_lanes`] for this one point (the certified posture, no cubic);
/// otherwise only what can be feasible is built: a feasible branch has s = (-1, -1, -1) and
/// R1 cos(alpha) > r1 (see [`crate::parallel_module::branches`]), so only the roots of eq. (9) with
/// cos(alpha) > r1/R1 are kept, with the sign of alpha that makes s1 = -1 in eq. (14) and the
/// lower roots of (12)-(13). Every step is the one [`solve`] takes for that branch; the margins
/// send every near-tie of a sign, a square root, alpha = 0 or two candidates to [`solve`].
pub fn working_fast(m: &Machine, p: &Vector3<f64>) -> Option<IkBranch> {
    if m.has_zeros() {
        return working_fast(&m.model(), p).map(|b| IkBranch {
            rho: m.joint_sliders(&b.rho),
            ..b
        });
    }
    match working_lanes(m, &[*p]) {
        [Some(branch)] => Some(branch),
        _ => working_by_cubic(m, p),
    }
}

/// The second half of [`working_fast`], for a point [`working_lanes`] was not sure of: the roots
/// of the cubic (9) above r1/R1, each polished, with the same margins.
fn working_by_cubic(m: &Machine, p: &Vector3<f64>) -> Option<IkBranch> {
    let g = &m.module;
    let coeffs = cubic_eq9(g, p)?; // None for a point that is not finite
    let (r, rr) = (g.r_big1, g.r_small1);
    let lo = (rr / r - FAST_MARGIN_RAD).max(-1.0);
    let cos_tilt = cos_tilt_max(m);
    let mut best: Option<IkBranch> = None;
    let mut last_alpha: Option<f64> = None;
    for root in cubic_roots_in(&coeffs, lo, 1.0) {
        let c = root.x.clamp(-1.0, 1.0);
        let sin_a = ((1.0 - c) * (1.0 + c)).sqrt();
        let h2 = leg1_height_sq(g, p, c);
        if root.touching || sin_a < FAST_MARGIN_RAD || h2.abs() < FAST_MARGIN_MM * FAST_MARGIN_MM {
            return None;
        }
        if h2 < 0.0 {
            continue;
        }
        // eq. (14): rho1 - zp = y (R1 cos a - r1) / (R1 sin a); s1 = -1 takes alpha of the sign
        // opposite to y (R1 cos a - r1). Near zero both signs could be s1 = -1.
        // h >= FAST_MARGIN_MM already: h2 passed the test above, and sqrt(1e-12) is 1e-6.
        let yw = p.y * (r * c - rr);
        let h = h2.sqrt();
        if (yw / (r * sin_a)).abs() < FAST_MARGIN_MM {
            return None;
        }
        let a = c.acos();
        let (alpha, sin) = if yw > 0.0 { (-a, -sin_a) } else { (a, sin_a) };
        if last_alpha.is_some_and(|l| (l - alpha).abs() < FAST_MARGIN_RAD) {
            return None;
        }
        last_alpha = Some(alpha);
        let leg1 = polish_leg1(
            g,
            p,
            Leg1 {
                alpha,
                rho1: p.z - h,
                sin,
                cos: c,
            },
        );
        let Ok(found) = working_on_posture(m, p, &leg1, cos_tilt) else {
            return None;
        };
        let Some(branch) = found else {
            continue;
        };
        match best {
            Some(b) if (b.alpha.abs() - branch.alpha.abs()).abs() < FAST_MARGIN_RAD => return None,
            Some(b) if b.alpha.abs() < branch.alpha.abs() => {}
            _ => best = Some(branch),
        }
    }
    best
}

/// The branch on a leg-I posture (s1 = -1) with the lower roots of eqs. (12)-(13) (s2 = s3 = -1)
/// when it is feasible: Ok(Some); Ok(None) when it is not feasible or a leg cannot reach; Err
/// when a square root of (12)-(13) is within [`FAST_MARGIN_MM`] of zero (the labels of the two
/// roots are then a close call for [`solve`]).
pub(crate) fn working_on_posture(
    m: &Machine,
    p: &Vector3<f64>,
    leg1: &Leg1,
    cos_tilt: f64,
) -> Result<Option<IkBranch>, ()> {
    let lower = lower_branch(m, p, leg1, cos_tilt);
    if lower.close_call {
        return Err(());
    }
    Ok(lower.feasible.then_some(lower.branch))
}

/// What [`lower_branch`] finds.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LowerBranch {
    /// The branch s = (-1, -1, -1), labelled as working (only meaningful when `feasible`).
    pub branch: IkBranch,
    /// Legs II and III reach; every leg as on the machine and inside its limits; rods of leg I
    /// not crossing (what [`crate::parallel_module::branches::combine`] of the legs' verdicts says, without
    /// building it).
    pub feasible: bool,
    /// A square root of (12)-(13) within [`FAST_MARGIN_MM`] of zero.
    pub close_call: bool,
}

/// The branch on a leg-I posture with the lower roots of eqs. (12)-(13), each leg's state as
/// [`solve`] has it, without a branch (for [`working_lanes`]).
#[inline(always)]
pub(crate) fn lower_branch(
    m: &Machine,
    p: &Vector3<f64>,
    leg1: &Leg1,
    cos_tilt: f64,
) -> LowerBranch {
    let g = &m.module;
    let (s, c) = (leg1.sin, leg1.cos);
    let dx2 = p.x + g.dx2;
    // The lower root of (12) or (13) (s = -1), whether its leg reaches and is fine there, and
    // whether the square root is a close call; as [`leg_root`] and [`solve`] have them.
    let lower = |leg: usize, l: f64, dy: f64, offset: f64| {
        let arg = l * l - dx2 * dx2 - dy * dy;
        let reaches = (arg >= -SQRT_ARG_REL * l * l) & arg.is_finite();
        let h = arg.max(0.0).sqrt();
        let close = (reaches & (h <= FAST_MARGIN_MM)) | (!reaches & (arg > -FAST_MARGIN_MM * l));
        let rho = [offset - h, offset + h];
        let state = outer_leg_states(m, leg, (dx2, dy, h), rho, cos_tilt)[0];
        (rho[0], reaches & state.ok(), close)
    };
    // eq. (12): rho2 = zp - R2 sin a - sqrt(L2^2 - (xp + D2 - d2)^2 - (yp - R2 cos a + r4)^2)
    let (rho2, ok2, close2) = lower(1, g.l2, p.y - g.r_big2 * c + g.r4, p.z - g.r_big2 * s);
    // eq. (13): rho3 = zp + R2 sin a - sqrt(L3^2 - (xp + D2 - d2)^2 - (yp + R2 cos a - r4)^2)
    let (rho3, ok3, close3) = lower(2, g.l3, p.y + g.r_big2 * c - g.r4, p.z + g.r_big2 * s);
    let feasible = ok2
        & ok3
        & leg_state(m, 0, p, s, c, leg1.rho1, cos_tilt).ok()
        & (g.r_big1 * c > g.r_small1);
    LowerBranch {
        branch: IkBranch {
            alpha: leg1.alpha,
            rho: Sliders::new(leg1.rho1, rho2, rho3),
            config: WORKING_CONFIG,
            verdict: Verdict::default(),
        },
        feasible,
        close_call: close2 | close3,
    }
}

/// A leg-I posture clear of the fast path's margins: R1 cos(alpha) > r1, away from alpha = 0
/// (where the two postures of a root meet) and with s1 = -1.
#[inline(always)]
pub(crate) fn clear_of_margins(g: &ModuleGeometry, p: &Vector3<f64>, l: &Leg1) -> bool {
    (g.r_big1 * l.cos - g.r_small1 > FAST_MARGIN_MM)
        & (l.sin.abs() > FAST_MARGIN_RAD)
        & (l.rho1 - p.z < -FAST_MARGIN_MM)
}

/// Points [`working_lanes`] runs side by side.
pub const LANES: usize = 4;

/// The working branch of each of N points, each alone (no continuity between them), when
/// [`working_fast`]'s certified shortcut gives it: the posture of `certified_lanes` with the
/// lower roots of (12)-(13), feasible and clear of the margins; None for a point where it does
/// not (the caller then runs [`solve_working_into`] for it, which says why). The points run in
/// lockstep and without a branch, so the processor overlaps their dependency chains (a square
/// root and a division for the start, a division and the sin/cos series for the step, two
/// square roots for (12)-(13)).
#[inline(always)]
pub fn working_lanes<const N: usize>(
    m: &Machine,
    pts: &[Vector3<f64>; N],
) -> [Option<IkBranch>; N] {
    if m.has_zeros() {
        return working_lanes(&m.model(), pts).map(|b| {
            b.map(|b| IkBranch {
                rho: m.joint_sliders(&b.rho),
                ..b
            })
        });
    }
    let ct = cos_tilt_max(m);
    let (legs, mut sure) = certified_lanes(m, pts);
    let mut out = [None; N];
    for k in 0..N {
        let lower = lower_branch(m, &pts[k], &legs[k], ct);
        sure[k] &= lower.feasible & !lower.close_call;
        out[k] = sure[k].then_some(lower.branch);
    }
    out
}

/// For each of N points, the leg-I posture with s1 = -1 on the only root of the cubic (9) with
/// R1 cos(alpha) > r1, with true when it is certified (see the section on the certificate
/// below): Chebyshev steps on leg I from [`estimated_start`] until one settles, at most
/// [`LEG1_MAX_STEPS`], the posture clear of the fast path's margins and the root alone on
/// [r1/R1, 1]. The points run side by side, phase by phase, in plain loops (the closures of
/// `array::from_fn` are not always inlined, which would serialise the points again).
#[inline(always)]
fn certified_lanes<const N: usize>(m: &Machine, pts: &[Vector3<f64>; N]) -> ([Leg1; N], [bool; N]) {
    let g = &m.module;
    let mut sure = [false; N];
    let mut legs = [Leg1 {
        alpha: 0.0,
        rho1: 0.0,
        sin: 0.0,
        cos: 1.0,
    }; N];
    for k in 0..N {
        let p = &pts[k];
        let (start, usable) = estimated_start(g, p);
        sure[k] = p.x.is_finite() & p.y.is_finite() & p.z.is_finite() & usable;
        legs[k] = start;
    }
    // Chebyshev steps until every point has settled: one almost always near alpha = 0 (all
    // points side by side, without a branch), two towards |alpha| = 0.2 (then only the points
    // that need them). |alpha| stays below 0.24 + 6 x 0.25 < pi: no wrapping.
    let mut settled = [false; N];
    for k in 0..N {
        let step = Leg1Equations::new(g, &pts[k]).corrected_step(&legs[k]);
        legs[k] = step.leg1;
        sure[k] &= step.usable;
        settled[k] = step.settled;
    }
    for k in 0..N {
        for _ in 1..LEG1_MAX_STEPS {
            if settled[k] | !sure[k] {
                break;
            }
            let step = Leg1Equations::new(g, &pts[k]).corrected_step(&legs[k]);
            legs[k] = step.leg1;
            sure[k] &= step.usable;
            settled[k] = step.settled;
        }
    }
    for k in 0..N {
        sure[k] &=
            settled[k] & clear_of_margins(g, &pts[k], &legs[k]) & isolated_working_root(m, &pts[k]);
    }
    (legs, sure)
}

/// A leg-I start near the posture with s1 = -1 on the root of (9) nearest cos(alpha) = 1,
/// estimated without root isolation: eq. (14) about alpha = 0 with z - rho1 = h(alpha) from eq.
/// (11), h(alpha)^2 = h0^2 - 2 R1 r1 (1 - cos alpha), to third order in alpha:
///   R1 h0 a + y (R1 - r1) - y R1 a^2 / 2 - R1 (h0 / 6 + R1 r1 / (2 h0)) a^3 = 0,
/// solved by one correction of the first-order root a1 = -y (R1 - r1) / (R1 h0). Not usable
/// (false) where y is near 0 (alpha = 0 is then a root and both its postures meet) or leg I
/// cannot reach at alpha = 0. Without a branch, for [`working_lanes`].
#[inline(always)]
fn estimated_start(g: &ModuleGeometry, p: &Vector3<f64>) -> (Leg1, bool) {
    let (r, rr) = (g.r_big1, g.r_small1);
    let h0_sq = leg1_height_sq(g, p, 1.0);
    let usable = (p.y.abs() >= FAST_MARGIN_MM) & (h0_sq > 0.0);
    let inv_h0 = 1.0 / h0_sq.sqrt();
    let a1 = -p.y * (r - rr) / r * inv_h0;
    let cubic = h0_sq * (1.0 / 6.0) + 0.5 * r * rr;
    // Inside the range of the sin/cos series (a NaN stays NaN and fails the first step).
    let alpha = (a1 + a1 * a1 * (0.5 * p.y + a1 * cubic * inv_h0) * inv_h0).clamp(-0.24, 0.24);
    let (sin, cos) = sin_cos_small(alpha);
    // h(alpha) ~ h0 - R1 r1 (1 - cos alpha) / h0.
    let start = Leg1 {
        alpha,
        rho1: p.z - (h0_sq - r * rr * (1.0 - cos)) * inv_h0,
        sin,
        cos,
    };
    (start, usable)
}

/// What `verne ik` needs for one point: the working branch alone when [`working_fast`] is sure
/// of it, every branch otherwise; [`working`] of the result is the working branch either way.
pub fn solve_working_into(m: &Machine, p: &Vector3<f64>, out: &mut IkBranches) {
    if m.has_zeros() {
        solve_working_into(&m.model(), p, out);
        return joints_of(m, out);
    }
    working_or_all_into(m, p, working_fast(m, p), out);
}

/// `working` alone into `out` when there is one, else every branch of `p` ([`solve_into`]).
fn working_or_all_into(
    m: &Machine,
    p: &Vector3<f64>,
    working: Option<IkBranch>,
    out: &mut IkBranches,
) {
    match working {
        Some(b) => {
            out.reset();
            out.push(b);
        }
        None => solve_into(m, p, out),
    }
}

/// The machine's branch: the unique feasible one. Two roots of eq. (9) with feasible branches
/// would both need the leg-I rods within 90 degrees of +z, which makes the cubic increase through each of
/// them, and two such roots in (r1/R1, 1) force a third (proof and check in
/// `at_most_one_root_of_eq9_carries_a_feasible_branch`); only the rod-tilt limit's slack leaves a
/// thin set on a near-parallelogram leg I open, and there the one with the smallest |alpha|.
pub fn working(branches: &[IkBranch]) -> Option<&IkBranch> {
    branches
        .iter()
        .filter(|b| b.working())
        .min_by(|a, b| a.alpha.abs().total_cmp(&b.alpha.abs()))
}

// ------------------------------------------------------- the certificate of the working root

// The working branch alone rests on this: every feasible branch has R1 cos(alpha) > r1 and
// s1 = -1 (see [`crate::parallel_module::branches`]), and one root of (9) carries exactly one posture with
// s1 = -1 (eq. (14) fixes the sign of alpha). So when the cubic (9) is certified to have one
// root with R1 cos(alpha) > r1 (its derivative keeps one sign on [r1/R1, 1]: it is a parabola,
// so its values at the ends and at its vertex decide), the working branch, if the point has
// one, stands on the posture of that root with s1 = -1, with the lower roots of (12) and (13),
// and Chebyshev steps on leg I from a good start find that posture without isolating
// the cubic's roots.

/// How far (relative to the cubic's largest coefficient) its derivative must stay from zero on
/// [r1/R1, 1] for the root there to count as isolated.
const MONOTONE_MARGIN: f64 = 1e-9;

/// Chebyshev steps allowed to settle leg I from [`estimated_start`]: one almost always; more
/// means the start was poor and the cubic answers.
const LEG1_MAX_STEPS: usize = 6;

/// True when the cubic (9) of `p` has at most one root with cos(alpha) in [r1/R1, 1] (slightly
/// widened), certified by the sign of its derivative, which is a parabola opening upwards (the
/// leading coefficient 2 R1^3 r1 is positive): negative at both ends means negative between;
/// positive at both ends and at the vertex (when inside) means positive throughout.
#[inline(always)]
pub(crate) fn isolated_working_root(m: &Machine, p: &Vector3<f64>) -> bool {
    let g = &m.module;
    // The coefficients of (9) as cubic_eq9 has them, without its normalisation (no division):
    // the margin is taken relative to the largest.
    let [c0, c1, c2, c3] = eq9_coefficients(g, p);
    // Plain comparisons (no NaN handling of f64::max): a NaN coefficient fails every test below.
    let larger = |a: f64, b: f64| if a > b { a } else { b };
    let largest = larger(larger(c0.abs(), c1.abs()), larger(c2.abs(), c3.abs()));
    let margin = MONOTONE_MARGIN * largest;
    let lo = (g.r_small1 / g.r_big1 - FAST_MARGIN_RAD).max(-1.0);
    let d = |x: f64| (3.0 * c3 * x + 2.0 * c2) * x + c1;
    let (d_lo, d_hi) = (d(lo), d(1.0));
    // Vertex x_v = -c2 / (3 c3), where the derivative is c1 - c2^2 / (3 c3); c3 > 0.
    let vertex_inside = (-c2 > 3.0 * c3 * lo) & (-c2 < 3.0 * c3);
    let decreasing = (d_lo < -margin) & (d_hi < -margin);
    let increasing = (d_lo > margin)
        & (d_hi > margin)
        & (!vertex_inside | (3.0 * c3 * c1 - c2 * c2 > 3.0 * c3 * margin));
    // Without a branch (for working_lanes); a NaN fails every comparison.
    (c3 > margin) & margin.is_finite() & (decreasing | increasing)
}

#[cfg(test)]
mod tests;
