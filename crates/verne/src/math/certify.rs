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
/// each), so this is reached only where nothing can be proved over a whole neighbourhood: inputs
/// that overflow, or (in [`poly_roots`]) a close pair whose coefficients' errors are so large that
/// neither p nor p' can be told from zero about it.
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

/// The pieces of [lo, hi] in each half-angle chart: x in [-pi/2, pi/2] (t = tan(x/2)), beyond
/// it up to 3 pi/2 (t = tan((x -+ pi)/2)), and past 3 pi/2 (t = tan(x/2) again, centred on
/// 2 pi).
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

/// What a piece's isolation in double-double proves ([`dd_verdict`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum DdVerdict {
    /// Every root found is proved, and each undecided interval is narrower than
    /// [`SAME_ROOT_WIDTH`]: it holds at most one solution, which a candidate at its middle finds
    /// if it is real (each interval with its middle).
    Decided {
        roots: ArrayVec<f64, 16>,
        undecided: ArrayVec<([f64; 2], f64), 8>,
    },
    /// Nothing is proved on the piece (an undecided interval too wide, or more roots than the
    /// lists hold): best-effort candidates only, the roots found, then the middles of the
    /// undecided intervals and of the piece.
    Unproved {
        roots: ArrayVec<f64, 16>,
        middles: ArrayVec<f64, 9>,
    },
}

/// Sorts what an isolation in double-double ([`dd_roots`] or [`poly_roots`]) found on the piece
/// [lo, hi] into what it proves ([`DdVerdict`]): the one decision of the three proofs by
/// double-double (the forward kinematics', leg I's along a tool pose, and the module's inverse
/// kinematics' at a touching root of eq. (9)).
pub(crate) fn dd_verdict(found: Result<DdRoots, ()>, lo: f64, hi: f64) -> DdVerdict {
    let middle = |[a, b]: [f64; 2]| 0.5 * (a + b);
    match found {
        Ok(found) if found.decided_up_to_same_root() => DdVerdict::Decided {
            undecided: found.undecided.iter().map(|&ab| (ab, middle(ab))).collect(),
            roots: found.roots,
        },
        other => {
            let found = other.unwrap_or_default();
            let mut middles: ArrayVec<f64, 9> =
                found.undecided.iter().map(|&ab| middle(ab)).collect();
            middles.push(middle([lo, hi]));
            DdVerdict::Unproved {
                roots: found.roots,
                middles,
            }
        }
    }
}

/// Every root of F in [lo, hi] (angles, rad) from its half-angle polynomial in double-double,
/// `poly(at_pi)` giving (1 + t^2)^d F in the chart at 0 or at pi ([`DdRoots`], angles); Err only
/// where there are more than the lists hold, or [`poly_roots`] runs out of pieces.
pub(crate) fn dd_roots(poly: impl Fn(bool) -> Poly8, lo: f64, hi: f64) -> Result<DdRoots, ()> {
    use std::f64::consts::PI;
    let mut charts: [Option<Poly8>; 2] = [None, None];
    let mut out = DdRoots::default();
    // The roots the previous piece found next to the cut it shares with this one.
    let mut at_cut: ArrayVec<f64, 16> = ArrayVec::new();
    for (clo, chi) in chart_pieces(lo, hi) {
        // The chart centred on the multiple of pi nearest the piece (|t| <= 1 on it): at 0 on
        // [-pi/2, pi/2], at -pi or pi beyond, at 2 pi past 3 pi/2 (a piece joined across pi).
        let turns = (0.5 * (clo + chi) / PI).round();
        let at_pi = turns.rem_euclid(2.0) == 1.0;
        let centre = turns * PI;
        let p = *charts[usize::from(at_pi)].get_or_insert_with(|| poly(at_pi));
        let t_of = |x: f64| (0.5 * (x - centre)).tan();
        // The chart's ends, widened by a few units: the neighbours of [lo, hi] are proved
        // root-free near it, so the overlap holds no root of theirs.
        let widen = |t: f64, dir: f64| t + dir * 4.0 * f64::EPSILON * t.abs().max(1e-300);
        let found = poly_roots(&p, widen(t_of(clo), -1.0), widen(t_of(chi), 1.0))?;
        let angle = |t: f64| centre + 2.0 * t.atan();
        let first = out.roots.len();
        for x in found.roots.into_iter().map(angle) {
            // Both pieces' widened ends hold a root at their cut: it is found twice. (Two
            // roots this close, a few units apart, are one solution: `SAME_ROOT_WIDTH`.)
            if next_to_cut(x, clo) {
                if let Some(k) = at_cut.iter().position(|&y| next_to_cut(x, y)) {
                    at_cut.swap_remove(k);
                    continue;
                }
            }
            out.roots.try_push(x).map_err(|_| ())?;
        }
        at_cut = out.roots[first..]
            .iter()
            .copied()
            .filter(|&x| next_to_cut(x, chi))
            .collect();
        for [a, b] in found.undecided {
            let (a, b) = (angle(a), angle(b));
            match out.undecided.last_mut() {
                // An interval across the cut, as each piece saw it: one interval.
                Some(last) if a <= last[1] => last[1] = last[1].max(b),
                _ => out.undecided.try_push([a, b]).map_err(|_| ())?,
            }
        }
    }
    Ok(out)
}

/// Whether the angle x lies within the overlap of two chart pieces' widened ends at `cut` (four
/// units of t each, a few units of the angle), with room for the rounding of the angle.
fn next_to_cut(x: f64, cut: f64) -> bool {
    (x - cut).abs() <= 16.0 * f64::EPSILON * cut.abs().max(1.0)
}

