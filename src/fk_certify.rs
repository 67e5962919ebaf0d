//! The forward kinematics' proof of completeness where double precision alone cannot give it:
//! the intervals of alpha on which [`crate::trig::Trig::roots_certified`] could neither exclude
//! nor isolate a root of F (IFToMM 2007 section VI; see [`crate::module_fk`]).
//!
//! Two methods, tried in this order on each such interval:
//!
//! 1. **The two factors of F.** With tau = b / Det (the solution of the linear (y, zp) system is
//!    (y, zp - rho1) = tau (-R1 sin a, R1 cos a - r1), and xp + D1 - d1 = (A + 2 tau Q) /
//!    (2 delta)), eq. (10) becomes a quadratic in tau,
//!
//!    H1(a, tau) = P tau^2 + R tau + S = 0,  P = 4 (Q^2 + delta^2 N), R = 4 A Q,
//!    S = A^2 - 4 delta^2 K1,
//!
//!    and F = P b^2 + R b Det + S Det^2 = P g+ g-, with g+- = tau+- Det - b and tau+- the two
//!    roots of H1: (-A Q +- |delta| sqrt(Delta)) / (2 (Q^2 + delta^2 N)),
//!    Delta = 4 K1 (Q^2 + delta^2 N) - N A^2. Every solution of (3)-(6) at angle a is a root of
//!    g+ or g- (with its own tau, so its own pose), and there is none where Delta < 0. Where Det
//!    vanishes (condition (21)), two assembly modes share nearly the same alpha and F has two
//!    roots closer than its rounding (F is of the order of b^2 there); g+ and g- each have one
//!    simple root, of the order of b. Each factor is proved monotone on a sub-interval by
//!    interval arithmetic on its derivative ([`crate::interval`]), and its sign change there
//!    proved at the ends: exactly one root.
//! 2. **Double-double precision.** (1 + t^2)^4 F as the degree-8 polynomial in t = tan(a/2) (or
//!    tan((a - pi)/2) away from alpha = 0) of the paper, its coefficients computed in
//!    double-double from the exact inputs with a running error bound ([`crate::dd::Tracked`]);
//!    exclusion and monotonicity tests as in double precision, with that bound.
//!
//! What neither decides is reported: the solution is then marked unproved
//! ([`crate::module_fk::Certificate::Unproved`]).

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::dd::Tracked;
use crate::interval::Iv;
use crate::machine::ModuleGeometry;
use crate::module_geometry::{ModulePose, Sliders};
use crate::scalar::{Mag, Scalar};

/// a c0 + cc cos(alpha) + cs sin(alpha).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lin<T> {
    pub c0: T,
    pub cc: T,
    pub cs: T,
}

impl<T: Scalar> Lin<T> {
    fn new(c0: T, cc: T, cs: T) -> Lin<T> {
        Lin { c0, cc, cs }
    }

    /// The value at (sin, cos).
    #[inline]
    pub fn at(&self, s: T, c: T) -> T {
        self.c0 + self.cc * c + self.cs * s
    }

    /// The derivative in alpha at (sin, cos).
    #[inline]
    pub fn d_at(&self, s: T, c: T) -> T {
        self.cs * c - self.cc * s
    }
}

/// The linear trigonometric forms of the elimination of [`crate::module_fk`] (its module
/// documentation), for one set of slider positions, in any arithmetic.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Forms<T> {
    /// The right side of (6) - (5).
    pub b: Lin<T>,
    /// Twice the left side of condition (21).
    pub det: Lin<T>,
    pub a: Lin<T>,
    pub q: Lin<T>,
    /// R1^2 + r1^2 - 2 R1 r1 cos a.
    pub n: Lin<T>,
    /// L1^2 - R1^2 - r1^2 + 2 R1 r1 cos a (eq. (10)).
    pub k1: Lin<T>,
    /// (D2 - d2) - (D1 - d1).
    pub delta: T,
}

