//! `verne ik`: tool poses (workpiece frame) -> machine joints, or platform points -> joints of
//! the parallel module (IFToMM 2007, section V), from CSV or a CL file.

use crate::engine::machine_rows::{MachineIk, OrientationColumns};
use crate::engine::module_rows::{ModuleIkAll, ModuleIkWorking};
use crate::error::VerneError;
use crate::table::CsvSource;
use verne::machine::FirstRowChoice;

use super::{Mechanism, inline_source, load_mechanism, refuse_for_glider, run_rows, units};
use crate::cli::{IkArgs, OutputFormat, Prefer};
use crate::input::as_csv::AsCsv;
use crate::input::cl::{ClAsCsv, ClRows, PathInput, open_path_input, report_summary};
use crate::input::gcode::{TcpAsCsv, TcpRows};
use crate::input::resample::Resampler;

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
    let mut cl_summary = None;
    let mut gcode_summary = None;
    let mut travel = None;
    crate::arg_values::spatial(&args.pose, "--pose", "XP,YP,ZP").map_err(VerneError::Usage)?;
    let source = if !args.pose.is_empty() {
        inline_source(
            "xp,yp,zp",
            &args.pose.iter().map(|p| p.to_vec()).collect::<Vec<_>>(),
        )?
    } else if !args.tool.is_empty() {
        inline_source(
            "x,y,z,i,j,k",
            &args.tool.iter().map(|p| p.to_vec()).collect::<Vec<_>>(),
        )?
    } else {
        let options = args.part.read_options(&machine.gcode);
        match open_path_input(args.input.as_deref(), args.input_format, &options)? {
            PathInput::Csv(src) => src,
            PathInput::Gcode(reader, name) => {
                let rows = TcpRows::new(*reader, &name, &machine.gcode);
                gcode_summary = Some((rows.summary(), name.clone()));
                CsvSource::from_reader(Box::new(TcpAsCsv::new(rows)), &name)?
                    .with_line_column("line")
            }
            PathInput::Cl(reader, name) => {
                let rows = ClRows::new(*reader);
                cl_summary = Some((rows.summary(), name.clone()));
                CsvSource::from_reader(Box::new(ClAsCsv::new(rows)), &name)?
                    .with_line_column("line")
            }
        }
    };
    let source = match args.period {
        Some(period) => {
            if source.column("xp").is_some() && source.column("x").is_none() {
                return Err(VerneError::Usage(
                    "--period resamples a toolpath of tool poses (x,y,z with i,j,k or phi1,phi2), not platform points".into(),
                ));
            }
            let name = source.name().to_string();
            let rows = Resampler::new(source, period, args.rapid, args.common.radians)?;
            CsvSource::from_reader(Box::new(AsCsv::new(rows)), &name)?.with_line_column("line")
        }
        None => source,
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
            let mut job = MachineIk::new(machine, tool_length, orientation, args.all, first);
            job.offset = offset;
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
