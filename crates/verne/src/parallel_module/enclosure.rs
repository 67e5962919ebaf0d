//! Certified enclosures of the platform's pose along a straight move of the sliders,
//! rho(s) = rho_a + s (rho_b - rho_a), as a controller interpolates them: for every s of an
//! interval, the pose that solves constraint equations (3)-(6), IFToMM 2007, continued from a
//! pose near the interval's middle, and its rate d pose / ds.
//!
//! The proof is Krawczyk's (R. Krawczyk, *Computing* 4, 1969; A. Neumaier, *Interval Methods
//! for Systems of Equations*, 1990, ch. 5) with the sliders as an interval parameter: for a box
//! X around the approximate pose x~ and C ~ A(x~)^-1 (A the parallel Jacobian),
//!
//!   K = x~ - C f(x~, rho(S)) + (I - C A(X, rho(S))) (X - x~),
//!
//! and K strictly inside X proves that for every s in S the equations have exactly one solution
//! in X, and that it lies in K: the assembly mode is continuous over S and cannot switch. The
//! rate then follows from A(x, rho) x' = -B(x, rho) rho' (implicit differentiation), enclosed
//! over K by the same preconditioning: with E = I - C A(K) and b = -C B(K) rho', every
//! solution of x' = b + E x' lies in b + E [-R, R] when ||E|| < 1 and R = ||b|| / (1 - ||E||).
//!
//! The unknowns are scaled to one unit: x, y, z in mm and R2 alpha (mm of arc on the platform),
//! so that the norms weigh them alike.

use nalgebra::Matrix4;

use crate::math::interval::{Iv, next_up, point_dot};
use crate::spec::ModuleGeometry;

use super::equations::{ModulePose, Sliders, jacobian_pose, jacobian_sliders};

/// The pose and its rate over an interval of s, certified.
#[derive(Debug, Clone, Copy)]
pub struct SegmentEnclosure {
    /// x, y, z (mm) and alpha (rad) of the platform, for every s of the interval.
    pub pose: [Iv; 4],
    /// d/ds of the same (mm and rad per unit of s).
    pub rate: [Iv; 4],
}

/// Tries the proof with boxes this many times larger than the first guess before giving up.
const INFLATIONS: usize = 3;

/// Radius (mm) added to every side of the box beyond the pose's travel over the interval: it
/// covers the error of the approximate pose (a Newton polish leaves less than 1e-9 mm).
const BOX_SLACK_MM: f64 = 1e-6;

/// The rod vectors of eqs. (3)-(6) over intervals: pose (x, y, z, alpha) and sliders.
fn rod_vectors(g: &ModuleGeometry, x: &[Iv; 4], rho: &[Iv; 3]) -> [[Iv; 3]; 4] {
    let (s, c) = x[3].sin_cos();
    rod_vectors_sc(g, x, rho, s, c)
}

/// [`rod_vectors`] from (sin alpha, cos alpha).
fn rod_vectors_sc(g: &ModuleGeometry, x: &[Iv; 4], rho: &[Iv; 3], s: Iv, c: Iv) -> [[Iv; 3]; 4] {
    let k = Iv::point;
    let (r1, rs1, r2, r4) = (k(g.r_big1), k(g.r_small1), k(g.r_big2), k(g.r4));
    // The joints' sliders plus their zero offsets are the equations' (equations::rod_vectors);
    // a zero offset of 0 leaves the interval as it is.
    let eq = |i: usize| {
        if g.rho_zero[i] == 0.0 {
            rho[i]
        } else {
            rho[i] + k(g.rho_zero[i])
        }
    };
    let (q1, q2, q3) = (eq(0), eq(1), eq(2));
    [
        [x[0] + k(g.dx1), x[1] + r1 * c - rs1, x[2] + r1 * s - q1],
        [x[0] + k(g.dx1), x[1] - r1 * c + rs1, x[2] - r1 * s - q1],
        [x[0] + k(g.dx2), x[1] - r2 * c + r4, x[2] - r2 * s - q2],
        [x[0] + k(g.dx2), x[1] + r2 * c - r4, x[2] + r2 * s - q3],
    ]
}

