//! The whole 5-axis machine as row jobs (`verne ik` on tool poses, `verne fk` on five joints):
//! tool tip and axis in the workpiece frame <-> (rho1, rho2, rho3, theta1, theta2).

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::engine::module_rows::{Working, emit_every, emit_working};
use crate::engine::pipeline::{Cell, RowJob, RowOutcome, RowWriter};
use crate::error::VerneError;
use verne::machine::orientation::{ToolAngles, ToolOrientation};
use verne::machine::{
    FirstRowChoice, MAX_MACHINE_IK_BRANCHES, MachineFkMode, MachineFkModes, PathCandidates,
    PathError, PathState, machine_fk, path_candidates, path_candidates_into,
};
use verne::parallel_module::branches::{Config, Verdict};
use verne::parallel_module::equations::Sliders;
use verne::spec::Machine;

/// How the tool orientation is given in the input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrientationColumns {
    /// `i,j,k`: the tool axis, tip towards spindle (CAM convention).
    Axis,
    /// `phi1,phi2`: the angles of AIM 2007 eq. (8).
    Angles,
}

impl OrientationColumns {
    /// Chooses from a header: `i,j,k` or `phi1,phi2`, exactly one of the two.
    pub fn detect(has: impl Fn(&str) -> bool) -> Result<OrientationColumns, String> {
        let axis = ["i", "j", "k"].iter().filter(|c| has(c)).count();
        let angles = ["phi1", "phi2"].iter().filter(|c| has(c)).count();
        match (axis, angles) {
            (3, 0) => Ok(OrientationColumns::Axis),
            (0, 2) => Ok(OrientationColumns::Angles),
            (0, 0) => Err(
                "tool poses need the tool axis `i,j,k` or the angles `phi1,phi2` besides `x,y,z`"
                    .into(),
            ),
            (3, 2) => Err("both `i,j,k` and `phi1,phi2` are present: keep one orientation".into()),
            _ => Err(
                "incomplete orientation columns: expected all of `i,j,k` or both `phi1,phi2`"
                    .into(),
            ),
        }
    }
}

/// Machine IK along a path (default) or every branch of every row (`all`).
pub struct MachineIk {
    pub machine: Machine,
    pub tool_length: f64,
    pub orientation: OrientationColumns,
    pub all: bool,
    pub state: PathState,
    /// Where the part sits on the table (mm, `--offset`): added to every tip read.
    pub offset: Vector3<f64>,
    /// The joints' travel over the ok rows of the path.
    pub travel: JointTravel,
}

/// Where each joint went along a path: its range over the ok rows, and how far theta2 turned.
#[derive(Debug, Clone, Default)]
pub struct JointTravel {
    pub rows: u64,
    /// rho1, rho2, rho3 (mm), theta1, theta2 (rad).
    pub min: [f64; 5],
    pub max: [f64; 5],
    /// Sum of |change of theta2| from row to row (rad).
    pub theta2_travel: f64,
    /// Rows flagged `near_rotary_singularity` (the tool axis near the rotary axis).
    pub near_rotary_singularity: u64,
    /// The servo period (s) when the rows are samples at it (`--period`): the joints' speeds
    /// are then known, the feeds having timed the samples.
    pub period: Option<f64>,
    /// Largest |change| per period of each joint (mm/s, rad/s), with `period`.
    pub max_speed: [f64; 5],
    last: Option<[f64; 5]>,
}

impl JointTravel {
    fn add(&mut self, q: [f64; 5]) {
        if self.rows == 0 {
            self.min = q;
            self.max = q;
        }
        for ((lo, hi), v) in self.min.iter_mut().zip(self.max.iter_mut()).zip(q) {
            *lo = lo.min(v);
            *hi = hi.max(v);
        }
        if let Some(last) = self.last {
            self.theta2_travel += (q[4] - last[4]).abs();
            if let Some(period) = self.period {
                for k in 0..5 {
                    self.max_speed[k] = self.max_speed[k].max((q[k] - last[k]).abs() / period);
                }
            }
        }
        self.last = Some(q);
        self.rows += 1;
    }

