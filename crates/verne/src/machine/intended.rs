//! The intended move between two tool poses of a path, as a CAM system means it and as `verne
//! verify` and the post check it: the tip on the straight line at the uniform fraction s, and the
//! tool axis turning uniformly in the plane of its two ends (the great circle, APT's meaning of a
//! 5-axis GOTO); or, when the path states the tool angles at both ends (a tool-centre program's
//! angle words, a CSV's phi1,phi2), the angles interpolated linearly, as the controller of such a
//! program moves them ([`super::orientation::move_angles`]).

use nalgebra::Vector3;

use super::orientation::{move_angles, tool_axis};
use crate::math::interval::Iv;

/// Two axes this close (rad) are the same: the axis does not turn.
const SAME_AXIS_RAD: f64 = 1e-12;

/// Two axes this close to opposite (rad) have no plane to turn in.
const OPPOSITE_AXIS_RAD: f64 = 1e-6;

/// How the axis turns.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Turn {
    /// Along the great circle from `ua` to `ub`, through the angle `omega` (rad).
    Arc { omega: f64 },
    /// The tool angles (phi1, phi2) interpolated from `from` to `to` (rad).
    Angles { from: (f64, f64), to: (f64, f64) },
}

/// The angles a row states, when its joints realize them (phi1 = alpha - theta1 and
/// phi2 = -theta2 up to whole turns, within [`SAME_ANGLES_RAD`]): a controller interpolates
/// the stated angles only where the joints follow them. Near the table normal a path follower
/// may keep theta2 still where the stated phi2 turns (the axis is the same); the move is then
/// the axis's great circle.
pub fn followed_angles(stated: Option<(f64, f64)>, achieved: (f64, f64)) -> Option<(f64, f64)> {
    let (p1, p2) = stated?;
    let same =
        |a: f64, b: f64| crate::parallel_module::ik::wrap_angle(a - b).abs() <= SAME_ANGLES_RAD;
    (same(p1, achieved.0) && same(p2, achieved.1)).then_some((p1, p2))
}

/// Stated and achieved tool angles this close (rad) are the same.
pub const SAME_ANGLES_RAD: f64 = 1e-6;

/// The intended move from pose A to pose B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntendedMove {
    /// Tips (mm).
    pub a: Vector3<f64>,
    pub b: Vector3<f64>,
    /// Unit tool axes.
    pub ua: Vector3<f64>,
    pub ub: Vector3<f64>,
    turn: Turn,
}

/// Why two poses do not define a move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OppositeAxes;

impl std::fmt::Display for OppositeAxes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the tool axis turns half a turn in one move: no plane to turn it in")
    }
}

impl IntendedMove {
    /// The move from (tip `a`, unit axis `ua`) to (`b`, `ub`); the stated angles of each end
    /// when the path states them.
    pub fn new(
        a: Vector3<f64>,
        ua: Vector3<f64>,
        stated_a: Option<(f64, f64)>,
        b: Vector3<f64>,
        ub: Vector3<f64>,
        stated_b: Option<(f64, f64)>,
    ) -> Result<IntendedMove, OppositeAxes> {
        let turn = match (stated_a, stated_b) {
            (Some(_), Some(_)) => {
                let [from, to] = move_angles(&ua, stated_a, &ub, stated_b);
                Turn::Angles { from, to }
            }
            _ => {
                let omega = ua.angle(&ub);
                if std::f64::consts::PI - omega < OPPOSITE_AXIS_RAD {
                    return Err(OppositeAxes);
                }
                Turn::Arc { omega }
            }
        };
        Ok(IntendedMove { a, b, ua, ub, turn })
    }

    /// The part of the move from fraction `s0` to `s1`, as a move of its own (the same line, the
    /// same arc or the same angles, uniform again in its own fraction).
    pub fn between(&self, s0: f64, s1: f64) -> IntendedMove {
        let turn = match self.turn {
            Turn::Arc { omega } => Turn::Arc {
                omega: omega * (s1 - s0),
            },
            Turn::Angles { .. } => Turn::Angles {
                from: self.angles(s0).unwrap_or_default(),
                to: self.angles(s1).unwrap_or_default(),
            },
        };
        IntendedMove {
            a: self.tip(s0),
            b: self.tip(s1),
            ua: self.axis(s0),
            ub: self.axis(s1),
            turn,
        }
    }

    /// The intended tip at fraction `s` of the move.
    pub fn tip(&self, s: f64) -> Vector3<f64> {
        self.a + (self.b - self.a) * s
    }

    /// The intended tool axis (unit) at fraction `s` of the move.
    pub fn axis(&self, s: f64) -> Vector3<f64> {
        match self.turn {
            Turn::Arc { omega } if omega < SAME_AXIS_RAD => self.ua,
            Turn::Arc { omega } => {
                let k = 1.0 / omega.sin();
                self.ua * (((1.0 - s) * omega).sin() * k) + self.ub * ((s * omega).sin() * k)
            }
            Turn::Angles { from, to } => {
                tool_axis(from.0 + s * (to.0 - from.0), from.1 + s * (to.1 - from.1))
            }
        }
    }

