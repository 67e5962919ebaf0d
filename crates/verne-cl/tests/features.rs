//! One feature at a time: frames, units, feeds, cycles, arcs, tools, syntax, errors.

use std::io::Cursor;

use verne_cl::{
    ArcRule, ClError, ClErrorKind, Dialect, Kind, Motion, Options, Reader, Row, Summary, Units,
    UnitsSource, WarningKind, read_all,
};

fn read(text: &str) -> (Vec<Row>, Summary) {
    read_opts(text, &Options::default())
}

fn read_opts(text: &str, opts: &Options) -> (Vec<Row>, Summary) {
    read_all("t.cl", text.as_bytes(), opts).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn err(text: &str) -> ClError {
    match read_all("t.cl", text.as_bytes(), &Options::default()) {
        Ok((rows, _)) => panic!("no error, {} rows:\n{text}", rows.len()),
        Err(e) => e,
    }
}

fn close3(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
}

#[track_caller]
fn assert_row(r: &Row, tip: [f64; 3], axis: [f64; 3]) {
    assert!(close3(r.tip, tip, 1e-6), "tip {:?} vs {tip:?}", r.tip);
    assert!(close3(r.axis, axis, 1e-6), "axis {:?} vs {axis:?}", r.axis);
}

// ---------------------------------------------------------------- frames (SPEC §6)

#[test]
fn msys_worked_example() {
    // SPEC §6.1, the three paths of nx_msys.cls
    let text = "\
TOOL PATH/A,TOOL,T
MSYS/100,50,20,1,0,0,0,1,0
RAPID
GOTO/10,0,5,0,0,1
END-OF-PATH
TOOL PATH/B,TOOL,T
MSYS/100,50,20,0,1,0,-1,0,0
GOTO/10,0,5,0,0,1
GOTO/10,5,-2,1,0,0
END-OF-PATH
TOOL PATH/C,TOOL,T
MSYS/0,0,180,0.5,0,0.8660254,0.8660254,0,-0.5
GOTO/0,0,10,0,0,1
GOTO/20,10,0
END-OF-PATH
";
    let (rows, s) = read(text);
    assert_eq!(rows.len(), 5);
    assert_row(&rows[0], [10.0, 0.0, 5.0], [0.0, 0.0, 1.0]);
    assert_row(&rows[1], [0.0, 10.0, 5.0], [0.0, 0.0, 1.0]);
    assert_row(&rows[2], [-5.0, 10.0, -2.0], [0.0, 1.0, 0.0]);
    // the third MSYS is rounded to 7 decimals as NX writes it: 1e-6 agreement
    assert!(close3(rows[3].tip, [-100.0, -40.0, 160.0], 1e-5));
    assert!(close3(rows[3].axis, [0.0, 1.0, 0.0], 1e-6));
    assert!(close3(rows[4].tip, [-81.339746, -50.0, 172.320508], 1e-5));
    assert_eq!(s.dialect, Dialect::NxClsf);
}

#[test]
fn msys_refusals_and_inch_origin() {
    assert_eq!(
        err("MSYS/1,0,0,1,0,0,0,1,0,0,0,1\nGOTO/0,0,0\n").kind,
        ClErrorKind::Msys12
    );
    assert!(matches!(
        err("MSYS/0,0,0,1,0,0\nGOTO/0,0,0\n").kind,
        ClErrorKind::FieldCount { .. }
    ));
    assert_eq!(
        err("MSYS/0,0,0,1,0,0,0.5,0.5,0\nGOTO/0,0,0\n").kind,
        ClErrorKind::MsysNotOrthonormal
    );
    // MSYS before the first motion: the output frame, points unchanged
    let (rows, _) = read("UNITS/INCH\nMSYS/1,2,3,1,0,0,0,1,0\nGOTO/1,1,1\n");
    assert_row(&rows[0], [25.4, 25.4, 25.4], [0.0, 0.0, 1.0]);
    // a second MSYS with another origin (inches): translated by the origin difference
    let (rows, _) = read(
        "UNITS/INCH\nMSYS/1,2,3,1,0,0,0,1,0\nGOTO/1,1,1\nMSYS/2,2,3,1,0,0,0,1,0\nGOTO/1,1,1\n",
    );
    assert_row(&rows[1], [50.8, 25.4, 25.4], [0.0, 0.0, 1.0]);
}

#[test]
fn csys_and_comment_frames() {
    let world = "UNIT/MM\nTRNTYP/WORLD,0,0,0\nCSYS/-1.,0,0,150.,0,-1.,0,80.,0,0,1.,0\nRAPID/\nGOTO/130.,65.,25.\nFINI\n";
    let (rows, s) = read(world);
    assert_row(&rows[0], [130.0, 65.0, 25.0], [0.0, 0.0, 1.0]);
    assert_eq!(s.dialect, Dialect::SolidWorks);
    let local = "UNIT/MM\nCSYS/-1.,0,0,150.,0,-1.,0,80.,0,0,1.,0\nGOTO/130.,65.,25.\n";
    let e = err(local);
    assert_eq!((e.line, e.kind), (2, ClErrorKind::CsysLocal));
    // identity without TRNTYP is fine; TRNTYP other than WORLD ends the WORLD mode
    read("CSYS/1,0,0,0,0,1,0,0,0,0,1,0\nGOTO/1,2,3\n");
    let e = err(
        "TRNTYP/WORLD\nCSYS/0,-1,0,0,1,0,0,0,0,0,1,0\nTRNTYP/LOCAL\nCSYS/0,-1,0,0,1,0,0,0,0,0,1,0\nGOTO/1,2,3\n",
    );
    assert_eq!(e.line, 4);
    // Creo: the same $$-> CSYS again is fine, a different one is refused
    let csys = |t: &str| format!("$$-> CSYS / 1,0,0,{t}, $\n 0,1,0,0, $\n 0,0,1,0\n");
    let same = format!(
        "UNITS/MM\n{}GOTO/1,2,3\n{}GOTO/4,5,6\n",
        csys("0"),
        csys("0")
    );
    assert_eq!(read(&same).0.len(), 2);
    let diff = format!(
        "UNITS/MM\n{}GOTO/1,2,3\n{}GOTO/4,5,6\n",
        csys("0"),
        csys("5")
    );
    let e = err(&diff);
    assert_eq!(e.line, 6);
    assert!(matches!(
        e.kind,
        ClErrorKind::FrameChanged { first_line: 2, .. }
    ));
    assert!(matches!(
        err("$$-> CSYS / 1,0,0\nGOTO/1,2,3\n").kind,
        ClErrorKind::FrameMatrix { .. }
    ));
    // CATIA: a second, different $$*CATIA0 block is refused; an incomplete one is a warning
    let block = |a: &str| format!("$$*CATIA0\n$$ Program\n$$ {a} 0 0 0\n$$ 0 1 0 0\n$$ 0 0 1 0\n");
    let two = format!(
        "{}UNITS/MM\nGOTO/1,2,3\n{}GOTO/1,2,3\n",
        block("1"),
        block("-1")
    );
    assert_eq!(err(&two).line, 8);
    let (_, s) = read("$$*CATIA0\n$$ Program\n$$ 1 0 0 0\nUNITS/MM\nGOTO/1,2,3\n");
    assert_eq!(s.warnings.len(), 1);
    assert_eq!(s.warnings[0].kind, WarningKind::CatiaBlockIncomplete);
    assert_eq!(s.dialect, Dialect::Catia);
}

// ---------------------------------------------------------------- units (SPEC §4)

#[test]
fn inch_conversion() {
    let (rows, s) = read(
        "UNITS/INCHES\nFROM/0,0,4\nFEDRAT/10\nGOTO/1,0.5,-0.25\nGODLTA/0.5\nGODLTA/1,0,0\nFEDRAT/MMPM,100\nGOTO/2,0,0\n",
    );
    assert_eq!(s.units, Units::Inch);
    assert_eq!(s.units_source, UnitsSource::Record { line: 1 });
    assert_row(&rows[0], [0.0, 0.0, 101.6], [0.0, 0.0, 1.0]);
    assert_row(&rows[1], [25.4, 12.7, -6.35], [0.0, 0.0, 1.0]);
    assert!((rows[1].feed_mm_min.unwrap() - 254.0).abs() < 1e-9);
    assert_row(&rows[2], [25.4, 12.7, 6.35], [0.0, 0.0, 1.0]);
    assert_row(&rows[3], [50.8, 12.7, 6.35], [0.0, 0.0, 1.0]);
    assert_eq!(rows[4].feed_mm_min, Some(100.0));
    // UNITS/INCH and lower case
    let (rows, _) = read("units / inch\ngoto / 1.0d0 , 2.5D-01 , 1.0D+00\n");
    assert_row(&rows[0], [25.4, 6.35, 25.4], [0.0, 0.0, 1.0]);
}

#[test]
fn units_decisions() {
    // no UNITS: feed words decide; listing header decides; nothing: mm with a warning
    let (_, s) = read("GOTO/1,2,3\nFEDRAT/IPM,10\nGOTO/1,2,4\n");
    assert_eq!((s.units, s.warnings[0].line), (Units::Inch, 2));
    let (_, s) = read("GOTO/1,2,3\nFEDRAT/MMPR,0.1\nSPINDL/100\nGOTO/1,2,4\n");
    assert_eq!((s.units, s.warnings.len()), (Units::Mm, 0));
    let (rows, s) = read("Information Units : in\nGOTO/1,2,3\nFEDRAT/MMPM,10\n");
    assert_eq!(s.units, Units::Inch);
    assert_eq!(s.units_source, UnitsSource::ListingHeader { line: 1 });
    assert_row(&rows[0], [25.4, 50.8, 76.2], [0.0, 0.0, 1.0]);
    let (_, s) = read("\n\nGOTO/1,2,3\n");
    assert_eq!(s.units, Units::Mm);
    assert_eq!(s.warnings[0].line, 3);
    assert_eq!(s.warnings[0].kind, WarningKind::UnitsAssumedMm);
    // UNITS after motion: same value fine, other value an error
    read("UNITS/MM\nGOTO/1,2,3\nUNITS/MM\nGOTO/1,2,3\n");
    let e = err("GOTO/1,2,3\nFEDRAT/MMPM,5\nUNITS/INCHES\n");
    assert_eq!(e.line, 3);
    assert!(matches!(e.kind, ClErrorKind::UnitsChanged { .. }));
    // a conflicting listing header
    let e = err("UNITS/MM\nInformation Units : in\nGOTO/1,2,3\n");
    assert_eq!(e.line, 2);
    assert!(matches!(e.kind, ClErrorKind::UnitsConflict { .. }));
    // UNITS without value, unknown value
    assert!(matches!(
        err("UNITS\nGOTO/1,2,3\n").kind,
        ClErrorKind::UnknownUnits { .. }
    ));
    assert!(matches!(
        err("UNITS/CM\nGOTO/1,2,3\n").kind,
        ClErrorKind::UnknownUnits { .. }
    ));
}

#[test]
fn stated_units() {
    let inch = Options {
        units: Some(Units::Inch),
        ..Options::default()
    };
    let (rows, s) = read_opts("GOTO/1,2,3\nFEDRAT/10\nGOTO/1,2,4\n", &inch);
    assert_eq!(s.units_source, UnitsSource::Stated);
    assert!(s.warnings.is_empty());
    assert_row(&rows[0], [25.4, 50.8, 76.2], [0.0, 0.0, 1.0]);
    assert_eq!(rows[1].feed_mm_min, Some(254.0));
    // the file saying the same is fine; saying otherwise is an error at its line
    read_opts("UNITS/INCH\nGOTO/1,2,3\n", &inch);
    let e = read_all("t.cl", b"PARTNO X\nUNITS/MM\nGOTO/1,2,3\n", &inch).unwrap_err();
    assert_eq!(e.line, 2);
    assert_eq!(
        e.kind,
        ClErrorKind::UnitsConflict {
            stated: Units::Inch,
            found: Units::Mm
        }
    );
    // stated units also remove the undecidable case
    let mixed = "GOTO/0,0,1\nFEDRAT/IPM,20\nGOTO/1,0,0\nFEDRAT/MMPM,500\nGOTO/2,0,0\n";
    assert_eq!(err(mixed).line, 4);
    let mm = Options {
        units: Some(Units::Mm),
        ..Options::default()
    };
    let (rows, _) = read_opts(mixed, &mm);
    assert_eq!(rows[1].feed_mm_min, Some(508.0));
    assert_eq!(rows[2].feed_mm_min, Some(500.0));
    // a non-seekable source (a byte slice) with stated units: one pass, the same rows
    let text = "TOOL PATH/X,TOOL,T\nRAPID\nGOTO/1,2,3\nFEDRAT/MMPM,100\nCIRCLE/0,2,3,0,0,1,1,0.06,0.5,2,0\nGOTO/-1,2,3\nEND-OF-PATH\n";
    let one: Vec<Row> = Reader::with_units(text.as_bytes(), Units::Mm, Options::default())
        .unwrap()
        .map(Result::unwrap)
        .collect();
    let two: Vec<Row> = Reader::new(Cursor::new(text.as_bytes()), Options::default())
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(one, two);
}

// ---------------------------------------------------------------- feeds (SPEC §5.6, §5.7)

#[test]
fn feed_forms_and_per_rev() {
    let (rows, _) = read(
        "UNITS/MM\nSPINDL/RPM,2000,CLW\nGOTO/0,0,0\nFEDRAT/MMPR,0.1\nGOTO/1,0,0\nFEDRAT/0.005,IPR\nGOTO/2,0,0\nSPINDL/3000,RPM,CLW\nGOTO/3,0,0\nFEDRAT/PERREV,0.1\nGOTO/4,0,0\nFEDRAT/PERMIN,40\nGOTO/5,0,0\n",
    );
    let f: Vec<Option<f64>> = rows.iter().map(|r| r.feed_mm_min).collect();
    assert_eq!(f[0], None);
    assert!((f[1].unwrap() - 200.0).abs() < 1e-9);
    assert!((f[2].unwrap() - 254.0).abs() < 1e-9);
    assert!(
        (f[3].unwrap() - 381.0).abs() < 1e-9,
        "the rpm at the time of the move"
    );
    assert!((f[4].unwrap() - 300.0).abs() < 1e-9);
    assert_eq!(f[5], Some(40.0));
    // per revolution without spindle speed, after SPINDL/OFF, with surface speed: errors at the move
    let e = err("UNITS/MM\nGOTO/0,0,0\nFEDRAT/MMPR,0.1\nGOTO/1,0,0\n");
    assert_eq!(e.line, 4);
    assert_eq!(e.kind, ClErrorKind::PerRevWithoutSpindle { feed_line: 3 });
    let e = err("UNITS/MM\nSPINDL/1000\nGOTO/0,0,0\nFEDRAT/MMPR,0.1\nSPINDL/OFF\nGOTO/1,0,0\n");
    assert_eq!(e.line, 6);
    let e = err("UNITS/MM\nSPINDL/1000\nSPINDL/SFM,300\nGOTO/0,0,0\nFEDRAT/MMPR,0.1\nGOTO/1,0,0\n");
    assert_eq!(e.line, 6);
    // SPINDL/ON keeps the speed
    let (rows, _) = read(
        "UNITS/MM\nSPINDL/1000\nSPINDL/OFF\nSPINDL/1200\nSPINDL/ON\nGOTO/0,0,0\nFEDRAT/MMPR,0.5\nGOTO/1,0,0\n",
    );
    assert_eq!(rows[1].feed_mm_min, Some(600.0));
    // bad FEDRAT forms
    for (t, line) in [
        ("FEDRAT/MMPM\n", 2),
        ("FEDRAT/1,2\n", 2),
        ("FEDRAT/0,MMPM\n", 2),
        ("FEDRAT/-5\n", 2),
        ("FEDRAT/5,FPM\n", 2),
        ("FEDRAT/MMPM,IPM,5\n", 2),
    ] {
        assert_eq!(err(&format!("UNITS/MM\n{t}GOTO/1,2,3\n")).line, line, "{t}");
    }
}

#[test]
fn inverse_time_feeds() {
    // a 20 mm move in 1/30 min: 600 mm/min; an arc: its length
    let (rows, _) = read(
        "UNITS/MM\nGOTO/0,0,0\nFEDRAT/INVERS,30\nGOTO/20,0,0\nCIRCLE/10,0,0,0,0,1,10\nGOTO/0,0,0\n",
    );
    assert!((rows[1].feed_mm_min.unwrap() - 600.0).abs() < 1e-9);
    let half = std::f64::consts::PI * 10.0 * 30.0;
    let arc: Vec<&Row> = rows.iter().filter(|r| r.kind == Kind::Circle).collect();
    assert!(arc.len() > 10);
    assert!(
        arc.iter()
            .all(|r| (r.feed_mm_min.unwrap() - half).abs() < 1e-9)
    );
}

// ---------------------------------------------------------------- RAPID, GOTO, tools (SPEC §5)

#[test]
fn rapid_is_one_shot_and_axes() {
    let (rows, _) = read(
        "UNITS/MM\nFROM/0,0,100\nRAPID\nFROM/0,0,90\nGOTO/0,0,50\nGOTO/0,0,40\nRAPID\nGOTO/1,0,40,0,3,4\nGOTO/2,0,40\nFROM/0,0,0,-2,0,0\nGOTO/0,0,1\n",
    );
    let m: Vec<Motion> = rows.iter().map(|r| r.motion).collect();
    assert_eq!(
        m,
        [
            Motion::Rapid,
            Motion::Rapid,
            Motion::Rapid,
            Motion::Feed,
            Motion::Rapid,
            Motion::Feed,
            Motion::Rapid,
            Motion::Feed
        ]
    );
    assert_eq!(rows[0].kind, Kind::From);
    assert_row(&rows[4], [1.0, 0.0, 40.0], [0.0, 0.6, 0.8]);
    assert_row(&rows[5], [2.0, 0.0, 40.0], [0.0, 0.6, 0.8]);
    assert_row(&rows[7], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]);
    // zero axis: line and column of the axis
    let e = err("UNITS/MM\nGOTO/1,2,3\nGOTO/1,2,3, 0,0,0\n");
    assert_eq!((e.line, e.column), (3, Some(13)));
    // counts and fields
    let e = err("UNITS/MM\nGOTO/1,2,3,4\n");
    assert_eq!(
        e.kind,
        ClErrorKind::FieldCount {
            record: "GOTO".into(),
            expected: "3 or 6",
            found: 4
        }
    );
    let e = err("UNITS/MM\nGOTO/1,2,3,\n");
    assert!(matches!(e.kind, ClErrorKind::FieldCount { found: 4, .. }));
    let e = err("UNITS/MM\nGOTO/1,2,-115 .0000\n");
    assert_eq!((e.line, e.column), (2, Some(10)));
    assert!(matches!(e.kind, ClErrorKind::BadNumber { field: 3, .. }));
    let e = err("UNITS/MM\nGOTO/1,2,1e999\n");
    assert!(matches!(e.kind, ClErrorKind::NumberOutOfRange { .. }));
    let e = err("UNITS/INCH\nGOTO/1,2,1e307\n");
    assert!(matches!(e.kind, ClErrorKind::NumberOutOfRange { .. }));
    assert_eq!(
        err("UNITS/MM\nGODLTA/1\n").kind,
        ClErrorKind::GodltaBeforePosition
    );
}