    /// One line for stderr: each joint's range and its margins to the machine's limits (mm and
    /// degrees; theta2 is unlimited, its turns are given instead).
    pub fn line(&self, m: &Machine) -> String {
        let l = &m.limits;
        let mut parts = Vec::new();
        for k in 0..3 {
            parts.push(format!(
                "rho{} {:.3}..{:.3} mm (margins {:.3} / {:.3})",
                k + 1,
                self.min[k],
                self.max[k],
                self.min[k] - l.rho_min[k],
                l.rho_max[k] - self.max[k]
            ));
        }
        parts.push(format!(
            "theta1 {:.3}..{:.3} deg (margins {:.3} / {:.3})",
            self.min[3].to_degrees(),
            self.max[3].to_degrees(),
            (self.min[3] - l.theta1_min).to_degrees(),
            (l.theta1_max - self.max[3]).to_degrees()
        ));
        parts.push(format!(
            "theta2 {:.3}..{:.3} deg ({:.2} turns travelled)",
            self.min[4].to_degrees(),
            self.max[4].to_degrees(),
            self.theta2_travel / std::f64::consts::TAU
        ));
        let speeds = match self.period {
            Some(_) => {
                let s = &self.max_speed;
                format!(
                    "; largest speeds rho1 {:.3}, rho2 {:.3}, rho3 {:.3} mm/s, theta1 {:.3}, theta2 {:.3} deg/s",
                    s[0],
                    s[1],
                    s[2],
                    s[3].to_degrees(),
                    s[4].to_degrees()
                )
            }
            None => String::new(),
        };
        format!(
            "joint travel over {} ok rows: {}; {} rows near the rotary-axis singularity{speeds}",
            self.rows,
            parts.join(", "),
            self.near_rotary_singularity
        )
    }
}

impl MachineIk {
    pub fn new(
        machine: Machine,
        tool_length: f64,
        orientation: OrientationColumns,
        all: bool,
        first: FirstRowChoice,
    ) -> MachineIk {
        MachineIk {
            machine,
            tool_length,
            orientation,
            all,
            state: PathState::new(first),
            offset: Vector3::zeros(),
            travel: JointTravel::default(),
        }
    }
}

const IK_AXIS_INPUTS: &[(&str, bool)] = &[
    ("x", false),
    ("y", false),
    ("z", false),
    ("i", false),
    ("j", false),
    ("k", false),
];
const IK_ANGLE_INPUTS: &[(&str, bool)] = &[
    ("x", false),
    ("y", false),
    ("z", false),
    ("phi1", true),
    ("phi2", true),
];
const IK_OUT_PATH: &[&str] = &[
    "rho1",
    "rho2",
    "rho3",
    "theta1",
    "theta2",
    "orientation",
    "flags",
    "status",
];
const IK_OUT_ALL: &[&str] = &[
    "branch",
    "orientation",
    "rho1",
    "rho2",
    "rho3",
    "theta1",
    "theta2",
    "s1",
    "s2",
    "s3",
    "working",
    "status",
];

/// One row's solve result: the tip and orientation read, and the candidates computed with no
/// previous row (recomputed in order when the axis is inside the rotary cone), kept from row to
/// row and refilled in place.
#[derive(Default)]
pub struct SolvedToolPose {
    tip: Vector3<f64>,
    orientation: Option<ToolOrientation>,
    candidates: PathCandidates,
    /// None until the row is solved; the error when it has no candidates.
    outcome: Option<Result<(), PathError>>,
}

impl MachineIk {
    fn orientation_of(&self, inputs: &[f64]) -> ToolOrientation {
        match self.orientation {
            OrientationColumns::Axis => {
                ToolOrientation::Axis(Vector3::new(inputs[3], inputs[4], inputs[5]))
            }
            OrientationColumns::Angles => ToolOrientation::Angles(ToolAngles {
                phi1: inputs[3],
                phi2: inputs[4],
            }),
        }
    }
}

impl RowJob for MachineIk {
    type Solved = SolvedToolPose;

