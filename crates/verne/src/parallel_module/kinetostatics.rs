//! Kinetostatics of the parallel module: differentiating constraints (3)-(6) gives
//! A dX + B drho = 0 with X = (xp, yp, zp, alpha) (A: 4x4, B: 4x3), as the comparative study
//! (Wenger, Gosselin, Chablat 2001, section 2.3) does for its planar mechanisms.
//!
//! - Parallel singularity: det A = 0 (two assembly modes meet; the platform gains a motion).
//! - Serial singularity: a rod perpendicular to its slider (its row of B vanishes).
//! - Velocity amplification factors: singular values of the 3x3 map from slider rates to the
//!   velocity of P (first three rows of -A^-1 B); the study bounds them within 1/3 .. 3.
//! - Platform rotation rate: the fourth row of -A^-1 B (rad per mm of slider motion).

use nalgebra::{Matrix3, Matrix4, Matrix4x3, RowVector3, Vector3};

use crate::parallel_module::equations::{
    ModulePose, Sliders, jacobian_pose, jacobian_sliders, jacobians, rod_lengths, rod_vectors,
};
use crate::spec::ModuleGeometry;

/// Kinetostatic measures of one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinetostatics {
    /// det A with every row divided by 2 L_i (rows become rod directions and their moment about
    /// the x axis through P, in mm): dimension mm, zero at a parallel singularity.
    pub det_a: f64,
    /// Inverse condition number of the row-normalised A, with the alpha column divided by R2 so
    /// that every column is dimensionless: 1 far from, 0 at a parallel singularity.
    pub parallel_margin: f64,
    /// Smallest |cos| of the angle between a rod and its slider axis: 0 at a serial singularity.
    pub serial_margin: f64,
    /// Velocity amplification factors, largest first (mm/s of P per mm/s of sliders); infinite
    /// at a parallel singularity.
    pub amplification: [f64; 3],
    /// d alpha / d rho (rad/mm).
    pub rotation_rate: RowVector3<f64>,
}

impl Kinetostatics {
    /// True when every amplification factor lies within [lo, hi].
    pub fn amplification_within(&self, lo: f64, hi: f64) -> bool {
        self.amplification.iter().all(|&l| l >= lo && l <= hi)
    }
}

/// A and B of A dX + B drho = 0 with every row divided by 2 L_i (rows become rod directions),
/// and the rod lengths.
fn scaled_jacobians(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
) -> (Matrix4<f64>, Matrix4x3<f64>, [f64; 4]) {
    let (mut a, mut b) = jacobians(g, pose, rho);
    let l = rod_lengths(g);
    for (i, li) in l.iter().enumerate() {
        let k = 1.0 / (2.0 * li);
        a.row_mut(i).scale_mut(k);
        b.row_mut(i).scale_mut(k);
    }
    (a, b, l)
}

/// Velocity amplification factors (largest first) and d alpha / d rho from the scaled A and B:
/// the singular values of the first three rows of -A^-1 B, and its fourth row; infinite at a
/// parallel singularity.
fn velocity_map(a: &Matrix4<f64>, b: &Matrix4x3<f64>) -> ([f64; 3], RowVector3<f64>) {
    match a.lu().solve(b) {
        Some(x) if x.iter().all(|e| e.is_finite()) => {
            let jp: Matrix3<f64> = -x.fixed_rows::<3>(0).into_owned();
            let mut s: [f64; 3] = jp.singular_values().into();
            s.sort_by(|p, q| q.total_cmp(p));
            (s, -x.fixed_rows::<1>(3).into_owned())
        }
        _ => ([f64::INFINITY; 3], RowVector3::repeat(f64::INFINITY)),
    }
}

