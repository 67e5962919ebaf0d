//! `verne fk`: machine joints -> tool pose in the workpiece frame, or slider positions -> platform
//! pose of the parallel module (IFToMM 2007, section VI).

use crate::engine::machine_rows::{MachineFkAll, MachineFkWorking};
use crate::engine::module_rows::{ModuleFkAll, ModuleFkWorking};
use crate::error::VerneError;
use crate::input::gcode::JointProgram;
use crate::table::CsvSource;
use crate::toolpath::open::{Format, Input, ReadOptions};
use verne::verify::RowSource;

use super::{Mechanism, inline_source, load_mechanism, refuse_for_glider, run_rows, units};
use crate::cli::FkArgs;

pub fn run(args: &FkArgs) -> Result<u8, VerneError> {
    let machine = match load_mechanism(args.common.machine.as_deref())? {
        Mechanism::Glider(spec) => {
            refuse_for_glider(
                &spec.name,
                &[
                    ("--machine-joints", !args.machine_joints.is_empty()),
                    ("--tool-length", args.tool_length.is_some()),
                    ("--offset", args.offset.is_some()),
                ],
            )?;
            return super::glider::fk(args, spec);
        }
        Mechanism::Verne(m) => m,
    };
    crate::arg_values::spatial(&args.joints, "--joints", "R1,R2,R3").map_err(VerneError::Usage)?;
    let u = units(&args.common);
    let source = if !args.joints.is_empty() {
        inline_source(
            &["rho1", "rho2", "rho3"],
            args.joints.iter().map(|j| j.to_vec()).collect(),
        )
    } else if !args.machine_joints.is_empty() {
        inline_source(
            &["rho1", "rho2", "rho3", "theta1", "theta2"],
            args.machine_joints.iter().map(|j| j.to_vec()).collect(),
        )
    } else {
        let options = crate::toolpath::open::ReadOptions {
            cl: verne_cl::Options::default(),
            gcode: crate::input::gcode::options(
                verne_gcode::DEFAULT_CHORD_TOL_MM,
                None,
                &machine.gcode,
            ),
            words: machine.gcode,
        };
        let input = Input::open(args.input.as_deref(), None, &[Format::Csv, Format::Gcode])?;
        match input.format {
            Format::Gcode => joint_program(input, &options, args.common.radians)?,
            _ => input.into_csv()?,
        }
    };
    let table = source.column("theta1").is_some() || source.column("theta2").is_some();
    if table {
        let tool_length = args.tool_length.unwrap_or(machine.tool_length);
        let offset = args
            .offset
            .map_or(nalgebra::Vector3::zeros(), nalgebra::Vector3::from);
        let output = args.output.as_ref();
        if args.all {
            let mut job = MachineFkAll {
                machine,
                tool_length,
                offset,
            };
            run_rows("fk", &mut job, source, output, u)
        } else {
            let mut job = MachineFkWorking {
                machine,
                tool_length,
                offset,
            };
            run_rows("fk", &mut job, source, output, u)
        }
    } else {
        if args.offset.is_some() {
            return Err(VerneError::Usage(
                "--offset places tool poses: slider rows (rho1,rho2,rho3 without theta1,theta2) give platform points in the machine's frame".into(),
            ));
        }
        let output = args.output.as_ref();
        if args.all {
            run_rows("fk", &mut ModuleFkAll { machine }, source, output, u)
        } else {
            run_rows("fk", &mut ModuleFkWorking { machine }, source, output, u)
        }
    }
}

/// A G-code joint program's blocks as rows of machine joints (`line,rho1,rho2,rho3,theta1,
/// theta2`, angles in degrees unless `radians`), so that `verne fk` turns a post back into tool
/// poses.
fn joint_program(
    input: Input,
    options: &ReadOptions,
    radians: bool,
) -> Result<CsvSource, VerneError> {
    let name = input.name.clone();
    let shown = name.clone();
    let reader = input.into_gcode(options.gcode)?;
    let mut program = JointProgram::new(reader, &name, &options.words);
    let rows = std::iter::from_fn(move || match program.next_item() {
        Ok(None) => None,
        Err(e) => Some(Err(e)),
        Ok(Some(item)) => Some(
            item.value
                .map_err(|m| VerneError::input(&name, Some(item.line), None, m))
                .map(|q| {
                    let angle = |a: f64| if radians { a } else { a.to_degrees() };
                    (
                        item.line,
                        vec![
                            item.line as f64,
                            q.rho.x,
                            q.rho.y,
                            q.rho.z,
                            angle(q.theta1),
                            angle(q.theta2),
                        ],
                    )
                }),
        ),
    });
    Ok(CsvSource::from_number_rows(
        &["line", "rho1", "rho2", "rho3", "theta1", "theta2"],
        Box::new(rows),
        &shown,
    ))
}
