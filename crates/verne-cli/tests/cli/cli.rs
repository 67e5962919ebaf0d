//! CLI tests: run the real binary and check the column contract, pass-through, stdin, units,
//! exit codes and error messages.

use crate::common;

use common::{col, num, run, table_of as table};

/// Tolerance for numbers read back from CSV output (mm, rad).
const NUM_TOL: f64 = 1e-9;

#[test]
fn fk_all_reproduces_table_three() {
    let out = run(
        &["fk", "--all", "--radians", "--joints", "674,685,250"],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let (h, rows) = table(&out);
    assert_eq!(
        h,
        [
            "rho1", "rho2", "rho3", "branch", "xp", "yp", "zp", "alpha", "s1", "s2", "s3",
            "working", "status"
        ]
    );
    // verne-geometry.md, reference table (alpha rad, xp, yp, zp).
    let reference = [
        (-0.226839103, -199.799382, 355.845336, 1242.022753),
        (-0.140850326, 298.353956, -297.553100, -120.221391),
        (1.812420577, -393.585767, 322.872468, 958.203620),
        (2.699989141, -115.625453, -189.660908, -0.280803),
    ];
    assert_eq!(rows.len(), 4);
    for (r, (a, x, y, z)) in rows.iter().zip(reference) {
        assert!((num(&r[col(&h, "alpha")]) - a).abs() < 1e-9);
        assert!((num(&r[col(&h, "xp")]) - x).abs() < 1e-6);
        assert!((num(&r[col(&h, "yp")]) - y).abs() < 1e-6);
        assert!((num(&r[col(&h, "zp")]) - z).abs() < 1e-6);
    }
    let working: Vec<&str> = rows
        .iter()
        .map(|r| r[col(&h, "working")].as_str())
        .collect();
    assert_eq!(working, ["true", "false", "false", "false"]);
}

#[test]
fn ik_all_gives_sixteen_branches_in_degrees_by_default() {
    let out = run(&["ik", "--all", "--pose=-240,-86,1000"], None);
    assert_eq!(out.status.code(), Some(0));
    let (h, rows) = table(&out);
    assert_eq!(rows.len(), 16);
    let working: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[col(&h, "working")] == "true")
        .collect();
    assert_eq!(working.len(), 1);
    let w = working[0];
    assert!((num(&w[col(&h, "alpha")]) - 0.052204524f64.to_degrees()).abs() < 1e-6);
    assert!((num(&w[col(&h, "rho1")]) - 368.354796).abs() < 1e-6);
    assert!((num(&w[col(&h, "rho2")]) - 84.956547).abs() < 1e-6);
    assert!((num(&w[col(&h, "rho3")]) - 179.032689).abs() < 1e-6);
    let branches: Vec<i64> = rows
        .iter()
        .map(|r| num(&r[col(&h, "branch")]) as i64)
        .collect();
    assert_eq!(branches, (1..=16).collect::<Vec<_>>());
}

#[test]
fn columns_pass_through_and_pipe_into_fk() {
    let input = "id,xp,yp,zp,feed\n7,-240,-86,1000,1500\n8,-200,10,1100,1500\n";
    let ik = run(&["ik"], Some(input));
    assert_eq!(
        ik.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ik.stderr)
    );
    let (h, rows) = table(&ik);
    assert_eq!(
        h,
        [
            "id", "xp", "yp", "zp", "feed", "alpha", "rho1", "rho2", "rho3", "status"
        ]
    );
    assert_eq!(rows[0][0], "7");
    assert_eq!(rows[0][4], "1500");
    assert_eq!(rows[1][1], "-200");
    let fk = run(
        &["fk"],
        Some(&String::from_utf8(ik.stdout.clone()).unwrap()),
    );
    assert_eq!(fk.status.code(), Some(0));
    let (h2, rows2) = table(&fk);
    // Same columns: xp,yp,zp,alpha and status are replaced in place.
    assert_eq!(h2, h);
    for (a, b) in rows.iter().zip(&rows2) {
        for c in ["xp", "yp", "zp", "alpha"] {
            let k = col(&h, c);
            assert!(
                (num(&a[k]) - num(&b[k])).abs() < NUM_TOL * 1e3,
                "{c}: {} vs {}",
                a[k],
                b[k]
            );
        }
        assert_eq!(a[0], b[0]);
    }
}

#[test]
fn radians_flag_changes_angle_units() {
    let deg = table(&run(&["ik", "--pose=-240,-86,1000"], None));
    let rad = table(&run(&["ik", "--radians", "--pose=-240,-86,1000"], None));
    let k = col(&deg.0, "alpha");
    assert!((num(&deg.1[0][k]).to_radians() - num(&rad.1[0][k])).abs() < 1e-12);
}

