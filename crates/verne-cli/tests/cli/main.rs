//! The command's tests, one module per subject, in one test binary (one link, not one per
//! file): `cargo test -p verne-cli --test cli` runs them all, `... --test cli golden::` one
//! module. Each runs the real `verne` binary from the repository root (`common`).

mod common;

mod calibrate;
mod cl_example;
mod cli;
mod cli_glider;
mod cli_hard_sets;
mod cli_machine;
mod cli_modes_machine;
mod cli_workspace;
mod docs;
mod fuzz_corpus;
mod gcode;
mod golden;
mod hostile;
mod hostile_files;
mod machine_offsets;
mod output_safety;
mod period;
mod post;
mod reports;
mod verify;
mod verify_recording;
