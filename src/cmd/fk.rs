//! `verne fk`: joints -> platform pose of the parallel module (IFToMM 2007, section VI).

use verne::error::VerneError;
use verne::module_rows::ModuleFk;
use verne::table::CsvSource;

use super::{inline_source, load_machine, run_rows, units};
use crate::cli::FkArgs;

pub fn run(args: &FkArgs) -> Result<u8, VerneError> {
    if let Some(spec) = super::glider::load(args.common.machine.as_deref())? {
        return super::glider::fk(args, spec);
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let source = if args.joints.is_empty() {
        CsvSource::open(args.input.as_deref())?
    } else {
        inline_source("rho1,rho2,rho3", &args.joints)?
    };
    let mut job = ModuleFk {
        machine,
        all: args.all,
    };
    run_rows(
        "fk",
        &mut job,
        source,
        args.output.as_ref(),
        units(&args.common),
    )
}
