//! The workspace is continuous in every machine parameter. A small change of a parameter moves
//! the workspace's boundary by a small distance, so between two nearby machines only grid points
//! next to the boundary may change sides, the volume changes by at most the boundary layer, and
//! the largest box shrinks by at most a grid step on each face. On a symmetry plane (y = 0) a
//! grid point has the classification of its neighbours at y = +-epsilon. None of this is
//! computed by the classifier itself: the truths are the grid's neighbourhoods and the points
//! just off the plane.

use nalgebra::Vector3;
use verne::spec::Machine;
use verne::workspace::{
    self, Bounds, Of, Outcome, PAPER_LAMBDA_BOUNDS, Workspace, WorkspaceOptions,
};

/// Grid step of the sweeps (mm): coarse, so that the test runs in seconds.
const STEP_MM: f64 = 60.0;

/// Tool lengths of the fine sweep: FIRST_TOOL_LENGTH_MM + k TOOL_LENGTH_STEP_MM, k < 50 (mm).
/// A change of Delta moves the tool tip by at most that much, far less than a grid step.
const FIRST_TOOL_LENGTH_MM: f64 = 12.3456;
const TOOL_LENGTH_STEP_MM: f64 = 0.7;
const TOOL_LENGTHS: usize = 50;

/// Tool length of the parameter sweeps (mm), not a round number.
const SWEEP_TOOL_LENGTH_MM: f64 = 37.891;

/// Distances off the plane y = 0 (mm) at which a point must be classified as on the plane.
const SYMMETRY_EPS_MM: [f64; 2] = [1e-9, 1e-6];

fn options(of: Of, tool_length: f64, bounds: Bounds) -> WorkspaceOptions {
    WorkspaceOptions {
        of,
        tool_length,
        step: STEP_MM,
        bounds: Some(bounds),
        lambda: PAPER_LAMBDA_BOUNDS,
    }
}

fn run(m: &Machine, opts: &WorkspaceOptions) -> Workspace {
    workspace::compute::<()>(m, opts, &|_| {}, |_| Ok(()))
        .unwrap()
        .unwrap()
}

/// One box holding the default boxes of every machine of a sweep, one step wider on each side,
/// on multiples of the step (so that y = 0 is a grid plane).
fn common_bounds(machines: &[Machine], of: Of, tool_length: f64) -> Bounds {
    let mut b = workspace::default_bounds(&machines[0], of, tool_length);
    for m in machines {
        let d = workspace::default_bounds(m, of, tool_length);
        b.min = b.min.inf(&d.min);
        b.max = b.max.sup(&d.max);
    }
    b.min -= Vector3::repeat(STEP_MM);
    b.max += Vector3::repeat(STEP_MM);
    workspace::round_bounds(&b, STEP_MM)
}

fn inside(ws: &Workspace, i: usize, j: usize, k: usize) -> bool {
    ws.map.at(i, j, k) == Outcome::Inside
}

/// A grid point with a neighbour (of the 26) on the other side of the boundary.
fn on_boundary(ws: &Workspace, i: usize, j: usize, k: usize) -> bool {
    let n = ws.map.grid.n;
    let here = inside(ws, i, j, k);
    for dk in -1i64..=1 {
        for dj in -1i64..=1 {
            for di in -1i64..=1 {
                let (a, b, c) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                if a < 0 || b < 0 || c < 0 {
                    continue;
                }
                let (a, b, c) = (a as usize, b as usize, c as usize);
                if a < n[0] && b < n[1] && c < n[2] && inside(ws, a, b, c) != here {
                    return true;
                }
            }
        }
    }
    false
}

/// Volume (mm^3) of the largest box of `ws` with one grid step taken off each face.
fn shrunk_box_mm3(ws: &Workspace) -> f64 {
    ws.summary.largest_box.map_or(0.0, |b| {
        b.edges()
            .iter()
            .map(|&e| e.saturating_sub(2) as f64 * STEP_MM)
            .product()
    })
}

fn box_mm3(ws: &Workspace) -> f64 {
    ws.summary.largest_box_size().map_or(0.0, |(_, v)| v)
}

