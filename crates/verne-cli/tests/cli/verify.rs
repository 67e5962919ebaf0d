//! `verne verify` on joint tables made by the library (machine inverse kinematics along a path,
//! `PathState`), clean and with one defect each: every defect is reported by exactly the check
//! meant for it, on the right row, and by no other check. Runs the real binary.

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::Command;

use nalgebra::Vector3;
use verne::machine::orientation::{AxisAngles, ToolOrientation, axis_angles};
use verne::machine::{FirstRowChoice, PathState, ToolPose, machine_ik};
use verne::parallel_module::equations::{ModulePose, Sliders, polish_pose};
use verne::parallel_module::fk;
use verne::parallel_module::kinetostatics::kinetostatics;
use verne::spec::Machine;

const BIN: &str = env!("CARGO_BIN_EXE_verne");

/// Distance between rows (mm) and the feed (mm/s) of the test path.
const STEP_MM: f64 = 0.5;
const FEED_MM_S: f64 = 25.0;

#[derive(Clone, Copy, Debug)]
struct Joints {
    rho: [f64; 3],
    /// rad
    theta1: f64,
    /// rad
    theta2: f64,
    t: f64,
}

#[derive(Clone, Copy, Debug)]
struct Pose {
    tip: Vector3<f64>,
    axis: Vector3<f64>,
}

/// A 5-axis pass on a dome (tool normal to the surface, leaning outwards 8 to 20 degrees),
/// `n` rows 0.5 mm apart, and the joints of the library's path branch.
fn library_path(n: usize) -> (Vec<Pose>, Vec<Joints>) {
    let m = Machine::default_verne();
    let (r, c) = (150.0, Vector3::new(0.0, 0.0, -100.0));
    let (b0, b1) = (8f64.to_radians(), 20f64.to_radians());
    let psi_end = 4.0 * PI;
    let mut psi = 0.0f64;
    let mut poses = Vec::new();
    let mut joints = Vec::new();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    for k in 0..n {
        let beta = b0 + (b1 - b0) * (psi / psi_end).min(1.0);
        let a = Vector3::new(beta.sin() * psi.cos(), beta.sin() * psi.sin(), beta.cos());
        let tip = c + r * a;
        let row = state
            .next_row(&m, &tip, &ToolOrientation::Axis(a), m.tool_length)
            .unwrap_or_else(|e| panic!("row {}: {e}", k + 1));
        poses.push(Pose { tip, axis: a });
        joints.push(Joints {
            rho: [row.rho.x, row.rho.y, row.rho.z],
            theta1: row.theta1,
            theta2: row.theta2,
            t: k as f64 * STEP_MM / FEED_MM_S,
        });
        psi += STEP_MM / (r * beta.sin());
    }
    (poses, joints)
}

fn path_csv(poses: &[Pose]) -> String {
    let mut s = String::from("id,x,y,z,i,j,k\n");
    for (k, p) in poses.iter().enumerate() {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{}",
            k + 1,
            p.tip.x,
            p.tip.y,
            p.tip.z,
            p.axis.x,
            p.axis.y,
            p.axis.z
        );
    }
    s
}

fn joints_csv(j: &[Joints], with_t: bool) -> String {
    let mut s = String::from(if with_t {
        "id,t,rho1,rho2,rho3,theta1,theta2\n"
    } else {
        "id,rho1,rho2,rho3,theta1,theta2\n"
    });
    for (k, q) in j.iter().enumerate() {
        let _ = write!(s, "{}", k + 1);
        if with_t {
            let _ = write!(s, ",{}", q.t);
        }
        let _ = writeln!(
            s,
            ",{},{},{},{},{}",
            q.rho[0],
            q.rho[1],
            q.rho[2],
            q.theta1.to_degrees(),
            q.theta2.to_degrees()
        );
    }
    s
}

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-verify-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[derive(Debug, Clone, PartialEq)]
struct Finding {
    row: String,
    check: String,
    value: f64,
    detail: String,
}

struct Run {
    code: i32,
    findings: Vec<Finding>,
    stdout: String,
    stderr: String,
}

/// Runs `verne verify` with a report file and parses the report.
fn verify(tag: &str, joints: &str, path: &str, extra: &[&str]) -> Run {
    let jp = temp(&format!("{tag}-joints.csv"), joints);
    let pp = temp(&format!("{tag}-path.csv"), path);
    verify_files(tag, &jp, &pp, extra)
}

