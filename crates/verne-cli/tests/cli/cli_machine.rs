//! CLI tests of the whole machine: tool poses (CSV or APT CL) -> five joints -> tool poses.

use crate::common;

use common::{col, num, run, table};

/// Round-trip tolerance of the tool tip through `ik | fk` (mm) and of the unit axis.
const TIP_TOL_MM: f64 = 1e-9;
const AXIS_TOL: f64 = 1e-12;

#[test]
fn cl_file_converts_and_round_trips_through_fk() {
    let ik = run(&["ik", "data/example.cl"], None);
    assert_eq!(
        ik.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ik.stderr)
    );
    let ik_text = String::from_utf8(ik.stdout).unwrap();
    let (h, rows) = table(&ik_text);
    assert_eq!(
        h,
        [
            "line",
            "kind",
            "motion",
            "feed",
            "tool",
            "x",
            "y",
            "z",
            "i",
            "j",
            "k",
            "rho1",
            "rho2",
            "rho3",
            "theta1",
            "theta2",
            "orientation",
            "flags",
            "status"
        ]
    );
    assert_eq!(rows.len(), 181, "180 GOTO rows and the FROM row");
    assert_fk_gives_back(&ik_text, &["fk"]);
}

/// `verne fk` (with `fk_args`) on the joint table `ik_text` gives back its x,y,z and unit axis.
fn assert_fk_gives_back(ik_text: &str, fk_args: &[&str]) {
    let (h, rows) = table(ik_text);
    let fk = run(fk_args, Some(ik_text));
    assert_eq!(fk.status.code(), Some(0));
    let (h2, back) = table(&String::from_utf8(fk.stdout).unwrap());
    assert_eq!(rows.len(), back.len());
    for (a, b) in rows.iter().zip(&back) {
        for c in ["x", "y", "z"] {
            let d = (num(&a[col(&h, c)]) - num(&b[col(&h2, c)])).abs();
            assert!(d < TIP_TOL_MM, "line {}: {c} off by {d}", a[0]);
        }
        let (ia, ib) = (col(&h, "i"), col(&h2, "i"));
        let axis_in: Vec<f64> = (0..3).map(|k| num(&a[ia + k])).collect();
        let norm = axis_in.iter().map(|v| v * v).sum::<f64>().sqrt();
        for k in 0..3 {
            let d = (axis_in[k] / norm - num(&b[ib + k])).abs();
            assert!(d < AXIS_TOL, "line {}: axis component {k} off by {d}", a[0]);
        }
    }
}

/// `--offset` places the part on the table: the joints are exactly those of the same poses
/// moved by the offset (given as CSV, without the flag), and `verne fk --offset` gives back the
/// file's own tips.
#[test]
fn offset_places_the_part_and_fk_takes_it_off() {
    let offset = [-30.0, 20.0, 50.0];
    let flag = "--offset=-30,20,50";
    let ik = run(&["ik", "data/example.cl", flag], None);
    assert_eq!(ik.status.code(), Some(0));
    let ik_text = String::from_utf8(ik.stdout).unwrap();
    let (h, rows) = table(&ik_text);
    let mut moved = String::from("x,y,z,i,j,k\n");
    for r in &rows {
        let v: Vec<f64> = ["x", "y", "z", "i", "j", "k"]
            .iter()
            .map(|c| num(&r[col(&h, c)]))
            .collect();
        moved.push_str(&format!(
            "{},{},{},{},{},{}\n",
            v[0] + offset[0],
            v[1] + offset[1],
            v[2] + offset[2],
            v[3],
            v[4],
            v[5]
        ));
    }
    // Given as a file, as the CL file was: both are read ahead to their first tilted pose.
    let moved_file = std::env::temp_dir().join(format!("verne-offset-{}.csv", std::process::id()));
    std::fs::write(&moved_file, &moved).unwrap();
    let plain = run(&["ik", moved_file.to_str().unwrap()], None);
    assert_eq!(plain.status.code(), Some(0));
    let (h2, rows2) = table(&String::from_utf8(plain.stdout).unwrap());
    for (a, b) in rows.iter().zip(&rows2) {
        for c in ["rho1", "rho2", "rho3", "theta1", "theta2"] {
            let d = (num(&a[col(&h, c)]) - num(&b[col(&h2, c)])).abs();
            assert!(d < 1e-9, "line {}: {c} differs by {d}", a[0]);
        }
    }
    assert_fk_gives_back(&ik_text, &["fk", flag]);
}