#[test]
fn tools_and_tool_changes() {
    let text = "\
TOOL PATH/OP1,TOOL,EM10
TLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000
LOAD/TOOL,3,ADJUST,3
SELECT/TOOL,5
GOTO/0,0,10
END-OF-PATH
TOOL PATH/OP2,TOOL,EM10
TLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000
LOAD/TOOL,3,ADJUST,3
GOTO/0,0,20
END-OF-PATH
TOOL PATH/OP3,TOOL,DR8
TLDATA/DRILL,MILL,8.0000,0.0000,90.0000,118.0000,35.0000
LOAD/TOOL,8
GOTO/0,0,30
LOADTL/9
GOTO/0,0,40
";
    let mm = Options {
        units: Some(Units::Mm),
        ..Options::default()
    };
    let (rows, s) = read_opts(text, &mm);
    let tools: Vec<Option<u32>> = rows.iter().map(|r| r.tool).collect();
    assert_eq!(tools, [Some(3), Some(3), Some(8), Some(9)]);
    assert_eq!(s.tools.len(), 3, "{:#?}", s.tools);
    assert_eq!(s.tools[0].tool, Some(3));
    assert_eq!(s.tools[0].length_mm, Some(75.0));
    assert_eq!(s.tools[0].name.as_deref(), Some("EM10"));
    assert_eq!((s.tools[0].line, s.tools[0].first_row_line), (3, 5));
    assert_eq!(
        (s.tools[1].tool, s.tools[1].length_mm),
        (Some(8), Some(90.0))
    );
    assert_eq!(
        (s.tools[1].first_row_line, s.tools[1].first_row_index),
        (15, 2)
    );
    assert_eq!(
        (s.tools[2].tool, s.tools[2].length_mm, s.tools[2].line),
        (Some(9), Some(90.0), 16)
    );
    // inch TLDATA length converted
    let inch = Options {
        units: Some(Units::Inch),
        ..Options::default()
    };
    let (_, s) = read_opts("TLDATA/MILL,0.5,0,3,0,0\nGOTO/0,0,1\n", &inch);
    assert!((s.tools[0].length_mm.unwrap() - 76.2).abs() < 1e-12);
    // tool numbers must be non-negative integers
    for t in [
        "LOADTL/\n",
        "LOADTL/,1\n",
        "LOADTL/1.5\n",
        "LOADTL/-1\n",
        "LOAD/TOOL\n",
        "LOAD/TOOL,X\n",
    ] {
        let e = err(&format!("UNITS/MM\n{t}GOTO/1,2,3\n"));
        assert!(matches!(e.kind, ClErrorKind::ToolNumber { .. }), "{t}: {e}");
    }
    // LOAD/WIRE is skipped
    let (_, s) = read("UNITS/MM\nLOAD/WIRE,1\nGOTO/1,2,3\n");
    assert_eq!(s.skipped.get("LOAD"), Some(&1));
}

