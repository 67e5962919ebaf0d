//! Workspace invariants: every inside point round-trips through the forward kinematics, the
//! points just outside fail the constraint named binding (checked from the rod geometry, not
//! from the classifier), the volume converges as the step halves, the result does not depend on
//! the thread count (the pictures and the command: crates/verne-cli/tests/cli_workspace.rs).

use nalgebra::Vector3;
use verne::parallel_module::branches::WORKING_CONFIG;
use verne::parallel_module::equations::{ModulePose, rod_vectors};
use verne::parallel_module::fk;
use verne::parallel_module::ik;
use verne::parallel_module::kinetostatics::kinetostatics;
use verne::spec::Machine;
use verne::workspace::{
    self, Bounds, Constraint, Of, Outcome, PAPER_LAMBDA_BOUNDS, PointResult, Workspace,
    WorkspaceOptions,
};

/// FK pose against the pose the workspace reported (mm; rad for alpha).
const ROUND_TRIP_MM: f64 = 1e-6;
const ROUND_TRIP_RAD: f64 = 1e-9;

fn options(of: Of, tool_length: f64, step: f64) -> WorkspaceOptions {
    WorkspaceOptions {
        of,
        tool_length,
        step,
        bounds: None,
        lambda: PAPER_LAMBDA_BOUNDS,
    }
}

fn run(m: &Machine, opts: &WorkspaceOptions) -> (Workspace, Vec<PointResult>) {
    let mut points = Vec::new();
    let ws = workspace::compute::<()>(m, opts, &|_| {}, |r| {
        points.push(*r);
        Ok(())
    })
    .unwrap()
    .unwrap();
    (ws, points)
}

#[test]
fn every_inside_point_round_trips_through_the_forward_kinematics() {
    let m = Machine::default_verne();
    for (of, delta, step) in [
        (Of::Platform, 0.0, 40.0),
        (Of::Tool, 100.0, 40.0),
        (Of::Manufacturing, 50.0, 50.0),
    ] {
        let (ws, points) = run(&m, &options(of, delta, step));
        assert!(ws.summary.inside > 100, "{of:?}: {}", ws.summary.inside);
        for r in points.iter().filter(|r| r.outcome == Outcome::Inside) {
            let b = r.branch.unwrap();
            let modes = fk::solve(&m, &b.rho);
            let found = modes.iter().find(|md| {
                md.config == WORKING_CONFIG
                    && (md.pose.p - b.pose.p).amax() < ROUND_TRIP_MM
                    && (md.pose.alpha - b.pose.alpha).abs() < ROUND_TRIP_RAD
            });
            let md = found.unwrap_or_else(|| {
                panic!(
                    "{of:?} {}: rho {} not returned by FK: {modes:?}",
                    r.q, b.rho
                )
            });
            // The FK pose gives back the grid point through eq. (27) or eq. (26).
            let q = workspace::grid_point_of(&m, of, delta, &md.pose.p, md.pose.alpha);
            assert!((q - r.q).amax() < ROUND_TRIP_MM, "{of:?}: {q} vs {}", r.q);
            // And the machine's own choice of assembly mode is that pose.
            let w = fk::working(&modes).unwrap();
            assert!((w.pose.p - b.pose.p).amax() < ROUND_TRIP_MM);
        }
    }
}

/// Whether the branch (pose, rho) fails constraint `c`, from the rod geometry directly.
fn fails(
    m: &Machine,
    of: Of,
    pose: &ModulePose,
    rho: &nalgebra::Vector3<f64>,
    c: Constraint,
) -> bool {
    let g = &m.module;
    let slack = 1e-9;
    match c {
        Constraint::RodsCross => g.r_big1 * pose.alpha.cos() <= g.r_small1,
        Constraint::RodTilt => rod_vectors(g, pose, rho)
            .iter()
            .any(|v| (v.z / v.norm()).acos() > m.limits.rod_tilt_max + slack),
        Constraint::Singularity => !kinetostatics(g, pose, rho)
            .amplification_within(PAPER_LAMBDA_BOUNDS[0], PAPER_LAMBDA_BOUNDS[1]),
        Constraint::Stroke => (0..3)
            .any(|i| rho[i] < m.limits.rho_min[i] - slack || rho[i] > m.limits.rho_max[i] + slack),
        Constraint::Theta1Range => {
            of == Of::Manufacturing
                && (pose.alpha < m.limits.theta1_min - slack
                    || pose.alpha > m.limits.theta1_max + slack)
        }
    }
}