/// d(rod vector)/d alpha of each rod (the sign pattern of [`rod_vectors`]).
fn rod_vectors_d_alpha(g: &ModuleGeometry, s: Iv, c: Iv) -> [[Iv; 2]; 4] {
    let (r1, r2) = (Iv::point(g.r_big1), Iv::point(g.r_big2));
    [
        [-(r1 * s), r1 * c],
        [r1 * s, -(r1 * c)],
        [r2 * s, -(r2 * c)],
        [-(r2 * s), r2 * c],
    ]
}

fn dot3(a: &[Iv; 3], b: &[Iv; 3]) -> Iv {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The residuals |v|^2 - L^2 of eqs. (3)-(6).
fn residuals(g: &ModuleGeometry, x: &[Iv; 4], rho: &[Iv; 3]) -> [Iv; 4] {
    let v = rod_vectors(g, x, rho);
    let l = [g.l1, g.l1, g.l2, g.l3];
    std::array::from_fn(|i| dot3(&v[i], &v[i]) - Iv::point(l[i] * l[i]))
}

/// The parallel Jacobian A in the scaled unknowns (x, y, z, R2 alpha).
fn jacobian(g: &ModuleGeometry, x: &[Iv; 4], rho: &[Iv; 3], scale: f64) -> [[Iv; 4]; 4] {
    let (s, c) = x[3].sin_cos();
    let v = rod_vectors_sc(g, x, rho, s, c);
    let dv = rod_vectors_d_alpha(g, s, c);
    let two = Iv::point(2.0);
    let inv_scale = Iv::point(1.0 / scale);
    std::array::from_fn(|i| {
        [
            two * v[i][0],
            two * v[i][1],
            two * v[i][2],
            two * (v[i][1] * dv[i][0] + v[i][2] * dv[i][1]) * inv_scale,
        ]
    })
}

/// -B rho': the residuals' rate from the sliders' alone (rods 1 and 2 on slider 1, rod 3 on
/// slider 2, rod 4 on slider 3).
fn slider_rate(g: &ModuleGeometry, x: &[Iv; 4], rho: &[Iv; 3], drho: &Sliders) -> [Iv; 4] {
    let v = rod_vectors(g, x, rho);
    let two = Iv::point(2.0);
    [
        two * v[0][2] * Iv::point(drho.x),
        two * v[1][2] * Iv::point(drho.x),
        two * v[2][2] * Iv::point(drho.y),
        two * v[3][2] * Iv::point(drho.z),
    ]
}

/// Row `i` of C.
fn row(c: &Matrix4<f64>, i: usize) -> [f64; 4] {
    std::array::from_fn(|j| c[(i, j)])
}

/// C times an interval vector.
fn mul_point(c: &Matrix4<f64>, v: &[Iv; 4]) -> [Iv; 4] {
    std::array::from_fn(|i| point_dot(&row(c, i), v))
}

/// C times an interval matrix.
fn mul_point_matrix(c: &Matrix4<f64>, a: &[[Iv; 4]; 4]) -> [[Iv; 4]; 4] {
    std::array::from_fn(|i| {
        let ci = row(c, i);
        std::array::from_fn(|j| point_dot(&ci, &std::array::from_fn(|k| a[k][j])))
    })
}

/// I - M.
fn identity_minus(m: &[[Iv; 4]; 4]) -> [[Iv; 4]; 4] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| Iv::point(if i == j { 1.0 } else { 0.0 }) - m[i][j])
    })
}

/// M times the box [-r, r]: row i is +-(sum of |M_ij| r_j), rounded up.
fn mul_symmetric(m: &[[Iv; 4]; 4], r: &[f64; 4]) -> [Iv; 4] {
    std::array::from_fn(|i| {
        let sum: f64 = (0..4).map(|j| m[i][j].mag() * r[j]).sum();
        let bound = next_up(sum * (1.0 + 8.0 * f64::EPSILON));
        Iv::new(-bound, bound)
    })
}

