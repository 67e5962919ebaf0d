//! Where the platform can be at all with every slider within its stroke: a box from the
//! constraint equations (3)-(6), IFToMM 2007. The machine's inverse kinematics checks a tool
//! pose against it before forming its theta1 equation: a pose whose platform points (a circle
//! in theta1) all lie outside it, by more than rounding, has no branch with its sliders in their
//! strokes however far it is, and is answered "no branch", proved, instead of solving an
//! equation whose coefficients have lost every digit to the pose's size. (The module's inverse
//! kinematics needs no such test: its cubic (9) stays exact at any size, and it lists every real
//! branch, strokes or not.)
//!
//! Each rod vector of eqs. (3)-(6) has length L and components (xp + D - d, yp +- R cos(alpha)
//! -+ r, zp +- R sin(alpha) - rho), so with |cos|, |sin| <= 1 and rho in [rho_min, rho_max]:
//!
//! - |xp + D1 - d1| <= L1, |xp + D2 - d2| <= L2 and L3;
//! - yp within r1 +- (R1 + L1) and -r1 +- (R1 + L1) (the two rods of leg I), -r4 +- (R2 + L2)
//!   (leg II), r4 +- (R2 + L3) (leg III);
//! - zp within [rho_min - R - L, rho_max + R + L] for each leg.

use nalgebra::Vector3;

use crate::spec::Machine;
use crate::tolerance::{LIMIT_SLACK, REACH_MARGIN_MM, REACH_MARGIN_REL};

/// The box that holds every platform point P whose sliders are all within their strokes
/// (with the limits' slack), for any rod tilt and any alpha (mm, base frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReachBox {
    pub min: Vector3<f64>,
    pub max: Vector3<f64>,
}

impl ReachBox {
    /// The box of the machine's module and strokes (module documentation).
    pub fn of(m: &Machine) -> ReachBox {
        let g = &m.module;
        let lim = &m.limits;
        let (r1, r2) = (g.r_big1.abs(), g.r_big2.abs());
        let legs = [(g.dx1, g.l1, r1), (g.dx2, g.l2, r2), (g.dx2, g.l3, r2)];
        let mut min = Vector3::repeat(f64::NEG_INFINITY);
        let mut max = Vector3::repeat(f64::INFINITY);
        let mut within = |d: usize, centre: f64, half: f64| {
            min[d] = min[d].max(centre - half);
            max[d] = max[d].min(centre + half);
        };
        for (leg, &(dx, l, r)) in legs.iter().enumerate() {
            within(0, -dx, l.abs());
            // The equations' strokes: the joints' moved by the sliders' zero offsets.
            let (lo, hi) = (
                lim.rho_min[leg] + g.rho_zero[leg] - LIMIT_SLACK,
                lim.rho_max[leg] + g.rho_zero[leg] + LIMIT_SLACK,
            );
            within(2, 0.5 * (lo + hi), 0.5 * (hi - lo) + r + l.abs());
        }
        within(1, g.r_small1, r1 + g.l1.abs());
        within(1, -g.r_small1, r1 + g.l1.abs());
        within(1, -g.r4, r2 + g.l2.abs());
        within(1, g.r4, r2 + g.l3.abs());
        ReachBox { min, max }
    }

    /// The largest magnitude of the box's bounds (mm), the scale of their rounding.
    fn scale(&self) -> f64 {
        self.min.amax().max(self.max.amax())
    }

    /// How far outside the box a point must be to be proved beyond reach (mm), for points of
    /// magnitude up to `size` (mm).
    fn margin(&self, size: f64) -> f64 {
        REACH_MARGIN_MM + REACH_MARGIN_REL * (self.scale() + size)
    }

    /// P lies outside the box by more than rounding: no branch of P has every slider within its
    /// stroke. False for a point that is not finite (the solvers refuse it themselves).
    pub fn beyond(&self, p: &Vector3<f64>) -> bool {
        let tol = self.margin(p.amax());
        (0..3).any(|d| p[d] < self.min[d] - tol || p[d] > self.max[d] + tol)
    }

