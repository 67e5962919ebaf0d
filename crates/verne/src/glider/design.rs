//! Dimensioning of the three glider architectures from the amplification bounds (section 3.2,
//! Wenger 2001) and the comparison rows of Table 1 (L0, delta-rho, S per L) and Table 2
//! (dimensions and envelope for a prescribed rectangle or square, section 3.3), each with the
//! paper's printed value beside the computed one.

use crate::par::*;
use nalgebra::{Point2, Vector2};

use super::jacobian::amplification;
use super::kinematics::{Branch, forward_kinematics_in_mode};
use super::spec::GliderSpec;
use super::tolerance::DESIGN_BISECTION_REL;
use super::workspace::{
    PAPER_LAMBDA_BOUNDS, Rectangle, WorkspaceOptions, largest_rectangle, largest_square,
    sample_workspace,
};

/// Steps of the scan that brackets L0 (over (0, 2L)) before the bisection.
const L0_SCAN_STEPS: usize = 2000;

/// Steps per L of the scan that brackets delta-rho before the bisection.
const DELTA_RHO_SCAN_STEPS_PER_L: usize = 1000;

/// Largest joint range searched, in multiples of L.
const DELTA_RHO_SCAN_MAX_L: f64 = 4.0;

/// Largest strut length L (mm) whose Table 1 in mm (L0 L, delta-rho L, S L^2) is finite. In
/// multiples of L, L0 < 2 and delta-rho <= 4 (the ranges the design scans); the
/// workspace lies within L of the guides' strokes, so its rectangle S is within a square of
/// side L0 + 2 delta-rho + 2 < 12: S < 144 L^2, and at L = 1e150 mm, S < 1.44e302 mm^2, below
/// f64::MAX (1.8e308). Beyond it S in mm^2 can overflow (L = 1e200 mm gives infinity).
pub const MAX_STRUT_LENGTH_MM: f64 = 1e150;

/// Samples per joint of the joint box when its envelope is measured.
const ENVELOPE_JOINT_SAMPLES: usize = 401;

/// The three architectures of section 3.1, Wenger 2001.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Architecture {
    /// alpha1 = 0, alpha2 = pi (Fig. 7): collinear guides facing each other.
    Biglide1,
    /// alpha1 = alpha2 = pi/2 (Fig. 8): parallel guides.
    Biglide2,
    /// alpha1 = pi/4, alpha2 = 3 pi/4 (Fig. 9): orthogonal guides.
    Orthoglide,
}

/// Table 1, Wenger 2001: L0 / L, delta-rho / L, S / L^2 as printed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperTable1 {
    pub l0: f64,
    pub delta_rho: f64,
    pub s: f64,
}

/// Table 2 (and the square of section 3.3), Wenger 2001: dimensions in m, envelope in m^2,
/// for a 1 m^2 workspace. The envelope of the square was not printed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperTable2 {
    pub l0: f64,
    pub l: f64,
    pub delta_rho: f64,
    pub envelope: Option<f64>,
}

impl Architecture {
    pub const ALL: [Architecture; 3] = [
        Architecture::Biglide1,
        Architecture::Biglide2,
        Architecture::Orthoglide,
    ];

