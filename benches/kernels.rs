//! Criterion benchmarks of the parallel-module kernels (IFToMM 2007, sections V-VI) against the
//! Newton-Raphson resolution the VERNE controller uses, measured in the same run and reported as
//! ratios (docs/benchmarks.md; `scripts/bench.sh` runs this and records the table).
//!
//! Inputs are deterministic: a helix around (-250, 0, 1050) mm sampled at about 0.2 mm per row
//! (12 m/min at a 1 kHz servo rate), and a scattered set from a fixed LCG for the kernels that do
//! not depend on row order. Baselines: Newton-Raphson on the four equations (3)-(6) for
//! (xp, yp, zp, alpha) given the sliders (FK) or for (alpha, rho1, rho2, rho3) given P (IK),
//! warm-started from the previous row, stopping when every residual, expressed as a length error
//! along its rod, is below 1e-9 mm, at most 120 iterations (LinuxCNC genhexkins'
//! HEXKINS_CONV_CRITERION and HEXKINS_ITER_LIMIT).
//!
//! Also here: a working-mode FK tracker (Newton on (3)-(6) from the previous row's pose, accepted
//! only when it converges quickly on the machine's configuration, `module_fk::solve` otherwise),
//! a candidate for the library; and a few sub-kernels that show where the FK time goes.
//!
//! `cargo bench --bench kernels` prints a summary table at the end; with `VERNE_BENCH_SUMMARY=FILE`
//! the table is also written to FILE (markdown).

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use nalgebra::{Matrix4, Vector3, Vector4};
use verne::branches::{Config, Reason, Verdict, WORKING_CONFIG, config_of, module_verdict};
use verne::machine::{Machine, ModuleGeometry};
use verne::module_fk;
use verne::module_geometry::{
    ModulePose, Sliders, jacobian_pose, jacobian_sliders, polish_pose, residuals,
};
use verne::module_ik;
use verne::poly::roots_in;
use verne::tolerance::LIMIT_SLACK;
use verne::trig::Trig;

// ------------------------------------------------------------------------------ parameters

/// Rows of the benchmark trajectory (one criterion iteration solves all of them).
const PATH_ROWS: usize = 4096;
/// Helix: centre (mm), radius (mm), turns over the path, z rise over the path (mm).
const HELIX_CENTER: [f64; 3] = [-250.0, 0.0, 1000.0];
const HELIX_RADIUS_MM: f64 = 120.0;
const HELIX_TURNS: f64 = 1.0;
const HELIX_RISE_MM: f64 = 300.0;
/// Box of the scattered inputs (mm): inside the workspace.
const SCATTER_MIN: [f64; 3] = [-370.0, -120.0, 950.0];
const SCATTER_MAX: [f64; 3] = [-130.0, 120.0, 1350.0];
const SCATTER_SEED: u64 = 0x5eed_0007;

/// Newton baselines: every residual of (3)-(6) as a length error along its rod, |f| / (2 L),
/// below this (mm) (LinuxCNC genhexkins HEXKINS_CONV_CRITERION = 1e-9).
const NEWTON_TOL_MM: f64 = 1e-9;
/// Newton baselines: iteration cap (LinuxCNC genhexkins HEXKINS_ITER_LIMIT = 120).
const NEWTON_ITER_LIMIT: usize = 120;

/// Tracker: Newton steps allowed before the row is handed to `module_fk::solve`.
const TRACK_MAX_ITER: usize = 4;
/// Tracker: same stopping rule as the baselines (mm along the rod).
const TRACK_TOL_MM: f64 = NEWTON_TOL_MM;

/// Criterion settings: short, so that the whole bench runs in a few minutes on 2 cores.
const WARM_UP: Duration = Duration::from_millis(800);
const MEASURE: Duration = Duration::from_secs(3);
const SAMPLES: usize = 20;

// ---------------------------------------------------------------------------- inputs

/// Fixed 64-bit LCG (Knuth MMIX constants): the only source of "randomness".
struct Lcg(u64);

