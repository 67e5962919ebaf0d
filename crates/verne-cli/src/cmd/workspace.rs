//! `verne workspace`: samples the workspace for each tool length asked, writes the grid points
//! CSV and the pictures, and prints the summary (stdout, or stderr when the CSV goes to stdout).

use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::error::VerneError;
use crate::files::Sink;
use crate::plot::sweep::{SweepPoint, VOLUME_LABELS, sweep_picture};
use crate::plot::{self, View};
use crate::report::workspace::{POINTS_HEADER, write_point};
use csv::ByteRecord;
use nalgebra::Vector3;
use verne::workspace::{
    self, Bounds, Constraint, Of, Outcome, PAPER_LAMBDA_BOUNDS, WorkspaceOptions, WorkspaceSummary,
};

use super::glider::workspace::GridSize;
use super::{EXIT_OK, EXIT_ROWS_FAILED, load_machine, units, write_stdout};
use crate::cli::{WorkspaceArgs, WorkspaceOf};
use verne::glider::Sampling;

/// Grid step of the VERNE workspace when `--step` is not given (mm).
const DEFAULT_STEP_MM: f64 = 10.0;

/// Below this step (mm), `verne workspace` samples adaptively unless told otherwise.
const ADAPTIVE_BELOW_MM: f64 = 5.0;

