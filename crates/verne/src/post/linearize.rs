//! Linearization: the poses inserted between two rows of a path so that, in every block of the
//! joint program, the tool stays within the tolerances of the intended move
//! ([`deviation`](super::deviation)): the tip within `tip_mm`, the axis within `axis_rad`, at
//! every fraction of the block, proved (not only at samples).
//!
//! A block is first sampled at a quarter, a half and three quarters. The deviation of a short
//! block grows with the square of its length, so a block whose sampled deviation is r times the
//! tolerance is split into n = ceil(sqrt(r / `TARGET`)) equal parts of the intended move: its
//! poses are solved exactly (the inverse kinematics on the branch nearest the interpolated
//! joints, which must continue the block's), and each part is treated the same way. A block
//! sampled within `TARGET` of its tolerances is then proved ([`prove_within`]); if the proof
//! fails, it is split in two. A block that cannot be split further, or a pose that has no
//! working branch continuing the block's, is an error: the path cannot be linearized there
//! (a singularity, a limit, a change of branch).

use nalgebra::Vector3;

use super::deviation::{Block, JointVector, deviation_at, prove_within};
use crate::machine::intended::IntendedMove;
use crate::machine::orientation::ToolOrientation;
use crate::machine::{JOINT_DISTANCE_MM_PER_RAD, path_candidates};
use crate::parallel_module::equations::ModulePose;
use crate::parallel_module::ik::wrap_angle;
use crate::spec::Machine;

/// The sampled deviation a block is split down to, as a fraction of its tolerances: the proof's
/// bound comes within 10-20 % of the truth, so a block sampled at half its tolerance is proved at
/// once.
const TARGET: f64 = 0.5;

/// Most parts a block is split into at once.
const MAX_PARTS: usize = 64;

/// Most pieces the proof splits a block into before the block itself is split.
const PROOF_PIECES: usize = 8;

/// The smallest part of the intended move a block may be (a fraction): below it, the
/// deviation does not shrink with the block, and the path cannot be linearized there.
const MIN_FRACTION: f64 = 1e-7;

/// The tolerances of a linearized block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// The tip's distance from the intended tip (mm).
    pub tip_mm: f64,
    /// The axis's angle from the intended axis (rad).
    pub axis_rad: f64,
}

/// A pose of the path with its joints: a row's, or one inserted at fraction `s` of the move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    /// Fraction of the intended move (0 at its start row, 1 at its end row).
    pub s: f64,
    pub joints: JointVector,
    /// The module's pose (the assembly mode).
    pub module: ModulePose,
    /// The orientation solution (1 or 2) of the joints.
    pub orientation: u8,
}

/// Why a move cannot be linearized.
#[derive(Debug, Clone, PartialEq)]
pub enum LinearizeError {
    /// The tool axis turns half a turn in one move.
    OppositeAxes,
    /// The intended pose at fraction `s` has no working branch that continues the block's
    /// (unreachable there, outside a limit, or only on another branch: a jump of the joints).
    NoContinuation { s: f64, why: String },
    /// The deviation could not be proved within the tolerances on the part from `s0` to `s1`
    /// however short (a singularity near, or the joints leave the assembly mode).
    NotProved { s0: f64, s1: f64 },
}

impl std::fmt::Display for LinearizeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinearizeError::OppositeAxes => f.write_str(
                "the tool axis turns half a turn in one move: the move has no plane to turn in",
            ),
            LinearizeError::NoContinuation { s, why } => write!(
                f,
                "the intended pose at {:.4} of the move has no working branch continuing the joints: {why}",
                s
            ),
            LinearizeError::NotProved { s0, s1 } => write!(
                f,
                "the tool's deviation cannot be proved within the tolerances between {s0:.6} and {s1:.6} of the move (a singularity, or the joints leave their assembly mode)"
            ),
        }
    }
}

impl std::error::Error for LinearizeError {}

/// The machine and tolerances a path is linearized with.
#[derive(Debug, Clone, Copy)]
pub struct Linearizer<'a> {
    pub machine: &'a Machine,
    pub tool_length: f64,
    pub tolerances: Tolerances,
}