fn verify_files(tag: &str, jp: &PathBuf, pp: &PathBuf, extra: &[&str]) -> Run {
    let rp = std::env::temp_dir()
        .join(format!("verne-verify-test-{}", std::process::id()))
        .join(format!("{tag}-report.csv"));
    let _ = std::fs::remove_file(&rp);
    let out = Command::new(BIN)
        .arg("verify")
        .arg("--joints")
        .arg(jp)
        .arg("--path")
        .arg(pp)
        .arg("--report")
        .arg(&rp)
        .args(extra)
        .output()
        .unwrap();
    let code = out.status.code().unwrap();
    let mut findings = Vec::new();
    if let Ok(text) = std::fs::read_to_string(&rp) {
        let mut rd = csv::Reader::from_reader(text.as_bytes());
        assert_eq!(
            rd.headers().unwrap(),
            vec![
                "row",
                "check",
                "value",
                "limit",
                "detail",
                "joints_line",
                "path_line"
            ]
        );
        for r in rd.records() {
            let r = r.unwrap();
            // Every finding names the joint table's line (and the path's, when paired).
            assert!(r[5].parse::<u64>().is_ok(), "{r:?}");
            findings.push(Finding {
                row: r[0].to_string(),
                check: r[1].to_string(),
                value: r[2].parse().unwrap_or(f64::NAN),
                detail: r[4].to_string(),
            });
        }
    }
    Run {
        code,
        findings,
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Asserts that the findings are exactly `check` on `rows`, one each.
fn only(run: &Run, check: &str, rows: &[usize]) {
    let got: Vec<(String, String)> = run
        .findings
        .iter()
        .map(|f| (f.row.clone(), f.check.clone()))
        .collect();
    let want: Vec<(String, String)> = rows
        .iter()
        .map(|r| (r.to_string(), check.to_string()))
        .collect();
    assert_eq!(got, want, "findings: {:#?}\n{}", run.findings, run.stderr);
    assert_eq!(run.code, 1, "{}", run.stderr);
}

#[test]
fn a_library_joint_table_is_clean() {
    let (poses, joints) = library_path(600);
    let run = verify("clean", &joints_csv(&joints, true), &path_csv(&poses), &[]);
    assert_eq!(run.code, 0, "{:#?}\n{}", run.findings, run.stderr);
    assert!(run.findings.is_empty());
    assert!(
        run.stderr.contains("600 rows, 599 segments checked"),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("clean"));
}

#[test]
fn a_wrong_sign_on_theta1_is_a_tip_and_axis_error_on_its_row_only() {
    let (poses, mut joints) = library_path(400);
    let k = 200;
    assert!(joints[k - 1].theta1.abs() > 2f64.to_radians());
    joints[k - 1].theta1 = -joints[k - 1].theta1;
    let run = verify("sign", &joints_csv(&joints, true), &path_csv(&poses), &[]);
    let checks: Vec<&str> = run.findings.iter().map(|f| f.check.as_str()).collect();
    assert_eq!(checks, ["tip_error", "axis_error"], "{:#?}", run.findings);
    assert!(run.findings.iter().all(|f| f.row == k.to_string()));
    assert_eq!(run.code, 1);
    // Its two segments are not checked: the row's error is the finding.
    assert!(run.stderr.contains("(2 skipped"), "{}", run.stderr);
}

#[test]
fn a_0_01_mm_offset_is_a_tip_error_of_0_01_mm() {
    let (mut poses, joints) = library_path(400);
    let k = 123;
    poses[k - 1].tip.x += 0.01;
    let run = verify("offset", &joints_csv(&joints, true), &path_csv(&poses), &[]);
    only(&run, "tip_error", &[k]);
    assert!(
        (run.findings[0].value - 0.01).abs() < 1e-6,
        "{:?}",
        run.findings
    );
    // The machine file's [verify] table, then the command line, set the threshold.
    let machine = format!(
        "{}\n[verify]\ntip_error_mm = 0.02\n",
        verne::spec::DEFAULT_MACHINE_TOML
    );
    let mp = temp("offset-machine.toml", &machine);
    let mps = mp.to_str().unwrap();
    let run = verify(
        "offset2",
        &joints_csv(&joints, true),
        &path_csv(&poses),
        &["-m", mps],
    );
    assert_eq!(run.code, 0, "{:#?}", run.findings);
    let run = verify(
        "offset3",
        &joints_csv(&joints, true),
        &path_csv(&poses),
        &["-m", mps, "--threshold", "tip_error_mm=0.009"],
    );
    only(&run, "tip_error", &[k]);
}

#[test]
fn theta2_off_by_a_full_turn_is_a_joint_jump_on_both_segments() {
    let (poses, mut joints) = library_path(400);
    let k = 250;
    joints[k - 1].theta2 += 2.0 * PI;
    let run = verify("turn", &joints_csv(&joints, true), &path_csv(&poses), &[]);
    let jumps: Vec<&Finding> = run
        .findings
        .iter()
        .filter(|f| f.check == "joint_jump")
        .collect();
    let rows: Vec<&str> = jumps.iter().map(|f| f.row.as_str()).collect();
    assert_eq!(
        rows,
        [k.to_string(), (k + 1).to_string()],
        "{:#?}",
        run.findings
    );
    assert!(jumps.iter().all(|f| f.detail.contains("theta2")));
    assert!(jumps.iter().all(|f| (f.value - 360.0).abs() < 5.0));
    // The table really turns: its chord and axis along the jumps are findings of their own,
    // on the same rows, and nothing else is.
    for f in &run.findings {
        assert!(
            ["joint_jump", "chord_error", "chord_axis"].contains(&f.check.as_str())
                && (f.row == k.to_string() || f.row == (k + 1).to_string()),
            "{f:?}"
        );
    }
    assert!(
        run.findings
            .iter()
            .any(|f| f.check == "chord_error" && f.value > 1.0)
    );
    assert_eq!(run.code, 1);
}

/// Another working branch of the same tool pose, with theta2 taken near the path's.
fn other_branch(poses: &[Pose], joints: &[Joints], k: usize) -> Option<Joints> {
    let m = Machine::default_verne();
    let p = poses[k - 1];
    let cur = joints[k - 1];
    let Ok(AxisAngles::Regular(sols)) = axis_angles(&p.axis) else {
        return None;
    };
    let b = sols
        .iter()
        .flat_map(|a| {
            machine_ik(
                &m,
                &ToolPose {
                    tip: p.tip,
                    phi1: a.phi1,
                    phi2: a.phi2,
                },
                m.tool_length,
            )
        })
        .filter(|b| b.working() && (b.theta1 - cur.theta1).abs() > 1e-3)
        .min_by(|a, b| a.theta1.abs().total_cmp(&b.theta1.abs()))?;
    let theta2 = cur.theta2 + verne::parallel_module::ik::wrap_angle(b.theta2 - cur.theta2);
    Some(Joints {
        rho: [b.rho.x, b.rho.y, b.rho.z],
        theta1: b.theta1,
        theta2,
        t: cur.t,
    })
}

#[test]
fn a_row_from_another_branch_is_a_branch_flip_on_both_segments() {
    let (poses, mut joints) = library_path(400);
    let k = (150..400)
        .find(|&k| other_branch(&poses, &joints, k).is_some())
        .expect("a row with a second working branch");
    joints[k - 1] = other_branch(&poses, &joints, k).unwrap();
    let run = verify("branch", &joints_csv(&joints, true), &path_csv(&poses), &[]);
    only(&run, "branch", &[k, k + 1]);
    assert!(run.findings[0].detail.contains("orientation solution"));
}

/// Velocity amplification along one segment, sampled as the verifier does (2 samples per
/// segment of at most 4 mm of slider travel: the midpoint).
fn lambda_max_at(m: &Machine, rho: [f64; 3], start: Option<ModulePose>) -> (f64, ModulePose) {
    let r = Sliders::new(rho[0], rho[1], rho[2]);
    let pose = match start {
        None => fk::working(&fk::solve(m, &r)).unwrap().pose,
        Some(p) => polish_pose(&m.module, p, &r),
    };
    (kinetostatics(&m.module, &pose, &r).amplification[0], pose)
}

/// A straight pass along y_t with a vertical tool, rows 0.5 mm apart placed so that y_t = 0,
/// where lambda_max peaks (the machine is symmetric in y there), falls between two rows.
fn line_path() -> (Vec<Pose>, Vec<Joints>) {
    let m = Machine::default_verne();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let axis = Vector3::new(0.0, 0.0, 1.0);
    let mut poses = Vec::new();
    let mut joints = Vec::new();
    for k in 0..200 {
        let tip = Vector3::new(0.0, -50.25 + STEP_MM * k as f64, 40.0);
        let r = state
            .next_row(&m, &tip, &ToolOrientation::Axis(axis), m.tool_length)
            .unwrap();
        poses.push(Pose { tip, axis });
        joints.push(Joints {
            rho: [r.rho.x, r.rho.y, r.rho.z],
            theta1: r.theta1,
            theta2: r.theta2,
            t: k as f64 * STEP_MM / FEED_MM_S,
        });
    }
    (poses, joints)
}

/// Joints as the verifier reads them back from the CSV.
fn as_read(j: &Joints) -> [f64; 3] {
    let s = format!("{},{},{}", j.rho[0], j.rho[1], j.rho[2]);
    let v: Vec<f64> = s.split(',').map(|x| x.parse().unwrap()).collect();
    [v[0], v[1], v[2]]
}

/// A genuinely mid-segment defect. Along joints interpolated linearly the sliders are linear
/// (strokes are exceeded only at rows) and the rod tilts have no interior maximum (none in
/// 60 000 random segments of 20 to 400 mm); the velocity amplification factor does. On a
/// window of the path around a local maximum of lambda_max, with lambda_max set between the
/// rows' largest value and the value at the midpoint of the segment holding the peak, only
/// that segment is reported, on its end row.
#[test]
fn an_amplification_peak_between_two_rows_is_found_mid_segment() {
    let m = Machine::default_verne();
    let (poses, joints) = line_path();
    let rows: Vec<f64> = joints
        .iter()
        .map(|j| lambda_max_at(&m, as_read(j), None).0)
        .collect();
    let mids: Vec<f64> = (1..joints.len())
        .map(|k| {
            let a = as_read(&joints[k - 1]);
            let b = as_read(&joints[k]);
            let (_, pa) = lambda_max_at(&m, a, None);
            // As the verifier samples: rho_a + (rho_b - rho_a) s at s = 1/2, from row a's pose.
            let mid = std::array::from_fn(|i| a[i] + (b[i] - a[i]) * 0.5);
            lambda_max_at(&m, mid, Some(pa)).0
        })
        .collect();
    // A segment (ending at row e, 0-based) whose midpoint beats both ends and both neighbours.
    let e = (20..joints.len() - 20)
        .filter(|&e| {
            let mid = mids[e - 1];
            mid > rows[e - 1].max(rows[e]) && mid > mids[e - 2].max(mids[e])
        })
        .max_by(|&a, &b| {
            let ea = mids[a - 1] - rows[a - 1].max(rows[a]);
            let eb = mids[b - 1] - rows[b - 1].max(rows[b]);
            ea.total_cmp(&eb)
        })
        .expect("a local maximum of lambda_max inside a segment");
    let window = e - 10..e + 11;
    let top_row = rows[window.clone()].iter().cloned().fold(0.0, f64::max);
    let other_mids = (window.start + 1..window.end)
        .filter(|&k| k != e)
        .map(|k| mids[k - 1])
        .fold(0.0, f64::max);
    let floor = top_row.max(other_mids);
    assert!(mids[e - 1] > floor, "{} vs {floor}", mids[e - 1]);
    let limit = 0.5 * (floor + mids[e - 1]);
    let arg = format!("lambda_max={limit}");
    let run = verify(
        "midseg",
        &joints_csv(&joints[window.clone()], true),
        &path_csv(&poses[window.clone()]),
        &["--threshold", &arg],
    );
    // Rows are numbered 1.. within the window; the segment ends at window row 11.
    only(&run, "singularity", &[11]);
    assert!(
        run.findings[0].detail.contains("s = 0.5"),
        "{:?}",
        run.findings
    );
    assert!((run.findings[0].value - mids[e - 1]).abs() < 1e-7); // 9 digits in the report
}

#[test]
fn a_segment_given_too_little_time_is_a_velocity_violation() {
    let (poses, mut joints) = library_path(400);
    let k = 300;
    // Segment k-1 -> k gets a tenth of its time: every later row shifts.
    let dt = STEP_MM / FEED_MM_S;
    for j in joints.iter_mut().skip(k - 1) {
        j.t -= 0.9 * dt;
    }
    let run = verify("fast", &joints_csv(&joints, true), &path_csv(&poses), &[]);
    only(&run, "velocity", &[k]);
    assert!(run.findings[0].detail.contains("theta2"));
    // Without the t column the same table is clean.
    let run = verify(
        "fast-untimed",
        &joints_csv(&joints, false),
        &path_csv(&poses),
        &[],
    );
    assert_eq!(run.code, 0, "{:#?}", run.findings);
    assert!(run.stderr.contains("velocity and acceleration not checked"));
}

#[test]
fn rows_dropped_from_both_files_are_a_joint_jump() {
    let (poses, joints) = library_path(400);
    // Rows 201..=260 dropped (30 mm of path): the segment from row 200 to (old) row 261 jumps.
    let keep = |k: &usize| !(201..=260).contains(k);
    let p: Vec<Pose> = (1..=400).filter(keep).map(|k| poses[k - 1]).collect();
    let j: Vec<Joints> = (1..=400).filter(keep).map(|k| joints[k - 1]).collect();
    let run = verify("drop", &joints_csv(&j, false), &path_csv(&p), &[]);
    let checks: Vec<&str> = run.findings.iter().map(|f| f.check.as_str()).collect();
    // The jump, and the gouge it makes: the tool's distance from the straight move between the
    // two rows, measured along the interpolated joints.
    assert!(
        checks.contains(&"joint_jump")
            && checks.contains(&"chord_error")
            && checks
                .iter()
                .all(|c| ["joint_jump", "chord_error", "chord_axis"].contains(c)),
        "{:#?}",
        run.findings
    );
    // The segment ends at data row 201 (ids are not paired: the path CSV renumbers them).
    assert!(run.findings.iter().all(|f| f.row == "201"));
}

#[test]
fn ids_pair_rows_and_a_missing_id_is_reported() {
    let (poses, joints) = library_path(300);
    let mut text = joints_csv(&joints, false);
    // Remove id 150 from the joint table; the path keeps it.
    text = text
        .lines()
        .filter(|l| !l.starts_with("150,"))
        .map(|l| format!("{l}\n"))
        .collect();
    let run = verify("ids", &text, &path_csv(&poses), &[]);
    let pairing: Vec<&Finding> = run
        .findings
        .iter()
        .filter(|f| f.check == "pairing")
        .collect();
    assert_eq!(pairing.len(), 1, "{:#?}", run.findings);
    assert_eq!(pairing[0].row, "150");
    assert!(pairing[0].detail.contains("has no joint row"));
    assert_eq!(run.code, 1);
    // An id only in the joint table.
    let extra = joints_csv(&joints, false).replace("\n77,", "\n9077,");
    let run = verify("ids2", &extra, &path_csv(&poses), &[]);
    let rows: Vec<(&str, &str)> = run
        .findings
        .iter()
        .map(|f| (f.row.as_str(), f.check.as_str()))
        .collect();
    assert!(
        rows.contains(&("9077", "pairing")) && rows.contains(&("77", "pairing")),
        "{rows:?}"
    );
}

#[test]
fn fatal_inputs_exit_2_with_file_line_and_column() {
    let (poses, joints) = library_path(20);
    // Row counts differ without ids: the rows the joint table lacks are pairing findings (the
    // rest is checked, and the report is written).
    let j = joints_csv(&joints[..19], false).replace("id,", "n,");
    let p = path_csv(&poses).replace("id,", "n,");
    let run = verify("count", &j, &p, &[]);
    assert_eq!(run.code, 1, "{}", run.stderr);
    assert_eq!(run.findings.len(), 1, "{:#?}", run.findings);
    assert_eq!(run.findings[0].check, "pairing");
    assert!(
        run.findings[0]
            .detail
            .contains("row 20 (line 21) has no joint row"),
        "{:#?}",
        run.findings
    );

    // A cell that is not a number.
    let j = joints_csv(&joints, false).replacen("\n3,", "\n3,abc", 1);
    let run = verify("cell", &j, &path_csv(&poses), &[]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr
            .contains(":4: column rho1: expected a number (mm), found `abc"),
        "{}",
        run.stderr
    );
    // No partial report is left behind.
    assert!(run.findings.is_empty());
    // An unknown threshold in the machine file, with its line.
    let machine = format!(
        "{}\n[verify]\ntip_error_mm = 0.02\nchord_eror_mm = 1\n",
        verne::spec::DEFAULT_MACHINE_TOML
    );
    let lines = machine.lines().count();
    let mp = temp("bad-machine.toml", &machine);
    let run = verify(
        "badm",
        &joints_csv(&joints, false),
        &path_csv(&poses),
        &["-m", mp.to_str().unwrap()],
    );
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains(&format!(
            ":{lines}: verify.chord_eror_mm: unknown threshold"
        )),
        "{}",
        run.stderr
    );
    let run = verify(
        "badt",
        &joints_csv(&joints, false),
        &path_csv(&poses),
        &["--threshold", "lambda_max=-3"],
    );
    assert_eq!(run.code, 2);
}

#[test]
fn json_summary_and_deterministic_report() {
    let (poses, mut joints) = library_path(3000);
    joints[2100].theta2 += 2.0 * PI;
    joints[700].rho[1] += 0.05;
    let jp = temp("det-joints.csv", &joints_csv(&joints, true));
    let pp = temp("det-path.csv", &path_csv(&poses));
    let a = verify_files("det-a", &jp, &pp, &["--format", "json"]);
    let out = Command::new(BIN)
        .env("RAYON_NUM_THREADS", "1")
        .args(["verify", "--joints"])
        .arg(&jp)
        .arg("--path")
        .arg(&pp)
        .args(["--format", "json"])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&out.stdout), a.stdout);
    assert!(a.stdout.starts_with("{\"rows\":3000,"), "{}", a.stdout);
    assert!(
        a.stdout.contains("\"joint_jump\":{\"count\":2,"),
        "{}",
        a.stdout
    );
    assert!(a.stdout.contains("\"clean\":false"));
    assert_eq!(a.code, 1);
    let mut rows: Vec<&str> = a.findings.iter().map(|f| f.row.as_str()).collect();
    rows.dedup();
    assert_eq!(rows, ["701", "2101", "2102"], "{:#?}", a.findings);
}

