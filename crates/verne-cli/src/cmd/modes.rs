//! `verne modes`: every branch of one query with its verdict and kinetostatic measures, aligned
//! for a person or as CSV: a tool pose or machine joints of the 5-axis machine, a platform point
//! or sliders of the parallel module.

use crate::engine::machine_rows::machine_fk_parts;
use crate::engine::pipeline::{Cell, Units, write_cell};
use crate::error::VerneError;
use crate::plot::{BranchSketch, branches_picture};
use crate::report::html::modes::Branch3d;
use nalgebra::Vector3;
use verne::certificate::Certificate;
use verne::machine::fk::machine_fk;
use verne::machine::orientation::ToolOrientation;
use verne::machine::path::path_candidates;
use verne::parallel_module::branches::{Config, Verdict};
use verne::parallel_module::equations::{ModulePose, Sliders};
use verne::parallel_module::fk;
use verne::parallel_module::ik;
use verne::parallel_module::kinetostatics::kinetostatics;
use verne::spec::Machine;

use super::{
    EXIT_OK, EXIT_ROWS_FAILED, Mechanism, load_mechanism, refuse_for_glider, units, write_stdout,
};
use crate::cli::ModesArgs;

/// One query's answer: the title, the columns and one row per real branch, and what to draw.
struct Listing {
    title: String,
    header: Vec<&'static str>,
    rows: Vec<Vec<Cell>>,
    sketches: Vec<BranchSketch>,
    /// For the 5-axis queries: each branch's table angles and tool tip (the 3D view's table).
    tables: Vec<Option<(f64, f64, Vector3<f64>)>>,
}

/// The columns every listing ends with: the verdict and the kinetostatic figures.
const FIGURES: [&str; 7] = [
    "working",
    "det_a",
    "lambda_min",
    "lambda_max",
    "parallel_margin",
    "serial_margin",
    "status",
];

pub fn run(args: &ModesArgs) -> Result<u8, VerneError> {
    if let Some(p) = args.plot.as_deref().filter(|p| !is_html(p)) {
        crate::plot::check_picture_path(p)?;
    } else if let Some(p) = &args.plot {
        crate::files::check_output_path(p)
            .map_err(|e| VerneError::io(&p.display().to_string(), e))?;
    }
    let machine = match load_mechanism(args.common.machine.as_deref())? {
        Mechanism::Glider(spec) => {
            refuse_for_glider(
                &spec.name,
                &[
                    ("--tool", args.tool.is_some()),
                    ("--machine-joints", args.machine_joints.is_some()),
                    ("--tool-length", args.tool_length.is_some()),
                ],
            )?;
            if args.plot.as_deref().is_some_and(is_html) {
                return Err(VerneError::Usage(format!(
                    "--plot FILE.html draws the VERNE machine in 3D; {} is a glider: draw its branches to FILE.svg or FILE.png",
                    spec.name
                )));
            }
            return super::glider::modes(args, spec);
        }
        Mechanism::Verne(m) => m,
    };
    let u = units(&args.common);
    let listing = if let Some(t) = args.tool {
        machine_ik_listing(&machine, &t, tool_length(args, &machine), u)?
    } else if let Some(j) = args.machine_joints {
        machine_fk_listing(&machine, &j, tool_length(args, &machine), u)
    } else {
        if args.tool_length.is_some() {
            return Err(VerneError::Usage(
                "--tool-length applies to the 5-axis machine's --tool and --machine-joints; the parallel module's --pose and --joints have no tool".into(),
            ));
        }
        module_listing(&machine, args)?
    };
    let text_rows: Vec<Vec<String>> = listing
        .rows
        .iter()
        .map(|r| r.iter().map(|c| cell_text(*c, u, args.csv)).collect())
        .collect();
    write_stdout(&render(
        &listing.title,
        &listing.header,
        &text_rows,
        args.csv,
    ))?;
    if let Some(path) = args.plot.as_deref().filter(|p| is_html(p)) {
        let branches: Vec<Branch3d> = listing
            .sketches
            .iter()
            .enumerate()
            .map(|(k, b)| Branch3d {
                label: b.label.clone(),
                detail: b.detail.clone(),
                working: b.working,
                pose: b.pose,
                rho: b.rho,
                table: listing.tables.get(k).copied().flatten(),
            })
            .collect();
        let page = crate::report::html::modes::page(
            &machine,
            tool_length(args, &machine),
            &listing.title,
            &branches,
        );
        crate::files::write_output(path, page.as_bytes())
            .map_err(|e| VerneError::io(&path.display().to_string(), e))?;
    } else if let Some(path) = &args.plot {
        branches_picture(path, &machine, &listing.title, &listing.sketches)
            .map_err(|e| VerneError::io(&path.display().to_string(), std::io::Error::other(e)))?;
    }
    Ok(if listing.rows.is_empty() {
        EXIT_ROWS_FAILED
    } else {
        EXIT_OK
    })
}

