//! The whole 5-axis machine's forward kinematics as row jobs (`verne fk` on five joints):
//! (rho1, rho2, rho3, theta1, theta2) -> tool tip and axis in the workpiece frame. The inverse,
//! along a toolpath, is [`crate::follow`].

use nalgebra::Vector3;

use crate::engine::module_rows::{Working, emit_every, emit_working};
use crate::engine::pipeline::{Cell, RowJob, RowOutcome, RowWriter};
use crate::error::VerneError;
use verne::machine::{MachineFkMode, MachineFkModes, machine_fk};
use verne::parallel_module::branches::{Config, Verdict};
use verne::parallel_module::equations::Sliders;
use verne::spec::Machine;

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