/// The CL example path with joints from the library: the rows agree exactly; rapid moves are
/// exempt from the jump and chordal checks (the long feed plunges and the 5-degree contour
/// steps are not: see docs/verify.md), and the path's feeds time the segments.
#[test]
fn a_cl_path_is_read_and_its_rows_agree() {
    let m = Machine::default_verne();
    let cl = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/example.cl"
    ))
    .unwrap();
    let (rows, _) =
        verne_cl::read_all("example.cl", cl.as_bytes(), &verne_cl::Options::default()).unwrap();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let mut joints = Vec::new();
    for row in &rows {
        let axis = ToolOrientation::Axis(Vector3::from(row.axis));
        let r = state
            .next_row(&m, &Vector3::from(row.tip), &axis, m.tool_length)
            .unwrap();
        joints.push(Joints {
            rho: [r.rho.x, r.rho.y, r.rho.z],
            theta1: r.theta1,
            theta2: r.theta2,
            t: 0.0,
        });
    }
    let jp = temp("apt-joints.csv", &joints_csv(&joints, false));
    let pp = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/example.cl"
    ));
    let run = verify_files("apt", &jp, &pp, &[]);
    assert!(
        run.stderr.contains(&format!("{} rows", joints.len())),
        "{}",
        run.stderr
    );
    assert!(!run.stderr.contains("no t or feed"), "{}", run.stderr);
    let rapid_rows: Vec<String> = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.motion == verne_cl::Motion::Rapid)
        .map(|(k, _)| (k + 1).to_string())
        .collect();
    assert_eq!(rapid_rows.len(), 7, "FROM and six RAPIDs");
    for f in &run.findings {
        assert!(
            ![
                "input",
                "pairing",
                "tip_error",
                "axis_error",
                "branch",
                "limits"
            ]
            .contains(&f.check.as_str()),
            "{f:?}"
        );
        if ["joint_jump", "chord_error"].contains(&f.check.as_str()) {
            assert!(!rapid_rows.contains(&f.row), "{f:?}");
        }
    }
}

