//! Invariants of the machine kinematics (AIM 2007, section III): eq. (26) against the transforms,
//! ik -> fk -> ik round trips over deterministic grids, the theta1 root count against a dense
//! scan, the tool-axis convention worked by hand, and a path through the rotary singularity.
//!
//! Expected values here come from the paper's transforms re-implemented in this file, from hand
//! calculation, or from round trips: never from the function under test alone.

use std::f64::consts::{FRAC_PI_6, PI, TAU};

use nalgebra::{Matrix4, Vector3, Vector4};
use verne::machine::orientation::{ROTARY_SINGULAR_CONE_RAD, ToolOrientation, tool_axis};
use verne::machine::{
    FirstRowChoice, PathCandidates, PathState, ToolPose, machine_fk, machine_ik, path_candidates,
    path_candidates_into, theta1_equation, tool_pose_eq26,
};
use verne::parallel_module::equations::{ModulePose, jacobian_pose, jacobian_sliders};
use verne::parallel_module::ik::wrap_angle;
use verne::spec::Machine;

/// Round-trip tolerance on positions (mm).
const ROUND_TRIP_MM: f64 = 1e-9;
/// Round-trip tolerance on angles (rad).
const ROUND_TRIP_RAD: f64 = 1e-9;
/// Agreement between two evaluations of the same closed form (mm).
const SAME_FORMULA_MM: f64 = 1e-9;
/// Near a singularity the joints fix the pose (or the pose the joints) only to about the condition
/// number times the rounding error: a result can be off by this much (mm or rad) per unit of the
/// condition number (of the Jacobians in `condition`) while its residuals are at machine
/// precision: the rounding of a length of about 1000 mm (half a unit in the last place of 1000
/// is 1.1e-13). (It was 1e-15, a hundred times below that model: a change of the last bit of
/// theta1 moved one branch with condition 1.01e6 past it, to 1.15e-9 mm.)
/// Branches with a condition number <= 1e6 (see `condition`; and every working branch) are held
/// to the 1e-9 bounds.
const FORWARD_ERROR_PER_COND_MM: f64 = 0.5 * f64::EPSILON * 1000.0;
/// Tool length used throughout (mm), the AIM paper's.
const DELTA: f64 = 50.0;

// --- The paper's transforms, written out independently of the library. ---

fn trans(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    let mut m = Matrix4::identity();
    m[(0, 3)] = x;
    m[(1, 3)] = y;
    m[(2, 3)] = z;
    m
}

fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    let mut m = Matrix4::identity();
    m[(1, 1)] = c;
    m[(1, 2)] = -s;
    m[(2, 1)] = s;
    m[(2, 2)] = c;
    m
}

fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    let mut m = Matrix4::identity();
    m[(0, 0)] = c;
    m[(0, 1)] = -s;
    m[(1, 0)] = s;
    m[(1, 1)] = c;
    m
}

/// eq. (7).
fn b_t_t(m: &Machine, theta1: f64, theta2: f64) -> Matrix4<f64> {
    trans(0.0, 0.0, m.table.d_a)
        * rot_x(theta1)
        * trans(0.0, 0.0, m.table.d_t)
        * rot_x(PI)
        * rot_z(theta2)
}

/// eq. (8).
fn t_t_pl(p: &ToolPose) -> Matrix4<f64> {
    trans(p.tip.x, p.tip.y, p.tip.z) * rot_z(p.phi2) * rot_x(PI + p.phi1) * trans(0.0, 0.0, -DELTA)
}

/// eq. (1).
fn b_t_pl(p: &ModulePose) -> Matrix4<f64> {
    trans(p.p.x, p.p.y, p.p.z) * rot_x(p.alpha)
}

/// Condition number of the problem at a branch: the larger of that of the module's parallel
/// Jacobian A (forward kinematics: pose from joints) and that of the machine inverse problem's
/// Jacobian [A (dP/dtheta1, dalpha/dtheta1) | B] (joints from the tool pose), where
/// dP/dtheta1 = x_b cross (P - (0, 0, d_a)) = (0, -(zp - d_a), yp) by eq. (7) and dalpha/dtheta1 = 1
/// by eq. (14).
fn condition(m: &Machine, pose: &ModulePose, rho: &Vector3<f64>) -> f64 {
    let a = jacobian_pose(&m.module, pose, rho);
    let b = jacobian_sliders(&m.module, pose, rho);
    let d = Vector4::new(0.0, -(pose.p.z - m.table.d_a), pose.p.y, 1.0);
    let mut j = Matrix4::zeros();
    j.set_column(0, &(a * d));
    for k in 0..3 {
        j.set_column(k + 1, &b.column(k));
    }
    let cond = |sv: Vector4<f64>| sv.max() / sv.min();
    cond(a.svd(false, false).singular_values).max(cond(j.svd(false, false).singular_values))
}