impl Lcg {
    fn next_unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn helix(rows: usize) -> Vec<Vector3<f64>> {
    (0..rows)
        .map(|i| {
            let f = i as f64 / rows as f64;
            let t = TAU * HELIX_TURNS * f;
            Vector3::new(
                HELIX_CENTER[0] + HELIX_RADIUS_MM * t.cos(),
                HELIX_CENTER[1] + HELIX_RADIUS_MM * t.sin(),
                HELIX_CENTER[2] + HELIX_RISE_MM * f,
            )
        })
        .collect()
}

fn scattered(rows: usize) -> Vec<Vector3<f64>> {
    let mut g = Lcg(SCATTER_SEED);
    (0..rows)
        .map(|_| {
            Vector3::from_fn(|k, _| {
                SCATTER_MIN[k] + (SCATTER_MAX[k] - SCATTER_MIN[k]) * g.next_unit()
            })
        })
        .collect()
}

// ------------------------------------------------------- equations (3)-(6), fused evaluation

/// Residuals of (3)-(6) and the partial derivatives a Newton step needs, from one sin_cos.
struct System {
    /// |B - A|^2 - L^2 (mm^2).
    f: Vector4<f64>,
    /// Rod vectors B - A.
    v: [Vector3<f64>; 4],
    /// d f / d alpha.
    dfa: Vector4<f64>,
    /// cos(alpha).
    cos_alpha: f64,
}

#[inline(always)]
fn system(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> System {
    let (s, c) = pose.alpha.sin_cos();
    let (x, y, z) = (pose.p.x, pose.p.y, pose.p.z);
    let (r1c, r1s, r2c, r2s) = (g.r_big1 * c, g.r_big1 * s, g.r_big2 * c, g.r_big2 * s);
    let v = [
        Vector3::new(x + g.dx1, y + r1c - g.r_small1, z + r1s - rho.x),
        Vector3::new(x + g.dx1, y - r1c + g.r_small1, z - r1s - rho.x),
        Vector3::new(x + g.dx2, y - r2c + g.r4, z - r2s - rho.y),
        Vector3::new(x + g.dx2, y + r2c - g.r4, z + r2s - rho.z),
    ];
    let l2 = [g.l1 * g.l1, g.l1 * g.l1, g.l2 * g.l2, g.l3 * g.l3];
    let f = Vector4::new(
        v[0].norm_squared() - l2[0],
        v[1].norm_squared() - l2[1],
        v[2].norm_squared() - l2[2],
        v[3].norm_squared() - l2[3],
    );
    // d v / d alpha = (0, -+R s, +-R c) per rod, as in `rod_vectors`.
    let dfa = Vector4::new(
        2.0 * (-v[0].y * r1s + v[0].z * r1c),
        2.0 * (v[1].y * r1s - v[1].z * r1c),
        2.0 * (v[2].y * r2s - v[2].z * r2c),
        2.0 * (-v[3].y * r2s + v[3].z * r2c),
    );
    System {
        f,
        v,
        dfa,
        cos_alpha: c,
    }
}

/// |f_i| <= 2 L_i tol for every rod: the length error along each rod is below `tol` (mm).
#[inline(always)]
fn converged(f: &Vector4<f64>, limit: &Vector4<f64>) -> bool {
    f[0].abs() <= limit[0]
        && f[1].abs() <= limit[1]
        && f[2].abs() <= limit[2]
        && f[3].abs() <= limit[3]
}

fn residual_limits(g: &ModuleGeometry, tol_mm: f64) -> Vector4<f64> {
    Vector4::new(g.l1, g.l1, g.l2, g.l3) * (2.0 * tol_mm)
}

/// d f / d (xp, yp, zp, alpha): the FK Jacobian.
#[inline(always)]
fn jac_pose(sys: &System) -> Matrix4<f64> {
    let v = &sys.v;
    Matrix4::new(
        2.0 * v[0].x,
        2.0 * v[0].y,
        2.0 * v[0].z,
        sys.dfa[0],
        2.0 * v[1].x,
        2.0 * v[1].y,
        2.0 * v[1].z,
        sys.dfa[1],
        2.0 * v[2].x,
        2.0 * v[2].y,
        2.0 * v[2].z,
        sys.dfa[2],
        2.0 * v[3].x,
        2.0 * v[3].y,
        2.0 * v[3].z,
        sys.dfa[3],
    )
}

/// d f / d (alpha, rho1, rho2, rho3): the IK Jacobian.
#[inline(always)]
fn jac_joints(sys: &System) -> Matrix4<f64> {
    let v = &sys.v;
    Matrix4::new(
        sys.dfa[0],
        -2.0 * v[0].z,
        0.0,
        0.0,
        sys.dfa[1],
        -2.0 * v[1].z,
        0.0,
        0.0,
        sys.dfa[2],
        0.0,
        -2.0 * v[2].z,
        0.0,
        sys.dfa[3],
        0.0,
        0.0,
        -2.0 * v[3].z,
    )
}

// ------------------------------------------------------------------------- baselines

/// Newton-Raphson FK as the controller does it: (xp, yp, zp, alpha) from the sliders, warm start.
/// Returns the pose and the iterations used (a failure to converge returns the last iterate).
#[inline]
fn newton_fk(
    g: &ModuleGeometry,
    limit: &Vector4<f64>,
    start: ModulePose,
    rho: &Sliders,
) -> (ModulePose, usize) {
    let mut pose = start;
    for it in 0..NEWTON_ITER_LIMIT {
        let sys = system(g, &pose, rho);
        if converged(&sys.f, limit) {
            return (pose, it);
        }
        let Some(step) = jac_pose(&sys).lu().solve(&sys.f) else {
            return (pose, it);
        };
        pose.p -= step.xyz();
        pose.alpha -= step[3];
    }
    (pose, NEWTON_ITER_LIMIT)
}

/// Newton-Raphson IK as the controller does it: (alpha, rho1, rho2, rho3) from P, warm start.
#[inline]
fn newton_ik(
    g: &ModuleGeometry,
    limit: &Vector4<f64>,
    p: &Vector3<f64>,
    start: (f64, Sliders),
) -> ((f64, Sliders), usize) {
    let (mut alpha, mut rho) = start;
    for it in 0..NEWTON_ITER_LIMIT {
        let sys = system(g, &ModulePose { p: *p, alpha }, &rho);
        if converged(&sys.f, limit) {
            return ((alpha, rho), it);
        }
        let Some(step) = jac_joints(&sys).lu().solve(&sys.f) else {
            return ((alpha, rho), it);
        };
        alpha -= step[0];
        rho -= Vector3::new(step[1], step[2], step[3]);
    }
    ((alpha, rho), NEWTON_ITER_LIMIT)
}

// ------------------------------------------------------------ verdict without inverse cosines

/// `module_verdict` with the rod-tilt test done on cosines: tilt = acos(v_z / |v|) > T is
/// v_z < cos(T) |v| since acos decreases (T <= pi), so no `acos` per rod; the rod vectors are
/// passed in (a solver has them). Same reasons as `module_verdict` (checked in the fixture).
#[inline]
fn verdict_no_acos(
    m: &Machine,
    cos_tilt_max: f64,
    cos_alpha: f64,
    v: &[Vector3<f64>; 4],
    rho: &Sliders,
    config: Config,
) -> Verdict {
    let mut out = Verdict::default();
    let inverted = [
        Reason::Leg1Inverted,
        Reason::Leg2Inverted,
        Reason::Leg3Inverted,
    ];
    let stroke = [Reason::Rho1Stroke, Reason::Rho2Stroke, Reason::Rho3Stroke];
    for i in 0..3 {
        if config[i] != -1 {
            out.add(inverted[i]);
        }
        if rho[i] < m.limits.rho_min[i] - LIMIT_SLACK || rho[i] > m.limits.rho_max[i] + LIMIT_SLACK
        {
            out.add(stroke[i]);
        }
    }
    if m.module.r_big1 * cos_alpha <= m.module.r_small1 {
        out.add(Reason::RodsCross);
    }
    if v.iter().any(|r| r.z < cos_tilt_max * r.norm()) {
        out.add(Reason::RodTilt);
    }
    out
}

fn cos_tilt_max(m: &Machine) -> f64 {
    (m.limits.rod_tilt_max + LIMIT_SLACK)
        .min(std::f64::consts::PI)
        .cos()
}

// ----------------------------------------------------------------------------- tracker

/// The machine's assembly mode of one row, as `module_fk::working` would report it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Tracked {
    pose: ModulePose,
    config: Config,
    verdict: Verdict,
}

/// How the tracker takes its Newton steps.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Step {
    /// Full Newton: Jacobian and LU solve at every iterate.
    Newton,
    /// Chord: the Jacobian inverse of the previous row's solution, refreshed once per row.
    Chord,
}

