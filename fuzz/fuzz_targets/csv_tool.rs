#![no_main]
//! Fuzz target: see verne::fuzz_entry.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    verne::fuzz_entry::csv_tool_rows(data);
});
