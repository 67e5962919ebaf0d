//! The identification Jacobian: the derivative of every reading's residual with respect to the
//! machine's parameters and the instrument's, exact.
//!
//! The module's pose q = (xp, yp, zp, alpha) of a row is defined implicitly by the constraint
//! equations f(q, p) = 0, eqs. (3)-(6) of IFToMM 2007, f_i = |v_i|^2 - L_i^2 with v_i the rod
//! vectors (the joints' sliders plus their zero offsets). Differentiating,
//! A dq + (df/dp) dp = 0 with A = df/dq (the parallel Jacobian), so dq/dp = -A^-1 df/dp, and
//! df_i/dp = 2 v_i . dv_i/dp - d(L_i^2)/dp with, per rod (3), (4), (5), (6) and
//! c, s = cos, sin alpha:
//!
//! | p | dv3 | dv4 | dv5 | dv6 |
//! |---|---|---|---|---|
//! | D1 (d1: the negative) | (1, 0, 0) | (1, 0, 0) | 0 | 0 |
//! | R1 | (0, c, s) | (0, -c, -s) | 0 | 0 |
//! | r1 | (0, -1, 0) | (0, 1, 0) | 0 | 0 |
//! | D2 (d2: the negative) | 0 | 0 | (1, 0, 0) | (1, 0, 0) |
//! | R2 | 0 | 0 | (0, -c, -s) | (0, c, s) |
//! | r4 | 0 | 0 | (0, 1, 0) | (0, -1, 0) |
//! | zero of slider 1, 2, 3 | (0, 0, -1) on the rods of that slider |||
//!
//! and d(L_i^2)/dL_i = 2 L_i on the rods of leg i. The readings then follow by the chain rule
//! ([`super::model`]); the instrument's rotation is differentiated on the right,
//! d(R exp(\[r\]) x)/dr = -R \[x\]x at r = 0.

use nalgebra::{DMatrix, Matrix3, Matrix4, RowVector4, Vector3, Vector4};

use crate::machine::table_transform;
use crate::parallel_module::equations::{ModulePose, rod_vectors};
use crate::spec::Machine;

use super::model::{
    Instrument, Measurement, Noise, Nuisance, NuisanceParam, Observed, noise_of, platform_axis,
};
use super::params::Param;

/// df/dp (the four constraint equations) for a module parameter, zero for the others.
fn constraint_derivative(
    m: &Machine,
    pose: &ModulePose,
    row: &Measurement,
    p: Param,
) -> Vector4<f64> {
    let g = &m.module;
    let v = rod_vectors(g, pose, &row.rho);
    let (s, c) = pose.alpha.sin_cos();
    let x = Vector3::x();
    let y = Vector3::y();
    let z = Vector3::z();
    let along = |dv: [Vector3<f64>; 4]| Vector4::from_fn(|i, _| 2.0 * v[i].dot(&dv[i]));
    let zero = Vector3::zeros();
    match p {
        Param::D1 => along([x, x, zero, zero]),
        Param::LowerD1 => along([-x, -x, zero, zero]),
        Param::R1 => along([
            Vector3::new(0.0, c, s),
            Vector3::new(0.0, -c, -s),
            zero,
            zero,
        ]),
        Param::LowerR1 => along([-y, y, zero, zero]),
        Param::L1 => Vector4::new(-2.0 * g.l1, -2.0 * g.l1, 0.0, 0.0),
        Param::D2 => along([zero, zero, x, x]),
        Param::LowerD2 => along([zero, zero, -x, -x]),
        Param::R2 => along([
            zero,
            zero,
            Vector3::new(0.0, -c, -s),
            Vector3::new(0.0, c, s),
        ]),
        Param::R4 => along([zero, zero, y, -y]),
        Param::L2 => Vector4::new(0.0, 0.0, -2.0 * g.l2, 0.0),
        Param::L3 => Vector4::new(0.0, 0.0, 0.0, -2.0 * g.l3),
        Param::Rho1Zero => along([-z, -z, zero, zero]),
        Param::Rho2Zero => along([zero, zero, -z, zero]),
        Param::Rho3Zero => along([zero, zero, zero, -z]),
        Param::ToolLength
        | Param::TableDa
        | Param::TableDt
        | Param::TableYt
        | Param::Theta1Zero
        | Param::Theta2Zero => Vector4::zeros(),
    }
}

/// [x]x, the matrix of the cross product x cross.
fn cross_matrix(x: &Vector3<f64>) -> Matrix3<f64> {
    x.cross_matrix()
}

