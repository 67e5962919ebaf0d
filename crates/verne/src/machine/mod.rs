//! Kinematics of the whole VERNE machine (AIM 2007, section III): the parallel module plus the
//! two-axis tilting table. Inverse kinematics from a tool pose in the workpiece frame R_t to
//! (rho1, rho2, rho3, theta1, theta2), forward kinematics back, and a path helper that picks one
//! branch per row continuously.
//!
//! Model (see docs/conventions-machine.md):
//! - eq. (7), AIM 2007: bT_t = trans(z, d_a) rot(x, theta1) trans(z, d_t) rot(x, pi) rot(z, theta2);
//! - eq. (8): tT_pl = trans(X, Y, Z) rot(z, phi2) rot(x, pi + phi1) trans(z, -Delta);
//! - eq. (1): bT_pl = trans(xp, yp, zp) rot(x, alpha);
//! - bT_t tT_pl = bT_pl holds iff theta2 = -phi2 (eq. (9)) and alpha = theta1 + phi1 (eq. (14));
//! - eq. (26) gives the tool pose in R_t from (xp, yp, zp, alpha, theta1, theta2).
//!
//! - [`transforms`]: the homogeneous transforms of eqs. (1), (7), (8) and the tool pose of eq.
//!   (26);
//! - [`ik`]: inverse kinematics, every real branch of a tool pose;
//! - [`fk`]: forward kinematics, every assembly mode of the joints;
//! - [`orientation`]: the tool axis and the angles (phi1, phi2);
//! - [`path`]: one branch per row along a toolpath, continuously;
//! - [`continuation`]: the branch that continues the previous joints, proved from them alone
//!   where it can be (a controller's servo loop), else from every branch.

use nalgebra::Vector3;

pub mod continuation;
pub mod fk;
pub mod ik;
pub mod intended;
pub mod orientation;
pub mod path;
pub mod transforms;

pub use continuation::{
    Continued, Fallback, NoBranch, PreviousJoints, choose_continuation, continue_branch,
    continue_locally, joint_distance,
};
pub use fk::{MAX_MACHINE_FK_MODES, MachineFkMode, MachineFkModes, machine_fk};
#[cfg(test)]
pub(crate) use ik::tilt_frame_platform;
pub use ik::{
    ALPHA_ZERO_SEED_REL, BOTH_SIGNS_SIN_ALPHA, MAX_MACHINE_IK_BRANCHES, MAX_THETA1_SOLUTIONS,
    MachineIkBranch, MachineIkBranches, machine_ik, machine_ik_into, theta1_equation,
};
pub use path::{
    FirstRowChoice, JOINT_DISTANCE_MM_PER_RAD, PathCandidates, PathError, PathRow, PathState,
    first_decided_theta2, path_candidates, path_candidates_into,
};
pub use transforms::{
    platform_transform, table_transform, tool_pose_eq26, tool_tip_by_transforms, tool_transform,
};

use crate::spec::Machine;
use crate::tolerance::LIMIT_SLACK;

/// A tool pose in the workpiece frame R_t: the tool tip (TCP, mm) and the orientation angles
/// (rad) of eq. (8), AIM 2007.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolPose {
    /// Tool tip U = (X, Y, Z) in R_t (mm).
    pub tip: Vector3<f64>,
    /// Tilt of the tool from the table normal (rad).
    pub phi1: f64,
    /// Azimuth of the tilt plane (rad).
    pub phi2: f64,
}

/// theta1 within the table's tilting range (with the slack of every limit test).
pub(crate) fn theta1_in_limits(m: &Machine, theta1: f64) -> bool {
    theta1 >= m.limits.theta1_min - LIMIT_SLACK && theta1 <= m.limits.theta1_max + LIMIT_SLACK
}
