//! `verne modes --tool` and `--machine-joints`: every branch of the 5-axis machine for one query,
//! checked against the other direction's solver (each inverse branch's joints, through the
//! machine's forward kinematics, give back the tool pose), against `verne ik --all` and `verne fk
//! --all` on the same query, and on a pose built from known joints.

use crate::common;

use common::{col, num, run, table};
use verne::machine::fk::machine_fk;
use verne::parallel_module::equations::Sliders;
use verne::spec::Machine;

/// Tip tolerance (mm) and axis tolerance of a round trip through the other solver.
const TIP_TOL_MM: f64 = 1e-7;
const AXIS_TOL: f64 = 1e-9;

fn stdout(args: &[&str]) -> (Option<i32>, String, String) {
    let out = run(args, None);
    (
        out.status.code(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// A tool pose made from joints of the machine's working branch: the machine's forward
/// kinematics of (rho, theta1, theta2).
fn pose_from_joints(rho: [f64; 3], theta1_deg: f64, theta2_deg: f64) -> [f64; 6] {
    let m = Machine::default_verne();
    let modes = machine_fk(
        &m,
        &Sliders::new(rho[0], rho[1], rho[2]),
        theta1_deg.to_radians(),
        theta2_deg.to_radians(),
        m.tool_length,
    );
    let w = modes.iter().find(|md| md.working()).expect("working mode");
    let (t, a) = (w.tool.tip, w.axis);
    [t.x, t.y, t.z, a.x, a.y, a.z]
}

fn csv_arg(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(",")
}

#[test]
fn every_inverse_branch_of_a_tool_pose_returns_it_through_the_forward_kinematics() {
    let m = Machine::default_verne();
    let joints = ([330.0, 280.0, 300.0], 12.5, -37.0);
    let pose = pose_from_joints(joints.0, joints.1, joints.2);
    let arg = csv_arg(&pose);
    let (code, text, err) = stdout(&["modes", "--csv", &format!("--tool={arg}")]);
    assert_eq!(code, Some(0), "{err}");
    let (h, rows) = table(&text);
    assert!(rows.len() >= 8, "{text}");
    let mut found_the_joints = false;
    for r in &rows {
        let rho = Sliders::new(
            num(&r[col(&h, "rho1")]),
            num(&r[col(&h, "rho2")]),
            num(&r[col(&h, "rho3")]),
        );
        let (t1, t2) = (
            num(&r[col(&h, "theta1_deg")]),
            num(&r[col(&h, "theta2_deg")]),
        );
        let config: Vec<i8> = ["s1", "s2", "s3"]
            .iter()
            .map(|c| r[col(&h, c)].parse().unwrap())
            .collect();
        // The forward kinematics of the branch's joints has a mode with its configuration whose
        // tool pose is the query.
        let back = machine_fk(&m, &rho, t1.to_radians(), t2.to_radians(), m.tool_length);
        let hit = back.iter().any(|md| {
            md.config.iter().copied().eq(config.iter().copied())
                && (0..3).all(|k| (md.tool.tip[k] - pose[k]).abs() < TIP_TOL_MM)
                && (0..3).all(|k| (md.axis[k] - pose[3 + k]).abs() < AXIS_TOL)
        });
        assert!(hit, "branch {} does not return the pose: {r:?}", r[0]);
        if (rho.x - joints.0[0]).abs() < 1e-6
            && (rho.y - joints.0[1]).abs() < 1e-6
            && (rho.z - joints.0[2]).abs() < 1e-6
            && (t1 - joints.1).abs() < 1e-6
            && (t2 - joints.2).abs() < 1e-6
        {
            found_the_joints = true;
            assert_eq!(r[col(&h, "working")], "true");
            assert_eq!(r[col(&h, "status")], "ok");
        }
    }
    assert!(
        found_the_joints,
        "the joints the pose was built from are not listed:\n{text}"
    );
}

#[test]
fn tool_branches_are_those_of_ik_all() {
    let pose = "80,0,30,0.342020,0,0.939693";
    let (code, text, _) = stdout(&["modes", "--csv", "--tool", pose]);
    assert_eq!(code, Some(0));
    let (h, rows) = table(&text);
    let (_, ik_text, _) = stdout(&["ik", "--all", "--tool", pose]);
    let (hi, ik_rows) = table(&ik_text);
    assert_eq!(rows.len(), ik_rows.len());
    for (r, q) in rows.iter().zip(&ik_rows) {
        for (a, b) in [
            ("orientation", "orientation"),
            ("rho1", "rho1"),
            ("rho2", "rho2"),
            ("rho3", "rho3"),
            ("theta1_deg", "theta1"),
            ("theta2_deg", "theta2"),
            ("s1", "s1"),
            ("s2", "s2"),
            ("s3", "s3"),
            ("working", "working"),
            ("status", "status"),
        ] {
            assert_eq!(r[col(&h, a)], q[col(&hi, b)], "{a} of branch {}", r[0]);
        }
    }
    // Both orientation solutions, one working branch in each (the pose is mirror-symmetric).
    for o in ["1", "2"] {
        assert_eq!(
            rows.iter()
                .filter(|r| r[col(&h, "orientation")] == o && r[col(&h, "working")] == "true")
                .count(),
            1
        );
    }
}

#[test]
fn machine_joints_modes_are_those_of_fk_all_with_figures() {
    let j = "330,280,300,12.5,-37";
    let (code, text, err) = stdout(&["modes", "--csv", "--machine-joints", j]);
    assert_eq!(code, Some(0), "{err}");
    let (h, rows) = table(&text);
    let (_, fk_text, _) = stdout(&["fk", "--all", "--machine-joints", j]);
    let (hf, fk_rows) = table(&fk_text);
    assert_eq!(rows.len(), fk_rows.len());
    assert!(rows.len() >= 2);
    for (r, q) in rows.iter().zip(&fk_rows) {
        for (a, b) in [
            ("x", "x"),
            ("y", "y"),
            ("z", "z"),
            ("i", "i"),
            ("j", "j"),
            ("k", "k"),
            ("phi1_deg", "phi1"),
            ("phi2_deg", "phi2"),
            ("working", "working"),
            ("status", "status"),
        ] {
            assert_eq!(r[col(&h, a)], q[col(&hf, b)], "{a} of mode {}", r[0]);
        }
        // Figures of a real configuration: finite, amplification factors ordered.
        let (lo, hi) = (
            num(&r[col(&h, "lambda_min")]),
            num(&r[col(&h, "lambda_max")]),
        );
        assert!(
            lo.is_finite() && hi.is_finite() && 0.0 < lo && lo <= hi,
            "{r:?}"
        );
    }
    // The working mode's tool pose is the one the joints were built from.
    let pose = pose_from_joints([330.0, 280.0, 300.0], 12.5, -37.0);
    let w = rows
        .iter()
        .find(|r| r[col(&h, "working")] == "true")
        .unwrap();
    for (k, c) in ["x", "y", "z"].iter().enumerate() {
        assert!((num(&w[col(&h, c)]) - pose[k]).abs() < TIP_TOL_MM);
    }
}

#[test]
fn a_vertical_axis_takes_theta2_zero_and_says_so() {
    let (code, text, _) = stdout(&["modes", "--tool", "0,0,150,0,0,1"]);
    assert_eq!(code, Some(0));
    let title = text.lines().next().unwrap();
    assert!(
        title.contains("theta2 is free: theta2 = 0 taken"),
        "{title}"
    );
    let (_, csv, _) = stdout(&["modes", "--csv", "--tool", "0,0,150,0,0,1"]);
    let (h, rows) = table(&csv);
    assert!(!rows.is_empty());
    assert!(rows.iter().all(|r| num(&r[col(&h, "theta2_deg")]) == 0.0));
    assert!(rows.iter().all(|r| r[col(&h, "orientation")] == "1"));
}

#[test]
fn an_unreachable_pose_is_an_answer_and_bad_input_is_fatal() {
    // Far beside the machine (beyond the rods): no real branch, exit 1, the title says 0.
    let (code, text, _) = stdout(&["modes", "--tool", "5000,0,100,0,0,1"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains(": 0 real branches"), "{text}");
    // A zero axis, a tool length for the module, a glider: exit 2 with the reason.
    let (code, _, err) = stdout(&["modes", "--tool", "0,0,100,0,0,0"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--tool") && err.contains("axis"), "{err}");
    let (code, _, err) = stdout(&["modes", "--joints", "674,685,250", "--tool-length", "50"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--tool-length"), "{err}");
    let (code, _, err) = stdout(&["modes", "-m", "orthoglide", "--tool", "0,0,100,0,0,1"]);
    assert_eq!(code, Some(2));
    assert!(
        err.contains("--tool") && err.contains("orthoglide"),
        "{err}"
    );
}

#[test]
fn tool_length_and_radians_are_honoured() {
    // A longer tool moves the platform: the same tip needs other joints.
    let pose = "80,0,30,0.342020,0,0.939693";
    let (_, a, _) = stdout(&["modes", "--csv", "--tool", pose]);
    let (_, b, _) = stdout(&["modes", "--csv", "--tool", pose, "--tool-length", "120"]);
    let (h, ra) = table(&a);
    let (_, rb) = table(&b);
    assert_ne!(ra[0][col(&h, "rho1")], rb[0][col(&h, "rho1")]);
    // Radians in and out give the same modes.
    let (_, deg, _) = stdout(&["modes", "--csv", "--machine-joints", "330,280,300,12.5,-37"]);
    let j = format!(
        "330,280,300,{:?},{:?}",
        12.5f64.to_radians(),
        (-37.0f64).to_radians()
    );
    let (_, rad, _) = stdout(&["modes", "--csv", "--radians", "--machine-joints", &j]);
    let (hd, rd) = table(&deg);
    let (hr, rr) = table(&rad);
    assert!(hr.contains(&"phi1_rad".to_string()));
    for (x, y) in rd.iter().zip(&rr) {
        assert!((num(&x[col(&hd, "x")]) - num(&y[col(&hr, "x")])).abs() < 1e-9);
        assert!(
            (num(&x[col(&hd, "phi1_deg")]).to_radians() - num(&y[col(&hr, "phi1_rad")])).abs()
                < 1e-12
        );
    }
}

#[test]
fn tool_plot_draws_every_branch_with_its_orientation() {
    let dir = std::env::temp_dir().join(format!("verne-modes-tool-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("tool.svg");
    let (code, text, err) = stdout(&[
        "modes",
        "--tool",
        "80,0,30,0.342020,0,0.939693",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let rows = text.lines().count() - 2;
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.contains("o1 s=(-1,-1,-1)") && picture.contains("o2 s=(-1,-1,-1)"));
    assert_eq!(picture.matches(": o").count(), rows, "one panel per branch");
    let _ = std::fs::remove_dir_all(&dir);
}
