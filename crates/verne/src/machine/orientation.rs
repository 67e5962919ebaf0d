//! Tool orientation in the workpiece (tilting-table) frame R_t: the angles (phi1, phi2) of
//! AIM 2007 eq. (8), the CAM tool-axis vector (i, j, k), and the map between them.
//!
//! Convention (derived from eq. (8), see docs/conventions-machine.md): the tool axis is the unit
//! vector from the tool tip U towards the spindle (the platform point P), in R_t, whose z_t axis
//! is the table normal pointing away from the table top (towards the spindle). From
//! tT_pl = trans(X, Y, Z) rot(z, phi2) rot(x, pi + phi1) trans(z, -Delta), P = U + Delta a with
//!
//!   a = rot(z, phi2) rot(x, pi + phi1) (0, 0, -1) = (sin phi1 sin phi2, -sin phi1 cos phi2, cos phi1).
//!
//! So phi1 is the tilt of the tool from the table normal and phi2 the azimuth of the tilt plane:
//! phi1 > 0, phi2 = 0 leans the tool towards -y_t. The pairs (phi1, phi2) and (-phi1, phi2 + pi)
//! give the same axis. On the table normal (phi1 = 0) phi2 is undetermined: the rotary
//! singularity.

use nalgebra::Vector3;
use std::f64::consts::PI;
use std::fmt;

use crate::parallel_module::ik::wrap_angle;

/// Half-angle (rad) of the cone around the table normal (and its opposite) inside which phi2 is
/// treated as undetermined. 1e-6 rad is the resolution of a tool axis printed with six decimals
/// (the usual CL precision), so a smaller tilt is not distinguishable from zero in the input;
/// and keeping the previous theta2 there changes the achieved axis by at most this angle, which
/// moves the spindle end of a 500 mm tool by 0.5 um, below the machine's resolution. Outside
/// the cone, double rounding of (i, j) perturbs phi2 by at most ~1e-16 / 1e-6 = 1e-10 rad.
pub const ROTARY_SINGULAR_CONE_RAD: f64 = 1e-6;

/// A tool-axis vector whose length differs from 1 by at most this (dimensionless) is normalised;
/// a larger difference is an error. CL files print axes with 4 to 7 decimals, which leaves the
/// length off by at most ~2e-4.
pub const AXIS_NORM_TOL: f64 = 1e-3;

/// Tool orientation angles (rad) of AIM 2007 eq. (8), relative to the workpiece frame R_t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolAngles {
    /// Tilt of the tool from the table normal.
    pub phi1: f64,
    /// Azimuth of the tilt plane about the table normal.
    pub phi2: f64,
}

/// A tool orientation as given by the user.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolOrientation {
    /// The angles themselves: used as given (one solution, theta2 = -phi2).
    Angles(ToolAngles),
    /// A CAM tool-axis vector (i, j, k) in R_t, tip towards spindle; normalised if nearly unit.
    Axis(Vector3<f64>),
}

/// Why a tool-axis vector was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisError {
    /// A component is NaN or infinite.
    NotFinite,
    /// The vector is (0, 0, 0).
    Zero,
    /// The length is off 1 by more than [`AXIS_NORM_TOL`].
    NotUnit {
        /// The vector's length.
        norm: f64,
    },
}

impl fmt::Display for AxisError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AxisError::NotFinite => f.write_str("tool axis (i,j,k) has a non-finite component"),
            AxisError::Zero => f.write_str("tool axis (i,j,k) is the zero vector"),
            AxisError::NotUnit { norm } => write!(
                f,
                "tool axis (i,j,k) has length {norm}, expected 1 within {AXIS_NORM_TOL}"
            ),
        }
    }
}

impl std::error::Error for AxisError {}

/// The (phi1, phi2) solutions of one tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AxisAngles {
    /// Two solutions: orientation 1 = (phi1, phi2) with phi1 in (0, pi), and orientation 2 =
    /// (-phi1, phi2 + pi); both phi2 in (-pi, pi].
    Regular([ToolAngles; 2]),
    /// The axis is within [`ROTARY_SINGULAR_CONE_RAD`] of the table normal (`phi1_abs` = 0) or
    /// of its opposite (`phi1_abs` = pi): phi2 is undetermined. Pick phi2 (the previous row's
    /// -theta2) and get phi1 from [`phi1_at`].
    NearRotary {
        /// |phi1| of the axis: its angle from the table normal (rad).
        phi1_abs: f64,
    },
}

/// The tool axis (unit, tip towards spindle, in R_t) for angles (phi1, phi2): eq. (8).
pub fn tool_axis(phi1: f64, phi2: f64) -> Vector3<f64> {
    let (s1, c1) = phi1.sin_cos();
    let (s2, c2) = phi2.sin_cos();
    Vector3::new(s1 * s2, -s1 * c2, c1)
}