/// The forms of the elimination, each input taken as exact and every operation done in `T`
/// (the same formulas as [`crate::module_fk`]'s `Elimination::new`).
pub(crate) fn forms<T: Scalar>(g: &ModuleGeometry, rho: &Sliders) -> Forms<T> {
    let t = |x: f64| T::from(x);
    let (r, rr, r2, r4) = (t(g.r_big1), t(g.r_small1), t(g.r_big2), t(g.r4));
    let (l1, l2, l3) = (t(g.l1), t(g.l2), t(g.l3));
    let zero = t(0.0);
    let p2 = t(rho.y) - t(rho.x);
    let p3 = t(rho.z) - t(rho.x);
    let delta = t(g.dx2) - t(g.dx1);
    let k0 = l1 * l1 - r * r - rr * rr;
    let two = t(2.0);
    let four = t(4.0);
    Forms {
        b: Lin::new(
            l3 * l3 - l2 * l2 + (p2 + p3) * (p2 - p3),
            zero,
            two * r2 * (p2 + p3),
        ),
        det: Lin::new(
            -(two * rr * (p2 - p3)),
            two * r * (p2 - p3),
            four * (r * r4 - rr * r2),
        ),
        a: Lin::new(
            l2 * l2 - k0 - delta * delta - r2 * r2 - r4 * r4 - p2 * p2,
            two * r2 * r4 - two * r * rr,
            -(two * r2 * p2),
        ),
        q: Lin::new(-(rr * p2), r * p2, r * r4 - rr * r2),
        n: Lin::new(r * r + rr * rr, -(two * r * rr), zero),
        k1: Lin::new(k0, two * r * rr, zero),
        delta,
    }
}

/// Rounded operations on any path from an input to a coefficient of F, and on to its value at
/// a point (a generous count: the coefficient formulas of `Elimination` chain about 60, the
/// evaluation 15).
const CHARACTERISTIC_OPS: f64 = 128.0;

/// A bound on |F(alpha) - F_exact(alpha)| for every alpha, F as `module_fk::characteristic`
/// computes its coefficients in double precision: [`CHARACTERISTIC_OPS`] roundings of the
/// magnitude of F's formula ([`Mag`]), with |lin(alpha)| <= |c0| + |cc| + |cs| for each form
/// (the bound is a norm that products do not increase).
pub fn characteristic_error(g: &ModuleGeometry, rho: &Sliders) -> f64 {
    let m = forms::<Mag>(g, rho);
    let n1 = |l: &Lin<Mag>| l.c0.0 + l.cc.0 + l.cs.0;
    let (a, b, det, q) = (n1(&m.a), n1(&m.b), n1(&m.det), n1(&m.q));
    let u = a * det + 2.0 * b * q;
    let d2 = m.delta.0 * m.delta.0;
    let f_mag = u * u + 4.0 * d2 * (b * b * n1(&m.n) + n1(&m.k1) * det * det);
    CHARACTERISTIC_OPS * f64::EPSILON * f_mag
}

/// tau+- and what they need, at one angle, in arithmetic `T` ([`Forms`]).
struct FactorsAt<T> {
    /// Q^2 + delta^2 N (P / 4).
    p4: T,
    /// Delta: H1 has real roots in tau where it is >= 0.
    disc: T,
    a: T,
    q: T,
    b: T,
    det: T,
}

fn factors_at<T: Scalar>(f: &Forms<T>, s: T, c: T) -> FactorsAt<T> {
    let (a, q, n, k1) = (f.a.at(s, c), f.q.at(s, c), f.n.at(s, c), f.k1.at(s, c));
    let d2 = f.delta * f.delta;
    let p4 = q * q + d2 * n;
    FactorsAt {
        p4,
        disc: T::from(4.0) * k1 * p4 - n * a * a,
        a,
        q,
        b: f.b.at(s, c),
        det: f.det.at(s, c),
    }
}

/// The pose of the assembly mode with tau at (sin a, cos a): (y, zp - rho1) = tau (-R1 s, w),
/// xp + D1 - d1 = (A + 2 tau Q) / (2 delta).
fn pose_from_tau(
    g: &ModuleGeometry,
    rho: &Sliders,
    alpha: f64,
    (s, c): (f64, f64),
    tau: f64,
    fa: &FactorsAt<f64>,
    delta: f64,
) -> ModulePose {
    let y = -g.r_big1 * s * tau;
    let zr = (g.r_big1 * c - g.r_small1) * tau;
    let u = (fa.a + 2.0 * tau * fa.q) / (2.0 * delta);
    ModulePose {
        p: Vector3::new(u - g.dx1, y, zr + rho.x),
        alpha,
    }
}

