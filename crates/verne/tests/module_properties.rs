//! Invariants of the parallel module's kinematics (IFToMM 2007, eqs. (3)-(6)): IK -> FK and
//! FK -> IK round trips over deterministic grids, the special cases named by the paper (y_p = 0,
//! R1 cos(alpha) = r1, rho2 = rho3, alpha = pi) exactly and within 1e-9 of each, uniqueness of
//! the working branch, and property tests over boxes of poses and joints.

use std::f64::consts::PI;

use nalgebra::Vector3;
use proptest::prelude::*;
use verne::parallel_module::equations::{ModulePose, residual_mm};
use verne::parallel_module::fk::{self, FkMode};
use verne::parallel_module::ik::{self, IkBranch};
use verne::spec::Machine;

/// Every returned solution must satisfy eqs. (3)-(6) to this length error along the rod (mm).
const EQ_MM: f64 = 1e-6;
/// A round trip must give back the same solution to these (rad, mm).
const TRIP_RAD: f64 = 1e-9;
const TRIP_MM: f64 = 1e-6;
/// Size of a perturbation "within 1e-9" of a special case (mm).
const NUDGE: f64 = 1e-9;
/// A solution of a nudged input must lie this close to one of the exact input (rad, mm). The
/// nudge is 1e-9 mm; roots move by it times the condition number, which stays below ~1e3 for
/// the inputs used here (clusters of roots 1e-4 rad apart are the worst).
const NEAR_RAD: f64 = 1e-6;
const NEAR_MM: f64 = 1e-4;

fn machine() -> Machine {
    Machine::default_verne()
}

fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI { w - 2.0 * PI } else { w }
}

fn ang(a: f64, b: f64) -> f64 {
    wrap(a - b).abs()
}

fn lin(lo: f64, hi: f64, n: usize, i: usize) -> f64 {
    lo + (hi - lo) * i as f64 / (n - 1) as f64
}

fn fk_has(modes: &[FkMode], p: &Vector3<f64>, alpha: f64, rad: f64, mm: f64) -> bool {
    modes
        .iter()
        .any(|md| ang(md.pose.alpha, alpha) <= rad && (md.pose.p - p).amax() <= mm)
}

fn ik_has(branches: &[IkBranch], alpha: f64, rho: &Vector3<f64>, rad: f64, mm: f64) -> bool {
    branches
        .iter()
        .any(|b| ang(b.alpha, alpha) <= rad && (b.rho - rho).amax() <= mm)
}

/// Worst quantities seen, reported at the end of each test (run with --nocapture).
#[derive(Default, Debug)]
struct Worst {
    residual_mm: f64,
    trip_rad: f64,
    trip_mm: f64,
    solutions: usize,
}

/// IK at p: every branch satisfies (3)-(6), at most one is working, and FK of each branch's
/// joints contains the pose. Returns an error message instead of panicking so that a grid
/// reports every failure at once.
fn ik_round_trip(m: &Machine, p: &Vector3<f64>, w: &mut Worst) -> Result<usize, String> {
    let br = ik::solve(m, p);
    if br.iter().filter(|b| b.working()).count() > 1 {
        return Err(format!("p={p:?}: several working IK branches {br:#?}"));
    }
    for b in &br {
        let pose = ModulePose {
            p: *p,
            alpha: b.alpha,
        };
        let r = residual_mm(&m.module, &pose, &b.rho);
        w.residual_mm = w.residual_mm.max(r);
        if r.is_nan() || r >= EQ_MM {
            return Err(format!("p={p:?}: IK branch {b:?} residual {r:e} mm"));
        }
        let modes = fk::solve(m, &b.rho);
        let best = modes
            .iter()
            .map(|md| (ang(md.pose.alpha, b.alpha), (md.pose.p - p).amax()))
            .min_by(|x, y| (x.0 + x.1).total_cmp(&(y.0 + y.1)));
        match best {
            Some((da, dp)) if da <= TRIP_RAD && dp <= TRIP_MM => {
                w.trip_rad = w.trip_rad.max(da);
                w.trip_mm = w.trip_mm.max(dp);
            }
            _ => {
                return Err(format!(
                    "p={p:?}: FK of IK branch {b:?} misses the pose (closest {best:?}); modes {:?}",
                    modes.iter().map(|md| md.pose).collect::<Vec<_>>()
                ));
            }
        }
    }
    w.solutions += br.len();
    Ok(br.len())
}

