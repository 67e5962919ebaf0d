//! The APT CL reader on the shipped example (data/example.cl, checked row by row against the
//! generation rule in its header, and every row reachable along a path) and on malformed input,
//! where the error text is the contract.

use std::io::Cursor;

use nalgebra::Vector3;
use verne::machine::orientation::ToolOrientation;
use verne::machine::{FirstRowChoice, PathState};
use verne::spec::Machine;
use verne_cli::input::apt::{AptError, AptReader, AptRow, MotionKind};

const EXAMPLE: &str = include_str!("../../../data/example.cl");

/// Half a unit of the last printed decimal: coordinates (mm) and axis components.
const PRINT_MM: f64 = 0.5e-4;
const PRINT_AXIS: f64 = 0.5e-6;

fn read_all(text: &str) -> Result<(Vec<AptRow>, verne_cli::input::apt::AptSummary), AptError> {
    let mut reader = AptReader::new(Cursor::new(text.as_bytes()));
    let mut rows = Vec::new();
    while let Some(row) = reader.next_row()? {
        rows.push(row);
    }
    Ok((rows, reader.summary().clone()))
}

fn first_error(text: &str) -> AptError {
    match read_all(text) {
        Ok((rows, _)) => panic!("expected an error, read {} rows", rows.len()),
        Err(e) => e,
    }
}

/// The rows of data/example.cl by the rule in its header: (kind, tip, axis).
fn rule_rows() -> Vec<(MotionKind, Vector3<f64>, Option<Vector3<f64>>)> {
    let d = f64::to_radians;
    let z = Some(Vector3::new(0.0, 0.0, 1.0));
    let lean = Some(Vector3::new(d(20.0).sin(), 0.0, d(20.0).cos()));
    let mut out = vec![(MotionKind::From, Vector3::new(0.0, 0.0, 150.0), z)];
    let g = |x: f64, y: f64, zz: f64, a: Option<Vector3<f64>>| {
        (MotionKind::Goto, Vector3::new(x, y, zz), a)
    };
    out.push(g(80.0, 0.0, 120.0, lean));
    for k in 0..73 {
        let psi = d(5.0 * k as f64);
        let (s, c) = psi.sin_cos();
        let a = Vector3::new(d(20.0).sin() * c, d(20.0).sin() * s, d(20.0).cos());
        out.push(g(80.0 * c, 80.0 * s, 30.0, Some(a)));
    }
    out.push(g(80.0, 0.0, 120.0, lean));
    out.push(g(
        -60.0,
        -40.0,
        120.0,
        Some(Vector3::new(d(15.0).sin(), 0.0, d(15.0).cos())),
    ));
    for k in 0..41 {
        let gamma = d(15.0 - 0.75 * k as f64);
        let a = Vector3::new(gamma.sin(), 0.0, gamma.cos());
        out.push(g(-60.0 + 3.0 * k as f64, -40.0, 40.0, Some(a)));
    }
    out.push(g(60.0, -40.0, 120.0, z));
    out.push(g(-55.0, -20.0, 120.0, None));
    for r in 0..5 {
        for q in 0..12 {
            let q = if r % 2 == 0 { q } else { 11 - q };
            out.push(g(
                -55.0 + 10.0 * q as f64,
                -20.0 + 10.0 * r as f64,
                50.0,
                None,
            ));
        }
    }
    out.push(g(55.0, 20.0, 120.0, z));
    out
}

