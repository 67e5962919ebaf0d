//! Inverse kinematics of the parallel module (IFToMM 2007, section V): for a point P, every real
//! (alpha, rho1, rho2, rho3).
//!
//! alpha comes from the cubic in cos(alpha) of eq. (9), rho1 from eq. (14) (both signs of eq. (11)
//! where sin(alpha) = 0, Table II), rho2 and rho3 from eqs. (12)-(13) with both signs.

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::branches::{
    Config, Verdict, WORKING_CONFIG, cos_tilt_max, leg_state, outer_leg_states, rods_cross,
};
use crate::cubic::{cubic_roots_in, deflated_roots_in};
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
pub(crate) struct Leg1 {
    pub alpha: f64,
    pub rho1: f64,
    pub sin: f64,
    pub cos: f64,
}

/// The cubic eq. (9) in cos(alpha) for the point, normalised, lowest degree first; None when it
/// is degenerate (every coefficient zero or not finite).
pub fn cubic_eq9(g: &ModuleGeometry, p: &Vector3<f64>) -> Option<[f64; 4]> {
    let c = eq9_coefficients(g, p);
    let scale = c.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    Some(c.map(|a| a / scale))
}

/// The coefficients of eq. (9), lowest degree first, as they come (not normalised).
#[inline]
pub(crate) fn eq9_coefficients(g: &ModuleGeometry, p: &Vector3<f64>) -> [f64; 4] {
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

/// |rho1 - zp| from eq. (11) at cos(alpha) = c, squared (negative when leg I cannot reach).
fn leg1_height_sq(g: &ModuleGeometry, p: &Vector3<f64>, c: f64) -> f64 {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let k1 = g.l1 * g.l1 - r * r - rr * rr + 2.0 * r * rr * c;
    k1 - u * u - p.y * p.y
}

/// Every real leg-I posture (alpha, rho1) for the point into `out`: eqs. (9), (11), (14),
/// polished by Newton on eqs. (10) and (14) (the half-sum and half-difference of (3) and (4)).
fn leg1_postures_into(m: &Machine, p: &Vector3<f64>, out: &mut ArrayVec<Leg1, 6>) {
    let g = &m.module;
    let (r, rr) = (g.r_big1, g.r_small1);
    out.clear();
    let Some(coeffs) = cubic_eq9(g, p) else {
        return;
    };
    let mut push = |l: Leg1| {
        let dup = out.iter().any(|o: &Leg1| {
            (o.rho1 - l.rho1).abs() < 1e-7 && angle_diff(o.alpha, l.alpha).abs() < SAME_SOLUTION_RAD
        });
        if !dup && !out.is_full() {
            out.push(l);
        }
    };
    // The root with R1 cos(alpha) > r1, when it is certified alone there, by Newton on leg I
    // from an estimate (no isolation, no acos, no separate polish); the other roots, all below
    // r1/R1 then, from the cubic divided by it, or by isolation when that is a close call.
    let certified =
        estimated_start(g, p).and_then(|start| crate::ik_track::certified_posture(m, p, start));
    let roots: ArrayVec<f64, 8> = match certified {
        // Below r1/R1: the cubic divided by the known root, unless that is a close call.
        Some(leg1) => {
            let hi = rr / r - FAST_MARGIN_RAD;
            match deflated_roots_in(&coeffs, leg1.cos, -1.0, hi) {
                Some(roots) => roots.into_iter().collect(),
                None => cubic_roots_in(&coeffs, -1.0, hi)
                    .iter()
                    .map(|t| t.x)
                    .collect(),
            }
        }
        None => cubic_roots_in(&coeffs, -1.0, 1.0)
            .iter()
            .map(|t| t.x)
            .collect(),
    };
    for root in roots {
        let c = root.clamp(-1.0, 1.0);
        let sin_a = ((1.0 - c) * (1.0 + c)).sqrt();
        let h2 = leg1_height_sq(g, p, c);
        let h = if h2 >= -SQRT_ARG_REL * g.l1 * g.l1 {
            h2.max(0.0).sqrt()
        } else {
            continue;
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
            continue;
        }
        // sgn(rho1 - zp) from eq. (14): y (R1 cos a - r1) = R1 sin a (rho1 - zp).
        let q = p.y * (r * c - rr) / (r * sin_a);
        let rho1 = if q == 0.0 { p.z } else { p.z + q.signum() * h };
        let polished = polish_leg1(
            g,
            p,
            Leg1 {
                alpha: c.acos(),
                rho1,
                sin: sin_a,
                cos: c,
            },
        );
        push(polished);
        push(mirror(p, polished));
    }
    // Last, as the root with the largest cos(alpha) (postures come out by increasing cos).
    if let Some(leg1) = certified {
        push(leg1);
        push(mirror(p, leg1));
    }
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
        let Some((next, settled)) = eqs.newton_step(&cur, f, dz) else {
            break;
        };
        cur = next;
        if settled {
            return with_wrapped_alpha(cur);
        }
        (f, dz) = eqs.residuals(&cur);
        if amax(f) <= best.1 {
            best = (cur, amax(f));
        }
    }
    with_wrapped_alpha(best.0)
}

