//! The machine file's real-machine offsets (`[zeros]`, `table.y_t`) as `verne ik`, `verne fk`
//! and `verne verify` apply them, against machines built here:
//!
//! - the sliders' and the table axes' zero offsets only rename the joints: a machine without
//!   them, its limits moved by them by hand, gives joints that are the offset machine's plus
//!   the offsets, pose for pose;
//! - the rotary axis's offset y_t moves the workpiece frame by y_t across the rotary axis
//!   (eq. (7) of AIM 2007 with trans(y, y_t)): the same joints give, without it, a tool tip
//!   |y_t| away in the plane of the table and the same tool axis;
//! - the inverse and the forward of the offset machine give each other back, and verify accepts
//!   the joints of the offset machine on it and finds them off on the drawing's machine.

use crate::common;

use std::path::{Path, PathBuf};

use common::{col, num, run, table};

/// The offsets: sliders (mm), table angles (degrees), rotary axis (mm).
const RHO_ZERO: [f64; 3] = [0.4, -0.3, 0.2];
const THETA_ZERO_DEG: [f64; 2] = [0.05, -0.1];
const Y_T: f64 = 0.25;

/// Tool poses x,y,z,phi1,phi2 (mm, degrees) over the default workspace.
const POSES: &str =
    "x,y,z,phi1,phi2\n10,-20,5,12,30\n-30,15,20,20,-60\n40,30,-10,8,135\n0,-50,30,25,-150\n";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-offsets-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The machine with the offsets, as a user writes it over the default machine.
fn offset_machine(dir: &Path) -> PathBuf {
    let path = dir.join("offsets.toml");
    std::fs::write(
        &path,
        format!(
            "base = \"verne\"\n[zeros]\nrho1 = {}\nrho2 = {}\nrho3 = {}\ntheta1 = {}\ntheta2 = {}\n[table]\ny_t = {Y_T}\n",
            RHO_ZERO[0], RHO_ZERO[1], RHO_ZERO[2], THETA_ZERO_DEG[0], THETA_ZERO_DEG[1]
        ),
    )
    .unwrap();
    path
}

/// The same machine without zero offsets, its joint limits moved by them by hand; `y_t` its
/// rotary axis's offset.
fn by_hand(dir: &Path, name: &str, y_t: f64) -> PathBuf {
    let m = verne::spec::Machine::default_verne();
    let l = m.limits;
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "base = \"verne\"\n[limits]\nrho1_min = {}\nrho1_max = {}\nrho2_min = {}\nrho2_max = {}\nrho3_min = {}\nrho3_max = {}\ntheta1_min = {}\ntheta1_max = {}\n[table]\ny_t = {y_t}\n",
            l.rho_min[0] + RHO_ZERO[0],
            l.rho_max[0] + RHO_ZERO[0],
            l.rho_min[1] + RHO_ZERO[1],
            l.rho_max[1] + RHO_ZERO[1],
            l.rho_min[2] + RHO_ZERO[2],
            l.rho_max[2] + RHO_ZERO[2],
            l.theta1_min.to_degrees() + THETA_ZERO_DEG[0],
            l.theta1_max.to_degrees() + THETA_ZERO_DEG[0],
        ),
    )
    .unwrap();
    path
}

/// `verne ARGS` that must succeed: its stdout as a table.
fn ok(args: &[&str], stdin: Option<&str>) -> (Vec<String>, Vec<Vec<String>>) {
    let out = run(args, stdin);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    table(&String::from_utf8(out.stdout).unwrap())
}

/// The columns `names` of every row, as numbers.
fn columns(t: &(Vec<String>, Vec<Vec<String>>), names: &[&str]) -> Vec<Vec<f64>> {
    let cols: Vec<usize> = names.iter().map(|n| col(&t.0, n)).collect();
    t.1.iter()
        .map(|r| cols.iter().map(|&c| num(&r[c])).collect())
        .collect()
}

const JOINTS: [&str; 5] = ["rho1", "rho2", "rho3", "theta1", "theta2"];
const POSE: [&str; 5] = ["x", "y", "z", "phi1", "phi2"];

/// `a - b` of pose column `k`, the rotary angle phi2 (degrees) modulo a turn.
fn difference(k: usize, a: f64, b: f64) -> f64 {
    if k == 4 {
        (a - b + 180.0).rem_euclid(360.0) - 180.0
    } else {
        a - b
    }
}

