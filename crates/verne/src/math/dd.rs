//! Double-double arithmetic (Dekker 1971; Hida, Li, Bailey's QD library): a number as the
//! unevaluated sum hi + lo of two doubles, about 106 bits of precision. The solvers recompute a
//! row in it where double precision cannot separate two roots (the forward kinematics' degree-8
//! polynomial of IFToMM 2007 section VI, the machine's theta1 equation of AIM 2007, the cubic
//! (9)); [`Tracked`] carries beside each value a bound on the magnitudes that entered it, from
//! which a rigorous bound on the rounding error follows (running error analysis, Higham,
//! *Accuracy and Stability of Numerical Algorithms*, 2nd ed., section 3.1).
//!
//! Products use Dekker's splitting rather than a fused multiply-add, so that the baseline x86-64
//! build (no FMA instruction) gives the same results as the AVX2 one.

use std::ops::{Add, Mul, Neg, Sub};

/// A double-double number hi + lo, |lo| <= ulp(hi) / 2.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

/// a + b = s + e exactly (Knuth's TwoSum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// a + b = s + e exactly when |a| >= |b|.
#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// a = hi + lo with each half fitting in 26 bits (Dekker's split).
#[inline]
fn split(a: f64) -> (f64, f64) {
    const SPLITTER: f64 = 134_217_729.0; // 2^27 + 1
    let t = SPLITTER * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

/// a * b = p + e exactly (Dekker's TwoProduct; |a b| below about 1e300).
#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    let e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    (p, e)
}

impl Dd {
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    pub const fn from_f64(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    /// The nearest double.
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// The exact product of two doubles.
    pub fn prod(a: f64, b: f64) -> Dd {
        let (p, e) = two_prod(a, b);
        Dd { hi: p, lo: e }
    }

    /// The exact sum of two doubles.
    pub fn sum(a: f64, b: f64) -> Dd {
        let (s, e) = two_sum(a, b);
        Dd { hi: s, lo: e }
    }

    pub fn abs(self) -> Dd {
        if self.hi < 0.0 { -self } else { self }
    }

    /// The sign of hi + lo (0 for zero).
    pub fn signum(self) -> f64 {
        if self.hi > 0.0 || (self.hi == 0.0 && self.lo > 0.0) {
            1.0
        } else if self.hi < 0.0 || (self.hi == 0.0 && self.lo < 0.0) {
            -1.0
        } else {
            0.0
        }
    }

    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }
}

impl Add for Dd {
    type Output = Dd;
    /// The accurate addition of the QD library (relative error about 2^-104 of |a| + |b|).
    #[inline]
    fn add(self, o: Dd) -> Dd {
        let (s1, s2) = two_sum(self.hi, o.hi);
        let (t1, t2) = two_sum(self.lo, o.lo);
        let s2 = s2 + t1;
        let (s1, s2) = quick_two_sum(s1, s2);
        let s2 = s2 + t2;
        let (hi, lo) = quick_two_sum(s1, s2);
        Dd { hi, lo }
    }
}

impl Neg for Dd {
    type Output = Dd;
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, o: Dd) -> Dd {
        self + (-o)
    }
}

impl Mul for Dd {
    type Output = Dd;
    /// Relative error about 2^-104 (a few units of the lower half).
    #[inline]
    fn mul(self, o: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, o.hi);
        let e = e + (self.hi * o.lo + self.lo * o.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}

impl Mul<f64> for Dd {
    type Output = Dd;
    #[inline]
    fn mul(self, k: f64) -> Dd {
        self * Dd::from_f64(k)
    }
}

impl From<f64> for Dd {
    fn from(x: f64) -> Dd {
        Dd::from_f64(x)
    }
}

/// Relative rounding of one double-double operation, in units of the magnitudes that enter it
/// (a generous bound on the QD library's: 2^-104 times a small constant).
pub const DD_OP_ERROR: f64 = 8.0 * 4.930_380_657_631_324e-32; // 8 * 2^-104

/// A double-double value with the magnitude it was computed from: for a sum, the sum of the
/// operands' magnitudes; for a product, their product (the value of the same expression with
/// every input and intermediate replaced by its absolute value). After n operations on any path
/// from an input, |value - exact| <= n [`DD_OP_ERROR`] mag (running error analysis; the
/// magnitudes are computed in double precision, rounded: a relative 1e-15, far inside the
/// bound's margin).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tracked {
    pub v: Dd,
    pub mag: f64,
}

impl Tracked {
    /// An exact input.
    pub fn exact(x: f64) -> Tracked {
        Tracked {
            v: Dd::from_f64(x),
            mag: x.abs(),
        }
    }

    /// A bound on |value - exact| after at most `ops` operations on any path.
    pub fn error(self, ops: u32) -> f64 {
        f64::from(ops) * DD_OP_ERROR * self.mag * (1.0 + 1e-12)
    }
}

impl From<f64> for Tracked {
    fn from(x: f64) -> Tracked {
        Tracked::exact(x)
    }
}

