//! Real roots of a cubic on an interval, for the inverse kinematics' eq. (9) (IFToMM 2007): the
//! method of [`crate::math::poly::roots_in`] (critical points split the interval into monotone
//! pieces; a piece with a sign change holds exactly one root) with the critical points in closed
//! form and each root found by Halley steps kept inside its bracket, started from the secant
//! point instead of the midpoint. Close calls (a critical point within rounding of a double root
//! of p', a leading coefficient within rounding of zero) go to the general routine.

use arrayvec::ArrayVec;

use crate::math::poly::{Root, push_unique, roots_in_with_error};

/// The roots on one interval: at most three, plus critical points reported as touching.
pub type CubicRoots = ArrayVec<Root, 8>;

/// All real roots of `c[0] + c[1] x + c[2] x^2 + c[3] x^3` in [lo, hi], sorted, with the
/// semantics of [`roots_in`](crate::math::poly::roots_in) (end points that are roots included, critical points where |p|
/// is within its rounding error reported as touching).
pub fn cubic_roots_in(c: &[f64; 4], lo: f64, hi: f64) -> CubicRoots {
    cubic_roots_in_with_error(c, &[0.0; 4], lo, hi)
}

/// [`cubic_roots_in`] where coefficient i may be off by `err[i]`: its decisions (a sign change,
/// a critical point touching zero) hold for the exact cubic.
pub fn cubic_roots_in_with_error(c: &[f64; 4], err: &[f64; 4], lo: f64, hi: f64) -> CubicRoots {
    let scale = c.iter().fold(0.0f64, |m, a| m.max(a.abs()));
    // p' = 3 c3 x^2 + 2 c2 x + c1: closed form unless it is (nearly) linear or (nearly) a square.
    let (a, b, k) = (3.0 * c[3], 2.0 * c[2], c[1]);
    let disc = b * b - 4.0 * a * k;
    let rounding = 16.0 * f64::EPSILON * (b * b + (4.0 * a * k).abs());
    if c[3].abs() <= 1e-8 * scale
        || disc.abs() <= rounding
        || !disc.is_finite()
        || lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less)
    {
        return roots_in_with_error(c, err, lo, hi)
            .into_iter()
            .take(8)
            .collect();
    }
    let mut crit = ArrayVec::<f64, 2>::new();
    if disc > 0.0 {
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        let (x1, x2) = (q / a, k / q);
        let (x1, x2) = if x1 <= x2 { (x1, x2) } else { (x2, x1) };
        crit.extend([x1, x2].into_iter().filter(|&x| x > lo && x < hi));
    }
    let mut out = CubicRoots::new();
    let (mut xa, (mut fa, mut ea)) = (lo, eval_with_error(c, err, lo));
    if fa.abs() <= ea {
        out.push(Root {
            x: lo,
            touching: false,
        });
    }
    for k in 0..=crit.len() {
        let xb = if k < crit.len() { crit[k] } else { hi };
        let (fb, eb) = eval_with_error(c, err, xb);
        let b_zero = fb.abs() <= eb;
        if fa.abs() > ea && !b_zero && (fa < 0.0) != (fb < 0.0) {
            push_unique(&mut out, bracketed(c, xa, xb, fa, fb));
        } else if b_zero {
            push_unique(
                &mut out,
                Root {
                    x: xb,
                    touching: k < crit.len(),
                },
            );
        }
        (xa, fa, ea) = (xb, fb, eb);
    }
    out
}

/// p(x) and a bound on its error, as [`crate::math::poly::eval_with_coefficient_error`] for degree 3.
#[inline]
fn eval_with_error(c: &[f64; 4], err: &[f64; 4], x: f64) -> (f64, f64) {
    let ax = x.abs();
    let coef = ((err[3] * ax + err[2]) * ax + err[1]) * ax + err[0];
    let p3 = c[3];
    let p2 = p3 * x + c[2];
    let p1 = p2 * x + c[1];
    let p0 = p1 * x + c[0];
    let bound = ((p3.abs() * ax + p2.abs()) * ax + p1.abs()) * ax + p0.abs();
    (p0, bound * 16.0 * f64::EPSILON + coef)
}

