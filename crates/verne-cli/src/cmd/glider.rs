//! The glider mechanisms (`-m biglide1|biglide2|orthoglide` or a `kind = "glider"` file) under
//! the row commands of the VERNE machine (`ik`, `fk`, `modes`), and the glider workspace that
//! `verne workspace` calls. Conventions and column contracts: docs/gliders.md.
//!
//! The row jobs are in [`crate::engine::glider_rows`]; what makes a solution `ok` (working mode
//! `++`, assembly mode `+`, inside the joint ranges, not singular) in [`verne::glider::verdict`](mod@verne::glider::verdict).

use std::fmt::Write as _;
use std::path::Path;

use csv::ByteRecord;
use nalgebra::{Point2, Vector2};
use verne::glider::jacobian::singular_values_2x2;
use verne::glider::{
    ForwardKinematics, GliderSpec, NodeClass, PAPER_LAMBDA_BOUNDS, Rectangle, WorkspaceGrid,
    WorkspaceOptions, amplification, branch_label, det_a, det_b, forward_kinematics,
    inverse_kinematics, inverse_kinematics_in_mode, is_parallel_singular, is_serial_singular,
    jacobians, largest_rectangle, largest_square, mode_label, sample_workspace, verdict,
};

use super::{EXIT_OK, EXIT_ROWS_FAILED, run_rows, units, write_stdout};
use crate::cli::{FkArgs, IkArgs, ModesArgs};
use crate::engine::glider_rows::{GliderFk, GliderIk, MAX_STRUCTURAL_REPORTS};
use crate::engine::pipeline::{Cell, Units, write_cell};
use crate::error::VerneError;
use crate::table::{CsvSource, Sink};

/// Decimals of the aligned tables of `verne modes` (unless `--precision`).
const TABLE_DECIMALS: usize = 6;

/// Default grid nodes along the longer side of the workspace window.
pub const WORKSPACE_DEFAULT_NODES: usize = 801;

/// Most grid nodes along one side of a workspace (memory: 2 bytes per node).
pub const WORKSPACE_MAX_NODES: usize = 10_001;

/// Width of the SVG picture in pixels.
const PLOT_WIDTH_PX: f64 = 800.0;

/// The rows of `--pose X,Y,0` / `--joints R1,R2,0` as an in-memory CSV with `header`; the third
/// value of a planar mechanism must be 0.
fn inline_planar(header: &str, flag: &str, rows: &[[f64; 3]]) -> Result<CsvSource, VerneError> {
    let mut text = format!("{header}\n");
    for r in rows {
        if r[2] != 0.0 {
            return Err(VerneError::Usage(format!(
                "{flag} {},{},{}: a glider is planar; give {flag} A,B,0 (the third value must be \
                 0, found {})",
                r[0], r[1], r[2], r[2]
            )));
        }
        text.push_str(&format!("{},{}\n", r[0], r[1]));
    }
    CsvSource::from_reader(
        Box::new(std::io::Cursor::new(text.into_bytes())),
        "<command line>",
    )
}

/// The glider named by `-m`: a preset name (when no file of that name exists) or a file whose
/// `kind` is "glider". `None` for a VERNE machine.
pub fn load(machine: Option<&Path>) -> Result<Option<GliderSpec>, VerneError> {
    let Some(p) = machine else { return Ok(None) };
    if !p.exists() {
        return Ok(p.to_str().and_then(GliderSpec::preset));
    }
    let name = p.display().to_string();
    let text = std::fs::read_to_string(p).map_err(|e| VerneError::io(&name, e))?;
    let is_glider = text.lines().any(|l| {
        let l = l.trim().replace(' ', "");
        l == "kind=\"glider\"" || l == "kind,glider"
    });
    if !is_glider {
        return Ok(None);
    }
    GliderSpec::from_toml_str(&text, &name)
        .map(Some)
        .map_err(|e| VerneError::input(&name, None, None, e.to_string()))
}

// ---------------------------------------------------------------------------------------------
// verne ik

