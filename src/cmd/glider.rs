//! The glider mechanisms (`-m biglide1|biglide2|orthoglide` or a `kind = "glider"` file) under
//! the row commands of the VERNE machine (`ik`, `fk`, `modes`), and the glider workspace that
//! `verne workspace` calls. Conventions and column contracts: docs/gliders.md.
//!
//! The machine works in working mode `++` and assembly mode `+` (the paper's figures, section
//! 3.2, Wenger 2001); a solution is `ok` when it is in both, inside the joint ranges and not
//! singular. Otherwise its status lists why, codes joined by `;`.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::OnceLock;

use arrayvec::ArrayVec;
use csv::ByteRecord;
use nalgebra::{Point2, Vector2};
use verne::error::VerneError;
use verne::glider::jacobian::singular_values_2x2;
use verne::glider::tolerance::{COINCIDENT_REL, JOINT_LIMIT_REL};
use verne::glider::{
    Branch, ForwardKinematics, GliderSpec, IkSolution, NodeClass, PAPER_LAMBDA_BOUNDS, Rectangle,
    WorkingMode, WorkspaceGrid, WorkspaceOptions, amplification, det_a, det_b, forward_kinematics,
    inverse_kinematics, inverse_kinematics_in_mode, is_parallel_singular, is_serial_singular,
    jacobians, largest_rectangle, largest_square, sample_workspace,
};
use verne::pipeline::{Cell, RowJob, RowOutcome, RowWriter, Units, write_cell};
use verne::table::{CsvSource, Sink};

use super::{EXIT_OK, EXIT_ROWS_FAILED, run_rows, units, write_stdout};
use crate::cli::{FkArgs, IkArgs, ModesArgs};

/// The working mode of the machine (paper's figures, docs/gliders.md).
const WORKING_MODE: WorkingMode = WorkingMode::new(Branch::Plus, Branch::Plus);

/// The assembly mode of the machine.
const WORKING_ASSEMBLY: Branch = Branch::Plus;

/// Structural singularities reported one by one on stderr before only counting them.
const MAX_STRUCTURAL_REPORTS: u64 = 5;

/// Decimals of the aligned tables of `verne modes` (unless `--precision`).
const TABLE_DECIMALS: usize = 6;

/// Default grid nodes along the longer side of the workspace window.
pub const WORKSPACE_DEFAULT_NODES: usize = 801;

/// Most grid nodes along one side of a workspace (memory: 2 bytes per node).
pub const WORKSPACE_MAX_NODES: usize = 10_001;

/// Width of the SVG picture in pixels.
const PLOT_WIDTH_PX: f64 = 800.0;

// Reason codes of a solution, in the order they are written.
const OTHER_WORKING_MODE: u8 = 1 << 0;
const OTHER_ASSEMBLY: u8 = 1 << 1;
const RHO1_RANGE: u8 = 1 << 2;
const RHO2_RANGE: u8 = 1 << 3;
const STRUCTURAL: u8 = 1 << 4;
const PARALLEL: u8 = 1 << 5;
const SERIAL: u8 = 1 << 6;
const CODES: [&str; 7] = [
    "other_working_mode",
    "other_assembly",
    "rho1_range",
    "rho2_range",
    "structural_singularity",
    "parallel_singularity",
    "serial_singularity",
];

/// `ok`, or the codes of the set bits joined by `;`.
fn status_text(bits: u8) -> &'static str {
    static TEXT: OnceLock<Vec<String>> = OnceLock::new();
    let text = TEXT.get_or_init(|| {
        (0..1u16 << CODES.len())
            .map(|b| {
                if b == 0 {
                    return "ok".to_string();
                }
                let set: Vec<&str> = CODES
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| b & (1 << k) != 0)
                    .map(|(_, c)| *c)
                    .collect();
                set.join(";")
            })
            .collect()
    });
    &text[bits as usize]
}

/// `++`, `+-`, ... as a static string.
fn mode_label(m: WorkingMode) -> &'static str {
    const LABELS: [&str; 9] = ["++", "+-", "+0", "-+", "--", "-0", "0+", "0-", "00"];
    let k = |b: Branch| match b {
        Branch::Plus => 0,
        Branch::Minus => 1,
        Branch::Double => 2,
    };
    LABELS[3 * k(m.strut1) + k(m.strut2)]
}

fn branch_label(b: Branch) -> &'static str {
    match b {
        Branch::Plus => "+",
        Branch::Minus => "-",
        Branch::Double => "0",
    }
}

/// C = D with l1 = l2: the structural singularity of section 2.4 (Fig. 5), Wenger 2001.
fn is_structural(spec: &GliderSpec, rho: Vector2<f64>) -> bool {
    let (c, d) = spec.sliders(rho);
    (c - d).norm() <= COINCIDENT_REL * spec.l1
        && (spec.l1 - spec.l2).abs() <= COINCIDENT_REL * spec.l1
}

