//! `verne calibrate`: a machine file calibrated from measurement files, with the report of what
//! they determine; `verne calibrate plan`: the poses to measure. The core computes
//! ([`verne::calibrate`]); this reads the files, writes the machine file, the report and the
//! summary, and picks the exit code.

use std::path::{Component, Path, PathBuf};

use csv::ByteRecord;
use nalgebra::Vector3;

use verne::calibrate::model::{DEFAULT_NOISE, Noise};
use verne::calibrate::plan::{PlanOptions, plan};
use verne::calibrate::{
    Calibration, CalibrationError, Device, Measurement, Observed, Options, Param, calibrate,
};
use verne::parallel_module::equations::Sliders;
use verne::spec::Machine;

use super::{EXIT_OK, EXIT_ROWS_FAILED, load_machine};
use crate::cli::{
    CalibrateArgs, CalibrateCommand, CalibrateFitArgs, CalibratePlanArgs, CalibrationDevice,
};
use crate::error::VerneError;
use crate::files::Sink;
use crate::table::{CellError, CsvSource, TableRow, format_number, parse_number};

/// Parses a prior bound `KEY=BOUND` (a machine-file key a calibration can move, a positive
/// bound in mm or degrees).
pub fn parse_prior(s: &str) -> Result<(String, f64), String> {
    let Some((key, value)) = s.split_once('=') else {
        return Err(format!(
            "expected KEY=BOUND like module.L1=2, found `{}`",
            verne::error::shown(s.as_bytes())
        ));
    };
    let key = key.trim();
    if Param::from_key(key).is_none() {
        return Err(format!(
            "`{}` is not a key a calibration moves; {}",
            verne::error::shown(key.as_bytes()),
            known_keys()
        ));
    }
    match value.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok((key.to_string(), v)),
        _ => Err(format!(
            "`{}` is not a positive bound",
            verne::error::shown(value.as_bytes())
        )),
    }
}

fn known_keys() -> String {
    let keys: Vec<&str> = verne::calibrate::params::ALL
        .iter()
        .map(|p| p.key())
        .collect();
    format!("the keys are {}", keys.join(", "))
}

/// The parameters named by `--free` or `--fixed`.
fn keys_of(list: &[String], option: &str) -> Result<Vec<Param>, VerneError> {
    list.iter()
        .filter(|k| !k.trim().is_empty())
        .map(|k| {
            Param::from_key(k.trim()).ok_or_else(|| {
                VerneError::Usage(format!(
                    "{option} {}: not a key a calibration moves; {}",
                    verne::error::shown(k.as_bytes()),
                    known_keys()
                ))
            })
        })
        .collect()
}

/// The fit's options from the command line.
fn options_of(fit: &CalibrateFitArgs) -> Result<Options, VerneError> {
    let priors = fit
        .prior
        .iter()
        .map(|(k, v)| {
            let p = Param::from_key(k).expect("checked by parse_prior");
            (p, p.stored(*v))
        })
        .collect();
    Ok(Options {
        free: keys_of(&fit.free, "--free")?,
        fixed: keys_of(&fit.fixed, "--fixed")?,
        noise: noise_of(fit),
        folds: fit.folds as usize,
        priors,
        allow_large: fit.allow_large,
    })
}

fn noise_of(fit: &CalibrateFitArgs) -> Noise {
    Noise {
        length_mm: fit.noise,
        axis_rad: fit.noise_axis,
    }
}

