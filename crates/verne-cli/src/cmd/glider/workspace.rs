//! `verne workspace -m GLIDER`: the Cartesian workspace of a glider (section 2.6, Wenger 2001),
//! the points CSV, the SVG picture and the summary on stderr (docs/gliders.md).

use std::fmt::Write as _;
use std::path::Path;

use csv::ByteRecord;
use verne::glider::{
    GliderSpec, NodeClass, Rectangle, Sampling, WorkspaceGrid, WorkspaceOptions, amplification,
    branch_label, inverse_kinematics_in_mode, largest_rectangle, largest_square, mode_label,
    sample_workspace,
};

use crate::cmd::{EXIT_OK, EXIT_ROWS_FAILED};
use crate::engine::pipeline::{Cell, Units, write_cell};
use crate::error::VerneError;
use crate::files::Sink;
use crate::plot::glider::workspace_picture;

/// Default grid nodes along the longer side of the workspace window.
pub const WORKSPACE_DEFAULT_NODES: usize = 801;

/// Most grid nodes along one side of a workspace (memory: 2 bytes per node).
pub const WORKSPACE_MAX_NODES: usize = 10_001;

/// How fine the grid is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GridSize {
    /// [`WORKSPACE_DEFAULT_NODES`] along the window's longer side.
    Default,
    /// A step in the spec's length unit.
    Step(f64),
    /// Nodes along the window's longer side.
    Nodes(usize),
}

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
/// - `size`: the grid's step in the spec's length unit, or its nodes along the longer side of
///   the window (at most [`WORKSPACE_MAX_NODES`]).
/// - `lambda_bounds`: eq. (4) bounds on both amplification factors (`Some(PAPER_LAMBDA_BOUNDS)`
///   for the paper's 1/3 < lambda < 3), `None` for none.
/// - `sampling`: every node classified, or only those near the boundaries between classes
///   (the same grid wherever no feature hides inside a coarse cell; [`Sampling`]).
/// - `output`: the points CSV ([`WORKSPACE_HEADER`], one row per node, y slowest), written
///   atomically; `None` writes no points, `-` writes stdout.
/// - `plot`: a picture (SVG or PNG) of the workspace, the region, the rectangle and the guides.
///
/// The summary goes to stderr. Returns exit code 0, or 1 when the region is empty.
pub fn workspace(
    spec: &GliderSpec,
    size: GridSize,
    lambda_bounds: Option<[f64; 2]>,
    sampling: Sampling,
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
    if let Some(p) = plot {
        crate::plot::check_picture_path(p)?;
    }
    let base = WorkspaceOptions {
        lambda_bounds,
        sampling,
        ..WorkspaceOptions::default()
    };
    let nodes = nodes_for(spec, size, &base)?;
    let opts = WorkspaceOptions { nodes, ..base };
    let (grid, rect, square) = analyse(spec, &opts);

    if let Some(out) = output {
        write_workspace_points(spec, &grid, &opts, out, units)?;
    }
    if let Some(p) = plot {
        workspace_picture(p, spec, &grid, rect, square)
            .map_err(|e| VerneError::io(&p.display().to_string(), std::io::Error::other(e)))?;
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
    let _ = match grid.coarse_step {
        Some(coarse) => writeln!(
            s,
            "  grid: {} x {} nodes, step {:.6}, adaptive from a coarse step of {coarse:.6}: {} \
             points classified",
            grid.nx, grid.ny, grid.step, grid.classified
        ),
        None => writeln!(
            s,
            "  grid: {} x {} nodes, step {:.6}, uniform: {} points classified",
            grid.nx, grid.ny, grid.step, grid.classified
        ),
    };
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
            let e = grid.region_estimate;
            let _ = writeln!(
                s,
                "  t-connected region of ({:.6}, {:.6}): area {:.6} (between {:.6} and {:.6}; \
                 sampled {:.6} +- {:.6} at 99.7 %)",
                c.x,
                c.y,
                grid.region_area(),
                e.lo,
                e.hi,
                e.sampled,
                e.half_width
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
    say!("{s}");
    Ok(if grid.seed.is_some() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

/// The grid's nodes along the window's longer side for `size` (the window is the image of the
/// joint box of `spec`, so a step gives more nodes on a larger machine).
pub(super) fn nodes_for(
    spec: &GliderSpec,
    size: GridSize,
    base: &WorkspaceOptions,
) -> Result<usize, VerneError> {
    Ok(match size {
        GridSize::Step(s) => {
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
        GridSize::Nodes(n) => {
            if !(2..=WORKSPACE_MAX_NODES).contains(&n) {
                return Err(VerneError::Usage(format!(
                    "{n} nodes: expected 2 to {WORKSPACE_MAX_NODES}"
                )));
            }
            n
        }
        GridSize::Default => WORKSPACE_DEFAULT_NODES,
    })
}

/// The workspace grid of `opts`, and S and the largest square: the better of the two
/// orientations of docs/gliders.md (the grid as given, and turned by 45 deg).
pub(super) fn analyse(
    spec: &GliderSpec,
    opts: &WorkspaceOptions,
) -> (WorkspaceGrid, Option<Rectangle>, Option<Rectangle>) {
    let grid = sample_workspace(spec, opts);
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
    (grid, rect, square)
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use verne::glider::PAPER_LAMBDA_BOUNDS;

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
            GridSize::Nodes(101),
            Some(PAPER_LAMBDA_BOUNDS),
            Sampling::Auto,
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
        // Axes in the preset's unit, a legend naming S and the square (one outline when they
        // are the same: the orthoglide's S is its largest square on a fine grid).
        assert!(
            picture.contains("x (L)") && picture.contains("y (L)"),
            "axes"
        );
        assert!(
            picture.contains("S = largest square")
                || (picture.contains("S, largest rectangle")
                    && picture.contains("largest square (dashed)")),
            "legend"
        );
        // No temporary file is left beside the outputs.
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn workspace_step_sets_the_grid_and_bad_arguments_are_refused() {
        let spec = GliderSpec::preset("biglide2").unwrap();
        let call = |size, lambda, plot: Option<&Path>| {
            workspace(
                &spec,
                size,
                lambda,
                Sampling::Auto,
                None,
                plot,
                Units::default(),
            )
        };
        assert_eq!(call(GridSize::Step(0.05), None, None).unwrap(), EXIT_OK);
        let error = |size, lambda, plot| call(size, lambda, plot).unwrap_err().to_string();
        assert!(error(GridSize::Nodes(1), None, None).contains("expected 2 to"));
        assert!(error(GridSize::Step(1e-9), None, None).contains("larger step"));
        let gif = error(GridSize::Nodes(11), None, Some(Path::new("w.gif")));
        assert!(gif.contains(".svg or .png"));
        assert!(error(GridSize::Nodes(11), Some([3.0, 1.0]), None).contains("0 < LO < HI"));
    }
}