/// The round-trip bound for a branch (mm or rad).
fn bound(m: &Machine, pose: &ModulePose, rho: &Vector3<f64>, working: bool) -> (f64, bool) {
    let c = condition(m, pose, rho);
    if working || c <= 1e6 {
        (ROUND_TRIP_MM.max(ROUND_TRIP_RAD), true)
    } else {
        (ROUND_TRIP_MM.max(c * FORWARD_ERROR_PER_COND_MM), false)
    }
}

fn xyz(v: Vector4<f64>) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

/// eq. (15) at the platform pose reached through the table for a given theta1 (mm^4): the
/// leg-I coupling residual, computed from the matrices above.
fn coupling_residual(m: &Machine, pose: &ToolPose, theta1: f64) -> f64 {
    let g = &m.module;
    let t = b_t_t(m, theta1, -pose.phi2) * t_t_pl(pose);
    let p = t.column(3);
    let alpha = theta1 + pose.phi1;
    let (s, c) = alpha.sin_cos();
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let k1 = g.l1 * g.l1 - (r * r + rr * rr - 2.0 * r * rr * c);
    r * r * s * s * u * u + (rr * rr - 2.0 * r * rr * c + r * r) * p.y * p.y - r * r * s * s * k1
}

/// Whether legs II and III can close (eqs. (12)-(13) real) at the pose reached with theta1.
fn legs_23_real(m: &Machine, pose: &ToolPose, theta1: f64) -> bool {
    let g = &m.module;
    let t = b_t_t(m, theta1, -pose.phi2) * t_t_pl(pose);
    let p = t.column(3);
    let c = (theta1 + pose.phi1).cos();
    let dx = p.x + g.dx2;
    let a2 = g.l2 * g.l2 - dx * dx - (p.y - g.r_big2 * c + g.r4).powi(2);
    let a3 = g.l3 * g.l3 - dx * dx - (p.y + g.r_big2 * c - g.r4).powi(2);
    a2 >= 0.0 && a3 >= 0.0
}

/// A deterministic pseudo-random sequence in [0, 1) (xorshift64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn eq26_matches_the_transforms_and_eqs_9_14_close_the_loop() {
    let m = Machine::default_verne();
    let mut rng = Rng(7);
    for _ in 0..2000 {
        let module = ModulePose {
            p: Vector3::new(
                rng.next() * 800.0 - 400.0,
                rng.next() * 800.0 - 400.0,
                800.0 + rng.next() * 500.0,
            ),
            alpha: rng.next() * TAU - PI,
        };
        let theta1 = rng.next() * TAU - PI;
        let theta2 = rng.next() * 4.0 * PI - TAU;
        // eq. (25): tU = bT_t^-1 bT_pl (0, 0, Delta, 1).
        let expected = xyz(b_t_t(&m, theta1, theta2).try_inverse().unwrap()
            * b_t_pl(&module)
            * Vector4::new(0.0, 0.0, DELTA, 1.0));
        let got = tool_pose_eq26(&m.table, &module, theta1, theta2, DELTA);
        assert!(
            (got.tip - expected).amax() < SAME_FORMULA_MM,
            "{:?} vs {expected:?}",
            got.tip
        );
        // eqs. (9) and (14): with phi1 = alpha - theta1, phi2 = -theta2, bT_t tT_pl = bT_pl.
        let composed = b_t_t(&m, theta1, theta2) * t_t_pl(&got);
        let direct = b_t_pl(&module);
        assert!(
            (composed - direct).amax() < SAME_FORMULA_MM,
            "{composed} vs {direct}"
        );
    }
}

