//! Calibration of a VERNE-type machine: the parameters of its machine file that make its
//! kinematics match measurements of the real machine, with what the measurements can and
//! cannot determine, in words.
//!
//! - [`params`]: the machine file's parameters a calibration can move (the module's dimensions
//!   of eqs. (3)-(6) of IFToMM 2007, the joints' zero offsets, the tool length, the table of eq.
//!   (7) of AIM 2007), with units and prior bounds;
//! - [`model`]: the measurements (tracker, the module alone, double ballbar, probe) and the
//!   machine's model of them, the forward kinematics followed on the working mode;
//! - [`jacobian`]: the exact identification Jacobian, by implicit differentiation of eqs.
//!   (3)-(6);
//! - [`identifiability`]: the rank of the scaled Jacobian and the combinations the readings
//!   cannot see;
//! - [`fit`](mod@fit): Levenberg-Marquardt, sigmas and correlations;
//! - [`plan`]: D-optimal poses for a device (exchange algorithm) with the predicted sigmas;
//! - [`synthetic`]: perturbed machines and what instruments read of them, for tests and
//!   examples.
//!
//! [`calibrate`] runs them in order: the rows' modes on the nominal machine, the instrument's
//! first estimate, what the readings determine, the fit of that, the checks (rows far from the
//! model, parameters beyond their prior bounds, the calibrated machine file's validity) and a
//! k-fold hold-out.

pub mod fit;
pub mod identifiability;
pub mod jacobian;
pub mod model;
pub mod params;
pub mod plan;
pub mod synthetic;

use nalgebra::DVector;

use crate::error::MachineError;
use crate::spec::Machine;

pub use identifiability::{Held, Identifiability};
pub use model::{
    DEFAULT_NOISE, Device, Instrument, Measurement, Noise, Nuisance, NuisanceParam, Observed,
    RowProblem,
};
pub use params::Param;

use fit::{State, Work, covariance, fit, state_at};
use model::{initial_instruments, initial_poses, noise_of, nuisance_columns};

/// A row whose reading is farther than this (mm) from what the nominal machine gives at its
/// joints, once the instrument is placed, is not a reading of those joints: no machine within
/// the parameters' prior bounds ([`params::PRIOR_BOUND_MM`]) is that far from its drawing.
pub const FAR_ROW_MM: f64 = 25.0;

/// After the fit, a row whose residual exceeds this many times the residuals' robust sigma
/// (1.4826 times their median absolute value) is an outlier: with Gaussian noise of the sigma
/// the fit finds, one in 1e15 rows.
pub const OUTLIER_SIGMAS: f64 = 8.0;

/// The robust sigma of the outlier test is at least this fraction of the readings' stated noise:
/// readings without noise (a plan's own) leave residuals of rounding, whose ratios mean
/// nothing.
pub const OUTLIER_FLOOR: f64 = 0.01;

/// Pairs of parameters whose estimates are correlated beyond this are flagged: the readings
/// tell little of their difference (or sum) apart.
pub const CORRELATION_FLAG: f64 = 0.95;

/// The hold-out's folds by default.
pub const DEFAULT_FOLDS: usize = 5;

/// How to calibrate.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// The parameters the fit may move; empty: those of the data sets' devices
    /// ([`Device::parameters`]).
    pub free: Vec<Param>,
    /// Parameters held at their nominal values whatever `free` says.
    pub fixed: Vec<Param>,
    /// The readings' noise (the weights; the sigmas scale with the residuals).
    pub noise: Noise,
    /// Folds of the hold-out (0: none).
    pub folds: usize,
    /// Prior bounds other than the defaults (stored units: mm, rad).
    pub priors: Vec<(Param, f64)>,
    /// Accept parameters that move beyond their prior bounds.
    pub allow_large: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            free: Vec::new(),
            fixed: Vec::new(),
            noise: DEFAULT_NOISE,
            folds: DEFAULT_FOLDS,
            priors: Vec::new(),
            allow_large: false,
        }
    }
}

