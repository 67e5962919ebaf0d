//! The glider mechanisms (`-m biglide1|biglide2|orthoglide` or a `kind = "glider"` file) under
//! the row commands of the VERNE machine (`ik`, `fk`, `modes`); the glider workspace that
//! `verne workspace` calls is in [`workspace`](mod@workspace). Conventions and column contracts: docs/gliders.md.
//!
//! The row jobs are in [`crate::engine::glider_rows`]; what makes a solution `ok` (working mode
//! `++`, assembly mode `+`, inside the joint ranges, not singular) in [`verne::glider::verdict`](mod@verne::glider::verdict).

use std::path::Path;

use nalgebra::{Point2, Vector2};
use verne::glider::jacobian::singular_values_2x2;
use verne::glider::{
    ForwardKinematics, GliderSpec, PAPER_LAMBDA_BOUNDS, Verdict, amplification, branch_label,
    det_a, det_b, forward_kinematics, inverse_kinematics, is_parallel_singular, is_serial_singular,
    jacobians, mode_label, verdict,
};

pub mod sweep;
pub mod workspace;

pub use sweep::workspace_sweep;
pub use workspace::workspace;

use super::{EXIT_OK, EXIT_ROWS_FAILED, run_rows, units, write_stdout};
use crate::cli::{FkArgs, IkArgs, ModesArgs};
use crate::engine::glider_rows::{GliderFk, GliderIk, MAX_STRUCTURAL_REPORTS};
use crate::engine::pipeline::{Cell, Units, write_cell};
use crate::error::VerneError;
use crate::plot::glider::{GliderSketch, branches_picture};
use crate::report::text_table::{aligned, csv_text};
use crate::table::CsvSource;

/// Decimals of the aligned tables of `verne modes` (unless `--precision`).
const TABLE_DECIMALS: usize = 6;

/// The rows of `--pose X,Y,0` / `--joints R1,R2,0` as numbers in the columns `header`; the
/// third value of a planar mechanism must be 0.
fn inline_planar(header: &[&str], flag: &str, rows: &[[f64; 3]]) -> Result<CsvSource, VerneError> {
    for r in rows {
        planar(*r, flag)?;
    }
    Ok(crate::cmd::inline_source(
        header,
        rows.iter().map(|r| vec![r[0], r[1]]).collect(),
    ))
}

/// A point given to a glider: `A,B` (or `A,B,0`).
fn planar(v: [f64; 3], flag: &str) -> Result<(), VerneError> {
    if v[2] == 0.0 || v[2].is_nan() {
        return Ok(());
    }
    Err(VerneError::Usage(format!(
        "{flag} {},{},{}: a glider is planar; give {flag} A,B (a third value must be 0, found {})",
        v[0], v[1], v[2], v[2]
    )))
}

/// The glider named by `-m`: a preset name (when no file of that name exists) or a file whose
/// `kind` is "glider". `None` for a VERNE machine.
pub fn load(machine: Option<&Path>) -> Result<Option<GliderSpec>, VerneError> {
    let Some(p) = machine else { return Ok(None) };
    if !p.exists() {
        return Ok(p.to_str().and_then(GliderSpec::preset));
    }
    let name = p.display().to_string();
    let bytes = crate::files::read_input_file(p).map_err(|e| VerneError::io(&name, e))?;
    let text = String::from_utf8_lossy(&bytes);
    if !is_glider_text(&text) {
        return Ok(None);
    }
    glider_from_text(&text, &name).map(Some)
}

/// The file says `kind = "glider"` (TOML) or `kind,glider` (CSV).
pub fn is_glider_text(text: &str) -> bool {
    text.lines().any(|l| {
        let l = l.trim().replace(' ', "");
        l == "kind=\"glider\"" || l == "kind,glider"
    })
}

/// A glider file's text as a glider, or the error with the file's name.
pub fn glider_from_text(text: &str, name: &str) -> Result<GliderSpec, VerneError> {
    GliderSpec::from_toml_str(text, name)
        .map_err(|e| VerneError::input(name, None, None, e.to_string()))
}

// ---------------------------------------------------------------------------------------------
// verne ik

/// `verne ik -m GLIDER`: columns x,y -> rho1,rho2 of working mode `++`, or every mode (`--all`).
pub fn ik(args: &IkArgs, spec: GliderSpec) -> Result<u8, VerneError> {
    let source = if args.pose.is_empty() {
        CsvSource::open(args.input.as_deref())?
    } else {
        inline_planar(&["x", "y"], "--pose", &args.pose)?
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
        inline_planar(&["rho1", "rho2"], "--joints", &args.joints)?
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
        sayln!(
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
    let third = planar;
    let mut header: Vec<&str>;
    let mut rows: Vec<Vec<Cell>> = Vec::new();
    let mut sketches: Vec<GliderSketch> = Vec::new();
    let mut sketch =
        |k: usize, p: Point2<f64>, rho: Vector2<f64>, labels: [&str; 2], v: &Verdict| {
            sketches.push(GliderSketch {
                p,
                rho,
                label: format!("{}: mode {}, assembly {}", k + 1, labels[0], labels[1]),
                detail: v.as_str().to_string(),
                working: v.ok(),
            })
        };
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
            sketch(
                k,
                p,
                s.rho,
                [mode_label(s.mode), branch_label(s.assembly)],
                &v,
            );
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
        header = vec!["branch", "mode", "assembly", "x", "y"];
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
                        Cell::Str(mode_label(f.mode)),
                        Cell::Str(branch_label(f.assembly)),
                        Cell::Num(f.p.x),
                        Cell::Num(f.p.y),
                    ];
                    r.extend(kinetostatic_cells(&spec, f.p, rho));
                    r.extend([Cell::Bool(v.ok()), Cell::Str(v.as_str())]);
                    rows.push(r);
                    sketch(
                        k,
                        f.p,
                        rho,
                        [mode_label(f.mode), branch_label(f.assembly)],
                        &v,
                    );
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
    if let Some(path) = &args.plot {
        branches_picture(path, &spec, &title, &sketches)
            .map_err(|e| VerneError::io(&path.display().to_string(), std::io::Error::other(e)))?;
    }
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
