//! Jacobian matrices A and B of a glider (section 2.3, Wenger 2001), its parallel (section 2.4)
//! and serial (section 2.5) singularities, and the velocity amplification factors (section 2.7).

use nalgebra::{Matrix2, Point2, Vector2};

use super::spec::GliderSpec;
use super::tolerance::{PARALLEL_SINGULAR_SIN, SERIAL_SINGULAR_COS};

/// The two Jacobians of eqs. (2a)-(2b), Wenger 2001: A p' = B rho'.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jacobians {
    /// Parallel Jacobian: rows (p - c)^T and (p - d)^T.
    pub a: Matrix2<f64>,
    /// Serial Jacobian: diag((p - c).u1, (p - d).u2), u_i the unit guide directions.
    pub b: Matrix2<f64>,
}

/// The velocity amplification factors of section 2.7, Wenger 2001: lambda_i = 1/gamma_i with
/// gamma_i the singular values of J^-1 = B^-1 A (eq. (3b)), i.e. the singular values of
/// J = A^-1 B (eq. (3a)): output speed of P per unit joint speed along the principal axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Amplification {
    /// Smallest factor (0 at a serial singularity).
    pub lambda_min: f64,
    /// Largest factor.
    pub lambda_max: f64,
}

impl Amplification {
    /// Whether both factors satisfy lo < lambda < hi (eq. (4), Wenger 2001, with lo = 1/3 and
    /// hi = 3), with the slack [`LAMBDA_BOUND_SLACK`](super::tolerance::LAMBDA_BOUND_SLACK).
    pub fn within(&self, lo: f64, hi: f64) -> bool {
        self.outside(lo, hi) == (false, false)
    }

    /// Which bound of [`within`](Self::within) fails: (lambda_min below lo, lambda_max above
    /// hi); a factor that is not a number fails its bound.
    pub fn outside(&self, lo: f64, hi: f64) -> (bool, bool) {
        let s = super::tolerance::LAMBDA_BOUND_SLACK;
        use std::cmp::Ordering::{Equal, Greater, Less};
        (
            !matches!(
                self.lambda_min.partial_cmp(&(lo * (1.0 - s))),
                Some(Greater | Equal)
            ),
            !matches!(
                self.lambda_max.partial_cmp(&(hi * (1.0 + s))),
                Some(Less | Equal)
            ),
        )
    }
}

/// A and B of eqs. (2a)-(2b) at the pose (P, rho).
pub fn jacobians(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> Jacobians {
    let (c, d) = spec.sliders(rho);
    let (pc, pd) = (p - c, p - d);
    Jacobians {
        a: Matrix2::new(pc.x, pc.y, pd.x, pd.y),
        b: Matrix2::new(pc.dot(&spec.u1()), 0.0, 0.0, pd.dot(&spec.u2())),
    }
}

/// det A = (p - c) x (p - d): zero when C, D and P are aligned (section 2.4, Wenger 2001).
pub fn det_a(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> f64 {
    jacobians(spec, p, rho).a.determinant()
}

/// det B = ((p - c).u1) ((p - d).u2): zero when a strut is orthogonal to its guide
/// (section 2.5, Wenger 2001).
pub fn det_b(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> f64 {
    let b = jacobians(spec, p, rho).b;
    b[(0, 0)] * b[(1, 1)]
}

/// Parallel singularity (section 2.4): |det A| / (l1 l2), the sine of the angle between the
/// struts, below [`PARALLEL_SINGULAR_SIN`].
pub fn is_parallel_singular(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> bool {
    det_a(spec, p, rho).abs() / (spec.l1 * spec.l2) <= PARALLEL_SINGULAR_SIN
}

/// Serial singularity (section 2.5): some |B_ii| / l_i, the cosine of the angle between strut i
/// and its guide, below [`SERIAL_SINGULAR_COS`].
pub fn is_serial_singular(spec: &GliderSpec, p: Point2<f64>, rho: Vector2<f64>) -> bool {
    let b = jacobians(spec, p, rho).b;
    (b[(0, 0)] / spec.l1).abs() <= SERIAL_SINGULAR_COS
        || (b[(1, 1)] / spec.l2).abs() <= SERIAL_SINGULAR_COS
}

/// Singular values (largest, smallest) of a 2x2 matrix, in closed form.
pub fn singular_values_2x2(m: &Matrix2<f64>) -> (f64, f64) {
    let e = 0.5 * (m[(0, 0)] + m[(1, 1)]);
    let f = 0.5 * (m[(0, 0)] - m[(1, 1)]);
    let g = 0.5 * (m[(1, 0)] + m[(0, 1)]);
    let h = 0.5 * (m[(1, 0)] - m[(0, 1)]);
    let q = e.hypot(h);
    let r = f.hypot(g);
    (q + r, (q - r).abs())
}

/// Velocity amplification factors of section 2.7 at (P, rho): singular values of
/// J = A^-1 B (eq. (3a)), computed as those of adj(A) B divided by |det A|. `None` at a
/// parallel singularity, where the largest factor is unbounded.
pub fn amplification(
    spec: &GliderSpec,
    p: Point2<f64>,
    rho: Vector2<f64>,
) -> Option<Amplification> {
    let j = jacobians(spec, p, rho);
    let det = j.a.determinant();
    if det.abs() / (spec.l1 * spec.l2) <= PARALLEL_SINGULAR_SIN {
        return None;
    }
    let adj = Matrix2::new(j.a[(1, 1)], -j.a[(0, 1)], -j.a[(1, 0)], j.a[(0, 0)]);
    let (hi, lo) = singular_values_2x2(&(adj * j.b));
    Some(Amplification {
        lambda_min: lo / det.abs(),
        lambda_max: hi / det.abs(),
    })
}