#[test]
fn theta2_never_jumps_by_a_turn_and_singular_rows_are_flagged() {
    let ik = run(&["ik", "data/example.cl"], None);
    let (h, rows) = table(&String::from_utf8(ik.stdout).unwrap());
    let t2 = col(&h, "theta2");
    for w in rows.windows(2) {
        let jump = (num(&w[1][t2]) - num(&w[0][t2])).abs();
        assert!(
            jump < 180.0,
            "theta2 jumps by {jump} deg at line {}",
            w[1][0]
        );
    }
    let flagged: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[col(&h, "flags")].contains("near_rotary_singularity"))
        .collect();
    assert!(!flagged.is_empty());
    for r in flagged {
        let k = num(&r[col(&h, "k")]);
        let (i, j) = (num(&r[col(&h, "i")]), num(&r[col(&h, "j")]));
        assert!(
            i.hypot(j) < 1e-6 && k > 0.0,
            "flagged row {} is not on the rotary axis",
            r[0]
        );
    }
}

#[test]
fn tool_pose_columns_angles_and_ambiguity() {
    // The same pose by axis and by angles (phi1 = 20 deg towards +x: axis (sin 20 sin phi2,
    // -sin 20 cos phi2, cos 20) with phi2 = 90 deg).
    let s = 20f64.to_radians().sin();
    let c = 20f64.to_radians().cos();
    let by_axis = run(
        &["ik", "--prefer", "orientation1"],
        Some(&format!("x,y,z,i,j,k\n10,5,40,{s},0,{c}\n")),
    );
    let by_angles = run(&["ik"], Some("x,y,z,phi1,phi2\n10,5,40,20,90\n"));
    assert_eq!(
        by_axis.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&by_axis.stderr)
    );
    assert_eq!(
        by_angles.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&by_angles.stderr)
    );
    let (ha, ra) = table(&String::from_utf8(by_axis.stdout).unwrap());
    let (hb, rb) = table(&String::from_utf8(by_angles.stdout).unwrap());
    for c in ["rho1", "rho2", "rho3", "theta1"] {
        assert!(
            (num(&ra[0][col(&ha, c)]) - num(&rb[0][col(&hb, c)])).abs() < 1e-9,
            "{c}"
        );
    }
    let both = run(&["ik"], Some("x,y,z,i,j,k,phi1,phi2\n0,0,0,0,0,1,0,0\n"));
    assert_eq!(both.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&both.stderr).contains("both `i,j,k` and `phi1,phi2` are present")
    );
    let mixed = run(&["ik"], Some("x,y,z,xp,yp,zp,i,j,k\n0,0,0,0,0,0,0,0,1\n"));
    assert_eq!(mixed.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&mixed.stderr).contains("keep one"));
    let none = run(&["ik"], Some("x,y,z\n0,0,0\n"));
    assert_eq!(none.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&none.stderr).contains("`i,j,k` or the angles `phi1,phi2`"));
}