/// `verne ik -m GLIDER`: columns x,y -> rho1,rho2 of working mode `++`, or every mode (`--all`).
pub fn ik(args: &IkArgs, spec: GliderSpec) -> Result<u8, VerneError> {
    let source = if args.pose.is_empty() {
        CsvSource::open(args.input.as_deref())?
    } else {
        inline_planar("x,y", "--pose", &args.pose)?
    };
    let mut job = GliderIk {
        spec,
        all: args.all,
    };
    run_rows(
        "ik",
        &mut job,
        source,
        args.output.as_ref(),
        units(&args.common),
    )
}

// ---------------------------------------------------------------------------------------------
// verne fk

/// `verne fk -m GLIDER`: columns rho1,rho2 -> x,y of assembly mode `+`, or both (`--all`).
pub fn fk(args: &FkArgs, spec: GliderSpec) -> Result<u8, VerneError> {
    let source = if args.joints.is_empty() {
        CsvSource::open(args.input.as_deref())?
    } else {
        inline_planar("rho1,rho2", "--joints", &args.joints)?
    };
    let mut job = GliderFk {
        spec,
        all: args.all,
        structural: 0,
    };
    let code = run_rows(
        "fk",
        &mut job,
        source,
        args.output.as_ref(),
        units(&args.common),
    )?;
    if job.structural > MAX_STRUCTURAL_REPORTS {
        eprintln!(
            "verne fk: {} rows at a structural singularity in all ({} more not shown)",
            job.structural,
            job.structural - MAX_STRUCTURAL_REPORTS
        );
    }
    Ok(code)
}

// ---------------------------------------------------------------------------------------------
// verne modes

