//! Helpers shared by the CLI tests: run the real binary, read its CSV output.
// Each test crate uses a different subset.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::io::Write;
use std::process::{Command, Output, Stdio};

pub const BIN: &str = env!("CARGO_BIN_EXE_verne");

/// The repository root, where the binary runs so that `data/...` and `tests/data/...` resolve.
pub const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// `verne ARGS` run from the repository root with stdin, stdout and stderr piped; help text
/// wraps at no inherited terminal width (`COLUMNS`, `LINES` removed).
pub fn command<S: AsRef<OsStr>>(args: &[S]) -> Command {
    let mut c = Command::new(BIN);
    c.args(args)
        .current_dir(ROOT)
        .env_remove("COLUMNS")
        .env_remove("LINES")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

/// Runs `verne ARGS` from the repository root, feeding `stdin` (then closing it).
pub fn run(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = command(args).spawn().expect("binary runs");
    {
        let mut input = child.stdin.take().unwrap();
        if let Some(s) = stdin {
            input.write_all(s.as_bytes()).unwrap();
        }
    }
    child.wait_with_output().unwrap()
}

/// CSV text split into its header and rows of cells (no quoting in verne's numeric output).
pub fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap_or("")
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

/// [`table`] of a run's stdout.
pub fn table_of(out: &Output) -> (Vec<String>, Vec<Vec<String>>) {
    table(&String::from_utf8(out.stdout.clone()).unwrap())
}

pub fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

pub fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s:?}"))
}
