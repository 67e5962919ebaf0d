//! `verne verify --recording`: a servo-period joint stream (a halstreamer stream written by
//! `verne ik --period`, the same with halsampler's sample numbers, extra columns and an overrun
//! line) against the program it came from: every sample on the path (contour errors at rounding
//! level), a perturbed sample reported at its line by the tip check, lost samples reported, bad
//! input fatal with the line.

use crate::common;

use std::fs;
use std::path::{Path, PathBuf};

use common::run;

/// A CL path (tool axes): the stream and the contour interpolate its angles the same way.
const PROGRAM: &str = "data/example.cl";

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-recording-{}-{test}", std::process::id()));
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// The program's joints resampled at 1 ms, as halstreamer plays them.
fn stream(dir: &Path) -> Vec<String> {
    stream_of(dir, PROGRAM)
}

fn stream_of(dir: &Path, program: &str) -> Vec<String> {
    let file = dir.join("stream.hal");
    let out = run(
        &[
            "ik",
            program,
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
    fs::read_to_string(file)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Runs verify on `lines` written to `name`; returns (exit code, report rows, stderr).
fn verify(dir: &Path, name: &str, lines: &[String], extra: &[&str]) -> (i32, Vec<String>, String) {
    verify_against(dir, name, lines, PROGRAM, extra)
}

fn verify_against(
    dir: &Path,
    name: &str,
    lines: &[String],
    program: &str,
    extra: &[&str],
) -> (i32, Vec<String>, String) {
    let file = dir.join(name);
    fs::write(&file, lines.join("\n") + "\n").unwrap();
    let report = dir.join(format!("{name}.report.csv"));
    let mut args = vec![
        "verify",
        "--joints",
        file.to_str().unwrap(),
        "--recording",
        "--period",
        "1ms",
        "--path",
        program,
        "--report",
        report.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = run(&args, None);
    let rows = fs::read_to_string(&report)
        .map(|t| t.lines().skip(1).map(str::to_string).collect())
        .unwrap_or_default();
    (
        out.status.code().unwrap(),
        rows,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The checks of the report rows other than acceleration (the stream changes speed at a corner
/// within one period: no acceleration planning, reported as it should be).
fn checks_besides_acceleration(rows: &[String]) -> Vec<String> {
    rows.iter()
        .filter(|r| r.split(',').nth(1) != Some("acceleration"))
        .cloned()
        .collect()
}

#[test]
fn a_stream_follows_its_program_and_a_perturbed_sample_is_found_at_its_line() {
    let dir = scratch("stream");
    let lines = stream(&dir);
    assert!(lines.len() > 10_000, "{} samples", lines.len());
    let (code, rows, err) = verify(&dir, "clean.hal", &lines, &[]);
    assert!(code <= 1, "{err}");
    assert!(
        checks_besides_acceleration(&rows).is_empty(),
        "{rows:?}\n{err}"
    );
    // The samples are timed by the period: the speed changed at a corner within one period is
    // reported (so speeds are checked).
    assert!(
        rows.iter().any(|r| r.contains(",acceleration,")),
        "{rows:?}\n{err}"
    );
    // The contour error of the clean stream is at rounding level.
    let tip_line = err.lines().find(|l| l.starts_with("tip_error")).unwrap();
    let worst: f64 = tip_line.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!(worst < 1e-4, "{tip_line}");

    // Slider 1 of sample 20000 moved by 0.5 mm: the tip leaves the path there.
    let mut bad = lines.clone();
    let k = 19_999;
    let mut f: Vec<f64> = bad[k]
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    f[0] += 0.5;
    bad[k] = f
        .iter()
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(" ");
    let (code, rows, err) = verify(&dir, "bad.hal", &bad, &[]);
    assert_eq!(code, 1, "{err}");
    let tips: Vec<&String> = rows.iter().filter(|r| r.contains(",tip_error,")).collect();
    assert_eq!(tips.len(), 1, "{rows:?}");
    assert!(tips[0].starts_with("20000,"), "{}", tips[0]);
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_tool_centre_program_streams_its_angle_words() {
    // data/example-tcp.ngc gives the orientation as A C words: its last rapid, A10 C30 to A0 C0,
    // turns C as it tilts back to the table normal. The stream interpolates the words as
    // LinuxCNC does (it took them from the axes before, keeping C: 0.47 deg off there), and the
    // vertical rows take theta2 = -C = 0 as programmed.
    let dir = scratch("tcp");
    let lines = stream_of(&dir, "data/example-tcp.ngc");
    let (code, rows, err) = verify_against(&dir, "tcp.hal", &lines, "data/example-tcp.ngc", &[]);
    assert!(code <= 1, "{err}");
    assert!(
        checks_besides_acceleration(&rows).is_empty(),
        "{rows:?}\n{err}"
    );
    for check in ["tip_error", "axis_error"] {
        let line = err.lines().find(|l| l.starts_with(check)).unwrap();
        let worst: f64 = line.split_whitespace().nth(2).unwrap().parse().unwrap();
        assert!(worst < 1e-6, "{line}");
    }
    let theta2: Vec<f64> = lines
        .iter()
        .map(|l| l.split_whitespace().nth(4).unwrap().parse().unwrap())
        .collect();
    assert_eq!(
        theta2[0], 0.0,
        "the program starts at C0 on the table normal"
    );
    assert_eq!(*theta2.last().unwrap(), 0.0, "and ends there");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_halsampler_recording_with_tags_extra_columns_and_an_overrun() {
    let dir = scratch("halsampler");
    let lines = stream(&dir);
    // halsampler -t: the sample number first; two more pins after the joints; lost samples
    // leave a gap in the numbers and an `overrun` line.
    let mut rec: Vec<String> = Vec::new();
    for (k, l) in lines.iter().enumerate().take(5000) {
        if (3000..3010).contains(&k) {
            if k == 3000 {
                rec.push("overrun".into());
            }
            continue;
        }
        rec.push(format!("{} {l} 42 0", k + 100));
    }
    let cols = ["--columns", "tag,rho1,rho2,rho3,theta1,theta2,_,_"];
    let (code, rows, err) = verify(&dir, "samples.txt", &rec, &cols);
    assert_eq!(code, 1, "{err}");
    let other = checks_besides_acceleration(&rows);
    // The overrun line is the one input finding (line 3001 of the file); the first 5000
    // samples do not reach the path's end, which is a finding of its own; nothing else.
    assert_eq!(other.len(), 2, "{other:?}");
    assert!(
        other[0].starts_with("3001,input,") && other[0].contains("overrun"),
        "{other:?}"
    );
    assert!(
        other[1].contains(",pairing,") && other[1].contains("before its last point"),
        "{other:?}"
    );
    // Times from the tags: the gap of 10 samples is 11 ms, not 1 (no speed finding there).
    assert!(!rows.iter().any(|r| r.contains(",velocity,")), "{rows:?}");

    // A line with a value missing, a non-number, unnamed joints: fatal, with the line.
    let mut short = rec.clone();
    short[10] = "110 1 2 3".into();
    let (code, _, err) = verify(&dir, "short.txt", &short, &cols);
    assert_eq!(code, 2);
    assert!(
        err.contains("short.txt:11") && err.contains("4 values"),
        "{err}"
    );
    let mut word = rec.clone();
    word[5] = word[5].replacen(" ", " x", 2);
    let (code, _, err) = verify(&dir, "word.txt", &word, &cols);
    assert_eq!(code, 2);
    assert!(
        err.contains("word.txt:6") && err.contains("expected a number"),
        "{err}"
    );
    let (code, _, err) = verify(&dir, "cols.txt", &rec, &["--columns", "tag,rho1,rho2"]);
    assert_eq!(code, 2);
    assert!(err.contains("--columns") && err.contains("rho3"), "{err}");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn recording_options_go_together() {
    // --recording needs the period; --columns and --period need --recording.
    for args in [
        vec!["verify", "--joints", "x", "--path", PROGRAM, "--recording"],
        vec![
            "verify", "--joints", "x", "--path", PROGRAM, "--period", "1ms",
        ],
        vec![
            "verify",
            "--joints",
            "x",
            "--path",
            PROGRAM,
            "--columns",
            "tag",
        ],
    ] {
        let out = run(&args, None);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
    }
}

/// A recording must cover its path: an empty one, one of blank lines, or its first 1 % is a
/// finding, never clean; its tags are sample numbers that increase.
#[test]
fn a_recording_that_covers_nothing_or_part_of_the_path_is_a_finding() {
    let dir = scratch("coverage");
    let lines = stream(&dir);
    let first = lines.len() / 100;
    for (name, rec) in [
        ("empty.txt", Vec::new()),
        ("blank.txt", vec![String::new(), "   ".to_string()]),
        ("part.txt", lines[..first].to_vec()),
    ] {
        let (code, rows, err) = verify(&dir, name, &rec, &[]);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(
            rows.iter().any(|r| r.contains(",pairing,")),
            "{name}: {rows:?}"
        );
    }
    let whole = verify(&dir, "whole.txt", &lines, &[]);
    assert!(
        !whole.1.iter().any(|r| r.contains(",pairing,")),
        "{:?}",
        whole.1
    );
    let cols = ["--columns", "tag,rho1,rho2,rho3,theta1,theta2"];
    for (name, tags) in [("back.txt", [5.0, 7.0, 6.0]), ("half.txt", [5.0, 5.5, 6.0])] {
        let rec: Vec<String> = tags
            .iter()
            .zip(&lines)
            .map(|(t, l)| format!("{t} {l}"))
            .collect();
        let (code, _, err) = verify(&dir, name, &rec, &cols);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains("column tag"), "{name}: {err}");
    }
    let _ = fs::remove_dir_all(&dir);
}
