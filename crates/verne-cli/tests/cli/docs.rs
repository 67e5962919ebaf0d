//! The documentation's console examples, run: every ```` ```console ```` block of README.md and
//! docs/*.md is a list of `$ COMMAND` lines, each followed by the output it prints. Each command
//! runs in `sh` (pipes work) with the freshly built `verne` first on `PATH`, from a scratch copy of
//! the repository (its entries linked, `docs/` empty, so what a command writes stays there), the
//! commands of one block in order in the same directory. What it prints (stdout, then stderr) must
//! match the lines under it, and a file it writes under `docs/` that the repository also has (the
//! sweep table of docs/workspace.md) must match the committed one: a changed output fails here
//! until the doc is updated.
//!
//! Matching: text exactly (runs of spaces as one, so a column may widen); numbers to a stated
//! precision, [`NUMBER_TOLERANCE`] relative (absolute below 1), since their last digits may vary
//! with the CPU, except that `-0` never matches `0`; a line `...` stands for any number of lines (the doc shows the head or the tail).
//! Filtered as in the golden test, because they measure the machine, not the code: elapsed times
//! ([`common::filter_timing`]) and a CSV's `seconds` column.
//!
//! `VERNE_DOCS_UPDATE=1 cargo test -p verne-cli --test cli docs::` rewrites the examples (and the files)
//! that no longer match from the actual output, keeping a leading or trailing `...`; review the
//! diff (times written by an update come from the test build: rerun those commands in release).

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use crate::common;

/// Numbers in the docs are compared to this relative precision (absolute below 1).
const NUMBER_TOLERANCE: f64 = 1e-9;
/// Set to rewrite the blocks from the actual output.
const UPDATE_VAR: &str = "VERNE_DOCS_UPDATE";
/// The line that elides output.
const ELLIPSIS: &str = "...";

/// One `$ COMMAND` line and the output lines under it.
struct Example {
    /// 0-based index of the `$` line in its file.
    line: usize,
    command: String,
    expected: Vec<String>,
}

/// One console block.
struct Block {
    file: PathBuf,
    examples: Vec<Example>,
}

/// The documents whose console blocks are run.
fn documents(root: &Path) -> Vec<PathBuf> {
    let mut docs = vec![root.join("README.md")];
    let mut more: Vec<PathBuf> = fs::read_dir(root.join("docs"))
        .expect("docs/")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    more.sort();
    docs.extend(more);
    docs
}

fn blocks_of(file: &Path) -> Vec<Block> {
    let text = fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let mut blocks = Vec::new();
    let mut current: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        match &mut current {
            None if line.trim_end() == "```console" => {
                current = Some(Block {
                    file: file.to_path_buf(),
                    examples: Vec::new(),
                })
            }
            None => {}
            Some(_) if line.starts_with("```") => blocks.push(current.take().unwrap()),
            Some(block) => match line.strip_prefix("$ ") {
                Some(command) => block.examples.push(Example {
                    line: i,
                    command: command.to_string(),
                    expected: Vec::new(),
                }),
                None => match block.examples.last_mut() {
                    Some(e) => e.expected.push(line.to_string()),
                    None => panic!(
                        "{}:{}: a console block must start with a `$ ` command",
                        file.display(),
                        i + 1
                    ),
                },
            },
        }
    }
    assert!(
        current.is_none(),
        "{}: unclosed console block",
        file.display()
    );
    blocks
}

