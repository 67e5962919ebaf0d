//! Pictures (SVG or PNG, by the file's extension, drawn with plotters): workspace slices and
//! projections coloured by binding constraint, and schematics of the branches of one query
//! (sliders, rods, platform; compare Figs. 5-6, AIM 2007); the gliders' pictures are in
//! [`glider`].
//!
//! Files are written to a temporary file beside the target and renamed into place. PNG text is
//! drawn with DejaVu Sans, embedded from `assets/fonts/` (Bitstream Vera licence, which allows
//! redistribution with software; see `assets/fonts/LICENSE-DejaVu.txt`).

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use verne::parallel_module::equations::{ModulePose, Sliders, rod_vectors};
use verne::spec::Machine;
use verne::workspace::{Bounds, Outcome, OutcomeGrid, WorkspaceSummary};

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
const FAMILY: &str = "sans-serif";
static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The embedded file is a valid font (tested); a failure would only lose the labels.
        let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
    });
}

/// Picture formats, from the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

impl Format {
    pub fn of_path(path: &Path) -> Result<Format, String> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(format!(
                "{}: a picture file must end in .svg or .png",
                path.display()
            )),
        }
    }
}

/// Colour of an outcome in every picture.
pub fn outcome_color(o: Outcome) -> RGBColor {
    use verne::workspace::Constraint::*;
    match o {
        Outcome::Inside => RGBColor(46, 160, 67),
        Outcome::Bound(RodsCross) => RGBColor(148, 103, 189),
        Outcome::Bound(RodTilt) => RGBColor(255, 140, 0),
        Outcome::Bound(Singularity) => RGBColor(214, 39, 40),
        Outcome::Bound(Stroke) => RGBColor(31, 119, 180),
        Outcome::Bound(Theta1Range) => RGBColor(140, 86, 75),
        Outcome::OutOfReach => RGBColor(235, 235, 235),
    }
}

/// A drawing's I/O error, for a caller that names the file ([`check_picture_path`]'s callers).
fn io_err(_path: &Path, e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// Checks a picture's path before anything is computed: a known extension, a directory that
/// exists, not a read-only file (the same check as every output).
pub fn check_picture_path(path: &Path) -> Result<(), crate::error::VerneError> {
    use crate::error::VerneError;
    Format::of_path(path).map_err(VerneError::Usage)?;
    crate::files::check_output_path(path)
        .map_err(|e| VerneError::io(&path.display().to_string(), e))
}

/// Draws with `$draw(&root)` on an SVG or PNG backend of `$size` and writes `$path` atomically.
macro_rules! render {
    ($path:expr, $size:expr, $draw:expr) => {{
        let path: &Path = $path;
        register_font();
        // A device or a FIFO is written in place (see `files::output_destination`).
        let dest = crate::files::output_destination(path);
        match Format::of_path(path)
            .map_err(|_| String::from("a picture file must end in .svg or .png"))?
        {
            Format::Svg => {
                let mut text = String::new();
                {
                    let root = SVGBackend::with_string(&mut text, $size).into_drawing_area();
                    $draw(&root)?;
                    root.present().map_err(|e| io_err(path, e))?;
                }
                crate::files::write_output(path, text.as_bytes()).map_err(|e| io_err(path, e))
            }
            Format::Png => {
                // The bitmap encoder picks the format from the extension: keep it.
                let tmp = if dest.in_place {
                    dest.path.clone()
                } else {
                    crate::files::remove_stale_temps(&dest.path);
                    let ext = dest
                        .path
                        .extension()
                        .map(|e| format!(".{}", e.to_string_lossy()))
                        .unwrap_or_default();
                    crate::files::temp_path_for(&dest.path, &ext)
                };
                let drawn = (|| -> Result<(), String> {
                    let root = BitMapBackend::new(&tmp, $size).into_drawing_area();
                    $draw(&root)?;
                    root.present().map_err(|e| io_err(path, e))
                })();
                if dest.in_place {
                    drawn
                } else {
                    drawn
                        .and_then(|_| {
                            std::fs::rename(&tmp, &dest.path).map_err(|e| io_err(path, e))
                        })
                        .map_err(|e| {
                            let _ = std::fs::remove_file(&tmp);
                            e
                        })
                }
            }
        }
    }};
}

pub mod glider;
pub mod sweep;

fn drawing<E: std::fmt::Display>(e: E) -> String {
    format!("drawing: {e}")
}

/// Legend entries, in a row (wrapping), under the title: (swatch, outline only, label).
fn draw_title_and_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    entries: &[(RGBColor, bool, String)],
) -> Result<(), String> {
    let (width, _) = area.dim_in_pixel();
    area.draw(&Text::new(title.to_string(), (10, 8), (FAMILY, 15)))
        .map_err(drawing)?;
    let (mut x, mut y) = (10, 36);
    for (colour, outline, label) in entries {
        let w = 30 + 7 * label.len() as i32;
        if x + w > width as i32 - 10 && x > 10 {
            (x, y) = (10, y + 22);
        }
        let swatch = [(x, y), (x + 14, y + 14)];
        if *outline {
            area.draw(&Rectangle::new(swatch, colour.stroke_width(2)))
                .map_err(drawing)?;
        } else {
            area.draw(&Rectangle::new(swatch, colour.filled()))
                .map_err(drawing)?;
            area.draw(&Rectangle::new(swatch, BLACK)).map_err(drawing)?;
        }
        area.draw(&Text::new(label.clone(), (x + 20, y), (FAMILY, 13)))
            .map_err(drawing)?;
        x += w;
    }
    Ok(())
}

