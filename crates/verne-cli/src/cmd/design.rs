//! `verne design`: the comparative study of the glider architectures (section 3, Wenger 2001):
//! Table 1 (L0, delta-rho per L, S per L^2) and Table 2 (dimensions and envelope for a 1 m^2
//! rectangle, then a square), computed beside the paper's printed values.

use crate::error::VerneError;
use crate::table::format_number;
use verne::glider::{
    Architecture, DesignOptions, PAPER_LAMBDA_BOUNDS, Table1Row, Table2Row, table1_row, table2,
};

use super::{EXIT_OK, EXIT_ROWS_FAILED, write_stdout};
use crate::cli::DesignArgs;
use crate::report::text_table::{aligned, csv_text};

/// Bounds within this relative difference of 1/3 and 3 are the paper's, and its values apply.
/// Dimensionless.
const PAPER_BOUNDS_MATCH_REL: f64 = 1e-9;

/// Area of the prescribed workspace of Table 2 (m^2), as in the paper.
const TARGET_AREA_M2: f64 = 1.0;

/// Decimals of the aligned Table 1 (multiples of L) and Table 2 (m, m^2).
const TABLE1_DECIMALS: usize = 5;
const TABLE2_DECIMALS: usize = 3;

/// Most decimals tried to print a paper value exactly.
const DECIMALS_MAX: usize = 6;

/// Header of `--csv`.
pub const CSV_HEADER: [&str; 8] = [
    "table",
    "mechanism",
    "target",
    "quantity",
    "unit",
    "computed",
    "paper",
    "rel_diff",
];

