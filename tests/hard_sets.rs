//! The forward kinematics on poses built ON the solvers' degenerate sets (issue: never lose a
//! real branch): for each constructed pose P with its branch's sliders rho, the assembly modes
//! of rho must contain P, and their certificate must say they are complete. Default machine and
//! ten random valid geometries; `cargo run --release --example hard_sets` runs the full count
//! (docs/reliability.md).

use verne::hard_sets::{HardSet, Sampler, construct, random_geometries, random_start};
use verne::machine::Machine;
use verne::module_fk::{self, Certificate};
use verne::module_ik::wrap_angle;

/// A mode matches the constructed pose within these (mm, rad): the pose's own accuracy is that
/// of the inverse kinematics, about 1e-12 mm.
const MATCH_MM: f64 = 1e-6;
const MATCH_RAD: f64 = 1e-8;
/// The same at a parallel singularity (see the test).
const FOLD_MATCH_MM: f64 = 1e-4;
const FOLD_MATCH_RAD: f64 = 1e-6;
const FOLD_ROUNDING_OFFSET_MM: f64 = 1e-5;

#[derive(Default, Debug)]
struct Tally {
    poses: usize,
    lost: Vec<String>,
    factored: usize,
    extended: usize,
    unproved: Vec<String>,
}

fn check_machine(m: &Machine, starts_per_set: usize, seed: u64, t: &mut Tally) {
    let mut rng = Sampler::new(seed);
    for set in HardSet::ALL {
        let mut built = 0;
        let mut tries = 0;
        while built < starts_per_set && tries < 20 * starts_per_set {
            tries += 1;
            let Some((p0, b)) = random_start(m, &mut rng) else {
                continue;
            };
            let dir = rng.direction();
            let poses = construct(m, set, &p0, &dir, &b, 300.0);
            if poses.is_empty() {
                continue;
            }
            built += 1;
            for c in poses {
                t.poses += 1;
                let modes = module_fk::solve(m, &c.rho);
                // At a parallel singularity the pose is determined by the sliders only to the
                // square root of their rounding (two modes meet: about 1e-5 mm), and the line
                // through P maps to a curve of sliders tangent to the fold, which stays within
                // rounding of it up to offsets of about 1e-5 mm: there the two modes may be
                // a pair or none for the rounded sliders, and either is correct when proved.
                let fold = set == HardSet::ParallelSingularity;
                let (mm, rad) = if fold {
                    (FOLD_MATCH_MM, FOLD_MATCH_RAD)
                } else {
                    (MATCH_MM, MATCH_RAD)
                };
                let found = modes.iter().any(|f| {
                    (f.pose.p - c.p).amax() < mm && wrap_angle(f.pose.alpha - c.alpha).abs() < rad
                }) || (fold
                    && c.offset_mm.abs() <= FOLD_ROUNDING_OFFSET_MM
                    && modes.certificate.proved());
                let what = format!(
                    "{} {:?} offset {:e}: rho = ({:?}, {:?}, {:?}), P = {:?}, alpha = {:?}",
                    m.name, set, c.offset_mm, c.rho.x, c.rho.y, c.rho.z, c.p, c.alpha
                );
                if !found {
                    t.lost.push(what.clone());
                }
                match modes.certificate {
                    Certificate::Double => {}
                    Certificate::Factored => t.factored += 1,
                    Certificate::Extended => t.extended += 1,
                    _ => t.unproved.push(what),
                }
            }
        }
    }
}

