//! Forward kinematics of the parallel module (IFToMM 2007, section VI): for (rho1, rho2, rho3),
//! every real assembly mode (xp, yp, zp, alpha).
//!
//! Elimination (re-derived; the paper's intermediate systems (S2)-(S3) are not printed). With
//! u = xp + D1 - d1, z' = zp - rho1, delta = (D2 - d2) - (D1 - d1), p2 = rho2 - rho1,
//! p3 = rho3 - rho1 and c, s = cos, sin alpha:
//! - (3) - (4) is eq. (14): w y + R1 s z' = 0, with w = R1 c - r1;
//! - (6) - (5): 4 y e + 2 z' (2 R2 s + p2 - p3) = b, e = R2 c - r4,
//!   b = L3^2 - L2^2 + (p2 + p3)(2 R2 s + p2 - p3);
//!
//! a linear system in (y, z') whose determinant
//! Det = 2 (p2 - p3)(R1 c - r1) + 4 (R1 r4 - r1 R2) s is twice the left side of the existence
//! condition (21). Then
//! y = -R1 s b / Det, z' = w b / Det, and (5) - (10) gives u = U / (2 delta Det) with
//! U = A Det + 2 b Q, A = L2^2 - K1 - delta^2 - e^2 - (R2 s + p2)^2, Q = (R1 r4 - r1 R2) s + w p2.
//! Substituting into (10), u^2 + y^2 + z'^2 = K1 = L1^2 - R1^2 - r1^2 + 2 R1 r1 c, gives
//!
//!   F(alpha) = U^2 + 4 delta^2 (b^2 (R1^2 + r1^2 - 2 R1 r1 c) - K1 Det^2) = 0,
//!
//! a trigonometric polynomial of degree 4: with t = tan(alpha/2), (1 + t^2)^4 F is the paper's
//! degree-8 polynomial. Its real roots are isolated directly on the circle by `Trig::roots`
//! (certified exclusion and monotonicity tests on a grid, the half-angle charts only around a
//! near-double root). Every root is
//! back-substituted and polished by Newton on the original equations (3)-(6); where Det ~ 0
//! (condition (21)) the point is found instead as the intersection of the four spheres at that
//! alpha, which also yields the two solutions of a degenerate alpha.

use arrayvec::ArrayVec;
use nalgebra::{Matrix3, Vector3};

pub use crate::certificate::Certificate;
use crate::certificate::Certified;
use crate::math::cpu;
use crate::math::trig::Trig;
use crate::parallel_module::branches::{Config, Verdict, label};
use crate::parallel_module::equations::{ModulePose, Sliders, polish_pose_from, residual_mm};
use crate::parallel_module::fk_certify::{self, ProvedStart};
use crate::parallel_module::ik::wrap_angle;
use crate::spec::{Machine, ModuleGeometry};
use crate::tolerance::{ACCEPT_RESIDUAL_MM, FK_DET_REL, SAME_SOLUTION_MM, SAME_SOLUTION_RAD};

/// Where Det = 0 (condition (21)), the fixed-angle sphere intersection is tried only when
/// |b| there is below this fraction of its coefficients (a solution needs b = 0).
const DET_ZERO_B_REL: f64 = 1e-6;

/// How far (rad) the Newton polish may move alpha from a proved root: the root is accurate to
/// rounding, so a mode farther than this is some other root's.
const ROOT_POLISH_RAD: f64 = 1e-6;

/// Most assembly modes returned (the degree-8 polynomial, plus degenerate doubled solutions).
pub const MAX_FK_MODES: usize = 16;

/// One assembly mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FkMode {
    pub pose: ModulePose,
    pub config: Config,
    pub verdict: Verdict,
}

impl FkMode {
    pub fn working(&self) -> bool {
        self.verdict.feasible()
    }
}

/// Every real assembly mode of one set of slider positions, with the certificate that says why
/// there are no others. Dereferences to the list of modes.
pub type FkModes = Certified<FkMode, MAX_FK_MODES>;

/// The linear trigonometric forms of the elimination for one set of slider positions.
struct Elimination {
    w: Trig,
    b: Trig,
    det: Trig,
    u_num: Trig,
    delta: f64,
}

impl Elimination {
    #[inline(always)]
    fn new(g: &ModuleGeometry, rho: &Sliders) -> Elimination {
        let (r, rr, r2, r4) = (g.r_big1, g.r_small1, g.r_big2, g.r4);
        let p2 = rho.y - rho.x;
        let p3 = rho.z - rho.x;
        let delta = g.dx2 - g.dx1;
        let k0 = g.l1 * g.l1 - r * r - rr * rr;
        let w = Trig::linear(-rr, r, 0.0);
        let b = Trig::linear(
            g.l3 * g.l3 - g.l2 * g.l2 + (p2 + p3) * (p2 - p3),
            0.0,
            2.0 * r2 * (p2 + p3),
        );
        let det = Trig::linear(
            -2.0 * rr * (p2 - p3),
            2.0 * r * (p2 - p3),
            4.0 * (r * r4 - rr * r2),
        );
        let a = Trig::linear(
            g.l2 * g.l2 - k0 - delta * delta - r2 * r2 - r4 * r4 - p2 * p2,
            2.0 * r2 * r4 - 2.0 * r * rr,
            -2.0 * r2 * p2,
        );
        let q = Trig::linear(-rr * p2, r * p2, r * r4 - rr * r2);
        let u_num = a
            .mul_deg::<1, 1>(&det)
            .add(&b.mul_deg::<1, 1>(&q).scale(2.0));
        Elimination {
            w,
            b,
            det,
            u_num,
            delta,
        }
    }

