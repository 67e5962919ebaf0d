//! Pictures of the planar gliders, drawn with plotters like the VERNE machine's (SVG or PNG by the
//! file's extension, written atomically): the workspace (`verne workspace -m GLIDER --plot`) and
//! every branch of one query (`verne modes -m GLIDER --plot`). Axes with ticks in the glider
//! file's length unit (multiples of the strut length L for the presets), a legend outside the
//! chart, equal scales on both axes.

use nalgebra::{Point2, Vector2};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::series::DashedLineSeries;
use verne::glider::{GliderSpec, NodeClass, Rectangle as Region, WorkspaceGrid};

use super::{FAMILY, Format, draw_title_and_legend, drawing, io_err, register_font};
use std::path::Path;

/// Width of the workspace chart's plotting area (px).
const CHART_WIDTH_PX: u32 = 720;
/// Height of the title and legend band above a picture (px).
const LEGEND_HEIGHT_PX: u32 = 88;
/// Room for the axes' ticks and labels (px).
const AXIS_ROOM_PX: u32 = 60;

const REGION: RGBColor = RGBColor(76, 175, 80);
const ADMISSIBLE: RGBColor = RGBColor(165, 214, 167);
const OUT_OF_BOUNDS: RGBColor = RGBColor(255, 224, 130);
const OTHER_ASSEMBLY: RGBColor = RGBColor(176, 190, 197);
const SINGULAR: RGBColor = RGBColor(0, 0, 0);
const RECTANGLE: RGBColor = RGBColor(211, 47, 47);
const SQUARE: RGBColor = RGBColor(21, 101, 192);
const GUIDE: RGBColor = RGBColor(66, 66, 66);

/// The axis label's unit: L for a preset (its lengths are multiples of the strut length), the
/// file's own unit otherwise.
fn unit(spec: &GliderSpec) -> &'static str {
    match GliderSpec::preset(&spec.name) {
        Some(p) if p == *spec => "L",
        _ => "length unit of the glider file",
    }
}

/// The guides over their strokes: (origin, direction, [rho_min, rho_max]).
fn guides(spec: &GliderSpec) -> [(Point2<f64>, Vector2<f64>, [f64; 2]); 2] {
    [
        (spec.a(), spec.u1(), spec.rho1_range),
        (spec.b(), spec.u2(), spec.rho2_range),
    ]
}

/// The guides' origins and stroke ends, which every picture shows.
fn guide_points(spec: &GliderSpec) -> impl Iterator<Item = Point2<f64>> {
    guides(spec)
        .into_iter()
        .flat_map(|(o, u, [r0, r1])| [o, o + u * r0, o + u * r1])
}

/// A window around the points, padded, as ((x0, x1), (y0, y1)).
fn window(points: impl Iterator<Item = Point2<f64>>) -> ((f64, f64), (f64, f64)) {
    let (mut lo, mut hi) = (
        Point2::new(f64::INFINITY, f64::INFINITY),
        Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for p in points.filter(|p| p.x.is_finite() && p.y.is_finite()) {
        lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    if lo.x > hi.x {
        return ((-1.0, 1.0), (-1.0, 1.0));
    }
    let pad = 0.05 * (hi.x - lo.x).max(hi.y - lo.y).max(1e-9);
    ((lo.x - pad, hi.x + pad), (lo.y - pad, hi.y + pad))
}

/// Pixel size of a chart of `width_px` with equal scales over the window.
fn equal_scale_height(width_px: u32, ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64))) -> u32 {
    ((width_px as f64) * (y1 - y0) / (x1 - x0))
        .round()
        .clamp(120.0, 2000.0) as u32
}

/// A chart over the window with axes, ticks and the unit.
fn chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    unit: &str,
    font: u32,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let mut c = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(36)
        .y_label_area_size(52)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(drawing)?;
    c.configure_mesh()
        .disable_mesh()
        .x_desc(format!("x ({unit})"))
        .y_desc(format!("y ({unit})"))
        .label_style((FAMILY, font))
        .axis_desc_style((FAMILY, font + 1))
        .x_labels(7)
        .y_labels(7)
        .draw()
        .map_err(drawing)?;
    Ok(c)
}