/// The pose at a root of F where Det is too small for the linear solution (condition (21)): the
/// factor g+- the root belongs to (the smaller |g| there) gives tau and the pose. None where H1
/// has no real root in tau.
pub(crate) fn pose_at_root_by_factors(
    g: &ModuleGeometry,
    rho: &Sliders,
    alpha: f64,
    sc: (f64, f64),
) -> Option<ModulePose> {
    let f = forms::<f64>(g, rho);
    let fa = factors_at(&f, sc.0, sc.1);
    if !(fa.disc >= 0.0 && fa.p4 > 0.0) {
        return None;
    }
    let root = f.delta.abs() * fa.disc.sqrt();
    let tau = [(-fa.a * fa.q + root), (-fa.a * fa.q - root)].map(|n| n / (2.0 * fa.p4));
    let g_of = |t: f64| (t * fa.det - fa.b).abs();
    let tau = if g_of(tau[0]) <= g_of(tau[1]) {
        tau[0]
    } else {
        tau[1]
    };
    Some(pose_from_tau(g, rho, alpha, sc, tau, &fa, f.delta))
}

/// How a hard interval was decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Resolution {
    /// By the two factors of F (interval arithmetic, double precision).
    Factored,
    /// By the degree-8 polynomial in double-double precision.
    Extended,
    /// Not decided.
    Unproved,
}

/// A proved root with the start pose of its mode.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProvedStart {
    pub pose: ModulePose,
    pub sc: (f64, f64),
}

/// Deepest bisection of a hard interval (from pi / 16 down to rounding).
const MAX_SPLIT_DEPTH: u32 = 64;

/// Decides each interval of `ambiguous` (alpha, rad; from `Trig::roots_certified`), pushing the
/// start pose of every mode it proves there into `starts`, and returns the strongest method it
/// needed. `fallback` receives best-effort starts where nothing could be proved.
#[cold]
#[inline(never)]
pub(crate) fn resolve(
    g: &ModuleGeometry,
    rho: &Sliders,
    ambiguous: &[[f64; 2]],
    starts: &mut ArrayVec<ProvedStart, 40>,
    fallback: &mut ArrayVec<ProvedStart, 40>,
) -> Resolution {
    let fi = forms::<Iv>(g, rho);
    let ff = forms::<f64>(g, rho);
    let mut worst = Resolution::Factored;
    // A root at alpha = +-pi sits at the ends of the circle's parametrization: the pieces at both
    // ends make one interval across pi (sin and cos are periodic; the roots are wrapped later).
    let mut pieces: ArrayVec<[f64; 2], { crate::trig::MAX_AMBIGUOUS }> =
        ambiguous.iter().copied().collect();
    let (first, last) = (pieces.first().copied(), pieces.last().copied());
    if let (Some(f), Some(l)) = (first, last) {
        use std::f64::consts::{PI, TAU};
        if pieces.len() > 1 && f[0] <= -PI && l[1] >= PI {
            pieces.remove(0);
            if let Some(l) = pieces.last_mut() {
                l[1] = f[1] + TAU;
            }
        }
    }
    for &[lo, hi] in &pieces {
        let mut found: ArrayVec<ProvedStart, 16> = ArrayVec::new();
        let by_factors = [1.0, -1.0]
            .into_iter()
            .try_for_each(|sigma| factor_roots(g, rho, &fi, &ff, sigma, lo, hi, 0, &mut found));
        if by_factors.is_ok() {
            push_all(starts, &found);
            continue;
        }
        found.clear();
        let tf = forms::<Tracked>(g, rho);
        let mut undecided = false;
        for (clo, chi) in chart_pieces(lo, hi) {
            if dd_chart_roots(&tf, clo, chi, &mut found).is_err() {
                undecided = true;
            }
        }
        let as_starts = |found: &ArrayVec<ProvedStart, 16>| -> ArrayVec<ProvedStart, 16> {
            found
                .iter()
                .filter_map(|r| {
                    start_at(g, rho, r.pose.alpha, r.sc).map(|pose| ProvedStart { pose, sc: r.sc })
                })
                .collect()
        };
        if undecided {
            worst = Resolution::Unproved;
            push_all(fallback, &as_starts(&found));
            // Best effort where nothing is proved: the midpoint of the interval, and the
            // fixed-angle points there.
            let mid = 0.5 * (lo + hi);
            let sc = mid.sin_cos();
            if let Some(pose) = start_at(g, rho, mid, sc) {
                let _ = fallback.try_push(ProvedStart { pose, sc });
            }
        } else {
            worst = worst.max(Resolution::Extended);
            push_all(starts, &as_starts(&found));
        }
    }
    worst
}

