//! Arcs and helices of `CIRCLE` records (SPEC §7): geometry, checks, interpolation.

use std::f64::consts::{PI, TAU};

use super::error::ClErrorKind;
use super::geom::{V3, add, cross, dot, finite, norm, scale, slerp, sub, unit};
use super::types::ArcRule;

/// Start, end and given radius must agree within this, mm (SPEC §7.1).
pub(super) const TOL_RADIUS: f64 = 0.005;
/// Points given after `CIRCLE` (Creo) must be on the arc within this, mm (SPEC §7.4).
pub(super) const TOL_ON_ARC: f64 = 0.005;
/// Start and end closer than this (radially) make a full circle, mm (SPEC §7.2).
pub(super) const FULL_CIRCLE: f64 = 1e-6;

/// An arc from the current position to an end point, in the output frame, mm.
#[derive(Debug, Clone, Copy)]
pub(super) struct Arc {
    /// Centre.
    c: V3,
    /// Rotation axis: the tool travels counter-clockwise about it (right-hand rule).
    u: V3,
    /// Unit radial direction of the start, and `u × e1`.
    e1: V3,
    e2: V3,
    /// Start and end radius.
    rs: f64,
    re: f64,
    /// Axial offsets of start and end along `u`.
    hs: f64,
    he: f64,
    /// Angle travelled, radians, in (0, 2π].
    sweep: f64,
}

impl Arc {
    /// The arc of a `CIRCLE` with centre `c`, unit axis `axis` (as written, in the output
    /// frame) and optional radius, from `start` to `end`.
    pub(super) fn new(
        c: V3,
        axis: V3,
        radius: Option<f64>,
        rule: ArcRule,
        start: V3,
        end: V3,
    ) -> Result<Arc, ClErrorKind> {
        let u = match rule {
            ArcRule::RightHand => axis,
            ArcRule::ClockwiseAboutAxis => scale(axis, -1.0),
        };
        let ds = sub(start, c);
        let de = sub(end, c);
        let hs = dot(ds, u);
        let he = dot(de, u);
        let sr = sub(ds, scale(u, hs));
        let er = sub(de, scale(u, he));
        let rs = norm(sr);
        let re = norm(er);
        if !(rs.is_finite() && re.is_finite() && hs.is_finite() && he.is_finite()) {
            return Err(ClErrorKind::NumberOutOfRange {
                record: "CIRCLE".into(),
            });
        }
        if (rs - re).abs() > TOL_RADIUS {
            return Err(ClErrorKind::ArcRadius { start: rs, end: re });
        }
        if radius.is_some_and(|r| (rs - r).abs() > TOL_RADIUS || (re - r).abs() > TOL_RADIUS) {
            let r = radius.unwrap_or(0.0);
            return Err(ClErrorKind::ArcRadiusGiven {
                given: r,
                start: rs,
                end: re,
            });
        }
        let Some(e1) = unit(sr, 1e-9) else {
            return Err(ClErrorKind::ArcZeroRadius);
        };
        let e2 = cross(u, e1);
        let chord = norm(sub(er, sr));
        let sweep = if chord < FULL_CIRCLE {
            TAU
        } else {
            let mut a = dot(u, cross(sr, er)).atan2(dot(sr, er));
            if a <= 0.0 {
                a += TAU;
            }
            if chord < TOL_RADIUS && a > PI {
                return Err(ClErrorKind::ArcAmbiguous { chord });
            }
            a
        };
        Ok(Arc {
            c,
            u,
            e1,
            e2,
            rs,
            re,
            hs,
            he,
            sweep,
        })
    }

    /// Sweep, radians.
    #[cfg(test)]
    pub(super) fn sweep(&self) -> f64 {
        self.sweep
    }

    /// Length along the arc (the helix for a helix), mm (SPEC §5.6 inverse time).
    pub(super) fn length(&self) -> f64 {
        (self.rs * self.sweep).hypot(self.he - self.hs)
    }