/// A `--plot` file that is an HTML page (the 3D views) rather than a picture.
fn is_html(p: &std::path::Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"))
}

fn tool_length(args: &ModesArgs, machine: &Machine) -> f64 {
    args.tool_length.unwrap_or(machine.tool_length)
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

/// An angle column's name with its unit.
fn angle_column(name: &'static str, u: Units) -> &'static str {
    // (name, in degrees, in radians)
    const ANGLES: [(&str, &str, &str); 5] = [
        ("alpha", "alpha_deg", "alpha_rad"),
        ("theta1", "theta1_deg", "theta1_rad"),
        ("theta2", "theta2_deg", "theta2_rad"),
        ("phi1", "phi1_deg", "phi1_rad"),
        ("phi2", "phi2_deg", "phi2_rad"),
    ];
    ANGLES
        .iter()
        .find(|(n, _, _)| *n == name)
        .map_or(name, |(_, deg, rad)| if u.radians { rad } else { deg })
}

/// The columns of [`module_cells`]: with the sliders or without (where they are the query).
fn module_columns(u: Units, sliders: bool) -> Vec<&'static str> {
    let mut c = vec!["xp", "yp", "zp", angle_column("alpha", u)];
    if sliders {
        c.extend(["rho1", "rho2", "rho3"]);
    }
    c.extend(["s1", "s2", "s3"]);
    c
}

/// The module's part of a row: platform point, alpha, sliders (when given), configuration.
fn module_cells(pose: &ModulePose, rho: Option<&Sliders>, config: Config) -> Vec<Cell> {
    let mut c = vec![
        Cell::Num(pose.p.x),
        Cell::Num(pose.p.y),
        Cell::Num(pose.p.z),
        Cell::Angle(pose.alpha),
    ];
    if let Some(rho) = rho {
        c.extend([Cell::Num(rho.x), Cell::Num(rho.y), Cell::Num(rho.z)]);
    }
    c.extend(config.map(|s| Cell::Int(s.into())));
    c
}

/// The figures that end every row: working, det A, the extreme amplification factors, the
/// singularity margins (constraints (3)-(6), kinetostatics.rs) and the status.
fn figure_cells(
    machine: &Machine,
    pose: &ModulePose,
    rho: &Sliders,
    verdict: Verdict,
) -> [Cell; 7] {
    let ks = kinetostatics(&machine.module, pose, rho);
    [
        Cell::Bool(verdict.feasible()),
        Cell::Num(ks.det_a),
        Cell::Num(ks.amplification[2]),
        Cell::Num(ks.amplification[0]),
        Cell::Num(ks.parallel_margin),
        Cell::Num(ks.serial_margin),
        Cell::Verdict(verdict),
    ]
}

fn sketch(label: String, pose: ModulePose, rho: Sliders, verdict: Verdict) -> BranchSketch {
    BranchSketch {
        pose,
        rho,
        label,
        detail: verdict.to_string(),
        working: verdict.feasible(),
    }
}

fn config_text(c: Config) -> String {
    format!("s=({},{},{})", c[0], c[1], c[2])
}

/// `--pose`: every inverse branch of the module; `--joints`: every assembly mode.
fn module_listing(machine: &Machine, args: &ModesArgs) -> Result<Listing, VerneError> {
    let (given, flag, names) = match (args.pose, args.joints) {
        (Some(p), _) => (p, "--pose", "XP,YP,ZP"),
        (None, Some(j)) => (j, "--joints", "R1,R2,R3"),
        (None, None) => unreachable!("clap requires one query"),
    };
    crate::arg_values::spatial(&[given], flag, names).map_err(VerneError::Usage)?;
    let u = units(&args.common);
    let mut header = vec!["branch"];
    header.extend(module_columns(u, true));
    header.extend(FIGURES);
    let mut listing = Listing {
        title: String::new(),
        header,
        rows: Vec::new(),
        sketches: Vec::new(),
        tables: Vec::new(),
    };
    let mut add = |pose: ModulePose, rho: Sliders, config: Config, verdict: Verdict| {
        let k = listing.rows.len() + 1;
        let mut row = vec![Cell::Int(k as i64)];
        row.extend(module_cells(&pose, Some(&rho), config));
        row.extend(figure_cells(machine, &pose, &rho, verdict));
        listing.rows.push(row);
        listing.sketches.push(sketch(
            format!("{k}: {}", config_text(config)),
            pose,
            rho,
            verdict,
        ));
    };
    let title = if flag == "--pose" {
        let p = Vector3::new(given[0], given[1], given[2]);
        let b = ik::solve(machine, &p);
        for br in b.iter() {
            add(
                ModulePose { p, alpha: br.alpha },
                br.rho,
                br.config,
                br.verdict,
            );
        }
        format!(
            "inverse kinematics of P = ({}, {}, {}) mm: {} real branches ({})",
            p.x,
            p.y,
            p.z,
            b.len(),
            proof(b.certificate)
        )
    } else {
        let rho = Sliders::new(given[0], given[1], given[2]);
        let m = fk::solve(machine, &rho);
        for md in m.iter() {
            add(md.pose, rho, md.config, md.verdict);
        }
        format!(
            "forward kinematics of rho = ({}, {}, {}) mm: {} real assembly modes ({})",
            given[0],
            given[1],
            given[2],
            m.len(),
            proof(m.certificate)
        )
    };
    listing.title = title;
    Ok(listing)
}

/// A number for a title: shortest exact form, or an angle in the run's unit.
fn title_angle(v: f64, u: Units) -> String {
    if u.radians {
        format!("{v} rad")
    } else {
        format!("{} deg", v.to_degrees())
    }
}

/// `--tool`: every branch of the 5-axis machine for one tool pose, over both orientation
/// solutions of the axis (AIM 2007, section III.C; orientation labels as `verne ik --all`).
fn machine_ik_listing(
    machine: &Machine,
    t: &[f64; 6],
    tool_length: f64,
    u: Units,
) -> Result<Listing, VerneError> {
    let tip = Vector3::new(t[0], t[1], t[2]);
    let axis = Vector3::new(t[3], t[4], t[5]);
    let candidates = path_candidates(
        machine,
        &tip,
        &ToolOrientation::Axis(axis),
        tool_length,
        None,
    )
    .map_err(|e| VerneError::Usage(format!("--tool {}: {e}", join(t))))?;
    let mut header = vec![
        "branch",
        "orientation",
        "rho1",
        "rho2",
        "rho3",
        angle_column("theta1", u),
        angle_column("theta2", u),
        angle_column("phi1", u),
        angle_column("phi2", u),
    ];
    header.extend(module_columns(u, false));
    header.extend(FIGURES);
    let mut rows = Vec::new();
    let mut sketches = Vec::new();
    let mut tables = Vec::new();
    for (k, (b, orientation, theta2)) in candidates.iter().enumerate() {
        tables.push(Some((b.theta1, theta2, tip)));
        let pose = ModulePose {
            p: b.platform,
            alpha: b.alpha,
        };
        // phi1 = alpha - theta1 (eq. (14)), phi2 = -theta2 (eq. (9)).
        let phi1 = verne::parallel_module::ik::wrap_angle(b.alpha - b.theta1);
        let mut row = vec![
            Cell::Int(k as i64 + 1),
            Cell::Int(orientation.into()),
            Cell::Num(b.rho.x),
            Cell::Num(b.rho.y),
            Cell::Num(b.rho.z),
            Cell::Angle(b.theta1),
            Cell::Angle(theta2),
            Cell::Angle(phi1),
            Cell::Angle(verne::parallel_module::ik::wrap_angle(-theta2)),
        ];
        row.extend(module_cells(&pose, None, b.config));
        row.extend(figure_cells(machine, &pose, &b.rho, b.verdict));
        rows.push(row);
        sketches.push(sketch(
            format!("{}: o{orientation} {}", k + 1, config_text(b.config)),
            pose,
            b.rho,
            b.verdict,
        ));
    }
    let over = if candidates.needs_previous() {
        "the axis is inside the rotary-axis singularity cone, so theta2 is free: theta2 = 0 taken"
            .to_string()
    } else {
        "over both orientation solutions of the axis".to_string()
    };
    let title = format!(
        "inverse kinematics of the tool pose: tip ({}, {}, {}) mm, axis ({}, {}, {}), tool length {} mm: {} real branches, {over} ({})",
        t[0],
        t[1],
        t[2],
        t[3],
        t[4],
        t[5],
        tool_length,
        rows.len(),
        proof(candidates.certificate)
    );
    Ok(Listing {
        title,
        header,
        rows,
        sketches,
        tables,
    })
}

/// `--machine-joints`: every assembly mode of the 5-axis machine with its tool pose (AIM 2007,
/// section III.D, eq. (26)).
fn machine_fk_listing(machine: &Machine, j: &[f64; 5], tool_length: f64, u: Units) -> Listing {
    let to_rad = |v: f64| if u.radians { v } else { v.to_radians() };
    let rho = Sliders::new(j[0], j[1], j[2]);
    let (theta1, theta2) = (to_rad(j[3]), to_rad(j[4]));
    let modes = machine_fk(machine, &rho, theta1, theta2, tool_length);
    let mut header = vec![
        "branch",
        "x",
        "y",
        "z",
        "i",
        "j",
        "k",
        angle_column("phi1", u),
        angle_column("phi2", u),
    ];
    header.extend(module_columns(u, false));
    header.extend(FIGURES);
    let mut rows = Vec::new();
    let mut sketches = Vec::new();
    let mut tables = Vec::new();
    for (k, m) in modes.iter().enumerate() {
        tables.push(Some((theta1, theta2, m.tool.tip)));
        let mut row = vec![Cell::Int(k as i64 + 1)];
        row.extend(machine_fk_parts(m).0);
        row.extend(module_cells(&m.module, None, m.config));
        row.extend(figure_cells(machine, &m.module, &rho, m.verdict));
        rows.push(row);
        sketches.push(sketch(
            format!("{}: {}", k + 1, config_text(m.config)),
            m.module,
            rho,
            m.verdict,
        ));
    }
    let title = format!(
        "forward kinematics of the machine joints rho = ({}, {}, {}) mm, theta1 = {}, theta2 = {}, tool length {} mm: {} real assembly modes ({})",
        j[0],
        j[1],
        j[2],
        title_angle(theta1, u),
        title_angle(theta2, u),
        tool_length,
        rows.len(),
        proof(modes.certificate)
    );
    Listing {
        title,
        header,
        rows,
        sketches,
        tables,
    }
}

fn join(v: &[f64]) -> String {
    v.iter().map(f64::to_string).collect::<Vec<_>>().join(",")
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