/// Encloses the platform's pose and its rate for every s of `s` (within [0, 1]) along the slider
/// move from `rho_a` to `rho_b`, continued from `mid`, an approximate pose at the middle of `s`
/// (a Newton polish). `None` when the proof does not go through (a singularity near, or an
/// interval too long): split it, or give up.
pub fn enclose_segment(
    g: &ModuleGeometry,
    rho_a: &Sliders,
    rho_b: &Sliders,
    s: Iv,
    mid: &ModulePose,
) -> Option<SegmentEnclosure> {
    let kr = krawczyk(g, rho_a, rho_b, s, mid)?;
    let rate = rate_over(g, &kr)?;
    Some(SegmentEnclosure {
        pose: kr.unscaled(&kr.k),
        rate: kr.unscaled(&rate),
    })
}

/// [`enclose_segment`], and the pose at the middle of `s` enclosed tightly (the same proof at
/// the point: its E = I - C A over the larger box holds over the smaller one too).
pub fn enclose_segment_and_middle(
    g: &ModuleGeometry,
    rho_a: &Sliders,
    rho_b: &Sliders,
    s: Iv,
    mid: &ModulePose,
) -> Option<(SegmentEnclosure, [Iv; 4])> {
    let kr = krawczyk(g, rho_a, rho_b, s, mid)?;
    let rate = rate_over(g, &kr)?;
    // At s_m: K = x - C f(x, rho(s_m)) + E (X_m - x), X_m a box of radius BOX_SLACK_MM.
    let sm = s.mid();
    let rho_m: [Iv; 3] = std::array::from_fn(|k| Iv::point(rho_a[k] + sm * kr.drho[k]));
    let xm = [mid.p.x, mid.p.y, mid.p.z, mid.alpha * kr.scale];
    let point: [Iv; 4] = std::array::from_fn(|k| Iv::point(xm[k]));
    let f = mul_point(&kr.c, &residuals(g, &kr.unscaled(&point), &rho_m));
    let eo = mul_symmetric(&kr.e, &[BOX_SLACK_MM; 4]);
    let k: [Iv; 4] = std::array::from_fn(|i| point[i] - f[i] + eo[i]);
    let inside = (0..4).all(|i| k[i].lo > xm[i] - BOX_SLACK_MM && k[i].hi < xm[i] + BOX_SLACK_MM);
    inside.then(|| {
        (
            SegmentEnclosure {
                pose: kr.unscaled(&kr.k),
                rate: kr.unscaled(&rate),
            },
            kr.unscaled(&k),
        )
    })
}

/// A Krawczyk proof that went through, and what the rate's enclosure reuses of it.
struct Proof {
    /// The enclosure K (scaled unknowns).
    k: [Iv; 4],
    /// I - C A over the box K lies in (the box holds K, so this holds I - C A(K)).
    e: [[Iv; 4]; 4],
    c: Matrix4<f64>,
    rho: [Iv; 3],
    drho: Sliders,
    scale: f64,
}

impl Proof {
    fn unscaled(&self, x: &[Iv; 4]) -> [Iv; 4] {
        [x[0], x[1], x[2], x[3] * Iv::point(1.0 / self.scale)]
    }
}