/// The derivatives of one row's readings (up to 6) with respect to the pose q (columns x, y, z,
/// alpha), to each parameter directly (the pose held), and to each nuisance parameter.
struct RowDerivatives {
    /// d(reading)/dq, one row per reading.
    by_pose: [RowVector4<f64>; 6],
}

/// The weighted Jacobian of [`super::model::residuals`]: one row per reading, the columns
/// `params` then `nuisance` (each data set's instrument only moves its own rows). `inverses`
/// are A^-1 at each row's pose.
#[allow(clippy::too_many_arguments)]
pub fn jacobian(
    m: &Machine,
    insts: &[Instrument],
    rows: &[Measurement],
    poses: &[ModulePose],
    inverses: &[Matrix4<f64>],
    params: &[Param],
    nuisance: &[NuisanceParam],
    noise: &Noise,
) -> DMatrix<f64> {
    let n_rows: usize = rows.iter().map(|r| r.observed.len()).sum();
    let cols = params.len() + nuisance.len();
    let mut out = DMatrix::zeros(n_rows, cols);
    let mut k = 0;
    let mut sigma = [0.0; 6];
    for ((row, pose), inv) in rows.iter().zip(poses).zip(inverses) {
        let len = row.observed.len();
        let inst = &insts[row.set];
        noise_of(row, noise, &mut sigma);
        let d = row_derivatives(m, inst, row, pose);
        for (j, &p) in params.iter().enumerate() {
            let dq = -(inv * constraint_derivative(m, pose, row, p));
            let direct = direct_derivative(m, inst, row, pose, p);
            for i in 0..len {
                out[(k + i, j)] = (d.by_pose[i].dot(&dq.transpose()) + direct[i]) / sigma[i];
            }
        }
        for (j, n) in nuisance.iter().enumerate() {
            if n.set != row.set {
                continue;
            }
            let dn = nuisance_derivative(m, inst, row, pose, n.which);
            for i in 0..len {
                out[(k + i, params.len() + j)] = dn[i] / sigma[i];
            }
        }
        k += len;
    }
    out
}

/// d(tool tip)/dq: [I | Delta dn/dalpha], dn/dalpha = (0, -cos alpha, -sin alpha).
fn tip_by_pose(m: &Machine, alpha: f64) -> [Vector3<f64>; 4] {
    let (s, c) = alpha.sin_cos();
    [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        m.tool_length * Vector3::new(0.0, -c, -s),
    ]
}

/// The unit vector from the table ball to the tool ball, the ball in the base frame and the
/// table's transform (its rotation and the tilted frame's origin).
fn ballbar_geometry(
    m: &Machine,
    inst: &Instrument,
    row: &Measurement,
    pose: &ModulePose,
) -> (Vector3<f64>, Matrix4<f64>) {
    let t = table_transform(&m.table, row.theta[0], row.theta[1]);
    let b = (t * Vector4::new(inst.ball.x, inst.ball.y, inst.ball.z, 1.0)).xyz();
    let e = super::model::tool_tip(m, pose) - b;
    (e / e.norm(), t)
}

fn row_derivatives(
    m: &Machine,
    inst: &Instrument,
    row: &Measurement,
    pose: &ModulePose,
) -> RowDerivatives {
    let r = inst.rotation.matrix();
    let mut by_pose = [RowVector4::zeros(); 6];
    let tip = tip_by_pose(m, pose.alpha);
    match row.observed {
        Observed::Tip { axis, .. } => {
            for (q, d) in tip.iter().enumerate() {
                let rd = r * d;
                for i in 0..3 {
                    by_pose[i][q] = rd[i];
                }
            }
            if axis.is_some() {
                // axis = R (0, sin alpha, -cos alpha): d/dalpha = R (0, cos alpha, sin alpha).
                let (s, c) = pose.alpha.sin_cos();
                let da = r * Vector3::new(0.0, c, s);
                for i in 0..3 {
                    by_pose[3 + i][3] = da[i];
                }
            }
        }
        Observed::Platform(_) => {
            for q in 0..3 {
                for i in 0..3 {
                    by_pose[i][q] = r[(i, q)];
                }
            }
        }
        Observed::Distance(_) => {
            let (u, _) = ballbar_geometry(m, inst, row, pose);
            for (q, d) in tip.iter().enumerate() {
                by_pose[0][q] = u.dot(d);
            }
        }
        Observed::Height(_) => {
            for (q, d) in tip.iter().enumerate() {
                by_pose[0][q] = (r * d)[2];
            }
        }
    }
    RowDerivatives { by_pose }
}

