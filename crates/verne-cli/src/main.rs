//! The `verne` binary: everything is in the library ([`verne_cli::run`]).

fn main() -> std::process::ExitCode {
    verne_cli::run()
}
