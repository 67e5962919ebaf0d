//! Trigonometric polynomials a0 + sum_k (a_k cos k x + b_k sin k x) of degree at most 4, their
//! conversion to ordinary polynomials by the half-angle substitution t = tan(x/2), and the
//! isolation of their real roots directly on the circle ([`Trig::roots`]).

use arrayvec::ArrayVec;

use crate::math::poly::Coeffs;

/// sin and cos of `alpha` = a - d from those of a (a Newton step d): by the angle-difference
/// formulas with the series of sin d and cos d (two terms for |d| < 1e-3, six up to 0.25: both
/// exact in double precision), else by `sin_cos`.
#[inline(always)]
pub fn sin_cos_after_step(sin_a: f64, cos_a: f64, alpha: f64, d: f64) -> (f64, f64) {
    let d2 = d * d;
    let (sd, cd) = if d.abs() < 1e-3 {
        (
            d * (1.0 - d2 * (1.0 / 6.0) * (1.0 - d2 * (1.0 / 20.0))),
            1.0 - d2 * 0.5 * (1.0 - d2 * (1.0 / 12.0)),
        )
    } else if d.abs() < SMALL_ANGLE {
        sin_cos_small(d)
    } else {
        return alpha.sin_cos();
    };
    (sin_a * cd - cos_a * sd, cos_a * cd + sin_a * sd)
}

/// Largest |d| for [`sin_cos_small`].
pub const SMALL_ANGLE: f64 = 0.25;