    /// `biglide1`, `biglide2` or `orthoglide` (the preset names).
    pub fn name(self) -> &'static str {
        match self {
            Architecture::Biglide1 => "biglide1",
            Architecture::Biglide2 => "biglide2",
            Architecture::Orthoglide => "orthoglide",
        }
    }

    pub fn from_name(name: &str) -> Option<Architecture> {
        Architecture::ALL.into_iter().find(|a| a.name() == name)
    }

    /// (alpha1, alpha2) in rad, section 3.1.
    pub fn alphas(self) -> (f64, f64) {
        use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        match self {
            Architecture::Biglide1 => (0.0, PI),
            Architecture::Biglide2 => (FRAC_PI_2, FRAC_PI_2),
            Architecture::Orthoglide => (FRAC_PI_4, 3.0 * FRAC_PI_4),
        }
    }

    /// The row of Table 1, Wenger 2001.
    pub fn paper_table1(self) -> PaperTable1 {
        let (l0, delta_rho, s) = match self {
            Architecture::Biglide1 => (1.946, 0.547, 0.107),
            Architecture::Biglide2 => (0.458, 0.529, 0.249),
            Architecture::Orthoglide => (1.961, 1.109, 0.885),
        };
        PaperTable1 { l0, delta_rho, s }
    }

    /// The row of Table 2, Wenger 2001 (1 m^2 rectangle).
    pub fn paper_table2_rectangle(self) -> PaperTable2 {
        let (l0, l, delta_rho, envelope) = match self {
            Architecture::Biglide1 => (5.95, 3.05, 1.67, 16.45),
            Architecture::Biglide2 => (0.92, 2.00, 1.06, 8.50),
            Architecture::Orthoglide => (2.08, 1.06, 1.18, 3.91),
        };
        PaperTable2 {
            l0,
            l,
            delta_rho,
            envelope: Some(envelope),
        }
    }

    /// The 1 m^2 square of section 3.3, Wenger 2001: printed for the biglide2 only; for the
    /// other two the paper states that the rectangle of Table 2 is already an exact square.
    pub fn paper_table2_square(self) -> PaperTable2 {
        match self {
            Architecture::Biglide2 => PaperTable2 {
                l0: 1.075,
                l: 2.348,
                delta_rho: 1.242,
                envelope: None,
            },
            other => other.paper_table2_rectangle(),
        }
    }
}

/// Dimensions of one design.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dimensions {
    /// Strut length L = l1 = l2.
    pub l: f64,
    /// Distance between the guide origins A and B.
    pub l0: f64,
    /// Joint range: both joints move over [0, delta_rho].
    pub delta_rho: f64,
}

/// The glider with guide angles alpha1, alpha2 and the given dimensions: l1 = l2 = L, both
/// joint ranges [0, delta_rho].
pub fn design_spec(name: &str, alpha1: f64, alpha2: f64, dims: Dimensions) -> GliderSpec {
    GliderSpec {
        name: name.to_string(),
        alpha1,
        alpha2,
        l1: dims.l,
        l2: dims.l,
        l0: dims.l0,
        rho1_range: [0.0, dims.delta_rho],
        rho2_range: [0.0, dims.delta_rho],
    }
}

/// Whether both amplification factors at rho (forward kinematics in the `+` assembly mode of
/// the paper's figures) satisfy eq. (4); false where the mechanism does not assemble or is
/// parallel-singular.
fn within_bounds(spec: &GliderSpec, rho: Vector2<f64>, [lo, hi]: [f64; 2]) -> bool {
    forward_kinematics_in_mode(spec, rho, Branch::Plus)
        .and_then(|p| amplification(spec, p, rho))
        // Exact comparison: the design solves lambda = bound (the workspace adds a slack).
        .is_some_and(|a| a.lambda_min >= lo && a.lambda_max <= hi)
}