/// The velocity amplification factors alone, largest first: [`kinetostatics`]'s, bit for bit,
/// without its singular value decomposition of A (the workspace's constraint (iii) needs only
/// these).
pub fn amplification_factors(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> [f64; 3] {
    let (a, b, _) = scaled_jacobians(g, pose, rho);
    velocity_map(&a, &b).0
}

pub fn kinetostatics(g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> Kinetostatics {
    let (a, b, l) = scaled_jacobians(g, pose, rho);
    let det_a = a.determinant();
    let mut a_dimless: Matrix4<f64> = a;
    a_dimless.column_mut(3).scale_mut(1.0 / g.r_big2);
    let sv = a_dimless.singular_values();
    let parallel_margin = if sv.max() > 0.0 {
        sv.min() / sv.max()
    } else {
        0.0
    };
    let v = rod_vectors(g, pose, rho);
    let serial_margin = (0..4).fold(f64::INFINITY, |m, i| m.min((v[i].z / l[i]).abs()));
    let (amplification, rotation_rate) = velocity_map(&a, &b);
    Kinetostatics {
        det_a,
        parallel_margin,
        serial_margin,
        amplification,
        rotation_rate,
    }
}

/// How far from singularities a pose must be: the thresholds `verne verify` checks (its
/// `lambda_min`, `lambda_max` and `parallel_margin_min`, docs/verify.md), and that a controller
/// (`crates/verne-kins`) refuses a pose by.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SingularityLimits {
    /// Smallest velocity amplification factor allowed.
    pub lambda_min: f64,
    /// Largest velocity amplification factor allowed.
    pub lambda_max: f64,
    /// Smallest parallel margin (inverse condition number of A) allowed.
    pub parallel_margin_min: f64,
}

/// Relative slack of the proof that a pose is clear of the [`SingularityLimits`]
/// ([`clear_of_singularities`]): the squared amplification factors are proved at most
/// lambda_max^2 (1 - this) and at least lambda_min^2 (1 + this), the squared parallel margin at
/// least parallel_margin_min^2 (1 + this). Far above the rounding of the proof and of the
/// singular value decompositions it stands in for (about cond(A) 1e-14 of the same quantities,
/// cond(A) at most [`SINGULARITY_PROOF_COND`]), so that a pose it clears is one [`kinetostatics`]
/// clears.
pub const SINGULARITY_PROOF_REL: f64 = 1e-6;

/// Largest condition number of the scaled A (Frobenius norms) for which
/// [`clear_of_singularities`] decides: the rounding of A^-1 B, relative, is below cond(A) times a
/// few hundred units in the last place, under a hundredth of [`SINGULARITY_PROOF_REL`] there.
pub const SINGULARITY_PROOF_COND: f64 = 1e6;

impl SingularityLimits {
    /// The measures are within the limits: amplification factors within [lambda_min,
    /// lambda_max] and the parallel margin at least its minimum; a NaN fails.
    pub fn admit(&self, k: &Kinetostatics) -> bool {
        k.amplification[0] <= self.lambda_max
            && k.amplification[2] >= self.lambda_min
            && k.parallel_margin >= self.parallel_margin_min
    }

    /// The pose is within the limits ([`SingularityLimits::admit`] of its [`kinetostatics`]):
    /// proved by [`clear_of_singularities`] where it can, which is most poses, else decided by
    /// the singular value decompositions. The same answer either way.
    pub fn admit_pose(&self, g: &ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> bool {
        clear_of_singularities(g, pose, rho, self) || self.admit(&kinetostatics(g, pose, rho))
    }
}

/// True when the pose is proved within `limits` without a singular value decomposition; false
/// when it is not, or too close to a limit to tell (the caller then decides by
/// [`kinetostatics`]), or A is too ill-conditioned ([`SINGULARITY_PROOF_COND`]). With the slack
/// [`SINGULARITY_PROOF_REL`]:
///
/// - the parallel margin sigma_min / sigma_max of the dimensionless A_d is at least
///   1 / (|A_d|_F |A_d^-1|_F) (sigma_max <= |A_d|_F, 1 / sigma_min = |A_d^-1|_2 <= |A_d^-1|_F);
/// - the amplification factors are the square roots of the eigenvalues of G = J_P^T J_P, J_P the
///   first three rows of -A^-1 B (B has one entry per row: A^-1 B is three columns of A^-1
///   scaled), so lambda_max^2 I - G > 0 and G - lambda_min^2 I > 0, proved by LDL^T
///   factorizations, bound them.
pub fn clear_of_singularities(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
    limits: &SingularityLimits,
) -> bool {
    let (a, b, _) = scaled_jacobians(g, pose, rho);
    let Some(inv) = inverse4(&a) else {
        return false;
    };
    let (norm_a, norm_inv) = (a.norm_squared(), inv.norm_squared());
    let cond_sq = norm_a * norm_inv;
    if cond_sq.is_nan() || cond_sq > SINGULARITY_PROOF_COND * SINGULARITY_PROOF_COND {
        return false;
    }
    // A_d = A diag(1, 1, 1, 1 / R2), A_d^-1 = diag(1, 1, 1, R2) A^-1.
    let r2 = g.r_big2;
    let col3 = a.column(3).norm_squared();
    let row3 = inv.row(3).norm_squared();
    let dimless = (norm_a - col3 + col3 / (r2 * r2)) * (norm_inv - row3 + row3 * r2 * r2);
    let margin_min = limits.parallel_margin_min;
    let margin_test = dimless * margin_min * margin_min * (1.0 + SINGULARITY_PROOF_REL);
    if margin_test.is_nan() || margin_test >= 1.0 {
        return false;
    }
    // Rows 0, 1, 2 of A^-1 B = -J_P: B's entries are b00, b10 (slider 1), b21, b32 (the sign
    // does not change G).
    let jp = |i: usize| {
        [
            inv[(i, 0)] * b[(0, 0)] + inv[(i, 1)] * b[(1, 0)],
            inv[(i, 2)] * b[(2, 1)],
            inv[(i, 3)] * b[(3, 2)],
        ]
    };
    let (j0, j1, j2) = (jp(0), jp(1), jp(2));
    let gram = |k: usize, l: usize| j0[k] * j0[l] + j1[k] * j1[l] + j2[k] * j2[l];
    let (g00, g10, g11, g20, g21, g22) = (
        gram(0, 0),
        gram(1, 0),
        gram(1, 1),
        gram(2, 0),
        gram(2, 1),
        gram(2, 2),
    );
    let hi = limits.lambda_max * limits.lambda_max * (1.0 - SINGULARITY_PROOF_REL);
    let lo = limits.lambda_min * limits.lambda_min * (1.0 + SINGULARITY_PROOF_REL);
    positive_definite([
        [hi - g00, 0.0, 0.0],
        [-g10, hi - g11, 0.0],
        [-g20, -g21, hi - g22],
    ]) && positive_definite([
        [g00 - lo, 0.0, 0.0],
        [g10, g11 - lo, 0.0],
        [g20, g21, g22 - lo],
    ])
}

/// The inverse of a 4x4 matrix by its adjugate, from the twelve 2x2 minors of its top and
/// bottom row pairs (Laplace expansion along them): about half the multiplications of
/// nalgebra's cofactors. None when the determinant is zero or not finite. Accurate to cond(A)
/// times a few units in the last place, as any inverse.
#[inline]
fn inverse4(a: &Matrix4<f64>) -> Option<Matrix4<f64>> {
    let m = |i: usize, j: usize| a[(i, j)];
    // Minors of rows 0-1 (s) and of rows 2-3 (c), columns (0,1) (0,2) (0,3) (1,2) (1,3) (2,3).
    let s0 = m(0, 0) * m(1, 1) - m(1, 0) * m(0, 1);
    let s1 = m(0, 0) * m(1, 2) - m(1, 0) * m(0, 2);
    let s2 = m(0, 0) * m(1, 3) - m(1, 0) * m(0, 3);
    let s3 = m(0, 1) * m(1, 2) - m(1, 1) * m(0, 2);
    let s4 = m(0, 1) * m(1, 3) - m(1, 1) * m(0, 3);
    let s5 = m(0, 2) * m(1, 3) - m(1, 2) * m(0, 3);
    let c5 = m(2, 2) * m(3, 3) - m(3, 2) * m(2, 3);
    let c4 = m(2, 1) * m(3, 3) - m(3, 1) * m(2, 3);
    let c3 = m(2, 1) * m(3, 2) - m(3, 1) * m(2, 2);
    let c2 = m(2, 0) * m(3, 3) - m(3, 0) * m(2, 3);
    let c1 = m(2, 0) * m(3, 2) - m(3, 0) * m(2, 2);
    let c0 = m(2, 0) * m(3, 1) - m(3, 0) * m(2, 1);
    let det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let k = 1.0 / det;
    Some(Matrix4::new(
        (m(1, 1) * c5 - m(1, 2) * c4 + m(1, 3) * c3) * k,
        (-m(0, 1) * c5 + m(0, 2) * c4 - m(0, 3) * c3) * k,
        (m(3, 1) * s5 - m(3, 2) * s4 + m(3, 3) * s3) * k,
        (-m(2, 1) * s5 + m(2, 2) * s4 - m(2, 3) * s3) * k,
        (-m(1, 0) * c5 + m(1, 2) * c2 - m(1, 3) * c1) * k,
        (m(0, 0) * c5 - m(0, 2) * c2 + m(0, 3) * c1) * k,
        (-m(3, 0) * s5 + m(3, 2) * s2 - m(3, 3) * s1) * k,
        (m(2, 0) * s5 - m(2, 2) * s2 + m(2, 3) * s1) * k,
        (m(1, 0) * c4 - m(1, 1) * c2 + m(1, 3) * c0) * k,
        (-m(0, 0) * c4 + m(0, 1) * c2 - m(0, 3) * c0) * k,
        (m(3, 0) * s4 - m(3, 1) * s2 + m(3, 3) * s0) * k,
        (-m(2, 0) * s4 + m(2, 1) * s2 - m(2, 3) * s0) * k,
        (-m(1, 0) * c3 + m(1, 1) * c1 - m(1, 2) * c0) * k,
        (m(0, 0) * c3 - m(0, 1) * c1 + m(0, 2) * c0) * k,
        (-m(3, 0) * s3 + m(3, 1) * s1 - m(3, 2) * s0) * k,
        (m(2, 0) * s3 - m(2, 1) * s1 + m(2, 2) * s0) * k,
    ))
}

/// Whether the symmetric 3x3 matrix `s` (its lower triangle read) is positive definite: every
/// pivot of its LDL^T factorization above zero (a NaN fails).
#[inline]
fn positive_definite(s: [[f64; 3]; 3]) -> bool {
    let d0 = s[0][0];
    if d0.is_nan() || d0 <= 0.0 {
        return false;
    }
    let (l10, l20) = (s[1][0] / d0, s[2][0] / d0);
    let d1 = s[1][1] - l10 * s[1][0];
    if d1.is_nan() || d1 <= 0.0 {
        return false;
    }
    let e21 = s[2][1] - l20 * s[1][0];
    let d2 = s[2][2] - l20 * s[2][0] - e21 / d1 * e21;
    d2 > 0.0
}

/// Velocity of P and alpha rate for given slider rates (the forward velocity map).
pub fn pose_rates(
    g: &ModuleGeometry,
    pose: &ModulePose,
    rho: &Sliders,
    rho_rate: &Vector3<f64>,
) -> Option<(Vector3<f64>, f64)> {
    let a = jacobian_pose(g, pose, rho);
    let b = jacobian_sliders(g, pose, rho);
    let x = a.lu().solve(&(-(b * rho_rate)))?;
    Some((Vector3::new(x[0], x[1], x[2]), x[3]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel_module::fk;
    use crate::spec::Machine;

    #[test]
    fn velocity_map_matches_finite_differences_of_fk() {
        let m = Machine::default_verne();
        let rho = Sliders::new(368.354796, 84.956547, 179.032689);
        let w = *fk::working(&fk::solve(&m, &rho)).unwrap();
        let h = 1e-5;
        for j in 0..3 {
            let mut rp = rho;
            rp[j] += h;
            let mut rm = rho;
            rm[j] -= h;
            let fp = fk::working(&fk::solve(&m, &rp)).unwrap().pose;
            let fm = fk::working(&fk::solve(&m, &rm)).unwrap().pose;
            let mut e = Vector3::zeros();
            e[j] = 1.0;
            let (v, da) = pose_rates(&m.module, &w.pose, &rho, &e).unwrap();
            let fd = (fp.p - fm.p) / (2.0 * h);
            assert!((fd - v).amax() < 1e-5, "{fd} vs {v}");
            assert!(((fp.alpha - fm.alpha) / (2.0 * h) - da).abs() < 1e-7);
        }
        let k = kinetostatics(&m.module, &w.pose, &rho);
        assert!(
            k.amplification[0] >= k.amplification[1] && k.amplification[1] >= k.amplification[2]
        );
        // The workspace's shortcut gives the same factors, bit for bit.
        assert_eq!(
            amplification_factors(&m.module, &w.pose, &rho),
            k.amplification
        );
        assert!(k.parallel_margin > 0.0 && k.parallel_margin <= 1.0);
        assert!(k.serial_margin > 0.0);
    }

    /// [`inverse4`] is the inverse: against nalgebra's on matrices with entries in [-1, 1]
    /// (relative to its largest entry, 1e-12 times the condition number), and None for a
    /// singular matrix.
    #[test]
    fn the_adjugate_inverse_is_the_inverse() {
        let mut unit = crate::math::test_rng::lcg(0x41e5_0000_0000_0004);
        for _ in 0..500 {
            let a = Matrix4::from_fn(|_, _| 2.0 * unit() - 1.0);
            let (Some(mine), Some(theirs)) = (inverse4(&a), a.try_inverse()) else {
                continue;
            };
            let cond = a.norm() * theirs.norm();
            assert!(
                (mine - theirs).amax() <= 1e-12 * cond * theirs.amax(),
                "{a} {mine} {theirs}"
            );
        }
        let mut singular = Matrix4::from_fn(|i, j| (i * 4 + j) as f64);
        assert!(inverse4(&singular).is_none());
        singular[(0, 0)] = f64::NAN;
        assert!(inverse4(&singular).is_none());
    }

    /// [`clear_of_singularities`] clears a pose only when the singular value decompositions
    /// admit it ([`SingularityLimits::admit`] of [`kinetostatics`]), with each limit set at the
    /// pose's own value and 1e-9, 1e-7 and 1e-3 of it either side; and it clears every working
    /// pose of a sample under the defaults of `verne verify` and with each amplification limit
    /// 1e-3 outside the pose's value (the parallel margin's bound is cruder: at half of it).
    #[test]
    fn the_proof_clears_only_what_the_decompositions_admit() {
        use crate::parallel_module::ik;
        let m = crate::spec::Machine::default_verne();
        let g = &m.module;
        let defaults = SingularityLimits {
            lambda_min: 1.0 / 3.0,
            lambda_max: 3.0,
            parallel_margin_min: 0.05,
        };
        let mut unit = crate::math::test_rng::lcg(0x5146_0000_0000_0005);
        let mut poses = 0;
        while poses < 300 {
            let p = Vector3::new(
                600.0 * unit() - 300.0,
                600.0 * unit() - 300.0,
                700.0 + 600.0 * unit(),
            );
            let Some(b) = ik::working(&ik::solve(&m, &p)).copied() else {
                continue;
            };
            poses += 1;
            let pose = ModulePose { p, alpha: b.alpha };
            let k = kinetostatics(g, &pose, &b.rho);
            assert!(
                clear_of_singularities(g, &pose, &b.rho, &defaults),
                "{pose:?}"
            );
            let [hi, _, lo] = k.amplification;
            let margin = k.parallel_margin;
            for f in [1e-9, 1e-7, 1e-3, 0.0, -1e-9, -1e-7, -1e-3] {
                for limits in [
                    SingularityLimits {
                        lambda_max: hi * (1.0 + f),
                        ..defaults
                    },
                    SingularityLimits {
                        lambda_min: lo * (1.0 - f),
                        ..defaults
                    },
                    SingularityLimits {
                        parallel_margin_min: margin * (1.0 - f),
                        ..defaults
                    },
                ] {
                    if clear_of_singularities(g, &pose, &b.rho, &limits) {
                        assert!(limits.admit(&k), "{limits:?} {k:?}");
                    }
                }
            }
            let outside = |f: f64| SingularityLimits {
                lambda_min: lo * (1.0 - f),
                lambda_max: hi * (1.0 + f),
                parallel_margin_min: 0.5 * margin,
            };
            assert!(clear_of_singularities(g, &pose, &b.rho, &outside(1e-3)));
            assert!(!clear_of_singularities(g, &pose, &b.rho, &outside(-1e-9)));
            assert_eq!(
                defaults.admit_pose(g, &pose, &b.rho),
                defaults.admit(&k),
                "{pose:?}"
            );
        }
    }

    #[test]
    fn a_horizontal_rod_is_a_serial_singularity() {
        let m = Machine::default_verne();
        let g = m.module;
        // Put slider 2 level with its platform joint: rho2 = zp - R2 sin(alpha).
        let pose = ModulePose {
            p: Vector3::new(-240.0, -86.0, 1000.0),
            alpha: 0.05,
        };
        let rho = Sliders::new(368.0, pose.p.z - g.r_big2 * pose.alpha.sin(), 179.0);
        let k = kinetostatics(&g, &pose, &rho);
        assert!(k.serial_margin < 1e-12);
    }
}
