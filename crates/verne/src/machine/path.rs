//! A toolpath followed on one branch (pure: no I/O): every branch of each row over both
//! orientation solutions ([`path_candidates`]), then the choice nearest the previous row's
//! joints ([`PathState`]), theta2 unwrapped along the path.

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::certificate::Certificate;
use crate::machine::orientation::{
    AxisAngles, AxisError, ToolAngles, ToolOrientation, axis_angles, phi1_at, unit_axis,
};
use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::parallel_module::ik::wrap_angle;
use crate::spec::Machine;

use super::ToolPose;
use super::ik::{MAX_MACHINE_IK_BRANCHES, MachineIkBranch, MachineIkBranches, machine_ik_into};

/// Weight (mm per rad) that puts slider travel and table rotation on one scale when choosing the
/// branch nearest the previous row: 1 rad of table rotation counts as 1000 mm of slider travel,
/// about the size of the machine.
pub const JOINT_DISTANCE_MM_PER_RAD: f64 = 1000.0;

/// The first-row choice of [`PathState`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FirstRowChoice {
    /// The working branch with the smallest |theta1| over both orientation solutions.
    #[default]
    SmallestTheta1,
    /// Orientation solution 1, (phi1 >= 0, phi2) (see `orientation::AxisAngles`), if it has a
    /// working branch; otherwise the other one, and the row is flagged `switched`.
    Orientation1,
    /// Orientation solution 2, (-phi1, phi2 + pi); same fallback.
    Orientation2,
}

/// The branch chosen for one row of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathRow {
    /// Slider positions (mm).
    pub rho: Sliders,
    /// Tilting axis (rad).
    pub theta1: f64,
    /// Rotary axis (rad), unwrapped: the turn nearest the previous row's theta2.
    pub theta2: f64,
    /// The orientation angles used (rad): phi2 = -theta2 up to whole turns.
    pub angles: ToolAngles,
    /// Which orientation solution: 1 = (phi1 >= 0, phi2), 2 = (-phi1, phi2 + pi); 1 for angle
    /// input and inside the rotary-singularity cone.
    pub orientation: u8,
    /// Platform rotation alpha (rad) and point P (mm, base frame).
    pub module: ModulePose,
    /// True when the continuation of the previous row's branch left the limits and another
    /// working branch was taken (or, on the first row, when the preferred orientation had none).
    pub switched: bool,
    /// True when the tool axis lies inside the rotary-singularity cone
    /// (`orientation::ROTARY_SINGULAR_CONE_RAD`); for axis input theta2 was then kept from the
    /// previous row (0 on the first row) and phi1 fitted to it.
    pub near_rotary_singularity: bool,
    /// Number of real branches over the orientation solutions considered.
    pub real_branches: usize,
}

/// Why a row of a path has no branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathError {
    /// The tool axis vector is invalid.
    Axis(AxisError),
    /// No working branch. `nearest` is the branch of the machine's kind (configuration
    /// (-1, -1, -1), rods not crossing) nearest the previous row, or with the smallest |theta1|,
    /// whose verdict says which limits fail; None when no such branch is real.
    NoWorkingBranch {
        /// Number of real branches.
        real_branches: usize,
        /// False when the solver could not prove the branches complete (status `uncertified`).
        proved: bool,
        /// See above.
        nearest: Option<MachineIkBranch>,
    },
}

impl std::fmt::Display for PathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PathError::Axis(e) => e.fmt(f),
            PathError::NoWorkingBranch {
                real_branches,
                proved,
                nearest,
            } => {
                write!(f, "no working branch ({real_branches} real branches")?;
                if !proved {
                    f.write_str(", not proved complete")?;
                }
                if let Some(b) = nearest {
                    write!(
                        f,
                        "; nearest: theta1 = {:.6} deg, rho = ({:.4}, {:.4}, {:.4}) mm, fails {}",
                        b.theta1.to_degrees(),
                        b.rho.x,
                        b.rho.y,
                        b.rho.z,
                        b.verdict
                    )?;
                }
                f.write_str(")")
            }
        }
    }
}

impl std::error::Error for PathError {}

