//! The G-code reader against programs whose moves are known by construction.

use verne_gcode::{Axis, Kind, Motion, Options, Row, Summary, Units, read_all};

fn read(program: &str) -> (Vec<Row>, Summary) {
    read_all(program.as_bytes(), &Options::default()).unwrap_or_else(|e| panic!("{e}\n{program}"))
}

fn refuse(program: &str) -> verne_gcode::GcodeError {
    match read_all(program.as_bytes(), &Options::default()) {
        Ok((rows, _)) => panic!(
            "read {} rows from a program it must refuse:\n{program}",
            rows.len()
        ),
        Err(e) => e,
    }
}

fn xyz(r: &Row) -> [f64; 3] {
    [r.get(Axis::X), r.get(Axis::Y), r.get(Axis::Z)]
}

#[test]
fn straight_moves_modes_units_and_feeds() {
    let (rows, s) = read(
        "%\n(header)\nN10 G21 G90 G17 G94\nN20 G0 X1 Y2 Z3 A4 C5\nN30 G1 X11 F600\nG91 Y10\nG90 G20 G1 X1 F10\nG93 G1 X2 F2\nG94 G1 C95 F900\nG95 S1000 F0.01 G1 Y0\nM30\n%\nG0 X99\n",
    );
    assert_eq!(rows.len(), 7);
    assert_eq!(
        (rows[0].line, rows[0].n, rows[0].motion),
        (4, Some(20), Motion::Rapid)
    );
    assert_eq!(rows[0].duration_s, None);
    assert_eq!(xyz(&rows[1]), [11.0, 2.0, 3.0]);
    assert_eq!(rows[1].duration_s, Some(1.0)); // 10 mm at 600 mm/min
    assert_eq!(xyz(&rows[2]), [11.0, 12.0, 3.0]); // G91
    assert_eq!(rows[3].get(Axis::X), 25.4); // G20
    assert_eq!(rows[3].feed_per_min, Some(254.0));
    assert_eq!(rows[4].duration_s, Some(30.0)); // G93 F2: half a minute
    assert_eq!(rows[4].feed_per_min, None);
    // A rotary-only move: degrees per minute (90 deg at 900 deg/min).
    assert!((rows[5].duration_s.unwrap() - 6.0).abs() < 1e-12);
    // G95: 0.01 in/rev at 1000 rev/min = 254 mm/min; 2 * 25.4 + 10 mm back... Y from 12 to 0.
    assert!((rows[6].duration_s.unwrap() - 60.0 * 12.0 / 254.0).abs() < 1e-12);
    assert_eq!(s.end_line, Some(11));
    assert_eq!(
        s.lines_after_end, 1,
        "the line after the closing % is not read"
    );
    assert_eq!(s.units, Units::Inch);
    assert_eq!(s.axes_used_letters(), "XYZAC");
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

#[test]
fn unknown_axes_stay_unknown_and_incremental_needs_a_start() {
    let (rows, _) = read("G21 G90\nG0 Z50\nG0 X1 Y1\nM2\n");
    assert!(rows[0].get(Axis::X).is_nan());
    assert_eq!(rows[0].known, Axis::Z.bit());
    assert_eq!(rows[1].known, Axis::X.bit() | Axis::Y.bit() | Axis::Z.bit());
    let e = refuse("G21 G91\nG0 X1\nM2\n");
    assert_eq!((e.line, e.column), (2, Some(4)));
    assert!(e.message.contains("before its position is known"), "{e}");
}

/// Every row of an arc lies on the circle; every chord within the tolerance; the end exact.
fn check_arc(rows: &[Row], centre: [f64; 2], r: f64, tol: f64) {
    let mut prev: Option<[f64; 2]> = None;
    for row in rows {
        let p = [row.get(Axis::X), row.get(Axis::Y)];
        let d = ((p[0] - centre[0]).powi(2) + (p[1] - centre[1]).powi(2)).sqrt();
        assert!((d - r).abs() < 1e-9, "off the circle: {p:?}");
        if let Some(q) = prev {
            let chord = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
            let sagitta = r - (r * r - chord * chord / 4.0).max(0.0).sqrt();
            assert!(sagitta <= tol + 1e-12, "chord of sagitta {sagitta}");
        }
        prev = Some(p);
    }
}

#[test]
fn arcs_turn_the_right_way_within_the_tolerance() {
    // From (10, 0) to (0, 10) about the origin: G3 is a quarter turn, G2 three quarters
    // (through (0, -10) and (-10, 0)).
    let (ccw, _) = read("G21 G90 G17 F100\nG0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0\nM2\n");
    let (cw, _) = read("G21 G90 G17 F100\nG0 X10 Y0 Z0\nG2 X0 Y10 I-10 J0\nM2\n");
    let tol = Options::default().chord_tol_mm;
    check_arc(&ccw[1..], [0.0, 0.0], 10.0, tol);
    check_arc(&cw[1..], [0.0, 0.0], 10.0, tol);
    assert!(
        ccw[1..]
            .iter()
            .all(|r| r.get(Axis::X) >= -1e-9 && r.get(Axis::Y) >= -1e-9)
    );
    assert!(cw[1..].iter().any(|r| r.get(Axis::Y) < -9.99));
    assert!(cw[1..].iter().any(|r| r.get(Axis::X) < -9.99));
    assert!(cw.len() > 2 * ccw.len(), "{} vs {}", cw.len(), ccw.len());
    let end = ccw.last().unwrap();
    assert_eq!(
        (end.get(Axis::X), end.get(Axis::Y), end.kind),
        (0.0, 10.0, Kind::Arc)
    );
    // The arc's time: its chords at 100 mm/min, close to the arc length.
    let t: f64 = ccw[1..].iter().map(|r| r.duration_s.unwrap()).sum();
    let exact = 60.0 * (10.0 * std::f64::consts::FRAC_PI_2) / 100.0;
    assert!((t - exact).abs() < 1e-3 * exact, "{t} vs {exact}");
}

#[test]
fn radius_format_full_circles_turns_and_helices() {
    // R > 0: the short way; R < 0: the long way.
    let (short, _) = read("G21 G90 F100\nG0 X10 Y0 Z0\nG3 X0 Y10 R10\nM2\n");
    let (long, _) = read("G21 G90 F100\nG0 X10 Y0 Z0\nG3 X0 Y10 R-10\nM2\n");
    check_arc(&short[1..], [0.0, 0.0], 10.0, 0.005);
    check_arc(&long[1..], [10.0, 10.0], 10.0, 0.005);
    // A full circle in two turns, rising 4 mm: Z linear in the angle.
    let (helix, _) = read("G21 G90 F100\nG0 X10 Y0 Z0\nG2 X10 Y0 Z4 I-10 J0 P2\nM2\n");
    let rows = &helix[1..];
    check_arc(rows, [0.0, 0.0], 10.0, 0.005);
    let n = rows.len() as f64;
    for (k, r) in rows.iter().enumerate() {
        assert!((r.get(Axis::Z) - 4.0 * (k + 1) as f64 / n).abs() < 1e-12);
    }
    assert_eq!(rows.last().unwrap().get(Axis::Z), 4.0);
    // Planes: G18 (Z X) and G19 (Y Z) with their centre words.
    let (g18, _) = read("G21 G90 F100\nG0 X0 Y0 Z10\nG18 G2 X10 Z0 I0 K-10\nM2\n");
    for r in &g18[1..] {
        let d = (r.get(Axis::X).powi(2) + r.get(Axis::Z).powi(2)).sqrt();
        assert!((d - 10.0).abs() < 1e-9 && r.get(Axis::Y) == 0.0);
    }
    let e = refuse("G21 G90 F100\nG0 X0 Y0 Z0\nG3 X10 Y0 R4\nM2\n");
    assert!(e.message.contains("smaller than half"), "{e}");
    let e = refuse("G21 G90 F100\nG0 X0 Y0 Z0\nG3 X10 Y0 I3 J0\nM2\n");
    assert!(e.message.contains("not an arc"), "{e}");
}

#[test]
fn drilling_cycles_expand_as_linuxcnc_makes_them() {
    // G98 from Z10: rapid to X Y, rapid to R2, feed to -5, rapid back to 10.
    let (rows, _) = read("G21 G90 F100\nG0 X0 Y0 Z10\nG98 G81 X5 Y6 Z-5 R2\nX8\nG80\nM2\n");
    let moves: Vec<([f64; 3], Motion)> = rows[1..].iter().map(|r| (xyz(r), r.motion)).collect();
    use Motion::{Feed, Rapid};
    assert_eq!(
        moves,
        vec![
            ([5.0, 6.0, 10.0], Rapid),
            ([5.0, 6.0, 2.0], Rapid),
            ([5.0, 6.0, -5.0], Feed),
            ([5.0, 6.0, 10.0], Rapid),
            ([8.0, 6.0, 10.0], Rapid),
            ([8.0, 6.0, 2.0], Rapid),
            ([8.0, 6.0, -5.0], Feed),
            ([8.0, 6.0, 10.0], Rapid),
        ]
    );
    // G99 G83: pecks of 3 from R2 to -5 (2 -> -1 -> -4 -> -5), back to R between pecks.
    let (rows, _) = read("G21 G90 F100\nG0 X0 Y0 Z10\nG99 G83 X1 Y1 Z-5 R2 Q3\nG80\nM2\n");
    let feeds: Vec<f64> = rows
        .iter()
        .filter(|r| r.motion == Motion::Feed)
        .map(|r| r.get(Axis::Z))
        .collect();
    assert_eq!(feeds, vec![-1.0, -4.0, -5.0]);
    assert_eq!(rows.last().unwrap().get(Axis::Z), 2.0);
    assert!(
        rows.iter()
            .all(|r| r.kind == Kind::Line || r.kind == Kind::Cycle)
    );
}

#[test]
fn what_cannot_be_read_exactly_is_refused_with_its_place() {
    let cases: &[(&str, u64, &str)] = &[
        ("G21 G90\nG41 D1 G1 X1 F100\n", 2, "cutter radius"),
        ("G21 G90\nG43 H1\n", 2, "tool length offset"),
        ("G21 G90\nG55\n", 2, "work offset"),
        ("G21 G90\nG28 X0\n", 2, "home position"),
        ("G21 G90\nG92 X0\n", 2, "coordinate offset"),
        ("G21\nM98 P100\n", 2, "subprogram"),
        ("G21\nX1\n", 2, "no motion mode"),
        ("G21 G93\nG1 X1\n", 2, "inverse time"),
        ("G21\nG1 X1\n", 2, "before any F"),
        ("G21\nG0 G1 X1\n", 2, "same modal group"),
        ("G21\nG1 X1 X2 F1\n", 2, "given twice"),
        (
            "G21\nG0 X0 Y0\nG1 X1 I1 F1\n",
            3,
            "I J K on a straight move",
        ),
        ("G21\nG5.1 X1\n", 2, "spline"),
        ("G20\n", 1, "stated as mm"),
    ];
    for (program, line, what) in cases {
        let opts = Options {
            units: Some(Units::Mm),
            ..Options::default()
        };
        let e = read_all(program.as_bytes(), &opts).expect_err(program);
        assert_eq!(e.line, *line, "{program}: {e}");
        assert!(e.column.is_some(), "{program}: {e}");
        assert!(e.message.contains(what), "{program}: {e}");
    }
}

#[test]
fn tool_vectors_when_asked_for() {
    let opts = Options {
        ijk_tool_vector: true,
        ..Options::default()
    };
    let p = "G21 G90 F100\nG0 X0 Y0 Z10 I0 J0 K2\nG1 X1 I0 J1 K1\nG1 X2\nG2 X4 Y0 I1 J0\nM2\n";
    let (rows, _) = read_all(p.as_bytes(), &opts).unwrap();
    assert_eq!(rows[0].tool_vector, Some([0.0, 0.0, 1.0]));
    let close = |v: Option<[f64; 3]>| {
        let v = v.unwrap();
        let s = 0.5f64.sqrt();
        v[0] == 0.0 && (v[1] - s).abs() < 1e-15 && (v[2] - s).abs() < 1e-15
    };
    assert!(close(rows[1].tool_vector));
    assert!(close(rows[2].tool_vector), "kept until changed");
    assert!(close(rows.last().unwrap().tool_vector), "arcs keep it");
    let e = read_all(b"G21\nG0 X0 I0 J0 K0\n", &opts).unwrap_err();
    assert!(e.message.contains("zero"), "{e}");
    let e = read_all(b"G21\nG0 X0 I0 K1\n", &opts).unwrap_err();
    assert!(e.message.contains("together"), "{e}");
}

#[test]
fn warnings_block_delete_and_line_ends() {
    let (rows, s) = read("G0 X1 Y1 Z1\r\n/G0 X5\r\nG0 X2 ; comment\r\n");
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[1].line, 3);
    assert_eq!(s.block_deleted, 1);
    let w: Vec<String> = s.warnings.iter().map(|w| w.to_string()).collect();
    assert!(w.iter().any(|w| w.contains("block delete")), "{w:?}");
    assert!(w.iter().any(|w| w.contains("no end")), "{w:?}");
    assert!(w.iter().any(|w| w.contains("millimetres assumed")), "{w:?}");
    let e = refuse("G0 X1\rG0 X2\r");
    assert!(e.message.contains("carriage return"), "{e}");
}