/// A line split into text and numbers.
#[derive(Debug)]
enum Token<'a> {
    Text(&'a str),
    Number(f64, &'a str),
}

/// Splits at numbers (`-12`, `3.5`, `1.2e-13`); a digit inside a word (`rho1`, `N700`) is a
/// number too, compared the same way on both sides.
fn tokens(line: &str) -> Vec<Token<'_>> {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let (mut i, mut text_start) = (0, 0);
    let digit = |k: usize| b.get(k).is_some_and(|c| c.is_ascii_digit());
    while i < b.len() {
        let signed = (b[i] == b'-' || b[i] == b'+')
            && (digit(i + 1) || (b.get(i + 1) == Some(&b'.') && digit(i + 2)));
        let starts = digit(i) || (b[i] == b'.' && digit(i + 1)) || signed;
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        if signed {
            i += 1;
        }
        while digit(i) {
            i += 1;
        }
        if b.get(i) == Some(&b'.') && digit(i + 1) {
            i += 1;
            while digit(i) {
                i += 1;
            }
        }
        if matches!(b.get(i), Some(b'e' | b'E')) {
            let k = if matches!(b.get(i + 1), Some(b'-' | b'+')) {
                i + 2
            } else {
                i + 1
            };
            if digit(k) {
                i = k;
                while digit(i) {
                    i += 1;
                }
            }
        }
        if text_start < start {
            out.push(Token::Text(&line[text_start..start]));
        }
        let s = &line[start..i];
        out.push(Token::Number(s.parse().unwrap(), s));
        text_start = i;
    }
    if text_start < line.len() {
        out.push(Token::Text(&line[text_start..]));
    }
    out
}

fn same_text(a: &str, b: &str) -> bool {
    a.split_whitespace().eq(b.split_whitespace()) && a.starts_with(' ') == b.starts_with(' ')
}

/// `-0`, `-0.000`: the docs promise it is written `0`, so it is compared as text.
fn negative_zero(value: &f64, text: &str) -> bool {
    *value == 0.0 && text.starts_with('-')
}

/// One expected line against one actual line (module doc).
fn line_matches(expected: &str, actual: &str) -> bool {
    if expected == actual {
        return true;
    }
    let (e, a) = (tokens(expected.trim_end()), tokens(actual.trim_end()));
    e.len() == a.len()
        && e.iter().zip(&a).all(|pair| match pair {
            (Token::Text(x), Token::Text(y)) => same_text(x, y),
            (Token::Number(x, xs), Token::Number(y, ys)) => {
                xs == ys
                    || (!negative_zero(x, xs)
                        && !negative_zero(y, ys)
                        && (x - y).abs() <= NUMBER_TOLERANCE * x.abs().max(y.abs()).max(1.0))
            }
            _ => false,
        })
}

/// The expected lines (with `...`) against the actual ones.
fn lines_match(expected: &[String], actual: &[&str]) -> bool {
    match expected.split_first() {
        None => actual.is_empty(),
        Some((first, rest)) if first == ELLIPSIS => {
            (0..=actual.len()).any(|skip| lines_match(rest, &actual[skip..]))
        }
        Some((first, rest)) => match actual.split_first() {
            Some((a, more)) => line_matches(first, a) && lines_match(rest, more),
            None => false,
        },
    }
}

/// The first line where they part, for the failure message.
fn first_difference(expected: &[String], actual: &[&str]) -> String {
    if expected.first().is_some_and(|l| l == ELLIPSIS) && expected.len() > 1 {
        // The doc shows the tail: align the ends.
        let tail = &expected[1..];
        let skip = actual.len().saturating_sub(tail.len());
        return first_difference(tail, &actual[skip..]);
    }
    let n = expected
        .iter()
        .zip(actual)
        .take_while(|(e, a)| e.as_str() != ELLIPSIS && line_matches(e, a))
        .count();
    format!(
        "output line {}:\n      expected: {:?}\n      actual:   {:?}\n    whole actual output:\n{}",
        n + 1,
        expected.get(n).map_or("<end>", |s| s.as_str()),
        actual.get(n).copied().unwrap_or("<end>"),
        actual
            .iter()
            .map(|l| format!("      {l}\n"))
            .collect::<String>()
    )
}

/// What `...` keeps when a block is rewritten: the same number of lines at the same end.
fn updated(expected: &[String], actual: &[&str]) -> Vec<String> {
    let shown = expected.len().saturating_sub(1);
    let all = || actual.iter().map(|s| s.to_string());
    if expected.first().is_some_and(|l| l == ELLIPSIS) && expected.len() > 1 {
        let mut v = vec![ELLIPSIS.to_string()];
        v.extend(all().skip(actual.len().saturating_sub(shown)));
        v
    } else if expected.last().is_some_and(|l| l == ELLIPSIS) && expected.len() > 1 {
        let mut v: Vec<String> = all().take(shown).collect();
        v.push(ELLIPSIS.to_string());
        v
    } else {
        all().collect()
    }
}

