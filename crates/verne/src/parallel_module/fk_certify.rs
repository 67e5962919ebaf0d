//! The forward kinematics' proof of completeness where double precision alone cannot give it:
//! the intervals of alpha on which [`crate::math::trig::Trig::roots_certified`] could neither exclude
//! nor isolate a root of F (IFToMM 2007 section VI; see [`crate::parallel_module::fk`]).
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
//!    interval arithmetic on its derivative ([`crate::math::interval`]), and its sign change there
//!    proved at the ends: exactly one root.
//! 2. **Double-double precision.** (1 + t^2)^4 F as the degree-8 polynomial in t = tan(a/2) (or
//!    tan((a - pi)/2) away from alpha = 0) of the paper, its coefficients computed in
//!    double-double from the exact inputs with a running error bound ([`crate::math::dd::Tracked`]);
//!    exclusion and monotonicity tests as in double precision, with that bound.
//!
//! What neither decides is reported: the solution is then marked unproved
//! ([`crate::parallel_module::fk::Certificate::Unproved`]).

use arrayvec::ArrayVec;
use nalgebra::Vector3;

pub(crate) use crate::math::certify::Resolution;
use crate::math::certify::{self, DdVerdict, Enclosure, Factor, Lin, Poly8};
use crate::math::dd::Tracked;
use crate::math::interval::Iv;
use crate::math::scalar::{Mag, Scalar};
use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::spec::ModuleGeometry;

/// The linear trigonometric forms of the elimination of [`crate::parallel_module::fk`] (its module
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
/// (the same formulas as [`crate::parallel_module::fk`]'s `Elimination::new`).
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

/// A bound on |F(alpha) - F_exact(alpha)| for every alpha, F as `fk::characteristic`
/// computes its coefficients in double precision: `CHARACTERISTIC_OPS` roundings of the
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

/// Rounded operations on any path from an input to Delta at a point (the forms' coefficients,
/// then 4 K1 (Q^2 + delta^2 N) - N A^2): a generous count, as for `CHARACTERISTIC_OPS`.
const DISC_OPS: f64 = 64.0;

/// A bound on the rounding of Delta as [`factors_at`] computes it at (sin a, cos a):
/// `DISC_OPS` roundings of the magnitude of its formula ([`Mag`]). Where leg I is tangent
/// (Delta = 0 at a root of F), Delta comes out of either sign; negative by less than this, it is
/// zero (as `leg1_radicand` does for leg I's posture).
fn disc_error(g: &ModuleGeometry, rho: &Sliders, (s, c): (f64, f64)) -> f64 {
    let m = factors_at(&forms::<Mag>(g, rho), Mag::from(s), Mag::from(c));
    DISC_OPS * f64::EPSILON * m.disc.0
}

/// The pose at a root of F where Det is too small for the linear solution (condition (21)): the
/// factor g+- the root belongs to (the smaller |g| there) gives tau and the pose. None where H1
/// has no real root in tau (Delta negative beyond its rounding, [`disc_error`]).
pub(crate) fn pose_at_root_by_factors(
    g: &ModuleGeometry,
    rho: &Sliders,
    alpha: f64,
    sc: (f64, f64),
) -> Option<ModulePose> {
    let f = forms::<f64>(g, rho);
    let fa = factors_at(&f, sc.0, sc.1);
    if !(fa.disc >= -disc_error(g, rho, sc) && fa.p4 > 0.0) {
        return None;
    }
    let root = f.delta.abs() * fa.disc.max(0.0).sqrt();
    let tau = [(-fa.a * fa.q + root), (-fa.a * fa.q - root)].map(|n| n / (2.0 * fa.p4));
    let g_of = |t: f64| (t * fa.det - fa.b).abs();
    let tau = if g_of(tau[0]) <= g_of(tau[1]) {
        tau[0]
    } else {
        tau[1]
    };
    Some(pose_from_tau(g, rho, alpha, sc, tau, &fa, f.delta))
}

/// The start pose of a mode proved at angle `alpha`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProvedStart {
    pub pose: ModulePose,
    pub sc: (f64, f64),
}

/// One factor g_sigma = tau_sigma Det - b of F, for [`certify::factor_roots`].
struct FkFactor<'a> {
    iv: &'a Forms<Iv>,
    f64: &'a Forms<f64>,
    sigma: f64,
}