// ---------------------------------------------------------------- arcs (SPEC §7)

#[test]
fn arc_direction_by_dialect() {
    // the same arc: right-hand without NX records, clockwise about the axis after TOOL PATH
    let arc = "GOTO/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n";
    let (rows, s) = read(&format!("UNITS/MM\n{arc}"));
    assert_eq!(s.arc_rule, Some(ArcRule::RightHand));
    let mid = rows[rows.len() / 2].tip;
    assert!(mid[0] > 0.0 && mid[1] > 0.0, "quarter in +X+Y: {mid:?}");
    let (rows, s) = read(&format!("TOOL PATH/X,TOOL,T\n{arc}"));
    assert_eq!(s.arc_rule, Some(ArcRule::ClockwiseAboutAxis));
    assert!(
        rows.iter().any(|r| r.tip[1] < -9.0),
        "three quarters through -Y"
    );
    // an NX record after the first CIRCLE does not change the rule
    let (_, s) = read(&format!(
        "UNITS/MM\n{arc}TOOL PATH/X\n{}",
        "CIRCLE/0,0,0,0,0,1,10\nGOTO/10,0,0\n"
    ));
    assert_eq!(s.arc_rule, Some(ArcRule::RightHand));
}

#[test]
fn arc_rows_helix_full_circle_and_axis() {
    let (rows, _) =
        read("UNITS/MM\nGOTO/10,0,0\nFEDRAT/100\nCIRCLE/0,0,0,0,0,1,10\nGOTO/10,0,-2\n");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.kind == Kind::Circle).collect();
    assert!(arc.len() >= 4);
    for (k, r) in arc.iter().enumerate() {
        let rad = (r.tip[0].powi(2) + r.tip[1].powi(2)).sqrt();
        assert!((rad - 10.0).abs() < 1e-9);
        assert_eq!(r.line, 4);
        assert_eq!(r.feed_mm_min, Some(100.0));
        let frac = (k + 1) as f64 / arc.len() as f64;
        assert!(
            (r.tip[2] + 2.0 * frac).abs() < 1e-9,
            "helix: z linear in the angle"
        );
    }
    // the axis turns along the arc when the end GOTO carries another one
    let (rows, _) = read("UNITS/MM\nGOTO/10,0,0,0,0,1\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0,0,1,0\n");
    let arc: Vec<&Row> = rows.iter().filter(|r| r.kind == Kind::Circle).collect();
    let mid = arc[arc.len() / 2 - 1].axis;
    assert!(
        mid[1] > 0.3 && mid[2] > 0.3 && ((mid[1] * mid[1] + mid[2] * mid[2]) - 1.0).abs() < 1e-9
    );
    assert_eq!(arc.last().unwrap().axis, [0.0, 1.0, 0.0]);
    assert_eq!(
        err("UNITS/MM\nGOTO/10,0,0,0,0,1\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0,0,0,-1\n").kind,
        ClErrorKind::ArcAxisFlip
    );
}