/// Hand-worked tool-axis example. Table tilted by theta1 = +30 deg, theta2 = 0, platform level
/// (alpha = 0) at P = (-300, 0, 1100) mm (on yp = 0, where alpha = 0 is a module solution).
///
/// By eq. (7) the table's rotation is rot(x, theta1 + pi), so its axes in the base frame are
/// x_t = (1, 0, 0), y_t = (0, -cos t1, -sin t1), z_t = (0, sin t1, -cos t1): at 30 deg the table
/// normal z_t = (0, 1/2, -sqrt3/2) points up (z_b is down) and leans towards +y_b. The tool axis
/// (tip towards spindle) is straight up in the base frame, (0, 0, -1); its components on
/// (x_t, y_t, z_t) are (0, sin t1, cos t1) = (0, 1/2, sqrt3/2): in the workpiece frame the tool
/// leans towards +y_t, by 30 deg. By eq. (8) that is phi1 = -30 deg, phi2 = 0 (the
/// a = (sin phi1 sin phi2, -sin phi1 cos phi2, cos phi1) convention), i.e. phi1 = alpha - theta1.
///
/// Tip: U_b = P + Delta (0, 0, 1) = (-300, 0, 1150). The table origin is
/// O_t = (0, 0, d_a) + rot(x, t1) (0, 0, d_t) = (0, -d_t sin t1, d_a + d_t cos t1)
/// = (0, 150 s, 1400 - 150 c). U_b - O_t = (-300, -150 s, -250 + 150 c); on y_t:
/// 150 s c + 250 s - 150 s c = 250 s = 125; on z_t: -150 s^2 + 250 c - 150 c^2 = 250 c - 150.
/// (U lies 250 mm above the tilting axis, the table top 150 mm above it.)
#[test]
fn tool_axis_convention_worked_by_hand() {
    let m = Machine::default_verne();
    // Working joints of P = (-300, 0, 1100), alpha = 0 (docs/reference table).
    let rho = Vector3::new(520.690065682, 228.944160917, 228.769607739);
    let theta1 = FRAC_PI_6;
    let modes = machine_fk(&m, &rho, theta1, 0.0, DELTA);
    let mode = modes
        .iter()
        .find(|md| md.module.alpha.abs() < 1e-6)
        .expect("the alpha = 0 assembly mode");
    let (s, c) = (0.5, 3f64.sqrt() / 2.0);
    let axis = Vector3::new(0.0, s, c);
    assert!((mode.axis - axis).amax() < 1e-9, "{:?}", mode.axis);
    assert!(
        (mode.tool.phi1 + FRAC_PI_6).abs() < 1e-6,
        "{}",
        mode.tool.phi1
    );
    assert!(mode.tool.phi2.abs() < 1e-12);
    let tip = Vector3::new(-300.0, 250.0 * s, 250.0 * c - 150.0);
    assert!(
        (mode.tool.tip - tip).amax() < 1e-5,
        "{:?} vs {tip:?}",
        mode.tool.tip
    );
    assert!(mode.working(), "{}", mode.verdict);
    // And the library's axis formula agrees with the hand result.
    assert!((tool_axis(-FRAC_PI_6, 0.0) - axis).amax() < 1e-15);
    // Tilting about theta2 by +90 deg turns the workpiece: the same axis, seen from R_t rotated
    // by rot(z, theta2), has azimuth phi2 = -90 deg: a = (sin(-30) sin(-90), ...) = (1/2, 0, c).
    let modes = machine_fk(&m, &rho, theta1, PI / 2.0, DELTA);
    let mode = modes
        .iter()
        .find(|md| md.module.alpha.abs() < 1e-6)
        .unwrap();
    assert!(
        (mode.axis - Vector3::new(0.5, 0.0, c)).amax() < 1e-9,
        "{:?}",
        mode.axis
    );
}

/// The grid of tool poses of the round-trip test: 15 x 15 x 4 tips, 3 tilts, 5 azimuths.
fn pose_grid() -> Vec<ToolPose> {
    let mut out = Vec::new();
    for ix in 0..15 {
        for iy in 0..15 {
            for iz in 0..4 {
                for &phi1 in &[-0.35, 0.0, 0.2] {
                    for k in 0..5 {
                        out.push(ToolPose {
                            tip: Vector3::new(
                                -280.0 + 38.0 * ix as f64,
                                -270.0 + 37.0 * iy as f64,
                                -40.0 + 55.0 * iz as f64,
                            ),
                            phi1,
                            phi2: -3.0 + 1.37 * k as f64,
                        });
                    }
                }
            }
        }
    }
    out
}

