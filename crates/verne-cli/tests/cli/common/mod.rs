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

/// Replaces what depends on the machine's speed, load or the scratch directory: the elapsed time
/// in `verne selftest`'s first line, the `time` line of a `verne workspace` summary, a sweep's
/// progress lines and the `time_s` column of its volume-against-tool-length table; `scratch` is written `$OUT`.
pub fn filter_timing(bytes: &[u8], scratch: &str) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes).replace(scratch, "$OUT");
    let mut out = String::with_capacity(text.len());
    let mut in_time_table = false;
    for line in text.split_inclusive('\n') {
        let (body, end) = match line.strip_suffix('\n') {
            Some(b) => (b, "\n"),
            None => (line, ""),
        };
        let filtered = if body.starts_with("selftest of machine ") && body.ends_with(" s)") {
            // "... (4.6 s)": the run's elapsed time.
            match body.rfind(" (") {
                Some(k) => format!("{} (<time> s)", &body[..k]),
                None => body.to_string(),
            }
        } else if body.starts_with("verne workspace: ")
            && body.ends_with(" s")
            && body.contains(" l in ")
        {
            // A sweep's progress line "verne workspace: tool.length=0: 453.962 l in 9.1 s".
            match body.rfind(" in ") {
                Some(k) => format!("{} in <time> s", &body[..k]),
                None => body.to_string(),
            }
        } else if body.trim_start().starts_with("time ") && body.starts_with("  time") {
            // The workspace summary's "time  0.76 s, 12845 points/s, 2 threads".
            "  time               <filtered>".to_string()
        } else if body.starts_with("tool_length_mm") && body.ends_with("time_s") {
            in_time_table = true;
            body.to_string()
        } else if in_time_table && !body.trim().is_empty() {
            // The last column of the volume-against-tool-length table is seconds.
            match body.trim_end().rfind(' ') {
                Some(k) => format!("{} <t>", &body[..k]),
                None => body.to_string(),
            }
        } else {
            in_time_table = false;
            body.to_string()
        };
        out.push_str(&filtered);
        out.push_str(end);
    }
    out.into_bytes()
}