/// Working-mode FK along a path: Newton on (3)-(6) from the previous row's pose, accepted when it
/// converges within [`TRACK_MAX_ITER`] steps, keeps the machine's configuration (s1, s2, s3) =
/// (-1, -1, -1) and R1 cos(alpha) > r1, and passes the machine's verdict; `module_fk::solve` and
/// `module_fk::working` otherwise (first row, a jump, a limit, a slow convergence).
struct Tracker<'m> {
    machine: &'m Machine,
    limit: Vector4<f64>,
    step: Step,
    /// Verdict by `verdict_no_acos` instead of `module_verdict`.
    fast_verdict: bool,
    cos_tilt_max: f64,
    /// The previous row's working pose and the inverse FK Jacobian there.
    last: Option<(ModulePose, Matrix4<f64>)>,
    fallbacks: u64,
    iterations: u64,
}

impl<'m> Tracker<'m> {
    fn new(machine: &'m Machine, step: Step, fast_verdict: bool) -> Tracker<'m> {
        Tracker {
            machine,
            limit: residual_limits(&machine.module, TRACK_TOL_MM),
            step,
            fast_verdict,
            cos_tilt_max: cos_tilt_max(machine),
            last: None,
            fallbacks: 0,
            iterations: 0,
        }
    }

    #[inline]
    fn solve(&mut self, rho: &Sliders) -> Option<Tracked> {
        if let Some(t) = self.track(rho) {
            return Some(t);
        }
        self.fallbacks += 1;
        let modes = module_fk::solve(self.machine, rho);
        let w = module_fk::working(&modes).copied();
        self.last = w.and_then(|w| {
            jac_pose(&system(&self.machine.module, &w.pose, rho))
                .try_inverse()
                .map(|inv| (w.pose, inv))
        });
        w.map(|w| Tracked {
            pose: w.pose,
            config: w.config,
            verdict: w.verdict,
        })
    }

    #[inline]
    fn track(&mut self, rho: &Sliders) -> Option<Tracked> {
        let g = &self.machine.module;
        let (mut pose, inv) = self.last?;
        let mut done = None;
        for it in 0..=TRACK_MAX_ITER {
            let sys = system(g, &pose, rho);
            if converged(&sys.f, &self.limit) {
                done = Some((sys, it));
                break;
            }
            if it == TRACK_MAX_ITER {
                break;
            }
            let step = match self.step {
                Step::Newton => jac_pose(&sys).lu().solve(&sys.f)?,
                Step::Chord => inv * sys.f,
            };
            pose.p -= step.xyz();
            pose.alpha -= step[3];
        }
        let (sys, it) = done?;
        self.iterations += it as u64;
        // Same configuration as the machine's mode, rods of leg I not crossing (section V).
        if g.r_big1 * sys.cos_alpha <= g.r_small1 {
            return None;
        }
        let config = config_of(g, &pose, rho);
        if config != WORKING_CONFIG {
            return None;
        }
        let verdict = if self.fast_verdict {
            verdict_no_acos(
                self.machine,
                self.cos_tilt_max,
                sys.cos_alpha,
                &sys.v,
                rho,
                config,
            )
        } else {
            module_verdict(self.machine, &pose, rho, config)
        };
        if !verdict.feasible() {
            return None;
        }
        let inv = match self.step {
            Step::Newton => inv,
            Step::Chord => jac_pose(&sys).try_inverse()?,
        };
        self.last = Some((pose, inv));
        Some(Tracked {
            pose,
            config,
            verdict,
        })
    }
}

// ------------------------------------------- sub-kernels: where the forward kinematics spends

/// The characteristic trigonometric polynomial F(alpha) of `module_fk` (its module
/// documentation), rebuilt here from the public `Trig` type so that its cost and the cost of
/// isolating its roots can be timed separately. Not used for results.
fn fk_characteristic(g: &ModuleGeometry, rho: &Sliders) -> Trig {
    let (r, rr, r2, r4) = (g.r_big1, g.r_small1, g.r_big2, g.r4);
    let p2 = rho.y - rho.x;
    let p3 = rho.z - rho.x;
    let delta = g.dx2 - g.dx1;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    let b = Trig::linear(
        g.l3 * g.l3 - g.l2 * g.l2 + (p2 + p3) * (p2 - p3),
        0.0,
        2.0 * r2 * (p2 + p3),
    );
    let det = Trig::linear(
        -2.0 * rr * (p2 - p3),
        2.0 * r * (p2 - p3),
        4.0 * (r * r4 - rr * r2),
    );
    let a = Trig::linear(
        g.l2 * g.l2 - k0 - delta * delta - r2 * r2 - r4 * r4 - p2 * p2,
        2.0 * r2 * r4 - 2.0 * r * rr,
        -2.0 * r2 * p2,
    );
    let q = Trig::linear(-rr * p2, r * p2, r * r4 - rr * r2);
    let u_num = a.mul(&det).add(&b.mul(&q).scale(2.0));
    let n1 = Trig::linear(r * r + rr * rr, -2.0 * r * rr, 0.0);
    let k1 = Trig::linear(k0, 2.0 * r * rr, 0.0);
    let inner = b.mul(&b).mul(&n1).add(&k1.mul(&det.mul(&det)).scale(-1.0));
    u_num.mul(&u_num).add(&inner.scale(4.0 * delta * delta))
}

/// The cubic (9) in cos(alpha), normalised as `module_ik` does.
fn ik_cubic(g: &ModuleGeometry, p: &Vector3<f64>) -> [f64; 4] {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let y = p.y;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    let p1 = 2.0 * r * r * r * rr;
    let p2 = r * r * k0 - r * r * u * u;
    let p3 = -2.0 * r * r * r * rr - 2.0 * r * rr * y * y;
    let p4 = r * r * u * u + (r * r + rr * rr) * y * y - r * r * k0;
    let scale = p1.abs().max(p2.abs()).max(p3.abs()).max(p4.abs());
    [p4 / scale, p3 / scale, p2 / scale, p1 / scale]
}

// --------------------------------------------------------------------------- fixture

struct Fixture {
    machine: Machine,
    limit: Vector4<f64>,
    path: Vec<Vector3<f64>>,
    /// The machine's IK solution of every path row: (alpha, rho).
    path_joints: Vec<(f64, Sliders)>,
    /// The machine's FK pose of every path row.
    path_poses: Vec<ModulePose>,
    scatter: Vec<Vector3<f64>>,
    /// Joints of the scattered points that have a working branch.
    scatter_joints: Vec<Sliders>,
}

impl Fixture {
    fn new() -> Fixture {
        let machine = Machine::default_verne();
        let limit = residual_limits(&machine.module, NEWTON_TOL_MM);
        let path = helix(PATH_ROWS);
        let path_joints: Vec<(f64, Sliders)> = path
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let b = module_ik::solve(&machine, p);
                let w = module_ik::working(&b)
                    .unwrap_or_else(|| panic!("path row {i} ({p:?}) has no working branch"));
                (w.alpha, w.rho)
            })
            .collect();
        let path_poses = path
            .iter()
            .zip(&path_joints)
            .map(|(p, &(alpha, _))| ModulePose { p: *p, alpha })
            .collect();
        let scatter = scattered(PATH_ROWS);
        let scatter_joints = scatter
            .iter()
            .filter_map(|p| module_ik::working(&module_ik::solve(&machine, p)).map(|w| w.rho))
            .collect();
        let fx = Fixture {
            machine,
            limit,
            path,
            path_joints,
            path_poses,
            scatter,
            scatter_joints,
        };
        fx.check_fused_system();
        fx
    }

    /// The fused evaluation used by the baselines agrees with the library's equations.
    fn check_fused_system(&self) {
        let g = &self.machine.module;
        for (pose, (_, rho)) in self.path_poses.iter().zip(&self.path_joints).step_by(97) {
            let shifted = ModulePose {
                p: pose.p + Vector3::new(0.3, -0.2, 0.1),
                alpha: pose.alpha + 0.01,
            };
            let sys = system(g, &shifted, rho);
            let f = residuals(g, &shifted, rho);
            let a = jacobian_pose(g, &shifted, rho);
            let b = jacobian_sliders(g, &shifted, rho);
            assert!((sys.f - f).amax() <= 1e-6 * (1.0 + f.amax()));
            assert!((jac_pose(&sys) - a).amax() <= 1e-9 * (1.0 + a.amax()));
            let jj = jac_joints(&sys);
            for i in 0..4 {
                assert!((jj[(i, 0)] - a[(i, 3)]).abs() <= 1e-9 * (1.0 + a.amax()));
                for k in 0..3 {
                    assert!((jj[(i, k + 1)] - b[(i, k)]).abs() <= 1e-9 * (1.0 + b.amax()));
                }
            }
        }
    }

    // One pass over the path for each kernel; each returns something to black_box.

    fn run_ik_working(&self, pts: &[Vector3<f64>]) -> f64 {
        let mut acc = 0.0;
        let mut b = module_ik::IkBranches::new();
        for p in pts {
            module_ik::solve_working_into(&self.machine, black_box(p), &mut b);
            if let Some(w) = module_ik::working(&b) {
                acc += w.rho.x;
            }
        }
        acc
    }

    fn run_ik_all(&self, pts: &[Vector3<f64>]) -> usize {
        pts.iter()
            .map(|p| module_ik::solve(&self.machine, black_box(p)).len())
            .sum()
    }

    fn run_newton_ik(&self) -> (f64, u64) {
        let g = &self.machine.module;
        let mut q = self.path_joints[0];
        let (mut acc, mut iters) = (0.0, 0u64);
        for p in &self.path {
            let (next, it) = newton_ik(g, &self.limit, black_box(p), q);
            q = next;
            acc += q.1.x;
            iters += it as u64;
        }
        (acc, iters)
    }

    fn run_fk_all(&self, rhos: impl Iterator<Item = Sliders>) -> usize {
        rhos.map(|r| module_fk::solve(&self.machine, black_box(&r)).len())
            .sum()
    }

    fn run_fk_working(&self) -> f64 {
        let mut acc = 0.0;
        for (_, rho) in &self.path_joints {
            let modes = module_fk::solve(&self.machine, black_box(rho));
            if let Some(w) = module_fk::working(&modes) {
                acc += w.pose.p.x;
            }
        }
        acc
    }

    fn run_newton_fk(&self) -> (f64, u64) {
        let g = &self.machine.module;
        let mut pose = self.path_poses[0];
        let (mut acc, mut iters) = (0.0, 0u64);
        for (_, rho) in &self.path_joints {
            let (next, it) = newton_fk(g, &self.limit, pose, black_box(rho));
            pose = next;
            acc += pose.p.x;
            iters += it as u64;
        }
        (acc, iters)
    }

    fn run_tracker(&self, step: Step, fast: bool, rhos: &[Sliders]) -> (f64, Tracker<'_>) {
        let mut t = Tracker::new(&self.machine, step, fast);
        let mut acc = 0.0;
        for rho in rhos {
            if let Some(w) = t.solve(black_box(rho)) {
                acc += w.pose.p.x;
            }
        }
        (acc, t)
    }

    /// Accuracy and behaviour of the tracker and the baselines, printed before timing.
    fn accuracy_report(&self) -> Vec<String> {
        let g = &self.machine.module;
        let mut lines = Vec::new();
        let path_rho: Vec<Sliders> = self.path_joints.iter().map(|q| q.1).collect();
        for (label, rhos) in [
            ("path", &path_rho),
            ("scattered (no continuity)", &self.scatter_joints),
        ] {
            for (step, fast) in [
                (Step::Newton, false),
                (Step::Chord, false),
                (Step::Chord, true),
            ] {
                let mut t = Tracker::new(&self.machine, step, fast);
                let (mut dp, mut da, mut mismatch) = (0.0f64, 0.0f64, 0usize);
                for rho in rhos.iter() {
                    let got = t.solve(rho);
                    let want = module_fk::working(&module_fk::solve(&self.machine, rho)).copied();
                    match (got, want) {
                        (Some(a), Some(b)) => {
                            dp = dp.max((a.pose.p - b.pose.p).amax());
                            da = da.max((a.pose.alpha - b.pose.alpha).abs());
                            if a.config != b.config || a.verdict != b.verdict {
                                mismatch += 1;
                            }
                        }
                        (None, None) => {}
                        _ => mismatch += 1,
                    }
                }
                let tracked = rhos.len() as u64 - t.fallbacks;
                let verdict = if fast { ", verdict_no_acos" } else { "" };
                lines.push(format!(
                    "tracker ({step:?}{verdict}) on {label}: {} rows, {} fallbacks to module_fk::solve, \
                     {:.2} steps per tracked row; vs module_fk::working: max |dP| {:.1e} mm, \
                     max |d alpha| {:.1e} rad, {} mismatched rows",
                    rhos.len(),
                    t.fallbacks,
                    t.iterations as f64 / tracked.max(1) as f64,
                    dp,
                    da,
                    mismatch
                ));
            }
        }
        let ct = cos_tilt_max(&self.machine);
        let (mut checked, mut differ) = (0usize, 0usize);
        for p in self.path.iter().chain(&self.scatter) {
            for b in module_ik::solve(&self.machine, p) {
                let pose = ModulePose {
                    p: *p,
                    alpha: b.alpha,
                };
                let sys = system(g, &pose, &b.rho);
                let v = verdict_no_acos(&self.machine, ct, sys.cos_alpha, &sys.v, &b.rho, b.config);
                checked += 1;
                if v != b.verdict {
                    differ += 1;
                }
            }
        }
        lines.push(format!(
            "verdict_no_acos vs module_verdict: {checked} IK branches (path + scattered), {differ} differ"
        ));
        let (_, it_fk) = self.run_newton_fk();
        let (_, it_ik) = self.run_newton_ik();
        // Baseline accuracy against the exact solutions.
        let mut pose = self.path_poses[0];
        let mut q = self.path_joints[0];
        let (mut fk_err, mut ik_err) = (0.0f64, 0.0f64);
        for ((p, exact_q), exact_pose) in self
            .path
            .iter()
            .zip(&self.path_joints)
            .zip(&self.path_poses)
        {
            pose = newton_fk(g, &self.limit, pose, &exact_q.1).0;
            fk_err = fk_err.max((pose.p - exact_pose.p).amax());
            q = newton_ik(g, &self.limit, p, q).0;
            ik_err = ik_err.max((q.1 - exact_q.1).amax());
        }
        lines.push(format!(
            "newton FK baseline on path: {:.2} iterations per row, max |dP| vs exact {:.1e} mm",
            it_fk as f64 / self.path.len() as f64,
            fk_err
        ));
        lines.push(format!(
            "newton IK baseline on path: {:.2} iterations per row, max |d rho| vs exact {:.1e} mm",
            it_ik as f64 / self.path.len() as f64,
            ik_err
        ));
        let modes: usize = self.run_fk_all(path_rho.iter().copied());
        let branches: usize = self.run_ik_all(&self.path);
        lines.push(format!(
            "path: {} rows, step {:.3} mm per row; {:.2} IK branches and {:.2} FK modes per row; \
             scattered: {} points, {} with a working branch",
            self.path.len(),
            (self.path[1] - self.path[0]).norm(),
            branches as f64 / self.path.len() as f64,
            modes as f64 / self.path.len() as f64,
            self.scatter.len(),
            self.scatter_joints.len()
        ));
        lines
    }
}

