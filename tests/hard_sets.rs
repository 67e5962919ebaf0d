//! The forward kinematics on poses built ON the solvers' degenerate sets (issue: never lose a
//! real branch): for each constructed pose P with its branch's sliders rho, the assembly modes
//! of rho must contain P, and their certificate must say they are complete. Default machine and
//! ten random valid geometries; `cargo run --release --example hard_sets` runs the full count
//! (docs/reliability.md).

mod common;

use verne::hard_sets::{
    HardSet, Sampler, Tally, check_fk, check_ik, check_machine_ik, random_geometries,
};
use verne::machine::Machine;
use verne::module_fk;

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
        let modes = module_fk::solve(&m, &rho);
        assert_eq!(modes.len(), 4, "{d}: {modes:?}");
        let w = module_fk::working(&modes).expect("working mode");
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
        let modes = module_fk::solve(&sym, &rho);
        assert_eq!(modes.len(), 4, "{d}: {modes:?}");
        assert!(module_fk::working(&modes).is_some());
        assert!(modes.certificate.proved());
    }
}

/// The 11-row path, 0.002 mm steps of rho2 across the thin set of the default machine:
/// `verne fk` gives the working mode on every row (tracked or solved), and `verne verify` of the
/// machine joints against the tool poses `verne fk` computes for them is clean (no false
/// `branch` finding).
#[test]
fn a_path_across_the_thin_set_is_ok_in_fk_and_verify() {
    let rows: Vec<[f64; 3]> = (-5..=5)
        .map(|k| {
            [
                923.8484370198487,
                967.2529090413111 + 0.002 * k as f64,
                876.4439649983864,
            ]
        })
        .collect();
    let module: String = std::iter::once("rho1,rho2,rho3\n".to_string())
        .chain(
            rows.iter()
                .map(|r| format!("{:?},{:?},{:?}\n", r[0], r[1], r[2])),
        )
        .collect();
    let out = common::run(&["fk"], Some(&module));
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (h, cells) = common::table_of(&out);
    let status = common::col(&h, "status");
    assert_eq!(cells.len(), 11);
    assert!(cells.iter().all(|r| r[status] == "ok"), "{cells:?}");
    // The library's tracker along the same rows: the working mode on every row.
    let m = Machine::default_verne();
    let mut tracker = verne::fk_track::FkTracker::new(&m);
    let mut modes = module_fk::FkModes::new();
    for r in &rows {
        tracker.working_into(&nalgebra::Vector3::new(r[0], r[1], r[2]), &mut modes);
        assert!(module_fk::working(&modes).is_some(), "{r:?}");
    }
    // Machine joints (theta1 = theta2 = 0), their tool poses, and verify.
    let dir = std::env::temp_dir().join(format!("verne-thin-set-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let joints: String = std::iter::once("id,t,rho1,rho2,rho3,theta1,theta2\n".to_string())
        .chain(rows.iter().enumerate().map(|(k, r)| {
            format!(
                "{},{},{:?},{:?},{:?},0,0\n",
                k + 1,
                0.01 * k as f64,
                r[0],
                r[1],
                r[2]
            )
        }))
        .collect();
    let jpath = dir.join("joints.csv");
    std::fs::write(&jpath, &joints).unwrap();
    let fk = common::run(&["fk", jpath.to_str().unwrap()], None);
    assert_eq!(fk.status.code(), Some(0));
    let (h, cells) = common::table_of(&fk);
    let cols = ["id", "x", "y", "z", "i", "j", "k"].map(|c| common::col(&h, c));
    let path: String = std::iter::once("id,x,y,z,i,j,k\n".to_string())
        .chain(cells.iter().map(|r| {
            let v: Vec<&str> = cols.iter().map(|&c| r[c].as_str()).collect();
            format!("{}\n", v.join(","))
        }))
        .collect();
    let ppath = dir.join("path.csv");
    std::fs::write(&ppath, &path).unwrap();
    let verify = common::run(
        &[
            "verify",
            "--joints",
            jpath.to_str().unwrap(),
            "--path",
            ppath.to_str().unwrap(),
        ],
        None,
    );
    let text = String::from_utf8_lossy(&verify.stdout).to_string()
        + &String::from_utf8_lossy(&verify.stderr);
    assert_eq!(verify.status.code(), Some(0), "{text}");
    assert!(text.contains("clean"), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `verne selftest` tells the truth: the L2 = L3 machine of the issue passes (its degenerate
/// sets sampled too), and a machine on which nothing can be assembled within its strokes fails,
/// saying that nothing was tested.
#[test]
fn selftest_samples_the_hard_sets_and_fails_when_nothing_is_tested() {
    let dir = std::env::temp_dir().join(format!("verne-selftest-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let show = common::run(&["machine", "show"], None);
    let text = String::from_utf8(show.stdout).unwrap();
    let sym = text
        .lines()
        .map(|l| {
            if l.starts_with("L3 =") {
                "L3 = 950.30"
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let sym_path = dir.join("sym.toml");
    std::fs::write(&sym_path, &sym).unwrap();
    let out = common::run(&["selftest", "-m", sym_path.to_str().unwrap()], None);
    let report = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(out.status.code(), Some(0), "{report}");
    assert!(report.contains("PASS"), "{report}");
    let line = report
        .lines()
        .find(|l| l.starts_with("poses on degenerate sets"))
        .unwrap();
    let n: u64 = line.split_whitespace().nth(4).unwrap().parse().unwrap();
    assert!(n > 100, "{line}");
    // Slider II 5 m above the others: the rods cannot close, no mode anywhere.
    let far: Vec<String> = text
        .lines()
        .map(|l| match l.split('=').next().map(str::trim) {
            Some("rho1_min") | Some("rho3_min") => {
                format!("{} = 0.0", l.split('=').next().unwrap())
            }
            Some("rho1_max") | Some("rho3_max") => {
                format!("{} = 1.0", l.split('=').next().unwrap())
            }
            Some("rho2_min") => "rho2_min = 5000.0".to_string(),
            Some("rho2_max") => "rho2_max = 5001.0".to_string(),
            _ => l.to_string(),
        })
        .collect();
    let far_path = dir.join("far.toml");
    std::fs::write(&far_path, far.join("\n")).unwrap();
    let out = common::run(&["selftest", "-m", far_path.to_str().unwrap()], None);
    let report =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{report}");
    assert!(report.contains("FAIL: no assembly mode"), "{report}");
    std::fs::remove_dir_all(&dir).ok();
}
