//! Plain `[f64; 3]` vector math and the frames of SPEC §6.

pub(super) type V3 = [f64; 3];
/// 3×3 matrix stored by rows.
pub(super) type M3 = [[f64; 3]; 3];

pub(super) const IDENTITY: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

pub(super) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(super) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub(super) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn norm(a: V3) -> f64 {
    // hypot-like scaling so that huge finite components do not overflow to infinity
    let m = a[0].abs().max(a[1].abs()).max(a[2].abs());
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let b = scale(a, 1.0 / m);
    m * dot(b, b).sqrt()
}

/// `a / |a|`; `None` when `|a| < min` (or not finite).
pub(super) fn unit(a: V3, min: f64) -> Option<V3> {
    let n2 = dot(a, a);
    // the plain formula unless the squares overflow or underflow
    let n = if n2.is_normal() && n2 < 1e300 && n2 > 1e-300 {
        n2.sqrt()
    } else {
        norm(a)
    };
    if n.is_nan() || n < min || !n.is_finite() {
        return None;
    }
    Some(scale(a, 1.0 / n))
}

pub(super) fn finite(a: V3) -> bool {
    a.iter().all(|x| x.is_finite())
}

pub(super) fn mat_vec(m: &M3, v: V3) -> V3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

pub(super) fn transpose(m: &M3) -> M3 {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

pub(super) fn mat_mul(a: &M3, b: &M3) -> M3 {
    let bt = transpose(b);
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(a[i], bt[j]);
        }
    }
    r
}

/// A frame: `x_world = o + r x_local` (SPEC §6.1: `P_ACS = O + R p`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Frame {
    pub(super) o: V3,
    pub(super) r: M3,
}

impl Frame {
    pub(super) const IDENTITY: Frame = Frame {
        o: [0.0; 3],
        r: IDENTITY,
    };
}

/// The map from the current frame's coordinates to the output frame's (SPEC §6.1):
/// `p_out = R1ᵀ (O + R p − O1)`, `a_out = R1ᵀ R a`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Xform {
    m: M3,
    t: V3,
    identity: bool,
}

impl Xform {
    pub(super) const IDENTITY: Xform = Xform {
        m: IDENTITY,
        t: [0.0; 3],
        identity: true,
    };

    /// From `frame` (where the coordinates are written) to `output`.
    pub(super) fn between(frame: &Frame, output: &Frame) -> Xform {
        if frame == output {
            return Xform::IDENTITY;
        }
        let r1t = transpose(&output.r);
        Xform {
            m: mat_mul(&r1t, &frame.r),
            t: mat_vec(&r1t, sub(frame.o, output.o)),
            identity: false,
        }
    }

    pub(super) fn point(&self, p: V3) -> V3 {
        if self.identity {
            p
        } else {
            add(mat_vec(&self.m, p), self.t)
        }
    }

    pub(super) fn vector(&self, v: V3) -> V3 {
        if self.identity {
            v
        } else {
            mat_vec(&self.m, v)
        }
    }
}

/// Spherical interpolation between unit vectors `a` and `b` at `t` in [0, 1]; `None` when they
/// are opposite (no unique great circle).
pub(super) fn slerp(a: V3, b: V3, t: f64) -> Option<V3> {
    let c = dot(a, b).clamp(-1.0, 1.0);
    let w = c.acos();
    if w < 1e-12 {
        return Some(a);
    }
    let s = w.sin();
    if s < 1e-9 {
        return None;
    }
    let p = ((1.0 - t) * w).sin() / s;
    let q = (t * w).sin() / s;
    unit(add(scale(a, p), scale(b, q)), 1e-300)
}