/// det A, det B, singularity flags and amplification factors of one pose.
fn kinetostatic_cells(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> [Cell; 7] {
    let (lambda1, lambda2) = match amplification(spec, p, rho) {
        Some(a) => (Cell::Num(a.lambda_min), Cell::Num(a.lambda_max)),
        None => {
            // Parallel singularity: lambda_max is unbounded; lambda_min = 1 / sigma_max(B^-1 A)
            // while B is regular.
            let j = jacobians(spec, p, rho);
            let small = match j.b.try_inverse() {
                Some(bi) => {
                    let (hi, _) = singular_values_2x2(&(bi * j.a));
                    Cell::Num(1.0 / hi)
                }
                None => Cell::Empty,
            };
            (small, Cell::Str("inf"))
        }
    };
    let in_bounds = amplification(spec, p, rho)
        .is_some_and(|a| a.within(PAPER_LAMBDA_BOUNDS[0], PAPER_LAMBDA_BOUNDS[1]));
    [
        Cell::Num(det_a(spec, p, rho)),
        Cell::Num(det_b(spec, p, rho)),
        Cell::Bool(is_parallel_singular(spec, p, rho)),
        Cell::Bool(is_serial_singular(spec, p, rho)),
        lambda1,
        lambda2,
        Cell::Bool(in_bounds),
    ]
}

const KINETOSTATIC_HEADER: [&str; 7] = [
    "det_a",
    "det_b",
    "parallel_singular",
    "serial_singular",
    "lambda1",
    "lambda2",
    "eq4",
];

/// `verne modes -m GLIDER --pose X,Y,0 | --joints R1,R2,0`: every branch with its Jacobians,
/// singularity flags and amplification factors.
pub fn modes(args: &ModesArgs, spec: GliderSpec) -> Result<u8, VerneError> {
    let u = units(&args.common);
    let third = |v: [f64; 3], flag: &str| {
        if v[2] == 0.0 {
            Ok(())
        } else {
            Err(VerneError::Usage(format!(
                "{flag} {},{},{}: a glider is planar; give {flag} A,B,0 (the third value must be \
                 0, found {})",
                v[0], v[1], v[2], v[2]
            )))
        }
    };
    let mut header: Vec<&str>;
    let mut rows: Vec<Vec<Cell>> = Vec::new();
    let title;
    if let Some(q) = args.pose {
        third(q, "--pose")?;
        let p = Point2::new(q[0], q[1]);
        let sols = inverse_kinematics(&spec, p);
        header = vec!["branch", "mode", "assembly", "rho1", "rho2"];
        for (k, s) in sols.iter().enumerate() {
            let v = verdict(&spec, p, s.rho, s.mode, s.assembly);
            let mut r = vec![
                Cell::Int(k as i64 + 1),
                Cell::Str(mode_label(s.mode)),
                Cell::Str(branch_label(s.assembly)),
                Cell::Num(s.rho.x),
                Cell::Num(s.rho.y),
            ];
            r.extend(kinetostatic_cells(&spec, p, s.rho));
            r.extend([Cell::Bool(v.ok()), Cell::Str(v.as_str())]);
            rows.push(r);
        }
        title = format!(
            "{}: inverse kinematics of P = ({}, {}): {} real working modes",
            spec.name,
            q[0],
            q[1],
            sols.len()
        );
    } else {
        let j = args.joints.unwrap_or([0.0; 3]);
        third(j, "--joints")?;
        let rho = Vector2::new(j[0], j[1]);
        header = vec!["branch", "assembly", "mode", "x", "y"];
        match forward_kinematics(&spec, rho) {
            ForwardKinematics::StructuralSingularity { centre, radius } => {
                title = format!(
                    "{}: forward kinematics of rho = ({}, {}): structural singularity: C = D = \
                     ({}, {}), P is anywhere on the circle of radius {} about it",
                    spec.name, j[0], j[1], centre.x, centre.y, radius
                );
            }
            ForwardKinematics::Isolated(sols) => {
                for (k, f) in sols.iter().enumerate() {
                    let v = verdict(&spec, f.p, rho, f.mode, f.assembly);
                    let mut r = vec![
                        Cell::Int(k as i64 + 1),
                        Cell::Str(branch_label(f.assembly)),
                        Cell::Str(mode_label(f.mode)),
                        Cell::Num(f.p.x),
                        Cell::Num(f.p.y),
                    ];
                    r.extend(kinetostatic_cells(&spec, f.p, rho));
                    r.extend([Cell::Bool(v.ok()), Cell::Str(v.as_str())]);
                    rows.push(r);
                }
                title = format!(
                    "{}: forward kinematics of rho = ({}, {}): {} real assembly modes",
                    spec.name,
                    j[0],
                    j[1],
                    sols.len()
                );
            }
        }
    }
    header.extend(KINETOSTATIC_HEADER);
    header.extend(["working", "status"]);
    let decimals = Units {
        decimals: Some(u.decimals.unwrap_or(TABLE_DECIMALS)),
        ..u
    };
    let text_rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            r.iter()
                .map(|&c| cell_text(c, if args.csv { u } else { decimals }))
                .collect()
        })
        .collect();
    let text = if args.csv {
        csv_text(&header, &text_rows)
    } else {
        let n = header.len();
        let mut t = format!("{title}\n");
        t.push_str(&aligned(&header, &text_rows, &[1, 2, n - 1]));
        t
    };
    write_stdout(&text)?;
    Ok(if rows.is_empty() {
        EXIT_ROWS_FAILED
    } else {
        EXIT_OK
    })
}

fn cell_text(c: Cell, u: Units) -> String {
    let mut out = Vec::new();
    write_cell(&mut out, c, u);
    String::from_utf8_lossy(&out).into_owned()
}

/// Header and rows as CSV text (the cells need no quoting: numbers and codes).
pub fn csv_text(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut t = header.join(",");
    t.push('\n');
    for r in rows {
        t.push_str(&r.join(","));
        t.push('\n');
    }
    t
}