impl Options {
    /// The prior bound of a parameter (stored units).
    pub fn prior(&self, p: Param) -> f64 {
        self.priors
            .iter()
            .rev()
            .find(|(q, _)| *q == p)
            .map_or(p.default_prior(), |(_, b)| *b)
    }
}

/// Residuals in the readings' units: lengths (mm), and tool axes (rad) when measured.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Residuals {
    /// Root mean square of every length reading's residual, per coordinate (mm).
    pub rms_mm: f64,
    /// The largest |residual| of a length reading (mm).
    pub max_mm: f64,
    /// The same for tool axes (rad), when there are any.
    pub rms_axis_rad: Option<f64>,
    pub max_axis_rad: Option<f64>,
}

/// One parameter's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    pub param: Param,
    /// Nominal and calibrated values (stored units).
    pub nominal: f64,
    pub value: f64,
    /// 1 sigma (stored units) when identified; None when held.
    pub sigma: Option<f64>,
}

/// A parameter the readings determine too poorly: its sigma beyond its prior bound.
#[derive(Debug, Clone, PartialEq)]
pub struct Weak {
    pub param: Param,
    /// Its 1 sigma and prior bound (stored units).
    pub sigma: f64,
    pub bound: f64,
}

/// A calibration.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// The device of each data set.
    pub devices: Vec<Device>,
    /// The calibrated machine (the nominal with the identified parameters moved).
    pub machine: Machine,
    /// Every parameter considered, identified or held, in the machine file's order.
    pub estimates: Vec<Estimate>,
    /// What the readings determine (at the nominal machine).
    pub identifiability: Identifiability,
    /// Parameters held because the readings determine them too poorly.
    pub weak: Vec<Weak>,
    /// Each data set's instrument fitted, and the instruments' parameters' values and 1 sigma
    /// (stored units: rad for the frames' rotation vectors, mm).
    pub instruments: Vec<Instrument>,
    pub instrument_estimates: Vec<(NuisanceParam, f64, f64)>,
    /// Pairs of estimates correlated beyond [`CORRELATION_FLAG`] (keys, correlation).
    pub correlations: Vec<(String, String, f64)>,
    /// Residuals with the nominal machine (the instrument fitted to it) and the calibrated one.
    pub before: Residuals,
    pub after: Residuals,
    /// Residuals of rows held out of a fit on the others, [`Options::folds`] folds; None when
    /// there are too few rows.
    pub holdout: Option<Residuals>,
    /// The noise the residuals say (mm): the length weight times the fit's scale.
    pub noise_mm: f64,
    pub rows: usize,
    pub readings: usize,
    /// Forward kinematics solved: complete solutions (the nominal modes) and followed ones.
    pub fk_complete: u64,
    pub fk_followed: u64,
    /// Levenberg-Marquardt iterations (Jacobians) of the main fit.
    pub iterations: usize,
}

/// Why a calibration gave no machine.
#[derive(Debug, Clone, PartialEq)]
pub enum CalibrationError {
    /// No rows, or rows of two devices.
    Input(String),
    /// Fewer readings than unknowns (the fit's parameters and the instrument's).
    TooFew { readings: usize, unknowns: usize },
    /// Rows that cannot be used: no mode of the machine's kind, far from the model, outliers.
    Rows(Vec<RowProblem>),
    /// Parameters moved beyond their prior bounds: (parameter, change, bound, sigma), stored
    /// units.
    Prior(Vec<(Param, f64, f64, f64)>),
    /// The calibrated machine is not a valid machine file.
    Invalid(MachineError),
}

