//! The shipped CL example through the CL reader (verne-cl): data/example.cl checked row by row
//! against the generation rule in its header, and every row reachable along a path. The
//! reader's own tests (dialects, malformed input, the error texts) live in crates/verne-cl.

use nalgebra::Vector3;
use verne::machine::orientation::ToolOrientation;
use verne::machine::{FirstRowChoice, PathState};
use verne::spec::Machine;
use verne_cl::{Kind, Options, Row, Summary};

const EXAMPLE: &str = include_str!("../../../../data/example.cl");

/// Half a unit of the last printed decimal (4 for coordinates, mm).
const PRINT_MM: f64 = 0.5e-4;
/// The axis is printed with 6 decimals and normalized by the reader: half a unit of the last
/// decimal per component, plus what the normalization spreads of it (up to sqrt(3) times that).
const PRINT_AXIS: f64 = 0.5e-6 * (1.0 + 1.8);

fn read_example() -> (Vec<Row>, Summary) {
    verne_cl::read_all("example.cl", EXAMPLE.as_bytes(), &Options::default())
        .unwrap_or_else(|e| panic!("data/example.cl: {e}"))
}

fn tip(row: &Row) -> Vector3<f64> {
    Vector3::from(row.tip)
}

fn axis(row: &Row) -> Vector3<f64> {
    Vector3::from(row.axis)
}

/// The rows of data/example.cl by the rule in its header: (kind, tip, axis).
fn rule_rows() -> Vec<(Kind, Vector3<f64>, Option<Vector3<f64>>)> {
    let d = f64::to_radians;
    let z = Some(Vector3::new(0.0, 0.0, 1.0));
    let lean = Some(Vector3::new(d(20.0).sin(), 0.0, d(20.0).cos()));
    let mut out = vec![(Kind::From, Vector3::new(0.0, 0.0, 150.0), z)];
    let g =
        |x: f64, y: f64, zz: f64, a: Option<Vector3<f64>>| (Kind::Goto, Vector3::new(x, y, zz), a);
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
    let (rows, summary) = read_example();
    let rule = rule_rows();
    assert_eq!(rows.len(), rule.len());
    let z = Vector3::new(0.0, 0.0, 1.0);
    for (i, (row, (kind, rule_tip, rule_axis))) in rows.iter().zip(&rule).enumerate() {
        assert_eq!(row.kind, *kind, "row {i}");
        assert!(
            (tip(row) - rule_tip).amax() <= PRINT_MM,
            "row {i}: {row:?} vs {rule_tip:?}"
        );
        // 3-value records: the tool axis is the table normal (APT default).
        let want = rule_axis.unwrap_or(z);
        assert!(
            (axis(row) - want).amax() <= PRINT_AXIS,
            "row {i}: {row:?} vs {want:?}"
        );
    }
    let kinds = |k: Kind| rows.iter().filter(|r| r.kind == k).count();
    assert_eq!((kinds(Kind::From), kinds(Kind::Goto)), (1, 180));
    assert_eq!(summary.rows, rows.len() as u64);
    assert_eq!(summary.units, verne_cl::Units::Mm);
    let n = |name: &str| summary.skipped.get(name).copied().unwrap_or(0);
    assert_eq!(
        (
            n("PARTNO"),
            n("PPRINT"),
            n("CUTTER"),
            n("SPINDL"),
            n("COOLNT")
        ),
        (1, 2, 2, 3, 2),
        "{:?}",
        summary.skipped
    );
    // MULTAX is informational (docs/cl-dialects.md §5): counted, never a motion.
    assert_eq!(n("MULTAX"), 3);
    assert!(!summary.skipped.contains_key("GOTO") && !summary.skipped.contains_key("FROM"));
    assert_eq!(summary.fini_line, Some(EXAMPLE.lines().count() as u64));
    // A continued GOTO carries the line of its first line.
    let split = EXAMPLE.lines().position(|l| l.ends_with(",$")).unwrap() as u64 + 1;
    assert!(rows.iter().any(|r| r.line == split));
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
    let (rows, _) = read_example();
    for row in &rows {
        let r = state
            .next_row(
                &m,
                &tip(row),
                &ToolOrientation::Axis(axis(row)),
                m.tool_length,
            )
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
        .filter(|r| r.axis[0] == 0.0 && r.axis[1] == 0.0)
        .count();
    assert_eq!(flagged, vertical);
    assert_eq!(vertical, 1 + 1 + 1 + 61 + 1);
    assert_eq!(switches, 0);
    assert!(
        t2_max - t2_min > 6.0,
        "theta2 did not turn with the contour"
    );
}
