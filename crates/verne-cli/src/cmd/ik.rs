//! `verne ik`: tool poses (workpiece frame) -> machine joints, or platform points -> joints of
//! the parallel module (IFToMM 2007, section V), from CSV or a CL file.

use crate::engine::machine_rows::{MachineIk, OrientationColumns};
use crate::engine::module_rows::{ModuleIkAll, ModuleIkWorking};
use crate::error::VerneError;
use crate::table::{CsvSource, parse_number};
use std::sync::{Arc, Mutex};

use verne::machine::orientation::{ToolAngles, ToolOrientation};
use verne::machine::{FirstRowChoice, PathState, first_decided_theta2};
use verne::spec::Machine;

use super::{Mechanism, inline_source, load_mechanism, refuse_for_glider, run_rows, units};
use crate::cli::{IkArgs, OutputFormat, Prefer};
use crate::input::cl::{ClRows, PathInput, open_path_input, report_summary};
use crate::input::gcode::TcpRows;
use crate::input::resample::{CsvPoses, Resampler};

pub fn run(args: &IkArgs) -> Result<u8, VerneError> {
    let machine = match load_mechanism(args.common.machine.as_deref())? {
        Mechanism::Glider(spec) => {
            refuse_for_glider(
                &spec.name,
                &[
                    ("--tool", !args.tool.is_empty()),
                    ("--tool-length", args.tool_length.is_some()),
                    ("--prefer", args.prefer != Prefer::SmallestTheta1),
                    ("--format", args.format != OutputFormat::Csv),
                    ("--period", args.period.is_some()),
                    ("--units", args.part.units.is_some()),
                    ("--offset", args.part.offset.is_some()),
                    ("--input-format", args.input_format.is_some()),
                ],
            )?;
            return super::glider::ik(args, spec);
        }
        Mechanism::Verne(m) => m,
    };
    let mut u = units(&args.common);
    u.halstreamer = args.format == OutputFormat::Halstreamer;
    if args.format == OutputFormat::Gcode {
        if args.common.radians || args.common.precision.is_some() {
            return Err(VerneError::Usage(
                "--format gcode writes degrees and mm with its own precision: drop --radians and --precision".into(),
            ));
        }
        u.gcode = Some(machine.gcode);
    }
    let format_name = if u.halstreamer {
        "halstreamer"
    } else {
        "gcode"
    };
    if u.every_row_needed() && args.all {
        return Err(VerneError::Usage(format!(
            "--format {format_name} writes one joint row per pose; it cannot be combined with --all"
        )));
    }
    let tool_length = args.tool_length.unwrap_or(machine.tool_length);
    let cl_summary;
    let gcode_summary;
    let mut travel = None;
    crate::arg_values::spatial(&args.pose, "--pose", "XP,YP,ZP").map_err(VerneError::Usage)?;
    let (source, summaries) = open_source(args, &machine)?;
    (cl_summary, gcode_summary) = summaries;
    let source = match (args.period, source) {
        // A program's poses straight from its reader, angle words and all.
        (Some(period), Source::Program(rows, name)) => {
            let rows = Resampler::new(rows, period, args.rapid, args.common.radians);
            CsvSource::from_rows(Box::new(rows), &name)
        }
        (None, program @ Source::Program(..)) => program.into_rows(),
        (Some(period), Source::Csv(source)) => {
            if source.column("xp").is_some() && source.column("x").is_none() {
                return Err(VerneError::Usage(
                    "--period resamples a toolpath of tool poses (x,y,z with i,j,k or phi1,phi2), not platform points".into(),
                ));
            }
            let name = source.name().to_string();
            let poses = CsvPoses::new(source, args.common.radians)?;
            let rows = Resampler::new(Box::new(poses), period, args.rapid, args.common.radians);
            CsvSource::from_rows(Box::new(rows), &name)
        }
        (None, Source::Csv(source)) => source,
    };
    let offset = args.part.offset();
    let has = |c: &str| source.column(c).is_some();
    let tool_columns = ["x", "y", "z"].iter().all(|c| has(c));
    let platform_columns = ["xp", "yp", "zp"].iter().all(|c| has(c));
    let code = match (tool_columns, platform_columns) {
        (true, true) => {
            return Err(VerneError::input(
                source.name(),
                Some(1),
                None,
                "both tool poses (x,y,z) and platform points (xp,yp,zp) are present: keep one (xp,yp,zp is the parallel module alone)",
            ));
        }
        (true, false) => {
            let orientation = OrientationColumns::detect(has)
                .map_err(|m| VerneError::input(source.name(), Some(1), None, m))?;
            let first = match args.prefer {
                Prefer::SmallestTheta1 => FirstRowChoice::SmallestTheta1,
                Prefer::Orientation1 => FirstRowChoice::Orientation1,
                Prefer::Orientation2 => FirstRowChoice::Orientation2,
            };
            let machine_for_travel = machine.clone();
            // A path that starts with the tool vertical: its orientation is decided further on;
            // look there first, so that --prefer is honoured and theta2 does not swing.
            let seed = if args.all {
                None
            } else {
                prescan_theta2(args, &machine, tool_length, offset, first)?
            };
            let mut job = MachineIk::new(machine, tool_length, orientation, args.all, first);
            job.offset = offset;
            job.travel.period = args.period;
            if let Some(theta2) = seed {
                job.state = PathState::with_theta2(first, theta2);
            }
            let code = run_rows("ik", &mut job, source, args.output.as_ref(), u)?;
            // A CAM job (a CL file or a program): where the joints went, against the limits.
            if (cl_summary.is_some() || gcode_summary.is_some()) && job.travel.rows > 0 {
                travel = Some(job.travel.line(&machine_for_travel));
            }
            code
        }
        (false, _) => {
            if args.part.offset.is_some() {
                return Err(VerneError::Usage(
                    "--offset places tool poses (x,y,z): platform points (xp,yp,zp) are already in the machine's frame".into(),
                ));
            }
            if u.every_row_needed() {
                return Err(VerneError::Usage(format!(
                    "--format {format_name} writes machine joints: give tool poses (x,y,z with i,j,k or phi1,phi2), not platform points"
                )));
            }
            let output = args.output.as_ref();
            if args.all {
                run_rows("ik", &mut ModuleIkAll { machine }, source, output, u)?
            } else {
                run_rows("ik", &mut ModuleIkWorking { machine }, source, output, u)?
            }
        }
    };
    if let Some((summary, name)) = cl_summary
        && let Ok(s) = summary.lock()
    {
        report_summary("ik", &name, &s, tool_length);
    }
    if let Some((summary, name)) = gcode_summary
        && let Ok(s) = summary.lock()
    {
        crate::input::gcode::report_summary("ik", &name, &s);
    }
    if let Some(line) = travel {
        sayln!("verne ik: {line}");
    }
    if u.halstreamer && args.period.is_none() {
        sayln!(
            "verne ik: note: one row per path point, not per servo period (halstreamer plays one row per period: --period 1ms plays the path at its feeds)"
        );
    }
    Ok(code)
}

