//! `verne fk`: joints -> platform pose of the parallel module (IFToMM 2007, section VI).

use nalgebra::Vector3;
use verne::error::VerneError;
use verne::machine::Machine;
use verne::module_fk::{self, FkModes};
use verne::pipeline::{Cell, RowJob, RowOutcome, RowWriter};
use verne::table::CsvSource;

use super::ik::missing_status;
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

/// Module FK as a row job: the working assembly mode, or every mode with `--all`.
pub struct ModuleFk {
    pub machine: Machine,
    pub all: bool,
}

const INPUTS: &[(&str, bool)] = &[("rho1", false), ("rho2", false), ("rho3", false)];
const OUT_WORKING: &[&str] = &["xp", "yp", "zp", "alpha", "status"];
const OUT_ALL: &[&str] = &[
    "branch", "xp", "yp", "zp", "alpha", "s1", "s2", "s3", "working", "status",
];

impl RowJob for ModuleFk {
    type Solved = FkModes;

    fn inputs(&self) -> &[(&'static str, bool)] {
        INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { OUT_ALL } else { OUT_WORKING }
    }

    fn solve(&self, inputs: &[f64], solved: &mut FkModes) {
        *solved = module_fk::solve(
            &self.machine,
            &Vector3::new(inputs[0], inputs[1], inputs[2]),
        );
    }

    fn emit(&mut self, modes: &FkModes, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        if self.all {
            if modes.is_empty() {
                let mut cells = [Cell::Empty; 10];
                cells[9] = Cell::Str("unreachable");
                out.row(&cells)?;
                return Ok(RowOutcome {
                    ok: false,
                    status: Cell::Str("unreachable"),
                });
            }
            for (k, m) in modes.iter().enumerate() {
                out.row(&[
                    Cell::Int(k as i64 + 1),
                    Cell::Num(m.pose.p.x),
                    Cell::Num(m.pose.p.y),
                    Cell::Num(m.pose.p.z),
                    Cell::Angle(m.pose.alpha),
                    Cell::Int(m.config[0].into()),
                    Cell::Int(m.config[1].into()),
                    Cell::Int(m.config[2].into()),
                    Cell::Bool(m.working()),
                    Cell::Verdict(m.verdict),
                ])?;
            }
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        if let Some(w) = module_fk::working(modes) {
            out.row(&[
                Cell::Num(w.pose.p.x),
                Cell::Num(w.pose.p.y),
                Cell::Num(w.pose.p.z),
                Cell::Angle(w.pose.alpha),
                Cell::Str("ok"),
            ])?;
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        let status = missing_status(modes.iter().map(|m| m.verdict), modes.is_empty());
        out.row(&[Cell::Empty, Cell::Empty, Cell::Empty, Cell::Empty, status])?;
        Ok(RowOutcome { ok: false, status })
    }
}
