//! Inverse kinematics of the parallel module (IFToMM 2007, section V): for a point P, every real
//! (alpha, rho1, rho2, rho3).
//!
//! alpha comes from the cubic in cos(alpha) of eq. (9), rho1 from eq. (14) (both signs of eq. (11)
//! where sin(alpha) = 0, Table II), rho2 and rho3 from eqs. (12)-(13) with both signs.

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::branches::{Config, Verdict, combine, cos_tilt_max, leg_check};
use crate::cubic::cubic_roots_in;
use crate::machine::{Machine, ModuleGeometry};
use crate::module_geometry::Sliders;
use crate::tolerance::{
    NEWTON_MAX_ITER, NEWTON_STEP_STOP, SAME_SOLUTION_RAD, SIN_ALPHA_ZERO, SQRT_ARG_REL,
};
use crate::trig::sin_cos_after_step;

/// Most branches one point can have: three roots of eq. (9), two alphas each, two rho2, two rho3.
pub const MAX_IK_BRANCHES: usize = 24;

/// One inverse-kinematics branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkBranch {
    pub alpha: f64,
    pub rho: Sliders,
    pub config: Config,
    pub verdict: Verdict,
}

impl IkBranch {
    pub fn working(&self) -> bool {
        self.verdict.feasible()
    }
}

pub type IkBranches = ArrayVec<IkBranch, MAX_IK_BRANCHES>;

/// A leg-I posture: an orientation alpha and the slider-1 position that goes with it.
#[derive(Debug, Clone, Copy)]
struct Leg1 {
    alpha: f64,
    rho1: f64,
    sin: f64,
    cos: f64,
}

/// The cubic eq. (9) in cos(alpha) for the point, normalised, lowest degree first; None when it
/// is degenerate (every coefficient zero or not finite).
pub fn cubic_eq9(g: &ModuleGeometry, p: &Vector3<f64>) -> Option<[f64; 4]> {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let y = p.y;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    // eq. (9): p1 c^3 + p2 c^2 + p3 c + p4 = 0.
    let p1 = 2.0 * r * r * r * rr;
    let p2 = r * r * k0 - r * r * u * u;
    let p3 = -2.0 * r * r * r * rr - 2.0 * r * rr * y * y;
    let p4 = r * r * u * u + (r * r + rr * rr) * y * y - r * r * k0;
    let scale = p1.abs().max(p2.abs()).max(p3.abs()).max(p4.abs());
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    Some([p4 / scale, p3 / scale, p2 / scale, p1 / scale])
}

/// |rho1 - zp| from eq. (11) at cos(alpha) = c, squared (negative when leg I cannot reach).
fn leg1_height_sq(g: &ModuleGeometry, p: &Vector3<f64>, c: f64) -> f64 {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let k1 = g.l1 * g.l1 - r * r - rr * rr + 2.0 * r * rr * c;
    k1 - u * u - p.y * p.y
}

