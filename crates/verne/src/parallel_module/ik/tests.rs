use super::wrap_angle;
use std::f64::consts::{PI, TAU};

/// The remainder formula the one-turn shortcut of [`wrap_angle`] replaces.
fn by_remainder(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// Within one turn out, the shortcut gives the remainder's result exactly (a zero result
/// always +0); ends and far angles included.
#[test]
fn wrap_angle_one_turn_out_is_the_remainder() {
    let mut unit = crate::math::test_rng::lcg(0x9e37_79b9_7f4a_7c15);
    let mut angles = vec![PI, -PI, 3.0 * PI, -3.0 * PI, TAU, -TAU, 0.0, 1e300, -7.5e3];
    for k in [PI, 3.0 * PI, TAU] {
        angles.extend([k.next_up(), k.next_down(), -k.next_up(), -k.next_down()]);
    }
    angles.extend((0..200_000).map(|_| (unit() - 0.5) * 7.0 * PI));
    for a in angles {
        let w = wrap_angle(a);
        assert!(w > -PI && w <= PI, "{a} -> {w}");
        if a.abs() > PI {
            assert_eq!(w, by_remainder(a), "{a}");
        }
        if w == 0.0 {
            assert!(w.is_sign_positive(), "{a}");
        }
    }
}

// ------------------------------------------------- the solvers against each other on a grid

use super::{IkBranch, solve, working, working_by_cubic};
use crate::certificate::Certificate;
use crate::selftest::hard_sets::random_geometries;
use crate::spec::Machine;
use nalgebra::Vector3;

/// The default machine and four random valid geometries (each dimension within 30 % of the
/// default's, with the variants of [`random_geometries`]).
fn machines() -> Vec<Machine> {
    let mut out = vec![Machine::default_verne()];
    out.extend(random_geometries(4, 27));
    out
}

/// An n x n x n grid over the box the module's workspace lies in, off-centre in each cell (no
/// point on y = 0, where alpha = 0 is a root and the fast paths hand over).
fn grid(n: usize) -> impl Iterator<Item = Vector3<f64>> {
    let lin = move |lo: f64, hi: f64, i: usize| lo + (hi - lo) * (i as f64 + 0.37) / n as f64;
    (0..n * n * n).map(move |k| {
        let (i, j, l) = (k / (n * n), (k / n) % n, k % n);
        Vector3::new(
            lin(-650.0, 450.0, i),
            lin(-550.0, 550.0, j),
            lin(450.0, 1650.0, l),
        )
    })
}

/// Whether the fast path's `found` is the complete solver's working branch `expected`: the same
/// configuration and verdict, alpha within 1e-12 rad and the sliders within 1e-9 mm.
fn same_branch(found: &IkBranch, expected: &IkBranch) -> bool {
    found.config == expected.config
        && found.verdict == expected.verdict
        && (found.alpha - expected.alpha).abs() <= 1e-12
        && (found.rho - expected.rho).amax() <= 1e-9
}

/// `working_by_cubic`, the half of `working_fast` for points the certified lanes hand over (on
/// the default machine only points at its margins, so the other tests barely reach it), called
/// alone: where it answers it gives the complete solver's working branch, and it answers for
/// almost every point that has one (not only the margins hand over).
#[test]
fn working_by_cubic_alone_gives_the_working_branch() {
    for m in machines() {
        let (mut working_points, mut answered) = (0usize, 0usize);
        for p in grid(36) {
            let full = solve(&m, &p);
            let expected = working(&full);
            working_points += expected.is_some() as usize;
            let Some(found) = working_by_cubic(&m, &p) else {
                continue;
            };
            answered += 1;
            let e = expected.unwrap_or_else(|| panic!("{}: {p:?}: {found:?}, no working", m.name));
            assert!(
                same_branch(&found, e),
                "{}: {p:?}: {found:?} vs {e:?}",
                m.name
            );
        }
        assert!(working_points > 2000, "{}: {working_points}", m.name);
        assert!(
            answered * 1000 >= working_points * 999,
            "{}: {answered} of {working_points}",
            m.name
        );
    }
}

/// Points off the degenerate sets (the grid above) have their roots of eq. (9) proved simple in
/// double precision: the certificate is `Double`, no root goes to the factors of leg I (which
/// a bound on the coefficients' error made too large would send them to).
#[test]
fn ordinary_points_are_proved_in_double() {
    for m in machines() {
        for p in grid(24) {
            let c = solve(&m, &p).certificate;
            assert_eq!(c, Certificate::Double, "{}: {p:?}", m.name);
        }
    }
}

/// The bounds on the rounding of eq. (9)'s coefficients are [`super::EQ9_OPS`] ulps of the
/// magnitudes of their formulas, the same magnitudes the double-double transcription
/// ([`super::eq9_tracked`], written from the paper separately) carries, and they hold: the
/// coefficients in double differ from the double-double ones by less, on points near and far,
/// with and without cancellation (x_p = -D1 makes u = 0; the last box reaches 1e5 mm).
#[test]
fn eq9_error_bounds_are_the_magnitudes_and_hold() {
    use super::{EQ9_OPS, eq9_coefficients, eq9_errors, eq9_tracked};
    let mut unit = crate::math::test_rng::lcg(0x5eed_0009);
    let mut worst = 0.0f64;
    for m in machines() {
        let g = &m.module;
        for k in 0..20_000 {
            let span = [1e3, 1e3, 3e3, 1e5][k % 4];
            let mut p = Vector3::new(unit() - 0.5, unit() - 0.5, unit()) * span;
            if k % 7 == 0 {
                p.x = -g.dx1;
            }
            let (c, bound, exact) = (
                eq9_coefficients(g, &p),
                eq9_errors(g, &p),
                eq9_tracked(g, &p),
            );
            for i in 0..4 {
                let mag_bound = EQ9_OPS * f64::EPSILON * exact[i].mag;
                assert!(
                    (bound[i] - mag_bound).abs() <= 1e-12 * mag_bound,
                    "{}: {p:?}: coefficient {i}: bound {:e}, magnitude {:e}",
                    m.name,
                    bound[i],
                    exact[i].mag
                );
                let err = (c[i] - exact[i].v.to_f64()).abs();
                assert!(
                    err <= bound[i],
                    "{}: {p:?}: coefficient {i}: {err:e} > {:e}",
                    m.name,
                    bound[i]
                );
                if bound[i] > 0.0 {
                    worst = worst.max(err / bound[i]);
                }
            }
        }
    }
    eprintln!("worst error / bound: {worst:e}");
}