#[test]
fn example_matches_its_generation_rule() {
    let (rows, summary) = read_all(EXAMPLE).unwrap();
    let rule = rule_rows();
    assert_eq!(rows.len(), rule.len());
    for (i, (row, (kind, tip, axis))) in rows.iter().zip(&rule).enumerate() {
        assert_eq!(row.kind, *kind, "row {i}");
        assert!(
            (row.tip - tip).amax() <= PRINT_MM,
            "row {i}: {row:?} vs {tip:?}"
        );
        match (row.axis, axis) {
            (Some(a), Some(b)) => assert!((a - b).amax() <= PRINT_AXIS, "row {i}: {a:?} vs {b:?}"),
            (None, None) => {}
            other => panic!("row {i}: {other:?}"),
        }
    }
    assert_eq!(summary.goto_rows, 180);
    assert_eq!(summary.from_rows, 1);
    let n = |name: &str| summary.skipped.get(name).copied().unwrap_or(0);
    assert_eq!(
        (
            n("PARTNO"),
            n("PPRINT"),
            n("UNITS"),
            n("CUTTER"),
            n("LOADTL")
        ),
        (1, 2, 1, 2, 2)
    );
    assert_eq!(
        (n("SPINDL"), n("COOLNT"), n("RAPID"), n("FEDRAT")),
        (3, 2, 6, 3)
    );
    assert!(!summary.skipped.contains_key("GOTO") && !summary.skipped.contains_key("MULTAX"));
    assert_eq!(summary.fini_line, Some(EXAMPLE.lines().count()));
    assert!(summary.comment_lines >= 12);
    // A continued GOTO carries the line of its first line.
    let split = EXAMPLE.lines().position(|l| l.ends_with(",$")).unwrap() + 1;
    assert!(rows.iter().any(|r| r.line == split && r.axis.is_some()));
    let after = rows.iter().find(|r| r.line > split).unwrap();
    assert_eq!(after.line, split + 2);
}

/// Every row of the example has a working branch on the default machine, and the path through
/// it is continuous: theta2 turns once with the contour, never jumps, and the rows on the table
/// normal are flagged.
#[test]
fn every_example_row_is_reachable_along_a_path() {
    let m = Machine::default_verne();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let mut prev: Option<(f64, f64, bool)> = None;
    let mut flagged = 0;
    let mut switches = 0;
    let (mut t2_min, mut t2_max) = (f64::INFINITY, f64::NEG_INFINITY);
    let (rows, _) = read_all(EXAMPLE).unwrap();
    for row in &rows {
        // 3-value records: the tool axis is the table normal (APT default).
        let axis = row.axis.unwrap_or(Vector3::new(0.0, 0.0, 1.0));
        let r = state
            .next_row(&m, &row.tip, &ToolOrientation::Axis(axis), m.tool_length)
            .unwrap_or_else(|e| panic!("line {}: {e}", row.line));
        if r.near_rotary_singularity {
            flagged += 1;
        }
        if r.switched {
            switches += 1;
        }
        if let Some((t1, t2, was_singular)) = prev {
            // Leaving or entering the table normal the rotary axis may have to turn (at most a
            // quarter turn, since the two orientation solutions differ by half a turn);
            // elsewhere it moves continuously.
            let jump = (r.theta2 - t2).abs();
            if was_singular || r.near_rotary_singularity {
                assert!(
                    jump <= std::f64::consts::FRAC_PI_2 + 1e-9,
                    "line {}: {jump}",
                    row.line
                );
            } else {
                assert!(jump < 0.2, "line {}: theta2 {t2} -> {}", row.line, r.theta2);
            }
            assert!(
                (r.theta1 - t1).abs() < 0.8,
                "line {}: theta1 {t1} -> {}",
                row.line,
                r.theta1
            );
        }
        t2_min = t2_min.min(r.theta2);
        t2_max = t2_max.max(r.theta2);
        prev = Some((r.theta1, r.theta2, r.near_rotary_singularity));
    }
    // FROM, the singular pass row, the vertical rapids and the 61 rows of the raster block.
    let vertical = rows
        .iter()
        .filter(|r| r.axis.is_none_or(|a| a.x == 0.0 && a.y == 0.0))
        .count();
    assert_eq!(flagged, vertical);
    assert_eq!(vertical, 1 + 1 + 1 + 61 + 1);
    assert_eq!(switches, 0);
    assert!(
        t2_max - t2_min > 6.0,
        "theta2 did not turn with the contour"
    );
}

#[test]
fn bad_number_names_line_column_and_field() {
    let text = "MULTAX/ON\nGOTO/1.0,2.0,3.0,0,0,1\nGOTO/1.0, 2.O ,3.0,0,0,1\n";
    let e = first_error(text);
    assert_eq!((e.line, e.column), (3, 11));
    assert_eq!(
        e.to_string(),
        "line 3, column 11: GOTO: bad number `2.O` for y, expected a finite decimal number"
    );
    let e = first_error("GOTO/1,,3\n");
    assert_eq!(
        e.to_string(),
        "line 1, column 8: GOTO: empty value for y, expected a number"
    );
    let e = first_error("GOTO/1,2,nan\n");
    assert_eq!((e.line, e.column), (1, 10));
}