/// The root of a cubic that is monotone on [a, b] with p(a), p(b) of opposite signs: Halley
/// steps from the secant point, every step kept inside the shrinking bracket (bisection
/// otherwise). Halley's error after a step d is about C d^3 (C from p's derivatives); the
/// iteration ends when that is below rounding, or a step or the bracket reaches rounding level.
fn bracketed(c: &[f64; 4], mut a: f64, mut b: f64, fa: f64, fb: f64) -> Root {
    let a_neg = fa < 0.0;
    let mut x = a + (b - a) * (fa / (fa - fb));
    if !(x > a && x < b) {
        x = 0.5 * (a + b);
    }
    for _ in 0..200 {
        let f = ((c[3] * x + c[2]) * x + c[1]) * x + c[0];
        if f == 0.0 {
            break;
        }
        if (f < 0.0) == a_neg {
            a = x;
        } else {
            b = x;
        }
        let d1 = (3.0 * c[3] * x + 2.0 * c[2]) * x + c[1];
        let d2 = 6.0 * c[3] * x + 2.0 * c[2];
        let step = 2.0 * f * d1 / (2.0 * d1 * d1 - f * d2);
        let next = x - step;
        let tiny = 2.0 * f64::EPSILON * x.abs().max(1e-300);
        let inside = next > a && next < b && step.is_finite();
        if !inside {
            // Outside the bracket (or at its end, with f at rounding level): bisect.
            if step.abs() <= tiny {
                break;
            }
            x = 0.5 * (a + b);
        } else {
            x = next;
            // error = (r2^2 / 4 + |r3| / 6) |step|^3 with r2 = p''/p', r3 = p'''/p', multiplied
            // through by p'^2 (no division).
            let s = step.abs();
            let error_d1sq = (0.25 * d2 * d2 + (c[3] * d1).abs()) * (s * s * s);
            if s <= tiny || error_d1sq <= 0.5 * f64::EPSILON * x.abs() * (d1 * d1) {
                break;
            }
        }
        if b - a <= f64::EPSILON * (a.abs() + b.abs()) {
            break;
        }
    }
    Root { x, touching: false }
}

/// How far (relative to the quadratic's largest coefficient, squared) the discriminant of a
/// deflated cubic, and (absolute) its roots from the interval's ends, must be for
/// [`deflated_roots_in`] to decide alone.
const DEFLATED_DISC_MARGIN: f64 = 1e-6;
const DEFLATED_END_MARGIN: f64 = 1e-9;

