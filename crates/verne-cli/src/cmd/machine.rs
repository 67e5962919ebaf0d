//! `verne machine show|check`: the default machine file, and validation of a user's file.

use crate::error::VerneError;
use verne::spec::DEFAULT_MACHINE_TOML;

use super::{EXIT_OK, load_machine, write_stdout};
use crate::cli::MachineCommand;

pub fn run(cmd: &MachineCommand) -> Result<u8, VerneError> {
    match cmd {
        MachineCommand::Show => {
            write_stdout(DEFAULT_MACHINE_TOML)?;
            Ok(EXIT_OK)
        }
        MachineCommand::Check { file } => {
            let m = load_machine(Some(file))?;
            write_stdout(&format!("{}: valid machine `{}`\n", file.display(), m.name))?;
            Ok(EXIT_OK)
        }
    }
}
