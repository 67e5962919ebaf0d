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