/// FK at rho: every mode satisfies (3)-(6), at most one is working, and IK of each mode's point
/// contains (alpha, rho).
fn fk_round_trip(m: &Machine, rho: &Vector3<f64>, w: &mut Worst) -> Result<usize, String> {
    let modes = fk::solve(m, rho);
    if modes.iter().filter(|md| md.working()).count() > 1 {
        return Err(format!("rho={rho:?}: several working FK modes {modes:#?}"));
    }
    for md in &modes {
        let r = residual_mm(&m.module, &md.pose, rho);
        w.residual_mm = w.residual_mm.max(r);
        if r.is_nan() || r >= EQ_MM {
            return Err(format!("rho={rho:?}: FK mode {md:?} residual {r:e} mm"));
        }
        let br = ik::solve(m, &md.pose.p);
        let best = br
            .iter()
            .map(|b| (ang(b.alpha, md.pose.alpha), (b.rho - rho).amax()))
            .min_by(|x, y| (x.0 + x.1).total_cmp(&(y.0 + y.1)));
        match best {
            Some((da, dr)) if da <= TRIP_RAD && dr <= TRIP_MM => {
                w.trip_rad = w.trip_rad.max(da);
                w.trip_mm = w.trip_mm.max(dr);
            }
            _ => {
                return Err(format!(
                    "rho={rho:?}: IK of FK mode {md:?} misses the joints (closest {best:?})"
                ));
            }
        }
    }
    w.solutions += modes.len();
    Ok(modes.len())
}

fn report(what: &str, w: &Worst, failures: &[String]) {
    eprintln!("{what}: {w:?}, {} failures", failures.len());
    assert!(
        failures.is_empty(),
        "{what}: {} failures, first: {:#?}",
        failures.len(),
        &failures[..failures.len().min(10)]
    );
}

// ---------------------------------------------------------------- grids

#[test]
fn ik_fk_round_trip_over_workspace_grid() {
    let m = machine();
    let n = 22; // 22^3 = 10648 points
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let mut reachable = 0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = Vector3::new(
                    lin(-600.0, 400.0, n, i),
                    lin(-500.0, 500.0, n, j),
                    lin(500.0, 1600.0, n, k),
                );
                match ik_round_trip(&m, &p, &mut w) {
                    Ok(c) => reachable += (c > 0) as usize,
                    Err(e) => failures.push(e),
                }
            }
        }
    }
    report("IK -> FK grid", &w, &failures);
    assert!(
        reachable > n * n * n / 2,
        "only {reachable} reachable points"
    );
}

#[test]
fn fk_ik_round_trip_over_joint_grid() {
    let m = machine();
    let n = 22;
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let mut assembled = 0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let rho = Vector3::new(
                    lin(0.0, 1100.0, n, i),
                    lin(0.0, 1100.0, n, j),
                    lin(0.0, 1100.0, n, k),
                );
                match fk_round_trip(&m, &rho, &mut w) {
                    Ok(c) => assembled += (c > 0) as usize,
                    Err(e) => failures.push(e),
                }
            }
        }
    }
    report("FK -> IK grid", &w, &failures);
    // The grid contains rho2 = rho3 (j == k) on its diagonal: 484 of the points.
    assert!(
        assembled > n * n * n / 4,
        "only {assembled} assemblable joints"
    );
}

// ---------------------------------------------------------------- the vertical origin