// ------------------------------------------------------------------ timing and summary

/// Per-pose times (ns) of every sample of every kernel, recorded from `iter_custom`.
#[derive(Default)]
struct Record(RefCell<BTreeMap<String, Vec<f64>>>);

impl Record {
    fn median_ns(&self, name: &str) -> Option<f64> {
        let map = self.0.borrow();
        let mut v = map.get(name)?.clone();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        Some(v[v.len() / 2])
    }
}

/// Times `routine`, which handles `rows` inputs per call, as `group/name`, recording ns per row.
fn bench<R, F>(c: &mut Criterion, rec: &Record, group: &str, name: &str, rows: usize, mut f: F)
where
    F: FnMut() -> R,
{
    let key = format!("{group}/{name}");
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(rows as u64));
    g.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let start = Instant::now();
            for _ in 0..iters {
                black_box(f());
            }
            let el = start.elapsed();
            rec.0
                .borrow_mut()
                .entry(key.clone())
                .or_default()
                .push(el.as_nanos() as f64 / (iters.max(1) as f64 * rows as f64));
            el
        })
    });
    g.finish();
}

/// (kernel, baseline, target text): the pairs reported as ratios.
const RATIOS: &[(&str, &str, &str)] = &[
    (
        "ik/working_branch",
        "ik/newton_warm",
        "< 100 ns/pose and <= 0.5x Newton IK",
    ),
    (
        "ik/all_branches",
        "ik/newton_warm",
        "< 250 ns/pose (all sixteen branches)",
    ),
    (
        "ik/working_branch_scattered",
        "ik/newton_warm",
        "(no continuity; Newton needs it)",
    ),
    ("fk/all_modes", "fk/newton_warm", "< 2 us/pose"),
    (
        "fk/all_modes_scattered",
        "fk/newton_warm",
        "(no continuity; Newton needs it)",
    ),
    (
        "fk/working_solve",
        "fk/newton_warm",
        "(solve + working on every row, no tracking)",
    ),
    (
        "fk/working_track_newton",
        "fk/newton_warm",
        "<= 1.0x warm-started Newton FK",
    ),
    (
        "fk/working_track_chord",
        "fk/newton_warm",
        "<= 1.0x warm-started Newton FK",
    ),
    (
        "fk/working_track_chord_fast_verdict",
        "fk/newton_warm",
        "<= 1.0x warm-started Newton FK",
    ),
];