#[test]
fn points_just_outside_fail_the_constraint_named_binding() {
    let m = Machine::default_verne();
    for (of, delta, step) in [
        (Of::Platform, 0.0, 30.0),
        (Of::Tool, 150.0, 40.0),
        (Of::Manufacturing, 50.0, 40.0),
    ] {
        let (ws, points) = run(&m, &options(of, delta, step));
        let g = ws.map.grid;
        let mut boundary = 0;
        let mut seen = std::collections::HashSet::new();
        for k in 0..g.n[2] {
            for j in 0..g.n[1] {
                for i in 0..g.n[0] {
                    let r = &points[g.index(i, j, k)];
                    if r.outcome == Outcome::Inside {
                        continue;
                    }
                    let near_inside = [
                        (1i64, 0i64, 0i64),
                        (-1, 0, 0),
                        (0, 1, 0),
                        (0, -1, 0),
                        (0, 0, 1),
                        (0, 0, -1),
                    ]
                    .iter()
                    .any(|&(di, dj, dk)| {
                        let (a, b, c) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                        a >= 0
                            && b >= 0
                            && c >= 0
                            && (a as usize) < g.n[0]
                            && (b as usize) < g.n[1]
                            && (c as usize) < g.n[2]
                            && ws.map.at(a as usize, b as usize, c as usize) == Outcome::Inside
                    });
                    if !near_inside {
                        continue;
                    }
                    boundary += 1;
                    let Outcome::Bound(c) = r.outcome else {
                        // Out of reach next to an inside point: no s=(-1,-1,-1) branch at P
                        // (platform: P is the grid point itself).
                        if of == Of::Platform {
                            assert!(
                                ik::solve(&m, &r.q)
                                    .iter()
                                    .all(|b| b.config != WORKING_CONFIG)
                            );
                        }
                        continue;
                    };
                    seen.insert(c);
                    let b = r.branch.unwrap();
                    // The reported branch is a real s=(-1,-1,-1) IK branch of its P ...
                    let ik = ik::solve(&m, &b.pose.p);
                    let same = ik.iter().find(|x| {
                        x.config == WORKING_CONFIG
                            && (x.alpha - b.pose.alpha).abs() < 1e-9
                            && (x.rho - b.rho).amax() < 1e-6
                    });
                    assert!(same.is_some(), "{of:?} {}: branch not an IK branch", r.q);
                    // ... whose grid point is this one ...
                    let q = workspace::grid_point_of(&m, of, delta, &b.pose.p, b.pose.alpha);
                    assert!((q - r.q).amax() < 1e-6);
                    // ... and which fails the binding constraint, and none before it.
                    assert!(
                        fails(&m, of, &b.pose, &b.rho, c),
                        "{of:?} {}: does not fail {c:?}",
                        r.q
                    );
                    for earlier in Constraint::ALL.iter().take_while(|&&x| x != c) {
                        assert!(
                            !fails(&m, of, &b.pose, &b.rho, *earlier),
                            "{of:?} {}: fails {earlier:?} before {c:?}",
                            r.q
                        );
                    }
                    // For the platform, no s=(-1,-1,-1) branch of P satisfies every constraint.
                    if of == Of::Platform {
                        for x in ik.iter().filter(|x| x.config == WORKING_CONFIG) {
                            let pose = ModulePose {
                                p: r.q,
                                alpha: x.alpha,
                            };
                            assert!(
                                Constraint::ALL
                                    .iter()
                                    .any(|&c| fails(&m, of, &pose, &x.rho, c))
                            );
                        }
                    }
                }
            }
        }
        assert!(boundary > 50, "{of:?}: {boundary} boundary points");
        assert!(!seen.is_empty());
    }
}

#[test]
fn volume_converges_as_the_step_halves() {
    let m = Machine::default_verne();
    // A fixed box around the platform workspace, its edges multiples of every step.
    let bounds = Bounds {
        min: Vector3::new(-420.0, -480.0, 780.0),
        max: Vector3::new(540.0, 480.0, 1980.0),
    };
    let vols: Vec<f64> = [60.0, 30.0, 15.0]
        .iter()
        .map(|&h| {
            let opts = WorkspaceOptions {
                bounds: Some(bounds),
                ..options(Of::Platform, 0.0, h)
            };
            let (ws, _) = run(&m, &opts);
            assert!(!ws.summary.touches_bounds);
            ws.summary.volume_mm3
        })
        .collect();
    let d1 = (vols[1] - vols[0]).abs();
    let d2 = (vols[2] - vols[1]).abs();
    eprintln!("volumes {vols:?} mm^3, differences {d1} then {d2}");
    assert!(d2 < d1, "{vols:?}");
    assert!(d2 < 0.01 * vols[2], "{vols:?}");
}