pub fn run(args: &CalibrateArgs) -> Result<u8, VerneError> {
    if let Some(CalibrateCommand::Plan(p)) = &args.plan {
        return run_plan(p);
    }
    let machine_path = args.common.machine.as_deref();
    let output = args.output.as_deref().expect("required by clap");
    if let Some(r) = &args.report {
        crate::files::check_distinct_outputs(&[("-o", output), ("--report", r)])?;
    }
    // The calibrated file names the nominal as its base and must not replace it or a reading.
    let inputs = machine_path
        .map(|m| ("-m", m))
        .into_iter()
        .chain(args.measurements.iter().map(|p| ("MEAS.csv", p.as_path())));
    for (option, input) in inputs {
        crate::files::check_distinct_outputs(&[("-o", output), (option, input)]).map_err(|_| {
            VerneError::Usage(format!(
                "-o {} is the input {option} {}: the calibrated file needs a file of its own",
                output.display(),
                input.display()
            ))
        })?;
    }
    let nominal = load_machine(machine_path)?;
    let options = options_of(&args.fit)?;
    let radians = args.common.radians;
    let mut rows = Vec::new();
    for (set, path) in args.measurements.iter().enumerate() {
        rows.extend(read_measurements(path, set, radians)?);
    }
    let names: Vec<String> = args
        .measurements
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let started = std::time::Instant::now();
    let result = calibrate(&nominal, &rows, &options);
    let seconds = started.elapsed().as_secs_f64();
    let c = match result {
        Ok(c) => c,
        Err(e) => return refused(&names, &rows, e),
    };
    sayln_verbose!(
        "verne calibrate: {} rows in {seconds:.3} s: {} complete and {} followed forward kinematics, {} iterations",
        c.rows,
        c.fk_complete,
        c.fk_followed,
        c.iterations
    );
    let base = base_of(machine_path, output);
    let command = format!(
        "verne calibrate {}{}",
        names.join(" "),
        machine_path.map_or(String::new(), |p| format!(" -m {}", p.display()))
    );
    let header = header_of(&c, &command);
    let text = c.machine_file(&base, &header);
    // The file as written must read back as a valid machine over its base.
    check_written(&text, machine_path, output)?;
    crate::files::write_output(output, text.as_bytes())
        .map_err(|e| VerneError::io(&output.display().to_string(), e))?;
    if let Some(report) = &args.report {
        write_report(report, &c, args.common.precision.map(usize::from))?;
    }
    summary(&c, &names, output, &base);
    Ok(EXIT_OK)
}

/// A calibration refused: the rows with their files and lines (exit 1), or a fatal error.
fn refused(names: &[String], rows: &[Measurement], e: CalibrationError) -> Result<u8, VerneError> {
    let file_of = |line: u64| {
        rows.iter()
            .find(|r| r.line == line)
            .map_or(names[0].as_str(), |r| names[r.set].as_str())
    };
    match e {
        CalibrationError::Rows(problems) => {
            sayln!(
                "verne calibrate: {} row{} cannot be used; no machine file written",
                problems.len(),
                if problems.len() == 1 { "" } else { "s" }
            );
            for p in &problems {
                sayln!("  {}:{}: {}", file_of(p.line), p.line, p.message);
            }
            Ok(EXIT_ROWS_FAILED)
        }
        e @ (CalibrationError::Prior(_) | CalibrationError::Invalid(_)) => {
            sayln!("verne calibrate: {e}\n  no machine file written");
            Ok(EXIT_ROWS_FAILED)
        }
        CalibrationError::TooFew { .. } | CalibrationError::Input(_) => Err(VerneError::input(
            &names.join(", "),
            None,
            None,
            e.to_string(),
        )),
    }
}

/// How the calibrated file names its base: the nominal machine file's path relative to the
/// output's folder (absolute when there is no such path), or `verne`.
fn base_of(machine: Option<&Path>, output: &Path) -> String {
    let Some(m) = machine else {
        return "verne".into();
    };
    if !m.exists() && m.as_os_str() == "verne" {
        return "verne".into();
    }
    let abs = |p: &Path| std::path::absolute(p).ok().map(|p| normalised(&p));
    let dir = output
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    match (abs(m), abs(dir)) {
        (Some(target), Some(from)) => relative(&target, &from).display().to_string(),
        _ => m.display().to_string(),
    }
}