/// Row-by-row branch choice along a tool path (pure: no I/O). Keeps the previous row's joints.
#[derive(Debug, Clone, Default)]
pub struct PathState {
    first: FirstRowChoice,
    prev: Option<PathRow>,
    /// theta2 for the rows before the first one chosen: the value that the path's first row
    /// outside the rotary-singularity cone needs ([`first_decided_theta2`]).
    seed_theta2: Option<f64>,
}

/// A candidate branch with the orientation it came from and its theta2.
#[derive(Clone, Copy)]
struct Candidate {
    branch: MachineIkBranch,
    angles: ToolAngles,
    orientation: u8,
    theta2: f64,
}

/// The rotary axis of tool angles: theta2 = -phi2 in (-pi, pi] (AIM 2007 eq. (8)) less the
/// rotary axis's zero offset `zero` (the joint's angle); `+ 0.0` so that phi2 = 0, the table
/// normal as a program states it, gives theta2 = 0, not -0.
fn theta2_of(angles: &ToolAngles, zero: f64) -> f64 {
    wrap_angle(-angles.phi2 - zero) + 0.0
}

/// theta2 + 2 k pi nearest `reference`.
fn unwrap_near(theta2: f64, reference: f64) -> f64 {
    reference + wrap_angle(theta2 - reference)
}

/// Every branch of one path row over the orientation solutions, before the choice that
/// depends on the previous row (so rows can be solved in parallel and chosen in order).
#[derive(Clone, Default)]
pub struct PathCandidates {
    options: ArrayVec<(ToolAngles, u8), 2>,
    all: ArrayVec<Candidate, { 2 * MAX_MACHINE_IK_BRANCHES }>,
    near_singular: bool,
    needs_previous: bool,
    /// The weakest certificate of the orientation solutions' branch lists.
    pub certificate: Certificate,
    /// The rotary axis's zero offset of the machine the candidates are of (rad).
    theta2_zero: f64,
}

impl PathCandidates {
    /// True for an axis inside the rotary-singularity cone: the candidates were computed with
    /// theta2 = 0 and must be recomputed with the previous row's theta2.
    pub fn needs_previous(&self) -> bool {
        self.needs_previous
    }

    /// Every branch with its orientation solution (1 or 2) and theta2 (rad, in (-pi, pi]).
    pub fn iter(&self) -> impl Iterator<Item = (MachineIkBranch, u8, f64)> + '_ {
        self.all.iter().map(|c| (c.branch, c.orientation, c.theta2))
    }

    /// Number of real branches.
    pub fn len(&self) -> usize {
        self.all.len()
    }

    pub fn is_empty(&self) -> bool {
        self.all.is_empty()
    }
}

/// The candidates of one row: both orientation solutions of an axis (or the given angles), every
/// machine IK branch of each, theta2 = -phi2 wrapped to (-pi, pi]. Inside the rotary cone, phi2 is
/// taken from `prev_theta2` (0 when None) and phi1 fitted to it.
pub fn path_candidates(
    m: &Machine,
    tip: &Vector3<f64>,
    orientation: &ToolOrientation,
    tool_length: f64,
    prev_theta2: Option<f64>,
) -> Result<PathCandidates, PathError> {
    let mut out = PathCandidates::default();
    path_candidates_into(m, tip, orientation, tool_length, prev_theta2, &mut out)?;
    Ok(out)
}

