//! The real machine's offsets from its drawing, as a machine file gives them (`[zeros]`,
//! `table.y_t`): every solver answers in the joints the controller reads.
//!
//! The truths here do not come from the code under test: a machine with zero offsets z must
//! answer, for every query, what the same machine without them answers with its joints moved by
//! z and its limits with them (a machine built by hand in this file); and the rotary axis's
//! offset y_t is checked against the transform of eq. (7), AIM 2007, written out here.

use std::f64::consts::PI;

use nalgebra::{Matrix4, Vector3, Vector4};
use verne::details::{FkTracker, lcg};
use verne::machine::{
    PreviousJoints, ToolPose, continue_branch, machine_fk, machine_ik, tool_pose_eq26,
};
use verne::parallel_module::equations::{ModulePose, Sliders};
use verne::parallel_module::fk::{self, FkModes};
use verne::parallel_module::ik::{self, IkBranches, wrap_angle};
use verne::parallel_module::kinetostatics::kinetostatics;
use verne::spec::{DEFAULT_MACHINE_TOML, Machine};

/// Two answers of the same equations, one with its joints moved: rounding only (mm, rad).
const SAME_MM: f64 = 1e-9;
const SAME_RAD: f64 = 1e-12;

/// The offsets used throughout: sliders (mm), table angles (degrees), rotary axis (mm).
const RHO_ZERO: [f64; 3] = [0.31, -0.27, 0.45];
const THETA_ZERO_DEG: [f64; 2] = [0.2, -0.15];
const Y_T: f64 = 0.4;

/// The default machine with the offsets, read from a machine file.
fn with_zeros() -> Machine {
    let text = format!(
        "base = \"verne\"\n[zeros]\nrho1 = {}\nrho2 = {}\nrho3 = {}\ntheta1 = {}\ntheta2 = {}\n[table]\ny_t = {Y_T}\n",
        RHO_ZERO[0], RHO_ZERO[1], RHO_ZERO[2], THETA_ZERO_DEG[0], THETA_ZERO_DEG[1]
    );
    Machine::from_toml_str(&text, "zeros.toml").expect("a valid machine file")
}

/// The same machine without zero offsets, its limits moved by them by hand: its joints are the
/// equations' variables.
fn by_hand() -> Machine {
    let mut m = Machine::default_verne();
    m.table.y_t = Y_T;
    for (k, z) in RHO_ZERO.iter().enumerate() {
        m.limits.rho_min[k] += z;
        m.limits.rho_max[k] += z;
    }
    m.limits.theta1_min += THETA_ZERO_DEG[0].to_radians();
    m.limits.theta1_max += THETA_ZERO_DEG[0].to_radians();
    m
}

fn moved(rho: &Sliders) -> Sliders {
    rho + Sliders::from(RHO_ZERO)
}

/// Platform points over the default machine's workspace, with some beyond it.
fn points(n: usize, seed: u64) -> Vec<Vector3<f64>> {
    let mut u = lcg(seed);
    (0..n)
        .map(|_| {
            Vector3::new(
                -400.0 + 300.0 * u(),
                -200.0 + 400.0 * u(),
                900.0 + 400.0 * u(),
            )
        })
        .collect()
}

#[test]
fn a_file_gives_the_offsets_and_checks_them() {
    let m = with_zeros();
    assert_eq!(m.module.rho_zero, RHO_ZERO);
    assert!((m.table.theta_zero[0] - THETA_ZERO_DEG[0].to_radians()).abs() < 1e-15);
    assert_eq!(m.table.y_t, Y_T);
    assert!(m.has_zeros());
    // Absent, they are zero: the embedded file has none.
    let d = Machine::default_verne();
    assert!(!d.has_zeros());
    assert_eq!(
        (d.module.rho_zero, d.table.theta_zero, d.table.y_t),
        ([0.0; 3], [0.0; 2], 0.0)
    );
    // to_toml writes them back, and a machine without them writes none.
    assert_eq!(Machine::from_toml_str(&m.to_toml(), "again").unwrap(), m);
    assert!(!d.to_toml().contains("[zeros]") && !d.to_toml().contains("y_t"));
    // A zero offset larger than the stroke, an angle beyond 180 degrees and a text are refused
    // at their lines.
    for (text, key, line) in [
        ("base = \"verne\"\n[zeros]\nrho2 = 2000\n", "zeros.rho2", 3),
        (
            "base = \"verne\"\n[zeros]\n\ntheta2 = 190\n",
            "zeros.theta2",
            4,
        ),
        ("base = \"verne\"\n[table]\ny_t = \"x\"\n", "table.y_t", 3),
    ] {
        let e = Machine::from_toml_str(text, "bad.toml").unwrap_err();
        assert_eq!(e.problems.len(), 1, "{e}");
        assert_eq!(
            (e.problems[0].key.as_str(), e.problems[0].line),
            (key, Some(line)),
            "{e}"
        );
    }
    // A typo names the key it may be.
    let e = Machine::from_toml_str("base = \"verne\"\n[zeros]\nRho1 = 1\n", "t").unwrap_err();
    assert!(e.to_string().contains("did you mean `zeros.rho1`"), "{e}");
    // The default file's text is unchanged by the optional keys.
    assert!(!DEFAULT_MACHINE_TOML.contains("[zeros]"));
}

