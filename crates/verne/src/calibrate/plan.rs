//! Where to measure: joint sets inside the workspace that make the fit's estimates as sure as
//! the readings allow, chosen to maximise the determinant of the information matrix J^T J of
//! the parameters the readings determine and the instrument's (D-optimal), by an exchange
//! algorithm, with the sigma each parameter and the tool tip are predicted to have.
//!
//! Candidates are joint sets of the nominal machine's working branch: the module's inverse
//! kinematics of platform points drawn over its workspace box (tracker, platform, probe), or the
//! machine's of tool poses on a sphere around the ballbar's table ball (ballbar); each within
//! the strokes by [`STROKE_MARGIN_MM`] and clear of the singularity thresholds of `verne verify`
//! (the machine file's `[verify]` table). The design starts from a greedy sequence (each pose the
//! one that most increases the determinant) and exchanges poses with candidates while that
//! increases it (Fedorov's exchange, one design point at a time), det(M + U^T S U) =
//! det(M) det(I + S U M^-1 U^T) for the swap's rows U, S = diag(-1, +1).

use nalgebra::{DMatrix, Vector3};

use crate::machine::{ToolPose, machine_ik};
use crate::math::test_rng::lcg;
use crate::parallel_module::equations::ModulePose;
use crate::parallel_module::ik;
use crate::parallel_module::kinetostatics::SingularityLimits;
use crate::spec::Machine;
use crate::verify::{Th, Thresholds};
use crate::workspace::{Of, default_bounds};

use super::fit::covariance;
use super::identifiability::{Identifiability, analyse};
use super::jacobian::jacobian;
use super::model::{
    Device, Instrument, Measurement, Noise, Observed, followed_poses, nuisance_columns,
    platform_axis, predicted,
};
use super::params::Param;

/// The ballbar's table ball by default: on the table top, off the rotary axis (a ball on the
/// axis would not turn with the table, and its zero would not enter the readings) (mm).
pub const BALL_X_MM: f64 = 80.0;

/// A candidate's sliders are at least this far inside their strokes (mm).
pub const STROKE_MARGIN_MM: f64 = 5.0;

/// Draws per candidate kept before giving up (a machine whose workspace the box barely holds).
const DRAWS_PER_CANDIDATE: usize = 200;

/// An exchange is taken when it multiplies the determinant by more than 1 + this.
const EXCHANGE_GAIN: f64 = 1e-9;

/// Most passes of the exchange over the design.
const MAX_SWEEPS: usize = 50;

/// How to plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    pub device: Device,
    /// Poses to measure.
    pub poses: usize,
    /// Candidates drawn.
    pub candidates: usize,
    pub noise: Noise,
    /// Also measure the tool axis (tracker).
    pub axis: bool,
    /// The parameters considered (empty: the device's).
    pub free: Vec<Param>,
    /// Ballbar: the bar's length and the table ball in the workpiece frame (mm).
    pub bar_mm: f64,
    pub ball: Vector3<f64>,
    /// Random sets of the same size whose sigmas the plan is compared with.
    pub random_sets: usize,
    pub seed: u64,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            device: Device::Tracker,
            poses: 30,
            candidates: 1500,
            noise: super::model::DEFAULT_NOISE,
            axis: false,
            free: Vec::new(),
            bar_mm: 100.0,
            ball: Vector3::new(BALL_X_MM, 0.0, 0.0),
            random_sets: 50,
            seed: 1,
        }
    }
}

/// A plan.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The poses to measure: joints, and what the nominal machine's instrument would read.
    pub rows: Vec<Measurement>,
    /// What the candidates determine.
    pub identifiability: Identifiability,
    /// Predicted 1 sigma of each parameter the readings determine (stored units), for the plan.
    pub sigmas: Vec<(Param, f64)>,
    /// Parameters whose predicted sigma exceeds their prior bound: the readings cannot determine
    /// them (stored units).
    pub undetermined: Vec<(Param, f64)>,
    /// Predicted 1 sigma of the tool tip (mm, |sigma| of the position from the parameters'
    /// covariance) over the candidates: root mean square and largest.
    pub tip_rms_mm: f64,
    pub tip_max_mm: f64,
    /// The largest sigma among lengths (mm) for the plan, and the median of that over random
    /// sets of the same size drawn from the candidates.
    pub worst_mm: f64,
    pub random_worst_mm: f64,
    /// Candidates drawn.
    pub candidates: usize,
}