/// A table for a person: columns separated by two spaces, right-aligned except the columns
/// listed in `left`.
pub fn aligned(header: &[&str], rows: &[Vec<String>], left: &[usize]) -> String {
    let widths: Vec<usize> = (0..header.len())
        .map(|k| {
            rows.iter()
                .map(|r| r[k].chars().count())
                .chain([header[k].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: &[&str]| {
        let s = cells
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(k, (c, &w))| {
                if left.contains(&k) {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect::<Vec<_>>()
            .join("  ");
        format!("{}\n", s.trim_end())
    };
    let mut t = line(header);
    for r in rows {
        t.push_str(&line(&r.iter().map(String::as_str).collect::<Vec<_>>()));
    }
    t
}

// ---------------------------------------------------------------------------------------------
// verne workspace (called by the `workspace` subcommand for a glider)

/// Header of the workspace points CSV.
pub const WORKSPACE_HEADER: [&str; 8] = [
    "x", "y", "rho1", "rho2", "lambda1", "lambda2", "status", "region",
];

fn class_code(c: NodeClass) -> &'static str {
    match c {
        NodeClass::Unreachable => "unreachable",
        NodeClass::OutOfRange => "out_of_range",
        NodeClass::Singular => "singular",
        NodeClass::OtherAssembly => "other_assembly",
        NodeClass::OutOfBounds => "out_of_bounds",
        NodeClass::Admissible => "admissible",
    }
}

/// Cartesian workspace of a glider in working mode `++` (section 2.6, Wenger 2001): every node
/// of a square grid over the image of the joint box is classified (reached within the joint
/// ranges, singular, other assembly mode, outside the amplification bounds, admissible); the
/// t-connected region is the admissible nodes 4-connected to the forward kinematics of the
/// centre of the joint box; S is the largest rectangle in it, sides at 0 or 45 deg
/// (docs/gliders.md).
///
/// - `step`: grid step in the spec's length unit; `nodes`: grid nodes along the longer side of
///   the window (default [`WORKSPACE_DEFAULT_NODES`]); give at most one.
/// - `lambda_bounds`: eq. (4) bounds on both amplification factors (`Some(PAPER_LAMBDA_BOUNDS)`
///   for the paper's 1/3 < lambda < 3), `None` for none.
/// - `output`: the points CSV ([`WORKSPACE_HEADER`], one row per node, y slowest), written
///   atomically; `None` writes no points, `-` writes stdout.
/// - `plot`: an SVG picture of the workspace, the region, the rectangle and the guides.
///
/// The summary goes to stderr. Returns exit code 0, or 1 when the region is empty.
pub fn workspace(
    spec: &GliderSpec,
    step: Option<f64>,
    nodes: Option<usize>,
    lambda_bounds: Option<[f64; 2]>,
    output: Option<&Path>,
    plot: Option<&Path>,
    units: Units,
) -> Result<u8, VerneError> {
    if let Some([lo, hi]) = lambda_bounds
        && !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi)
    {
        return Err(VerneError::Usage(format!(
            "lambda bounds {lo},{hi}: expected 0 < LO < HI"
        )));
    }
    if let Some(p) = plot
        && !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("svg"))
    {
        return Err(VerneError::Usage(format!(
            "{}: a glider workspace is plotted as SVG; give a file name ending in .svg",
            p.display()
        )));
    }
    let base = WorkspaceOptions {
        lambda_bounds,
        ..WorkspaceOptions::default()
    };
    let nodes = match (step, nodes) {
        (Some(_), Some(_)) => {
            return Err(VerneError::Usage(
                "give the grid as a step or as a node count, not both".into(),
            ));
        }
        (Some(s), None) => {
            if !(s.is_finite() && s > 0.0) {
                return Err(VerneError::Usage(format!(
                    "step {s}: expected a length > 0"
                )));
            }
            // A two-node grid spans the window: its step is the window's longer side.
            let window = sample_workspace(
                spec,
                &WorkspaceOptions {
                    nodes: 2,
                    ..base.clone()
                },
            )
            .step;
            let n = (window / s).ceil() + 1.0;
            if n > WORKSPACE_MAX_NODES as f64 {
                return Err(VerneError::Usage(format!(
                    "step {s}: {n} nodes along the {window:.4} window, more than the \
                     {WORKSPACE_MAX_NODES} allowed; give a larger step"
                )));
            }
            n.max(2.0) as usize
        }
        (None, Some(n)) => {
            if !(2..=WORKSPACE_MAX_NODES).contains(&n) {
                return Err(VerneError::Usage(format!(
                    "{n} nodes: expected 2 to {WORKSPACE_MAX_NODES}"
                )));
            }
            n
        }
        (None, None) => WORKSPACE_DEFAULT_NODES,
    };
    let opts = WorkspaceOptions { nodes, ..base };
    let grid = sample_workspace(spec, &opts);
    // S and the largest square: the better of the two orientations of docs/gliders.md.
    let turned = sample_workspace(
        spec,
        &WorkspaceOptions {
            frame_angle: std::f64::consts::FRAC_PI_4,
            ..opts.clone()
        },
    );
    let best = |f: fn(&WorkspaceGrid) -> Option<Rectangle>| -> Option<Rectangle> {
        match (f(&grid), f(&turned)) {
            (Some(a), Some(b)) => Some(if b.area() > a.area() { b } else { a }),
            (a, b) => a.or(b),
        }
    };
    let (rect, square) = (best(largest_rectangle), best(largest_square));

    if let Some(out) = output {
        write_workspace_points(spec, &grid, &opts, out, units)?;
    }
    if let Some(p) = plot {
        write_atomic(p, &workspace_svg(spec, &grid, rect, square))?;
    }

    let cell = grid.step * grid.step;
    let count = |f: &dyn Fn(NodeClass) -> bool| grid.class.iter().filter(|&&c| f(c)).count();
    let reached = count(&|c| !matches!(c, NodeClass::Unreachable | NodeClass::OutOfRange));
    let admissible = count(&|c| c == NodeClass::Admissible);
    let mut s = String::new();
    let bounds = match lambda_bounds {
        Some([lo, hi]) => format!("{lo:.6} <= lambda_i <= {hi:.6} (eq. (4))"),
        None => "no amplification bound".into(),
    };
    let _ = writeln!(
        s,
        "verne workspace: {} (glider), working mode {}, assembly mode {}, {bounds}",
        spec.name,
        mode_label(opts.mode),
        branch_label(opts.assembly)
    );
    let _ = writeln!(
        s,
        "  grid: {} x {} nodes, step {:.6}",
        grid.nx, grid.ny, grid.step
    );
    let _ = writeln!(
        s,
        "  workspace of mode {} within the joint ranges: area {:.6} ({reached} nodes)",
        mode_label(opts.mode),
        reached as f64 * cell
    );
    let _ = writeln!(
        s,
        "  admissible (regular, assembly {}, bounds met): area {:.6} ({admissible} nodes)",
        branch_label(opts.assembly),
        admissible as f64 * cell
    );
    match grid.seed {
        Some((i, j)) => {
            let c = grid.node(i, j);
            let _ = writeln!(
                s,
                "  t-connected region of ({:.6}, {:.6}): area {:.6}",
                c.x,
                c.y,
                grid.region_area()
            );
        }
        None => {
            let _ = writeln!(
                s,
                "  t-connected region: empty (the centre of the joint box is not admissible)"
            );
        }
    }
    for (name, r) in [("largest rectangle (S)", rect), ("largest square", square)] {
        if let Some(r) = r {
            let _ = writeln!(
                s,
                "  {name}: {:.6} x {:.6} = {:.6}, sides at {:.0} deg, centre ({:.6}, {:.6})",
                r.width,
                r.height,
                r.area(),
                r.angle.to_degrees(),
                r.centre.x,
                r.centre.y
            );
        }
    }
    if let Some(out) = output {
        let _ = writeln!(
            s,
            "  wrote {} points to {}",
            grid.nx * grid.ny,
            out.display()
        );
    }
    if let Some(p) = plot {
        let _ = writeln!(s, "  wrote the picture to {}", p.display());
    }
    eprint!("{s}");
    Ok(if grid.seed.is_some() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

fn write_workspace_points(
    spec: &GliderSpec,
    grid: &WorkspaceGrid,
    opts: &WorkspaceOptions,
    out: &Path,
    units: Units,
) -> Result<(), VerneError> {
    let mut sink = Sink::create(Some(out))?;
    let mut rec = ByteRecord::new();
    for h in WORKSPACE_HEADER {
        rec.push_field(h.as_bytes());
    }
    sink.write(&rec)?;
    let mut buf = Vec::with_capacity(24);
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let k = j * grid.nx + i;
            let p = grid.node(i, j);
            let rho = inverse_kinematics_in_mode(spec, p, opts.mode);
            let lambda = rho.and_then(|r| amplification(spec, p, r));
            let cells = [
                Cell::Num(p.x),
                Cell::Num(p.y),
                rho.map_or(Cell::Empty, |r| Cell::Num(r.x)),
                rho.map_or(Cell::Empty, |r| Cell::Num(r.y)),
                lambda.map_or(Cell::Empty, |a| Cell::Num(a.lambda_min)),
                lambda.map_or(Cell::Empty, |a| Cell::Num(a.lambda_max)),
                Cell::Str(class_code(grid.class[k])),
                Cell::Bool(grid.region[k]),
            ];
            rec.clear();
            for c in cells {
                buf.clear();
                write_cell(&mut buf, c, units);
                rec.push_field(&buf);
            }
            if let Err(e) = sink.write(&rec) {
                sink.discard();
                return Err(e);
            }
        }
    }
    sink.finish()
}

/// Writes text to `path` as every output file is written ([`crate::table::write_output`]).
fn write_atomic(path: &Path, text: &str) -> Result<(), VerneError> {
    crate::table::write_output(path, text.as_bytes())
        .map_err(|e| VerneError::io(&path.display().to_string(), e))
}

/// An SVG picture: nodes by class (run-length rectangles per grid row), the rectangle S (red),
/// the largest square (blue, dashed), the guide strokes and the guide origins A and B.
fn workspace_svg(
    spec: &GliderSpec,
    grid: &WorkspaceGrid,
    rect: Option<Rectangle>,
    square: Option<Rectangle>,
) -> String {
    let half = 0.5 * grid.step;
    // Picture window: the grid and the guides.
    let mut lo = Point2::new(grid.origin.x - half, grid.origin.y - half);
    let mut hi = Point2::new(
        grid.origin.x + (grid.nx.max(1) - 1) as f64 * grid.step + half,
        grid.origin.y + (grid.ny.max(1) - 1) as f64 * grid.step + half,
    );
    let guides = [
        (spec.a(), spec.u1(), spec.rho1_range),
        (spec.b(), spec.u2(), spec.rho2_range),
    ];
    for (o, u, [r0, r1]) in guides {
        for p in [o, o + u * r0, o + u * r1] {
            lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
    }
    let span = (hi.x - lo.x).max(hi.y - lo.y).max(f64::MIN_POSITIVE);
    let pad = 0.05 * span;
    let scale = PLOT_WIDTH_PX / (hi.x - lo.x + 2.0 * pad).max(f64::MIN_POSITIVE);
    let height = (hi.y - lo.y + 2.0 * pad) * scale;
    let px = |p: Point2<f64>| ((p.x - lo.x + pad) * scale, (hi.y + pad - p.y) * scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{PLOT_WIDTH_PX:.0}\" \
         height=\"{height:.0}\" viewBox=\"0 0 {PLOT_WIDTH_PX:.0} {height:.0}\">"
    );
    let _ = writeln!(
        s,
        "<title>{}: workspace of working mode ++</title>\n<rect width=\"100%\" height=\"100%\" \
         fill=\"white\"/>",
        spec.name
    );
    let colour = |k: usize| -> Option<&'static str> {
        if grid.region[k] {
            return Some("#4caf50");
        }
        match grid.class[k] {
            NodeClass::Admissible => Some("#a5d6a7"),
            NodeClass::OutOfBounds => Some("#ffe082"),
            NodeClass::OtherAssembly => Some("#b0bec5"),
            NodeClass::Singular => Some("#000000"),
            NodeClass::Unreachable | NodeClass::OutOfRange => None,
        }
    };
    let w = grid.step * scale;
    for j in 0..grid.ny {
        let mut i = 0;
        while i < grid.nx {
            let c = colour(j * grid.nx + i);
            let start = i;
            while i < grid.nx && colour(j * grid.nx + i) == c {
                i += 1;
            }
            if let Some(fill) = c {
                // Grid frame at angle 0: node (i, j) is origin + step (i, j).
                let top_left = Point2::new(
                    grid.origin.x + start as f64 * grid.step - half,
                    grid.origin.y + j as f64 * grid.step + half,
                );
                let (x, y) = px(top_left);
                let _ = writeln!(
                    s,
                    "<rect x=\"{x:.2}\" y=\"{y:.2}\" width=\"{:.2}\" height=\"{w:.2}\" \
                     fill=\"{fill}\"/>",
                    (i - start) as f64 * w
                );
            }
        }
    }
    for (r, style) in [
        (rect, "stroke=\"#d32f2f\" stroke-width=\"2\""),
        (
            square,
            "stroke=\"#1565c0\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"",
        ),
    ] {
        if let Some(r) = r {
            let pts: Vec<String> = r
                .corners()
                .iter()
                .map(|&c| {
                    let (x, y) = px(c);
                    format!("{x:.2},{y:.2}")
                })
                .collect();
            let _ = writeln!(
                s,
                "<polygon points=\"{}\" fill=\"none\" {style}/>",
                pts.join(" ")
            );
        }
    }
    for (o, u, [r0, r1]) in guides {
        let (x0, y0) = px(o + u * r0);
        let (x1, y1) = px(o + u * r1);
        let _ = writeln!(
            s,
            "<line x1=\"{x0:.2}\" y1=\"{y0:.2}\" x2=\"{x1:.2}\" y2=\"{y1:.2}\" stroke=\"#424242\" \
             stroke-width=\"4\"/>"
        );
        let (x, y) = px(o);
        let _ = writeln!(
            s,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"4\" fill=\"#424242\"/>"
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"8\" y=\"18\" font-family=\"sans-serif\" font-size=\"13\">{}: t-connected \
         region (green), other admissible (light green), outside eq. (4) (amber), other assembly \
         (grey); S red, largest square blue</text>",
        spec.name
    );
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("verne-glider-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn workspace_writes_points_plot_and_finds_a_rectangle() {
        let dir = scratch("ws");
        let (csv, svg) = (dir.join("points.csv"), dir.join("ws.svg"));
        let spec = GliderSpec::preset("orthoglide").unwrap();
        let code = workspace(
            &spec,
            None,
            Some(101),
            Some(PAPER_LAMBDA_BOUNDS),
            Some(&csv),
            Some(&svg),
            Units::default(),
        )
        .unwrap();
        assert_eq!(code, EXIT_OK);
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some(WORKSPACE_HEADER.join(",").as_str()));
        let rows: Vec<&str> = lines.collect();
        // 101 nodes along the longer side; every node is written.
        assert!(rows.len() >= 101 * 50, "{} rows", rows.len());
        assert!(rows.iter().any(|r| r.ends_with(",admissible,true")));
        assert!(rows.iter().any(|r| r.contains(",unreachable,")));
        let picture = std::fs::read_to_string(&svg).unwrap();
        assert!(picture.starts_with("<svg") && picture.trim_end().ends_with("</svg>"));
        assert!(picture.contains("<polygon"));
        // No temporary file is left beside the outputs.
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn workspace_step_sets_the_grid_and_bad_arguments_are_refused() {
        let spec = GliderSpec::preset("biglide2").unwrap();
        let ok = workspace(&spec, Some(0.05), None, None, None, None, Units::default());
        assert_eq!(ok.unwrap(), EXIT_OK);
        let both = workspace(
            &spec,
            Some(0.05),
            Some(11),
            None,
            None,
            None,
            Units::default(),
        );
        assert!(both.unwrap_err().to_string().contains("not both"));
        let tiny = workspace(&spec, Some(1e-9), None, None, None, None, Units::default());
        assert!(tiny.unwrap_err().to_string().contains("larger step"));
        let png = workspace(
            &spec,
            None,
            Some(11),
            None,
            None,
            Some(Path::new("w.png")),
            Units::default(),
        );
        assert!(png.unwrap_err().to_string().contains(".svg"));
        let bounds = workspace(
            &spec,
            None,
            Some(11),
            Some([3.0, 1.0]),
            None,
            None,
            Units::default(),
        );
        assert!(bounds.is_err());
    }
}