/// An answer and the same input's answer moved: as many solutions, each pair `close`, and the
/// same proof status (`same_proof`).
fn same_moved<T>(x: &[T], y: &[T], same_proof: bool, close: impl Fn(&T, &T) -> bool) -> bool {
    same_proof && x.len() == y.len() && x.iter().zip(y).all(|(u, v)| close(u, v))
}

/// The three sliders and the platform's z move along parallel vertical axes, so moving every
/// slider by s moves every assembly mode by s along z and changes nothing else, and moving P by
/// s along z moves every slider by s: where the sliders' zero lies does not change the answer.
/// On grids of the joint space and of the workspace of three machines, moved by s = -2000 to
/// 1900 mm (in exact arithmetic: an input whose move does not undo exactly is skipped): the same
/// solutions in the same order, with the same configurations and the same proof or its
/// absence, alpha within 1e-11 rad and positions within 1e-9 mm. Verdicts are not compared (the
/// strokes are absolute), nor the kind of proof (its rounding bounds grow with the inputs'
/// magnitudes). Near a parallel singularity, within the fold's precision (the pose fixed only
/// to the square root of the joints' rounding, docs/reliability.md), the count itself may
/// differ, so the grids keep away from the thin sets.
#[test]
fn moving_the_vertical_origin_moves_every_solution_with_it() {
    use verne::selftest::hard_sets::random_geometries;
    let mut machines = vec![machine()];
    machines.extend(random_geometries(2, 41));
    let shifts = [-2000.0, -777.0, 333.0, 1900.0];
    let (mut compared, mut solutions) = (0, 0);
    let mut failures = Vec::new();
    let n = 11;
    for m in &machines {
        for i in 0..n * n * n {
            let (a, b, c) = (i / (n * n), (i / n) % n, i % n);
            let rho = Vector3::new(
                lin(0.3, 1100.7, n, a),
                lin(0.1, 1100.3, n, b),
                lin(0.2, 1100.9, n, c),
            );
            let p = Vector3::new(
                lin(-650.3, 450.1, n, a),
                lin(-550.7, 550.2, n, b),
                lin(450.9, 1650.4, n, c),
            );
            for s in shifts {
                let moved = rho.map(|v| v + s);
                if moved.map(|v| v - s) == rho {
                    let (x, y) = (fk::solve(m, &rho), fk::solve(m, &moved));
                    compared += 1;
                    solutions += x.len();
                    let same = same_moved(
                        &x,
                        &y,
                        x.certificate.proved() == y.certificate.proved(),
                        |u, v| {
                            u.config == v.config
                                && ang(u.pose.alpha, v.pose.alpha) <= 1e-11
                                && (u.pose.p + Vector3::new(0.0, 0.0, s) - v.pose.p).amax() <= 1e-9
                        },
                    );
                    if !same {
                        failures.push(format!(
                            "{}: FK of {rho:?} moved by {s}: {x:?} then {y:?}",
                            m.name
                        ));
                    }
                }
                let lifted = Vector3::new(p.x, p.y, p.z + s);
                if lifted.z - s == p.z {
                    let (x, y) = (ik::solve(m, &p), ik::solve(m, &lifted));
                    compared += 1;
                    solutions += x.len();
                    let same = same_moved(
                        &x,
                        &y,
                        x.certificate.proved() == y.certificate.proved(),
                        |u, v| {
                            u.config == v.config
                                && ang(u.alpha, v.alpha) <= 1e-11
                                && (u.rho.map(|r| r + s) - v.rho).amax() <= 1e-9
                        },
                    );
                    if !same {
                        failures.push(format!(
                            "{}: IK of {p:?} moved by {s}: {x:?} then {y:?}",
                            m.name
                        ));
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {compared}:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(
        compared > 15_000 && solutions > 80_000,
        "{compared} inputs, {solutions} solutions"
    );
}

// ---------------------------------------------------------------- special cases

/// The solutions of a nudged input must be as many as the exact input's, each close to one of
/// them. `sols` are (alpha, 3-vector) pairs.
fn same_solutions(
    what: &str,
    exact: &[(f64, Vector3<f64>)],
    nudged: &[(f64, Vector3<f64>)],
    failures: &mut Vec<String>,
) {
    if exact.len() != nudged.len() {
        failures.push(format!(
            "{what}: {} solutions exactly, {} nudged\nexact {exact:?}\nnudged {nudged:?}",
            exact.len(),
            nudged.len()
        ));
        return;
    }
    for (a, v) in nudged {
        if !exact
            .iter()
            .any(|(b, u)| ang(*a, *b) <= NEAR_RAD && (v - u).amax() <= NEAR_MM)
        {
            failures.push(format!(
                "{what}: nudged solution ({a}, {v:?}) not near {exact:?}"
            ));
        }
    }
}

fn ik_sols(m: &Machine, p: &Vector3<f64>) -> Vec<(f64, Vector3<f64>)> {
    ik::solve(m, p).iter().map(|b| (b.alpha, b.rho)).collect()
}

fn fk_sols(m: &Machine, rho: &Vector3<f64>) -> Vec<(f64, Vector3<f64>)> {
    fk::solve(m, rho)
        .iter()
        .map(|md| (md.pose.alpha, md.pose.p))
        .collect()
}

/// The six nudges of a point by +-NUDGE along each axis.
fn nudges(v: &Vector3<f64>) -> impl Iterator<Item = Vector3<f64>> + '_ {
    (0..6).map(move |i| {
        let mut u = *v;
        u[i / 2] += if i % 2 == 0 { NUDGE } else { -NUDGE };
        u
    })
}

#[test]
fn yp_zero_exact_and_nudged() {
    // y_p = 0: alpha in {0, pi, +-alpha1}, two rho1 at alpha in {0, pi} (Tables I-II).
    let m = machine();
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let mut at_pi = 0;
    let n = 25;
    for i in 0..n {
        for k in 0..n {
            let p = Vector3::new(lin(-700.0, 500.0, n, i), 0.0, lin(500.0, 1600.0, n, k));
            let exact = ik_sols(&m, &p);
            if let Err(e) = ik_round_trip(&m, &p, &mut w) {
                failures.push(e);
            }
            // Every branch at y_p = 0 has alpha in {0, pi} or rho1 = zp (alpha = +-alpha1).
            for (a, rho) in &exact {
                let on_axis = a.abs() <= TRIP_RAD || ang(*a, PI) <= TRIP_RAD;
                if !on_axis && (rho.x - p.z).abs() > TRIP_MM {
                    failures.push(format!(
                        "p={p:?}: branch ({a}, {rho:?}) is not a y_p = 0 one"
                    ));
                }
                at_pi += (ang(*a, PI) <= TRIP_RAD) as usize;
            }
            // Each leg-I posture carries 2 x 2 branches (eqs. (12)-(13)); postures whose legs II
            // or III cannot reach the point carry none (and a leg stretched to h = 0, its two
            // roots listed once, is at none of these points).
            if exact.len() % 4 != 0 {
                failures.push(format!("p={p:?}: {} branches", exact.len()));
            }
            for y in [NUDGE, -NUDGE] {
                let q = Vector3::new(p.x, y, p.z);
                if let Err(e) = ik_round_trip(&m, &q, &mut w) {
                    failures.push(e);
                }
                same_solutions(
                    &format!("IK p={q:?}"),
                    &exact,
                    &ik_sols(&m, &q),
                    &mut failures,
                );
            }
        }
    }
    report("y_p = 0", &w, &failures);
    assert!(at_pi > 0, "no alpha = pi branch met");
}

#[test]
fn r1_cos_alpha_equals_r1_exact_and_nudged() {
    // R1 cos(alpha) = r1: eq. (14) forces rho1 = zp, the ellipse (8) becomes the circle
    // u^2 + y^2 = K1 and the forward elimination's condition (20) fails.
    let m = machine();
    let g = m.module;
    let alpha0 = (g.r_small1 / g.r_big1).acos();
    let k1 = g.l1 * g.l1 - g.r_big1 * g.r_big1 + g.r_small1 * g.r_small1;
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let n = 40;
    for i in 0..n {
        // Points of the circle u = xp + D1 - d1 = +-sqrt(K1 - y^2), u < 0 (in front of leg I);
        // beyond |y| = 450 legs II or III no longer reach it.
        let y = lin(-450.0, 450.0, n, i);
        let x = -(k1 - y * y).sqrt() - g.dx1;
        for z in [600.0, 1000.0, 1400.0] {
            let p = Vector3::new(x, y, z);
            let br = ik::solve(&m, &p);
            for a0 in [alpha0, -alpha0] {
                if !br
                    .iter()
                    .any(|b| ang(b.alpha, a0) <= TRIP_RAD && (b.rho.x - z).abs() <= TRIP_MM)
                {
                    failures.push(format!("p={p:?}: no branch at alpha={a0} with rho1 = zp"));
                }
            }
            if let Err(e) = ik_round_trip(&m, &p, &mut w) {
                failures.push(e);
            }
            let exact = ik_sols(&m, &p);
            for q in nudges(&p) {
                same_solutions(
                    &format!("IK p={q:?}"),
                    &exact,
                    &ik_sols(&m, &q),
                    &mut failures,
                );
            }
            // FK of the joints at alpha0 (condition (20)), exactly and nudged.
            for b in br.iter().filter(|b| ang(b.alpha, alpha0) <= TRIP_RAD) {
                if let Err(e) = fk_round_trip(&m, &b.rho, &mut w) {
                    failures.push(e);
                }
                let exact = fk_sols(&m, &b.rho);
                for r in nudges(&b.rho) {
                    same_solutions(
                        &format!("FK rho={r:?}"),
                        &exact,
                        &fk_sols(&m, &r),
                        &mut failures,
                    );
                }
            }
        }
    }
    report("R1 cos(alpha) = r1", &w, &failures);
}

#[test]
fn rho2_equals_rho3_exact_and_nudged() {
    // rho2 = rho3: condition (21) fails at alpha in {0, pi}.
    let m = machine();
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let n = 30;
    let mut total = 0;
    for i in 0..n {
        for j in 0..n {
            let r = lin(0.0, 1100.0, n, j);
            let rho = Vector3::new(lin(0.0, 1100.0, n, i), r, r);
            match fk_round_trip(&m, &rho, &mut w) {
                Ok(c) => total += c,
                Err(e) => failures.push(e),
            }
            let exact = fk_sols(&m, &rho);
            for q in nudges(&rho) {
                same_solutions(
                    &format!("FK rho={q:?}"),
                    &exact,
                    &fk_sols(&m, &q),
                    &mut failures,
                );
            }
        }
    }
    report("rho2 = rho3", &w, &failures);
    assert!(total > 0);
}

/// The default machine with L3 = L2: legs II and III then mirror each other, and at y_p = 0,
/// alpha = 0 the IK gives rho2 = rho3 exactly, where the linear (y_p, z_p) system of the forward
/// elimination vanishes identically (condition (21) with b = 0): the fully degenerate case.
fn symmetric_machine() -> Machine {
    let text = verne::spec::DEFAULT_MACHINE_TOML.replace("L3 = 950.46", "L3 = 950.30");
    assert_ne!(text, verne::spec::DEFAULT_MACHINE_TOML);
    Machine::from_toml_str(&text, "<symmetric>").expect("valid machine")
}

#[test]
fn rho2_equals_rho3_degenerate_symmetric_machine() {
    let m = symmetric_machine();
    assert_eq!(m.module.l2, m.module.l3);
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let n = 15;
    let mut degenerate = 0;
    for i in 0..n {
        for k in 0..n {
            let p = Vector3::new(lin(-600.0, 400.0, n, i), 0.0, lin(500.0, 1600.0, n, k));
            if let Err(e) = ik_round_trip(&m, &p, &mut w) {
                failures.push(e);
            }
            for b in ik::solve(&m, &p) {
                if b.alpha == 0.0 && b.rho.y == b.rho.z {
                    degenerate += 1;
                }
                if let Err(e) = fk_round_trip(&m, &b.rho, &mut w) {
                    failures.push(e);
                }
                if b.alpha == 0.0 {
                    let exact = fk_sols(&m, &b.rho);
                    for r in nudges(&b.rho) {
                        let what = format!("FK rho={r:?}");
                        same_solutions(&what, &exact, &fk_sols(&m, &r), &mut failures);
                    }
                }
            }
        }
    }
    report("symmetric machine, rho2 = rho3", &w, &failures);
    assert!(degenerate > 0, "no rho2 = rho3 branch at alpha = 0 met");
}

#[test]
fn alpha_pi_exact_and_nudged() {
    // alpha = pi: t = tan(alpha / 2) is infinite. Poses at alpha = pi lie on y_p = 0.
    let m = machine();
    let mut w = Worst::default();
    let mut failures = Vec::new();
    let mut met = 0;
    let n = 25;
    for i in 0..n {
        for k in 0..n {
            let p = Vector3::new(lin(-700.0, 500.0, n, i), 0.0, lin(500.0, 1600.0, n, k));
            for b in ik::solve(&m, &p)
                .iter()
                .filter(|b| ang(b.alpha, PI) <= TRIP_RAD)
            {
                met += 1;
                let modes = fk::solve(&m, &b.rho);
                if !fk_has(&modes, &p, PI, TRIP_RAD, TRIP_MM) {
                    failures.push(format!("rho={:?}: FK misses alpha = pi at {p:?}", b.rho));
                }
                if let Err(e) = fk_round_trip(&m, &b.rho, &mut w) {
                    failures.push(e);
                }
                let exact = fk_sols(&m, &b.rho);
                for r in nudges(&b.rho) {
                    same_solutions(
                        &format!("FK rho={r:?}"),
                        &exact,
                        &fk_sols(&m, &r),
                        &mut failures,
                    );
                }
            }
        }
    }
    report("alpha = pi", &w, &failures);
    assert!(met > 0);
}

// ---------------------------------------------------------------- property tests

proptest! {
    // No regression file: tests/ has no lib.rs for proptest to place it beside; a failure
    // prints its shrunk input instead.
    #![proptest_config(ProptestConfig {
        cases: 512,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn any_pose_ik_branches_exact_and_round_trip(
        x in -800.0f64..600.0,
        y in -700.0f64..700.0,
        z in 300.0f64..1800.0,
    ) {
        let m = machine();
        let mut w = Worst::default();
        let r = ik_round_trip(&m, &Vector3::new(x, y, z), &mut w);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    #[test]
    fn any_joints_fk_modes_exact(
        r1 in -300.0f64..1400.0,
        r2 in -300.0f64..1400.0,
        r3 in -300.0f64..1400.0,
    ) {
        let m = machine();
        let rho = Vector3::new(r1, r2, r3);
        let modes = fk::solve(&m, &rho);
        prop_assert!(modes.iter().filter(|md| md.working()).count() <= 1);
        for md in &modes {
            let r = residual_mm(&m.module, &md.pose, &rho);
            prop_assert!(r < EQ_MM, "rho={:?} mode {:?} residual {:e}", rho, md, r);
            // ... and the mode's IK gives the joints back.
            let br = ik::solve(&m, &md.pose.p);
            prop_assert!(ik_has(&br, md.pose.alpha, &rho, TRIP_RAD, TRIP_MM), "rho={:?} mode {:?}", rho, md);
        }
    }
}
