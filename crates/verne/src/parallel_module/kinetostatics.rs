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
    ModulePose, Sliders, jacobian_pose, jacobian_sliders, rod_lengths, rod_vectors,
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
    let mut a = jacobian_pose(g, pose, rho);
    let mut b = jacobian_sliders(g, pose, rho);
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