#[test]
fn sniffing_tells_gcode_from_csv_and_cl() {
    use verne_gcode::{has_gcode_extension, sniff_content};
    for yes in [
        "%\nG0 X1",
        "(part)\nN10 G21",
        "O1000\nG0",
        "G0X1",
        "/N5 M3 S1000",
        "; c\nx1.5 y2",
    ] {
        assert!(sniff_content(yes.as_bytes()), "{yes}");
    }
    for no in [
        "x,y,z,i,j,k\n1,2,3,0,0,1",
        "xp,yp,zp",
        "GOTO/1,2,3",
        "PARTNO TEST",
        "$$ cl",
        "FROM/0,0,0",
        "",
    ] {
        assert!(!sniff_content(no.as_bytes()), "{no}");
    }
    assert!(has_gcode_extension("part.NGC") && has_gcode_extension("a.b.tap"));
    assert!(!has_gcode_extension("part.cl") && !has_gcode_extension("ngc"));
}

/// Two M codes of one of LinuxCNC's modal groups in a block are refused at the second, with the
/// line and column (`Interp::read_m`); codes of different groups are read. The groups are
/// LinuxCNC's own table (`Interp::_ems`), and `rs274.rs` checks the same blocks against its
/// interpreter.
#[test]
fn two_m_codes_of_one_modal_group_are_refused() {
    for (block, second, group) in [
        ("M3 M5", "M5", "spindle"),
        ("M4 M19", "M19", "spindle"),
        ("M70 M3", "M3", "spindle"),
        ("M3 M3", "M3", "spindle"),
        ("M2 M30", "M30", "stopping"),
        ("M0 M1", "M1", "stopping"),
        ("M0 M60", "M60", "stopping"),
        ("M7 M9", "M9", "coolant"),
        ("M7 M8", "M8", "coolant"),
        ("M8 M7 M9", "M7", "coolant"),
        ("M48 M49", "M49", "override"),
        ("M6 M61", "M61", "tool change"),
        ("M100 M101", "M101", "user-defined"),
    ] {
        let program = format!("G21 G90\nG0 X0 Y0 Z10\nF100 {block} G1 X1\nM2\n");
        let e = refuse(&program);
        let column = program.lines().nth(2).unwrap().rfind(second).unwrap() as u64 + 1;
        assert_eq!((e.line, e.column), (3, Some(column)), "{block}: {e}");
        assert!(
            e.message.contains("same modal group") && e.message.contains(group),
            "{block}: {e}"
        );
    }
    for block in ["M3 M8", "M5 M9", "M3 M6 M8 M48", "M1 M5"] {
        let (rows, s) = read(&format!("G21 G90\nT1 {block} G0 X1 Y2 Z3\nM2\n"));
        assert_eq!(rows.len(), 1, "{block}");
        assert!(s.end_line.is_some(), "{block}");
    }
}