/// Bisection of a predicate between `good` (true) and `bad` (false) down to `tol`; returns the
/// last `good` point.
fn bisect(mut good: f64, mut bad: f64, tol: f64, ok: impl Fn(f64) -> bool) -> f64 {
    while (bad - good).abs() > tol {
        let mid = 0.5 * (good + bad);
        if ok(mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    good
}

/// Section 3.2, Wenger 2001: L0 and delta-rho of the glider with guide angles alpha1, alpha2
/// and strut length L, from the amplification bounds [lo, hi] of eq. (4).
///
/// Converging guides (biglide1, orthoglide; |CD| shrinks as both sliders advance): CD is longest with C on A and D on B (rho = 0,
/// the largest amplification); L0 is the largest distance < 2L at which both factors there meet
/// the bounds. Then delta-rho is the largest range such that at rho = (delta-rho, delta-rho)
/// (C on C', D on D', CD shortest) the factors still meet them.
///
/// Guides with the same direction (biglide2, guides orthogonal to AB): CD is shortest when C and D are level
/// (rho1 = rho2); L0 is the smallest distance at which the factors there meet the bounds. Then
/// delta-rho is the largest range such that at rho = (0, delta-rho) (C on A, D on D', CD
/// longest) they still do.
///
/// Each length is bracketed by a scan and refined by bisection to
/// [`DESIGN_BISECTION_REL`] L. `None` if no length meets the bounds, or if the guides diverge
/// (|CD| grows as both sliders advance), a case the paper's rule does not cover.
pub fn dimension(alpha1: f64, alpha2: f64, l: f64, bounds: [f64; 2]) -> Option<Dimensions> {
    let (u1, u2) = (
        Vector2::new(alpha1.cos(), alpha1.sin()),
        Vector2::new(alpha2.cos(), alpha2.sin()),
    );
    // Same guide direction (biglide2): moving both sliders together keeps |CD|. Otherwise the
    // guides must converge (|CD| shrinks as both sliders advance, AB along +x); diverging guides
    // are outside the rule of section 3.2.
    let parallel = (u2 - u1).norm() < f64::EPSILON.sqrt();
    if !parallel && u2.x - u1.x >= 0.0 {
        return None;
    }
    let spec_with = |l0: f64| {
        design_spec(
            "design",
            alpha1,
            alpha2,
            Dimensions {
                l,
                l0,
                delta_rho: 0.0,
            },
        )
    };
    let first_ok = |l0: f64| within_bounds(&spec_with(l0), Vector2::zeros(), bounds);
    let tol = DESIGN_BISECTION_REL * l;
    // Scan L0 over (0, 2L): downwards for converging guides, upwards for parallel ones.
    let candidates: Vec<f64> = (1..L0_SCAN_STEPS)
        .map(|k| {
            let k = if parallel { k } else { L0_SCAN_STEPS - k };
            2.0 * l * k as f64 / L0_SCAN_STEPS as f64
        })
        .collect();
    let idx = candidates.iter().position(|&l0| first_ok(l0))?;
    let l0 = if idx == 0 {
        candidates[0]
    } else {
        bisect(candidates[idx], candidates[idx - 1], tol, first_ok)
    };

    let spec = spec_with(l0);
    let second = |dr: f64| {
        if parallel {
            Vector2::new(0.0, dr)
        } else {
            Vector2::new(dr, dr)
        }
    };
    let second_ok = |dr: f64| within_bounds(&spec, second(dr), bounds);
    let steps = (DELTA_RHO_SCAN_MAX_L * DELTA_RHO_SCAN_STEPS_PER_L as f64) as usize;
    let dr_at = |k: usize| l * k as f64 / DELTA_RHO_SCAN_STEPS_PER_L as f64;
    let first_bad = (1..=steps).find(|&k| !second_ok(dr_at(k)))?;
    let delta_rho = bisect(dr_at(first_bad - 1), dr_at(first_bad), tol, second_ok);
    Some(Dimensions { l, l0, delta_rho })
}

/// The design of one architecture for strut length L under the bounds of eq. (4).
pub fn architecture_spec(arch: Architecture, l: f64, bounds: [f64; 2]) -> Option<GliderSpec> {
    let (a1, a2) = arch.alphas();
    dimension(a1, a2, l, bounds).map(|d| design_spec(arch.name(), a1, a2, d))
}

/// Axis-aligned bounding box area of the mechanism over its joint box: guide origins A and B,
/// the guide strokes, and P (forward kinematics in the `+` assembly mode) on a
/// `ENVELOPE_JOINT_SAMPLES`^2 grid of the joint box.
pub fn envelope(spec: &GliderSpec) -> f64 {
    let n = ENVELOPE_JOINT_SAMPLES;
    let lerp = |[lo, hi]: [f64; 2], k: usize| lo + (hi - lo) * k as f64 / (n - 1) as f64;
    let mut points: Vec<Point2<f64>> = (0..n)
        .into_par_iter()
        .flat_map_iter(|a| {
            (0..n).filter_map(move |b| {
                let rho = Vector2::new(lerp(spec.rho1_range, a), lerp(spec.rho2_range, b));
                forward_kinematics_in_mode(spec, rho, Branch::Plus)
            })
        })
        .collect();
    points.push(spec.a());
    points.push(spec.b());
    for r1 in spec.rho1_range {
        for r2 in spec.rho2_range {
            let (c, d) = spec.sliders(Vector2::new(r1, r2));
            points.push(c);
            points.push(d);
        }
    }
    let (mut lo, mut hi) = (points[0], points[0]);
    for p in &points {
        lo = Point2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Point2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    (hi.x - lo.x) * (hi.y - lo.y)
}

/// Options of the Table 1 / Table 2 computation.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignOptions {
    /// Bounds of eq. (4) on both amplification factors.
    pub bounds: [f64; 2],
    /// Workspace grid nodes along the longer side of the window.
    pub nodes: usize,
    /// Orientations (rad) of the rectangle sides tried for S; the largest area wins (ties: the
    /// first). Default {0, pi/4}: the two orientations of a square symmetric about the
    /// mechanisms' axis of symmetry (docs/gliders.md).
    pub orientations: Vec<f64>,
    /// Area of the prescribed workspace of Table 2 (m^2).
    pub target_area: f64,
}

impl Default for DesignOptions {
    fn default() -> Self {
        DesignOptions {
            bounds: PAPER_LAMBDA_BOUNDS,
            nodes: 1201,
            orientations: vec![0.0, std::f64::consts::FRAC_PI_4],
            target_area: 1.0,
        }
    }
}

/// One row of Table 1 (lengths in multiples of L, areas of L^2), paper beside computed.
/// Relative differences are (computed - paper) / paper.
#[derive(Debug, Clone, PartialEq)]
pub struct Table1Row {
    pub mechanism: String,
    pub l0_paper: f64,
    pub l0: f64,
    pub l0_rel_diff: f64,
    pub delta_rho_paper: f64,
    pub delta_rho: f64,
    pub delta_rho_rel_diff: f64,
    pub s_paper: f64,
    pub s: f64,
    pub s_rel_diff: f64,
    /// Sides of the rectangle S and the orientation of its sides (degrees).
    pub s_width: f64,
    pub s_height: f64,
    pub s_angle_deg: f64,
    /// Largest square in the workspace (over the same orientations) and its orientation.
    pub square: f64,
    pub square_angle_deg: f64,
    /// Envelope of the mechanism (see [`envelope`]), L^2.
    pub envelope: f64,
}

/// What the workspace of Table 2 is prescribed to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Rectangle,
    Square,
}

impl Target {
    pub fn name(self) -> &'static str {
        match self {
            Target::Rectangle => "rectangle",
            Target::Square => "square",
        }
    }
}