/// Every real leg-I posture (alpha, rho1) for the point: eqs. (9), (11), (14), polished by Newton
/// on eqs. (10) and (14) (the half-sum and half-difference of (3) and (4)).
fn leg1_postures(g: &ModuleGeometry, p: &Vector3<f64>) -> ArrayVec<Leg1, 6> {
    let (r, rr) = (g.r_big1, g.r_small1);
    let y = p.y;
    let mut out = ArrayVec::new();
    let Some(coeffs) = cubic_eq9(g, p) else {
        return out;
    };
    for root in cubic_roots_in(&coeffs, -1.0, 1.0) {
        let c = root.x.clamp(-1.0, 1.0);
        let a = c.acos();
        let sin_a = ((1.0 - c) * (1.0 + c)).sqrt();
        let h2 = leg1_height_sq(g, p, c);
        let h = if h2 >= -SQRT_ARG_REL * g.l1 * g.l1 {
            h2.max(0.0).sqrt()
        } else {
            continue;
        };
        let candidates: ArrayVec<Leg1, 4> = if sin_a < SIN_ALPHA_ZERO {
            // alpha in {0, pi}: eq. (14) is 0 = 0, both signs of eq. (11) (Table II).
            let a0 = if c > 0.0 { 0.0 } else { std::f64::consts::PI };
            let (sin, cos) = a0.sin_cos();
            [p.z + h, p.z - h]
                .into_iter()
                .map(|rho1| Leg1 {
                    alpha: a0,
                    rho1,
                    sin,
                    cos,
                })
                .collect()
        } else {
            // sgn(rho1 - zp) from eq. (14): y (R1 cos a - r1) = R1 sin a (rho1 - zp).
            let w = r * c - rr;
            [(a, sin_a), (-a, -sin_a)]
                .into_iter()
                .map(|(alpha, sin)| {
                    let q = y * w / (r * sin);
                    let rho1 = if q == 0.0 { p.z } else { p.z + q.signum() * h };
                    Leg1 {
                        alpha,
                        rho1,
                        sin,
                        cos: c,
                    }
                })
                .collect()
        };
        for cand in candidates {
            let polished = polish_leg1(g, p, cand);
            let dup = out.iter().any(|o: &Leg1| {
                (o.rho1 - polished.rho1).abs() < 1e-7
                    && angle_diff(o.alpha, polished.alpha).abs() < SAME_SOLUTION_RAD
            });
            if !dup && !out.is_full() {
                out.push(polished);
            }
        }
    }
    out
}

/// Newton on g1 = u^2 + y^2 + (z - rho1)^2 - K1(alpha) (eq. (10)) and
/// g2 = y (R1 cos a - r1) + R1 sin a (z - rho1) (eq. (14)), unknowns (alpha, rho1), from a
/// posture whose sin and cos are given; the result carries the sin and cos of its alpha.
fn polish_leg1(g: &ModuleGeometry, p: &Vector3<f64>, start: Leg1) -> Leg1 {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let y = p.y;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    let residuals = |l: &Leg1| {
        let dz = p.z - l.rho1;
        let f = [
            u * u + y * y + dz * dz - k0 - 2.0 * r * rr * l.cos,
            y * (r * l.cos - rr) + r * l.sin * dz,
        ];
        (f, dz)
    };
    let amax = |f: [f64; 2]| f[0].abs().max(f[1].abs());
    let mut cur = start;
    let (mut f, mut dz) = residuals(&cur);
    // Residuals already at the rounding level of their terms: no step can improve the start.
    let rounding = [
        u * u + y * y + dz * dz + k0.abs() + (2.0 * r * rr * cur.cos).abs(),
        (y * r * cur.cos).abs() + (y * rr).abs() + (r * cur.sin * dz).abs(),
    ];
    if f[0].abs() <= 4.0 * f64::EPSILON * rounding[0]
        && f[1].abs() <= 4.0 * f64::EPSILON * rounding[1]
    {
        return with_wrapped_alpha(cur);
    }
    let mut best = (cur, amax(f));
    for _ in 0..NEWTON_MAX_ITER {
        if amax(f) == 0.0 {
            break;
        }
        // Jacobian of (g1, g2) in (alpha, rho1), solved by Cramer's rule.
        let (s, c) = (cur.sin, cur.cos);
        let (j11, j12, j21, j22) = (2.0 * r * rr * s, -2.0 * dz, -y * r * s + r * c * dz, -r * s);
        let det = j11 * j22 - j12 * j21;
        let step = [
            (j22 * f[0] - j12 * f[1]) / det,
            (j11 * f[1] - j21 * f[0]) / det,
        ];
        if det == 0.0 || !step.iter().all(|v| v.is_finite()) {
            break;
        }
        let alpha = cur.alpha - step[0];
        let (sin, cos) = sin_cos_after_step(cur.sin, cur.cos, alpha, step[0]);
        cur = Leg1 {
            alpha,
            rho1: cur.rho1 - step[1],
            sin,
            cos,
        };
        (f, dz) = residuals(&cur);
        if amax(f) <= best.1 {
            best = (cur, amax(f));
        }
        if step[0].abs() < NEWTON_STEP_STOP
            && step[1].abs() < NEWTON_STEP_STOP * (1.0 + cur.rho1.abs())
        {
            break;
        }
    }
    with_wrapped_alpha(best.0)
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
    if a > -std::f64::consts::PI && a <= std::f64::consts::PI {
        return a;
    }
    let tau = std::f64::consts::TAU;
    let mut w = a.rem_euclid(tau);
    if w > std::f64::consts::PI {
        w -= tau;
    }
    w
}

