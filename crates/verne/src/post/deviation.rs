//! How far the tool goes from the intended move inside a block of a joint program. The
//! controller moves the five joints linearly between the block's ends, q(s) = q_a + s (q_b -
//! q_a); the tool pose of those joints (the forward kinematics, eq. (26), AIM 2007, on the
//! assembly mode continued from the block's start) is compared, at the same fraction s, with the
//! intended pose ([`IntendedMove`]): the tip's distance (mm) and the axis's angle (rad). Both ends
//! are exact (the joints solve the poses), so the deviation is the chord's.
//!
//! Two ways to know it: at one s ([`deviation_at`], what `verne verify` samples), and over an
//! interval of s with a proof ([`deviation_bound`], what the post's linearization certifies with).
//! The bound is the mean-value form e(S) ⊆ e(s_m) + e'(S) (S - s_m), with the module's pose and
//! its rate enclosed by
//! [`enclose_segment_and_middle`]
//! and the tool pose's rate by [`crate::machine::transforms::tool_pose_over`]: every s of the
//! interval is
//! covered, not only samples.

use nalgebra::Vector3;

use crate::machine::intended::IntendedMove;
use crate::machine::orientation::tool_axis;
use crate::machine::transforms::{tool_pose_eq26, tool_pose_over};
use crate::math::interval::{Iv, next_up};
use crate::parallel_module::enclosure::enclose_segment_and_middle;
use crate::parallel_module::equations::{ModulePose, Sliders, polish_pose, residual_mm};
use crate::spec::Machine;
use crate::tolerance::ACCEPT_RESIDUAL_MM;

/// Joints (rho1, rho2, rho3 in mm; theta1, theta2 in rad).
pub type JointVector = [f64; 5];

/// A block of a joint program with the move it is meant to make.
#[derive(Debug, Clone, Copy)]
pub struct Block<'a> {
    pub machine: &'a Machine,
    pub tool_length: f64,
    /// The joints at the block's start and end.
    pub qa: JointVector,
    pub qb: JointVector,
    /// The module's pose at the start (the assembly mode the block continues) and at the end
    /// (where the interpolated joints must arrive: the same mode, continued).
    pub start: ModulePose,
    pub end: ModulePose,
    pub intended: IntendedMove,
}

/// The deviation at one s: the tip's distance (mm) and the axis's angle (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deviation {
    pub tip_mm: f64,
    pub axis_rad: f64,
}

impl Deviation {
    /// The larger of the two as a fraction of their tolerances.
    pub fn relative(&self, tip_tol_mm: f64, axis_tol_rad: f64) -> f64 {
        (self.tip_mm / tip_tol_mm).max(self.axis_rad / axis_tol_rad)
    }
}

impl Block<'_> {
    /// The sliders at s.
    pub fn sliders(&self, s: f64) -> Sliders {
        Sliders::new(
            self.qa[0] + s * (self.qb[0] - self.qa[0]),
            self.qa[1] + s * (self.qb[1] - self.qa[1]),
            self.qa[2] + s * (self.qb[2] - self.qa[2]),
        )
    }

    /// The joints at s.
    pub fn joints(&self, s: f64) -> JointVector {
        std::array::from_fn(|k| self.qa[k] + s * (self.qb[k] - self.qa[k]))
    }
}

/// The deviation at fraction `s` of the block, and the module's pose there, continued from
/// `from` (a pose at a nearby s: the block's start, or the previous sample). `None` when the
/// interpolated sliders cannot be assembled near `from`.
pub fn deviation_at(
    block: &Block<'_>,
    s: f64,
    from: &ModulePose,
) -> Option<(Deviation, ModulePose)> {
    let g = &block.machine.module;
    let rho = block.sliders(s);
    let pose = polish_pose(g, *from, &rho);
    if residual_mm(g, &pose, &rho) > ACCEPT_RESIDUAL_MM {
        return None;
    }
    let q = block.joints(s);
    let tool = tool_pose_eq26(&block.machine.table, &pose, q[3], q[4], block.tool_length);
    let axis = tool_axis(tool.phi1, tool.phi2);
    let dev = Deviation {
        tip_mm: (tool.tip - block.intended.tip(s)).norm(),
        axis_rad: axis.angle(&block.intended.axis(s)),
    };
    Some((dev, pose))
}

