//! verne-cli: the `verne` command over the kinematics core (crate `verne`). This crate talks:
//! it parses arguments (clap, [`cli`]), reads and writes CSV ([`table`]) and CL files
//! ([`input`]), streams rows through the core's solvers ([`engine`]), draws pictures ([`plot`]),
//! writes reports ([`report`]), prints one error and picks the exit code. The core computes and
//! returns typed values; nothing of this crate crosses into it (ARCHITECTURE.md).
//!
//! `src/main.rs` only calls [`run`].

/// `eprint!` that never panics: a message to a closed stderr (`verne ik F 2>&1 | head -1`) is
/// dropped, and the run exits with the code it would have had. Every message of the CLI goes
/// through it (or through `writeln!` with its result ignored).
macro_rules! say {
    ($($arg:tt)*) => {{
        if $crate::verbosity() >= 1 {
            use std::io::Write as _;
            let _ = write!(std::io::stderr(), $($arg)*);
        }
    }};
}

/// [`say!`] with a newline.
macro_rules! sayln {
    ($($arg:tt)*) => {{
        if $crate::verbosity() >= 1 {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), $($arg)*);
        }
    }};
}

/// [`sayln!`] only under `-v`.
macro_rules! sayln_verbose {
    ($($arg:tt)*) => {{
        if $crate::verbosity() >= 2 {
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), $($arg)*);
        }
    }};
}

/// How much goes to stderr besides errors: 0 nothing (`-q`), 1 summaries and warnings (the
/// default), 2 also the machine, timings and rates (`-v`).
static VERBOSITY: std::sync::atomic::AtomicU8 = std::sync::atomic::AtomicU8::new(1);

/// The verbosity set by `-q`/`-v` (`VERBOSITY`).
pub fn verbosity() -> u8 {
    VERBOSITY.load(std::sync::atomic::Ordering::Relaxed)
}

pub mod arg_values;
pub mod cli;
pub mod cmd;
pub mod engine;
pub mod error;
pub mod files;
pub mod follow;
pub mod fuzz_entry;
pub mod input;
pub mod plot;
pub mod report;
pub mod table;
pub mod toolpath;

use std::process::ExitCode;

use clap::Parser;

/// Runs the `verne` command on the process's arguments: parses them, runs one subcommand,
/// prints one error and returns the exit code (0 ok, 1 some row or check failed, 2 fatal).
pub fn run() -> ExitCode {
    // An interrupted run (SIGINT, SIGTERM, SIGHUP) leaves neither a partial output file nor a
    // temporary file behind, and exits with 128 + the signal's number, as a shell reports it.
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                files::remove_temp_files();
                std::process::exit(128 + signal);
            }
        });
    }
    let cli = match cli::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() {
                cmd::EXIT_FATAL
            } else {
                cmd::EXIT_OK
            });
        }
    };
    VERBOSITY.store(
        match (cli.quiet, cli.verbose) {
            (true, _) => 0,
            (false, true) => 2,
            (false, false) => 1,
        },
        std::sync::atomic::Ordering::Relaxed,
    );
    let started = std::time::Instant::now();
    let result = match &cli.command {
        cli::Command::Ik(a) => cmd::ik::run(a),
        cli::Command::Fk(a) => cmd::fk::run(a),
        cli::Command::Modes(a) => cmd::modes::run(a),
        cli::Command::Design(a) => cmd::design::run(a),
        cli::Command::Machine(c) => cmd::machine::run(c),
        cli::Command::Workspace(a) => cmd::workspace::run(a),
        cli::Command::Selftest(a) => cmd::selftest::run(a),
        cli::Command::Verify(a) => cmd::verify::run(a),
        cli::Command::Calibrate(a) => cmd::calibrate::run(a),
        cli::Command::Completions { shell } => cmd::shell::completions(*shell),
        cli::Command::Manpage => cmd::shell::manpage(),
    };
    sayln_verbose!("verne: {:.3} s", started.elapsed().as_secs_f64());
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) if e.is_broken_pipe() => ExitCode::from(cmd::EXIT_OK),
        Err(e) => {
            files::remove_temp_files();
            // Errors are written whatever the verbosity.
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "verne: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