/// Why the pose (P, rho) of the given modes is not a pose of the machine (0: it is).
fn verdict(
    spec: &GliderSpec,
    p: Point2<f64>,
    rho: Vector2<f64>,
    mode: WorkingMode,
    assembly: Branch,
) -> u8 {
    let mut bits = 0;
    // A double root (`0`) is the limit of both signs: flagged as a singularity, not a mode.
    if mode.strut1 == Branch::Minus || mode.strut2 == Branch::Minus {
        bits |= OTHER_WORKING_MODE;
    }
    if assembly == Branch::Minus {
        bits |= OTHER_ASSEMBLY;
    }
    let slack = JOINT_LIMIT_REL * spec.l1;
    let outside = |v: f64, [lo, hi]: [f64; 2]| v < lo - slack || v > hi + slack;
    if outside(rho.x, spec.rho1_range) {
        bits |= RHO1_RANGE;
    }
    if outside(rho.y, spec.rho2_range) {
        bits |= RHO2_RANGE;
    }
    if is_structural(spec, rho) {
        bits |= STRUCTURAL;
    } else if is_parallel_singular(spec, p, rho) {
        bits |= PARALLEL;
    }
    if is_serial_singular(spec, p, rho) {
        bits |= SERIAL;
    }
    bits
}

/// Whether a solution's labels are those of the machine, a double root counting as either sign.
fn compatible(b: Branch, working: Branch) -> bool {
    b == working || b == Branch::Double
}

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

/// Glider IK as a row job.
pub struct GliderIk {
    pub spec: GliderSpec,
    pub all: bool,
}

const IK_INPUTS: &[(&str, bool)] = &[("x", false), ("y", false)];
const IK_OUT: &[&str] = &["rho1", "rho2", "status"];
const IK_OUT_ALL: &[&str] = &[
    "branch", "mode", "assembly", "rho1", "rho2", "working", "status",
];

impl RowJob for GliderIk {
    type Solved = (Point2<f64>, ArrayVec<IkSolution, 4>);

