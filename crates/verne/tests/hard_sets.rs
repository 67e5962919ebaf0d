//! The forward kinematics on poses built ON the solvers' degenerate sets (issue: never lose a
//! real branch): for each constructed pose P with its branch's sliders rho, the assembly modes
//! of rho must contain P, and their certificate must say they are complete. Default machine and
//! ten random valid geometries; `cargo run --release --example hard_sets` runs the full count
//! (docs/reliability.md).

use verne::parallel_module::fk;
use verne::selftest::hard_sets::{
    HardSet, Sampler, Tally, check_fk, check_ik, check_machine_ik, random_geometries,
};
use verne::spec::Machine;

/// Runs `check` on the default machine and ten random valid geometries and asserts: enough
/// poses, none lost, unproved answers rare (at most one per thousand; counted in
/// docs/reliability.md), and the hard path reached.
fn across_machines(
    what: &str,
    seed: u64,
    check: impl Fn(&Machine, &mut Sampler) -> Tally,
    min_poses: u64,
) -> Tally {
    let mut machines = vec![Machine::default_verne()];
    machines.extend(random_geometries(10, seed));
    let mut rng = Sampler::new(seed);
    let mut t = Tally::default();
    for m in &machines {
        t.add(check(m, &mut rng));
    }
    eprintln!(
        "{what}: {} poses, {} lost, {} factored, {} extended, {} unproved",
        t.poses, t.lost, t.factored, t.extended, t.unproved
    );
    assert!(t.poses >= min_poses, "{what}: only {} poses", t.poses);
    assert!(t.lost == 0, "{what}: lost\n{}", t.examples.join("\n"));
    assert!(
        t.unproved * 1000 <= t.poses,
        "{what}: unproved {}\n{}",
        t.unproved,
        t.examples.join("\n")
    );
    t
}

#[test]
fn fk_of_constructed_hard_poses_contains_them() {
    let t = across_machines(
        "module FK",
        2024,
        |m, rng| {
            let mut t = Tally::default();
            for set in HardSet::ALL {
                t.add(check_fk(m, set, 3, rng));
            }
            t
        },
        2000,
    );
    assert!(t.factored + t.extended > t.poses / 20);
}

/// The machine's inverse kinematics on tool poses built on Table II's double root
/// ([`check_machine_ik`]).
#[test]
fn machine_ik_of_constructed_table_ii_poses_contains_the_joints() {
    let t = across_machines("machine IK", 77, |m, rng| check_machine_ik(m, 8, rng), 1000);
    // The construction reaches the hard path: the double root at alpha = 0 is on every pose
    // built at offset 0.
    assert!(t.factored + t.extended > t.poses / 20);
}

/// The module's inverse kinematics on points built on the degenerate sets from the slider side
/// ([`check_ik`]), the cubic (9)'s double root among them.
#[test]
fn ik_of_constructed_hard_points_contains_the_sliders() {
    let t = across_machines(
        "module IK",
        99,
        |m, rng| {
            let mut t = Tally::default();
            for set in HardSet::ALL {
                t.add(check_ik(m, set, 3, rng));
            }
            t
        },
        1000,
    );
    assert!(t.factored + t.extended > 0);
}

/// The examples of the issue: Table III's neighbourhood on the default machine, and the L2 = L3
/// machine at rho1 = (rho2 + rho3) / 2.
#[test]
fn the_reported_triples_give_every_mode() {
    let m = Machine::default_verne();
    for d in [0.0, 1e-6, 1e-4] {
        let rho =
            nalgebra::Vector3::new(923.8484370198487, 967.2529090413111 + d, 876.4439649983864);
        let modes = fk::solve(&m, &rho);
        assert_eq!(modes.len(), 4, "{d}: {modes:?}");
        let w = fk::working(&modes).expect("working mode");
        assert!((w.pose.p - nalgebra::Vector3::new(73.18, 81.79, 1731.55)).amax() < 0.01);
        assert!(modes.certificate.proved());
    }
    let mut sym = Machine::default_verne();
    sym.module.l3 = sym.module.l2;
    for d in [0.0, 1e-10] {
        let rho = nalgebra::Vector3::new(
            233.71565344591758 + d,
            230.40202084462968,
            237.02928614720548,
        );
        let modes = fk::solve(&sym, &rho);
        assert_eq!(modes.len(), 4, "{d}: {modes:?}");
        assert!(fk::working(&modes).is_some());
        assert!(modes.certificate.proved());
    }
}

