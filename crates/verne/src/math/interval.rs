//! Interval arithmetic with outward rounding: every operation returns an interval that contains
//! the exact result of the same operation on any values of its operand intervals. Used where a
//! solver must prove something (a sign, a monotone function) rather than estimate it: the
//! forward kinematics' certificate near the roots of condition (21), IFToMM 2007.
//!
//! IEEE 754 rounds each basic operation (+, -, *, /, sqrt) to nearest, so the exact result lies
//! within half a unit in the last place of the computed one: one step outward ([`next_down`],
//! [`next_up`]) bounds it. `sin` and `cos` come from the platform's libm, accurate to within one
//! unit in the last place; they are widened by four.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The next representable number towards +infinity (NaN and +infinity unchanged).
pub fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    f64::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
}

/// The next representable number towards -infinity (NaN and -infinity unchanged).
pub fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// A closed interval [lo, hi] of real numbers; empty or meaningless when either end is NaN.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Iv {
    pub lo: f64,
    pub hi: f64,
}

impl Iv {
    /// The interval holding exactly `x`.
    pub const fn point(x: f64) -> Iv {
        Iv { lo: x, hi: x }
    }

    /// The interval [lo, hi] (the caller guarantees lo <= hi).
    pub const fn new(lo: f64, hi: f64) -> Iv {
        Iv { lo, hi }
    }