    fn inputs(&self) -> &[(&'static str, bool)] {
        IK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { IK_OUT_ALL } else { IK_OUT }
    }

    fn solve(&self, inputs: &[f64], solved: &mut Self::Solved) {
        let p = Point2::new(inputs[0], inputs[1]);
        solved.0 = p;
        solved.1.clear();
        solved.1.extend(inverse_kinematics(&self.spec, p));
    }

    fn emit(
        &mut self,
        (p, sols): &Self::Solved,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError> {
        let unreachable = RowOutcome {
            ok: false,
            status: Cell::Str("unreachable"),
        };
        if sols.is_empty() {
            let mut cells = vec![Cell::Empty; self.outputs().len()];
            *cells.last_mut().expect("status column") = Cell::Str("unreachable");
            out.row(&cells)?;
            return Ok(unreachable);
        }
        if self.all {
            for (k, s) in sols.iter().enumerate() {
                let bits = verdict(&self.spec, *p, s.rho, s.mode, s.assembly);
                let labels = [mode_label(s.mode), branch_label(s.assembly)];
                branch_row(out, k, labels, [s.rho.x, s.rho.y], bits)?;
            }
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        // Each strut has a `+` root or a double root whenever it reaches its guide.
        let Some(s) = sols.iter().find(|s| {
            compatible(s.mode.strut1, WORKING_MODE.strut1)
                && compatible(s.mode.strut2, WORKING_MODE.strut2)
        }) else {
            let cells = [Cell::Empty, Cell::Empty, Cell::Str("unreachable")];
            out.row(&cells)?;
            return Ok(unreachable);
        };
        let bits = verdict(&self.spec, *p, s.rho, s.mode, s.assembly);
        let status = Cell::Str(status_text(bits));
        out.row(&[Cell::Num(s.rho.x), Cell::Num(s.rho.y), status])?;
        Ok(RowOutcome {
            ok: bits == 0,
            status,
        })
    }
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

/// Glider FK as a row job. Reports structural singularities on stderr as it meets them.
pub struct GliderFk {
    pub spec: GliderSpec,
    pub all: bool,
    /// Rows met so far at a structural singularity.
    pub structural: u64,
}

/// The joints of one row and their forward kinematics (`None` before solving).
#[derive(Default)]
pub struct FkSolved {
    rho: [f64; 2],
    fk: Option<ForwardKinematics>,
}

const FK_INPUTS: &[(&str, bool)] = &[("rho1", false), ("rho2", false)];
const FK_OUT: &[&str] = &["x", "y", "status"];
const FK_OUT_ALL: &[&str] = &["branch", "assembly", "mode", "x", "y", "working", "status"];

impl RowJob for GliderFk {
    type Solved = FkSolved;

    fn inputs(&self) -> &[(&'static str, bool)] {
        FK_INPUTS
    }

    fn outputs(&self) -> &[&'static str] {
        if self.all { FK_OUT_ALL } else { FK_OUT }
    }

    fn solve(&self, inputs: &[f64], solved: &mut FkSolved) {
        solved.rho = [inputs[0], inputs[1]];
        solved.fk = Some(forward_kinematics(
            &self.spec,
            Vector2::new(inputs[0], inputs[1]),
        ));
    }

    fn emit(&mut self, s: &FkSolved, out: &mut RowWriter<'_>) -> Result<RowOutcome, VerneError> {
        let rho = Vector2::new(s.rho[0], s.rho[1]);
        let n = self.outputs().len();
        let fail = |status: &'static str, out: &mut RowWriter<'_>| {
            let mut cells = vec![Cell::Empty; n];
            cells[n - 1] = Cell::Str(status);
            out.row(&cells).map(|_| RowOutcome {
                ok: false,
                status: Cell::Str(status),
            })
        };
        let sols = match &s.fk {
            None => return fail("unreachable", out),
            Some(ForwardKinematics::StructuralSingularity { centre, radius }) => {
                self.structural += 1;
                if self.structural <= MAX_STRUCTURAL_REPORTS {
                    eprintln!(
                        "verne fk: rho = ({}, {}): structural singularity: C = D = ({}, {}), \
                         P is anywhere on the circle of radius {} about it",
                        s.rho[0], s.rho[1], centre.x, centre.y, radius
                    );
                }
                return fail("structural_singularity", out);
            }
            Some(ForwardKinematics::Isolated(v)) if v.is_empty() => {
                return fail("unreachable", out);
            }
            Some(ForwardKinematics::Isolated(v)) => v,
        };
        if self.all {
            for (k, f) in sols.iter().enumerate() {
                let bits = verdict(&self.spec, f.p, rho, f.mode, f.assembly);
                let labels = [branch_label(f.assembly), mode_label(f.mode)];
                branch_row(out, k, labels, [f.p.x, f.p.y], bits)?;
            }
            return Ok(RowOutcome {
                ok: true,
                status: Cell::Str("ok"),
            });
        }
        // Two solutions are `+` and `-`; one is the double root.
        let Some(f) = sols
            .iter()
            .find(|f| compatible(f.assembly, WORKING_ASSEMBLY))
        else {
            return fail("unreachable", out);
        };
        let bits = verdict(&self.spec, f.p, rho, f.mode, f.assembly);
        let status = Cell::Str(status_text(bits));
        out.row(&[Cell::Num(f.p.x), Cell::Num(f.p.y), status])?;
        Ok(RowOutcome {
            ok: bits == 0,
            status,
        })
    }
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
            let bits = verdict(&spec, p, s.rho, s.mode, s.assembly);
            let mut r = vec![
                Cell::Int(k as i64 + 1),
                Cell::Str(mode_label(s.mode)),
                Cell::Str(branch_label(s.assembly)),
                Cell::Num(s.rho.x),
                Cell::Num(s.rho.y),
            ];
            r.extend(kinetostatic_cells(&spec, p, s.rho));
            r.extend([Cell::Bool(bits == 0), Cell::Str(status_text(bits))]);
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
                    let bits = verdict(&spec, f.p, rho, f.mode, f.assembly);
                    let mut r = vec![
                        Cell::Int(k as i64 + 1),
                        Cell::Str(branch_label(f.assembly)),
                        Cell::Str(mode_label(f.mode)),
                        Cell::Num(f.p.x),
                        Cell::Num(f.p.y),
                    ];
                    r.extend(kinetostatic_cells(&spec, f.p, rho));
                    r.extend([Cell::Bool(bits == 0), Cell::Str(status_text(bits))]);
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

/// Writes text to `path` as every output file is written ([`verne::table::write_output`]).
fn write_atomic(path: &Path, text: &str) -> Result<(), VerneError> {
    verne::table::write_output(path, text.as_bytes())
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

/// One `--all` row: `branch`, two labels, two values, `working`, `status`.
fn branch_row(
    out: &mut RowWriter<'_>,
    k: usize,
    labels: [&'static str; 2],
    values: [f64; 2],
    bits: u8,
) -> Result<(), VerneError> {
    out.row(&[
        Cell::Int(k as i64 + 1),
        Cell::Str(labels[0]),
        Cell::Str(labels[1]),
        Cell::Num(values[0]),
        Cell::Num(values[1]),
        Cell::Bool(bits == 0),
        Cell::Str(status_text(bits)),
    ])
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
    fn status_codes_join_in_order() {
        assert_eq!(status_text(0), "ok");
        assert_eq!(
            status_text(RHO2_RANGE | OTHER_ASSEMBLY),
            "other_assembly;rho2_range"
        );
        assert_eq!(mode_label(WORKING_MODE), "++");
        assert_eq!(
            mode_label(WorkingMode::new(Branch::Double, Branch::Minus)),
            "0-"
        );
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
