//! Replays the fuzzing corpus (fuzz/corpus/<target>/*) through the same entry points the fuzz
//! targets call: every input, including each crash the fuzzers found, must be handled without a
//! panic. (No fuzzing happens here; `cargo fuzz run <target>` does that.)

use std::path::Path;

fn replay(target: &str, entry: fn(&[u8])) -> usize {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("fuzz/corpus")
        .join(target);
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = e.unwrap().path();
        let data = std::fs::read(&path).unwrap();
        let r = std::panic::catch_unwind(|| entry(&data));
        assert!(r.is_ok(), "{target}: {} panicked", path.display());
        n += 1;
    }
    n
}

#[test]
fn fuzz_corpus_replays_without_panics() {
    let counts = [
        replay("csv_ik", |d| verne_cli::fuzz_entry::csv_rows(d, false)),
        replay("csv_fk", |d| verne_cli::fuzz_entry::csv_rows(d, true)),
        replay("csv_tool", verne_cli::fuzz_entry::csv_tool_rows),
        replay("machine_file", verne_cli::fuzz_entry::machine_file),
        replay("apt_file", verne_cli::fuzz_entry::apt_file),
        replay("gcode_file", verne_cli::fuzz_entry::gcode_file),
        replay("arg_values", verne_cli::fuzz_entry::arg_values),
        replay("recording", verne_cli::fuzz_entry::recording),
    ];
    for c in counts {
        assert!(c > 0, "every target has a corpus");
    }
}
