//! Criterion benchmarks of the kinematic kernels of `verne` (IFToMM 2007 sections V-VI for the
//! parallel module, AIM 2007 sections III-IV for the whole machine) against the Newton-Raphson
//! resolution the VERNE controller uses, measured in the same run and reported as ratios
//! (docs/benchmarks.md; `scripts/bench.sh` runs this and records the table).
//!
//! Inputs are deterministic: a helix of radius 120 mm around x = -250, y = 0 mm rising from
//! z = 1000 to 1300 mm, sampled at about 0.2 mm per row (12 m/min at a 1 kHz servo rate); a
//! scattered set from a fixed LCG for the kernels that do not depend on row order; a 5-axis tool
//! path (a spiral on a dome, the tool normal to the surface, as `examples/make_verify_data.rs`
//! writes) with the joints the library chooses along it; and a z layer of the `verne workspace`
//! grids. Baselines: Newton-Raphson on the four equations
//! (3)-(6) for (xp, yp, zp, alpha) given the sliders (FK) or for (alpha, rho1, rho2, rho3) given
//! P (IK), warm-started from the previous row, stopping when every residual, expressed as a
//! length error along its rod, is below 1e-9 mm, at most 120 iterations (LinuxCNC genhexkins'
//! HEXKINS_CONV_CRITERION and HEXKINS_ITER_LIMIT). The machine, verify and workspace kernels
//! have no such baseline.
//!
//! Also here: a few sub-kernels that show where the module FK and IK time goes.
//!
//! `cargo bench --bench kernels` prints a summary table at the end; with `VERNE_BENCH_SUMMARY=FILE`
//! the table is also written to FILE (markdown).

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::hint::black_box;
use std::io::Cursor;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use nalgebra::{Matrix4, Vector3, Vector4};
use verne::machine::orientation::ToolOrientation;
use verne::machine::{
    FirstRowChoice, PathCandidates, PathState, machine_fk, path_candidates, path_candidates_into,
};
use verne::math::cubic::cubic_roots_in;
use verne::math::trig::Trig;
use verne::parallel_module::branches::{Config, config_of, module_verdict};
use verne::parallel_module::equations::{
    ModulePose, Sliders, jacobian_pose, jacobian_sliders, polish_pose, residuals,
};
use verne::parallel_module::fk::{self, FkModes};
use verne::parallel_module::ik;
use verne::parallel_module::track::FkTracker;
use verne::spec::{Machine, ModuleGeometry};
use verne::verify::{Thresholds, VerifyOptions, verify};
use verne::workspace::{self, Of, Outcome, PAPER_LAMBDA_BOUNDS, WorkspaceOptions};
use verne_cli::engine::pipeline::RUN_ROWS;
use verne_cli::input::verify_files::{JointReader, PathReader};
use verne_cli::table::CsvSource;
use verne_cli::toolpath::csv::CsvToolpath;

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

/// Tool path of the machine kernels (workpiece frame R_t): tips on a dome (centre, radius, mm)
/// along a spiral whose polar angle grows from BETA0 to BETA1 (deg), the tool axis the surface
/// normal, tips DOME_STEP_MM apart, DOME_FEED_MM_MIN for the `t` column of the joint table
/// (examples/make_verify_data.rs, at this row count).
const DOME_ROWS: usize = 1024;
const DOME_CENTRE: [f64; 3] = [0.0, 0.0, -100.0];
const DOME_RADIUS_MM: f64 = 150.0;
const DOME_BETA0_DEG: f64 = 6.0;
const DOME_BETA1_DEG: f64 = 30.0;
const DOME_STEP_MM: f64 = 0.5;
const DOME_FEED_MM_MIN: f64 = 1500.0;

/// Workspace kernels: the z layer nearest WS_LAYER_Z_MM of the default `verne workspace` box
/// (`--of platform`, `--of tool` with the machine's tool length), on a grid of WS_STEP_MM (the
/// command's default is 10 mm; a coarser step keeps a layer to about 1,100-1,200 points, and the time
/// per point does not depend on the step).
const WS_STEP_MM: f64 = 30.0;
const WS_LAYER_Z_MM: f64 = 1150.0;

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

/// One intended tool pose of the machine path: tip (mm) and unit tool axis in R_t.
#[derive(Debug, Clone, Copy)]
struct ToolPoint {
    tip: Vector3<f64>,
    axis: Vector3<f64>,
}