impl Factor for FkFactor<'_> {
    /// tau' = -(P' tau^2 + R' tau + S') / (2 P tau + R), with 2 P tau + R = sigma 4 |delta|
    /// sqrt(Delta) (implicit differentiation of H1 = 0); P = 4 p4, R = 4 A Q,
    /// S = A^2 - 4 delta^2 K1. Where Delta < 0 there is no solution: Delta's enclosure is cut at
    /// zero (the derivative's enclosure is then unbounded: only an exclusion can be proved).
    fn over(&self, lo: f64, hi: f64) -> Enclosure {
        let f = self.iv;
        let (s, c) = Iv::new(lo, hi).sin_cos();
        let fa = factors_at(f, s, c);
        if fa.disc.negative() {
            return Enclosure::NoSolution;
        }
        if !fa.p4.positive() {
            return Enclosure::Unknown;
        }
        let disc = Iv::new(fa.disc.lo.max(0.0), fa.disc.hi);
        let root = f.delta.abs() * disc.sqrt() * Iv::point(self.sigma);
        let tau = (-(fa.a * fa.q) + root) / (Iv::point(2.0) * fa.p4);
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
        Enclosure::Values {
            g: tau * fa.det - fa.b,
            dg: dtau * fa.det + tau * f.det.d_at(s, c) - f.b.d_at(s, c),
        }
    }

    fn value(&self, x: f64) -> Option<(f64, f64)> {
        let f = self.f64;
        let (s, c) = x.sin_cos();
        let fa = factors_at(f, s, c);
        if !(fa.disc > 0.0 && fa.p4 > 0.0) {
            return None;
        }
        let root = f.delta.abs() * fa.disc.sqrt() * self.sigma;
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
}

