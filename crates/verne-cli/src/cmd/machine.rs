//! `verne machine show|check`: the default machine file, and validation of a user's file.

use crate::error::VerneError;
use verne::spec::DEFAULT_MACHINE_TOML;

use super::{EXIT_FATAL, EXIT_OK, Mechanism, load_mechanism, write_stdout};
use crate::cli::MachineCommand;
use verne::glider::GliderSpec;
use verne::verify::Thresholds;

pub fn run(cmd: &MachineCommand) -> Result<u8, VerneError> {
    match cmd {
        MachineCommand::Show { base } => {
            let text = match base.as_str() {
                "verne" => DEFAULT_MACHINE_TOML.to_string(),
                name => match GliderSpec::preset(name) {
                    Some(g) => g.to_toml_string(),
                    None => {
                        return Err(VerneError::Usage(format!(
                            "--base {name}: the presets are verne, biglide1, biglide2, orthoglide"
                        )));
                    }
                },
            };
            write_stdout(&text)?;
            Ok(EXIT_OK)
        }
        MachineCommand::Check { files } => {
            // Every file is checked; the first invalid one's problems are the error, the
            // others are reported as they come.
            let mut first_error = None;
            for file in files {
                match check(file) {
                    Ok(line) => write_stdout(&line)?,
                    Err(e) if files.len() == 1 => return Err(e),
                    Err(e) => {
                        sayln!("verne: error: {e}");
                        first_error.get_or_insert(e);
                    }
                }
            }
            match first_error {
                None => Ok(EXIT_OK),
                Some(_) => Ok(EXIT_FATAL),
            }
        }
    }
}

/// One machine file checked: `FILE: valid machine NAME`, or its problems.
fn check(file: &std::path::Path) -> Result<String, VerneError> {
    let name = file.display().to_string();
    match load_mechanism(Some(file))? {
        Mechanism::Verne(m) => {
            // The [verify] thresholds too: a file that verify would refuse is not valid.
            let thresholds = Thresholds::from_machine(&m, &name)?;
            thresholds
                .check()
                .map_err(|e| VerneError::input(&name, None, Some("verify"), e))?;
            Ok(format!("{name}: valid machine `{}`\n", m.name))
        }
        Mechanism::Glider(g) => Ok(format!("{name}: valid glider `{}`\n", g.name)),
    }
}