    /// F(alpha) of the module documentation (degree 4).
    #[inline(always)]
    fn characteristic(&self, g: &ModuleGeometry) -> Trig {
        let (r, rr) = (g.r_big1, g.r_small1);
        let n1 = Trig::linear(r * r + rr * rr, -2.0 * r * rr, 0.0);
        let k1 = Trig::linear(g.l1 * g.l1 - r * r - rr * rr, 2.0 * r * rr, 0.0);
        let b2 = self.b.mul_deg::<1, 1>(&self.b);
        let det2 = self.det.mul_deg::<1, 1>(&self.det);
        let inner = b2
            .mul_deg::<2, 1>(&n1)
            .add(&k1.mul_deg::<1, 2>(&det2).scale(-1.0));
        self.u_num
            .mul_deg::<2, 2>(&self.u_num)
            .add(&inner.scale(4.0 * self.delta * self.delta))
    }

    /// The pose at `alpha` from the linear solution, or None where Det ~ 0; (s, c) = sin, cos of
    /// alpha.
    #[inline(always)]
    fn back_substitute(
        &self,
        g: &ModuleGeometry,
        rho: &Sliders,
        alpha: f64,
        (s, c): (f64, f64),
    ) -> Option<ModulePose> {
        let det = self.det.eval_sc_deg::<1>(s, c);
        let det_scale = self.det.cos[0].abs() + self.det.cos[1].abs() + self.det.sin[1].abs();
        if det.abs() <= FK_DET_REL * det_scale || det_scale == 0.0 {
            return None;
        }
        let b = self.b.eval_sc_deg::<1>(s, c);
        let y = -g.r_big1 * s * b / det;
        let zp = self.w.eval_sc_deg::<1>(s, c) * b / det;
        let u = self.u_num.eval_sc_deg::<2>(s, c) / (2.0 * self.delta * det);
        Some(ModulePose {
            p: Vector3::new(u - g.dx1, y, zp + rho.x),
            alpha,
        })
    }
}

/// The characteristic trigonometric polynomial F(alpha) of the module documentation for the
/// slider positions (its real roots are the assembly modes' angles). `rho` are the equations'
/// sliders ([`Machine::model_sliders`] of the joints): `g`'s zero offsets are not added here.
pub fn characteristic(g: &ModuleGeometry, rho: &Sliders) -> Trig {
    Elimination::new(g, rho).characteristic(g)
}

/// Points P on all four spheres of eqs. (3)-(6) at a fixed alpha: three sphere differences are
/// planes; a unique point when they meet in one, and up to two points when they share a line
/// (the degenerate case of condition (21)).
/// (s, c) = sin, cos of alpha.
fn fixed_alpha_points(
    g: &ModuleGeometry,
    rho: &Sliders,
    alpha: f64,
    (s, c): (f64, f64),
) -> ArrayVec<ModulePose, 2> {
    let (r, rr, r2, r4) = (g.r_big1, g.r_small1, g.r_big2, g.r4);
    let centers = [
        Vector3::new(-g.dx1, rr - r * c, rho.x - r * s),
        Vector3::new(-g.dx1, r * c - rr, rho.x + r * s),
        Vector3::new(-g.dx2, r2 * c - r4, rho.y + r2 * s),
        Vector3::new(-g.dx2, r4 - r2 * c, rho.z - r2 * s),
    ];
    let lens = [g.l1, g.l1, g.l2, g.l3];
    let mut m = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for j in 1..4 {
        let d = centers[j] - centers[0];
        for k in 0..3 {
            m[(j - 1, k)] = 2.0 * d[k];
        }
        rhs[j - 1] = centers[j].norm_squared() - centers[0].norm_squared() - lens[j] * lens[j]
            + lens[0] * lens[0];
    }
    let mut out = ArrayVec::new();
    let svd = m.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return out;
    };
    let sv = svd.singular_values;
    let smax = sv.max();
    if smax == 0.0 {
        return out;
    }
    // Least-squares particular solution over the well-determined directions.
    let mut p0 = Vector3::zeros();
    let mut null = None;
    for k in 0..3 {
        let v = vt.row(k).transpose();
        if sv[k] > FK_DET_REL * smax {
            p0 += v * (u.column(k).dot(&rhs) / sv[k]);
        } else if null.is_none() {
            null = Some(v);
        } else {
            return out; // a plane of candidates: not a finite set, nothing to report
        }
    }
    match null {
        None => out.push(ModulePose { p: p0, alpha }),
        Some(n) => {
            // |p0 + l n - C0|^2 = L1^2, with |n| = 1.
            let d = p0 - centers[0];
            let bh = n.dot(&d);
            let cc = d.norm_squared() - lens[0] * lens[0];
            let disc = bh * bh - cc;
            if disc >= 0.0 {
                let h = disc.sqrt();
                for l in [-bh - h, -bh + h] {
                    out.push(ModulePose {
                        p: p0 + n * l,
                        alpha,
                    });
                }
            }
        }
    }
    out
}

