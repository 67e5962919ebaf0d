//! The parallel module's inverse and forward kinematics as row jobs for the streaming engine
//! (`verne ik` / `verne fk` on `xp,yp,zp` and `rho1,rho2,rho3` columns).

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::branches::{Config, Verdict};
use crate::error::VerneError;
use crate::fk_track::FkTracker;
use crate::machine::Machine;
use crate::module_fk::{self, FkModes};
use crate::module_ik::{self, IkBranches};
use crate::pipeline::{Cell, RowJob, RowOutcome, RowWriter};

/// Module IK as a row job: the working branch, or every branch with `--all`.
pub struct ModuleIk {
    pub machine: Machine,
    pub all: bool,
}

const IK_INPUTS: &[(&str, bool)] = &[("xp", false), ("yp", false), ("zp", false)];
const IK_OUT_WORKING: &[&str] = &["alpha", "rho1", "rho2", "rho3", "status"];
const IK_OUT_ALL: &[&str] = &[
    "branch", "alpha", "rho1", "rho2", "rho3", "s1", "s2", "s3", "working", "status",
];

impl RowJob for ModuleIk {
    type Solved = IkBranches;

    fn inputs(&self) -> &[(&'static str, bool)] {
        IK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { IK_OUT_ALL } else { IK_OUT_WORKING }
    }

    fn solve(&self, inputs: &[f64], solved: &mut IkBranches) {
        let p = Vector3::new(inputs[0], inputs[1], inputs[2]);
        if self.all {
            module_ik::solve_into(&self.machine, &p, solved);
        } else {
            module_ik::solve_working_into(&self.machine, &p, solved);
        }
    }

    /// A run's rows a few side by side: the working branch ([`module_ik::solve_working_each`]),
    /// or every branch with `--all` ([`module_ik::solve_each`]).
    fn solve_run<'a>(&self, rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut IkBranches)>)
    where
        IkBranches: 'a,
    {
        let present =
            rows.filter_map(|(v, solved)| Some((Vector3::new(v?[0], v?[1], v?[2]), solved)));
        if self.all {
            module_ik::solve_each(&self.machine, present);
        } else {
            module_ik::solve_working_each(&self.machine, present);
        }
    }

    fn emit(&mut self, b: &IkBranches, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        emit_branches(out, self.all, b, module_ik::working(b), |br| {
            let values = [
                Cell::Angle(br.alpha),
                Cell::Num(br.rho.x),
                Cell::Num(br.rho.y),
                Cell::Num(br.rho.z),
            ];
            (values, br.config, br.verdict)
        })
    }
}

/// Solves each row of a run that has its inputs, in order (rows without are left as they are).
fn solve_rows<'a, T: 'a>(
    rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut T)>,
    mut solve: impl FnMut(&[f64], &mut T),
) {
    for (inputs, solved) in rows {
        if let Some(v) = inputs {
            solve(v, solved);
        }
    }
}

/// Writes one input row's branches: with `all`, one row per branch
/// (`branch`, values, `s1,s2,s3`, `working`, `status`), or one `unreachable` row when there is
/// none; otherwise the working branch's values and `ok`, or empty values and why there is none.
pub fn emit_branches<T, const N: usize>(
    out: &mut RowWriter<'_>,
    all: bool,
    branches: &[T],
    working: Option<&T>,
    parts: impl Fn(&T) -> ([Cell; N], Config, Verdict),
) -> Result<RowOutcome, VerneError> {
    let mut cells = ArrayVec::<Cell, 24>::new();
    if all {
        if branches.is_empty() {
            cells.extend(std::iter::repeat_n(Cell::Empty, N + 5));
            cells.push(Cell::Str("unreachable"));
            out.row(&cells)?;
            return Ok(RowOutcome {
                ok: false,
                status: Cell::Str("unreachable"),
            });
        }
        for (k, b) in branches.iter().enumerate() {
            let (values, config, verdict) = parts(b);
            cells.clear();
            cells.push(Cell::Int(k as i64 + 1));
            cells.extend(values);
            cells.extend(config.iter().map(|&s| Cell::Int(s.into())));
            cells.push(Cell::Bool(verdict.feasible()));
            cells.push(Cell::Verdict(verdict));
            out.row(&cells)?;
        }
        return Ok(RowOutcome {
            ok: true,
            status: Cell::Str("ok"),
        });
    }
    if let Some(w) = working {
        cells.extend(parts(w).0);
        cells.push(Cell::Str("ok"));
        out.row(&cells)?;
        return Ok(RowOutcome {
            ok: true,
            status: Cell::Str("ok"),
        });
    }
    let status = missing_status(branches.iter().map(|b| parts(b).2), branches.is_empty());
    cells.extend(std::iter::repeat_n(Cell::Empty, N));
    cells.push(status);
    out.row(&cells)?;
    Ok(RowOutcome { ok: false, status })
}

/// Why a row has no working branch: `unreachable` (no real branch), the failed limits of the
/// machine-type branch when only limits fail, or `no_working_branch`.
pub fn missing_status(verdicts: impl Iterator<Item = Verdict>, empty: bool) -> Cell {
    if empty {
        return Cell::Str("unreachable");
    }
    let mut limits_only = verdicts.filter(|v| v.only_limits());
    match limits_only.next() {
        Some(v) => Cell::Verdict(v),
        None => Cell::Str("no_working_branch"),
    }
}

/// Module FK as a row job: the working assembly mode, or every mode with `--all`.
pub struct ModuleFk {
    pub machine: Machine,
    pub all: bool,
}

const FK_INPUTS: &[(&str, bool)] = &[("rho1", false), ("rho2", false), ("rho3", false)];
const FK_OUT_WORKING: &[&str] = &["xp", "yp", "zp", "alpha", "status"];
const FK_OUT_ALL: &[&str] = &[
    "branch", "xp", "yp", "zp", "alpha", "s1", "s2", "s3", "working", "status",
];

impl RowJob for ModuleFk {
    type Solved = FkModes;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { FK_OUT_ALL } else { FK_OUT_WORKING }
    }

    fn solve(&self, inputs: &[f64], solved: &mut FkModes) {
        *solved = module_fk::solve(
            &self.machine,
            &Vector3::new(inputs[0], inputs[1], inputs[2]),
        );
    }

    /// The working mode is followed from row to row within a run ([`FkTracker`]); `--all`
    /// solves every row completely.
    fn solve_run<'a>(&self, rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut FkModes)>)
    where
        FkModes: 'a,
    {
        let mut tracker = FkTracker::new(&self.machine);
        solve_rows(rows, |v, solved| {
            if self.all {
                self.solve(v, solved);
            } else {
                tracker.working_into(&Vector3::new(v[0], v[1], v[2]), solved);
            }
        });
    }

    fn emit(&mut self, modes: &FkModes, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        emit_branches(out, self.all, modes, module_fk::working(modes), |m| {
            let values = [
                Cell::Num(m.pose.p.x),
                Cell::Num(m.pose.p.y),
                Cell::Num(m.pose.p.z),
                Cell::Angle(m.pose.alpha),
            ];
            (values, m.config, m.verdict)
        })
    }
}