/// The module's inverse kinematics: every branch's sliders plus the zero offsets are the hand
/// machine's, with the same verdicts (limits included), by every entry point.
#[test]
fn module_inverse_kinematics_answers_in_joints() {
    let (m, h) = (with_zeros(), by_hand());
    let pts = points(400, 0x2e20_0001);
    let mut checked = 0;
    for p in &pts {
        let (a, b) = (ik::solve(&m, p), ik::solve(&h, p));
        assert_eq!(a.len(), b.len(), "{p}");
        assert_eq!(a.certificate, b.certificate);
        for (x, y) in a.iter().zip(b.iter()) {
            assert!((moved(&x.rho) - y.rho).amax() < SAME_MM, "{p}: {x:?} {y:?}");
            assert!((x.alpha - y.alpha).abs() < SAME_RAD);
            assert_eq!((x.config, x.verdict), (y.config, y.verdict), "{p}");
            checked += 1;
        }
        if let Some(w) = ik::working_fast(&m, p) {
            let v = ik::working(&b).expect("the hand machine's working branch");
            assert!((moved(&w.rho) - v.rho).amax() < SAME_MM, "{p}");
        }
    }
    assert!(checked > 1000, "{checked}");
    // The batched kernels: the same lists as one point at a time.
    let mut every = vec![IkBranches::new(); pts.len()];
    let mut working = vec![IkBranches::new(); pts.len()];
    ik::solve_each(&m, pts.iter().copied().zip(every.iter_mut()));
    ik::solve_working_each(&m, pts.iter().copied().zip(working.iter_mut()));
    for (k, p) in pts.iter().enumerate() {
        let one = ik::solve(&m, p);
        assert_eq!(every[k].len(), one.len());
        for (x, y) in every[k].iter().zip(one.iter()) {
            assert_eq!(x.rho, y.rho);
        }
        match (ik::working(&working[k]), ik::working(&one)) {
            (Some(x), Some(y)) => assert!((x.rho - y.rho).amax() < SAME_MM),
            (None, None) => {}
            other => panic!("{p}: {other:?}"),
        }
    }
}

/// The module's forward kinematics: the joints plus the zero offsets are the hand machine's
/// sliders (the same modes and verdicts), also when tracked along a path.
#[test]
fn module_forward_kinematics_reads_joints() {
    let (m, h) = (with_zeros(), by_hand());
    let mut tracker = FkTracker::new(&m);
    let mut out = FkModes::new();
    let mut working = 0;
    for p in points(200, 0x2e20_0002) {
        let Some(b) = ik::working(&ik::solve(&m, &p)).copied() else {
            continue;
        };
        let (a, c) = (fk::solve(&m, &b.rho), fk::solve(&h, &moved(&b.rho)));
        assert_eq!(a.len(), c.len());
        for (x, y) in a.iter().zip(c.iter()) {
            assert!(
                (x.pose.p - y.pose.p).amax() < SAME_MM
                    && (x.pose.alpha - y.pose.alpha).abs() < SAME_RAD
            );
            assert_eq!(x.verdict, y.verdict);
        }
        let w = fk::working(&a).expect("a working mode");
        assert!((w.pose.p - p).amax() < SAME_MM, "{p}: {w:?}");
        tracker.working_into(&b.rho, &mut out);
        let t = fk::working(&out).expect("tracked");
        assert!((t.pose.p - p).amax() < SAME_MM, "{p}");
        // The Jacobians read the joints too.
        let pose = ModulePose { p, alpha: b.alpha };
        let (k1, k2) = (
            kinetostatics(&m.module, &pose, &b.rho),
            kinetostatics(&h.module, &pose, &moved(&b.rho)),
        );
        assert_eq!(format!("{k1:?}"), format!("{k2:?}"));
        working += 1;
    }
    assert!(working > 50, "{working}");
}

