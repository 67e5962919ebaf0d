//! What the checks measured at each row, for a caller that draws or keeps the run (the HTML
//! report of `verne verify`): [`RowObservation`], handed in row order to the observer of
//! [`super::verify_observed`], each row's observation before that row's findings.
//!
//! The values are the checks': the errors, tilts, rates and chordal errors they measured, and
//! the tool pose and kinetostatics of the row's assembly mode by the functions the row checks
//! use (recomputed, in parallel, only when there is an observer: [`super::verify`] has none and
//! does no more work than before).

use nalgebra::Vector3;

use super::{Joints, PathPoint};
use crate::parallel_module::equations::ModulePose;

/// One row of the joint table as the checks saw it, and the segment that ends on it.
#[derive(Debug, Clone, PartialEq)]
pub struct RowObservation {
    /// The row as the report names it: the 1-based data row, or its id.
    pub label: String,
    /// The 1-based data row of the joint table (motion order).
    pub index: u64,
    /// The row's line in the joint table, and its intended row's line in the path.
    pub joints_line: u64,
    pub path_line: Option<u64>,
    /// The joints (mm, rad) and time of the row, when its cells are usable.
    pub joints: Option<Joints>,
    /// The intended pose it is paired with, when there is one.
    pub intended: Option<PathPoint>,
    /// The assembly mode the row is taken in and its tool pose, when it has one.
    pub pose: Option<PoseObservation>,
    /// The segment from the previous row to this one, when its checks ran.
    pub segment: Option<SegmentObservation>,
}

/// The forward kinematics of a row in the assembly mode the checks took, and what they measured
/// there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseObservation {
    /// The module's pose (platform point P in mm, base frame, z down; alpha in rad).
    pub module: ModulePose,
    /// The tool tip (mm) and unit axis in the workpiece frame (AIM 2007 eq. (26)).
    pub tip: Vector3<f64>,
    pub axis: Vector3<f64>,
    /// |tip - intended tip| (mm) and the angle between the axes (deg).
    pub tip_error_mm: f64,
    pub axis_error_deg: f64,
    /// The largest rod tilt from its slider axis (deg).
    pub rod_tilt_deg: f64,
    /// The velocity amplification factors, largest first, and the parallel margin.
    pub amplification: [f64; 3],
    pub parallel_margin: f64,
}

/// The segment from the previous row to a row: its timing, joint rates and chordal errors.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SegmentObservation {
    /// Its time (s), when the joint table or the path times it.
    pub dt: Option<f64>,
    /// The joints' rates (mm/s, rad/s), when timed.
    pub rates: Option<[f64; 5]>,
    /// The joints' accelerations (mm/s^2, rad/s^2) at the vertex between the previous segment
    /// and this one, when the acceleration check measured it (its findings are on this row).
    pub acceleration: Option<[f64; 5]>,
    /// The largest deviation of the interpolated joints' tip (mm) and axis (deg) from the
    /// intended move, when measured (not on a rapid move).
    pub chord_error_mm: Option<f64>,
    pub chord_axis_deg: Option<f64>,
}