/// The dome spiral: `rows` tips DOME_STEP_MM apart, the polar angle growing linearly with the
/// azimuth from DOME_BETA0_DEG to DOME_BETA1_DEG, the axis the outward normal; tips rounded to
/// 4 decimals and axes to 7, as a CAM system writes them (the joints are those of the values
/// written).
fn dome_spiral(rows: usize) -> Vec<ToolPoint> {
    let (b0, b1) = (DOME_BETA0_DEG.to_radians(), DOME_BETA1_DEG.to_radians());
    let mean_sin = ((b0.cos() - b1.cos()) / (b1 - b0)).abs();
    let turns = rows as f64 * DOME_STEP_MM / (TAU * DOME_RADIUS_MM * mean_sin);
    let dbeta_dpsi = (b1 - b0) / (TAU * turns);
    let round = |v: f64, d: i32| (v * 10f64.powi(d)).round() / 10f64.powi(d);
    let centre = Vector3::from(DOME_CENTRE);
    let mut psi = 0.0f64;
    (0..rows)
        .map(|_| {
            let beta = b0 + dbeta_dpsi * psi;
            let n = Vector3::new(beta.sin() * psi.cos(), beta.sin() * psi.sin(), beta.cos());
            let tip = centre + DOME_RADIUS_MM * n;
            psi +=
                DOME_STEP_MM / (DOME_RADIUS_MM * (beta.sin().powi(2) + dbeta_dpsi.powi(2)).sqrt());
            ToolPoint {
                tip: tip.map(|v| round(v, 4)),
                axis: n.map(|v| round(v, 7)),
            }
        })
        .collect()
}

// ------------------------------------------------------- equations (3)-(6), fused evaluation
//
// The library has residuals, jacobian_pose and jacobian_sliders as separate public functions,
// each recomputing the rod vectors and sin_cos(alpha); its fused evaluation is crate-private. A
// controller evaluates residuals and Jacobian together, so the Newton baselines keep this fused
// evaluation (one sin_cos per iterate): built from the separate functions they would be slower
// and the ratios flattering. `Fixture::check_fused_system` ties it to the library's equations.

/// Residuals of (3)-(6) and the partial derivatives a Newton step needs, from one sin_cos.
struct System {
    /// |B - A|^2 - L^2 (mm^2).
    f: Vector4<f64>,
    /// Rod vectors B - A.
    v: [Vector3<f64>; 4],
    /// d f / d alpha.
    dfa: Vector4<f64>,
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
    System { f, v, dfa }
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

// --------------------------------------------------------------------------- fixture

/// Joints of one machine row: sliders (mm), theta1, theta2 (rad).
#[derive(Debug, Clone, Copy)]
struct MachineJoints {
    rho: Sliders,
    theta1: f64,
    theta2: f64,
}

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
    /// The machine's tool path (dome spiral) and, for its rows where `PathState` found a
    /// working branch, the tool point and the joints chosen.
    tool_path: Vec<ToolPoint>,
    tool_joints: Vec<(ToolPoint, MachineJoints)>,
    /// `verne verify` inputs made from `tool_joints`: the intended path (id,x,y,z,i,j,k) and the
    /// joint table (id,t,rho1,rho2,rho3,theta1,theta2 in mm, s, degrees with 6 decimals).
    verify_path_csv: Arc<[u8]>,
    verify_joints_csv: Arc<[u8]>,
    verify_options: VerifyOptions,
    /// Workspace kernels: options and the grid layer, per `Of::Platform` and `Of::Tool`.
    ws: Vec<(WorkspaceOptions, Vec<Vector3<f64>>)>,
    /// The IK lists of one run of rows, reused (as the streaming engine keeps its own).
    ik_slots: Mutex<Vec<ik::IkBranches>>,
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
                let b = ik::solve(&machine, p);
                let w = ik::working(&b)
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
            .filter_map(|p| ik::working(&ik::solve(&machine, p)).map(|w| w.rho))
            .collect();

        // The machine path and the joints the library chooses along it (`verne machine ik`).
        let tool_path = dome_spiral(DOME_ROWS);
        let tl = machine.tool_length;
        let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
        let tool_joints: Vec<(ToolPoint, MachineJoints)> = tool_path
            .iter()
            .filter_map(|t| {
                let row = state
                    .next_row(&machine, &t.tip, &ToolOrientation::Axis(t.axis), tl)
                    .ok()?;
                Some((
                    *t,
                    MachineJoints {
                        rho: row.rho,
                        theta1: row.theta1,
                        theta2: row.theta2,
                    },
                ))
            })
            .collect();
        let dt = DOME_STEP_MM / (DOME_FEED_MM_MIN / 60.0);
        let (mut path_csv, mut joints_csv) = (
            String::from("id,x,y,z,i,j,k\n"),
            String::from("id,t,rho1,rho2,rho3,theta1,theta2\n"),
        );
        for (k, (t, q)) in tool_joints.iter().enumerate() {
            let _ = writeln!(
                path_csv,
                "{},{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}",
                k + 1,
                t.tip.x,
                t.tip.y,
                t.tip.z,
                t.axis.x,
                t.axis.y,
                t.axis.z
            );
            let _ = writeln!(
                joints_csv,
                "{},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6}",
                k + 1,
                k as f64 * dt,
                q.rho.x,
                q.rho.y,
                q.rho.z,
                q.theta1.to_degrees(),
                q.theta2.to_degrees()
            );
        }
        let verify_options = VerifyOptions {
            thresholds: Thresholds::from_machine(&machine, "<default>")
                .expect("the default machine's verify thresholds are valid"),
            tool_length: tl,
        };