/// The table's transform with its rotary axis at y_t, written out: bT_t = trans(z, d_a)
/// rot(x, theta1) trans(y, y_t) trans(z, d_t) rot(x, pi) rot(z, theta2), the joints' angles
/// plus their zero offsets.
fn table_by_hand(m: &Machine, theta1: f64, theta2: f64) -> Matrix4<f64> {
    let rx = |a: f64| Matrix4::from_scaled_axis(Vector3::x() * a);
    let rz = |a: f64| Matrix4::from_scaled_axis(Vector3::z() * a);
    let t = |x: f64, y: f64, z: f64| Matrix4::new_translation(&Vector3::new(x, y, z));
    t(0.0, 0.0, m.table.d_a)
        * rx(theta1 + THETA_ZERO_DEG[0].to_radians())
        * t(0.0, Y_T, m.table.d_t)
        * rx(PI)
        * rz(theta2 + THETA_ZERO_DEG[1].to_radians())
}

/// The machine: its inverse kinematics gives the joints of the tool pose (the tool tip by the
/// hand transform is the pose's), its forward kinematics gives the pose back, and the
/// continuation continues joints.
#[test]
fn machine_kinematics_answer_in_joints() {
    let m = with_zeros();
    let mut u = lcg(0x2e20_0003);
    let mut solved = 0;
    let mut scratch = verne::machine::MachineIkBranches::new();
    for _ in 0..300 {
        let pose = ToolPose {
            tip: Vector3::new(120.0 * u() - 60.0, 120.0 * u() - 60.0, 80.0 * u() - 20.0),
            phi1: (40.0 * u() - 20.0f64).to_radians(),
            phi2: 2.0 * PI * u() - PI,
        };
        let branches = machine_ik(&m, &pose, m.tool_length);
        for b in branches.iter().filter(|b| b.working()) {
            // The platform's tool tip, seen from the table at the joints' angles.
            let tip_base =
                b.platform + m.tool_length * Vector3::new(0.0, -b.alpha.sin(), b.alpha.cos());
            let t = table_by_hand(&m, b.theta1, b.theta2);
            let tip =
                t.try_inverse().unwrap() * Vector4::new(tip_base.x, tip_base.y, tip_base.z, 1.0);
            assert!((tip.xyz() - pose.tip).amax() < SAME_MM, "{pose:?}: {b:?}");
            // The sliders are the joints: the module's inverse of the platform point.
            let module = ik::working(&ik::solve(&m, &b.platform))
                .copied()
                .expect("module branch");
            assert!((module.rho - b.rho).amax() < SAME_MM);
            // Forward, from the joints.
            let modes = machine_fk(&m, &b.rho, b.theta1, b.theta2, m.tool_length);
            let back = modes.iter().find(|f| f.working()).expect("a working mode");
            assert!((back.tool.tip - pose.tip).amax() < SAME_MM);
            assert!(wrap_angle(back.tool.phi2 - pose.phi2).abs() < SAME_RAD * 1e3);
            let eq26 = tool_pose_eq26(&m.table, &back.module, b.theta1, b.theta2, m.tool_length);
            assert!((eq26.tip - pose.tip).amax() < SAME_MM);
            // From joints nearby, the continuation gives these joints.
            let prev = PreviousJoints {
                rho: b.rho + Sliders::new(0.01, -0.02, 0.01),
                theta1: b.theta1 + 1e-4,
            };
            let c = continue_branch(&m, &pose, m.tool_length, &prev, &mut scratch);
            let c = c.answer.expect("continued");
            assert!(
                (c.rho - b.rho).amax() < SAME_MM && (c.theta1 - b.theta1).abs() < SAME_RAD * 1e3
            );
            solved += 1;
        }
    }
    assert!(solved > 100, "{solved}");
}
