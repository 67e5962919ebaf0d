#![doc = include_str!("../README.md")]
//!
//! ## The modules
//!
//! Results are typed values. The folders follow the concepts (ARCHITECTURE.md):
//!
//! - [`spec`]: the machine's parameters and its machine file (TOML or key,value CSV);
//! - [`parallel_module`]: the 3-DOF parallel module of IFToMM 2007 (equations (3)-(6), inverse
//!   and forward kinematics, branch labels, tracking, kinetostatics);
//! - [`machine`]: the whole machine of AIM 2007 (module plus tilting table, tool orientation,
//!   a toolpath followed on one branch);
//! - [`workspace`], [`verify`], [`selftest`]: analyses built on them;
//! - [`calibrate`]: the machine file's parameters identified from measurements of the real
//!   machine, what the measurements cannot determine, and where to measure;
//! - [`post`]: joint programs a machine can run (linearization within tolerances, block times
//!   within the drives' limits);
//! - [`glider`]: the planar glider mechanisms of the comparative study (Wenger 2001);
//! - [`math`]: root finding, interval and double-double arithmetic, the run-time CPU dispatch;
//! - [`stream`]: the row engine the streaming commands and [`verify`] run on (three batches
//!   in flight: read, solved, written);
//! - [`details`]: the fast batched entry points and the baseline builds the benchmarks compare.
//!
//! The `parallel` feature (on by default) runs grids and batches on rayon's threads; without it
//! the same computations run in order, with the same results.

pub mod calibrate;
pub mod certificate;
pub mod details;
pub mod error;
pub mod glider;
pub mod kinematics;
pub mod machine;
pub mod math;
mod par;
pub mod parallel_module;
pub mod post;
pub mod selftest;
pub mod spec;
pub mod stream;
pub mod tolerance;
pub mod verify;
pub mod workspace;

pub use kinematics::{Follower, Joints};
pub use machine::orientation::{ToolAngles, ToolOrientation};
pub use machine::{
    MachineFkMode, MachineFkModes, MachineIkBranch, PathCandidates, PathError, PathRow, ToolPose,
};
pub use nalgebra::Vector3;
pub use spec::Machine;
