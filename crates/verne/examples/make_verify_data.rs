//! Generates the `verne verify` example (data/verify/, docs/verify.md), deterministically:
//!
//! - `path.csv`: a 5-axis finishing pass on a spherical dome, the tool normal to the surface
//!   (leaning outwards by 6 to 30 degrees), tips every 0.5 mm along a spiral, feed 1500 mm/min;
//!   columns id,x,y,z,i,j,k (tips with 4 decimals, axes with 7, as a CAM system writes them);
//! - `joints.csv`: the joints the library computes for the path as written (machine inverse
//!   kinematics, branch chosen row by row by `PathState`), id,t,rho1,rho2,rho3,theta1,theta2
//!   (mm, degrees, 6 decimals; t in s from the feed);
//! - `joints_defects.csv`: a copy with five defects injected (docs/verify.md lists them).
//!
//! `cargo run --release --example make_verify_data [-- ROWS OUTDIR]` (default 3000 rows into
//! data/verify; the 100k-row benchmark file uses `-- 100000 /tmp/verify100k`).

use std::f64::consts::PI;
use std::fmt::Write as _;

use nalgebra::Vector3;
use verne::machine::orientation::{AxisAngles, ToolOrientation, axis_angles};
use verne::machine::{FirstRowChoice, PathState, ToolPose, machine_ik};
use verne::spec::Machine;

/// Dome: centre and radius (mm, workpiece frame); tips on the sphere.
const CENTRE: [f64; 3] = [0.0, 0.0, -100.0];
const RADIUS: f64 = 150.0;
/// Polar angle of the spiral (deg): from BETA0 to BETA1.
const BETA0: f64 = 6.0;
const BETA1: f64 = 30.0;
/// Distance between rows along the path (mm) and feed (mm/min).
const STEP_MM: f64 = 0.5;
const FEED_MM_MIN: f64 = 1500.0;

struct Row {
    tip: Vector3<f64>,
    axis: Vector3<f64>,
}

/// The spiral: `rows` points STEP_MM apart, the polar angle growing linearly with the azimuth.
fn spiral(rows: usize) -> Vec<Row> {
    // Length of a turn at polar angle b is 2 pi R sin b; the turn count makes the path `rows`
    // steps long.
    let mean_sin = ((BETA0.to_radians().cos() - BETA1.to_radians().cos())
        / (BETA1 - BETA0).to_radians())
    .abs();
    let turns = rows as f64 * STEP_MM / (2.0 * PI * RADIUS * mean_sin);
    let psi_end = 2.0 * PI * turns;
    let dbeta_dpsi = (BETA1 - BETA0).to_radians() / psi_end;
    let mut psi = 0.0f64;
    let mut out = Vec::with_capacity(rows);
    for _ in 0..rows {
        let beta = BETA0.to_radians() + dbeta_dpsi * psi;
        let n = Vector3::new(beta.sin() * psi.cos(), beta.sin() * psi.sin(), beta.cos());
        let tip = Vector3::new(CENTRE[0], CENTRE[1], CENTRE[2]) + RADIUS * n;
        // Round as written to the file, so the joints are those of the file's values.
        let r = |v: f64, d: i32| (v * 10f64.powi(d)).round() / 10f64.powi(d);
        out.push(Row {
            tip: tip.map(|v| r(v, 4)),
            axis: n.map(|v| r(v, 7)),
        });
        psi += STEP_MM / (RADIUS * (beta.sin().powi(2) + dbeta_dpsi.powi(2)).sqrt());
    }
    out
}

/// Joints (mm, rad) of one row.
#[derive(Clone, Copy)]
struct J {
    rho: [f64; 3],
    theta1: f64,
    theta2: f64,
}

fn write_joints(rows: &[(J, f64)], path: &str) {
    let mut s = String::from("id,t,rho1,rho2,rho3,theta1,theta2\n");
    for (k, (j, t)) in rows.iter().enumerate() {
        let _ = writeln!(
            s,
            "{},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6}",
            k + 1,
            t,
            j.rho[0],
            j.rho[1],
            j.rho[2],
            j.theta1.to_degrees(),
            j.theta2.to_degrees()
        );
    }
    std::fs::write(path, s).unwrap_or_else(|e| panic!("{path}: {e}"));
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rows: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(3000);
    let dir = args.get(2).cloned().unwrap_or_else(|| "data/verify".into());
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{dir}: {e}"));
    let m = Machine::default_verne();
    let path = spiral(rows);
    let mut csv = String::from("id,x,y,z,i,j,k\n");
    for (k, r) in path.iter().enumerate() {
        let _ = writeln!(
            csv,
            "{},{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}",
            k + 1,
            r.tip.x,
            r.tip.y,
            r.tip.z,
            r.axis.x,
            r.axis.y,
            r.axis.z
        );
    }
    std::fs::write(format!("{dir}/path.csv"), csv).expect("path.csv");
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let dt = STEP_MM / (FEED_MM_MIN / 60.0);
    let mut joints = Vec::with_capacity(rows);
    for (k, r) in path.iter().enumerate() {
        let row = state
            .next_row(&m, &r.tip, &ToolOrientation::Axis(r.axis), m.tool_length)
            .unwrap_or_else(|e| panic!("row {}: {e}", k + 1));
        let j = J {
            rho: [row.rho.x, row.rho.y, row.rho.z],
            theta1: row.theta1,
            theta2: row.theta2,
        };
        joints.push((j, k as f64 * dt));
    }
    write_joints(&joints, &format!("{dir}/joints.csv"));
    if rows < 3000 {
        return;
    }
    // Defects (1-based rows), one of each kind the checks are meant for.
    let mut bad = joints.clone();
    // 1. A wrong sign on theta1 (row 500): tip_error and axis_error.
    bad[499].0.theta1 = -bad[499].0.theta1;
    // 2. A 0.02 mm offset on rho1 (row 1000): tip_error.
    bad[999].0.rho[0] += 0.02;
    // 3. theta2 off by a full turn (row 1500): joint_jump on the segments either side.
    bad[1499].0.theta2 += 2.0 * PI;
    // 4. A row from the other orientation solution (row 2000): branch flips either side.
    let r = &path[1999];
    let Ok(AxisAngles::Regular(sols)) = axis_angles(&r.axis) else {
        panic!("row 2000: regular axis expected")
    };
    let current = bad[1999].0;
    let other = sols
        .iter()
        .flat_map(|a| {
            machine_ik(
                &m,
                &ToolPose {
                    tip: r.tip,
                    phi1: a.phi1,
                    phi2: a.phi2,
                },
                m.tool_length,
            )
        })
        .filter(|b| b.working() && (b.theta1 - current.theta1).abs() > 1e-3)
        .min_by(|a, b| a.theta1.abs().total_cmp(&b.theta1.abs()))
        .expect("row 2000: another working branch");
    let turn =
        current.theta2 + verne::parallel_module::ik::wrap_angle(other.theta2 - current.theta2);
    bad[1999].0 = J {
        rho: [other.rho.x, other.rho.y, other.rho.z],
        theta1: other.theta1,
        theta2: turn,
    };
    // 5. Too fast (row 2500): the controller is given a tenth of the time for one segment.
    let shift = 0.9 * dt;
    for row in bad.iter_mut().skip(2499) {
        row.1 -= shift;
    }
    write_joints(&bad, &format!("{dir}/joints_defects.csv"));
}
