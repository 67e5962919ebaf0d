//! The working branch of the inverse kinematics along a path of points (IFToMM 2007 section V),
//! by following the previous row's leg-I posture instead of isolating every root of the cubic
//! (9); the per-point solution ([`module_ik::solve_working_into`]) is the safety net.
//!
//! A row is tracked when Newton on eqs. (10) and (14) (leg I, unknowns alpha and rho1),
//! started from the previous rows' posture, converges to a posture whose cos(alpha) is certified
//! to be the only root of the cubic (9) with R1 cos(alpha) > r1: the cubic's derivative keeps one
//! sign on [r1/R1, 1] (it is a parabola, so its values at the ends and at its vertex decide).
//! Every feasible branch has R1 cos(alpha) > r1 and s1 = -1 (see [`crate::branches`]), and one
//! root of (9) carries exactly one posture with s1 = -1 (eq. (14) fixes the sign of alpha), so the
//! working branch, if the point has one, stands on that posture with the lower roots of (12) and
//! (13). Anything closer than the fast path's margins (alpha near 0, s1 or a square root near
//! zero, a cubic that is not monotone there, a row that is not feasible) goes to the per-point
//! solution, whose working branch is then followed.

use nalgebra::Vector3;

use crate::branches::cos_tilt_max;
use crate::machine::Machine;
use crate::module_ik::{
    self, FAST_MARGIN_MM, FAST_MARGIN_RAD, IkBranch, IkBranches, Leg1, eq9_coefficients,
    newton_leg1, working_on_posture,
};
use crate::trig::sin_cos_after_step;

/// How far (relative to the cubic's largest coefficient) its derivative must stay from zero on
/// [r1/R1, 1] for the root there to count as isolated.
const MONOTONE_MARGIN: f64 = 1e-9;

/// Newton steps allowed to settle leg I from a start (the previous rows' extrapolation, or the
/// per-point estimate): two or three from either on a path or a grid; more means the start was
/// poor and the per-point solution answers.
const LEG1_MAX_STEPS: usize = 6;

/// Follows the working branch from row to row; one per run of consecutive rows.
pub struct IkTracker<'m> {
    machine: &'m Machine,
    cos_tilt: f64,
    /// The previous row's leg-I posture.
    last: Option<Leg1>,
    /// (alpha, rho1) one and two rows before `last`, as far as the rows were tracked in a row
    /// (for the predictor).
    history: [Option<(f64, f64)>; 2],
    /// Rows answered by tracking and by the per-point solution.
    pub tracked: u64,
    pub solved: u64,
}

