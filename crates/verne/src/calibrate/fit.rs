//! The fit: Levenberg-Marquardt on the weighted residuals, the machine's parameters and the
//! instrument's together, the forward kinematics of every row followed at each trial step on
//! its working mode ([`super::model::followed_poses`]); then the parameters' sigmas from the
//! residuals and their correlations.
//!
//! A step solves min |J d + r|^2 + lambda |D d|^2 (D^2 = diag(J^T J), Marquardt's scaling) from
//! the singular value decomposition of J D^-1, so that each trial lambda costs no
//! factorisation. A trial is taken when the residuals decrease and every row's mode is followed
//! (certified nearest the previous one); otherwise lambda grows and the step shrinks.

use nalgebra::{DMatrix, DVector, Matrix4};

use crate::parallel_module::equations::ModulePose;
use crate::spec::Machine;

use super::jacobian::jacobian;
use super::model::{
    Instrument, Measurement, Noise, NuisanceParam, followed_poses, moved_instruments, residuals,
};
use super::params::{Param, moved};

/// Most iterations (Jacobians) of one fit: the VERNE's fits from a nominal machine a few
/// tenths of a millimetre off converge in about five.
pub const MAX_ITERATIONS: usize = 60;

/// The fit has converged when an accepted step lowers the sum of squares by less than this
/// fraction of it.
pub const COST_REL_TOL: f64 = 1e-12;

/// ... or when the step, in the scaled parameters (D d), is below this fraction of |D x|.
pub const STEP_REL_TOL: f64 = 1e-12;

/// Lambda's first value, relative to the scaled J^T J (whose diagonal is 1), and its bounds.
const LAMBDA_START: f64 = 1e-4;
const LAMBDA_MAX: f64 = 1e12;
const LAMBDA_MIN: f64 = 1e-15;

/// The state of a fit: the machine and instrument, each row's pose and A^-1 there, the
/// weighted residuals.
#[derive(Debug, Clone)]
pub struct State {
    pub machine: Machine,
    /// Each data set's instrument.
    pub instruments: Vec<Instrument>,
    pub poses: Vec<ModulePose>,
    pub inverses: Vec<Matrix4<f64>>,
    pub residuals: DVector<f64>,
}

impl State {
    /// The sum of squares of the weighted residuals.
    pub fn cost(&self) -> f64 {
        self.residuals.norm_squared()
    }
}

/// What one fit did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Work {
    /// Jacobians evaluated.
    pub iterations: usize,
    /// Forward kinematics solved (every row of every trial step; the complete solutions of the
    /// first poses are counted by the caller).
    pub fk_evaluations: u64,
}

/// The state at `machine` and `instruments` with every row followed from `previous`; None when
/// a row's mode cannot be followed.
pub fn state_at(
    machine: Machine,
    instruments: Vec<Instrument>,
    rows: &[Measurement],
    previous: &[ModulePose],
    noise: &Noise,
    work: &mut Work,
) -> Option<State> {
    work.fk_evaluations += rows.len() as u64;
    let (poses, inverses) = followed_poses(&machine, rows, previous)?;
    let residuals = residuals(&machine, &instruments, rows, &poses, noise);
    residuals.iter().all(|r| r.is_finite()).then_some(State {
        machine,
        instruments,
        poses,
        inverses,
        residuals,
    })
}

/// Levenberg-Marquardt from `start` on the `params` and `nuisance` given (the others held).
pub fn fit(
    start: State,
    rows: &[Measurement],
    params: &[Param],
    nuisance: &[NuisanceParam],
    noise: &Noise,
    work: &mut Work,
) -> State {
    let mut cur = start;
    let n = params.len() + nuisance.len();
    if n == 0 {
        return cur;
    }
    let mut lambda = LAMBDA_START;
    for _ in 0..MAX_ITERATIONS {
        work.iterations += 1;
        let j = jacobian(
            &cur.machine,
            &cur.instruments,
            rows,
            &cur.poses,
            &cur.inverses,
            params,
            nuisance,
            noise,
        );
        let scale: Vec<f64> = (0..n)
            .map(|c| {
                let s = j.column(c).norm();
                if s > 0.0 { s } else { 1.0 }
            })
            .collect();
        let mut js = j.clone();
        for (c, s) in scale.iter().enumerate() {
            js.column_mut(c).scale_mut(1.0 / s);
        }
        let svd = js.svd(true, true);
        let (Some(u), Some(vt)) = (&svd.u, &svd.v_t) else {
            break;
        };
        let ur = u.transpose() * &cur.residuals;
        let cost = cur.cost();
        let mut accepted = None;
        while lambda <= LAMBDA_MAX {
            // d_s = -V diag(s / (s^2 + lambda)) U^T r, d = D^-1 d_s.
            let k = DVector::from_iterator(
                svd.singular_values.len(),
                svd.singular_values
                    .iter()
                    .zip(ur.iter())
                    .map(|(&s, &r)| -s * r / (s * s + lambda)),
            );
            let ds = vt.transpose() * k;
            let d: Vec<f64> = ds.iter().zip(&scale).map(|(x, s)| x / s).collect();
            let machine = moved(&cur.machine, params, &d[..params.len()]);
            let instruments = moved_instruments(&cur.instruments, nuisance, &d[params.len()..]);
            match state_at(machine, instruments, rows, &cur.poses, noise, work) {
                Some(trial) if trial.cost() < cost => {
                    lambda = (lambda / 10.0).max(LAMBDA_MIN);
                    accepted = Some((trial, ds.norm()));
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        let Some((next, step)) = accepted else {
            break;
        };
        let gain = (cost - next.cost()) / cost.max(f64::MIN_POSITIVE);
        cur = next;
        if gain < COST_REL_TOL || step < STEP_REL_TOL * (1.0 + step) {
            break;
        }
    }
    cur
}

/// The covariance of the fitted parameters (columns of `j`), for residuals whose noise is
/// `scale` times the weights' (scale^2 (J^T J)^-1 by the decomposition of J; directions of J's
/// rank deficiency, if any, infinite on the diagonal).
pub fn covariance(j: &DMatrix<f64>, scale: f64) -> DMatrix<f64> {
    let n = j.ncols();
    let norms: Vec<f64> = (0..n)
        .map(|c| {
            let s = j.column(c).norm();
            if s > 0.0 { s } else { 1.0 }
        })
        .collect();
    let mut js = j.clone();
    for (c, s) in norms.iter().enumerate() {
        js.column_mut(c).scale_mut(1.0 / s);
    }
    let svd = js.svd(false, true);
    let Some(vt) = svd.v_t else {
        return DMatrix::from_element(n, n, f64::INFINITY);
    };
    let mut cov = DMatrix::zeros(n, n);
    for (k, &s) in svd.singular_values.iter().enumerate() {
        let w = if s > 0.0 {
            1.0 / (s * s)
        } else {
            f64::INFINITY
        };
        let v = vt.row(k).transpose();
        cov += (&v * v.transpose()) * w;
    }
    for a in 0..n {
        for b in 0..n {
            cov[(a, b)] *= scale * scale / (norms[a] * norms[b]);
        }
    }
    cov
}
