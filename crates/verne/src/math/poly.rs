//! Real roots of small polynomials on an interval, found by a method that cannot miss a simple
//! root: the derivative recursion (roots of p' split the interval into pieces where p is
//! monotone; each piece with a sign change holds exactly one root, found by safeguarded Newton).
//!
//! Near-double roots, where p touches zero between two close roots or at a tangency, show up as
//! critical points whose |p| is within the rounding error of evaluating p; they are reported as
//! such so that the caller can decide on the original equations.

use arrayvec::ArrayVec;

/// Highest degree handled (the forward kinematics' degree-8 polynomial, IFToMM 2007 section VI).
pub const MAX_DEGREE: usize = 8;

/// Coefficients, lowest degree first.
pub type Coeffs = ArrayVec<f64, { MAX_DEGREE + 1 }>;

/// A root of p on the interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    pub x: f64,
    /// True when this is a critical point where |p| is within rounding error of 0: a double root,
    /// or two real roots too close to separate, or a near miss (complex pair) the caller must test.
    pub touching: bool,
}

/// Roots found on one interval (at most the degree, plus touching candidates).
pub type Roots = ArrayVec<Root, { 2 * MAX_DEGREE }>;

/// p(x) by Horner, with a running bound on its rounding error.
#[inline]
pub fn eval_with_error(c: &[f64], x: f64) -> (f64, f64) {
    let mut p = 0.0;
    let mut bound = 0.0;
    let ax = x.abs();
    for &a in c.iter().rev() {
        p = p * x + a;
        bound = bound * ax + p.abs();
    }
    (p, bound * 4.0 * f64::EPSILON * c.len() as f64)
}

#[inline]
fn eval_d(c: &[f64], x: f64) -> (f64, f64) {
    let mut p = 0.0;
    let mut d = 0.0;
    for &a in c.iter().rev() {
        d = d * x + p;
        p = p * x + a;
    }
    (p, d)
}

fn derivative(c: &[f64]) -> Coeffs {
    c.iter()
        .enumerate()
        .skip(1)
        .map(|(i, &a)| a * i as f64)
        .collect()
}

/// Drops leading coefficients that are negligible next to the largest one.
fn trimmed(c: &[f64]) -> &[f64] {
    let scale = c.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    let mut n = c.len();
    while n > 0 && c[n - 1].abs() <= scale * 1e-300 {
        n -= 1;
    }
    &c[..n]
}

/// [`eval_with_error`] with `err[i]` bounding the error of coefficient i itself (from the
/// formulas that computed it): the bound covers the exact polynomial's value.
#[inline]
pub fn eval_with_coefficient_error(c: &[f64], err: &[f64], x: f64) -> (f64, f64) {
    let (p, rounding) = eval_with_error(c, x);
    let ax = x.abs();
    let coef = err.iter().rev().fold(0.0, |acc, e| acc * ax + e);
    (p, rounding + coef)
}

/// All real roots of the polynomial `c` (lowest degree first) in [lo, hi], sorted; none when
/// the interval is empty (lo > hi) or an end is not a number.
pub fn roots_in(c: &[f64], lo: f64, hi: f64) -> Roots {
    roots_in_with_error(c, &[], lo, hi)
}

