//! `verne ik`: tool poses (workpiece frame) -> machine joints along a toolpath, from a CSV, a CL
//! file, a tool-centre G-code program or the command line; or platform points -> joints of the
//! parallel module (IFToMM 2007, section V).

use std::path::Path;

use crate::engine::module_rows::{ModuleIkAll, ModuleIkWorking};
use crate::error::VerneError;
use crate::follow::post::{Post, PostOptions, PostReport, ScheduleLine};
use crate::follow::write::{CsvRows, GcodeProgram, Halstreamer};
use crate::follow::{FollowOptions, Follower, RowSink};
use crate::table::CsvSource;
use crate::toolpath::columns::TableKind;
use crate::toolpath::csv::CsvToolpath;
use crate::toolpath::gcode::TcpToolpath;
use crate::toolpath::inline::InlineToolpath;
use crate::toolpath::lookahead::Lookahead;
use crate::toolpath::open::{Format, Input};
use crate::toolpath::resample::Resampler;
use crate::toolpath::{ReaderReport, ToolpathSource};
use verne::machine::{FirstRowChoice, first_decided_theta2};
use verne::post::linearize::Tolerances;
use verne::post::schedule::{Limiting, Limits};
use verne::spec::Machine;
use verne::verify::{JOINT_NAMES, Th, Thresholds};

use super::{
    EXIT_OK, EXIT_ROWS_FAILED, Mechanism, inline_source, load_mechanism, progress_bar,
    refuse_for_glider, report, run_rows, units,
};
use crate::cli::{IkArgs, InputFormat, OutputFormat, Prefer};

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
    let program = match args.format {
        OutputFormat::Csv => None,
        OutputFormat::Halstreamer => Some("halstreamer"),
        OutputFormat::Gcode => Some("gcode"),
    };
    if let Some(format) = program {
        if args.common.radians || args.common.precision.is_some() {
            return Err(VerneError::Usage(format!(
                "--format {format} writes degrees and mm as LinuxCNC reads them: drop --radians and --precision"
            )));
        }
        if args.all {
            return Err(VerneError::Usage(format!(
                "--format {format} writes one joint row per pose; it cannot be combined with --all"
            )));
        }
        if args.linearize {
            return Err(VerneError::Usage(format!(
                "--format {format} is linearized by default (--no-linearize turns it off); --linearize is for CSV output"
            )));
        }
    } else if args.no_linearize {
        return Err(VerneError::Usage(
            "--no-linearize is for --format gcode and halstreamer; CSV output is not linearized unless --linearize".into(),
        ));
    }
    if args.all && args.linearize {
        return Err(VerneError::Usage(
            "--linearize follows one branch; it cannot be combined with --all".into(),
        ));
    }
    if args.schedule_report.is_some() && args.format != OutputFormat::Gcode {
        return Err(VerneError::Usage(
            "--schedule-report reports the block times of a joint program: it goes with --format gcode".into(),
        ));
    }
    crate::arg_values::spatial(&args.pose, "--pose", "XP,YP,ZP").map_err(VerneError::Usage)?;
    if let (Some(o), Some(r)) = (&args.output, &args.schedule_report) {
        crate::files::check_distinct_outputs(&[("-o", o), ("--schedule-report", r)])?;
    }
    if !args.pose.is_empty() {
        let source = inline_source(
            &["xp", "yp", "zp"],
            args.pose.iter().map(|p| p.to_vec()).collect(),
        );
        return module_ik(args, machine, source, program);
    }
    let source: Box<dyn ToolpathSource> = if !args.tool.is_empty() {
        if args.period.is_some() {
            return Err(VerneError::Usage(
                "--period times each move by its feed, and --tool poses have none: give the path as a CSV with a `feed` column, a CL file or a program".into(),
            ));
        }
        Box::new(InlineToolpath::new(&args.tool))
    } else {
        let force = args.input_format.map(|f| match f {
            InputFormat::Csv => Format::Csv,
            InputFormat::Apt => Format::Cl,
            InputFormat::Gcode => Format::Gcode,
        });
        let options = args.part.read_options(&machine.gcode);
        let input = Input::open(
            args.input.as_deref(),
            force,
            &[Format::Csv, Format::Cl, Format::Gcode],
        )?;
        match input.format {
            Format::Cl => Box::new(input.into_cl(options.cl)?),
            Format::Gcode => {
                let name = input.name.clone();
                let reader = input.into_gcode(options.gcode)?;
                Box::new(TcpToolpath::new(reader, &name, &machine.gcode))
            }
            Format::Csv => {
                let csv = input.into_csv()?;
                let kind = TableKind::detect(|c| csv.column(c).is_some())
                    .map_err(|m| VerneError::input(csv.name(), Some(1), None, m))?;
                if kind != TableKind::ToolPoses {
                    if args.period.is_some() {
                        return Err(VerneError::Usage(
                            "--period resamples a toolpath of tool poses (x,y,z with i,j,k or phi1,phi2), not platform points".into(),
                        ));
                    }
                    return module_ik(args, machine, csv, program);
                }
                if args.period.is_some()
                    && csv.column("feed").is_none()
                    && csv.column("dt").is_none()
                {
                    return Err(VerneError::input(
                        csv.name(),
                        Some(1),
                        None,
                        "--period times each move by its feed: a CSV toolpath needs a `feed` column (mm/min) or a `dt` column (s)",
                    ));
                }
                Box::new(CsvToolpath::new(csv, args.common.radians)?)
            }
        }
    };
    follow_path(args, machine, source, program)
}