/// Branches in the documented order: by theta1, then by configuration.
fn assert_ordered(ik: &[verne::machine::MachineIkBranch], pose: &ToolPose) {
    for w in ik.windows(2) {
        let order = w[0]
            .theta1
            .total_cmp(&w[1].theta1)
            .then(w[0].config.cmp(&w[1].config));
        assert!(order.is_le(), "{pose:?}: {:?} before {:?}", w[0], w[1]);
    }
}

#[test]
fn fk_of_every_ik_branch_returns_the_pose() {
    let m = Machine::default_verne();
    let grid = pose_grid();
    let mut with_working = 0;
    let mut branches = 0;
    let mut worst_mm = 0.0f64;
    let mut worst_rad = 0.0f64;
    let mut ill_conditioned = 0;
    for pose in &grid {
        let ik = machine_ik(&m, pose, DELTA);
        assert_ordered(&ik, pose);
        if ik.iter().any(|b| b.working()) {
            with_working += 1;
        }
        for b in &ik {
            branches += 1;
            assert!((b.theta2 - wrap_angle(-pose.phi2)).abs() < 1e-15);
            let fk = machine_fk(&m, &b.rho, b.theta1, b.theta2, DELTA);
            let best = fk
                .iter()
                .map(|md| {
                    let mm = (md.tool.tip - pose.tip).amax();
                    let rad = wrap_angle(md.tool.phi1 - pose.phi1)
                        .abs()
                        .max(wrap_angle(md.tool.phi2 - pose.phi2).abs());
                    (mm, rad)
                })
                .min_by(|a, b| (a.0 + a.1).total_cmp(&(b.0 + b.1)));
            let Some((mm, rad)) = best else {
                panic!("no assembly mode for {b:?} of {pose:?}");
            };
            let module = ModulePose {
                p: b.platform,
                alpha: b.alpha,
            };
            let (tol, strict) = bound(&m, &module, &b.rho, b.working());
            if strict {
                worst_mm = worst_mm.max(mm);
                worst_rad = worst_rad.max(rad);
            } else {
                ill_conditioned += 1;
            }
            assert!(
                mm < tol && rad < tol,
                "{pose:?} branch {b:?}: off by {mm} mm, {rad} rad (bound {tol})"
            );
        }
    }
    assert!(
        with_working >= 10_000,
        "only {with_working} poses in the workspace"
    );
    eprintln!(
        "{} poses ({with_working} with a working branch), {branches} branches, worst {worst_mm:e} mm {worst_rad:e} rad; {ill_conditioned} branches with condition > 1e6",
        grid.len()
    );
}

#[test]
fn ik_of_every_fk_mode_contains_the_joints() {
    let m = Machine::default_verne();
    let mut modes_checked = 0;
    let mut worst = 0.0f64;
    let mut ill_conditioned = 0;
    for i1 in 0..9 {
        for i2 in 0..9 {
            for i3 in 0..9 {
                let rho = Vector3::new(
                    150.0 + 110.0 * i1 as f64,
                    120.0 + 105.0 * i2 as f64,
                    130.0 + 100.0 * i3 as f64,
                );
                for &(theta1, theta2) in &[(-0.6, 2.5), (0.0, 0.0), (0.35, -1.0), (0.7, 4.0)] {
                    for md in machine_fk(&m, &rho, theta1, theta2, DELTA) {
                        modes_checked += 1;
                        let ik = machine_ik(&m, &md.tool, DELTA);
                        let d = ik
                            .iter()
                            .map(|b| {
                                ((b.rho - rho).amax())
                                    .max(wrap_angle(b.theta1 - theta1).abs())
                                    .max(wrap_angle(b.theta2 - theta2).abs())
                            })
                            .fold(f64::INFINITY, f64::min);
                        let (tol, strict) = bound(&m, &md.module, &rho, md.working());
                        if strict {
                            worst = worst.max(d);
                        } else {
                            ill_conditioned += 1;
                        }
                        assert!(
                            d < tol,
                            "rho {rho:?}, theta {theta1} {theta2}, mode {md:?}: nearest branch off by {d}"
                        );
                    }
                }
            }
        }
    }
    assert!(modes_checked > 3000, "{modes_checked}");
    eprintln!(
        "{modes_checked} assembly modes, worst {worst:e}; {ill_conditioned} with condition > 1e6"
    );
}

