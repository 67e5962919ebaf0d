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
    let _ = render_page(&mut out, &cmd);
    String::from_utf8_lossy(&out).into_owned()
}

/// One page for the whole command: its subcommands are sections of it (`VERNE IK`, ...), not
/// pages of their own, so the list of subcommands names those sections.
fn render_page(out: &mut Vec<u8>, cmd: &clap::Command) -> std::io::Result<()> {
    use std::io::Write;
    let man = clap_mangen::Man::new(cmd.clone());
    man.render_title(out)?;
    man.render_name_section(out)?;
    man.render_synopsis_section(out)?;
    man.render_description_section(out)?;
    man.render_options_section(out)?;
    let subs: Vec<&clap::Command> = cmd
        .get_subcommands()
        .filter(|s| !s.is_hide_set() && s.get_name() != "help")
        .collect();
    writeln!(out, ".SH SUBCOMMANDS")?;
    for sub in &subs {
        let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
        writeln!(
            out,
            ".TP\n\\fBverne {}\\fR\n{} (section VERNE {} below)",
            sub.get_name(),
            roff_text(&about),
            sub.get_name().to_uppercase()
        )?;
    }
    man.render_extra_section(out)?;
    for sub in subs {
        writeln_section(out, sub)?;
    }
    man.render_version_section(out)
}

/// Text as roff reads it: backslashes and hyphens escaped, no line starting with a control
/// character.
fn roff_text(s: &str) -> String {
    let t = s.replace('\\', "\\e").replace('-', "\\-");
    if t.starts_with('.') || t.starts_with('\'') {
        format!("\\&{t}")
    } else {
        t
    }
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