/// A joint table as verify and fk read it.
fn joint_csv(rows: &[Vec<f64>]) -> String {
    let mut text = String::from("rho1,rho2,rho3,theta1,theta2\n");
    for r in rows {
        let cells: Vec<String> = r.iter().map(|v| format!("{v:?}")).collect();
        text.push_str(&cells.join(","));
        text.push('\n');
    }
    text
}

#[test]
fn zero_offsets_rename_the_joints_and_fk_gives_the_pose_back() {
    let dir = scratch("zeros");
    let offsets = offset_machine(&dir);
    let hand = by_hand(&dir, "hand.toml", Y_T);
    let joints = columns(&ok(&["ik", "-m", s(&offsets)], Some(POSES)), &JOINTS);
    let hand_joints = columns(&ok(&["ik", "-m", s(&hand)], Some(POSES)), &JOINTS);
    assert_eq!(joints.len(), 4);
    let zero = [
        RHO_ZERO[0],
        RHO_ZERO[1],
        RHO_ZERO[2],
        THETA_ZERO_DEG[0],
        THETA_ZERO_DEG[1],
    ];
    for (j, h) in joints.iter().zip(&hand_joints) {
        for k in 0..5 {
            assert!(
                (j[k] + zero[k] - h[k]).abs() < 1e-9,
                "joint {k}: {j:?} + offsets vs {h:?}"
            );
        }
    }
    // The forward of the offset machine gives the poses back.
    let back = columns(
        &ok(&["fk", "-m", s(&offsets)], Some(&joint_csv(&joints))),
        &POSE,
    );
    let poses = columns(&table(POSES), &POSE);
    for (b, p) in back.iter().zip(&poses) {
        for k in 0..5 {
            assert!(difference(k, b[k], p[k]).abs() < 1e-7, "{b:?} vs {p:?}");
        }
    }
}

#[test]
fn the_rotary_axis_offset_moves_the_workpiece_frame_by_y_t() {
    let dir = scratch("yt");
    let with = by_hand(&dir, "with.toml", Y_T);
    let without = by_hand(&dir, "without.toml", 0.0);
    let joints = columns(&ok(&["ik", "-m", s(&with)], Some(POSES)), &JOINTS);
    let input = joint_csv(&joints);
    let fk = |m: &Path| columns(&ok(&["fk", "-m", s(m)], Some(&input)), &POSE);
    let (a, b) = (fk(&with), fk(&without));
    for (p, q) in a.iter().zip(&b) {
        let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
        let dist = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        assert!((dist - Y_T).abs() < 1e-9, "{p:?} vs {q:?}: {dist}");
        assert!(d[2].abs() < 1e-9, "{d:?}");
        assert!(
            difference(3, p[3], q[3]).abs() < 1e-9 && difference(4, p[4], q[4]).abs() < 1e-9,
            "{p:?} vs {q:?}"
        );
    }
}

/// A straight pass in steps of 0.1 mm: verify accepts the offset machine's joints on the
/// offset machine, and finds every row off on the drawing's machine.
#[test]
fn verify_reads_the_joints_of_the_offset_machine() {
    let dir = scratch("verify");
    let offsets = offset_machine(&dir);
    let mut path = String::from("x,y,z,phi1,phi2\n");
    for k in 0..40 {
        path.push_str(&format!("{:?},-20,5,12,30\n", 10.0 + 0.1 * k as f64));
    }
    let path_file = dir.join("path.csv");
    std::fs::write(&path_file, &path).unwrap();
    let joints = columns(&ok(&["ik", "-m", s(&offsets)], Some(&path)), &JOINTS);
    let joints_file = dir.join("joints.csv");
    std::fs::write(&joints_file, joint_csv(&joints)).unwrap();
    let verify = |m: Option<&Path>| {
        let report = dir.join("report.csv");
        let mut args = vec![
            "verify",
            "--joints",
            s(&joints_file),
            "--path",
            s(&path_file),
            "--report",
            s(&report),
        ];
        if let Some(m) = m {
            args.extend(["-m", s(m)]);
        }
        let out = run(&args, None);
        let (h, rows) = table(&std::fs::read_to_string(&report).unwrap());
        let check = col(&h, "check");
        let tip = rows.iter().filter(|r| r[check] == "tip_error").count();
        (out.status.code(), tip)
    };
    assert_eq!(verify(Some(&offsets)), (Some(0), 0));
    assert_eq!(verify(None), (Some(1), 40));
}