/// Newton on eqs. (10) and (14) from `start`, step after step, until a step settles the posture
/// (it, or the step it predicts next, is below [`NEWTON_STEP_STOP`]: Newton has converged to
/// rounding); None when that takes more than `max_steps` steps or the Jacobian is singular.
#[inline]
pub(crate) fn newton_leg1(
    g: &ModuleGeometry,
    p: &Vector3<f64>,
    start: Leg1,
    max_steps: usize,
) -> Option<Leg1> {
    let eqs = Leg1Equations::new(g, p);
    let mut cur = start;
    for _ in 0..max_steps {
        let (f, dz) = eqs.residuals(&cur);
        let (next, settled) = eqs.newton_step(&cur, f, dz)?;
        cur = next;
        if settled {
            return Some(with_wrapped_alpha(cur));
        }
    }
    None
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
    fn newton_step(&self, cur: &Leg1, f: [f64; 2], dz: f64) -> Option<(Leg1, bool)> {
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
            return Some((next, true));
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
        Some((next, settled))
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

/// Both roots of eqs. (12)-(13) for one leg: `offset + s * sqrt(L^2 - dx^2 - dy^2)`, s = -1 first.
pub(crate) fn leg_sliders(l: f64, dx: f64, dy: f64, offset: f64) -> Option<[f64; 2]> {
    leg_root(l, dx, dy).map(|h| [offset - h, offset + h])
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
    let mut legs1 = ArrayVec::<Leg1, 6>::new();
    leg1_postures_into(m, p, &mut legs1);
    let n = legs1.len();
    let mut checks = [(0i8, Verdict::default()); 6];
    for (k, l) in legs1.iter().enumerate() {
        checks[k] = leg_state(m, 0, p, l.sin, l.cos, l.rho1, cos_tilt).check();
    }
    // Postures come in pairs (alpha >= 0, its mirror) by increasing cos(alpha): the mirrors in
    // that order, then the others in reverse, is usually the order already; sorted if not.
    let mut order = [0usize; 6];
    let (mut front, mut back) = (0, n);
    for k in 0..n {
        if legs1[k].alpha < 0.0 {
            order[front] = k;
            front += 1;
        } else {
            back -= 1;
            order[back] = k;
        }
    }
    let key = |k: usize| (legs1[k].alpha, checks[k].0);
    let before = |a: usize, b: usize| {
        let (ka, kb) = (key(a), key(b));
        ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1))
    };
    if order[..n].windows(2).any(|w| before(w[0], w[1]).is_gt()) {
        order[..n].sort_unstable_by(|&a, &b| before(a, b));
    }
    for &k in &order[..n] {
        let (leg1, l1) = (legs1[k], checks[k]);
        let (s, c) = (leg1.sin, leg1.cos);
        let dx2 = p.x + g.dx2;
        // eq. (12): rho2 = zp - R2 sin a + s2 sqrt(L2^2 - (xp + D2 - d2)^2 - (yp - R2 cos a + r4)^2)
        let (dy2, off2) = (p.y - g.r_big2 * c + g.r4, p.z - g.r_big2 * s);
        let Some(h2) = leg_root(g.l2, dx2, dy2) else {
            continue;
        };
        // eq. (13): rho3 = zp + R2 sin a + s3 sqrt(L3^2 - (xp + D2 - d2)^2 - (yp + R2 cos a - r4)^2)
        let (dy3, off3) = (p.y + g.r_big2 * c - g.r4, p.z + g.r_big2 * s);
        let Some(h3) = leg_root(g.l3, dx2, dy3) else {
            continue;
        };
        let (r2, r3) = ([off2 - h2, off2 + h2], [off3 - h3, off3 + h3]);
        // Labels and verdicts leg by leg: leg I once per posture, legs II and III once per pair
        // of roots.
        let [l2a, l2b] = outer_leg_states(m, 1, (dx2, dy2, h2), r2, cos_tilt);
        let [l3a, l3b] = outer_leg_states(m, 2, (dx2, dy3, h3), r3, cos_tilt);
        let (l2, l3) = ([l2a.check(), l2b.check()], [l3a.check(), l3b.check()]);
        let v1 = l1.1.with(rods_cross(m, c));
        let branch = |k2: usize, k3: usize| IkBranch {
            alpha: leg1.alpha,
            rho: Sliders::new(leg1.rho1, r2[k2], r3[k3]),
            config: [l1.0, l2[k2].0, l3[k3].0],
            verdict: v1.with(l2[k2].1).with(l3[k3].1),
        };
        let four = [branch(0, 0), branch(0, 1), branch(1, 0), branch(1, 1)];
        let pushed = out.try_extend_from_slice(&four);
        debug_assert!(
            pushed.is_ok(),
            "six postures of four branches fit MAX_IK_BRANCHES"
        );
    }
}