/// `verne ik` on platform points: the parallel module alone.
fn module_ik(
    args: &IkArgs,
    machine: Machine,
    source: CsvSource,
    program: Option<&str>,
) -> Result<u8, VerneError> {
    if args.part.offset.is_some() {
        return Err(VerneError::Usage(
            "--offset places tool poses (x,y,z): platform points (xp,yp,zp) are already in the machine's frame".into(),
        ));
    }
    if let Some(format) = program {
        return Err(VerneError::Usage(format!(
            "--format {format} writes machine joints: give tool poses (x,y,z with i,j,k or phi1,phi2), not platform points"
        )));
    }
    let output = args.output.as_ref();
    let u = units(&args.common);
    if args.all {
        run_rows("ik", &mut ModuleIkAll { machine }, source, output, u)
    } else {
        run_rows("ik", &mut ModuleIkWorking { machine }, source, output, u)
    }
}

/// `verne ik` on a toolpath: resampled at the servo period when asked, read ahead to the first
/// decided orientation, followed, written.
fn follow_path(
    args: &IkArgs,
    machine: Machine,
    source: Box<dyn ToolpathSource>,
    program: Option<&str>,
) -> Result<u8, VerneError> {
    let tool_length = args.tool_length.unwrap_or(machine.tool_length);
    let offset = args.part.offset();
    let source: Box<dyn ToolpathSource> = match args.period {
        Some(period) => {
            let rapid = args.rapid;
            Box::new(Resampler::new(source, period, rapid))
        }
        None => source,
    };
    let first = match args.prefer {
        Prefer::SmallestTheta1 => FirstRowChoice::SmallestTheta1,
        Prefer::Orientation1 => FirstRowChoice::Orientation1,
        Prefer::Orientation2 => FirstRowChoice::Orientation2,
    };
    // A path that starts with the tool vertical: its orientation is decided further on; read
    // ahead to there first, so that --prefer is honoured and theta2 does not swing.
    let (seed_theta2, mut source) = if args.all {
        (None, Lookahead::read(source, offset, |_| None::<f64>).1)
    } else {
        Lookahead::read(source, offset, |poses| {
            first_decided_theta2(&machine, poses, tool_length, first)
        })
    };
    let output = args.output.as_deref();
    let u = units(&args.common);
    let mut sink: Box<dyn RowSink> = match args.format {
        OutputFormat::Csv => Box::new(CsvRows::create(output, u, args.all)?),
        OutputFormat::Halstreamer => Box::new(Halstreamer::create(output, u)?),
        OutputFormat::Gcode => {
            Box::new(GcodeProgram::create(output, machine.gcode, source.name())?)
        }
    };
    let machine_for_travel = machine.clone();
    let name = args
        .common
        .machine
        .as_ref()
        .map_or("<default>".to_string(), |p| p.display().to_string());
    let thresholds = Thresholds::from_machine(&machine, &name)?;
    let linearize = (args.linearize
        || (program.is_some() && !args.no_linearize && args.period.is_none()))
    .then(|| Tolerances {
        tip_mm: args
            .part
            .chord_tol
            .unwrap_or(thresholds.get(Th::ChordErrorMm)),
        axis_rad: args
            .axis_tol
            .unwrap_or(thresholds.get(Th::ChordAxisErrorDeg))
            .to_radians(),
    });
    let schedule = (args.format == OutputFormat::Gcode).then(|| Limits::of(&machine.drives));
    let post_machine = machine.clone();
    let mut post = (linearize.is_some() || schedule.is_some()).then(|| {
        let mut p = Post::new(
            &post_machine,
            tool_length,
            offset,
            PostOptions {
                linearize,
                schedule,
            },
        );
        if args.schedule_report.is_some() {
            p.schedule_lines = Some(Vec::new());
        }
        p
    });
    let mut follower = Follower::new(FollowOptions {
        machine,
        tool_length,
        offset,
        all: args.all,
        first,
        seed_theta2,
        period: args.period,
    });
    let bar = progress_bar();
    let tick = |n: u64| {
        if let Some(b) = &bar {
            b.set_position(n);
        }
    };
    let started = std::time::Instant::now();
    let result = crate::follow::run(
        &mut source,
        &mut follower,
        post.as_mut(),
        sink.as_mut(),
        &tick,
    );
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let Err(mut e) = result {
        sink.discard();
        let input = match &mut e {
            VerneError::RowFailed(inner) => inner.as_mut(),
            other => other,
        };
        if let (Some(_), true, VerneError::Input { message, .. }) =
            (program, to_stdout(output), input)
        {
            // A file is never left partial; a pipe may have received the rows before.
            message.push_str(
                "; the rows before it went to stdout as they were solved: that list is incomplete, do not play it (-o FILE writes nothing on such an error)",
            );
        }
        return Err(e);
    }
    let not_linearized = post
        .as_ref()
        .is_some_and(|p| !p.report.not_linearized.is_empty());
    if not_linearized && program.is_some() {
        // Never a silently worse program: nothing is written, the moves are named.
        sink.discard();
    } else {
        sink.finish()?;
    }
    let name = source.name().to_string();
    if let Some(p) = &mut post {
        if let (Some(path), Some(lines)) = (&args.schedule_report, p.schedule_lines.take()) {
            write_schedule_report(path, &lines)?;
        }
        report_post("ik", &name, &p.report, program.is_some());
    }
    let summary = &follower.summary;
    report("ik", &name, summary);
    let cam_job = match source.report() {
        ReaderReport::Cl(s) => {
            crate::toolpath::cl::report_summary("ik", &name, &s, tool_length);
            true
        }
        ReaderReport::Gcode(s) => {
            crate::input::gcode::report_summary("ik", &name, &s);
            true
        }
        ReaderReport::Nothing => false,
    };
    // A CAM job (a CL file or a program): where the joints went, against the limits.
    if cam_job && follower.travel.rows > 0 {
        sayln!("verne ik: {}", follower.travel.line(&machine_for_travel));
    }
    if args.format == OutputFormat::Halstreamer && args.period.is_none() {
        sayln!(
            "verne ik: note: one row per path point, not per servo period (halstreamer plays one row per period: --period 1ms plays the path at its feeds)"
        );
    }
    let seconds = started.elapsed().as_secs_f64();
    sayln_verbose!(
        "verne ik: {name}: {} rows in, {} rows out, {} ok, in {seconds:.3} s ({:.0} rows/s)",
        summary.input_rows,
        summary.output_rows,
        summary.ok_rows,
        summary.input_rows as f64 / seconds.max(1e-9)
    );
    Ok(if summary.all_ok() && !not_linearized {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

/// The post's summary on stderr: the blocks inserted, the cycle time against the feeds' alone,
/// the blocks the drives slowed, and every move that could not be linearized.
fn report_post(cmd: &str, name: &str, r: &PostReport, program: bool) {
    if r.inserted > 0 || !r.not_linearized.is_empty() {
        sayln!(
            "verne {cmd}: {name}: linearized: {}, {} inserted",
            counted(r.rows, "row", "rows"),
            counted(r.inserted, "pose", "poses")
        );
    }
    if r.timed_blocks > 0 {
        sayln!(
            "verne {cmd}: {name}: scheduled: {} in {:.3} s ({:.3} s at the programmed feeds alone); {} slowed by the drives' limits",
            counted(r.timed_blocks, "feed block", "feed blocks"),
            r.time_s,
            r.feed_time_s,
            counted(r.slowed, "block", "blocks")
        );
    }
    for (line, why) in &r.not_linearized {
        sayln!("verne {cmd}: {name}:{line}: not linearized: {why}");
    }
    if !r.not_linearized.is_empty() && program {
        sayln!(
            "verne {cmd}: {name}: no program written: {} linearized within the tolerances (exit 1)",
            match r.not_linearized.len() {
                1 => "1 move cannot be".to_string(),
                n => format!("{n} moves cannot be"),
            }
        );
    }
}

/// `n` with its noun, singular for one.
fn counted(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// Writes the schedule report (CSV, atomically).
fn write_schedule_report(path: &Path, lines: &[ScheduleLine]) -> Result<(), VerneError> {
    let mut text = String::from("block,line,limit,share,feed_time_s,time_s\n");
    for l in lines {
        let limit = match l.limit {
            Limiting::Feed => "feed".to_string(),
            Limiting::Velocity(j) => format!("{}_velocity", JOINT_NAMES[j]),
            Limiting::Acceleration(j) => format!("{}_acceleration", JOINT_NAMES[j]),
        };
        text.push_str(&format!(
            "{},{},{limit},{:.6},{},{}\n",
            l.block, l.line, l.share, l.feed_time_s, l.time_s
        ));
    }
    crate::files::check_output_path(path)
        .and_then(|_| crate::files::write_output(path, text.as_bytes()))
        .map_err(|e| VerneError::io(&path.display().to_string(), e))
}

/// Whether the output goes to stdout.
fn to_stdout(output: Option<&Path>) -> bool {
    output.is_none_or(|p| p.as_os_str() == "-")
}