        // One z layer of the default `verne workspace` grids.
        let ws = [(Of::Platform, 0.0), (Of::Tool, tl)]
            .into_iter()
            .map(|(of, tool_length)| {
                let opts = WorkspaceOptions {
                    of,
                    tool_length,
                    step: WS_STEP_MM,
                    bounds: None,
                    lambda: PAPER_LAMBDA_BOUNDS,
                };
                let grid = workspace::grid_for(&machine, &opts).expect("workspace grid");
                let k = (0..grid.n[2])
                    .min_by(|&a, &b| {
                        (grid.coord(2, a) - WS_LAYER_Z_MM)
                            .abs()
                            .total_cmp(&(grid.coord(2, b) - WS_LAYER_Z_MM).abs())
                    })
                    .expect("non-empty grid");
                let layer = (0..grid.n[1])
                    .flat_map(|j| (0..grid.n[0]).map(move |i| grid.point(i, j, k)))
                    .collect();
                (opts, layer)
            })
            .collect();

        let fx = Fixture {
            machine,
            limit,
            path,
            path_joints,
            path_poses,
            scatter,
            scatter_joints,
            tool_path,
            tool_joints,
            verify_path_csv: path_csv.into_bytes().into(),
            verify_joints_csv: joints_csv.into_bytes().into(),
            verify_options,
            ws,
            ik_slots: Mutex::new(vec![ik::IkBranches::new(); RUN_ROWS]),
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
        let mut b = ik::IkBranches::new();
        for p in pts {
            ik::solve_working_into(&self.machine, black_box(p), &mut b);
            if let Some(w) = ik::working(&b) {
                acc += w.rho.x;
            }
        }
        acc
    }

    /// Every branch into one reused list (`ik::solve_into`, as `verne ik --all` does; the
    /// by-value `solve` adds a copy of the 24-entry list).
    fn run_ik_all(&self, pts: &[Vector3<f64>]) -> usize {
        let mut b = ik::IkBranches::new();
        pts.iter()
            .map(|p| {
                ik::solve_into(&self.machine, black_box(p), &mut b);
                b.len()
            })
            .sum()
    }

    /// Every branch of every point of `pts`, each alone, in runs of RUN_ROWS through
    /// `ik::solve_each` (as `verne ik --all` does); returns the number of branches.
    fn run_ik_all_lanes(&self, pts: &[Vector3<f64>]) -> usize {
        let mut n = 0;
        self.run_ik_runs(pts, |m, rows| ik::solve_each(m, rows), |_, b| n += b.len());
        n
    }

    /// [`Self::run_ik_all_lanes`] with `solve_each` built for the x86-64 baseline (no AVX2).
    fn run_ik_all_lanes_baseline(&self, pts: &[Vector3<f64>]) -> usize {
        let mut n = 0;
        self.run_ik_runs(
            pts,
            |m, rows| ik::solve_each_baseline(m, rows),
            |_, b| n += b.len(),
        );
        n
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
        rhos.map(|r| fk::solve(&self.machine, black_box(&r)).len())
            .sum()
    }

