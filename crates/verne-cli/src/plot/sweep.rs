//! The picture of a design sweep (`verne workspace --sweep ... --plot`): two panels against the
//! first key, the workspace volume (a glider's area) with its bracket as a bar at each value,
//! and the largest box with its bound as a bar (the box found .. no box of the lattice is
//! larger; a glider's S); one line per value of the second key when there is one.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{FAMILY, Format, draw_title_and_legend, drawing, io_err, register_font};

/// One workspace of a sweep: its key values, the volume and its bracket, the largest box found
/// and the volume no box exceeds (litres; a glider's area and S, in its length unit squared).
pub struct SweepPoint {
    pub keys: Vec<f64>,
    pub volume_l: f64,
    pub lo_l: f64,
    pub hi_l: f64,
    pub box_l: f64,
    pub box_upper_l: f64,
}

impl SweepPoint {
    /// The panel's value and its bar: the volume, or the largest box.
    fn value(&self, panel: Panel) -> (f64, f64, f64) {
        match panel {
            Panel::Volume => (self.volume_l, self.lo_l, self.hi_l),
            Panel::LargestBox => (self.box_l, self.box_l, self.box_upper_l),
        }
    }
}

/// The two panels of the picture.
#[derive(Clone, Copy)]
enum Panel {
    Volume,
    LargestBox,
}

/// Line colours, one per value of the second key (cycled).
const SERIES: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(46, 160, 67),
    RGBColor(148, 103, 189),
    RGBColor(255, 140, 0),
    RGBColor(140, 86, 75),
];

/// What the picture calls its two quantities.
pub struct SweepLabels {
    /// The first panel's axis, and the legend's name for it.
    pub volume_axis: &'static str,
    pub volume_name: &'static str,
    /// The second panel's axis.
    pub box_axis: &'static str,
    /// The legend's line about the bars.
    pub bars: &'static str,
}

/// The VERNE machine's sweep.
pub const VOLUME_LABELS: SweepLabels = SweepLabels {
    volume_axis: "workspace volume (l)",
    volume_name: "volume",
    box_axis: "largest box (l)",
    bars: "bars: the volume's bracket; the largest box found .. no box of the lattice larger",
};

const SIZE: (u32, u32) = (1200, 620);
const LEGEND_HEIGHT_PX: u32 = 86;

/// Draws the sweep: volume (l) against `keys[0]`, bracket bars, a line per `keys[1]` value.
pub fn sweep_picture(
    path: &Path,
    keys: &[&str],
    points: &[SweepPoint],
    title: &str,
    labels: &SweepLabels,
) -> Result<(), String> {
    if !points
        .iter()
        .any(|p| p.volume_l.is_finite() && p.volume_l > 0.0)
    {
        return Err(format!(
            "nothing to draw: no workspace of the sweep has a {}",
            labels.volume_name
        ));
    }
    // The series: one per value of the second key, in order of appearance.
    let mut series: Vec<Option<f64>> = Vec::new();
    for p in points {
        let s = p.keys.get(1).copied();
        if !series.contains(&s) {
            series.push(s);
        }
    }
    let entries: Vec<(RGBColor, bool, String)> = series
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let label = match (s, keys.get(1)) {
                (Some(v), Some(key)) => format!("{key} = {v}"),
                _ => labels.volume_name.to_string(),
            };
            (SERIES[k % SERIES.len()], false, label)
        })
        .chain(std::iter::once((
            RGBColor(90, 90, 90),
            true,
            labels.bars.to_string(),
        )))
        .collect();
    render!(
        path,
        SIZE,
        |root: &DrawingArea<_, Shift>| -> Result<(), String> {
            root.fill(&WHITE).map_err(drawing)?;
            let (top, body) = root.split_vertically(LEGEND_HEIGHT_PX);
            draw_title_and_legend(&top, title, &entries)?;
            let (left, right) = body.split_horizontally(SIZE.0 / 2);
            draw_panel(
                &left,
                keys[0],
                points,
                &series,
                labels.volume_axis,
                Panel::Volume,
            )?;
            draw_panel(
                &right,
                keys[0],
                points,
                &series,
                labels.box_axis,
                Panel::LargestBox,
            )
        }
    )
}

/// One panel: the panel's value against the first key, its bars, a line per series.
fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    key: &str,
    points: &[SweepPoint],
    series: &[Option<f64>],
    axis: &str,
    panel: Panel,
) -> Result<(), String> {
    let (x0, x1) = points
        .iter()
        .map(|p| p.keys[0])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    let (y0, y1) = points
        .iter()
        .flat_map(|p| {
            let (_, lo, hi) = p.value(panel);
            [lo, hi]
        })
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(y), b.max(y))
        });
    if !(x0.is_finite() && y0.is_finite()) {
        return Ok(());
    }
    let pad = |a: f64, b: f64| {
        let d = if b > a {
            0.05 * (b - a)
        } else {
            0.5 * a.abs().max(1.0)
        };
        (a - d, b + d)
    };
    let ((x0, x1), (y0, y1)) = (pad(x0, x1), pad(y0, y1));
    let mut c = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(drawing)?;
    c.configure_mesh()
        .x_desc(key)
        .y_desc(axis)
        .label_style((FAMILY, 12))
        .axis_desc_style((FAMILY, 13))
        .draw()
        .map_err(drawing)?;
    let cap = 0.006 * (x1 - x0);
    for (k, s) in series.iter().enumerate() {
        let colour = SERIES[k % SERIES.len()];
        let mut line: Vec<&SweepPoint> = points
            .iter()
            .filter(|p| p.keys.get(1).copied() == *s && p.value(panel).0.is_finite())
            .collect();
        line.sort_by(|a, b| a.keys[0].total_cmp(&b.keys[0]));
        c.draw_series(LineSeries::new(
            line.iter().map(|p| (p.keys[0], p.value(panel).0)),
            colour.stroke_width(2),
        ))
        .map_err(drawing)?;
        for p in &line {
            let x = p.keys[0];
            let (v, lo, hi) = p.value(panel);
            for seg in [
                vec![(x, lo), (x, hi)],
                vec![(x - cap, lo), (x + cap, lo)],
                vec![(x - cap, hi), (x + cap, hi)],
            ] {
                c.draw_series(std::iter::once(PathElement::new(
                    seg,
                    colour.stroke_width(1),
                )))
                .map_err(drawing)?;
            }
            c.draw_series(std::iter::once(Circle::new((x, v), 4, colour.filled())))
                .map_err(drawing)?;
        }
    }
    Ok(())
}
