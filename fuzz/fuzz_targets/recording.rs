#![no_main]
//! Fuzz target: see verne_cli::fuzz_entry.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    verne_cli::fuzz_entry::recording(data);
});