    fn inputs(&self) -> &[(&'static str, bool)] {
        match self.orientation {
            OrientationColumns::Axis => IK_AXIS_INPUTS,
            OrientationColumns::Angles => IK_ANGLE_INPUTS,
        }
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { IK_OUT_ALL } else { IK_OUT_PATH }
    }

    fn solve(&self, inputs: &[f64], solved: &mut SolvedToolPose) {
        let tip = Vector3::new(inputs[0], inputs[1], inputs[2]) + self.offset;
        let orientation = self.orientation_of(inputs);
        solved.tip = tip;
        solved.orientation = Some(orientation);
        solved.outcome = Some(path_candidates_into(
            &self.machine,
            &tip,
            &orientation,
            self.tool_length,
            None,
            &mut solved.candidates,
        ));
    }

    fn emit(
        &mut self,
        solved: &SolvedToolPose,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        let Some(outcome) = &solved.outcome else {
            return Err(VerneError::Usage(
                "internal: row emitted before it was solved".into(),
            ));
        };
        let candidates = outcome.as_ref().map(|()| &solved.candidates);
        let recomputed;
        let reference = self.state.reference_theta2();
        let candidates = match (candidates, solved.orientation, reference) {
            (Ok(c), Some(o), Some(theta2)) if c.needs_previous() && !self.all => {
                recomputed = path_candidates(
                    &self.machine,
                    &solved.tip,
                    &o,
                    self.tool_length,
                    Some(theta2),
                );
                recomputed.as_ref()
            }
            _ => candidates,
        };
        let candidates = match candidates {
            Ok(c) => c,
            Err(e) => return bad_row(out, e, self.all),
        };
        if self.all {
            let branches: ArrayVec<_, { 2 * MAX_MACHINE_IK_BRANCHES }> =
                candidates.iter().collect();
            let proved = candidates.certificate.proved();
            return emit_every(out, &branches, proved, |(b, orientation, theta2)| {
                let values = [
                    Cell::Int((*orientation).into()),
                    Cell::Num(b.rho.x),
                    Cell::Num(b.rho.y),
                    Cell::Num(b.rho.z),
                    Cell::Angle(b.theta1),
                    Cell::Angle(*theta2),
                ];
                (values, b.config, b.verdict)
            });
        }
        match self.state.choose(candidates) {
            Ok(row) => {
                self.travel
                    .add([row.rho.x, row.rho.y, row.rho.z, row.theta1, row.theta2]);
                self.travel.near_rotary_singularity += u64::from(row.near_rotary_singularity);
                let flags = match (row.near_rotary_singularity, row.switched) {
                    (true, true) => "near_rotary_singularity;orientation_switch",
                    (true, false) => "near_rotary_singularity",
                    (false, true) => "orientation_switch",
                    (false, false) => "",
                };
                out.row(&[
                    Cell::Num(row.rho.x),
                    Cell::Num(row.rho.y),
                    Cell::Num(row.rho.z),
                    Cell::Angle(row.theta1),
                    Cell::Angle(row.theta2),
                    Cell::Int(row.orientation.into()),
                    Cell::Str(flags),
                    Cell::Str("ok"),
                ])?;
                Ok(RowOutcome {
                    ok: true,
                    status: Cell::Str("ok"),
                })
            }
            Err(e) => bad_row(out, &e, false),
        }
    }
}

/// A row with no joints: empty cells and why.
fn bad_row(out: &mut RowWriter<'_>, e: &PathError, all: bool) -> Result<RowOutcome, VerneError> {
    let status = match e {
        PathError::Axis(_) => Cell::Str("invalid_axis"),
        PathError::NoWorkingBranch {
            real_branches: 0,
            proved: true,
            ..
        } => Cell::Str("unreachable"),
        PathError::NoWorkingBranch {
            real_branches: 0,
            proved: false,
            ..
        } => Cell::Str("uncertified"),
        PathError::NoWorkingBranch {
            nearest: Some(b), ..
        } if b.verdict.only_limits() => Cell::Verdict(b.verdict),
        PathError::NoWorkingBranch { .. } => Cell::Str("no_working_branch"),
    };
    let n = if all {
        IK_OUT_ALL.len()
    } else {
        IK_OUT_PATH.len()
    };
    // The longer of the two layouts holds either.
    const _: () = assert!(IK_OUT_PATH.len() <= IK_OUT_ALL.len());
    let mut cells = [Cell::Empty; IK_OUT_ALL.len()];
    cells[n - 1] = status;
    out.row(&cells[..n])?;
    Ok(RowOutcome { ok: false, status })
}

/// Machine FK: joints -> tool tip, axis and (phi1, phi2) in the workpiece frame, every assembly
/// mode (`verne fk --all` on machine joints).
pub struct MachineFkAll {
    pub machine: Machine,
    pub tool_length: f64,
    /// Where the part sits on the table (mm, `--offset`): taken off every tip written.
    pub offset: Vector3<f64>,
}

/// Machine FK, the working assembly mode of each row (`verne fk` on machine joints).
pub struct MachineFkWorking {
    pub machine: Machine,
    pub tool_length: f64,
    /// Where the part sits on the table (mm, `--offset`): taken off every tip written.
    pub offset: Vector3<f64>,
}

const FK_INPUTS: &[(&str, bool)] = &[
    ("rho1", false),
    ("rho2", false),
    ("rho3", false),
    ("theta1", true),
    ("theta2", true),
];
const FK_OUT_WORKING: &[&str] = &["x", "y", "z", "i", "j", "k", "phi1", "phi2", "status"];
const FK_OUT_ALL: &[&str] = &[
    "branch", "x", "y", "z", "i", "j", "k", "phi1", "phi2", "s1", "s2", "s3", "working", "status",
];

/// Every assembly mode of a row of machine joints, tips in the part's frame (`offset` off).
fn machine_fk_row(
    m: &Machine,
    tool_length: f64,
    offset: &Vector3<f64>,
    inputs: &[f64],
) -> MachineFkModes {
    let rho = Sliders::new(inputs[0], inputs[1], inputs[2]);
    let mut modes = machine_fk(m, &rho, inputs[3], inputs[4], tool_length);
    for mode in modes.iter_mut() {
        mode.tool.tip -= offset;
    }
    modes
}

/// The machine's mode: the feasible one (the smallest |alpha| if several are).
fn working_machine_mode(modes: &MachineFkModes) -> Option<&MachineFkMode> {
    modes
        .iter()
        .filter(|m| m.working())
        .min_by(|a, b| a.module.alpha.abs().total_cmp(&b.module.alpha.abs()))
}

/// The written values of a machine assembly mode: tip, axis, phi1, phi2 (also `verne modes
/// --machine-joints`).
pub(crate) fn machine_fk_parts(m: &MachineFkMode) -> ([Cell; 8], Config, Verdict) {
    let values = [
        Cell::Num(m.tool.tip.x),
        Cell::Num(m.tool.tip.y),
        Cell::Num(m.tool.tip.z),
        Cell::Num(m.axis.x),
        Cell::Num(m.axis.y),
        Cell::Num(m.axis.z),
        Cell::Angle(m.tool.phi1),
        Cell::Angle(m.tool.phi2),
    ];
    (values, m.config, m.verdict)
}

impl RowJob for MachineFkAll {
    type Solved = MachineFkModes;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        FK_OUT_ALL
    }

    fn solve(&self, inputs: &[f64], solved: &mut MachineFkModes) {
        *solved = machine_fk_row(&self.machine, self.tool_length, &self.offset, inputs);
    }

    fn emit(
        &mut self,
        modes: &MachineFkModes,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        emit_every(out, modes, modes.certificate.proved(), machine_fk_parts)
    }
}

impl RowJob for MachineFkWorking {
    type Solved = Working<MachineFkMode>;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        FK_OUT_WORKING
    }

    fn solve(&self, inputs: &[f64], solved: &mut Working<MachineFkMode>) {
        let modes = machine_fk_row(&self.machine, self.tool_length, &self.offset, inputs);
        *solved = Working::of(
            &modes,
            working_machine_mode(&modes),
            modes.certificate.proved(),
            |m| m.verdict,
        );
    }

    fn emit(
        &mut self,
        w: &Working<MachineFkMode>,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        emit_working(out, w.found(), machine_fk_parts)
    }
}
