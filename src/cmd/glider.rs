//! The glider mechanisms (`-m biglide1|biglide2|orthoglide` or a `kind = "glider"` file) under
//! the same subcommands as the VERNE machine.

use std::path::Path;

use verne::error::VerneError;
use verne::glider::GliderSpec;

use crate::cli::{FkArgs, IkArgs, ModesArgs};

/// The glider named by `-m`: a preset name (when no file of that name exists) or a file whose
/// `kind` is "glider". `None` for a VERNE machine.
pub fn load(machine: Option<&Path>) -> Result<Option<GliderSpec>, VerneError> {
    let Some(p) = machine else { return Ok(None) };
    if !p.exists() {
        return Ok(p.to_str().and_then(GliderSpec::preset));
    }
    let name = p.display().to_string();
    let text = std::fs::read_to_string(p).map_err(|e| VerneError::io(&name, e))?;
    let is_glider = text.lines().any(|l| {
        let l = l.trim().replace(' ', "");
        l == "kind=\"glider\"" || l == "kind,glider"
    });
    if !is_glider {
        return Ok(None);
    }
    GliderSpec::from_toml_str(&text, &name)
        .map(Some)
        .map_err(|e| VerneError::input(&name, None, None, e.to_string()))
}

pub fn ik(_args: &IkArgs, _spec: GliderSpec) -> Result<u8, VerneError> {
    Err(VerneError::Usage("glider inverse kinematics from the command line: being wired".into()))
}

pub fn fk(_args: &FkArgs, _spec: GliderSpec) -> Result<u8, VerneError> {
    Err(VerneError::Usage("glider forward kinematics from the command line: being wired".into()))
}

pub fn modes(_args: &ModesArgs, _spec: GliderSpec) -> Result<u8, VerneError> {
    Err(VerneError::Usage("glider modes from the command line: being wired".into()))
}