/// [`roots_in`] where coefficient i of `c` may be off by `err[i]` (missing entries: exact): the
/// decisions (a sign change, a critical point touching zero) hold for the exact polynomial.
pub fn roots_in_with_error(c: &[f64], err: &[f64], lo: f64, hi: f64) -> Roots {
    let mut out = Roots::new();
    // An empty or not-a-number interval holds no root (the pieces below assume lo <= hi: a
    // reversed interval bracketed a point that is no root).
    if lo
        .partial_cmp(&hi)
        .is_none_or(|o| o == std::cmp::Ordering::Greater)
    {
        return out;
    }
    let c = trimmed(c);
    let err = &err[..err.len().min(c.len())];
    if c.len() <= 1 {
        return out;
    }
    if c.len() == 2 {
        let x = -c[0] / c[1];
        if x >= lo && x <= hi {
            out.push(Root { x, touching: false });
        }
        return out;
    }
    let d = derivative(c);
    let d_err: ArrayVec<f64, { MAX_DEGREE + 1 }> = err
        .iter()
        .enumerate()
        .skip(1)
        .map(|(i, e)| e * i as f64)
        .collect();
    let crit = roots_in_with_error(&d, &d_err, lo, hi);
    // Refine each root to full precision: the caller's Newton polish on the original equations
    // starts from it, and close pairs of roots must stay apart (an early stop at the rounding
    // level of p lost a mode 1e-5 rad from its twin).
    let noise = 0.0;
    let mut a = lo;
    let (mut fa, mut ea) = eval_with_coefficient_error(c, err, a);
    if fa.abs() <= ea {
        out.push(Root {
            x: a,
            touching: false,
        });
    }
    for k in 0..=crit.len() {
        let b = if k < crit.len() { crit[k].x } else { hi };
        let (fb, eb) = eval_with_coefficient_error(c, err, b);
        let a_zero = fa.abs() <= ea;
        let b_zero = fb.abs() <= eb;
        if !a_zero && !b_zero && (fa < 0.0) != (fb < 0.0) {
            push_unique(&mut out, bracketed(c, a, b, fa, noise));
        } else if b_zero {
            // b is a root (an end point, or a critical point touching zero).
            let touching = k < crit.len();
            push_unique(&mut out, Root { x: b, touching });
        }
        a = b;
        fa = fb;
        ea = eb;
    }
    out
}

/// Appends a root to a sorted list, merging it with the last one when they coincide to rounding
/// (a root found both as a piece's end and as a critical point); a full list keeps what it has.
pub(crate) fn push_unique<const N: usize>(out: &mut ArrayVec<Root, N>, r: Root) {
    if let Some(last) = out.last_mut()
        && (r.x - last.x).abs() <= 4.0 * f64::EPSILON * (1.0 + r.x.abs())
    {
        last.touching &= r.touching;
        return;
    }
    let _ = out.try_push(r);
}