/// d(readings)/dp with the pose held: the tool length and the table's parameters.
fn direct_derivative(
    m: &Machine,
    inst: &Instrument,
    row: &Measurement,
    pose: &ModulePose,
    p: Param,
) -> [f64; 6] {
    let mut out = [0.0; 6];
    let r = inst.rotation.matrix();
    let n = platform_axis(pose.alpha);
    match (row.observed, p) {
        (Observed::Tip { .. }, Param::ToolLength) => {
            out[..3].copy_from_slice((r * n).as_slice());
        }
        (Observed::Height(_), Param::ToolLength) => out[0] = (r * n)[2],
        (Observed::Distance(_), _) => {
            let (u, t) = ballbar_geometry(m, inst, row, pose);
            let [z1, z2] = m.table.theta_zero;
            let tilt = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), row.theta[0] + z1);
            let b = inst.ball;
            // The ball in the base frame B = (0, 0, d_a) + Rx(theta1) [(0, y_t, d_t) +
            // Rx(pi) Rz(theta2) b] (eq. (7), AIM 2007, the angles with their zeros).
            let ball_base = (t * Vector4::new(b.x, b.y, b.z, 1.0)).xyz();
            let d_ball = match p {
                Param::ToolLength => return [u.dot(&n), 0.0, 0.0, 0.0, 0.0, 0.0],
                Param::TableDa => Vector3::z(),
                Param::TableDt => tilt * Vector3::z(),
                Param::TableYt => tilt * Vector3::y(),
                Param::Theta1Zero => Vector3::x().cross(&(ball_base - m.table.d_a * Vector3::z())),
                Param::Theta2Zero => {
                    let turn =
                        nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), row.theta[1] + z2);
                    let flip = nalgebra::Rotation3::from_axis_angle(
                        &Vector3::x_axis(),
                        std::f64::consts::PI,
                    );
                    tilt * (flip * Vector3::z().cross(&(turn * b)))
                }
                _ => Vector3::zeros(),
            };
            out[0] = -u.dot(&d_ball);
        }
        _ => {}
    }
    out
}