    /// The whole real line: what a division by an interval holding zero gives.
    pub const ENTIRE: Iv = Iv {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// Every value of the interval is above zero.
    pub fn positive(self) -> bool {
        self.lo > 0.0
    }

    /// Every value of the interval is below zero.
    pub fn negative(self) -> bool {
        self.hi < 0.0
    }

    /// The sign every value of the interval has: Some(+1 or -1), None when it holds zero (or is
    /// not finite).
    pub fn sign(self) -> Option<i8> {
        if self.positive() {
            Some(1)
        } else if self.negative() {
            Some(-1)
        } else {
            None
        }
    }

    /// Both ends finite.
    pub fn is_finite(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// The largest |x| over the interval.
    pub fn mag(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// |x| over the interval.
    pub fn abs(self) -> Iv {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Iv::new(0.0, self.mag())
        }
    }

    /// The midpoint (rounded).
    pub fn mid(self) -> f64 {
        0.5 * (self.lo + self.hi)
    }

    /// The midpoint and a radius that reaches both ends: [lo, hi] lies in mid +- rad.
    pub fn mid_rad(self) -> (f64, f64) {
        let m = self.mid();
        (m, next_up((self.hi - m).max(m - self.lo)))
    }

    fn outward(lo: f64, hi: f64) -> Iv {
        Iv {
            lo: next_down(lo),
            hi: next_up(hi),
        }
    }

    /// x^2 (tighter than x * x when the interval holds zero).
    pub fn sqr(self) -> Iv {
        if self.lo >= 0.0 {
            Iv::outward(self.lo * self.lo, self.hi * self.hi)
        } else if self.hi <= 0.0 {
            Iv::outward(self.hi * self.hi, self.lo * self.lo)
        } else {
            let m = self.mag();
            Iv::new(0.0, next_up(m * m))
        }
    }

    /// The square root of the part of the interval at or above zero; NaN ends when it is all
    /// below zero.
    pub fn sqrt(self) -> Iv {
        if self.hi < 0.0 {
            return Iv::point(f64::NAN);
        }
        Iv::new(
            next_down(self.lo.max(0.0).sqrt()).max(0.0),
            next_up(self.hi.sqrt()),
        )
    }

    /// sin and cos over [lo, hi] (an interval of angles, rad, narrower than pi / 2 for a useful
    /// answer): the values at the ends widened by four units in the last place, and +-1 where an
    /// extremum lies inside.
    pub fn sin_cos(self) -> (Iv, Iv) {
        use std::f64::consts::{FRAC_PI_2, PI};
        if !self.is_finite() || self.hi - self.lo >= FRAC_PI_2 {
            let unit = Iv::new(-1.0, 1.0);
            return (unit, unit);
        }
        let widen = |v: f64| {
            let pad = 4.0 * f64::EPSILON * v.abs() + f64::MIN_POSITIVE;
            (v - pad, v + pad)
        };
        let (sa, ca) = self.lo.sin_cos();
        if self.lo == self.hi {
            let (s0, s1) = widen(sa);
            let (c0, c1) = widen(ca);
            return (
                Iv::new(s0.max(-1.0), s1.min(1.0)),
                Iv::new(c0.max(-1.0), c1.min(1.0)),
            );
        }
        let (sb, cb) = self.hi.sin_cos();
        let span = |a: f64, b: f64| {
            let (a0, a1) = widen(a);
            let (b0, b1) = widen(b);
            Iv::new(a0.min(b0).max(-1.0), a1.max(b1).min(1.0))
        };
        let (mut s, mut c) = (span(sa, sb), span(ca, cb));
        // An extremum of cos at k pi, of sin at pi/2 + k pi, strictly inside (or within rounding
        // of an end: then the end values already come within rounding of +-1).
        let holds = |x0: f64| {
            let k = ((self.lo - x0) / PI).ceil();
            let x = x0 + k * PI;
            (x <= self.hi + 1e-15).then(|| {
                if (k as i64).rem_euclid(2) == 0 {
                    1.0
                } else {
                    -1.0
                }
            })
        };
        if let Some(v) = holds(0.0) {
            c = Iv::new(c.lo.min(v), c.hi.max(v));
        }
        if let Some(v) = holds(FRAC_PI_2) {
            s = Iv::new(s.lo.min(v), s.hi.max(v));
        }
        (s, c)
    }
}

/// The sum of c_j v_j for point coefficients c, in midpoint-radius form (S. M. Rump, *BIT* 39,
/// 1999): one floating-point dot product for the middle, one for the radius, and the rounding
/// error of both bounded by a multiple of the unit roundoff times the sum of |c_j m_j| (Higham,
/// *Accuracy and Stability of Numerical Algorithms*, 2002, sec. 3.1, with ample slack). Holds
/// every value of the interval sum, a few times cheaper; the whole line when a term is not finite.
pub fn point_dot<const N: usize>(c: &[f64; N], v: &[Iv; N]) -> Iv {
    let (mut mid, mut rad, mut size) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (cj, vj) in c.iter().zip(v) {
        let (m, r) = vj.mid_rad();
        mid += cj * m;
        rad += cj.abs() * r;
        size += (cj * m).abs();
    }
    // gamma_n = n u / (1 - n u) with u = EPSILON / 2 bounds each sum's error relative to its
    // terms' magnitudes; 2n + 4 units of EPSILON cover both sums and the final operations.
    let k = (2 * N + 4) as f64 * f64::EPSILON;
    let r = rad * (1.0 + k) + size * k + (N + 1) as f64 * f64::MIN_POSITIVE;
    if !(mid.is_finite() && r.is_finite()) {
        return Iv::ENTIRE;
    }
    Iv::outward(mid - r, mid + r)
}

impl From<f64> for Iv {
    fn from(x: f64) -> Iv {
        Iv::point(x)
    }
}

impl Add for Iv {
    type Output = Iv;
    fn add(self, o: Iv) -> Iv {
        Iv::outward(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Iv {
    type Output = Iv;
    fn sub(self, o: Iv) -> Iv {
        Iv::outward(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Neg for Iv {
    type Output = Iv;
    fn neg(self) -> Iv {
        Iv::new(-self.hi, -self.lo)
    }
}

impl Mul for Iv {
    type Output = Iv;
    fn mul(self, o: Iv) -> Iv {
        // A point times a finite interval: two products (the other two are the same).
        if o.lo == o.hi && o.lo.is_finite() && self.is_finite() {
            let (a, b) = (self.lo * o.lo, self.hi * o.lo);
            return Iv::outward(a.min(b), a.max(b));
        }
        if self.lo == self.hi && self.lo.is_finite() && o.is_finite() {
            let (a, b) = (o.lo * self.lo, o.hi * self.lo);
            return Iv::outward(a.min(b), a.max(b));
        }
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        if p.iter().any(|v| v.is_nan()) {
            // 0 * inf: the product of a zero-width zero and an unbounded interval.
            return if self == Iv::point(0.0) || o == Iv::point(0.0) {
                Iv::point(0.0)
            } else {
                Iv::ENTIRE
            };
        }
        let lo = p.iter().fold(f64::INFINITY, |m, v| m.min(*v));
        let hi = p.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
        Iv::outward(lo, hi)
    }
}

impl Div for Iv {
    type Output = Iv;
    fn div(self, o: Iv) -> Iv {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return Iv::ENTIRE;
        }
        let q = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        let lo = q.iter().fold(f64::INFINITY, |m, v| m.min(*v));
        let hi = q.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
        Iv::outward(lo, hi)
    }
}

impl Mul<f64> for Iv {
    type Output = Iv;
    fn mul(self, k: f64) -> Iv {
        self * Iv::point(k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The midpoint-radius sum holds the interval sum's every value (its ends and, for
    /// coefficients of mixed sign, the ends' corners), and is as tight to a few units.
    #[test]
    fn point_dot_holds_the_interval_sum() {
        let mut seed = 7_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        for trial in 0..2000 {
            let scale = 10f64.powi(trial % 9 - 4);
            let c: [f64; 4] = std::array::from_fn(|_| next() * 1e3);
            let v: [Iv; 4] = std::array::from_fn(|_| {
                let m = next() * scale;
                let r = if trial % 3 == 0 {
                    0.0
                } else {
                    next().abs() * scale * 1e-3
                };
                Iv::new(m - r, m + r)
            });
            let by_intervals = (0..4).fold(Iv::point(0.0), |acc, j| acc + Iv::point(c[j]) * v[j]);
            let fast = point_dot(&c, &v);
            assert!(
                fast.lo <= by_intervals.lo && by_intervals.hi <= fast.hi,
                "{trial}"
            );
            let slack =
                64.0 * f64::EPSILON * (0..4).map(|j| (c[j] * v[j].mag()).abs()).sum::<f64>();
            assert!(by_intervals.lo - fast.lo <= slack && fast.hi - by_intervals.hi <= slack);
            // Every corner of the box lies inside.
            for corner in 0..16 {
                let x: f64 = (0..4)
                    .map(|j| {
                        c[j] * if corner >> j & 1 == 1 {
                            v[j].hi
                        } else {
                            v[j].lo
                        }
                    })
                    .sum();
                assert!(fast.lo <= x && x <= fast.hi);
            }
        }
        assert_eq!(
            point_dot(&[1.0, 2.0], &[Iv::ENTIRE, Iv::point(1.0)]),
            Iv::ENTIRE
        );
    }

    #[test]
    fn steps_are_one_unit() {
        for x in [1.0, -1.0, 1e-300, -3.5e200, 0.1] {
            assert!(next_up(x) > x && next_down(x) < x);
            assert_eq!(next_down(next_up(x)), x);
        }
        assert_eq!(next_up(0.0), f64::from_bits(1));
        assert_eq!(next_down(0.0), -f64::from_bits(1));
        assert_eq!(next_up(f64::MAX), f64::INFINITY);
        assert_eq!(next_up(f64::INFINITY), f64::INFINITY);
        assert_eq!(next_down(f64::NEG_INFINITY), f64::NEG_INFINITY);
        assert_eq!(next_up(f64::NEG_INFINITY), -f64::MAX);
        assert!(next_up(f64::NAN).is_nan() && next_down(f64::NAN).is_nan());
    }

    /// The predicates the proofs rest on at their edges: an interval touching zero has no
    /// sign, one with an infinite or NaN end is not finite.
    #[test]
    fn signs_and_finiteness_at_the_edges() {
        for (iv, sign) in [
            (Iv::new(0.0, 1.0), None),
            (Iv::new(-1.0, 0.0), None),
            (Iv::point(0.0), None),
            (Iv::new(-1.0, 1.0), None),
            (Iv::new(f64::MIN_POSITIVE, 1.0), Some(1)),
            (Iv::new(-1.0, -f64::MIN_POSITIVE), Some(-1)),
        ] {
            assert_eq!(iv.sign(), sign, "{iv:?}");
            assert_eq!(iv.positive(), sign == Some(1), "{iv:?}");
            assert_eq!(iv.negative(), sign == Some(-1), "{iv:?}");
        }
        assert!(Iv::new(-1.0, 2.0).is_finite());
        for iv in [
            Iv::new(f64::NEG_INFINITY, 0.0),
            Iv::new(0.0, f64::INFINITY),
            Iv::new(f64::NAN, 0.0),
            Iv::new(0.0, f64::NAN),
            Iv::ENTIRE,
        ] {
            assert!(!iv.is_finite(), "{iv:?}");
        }
    }

    /// The midpoint; the square root of an interval touching zero from below (zero) and of one
    /// below it (NaN); 0 times an unbounded interval (exactly 0 for a zero-width zero, unbounded
    /// otherwise).
    #[test]
    fn midpoint_square_root_at_zero_and_zero_times_unbounded() {
        assert_eq!(Iv::new(1.0, 4.0).mid(), 2.5);
        assert_eq!(Iv::new(-3.0, -2.0).mid(), -2.5);
        assert_eq!(Iv::new(-1.0, 0.0).sqrt(), Iv::new(0.0, next_up(0.0)));
        assert!(Iv::new(-2.0, -1.0).sqrt().lo.is_nan());
        assert_eq!(Iv::point(0.0) * Iv::ENTIRE, Iv::point(0.0));
        assert_eq!(Iv::ENTIRE * Iv::point(0.0), Iv::point(0.0));
        assert_eq!(Iv::new(0.0, 1.0) * Iv::ENTIRE, Iv::ENTIRE);
        assert_eq!(Iv::ENTIRE * Iv::new(-1.0, 0.0), Iv::ENTIRE);
    }

    /// Every operation's interval holds the exact result of sample points, checked against
    /// products and sums that are exact in double precision (small integers).
    #[test]
    fn operations_enclose_their_results() {
        let a = Iv::new(-3.0, 5.0);
        let b = Iv::new(2.0, 7.0);
        let within = |i: Iv, x: f64| i.lo <= x && x <= i.hi;
        for x in [-3.0, -1.0, 0.0, 5.0] {
            for y in [2.0, 3.0, 7.0] {
                assert!(within(a + b, x + y));
                assert!(within(a - b, x - y));
                assert!(within(a * b, x * y));
                assert!(within(a / b, x / y));
                assert!(within(a.sqr(), x * x));
            }
        }
        assert_eq!((a / Iv::new(-1.0, 1.0)), Iv::ENTIRE);
        assert!(Iv::new(0.1, 0.3).sqrt().lo > 0.3 && Iv::new(0.1, 0.3).sqrt().hi < 0.55);
        // 0.1 + 0.2 is not 0.3 in binary: the interval of the sum of the two points holds the
        // exact sum of the two binary numbers, which lies between the two neighbours of 0.3.
        let s = Iv::point(0.1) + Iv::point(0.2);
        assert!(s.lo < s.hi && s.lo <= 0.3 + 1e-16 && s.hi >= 0.3 - 1e-16);
    }

    #[test]
    fn sine_and_cosine_over_intervals() {
        use std::f64::consts::{FRAC_PI_2, PI};
        for (lo, hi) in [
            (0.1, 0.2),
            (-0.1, 0.1),
            (FRAC_PI_2 - 0.01, FRAC_PI_2 + 0.02),
        ] {
            let (s, c) = Iv::new(lo, hi).sin_cos();
            for k in 0..=100 {
                let x = lo + (hi - lo) * k as f64 / 100.0;
                assert!(s.lo <= x.sin() && x.sin() <= s.hi, "{x}");
                assert!(c.lo <= x.cos() && x.cos() <= c.hi, "{x}");
            }
        }
        let (_, c) = Iv::new(PI - 0.01, PI + 0.01).sin_cos();
        assert_eq!(c.lo, -1.0);
        let (_, c) = Iv::new(-0.01, 0.01).sin_cos();
        assert_eq!(c.hi, 1.0);
    }

    /// Exact results of one rounded operation by error-free transformations: x op y = v + e
    /// with both parts doubles (sum: Knuth's two-sum; product: a fused multiply-add; quotient
    /// and square root: the remainder, whose sign is the error's).
    fn exact_sum(x: f64, y: f64) -> (f64, f64) {
        let s = x + y;
        let yy = s - x;
        (s, (x - (s - yy)) + (y - yy))
    }

    fn exact_product(x: f64, y: f64) -> (f64, f64) {
        let p = x * y;
        (p, x.mul_add(y, -p))
    }

    /// lo <= v + e, exactly (v - lo is exact for lo within a factor two of v, and the sign of a
    /// rounded sum of two doubles is the sign of the exact one).
    fn at_least(lo: f64, (v, e): (f64, f64)) -> bool {
        v.is_infinite() || (v - lo) + e >= 0.0
    }

    fn at_most(hi: f64, (v, e): (f64, f64)) -> bool {
        v.is_infinite() || (hi - v) - e >= 0.0
    }

    fn holds(i: Iv, exact: (f64, f64)) -> bool {
        at_least(i.lo, exact) && at_most(i.hi, exact)
    }

    /// Random intervals with ends from 1e-300 to 1e300 of both signs, and straddling zero.
    fn intervals(count: usize) -> Vec<Iv> {
        let mut unit = crate::math::test_rng::lcg(0x001e_7ea1);
        (0..count)
            .map(|k| {
                let scale = 10f64.powi((unit() * 600.0) as i32 - 300);
                let a = (unit() - 0.5) * scale;
                let b = match k % 3 {
                    0 => a + unit() * scale,
                    1 => a * (1.0 + unit() * 1e-6),
                    _ => -a * unit(),
                };
                Iv::new(a.min(b), a.max(b))
            })
            .collect()
    }

    /// Each operation's interval holds the exact result at every pair of ends (where +, -, *
    /// and / take their extremes) and at the ends of x^2 and sqrt (monotone pieces): rounding
    /// to nearest is corrected outward. 6,400 pairs over 600 decades.
    #[test]
    fn every_operation_holds_the_exact_results_at_its_ends() {
        let ivs = intervals(80);
        let mut checked = 0;
        for &a in &ivs {
            for &b in &ivs {
                for x in [a.lo, a.hi] {
                    for y in [b.lo, b.hi] {
                        assert!(holds(a + b, exact_sum(x, y)), "{a:?} + {b:?}");
                        assert!(holds(a - b, exact_sum(x, -y)), "{a:?} - {b:?}");
                        let p = exact_product(x, y);
                        if p.0.is_finite() && p.0.abs() > 1e-290 {
                            assert!(holds(a * b, p), "{a:?} * {b:?}");
                            assert!(holds(a * y, p), "{a:?} * {y}");
                        }
                        let q = x / y;
                        if b.sign().is_some() && q.is_finite() && q.abs() > 1e-290 {
                            // x = q y + r exactly; x / y = q + r / y.
                            let r = (-q).mul_add(y, x);
                            assert!(holds(a / b, (q, r / y)), "{a:?} / {b:?}");
                        }
                        checked += 1;
                    }
                }
                let sq = exact_product(a.lo, a.lo);
                if sq.0.is_finite() && sq.0 > 1e-290 {
                    assert!(holds(a.sqr(), sq), "{a:?}^2");
                }
                for x in [a.lo, a.hi] {
                    if x > 1e-290 {
                        let s = x.sqrt();
                        let r = (-s).mul_add(s, x);
                        assert!(holds(a.sqrt(), (s, r / (2.0 * s))), "sqrt {a:?}");
                    }
                }
            }
        }
        assert_eq!(checked, 25_600);
    }

    /// No operation widens by more than one unit beyond the rounded results at the ends (what
    /// the proofs' bisection depth is sized for).
    #[test]
    fn enclosures_are_one_unit_beyond_the_rounded_ends() {
        let ivs = intervals(80);
        let tight = |i: Iv, values: &[f64]| {
            let lo = values.iter().fold(f64::INFINITY, |m, v| m.min(*v));
            let hi = values.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
            i.lo == next_down(lo) && i.hi == next_up(hi)
        };
        for &a in &ivs {
            for &b in &ivs {
                let ends = |f: fn(f64, f64) -> f64| {
                    [f(a.lo, b.lo), f(a.lo, b.hi), f(a.hi, b.lo), f(a.hi, b.hi)]
                };
                assert!(tight(a + b, &ends(|x, y| x + y)), "{a:?} + {b:?}");
                assert!(tight(a - b, &ends(|x, y| x - y)), "{a:?} - {b:?}");
                let p = ends(|x, y| x * y);
                if p.iter().all(|v| v.is_finite()) {
                    assert!(tight(a * b, &p), "{a:?} * {b:?}");
                }
                let q = ends(|x, y| x / y);
                if b.sign().is_some() && q.iter().all(|v| v.is_finite()) {
                    assert!(tight(a / b, &q), "{a:?} / {b:?}");
                }
            }
            let s = [a.lo * a.lo, a.hi * a.hi];
            if s.iter().all(|v| v.is_finite()) {
                let sq = a.sqr();
                if a.lo >= 0.0 || a.hi <= 0.0 {
                    assert!(tight(sq, &s), "{a:?}^2");
                } else {
                    assert!(sq.lo == 0.0 && sq.hi == next_up(s[0].max(s[1])), "{a:?}^2");
                }
            }
            assert_eq!(-a, Iv::new(-a.hi, -a.lo));
            let abs = a.abs();
            assert!(abs.lo >= 0.0 && abs.hi == a.mag(), "{a:?}");
            assert_eq!(
                abs.lo,
                if a.lo > 0.0 {
                    a.lo
                } else if a.hi < 0.0 {
                    -a.hi
                } else {
                    0.0
                }
            );
        }
    }

    /// sin and cos over random intervals narrower than pi / 2 anywhere in [-8, 8]: every sample
    /// inside (and the extremum +-1 where one lies inside) is held, and the enclosure is no
    /// wider than the sampled range plus the widening and the samples' spacing.
    #[test]
    fn sine_and_cosine_hold_every_value_and_no_more() {
        let mut unit = crate::math::test_rng::lcg(0x0005_1c05);
        for k in 0..4_000 {
            let lo = (unit() - 0.5) * 16.0;
            let width = [1e-9, 1e-3, 0.3, 1.5][k % 4] * unit();
            let i = Iv::new(lo, lo + width);
            let (s, c) = i.sin_cos();
            let (mut smin, mut smax, mut cmin, mut cmax) = (2.0f64, -2.0f64, 2.0f64, -2.0f64);
            for j in 0..=256 {
                let x = if j == 256 {
                    i.hi
                } else {
                    lo + width * f64::from(j) / 256.0
                };
                let (sx, cx) = x.sin_cos();
                assert!(s.lo <= sx && sx <= s.hi, "{i:?}: sin {x}");
                assert!(c.lo <= cx && cx <= c.hi, "{i:?}: cos {x}");
                (smin, smax) = (smin.min(sx), smax.max(sx));
                (cmin, cmax) = (cmin.min(cx), cmax.max(cx));
            }
            // The ends' values are widened (libm is within one unit of sin and cos) where no
            // extremum lies inside.
            let two_units = |v: f64| 2.0 * f64::EPSILON * v.abs();
            let (sa, ca) = lo.sin_cos();
            let (sb, cb) = i.hi.sin_cos();
            if s.lo > -1.0 && s.hi < 1.0 {
                assert!(s.lo <= sa.min(sb) - two_units(sa.min(sb)), "{i:?}: {s:?}");
                assert!(s.hi >= sa.max(sb) + two_units(sa.max(sb)), "{i:?}: {s:?}");
            }
            if c.lo > -1.0 && c.hi < 1.0 {
                assert!(c.lo <= ca.min(cb) - two_units(ca.min(cb)), "{i:?}: {c:?}");
                assert!(c.hi >= ca.max(cb) + two_units(ca.max(cb)), "{i:?}: {c:?}");
            }
            // The spacing's bound on what the samples miss, plus the widening of four units.
            let slack = (width / 256.0).powi(2) + 1e-15;
            assert!(
                s.lo >= smin - slack && s.hi <= smax + slack,
                "{i:?}: {s:?} {smin} {smax}"
            );
            assert!(
                c.lo >= cmin - slack && c.hi <= cmax + slack,
                "{i:?}: {c:?} {cmin} {cmax}"
            );
        }
        let wide = Iv::new(0.0, 2.0).sin_cos();
        assert_eq!(wide, (Iv::new(-1.0, 1.0), Iv::new(-1.0, 1.0)));
        assert_eq!(Iv::new(f64::NAN, 1.0).sin_cos().0, Iv::new(-1.0, 1.0));
    }
}
