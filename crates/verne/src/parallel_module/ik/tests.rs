//! Tests of the parallel module's IK by its parts: each part for what it promises (the fast
//! path's second half alone, the bounds on eq. (9)'s rounding, the order and stopping rule of
//! the steps on leg I, the lanes' start and certificate, the postures at a double root of (9)).

use super::{
    IkBranch, IkBranches, Leg1, Leg1Equations, solve, touching_interval, working, working_by_cubic,
    wrap_angle,
};
use crate::certificate::Certificate;
use crate::machine::ik::machine_ik;
use crate::machine::transforms::tool_pose_eq26;
use crate::parallel_module::branches::Config;
use crate::parallel_module::equations::ModulePose;
use crate::selftest::hard_sets::random_geometries;
use crate::spec::Machine;
use crate::tolerance::NEWTON_STEP_STOP;
use nalgebra::Vector3;
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

/// The default machine and four random valid geometries (each dimension within 30 % of the
/// default's, with the variants of [`random_geometries`]).
fn machines() -> Vec<Machine> {
    let mut out = vec![Machine::default_verne()];
    out.extend(random_geometries(4, 27));
    out
}

/// `m` with its rods free to tilt any way and its strokes unbounded, so that only reach and
/// the rods of leg I crossing refuse a branch (a machine file cannot say this: its rod tilt is
/// at most 90 degrees; a `Machine` built in code can).
fn with_limits_opened(mut m: Machine) -> Machine {
    m.limits.cos_rod_tilt_max = -1.0;
    m.limits.rho_min = [-1e9; 3];
    m.limits.rho_max = [1e9; 3];
    m
}