/// `verne workspace --sweep KEY=FROM..TO:N [--sweep KEY2=...]`: one adaptive workspace per
/// value (per pair of values), each machine read as a file over the given one (so every value
/// is validated as a machine file is), the table as CSV on -o or stdout.
fn run_sweep(
    args: &WorkspaceArgs,
    machine: &verne::spec::Machine,
    of: Of,
    step: f64,
    bounds: Option<Bounds>,
    lambda: [f64; 2],
) -> Result<u8, VerneError> {
    let keys: Vec<&str> = args.sweep.iter().map(|s| s.0.as_str()).collect();
    if let Some(key) = keys.iter().find(|k| !k.contains('.')) {
        return Err(VerneError::Usage(format!(
            "--sweep {key}: the key of a machine file, section.key (e.g. module.L1, \
             tool.length)"
        )));
    }
    if let Some(key) = keys.iter().find(|k| {
        !["module.", "limits.", "table.", "tool."]
            .iter()
            .any(|s| k.starts_with(s))
    }) {
        return Err(VerneError::Usage(format!(
            "--sweep {key}: the workspace depends on the keys of [module], [limits], [table] and [tool] only"
        )));
    }
    let points = crate::arg_values::sweep_points(&args.sweep);
    let base = machine.to_toml();
    let resolve = |_: &str| -> Result<(String, String), String> {
        Ok((base.clone(), "the machine swept".to_string()))
    };
    // Every machine first: a value that makes an invalid machine stops the sweep before it runs.
    let mut machines = Vec::with_capacity(points.len());
    for p in &points {
        // Each section once (two keys of one section, module.L1 and module.L2, share it).
        let mut text = String::from("base = \"swept\"\n");
        let mut sections: Vec<(&str, Vec<String>)> = Vec::new();
        for (key, v) in keys.iter().zip(p) {
            let (section, name) = key.split_once('.').unwrap_or(("", key));
            let line = format!("{name} = {v:?}");
            match sections.iter_mut().find(|(s, _)| *s == section) {
                Some((_, lines)) => lines.push(line),
                None => sections.push((section, vec![line])),
            }
        }
        for (section, lines) in sections {
            text.push_str(&format!("[{section}]\n{}\n", lines.join("\n")));
        }
        let label = keys
            .iter()
            .zip(p)
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(", ");
        // The problems are the swept values' own: named by the value, not by a line of the
        // text the sweep wrote.
        let m = verne::spec::Machine::from_str_on_base(&text, "--sweep", Some(&resolve)).map_err(
            |e| {
                let problems: Vec<String> = e
                    .problems
                    .iter()
                    .map(|p| format!("{}: {}", p.key, p.message))
                    .collect();
                VerneError::Usage(format!(
                    "--sweep {label}: not a valid machine: {}",
                    problems.join("; ")
                ))
            },
        )?;
        machines.push(m);
    }
    let mut sink = Sink::create(args.output.as_deref())?;
    let mut header: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    header.extend(
        [
            "volume_l",
            "bracket_lo_l",
            "bracket_hi_l",
            "sampled_l",
            "sampled_half_width_l",
            "xmin",
            "xmax",
            "ymin",
            "ymax",
            "zmin",
            "zmax",
            "largest_box_l",
            "largest_box_upper_l",
            "box_xmin",
            "box_xmax",
            "box_ymin",
            "box_ymax",
            "box_zmin",
            "box_zmax",
            "largest_cube_l",
            "largest_cube_upper_l",
            "points_classified",
            "seconds",
        ]
        .map(String::from),
    );
    // The binding constraints' shares of the lattice points outside.
    header.extend(
        Outcome::ALL[1..]
            .iter()
            .map(|o| format!("share_{}", o.code())),
    );
    sink.write(&ByteRecord::from(header))?;
    let mut any_empty = false;
    let mut drawn = Vec::with_capacity(points.len());
    for (p, m) in points.iter().zip(&machines) {
        let opts = options(of, m.tool_length, step, bounds, lambda);
        let start = Instant::now();
        let a = workspace::compute_adaptive(m, &opts, workspace::DEFAULT_COARSE_FACTOR, &|_| {})
            .map_err(VerneError::Usage)?;
        let secs = start.elapsed().as_secs_f64();
        let mut row: Vec<String> = p.iter().map(|v| v.to_string()).collect();
        row.push(format!("{:.4}", a.volume_mm3 * 1e-6));
        row.push(format!("{:.4}", a.volume_lo_mm3 * 1e-6));
        row.push(format!("{:.4}", a.volume_hi_mm3 * 1e-6));
        row.push(format!("{:.4}", a.volume_sampled_mm3 * 1e-6));
        row.push(format!("{:.4}", a.sampled_half_width_mm3 * 1e-6));
        match a.bbox {
            Some(b) => {
                for d in 0..3 {
                    row.push(b.min[d].to_string());
                    row.push(b.max[d].to_string());
                }
            }
            None => {
                any_empty = true;
                row.extend(std::iter::repeat_n(String::new(), 6));
            }
        }
        row.push(format!("{:.4}", a.largest_box_mm3 * 1e-6));
        row.push(format!("{:.4}", a.largest_box_upper_mm3 * 1e-6));
        match a.largest_box {
            Some(b) => {
                for d in 0..3 {
                    row.push(b.min[d].to_string());
                    row.push(b.max[d].to_string());
                }
            }
            None => row.extend(std::iter::repeat_n(String::new(), 6)),
        }
        row.push(format!("{:.4}", a.largest_cube_mm3 * 1e-6));
        row.push(format!("{:.4}", a.largest_cube_upper_mm3 * 1e-6));
        row.push(a.classified.to_string());
        row.push(format!("{secs:.2}"));
        let outside = (a.lattice_points - a.inside_points).max(1) as f64;
        row.extend(
            a.binding[1..]
                .iter()
                .map(|&n| format!("{:.4}", n as f64 / outside)),
        );
        sink.write(&ByteRecord::from(row))?;
        drawn.push(SweepPoint {
            keys: p.clone(),
            volume_l: a.volume_mm3 * 1e-6,
            lo_l: a.volume_lo_mm3 * 1e-6,
            hi_l: a.volume_hi_mm3 * 1e-6,
            box_l: if a.largest_box.is_some() {
                a.largest_box_mm3 * 1e-6
            } else {
                f64::NAN
            },
            box_upper_l: a.largest_box_upper_mm3 * 1e-6,
        });
        sayln!(
            "verne workspace: {}: {:.3} l in {secs:.1} s",
            keys.iter()
                .zip(p)
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(", "),
            a.volume_mm3 * 1e-6
        );
    }
    sink.finish()?;
    if let Some(path) = &args.plot {
        let title = format!(
            "{} workspace of `{}` against {}: adaptive, step {step} mm",
            of.name(),
            machine.name,
            keys.join(" and ")
        );
        sweep_picture(path, &keys, &drawn, &title, &VOLUME_LABELS)
            .map_err(|e| VerneError::io(&path.display().to_string(), std::io::Error::other(e)))?;
    }
    Ok(if any_empty { EXIT_ROWS_FAILED } else { EXIT_OK })
}

