//! `verne verify`: a postprocessor's joint table against the intended path (docs/verify.md).
//! Opens the files, writes the report CSV atomically, prints the summary, picks the exit code.

use std::path::Path;

use crate::error::VerneError;
use crate::files::Sink;
use crate::input::recording::{DEFAULT_COLUMNS, RecordingReader, parse_columns};
use crate::input::verify_files::{JointInput, PathReader};
use crate::report::html::verify::{Inputs, VerifyHtml};
use crate::report::junit::JunitReport;
use crate::report::sarif::SarifReport;
use crate::report::verify::{short_number, summary_json, summary_text};
use crate::toolpath::ReaderReport;
use csv::ByteRecord;
use std::sync::Mutex;
use verne::verify::contour::{ContourPath, verify_recording_observed};
use verne::verify::{RowObservation, RowSource, Thresholds, VerifyOptions, verify_observed};

use super::{EXIT_OK, EXIT_ROWS_FAILED, load_machine, write_stdout};
use crate::cli::{VerifyArgs, VerifyFormat};

pub fn run(args: &VerifyArgs) -> Result<u8, VerneError> {
    let result = checked(args);
    if let (Err(e), VerifyFormat::Json) = (&result, args.format)
        && !e.is_broken_pipe()
    {
        // A script reading the JSON gets an object whatever happened.
        let _ = write_stdout(&format!("{}\n", crate::report::verify::error_json(e)));
    }
    result
}