#[test]
fn the_summary_does_not_depend_on_the_thread_count() {
    let m = Machine::default_verne();
    let opts = options(Of::Manufacturing, 50.0, 40.0);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run(&m, &opts))
    };
    let (a, pa) = on(1);
    let (b, pb) = on(2);
    assert_eq!(a.summary, b.summary);
    assert_eq!(a.map, b.map);
    assert_eq!(pa, pb);
}

#[test]
fn a_zero_length_tool_has_the_platform_workspace() {
    let m = Machine::default_verne();
    let (p, _) = run(&m, &options(Of::Platform, 0.0, 40.0));
    let (t, _) = run(&m, &options(Of::Tool, 0.0, 40.0));
    assert_eq!(p.map.outcome, t.map.outcome);
    assert_eq!(p.summary.volume_mm3, t.summary.volume_mm3);
}

// ---------------------------------------------------------------------------------------------
// Adaptive sampling (workspace/adaptive.rs) against the uniform grid at the same step: the
// same inside points (the estimator the volume is made of), the volume inside the adaptive
// run's own bracket, and far fewer points classified at a fine step.

fn compare(m: &Machine, opts: &WorkspaceOptions, factor: usize) -> (u64, u64) {
    let run = workspace::compute(m, opts, &|_| {}, |_| Ok::<(), ()>(()))
        .unwrap()
        .unwrap();
    let (uniform, uniform_map) = (run.summary, run.map);
    // The largest box and cube grown from the coarse lattice's (as on fine lattices), and
    // searched exhaustively (as on these small ones).
    let adaptive = workspace::compute_adaptive_with(m, opts, factor, 0, &|_| {}).unwrap();
    let exact = workspace::compute_adaptive(m, opts, factor, &|_| {}).unwrap();
    assert!(!adaptive.box_exact && exact.box_exact);
    assert_eq!(adaptive.box_lattice_step, opts.step * factor as f64);
    // And from the lattice of every (factor / 2)-th point of the inside points' box too: a
    // limit that admits it (twice the limit) and not the fine lattice.
    let bb = adaptive.bbox.unwrap();
    let half = factor / 2;
    let limit: u64 = [0, 1, 2]
        .map(|d| ((bb.max[d] - bb.min[d]) / opts.step).round() as usize)
        .iter()
        .map(|&e| e.div_ceil(half) as u64 + 1)
        .product::<u64>()
        .div_ceil(2);
    let middle = workspace::compute_adaptive_with(m, opts, factor, limit, &|_| {}).unwrap();
    assert!(!middle.box_exact);
    assert_eq!(middle.box_lattice_step, opts.step * half as f64);
    assert!(middle.largest_box_mm3 >= adaptive.largest_box_mm3);
    assert!(middle.largest_box_upper_mm3 <= adaptive.largest_box_upper_mm3);
    assert!(middle.largest_cube_mm3 >= adaptive.largest_cube_mm3);
    assert!(middle.largest_cube_upper_mm3 <= adaptive.largest_cube_upper_mm3);
    let name = format!(
        "{} {} mm, tool {} mm",
        opts.of.name(),
        opts.step,
        opts.tool_length
    );
    assert!(uniform.inside > 100, "{name}: a workspace to compare");
    assert!(
        !uniform.touches_bounds,
        "{name}: the bounds hold the workspace"
    );
    assert_eq!(
        adaptive.inside_points, uniform.inside,
        "{name}: inside points"
    );
    assert!((adaptive.volume_mm3 - uniform.volume_mm3).abs() < 1e-6 * uniform.volume_mm3);
    assert!(
        adaptive.volume_lo_mm3 <= adaptive.volume_mm3
            && adaptive.volume_mm3 <= adaptive.volume_hi_mm3,
        "{name}: {} not in [{}, {}]",
        adaptive.volume_mm3,
        adaptive.volume_lo_mm3,
        adaptive.volume_hi_mm3
    );
    assert_eq!(adaptive.binding[0], uniform.inside);
    // The largest box: the one found is a box of the grid all inside, so no larger than the
    // uniform grid's (exhaustive) largest box, and that is within the bound.
    let (_, best) = uniform.largest_box_size().unwrap();
    let found = adaptive.largest_box.unwrap();
    let g = uniform.grid;
    let grid_box =
        |p: Vector3<f64>| [0, 1, 2].map(|d| ((p[d] - g.origin[d]) / g.step).round() as usize);
    // Every grid point of `b` (mm) is inside on the uniform grid; its index box.
    let all_inside = |b: &Bounds, what: &str| {
        let (lo, hi) = (grid_box(b.min), grid_box(b.max));
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    assert_eq!(
                        uniform_map.at(i, j, k),
                        Outcome::Inside,
                        "{name}: the largest {what} {b:?} holds a point outside"
                    );
                }
            }
        }
        (lo, hi)
    };
    all_inside(&found, "box");
    // The same for the largest cube.
    let (_, best_cube) = uniform.largest_cube_size().unwrap();
    let cube = adaptive.largest_cube.unwrap();
    let (lo, hi) = all_inside(&cube, "cube");
    assert!(
        hi[0] - lo[0] == hi[1] - lo[1] && hi[1] - lo[1] == hi[2] - lo[2],
        "{name}: a cube"
    );
    assert!(
        adaptive.largest_cube_mm3 <= best_cube * (1.0 + 1e-12)
            && best_cube <= adaptive.largest_cube_upper_mm3 * (1.0 + 1e-12),
        "{name}: cube found {} <= uniform {best_cube} <= bound {}",
        adaptive.largest_cube_mm3,
        adaptive.largest_cube_upper_mm3
    );
    assert!(
        adaptive.largest_box_mm3 <= best * (1.0 + 1e-12)
            && best <= adaptive.largest_box_upper_mm3 * (1.0 + 1e-12),
        "{name}: found {} <= uniform {best} <= bound {}",
        adaptive.largest_box_mm3,
        adaptive.largest_box_upper_mm3
    );
    all_inside(&middle.largest_box.unwrap(), "box (middle lattice)");
    all_inside(&middle.largest_cube.unwrap(), "cube (middle lattice)");
    assert!(
        middle.largest_box_mm3 <= best * (1.0 + 1e-12)
            && best <= middle.largest_box_upper_mm3 * (1.0 + 1e-12)
            && middle.largest_cube_mm3 <= best_cube * (1.0 + 1e-12)
            && best_cube <= middle.largest_cube_upper_mm3 * (1.0 + 1e-12),
        "{name}: middle lattice {middle:?}"
    );
    // The exhaustive search finds the uniform grid's box and cube, with the bounds equal.
    let (uniform_box, _) = uniform.largest_box_size().unwrap();
    let (uniform_cube, _) = uniform.largest_cube_size().unwrap();
    let close = |a: Bounds, b: Bounds| (a.min - b.min).norm() + (a.max - b.max).norm() < 1e-9;
    assert!(
        close(exact.largest_box.unwrap(), uniform_box),
        "{name}: exact box"
    );
    assert!(
        close(exact.largest_cube.unwrap(), uniform_cube),
        "{name}: exact cube"
    );
    assert!((exact.largest_box_mm3 - best).abs() <= 1e-9 * best);
    assert!((exact.largest_cube_mm3 - best_cube).abs() <= 1e-9 * best_cube);
    assert_eq!(exact.largest_box_upper_mm3, exact.largest_box_mm3);
    assert_eq!(exact.largest_cube_upper_mm3, exact.largest_cube_mm3);
    assert_eq!(
        (exact.inside_points, exact.classified),
        (adaptive.inside_points, adaptive.classified)
    );
    let (ub, ab) = (uniform.bbox.unwrap(), adaptive.bbox.unwrap());
    assert!(
        (ub.min - ab.min).norm() < 1e-9 && (ub.max - ab.max).norm() < 1e-9,
        "{name}: bbox"
    );
    (adaptive.classified, uniform.points)
}