#[test]
fn arc_errors() {
    let base = "UNITS/MM\nGOTO/10,0,0\n";
    for (t, line, kind) in [
        (
            "RAPID\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n",
            4,
            "RapidBeforeCircle",
        ),
        (
            "CIRCLE/0,0,0,0,0,1,10\nRAPID\nGOTO/0,10,0\n",
            4,
            "RecordAfterCircle",
        ),
        ("CIRCLE/0,0,0,0,0,1,10\nGOTO/0,11,0\n", 3, "ArcRadius"),
        ("CIRCLE/0,0,0,0,0,1,9\nGOTO/0,10,0\n", 3, "ArcRadiusGiven"),
        ("CIRCLE/0,0,0,0,0,1,10\n", 3, "CircleWithoutEnd"),
        ("CIRCLE/0,0,0,0,0,1,10\nFINI\n", 3, "CircleWithoutEnd"),
        ("CIRCLE/0,0,0,0,0,0,10\nGOTO/0,10,0\n", 3, "ZeroAxis"),
        ("CIRCLE/0,0,0,0,0\n", 3, "FieldCount"),
        (
            "CIRCLE/0,0,0,0,0,1,10\nGOTO/10,-0.001,0\n",
            3,
            "ArcAmbiguous",
        ),
        (
            "CIRCLE/0,0,0,0,0,1,10\nGOTO/-10,0,0\n 0,10,0\n",
            4,
            "ArcPointOrder",
        ),
        (
            "CIRCLE/0,0,0,0,0,1,10\nGOTO/0,10.1,0\n -10,0,0\n",
            4,
            "ArcPointOff",
        ),
        ("CIRCLE/0,0,0,0,0,1,10\n0,10,0\n", 4, "BarePoint"),
        ("CIRCLE/0,0,0,0,0,1,10\nGODLTA/1\n", 4, "RecordAfterCircle"),
        (
            "CIRCLE/0,0,0,0,0,1,10\nEND-OF-PATH\n",
            4,
            "RecordAfterCircle",
        ),
    ] {
        let e = err(&format!("{base}{t}"));
        assert_eq!(e.line, line, "{t}: {e}");
        assert!(format!("{:?}", e.kind).starts_with(kind), "{t}: {e:?}");
    }
    // The arc's errors name the CIRCLE record's column, a stated radius its own field's.
    let e = err(&format!("{base}CIRCLE/0,0,0,0,0,1,10\nGOTO/0,11,0\n"));
    assert_eq!((e.line, e.column), (3, Some(1)), "{e}");
    let e = err(&format!("{base}CIRCLE/0,0,0,0,0,1,9\nGOTO/0,10,0\n"));
    assert_eq!((e.line, e.column), (3, Some(20)), "{e}");
    // comments, PAINT, FEDRAT between CIRCLE and GOTO are fine; the FEDRAT applies to the arc
    let (rows, _) = read(&format!(
        "{base}CIRCLE/0,0,0,0,0,1,10\n$$ c\nPAINT/COLOR,1\nFEDRAT/77\nPPRINT x\nGOTO/0,10,0\n"
    ));
    assert_eq!(rows.last().unwrap().feed_mm_min, Some(77.0));
    // too many points for the limit
    let tiny = Options {
        chord_tol_mm: 1e-7,
        max_arc_points: 100,
        ..Options::default()
    };
    let e = read_all(
        "t.cl",
        format!("{base}CIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n").as_bytes(),
        &tiny,
    )
    .unwrap_err();
    assert!(matches!(e.kind, ClErrorKind::ArcTooManyPoints { .. }));
}