fn push_all<const N: usize, const M: usize>(
    to: &mut ArrayVec<ProvedStart, N>,
    from: &ArrayVec<ProvedStart, M>,
) {
    for s in from {
        let _ = to.try_push(*s);
    }
}

/// The start pose for a root at alpha: the linear solution of the elimination, or the factor's
/// where Det is small.
fn start_at(g: &ModuleGeometry, rho: &Sliders, alpha: f64, sc: (f64, f64)) -> Option<ModulePose> {
    let f = forms::<f64>(g, rho);
    let det = f.det.at(sc.0, sc.1);
    let det_scale = f.det.c0.abs() + f.det.cc.abs() + f.det.cs.abs();
    if det.abs() > crate::tolerance::FK_DET_REL * det_scale {
        let fa = factors_at(&f, sc.0, sc.1);
        let tau = fa.b / det;
        return Some(pose_from_tau(g, rho, alpha, sc, tau, &fa, f.delta));
    }
    pose_at_root_by_factors(g, rho, alpha, sc)
}

/// g_sigma = tau_sigma Det - b and its derivative over (sin, cos) in interval arithmetic, where
/// Delta >= 0 (where Delta < 0 there is no solution: the enclosures hold for the angles that can
/// have one; the derivative's is unbounded where Delta is not proved positive). None where P is
/// not proved positive; `Some(Err(()))` where Delta is proved negative: no solution there.
#[allow(clippy::type_complexity)]
fn factor_over(f: &Forms<Iv>, sigma: f64, s: Iv, c: Iv) -> Option<Result<(Iv, Iv), ()>> {
    let fa = factors_at(f, s, c);
    if fa.disc.negative() {
        return Some(Err(()));
    }
    if !fa.p4.positive() {
        return None;
    }
    // Solutions exist only where Delta >= 0: g is bounded there with Delta's enclosure cut at
    // zero (its derivative is then unbounded: only an exclusion can be proved).
    let disc = Iv::new(fa.disc.lo.max(0.0), fa.disc.hi);
    let root = f.delta.abs_iv() * disc.sqrt() * Iv::point(sigma);
    let tau = (-(fa.a * fa.q) + root) / (Iv::point(2.0) * fa.p4);
    let g = tau * fa.det - fa.b;
    // tau' = -(P' tau^2 + R' tau + S') / (2 P tau + R), 2 P tau + R = sigma 4 |delta| sqrt(Delta)
    // (implicit differentiation of H1 = 0); P = 4 p4, R = 4 A Q, S = A^2 - 4 delta^2 K1.
    let (da, dq, dn, dk1) = (
        f.a.d_at(s, c),
        f.q.d_at(s, c),
        f.n.d_at(s, c),
        f.k1.d_at(s, c),
    );
    let d2 = f.delta * f.delta;
    let four = Iv::point(4.0);
    let dp = four * (Iv::point(2.0) * fa.q * dq + d2 * dn);
    let dr = four * (da * fa.q + fa.a * dq);
    let ds = Iv::point(2.0) * fa.a * da - four * d2 * dk1;
    let dtau = -(dp * tau.sqr() + dr * tau + ds) / (four * root);
    let dg = dtau * fa.det + tau * f.det.d_at(s, c) - f.b.d_at(s, c);
    Some(Ok((g, dg)))
}

impl Iv {
    fn abs_iv(self) -> Iv {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Iv::new(0.0, self.mag())
        }
    }
}

/// The sign of g_sigma at the angle x, proved; None when not proved.
fn factor_sign_at(f: &Forms<Iv>, sigma: f64, x: f64) -> Option<i8> {
    let (s, c) = Iv::point(x).sin_cos();
    match factor_over(f, sigma, s, c)? {
        Ok((g, _)) => g.sign(),
        Err(()) => None,
    }
}

