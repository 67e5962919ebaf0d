//! The working assembly mode along a path of slider positions (forward kinematics, IFToMM 2007
//! section VI), by following the previous row's mode instead of solving the degree-8 polynomial
//! on every row; the complete solution ([`fk::solve`]) is the safety net.
//!
//! A row is tracked when chord iterations on eqs. (3)-(6) (the previous solution's inverse
//! Jacobian) converge from the previous pose q0 to a pose q* that is certified to be the mode
//! nearest q0: with beta = |J(q*)^-1| and L a Lipschitz constant of J, every other solution lies
//! at least 2 / (beta L) from q* (from f(y) = J(q*)(y - q*) + E, |E| <= L/2 |y - q*|^2), so
//! |q* - q0| < 1 / (2 beta L) leaves no other solution nearer q0 than q*. The mode must also keep
//! the machine's configuration and limits. Anything else (the first row of a run, a jump, the
//! neighbourhood of a parallel singularity where two modes meet, a limit) goes to the complete
//! solution, whose working mode is then followed.
//!
//! On a machine whose feasible mode is unique (the default machine: checked over joint grids and
//! property tests), the tracked mode is the working mode [`fk::working`] picks.

use nalgebra::{Matrix4, Vector4};

use crate::parallel_module::branches::{WORKING_CONFIG, label};
use crate::parallel_module::equations::{
    ModulePose, Sliders, jacobian_pose, residuals, residuals_jacobian_sin_cos,
};
use crate::parallel_module::fk::{self, FkMode, FkModes};
use crate::parallel_module::ik::wrap_angle;
use crate::spec::{Machine, ModuleGeometry};
use crate::tolerance::NEWTON_MAX_ITER;

/// Chord iterations before a row goes to the complete solution.
const MAX_CHORD_STEPS: usize = 8;
/// A chord step below this (mm, alpha scaled by the platform radius) ends the iteration: the
/// next one would be below rounding.
const STEP_DONE_MM: f64 = 1e-11;
/// Fraction of the certified isolation radius 2 / (beta L) a row may move the pose.
const CERTIFIED_FRACTION: f64 = 0.25;

/// The assembly mode nearest `from` for the sliders `rho` (joints) of the geometry `g`, when it
/// is certified to be: Newton on eqs. (3)-(6) from `from` converges to q*, and q* moved less
/// than `CERTIFIED_FRACTION` (1/4) of the isolation radius 2 / (beta L) from `from` (the lemma of
/// the module documentation, the bounds of [`FkTracker`]), so that no other solution of the
/// equations is nearer `from`. Also returns A^-1 at q* (A = d(residuals)/d(pose)). For a
/// caller whose geometry changes between calls (a calibration's steps) as the sliders do along a
/// path; None when Newton does not converge or the step is not certified.
pub fn nearest_mode(
    g: &ModuleGeometry,
    from: &ModulePose,
    rho: &Sliders,
) -> Option<(ModulePose, Matrix4<f64>)> {
    let radius = g.r_big1.max(g.r_big2);
    let lipschitz = 4.0 * (3.0 + g.l1.max(g.l2).max(g.l3) / radius);
    let scaled = |d: &Vector4<f64>| Vector4::new(d[0], d[1], d[2], d[3] * radius).norm();
    let mut pose = *from;
    let mut converged = false;
    for _ in 0..NEWTON_MAX_ITER {
        let (f, a, _) = residuals_jacobian_sin_cos(g, &pose, rho);
        let step = a.try_inverse()? * f;
        if !step.iter().all(|v| v.is_finite()) {
            return None;
        }
        pose.p -= step.xyz();
        pose.alpha -= step[3];
        if scaled(&step) < STEP_DONE_MM {
            converged = true;
            break;
        }
    }
    if !converged {
        return None;
    }
    let inv = jacobian_pose(g, &pose, rho).try_inverse()?;
    let beta = Matrix4::from_fn(|i, j| {
        if i == 3 {
            inv[(i, j)] * radius
        } else {
            inv[(i, j)]
        }
    })
    .norm();
    let moved = scaled(&Vector4::new(
        pose.p.x - from.p.x,
        pose.p.y - from.p.y,
        pose.p.z - from.p.z,
        wrap_angle(pose.alpha - from.alpha),
    ));
    (moved * beta * lipschitz < 2.0 * CERTIFIED_FRACTION).then(|| {
        pose.alpha = wrap_angle(pose.alpha);
        (pose, inv)
    })
}