/// Why there is no plan.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanError {
    /// The workspace gave fewer candidates than poses asked.
    Candidates { found: usize, wanted: usize },
    /// Fewer readings than the unknowns the readings determine.
    TooFew { readings: usize, unknowns: usize },
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Candidates { found, wanted } => write!(
                f,
                "only {found} candidate poses inside the workspace (clear of the limits and singularities) for {wanted} wanted"
            ),
            PlanError::TooFew { readings, unknowns } => write!(
                f,
                "{readings} readings for {unknowns} unknowns: plan more poses"
            ),
        }
    }
}

impl std::error::Error for PlanError {}

/// The singularity thresholds of the machine's `[verify]` table (defaults where absent).
fn singularity_limits(m: &Machine) -> SingularityLimits {
    let th = Thresholds::from_machine(m, "the machine").unwrap_or_default();
    SingularityLimits {
        lambda_min: th.get(Th::LambdaMin),
        lambda_max: th.get(Th::LambdaMax),
        parallel_margin_min: th.get(Th::ParallelMarginMin),
    }
}

/// Sliders within the strokes by the margin.
fn within_strokes(m: &Machine, rho: &nalgebra::Vector3<f64>) -> bool {
    (0..3).all(|k| {
        rho[k] >= m.limits.rho_min[k] + STROKE_MARGIN_MM
            && rho[k] <= m.limits.rho_max[k] - STROKE_MARGIN_MM
    })
}

/// Candidate joint sets of the device, with their poses.
fn candidates(m: &Machine, options: &PlanOptions) -> Vec<(Measurement, ModulePose)> {
    let mut u = lcg(options.seed);
    let limits = singularity_limits(m);
    let mut out = Vec::new();
    let wanted = options.candidates;
    let inst = Instrument {
        ball: options.ball,
        ..Instrument::default()
    };
    let mut draws = 0;
    while out.len() < wanted && draws < wanted * DRAWS_PER_CANDIDATE {
        draws += 1;
        let (rho, theta, pose) = match options.device {
            Device::Ballbar => {
                // A tool ball on the sphere around the table ball, above the table.
                let z: f64 = 0.2 + 0.8 * u();
                let phi = std::f64::consts::TAU * u();
                let r = (1.0 - z * z).sqrt();
                let tip =
                    options.ball + options.bar_mm * Vector3::new(r * phi.cos(), r * phi.sin(), z);
                let tool = ToolPose {
                    tip,
                    phi1: (30.0 * u()).to_radians(),
                    phi2: std::f64::consts::TAU * u() - std::f64::consts::PI,
                };
                let branches = machine_ik(m, &tool, m.tool_length);
                let Some(b) = branches
                    .iter()
                    .filter(|b| b.working())
                    .min_by(|a, b| a.theta1.abs().total_cmp(&b.theta1.abs()))
                else {
                    continue;
                };
                (
                    b.rho,
                    [b.theta1, b.theta2],
                    ModulePose {
                        p: b.platform,
                        alpha: b.alpha,
                    },
                )
            }
            _ => {
                let bx = default_bounds(m, Of::Platform, 0.0);
                let p = Vector3::from_fn(|k, _| bx.min[k] + (bx.max[k] - bx.min[k]) * u());
                let Some(b) = ik::working_fast(m, &p) else {
                    continue;
                };
                (b.rho, [0.0, 0.0], ModulePose { p, alpha: b.alpha })
            }
        };
        if !within_strokes(m, &rho) || !limits.admit_pose(&m.module, &pose, &rho) {
            continue;
        }
        let observed = match options.device {
            Device::Tracker => Observed::Tip {
                tip: Vector3::zeros(),
                axis: options.axis.then(|| -platform_axis(pose.alpha)),
            },
            Device::Platform => Observed::Platform(Vector3::zeros()),
            Device::Ballbar => Observed::Distance(0.0),
            Device::Probe => Observed::Height(0.0),
        };
        let mut row = Measurement {
            rho,
            theta,
            observed,
            set: 0,
            line: out.len() as u64 + 1,
        };
        // What the nominal machine's instrument reads there.
        let mut v = [0.0; 6];
        predicted(m, &inst, &row, &pose, &mut v);
        row.observed = match row.observed {
            Observed::Tip { axis, .. } => Observed::Tip {
                tip: Vector3::new(v[0], v[1], v[2]),
                axis: axis.map(|_| Vector3::new(v[3], v[4], v[5])),
            },
            Observed::Platform(_) => Observed::Platform(Vector3::new(v[0], v[1], v[2])),
            Observed::Distance(_) => Observed::Distance(v[0]),
            Observed::Height(_) => Observed::Height(v[0]),
        };
        out.push((row, pose));
    }
    out
}