/// d(readings)/d(nuisance parameter).
fn nuisance_derivative(
    m: &Machine,
    inst: &Instrument,
    row: &Measurement,
    pose: &ModulePose,
    n: Nuisance,
) -> [f64; 6] {
    let mut out = [0.0; 6];
    let r = inst.rotation.matrix();
    // d(R exp([w]) x)/dw = -R [x]x: column k for w_k.
    let rotation_column = |x: &Vector3<f64>, k: usize| -> Vector3<f64> {
        -(r * cross_matrix(x)).column(k).into_owned()
    };
    let axis_index = match n {
        Nuisance::FrameRx => Some(0),
        Nuisance::FrameRy => Some(1),
        Nuisance::FrameRz => Some(2),
        _ => None,
    };
    let translation_index = match n {
        Nuisance::FrameX => Some(0),
        Nuisance::FrameY => Some(1),
        Nuisance::FrameZ => Some(2),
        _ => None,
    };
    match row.observed {
        Observed::Tip { axis, .. } => {
            if let Some(k) = axis_index {
                let d = rotation_column(&super::model::tool_tip(m, pose), k);
                out[..3].copy_from_slice(d.as_slice());
                if axis.is_some() {
                    let d = rotation_column(&-platform_axis(pose.alpha), k);
                    out[3..6].copy_from_slice(d.as_slice());
                }
            }
            if let Some(k) = translation_index {
                out[k] = 1.0;
            }
        }
        Observed::Platform(_) => {
            if let Some(k) = axis_index {
                out[..3].copy_from_slice(rotation_column(&pose.p, k).as_slice());
            }
            if let Some(k) = translation_index {
                out[k] = 1.0;
            }
        }
        Observed::Height(_) => {
            if let Some(k) = axis_index {
                out[0] = rotation_column(&super::model::tool_tip(m, pose), k)[2];
            }
            if translation_index == Some(2) {
                out[0] = 1.0;
            }
        }
        Observed::Distance(_) => {
            let k = match n {
                Nuisance::BallX => 0,
                Nuisance::BallY => 1,
                Nuisance::BallZ => 2,
                _ => return out,
            };
            let (u, t) = ballbar_geometry(m, inst, row, pose);
            let column = Vector3::new(t[(0, k)], t[(1, k)], t[(2, k)]);
            out[0] = -u.dot(&column);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use nalgebra::{Rotation3, Vector3};

    use super::*;
    use crate::calibrate::model::{
        DEFAULT_NOISE, Device, followed_poses, initial_poses, moved_instruments, nuisance_columns,
        residuals,
    };
    use crate::calibrate::params::moved;
    use crate::math::test_rng::lcg;

    /// Rows of each device on the default machine (its working joints of points spread over the
    /// workspace, the table turned), readings that need not match.
    fn rows(device: Device) -> Vec<Measurement> {
        let m = Machine::default_verne();
        let mut u = lcg(0x1ac0_b1a0 + device as u64);
        let mut out = Vec::new();
        while out.len() < 12 {
            let p = Vector3::new(
                -360.0 + 200.0 * u(),
                -120.0 + 240.0 * u(),
                1000.0 + 250.0 * u(),
            );
            let Some(b) = crate::parallel_module::ik::working_fast(&m, &p) else {
                continue;
            };
            let observed = match device {
                Device::Tracker => Observed::Tip {
                    tip: Vector3::new(u(), u(), u()),
                    axis: Some(Vector3::new(0.1, 0.2, -1.0).normalize()),
                },
                Device::Platform => Observed::Platform(Vector3::new(u(), u(), u())),
                Device::Ballbar => Observed::Distance(150.0),
                Device::Probe => Observed::Height(u()),
            };
            out.push(Measurement {
                rho: b.rho,
                theta: [0.5 * u() - 0.25, 6.0 * u() - 3.0],
                observed,
                set: 0,
                line: out.len() as u64 + 2,
            });
        }
        out
    }

    /// Every column of the Jacobian (machine and instrument) against central finite differences
    /// of the residuals, the poses re-solved by the forward kinematics at each moved machine:
    /// 1e-6 relative to the column's size, h = 1e-5 (mm, rad).
    #[test]
    fn the_jacobian_is_the_derivative_of_the_residuals() {
        let mut m = Machine::default_verne();
        // Away from the nominal zeros and table, so that no derivative vanishes by accident.
        m = moved(
            &m,
            &[Param::Rho1Zero, Param::Theta1Zero, Param::TableYt],
            &[0.3, 0.002, 0.4],
        );
        let inst = Instrument {
            rotation: Rotation3::new(Vector3::new(0.3, -0.2, 1.1)),
            translation: Vector3::new(1500.0, -300.0, 200.0),
            ball: Vector3::new(20.0, -35.0, 60.0),
        };
        let noise = DEFAULT_NOISE;
        for device in [
            Device::Tracker,
            Device::Platform,
            Device::Ballbar,
            Device::Probe,
        ] {
            let rows = rows(device);
            let poses = initial_poses(&m, &rows).expect("working modes");
            let (poses, inv) = followed_poses(&m, &rows, &poses).expect("followed");
            let params = device.sensitive();
            let nuisance = nuisance_columns(&[device]);
            let insts = [inst];
            let j = jacobian(&m, &insts, &rows, &poses, &inv, &params, &nuisance, &noise);
            let h = 1e-5;
            let at = |mm: &Machine, ii: &[Instrument]| {
                let (p, _) = followed_poses(mm, &rows, &poses).expect("followed");
                residuals(mm, ii, &rows, &p, &noise)
            };
            for (c, &p) in params.iter().enumerate() {
                let fd = (at(&moved(&m, &[p], &[h]), &insts) - at(&moved(&m, &[p], &[-h]), &insts))
                    / (2.0 * h);
                let col = j.column(c);
                let scale = col.amax().max(fd.amax()).max(1.0);
                assert!(
                    (col - &fd).amax() <= 1e-6 * scale,
                    "{device:?} {p:?}: {} vs {}",
                    col.transpose(),
                    fd.transpose()
                );
            }
            for (c, n) in nuisance.iter().enumerate() {
                let fd = (at(&m, &moved_instruments(&insts, &[*n], &[h]))
                    - at(&m, &moved_instruments(&insts, &[*n], &[-h])))
                    / (2.0 * h);
                let col = j.column(params.len() + c);
                let scale = col.amax().max(fd.amax()).max(1.0);
                assert!(
                    (col - &fd).amax() <= 1e-6 * scale,
                    "{device:?} {n:?}: {} vs {}",
                    col.transpose(),
                    fd.transpose()
                );
            }
        }
    }
}