/// An upper bound of the deviation at every s of `s` (within [0, 1]), proved, with the
/// module's pose at the middle of `s` (`mid`, a Newton polish on the block's assembly mode), and
/// the enclosure of the module's pose over `s` (x, y, z, alpha); `None` when the proof does not
/// go through (split `s`, or the block).
pub fn deviation_bound(block: &Block<'_>, s: Iv, mid: &ModulePose) -> Option<(Deviation, [Iv; 4])> {
    let m = block.machine;
    let g = &m.module;
    let (ra, rb) = (block.sliders(0.0), block.sliders(1.0));
    let sm = s.mid();
    let (over, at_mid) = enclose_segment_and_middle(g, &ra, &rb, s, mid)?;
    let zero = [Iv::point(0.0); 4];
    let dq: [f64; 2] = [block.qb[3] - block.qa[3], block.qb[4] - block.qa[4]];
    let theta = |s: Iv| -> [Iv; 2] {
        [
            Iv::point(block.qa[3]) + s * Iv::point(dq[0]),
            Iv::point(block.qa[4]) + s * Iv::point(dq[1]),
        ]
    };
    let table = &m.table;
    let pose_s = tool_pose_over(
        table,
        &over.pose,
        &over.rate,
        theta(s),
        dq,
        block.tool_length,
    );
    let pose_m = tool_pose_over(
        table,
        &at_mid,
        &zero,
        theta(Iv::point(sm)),
        dq,
        block.tool_length,
    );
    let around = s - Iv::point(sm);
    let intended = &block.intended;
    // The tip: e(s) = tip(s) - (a + s (b - a)).
    let line_m = intended.tip(sm);
    let chord = intended.b - intended.a;
    let tip: [Iv; 3] = std::array::from_fn(|i| {
        (pose_m.tip[i] - Iv::point(line_m[i])) + (pose_s.tip_rate[i] - Iv::point(chord[i])) * around
    });
    // The axis: e(s) = axis(s) - h(s).
    let (_, h_rate) = intended.axis_over(s);
    let (h_m, _) = intended.axis_over(Iv::point(sm));
    let axis: [Iv; 3] = std::array::from_fn(|i| {
        (pose_m.axis[i] - h_m[i]) + (pose_s.axis_rate[i] - h_rate[i]) * around
    });
    let norm = |v: &[Iv; 3]| {
        next_up(
            v.iter().map(|c| c.mag() * c.mag()).sum::<f64>().sqrt() * (1.0 + 4.0 * f64::EPSILON),
        )
    };
    let (tip, chord_axis) = (norm(&tip), norm(&axis));
    if !(tip.is_finite() && chord_axis.is_finite()) {
        return None;
    }
    // |a - h| = 2 sin(angle / 2) for unit vectors.
    let axis_rad = next_up(2.0 * (0.5 * chord_axis).min(1.0).asin() * (1.0 + 4.0 * f64::EPSILON));
    Some((
        Deviation {
            tip_mm: tip,
            axis_rad,
        },
        over.pose,
    ))
}

/// Whether a pose lies in an enclosure of the module's pose.
fn holds(enclosure: &[Iv; 4], pose: &ModulePose) -> bool {
    let x = [pose.p.x, pose.p.y, pose.p.z, pose.alpha];
    (0..4).all(|i| enclosure[i].lo <= x[i] && x[i] <= enclosure[i].hi)
}

/// The deviation's bound over the whole block, proved in `pieces` equal pieces of [0, 1]: the
/// largest bound of the pieces, or `None` when a piece is not proved. The proof covers the
/// assembly mode too: the first piece's enclosure holds the block's start pose and the last
/// one's its end pose, so the interpolated joints go from one to the other without leaving the
/// mode.
pub fn bound_in_pieces(block: &Block<'_>, pieces: usize) -> Option<Deviation> {
    let g = &block.machine.module;
    let mut worst = Deviation {
        tip_mm: 0.0,
        axis_rad: 0.0,
    };
    let mut pose = block.start;
    for k in 0..pieces {
        let (s0, s1) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
        let sm = 0.5 * (s0 + s1);
        let rho = block.sliders(sm);
        pose = polish_pose(g, pose, &rho);
        if residual_mm(g, &pose, &rho) > ACCEPT_RESIDUAL_MM {
            return None;
        }
        let (d, enclosure) = deviation_bound(block, Iv::new(s0, s1), &pose)?;
        if (k == 0 && !holds(&enclosure, &block.start))
            || (k + 1 == pieces && !holds(&enclosure, &block.end))
        {
            return None;
        }
        worst.tip_mm = worst.tip_mm.max(d.tip_mm);
        worst.axis_rad = worst.axis_rad.max(d.axis_rad);
    }
    Some(worst)
}