/// Every root of the polynomial `p` (double-double with magnitudes, lowest degree first) in
/// [a, b] ([`DdRoots`]); Err only where there are more than the lists hold, or more than
/// [`MAX_PIECES`] pieces would be needed (nothing is proved then).
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

    use std::f64::consts::{FRAC_PI_2, PI};

    /// (x - a)(x - b) with its enclosures by interval arithmetic; no solution below `floor`
    /// (where a radicand would be negative), and enclosures over the part at or above it.
    struct Quadratic {
        a: f64,
        b: f64,
        floor: f64,
    }

    impl Factor for Quadratic {
        fn over(&self, lo: f64, hi: f64) -> Enclosure {
            if hi < self.floor {
                return Enclosure::NoSolution;
            }
            let x = Iv::new(lo.max(self.floor), hi);
            Enclosure::Values {
                g: (x - Iv::point(self.a)) * (x - Iv::point(self.b)),
                dg: x * 2.0 - Iv::point(self.a) - Iv::point(self.b),
            }
        }
        fn value(&self, x: f64) -> Option<(f64, f64)> {
            (x >= self.floor).then_some(((x - self.a) * (x - self.b), 2.0 * x - self.a - self.b))
        }
    }

    /// sin(x) - level, enclosed with `Iv::sin_cos`.
    struct SineLevel(f64);

    impl Factor for SineLevel {
        fn over(&self, lo: f64, hi: f64) -> Enclosure {
            let (s, c) = Iv::new(lo, hi).sin_cos();
            Enclosure::Values {
                g: s - Iv::point(self.0),
                dg: c,
            }
        }
        fn value(&self, x: f64) -> Option<(f64, f64)> {
            Some((x.sin() - self.0, x.cos()))
        }
    }

    fn roots_of(f: &impl Factor, lo: f64, hi: f64) -> Result<Vec<f64>, ()> {
        let mut out = ArrayVec::new();
        factor_roots(f, lo, hi, 0, &mut MAX_PIECES.clone(), &mut out)?;
        Ok(out.to_vec())
    }

    /// Within `ulps` units in the last place of `want`.
    fn close(got: f64, want: f64, ulps: f64) -> bool {
        (got - want).abs() <= ulps * f64::EPSILON * want.abs().max(f64::MIN_POSITIVE)
    }

    /// Each simple root once, in order, to the last few bits: apart, 1e-9 apart, on the first
    /// split point (g = 0 exactly there: the split moves), and of a sine (whose enclosure is
    /// the whole [-1, 1] on wide pieces).
    #[test]
    fn factor_roots_proves_each_simple_root_once() {
        for (a, b) in [(0.3, 0.7), (0.3, 0.3 + 1e-9), (0.5, 0.75), (-0.25, 0.5)] {
            let f = Quadratic {
                a,
                b,
                floor: f64::NEG_INFINITY,
            };
            let r = roots_of(&f, -1.0, 1.0).unwrap();
            assert_eq!(r.len(), 2, "({a}, {b}): {r:?}");
            assert!(
                close(r[0], a, 4.0) && close(r[1], b, 4.0),
                "({a}, {b}): {r:?}"
            );
        }
        let r = roots_of(&SineLevel(0.5), -PI, PI).unwrap();
        assert_eq!(r.len(), 2, "{r:?}");
        assert!(
            close(r[0], PI / 6.0, 4.0) && close(r[1], 5.0 * PI / 6.0, 4.0),
            "{r:?}"
        );
        // No root at all: g keeps its sign, or is monotone with ends of one sign.
        assert!(roots_of(&SineLevel(1.5), -PI, PI).unwrap().is_empty());
        let f = Quadratic {
            a: 2.0,
            b: 3.0,
            floor: f64::NEG_INFINITY,
        };
        assert!(roots_of(&f, -1.0, 1.0).unwrap().is_empty());
    }

    /// Where no solution can be, nothing is reported; a root there is not a solution.
    #[test]
    fn factor_roots_skips_where_no_solution_is_proved() {
        let f = Quadratic {
            a: 0.1,
            b: 0.6,
            floor: 0.3,
        };
        let r = roots_of(&f, -1.0, 1.0).unwrap();
        assert_eq!(r.len(), 1, "{r:?}");
        assert!(close(r[0], 0.6, 4.0), "{r:?}");
    }

    /// A double root (g = (x - a)^2, or sin x = 1) cannot be proved simple: Err, never a
    /// guess; and a factor nothing is proved about ends within the piece budget.
    #[test]
    fn factor_roots_refuses_what_it_cannot_decide() {
        let f = Quadratic {
            a: 0.3,
            b: 0.3,
            floor: f64::NEG_INFINITY,
        };
        assert!(roots_of(&f, -1.0, 1.0).is_err());
        assert!(roots_of(&SineLevel(1.0), 0.0, PI).is_err());
        struct Nothing;
        impl Factor for Nothing {
            fn over(&self, _: f64, _: f64) -> Enclosure {
                Enclosure::Unknown
            }
            fn value(&self, _: f64) -> Option<(f64, f64)> {
                None
            }
        }
        let (mut out, mut budget) = (ArrayVec::new(), MAX_PIECES);
        assert!(factor_roots(&Nothing, -1.0, 1.0, 0, &mut budget, &mut out).is_err());
        assert!(out.is_empty());
        // Bisection stopped at its depth (2^64 pieces would not be examined), also next to 0,
        // where the pieces' width stays above the rounding of their ends all the way down.
        assert!(budget >= MAX_PIECES - 2 * MAX_SPLIT_DEPTH, "{budget}");
        let mut budget = MAX_PIECES;
        assert!(factor_roots(&Nothing, 0.0, 1.0, 0, &mut budget, &mut out).is_err());
        assert_eq!(budget, MAX_PIECES - MAX_SPLIT_DEPTH - 1);
        // Undecided only on the right halves (no solution below 0): the same depth limit.
        struct NothingAbove0;
        impl Factor for NothingAbove0 {
            fn over(&self, _: f64, hi: f64) -> Enclosure {
                if hi < 0.0 {
                    Enclosure::NoSolution
                } else {
                    Enclosure::Unknown
                }
            }
            fn value(&self, _: f64) -> Option<(f64, f64)> {
                None
            }
        }
        let mut budget = MAX_PIECES;
        assert!(factor_roots(&NothingAbove0, -1.0, 0.0, 0, &mut budget, &mut out).is_err());
        assert_eq!(budget, MAX_PIECES - 2 * MAX_SPLIT_DEPTH - 1);
        // A spent budget refuses at once.
        let mut spent = 0;
        let f = Quadratic {
            a: 0.3,
            b: 0.7,
            floor: f64::NEG_INFINITY,
        };
        assert!(factor_roots(&f, -1.0, 1.0, 0, &mut spent, &mut out).is_err());
    }

    /// A factor with its enclosures and values counted, and its double-precision values given
    /// as they are (`Honest`), withheld (`Absent`) or for a root `shift` away (`Misleading`):
    /// Newton's steps only place the estimate, and only enclosures prove it.
    struct Counted<F> {
        f: F,
        values: Values,
        enclosures: std::cell::Cell<u32>,
        values_given: std::cell::Cell<u32>,
    }

    #[derive(Clone, Copy, Debug)]
    enum Values {
        Honest,
        Absent,
        Misleading(f64),
    }

    impl<F: Factor> Factor for Counted<F> {
        fn over(&self, lo: f64, hi: f64) -> Enclosure {
            self.enclosures.set(self.enclosures.get() + 1);
            self.f.over(lo, hi)
        }
        fn value(&self, x: f64) -> Option<(f64, f64)> {
            self.values_given.set(self.values_given.get() + 1);
            match self.values {
                Values::Honest => self.f.value(x),
                Values::Absent => None,
                Values::Misleading(shift) => self.f.value(x - shift),
            }
        }
    }

    /// k ((x - at) - half): a root at `at` + `half`, with enclosures `fuzz` wider either way
    /// (what a long formula's interval arithmetic gives).
    struct Line {
        k: f64,
        at: f64,
        half: f64,
        fuzz: f64,
    }

    impl Line {
        fn new(k: f64, at: f64) -> Line {
            Line {
                k,
                at,
                half: 0.0,
                fuzz: 0.0,
            }
        }
    }

    impl Factor for Line {
        fn over(&self, lo: f64, hi: f64) -> Enclosure {
            let d = Iv::new(lo, hi) - Iv::point(self.at) - Iv::point(self.half);
            Enclosure::Values {
                g: d * Iv::point(self.k) + Iv::new(-self.fuzz, self.fuzz),
                dg: Iv::point(self.k),
            }
        }
        fn value(&self, x: f64) -> Option<(f64, f64)> {
            Some((((x - self.at) - self.half) * self.k, self.k))
        }
    }

    /// `refine_root` on a bracket of a simple root: with honest values, Newton's estimate,
    /// settled before its last step, and one proved bracket round it (three enclosures); with
    /// values withheld or misleading (a root 1e-4 or 1e-12 away), bisection on proved signs.
    /// Each time the root to the last bits, or to where the enclosures allow a sign: steep,
    /// shallow and curved factors, brackets wide and narrow, the root off-centre, next to 0,
    /// or half-way between two doubles (bisection then ends on the two).
    #[test]
    fn refine_root_places_and_proves_the_root() {
        let quadratic = || Quadratic {
            a: 0.3,
            b: 0.7,
            floor: f64::NEG_INFINITY,
        };
        let half = 0.5 * (0.3f64.next_up() - 0.3);
        for values in [
            Values::Honest,
            Values::Absent,
            Values::Misleading(1e-4),
            Values::Misleading(1e-12),
        ] {
            // (root found, true root, how far it may be, enclosures and values used)
            let mut found = Vec::new();
            let mut push = |(x, n, v): (f64, u32, u32), root: f64, room: f64| {
                found.push((x, root, room, n, v));
            };
            for (lo, hi) in [(0.0, 1.0), (0.29, 0.31), (0.2999, 0.3000001), (0.1, 0.9)] {
                for k in [1e6, 1.0, 1e-6, -3.0] {
                    let sign_lo = if k > 0.0 { -1 } else { 1 };
                    push(
                        refined(Line::new(k, 0.3), values, lo, hi, sign_lo),
                        0.3,
                        0.0,
                    );
                    let between = Line {
                        half,
                        ..Line::new(k, 0.3)
                    };
                    push(refined(between, values, lo, hi, sign_lo), 0.3 + half, 0.0);
                }
                let fuzzy = Line {
                    fuzz: 1e-12,
                    ..Line::new(1e-3, 0.3)
                };
                push(refined(fuzzy, values, lo, hi, -1), 0.3, 4e-9);
            }
            for (lo, hi) in [(0.0, 1e-9), (-1e-9, 1e-9)] {
                push(
                    refined(Line::new(1.0, 1e-10), values, lo, hi, -1),
                    1e-10,
                    0.0,
                );
            }
            push(refined(quadratic(), values, 0.5, 0.9, -1), 0.7, 0.0);
            push(refined(SineLevel(0.5), values, 0.0, 1.2, -1), PI / 6.0, 0.0);
            for (x, root, room, n, v) in found {
                assert!(
                    (x - root).abs() <= room + 4.0 * f64::EPSILON * root.abs(),
                    "{values:?}: {x} for {root}"
                );
                if let Values::Honest = values {
                    assert_eq!(n, 3, "{values:?}: {n} enclosures for {root}");
                    assert!(v < 8, "{values:?}: {v} Newton steps for {root}");
                }
            }
        }
    }

    /// `refine_root` of `f` with its values as `values`: the root, and the enclosures and
    /// values it took.
    fn refined<F: Factor>(f: F, values: Values, lo: f64, hi: f64, sign_lo: i8) -> (f64, u32, u32) {
        let f = Counted {
            f,
            values,
            enclosures: std::cell::Cell::new(0),
            values_given: std::cell::Cell::new(0),
        };
        let x = refine_root(&f, lo, hi, sign_lo);
        (x, f.enclosures.get(), f.values_given.get())
    }

    /// Every factor's roots, each with the index of its factor; Err when one factor's is.
    #[test]
    fn all_factor_roots_labels_each_root_with_its_factor() {
        let make = |a: f64, b: f64| Quadratic {
            a,
            b,
            floor: f64::NEG_INFINITY,
        };
        let r = all_factor_roots(&[make(0.2, 0.9), make(-0.4, 2.0)], -1.0, 1.0).unwrap();
        let labels: Vec<usize> = r.iter().map(|&(k, _)| k).collect();
        assert_eq!(labels, [0, 0, 1], "{r:?}");
        assert!(close(r[0].1, 0.2, 4.0) && close(r[1].1, 0.9, 4.0) && close(r[2].1, -0.4, 4.0));
        assert!(all_factor_roots(&[make(0.2, 0.9), make(0.5, 0.5)], -1.0, 1.0).is_err());
    }

    /// Ambiguous intervals at both ends of the circle become one piece across pi; others are
    /// kept as they are.
    #[test]
    fn pieces_join_the_ends_across_pi() {
        let joined = pieces(&[[-PI, -3.0], [0.1, 0.2], [3.0, PI]]);
        assert_eq!(joined.as_slice(), [[0.1, 0.2], [3.0, -3.0 + 2.0 * PI]]);
        for kept in [
            vec![[-PI, PI]],
            vec![[-3.1, -3.0], [3.0, PI]],
            vec![[-PI, -3.0], [3.0, 3.1]],
            vec![[-PI, -3.0], [0.1, 0.2]],
        ] {
            assert_eq!(pieces(&kept).as_slice(), kept.as_slice());
        }
    }

    /// The chart pieces cover [lo, hi] end to end, cut at -pi/2, pi/2 and 3 pi/2 only where
    /// those lie strictly inside.
    #[test]
    fn chart_pieces_cut_at_the_charts_edges() {
        let cases: [(f64, f64, &[f64]); 5] = [
            (-0.3, 0.4, &[]),
            (-3.0, 3.0, &[-FRAC_PI_2, FRAC_PI_2]),
            (-FRAC_PI_2, FRAC_PI_2, &[]),
            (3.0, 5.0, &[PI + FRAC_PI_2]),
            (-2.0, 6.0, &[-FRAC_PI_2, FRAC_PI_2, PI + FRAC_PI_2]),
        ];
        for (lo, hi, cuts) in cases {
            let p = chart_pieces(lo, hi);
            let ends: Vec<f64> = p.iter().map(|&(_, b)| b).collect();
            let mut want = cuts.to_vec();
            want.push(hi);
            assert_eq!(ends, want, "[{lo}, {hi}]");
            assert_eq!(p[0].0, lo);
            assert!(
                p.windows(2).all(|w| w[0].1 == w[1].0),
                "[{lo}, {hi}]: {p:?}"
            );
        }
    }

    /// l(x) and its derivative, against the formula and a central difference.
    #[test]
    fn lin_is_its_form_and_its_derivative() {
        let l = Lin::new(0.7, -1.3, 2.1);
        for k in -12..=12 {
            let x = 0.27 * f64::from(k);
            let (s, c) = x.sin_cos();
            assert!((l.at(s, c) - (0.7 - 1.3 * x.cos() + 2.1 * x.sin())).abs() < 1e-15);
            let h = 1e-6;
            let (sp, cp) = (x + h).sin_cos();
            let (sm, cm) = (x - h).sin_cos();
            let diff = (l.at(sp, cp) - l.at(sm, cm)) / (2.0 * h);
            assert!((l.d_at(s, c) - diff).abs() < 1e-8, "x = {x}");
        }
    }

    fn value_at(p: &[Tracked], t: f64) -> f64 {
        p.iter().rev().fold(0.0, |acc, c| acc * t + c.v.to_f64())
    }

    /// (1 + t^2) l(x) is `quad` at t = tan(x / 2) in the chart at 0 and t = tan((x - pi) / 2)
    /// in the chart at pi; `mul`, `add` and `scale` are the product, sum and multiple.
    #[test]
    fn half_angle_quadratics_and_their_arithmetic() {
        let l = Lin::new(
            Tracked::exact(0.7),
            Tracked::exact(-1.3),
            Tracked::exact(2.1),
        );
        let m = Lin::new(
            Tracked::exact(-0.2),
            Tracked::exact(0.5),
            Tracked::exact(0.9),
        );
        for k in -11..=11 {
            let x = 0.28 * f64::from(k);
            let (s, c) = x.sin_cos();
            let lx = 0.7 - 1.3 * c + 2.1 * s;
            let mx = -0.2 + 0.5 * c + 0.9 * s;
            for (at_pi, t) in [(false, (0.5 * x).tan()), (true, (0.5 * (x - PI)).tan())] {
                if t.abs() > 10.0 {
                    continue;
                }
                let w = 1.0 + t * t;
                let (ql, qm) = (quad(&l, at_pi), quad(&m, at_pi));
                assert!(
                    (value_at(&ql, t) - w * lx).abs() < 1e-12 * w * w,
                    "x {x} {at_pi}"
                );
                let prod = mul::<3, 3, 5>(&ql, &qm);
                assert!((value_at(&prod, t) - w * w * lx * mx).abs() < 1e-11 * w * w * w);
                let sum = add(&ql, &qm);
                assert!((value_at(&sum, t) - w * (lx + mx)).abs() < 1e-12 * w * w);
                let triple = scale(&ql, Tracked::exact(3.0));
                assert!((value_at(&triple, t) - 3.0 * w * lx).abs() < 1e-12 * w * w);
            }
        }
    }

    /// `horner`'s bound covers its double result's distance from the polynomial's value in
    /// double-double (summed by powers of t instead, a different rounding): the rounding to
    /// double included, which is most of it where the value is not small.
    #[test]
    fn horner_bounds_its_error_rounding_to_double_included() {
        let third = Tracked::exact(1.0) * Tracked::exact(1.0 / 3.0);
        let coefficients: Vec<Tracked> = (0..9)
            .map(|k| {
                third * Tracked::exact(0.7f64.powi(k) - 0.45) + Tracked::exact(1e-3 * f64::from(k))
            })
            .collect();
        for k in -40..=40 {
            let t = 0.0731 * f64::from(k);
            let (v, e) = horner(&coefficients, t);
            let mut power = Tracked::exact(1.0);
            let mut sum = Tracked::exact(0.0);
            for c in &coefficients {
                sum = sum + *c * power;
                power = power * Tracked::exact(t);
            }
            let off = (crate::math::dd::Dd::from_f64(v) - sum.v).to_f64().abs();
            assert!(off <= e, "t = {t}: {v} is {off} off, bound {e}");
            assert!(
                e <= 2.0 * f64::EPSILON * v.abs() + sum.error(2 * HALF_ANGLE_OPS),
                "t = {t}"
            );
        }
    }

    /// `bound_on` bounds sum (|p_k| + e_k) tmax^k from above, e_k the coefficients' error
    /// bounds (made large here by cancellation: 1e20 - 1e20 + c), and by little more (1e-11);
    /// the reference summed in double-double.
    #[test]
    fn bound_on_covers_the_coefficients_and_their_errors() {
        use crate::math::dd::Dd;
        let big = Tracked::exact(1e20);
        let p: Vec<Tracked> = [0.3, -1.7, 2.9, 0.0, -0.45, 1.1]
            .iter()
            .map(|&c| big - big + Tracked::exact(c))
            .collect();
        assert!(p[0].error(HALF_ANGLE_OPS) > 1e-9);
        for tmax in [0.25, 1.0, 3.0] {
            let mut reference = Dd::ZERO;
            for c in p.iter().rev() {
                reference = reference * Dd::from_f64(tmax)
                    + c.v.abs()
                    + Dd::from_f64(c.error(HALF_ANGLE_OPS));
            }
            let (bound, exact) = (bound_on(&p, tmax), reference.to_f64());
            assert!(
                bound >= exact && bound <= exact * (1.0 + 1e-11),
                "{bound} {exact}"
            );
        }
    }

    /// prod (t - r) for the given roots, in double-double.
    fn with_roots(roots: &[Tracked]) -> Vec<Tracked> {
        let mut p = vec![Tracked::exact(1.0)];
        for &r in roots {
            let mut next = vec![Tracked::exact(0.0); p.len() + 1];
            for (i, &c) in p.iter().enumerate() {
                next[i + 1] = next[i + 1] + c;
                next[i] = next[i] - c * r;
            }
            p = next;
        }
        p
    }

    /// Simple roots, 1e-10 apart among them, each proved once to the last bits; at any scale
    /// (a power of two: the same bits); none where there are none.
    #[test]
    fn poly_roots_proves_simple_roots() {
        let want = [-0.9, -0.35, 0.1, 0.6, 0.6 + 1e-10, 1.7];
        let p = with_roots(&want.map(Tracked::exact));
        let out = poly_roots(&p, -1.0, 2.0).unwrap();
        assert!(out.undecided.is_empty(), "{out:?}");
        assert_eq!(out.roots.len(), want.len(), "{out:?}");
        for (got, want) in out.roots.iter().zip(want) {
            assert!(close(*got, want, 4.0), "{got} for {want}");
        }
        for k in [2f64.powi(600), 2f64.powi(-600)] {
            let scaled: Vec<Tracked> = p.iter().map(|&c| c * k).collect();
            let again = poly_roots(&scaled, -1.0, 2.0).unwrap();
            assert_eq!(again.roots, out.roots, "scaled by {k}");
        }
        // Only the roots inside [a, b].
        let inner = poly_roots(&p, 0.0, 1.0).unwrap();
        assert_eq!(inner.roots.as_slice(), &out.roots[2..5]);
        let none = [
            Tracked::exact(1.0),
            Tracked::exact(0.0),
            Tracked::exact(1.0),
        ];
        let out = poly_roots(&none, -5.0, 5.0).unwrap();
        assert!(out.roots.is_empty() && out.undecided.is_empty());
    }

    /// A double root, a pair 1e-30 apart (exact in double-double, closer than it can
    /// separate) and a triple root are each left undecided in one interval narrower than
    /// [`SAME_ROOT_WIDTH`] holding them; the simple roots are still proved.
    #[test]
    fn poly_roots_leaves_what_it_cannot_separate_undecided() {
        let quarter = Tracked::exact(0.25);
        let pair = quarter + Tracked::exact(1e-30);
        for (roots, hidden) in [
            (vec![quarter, quarter, Tracked::exact(-0.5)], [0.25, 0.25]),
            (
                vec![quarter, pair, Tracked::exact(-0.5)],
                [0.25, 0.25 + 1e-30],
            ),
            // A triple root: flat enough that no split point's sign is proved next to it.
            (
                vec![quarter, quarter, quarter, Tracked::exact(-0.5)],
                [0.25, 0.25],
            ),
            // A double root at t = 0, where the pieces' width never falls below the rounding
            // of their ends: the depth limit ends the bisection.
            (
                vec![Tracked::exact(0.0); 2]
                    .into_iter()
                    .chain([Tracked::exact(-0.5)])
                    .collect(),
                [0.0, 0.0],
            ),
        ] {
            let out = poly_roots(&with_roots(&roots), -1.0, 1.0).unwrap();
            assert_eq!(out.roots.len(), 1, "{out:?}");
            assert!(close(out.roots[0], -0.5, 4.0), "{out:?}");
            assert_eq!(out.undecided.len(), 1, "{out:?}");
            let [a, b] = out.undecided[0];
            assert!(
                a <= hidden[0] && b >= hidden[1] && b - a <= SAME_ROOT_WIDTH,
                "{out:?}"
            );
            assert!(out.decided_up_to_same_root());
        }
        // Two double roots: two undecided intervals, each holding its root.
        let two = poly_roots(
            &with_roots(&[quarter, quarter, -quarter, -quarter]),
            -1.0,
            1.0,
        )
        .unwrap();
        assert!(two.roots.is_empty(), "{two:?}");
        assert_eq!(two.undecided.len(), 2, "{two:?}");
        for ([a, b], x) in two.undecided.iter().zip([-0.25, 0.25]) {
            assert!(*a <= x && *b >= x && b - a <= SAME_ROOT_WIDTH, "{two:?}");
        }
        let wide = DdRoots {
            roots: ArrayVec::new(),
            undecided: [[0.0, 2.0 * SAME_ROOT_WIDTH]].into_iter().collect(),
        };
        assert!(!wide.decided_up_to_same_root());
    }

    /// prod sin(x - r) over four angles r as (1 + t^2)^4 F in the chart at 0 or at pi, and F's
    /// roots r + k pi in (lo, hi), in order.
    fn sines(r: [f64; 4], lo: f64, hi: f64) -> (impl Fn(bool) -> Poly8, Vec<f64>) {
        let sc = r.map(f64::sin_cos);
        let poly = move |at_pi: bool| -> Poly8 {
            let q = sc.map(|(s, c)| {
                quad(
                    &Lin::new(Tracked::exact(0.0), Tracked::exact(-s), Tracked::exact(c)),
                    at_pi,
                )
            });
            let a = mul::<3, 3, 5>(&q[0], &q[1]);
            let b = mul::<3, 3, 5>(&q[2], &q[3]);
            mul::<5, 5, 9>(&a, &b)
        };
        let mut roots: Vec<f64> = sc
            .iter()
            .flat_map(|&(s, c)| {
                let x = s.atan2(c);
                [x - 2.0 * PI, x - PI, x, x + PI, x + 2.0 * PI]
            })
            .filter(|&x| x > lo && x < hi)
            .collect();
        roots.sort_by(f64::total_cmp);
        (poly, roots)
    }

    /// `dd_roots` finds every root of prod sin(x - r) inside [lo, hi] once, as an angle inside
    /// it, across the charts' edges, with a root next to pi/2 and one next to pi; with the
    /// roots made double, one narrow undecided interval round each, in every piece (not joined
    /// across the pieces).
    #[test]
    fn dd_roots_finds_each_angle_once_across_the_charts() {
        for (lo, hi) in [(-PI, PI), (-3.0, 3.0), (0.0, 2.0 * PI), (1.0, 5.0)] {
            let (poly, want) = sines([-1.2, 0.4, FRAC_PI_2 + 1e-3, PI - 2e-3], lo, hi);
            let out = dd_roots(poly, lo, hi).unwrap();
            assert!(out.undecided.is_empty(), "[{lo}, {hi}]: {out:?}");
            let mut got = out.roots.to_vec();
            got.sort_by(f64::total_cmp);
            assert_eq!(got.len(), want.len(), "[{lo}, {hi}]: {got:?} for {want:?}");
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).abs() < 4e-15 * (1.0 + w.abs()), "{g} for {w}");
            }
            let (poly, mut want) = sines([0.4, 0.4, 2.0, 2.0], lo, hi);
            want.dedup();
            let out = dd_roots(poly, lo, hi).unwrap();
            assert!(out.roots.is_empty(), "[{lo}, {hi}]: {out:?}");
            assert_eq!(out.undecided.len(), want.len(), "[{lo}, {hi}]: {out:?}");
            for ([a, b], w) in out.undecided.iter().zip(&want) {
                assert!(
                    a - 1e-15 <= *w && b + 1e-15 >= *w && b - a <= SAME_ROOT_WIDTH,
                    "{out:?}"
                );
            }
        }
    }

    /// A simple root within a few units of a chart's edge (pi/2, -pi/2, 3 pi/2) lies in both
    /// pieces' widened ends: reported once (it was twice, 2 units either side of the edge).
    #[test]
    fn dd_roots_reports_a_root_at_a_charts_edge_once() {
        for cut in [-FRAC_PI_2, FRAC_PI_2, PI + FRAC_PI_2] {
            for k in -24..=24 {
                let x0 = cut + f64::from(k) * f64::EPSILON * cut.abs();
                let (s, c) = x0.sin_cos();
                // sin(x - x0) and 2 + 0.3 cos x + 0.1 sin x (> 0) as quadratics in the chart.
                let factors = |at_pi: bool| {
                    let root = Lin::new(Tracked::exact(0.0), Tracked::exact(-s), Tracked::exact(c));
                    let positive = Lin::new(
                        Tracked::exact(2.0),
                        Tracked::exact(0.3),
                        Tracked::exact(0.1),
                    );
                    (quad(&root, at_pi), quad(&positive, at_pi))
                };
                // sin(x - x0) (2 + 0.3 cos x + 0.1 sin x)^3: one simple root in [cut -+ 0.5].
                let poly = |at_pi: bool| -> Poly8 {
                    let (q, positive) = factors(at_pi);
                    let a = mul::<3, 3, 5>(&q, &positive);
                    let b = mul::<5, 3, 7>(&a, &positive);
                    mul::<7, 3, 9>(&b, &positive)
                };
                let out = dd_roots(poly, cut - 0.5, cut + 0.5).unwrap();
                assert!(out.undecided.is_empty(), "{cut} {k}: {out:?}");
                assert_eq!(out.roots.len(), 1, "{cut} {k}: {out:?}");
                let want = s.atan2(c) + if cut > PI { 2.0 * PI } else { 0.0 };
                assert!((out.roots[0] - want).abs() < 8e-15, "{cut} {k}: {out:?}");
                // The root made double: one undecided interval round it, whichever pieces saw it.
                let double = |at_pi: bool| -> Poly8 {
                    let (q, positive) = factors(at_pi);
                    let a = mul::<3, 3, 5>(&q, &q);
                    mul::<5, 5, 9>(&a, &mul::<3, 3, 5>(&positive, &positive))
                };
                let out = dd_roots(double, cut - 0.5, cut + 0.5).unwrap();
                assert!(out.roots.is_empty(), "{cut} {k}: {out:?}");
                assert_eq!(out.undecided.len(), 1, "{cut} {k}: {out:?}");
                let [a, b] = out.undecided[0];
                assert!(a <= want + 8e-15 && b >= want - 8e-15, "{cut} {k}: {out:?}");
                assert!(out.decided_up_to_same_root(), "{cut} {k}: {out:?}");
            }
        }
    }

    /// `dd_verdict` proves what double-double decided up to one solution per narrow interval,
    /// with each interval's exact middle, and where it did not (an interval wider than
    /// [`SAME_ROOT_WIDTH`], or `Err`), proves nothing and gives every candidate: the roots, the
    /// middles of the intervals, then the piece's. The ends are dyadic, so the middles are exact
    /// and any other operation gives another number. The verdict `Unproved` is reached only
    /// here: no input is known for which double-double leaves a wide interval, so the callers'
    /// best-effort branches, which it sends the piece to, are reached by no test.
    #[test]
    fn dd_verdict_sorts_what_double_double_proves() {
        // Dyadic ends: every middle below is exact.
        let (narrow, narrow_middle) = ([0.25, 0.25 + 2f64.powi(-32)], 0.25 + 2f64.powi(-33));
        let (wide, wide_middle) = ([0.5, 0.5 + 2f64.powi(-20)], 0.5 + 2f64.powi(-21));
        assert!(narrow[1] - narrow[0] < SAME_ROOT_WIDTH && wide[1] - wide[0] > SAME_ROOT_WIDTH);
        let found = |undecided: &[[f64; 2]]| DdRoots {
            roots: [0.125, 0.75].into_iter().collect(),
            undecided: undecided.iter().copied().collect(),
        };
        let (lo, hi) = (0.0625, 1.0);
        assert_eq!(
            dd_verdict(Ok(found(&[narrow])), lo, hi),
            DdVerdict::Decided {
                roots: [0.125, 0.75].into_iter().collect(),
                undecided: [(narrow, narrow_middle)].into_iter().collect(),
            }
        );
        assert_eq!(
            dd_verdict(Ok(found(&[])), lo, hi),
            DdVerdict::Decided {
                roots: [0.125, 0.75].into_iter().collect(),
                undecided: ArrayVec::new(),
            }
        );
        assert_eq!(
            dd_verdict(Ok(found(&[narrow, wide])), lo, hi),
            DdVerdict::Unproved {
                roots: [0.125, 0.75].into_iter().collect(),
                middles: [narrow_middle, wide_middle, 0.53125].into_iter().collect(),
            }
        );
        assert_eq!(
            dd_verdict(Err(()), lo, hi),
            DdVerdict::Unproved {
                roots: ArrayVec::new(),
                middles: [0.53125].into_iter().collect(),
            }
        );
        // On dd_roots' own answer for a double root at 0.3 (sin(x - 0.3)^2 (2 + cos x)^2): one
        // narrow interval, its middle within it.
        let (s, c) = 0.3f64.sin_cos();
        let double = |at_pi: bool| -> Poly8 {
            let q = quad(
                &Lin::new(Tracked::exact(0.0), Tracked::exact(-s), Tracked::exact(c)),
                at_pi,
            );
            let positive = quad(
                &Lin::new(
                    Tracked::exact(2.0),
                    Tracked::exact(1.0),
                    Tracked::exact(0.0),
                ),
                at_pi,
            );
            mul::<5, 5, 9>(
                &mul::<3, 3, 5>(&q, &q),
                &mul::<3, 3, 5>(&positive, &positive),
            )
        };
        match dd_verdict(dd_roots(double, 0.0, 1.0), 0.0, 1.0) {
            DdVerdict::Decided { roots, undecided } => {
                assert!(roots.is_empty(), "{roots:?}");
                assert_eq!(undecided.len(), 1, "{undecided:?}");
                let ([a, b], m) = undecided[0];
                assert!(a <= 0.3 && 0.3 <= b && a < m && m < b, "{undecided:?}");
            }
            other => panic!("{other:?}"),
        }
    }

    /// `next_to_cut` holds an angle within 16 roundings of the cut (relative to |cut|, at
    /// least 1) and no further: at each chart's cut, and at 0.5 for the floor at 1, 15 and 17
    /// of them either side. The duplicates that `dd_roots_reports_a_root_at_a_charts_edge_once`
    /// builds lie within a few units, so a tolerance several times narrower passed it.
    #[test]
    fn next_to_cut_is_sixteen_roundings_wide() {
        for cut in [-FRAC_PI_2, FRAC_PI_2, PI + FRAC_PI_2, 0.5] {
            let unit = f64::EPSILON * f64::abs(cut).max(1.0);
            for sign in [1.0, -1.0] {
                assert!(next_to_cut(cut + sign * 15.0 * unit, cut), "{cut} {sign}");
                assert!(!next_to_cut(cut + sign * 17.0 * unit, cut), "{cut} {sign}");
            }
        }
    }

    /// `Polys::refine` keeps its Newton steps inside the bracket: on p = (t - 1/2)^3 + 1/8 =
    /// t^3 - 3/2 t^2 + 3/4 t (monotone, its only real root 0), the bracket [-1/4, 5/4] has its
    /// middle at p's flat point, where Newton's step goes to -inf. Bisected instead, the root is
    /// found to rounding (no test's bracket made a step leave it before).
    #[test]
    fn refine_keeps_to_its_bracket_where_newton_leaves_it() {
        let p = [0.0, 0.75, -1.5, 1.0].map(Tracked::exact);
        let d1 = derivative(&p);
        let d2 = derivative(&d1);
        let d3 = derivative(&d2);
        let polys = Polys {
            p: &p,
            d1: &d1,
            d2: &d2,
            d3: &d3,
        };
        assert_eq!(horner(&d1, 0.5).0, 0.0);
        let x = polys.refine(-0.25, 1.25, true);
        assert!(x.abs() < 1e-15, "{x}");
    }

    /// A simple root x1 = x2 - 24/65536 just below a double root x2 = 1372/4096, in p = (t -
    /// x1)(t - x2)^2 with a constant coefficient of magnitude 1e17 (its error about 4e-12, a
    /// rounding band about 1e-4 either side of x2): the pieces that reach the band have p
    /// within its error at their 0.3, 0.5 and 0.7 points, so they are split at the middle with
    /// no sign proved there. x1 is found once, in the gap the band leaves below it, and x2 is
    /// one undecided interval inside [0, 1]. (With the split point mirrored outside such a
    /// piece, the search goes back over x1 and finds it again until its list is full: an error.)
    #[test]
    fn a_piece_with_no_sign_at_its_split_points_is_split_inside_it() {
        let x2 = 1372.0 / 4096.0;
        let x1 = x2 - 24.0 / 65536.0;
        // x1 = 2741/8192 and x2 = 343/1024 (12 and 9 bits): the coefficients are exact.
        let c = [
            -x1 * x2 * x2,
            2.0 * x1 * x2 + x2 * x2,
            -(x1 + 2.0 * x2),
            1.0,
        ];
        let mut p = c.map(Tracked::exact);
        p[0].mag = 1e17;
        let out = poly_roots(&p, 0.0, 1.0).unwrap();
        assert_eq!(out.roots.len(), 1, "{out:?}");
        assert_eq!(out.undecided.len(), 1, "{out:?}");
        let [lo, hi] = out.undecided[0];
        assert!(lo < x2 && x2 < hi && hi - lo < 4e-4, "{out:?}");
        let root = out.roots[0];
        let (v, e) = horner(&p, root);
        assert!(
            v.abs() <= e && (root - x1).abs() < 1e-4 && root < lo,
            "{root}: {out:?}"
        );
    }

    /// The real roots of c0 + c1 t + c2 t^2 (c2 != 0), in double precision.
    fn quadratic_roots(c: [f64; 3]) -> Vec<f64> {
        let disc = c[1] * c[1] - 4.0 * c[2] * c[0];
        if disc < 0.0 {
            return Vec::new();
        }
        let q = -0.5 * (c[1] + c[1].signum() * disc.sqrt());
        vec![q / c[2], c[0] / q]
    }

    /// Checks `poly_roots`' answer `out` on [a, b] for c0 + c1 t + c2 t^2 with coefficient k
    /// given the error `err`: for 41 polynomials with that coefficient anywhere in 0.999 of its
    /// error, the roots in [a, b] outside the undecided intervals are as many as the roots
    /// found, each nearest a different one. Returns how many roots it checked.
    fn assert_roots_hold(
        c: [f64; 3],
        k: usize,
        err: f64,
        [a, b]: [f64; 2],
        out: &DdRoots,
    ) -> usize {
        let mut checked = 0;
        for j in 0..=40 {
            let mut q = c;
            q[k] += 0.999 * err * (f64::from(j) / 20.0 - 1.0);
            let outside: Vec<f64> = quadratic_roots(q)
                .into_iter()
                .filter(|&x| x >= a && x <= b)
                .filter(|&x| !out.undecided.iter().any(|u| x >= u[0] && x <= u[1]))
                .collect();
            let case = format!("{c:?} with c{k} {q:?} on [{a}, {b}]: {outside:?}, {out:?}");
            assert_eq!(outside.len(), out.roots.len(), "{case}");
            let mut nearest: Vec<usize> = outside
                .iter()
                .map(|x| {
                    let d = |r: &f64| (r - x).abs();
                    (0..out.roots.len())
                        .min_by(|&i, &l| d(&out.roots[i]).total_cmp(&d(&out.roots[l])))
                        .unwrap()
                })
                .collect();
            nearest.dedup();
            assert_eq!(nearest.len(), outside.len(), "{case}");
            checked += outside.len();
        }
        checked
    }

    /// The quadratic with roots `r` and coefficient k given the error `err` by its magnitude.
    fn quadratic_with_error(r: [f64; 2], k: usize, err: f64) -> ([f64; 3], Vec<Tracked>) {
        let unit = f64::from(HALF_ANGLE_OPS) * crate::math::dd::DD_OP_ERROR * (1.0 + 1e-12);
        let c = [r[0] * r[1], -(r[0] + r[1]), 1.0];
        let mut p = c.map(Tracked::exact).to_vec();
        p[k].mag = err / unit;
        assert!((p[k].error(HALF_ANGLE_OPS) / err - 1.0).abs() < 1e-12);
        (c, p)
    }

    /// `poly_roots` promises its answer for every polynomial within the coefficients' errors:
    /// each root there lies in a piece proved to hold exactly one (a root found) or in an
    /// undecided interval. Quadratics with dyadic roots, one coefficient given an error of
    /// 1/32 to 1/2 by its magnitude, checked by [`assert_roots_hold`]. Such large errors put
    /// the isolation's Taylor tests where the errors of p'(m) and p''(m) decide (each taken
    /// away, a piece with a root of some of these polynomials was excluded).
    #[test]
    fn the_roots_hold_for_every_polynomial_within_the_error() {
        // (roots, the coefficient with the error, its error, [a, b]), in 64ths.
        let cases: [([f64; 2], usize, f64, [f64; 2]); 6] = [
            ([-41.0, 38.0], 1, 1.0 / 16.0, [-52.0, 37.0]),
            ([-59.0, 7.0], 1, 1.0 / 8.0, [-55.0, 45.0]),
            ([-2.0, 46.0], 2, 1.0 / 32.0, [-53.0, 45.0]),
            ([-57.0, 8.0], 2, 1.0 / 16.0, [-26.0, 8.0]),
            ([-26.0, 25.0], 2, 1.0 / 16.0, [-26.0, 59.0]),
            ([-60.0, 62.0], 2, 0.5, [-54.0, 38.0]),
        ];
        let (mut roots_checked, mut undecided_seen) = (0, 0);
        for (r, k, err, ab) in cases {
            let (r, ab) = (r.map(|x| x / 64.0), ab.map(|x| x / 64.0));
            let (c, p) = quadratic_with_error(r, k, err);
            let out = poly_roots(&p, ab[0], ab[1]).unwrap();
            undecided_seen += out.undecided.len();
            roots_checked += assert_roots_hold(c, k, err, ab, &out);
        }
        assert!(
            roots_checked > 100 && undecided_seen >= 6,
            "{roots_checked} {undecided_seen}"
        );
    }

    /// A close pair whose vertex p cannot be told from zero within the coefficients' error is
    /// not proved root-free: p = (t + 3/256)(t + 1/256), c1 with an error of 1/32, on [-1/2,
    /// 1/2]. Split at 0, where p is exact, the piece [-1/2, 0] has ends of one sign and p'
    /// changing sign inside, by less than the error of p'(-1/4) from the monotone test's margin:
    /// taken as monotone, it would be proved root-free. Either nothing is proved (Err: today no
    /// piece about the pair is decided and the pieces run out) or the roots hold as in
    /// [`assert_roots_hold`].
    #[test]
    fn a_pair_within_the_error_is_not_proved_root_free() {
        let (r, ab) = ([-3.0 / 256.0, -1.0 / 256.0], [-0.5, 0.5]);
        let (c, p) = quadratic_with_error(r, 1, 1.0 / 32.0);
        // The premise: p'(-1/4) is within its error of the monotone test's margin, 2 r = 1/2.
        let (dm, edm) = horner(&derivative(&p), -0.25);
        assert!(dm.abs() - edm < 0.5 && dm.abs() + edm > 0.5, "{dm} {edm}");
        if let Ok(out) = poly_roots(&p, ab[0], ab[1]) {
            assert_roots_hold(c, 1, 1.0 / 32.0, ab, &out);
        }
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
