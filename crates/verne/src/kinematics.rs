//! The machine's kinematics in three calls: [`Machine::inverse`] (every branch of a tool pose),
//! [`Machine::forward`] (every assembly mode of the joints) and [`Machine::follow`] (one branch
//! per row along a toolpath; [`Machine::follow_path`] for a whole path at once, as `verne ik`
//! follows it), each with the machine's own tool length ([`Machine::with_tool_length`] for
//! another one).
//!
//! ```
//! use verne::{Machine, ToolOrientation, Vector3};
//!
//! let machine = Machine::default_verne();
//! // A tool pose: the tip in the workpiece frame R_t (mm), the tool axis tilted 20 degrees.
//! let tip = Vector3::new(40.0, -10.0, 25.0);
//! let axis = ToolOrientation::Axis(Vector3::new(20f64.to_radians().sin(), 0.0, 20f64.to_radians().cos()));
//!
//! // Every real branch of both orientation solutions, proved complete.
//! let branches = machine.inverse(&tip, &axis).unwrap();
//! assert!(branches.certificate.proved());
//! let working: Vec<_> = branches.iter().filter(|(b, _, _)| b.working()).collect();
//! assert!(!working.is_empty());
//!
//! // The forward kinematics of a working branch gives the pose back in one of its modes.
//! let (b, _, theta2) = working[0];
//! let modes = machine.forward(&[b.rho.x, b.rho.y, b.rho.z, b.theta1, theta2]);
//! assert!(modes.iter().any(|m| (m.tool.tip - tip).norm() < 1e-9));
//!
//! // Along a path: one branch per row, continuously.
//! let mut follower = machine.follow();
//! for k in 0..10 {
//!     let row = follower.next(&Vector3::new(40.0 - k as f64, -10.0, 25.0), &axis).unwrap();
//!     assert!(row.rho.x > 0.0);
//! }
//! ```

use nalgebra::Vector3;

use crate::machine::orientation::ToolOrientation;
use crate::machine::{
    FirstRowChoice, MachineFkModes, PathCandidates, PathError, PathRow, PathState,
    first_decided_theta2, machine_fk, path_candidates,
};
use crate::parallel_module::equations::Sliders;
use crate::spec::Machine;

/// The five joints (rho1, rho2, rho3 in mm; theta1, theta2 in rad).
pub type Joints = [f64; 5];

impl Machine {
    /// Every real branch of the tool pose (AIM 2007, section III.C): the tip in R_t (mm) and
    /// the tool's orientation (an axis has two orientation solutions, both solved), with this
    /// machine's tool length. Each branch with its orientation solution (1 or 2) and theta2
    /// (rad, in (-pi, pi]); `certificate` says whether the list is proved complete. An invalid
    /// axis (zero, not finite) is an error; an unreachable pose is an empty list.
    pub fn inverse(
        &self,
        tip: &Vector3<f64>,
        orientation: &ToolOrientation,
    ) -> Result<PathCandidates, PathError> {
        path_candidates(self, tip, orientation, self.tool_length, None)
    }

    /// Every assembly mode of the joints (AIM 2007, section III.D): the module's forward
    /// kinematics, then eq. (26) for the tool pose in R_t, with this machine's tool length.
    pub fn forward(&self, joints: &Joints) -> MachineFkModes {
        let rho = Sliders::new(joints[0], joints[1], joints[2]);
        machine_fk(self, &rho, joints[3], joints[4], self.tool_length)
    }

    /// A follower of a toolpath on this machine: one working branch per row, continuous from
    /// the row before (the rotary axis unwrapped, no jump to another branch where one
    /// continues).
    pub fn follow(&self) -> Follower<'_> {
        Follower {
            machine: self,
            state: PathState::default(),
        }
    }

    /// The joints of a whole toolpath, as `verne ik` follows it: one working branch per pose,
    /// continuous from the one before, the first chosen by `first`. A path that starts with
    /// the tool inside the rotary axis's singular cone (on the table normal, as a CL file's
    /// FROM) takes the theta2 of its first pose outside it from the start, so the rotary axis
    /// does not swing on the first tilted move. A pose that is not finite is an error of its
    /// own and the next continues from the last with joints.
    ///
    /// ```
    /// use verne::machine::FirstRowChoice;
    /// use verne::{Machine, ToolOrientation, Vector3};
    ///
    /// let machine = Machine::default_verne();
    /// let up = ToolOrientation::Axis(Vector3::new(0.0, 0.0, 1.0));
    /// let tilted = ToolOrientation::Axis(Vector3::new(0.0, 0.5, 0.75f64.sqrt()));
    /// let path = [
    ///     (Vector3::new(0.0, 0.0, 60.0), up),
    ///     (Vector3::new(10.0, 0.0, 30.0), tilted),
    /// ];
    /// let rows = machine.follow_path(&path, FirstRowChoice::SmallestTheta1);
    /// let (a, b) = (rows[0].as_ref().unwrap(), rows[1].as_ref().unwrap());
    /// // The rotary axis is already where the tilted pose needs it.
    /// assert!((a.theta2 - b.theta2).abs() < 1e-12);
    /// ```
    pub fn follow_path(
        &self,
        poses: &[(Vector3<f64>, ToolOrientation)],
        first: FirstRowChoice,
    ) -> Vec<Result<PathRow, PathError>> {
        let finite = |(tip, orientation): &&(Vector3<f64>, ToolOrientation)| {
            tip.iter().all(|v| v.is_finite())
                && match orientation {
                    ToolOrientation::Axis(a) => a.iter().all(|v| v.is_finite()),
                    ToolOrientation::Angles(a) => a.phi1.is_finite() && a.phi2.is_finite(),
                }
        };
        let seed = first_decided_theta2(
            self,
            poses.iter().filter(finite).copied(),
            self.tool_length,
            first,
        );
        let mut state = match seed {
            Some(theta2) => PathState::with_theta2(first, theta2),
            None => PathState::new(first),
        };
        poses
            .iter()
            .map(|(tip, orientation)| state.next_row(self, tip, orientation, self.tool_length))
            .collect()
    }

    /// This machine with another tool length Delta (mm, AIM 2007 eq. (8)); `None` unless it is
    /// finite and not negative (the machine file's rule).
    pub fn with_tool_length(&self, mm: f64) -> Option<Machine> {
        (mm.is_finite() && mm >= 0.0).then(|| Machine {
            tool_length: mm,
            ..self.clone()
        })
    }
}

/// One branch per row along a toolpath ([`Machine::follow`]).
#[derive(Debug, Clone)]
pub struct Follower<'a> {
    machine: &'a Machine,
    state: PathState,
}

impl Follower<'_> {
    /// The joints of the next row. On an error (no working branch, an invalid axis) the
    /// follower is unchanged: the next row continues from the last one that had joints.
    pub fn next(
        &mut self,
        tip: &Vector3<f64>,
        orientation: &ToolOrientation,
    ) -> Result<PathRow, PathError> {
        self.state
            .next_row(self.machine, tip, orientation, self.machine.tool_length)
    }

    /// The last row with joints, if any.
    pub fn previous(&self) -> Option<&PathRow> {
        self.state.previous()
    }
}
