//! One file per subcommand; this file holds what they share: loading the machine, opening the
//! input and output, and turning a run's summary into an exit code.

pub mod calibrate;
pub mod design;
pub mod fk;
pub mod glider;
pub mod ik;
pub mod machine;
pub mod modes;
pub mod selftest;
pub mod shell;
pub mod verify;
pub mod workspace;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::engine::pipeline::{self, RowJob, RunSummary, Units};
use crate::error::VerneError;
use crate::files::Sink;
use crate::table::CsvSource;
use verne::spec::Machine;

use crate::cli::CommonArgs;

/// The exit-code contract (README, `--help`).
pub const EXIT_OK: u8 = 0;
pub const EXIT_ROWS_FAILED: u8 = 1;
pub const EXIT_FATAL: u8 = 2;

/// The mechanism a command runs on: the VERNE machine (a machine file) or a planar glider (a
/// preset name or a glider file), decided once from `-m` (ARCHITECTURE.md).
#[allow(clippy::large_enum_variant)] // one per run
pub enum Mechanism {
    Verne(Machine),
    Glider(verne::glider::GliderSpec),
}

/// Loads `-m`: a preset name (`verne`, `biglide1`, `biglide2`, `orthoglide`), a glider file
/// (`kind = "glider"`) or a VERNE machine file; the embedded VERNE machine without `-m`.
pub fn load_mechanism(path: Option<&Path>) -> Result<Mechanism, VerneError> {
    if let Some(spec) = glider::load(path)? {
        sayln_verbose!("verne: glider `{}`", spec.name);
        return Ok(Mechanism::Glider(spec));
    }
    load_machine(path).map(Mechanism::Verne)
}

/// Refuses the options that a glider does not have, naming them: `what` lists (option, given).
pub fn refuse_for_glider(glider: &str, options: &[(&str, bool)]) -> Result<(), VerneError> {
    let given: Vec<&str> = options
        .iter()
        .filter(|(_, g)| *g)
        .map(|(o, _)| *o)
        .collect();
    if given.is_empty() {
        return Ok(());
    }
    Err(VerneError::Usage(format!(
        "{} {} for the VERNE machine; `{glider}` is a planar glider (its poses are --pose X,Y, its joints --joints RHO1,RHO2; docs/gliders.md)",
        given.join(", "),
        if given.len() == 1 {
            "is an option"
        } else {
            "are options"
        }
    )))
}

/// Loads `-m FILE`, or the embedded VERNE machine.
pub fn load_machine(path: Option<&Path>) -> Result<Machine, VerneError> {
    let machine = read_machine(path)?;
    sayln_verbose!(
        "verne: machine `{}` from {}",
        machine.name,
        path.map_or("the embedded default".to_string(), |p| p
            .display()
            .to_string())
    );
    Ok(machine)
}

fn read_machine(path: Option<&Path>) -> Result<Machine, VerneError> {
    match path {
        None => Ok(Machine::default_verne()),
        Some(p) if !p.exists() && p.as_os_str() == "verne" => Ok(Machine::default_verne()),
        Some(p) => {
            let name = p.display().to_string();
            let text = crate::files::read_input_file(p).map_err(|e| VerneError::io(&name, e))?;
            let text = String::from_utf8(text).map_err(|e| {
                let upto = &e.as_bytes()[..e.utf8_error().valid_up_to()];
                let line = upto.iter().filter(|&&b| b == b'\n').count() as u64 + 1;
                VerneError::input(
                    &name,
                    Some(line),
                    None,
                    "not UTF-8 text; expected a TOML or key,value CSV machine file",
                )
            })?;
            // A base named by path is read relative to this file's folder.
            let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
            let resolve = |base: &str| -> Result<(String, String), String> {
                let path = dir.join(base);
                if !path.exists() && verne::glider::GliderSpec::preset(base).is_some() {
                    return Err(format!(
                        "`{base}` is a glider preset, not a VERNE machine: a VERNE machine file's base is `verne` or the path of another VERNE machine file"
                    ));
                }
                let shown = path.display().to_string();
                let bytes = crate::files::read_input_file(&path)
                    .map_err(|e| format!("base {shown}: {e}"))?;
                String::from_utf8(bytes)
                    .map(|t| (t, shown.clone()))
                    .map_err(|_| format!("base {shown}: not UTF-8 text"))
            };
            Ok(Machine::from_str_on_base(&text, &name, Some(&resolve))?)
        }
    }
}

pub fn units(common: &CommonArgs) -> Units {
    Units {
        radians: common.radians,
        decimals: common.precision.map(usize::from),
    }
}

/// The rows given on the command line, numbers in the columns `header`.
pub fn inline_source(header: &[&str], rows: Vec<Vec<f64>>) -> CsvSource {
    CsvSource::from_numbers(header, rows, INLINE_SOURCE)
}

pub use crate::toolpath::inline::INLINE_SOURCE;

/// Runs a row job from `source` to `output`, with a progress indicator on a terminal, and
/// prints the summary of rows that were not ok to stderr.
pub fn run_rows<J: RowJob>(
    command: &str,
    job: &mut J,
    mut source: CsvSource,
    output: Option<&PathBuf>,
    units: Units,
) -> Result<u8, VerneError> {
    let mut sink = Sink::create(output.map(PathBuf::as_path))?;
    let bar = progress_bar();
    let tick = |n: u64| {
        if let Some(b) = &bar {
            b.set_position(n);
        }
    };
    let started = std::time::Instant::now();
    let result = pipeline::run(job, &mut source, &mut sink, units, &tick);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let summary = match result {
        Ok(s) => s,
        Err(e) => {
            sink.discard();
            return Err(e);
        }
    };
    sink.finish()?;
    report(command, source.name(), &summary);
    let seconds = started.elapsed().as_secs_f64();
    sayln_verbose!(
        "verne {command}: {}: {} rows in, {} rows out, {} ok, in {seconds:.3} s ({:.0} rows/s)",
        source.name(),
        summary.input_rows,
        summary.output_rows,
        summary.ok_rows,
        summary.input_rows as f64 / seconds.max(1e-9)
    );
    Ok(if summary.all_ok() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

/// A spinner with the row count and rate, shown only when stderr is a terminal and the run
/// lasts more than a moment.
pub fn progress_bar() -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {pos} rows ({per_sec}) {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    Some(bar)
}

pub fn report(command: &str, file: &str, s: &RunSummary) {
    if s.all_ok() {
        return;
    }
    let counts: Vec<String> = s.not_ok.iter().map(|(st, n)| format!("{n} {st}")).collect();
    sayln!(
        "verne {command}: {file}: {} of {} rows not ok ({})",
        s.input_rows - s.ok_rows,
        s.input_rows,
        counts.join(", ")
    );
    for (line, st) in &s.first_failures {
        if file == INLINE_SOURCE {
            sayln!("  {file}: row {line}: {st}");
        } else {
            sayln!("  {file}:{line}: {st}");
        }
    }
}

/// Writes text to stdout; a closed pipe surfaces as a broken-pipe error (exit 0), never a panic.
pub fn write_stdout(text: &str) -> Result<(), VerneError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|_| out.flush())
        .map_err(|e| VerneError::io("<stdout>", e))
}
