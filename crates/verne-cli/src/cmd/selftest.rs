//! `verne selftest`: round trips of the kinematics over a grid of joints and over poses built on
//! the solvers' degenerate sets, for a machine file.

use crate::error::VerneError;
use verne::selftest;

use super::{EXIT_OK, EXIT_ROWS_FAILED, Mechanism, load_mechanism, write_stdout};
use crate::cli::SelftestArgs;

pub fn run(args: &SelftestArgs) -> Result<u8, VerneError> {
    let machine = match load_mechanism(args.machine.as_deref())? {
        Mechanism::Verne(m) => m,
        Mechanism::Glider(spec) => {
            return Err(VerneError::Usage(format!(
                "selftest checks the VERNE machine's spatial solvers over its joint strokes; `{}` is a planar glider, whose closed-form kinematics are checked by `verne design` (Tables 1 and 2) and the test suite (docs/gliders.md)",
                spec.name
            )));
        }
    };
    let n = usize::from(args.grid);
    let start = std::time::Instant::now();
    let r = selftest::run(&machine, n);
    let mut text = format!(
        "selftest of machine `{}`: a {n}x{n}x{n} grid of joints spanning the strokes, and poses \
         built on the solvers' degenerate sets ({:.1} s)\n\
         joint sets                      {}\n\
         forward assembly modes          {}\n\
         inverse branches of those poses {}\n\
         poses on degenerate sets        {} ({} missing from their sliders' modes)\n\
         solutions not proved complete   {}\n\
         worst residual of eqs. (3)-(6)  {:.3e} mm\n\
         worst fk -> ik return           {:.3e} mm ({} misses)\n\
         worst ik -> fk return           {:.3e} mm ({} misses)\n",
        machine.name,
        start.elapsed().as_secs_f64(),
        r.joint_sets,
        r.fk_modes,
        r.ik_branches,
        r.hard_poses,
        r.hard_misses,
        r.uncertified,
        r.worst_residual_mm,
        r.worst_fk_ik_mm,
        r.fk_ik_misses,
        r.worst_ik_fk_mm,
        r.ik_fk_misses,
    );
    if let Some(why) = r.untested() {
        text.push_str(&format!("FAIL: {why}\n"));
    } else if r.passed() {
        text.push_str(&format!(
            "PASS (tolerance {:e} mm)\n",
            selftest::RETURN_TOL_MM
        ));
    } else {
        text.push_str(&format!(
            "FAIL (tolerance {:e} mm); the first failures, to reproduce with `verne modes`:\n",
            selftest::RETURN_TOL_MM
        ));
        for f in &r.failures {
            text.push_str(&format!("  {f}\n"));
        }
    }
    write_stdout(&text)?;
    Ok(if r.passed() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}