impl std::fmt::Display for CalibrationError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CalibrationError::Input(s) => f.write_str(s),
            CalibrationError::TooFew { readings, unknowns } => write!(
                f,
                "{readings} readings for {unknowns} unknowns (the machine's parameters and the instrument's): a fit needs more readings than unknowns"
            ),
            CalibrationError::Rows(rows) => {
                write!(
                    f,
                    "{} row{} cannot be used",
                    rows.len(),
                    if rows.len() == 1 { "" } else { "s" }
                )?;
                for r in rows {
                    write!(f, "\n  line {}: {}", r.line, r.message)?;
                }
                Ok(())
            }
            CalibrationError::Prior(list) => {
                write!(
                    f,
                    "the fit moves parameters beyond their prior bounds (refused; allow it to accept)"
                )?;
                for (p, change, bound, sigma) in list {
                    write!(
                        f,
                        "\n  {}: {:+.4} {u} (1 sigma {:.4} {u}) beyond +-{} {u}",
                        p.key(),
                        p.shown(*change),
                        p.shown(*sigma),
                        p.shown(*bound),
                        u = p.unit()
                    )?;
                }
                Ok(())
            }
            CalibrationError::Invalid(e) => write!(f, "the calibrated machine is not valid: {e}"),
        }
    }
}

impl std::error::Error for CalibrationError {}

/// The residuals of `state` in the readings' units.
fn residual_stats(rows: &[Measurement], r: &DVector<f64>, noise: &Noise) -> Residuals {
    let (mut len_sq, mut len_n, mut len_max) = (0.0, 0usize, 0.0f64);
    let (mut ax_sq, mut ax_n, mut ax_max) = (0.0, 0usize, 0.0f64);
    let mut sigma = [0.0; 6];
    let mut k = 0;
    for row in rows {
        noise_of(row, noise, &mut sigma);
        for j in 0..row.observed.len() {
            let v = (r[k + j] * sigma[j]).abs();
            if j >= 3 {
                ax_sq += v * v;
                ax_n += 1;
                ax_max = ax_max.max(v);
            } else {
                len_sq += v * v;
                len_n += 1;
                len_max = len_max.max(v);
            }
        }
        k += row.observed.len();
    }
    Residuals {
        rms_mm: (len_sq / len_n.max(1) as f64).sqrt(),
        max_mm: len_max,
        rms_axis_rad: (ax_n > 0).then(|| (ax_sq / ax_n as f64).sqrt()),
        max_axis_rad: (ax_n > 0).then_some(ax_max),
    }
}

