//! Inverse kinematics of the parallel module (IFToMM 2007, section V): for a point P, every real
//! (alpha, rho1, rho2, rho3).
//!
//! alpha comes from the cubic in cos(alpha) of eq. (9), rho1 from eq. (14) (both signs of eq. (11)
//! where sin(alpha) = 0, Table II), rho2 and rho3 from eqs. (12)-(13) with both signs.

use arrayvec::ArrayVec;
use nalgebra::{Matrix2, Vector2, Vector3};

use crate::branches::{Config, Verdict, combine, cos_tilt_max, leg_check};
use crate::machine::{Machine, ModuleGeometry};
use crate::module_geometry::Sliders;
use crate::poly::roots_in;
use crate::tolerance::{
    NEWTON_MAX_ITER, NEWTON_STEP_STOP, SAME_SOLUTION_RAD, SIN_ALPHA_ZERO, SQRT_ARG_REL,
};

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
}

/// Every real leg-I posture (alpha, rho1) for the point: eqs. (9), (11), (14), polished by Newton
/// on eqs. (10) and (14) (the half-sum and half-difference of (3) and (4)).
fn leg1_postures(g: &ModuleGeometry, p: &Vector3<f64>) -> ArrayVec<Leg1, 6> {
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
    let mut out = ArrayVec::new();
    if scale == 0.0 || !scale.is_finite() {
        return out;
    }
    let coeffs = [p4 / scale, p3 / scale, p2 / scale, p1 / scale];
    for root in roots_in(&coeffs, -1.0, 1.0) {
        let c = root.x.clamp(-1.0, 1.0);
        let a = c.acos();
        let k1 = k0 + 2.0 * r * rr * c;
        // |rho1 - zp| from eq. (11).
        let h2 = k1 - u * u - y * y;
        let h = if h2 >= -SQRT_ARG_REL * g.l1 * g.l1 {
            h2.max(0.0).sqrt()
        } else {
            continue;
        };
        let candidates: ArrayVec<Leg1, 4> = if a.sin() < SIN_ALPHA_ZERO {
            // alpha in {0, pi}: eq. (14) is 0 = 0, both signs of eq. (11) (Table II).
            let a0 = if c > 0.0 { 0.0 } else { std::f64::consts::PI };
            [
                Leg1 {
                    alpha: a0,
                    rho1: p.z + h,
                },
                Leg1 {
                    alpha: a0,
                    rho1: p.z - h,
                },
            ]
            .into_iter()
            .collect()
        } else {
            // sgn(rho1 - zp) from eq. (14): y (R1 cos a - r1) = R1 sin a (rho1 - zp).
            let w = r * c - rr;
            [a, -a]
                .into_iter()
                .map(|al| {
                    let s = al.sin();
                    let q = y * w / (r * s);
                    let rho1 = if q == 0.0 { p.z } else { p.z + q.signum() * h };
                    Leg1 { alpha: al, rho1 }
                })
                .collect()
        };
        for cand in candidates {
            let polished = polish_leg1(g, p, cand);
            let dup = out.iter().any(|o: &Leg1| {
                angle_diff(o.alpha, polished.alpha).abs() < SAME_SOLUTION_RAD
                    && (o.rho1 - polished.rho1).abs() < 1e-7
            });
            if !dup && !out.is_full() {
                out.push(polished);
            }
        }
    }
    out
}

/// Newton on g1 = u^2 + y^2 + (z - rho1)^2 - K1(alpha) (eq. (10)) and
/// g2 = y (R1 cos a - r1) + R1 sin a (z - rho1) (eq. (14)), unknowns (alpha, rho1).
fn polish_leg1(g: &ModuleGeometry, p: &Vector3<f64>, start: Leg1) -> Leg1 {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let y = p.y;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    // Residuals at (alpha, rho1) and what the Jacobian needs, from one sin_cos.
    let eval = |l: &Leg1| {
        let (s, c) = l.alpha.sin_cos();
        let dz = p.z - l.rho1;
        let f = Vector2::new(
            u * u + y * y + dz * dz - k0 - 2.0 * r * rr * c,
            y * (r * c - rr) + r * s * dz,
        );
        (f, s, c, dz)
    };
    let mut cur = start;
    let (mut f, mut s, mut c, mut dz) = eval(&cur);
    let mut best = (cur, f.amax());
    for _ in 0..NEWTON_MAX_ITER {
        if f.amax() == 0.0 {
            break;
        }
        let j = Matrix2::new(2.0 * r * rr * s, -2.0 * dz, -y * r * s + r * c * dz, -r * s);
        let Some(step) = j.try_inverse().map(|inv| inv * f) else {
            break;
        };
        if !step.iter().all(|v| v.is_finite()) {
            break;
        }
        cur = Leg1 {
            alpha: cur.alpha - step.x,
            rho1: cur.rho1 - step.y,
        };
        (f, s, c, dz) = eval(&cur);
        if f.amax() <= best.1 {
            best = (cur, f.amax());
        }
        if step.x.abs() < NEWTON_STEP_STOP
            && step.y.abs() < NEWTON_STEP_STOP * (1.0 + cur.rho1.abs())
        {
            break;
        }
    }
    let mut out = best.0;
    out.alpha = wrap_angle(out.alpha);
    out
}

/// Angle in (-pi, pi].
pub fn wrap_angle(a: f64) -> f64 {
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
            let (s, c) = l.alpha.sin_cos();
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

/// The machine's branch: the unique feasible one, or (if several are feasible, which the default
/// machine never shows) the one with the smallest |alpha|.
pub fn working(branches: &[IkBranch]) -> Option<&IkBranch> {
    branches
        .iter()
        .filter(|b| b.working())
        .min_by(|a, b| a.alpha.abs().total_cmp(&b.alpha.abs()))
}