/// Follows the working mode from row to row; one per run of consecutive rows.
pub struct FkTracker<'m> {
    machine: &'m Machine,
    /// Length by which alpha is scaled, so that pose differences are in mm.
    radius: f64,
    /// Lipschitz constant of the Jacobian in the scaled pose (mm^2 / mm^2 per mm).
    lipschitz: f64,
    /// The previous row's mode and the inverse Jacobian there.
    last: Option<(FkMode, Matrix4<f64>)>,
    /// The pose two rows back, when the previous row was tracked from it (for the predictor).
    before_last: Option<ModulePose>,
    /// Rows answered by tracking and by the complete solution.
    pub tracked: u64,
    pub solved: u64,
    /// Chord steps taken, tracked or not (the predictor's worth: fewer steps a row).
    pub chord_steps: u64,
}

impl<'m> FkTracker<'m> {
    pub fn new(machine: &'m Machine) -> FkTracker<'m> {
        let g = &machine.module;
        let radius = g.r_big1.max(g.r_big2);
        let lmax = g.l1.max(g.l2).max(g.l3);
        // Second derivatives of |v_i|^2 - L_i^2 in (x, y, z, radius * alpha): 2 on x, y, z, at
        // most 2 across, at most 2 (1 + L_i / radius) on alpha: |H_i| <= 2 (3 + L / radius),
        // and |J(a) - J(b)| <= sqrt(4) max |H_i| |a - b|.
        let lipschitz = 4.0 * (3.0 + lmax / radius);
        FkTracker {
            machine,
            radius,
            lipschitz,
            last: None,
            before_last: None,
            tracked: 0,
            solved: 0,
            chord_steps: 0,
        }
    }

    /// The working mode for `rho` into `out`: alone when tracked, every mode otherwise;
    /// [`fk::working`] of `out` is the answer either way.
    pub fn working_into(&mut self, rho: &Sliders, out: &mut FkModes) {
        out.clear();
        if let Some(mode) = self.track(rho) {
            self.tracked += 1;
            out.push(mode);
            return;
        }
        self.solved += 1;
        self.before_last = None;
        *out = fk::solve(self.machine, rho);
        let g = &self.machine.module;
        self.last = fk::working(out).and_then(|w| {
            jacobian_pose(g, &w.pose, rho)
                .try_inverse()
                .map(|inv| (*w, inv))
        });
    }

    fn track(&mut self, rho: &Sliders) -> Option<FkMode> {
        let g = &self.machine.module;
        let (prev, inv_prev) = self.last.take()?;
        let scaled = |d: &Vector4<f64>| Vector4::new(d[0], d[1], d[2], d[3] * self.radius).norm();
        // Start from the previous pose, or its linear extrapolation along the path.
        let mut pose = match self.before_last.take() {
            Some(b) => ModulePose {
                p: 2.0 * prev.pose.p - b.p,
                alpha: 2.0 * prev.pose.alpha - b.alpha,
            },
            None => prev.pose,
        };
        let mut converged = false;
        for _ in 0..MAX_CHORD_STEPS {
            self.chord_steps += 1;
            let step = inv_prev * residuals(g, &pose, rho);
            if !step.iter().all(|v| v.is_finite()) {
                return None;
            }
            pose.p -= step.xyz();
            pose.alpha -= step[3];
            if scaled(&step) < STEP_DONE_MM {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        let (_, jac, (s, c)) = residuals_jacobian_sin_cos(g, &pose, rho);
        let inv = jac.try_inverse()?;
        // beta = |J^-1| in the scaled pose (Frobenius norm, an upper bound of the 2-norm).
        let beta = Matrix4::from_fn(|i, j| {
            if i == 3 {
                inv[(i, j)] * self.radius
            } else {
                inv[(i, j)]
            }
        })
        .norm();
        let moved = scaled(&Vector4::new(
            pose.p.x - prev.pose.p.x,
            pose.p.y - prev.pose.p.y,
            pose.p.z - prev.pose.p.z,
            wrap_angle(pose.alpha - prev.pose.alpha),
        ));
        let certified = moved * beta * self.lipschitz < 2.0 * CERTIFIED_FRACTION;
        if !certified {
            return None;
        }
        pose.alpha = wrap_angle(pose.alpha);
        let mode = self.labelled(&pose, rho, s, c)?;
        self.last = Some((mode, inv));
        self.before_last = Some(prev.pose);
        Some(mode)
    }

    /// The mode with its configuration and verdict, when it is the machine's and feasible;
    /// (s, c) = sin, cos of its alpha.
    fn labelled(&self, pose: &ModulePose, rho: &Sliders, s: f64, c: f64) -> Option<FkMode> {
        let (config, verdict) = label(self.machine, &pose.p, s, c, rho);
        (config == WORKING_CONFIG && verdict.feasible()).then_some(FkMode {
            pose: *pose,
            config,
            verdict,
        })
    }
}
