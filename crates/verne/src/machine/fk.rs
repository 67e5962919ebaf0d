//! Forward kinematics of the whole machine (AIM 2007, section III.D): the module's assembly
//! modes, then eq. (26) for the tool pose in R_t.

use nalgebra::Vector3;

use crate::certificate::Certified;
use crate::parallel_module::branches::{Config, Reason, Verdict};
use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::spec::Machine;

/// Largest number of assembly modes returned by the forward kinematics (that of the module).
pub const MAX_MACHINE_FK_MODES: usize = crate::parallel_module::fk::MAX_FK_MODES;

/// One assembly mode of the machine's forward kinematics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineFkMode {
    /// Tool tip and (phi1, phi2) = (alpha - theta1, -theta2), both wrapped to (-pi, pi].
    pub tool: ToolPose,
    /// Tool axis (i, j, k) in R_t, tip towards spindle.
    pub axis: Vector3<f64>,
    /// The module's pose (P in the base frame, alpha).
    pub module: ModulePose,
    /// Configuration indices of the module.
    pub config: Config,
    /// Module verdict plus [`Reason::Theta1Range`].
    pub verdict: Verdict,
}

impl MachineFkMode {
    /// True when the machine can be in this mode (every check passes).
    pub fn working(&self) -> bool {
        self.verdict.feasible()
    }
}

/// Every assembly mode of the machine for one set of joints, with the module's certificate.
pub type MachineFkModes = Certified<MachineFkMode, MAX_MACHINE_FK_MODES>;
use super::transforms::tool_pose_eq26;
use super::{ToolPose, theta1_in_limits};

/// Every assembly mode of the machine for the joints (AIM 2007, section III.D): the module's
/// forward kinematics, then eq. (26) for the tool pose in R_t. Ordered as the module's modes.
pub fn machine_fk(
    m: &Machine,
    rho: &Sliders,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> MachineFkModes {
    let mut out = MachineFkModes::new();
    if !(theta1.is_finite() && theta2.is_finite() && tool_length.is_finite()) {
        return out;
    }
    let modes = crate::parallel_module::fk::solve(m, rho);
    out.certificate = modes.certificate;
    for mode in modes {
        let tool = tool_pose_eq26(&m.table, &mode.pose, theta1, theta2, tool_length);
        let mut verdict = mode.verdict;
        if !theta1_in_limits(m, theta1) {
            verdict.add(Reason::Theta1Range);
        }
        out.push(MachineFkMode {
            tool,
            axis: crate::machine::orientation::tool_axis(tool.phi1, tool.phi2),
            module: mode.pose,
            config: mode.config,
            verdict,
        });
    }
    out
}