fn checked(args: &VerifyArgs) -> Result<u8, VerneError> {
    let stdout = Path::new("-");
    let mut outputs: Vec<(&str, &Path)> = Vec::new();
    if let Some(r) = &args.report {
        outputs.push(("--report", r));
    }
    if let Some(s) = &args.summary {
        outputs.push(("--summary", s));
    }
    if args.format == VerifyFormat::Json {
        outputs.push(("--format json", stdout));
    }
    for (option, p) in [
        ("--html", &args.html),
        ("--junit", &args.junit),
        ("--sarif", &args.sarif),
    ] {
        if let Some(p) = p {
            outputs.push((option, p));
        }
    }
    crate::files::check_distinct_outputs(&outputs)?;
    let summary_to_stdout = args.summary.as_ref().is_some_and(|p| p.as_os_str() == "-");
    if summary_to_stdout && args.format == VerifyFormat::Json {
        return Err(VerneError::Usage(
            "--summary - and --format json both write stdout: give --summary a file".into(),
        ));
    }
    // The reports' files are checked before the run, written after it.
    let reports = [&args.html, &args.junit, &args.sarif];
    for p in reports.into_iter().flatten() {
        crate::files::check_output_path(p)
            .map_err(|e| VerneError::io(&p.display().to_string(), e))?;
    }
    let machine = load_machine(args.machine.as_deref())?;
    let machine_name = args
        .machine
        .as_ref()
        .map(|p| p.display().to_string())
        .unwrap_or_else(|| "<default>".into());
    let mut thresholds = Thresholds::from_machine(&machine, &machine_name)?;
    for (name, value) in &args.threshold {
        thresholds
            .set(name, *value)
            .map_err(|e| VerneError::Usage(format!("--threshold {name}={value}: {e}")))?;
    }
    thresholds
        .check()
        .map_err(|e| VerneError::Usage(format!("thresholds: {e}")))?;
    let opt = VerifyOptions {
        thresholds,
        tool_length: args.tool_length.unwrap_or(machine.tool_length),
    };
    let options = args.part.read_options(&machine.gcode);
    let mut path = PathReader::open(&args.path, &options, args.part.offset())?;
    let mut recording = match (args.recording, args.period) {
        (true, Some(period)) => {
            let columns = parse_columns(args.columns.as_deref().unwrap_or(DEFAULT_COLUMNS))
                .map_err(|e| VerneError::Usage(format!("--columns: {e}")))?;
            Some((
                RecordingReader::open(&args.joints, columns, period)?,
                contour_path(&mut path)?,
            ))
        }
        _ => None,
    };
    let mut joints = match recording {
        Some(_) => None,
        None => Some(JointInput::open(&args.joints, &options)?),
    };
    let mut sink = match &args.report {
        Some(p) => {
            let mut s = Sink::create(Some(p))?;
            s.write(&ByteRecord::from(vec![
                "row",
                "check",
                "value",
                "limit",
                "detail",
                "joints_line",
                "path_line",
            ]))?;
            Some(s)
        }
        None => None,
    };
    let started = std::time::Instant::now();
    let html = args.html.as_ref().map(|_| Mutex::new(VerifyHtml::new()));
    let mut junit = args.junit.as_ref().map(|_| JunitReport::new());
    let mut sarif = args.sarif.as_ref().map(|_| SarifReport::new());
    let mut rec = ByteRecord::new();
    let mut observe = |o: &RowObservation| {
        if let Some(h) = &html {
            h.lock().expect("one writer").observe(o);
        }
    };
    let observer: Option<verne::verify::Observer<'_>> = match &html {
        Some(_) => Some(&mut observe),
        None => None,
    };
    let mut write = |v: &verne::verify::Violation| -> Result<(), VerneError> {
        if let Some(h) = &html {
            h.lock().expect("one writer").finding(v);
        }
        if let Some(j) = junit.as_mut() {
            j.finding(v);
        }
        if let Some(s) = sarif.as_mut() {
            s.finding(v);
        }
        if let Some(s) = sink.as_mut() {
            rec.clear();
            rec.push_field(v.row.as_bytes());
            rec.push_field(v.check.code().as_bytes());
            rec.push_field(short_number(v.value).as_bytes());
            rec.push_field(short_number(v.limit).as_bytes());
            rec.push_field(v.detail.as_bytes());
            let line = |l: Option<u64>| l.map_or(String::new(), |l| l.to_string());
            rec.push_field(line(v.joints_line).as_bytes());
            rec.push_field(line(v.path_line).as_bytes());
            s.write(&rec)?;
        }
        Ok(())
    };
    let summary = match (&mut joints, recording.take()) {
        (Some(j), _) => verify_observed(&machine, &opt, j, &mut path, &mut write, observer),
        (None, Some((mut r, contour))) => {
            let name = args.path.display().to_string();
            verify_recording_observed(&machine, &opt, &mut r, contour, &name, &mut write, observer)
        }
        (None, None) => unreachable!("one joint input is open"),
    };
    let summary = match summary {
        Ok(s) => s,
        Err(e) => {
            if let Some(s) = sink.as_mut() {
                s.discard();
            }
            return Err(e);
        }
    };
    if let Some(s) = sink {
        s.finish()?;
    }
    match path.report() {
        ReaderReport::Cl(s) => {
            crate::toolpath::cl::report_summary("verify", path.name(), &s, opt.tool_length)
        }
        ReaderReport::Gcode(s) => crate::input::gcode::report_summary("verify", path.name(), &s),
        ReaderReport::Nothing => {}
    }
    if let Some((name, s)) = joints.as_ref().and_then(|j| j.gcode_summary()) {
        crate::input::gcode::report_summary("verify", name, s);
    }
    let text = format!(
        "verne verify: {} against {}: {}",
        args.joints.display(),
        args.path.display(),
        summary_text(&summary)
    );
    match &args.summary {
        None => say!("{text}"),
        Some(p) if p.as_os_str() == "-" => write_stdout(&text)?,
        Some(p) => {
            let mut s = Sink::create(Some(p))?;
            s.write_encoded(text.as_bytes())?;
            s.finish()?;
        }
    }
    let inputs = Inputs {
        joints: &args.joints,
        path: &args.path,
        recording: args.recording,
        machine: &machine_name,
    };
    let seconds = started.elapsed().as_secs_f64();
    if let (Some(p), Some(h)) = (&args.html, html) {
        let page = h
            .into_inner()
            .expect("one writer")
            .render(&machine, &opt, &summary, &inputs, p);
        write_report(p, page.as_bytes())?;
    }
    if let (Some(p), Some(j)) = (&args.junit, junit) {
        write_report(p, j.render(&summary, &inputs, seconds).as_bytes())?;
    }
    if let (Some(p), Some(s)) = (&args.sarif, sarif) {
        write_report(p, s.render(&summary, &inputs).as_bytes())?;
    }
    if args.format == VerifyFormat::Json {
        write_stdout(&format!("{}\n", summary_json(&summary)))?;
    }
    Ok(if summary.clean() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

/// Writes a report file atomically (a temporary file renamed into place).
fn write_report(path: &Path, bytes: &[u8]) -> Result<(), VerneError> {
    crate::files::write_output(path, bytes)
        .map_err(|e| VerneError::io(&path.display().to_string(), e))
}

/// The whole intended path, for the nearest-point pairing of a recording: a path row that
/// cannot be used is fatal here (there is no joint row to report it with).
fn contour_path(path: &mut PathReader) -> Result<ContourPath, VerneError> {
    let mut points = Vec::new();
    while let Some(item) = path.next_item()? {
        match item.value {
            Ok(p) => points.push(p),
            Err(e) => {
                return Err(VerneError::input(
                    path.name(),
                    Some(item.line),
                    None,
                    format!("{e}: a recording is compared with every point of the path"),
                ));
            }
        }
    }
    if points.is_empty() {
        return Err(VerneError::input(
            path.name(),
            None,
            None,
            "no path points: a recording needs the path it follows",
        ));
    }
    Ok(ContourPath::new(points))
}
