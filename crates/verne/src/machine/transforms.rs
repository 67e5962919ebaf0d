//! The homogeneous transforms of the machine (AIM 2007): eq. (1) the platform in the base frame,
//! eq. (7) the workpiece frame on the tilting table, eq. (8) the platform from the tool pose, and
//! eq. (26) the tool pose from the joints.

use std::f64::consts::PI;

use nalgebra::{Matrix4, Vector3, Vector4};

use crate::math::interval::Iv;
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

/// bT_t of eq. (7), AIM 2007: the workpiece frame R_t in the base frame, for the joints'
/// (theta1, theta2): the table's zero offsets are added here, and its rotary axis sits at
/// (y_t, d_t) in the tilted frame, bT_t = trans(z, d_a) rot(x, theta1) trans(y, y_t)
/// trans(z, d_t) rot(x, pi) rot(z, theta2) (y_t = 0 in the paper).
pub fn table_transform(table: &TableGeometry, theta1: f64, theta2: f64) -> Matrix4<f64> {
    let [z1, z2] = table.theta_zero;
    trans(Vector3::new(0.0, 0.0, table.d_a))
        * rot_x(theta1 + z1)
        * trans(Vector3::new(0.0, table.y_t, table.d_t))
        * rot_x(PI)
        * rot_z(theta2 + z2)
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

/// The tool pose in R_t from the module pose and the joints' table angles: eq. (26), AIM 2007,
/// as printed (phi1 = alpha - theta1, phi2 = -theta2, both wrapped to (-pi, pi]), with the
/// table's zero offsets added to the angles and its rotary axis at y_t (0 in the paper:
/// [`table_transform`]).
pub fn tool_pose_eq26(
    table: &TableGeometry,
    module: &ModulePose,
    theta1: f64,
    theta2: f64,
    tool_length: f64,
) -> ToolPose {
    let (theta1, theta2) = (theta1 + table.theta_zero[0], theta2 + table.theta_zero[1]);
    let (xp, yp, zp) = (module.p.x, module.p.y, module.p.z);
    let (s1, c1) = theta1.sin_cos();
    let (s2, c2) = theta2.sin_cos();
    let d = module.alpha - theta1;
    let v1 = tool_length * d.sin() - c1 * yp - s1 * (zp - table.d_a) + table.y_t;
    let v2 = table.d_t - c1 * zp + table.d_a * c1 - tool_length * d.cos();
    ToolPose {
        tip: Vector3::new(c2 * xp + v1 * s2, -s2 * xp + v1 * c2, s1 * yp + v2),
        phi1: wrap_angle(d),
        phi2: wrap_angle(-theta2),
    }
}

/// The tool pose of eq. (26), AIM 2007, and its rate along a move, over intervals: the tip,
/// the tool axis (eq. (8), with phi1 = alpha - theta1, phi2 = -theta2) and their derivatives
/// d/ds, for every module pose in `pose` (x, y, z, alpha) with rate `rate`, and table angles in
/// `theta` moving at `dtheta` per unit of s.
pub struct ToolPoseOver {
    pub tip: [Iv; 3],
    pub tip_rate: [Iv; 3],
    pub axis: [Iv; 3],
    pub axis_rate: [Iv; 3],
}

/// [`tool_pose_eq26`] and its derivative along a move, enclosed (see [`ToolPoseOver`]).
pub fn tool_pose_over(
    table: &TableGeometry,
    pose: &[Iv; 4],
    rate: &[Iv; 4],
    theta: [Iv; 2],
    dtheta: [f64; 2],
    tool_length: f64,
) -> ToolPoseOver {
    let p = Iv::point;
    let [xp, yp, zp, alpha] = *pose;
    let [dxp, dyp, dzp, dalpha] = *rate;
    // The joints' angles plus the table's zero offsets (a zero of 0 leaves the interval as is).
    let add = |t: Iv, z: f64| if z == 0.0 { t } else { t + p(z) };
    let theta = [
        add(theta[0], table.theta_zero[0]),
        add(theta[1], table.theta_zero[1]),
    ];
    let (s1, c1) = theta[0].sin_cos();
    let (s2, c2) = theta[1].sin_cos();
    let (t1, t2) = (p(dtheta[0]), p(dtheta[1]));
    let d = alpha - theta[0];
    let dd = dalpha - t1;
    let (sd, cd) = d.sin_cos();
    let l = p(tool_length);
    let da = p(table.d_a);
    // eq. (26): v1 = L sin d - c1 yp - s1 (zp - d_a), v2 = d_t - c1 zp + d_a c1 - L cos d.
    let v1 = l * sd - c1 * yp - s1 * (zp - da);
    let v1 = if table.y_t == 0.0 {
        v1
    } else {
        v1 + p(table.y_t)
    };
    let v2 = p(table.d_t) - c1 * zp + da * c1 - l * cd;
    let dv1 = l * cd * dd + s1 * t1 * yp - c1 * dyp - c1 * t1 * (zp - da) - s1 * dzp;
    let dv2 = s1 * t1 * zp - c1 * dzp - da * s1 * t1 + l * sd * dd;
    ToolPoseOver {
        tip: [c2 * xp + v1 * s2, -(s2 * xp) + v1 * c2, s1 * yp + v2],
        tip_rate: [
            -(s2 * t2 * xp) + c2 * dxp + dv1 * s2 + v1 * c2 * t2,
            -(c2 * t2 * xp) - s2 * dxp + dv1 * c2 - v1 * s2 * t2,
            c1 * t1 * yp + s1 * dyp + dv2,
        ],
        // a = (sin phi1 sin phi2, -sin phi1 cos phi2, cos phi1) with phi2 = -theta2.
        axis: [-(sd * s2), -(sd * c2), cd],
        axis_rate: [
            -(cd * dd * s2) - sd * c2 * t2,
            -(cd * dd * c2) + sd * s2 * t2,
            -(sd * dd),
        ],
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
