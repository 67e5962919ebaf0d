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
        use std::io::Write as _;
        let _ = write!(std::io::stderr(), $($arg)*);
    }};
}

/// [`say!`] with a newline.
macro_rules! sayln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

pub mod arg_values;
pub mod cli;
pub mod cmd;
pub mod engine;
pub mod error;
pub mod fuzz_entry;
pub mod input;
pub mod plot;
pub mod post;
pub mod report;
pub mod table;

use std::process::ExitCode;

use clap::Parser;

/// Exit code after Ctrl-C or SIGTERM (128 + SIGINT), once temporary output files are removed.
const EXIT_INTERRUPTED: i32 = 130;

/// Runs the `verne` command on the process's arguments: parses them, runs one subcommand,
/// prints one error and returns the exit code (0 ok, 1 some row or check failed, 2 fatal).
pub fn run() -> ExitCode {
    // An interrupted run leaves neither a partial output file nor a temporary file behind.
    let _ = ctrlc::set_handler(|| {
        table::remove_temp_files();
        std::process::exit(EXIT_INTERRUPTED);
    });
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
    let result = match &cli.command {
        cli::Command::Ik(a) => cmd::ik::run(a),
        cli::Command::Fk(a) => cmd::fk::run(a),
        cli::Command::Modes(a) => cmd::modes::run(a),
        cli::Command::Design(a) => cmd::design::run(a),
        cli::Command::Machine(c) => cmd::machine::run(c),
        cli::Command::Workspace(a) => cmd::workspace::run(a),
        cli::Command::Selftest(a) => cmd::selftest::run(a),
        cli::Command::Verify(a) => cmd::verify::run(a),
        cli::Command::Completions { shell } => cmd::shell::completions(*shell),
        cli::Command::Manpage => cmd::shell::manpage(),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) if e.is_broken_pipe() => ExitCode::from(cmd::EXIT_OK),
        Err(e) => {
            table::remove_temp_files();
            sayln!("verne: error: {e}");
            ExitCode::from(cmd::EXIT_FATAL)
        }
    }
}
