//! What the root finders of the solvers do where double precision alone cannot prove that they
//! found every root: on the intervals of the angle that [`crate::math::trig::Trig::roots_certified`]
//! left undecided. Shared by the forward kinematics of the module ([`crate::parallel_module::fk_certify`]) and the
//! machine's inverse kinematics ([`crate::machine`]).
//!
//! Both eliminate to an equation F(angle) = 0 whose close or double roots come from a product:
//! F = P g+ g-, two factors each with a simple root where F has a near-double one (the two
//! intersections of a line and a sphere for the forward kinematics, the two signs of rho1 - zp
//! for the machine's). The first method isolates each factor's roots: interval arithmetic over a
//! piece of the angle ([`crate::math::interval`]) proves the factor monotone there, or excludes it, and
//! its signs at the ends are proved ([`factor_roots`]). The second recomputes F in
//! double-double precision as the half-angle polynomial of the papers and isolates its roots with
//! the same kind of tests ([`dd_roots`]). What neither decides is reported, never guessed.

use arrayvec::ArrayVec;

use crate::math::dd::Tracked;
use crate::math::interval::Iv;
use crate::math::scalar::Scalar;

/// c0 + cc cos(x) + cs sin(x), in any arithmetic.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lin<T> {
    pub c0: T,
    pub cc: T,
    pub cs: T,
}

impl<T: Scalar> Lin<T> {
    pub fn new(c0: T, cc: T, cs: T) -> Lin<T> {
        Lin { c0, cc, cs }
    }

    /// The value at (sin, cos).
    #[inline]
    pub fn at(&self, s: T, c: T) -> T {
        self.c0 + self.cc * c + self.cs * s
    }

    /// The derivative in x at (sin, cos).
    #[inline]
    pub fn d_at(&self, s: T, c: T) -> T {
        self.cs * c - self.cc * s
    }
}

/// How an undecided interval was decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Resolution {
    /// By the two factors (interval arithmetic on double-precision inputs).
    Factored,
    /// By the half-angle polynomial in double-double precision.
    Extended,
    /// Not decided.
    Unproved,
}

/// What interval arithmetic proves about one factor over an interval of the angle.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Enclosure {
    /// No solution has its angle there (the factor's radicand is proved negative).
    NoSolution,
    /// Enclosures of the factor and of its derivative, valid wherever a solution can be.
    Values { g: Iv, dg: Iv },
    /// Nothing proved.
    Unknown,
}

/// One factor g of an eliminated equation, as a function of the angle.
pub(crate) trait Factor {
    /// [`Enclosure`] of g over the angles [lo, hi] (lo = hi: one angle).
    fn over(&self, lo: f64, hi: f64) -> Enclosure;
    /// g and g' at an angle in double precision: for Newton's steps only, never for a proof.
    fn value(&self, x: f64) -> Option<(f64, f64)>;
}

/// The sign of g at x, when proved.
fn sign_at(f: &impl Factor, x: f64) -> Option<i8> {
    match f.over(x, x) {
        Enclosure::Values { g, .. } => g.sign(),
        _ => None,
    }
}

/// Deepest bisection of an undecided interval (from pi / 16 down to rounding).
const MAX_SPLIT_DEPTH: u32 = 64;

/// Most pieces one isolation examines: bisection goes deep only around roots (a few dozen pieces
/// each), so this is reached only where nothing can be proved anywhere (inputs that overflow).
const MAX_PIECES: u32 = 4096;

/// Every root of the factor in [lo, hi], by bisection until, on each piece, g is proved nonzero
/// (or no solution is possible there) or proved monotone with proved signs at the ends (one root
/// where they differ). Err where some piece stays undecided down to rounding.
pub(crate) fn factor_roots(
    f: &impl Factor,
    lo: f64,
    hi: f64,
    depth: u32,
    budget: &mut u32,
    out: &mut ArrayVec<f64, 16>,
) -> Result<(), ()> {
    *budget = budget.checked_sub(1).ok_or(())?;
    match f.over(lo, hi) {
        Enclosure::NoSolution => return Ok(()),
        Enclosure::Values { g, .. } if g.sign().is_some() => return Ok(()),
        Enclosure::Values { dg, .. } if dg.sign().is_some() => {
            let (sa, sb) = (sign_at(f, lo).ok_or(())?, sign_at(f, hi).ok_or(())?);
            if sa != sb {
                out.try_push(refine_root(f, lo, hi, sa)).map_err(|_| ())?;
            }
            return Ok(());
        }
        _ => {}
    }
    if depth >= MAX_SPLIT_DEPTH || hi - lo <= 4.0 * f64::EPSILON * lo.abs().max(hi.abs()) {
        return Err(());
    }
    // Split where the sign can be proved (not on a root: a grid point can be one); else in
    // the middle (a piece with an end of unproved sign is then decided only by exclusion).
    let mid = [0.5, 0.3, 0.7, 0.4, 0.6, 0.2, 0.8]
        .into_iter()
        .map(|k| lo + k * (hi - lo))
        .find(|&x| sign_at(f, x).is_some())
        .unwrap_or(0.5 * (lo + hi));
    factor_roots(f, lo, mid, depth + 1, budget, out)?;
    factor_roots(f, mid, hi, depth + 1, budget, out)
}

