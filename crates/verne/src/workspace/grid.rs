//! The box a workspace is sampled in (given, or derived from the machine's rod lengths, rod-tilt
//! limit and strokes: docs/workspace.md) and its grid.

use std::f64::consts::PI;

use nalgebra::Vector3;

use crate::spec::Machine;

use super::classify::manufacturing_tip;
use super::{Of, WorkspaceOptions};

/// Most grid points of one run (a guard against a typo in `--step`): 2^31.
pub const MAX_GRID_POINTS: u64 = 1 << 31;

/// Samples of the tilting angle used to bound the manufacturing workspace's default box; the
/// box is widened by the largest distance a corner moves between two samples.
const MANUFACTURING_BOUND_SAMPLES: usize = 64;

/// An axis-aligned box [min, max] (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub min: Vector3<f64>,
    pub max: Vector3<f64>,
}

/// A regular grid: points origin + step (i, j, k), 0 <= i < `n[0]`, ...
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub origin: Vector3<f64>,
    pub step: f64,
    pub n: [usize; 3],
}

impl Grid {
    /// The grid from `b.min` with the given step, up to `b.max` (the last point is the largest
    /// one not beyond `b.max`, within a part in 1e9 of the step).
    pub fn new(b: &Bounds, step: f64) -> Result<Grid, String> {
        if !(step.is_finite() && step > 0.0) {
            return Err(format!(
                "the step must be a positive number of mm, got {step}"
            ));
        }
        // Counted in f64 first: a tiny step or huge bounds must be refused, not wrap around.
        let mut counts = [0f64; 3];
        for (d, name) in ["x", "y", "z"].iter().enumerate() {
            let (lo, hi) = (b.min[d], b.max[d]);
            if !(lo.is_finite() && hi.is_finite()) || lo > hi {
                return Err(format!(
                    "bounds: {name} range [{lo}, {hi}] is empty or not finite"
                ));
            }
            counts[d] = ((hi - lo) / step + 1e-9).floor() + 1.0;
        }
        let total = counts[0] * counts[1] * counts[2];
        // NaN cannot arise (finite bounds, positive step); `>` also refuses infinity.
        if total > MAX_GRID_POINTS as f64 {
            let show = |c: f64| {
                if c < 1e15 {
                    format!("{c}")
                } else {
                    format!("{c:.3e}")
                }
            };
            return Err(format!(
                "{} x {} x {} = {} grid points is more than {MAX_GRID_POINTS}: increase the step or narrow the bounds",
                show(counts[0]),
                show(counts[1]),
                show(counts[2]),
                show(total)
            ));
        }
        let n = counts.map(|c| c as usize);
        Ok(Grid {
            origin: b.min,
            step,
            n,
        })
    }

    pub fn len(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.n[1] + j) * self.n[0] + i
    }

    #[inline]
    pub fn point(&self, i: usize, j: usize, k: usize) -> Vector3<f64> {
        self.origin + Vector3::new(i as f64, j as f64, k as f64) * self.step
    }

    /// Coordinate of index `i` along axis `d`.
    #[inline]
    pub fn coord(&self, d: usize, i: usize) -> f64 {
        self.origin[d] + i as f64 * self.step
    }

    /// The last grid point.
    pub fn max(&self) -> Vector3<f64> {
        self.point(self.n[0] - 1, self.n[1] - 1, self.n[2] - 1)
    }
}

/// A box of grid points, index ranges inclusive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridBox {
    pub lo: [usize; 3],
    pub hi: [usize; 3],
}

impl GridBox {
    /// Edge lengths in steps.
    pub fn edges(&self) -> [usize; 3] {
        [0, 1, 2].map(|d| self.hi[d] - self.lo[d])
    }
}