#[test]
fn adaptive_equals_uniform_on_the_default_machine() {
    let m = Machine::default_verne();
    compare(&m, &options(Of::Platform, 0.0, 20.0), 8);
    compare(&m, &options(Of::Tool, 100.0, 25.0), 4);
    // At 10 mm the boundary is already a small part of the volume.
    let (classified, points) = compare(&m, &options(Of::Platform, 0.0, 10.0), 8);
    assert!(
        classified * 4 < points,
        "{classified} classified for {points} grid points"
    );
}

#[test]
fn adaptive_equals_uniform_on_other_machines() {
    // A shorter leg I and narrower strokes: a different shape.
    let text = verne::spec::DEFAULT_MACHINE_TOML
        .replace("L1 = 850.0", "L1 = 700.0")
        .replace("rho2_max = 1100.0", "rho2_max = 800.0");
    let m = Machine::from_toml_str(&text, "other").unwrap();
    compare(&m, &options(Of::Platform, 0.0, 25.0), 8);
}

#[test]
fn bad_options_are_refused() {
    let m = Machine::default_verne();
    let o = options(Of::Platform, 0.0, 10.0);
    assert!(workspace::compute_adaptive(&m, &o, 3, &|_| {}).is_err());
    assert!(
        workspace::compute_adaptive(&m, &options(Of::Platform, 0.0, -1.0), 8, &|_| {}).is_err()
    );
    assert!(
        workspace::compute_adaptive(&m, &options(Of::Platform, 0.0, 1e-9), 8, &|_| {}).is_err()
    );
}