/// One row of Table 2: the design scaled so that its largest rectangle (or square) has the
/// target area; paper beside computed where the paper printed a value.
#[derive(Debug, Clone, PartialEq)]
pub struct Table2Row {
    pub mechanism: String,
    pub target: Target,
    pub l0_paper: Option<f64>,
    pub l0: f64,
    pub l0_rel_diff: Option<f64>,
    pub l_paper: Option<f64>,
    pub l: f64,
    pub l_rel_diff: Option<f64>,
    pub delta_rho_paper: Option<f64>,
    pub delta_rho: f64,
    pub delta_rho_rel_diff: Option<f64>,
    pub envelope_paper: Option<f64>,
    pub envelope: f64,
    pub envelope_rel_diff: Option<f64>,
}

fn rel_diff(computed: f64, paper: f64) -> f64 {
    (computed - paper) / paper
}

/// The largest rectangle and square of the workspace of `spec` over the given orientations.
fn best_shapes(spec: &GliderSpec, opts: &DesignOptions) -> (Option<Rectangle>, Option<Rectangle>) {
    let mut best_rect: Option<Rectangle> = None;
    let mut best_square: Option<Rectangle> = None;
    for &angle in &opts.orientations {
        let grid = sample_workspace(
            spec,
            &WorkspaceOptions {
                lambda_bounds: Some(opts.bounds),
                nodes: opts.nodes,
                frame_angle: angle,
                ..WorkspaceOptions::default()
            },
        );
        if let Some(r) = largest_rectangle(&grid)
            && best_rect.is_none_or(|b| r.area() > b.area())
        {
            best_rect = Some(r);
        }
        if let Some(r) = largest_square(&grid)
            && best_square.is_none_or(|b| r.area() > b.area())
        {
            best_square = Some(r);
        }
    }
    (best_rect, best_square)
}

