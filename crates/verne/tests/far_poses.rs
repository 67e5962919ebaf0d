//! Tool poses far beyond the machine (1e6 to 1e308 mm along each axis) have no branch with
//! their sliders within the strokes: the machine's inverse kinematics says so, proved (no
//! `uncertified`), however many digits its equation's coefficients would lose. The truth is
//! the geometry: with every slider within its stroke a rod of length L reaches at most L + R
//! from it, a few metres, and these poses are a thousand times farther at least. Platform
//! points that far keep the module's answer, every real branch, proved: none, or branches whose
//! sliders are outside their strokes.

use nalgebra::Vector3;
use verne::certificate::Certificate;
use verne::machine::{ToolPose, machine_ik};
use verne::parallel_module::ik::{self, IkBranches};
use verne::spec::Machine;

/// Distances from the origin along one axis (mm).
const FAR_MM: [f64; 4] = [1e6, 1e12, 1e100, 1e308];

/// The far points: each distance, both signs, along each axis, the other coordinates those of a
/// point inside the workspace.
fn far_points(inside: Vector3<f64>) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for v in FAR_MM {
        for d in 0..3 {
            for sign in [1.0, -1.0] {
                let mut p = inside;
                p[d] = sign * v;
                out.push(p);
            }
        }
    }
    out
}

#[test]
fn far_platform_points_have_proved_answers_and_no_usable_branch() {
    let m = Machine::default_verne();
    let points = far_points(Vector3::new(-240.0, -86.0, 1000.0));
    let check = |p: &Vector3<f64>, out: &IkBranches, what: &str| {
        assert_ne!(out.certificate, Certificate::Unproved, "{what} {p:?}");
        for b in out.iter() {
            assert!(!b.working(), "{what} {p:?}: working branch {b:?}");
            let outside =
                (0..3).any(|i| b.rho[i] < m.limits.rho_min[i] || b.rho[i] > m.limits.rho_max[i]);
            assert!(outside, "{what} {p:?}: branch within the strokes {b:?}");
        }
    };
    for p in &points {
        check(p, &ik::solve(&m, p), "solve");
        let mut working = IkBranches::new();
        ik::solve_working_into(&m, p, &mut working);
        check(p, &working, "solve_working_into");
    }
    // The batched kernels, four points side by side, say the same.
    for every in [true, false] {
        let mut outs: Vec<IkBranches> = points.iter().map(|_| IkBranches::new()).collect();
        let rows = points.iter().copied().zip(outs.iter_mut());
        if every {
            ik::solve_each(&m, rows);
        } else {
            ik::solve_working_each(&m, rows);
        }
        for (p, out) in points.iter().zip(&outs) {
            check(
                p,
                out,
                if every {
                    "solve_each"
                } else {
                    "solve_working_each"
                },
            );
        }
    }
}

#[test]
fn far_tool_poses_are_proved_unreachable() {
    let m = Machine::default_verne();
    for tip in far_points(Vector3::new(20.0, -30.0, 40.0)) {
        for (phi1, phi2) in [(0.0, 0.0), (0.3, 1.1), (-0.7, -2.5)] {
            for tool_length in [0.0, 50.0, 123.4] {
                let pose = ToolPose { tip, phi1, phi2 };
                let b = machine_ik(&m, &pose, tool_length);
                assert!(
                    b.is_empty(),
                    "{pose:?}, Delta {tool_length}: {} branches",
                    b.len()
                );
                assert_ne!(b.certificate, Certificate::Unproved, "{pose:?}");
            }
        }
    }
}
