//! The post end to end: for the shipped example and four kinds of 5-axis path (a swarf ring, a
//! pass next to the table normal, long moves with tilt changes, a 3+2 pocket with CIRCLE arcs),
//! `verne ik PATH --format gcode` writes a program that `verne verify` finds clean, and an
//! independent dense check confirms the tolerance: the complete forward kinematics of the
//! interpolated joints at 64 points of every block, against the intended move computed here
//! from the CL reader's rows (no code of the post or of verify in between).

use crate::common;

use common::run;
use nalgebra::Vector3;
use verne::machine::machine_fk;
use verne::machine::orientation::tool_axis;
use verne::spec::Machine;

const PATHS: [&str; 5] = [
    "data/example.cl",
    "tests/data/post/ring.cl",
    "tests/data/post/normal.cl",
    "tests/data/post/long.cl",
    "tests/data/post/pocket.cl",
];

/// The default tolerances the program is linearized within: the machine's chord_error_mm (mm)
/// and chord_axis_error_deg.
const TIP_TOL_MM: f64 = 0.01;
const AXIS_TOL_DEG: f64 = 0.01;

/// One block of a joint program: joints (mm, rad), the path row it leads to and the fraction of
/// the move for an inserted pose, and whether it is a feed block.
struct Block {
    q: [f64; 5],
    row: usize,
    fraction: Option<f64>,
    feed: bool,
}

fn blocks(program: &str) -> Vec<Block> {
    program
        .lines()
        .filter(|l| l.starts_with('N'))
        .map(|l| {
            let word = |c: char| -> f64 {
                l.split(' ')
                    .find_map(|w| w.strip_prefix(c))
                    .unwrap_or_else(|| panic!("{c} in {l}"))
                    .parse()
                    .unwrap()
            };
            let comment = l.split('(').nth(1).unwrap().trim_end_matches(')');
            let words: Vec<&str> = comment.split(' ').collect();
            assert_eq!(&words[..2], ["path", "row"], "{l}");
            let row: usize = words[2].parse().unwrap();
            let fraction = (words[3] == "at").then(|| words[4].parse::<f64>().unwrap());
            Block {
                q: [
                    word('U'),
                    word('V'),
                    word('W'),
                    word('A').to_radians(),
                    word('C').to_radians(),
                ],
                row,
                fraction,
                feed: l.contains(" G1 "),
            }
        })
        .collect()
}

/// The great-circle axis a fraction `s` of the way from `a` to `b`.
fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, s: f64) -> Vector3<f64> {
    let w = a.angle(b);
    if w < 1e-12 {
        return *a;
    }
    (a * ((1.0 - s) * w).sin() + b * (s * w).sin()) / w.sin()
}