/// The roots of g_sigma in [lo, hi], each as a proved start, by bisection until g_sigma is proved
/// monotone (or Delta negative: no root) on each piece. Err where neither can be proved.
#[allow(clippy::too_many_arguments)]
fn factor_roots(
    g: &ModuleGeometry,
    rho: &Sliders,
    fi: &Forms<Iv>,
    ff: &Forms<f64>,
    sigma: f64,
    lo: f64,
    hi: f64,
    depth: u32,
    out: &mut ArrayVec<ProvedStart, 16>,
) -> Result<(), ()> {
    let (s, c) = Iv::new(lo, hi).sin_cos();
    match factor_over(fi, sigma, s, c) {
        // Delta < 0 (no solution at these angles), or g_sigma proved nonzero.
        Some(Err(())) => return Ok(()),
        Some(Ok((gv, _))) if gv.sign().is_some() => return Ok(()),
        Some(Ok((_, dg))) if dg.sign().is_some() => {
            let (sa, sb) = (
                factor_sign_at(fi, sigma, lo).ok_or(())?,
                factor_sign_at(fi, sigma, hi).ok_or(())?,
            );
            if sa != sb {
                let x = refine_factor_root(fi, ff, sigma, lo, hi, sa);
                let sc = x.sin_cos();
                let fa = factors_at(ff, sc.0, sc.1);
                let root = ff.delta.abs() * fa.disc.max(0.0).sqrt() * sigma;
                let tau = (-fa.a * fa.q + root) / (2.0 * fa.p4);
                let pose = pose_from_tau(g, rho, x, sc, tau, &fa, ff.delta);
                out.try_push(ProvedStart { pose, sc }).map_err(|_| ())?;
            }
            return Ok(());
        }
        _ => {}
    }
    if depth >= MAX_SPLIT_DEPTH || hi - lo <= 4.0 * f64::EPSILON * lo.abs().max(hi.abs()) {
        return Err(());
    }
    // Split where the sign can be proved (not on a root: alpha = 0 is both a grid point and,
    // on symmetric sliders, a root).
    let mid = [0.5, 0.3, 0.7]
        .into_iter()
        .map(|k| lo + k * (hi - lo))
        .find(|&x| factor_sign_at(fi, sigma, x).is_some())
        .unwrap_or(0.5 * (lo + hi));
    factor_roots(g, rho, fi, ff, sigma, lo, mid, depth + 1, out)?;
    factor_roots(g, rho, fi, ff, sigma, mid, hi, depth + 1, out)
}

/// g_sigma and its derivative at (sin, cos) in double precision (for the refinement only: the
/// proof is in interval arithmetic).
fn factor_value(f: &Forms<f64>, sigma: f64, s: f64, c: f64) -> Option<(f64, f64)> {
    let fa = factors_at(f, s, c);
    if !(fa.disc > 0.0 && fa.p4 > 0.0) {
        return None;
    }
    let root = f.delta.abs() * fa.disc.sqrt() * sigma;
    let tau = (-(fa.a * fa.q) + root) / (2.0 * fa.p4);
    let (da, dq, dn, dk1) = (
        f.a.d_at(s, c),
        f.q.d_at(s, c),
        f.n.d_at(s, c),
        f.k1.d_at(s, c),
    );
    let d2 = f.delta * f.delta;
    let dp = 4.0 * (2.0 * fa.q * dq + d2 * dn);
    let dr = 4.0 * (da * fa.q + fa.a * dq);
    let ds = 2.0 * fa.a * da - 4.0 * d2 * dk1;
    let dtau = -(dp * tau * tau + dr * tau + ds) / (4.0 * root);
    Some((
        tau * fa.det - fa.b,
        dtau * fa.det + tau * f.det.d_at(s, c) - f.b.d_at(s, c),
    ))
}