    /// The tool angles the axis is interpolated by, when the path states them: (phi1, phi2) at
    /// fraction `s`.
    pub fn angles(&self, s: f64) -> Option<(f64, f64)> {
        match self.turn {
            Turn::Angles { from, to } => {
                Some((from.0 + s * (to.0 - from.0), from.1 + s * (to.1 - from.1)))
            }
            Turn::Arc { .. } => None,
        }
    }

    /// The intended axis and its rate d/ds over an interval of s, enclosed.
    pub fn axis_over(&self, s: Iv) -> ([Iv; 3], [Iv; 3]) {
        let p = |v: f64| Iv::point(v);
        match self.turn {
            Turn::Arc { omega } if omega < SAME_AXIS_RAD => {
                let zero = p(0.0);
                (
                    [p(self.ua.x), p(self.ua.y), p(self.ua.z)],
                    [zero, zero, zero],
                )
            }
            Turn::Arc { omega } => {
                let k = p(1.0) / p(omega).sin_cos().0;
                let w = p(omega);
                let (s1, c1) = ((p(1.0) - s) * w).sin_cos();
                let (s2, c2) = (s * w).sin_cos();
                let axis = std::array::from_fn(|i| (p(self.ua[i]) * s1 + p(self.ub[i]) * s2) * k);
                let rate =
                    std::array::from_fn(|i| (p(self.ub[i]) * c2 - p(self.ua[i]) * c1) * w * k);
                (axis, rate)
            }
            Turn::Angles { from, to } => {
                let (d1, d2) = (to.0 - from.0, to.1 - from.1);
                let phi1 = p(from.0) + s * p(d1);
                let phi2 = p(from.1) + s * p(d2);
                let (s1, c1) = phi1.sin_cos();
                let (s2, c2) = phi2.sin_cos();
                // eq. (8), AIM 2007: a = (sin phi1 sin phi2, -sin phi1 cos phi2, cos phi1).
                let axis = [s1 * s2, -(s1 * c2), c1];
                let rate = [
                    c1 * s2 * p(d1) + s1 * c2 * p(d2),
                    -(c1 * c2 * p(d1)) + s1 * s2 * p(d2),
                    -(s1 * p(d1)),
                ];
                (axis, rate)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The arc is uniform: the axis at s is s of the way round, unit, in the plane of the ends;
    /// the enclosure of the axis and of its rate hold the values at points inside (rate by a
    /// central difference).
    #[test]
    fn the_axis_turns_uniformly_and_its_enclosures_hold() {
        let ua = tool_axis(0.2, 0.3);
        let ub = tool_axis(0.7, -0.4);
        let omega = ua.angle(&ub);
        let mv = IntendedMove::new(Vector3::zeros(), ua, None, Vector3::x(), ub, None).unwrap();
        let stated = IntendedMove::new(
            Vector3::zeros(),
            ua,
            Some((0.2, 0.3)),
            Vector3::x(),
            ub,
            Some((0.7, -0.4)),
        )
        .unwrap();
        for k in 0..=20 {
            let s = k as f64 / 20.0;
            let h = mv.axis(s);
            assert!((h.norm() - 1.0).abs() < 1e-14);
            assert!((h.angle(&ua) - s * omega).abs() < 1e-12);
            assert!(h.dot(&ua.cross(&ub)).abs() < 1e-14);
            let (p1, p2) = stated.angles(s).unwrap();
            assert!((stated.axis(s) - tool_axis(p1, p2)).norm() < 1e-15);
        }
        for m in [mv, stated] {
            for k in 0..8 {
                let s = Iv::new(k as f64 / 8.0, (k + 1) as f64 / 8.0);
                let (axis, rate) = m.axis_over(s);
                for j in 0..=10 {
                    let t = s.lo + (s.hi - s.lo) * j as f64 / 10.0;
                    let h = m.axis(t);
                    let d = (m.axis(t + 1e-6) - m.axis(t - 1e-6)) / 2e-6;
                    for i in 0..3 {
                        assert!(axis[i].lo <= h[i] && h[i] <= axis[i].hi);
                        assert!(rate[i].lo - 1e-8 <= d[i] && d[i] <= rate[i].hi + 1e-8);
                    }
                }
            }
        }
        assert!(IntendedMove::new(Vector3::zeros(), ua, None, Vector3::x(), -ua, None).is_err());
        // A part of the move is the move there, uniform in its own fraction.
        for m in [mv, stated] {
            let part = m.between(0.25, 0.75);
            for k in 0..=10 {
                let t = k as f64 / 10.0;
                let s = 0.25 + 0.5 * t;
                assert!((part.tip(t) - m.tip(s)).norm() < 1e-14);
                assert!((part.axis(t) - m.axis(s)).norm() < 1e-14, "{t}");
            }
        }
    }
}