#[test]
fn unreachable_and_invalid_rows_are_kept_with_status_and_exit_one() {
    let input = "xp,yp,zp\n-240,-86,1000\n5000,0,0\nNaN,0,0\n,1,2\n";
    let out = run(&["ik"], Some(input));
    assert_eq!(out.status.code(), Some(1));
    let (h, rows) = table(&out);
    assert_eq!(rows.len(), 4);
    let st: Vec<&str> = rows.iter().map(|r| r[col(&h, "status")].as_str()).collect();
    assert_eq!(st, ["ok", "unreachable", "invalid_input", "invalid_input"]);
    assert_eq!(rows[1][col(&h, "rho1")], "");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("3 of 4 rows not ok"), "{err}");
    // --all: an unreachable row still yields one row.
    let out = run(&["ik", "--all"], Some("xp,yp,zp\n5000,0,0\n"));
    assert_eq!(out.status.code(), Some(1));
    let (h, rows) = table(&out);
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0][col(&h, "status")], "unreachable");
}

#[test]
fn fatal_errors_name_file_line_column_and_expectation() {
    let out = run(&["ik"], Some("xp,yp,zp\n1,2,3\n1,abc,3\n"));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("<stdin>:3: column yp: expected a number (mm), found `abc`"),
        "{err}"
    );

    let out = run(&["ik"], Some("x,y\n1,2\n"));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("missing columns `xp`, `yp`, `zp`"), "{err}");

    let out = run(&["fk"], Some(""));
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("empty input"), "{err}");

    let dir = std::env::temp_dir().join(format!("verne-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "kind = \"verne\"\n[module]\nR1 = -5\n").unwrap();
    let out = run(
        &["ik", "-m", bad.to_str().unwrap(), "--pose", "1,2,3"],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.toml:3: module.R1: must be a positive length"),
        "{err}"
    );
    assert!(err.contains("module.L1: missing required key"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failed_run_leaves_no_output_file() {
    let dir = std::env::temp_dir().join(format!("verne-cli-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let target = dir.join("joints.csv");
    let out = run(
        &["ik", "-o", target.to_str().unwrap()],
        Some("xp,yp,zp\n1,2,3\n1,2,x\n"),
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(!target.exists());
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "temporary file left behind"
    );
    let out = run(
        &["ik", "-o", target.to_str().unwrap()],
        Some("xp,yp,zp\n-240,-86,1000\n"),
    );
    assert_eq!(out.status.code(), Some(0));
    assert!(
        std::fs::read_to_string(&target)
            .unwrap()
            .starts_with("xp,yp,zp,alpha")
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn machine_show_is_a_valid_machine_file() {
    let out = run(&["machine", "show"], None);
    assert_eq!(out.status.code(), Some(0));
    let dir = std::env::temp_dir().join(format!("verne-cli-m-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("m.toml");
    std::fs::write(&f, &out.stdout).unwrap();
    let check = run(&["machine", "check", f.to_str().unwrap()], None);
    assert_eq!(check.status.code(), Some(0));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bom_crlf_and_quoted_numbers_are_accepted() {
    let input = "\u{feff}xp,yp,zp\r\n\"-240\",\"-86\",\" 1000\"\r\n";
    let out = run(&["ik"], Some(input));
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (h, rows) = table(&out);
    assert_eq!(h[0], "xp");
    assert!((num(&rows[0][col(&h, "rho1")]) - 368.354796).abs() < 1e-6);
}

#[test]
fn modes_prints_an_aligned_table() {
    let out = run(&["modes", "--joints", "674,685,250"], None);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("4 real assembly modes"), "{text}");
    assert_eq!(
        text.lines().filter(|l| l.contains(" true ")).count(),
        1,
        "{text}"
    );
}

#[test]
fn committed_man_page_matches_the_cli() {
    let out = run(&["manpage"], None);
    assert_eq!(out.status.code(), Some(0));
    let committed =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/verne.1"))
            .unwrap();
    assert!(
        String::from_utf8(out.stdout).unwrap() == committed,
        "docs/verne.1 is stale: regenerate it with `cargo run -- manpage > docs/verne.1`"
    );
}

#[test]
fn every_subcommand_help_has_an_example() {
    for sub in [
        "ik",
        "fk",
        "modes",
        "workspace",
        "verify",
        "design",
        "selftest",
        "completions",
    ] {
        let out = run(&[sub, "--help"], None);
        assert_eq!(out.status.code(), Some(0), "{sub}");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.contains("verne "),
            "{sub} --help has no example:\n{text}"
        );
        assert!(
            text.contains("Example"),
            "{sub} --help has no example:\n{text}"
        );
    }
    let v = run(&["--version"], None);
    assert!(String::from_utf8_lossy(&v.stdout).starts_with("verne "));
}

#[test]
fn modes_plot_draws_every_branch() {
    let dir = std::env::temp_dir().join(format!("verne-cli-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("b.svg");
    let out = run(
        &[
            "modes",
            "--joints",
            "674,685,250",
            "--plot",
            f.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let svg = std::fs::read_to_string(&f).unwrap();
    assert!(svg.contains("<svg"));
    // A legend for the legs (colours alone said nothing).
    for leg in ["leg I: two rods", "leg II", "leg III", "guideways"] {
        assert!(svg.contains(leg), "legend entry {leg} missing");
    }
    for k in 1..=4 {
        assert!(svg.contains(&format!("{k}: s=(")), "panel {k} missing");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The examples in `verne ik --help`, `verne fk --help` and `verne modes --help` run: each
/// `verne ...` line (up to the two spaces before its note) runs, through `sh` for pipes, and
/// does not fail with a fatal error (exit 2).
#[test]
fn help_examples_run() {
    let dir = std::env::temp_dir().join(format!("verne-help-examples-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // From a scratch directory that sees the repository's data/, so what an example writes
    // (-o joints.csv, --plot modes.svg) lands there.
    let _ = std::os::unix::fs::symlink(
        std::path::Path::new(common::ROOT).join("data"),
        dir.join("data"),
    );
    let mut ran = 0;
    for sub in ["ik", "fk", "modes"] {
        let help = String::from_utf8(run(&[sub, "--help"], None).stdout).unwrap();
        for line in help.lines().filter(|l| l.starts_with("  verne ")) {
            let cmd = line.trim().split("  ").next().unwrap();
            let cmd = cmd.replace("verne ", &format!("{} ", common::BIN));
            let out = std::process::Command::new("sh")
                .args(["-c", &cmd])
                .current_dir(&dir)
                .output()
                .unwrap();
            assert!(
                matches!(out.status.code(), Some(0 | 1)),
                "`{line}` in `verne {sub} --help`: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(ran >= 8, "{ran} examples");
}

#[test]
fn quiet_verbose_and_the_summary_where_a_script_wants_it() {
    // -q: nothing on stderr but errors; the exit code still tells.
    let quiet = run(&["-q", "ik", "data/example.cl"], None);
    assert_eq!(quiet.status.code(), Some(0));
    assert!(
        quiet.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&quiet.stderr)
    );
    let normal = run(&["ik", "data/example.cl"], None);
    assert_eq!(quiet.stdout, normal.stdout, "-q changes only stderr");
    let failed = run(&["ik", "-q", "tests/data/cl-corpus/nx_axis_zero.cls"], None);
    assert_eq!(failed.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&failed.stderr).starts_with("verne: error: "));
    // -v: the machine, the rows and their rate, the time.
    let verbose = run(&["ik", "-v", "data/example.cl"], None);
    let e = String::from_utf8_lossy(&verbose.stderr);
    assert!(
        e.contains("machine `VERNE` from the embedded default"),
        "{e}"
    );
    assert!(e.contains("181 rows in, 181 rows out, 181 ok"), "{e}");
    assert_eq!(
        run(&["-q", "-v", "ik", "data/example.cl"], None)
            .status
            .code(),
        Some(2)
    );
    // verify --summary -: the text summary on stdout, nothing on stderr with -q.
    let v = run(
        &[
            "verify",
            "-q",
            "--joints",
            "data/example-post.ngc",
            "--path",
            "data/example-tcp.ngc",
            "--summary",
            "-",
        ],
        None,
    );
    assert_eq!(v.status.code(), Some(0));
    assert!(v.stderr.is_empty());
    assert!(String::from_utf8_lossy(&v.stdout).contains(": clean"));
    let both = run(
        &[
            "verify",
            "--joints",
            "data/example-post.ngc",
            "--path",
            "data/example-tcp.ngc",
            "--summary",
            "-",
            "--format",
            "json",
        ],
        None,
    );
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn command_line_poses_are_counted_from_one_and_zero_has_no_sign() {
    let out = run(
        &["ik", "--tool", "10,-20,80,0,0,1", "--tool", "1e9,0,0,0,0,1"],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("<command line>: row 2: unreachable"), "{e}");
    // fk of the home pose writes y and phi1 near zero: never "-0.000".
    let out = run(
        &[
            "fk",
            "--precision",
            "3",
            "--machine-joints",
            "314.1247,260.7776,260.5964,0,0",
        ],
        None,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("0.000") && !text.contains("-0.000"), "{text}");
}

#[test]
fn prefer_is_honoured_where_a_vertical_start_decides_and_theta2_does_not_swing() {
    // data/example.cl starts with a vertical FROM: the orientation is decided at the first
    // tilted GOTO. Each preference must hold there, and the vertical rows before it take the
    // theta2 that row needs (the rotary axis does not swing 90 degrees on the first move).
    for (prefer, orientation, theta1_sign) in
        [("orientation1", "1", -1.0), ("orientation2", "2", 1.0)]
    {
        let out = run(&["ik", "--prefer", prefer, "data/example.cl"], None);
        assert_eq!(out.status.code(), Some(0));
        let (h, rows) = table(&out);
        let decided = rows
            .iter()
            .position(|r| !r[col(&h, "flags")].contains("near_rotary_singularity"))
            .unwrap();
        assert!(decided > 0, "the path starts vertical");
        let d = &rows[decided];
        assert_eq!(d[col(&h, "orientation")], orientation, "{prefer}");
        let theta1: f64 = d[col(&h, "theta1")].parse().unwrap();
        assert_eq!(theta1.signum(), theta1_sign, "{prefer}: theta1 {theta1}");
        let t2 = |r: &Vec<String>| r[col(&h, "theta2")].parse::<f64>().unwrap();
        for r in &rows[..decided] {
            assert!(
                (t2(r) - t2(d)).abs() < 1e-9,
                "{prefer}: vertical row theta2 {} vs {}",
                t2(r),
                t2(d)
            );
        }
    }
    // The same file on stdin is read once and looked ahead in the same buffer: the same joints.
    let example = std::fs::read_to_string(format!("{}/data/example.cl", common::ROOT)).unwrap();
    let piped = run(&["ik", "--prefer", "orientation2"], Some(&example));
    let named = run(&["ik", "--prefer", "orientation2", "data/example.cl"], None);
    assert_eq!(piped.status.code(), Some(0));
    assert_eq!(table(&piped).1, table(&named).1);
    assert_ne!(table(&piped).1[0][col(&table(&piped).0, "theta2")], "0");
}

/// A joint list (halstreamer, G-code) stops at a row it cannot solve (exit 1, a row failed): to a file nothing is
/// written; to stdout the rows before it may already be in the pipe, and the error says so.
#[test]
fn a_stopped_joint_list_on_stdout_is_called_incomplete() {
    let path = "x,y,z,i,j,k\n0,0,150,0,0,1\n5000,0,0,0,0,1\n";
    let out = run(&["ik", "--format", "halstreamer"], Some(path));
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("<stdin>:3") && err.contains("incomplete"),
        "{err}"
    );
    let dir = std::env::temp_dir().join(format!("verne-stopped-list-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("joints.hal");
    let out = run(
        &[
            "ik",
            "--format",
            "halstreamer",
            "-o",
            file.to_str().unwrap(),
        ],
        Some(path),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("incomplete"), "{err}");
    assert!(!file.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every input is opened once: a named pipe or `/dev/stdin` gives the same output as the file
/// (a CL file, a tool-centre program, a CSV toolpath, and both inputs of `verify`), never a hang
/// or a second read.
#[test]
fn a_named_pipe_reads_as_the_file_does() {
    let dir = std::env::temp_dir().join(format!("verne-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = |name: &str, from: &str| -> (std::path::PathBuf, std::thread::JoinHandle<()>) {
        let p = dir.join(name);
        let _ = std::fs::remove_file(&p);
        let made = std::process::Command::new("mkfifo")
            .arg(&p)
            .status()
            .unwrap();
        assert!(made.success());
        let bytes = std::fs::read(format!("{}/{from}", common::ROOT)).unwrap();
        let q = p.clone();
        let writer = std::thread::spawn(move || {
            let _ = std::fs::write(&q, bytes);
        });
        (p, writer)
    };
    for file in [
        "data/example.cl",
        "data/example-tcp.ngc",
        "data/platform_path.csv",
    ] {
        let named = run(&["ik", file], None);
        let (p, writer) = fifo("input", file);
        let piped = run(&["ik", p.to_str().unwrap()], None);
        writer.join().unwrap();
        assert_eq!(piped.status.code(), named.status.code(), "{file}");
        assert_eq!(piped.stdout, named.stdout, "{file}");
        let text = std::fs::read_to_string(format!("{}/{file}", common::ROOT)).unwrap();
        let stdin = run(&["ik", "/dev/stdin"], Some(&text));
        assert_eq!(stdin.stdout, named.stdout, "{file} through /dev/stdin");
    }
    let named = run(
        &[
            "verify",
            "--joints",
            "data/example-post.ngc",
            "--path",
            "data/example-tcp.ngc",
        ],
        None,
    );
    let (j, wj) = fifo("joints", "data/example-post.ngc");
    let (p, wp) = fifo("path", "data/example-tcp.ngc");
    let piped = run(
        &[
            "verify",
            "--joints",
            j.to_str().unwrap(),
            "--path",
            p.to_str().unwrap(),
        ],
        None,
    );
    wj.join().unwrap();
    wp.join().unwrap();
    assert_eq!(piped.status.code(), named.status.code());
    let _ = std::fs::remove_dir_all(&dir);
}
