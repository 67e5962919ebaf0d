//! The parallel module's inverse and forward kinematics as row jobs for the streaming engine
//! (`verne ik` / `verne fk` on `xp,yp,zp` and `rho1,rho2,rho3` columns).

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::engine::pipeline::{Cell, RowJob, RowOutcome, RowWriter};
use crate::error::VerneError;
use verne::parallel_module::branches::{Config, Verdict};
use verne::parallel_module::fk::{self, FkMode, FkModes};
use verne::parallel_module::ik::{self, IkBranch, IkBranches};
use verne::parallel_module::track::FkTracker;
use verne::spec::Machine;

/// Module IK as a row job, every branch of each point (`verne ik --all`).
pub struct ModuleIkAll {
    pub machine: Machine,
}

/// Module IK as a row job, the working branch of each point (`verne ik`).
pub struct ModuleIkWorking {
    pub machine: Machine,
}

const IK_INPUTS: &[(&str, bool)] = &[("xp", false), ("yp", false), ("zp", false)];
const IK_OUT_WORKING: &[&str] = &["alpha", "rho1", "rho2", "rho3", "status"];
const IK_OUT_ALL: &[&str] = &[
    "branch", "alpha", "rho1", "rho2", "rho3", "s1", "s2", "s3", "working", "status",
];