#[test]
fn fk_of_constructed_hard_poses_contains_them() {
    let mut t = Tally::default();
    check_machine(&Machine::default_verne(), 6, 1, &mut t);
    for (k, m) in random_geometries(10, 2024).iter().enumerate() {
        check_machine(m, 3, 100 + k as u64, &mut t);
    }
    eprintln!(
        "{} constructed poses: {} lost, {} factored, {} extended, {} unproved",
        t.poses,
        t.lost.len(),
        t.factored,
        t.extended,
        t.unproved.len()
    );
    assert!(t.poses > 2000, "only {} poses", t.poses);
    assert!(t.lost.is_empty(), "lost modes:\n{}", t.lost.join("\n"));
    // Unproved rows must be rare (and are counted in docs/reliability.md).
    assert!(
        t.unproved.len() * 1000 <= t.poses,
        "unproved: {}\n{}",
        t.unproved.len(),
        t.unproved
            .iter()
            .take(10)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
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

/// The machine's inverse kinematics on tool poses whose theta1 equation (15) has its double root
/// (Table II of IFToMM 2007 along the pose: at the theta1 where alpha = 0 the platform point has
/// y_p = 0, and rho1 - z_p takes both signs), and next to it: the platform point P = (x, offset,
/// z) with a module branch at alpha near 0, any theta1 and theta2, the tool pose from eq. (26) of
/// AIM 2007. The machine IK of that pose must contain the joints, with a proved certificate.
#[test]
fn machine_ik_of_constructed_table_ii_poses_contains_the_joints() {
    use verne::machine_kin::{machine_ik, tool_pose_eq26};
    use verne::module_geometry::ModulePose;
    use verne::module_ik;
    let mut machines = vec![Machine::default_verne()];
    machines.extend(random_geometries(10, 77));
    let (mut poses, mut lost, mut unproved) = (0usize, Vec::new(), Vec::new());
    let (mut factored, mut extended) = (0usize, 0usize);
    let mut rng = Sampler::new(5);
    for m in &machines {
        let mut built = 0;
        for _ in 0..400 {
            if built >= 8 {
                break;
            }
            let Some((p0, _)) = random_start(m, &mut rng) else {
                continue;
            };
            let (theta1, theta2) = (
                rng.uniform(m.limits.theta1_min, m.limits.theta1_max),
                rng.uniform(-3.0, 3.0),
            );
            let mut any = false;
            for off in verne::hard_sets::OFFSETS_MM {
                let p = nalgebra::Vector3::new(p0.x, off, p0.z);
                for b in module_ik::solve(m, &p) {
                    if b.alpha.abs() > 0.1 {
                        continue;
                    }
                    any = true;
                    poses += 1;
                    let module = ModulePose { p, alpha: b.alpha };
                    let tool = tool_pose_eq26(&m.table, &module, theta1, theta2, m.tool_length);
                    let ik = machine_ik(m, &tool, m.tool_length);
                    let found = ik.iter().any(|x| {
                        (x.rho - b.rho).amax() < MATCH_MM
                            && wrap_angle(x.theta1 - theta1).abs() < MATCH_RAD
                    });
                    let what = format!(
                        "{}: P = {p:?}, alpha = {:?}, rho = {:?}, theta1 = {theta1:?}, theta2 = {theta2:?}",
                        m.name, b.alpha, b.rho
                    );
                    if !found {
                        lost.push(what.clone());
                    }
                    match ik.certificate {
                        Certificate::Double => {}
                        Certificate::Factored => factored += 1,
                        Certificate::Extended => extended += 1,
                        _ => unproved.push(what),
                    }
                }
            }
            built += usize::from(any);
        }
    }
    eprintln!(
        "{poses} machine poses: {} lost, {factored} factored, {extended} extended, {} unproved",
        lost.len(),
        unproved.len()
    );
    // The construction reaches the hard path: the double root at alpha = 0 is on every pose
    // built at offset 0.
    assert!(
        factored + extended > poses / 20,
        "{factored} + {extended} of {poses}"
    );
    assert!(poses > 300, "only {poses}");
    assert!(lost.is_empty(), "lost:\n{}", lost.join("\n"));
    assert!(
        unproved.len() * 1000 <= poses,
        "unproved:\n{}",
        unproved.join("\n")
    );
}

/// The inverse kinematics of the module on points built on the degenerate sets from the other
/// side: sliders moved along a line while an assembly mode is followed, to the zero of the
/// vanishing quantity at the mode (the cubic (9)'s double root among them: two leg-I postures
/// meet). The branches of the mode's point must contain the sliders, with a proved certificate.
#[test]
fn ik_of_constructed_hard_points_contains_the_sliders() {
    use verne::hard_sets::{construct_from_sliders, random_slider_start};
    use verne::module_ik;
    let mut machines = vec![Machine::default_verne()];
    machines.extend(random_geometries(10, 99));
    let (mut poses, mut lost, mut unproved) = (0usize, Vec::new(), Vec::new());
    let (mut factored, mut extended) = (0usize, 0usize);
    let mut rng = Sampler::new(11);
    for m in &machines {
        for set in HardSet::ALL {
            let mut built = 0;
            for _ in 0..60 {
                if built >= 3 {
                    break;
                }
                let Some((rho0, mode)) = random_slider_start(m, &mut rng) else {
                    continue;
                };
                let dir = rng.direction();
                let cs = construct_from_sliders(m, set, &rho0, &dir, &mode, 300.0);
                if cs.is_empty() {
                    continue;
                }
                built += 1;
                for c in cs {
                    poses += 1;
                    let ik = module_ik::solve(m, &c.p);
                    // A fold of the inverse kinematics (two postures meet) fixes the sliders
                    // only to the square root of the point's rounding, as a parallel
                    // singularity fixes the pose (see the forward kinematics' test).
                    let fold = set == HardSet::Cubic9DoubleRoot;
                    let (mm, rad) = if fold {
                        (FOLD_MATCH_MM, FOLD_MATCH_RAD)
                    } else {
                        (MATCH_MM, MATCH_RAD)
                    };
                    let found = ik.iter().any(|b| {
                        (b.rho - c.rho).amax() < mm && wrap_angle(b.alpha - c.alpha).abs() < rad
                    }) || (fold
                        && c.offset_mm.abs() <= FOLD_ROUNDING_OFFSET_MM
                        && ik.certificate.proved());
                    let what = format!(
                        "{} {:?} offset {:e}: P = {:?}, alpha = {:?}, rho = {:?}",
                        m.name, set, c.offset_mm, c.p, c.alpha, c.rho
                    );
                    if !found {
                        lost.push(what.clone());
                    }
                    match ik.certificate {
                        Certificate::Double => {}
                        Certificate::Factored => factored += 1,
                        Certificate::Extended => extended += 1,
                        _ => unproved.push(what),
                    }
                }
            }
        }
    }
    eprintln!(
        "{poses} points: {} lost, {factored} factored, {extended} extended, {} unproved",
        lost.len(),
        unproved.len()
    );
    assert!(poses > 1000, "only {poses}");
    assert!(lost.is_empty(), "lost:\n{}", lost.join("\n"));
    assert!(
        unproved.len() * 1000 <= poses,
        "unproved:\n{}",
        unproved.join("\n")
    );
}