/// [`path_candidates`] into an existing set (cleared first), so that a caller that keeps one (a
/// batch's row) does not copy it; on error the set is left empty.
pub fn path_candidates_into(
    m: &Machine,
    tip: &Vector3<f64>,
    orientation: &ToolOrientation,
    tool_length: f64,
    prev_theta2: Option<f64>,
    out: &mut PathCandidates,
) -> Result<(), PathError> {
    out.options.clear();
    out.all.clear();
    out.near_singular = false;
    out.needs_previous = false;
    out.certificate = Certificate::Double;
    out.theta2_zero = m.table.theta_zero[1];
    match orientation {
        ToolOrientation::Angles(a) => {
            out.near_singular =
                a.phi1.sin().abs() < crate::machine::orientation::ROTARY_SINGULAR_CONE_RAD;
            out.options.push((*a, 1));
        }
        ToolOrientation::Axis(v) => match axis_angles(v).map_err(PathError::Axis)? {
            AxisAngles::Regular(sols) => {
                out.options.push((sols[0], 1));
                out.options.push((sols[1], 2));
            }
            AxisAngles::NearRotary { .. } => {
                let a = unit_axis(v).map_err(PathError::Axis)?;
                out.near_singular = true;
                out.needs_previous = true;
                // The previous row's joint plus the rotary axis's zero is the equations' angle.
                let phi2 = -prev_theta2.unwrap_or(0.0) - out.theta2_zero;
                out.options.push((
                    ToolAngles {
                        phi1: phi1_at(&a, phi2),
                        phi2,
                    },
                    1,
                ));
            }
        },
    }
    let mut branches = MachineIkBranches::new();
    for &(angles, label) in &out.options {
        let pose = ToolPose {
            tip: *tip,
            phi1: angles.phi1,
            phi2: angles.phi2,
        };
        machine_ik_into(m, &pose, tool_length, &mut branches);
        out.certificate = out.certificate.max(branches.certificate);
        for &branch in &branches {
            out.all.push(Candidate {
                branch,
                angles,
                orientation: label,
                theta2: theta2_of(&angles, out.theta2_zero),
            });
        }
    }
    Ok(())
}

impl PathState {
    /// A new path; `first` says how to choose on the first row.
    pub fn new(first: FirstRowChoice) -> PathState {
        PathState {
            first,
            prev: None,
            seed_theta2: None,
        }
    }

    /// A new path whose rows inside the rotary-singularity cone, before any other, take
    /// `theta2` (rad): the value the first row outside the cone needs, so that the first
    /// tilted move does not swing the rotary axis, and `first` is honoured where the
    /// orientation is decided.
    pub fn with_theta2(first: FirstRowChoice, theta2: f64) -> PathState {
        PathState {
            first,
            prev: None,
            seed_theta2: Some(theta2),
        }
    }

    /// The last row chosen, if any.
    pub fn previous(&self) -> Option<&PathRow> {
        self.prev.as_ref()
    }

    /// The theta2 the next row is unwrapped near: the previous row's, else the seed.
    pub fn reference_theta2(&self) -> Option<f64> {
        self.prev.map(|p| p.theta2).or(self.seed_theta2)
    }

    /// Chooses the branch for the next row. On error the state is unchanged, so the next row
    /// continues from the last successful one.
    pub fn next_row(
        &mut self,
        m: &Machine,
        tip: &Vector3<f64>,
        orientation: &ToolOrientation,
        tool_length: f64,
    ) -> Result<PathRow, PathError> {
        let prev_theta2 = self.reference_theta2();
        let candidates = path_candidates(m, tip, orientation, tool_length, prev_theta2)?;
        self.choose(&candidates)
    }