/// The joints of the candidates (for synthetic data sets).
pub(crate) fn candidate_joints(
    m: &Machine,
    options: &PlanOptions,
) -> Vec<(crate::parallel_module::equations::Sliders, [f64; 2])> {
    candidates(m, options)
        .into_iter()
        .map(|(r, _)| (r.rho, r.theta))
        .collect()
}

/// The rows of the weighted Jacobian of each candidate (its readings' rows).
fn blocks(j: &DMatrix<f64>, rows: &[Measurement]) -> Vec<DMatrix<f64>> {
    let mut out = Vec::with_capacity(rows.len());
    let mut k = 0;
    for r in rows {
        let len = r.observed.len();
        out.push(j.rows(k, len).into_owned());
        k += len;
    }
    out
}

/// det(I + S U M^-1 U^T) for U = [remove; add], S = diag(-I, I): the factor by which the
/// determinant of M changes when `remove`'s rows leave and `add`'s come in (either may be
/// empty).
fn swap_gain(minv: &DMatrix<f64>, remove: Option<&DMatrix<f64>>, add: &DMatrix<f64>) -> f64 {
    let (kr, ka) = (remove.map_or(0, |r| r.nrows()), add.nrows());
    let n = minv.nrows();
    let mut u = DMatrix::zeros(kr + ka, n);
    if let Some(r) = remove {
        u.rows_mut(0, kr).copy_from(r);
    }
    u.rows_mut(kr, ka).copy_from(add);
    let mut k = &u * minv * u.transpose();
    for i in 0..kr {
        k.row_mut(i).neg_mut();
    }
    for i in 0..kr + ka {
        k[(i, i)] += 1.0;
    }
    k.determinant()
}