/// Krawczyk's test over `s`, with boxes inflated up to [`INFLATIONS`] times.
fn krawczyk(
    g: &ModuleGeometry,
    rho_a: &Sliders,
    rho_b: &Sliders,
    s: Iv,
    mid: &ModulePose,
) -> Option<Proof> {
    let scale = g.r_big2;
    let drho = rho_b - rho_a;
    let rho: [Iv; 3] = std::array::from_fn(|k| Iv::point(rho_a[k]) + s * Iv::point(drho[k]));
    let sm = s.mid();
    let rho_mid = rho_a + drho * sm;
    let c = {
        let mut a = jacobian_pose(g, mid, &rho_mid);
        for i in 0..4 {
            a[(i, 3)] /= scale;
        }
        a.try_inverse()?
    };
    let xm = [mid.p.x, mid.p.y, mid.p.z, mid.alpha * scale];
    let unscaled = |x: &[Iv; 4]| -> [Iv; 4] { [x[0], x[1], x[2], x[3] * Iv::point(1.0 / scale)] };
    let point: [Iv; 4] = std::array::from_fn(|k| Iv::point(xm[k]));
    let half = 0.5 * (s.hi - s.lo);
    // The pose's travel over `s`, from the rate at the middle: the box's first radius.
    // (A guess, not part of the proof: in floating point.)
    let travel: [f64; 4] = if half > 0.0 {
        let b = c * (jacobian_sliders(g, mid, &rho_mid) * drho);
        std::array::from_fn(|k| 1.25 * b[k].abs() * half)
    } else {
        [0.0; 4]
    };
    let f = mul_point(&c, &residuals(g, &unscaled(&point), &rho));
    let mut radius: [f64; 4] = std::array::from_fn(|k| travel[k] + BOX_SLACK_MM);
    for _ in 0..INFLATIONS {
        let bx: [Iv; 4] = std::array::from_fn(|k| Iv::new(xm[k] - radius[k], xm[k] + radius[k]));
        let e = identity_minus(&mul_point_matrix(
            &c,
            &jacobian(g, &unscaled(&bx), &rho, scale),
        ));
        let offset: [f64; 4] = std::array::from_fn(|k| (bx[k] - point[k]).mag());
        let eo = mul_symmetric(&e, &offset);
        let k: [Iv; 4] = std::array::from_fn(|i| point[i] - f[i] + eo[i]);
        let inside = (0..4).all(|i| k[i].lo > bx[i].lo && k[i].hi < bx[i].hi);
        if inside {
            return Some(Proof {
                k,
                e,
                c,
                rho,
                drho,
                scale,
            });
        }
        for (r, ki) in radius.iter_mut().zip(&k) {
            let reach = (ki.lo - ki.mid()).abs().max((ki.hi - ki.mid()).abs());
            *r = (2.0 * *r).max(2.0 * reach);
        }
    }
    None
}

/// The rate d pose/ds over the proof's enclosure K (scaled unknowns): every solution of
/// x' = b + E x' with b = -C B rho' and E = I - C A, both over K (E over K, not over the larger
/// box of the test: the rate's width is E's width times the rate); `None` when ||E|| is not
/// below 1.
fn rate_over(g: &ModuleGeometry, p: &Proof) -> Option<[Iv; 4]> {
    let x = p.unscaled(&p.k);
    let e = identity_minus(&mul_point_matrix(&p.c, &jacobian(g, &x, &p.rho, p.scale)));
    let b = mul_point(&p.c, &slider_rate(g, &x, &p.rho, &p.drho));
    let norm = e
        .iter()
        .map(|row| row.iter().map(|v| v.mag()).sum::<f64>())
        .fold(0.0, f64::max);
    if norm.is_nan() || norm >= 1.0 {
        return None;
    }
    let r = b.iter().map(|v| v.mag()).fold(0.0, f64::max) / (1.0 - norm);
    let er = mul_symmetric(&e, &[next_up(r); 4]);
    Some(std::array::from_fn(|i| b[i] + er[i]))
}