/// Each row's largest residual, as a length where it has one (mm; axes in rad).
fn row_residuals(rows: &[Measurement], r: &DVector<f64>, noise: &Noise) -> Vec<f64> {
    let mut out = Vec::with_capacity(rows.len());
    let mut sigma = [0.0; 6];
    let mut k = 0;
    for row in rows {
        noise_of(row, noise, &mut sigma);
        let len = row.observed.len().min(3);
        let v = (0..len)
            .map(|j| (r[k + j] * sigma[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        out.push(v);
        k += row.observed.len();
    }
    out
}

/// The rows' checks before a fit: data sets numbered from 0, one device each, finite joints
/// and readings. The device of each set.
fn check_rows(rows: &[Measurement]) -> Result<Vec<Device>, CalibrationError> {
    if rows.is_empty() {
        return Err(CalibrationError::Input("no measurements".into()));
    }
    let sets = rows.iter().map(|r| r.set).max().unwrap_or(0) + 1;
    let mut devices: Vec<Option<Device>> = vec![None; sets];
    for row in rows {
        let d = row.observed.device();
        match devices[row.set] {
            None => devices[row.set] = Some(d),
            Some(first) if first != d => {
                return Err(CalibrationError::Input(format!(
                    "line {}: a {} reading among {} readings: one device per data set",
                    row.line,
                    d.name(),
                    first.name()
                )));
            }
            Some(_) => {}
        }
    }
    let Some(devices) = devices.into_iter().collect::<Option<Vec<Device>>>() else {
        return Err(CalibrationError::Input("a data set without rows".into()));
    };
    let mut problems = Vec::new();
    let mut values = [0.0; 6];
    for row in rows {
        model::observed_values(row, &mut values);
        let finite = row.rho.iter().all(|v| v.is_finite())
            && row.theta.iter().all(|v| v.is_finite())
            && values[..row.observed.len()].iter().all(|v| v.is_finite());
        if !finite {
            problems.push(RowProblem {
                line: row.line,
                message: "a joint or a reading is not a finite number".into(),
            });
        }
    }
    if problems.is_empty() {
        Ok(devices)
    } else {
        Err(CalibrationError::Rows(problems))
    }
}

/// The parameters a fit considers: `options.free` (or the devices'), less `options.fixed`, in
/// the machine file's order.
fn considered(devices: &[Device], options: &Options) -> Vec<Param> {
    let base: Vec<Param> = if options.free.is_empty() {
        devices.iter().flat_map(|d| d.parameters()).collect()
    } else {
        options.free.clone()
    };
    params::ALL
        .into_iter()
        .filter(|p| base.contains(p) && !options.fixed.contains(p))
        .collect()
}

/// The nominal state: every row's working mode by the complete forward kinematics, the
/// instrument placed by its closed form, then fitted alone.
fn nominal_state(
    nominal: &Machine,
    rows: &[Measurement],
    nuisance: &[NuisanceParam],
    sets: usize,
    noise: &Noise,
    work: &mut Work,
) -> Result<State, CalibrationError> {
    let poses = initial_poses(nominal, rows).map_err(CalibrationError::Rows)?;
    let instruments = initial_instruments(nominal, rows, &poses, sets);
    let state =
        state_at(nominal.clone(), instruments, rows, &poses, noise, work).ok_or_else(|| {
            CalibrationError::Input("the nominal machine's modes could not be followed".into())
        })?;
    Ok(fit(state, rows, &[], nuisance, noise, work))
}

/// Calibrates `nominal` from `rows` (see the module documentation).
pub fn calibrate(
    nominal: &Machine,
    rows: &[Measurement],
    options: &Options,
) -> Result<Calibration, CalibrationError> {
    let devices = check_rows(rows)?;
    let noise = &options.noise;
    let candidates = considered(&devices, options);
    let nuisance = &nuisance_columns(&devices)[..];
    let readings: usize = rows.iter().map(|r| r.observed.len()).sum();
    let unknowns = candidates.len() + nuisance.len();
    if readings <= unknowns {
        return Err(CalibrationError::TooFew { readings, unknowns });
    }
    let mut work = Work::default();
    let start = nominal_state(nominal, rows, nuisance, devices.len(), noise, &mut work)?;
    let fk_complete = rows.len() as u64;
    // Rows far from the nominal model, the instrument placed.
    let far: Vec<RowProblem> = rows
        .iter()
        .zip(row_residuals(rows, &start.residuals, noise))
        .filter(|(_, r)| r.is_nan() || *r > FAR_ROW_MM)
        .map(|(row, r)| RowProblem {
            line: row.line,
            message: format!(
                "the reading is {r:.3} mm from what the nominal machine gives at these joints (more than {FAR_ROW_MM} mm): far from any pose the machine reaches with them"
            ),
        })
        .collect();
    if !far.is_empty() {
        return Err(CalibrationError::Rows(far));
    }
    let before = residual_stats(rows, &start.residuals, noise);
    // What the readings determine, at the nominal machine.
    let j0 = jacobian::jacobian(
        &start.machine,
        &start.instruments,
        rows,
        &start.poses,
        &start.inverses,
        &candidates,
        nuisance,
        noise,
    );
    let ident = identifiability::analyse(&j0, &candidates, &devices);
    let mut free = ident.identified.clone();
    let mut weak = Vec::new();
    // Fit; a parameter whose sigma exceeds its prior bound is held and the fit run again.
    let (state, cov, scale, iterations) = loop {
        let mut w = Work::default();
        let state = fit(start.clone(), rows, &free, nuisance, noise, &mut w);
        work.fk_evaluations += w.fk_evaluations;
        let j = jacobian::jacobian(
            &state.machine,
            &state.instruments,
            rows,
            &state.poses,
            &state.inverses,
            &free,
            nuisance,
            noise,
        );
        let dof = readings.saturating_sub(free.len() + nuisance.len()).max(1);
        let scale = (state.cost() / dof as f64).sqrt();
        let cov = covariance(&j, scale);
        let worst = free
            .iter()
            .enumerate()
            .map(|(c, &p)| (c, p, cov[(c, c)].sqrt() / options.prior(p)))
            .filter(|(_, _, r)| r.is_nan() || *r > 1.0)
            .max_by(|a, b| a.2.total_cmp(&b.2));
        match worst {
            Some((c, p, _)) => {
                weak.push(Weak {
                    param: p,
                    sigma: cov[(c, c)].sqrt(),
                    bound: options.prior(p),
                });
                free.remove(c);
            }
            None => break (state, cov, scale, w.iterations),
        }
    };
    // Outliers: rows far beyond the residuals' robust sigma.
    let per_row = row_residuals(rows, &state.residuals, noise);
    let robust = {
        let mut r: Vec<f64> = state.residuals.iter().map(|v| v.abs()).collect();
        r.sort_by(f64::total_cmp);
        (1.4826 * r[r.len() / 2]).max(OUTLIER_FLOOR) * noise.length_mm
    };
    let outliers: Vec<RowProblem> = rows
        .iter()
        .zip(&per_row)
        .filter(|(_, r)| r.is_nan() || **r > OUTLIER_SIGMAS * robust * 3f64.sqrt())
        .map(|(row, r)| RowProblem {
            line: row.line,
            message: format!(
                "the reading is {r:.4} mm from the calibrated model, {:.0} times the residuals' robust sigma ({robust:.4} mm per coordinate): an outlier",
                r / robust
            ),
        })
        .collect();
    if !outliers.is_empty() {
        return Err(CalibrationError::Rows(outliers));
    }
    // Prior bounds.
    let beyond: Vec<(Param, f64, f64, f64)> = free
        .iter()
        .enumerate()
        .filter_map(|(c, &p)| {
            let change = p.value(&state.machine) - p.value(nominal);
            let bound = options.prior(p);
            (change.abs() > bound).then(|| (p, change, bound, cov[(c, c)].sqrt()))
        })
        .collect();
    if !beyond.is_empty() && !options.allow_large {
        return Err(CalibrationError::Prior(beyond));
    }
    // The calibrated machine must be a valid machine file.
    Machine::from_toml_str(&state.machine.to_toml(), "the calibrated machine")
        .map_err(CalibrationError::Invalid)?;
    let after = residual_stats(rows, &state.residuals, noise);
    let holdout = holdout(&state, rows, &free, nuisance, options, &mut work);
    // Correlations among the fitted parameters, the instrument's included.
    let names: Vec<String> = free
        .iter()
        .map(|p| p.key().to_string())
        .chain(nuisance.iter().map(|n| n.key(devices.len())))
        .collect();
    let mut correlations = Vec::new();
    for a in 0..names.len() {
        for b in a + 1..names.len() {
            if a >= free.len() && b >= free.len() {
                continue;
            }
            let c = cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt();
            if c.abs() > CORRELATION_FLAG {
                correlations.push((names[a].clone(), names[b].clone(), c));
            }
        }
    }
    let estimates = candidates
        .iter()
        .map(|&p| Estimate {
            param: p,
            nominal: p.value(nominal),
            value: p.value(&state.machine),
            sigma: free
                .iter()
                .position(|&q| q == p)
                .map(|c| cov[(c, c)].sqrt()),
        })
        .collect();
    let instrument_estimates = nuisance
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            (
                n,
                state.instruments[n.set].value(n.which),
                cov[(free.len() + k, free.len() + k)].sqrt(),
            )
        })
        .collect();
    Ok(Calibration {
        devices,
        machine: state.machine.clone(),
        estimates,
        identifiability: ident,
        weak,
        instruments: state.instruments.clone(),
        instrument_estimates,
        correlations,
        before,
        after,
        holdout,
        noise_mm: scale * noise.length_mm,
        rows: rows.len(),
        readings,
        fk_complete,
        fk_followed: work.fk_evaluations,
        iterations,
    })
}

/// The k-fold hold-out: each fold's rows predicted by a fit of the others (started from the
/// whole fit), their residuals together. None when a fold's fit would have no more readings
/// than unknowns, or a fold's rows cannot be followed.
fn holdout(
    full: &State,
    rows: &[Measurement],
    free: &[Param],
    nuisance: &[NuisanceParam],
    options: &Options,
    work: &mut Work,
) -> Option<Residuals> {
    let k = options.folds;
    if k < 2 || rows.len() < k {
        return None;
    }
    let unknowns = free.len() + nuisance.len();
    let mut held_rows = Vec::with_capacity(rows.len());
    let mut held_res: Vec<f64> = Vec::new();
    for fold in 0..k {
        let train: Vec<usize> = (0..rows.len()).filter(|i| i % k != fold).collect();
        let test: Vec<usize> = (0..rows.len()).filter(|i| i % k == fold).collect();
        let train_rows: Vec<Measurement> = train.iter().map(|&i| rows[i]).collect();
        let readings: usize = train_rows.iter().map(|r| r.observed.len()).sum();
        if readings <= unknowns {
            return None;
        }
        let train_poses: Vec<_> = train.iter().map(|&i| full.poses[i]).collect();
        let start = state_at(
            full.machine.clone(),
            full.instruments.clone(),
            &train_rows,
            &train_poses,
            &options.noise,
            work,
        )?;
        let fitted = fit(start, &train_rows, free, nuisance, &options.noise, work);
        let test_rows: Vec<Measurement> = test.iter().map(|&i| rows[i]).collect();
        let test_poses: Vec<_> = test.iter().map(|&i| full.poses[i]).collect();
        let predicted = state_at(
            fitted.machine,
            fitted.instruments,
            &test_rows,
            &test_poses,
            &options.noise,
            work,
        )?;
        held_rows.extend(test_rows);
        held_res.extend(predicted.residuals.iter());
    }
    Some(residual_stats(
        &held_rows,
        &DVector::from_vec(held_res),
        &options.noise,
    ))
}

impl Calibration {
    /// The calibrated parameters as a machine file over `base` (the nominal's file, or
    /// "verne"): a comment `header` (each line prefixed with `# `), `base = ...`, then the
    /// identified keys, each with its change and 1 sigma.
    pub fn machine_file(&self, base: &str, header: &str) -> String {
        let mut out = String::new();
        for line in header.lines() {
            out.push_str("# ");
            out.push_str(line);
            out.push('\n');
        }
        out.push_str(&format!("base = {base:?}\n"));
        for section in ["module", "zeros", "tool", "table"] {
            let mut first = true;
            for e in &self.estimates {
                let Some(sigma) = e.sigma else { continue };
                let p = e.param;
                let Some((sec, key)) = p.key().split_once('.') else {
                    continue;
                };
                if sec != section {
                    continue;
                }
                if first {
                    out.push_str(&format!("\n[{sec}]\n"));
                    first = false;
                }
                out.push_str(&format!(
                    "{key} = {:.6}   # {:+.6} {u} from nominal, 1 sigma {:.6} {u}\n",
                    p.shown(e.value),
                    p.shown(e.value - e.nominal),
                    p.shown(sigma),
                    u = p.unit()
                ));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests;