#[test]
fn every_posted_program_verifies_clean_and_holds_the_tolerance_between_its_blocks() {
    let m = Machine::default_verne();
    let dir = std::env::temp_dir().join(format!("verne-post-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for path in PATHS {
        let post = dir.join("post.ngc");
        let ik = run(
            &[
                "ik",
                path,
                "--format",
                "gcode",
                "-o",
                post.to_str().unwrap(),
            ],
            None,
        );
        assert_eq!(
            ik.status.code(),
            Some(0),
            "{path}: {}",
            String::from_utf8_lossy(&ik.stderr)
        );
        let v = run(
            &["verify", "--joints", post.to_str().unwrap(), "--path", path],
            None,
        );
        let err = String::from_utf8_lossy(&v.stderr);
        assert_eq!(v.status.code(), Some(0), "{path}: {err}");
        assert!(err.contains(": clean"), "{path}: {err}");
        // The intended poses, from the CL reader alone.
        let text = std::fs::read(format!("{}/{path}", common::ROOT)).unwrap();
        let (rows, _) = verne_cl::read_all(path, &text, &verne_cl::Options::default()).unwrap();
        let pose = |row: usize, fraction: Option<f64>| -> (Vector3<f64>, Vector3<f64>) {
            let b = &rows[row - 1];
            let (tb, ab) = (Vector3::from(b.tip), Vector3::from(b.axis));
            match fraction {
                None => (tb, ab),
                Some(s) => {
                    let a = &rows[row - 2];
                    let (ta, aa) = (Vector3::from(a.tip), Vector3::from(a.axis));
                    (ta + (tb - ta) * s, slerp(&aa, &ab, s))
                }
            }
        };
        let program = blocks(&std::fs::read_to_string(&post).unwrap());
        let mut worst: (f64, f64) = (0.0, 0.0);
        for w in program.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            if !b.feed {
                continue;
            }
            let (pa, ua) = pose(a.row, a.fraction);
            let (pb, ub) = pose(b.row, b.fraction);
            for k in 0..=64 {
                let s = k as f64 / 64.0;
                let q: [f64; 5] = std::array::from_fn(|j| a.q[j] + s * (b.q[j] - a.q[j]));
                let (tip, axis) = (pa + (pb - pa) * s, slerp(&ua, &ub, s));
                let rho = Vector3::new(q[0], q[1], q[2]);
                let mode = machine_fk(&m, &rho, q[3], q[4], m.tool_length)
                    .iter()
                    .filter(|md| md.working())
                    .min_by(|x, y| {
                        (x.tool.tip - tip)
                            .norm()
                            .total_cmp(&(y.tool.tip - tip).norm())
                    })
                    .map(|md| (md.tool.tip, tool_axis(md.tool.phi1, md.tool.phi2)))
                    .unwrap_or_else(|| panic!("{path}: no working mode inside a block"));
                worst.0 = worst.0.max((mode.0 - tip).norm());
                worst.1 = worst.1.max(mode.1.angle(&axis).to_degrees());
            }
        }
        // The blocks' ends carry the joint words' rounding (1e-6 mm and degrees).
        assert!(worst.0 <= TIP_TOL_MM + 1e-4, "{path}: tip {} mm", worst.0);
        assert!(
            worst.1 <= AXIS_TOL_DEG + 1e-4,
            "{path}: axis {} deg",
            worst.1
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same paths posted one block per row (`--no-linearize`): the tool leaves the intended
/// move, and verify says so with the size of the gouge (a long move with a tilt change: tens of
/// mm, even where its joints also jump).
#[test]
fn unlinearized_programs_are_found_off_the_intended_move() {
    let dir = std::env::temp_dir().join(format!("verne-post-raw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (path, at_least_mm) in [
        ("tests/data/post/long.cl", 10.0),
        ("tests/data/post/ring.cl", 0.05),
    ] {
        let post = dir.join("raw.ngc");
        let report = dir.join("report.csv");
        let ik = run(
            &[
                "ik",
                path,
                "--format",
                "gcode",
                "--no-linearize",
                "-o",
                post.to_str().unwrap(),
            ],
            None,
        );
        assert_eq!(ik.status.code(), Some(0));
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
        assert_eq!(v.status.code(), Some(1));
        let (h, rows) = common::table(&std::fs::read_to_string(&report).unwrap());
        let worst = rows
            .iter()
            .filter(|r| r[common::col(&h, "check")] == "chord_error")
            .map(|r| r[common::col(&h, "value")].parse::<f64>().unwrap())
            .fold(0.0, f64::max);
        assert!(worst >= at_least_mm, "{path}: {worst}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `verne fk` reads a joint program: the tool poses of the blocks that end on a path row are
/// the path's (to the joint words' rounding), inserted ones lie on their move.
#[test]
fn fk_turns_a_posted_program_back_into_the_path() {
    let dir = std::env::temp_dir().join(format!("verne-post-fk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let post = dir.join("post.ngc");
    let path = "tests/data/post/long.cl";
    let ik = run(
        &[
            "ik",
            path,
            "--format",
            "gcode",
            "-o",
            post.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(ik.status.code(), Some(0));
    let fk = run(&["fk", post.to_str().unwrap()], None);
    assert_eq!(
        fk.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&fk.stderr)
    );
    let (h, rows) = common::table_of(&fk);
    let program = blocks(&std::fs::read_to_string(&post).unwrap());
    assert_eq!(rows.len(), program.len());
    let text = std::fs::read(format!("{}/{path}", common::ROOT)).unwrap();
    let (cl, _) = verne_cl::read_all(path, &text, &verne_cl::Options::default()).unwrap();
    for (r, b) in rows.iter().zip(&program) {
        let tip = Vector3::new(
            r[common::col(&h, "x")].parse::<f64>().unwrap(),
            r[common::col(&h, "y")].parse::<f64>().unwrap(),
            r[common::col(&h, "z")].parse::<f64>().unwrap(),
        );
        let want = Vector3::from(cl[b.row - 1].tip);
        let start = if b.row > 1 {
            Vector3::from(cl[b.row - 2].tip)
        } else {
            want
        };
        let on = match b.fraction {
            None => want,
            Some(s) => start + (want - start) * s,
        };
        assert!(
            (tip - on).norm() < 1e-4,
            "block to row {} at {:?}: {tip} vs {on}",
            b.row,
            b.fraction
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