// ---------------------------------------------------------------- cycles (SPEC §8)

#[test]
fn cycles() {
    let (rows, _) = read(
        "UNITS/MM\nSPINDL/1000\nRAPID\nGOTO/0,0,50\nCYCLE/DRILL,RAPTO,2,FEDTO,-10,RTRCTO,AUTO,MMPR,0.1\nGOTO/0,0,0\nCYCLE/ON,DEPTH,5,RTRCTO,20\nGOTO/5,0,0,1,0,0\nCYCLE/OFF\nGOTO/9,9,9\n",
    );
    assert_eq!(rows.len(), 8);
    assert!(rows[1..7].iter().all(|r| r.kind == Kind::Cycle));
    assert_row(&rows[1], [0.0, 0.0, 2.0], [0.0, 0.0, 1.0]);
    assert_row(&rows[2], [0.0, 0.0, -10.0], [0.0, 0.0, 1.0]);
    assert_eq!(rows[2].feed_mm_min, Some(100.0));
    assert_row(&rows[3], [0.0, 0.0, 2.0], [0.0, 0.0, 1.0]);
    // a cycle point with its own axis: along that axis
    assert_row(&rows[4], [7.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    assert_row(&rows[5], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    assert_row(&rows[6], [25.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    assert_eq!((rows[7].kind, rows[7].motion), (Kind::Goto, Motion::Feed));
    // the current feed when the cycle gives none; inch positional form
    let (rows, _) = read(
        "UNITS/INCH\nGOTO/0,0,2\nFEDRAT/5\nCYCLE/TAP,0.5,IPM,4,0.1\nGOTO/1,0,0\nCYCLE/OFF\nCYCLE/BORE,FEDTO,1\nGOTO/2,0,0\n",
    );
    assert_eq!(rows[2].feed_mm_min, Some(4.0 * 25.4));
    assert_row(&rows[2], [25.4, 0.0, -12.7], [0.0, 0.0, 1.0]);
    assert_eq!(rows[5].feed_mm_min, Some(127.0));
    assert_row(&rows[4], [50.8, 0.0, 0.0], [0.0, 0.0, 1.0]);
    // END-OF-PATH ends the cycle
    let (rows, _) = read("UNITS/MM\nGOTO/0,0,1\nCYCLE/DRILL,FEDTO,1\nEND-OF-PATH\nGOTO/1,1,1\n");
    assert_eq!(rows[1].kind, Kind::Goto);
    // errors
    for (t, kind) in [
        ("CYCLE\n", "CycleEmpty"),
        ("CYCLE/ON,FEDTO,1\n", "CycleOnWithoutCycle"),
        ("CYCLE/DRILL,RAPTO,2\n", "CycleNoDepth"),
        ("CYCLE/MILL,FEDTO,2\n", "CycleType"),
        ("CYCLE/DRILL,5,MMPM\n", "CyclePositional"),
        ("CYCLE/DRILL,5,XX,100,2\n", "CyclePositional"),
        ("CYCLE/DRILL,FEDTO\n", "CycleKeyword"),
        ("CYCLE/DRILL,FEDTO,,RAPTO,1\n", "CycleKeyword"),
        ("CYCLE/DRILL,FEDTO,1,RTRCTO,X\n", "BadNumber"),
        ("CYCLE/DRILL,FEDTO,1,MMPM,0\n", "FeedNotPositive"),
    ] {
        let e = err(&format!("UNITS/MM\nGOTO/0,0,1\n{t}GOTO/1,1,1\n"));
        assert_eq!(e.line, 3, "{t}: {e}");
        assert!(format!("{:?}", e.kind).starts_with(kind), "{t}: {e:?}");
    }
}

// ---------------------------------------------------------------- syntax (SPEC §3)

#[test]
fn bare_point_lines() {
    let (rows, _) = read("UNITS/MM\nGOTO/0,0,0\nGOTO/1,0,0\n 2,0,0\n3,0,0\nFEDRAT/5\nGOTO/4,0,0\n");
    let lines: Vec<u64> = rows.iter().map(|r| r.line).collect();
    assert_eq!(lines, [2, 3, 4, 5, 7]);
    assert!(rows.iter().all(|r| r.kind == Kind::Goto));
    for t in [
        "UNITS/MM\n1,2,3\n",
        "UNITS/MM\nGOTO/1,2,3\nFEDRAT/5\n4,5,6\n",
        "UNITS/MM\nGOTO/1,2,3\n$$ c\n4,5,6\n",
        "UNITS/MM\nFROM/1,2,3\n4,5,6\n",
    ] {
        assert_eq!(err(t).kind, ClErrorKind::BarePoint, "{t}");
    }
    let e = err("UNITS/MM\nGOTO/1,2,3\n4,x,6\n");
    assert_eq!((e.line, e.column), (3, Some(3)));
}

#[test]
fn comments_text_and_fini() {
    let (rows, s) = read(
        "PARTNO/X $ not continued\nPPRINT/GOTO/1,2,3 $\nUNITS/MM\nGOTO/1,2,3 $$ c $\nINSERT/x\nREMARK y\nTPRINT/z\nFINI\nGOTO/garbage\n\u{1}\u{2}",
    );
    assert_eq!(rows.len(), 1);
    assert_eq!(s.fini_line, Some(8));
    assert_eq!(
        s.skipped_line(),
        "INSERT 1, PARTNO 1, PPRINT 1, REMARK 1, TPRINT 1"
    );
    // a comment continued onto a GOTO line: read as comment, with a warning
    let (rows, s) = read("UNITS/MM\nGOTO/0,0,0\n$$ price in $\nGOTO/1,2,3\nGOTO/4,5,6\n");
    assert_eq!(rows.len(), 2);
    assert!(matches!(
        s.warnings[0].kind,
        WarningKind::CommentTakesRecord { .. }
    ));
    assert_eq!(s.warnings[0].line, 4);
}

#[test]
fn refused_records() {
    for (t, kind) in [
        (
            "TLON,GOFWD/(CIRCLE/0,0,0,1),ON,(LINE/1,2,3,4,5,6)\n",
            "GeometricStatement",
        ),
        ("GOFWD/S1,TANTO,S2\n", "GeometricStatement"),
        ("TLLFT, GOLFT/S1\n", "GeometricStatement"),
        ("NURBS/\n", "Nurbs"),
        ("KNOT/0,0,1\n", "Nurbs"),
        ("CNTRL/1,2,3\n", "Nurbs"),
        ("TRACUT/1,0,0,5,0,1,0,0,0,0,1,0\n", "Transformation"),
        ("COPY/1,TRANSL,10,0,0,2\n", "Transformation"),
        ("G0 X1 Y2\n", "BadRecordName"),
        ("GOTO 1,2,3\n", "BadRecordName"),
    ] {
        let e = err(&format!("UNITS/MM\nGOTO/0,0,0\n{t}GOTO/1,1,1\n"));
        assert_eq!(e.line, 3, "{t}");
        assert!(format!("{:?}", e.kind).starts_with(kind), "{t}: {e:?}");
    }
    // TRACUT/NOMORE is harmless
    read("UNITS/MM\nTRACUT/NOMORE\nGOTO/0,0,0\n");
}

#[test]
fn no_motion_and_not_cl() {
    let e = err("PARTNO/X\nUNITS/MM\nFINI\n");
    assert_eq!((e.line, e.kind), (3, ClErrorKind::NoMotion));
    let e = err("UNITS/MM\n$$ only\n");
    assert_eq!((e.line, e.kind), (2, ClErrorKind::NoMotion));
    let e = read_all("a.txt", b"%\nG0 X0\n", &Options::default()).unwrap_err();
    assert_eq!((e.line, e.kind), (1, ClErrorKind::NotClFile));
    let e = read_all("a.txt", b"", &Options::default()).unwrap_err();
    assert_eq!(e.kind, ClErrorKind::NotClFile);
    // by extension, the content is not judged: a G-code file named .cl fails at its first line
    let e = read_all("a.cl", b"%\nG0 X0\n", &Options::default()).unwrap_err();
    assert_eq!(e.line, 1);
    assert!(matches!(e.kind, ClErrorKind::BadRecordName { .. }));
}

#[test]
fn invalid_options() {
    for o in [
        Options {
            chord_tol_mm: 0.0,
            ..Options::default()
        },
        Options {
            chord_tol_mm: f64::NAN,
            ..Options::default()
        },
        Options {
            max_arc_points: 0,
            ..Options::default()
        },
        Options {
            max_record_bytes: 10,
            ..Options::default()
        },
    ] {
        let e = read_all("t.cl", b"GOTO/1,2,3\n", &o).unwrap_err();
        assert_eq!(e.line, 0);
        assert!(matches!(e.kind, ClErrorKind::InvalidOptions(_)));
    }
}

#[test]
fn skipped_summary_is_bounded_and_names_only() {
    let mut text = String::from("UNITS/MM\n");
    for i in 0..400 {
        text.push_str(&format!("UNKNOWN{i}/1\n"));
    }
    text.push_str("PAINT/COLOR,1\nGOTO/1,2,3\n");
    let (_, s) = read(&text);
    assert_eq!(s.skipped.len(), verne_cl::MAX_SKIPPED_NAMES + 1);
    assert_eq!(s.skipped.get(verne_cl::OTHER_RECORDS), Some(&145));
    assert!(s.skipped.keys().all(|k| k.len() <= 32 && !k.contains('/')));
}

// ---------------------------------------------------------------- TLAXIS (SPEC §5.2a)

#[test]
fn tlaxis_is_the_axis_of_the_motions_that_give_none() {
    // Each expected axis is written out by hand: TLAXIS normalised, a 6-value GOTO replacing
    // it, GODLTA/d along it, a cycle along it (R, B, Q = P + 1 a, P - 3 a, P + 1 a).
    let (rows, _) = read(
        "UNITS/MM\nTLAXIS/0,3,4\nFROM/0,0,100\nGOTO/10,0,0\nGOTO/10,10,0,1,0,0\nGOTO/20,10,0\n\
         TLAXIS/0,0,-2\nGODLTA/5\nCYCLE/DRILL,FEDTO,3,RAPTO,1,MMPM,100\nGOTO/1,1,1\nCYCLE/OFF\n\
         GOTO/2,2,2\n",
    );
    let tilted = [0.0, 0.6, 0.8];
    let down = [0.0, 0.0, -1.0];
    assert_eq!(rows.len(), 9);
    assert_row(&rows[0], [0.0, 0.0, 100.0], tilted);
    assert_row(&rows[1], [10.0, 0.0, 0.0], tilted);
    assert_row(&rows[2], [10.0, 10.0, 0.0], [1.0, 0.0, 0.0]);
    assert_row(&rows[3], [20.0, 10.0, 0.0], [1.0, 0.0, 0.0]);
    assert_row(&rows[4], [20.0, 10.0, -5.0], down);
    assert_row(&rows[5], [1.0, 1.0, 0.0], down);
    assert_row(&rows[6], [1.0, 1.0, 4.0], down);
    assert_row(&rows[7], [1.0, 1.0, 0.0], down);
    assert_row(&rows[8], [2.0, 2.0, 2.0], down);
    // Without TLAXIS the same 3-value GOTO has the axis (0, 0, 1): the record is what moved it.
    let (rows, s) = read("UNITS/MM\nGOTO/10,0,0\n");
    assert_row(&rows[0], [10.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    assert!(!s.skipped.contains_key("TLAXIS"));
}

#[test]
fn tlaxis_follows_the_frames() {
    // SPEC §6.1: path B's MSYS turns its frame 90 degrees about z; the axis (1, 0, 0) written
    // under it is (0, 1, 0) in the output frame (path A's), as a GOTO's axis would be.
    let text = "\
TOOL PATH/A,TOOL,T
MSYS/0,0,0,1,0,0,0,1,0
GOTO/0,0,0
END-OF-PATH
TOOL PATH/B,TOOL,T
MSYS/100,50,20,0,1,0,-1,0,0
TLAXIS/1,0,0
GOTO/10,0,5
END-OF-PATH
";
    let (rows, _) = read(text);
    assert_row(&rows[1], [100.0, 60.0, 25.0], [0.0, 1.0, 0.0]);
    // Before any frame and motion, TLAXIS fixes the output frame (as a motion would): the
    // MSYS after it is applied to the points, and the axis is the one written.
    let (rows, _) = read("TLAXIS/0,0,1\nMSYS/100,0,0,0,1,0,-1,0,0\nGOTO/10,0,0\n");
    assert_row(&rows[0], [100.0, 10.0, 0.0], [0.0, 0.0, 1.0]);
}

#[test]
fn tlaxis_forms_that_cannot_be_read_are_refused_at_their_field() {
    for (t, column, found) in [
        ("TLAXIS/NORMPS", 8, "NORMPS"),
        ("TLAXIS/0,0,1,ATANGL,5", 14, "ATANGL"),
        ("TLAXIS/0,0", 11, ""),
        ("TLAXIS/0,0,1,0", 14, ""),
        ("TLAXIS", 7, ""),
    ] {
        let e = err(&format!("UNITS/MM\nGOTO/0,0,0\n{t}\nGOTO/1,1,1\n"));
        assert_eq!((e.line, e.column), (3, Some(column)), "{t}: {e}");
        match &e.kind {
            ClErrorKind::TlaxisForm { found: f, .. } => assert_eq!(f, found, "{t}"),
            other => panic!("{t}: {other:?}"),
        }
        assert!(e.to_string().contains("TLAXIS"), "{e}");
    }
    let e = err("UNITS/MM\nTLAXIS/0,,1\nGOTO/1,1,1\n");
    assert_eq!((e.line, e.column), (2, Some(10)));
    assert!(matches!(e.kind, ClErrorKind::BadNumber { field: 2, .. }));
    let e = err("UNITS/MM\nTLAXIS/0,0,0\nGOTO/1,1,1\n");
    assert_eq!((e.line, e.column), (2, Some(8)));
    assert!(matches!(e.kind, ClErrorKind::ZeroAxis { .. }));
    let e = err("UNITS/MM\nTLAXIS/0,0,1e999\nGOTO/1,1,1\n");
    assert_eq!((e.line, e.column), (2, Some(12)));
    assert!(matches!(e.kind, ClErrorKind::NumberOutOfRange { .. }));
}

// ---------------------------------------------------------------- NX listing end (SPEC §3.9)

#[test]
fn a_listing_ends_at_its_line_count_and_what_follows_is_ignored() {
    let text = "\
TOOL PATH/A,TOOL,T
RAPID
GOTO/0,0,10
GOTO/1,0,0
END-OF-PATH

Tool Path Listing has 5 lines.
anything # at all
GOTO/99,99,99
=====
Information listing created by : x
TOOL PATH/B,TOOL,T
GOTO/2,0,0
END-OF-PATH
tool   path listing HAS 3 line
";
    let (rows, s) = read_opts(
        text,
        &Options {
            units: Some(Units::Mm),
            ..Options::default()
        },
    );
    let tips: Vec<[f64; 3]> = rows.iter().map(|r| r.tip).collect();
    assert_eq!(tips, [[0.0, 0.0, 10.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
    assert_eq!(s.dialect, Dialect::NxListing);
    assert_eq!(s.skipped.get("TOOL PATH LISTING"), Some(&2));
    let after: Vec<(u64, &WarningKind)> = s
        .warnings
        .iter()
        .filter(|w| matches!(w.kind, WarningKind::AfterListingEnd { .. }))
        .map(|w| (w.line, &w.kind))
        .collect();
    assert_eq!(
        after,
        [(8, &WarningKind::AfterListingEnd { end_line: 7 })],
        "{:?}",
        s.warnings
    );
    // Only that line: a line that merely starts like it is not the end.
    for t in [
        "Tool Path Listing has many lines.",
        "Tool Path Listing has 5 lines. More",
        "Tool Path Listing 5 lines.",
    ] {
        let e = err(&format!("UNITS/MM\nGOTO/0,0,0\n{t}\n"));
        assert_eq!(e.line, 3, "{t}");
    }
}

// ---------------------------------------------------------------- messages (terminal safety)

#[test]
fn messages_escape_the_control_bytes_of_the_file() {
    let raw_control = |s: &str| s.chars().any(char::is_control);
    for bad in [
        &b"UNITS/MM\nGOTO/1,2,\x1b[31mX\x07\x00\n"[..],
        b"UNITS/MM\nGOTO/0,0,0\n\x1b]0;title\x07/1,2\n",
        b"UNITS/MM\nFEDRAT/\x1b[2J,100\nGOTO/0,0,0\n",
        b"UNITS/MM\nGOTO/0,0,0\nTLAXIS/\x9b31m,0,1\n",
        b"UNITS/\x00\x1b\x07\nGOTO/0,0,0\n",
    ] {
        let e = read_all("t.cl", bad, &Options::default()).unwrap_err();
        let shown = e.to_string();
        assert!(!raw_control(&shown), "{shown:?}");
        assert!(
            shown.contains("\\u{1b}") || shown.contains("\\u{9b}") || shown.contains("\\0"),
            "{shown:?}"
        );
    }
    // Tool names go to the summary the same way.
    let (_, s) = read("TOOL PATH/OP,TOOL,EM\x1b[5m\nGOTO/0,0,0\n");
    let name = s.tools[0].name.as_deref().unwrap();
    assert!(!raw_control(name) && name.contains("\\u{1b}"), "{name:?}");
}