/// The path without `.` and with `..` applied.
fn normalised(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `target` as seen from the folder `from` (both absolute).
fn relative(target: &Path, from: &Path) -> PathBuf {
    let t: Vec<_> = target.components().collect();
    let f: Vec<_> = from.components().collect();
    let common = t.iter().zip(&f).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out
}

/// The calibrated file read back as `load_machine` reads it from where it will be written.
fn check_written(text: &str, machine: Option<&Path>, output: &Path) -> Result<(), VerneError> {
    let dir = output.parent().map(Path::to_path_buf).unwrap_or_default();
    let resolve = |base: &str| -> Result<(String, String), String> {
        let path = dir.join(base);
        std::fs::read_to_string(&path)
            .map(|t| (t, path.display().to_string()))
            .map_err(|e| format!("base {}: {e}", path.display()))
    };
    let _ = machine;
    Machine::from_str_on_base(text, &output.display().to_string(), Some(&resolve))
        .map(|_| ())
        .map_err(VerneError::from)
}

/// The comment at the head of the calibrated file: where it came from.
fn header_of(c: &Calibration, command: &str) -> String {
    let mut h = format!(
        "Calibrated by `{command}`:\n{} rows ({} readings) of {}; residual RMS {:.4} mm with the nominal machine, {:.4} mm calibrated",
        c.rows,
        c.readings,
        c.devices
            .iter()
            .map(|d| d.name())
            .collect::<Vec<_>>()
            .join(" and "),
        c.before.rms_mm,
        c.after.rms_mm
    );
    if let Some(h2) = &c.holdout {
        h.push_str(&format!(", {:.4} mm on held-out rows", h2.rms_mm));
    }
    h.push_str(".\nHeld at nominal (the readings cannot determine them):");
    if c.identifiability.held.is_empty() && c.weak.is_empty() {
        h.push_str(" none.");
    }
    for held in &c.identifiability.held {
        h.push_str(&format!("\n  {}: {}", held.param.key(), held.why));
    }
    for w in &c.weak {
        h.push_str(&format!(
            "\n  {}: 1 sigma {:.4} {u} beyond its prior bound {} {u}",
            w.param.key(),
            w.param.shown(w.sigma),
            w.param.shown(w.bound),
            u = w.param.unit()
        ));
    }
    h.push_str("\nEach key below: the calibrated value, its change from nominal and its 1 sigma.");
    h
}

/// The summary on stderr.
fn summary(c: &Calibration, names: &[String], output: &Path, base: &str) {
    sayln!(
        "verne calibrate: {}: {} rows, {} readings ({})",
        names.join(", "),
        c.rows,
        c.readings,
        c.devices
            .iter()
            .map(|d| d.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let identified = c.estimates.iter().filter(|e| e.sigma.is_some()).count();
    sayln!(
        "  {identified} parameters identified, {} held at nominal",
        c.estimates.len() - identified
    );
    sayln!(
        "  residual RMS {:.4} mm before, {:.4} mm after (largest {:.4}, {:.4} mm); noise {:.4} mm",
        c.before.rms_mm,
        c.after.rms_mm,
        c.before.max_mm,
        c.after.max_mm,
        c.noise_mm
    );
    if let (Some(b), Some(a)) = (c.before.rms_axis_rad, c.after.rms_axis_rad) {
        sayln!("  tool axis RMS {:.3e} rad before, {:.3e} rad after", b, a);
    }
    match &c.holdout {
        Some(h) => sayln!(
            "  hold-out RMS {:.4} mm (largest {:.4} mm): each fold's rows predicted by a fit of the others",
            h.rms_mm,
            h.max_mm
        ),
        None => sayln!("  no hold-out: too few rows for its folds"),
    }
    if !c.identifiability.held.is_empty() || !c.weak.is_empty() {
        sayln!("  held at nominal, the readings cannot determine them:");
        for h in &c.identifiability.held {
            sayln!("    {}: {}", h.param.key(), h.why);
        }
        for w in &c.weak {
            sayln!(
                "    {}: 1 sigma {:.4} {u} beyond its prior bound {} {u}",
                w.param.key(),
                w.param.shown(w.sigma),
                w.param.shown(w.bound),
                u = w.param.unit()
            );
        }
    }
    sayln!("  identified: value, change from nominal, 1 sigma");
    for e in &c.estimates {
        let Some(s) = e.sigma else { continue };
        let p = e.param;
        sayln!(
            "    {:<13} {:>11.4} {:>+9.4} {:>8.4} {}",
            p.key(),
            p.shown(e.value),
            p.shown(e.value - e.nominal),
            p.shown(s),
            p.unit()
        );
    }
    if !c.correlations.is_empty() {
        let pairs: Vec<String> = c
            .correlations
            .iter()
            .map(|(a, b, r)| format!("{a} ~ {b} ({r:+.3})"))
            .collect();
        sayln!("  correlated beyond 0.95: {}", pairs.join(", "));
    }
    sayln!("  wrote {} (base = {base:?})", output.display());
}

/// The report CSV: item,key,unit,nominal,value,change,sigma,detail.
fn write_report(path: &Path, c: &Calibration, decimals: Option<usize>) -> Result<(), VerneError> {
    let mut sink = Sink::create(Some(path))?;
    let num = |v: f64| {
        let mut out = Vec::new();
        format_number(&mut out, v, decimals);
        out
    };
    let mut write = |cells: [Vec<u8>; 8]| -> Result<(), VerneError> {
        let rec: ByteRecord = cells.iter().map(|c| c.as_slice()).collect();
        sink.write(&rec)
    };
    let t = |s: &str| s.as_bytes().to_vec();
    let written = (|| -> Result<(), VerneError> {
        write([
            t("item"),
            t("key"),
            t("unit"),
            t("nominal"),
            t("value"),
            t("change"),
            t("sigma"),
            t("detail"),
        ])?;
        for e in &c.estimates {
            let p = e.param;
            let detail = match (
                e.sigma,
                c.identifiability.held.iter().find(|h| h.param == p),
            ) {
                (Some(_), _) => "identified".to_string(),
                (None, Some(h)) => format!("held at nominal: {}", h.why),
                (None, None) => c.weak.iter().find(|w| w.param == p).map_or(
                    "held at nominal".to_string(),
                    |w| {
                        format!(
                            "held at nominal: 1 sigma {:.4} {u} beyond its prior bound {} {u}",
                            p.shown(w.sigma),
                            p.shown(w.bound),
                            u = p.unit()
                        )
                    },
                ),
            };
            write([
                t("parameter"),
                t(p.key()),
                t(p.unit()),
                num(p.shown(e.nominal)),
                num(p.shown(e.value)),
                num(p.shown(e.value - e.nominal)),
                e.sigma.map_or(Vec::new(), |s| num(p.shown(s))),
                t(&detail),
            ])?;
        }
        for h in &c.identifiability.held {
            let comb: Vec<String> = h
                .combination
                .iter()
                .map(|(p, k)| format!("{} {:+}", p.key(), k))
                .collect();
            write([
                t("combination"),
                t(h.param.key()),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                t(&format!("{}; moves {}", h.why, comb.join(", "))),
            ])?;
        }
        for (n, value, sigma) in &c.instrument_estimates {
            let (unit, k) = if n.which.is_angle() {
                ("deg", 180.0 / std::f64::consts::PI)
            } else {
                ("mm", 1.0)
            };
            write([
                t("instrument"),
                t(&n.key(c.devices.len())),
                t(unit),
                Vec::new(),
                num(value * k),
                Vec::new(),
                num(sigma * k),
                t(if n.which.is_angle() {
                    "the frame's rotation vector (R = exp([r]), y = R x + t)"
                } else {
                    ""
                }),
            ])?;
        }
        for (a, b, r) in &c.correlations {
            write([
                t("correlation"),
                t(&format!("{a}/{b}")),
                Vec::new(),
                Vec::new(),
                num(*r),
                Vec::new(),
                Vec::new(),
                Vec::new(),
            ])?;
        }
        let mut residual = |key: &str, v: f64, unit: &str| {
            write([
                t("residual"),
                t(key),
                t(unit),
                Vec::new(),
                num(v),
                Vec::new(),
                Vec::new(),
                Vec::new(),
            ])
        };
        residual("rms_before", c.before.rms_mm, "mm")?;
        residual("max_before", c.before.max_mm, "mm")?;
        residual("rms_after", c.after.rms_mm, "mm")?;
        residual("max_after", c.after.max_mm, "mm")?;
        if let Some(h) = &c.holdout {
            residual("rms_holdout", h.rms_mm, "mm")?;
            residual("max_holdout", h.max_mm, "mm")?;
        }
        residual("noise", c.noise_mm, "mm")?;
        if let (Some(b), Some(a)) = (c.before.rms_axis_rad, c.after.rms_axis_rad) {
            residual("axis_rms_before", b, "rad")?;
            residual("axis_rms_after", a, "rad")?;
        }
        for (k, s) in c.identifiability.singular_values.iter().enumerate() {
            write([
                t("singular_value"),
                t(&(k + 1).to_string()),
                Vec::new(),
                Vec::new(),
                num(*s),
                Vec::new(),
                Vec::new(),
                t(if *s > verne::calibrate::identifiability::RANK_TOL {
                    "determined"
                } else {
                    "not determined"
                }),
            ])?;
        }
        Ok(())
    })();
    match written {
        Ok(()) => sink.finish(),
        Err(e) => {
            sink.discard();
            Err(e)
        }
    }
}

/// The columns a measurement file may have, by device.
const DEVICE_COLUMNS: &[(&[&str], Device)] = &[
    (&["x", "y", "z"], Device::Tracker),
    (&["xp", "yp", "zp"], Device::Platform),
    (&["distance"], Device::Ballbar),
    (&["height"], Device::Probe),
];

/// Reads one measurement file as data set `set`.
fn read_measurements(
    path: &Path,
    set: usize,
    radians: bool,
) -> Result<Vec<Measurement>, VerneError> {
    let mut src = CsvSource::open(Some(path))?;
    let name = src.name().to_string();
    let joints = src.require(&["rho1", "rho2", "rho3"])?;
    let found: Vec<(&[&str], Device)> = DEVICE_COLUMNS
        .iter()
        .filter(|(cols, _)| cols.iter().all(|c| src.column(c).is_some()))
        .copied()
        .collect();
    let (cols, device) = match found.as_slice() {
        [one] => *one,
        [] => {
            return Err(VerneError::input(
                &name,
                Some(1),
                None,
                format!(
                    "no reading's columns: expected x,y,z (tracker, optionally i,j,k), xp,yp,zp (the module alone), distance (ballbar) or height (probe) besides rho1,rho2,rho3; found `{}`",
                    src.header_text()
                ),
            ));
        }
        several => {
            return Err(VerneError::input(
                &name,
                Some(1),
                None,
                format!(
                    "the readings of {} devices ({}): one device per file",
                    several.len(),
                    several
                        .iter()
                        .map(|(_, d)| d.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    };
    // Every column is known: a misspelt one is not silently left out.
    let known = [
        "rho1", "rho2", "rho3", "theta1", "theta2", "i", "j", "k", "id",
    ];
    for (k, h) in src.headers().iter().enumerate() {
        let h = String::from_utf8_lossy(h).to_ascii_lowercase();
        if !known.contains(&h.as_str()) && !cols.contains(&h.as_str()) {
            return Err(VerneError::input(
                &name,
                Some(1),
                Some(&src.header_name(k)),
                format!(
                    "unknown column; expected rho1,rho2,rho3, theta1,theta2, id and a device's readings ({})",
                    cols.join(",")
                ),
            ));
        }
    }
    let reading: Vec<usize> = cols.iter().map(|c| src.column(c).unwrap_or(0)).collect();
    let theta = match (src.column("theta1"), src.column("theta2")) {
        (Some(a), Some(b)) => Some([a, b]),
        (None, None) if device != Device::Ballbar => None,
        _ => {
            return Err(VerneError::input(
                &name,
                Some(1),
                None,
                if device == Device::Ballbar {
                    "a ballbar's rows need theta1,theta2 (the table's joints)"
                } else {
                    "theta1 and theta2 come together"
                },
            ));
        }
    };
    let axis = match (src.column("i"), src.column("j"), src.column("k")) {
        (Some(i), Some(j), Some(k)) if device == Device::Tracker => Some([i, j, k]),
        (None, None, None) => None,
        _ => {
            return Err(VerneError::input(
                &name,
                Some(1),
                None,
                "a tool axis is i,j,k, all three, with a tracker's x,y,z",
            ));
        }
    };
    let mut row = TableRow::default();
    let mut out = Vec::new();
    let angle = |v: f64| if radians { v } else { v.to_radians() };
    while src.read_row(&mut row)? {
        let line = row.line;
        let cell = |k: usize| -> Result<f64, VerneError> {
            let field = row.record.get(k).unwrap_or(b"");
            parse_number(field).map_err(|e| {
                VerneError::input(
                    &name,
                    Some(line),
                    Some(&src.header_name(k)),
                    match e {
                        CellError::NotANumber => format!(
                            "`{}` is not a number; expected a finite number",
                            verne::error::shown(field)
                        ),
                        CellError::NotFinite => format!(
                            "`{}`: expected a finite number (a measurement cannot be missing)",
                            verne::error::shown(field)
                        ),
                    },
                )
            })
        };
        let rho = Sliders::new(cell(joints[0])?, cell(joints[1])?, cell(joints[2])?);
        let th = match theta {
            Some([a, b]) => [angle(cell(a)?), angle(cell(b)?)],
            None => [0.0, 0.0],
        };
        let v = reading
            .iter()
            .map(|&k| cell(k))
            .collect::<Result<Vec<f64>, _>>()?;
        let observed = match device {
            Device::Tracker => Observed::Tip {
                tip: Vector3::new(v[0], v[1], v[2]),
                axis: match axis {
                    Some([i, j, k]) => {
                        let a = Vector3::new(cell(i)?, cell(j)?, cell(k)?);
                        let n = a.norm();
                        if !(n > 0.5 && n < 1.5) {
                            return Err(VerneError::input(
                                &name,
                                Some(line),
                                Some("i"),
                                format!(
                                    "the tool axis ({}, {}, {}) is not a unit vector",
                                    a.x, a.y, a.z
                                ),
                            ));
                        }
                        Some(a / n)
                    }
                    None => None,
                },
            },
            Device::Platform => Observed::Platform(Vector3::new(v[0], v[1], v[2])),
            Device::Ballbar => Observed::Distance(v[0]),
            Device::Probe => Observed::Height(v[0]),
        };
        out.push(Measurement {
            rho,
            theta: th,
            observed,
            set,
            line,
        });
    }
    Ok(out)
}

/// `verne calibrate plan`.
fn run_plan(args: &CalibratePlanArgs) -> Result<u8, VerneError> {
    if let (Some(o), Some(r)) = (&args.output, &args.report) {
        crate::files::check_distinct_outputs(&[("-o", o), ("--report", r)])?;
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let device = match args.device {
        CalibrationDevice::Tracker => Device::Tracker,
        CalibrationDevice::Platform => Device::Platform,
        CalibrationDevice::Ballbar => Device::Ballbar,
        CalibrationDevice::Probe => Device::Probe,
    };
    let defaults = PlanOptions::default();
    let options = PlanOptions {
        device,
        poses: args.poses as usize,
        candidates: args.candidates as usize,
        noise: noise_of(&args.fit),
        axis: args.axis,
        free: keys_of(&args.fit.free, "--free")?
            .into_iter()
            .filter(|p| {
                !keys_of(&args.fit.fixed, "--fixed")
                    .unwrap_or_default()
                    .contains(p)
            })
            .collect(),
        bar_mm: args.bar,
        ball: args.ball.map_or(defaults.ball, Vector3::from),
        seed: args.seed,
        ..defaults
    };
    let fixed = keys_of(&args.fit.fixed, "--fixed")?;
    let options = if options.free.is_empty() && !fixed.is_empty() {
        PlanOptions {
            free: device
                .parameters()
                .into_iter()
                .filter(|p| !fixed.contains(p))
                .collect(),
            ..options
        }
    } else {
        options
    };
    let p = plan(&machine, &options)
        .map_err(|e| VerneError::Usage(format!("verne calibrate plan: {e}")))?;
    let decimals = args.common.precision.map(usize::from);
    // The poses: joints, and what the nominal machine's instrument would read.
    let mut sink = Sink::create(args.output.as_deref())?;
    let angle = |v: f64| {
        if args.common.radians {
            v
        } else {
            v.to_degrees()
        }
    };
    let mut header = vec!["rho1", "rho2", "rho3", "theta1", "theta2"];
    header.extend(match device {
        Device::Tracker if args.axis => vec!["x", "y", "z", "i", "j", "k"],
        Device::Tracker => vec!["x", "y", "z"],
        Device::Platform => vec!["xp", "yp", "zp"],
        Device::Ballbar => vec!["distance"],
        Device::Probe => vec!["height"],
    });
    let written = (|| -> Result<(), VerneError> {
        sink.write(&ByteRecord::from(header.clone()))?;
        let mut values = [0.0; 6];
        for r in &p.rows {
            verne::calibrate::model::observed_values(r, &mut values);
            let mut cells = vec![
                r.rho.x,
                r.rho.y,
                r.rho.z,
                angle(r.theta[0]),
                angle(r.theta[1]),
            ];
            cells.extend_from_slice(&values[..r.observed.len()]);
            let rec: ByteRecord = cells
                .iter()
                .map(|v| {
                    let mut o = Vec::new();
                    format_number(&mut o, *v, decimals);
                    o
                })
                .collect();
            sink.write(&rec)?;
        }
        Ok(())
    })();
    match written {
        Ok(()) => sink.finish()?,
        Err(e) => {
            sink.discard();
            return Err(e);
        }
    }
    if let Some(report) = &args.report {
        let mut sink = Sink::create(Some(report))?;
        let rows = (|| -> Result<(), VerneError> {
            sink.write(&ByteRecord::from(vec!["key", "unit", "sigma", "detail"]))?;
            for (q, s) in &p.sigmas {
                let mut v = Vec::new();
                format_number(&mut v, q.shown(*s), decimals);
                let detail = if p.undetermined.iter().any(|(u, _)| u == q) {
                    "not determined: 1 sigma beyond its prior bound"
                } else {
                    "predicted"
                };
                sink.write(&ByteRecord::from(vec![
                    q.key().as_bytes(),
                    q.unit().as_bytes(),
                    &v,
                    detail.as_bytes(),
                ]))?;
            }
            for h in &p.identifiability.held {
                sink.write(&ByteRecord::from(vec![
                    h.param.key().as_bytes(),
                    h.param.unit().as_bytes(),
                    b"",
                    format!("held at nominal: {}", h.why).as_bytes(),
                ]))?;
            }
            Ok(())
        })();
        match rows {
            Ok(()) => sink.finish()?,
            Err(e) => {
                sink.discard();
                return Err(e);
            }
        }
    }
    let noise = if options.noise == DEFAULT_NOISE {
        format!("{} mm", options.noise.length_mm)
    } else {
        format!(
            "{} mm, axis {} rad",
            options.noise.length_mm, options.noise.axis_rad
        )
    };
    sayln!(
        "verne calibrate plan: {} poses for a {} from {} candidates (D-optimal), noise {noise}",
        p.rows.len(),
        device.name(),
        p.candidates
    );
    if !p.identifiability.held.is_empty() {
        sayln!("  cannot be determined by these readings, held at nominal:");
        for h in &p.identifiability.held {
            sayln!("    {}: {}", h.param.key(), h.why);
        }
    }
    if !p.undetermined.is_empty() {
        sayln!("  determined too poorly to calibrate (1 sigma beyond the prior bound):");
        for (q, s) in &p.undetermined {
            sayln!("    {}: 1 sigma {:.4} {}", q.key(), q.shown(*s), q.unit());
        }
    }
    sayln!("  predicted 1 sigma:");
    for (q, s) in &p.sigmas {
        sayln!("    {:<13} {:>9.4} {}", q.key(), q.shown(*s), q.unit());
    }
    sayln!(
        "  tool tip 1 sigma over the workspace: RMS {:.4} mm, largest {:.4} mm",
        p.tip_rms_mm,
        p.tip_max_mm
    );
    sayln!(
        "  worst length sigma {:.4} mm; median of {} random sets of {}: {:.4} mm ({:.2}x)",
        p.worst_mm,
        options.random_sets,
        p.rows.len(),
        p.random_worst_mm,
        p.worst_mm / p.random_worst_mm
    );
    Ok(EXIT_OK)
}
