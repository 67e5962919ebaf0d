//! `verne modes`: every branch of one query with its verdict and kinetostatic measures, aligned
//! for a person or as CSV.

use crate::engine::pipeline::{Cell, Units, write_cell};
use crate::error::VerneError;
use crate::plot::{BranchSketch, branches_picture};
use nalgebra::Vector3;
use verne::certificate::Certificate;
use verne::parallel_module::branches::{Config, Verdict};
use verne::parallel_module::equations::{ModulePose, Sliders};
use verne::parallel_module::fk;
use verne::parallel_module::ik;
use verne::parallel_module::kinetostatics::kinetostatics;
use verne::spec::Machine;

use super::{EXIT_OK, EXIT_ROWS_FAILED, load_machine, units, write_stdout};
use crate::cli::ModesArgs;

/// One branch: a full configuration of the module, whichever side of the query it came from.
struct Solution {
    pose: ModulePose,
    rho: Sliders,
    config: Config,
    verdict: Verdict,
}

pub fn run(args: &ModesArgs) -> Result<u8, VerneError> {
    if let Some(spec) = super::glider::load(args.common.machine.as_deref())? {
        return super::glider::modes(args, spec);
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let given: Vec<[f64; 3]> = args.pose.iter().chain(&args.joints).copied().collect();
    let names = if args.pose.is_some() {
        "XP,YP,ZP"
    } else {
        "R1,R2,R3"
    };
    let flag = if args.pose.is_some() {
        "--pose"
    } else {
        "--joints"
    };
    crate::arg_values::spatial(&given, flag, names).map_err(VerneError::Usage)?;
    let u = units(&args.common);
    let (title, solutions) = query(&machine, args);
    let angle = if u.radians { "alpha_rad" } else { "alpha_deg" };
    let header = [
        "branch",
        "xp",
        "yp",
        "zp",
        angle,
        "rho1",
        "rho2",
        "rho3",
        "s1",
        "s2",
        "s3",
        "working",
        "det_a",
        "lambda_min",
        "lambda_max",
        "parallel_margin",
        "serial_margin",
        "status",
    ];
    let rows: Vec<Vec<Cell>> = solutions
        .iter()
        .enumerate()
        .map(|(k, s)| row_cells(&machine, k, s))
        .collect();
    let text_rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|c| cell_text(*c, u, args.csv)).collect())
        .collect();
    write_stdout(&render(&title, &header, &text_rows, args.csv))?;
    if let Some(path) = &args.plot {
        let sketches: Vec<BranchSketch> = solutions
            .iter()
            .enumerate()
            .map(|(k, s)| BranchSketch {
                pose: s.pose,
                rho: s.rho,
                label: format!(
                    "{}: s=({},{},{})",
                    k + 1,
                    s.config[0],
                    s.config[1],
                    s.config[2]
                ),
                detail: s.verdict.to_string(),
                working: s.verdict.feasible(),
            })
            .collect();
        branches_picture(path, &machine, &title, &sketches)
            .map_err(|e| VerneError::io(&path.display().to_string(), std::io::Error::other(e)))?;
    }
    Ok(if rows.is_empty() {
        EXIT_ROWS_FAILED
    } else {
        EXIT_OK
    })
}

/// What proves the list complete, in words.
fn proof(c: Certificate) -> &'static str {
    match c {
        Certificate::Double => "proved complete in double precision",
        Certificate::Factored => {
            "proved complete; close roots separated by the two factors of the equation"
        }
        Certificate::Extended => "proved complete; close roots separated in double-double",
        _ => "NOT proved complete: status uncertified",
    }
}

/// Every branch of the query (`--pose`: inverse; `--joints`: forward) and a title line.
fn query(machine: &Machine, args: &ModesArgs) -> (String, Vec<Solution>) {
    if let Some(p) = args.pose {
        let p = Vector3::new(p[0], p[1], p[2]);
        let b = ik::solve(machine, &p);
        let title = format!(
            "inverse kinematics of P = ({}, {}, {}) mm: {} real branches ({})",
            p.x,
            p.y,
            p.z,
            b.len(),
            proof(b.certificate)
        );
        let s = b
            .iter()
            .map(|br| Solution {
                pose: ModulePose { p, alpha: br.alpha },
                rho: br.rho,
                config: br.config,
                verdict: br.verdict,
            })
            .collect();
        (title, s)
    } else {
        let j = args.joints.unwrap_or([0.0; 3]);
        let rho = Sliders::new(j[0], j[1], j[2]);
        let m = fk::solve(machine, &rho);
        let title = format!(
            "forward kinematics of rho = ({}, {}, {}) mm: {} real assembly modes ({})",
            j[0],
            j[1],
            j[2],
            m.len(),
            proof(m.certificate)
        );
        let s = m
            .iter()
            .map(|md| Solution {
                pose: md.pose,
                rho,
                config: md.config,
                verdict: md.verdict,
            })
            .collect();
        (title, s)
    }
}

fn row_cells(machine: &Machine, k: usize, s: &Solution) -> Vec<Cell> {
    let ks = kinetostatics(&machine.module, &s.pose, &s.rho);
    vec![
        Cell::Int(k as i64 + 1),
        Cell::Num(s.pose.p.x),
        Cell::Num(s.pose.p.y),
        Cell::Num(s.pose.p.z),
        Cell::Angle(s.pose.alpha),
        Cell::Num(s.rho.x),
        Cell::Num(s.rho.y),
        Cell::Num(s.rho.z),
        Cell::Int(s.config[0].into()),
        Cell::Int(s.config[1].into()),
        Cell::Int(s.config[2].into()),
        Cell::Bool(s.verdict.feasible()),
        Cell::Num(ks.det_a),
        Cell::Num(ks.amplification[2]),
        Cell::Num(ks.amplification[0]),
        Cell::Num(ks.parallel_margin),
        Cell::Num(ks.serial_margin),
        Cell::Verdict(s.verdict),
    ]
}

/// CSV, or a title and right-aligned columns (the last one left-aligned).
fn render(title: &str, header: &[&str], rows: &[Vec<String>], csv: bool) -> String {
    let mut text = String::new();
    if csv {
        text.push_str(&header.join(","));
        text.push('\n');
        for r in rows {
            text.push_str(&r.join(","));
            text.push('\n');
        }
        return text;
    }
    text.push_str(title);
    text.push('\n');
    let widths: Vec<usize> = (0..header.len())
        .map(|k| {
            rows.iter()
                .map(|r| r[k].len())
                .chain([header[k].len()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: Vec<&str>| {
        let n = cells.len();
        cells
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(k, (c, w))| {
                if k + 1 == n {
                    c.to_string()
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect::<Vec<_>>()
            .join("  ")
    };
    text.push_str(&line(header.to_vec()));
    text.push('\n');
    for r in rows {
        text.push_str(&line(r.iter().map(String::as_str).collect()));
        text.push('\n');
    }
    text
}

/// Exact numbers for CSV; for a person, 6 decimals (9 for angles in radians).
fn cell_text(c: Cell, u: Units, exact: bool) -> String {
    let mut out = Vec::new();
    let units = if exact {
        u
    } else {
        let d = if matches!(c, Cell::Angle(_)) && u.radians {
            9
        } else {
            6
        };
        Units {
            decimals: Some(u.decimals.unwrap_or(d)),
            ..u
        }
    };
    write_cell(&mut out, c, units);
    String::from_utf8_lossy(&out).into_owned()
}