/// (sin alpha, cos alpha) where Det = A cos(alpha) + B sin(alpha) + C vanishes (condition
/// (21)): the line A c + B s + C = 0 met with the unit circle, without trigonometric calls; none,
/// one or two; none when Det is identically zero or never zero.
fn det_zeros(det: &Trig) -> ArrayVec<(f64, f64), 2> {
    let (a, b, c) = (det.cos[1], det.sin[1], det.cos[0]);
    let r2 = a * a + b * b;
    let mut out = ArrayVec::new();
    if r2 == 0.0 || !r2.is_finite() || c * c > r2 {
        return out;
    }
    // The foot of the perpendicular from the origin, -C (A, B) / r^2, plus or minus the half
    // chord sqrt(r^2 - C^2) along (-B, A) / r.
    let h = (r2 - c * c).sqrt();
    let (foot_c, foot_s) = (-c * a / r2, -c * b / r2);
    let (along_c, along_s) = (-b * h / r2, a * h / r2);
    out.push((foot_s - along_s, foot_c - along_c));
    if h != 0.0 {
        out.push((foot_s + along_s, foot_c + along_c));
    }
    out
}

/// Every real assembly mode for the slider positions, ordered by alpha, each with its
/// configuration and verdict. Empty when the sliders cannot be assembled. Built with AVX2 where
/// the processor has it ([`crate::math::cpu`]).
pub fn solve(m: &Machine, rho: &Sliders) -> FkModes {
    // The joints plus the sliders' zero offsets are the equations' sliders: solved on the model.
    if m.has_zeros() {
        return solve(&m.model(), &m.model_sliders(rho));
    }
    #[cfg(target_arch = "x86_64")]
    if cpu::has_avx2() {
        // SAFETY: the processor has AVX2 (checked just above).
        return unsafe { solve_avx2(m, rho) };
    }
    solve_built::<false>(m, rho)
}