/// A panel of a workspace picture: a slice through the grid or a projection along an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    /// Grid points with coordinate `axis` (0 x, 1 y, 2 z) nearest `value` (mm).
    Slice { axis: usize, value: f64 },
    /// Every grid point projected along `axis`: inside where any point of the line is inside,
    /// else the most frequent binding constraint on the line (ties: order of `Outcome::ALL`),
    /// else out of reach.
    Projection { axis: usize },
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// The two in-plane axes of a view (horizontal, vertical).
fn plane(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Outcome of every cell of a view: (index along horizontal axis, vertical axis) -> outcome.
fn view_cells(map: &OutcomeGrid, view: View) -> (usize, usize, Vec<Outcome>, String) {
    let g = &map.grid;
    let axis = match view {
        View::Slice { axis, .. } | View::Projection { axis } => axis,
    };
    let (a, b) = plane(axis);
    let (na, nb, nc) = (g.n[a], g.n[b], g.n[axis]);
    let idx = |ia: usize, ib: usize, ic: usize| {
        let mut ijk = [0usize; 3];
        ijk[a] = ia;
        ijk[b] = ib;
        ijk[axis] = ic;
        g.index(ijk[0], ijk[1], ijk[2])
    };
    let mut cells = Vec::with_capacity(na * nb);
    let title;
    match view {
        View::Slice { value, .. } => {
            let ic = ((value - g.origin[axis]) / g.step)
                .round()
                .clamp(0.0, (nc - 1) as f64) as usize;
            title = format!("slice {} = {} mm", AXES[axis], g.coord(axis, ic));
            for ib in 0..nb {
                for ia in 0..na {
                    cells.push(map.outcome[idx(ia, ib, ic)]);
                }
            }
        }
        View::Projection { .. } => {
            title = format!("projection along {}", AXES[axis]);
            for ib in 0..nb {
                for ia in 0..na {
                    let mut counts = [0u64; 7];
                    for ic in 0..nc {
                        counts[map.outcome[idx(ia, ib, ic)].index()] += 1;
                    }
                    let o = if counts[0] > 0 {
                        Outcome::Inside
                    } else {
                        let mut best = 6;
                        for k in 1..6 {
                            if counts[k] > 0 && (best == 6 || counts[k] > counts[best]) {
                                best = k;
                            }
                        }
                        Outcome::ALL[best]
                    };
                    cells.push(o);
                }
            }
        }
    }
    (na, nb, cells, title)
}

fn draw_view<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    map: &OutcomeGrid,
    summary: &WorkspaceSummary,
    view: View,
) -> Result<(), String> {
    let g = &map.grid;
    let axis = match view {
        View::Slice { axis, .. } | View::Projection { axis } => axis,
    };
    let (a, b) = plane(axis);
    let (na, nb, cells, title) = view_cells(map, view);
    let h = g.step;
    let (a0, a1) = (g.origin[a] - h / 2.0, g.coord(a, na - 1) + h / 2.0);
    let (b0, b1) = (g.origin[b] - h / 2.0, g.coord(b, nb - 1) + h / 2.0);
    // z points down in the base frame: draw it downward.
    let (v0, v1) = if b == 2 && map.of != verne::workspace::Of::Manufacturing {
        (b1, b0)
    } else {
        (b0, b1)
    };
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("drawing: {e}");
    let mut chart = ChartBuilder::on(area)
        .caption(&title, (FAMILY, 16))
        .margin(8)
        .x_label_area_size(34)
        .y_label_area_size(52)
        .build_cartesian_2d(a0..a1, v0..v1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(format!("{} (mm)", AXES[a]))
        .y_desc(format!("{} (mm)", AXES[b]))
        .label_style((FAMILY, 12))
        .axis_desc_style((FAMILY, 13))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(e)?;
    // One rectangle per run of equal outcomes along a row (keeps SVG files small).
    let mut rects = Vec::new();
    for ib in 0..nb {
        let mut ia = 0;
        while ia < na {
            let o = cells[ib * na + ia];
            let mut end = ia + 1;
            while end < na && cells[ib * na + end] == o {
                end += 1;
            }
            if o != Outcome::OutOfReach {
                let y = g.coord(b, ib);
                rects.push(Rectangle::new(
                    [
                        (g.coord(a, ia) - h / 2.0, y - h / 2.0),
                        (g.coord(a, end - 1) + h / 2.0, y + h / 2.0),
                    ],
                    outcome_color(o).filled(),
                ));
            }
            ia = end;
        }
    }
    chart.draw_series(rects).map_err(e)?;
    // The largest inside box, where the view meets it.
    if let Some((bx, _)) = summary.largest_box_size() {
        let shows = match view {
            View::Projection { .. } => true,
            View::Slice { value, .. } => {
                let ic = ((value - g.origin[axis]) / h)
                    .round()
                    .clamp(0.0, (g.n[axis] - 1) as f64) as usize;
                let c = g.coord(axis, ic);
                c >= bx.min[axis] - 1e-9 && c <= bx.max[axis] + 1e-9
            }
        };
        if shows {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(bx.min[a], bx.min[b]), (bx.max[a], bx.max[b])],
                    BLACK.stroke_width(2),
                )))
                .map_err(e)?;
        }
    }
    Ok(())
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    summary: &WorkspaceSummary,
    title: &str,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("drawing: {e}");
    area.draw(&Text::new(title.to_string(), (10, 6), (FAMILY, 16)))
        .map_err(e)?;
    let mut x = 10;
    for o in Outcome::ALL {
        let n = summary.binding[o.index()];
        if n == 0 && o != Outcome::Inside {
            continue;
        }
        area.draw(&Rectangle::new(
            [(x, 32), (x + 14, 46)],
            outcome_color(o).filled(),
        ))
        .map_err(e)?;
        area.draw(&Rectangle::new([(x, 32), (x + 14, 46)], BLACK))
            .map_err(e)?;
        let label = format!("{} ({n})", o.label());
        area.draw(&Text::new(label.clone(), (x + 20, 32), (FAMILY, 13)))
            .map_err(e)?;
        x += 40 + 7 * label.len() as i32;
    }
    area.draw(&Rectangle::new(
        [(x, 32), (x + 14, 46)],
        BLACK.stroke_width(2),
    ))
    .map_err(e)?;
    area.draw(&Text::new(
        "largest box".to_string(),
        (x + 20, 32),
        (FAMILY, 13),
    ))
    .map_err(e)?;
    Ok(())
}