/// The two workspaces of nearby machines differ only where the boundary passes: a grid point
/// that changes sides has the boundary within less than a step in both, so a neighbour on the
/// other side in each; and each one's largest box is at least the other's with a grid step off
/// each face.
fn assert_continuous(label: &str, a: &Workspace, b: &Workspace) {
    let grid = a.map.grid;
    assert_eq!(grid, b.map.grid, "{label}: the sweep uses one grid");
    let mut jumps = Vec::new();
    for k in 0..grid.n[2] {
        for j in 0..grid.n[1] {
            for i in 0..grid.n[0] {
                if inside(a, i, j, k) != inside(b, i, j, k)
                    && !(on_boundary(a, i, j, k) && on_boundary(b, i, j, k))
                {
                    let q = grid.point(i, j, k);
                    jumps.push((q.x, q.y, q.z));
                }
            }
        }
    }
    assert!(
        jumps.is_empty(),
        "{label}: {} grid points not on the boundary of both change sides (volumes {:.3} l and \
         {:.3} l), the first {:?}",
        jumps.len(),
        a.summary.volume_litres(),
        b.summary.volume_litres(),
        &jumps[..jumps.len().min(4)]
    );
    for (x, y) in [(a, b), (b, a)] {
        assert!(
            box_mm3(y) >= shrunk_box_mm3(x),
            "{label}: largest box {:.3} l against {:.3} l (boxes {:?} and {:?})",
            box_mm3(y) * 1e-6,
            box_mm3(x) * 1e-6,
            y.summary.largest_box_size(),
            x.summary.largest_box_size()
        );
    }
}

/// Every grid point on the plane y = 0 is classified as its neighbours at y = +-epsilon.
fn assert_symmetry_plane(label: &str, m: &Machine, opts: &WorkspaceOptions, ws: &Workspace) {
    let grid = ws.map.grid;
    let j0 = (-grid.origin.y / grid.step).round() as usize;
    assert_eq!(grid.coord(1, j0), 0.0, "{label}: y = 0 is a grid plane");
    let mut checked = 0;
    for k in 0..grid.n[2] {
        for i in 0..grid.n[0] {
            let q = grid.point(i, j0, k);
            let here = ws.map.at(i, j0, k);
            for eps in SYMMETRY_EPS_MM {
                for side in [-eps, eps] {
                    let off = workspace::classify(m, opts, &(q + Vector3::new(0.0, side, 0.0)));
                    assert_eq!(
                        off.outcome, here,
                        "{label}: ({}, 0, {}) is {here:?}, at y = {side} mm {:?}",
                        q.x, q.z, off.outcome
                    );
                }
            }
            checked += usize::from(here == Outcome::Inside);
        }
    }
    assert!(
        checked > 50,
        "{label}: only {checked} points inside on y = 0"
    );
}

/// Workspaces of the machines of a sweep, each compared with the next and checked on y = 0.
fn assert_sweep_continuous(label: &str, of: Of, tool_length: f64, machines: &[(String, Machine)]) {
    let ms: Vec<Machine> = machines.iter().map(|(_, m)| m.clone()).collect();
    let bounds = common_bounds(&ms, of, tool_length);
    let opts = options(of, tool_length, bounds);
    let mut prev: Option<(String, Workspace)> = None;
    for (name, m) in machines {
        let ws = run(m, &opts);
        assert!(
            ws.summary.inside > 1000,
            "{label} {name}: {}",
            ws.summary.inside
        );
        assert_symmetry_plane(&format!("{label} {name}"), m, &opts, &ws);
        if let Some((pname, pws)) = &prev {
            assert_continuous(&format!("{label}: {pname} -> {name}"), pws, &ws);
        }
        prev = Some((name.clone(), ws));
    }
}

#[test]
fn the_tool_workspace_is_continuous_in_the_tool_length() {
    let m = Machine::default_verne();
    let lengths: Vec<f64> = std::iter::once(12.345)
        .chain((0..TOOL_LENGTHS).map(|k| FIRST_TOOL_LENGTH_MM + k as f64 * TOOL_LENGTH_STEP_MM))
        .collect();
    let last = *lengths.last().unwrap();
    let bounds = common_bounds(std::slice::from_ref(&m), Of::Tool, last);
    let mut prev: Option<(f64, Workspace)> = None;
    for &delta in &lengths {
        let opts = options(Of::Tool, delta, bounds);
        let ws = run(&m, &opts);
        assert_symmetry_plane(&format!("tool, Delta = {delta} mm"), &m, &opts, &ws);
        if let Some((pd, pws)) = &prev {
            assert_continuous(&format!("tool, Delta {pd} -> {delta} mm"), pws, &ws);
        }
        prev = Some((delta, ws));
    }
}

