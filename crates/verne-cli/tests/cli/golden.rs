//! Golden output: runs the real binary on every case of `tests/golden/commands.txt` (every
//! subcommand, the README's console examples, the hostile inputs, error cases) and compares its
//! stdout, stderr, exit code and the files it writes byte for byte with the recorded ones in
//! `tests/golden/expected/NAME/`. Recorded before the workspace split, so it proves that a
//! structural change left the behaviour alone.
//!
//! `VERNE_GOLDEN_UPDATE=1 cargo test -p verne-cli --test cli golden::` rewrites the expected files (then review the
//! diff).
//!
//! What is filtered, deliberately, because it depends on the machine's speed or load rather than
//! on the code (see [`common::filter_timing`]): the elapsed time in `verne selftest`'s first line, the `time`
//! line of each `verne workspace` summary (seconds, points per second, threads), and the
//! `time_s` column of the volume-against-tool-length table. Paths under the scratch directory
//! are written as `$OUT`. Nothing else is filtered.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::common;

/// The corpus, relative to the repository root ([`common::ROOT`]), where the binary runs so that
/// the cases' relative paths (`data/...`, `tests/...`) resolve.
const GOLDEN: &str = "tests/golden";
/// Set to rewrite the expected files.
const UPDATE_VAR: &str = "VERNE_GOLDEN_UPDATE";

/// One line of commands.txt.
struct Case {
    name: String,
    args: Vec<String>,
    stdin: Option<PathBuf>,
}

/// What one run produced, filtered.
#[derive(PartialEq)]
struct Outcome {
    stdout: Vec<u8>,
    stderr: Vec<u8>,
    code: String,
    /// Files written under `$OUT`, by name, sorted.
    files: Vec<(String, Vec<u8>)>,
}

fn cases(root: &Path) -> Vec<Case> {
    let text = fs::read_to_string(root.join(GOLDEN).join("commands.txt")).expect("commands.txt");
    let mut out: Vec<Case> = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut tokens = line.split_whitespace();
        let name = tokens.next().unwrap().to_string();
        assert!(
            out.iter().all(|c| c.name != name),
            "case {name} appears twice"
        );
        let mut args = Vec::new();
        let mut stdin = None;
        for t in tokens {
            match t.strip_prefix('<') {
                Some(f) => stdin = Some(root.join(f)),
                None => args.push(t.to_string()),
            }
        }
        out.push(Case { name, args, stdin });
    }
    out
}

fn run(case: &Case, scratch: &Path) -> Outcome {
    let _ = fs::remove_dir_all(scratch);
    fs::create_dir_all(scratch).unwrap();
    let scratch_text = scratch.display().to_string();
    let args: Vec<String> = case
        .args
        .iter()
        .map(|a| a.replace("$OUT", &scratch_text))
        .collect();
    let mut child = common::command(&args).spawn().expect("binary runs");
    {
        let mut input = child.stdin.take().unwrap();
        if let Some(f) = &case.stdin {
            let bytes = fs::read(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            // A command that stops reading early closes the pipe: not a failure of the test.
            let _ = input.write_all(&bytes);
        }
    }
    let out = child.wait_with_output().unwrap();
    let mut files: Vec<(String, Vec<u8>)> = fs::read_dir(scratch)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            (name, fs::read(e.path()).unwrap())
        })
        .collect();
    files.sort();
    Outcome {
        stdout: common::filter_timing(&out.stdout, &scratch_text),
        stderr: common::filter_timing(&out.stderr, &scratch_text),
        code: match out.status.code() {
            Some(c) => format!("{c}\n"),
            None => "signal\n".to_string(),
        },
        files,
    }
}

fn read_expected(dir: &Path) -> Option<Outcome> {
    let files_dir = dir.join("files");
    let mut files = Vec::new();
    if files_dir.is_dir() {
        for e in fs::read_dir(&files_dir).ok()? {
            let e = e.ok()?;
            files.push((
                e.file_name().to_string_lossy().into_owned(),
                fs::read(e.path()).ok()?,
            ));
        }
        files.sort();
    }
    Some(Outcome {
        stdout: fs::read(dir.join("stdout")).ok()?,
        stderr: fs::read(dir.join("stderr")).ok()?,
        code: fs::read_to_string(dir.join("code")).ok()?,
        files,
    })
}