    /// The point at angle `a` from the start (radius and axial offset linear in the angle).
    pub(super) fn point(&self, a: f64) -> V3 {
        let t = a / self.sweep;
        let r = self.rs + (self.re - self.rs) * t;
        let h = self.hs + (self.he - self.hs) * t;
        let (s, co) = a.sin_cos();
        let radial = add(scale(self.e1, r * co), scale(self.e2, r * s));
        add(add(self.c, scale(self.u, h)), radial)
    }

    /// Checks a point given on the arc (Creo, SPEC §7.4) that must come after angle `prev`;
    /// returns its angle.
    pub(super) fn check_point(&self, q: V3, prev: f64) -> Result<f64, ClErrorKind> {
        let d = sub(q, self.c);
        let h = dot(d, self.u);
        let radial = sub(d, scale(self.u, h));
        let r = norm(radial);
        let off = (r - self.rs).abs();
        if off > TOL_ON_ARC || !off.is_finite() {
            return Err(ClErrorKind::ArcPointOff { distance: off });
        }
        let mut a = dot(radial, self.e2).atan2(dot(radial, self.e1));
        if a < 0.0 {
            a += TAU;
        }
        // angular slack equivalent to the distance tolerance
        let eps = (TOL_ON_ARC / self.rs.max(TOL_ON_ARC)).min(0.5);
        if a > TAU - eps && prev < eps {
            // at the start, a hair before it
            a -= TAU;
        }
        if a < prev - eps {
            // past the start point again (full circles): one more turn
            a += TAU;
        }
        if a < prev - eps || a > self.sweep + eps {
            return Err(ClErrorKind::ArcPointOrder);
        }
        let h_expected = self.hs + (self.he - self.hs) * (a / self.sweep).clamp(0.0, 1.0);
        let dh = (h - h_expected).abs();
        if dh > TOL_ON_ARC {
            return Err(ClErrorKind::ArcPointOff { distance: dh });
        }
        Ok(a.max(prev))
    }

    /// Number of chords so that each stays within `tol` of the arc (at most 90° each).
    pub(super) fn segments(&self, tol: f64) -> f64 {
        let r = self.rs.max(self.re);
        let step = if tol < r {
            2.0 * (1.0 - tol / r).acos()
        } else {
            PI
        };
        let step = step.min(PI / 2.0);
        (self.sweep / step).ceil().max(1.0)
    }

    /// Whether all interpolated points are finite.
    pub(super) fn finite(&self) -> bool {
        let big = norm(self.c) + self.rs.max(self.re) + self.hs.abs().max(self.he.abs());
        finite(self.c) && big.is_finite() && big < 1e300
    }
}

/// Lazy generator of the rows of one arc: `n - 1` interpolated points, then the end point.
#[derive(Debug, Clone, Copy)]
pub(super) struct ArcRows {
    arc: Arc,
    n: u64,
    i: u64,
    end: V3,
    a0: V3,
    a1: V3,
    turn_axis: bool,
}

impl ArcRows {
    pub(super) fn new(arc: Arc, n: u64, end: V3, a0: V3, a1: V3) -> Result<ArcRows, ClErrorKind> {
        let turn_axis = a0 != a1;
        if turn_axis && slerp(a0, a1, 0.5).is_none() {
            return Err(ClErrorKind::ArcAxisFlip);
        }
        Ok(ArcRows {
            arc,
            n,
            i: 0,
            end,
            a0,
            a1,
            turn_axis,
        })
    }

    /// The next (tip, axis), or `None` after the end point.
    pub(super) fn next_point(&mut self) -> Option<(V3, V3)> {
        if self.i >= self.n {
            return None;
        }
        self.i += 1;
        if self.i == self.n {
            return Some((self.end, self.a1));
        }
        let t = self.i as f64 / self.n as f64;
        let p = self.arc.point(self.arc.sweep * t);
        let a = if self.turn_axis {
            slerp(self.a0, self.a1, t).unwrap_or(self.a1)
        } else {
            self.a0
        };
        Some((p, a))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: V3, b: V3) -> bool {
        norm(sub(a, b)) < 1e-9
    }