/// `verne workspace --adaptive`: one adaptive run per tool length, its summary on stdout.
fn run_adaptive(
    machine: &verne::spec::Machine,
    of: Of,
    lengths: &[f64],
    step: f64,
    bounds: Option<Bounds>,
    lambda: [f64; 2],
) -> Result<u8, VerneError> {
    let mut text = String::new();
    let mut any_empty = false;
    for &l in lengths {
        let opts = options(of, l, step, bounds, lambda);
        let start = Instant::now();
        let a =
            workspace::compute_adaptive(machine, &opts, workspace::DEFAULT_COARSE_FACTOR, &|_| {})
                .map_err(VerneError::Usage)?;
        let secs = start.elapsed().as_secs_f64();
        let tool = if of == Of::Platform {
            String::new()
        } else {
            format!(", tool length {l} mm")
        };
        let _ = writeln!(
            text,
            "{} workspace{tool} of `{}` ({}), adaptive: step {step} mm, coarse step {} mm",
            of.name(),
            machine.name,
            of.frame(),
            a.coarse_step
        );
        let _ = writeln!(
            text,
            "  volume             {:.4} l (inside points x step^3, as the uniform grid counts them)",
            a.volume_mm3 * 1e-6
        );
        let _ = writeln!(
            text,
            "  bracket            [{:.4}, {:.4}] l: cells all inside, plus the {} boundary cells of one step (width {:.3} %)",
            a.volume_lo_mm3 * 1e-6,
            a.volume_hi_mm3 * 1e-6,
            a.boundary_cells,
            if a.volume_mm3 > 0.0 {
                100.0 * a.error_bound_mm3() / a.volume_mm3
            } else {
                0.0
            }
        );
        if a.sampled_cells > 0 {
            let _ = writeln!(
                text,
                "  boundary sampled   {:.4} l +- {:.4} % (99.7 % confidence, Hoeffding): one pseudo-random point in each of {} boundary cells",
                a.volume_sampled_mm3 * 1e-6,
                100.0 * a.sampled_half_width_mm3 / a.volume_sampled_mm3.max(f64::MIN_POSITIVE),
                a.sampled_cells
            );
        }
        let _ = writeln!(
            text,
            "  points classified  {} of {} lattice points ({:.2} %), {secs:.1} s",
            a.classified,
            a.lattice_points,
            100.0 * a.classified as f64 / a.lattice_points as f64
        );
        if let Some(b) = a.bbox {
            let _ = writeln!(
                text,
                "  bounding box       x [{}, {}]  y [{}, {}]  z [{}, {}] mm{}",
                b.min.x,
                b.max.x,
                b.min.y,
                b.max.y,
                b.min.z,
                b.max.z,
                if a.touches_bounds {
                    " (touches the sampled box: widen --bounds)"
                } else {
                    ""
                }
            );
            // An exhaustive search (small lattices) is exact, as the uniform grid's: no bound.
            let found = |b: Option<Bounds>, v: f64, upper: f64| {
                b.map(|b| (b, v, (!a.box_exact).then_some(upper)))
            };
            largest_box_lines(
                &mut text,
                found(a.largest_box, a.largest_box_mm3, a.largest_box_upper_mm3),
                found(a.largest_cube, a.largest_cube_mm3, a.largest_cube_upper_mm3),
            );
        } else {
            any_empty = true;
            let _ = writeln!(text, "  no point inside");
        }
    }
    write_stdout(&text)?;
    Ok(if any_empty { EXIT_ROWS_FAILED } else { EXIT_OK })
}