    fn run_fk_working(&self) -> f64 {
        let mut acc = 0.0;
        for (_, rho) in &self.path_joints {
            let modes = fk::solve(&self.machine, black_box(rho));
            if let Some(w) = fk::working(&modes) {
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

    /// The working mode along rows `rhos` by the library's tracker, a fresh tracker per run of
    /// `RUN_ROWS` rows as `verne fk` does (`ModuleFk::solve_run`); calls `each` per row.
    fn run_tracker(
        &self,
        rhos: &[Sliders],
        mut each: impl FnMut(&Sliders, &FkModes),
    ) -> (u64, u64) {
        let mut modes = FkModes::new();
        let (mut tracked, mut solved) = (0, 0);
        for run in rhos.chunks(RUN_ROWS) {
            let mut t = FkTracker::new(&self.machine);
            for rho in run {
                t.working_into(black_box(rho), &mut modes);
                each(rho, &modes);
            }
            tracked += t.tracked;
            solved += t.solved;
        }
        (tracked, solved)
    }

    /// The IK working branch of every point of `pts`, each alone, in runs of RUN_ROWS through
    /// `ik::solve_working_each` (as `verne ik` does); `each` sees every row's answer.
    fn run_ik_lanes(&self, pts: &[Vector3<f64>], each: impl FnMut(&Vector3<f64>, &ik::IkBranches)) {
        self.run_ik_runs(pts, |m, rows| ik::solve_working_each(m, rows), each);
    }

    /// `solve` (LANES points side by side) on `pts` in runs of RUN_ROWS, into lists reused
    /// from run to run as the streaming engine keeps its own; `each` sees every row's answer.
    fn run_ik_runs(
        &self,
        pts: &[Vector3<f64>],
        solve: impl for<'a> Fn(
            &Machine,
            &mut dyn Iterator<Item = (Vector3<f64>, &'a mut ik::IkBranches)>,
        ),
        mut each: impl FnMut(&Vector3<f64>, &ik::IkBranches),
    ) {
        let mut slots = self.ik_slots.lock().expect("one benchmark at a time");
        for run in pts.chunks(RUN_ROWS) {
            let mut rows = run.iter().map(|p| *black_box(p)).zip(slots.iter_mut());
            solve(&self.machine, &mut rows);
            for (p, b) in run.iter().zip(slots.iter()) {
                each(p, b);
            }
        }
    }

    /// Every branch of every tool pose of the machine path, over both orientation solutions of
    /// the axis (what `verne ik` solves per row of tool poses before choosing), into one set
    /// refilled row after row as the streaming engine refills a batch row's.
    fn run_machine_ik(&self) -> usize {
        let tl = self.machine.tool_length;
        let mut candidates = PathCandidates::default();
        self.tool_path
            .iter()
            .map(|t| {
                path_candidates_into(
                    &self.machine,
                    black_box(&t.tip),
                    &ToolOrientation::Axis(t.axis),
                    tl,
                    None,
                    &mut candidates,
                )
                .map_or(0, |()| candidates.len())
            })
            .sum()
    }

    /// Every assembly mode of the machine for the joints chosen along the path.
    fn run_machine_fk(&self) -> usize {
        let tl = self.machine.tool_length;
        self.tool_joints
            .iter()
            .map(|(_, q)| {
                machine_fk(&self.machine, black_box(&q.rho), q.theta1, q.theta2, tl).len()
            })
            .sum()
    }

    /// `verne verify` of the joint table against the path, from in-memory CSV (the API reads
    /// `CsvSource`s), findings counted instead of written. Returns (rows, findings).
    fn run_verify(&self) -> (u64, u64) {
        let src = |bytes: &Arc<[u8]>, name: &str| {
            CsvSource::from_reader(Box::new(Cursor::new(Arc::clone(bytes))), name)
                .expect("in-memory CSV")
        };
        let mut joints = JointReader::new(src(&self.verify_joints_csv, "joints")).expect("joints");
        let toolpath = CsvToolpath::new(src(&self.verify_path_csv, "path"), false).expect("path");
        let mut path = PathReader::new(Box::new(toolpath), nalgebra::Vector3::zeros());
        let mut findings = 0u64;
        let summary = verify(
            &self.machine,
            &self.verify_options,
            &mut joints,
            &mut path,
            &mut |_| {
                findings += 1;
                Ok(())
            },
        )
        .expect("verify");
        (summary.rows, findings)
    }

    /// Classifies every point of workspace layer `w` (0: platform, 1: tool).
    fn run_workspace(&self, w: usize) -> [usize; 3] {
        let (opts, layer) = &self.ws[w];
        let mut n = [0usize; 3];
        for q in layer {
            let r = workspace::classify(&self.machine, opts, black_box(q));
            n[match r.outcome {
                Outcome::Inside => 0,
                Outcome::Bound(_) => 1,
                Outcome::OutOfReach => 2,
            }] += 1;
        }
        n
    }

    /// Accuracy and behaviour of the tracker, the baselines and the inputs, printed before timing.
    fn accuracy_report(&self) -> Vec<String> {
        let g = &self.machine.module;
        let mut lines = Vec::new();
        let path_rho: Vec<Sliders> = self.path_joints.iter().map(|q| q.1).collect();
        for (label, rhos) in [
            ("path", &path_rho),
            ("scattered (no continuity)", &self.scatter_joints),
        ] {
            let (mut dp, mut da, mut mismatch) = (0.0f64, 0.0f64, 0usize);
            let (tracked, solved) = self.run_tracker(rhos, |rho, modes| {
                let got = fk::working(modes);
                let full = fk::solve(&self.machine, rho);
                match (got, fk::working(&full)) {
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
            });
            lines.push(format!(
                "track::FkTracker on {label}: {} rows in runs of {RUN_ROWS}, {tracked} tracked, \
                 {solved} solved by fk::solve; vs fk::working(fk::solve): \
                 max |dP| {dp:.1e} mm, max |d alpha| {da:.1e} rad, {mismatch} mismatched rows",
                rhos.len(),
            ));
        }
        for (label, pts) in [
            ("path", &self.path),
            ("scattered (no continuity)", &self.scatter),
        ] {
            let (mut dr, mut da, mut mismatch) = (0.0f64, 0.0f64, 0usize);
            self.run_ik_lanes(pts, |p, got| {
                let full = ik::solve(&self.machine, p);
                match (ik::working(got), ik::working(&full)) {
                    (Some(a), Some(b)) => {
                        dr = dr.max((a.rho - b.rho).amax());
                        da = da.max((a.alpha - b.alpha).abs());
                        if a.config != b.config || a.verdict != b.verdict {
                            mismatch += 1;
                        }
                    }
                    (None, None) => {}
                    _ => mismatch += 1,
                }
            });
            let by_lanes: usize = pts
                .chunks_exact(ik::LANES)
                .map(|c| {
                    let c: &[Vector3<f64>; ik::LANES] = c.try_into().unwrap();
                    ik::working_lanes(&self.machine, c).iter().flatten().count()
                })
                .sum();
            lines.push(format!(
                "ik::solve_working_each on {label}: {} rows, {by_lanes} answered by \
                 ik::working_lanes ({} side by side), the others by the cubic or \
                 ik::solve_into; vs ik::working(ik::solve): \
                 max |d rho| {dr:.1e} mm, max |d alpha| {da:.1e} rad, {mismatch} mismatched rows",
                pts.len(),
                ik::LANES,
            ));
        }
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
        let fast = |pts: &[Vector3<f64>]| {
            pts.iter()
                .filter(|p| ik::working_fast(&self.machine, p).is_some())
                .count()
        };
        lines.push(format!(
            "path: {} rows, step {:.3} mm per row; {:.2} IK branches and {:.2} FK modes per row; \
             scattered: {} points, {} with a working branch; ik::solve_working_into took \
             the fast path (working_fast) on {} path rows and {} scattered points",
            self.path.len(),
            (self.path[1] - self.path[0]).norm(),
            branches as f64 / self.path.len() as f64,
            modes as f64 / self.path.len() as f64,
            self.scatter.len(),
            self.scatter_joints.len(),
            fast(&self.path),
            fast(&self.scatter),
        ));

        // Machine path: reachability, branches, and FK of the chosen joints back to the path.
        let tl = self.machine.tool_length;
        let (mut reachable, mut working) = (0usize, 0usize);
        for t in &self.tool_path {
            if let Ok(c) = path_candidates(
                &self.machine,
                &t.tip,
                &ToolOrientation::Axis(t.axis),
                tl,
                None,
            ) {
                reachable += usize::from(!c.is_empty());
                working += usize::from(c.iter().any(|(b, _, _)| b.working()));
            }
        }
        let (mut tip_err, mut axis_err, mut no_mode) = (0.0f64, 0.0f64, 0usize);
        for (t, q) in &self.tool_joints {
            let modes = machine_fk(&self.machine, &q.rho, q.theta1, q.theta2, tl);
            let w = modes
                .iter()
                .filter(|m| m.working())
                .min_by(|a, b| a.module.alpha.abs().total_cmp(&b.module.alpha.abs()));
            match w {
                Some(w) => {
                    tip_err = tip_err.max((w.tool.tip - t.tip).amax());
                    axis_err = axis_err.max((w.axis - t.axis.normalize()).amax());
                }
                None => no_mode += 1,
            }
        }
        lines.push(format!(
            "machine path (dome spiral, R = {DOME_RADIUS_MM} mm, tool tilted {DOME_BETA0_DEG} to \
             {DOME_BETA1_DEG} deg, {DOME_STEP_MM} mm per row, tool length {tl} mm): {} tool poses, \
             {reachable} with a real branch, {working} with a working branch; {:.2} branches per \
             pose (both orientation solutions); {:.2} machine FK modes per row; FK of the chosen \
             joints vs the path: max |dU| {tip_err:.1e} mm, max |d axis| {axis_err:.1e}, \
             {no_mode} rows without a working mode",
            self.tool_path.len(),
            self.run_machine_ik() as f64 / self.tool_path.len() as f64,
            self.run_machine_fk() as f64 / self.tool_joints.len().max(1) as f64,
        ));
        let (rows, findings) = self.run_verify();
        lines.push(format!(
            "verify: {rows} joint rows (machine path, joints of PathState written with 6 \
             decimals) against the path, {findings} findings; timed on a 1-thread rayon pool, \
             CSV parsing of both in-memory tables included"
        ));
        for (w, (opts, layer)) in self.ws.iter().enumerate() {
            let [inside, bound, out] = self.run_workspace(w);
            lines.push(format!(
                "workspace --of {}: z = {} mm layer of the default box at {WS_STEP_MM} mm: {} \
                 points, {inside} inside, {bound} outside by a constraint, {out} out of reach",
                opts.of.name(),
                layer.first().map_or(f64::NAN, |q| q.z),
                layer.len(),
            ));
        }
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

/// (kernel, what one input is, baseline or "" for none, target text): the main table, with
/// ratios to the baseline measured in the same run.
const KERNELS: &[(&str, &str, &str, &str)] = &[
    (
        "ik/working_branch",
        "module pose",
        "ik/newton_warm",
        "< 100 ns/pose and <= 0.5x Newton IK (each point alone)",
    ),
    (
        "ik/working_lanes",
        "module pose",
        "ik/newton_warm",
        "< 100 ns/pose and <= 0.5x Newton IK (each point alone, four side by side, as `verne ik`)",
    ),
    (
        "ik/working_lanes_baseline",
        "module pose",
        "ik/newton_warm",
        "(the same built for the x86-64 baseline, without AVX2)",
    ),
    (
        "ik/all_branches",
        "module pose",
        "ik/newton_warm",
        "< 250 ns/pose (all sixteen branches, each point alone)",
    ),
    (
        "ik/all_branches_lanes",
        "module pose",
        "ik/newton_warm",
        "< 250 ns/pose (all sixteen branches, four side by side, as `verne ik --all`)",
    ),
    (
        "ik/all_branches_lanes_baseline",
        "module pose",
        "ik/newton_warm",
        "(the same built for the x86-64 baseline, without AVX2)",
    ),
    (
        "ik/working_branch_scattered",
        "module pose",
        "ik/newton_warm",
        "(no continuity; Newton needs it)",
    ),
    (
        "fk/all_modes",
        "slider row",
        "fk/newton_warm",
        "< 2 us/pose",
    ),
    (
        "fk/all_modes_baseline",
        "slider row",
        "fk/newton_warm",
        "(the same built for the x86-64 baseline, without AVX2)",
    ),
    (
        "fk/all_modes_scattered",
        "slider row",
        "fk/newton_warm",
        "(no continuity; Newton needs it)",
    ),
    (
        "fk/working_solve",
        "slider row",
        "fk/newton_warm",
        "(solve + working on every row, no tracking)",
    ),
    (
        "fk/working_track",
        "slider row",
        "fk/newton_warm",
        "<= 1.0x warm-started Newton FK",
    ),
    (
        "machine/ik_all_branches",
        "tool pose",
        "",
        "tip + axis -> every branch, both orientation solutions (path_candidates_into)",
    ),
    (
        "machine/fk_all_modes",
        "joint row",
        "",
        "joints -> every assembly mode and its tool pose (machine_fk)",
    ),
    (
        "verify/row",
        "joint row",
        "",
        "verne verify per row: CSV parse, row and segment checks, 1 thread",
    ),
    (
        "workspace/platform_point",
        "grid point",
        "",
        "workspace::classify, --of platform",
    ),
    (
        "workspace/tool_point",
        "grid point",
        "",
        "workspace::classify, --of tool (tool length of the machine)",
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
        "module_verdict (squared rod tilts, no acos), per call",
    ),
    ("parts/config_of", "config_of, per call"),
    (
        "parts/ik_cubic_roots_in",
        "cubic_roots_in on the cubic (9) over [-1, 1], per row",
    ),
];

// ------------------------------------------------------------------ pass by pass

/// Rounds of [`PassKernel`]s for the pass-by-pass timing: each round times one pass of every
/// kernel over its whole input (about 10 ms a round).
const PASS_ROUNDS: usize = 600;

/// A kernel timed pass by pass: its name in the main table, the target it answers to (ns per
/// input) with its baseline's name (None for a baseline), and one pass over the path.
struct PassKernel<'a> {
    name: &'static str,
    target: Option<(f64, &'static str)>,
    pass: Box<dyn Fn() + 'a>,
}

impl<'a> PassKernel<'a> {
    fn new(
        name: &'static str,
        target: Option<(f64, &'static str)>,
        pass: impl Fn() + 'a,
    ) -> PassKernel<'a> {
        PassKernel {
            name,
            target,
            pass: Box::new(pass),
        }
    }
}

/// ns per input of every pass of every kernel, in the order of the kernels.
type PassTimes = Vec<Vec<f64>>;

/// The `q` quantile of sorted `v`, nearest rank.
fn quantile(v: &[f64], q: f64) -> f64 {
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Times the kernels pass by pass, `rounds` rounds of one pass each, in a different order every
/// round. Criterion's samples each average many passes over some 150 ms. This machine is a
/// virtual one whose vCPUs share physical cores with load from outside it (at times for seconds,
/// at times for minutes), and a throughput-bound kernel then runs up to 1.8 times slower (a
/// latency-bound one, such as the Newton baselines, hardly slower): a sample's mean mixes the
/// two states in whatever share the run met. Single passes of about a millisecond mostly fall in
/// one state or the other: the fastest passes show what the code costs when it has the core to
/// itself, the median and the 90th percentile what the run met.
/// Each pass handles `rows` inputs.
fn passes(kernels: &[PassKernel], rows: usize, rounds: usize) -> PassTimes {
    for k in kernels {
        (k.pass)();
    }
    let mut ns: PassTimes = vec![Vec::with_capacity(rounds); kernels.len()];
    for round in 0..rounds {
        for j in 0..kernels.len() {
            let k = (j + round) % kernels.len();
            let start = Instant::now();
            (kernels[k].pass)();
            ns[k].push(start.elapsed().as_nanos() as f64 / rows.max(1) as f64);
        }
    }
    ns
}

/// The pass-by-pass table: per kernel the fastest pass, the 10th, 50th and 90th percentiles (ns
/// per input), the share of passes under its target, and the median ratio to its baseline's
/// pass of the same round.
fn passes_summary(kernels: &[PassKernel], times: &PassTimes) -> String {
    let mut s = format!(
        "Pass by pass ({PASS_ROUNDS} rounds of one pass of each kernel over its whole input, in \
         turn; ns per input; ratios to the baseline's pass of the same round):\n\n\
         | kernel | target | fastest | p10 | median | p90 | passes under target | median ratio \
         to baseline |\n|---|---:|---:|---:|---:|---:|---:|---|\n"
    );
    let sorted = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v
    };
    for (k, kernel) in kernels.iter().enumerate() {
        let t = sorted(&times[k]);
        if t.is_empty() {
            continue;
        }
        let (mut target, mut under, mut ratio) =
            ("-".to_string(), "-".to_string(), "-".to_string());
        if let Some((target_ns, baseline)) = kernel.target {
            let n = t.iter().filter(|&&x| x < target_ns).count();
            target = format!("{target_ns:.0}");
            under = format!("{:.0} %", 100.0 * n as f64 / t.len() as f64);
            if let Some(b) = kernels.iter().position(|x| x.name == baseline) {
                let r: Vec<f64> = times[k].iter().zip(&times[b]).map(|(x, y)| x / y).collect();
                ratio = format!("{:.2} (`{baseline}`)", quantile(&sorted(&r), 0.5));
            }
        }
        let _ = writeln!(
            s,
            "| `{}` | {target} | {:.0} | {:.0} | {:.0} | {:.0} | {under} | {ratio} |",
            kernel.name,
            t[0],
            quantile(&t, 0.1),
            quantile(&t, 0.5),
            quantile(&t, 0.9),
        );
    }
    s
}

fn summary(rec: &Record, accuracy: &[String]) -> String {
    let mut s = String::new();
    s.push_str("| kernel | input | ns/input | baseline | baseline ns/input | ratio | target |\n");
    s.push_str("|---|---|---:|---|---:|---:|---|\n");
    for (k, input, b, target) in KERNELS {
        let Some(tk) = rec.median_ns(k) else {
            continue;
        };
        match rec.median_ns(b) {
            Some(tb) => s.push_str(&format!(
                "| `{k}` | {input} | {tk:.0} | `{b}` | {tb:.0} | {:.2} | {target} |\n",
                tk / tb
            )),
            None => s.push_str(&format!(
                "| `{k}` | {input} | {tk:.0} | - | - | - | {target} |\n"
            )),
        }
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
    bench(&mut c, &rec, "ik", "all_branches_lanes", n, || {
        fx.run_ik_all_lanes(&fx.path)
    });
    bench(&mut c, &rec, "ik", "all_branches_lanes_baseline", n, || {
        fx.run_ik_all_lanes_baseline(&fx.path)
    });
    bench(&mut c, &rec, "ik", "working_branch_scattered", n, || {
        fx.run_ik_working(&fx.scatter)
    });
    bench(&mut c, &rec, "ik", "working_lanes", n, || {
        let mut acc = 0.0;
        fx.run_ik_lanes(&fx.path, |_, b| {
            if let Some(w) = ik::working(b) {
                acc += w.rho.x;
            }
        });
        acc
    });
    bench(&mut c, &rec, "ik", "working_lanes_baseline", n, || {
        let mut acc = 0.0;
        fx.run_ik_runs(
            &fx.path,
            |m, rows| ik::solve_working_each_baseline(m, rows),
            |_, b| {
                if let Some(w) = ik::working(b) {
                    acc += w.rho.x;
                }
            },
        );
        acc
    });
    bench(&mut c, &rec, "ik", "newton_warm", n, || fx.run_newton_ik());

    bench(&mut c, &rec, "fk", "all_modes", n, || {
        fx.run_fk_all(path_rho.iter().copied())
    });
    bench(&mut c, &rec, "fk", "all_modes_baseline", n, || {
        path_rho
            .iter()
            .map(|r| fk::solve_baseline(&fx.machine, black_box(r)).len())
            .sum::<usize>()
    });
    let ns = fx.scatter_joints.len();
    bench(&mut c, &rec, "fk", "all_modes_scattered", ns, || {
        fx.run_fk_all(fx.scatter_joints.iter().copied())
    });
    bench(&mut c, &rec, "fk", "working_solve", n, || {
        fx.run_fk_working()
    });
    bench(&mut c, &rec, "fk", "newton_warm", n, || fx.run_newton_fk());
    bench(&mut c, &rec, "fk", "working_track", n, || {
        let mut acc = 0.0;
        fx.run_tracker(&path_rho, |_, modes| {
            if let Some(w) = fk::working(modes) {
                acc += w.pose.p.x;
            }
        });
        acc
    });

    // The whole machine, verify, workspace.
    bench(
        &mut c,
        &rec,
        "machine",
        "ik_all_branches",
        fx.tool_path.len(),
        || fx.run_machine_ik(),
    );
    bench(
        &mut c,
        &rec,
        "machine",
        "fk_all_modes",
        fx.tool_joints.len(),
        || fx.run_machine_fk(),
    );
    // verify solves its batches with rayon: one thread, so that the time per row is the work
    // per row (and does not depend on what else runs on the machine's cores).
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("rayon pool");
    bench(&mut c, &rec, "verify", "row", fx.tool_joints.len(), || {
        one_thread.install(|| fx.run_verify())
    });
    for (w, name) in [(0, "platform_point"), (1, "tool_point")] {
        bench(&mut c, &rec, "workspace", name, fx.ws[w].1.len(), || {
            fx.run_workspace(w)
        });
    }

    // Sub-kernels.
    bench(&mut c, &rec, "parts", "fk_characteristic", n, || {
        path_rho
            .iter()
            .map(|r| fk::characteristic(&g, black_box(r)).cos[0])
            .sum::<f64>()
    });
    let chars: Vec<Trig> = path_rho.iter().map(|r| fk::characteristic(&g, r)).collect();
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
    bench(&mut c, &rec, "parts", "config_of", n, || {
        fx.path_poses
            .iter()
            .zip(&path_rho)
            .map(|(p, r)| config_of(&g, black_box(p), r)[0] as i64)
            .sum::<i64>()
    });
    let cubics: Vec<[f64; 4]> = fx
        .path
        .iter()
        .filter_map(|p| ik::cubic_eq9(&g, p))
        .collect();
    bench(&mut c, &rec, "parts", "ik_cubic_roots_in", n, || {
        cubics
            .iter()
            .map(|c| cubic_roots_in(black_box(c), -1.0, 1.0).len())
            .sum::<usize>()
    });

    // The kernels with an absolute target and their baselines, pass by pass.
    let pass_kernels = [
        PassKernel::new("ik/working_lanes", Some((100.0, "ik/newton_warm")), || {
            fx.run_ik_lanes(&fx.path, |_, b| {
                black_box(ik::working(b));
            })
        }),
        PassKernel::new(
            "ik/all_branches_lanes",
            Some((250.0, "ik/newton_warm")),
            || {
                black_box(fx.run_ik_all_lanes(&fx.path));
            },
        ),
        PassKernel::new("ik/newton_warm", None, || {
            black_box(fx.run_newton_ik());
        }),
        PassKernel::new("fk/all_modes", Some((2000.0, "fk/newton_warm")), || {
            black_box(fx.run_fk_all(path_rho.iter().copied()));
        }),
        PassKernel::new("fk/newton_warm", None, || {
            black_box(fx.run_newton_fk());
        }),
    ];
    let pass_times = passes(&pass_kernels, n, PASS_ROUNDS);
    let pass_text = passes_summary(&pass_kernels, &pass_times);
    eprintln!("\n{pass_text}");

    c.final_summary();
    if rec.0.borrow().is_empty() {
        return;
    }
    let text = summary(&rec, &accuracy) + "\n" + &pass_text;
    println!("\n{text}");
    if let Some(path) = std::env::var_os("VERNE_BENCH_SUMMARY") {
        std::fs::write(&path, &text).expect("cannot write VERNE_BENCH_SUMMARY");
    }
}