/// Each of [`machines`] as built and with its limits opened (true).
fn as_built_and_opened() -> impl Iterator<Item = (Machine, bool)> {
    machines()
        .into_iter()
        .flat_map(|m| [(m.clone(), false), (with_limits_opened(m), true)])
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

/// A fast path answered for at least `per_mille` thousandths of the `working_points` (points
/// with a working branch) of machine `m`, of which there were more than `at_least`.
fn assert_answered_most(
    m: &Machine,
    answered: usize,
    working_points: usize,
    at_least: usize,
    per_mille: usize,
) {
    assert!(working_points > at_least, "{}: {working_points}", m.name);
    assert!(
        answered * 1000 >= working_points * per_mille,
        "{}: {answered} of {working_points}",
        m.name
    );
}

/// `working_by_cubic`, the half of `working_fast` for points the certified lanes hand over (on
/// the default machine only points at its margins, so the other tests barely reach it), called
/// alone: where it answers it gives the complete solver's working branch, and it answers for
/// almost every point that has one (not only the margins hand over). On five machines as built
/// and with their limits opened (rods free to tilt, strokes unbounded). With the sign of eq.
/// (14) flipped in its start, the machines as built still pass; the opened default machine
/// then answers for 33,156 of its 34,488 working points (measured), below the 99.9 % asked.
#[test]
fn working_by_cubic_alone_gives_the_working_branch() {
    for (m, _) in as_built_and_opened() {
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
        assert_answered_most(&m, answered, working_points, 2000, 999);
    }
}

/// A point's working branch does not depend on how it is asked for: where [`working_lanes`]
/// answers for the point alone, [`working_fast`] returns that branch and
/// [`super::solve_working_each`] (the points side by side, [`super::LANES`] at a time, as `verne
/// ik` solves a file) gives it too, bit for bit, on five machines (the lanes answer for at
/// least 99 % of the working points of a 24^3 grid; measured: all of them).
#[test]
fn a_point_gets_the_same_bits_alone_and_side_by_side() {
    use super::{IkBranches, solve_working_each, working_fast, working_lanes};
    for m in machines() {
        let points: Vec<Vector3<f64>> = grid(24).collect();
        let mut side_by_side = vec![IkBranches::new(); points.len()];
        solve_working_each(&m, points.iter().copied().zip(side_by_side.iter_mut()));
        let (mut working_points, mut answered) = (0usize, 0usize);
        for (p, got) in points.iter().zip(&side_by_side) {
            working_points += working(got).is_some() as usize;
            let [Some(alone)] = working_lanes(&m, &[*p]) else {
                continue;
            };
            answered += 1;
            assert_eq!(working_fast(&m, p), Some(alone), "{}: {p:?}", m.name);
            assert_eq!(working(got), Some(&alone), "{}: {p:?}", m.name);
        }
        assert_answered_most(&m, answered, working_points, 500, 990);
    }
}

/// The solvers do not depend on the unit of length: each point of a 16^3 grid on five
/// machines, as built and with their limits opened, and the same point on the machine scaled
/// by 2^-10 and by 2^10 (exactly: a power of two), give the same branches with the same
/// configurations and verdicts, alpha and the sliders (relative to 1 + the largest) within
/// 2e-15 (measured: 2.2e-16; most are equal to the bit), from [`solve`] and from
/// [`super::working_fast`]. The sliders of every branch of a 10^3 grid give, by the forward
/// kinematics, the same modes with the same configurations, verdicts and certificate at both
/// scales, the platform point (relative to 1 + its largest coordinate) and alpha within 5e-12
/// (measured: 8.7e-13; its roots of a trigonometric polynomial are less well conditioned). A
/// margin, stop or bound in absolute units that decided otherwise at another scale, or a term
/// of the wrong power of length, would show.
#[test]
fn the_solvers_do_not_depend_on_the_unit_of_length() {
    use super::working_fast;
    use crate::parallel_module::fk;
    let close = |a: &IkBranch, b: &IkBranch, k: f64| {
        a.config == b.config
            && a.verdict == b.verdict
            && (a.alpha - b.alpha).abs() <= 2e-15
            && (a.rho - b.rho / k).amax() <= 2e-15 * (1.0 + a.rho.amax())
    };
    let (mut compared, mut fast, mut modes) = (0, 0, 0);
    for (m, _) in as_built_and_opened() {
        for k in [2f64.powi(-10), 2f64.powi(10)] {
            let scaled = m.scaled(k);
            for p in grid(16) {
                let (one, other) = (solve(&m, &p), solve(&scaled, &(p * k)));
                let at = format!("{} x{k}: {p:?}:\n{one:?}\n{other:?}", m.name);
                assert_eq!(one.len(), other.len(), "{at}");
                for (a, b) in one.iter().zip(other.iter()) {
                    assert!(close(a, b, k), "{at}");
                }
                compared += one.len();
                match (working_fast(&m, &p), working_fast(&scaled, &(p * k))) {
                    (None, None) => {}
                    (Some(a), Some(b)) if close(&a, &b, k) => fast += 1,
                    found => panic!("{at}: {found:?}"),
                }
            }
            for p in grid(10) {
                for rho in solve(&m, &p).iter().map(|b| b.rho) {
                    let (one, other) = (fk::solve(&m, &rho), fk::solve(&scaled, &(rho * k)));
                    let at = format!("{} x{k}: {rho:?}:\n{one:?}\n{other:?}", m.name);
                    assert_eq!(one.certificate, other.certificate, "{at}");
                    assert_eq!(one.len(), other.len(), "{at}");
                    for (a, b) in one.iter().zip(other.iter()) {
                        assert!(a.config == b.config && a.verdict == b.verdict, "{at}");
                        let off = (a.pose.p - b.pose.p / k).amax() / (1.0 + a.pose.p.amax());
                        assert!(off <= 5e-12, "{at}");
                        assert!((a.pose.alpha - b.pose.alpha).abs() <= 5e-12, "{at}");
                    }
                    modes += one.len();
                }
            }
        }
    }
    assert!(
        compared > 100_000 && fast > 1000 && modes > 100_000,
        "{compared} branches, {fast} fast, {modes} modes"
    );
}

/// A point whose leg II (or leg III) is stretched to within h = 1e-3 to 1e-5 mm, or fully (h =
/// 0), or short by rounding noise (the square root's argument -1e-8 mm^2, within
/// [`crate::tolerance::SQRT_ARG_REL`] L^2 of zero): built from a leg-I posture (alpha, rho1) by
/// eqs. (14) and (10), with y set by bisection so that the leg's argument in eq. (12) (or (13))
/// is that. The complete solver finds the branches on that posture with both roots, z -+ R2
/// sin(alpha) -+ h (h = 0 for the last two), on five machines (points built where the other
/// outer leg reaches too): a reachable leg is never called out of reach, however little room it
/// has. Each branch is listed once: where the two roots meet (the argument below zero, h = 0)
/// the leg shows one, labelled -1, not the same branch twice.
#[test]
fn a_stretched_outer_leg_still_reaches() {
    let mut built = [0; 2];
    for m in machines() {
        let mut points = Vec::new();
        let g = &m.module;
        let (r, rr) = (g.r_big1, g.r_small1);
        let k0 = g.l1 * g.l1 - r * r - rr * rr;
        // The stretched leg: its index in a configuration and in the sliders (1: leg II, eq.
        // (12); 2: leg III, eq. (13)), its length, and the sign of R2 in its equation.
        for ((alpha, u_sign), (leg, l, l_other, sign)) in [0.1, 0.25, 0.4, 0.55, -0.3, -0.5]
            .into_iter()
            .flat_map(|a| [(a, 1.0), (a, -1.0)])
            .flat_map(|a| [(a, (1, g.l2, g.l3, -1.0)), (a, (2, g.l3, g.l2, 1.0))])
        {
            let (s, c) = f64::sin_cos(alpha);
            let z = 1000.0;
            // eq. (14) gives z - rho1 from y, eq. (10) u; then the leg's argument of (12) or (13).
            let point = |y: f64| {
                let dz = -y * (r * c - rr) / (r * s);
                let u2 = k0 + 2.0 * r * rr * c - y * y - dz * dz;
                let x = u_sign * u2.max(0.0).sqrt() - g.dx1;
                let arg = l * l - (x + g.dx2).powi(2) - (y + sign * (g.r_big2 * c - g.r4)).powi(2);
                (Vector3::new(x, y, z), z - dz, u2, arg)
            };
            for room in [1e-6f64, 1e-8, 1e-10, 0.0, -1e-8] {
                let h = room.max(0.0).sqrt();
                // The first change of sign of arg - room along y, where leg I reaches.
                let excess = |y: f64| {
                    let (_, _, u2, arg) = point(y);
                    (u2 > 1.0).then_some(arg - room)
                };
                let bracket =
                    (-1500..1500)
                        .map(f64::from)
                        .find_map(|y| match (excess(y), excess(y + 1.0)) {
                            (Some(a), Some(b)) if (a < 0.0) != (b < 0.0) => {
                                Some((y, y + 1.0, a < 0.0))
                            }
                            _ => None,
                        });
                let Some((mut lo, mut hi, lo_negative)) = bracket else {
                    continue;
                };
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if (excess(mid).unwrap() < 0.0) == lo_negative {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let (p, rho1, _, _) = point(lo);
                let dy_other = p.y - sign * (g.r_big2 * c - g.r4);
                if l_other * l_other - (p.x + g.dx2).powi(2) - dy_other * dy_other < 1.0 {
                    continue; // the other outer leg cannot reach: no branch on this posture
                }
                built[leg - 1] += 1;
                points.push(p);
                // Both roots of (12) or (13) on the posture, each with (rho - off)^2 = h^2 to
                // the rounding of the square root's argument (terms of L^2, here and in the
                // test's construction: 64 eps L^2, about 1.3e-8 mm^2).
                let off = z + sign * g.r_big2 * s;
                let full = solve(&m, &p);
                let on_posture: Vec<&IkBranch> = full
                    .iter()
                    .filter(|b| (b.alpha - alpha).abs() < 1e-9 && (b.rho.x - rho1).abs() < 1e-6)
                    .collect();
                let rho: Vec<f64> = on_posture.iter().map(|b| b.rho[leg]).collect();
                let what = format!("{}: {p:?}, h {h:e}: {full:?}", m.name);
                let configs: Vec<Config> = on_posture.iter().map(|b| b.config).collect();
                assert_each_once(&configs, (room < 0.0).then_some(leg), &what);
                if room < 0.0 {
                    // The machine's branches at that module pose (theta1 = theta2 = 0, the tool
                    // pose by eq. (26)): the same, once each.
                    let module = ModulePose { p, alpha };
                    let pose = tool_pose_eq26(&m.table, &module, 0.0, 0.0, m.tool_length);
                    let machine = machine_ik(&m, &pose, m.tool_length);
                    let configs: Vec<Config> = machine
                        .iter()
                        .filter(|b| {
                            b.theta1.abs() < 1e-9
                                && (b.alpha - alpha).abs() < 1e-9
                                && (b.rho.x - rho1).abs() < 1e-6
                        })
                        .map(|b| b.config)
                        .collect();
                    assert!(!configs.is_empty(), "{what}: machine {machine:?}");
                    let what = format!("{what}: machine {machine:?}");
                    assert_each_once(&configs, Some(leg), &what);
                }
                let root = |below: bool| {
                    rho.iter().any(|&r| {
                        ((r - off).powi(2) - h * h).abs() <= 64.0 * f64::EPSILON * l * l
                            && (if below {
                                r <= off + 1e-9
                            } else {
                                r >= off - 1e-9
                            })
                    })
                };
                assert!(
                    root(true) && root(false),
                    "{}: {p:?}, leg {leg}, h {h:e}: {off} -+ h not in {full:?}",
                    m.name
                );
            }
        }
        // A file's points, four side by side (the lanes' branches), give the same lists.
        for baseline in [false, true] {
            let mut lists = vec![IkBranches::new(); points.len()];
            let rows = points.iter().copied().zip(lists.iter_mut());
            if baseline {
                super::solve_each_baseline(&m, rows);
            } else {
                super::solve_each(&m, rows);
            }
            for (p, list) in points.iter().zip(&lists) {
                assert_eq!(list[..], solve(&m, p)[..], "{}: {p:?}", m.name);
            }
        }
    }
    assert!(built[0] >= 100 && built[1] >= 100, "{built:?}");
}

/// No two of one posture's branches share a configuration (each branch once), and where the
/// two roots of an outer leg meet (`meets`: 1 for leg II, 2 for leg III) it shows only -1.
fn assert_each_once(configs: &[Config], meets: Option<usize>, what: &str) {
    for (k, c) in configs.iter().enumerate() {
        assert!(!configs[..k].contains(c), "{c:?} twice: {what}");
        assert!(meets.is_none_or(|leg| c[leg] == -1), "{c:?}: {what}");
    }
}

/// Every branch's alpha is in (-pi, pi], also at and next to alpha = pi: at y_p = 0 eq. (9) is
/// (c^2 - 1) (2 R1^3 r1 c + R1^2 (k0 - u^2)) (k0 = L1^2 - R1^2 - r1^2, u = x_p + D1 - d1), so
/// cos(alpha) = -1 is a root for every point, and a polish from alpha = pi, or the mirror image
/// of a posture there, lands on either side of the turn.
#[test]
fn alpha_stays_in_the_half_open_turn_next_to_pi() {
    let mut near_pi = 0;
    for m in machines() {
        let g = &m.module;
        for x in [-200.0, -80.0, 0.0, 60.0, 150.0].map(|v| v - g.dx1) {
            for y in [0.0, 1e-12, -1e-12, 1e-10, -1e-10, 1e-8, -1e-8, 1e-6, -1e-6] {
                let p = Vector3::new(x, y, 1000.0);
                for b in &solve(&m, &p) {
                    assert!(b.alpha > -PI && b.alpha <= PI, "{}: {p:?}: {b:?}", m.name);
                    near_pi += (PI - b.alpha.abs() < 1e-3) as usize;
                }
            }
        }
    }
    assert!(near_pi >= 100, "{near_pi} branches next to alpha = pi");
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

/// The public cubic of eq. (9) is the coefficients divided by the largest magnitude (the same
/// ratios, the largest 1); none for a point that is not finite (z_p is not in eq. (9), and with
/// NaN in x_p the coefficients of y_p alone stay finite, so the coefficients do not tell) nor
/// for one so far that the coefficients overflow.
#[test]
fn cubic_eq9_is_normalised_and_refuses_a_point_not_finite() {
    use super::{cubic_eq9, eq9_coefficients};
    for m in machines() {
        let g = &m.module;
        for p in grid(6) {
            let (c, cubic) = (eq9_coefficients(g, &p), cubic_eq9(g, &p).expect("a cubic"));
            let largest = cubic.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            assert_eq!(largest, 1.0, "{}: {p:?}: {cubic:?}", m.name);
            let scale = c.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            assert_eq!(cubic, c.map(|a| a / scale), "{}: {p:?}", m.name);
        }
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for i in 0..3 {
                let mut p = Vector3::new(-250.0, 100.0, 1000.0);
                p[i] = bad;
                assert_eq!(cubic_eq9(g, &p), None, "{}: {p:?}", m.name);
            }
        }
        for far in [
            Vector3::new(1e200, 0.0, 0.0),
            Vector3::new(0.0, -1e200, 0.0),
        ] {
            assert_eq!(cubic_eq9(g, &far), None, "{}: {far:?}", m.name);
        }
    }
}

// ------------------------------------------------------------- Newton's and Chebyshev's steps

/// A point and one of its leg-I postures.
type PointPosture = (Vector3<f64>, Leg1);

/// Every leg-I posture (alpha, rho1) of the points of an n-grid on the machines, from the
/// complete solver (polished to rounding), with its point; postures whose Jacobian in (alpha,
/// rho1) is ill-conditioned (|det| below 1e-3 of its scale: near a fold, where no step
/// converges fast) are left out.
fn leg1_roots(n: usize) -> Vec<(Machine, Vec<PointPosture>)> {
    machines()
        .into_iter()
        .map(|m| {
            let g = &m.module;
            let mut out: Vec<PointPosture> = Vec::new();
            for p in grid(n) {
                let branches = solve(&m, &p);
                for b in branches.iter().step_by(4) {
                    let (sin, cos) = b.alpha.sin_cos();
                    let l = Leg1 {
                        alpha: b.alpha,
                        rho1: b.rho.x,
                        sin,
                        cos,
                    };
                    let (r, rr, dz) = (g.r_big1, g.r_small1, p.z - l.rho1);
                    // det of the Jacobian (2 R1 r1 s, -2 dz; -y R1 s + R1 c dz, -R1 s).
                    let det =
                        -2.0 * r * r * rr * sin * sin + 2.0 * dz * (-p.y * r * sin + r * cos * dz);
                    let scale = r * r * rr + dz * dz * r + p.y.abs() * r * dz.abs();
                    if det.abs() > 1e-3 * scale {
                        out.push((p, l));
                    }
                }
            }
            (m, out)
        })
        .collect()
}

/// The postures at alpha = 0 of points on y = 0 (Table II: eq. (14) holds there for every
/// rho1), from the complete solver, with their points: at least a hundred on each machine.
fn table_ii_postures(m: &Machine) -> Vec<PointPosture> {
    let mut postures: Vec<PointPosture> = Vec::new();
    for p in grid(10).map(|p| Vector3::new(p.x, 0.0, p.z)) {
        for b in solve(m, &p).iter().step_by(4).filter(|b| b.alpha == 0.0) {
            let l = Leg1 {
                alpha: 0.0,
                rho1: b.rho.x,
                sin: 0.0,
                cos: 1.0,
            };
            postures.push((p, l));
        }
    }
    assert!(postures.len() > 100, "{}: {}", m.name, postures.len());
    postures
}

/// `l` moved by (da, dr) with its sin and cos.
fn moved(l: &Leg1, da: f64, dr: f64) -> Leg1 {
    let alpha = l.alpha + da;
    let (sin, cos) = alpha.sin_cos();
    Leg1 {
        alpha,
        rho1: l.rho1 + dr,
        sin,
        cos,
    }
}

/// Distance of `l` from the root `root`: (rad, mm).
fn off(l: &Leg1, root: &Leg1) -> (f64, f64) {
    ((l.alpha - root.alpha).abs(), (l.rho1 - root.rho1).abs())
}

/// Whether `l` is within the polish's stopping rule of `root` (both postures settled: each
/// within [`NEWTON_STEP_STOP`] of the exact posture, rounding included).
fn within_stop(l: &Leg1, root: &Leg1) -> bool {
    let (ea, er) = off(l, root);
    ea <= 3.0 * NEWTON_STEP_STOP && er <= 3.0 * NEWTON_STEP_STOP * (1.0 + root.rho1.abs())
}

/// The start moved from each root by `d` rad and -70 `d` mm (both unknowns off, neither
/// dominating), and the largest distance (rad, or mm / 100) of what `step` makes of it.
fn worst_after_one_step(d: f64, step: impl Fn(&Leg1Equations, &Leg1) -> Option<Leg1>) -> f64 {
    let mut worst = 0.0f64;
    for (m, roots) in leg1_roots(14) {
        for (p, root) in &roots {
            let eqs = Leg1Equations::new(&m.module, p);
            let next = step(&eqs, &moved(root, d, -70.0 * d)).expect("a step");
            let (ea, er) = off(&next, root);
            worst = worst.max(ea.max(er / 100.0));
        }
    }
    worst
}

/// Chebyshev's step as [`steps_to_settle`] takes it (the posture must stay usable).
fn chebyshev_step(eqs: &Leg1Equations, l: &Leg1) -> Option<(Leg1, bool)> {
    let step = eqs.corrected_step(l);
    step.usable.then_some((step.leg1, step.settled))
}

/// Newton's step as [`steps_to_settle`] takes it.
fn newton_step(eqs: &Leg1Equations, l: &Leg1) -> Option<(Leg1, bool)> {
    let (f, dz) = eqs.residuals(l);
    eqs.newton_step(l, f, dz)
        .map(|step| (step.leg1, step.settled))
}

/// Newton's step on eqs. (10) and (14) is of order two: from d = 1e-3 and 1e-4 rad (and 70 d
/// mm) off a root (about 27,000 postures on five machines), at most 5 d^2 off after it
/// (measured: 1.1 d^2 worst); a step with a wrong Jacobian would be of order one (about d).
#[test]
fn newton_step_on_leg1_is_of_order_two() {
    for d in [1e-3, 1e-4] {
        let worst = worst_after_one_step(d, |e, l| newton_step(e, l).map(|(next, _)| next));
        assert!(worst <= 5.0 * d * d, "{d:e}: {worst:e}");
    }
}

/// Chebyshev's corrected step is of order three (measured: 2.5e-6 worst at 1e-2, 2.4e-9 at
/// 1e-3): at most 5 d^3 off, where Newton's step (order two, above) is about d^2 / 2.
#[test]
fn chebyshev_step_on_leg1_is_of_order_three() {
    for d in [1e-2, 1e-3] {
        let worst = worst_after_one_step(d, |e, l| chebyshev_step(e, l).map(|(next, _)| next));
        assert!(worst <= 5.0 * d * d * d, "{d:e}: {worst:e}");
    }
}

/// Each step's prediction of the error it leaves (`Leg1Step::left`, which its stopping rule
/// compares with the step stop) is that error's leading term: Newton's from d = 1e-3 and 1e-4
/// rad (and 70 d mm) off a root, Chebyshev's from 1e-2 and 1e-3 (about 27,000 postures on five
/// machines; the errors left far above the roots' rounding), each unknown is within its
/// prediction but for the next order's (1 + 4 d; measured at most 1 + 1.7 d), and on the
/// worst posture the error is at least 0.9 of it, in each unknown (measured 0.978 to 1.017:
/// the prediction is sharp in both). The same, bound and sharpness, on the machines scaled by
/// 1e-2 and by 1e2, each scale asserted alone (points, rho1 and the start's offset with it; leg
/// I's equations are homogeneous in length, so the errors are the same in rad and scale in mm),
/// where a term with lengths of the wrong power (a product made a sum) no longer passes for the
/// right one.
#[test]
fn leg1_steps_predict_the_error_they_leave() {
    let cases = [(false, 1e-3), (false, 1e-4), (true, 1e-2), (true, 1e-3)];
    let roots = leg1_roots(14);
    for k in [1.0, 1e-2, 1e2] {
        let mut worst = [[0.0f64; 2]; 4];
        for (m, roots) in &roots {
            let g = m.module.scaled(k);
            for (p, root) in roots {
                let (p, root) = (
                    p * k,
                    Leg1 {
                        rho1: root.rho1 * k,
                        ..*root
                    },
                );
                let eqs = Leg1Equations::new(&g, &p);
                for ((chebyshev, d), worst) in cases.into_iter().zip(&mut worst) {
                    let start = moved(&root, d, -70.0 * d * k);
                    let step = if chebyshev {
                        eqs.corrected_step(&start)
                    } else {
                        let (f, dz) = eqs.residuals(&start);
                        eqs.newton_step(&start, f, dz).expect("a step")
                    };
                    let (ea, er) = off(&step.leg1, &root);
                    let ratio = [ea / step.left[0], er / step.left[1]];
                    assert!(
                        ratio[0].max(ratio[1]) <= 1.0 + 4.0 * d,
                        "x{k}: {p:?} from {start:?}: {ea:e} rad, {er:e} mm left, {:?} predicted",
                        step.left
                    );
                    *worst = [worst[0].max(ratio[0]), worst[1].max(ratio[1])];
                }
            }
        }
        for ((chebyshev, d), worst) in cases.into_iter().zip(worst) {
            assert!(
                worst.into_iter().all(|w| w >= 0.9),
                "x{k}: Chebyshev {chebyshev}, {d:e}: {worst:?}"
            );
        }
    }
}

/// How many of `step` it takes from `start` until one says settled (at most eight); every
/// posture said settled is checked within the stopping rule of `root`.
fn steps_to_settle(
    eqs: &Leg1Equations,
    start: Leg1,
    root: &Leg1,
    step: fn(&Leg1Equations, &Leg1) -> Option<(Leg1, bool)>,
    at: &dyn Fn() -> String,
) -> usize {
    let mut cur = start;
    for n in 1..=8 {
        let (next, settled) = step(eqs, &cur).unwrap_or_else(|| panic!("step {n}: {}", at()));
        cur = next;
        if settled {
            assert!(within_stop(&cur, root), "step {n}: {cur:?}: {}", at());
            return n;
        }
    }
    panic!("not settled in 8 steps: {}", at());
}

/// Both steps say `settled` only within the stopping rule of the root, from starts 1e-2 to
/// 1e-14 off it, and they settle as soon as their order allows (the counts measured on these
/// postures; one more is a polish that missed its prediction of the next step): Chebyshev's
/// within two steps of 1e-2 (the lanes allow [`super::LEG1_MAX_STEPS`]), Newton's within four
/// of 1e-2 and three of 1e-3 (the polish allows [`crate::tolerance::NEWTON_MAX_ITER`]), both
/// at once from 1e-9 and closer. The same with one unknown alone off (the other's first step
/// is then of the next order, so a step that settled on that step alone would stop short),
/// but for Chebyshev's three steps from rho1 alone 0.7 mm off.
#[test]
fn leg1_steps_settle_only_at_the_root_and_soon() {
    // (distance, Chebyshev's steps, Newton's steps; Chebyshev's with one unknown alone off)
    let cases = [
        (1e-2, 2, 4, 3),
        (1e-3, 2, 3, 2),
        (1e-5, 2, 2, 2),
        (1e-7, 1, 2, 1),
        (1e-9, 1, 1, 1),
        (1e-11, 1, 1, 1),
        (1e-13, 1, 1, 1),
        (1e-14, 1, 1, 1),
        (0.0, 1, 1, 1),
    ];
    for (m, roots) in leg1_roots(10) {
        for (p, root) in &roots {
            let eqs = Leg1Equations::new(&m.module, p);
            for (d, chebyshev, newton, chebyshev_one_off) in cases {
                let at = || format!("{}: {p:?} {root:?}, {d:e} off", m.name);
                let start = moved(root, d, -70.0 * d);
                let n = steps_to_settle(&eqs, start, root, chebyshev_step, &at);
                assert!(n <= chebyshev, "{} steps: {}", n, at());
                let n = steps_to_settle(&eqs, start, root, newton_step, &at);
                assert!(n <= newton, "Newton, {} steps: {}", n, at());
                for start in [moved(root, d, 0.0), moved(root, 0.0, -70.0 * d)] {
                    let n = steps_to_settle(&eqs, start, root, chebyshev_step, &at);
                    assert!(n <= chebyshev_one_off, "{} steps, one off: {}", n, at());
                    let n = steps_to_settle(&eqs, start, root, newton_step, &at);
                    assert!(n <= newton, "Newton, {} steps, one off: {}", n, at());
                }
            }
        }
    }
}

/// Each step settles by its stopping rule, read from what it returns: Newton's exactly when
/// both predicted errors (`left`) are within [`super::PREDICTED_STEP_FRACTION`] of their stops
/// (NEWTON_STEP_STOP, and that times 1 + |rho1| in mm), its small-step exit (no prediction,
/// `left` zero) only on a step below both stops; Chebyshev's whenever its predictions are
/// within them, otherwise only on a step below both stops. From starts 1e-2 to 1e-14 off the
/// roots (four to a decade), both unknowns or one alone; each test decides alone somewhere (the
/// counts asserted).
#[test]
fn each_step_settles_by_its_stopping_rule() {
    use super::PREDICTED_STEP_FRACTION as FRACTION;
    // Newton: [alpha's prediction alone over, rho1's alone over, the small-step exit];
    // Chebyshev: [alpha's alone over, rho1's alone over] (on these starts it never settles on
    // the step alone: its predictions are within the stops first).
    let (mut newton, mut chebyshev) = ([0usize; 3], [0usize; 2]);
    for (m, roots) in leg1_roots(8) {
        for (p, root) in &roots {
            let eqs = Leg1Equations::new(&m.module, p);
            for k in 0..=48 {
                let d = 10f64.powf(-2.0 - 0.25 * f64::from(k));
                for start in [
                    moved(root, d, -70.0 * d),
                    moved(root, d, 0.0),
                    moved(root, 0.0, -70.0 * d),
                ] {
                    let at = format!("{}: {p:?} from {start:?}", m.name);
                    let (f, dz) = eqs.residuals(&start);
                    let steps = [
                        eqs.newton_step(&start, f, dz).expect("a step"),
                        eqs.corrected_step(&start),
                    ];
                    for (is_chebyshev, step) in [false, true].into_iter().zip(&steps) {
                        let rho_stop = NEWTON_STEP_STOP * (1.0 + step.leg1.rho1.abs());
                        let over = [
                            step.left[0] > FRACTION * NEWTON_STEP_STOP,
                            step.left[1] > FRACTION * rho_stop,
                        ];
                        let (da, dr) = off(&step.leg1, &start);
                        // The step taken, to the rounding of the subtraction that applied it.
                        let ulps = |x: f64| 4.0 * f64::EPSILON * (1.0 + x.abs());
                        let small = da <= NEWTON_STEP_STOP + ulps(start.alpha)
                            && dr <= rho_stop + ulps(start.rho1);
                        if !is_chebyshev {
                            assert_eq!(step.settled, over == [false; 2], "Newton: {at}");
                            if step.left == [0.0; 2] {
                                assert!(small, "Newton, {da:e} rad, {dr:e} mm: {at}");
                                newton[2] += 1;
                            } else if over[0] != over[1] {
                                newton[usize::from(over[1])] += 1;
                            }
                        } else if over != [false; 2] {
                            assert!(!step.settled || small, "Chebyshev: {at}");
                            if over[0] != over[1] {
                                chebyshev[usize::from(over[1])] += 1;
                            }
                        } else {
                            assert!(step.settled, "Chebyshev: {at}");
                        }
                    }
                }
            }
        }
    }
    eprintln!("Newton {newton:?}, Chebyshev {chebyshev:?}");
    assert!(
        newton.iter().chain(&chebyshev).all(|&k| k > 10),
        "{newton:?} {chebyshev:?}"
    );
}

/// On y = 0 from Table II's starts with rho1 alone off by 1e-9 to 10 mm (alpha = 0: eq. (14)
/// holds for every rho1, and neither step moves alpha, so a step that settled on alpha's step
/// alone would stop short), both steps say `settled` only within the stopping rule of the
/// posture, in at most three steps from 1e-3 mm (and eight from 10 mm).
#[test]
fn leg1_steps_from_table_ii_starts_settle_only_at_the_root() {
    for m in machines() {
        for (p, root) in &table_ii_postures(&m) {
            let eqs = Leg1Equations::new(&m.module, p);
            for d in [10.0, -1.0, 1e-3, -1e-6, 1e-9] {
                let at = || format!("{}: {p:?} {root:?}, rho1 {d:e} off", m.name);
                let start = moved(root, 0.0, d);
                let limit = if d.abs() <= 1e-3 { 3 } else { 8 };
                assert!(steps_to_settle(&eqs, start, root, chebyshev_step, &at) <= limit);
                assert!(steps_to_settle(&eqs, start, root, newton_step, &at) <= limit);
            }
        }
    }
}

/// The start of the lanes' Chebyshev steps ([`super::estimated_start`], eq. (14) about alpha =
/// 0 to third order, solved by one correction) is of order four: for the certified posture of
/// every grid point with |alpha| < 0.2 on five machines, its alpha (and rho1 / 1000 mm) is
/// within 2 alpha^4 of it (measured: 1.1 alpha^4 worst); beyond, of the posture's sign and
/// within the clamp at +-0.24. Not usable at y = 0 and within [`super::FAST_MARGIN_MM`] of it, nor
/// where leg I cannot reach at alpha = 0; usable everywhere else.
#[test]
fn estimated_start_is_of_order_four() {
    use super::{FAST_MARGIN_MM, certified_lanes, estimated_start, leg1_height_sq};
    for m in machines() {
        let g = &m.module;
        let mut checked = 0;
        for p in grid(30) {
            let (start, usable) = estimated_start(g, &p);
            assert_eq!(
                usable,
                leg1_height_sq(g, &p, 1.0) > 0.0,
                "{}: {p:?}",
                m.name
            );
            let ([leg], [sure]) = certified_lanes(&m, &[p]);
            if !sure {
                continue;
            }
            let a = leg.alpha.abs();
            if a < 0.2 {
                let e = (start.alpha - leg.alpha)
                    .abs()
                    .max((start.rho1 - leg.rho1).abs() / 1e3);
                assert!(
                    e <= 2.0 * a.powi(4),
                    "{}: {p:?}: {start:?} vs {leg:?}",
                    m.name
                );
                checked += 1;
            } else {
                let (s, l) = (start.alpha, leg.alpha);
                assert!(
                    s.abs() <= 0.24 && s * l > 0.0,
                    "{}: {p:?}: {s} vs {l}",
                    m.name
                );
            }
            let (sin, cos) = start.alpha.sin_cos();
            assert!((start.sin - sin).abs() <= 3e-16 && (start.cos - cos).abs() <= 3e-16);
        }
        assert!(checked > 5000, "{}: {checked}", m.name);
        let p = Vector3::new(-200.0, 0.0, 1000.0);
        assert!(leg1_height_sq(g, &p, 1.0) > 0.0);
        for y in [0.0, 0.5 * FAST_MARGIN_MM, -0.99 * FAST_MARGIN_MM] {
            assert!(
                !estimated_start(g, &Vector3::new(p.x, y, p.z)).1,
                "{}: {y}",
                m.name
            );
        }
        assert!(estimated_start(g, &Vector3::new(p.x, 1.01 * FAST_MARGIN_MM, p.z)).1);
    }
}

/// A machine (as a file can give it) whose working posture lies far from the lanes' start: the
/// eighth of `random_geometries(30, 5)`, rounded to 0.01 mm, with its rods free to tilt to 90
/// degrees and strokes wide enough for every branch; and a point of it, whose working posture
/// is at alpha = 0.77 rad.
fn far_from_the_start() -> (Machine, Vector3<f64>) {
    let text = "kind = \"verne\"\nname = \"far from the start\"\n\n[module]\n\
        D1 = -277.24\nd1 = 0.0\nR1 = 138.2\nr1 = 58.82\nL1 = 667.72\n\
        D2 = 274.57\nd2 = 0.0\nR2 = 310.25\nr4 = 684.55\nL2 = 1132.75\nL3 = 1176.81\n\n\
        [limits]\nrho1_min = -2000\nrho1_max = 3000\nrho2_min = -2000\nrho2_max = 3000\n\
        rho3_min = -2000\nrho3_max = 3000\nrod_tilt_max = 90\ntheta1_min = -45\ntheta1_max = 45\n\n\
        [table]\nd_a = 1400\nd_t = -150\n\n[tool]\nlength = 50\n";
    let m = Machine::from_toml_str(text, "far from the start").expect("a valid machine");
    (m, Vector3::new(-19.88, -543.22, 497.4))
}

/// A first Chebyshev step longer than the sin/cos series allows ([`super::SMALL_ANGLE`]) ends
/// the lanes' certificate: the point is handed over, and its working branch comes from the
/// cubic all the same. At the point of [`far_from_the_start`] the start is at alpha = -0.12 rad,
/// 0.9 rad from the working posture, and the first step, about 5 rad long, leaves sin and cos
/// off the unit circle by more than 0.1; the steps after it settle there, on a posture that
/// passes every other test of the lanes (the margins, the isolated root, a feasible lower
/// branch), with a branch that is not the working one. Only that first step's `usable` keeps
/// the lanes from answering with it.
#[test]
fn a_first_step_beyond_the_series_is_handed_over() {
    use super::{
        LEG1_MAX_STEPS, SMALL_ANGLE, certified_lanes, clear_of_margins, estimated_start,
        isolated_working_root, lower_branch, solve_working_each, working_fast, working_lanes,
    };
    use crate::parallel_module::branches::cos_tilt_max;
    let (m, p) = far_from_the_start();
    let g = &m.module;
    // The working branch from the roots of the cubic (9), without the lanes.
    let expected = working_by_cubic(&m, &p).expect("a working branch");
    assert!((expected.alpha - 0.77).abs() < 0.01, "{expected:?}");
    // What the steps do when a step beyond the series is not stopped.
    let (start, usable) = estimated_start(g, &p);
    assert!(usable && (start.alpha + 0.12).abs() < 0.01, "{start:?}");
    let eqs = Leg1Equations::new(g, &p);
    let first = eqs.corrected_step(&start);
    assert!(
        !first.usable && (start.alpha - first.leg1.alpha).abs() > SMALL_ANGLE,
        "{first:?}"
    );
    let (mut leg, mut settled) = (first.leg1, first.settled);
    for _ in 1..LEG1_MAX_STEPS {
        if settled {
            break;
        }
        let step = eqs.corrected_step(&leg);
        assert!(step.usable, "{step:?}");
        (leg, settled) = (step.leg1, step.settled);
    }
    assert!((leg.sin.hypot(leg.cos) - 1.0).abs() > 0.1, "{leg:?}");
    assert!(settled && clear_of_margins(g, &p, &leg) && isolated_working_root(&m, &p));
    let lower = lower_branch(&m, &p, &leg, cos_tilt_max(&m));
    assert!(lower.feasible && !lower.close_call, "{lower:?}");
    assert!(!same_branch(&lower.branch, &expected), "{lower:?}");
    // The lanes hand the point over, in every lane; the working branch comes all the same, by
    // every way of asking.
    assert!(!certified_lanes(&m, &[p]).1[0]);
    assert_eq!(working_lanes(&m, &[p; 4]), [None; 4]);
    let fast = working_fast(&m, &p).expect("the working branch");
    assert!(same_branch(&fast, &expected), "{fast:?} vs {expected:?}");
    let all = solve(&m, &p);
    let found = working(&all).expect("the working branch");
    assert!(same_branch(found, &expected), "{found:?} vs {expected:?}");
    let mut got = vec![IkBranches::new(); 5];
    solve_working_each(&m, [p; 5].into_iter().zip(got.iter_mut()));
    for branches in &got {
        let found = working(branches).expect("the working branch");
        assert!(same_branch(found, &expected), "{found:?} vs {expected:?}");
    }
}

// ------------------------------------------------------------ the certificate of the lanes

/// The certificate that the cubic (9) has at most one root with cos(alpha) in [r1/R1, 1]
/// ([`super::isolated_working_root`]), against the cubic's derivative sampled at 2,001 points
/// of the interval: where the derivative keeps one sign with a clear margin (ten times the
/// certificate's) the certificate is given, and where it changes sign it is not; on five
/// machines, points of each kind are met (decreasing, increasing, not monotone). The test of
/// the derivative at its vertex never decides: the derivative at r1/R1 is negative whenever
/// the vertex x_v = -c2 / (3 c3) lies past it (d(lo) = 3 c3 lo (lo - 2 x_v) + c1 with lo >= 0,
/// c3 > 0 and c1 = -2 R1 r1 (R1^2 + y^2) < 0), which every point checks.
#[test]
fn isolated_working_root_certifies_exactly_the_monotone_cubics() {
    use super::{FAST_MARGIN_RAD, MONOTONE_MARGIN, eq9_coefficients, isolated_working_root};
    let mut kinds = [0usize; 3];
    for m in machines() {
        let g = &m.module;
        let lo = (g.r_small1 / g.r_big1 - FAST_MARGIN_RAD).max(-1.0);
        for p in grid(30).chain(grid(7).map(|p| p * 3.0)) {
            let [c0, c1, c2, c3] = eq9_coefficients(g, &p);
            let margin = MONOTONE_MARGIN * c0.abs().max(c1.abs()).max(c2.abs()).max(c3.abs());
            let d = |x: f64| (3.0 * c3 * x + 2.0 * c2) * x + c1;
            let samples: Vec<f64> = (0..=2000)
                .map(|i| d(lo + (1.0 - lo) * i as f64 / 2000.0))
                .collect();
            let (min, max) = samples
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            let certified = isolated_working_root(&m, &p);
            let vertex_inside = -c2 / (3.0 * c3) > lo && -c2 / (3.0 * c3) < 1.0;
            assert!(!vertex_inside || d(lo) < 0.0, "{}: {p:?}", m.name);
            let at = format!(
                "{}: {p:?}: derivative in [{min:e}, {max:e}], margin {margin:e}",
                m.name
            );
            if max < -10.0 * margin {
                assert!(certified, "{at}");
                kinds[0] += 1;
            } else if min > 10.0 * margin {
                assert!(certified && !vertex_inside, "{at}");
                kinds[1] += 1;
            } else if min < -margin && max > margin {
                assert!(!certified, "{at}");
                kinds[2] += 1;
            }
        }
    }
    eprintln!("decreasing, increasing, not monotone: {kinds:?}");
    assert!(kinds.iter().all(|&k| k > 0), "{kinds:?}");
}

/// The lanes' certificate decides only with the cubic's derivative beyond its margin at both
/// ends of [r1/R1, 1] (1e-9 of the largest coefficient, on the same side of zero): points built
/// with the derivative at one end t times the margin, t = +-0.5 and +-2, and the other end at
/// least 10 margins away, are certified exactly when |t| > 1 and the two ends agree in sign.
/// (Where the derivative is zero at r1/R1 it is 2 R1^2 (1 - r1/R1) (R1^2 + 3 R1 r1 + y^2) > 0 at
/// 1, so the increasing test decides at the first end and the decreasing one at the second.)
#[test]
fn the_lanes_certificate_needs_its_margin_at_both_ends() {
    use super::{FAST_MARGIN_RAD, MONOTONE_MARGIN, eq9_coefficients, isolated_working_root};
    let mut unit = crate::math::test_rng::lcg(0x005e_ed0f_ca57);
    let mut decided = [[0usize; 2]; 2]; // [certified, not] for each end
    for m in machines() {
        let g = &m.module;
        let lo = (g.r_small1 / g.r_big1 - FAST_MARGIN_RAD).max(-1.0);
        let slope = |p: &Vector3<f64>, x: f64| {
            let [_, c1, c2, c3] = eq9_coefficients(g, p);
            (3.0 * c3 * x + 2.0 * c2) * x + c1
        };
        let margin_at = |p: &Vector3<f64>| {
            let c = eq9_coefficients(g, p);
            MONOTONE_MARGIN * c.iter().fold(0.0f64, |a, b| a.max(b.abs()))
        };
        for (end, (x, other)) in [(lo, 1.0), (1.0, lo)].into_iter().enumerate() {
            let (_, d) = eq9_in_u_and_y(&m, x);
            for _ in 0..200 {
                let y2 = (50.0 + 500.0 * unit()).powi(2);
                for t in [-2.0, -0.5, 0.5, 2.0] {
                    // F'(x) = d0 + U d1 + Y d2 = t margin, the margin taken at the last point.
                    let mut p = Vector3::new(0.0, y2.sqrt(), 1000.0);
                    let mut u2 = -1.0;
                    for _ in 0..4 {
                        u2 = (t * margin_at(&p) - d[0] - y2 * d[2]) / d[1];
                        p.x = u2.max(0.0).sqrt() - g.dx1;
                    }
                    let (here, there, margin) = (slope(&p, x), slope(&p, other), margin_at(&p));
                    let [_, _, c2, c3] = eq9_coefficients(g, &p);
                    let vertex = -c2 / (3.0 * c3);
                    if u2 < 0.0 || there.abs() < 10.0 * margin || (vertex > lo && vertex < 1.0) {
                        continue;
                    }
                    assert!(
                        (here / margin - t).abs() < 1e-3,
                        "{}: {p:?} {here:e}",
                        m.name
                    );
                    let expected = t.abs() > 1.0 && (t > 0.0) == (there > 0.0);
                    assert_eq!(
                        isolated_working_root(&m, &p),
                        expected,
                        "{}: {p:?}: slope {t} margins at {x}, {there:e} at {other}",
                        m.name
                    );
                    decided[end][usize::from(!expected)] += 1;
                }
            }
        }
    }
    eprintln!("[certified, not] at r1/R1, at 1: {decided:?}");
    assert!(decided.iter().flatten().all(|&k| k > 50), "{decided:?}");
}

/// Every leg-I posture of `p` as [`super::solve_into`] finds them, with the certificate.
fn leg1_postures(m: &Machine, p: &Vector3<f64>) -> (arrayvec::ArrayVec<Leg1, 6>, Certificate) {
    use super::{certified_lanes, leg1_postures_into, other_roots};
    let ([leg1], [certified]) = certified_lanes(m, &[*p]);
    let certified = certified.then_some(leg1);
    let roots = other_roots(&m.module, p, certified);
    let mut out = arrayvec::ArrayVec::new();
    let certificate = leg1_postures_into(&m.module, p, &roots, certified, &mut out);
    (out, certificate)
}

/// Eq. (9) at cos(alpha) = c0 as linear functions of U = u^2 and Y = y^2 (z_p enters neither
/// it nor leg I's height): F(c0) = f[0] + U f[1] + Y f[2] and F'(c0) = d[0] + U d[1] + Y d[2],
/// from F(c) = 2 R1^3 r1 c^3 + R1^2 (k0 - U) c^2 - 2 R1 r1 (R1^2 + Y) c + R1^2 U
/// + (R1^2 + r1^2) Y - R1^2 k0.
fn eq9_in_u_and_y(m: &Machine, c0: f64) -> ([f64; 3], [f64; 3]) {
    let g = &m.module;
    let (r, rr) = (g.r_big1, g.r_small1);
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    let p1 = 2.0 * r * r * r * rr;
    let f = [
        p1 * c0.powi(3) + r * r * k0 * c0 * c0 - 2.0 * r * r * r * rr * c0 - r * r * k0,
        r * r * (1.0 - c0 * c0),
        r * r + rr * rr - 2.0 * r * rr * c0,
    ];
    let d = [
        3.0 * p1 * c0 * c0 + 2.0 * r * r * k0 * c0 - 2.0 * r * r * r * rr,
        -2.0 * r * r * c0,
        -2.0 * r * rr,
    ];
    (f, d)
}

/// The point with u = sqrt(U), y = sqrt(Y) and z = 1000 mm when leg I reaches at cos(alpha) =
/// c0 there; None where U or Y is negative or leg I cannot reach.
fn point_from_u_and_y(m: &Machine, c0: f64, u2: f64, y2: f64) -> Option<Vector3<f64>> {
    let g = &m.module;
    let k1 = g.l1 * g.l1 - g.r_big1 * g.r_big1 - g.r_small1 * g.r_small1
        + 2.0 * g.r_big1 * g.r_small1 * c0;
    (u2 >= 0.0 && y2 >= 0.0 && k1 - u2 - y2 > 0.0)
        .then(|| Vector3::new(u2.sqrt() - g.dx1, y2.sqrt(), 1000.0))
}

/// (U, Y) where two of [`eq9_in_u_and_y`]'s linear functions a[0] + U a[1] + Y a[2] and
/// b[0] + U b[1] + Y b[2] are both zero (Cramer's rule).
fn u_and_y_where(a: [f64; 3], b: [f64; 3]) -> (f64, f64) {
    let det = a[1] * b[2] - a[2] * b[1];
    (
        (a[2] * b[0] - a[0] * b[2]) / det,
        (a[0] * b[1] - a[1] * b[0]) / det,
    )
}

/// A point whose cubic (9) has a double root at cos(alpha) = c0 (F(c0) = F'(c0) = 0, linear
/// in u^2 and y^2) and whose leg I reaches there.
fn on_double_root(m: &Machine, c0: f64) -> Option<Vector3<f64>> {
    let (f, d) = eq9_in_u_and_y(m, c0);
    let (u2, y2) = u_and_y_where(f, d);
    point_from_u_and_y(m, c0, u2, y2)
}

/// The points of [`on_double_root`] for c0 = -0.9, -0.8, ..., 0.9 where there is one, with
/// their c0.
fn double_root_points(m: &Machine) -> Vec<(f64, Vector3<f64>)> {
    (0..19)
        .map(|i| -0.9 + 0.1 * f64::from(i))
        .filter_map(|c0| on_double_root(m, c0).map(|p| (c0, p)))
        .collect()
}

/// How many roots the cubic (9) of `p` has near its critical point close to `c0` (two or none),
/// from the sign of the cubic there and of its second derivative, the cubic evaluated in
/// double-double with its error bound (the test's own Horner on [`super::eq9_tracked`]); None
/// when the value is within its error.
fn roots_near(m: &Machine, p: &Vector3<f64>, c0: f64) -> Option<usize> {
    use crate::math::dd::Tracked;
    let c = super::eq9_tracked(&m.module, p);
    let v: Vec<f64> = c.iter().map(|t| t.v.to_f64()).collect();
    let mut x = c0;
    for _ in 0..50 {
        let (d1, d2) = (
            (3.0 * v[3] * x + 2.0 * v[2]) * x + v[1],
            6.0 * v[3] * x + 2.0 * v[2],
        );
        x -= d1 / d2;
    }
    let t = Tracked::exact(x);
    let f = ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
    if f.v.to_f64().abs() <= f.error(40) {
        return None;
    }
    let curvature = 6.0 * v[3] * x + 2.0 * v[2];
    Some(if f.v.to_f64() * curvature < 0.0 { 2 } else { 0 })
}

/// Points on and next to a double root of the cubic (9) away from alpha = 0 (two leg-I
/// postures of one sign meeting; five machines, c0 from -0.9 to 0.9), moved off it by 1e-6 to
/// 1e-14 (relative, in u) to both sides: every posture found satisfies leg I's equations, the
/// result is proved, and near c0 there are four postures (two roots with their mirror images)
/// where the cubic has two roots there and none where it has none, as the test's own
/// double-double evaluation decides. The points on the root itself, at rounding, and only
/// those, reach the double-double isolation of the cubic (`Extended`): a search about a
/// touching root that missed it would send the others there too. The same on the machines and
/// points scaled by 2^-10 and 2^10 (exactly: the cubic's coefficients scale by k^4, and their
/// bounds with them). At 2^-10 the coefficients are below 1, where an error bound left
/// unnormalised, or multiplied by the largest coefficient instead of divided, is smaller, not
/// larger: the search about a touching root then misses the roots.
#[test]
fn postures_at_a_double_root_of_eq9() {
    use super::leg1_residual_mm;
    for k in [1.0, 2f64.powi(-10), 2f64.powi(10)] {
        let (mut decided, mut extended) = (0, 0);
        for m0 in machines() {
            let m = m0.scaled(k);
            for (c0, p0) in double_root_points(&m0) {
                let u0 = p0.x + m0.module.dx1;
                for rel in [1e-6, 1e-9, 1e-12, 1e-14, 0.0, -1e-14, -1e-12, -1e-9, -1e-6] {
                    let p = Vector3::new(u0 * (1.0 + rel) - m0.module.dx1, p0.y, p0.z) * k;
                    let (legs, certificate) = leg1_postures(&m, &p);
                    let at = format!(
                        "x{k}: {}: c0 {c0:.1}, {rel:e} off: {p:?}: {certificate:?} {legs:?}",
                        m.name
                    );
                    assert!(certificate.proved(), "{at}");
                    // The certified factors of leg I prove every point off the root (two roots
                    // about 1e-7 apart at 1e-14); only those on it need the double-double
                    // isolation.
                    assert_eq!(certificate == Certificate::Extended, rel == 0.0, "{at}");
                    extended += usize::from(certificate == Certificate::Extended);
                    for l in &legs {
                        assert!(leg1_residual_mm(&m.module, &p, l) <= 1e-9 * k, "{at}");
                    }
                    let near = legs.iter().filter(|l| (l.cos - c0).abs() < 1e-2).count();
                    if let Some(expected) = roots_near(&m, &p, c0) {
                        assert_eq!(near, 2 * expected, "{at}");
                        decided += 1;
                    }
                }
            }
        }
        assert!(
            decided > 100 && extended > 10,
            "x{k}: {decided} decided, {extended} extended"
        );
    }
}

/// The roots of the cubic (9) of `p` that `working_by_cubic` searches, in [r1/R1 - its angle
/// margin, 1]; None where it has no cubic.
fn roots_searched_by_cubic(
    m: &Machine,
    p: &Vector3<f64>,
) -> Option<crate::math::cubic::CubicRoots> {
    let g = &m.module;
    let lo = (g.r_small1 / g.r_big1 - super::FAST_MARGIN_RAD).max(-1.0);
    super::cubic_eq9(g, p).map(|c| crate::math::cubic::cubic_roots_in(&c, lo, 1.0))
}

/// Two roots of the cubic (9) proved apart but within [`super::FAST_MARGIN_RAD`] of each other in
/// alpha (a double root above r1/R1 split by moving u 1e-9 to 1e-15, relative), at heights z
/// from 450 to 1650 mm: `working_by_cubic` hands every such point over (None) where leg I
/// reaches at both roots. On the machines as built none has a working branch: at a double root
/// F'(c) = 0, and a root with leg I's rods within 90 degrees of +z has F' > 0
/// (`at_most_one_root_of_eq9_carries_a_feasible_branch`), so the rods of both roots lie about
/// 90 degrees from +z, beyond these machines' tilt limits. With the limits opened (rods free,
/// strokes unbounded) some have one, and are handed over all the same.
#[test]
fn two_roots_within_the_angle_margin_are_handed_over() {
    use super::{FAST_MARGIN_MM, FAST_MARGIN_RAD, leg1_height_sq};
    let (mut close, mut working_open) = (0, 0);
    for (m, open) in as_built_and_opened() {
        let g = &m.module;
        for (c0, p0) in double_root_points(&m) {
            let u0 = p0.x + g.dx1;
            for k in 0..=24 {
                for side in [1.0, -1.0] {
                    let rel = side * 10f64.powf(-9.0 - 0.25 * f64::from(k));
                    let p = Vector3::new(u0 * (1.0 + rel) - g.dx1, p0.y, p0.z);
                    let Some(roots) = roots_searched_by_cubic(&m, &p) else {
                        continue;
                    };
                    let near: Vec<_> = roots.iter().filter(|r| (r.x - c0).abs() < 1e-2).collect();
                    let [a, b] = near[..] else {
                        continue;
                    };
                    let apart = (a.x.acos() - b.x.acos()).abs();
                    let reach = [a.x, b.x]
                        .map(|c| leg1_height_sq(g, &p, c) > FAST_MARGIN_MM * FAST_MARGIN_MM);
                    if a.touching || b.touching || apart >= FAST_MARGIN_RAD || reach != [true; 2] {
                        continue;
                    }
                    assert!(apart > 0.0, "{}: {p:?}", m.name);
                    // Neither the cubic (9) nor leg I's height depends on z.
                    for z in (0..=12).map(|i| 450.0 + 100.0 * f64::from(i)) {
                        let p = Vector3::new(p.x, p.y, z);
                        let at = format!("{}: c0 {c0:.1}, {rel:e} off: {p:?}: {apart:e}", m.name);
                        assert_eq!(working_by_cubic(&m, &p), None, "{at}");
                        let has = working(&solve(&m, &p)).is_some();
                        assert!(open || !has, "{at}");
                        working_open += usize::from(has);
                        close += 1;
                    }
                }
            }
        }
    }
    eprintln!("{close} points, {working_open} with a working branch (limits opened)");
    assert!(close > 500 && working_open > 10, "{close}, {working_open}");
}

/// A root of the cubic (9) that touches zero within its error (a double root of (9), at
/// rounding and 1e-14 or 1e-12 off, relative, in u; z from 450 to 1650 mm) is a close call
/// for the fast path: `working_by_cubic` hands every such point over, on the machines as built
/// and with their limits opened (where some have a working branch).
#[test]
fn a_touching_root_is_handed_over() {
    let (mut touching, mut with_working) = (0, 0);
    for (m, _) in as_built_and_opened() {
        let g = &m.module;
        for (c0, p0) in double_root_points(&m) {
            let u0 = p0.x + g.dx1;
            for rel in [0.0, 1e-14, -1e-14, 1e-12, -1e-12] {
                let p = Vector3::new(u0 * (1.0 + rel) - g.dx1, p0.y, p0.z);
                let Some(roots) = roots_searched_by_cubic(&m, &p) else {
                    continue;
                };
                if !roots.iter().any(|r| r.touching && (r.x - c0).abs() < 1e-6) {
                    continue;
                }
                for z in (0..=6).map(|i| 450.0 + 200.0 * f64::from(i)) {
                    let p = Vector3::new(p.x, p.y, z);
                    assert_eq!(working_by_cubic(&m, &p), None, "{}: {p:?}", m.name);
                    touching += 1;
                    with_working += usize::from(working(&solve(&m, &p)).is_some());
                }
            }
        }
    }
    eprintln!("{touching} points with a touching root, {with_working} with a working branch");
    assert!(touching > 100, "{touching}");
}

/// Next to y = 0 the cubic (9) has a root next to cos(alpha) = 1, where the two postures of the
/// root (alpha and -alpha) meet: within [`super::FAST_MARGIN_RAD`] of alpha = 0 the fast path's
/// label is a close call. Points 1e-10 to 1e-7 mm off y = 0 (an 8^3 grid otherwise, either side,
/// five machines as built and opened) with such a root in range are all handed over.
#[test]
fn a_root_within_the_angle_margin_of_zero_is_handed_over() {
    use super::FAST_MARGIN_RAD;
    let (mut near_zero, mut with_working) = (0, 0);
    for (m, _) in as_built_and_opened() {
        for p0 in grid(8) {
            for y in [1e-7, -1e-8, 1e-9, -1e-10] {
                let p = Vector3::new(p0.x, y, p0.z);
                let Some(roots) = roots_searched_by_cubic(&m, &p) else {
                    continue;
                };
                let at_zero = roots.iter().any(|r| {
                    let c = r.x.clamp(-1.0, 1.0);
                    ((1.0 - c) * (1.0 + c)).sqrt() < FAST_MARGIN_RAD
                });
                if at_zero {
                    assert_eq!(working_by_cubic(&m, &p), None, "{}: {p:?}", m.name);
                    near_zero += 1;
                    with_working += usize::from(working(&solve(&m, &p)).is_some());
                }
            }
        }
    }
    eprintln!("{near_zero} points with a root at alpha = 0, {with_working} with a working branch");
    assert!(
        near_zero > 500 && with_working > 100,
        "{near_zero}, {with_working}"
    );
}

/// Eq. (14) gives |rho1 - z_p| = |y (R1 cos(alpha) - r1)| / (R1 |sin(alpha)|) at a root; below
/// [`super::FAST_MARGIN_MM`] the posture is too close to its mirror image (s1 = +1) for the
/// fast path's label. Points 1e-7 to 0.1 mm off y = 0 next to where leg I lies flat (either
/// side, five machines, limits opened so that nothing else refuses them) have a root in
/// (r1/R1, 1] with that height below the margin, where leg I's height from eq. (11), computed
/// with the rounding of its cancellation, can still come out above it: `working_by_cubic` hands
/// every such point over.
#[test]
fn a_root_with_rho1_within_the_margin_of_z_is_handed_over() {
    use super::{FAST_MARGIN_MM, FAST_MARGIN_RAD, leg1_height_sq};
    let (mut low, mut with_working) = (0, 0);
    for m in machines().into_iter().map(with_limits_opened) {
        let g = &m.module;
        let (r, rr) = (g.r_big1, g.r_small1);
        // At y = 0, eq. (9) is (c^2 - 1) (2 R1^3 r1 c + R1^2 (k0 - u^2)): the root c = (u^2 -
        // k0) / (2 R1 r1), where leg I lies flat (eq. (11): rho1 = z_p). Points next to it.
        let k0 = g.l1 * g.l1 - r * r - rr * rr;
        // Just above r1/R1, the root near cos(alpha) = 1 (sin(alpha) about y sqrt(r1 / (2 R1 (1 -
        // c))) / R1 there) clears the angle margin while the height at c stays below its own.
        let near = [1e-2, 1e-3, 1e-4, 1e-5].map(|d| rr / r + d);
        let across = (0..20).map(|i| rr / r + (1.0 - rr / r) * (f64::from(i) + 0.5) / 20.0);
        for (i, c) in near.into_iter().chain(across).enumerate() {
            let u = (k0 + 2.0 * r * rr * c).sqrt();
            for k in 0..=24 {
                for side in [1.0, -1.0] {
                    let y = side * 10f64.powf(-1.0 - 0.25 * f64::from(k));
                    let p = Vector3::new(u - g.dx1, y, 500.0 + 40.0 * i as f64);
                    let Some(roots) = roots_searched_by_cubic(&m, &p) else {
                        continue;
                    };
                    let below = roots.iter().any(|root| {
                        let c = root.x.clamp(-1.0, 1.0);
                        let sin = ((1.0 - c) * (1.0 + c)).sqrt();
                        let h2 = leg1_height_sq(g, &p, c);
                        !root.touching
                            && sin >= FAST_MARGIN_RAD
                            && h2 >= FAST_MARGIN_MM * FAST_MARGIN_MM
                            && (p.y * (r * c - rr) / (r * sin)).abs() < FAST_MARGIN_MM
                    });
                    if below {
                        assert_eq!(working_by_cubic(&m, &p), None, "{}: {p:?}", m.name);
                        low += 1;
                        with_working += usize::from(working(&solve(&m, &p)).is_some());
                    }
                }
            }
        }
    }
    eprintln!("{low} points with a root below the margin, {with_working} with a working branch");
    assert!(low > 100 && with_working > 10, "{low}, {with_working}");
}

/// The last resort for a touching root that neither proof decides gives postures at the root,
/// each with its mirror image: at double roots of (9) (c0 from -0.9 to 0.9, five machines, z
/// from 600 to 1400 mm), four postures, the one of the sign of eq. (11) that eq. (14) takes
/// exact (1e-9 mm, cos(alpha) within 1e-9 of c0); the other sign's start is not a posture at
/// c0, and its polish at the fold stops up to 1.4e-5 mm off, 1.7e-4 from c0 (measured; 1e-4 mm
/// and 1e-3 asserted); at cos(alpha) = 1 on y = 0 (Table II: eq. (14) holds for every
/// rho1 there), given 1 or a rounding beyond it, both signs of eq. (11), (0, z_p +- h); at the
/// stretched machine's double root there, (0, z_p).
#[test]
fn unproved_touching_postures_are_the_postures_at_the_root() {
    use super::{leg1_height_sq, leg1_residual_mm, unproved_touching_postures};
    let postures = |m: &Machine, p: &Vector3<f64>, ct: f64| {
        let mut out = Vec::new();
        unproved_touching_postures(&m.module, p, ct, &mut |l: Leg1| out.push(l));
        out
    };
    let (mut double, mut table_ii) = (0, 0);
    for m in machines() {
        for (c0, p0) in double_root_points(&m) {
            for z in [600.0, 1000.0, 1400.0] {
                let p = Vector3::new(p0.x, p0.y, z);
                let found = postures(&m, &p, c0);
                let at = format!("{}: c0 {c0:.1}: {p:?}: {found:?}", m.name);
                assert_eq!(found.len(), 4, "{at}");
                let residual = |l: &Leg1| leg1_residual_mm(&m.module, &p, l);
                for l in &found {
                    assert!(residual(l) <= 1e-4 && (l.cos - c0).abs() <= 1e-3, "{at}");
                }
                assert!(
                    [found[0], found[2]]
                        .iter()
                        .any(|l| residual(l) <= 1e-9 && (l.cos - c0).abs() <= 1e-9),
                    "{at}"
                );
                for (l, image) in [(found[0], found[1]), (found[2], found[3])] {
                    assert_eq!(image.alpha, -l.alpha, "{at}");
                    assert!((image.rho1 - z + l.rho1 - z).abs() <= 1e-9, "{at}");
                }
                double += 1;
            }
        }
        for p in grid(6).map(|p| Vector3::new(p.x, 0.0, p.z)) {
            let h2 = leg1_height_sq(&m.module, &p, 1.0);
            if h2 < 1.0 {
                continue;
            }
            for ct in [1.0, 1.0 + 1e-12] {
                let found = postures(&m, &p, ct);
                let at = format!("{}: {p:?}, {ct}: {found:?}", m.name);
                assert_eq!(found.len(), 4, "{at}");
                for (l, side) in found.iter().zip([1.0, -1.0, -1.0, 1.0]) {
                    assert!(l.alpha == 0.0, "{at}");
                    assert!((l.rho1 - p.z - side * h2.sqrt()).abs() <= 1e-9, "{at}");
                    assert!(leg1_residual_mm(&m.module, &p, l) <= 1e-9, "{at}");
                }
                table_ii += 1;
            }
        }
    }
    assert!(double > 40 && table_ii > 100, "{double}, {table_ii}");
    let (m, p) = stretched_at_alpha_zero();
    for ct in [1.0, 1.0 + 1e-12] {
        let found = postures(&m, &p, ct);
        assert_eq!(found.len(), 4, "{ct}: {found:?}");
        for l in found {
            assert!(
                l.alpha == 0.0 && (l.rho1 - p.z).abs() <= 1e-9,
                "{ct}: {l:?}"
            );
        }
    }
}

/// A posture met twice is listed once ([`super::leg1_postures_into`]): the certified posture
/// of each grid point (from Chebyshev's steps) given again as a root of (9) (its posture then
/// comes from Newton's polish, equal to rounding, not always to the bit) gives it and its
/// mirror image once each.
#[test]
fn a_posture_met_twice_is_listed_once() {
    use super::{OtherRoots, certified_lanes, leg1_postures_into};
    let mut unequal_bits = 0;
    for m in machines() {
        for p in grid(12) {
            let ([leg], [certified]) = certified_lanes(&m, &[p]);
            if !certified {
                continue;
            }
            let roots = OtherRoots {
                roots: [leg.cos].into_iter().collect(),
                touching: arrayvec::ArrayVec::new(),
            };
            let mut out = arrayvec::ArrayVec::new();
            leg1_postures_into(&m.module, &p, &roots, Some(leg), &mut out);
            assert_eq!(out.len(), 2, "{}: {p:?}: {out:?}", m.name);
            let (mut alone, mut again) = (arrayvec::ArrayVec::new(), arrayvec::ArrayVec::new());
            leg1_postures_into(&m.module, &p, &OtherRoots::default(), Some(leg), &mut alone);
            leg1_postures_into(&m.module, &p, &roots, None, &mut again);
            unequal_bits += usize::from(alone[0].rho1 != again[0].rho1);
        }
    }
    // The duplicate test is not one of equality: over a hundred pairs differ in their last bits.
    assert!(unequal_bits > 100, "{unequal_bits}");
}

/// The machine and point of [`an_exact_double_root_at_alpha_zero_with_leg_one_stretched`].
fn stretched_at_alpha_zero() -> (Machine, Vector3<f64>) {
    let mut m = Machine::default_verne();
    (m.module.r_big1, m.module.r_small1, m.module.l1) = (400.0, 100.0, 500.0);
    let m = Machine::from_toml_str(&m.to_toml(), "stretched").expect("a valid machine");
    let p = Vector3::new(400.0 - m.module.dx1, 0.0, 1000.0);
    (m, p)
}

/// A machine whose cubic (9) has an exact double root at cos(alpha) = 1 with leg I fully
/// stretched there (R1 = 400, r1 = 100, L1 = 500 mm, u = 400 mm, y = 0: F(1) = 0 as y = 0 and
/// F'(1) = 2 R1^2 (L1^2 - (R1 - r1)^2 - u^2) = 0): the one posture (0, z_p), once (the two
/// signs of eq. (11) meet), proved.
#[test]
fn an_exact_double_root_at_alpha_zero_with_leg_one_stretched() {
    let (m, p) = stretched_at_alpha_zero();
    let (legs, certificate) = leg1_postures(&m, &p);
    assert!(certificate.proved(), "{certificate:?}");
    let at_zero: Vec<&Leg1> = legs.iter().filter(|l| l.alpha.abs() < 1e-6).collect();
    assert_eq!(at_zero.len(), 1, "{legs:?}");
    assert!(
        at_zero[0].alpha == 0.0 && (at_zero[0].rho1 - p.z).abs() <= 1e-9,
        "{legs:?}"
    );
}

/// The complete solver's postures are mostly recognised as at the rounding level of leg I's
/// equations ([`Leg1Equations::at_rounding`]; 95.7 % of 17,184 measured), and polishing one
/// of those again returns it bit for bit (no Newton step is taken from a posture no step can
/// improve); the others move within the stopping rule.
#[test]
fn polished_postures_are_at_rounding() {
    use super::polish_leg1;
    let (mut total, mut at_rounding) = (0, 0);
    for (m, roots) in leg1_roots(12) {
        for (p, root) in &roots {
            let eqs = Leg1Equations::new(&m.module, p);
            let (f, dz) = eqs.residuals(root);
            let again = polish_leg1(&m.module, p, *root);
            total += 1;
            if eqs.at_rounding(root, f, dz) {
                at_rounding += 1;
                let bits = |l: &Leg1| (l.alpha.to_bits(), l.rho1.to_bits());
                assert_eq!(bits(&again), bits(root), "{}: {p:?}", m.name);
            } else {
                assert!(within_stop(&again, root), "{}: {p:?}", m.name);
            }
        }
    }
    assert!(at_rounding * 100 >= total * 95, "{at_rounding} of {total}");
}

/// Newton's polish returns the best posture it met when it cannot settle: from starts 1e-2 and
/// 1e-3 rad off a fold (a double root of (9), where Newton converges only linearly and runs out
/// of iterations) it ends within 1e-9 mm of leg I's equations (measured 6e-11 worst); and from
/// random starts up to a radian away it never returns a posture worse than its start.
#[test]
fn polish_returns_the_best_posture_it_met() {
    use super::{leg1_residual_mm, polish_leg1};
    let mut folds = 0;
    for m in machines() {
        for (c0, p) in double_root_points(&m) {
            let (legs, _) = leg1_postures(&m, &p);
            for l in legs.iter().filter(|l| (l.cos - c0).abs() < 1e-2) {
                for d in [1e-2, 1e-3, -1e-3] {
                    let polished = polish_leg1(&m.module, &p, moved(l, d, 0.0));
                    let residual = leg1_residual_mm(&m.module, &p, &polished);
                    assert!(
                        residual <= 1e-9,
                        "{}: c0 {c0}, {d:e} off: {residual:e}",
                        m.name
                    );
                    folds += 1;
                }
            }
        }
    }
    assert!(folds > 100, "{folds}");
    let mut unit = crate::math::test_rng::lcg(0x0b1e_55ed);
    for (m, roots) in leg1_roots(6) {
        for (p, root) in &roots {
            for _ in 0..4 {
                let start = moved(root, 2.0 * unit() - 1.0, 200.0 * (unit() - 0.5));
                let polished = polish_leg1(&m.module, p, start);
                let (before, after) = (
                    leg1_residual_mm(&m.module, p, &start),
                    leg1_residual_mm(&m.module, p, &polished),
                );
                assert!(
                    after <= before,
                    "{}: {p:?} from {start:?}: {after:e} > {before:e}",
                    m.name
                );
            }
        }
    }
}
/// Newton's polish from starts 1e-3 to 1e-11 rad (and 70 times that in mm) off a posture ends
/// within the stopping rule of it; so it does on y = 0 from Table II's starts (alpha = 0, where
/// eq. (14) holds for every rho1) with rho1 alone 1e-3 to 1e-8 mm off: a start off by more
/// than rounding in either equation is never taken as converged.
#[test]
fn polish_converges_from_near_starts() {
    use super::polish_leg1;
    let check = |m: &Machine, p: &Vector3<f64>, root: &Leg1, start: Leg1| {
        let polished = polish_leg1(&m.module, p, start);
        let at = format!("{}: {p:?} from {start:?}", m.name);
        assert!(
            within_stop(&polished, root),
            "{at}: {polished:?} vs {root:?}"
        );
    };
    for (m, roots) in leg1_roots(10) {
        for (p, root) in &roots {
            for d in [1e-3, 1e-6, -1e-7, 1e-9, -1e-11] {
                check(&m, p, root, moved(root, d, -70.0 * d));
            }
        }
        for (p, root) in &table_ii_postures(&m) {
            for d in [1e-3, -1e-5, 1e-8] {
                check(&m, p, root, moved(root, 0.0, d));
            }
        }
    }
}

/// Every point's branches come out ordered by alpha (`total_cmp`), then configuration, as
/// [`posture_order`](super::posture_order) promises: on grids of five machines, with the planes
/// where its first guess (the mirrors, then the others in reverse) could be wrong: y = 0 and
/// next to it (postures at alpha = 0 and at alpha = pi, each with both s1), and x, z across the
/// workspace. (The guess is right on all of them: the sort after it is a safety net.)
#[test]
fn branches_come_out_by_alpha_then_configuration() {
    let mut lists = 0;
    for m in machines() {
        let g = &m.module;
        for x in [-300.0, -150.0, -40.0, 0.0, 90.0, 200.0].map(|v| v - g.dx1) {
            for y in [
                0.0, -0.0, 1e-12, -1e-12, 1e-6, -1e-6, 0.5, -0.5, 60.0, -60.0, 250.0,
            ] {
                for z in [600.0, 900.0, 1000.0, 1200.0] {
                    let p = Vector3::new(x, y, z);
                    let all = solve(&m, &p);
                    lists += (all.len() > 1) as usize;
                    for w in all.windows(2) {
                        let order = w[0]
                            .alpha
                            .total_cmp(&w[1].alpha)
                            .then(w[0].config.cmp(&w[1].config));
                        assert!(order.is_lt(), "{}: {p:?}: {:?}", m.name, &all[..]);
                    }
                }
            }
        }
    }
    assert!(lists > 500, "{lists}");
}

/// The fast path's test of the rods of leg I crossing (R1 cos(alpha) > r1, in `lower_branch`),
/// reached: on the default machine the rods' tilt ends a working branch 35 mm before it, so
/// here machines whose rods cross at a small alpha (R1 - r1 = 3e-5 and 1e-4 mm), the rods
/// free to tilt to 90 degrees and slider I's stroke starting at 1000 mm. The points put a root
/// of eq. (9) just past r1/R1 (cos(alpha) = r1/R1 - k 1e-7, inside the margin below r1/R1 that
/// `working_by_cubic` searches): y from eqs. (11) and (14) (h^2 = k1 - u^2 - y^2 and
/// h = y (R1 c - r1) / (R1 sin(alpha)), so y^2 (1 + ((R1 c - r1) / (R1 sin(alpha)))^2) =
/// k1 - u^2), z so that slider I is inside its stroke on the crossing posture alone. There
/// the branch of the machine's kind fails only as its rods cross, and no branch is working:
/// the fast path must say so too.
#[test]
fn the_fast_path_refuses_a_posture_whose_rods_cross() {
    use super::working_fast;
    use crate::parallel_module::branches::{Reason, WORKING_CONFIG};
    let mut crossing_only = 0;
    for gap in [3e-5, 1e-4] {
        let mut m = Machine::default_verne();
        m.module.r_small1 = m.module.r_big1 - gap;
        m.limits.rod_tilt_max = std::f64::consts::FRAC_PI_2;
        m.limits.rho_min[0] = 1000.0;
        let m = Machine::from_toml_str(&m.to_toml(), "rods crossing at a small alpha")
            .expect("a valid machine");
        let g = &m.module;
        let (r, rr) = (g.r_big1, g.r_small1);
        let kind = |b: &&IkBranch| b.config == WORKING_CONFIG;
        for k in 1..10 {
            let c = rr / r - k as f64 * 1e-7;
            let (sin_a, delta) = ((1.0 - c * c).sqrt(), r * c - rr);
            for i in 0..30 {
                let x = -650.0 + 1100.0 * (i as f64 + 0.5) / 30.0;
                // k1 - u^2: eq. (11)'s h^2 at y = 0.
                let k1_u2 = super::leg1_height_sq(g, &Vector3::new(x, 0.0, 0.0), c);
                let y2 = k1_u2 / (1.0 + (delta / (r * sin_a)).powi(2));
                if y2 <= 0.0 {
                    continue;
                }
                let y = y2.sqrt();
                // Leg I's postures do not depend on z: place the crossing one's slider I 0.5 mm
                // (or half the distance to the next posture's) above the stroke's start.
                let z0 = 1000.0;
                let at_z0 = solve(&m, &Vector3::new(x, y, z0));
                let Some(cross) = at_z0
                    .iter()
                    .filter(kind)
                    .find(|b| b.verdict.has(Reason::RodsCross))
                else {
                    continue;
                };
                let below = at_z0
                    .iter()
                    .filter(kind)
                    .filter(|b| !b.verdict.has(Reason::RodsCross))
                    .map(|b| cross.rho.x - b.rho.x)
                    .fold(1.0f64, f64::min);
                if below <= 0.0 {
                    continue;
                }
                let p = Vector3::new(x, y, m.limits.rho_min[0] + 0.5 * below + (z0 - cross.rho.x));
                let full = solve(&m, &p);
                let expected = working(&full);
                for found in [working_by_cubic(&m, &p), working_fast(&m, &p)] {
                    assert!(
                        match (found, expected) {
                            (None, _) => true,
                            (Some(f), Some(e)) => same_branch(&f, e),
                            (Some(_), None) => false,
                        },
                        "{gap}: {p:?}: {found:?} vs {expected:?}"
                    );
                }
                let only_crossing = full
                    .iter()
                    .filter(kind)
                    .any(|b| b.verdict.reasons().eq([Reason::RodsCross]));
                crossing_only += usize::from(only_crossing && expected.is_none());
            }
        }
    }
    // Points where the crossing posture is the only candidate (27 measured).
    assert!(crossing_only >= 20, "{crossing_only}");
}

/// Points whose cubic (9) has a double root exact in double-double, away from alpha = 0: the
/// postures there are found by the double-double isolation's undecided intervals (each
/// taken at its midpoint when leg I's equations hold there), which no rounded double root
/// reaches. With A = U - k0 - 2 R1 r1 c (U = u^2), eq. (9) is
/// F(c) = (1 - c^2) R1^2 A + Y (R1^2 + r1^2 - 2 R1 r1 c) (Y = y^2); F(c0) = F'(c0) = 0 gives
/// A = R1 r1 (1 - c0^2) D / ((1 - c0^2) R1 r1 - c0 D), D = R1^2 + r1^2 - 2 R1 r1 c0, and
/// Y = -c0 R1 A / r1 - R1^2 (1 - c0^2). A search over whole R1, r1 and c0 = k / 2^n found these,
/// where A is a binary fraction and Y the square of one; L1 and u then solve
/// L1^2 - u^2 = R1^2 + r1^2 - A - 2 R1 r1 c0 in binary fractions, so that every product in
/// eq. (9) is exact. There: exactly the posture at alpha = acos(c0) with rho1 from eq. (14) and
/// its mirror image, to rounding.
#[test]
fn postures_at_a_double_root_exact_in_double_double() {
    use super::leg1_residual_mm;
    // (R1, r1, L1, u, y, c0), mm.
    let cases = [
        (120.0, 80.0, 816.0, -784.0, 210.0, 0.75),
        (144.0, 64.0, 656.0, -624.0, 162.0, 0.625),
        (150.0, 72.0, 848.5625, -833.4375, 109.375, 0.75),
        (135.0, 90.0, 830.0, -790.0, 236.25, 0.75),
        (135.0, 60.0, 811.25, -788.75, 151.875, 0.625),
    ];
    for (r, rr, l1, u, y, c0) in cases {
        let mut m = Machine::default_verne();
        (m.module.r_big1, m.module.r_small1, m.module.l1) = (r, rr, l1);
        let m =
            Machine::from_toml_str(&m.to_toml(), "an exact double root").expect("a valid machine");
        for (y, z) in [(y, 1000.0), (-y, 1000.0), (y, 1234.5)] {
            let p = Vector3::new(u - m.module.dx1, y, z);
            let c = super::eq9_tracked(&m.module, &p);
            let f_at = |x: f64| c.iter().rev().fold(0.0, |acc, t| acc * x + t.v.to_f64());
            // The root is double in the inputs as given: the coefficients are doubles (34 bits at
            // most) and F(c0) = F'(c0) = 0 exactly (the third root lies below -1).
            assert!(c.iter().all(|t| t.v.lo == 0.0), "{c:?}");
            let d = [
                c[1].v.to_f64(),
                2.0 * c[2].v.to_f64(),
                3.0 * c[3].v.to_f64(),
            ];
            assert_eq!((f_at(c0), d[0] + c0 * (d[1] + c0 * d[2])), (0.0, 0.0));
            let (legs, certificate) = leg1_postures(&m, &p);
            let at = format!("R1 {r}, r1 {rr}: {p:?}: {certificate:?} {legs:?}");
            assert_eq!(certificate, Certificate::Extended, "{at}");
            assert_eq!(legs.len(), 2, "{at}");
            let alpha = c0.acos();
            for l in &legs {
                // eq. (14): rho1 - zp = y (R1 cos(alpha) - r1) / (R1 sin(alpha)).
                let rho1 = z + y * (r * c0 - rr) / (r * l.alpha.sin());
                assert!(
                    (l.alpha.abs() - alpha).abs() <= 1e-12 && (l.rho1 - rho1).abs() <= 1e-9,
                    "{at}"
                );
                assert!(leg1_residual_mm(&m.module, &p, l) <= 1e-9, "{at}");
            }
            assert!(legs[0].alpha * legs[1].alpha < 0.0, "{at}");
        }
    }
}

/// At most one root of eq. (9) carries a feasible branch, on every machine (the fast path's
/// choice between two feasible candidates in `working_by_cubic` is a safety net). In units of
/// R1, with rho = r1/R1, s = sin(alpha) and D = 1 + rho^2 - 2 rho c > 0, eq. (9) is, up to a
/// positive factor, F(c) = D (Y - phi(c)) with phi(c) = (k0 - U + 2 rho c) s^2 / D, and eq. (14)
/// gives h^2 = (zp - rho1)^2 = Y (c - rho)^2 / s^2. Both rods of leg I are within 90 degrees of
/// +z (the rod tilt's largest limit; "up" below) when zp - rho1 > |s|, that is
/// Y (c - rho)^2 > s^4. At such a root F'(c) = -D phi'(c) > 0: phi'(c) < 0 reads
/// rho s^2 (c - rho) < h^2 (1 - rho c), which h^2 > s^2 gives, as 1 - rho c - rho (c - rho) = D.
/// F(-1) = Y (R1 + r1)^2 >= 0 and the leading coefficient 2 R1^3 r1 > 0 put a root at or below
/// -1, so at most two lie in (r1/R1, 1), and if both had F' > 0 a third would lie between them.
/// (The limit's slack of 1e-9 rad lets a rod's z component be -1e-9 L1; the argument then needs
/// s D R1 > 2e-9 L1, which `working_by_cubic`'s margin s > 1e-6 gives on every machine with
/// (R1 - r1)^2 > 2e-3 L1 R1: the five here, and any but a near-parallelogram leg I.) Checked on
/// points built with two roots c_a < c_b above r1/R1 (eq. (9) is linear in U = u^2 and Y = y^2),
/// both signs of u and y, on the five machines with every limit opened but the rods' 90
/// degrees: at most one of the two has its rods up, F' > 0 there, and `solve` lists at most one
/// feasible branch.
#[test]
fn at_most_one_root_of_eq9_carries_a_feasible_branch() {
    let (mut points, mut one_up, mut one_feasible) = (0, 0, 0);
    for m in machines() {
        let mut m = m;
        m.limits.rod_tilt_max = std::f64::consts::FRAC_PI_2;
        m.limits.rho_min = [-1e5; 3];
        m.limits.rho_max = [1e5; 3];
        let m = Machine::from_toml_str(&m.to_toml(), "limits opened").expect("a valid machine");
        let g = &m.module;
        let (r, rr) = (g.r_big1, g.r_small1);
        let n = 40;
        let at = |i: usize| rr / r + (1.0 - rr / r) * i as f64 / n as f64;
        for (ca, cb) in (1..n).flat_map(|i| (i + 1..n).map(move |j| (at(i), at(j)))) {
            let ((fa, _), (fb, _)) = (eq9_in_u_and_y(&m, ca), eq9_in_u_and_y(&m, cb));
            let (u2, y2) = u_and_y_where(fa, fb);
            let (Some(p), Some(_)) = (
                point_from_u_and_y(&m, ca, u2, y2),
                point_from_u_and_y(&m, cb, u2, y2),
            ) else {
                continue;
            };
            let c = super::eq9_coefficients(g, &p);
            let slope = |x: f64| (3.0 * c[3] * x + 2.0 * c[2]) * x + c[1];
            // Eq. (14): zp - rho1 = |y| (R1 c - r1) / (R1 s) on the posture with s1 = -1.
            let rods_up = |x: f64| {
                let s = (1.0 - x * x).sqrt();
                p.y.abs() * (r * x - rr) / (r * s) > r * s
            };
            let up = [ca, cb].map(rods_up);
            assert!(!(up[0] && up[1]), "{ca} {cb} {p:?}");
            for (x, up) in [ca, cb].into_iter().zip(up) {
                assert!(!up || slope(x) > 0.0, "{x}: F' = {} at {p:?}", slope(x));
            }
            one_up += usize::from(up[0] || up[1]);
            let u = p.x + g.dx1;
            for (su, sy) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
                let q = Vector3::new(su * u - g.dx1, sy * p.y, p.z);
                let feasible = solve(&m, &q).iter().filter(|b| b.working()).count();
                assert!(
                    feasible <= 1,
                    "{ca} {cb} {q:?}: {feasible} feasible branches"
                );
                one_feasible += usize::from(feasible == 1);
                points += 1;
            }
        }
    }
    // Measured: 14,820 points, 1,508 pairs with one root's rods up, 3,016 points with a
    // feasible branch.
    assert!(points > 10_000 && one_up > 1000 && one_feasible > 2000);
}

/// [`touching_interval`] holds every root near the critical point that a cubic within the error
/// can have. Cubics k (x - ct)^2 (x - d) + v normalised (largest coefficient 1), with the
/// critical point ct across [-1, 1], the third root d 0.1 to 1.5 away on either side, k from
/// 1e-3 to 1e3, the error 1e-15 to 1e-6 and the value at ct anywhere within it (the cubic
/// routine calls ct touching then), each moved by the whole error either way: each root within
/// (d - ct) / 2 of ct (found by bisection on the factored form, monotone there) lies in the
/// interval.
#[test]
fn touching_interval_holds_every_root_the_error_allows() {
    let mut roots = 0;
    for ct in [-0.95, -0.6, -0.2, 0.0, 0.35, 0.7, 0.97] {
        for delta in [-1.5, -0.5, -0.1, 0.1, 0.5, 1.5] {
            let d: f64 = ct + delta;
            for k in [1e-3, 1.0, 1e3] {
                let raw: [f64; 4] = [
                    -k * ct * ct * d,
                    k * (ct * ct + 2.0 * ct * d),
                    -k * (d + 2.0 * ct),
                    k,
                ];
                let scale = raw.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                let c = raw.map(|a| a / scale);
                let kn = k / scale;
                for err in [1e-15, 1e-12, 1e-9, 1e-6] {
                    let (lo, hi) = touching_interval(&c, err, ct);
                    for v in [-err, -0.5 * err, 0.0, 0.5 * err, err] {
                        for e in [-err, err] {
                            let f = |t: f64| kn * t * t * (t - delta) + (v + e);
                            for side in [-1.0, 1.0] {
                                let (mut a, mut b) = (0.0, side * 0.5 * delta.abs());
                                if f(a) * f(b) > 0.0 || f(a) == 0.0 {
                                    continue;
                                }
                                for _ in 0..200 {
                                    let m = 0.5 * (a + b);
                                    if f(m) * f(a) > 0.0 { a = m } else { b = m }
                                }
                                let x = ct + 0.5 * (a + b);
                                if x.abs() > 1.0 {
                                    continue;
                                }
                                roots += 1;
                                assert!(
                                    lo <= x && x <= hi,
                                    "ct {ct} d {d} k {k} err {err} v {v} e {e}: root {x} outside [{lo}, {hi}]"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(roots > 1000, "{roots}");
}

// ------------------------------------------------------------ the fast path's lower branch

/// A point and a leg-I posture at alpha (slider 1 half L1 below the platform) where leg `tight`
/// (1 or 2) has the room `arg` (L^2 - dx^2 - dy^2 of eq. (12) or (13), mm^2) and the other leg
/// about 100 mm^2 more (the test checks that it has more than 1 mm^2).
fn posture_with_room(m: &Machine, alpha: f64, tight: usize, arg: f64) -> (Vector3<f64>, Leg1) {
    let g = &m.module;
    let (sin, cos) = alpha.sin_cos();
    // dy2 = y - R2 c + r4 and dy3 = y + R2 c - r4: the leg whose |dy| is larger has less room.
    // dy_tight^2 - dy_other^2 = 4 |y k|: enough for the other leg's 1 mm^2 more and its L.
    let k = g.r_big2 * cos - g.r4;
    let (l, l_other) = if tight == 1 {
        (g.l2, g.l3)
    } else {
        (g.l3, g.l2)
    };
    let y_mag = (60.0f64).max((l * l - l_other * l_other + 100.0) / (4.0 * k.abs()));
    let y = if tight == 1 { -k.signum() } else { k.signum() } * y_mag;
    let dy = if tight == 1 { y - k } else { y + k };
    let dx = (l * l - dy * dy - arg).sqrt();
    let p = Vector3::new(dx - g.dx2, y, 1000.0);
    let leg1 = Leg1 {
        alpha,
        rho1: p.z - 0.5 * g.l1,
        sin,
        cos,
    };
    (p, leg1)
}

/// The lower branch's close call (a square root of eqs. (12)-(13) within `FAST_MARGIN_MM` of
/// zero, where the labels of its two roots are for `solve` to give): a leg that reaches within
/// the rounding allowance (h = 0) or misses by less than the margin is a close call, alone (the
/// other leg with room); a leg that misses by more, or has 1e-3 mm or more of room, is not.
#[test]
fn lower_branch_calls_a_leg_at_its_margin_close() {
    use super::{FAST_MARGIN_MM, lower_branch};
    use crate::parallel_module::branches::cos_tilt_max;
    use crate::tolerance::SQRT_ARG_REL;
    for m in machines() {
        let ct = cos_tilt_max(&m);
        for tight in [1, 2] {
            let l = if tight == 1 { m.module.l2 } else { m.module.l3 };
            for (arg, close) in [
                (-0.25 * SQRT_ARG_REL * l * l, true),
                (-0.5 * FAST_MARGIN_MM * l, true),
                (-2.0 * FAST_MARGIN_MM * l, false),
                (1e-6, false),
                (1.0, false),
            ] {
                for alpha in [0.05, -0.2] {
                    let (p, leg1) = posture_with_room(&m, alpha, tight, arg);
                    let g = &m.module;
                    let other_dy = if tight == 1 {
                        p.y + g.r_big2 * leg1.cos - g.r4
                    } else {
                        p.y - g.r_big2 * leg1.cos + g.r4
                    };
                    let dx = p.x + g.dx2;
                    let other_l = if tight == 1 { g.l3 } else { g.l2 };
                    assert!(
                        other_l * other_l - dx * dx - other_dy * other_dy > 1.0,
                        "{}",
                        m.name
                    );
                    let lower = lower_branch(&m, &p, &leg1, ct);
                    assert_eq!(
                        lower.close_call, close,
                        "{}: leg {tight}, room {arg} mm^2, alpha {alpha}",
                        m.name
                    );
                    // Both legs at once: with L2 = L3 = l and y = 0, dy2 = -dy3, and both
                    // legs have this room.
                    let mut twin = m.clone();
                    (twin.module.l2, twin.module.l3) = (l, l);
                    let k = g.r_big2 * leg1.cos - g.r4;
                    let at = Vector3::new((l * l - k * k - arg).sqrt() - g.dx2, 0.0, p.z);
                    let lower = lower_branch(&twin, &at, &leg1, ct);
                    assert_eq!(lower.close_call, close, "{}: both legs, room {arg}", m.name);
                }
            }
        }
    }
}

/// The lower branch is feasible only with R1 cos(alpha) > r1 (leg I's rods not crossing): on
/// machines whose rods may tilt any way and whose strokes are unbounded, so that nothing else
/// refuses it, a posture 1 mm on either side of R1 cos(alpha) = r1 is feasible on one side only
/// (on the machines as built, the rods' tilt refuses these postures first).
#[test]
fn lower_branch_refuses_crossing_rods_of_leg_one() {
    use super::lower_branch;
    for m in machines().into_iter().map(with_limits_opened) {
        let g = m.module;
        for side in [1.0, -1.0] {
            let cos = (g.r_small1 + side) / g.r_big1;
            for alpha in [cos.acos(), -cos.acos()] {
                let (p, leg1) = posture_with_room(&m, alpha, 1, 400.0 * 400.0);
                let lower = lower_branch(&m, &p, &leg1, m.limits.cos_rod_tilt_max);
                assert!(!lower.close_call, "{}", m.name);
                assert_eq!(lower.feasible, side > 0.0, "{}: alpha {alpha}", m.name);
            }
        }
    }
}

/// A leg-I posture is clear of the fast path's margins only when all three hold: R1 cos(alpha)
/// more than `FAST_MARGIN_MM` above r1, |alpha| more than `FAST_MARGIN_RAD` from 0, and slider
/// 1 more than `FAST_MARGIN_MM` below the platform (s1 = -1); any one at half its margin, or on
/// the wrong side, is not clear.
#[test]
fn clear_of_margins_needs_all_three() {
    use super::{FAST_MARGIN_MM, FAST_MARGIN_RAD, clear_of_margins};
    for m in machines() {
        let g = &m.module;
        let p = Vector3::new(-300.0, 10.0, 1000.0);
        let posture = |alpha: f64, below: f64| {
            let (sin, cos) = alpha.sin_cos();
            Leg1 {
                alpha,
                rho1: p.z - below,
                sin,
                cos,
            }
        };
        // alpha where R1 cos(alpha) - r1 = d.
        let at = |d: f64| ((g.r_small1 + d) / g.r_big1).acos();
        for sign in [1.0, -1.0] {
            assert!(
                clear_of_margins(g, &p, &posture(sign * at(10.0), 100.0)),
                "{}",
                m.name
            );
            for (alpha, below) in [
                (sign * at(0.5 * FAST_MARGIN_MM), 100.0),
                (sign * at(-10.0), 100.0),
                (sign * 0.5 * FAST_MARGIN_RAD, 100.0),
                (sign * at(10.0), 0.5 * FAST_MARGIN_MM),
                (sign * at(10.0), -1.0),
            ] {
                let l = posture(alpha, below);
                assert!(!clear_of_margins(g, &p, &l), "{}: {l:?}", m.name);
            }
        }
    }
}