/// How far (mm) a configuration sign or a square root must be from zero, and (rad) two candidate
/// angles from each other, for [`working_fast`] to decide alone; closer calls go to [`solve`].
pub(crate) const FAST_MARGIN_MM: f64 = 1e-6;
pub(crate) const FAST_MARGIN_RAD: f64 = 1e-6;

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
    if let Some((branch, _)) = certified_from_estimate(m, p) {
        return Some(branch);
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
    let g = &m.module;
    let (s, c) = (leg1.sin, leg1.cos);
    let dx2 = p.x + g.dx2;
    // The lower root of (12) or (13) (s = -1) and its leg's state, as [`solve`] has them.
    let lower = |leg: usize, l: f64, dy: f64, offset: f64| match leg_root(l, dx2, dy) {
        Some(h) if h > FAST_MARGIN_MM => {
            let rho = [offset - h, offset + h];
            Ok(Some((
                rho[0],
                outer_leg_states(m, leg, (dx2, dy, h), rho, cos_tilt)[0],
            )))
        }
        Some(_) => Err(()),
        None if l * l - dx2 * dx2 - dy * dy > -FAST_MARGIN_MM * l => Err(()),
        None => Ok(None),
    };
    let r2 = lower(1, g.l2, p.y - g.r_big2 * c + g.r4, p.z - g.r_big2 * s)?;
    let r3 = lower(2, g.l3, p.y + g.r_big2 * c - g.r4, p.z + g.r_big2 * s)?;
    let (Some((rho2, leg2)), Some((rho3, leg3))) = (r2, r3) else {
        return Ok(None);
    };
    // Feasible: every leg as on the machine and inside its limits, rods of leg I not crossing
    // (what [`combine`] of the three legs' verdicts says, without building it).
    let feasible = leg_state(m, 0, p, s, c, leg1.rho1, cos_tilt).ok()
        && leg2.ok()
        && leg3.ok()
        && g.r_big1 * c > g.r_small1;
    Ok(feasible.then_some(IkBranch {
        alpha: leg1.alpha,
        rho: Sliders::new(leg1.rho1, rho2, rho3),
        config: WORKING_CONFIG,
        verdict: Verdict::default(),
    }))
}

/// A leg-I start near the posture with s1 = -1 on the root of (9) nearest cos(alpha) = 1,
/// estimated without root isolation: eq. (14) about alpha = 0 with z - rho1 = h(alpha) from eq.
/// (11), h(alpha)^2 = h0^2 - 2 R1 r1 (1 - cos alpha), to third order in alpha:
///   R1 h0 a + y (R1 - r1) - y R1 a^2 / 2 - R1 (h0 / 6 + R1 r1 / (2 h0)) a^3 = 0,
/// solved by one correction of the first-order root a1 = -y (R1 - r1) / (R1 h0). None where
/// y is near 0 (alpha = 0 is then a root and both its postures meet) or leg I cannot reach at
/// alpha = 0.
fn estimated_start(g: &ModuleGeometry, p: &Vector3<f64>) -> Option<Leg1> {
    let (r, rr) = (g.r_big1, g.r_small1);
    let h0_sq = leg1_height_sq(g, p, 1.0);
    if p.y.abs() < FAST_MARGIN_MM || h0_sq <= 0.0 {
        return None;
    }
    let inv_h0 = 1.0 / h0_sq.sqrt();
    let a1 = -p.y * (r - rr) / r * inv_h0;
    let cubic = h0_sq * (1.0 / 6.0) + 0.5 * r * rr;
    // Small enough for the series of sin_cos_after_step (|alpha| < 0.25).
    let alpha = (a1 + a1 * a1 * (0.5 * p.y + a1 * cubic * inv_h0) * inv_h0).clamp(-0.24, 0.24);
    let (sin, cos) = sin_cos_after_step(0.0, 1.0, alpha, -alpha);
    // h(alpha) ~ h0 - R1 r1 (1 - cos alpha) / h0.
    Some(Leg1 {
        alpha,
        rho1: p.z - (h0_sq - r * rr * (1.0 - cos)) * inv_h0,
        sin,
        cos,
    })
}

/// [`crate::ik_track::certified_working`] from [`estimated_start`]: no cubic and no `acos` when
/// Newton reaches the certified posture.
fn certified_from_estimate(m: &Machine, p: &Vector3<f64>) -> Option<(IkBranch, Leg1)> {
    let start = estimated_start(&m.module, p)?;
    crate::ik_track::certified_working(m, p, start, cos_tilt_max(m))
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
