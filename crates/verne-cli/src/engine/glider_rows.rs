//! The glider mechanisms' row jobs (`verne ik -m GLIDER`, `verne fk -m GLIDER`): the columns
//! they read and write, over the core's glider kinematics and [`verne::glider::verdict`](mod@verne::glider::verdict).

use arrayvec::ArrayVec;
use nalgebra::{Point2, Vector2};
use verne::glider::{
    ForwardKinematics, GliderSpec, IkSolution, Verdict, WORKING_ASSEMBLY, WORKING_MODE,
    branch_label, compatible, forward_kinematics, inverse_kinematics, mode_label, verdict,
};

use crate::engine::pipeline::{Cell, RowJob, RowOutcome, RowWriter};
use crate::error::VerneError;

/// Structural singularities reported one by one on stderr before only counting them.
pub const MAX_STRUCTURAL_REPORTS: u64 = 5;

/// Glider IK as a row job.
pub struct GliderIk {
    pub spec: GliderSpec,
    pub all: bool,
}

const IK_INPUTS: &[(&str, bool)] = &[("x", false), ("y", false)];
const IK_OUT: &[&str] = &["rho1", "rho2", "status"];
const IK_OUT_ALL: &[&str] = &[
    "branch", "mode", "assembly", "rho1", "rho2", "working", "status",
];

impl RowJob for GliderIk {
    type Solved = (Point2<f64>, ArrayVec<IkSolution, 4>);

    fn inputs(&self) -> &[(&'static str, bool)] {
        IK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { IK_OUT_ALL } else { IK_OUT }
    }

    fn solve(&self, inputs: &[f64], solved: &mut Self::Solved) {
        let p = Point2::new(inputs[0], inputs[1]);
        solved.0 = p;
        solved.1.clear();
        solved.1.extend(inverse_kinematics(&self.spec, p));
    }

    fn emit(
        &mut self,
        (p, sols): &Self::Solved,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        let unreachable = RowOutcome {
            ok: false,
            status: Cell::Str("unreachable"),
        };
        if sols.is_empty() {
            let mut cells = vec![Cell::Empty; self.outputs().len()];
            *cells.last_mut().expect("status column") = Cell::Str("unreachable");
            out.row(&cells)?;
            return Ok(unreachable);
        }
        if self.all {
            for (k, s) in sols.iter().enumerate() {
                let v = verdict(&self.spec, *p, s.rho, s.mode, s.assembly);
                let labels = [mode_label(s.mode), branch_label(s.assembly)];
                branch_row(out, k, labels, [s.rho.x, s.rho.y], v)?;
            }
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        // Each strut has a `+` root or a double root whenever it reaches its guide.
        let Some(s) = sols.iter().find(|s| {
            compatible(s.mode.strut1, WORKING_MODE.strut1)
                && compatible(s.mode.strut2, WORKING_MODE.strut2)
        }) else {
            let cells = [Cell::Empty, Cell::Empty, Cell::Str("unreachable")];
            out.row(&cells)?;
            return Ok(unreachable);
        };
        let v = verdict(&self.spec, *p, s.rho, s.mode, s.assembly);
        let status = Cell::Str(v.as_str());
        let [a, b] = ok_cells(&v, [s.rho.x, s.rho.y]);
        out.row(&[a, b, status])?;
        Ok(RowOutcome { ok: v.ok(), status })
    }
}

/// Glider FK as a row job. Reports structural singularities on stderr as it meets them.
pub struct GliderFk {
    pub spec: GliderSpec,
    pub all: bool,
    /// Rows met so far at a structural singularity.
    pub structural: u64,
}

/// The joints of one row and their forward kinematics (`None` before solving).
#[derive(Default)]
pub struct FkSolved {
    rho: [f64; 2],
    fk: Option<ForwardKinematics>,
}

const FK_INPUTS: &[(&str, bool)] = &[("rho1", false), ("rho2", false)];
const FK_OUT: &[&str] = &["x", "y", "status"];
const FK_OUT_ALL: &[&str] = &["branch", "mode", "assembly", "x", "y", "working", "status"];

impl RowJob for GliderFk {
    type Solved = FkSolved;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { FK_OUT_ALL } else { FK_OUT }
    }

    fn solve(&self, inputs: &[f64], solved: &mut FkSolved) {
        solved.rho = [inputs[0], inputs[1]];
        solved.fk = Some(forward_kinematics(
            &self.spec,
            Vector2::new(inputs[0], inputs[1]),
        ));
    }

    fn emit(&mut self, s: &FkSolved, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        let rho = Vector2::new(s.rho[0], s.rho[1]);
        let n = self.outputs().len();
        let fail = |status: &'static str, out: &mut RowWriter<'_>| {
            let mut cells = vec![Cell::Empty; n];
            cells[n - 1] = Cell::Str(status);
            out.row(&cells).map(|_| RowOutcome {
                ok: false,
                status: Cell::Str(status),
            })
        };
        let sols = match &s.fk {
            None => return fail("unreachable", out),
            Some(ForwardKinematics::StructuralSingularity { centre, radius }) => {
                self.structural += 1;
                if self.structural <= MAX_STRUCTURAL_REPORTS {
                    sayln!(
                        "verne fk: rho = ({}, {}): structural singularity: C = D = ({}, {}), \
                         P is anywhere on the circle of radius {} about it",
                        s.rho[0],
                        s.rho[1],
                        centre.x,
                        centre.y,
                        radius
                    );
                }
                return fail("structural_singularity", out);
            }
            Some(ForwardKinematics::Isolated(v)) if v.is_empty() => {
                return fail("unreachable", out);
            }
            Some(ForwardKinematics::Isolated(v)) => v,
        };
        if self.all {
            for (k, f) in sols.iter().enumerate() {
                let v = verdict(&self.spec, f.p, rho, f.mode, f.assembly);
                let labels = [mode_label(f.mode), branch_label(f.assembly)];
                branch_row(out, k, labels, [f.p.x, f.p.y], v)?;
            }
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        // Two solutions are `+` and `-`; one is the double root.
        let Some(f) = sols
            .iter()
            .find(|f| compatible(f.assembly, WORKING_ASSEMBLY))
        else {
            return fail("unreachable", out);
        };
        let v = verdict(&self.spec, f.p, rho, f.mode, f.assembly);
        let status = Cell::Str(v.as_str());
        let [a, b] = ok_cells(&v, [f.p.x, f.p.y]);
        out.row(&[a, b, status])?;
        Ok(RowOutcome { ok: v.ok(), status })
    }
}

/// The computed cells of a default (one-solution) row: filled when it is ok, empty otherwise,
/// the status saying why (the contract of the VERNE machine's rows, docs/csv.md); `--all` fills
/// every branch.
fn ok_cells(v: &Verdict, values: [f64; 2]) -> [Cell; 2] {
    if v.ok() {
        values.map(Cell::Num)
    } else {
        [Cell::Empty, Cell::Empty]
    }
}

/// One `--all` row: `branch`, `mode`, `assembly`, two values, `working`, `status`.
pub(crate) fn branch_row(
    out: &mut RowWriter<'_>,
    k: usize,
    labels: [&'static str; 2],
    values: [f64; 2],
    verdict: Verdict,
) -> Result<(), VerneError> {
    out.row(&[
        Cell::Int(k as i64 + 1),
        Cell::Str(labels[0]),
        Cell::Str(labels[1]),
        Cell::Num(values[0]),
        Cell::Num(values[1]),
        Cell::Bool(verdict.ok()),
        Cell::Str(verdict.as_str()),
    ])
}