/// A box that contains every point of the workspace (a proven superset), before rounding.
///
/// Platform: with a rod tilt of at most `rod_tilt_max` = tau from its slider axis (z), a rod's
/// horizontal extent is at most L sin(tau) and its vertical extent, slider above platform
/// (s = -1), between L max(cos(tau), 0) and L (for tau >= 90 degrees, L and 0). With the
/// platform attachments at most R from P vertically, and eqs. (3)-(6):
/// - x: |xp + D1 - d1| <= L1 sin(tau), |xp + D2 - d2| <= L2 sin(tau) and L3 sin(tau);
/// - y: |yp| <= L1 sin(tau) (both leg-I rods), yp in [-r4 - R2 - L2 sin(tau), r4 + R2 + ...]
///   per leg II and III;
/// - z: zp in [rho_min + L cos(tau) - R, rho_max + L + R] for every leg.
///
/// Tool: that box widened by Delta in y and z (eq. (27)). Manufacturing: the platform box's
/// (y, z) rectangle mapped by eq. (26) for theta1 sampled over [theta1_min, theta1_max],
/// widened by the largest distance a corner moves between two samples.
pub fn default_bounds(m: &Machine, of: Of, tool_length: f64) -> Bounds {
    // The equations' strokes and tilting range (the file's moved by the joints' zero offsets).
    let model = m.model();
    let m = &*model;
    let g = &m.module;
    let lim = &m.limits;
    let tau = lim.rod_tilt_max;
    let hs = if tau < PI / 2.0 { tau.sin() } else { 1.0 };
    let vc = tau.cos().max(0.0);
    let legs = [
        (g.dx1, g.l1, g.r_big1, 0),
        (g.dx2, g.l2, g.r_big2, 1),
        (g.dx2, g.l3, g.r_big2, 2),
    ];
    let mut min = Vector3::repeat(f64::NEG_INFINITY);
    let mut max = Vector3::repeat(f64::INFINITY);
    for (dx, l, r, i) in legs {
        min.x = min.x.max(-dx - l * hs);
        max.x = max.x.min(-dx + l * hs);
        min.z = min.z.max(lim.rho_min[i] + l * vc - r);
        max.z = max.z.min(lim.rho_max[i] + l + r);
    }
    min.y = (-g.l1 * hs)
        .max(-g.r4 - g.r_big2 - g.l2 * hs)
        .max(g.r4 - g.r_big2 - g.l3 * hs);
    max.y = (g.l1 * hs)
        .min(-g.r4 + g.r_big2 + g.l2 * hs)
        .min(g.r4 + g.r_big2 + g.l3 * hs);
    // An empty intersection (a machine that cannot move) still gives a one-point box.
    for d in 0..3 {
        if min[d] > max[d] {
            let mid = 0.5 * (min[d] + max[d]);
            min[d] = mid;
            max[d] = mid;
        }
    }
    let d = tool_length.abs();
    match of {
        Of::Platform => Bounds { min, max },
        Of::Tool => Bounds {
            min: min - Vector3::new(0.0, d, d),
            max: max + Vector3::new(0.0, d, d),
        },
        Of::Manufacturing => {
            let (lo, hi) = (lim.theta1_min.max(-PI), lim.theta1_max.min(PI));
            let n = MANUFACTURING_BOUND_SAMPLES;
            let dth = (hi - lo) / n as f64;
            let mut bmin = Vector3::new(min.x, f64::INFINITY, f64::INFINITY);
            let mut bmax = Vector3::new(max.x, f64::NEG_INFINITY, f64::NEG_INFINITY);
            let mut radius: f64 = 0.0;
            for k in 0..=n {
                let th = lo + dth * k as f64;
                for (y, z) in [
                    (min.y, min.z),
                    (min.y, max.z),
                    (max.y, min.z),
                    (max.y, max.z),
                ] {
                    let p = Vector3::new(0.0, y, z);
                    let q = manufacturing_tip(&m.table, &p, th, tool_length);
                    radius = radius.max(y.hypot(z - m.table.d_a));
                    for dd in 1..3 {
                        bmin[dd] = bmin[dd].min(q[dd]);
                        bmax[dd] = bmax[dd].max(q[dd]);
                    }
                }
            }
            let margin = radius * dth / 2.0;
            bmin.y -= margin;
            bmin.z -= margin;
            bmax.y += margin;
            bmax.z += margin;
            Bounds {
                min: bmin,
                max: bmax,
            }
        }
    }
}

/// `b` rounded outward to multiples of `step`.
pub fn round_bounds(b: &Bounds, step: f64) -> Bounds {
    Bounds {
        min: b.min.map(|v| (v / step).floor() * step),
        max: b.max.map(|v| (v / step).ceil() * step),
    }
}

/// The grid a run with these options samples.
pub fn grid_for(m: &Machine, opts: &WorkspaceOptions) -> Result<Grid, String> {
    let bounds = match opts.bounds {
        Some(b) => b,
        None => round_bounds(&default_bounds(m, opts.of, opts.tool_length), opts.step),
    };
    if !(opts.lambda[0] <= opts.lambda[1] && opts.lambda[0] >= 0.0) {
        return Err(format!(
            "lambda bounds [{}, {}]: need 0 <= LO <= HI",
            opts.lambda[0], opts.lambda[1]
        ));
    }
    if !opts.tool_length.is_finite() {
        return Err("the tool length must be a finite number of mm".into());
    }
    Grid::new(&bounds, opts.step)
}