/// The roots of the theta1 equation against a dense scan of eq. (15) computed from the
/// transforms, with bisection: same count, same places; and every root where legs II and III
/// close is a branch of the inverse kinematics. Poses drawn over a box much larger than the
/// workspace, so that four- and six-root cases occur.
#[test]
fn theta1_roots_match_a_dense_scan() {
    const SCAN: usize = 20_000;
    let m = Machine::default_verne();
    let mut rng = Rng(99);
    let mut histogram = [0usize; 7];
    for _ in 0..1500 {
        let pose = ToolPose {
            tip: Vector3::new(
                rng.next() * 2000.0 - 1000.0,
                rng.next() * 2000.0 - 1000.0,
                rng.next() * 2000.0 - 1000.0,
            ),
            phi1: rng.next() * TAU - PI,
            phi2: rng.next() * TAU - PI,
        };
        // Scan and bisect.
        let f = |t: f64| coupling_residual(&m, &pose, t);
        let mut scan_roots = Vec::new();
        let mut a = -PI;
        let mut fa = f(a);
        for i in 1..=SCAN {
            let b = -PI + TAU * i as f64 / SCAN as f64;
            let fb = f(b);
            if (fa < 0.0) != (fb < 0.0) {
                let (mut lo, mut hi, mut flo) = (a, b, fa);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let fm = f(mid);
                    if (fm < 0.0) == (flo < 0.0) {
                        lo = mid;
                        flo = fm;
                    } else {
                        hi = mid;
                    }
                }
                scan_roots.push(0.5 * (lo + hi));
            }
            a = b;
            fa = fb;
        }
        histogram[scan_roots.len().min(6)] += 1;
        // The library's polynomial agrees with eq. (15) pointwise, to rounding of its size.
        let trig = theta1_equation(&m, &pose, DELTA);
        let samples: Vec<f64> = (0..16).map(|k| -PI + TAU * k as f64 / 16.0).collect();
        let size = samples.iter().fold(0.0f64, |acc, &t| acc.max(f(t).abs()));
        for &t in &samples {
            assert!(
                (trig.eval(t) - f(t)).abs() <= 1e-10 * size,
                "{pose:?} at {t}"
            );
        }
        let ik = machine_ik(&m, &pose, DELTA);
        for &r in &scan_roots {
            if legs_23_real(&m, &pose, r) {
                assert!(
                    ik.iter().any(|b| wrap_angle(b.theta1 - r).abs() < 1e-7),
                    "{pose:?}: scan root {r} missing from {:?}",
                    ik.iter().map(|b| b.theta1).collect::<Vec<_>>()
                );
            }
        }
        for b in &ik {
            assert!(
                scan_roots
                    .iter()
                    .any(|&r| wrap_angle(b.theta1 - r).abs() < 1e-7),
                "{pose:?}: branch theta1 {} is no scan root {scan_roots:?}",
                b.theta1
            );
        }
    }
    eprintln!("scan root counts 0..6: {histogram:?}");
    assert!(histogram[6] > 0, "no six-root pose drawn: {histogram:?}");
}

/// The double root of F at sin(alpha) = 0: a vertical tool over the table's centre line at
/// theta2 = 0 reaches alpha = theta1 = 0 with both signs of rho1 - zp. The scan cannot see it (F
/// does not change sign); both postures must be found.
#[test]
fn double_root_at_alpha_zero_gives_both_leg1_postures() {
    let m = Machine::default_verne();
    let pose = ToolPose {
        tip: Vector3::new(-120.0, 0.0, 40.0),
        phi1: 0.0,
        phi2: 0.0,
    };
    let ik = machine_ik(&m, &pose, DELTA);
    let at_zero: Vec<_> = ik.iter().filter(|b| b.theta1.abs() < 1e-12).collect();
    assert_eq!(at_zero.len(), 8, "{ik:?}");
    let working: Vec<_> = ik.iter().filter(|b| b.working()).collect();
    assert_eq!(working.len(), 1);
    // Independent: at theta1 = 0 the platform is straight above the tip: P_b = (x, -y, d_a + d_t
    // - z - Delta) by eqs. (7)-(8) (rot(x, pi) flips y and z), and rho1 = zp -/+ sqrt(K1 - u^2).
    let g = &m.module;
    let p = Vector3::new(-120.0, 0.0, 1400.0 - 150.0 - 40.0 - DELTA);
    let k1 = g.l1 * g.l1 - (g.r_big1 - g.r_small1).powi(2);
    let h = (k1 - (p.x + g.dx1).powi(2)).sqrt();
    assert!((working[0].rho.x - (p.z - h)).abs() < 1e-9);
    assert!(at_zero.iter().any(|b| (b.rho.x - (p.z + h)).abs() < 1e-9));
    assert!((working[0].platform - p).amax() < 1e-9);
}

