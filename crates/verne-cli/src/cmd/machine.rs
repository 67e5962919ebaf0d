//! `verne machine show|check`: the default machine file, and validation of a user's file.

use crate::error::VerneError;
use verne::spec::DEFAULT_MACHINE_TOML;

use super::{EXIT_OK, Mechanism, load_mechanism, write_stdout};
use crate::cli::MachineCommand;
use verne::verify::Thresholds;

pub fn run(cmd: &MachineCommand) -> Result<u8, VerneError> {
    match cmd {
        MachineCommand::Show => {
            write_stdout(DEFAULT_MACHINE_TOML)?;
            Ok(EXIT_OK)
        }
        MachineCommand::Check { file } => {
            let name = file.display().to_string();
            match load_mechanism(Some(file))? {
                Mechanism::Verne(m) => {
                    // The [verify] thresholds too: a file that verify would refuse is not valid.
                    let thresholds = Thresholds::from_machine(&m, &name)?;
                    thresholds
                        .check()
                        .map_err(|e| VerneError::input(&name, None, Some("verify"), e))?;
                    write_stdout(&format!("{name}: valid machine `{}`\n", m.name))?;
                }
                Mechanism::Glider(g) => {
                    write_stdout(&format!("{name}: valid glider `{}`\n", g.name))?;
                }
            }
            Ok(EXIT_OK)
        }
    }
}
