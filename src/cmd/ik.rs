//! `verne ik`: platform points -> joints of the parallel module (IFToMM 2007, section V).

use verne::error::VerneError;
use verne::module_rows::ModuleIk;

use super::{inline_source, load_machine, run_rows, units};
use crate::cli::IkArgs;
use verne::table::CsvSource;

pub fn run(args: &IkArgs) -> Result<u8, VerneError> {
    if let Some(spec) = super::glider::load(args.common.machine.as_deref())? {
        return super::glider::ik(args, spec);
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let source = if args.pose.is_empty() {
        CsvSource::open(args.input.as_deref())?
    } else {
        inline_source("xp,yp,zp", &args.pose)?
    };
    let mut job = ModuleIk {
        machine,
        all: args.all,
    };
    run_rows(
        "ik",
        &mut job,
        source,
        args.output.as_ref(),
        units(&args.common),
    )
}
