//! `verne workspace -m GLIDER --sweep KEY=FROM..TO:N`: a glider's design sweep, one workspace
//! per value of a numeric key of its file (twice for a grid of two keys), into a CSV table of
//! the t-connected region's area (with its bracket and sampled estimate), S and the largest
//! square, and a picture of the area and S against the first key (docs/gliders.md).

use std::path::Path;
use std::time::Instant;

use csv::ByteRecord;
use verne::glider::{GliderSpec, Sampling, WorkspaceOptions};

use super::workspace::{GridSize, analyse, nodes_for};
use crate::cmd::{EXIT_OK, EXIT_ROWS_FAILED};
use crate::error::VerneError;
use crate::files::Sink;
use crate::plot::sweep::{SweepLabels, SweepPoint, sweep_picture};

/// The numeric keys of a glider file that a sweep can change.
pub const GLIDER_SWEEP_KEYS: [&str; 5] = ["alpha1_deg", "alpha2_deg", "l1", "l2", "l0"];

/// The table's columns after the keys.
const COLUMNS: [&str; 15] = [
    "region_area",
    "area_lo",
    "area_hi",
    "sampled_area",
    "sampled_half_width",
    "admissible_area",
    "s_area",
    "s_width",
    "s_height",
    "s_angle_deg",
    "square_area",
    "square_side",
    "nodes",
    "points_classified",
    "seconds",
];

const GLIDER_LABELS: SweepLabels = SweepLabels {
    volume_axis: "t-connected region's area (L^2)",
    volume_name: "area",
    box_axis: "S, largest rectangle (L^2)",
    bars: "bars: the area's bracket (cells all in the region .. touching it); S is exact on the grid",
};

/// `spec` with `key` set to `value`, checked as its file would be.
fn with_key(spec: &GliderSpec, key: &str, value: f64) -> Result<GliderSpec, VerneError> {
    let mut s = spec.clone();
    match key {
        "alpha1_deg" => s.alpha1 = value.to_radians(),
        "alpha2_deg" => s.alpha2 = value.to_radians(),
        "l1" => s.l1 = value,
        "l2" => s.l2 = value,
        "l0" => s.l0 = value,
        _ => {
            return Err(VerneError::Usage(format!(
                "--sweep {key}: a glider file's numeric keys are {}",
                GLIDER_SWEEP_KEYS.join(", ")
            )));
        }
    }
    let problems = s.validate();
    if let Some(p) = problems.first() {
        return Err(VerneError::Usage(format!(
            "--sweep {key}={value}: the glider is invalid: {}: {}",
            p.key, p.message
        )));
    }
    Ok(s)
}

/// Runs the sweep: every glider is built (and checked) first, then one workspace each, a row
/// each to `output` (stdout when `None`), a progress line each on stderr; `plot` draws the area
/// and S against the first key. Exit 1 when a workspace of the sweep is empty.
pub fn workspace_sweep(
    spec: &GliderSpec,
    sweeps: &[(String, f64, f64, usize)],
    size: GridSize,
    lambda_bounds: Option<[f64; 2]>,
    sampling: Sampling,
    output: Option<&Path>,
    plot: Option<&Path>,
) -> Result<u8, VerneError> {
    if sweeps.len() > 2 {
        return Err(VerneError::Usage(
            "--sweep: one or two keys (a grid of two)".into(),
        ));
    }
    if let Some(p) = plot {
        crate::plot::check_picture_path(p)?;
    }
    let points = crate::arg_values::sweep_points(sweeps);
    let keys: Vec<&str> = sweeps.iter().map(|s| s.0.as_str()).collect();
    let base = WorkspaceOptions {
        lambda_bounds,
        sampling,
        ..WorkspaceOptions::default()
    };
    // Every glider and its grid first: a value that makes an invalid glider stops the sweep
    // before it runs.
    let mut runs = Vec::with_capacity(points.len());
    for p in &points {
        let mut s = spec.clone();
        for (key, &v) in keys.iter().zip(p) {
            s = with_key(&s, key, v)?;
        }
        let nodes = nodes_for(&s, size, &base)?;
        runs.push((s, nodes));
    }
    let mut sink = Sink::create(output)?;
    let mut header: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    header.extend(COLUMNS.map(String::from));
    sink.write(&ByteRecord::from(header))?;
    let mut any_empty = false;
    let mut drawn = Vec::with_capacity(points.len());
    for (p, (s, nodes)) in points.iter().zip(&runs) {
        let start = Instant::now();
        let opts = WorkspaceOptions {
            nodes: *nodes,
            ..base.clone()
        };
        let (grid, rect, square) = analyse(s, &opts);
        let secs = start.elapsed().as_secs_f64();
        let e = grid.region_estimate;
        let mut row: Vec<String> = p.iter().map(|v| v.to_string()).collect();
        let num = |v: f64| format!("{v:.6}");
        row.extend(
            [
                grid.region_area(),
                e.lo,
                e.hi,
                e.sampled,
                e.half_width,
                grid.admissible_area(),
            ]
            .map(num),
        );
        match rect {
            Some(r) => row.extend([
                num(r.area()),
                num(r.width),
                num(r.height),
                format!("{:.0}", r.angle.to_degrees()),
            ]),
            None => {
                any_empty = true;
                row.extend(std::iter::repeat_n(String::new(), 4));
            }
        }
        match square {
            Some(q) => row.extend([num(q.area()), num(q.width)]),
            None => row.extend(std::iter::repeat_n(String::new(), 2)),
        }
        row.push(grid.nx.max(grid.ny).to_string());
        row.push(grid.classified.to_string());
        row.push(format!("{secs:.2}"));
        sink.write(&ByteRecord::from(row))?;
        drawn.push(SweepPoint {
            keys: p.clone(),
            volume_l: grid.region_area(),
            lo_l: e.lo,
            hi_l: e.hi,
            box_l: rect.map_or(f64::NAN, |r| r.area()),
            box_upper_l: rect.map_or(f64::NAN, |r| r.area()),
        });
        sayln!(
            "verne workspace: {}: area {:.6}, S {} in {secs:.1} s",
            keys.iter()
                .zip(p)
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(", "),
            grid.region_area(),
            rect.map_or("none".to_string(), |r| format!("{:.6}", r.area()))
        );
    }
    sink.finish()?;
    if let Some(path) = plot {
        let title = format!(
            "workspace of the glider `{}` against {}",
            spec.name,
            keys.join(" and ")
        );
        sweep_picture(path, &keys, &drawn, &title, &GLIDER_LABELS)
            .map_err(|e| VerneError::io(&path.display().to_string(), std::io::Error::other(e)))?;
    }
    Ok(if any_empty { EXIT_ROWS_FAILED } else { EXIT_OK })
}