    /// Every point (x, d_a + rot(theta) (wy, wz)) of the circle of the platform points of a tool
    /// pose ([`crate::machine`]: P(theta1) = (w_x, c w_y - s w_z, d_a + s w_y + c w_z)) lies
    /// outside the box by more than rounding: the pose has no branch with every slider within
    /// its stroke, whatever theta1.
    pub fn circle_beyond(&self, x: f64, d_a: f64, wy: f64, wz: f64) -> bool {
        let radius = wy.hypot(wz);
        let tol = self.margin(x.abs().max(radius).max(d_a.abs()));
        if x < self.min.x - tol || x > self.max.x + tol {
            return true;
        }
        // The circle of centre (0, d_a) in the (y, z) plane meets the rectangle iff its radius
        // is between the nearest and the farthest distance from the centre to the rectangle.
        let (y0, y1) = (self.min.y, self.max.y);
        let (z0, z1) = (self.min.z - d_a, self.max.z - d_a);
        let near_y = if y0 > 0.0 {
            y0
        } else if y1 < 0.0 {
            -y1
        } else {
            0.0
        };
        let near_z = if z0 > 0.0 {
            z0
        } else if z1 < 0.0 {
            -z1
        } else {
            0.0
        };
        let nearest = near_y.hypot(near_z);
        let farthest = y0.abs().max(y1.abs()).hypot(z0.abs().max(z1.abs()));
        radius < nearest - tol || radius > farthest + tol
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::{machine_fk, tilt_frame_platform};
    use crate::parallel_module::equations::Sliders;
    use crate::parallel_module::fk;
    use crate::selftest::hard_sets::random_geometries;

    /// The default machine and four random valid geometries.
    fn machines() -> Vec<Machine> {
        let mut out = vec![Machine::default_verne()];
        out.extend(random_geometries(4, 23));
        out
    }

    /// Sliders drawn within the strokes, one in eight at a stroke's end.
    fn sliders_within(m: &Machine, unit: &mut impl FnMut() -> f64) -> Sliders {
        Sliders::from_fn(|i, _| {
            let (lo, hi) = (m.limits.rho_min[i], m.limits.rho_max[i]);
            match (unit() * 8.0) as u32 {
                0 => lo,
                1 => hi,
                _ => lo + unit() * (hi - lo),
            }
        })
    }

    /// No assembly mode of sliders within their strokes is beyond reach: every mode of the
    /// forward kinematics (all of them, any configuration, rods crossing or not) lies in the
    /// box, and the circle of every tool pose of the machine's forward kinematics (theta1,
    /// theta2 and the tool length anywhere) is not beyond it.
    #[test]
    fn no_pose_of_sliders_within_their_strokes_is_beyond_reach() {
        let mut unit = crate::math::test_rng::lcg(0x4eac_4b0c);
        let mut modes = 0;
        for m in machines() {
            let b = ReachBox::of(&m);
            for _ in 0..3_000 {
                let rho = sliders_within(&m, &mut unit);
                for md in fk::solve(&m, &rho).iter() {
                    assert!(
                        !b.beyond(&md.pose.p),
                        "{}: {rho:?} reaches {:?}",
                        m.name,
                        md.pose
                    );
                    modes += 1;
                }
                let (theta1, theta2) = ((unit() - 0.5) * 6.5, (unit() - 0.5) * 6.5);
                let delta = unit() * 300.0;
                for md in machine_fk(&m, &rho, theta1, theta2, delta).iter() {
                    let w = tilt_frame_platform(&m.table, &md.tool, delta);
                    assert!(
                        !b.circle_beyond(w.x, m.table.d_a, w.y, w.z),
                        "{}: {rho:?}, theta1 {theta1}: tool pose {:?}",
                        m.name,
                        md.tool
                    );
                }
            }
        }
        assert!(modes > 10_000, "{modes}");
    }

    /// The box's faces are where the rods reach: on the default machine, a point just inside
    /// each face (by 1e-3 mm) is not beyond reach and a point just outside it (by 1e-3 mm) is;
    /// the circle test agrees with the circle sampled at 100,000 angles (0.2 mm apart at most):
    /// a circle beyond the box has no sample in it, and one that is not has a sample within
    /// 1 mm of it.
    #[test]
    fn the_faces_and_the_circle_test() {
        let m = Machine::default_verne();
        let b = ReachBox::of(&m);
        let centre = 0.5 * (b.min + b.max);
        for d in 0..3 {
            for (face, out) in [(b.min[d], -1.0), (b.max[d], 1.0)] {
                let mut p = centre;
                p[d] = face - out * 1e-3;
                assert!(!b.beyond(&p), "{p:?}");
                p[d] = face + out * 1e-3;
                assert!(b.beyond(&p), "{p:?}");
            }
        }
        let widened = ReachBox {
            min: b.min - Vector3::repeat(1.0),
            max: b.max + Vector3::repeat(1.0),
        };
        let mut unit = crate::math::test_rng::lcg(0xc12c_1e55);
        let mut both = [0; 2];
        for _ in 0..300 {
            let x = centre.x + (unit() - 0.5) * 1.5 * (b.max.x - b.min.x);
            let (wy, wz) = ((unit() - 0.5) * 5000.0, (unit() - 0.5) * 5000.0);
            let samples = (0..100_000).map(|i| {
                let (s, c) = (std::f64::consts::TAU * f64::from(i) / 1e5).sin_cos();
                Vector3::new(x, c * wy - s * wz, m.table.d_a + s * wy + c * wz)
            });
            let beyond = b.circle_beyond(x, m.table.d_a, wy, wz);
            if beyond {
                assert!(
                    samples.clone().all(|p| b.beyond(&p)),
                    "x {x}, w ({wy}, {wz}): beyond, but a sample is inside"
                );
            } else {
                assert!(
                    samples.clone().any(|p| !widened.beyond(&p)),
                    "x {x}, w ({wy}, {wz}): not beyond, but no sample within 1 mm"
                );
            }
            both[usize::from(beyond)] += 1;
        }
        assert!(both[0] > 30 && both[1] > 30, "{both:?}");
    }
}