fn write_expected(dir: &Path, o: &Outcome) {
    let _ = fs::remove_dir_all(dir);
    fs::create_dir_all(dir).unwrap();
    fs::write(dir.join("stdout"), &o.stdout).unwrap();
    fs::write(dir.join("stderr"), &o.stderr).unwrap();
    fs::write(dir.join("code"), &o.code).unwrap();
    if !o.files.is_empty() {
        fs::create_dir_all(dir.join("files")).unwrap();
        for (name, bytes) in &o.files {
            fs::write(dir.join("files").join(name), bytes).unwrap();
        }
    }
}

/// The first difference between two outputs, as a short description.
fn first_difference(what: &str, expected: &[u8], actual: &[u8]) -> Option<String> {
    if expected == actual {
        return None;
    }
    let e = String::from_utf8_lossy(expected);
    let a = String::from_utf8_lossy(actual);
    let mut el = e.lines();
    let mut al = a.lines();
    let mut n = 0;
    loop {
        n += 1;
        match (el.next(), al.next()) {
            (Some(x), Some(y)) if x == y => continue,
            (x, y) => {
                return Some(format!(
                    "{what}, line {n}:\n    expected: {:?}\n    actual:   {:?}",
                    x.unwrap_or("<end>"),
                    y.unwrap_or("<end>")
                ));
            }
        }
    }
}

fn differences(expected: &Outcome, actual: &Outcome) -> Vec<String> {
    let mut d = Vec::new();
    d.extend(first_difference("stdout", &expected.stdout, &actual.stdout));
    d.extend(first_difference("stderr", &expected.stderr, &actual.stderr));
    d.extend(first_difference(
        "exit code",
        expected.code.as_bytes(),
        actual.code.as_bytes(),
    ));
    let names = |o: &Outcome| o.files.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    if names(expected) != names(actual) {
        d.push(format!(
            "files written: expected {:?}, actual {:?}",
            names(expected),
            names(actual)
        ));
    } else {
        for ((name, e), (_, a)) in expected.files.iter().zip(&actual.files) {
            d.extend(first_difference(&format!("file {name}"), e, a));
        }
    }
    d
}

#[test]
fn every_case_matches_its_recorded_output() {
    let root = Path::new(common::ROOT);
    let update = std::env::var_os(UPDATE_VAR).is_some();
    let cases = cases(root);
    let expected_dir = root.join(GOLDEN).join("expected");
    let scratch_base = std::env::temp_dir().join(format!("verne-golden-{}", std::process::id()));
    // Two workers: the cases are independent processes.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let failures = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for w in 0..2 {
            let (cases, next, failures) = (&cases, &next, &failures);
            let (expected_dir, scratch) = (&expected_dir, scratch_base.join(format!("w{w}")));
            s.spawn(move || {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(case) = cases.get(i) else { break };
                    let actual = run(case, &scratch);
                    let dir = expected_dir.join(&case.name);
                    if update {
                        write_expected(&dir, &actual);
                        continue;
                    }
                    let problems = match read_expected(&dir) {
                        None => vec![format!(
                            "no recorded output in {} (run with {UPDATE_VAR}=1)",
                            dir.display()
                        )],
                        Some(expected) => differences(&expected, &actual),
                    };
                    if !problems.is_empty() {
                        failures.lock().unwrap().push(format!(
                            "{}: {}",
                            case.name,
                            problems.join("\n  ")
                        ));
                    }
                }
            });
        }
    });
    let _ = fs::remove_dir_all(&scratch_base);
    if update {
        // Recorded cases no longer in commands.txt.
        for e in fs::read_dir(&expected_dir).unwrap() {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            if cases.iter().all(|c| c.name != name) {
                let _ = fs::remove_dir_all(expected_dir.join(name));
            }
        }
        return;
    }
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {} golden cases differ:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}