/// A CL path's feed times the segments when the joint table has none: a 10 mm move at
/// 1,000,000 mm/min is a velocity finding; the same move as a rapid is not checked; a long rapid
/// is not a jump, a long feed move is.
#[test]
fn a_cl_path_feed_times_segments_and_rapids_are_exempt() {
    let m = Machine::default_verne();
    let cl = "UNITS/MM\nMULTAX/ON\nFEDRAT/MMPM,600\nGOTO/0,0,50,0,0,1\nRAPID\nGOTO/60,-40,120,0,0,1\n\
              FEDRAT/MMPM,1000000\nGOTO/60,-40,110,0,0,1\nRAPID\nGOTO/60,-40,100,0,0,1\n\
              FEDRAT/MMPM,600\nGOTO/0,0,50,0,0,1\n";
    let (rows, _) =
        verne_cl::read_all("feeds.cl", cl.as_bytes(), &verne_cl::Options::default()).unwrap();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let joints: Vec<Joints> = rows
        .iter()
        .map(|row| {
            let axis = ToolOrientation::Axis(Vector3::from(row.axis));
            let r = state
                .next_row(&m, &Vector3::from(row.tip), &axis, m.tool_length)
                .unwrap();
            Joints {
                rho: [r.rho.x, r.rho.y, r.rho.z],
                theta1: r.theta1,
                theta2: r.theta2,
                t: 0.0,
            }
        })
        .collect();
    let jp = temp("feeds-joints.csv", &joints_csv(&joints, false));
    let pp = temp("feeds.cl", cl);
    let run = verify_files("feeds", &jp, &pp, &[]);
    let found: Vec<(&str, &str)> = run
        .findings
        .iter()
        .map(|f| (f.row.as_str(), f.check.as_str()))
        .collect();
    // Row 2: a long rapid (no jump, no chord, no speed); row 3: 10 mm at 16,667 mm/s; row 4:
    // the same 10 mm as a rapid; row 5: back to the start at a feed, a jump.
    assert!(found.contains(&("3", "velocity")), "{found:?}");
    assert!(found.contains(&("5", "joint_jump")), "{found:?}");
    assert!(
        found.iter().all(|(r, _)| *r != "2" && *r != "4"),
        "{found:?}"
    );
    assert_eq!(run.code, 1);
}