pub fn run(args: &WorkspaceArgs) -> Result<u8, VerneError> {
    // Every output of the run, pictures of several tool lengths included, a file of its own.
    let mut outputs: Vec<(String, PathBuf)> = Vec::new();
    if let Some(o) = &args.output {
        outputs.push(("-o".into(), o.clone()));
    }
    if let Some(p) = &args.plot {
        if args.tool_length.len() > 1 && args.sweep.is_empty() {
            for &l in &args.tool_length {
                outputs.push((
                    format!("--plot (tool length {l})"),
                    plot_path(p, &args.tool_length, l),
                ));
            }
        } else {
            outputs.push(("--plot".into(), p.clone()));
        }
    }
    let named: Vec<(&str, &Path)> = outputs
        .iter()
        .map(|(o, p)| (o.as_str(), p.as_path()))
        .collect();
    crate::files::check_distinct_outputs(&named)?;
    if let Some(spec) = super::glider::load(args.common.machine.as_deref())? {
        // The options of the VERNE machine's workspace have no meaning for a planar glider:
        // refused, not ignored.
        let not_for_a_glider = [
            ("--of", args.of.is_some()),
            ("--tool-length", !args.tool_length.is_empty()),
            ("--bounds", args.bounds.is_some()),
            ("--inside-only", args.inside_only),
            ("--slice", !args.slice.is_empty()),
        ];
        if let Some((flag, _)) = not_for_a_glider.iter().find(|(_, given)| *given) {
            return Err(VerneError::Usage(format!(
                "{flag} applies to the VERNE machine's workspace, not to a glider's (`{}`): \
                 a glider's takes --step, --lambda, --adaptive or --uniform, --sweep, -o and \
                 --plot (docs/gliders.md)",
                spec.name
            )));
        }
        let sampling = match (args.adaptive, args.uniform) {
            (true, _) => Sampling::Adaptive,
            (_, true) => Sampling::Uniform,
            _ => Sampling::Auto,
        };
        let size = args.step.map_or(GridSize::Default, GridSize::Step);
        if !args.sweep.is_empty() {
            return super::glider::workspace_sweep(
                &spec,
                &args.sweep,
                size,
                Some(args.lambda.unwrap_or(PAPER_LAMBDA_BOUNDS)),
                sampling,
                args.output.as_deref(),
                args.plot.as_deref(),
            );
        }
        return super::glider::workspace(
            &spec,
            size,
            Some(args.lambda.unwrap_or(PAPER_LAMBDA_BOUNDS)),
            sampling,
            args.output.as_deref(),
            args.plot.as_deref(),
            units(&args.common),
        );
    }
    let machine = load_machine(args.common.machine.as_deref())?;
    let step = args.step.unwrap_or(DEFAULT_STEP_MM);
    let u = units(&args.common);
    let of = match args.of {
        Some(WorkspaceOf::Platform) => Of::Platform,
        Some(WorkspaceOf::Tool) => Of::Tool,
        Some(WorkspaceOf::Manufacturing) => Of::Manufacturing,
        None if !args.tool_length.is_empty() => Of::Tool,
        None => Of::Platform,
    };
    if of == Of::Platform && !args.tool_length.is_empty() {
        return Err(VerneError::Usage(
            "--tool-length applies to --of tool or --of manufacturing, not to the platform".into(),
        ));
    }
    let lengths: Vec<f64> = match of {
        Of::Platform => vec![0.0],
        _ if args.tool_length.is_empty() => vec![machine.tool_length],
        _ => args.tool_length.clone(),
    };
    if let Some(bad) = lengths.iter().find(|l| !l.is_finite()) {
        return Err(VerneError::Usage(format!(
            "--tool-length: `{bad}` is not a finite number of mm"
        )));
    }
    if let Some(p) = &args.plot {
        plot::check_picture_path(p)?;
    }
    let bounds = args.bounds.map(|b| Bounds {
        min: Vector3::new(b[0], b[2], b[4]),
        max: Vector3::new(b[1], b[3], b[5]),
    });
    let lambda = args.lambda.unwrap_or(PAPER_LAMBDA_BOUNDS);
    // Check every option before the first (possibly long) run.
    for &l in &lengths {
        let opts = options(of, l, step, bounds, lambda);
        workspace::grid_for(&machine, &opts).map_err(VerneError::Usage)?;
    }

    if !args.sweep.is_empty() {
        if args.uniform
            || !args.tool_length.is_empty()
            || args.sweep.len() > 2
            || of == Of::Platform && args.sweep.iter().any(|s| s.0 == "tool.length")
        {
            return Err(VerneError::Usage(
                "--sweep runs adaptive workspaces over one or two machine-file keys (tool.length with --of tool or manufacturing): no --uniform or --tool-length".into(),
            ));
        }
        return run_sweep(args, &machine, of, step, bounds, lambda);
    }
    let adaptive = match (args.adaptive, args.uniform) {
        (true, _) => true,
        (_, true) => false,
        _ => step < ADAPTIVE_BELOW_MM && args.output.is_none() && args.plot.is_none(),
    };
    if adaptive {
        if args.output.is_some() || args.plot.is_some() {
            return Err(VerneError::Usage(
                "--adaptive classifies only the points near the boundary: the points CSV (-o) and the pictures (--plot) need every grid point (--uniform)".into(),
            ));
        }
        return run_adaptive(&machine, of, &lengths, step, bounds, lambda);
    }
    let to_stdout = args.output.as_deref().is_some_and(|p| p.as_os_str() == "-");
    let mut sink = match &args.output {
        Some(p) => Some(Sink::create(Some(p.as_path()))?),
        None => None,
    };
    if let Some(s) = sink.as_mut() {
        s.write(&ByteRecord::from(POINTS_HEADER.to_vec()))?;
    }
    let mut rec = ByteRecord::new();
    let mut summaries = Vec::new();
    let mut text = String::new();
    for &l in &lengths {
        let opts = options(of, l, step, bounds, lambda);
        let grid = workspace::grid_for(&machine, &opts).map_err(VerneError::Usage)?;
        let bar = progress_bar(grid.len() as u64, of, l);
        let tick = |n: u64| {
            if let Some(b) = &bar {
                b.set_position(n);
            }
        };
        let tool = (of != Of::Platform).then_some(l);
        let start = Instant::now();
        let result = workspace::compute(&machine, &opts, &tick, |r| match sink.as_mut() {
            Some(s) if !args.inside_only || r.outcome == Outcome::Inside => {
                write_point(r, tool, u, &mut rec);
                s.write(&rec)
            }
            _ => Ok(()),
        });
        let elapsed = start.elapsed();
        if let Some(b) = &bar {
            b.finish_and_clear();
        }
        let ws = match result {
            Ok(Ok(ws)) => ws,
            Ok(Err(msg)) => return Err(VerneError::Usage(msg)),
            Err(e) => {
                if let Some(s) = sink.as_mut() {
                    s.discard();
                }
                return Err(e);
            }
        };
        if let Some(p) = &args.plot {
            let path = plot_path(p, &lengths, l);
            let views: Vec<View> = if args.slice.is_empty() {
                plot::default_views(&ws.summary)
            } else {
                let g = &ws.map.grid;
                for &(axis, value) in &args.slice {
                    let (lo, hi) = (g.coord(axis, 0), g.coord(axis, g.n[axis] - 1));
                    if value < lo - 0.5 * g.step || value > hi + 0.5 * g.step {
                        let nearest = if value < lo { lo } else { hi };
                        let name = ["x", "y", "z"][axis];
                        sayln!(
                            "verne workspace: --slice {name}={value} is outside the grid ({name} from {lo} to {hi} mm): the nearest slice, {name} = {nearest} mm, is drawn"
                        );
                    }
                }
                let mut v: Vec<View> = args
                    .slice
                    .iter()
                    .map(|&(axis, value)| View::Slice { axis, value })
                    .collect();
                v.extend([2, 1, 0].map(|axis| View::Projection { axis }));
                v
            };
            let title = format!(
                "{} workspace{}, step {} mm, {} ({}): {:.1} l",
                of.name(),
                tool.map(|t| format!(", tool length {} mm", fmt_num(t, 6)))
                    .unwrap_or_default(),
                step,
                machine.name,
                of.frame(),
                ws.summary.volume_litres()
            );
            plot::workspace_picture(&path, &ws.map, &ws.summary, &views, &title).map_err(|e| {
                VerneError::io(&path.display().to_string(), std::io::Error::other(e))
            })?;
        }
        describe(&mut text, &ws.summary, elapsed);
        summaries.push((ws.summary, elapsed));
    }
    if let Some(s) = sink {
        s.finish()?;
    }
    let mut out = String::new();
    let _ = writeln!(
        out,
        "verne workspace: {} ({}), machine {}",
        match of {
            Of::Platform => "platform point P",
            Of::Tool => "tool tip, eq. (27)",
            Of::Manufacturing => "tool tip with the table following the platform, eq. (26)",
        },
        of.frame(),
        machine.name
    );
    let s0 = &summaries[0].0;
    let _ = writeln!(
        out,
        "constraints: (i) leg-I rods cross, (ii) rod tilt <= {} deg, (iii) amplification factors in [{}, {}], (iv) strokes{}",
        fmt_num(machine.limits.rod_tilt_max.to_degrees(), 3),
        fmt_num(s0.lambda[0], 6),
        fmt_num(s0.lambda[1], 6),
        if of == Of::Manufacturing {
            format!(
                ", (v) theta1 = alpha in [{}, {}] deg",
                fmt_num(machine.limits.theta1_min.to_degrees(), 3),
                fmt_num(machine.limits.theta1_max.to_degrees(), 3)
            )
        } else {
            String::new()
        }
    );
    out.push_str(&text);
    if lengths.len() > 1 {
        let _ = writeln!(out, "\nvolume against tool length (step {} mm)", step);
        let _ = writeln!(
            out,
            "{:>14}  {:>10}  {:>10}  {:>15}  {:>8}",
            "tool_length_mm", "volume_l", "error_l", "largest_box_l", "time_s"
        );
        for (s, t) in &summaries {
            let bx = s.largest_box_size().map_or(0.0, |(_, v)| v * 1e-6);
            let _ = writeln!(
                out,
                "{:>14}  {:>10.2}  {:>10.2}  {:>15.2}  {:>8.1}",
                fmt_num(s.tool_length, 3),
                s.volume_litres(),
                s.volume_error_mm3() * 1e-6,
                bx,
                t.as_secs_f64()
            );
        }
    }
    if to_stdout {
        say!("{out}");
    } else {
        write_stdout(&out)?;
    }
    Ok(if summaries.iter().all(|(s, _)| s.inside > 0) {
        EXIT_OK
    } else {
        EXIT_ROWS_FAILED
    })
}