#[test]
fn missing_and_extra_fields() {
    let e = first_error("MULTAX\nGOTO/1,2,3\n");
    assert_eq!(
        e.to_string(),
        "line 2, column 11: GOTO: missing value i: expected 6 (x,y,z,i,j,k: MULTAX is on) values, found 3"
    );
    let e = first_error("GOTO/1,2,3,0,1\n");
    assert_eq!(
        e.to_string(),
        "line 1, column 15: GOTO: missing value k: expected 3 or 6 (x,y,z[,i,j,k]) values, found 5"
    );
    let e = first_error("GOTO/1,2\n");
    assert!(e.to_string().contains("missing value z"), "{e}");
    let e = first_error("GOTO\n");
    assert!(e.to_string().contains("missing value x"), "{e}");
    let e = first_error("GOTO/1,2,3,0,0,1,5\n");
    assert_eq!(
        e.to_string(),
        "line 1, column 18: GOTO: expected 3 or 6 (x,y,z[,i,j,k]) values, found 7"
    );
    let e = first_error("MULTAX/SOMETIMES\n");
    assert_eq!(
        e.to_string(),
        "line 1, column 8: MULTAX: expected MULTAX, MULTAX/ON or MULTAX/OFF, found `SOMETIMES`"
    );
}

#[test]
fn multax_off_allows_three_values_and_on_off_toggle() {
    let text =
        "GOTO/1,2,3\nMULTAX/ON\nGOTO/1,2,3,0,0,1\nMULTAX/OFF\nGOTO/4,5,6\nGOTO/4,5,6,0,1,0\n";
    let (rows, _) = read_all(text).unwrap();
    assert_eq!(rows.len(), 4);
    assert_eq!(rows[0].axis, None);
    assert_eq!(rows[1].axis, Some(Vector3::new(0.0, 0.0, 1.0)));
    assert_eq!(rows[2].axis, None);
    assert_eq!(rows[3].axis, Some(Vector3::new(0.0, 1.0, 0.0)));
}

#[test]
fn continuation_errors_point_into_the_continued_line() {
    // An error on the second line of a continued record: its own line and column.
    let e = first_error("MULTAX\nGOTO/1,2,3,$\n   0,x,1\n");
    assert_eq!((e.line, e.column), (3, 6));
    assert!(e.to_string().contains("bad number `x` for j"), "{e}");
    // The file ends on a `$`.
    let e = first_error("GOTO/1,2,3\nGOTO/1,2,$  $$ more to come\n");
    assert_eq!(
        e.to_string(),
        "line 2, column 10: the file ends inside a record continued with `$`: expected a continuation line"
    );
    // Continued over three lines, with comments between: the row keeps its first line.
    let text = "$$ head\nGOTO/1,$\n$$ a comment line inside the record\n2,$\n3\nFINI\nGOTO/bad\n";
    let (rows, summary) = read_all(text).unwrap();
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].line, 2);
    assert_eq!(rows[0].tip, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(summary.fini_line, Some(6));
}

#[test]
fn comments_text_records_crlf_and_unknown_records() {
    let text = "\u{feff}PARTNO/A $ B, C\r\nPPRINT  GOTO/this is text\r\n  goto/ 1 , 2 , 3 $$ trailing\r\n\
                TOOL PATH/PROFILE,TOOL,T1\r\nFEDRAT/MMPM,100\r\nfedrat/200\r\nFROM/0,0,100\r\n";
    let (rows, summary) = read_all(text).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].tip, Vector3::new(1.0, 2.0, 3.0));
    assert_eq!(rows[0].line, 3);
    assert_eq!(rows[1].kind, MotionKind::From);
    assert_eq!(summary.skipped.get("FEDRAT"), Some(&2));
    assert_eq!(summary.skipped.get("TOOL PATH"), Some(&1));
    assert_eq!(summary.skipped.get("PARTNO"), Some(&1));
    assert_eq!(summary.skipped.get("PPRINT"), Some(&1));
    assert_eq!(summary.fini_line, None);
}

#[test]
fn iterator_stops_after_an_error() {
    let reader = AptReader::new(Cursor::new(
        "GOTO/1,2,3\nGOTO/x,2,3\nGOTO/4,5,6\n".as_bytes(),
    ));
    let items: Vec<_> = reader.collect();
    assert_eq!(items.len(), 2);
    assert!(items[0].is_ok() && items[1].is_err());
}