/// Table 1 row of one architecture (section 3.2): design for L = 1, then S. `None` if the
/// bounds admit no design or the workspace is empty.
pub fn table1_row(arch: Architecture, opts: &DesignOptions) -> Option<Table1Row> {
    let spec = architecture_spec(arch, 1.0, opts.bounds)?;
    let (rect, square) = best_shapes(&spec, opts);
    let (rect, square) = (rect?, square?);
    let paper = arch.paper_table1();
    let delta_rho = spec.rho1_range[1] - spec.rho1_range[0];
    Some(Table1Row {
        mechanism: arch.name().to_string(),
        l0_paper: paper.l0,
        l0: spec.l0,
        l0_rel_diff: rel_diff(spec.l0, paper.l0),
        delta_rho_paper: paper.delta_rho,
        delta_rho,
        delta_rho_rel_diff: rel_diff(delta_rho, paper.delta_rho),
        s_paper: paper.s,
        s: rect.area(),
        s_rel_diff: rel_diff(rect.area(), paper.s),
        s_width: rect.width,
        s_height: rect.height,
        s_angle_deg: rect.angle.to_degrees(),
        square: square.area(),
        square_angle_deg: square.angle.to_degrees(),
        envelope: envelope(&spec),
    })
}

/// Table 1 for the three architectures, in the paper's order (rows that cannot be computed
/// under the given bounds are left out).
pub fn table1(opts: &DesignOptions) -> Vec<Table1Row> {
    Architecture::ALL
        .into_iter()
        .filter_map(|a| table1_row(a, opts))
        .collect()
}

/// Table 2 (section 3.3) from Table 1 rows: each design scaled by k = sqrt(target / S) (lengths)
/// and k^2 (envelope), first for the largest rectangle, then for the largest square.
pub fn table2(rows: &[Table1Row], target_area: f64) -> Vec<Table2Row> {
    let mut out = Vec::with_capacity(2 * rows.len());
    for target in [Target::Rectangle, Target::Square] {
        for row in rows {
            let arch = Architecture::from_name(&row.mechanism);
            let paper = arch.map(|a| match target {
                Target::Rectangle => a.paper_table2_rectangle(),
                Target::Square => a.paper_table2_square(),
            });
            let area = match target {
                Target::Rectangle => row.s,
                Target::Square => row.square,
            };
            let k = (target_area / area).sqrt();
            let (l0, l, delta_rho, envelope) =
                (row.l0 * k, k, row.delta_rho * k, row.envelope * k * k);
            let diff = |c: f64, p: Option<f64>| p.map(|p| rel_diff(c, p));
            out.push(Table2Row {
                mechanism: row.mechanism.clone(),
                target,
                l0_paper: paper.map(|p| p.l0),
                l0,
                l0_rel_diff: diff(l0, paper.map(|p| p.l0)),
                l_paper: paper.map(|p| p.l),
                l,
                l_rel_diff: diff(l, paper.map(|p| p.l)),
                delta_rho_paper: paper.map(|p| p.delta_rho),
                delta_rho,
                delta_rho_rel_diff: diff(delta_rho, paper.map(|p| p.delta_rho)),
                envelope_paper: paper.and_then(|p| p.envelope),
                envelope,
                envelope_rel_diff: diff(envelope, paper.and_then(|p| p.envelope)),
            });
        }
    }
    out
}
