//! Command-line definitions (clap derive). The `///` comments are the help text.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

const EXIT_CODES: &str = "\
Exit codes:
  0  success: every row ok (every check passed)
  1  the run finished, but some row is not ok (or a check failed)
  2  fatal: bad arguments, unreadable or malformed input or machine file";

/// Exact kinematics of the VERNE 5-axis parallel kinematic machine tool (and planar glider
/// mechanisms): joint tables from toolpaths, every inverse and forward branch, workspaces.
#[derive(Debug, Parser)]
#[command(name = "verne", version, after_help = EXIT_CODES, max_term_width = 100)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Inverse kinematics: platform points (xp,yp,zp) -> joints (alpha, rho1, rho2, rho3).
    #[command(
        after_help = "Example:\n  verne ik data/path.csv -o joints.csv\n  verne ik --all --radians --pose=-240,-86,1000\n\nInput columns: xp,yp,zp (mm). Output adds alpha,rho1,rho2,rho3,status\n(--all: branch,alpha,rho1,rho2,rho3,s1,s2,s3,working,status).\n\nExit codes: 0 all rows ok, 1 some row not ok, 2 fatal."
    )]
    Ik(IkArgs),
    /// Forward kinematics: joints (rho1,rho2,rho3) -> platform pose (xp, yp, zp, alpha).
    #[command(
        after_help = "Example:\n  verne fk joints.csv\n  verne fk --all --radians --joints 674,685,250\n  verne ik path.csv | verne fk\n\nInput columns: rho1,rho2,rho3 (mm). Output adds xp,yp,zp,alpha,status\n(--all: branch,xp,yp,zp,alpha,s1,s2,s3,working,status).\n\nExit codes: 0 all rows ok, 1 some row not ok, 2 fatal."
    )]
    Fk(FkArgs),
    /// Every branch of one query, with its verdict, as a table for a person (or --csv).
    #[command(
        after_help = "Example:\n  verne modes --joints 674,685,250\n  verne modes --pose=-240,-86,1000 --csv"
    )]
    Modes(ModesArgs),
    /// Show the default machine file, or check one.
    #[command(subcommand)]
    Machine(MachineCommand),
    /// Round-trip self-test of a machine file over a grid of joints: reports the worst residual.
    #[command(
        after_help = "Example:\n  verne selftest -m my_machine.toml --grid 16\n\nExit codes: 0 every round trip returned, 1 some did not, 2 fatal."
    )]
    Selftest(SelftestArgs),
    /// Print a shell completion script.
    #[command(
        after_help = "Example:\n  verne completions bash > ~/.local/share/bash-completion/completions/verne"
    )]
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff), as kept in docs/verne.1.
    #[command(hide = true)]
    Manpage,
}

/// Options shared by the row commands.
#[derive(Debug, Args)]
pub struct CommonArgs {
    /// Machine file (TOML, or CSV with a `key,value` header). Default: the embedded VERNE machine.
    #[arg(short = 'm', long = "machine", value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Angles in radians instead of degrees (input and output).
    #[arg(long)]
    pub radians: bool,
    /// Write numbers with this many decimals (default: shortest exact form).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=17))]
    pub precision: Option<u8>,
}

#[derive(Debug, Args)]
pub struct IkArgs {
    /// Input CSV with columns xp,yp,zp (mm); absent or `-` reads stdin.
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// One point XP,YP,ZP instead of an input file (repeatable). Use `--pose=-240,-86,1000`
    /// for negative values.
    #[arg(long, value_name = "XP,YP,ZP", value_parser = parse_triple, conflicts_with = "input")]
    pub pose: Vec<[f64; 3]>,
    /// Output CSV (written atomically); absent or `-` writes stdout.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Every real branch, one row each, instead of the machine's working branch.
    #[arg(long)]
    pub all: bool,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct FkArgs {
    /// Input CSV with columns rho1,rho2,rho3 (mm); absent or `-` reads stdin.
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// One set of joints R1,R2,R3 instead of an input file (repeatable).
    #[arg(long, value_name = "R1,R2,R3", value_parser = parse_triple, conflicts_with = "input")]
    pub joints: Vec<[f64; 3]>,
    /// Output CSV (written atomically); absent or `-` writes stdout.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Every real assembly mode, one row each, instead of the machine's working mode.
    #[arg(long)]
    pub all: bool,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Args)]
pub struct ModesArgs {
    /// A platform point XP,YP,ZP: every inverse branch.
    #[arg(long, value_name = "XP,YP,ZP", value_parser = parse_triple, required_unless_present = "joints", conflicts_with = "joints")]
    pub pose: Option<[f64; 3]>,
    /// Slider positions R1,R2,R3: every assembly mode.
    #[arg(long, value_name = "R1,R2,R3", value_parser = parse_triple)]
    pub joints: Option<[f64; 3]>,
    /// CSV for a script instead of an aligned table.
    #[arg(long)]
    pub csv: bool,
    #[command(flatten)]
    pub common: CommonArgs,
}

#[derive(Debug, Subcommand)]
pub enum MachineCommand {
    /// Print the default machine file (a template to edit).
    Show,
    /// Validate a machine file and report every problem.
    Check {
        /// The machine file (TOML or key,value CSV).
        file: PathBuf,
    },
}

/// Parses `a,b,c` into three finite numbers.
pub fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected three comma-separated numbers like 1,2,3, found {} value{}",
            parts.len(),
            if parts.len() == 1 { "" } else { "s" }
        ));
    }
    let mut out = [0.0; 3];
    for (k, p) in parts.iter().enumerate() {
        match p.parse::<f64>() {
            Ok(v) if v.is_finite() => out[k] = v,
            Ok(_) => return Err(format!("value {} `{p}` is not a finite number", k + 1)),
            Err(_) => return Err(format!("value {} `{p}` is not a number", k + 1)),
        }
    }
    Ok(out)
}

#[derive(Debug, Args)]
pub struct SelftestArgs {
    /// Machine file (default: the embedded VERNE machine).
    #[arg(short = 'm', long = "machine", value_name = "FILE")]
    pub machine: Option<PathBuf>,
    /// Grid points per slider axis (the grid spans the strokes: N^3 joint sets).
    #[arg(long, value_name = "N", default_value_t = 12, value_parser = clap::value_parser!(u16).range(2..=200))]
    pub grid: u16,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn cli_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn triples_parse_or_explain() {
        assert_eq!(parse_triple("1, -2.5,3e2"), Ok([1.0, -2.5, 300.0]));
        assert!(parse_triple("1,2").unwrap_err().contains("three"));
        assert!(parse_triple("1,x,3").unwrap_err().contains("value 2"));
        assert!(parse_triple("1,inf,3").unwrap_err().contains("finite"));
    }
}
