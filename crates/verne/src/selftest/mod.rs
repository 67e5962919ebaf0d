//! Self-test of a machine file: round trips of the parallel module's kinematics over a grid of
//! joints inside the strokes, and over poses built on the solvers' degenerate sets
//! ([`crate::selftest::hard_sets`]), reporting the worst residual and every miss (the check that finds
//! wrong kinematics modules: every forward mode must come back from the inverse, every inverse
//! branch of that pose must satisfy eqs. (3)-(6) and come back from the forward kinematics, and
//! every constructed pose must be among the modes of its sliders). Angles are compared modulo
//! 2 pi. A machine on which nothing could be tested fails, saying so.

pub mod hard_sets;

use crate::par::*;

use crate::parallel_module::equations::{ModulePose, Sliders, residual_mm};
use crate::parallel_module::fk;
use crate::parallel_module::ik::{self, wrap_angle};
use crate::spec::Machine;
use hard_sets::{HardSet, Sampler};

/// Results of a self-test.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SelftestReport {
    /// Joint sets tried on the grid.
    pub joint_sets: u64,
    /// Forward assembly modes found (all of them, working or not).
    pub fk_modes: u64,
    /// Inverse branches checked (all branches of every mode's pose).
    pub ik_branches: u64,
    /// Poses built on the degenerate sets, and how many of them are missing from the forward
    /// kinematics of their sliders.
    pub hard_poses: u64,
    pub hard_misses: u64,
    /// Solutions whose completeness could not be proved (status `uncertified`).
    pub uncertified: u64,
    /// Worst residual of eqs. (3)-(6) over all solutions (mm along a rod).
    pub worst_residual_mm: f64,
    /// Worst distance from the joints to the nearest inverse branch of a forward mode (mm).
    pub worst_fk_ik_mm: f64,
    /// Worst distance from a pose to the nearest forward mode of an inverse branch's joints
    /// (mm, with alpha weighted by R2).
    pub worst_ik_fk_mm: f64,
    /// Forward modes whose pose has no inverse branch returning the joints.
    pub fk_ik_misses: u64,
    /// Inverse branches whose joints have no forward mode returning the pose.
    pub ik_fk_misses: u64,
    /// The first failures, each with the joints that reproduce it.
    pub failures: Vec<String>,
}

/// Round trips closer than this (mm) count as returning.
pub const RETURN_TOL_MM: f64 = 1e-6;

/// Failures kept for the report.
const FAILURES_KEPT: usize = 5;

/// Starts per degenerate set (each gives up to eleven poses).
const HARD_STARTS_PER_SET: usize = 12;

/// Runs the round trips on an n x n x n grid of joints spanning the strokes, and on poses built
/// on every degenerate set.
pub fn run(m: &Machine, n: usize) -> SelftestReport {
    let n = n.max(2);
    let lim = m.limits;
    let joints: Vec<Sliders> = (0..n * n * n)
        .map(|k| {
            let (i, j, l) = (k % n, (k / n) % n, k / (n * n));
            let f = |t: usize, d: usize| {
                t as f64 / (n - 1) as f64 * (lim.rho_max[d] - lim.rho_min[d]) + lim.rho_min[d]
            };
            Sliders::new(f(i, 0), f(j, 1), f(l, 2))
        })
        .collect();
    let grid = joints
        .par_iter()
        .map(|rho| check_joints(m, rho))
        .reduce(SelftestReport::default, merge);
    let hard = HardSet::ALL
        .par_iter()
        .enumerate()
        .map(|(k, set)| check_hard_set(m, *set, k as u64))
        .reduce(SelftestReport::default, merge);
    merge(grid, hard)
}

fn fail(r: &mut SelftestReport, what: String) {
    if r.failures.len() < FAILURES_KEPT {
        r.failures.push(what);
    }
}

