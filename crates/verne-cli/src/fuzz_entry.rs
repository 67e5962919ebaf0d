//! Entry points shared by the fuzz targets (fuzz/fuzz_targets) and the corpus replay test
//! (tests/fuzz_corpus.rs): each feeds arbitrary bytes to one reader of user input and must
//! return (an answer or an error), never panic or hang.

use std::io::Cursor;

use crate::engine::module_rows::{ModuleFkAll, ModuleFkWorking, ModuleIkAll, ModuleIkWorking};
use crate::engine::pipeline::{self, Units};
use crate::files::Sink;
use crate::table::CsvSource;
use verne::machine::FirstRowChoice;
use verne::spec::Machine;

/// CSV rows through the module inverse (`fk == false`) or forward kinematics, every branch
/// (`--all`) and the working one (the IK fast path, the FK tracker).
pub fn csv_rows(data: &[u8], fk: bool) {
    for all in [true, false] {
        let Ok(mut source) = CsvSource::from_reader(Box::new(Cursor::new(data.to_vec())), "fuzz")
        else {
            return;
        };
        let mut sink = Sink::from_writer(Box::new(std::io::sink()), "sink");
        let machine = Machine::default_verne();
        let units = Units::default();
        let (src, snk) = (&mut source, &mut sink);
        let _ = match (fk, all) {
            (true, true) => pipeline::run(&mut ModuleFkAll { machine }, src, snk, units, &|_| {}),
            (true, false) => {
                pipeline::run(&mut ModuleFkWorking { machine }, src, snk, units, &|_| {})
            }
            (false, true) => pipeline::run(&mut ModuleIkAll { machine }, src, snk, units, &|_| {}),
            (false, false) => {
                pipeline::run(&mut ModuleIkWorking { machine }, src, snk, units, &|_| {})
            }
        };
    }
}

/// CSV tool poses (x,y,z with i,j,k or phi1,phi2) through the machine inverse kinematics along
/// a path (`verne ik` on a toolpath), every branch (`--all`) and the followed one.
pub fn csv_tool_rows(data: &[u8]) {
    use crate::follow::{FollowOptions, Follower};
    use crate::toolpath::csv::CsvToolpath;
    for all in [true, false] {
        let Ok(source) = CsvSource::from_reader(Box::new(Cursor::new(data.to_vec())), "fuzz")
        else {
            return;
        };
        let Ok(mut path) = CsvToolpath::new(source, false) else {
            return;
        };
        let machine = Machine::default_verne();
        let mut follower = Follower::new(FollowOptions {
            tool_length: machine.tool_length,
            machine,
            offset: nalgebra::Vector3::zeros(),
            all,
            first: FirstRowChoice::default(),
            seed_theta2: None,
            period: None,
        });
        let mut sink = crate::follow::write::CsvRows::to_writer(Box::new(std::io::sink()), all);
        let _ = crate::follow::run(&mut path, &mut follower, None, &mut sink, &|_| {});
    }
}

/// A machine file, TOML or key,value CSV.
pub fn machine_file(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = Machine::from_str_auto(text, "fuzz");
    }
}

/// A CL file in any dialect, read to the end or to its first error (`verne_cl::fuzz_read`).
pub fn apt_file(data: &[u8]) {
    verne_cl::fuzz_read(data);
}

/// A G-code program, any bytes: the reader's invariants (`verne_gcode::fuzz_read`), then the
/// CLI's readings of it as a tool-centre program and as a joint program (default words, and
/// the tool-vector form), which must end in rows or an error, never a panic.
pub fn gcode_file(data: &[u8]) {
    use crate::input::gcode::JointProgram;
    use crate::toolpath::ToolpathSource;
    use crate::toolpath::gcode::TcpToolpath;
    use verne::spec::gcode::{GcodeOrientation, GcodeWords};
    use verne::verify::RowSource;
    verne_gcode::fuzz_read(data);
    let vector = GcodeWords {
        orientation: GcodeOrientation::Vector,
        ..GcodeWords::default()
    };
    for words in [GcodeWords::default(), vector] {
        let options = crate::input::gcode::options(0.01, None, &words);
        let open = || -> Option<crate::input::gcode::GcodeReader> {
            let input: Box<dyn std::io::BufRead + Send> =
                Box::new(std::io::Cursor::new(data.to_vec()));
            verne_gcode::Reader::new(input, options).ok()
        };
        if let Some(reader) = open() {
            let mut rows = TcpToolpath::new(reader, "fuzz.ngc", &words);
            let mut row = crate::toolpath::PoseRow::default();
            for _ in 0..100_000 {
                match rows.next_row(&mut row) {
                    Ok(true) => assert!(row.tip.iter().all(|v| v.is_finite()), "tip"),
                    _ => break,
                }
            }
        }
        if let Some(reader) = open() {
            let mut joints = JointProgram::new(reader, "fuzz.ngc", &words);
            for _ in 0..100_000 {
                match joints.next_item() {
                    Ok(Some(_)) => {}
                    _ => break,
                }
            }
        }
    }
}

/// A recording (`verify --recording`), any bytes, under the first byte's choice of columns:
/// read to its end or an error, then verified against a short path (the contour search on
/// whatever joints the bytes hold), never a panic.
pub fn recording(data: &[u8]) {
    use crate::input::recording::{RecordingReader, parse_columns};
    use nalgebra::Vector3;
    use verne::verify::contour::{ContourPath, verify_recording};
    use verne::verify::{PathPoint, RowSource, Thresholds, VerifyOptions};
    let Some((&choice, rest)) = data.split_first() else {
        return;
    };
    let columns = [
        "rho1,rho2,rho3,theta1,theta2",
        "tag,rho1,rho2,rho3,theta1,theta2,_,_",
        "theta2,_,rho3,tag,rho1,theta1,rho2",
    ][usize::from(choice % 3)];
    let open = || {
        RecordingReader::from_reader(
            Box::new(std::io::Cursor::new(rest.to_vec())),
            "fuzz.txt",
            parse_columns(columns).expect("valid columns"),
            0.001,
        )
    };
    let mut reader = open();
    for _ in 0..100_000 {
        match reader.next_item() {
            Ok(Some(_)) => {}
            _ => break,
        }
    }
    let machine = verne::spec::Machine::default_verne();
    let Ok(thresholds) = Thresholds::from_machine(&machine, "fuzz") else {
        return;
    };
    let opt = VerifyOptions {
        thresholds,
        tool_length: machine.tool_length,
    };
    let path = ContourPath::new(vec![
        PathPoint::new(Vector3::new(0.0, 0.0, 100.0), Vector3::z()),
        PathPoint::new(Vector3::new(20.0, 10.0, 80.0), Vector3::z()),
        PathPoint::new(
            Vector3::new(40.0, 10.0, 80.0),
            verne::machine::orientation::tool_axis(0.2, 0.8),
        ),
    ]);
    let mut report =
        |_: &verne::verify::Violation| -> Result<(), crate::error::VerneError> { Ok(()) };
    let _ = verify_recording(&machine, &opt, &mut open(), path, "path", &mut report);
}

/// The command-line value parsers, on any text.
pub fn arg_values(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        use crate::arg_values::*;
        let _ = parse_triple(text);
        let _ = parse_bounds(text);
        let _ = parse_pair(text);
        let _ = parse_slice(text);
        let _ = parse_ratio(text);
        let _ = parse_positive(text);
        let _ = parse_lambda_bounds(text);
        let _ = parse_tool_pose(text);
        let _ = parse_machine_joints(text);
        let _ = parse_threshold(text);
    }
}
