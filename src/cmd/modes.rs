//! `verne modes`: every branch of one query with its verdict, aligned for a person or as CSV.

use nalgebra::Vector3;
use verne::error::VerneError;
use verne::module_fk;
use verne::module_ik;
use verne::pipeline::{Cell, Units, write_cell};

use super::{EXIT_OK, EXIT_ROWS_FAILED, load_machine, units, write_stdout};
use crate::cli::ModesArgs;

pub fn run(args: &ModesArgs) -> Result<u8, VerneError> {
    if let Some(spec) = super::glider::load(args.common.machine.as_deref())? {
        return super::glider::modes(args, spec);
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let u = units(&args.common);
    let angle = if u.radians { "alpha_rad" } else { "alpha_deg" };
    let (title, header, rows): (String, Vec<&str>, Vec<Vec<Cell>>) = if let Some(p) = args.pose {
        let b = module_ik::solve(&machine, &Vector3::new(p[0], p[1], p[2]));
        let rows = b
            .iter()
            .enumerate()
            .map(|(k, br)| {
                vec![
                    Cell::Int(k as i64 + 1),
                    Cell::Angle(br.alpha),
                    Cell::Num(br.rho.x),
                    Cell::Num(br.rho.y),
                    Cell::Num(br.rho.z),
                    Cell::Int(br.config[0].into()),
                    Cell::Int(br.config[1].into()),
                    Cell::Int(br.config[2].into()),
                    Cell::Bool(br.working()),
                    Cell::Verdict(br.verdict),
                ]
            })
            .collect();
        (
            format!(
                "inverse kinematics of P = ({}, {}, {}) mm: {} real branches",
                p[0],
                p[1],
                p[2],
                b.len()
            ),
            vec![
                "branch", angle, "rho1", "rho2", "rho3", "s1", "s2", "s3", "working", "status",
            ],
            rows,
        )
    } else {
        let j = args.joints.unwrap_or([0.0; 3]);
        let m = module_fk::solve(&machine, &Vector3::new(j[0], j[1], j[2]));
        let rows = m
            .iter()
            .enumerate()
            .map(|(k, md)| {
                vec![
                    Cell::Int(k as i64 + 1),
                    Cell::Num(md.pose.p.x),
                    Cell::Num(md.pose.p.y),
                    Cell::Num(md.pose.p.z),
                    Cell::Angle(md.pose.alpha),
                    Cell::Int(md.config[0].into()),
                    Cell::Int(md.config[1].into()),
                    Cell::Int(md.config[2].into()),
                    Cell::Bool(md.working()),
                    Cell::Verdict(md.verdict),
                ]
            })
            .collect();
        (
            format!(
                "forward kinematics of rho = ({}, {}, {}) mm: {} real assembly modes",
                j[0],
                j[1],
                j[2],
                m.len()
            ),
            vec![
                "branch", "xp", "yp", "zp", angle, "s1", "s2", "s3", "working", "status",
            ],
            rows,
        )
    };
    let text_rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|c| cell_text(*c, u, args.csv)).collect())
        .collect();
    let mut text = String::new();
    if args.csv {
        text.push_str(&header.join(","));
        text.push('\n');
        for r in &text_rows {
            text.push_str(&r.join(","));
            text.push('\n');
        }
    } else {
        text.push_str(&title);
        text.push('\n');
        let widths: Vec<usize> = (0..header.len())
            .map(|k| {
                text_rows
                    .iter()
                    .map(|r| r[k].len())
                    .chain([header[k].len()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |cells: Vec<&str>| {
            cells
                .iter()
                .zip(&widths)
                .enumerate()
                .map(|(k, (c, w))| {
                    if k + 1 == cells.len() {
                        c.to_string()
                    } else {
                        format!("{c:>w$}")
                    }
                })
                .collect::<Vec<_>>()
                .join("  ")
        };
        text.push_str(&line(header.clone()));
        text.push('\n');
        for r in &text_rows {
            text.push_str(&line(r.iter().map(String::as_str).collect()));
            text.push('\n');
        }
    }
    write_stdout(&text)?;
    Ok(if rows.is_empty() {
        EXIT_ROWS_FAILED
    } else {
        EXIT_OK
    })
}

fn cell_text(c: Cell, u: Units, exact: bool) -> String {
    let mut out = Vec::new();
    let units = if exact {
        u
    } else {
        Units {
            decimals: Some(
                u.decimals
                    .unwrap_or(if matches!(c, Cell::Angle(_)) && u.radians {
                        9
                    } else {
                        6
                    }),
            ),
            ..u
        }
    };
    write_cell(&mut out, c, units);
    String::from_utf8_lossy(&out).into_owned()
}