/// The roots in (lo, hi) of `c[0] + c[1] x + c[2] x^2 + c[3] x^3` other than its known root `w`
/// (outside [lo, hi]): the quadratic c / (x - w) in closed form, sorted. None when that is a close
/// call (a discriminant near zero: a close pair or double root; a root near `lo` or `hi`), so
/// that [`cubic_roots_in`] decides; a caller polishes the roots on its own equations (the
/// deflation adds a rounding error of the order of `w`'s). At most two, in a list of
/// [`CubicRoots`]' size, so that a caller that falls back on [`cubic_roots_in`] keeps one list
/// type for both and takes this one as it is (no copy).
#[inline]
pub fn deflated_roots_in(c: &[f64; 4], w: f64, lo: f64, hi: f64) -> Option<ArrayVec<f64, 8>> {
    // Synthetic division: c = (x - w) (a x^2 + b x + k) + remainder.
    let a = c[3];
    let b = c[2] + w * a;
    let k = c[1] + w * b;
    let scale = a.abs().max(b.abs()).max(k.abs());
    if a.abs() <= 1e-8 * scale || !scale.is_finite() {
        return None;
    }
    let disc = b * b - 4.0 * a * k;
    let mut out = ArrayVec::new();
    if disc.abs() <= DEFLATED_DISC_MARGIN * scale * scale {
        return None;
    }
    if disc < 0.0 {
        return Some(out);
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (x1, x2) = (q / a, k / q);
    for x in if x1 <= x2 { [x1, x2] } else { [x2, x1] } {
        if (x - lo).abs() <= DEFLATED_END_MARGIN || (x - hi).abs() <= DEFLATED_END_MARGIN {
            return None;
        }
        if x > lo && x < hi {
            out.push(x);
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::poly::roots_in;
    use crate::math::test_rng::lcg;

    fn from_roots(rs: [f64; 3], lead: f64) -> [f64; 4] {
        let [r1, r2, r3] = rs;
        [
            -lead * r1 * r2 * r3,
            lead * (r1 * r2 + r1 * r3 + r2 * r3),
            -lead * (r1 + r2 + r3),
            lead,
        ]
    }

    /// Same roots as the general routine, to rounding, on random cubics and sub-intervals.
    #[test]
    fn agrees_with_the_general_routine() {
        let mut unit = lcg(1);
        for _ in 0..20_000 {
            let rs = [2.4 * unit() - 1.2, 2.4 * unit() - 1.2, 2.4 * unit() - 1.2];
            let c = from_roots(rs, if unit() < 0.5 { -1.0 } else { 0.3 });
            let lo = -1.0 + 0.5 * unit();
            let fast = cubic_roots_in(&c, lo, 1.0);
            let slow = roots_in(&c, lo, 1.0);
            assert_eq!(
                fast.len(),
                slow.len(),
                "{rs:?} on [{lo}, 1]: {fast:?} vs {slow:?}"
            );
            for (f, g) in fast.iter().zip(&slow) {
                assert!((f.x - g.x).abs() < 1e-9, "{rs:?}: {fast:?} vs {slow:?}");
                assert_eq!(f.touching, g.touching, "{rs:?}: {fast:?} vs {slow:?}");
                // As exact as the cubic allows: p there within twice its rounding error.
                let (p, err) = eval_with_error(&c, &[0.0; 4], f.x);
                assert!(p.abs() <= 2.0 * err, "{rs:?}: p({}) = {p:e} > {err:e}", f.x);
            }
        }
    }

    #[test]
    fn close_pair_double_root_and_end_points() {
        let got = cubic_roots_in(&from_roots([0.1, 0.1 + 1e-5, 0.5], 1.0), -1.0, 1.0);
        assert_eq!(got.len(), 3, "{got:?}");
        let got = cubic_roots_in(&from_roots([0.3, 0.3, -0.7], 1.0), -1.0, 1.0);
        assert!(
            got.iter().any(|r| (r.x - 0.3).abs() < 1e-7 && r.touching),
            "{got:?}"
        );
        assert!(got.iter().any(|r| (r.x + 0.7).abs() < 1e-12), "{got:?}");
        let got = cubic_roots_in(&from_roots([-1.0, 2.0, 0.25], 1.0), -1.0, 1.0);
        assert_eq!(got.len(), 2, "{got:?}");
        assert_eq!(got[0].x, -1.0);
    }

    /// Coefficients each off by at most err: the value of every cubic within those errors lies
    /// within the bound of the computed value, and the bound is no wider than the errors' worst
    /// case plus the rounding bound.
    #[test]
    fn the_error_bound_covers_the_coefficients_errors() {
        let (c, err) = ([1.0, -2.0, 3.0, 0.5], [0.1, 0.05, 0.2, 0.01]);
        for x in [-2.0, -0.5, 0.0, 0.7, 3.0] {
            let (p, bound) = eval_with_error(&c, &err, x);
            let rounding = eval_with_error(&c, &[0.0; 4], x).1;
            let mut widest = 0.0f64;
            for signs in 0..16u32 {
                let shifted: [f64; 4] = std::array::from_fn(|i| {
                    c[i] + if signs >> i & 1 == 1 { err[i] } else { -err[i] }
                });
                let q = eval_with_error(&shifted, &[0.0; 4], x).0;
                assert!((q - p).abs() <= bound, "x={x}: |{q} - {p}| > {bound}");
                widest = widest.max((q - p).abs());
            }
            assert!(
                bound <= widest * (1.0 + 1e-9) + 2.0 * rounding,
                "x={x}: {bound} vs {widest}"
            );
        }
    }

    /// Cubics of every scale (roots from 1e-3 to 1e3 apart, leading coefficients from 1e-4 to
    /// 1e4, intervals cutting the roots anywhere): the same roots as the general routine, each
    /// as exact as the cubic allows. Pieces next to a critical point, where p' vanishes at one
    /// end, send Halley's step out of the bracket (then bisected).
    #[test]
    fn agrees_with_the_general_routine_at_every_scale() {
        let mut unit = lcg(11);
        let mut roots_seen = 0;
        for _ in 0..20_000 {
            let scale = 10f64.powf(6.0 * unit() - 3.0);
            let centre = scale * (4.0 * unit() - 2.0);
            let rs = [0; 3].map(|_| centre + scale * (2.0 * unit() - 1.0));
            let lead = (if unit() < 0.5 { -1.0 } else { 1.0 }) * 10f64.powf(8.0 * unit() - 4.0);
            let c = from_roots(rs, lead);
            let (lo, hi) = (
                centre - scale * (1.5 * unit()),
                centre + scale * (1.5 * unit()),
            );
            let fast = cubic_roots_in(&c, lo, hi);
            let slow = roots_in(&c, lo, hi);
            assert_eq!(
                fast.len(),
                slow.len(),
                "{rs:?} x {lead} on [{lo}, {hi}]: {fast:?} vs {slow:?}"
            );
            for (f, g) in fast.iter().zip(&slow) {
                assert!(
                    (f.x - g.x).abs() <= 1e-9 * scale.max(centre.abs()),
                    "{rs:?} x {lead}: {fast:?} vs {slow:?}"
                );
                assert!(f.x >= lo && f.x <= hi, "{rs:?}: {f:?} outside [{lo}, {hi}]");
                let (p, err) = eval_with_error(&c, &[0.0; 4], f.x);
                assert!(p.abs() <= 2.0 * err, "{rs:?}: p({}) = {p:e} > {err:e}", f.x);
            }
            roots_seen += fast.len();
        }
        assert!(roots_seen > 20_000, "{roots_seen}");
    }

    /// The deflation decides alike at every scale of the coefficients (its margins are
    /// relative to them), and refuses a root within its margin of either end of the interval.
    #[test]
    fn deflation_is_scale_free_and_refuses_roots_at_the_ends() {
        let mut unit = lcg(13);
        for _ in 0..5_000 {
            let w = 0.5 + 0.5 * unit();
            let (r2, r3) = (2.4 * unit() - 1.2, 2.4 * unit() - 1.2);
            let c = from_roots([w, r2, r3], 0.3 + unit());
            let base = deflated_roots_in(&c, w, -1.0, 0.45);
            for f in [1e-4, 1e4] {
                let scaled = c.map(|v| v * f);
                let got = deflated_roots_in(&scaled, w, -1.0, 0.45);
                assert_eq!(got.is_some(), base.is_some(), "{w} {r2} {r3} x {f}");
                if let (Some(a), Some(b)) = (&got, &base) {
                    assert_eq!(a.len(), b.len());
                    for (x, y) in a.iter().zip(b) {
                        assert!((x - y).abs() < 1e-9);
                    }
                }
            }
        }
        // A root just inside either end: a close call, left to the isolator.
        for (lo, hi, r) in [(-1.0, 0.45, -1.0 + 1e-11), (-1.0, 0.45, 0.45 - 1e-11)] {
            let c = from_roots([0.8, r, -0.2], 1.0);
            assert_eq!(deflated_roots_in(&c, 0.8, lo, hi), None, "root {r}");
        }
    }

    /// The bisection fallback of `bracketed`, taken when a Halley step leaves the bracket or
    /// the secant point rounds onto an end: cubics found by a search (three close roots, a
    /// piece ending at a critical point) where a wrong midpoint, or a step accepted outside
    /// the bracket, ends outside the bracket or off the root.
    #[test]
    fn bracketed_stays_in_its_bracket_when_halley_leaves_it() {
        let p = |c: &[f64; 4], x: f64| ((c[3] * x + c[2]) * x + c[1]) * x + c[0];
        let cases: [([f64; 4], f64, f64); 10] = [
            (
                [
                    -0.04345861414348768,
                    0.21993079631705534,
                    -0.37100090178523837,
                    0.208613605235847,
                ],
                -3.0,
                0.5927837808208003,
            ),
            (
                [
                    -0.026385612361595225,
                    0.04639586726295099,
                    -0.027193816183017125,
                    0.0053129993017665906,
                ],
                1.7059467563456108,
                1.7062898653776517,
            ),
            (
                [
                    0.004116549612865756,
                    -0.04392864687966058,
                    0.15625756180030367,
                    -0.18527337211025333,
                ],
                0.28113141265356956,
                3.0,
            ),
            // The secant point rounds onto an end (p(b) near rounding level): the midpoint
            // start; 0.5 a b instead leaves the bracket for another root.
            (
                [
                    0.0058042037054173955,
                    0.9961899462346724,
                    30.728798739992786,
                    18.98169920115993,
                ],
                -1.0627825529955628,
                -0.02537170963198746,
            ),
            (
                [
                    0.5167506192679999,
                    11.770938420371316,
                    66.50680472655166,
                    21.058378653855474,
                ],
                -2.0129104041990353,
                -0.11063219721187734,
            ),
            (
                [
                    -0.0006833847035556391,
                    -0.028020655116685934,
                    -0.2705181498595575,
                    -0.1070770823562216,
                ],
                -1.6307685511431986,
                -0.06864637937560651,
            ),
            // A secant point on an end kept as the start (the guard's `!` deleted, or `>` as
            // `>=`), a midpoint 0.5 + (a + b), a step beyond a accepted (`next > a` as
            // `next < a`): each ends outside its bracket or off the root on one of these
            // (found by the same search).
            (
                [
                    2.6882296147329855e-07,
                    0.0002182438011259801,
                    0.05906037686139519,
                    5.327571063800048,
                ],
                -0.003694891586839332,
                0.929477455929554,
            ),
            (
                [
                    -1.3944234949291775e-05,
                    0.007344316744884802,
                    -1.289397579086972,
                    75.4572627098494,
                ],
                0.005696163597819528,
                0.4280733083345863,
            ),
            (
                [
                    -5.788467027601219e-07,
                    -0.0006520952959404948,
                    -0.2448709780491649,
                    -30.650834946247922,
                ],
                -0.1555209854884664,
                -0.0026630806160470666,
            ),
            (
                [
                    -27.237528205335906,
                    76.59000608520242,
                    -71.78856300529563,
                    22.429374444793684,
                ],
                1.0669076452278796,
                1.6021128764201191,
            ),
        ];
        for (c, a, b) in cases {
            let (fa, fb) = (p(&c, a), p(&c, b));
            assert!(
                (fa < 0.0) != (fb < 0.0),
                "{c:?}: a sign change on [{a}, {b}]"
            );
            let r = bracketed(&c, a, b, fa, fb);
            assert!(r.x >= a && r.x <= b, "{c:?}: {} outside [{a}, {b}]", r.x);
            let (v, err) = eval_with_error(&c, &[0.0; 4], r.x);
            assert!(v.abs() <= 2.0 * err, "{c:?}: p({}) = {v:e} > {err:e}", r.x);
        }
    }

    /// Critical points within rounding of a double one (p = (x - r)^3 + d (x - r) + g with d
    /// near zero: a near-triple root or an inflection with a tiny slope) go to the general
    /// routine: the same roots, where the closed form's discriminant has no reliable sign.
    #[test]
    fn near_double_critical_points_agree_with_the_general_routine() {
        let mut cases = 0;
        for r in [-2.0, 0.3, 1.7] {
            for lead in [1.0, -3.0] {
                for d in [0.0, 1e-17, -1e-17, 1e-15, -1e-15] {
                    for g in [0.0, 1e-16, -1e-16, 1e-12, -1e-12, 1e-8, -1e-8] {
                        // (x - r)^3 + d (x - r) + g, times lead.
                        let c = [
                            lead * (-r * r * r - d * r + g),
                            lead * (3.0 * r * r + d),
                            lead * (-3.0 * r),
                            lead,
                        ];
                        let (lo, hi) = (r - 1.0, r + 1.0);
                        let fast = cubic_roots_in(&c, lo, hi);
                        let slow = roots_in(&c, lo, hi);
                        assert_eq!(fast.len(), slow.len(), "{c:?}: {fast:?} vs {slow:?}");
                        for (f, s) in fast.iter().zip(&slow) {
                            assert!((f.x - s.x).abs() <= 1e-6, "{c:?}: {fast:?} vs {slow:?}");
                        }
                        cases += 1;
                    }
                }
            }
        }
        assert_eq!(cases, 210);
    }

    /// An empty, reversed or not-a-number interval goes to the general routine: the same
    /// answer (here none, or the root an interval of one point holds), never a root outside.
    #[test]
    fn a_degenerate_interval_answers_as_the_general_routine() {
        let c = from_roots([-1.0, 0.5, 2.0], 1.0);
        for (lo, hi) in [
            (1.5, 0.0),
            (3.0, -3.0),
            (0.5, 0.5),
            (1.0, 1.0),
            (f64::NAN, 1.0),
            (0.0, f64::NAN),
        ] {
            let fast: Vec<_> = cubic_roots_in(&c, lo, hi).into_iter().collect();
            let slow: Vec<_> = roots_in(&c, lo, hi).into_iter().collect();
            assert_eq!(fast, slow, "[{lo}, {hi}]");
            assert!(
                fast.iter().all(|r| r.x >= lo && r.x <= hi),
                "[{lo}, {hi}]: {fast:?}"
            );
        }
    }

    /// Critical points far apart (p' with b^2 >> 4ak): the stable form of the quadratic
    /// formula keeps the small one accurate, so a close pair of roots beside it is split by
    /// it and found; the form that subtracts nearly equal numbers misplaces it by more than
    /// the pair's width.
    #[test]
    fn a_close_pair_beside_a_far_critical_point_is_found() {
        for (pair, far) in [(1e-7f64, 1e7f64), (3e-5, -2e6), (-1e-6, 5e8)] {
            let rs = [pair * (1.0 - 1e-4), pair * (1.0 + 1e-4), far];
            let c = from_roots(rs, 1.0);
            let (lo, hi) = (
                pair.min(0.0) - 2.0 * pair.abs(),
                pair.max(0.0) + 2.0 * pair.abs(),
            );
            let found = cubic_roots_in(&c, lo, hi);
            assert_eq!(found.len(), 2, "{rs:?}: {found:?}");
            let mut pair_roots = [rs[0], rs[1]];
            pair_roots.sort_by(f64::total_cmp);
            for (f, r) in found.iter().zip(&pair_roots) {
                assert!((f.x - r).abs() <= 1e-9 * pair.abs(), "{rs:?}: {found:?}");
            }
        }
    }

    /// A critical point where p is above zero by more than its rounding is no root: the
    /// error bound of p at x weighs c3 by |x|^3 (a small |x| and a large c3 here), not by c3
    /// plus |x|.
    #[test]
    fn a_minimum_above_its_rounding_is_no_root() {
        // p = 1e6 (x^3 - 3e-6 x) + d: a local minimum at x = 1e-3 of 1e-16, about ten times
        // the rounding of p there (1.1e-17).
        let d = 2e-3 + 1e-16;
        let c = [d, -3.0, 0.0, 1e6];
        let (p, err) = eval_with_error(&c, &[0.0; 4], 1e-3);
        assert!(p > 5e-17 && err < 2e-17, "p {p:e}, bound {err:e}");
        assert!(cubic_roots_in(&c, 0.0, 1.0).is_empty());
        // Lowered by 2e-16 it crosses zero twice near the minimum.
        let c = [d - 2e-16, -3.0, 0.0, 1e6];
        assert_eq!(cubic_roots_in(&c, 0.0, 1.0).len(), 2);
    }

    /// Coefficients so large that the discriminant of p' is inf - inf go to the general
    /// routine (an infinite one already fails the rounding test): the same roots at every
    /// such scale.
    #[test]
    fn an_overflowing_discriminant_goes_to_the_general_routine() {
        let roots = [0.5, 2.0, 3.0];
        for scale in [1e160, 1e200, 1e250, 1e300] {
            let c = from_roots(roots, 1.0).map(|v| v * scale);
            let (a, b, k) = (3.0 * c[3], 2.0 * c[2], c[1]);
            assert!((b * b - 4.0 * a * k).is_nan(), "{scale:e}");
            let found = cubic_roots_in(&c, -5.0, 5.0);
            assert_eq!(found.len(), 3, "{scale:e}: {found:?}");
            for (f, r) in found.iter().zip(roots) {
                assert!((f.x - r).abs() < 1e-12, "{scale:e}: {found:?}");
            }
        }
    }

    /// The deflated quadratic's roots far apart: the stable form keeps the small one, the one
    /// in the interval, to rounding.
    #[test]
    fn deflation_keeps_a_small_root_beside_a_large_one() {
        for (small, large) in [(1e-6f64, 1e6f64), (-3e-5, 4e6), (2e-4, -5e6)] {
            let c = from_roots([-3.0, small, large], 1.0);
            let roots = deflated_roots_in(&c, -3.0, -1.0, 1.0).unwrap();
            assert_eq!(roots.len(), 1, "{small} {large}: {roots:?}");
            assert!(
                (roots[0] - small).abs() <= 1e-9 * small.abs(),
                "{small} {large}: {roots:?}"
            );
        }
    }

    /// The deflated roots are the isolator's, to rounding, whenever they decide.
    #[test]
    fn deflation_agrees_with_isolation() {
        let mut unit = lcg(7);
        let mut decided = 0;
        for _ in 0..20_000 {
            let w = 0.5 + 0.5 * unit();
            let (r2, r3) = (2.4 * unit() - 1.2, 2.4 * unit() - 1.2);
            let c = from_roots([w, r2, r3], 0.3 + unit());
            let hi = 0.45;
            let Some(fast) = deflated_roots_in(&c, w, -1.0, hi) else {
                continue;
            };
            decided += 1;
            let slow = cubic_roots_in(&c, -1.0, hi);
            assert_eq!(
                fast.len(),
                slow.len(),
                "{w} {r2} {r3}: {fast:?} vs {slow:?}"
            );
            for (f, g) in fast.iter().zip(&slow) {
                assert!(
                    (f - g.x).abs() < 1e-9,
                    "{w} {r2} {r3}: {fast:?} vs {slow:?}"
                );
            }
        }
        assert!(decided > 19_000, "{decided}");
    }
}
