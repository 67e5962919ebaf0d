//! The homogeneous transforms of the machine (AIM 2007): eq. (1) the platform in the base frame,
//! eq. (7) the workpiece frame on the tilting table, eq. (8) the platform from the tool pose, and
//! eq. (26) the tool pose from the joints.

use std::f64::consts::PI;

use nalgebra::{Matrix4, Vector3, Vector4};

use crate::parallel_module::equations::ModulePose;
use crate::parallel_module::ik::wrap_angle;
use crate::spec::TableGeometry;

use super::ToolPose;

fn trans(v: Vector3<f64>) -> Matrix4<f64> {
    Matrix4::new_translation(&v)
}

fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    )
}

/// bT_t of eq. (7), AIM 2007: the workpiece frame R_t in the base frame.
pub fn table_transform(table: &TableGeometry, theta1: f64, theta2: f64) -> Matrix4<f64> {
    trans(Vector3::new(0.0, 0.0, table.d_a))
        * rot_x(theta1)
        * trans(Vector3::new(0.0, 0.0, table.d_t))
        * rot_x(PI)
        * rot_z(theta2)
}

/// tT_pl of eq. (8), AIM 2007: the platform frame R_pl in the workpiece frame.
pub fn tool_transform(pose: &ToolPose, tool_length: f64) -> Matrix4<f64> {
    trans(pose.tip)
        * rot_z(pose.phi2)
        * rot_x(PI + pose.phi1)
        * trans(Vector3::new(0.0, 0.0, -tool_length))
}

/// bT_pl of eq. (1), AIM 2007: the platform frame in the base frame.
pub fn platform_transform(pose: &ModulePose) -> Matrix4<f64> {
    trans(pose.p) * rot_x(pose.alpha)
}

/// The tool pose in R_t from the module pose and the table angles: eq. (26), AIM 2007, as
/// printed (phi1 = alpha - theta1, phi2 = -theta2, both wrapped to (-pi, pi]).
pub fn tool_pose_eq26(
    table: &TableGeometry,
    module: &ModulePose,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> ToolPose {
    let (xp, yp, zp) = (module.p.x, module.p.y, module.p.z);
    let (s1, c1) = theta1.sin_cos();
    let (s2, c2) = theta2.sin_cos();
    let d = module.alpha - theta1;
    let v1 = tool_length * d.sin() - c1 * yp - s1 * (zp - table.d_a);
    let v2 = table.d_t - c1 * zp + table.d_a * c1 - tool_length * d.cos();
    ToolPose {
        tip: Vector3::new(c2 * xp + v1 * s2, -s2 * xp + v1 * c2, s1 * yp + v2),
        phi1: wrap_angle(d),
        phi2: wrap_angle(-theta2),
    }
}

pub fn tool_tip_by_transforms(
    table: &TableGeometry,
    module: &ModulePose,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> Vector3<f64> {
    let t = table_transform(table, theta1, theta2);
    let inv = t.try_inverse().unwrap_or_else(Matrix4::zeros);
    let u = inv * platform_transform(module) * Vector4::new(0.0, 0.0, tool_length, 1.0);
    Vector3::new(u.x, u.y, u.z)
}