/// Decides each interval of `ambiguous` (alpha, rad; from `Trig::roots_certified`), pushing the
/// start pose of every mode it proves there into `starts`, and returns the strongest method it
/// needed. `allowed` receives the starts of intervals narrower than
/// [`certify::SAME_ROOT_WIDTH`] that double-double could not decide (at most one alpha each,
/// which the start finds if it is real; those intervals go to `undecided`: at a zero of
/// condition (21) one alpha carries two modes), `fallback` best-effort starts where nothing
/// could be proved.
#[cold]
#[inline(never)]
pub(crate) fn resolve(
    g: &ModuleGeometry,
    rho: &Sliders,
    ambiguous: &[[f64; 2]],
    starts: &mut ArrayVec<ProvedStart, 40>,
    allowed: &mut ArrayVec<ProvedStart, 40>,
    fallback: &mut ArrayVec<ProvedStart, 40>,
    undecided: &mut ArrayVec<[f64; 2], 8>,
) -> Resolution {
    let fi = forms::<Iv>(g, rho);
    let ff = forms::<f64>(g, rho);
    if !characteristic_error(g, rho).is_finite() {
        // The elimination overflows: nothing can be proved (and nothing isolated).
        return Resolution::Unproved;
    }
    let factors = [1.0, -1.0].map(|sigma| FkFactor {
        iv: &fi,
        f64: &ff,
        sigma,
    });
    let mut worst = Resolution::Factored;
    for [lo, hi] in certify::pieces(ambiguous) {
        if let Ok(roots) = certify::all_factor_roots(&factors, lo, hi) {
            for (k, x) in roots {
                let sc = x.sin_cos();
                let fa = factors_at(&ff, sc.0, sc.1);
                let root = ff.delta.abs() * fa.disc.max(0.0).sqrt() * factors[k].sigma;
                let tau = (-fa.a * fa.q + root) / (2.0 * fa.p4);
                let pose = pose_from_tau(g, rho, x, sc, tau, &fa, ff.delta);
                let _ = starts.try_push(ProvedStart { pose, sc });
            }
            continue;
        }
        let tf = forms::<Tracked>(g, rho);
        let found = certify::dd_roots(|at_pi| half_angle_poly(&tf, at_pi), lo, hi);
        // False where no start pose could be built at x.
        let push = |to: &mut ArrayVec<ProvedStart, 40>, x: f64| {
            let sc = x.sin_cos();
            let pose = start_at(g, rho, x, sc);
            if let Some(pose) = pose {
                let _ = to.try_push(ProvedStart { pose, sc });
            }
            pose.is_some()
        };
        match certify::dd_verdict(found, lo, hi) {
            DdVerdict::Decided {
                roots,
                undecided: narrow,
            } => {
                worst = worst.max(Resolution::Extended);
                // A proved root without its start would be a mode dropped: never silently.
                let built = roots.iter().filter(|&&x| push(starts, x)).count();
                if built < roots.len() {
                    worst = Resolution::Unproved;
                }
                for (interval, middle) in narrow {
                    push(allowed, middle);
                    let _ = undecided.try_push(interval);
                }
            }
            DdVerdict::Unproved { roots, middles } => {
                // Best effort where nothing is proved: what was found, and the middles.
                worst = Resolution::Unproved;
                for &x in roots.iter().chain(&middles) {
                    push(fallback, x);
                }
            }
        }
    }
    worst
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

/// (1 + t^2)^4 F as a polynomial in t (chart at 0 or at pi, [`certify::quad`]): with U = A Det
/// + 2 b Q (degree 4), (1 + t^2)^4 F = U^2 + 4 delta^2 (1 + t^2) (b^2 N - K1 Det^2).
fn half_angle_poly(f: &Forms<Tracked>, at_pi: bool) -> Poly8 {
    use certify::{add, mul, quad, scale};
    let q = |l: &Lin<Tracked>| quad(l, at_pi);
    let (a, b, det, qq, n, k1) = (q(&f.a), q(&f.b), q(&f.det), q(&f.q), q(&f.n), q(&f.k1));
    let two = Tracked::exact(2.0);
    let u = add::<5>(
        &mul::<3, 3, 5>(&a, &det),
        &scale(&mul::<3, 3, 5>(&b, &qq), two),
    );
    let b2n = mul::<5, 3, 7>(&mul::<3, 3, 5>(&b, &b), &n);
    let k1d2 = mul::<3, 5, 7>(&k1, &mul::<3, 3, 5>(&det, &det));
    let one = Tracked::exact(1.0);
    let inner = mul::<7, 3, 9>(
        &add::<7>(&b2n, &scale(&k1d2, -one)),
        &[one, Tracked::exact(0.0), one],
    );
    let d2 = f.delta * f.delta * 4.0;
    add::<9>(&mul::<5, 5, 9>(&u, &u), &scale(&inner, d2))
}

#[cfg(test)]
mod tests {
    use super::{
        CHARACTERISTIC_OPS, FkFactor, characteristic_error, disc_error, factors_at, forms,
        pose_at_root_by_factors,
    };
    use crate::math::dd::Tracked;
    use crate::parallel_module::equations::residual_mm;
    use crate::selftest::hard_sets::{DET_B_DELTA_ZERO, random_geometries};
    use crate::spec::Machine;
    use nalgebra::Vector3;

    /// [`characteristic_error`] bounds the rounding of F as `fk::characteristic` computes it. At
    /// 64 angles, F in double precision lies within the bound of F in double-double (the module
    /// documentation's formula U^2 + 4 delta^2 (b^2 N - K1 Det^2) from the exact inputs, its own
    /// error added); and the bound is at least [`CHARACTERISTIC_OPS`] roundings of the formula's
    /// magnitude at every angle ([`Tracked`]'s, computed term by term at that angle) and at most
    /// 4 times the largest (measured up to 1.8; F's actual error up to 0.0074 of the bound).
    /// And the bound is the formula it states, to 1e-12: that magnitude with every form at its
    /// norm (the formal point sin = cos = 1), which catches a term dropped that the floor's
    /// slack would hide. Sliders from 1 to 1e5 mm on the default machine and four random ones,
    /// and the triples of `DET_B_DELTA_ZERO`.
    #[test]
    fn characteristic_error_covers_the_rounding_of_f() {
        let mut unit = crate::math::test_rng::lcg(0xc4a2_e770);
        let machines = machines();
        let mut loosest = 0.0f64;
        for (i, m) in machines.iter().enumerate() {
            let g = &m.module;
            let mut triples: Vec<Vector3<f64>> = (0..2_000)
                .map(|k| {
                    let span = [1.0, 1e3, 3e3, 1e5][k % 4];
                    Vector3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * span
                })
                .collect();
            if i == 0 {
                triples.extend(
                    DET_B_DELTA_ZERO.map(|(p2, p3, _)| Vector3::new(250.0, 250.0 + p2, 250.0 + p3)),
                );
            }
            for rho in &triples {
                let bound = characteristic_error(g, rho);
                let f64_f = crate::parallel_module::fk::characteristic(g, rho);
                let t = forms::<Tracked>(g, rho);
                let f_at = |s: Tracked, c: Tracked| {
                    let (det, b) = (t.det.at(s, c), t.b.at(s, c));
                    let u = t.a.at(s, c) * det + Tracked::from(2.0) * b * t.q.at(s, c);
                    let inner = b * b * t.n.at(s, c) - t.k1.at(s, c) * det * det;
                    u * u + Tracked::from(4.0) * t.delta * t.delta * inner
                };
                let mut largest = 0.0f64;
                for k in 0..64 {
                    let (s, c) = (std::f64::consts::TAU * (f64::from(k) + unit()) / 64.0).sin_cos();
                    let f = f_at(Tracked::exact(s), Tracked::exact(c));
                    let err = (f64_f.eval_sc(s, c) - f.v.to_f64()).abs();
                    assert!(
                        err <= bound + f.error(64) + f64::EPSILON * f.v.to_f64().abs(),
                        "{}: {rho:?} at ({s}, {c}): F off by {err:e}, bound {bound:e}",
                        m.name
                    );
                    largest = largest.max(f.mag);
                }
                let floor = CHARACTERISTIC_OPS * f64::EPSILON * largest;
                assert!(
                    bound >= floor * (1.0 - 1e-12) && bound <= 4.0 * floor,
                    "{}: {rho:?}: bound {bound:e}, magnitude's rounding {floor:e}",
                    m.name
                );
                // The bound is loose by up to 1.8 there, more than some of its terms weigh, so
                // it is checked against the formula it states: the formula's magnitude with
                // every form at its norm |c0| + |cc| + |cs|, which is the magnitude at the
                // formal point sin = cos = 1.
                let one = Tracked::exact(1.0);
                let formula = CHARACTERISTIC_OPS * f64::EPSILON * f_at(one, one).mag;
                assert!(
                    (bound - formula).abs() <= 1e-12 * formula,
                    "{}: {rho:?}: bound {bound:e}, the formula at the norms {formula:e}",
                    m.name
                );
                loosest = loosest.max(bound / floor);
            }
        }
        assert!(loosest > 1.0, "{loosest}");
    }

    /// The default machine and four random valid geometries.
    fn machines() -> Vec<Machine> {
        let mut out = vec![Machine::default_verne()];
        out.extend(random_geometries(4, 15));
        out
    }

    /// Slider triples for the factors' tests: within 500 mm of each other (where modes are)
    /// and from 3,000 mm to 1e4 mm apart.
    fn triples(unit: &mut impl FnMut() -> f64, count: usize) -> Vec<Vector3<f64>> {
        (0..count)
            .map(|k| {
                let span = [500.0, 3e3, 1e4][k % 3];
                Vector3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * span
            })
            .collect()
    }

    /// F is the product of its factors: P g+ g- = F (module documentation, P = 4 (Q^2 + delta^2
    /// N)) at every angle where Delta > 0, F from `fk::characteristic`, to 1e-9 of the
    /// magnitude of its formula; and each factor's slope is its derivative (a central difference
    /// of the value, step 1e-6 rad, to 1e-5 of the slope's scale). 600 triples on five machines,
    /// 64 angles each.
    #[test]
    fn the_factors_multiply_to_f_and_their_slopes_are_their_derivatives() {
        use crate::math::certify::Factor;
        use crate::math::interval::Iv;
        let mut unit = crate::math::test_rng::lcg(0x0fac_7012);
        let mut checked = 0;
        for m in &machines() {
            let g = &m.module;
            for rho in triples(&mut unit, 120) {
                let (fi, ff) = (forms::<Iv>(g, &rho), forms::<f64>(g, &rho));
                let big_f = crate::parallel_module::fk::characteristic(g, &rho);
                let scale = characteristic_error(g, &rho) / (CHARACTERISTIC_OPS * f64::EPSILON);
                let [plus, minus] = [1.0, -1.0].map(|sigma| FkFactor {
                    iv: &fi,
                    f64: &ff,
                    sigma,
                });
                for _ in 0..64 {
                    let x = (unit() - 0.5) * 6.5;
                    let (Some((gp, dgp)), Some((gm, dgm))) = (plus.value(x), minus.value(x)) else {
                        continue;
                    };
                    let (s, c) = x.sin_cos();
                    let p4 = factors_at(&ff, s, c).p4;
                    let (product, f) = (4.0 * p4 * gp * gm, big_f.eval_sc(s, c));
                    assert!(
                        (product - f).abs() <= 1e-9 * scale,
                        "{}: {rho:?} at {x}: P g+ g- = {product:e}, F = {f:e}",
                        m.name
                    );
                    for (factor, slope) in [(&plus, dgp), (&minus, dgm)] {
                        let h = 1e-6;
                        let (Some((up, _)), Some((down, _))) =
                            (factor.value(x + h), factor.value(x - h))
                        else {
                            continue;
                        };
                        let diff = (up - down) / (2.0 * h);
                        let size = slope.abs().max(diff.abs()).max(1e-3 * scale.sqrt());
                        assert!(
                            (diff - slope).abs() <= 1e-5 * size,
                            "{}: {rho:?} at {x}: slope {slope:e}, difference {diff:e}",
                            m.name
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 20_000, "{checked}");
    }

    /// The factors' values and slopes in double precision (for Newton's steps) are the
    /// enclosures' own: at every angle where `value` gives them, they lie in `over(x, x)`'s
    /// intervals (widened by four times their width and 1e-12 relative, for the double
    /// evaluation's rounding); where `over` proves there is no solution, `value` gives nothing;
    /// and over an interval, the enclosures hold the values at its sample points.
    #[test]
    fn factor_values_lie_in_their_enclosures() {
        use crate::math::certify::{Enclosure, Factor, value_against_enclosure, within_enclosure};
        use crate::math::interval::Iv;
        let mut unit = crate::math::test_rng::lcg(0x0fac_7013);
        let (mut checked, mut none, mut spans) = (0, 0, 0);
        for m in &machines() {
            let g = &m.module;
            for rho in triples(&mut unit, 120) {
                let (fi, ff) = (forms::<Iv>(g, &rho), forms::<f64>(g, &rho));
                for sigma in [1.0, -1.0] {
                    let f = FkFactor {
                        iv: &fi,
                        f64: &ff,
                        sigma,
                    };
                    for _ in 0..64 {
                        let x = (unit() - 0.5) * 6.5;
                        match value_against_enclosure(&f, x) {
                            Ok(Some(true)) => checked += 1,
                            Ok(Some(false)) => none += 1,
                            Ok(None) => {}
                            Err(e) => panic!("{rho:?} sigma {sigma} x {x}: {e}"),
                        }
                        let (lo, hi) = (x, x + 1e-3 * unit());
                        if let Enclosure::Values { g, dg } = f.over(lo, hi) {
                            for k in 0..=4 {
                                let y = lo + (hi - lo) * f64::from(k) / 4.0;
                                if let Some((v, d)) = f.value(y) {
                                    assert!(
                                        within_enclosure(v, g) && within_enclosure(d, dg),
                                        "{rho:?} [{lo}, {hi}] at {y}"
                                    );
                                    spans += 1;
                                }
                            }
                        }
                    }
                }
            }
        }
        assert!(
            checked > 20_000 && none > 20_000 && spans > 50_000,
            "{checked} {none} {spans}"
        );
    }

    /// The half-angle polynomial of the double-double path is (1 + t^2)^4 F: in each chart (t =
    /// tan(x / 2) about 0, tan((x - pi) / 2) about pi), its value at 32 angles of the chart
    /// agrees with F(x) (1 + t^2)^4, F from `fk::characteristic`, to 1e-12 of the terms'
    /// magnitudes. 600 triples on five machines.
    #[test]
    fn half_angle_polynomial_is_f_times_its_denominator() {
        use super::half_angle_poly;
        let mut unit = crate::math::test_rng::lcg(0x4a1f_f001);
        let mut checked = 0;
        for m in &machines() {
            let g = &m.module;
            for rho in triples(&mut unit, 120) {
                let big_f = crate::parallel_module::fk::characteristic(g, &rho);
                let scale = characteristic_error(g, &rho) / (CHARACTERISTIC_OPS * f64::EPSILON);
                let tf = forms::<Tracked>(g, &rho);
                for (at_pi, centre) in [(false, 0.0), (true, std::f64::consts::PI)] {
                    let coefficients = half_angle_poly(&tf, at_pi).map(|c| c.v.to_f64());
                    for _ in 0..32 {
                        let x = centre + (unit() - 0.5) * std::f64::consts::PI;
                        let t = (0.5 * (x - centre)).tan();
                        let (value, size) = coefficients
                            .iter()
                            .rev()
                            .fold((0.0, 0.0), |(v, a), c| (v * t + c, a * t.abs() + c.abs()));
                        let (s, c) = x.sin_cos();
                        let w = (1.0 + t * t).powi(4);
                        let f = big_f.eval_sc(s, c) * w;
                        assert!(
                            (value - f).abs() <= 1e-12 * (size + scale * w),
                            "{}: {rho:?} x {x} ({at_pi}): {value:e} against {f:e}",
                            m.name
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 38_400);
    }

    /// Next to condition (21) (Det = 0 at the pose's alpha, `HardSet::Condition21`, and the
    /// plane where L2 = L3 makes every zero of Det a double root, `HardSet::SliderMean`), the
    /// factors' pose at a built pose's alpha is that pose (within 1e-8 mm; measured 3e-11), the
    /// mode of its own factor and not the other's: poses built at 1e-9 to 0.1 mm either side of
    /// the set on five machines. On the set itself both modes share alpha (b = 0 there too) and
    /// either may come out (the other, 990 to 1,550 mm away, in 23 of 81; the fixed-angle points
    /// find both): the pose must close the four loops within 1e-8 mm.
    #[test]
    fn the_factors_give_the_built_mode_next_to_condition_21() {
        use crate::selftest::hard_sets::{HardSet, Sampler, construct, random_start};
        let mut rng = Sampler::new(0x0021_fac7);
        let mut poses = 0;
        for m in &machines() {
            for set in [HardSet::Condition21, HardSet::SliderMean] {
                let mut m = m.clone();
                if set == HardSet::SliderMean {
                    m.module.l3 = m.module.l2;
                }
                for _ in 0..40 {
                    let Some((p0, b)) = random_start(&m, &mut rng) else {
                        continue;
                    };
                    for c in construct(&m, set, &p0, &rng.direction(), &b, 300.0) {
                        let sc = c.alpha.sin_cos();
                        let pose = pose_at_root_by_factors(&m.module, &c.rho, c.alpha, sc);
                        let Some(pose) = pose else {
                            panic!("{}: {c:?}: no pose", m.name);
                        };
                        let res = residual_mm(&m.module, &pose, &c.rho);
                        assert!(res < 1e-8, "{}: {c:?}: {pose:?} residual {res} mm", m.name);
                        if c.offset_mm != 0.0 {
                            let off = (pose.p - c.p).amax();
                            assert!(off < 1e-8, "{}: {c:?}: {pose:?} {off} mm off", m.name);
                            poses += 1;
                        }
                    }
                }
            }
        }
        assert!(poses >= 500, "{poses}");
    }

    /// Where Det = b = Delta = 0 at one alpha (`DET_B_DELTA_ZERO`, shifted along all three
    /// sliders), the pose from the factors at the root and at 128 angles within 6.4e-16 (1 +
    /// |alpha|) of it, where Delta is zero to rounding and comes out of either sign: every one is
    /// built and closes the four loops within 1e-9 mm. A strict Delta >= 0 refused 27 to 70 of
    /// the 129 on each triple. Where Delta is negative beyond its rounding (1e-6 rad from the
    /// root, on the side where leg I cannot reach), there is no pose.
    #[test]
    fn the_pose_at_a_tangent_of_leg_i_is_built_where_delta_is_zero_to_rounding() {
        let m = Machine::default_verne();
        let g = &m.module;
        for (p2, p3, alpha) in DET_B_DELTA_ZERO {
            for rho1 in [0.0, 300.0, 1700.0] {
                let rho = Vector3::new(rho1, rho1 + p2, rho1 + p3);
                let f = forms::<f64>(g, &rho);
                for k in -64i32..=64 {
                    let a = alpha + f64::from(k) * 1e-17 * (1.0 + alpha.abs());
                    let sc = a.sin_cos();
                    let disc = factors_at(&f, sc.0, sc.1).disc;
                    assert!(disc.abs() <= disc_error(g, &rho, sc), "{rho:?} {a}: {disc}");
                    let pose = pose_at_root_by_factors(g, &rho, a, sc);
                    let Some(pose) = pose else {
                        panic!("{rho:?} {a}: Delta {disc}: no pose");
                    };
                    let res = residual_mm(g, &pose, &rho);
                    assert!(res < 1e-9, "{rho:?} {a}: residual {res} mm");
                }
                let outside: Vec<f64> = [alpha - 1e-6, alpha + 1e-6]
                    .into_iter()
                    .filter(|a| {
                        let sc = a.sin_cos();
                        factors_at(&f, sc.0, sc.1).disc < -disc_error(g, &rho, sc)
                    })
                    .collect();
                assert_eq!(outside.len(), 1, "{rho:?}");
                let sc = outside[0].sin_cos();
                assert!(pose_at_root_by_factors(g, &rho, outside[0], sc).is_none());
            }
        }
    }
}