fn angle_diff(a: f64, b: f64) -> f64 {
    wrap_angle(a - b)
}

/// Both roots of eqs. (12)-(13) for one leg: `offset + s * sqrt(L^2 - dx^2 - dy^2)`, s = -1 first.
pub(crate) fn leg_sliders(l: f64, dx: f64, dy: f64, offset: f64) -> Option<[f64; 2]> {
    let arg = l * l - dx * dx - dy * dy;
    if arg < -SQRT_ARG_REL * l * l || !arg.is_finite() {
        return None;
    }
    let h = arg.max(0.0).sqrt();
    Some([offset - h, offset + h])
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
    let g = &m.module;
    out.clear();
    if !p.iter().all(|v| v.is_finite()) {
        return;
    }
    let cos_tilt = cos_tilt_max(m);
    // Branches come out ordered by alpha, then (s1, s2, s3): postures sorted by (alpha, s1), and
    // within a posture s2, s3 = -1 before +1 (the roots of (12)-(13) in increasing order).
    let mut postures: ArrayVec<(Leg1, f64, f64, (i8, Verdict)), 6> = leg1_postures(g, p)
        .into_iter()
        .map(|l| {
            let (s, c) = (l.sin, l.cos);
            (l, s, c, leg_check(m, 0, p, s, c, l.rho1, cos_tilt))
        })
        .collect();
    postures.sort_unstable_by(|a, b| a.0.alpha.total_cmp(&b.0.alpha).then(a.3.0.cmp(&b.3.0)));
    for (leg1, s, c, l1) in postures {
        let dx2 = p.x + g.dx2;
        // eq. (12): rho2 = zp - R2 sin a + s2 sqrt(L2^2 - (xp + D2 - d2)^2 - (yp - R2 cos a + r4)^2)
        let Some(r2) = leg_sliders(g.l2, dx2, p.y - g.r_big2 * c + g.r4, p.z - g.r_big2 * s) else {
            continue;
        };
        // eq. (13): rho3 = zp + R2 sin a + s3 sqrt(L3^2 - (xp + D2 - d2)^2 - (yp + R2 cos a - r4)^2)
        let Some(r3) = leg_sliders(g.l3, dx2, p.y + g.r_big2 * c - g.r4, p.z + g.r_big2 * s) else {
            continue;
        };
        // Labels and verdicts leg by leg: leg I once per posture, legs II and III once per root.
        let leg = |i: usize, rho_i: f64| leg_check(m, i, p, s, c, rho_i, cos_tilt);
        let l2 = [leg(1, r2[0]), leg(1, r2[1])];
        let l3 = [leg(2, r3[0]), leg(2, r3[1])];
        for (k2, rho2) in r2.into_iter().enumerate() {
            for (k3, rho3) in r3.into_iter().enumerate() {
                out.push(IkBranch {
                    alpha: leg1.alpha,
                    rho: Sliders::new(leg1.rho1, rho2, rho3),
                    config: [l1.0, l2[k2].0, l3[k3].0],
                    verdict: combine(m, c, [l1.1, l2[k2].1, l3[k3].1]),
                });
            }
        }
    }
}