fn check_joints(m: &Machine, rho: &Sliders) -> SelftestReport {
    let g = &m.module;
    let mut r = SelftestReport {
        joint_sets: 1,
        ..Default::default()
    };
    let modes = fk::solve(m, rho);
    if !modes.certificate.proved() {
        r.uncertified += 1;
        fail(
            &mut r,
            format!("--joints {},{},{}: FK uncertified", rho.x, rho.y, rho.z),
        );
    }
    for mode in modes {
        r.fk_modes += 1;
        r.worst_residual_mm = r.worst_residual_mm.max(residual_mm(g, &mode.pose, rho));
        let branches = ik::solve(m, &mode.pose.p);
        if !branches.certificate.proved() {
            r.uncertified += 1;
            let p = mode.pose.p;
            fail(
                &mut r,
                format!("--pose={},{},{}: IK uncertified", p.x, p.y, p.z),
            );
        }
        let back = branches
            .iter()
            .filter(|b| wrap_angle(b.alpha - mode.pose.alpha).abs() < 1e-6)
            .map(|b| (b.rho - rho).amax())
            .fold(f64::INFINITY, f64::min);
        r.worst_fk_ik_mm = r.worst_fk_ik_mm.max(back);
        if back.is_nan() || back > RETURN_TOL_MM {
            r.fk_ik_misses += 1;
            let p = mode.pose.p;
            fail(
                &mut r,
                format!(
                    "--joints {},{},{}: mode at P = ({}, {}, {}) has no inverse branch back ({back:e} mm)",
                    rho.x, rho.y, rho.z, p.x, p.y, p.z
                ),
            );
        }
        for b in &branches {
            r.ik_branches += 1;
            let pose = ModulePose {
                p: mode.pose.p,
                alpha: b.alpha,
            };
            r.worst_residual_mm = r.worst_residual_mm.max(residual_mm(g, &pose, &b.rho));
            let fwd = fk::solve(m, &b.rho)
                .iter()
                .map(|f| {
                    (f.pose.p - pose.p)
                        .amax()
                        .max(wrap_angle(f.pose.alpha - pose.alpha).abs() * g.r_big2)
                })
                .fold(f64::INFINITY, f64::min);
            r.worst_ik_fk_mm = r.worst_ik_fk_mm.max(fwd);
            if fwd.is_nan() || fwd > RETURN_TOL_MM {
                r.ik_fk_misses += 1;
                fail(
                    &mut r,
                    format!(
                        "--joints {},{},{}: the pose ({}, {}, {}) of an inverse branch is not among its modes ({fwd:e} mm)",
                        b.rho.x, b.rho.y, b.rho.z, pose.p.x, pose.p.y, pose.p.z
                    ),
                );
            }
        }
    }
    r
}

/// Poses built on one degenerate set, both ways ([`hard_sets::check_fk`],
/// [`hard_sets::check_ik`]).
fn check_hard_set(m: &Machine, set: HardSet, seed: u64) -> SelftestReport {
    let mut rng = Sampler::new(0x5e1f_7e57 + seed);
    let mut t = hard_sets::check_fk(m, set, HARD_STARTS_PER_SET, &mut rng);
    t.add(hard_sets::check_ik(
        m,
        set,
        HARD_STARTS_PER_SET / 2,
        &mut rng,
    ));
    SelftestReport {
        hard_poses: t.poses,
        hard_misses: t.lost,
        uncertified: t.unproved,
        failures: t.examples.into_iter().take(FAILURES_KEPT).collect(),
        ..Default::default()
    }
}

fn merge(a: SelftestReport, b: SelftestReport) -> SelftestReport {
    let mut failures = a.failures;
    failures.extend(b.failures);
    failures.truncate(FAILURES_KEPT);
    SelftestReport {
        joint_sets: a.joint_sets + b.joint_sets,
        fk_modes: a.fk_modes + b.fk_modes,
        ik_branches: a.ik_branches + b.ik_branches,
        hard_poses: a.hard_poses + b.hard_poses,
        hard_misses: a.hard_misses + b.hard_misses,
        uncertified: a.uncertified + b.uncertified,
        worst_residual_mm: a.worst_residual_mm.max(b.worst_residual_mm),
        worst_fk_ik_mm: a.worst_fk_ik_mm.max(b.worst_fk_ik_mm),
        worst_ik_fk_mm: a.worst_ik_fk_mm.max(b.worst_ik_fk_mm),
        fk_ik_misses: a.fk_ik_misses + b.fk_ik_misses,
        ik_fk_misses: a.ik_fk_misses + b.ik_fk_misses,
        failures,
    }
}

impl SelftestReport {
    /// Why nothing could be tested, when that is the case: no assembly mode on the whole grid
    /// (the machine cannot be assembled with sliders within its strokes, or its dimensions
    /// overflow), or no pose could be built on any degenerate set.
    pub fn untested(&self) -> Option<&'static str> {
        if self.fk_modes == 0 {
            Some(
                "no assembly mode on the grid of joints: nothing could be tested (can the machine be assembled within its strokes?)",
            )
        } else if self.ik_branches == 0 {
            Some("no inverse branch of any assembly mode: nothing could be tested")
        } else if self.hard_poses == 0 {
            Some("no pose could be built on the solvers' degenerate sets")
        } else {
            None
        }
    }

    pub fn passed(&self) -> bool {
        self.untested().is_none()
            && self.fk_ik_misses == 0
            && self.ik_fk_misses == 0
            && self.hard_misses == 0
            && self.uncertified == 0
            && self.worst_residual_mm <= crate::tolerance::ACCEPT_RESIDUAL_MM
    }
}