/// Fedorov's exchange: from a greedy start, swap design points with candidates while the
/// determinant of the information matrix grows. Returns the chosen candidates' indices.
fn d_optimal(blocks: &[DMatrix<f64>], size: usize) -> Vec<usize> {
    let n = blocks[0].ncols();
    let info = |set: &[usize]| {
        let mut m = DMatrix::<f64>::zeros(n, n);
        for &i in set {
            m += blocks[i].transpose() * &blocks[i];
        }
        m
    };
    // A ridge far below the information any reading brings, so that the greedy start's first
    // poses have an inverse.
    let trace: f64 = blocks.iter().map(|b| b.norm_squared()).sum::<f64>() / blocks.len() as f64;
    let ridge = 1e-9 * trace / n as f64;
    let inverse = |m: &DMatrix<f64>| {
        let mut r = m.clone();
        for i in 0..n {
            r[(i, i)] += ridge;
        }
        r.try_inverse().unwrap_or_else(|| DMatrix::identity(n, n))
    };
    let mut design: Vec<usize> = Vec::with_capacity(size);
    let mut minv = inverse(&DMatrix::zeros(n, n));
    for _ in 0..size {
        let best = (0..blocks.len())
            .filter(|i| !design.contains(i))
            .map(|i| (i, swap_gain(&minv, None, &blocks[i])))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((i, _)) = best else { break };
        design.push(i);
        minv = inverse(&info(&design));
    }
    for _ in 0..MAX_SWEEPS {
        let mut improved = false;
        for s in 0..design.len() {
            let out = design[s];
            let best = (0..blocks.len())
                .filter(|i| !design.contains(i))
                .map(|i| (i, swap_gain(&minv, Some(&blocks[out]), &blocks[i])))
                .max_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((i, gain)) = best
                && gain > 1.0 + EXCHANGE_GAIN
            {
                design[s] = i;
                minv = inverse(&info(&design));
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    design
}

/// The predicted sigmas of the parameters (stored units) for a set of candidates, from the
/// weighted Jacobian's rows (noise scale 1: the weights are the noise).
fn sigmas_of(blocks: &[DMatrix<f64>], set: &[usize]) -> DMatrix<f64> {
    let rows: Vec<_> = set.iter().map(|&i| blocks[i].clone()).collect();
    let total: usize = rows.iter().map(|b| b.nrows()).sum();
    let n = blocks[0].ncols();
    let mut j = DMatrix::zeros(total, n);
    let mut k = 0;
    for b in rows {
        j.rows_mut(k, b.nrows()).copy_from(&b);
        k += b.nrows();
    }
    covariance(&j, 1.0)
}

/// The largest sigma among lengths (mm) of `params` in `cov`.
fn worst_length(cov: &DMatrix<f64>, params: &[Param]) -> f64 {
    params
        .iter()
        .enumerate()
        .filter(|(_, p)| !p.is_angle())
        .map(|(c, _)| cov[(c, c)].sqrt())
        .fold(0.0, f64::max)
}

/// Plans `options.poses` poses for `options.device` on the nominal machine.
pub fn plan(m: &Machine, options: &PlanOptions) -> Result<Plan, PlanError> {
    let found = candidates(m, options);
    if found.len() < options.poses.max(1) {
        return Err(PlanError::Candidates {
            found: found.len(),
            wanted: options.poses,
        });
    }
    let (rows, poses): (Vec<Measurement>, Vec<ModulePose>) = found.into_iter().unzip();
    let (poses, inverses) =
        followed_poses(m, &rows, &poses).expect("the candidates' own poses are followed");
    let inst = Instrument {
        ball: options.ball,
        ..Instrument::default()
    };
    let device = options.device;
    let considered: Vec<Param> = if options.free.is_empty() {
        device.parameters()
    } else {
        options.free.clone()
    };
    let nuisance = nuisance_columns(&[device]);
    let j = jacobian(
        m,
        &[inst],
        &rows,
        &poses,
        &inverses,
        &considered,
        &nuisance,
        &options.noise,
    );
    let identifiability = analyse(&j, &considered, &[device]);
    let free = identifiability.identified.clone();
    let columns: Vec<usize> = free
        .iter()
        .map(|p| {
            considered
                .iter()
                .position(|q| q == p)
                .expect("identified are considered")
        })
        .chain((0..nuisance.len()).map(|k| considered.len() + k))
        .collect();
    let jf = j.select_columns(columns.iter());
    let blocks = blocks(&jf, &rows);
    let readings: usize = blocks[0].nrows() * options.poses;
    let unknowns = jf.ncols();
    if readings <= unknowns {
        return Err(PlanError::TooFew { readings, unknowns });
    }
    let design = d_optimal(&blocks, options.poses);
    let cov = sigmas_of(&blocks, &design);
    let sigmas: Vec<(Param, f64)> = free
        .iter()
        .enumerate()
        .map(|(c, &p)| (p, cov[(c, c)].sqrt()))
        .collect();
    let undetermined = sigmas
        .iter()
        .filter(|(p, s)| s.is_nan() || *s > p.default_prior())
        .copied()
        .collect();
    // The tool tip's sigma over the candidates: its derivative in the machine's parameters
    // (the instrument's rows of a tracker's reading at R = I, t = 0 are the tip itself).
    let tip_rows = jacobian(
        m,
        &[Instrument::default()],
        &rows
            .iter()
            .map(|r| Measurement {
                observed: Observed::Tip {
                    tip: Vector3::zeros(),
                    axis: None,
                },
                ..*r
            })
            .collect::<Vec<_>>(),
        &poses,
        &inverses,
        &free,
        &[],
        &Noise {
            length_mm: 1.0,
            axis_rad: 1.0,
        },
    );
    let cmm = cov.view((0, 0), (free.len(), free.len())).into_owned();
    let (mut sum, mut max) = (0.0, 0.0f64);
    for k in 0..rows.len() {
        let t = tip_rows.rows(3 * k, 3);
        let var = (t * &cmm * t.transpose()).trace();
        sum += var;
        max = max.max(var.sqrt());
    }
    let worst_mm = worst_length(&cov, &free);
    let mut u = lcg(options.seed ^ 0x005e_ed0f_5e75);
    let mut random: Vec<f64> = (0..options.random_sets)
        .map(|_| {
            let mut set: Vec<usize> = Vec::with_capacity(options.poses);
            while set.len() < options.poses {
                let i = ((u() * rows.len() as f64) as usize).min(rows.len() - 1);
                if !set.contains(&i) {
                    set.push(i);
                }
            }
            worst_length(&sigmas_of(&blocks, &set), &free)
        })
        .collect();
    random.sort_by(f64::total_cmp);
    let random_worst_mm = random.get(random.len() / 2).copied().unwrap_or(f64::NAN);
    Ok(Plan {
        rows: design.iter().map(|&i| rows[i]).collect(),
        identifiability,
        sigmas,
        undetermined,
        tip_rms_mm: (sum / rows.len() as f64).sqrt(),
        tip_max_mm: max,
        worst_mm,
        random_worst_mm,
        candidates: rows.len(),
    })
}