/// Checks and normalises a tool-axis vector.
pub fn unit_axis(axis: &Vector3<f64>) -> Result<Vector3<f64>, AxisError> {
    if !axis.iter().all(|v| v.is_finite()) {
        return Err(AxisError::NotFinite);
    }
    let norm = axis.norm();
    if norm == 0.0 {
        return Err(AxisError::Zero);
    }
    if (norm - 1.0).abs() > AXIS_NORM_TOL {
        return Err(AxisError::NotUnit { norm });
    }
    Ok(axis / norm)
}

/// Every (phi1, phi2) giving the tool axis, or the rotary singularity. The vector is checked and
/// normalised by [`unit_axis`].
pub fn axis_angles(axis: &Vector3<f64>) -> Result<AxisAngles, AxisError> {
    let a = unit_axis(axis)?;
    let r = a.x.hypot(a.y);
    // atan2 keeps full accuracy near both poles, unlike acos(k).
    let phi1 = r.atan2(a.z);
    if phi1 < ROTARY_SINGULAR_CONE_RAD || PI - phi1 < ROTARY_SINGULAR_CONE_RAD {
        return Ok(AxisAngles::NearRotary { phi1_abs: phi1 });
    }
    // (i, j) = sin(phi1) (sin phi2, -cos phi2).
    let phi2 = a.x.atan2(-a.y);
    Ok(AxisAngles::Regular([
        ToolAngles { phi1, phi2 },
        ToolAngles {
            phi1: -phi1,
            phi2: wrap_angle(phi2 + PI),
        },
    ]))
}

/// The tool angles at the two ends of a move as a controller whose world axes are the tool
/// angles moves them (LinuxCNC with `vernekins`: A = phi1, C = phi2, each interpolated
/// linearly): the angles the path states at both ends when it states them (a program's words,
/// a CSV's phi1,phi2), used as stated; otherwise, of the two solutions of each axis, the pair
/// with the smaller table move |d phi1| + |d phi2| (phi2 the shorter way round), so that a tilt
/// that changes sign passes through the table normal; an end on the table normal takes the other
/// end's phi2. The axis along the move is then [`tool_axis`] of the interpolated angles.
pub fn move_angles(
    a: &Vector3<f64>,
    a_stated: Option<(f64, f64)>,
    b: &Vector3<f64>,
    b_stated: Option<(f64, f64)>,
) -> [(f64, f64); 2] {
    if let (Some(sa), Some(sb)) = (a_stated, b_stated) {
        return [sa, sb];
    }
    // Orientation solution 1 of each end; None for phi2 on the table normal.
    let angles = |v: &Vector3<f64>| match axis_angles(v) {
        Ok(AxisAngles::Regular([s, _])) => (s.phi1, Some(s.phi2)),
        Ok(AxisAngles::NearRotary { phi1_abs }) => (phi1_abs, None),
        Err(_) => (0.0, None),
    };
    let ((p1a, p2a), (p1b, p2b)) = (angles(a), angles(b));
    let p2a = p2a.or(p2b).unwrap_or(0.0);
    let p2b = p2b.unwrap_or(p2a);
    let both = |p1: f64, p2: f64| [(p1, p2), (-p1, wrap_angle(p2 + PI))];
    let mut best: Option<(f64, [(f64, f64); 2])> = None;
    for ea in both(p1a, p2a) {
        for eb in both(p1b, p2b) {
            let d2 = wrap_angle(eb.1 - ea.1);
            let cost = (eb.0 - ea.0).abs() + d2.abs();
            if best.is_none_or(|(c, _)| cost < c - 1e-12) {
                best = Some((cost, [ea, (eb.0, ea.1 + d2)]));
            }
        }
    }
    best.expect("four candidates").1
}