/// The point of a row's inputs.
fn point(v: &[f64]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// The written values of an IK branch.
fn ik_parts(b: &IkBranch) -> ([Cell; 4], Config, Verdict) {
    let values = [
        Cell::Angle(b.alpha),
        Cell::Num(b.rho.x),
        Cell::Num(b.rho.y),
        Cell::Num(b.rho.z),
    ];
    (values, b.config, b.verdict)
}

impl RowJob for ModuleIkAll {
    type Solved = IkBranches;

    fn inputs(&self) -> &[(&'static str, bool)] {
        IK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        IK_OUT_ALL
    }

    fn solve(&self, inputs: &[f64], solved: &mut IkBranches) {
        ik::solve_into(&self.machine, &point(inputs), solved);
    }

    /// A run's rows a few side by side ([`ik::solve_each`]).
    fn solve_run<'a>(&self, rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut IkBranches)>)
    where
        IkBranches: 'a,
    {
        ik::solve_each(
            &self.machine,
            rows.filter_map(|(v, solved)| Some((point(v?), solved))),
        );
    }

    fn emit(&mut self, b: &IkBranches, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        emit_every(out, b, b.certificate.proved(), ik_parts)
    }
}

impl RowJob for ModuleIkWorking {
    type Solved = Working<IkBranch>;

    fn inputs(&self) -> &[(&'static str, bool)] {
        IK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        IK_OUT_WORKING
    }

    fn solve(&self, inputs: &[f64], solved: &mut Working<IkBranch>) {
        let mut branches = IkBranches::new();
        ik::solve_working_into(&self.machine, &point(inputs), &mut branches);
        *solved = Working::of_ik(&branches);
    }

    /// A run's rows [`ik::LANES`] side by side ([`ik::solve_working_each`]), each
    /// into a scratch list and kept as [`Working`].
    fn solve_run<'a>(
        &self,
        rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut Working<IkBranch>)>,
    ) where
        Working<IkBranch>: 'a,
    {
        let mut present = rows.filter_map(|(v, solved)| Some((point(v?), solved)));
        let mut scratch: [IkBranches; ik::LANES] = Default::default();
        loop {
            let group: ArrayVec<_, { ik::LANES }> = present.by_ref().take(ik::LANES).collect();
            if group.is_empty() {
                return;
            }
            ik::solve_working_each(
                &self.machine,
                group.iter().map(|(p, _)| *p).zip(scratch.iter_mut()),
            );
            for ((_, solved), branches) in group.into_iter().zip(&scratch) {
                *solved = Working::of_ik(branches);
            }
        }
    }

    fn emit(
        &mut self,
        w: &Working<IkBranch>,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        emit_working(out, w.found(), ik_parts)
    }
}

/// What is written of a row without `--all`: its working branch, or why it has none (kept in a
/// batch instead of every branch, a few dozen bytes instead of a kilobyte per row, so that the
/// batches in flight stay in the processor's cache).
#[derive(Debug, Clone, Copy)]
pub enum Working<T> {
    Found(T),
    /// The status written instead ([`missing_status`]).
    Missing(Cell),
}

impl<T> Default for Working<T> {
    fn default() -> Working<T> {
        Working::Missing(Cell::Str("unreachable"))
    }
}

impl<T: Copy> Working<T> {
    /// The working branch of `branches` (`working`), or the status that says why there is none.
    pub fn of(
        branches: &[T],
        working: Option<&T>,
        proved: bool,
        verdict: impl Fn(&T) -> Verdict,
    ) -> Working<T> {
        match working {
            Some(w) => Working::Found(*w),
            None => Working::Missing(missing_status(
                branches.iter().map(verdict),
                branches.is_empty(),
                proved,
            )),
        }
    }

    /// The branch, or the status written instead.
    pub fn found(&self) -> Result<&T, Cell> {
        match self {
            Working::Found(b) => Ok(b),
            Working::Missing(status) => Err(*status),
        }
    }
}

impl Working<IkBranch> {
    fn of_ik(branches: &IkBranches) -> Working<IkBranch> {
        Working::of(
            branches,
            ik::working(branches),
            branches.certificate.proved(),
            |b| b.verdict,
        )
    }
}

impl Working<FkMode> {
    fn of_fk(modes: &FkModes) -> Working<FkMode> {
        Working::of(modes, fk::working(modes), modes.certificate.proved(), |m| {
            m.verdict
        })
    }
}

/// One row per branch (`branch`, values, `s1,s2,s3`, `working`, `status`), or one
/// `unreachable` row when there is none (`uncertified` when the solver could not prove that).
pub fn emit_every<T, const N: usize>(
    out: &mut RowWriter<'_>,
    branches: &[T],
    proved: bool,
    parts: impl Fn(&T) -> ([Cell; N], Config, Verdict),
) -> Result<RowOutcome, VerneError> {
    let mut cells = ArrayVec::<Cell, 24>::new();
    if branches.is_empty() {
        let status = Cell::Str(if proved { "unreachable" } else { "uncertified" });
        cells.extend(std::iter::repeat_n(Cell::Empty, N + 5));
        cells.push(status);
        out.row(&cells)?;
        return Ok(RowOutcome { ok: false, status });
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
    Ok(RowOutcome {
        ok: proved,
        status: Cell::Str(if proved { "ok" } else { "uncertified" }),
    })
}

/// The working branch's values and `ok`, or empty values and the status that says why there is
/// none (`found`'s error).
pub fn emit_working<T, const N: usize>(
    out: &mut RowWriter<'_>,
    found: Result<&T, Cell>,
    parts: impl Fn(&T) -> ([Cell; N], Config, Verdict),
) -> Result<RowOutcome, VerneError> {
    let mut cells = ArrayVec::<Cell, 24>::new();
    let (ok, status) = match found {
        Ok(w) => {
            cells.extend(parts(w).0);
            (true, Cell::Str("ok"))
        }
        Err(status) => {
            cells.extend(std::iter::repeat_n(Cell::Empty, N));
            (false, status)
        }
    };
    cells.push(status);
    out.row(&cells)?;
    Ok(RowOutcome { ok, status })
}

/// Why a row has no working branch: `unreachable` (no real branch; `uncertified` when that
/// could not be proved), the failed limits of the machine-type branch when only limits fail
/// (`uncertified` among them for an unproved row), or `no_working_branch`.
pub fn missing_status(verdicts: impl Iterator<Item = Verdict>, empty: bool, proved: bool) -> Cell {
    if empty {
        return Cell::Str(if proved { "unreachable" } else { "uncertified" });
    }
    let mut limits_only = verdicts.filter(|v| v.only_limits());
    match limits_only.next() {
        Some(v) => Cell::Verdict(v),
        None => Cell::Str("no_working_branch"),
    }
}

/// Module FK as a row job, every assembly mode of each slider row (`verne fk --all`).
pub struct ModuleFkAll {
    pub machine: Machine,
}

/// Module FK as a row job, the working assembly mode of each slider row (`verne fk`), followed
/// from row to row within a run ([`FkTracker`]).
pub struct ModuleFkWorking {
    pub machine: Machine,
}

const FK_INPUTS: &[(&str, bool)] = &[("rho1", false), ("rho2", false), ("rho3", false)];
const FK_OUT_WORKING: &[&str] = &["xp", "yp", "zp", "alpha", "status"];
const FK_OUT_ALL: &[&str] = &[
    "branch", "xp", "yp", "zp", "alpha", "s1", "s2", "s3", "working", "status",
];

/// The written values of an assembly mode.
fn fk_parts(m: &FkMode) -> ([Cell; 4], Config, Verdict) {
    let values = [
        Cell::Num(m.pose.p.x),
        Cell::Num(m.pose.p.y),
        Cell::Num(m.pose.p.z),
        Cell::Angle(m.pose.alpha),
    ];
    (values, m.config, m.verdict)
}

impl RowJob for ModuleFkAll {
    type Solved = FkModes;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        FK_OUT_ALL
    }

    fn solve(&self, inputs: &[f64], solved: &mut FkModes) {
        *solved = fk::solve(&self.machine, &point(inputs));
    }

    fn emit(&mut self, modes: &FkModes, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        emit_every(out, modes, modes.certificate.proved(), fk_parts)
    }
}

impl RowJob for ModuleFkWorking {
    type Solved = Working<FkMode>;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        FK_OUT_WORKING
    }

    fn solve(&self, inputs: &[f64], solved: &mut Working<FkMode>) {
        *solved = Working::of_fk(&fk::solve(&self.machine, &point(inputs)));
    }

    /// The working mode is followed from row to row within a run ([`FkTracker`]), each row's
    /// modes into one scratch list.
    fn solve_run<'a>(
        &self,
        rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut Working<FkMode>)>,
    ) where
        Working<FkMode>: 'a,
    {
        let mut tracker = FkTracker::new(&self.machine);
        let mut modes = FkModes::new();
        for (inputs, solved) in rows {
            if let Some(v) = inputs {
                tracker.working_into(&point(v), &mut modes);
                *solved = Working::of_fk(&modes);
            }
        }
    }

    fn emit(
        &mut self,
        w: &Working<FkMode>,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        emit_working(out, w.found(), fk_parts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::pipeline::{self, Units};
    use crate::files::Sink;
    use crate::table::CsvSource;
    use crate::table::tests::SharedBuf;
    use verne::details::lcg;

    /// What `verne ik` and `verne fk` did before [`Working`]: every branch kept per row, the
    /// working one picked when the row is written.
    struct EveryBranchKept {
        machine: Machine,
        fk: bool,
    }

    #[derive(Default)]
    struct Kept {
        ik: IkBranches,
        fk: FkModes,
    }

    impl RowJob for EveryBranchKept {
        type Solved = Kept;

        fn inputs(&self) -> &[(&'static str, bool)] {
            if self.fk { FK_INPUTS } else { IK_INPUTS }
        }

        fn outputs(&self) -> &[&'static str] {
            if self.fk {
                FK_OUT_WORKING
            } else {
                IK_OUT_WORKING
            }
        }

        fn solve(&self, _: &[f64], _: &mut Kept) {
            unreachable!("solve_run is given")
        }

        fn solve_run<'a>(&self, rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut Kept)>)
        where
            Kept: 'a,
        {
            let mut tracker = FkTracker::new(&self.machine);
            let present = rows.filter_map(|(v, kept)| Some((point(v?), kept)));
            if self.fk {
                for (rho, kept) in present {
                    tracker.working_into(&rho, &mut kept.fk);
                }
            } else {
                ik::solve_working_each(&self.machine, present.map(|(p, kept)| (p, &mut kept.ik)));
            }
        }

        fn emit(&mut self, kept: &Kept, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
            // The working branch picked here, from every branch kept, as the old emit did.
            fn picked<'a, T>(
                all: &'a [T],
                working: Option<&'a T>,
                verdict: impl Fn(&T) -> Verdict,
            ) -> Result<&'a T, Cell> {
                working.ok_or_else(|| missing_status(all.iter().map(verdict), all.is_empty(), true))
            }
            if self.fk {
                let found = picked(&kept.fk, fk::working(&kept.fk), |m| m.verdict);
                emit_working(out, found, fk_parts)
            } else {
                let found = picked(&kept.ik, ik::working(&kept.ik), |b| b.verdict);
                emit_working(out, found, ik_parts)
            }
        }
    }

    fn output_of<J: RowJob>(job: &mut J, csv: &str) -> Vec<u8> {
        let mut source =
            CsvSource::from_reader(Box::new(std::io::Cursor::new(csv.as_bytes().to_vec())), "t")
                .unwrap();
        let buf = SharedBuf::default();
        let mut sink = Sink::from_writer(Box::new(buf.clone()), "t");
        pipeline::run(job, &mut source, &mut sink, Units::default(), &|_| {}).unwrap();
        sink.finish().unwrap();
        buf.0.lock().unwrap().clone()
    }

    /// Rows of three numbers: a smooth path (tracked by the FK), random values over a wide box
    /// (many without a working branch or unreachable), a tenth with the middle one zero, a few
    /// blank; 3,000 in all, so that batches and runs are cut in several places.
    fn rows_csv(header: &str, path: impl Fn(f64) -> [f64; 3], lo: f64, hi: f64) -> String {
        let mut unit = lcg(0x51de_0001);
        let mut csv = format!("{header}\n");
        for i in 0..3000 {
            let v = match i % 3 {
                0 => path(i as f64 / 3000.0),
                _ => [0; 3].map(|_| lo + (hi - lo) * unit()),
            };
            let middle = if unit() < 0.1 { 0.0 } else { v[1] };
            if unit() < 0.01 {
                csv.push_str(&format!("{},,{}\n", v[0], v[2]));
            } else {
                csv.push_str(&format!("{},{},{}\n", v[0], middle, v[2]));
            }
        }
        csv
    }

    /// The working IK job writes, row for row and byte for byte, the working branch of every
    /// branch kept, or the same status when there is none.
    #[test]
    fn working_ik_rows_are_those_of_every_branch_kept() {
        let machine = Machine::default_verne();
        let helix = |f: f64| {
            let t = std::f64::consts::TAU * 3.0 * f;
            [
                -250.0 + 120.0 * t.cos(),
                120.0 * t.sin(),
                1000.0 + 300.0 * f,
            ]
        };
        let csv = rows_csv("xp,yp,zp", helix, -900.0, 1700.0);
        let ours = output_of(
            &mut ModuleIkWorking {
                machine: machine.clone(),
            },
            &csv,
        );
        let kept = output_of(&mut EveryBranchKept { machine, fk: false }, &csv);
        assert!(ours.len() > 3000 * 10);
        assert_eq!(
            String::from_utf8(ours).unwrap(),
            String::from_utf8(kept).unwrap()
        );
    }

    /// The working FK job (tracked from row to row) writes what keeping every mode wrote.
    #[test]
    fn working_fk_rows_are_those_of_every_mode_kept() {
        let machine = Machine::default_verne();
        let sliders = |f: f64| {
            let t = std::f64::consts::TAU * 3.0 * f;
            let p = Vector3::new(
                -250.0 + 120.0 * t.cos(),
                120.0 * t.sin(),
                1000.0 + 300.0 * f,
            );
            let b = ik::solve(&machine, &p);
            let rho = ik::working(&b).map_or(Vector3::new(700.0, 700.0, 700.0), |w| w.rho);
            [rho.x, rho.y, rho.z]
        };
        let csv = rows_csv("rho1,rho2,rho3", sliders, 200.0, 1500.0);
        let ours = output_of(
            &mut ModuleFkWorking {
                machine: machine.clone(),
            },
            &csv,
        );
        let kept = output_of(&mut EveryBranchKept { machine, fk: true }, &csv);
        assert!(ours.len() > 3000 * 10);
        assert_eq!(
            String::from_utf8(ours).unwrap(),
            String::from_utf8(kept).unwrap()
        );
    }
}