    #[test]
    fn direction_by_rule() {
        // quarter from (10,0) to (0,10) about +Z
        let c = [0.0, 0.0, 0.0];
        let z = [0.0, 0.0, 1.0];
        let a = Arc::new(
            c,
            z,
            Some(10.0),
            ArcRule::RightHand,
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
        )
        .unwrap();
        assert!((a.sweep() - PI / 2.0).abs() < 1e-12);
        assert!(close(
            a.point(PI / 4.0),
            [10.0 / 2f64.sqrt(), 10.0 / 2f64.sqrt(), 0.0]
        ));
        let b = Arc::new(
            c,
            z,
            Some(10.0),
            ArcRule::ClockwiseAboutAxis,
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
        )
        .unwrap();
        assert!((b.sweep() - 1.5 * PI).abs() < 1e-12);
        assert!(close(b.point(PI / 2.0), [0.0, -10.0, 0.0]));
    }

    #[test]
    fn full_circle_helix_and_checks() {
        let c = [0.0, 0.0, -5.0];
        let z = [0.0, 0.0, 1.0];
        let a = Arc::new(
            c,
            z,
            None,
            ArcRule::RightHand,
            [10.0, 0.0, -5.0],
            [10.0, 0.0, -6.5],
        )
        .unwrap();
        assert!((a.sweep() - TAU).abs() < 1e-12);
        assert!(close(a.point(PI), [-10.0, 0.0, -5.75]));
        assert!(a.check_point([0.0, 10.0, -5.375], 0.0).is_ok());
        assert_eq!(a.check_point([0.0, -10.0, -6.125], 4.0), Ok(1.5 * PI));
        assert!(matches!(
            a.check_point([0.0, 10.1, -5.375], 0.0),
            Err(ClErrorKind::ArcPointOff { .. })
        ));
        assert!(matches!(
            a.check_point([0.0, 10.0, -6.0], 0.0),
            Err(ClErrorKind::ArcPointOff { .. })
        ));
        assert_eq!(
            a.check_point([0.0, 10.0, -5.375], 3.5),
            Err(ClErrorKind::ArcPointOrder)
        );
        // radius checks, ambiguity, zero radius
        assert!(matches!(
            Arc::new(
                c,
                z,
                None,
                ArcRule::RightHand,
                [10.0, 0.0, -5.0],
                [0.0, 10.01, -5.0]
            ),
            Err(ClErrorKind::ArcRadius { .. })
        ));
        assert!(matches!(
            Arc::new(
                c,
                z,
                Some(9.9),
                ArcRule::RightHand,
                [10.0, 0.0, -5.0],
                [0.0, 10.0, -5.0]
            ),
            Err(ClErrorKind::ArcRadiusGiven { .. })
        ));
        assert!(matches!(
            Arc::new(
                c,
                z,
                None,
                ArcRule::RightHand,
                [10.0, 0.0, -5.0],
                [10.0, -0.001, -5.0]
            ),
            Err(ClErrorKind::ArcAmbiguous { .. })
        ));
        assert!(
            Arc::new(
                c,
                z,
                None,
                ArcRule::RightHand,
                [10.0, 0.0, -5.0],
                [10.0, 0.001, -5.0]
            )
            .is_ok()
        );
        assert_eq!(
            Arc::new(
                c,
                z,
                None,
                ArcRule::RightHand,
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0]
            )
            .unwrap_err(),
            ClErrorKind::ArcZeroRadius
        );
    }

    #[test]
    fn chord_error_within_tolerance() {
        for &(r, tol) in &[(10.0, 0.005), (0.5, 0.005), (1000.0, 0.001), (0.001, 0.005)] {
            let a = Arc::new(
                [0.0; 3],
                [0.0, 0.0, 1.0],
                None,
                ArcRule::RightHand,
                [r, 0.0, 0.0],
                [r, 0.0, 0.0],
            )
            .unwrap();
            let n = a.segments(tol);
            let step = a.sweep() / n;
            let sagitta = r * (1.0 - (step / 2.0).cos());
            assert!(sagitta <= tol * (1.0 + 1e-9), "r {r} tol {tol}: {sagitta}");
            assert!(step <= PI / 2.0 + 1e-12);
        }
    }
}