fn options(
    of: Of,
    l: f64,
    step: f64,
    bounds: Option<Bounds>,
    lambda: [f64; 2],
) -> WorkspaceOptions {
    WorkspaceOptions {
        of,
        tool_length: if of == Of::Platform { 0.0 } else { l },
        step,
        bounds,
        lambda,
    }
}

/// FILE.svg for one workspace; FILE-L50.svg for tool length 50 when several are asked.
fn plot_path(p: &Path, lengths: &[f64], l: f64) -> PathBuf {
    if lengths.len() <= 1 {
        return p.to_path_buf();
    }
    let stem = p
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = p
        .extension()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    p.with_file_name(format!("{stem}-L{}.{ext}", fmt_num(l, 3)))
}

/// A number with at most `decimals` decimals for a title or a file name; in exponent form from
/// 1e9 on (a number of 309 digits is no name).
fn fmt_num(v: f64, decimals: usize) -> String {
    if v.abs() >= 1e9 {
        return format!("{v:e}");
    }
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// The summary's lines of the largest box and cube inside: (corners in mm, volume in mm^3, and
/// for an adaptive run the volume none of the lattice exceeds).
fn largest_box_lines(
    out: &mut String,
    largest_box: Option<(Bounds, f64, Option<f64>)>,
    largest_cube: Option<(Bounds, f64, Option<f64>)>,
) {
    let bound = |what: &str, upper: Option<f64>| {
        upper.map_or(String::new(), |u| {
            format!(
                " (no {what} of the lattice is larger than {:.3} l)",
                u * 1e-6
            )
        })
    };
    match largest_box {
        Some((b, v, upper)) => {
            let e = b.max - b.min;
            let _ = writeln!(
                out,
                "  largest box        {}: {} x {} x {} mm = {:.3} l{}",
                range(&b),
                fmt_num(e.x, 3),
                fmt_num(e.y, 3),
                fmt_num(e.z, 3),
                v * 1e-6,
                bound("box", upper)
            );
        }
        None => {
            let _ = writeln!(out, "  largest box        (none with positive volume)");
        }
    }
    match largest_cube {
        Some((b, v, upper)) => {
            let _ = writeln!(
                out,
                "  largest cube       {}: edge {} mm = {:.3} l{}",
                range(&b),
                fmt_num(b.max.x - b.min.x, 3),
                v * 1e-6,
                bound("cube", upper)
            );
        }
        None => {
            let _ = writeln!(out, "  largest cube       (none with positive volume)");
        }
    }
}

fn range(b: &Bounds) -> String {
    format!(
        "x [{}, {}]  y [{}, {}]  z [{}, {}] mm",
        fmt_num(b.min.x, 3),
        fmt_num(b.max.x, 3),
        fmt_num(b.min.y, 3),
        fmt_num(b.max.y, 3),
        fmt_num(b.min.z, 3),
        fmt_num(b.max.z, 3)
    )
}

fn describe(out: &mut String, s: &WorkspaceSummary, elapsed: Duration) {
    let g = &s.grid;
    let _ = writeln!(out);
    match s.of {
        Of::Platform => {
            let _ = writeln!(out, "platform workspace");
        }
        _ => {
            let _ = writeln!(out, "tool length {} mm", fmt_num(s.tool_length, 3));
        }
    }
    let _ = writeln!(
        out,
        "  grid               step {} mm over {}: {} x {} x {} = {} points",
        fmt_num(g.step, 6),
        range(&Bounds {
            min: g.origin,
            max: g.max()
        }),
        g.n[0],
        g.n[1],
        g.n[2],
        s.points
    );
    let _ = writeln!(
        out,
        "  volume             {:.3} l = {:.6e} mm^3 ({} points inside x step^3)",
        s.volume_litres(),
        s.volume_mm3,
        s.inside
    );
    let _ = writeln!(
        out,
        "  error estimate     +-{:.3} l (|V(h) - V(2h)|, V(2h) = {:.3} l on the even-index subgrid)",
        s.volume_error_mm3() * 1e-6,
        s.volume_double_step_mm3 * 1e-6
    );
    match &s.bbox {
        Some(b) => {
            let _ = writeln!(out, "  bounding box       {}", range(b));
        }
        None => {
            let _ = writeln!(out, "  bounding box       (empty workspace)");
        }
    }
    let found = |b: Option<(Bounds, f64)>| b.map(|(b, v)| (b, v, None));
    largest_box_lines(
        out,
        found(s.largest_box_size()),
        found(s.largest_cube_size()),
    );
    if s.touches_bounds {
        let _ = writeln!(
            out,
            "  warning            inside points lie on the grid's faces: the bounds cut the workspace"
        );
    }
    let _ = writeln!(
        out,
        "  {:<40} {:>12} {:>12}",
        "constraint", "binding", "fails"
    );
    for o in Outcome::ALL {
        let fails = match o {
            Outcome::Bound(c) => s.failures[c as usize].to_string(),
            _ => String::new(),
        };
        if let Outcome::Bound(Constraint::Theta1Range) = o
            && s.of != Of::Manufacturing
        {
            continue;
        }
        let _ = writeln!(
            out,
            "    {:<38} {:>12} {:>12}",
            o.label(),
            s.binding[o.index()],
            fails
        );
    }
    let secs = elapsed.as_secs_f64();
    let _ = writeln!(
        out,
        "  time               {:.2} s, {:.0} points/s, {} threads",
        secs,
        s.points as f64 / secs.max(1e-9),
        rayon::current_num_threads()
    );
}

/// A bar over the grid points, shown only when stderr is a terminal.
fn progress_bar(total: u64, of: Of, l: f64) -> Option<indicatif::ProgressBar> {
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(total);
    let label = match of {
        Of::Platform => "platform".to_string(),
        _ => format!("{} L={l}", of.name()),
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{prefix} {bar:30} {pos}/{len} points ({per_sec}, eta {eta})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_prefix(label);
    bar.enable_steady_tick(Duration::from_millis(200));
    Some(bar)
}