/// The root of g, proved monotone on [lo, hi] with the sign `sign_lo` at lo and the other at hi:
/// Newton steps in double precision inside the bracket, then the bracket proved around the
/// estimate (points at the distance where g's enclosure first allows a sign have proved opposite
/// signs); bisection on proved signs where that fails, down to rounding (or to a midpoint whose
/// sign cannot be proved: within rounding of the root).
fn refine_root(f: &impl Factor, mut lo: f64, mut hi: f64, sign_lo: i8) -> f64 {
    let mut x = 0.5 * (lo + hi);
    let mut slope = 0.0;
    for _ in 0..8 {
        let Some((gv, dg)) = f.value(x) else {
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
    if let Enclosure::Values { g, .. } = f.over(x, x) {
        let step = 4.0 * (g.hi - g.lo) / slope.abs() + 4.0 * f64::EPSILON * x.abs();
        let (a, b) = (x - step, x + step);
        if a > lo && b < hi && sign_at(f, a) == Some(sign_lo) && sign_at(f, b) == Some(-sign_lo) {
            return x;
        }
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        match sign_at(f, mid) {
            Some(sg) if sg == sign_lo => lo = mid,
            Some(_) => hi = mid,
            None => return mid,
        }
    }
    0.5 * (lo + hi)
}

/// The undecided intervals of a circle isolation as the pieces to decide: the pieces at -pi and
/// at pi (a root at pi sits at the ends of the parametrization) joined into one across pi
/// (angles beyond pi: sin and cos are periodic; the caller wraps the roots).
pub(crate) fn pieces(
    ambiguous: &[[f64; 2]],
) -> ArrayVec<[f64; 2], { crate::math::trig::MAX_AMBIGUOUS }> {
    use std::f64::consts::{PI, TAU};
    let mut out: ArrayVec<[f64; 2], { crate::math::trig::MAX_AMBIGUOUS }> =
        ambiguous.iter().copied().collect();
    if let (Some(f), Some(l)) = (out.first().copied(), out.last().copied()) {
        if out.len() > 1 && f[0] <= -PI && l[1] >= PI {
            out.remove(0);
            if let Some(l) = out.last_mut() {
                l[1] = f[1] + TAU;
            }
        }
    }
    out
}

/// Proves the factors' roots on one piece: the roots of every factor, or Err.
pub(crate) fn all_factor_roots<F: Factor>(
    factors: &[F],
    lo: f64,
    hi: f64,
) -> Result<ArrayVec<(usize, f64), 16>, ()> {
    let mut out = ArrayVec::new();
    for (k, f) in factors.iter().enumerate() {
        let (mut roots, mut budget) = (ArrayVec::new(), MAX_PIECES);
        factor_roots(f, lo, hi, 0, &mut budget, &mut roots)?;
        for r in roots {
            out.try_push((k, r)).map_err(|_| ())?;
        }
    }
    Ok(out)
}

// ------------------------------------------------------------------ double-double polynomials

/// A polynomial of degree at most 8 in t, lowest degree first, in double-double with magnitudes
/// (the forward kinematics' degree 8; the machine's degree 6 times 1 + t^2).
pub(crate) type Poly8 = [Tracked; 9];

/// Operations on any path from an input to a coefficient of a half-angle polynomial (about 30)
/// and on through a Horner evaluation of it or of a derivative (about 20): a generous count.
const HALF_ANGLE_OPS: u32 = 96;

/// (1 + t^2) l(x) for a linear form l as a quadratic in t: t = tan(x / 2) for the chart at 0,
/// t = tan((x - pi) / 2) for the chart at pi (where cos and sin change sign):
/// (l0 + lc) + 2 ls t + (l0 - lc) t^2, or (l0 - lc) - 2 ls t + (l0 + lc) t^2.
pub(crate) fn quad(l: &Lin<Tracked>, at_pi: bool) -> [Tracked; 3] {
    if at_pi {
        [l.c0 - l.cc, -(l.cs * 2.0), l.c0 + l.cc]
    } else {
        [l.c0 + l.cc, l.cs * 2.0, l.c0 - l.cc]
    }
}

/// The product of polynomials of A and B coefficients (C = A + B - 1).
pub(crate) fn mul<const A: usize, const B: usize, const C: usize>(
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

pub(crate) fn add<const N: usize>(p: &[Tracked; N], q: &[Tracked; N]) -> [Tracked; N] {
    std::array::from_fn(|i| p[i] + q[i])
}

pub(crate) fn scale<const N: usize>(p: &[Tracked; N], k: Tracked) -> [Tracked; N] {
    p.map(|x| x * k)
}

/// The value of `p` at t, with a bound on its error (the rounding to double included).
fn horner(p: &[Tracked], t: f64) -> (f64, f64) {
    let tt = Tracked::exact(t);
    let mut acc = Tracked::exact(0.0);
    for c in p.iter().rev() {
        acc = acc * tt + *c;
    }
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

/// The pieces of [lo, hi] in each half-angle chart: x in [-pi/2, pi/2] (t = tan(x/2)) and
/// beyond (t = tan((x -+ pi)/2)).
fn chart_pieces(lo: f64, hi: f64) -> ArrayVec<(f64, f64), 4> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut out = ArrayVec::new();
    let mut a = lo;
    for cut in [-FRAC_PI_2, FRAC_PI_2, PI + FRAC_PI_2] {
        if a < cut && hi > cut {
            out.push((a, cut));
            a = cut;
        }
    }
    out.push((a, hi));
    out
}

/// Width (rad, or in the unknown of a plain polynomial) below which an interval that stays
/// undecided in double-double precision holds at most "one" root: two solutions closer than
/// this are the same solution (as the solvers merge them, `tolerance::SAME_SOLUTION_RAD`).
pub(crate) const SAME_ROOT_WIDTH: f64 = crate::tolerance::SAME_SOLUTION_RAD;

/// What an isolation in double-double proves on an interval: its roots (each simple, proved),
/// and the intervals it could decide down to rounding neither way (a double root, or a pair of
/// roots, or none, closer than double-double can separate).
#[derive(Debug, Clone, Default)]
pub(crate) struct DdRoots {
    pub roots: ArrayVec<f64, 16>,
    pub undecided: ArrayVec<[f64; 2], 8>,
}

impl DdRoots {
    /// Every undecided interval is narrower than [`SAME_ROOT_WIDTH`]: what it holds counts as
    /// at most one solution, which a candidate at its middle finds if it is real.
    pub fn decided_up_to_same_root(&self) -> bool {
        self.undecided
            .iter()
            .all(|[a, b]| (b - a).abs() <= SAME_ROOT_WIDTH)
    }
}

/// Every root of F in [lo, hi] (angles, rad) from its half-angle polynomial in double-double,
/// `poly(at_pi)` giving (1 + t^2)^d F in the chart at 0 or at pi ([`DdRoots`], angles); Err only
/// where there are more than the lists hold.
pub(crate) fn dd_roots(poly: impl Fn(bool) -> Poly8, lo: f64, hi: f64) -> Result<DdRoots, ()> {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut charts: [Option<Poly8>; 2] = [None, None];
    let mut out = DdRoots::default();
    for (clo, chi) in chart_pieces(lo, hi) {
        let mid = 0.5 * (clo + chi);
        let at_pi = !(-FRAC_PI_2..=FRAC_PI_2).contains(&mid);
        let centre = match (at_pi, mid < 0.0) {
            (false, _) => 0.0,
            (true, true) => -PI,
            (true, false) => PI,
        };
        let p = *charts[usize::from(at_pi)].get_or_insert_with(|| poly(at_pi));
        let t_of = |x: f64| (0.5 * (x - centre)).tan();
        // The chart's ends, widened by a few units: the neighbours of [lo, hi] are proved
        // root-free near it, so the overlap holds no root of theirs.
        let widen = |t: f64, dir: f64| t + dir * 4.0 * f64::EPSILON * t.abs().max(1e-300);
        let found = poly_roots(&p, widen(t_of(clo), -1.0), widen(t_of(chi), 1.0))?;
        let angle = |t: f64| centre + 2.0 * t.atan();
        for t in found.roots {
            out.roots.try_push(angle(t)).map_err(|_| ())?;
        }
        for [a, b] in found.undecided {
            out.undecided
                .try_push([angle(a), angle(b)])
                .map_err(|_| ())?;
        }
    }
    Ok(out)
}

/// Every root of the polynomial `p` (double-double with magnitudes, lowest degree first) in
/// [a, b] ([`DdRoots`]); Err only where there are more than the lists hold.
pub(crate) fn poly_roots(p: &[Tracked], a: f64, b: f64) -> Result<DdRoots, ()> {
    let d1 = derivative(p);
    let d2 = derivative(&d1);
    let d3 = derivative(&d2);
    let polys = Polys {
        p,
        d1: &d1,
        d2: &d2,
        d3: &d3,
    };
    let (mut out, mut budget) = (DdRoots::default(), MAX_PIECES);
    polys.isolate(polys.at(a), polys.at(b), 0, &mut budget, &mut out)?;
    Ok(out)
}

/// A polynomial and its first three derivatives.
struct Polys<'a> {
    p: &'a [Tracked],
    d1: &'a [Tracked],
    d2: &'a [Tracked],
    d3: &'a [Tracked],
}

/// A point with p there and its error bound.
#[derive(Debug, Clone, Copy)]
struct DdPt {
    t: f64,
    p: (f64, f64),
}

impl Polys<'_> {
    fn at(&self, t: f64) -> DdPt {
        DdPt {
            t,
            p: horner(self.p, t),
        }
    }

    /// Exclusion (p proved nonzero on [a, b]) and monotonicity (p' proved nonzero: one root
    /// exactly where p changes sign between the ends) by Taylor bounds about the midpoint,
    /// bisecting what neither decides; the bound on the third derivative comes from the
    /// coefficients' magnitudes at max |t|.
    fn isolate(
        &self,
        a: DdPt,
        b: DdPt,
        depth: u32,
        budget: &mut u32,
        out: &mut DdRoots,
    ) -> Result<(), ()> {
        *budget = budget.checked_sub(1).ok_or(())?;
        let tmax = a.t.abs().max(b.t.abs());
        let h = b.t - a.t;
        // Taylor's formula about the midpoint, with the first two derivatives computed there
        // and the third bounded over the interval (r its half-width): p stays within
        // |p'(m)| r + |p''(m)| r^2 / 2 + M3 r^3 / 6 of p(m), and p' within
        // |p''(m)| r + M3 r^2 / 2 of p'(m). Sharper than chord bounds with a global second
        // derivative where p is flat next to a double root (a fold of the kinematics).
        let r = 0.5 * h;
        let mid = a.t + r;
        let (pm, epm) = horner(self.p, mid);
        let (dm, edm) = horner(self.d1, mid);
        let (sm, esm) = horner(self.d2, mid);
        let m3 = bound_on(self.d3, tmax);
        let (dm_hi, sm_hi) = (dm.abs() + edm, sm.abs() + esm);
        if pm.abs() - epm > dm_hi * r + sm_hi * r * r * 0.5 + m3 * r * r * r / 6.0 {
            return Ok(());
        }
        if dm.abs() - edm > sm_hi * r + m3 * r * r * 0.5 {
            // Monotone: one root where the ends' signs differ (proved), none where they agree.
            let sign = |v: (f64, f64)| (v.0.abs() > v.1).then_some(v.0 < 0.0);
            match (sign(a.p), sign(b.p)) {
                (Some(na), Some(nb)) => {
                    if na != nb {
                        let t = self.refine(a.t, b.t, na);
                        out.roots.try_push(t).map_err(|_| ())?;
                    }
                    return Ok(());
                }
                // Both ends within rounding of zero: the whole (monotone) interval is, and holds
                // at most one root that no precision here can place.
                (None, None) => return self.undecided(a.t, b.t, out),
                // One end within rounding: bisection walks to the edge of that band.
                _ => {}
            }
        }
        if depth >= MAX_SPLIT_DEPTH || h <= 4.0 * f64::EPSILON * tmax.max(1e-300) {
            return self.undecided(a.t, b.t, out);
        }
        // Split where the sign of p can be proved.
        let m = [0.5, 0.3, 0.7]
            .into_iter()
            .map(|k| self.at(a.t + k * h))
            .find(|m| m.p.0.abs() > m.p.1)
            .unwrap_or_else(|| self.at(a.t + 0.5 * h));
        self.isolate(a, m, depth + 1, budget, out)?;
        self.isolate(m, b, depth + 1, budget, out)
    }

    /// Records [a, b] as undecided; adjacent undecided pieces make one interval.
    fn undecided(&self, a: f64, b: f64, out: &mut DdRoots) -> Result<(), ()> {
        match out.undecided.last_mut() {
            Some(last) if last[1] >= a => {
                last[1] = b;
                Ok(())
            }
            _ => out.undecided.try_push([a, b]).map_err(|_| ()),
        }
    }

    /// The root of p in [a, b] (p monotone there, negative at a when `neg_at_a`): Newton steps
    /// from double-double values, kept inside the bracket (bisection otherwise), until the
    /// bracket is at rounding or the sign of p cannot be proved.
    fn refine(&self, mut a: f64, mut b: f64, neg_at_a: bool) -> f64 {
        let mut x = 0.5 * (a + b);
        for _ in 0..100 {
            let (v, e) = horner(self.p, x);
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
            let (d, _) = horner(self.d1, x);
            let next = x - v / d;
            x = if next > a && next < b {
                next
            } else {
                0.5 * (a + b)
            };
        }
        x
    }
}

/// For the factors' tests (leg I's and the forward kinematics'): whether `v` lies in `iv`
/// widened for the double evaluation's rounding (four times its width and 1e-12 relative).
#[cfg(test)]
pub(crate) fn within_enclosure(v: f64, iv: Iv) -> bool {
    let slack = 4.0 * (iv.hi - iv.lo) + 1e-12 * iv.lo.abs().max(iv.hi.abs());
    v >= iv.lo - slack && v <= iv.hi + slack
}

/// For the factors' tests: a factor's double-precision value and slope at `x` against its
/// enclosure over [x, x]. `Ok(Some(true))` where both give values and the values lie in the
/// enclosures ([`within_enclosure`]), `Ok(Some(false))` where the enclosure proves no solution
/// and `value` gives nothing, `Ok(None)` where there is nothing to compare, and `Err` (what
/// disagreed) otherwise.
#[cfg(test)]
pub(crate) fn value_against_enclosure(f: &impl Factor, x: f64) -> Result<Option<bool>, String> {
    match (f.over(x, x), f.value(x)) {
        (Enclosure::Values { g, dg }, Some((v, d))) => {
            if within_enclosure(v, g) && within_enclosure(d, dg) {
                Ok(Some(true))
            } else {
                Err(format!("({v}, {d}) against {g:?}, {dg:?}"))
            }
        }
        (Enclosure::NoSolution, None) => Ok(Some(false)),
        (Enclosure::NoSolution, v) => Err(format!("{v:?} where no solution is proved")),
        _ => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (t - 1/4)(t - 1/4 - 1e-13) as a double-double polynomial: between its roots it is
    /// -2.5e-27, far below the rounding of its coefficients in double precision (about 1e-17),
    /// yet both roots are proved and found.
    #[test]
    fn double_double_separates_a_pair_double_cannot() {
        // In the chart at 0, t = tan(x / 2); build p(t) = (t - a)(t - a - d) directly.
        let a = Tracked::exact(0.25);
        let d = Tracked::exact(1e-13);
        let one = Tracked::exact(1.0);
        let p = mul::<2, 2, 3>(&[-a, one], &[-(a + d), one]);
        let poly =
            |_at_pi: bool| std::array::from_fn(|i| if i < 3 { p[i] } else { Tracked::exact(0.0) });
        let out = dd_roots(poly, 0.4, 0.6).unwrap();
        assert!(out.undecided.is_empty());
        assert_eq!(out.roots.len(), 2, "{out:?}");
        let t: Vec<f64> = out.roots.iter().map(|x| (0.5 * x).tan()).collect();
        assert!(
            (t[0] - 0.25).abs() < 1e-15 && (t[1] - 0.25 - 1e-13).abs() < 1e-15,
            "{t:?}"
        );
    }

    /// A factor linear in the angle: its root is proved and found.
    #[test]
    fn factor_roots_of_a_line() {
        struct Line;
        impl Factor for Line {
            fn over(&self, lo: f64, hi: f64) -> Enclosure {
                Enclosure::Values {
                    g: Iv::new(lo, hi) - Iv::point(0.3),
                    dg: Iv::point(1.0),
                }
            }
            fn value(&self, x: f64) -> Option<(f64, f64)> {
                Some((x - 0.3, 1.0))
            }
        }
        let mut out = ArrayVec::new();
        factor_roots(&Line, 0.0, 1.0, 0, &mut 100, &mut out).unwrap();
        assert_eq!(out.len(), 1);
        assert!((out[0] - 0.3).abs() < 1e-15);
    }
}
