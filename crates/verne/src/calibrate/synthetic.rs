//! Synthetic machines and measurements, for the tests, the example data and the benchmarks: a
//! machine file perturbed as a real machine differs from its drawing, and what an instrument
//! reads of it, computed by the forward kinematics of the perturbed machine
//! ([`crate::parallel_module::fk::solve`], its working mode) and the instrument's formulas
//! written out here, with Gaussian noise.

use nalgebra::{Rotation3, Vector3, Vector4};

use crate::machine::table_transform;
use crate::math::test_rng::lcg;
use crate::parallel_module::equations::Sliders;
use crate::parallel_module::fk;
use crate::spec::Machine;

use super::model::{Device, Instrument, Measurement, Observed};
use super::params::Param;
use super::plan::{PlanOptions, candidate_joints};

/// How far a synthetic machine is from its drawing: each length (mm) uniform within
/// +-`lengths_mm`, each offset (zeros, table) within +-`offsets_mm` or +-`angles_deg`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Perturbation {
    pub lengths_mm: f64,
    pub offsets_mm: f64,
    pub angles_deg: f64,
}

/// The perturbation of the issue that asked for calibration: lengths +-0.5 mm, offsets +-0.3
/// mm and 0.2 degrees.
pub const TYPICAL: Perturbation = Perturbation {
    lengths_mm: 0.5,
    offsets_mm: 0.3,
    angles_deg: 0.2,
};

/// `nominal` with every parameter of [`super::params::ALL`] moved at random (seeded).
pub fn perturbed(nominal: &Machine, p: &Perturbation, seed: u64) -> Machine {
    let mut u = lcg(seed);
    let mut m = nominal.clone();
    for q in super::params::ALL {
        let unit = 2.0 * u() - 1.0;
        let d = match q {
            Param::Theta1Zero | Param::Theta2Zero => (unit * p.angles_deg).to_radians(),
            Param::Rho1Zero
            | Param::Rho2Zero
            | Param::Rho3Zero
            | Param::TableDa
            | Param::TableDt
            | Param::TableYt
            | Param::ToolLength => unit * p.offsets_mm,
            _ => unit * p.lengths_mm,
        };
        q.add_to(&mut m, d);
    }
    m
}

/// A standard normal deviate from a uniform source (Box-Muller).
pub fn gaussian(u: &mut impl FnMut() -> f64) -> f64 {
    let a = u().max(f64::MIN_POSITIVE);
    let b = u();
    (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
}

/// Joint sets of `device` inside the nominal machine's workspace (the plan's candidates:
/// working branch, within the strokes, clear of the singularity thresholds), drawn at random.
pub fn joints(nominal: &Machine, device: Device, n: usize, seed: u64) -> Vec<(Sliders, [f64; 2])> {
    candidate_joints(
        nominal,
        &PlanOptions {
            device,
            candidates: n,
            seed,
            ..PlanOptions::default()
        },
    )
}

/// What `device` reads of the machine `truth` at each joint set, the instrument at `inst`,
/// with Gaussian noise of `noise_mm` on each length coordinate and `noise_axis_rad` on each axis
/// coordinate (`axis`: a tracker also reads the tool axis). A joint set without a working mode
/// of `truth` is left out.
#[allow(clippy::too_many_arguments)]
pub fn measure(
    truth: &Machine,
    joints: &[(Sliders, [f64; 2])],
    device: Device,
    inst: &Instrument,
    noise_mm: f64,
    noise_axis_rad: f64,
    axis: bool,
    seed: u64,
) -> Vec<Measurement> {
    let mut u = lcg(seed);
    let mut out = Vec::with_capacity(joints.len());
    for (k, (rho, theta)) in joints.iter().enumerate() {
        let modes = fk::solve(truth, rho);
        let Some(mode) = fk::working(&modes) else {
            continue;
        };
        let (p, alpha) = (mode.pose.p, mode.pose.alpha);
        // The platform's z axis and the tool tip, eq. (27) of AIM 2007.
        let z_axis = Vector3::new(0.0, -alpha.sin(), alpha.cos());
        let tip = p + truth.tool_length * z_axis;
        let mut noisy = |v: Vector3<f64>, s: f64| {
            v + Vector3::new(gaussian(&mut u), gaussian(&mut u), gaussian(&mut u)) * s
        };
        let r: Rotation3<f64> = inst.rotation;
        let observed = match device {
            Device::Tracker => Observed::Tip {
                tip: noisy(r * tip + inst.translation, noise_mm),
                axis: axis.then(|| noisy(r * -z_axis, noise_axis_rad)),
            },
            Device::Platform => Observed::Platform(noisy(r * p + inst.translation, noise_mm)),
            Device::Probe => {
                Observed::Height((r * tip + inst.translation).z + noise_mm * gaussian(&mut u))
            }
            Device::Ballbar => {
                let t = table_transform(&truth.table, theta[0], theta[1]);
                let b = inst.ball;
                let ball = (t * Vector4::new(b.x, b.y, b.z, 1.0)).xyz();
                Observed::Distance((tip - ball).norm() + noise_mm * gaussian(&mut u))
            }
        };
        out.push(Measurement {
            rho: *rho,
            theta: *theta,
            observed,
            set: 0,
            line: k as u64 + 2,
        });
    }
    out
}