/// How far (mm) a configuration sign or a square root must be from zero, and (rad) two candidate
/// angles from each other, for [`working_fast`] to decide alone; closer calls go to [`solve`].
const FAST_MARGIN_MM: f64 = 1e-6;
const FAST_MARGIN_RAD: f64 = 1e-6;

/// The working branch alone, without building the others, when the decision is clear-cut; None
/// when unsure or when there is no feasible branch (the caller then runs [`solve`], which also
/// says why). Only what can be feasible is built: a feasible branch has s = (-1, -1, -1) and
/// R1 cos(alpha) > r1 (see [`crate::branches`]), so only the roots of eq. (9) with
/// cos(alpha) > r1/R1 are kept, with the sign of alpha that makes s1 = -1 in eq. (14) and the
/// lower roots of (12)-(13). Every step is the one [`solve`] takes for that branch; the margins
/// send every near-tie of a sign, a square root, alpha = 0 or two candidates to [`solve`].
pub fn working_fast(m: &Machine, p: &Vector3<f64>) -> Option<IkBranch> {
    let g = &m.module;
    if !p.iter().all(|v| v.is_finite()) {
        return None;
    }
    let coeffs = cubic_eq9(g, p)?;
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
        let yw = p.y * (r * c - rr);
        let h = h2.sqrt();
        if (yw / (r * sin_a)).abs() < FAST_MARGIN_MM || h < FAST_MARGIN_MM {
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
        let (s, c) = (leg1.sin, leg1.cos);
        let dx2 = p.x + g.dx2;
        let lower = |l: f64, dy: f64, offset: f64| match leg_sliders(l, dx2, dy, offset) {
            Some([lo, hi]) if hi - lo > 2.0 * FAST_MARGIN_MM => Ok(Some(lo)),
            Some(_) => Err(()),
            None if l * l - dx2 * dx2 - dy * dy > -FAST_MARGIN_MM * l => Err(()),
            None => Ok(None),
        };
        let (Ok(r2), Ok(r3)) = (
            lower(g.l2, p.y - g.r_big2 * c + g.r4, p.z - g.r_big2 * s),
            lower(g.l3, p.y + g.r_big2 * c - g.r4, p.z + g.r_big2 * s),
        ) else {
            return None;
        };
        let (Some(rho2), Some(rho3)) = (r2, r3) else {
            continue;
        };
        let legs = [
            leg_check(m, 0, p, s, c, leg1.rho1, cos_tilt),
            leg_check(m, 1, p, s, c, rho2, cos_tilt),
            leg_check(m, 2, p, s, c, rho3, cos_tilt),
        ];
        let verdict = combine(m, c, [legs[0].1, legs[1].1, legs[2].1]);
        if !verdict.feasible() {
            continue;
        }
        let branch = IkBranch {
            alpha: leg1.alpha,
            rho: Sliders::new(leg1.rho1, rho2, rho3),
            config: [legs[0].0, legs[1].0, legs[2].0],
            verdict,
        };
        match best {
            Some(b) if (b.alpha.abs() - branch.alpha.abs()).abs() < FAST_MARGIN_RAD => return None,
            Some(b) if b.alpha.abs() < branch.alpha.abs() => {}
            _ => best = Some(branch),
        }
    }
    best
}

/// What `verne ik` needs for one point: the working branch alone when [`working_fast`] is sure
/// of it, every branch otherwise; [`working`] of the result is the working branch either way.
pub fn solve_working_into(m: &Machine, p: &Vector3<f64>, out: &mut IkBranches) {
    match working_fast(m, p) {
        Some(b) => {
            out.clear();
            out.push(b);
        }
        None => solve_into(m, p, out),
    }
}

/// The machine's branch: the unique feasible one, or (if several are feasible, which the default
/// machine never shows) the one with the smallest |alpha|.
pub fn working(branches: &[IkBranch]) -> Option<&IkBranch> {
    branches
        .iter()
        .filter(|b| b.working())
        .min_by(|a, b| a.alpha.abs().total_cmp(&b.alpha.abs()))
}