/// A postprocessor that always takes orientation solution 1 (phi1 > 0): where the tool axis
/// passes through the table normal, theta2 whips round half a turn between two rows. Reported
/// as `theta2_flip` on that segment only (the library's `PathState` keeps theta2 and lets phi1
/// change sign instead).
#[test]
fn a_half_turn_of_theta2_through_the_table_normal_is_a_theta2_flip() {
    let m = Machine::default_verne();
    let mut poses = Vec::new();
    let mut joints: Vec<Joints> = Vec::new();
    for k in 0..60 {
        // gamma from 14.75 to -14.75 deg in 0.5 deg steps: never exactly on the normal.
        let gamma = (14.75 - 0.5 * k as f64).to_radians();
        let tip = Vector3::new(-15.0 + 0.5 * k as f64, 10.0, 40.0);
        let axis = Vector3::new(gamma.sin(), 0.0, gamma.cos());
        let Ok(AxisAngles::Regular(sols)) = axis_angles(&axis) else {
            panic!("regular axis expected")
        };
        let a = sols[0];
        let prev = joints.last().copied();
        let b = machine_ik(
            &m,
            &ToolPose {
                tip,
                phi1: a.phi1,
                phi2: a.phi2,
            },
            m.tool_length,
        )
        .into_iter()
        .filter(|b| b.working())
        .min_by(|x, y| {
            let d = |b: &verne::machine::MachineIkBranch| {
                prev.map_or(b.theta1.abs(), |p| (b.theta1 - p.theta1).abs())
            };
            d(x).total_cmp(&d(y))
        })
        .unwrap();
        let theta2 = match prev {
            Some(p) => p.theta2 + verne::parallel_module::ik::wrap_angle(b.theta2 - p.theta2),
            None => b.theta2,
        };
        poses.push(Pose { tip, axis });
        joints.push(Joints {
            rho: [b.rho.x, b.rho.y, b.rho.z],
            theta1: b.theta1,
            theta2,
            t: 0.0,
        });
    }
    let run = verify("flip", &joints_csv(&joints, false), &path_csv(&poses), &[]);
    // The axis crosses the normal between rows 30 (gamma = 0.25) and 31 (gamma = -0.25).
    only(&run, "theta2_flip", &[31]);
    assert!(
        (run.findings[0].value - 180.0).abs() < 1.0,
        "{:?}",
        run.findings
    );
}
