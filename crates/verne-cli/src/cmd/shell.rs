//! `verne completions SHELL` and the man page, both generated from the clap definitions.

use crate::error::VerneError;
use clap::CommandFactory;

use super::EXIT_OK;
use crate::cli::Cli;

pub fn completions(shell: clap_complete::Shell) -> Result<u8, VerneError> {
    let mut out = Vec::new();
    clap_complete::generate(shell, &mut Cli::command(), "verne", &mut out);
    super::write_stdout(&String::from_utf8_lossy(&out))?;
    Ok(EXIT_OK)
}

/// The roff man page of `verne` and its subcommands.
pub fn manpage_text() -> String {
    let cmd = Cli::command();
    let mut out = Vec::new();
    let _ = clap_mangen::Man::new(cmd.clone()).render(&mut out);
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        let _ = writeln_section(&mut out, sub);
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn writeln_section(out: &mut Vec<u8>, sub: &clap::Command) -> std::io::Result<()> {
    use std::io::Write;
    writeln!(out, ".SH \"VERNE {}\"", sub.get_name().to_uppercase())?;
    let mut page = Vec::new();
    let man = clap_mangen::Man::new(sub.clone());
    man.render_description_section(&mut page)?;
    man.render_options_section(&mut page)?;
    man.render_extra_section(&mut page)?;
    // Demote the sub-page's own section headings.
    let text = String::from_utf8_lossy(&page).replace(".SH ", ".SS ");
    out.write_all(text.as_bytes())
}

pub fn manpage() -> Result<u8, VerneError> {
    super::write_stdout(&manpage_text())?;
    Ok(EXIT_OK)
}
