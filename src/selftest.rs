//! Self-test of a machine file: round trips of the parallel module's kinematics over a grid of
//! joints inside the strokes, reporting the worst residual (the check that finds wrong
//! kinematics modules: every forward mode must come back from the inverse, and every inverse
//! branch of that pose must satisfy eqs. (3)-(6) and come back from the forward kinematics).

use rayon::prelude::*;

use crate::machine::Machine;
use crate::module_fk;
use crate::module_geometry::{ModulePose, Sliders, residual_mm};
use crate::module_ik;

/// Results of a self-test.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SelftestReport {
    /// Joint sets tried.
    pub joint_sets: u64,
    /// Forward assembly modes found (all of them, working or not).
    pub fk_modes: u64,
    /// Inverse branches checked (all branches of every mode's pose).
    pub ik_branches: u64,
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
}

/// Round trips closer than this (mm) count as returning.
pub const RETURN_TOL_MM: f64 = 1e-6;

/// Runs the round trips on an n x n x n grid of joints spanning the strokes.
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
    joints
        .par_iter()
        .map(|rho| check_joints(m, rho))
        .reduce(SelftestReport::default, merge)
}

fn check_joints(m: &Machine, rho: &Sliders) -> SelftestReport {
    let g = &m.module;
    let mut r = SelftestReport {
        joint_sets: 1,
        ..Default::default()
    };
    for mode in module_fk::solve(m, rho) {
        r.fk_modes += 1;
        r.worst_residual_mm = r.worst_residual_mm.max(residual_mm(g, &mode.pose, rho));
        let branches = module_ik::solve(m, &mode.pose.p);
        let back = branches
            .iter()
            .filter(|b| (b.alpha - mode.pose.alpha).abs() < 1e-6)
            .map(|b| (b.rho - rho).amax())
            .fold(f64::INFINITY, f64::min);
        r.worst_fk_ik_mm = r.worst_fk_ik_mm.max(back);
        if back.is_nan() || back > RETURN_TOL_MM {
            r.fk_ik_misses += 1;
        }
        for b in &branches {
            r.ik_branches += 1;
            let pose = ModulePose {
                p: mode.pose.p,
                alpha: b.alpha,
            };
            r.worst_residual_mm = r.worst_residual_mm.max(residual_mm(g, &pose, &b.rho));
            let fwd = module_fk::solve(m, &b.rho)
                .iter()
                .map(|f| {
                    (f.pose.p - pose.p)
                        .amax()
                        .max((f.pose.alpha - pose.alpha).abs() * g.r_big2)
                })
                .fold(f64::INFINITY, f64::min);
            r.worst_ik_fk_mm = r.worst_ik_fk_mm.max(fwd);
            if fwd.is_nan() || fwd > RETURN_TOL_MM {
                r.ik_fk_misses += 1;
            }
        }
    }
    r
}

fn merge(a: SelftestReport, b: SelftestReport) -> SelftestReport {
    SelftestReport {
        joint_sets: a.joint_sets + b.joint_sets,
        fk_modes: a.fk_modes + b.fk_modes,
        ik_branches: a.ik_branches + b.ik_branches,
        worst_residual_mm: a.worst_residual_mm.max(b.worst_residual_mm),
        worst_fk_ik_mm: a.worst_fk_ik_mm.max(b.worst_fk_ik_mm),
        worst_ik_fk_mm: a.worst_ik_fk_mm.max(b.worst_ik_fk_mm),
        fk_ik_misses: a.fk_ik_misses + b.fk_ik_misses,
        ik_fk_misses: a.ik_fk_misses + b.ik_fk_misses,
    }
}

impl SelftestReport {
    pub fn passed(&self) -> bool {
        self.fk_ik_misses == 0
            && self.ik_fk_misses == 0
            && self.worst_residual_mm <= crate::tolerance::ACCEPT_RESIDUAL_MM
    }
}