/// Proves the block within the tolerances (`tip_mm`, `axis_rad`), splitting [0, 1] into 1, 2, 4,
/// ... up to `max_pieces` equal pieces until every piece's bound is within them: the bound, or
/// `None` when no split proves it.
pub fn prove_within(
    block: &Block<'_>,
    tip_mm: f64,
    axis_rad: f64,
    max_pieces: usize,
) -> Option<Deviation> {
    let mut pieces = 1;
    while pieces <= max_pieces {
        if let Some(d) = bound_in_pieces(block, pieces)
            && d.tip_mm <= tip_mm
            && d.axis_rad <= axis_rad
        {
            return Some(d);
        }
        pieces *= 2;
    }
    None
}

/// The tip of the joints at s of the block: for tests and dense checks.
pub fn tip_at(block: &Block<'_>, s: f64, from: &ModulePose) -> Option<(Vector3<f64>, ModulePose)> {
    let g = &block.machine.module;
    let rho = block.sliders(s);
    let pose = polish_pose(g, *from, &rho);
    if residual_mm(g, &pose, &rho) > ACCEPT_RESIDUAL_MM {
        return None;
    }
    let q = block.joints(s);
    Some((
        tool_pose_eq26(&block.machine.table, &pose, q[3], q[4], block.tool_length).tip,
        pose,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::orientation::ToolOrientation;
    use crate::machine::{PathState, path_candidates};
    use crate::parallel_module::enclosure::enclose_segment;

    /// The block between two tool poses of the default machine, joints by the path follower.
    fn block_between<'a>(
        m: &'a Machine,
        a: (Vector3<f64>, Vector3<f64>),
        b: (Vector3<f64>, Vector3<f64>),
    ) -> Block<'a> {
        let mut state = PathState::default();
        let l = m.tool_length;
        let ra = state
            .next_row(m, &a.0, &ToolOrientation::Axis(a.1), l)
            .unwrap();
        let rb = state
            .next_row(m, &b.0, &ToolOrientation::Axis(b.1), l)
            .unwrap();
        let _ = path_candidates;
        Block {
            machine: m,
            tool_length: l,
            qa: [ra.rho.x, ra.rho.y, ra.rho.z, ra.theta1, ra.theta2],
            qb: [rb.rho.x, rb.rho.y, rb.rho.z, rb.theta1, rb.theta2],
            start: ra.module,
            end: rb.module,
            intended: IntendedMove::new(a.0, a.1, None, b.0, b.1, None).unwrap(),
        }
    }

    /// The proved bound holds the deviation at 2,001 points of the block (an independent dense
    /// check), on moves with tilt changes of 5 to 40 degrees; the ends are exact.
    #[test]
    fn the_bound_holds_the_dense_deviation() {
        let m = Machine::default_verne();
        let ax = |phi1: f64, phi2: f64| tool_axis(phi1.to_radians(), phi2.to_radians());
        let moves = [
            (
                (Vector3::new(80.0, 0.0, 30.0), ax(20.0, 0.0)),
                (Vector3::new(60.0, 10.0, 30.0), ax(25.0, 10.0)),
            ),
            (
                (Vector3::new(-40.0, 30.0, 10.0), ax(5.0, 90.0)),
                (Vector3::new(-50.0, 20.0, 12.0), ax(15.0, 80.0)),
            ),
            (
                (Vector3::new(0.0, 0.0, 40.0), ax(10.0, -30.0)),
                (Vector3::new(40.0, -40.0, 20.0), ax(40.0, -20.0)),
            ),
        ];
        for (a, b) in moves {
            let block = block_between(&m, a, b);
            let bound = bound_in_pieces(&block, 32).expect("proved");
            let mut pose = block.start;
            let mut dense: f64 = 0.0;
            let mut dense_axis: f64 = 0.0;
            for k in 0..=2000 {
                let s = k as f64 / 2000.0;
                let (d, p) = deviation_at(&block, s, &pose).expect("tracked");
                pose = p;
                dense = dense.max(d.tip_mm);
                dense_axis = dense_axis.max(d.axis_rad);
                if k == 0 || k == 2000 {
                    assert!(d.tip_mm < 1e-6 && d.axis_rad < 1e-8, "{d:?} at s = {s}");
                }
            }
            assert!(
                bound.tip_mm >= dense,
                "tip: bound {} < dense {dense}",
                bound.tip_mm
            );
            assert!(
                bound.axis_rad >= dense_axis,
                "axis: bound {} < dense {dense_axis}",
                bound.axis_rad
            );
            // Not vacuous: in 32 pieces, within 10 % of the truth (the mean-value form adds at most
            // |e'| / 64, and |e'| <= 4 max|e| on a parabola-like chord).
            assert!(
                bound.tip_mm < 1.1 * dense + 1e-4,
                "tip: bound {} vs dense {dense}",
                bound.tip_mm
            );
            assert!(
                bound.axis_rad < 1.1 * dense_axis + 1e-7,
                "axis: bound {} vs dense {dense_axis}",
                bound.axis_rad
            );
            // And proved within a tolerance just above the truth.
            assert!(prove_within(&block, 1.2 * dense, 1.2 * dense_axis + 1e-9, 256).is_some());
            assert!(prove_within(&block, 0.9 * dense, 1.0, 256).is_none());
            assert!(dense > 1e-4, "a move that deviates: {dense}");
        }
    }

    /// The interval tool pose holds eq. (26)'s at points, and its rate the central difference.
    #[test]
    fn tool_pose_over_holds_points_and_rates() {
        let m = Machine::default_verne();
        let ax = |phi1: f64, phi2: f64| tool_axis(phi1.to_radians(), phi2.to_radians());
        let block = block_between(
            &m,
            (Vector3::new(80.0, 0.0, 30.0), ax(20.0, 0.0)),
            (Vector3::new(60.0, 10.0, 30.0), ax(25.0, 10.0)),
        );
        let g = &m.module;
        let (ra, rb) = (block.sliders(0.0), block.sliders(1.0));
        let mid = polish_pose(g, block.start, &block.sliders(0.5));
        let s = Iv::new(0.25, 0.75);
        let enc = enclose_segment(g, &ra, &rb, s, &mid).unwrap();
        let dq = [block.qb[3] - block.qa[3], block.qb[4] - block.qa[4]];
        let theta = [
            Iv::point(block.qa[3]) + s * Iv::point(dq[0]),
            Iv::point(block.qa[4]) + s * Iv::point(dq[1]),
        ];
        let over = tool_pose_over(&m.table, &enc.pose, &enc.rate, theta, dq, block.tool_length);
        let mut pose = mid;
        for k in 0..=20 {
            let t = 0.25 + 0.5 * k as f64 / 20.0;
            let (tip, p) = tip_at(&block, t, &pose).unwrap();
            pose = p;
            let (tp, _) = tip_at(&block, t + 1e-6, &pose).unwrap();
            let (tm, _) = tip_at(&block, t - 1e-6, &pose).unwrap();
            let rate = (tp - tm) / 2e-6;
            for i in 0..3 {
                assert!(over.tip[i].lo <= tip[i] && tip[i] <= over.tip[i].hi);
                assert!(
                    over.tip_rate[i].lo - 1e-5 <= rate[i] && rate[i] <= over.tip_rate[i].hi + 1e-5
                );
            }
        }
    }

    /// A plunge along a vertical tool at a level table moves the three sliders alike and the
    /// platform by a translation: its joints are exact along the block. The first-order bound is
    /// not (the rate's enclosure is as wide as the pose's box), but it shrinks with the square of
    /// the piece, and in the linearizer's eight pieces it is inside the default chordal
    /// tolerance (verify's 0.01 mm): such a block is written as it is.
    #[test]
    fn a_pure_plunge_is_proved_in_eight_pieces() {
        let m = Machine::default_verne();
        let up = Vector3::new(0.0, 0.0, 1.0);
        for (x, y, z0, z1) in [(40.0, 0.0, 16.4, 12.8), (-25.5, 13.25, 5.6, 2.0)] {
            let block = block_between(
                &m,
                (Vector3::new(x, y, z0), up),
                (Vector3::new(x, y, z1), up),
            );
            let eight = bound_in_pieces(&block, 8).expect("proved");
            let sixteen = bound_in_pieces(&block, 16).expect("proved");
            assert!(
                eight.tip_mm < 0.008,
                "{eight:?} on the plunge at ({x}, {y})"
            );
            assert!(
                sixteen.tip_mm < 0.3 * eight.tip_mm,
                "{sixteen:?} vs {eight:?}"
            );
        }
    }
}