/// Writes a workspace picture to `path` (.svg or .png): one panel per view (slices first, then
/// projections, three per row), every cell coloured by its outcome, the largest inside box
/// outlined in black, and a legend with the point count of each outcome.
pub fn workspace_picture(
    path: &Path,
    map: &OutcomeGrid,
    summary: &WorkspaceSummary,
    views: &[View],
    title: &str,
) -> Result<(), String> {
    if views.is_empty() || map.grid.is_empty() {
        return Err("nothing to draw".into());
    }
    let cols = views.len().min(3);
    let rows = views.len().div_ceil(3);
    let size = (460 * cols as u32, 430 * rows as u32 + 60);
    render!(
        path,
        size,
        |root: &DrawingArea<_, Shift>| -> Result<(), String> {
            root.fill(&WHITE).map_err(|e| format!("drawing: {e}"))?;
            let (top, body) = root.split_vertically(60);
            draw_legend(&top, summary, title)?;
            let panels = body.split_evenly((rows, cols));
            for (panel, view) in panels.iter().zip(views) {
                draw_view(panel, map, summary, *view)?;
            }
            Ok(())
        }
    )
}

/// Views of the default workspace picture: three horizontal slices at 1/4, 1/2 and 3/4 of the
/// inside points' z range (of the grid's, when nothing is inside), then the projections along
/// z, y and x.
pub fn default_views(summary: &WorkspaceSummary) -> Vec<View> {
    let g = &summary.grid;
    let (z0, z1) = match summary.bbox {
        Some(Bounds { min, max }) => (min.z, max.z),
        None => (g.origin.z, g.max().z),
    };
    let mut v: Vec<View> = [0.25, 0.5, 0.75]
        .iter()
        .map(|f| View::Slice {
            axis: 2,
            value: z0 + f * (z1 - z0),
        })
        .collect();
    v.extend([2, 1, 0].map(|axis| View::Projection { axis }));
    v
}