/// The root of g_sigma, proved monotone on [lo, hi] with the sign `sign_lo` at lo and the other
/// at hi: Newton steps in double precision inside the bracket, then the bracket proved around
/// the estimate (its neighbours a few units away have proved opposite signs); bisection on
/// proved signs where that fails, down to rounding (or to a midpoint whose sign cannot be
/// proved: within rounding of the root).
fn refine_factor_root(
    f: &Forms<Iv>,
    ff: &Forms<f64>,
    sigma: f64,
    mut lo: f64,
    mut hi: f64,
    sign_lo: i8,
) -> f64 {
    let mut x = 0.5 * (lo + hi);
    let mut slope = 0.0;
    for _ in 0..8 {
        let (s, c) = x.sin_cos();
        let Some((gv, dg)) = factor_value(ff, sigma, s, c) else {
            break;
        };
        slope = dg;
        let next = x - gv / dg;
        if !(next > lo && next < hi) {
            break;
        }
        let done = (next - x).abs() <= 2.0 * f64::EPSILON * x.abs().max(1e-300);
        x = next;
        if done {
            break;
        }
    }
    // The width of g's enclosure at a point, over its slope: how far from the root its sign
    // can first be proved.
    let (s, c) = Iv::point(x).sin_cos();
    if let Some(Ok((gx, _))) = factor_over(f, sigma, s, c) {
        let step = 4.0 * (gx.hi - gx.lo) / slope.abs() + 4.0 * f64::EPSILON * x.abs();
        let (a, b) = (x - step, x + step);
        if a > lo
            && b < hi
            && factor_sign_at(f, sigma, a) == Some(sign_lo)
            && factor_sign_at(f, sigma, b) == Some(-sign_lo)
        {
            return x;
        }
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        match factor_sign_at(f, sigma, mid) {
            Some(sg) if sg == sign_lo => lo = mid,
            Some(_) => hi = mid,
            None => return mid,
        }
    }
    0.5 * (lo + hi)
}

/// The pieces of [lo, hi] in each half-angle chart: alpha in [-pi/2, pi/2] (t = tan(a/2)) and
/// beyond (t = tan((a -+ pi)/2)), as (lo, hi) pairs of alpha.
fn chart_pieces(lo: f64, hi: f64) -> ArrayVec<(f64, f64), 3> {
    use std::f64::consts::FRAC_PI_2;
    let mut out = ArrayVec::new();
    let cuts = [-FRAC_PI_2, FRAC_PI_2];
    let mut a = lo;
    for cut in cuts {
        if a < cut && hi > cut {
            out.push((a, cut));
            a = cut;
        }
    }
    out.push((a, hi));
    out
}

/// A polynomial of degree at most 8 in t, lowest degree first, in double-double with magnitudes.
type Poly8 = [Tracked; 9];

/// Operations on any path from an input to a coefficient of the half-angle polynomial (about
/// 30) and on through a Horner evaluation of it or of a derivative (about 20): a generous count.
const HALF_ANGLE_OPS: u32 = 96;

/// (1 + t^2)^4 F as a polynomial in t: t = tan(alpha / 2) for the chart at 0, t = tan((alpha -
/// pi) / 2) for the chart at pi (cos and sin change sign). Each linear form l0 + lc c + ls s
/// becomes (1 + t^2) times itself: (l0 + lc) + 2 ls t + (l0 - lc) t^2 (at pi: (l0 - lc) - 2 ls
/// t + (l0 + lc) t^2); then U = A Det + 2 b Q (degree 4) and
/// (1 + t^2)^4 F = U^2 + 4 delta^2 (1 + t^2) (b^2 N - K1 Det^2).
fn half_angle_poly(f: &Forms<Tracked>, at_pi: bool) -> Poly8 {
    let quad = |l: &Lin<Tracked>| -> [Tracked; 3] {
        if at_pi {
            [l.c0 - l.cc, -(l.cs * 2.0), l.c0 + l.cc]
        } else {
            [l.c0 + l.cc, l.cs * 2.0, l.c0 - l.cc]
        }
    };
    let (a, b, det, q, n, k1) = (
        quad(&f.a),
        quad(&f.b),
        quad(&f.det),
        quad(&f.q),
        quad(&f.n),
        quad(&f.k1),
    );
    let u = add::<5>(
        &mul::<3, 3, 5>(&a, &det),
        &scale(&mul::<3, 3, 5>(&b, &q), 2.0),
    );
    let b2n = mul::<5, 3, 7>(&mul::<3, 3, 5>(&b, &b), &n);
    let k1d2 = mul::<3, 5, 7>(&k1, &mul::<3, 3, 5>(&det, &det));
    let inner = mul::<7, 3, 9>(
        &add::<7>(&b2n, &scale(&k1d2, -1.0)),
        &[
            Tracked::exact(1.0),
            Tracked::exact(0.0),
            Tracked::exact(1.0),
        ],
    );
    let d2 = f.delta * f.delta * 4.0;
    add::<9>(&mul::<5, 5, 9>(&u, &u), &inner.map(|x| x * d2))
}