/// A scratch directory with the repository's entries linked in, and an empty `docs/`.
fn scratch_copy(root: &Path, dir: &Path) {
    let _ = fs::remove_dir_all(dir);
    fs::create_dir_all(dir.join("docs")).unwrap();
    for e in fs::read_dir(root).unwrap() {
        let e = e.unwrap();
        let name = e.file_name();
        if [".git", "target", "docs"].iter().any(|n| name == *n) {
            continue;
        }
        std::os::unix::fs::symlink(e.path(), dir.join(&name)).unwrap();
    }
}

/// A CSV's `seconds` column (the run's time) replaced by `<t>`.
fn mask_seconds(text: &str) -> String {
    let mut lines = text.lines();
    let Some(header) = lines.next() else {
        return String::new();
    };
    let Some(col) = header.split(',').position(|c| c == "seconds") else {
        return text.to_string();
    };
    let mut out = format!("{header}\n");
    for line in lines {
        let cells: Vec<&str> = line
            .split(',')
            .enumerate()
            .map(|(k, c)| if k == col { "<t>" } else { c })
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// Outcome of one block: failures, and the rewritten lines per example when updating.
struct Ran {
    failures: Vec<String>,
    rewritten: Vec<(usize, usize, Vec<String>)>,
}

fn run_block(root: &Path, block: &Block, scratch: &Path, update: bool) -> Ran {
    scratch_copy(root, scratch);
    let bin_dir = Path::new(common::BIN).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut ran = Ran {
        failures: Vec::new(),
        rewritten: Vec::new(),
    };
    let scratch_text = scratch.display().to_string();
    for ex in &block.examples {
        let out = Command::new("sh")
            .arg("-c")
            .arg(&ex.command)
            .current_dir(scratch)
            .env("PATH", &path)
            .env_remove("COLUMNS")
            .env_remove("LINES")
            .stdin(Stdio::null())
            .output()
            .expect("sh runs");
        let mut raw = out.stdout;
        raw.extend_from_slice(&out.stderr);
        let filtered = |bytes: &[u8]| {
            String::from_utf8_lossy(&common::filter_timing(bytes, &scratch_text)).into_owned()
        };
        let text = filtered(&raw);
        let actual: Vec<&str> = text.lines().collect();
        let expected_text = filtered(ex.expected.join("\n").as_bytes());
        let expected: Vec<String> = expected_text.lines().map(str::to_string).collect();
        let here = format!("{}:{}: $ {}", block.file.display(), ex.line + 1, ex.command);
        let matches = lines_match(&expected, &actual);
        if update && !matches {
            ran.rewritten.push((
                ex.line + 1,
                ex.expected.len(),
                updated(
                    &ex.expected,
                    &String::from_utf8_lossy(&raw).lines().collect::<Vec<_>>(),
                ),
            ));
        } else if !update && !matches {
            ran.failures.push(format!(
                "{here}\n    {}",
                first_difference(&expected, &actual)
            ));
        }
    }
    // Files the block wrote under docs/ that the repository also has.
    for e in fs::read_dir(scratch.join("docs")).unwrap() {
        let made = e.unwrap().path();
        let committed = root.join("docs").join(made.file_name().unwrap());
        if !committed.is_file() {
            continue;
        }
        let (made_text, committed_text) = (
            mask_seconds(&fs::read_to_string(&made).unwrap()),
            mask_seconds(&fs::read_to_string(&committed).unwrap()),
        );
        let expected: Vec<String> = committed_text.lines().map(str::to_string).collect();
        let actual: Vec<&str> = made_text.lines().collect();
        if update && !lines_match(&expected, &actual) {
            fs::copy(&made, &committed).unwrap();
        } else if !update && !lines_match(&expected, &actual) {
            ran.failures.push(format!(
                "{}: the file the block writes differs from the committed {}\n    {}",
                block.file.display(),
                committed.display(),
                first_difference(&expected, &actual)
            ));
        }
    }
    ran
}

/// Rewrites one document's examples (`rewritten`: first output line, old length, new lines).
fn rewrite(file: &Path, mut rewritten: Vec<(usize, usize, Vec<String>)>) {
    let text = fs::read_to_string(file).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    rewritten.sort_by_key(|r| std::cmp::Reverse(r.0));
    for (start, len, new) in rewritten {
        lines.splice(start..start + len, new);
    }
    fs::write(file, lines.join("\n") + "\n").unwrap();
}

#[test]
fn every_console_example_in_the_docs_prints_what_the_doc_shows() {
    let root = Path::new(common::ROOT);
    let update = std::env::var_os(UPDATE_VAR).is_some();
    let mut blocks: Vec<Block> = documents(root).iter().flat_map(|d| blocks_of(d)).collect();
    // The workspace examples are the long ones: start them first, so the two workers finish
    // together.
    blocks.sort_by_key(|b| !b.examples.iter().any(|e| e.command.contains("workspace")));
    assert!(
        blocks
            .iter()
            .filter(|b| b.file.ends_with("README.md"))
            .count()
            >= 8,
        "the README's console examples were not found"
    );
    let scratch_base = std::env::temp_dir().join(format!("verne-docs-{}", std::process::id()));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    // Two workers: the blocks are independent (each its own directory).
    std::thread::scope(|s| {
        for w in 0..2 {
            let (blocks, next, results) = (&blocks, &next, &results);
            let scratch = scratch_base.join(format!("w{w}"));
            s.spawn(move || {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(block) = blocks.get(i) else { break };
                    let ran = run_block(root, block, &scratch, update);
                    results.lock().unwrap().push((i, ran));
                }
            });
        }
    });
    let _ = fs::remove_dir_all(&scratch_base);
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    if update {
        for doc in documents(root) {
            let edits: Vec<_> = results
                .iter_mut()
                .filter(|(i, _)| blocks[*i].file == doc)
                .flat_map(|(_, ran)| std::mem::take(&mut ran.rewritten))
                .collect();
            if !edits.is_empty() {
                rewrite(&doc, edits);
            }
        }
        return;
    }
    let failures: Vec<String> = results.into_iter().flat_map(|(_, r)| r.failures).collect();
    assert!(
        failures.is_empty(),
        "{} console example(s) no longer print what the doc shows (rerun with {UPDATE_VAR}=1 \
         and review the diff):\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn the_matcher_tolerates_only_what_it_states() {
    let v = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    // Last digits of a full-precision number; a widened column.
    assert!(line_matches("a,264.12469182446,b", "a,264.12469182447,b"));
    assert!(line_matches("x   1.5  ok", "x  1.5    ok"));
    assert!(line_matches("residual 4.288e-13 mm", "residual 3.9e-13 mm"));
    // A changed digit that matters, a changed word, a missing cell, a sign.
    assert!(!line_matches("a,264.1246,b", "a,264.1247,b"));
    assert!(!line_matches("status ok", "status rod_tilt"));
    assert!(!line_matches("1,2,3", "1,2,"));
    assert!(!line_matches("theta -90", "theta 90"));
    assert!(!line_matches("det 0.000000 x", "det -0.000000 x"));
    assert!(!line_matches("  indented", "indented"));
    // `...` for any number of lines, at the start, middle or end; nothing else is skipped.
    assert!(lines_match(&v(&["...", "c"]), &["a", "b", "c"]));
    assert!(lines_match(&v(&["a", "..."]), &["a"]));
    assert!(lines_match(&v(&["a", "...", "d"]), &["a", "b", "c", "d"]));
    assert!(!lines_match(&v(&["a", "c"]), &["a", "b", "c"]));
    assert!(!lines_match(&v(&["a"]), &["a", "b"]));
    assert!(!lines_match(&v(&["...", "x"]), &["a", "b"]));
    // Updating keeps the elision and the number of lines shown.
    assert_eq!(
        updated(&v(&["...", "old"]), &["a", "b", "c"]),
        v(&["...", "c"])
    );
    assert_eq!(updated(&v(&["old", "..."]), &["a", "b"]), v(&["a", "..."]));
    assert_eq!(updated(&v(&["old"]), &["a", "b"]), v(&["a", "b"]));
    assert_eq!(mask_seconds("k,seconds\n1,0.5\n"), "k,seconds\n1,<t>\n");
}