/// sin d and cos d for |d| < [`SMALL_ANGLE`] by their series, without a branch. The next terms
/// are below d^13 / 13! and d^14 / 14!: under 1e-17 relative for |d| < 0.25.
#[inline(always)]
pub fn sin_cos_small(d: f64) -> (f64, f64) {
    let d2 = d * d;
    let sd = d
        * (1.0
            - d2 * (1.0 / 6.0)
                * (1.0
                    - d2 * (1.0 / 20.0)
                        * (1.0
                            - d2 * (1.0 / 42.0)
                                * (1.0 - d2 * (1.0 / 72.0) * (1.0 - d2 * (1.0 / 110.0))))));
    let cd = 1.0
        - d2 * 0.5
            * (1.0
                - d2 * (1.0 / 12.0)
                    * (1.0
                        - d2 * (1.0 / 30.0)
                            * (1.0
                                - d2 * (1.0 / 56.0)
                                    * (1.0 - d2 * (1.0 / 90.0) * (1.0 - d2 * (1.0 / 132.0))))));
    (sd, cd)
}

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
        self.eval_sc(s1, c1)
    }

    /// The value at x from (sin x, cos x).
    #[inline]
    pub fn eval_sc(&self, s1: f64, c1: f64) -> f64 {
        self.eval_sc_up_to(s1, c1, MAX_HARMONIC)
    }

    /// [`Trig::eval_sc`] of a form of degree at most `D` (the terms left out are zero: the same
    /// value).
    #[inline]
    pub fn eval_sc_deg<const D: usize>(&self, s1: f64, c1: f64) -> f64 {
        debug_assert!(self.degree() <= D);
        self.eval_sc_up_to(s1, c1, D.min(MAX_HARMONIC))
    }

    #[inline(always)]
    fn eval_sc_up_to(&self, s1: f64, c1: f64, degree: usize) -> f64 {
        let (mut ck, mut sk) = (1.0, 0.0);
        let mut acc = self.cos[0];
        for k in 1..=degree {
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
        self.mul_up_to(o, self.degree(), o.degree())
    }

    /// [`Trig::mul`] of a form of degree at most `DA` by one of degree at most `DB`, with the
    /// loops fixed at compile time (the same sums in the same order: the same result).
    #[inline]
    pub fn mul_deg<const DA: usize, const DB: usize>(&self, o: &Trig) -> Trig {
        const { assert!(DA + DB <= MAX_HARMONIC) };
        debug_assert!(self.degree() <= DA && o.degree() <= DB);
        self.mul_up_to(o, DA, DB)
    }

    #[inline(always)]
    fn mul_up_to(&self, o: &Trig, da: usize, db: usize) -> Trig {
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

    /// The derivative d/dx.
    pub fn derivative(&self) -> Trig {
        let mut r = Trig::default();
        for k in 1..=MAX_HARMONIC {
            r.cos[k] = k as f64 * self.sin[k];
            r.sin[k] = -(k as f64) * self.cos[k];
        }
        r
    }

    /// sum_k k^order |(a_k, b_k)|: a bound on |d^order p / dx^order| over the circle.
    fn harmonic_bound(&self, order: i32) -> f64 {
        let b: f64 = (1..=MAX_HARMONIC)
            .map(|k| {
                let (a, b) = (self.cos[k], self.sin[k]);
                (k as f64).powi(order) * (a * a + b * b).sqrt()
            })
            .sum();
        b * (1.0 + 1e-12)
    }

    /// |a0| + sum_k (|a_k| + |b_k|), scaled to bound the rounding error of evaluating p (a sum
    /// of nine products of cosines and sines accurate to a few units in the last place, at a
    /// point representable to half a unit of pi).
    fn eval_error(&self) -> f64 {
        let abs: f64 = self.cos[0].abs()
            + (1..=MAX_HARMONIC)
                .map(|k| self.cos[k].abs() + self.sin[k].abs())
                .sum::<f64>();
        64.0 * f64::EPSILON * abs
    }

    /// The value at grid point j, as [`Trig::on_grid`] computes it (same sums, same order).
    #[inline]
    fn at_grid(&self, j: usize) -> f64 {
        let mut v = self.cos[0];
        for k in 0..MAX_HARMONIC {
            v += self.cos[k + 1] * GRID_COS[k][j] + self.sin[k + 1] * GRID_SIN[k][j];
        }
        v
    }

    /// p at the grid points x_j.
    #[inline(always)]
    fn on_grid(&self) -> [f64; GRID] {
        let mut v = [self.cos[0]; GRID];
        for k in 0..MAX_HARMONIC {
            let (a, b) = (self.cos[k + 1], self.sin[k + 1]);
            for (j, vj) in v.iter_mut().enumerate() {
                *vj += a * GRID_COS[k][j] + b * GRID_SIN[k][j];
            }
        }
        v
    }

    /// Every real root in [-pi, pi], each once (a root at +-pi as -pi), in increasing order;
    /// at a double root or a pair of roots too close to separate in floating point, one
    /// candidate. Empty when p is identically zero or not finite.
    ///
    /// Complete by construction: F, F', F'' are sampled on a grid of 32 points and every grid
    /// interval is either proved root-free, proved monotone (its one root, if F changes sign, is
    /// found by bracketed Chebyshev steps, Newton's corrected by F''), proved convex or concave
    /// (split at its critical point into two monotone pieces), or bisected (see
    /// `Isolation::interval`). This replaces the degree-8 half-angle polynomials of IFToMM 2007
    /// section VI for the forward kinematics (one pass over the circle, no chart at alpha = pi,
    /// no recursion on derivatives).
    pub fn roots(&self) -> ArrayVec<f64, MAX_TRIG_ROOTS> {
        self.roots_sin_cos().iter().map(|r| r.x).collect()
    }

    /// [`Trig::roots`], each with its sine and cosine (carried along the root finding). Built
    /// with AVX2 where the processor has it ([`crate::math::cpu`]).
    pub fn roots_sin_cos(&self) -> ArrayVec<TrigRoot, MAX_TRIG_ROOTS> {
        #[cfg(target_arch = "x86_64")]
        if crate::math::cpu::has_avx2() {
            // SAFETY: the processor has AVX2 (checked just above).
            return unsafe { roots_sin_cos_avx2(self) };
        }
        self.roots_sin_cos_built::<false>()
    }

    /// [`Trig::roots_sin_cos`] built for the x86-64 baseline whatever the processor has: the
    /// same roots, bit for bit.
    #[doc(hidden)]
    pub fn roots_sin_cos_baseline(&self) -> ArrayVec<TrigRoot, MAX_TRIG_ROOTS> {
        self.roots_sin_cos_built::<false>()
    }

    /// The body of [`Trig::roots_sin_cos`], inlined into each build (`AVX2` tells them apart:
    /// see [`crate::math::cpu`]).
    #[inline(always)]
    pub(crate) fn roots_sin_cos_built<const AVX2: bool>(
        &self,
    ) -> ArrayVec<TrigRoot, MAX_TRIG_ROOTS> {
        let mut roots = self.isolate_built::<AVX2>(0.0, false).roots;
        // A root on a grid point is found by the charts of both intervals it ends, and one at
        // pi by the last interval as well as at -pi by the first: each once, at -pi for +-pi.
        for r in roots.iter_mut() {
            if r.x >= std::f64::consts::PI {
                r.x -= std::f64::consts::TAU;
            }
        }
        roots.sort_by(|a, b| a.x.total_cmp(&b.x));
        let mut out: ArrayVec<TrigRoot, MAX_TRIG_ROOTS> = ArrayVec::new();
        for r in roots {
            if out.last().is_none_or(|last| r.x - last.x > SAME_ROOT_RAD) {
                out.push(r);
            }
        }
        out
    }

    /// Every real root in [-pi, pi] that can be proved, and the intervals where none can be
    /// proved or excluded in double precision ([`Isolated`]). `coef_err` bounds the error of
    /// the coefficients themselves (|p(x) - exact(x)| <= coef_err for every x, from the rounding
    /// of the formulas that computed them): the proofs hold for the exact polynomial. Built with
    /// AVX2 where the processor has it ([`crate::math::cpu`]).
    pub fn roots_certified(&self, coef_err: f64) -> Isolated {
        #[cfg(target_arch = "x86_64")]
        if crate::math::cpu::has_avx2() {
            // SAFETY: the processor has AVX2 (checked just above).
            return unsafe { roots_certified_avx2(self, coef_err) };
        }
        self.isolate_built::<false>(coef_err, true)
    }

    /// The body of [`Trig::roots_sin_cos`] and [`Trig::roots_certified`], inlined into each
    /// build. With `certify`, an interval no test decides is returned as ambiguous instead of
    /// handed to the half-angle charts.
    #[inline(always)]
    pub(crate) fn isolate_built<const AVX2: bool>(&self, coef_err: f64, certify: bool) -> Isolated {
        let scale = self
            .cos
            .iter()
            .chain(&self.sin)
            .fold(0.0f64, |m, a| m.max(a.abs()));
        // `max` passes over a NaN: finiteness is tested on the coefficients themselves.
        let finite = self.cos.iter().chain(&self.sin).all(|a| a.is_finite());
        if scale == 0.0 || !finite || !coef_err.is_finite() {
            let mut out = Isolated::default();
            if certify && !(scale == 0.0 && coef_err == 0.0) {
                // Not finite, or zero only within the coefficients' error: nothing is proved.
                out.ambiguous
                    .push([-std::f64::consts::PI, std::f64::consts::PI]);
            }
            return out;
        }
        let mut iso = Isolation::with_bounds(self, scale, coef_err, certify);
        let (f, d, s) = (iso.f, iso.d, iso.s);
        // F on the whole grid; F' and F'' only at the ends of the intervals that F alone does not
        // prove root-free (few: about two per root).
        let fv = f.on_grid();
        let step = std::f64::consts::PI / 16.0;
        let pt = |j: usize| Pt {
            x: (j as f64 - 16.0) * step,
            sin: GRID_SIN[0][j % GRID],
            cos: GRID_COS[0][j % GRID],
            f: fv[j % GRID],
            d: d.at_grid(j % GRID),
            s: s.at_grid(j % GRID),
        };
        // Intervals that F alone does not prove root-free, as a bit mask: bit j of `above`
        // (`below`) when F(x_j) is beyond the bound above (below) zero, and interval j (x_j to
        // x_j+1, around the circle) proved root-free when both its ends are. F is finite on
        // the grid, so these plain comparisons say what `same_sign_beyond` says.
        let root_free = step * step * 0.125 * iso.m2 + iso.ef;
        const _: () = assert!(GRID == u32::BITS as usize);
        let (mut above, mut below) = (0u32, 0u32);
        for (j, v) in fv.iter().enumerate() {
            above |= u32::from(*v > root_free) << j;
            below |= u32::from(*v < -root_free) << j;
        }
        let free = (above & above.rotate_right(1)) | (below & below.rotate_right(1));
        let mut undecided = !free;
        while undecided != 0 {
            let j = undecided.trailing_zeros() as usize;
            undecided &= undecided - 1;
            let (a, b) = (pt(j), pt(j + 1));
            let found = iso.out.len();
            let near_zero = a.f.abs() <= iso.ef || b.f.abs() <= iso.ef;
            if near_zero && iso.ambiguous.is_some() {
                iso.give_up(a.x, b.x);
            } else if near_zero || iso.interval::<AVX2>(a, b, 0).is_none() {
                iso.out.truncate(found);
                iso.chart_roots(a.x, b.x);
            }
        }
        let ambiguous = iso.ambiguous.unwrap_or_default();
        let mut roots = iso.out;
        // A full list of ambiguous intervals grows its last one over what follows: the roots
        // found there are the caller's to find again.
        roots.retain(|r| !ambiguous.iter().any(|[lo, hi]| r.x >= *lo && r.x <= *hi));
        Isolated { roots, ambiguous }
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

/// A root x of a trigonometric polynomial with sin x and cos x.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrigRoot {
    pub x: f64,
    pub sin: f64,
    pub cos: f64,
}

/// Most intervals [`Trig::roots_certified`] leaves undecided (each holds a close pair or
/// a multiple root; more would only come from a polynomial that is zero within rounding).
pub const MAX_AMBIGUOUS: usize = 4;

/// What [`Trig::roots_certified`] proves: the roots it isolated (each simple, each proved to be
/// the only root of the exact polynomial in an interval where the polynomial changes sign), in
/// increasing order, and the intervals [lo, hi] it could neither prove root-free nor isolate
/// (closed, disjoint, in increasing order; the roots are outside them). Every other point of
/// [-pi, pi] is proved not to be a root.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Isolated {
    pub roots: ArrayVec<TrigRoot, MAX_TRIG_ROOTS>,
    pub ambiguous: ArrayVec<[f64; 2], MAX_AMBIGUOUS>,
}

/// Most roots [`Trig::roots`] returns: 2 [`MAX_HARMONIC`] simple roots, plus candidates at
/// near-double roots.
pub const MAX_TRIG_ROOTS: usize = 32;

/// Two roots of [`Trig::roots`] closer than this (rad) are one: the same root found from the
/// two grid intervals it ends (far below the separation of roots the charts tell apart).
const SAME_ROOT_RAD: f64 = 1e-12;

/// Grid of the root isolation: x_j = -pi + j pi / 16, j = 0..32.
const GRID: usize = 32;

/// cos(m pi / 16), m = 0..=8, correctly rounded.
const COS_OCTANTS: [f64; 9] = [
    1.0,
    0.980_785_280_403_230_4,
    0.923_879_532_511_286_7,
    0.831_469_612_302_545_2,
    std::f64::consts::FRAC_1_SQRT_2,
    0.555_570_233_019_602_2,
    0.382_683_432_365_089_8,
    0.195_090_322_016_128_28,
    0.0,
];

/// cos(m pi / 16) for any m, by symmetry from the first quadrant (exact table entries).
const fn grid_cos(m: usize) -> f64 {
    let m = m % GRID;
    match m / 8 {
        0 => COS_OCTANTS[m],
        1 => -COS_OCTANTS[16 - m],
        2 => -COS_OCTANTS[m - 16],
        _ => COS_OCTANTS[32 - m],
    }
}

/// cos(k x_j) (`sin == false`) or sin(k x_j) on the grid, k = 1..=4 (row k - 1).
const fn grid_table(sin: bool) -> [[f64; GRID]; MAX_HARMONIC] {
    let mut t = [[0.0; GRID]; MAX_HARMONIC];
    let mut k = 1;
    while k <= MAX_HARMONIC {
        let mut j = 0;
        while j < GRID {
            // k x_j = (k j - 16 k) pi / 16; sin(y) = cos(y - pi / 2).
            let m = k * j + 4 * GRID - 16 * k + if sin { 3 * GRID / 4 } else { 0 };
            t[k - 1][j] = grid_cos(m);
            j += 1;
        }
        k += 1;
    }
    t
}

const GRID_COS: [[f64; GRID]; MAX_HARMONIC] = grid_table(false);
const GRID_SIN: [[f64; GRID]; MAX_HARMONIC] = grid_table(true);

/// Bisection depth at which an interval that no test decides is given up
/// ([`Isolation::give_up`]): near a root of multiplicity three or more, or an extremum whose
/// value lies just beyond rounding.
const MAX_DEPTH: u32 = 40;

/// A point with sin and cos of it and the values of F, F' and F'' there.
#[derive(Debug, Clone, Copy)]
struct Pt {
    x: f64,
    sin: f64,
    cos: f64,
    f: f64,
    d: f64,
    s: f64,
}

/// Both values beyond t on the same side of zero.
#[inline]
fn same_sign_beyond(u: f64, v: f64, t: f64) -> bool {
    u.min(v) > t || u.max(v) < -t
}

/// Both values beyond t, on opposite sides of zero.
#[inline]
fn opposite_beyond(u: f64, v: f64, t: f64) -> bool {
    u.abs() > t && v.abs() > t && (u < 0.0) != (v < 0.0)
}

/// Root isolation state for one normalised F (see [`Trig::roots`]).
struct Isolation {
    f: Trig,
    d: Trig,
    s: Trig,
    /// Bounds on |F''|, |F'''|, |F''''| over the whole circle.
    m2: f64,
    m3: f64,
    m4: f64,
    /// Bounds on the rounding errors of evaluating F, F', F''.
    ef: f64,
    ed: f64,
    es: f64,
    out: ArrayVec<TrigRoot, MAX_TRIG_ROOTS>,
    /// The polynomial as given, and its half-angle charts (computed when needed).
    orig: Trig,
    charts: [Option<Coeffs>; 2],
    /// In certifying mode ([`Trig::roots_certified`]), the intervals given up on.
    ambiguous: Option<ArrayVec<[f64; 2], MAX_AMBIGUOUS>>,
}

impl Isolation {
    /// The isolation of F = `orig` / `scale` (`scale` its largest coefficient), with its bounds.
    /// `coef_err` bounds the error of `orig`'s coefficients: it moves F by at most ce = coef_err /
    /// scale, F' by 4 ce, F'' by 16 ce, ... (each harmonic k scales by k per derivative, and
    /// the error is itself a form of degree 4), so every bound covers the exact polynomial as
    /// well as the computed one.
    #[inline(always)]
    fn with_bounds(orig: &Trig, scale: f64, coef_err: f64, certify: bool) -> Isolation {
        let f = orig.scale(1.0 / scale);
        let d = f.derivative();
        let s = d.derivative();
        let ce = coef_err / scale;
        Isolation {
            f,
            d,
            s,
            m2: s.harmonic_bound(0) + 16.0 * ce,
            m3: s.harmonic_bound(1) + 64.0 * ce,
            m4: s.harmonic_bound(2) + 256.0 * ce,
            ef: f.eval_error() + ce,
            ed: d.eval_error() + 4.0 * ce,
            es: s.eval_error() + 16.0 * ce,
            out: ArrayVec::new(),
            orig: *orig,
            charts: [None, None],
            ambiguous: certify.then(ArrayVec::new),
        }
    }

    /// F, F', F'' at x (one sin_cos; cos k x, sin k x by the angle-sum recurrence).
    #[inline(always)]
    fn at(&self, x: f64) -> Pt {
        let (s1, c1) = x.sin_cos();
        self.at_sc(x, s1, c1)
    }

    /// sin and cos of x along a root iteration: from those of the previous point when it is
    /// close ([`sin_cos_after_step`]), kept in `last`.
    #[inline(always)]
    fn sin_cos_following(x: f64, last: &std::cell::Cell<Option<(f64, f64, f64)>>) -> (f64, f64) {
        let (s1, c1) = match last.get() {
            Some((x0, s0, c0)) => sin_cos_after_step(s0, c0, x, x0 - x),
            None => x.sin_cos(),
        };
        last.set(Some((x, s1, c1)));
        (s1, c1)
    }

    /// [`Isolation::at`] along a root iteration ([`Isolation::sin_cos_following`]).
    #[inline(always)]
    fn at_following(&self, x: f64, last: &std::cell::Cell<Option<(f64, f64, f64)>>) -> Pt {
        let (s1, c1) = Self::sin_cos_following(x, last);
        self.at_sc(x, s1, c1)
    }

    /// g and h (two of F, F', F'') at x along a root iteration, without the third.
    #[inline(always)]
    fn pair_following(
        x: f64,
        last: &std::cell::Cell<Option<(f64, f64, f64)>>,
        g: &Trig,
        h: &Trig,
    ) -> (f64, f64) {
        let (s1, c1) = Self::sin_cos_following(x, last);
        let (c, s) = harmonics(s1, c1);
        (dot_harmonics(g, &c, &s), dot_harmonics(h, &c, &s))
    }

    #[inline(always)]
    fn at_sc(&self, x: f64, s1: f64, c1: f64) -> Pt {
        let (c, s) = harmonics(s1, c1);
        Pt {
            x,
            sin: s1,
            cos: c1,
            f: dot_harmonics(&self.f, &c, &s),
            d: dot_harmonics(&self.d, &c, &s),
            s: dot_harmonics(&self.s, &c, &s),
        }
    }

    fn push(&mut self, x: f64, (sin, cos): (f64, f64)) {
        if !self.out.is_full() {
            self.out.push(TrigRoot { x, sin, cos });
        }
    }

    /// Every root in [a.x, b.x] (F beyond rounding at both ends), or None where F comes within
    /// rounding of zero inside (a double root or a pair of roots too close for the trigonometric
    /// form: the caller hands the interval to [`Isolation::chart_roots`]).
    /// With h = b.x - a.x, a function g with |g''| <= M on the interval stays within h^2 M / 8 of
    /// its chord: when both end values are beyond that (plus rounding) on the same side of zero,
    /// g has no zero there. Applied to F (no root), F' (F strictly monotone: one root at most,
    /// exactly where F changes sign) and F'' (F' strictly monotone: at most one critical point,
    /// which splits the interval into two monotone pieces). Intervals none of these decides are
    /// bisected; the bounds shrink four times per bisection, so bisection reaches [`MAX_DEPTH`]
    /// only where F' is within rounding and F within rounding plus a vanishing margin (a triple
    /// root, or an extremum whose value lies just beyond rounding). Runs in the build `AVX2`
    /// names ([`crate::math::cpu`]), through a function of its own, so that its recursion stays
    /// in the build it started in.
    #[inline(always)]
    fn interval<const AVX2: bool>(&mut self, a: Pt, b: Pt, depth: u32) -> Option<()> {
        #[cfg(target_arch = "x86_64")]
        if AVX2 {
            // SAFETY: AVX2 is true only below `roots_sin_cos_avx2`, which runs where the
            // processor has AVX2.
            return unsafe { interval_avx2(self, a, b, depth) };
        }
        interval_baseline(self, a, b, depth)
    }

    /// The body of [`Isolation::interval`], inlined into each build; its recursion goes back
    /// through the dispatch, into the same build.
    #[inline(always)]
    fn interval_built<const AVX2: bool>(&mut self, a: Pt, b: Pt, depth: u32) -> Option<()> {
        let h = b.x - a.x;
        let w = h * h * 0.125;
        if self.no_root(&a, &b, w) {
            return Some(());
        }
        if self.no_critical_point(&a, &b, w) {
            self.monotone::<AVX2>(a, b);
            return Some(());
        }
        if self.no_inflection(&a, &b, w) {
            if opposite_beyond(a.d, b.d, self.ed) {
                // F is convex or concave here: a point where F is beyond rounding on the other
                // side of zero from both ends splits [a, b] into two pieces with one simple root
                // each. The estimate of the critical point usually is one (two close assembly
                // modes); otherwise the critical point itself decides.
                let guess = hermite_start(a.x, b.x, a.d, b.d, a.s, b.s);
                let (sg, cg) = sin_cos_after_step(a.sin, a.cos, guess, a.x - guess);
                let g = self.at_sc(guess, sg, cg);
                let splits =
                    opposite_beyond(g.f, a.f, self.ef) && opposite_beyond(g.f, b.f, self.ef);
                let c = if splits {
                    g
                } else {
                    self.critical::<AVX2>(a, b)
                };
                if c.f.abs() <= self.ef {
                    // Outside certifying mode the caller hands the interval to the charts.
                    self.ambiguous.as_ref()?;
                    // Only near c can F come within rounding of zero (two close roots, or a
                    // double one): the rest of [a, b] is proved root-free.
                    let (lo, hi) = self.band_around(a, c, b);
                    return self.give_up(lo, hi);
                }
                self.monotone::<AVX2>(a, c);
                self.monotone::<AVX2>(c, b);
                return Some(());
            } else if self.ambiguous.is_none() || same_sign_beyond(a.d, b.d, self.ed) {
                // F' monotone and not changing sign beyond rounding: F monotone. (Where an end
                // of F' is within rounding of zero, F could turn there: a proof bisects.)
                self.monotone::<AVX2>(a, b);
                return Some(());
            }
        }
        let mut m = self.at(0.5 * (a.x + b.x));
        if m.f.abs() <= self.ef && self.ambiguous.is_some() {
            // A proof needs split points where F is beyond rounding: try off-centre ones.
            for frac in [0.3, 0.7] {
                let p = self.at(a.x + frac * (b.x - a.x));
                if p.f.abs() > self.ef {
                    m = p;
                    break;
                }
            }
        }
        if depth >= MAX_DEPTH || m.f.abs() <= self.ef {
            return self.give_up(a.x, b.x);
        }
        self.interval::<AVX2>(a, m, depth + 1)?;
        self.interval::<AVX2>(m, b, depth + 1)
    }

    /// F has no zero on [a, b]: both ends beyond w M2 + rounding on one side, w = h^2 / 8 (the
    /// chord bound of [`Isolation::interval`]).
    #[inline(always)]
    fn no_root(&self, a: &Pt, b: &Pt, w: f64) -> bool {
        same_sign_beyond(a.f, b.f, w * self.m2 + self.ef)
    }

    /// F' has no zero on [a, b] (F strictly monotone): the same test on F', with M3.
    #[inline(always)]
    fn no_critical_point(&self, a: &Pt, b: &Pt, w: f64) -> bool {
        same_sign_beyond(a.d, b.d, w * self.m3 + self.ed)
    }

    /// F'' has no zero on [a, b] (F convex or concave): the same test on F'', with M4.
    #[inline(always)]
    fn no_inflection(&self, a: &Pt, b: &Pt, w: f64) -> bool {
        same_sign_beyond(a.s, b.s, w * self.m4 + self.es)
    }

    /// F monotone on [a, c] and on [c, b] (c its critical point, within rounding of zero; a and b
    /// beyond it): the interval around c outside which F is proved beyond rounding, so root-free.
    /// Found by stepping out from c by the distance at which F's quadratic model leaves the
    /// rounding band, four times farther each try.
    #[cold]
    fn band_around(&self, a: Pt, c: Pt, b: Pt) -> (f64, f64) {
        let r0 = (4.0 * self.ef / c.s.abs().max(f64::MIN_POSITIVE)).sqrt();
        let side = |end: Pt, dir: f64| {
            let mut r = r0;
            while r < (end.x - c.x).abs() {
                let p = self.at(c.x + dir * r);
                if p.f.abs() > self.ef && (p.f < 0.0) == (end.f < 0.0) {
                    return p.x;
                }
                r *= 4.0;
            }
            end.x
        };
        (side(a, -1.0), side(b, 1.0))
    }

    /// No test decides [xa, xb]: in certifying mode it is recorded as ambiguous (and the search
    /// goes on elsewhere); otherwise None, and the caller hands the grid interval to the charts.
    #[cold]
    fn give_up(&mut self, xa: f64, xb: f64) -> Option<()> {
        let amb = self.ambiguous.as_mut()?;
        let full = amb.is_full();
        match amb.last_mut() {
            // Adjacent pieces (a bisection that gave up on both halves) make one interval; with
            // the list full, the last one grows over the rest.
            Some(last) if last[1] >= xa || full => last[1] = last[1].max(xb),
            _ => amb.push([xa, xb]),
        }
        Some(())
    }

    /// The roots in [xa, xb] (inside [-pi/2, pi/2] or outside it) from the half-angle chart that
    /// covers it (IFToMM 2007 section VI), by `poly::roots_in`, whose Horner evaluation near the
    /// chart's centre (alpha = 0 or pi, where the close pairs of assembly modes occur) is accurate
    /// relative to the size of F there, not to its coefficients.
    fn chart_roots(&mut self, xa: f64, xb: f64) {
        use std::f64::consts::{FRAC_PI_2, PI};
        let shift = xa < -FRAC_PI_2 || xb > FRAC_PI_2;
        let k = usize::from(shift);
        let poly = self.charts[k].get_or_insert_with(|| {
            let mut poly = self.orig.to_half_angle_poly(shift);
            let scale = poly.iter().fold(0.0f64, |m, a| m.max(a.abs()));
            for a in poly.iter_mut() {
                *a /= scale;
            }
            poly
        });
        let centre = if !shift {
            0.0
        } else if xa < 0.0 {
            -PI
        } else {
            PI
        };
        let t = |x: f64| (0.5 * (x - centre)).tan();
        let (lo, hi) = ((t(xa) - 1e-12).max(-1.0), (t(xb) + 1e-12).min(1.0));
        for r in crate::math::poly::roots_in(poly, lo, hi) {
            let x = 2.0 * r.x.atan() + centre;
            self.push(x, x.sin_cos());
        }
    }

    /// F monotone on [a.x, b.x], or convex or concave there with one simple root: its root there
    /// when F changes sign beyond rounding.
    #[inline(always)]
    fn monotone<const AVX2: bool>(&mut self, a: Pt, b: Pt) {
        if opposite_beyond(a.f, b.f, self.ef) {
            let start = root_start(a, b);
            let last = std::cell::Cell::new(Some((a.x, a.sin, a.cos)));
            let bounds = StepBounds {
                m2: self.m2,
                m3: Some(self.m3),
            };
            let x = newton_bracketed(
                a.x,
                b.x,
                a.f,
                start,
                bounds,
                #[inline(always)]
                |x| {
                    let p = self.at_following(x, &last);
                    (p.f, p.d, p.s)
                },
            );
            self.push(x, Self::sin_cos_following(x, &last));
        }
    }

    /// The single root of F' on [a.x, b.x] (F' strictly monotone, changing sign), with F there.
    #[inline(always)]
    fn critical<const AVX2: bool>(&self, a: Pt, b: Pt) -> Pt {
        let start = hermite_start(a.x, b.x, a.d, b.d, a.s, b.s);
        let last = std::cell::Cell::new(Some((a.x, a.sin, a.cos)));
        let bounds = StepBounds {
            m2: self.m3,
            m3: None,
        };
        let x = newton_bracketed(
            a.x,
            b.x,
            a.d,
            start,
            bounds,
            #[inline(always)]
            |x| {
                let (g, dg) = Self::pair_following(x, &last, &self.d, &self.s);
                (g, dg, 0.0)
            },
        );
        self.at_following(x, &last)
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn roots_sin_cos_avx2(t: &Trig) -> ArrayVec<TrigRoot, MAX_TRIG_ROOTS> {
    t.roots_sin_cos_built::<true>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn roots_certified_avx2(t: &Trig, coef_err: f64) -> Isolated {
    t.isolate_built::<true>(coef_err, true)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn interval_avx2(iso: &mut Isolation, a: Pt, b: Pt, depth: u32) -> Option<()> {
    iso.interval_built::<true>(a, b, depth)
}

fn interval_baseline(iso: &mut Isolation, a: Pt, b: Pt, depth: u32) -> Option<()> {
    iso.interval_built::<false>(a, b, depth)
}

/// cos k x and sin k x, k = 1..=4, from sin x and cos x (angle-sum recurrences).
#[inline]
fn harmonics(s1: f64, c1: f64) -> ([f64; MAX_HARMONIC], [f64; MAX_HARMONIC]) {
    let (c2, s2) = (c1 * c1 - s1 * s1, 2.0 * s1 * c1);
    let (c3, s3) = (c2 * c1 - s2 * s1, s2 * c1 + c2 * s1);
    let (c4, s4) = (c2 * c2 - s2 * s2, 2.0 * s2 * c2);
    ([c1, c2, c3, c4], [s1, s2, s3, s4])
}

/// t(x) from the harmonics of x ([`harmonics`]).
#[inline(always)]
fn dot_harmonics(t: &Trig, c: &[f64; MAX_HARMONIC], s: &[f64; MAX_HARMONIC]) -> f64 {
    let mut acc = t.cos[0];
    for k in 0..MAX_HARMONIC {
        acc += t.cos[k + 1] * c[k] + t.sin[k + 1] * s[k];
    }
    acc
}

/// A start for the root of F, monotone on [a.x, b.x] and changing sign there: the inverse
/// Hermite interpolant when both slopes are usable; next to a critical point (an end where F' is
/// small, near a double root, where Newton from afar would only halve its distance per step),
/// the root of the second-order Taylor model of F at that end.
#[inline(always)]
fn root_start(a: Pt, b: Pt) -> f64 {
    let h = b.x - a.x;
    let (e, dir) = if a.d.abs() <= b.d.abs() {
        (a, 1.0)
    } else {
        (b, -1.0)
    };
    if e.d.abs() * h < 0.5 * (b.f - a.f).abs() {
        // F(e.x + dir t) ~ f + dir d t + s t^2 / 2: its smallest positive root.
        let (q2, q1, q0) = (0.5 * e.s, dir * e.d, e.f);
        let disc = q1 * q1 - 4.0 * q2 * q0;
        if disc >= 0.0 {
            let q = -0.5 * (q1 + q1.signum() * disc.sqrt());
            let t = [q0 / q, q / q2]
                .into_iter()
                .filter(|t| *t > 0.0 && *t < h)
                .fold(f64::INFINITY, f64::min);
            if t.is_finite() {
                return e.x + dir * t;
            }
        }
    }
    hermite_start(a.x, b.x, a.f, b.f, a.d, b.d)
}

/// A start for the root of g, monotone on [a, b] with g(a) = ga, g(b) = gb of opposite signs:
/// the cubic Hermite interpolant of the inverse function x(g) at g = 0 (slopes 1 / g'), or the
/// secant's root where a slope is unusable.
#[inline(always)]
fn hermite_start(a: f64, b: f64, ga: f64, gb: f64, da: f64, db: f64) -> f64 {
    let dy = gb - ga;
    let t = -ga / dy;
    let slope = (b - a) / dy;
    let usable = |d: f64| d != 0.0 && (d > 0.0) == (slope > 0.0);
    let x = if usable(da) && usable(db) {
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * a
            + (t3 - 2.0 * t2 + t) * dy / da
            + (3.0 * t2 - 2.0 * t3) * b
            + (t3 - t2) * dy / db
    } else {
        a + t * (b - a)
    };
    if x > a && x < b { x } else { 0.5 * (a + b) }
}

/// Bounds on the derivatives of g over the circle for [`newton_bracketed`]: `m2` on |g''|, and
/// `m3` on |g'''| when g'' is evaluated too (Chebyshev's steps).
#[derive(Debug, Clone, Copy)]
struct StepBounds {
    m2: f64,
    m3: Option<f64>,
}

impl StepBounds {
    /// From x, with `step` = g / g' (g' = `dg`, g'' = `ddg`): the next point, Newton's or
    /// Chebyshev's (see [`newton_bracketed`]), and the bound on its distance from the root that
    /// the leading term of the step's error gives.
    #[inline(always)]
    fn step(&self, x: f64, step: f64, dg: f64, ddg: f64) -> (f64, f64) {
        match self.m3 {
            None => (x - step, self.m2 * step * step / (2.0 * dg.abs())),
            Some(m3) => {
                let inv = 1.0 / dg;
                let q = self.m2 * inv;
                let step2 = step * step;
                (
                    x - step - 0.5 * ddg * inv * step2,
                    (0.5 * q * q + m3 * inv.abs() * (1.0 / 6.0)) * (step2 * step).abs(),
                )
            }
        }
    }
}

/// The single root of g, monotone on [a, b] and changing sign there (g(a) = ga), from `start`, by
/// steps kept inside a shrinking bracket (bisection when a step leaves it). `eval` gives g, g' and
/// g'' (used only with `bounds.m3`). With d = g / g' the Newton step, the step taken is Newton's,
/// x - d, which leaves an error of at most m2 d^2 / (2 |g'|); or, with g'', Chebyshev's,
/// x - d - g'' d^2 / (2 g'), which leaves at most (m2^2 / (2 g'^2) + m3 / (6 |g'|)) |d|^3 (the
/// e^3 term of its expansion about the root): the iteration stops once that (or the step itself)
/// is below the rounding of x, or the bracket cannot shrink.
#[inline(always)]
fn newton_bracketed(
    mut a: f64,
    mut b: f64,
    ga: f64,
    start: f64,
    bounds: StepBounds,
    eval: impl Fn(f64) -> (f64, f64, f64),
) -> f64 {
    let a_neg = ga < 0.0;
    let mut x = start;
    for _ in 0..200 {
        let (g, dg, ddg) = eval(x);
        if g == 0.0 {
            return x;
        }
        if (g < 0.0) == a_neg {
            a = x;
        } else {
            b = x;
        }
        let step = g / dg;
        let (next, left) = bounds.step(x, step, dg, ddg);
        if next > a && next < b {
            let tol = f64::EPSILON * next.abs().max(1e-3);
            if step.abs() <= tol || left <= tol {
                return next;
            }
            x = next;
        } else {
            x = 0.5 * (a + b);
        }
        if b - a <= f64::EPSILON * (a.abs() + b.abs()) {
            return x;
        }
    }
    x
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

    /// sin d and cos d by the series of [`sin_cos_small`] are within an ulp of the library's
    /// (and of sin^2 + cos^2 = 1) over |d| < [`SMALL_ANGLE`]: 200,001 angles with the ends, where
    /// the series' last terms matter most.
    #[test]
    fn sin_cos_small_is_the_library_to_an_ulp() {
        let mut angles: Vec<f64> = (0..=200_000)
            .map(|k| (k as f64 / 100_000.0 - 1.0) * SMALL_ANGLE)
            .collect();
        angles.extend([
            SMALL_ANGLE.next_down(),
            -SMALL_ANGLE.next_down(),
            1e-300,
            -1e-8,
            0.0,
        ]);
        for d in angles {
            let (s, c) = sin_cos_small(d);
            let (ls, lc) = d.sin_cos();
            let ulp = |x: f64| (x.abs().next_up() - x.abs()).max(f64::MIN_POSITIVE);
            assert!(
                (s - ls).abs() <= ulp(ls) && (c - lc).abs() <= ulp(lc),
                "{d}: ({s}, {c}) vs ({ls}, {lc})"
            );
            assert!((s * s + c * c - 1.0).abs() <= 4.0 * f64::EPSILON, "{d}");
        }
    }

    /// The start for the root of a monotone piece ([`hermite_start`], the cubic Hermite
    /// interpolant of the inverse function) is of order four: for g = +-(sin x - sin r)
    /// (increasing and decreasing pieces) on intervals of width h = 0.2 to 0.0125 about roots r
    /// in [-1.2, 1.2] (|g'| = cos x > 0.2 there: off the critical points at +-pi/2), within 2 h^4
    /// of r (measured 0.89 h^4); with a slope unusable, the secant's root, of order two (within
    /// h^2; measured 0.33 h^2).
    #[test]
    fn hermite_start_is_of_order_four() {
        let mut unit = crate::math::test_rng::lcg(0x4e_4d17);
        for k in 0..20_000 {
            let r = (2.0 * unit() - 1.0) * 1.2;
            let h = [0.2, 0.1, 0.05, 0.0125][(unit() * 4.0) as usize];
            let a = r - h * (0.05 + 0.9 * unit());
            let b = a + h;
            // Increasing and decreasing pieces.
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            let g = |x: f64| sign * (x.sin() - r.sin());
            let d = |x: f64| sign * x.cos();
            let x = hermite_start(a, b, g(a), g(b), d(a), d(b));
            assert!((x - r).abs() <= 2.0 * h.powi(4), "{r} in [{a}, {b}]: {x}");
            let secant = hermite_start(a, b, g(a), g(b), 0.0, d(b));
            assert!((secant - r).abs() <= h * h, "{r} in [{a}, {b}]: {secant}");
        }
    }

    /// Next to a critical point (an end where F' is small: near a double root, where the
    /// inverse interpolant has no usable slope), the start ([`root_start`]) is the root of the
    /// second-order Taylor model of F at that end. For F = A (1 - cos(x - c)) - e, with its root
    /// t past the critical point c, on intervals from 0 to t/4 past c to 0.2 t to 2 t past the
    /// root (and mirrored: the model then taken at the right end), it is within t^3 / 12 of the
    /// root (measured t^3 / 24, the model's error from F's fourth-order term), past F's rounding.
    /// So is -F, and an interval that starts on the critical point itself (a tenth of the
    /// cases: the end's slope exactly 0, where for -F the root is the model's other one, q / q2).
    #[test]
    fn root_start_next_to_a_critical_point_is_the_taylor_models_root() {
        let mut unit = crate::math::test_rng::lcg(0x7a_1105);
        for i in 0..40_000 {
            let (c, amp) = (6.0 * unit() - 3.0, 0.3 + 2.7 * unit());
            let t = 10f64.powf(-4.0 + 3.7 * unit());
            let past = if i % 10 == 0 { 0.0 } else { 0.25 * t * unit() };
            let beyond = t * (0.2 + 1.8 * unit());
            let e = amp * (1.0 - t.cos());
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let pt = |x: f64| Pt {
                x,
                sin: x.sin(),
                cos: x.cos(),
                f: sign * (amp * (1.0 - (x - c).cos()) - e),
                d: sign * amp * (x - c).sin(),
                s: sign * amp * (x - c).cos(),
            };
            for side in [1.0, -1.0] {
                let (near, far) = (pt(c + side * past), pt(c + side * (t + beyond)));
                let (a, b) = if side > 0.0 { (near, far) } else { (far, near) };
                let root = c + side * t;
                let x = root_start(a, b);
                // F's rounding (a few ulps of amp) moves the root by that over F' ~ amp t.
                let rounding = 8.0 * f64::EPSILON * (1.0 / t + root.abs());
                assert!(
                    (x - root).abs() <= t.powi(3) / 12.0 + rounding,
                    "{root} in [{}, {}]: {x}",
                    a.x,
                    b.x
                );
            }
        }
    }

    /// [`newton_bracketed`] keeps its steps inside the bracket: on g = atan(x - r) over [r - 1,
    /// r + 5], from starts 1.5 to 4.9 past the root (past 1.39 Newton's steps on atan overshoot
    /// further each time, and Chebyshev's too), both kinds of step find the root, to rounding,
    /// by bisecting where a step leaves the bracket.
    #[test]
    fn bracketed_steps_that_would_diverge_bisect() {
        for r in [-2.0, 0.0, 0.7] {
            let eval = |x: f64| {
                let v = x - r;
                let w = 1.0 / (1.0 + v * v);
                (v.atan(), w, -2.0 * v * w * w)
            };
            for start in [1.5, 2.0, 3.0, 4.9].map(|d| r + d) {
                // |atan''| <= 3 sqrt(3) / 8, |atan'''| <= 2.
                for m3 in [None, Some(2.0)] {
                    let bounds = StepBounds { m2: 0.65, m3 };
                    let x = newton_bracketed(r - 1.0, r + 5.0, (-1f64).atan(), start, bounds, eval);
                    assert!(
                        (x - r).abs() <= 4.0 * f64::EPSILON,
                        "{r} from {start}, {m3:?}: {x}"
                    );
                }
            }
        }
    }

    /// Each step of [`newton_bracketed`] leaves the error it promises: from 1e-4 (in units of
    /// g' / m2) off a simple root, Newton's step is within m2 d^2 / (2 |g'|) of the root and
    /// Chebyshev's within (m2^2 / (2 g'^2) + m3 / (6 |g'|)) |d|^3 (d the Newton step; both the
    /// leading term of the step's error bounded by the harmonic bounds m2 and m3; measured at
    /// most 0.997 and 0.52 of those). Forms of two harmonics (1 to 4), where those bounds are
    /// nearest to the derivatives, at roots set by their constant term.
    #[test]
    fn each_bracketed_step_leaves_at_most_its_predicted_error() {
        let mut unit = crate::math::test_rng::lcg(0x0c4e_b1c5);
        for _ in 0..200_000 {
            let mut g = Trig::default();
            let k1 = 1 + (unit() * 4.0) as usize;
            let k2 = 1 + (k1 + (unit() * 3.0) as usize) % 4;
            for k in [k1, k2] {
                g.cos[k] = 2.0 * unit() - 1.0;
                g.sin[k] = 2.0 * unit() - 1.0;
            }
            let root = std::f64::consts::PI * (2.0 * unit() - 1.0);
            g.cos[0] -= g.eval(root);
            let (dg, ddg) = (g.derivative(), g.derivative().derivative());
            let (m2, m3) = (g.harmonic_bound(2), g.harmonic_bound(3));
            let slope = dg.eval(root);
            if slope.abs() < 1e-2 * m2 {
                continue;
            }
            let x = root + 1e-4 * (slope.abs() / m2) * if unit() < 0.5 { -1.0 } else { 1.0 };
            let (gx, dgx, ddgx) = (g.eval(x), dg.eval(x), ddg.eval(x));
            // g's rounding moves the root by about that over g'.
            let rounding = g.eval_error() / slope.abs() + 4.0 * f64::EPSILON * root.abs();
            for m3 in [None, Some(m3)] {
                let (next, left) = StepBounds { m2, m3 }.step(x, gx / dgx, dgx, ddgx);
                assert!(
                    (next - root).abs() <= left + rounding,
                    "{g:?} from {x} to {next}: {} left, {left} predicted",
                    (next - root).abs()
                );
            }
        }
    }

    /// Each step's prediction is its leading error term, not more: where m2 and m3 bound |g''|
    /// and |g'''| between the start and the root within 0.2 % of their largest values there
    /// (about the tightest bounds a caller can give), a step from 1e-3 or 1e-4 off the root
    /// lands between 0.99 and 1.01 of its prediction from it (measured 0.997 to 1.002).
    /// Newton's on g = lambda sin(x - r) + gamma (1 - cos(x - r)), where its error is
    /// g'' d^2 / (2 g'); Chebyshev's on g = alpha sin(x - r) + beta sin(3 (x - r)),
    /// alpha, beta >= 0, where g'' = 0 at the root and its error is -g''' d^3 / (6 g'): the m3
    /// term alone (the m2 term is below 1e-4 of it). Slopes g' from 1e-3 to 1e3.
    #[test]
    fn each_bracketed_step_meets_its_prediction_where_its_bounds_are_tight() {
        let mut unit = crate::math::test_rng::lcg(0x7e1d_57e9);
        // Adds coef sin(k (x - r)) (odd) or coef cos(k (x - r)) to g.
        let harmonic = |g: &mut Trig, k: usize, coef: f64, r: f64, odd: bool| {
            let (s, c) = (k as f64 * r).sin_cos();
            if odd {
                g.sin[k] += coef * c;
                g.cos[k] -= coef * s;
            } else {
                g.cos[k] += coef * c;
                g.sin[k] += coef * s;
            }
        };
        let (mut newton, mut chebyshev) = (0, 0);
        for k in 0..4_000 {
            let r = std::f64::consts::PI * (2.0 * unit() - 1.0);
            let slope = [1e-3, 0.1, 1.0, 10.0, 1e3][k % 5];
            let d = [1e-3, 1e-4][k / 5 % 2] * if unit() < 0.5 { -1.0 } else { 1.0 };
            let x = r + d;
            let mut g = Trig::default();
            let bounds = if k % 4 < 2 {
                // Newton: g' = slope and g'' = gamma at r; |g''| <= |gamma| + slope |d| nearby.
                let gamma = slope * (0.5 + unit()) * if unit() < 0.5 { -1.0 } else { 1.0 };
                harmonic(&mut g, 1, slope, r, true);
                g.cos[0] += gamma;
                harmonic(&mut g, 1, -gamma, r, false);
                newton += 1;
                StepBounds {
                    m2: gamma.abs() + slope * d.abs(),
                    m3: None,
                }
            } else {
                // Chebyshev: g' = alpha + 3 beta = slope, g'' = 0 and g''' = -(alpha + 27 beta)
                // at r; |g''| <= (alpha + 27 beta) |d| nearby.
                let beta = slope / 3.0 * unit();
                let alpha = slope - 3.0 * beta;
                harmonic(&mut g, 1, alpha, r, true);
                harmonic(&mut g, 3, beta, r, true);
                chebyshev += 1;
                StepBounds {
                    m2: (alpha + 27.0 * beta) * d.abs(),
                    m3: Some(alpha + 27.0 * beta),
                }
            };
            let (dg, ddg) = (g.derivative(), g.derivative().derivative());
            let (gx, dgx) = (g.eval(x), dg.eval(x));
            let (next, left) = bounds.step(x, gx / dgx, dgx, ddg.eval(x));
            let off = (next - r).abs();
            assert!(
                off >= 0.99 * left && off <= 1.01 * left,
                "{bounds:?}, slope {slope}, from {d:e} off {r}: {off:e} off, {left:e} predicted"
            );
        }
        assert!(
            newton == 2_000 && chebyshev == 2_000,
            "{newton} {chebyshev}"
        );
    }

    /// The sin and cos after a Newton step ([`sin_cos_after_step`]) are those of the new angle
    /// to rounding: steps below 1e-3 (two terms of the series), up to [`SMALL_ANGLE`] (six) and
    /// beyond (the library), from angles all round the circle.
    #[test]
    fn sin_cos_after_a_step_are_those_of_the_new_angle() {
        let mut unit = crate::math::test_rng::lcg(0x51c0_57e9);
        for _ in 0..100_000 {
            let a = (2.0 * unit() - 1.0) * std::f64::consts::PI;
            let scale =
                [1e-9, 1e-5, 9.9e-4, 1.01e-3, 0.1, 0.2499, 0.26, 2.0][(unit() * 8.0) as usize];
            let d = (2.0 * unit() - 1.0) * scale;
            let (sin_a, cos_a) = a.sin_cos();
            let alpha = a - d;
            let (s, c) = sin_cos_after_step(sin_a, cos_a, alpha, d);
            let (ls, lc) = alpha.sin_cos();
            assert!(
                (s - ls).abs() <= 5e-16 && (c - lc).abs() <= 5e-16,
                "{a} - {d}: ({s}, {c}) vs ({ls}, {lc})"
            );
        }
    }

    /// From alpha = 0 the step's sine is the series' sin d alone, so there the series are
    /// checked relative to sin d, not to 1: within two roundings of the library's sine for steps
    /// from 1e-9 to [`SMALL_ANGLE`] (a fifth-order term of sin d dropped is 1e-16 of it at
    /// d = 1e-3, hundreds of roundings).
    #[test]
    fn the_series_of_a_small_step_are_exact_relative_to_it() {
        let mut unit = crate::math::test_rng::lcg(0x5e71_e5d0);
        for _ in 0..20_000 {
            let scale = [1e-9, 1e-5, 9.99e-4, 1.01e-3, 0.1, 0.2499][(unit() * 6.0) as usize];
            let d = (2.0 * unit() - 1.0) * scale;
            let (s, c) = sin_cos_after_step(0.0, 1.0, -d, d);
            let (ls, lc) = (-d).sin_cos();
            assert!(
                (s - ls).abs() <= 2.0 * f64::EPSILON * ls.abs()
                    && (c - lc).abs() <= 2.0 * f64::EPSILON,
                "0 - {d}: ({s}, {c}) vs ({ls}, {lc})"
            );
        }
    }

    /// [`Trig::at_grid`] is [`Trig::on_grid`] at one point, bit for bit (the isolation takes F
    /// from one and F' and F'' from the other at the same points).
    #[test]
    fn at_grid_is_on_grid_bit_for_bit() {
        let mut unit = crate::math::test_rng::lcg(0x0a7_9e1d);
        for _ in 0..200 {
            let f = Trig {
                cos: std::array::from_fn(|_| 2.0 * unit() - 1.0),
                sin: std::array::from_fn(|k| if k == 0 { 0.0 } else { 2.0 * unit() - 1.0 }),
            };
            let all = f.on_grid();
            for (j, v) in all.iter().enumerate() {
                assert_eq!(
                    f.at_grid(j).to_bits(),
                    v.to_bits(),
                    "{f:?} at grid point {j}"
                );
            }
        }
    }

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

    /// prod_i (cos((p_i - q_i)/2) - cos(x - (p_i + q_i)/2)): roots exactly at every p_i, q_i.
    fn from_pairs(pairs: &[(f64, f64)]) -> Trig {
        pairs
            .iter()
            .fold(Trig::linear(1.0, 0.0, 0.0), |acc, &(p, q)| {
                let m = 0.5 * (p + q);
                acc.mul(&Trig::linear((0.5 * (p - q)).cos(), -m.cos(), -m.sin()))
            })
    }

    fn circle_dist(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(std::f64::consts::TAU);
        d.min(std::f64::consts::TAU - d)
    }

    /// Every expected root is within `tol` of a reported one, and every reported one of an
    /// expected one; the reported roots lie in [-pi, pi] and increase.
    fn assert_roots(p: &Trig, want: &[f64], tol: f64) {
        let got = p.roots();
        // In [-pi, pi], increasing, as `roots` promises.
        let pi = std::f64::consts::PI;
        assert!(got.iter().all(|x| (-pi..=pi).contains(x)), "{got:?}");
        assert!(got.windows(2).all(|w| w[0] < w[1]), "{got:?}");
        for &w in want {
            assert!(
                got.iter().any(|&g| circle_dist(g, w) < tol),
                "{w} not in {got:?}"
            );
        }
        for &g in &got {
            assert!(
                want.iter().any(|&w| circle_dist(g, w) < tol),
                "{g} not expected: {want:?}"
            );
        }
    }

    #[test]
    fn roots_on_the_circle() {
        let pairs = [(-2.9, -2.0), (-1.1, -0.3), (0.4, 1.2), (2.2, 3.0)];
        let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
        assert_roots(&from_pairs(&pairs), &want, 1e-12);
        assert_roots(&from_pairs(&pairs).scale(3.7e21), &want, 1e-12);
        assert!(Trig::linear(2.0, 1.0, 0.5).roots().is_empty());
        assert!(Trig::default().roots().is_empty());
    }

    #[test]
    fn roots_at_grid_points_and_pi() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let step = PI / 16.0;
        let pairs = [
            (0.0, FRAC_PI_2),
            (-FRAC_PI_2, 3.0 * step),
            (PI, -5.0 * step),
        ];
        let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
        assert_roots(&from_pairs(&pairs), &want, 1e-12);
    }

    #[test]
    fn close_pairs_are_separated() {
        use std::f64::consts::PI;
        for (centre, sep) in [
            (0.1, 6.7e-5),
            (1.0, 1e-5),
            (3.0 * PI / 16.0, 1e-5),
            (-0.0019, 2e-7),
            (0.0, 1e-7),
            (PI - 2e-3, 1e-7),
            (-PI + 1e-4, 1e-7),
        ] {
            let pairs = [
                (centre - 0.5 * sep, centre + 0.5 * sep),
                (2.0, -2.5),
                (1.7, 1.9),
            ];
            let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
            // 1 - cos(sep / 2) carries the pair's separation in the coefficients: rounded, it
            // moves the roots by a few percent of sep; a quarter of sep still tells them apart.
            assert_roots(&from_pairs(&pairs), &want, 0.25 * sep);
        }
    }

    #[test]
    fn double_root_gives_a_candidate() {
        for x in [0.3, 0.0, std::f64::consts::PI, -1.2] {
            let p = from_pairs(&[(x, x), (2.0, -2.5)]);
            assert_roots(&p, &[x, 2.0, -2.5], 1e-7);
        }
    }

    /// A form of the highest degree with coefficients from `unit`.
    fn random_form(unit: &mut impl FnMut() -> f64) -> Trig {
        let mut p = Trig::default();
        for k in 0..=MAX_HARMONIC {
            p.cos[k] = unit();
            if k > 0 {
                p.sin[k] = unit();
            }
        }
        p
    }

    #[test]
    fn agrees_with_the_half_angle_charts() {
        let mut uniform = crate::math::test_rng::lcg(0x1234_5678_9abc_def0);
        let mut unit = || uniform() * 2.0 - 1.0;
        for _ in 0..3000 {
            let p = random_form(&mut unit);
            let mut want = Vec::new();
            for shift in [false, true] {
                let q = p.to_half_angle_poly(shift);
                for r in crate::math::poly::roots_in(&q, -1.0, 1.0) {
                    want.push(2.0 * r.x.atan() + if shift { std::f64::consts::PI } else { 0.0 });
                }
            }
            assert_roots(&p, &want, 1e-9);
        }
    }

    /// [`Trig::roots_sin_cos`] (the AVX2 build where the processor has it) and its baseline
    /// build give the same roots bit for bit: random forms, forms with double roots and close
    /// pairs (the chart fallback), zero and not finite.
    #[test]
    fn roots_sin_cos_builds_agree() {
        let mut uniform = crate::math::test_rng::lcg(0x0bad_cafe_1234_5678);
        let mut unit = || uniform() * 2.0 - 1.0;
        let mut forms = vec![
            Trig::default(),
            Trig::linear(f64::NAN, 1.0, 0.0),
            Trig::linear(0.0, f64::INFINITY, 1.0),
        ];
        for _ in 0..3000 {
            forms.push(random_form(&mut unit));
            let (x, sep) = (3.0 * unit(), 1e-9 * (1.0 + unit()));
            forms.push(from_pairs(&[(x, x + sep), (x - 2.0, 0.5 * unit())]));
        }
        let bits = |roots: &[TrigRoot]| -> Vec<[u64; 3]> {
            roots
                .iter()
                .map(|r| [r.x, r.sin, r.cos].map(f64::to_bits))
                .collect()
        };
        for p in &forms {
            assert_eq!(
                bits(&p.roots_sin_cos()),
                bits(&p.roots_sin_cos_baseline()),
                "{p:?}"
            );
        }
    }

    /// [`Trig::roots_certified`]'s promise, checked against the roots a form was built with:
    /// the reported roots increase, lie outside the ambiguous intervals (closed, disjoint,
    /// increasing), carry their own sine and cosine, and each is within `tol` of a true root;
    /// every true root is reported within `tol` or lies in an ambiguous interval.
    fn assert_certified(p: &Trig, coef_err: f64, want: &[f64], tol: f64) -> Isolated {
        let iso = p.roots_certified(coef_err);
        let inside = |x: f64| iso.ambiguous.iter().any(|&[lo, hi]| x >= lo && x <= hi);
        for w in iso.roots.windows(2) {
            assert!(w[0].x < w[1].x, "{iso:?}");
        }
        for w in iso.ambiguous.windows(2) {
            assert!(w[0][1] < w[1][0], "{iso:?}");
        }
        for &[lo, hi] in &iso.ambiguous {
            assert!(lo <= hi && lo >= -std::f64::consts::PI && hi <= std::f64::consts::PI);
        }
        for r in &iso.roots {
            assert!(!inside(r.x), "{} in an ambiguous interval: {iso:?}", r.x);
            let (sin, cos) = r.x.sin_cos();
            assert!(
                (r.sin - sin).abs() <= 1e-15 && (r.cos - cos).abs() <= 1e-15,
                "{iso:?}"
            );
            assert!(
                want.iter().any(|&w| circle_dist(r.x, w) < tol),
                "{} is no root of {want:?}: {iso:?}",
                r.x
            );
        }
        for &w in want {
            // In [-pi, pi): the ambiguous intervals are.
            let w =
                (w + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            let found = iso.roots.iter().any(|r| circle_dist(r.x, w) < tol);
            let at_pi = (std::f64::consts::PI - w.abs()) < tol;
            let covered = inside(w) || (at_pi && (inside(-w) || inside(w)));
            assert!(found || covered, "{w} missed: {iso:?}");
        }
        iso
    }

    /// Simple roots apart from each other (1e-3 apart, 1e-3 from pi) are all proved: none left
    /// ambiguous, each reported once, within rounding.
    #[test]
    fn certified_isolation_proves_simple_roots() {
        use std::f64::consts::PI;
        for pairs in [
            vec![(-2.9, -2.0), (-1.1, -0.3), (0.4, 1.2), (2.2, 3.0)],
            vec![(0.7, 0.701), (-2.0, 2.5)],
            vec![(-PI + 1e-3, PI - 1e-3), (0.1, 0.2)],
        ] {
            let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
            for scale in [1.0, 3.7e21, 2e-30] {
                let p = from_pairs(&pairs).scale(scale);
                let iso = assert_certified(&p, 0.0, &want, 1e-12);
                assert!(iso.ambiguous.is_empty(), "{pairs:?}: {iso:?}");
                assert_eq!(iso.roots.len(), want.len(), "{pairs:?}: {iso:?}");
            }
        }
    }

    /// A root on a point of the isolation's grid (x = -pi + j pi / 16: alpha = 0, pi/2, pi) is
    /// not proved in double precision: F there is within rounding of zero, and the grid
    /// intervals on both sides are left ambiguous, one interval for both (the callers' factors
    /// decide it). Roots elsewhere are proved.
    #[test]
    fn a_root_on_a_grid_point_is_left_ambiguous() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let step = PI / 16.0;
        for x in [0.0, FRAC_PI_2, -3.0 * step, PI] {
            let pairs = [
                (x, 1.0 + x + 0.5 * step),
                (-2.0 + x + 0.5 * step, 2.0 + x + 0.3 * step),
            ];
            let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
            let iso = assert_certified(&from_pairs(&pairs), 0.0, &want, 1e-12);
            assert_eq!(iso.roots.len(), 3, "{x}: {iso:?}");
            if x == PI {
                assert_eq!(iso.ambiguous.len(), 2, "{x}: {iso:?}");
                assert_eq!(iso.ambiguous[0], [-PI, -PI + step], "{iso:?}");
                assert_eq!(iso.ambiguous[1], [PI - step, PI], "{iso:?}");
            } else {
                assert_eq!(iso.ambiguous.len(), 1, "{x}: {iso:?}");
                let [lo, hi] = iso.ambiguous[0];
                assert!(
                    (lo - (x - step)).abs() < 1e-12 && (hi - (x + step)).abs() < 1e-12,
                    "{x}: {iso:?}"
                );
            }
        }
    }

    /// A double root (and a triple one) off the grid cannot be proved in double precision: it
    /// lies in a narrow ambiguous interval, nothing is reported there, and the simple roots
    /// elsewhere are proved. Four double roots (the most a form of degree 4 has) give four
    /// intervals.
    #[test]
    fn a_double_root_is_left_ambiguous_in_a_narrow_interval() {
        use std::f64::consts::PI;
        for x in [0.3, -1.2, 1.0 + 1e-9, PI - 0.01] {
            for pairs in [vec![(x, x), (2.0, -2.5)], vec![(x, x), (x, 2.0)]] {
                let p = from_pairs(&pairs);
                let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
                let iso = assert_certified(&p, 0.0, &want, 1e-12);
                assert_eq!(iso.ambiguous.len(), 1, "{pairs:?}: {iso:?}");
                let [lo, hi] = iso.ambiguous[0];
                assert!(hi - lo < 1e-3, "{pairs:?}: {iso:?}");
                let simple = if pairs[1].0 == x { 1 } else { 2 };
                assert_eq!(iso.roots.len(), simple, "{pairs:?}: {iso:?}");
            }
        }
        let xs = [-2.5, -1.0, 0.5, 2.0];
        let p = from_pairs(&xs.map(|x| (x, x)));
        let iso = assert_certified(&p, 0.0, &xs, 1e-12);
        assert!(iso.roots.is_empty(), "{iso:?}");
        assert_eq!(iso.ambiguous.len(), 4, "{iso:?}");
        for (&[lo, hi], x) in iso.ambiguous.iter().zip(xs) {
            assert!(lo <= x && x <= hi && hi - lo < 1e-3, "{x}: {iso:?}");
        }
    }

    /// Close pairs of roots, from 1e-3 apart down to 1e-14: each root is proved or lies in an
    /// ambiguous interval (the promise the forward kinematics' factors build on), at the grid's
    /// points, near pi and at random places.
    #[test]
    fn close_pairs_are_proved_or_left_ambiguous() {
        use std::f64::consts::PI;
        let mut uniform = crate::math::test_rng::lcg(0x5eed_0fc1_05e0);
        let mut centres = vec![0.0, 0.1, PI / 16.0, -PI / 2.0, PI - 2e-3, -PI + 1e-4, PI];
        for _ in 0..200 {
            centres.push(PI * (2.0 * uniform() - 1.0));
        }
        let mut ambiguous = 0;
        for &centre in &centres {
            for k in 3..=14 {
                let sep = 10f64.powi(-k) * (1.0 + uniform());
                let pairs = [
                    (centre - 0.5 * sep, centre + 0.5 * sep),
                    (centre + 2.0, centre - 2.5),
                ];
                let want: Vec<f64> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
                // Rounding the coefficients moves a pair's roots by up to ~1e-16 / sep.
                let tol = 1e-12 + 1e-15 / sep;
                let iso = assert_certified(&from_pairs(&pairs), 0.0, &want, tol);
                ambiguous += iso.ambiguous.len();
            }
        }
        assert!(ambiguous > 0, "no pair was too close to prove");
    }

    /// The coefficients' own error counts: F = 1 - cos x + 1e-6 has no root, proved with
    /// exact coefficients; with an error of 2e-6 in them, the exact polynomial might touch zero
    /// at x = 0, which is then left ambiguous (and only there).
    #[test]
    fn the_coefficients_error_widens_what_is_not_proved() {
        let p = Trig::linear(1.0 + 1e-6, -1.0, 0.0);
        let exact = p.roots_certified(0.0);
        assert!(
            exact.roots.is_empty() && exact.ambiguous.is_empty(),
            "{exact:?}"
        );
        let loose = p.roots_certified(2e-6);
        assert!(loose.roots.is_empty(), "{loose:?}");
        assert_eq!(loose.ambiguous.len(), 1, "{loose:?}");
        let [lo, hi] = loose.ambiguous[0];
        assert!(lo <= 0.0 && 0.0 <= hi && hi - lo < 0.5, "{loose:?}");
        let p = from_pairs(&[(0.4, 1.2), (-2.0, 2.5)]);
        let tight = p.roots_certified(1e-12);
        assert!(
            tight.ambiguous.is_empty() && tight.roots.len() == 4,
            "{tight:?}"
        );
    }

    /// Nothing is proved about a form that is not finite, or about the zero form when its
    /// coefficients carry an error (or when that error is not finite): the whole circle is
    /// ambiguous. The zero form with exact coefficients has no isolated root.
    #[test]
    fn certified_isolation_of_degenerate_forms() {
        use std::f64::consts::PI;
        let whole = [[-PI, PI]];
        for (p, coef_err) in [
            (Trig::default(), 1e-9),
            (Trig::linear(f64::NAN, 1.0, 0.0), 0.0),
            (Trig::linear(0.0, f64::INFINITY, 1.0), 0.0),
            (from_pairs(&[(0.4, 1.2)]), f64::INFINITY),
            (from_pairs(&[(0.4, 1.2)]), f64::NAN),
        ] {
            let iso = p.roots_certified(coef_err);
            assert!(iso.roots.is_empty(), "{p:?}: {iso:?}");
            assert_eq!(
                iso.ambiguous.as_slice(),
                &whole,
                "{p:?} +- {coef_err}: {iso:?}"
            );
        }
        let zero = Trig::default().roots_certified(0.0);
        assert!(
            zero.roots.is_empty() && zero.ambiguous.is_empty(),
            "{zero:?}"
        );
    }

    /// [`Trig::roots_certified`] (the AVX2 build where the processor has it) and the baseline
    /// build of the same isolation give the same roots and intervals, bit for bit.
    #[test]
    fn certified_builds_agree() {
        let mut uniform = crate::math::test_rng::lcg(0x0ce7_1f1e_d000_0001);
        let mut unit = || uniform() * 2.0 - 1.0;
        for _ in 0..2000 {
            let (x, sep) = (3.0 * unit(), 1e-9 * (1.0 + unit()));
            for p in [
                random_form(&mut unit),
                from_pairs(&[(x, x + sep), (x - 2.0, 0.5 * unit())]),
            ] {
                let err = 1e-14 * (1.0 + unit());
                let a = p.roots_certified(err);
                let b = p.isolate_built::<false>(err, true);
                let bits = |i: &Isolated| -> (Vec<[u64; 3]>, Vec<[u64; 2]>) {
                    (
                        i.roots
                            .iter()
                            .map(|r| [r.x, r.sin, r.cos].map(f64::to_bits))
                            .collect(),
                        i.ambiguous.iter().map(|a| a.map(f64::to_bits)).collect(),
                    )
                };
                assert_eq!(bits(&a), bits(&b), "{p:?}");
            }
        }
    }

    /// `harmonic_bound(order)` bounds |p^(order)| over the circle and is attained by a single
    /// harmonic a cos kx + b sin kx (k^order sqrt(a^2 + b^2) at its crest, to 1e-12); for sums
    /// of harmonics it covers every sampled value.
    #[test]
    fn harmonic_bound_is_the_largest_derivative() {
        let mut uniform = crate::math::test_rng::lcg(0x4a12_b0c5_0000_0007);
        let mut unit = || uniform() * 2.0 - 1.0;
        for k in 1..=MAX_HARMONIC {
            let (a, b) = (unit(), unit());
            let mut p = Trig::default();
            p.cos[k] = a;
            p.sin[k] = b;
            let mut d = p;
            for order in 0..=2 {
                // p^(order) = k^order sqrt(a^2 + b^2) cos(k x - atan2(b, a) + order pi / 2).
                let crest = (b.atan2(a) - order as f64 * std::f64::consts::FRAC_PI_2) / k as f64;
                let bound = p.harmonic_bound(order);
                let top = d.eval(crest).abs();
                let exact = (k as f64).powi(order) * a.hypot(b);
                assert!((top - exact).abs() <= 1e-12 * exact, "k {k}, order {order}");
                assert!(
                    bound >= top && bound <= exact * (1.0 + 1e-11),
                    "k {k}, order {order}"
                );
                d = d.derivative();
            }
        }
        for _ in 0..200 {
            let mut p = random_form(&mut unit);
            p.cos[0] = 0.0;
            let mut d = p;
            for order in 0..=2 {
                let bound = p.harmonic_bound(order);
                for j in 0..100 {
                    let x = -3.2 + 0.064 * j as f64;
                    assert!(d.eval(x).abs() <= bound, "order {order} at {x}: {p:?}");
                }
                d = d.derivative();
            }
        }
    }

    /// p at x in double-double, from the library's sin x and cos x (the harmonics by their
    /// recurrences in double-double): the reference the rounding bounds are measured against.
    fn eval_dd(p: &Trig, x: f64) -> crate::math::dd::Dd {
        use crate::math::dd::Dd;
        let (s1, c1) = x.sin_cos();
        let (dc1, ds1) = (Dd::from(c1), Dd::from(s1));
        let (mut ck, mut sk) = (dc1, ds1);
        let mut exact = Dd::from(p.cos[0]);
        for k in 1..=MAX_HARMONIC {
            exact = exact + ck * p.cos[k] + sk * p.sin[k];
            (ck, sk) = (ck * dc1 - sk * ds1, sk * dc1 + ck * ds1);
        }
        exact
    }

    /// The largest |coefficient| of p: the scale `isolate_built` normalises by.
    fn largest_coefficient(p: &Trig) -> f64 {
        p.cos
            .iter()
            .chain(&p.sin)
            .fold(0.0f64, |m, a| m.max(a.abs()))
    }

    /// A root 6e-13 to 1e-12 inside an end of a grid interval that holds a double root as well:
    /// that interval goes to its chart, whose range reaches 1e-12 past the interval's ends in t
    /// (the tangent of each end is rounded), while F is beyond rounding at the end (F = -(1 -
    /// cos 3 (x - xd)) sin(x - xr) / 4, steep there) and the neighbour is proved root-free
    /// without a chart. The root is found once (within 1e-9: `roots` gives candidates), near
    /// the start and near the end of intervals all round; the other roots are the double ones.
    #[test]
    fn a_root_at_a_charted_intervals_end_is_found() {
        use std::f64::consts::PI;
        let step = PI / 16.0;
        let third = 2.0 * PI / 3.0;
        for j in [1, 5, 9, 12, 17, 21, 27, 30] {
            let (xa, xb) = ((j as f64 - 16.0) * step, (j as f64 - 15.0) * step);
            for inset in [6e-13, 8e-13, 1e-12] {
                for (simple, double) in
                    [(xa + inset, xb - 0.1 * step), (xb - inset, xa + 0.1 * step)]
                {
                    let doubles = [double, double + third, double - third];
                    let p = from_pairs(&[
                        (doubles[0], doubles[0]),
                        (doubles[1], doubles[1]),
                        (doubles[2], doubles[2]),
                        (simple, simple + PI),
                    ]);
                    // The premise: F beyond rounding at the grid point next to the root.
                    let f = p.scale(1.0 / largest_coefficient(&p));
                    let end = if simple < double { j } else { j + 1 };
                    assert!(
                        f.at_grid(end % GRID).abs() > f.eval_error(),
                        "j {j}, {simple}"
                    );
                    let got = p.roots();
                    let near = got.iter().filter(|&&x| (x - simple).abs() < 1e-9).count();
                    assert_eq!(near, 1, "j {j}, root at {simple}: {got:?}");
                    let expected = [simple, simple + PI].into_iter().chain(doubles);
                    for &x in &got {
                        assert!(
                            expected.clone().any(|r| circle_dist(x, r) < 1e-6),
                            "j {j}: {x} in {got:?}"
                        );
                    }
                }
            }
        }
    }

    /// A double root at the middle of a grid interval, where F is within rounding: the proof
    /// splits the interval off-centre, at 0.3 or 0.7 of it, never outside it. A root 0.1 of a
    /// step before the interval (found by the neighbour) is reported once, the double root is
    /// left in one narrow interval, and the other roots are proved: 30 intervals, 120 forms.
    #[test]
    fn a_double_root_at_an_intervals_middle_is_split_inside_it() {
        use std::f64::consts::PI;
        let step = PI / 16.0;
        let mut uniform = crate::math::test_rng::lcg(0x0ffc_e47e_0000_0003);
        let mut unit = || uniform() * 2.0 - 1.0;
        for trial in 0..120 {
            let j = 1 + trial % 30;
            let (xa, xb) = ((j as f64 - 16.0) * step, (j as f64 - 15.0) * step);
            let double = 0.5 * (xa + xb);
            let before = xa - 0.1 * step;
            let (q1, q2) = (PI * unit(), PI * unit());
            let far = before + 0.3 + 2.0 * unit().abs();
            let p = from_pairs(&[(double, double), (before, far), (q1, q2)]);
            let iso = assert_certified(&p, 0.0, &[double, before, far, q1, q2], 1e-9);
            assert!(
                iso.roots.iter().any(|r| (r.x - before).abs() < 1e-9),
                "{iso:?}"
            );
            assert_eq!(iso.ambiguous.len(), 1, "{iso:?}");
            let [lo, hi] = iso.ambiguous[0];
            assert!(lo <= double && double <= hi && hi - lo < 1e-3, "{iso:?}");
        }
    }

    /// The isolation's bounds (`Isolation::with_bounds`) cover every form within the coefficients'
    /// error, and that error reaches them. F is a single harmonic of degree 4, whose derivatives
    /// attain `harmonic_bound`; the exact form is F + e with e = ce cos(k (x - x0)), |e| <= ce
    /// on the circle, k = 0..4, placed so that e^(n) is at its crest, ce k^n, where F^(n) is.
    /// There |F^(n) + e^(n)| is within m2, m3, m4 (n = 2, 3, 4), and with k = 4 reaches them to
    /// 1e-11; the computed F, F', F'' are within ef, ed, es of the exact F + e, F' + e', F'' +
    /// e''. Amplitudes 1e-8 to 1e8, errors 1e-9 to 0.1 of them.
    #[test]
    fn isolation_bounds_cover_the_coefficients_error() {
        use crate::math::dd::Dd;
        use std::f64::consts::{FRAC_PI_2, PI};
        let mut uniform = crate::math::test_rng::lcg(0x5b0d_17e4_0000_0009);
        let mut unit = || uniform() * 2.0 - 1.0;
        // d^n/dx^n of a cos(k (x - x0)) at x.
        let nth = |a: f64, k: f64, x0: f64, n: i32, x: f64| {
            a * k.powi(n) * (k * (x - x0) + f64::from(n) * FRAC_PI_2).cos()
        };
        for trial in 0..40 {
            let (phase, amp) = (PI * unit(), 10f64.powf(8.0 * unit()));
            let mut p = Trig::default();
            p.cos[4] = amp * (4.0 * phase).cos();
            p.sin[4] = amp * (4.0 * phase).sin();
            let scale = p.cos[4].abs().max(p.sin[4].abs());
            let rel = [1e-9, 1e-6, 1e-3, 0.1][trial % 4];
            let iso = Isolation::with_bounds(&p, scale, rel * amp, true);
            // F = fa cos(4 (x - phase)), normalised, and its error ce, as `with_bounds` sees them.
            let (fa, ce) = (amp / scale, rel * amp / scale);
            for n in 0..=4 {
                // F^(n) at its crest.
                let top = phase - f64::from(n) * PI / 8.0;
                for k in 0..=MAX_HARMONIC {
                    if k == 0 && n > 0 {
                        continue;
                    }
                    let kf = k as f64;
                    let x0 = if k == 0 {
                        0.0
                    } else {
                        top + f64::from(n) * FRAC_PI_2 / kf
                    };
                    let e = |m: i32| nth(ce, kf, x0, m, top);
                    assert!((e(n) - ce * kf.powi(n)).abs() <= 1e-9 * ce * 4f64.powi(n));
                    let wanted = nth(fa, 4.0, phase, n, top) + e(n);
                    if n >= 2 {
                        let bound = [iso.m2, iso.m3, iso.m4][n as usize - 2];
                        assert!(wanted.abs() <= bound, "n {n}, k {k}: {wanted} > {bound}");
                        if k == MAX_HARMONIC {
                            let reach = wanted.abs() * (1.0 + 1e-11);
                            assert!(bound <= reach, "n {n}: {bound} > {reach}");
                        }
                    }
                    if n <= 2 {
                        let (form, bound) =
                            [(iso.f, iso.ef), (iso.d, iso.ed), (iso.s, iso.es)][n as usize];
                        let pt = iso.at(top);
                        let got = [pt.f, pt.d, pt.s][n as usize];
                        let exact = eval_dd(&form, top) + Dd::from(e(n));
                        let err = (Dd::from(got) - exact).abs().to_f64();
                        assert!(err <= bound, "n {n}, k {k}: {err} > {bound}");
                    }
                }
            }
        }
    }

    /// The three tests of an interval hold exactly at their margins: both ends of F (F', F'')
    /// beyond w M + rounding on one side decide it, an end within that does not, nor ends on
    /// either side; a coefficient error of 1e-3 makes the rounding as large as the chord term.
    #[test]
    fn the_interval_tests_decide_only_beyond_their_margins() {
        let mut uniform = crate::math::test_rng::lcg(0x7e57_3a12_0000_0005);
        let mut unit = || uniform() * 2.0 - 1.0;
        for _ in 0..50 {
            let p = random_form(&mut unit);
            let scale = largest_coefficient(&p);
            let iso = Isolation::with_bounds(&p, scale, 1e-3 * scale, true);
            let w = 1e-4 * (1.0 + unit());
            let margins = [
                w * iso.m2 + iso.ef,
                w * iso.m3 + iso.ed,
                w * iso.m4 + iso.es,
            ];
            for (test, margin) in margins.into_iter().enumerate() {
                // A point whose value of F (F', F'') is v.
                let at = |v: f64| {
                    let mut pt = iso.at(0.0);
                    match test {
                        0 => pt.f = v,
                        1 => pt.d = v,
                        _ => pt.s = v,
                    }
                    pt
                };
                let decides = |u: f64, v: f64| {
                    let (a, b) = (at(u), at(v));
                    [
                        iso.no_root(&a, &b, w),
                        iso.no_critical_point(&a, &b, w),
                        iso.no_inflection(&a, &b, w),
                    ][test]
                };
                let (out, inside) = (margin * (1.0 + 1e-12), margin * (1.0 - 1e-12));
                for sign in [1.0, -1.0] {
                    assert!(decides(sign * out, sign * 2.0 * out), "test {test}");
                    assert!(!decides(sign * inside, sign * 2.0 * out), "test {test}");
                    assert!(!decides(sign * 2.0 * out, sign * inside), "test {test}");
                    assert!(!decides(sign * out, -sign * out), "test {test}");
                }
            }
        }
    }

    /// K + (1 - cos u) + b sin u (1 - cos u), u = x - x0: a minimum K at x0 (F' = 0 there, F''
    /// = 1), with F - K about u^2 / 2 + b u^3 / 2 near it.
    fn bowl(x0: f64, k: f64, b: f64) -> Trig {
        // b sin u (1 - cos u) = b (sin u - sin 2u / 2).
        let (s1, c1) = x0.sin_cos();
        let (s2, c2) = (2.0 * x0).sin_cos();
        let mut p = Trig::default();
        p.cos[0] = k + 1.0;
        p.cos[1] = -c1 - b * s1;
        p.sin[1] = -s1 + b * c1;
        p.cos[2] = 0.5 * b * s2;
        p.sin[2] = -0.5 * b * c2;
        p
    }

    /// The band around a minimum of F within rounding of zero ([`Isolation::band_around`]) ends
    /// only where F is beyond rounding with the sign of the interval's ends: a point where F has
    /// that sign but is within rounding is not an end, since a form within the error can be
    /// below zero there and have its root beyond it. F = [`bowl`] with its minimum K just
    /// inside the rounding (K = -ef + 1e-4 ce, the coefficient error ce 1e-6 or 1e-8) and b =
    /// +-0.5: at the band's first point, r0 = sqrt(4 ef / F'') from x0, F is about K + 2 ef on
    /// one side, beyond rounding, and K + 2 ef - |b| r0^3 / 2 on the other, within it. There the
    /// form lowered by ce has its root beyond r0: both of its roots must lie in the band.
    #[test]
    fn the_band_around_a_minimum_ends_beyond_rounding() {
        for x0 in [0.0613, -1.234, 2.71] {
            for b in [0.5, -0.5] {
                for ce in [1e-6, 1e-8] {
                    // ef hardly depends on K: take it from the form with K = 0.
                    let flat = bowl(x0, 0.0, b);
                    let scale = largest_coefficient(&flat);
                    let ef = Isolation::with_bounds(&flat, scale, ce * scale, true).ef;
                    // F is p / scale: K in p's units.
                    let p = bowl(x0, -(ef - 1e-4 * ce) * scale, b);
                    let scale = largest_coefficient(&p);
                    let iso = Isolation::with_bounds(&p, scale, ce * scale, true);
                    // The premises: the minimum within rounding, and the band's first point on
                    // the side b points away from within rounding with the ends' sign.
                    let min = iso.at(x0);
                    assert!(
                        min.f < 0.0 && min.f.abs() <= iso.ef,
                        "{x0} {b} {ce}: {min:?}"
                    );
                    let r0 = (4.0 * iso.ef / min.s).sqrt();
                    let near = iso.at(x0 - b.signum() * r0).f;
                    assert!(near > 0.0 && near <= iso.ef, "{x0} {b} {ce}: {near}");
                    assert!(iso.at(x0 + b.signum() * r0).f > iso.ef, "{x0} {b} {ce}");
                    // The form within the error whose root lies beyond that point.
                    let mut q = p;
                    q.cos[0] -= ce * scale;
                    let roots = sampled_roots(&q);
                    assert_eq!(roots.len(), 2, "{x0} {b} {ce}: {roots:?}");
                    let beyond = roots.iter().any(|&r| -b.signum() * (r - x0) > r0);
                    assert!(beyond, "{x0} {b} {ce}: {roots:?}, r0 {r0}");
                    let got = assert_certified(&p, ce * scale, &roots, 1e-9);
                    assert!(got.roots.is_empty(), "{x0} {b} {ce}: {got:?}");
                    for r in roots {
                        assert!(
                            got.ambiguous.iter().any(|&[lo, hi]| r >= lo && r <= hi),
                            "{x0} {b} {ce}: {r} outside {got:?}"
                        );
                    }
                }
            }
        }
    }

    /// An interval that no test decides is bisected at most [`MAX_DEPTH`] times, then given
    /// up. F = [`bowl`] at x0 = 0, a grid point, with b = 0: F' is within rounding of zero near
    /// 0, so the intervals there are not proved monotone; with the coefficient error chosen so
    /// that F(0) = K lies less than 1e-27 beyond the rounding ef, no root is excluded until h^2
    /// F'' / 8 < F(0) - ef, h < 1e-13: beyond 40 bisections of the grid step. What is given up
    /// is one interval about 0, made of whole pieces step / 2^40 on each side; nothing else.
    #[test]
    fn an_interval_no_test_decides_is_given_up_at_the_depth_limit() {
        let step = std::f64::consts::PI / 16.0;
        let piece = step * 2f64.powi(-(MAX_DEPTH as i32));
        for size in [1.0, 3.7e21, 2e-30] {
            for k in [4e-14, 1e-13, 3e-13] {
                let p = bowl(0.0, k, 0.0).scale(size);
                let scale = largest_coefficient(&p);
                let ef = |coef_err: f64| Isolation::with_bounds(&p, scale, coef_err, true).ef;
                let f0 = Isolation::with_bounds(&p, scale, 0.0, true).f.on_grid()[16];
                // The largest coefficient error whose rounding stays below F(0).
                let (mut lo, mut hi) = (0.0, f0 * scale);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if ef(mid) < f0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let gap = f0 - ef(lo);
                assert!(gap > 0.0 && gap < 1e-27, "{size} {k}: {gap}");
                let got = p.roots_certified(lo);
                assert!(got.roots.is_empty(), "{size} {k}: {got:?}");
                // F is flat in double precision this near 0 (cos x rounds to 1), so the pieces
                // given up are those whose F' = sin x is within the rounding ed at their inner
                // end: n of them on each side.
                let ed = Isolation::with_bounds(&p, scale, lo, true).ed;
                let n = (ed / piece).floor() + 1.0;
                let want = [-n * piece, n * piece];
                assert_eq!(got.ambiguous.as_slice(), &[want], "{size} {k}: {n} pieces");
            }
        }
    }

    /// `eval_error` bounds the rounding of the isolation's evaluation of p (the harmonics by
    /// their recurrences, then the sum) against the same evaluation in double-double, for
    /// random forms (a third of them of cosines or of sines only) and points.
    #[test]
    fn eval_error_bounds_the_evaluation() {
        use crate::math::dd::Dd;
        let mut uniform = crate::math::test_rng::lcg(0x3e7a_1e44_0000_0003);
        let mut unit = || uniform() * 2.0 - 1.0;
        let mut worst = 0.0f64;
        for trial in 0..300 {
            let mut p = random_form(&mut unit).scale(10f64.powi((8.0 * unit()) as i32));
            if trial % 3 == 0 {
                // Cosines only (or sines only): the bound must not lean on the other half.
                let k = trial % 2;
                p.sin = [0.0; MAX_HARMONIC + 1];
                if k == 1 {
                    p.sin = p.cos;
                    p.sin[0] = 0.0;
                    p.cos = [0.0; MAX_HARMONIC + 1];
                }
            }
            for _ in 0..50 {
                let x = std::f64::consts::PI * unit();
                let (s1, c1) = x.sin_cos();
                let (c, s) = harmonics(s1, c1);
                let got = dot_harmonics(&p, &c, &s);
                let err = (Dd::from(got) - eval_dd(&p, x)).abs().to_f64();
                let bound = p.eval_error();
                assert!(err <= bound, "{err} > {bound} at {x}: {p:?}");
                worst = worst.max(err / bound);
            }
        }
        assert!(worst > 0.0, "no rounding seen");
    }

    /// The roots of p on the circle found by sampling 20,000 points and bisecting each sign
    /// change: every simple root, none of the pairs closer than the sampling (a slow method
    /// independent of the isolation).
    fn sampled_roots(p: &Trig) -> Vec<f64> {
        use std::f64::consts::{PI, TAU};
        let n = 20_000;
        let x = |j: usize| -PI + TAU * j as f64 / n as f64;
        let mut out = Vec::new();
        for j in 0..n {
            let (mut a, mut b) = (x(j), x(j + 1));
            let (fa, fb) = (p.eval(a), p.eval(b));
            if fa == 0.0 {
                out.push(a);
                continue;
            }
            if (fa < 0.0) == (fb < 0.0) || fb == 0.0 {
                continue;
            }
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if (p.eval(m) < 0.0) == (fa < 0.0) {
                    a = m;
                } else {
                    b = m;
                }
            }
            out.push(0.5 * (a + b));
        }
        out
    }

    /// The isolation with a coefficient error covers every form within that error: for random
    /// forms p and perturbations d = e cos(k x + phi) (|d| <= e, with the largest derivatives
    /// Bernstein's inequality allows, k^n e), every root of p + d outside p's ambiguous
    /// intervals is next to one of p's proved roots, one for one (each proved root is the only
    /// root of every form within the error on its interval, and the rest of the circle is
    /// root-free for all of them).
    #[test]
    fn certified_isolation_covers_every_form_within_its_error() {
        let mut uniform = crate::math::test_rng::lcg(0x00c0_7e25_e770_0005);
        let mut checked = 0;
        for trial in 0..300 {
            let mut unit = || uniform() * 2.0 - 1.0;
            // Random forms, and forms with a pair of roots 1e-3 to 0.3 apart (where the error
            // decides whether they are proved), at scales 1e-3 to 1e3.
            let p = if trial % 2 == 0 {
                random_form(&mut unit)
            } else {
                let (c, sep) = (3.0 * unit(), 10f64.powf(-2.0 + 1.5 * unit()));
                from_pairs(&[(c - 0.5 * sep, c + 0.5 * sep), (c + 2.0, c - 2.0 + unit())])
            };
            let p = p.scale(10f64.powf(3.0 * unit()));
            let scale = p
                .cos
                .iter()
                .chain(&p.sin)
                .fold(0.0f64, |m, a| m.max(a.abs()));
            let e = scale * 10f64.powf(-2.0 - 2.0 * (0.5 + 0.5 * unit()));
            let iso = p.roots_certified(e);
            let inside = |x: f64| iso.ambiguous.iter().any(|&[lo, hi]| x >= lo && x <= hi);
            let d = p.derivative();
            for k in 0..=MAX_HARMONIC {
                let phi = std::f64::consts::PI * unit();
                let mut q = p;
                q.cos[k] += e * phi.cos();
                if k > 0 {
                    q.sin[k] -= e * phi.sin();
                }
                let outside: Vec<f64> = sampled_roots(&q)
                    .into_iter()
                    .filter(|&r| !inside(r))
                    .collect();
                assert_eq!(
                    outside.len(),
                    iso.roots.len(),
                    "e {e}, k {k}: {outside:?} vs {iso:?} of {p:?}"
                );
                for (r, x) in outside.iter().zip(&iso.roots) {
                    // A root of p moves by about e / |p'| under d.
                    let tol = 4.0 * e / d.eval(x.x).abs() + 1e-9;
                    assert!(
                        circle_dist(*r, x.x) <= tol,
                        "{r} vs {x:?}: e {e}, k {k}, {p:?}"
                    );
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 1500);
    }
}