pub fn run(args: &DesignArgs) -> Result<u8, VerneError> {
    let opts = DesignOptions {
        bounds: args.bounds,
        nodes: args.nodes as usize,
        target_area: TARGET_AREA_M2,
        ..DesignOptions::default()
    };
    let is_paper = args
        .bounds
        .iter()
        .zip(PAPER_LAMBDA_BOUNDS)
        .all(|(a, b)| ((a - b) / b).abs() <= PAPER_BOUNDS_MATCH_REL);
    let mut rows: Vec<Table1Row> = Vec::new();
    let mut missing = Vec::new();
    for arch in Architecture::ALL {
        match table1_row(arch, &opts) {
            Some(r) => rows.push(r),
            None => missing.push(arch.name()),
        }
    }
    let mut t2 = table2(&rows, opts.target_area);
    if !is_paper {
        for r in &mut rows {
            r.l0_rel_diff = f64::NAN;
            r.delta_rho_rel_diff = f64::NAN;
            r.s_rel_diff = f64::NAN;
        }
        for r in &mut t2 {
            r.l0_paper = None;
            r.l_paper = None;
            r.delta_rho_paper = None;
            r.envelope_paper = None;
            r.l0_rel_diff = None;
            r.l_rel_diff = None;
            r.delta_rho_rel_diff = None;
            r.envelope_rel_diff = None;
        }
    }
    let text = if args.csv {
        csv_output(&rows, &t2, args.l, is_paper)
    } else {
        human_output(&rows, &t2, args, is_paper)
    };
    write_stdout(&text)?;
    if !is_paper {
        sayln!(
            "verne design: bounds {},{} are not the paper's 1/3,3: its values are not shown",
            args.bounds[0],
            args.bounds[1]
        );
    }
    for name in &missing {
        sayln!(
            "verne design: {name}: no dimensions meet {} <= lambda_i <= {} at the \
             configurations of section 3.2",
            args.bounds[0],
            args.bounds[1]
        );
    }
    Ok(if missing.is_empty() {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

fn num(v: f64) -> String {
    let mut out = Vec::new();
    format_number(&mut out, v, None);
    String::from_utf8_lossy(&out).into_owned()
}

fn fixed(v: f64, decimals: usize) -> String {
    format!("{v:.decimals$}")
}

/// A relative difference as a signed percentage, `-` when there is no paper value.
fn percent(d: Option<f64>) -> String {
    match d {
        Some(d) if d.is_finite() => format!("{:+.2} %", 100.0 * d),
        _ => "-".into(),
    }
}

/// A paper value with at least `decimals` decimals (2.00, not 2), more if it has them.
fn paper_text(p: Option<f64>, decimals: usize) -> String {
    let Some(v) = p else { return "-".into() };
    (decimals..=DECIMALS_MAX)
        .map(|d| fixed(v, d))
        .find(|t| t.parse::<f64>() == Ok(v))
        .unwrap_or_else(|| v.to_string())
}

fn human_output(t1: &[Table1Row], t2: &[Table2Row], args: &DesignArgs, is_paper: bool) -> String {
    let [lo, hi] = args.bounds;
    let bounds = if is_paper {
        "1/3 <= lambda_i <= 3".to_string()
    } else {
        format!("{lo} <= lambda_i <= {hi}")
    };
    let p1 = |v: f64| if is_paper { Some(v) } else { None };
    let d1 = |v: f64| if is_paper { Some(v) } else { None };
    let mut header = vec![
        "mechanism",
        "L0 (L)",
        "paper",
        "diff",
        "delta-rho (L)",
        "paper",
        "diff",
        "S (L^2)",
        "paper",
        "diff",
        "S sides (L)",
        "S angle",
    ];
    if args.l.is_some() {
        header.extend(["L0 (mm)", "delta-rho (mm)", "S (mm^2)"]);
    }
    let rows: Vec<Vec<String>> = t1
        .iter()
        .map(|r| {
            let mut v = vec![
                r.mechanism.clone(),
                fixed(r.l0, TABLE1_DECIMALS),
                paper_text(p1(r.l0_paper), 3),
                percent(d1(r.l0_rel_diff)),
                fixed(r.delta_rho, TABLE1_DECIMALS),
                paper_text(p1(r.delta_rho_paper), 3),
                percent(d1(r.delta_rho_rel_diff)),
                fixed(r.s, TABLE1_DECIMALS),
                paper_text(p1(r.s_paper), 3),
                percent(d1(r.s_rel_diff)),
                format!("{:.3} x {:.3}", r.s_width, r.s_height),
                format!("{:.0} deg", r.s_angle_deg),
            ];
            if let Some(l) = args.l {
                v.extend([
                    fixed(r.l0 * l, 1),
                    fixed(r.delta_rho * l, 1),
                    fixed(r.s * l * l, 0),
                ]);
            }
            v
        })
        .collect();
    let mut t = format!(
        "Table 1 (Wenger 2001): multiples of the strut length L; {bounds} (eq. (4)); S on \
         a {}-node grid\n",
        args.nodes
    );
    if let Some(l) = args.l {
        t.push_str(&format!("with L = {l} mm\n"));
    }
    t.push_str(&aligned(&header, &rows, &[0]));

    let header2 = [
        "mechanism",
        "target",
        "L0 (m)",
        "paper",
        "diff",
        "L (m)",
        "paper",
        "diff",
        "delta-rho (m)",
        "paper",
        "diff",
        "envelope (m^2)",
        "paper",
        "diff",
    ];
    let rows2: Vec<Vec<String>> = t2
        .iter()
        .map(|r| {
            vec![
                r.mechanism.clone(),
                r.target.name().to_string(),
                fixed(r.l0, TABLE2_DECIMALS),
                paper_text(r.l0_paper, 2),
                percent(r.l0_rel_diff),
                fixed(r.l, TABLE2_DECIMALS),
                paper_text(r.l_paper, 2),
                percent(r.l_rel_diff),
                fixed(r.delta_rho, TABLE2_DECIMALS),
                paper_text(r.delta_rho_paper, 2),
                percent(r.delta_rho_rel_diff),
                fixed(r.envelope, TABLE2_DECIMALS),
                paper_text(r.envelope_paper, 2),
                percent(r.envelope_rel_diff),
            ]
        })
        .collect();
    t.push_str(&format!(
        "\nTable 2 (Wenger 2001): m and m^2 for a workspace of {TARGET_AREA_M2} m^2, a \
         rectangle then a square (section 3.3)\n"
    ));
    t.push_str(&aligned(&header2, &rows2, &[0, 1]));
    t
}

fn csv_output(t1: &[Table1Row], t2: &[Table2Row], l: Option<f64>, is_paper: bool) -> String {
    let mut rows: Vec<Vec<String>> = Vec::new();
    let mut push = |table: &str,
                    mech: &str,
                    target: &str,
                    quantity: &str,
                    unit: &str,
                    computed: f64,
                    paper: Option<f64>,
                    diff: Option<f64>| {
        rows.push(vec![
            table.to_string(),
            mech.to_string(),
            target.to_string(),
            quantity.to_string(),
            unit.to_string(),
            num(computed),
            paper.map_or(String::new(), num),
            diff.filter(|d| d.is_finite()).map_or(String::new(), num),
        ]);
    };
    for r in t1 {
        let m = r.mechanism.as_str();
        let p = |v: f64| if is_paper { Some(v) } else { None };
        push("1", m, "", "l0", "L", r.l0, p(r.l0_paper), p(r.l0_rel_diff));
        push(
            "1",
            m,
            "",
            "delta_rho",
            "L",
            r.delta_rho,
            p(r.delta_rho_paper),
            p(r.delta_rho_rel_diff),
        );
        push("1", m, "", "s", "L^2", r.s, p(r.s_paper), p(r.s_rel_diff));
        push("1", m, "", "s_width", "L", r.s_width, None, None);
        push("1", m, "", "s_height", "L", r.s_height, None, None);
        push("1", m, "", "s_angle", "deg", r.s_angle_deg, None, None);
        push("1", m, "", "square", "L^2", r.square, None, None);
        push("1", m, "", "envelope", "L^2", r.envelope, None, None);
        if let Some(l) = l {
            push("1", m, "", "l0", "mm", r.l0 * l, None, None);
            push("1", m, "", "delta_rho", "mm", r.delta_rho * l, None, None);
            push("1", m, "", "s", "mm^2", r.s * l * l, None, None);
        }
    }
    for r in t2 {
        let (m, target) = (r.mechanism.as_str(), r.target.name());
        push("2", m, target, "l0", "m", r.l0, r.l0_paper, r.l0_rel_diff);
        push("2", m, target, "l", "m", r.l, r.l_paper, r.l_rel_diff);
        push(
            "2",
            m,
            target,
            "delta_rho",
            "m",
            r.delta_rho,
            r.delta_rho_paper,
            r.delta_rho_rel_diff,
        );
        push(
            "2",
            m,
            target,
            "envelope",
            "m^2",
            r.envelope,
            r.envelope_paper,
            r.envelope_rel_diff,
        );
    }
    csv_text(&CSV_HEADER, &rows)
}
