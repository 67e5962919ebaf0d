//! `verne selftest`: round trips of the kinematics over a grid of joints for a machine file.

use verne::error::VerneError;
use verne::selftest;

use super::{EXIT_OK, EXIT_ROWS_FAILED, load_machine, write_stdout};
use crate::cli::SelftestArgs;

pub fn run(args: &SelftestArgs) -> Result<u8, VerneError> {
    let machine = load_machine(args.machine.as_deref())?;
    let n = usize::from(args.grid);
    let start = std::time::Instant::now();
    let r = selftest::run(&machine, n);
    let verdict = if r.passed() { "PASS" } else { "FAIL" };
    write_stdout(&format!(
        "selftest of machine `{}` on a {n}x{n}x{n} grid of joints spanning the strokes ({:.1} s)\n\
         joint sets                      {}\n\
         forward assembly modes          {}\n\
         inverse branches of those poses {}\n\
         worst residual of eqs. (3)-(6)  {:.3e} mm\n\
         worst fk -> ik return           {:.3e} mm ({} misses)\n\
         worst ik -> fk return           {:.3e} mm ({} misses)\n\
         {verdict} (tolerance {:e} mm)\n",
        machine.name,
        start.elapsed().as_secs_f64(),
        r.joint_sets,
        r.fk_modes,
        r.ik_branches,
        r.worst_residual_mm,
        r.worst_fk_ik_mm,
        r.fk_ik_misses,
        r.worst_ik_fk_mm,
        r.ik_fk_misses,
        selftest::RETURN_TOL_MM,
    ))?;
    Ok(if r.passed() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}