type Summaries = (
    Option<(Arc<Mutex<verne_cl::Summary>>, String)>,
    Option<(Arc<Mutex<verne_gcode::Summary>>, String)>,
);

/// The input of `verne ik`: a table (inline poses, a CSV, a CL file's rows), or a tool-centre
/// program's poses (its rows for the row engine, or its poses for `--period`).
enum Source {
    Csv(CsvSource),
    Program(Box<TcpRows>, String),
}

impl Source {
    /// The input as a table (a program's poses in the columns of [`TcpRows`]).
    fn into_rows(self) -> CsvSource {
        match self {
            Source::Csv(src) => src,
            Source::Program(rows, name) => CsvSource::from_rows(rows, &name),
        }
    }
}

fn open_source(args: &IkArgs, machine: &Machine) -> Result<(Source, Summaries), VerneError> {
    if !args.pose.is_empty() {
        let rows: Vec<Vec<f64>> = args.pose.iter().map(|p| p.to_vec()).collect();
        return Ok((Source::Csv(inline_source("xp,yp,zp", &rows)?), (None, None)));
    }
    if !args.tool.is_empty() {
        let rows: Vec<Vec<f64>> = args.tool.iter().map(|p| p.to_vec()).collect();
        return Ok((
            Source::Csv(inline_source("x,y,z,i,j,k", &rows)?),
            (None, None),
        ));
    }
    let options = args.part.read_options(&machine.gcode);
    Ok(
        match open_path_input(args.input.as_deref(), args.input_format, &options)? {
            PathInput::Csv(src) => (Source::Csv(src), (None, None)),
            PathInput::Gcode(reader, name) => {
                let rows = TcpRows::new(*reader, &name, &machine.gcode);
                let summary = Some((rows.summary(), name.clone()));
                (Source::Program(Box::new(rows), name), (None, summary))
            }
            PathInput::Cl(reader, name) => {
                let rows = ClRows::new(*reader);
                let summary = Some((rows.summary(), name.clone()));
                (
                    Source::Csv(CsvSource::from_rows(Box::new(rows), &name)),
                    (summary, None),
                )
            }
        },
    )
}

/// Rows read ahead at most, looking for the first pose outside the rotary-singularity cone.
const PRESCAN_ROWS: usize = 100_000;

/// The theta2 that the path's first decided pose needs ([`first_decided_theta2`]), read ahead
/// in a second pass over the input: a file or the command line's poses (stdin is read once,
/// so a path on stdin starts at theta2 = 0). Rows that cannot be read end the look-ahead (the
/// main pass reports them).
fn prescan_theta2(
    args: &IkArgs,
    machine: &Machine,
    tool_length: f64,
    offset: nalgebra::Vector3<f64>,
    first: FirstRowChoice,
) -> Result<Option<f64>, VerneError> {
    let rereadable =
        !args.tool.is_empty() || args.input.as_ref().is_some_and(|p| p.as_os_str() != "-");
    if !rereadable {
        return Ok(None);
    }
    let mut src = open_source(args, machine)?.0.into_rows();
    let col = |c: &str| src.column(c);
    let (Some(x), Some(y), Some(z)) = (col("x"), col("y"), col("z")) else {
        return Ok(None);
    };
    let axis = [col("i"), col("j"), col("k")];
    let angles = [col("phi1"), col("phi2")];
    let radians = args.common.radians;
    let mut rec = csv::ByteRecord::new();
    let poses = std::iter::from_fn(|| {
        if !src.read(&mut rec).ok()? {
            return None;
        }
        let num = |i: usize| parse_number(rec.get(i).unwrap_or(b"")).ok();
        let tip = nalgebra::Vector3::new(num(x)?, num(y)?, num(z)?) + offset;
        let orientation = match (axis, angles) {
            ([Some(i), Some(j), Some(k)], _) => {
                ToolOrientation::Axis(nalgebra::Vector3::new(num(i)?, num(j)?, num(k)?))
            }
            (_, [Some(p1), Some(p2)]) => {
                let a = |v: f64| if radians { v } else { v.to_radians() };
                ToolOrientation::Angles(ToolAngles {
                    phi1: a(num(p1)?),
                    phi2: a(num(p2)?),
                })
            }
            _ => return None,
        };
        Some((tip, orientation))
    })
    .take(PRESCAN_ROWS);
    Ok(first_decided_theta2(machine, poses, tool_length, first))
}