/// Where condition (21) (Det = 0), b = 0 and a tangent of leg I (Delta = 0: the two tau of
/// eq. (10) on the line of eq. (14) are equal) meet at one alpha, two assembly modes merge at a
/// zero of Det, and both factors of F lose their square root's smoothness. Four slider
/// triples of the default machine do this (`DET_B_DELTA_ZERO`, rho1 = 0; checked here to vanish
/// to 1e-9 of their scales), shifted along rho2 by d from -1e-6 to 1e-6 mm and along all three
/// sliders by 0, 300 and 1,700 mm. At 50 digits
/// (the minimum of F next to alpha) each shift of 1e-10 mm or more has two modes on one side
/// and none on the other; the solver must agree, and within 1e-12 mm give at most two, every
/// answer proved and every mode within 1e-9 mm of closing.
#[test]
fn where_condition_21_meets_a_tangent_of_leg_i_both_modes_are_found() {
    use verne::parallel_module::equations::residual_mm;
    use verne::parallel_module::ik::wrap_angle;
    let m = Machine::default_verne();
    let g = &m.module;
    let (r, rr, r2, r4) = (g.r_big1, g.r_small1, g.r_big2, g.r4);
    let delta = g.dx2 - g.dx1;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    for (p2, p3, alpha) in verne::selftest::hard_sets::DET_B_DELTA_ZERO {
        // The forms of the elimination (fk_certify's module documentation) at alpha.
        let (s, c) = f64::sin_cos(alpha);
        let b = g.l3 * g.l3 - g.l2 * g.l2 + (p2 + p3) * (p2 - p3) + 2.0 * r2 * (p2 + p3) * s;
        let det = 2.0 * (p2 - p3) * (r * c - rr) + 4.0 * (r * r4 - rr * r2) * s;
        let a = g.l2 * g.l2 - k0 - delta * delta - r2 * r2 - r4 * r4 - p2 * p2
            + 2.0 * (r2 * r4 - r * rr) * c
            - 2.0 * r2 * p2 * s;
        let q = (r * c - rr) * p2 + (r * r4 - rr * r2) * s;
        let n = r * r + rr * rr - 2.0 * r * rr * c;
        let k1 = k0 + 2.0 * r * rr * c;
        let p4 = q * q + delta * delta * n;
        let disc = 4.0 * k1 * p4 - n * a * a;
        assert!(
            det.abs() < 1e-9 * 4.0 * (r * r4 - rr * r2).abs(),
            "Det {det}"
        );
        assert!(b.abs() < 1e-9 * (p2 * p2 + g.l2 * g.l2), "b {b}");
        assert!(
            disc.abs() < 1e-9 * (4.0 * k1.abs() * p4 + n * a * a),
            "Delta {disc}"
        );
        for rho1 in [0.0, 300.0, 1700.0] {
            let near = |d: f64| {
                let rho = nalgebra::Vector3::new(rho1, rho1 + p2 + d, rho1 + p3);
                let modes = fk::solve(&m, &rho);
                assert!(
                    modes.certificate.proved(),
                    "{rho:?}: {:?}",
                    modes.certificate
                );
                let near: Vec<_> = modes
                    .iter()
                    .filter(|x| wrap_angle(x.pose.alpha - alpha).abs() < 1e-3)
                    .collect();
                for x in &near {
                    assert!(residual_mm(g, &x.pose, &rho) < 1e-9, "{rho:?}: {x:?}");
                }
                near.len()
            };
            for d in [1e-10, 1e-8, 1e-6] {
                let (up, down) = (near(d), near(-d));
                assert!(
                    up + down == 2 && up * down == 0,
                    "{p2} {rho1} {d}: {up} {down}"
                );
            }
            for d in [0.0, 1e-12, -1e-12] {
                assert!(near(d) <= 2, "{p2} {rho1} {d}");
            }
        }
    }
}