/// The residuals of a point pose and its slider rate, in f64, for the tests.
#[cfg(test)]
fn point_rate(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
    drho: &Sliders,
) -> nalgebra::Vector4<f64> {
    let a = jacobian_pose(g, pose, rho);
    let b = jacobian_sliders(g, pose, rho);
    -(a.try_inverse().expect("regular") * (b * drho))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel_module::equations::{polish_pose, residual_mm};
    use crate::spec::Machine;
    use nalgebra::Vector3;

    /// The working pose at sliders `rho`, from the inverse kinematics of `p`.
    fn working(m: &Machine, p: Vector3<f64>) -> (Sliders, ModulePose) {
        let b = crate::parallel_module::ik::solve(m, &p)
            .iter()
            .find(|b| b.verdict.feasible())
            .copied()
            .expect("a working branch");
        (b.rho, ModulePose { p, alpha: b.alpha })
    }

    /// Along a slider move of the default machine (100 mm of platform travel), the enclosure over
    /// each of 16 sub-intervals holds the pose tracked by Newton at 50 points inside it, and its
    /// rate holds the rate solved from the Jacobians there.
    #[test]
    fn the_enclosure_holds_the_tracked_poses_and_rates() {
        let m = Machine::default_verne();
        let g = &m.module;
        let (ra, pa) = working(&m, Vector3::new(-60.0, 40.0, 1100.0));
        let (rb, _) = working(&m, Vector3::new(30.0, -50.0, 1150.0));
        let drho = rb - ra;
        let pieces = 16;
        let mut pose = pa;
        for piece in 0..pieces {
            let (s0, s1) = (
                piece as f64 / pieces as f64,
                (piece + 1) as f64 / pieces as f64,
            );
            let sm = 0.5 * (s0 + s1);
            let mid = polish_pose(g, pose, &(ra + drho * sm));
            let enc = enclose_segment(g, &ra, &rb, Iv::new(s0, s1), &mid).expect("proved");
            for k in 0..=50 {
                let s = s0 + (s1 - s0) * k as f64 / 50.0;
                let rho = ra + drho * s;
                pose = polish_pose(g, pose, &rho);
                assert!(residual_mm(g, &pose, &rho) < 1e-9);
                let x = [pose.p.x, pose.p.y, pose.p.z, pose.alpha];
                let r = point_rate(g, &pose, &rho, &drho);
                for i in 0..4 {
                    assert!(
                        enc.pose[i].lo <= x[i] && x[i] <= enc.pose[i].hi,
                        "pose {i} at s = {s}: {} outside {:?}",
                        x[i],
                        enc.pose[i]
                    );
                    assert!(
                        enc.rate[i].lo <= r[i] && r[i] <= enc.rate[i].hi,
                        "rate {i} at s = {s}: {} outside {:?}",
                        r[i],
                        enc.rate[i]
                    );
                }
            }
            // Tight: the box is of the order of the travel over the piece.
            let travel = (enc.pose[0].hi - enc.pose[0].lo).max(enc.pose[2].hi - enc.pose[2].lo);
            assert!(travel < 50.0, "{travel}");
        }
    }

    /// Sound, whatever the starting pose: started from each assembly mode of the middle
    /// sliders, or from a pose 5 or 50 mm off the working one, an enclosure that is proved holds
    /// the mode it continues at the middle, and no other mode.
    #[test]
    fn a_proved_enclosure_holds_its_own_mode_only() {
        let m = Machine::default_verne();
        let g = &m.module;
        let (ra, pa) = working(&m, Vector3::new(-60.0, 40.0, 1100.0));
        let (rb, _) = working(&m, Vector3::new(-50.0, 30.0, 1105.0));
        let rho_mid = ra + (rb - ra) * 0.5;
        let working_mid = polish_pose(g, pa, &rho_mid);
        let modes: Vec<ModulePose> = crate::parallel_module::fk::solve(&m, &rho_mid)
            .iter()
            .map(|md| md.pose)
            .collect();
        assert!(modes.len() >= 2, "{} modes", modes.len());
        let holds = |e: &SegmentEnclosure, p: &ModulePose| {
            let x = [p.p.x, p.p.y, p.p.z, p.alpha];
            (0..4).all(|i| e.pose[i].lo <= x[i] && x[i] <= e.pose[i].hi)
        };
        let mut starts = modes.clone();
        for off in [5.0, 50.0] {
            starts.push(ModulePose {
                p: working_mid.p + Vector3::new(off, -off, off),
                alpha: working_mid.alpha,
            });
        }
        let mut proved = 0;
        for start in &starts {
            let Some(e) = enclose_segment(g, &ra, &rb, Iv::new(0.0, 1.0), start) else {
                continue;
            };
            proved += 1;
            let inside: Vec<&ModulePose> = modes.iter().filter(|md| holds(&e, md)).collect();
            assert_eq!(
                inside.len(),
                1,
                "from {start:?}: {} modes inside",
                inside.len()
            );
        }
        assert!(proved >= 2, "{proved} proved");
    }
}