#[test]
fn the_manufacturing_workspace_is_continuous_in_the_tool_length() {
    let m = Machine::default_verne();
    let lengths: Vec<f64> = (0..TOOL_LENGTHS / 5)
        .map(|k| 41.2345 + k as f64 * TOOL_LENGTH_STEP_MM)
        .collect();
    let bounds = common_bounds(std::slice::from_ref(&m), Of::Manufacturing, lengths[0]);
    let mut prev: Option<(f64, Workspace)> = None;
    for &delta in &lengths {
        let opts = options(Of::Manufacturing, delta, bounds);
        let ws = run(&m, &opts);
        assert_symmetry_plane(
            &format!("manufacturing, Delta = {delta} mm"),
            &m,
            &opts,
            &ws,
        );
        if let Some((pd, pws)) = &prev {
            assert_continuous(
                &format!("manufacturing, Delta {pd} -> {delta} mm"),
                pws,
                &ws,
            );
        }
        prev = Some((delta, ws));
    }
}

/// A machine parameter, how to set it, and its increment (mm or rad): small enough that the
/// boundary moves by a fraction of a grid step.
type Param = (&'static str, fn(&mut Machine, f64), f64);

/// The sweep of one parameter: three increments from its default value plus a non-round offset.
fn sweep(m: &Machine, (name, set, inc): Param, get: f64) -> Vec<(String, Machine)> {
    (0..4)
        .map(|k| {
            let v = get + 0.123 * inc + k as f64 * inc;
            let mut mk = m.clone();
            set(&mut mk, v);
            (format!("{name} = {v}"), mk)
        })
        .collect()
}

#[test]
fn the_workspaces_are_continuous_in_the_machine_parameters() {
    let m = Machine::default_verne();
    let g = m.module;
    let lim = m.limits;
    let mm = 0.731;
    let rad = 0.00087;
    let module_params: [(Param, f64); 12] = [
        (("module.D1-d1", |m, v| m.module.dx1 = v, mm), g.dx1),
        (("module.R1", |m, v| m.module.r_big1 = v, mm), g.r_big1),
        (("module.r1", |m, v| m.module.r_small1 = v, mm), g.r_small1),
        (("module.L1", |m, v| m.module.l1 = v, mm), g.l1),
        (("module.D2-d2", |m, v| m.module.dx2 = v, mm), g.dx2),
        (("module.R2", |m, v| m.module.r_big2 = v, mm), g.r_big2),
        (("module.r4", |m, v| m.module.r4 = v, mm), g.r4),
        (("module.L2", |m, v| m.module.l2 = v, mm), g.l2),
        (("module.L3", |m, v| m.module.l3 = v, mm), g.l3),
        (
            (
                "limits.rod_tilt_max",
                |m, v| {
                    m.limits.rod_tilt_max = v;
                    m.limits.cos_rod_tilt_max = (v + verne::tolerance::LIMIT_SLACK).cos();
                },
                rad,
            ),
            lim.rod_tilt_max,
        ),
        (
            ("limits.rho1_max", |m, v| m.limits.rho_max[0] = v, mm),
            lim.rho_max[0],
        ),
        (
            ("limits.rho2_min", |m, v| m.limits.rho_min[1] = v, mm),
            lim.rho_min[1],
        ),
    ];
    for (param, value) in module_params {
        let machines = sweep(&m, param, value);
        assert_sweep_continuous("tool", Of::Tool, SWEEP_TOOL_LENGTH_MM, &machines);
    }
    let table_params: [(Param, f64); 4] = [
        (("table.d_a", |m, v| m.table.d_a = v, mm), m.table.d_a),
        (("table.d_t", |m, v| m.table.d_t = v, mm), m.table.d_t),
        (("module.R1", |m, v| m.module.r_big1 = v, mm), g.r_big1),
        (
            ("limits.theta1_max", |m, v| m.limits.theta1_max = v, rad),
            lim.theta1_max,
        ),
    ];
    for (param, value) in table_params {
        let machines = sweep(&m, param, value);
        assert_sweep_continuous(
            "manufacturing",
            Of::Manufacturing,
            SWEEP_TOOL_LENGTH_MM,
            &machines,
        );
    }
}
