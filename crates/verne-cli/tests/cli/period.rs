//! `verne ik --period`: a joint stream at the servo period has one row per period of programmed
//! motion (to within a row per move), its time column steps by the period, and each row's
//! joints are the inverse kinematics of a pose on the programmed move.

use crate::common;

use common::{col, run, table_of};
use verne_cl::{Motion, Options};

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The programmed time of data/example.cl (s), by the rule of docs/gcode.md: each move's tip
/// path at its feed, or its axis turn in degrees at the feed when the tip stays; rapids at
/// `rapid` mm/min.
fn programmed_time(rapid: f64) -> (f64, usize) {
    let text = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../data/example.cl"
    ))
    .unwrap();
    let (rows, _) = verne_cl::read_all("example.cl", &text, &Options::default()).unwrap();
    let mut t = 0.0;
    for w in rows.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let len = (0..3)
            .map(|k| (b.tip[k] - a.tip[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let dot: f64 = (0..3).map(|k| a.axis[k] * b.axis[k]).sum();
        let turn = dot.clamp(-1.0, 1.0).acos().to_degrees();
        let rate = match b.motion {
            Motion::Rapid => rapid,
            Motion::Feed => b.feed_mm_min.unwrap(),
        };
        t += 60.0 * if len > 1e-9 { len } else { turn } / rate;
    }
    (t, rows.len())
}

#[test]
fn a_halstreamer_stream_has_one_row_per_period() {
    let (t, moves) = programmed_time(12_000.0);
    for (period, arg) in [(1e-3, "1ms"), (4e-3, "4ms")] {
        let out = run(
            &[
                "ik",
                "data/example.cl",
                "--format",
                "halstreamer",
                "--period",
                arg,
                "--rapid",
                "12000",
            ],
            None,
        );
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let rows = String::from_utf8_lossy(&out.stdout).lines().count() as f64;
        let expected = (t / period).floor() + 1.0;
        assert!(
            (rows - expected).abs() <= 1.0,
            "{arg}: {rows} rows for {t:.3} s of motion ({expected} expected, {moves} moves)"
        );
        assert!(!stderr(&out).contains("one row per path point"));
    }
    // Without --period, stderr says what the rows are.
    let out = run(&["ik", "data/example.cl", "--format", "halstreamer"], None);
    assert!(
        stderr(&out).contains("one row per path point"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn the_time_column_steps_by_the_period_and_the_rows_are_on_the_moves() {
    let out = run(
        &[
            "ik",
            "tests/data/gcode/tcp-inch-cycles.ngc",
            "--period",
            "2ms",
            "--rapid",
            "5000",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (h, rows) = table_of(&out);
    let t: Vec<f64> = rows
        .iter()
        .map(|r| r[col(&h, "t")].parse().unwrap())
        .collect();
    for (k, w) in t.windows(2).enumerate() {
        if k + 2 < t.len() {
            assert!(
                (w[1] - w[0] - 0.002).abs() < 2e-6,
                "row {k}: {} -> {}",
                w[0],
                w[1]
            );
        } else {
            assert!(
                w[1] > w[0] && w[1] - w[0] <= 0.002 + 1e-6,
                "the end of the path"
            );
        }
    }
    // Block N15 (G93 F30) takes 2 s: its rows span 2 s at 2 ms.
    let n15: Vec<f64> = rows
        .iter()
        .filter(|r| r[col(&h, "line")] == "17")
        .map(|r| r[col(&h, "t")].parse().unwrap())
        .collect();
    let span = n15.last().unwrap() - n15.first().unwrap();
    assert!(
        (span - 2.0).abs() <= 0.0041,
        "G93 block over {span} s ({} rows)",
        n15.len()
    );
    // Every row is ok and its tip lies on the segment of its block (here: N15 from
    // (7, 1, 2) in to (8, 3, 1) in).
    assert!(rows.iter().all(|r| r[col(&h, "status")] == "ok"));
    let (a, b) = (
        [7.0 * 25.4, 25.4, 2.0 * 25.4],
        [8.0 * 25.4, 3.0 * 25.4, 25.4],
    );
    for r in rows.iter().filter(|r| r[col(&h, "line")] == "17") {
        let p: Vec<f64> = ["x", "y", "z"]
            .iter()
            .map(|c| r[col(&h, c)].parse().unwrap())
            .collect();
        let d: Vec<f64> = (0..3).map(|k| b[k] - a[k]).collect();
        let s = (0..3).map(|k| (p[k] - a[k]) * d[k]).sum::<f64>()
            / d.iter().map(|v| v * v).sum::<f64>();
        let off = (0..3)
            .map(|k| (a[k] + s * d[k] - p[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(
            (-1e-9..=1.0 + 1e-9).contains(&s) && off < 1e-9,
            "{p:?} off the move by {off}"
        );
    }
}

#[test]
fn what_cannot_be_timed_is_refused() {
    let out = run(&["ik", "data/example.cl", "--period", "1ms"], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--rapid"), "{}", stderr(&out));
    let out = run(
        &["ik", "--tool", "10,-20,80,0,0,1", "--period", "1ms"],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("feed"), "{}", stderr(&out));
    let out = run(&["ik", "data/example.cl", "--rapid", "1000"], None);
    assert_eq!(
        out.status.code(),
        Some(2),
        "--rapid alone: {}",
        stderr(&out)
    );
    let out = run(&["ik", "data/example.cl", "--period", "1ns"], None);
    assert_eq!(out.status.code(), Some(2));
}

/// With --period the samples are timed by the feeds, so the travel summary gives each joint's
/// largest speed: equal to the largest change per period in the stream itself.
#[test]
fn the_travel_summary_gives_the_joint_speeds_of_a_timed_stream() {
    let dir = std::env::temp_dir().join(format!("verne-period-speeds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("stream.hal");
    let out = common::run(
        &[
            "ik",
            "data/example.cl",
            "--format",
            "halstreamer",
            "--period",
            "1ms",
            "--rapid",
            "5000",
            "-o",
            file.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    let speeds = err
        .split("largest speeds ")
        .nth(1)
        .unwrap_or_else(|| panic!("no speeds: {err}"));
    let printed: Vec<f64> = speeds
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter_map(|w| w.parse().ok())
        .collect();
    assert_eq!(printed.len(), 5, "{speeds}");
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&file)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    for k in 0..5 {
        let largest = rows
            .windows(2)
            .map(|w| (w[1][k] - w[0][k]).abs() / 0.001)
            .fold(0.0, f64::max);
        assert!(
            (largest - printed[k]).abs() < 1e-3,
            "joint {k}: {largest} vs {}",
            printed[k]
        );
    }
    // Without --period the rows are path points, not timed: no speeds are claimed.
    let out = common::run(&["ik", "data/example.cl"], None);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("largest speeds"));
    let _ = std::fs::remove_dir_all(&dir);
}
