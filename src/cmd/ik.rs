//! `verne ik`: platform points -> joints of the parallel module (IFToMM 2007, section V).

use nalgebra::Vector3;
use verne::error::VerneError;
use verne::machine::Machine;
use verne::module_ik::{self, IkBranches};
use verne::pipeline::{Cell, RowJob, RowOutcome, RowWriter};

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

/// Module IK as a row job: the working branch, or every branch with `--all`.
pub struct ModuleIk {
    pub machine: Machine,
    pub all: bool,
}

const INPUTS: &[(&str, bool)] = &[("xp", false), ("yp", false), ("zp", false)];
const OUT_WORKING: &[&str] = &["alpha", "rho1", "rho2", "rho3", "status"];
const OUT_ALL: &[&str] = &[
    "branch", "alpha", "rho1", "rho2", "rho3", "s1", "s2", "s3", "working", "status",
];

impl RowJob for ModuleIk {
    type Solved = IkBranches;

    fn inputs(&self) -> &[(&'static str, bool)] {
        INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { OUT_ALL } else { OUT_WORKING }
    }

    fn solve(&self, inputs: &[f64], solved: &mut IkBranches) {
        *solved = module_ik::solve(
            &self.machine,
            &Vector3::new(inputs[0], inputs[1], inputs[2]),
        );
    }

    fn emit(&mut self, b: &IkBranches, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        if self.all {
            if b.is_empty() {
                let mut cells = [Cell::Empty; 10];
                cells[9] = Cell::Str("unreachable");
                out.row(&cells)?;
                return Ok(RowOutcome {
                    ok: false,
                    status: Cell::Str("unreachable"),
                });
            }
            for (k, br) in b.iter().enumerate() {
                out.row(&[
                    Cell::Int(k as i64 + 1),
                    Cell::Angle(br.alpha),
                    Cell::Num(br.rho.x),
                    Cell::Num(br.rho.y),
                    Cell::Num(br.rho.z),
                    Cell::Int(br.config[0].into()),
                    Cell::Int(br.config[1].into()),
                    Cell::Int(br.config[2].into()),
                    Cell::Bool(br.working()),
                    Cell::Verdict(br.verdict),
                ])?;
            }
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        if let Some(w) = module_ik::working(b) {
            out.row(&[
                Cell::Angle(w.alpha),
                Cell::Num(w.rho.x),
                Cell::Num(w.rho.y),
                Cell::Num(w.rho.z),
                Cell::Str("ok"),
            ])?;
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        let status = missing_status(b.iter().map(|br| br.verdict), b.is_empty());
        out.row(&[Cell::Empty, Cell::Empty, Cell::Empty, Cell::Empty, status])?;
        Ok(RowOutcome { ok: false, status })
    }
}

/// Why a row has no working branch: `unreachable` (no real branch), the failed limits of the
/// machine-type branch when only limits fail, or `no_working_branch`.
pub fn missing_status(
    verdicts: impl Iterator<Item = verne::branches::Verdict>,
    empty: bool,
) -> Cell {
    if empty {
        return Cell::Str("unreachable");
    }
    let mut limits_only = verdicts.filter(|v| v.only_limits());
    match limits_only.next() {
        Some(v) => Cell::Verdict(v),
        None => Cell::Str("no_working_branch"),
    }
}