/// Near the double roots at sin(alpha) = 0 (F = yp^2 (R1 -/+ r1)^2 there, zero iff yp = 0): tilted
/// tools whose tip puts yp at those angles at 0 or a little off it. Either F has a double root
/// there (both signs of rho1 - zp) or two simple roots close by (one posture each): two leg-I
/// postures near each such angle whenever leg I reaches it, and each is a solution of the
/// unsquared leg-I pair at its own theta1.
#[test]
fn near_double_roots_at_alpha_zero_keep_both_postures() {
    let m = Machine::default_verne();
    let d_t = m.table.d_t;
    let mut near = 0;
    for phi1 in [0.1f64, 0.3, -0.2] {
        for (x, z) in [(-120.0, 0.0), (-60.0, 40.0), (0.0, 120.0)] {
            // yp(theta1 = -phi1) = 0 (and yp(pi - phi1) = 0: it is its negative).
            let y0 = DELTA * phi1.sin() + phi1.tan() * (d_t - z - DELTA * phi1.cos());
            for eps in [0.0, 1e-12, -1e-9, 1e-6, -1e-3, 0.03, 1.0] {
                let pose = ToolPose {
                    tip: Vector3::new(x, y0 + eps, z),
                    phi1,
                    phi2: 0.0,
                };
                let ik = machine_ik(&m, &pose, DELTA);
                assert_ordered(&ik, &pose);
                for th in [-phi1, PI - phi1] {
                    let mut rho1: Vec<f64> = ik
                        .iter()
                        .filter(|b| wrap_angle(b.theta1 - th).abs() < 0.05)
                        .map(|b| b.rho.x)
                        .collect();
                    rho1.sort_by(f64::total_cmp);
                    rho1.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
                    if !rho1.is_empty() {
                        near += 1;
                        assert_eq!(rho1.len(), 2, "{pose:?} near theta1 = {th}: {rho1:?}");
                    }
                }
            }
        }
    }
    assert!(near > 20, "too few reachable cases: {near}");
}

