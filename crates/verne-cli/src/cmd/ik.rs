//! `verne ik`: tool poses (workpiece frame) -> machine joints, or platform points -> joints of
//! the parallel module (IFToMM 2007, section V), from CSV or an APT CL file.

use std::path::Path;

use crate::engine::machine_rows::{MachineIk, OrientationColumns};
use crate::engine::module_rows::{ModuleIkAll, ModuleIkWorking};
use crate::error::VerneError;
use crate::table::CsvSource;
use verne::machine::FirstRowChoice;

use super::{inline_source, load_machine, run_rows, units};
use crate::cli::{IkArgs, InputFormat, OutputFormat, Prefer};

pub fn run(args: &IkArgs) -> Result<u8, VerneError> {
    if let Some(spec) = super::glider::load(args.common.machine.as_deref())? {
        return super::glider::ik(args, spec);
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let mut u = units(&args.common);
    u.halstreamer = args.format == OutputFormat::Halstreamer;
    if u.halstreamer && args.all {
        return Err(VerneError::Usage(
            "--format halstreamer writes one joint row per pose; it cannot be combined with --all"
                .into(),
        ));
    }
    let tool_length = args.tool_length.unwrap_or(machine.tool_length);
    let mut apt_summary = None;
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
    } else if is_apt(args.input.as_deref(), args.input_format) {
        let (src, summary) = apt_source(args.input.as_deref())?;
        apt_summary = Some(summary);
        src
    } else {
        CsvSource::open(args.input.as_deref())?
    };
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
            let mut job = MachineIk::new(machine, tool_length, orientation, args.all, first);
            run_rows("ik", &mut job, source, args.output.as_ref(), u)?
        }
        (false, _) => {
            if u.halstreamer {
                return Err(VerneError::Usage("--format halstreamer writes machine joints: give tool poses (x,y,z with i,j,k or phi1,phi2), not platform points".into()));
            }
            let output = args.output.as_ref();
            if args.all {
                run_rows("ik", &mut ModuleIkAll { machine }, source, output, u)?
            } else {
                run_rows("ik", &mut ModuleIkWorking { machine }, source, output, u)?
            }
        }
    };
    if let Some((summary, name)) = apt_summary
        && let Ok(s) = summary.lock()
    {
        crate::input::cl::report_summary("ik", &name, &s);
    }
    Ok(code)
}

fn is_apt(input: Option<&Path>, format: Option<InputFormat>) -> bool {
    match format {
        Some(f) => f == InputFormat::Apt,
        None => input
            .and_then(|p| p.to_str())
            .is_some_and(verne_cl::has_cl_extension),
    }
}

type SharedClSummary = std::sync::Arc<std::sync::Mutex<verne_cl::Summary>>;

/// A CL file as a CSV source with columns line,kind,motion,feed,tool,x,y,z,i,j,k.
fn apt_source(input: Option<&Path>) -> Result<(CsvSource, (SharedClSummary, String)), VerneError> {
    let (reader, name) = crate::input::cl::open_cl(input, verne_cl::Options::default())?;
    let adapter = crate::input::cl::ClAsCsv::new(reader);
    let summary = adapter.summary();
    let source = CsvSource::from_reader(Box::new(adapter), &name)?;
    Ok((source, (summary, name)))
}