fn mul<const A: usize, const B: usize, const C: usize>(
    p: &[Tracked; A],
    q: &[Tracked; B],
) -> [Tracked; C] {
    debug_assert!(A + B - 1 == C);
    let mut r = [Tracked::exact(0.0); C];
    for i in 0..A {
        for j in 0..B {
            r[i + j] = r[i + j] + p[i] * q[j];
        }
    }
    r
}

fn add<const N: usize>(p: &[Tracked; N], q: &[Tracked; N]) -> [Tracked; N] {
    std::array::from_fn(|i| p[i] + q[i])
}

fn scale<const N: usize>(p: &[Tracked; N], k: f64) -> [Tracked; N] {
    p.map(|x| x * k)
}

/// The value of `p` (its first `n` coefficients) at t, with a bound on its error.
fn horner(p: &[Tracked], t: f64) -> (f64, f64) {
    let tt = Tracked::exact(t);
    let mut acc = Tracked::exact(0.0);
    for c in p.iter().rev() {
        acc = acc * tt + *c;
    }
    // The value rounded to double precision: its own rounding joins the bound.
    let v = acc.v.to_f64();
    (v, acc.error(HALF_ANGLE_OPS) + v.abs() * f64::EPSILON)
}

fn derivative(p: &[Tracked]) -> ArrayVec<Tracked, 9> {
    p.iter()
        .enumerate()
        .skip(1)
        .map(|(k, c)| *c * k as f64)
        .collect()
}

/// An upper bound on |p(t)| for |t| <= tmax: sum |p_k| tmax^k with each |p_k| raised by its
/// error bound.
fn bound_on(p: &[Tracked], tmax: f64) -> f64 {
    let mut acc = 0.0;
    for c in p.iter().rev() {
        acc = acc * tmax + c.v.to_f64().abs() + c.error(HALF_ANGLE_OPS);
    }
    acc * (1.0 + 1e-12)
}

/// The proved roots of F in [lo, hi] (alpha, inside one chart) from the half-angle polynomial
/// in double-double; Err where an interval stays undecided down to rounding.
fn dd_chart_roots(
    f: &Forms<Tracked>,
    lo: f64,
    hi: f64,
    out: &mut ArrayVec<ProvedStart, 16>,
) -> Result<(), ()> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let at_pi = lo < -FRAC_PI_2 || hi > FRAC_PI_2;
    let centre = if !at_pi {
        0.0
    } else if lo < 0.0 {
        -PI
    } else {
        PI
    };
    let p = half_angle_poly(f, at_pi);
    let d1 = derivative(&p);
    let d2 = derivative(&d1);
    let d3 = derivative(&d2);
    let t_of = |x: f64| (0.5 * (x - centre)).tan();
    // The chart's ends, widened by a few units: the neighbours of [lo, hi] are proved root-free
    // near it, so the overlap holds no root of theirs.
    let widen = |t: f64, dir: f64| t + dir * 4.0 * f64::EPSILON * t.abs().max(1e-300);
    let (ta, tb) = (widen(t_of(lo), -1.0), widen(t_of(hi), 1.0));
    let mut roots: ArrayVec<f64, 16> = ArrayVec::new();
    let (a, b) = (dd_pt(&p, &d1, ta), dd_pt(&p, &d1, tb));
    dd_isolate(&p, &d1, &d2, &d3, a, b, 0, &mut roots)?;
    for t in roots {
        let alpha = crate::module_ik::wrap_angle(centre + 2.0 * t.atan());
        let sc = alpha.sin_cos();
        out.try_push(ProvedStart {
            pose: ModulePose {
                p: Vector3::zeros(),
                alpha,
            },
            sc,
        })
        .map_err(|_| ())?;
    }
    Ok(())
}

/// A point of the half-angle chart with p and p' there, each with its error bound.
#[derive(Debug, Clone, Copy)]
struct DdPt {
    t: f64,
    p: (f64, f64),
    d: (f64, f64),
}

fn dd_pt(p: &Poly8, d1: &[Tracked], t: f64) -> DdPt {
    DdPt {
        t,
        p: horner(p, t),
        d: horner(d1, t),
    }
}

/// Both values beyond `bound` (plus their own errors) on the same side of zero.
fn same_side(u: (f64, f64), v: (f64, f64), bound: f64) -> bool {
    (u.0 - u.1 > bound && v.0 - v.1 > bound) || (u.0 + u.1 < -bound && v.0 + v.1 < -bound)
}

