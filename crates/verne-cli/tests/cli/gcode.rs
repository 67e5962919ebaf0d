//! G-code through the CLI: tool-centre programs into `verne ik` (their joints give back the
//! programmed poses through `verne fk`), `--format gcode` joint programs read back by
//! `verne verify --joints` (the shipped example clean, an injected defect found at its line;
//! the same findings as the CSV post on the CL corpus), the machine file's `[gcode]` letters,
//! and the refusals that keep one kind of program from being read as the other.

use crate::common;

use common::{ROOT, col, run, table, table_of};

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-gcode-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn the_joints_of_a_tool_centre_program_give_back_its_poses() {
    for program in [
        "data/example-tcp.ngc",
        "tests/data/gcode/tcp-arcs.ngc",
        "tests/data/gcode/tcp-inch-cycles.ngc",
    ] {
        let ik = run(&["ik", program], None);
        assert_eq!(ik.status.code(), Some(0), "{program}: {}", stderr(&ik));
        let (h, rows) = table_of(&ik);
        assert!(rows.len() > 20, "{program}");
        // The joints, back through the forward kinematics.
        let mut joints = String::from("rho1,rho2,rho3,theta1,theta2\n");
        for r in &rows {
            let cells: Vec<&str> = ["rho1", "rho2", "rho3", "theta1", "theta2"]
                .iter()
                .map(|c| r[col(&h, c)].as_str())
                .collect();
            joints.push_str(&cells.join(","));
            joints.push('\n');
        }
        let fk = run(&["fk"], Some(&joints));
        assert_eq!(fk.status.code(), Some(0), "{program}: {}", stderr(&fk));
        let (fh, back) = table_of(&fk);
        assert_eq!(back.len(), rows.len());
        let num = |s: &str| s.parse::<f64>().unwrap();
        for (r, b) in rows.iter().zip(&back) {
            for c in ["x", "y", "z", "i", "j", "k"] {
                let (want, got) = (num(&r[col(&h, c)]), num(&b[col(&fh, c)]));
                assert!(
                    (want - got).abs() < 1e-6,
                    "{program} line {}: {c} {want} vs {got}",
                    r[0]
                );
            }
        }
    }
}