/// One branch to draw in a schematic.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchSketch {
    pub pose: ModulePose,
    pub rho: Sliders,
    /// Panel title, e.g. `3: s=(-1,-1,-1)`.
    pub label: String,
    /// A smaller line under the title, e.g. the verdict `leg1_inverted;rho1_stroke` (`;` are
    /// shown as `, `, and the line is wrapped to the panel).
    pub detail: String,
    /// Drawn with a highlighted frame (the machine's branch).
    pub working: bool,
}

/// Writes a schematic of every branch of one query to `path` (.svg or .png): one panel per
/// branch, four per row, each a front view (y to the right, z down, looking along +x) of the
/// slider guideways (dashed, over the strokes of the machine file), the slider attachments A,
/// the rods (leg I: two rods; legs II and III: one line per parallelogram), the platform
/// through its attachments B, and the point P.
pub fn branches_picture(
    path: &Path,
    m: &Machine,
    title: &str,
    branches: &[BranchSketch],
) -> Result<(), String> {
    let n = branches.len().max(1);
    let cols = n.min(4);
    let rows = n.div_ceil(4);
    let size = (340 * cols as u32, 380 * rows as u32 + BRANCH_LEGEND_PX);
    // Common window: every attachment of every branch plus the guideways.
    let g = &m.module;
    let mut ys = vec![-g.r4, g.r4, -g.r_small1, g.r_small1];
    let mut zs = vec![
        m.limits
            .rho_min
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min),
        m.limits
            .rho_max
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max),
    ];
    for b in branches {
        for (a, bb) in attachments(m, &b.pose, &b.rho) {
            ys.extend([a.y, bb.y]);
            zs.extend([a.z, bb.z]);
        }
    }
    let span = |v: &[f64]| {
        let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let pad = 0.06 * (hi - lo).max(1.0);
        (lo - pad, hi + pad)
    };
    let (y0, y1) = span(&ys);
    let (z0, z1) = span(&zs);
    render!(
        path,
        size,
        |root: &DrawingArea<_, Shift>| -> Result<(), String> {
            let e = |e| format!("drawing: {e}");
            root.fill(&WHITE).map_err(e)?;
            let (top, body) = root.split_vertically(BRANCH_LEGEND_PX);
            draw_title_and_legend(&top, title, &branch_legend())?;
            let panels = body.split_evenly((rows, cols));
            for (panel, b) in panels.iter().zip(branches) {
                draw_branch(panel, m, b, (y0, y1), (z0, z1))?;
            }
            Ok(())
        }
    )
}

/// Height of the title and legend band of a branches picture (px).
const BRANCH_LEGEND_PX: u32 = 62;
/// Colours of the legs in a branches picture: leg I (two rods), leg II, leg III.
const LEG_COLOURS: [RGBColor; 3] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

/// The legend of a branches picture: the legs, the platform, the guideways, the working frame.
fn branch_legend() -> Vec<(RGBColor, bool, String)> {
    vec![
        (LEG_COLOURS[0], false, "leg I: two rods, slider 1".into()),
        (LEG_COLOURS[1], false, "leg II: slider 2".into()),
        (LEG_COLOURS[2], false, "leg III: slider 3".into()),
        (BLACK, false, "platform and P".into()),
        (
            RGBColor(150, 150, 150),
            true,
            "guideways over the strokes (dashed)".into(),
        ),
        (RGBColor(46, 160, 67), true, "the working branch".into()),
    ]
}

/// Slider attachment A and platform attachment B of the four rods of eqs. (3)-(6).
fn attachments(
    m: &Machine,
    pose: &ModulePose,
    rho: &Sliders,
) -> [(nalgebra::Vector3<f64>, nalgebra::Vector3<f64>); 4] {
    let g = &m.module;
    let (s, c) = pose.alpha.sin_cos();
    let p = pose.p;
    let b = [
        p + nalgebra::Vector3::new(0.0, g.r_big1 * c, g.r_big1 * s),
        p - nalgebra::Vector3::new(0.0, g.r_big1 * c, g.r_big1 * s),
        p - nalgebra::Vector3::new(0.0, g.r_big2 * c, g.r_big2 * s),
        p + nalgebra::Vector3::new(0.0, g.r_big2 * c, g.r_big2 * s),
    ];
    let v = rod_vectors(g, pose, rho);
    std::array::from_fn(|i| (b[i] - v[i], b[i]))
}