/// The joint distance of the path follower (mm; radians weighted by
/// [`JOINT_DISTANCE_MM_PER_RAD`]).
fn joint_distance(a: &JointVector, b: &JointVector) -> f64 {
    let rho = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
    rho + JOINT_DISTANCE_MM_PER_RAD * ((a[3] - b[3]).abs() + (a[4] - b[4]).abs())
}

impl Linearizer<'_> {
    /// The poses to insert between `a` (s = 0) and `b` (s = 1) of the intended move, in order;
    /// none when the block between them is already within the tolerances.
    pub fn linearize(
        &self,
        a: &Vertex,
        b: &Vertex,
        intended: &IntendedMove,
    ) -> Result<Vec<Vertex>, LinearizeError> {
        let mut out = Vec::new();
        self.part(a, b, intended, &mut out)?;
        Ok(out)
    }

    /// Linearizes the part between `va` and `vb`, appending the poses inserted inside it.
    fn part(
        &self,
        va: &Vertex,
        vb: &Vertex,
        intended: &IntendedMove,
        out: &mut Vec<Vertex>,
    ) -> Result<(), LinearizeError> {
        let tol = self.tolerances;
        let block = Block {
            machine: self.machine,
            tool_length: self.tool_length,
            qa: va.joints,
            qb: vb.joints,
            start: va.module,
            end: vb.module,
            intended: intended.between(va.s, vb.s),
        };
        // Most blocks of a dense path are within their tolerances as they are: prove that first.
        if prove_within(&block, tol.tip_mm, tol.axis_rad, 1).is_some() {
            return Ok(());
        }
        let mut sampled: f64 = 0.0;
        let mut pose = va.module;
        for s in [0.25, 0.5, 0.75] {
            match deviation_at(&block, s, &pose) {
                Some((d, p)) => {
                    sampled = sampled.max(d.relative(tol.tip_mm, tol.axis_rad));
                    pose = p;
                }
                None => {
                    sampled = f64::INFINITY;
                    break;
                }
            }
        }
        let parts = if sampled <= TARGET {
            if prove_within(&block, tol.tip_mm, tol.axis_rad, PROOF_PIECES).is_some() {
                return Ok(());
            }
            2
        } else if sampled.is_finite() {
            ((sampled / TARGET).sqrt().ceil() as usize).clamp(2, MAX_PARTS)
        } else {
            2
        };
        if (vb.s - va.s) / (parts as f64) < MIN_FRACTION {
            return Err(LinearizeError::NotProved { s0: va.s, s1: vb.s });
        }
        let mut prev = *va;
        for k in 1..=parts {
            let next = if k == parts {
                *vb
            } else {
                let t = k as f64 / parts as f64;
                let s = va.s + (vb.s - va.s) * t;
                let guess: JointVector =
                    std::array::from_fn(|j| va.joints[j] + t * (vb.joints[j] - va.joints[j]));
                self.solve(intended, s, &guess, joint_distance(&va.joints, &vb.joints))?
            };
            self.part(&prev, &next, intended, out)?;
            if k < parts {
                out.push(next);
            }
            prev = next;
        }
        Ok(())
    }

    /// The joints of the intended pose at `s`: the working branch nearest `guess` (the
    /// interpolated joints), which must be no farther from it than the block is long (`span`),
    /// theta2 unwrapped next to it.
    fn solve(
        &self,
        intended: &IntendedMove,
        s: f64,
        guess: &JointVector,
        span: f64,
    ) -> Result<Vertex, LinearizeError> {
        let tip: Vector3<f64> = intended.tip(s);
        // The axis, with both its orientation solutions: the branch nearest the interpolated
        // joints decides (a row solved from stated angles is one of them).
        let orientation = ToolOrientation::Axis(intended.axis(s));
        let no = |why: String| LinearizeError::NoContinuation { s, why };
        let candidates = path_candidates(
            self.machine,
            &tip,
            &orientation,
            self.tool_length,
            Some(guess[4]),
        )
        .map_err(|e| no(e.to_string()))?;
        let best = candidates
            .iter()
            .filter(|(b, _, _)| b.working())
            .map(|(b, orientation, theta2)| {
                let theta2 = guess[4] + wrap_angle(theta2 - guess[4]);
                let q = [b.rho.x, b.rho.y, b.rho.z, b.theta1, theta2];
                (joint_distance(&q, guess), q, b, orientation)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0));
        let Some((distance, joints, branch, orientation)) = best else {
            return Err(no(if candidates.is_empty() {
                "unreachable".into()
            } else {
                "no branch within the machine's limits".into()
            }));
        };
        if distance > span.max(1e-9) {
            return Err(no(format!(
                "the nearest working branch is {distance:.4} (mm and mm-weighted radians) from the interpolated joints, farther than the block's {span:.4}: another branch"
            )));
        }
        Ok(Vertex {
            s,
            joints,
            module: ModulePose {
                p: branch.platform,
                alpha: branch.alpha,
            },
            orientation,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::PathState;
    use crate::machine::orientation::tool_axis;
    use crate::post::deviation::deviation_at;

    fn vertex(
        m: &Machine,
        state: &mut PathState,
        tip: Vector3<f64>,
        axis: Vector3<f64>,
        s: f64,
    ) -> Vertex {
        let r = state
            .next_row(m, &tip, &ToolOrientation::Axis(axis), m.tool_length)
            .unwrap();
        Vertex {
            s,
            joints: [r.rho.x, r.rho.y, r.rho.z, r.theta1, r.theta2],
            module: r.module,
            orientation: r.orientation,
        }
    }

    /// Every block of a linearized move (a long move with a tilt change, a swarf-like tilt
    /// sweep) is within the tolerances at 401 points each (an independent dense check), and the
    /// inserted poses lie on the intended move.
    #[test]
    fn linearized_blocks_are_within_the_tolerances_everywhere() {
        let m = Machine::default_verne();
        let ax = |phi1: f64, phi2: f64| tool_axis(phi1.to_radians(), phi2.to_radians());
        let tol = Tolerances {
            tip_mm: 0.01,
            axis_rad: 0.01f64.to_radians(),
        };
        let lin = Linearizer {
            machine: &m,
            tool_length: m.tool_length,
            tolerances: tol,
        };
        for (a, b) in [
            (
                (Vector3::new(-80.0, 0.0, 30.0), ax(0.5, 0.0)),
                (Vector3::new(80.0, 0.0, 30.0), ax(40.0, 0.0)),
            ),
            (
                (Vector3::new(50.0, 20.0, 10.0), ax(15.0, 0.0)),
                (Vector3::new(45.0, 25.0, 10.0), ax(30.0, 8.0)),
            ),
        ] {
            let mut state = PathState::default();
            let va = vertex(&m, &mut state, a.0, a.1, 0.0);
            let vb = vertex(&m, &mut state, b.0, b.1, 1.0);
            let intended = IntendedMove::new(a.0, a.1, None, b.0, b.1, None).unwrap();
            let inserted = lin.linearize(&va, &vb, &intended).expect("linearized");
            assert!(!inserted.is_empty());
            let mut all = vec![va];
            all.extend(inserted.iter().copied());
            all.push(vb);
            for w in all.windows(2) {
                assert!(w[0].s < w[1].s);
                let block = Block {
                    machine: &m,
                    tool_length: m.tool_length,
                    qa: w[0].joints,
                    qb: w[1].joints,
                    start: w[0].module,
                    end: w[1].module,
                    intended: intended.between(w[0].s, w[1].s),
                };
                let mut pose = w[0].module;
                for k in 0..=400 {
                    let (d, p) = deviation_at(&block, k as f64 / 400.0, &pose).unwrap();
                    pose = p;
                    assert!(
                        d.tip_mm <= tol.tip_mm && d.axis_rad <= tol.axis_rad,
                        "{d:?}"
                    );
                }
            }
            for v in &inserted {
                let q = v.joints;
                let tool =
                    crate::machine::tool_pose_eq26(&m.table, &v.module, q[3], q[4], m.tool_length);
                assert!((tool.tip - intended.tip(v.s)).norm() < 1e-6);
            }
        }
    }
}
