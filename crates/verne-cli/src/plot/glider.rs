//! The SVG picture of a glider's workspace (`verne workspace -m GLIDER --plot FILE.svg`), written
//! as text: the nodes by class, the largest rectangle and square, the guides.

use std::fmt::Write as _;

use nalgebra::Point2;
use verne::glider::{GliderSpec, NodeClass, Rectangle, WorkspaceGrid};

/// Width of the SVG picture in pixels.
const PLOT_WIDTH_PX: f64 = 800.0;

/// An SVG picture: nodes by class (run-length rectangles per grid row), the rectangle S (red),
/// the largest square (blue, dashed), the guide strokes and the guide origins A and B.
pub fn workspace_svg(
    spec: &GliderSpec,
    grid: &WorkspaceGrid,
    rect: Option<Rectangle>,
    square: Option<Rectangle>,
) -> String {
    let half = 0.5 * grid.step;
    // Picture window: the grid and the guides.
    let mut lo = Point2::new(grid.origin.x - half, grid.origin.y - half);
    let mut hi = Point2::new(
        grid.origin.x + (grid.nx.max(1) - 1) as f64 * grid.step + half,
        grid.origin.y + (grid.ny.max(1) - 1) as f64 * grid.step + half,
    );
    let guides = [
        (spec.a(), spec.u1(), spec.rho1_range),
        (spec.b(), spec.u2(), spec.rho2_range),
    ];
    for (o, u, [r0, r1]) in guides {
        for p in [o, o + u * r0, o + u * r1] {
            lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
    }
    let span = (hi.x - lo.x).max(hi.y - lo.y).max(f64::MIN_POSITIVE);
    let pad = 0.05 * span;
    let scale = PLOT_WIDTH_PX / (hi.x - lo.x + 2.0 * pad).max(f64::MIN_POSITIVE);
    let height = (hi.y - lo.y + 2.0 * pad) * scale;
    let px = |p: Point2<f64>| ((p.x - lo.x + pad) * scale, (hi.y + pad - p.y) * scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{PLOT_WIDTH_PX:.0}\" \
         height=\"{height:.0}\" viewBox=\"0 0 {PLOT_WIDTH_PX:.0} {height:.0}\">"
    );
    let _ = writeln!(
        s,
        "<title>{}: workspace of working mode ++</title>\n<rect width=\"100%\" height=\"100%\" \
         fill=\"white\"/>",
        spec.name
    );
    let colour = |k: usize| -> Option<&'static str> {
        if grid.region[k] {
            return Some("#4caf50");
        }
        match grid.class[k] {
            NodeClass::Admissible => Some("#a5d6a7"),
            NodeClass::OutOfBounds => Some("#ffe082"),
            NodeClass::OtherAssembly => Some("#b0bec5"),
            NodeClass::Singular => Some("#000000"),
            NodeClass::Unreachable | NodeClass::OutOfRange => None,
        }
    };
    let w = grid.step * scale;
    for j in 0..grid.ny {
        let mut i = 0;
        while i < grid.nx {
            let c = colour(j * grid.nx + i);
            let start = i;
            while i < grid.nx && colour(j * grid.nx + i) == c {
                i += 1;
            }
            if let Some(fill) = c {
                // Grid frame at angle 0: node (i, j) is origin + step (i, j).
                let top_left = Point2::new(
                    grid.origin.x + start as f64 * grid.step - half,
                    grid.origin.y + j as f64 * grid.step + half,
                );
                let (x, y) = px(top_left);
                let _ = writeln!(
                    s,
                    "<rect x=\"{x:.2}\" y=\"{y:.2}\" width=\"{:.2}\" height=\"{w:.2}\" \
                     fill=\"{fill}\"/>",
                    (i - start) as f64 * w
                );
            }
        }
    }
    for (r, style) in [
        (rect, "stroke=\"#d32f2f\" stroke-width=\"2\""),
        (
            square,
            "stroke=\"#1565c0\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"",
        ),
    ] {
        if let Some(r) = r {
            let pts: Vec<String> = r
                .corners()
                .iter()
                .map(|&c| {
                    let (x, y) = px(c);
                    format!("{x:.2},{y:.2}")
                })
                .collect();
            let _ = writeln!(
                s,
                "<polygon points=\"{}\" fill=\"none\" {style}/>",
                pts.join(" ")
            );
        }
    }
    for (o, u, [r0, r1]) in guides {
        let (x0, y0) = px(o + u * r0);
        let (x1, y1) = px(o + u * r1);
        let _ = writeln!(
            s,
            "<line x1=\"{x0:.2}\" y1=\"{y0:.2}\" x2=\"{x1:.2}\" y2=\"{y1:.2}\" stroke=\"#424242\" \
             stroke-width=\"4\"/>"
        );
        let (x, y) = px(o);
        let _ = writeln!(
            s,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"4\" fill=\"#424242\"/>"
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"8\" y=\"18\" font-family=\"sans-serif\" font-size=\"13\">{}: t-connected \
         region (green), other admissible (light green), outside eq. (4) (amber), other assembly \
         (grey); S red, largest square blue</text>",
        spec.name
    );
    s.push_str("</svg>\n");
    s
}