/// Sub-kernels reported per call, to show where the time goes.
const PARTS: &[(&str, &str)] = &[
    (
        "parts/fk_characteristic",
        "F(alpha) from the sliders (Trig products), per row",
    ),
    (
        "parts/fk_trig_roots",
        "Trig::roots of F over the circle, per row",
    ),
    (
        "parts/fk_polish_pose_exact",
        "polish_pose from an exact root, per call (FK does one per root)",
    ),
    (
        "parts/module_verdict",
        "module_verdict (4 acos in rod_tilts), per call (IK: 16 per row)",
    ),
    (
        "parts/verdict_no_acos",
        "the same verdict tested on cosines (rod vectors given), per call",
    ),
    ("parts/config_of", "config_of, per call"),
    (
        "parts/ik_cubic_roots_in",
        "roots_in on the cubic (9), per row",
    ),
];

fn summary(rec: &Record, accuracy: &[String]) -> String {
    let mut s = String::new();
    s.push_str("| kernel | ns/pose | baseline | baseline ns/pose | ratio | target |\n");
    s.push_str("|---|---:|---|---:|---:|---|\n");
    for (k, b, target) in RATIOS {
        let (Some(tk), Some(tb)) = (rec.median_ns(k), rec.median_ns(b)) else {
            continue;
        };
        s.push_str(&format!(
            "| `{k}` | {tk:.0} | `{b}` | {tb:.0} | {:.2} | {target} |\n",
            tk / tb
        ));
    }
    let mut parts = String::new();
    for (k, what) in PARTS {
        if let Some(t) = rec.median_ns(k) {
            parts.push_str(&format!("| `{k}` | {t:.0} | {what} |\n"));
        }
    }
    if !parts.is_empty() {
        s.push_str("\n| sub-kernel | ns | what |\n|---|---:|---|\n");
        s.push_str(&parts);
    }
    s.push('\n');
    for l in accuracy {
        s.push_str(&format!("- {l}\n"));
    }
    s
}