/// A path whose tool axis sweeps through the table normal in the y-z plane, then circles it at a
/// small tilt: theta2 must not jump by a turn (or half a turn), the singular rows are flagged,
/// and the tip is always reached.
#[test]
fn path_through_the_rotary_singularity() {
    let m = Machine::default_verne();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let mut prev: Option<(f64, f64)> = None;
    let mut flagged = 0;
    // Sweep: tilt gamma from +20 deg to -20 deg through exactly 0 and through tiny tilts.
    let mut gammas: Vec<f64> = (0..=40).map(|k| (20.0 - k as f64).to_radians()).collect();
    gammas.insert(20, 5e-7);
    gammas.insert(22, -3e-7);
    // Back to a -1e-3 rad tilt, then circle the normal at that tilt, a full turn and a bit.
    gammas.extend((1..20).map(|k| (-20.0 + k as f64).to_radians()));
    let circle: Vec<f64> = (0..=90).map(|k| k as f64 * 4.5f64.to_radians()).collect();
    let mut rows = 0;
    for (i, step) in gammas
        .iter()
        .map(|&g| (g, 0.0))
        .chain(circle.iter().map(|&az| (-1e-3, az)))
        .enumerate()
    {
        let (gamma, az) = step;
        // axis tilted by gamma in the plane of azimuth az (az = 0: the y-z plane).
        let axis = Vector3::new(gamma.sin() * az.sin(), gamma.sin() * az.cos(), gamma.cos());
        let tip = Vector3::new(-100.0 + i as f64, 20.0, 60.0);
        let row = state
            .next_row(&m, &tip, &ToolOrientation::Axis(axis), DELTA)
            .unwrap_or_else(|e| panic!("row {i}: {e}"));
        rows += 1;
        let singular = gamma.abs() < ROTARY_SINGULAR_CONE_RAD;
        assert_eq!(row.near_rotary_singularity, singular, "row {i}");
        if singular {
            flagged += 1;
            assert_eq!(Some(row.theta2), prev.map(|p| p.1), "row {i} keeps theta2");
        }
        assert!(!row.switched, "row {i}");
        // The achieved axis is the requested one (within the cone on singular rows).
        let got = tool_axis(row.angles.phi1, row.angles.phi2);
        assert!(
            (got - axis).norm() < 2.0 * ROTARY_SINGULAR_CONE_RAD,
            "row {i}: {got:?} vs {axis:?}"
        );
        // FK of the chosen joints gives the tip and the axis back.
        let fk = machine_fk(&m, &row.rho, row.theta1, row.theta2, DELTA);
        assert!(fk.iter().any(|md| md.working()
            && (md.tool.tip - tip).amax() < 1e-9
            && (md.axis - got).amax() < 1e-9));
        if let Some((t1, t2)) = prev {
            assert!(
                (row.theta2 - t2).abs() < 0.2,
                "row {i}: theta2 {t2} -> {}",
                row.theta2
            );
            assert!(
                (row.theta1 - t1).abs() < 0.05,
                "row {i}: theta1 {t1} -> {}",
                row.theta1
            );
        }
        prev = Some((row.theta1, row.theta2));
    }
    assert_eq!(flagged, 3);
    assert_eq!(rows, gammas.len() + circle.len());
    // After a full circle and a bit, theta2 has turned by a whole turn, unwrapped.
    let last = state.previous().unwrap();
    assert!(
        last.theta2.abs() > 5.0,
        "theta2 not unwrapped: {}",
        last.theta2
    );
}

#[test]
fn first_row_preference_and_unreachable_rows() {
    let m = Machine::default_verne();
    let axis = Vector3::new(0.0, 0.2f64.sin(), 0.2f64.cos());
    let tip = Vector3::new(-50.0, 10.0, 50.0);
    let o = ToolOrientation::Axis(axis);
    let r1 = PathState::new(FirstRowChoice::Orientation1)
        .next_row(&m, &tip, &o, DELTA)
        .unwrap();
    let r2 = PathState::new(FirstRowChoice::Orientation2)
        .next_row(&m, &tip, &o, DELTA)
        .unwrap();
    let r0 = PathState::new(FirstRowChoice::SmallestTheta1)
        .next_row(&m, &tip, &o, DELTA)
        .unwrap();
    assert_eq!((r1.orientation, r2.orientation), (1, 2));
    assert!((r1.theta2 - r2.theta2).abs() > 3.0);
    assert!(r0.theta1.abs() <= r1.theta1.abs().min(r2.theta1.abs()));
    // Far outside the workspace: an error that names the failing limits, state unchanged.
    let mut st = PathState::default();
    st.next_row(&m, &tip, &o, DELTA).unwrap();
    let before = *st.previous().unwrap();
    let far = Vector3::new(-50.0, 10.0, 900.0);
    let err = st.next_row(&m, &far, &o, DELTA).unwrap_err();
    assert!(err.to_string().contains("no working branch"), "{err}");
    assert_eq!(*st.previous().unwrap(), before);
    let bad = st
        .next_row(
            &m,
            &tip,
            &ToolOrientation::Axis(Vector3::new(0.0, 0.0, 3.0)),
            DELTA,
        )
        .unwrap_err();
    assert!(bad.to_string().contains("length 3"), "{bad}");
}