impl Add for Tracked {
    type Output = Tracked;
    #[inline]
    fn add(self, o: Tracked) -> Tracked {
        Tracked {
            v: self.v + o.v,
            mag: self.mag + o.mag,
        }
    }
}

impl Sub for Tracked {
    type Output = Tracked;
    #[inline]
    fn sub(self, o: Tracked) -> Tracked {
        Tracked {
            v: self.v - o.v,
            mag: self.mag + o.mag,
        }
    }
}

impl Neg for Tracked {
    type Output = Tracked;
    fn neg(self) -> Tracked {
        Tracked {
            v: -self.v,
            mag: self.mag,
        }
    }
}

impl Mul for Tracked {
    type Output = Tracked;
    #[inline]
    fn mul(self, o: Tracked) -> Tracked {
        Tracked {
            v: self.v * o.v,
            mag: self.mag * o.mag,
        }
    }
}

impl Mul<f64> for Tracked {
    type Output = Tracked;
    #[inline]
    fn mul(self, k: f64) -> Tracked {
        self * Tracked::exact(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_and_products_are_exact_where_they_should_be() {
        // (1 + 2^-60) - 1 = 2^-60, lost in double precision.
        let tiny = 2f64.powi(-60);
        let x = Dd::from_f64(1.0) + Dd::from_f64(tiny);
        assert_eq!((x - Dd::from_f64(1.0)).to_f64(), tiny);
        // (2^27 + 1)^2 = 2^54 + 2^28 + 1: the 1 is below double precision.
        let a = 134_217_729.0;
        let p = Dd::prod(a, a);
        assert_eq!(p.hi, 2f64.powi(54) + 2f64.powi(28));
        assert_eq!(p.lo, 1.0);
        let q = Dd::from_f64(a) * Dd::from_f64(a) - Dd::from_f64(2f64.powi(54) + 2f64.powi(28));
        assert_eq!(q.to_f64(), 1.0);
    }

    /// 1/3 as a double-double times 3 is 1 to about 2^-104; 0.1 + 0.2 - 0.3 is exact.
    #[test]
    fn precision_is_about_106_bits() {
        let third = Dd::sum(1.0 / 3.0, 0.0);
        // A better third: one Newton step in double-double.
        let three = Dd::from_f64(3.0);
        let r = third + third * (Dd::from_f64(1.0) - three * third);
        let one = r * three;
        assert!((one - Dd::from_f64(1.0)).to_f64().abs() < 1e-30);
        // The binary numbers nearest 0.1, 0.2 and 0.3 are k/2^55, 2k/2^54 and (3k + 1)/2^55 with
        // k = 3602879701896397: their exact sum and difference is 2^-55. Double precision
        // rounds the sum first and leaves 2^-54.
        let d = Dd::from_f64(0.1) + Dd::from_f64(0.2) - Dd::from_f64(0.3);
        assert_eq!(d.to_f64(), 2f64.powi(-55));
        assert_eq!(0.1 + 0.2 - 0.3, 2f64.powi(-54));
    }

    #[test]
    fn tracked_error_bounds_hold() {
        // (x + y)(x - y) with x, y close: the exact value is x^2 - y^2.
        let x = 1.0 + 2f64.powi(-30);
        let y = 1.0;
        let e = (Tracked::exact(x) + Tracked::exact(y)) * (Tracked::exact(x) - Tracked::exact(y));
        let exact = Dd::prod(x, x) - Dd::prod(y, y);
        let diff = (e.v - exact).to_f64().abs();
        assert!(diff <= e.error(3), "{diff} {}", e.error(3));
        assert_eq!(e.mag, (x + y) * (x + y));
    }

    /// Exact rationals for the checks below (num-rational: every double is a rational).
    type Exact = num_rational::BigRational;

    fn exact(x: f64) -> Exact {
        Exact::from_float(x).expect("finite")
    }

    fn exact_dd(x: Dd) -> Exact {
        exact(x.hi) + exact(x.lo)
    }

    fn abs_exact(x: Exact) -> Exact {
        if x < exact(0.0) { -x } else { x }
    }

    /// Random double-doubles over 2^-60 to 2^60, both signs, normalised (the sum of two doubles
    /// of which the second is up to 2^-40 of the first, or an exact sum of two unrelated ones).
    fn random_dd(unit: &mut impl FnMut() -> f64, k: usize) -> Dd {
        let scale = 2f64.powi((unit() * 120.0) as i32 - 60);
        let a = (unit() - 0.5) * scale;
        let b = (unit() - 0.5) * scale * if k % 2 == 0 { 2f64.powi(-40) } else { 1.0 };
        Dd::sum(a, b)
    }

    /// |lo| is at most half a unit of hi: hi is the double nearest hi + lo.
    fn normalised(x: Dd) -> bool {
        x.hi + x.lo == x.hi
    }

    /// Every operation of [`Dd`] against exact rational arithmetic on 20,000 pairs: the results
    /// are normalised and within [`DD_OP_ERROR`] of the operands' magnitudes (sum: |a| + |b|,
    /// product: |a| |b|); `prod` and `sum` of two doubles are exact, and so are negation and
    /// `abs`. The signs and `to_f64` (the nearest double) follow the exact value.
    #[test]
    fn every_operation_is_within_its_bound_of_the_exact_result() {
        let mut unit = crate::math::test_rng::lcg(0x000d_d0b5);
        let bound = |mag: Exact| mag * exact(DD_OP_ERROR);
        for k in 0..20_000 {
            let (a, b) = (random_dd(&mut unit, k), random_dd(&mut unit, k / 2));
            let (ea, eb) = (exact_dd(a), exact_dd(b));
            let mag_sum = abs_exact(ea.clone()) + abs_exact(eb.clone());
            let mag_prod = abs_exact(ea.clone()) * abs_exact(eb.clone());
            for (name, got, want, mag) in [
                ("+", a + b, ea.clone() + eb.clone(), mag_sum.clone()),
                ("-", a - b, ea.clone() - eb.clone(), mag_sum),
                ("*", a * b, ea.clone() * eb.clone(), mag_prod.clone()),
                (
                    "* f64",
                    a * b.hi,
                    ea.clone() * exact(b.hi),
                    abs_exact(ea.clone() * exact(b.hi)),
                ),
            ] {
                assert!(normalised(got), "{a:?} {name} {b:?}: {got:?}");
                let err = abs_exact(exact_dd(got) - want);
                assert!(err <= bound(mag), "{a:?} {name} {b:?}: {got:?}");
            }
            assert_eq!(exact_dd(Dd::prod(a.hi, b.hi)), exact(a.hi) * exact(b.hi));
            assert_eq!(exact_dd(Dd::sum(a.hi, b.lo)), exact(a.hi) + exact(b.lo));
            assert!(normalised(Dd::sum(a.hi, b.lo)) && normalised(Dd::prod(a.hi, b.hi)));
            assert_eq!(exact_dd(-a), -ea.clone());
            assert_eq!(exact_dd(a.abs()), abs_exact(ea.clone()));
            let sign = if ea > exact(0.0) { 1.0 } else { -1.0 };
            assert_eq!(a.signum(), sign);
            // to_f64 is hi + lo rounded: the nearest double to the exact value.
            let x = a.to_f64();
            let gap = abs_exact(exact(x) - ea.clone());
            for y in [
                super::super::interval::next_up(x),
                super::super::interval::next_down(x),
            ] {
                assert!(gap <= abs_exact(exact(y) - ea.clone()), "{a:?}");
            }
        }
        assert_eq!(Dd::ZERO.signum(), 0.0);
        assert_eq!(
            Dd {
                hi: 0.0,
                lo: -1e-300
            }
            .signum(),
            -1.0
        );
        assert_eq!(
            Dd {
                hi: 0.0,
                lo: 1e-300
            }
            .signum(),
            1.0
        );
        assert!(
            Dd::ZERO.is_finite()
                && !Dd {
                    hi: 1.0,
                    lo: f64::NAN
                }
                .is_finite()
        );
        assert!(
            !Dd {
                hi: f64::INFINITY,
                lo: 0.0
            }
            .is_finite()
        );
    }

    /// [`Tracked`] on random expressions of exact inputs (sums, differences, products, negations
    /// and scalings, up to 12 operations deep): the value is within `error(ops)` of the exact
    /// one, where ops is the expression's depth, and `mag` is the value of the same expression
    /// on the inputs' absolute values with every difference a sum (to 1e-12).
    #[test]
    fn tracked_bounds_hold_on_random_expressions() {
        let mut unit = crate::math::test_rng::lcg(0x0007_aced);
        for _ in 0..2_000 {
            let input = |u: &mut dyn FnMut() -> f64| {
                let x = (u() - 0.5) * 2f64.powi((u() * 40.0) as i32 - 20);
                (Tracked::exact(x), exact(x), exact(x.abs()))
            };
            let (mut t, mut e, mut m) = input(&mut unit);
            for depth in 1..=12u32 {
                let (u, eu, mu) = input(&mut unit);
                (t, e, m) = match (unit() * 5.0) as u32 {
                    0 => (t + u, e + eu, m + mu),
                    1 => (t - u, e - eu, m + mu),
                    2 => (u - t, eu - e, m + mu),
                    3 => (t * u, e * eu, m * mu),
                    _ => {
                        let k = (unit() - 0.5) * 8.0;
                        (-(t * k), -(e * exact(k)), m * exact(k.abs()))
                    }
                };
                let err = abs_exact(exact_dd(t.v) - e.clone());
                assert!(err <= exact(t.error(depth)), "depth {depth}: {t:?}");
                let rel = abs_exact(exact(t.mag) - m.clone());
                assert!(rel <= m.clone() * exact(1e-12), "depth {depth}: {t:?}");
            }
        }
        assert_eq!(
            Tracked::exact(-2.0).error(3),
            3.0 * DD_OP_ERROR * 2.0 * (1.0 + 1e-12)
        );
        assert_eq!(Tracked::from(-2.5), Tracked::exact(-2.5));
        assert_eq!(Tracked::exact(-2.5).mag, 2.5);
    }
}