#[test]
fn the_shipped_post_is_what_ik_writes_and_verifies_clean() {
    let written = tmp("example-post.ngc");
    let ik = run(
        &[
            "ik",
            "data/example-tcp.ngc",
            "--format",
            "gcode",
            "-o",
            written.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(ik.status.code(), Some(0), "{}", stderr(&ik));
    let shipped = std::fs::read_to_string(format!("{ROOT}/data/example-post.ngc")).unwrap();
    let made = std::fs::read_to_string(&written).unwrap();
    let tail = |s: &str| {
        s.lines()
            .skip(1)
            .skip_while(|l| l.starts_with('('))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(
        tail(&made),
        tail(&shipped),
        "data/example-post.ngc is stale: rerun the command in the README"
    );
    let v = run(
        &[
            "verify",
            "--joints",
            "data/example-post.ngc",
            "--path",
            "data/example-tcp.ngc",
        ],
        None,
    );
    assert_eq!(v.status.code(), Some(0), "{}", stderr(&v));
    assert!(stderr(&v).contains("clean"), "{}", stderr(&v));
}

#[test]
fn a_defect_in_the_post_is_found_at_its_block() {
    let shipped = std::fs::read_to_string(format!("{ROOT}/data/example-post.ngc")).unwrap();
    // Move one slider of one block by 0.5 mm.
    let target = shipped
        .lines()
        .position(|l| l.starts_with("N300 "))
        .expect("block N300");
    let mut lines: Vec<String> = shipped.lines().map(str::to_string).collect();
    let words: Vec<String> = lines[target]
        .split(' ')
        .map(|w| match w.strip_prefix('V') {
            Some(v) => format!("V{}", v.parse::<f64>().unwrap() + 0.5),
            None => w.to_string(),
        })
        .collect();
    lines[target] = words.join(" ");
    let bad = tmp("bad-post.ngc");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    let report = tmp("report.csv");
    let v = run(
        &[
            "verify",
            "--joints",
            bad.to_str().unwrap(),
            "--path",
            "data/example-tcp.ngc",
            "--report",
            report.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(v.status.code(), Some(1), "{}", stderr(&v));
    let (h, rows) = table(&std::fs::read_to_string(&report).unwrap());
    let tip_errors: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[col(&h, "check")] == "tip_error")
        .collect();
    assert_eq!(tip_errors.len(), 1, "{rows:?}");
    assert_eq!(tip_errors[0][col(&h, "row")], "N300");
}

/// The joint program `verne ik` writes verifies clean against its path (CL files of three
/// dialects, a tool-centre program with arcs); the same path posted one row per block, without
/// the inserted poses, is found off the intended move (chord and axis findings, and joint jumps
/// on the long moves), and nothing else.
#[test]
fn the_posted_program_verifies_clean_and_the_unlinearized_one_does_not() {
    for path in [
        "data/example.cl",
        "tests/data/cl-corpus/nx_basic.cls",
        "tests/data/cl-corpus/catia_sweep.aptsource",
        "tests/data/gcode/tcp-arcs.ngc",
    ] {
        let mut counts = Vec::new();
        for extra in [None, Some("--no-linearize")] {
            let post = tmp("post.ngc");
            let mut args = vec![
                "ik",
                path,
                "--format",
                "gcode",
                "-o",
                post.to_str().unwrap(),
            ];
            args.extend(extra);
            let ik = run(&args, None);
            assert_eq!(ik.status.code(), Some(0), "{path}: {}", stderr(&ik));
            let report = tmp("report.csv");
            let v = run(
                &[
                    "verify",
                    "--joints",
                    post.to_str().unwrap(),
                    "--path",
                    path,
                    "--report",
                    report.to_str().unwrap(),
                ],
                None,
            );
            let (h, rows) = table(&std::fs::read_to_string(&report).unwrap());
            let checks: Vec<String> = rows.iter().map(|r| r[col(&h, "check")].clone()).collect();
            if extra.is_none() {
                assert_eq!(
                    v.status.code(),
                    Some(0),
                    "{path}: {checks:?} {}",
                    stderr(&v)
                );
            } else {
                assert!(
                    checks
                        .iter()
                        .all(|c| ["chord_error", "chord_axis", "joint_jump"].contains(&c.as_str())),
                    "{path}: {checks:?}"
                );
            }
            counts.push(checks.len());
        }
        assert_eq!(counts[0], 0, "{path}");
    }
}

#[test]
fn the_machine_file_names_the_joints() {
    let default = run(&["machine", "show"], None);
    let text = String::from_utf8(default.stdout).unwrap();
    let custom = text
        .replace("rho1 = \"U\"", "rho1 = \"X\"")
        .replace("rho2 = \"V\"", "rho2 = \"-Y\"")
        .replace("rho3 = \"W\"", "rho3 = \"Z\"\nrho3_offset = 100.0")
        .replace("theta2 = \"C\"", "theta2 = \"B\"");
    let machine = tmp("letters.toml");
    std::fs::write(&machine, custom).unwrap();
    let m = machine.to_str().unwrap();
    let post = tmp("letters.ngc");
    let ik = run(
        &[
            "ik",
            "-m",
            m,
            "data/example-tcp.ngc",
            "--format",
            "gcode",
            "-o",
            post.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(ik.status.code(), Some(0), "{}", stderr(&ik));
    let text = std::fs::read_to_string(&post).unwrap();
    let first = text.lines().find(|l| l.starts_with("N20 ")).unwrap();
    assert!(
        first.contains(" Y-") && first.contains(" B") && !first.contains(" U"),
        "{first}"
    );
    let v = run(
        &[
            "verify",
            "-m",
            m,
            "--joints",
            post.to_str().unwrap(),
            "--path",
            "data/example-tcp.ngc",
        ],
        None,
    );
    assert_eq!(v.status.code(), Some(0), "{}", stderr(&v));
    // Read with the default letters, the same program is refused at its first block.
    let v = run(
        &[
            "verify",
            "--joints",
            post.to_str().unwrap(),
            "--path",
            "data/example-tcp.ngc",
        ],
        None,
    );
    assert_eq!(v.status.code(), Some(2));
    let e = stderr(&v);
    assert!(
        e.contains("are not words of a joint program") && e.contains("tool-centre program"),
        "{e}"
    );
    let bad = tmp("bad-letters.toml");
    std::fs::write(
        &bad,
        String::from_utf8(run(&["machine", "show"], None).stdout)
            .unwrap()
            .replace("theta1 = \"A\"", "theta1 = \"U\""),
    )
    .unwrap();
    let c = run(&["machine", "check", bad.to_str().unwrap()], None);
    assert_eq!(c.status.code(), Some(2));
    assert!(stderr(&c).contains("gcode.theta1"), "{}", stderr(&c));
}

#[test]
fn one_kind_of_program_is_never_read_as_the_other() {
    // A joint program given as the intended path.
    let v = run(&["ik", "data/example-post.ngc"], None);
    assert_eq!(v.status.code(), Some(2));
    let e = stderr(&v);
    assert!(
        e.contains("are not words of a tool-centre program")
            && e.contains("data/example-post.ngc:7: "),
        "{e}"
    );
    // An incomplete first pose, on stdin (sniffed as G-code, not CSV).
    let v = run(&["ik"], Some("G21 G90\nG0 X0 Y0 Z100\nM2\n"));
    assert_eq!(v.status.code(), Some(2));
    let e = stderr(&v);
    assert!(
        e.contains("<stdin>:2: ") && e.contains("A C not given"),
        "{e}"
    );
    // What the reader does not evaluate, with its line and column.
    let v = run(&["ik"], Some("G21 G90\nG0 X#1 Y0 Z100 A0 C0\nM2\n"));
    assert_eq!(v.status.code(), Some(2));
    let e = stderr(&v);
    assert!(
        e.contains("<stdin>:2: column 5: ") && e.contains("parameters"),
        "{e}"
    );
}

#[test]
fn ik_reports_where_the_joints_went() {
    let ik = run(&["ik", "data/example-tcp.ngc"], None);
    assert_eq!(ik.status.code(), Some(0));
    let (h, rows) = table_of(&ik);
    let e = stderr(&ik);
    let line = e
        .lines()
        .find(|l| l.contains("joint travel"))
        .unwrap_or_else(|| panic!("{e}"));
    for (name, unit) in [
        ("rho1", "mm"),
        ("rho2", "mm"),
        ("rho3", "mm"),
        ("theta1", "deg"),
        ("theta2", "deg"),
    ] {
        let v: Vec<f64> = rows
            .iter()
            .map(|r| r[col(&h, name)].parse().unwrap())
            .collect();
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        let want = format!("{name} {lo:.3}..{hi:.3} {unit}");
        assert!(line.contains(&want), "{want} not in {line}");
    }
    // The turns of theta2, as the rows give them (at the vertical rows theta2 keeps its value).
    let t2: Vec<f64> = rows
        .iter()
        .map(|r| r[col(&h, "theta2")].parse().unwrap())
        .collect();
    let travel: f64 = t2.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>() / 360.0;
    assert!(
        line.contains(&format!("({travel:.2} turns travelled)")),
        "{line}"
    );
    assert!(line.contains("margins"), "{line}");
    let flagged = rows
        .iter()
        .filter(|r| r[col(&h, "flags")].contains("near_rotary_singularity"))
        .count();
    assert!(
        line.ends_with(&format!(
            "; {flagged} rows near the rotary-axis singularity"
        )),
        "{line}"
    );
}

/// A tool-centre program with a `G93` block (its own time of the move) is posted with that time:
/// the joint block's inverse-time F is 60 / dt (it was refused for want of a feed), and the post
/// verifies against the program row for row.
#[test]
fn a_g93_block_is_posted_with_the_time_the_program_states() {
    let dir = std::env::temp_dir().join(format!("verne-g93-post-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let post = dir.join("post.ngc");
    let program = "tests/data/gcode/tcp-inch-cycles.ngc";
    let out = common::run(
        &[
            "ik",
            program,
            "--format",
            "gcode",
            "-o",
            post.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&post).unwrap();
    // N15 G93 G1 X8. Y3. Z1. F30. (file line 17): inverse time 30/min, the move takes 2 s;
    // linearized, its blocks share the 2 s by length, and only the last is slower (the next
    // move, at 20 inch/min, is slower still: the machine slows into it).
    let times: Vec<f64> = text
        .lines()
        .filter(|l| l.contains(" line 17)"))
        .map(|l| {
            let f: f64 = l
                .split(" F")
                .nth(1)
                .unwrap()
                .split(' ')
                .next()
                .unwrap()
                .parse()
                .unwrap();
            60.0 / f
        })
        .collect();
    let total: f64 = times.iter().sum();
    assert!(times.len() > 1, "{times:?}");
    assert!((2.0..2.2).contains(&total), "{total}: {times:?}");
    let share = 2.0 / times.len() as f64;
    for t in &times[..times.len() - 1] {
        assert!(
            (t - share).abs() < 1e-6 * share,
            "{t} vs {share}: {times:?}"
        );
    }
    let out = common::run(
        &[
            "verify",
            "--joints",
            post.to_str().unwrap(),
            "--path",
            program,
        ],
        None,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("segments checked (0 skipped"), "{err}");
    assert!(err.contains(": clean"), "{err}");
    for check in [
        "pairing",
        "tip_error",
        "axis_error",
        "velocity",
        "acceleration",
    ] {
        let line = err.lines().find(|l| l.starts_with(check)).unwrap();
        assert_eq!(line.split_whitespace().nth(1), Some("0"), "{line}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
