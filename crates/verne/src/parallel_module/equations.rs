//! The parallel module's constraint equations (3)-(6) of IFToMM 2007 (= AIM 2007 (3)-(6)):
//! rod vectors, residuals and their derivatives, shared by every solver and check.

use nalgebra::{Matrix4, Matrix4x3, Vector3, Vector4};

use crate::math::trig::sin_cos_after_step;
use crate::spec::ModuleGeometry;

/// Pose of the platform: point P (mm, base frame, z down) and its rotation alpha about x (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModulePose {
    pub p: Vector3<f64>,
    pub alpha: f64,
}

/// Slider positions rho1, rho2, rho3 (mm).
pub type Sliders = Vector3<f64>;

/// The four rod vectors B_ij - A_ij of eqs. (3), (4), (5), (6), in that order. Leg I has two
/// rods (3)-(4); legs II and III are parallelograms, one vector each. `rho` are the joints'
/// sliders: the geometry's zero offsets ([`ModuleGeometry::rho_zero`]) are added here, the one
/// place the sliders enter the equations.
#[inline]
pub fn rod_vectors(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> [Vector3<f64>; 4] {
    let (s, c) = pose.alpha.sin_cos();
    rod_vectors_sc(g, pose, rho, s, c)
}

/// [`rod_vectors`] with (sin alpha, cos alpha) given.
#[inline]
fn rod_vectors_sc(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
    s: f64,
    c: f64,
) -> [Vector3<f64>; 4] {
    let (x, y, z) = (pose.p.x, pose.p.y, pose.p.z);
    // The joints' sliders plus their zero offsets are the equations' rho (0 on Machine::model).
    let [z1, z2, z3] = g.rho_zero;
    let (r1, r2, r3) = (rho.x + z1, rho.y + z2, rho.z + z3);
    [
        Vector3::new(
            x + g.dx1,
            y + g.r_big1 * c - g.r_small1,
            z + g.r_big1 * s - r1,
        ),
        Vector3::new(
            x + g.dx1,
            y - g.r_big1 * c + g.r_small1,
            z - g.r_big1 * s - r1,
        ),
        Vector3::new(x + g.dx2, y - g.r_big2 * c + g.r4, z - g.r_big2 * s - r2),
        Vector3::new(x + g.dx2, y + g.r_big2 * c - g.r4, z + g.r_big2 * s - r3),
    ]
}

/// Rod lengths in the order of [`rod_vectors`].
#[inline]
pub fn rod_lengths(g: &ModuleGeometry) -> [f64; 4] {
    [g.l1, g.l1, g.l2, g.l3]
}

/// Residuals |B - A|^2 - L^2 of eqs. (3)-(6) (mm^2).
#[inline]
pub fn residuals(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> Vector4<f64> {
    let v = rod_vectors(g, pose, rho);
    let l = rod_lengths(g);
    Vector4::from_fn(|i, _| v[i].norm_squared() - l[i] * l[i])
}

/// The largest residual expressed as a length error along its rod, |f| / (2 L) (mm); infinite
/// when a pose or sliders that are not finite make one NaN, so that no such pose passes a
/// residual test.
pub fn residual_mm(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> f64 {
    let (s, c) = pose.alpha.sin_cos();
    residual_mm_sc(g, pose, rho, s, c)
}

/// [`residual_mm`] with (sin alpha, cos alpha) given.
#[inline]
pub fn residual_mm_sc(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders, s: f64, c: f64) -> f64 {
    let v = rod_vectors_sc(g, pose, rho, s, c);
    let l = rod_lengths(g);
    (0..4).fold(0.0f64, |m, i| {
        worse(
            m,
            ((v[i].norm_squared() - l[i] * l[i]) / (2.0 * l[i])).abs(),
        )
    })
}

/// The larger of two residuals, a NaN counting as infinite: `f64::max` passes over a NaN, and
/// a pose or sliders that are not finite would then pass as a solution with residual 0.
#[inline(always)]
fn worse(m: f64, e: f64) -> f64 {
    m.max(if e.is_nan() { f64::INFINITY } else { e })
}

/// Derivatives of each rod vector with respect to alpha.
#[inline]
fn rod_vectors_d_alpha(g: &ModuleGeometry, s: f64, c: f64) -> [Vector3<f64>; 4] {
    [
        Vector3::new(0.0, -g.r_big1 * s, g.r_big1 * c),
        Vector3::new(0.0, g.r_big1 * s, -g.r_big1 * c),
        Vector3::new(0.0, g.r_big2 * s, -g.r_big2 * c),
        Vector3::new(0.0, -g.r_big2 * s, g.r_big2 * c),
    ]
}

/// A = d(residuals)/d(xp, yp, zp, alpha): the parallel Jacobian (4x4). det A = 0 is a parallel
/// singularity (two assembly modes meet).
pub fn jacobian_pose(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> Matrix4<f64> {
    let (s, c) = pose.alpha.sin_cos();
    jacobian_at(&rod_vectors_sc(g, pose, rho, s, c), g, s, c)
}

/// [`jacobian_pose`] from the rod vectors and (sin alpha, cos alpha).
#[inline]
fn jacobian_at(v: &[Vector3<f64>; 4], g: &ModuleGeometry, s: f64, c: f64) -> Matrix4<f64> {
    let dv = rod_vectors_d_alpha(g, s, c);
    let mut a = Matrix4::zeros();
    for i in 0..4 {
        a[(i, 0)] = 2.0 * v[i].x;
        a[(i, 1)] = 2.0 * v[i].y;
        a[(i, 2)] = 2.0 * v[i].z;
        a[(i, 3)] = 2.0 * v[i].dot(&dv[i]);
    }
    a
}

/// d(residuals)/d(rho1, rho2, rho3) (4x3). The serial Jacobian of the comparative study is its
/// negative; a zero entry in a rod's row is a serial singularity (rod perpendicular to its slider).
pub fn jacobian_sliders(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> Matrix4x3<f64> {
    sliders_at(&rod_vectors(g, pose, rho))
}

/// [`jacobian_pose`] and [`jacobian_sliders`] from one evaluation of the rod vectors: the same
/// matrices, bit for bit.
pub fn jacobians(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
) -> (Matrix4<f64>, Matrix4x3<f64>) {
    let (s, c) = pose.alpha.sin_cos();
    let v = rod_vectors_sc(g, pose, rho, s, c);
    (jacobian_at(&v, g, s, c), sliders_at(&v))
}

/// [`jacobian_sliders`] from the rod vectors.
#[inline]
fn sliders_at(v: &[Vector3<f64>; 4]) -> Matrix4x3<f64> {
    let mut b = Matrix4x3::zeros();
    b[(0, 0)] = -2.0 * v[0].z;
    b[(1, 0)] = -2.0 * v[1].z;
    b[(2, 1)] = -2.0 * v[2].z;
    b[(3, 2)] = -2.0 * v[3].z;
    b
}

/// Angle (rad) between each rod and the downward slider axis +z: 0 for a rod hanging straight
/// down from its slider, above 90 degrees for a rod rising from its slider.
pub fn rod_tilts(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> [f64; 4] {
    let v = rod_vectors(g, pose, rho);
    let l = rod_lengths(g);
    std::array::from_fn(|i| {
        (v[i].z / v[i].norm().max(l[i] * 1e-300))
            .clamp(-1.0, 1.0)
            .acos()
    })
}

/// Newton polish on eqs. (3)-(6) for the pose, sliders fixed (forward kinematics). Returns the
/// polished pose when it did not make the residual worse.
pub fn polish_pose(g: &ModuleGeometry, start: ModulePose, rho: &Sliders) -> ModulePose {
    polish_pose_with_residual(g, start, rho).0
}

/// [`polish_pose`], with the returned pose's [`residual_mm`]. One evaluation of the rod vectors
/// per Newton step gives the residuals and the Jacobian A, from one sin_cos. A step below
/// [`FINAL_STEP_MM`] ends it without a further evaluation; the residual returned is then the
/// one before that step (an upper bound in Newton's quadratic regime).
pub fn polish_pose_with_residual(
    g: &ModuleGeometry,
    start: ModulePose,
    rho: &Sliders,
) -> (ModulePose, f64) {
    let (pose, residual, _) = polish_pose_from(g, start, start.alpha.sin_cos(), rho);
    (pose, residual)
}

/// [`polish_pose_with_residual`] from a start whose (sin alpha, cos alpha) are known; also
/// returns those of the result.
#[inline(always)]
pub fn polish_pose_from(
    g: &ModuleGeometry,
    start: ModulePose,
    (s, c): (f64, f64),
    rho: &Sliders,
) -> (ModulePose, f64, (f64, f64)) {
    use crate::tolerance::{NEWTON_MAX_ITER, NEWTON_STEP_STOP};
    let l = rod_lengths(g);
    let as_mm =
        |f: &Vector4<f64>| (0..4).fold(0.0f64, |m, i| worse(m, (f[i] / (2.0 * l[i])).abs()));
    let mut cur = start;
    let mut sc = (s, c);
    let (mut f, mut a) = residuals_jacobian_at(g, &cur, rho, s, c);
    let mut res = as_mm(&f);
    let mut best = (cur, res, sc);
    for _ in 0..NEWTON_MAX_ITER {
        if res == 0.0 {
            break;
        }
        let Some(step) = solve4(a, f) else { break };
        if !step.iter().all(|v| v.is_finite()) {
            break;
        }
        cur = ModulePose {
            p: cur.p - Vector3::new(step[0], step[1], step[2]),
            alpha: cur.alpha - step[3],
        };
        let size = step
            .xyz()
            .amax()
            .max((step[3] * g.r_big1.max(g.r_big2)).abs());
        if size < FINAL_STEP_MM {
            // What such a step leaves is of the order of its square: no need to evaluate.
            return (cur, res, sin_cos_after_step(sc.0, sc.1, cur.alpha, step[3]));
        }
        sc = cur.alpha.sin_cos();
        (f, a) = residuals_jacobian_at(g, &cur, rho, sc.0, sc.1);
        res = as_mm(&f);
        if res <= best.1 {
            best = (cur, res, sc);
        }
        if step.amax() < NEWTON_STEP_STOP * (1.0 + cur.p.amax()) {
            break;
        }
    }
    best
}

/// A Newton step of the pose below this (mm; alpha times the platform radius) is the last.
pub const FINAL_STEP_MM: f64 = 1e-9;

/// Residuals and Jacobian A from the rod vectors at (sin alpha, cos alpha) = (s, c).
#[inline]
fn residuals_jacobian_at(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
    s: f64,
    c: f64,
) -> (Vector4<f64>, Matrix4<f64>) {
    let v = rod_vectors_sc(g, pose, rho, s, c);
    let l = rod_lengths(g);
    let f = Vector4::from_fn(|i, _| v[i].norm_squared() - l[i] * l[i]);
    (f, jacobian_at(&v, g, s, c))
}

/// The residuals of eqs. (3)-(6), the Jacobian A of [`jacobian_pose`] and (sin alpha,
/// cos alpha), from one sin_cos.
#[inline]
pub(crate) fn residuals_jacobian_sin_cos(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
) -> (Vector4<f64>, Matrix4<f64>, (f64, f64)) {
    let (s, c) = pose.alpha.sin_cos();
    let (f, a) = residuals_jacobian_at(g, pose, rho, s, c);
    (f, a, (s, c))
}

/// a^-1 b by Gaussian elimination with partial pivoting; None when a pivot is zero.
#[inline(always)]
fn solve4(mut a: Matrix4<f64>, mut b: Vector4<f64>) -> Option<Vector4<f64>> {
    for k in 0..4 {
        let p = (k..4)
            .max_by(|&i, &j| a[(i, k)].abs().total_cmp(&a[(j, k)].abs()))
            .unwrap_or(k);
        if a[(p, k)] == 0.0 {
            return None;
        }
        if p != k {
            a.swap_rows(p, k);
            b.swap_rows(p, k);
        }
        let inv = 1.0 / a[(k, k)];
        for i in k + 1..4 {
            let m = a[(i, k)] * inv;
            for j in k + 1..4 {
                a[(i, j)] -= m * a[(k, j)];
            }
            b[i] -= m * b[k];
        }
    }
    let mut x = Vector4::zeros();
    for k in (0..4).rev() {
        let mut acc = b[k];
        for j in k + 1..4 {
            acc -= a[(k, j)] * x[j];
        }
        x[k] = acc / a[(k, k)];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::Machine;

    #[test]
    fn jacobians_match_finite_differences() {
        let g = Machine::default_verne().module;
        let pose = ModulePose {
            p: Vector3::new(-150.0, 80.0, 1100.0),
            alpha: 0.13,
        };
        let rho = Sliders::new(400.0, 300.0, 350.0);
        let a = jacobian_pose(&g, &pose, &rho);
        let h = 1e-6;
        for j in 0..4 {
            let mut plus = pose;
            let mut minus = pose;
            if j < 3 {
                plus.p[j] += h;
                minus.p[j] -= h;
            } else {
                plus.alpha += h;
                minus.alpha -= h;
            }
            let fd = (residuals(&g, &plus, &rho) - residuals(&g, &minus, &rho)) / (2.0 * h);
            for i in 0..4 {
                assert!((fd[i] - a[(i, j)]).abs() < 1e-4 * (1.0 + a[(i, j)].abs()));
            }
        }
        let b = jacobian_sliders(&g, &pose, &rho);
        for j in 0..3 {
            let mut plus = rho;
            let mut minus = rho;
            plus[j] += h;
            minus[j] -= h;
            let fd = (residuals(&g, &pose, &plus) - residuals(&g, &pose, &minus)) / (2.0 * h);
            for i in 0..4 {
                assert!((fd[i] - b[(i, j)]).abs() < 1e-4 * (1.0 + b[(i, j)].abs()));
            }
        }
    }

    /// Three points of the default machine's workspace, each with its working branch: the
    /// exact solutions the residual's and the polish's tests start from.
    fn working_solutions(m: &Machine) -> Vec<(ModulePose, crate::parallel_module::ik::IkBranch)> {
        [
            Vector3::new(-300.0, 0.0, 1100.0),
            Vector3::new(-250.0, 40.0, 1100.0),
            Vector3::new(-320.0, -40.0, 1120.0),
        ]
        .into_iter()
        .map(|p| {
            let branches = crate::parallel_module::ik::solve(m, &p);
            let b = *crate::parallel_module::ik::working(&branches).expect("a working branch");
            (ModulePose { p, alpha: b.alpha }, b)
        })
        .collect()
    }

    /// `residual_mm` is the length error along the rod, |f| / (2 L): a slider of an exact
    /// solution moved by d changes f of each of its rods by d^2 - 2 d v_z exactly (v its rod
    /// vector), and the residual is the largest of those over 2 L, to 1e-9 relative. Three
    /// points, each slider, d from 1e-3 to 10 mm either way.
    #[test]
    fn the_residual_is_the_length_error_along_the_rod() {
        let m = crate::spec::Machine::default_verne();
        let g = &m.module;
        for (pose, b) in working_solutions(&m) {
            let v = rod_vectors(g, &pose, &b.rho);
            let l = rod_lengths(g);
            // The rods on each slider: leg I's two, then legs II and III.
            let rods: [&[usize]; 3] = [&[0, 1], &[2], &[3]];
            for (k, on_slider) in rods.iter().enumerate() {
                for d in [1e-3, -1e-3, 0.1, -0.1, 1.0, -1.0, 10.0, -10.0] {
                    let mut rho = b.rho;
                    rho[k] += d;
                    let want = on_slider
                        .iter()
                        .map(|&i| (d * d - 2.0 * d * v[i].z).abs() / (2.0 * l[i]))
                        .fold(0.0f64, f64::max);
                    let got = residual_mm(g, &pose, &rho);
                    assert!(
                        (got - want).abs() <= 1e-9 * want,
                        "slider {k}, {d}: {got} {want}"
                    );
                }
            }
        }
    }

    /// The polish's residual is `residual_mm`: from an exact solution (its first step is
    /// below `FINAL_STEP_MM`) it is that of the start, bit for bit; from starts moved by up to
    /// 1 mm and 0.01 rad it bounds that of the pose returned (to 1e-12 mm of rounding), which
    /// is the solution.
    #[test]
    fn the_polish_reports_the_residual_of_what_it_returns() {
        let m = crate::spec::Machine::default_verne();
        let g = &m.module;
        let mut uniform = crate::math::test_rng::lcg(0x9011_54e5_0000_0002);
        let mut unit = || uniform() * 2.0 - 1.0;
        for (exact, b) in working_solutions(&m) {
            let p = exact.p;
            let (_, residual) = polish_pose_with_residual(g, exact, &b.rho);
            assert_eq!(residual, residual_mm(g, &exact, &b.rho));
            for _ in 0..20 {
                let start = ModulePose {
                    p: p + Vector3::new(unit(), unit(), unit()),
                    alpha: b.alpha + 0.01 * unit(),
                };
                let (pose, residual) = polish_pose_with_residual(g, start, &b.rho);
                let actual = residual_mm(g, &pose, &b.rho);
                // To rounding: both are near 1e-13 mm there.
                assert!(
                    actual <= residual + 1e-12 && residual < 1e-9,
                    "{actual} {residual}"
                );
                assert!((pose.p - p).amax() < 1e-6, "{pose:?}");
            }
        }
    }

    /// `solve4` solves A x = b with partial pivoting: for random A with a zero or a 1e-12 first
    /// pivot (elimination without row swaps divides by it), or with rows 0 and 3 swapped, x
    /// comes back to 1e-9 relative (the draws of condition number below 1e4, over 250 of the
    /// 300); a zero column gives None.
    #[test]
    fn solve4_pivots() {
        let mut uniform = crate::math::test_rng::lcg(0x5017_e400_0000_0004);
        let mut unit = || uniform() * 2.0 - 1.0;
        let mut checked = 0;
        for trial in 0..300 {
            let mut a = Matrix4::from_fn(|_, _| unit());
            match trial % 3 {
                0 => a[(0, 0)] = 0.0,
                1 => a[(0, 0)] = 1e-12,
                _ => a.swap_rows(0, 1 + trial % 3),
            }
            let x = Vector4::from_fn(|_, _| unit());
            let got = solve4(a, a * x).expect("a regular matrix");
            // Within the matrix's conditioning: skip the rare nearly singular draw.
            let cond = a.norm() * a.try_inverse().map_or(f64::INFINITY, |i| i.norm());
            if cond < 1e4 {
                assert!((got - x).amax() <= 1e-9 * x.amax(), "{a} {x} {got}");
                checked += 1;
            }
            let mut singular = a;
            singular.set_column(trial % 4, &Vector4::zeros());
            assert_eq!(solve4(singular, a * x), None, "{singular}");
        }
        assert!(checked > 250, "{checked}");
    }

    /// `rod_tilts` is each rod vector's angle from +z, atan2(|v_xy|, v_z), whatever its length
    /// (poses that are not solutions, rods shorter and longer than L): 1e-12 rad.
    #[test]
    fn rod_tilts_are_the_angles_from_the_slider_axis() {
        let g = crate::spec::Machine::default_verne().module;
        let mut uniform = crate::math::test_rng::lcg(0x7117_5000_0000_0006);
        let mut unit = || uniform() * 2.0 - 1.0;
        for _ in 0..500 {
            let pose = ModulePose {
                p: Vector3::new(600.0 * unit(), 600.0 * unit(), 1100.0 + 900.0 * unit()),
                alpha: unit(),
            };
            let rho = Sliders::new(600.0 * unit(), 600.0 * unit(), 600.0 * unit());
            let v = rod_vectors(&g, &pose, &rho);
            for (tilt, v) in rod_tilts(&g, &pose, &rho).iter().zip(v) {
                let want = v.xy().norm().atan2(v.z);
                assert!((tilt - want).abs() <= 1e-12, "{tilt} {want}: {v}");
            }
        }
    }

    /// A pose or sliders with a NaN or an infinity never pass a residual test: the residual is
    /// infinite (it was 0 for a NaN, which `f64::max` passed over), and the polish from such a
    /// start reports an infinite residual, not a solution.
    #[test]
    fn a_pose_that_is_not_finite_has_an_infinite_residual() {
        let m = crate::spec::Machine::default_verne();
        let g = &m.module;
        let p = Vector3::new(-300.0, 0.0, 1100.0);
        let branches = crate::parallel_module::ik::solve(&m, &p);
        let b = crate::parallel_module::ik::working(&branches).expect("a working branch");
        let good = ModulePose { p, alpha: b.alpha };
        assert!(residual_mm(g, &good, &b.rho) < 1e-9);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in 0..7 {
                let (mut pose, mut rho) = (good, b.rho);
                match k {
                    0..=2 => pose.p[k] = bad,
                    3 => pose.alpha = bad,
                    _ => rho[k - 4] = bad,
                }
                assert_eq!(residual_mm(g, &pose, &rho), f64::INFINITY, "{bad} at {k}");
                let (_, residual) = polish_pose_with_residual(g, pose, &rho);
                assert_eq!(residual, f64::INFINITY, "{bad} at {k}");
            }
        }
    }
}