#[test]
fn all_lists_both_orientations_and_a_zero_axis_is_an_invalid_row() {
    let out = run(
        &["ik", "--all", "--tool", "10,5,40,0.3,0.2,0.9327379"],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let (h, rows) = table(&String::from_utf8(out.stdout).unwrap());
    let orientations: std::collections::BTreeSet<&str> = rows
        .iter()
        .map(|r| r[col(&h, "orientation")].as_str())
        .collect();
    assert_eq!(orientations.into_iter().collect::<Vec<_>>(), ["1", "2"]);
    assert!(rows.iter().any(|r| r[col(&h, "working")] == "true"));
    let bad = run(&["ik"], Some("x,y,z,i,j,k\n0,0,40,0,0,0\n"));
    assert_eq!(bad.status.code(), Some(1));
    let (h, rows) = table(&String::from_utf8(bad.stdout).unwrap());
    assert_eq!(rows[0][col(&h, "status")], "invalid_axis");
}

#[test]
fn halstreamer_writes_only_joints() {
    let out = run(
        &[
            "ik",
            "--format",
            "halstreamer",
            "--tool",
            "10,5,40,0,0,1",
            "--tool",
            "12,5,40,0,0,1",
        ],
        None,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    for l in lines {
        let v: Vec<f64> = l.split(' ').map(num).collect();
        assert_eq!(v.len(), 5);
    }
    let unreachable = run(
        &["ik", "--format", "halstreamer", "--tool", "5000,0,0,0,0,1"],
        None,
    );
    // An unreachable pose is an answer (a row that failed: exit 1), not a fatal error.
    assert_eq!(unreachable.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&unreachable.stderr).contains("cannot leave out a row"));
    // Into a file: nothing is written.
    let dir = std::env::temp_dir().join(format!("verne-unreachable-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("p.csv");
    std::fs::write(
        &path,
        "x,y,z,i,j,k,feed\n0,0,30,0,0,1,1000\n2000,0,30,0,0,1,1000\n",
    )
    .unwrap();
    let program = dir.join("p.ngc");
    let out = run(
        &[
            "ik",
            path.to_str().unwrap(),
            "--format",
            "gcode",
            "-o",
            program.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("p.csv:3: row status `unreachable`"));
    assert!(!program.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn malformed_cl_file_names_its_line() {
    let out = run(
        &["ik", "--input-format", "apt"],
        Some("MULTAX/ON\nGOTO/1,2,3,0,0,1\nGOTO/1,2.O,3,0,0,1\n"),
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    // The reader's typed error keeps its line and column to the message.
    assert!(
        err.contains("<stdin>:3: column 8: ") && err.contains("2.O"),
        "{err}"
    );
}

#[test]
fn machine_fk_all_lists_assembly_modes_with_one_working() {
    let ik = run(&["ik", "--tool", "10,5,40,0.3,0.2,0.9327379"], None);
    let (h, rows) = table(&String::from_utf8(ik.stdout).unwrap());
    let j: Vec<String> = ["rho1", "rho2", "rho3", "theta1", "theta2"]
        .iter()
        .map(|c| rows[0][col(&h, c)].clone())
        .collect();
    let out = run(&["fk", "--all", "--machine-joints", &j.join(",")], None);
    assert_eq!(out.status.code(), Some(0));
    let (h, rows) = table(&String::from_utf8(out.stdout).unwrap());
    assert!(rows.len() >= 2);
    assert_eq!(
        rows.iter()
            .filter(|r| r[col(&h, "working")] == "true")
            .count(),
        1
    );
    let w = rows
        .iter()
        .find(|r| r[col(&h, "working")] == "true")
        .unwrap();
    assert!((num(&w[col(&h, "x")]) - 10.0).abs() < TIP_TOL_MM);
    assert!((num(&w[col(&h, "z")]) - 40.0).abs() < TIP_TOL_MM);
}

#[test]
fn machine_check_checks_the_verify_thresholds_too() {
    let base = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/verne.toml"
    ))
    .unwrap();
    let dir = std::env::temp_dir().join(format!("verne-machine-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, table, expect) in [
        (
            "bogus.toml",
            "[verify]\nbogus = 1\n",
            "unknown threshold `bogus`",
        ),
        (
            "negative.toml",
            "[verify]\ntip_error_mm = -1\n",
            "must be a positive number",
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, format!("{base}\n{table}")).unwrap();
        let out = run(&["machine", "check", path.to_str().unwrap()], None);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(expect) && e.contains("verify."), "{name}: {e}");
    }
}

#[test]
fn machine_files_on_a_base_presets_and_several_checks() {
    let dir = std::env::temp_dir().join(format!("verne-machine-base-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("shop.toml"),
        "base = \"verne\"\nname = \"shop\"\n[tool]\nlength = 120\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("job.toml"),
        "base = \"shop.toml\"\nname = \"job\"\n[limits]\nrho1_max = 900\n",
    )
    .unwrap();
    std::fs::write(dir.join("broken.toml"), "base = \"missing.toml\"\n").unwrap();
    let p = |n: &str| dir.join(n).to_str().unwrap().to_string();
    // The job's joints are those of the default machine with a 120 mm tool.
    let job = run(
        &["ik", "-m", &p("job.toml"), "--tool", "10,-20,80,0,0,1"],
        None,
    );
    let long = run(
        &["ik", "--tool-length", "120", "--tool", "10,-20,80,0,0,1"],
        None,
    );
    assert_eq!(job.status.code(), Some(0));
    assert_eq!(job.stdout, long.stdout);
    // Several files: each one's verdict, exit 2 if any is invalid.
    let c = run(
        &[
            "machine",
            "check",
            &p("shop.toml"),
            &p("job.toml"),
            "data/orthoglide.toml",
            &p("broken.toml"),
        ],
        None,
    );
    assert_eq!(c.status.code(), Some(2));
    let out = String::from_utf8_lossy(&c.stdout);
    assert!(
        out.contains("valid machine `shop`")
            && out.contains("valid machine `job`")
            && out.contains("valid glider `orthoglide`"),
        "{out}"
    );
    let e = String::from_utf8_lossy(&c.stderr);
    assert!(
        e.contains("broken.toml:1: base") && e.contains("missing.toml"),
        "{e}"
    );
    // Presets.
    let g = run(&["machine", "show", "--base", "biglide2"], None);
    assert_eq!(g.status.code(), Some(0));
    let text = String::from_utf8_lossy(&g.stdout);
    assert!(
        text.contains("kind = \"glider\"") && text.contains("biglide2"),
        "{text}"
    );
    std::fs::write(dir.join("b2.toml"), g.stdout).unwrap();
    let again = run(&["machine", "check", &p("b2.toml")], None);
    assert_eq!(
        again.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
}