fn draw_branch<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    m: &Machine,
    b: &BranchSketch,
    (y0, y1): (f64, f64),
    (z0, z1): (f64, f64),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("drawing: {e}");
    let (w, _) = area.dim_in_pixel();
    let per_line = ((w as usize).saturating_sub(20) / 6).max(10);
    let mut lines: Vec<String> = vec![String::new()];
    for word in b.detail.split(';') {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.len() + word.len() + 2 > per_line {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push_str(", ");
            }
            last.push_str(word);
        }
    }
    for (k, l) in lines.iter().enumerate() {
        area.draw(&Text::new(
            l.clone(),
            (10, 24 + 13 * k as i32),
            (FAMILY, 11),
        ))
        .map_err(e)?;
    }
    area.draw(&Text::new(b.label.clone(), (10, 5), (FAMILY, 14)))
        .map_err(e)?;
    let inner = area.margin(26 + 13 * lines.len() as i32, 0, 0, 0);
    let mut chart = ChartBuilder::on(&inner)
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(44)
        .build_cartesian_2d(y0..y1, z1..z0)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("y (mm)")
        .y_desc("z (mm, down)")
        .label_style((FAMILY, 10))
        .axis_desc_style((FAMILY, 11))
        .x_labels(5)
        .y_labels(6)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(e)?;
    let g = &m.module;
    let lim = &m.limits;
    let guides = [(g.r_small1, 0), (-g.r_small1, 0), (-g.r4, 1), (g.r4, 2)];
    let grey = RGBColor(150, 150, 150);
    for (y, i) in guides {
        // Dashed guideway over the stroke.
        let (lo, hi) = (lim.rho_min[i], lim.rho_max[i]);
        let steps = 24;
        let dz = (hi - lo) / steps as f64;
        let dashes = (0..steps).step_by(2).map(|k| {
            let za = lo + dz * k as f64;
            PathElement::new(vec![(y, za), (y, za + dz)], grey.stroke_width(1))
        });
        chart.draw_series(dashes).map_err(e)?;
    }
    let att = attachments(m, &b.pose, &b.rho);
    let colors = [
        LEG_COLOURS[0],
        LEG_COLOURS[0],
        LEG_COLOURS[1],
        LEG_COLOURS[2],
    ];
    for ((a, bb), col) in att.iter().zip(colors) {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(a.y, a.z), (bb.y, bb.z)],
                col.stroke_width(2),
            )))
            .map_err(e)?;
        // Slider block.
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a.y - 25.0, a.z - 20.0), (a.y + 25.0, a.z + 20.0)],
                col.mix(0.6).filled(),
            )))
            .map_err(e)?;
    }
    // Platform: through leg-I attachments and legs II-III attachments (a line along its y axis).
    let mut pts: Vec<(f64, f64)> = att.iter().map(|(_, bb)| (bb.y, bb.z)).collect();
    pts.sort_by(|p, q| p.0.total_cmp(&q.0));
    chart
        .draw_series(std::iter::once(PathElement::new(
            pts,
            BLACK.stroke_width(4),
        )))
        .map_err(e)?;
    chart
        .draw_series(std::iter::once(Circle::new(
            (b.pose.p.y, b.pose.p.z),
            4,
            BLACK.filled(),
        )))
        .map_err(e)?;
    if b.working {
        area.draw(&Rectangle::new(
            [(1, 1), {
                let (w, h) = area.dim_in_pixel();
                (w as i32 - 2, h as i32 - 2)
            }],
            RGBColor(46, 160, 67).stroke_width(3),
        ))
        .map_err(e)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_font_is_valid() {
        assert!(plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    }

    #[test]
    fn formats_follow_the_extension() {
        assert_eq!(Format::of_path(Path::new("a/b.SVG")), Ok(Format::Svg));
        assert_eq!(Format::of_path(Path::new("b.png")), Ok(Format::Png));
        assert!(
            Format::of_path(Path::new("b.pdf"))
                .unwrap_err()
                .contains(".svg or .png")
        );
    }
}