/// The workspace picture: the nodes by class, the largest rectangle S (red) and square (blue,
/// dashed; one outline when they are the same), the guides over their strokes (grey) with their
/// origins A and B. The grid is the one sampled in the mechanism frame (angle 0).
pub fn workspace_picture(
    path: &Path,
    spec: &GliderSpec,
    grid: &WorkspaceGrid,
    rect: Option<Region>,
    square: Option<Region>,
) -> Result<(), String> {
    let half = 0.5 * grid.step;
    let corners = [
        Point2::new(grid.origin.x - half, grid.origin.y - half),
        Point2::new(
            grid.origin.x + (grid.nx.max(1) - 1) as f64 * grid.step + half,
            grid.origin.y + (grid.ny.max(1) - 1) as f64 * grid.step + half,
        ),
    ];
    let win = window(corners.into_iter().chain(guide_points(spec)));
    let height = equal_scale_height(CHART_WIDTH_PX, win);
    let size = (
        CHART_WIDTH_PX + AXIS_ROOM_PX + 20,
        height + AXIS_ROOM_PX + LEGEND_HEIGHT_PX,
    );
    let same = match (rect, square) {
        (Some(r), Some(s)) => {
            (r.area() - s.area()).abs() <= 1e-12 * r.area().max(1.0)
                && (r.centre - s.centre).norm() <= 1e-9 * grid.step.max(1.0)
        }
        _ => false,
    };
    let unit = unit(spec);
    let count = |f: &dyn Fn(usize) -> bool| (0..grid.class.len()).filter(|&k| f(k)).count();
    let region_nodes = count(&|k| grid.region[k]);
    let mut entries = vec![
        (
            REGION,
            false,
            format!("t-connected region ({region_nodes} nodes)"),
        ),
        (ADMISSIBLE, false, "other admissible".to_string()),
        (OUT_OF_BOUNDS, false, "outside eq. (4)".to_string()),
        (OTHER_ASSEMBLY, false, "other assembly mode".to_string()),
        (SINGULAR, false, "singular".to_string()),
    ];
    if let Some(r) = rect {
        let label = if same {
            "S = largest square"
        } else {
            "S, largest rectangle"
        };
        entries.push((
            RECTANGLE,
            true,
            format!("{label}: {:.4} x {:.4}", r.width, r.height),
        ));
    }
    if let (Some(s), false) = (square, same) {
        entries.push((
            SQUARE,
            true,
            format!("largest square (dashed): {:.4}", s.width),
        ));
    }
    entries.push((GUIDE, false, "guides over the strokes, A and B".to_string()));
    let title = format!(
        "{}: workspace of working mode ++ (grid step {:.5}{})",
        spec.name,
        grid.step,
        if unit == "L" { " L" } else { "" }
    );
    let colour = |k: usize| -> Option<RGBColor> {
        if grid.region[k] {
            return Some(REGION);
        }
        match grid.class[k] {
            NodeClass::Admissible => Some(ADMISSIBLE),
            NodeClass::OutOfBounds => Some(OUT_OF_BOUNDS),
            NodeClass::OtherAssembly => Some(OTHER_ASSEMBLY),
            NodeClass::Singular => Some(SINGULAR),
            NodeClass::Unreachable | NodeClass::OutOfRange => None,
        }
    };
    render!(
        path,
        size,
        |root: &DrawingArea<_, Shift>| -> Result<(), String> {
            root.fill(&WHITE).map_err(drawing)?;
            let (top, body) = root.split_vertically(LEGEND_HEIGHT_PX);
            draw_title_and_legend(&top, &title, &entries)?;
            let mut c = chart(&body, win, unit, 12)?;
            // Run-length rectangles along each grid row.
            let mut cells = Vec::new();
            for j in 0..grid.ny {
                let mut i = 0;
                while i < grid.nx {
                    let fill = colour(j * grid.nx + i);
                    let start = i;
                    while i < grid.nx && colour(j * grid.nx + i) == fill {
                        i += 1;
                    }
                    if let Some(fill) = fill {
                        let x0 = grid.origin.x + start as f64 * grid.step - half;
                        let x1 = grid.origin.x + (i - 1) as f64 * grid.step + half;
                        let y = grid.origin.y + j as f64 * grid.step;
                        cells.push(Rectangle::new(
                            [(x0, y - half), (x1, y + half)],
                            fill.filled(),
                        ));
                    }
                }
            }
            c.draw_series(cells).map_err(drawing)?;
            let outline = |r: &Region| {
                let mut p: Vec<(f64, f64)> = r.corners().iter().map(|c| (c.x, c.y)).collect();
                p.push(p[0]);
                p
            };
            if let Some(r) = &rect {
                c.draw_series(std::iter::once(PathElement::new(
                    outline(r),
                    RECTANGLE.stroke_width(2),
                )))
                .map_err(drawing)?;
            }
            if let (Some(s), false) = (&square, same) {
                c.draw_series(DashedLineSeries::new(
                    outline(s),
                    8,
                    5,
                    SQUARE.stroke_width(2),
                ))
                .map_err(drawing)?;
            }
            for (o, u, [r0, r1]) in guides(spec) {
                let (a, b) = (o + u * r0, o + u * r1);
                c.draw_series(std::iter::once(PathElement::new(
                    vec![(a.x, a.y), (b.x, b.y)],
                    GUIDE.stroke_width(4),
                )))
                .map_err(drawing)?;
                c.draw_series(std::iter::once(Circle::new((o.x, o.y), 4, GUIDE.filled())))
                    .map_err(drawing)?;
            }
            for (o, name) in [(spec.a(), "A"), (spec.b(), "B")] {
                c.draw_series(std::iter::once(Text::new(
                    name,
                    (o.x, o.y - 0.02 * (win.1.1 - win.1.0)),
                    (FAMILY, 13).into_font().color(&GUIDE),
                )))
                .map_err(drawing)?;
            }
            Ok(())
        }
    )
}