/// The boundary cells' sample (workspace/adaptive.rs): its estimate inside the bracket and its
/// interval narrower, at two steps; and the finer estimate against an independent slow method,
/// points drawn uniformly in the whole box and classified one by one (no cell, no assumption
/// that a cell with agreeing corners is all inside or all outside).
#[test]
fn the_sampled_volume_agrees_with_uniform_random_points() {
    let m = Machine::default_verne();
    let coarse =
        workspace::compute_adaptive(&m, &options(Of::Platform, 0.0, 20.0), 8, &|_| {}).unwrap();
    let fine =
        workspace::compute_adaptive(&m, &options(Of::Platform, 0.0, 5.0), 8, &|_| {}).unwrap();
    for a in [&coarse, &fine] {
        let name = format!("{} mm", a.step);
        assert!(
            a.sampled_cells > 1000 && a.sampled_cells <= a.boundary_cells,
            "{name}: {} of {} boundary cells sampled",
            a.sampled_cells,
            a.boundary_cells
        );
        assert!(
            a.volume_lo_mm3 <= a.volume_sampled_mm3 && a.volume_sampled_mm3 <= a.volume_hi_mm3,
            "{name}: the estimate is in the bracket"
        );
        assert!(
            a.sampled_half_width_mm3 > 0.0 && a.sampled_half_width_mm3 < 0.1 * a.error_bound_mm3(),
            "{name}: half-width {} against the bracket's {}",
            a.sampled_half_width_mm3,
            a.error_bound_mm3()
        );
    }
    let (c, f) = (&coarse, &fine);
    assert!(
        (c.volume_sampled_mm3 - f.volume_sampled_mm3).abs()
            <= c.sampled_half_width_mm3 + f.sampled_half_width_mm3,
        "20 mm: {} +- {}, 5 mm: {} +- {}",
        c.volume_sampled_mm3,
        c.sampled_half_width_mm3,
        f.volume_sampled_mm3,
        f.sampled_half_width_mm3
    );
    // 400,000 points uniform in the default box (a fixed LCG), each classified.
    let opts = options(Of::Platform, 0.0, 5.0);
    let b = workspace::default_bounds(&m, Of::Platform, 0.0);
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let n = 400_000u64;
    let mut inside = 0u64;
    for _ in 0..n {
        let p =
            b.min + (b.max - b.min).component_mul(&nalgebra::Vector3::new(next(), next(), next()));
        if workspace::classify(&m, &opts, &p).outcome == Outcome::Inside {
            inside += 1;
        }
    }
    let box_mm3 = (b.max - b.min).product();
    let mc = inside as f64 / n as f64 * box_mm3;
    let delta = workspace::SAMPLED_CONFIDENCE_DELTA;
    let mc_half = ((2.0 / delta).ln() / (2.0 * n as f64)).sqrt() * box_mm3;
    assert!(
        (f.volume_sampled_mm3 - mc).abs() <= f.sampled_half_width_mm3 + mc_half,
        "5 mm: {} +- {}, random points: {mc} +- {mc_half}",
        f.volume_sampled_mm3,
        f.sampled_half_width_mm3
    );
}