fn main() {
    let fx = Fixture::new();
    let accuracy = fx.accuracy_report();
    for l in &accuracy {
        eprintln!("{l}");
    }
    let rec = Record::default();
    let mut c = Criterion::default()
        .warm_up_time(WARM_UP)
        .measurement_time(MEASURE)
        .sample_size(SAMPLES)
        .configure_from_args();
    let n = fx.path.len();
    let path_rho: Vec<Sliders> = fx.path_joints.iter().map(|q| q.1).collect();
    let g = fx.machine.module;

    bench(&mut c, &rec, "ik", "working_branch", n, || {
        fx.run_ik_working(&fx.path)
    });
    bench(&mut c, &rec, "ik", "all_branches", n, || {
        fx.run_ik_all(&fx.path)
    });
    bench(&mut c, &rec, "ik", "working_branch_scattered", n, || {
        fx.run_ik_working(&fx.scatter)
    });
    bench(&mut c, &rec, "ik", "newton_warm", n, || fx.run_newton_ik());

    bench(&mut c, &rec, "fk", "all_modes", n, || {
        fx.run_fk_all(path_rho.iter().copied())
    });
    let ns = fx.scatter_joints.len();
    bench(&mut c, &rec, "fk", "all_modes_scattered", ns, || {
        fx.run_fk_all(fx.scatter_joints.iter().copied())
    });
    bench(&mut c, &rec, "fk", "working_solve", n, || {
        fx.run_fk_working()
    });
    bench(&mut c, &rec, "fk", "newton_warm", n, || fx.run_newton_fk());
    bench(&mut c, &rec, "fk", "working_track_newton", n, || {
        fx.run_tracker(Step::Newton, false, &path_rho).0
    });
    bench(&mut c, &rec, "fk", "working_track_chord", n, || {
        fx.run_tracker(Step::Chord, false, &path_rho).0
    });
    bench(
        &mut c,
        &rec,
        "fk",
        "working_track_chord_fast_verdict",
        n,
        || fx.run_tracker(Step::Chord, true, &path_rho).0,
    );

    // Sub-kernels.
    bench(&mut c, &rec, "parts", "fk_characteristic", n, || {
        path_rho
            .iter()
            .map(|r| fk_characteristic(&g, black_box(r)).cos[0])
            .sum::<f64>()
    });
    let chars: Vec<Trig> = path_rho.iter().map(|r| fk_characteristic(&g, r)).collect();
    bench(&mut c, &rec, "parts", "fk_trig_roots", n, || {
        chars
            .iter()
            .map(|f| black_box(f).roots().len())
            .sum::<usize>()
    });
    bench(&mut c, &rec, "parts", "fk_polish_pose_exact", n, || {
        fx.path_poses
            .iter()
            .zip(&path_rho)
            .map(|(p, r)| polish_pose(&g, black_box(*p), r).alpha)
            .sum::<f64>()
    });
    let configs: Vec<Config> = fx
        .path_poses
        .iter()
        .zip(&path_rho)
        .map(|(p, r)| config_of(&g, p, r))
        .collect();
    bench(&mut c, &rec, "parts", "module_verdict", n, || {
        fx.path_poses
            .iter()
            .zip(&path_rho)
            .zip(&configs)
            .filter(|((p, r), cfg)| module_verdict(&fx.machine, black_box(p), r, **cfg).feasible())
            .count()
    });
    let ct = cos_tilt_max(&fx.machine);
    let systems: Vec<System> = fx
        .path_poses
        .iter()
        .zip(&path_rho)
        .map(|(p, r)| system(&g, p, r))
        .collect();
    bench(&mut c, &rec, "parts", "verdict_no_acos", n, || {
        systems
            .iter()
            .zip(&path_rho)
            .zip(&configs)
            .filter(|((sys, r), cfg)| {
                verdict_no_acos(&fx.machine, ct, sys.cos_alpha, black_box(&sys.v), r, **cfg)
                    .feasible()
            })
            .count()
    });
    bench(&mut c, &rec, "parts", "config_of", n, || {
        fx.path_poses
            .iter()
            .zip(&path_rho)
            .map(|(p, r)| config_of(&g, black_box(p), r)[0] as i64)
            .sum::<i64>()
    });
    let cubics: Vec<[f64; 4]> = fx.path.iter().map(|p| ik_cubic(&g, p)).collect();
    bench(&mut c, &rec, "parts", "ik_cubic_roots_in", n, || {
        cubics
            .iter()
            .map(|c| roots_in(black_box(c), -1.0, 1.0).len())
            .sum::<usize>()
    });

    c.final_summary();
    if rec.0.borrow().is_empty() {
        return;
    }
    let text = summary(&rec, &accuracy);
    println!("\n{text}");
    if let Some(path) = std::env::var_os("VERNE_BENCH_SUMMARY") {
        std::fs::write(&path, &text).expect("cannot write VERNE_BENCH_SUMMARY");
    }
}