/// One branch of a glider query to draw.
pub struct GliderSketch {
    /// The point P.
    pub p: Point2<f64>,
    /// The joints (rho1, rho2).
    pub rho: Vector2<f64>,
    /// Panel title, e.g. `1: mode ++, assembly +`.
    pub label: String,
    /// The status (`;` shown as `, `).
    pub detail: String,
    /// Framed in green: the working branch.
    pub working: bool,
}

/// Every branch of one query, one panel each (up to four per row), on common axes: the guides
/// over their strokes, the sliders C = A + rho1 u1 and D = B + rho2 u2, the struts CP and DP,
/// and P.
pub fn branches_picture(
    path: &Path,
    spec: &GliderSpec,
    title: &str,
    branches: &[GliderSketch],
) -> Result<(), String> {
    let n = branches.len().max(1);
    let cols = n.min(4);
    let rows = n.div_ceil(4);
    let sliders = |b: &GliderSketch| {
        [
            spec.a() + spec.u1() * b.rho.x,
            spec.b() + spec.u2() * b.rho.y,
        ]
    };
    let points = branches.iter().flat_map(|b| {
        let [c, d] = sliders(b);
        [b.p, c, d]
    });
    let win = window(points.chain(guide_points(spec)));
    let panel_width = 330;
    let panel_height = equal_scale_height(panel_width - 70, win) + 110;
    let size = (
        panel_width * cols as u32,
        panel_height * rows as u32 + LEGEND_HEIGHT_PX,
    );
    let unit = unit(spec);
    let entries = [
        (GUIDE, false, "guides over the strokes".to_string()),
        (
            RECTANGLE,
            false,
            "strut CP (slider C on guide 1)".to_string(),
        ),
        (SQUARE, false, "strut DP (slider D on guide 2)".to_string()),
        (REGION, true, "the working branch (ok)".to_string()),
    ];
    render!(
        path,
        size,
        |root: &DrawingArea<_, Shift>| -> Result<(), String> {
            root.fill(&WHITE).map_err(drawing)?;
            let (top, body) = root.split_vertically(LEGEND_HEIGHT_PX);
            draw_title_and_legend(&top, title, &entries)?;
            for (panel, b) in body.split_evenly((rows, cols)).iter().zip(branches) {
                panel
                    .draw(&Text::new(b.label.clone(), (10, 6), (FAMILY, 14)))
                    .map_err(drawing)?;
                panel
                    .draw(&Text::new(
                        b.detail.replace(';', ", "),
                        (10, 24),
                        (FAMILY, 11),
                    ))
                    .map_err(drawing)?;
                let inner = panel.margin(40, 0, 0, 0);
                let mut c = chart(&inner, win, unit, 10)?;
                for (o, u, [r0, r1]) in guides(spec) {
                    let (a, e) = (o + u * r0, o + u * r1);
                    c.draw_series(std::iter::once(PathElement::new(
                        vec![(a.x, a.y), (e.x, e.y)],
                        GUIDE.stroke_width(3),
                    )))
                    .map_err(drawing)?;
                }
                let [sc, sd] = sliders(b);
                for (s, col) in [(sc, RECTANGLE), (sd, SQUARE)] {
                    c.draw_series(std::iter::once(PathElement::new(
                        vec![(s.x, s.y), (b.p.x, b.p.y)],
                        col.stroke_width(2),
                    )))
                    .map_err(drawing)?;
                    c.draw_series(std::iter::once(Circle::new((s.x, s.y), 5, col.filled())))
                        .map_err(drawing)?;
                }
                c.draw_series(std::iter::once(Circle::new(
                    (b.p.x, b.p.y),
                    4,
                    BLACK.filled(),
                )))
                .map_err(drawing)?;
                if b.working {
                    let (w, h) = panel.dim_in_pixel();
                    panel
                        .draw(&Rectangle::new(
                            [(1, 1), (w as i32 - 2, h as i32 - 2)],
                            REGION.stroke_width(3),
                        ))
                        .map_err(drawing)?;
                }
            }
            Ok(())
        }
    )
}