#[test]
fn candidates_refilled_in_place_are_the_fresh_ones() {
    // One set refilled row after row (as `verne ik` keeps one per batch row) gives what a fresh
    // one gives, through an invalid axis, the rotary cone, an unreachable tip and given angles.
    let m = Machine::default_verne();
    let tip = Vector3::new(-50.0, 10.0, 50.0);
    let rows = [
        (
            tip,
            ToolOrientation::Axis(Vector3::new(0.0, 0.2f64.sin(), 0.2f64.cos())),
        ),
        (tip, ToolOrientation::Axis(Vector3::new(0.0, 0.0, 3.0))),
        (tip, ToolOrientation::Axis(Vector3::new(1e-7, 0.0, 1.0))),
        (
            Vector3::new(-50.0, 10.0, 900.0),
            ToolOrientation::Axis(Vector3::z()),
        ),
        (
            tip,
            ToolOrientation::Angles(verne::machine::orientation::ToolAngles {
                phi1: 0.3,
                phi2: -1.2,
            }),
        ),
        (tip, ToolOrientation::Axis(Vector3::new(0.3, -0.1, 0.9))),
    ];
    let mut reused = PathCandidates::default();
    for prev_theta2 in [None, Some(2.5)] {
        for (tip, o) in &rows {
            let fresh = path_candidates(&m, tip, o, DELTA, prev_theta2);
            let refilled = path_candidates_into(&m, tip, o, DELTA, prev_theta2, &mut reused);
            match (fresh, refilled) {
                (Ok(f), Ok(())) => {
                    assert_eq!(f.needs_previous(), reused.needs_previous());
                    assert!(f.iter().eq(reused.iter()), "{tip:?} {o:?}");
                }
                (Err(f), Err(r)) => {
                    assert_eq!(f.to_string(), r.to_string());
                    assert!(reused.is_empty());
                }
                (f, r) => panic!("{tip:?} {o:?}: fresh {:?}, refilled {r:?}", f.err()),
            }
        }
    }
}

/// Joints or a tool length that are not finite give no assembly mode (not a mode with a NaN
/// tool pose), whichever of them it is.
#[test]
fn non_finite_joints_give_no_mode() {
    let m = Machine::default_verne();
    let rho = Vector3::new(520.690065682, 228.944160917, 228.769607739);
    assert!(!machine_fk(&m, &rho, FRAC_PI_6, 0.0, DELTA).is_empty());
    for bad in [f64::NAN, f64::INFINITY] {
        assert!(
            machine_fk(&m, &rho, bad, 0.0, DELTA).is_empty(),
            "theta1 {bad}"
        );
        assert!(
            machine_fk(&m, &rho, FRAC_PI_6, bad, DELTA).is_empty(),
            "theta2 {bad}"
        );
        assert!(
            machine_fk(&m, &rho, FRAC_PI_6, 0.0, bad).is_empty(),
            "tool length {bad}"
        );
    }
}

mod continuation_walk;

/// The continuation answers as the complete solve's choice does (the branch, its joints within
/// `SAME_JOINTS`, the verdicts of the limits and of the singularity thresholds), fallbacks
/// included, on random walks: 200,000 poses at a servo period's steps in the workspace, 20,000
/// at steps a hundred times larger, and 50,000 at a servo period's steps across the
/// workspace's boundary (unreachable poses, limits); and it answers almost every servo step in
/// the workspace alone. The walks of a million poses: `examples/continuation_walk.rs`
/// (docs/benchmarks.md).
#[test]
fn the_continuation_is_the_complete_solve_s_choice_on_random_walks() {
    use continuation_walk::{ACROSS, SERVO_STEP, WORKSPACE, walk};
    let m = Machine::default_verne();
    for (n, region, step, seed) in [
        (200_000, WORKSPACE, SERVO_STEP, 0x3a1c_0000_0000_0001),
        (
            20_000,
            WORKSPACE,
            SERVO_STEP.times(100.0),
            0x3a1c_0000_0000_0002,
        ),
        (50_000, ACROSS, SERVO_STEP, 0x3a1c_0000_0000_0003),
    ] {
        let w = walk(&m, n, region, step, seed);
        println!("{region:?} {step:?}: {w:?}");
        assert_eq!(w.different, 0, "{:#?}", w.differences);
        assert!(w.continued + w.fallbacks.iter().sum::<u64>() == n);
        if region.tilt_deg == WORKSPACE.tilt_deg && step.tip_mm == SERVO_STEP.tip_mm {
            // Nearly every servo step in the workspace is proved alone.
            assert!(w.continued as f64 >= 0.99 * n as f64, "{w:?}");
        }
        if region.tilt_deg == ACROSS.tilt_deg {
            // The walk does leave the workspace.
            assert!(w.no_branch.iter().sum::<u64>() > 0, "{w:?}");
        }
    }
}