/// On [a, b], a function g with |g''| <= M stays within h^2 M / 8 of its chord (h = b - a):
/// with both end values beyond that on one side of zero, g has no zero there. Applied to p (no
/// root) and to its derivative (p monotone: one root exactly where p changes sign), bisecting
/// what neither decides; the bounds on the second and third derivatives come from the
/// coefficients' magnitudes at max |t|.
#[allow(clippy::too_many_arguments)]
fn dd_isolate(
    p: &Poly8,
    d1: &[Tracked],
    d2: &[Tracked],
    d3: &[Tracked],
    a: DdPt,
    b: DdPt,
    depth: u32,
    roots: &mut ArrayVec<f64, 16>,
) -> Result<(), ()> {
    let tmax = a.t.abs().max(b.t.abs());
    let h = b.t - a.t;
    let chord = 0.125 * h * h;
    if same_side(a.p, b.p, chord * bound_on(d2, tmax)) {
        return Ok(());
    }
    if same_side(a.d, b.d, chord * bound_on(d3, tmax)) {
        // Monotone: one root where the ends' signs differ (proved), none where they agree.
        let sign = |v: (f64, f64)| (v.0.abs() > v.1).then_some(v.0 < 0.0);
        if let (Some(na), Some(nb)) = (sign(a.p), sign(b.p)) {
            if na != nb {
                let t = refine_dd_root(p, d1, a.t, b.t, na);
                roots.try_push(t).map_err(|_| ())?;
            }
            return Ok(());
        }
    }
    if depth >= MAX_SPLIT_DEPTH || h <= 4.0 * f64::EPSILON * tmax.max(1e-300) {
        return Err(());
    }
    // Split where the sign of p can be proved.
    let m = [0.5, 0.3, 0.7]
        .into_iter()
        .map(|k| dd_pt(p, d1, a.t + k * h))
        .find(|m| m.p.0.abs() > m.p.1)
        .unwrap_or_else(|| dd_pt(p, d1, a.t + 0.5 * h));
    dd_isolate(p, d1, d2, d3, a, m, depth + 1, roots)?;
    dd_isolate(p, d1, d2, d3, m, b, depth + 1, roots)
}

/// The root of p in [a, b] (p monotone there, negative at a when `neg_at_a`): Newton steps from
/// double-double values, kept inside the bracket (bisection otherwise), until the bracket is at
/// rounding or the sign of p cannot be proved.
fn refine_dd_root(p: &Poly8, d1: &[Tracked], mut a: f64, mut b: f64, neg_at_a: bool) -> f64 {
    let mut x = 0.5 * (a + b);
    for _ in 0..100 {
        let (v, e) = horner(p, x);
        if v.abs() <= e {
            return x;
        }
        if (v < 0.0) == neg_at_a {
            a = x;
        } else {
            b = x;
        }
        if b - a <= 2.0 * f64::EPSILON * a.abs().max(b.abs()) {
            break;
        }
        let (d, _) = horner(d1, x);
        let next = x - v / d;
        x = if next > a && next < b {
            next
        } else {
            0.5 * (a + b)
        };
    }
    x
}

/// Convenience for tests: the roots of the factors alone, as angles, over [lo, hi].
#[doc(hidden)]
pub fn factor_root_angles(g: &ModuleGeometry, rho: &Sliders, lo: f64, hi: f64) -> Option<Vec<f64>> {
    let fi = forms::<Iv>(g, rho);
    let ff = forms::<f64>(g, rho);
    let mut out = ArrayVec::new();
    for sigma in [1.0, -1.0] {
        factor_roots(g, rho, &fi, &ff, sigma, lo, hi, 0, &mut out).ok()?;
    }
    Some(out.iter().map(|s| s.pose.alpha).collect())
}

/// For tests: the proved roots of F over [lo, hi] in double-double, as angles.
#[doc(hidden)]
pub fn dd_root_angles(g: &ModuleGeometry, rho: &Sliders, lo: f64, hi: f64) -> Option<Vec<f64>> {
    let tf = forms::<Tracked>(g, rho);
    let mut out = ArrayVec::new();
    for (clo, chi) in chart_pieces(lo, hi) {
        dd_chart_roots(&tf, clo, chi, &mut out).ok()?;
    }
    Some(out.iter().map(|s| s.pose.alpha).collect())
}