    /// Chooses among the candidates of one row (from [`path_candidates`], computed with this
    /// state's previous theta2 when [`PathCandidates::needs_previous`] says so).
    pub fn choose(&mut self, candidates: &PathCandidates) -> Result<PathRow, PathError> {
        let options = &candidates.options;
        let near_singular = candidates.near_singular;
        // theta2 unwrapped next to the previous row's, once per orientation solution (every
        // branch of one has the same theta2; an `fmod` once the rotary axis has turned more than
        // once); the candidates are read with it, not copied.
        let unwrapped: ArrayVec<(u8, f64), 2> = options
            .iter()
            .map(|&(angles, label)| {
                let t = theta2_of(&angles, candidates.theta2_zero);
                (
                    label,
                    self.reference_theta2().map_or(t, |r| unwrap_near(t, r)),
                )
            })
            .collect();
        let theta2 = |c: &Candidate| {
            unwrapped
                .iter()
                .find(|(label, _)| *label == c.orientation)
                .map_or(c.theta2, |&(_, t)| t)
        };
        let with_unwrapped = |c: &Candidate| Candidate {
            theta2: theta2(c),
            ..*c
        };
        let all = &candidates.all;
        let machine_kind = |c: &&Candidate| c.branch.working() || c.branch.verdict.only_limits();
        let (chosen, switched) = match self.prev {
            Some(prev) => {
                let dist = |c: &Candidate| {
                    (c.branch.rho - prev.rho).amax() / JOINT_DISTANCE_MM_PER_RAD
                        + (c.branch.theta1 - prev.theta1).abs()
                        + (theta2(c) - prev.theta2).abs()
                };
                let nearest = |ok: &dyn Fn(&Candidate) -> bool| {
                    all.iter()
                        .filter(|c| ok(c))
                        .min_by(|a, b| dist(a).total_cmp(&dist(b)))
                        .map(with_unwrapped)
                };
                let continuation = nearest(&|c| machine_kind(&c));
                match continuation {
                    Some(c) if c.branch.working() => (c, false),
                    cont => match nearest(&|c| c.branch.working()) {
                        Some(c) => (c, true),
                        None => {
                            return Err(PathError::NoWorkingBranch {
                                real_branches: all.len(),
                                proved: candidates.certificate.proved(),
                                nearest: cont.map(|c| c.branch),
                            });
                        }
                    },
                }
            }
            None => {
                let smallest = |ok: &dyn Fn(&Candidate) -> bool| {
                    all.iter()
                        .filter(|c| ok(c))
                        .min_by(|a, b| a.branch.theta1.abs().total_cmp(&b.branch.theta1.abs()))
                        .map(with_unwrapped)
                };
                let wanted = match self.first {
                    FirstRowChoice::SmallestTheta1 => None,
                    FirstRowChoice::Orientation1 => Some(1),
                    FirstRowChoice::Orientation2 => Some(2),
                };
                let preferred = match wanted {
                    Some(o) if options.len() == 2 => {
                        smallest(&|c| c.branch.working() && c.orientation == o)
                    }
                    _ => smallest(&|c| c.branch.working()),
                };
                match preferred {
                    Some(c) => (c, false),
                    None => match smallest(&|c| c.branch.working()) {
                        Some(c) => (c, true),
                        None => {
                            return Err(PathError::NoWorkingBranch {
                                real_branches: all.len(),
                                proved: candidates.certificate.proved(),
                                nearest: smallest(&|c| machine_kind(&c)).map(|c| c.branch),
                            });
                        }
                    },
                }
            }
        };
        let row = PathRow {
            rho: chosen.branch.rho,
            theta1: chosen.branch.theta1,
            theta2: chosen.theta2,
            angles: chosen.angles,
            orientation: chosen.orientation,
            module: ModulePose {
                p: chosen.branch.platform,
                alpha: chosen.branch.alpha,
            },
            switched,
            near_rotary_singularity: near_singular,
            real_branches: all.len(),
        };
        self.prev = Some(row);
        Ok(row)
    }
}

/// The theta2 (rad) that the first pose outside the rotary-singularity cone needs, when the
/// path starts inside the cone (a vertical tool, as almost every CL file's FROM); `None` when
/// the first pose is already outside it, or no pose of `poses` is (or has a working branch).
/// With a preferred orientation (`first`), the branch that preference takes there; with
/// [`FirstRowChoice::SmallestTheta1`], the branch that the path followed from theta2 = 0 reaches
/// there (the choice is the one made without look-ahead; only the swing of the rotary axis on
/// the first tilted move goes). A path started with [`PathState::with_theta2`] of it keeps
/// theta2 still until the orientation is decided.
pub fn first_decided_theta2(
    m: &Machine,
    poses: impl IntoIterator<Item = (Vector3<f64>, ToolOrientation)>,
    tool_length: f64,
    first: FirstRowChoice,
) -> Option<f64> {
    let mut followed = PathState::new(first);
    for (k, (tip, orientation)) in poses.into_iter().enumerate() {
        let theta2 = followed.reference_theta2();
        let c = path_candidates(m, &tip, &orientation, tool_length, theta2).ok()?;
        if c.needs_previous() {
            followed.choose(&c).ok()?;
            continue;
        }
        if k == 0 {
            return None;
        }
        let row = match first {
            FirstRowChoice::SmallestTheta1 => followed.choose(&c),
            _ => PathState::new(first).choose(&c),
        };
        return row.ok().map(|r| r.theta2);
    }
    None
}