/// [`solve`] built for the x86-64 baseline whatever the processor has: the same modes, bit for
/// bit.
#[doc(hidden)]
pub fn solve_baseline(m: &Machine, rho: &Sliders) -> FkModes {
    if m.has_zeros() {
        return solve_baseline(&m.model(), &m.model_sliders(rho));
    }
    solve_built::<false>(m, rho)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn solve_avx2(m: &Machine, rho: &Sliders) -> FkModes {
    solve_built::<true>(m, rho)
}

/// The body of [`solve`], inlined into each build with what it calls (`AVX2` tells them apart:
/// see [`crate::math::cpu`]).
#[inline(always)]
fn solve_built<const AVX2: bool>(m: &Machine, rho: &Sliders) -> FkModes {
    let g = &m.module;
    let mut out = FkModes::new();
    if !rho.iter().all(|v| v.is_finite()) {
        return out;
    }
    let elim = Elimination::new(g, rho);
    let f = elim.characteristic(g);
    let iso = f.isolate_built::<AVX2>(fk_certify::characteristic_error(g, rho), true);
    // One start pose per proved root (each root of F gives exactly one mode where Det != 0;
    // next to a zero of Det the factor it belongs to gives it), each with (sin, cos) of alpha.
    let mut proved: ArrayVec<ProvedStart, 40> = ArrayVec::new();
    for root in &iso.roots {
        let (alpha, sc) = (root.x, (root.sin, root.cos));
        let pose = elim
            .back_substitute(g, rho, alpha, sc)
            .or_else(|| fk_certify::pose_at_root_by_factors(g, rho, alpha, sc));
        match pose {
            Some(pose) => {
                let _ = proved.try_push(ProvedStart { pose, sc });
            }
            None => out.certificate = Certificate::Unproved,
        }
    }
    // Other starts: what the proof does not predict (any mode they find that the proved roots
    // did not is a contradiction, and the result is then unproved).
    let mut others: ArrayVec<ProvedStart, 40> = ArrayVec::new();
    // Starts of intervals too narrow for double-double that hold at most one mode each: a mode
    // they find is expected, none is too.
    let mut allowed: ArrayVec<ProvedStart, 40> = ArrayVec::new();
    let mut undecided: ArrayVec<[f64; 2], 8> = ArrayVec::new();
    if !iso.ambiguous.is_empty() {
        let resolution = fk_certify::resolve(
            g,
            rho,
            &iso.ambiguous,
            &mut proved,
            &mut allowed,
            &mut others,
            &mut undecided,
        );
        out.weaken(Certificate::from(resolution));
    }
    det_zero_starts(g, rho, &elim, &undecided, &mut allowed, &mut others);
    polish_modes(m, rho, &proved, &allowed, &others, &mut out);
    out.sort_by(|a, b| {
        a.pose
            .alpha
            .total_cmp(&b.pose.alpha)
            .then(a.config.cmp(&b.config))
    });
    out.mark_unproved(|m| &mut m.verdict);
    out
}

/// Where condition (21) fails (Det = 0), a real solution forces b = 0 there and F then has (at
/// least) a double root, F = 4 b^2 (Q^2 + delta^2 (R1^2 + r1^2 - 2 R1 r1 c)) >= 0 (it happens
/// on a whole plane: L2 = L3, rho2 = rho3, alpha = 0, y_p = 0). Those (at most two) angles are
/// tried directly on the four spheres, keeping only points that already solve them: a
/// cross-check of the proof, which finds these modes as roots of the factors. A point inside an
/// interval double-double left `undecided` goes to `allowed`, any other to `others`.
#[inline(always)]
fn det_zero_starts(
    g: &ModuleGeometry,
    rho: &Sliders,
    elim: &Elimination,
    undecided: &[[f64; 2]],
    allowed: &mut ArrayVec<ProvedStart, 40>,
    others: &mut ArrayVec<ProvedStart, 40>,
) {
    let b_scale = elim.b.cos[0].abs() + elim.b.sin[1].abs();
    for sc in det_zeros(&elim.det) {
        // F = 4 b^2 (Q^2 + delta^2 N) > 0 there unless b = 0: no solution at this alpha.
        if elim.b.eval_sc_deg::<1>(sc.0, sc.1).abs() > DET_ZERO_B_REL * b_scale {
            continue;
        }
        let alpha = wrap_angle(sc.0.atan2(sc.1));
        // Inside an interval double-double left undecided (narrower than the same-solution
        // tolerance), the two points are what that interval holds: expected, not a surprise.
        let near = |x: f64| wrap_angle(x - alpha).abs() <= 1e-12;
        let expected = undecided.iter().any(|&[a, b]| {
            near(a) || near(b) || (wrap_angle(alpha - a) >= 0.0 && wrap_angle(b - alpha) >= 0.0)
        });
        for pose in fixed_alpha_points(g, rho, alpha, sc) {
            if residual_mm(g, &pose, rho) <= ACCEPT_RESIDUAL_MM {
                let to = if expected {
                    &mut *allowed
                } else {
                    &mut *others
                };
                let _ = to.try_push(ProvedStart { pose, sc });
            }
        }
    }
}

/// A mode already found is `pose` again: alpha within [`SAME_SOLUTION_RAD`] (either side of
/// pi) and P within [`SAME_SOLUTION_MM`] (1 + |P|) in every coordinate, |P| the largest of
/// `pose`'s.
#[inline]
fn same_mode(found: &ModulePose, pose: &ModulePose) -> bool {
    wrap_angle(found.alpha - pose.alpha).abs() < SAME_SOLUTION_RAD
        && (found.p - pose.p).amax() < SAME_SOLUTION_MM * (1.0 + pose.p.amax())
}

/// The modes polished (Newton on eqs. (3)-(6)) from three lists of starts, duplicates merged,
/// into `out`: `proved`, one per proved root of F, each of which must polish within
/// [`ROOT_POLISH_RAD`] of its alpha; `allowed`, starts that hold at most one mode each and may
/// fail; `others`, starts no proof predicts. The certificate becomes
/// [`Certificate::Unproved`] when a proved start fails or drifts, when a mode comes from
/// `others` alone, or when there are more modes than the list holds.
#[inline(always)]
fn polish_modes(
    m: &Machine,
    rho: &Sliders,
    proved: &[ProvedStart],
    allowed: &[ProvedStart],
    others: &[ProvedStart],
    out: &mut FkModes,
) {
    let g = &m.module;
    let n_proved = proved.len();
    let n_expected = n_proved + allowed.len();
    for (k, start) in proved.iter().chain(allowed).chain(others).enumerate() {
        let (pose, residual, (s, c)) = polish_pose_from(g, start.pose, start.sc, rho);
        if residual > ACCEPT_RESIDUAL_MM {
            if k < n_proved {
                // A proved root whose mode could not be polished: not proved after all.
                out.certificate = Certificate::Unproved;
            }
            continue;
        }
        if k < n_proved && wrap_angle(pose.alpha - start.pose.alpha).abs() > ROOT_POLISH_RAD {
            // The polish left its root's neighbourhood: the mode it found is not that root's.
            out.certificate = Certificate::Unproved;
        }
        let pose = ModulePose {
            alpha: wrap_angle(pose.alpha),
            ..pose
        };
        if out.iter().any(|o| same_mode(&o.pose, &pose)) {
            continue;
        }
        if k >= n_expected || out.is_full() {
            // A mode no proved root predicted (or more than the list holds).
            out.certificate = Certificate::Unproved;
            if out.is_full() {
                continue;
            }
        }
        // wrap_angle moves alpha by whole turns at most: the same sine and cosine.
        let (config, verdict) = label(m, &pose.p, s, c, rho);
        out.push(FkMode {
            pose,
            config,
            verdict,
        });
    }
}

/// The machine's assembly mode: the feasible one (the smallest |alpha| if several are).
pub fn working(modes: &[FkMode]) -> Option<&FkMode> {
    modes
        .iter()
        .filter(|b| b.working())
        .min_by(|a, b| a.pose.alpha.abs().total_cmp(&b.pose.alpha.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`same_mode`] merges a mode within [`SAME_SOLUTION_MM`] (1 + |P|) in every coordinate and
    /// [`SAME_SOLUTION_RAD`] in alpha, also across pi, and no further: each checked at 0.99 and
    /// 1.01 of its tolerance, either side, with |P| from 0 to 1e4 mm.
    #[test]
    fn same_mode_is_within_both_tolerances() {
        use std::f64::consts::PI;
        for scale in [0.0, 1.0, 300.0, 1e4] {
            for alpha in [0.3, PI - 0.4 * SAME_SOLUTION_RAD] {
                let p = Vector3::new(-0.5 * scale, scale, 0.25 * scale);
                let pose = ModulePose { p, alpha };
                let tol = SAME_SOLUTION_MM * (1.0 + scale);
                for (f, same) in [(0.99, true), (1.01, false)] {
                    for sign in [1.0, -1.0] {
                        for axis in 0..3 {
                            let mut found = pose;
                            found.p[axis] += sign * f * tol;
                            assert_eq!(same_mode(&found, &pose), same, "{found:?} {pose:?}");
                        }
                        let turned = alpha + sign * f * SAME_SOLUTION_RAD;
                        let found = ModulePose {
                            p,
                            alpha: wrap_angle(turned),
                        };
                        assert_eq!(same_mode(&found, &pose), same, "{found:?} {pose:?}");
                    }
                }
            }
        }
    }

    /// The points on the four spheres at a fixed alpha (the cross-check where condition (21)
    /// fails) hold the pose the sliders were computed from: P, its working branch's alpha and
    /// sliders, back to P (a pose constructed to be true).
    #[test]
    fn fixed_alpha_points_hold_the_pose_of_the_sliders() {
        let m = Machine::default_verne();
        for p in [
            Vector3::new(-300.0, 0.0, 1100.0),
            Vector3::new(-250.0, 120.0, 1050.0),
            Vector3::new(-370.0, -60.0, 1100.0),
        ] {
            let branches = crate::parallel_module::ik::solve(&m, &p);
            let b = crate::parallel_module::ik::working(&branches).expect("a working branch");
            let sc = b.alpha.sin_cos();
            let points = fixed_alpha_points(&m.module, &b.rho, b.alpha, sc);
            assert!(
                points
                    .iter()
                    .any(|q| (q.p - p).norm() < 1e-6 && q.alpha == b.alpha),
                "{p:?}: {points:?}"
            );
        }
    }

    /// On the plane where condition (21) fails (legs II and III alike, rho2 = rho3), the mode
    /// at alpha = 0 is found by the proof and again by the fixed-alpha points: reported once.
    #[test]
    fn a_mode_found_twice_is_reported_once() {
        let text = crate::spec::DEFAULT_MACHINE_TOML.replace("L3 = 950.46", "L3 = 950.30");
        let m = Machine::from_toml_str(&text, "symmetric").unwrap();
        let p = Vector3::new(-300.0, 0.0, 1100.0);
        let branches = crate::parallel_module::ik::solve(&m, &p);
        let b = crate::parallel_module::ik::working(&branches).expect("a working branch");
        let modes = solve(&m, &b.rho);
        assert!(
            modes.iter().any(|md| (md.pose.p - p).norm() < 1e-6),
            "{modes:?}"
        );
        for (i, x) in modes.iter().enumerate() {
            for y in &modes[i + 1..] {
                let apart =
                    (x.pose.p - y.pose.p).norm() + wrap_angle(x.pose.alpha - y.pose.alpha).abs();
                assert!(apart > 1e-6, "a mode twice: {x:?} {y:?}");
            }
        }
    }

    /// The zeros of Det = A cos + B sin + C on the circle: each on the unit circle and a zero,
    /// two where the line crosses it, one where it touches, none where it misses it, where Det
    /// is constant (zero included) or not finite.
    #[test]
    fn det_zeros_are_on_the_circle_and_zeros() {
        use crate::math::trig::Trig;
        for (c0, a, b, n) in [
            (0.3, 1.0, 0.5, 2),
            (-0.7, -0.2, 1.3, 2),
            (0.0, 2.0, 0.0, 2),
            (1.0, 0.0, 1.0, 1),
            (-1.0, 1.0, 0.0, 1),
            (2.0, 1.0, 1.0, 0),
            (1.0, 0.0, 0.0, 0),
            (0.0, 0.0, 0.0, 0),
            (0.0, f64::INFINITY, 1.0, 0),
        ] {
            let z = det_zeros(&Trig::linear(c0, a, b));
            assert_eq!(z.len(), n, "{c0} + {a} cos + {b} sin: {z:?}");
            for &(s, c) in &z {
                assert!((s * s + c * c - 1.0).abs() < 1e-12, "{z:?}");
                assert!((a * c + b * s + c0).abs() < 1e-12, "{z:?}");
            }
            if n == 2 {
                assert!((z[0].0 - z[1].0).abs() + (z[0].1 - z[1].1).abs() > 1e-6);
            }
        }
    }

    /// Where the three planes share a line (legs II and III alike, rho2 = rho3, alpha = 0: the
    /// plane where condition (21) fails), the points are where that line meets leg I's sphere:
    /// two, the pose among them, both on all four spheres.
    #[test]
    fn fixed_alpha_points_on_a_line_of_candidates() {
        let text = crate::spec::DEFAULT_MACHINE_TOML.replace("L3 = 950.46", "L3 = 950.30");
        let m = Machine::from_toml_str(&text, "symmetric").unwrap();
        let p = Vector3::new(-300.0, 0.0, 1100.0);
        let branches = crate::parallel_module::ik::solve(&m, &p);
        let b = crate::parallel_module::ik::working(&branches).expect("a working branch");
        assert_eq!(b.alpha, 0.0);
        assert_eq!(b.rho.y, b.rho.z);
        let points = fixed_alpha_points(&m.module, &b.rho, 0.0, (0.0, 1.0));
        assert_eq!(points.len(), 2, "{points:?}");
        assert!(points.iter().any(|q| (q.p - p).norm() < 1e-6), "{points:?}");
        assert!((points[0].p - points[1].p).norm() > 1.0, "{points:?}");
        for q in &points {
            assert!(residual_mm(&m.module, q, &b.rho) < 1e-6, "{q:?}");
        }
        // 1e-10 rad away the planes nearly share the line: their smallest singular value is
        // within FK_DET_REL of the largest, so the line is used, not a point divided by it.
        let alpha = 1e-10;
        let near = fixed_alpha_points(&m.module, &b.rho, alpha, alpha.sin_cos());
        assert_eq!(near.len(), 2, "{near:?}");
        for (q, q0) in near.iter().zip(&points) {
            assert!((q.p - q0.p).norm() < 1e-6, "{near:?} vs {points:?}");
        }
    }

    /// The working joints of three poses away from condition (21), for the tests below: the
    /// machine, and each pose with its sliders.
    fn poses_and_sliders() -> (Machine, Vec<(ModulePose, Sliders)>) {
        let m = Machine::default_verne();
        let out = [
            Vector3::new(-300.0, 0.0, 1100.0),
            Vector3::new(-250.0, 120.0, 1050.0),
            Vector3::new(-370.0, -60.0, 1100.0),
        ]
        .iter()
        .map(|&p| {
            let branches = crate::parallel_module::ik::solve(&m, &p);
            let b = crate::parallel_module::ik::working(&branches).expect("a working branch");
            (ModulePose { p, alpha: b.alpha }, b.rho)
        })
        .collect();
        (m, out)
    }

    /// Away from Det = 0 the linear solution of (14) and (6) - (5) back-substituted at the
    /// root's alpha is the pose the sliders were computed from (the factors are the other
    /// route, taken only where Det ~ 0).
    #[test]
    fn back_substitution_gives_the_pose_of_the_sliders() {
        let (m, poses) = poses_and_sliders();
        for (pose, rho) in poses {
            let elim = Elimination::new(&m.module, &rho);
            let sc = pose.alpha.sin_cos();
            let back = elim.back_substitute(&m.module, &rho, pose.alpha, sc);
            let back = back.expect("Det is not zero at the working mode");
            assert!((back.p - pose.p).norm() < 1e-6, "{back:?} vs {pose:?}");
            assert_eq!(back.alpha, pose.alpha);
        }
    }

    /// The back substitution refuses where |Det| is within FK_DET_REL of the sum of its
    /// coefficients' sizes: at angles beside a zero of Det where it is half that, and at the
    /// zero, not where it is twice that.
    #[test]
    fn back_substitution_refuses_within_its_tolerance_of_det_zero() {
        let (m, poses) = poses_and_sliders();
        let mut tried = 0;
        // Table III's sliders too: rho2 - rho3 = 435 mm makes Det's cosine terms a third of
        // the sum of its coefficients' sizes.
        let table3 = Vector3::new(674.0, 685.0, 250.0);
        for rho in poses.iter().map(|(_, rho)| *rho).chain([table3]) {
            let elim = Elimination::new(&m.module, &rho);
            let d = &elim.det;
            let scale = d.cos[0].abs() + d.cos[1].abs() + d.sin[1].abs();
            for (s0, c0) in det_zeros(d) {
                let alpha0 = s0.atan2(c0);
                let slope = -d.cos[1] * s0 + d.sin[1] * c0;
                assert!(
                    elim.back_substitute(&m.module, &rho, alpha0, (s0, c0))
                        .is_none()
                );
                for (k, refused) in [(0.5, true), (-0.5, true), (2.0, false), (-2.0, false)] {
                    let alpha = alpha0 + k * FK_DET_REL * scale / slope;
                    let sc = alpha.sin_cos();
                    let det = d.eval_sc(sc.0, sc.1);
                    let ratio = det / (FK_DET_REL * scale);
                    assert!((ratio - k).abs() < 1e-3 * k.abs(), "{ratio} for {k}");
                    let back = elim.back_substitute(&m.module, &rho, alpha, sc);
                    assert_eq!(
                        back.is_none(),
                        refused,
                        "Det at {k} of the tolerance: {back:?}"
                    );
                    tried += 1;
                }
            }
        }
        assert!(tried >= 12, "{tried}");
    }

    /// Sliders whose modes are simple, well-separated roots of F are proved in double
    /// precision alone (no interval left ambiguous for the factors to resolve): Table III of
    /// IFToMM 2007 and the working joints of the two poses off y = 0 above. The pose on y = 0
    /// has two modes 1.3e-4 rad apart in alpha (docs/reference-results.md): that pair needs the
    /// factors.
    #[test]
    fn simple_roots_are_proved_in_double_precision() {
        let (m, poses) = poses_and_sliders();
        let table3 = Vector3::new(674.0, 685.0, 250.0);
        let rhos = poses.iter().map(|(_, rho)| *rho).chain([table3]);
        for (k, rho) in rhos.enumerate() {
            let modes = solve(&m, &rho);
            assert!(!modes.is_empty(), "{rho:?}");
            let expected = if k == 0 {
                Certificate::Factored
            } else {
                Certificate::Double
            };
            assert_eq!(modes.certificate, expected, "{rho:?}: {modes:?}");
        }
    }

    /// The machine with legs II and III alike (L3 = L2), where condition (21) fails on a
    /// plane, and the sliders of P = (-300, 0, 1100) on it (rho2 = rho3, alpha = 0).
    fn symmetric_plane() -> (Machine, Vector3<f64>, Sliders) {
        let text = crate::spec::DEFAULT_MACHINE_TOML.replace("L3 = 950.46", "L3 = 950.30");
        let m = Machine::from_toml_str(&text, "symmetric").unwrap();
        let p = Vector3::new(-300.0, 0.0, 1100.0);
        let branches = crate::parallel_module::ik::solve(&m, &p);
        let rho = crate::parallel_module::ik::working(&branches)
            .expect("a working branch")
            .rho;
        (m, p, rho)
    }

    /// The starts [`det_zero_starts`] gives for `undecided`, as (the list `expected` names,
    /// `allowed` when true, and the other list).
    fn starts_in(
        m: &Machine,
        rho: &Sliders,
        undecided: &[[f64; 2]],
        expected: bool,
    ) -> (ArrayVec<ProvedStart, 40>, ArrayVec<ProvedStart, 40>) {
        let elim = Elimination::new(&m.module, rho);
        let (mut allowed, mut others) = (ArrayVec::new(), ArrayVec::new());
        det_zero_starts(&m.module, rho, &elim, undecided, &mut allowed, &mut others);
        if expected {
            (allowed, others)
        } else {
            (others, allowed)
        }
    }

    /// The cross-check at the zeros of Det: on the plane where condition (21) fails, the points
    /// at alpha = 0 (b = 0 there) are starts, the pose among them; they go to `allowed` when
    /// alpha = 0 is in an interval double-double left undecided (or within 1e-12 rad of one of
    /// its ends), to `others` otherwise. Where b is not zero at the zeros of Det, none.
    #[test]
    fn starts_at_the_zeros_of_det() {
        let (m, p, rho) = symmetric_plane();
        let at_zero =
            |starts: &[ProvedStart]| starts.iter().filter(|st| st.pose.alpha == 0.0).count();
        for (undecided, expected) in [
            (vec![], false),
            (vec![[-1e-3, 1e-3]], true),
            (vec![[5e-13, 0.1]], true),
            (vec![[-0.1, -5e-13]], true),
            (vec![[-0.2, -0.1], [1e-9, 0.1]], false),
            (vec![[-3.0, -1e-9]], false),
        ] {
            let (to, not) = starts_in(&m, &rho, &undecided, expected);
            assert_eq!(at_zero(&to), 2, "{undecided:?}: {to:?} {not:?}");
            assert_eq!(at_zero(&not), 0, "{undecided:?}: {to:?} {not:?}");
            assert!(to.iter().any(|st| (st.pose.p - p).norm() < 1e-6), "{to:?}");
            for st in to.iter().chain(&not) {
                assert!(residual_mm(&m.module, &st.pose, &rho) <= ACCEPT_RESIDUAL_MM);
                let (sin, cos) = st.pose.alpha.sin_cos();
                assert!((st.sc.0 - sin).abs() < 1e-15 && (st.sc.1 - cos).abs() < 1e-15);
            }
        }
        // The default machine (L3 != L2), the same sliders: b = L3^2 - L2^2 at alpha = 0.
        let m = Machine::default_verne();
        let elim = Elimination::new(&m.module, &rho);
        assert_eq!(det_zeros(&elim.det).len(), 2);
        let (mut allowed, mut others) = (ArrayVec::new(), ArrayVec::new());
        det_zero_starts(&m.module, &rho, &elim, &[], &mut allowed, &mut others);
        assert!(allowed.is_empty() && others.is_empty(), "{others:?}");
    }

    /// 1e-7 mm off that plane (rho3 moved by -+1e-7 mm) Det's zero leaves alpha = 0 by about
    /// 4e-11 rad and b there is about 1e-4 mm^2, still within DET_ZERO_B_REL of its
    /// coefficients: the points there, within 1e-7 mm of solving the equations, are starts,
    /// in `allowed` when an undecided interval holds that zero or ends within 1e-12 rad of it.
    #[test]
    fn starts_at_a_zero_of_det_next_to_the_plane() {
        let (m, p, on_plane) = symmetric_plane();
        for eps in [1e-7, -1e-7] {
            let rho = Vector3::new(on_plane.x, on_plane.y, on_plane.z + eps);
            let elim = Elimination::new(&m.module, &rho);
            let alpha0 = det_zeros(&elim.det)
                .iter()
                .map(|&(s, c)| s.atan2(c))
                .find(|a| a.abs() < 1e-6)
                .expect("a zero of Det next to alpha = 0");
            assert!(alpha0.abs() > 1e-11, "{alpha0}");
            let at_zero = |starts: &[ProvedStart]| {
                starts
                    .iter()
                    .filter(|st| (st.pose.alpha - alpha0).abs() < 1e-15)
                    .count()
            };
            for (undecided, expected) in [
                (vec![], false),
                (vec![[alpha0 + 5e-13, 0.1]], true),
                (vec![[-0.1, alpha0 - 5e-13]], true),
                (vec![[alpha0 - 1e-11, alpha0 + 1e-11]], true),
                (vec![[alpha0 + 2e-12, 0.1]], false),
                (vec![[-0.1, alpha0 - 2e-12]], false),
            ] {
                let (to, not) = starts_in(&m, &rho, &undecided, expected);
                let case = format!("{eps}, {undecided:?}: {to:?} {not:?}");
                assert_eq!((at_zero(&to), at_zero(&not)), (2, 0), "{case}");
                assert!(to.iter().any(|st| (st.pose.p - p).norm() < 1e-6), "{case}");
            }
        }
    }

    /// What the polish of the starts does to the certificate, with starts injected as a failing
    /// proof would give them: every proved start found keeps it; a mode found only from a
    /// start no proof predicted, a proved start that fails or that polishes to a mode more than
    /// 1e-6 rad away make it unproved; allowed starts count as expected, and one that fails
    /// or drifts proves nothing missing. A start a whole turn away polishes to the mode's alpha in
    /// (-pi, pi].
    #[test]
    fn the_polish_of_the_starts_keeps_the_certificate_only_when_the_proof_holds() {
        let (m, poses) = poses_and_sliders();
        let rho = poses[1].1;
        let modes = solve(&m, &rho);
        assert!(modes.len() >= 2 && modes.certificate == Certificate::Double);
        let start = |pose: ModulePose| ProvedStart {
            pose,
            sc: pose.alpha.sin_cos(),
        };
        let all: Vec<ProvedStart> = modes.iter().map(|md| start(md.pose)).collect();
        let (last, rest) = all.split_last().unwrap();
        let failing = start(ModulePose {
            p: Vector3::new(f64::NAN, 0.0, 0.0),
            alpha: f64::NAN,
        });
        let drifting = start(ModulePose {
            alpha: modes[0].pose.alpha + 1e-3,
            ..modes[0].pose
        });
        let turned = start(ModulePose {
            alpha: modes[0].pose.alpha + 2.0 * std::f64::consts::PI,
            ..modes[0].pose
        });
        let run = |proved: &[ProvedStart], allowed: &[ProvedStart], others: &[ProvedStart]| {
            let mut out = FkModes::new();
            polish_modes(&m, &rho, proved, allowed, others, &mut out);
            out.sort_by(|a, b| a.pose.alpha.total_cmp(&b.pose.alpha));
            assert_eq!(out.len(), modes.len(), "{out:?} vs {modes:?}");
            for (a, b) in out.iter().zip(modes.iter()) {
                assert!(
                    (a.pose.p - b.pose.p).norm() < 1e-6
                        && (a.pose.alpha - b.pose.alpha).abs() < 1e-9,
                    "{a:?} vs {b:?}"
                );
                assert_eq!((a.config, a.verdict), (b.config, b.verdict));
            }
            out.certificate
        };
        let with = |extra: ProvedStart| {
            let mut v = all.clone();
            v.push(extra);
            v
        };
        let (double, unproved) = (Certificate::Double, Certificate::Unproved);
        assert_eq!(run(&all, &[], &[]), double);
        assert_eq!(run(&all, &[], &all), double, "others that repeat the proof");
        assert_eq!(
            run(rest, &[], &[*last]),
            unproved,
            "a mode only others found"
        );
        assert_eq!(run(&all[..1], &all[1..], &[]), double, "the rest allowed");
        assert_eq!(
            run(&all, &[failing], &[]),
            double,
            "an allowed start that fails"
        );
        let mut allowed_drifting = all[1..].to_vec();
        allowed_drifting[0] = start(ModulePose {
            alpha: modes[1].pose.alpha + 1e-3,
            ..modes[1].pose
        });
        let drift = run(&all[..1], &allowed_drifting, &[]);
        assert_eq!(drift, double, "an allowed start that drifts");
        assert_eq!(
            run(&with(failing), &[], &[]),
            unproved,
            "a proved start that fails"
        );
        assert_eq!(
            run(&with(drifting), &[], &[]),
            unproved,
            "a proved start that drifts"
        );
        assert_eq!(
            run(&[turned], &all[1..], &[]),
            double,
            "a start a turn away"
        );
    }
}