/// The single root of a polynomial that is monotone on [a, b] with a sign change there:
/// Newton steps kept inside a shrinking bracket, started from its midpoint, falling back to
/// bisection when a step leaves the bracket. Stops once |p| is below `noise` (the rounding error
/// of evaluating p on the interval: further steps would only follow rounding) or the bracket
/// cannot shrink.
fn bracketed(c: &[f64], mut a: f64, mut b: f64, fa: f64, noise: f64) -> Root {
    let a_neg = fa < 0.0;
    let mut x = 0.5 * (a + b);
    for _ in 0..200 {
        let (f, df) = eval_d(c, x);
        if f.abs() <= noise {
            break;
        }
        if (f < 0.0) == a_neg {
            a = x;
        } else {
            b = x;
        }
        let newton = x - f / df;
        let next = if df != 0.0 && newton > a && newton < b {
            newton
        } else {
            0.5 * (a + b)
        };
        if (next - x).abs() <= 2.0 * f64::EPSILON * x.abs().max(1e-300)
            || b - a <= f64::EPSILON * (a.abs() + b.abs())
        {
            x = next;
            break;
        }
        x = next;
    }
    Root { x, touching: false }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_roots(rs: &[f64]) -> Vec<f64> {
        let mut c = vec![1.0];
        for &r in rs {
            let mut n = vec![0.0; c.len() + 1];
            for (i, &a) in c.iter().enumerate() {
                n[i + 1] += a;
                n[i] -= r * a;
            }
            c = n;
        }
        c
    }

    #[test]
    fn finds_every_root_of_a_degree_eight() {
        let rs = [-0.9, -0.5, -0.11390, -0.07054, 0.2, 0.5, 0.8, 0.95];
        let c = from_roots(&rs);
        let got = roots_in(&c, -1.0, 1.0);
        assert_eq!(got.len(), 8, "{got:?}");
        for (g, r) in got.iter().zip(rs) {
            assert!((g.x - r).abs() < 1e-12, "{} vs {}", g.x, r);
        }
    }

    #[test]
    fn close_pair_is_separated() {
        let rs = [0.1, 0.1 + 6.7e-5, 0.5];
        let c = from_roots(&rs);
        let got = roots_in(&c, -1.0, 1.0);
        assert_eq!(got.len(), 3, "{got:?}");
    }

    #[test]
    fn double_root_is_reported_touching() {
        let c = from_roots(&[0.3, 0.3, -0.7]);
        let got = roots_in(&c, -1.0, 1.0);
        assert!(
            got.iter().any(|r| (r.x - 0.3).abs() < 1e-7 && r.touching),
            "{got:?}"
        );
        assert!(
            got.iter().any(|r| (r.x + 0.7).abs() < 1e-12 && !r.touching),
            "{got:?}"
        );
    }

    #[test]
    fn roots_outside_are_ignored_and_endpoints_kept() {
        let c = from_roots(&[-1.0, 2.0, 0.25]);
        let got = roots_in(&c, -1.0, 1.0);
        assert_eq!(got.len(), 2, "{got:?}");
        assert_eq!(got[0].x, -1.0);
    }

    /// An empty (reversed) or not-a-number interval holds no root, at every degree; a
    /// one-point interval holds its point when that is a root.
    #[test]
    fn an_empty_interval_holds_no_root() {
        for rs in [
            &[0.5][..],
            &[-1.0, 0.5],
            &[-1.0, 0.5, 2.0],
            &[-1.0, -0.2, 0.5, 0.9, 2.0],
        ] {
            let c = from_roots(rs);
            for (lo, hi) in [(1.5, 0.0), (3.0, -3.0), (f64::NAN, 1.0), (0.0, f64::NAN)] {
                assert!(roots_in(&c, lo, hi).is_empty(), "{rs:?} on [{lo}, {hi}]");
            }
            let at = roots_in(&c, 0.5, 0.5);
            assert_eq!(at.len(), 1, "{rs:?}: {at:?}");
            assert_eq!(at[0].x, 0.5);
        }
    }

    /// Roots far from 1 are refined to full relative precision: the step test is relative to
    /// |x| (a root at 3e17, where a test of |next / x| against eps |x| would stop after one
    /// Newton step from the piece's midpoint).
    #[test]
    fn a_large_root_is_found_to_full_precision() {
        for r in [3e17, -5e20, 7e-12] {
            let c = from_roots(&[r, 1.0]);
            let (lo, hi) = if r > 1.0 {
                (2.0, 10.0 * r)
            } else if r < 0.0 {
                (10.0 * r, 0.5)
            } else {
                (0.0, 0.5)
            };
            let got = roots_in(&c, lo, hi);
            assert_eq!(got.len(), 1, "{r}: {got:?}");
            assert!(
                (got[0].x - r).abs() <= 8.0 * f64::EPSILON * r.abs(),
                "{r}: {got:?}"
            );
        }
    }

    /// A root at an end of the interval crosses zero there (it is no critical point):
    /// (x - 1)(x + 5) on [0, 1] and on [1, 2].
    #[test]
    fn a_root_at_an_end_is_not_touching() {
        let c = from_roots(&[1.0, -5.0]);
        for (lo, hi) in [(0.0, 1.0), (1.0, 2.0)] {
            let r = roots_in(&c, lo, hi);
            assert_eq!(r.len(), 1, "[{lo}, {hi}]: {r:?}");
            assert_eq!((r[0].x, r[0].touching), (1.0, false), "[{lo}, {hi}]");
        }
    }

    /// p = (x - 1/2)^3 + d (x - 1/2), d > 0: p' never vanishes (its minimum, d at 1/2), but
    /// with an error of e on every coefficient p' is known only to within its own error, sum
    /// i e |x|^(i-1) (2.75 e at 1/2): with d = 2 e below that, the root at 1/2 may be a double
    /// root of the exact polynomial and is reported touching; with d = 4 e above it, crossing.
    #[test]
    fn a_root_where_p_prime_may_vanish_within_its_error_is_touching() {
        let e = 1e-12;
        for (d, touching) in [(2.0 * e, true), (4.0 * e, false)] {
            // x^3 - 1.5 x^2 + (0.75 + d) x - (0.125 + d / 2), exact at x = 1/2.
            let c = [-(0.125 + 0.5 * d), 0.75 + d, -1.5, 1.0];
            let r = roots_in_with_error(&c, &[e; 4], 0.0, 1.0);
            assert_eq!(r.len(), 1, "{d}: {r:?}");
            assert!((r[0].x - 0.5).abs() < 1e-4, "{d}: {r:?}");
            assert_eq!(r[0].touching, touching, "{d}: {r:?}");
        }
    }

    /// A root found twice (as a piece's end and as a critical point) is one root: pushes within
    /// 4 eps (1 + |x|) of the last one merge, touching only if both were; farther apart, two.
    #[test]
    fn roots_within_rounding_of_each_other_merge() {
        for x in [0.0, 1000.0, -3.0e6] {
            let tol = 4.0 * f64::EPSILON * (1.0 + f64::abs(x));
            let mut out = Roots::new();
            push_unique(&mut out, Root { x, touching: true });
            push_unique(
                &mut out,
                Root {
                    x: x + 0.9 * tol,
                    touching: false,
                },
            );
            assert_eq!(out.len(), 1, "{x}: {out:?}");
            assert_eq!((out[0].x, out[0].touching), (x, false), "{x}");
            push_unique(
                &mut out,
                Root {
                    x: x + 2.5 * tol,
                    touching: true,
                },
            );
            assert_eq!(out.len(), 2, "{x}: {out:?}");
        }
    }

    #[test]
    fn the_zero_polynomial_has_no_isolated_root() {
        // Every coefficient zero (or none): nothing to isolate, nothing reported, no panic.
        assert!(roots_in(&[0.0; 5], -1.0, 1.0).is_empty());
        assert!(roots_in(&[], -1.0, 1.0).is_empty());
        // Leading coefficients negligible next to the others are dropped: a line's root.
        let r = roots_in(&[-1.0, 2.0, 1e-310, 0.0], -10.0, 10.0);
        assert_eq!(r.len(), 1);
        assert!((r[0].x - 0.5).abs() < 1e-15);
    }

    /// Coefficient errors on every coefficient of a degree-8 polynomial (the largest degree):
    /// the derivative's errors (i err[i]) fit, and the roots are those of the exact routine.
    /// At a small scale a derivative error far too wide (err[i] + i, say) would make the
    /// derivative look zero everywhere and lose the two roots between its critical points.
    #[test]
    fn small_coefficient_errors_keep_every_root() {
        // 1e-3 (x + 0.9)(x + 0.2)(x - 0.3)(x - 0.6)(x - 2)(x - 3)(x + 4)(x - 5): roots in [-1, 1].
        let mut c = vec![1e-3];
        for r in [-0.9, -0.2, 0.3, 0.6, 2.0, 3.0, -4.0, 5.0] {
            let mut next = vec![0.0; c.len() + 1];
            for (i, a) in c.iter().enumerate() {
                next[i + 1] += a;
                next[i] -= a * r;
            }
            c = next;
        }
        assert_eq!(c.len(), MAX_DEGREE + 1);
        let err = [1e-15; MAX_DEGREE + 1];
        let exact = roots_in(&c, -1.0, 1.0);
        let with_error = roots_in_with_error(&c, &err, -1.0, 1.0);
        assert_eq!(exact.len(), 4, "{exact:?}");
        assert_eq!(with_error.len(), exact.len(), "{with_error:?}");
        for (a, b) in exact.iter().zip(&with_error) {
            assert!((a.x - b.x).abs() < 1e-9, "{exact:?} vs {with_error:?}");
        }
    }

    #[test]
    fn the_error_bound_covers_the_coefficients_errors() {
        // Coefficients each off by at most err: the value of every polynomial within those
        // errors lies within the bound of the computed value.
        let (c, err) = ([1.0, -2.0, 3.0, 0.5], [0.1, 0.05, 0.2, 0.01]);
        for x in [-2.0, -0.5, 0.0, 0.7, 3.0] {
            let (p, bound) = eval_with_coefficient_error(&c, &err, x);
            let mut widest = 0.0f64;
            for signs in 0..16u32 {
                let shifted: Vec<f64> = (0..4)
                    .map(|i| c[i] + if signs >> i & 1 == 1 { err[i] } else { -err[i] })
                    .collect();
                let q = eval_with_error(&shifted, x).0;
                assert!((q - p).abs() <= bound, "x={x}: |{q} - {p}| > {bound}");
                widest = widest.max((q - p).abs());
            }
            // And no wider than needed: the errors' worst case plus p's rounding bound.
            let rounding = eval_with_error(&c, x).1;
            assert!(
                bound <= widest * (1.0 + 1e-9) + 2.0 * rounding,
                "x={x}: {bound} vs {widest}"
            );
        }
    }
}