impl<'m> IkTracker<'m> {
    pub fn new(machine: &'m Machine) -> IkTracker<'m> {
        IkTracker {
            machine,
            cos_tilt: cos_tilt_max(machine),
            last: None,
            history: [None; 2],
            tracked: 0,
            solved: 0,
        }
    }

    /// The working branch for `p` into `out`: alone when tracked, as
    /// [`module_ik::solve_working_into`] gives it otherwise; [`module_ik::working`] of `out` is
    /// the answer either way.
    pub fn working_into(&mut self, p: &Vector3<f64>, out: &mut IkBranches) {
        if let Some(branch) = self.track(p) {
            self.tracked += 1;
            out.clear();
            out.push(branch);
            return;
        }
        self.solved += 1;
        self.history = [None; 2];
        module_ik::solve_working_into(self.machine, p, out);
        self.last = module_ik::working(out).map(|w| {
            let (sin, cos) = w.alpha.sin_cos();
            Leg1 {
                alpha: w.alpha,
                rho1: w.rho.x,
                sin,
                cos,
            }
        });
    }

    fn track(&mut self, p: &Vector3<f64>) -> Option<IkBranch> {
        let m = self.machine;
        let prev = self.last.take()?;
        // Start from the previous posture, extrapolated along the path (quadratically from three
        // rows, linearly from two): Newton then needs one step.
        let (a1, r1) = (prev.alpha, prev.rho1);
        let predicted = match self.history {
            [Some((a2, r2)), Some((a3, r3))] => Some((3.0 * (a1 - a2) + a3, 3.0 * (r1 - r2) + r3)),
            [Some((a2, r2)), None] => Some((2.0 * a1 - a2, 2.0 * r1 - r2)),
            _ => None,
        };
        let start = match predicted {
            Some((alpha, rho1)) => {
                let (sin, cos) = sin_cos_after_step(prev.sin, prev.cos, alpha, a1 - alpha);
                Leg1 {
                    alpha,
                    rho1,
                    sin,
                    cos,
                }
            }
            None => prev,
        };
        let (branch, leg1) = certified_working(m, p, start, self.cos_tilt)?;
        self.history = [Some((a1, r1)), self.history[0]];
        self.last = Some(leg1);
        Some(branch)
    }
}

/// The working branch for `p` by Newton on leg I from `start`, when the result is certified (see
/// the module documentation), with its leg-I posture; None when unsure, or when the branch found
/// is not feasible (the per-point solution then says why).
pub(crate) fn certified_working(
    m: &Machine,
    p: &Vector3<f64>,
    start: Leg1,
    cos_tilt: f64,
) -> Option<(IkBranch, Leg1)> {
    let leg1 = certified_posture(m, p, start)?;
    let branch = working_on_posture(m, p, &leg1, cos_tilt).ok()??;
    Some((branch, leg1))
}

/// The leg-I posture with s1 = -1 on the only root of the cubic (9) with R1 cos(alpha) > r1, by
/// Newton on leg I from `start`, when that root is certified to be alone there and the posture
/// is clear of the fast path's margins; None when unsure.
pub(crate) fn certified_posture(m: &Machine, p: &Vector3<f64>, start: Leg1) -> Option<Leg1> {
    let g = &m.module;
    if !p.iter().all(|v| v.is_finite()) || !isolated_working_root(m, p) {
        return None;
    }
    let leg1 = newton_leg1(g, p, start, LEG1_MAX_STEPS)?;
    // The posture must be a root with R1 cos(alpha) > r1, away from alpha = 0 (where the two
    // postures of a root meet) and with s1 = -1 by a margin.
    let clear = g.r_big1 * leg1.cos - g.r_small1 > FAST_MARGIN_MM
        && leg1.sin.abs() > FAST_MARGIN_RAD
        && leg1.rho1 - p.z < -FAST_MARGIN_MM;
    clear.then_some(leg1)
}

/// True when the cubic (9) of `p` has at most one root with cos(alpha) in [r1/R1, 1] (slightly
/// widened), certified by the sign of its derivative, which is a parabola opening upwards (the
/// leading coefficient 2 R1^3 r1 is positive): negative at both ends means negative between;
/// positive at both ends and at the vertex (when inside) means positive throughout.
pub(crate) fn isolated_working_root(m: &Machine, p: &Vector3<f64>) -> bool {
    let g = &m.module;
    // The coefficients of (9) as cubic_eq9 has them, without its normalisation (no division):
    // the margin is taken relative to the largest.
    let [c0, c1, c2, c3] = eq9_coefficients(g, p);
    // Plain comparisons (no NaN handling of f64::max): a NaN coefficient fails every test below.
    let larger = |a: f64, b: f64| if a > b { a } else { b };
    let largest = larger(larger(c0.abs(), c1.abs()), larger(c2.abs(), c3.abs()));
    let margin = MONOTONE_MARGIN * largest;
    let leading_positive = c3 > margin;
    if !leading_positive || !margin.is_finite() {
        return false;
    }
    let lo = (g.r_small1 / g.r_big1 - FAST_MARGIN_RAD).max(-1.0);
    let d = |x: f64| (3.0 * c3 * x + 2.0 * c2) * x + c1;
    let (d_lo, d_hi) = (d(lo), d(1.0));
    if d_lo < -margin && d_hi < -margin {
        return true;
    }
    // Vertex x_v = -c2 / (3 c3), where the derivative is c1 - c2^2 / (3 c3); c3 > 0.
    let vertex_inside = -c2 > 3.0 * c3 * lo && -c2 < 3.0 * c3;
    d_lo > margin
        && d_hi > margin
        && (!vertex_inside || 3.0 * c3 * c1 - c2 * c2 > 3.0 * c3 * margin)
}