/// The phi1 whose axis, at the given phi2, is nearest the (unit) axis `a`: the signed tilt in the
/// plane of azimuth phi2. Exact when phi2 is one of the axis's own solutions; used inside the
/// rotary-singularity cone, where the achieved axis then differs from `a` by at most the cone.
pub fn phi1_at(a: &Vector3<f64>, phi2: f64) -> f64 {
    let (s2, c2) = phi2.sin_cos();
    (a.x * s2 - a.y * c2).atan2(a.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_solutions_give_the_axis() {
        for &(p1, p2) in &[(0.3, 0.0), (-0.7, 2.0), (1.2, -3.0), (3.0, 1.0)] {
            let a = tool_axis(p1, p2);
            let AxisAngles::Regular(sols) = axis_angles(&a).unwrap() else {
                panic!("regular expected")
            };
            for s in sols {
                assert!((tool_axis(s.phi1, s.phi2) - a).amax() < 1e-15);
            }
            assert!(sols[0].phi1 > 0.0 && sols[1].phi1 < 0.0);
        }
    }

    #[test]
    fn bad_vectors_are_rejected_and_near_unit_normalised() {
        assert_eq!(axis_angles(&Vector3::zeros()), Err(AxisError::Zero));
        assert!(matches!(
            axis_angles(&Vector3::new(0.0, 0.0, 2.0)),
            Err(AxisError::NotUnit { .. })
        ));
        assert!(matches!(
            axis_angles(&Vector3::new(f64::NAN, 0.0, 1.0)),
            Err(AxisError::NotFinite)
        ));
        assert!(matches!(
            axis_angles(&Vector3::new(0.0, 0.0, 1.0002)),
            Ok(AxisAngles::NearRotary { .. })
        ));
        assert!(matches!(
            axis_angles(&Vector3::new(0.0, 0.0, -1.0)),
            Ok(AxisAngles::NearRotary { .. })
        ));
    }

    #[test]
    fn a_near_unit_axis_is_normalised() {
        for v in [
            Vector3::new(0.0, 0.6, 0.8) * 1.0009,
            Vector3::new(0.3, -0.4, 0.5).normalize() * 0.9991,
        ] {
            let u = unit_axis(&v).unwrap();
            assert!((u.norm() - 1.0).abs() < 1e-15, "{u:?}");
            assert!((u - v.normalize()).amax() < 1e-15);
        }
    }

    #[test]
    fn the_cone_is_open() {
        // An axis exactly at ROTARY_SINGULAR_CONE_RAD from the pole is outside the cone: searched
        // ulp by ulp in x for (x, 0, 1), whose tilt is computed as axis_angles does. (At the
        // other pole PI - phi1 is a multiple of ulp(PI), which the cone is not: no axis lies
        // exactly on that edge.)
        let tilt = |v: &Vector3<f64>| {
            let a = unit_axis(v).unwrap();
            a.x.hypot(a.y).atan2(a.z)
        };
        let mut found = 0;
        let mut x = ROTARY_SINGULAR_CONE_RAD.tan();
        for _ in 0..64 {
            x = x.next_down();
        }
        for _ in 0..128 {
            let v = Vector3::new(x, 0.0, 1.0);
            let phi1 = tilt(&v);
            if phi1 == ROTARY_SINGULAR_CONE_RAD {
                found += 1;
                assert!(
                    matches!(axis_angles(&v), Ok(AxisAngles::Regular(_))),
                    "phi1 {phi1} on the cone's edge"
                );
            }
            x = x.next_up();
        }
        assert!(found >= 1, "no axis on the cone's edge found");
    }

    #[test]
    fn phi1_at_an_axis_own_azimuth_is_its_tilt() {
        for &(p1, p2) in &[(0.3, 0.0), (-0.7, 2.0), (1.2, -3.0), (2.5, 1.0)] {
            let a = tool_axis(p1, p2);
            assert!((phi1_at(&a, p2) - p1).abs() < 1e-14);
            // The other azimuth of the same plane: the opposite tilt.
            assert!((phi1_at(&a, p2 + PI) + p1).abs() < 1e-14);
        }
    }

    /// |d phi1| + |d phi2| of a move, phi2 the shorter way round.
    fn table_move(a: (f64, f64), b: (f64, f64)) -> f64 {
        (b.0 - a.0).abs() + wrap_angle(b.1 - a.1).abs()
    }

    #[test]
    fn a_move_takes_the_smallest_table_move() {
        // Every pair of orientation solutions, brute force, against move_angles' choice.
        let mut r = crate::math::test_rng::lcg(11);
        let mut axis = || tool_axis(0.01 + 1.49 * r(), PI * (2.0 * r() - 1.0));
        for _ in 0..2000 {
            let (a, b) = (axis(), axis());
            let [ea, eb] = move_angles(&a, None, &b, None);
            assert!((tool_axis(ea.0, ea.1) - a).amax() < 1e-14);
            assert!((tool_axis(eb.0, eb.1) - b).amax() < 1e-14);
            let sols = |v: &Vector3<f64>| match axis_angles(v).unwrap() {
                AxisAngles::Regular(s) => s.map(|s| (s.phi1, s.phi2)),
                AxisAngles::NearRotary { .. } => unreachable!("tilted axes"),
            };
            let best = sols(&a)
                .iter()
                .flat_map(|x| sols(&b).map(|y| table_move(*x, y)))
                .fold(f64::INFINITY, f64::min);
            assert!(
                (table_move(ea, eb) - best).abs() < 1e-12,
                "{ea:?} {eb:?} vs {best}"
            );
            // phi2 is carried the shorter way round, unwrapped from the start.
            assert!((eb.1 - ea.1).abs() <= PI + 1e-12);
        }
    }

    #[test]
    fn a_tie_keeps_the_first_solution_at_the_start() {
        // A tilt that changes sign in one plane: through the normal from solution 1 (phi1 > 0)
        // or from solution 2, the same table move; the first is kept.
        let (a, b) = (tool_axis(0.2, 0.0), tool_axis(-0.2, 0.0));
        let [ea, eb] = move_angles(&a, None, &b, None);
        assert!((ea.0 - 0.2).abs() < 1e-15 && ea.1.abs() < 1e-15, "{ea:?}");
        assert!((eb.0 + 0.2).abs() < 1e-15 && eb.1.abs() < 1e-15, "{eb:?}");
        // Stated angles are used as stated.
        let stated = [(0.1, 3.0), (-0.1, -3.0)];
        assert_eq!(
            move_angles(&a, Some(stated[0]), &b, Some(stated[1])),
            stated
        );
    }
}
