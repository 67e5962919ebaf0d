//! Trigonometric polynomials a0 + sum_k (a_k cos k x + b_k sin k x) of degree at most 4, and
//! their conversion to ordinary polynomials by the half-angle substitution t = tan(x/2).

use crate::poly::Coeffs;

/// Highest harmonic kept.
pub const MAX_HARMONIC: usize = 4;

/// `cos[k]`, `sin[k]` are the coefficients of cos(k x) and sin(k x); `sin[0]` is unused (0).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Trig {
    pub cos: [f64; MAX_HARMONIC + 1],
    pub sin: [f64; MAX_HARMONIC + 1],
}

impl Trig {
    /// a0 + ac cos x + as sin x.
    pub const fn linear(a0: f64, ac: f64, a_s: f64) -> Trig {
        Trig {
            cos: [a0, ac, 0.0, 0.0, 0.0],
            sin: [0.0, a_s, 0.0, 0.0, 0.0],
        }
    }

    pub fn degree(&self) -> usize {
        (0..=MAX_HARMONIC)
            .rev()
            .find(|&k| self.cos[k] != 0.0 || self.sin[k] != 0.0)
            .unwrap_or(0)
    }

    pub fn eval(&self, x: f64) -> f64 {
        let (s1, c1) = x.sin_cos();
        let (mut ck, mut sk) = (1.0, 0.0);
        let mut acc = self.cos[0];
        for k in 1..=MAX_HARMONIC {
            let c = ck * c1 - sk * s1;
            sk = sk * c1 + ck * s1;
            ck = c;
            acc += self.cos[k] * ck + self.sin[k] * sk;
        }
        acc
    }

    pub fn add(&self, o: &Trig) -> Trig {
        let mut r = *self;
        for k in 0..=MAX_HARMONIC {
            r.cos[k] += o.cos[k];
            r.sin[k] += o.sin[k];
        }
        r
    }

    pub fn scale(&self, f: f64) -> Trig {
        let mut r = *self;
        for k in 0..=MAX_HARMONIC {
            r.cos[k] *= f;
            r.sin[k] *= f;
        }
        r
    }

    /// The product; the caller guarantees the degrees add up to at most [`MAX_HARMONIC`].
    pub fn mul(&self, o: &Trig) -> Trig {
        let (da, db) = (self.degree(), o.degree());
        debug_assert!(da + db <= MAX_HARMONIC);
        let mut r = Trig::default();
        for j in 0..=da {
            let (aj, bj) = (self.cos[j], self.sin[j]);
            for k in 0..=db {
                let (ak, bk) = (o.cos[k], o.sin[k]);
                let sum = j + k;
                let diff = j.abs_diff(k);
                // cos j cos k = (cos(j-k) + cos(j+k)) / 2
                r.cos[sum] += 0.5 * aj * ak;
                r.cos[diff] += 0.5 * aj * ak;
                // sin j sin k = (cos(j-k) - cos(j+k)) / 2
                r.cos[diff] += 0.5 * bj * bk;
                r.cos[sum] -= 0.5 * bj * bk;
                // sin j cos k = (sin(j+k) + sin(j-k)) / 2
                r.sin[sum] += 0.5 * bj * ak;
                r.sin[sum] += 0.5 * aj * bk;
                if j >= k {
                    r.sin[diff] += 0.5 * bj * ak;
                    r.sin[diff] -= 0.5 * aj * bk;
                } else {
                    r.sin[diff] -= 0.5 * bj * ak;
                    r.sin[diff] += 0.5 * aj * bk;
                }
            }
        }
        r.sin[0] = 0.0;
        r
    }

    /// (1 + t^2)^4 p(x) as a polynomial in t = tan((x - shift)/2), shift in {0, pi}: the
    /// half-angle substitution of IFToMM 2007 section VI. With shift = pi the chart covers
    /// x near pi, where t = tan(x/2) would be infinite.
    pub fn to_half_angle_poly(&self, shift_pi: bool) -> Coeffs {
        let mut out = Coeffs::new();
        for _ in 0..=2 * MAX_HARMONIC {
            out.push(0.0);
        }
        for k in 0..=MAX_HARMONIC {
            let sign = if shift_pi && k % 2 == 1 { -1.0 } else { 1.0 };
            for i in 0..=2 * MAX_HARMONIC {
                out[i] += sign
                    * (self.cos[k] * HALF_ANGLE_COS[k][i] + self.sin[k] * HALF_ANGLE_SIN[k][i]);
            }
        }
        out
    }
}

/// (1+t^2)^4 cos(k x) and (1+t^2)^4 sin(k x) as polynomials in t = tan(x/2): the real and
/// imaginary parts of (1 + i t)^(4+k) (1 - i t)^(4-k).
const HALF_ANGLE_COS: [[f64; 9]; 5] = half_angle_table(false);
const HALF_ANGLE_SIN: [[f64; 9]; 5] = half_angle_table(true);

const fn half_angle_table(imag: bool) -> [[f64; 9]; 5] {
    let mut table = [[0.0; 9]; 5];
    let mut k = 0;
    while k <= 4 {
        // Complex polynomial coefficients (re, im) of (1 + i t)^(4+k) (1 - i t)^(4-k).
        let mut re = [0i64; 9];
        let mut im = [0i64; 9];
        re[0] = 1;
        let mut f = 0;
        while f < 8 {
            let sign = if f < 4 + k { 1 } else { -1 };
            // multiply by (1 + sign * i t)
            let mut nre = [0i64; 9];
            let mut nim = [0i64; 9];
            let mut d = 0;
            while d < 8 {
                nre[d] += re[d];
                nim[d] += im[d];
                // (re + i im) * (sign i t) = -sign im t + i sign re t
                nre[d + 1] -= sign * im[d];
                nim[d + 1] += sign * re[d];
                d += 1;
            }
            re = nre;
            im = nim;
            f += 1;
        }
        let mut d = 0;
        while d < 9 {
            table[k][d] = if imag { im[d] as f64 } else { re[d] as f64 };
            d += 1;
        }
        k += 1;
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Trig {
        Trig {
            cos: [0.3, -1.2, 0.7, 0.25, -0.4],
            sin: [0.0, 0.9, -0.3, 0.6, 0.15],
        }
    }

    #[test]
    fn product_matches_pointwise() {
        let a = Trig::linear(1.5, -0.5, 2.0);
        let b = Trig {
            cos: [0.2, 0.4, -1.0, 0.3, 0.0],
            sin: [0.0, 0.8, 0.5, -0.7, 0.0],
        };
        let p = a.mul(&b);
        for i in 0..50 {
            let x = -3.0 + i as f64 * 0.13;
            assert!((p.eval(x) - a.eval(x) * b.eval(x)).abs() < 1e-12);
        }
    }

    #[test]
    fn half_angle_polynomials_match() {
        let p = sample();
        for shift in [false, true] {
            let q = p.to_half_angle_poly(shift);
            for i in 0..40 {
                let t = -1.0 + i as f64 * 0.05;
                let x = 2.0 * t.atan() + if shift { std::f64::consts::PI } else { 0.0 };
                let lhs = q.iter().rev().fold(0.0, |acc, &a| acc * t + a);
                let rhs = (1.0 + t * t).powi(4) * p.eval(x);
                assert!((lhs - rhs).abs() < 1e-12 * (1.0 + rhs.abs()), "{lhs} {rhs}");
            }
        }
    }
}
