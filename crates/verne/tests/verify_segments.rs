//! `verne::verify`'s segment checks through the library, without the CLI (as `verify_rows.rs`
//! does for the row checks): the first rows of data/verify and paths built with the library's
//! inverse kinematics, each changed to break one segment check by a known amount; every
//! finding's check, row, value and limit asserted against a value computed here, and a limit
//! one step away asserted to find nothing. Segment findings are placed on the row that ends the
//! segment (1-based). So `cargo mutants -f crates/verne/src/verify/segment.rs` measures the
//! segment checks with the core crate's tests.

mod verify_data;

use std::f64::consts::PI;

use nalgebra::Vector3;
use verify_data::*;
use verne::machine::orientation::{AxisAngles, ToolOrientation, axis_angles};
use verne::machine::{FirstRowChoice, PathState, ToolPose, machine_fk, machine_ik};
use verne::parallel_module::branches::{WORKING_CONFIG, config_of};
use verne::parallel_module::equations::{ModulePose, Sliders, polish_pose, rod_tilts};
use verne::parallel_module::fk;
use verne::parallel_module::ik::wrap_angle;
use verne::parallel_module::kinetostatics::kinetostatics;
use verne::spec::Machine;
use verne::verify::{
    Check, JOINT_NAMES, Joints, PathPoint, SEGMENT_SAMPLE_MM, Summary, Th, Thresholds, Violation,
};

fn thresholds(set: &[(&str, f64)]) -> Thresholds {
    let mut th = Thresholds::default();
    for (name, value) in set {
        th.set(name, *value).unwrap();
    }
    th
}

/// A joint's value as verify compares it: mm for the sliders, degrees for the table's axes.
fn shown(i: usize, rad_or_mm: f64) -> f64 {
    if i < 3 {
        rad_or_mm
    } else {
        rad_or_mm.to_degrees()
    }
}

/// The changes of joint `i` along the segments (k: the segment from row k to row k + 1,
/// 0-based), signed, in mm or rad.
fn change(joints: &[Joints], i: usize) -> Vec<f64> {
    let get = |q: &Joints| [q.rho.x, q.rho.y, q.rho.z, q.theta1, q.theta2][i];
    joints.windows(2).map(|w| get(&w[1]) - get(&w[0])).collect()
}

/// The two largest of (segment, joint, value) over the joints `group`: a limit between them
/// is broken by exactly one joint of one segment.
fn two_largest(
    per_segment: impl Fn(usize) -> Vec<f64>,
    group: &[usize],
) -> [(usize, usize, f64); 2] {
    let mut all: Vec<(usize, usize, f64)> = group
        .iter()
        .flat_map(|&i| {
            per_segment(i)
                .into_iter()
                .enumerate()
                .map(move |(k, v)| (k, i, v))
        })
        .collect();
    all.sort_by(|a, b| b.2.total_cmp(&a.2));
    assert!(all[0].2 > all[1].2, "{:?}", &all[..2]);
    [all[0], all[1]]
}

/// The only finding of `check`: on row `row`, with `value` and `limit` (to 1e-12).
fn the_one_finding(
    found: &[Violation],
    check: Check,
    row: usize,
    value: f64,
    limit: f64,
) -> &Violation {
    let of_check = of(found, check);
    assert_eq!(of_check.len(), 1, "{check:?}: {found:?}");
    let v = of_check[0];
    assert_eq!(v.row, row.to_string(), "{v:?}");
    assert!((v.value - value).abs() <= 1e-12 * value, "{v:?} vs {value}");
    assert!((v.limit - limit).abs() <= 1e-12 * limit, "{v:?} vs {limit}");
    v
}

/// The joint groups of the step and speed thresholds (one threshold for the three sliders).
const GROUPS: [&[usize]; 3] = [&[0, 1, 2], &[3], &[4]];

#[test]
fn the_largest_joint_change_is_a_jump_above_its_limit() {
    let m = Machine::default_verne();
    let (joints, path) = clean();
    for (group, name) in GROUPS
        .iter()
        .zip(["rho_step_mm", "theta1_step_deg", "theta2_step_deg"])
    {
        let per_segment = |i: usize| -> Vec<f64> {
            change(&joints, i)
                .iter()
                .map(|d| shown(i, d.abs()))
                .collect()
        };
        let [(k, i, top), (_, _, next)] = two_largest(per_segment, group);
        let limit = 0.5 * (top + next);
        // The slider speeds are limited to nothing too: every segment is a velocity finding
        // but the one that jumped (its speed is the jump's finding; its chord and limits are
        // still measured).
        let th = thresholds(&[(name, limit), ("rho_velocity_mm_s", 1e-9)]);
        let (_, found) = run(&m, &th, oks(&joints), path.clone());
        let v = the_one_finding(&found, Check::JointJump, k + 2, top, limit);
        let signed = shown(i, change(&joints, i)[k]);
        assert!(
            v.detail
                .contains(&format!("{} changes by {signed:+.4}", JOINT_NAMES[i])),
            "{name}: {}",
            v.detail
        );
        let velocity_rows: Vec<&str> = of(&found, Check::Velocity)
            .iter()
            .map(|v| v.row.as_str())
            .collect();
        assert!(!velocity_rows.contains(&v.row.as_str()), "{name}");
        for r in 2..=ROWS {
            assert!(
                r == k + 2 || velocity_rows.contains(&r.to_string().as_str()),
                "{name}: row {r}"
            );
        }
        // The limit at the largest change: nothing.
        let th = thresholds(&[(name, top)]);
        assert!(
            of(
                &run(&m, &th, oks(&joints), path.clone()).1,
                Check::JointJump
            )
            .is_empty()
        );
        // A rapid move to the segment's end row (said by the path or by the joints): no jump.
        let th = thresholds(&[(name, limit)]);
        let mut rapid_path = path.clone();
        rapid_path[k + 1].rapid = true;
        assert!(of(&run(&m, &th, oks(&joints), rapid_path).1, Check::JointJump).is_empty());
        let mut rapid_joints = joints.clone();
        rapid_joints[k + 1].rapid = true;
        assert!(
            of(
                &run(&m, &th, oks(&rapid_joints), path.clone()).1,
                Check::JointJump
            )
            .is_empty()
        );
    }
}

/// Each joint's speed on each segment from the table's `t`, in mm/s or deg/s.
fn speeds(joints: &[Joints], i: usize) -> Vec<f64> {
    change(joints, i)
        .iter()
        .zip(joints.windows(2))
        .map(|(d, w)| shown(i, (d / (w[1].t.unwrap() - w[0].t.unwrap())).abs()))
        .collect()
}

#[test]
fn the_fastest_joint_is_a_velocity_finding_above_its_limit() {
    let m = Machine::default_verne();
    let (joints, path) = clean();
    for (group, name) in GROUPS.iter().zip([
        "rho_velocity_mm_s",
        "theta1_velocity_deg_s",
        "theta2_velocity_deg_s",
    ]) {
        let [(k, i, top), (_, _, next)] = two_largest(|i| speeds(&joints, i), group);
        let limit = 0.5 * (top + next);
        let (_, found) = run(
            &m,
            &thresholds(&[(name, limit)]),
            oks(&joints),
            path.clone(),
        );
        let v = the_one_finding(&found, Check::Velocity, k + 2, top, limit);
        let dt = joints[k + 1].t.unwrap() - joints[k].t.unwrap();
        assert!(
            v.detail.contains(JOINT_NAMES[i]) && v.detail.contains(&format!("(dt = {dt:.6} s)")),
            "{name}: {}",
            v.detail
        );
        let (_, found) = run(&m, &thresholds(&[(name, top)]), oks(&joints), path.clone());
        assert!(of(&found, Check::Velocity).is_empty(), "{name}: {found:?}");
    }
}

#[test]
fn a_time_that_does_not_increase_is_a_velocity_finding() {
    let m = Machine::default_verne();
    let (mut joints, path) = clean();
    // Row 11 at row 10's time, row 21 0.01 s before row 20's.
    joints[10].t = joints[9].t;
    joints[20].t = Some(joints[19].t.unwrap() - 0.01);
    let (_, found) = run(&m, &Thresholds::default(), oks(&joints), path);
    let v = of(&found, Check::Velocity);
    assert_eq!(v.len(), 2, "{found:?}");
    assert_eq!((v[0].row.as_str(), v[0].value), ("11", 0.0));
    assert!(
        v[0].detail.contains("t does not increase (dt = 0 s)"),
        "{}",
        v[0].detail
    );
    assert_eq!(v[1].row, "21");
    assert!((v[1].value + 0.01).abs() < 1e-12, "{:?}", v[1]);
    assert!(v[0].limit.is_nan() && v[1].limit.is_nan());
}

/// The time of a segment when the joint table has no `t`: the joints' own duration, else the
/// path's, else the path's length over its feed; none for a rapid move or a feed that is not
/// positive.
#[test]
fn without_t_the_segment_time_comes_from_durations_then_the_feed() {
    let m = Machine::default_verne();
    let (mut joints, mut path) = clean();
    for q in &mut joints {
        q.t = None;
    }
    let speed_findings = |found: &[Violation]| -> Vec<(String, f64)> {
        of(found, Check::Velocity)
            .iter()
            .map(|v| (v.row.clone(), v.value))
            .collect()
    };
    // A feed on the path: dt = |tip_b - tip_a| / feed. The fastest slider at those times, and
    // a slider speed limit between it and the next.
    let feed = 10.0;
    for p in &mut path {
        p.feed = Some(feed);
    }
    let dt: Vec<f64> = path
        .windows(2)
        .map(|w| (w[1].tip - w[0].tip).norm() / feed)
        .collect();
    let per_segment = |i: usize| -> Vec<f64> {
        change(&joints, i)
            .iter()
            .zip(&dt)
            .map(|(d, t)| (d / t).abs())
            .collect()
    };
    let [(k, _, top), (_, _, next)] = two_largest(per_segment, GROUPS[0]);
    let th = thresholds(&[("rho_velocity_mm_s", 0.5 * (top + next))]);
    let found = run(&m, &th, oks(&joints), path.clone()).1;
    let v = speed_findings(&found);
    assert_eq!(v.len(), 1, "{found:?}");
    assert_eq!(v[0].0, (k + 2).to_string());
    assert!((v[0].1 - top).abs() <= 1e-9 * top, "{v:?} vs {top}");
    // A feed that is zero or negative gives no time: on that segment alone, nothing is
    // measured (a zero feed's infinite time would measure a speed of 0).
    for bad in [0.0, -10.0] {
        let mut p = path.clone();
        p[k + 1].feed = Some(bad);
        assert!(
            speed_findings(&run(&m, &th, oks(&joints), p.clone()).1).is_empty(),
            "{bad}"
        );
        let (summary, found) = run(&m, &th, oks(&joints[k..k + 2]), p[k..k + 2].to_vec());
        assert!(found.is_empty(), "{bad}: {found:?}");
        let stats = stats(&summary, Check::Velocity);
        assert!(stats.worst.is_none(), "{bad}: {stats:?}");
    }
    // Durations come before the feed: the joints' (0.5 s: too slow to break the limit) before
    // the path's (1e-4 s: far too fast).
    let mut p = path.clone();
    p[k + 1].duration = Some(1e-4);
    let found = run(&m, &th, oks(&joints), p.clone()).1;
    assert!(
        speed_findings(&found)
            .iter()
            .any(|(r, _)| *r == (k + 2).to_string())
    );
    let mut q = joints.clone();
    q[k + 1].duration = Some(0.5);
    let found = run(&m, &th, oks(&q), p.clone()).1;
    assert!(speed_findings(&found).is_empty(), "{found:?}");
    // A rapid move has no programmed time: none of them counts.
    q[k + 1].duration = Some(1e-4);
    p[k + 1].rapid = true;
    let found = run(&m, &th, oks(&q), p).1;
    assert!(speed_findings(&found).is_empty(), "{found:?}");
}

/// The tool tip of the joints at fraction `s` of a segment, in the assembly mode of the
/// working configuration nearest `near` (the complete forward kinematics, no tracking).
fn tip_at(m: &Machine, a: &Joints, b: &Joints, s: f64, near: &Vector3<f64>) -> Vector3<f64> {
    let rho = a.rho + (b.rho - a.rho) * s;
    let q1 = a.theta1 + (b.theta1 - a.theta1) * s;
    let q2 = a.theta2 + (b.theta2 - a.theta2) * s;
    machine_fk(m, &rho, q1, q2, m.tool_length)
        .iter()
        .filter(|md| md.config == WORKING_CONFIG)
        .map(|md| md.tool.tip)
        .min_by(|x, y| (x - near).norm().total_cmp(&(y - near).norm()))
        .unwrap()
}

/// The chordal error is the largest distance, over the segment, of the interpolated joints' tip
/// from the intended tip at the same fraction (the line, travelled uniformly): within a
/// thousandth of an independent dense scan (400 points, the complete forward kinematics).
#[test]
fn the_chordal_error_is_the_largest_tip_off_the_intended_move() {
    let m = Machine::default_verne();
    let (joints, path) = clean();
    // The deviation at s, less the ends' own errors interpolated (docs/verify.md).
    let chords: Vec<f64> = (0..ROWS - 1)
        .map(|k| {
            let err = |s: f64| {
                let want = path[k].tip + (path[k + 1].tip - path[k].tip) * s;
                tip_at(&m, &joints[k], &joints[k + 1], s, &want) - want
            };
            let (e0, e1) = (err(0.0), err(1.0));
            (0..=400)
                .map(|i| {
                    let s = i as f64 / 400.0;
                    (err(s) - (e0 * (1.0 - s) + e1 * s)).norm()
                })
                .fold(0.0, f64::max)
        })
        .collect();
    // A limit of next to nothing: every segment, with its chord.
    let tiny = 1e-300;
    let (_, found) = run(
        &m,
        &thresholds(&[("chord_error_mm", tiny)]),
        oks(&joints),
        path.clone(),
    );
    let found = of(&found, Check::ChordError);
    assert_eq!(found.len(), ROWS - 1, "{found:?}");
    for (v, chord) in found.iter().zip(&chords) {
        assert!(
            v.value >= chord - 1e-9 && v.value <= chord * 1.001 + 1e-9,
            "{v:?} vs {chord}"
        );
        assert_eq!(v.limit, tiny);
    }
    // The largest chord as the limit: nothing; one ulp under it: that segment.
    let (k, _) = chords
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let top = found[k].value;
    assert!(top > 1e-6, "{top}");
    let th = thresholds(&[("chord_error_mm", top)]);
    assert!(
        of(
            &run(&m, &th, oks(&joints), path.clone()).1,
            Check::ChordError
        )
        .is_empty()
    );
    let th = thresholds(&[("chord_error_mm", top.next_down())]);
    let found = run(&m, &th, oks(&joints), path.clone()).1;
    let chord = of(&found, Check::ChordError);
    assert_eq!(chord.len(), 1, "{found:?}");
    assert_eq!(chord[0].row, (k + 2).to_string());
    assert!(chord[0].detail.contains("off the intended move"));
    // A rapid move is not along the line: no chord.
    let mut rapid = path.clone();
    rapid[k + 1].rapid = true;
    assert!(of(&run(&m, &th, oks(&joints), rapid).1, Check::ChordError).is_empty());
}

/// The joints `q` of path point `p` moved to the other orientation solution of its tool pose
/// (another working branch), theta2 unwrapped near `q`'s.
fn other_orientation(m: &Machine, q: &Joints, p: &PathPoint) -> Joints {
    let Ok(AxisAngles::Regular(sols)) = axis_angles(&p.axis) else {
        panic!("a regular axis expected: {p:?}")
    };
    let b = sols
        .iter()
        .flat_map(|a| {
            machine_ik(
                m,
                &ToolPose {
                    tip: p.tip,
                    phi1: a.phi1,
                    phi2: a.phi2,
                },
                m.tool_length,
            )
        })
        .filter(|b| b.working() && (b.theta1 - q.theta1).abs() > 1e-3)
        .min_by(|x, y| x.theta1.abs().total_cmp(&y.theta1.abs()))
        .unwrap();
    Joints {
        rho: b.rho,
        theta1: b.theta1,
        theta2: q.theta2 + wrap_angle(b.theta2 - q.theta2),
        ..*q
    }
}

#[test]
fn a_row_in_the_other_orientation_solution_is_a_branch_change_on_both_segments() {
    let m = Machine::default_verne();
    let (mut joints, path) = clean();
    let k = 14;
    let other = other_orientation(&m, &joints[k], &path[k]);
    assert!(other.theta1 * joints[k].theta1 < 0.0, "{other:?}");
    let turns = [
        wrap_angle(other.theta2 - joints[k - 1].theta2),
        wrap_angle(joints[k + 1].theta2 - other.theta2),
    ];
    joints[k] = other;
    let (_, found) = run(&m, &Thresholds::default(), oks(&joints), path);
    let branch = of(&found, Check::Branch);
    assert_eq!(branch.len(), 2, "{found:?}");
    // The two segments change solution one way and back (which is 1 depends on phi1's sign).
    let way = if branch[0].detail.contains("orientation solution 1 -> 2") {
        ["1 -> 2", "2 -> 1"]
    } else {
        ["2 -> 1", "1 -> 2"]
    };
    for (j, v) in branch.iter().enumerate() {
        assert_eq!(v.row, (k + 1 + j).to_string(), "{v:?}");
        assert!(
            v.detail
                .contains(&format!("orientation solution {}", way[j])),
            "{}",
            v.detail
        );
        assert!(
            (v.value - turns[j].abs().to_degrees()).abs() < 1e-9,
            "{v:?} vs {}",
            turns[j]
        );
        assert_eq!(v.limit, 90.0);
    }
    // A branch change ends the segment's checks: no jump of theta2 (half a turn) reported.
    assert!(of(&found, Check::JointJump).is_empty(), "{found:?}");
}

/// The joints of a tool pose from its axis's first orientation solution, in the working branch
/// whose theta1 is nearest the previous row's (the smallest without one), theta2 unwrapped near
/// the previous row's.
fn joints_for(
    m: &Machine,
    tip: &Vector3<f64>,
    axis: &Vector3<f64>,
    prev: Option<&Joints>,
) -> Joints {
    let Ok(AxisAngles::Regular(sols)) = axis_angles(axis) else {
        panic!("a regular axis expected: {axis:?}")
    };
    let pose = ToolPose {
        tip: *tip,
        phi1: sols[0].phi1,
        phi2: sols[0].phi2,
    };
    let b = machine_ik(m, &pose, m.tool_length)
        .into_iter()
        .filter(|b| b.working())
        .min_by(|x, y| {
            let d = |t: f64| prev.map_or(t.abs(), |p| (t - p.theta1).abs());
            d(x.theta1).total_cmp(&d(y.theta1))
        })
        .unwrap();
    at_rest(
        b.rho,
        b.theta1,
        prev.map_or(b.theta2, |p| p.theta2 + wrap_angle(b.theta2 - p.theta2)),
    )
}

/// A pass whose tool axis crosses the table normal between rows 30 and 31 (gamma from 14.75
/// to -14.75 deg in 0.5 deg steps), the joints of the first orientation solution nearest the
/// previous row, theta2 unwrapped: theta2 turns by half a turn between those rows.
fn through_the_normal(m: &Machine) -> (Vec<Joints>, Vec<PathPoint>) {
    let mut joints: Vec<Joints> = Vec::new();
    let mut path = Vec::new();
    for k in 0..60 {
        let gamma = (14.75 - 0.5 * k as f64).to_radians();
        let tip = Vector3::new(-15.0 + 0.5 * k as f64, 10.0, 40.0);
        let axis = Vector3::new(gamma.sin(), 0.0, gamma.cos());
        joints.push(joints_for(m, &tip, &axis, joints.last()));
        path.push(PathPoint::new(tip, axis));
    }
    (joints, path)
}

#[test]
fn half_a_turn_of_theta2_through_the_table_normal_is_a_flip() {
    let m = Machine::default_verne();
    let (joints, path) = through_the_normal(&m);
    let turn = joints[30].theta2 - joints[29].theta2;
    assert!((turn.abs() - PI).abs() < 1e-9, "{turn}");
    // The flip, and the same with a whole turn more from row 31 on (the turn is taken modulo
    // a full turn).
    for extra in [0.0, 2.0 * PI] {
        let mut q = joints.clone();
        for j in &mut q[30..] {
            j.theta2 += extra.copysign(turn);
        }
        let (_, found) = run(&m, &Thresholds::default(), oks(&q), path.clone());
        assert_eq!(found.len(), 1, "{found:?}");
        let v = &found[0];
        assert_eq!((v.check, v.row.as_str()), (Check::Theta2Flip, "31"));
        let expect = (turn.abs() + extra).to_degrees();
        assert!((v.value - expect).abs() < 1e-9, "{v:?} vs {expect}");
        assert_eq!(
            v.limit,
            Thresholds::default().get(verne::verify::Th::Theta2StepDeg)
        );
    }
    // Row 31's theta2 turned back by 3 deg (its tip and axis moved: the tip, axis and chord
    // limits relaxed), so that the turn is 3 deg short of half a turn: the flip tolerance just
    // above 3 deg finds a flip; just under it, a joint jump of theta2.
    let mut q = joints.clone();
    q[30].theta2 -= 3f64.to_radians().copysign(turn);
    for (tol, check) in [(3.03, Check::Theta2Flip), (2.97, Check::JointJump)] {
        let th = thresholds(&[
            ("theta2_flip_tol_deg", tol),
            ("tip_error_mm", 50.0),
            ("axis_error_deg", 10.0),
            ("chord_error_mm", 100.0),
            ("chord_axis_error_deg", 100.0),
        ]);
        let (_, found) = run(&m, &th, oks(&q), path.clone());
        let at31: Vec<&Violation> = found.iter().filter(|v| v.row == "31").collect();
        assert_eq!(at31.len(), 1, "{tol}: {found:?}");
        assert_eq!(at31[0].check, check, "{tol}: {found:?}");
        assert!((at31[0].value - 177.0).abs() < 1e-9, "{tol}: {found:?}");
    }
}

/// Joints with two assembly modes of the machine's kind (the triple of verify_rows.rs): two
/// rows with these joints whose intended tips are the two modes' tips are each checked in
/// their own mode, and the segment between them, where the joints do not move, arrives in a
/// mode other than the end row's.
#[test]
fn a_segment_that_arrives_in_another_assembly_mode_is_a_branch_change() {
    let m = Machine::default_verne();
    let q = joints_with_two_modes();
    let points: Vec<PathPoint> = modes_of_the_machine_kind(&m, &q)
        .iter()
        .map(|md| PathPoint::new(md.tool.tip, md.axis))
        .collect();
    assert_eq!(points.len(), 2);
    for (a, b, expect) in [(0, 1, true), (1, 0, true), (0, 0, false), (1, 1, false)] {
        let (_, found) = run(
            &m,
            &Thresholds::default(),
            vec![Ok(q), Ok(q)],
            vec![points[a], points[b]],
        );
        // (Near these joints the rods tilt too far and the module is near a singularity: those
        // row findings do not stop a segment's checks.)
        let branch = of(&found, Check::Branch);
        if expect {
            assert_eq!(branch.len(), 1, "{a}{b}: {found:?}");
            let v = branch[0];
            assert_eq!((v.row.as_str(), v.value), ("2", 1.0));
            assert!(
                v.detail.contains("arrive in another assembly mode"),
                "{}",
                v.detail
            );
        } else {
            assert!(branch.is_empty(), "{a}{b}: {found:?}");
        }
    }
}

/// The largest velocity amplification factor at sliders `rho`: of the working mode, or of the
/// pose continued from `start` (as verify tracks a segment).
fn lambda_max_at(m: &Machine, rho: &Sliders, start: Option<ModulePose>) -> (f64, ModulePose) {
    let pose = match start {
        None => fk::working(&fk::solve(m, rho)).unwrap().pose,
        Some(p) => polish_pose(&m.module, p, rho),
    };
    (kinetostatics(&m.module, &pose, rho).amplification[0], pose)
}

/// A genuinely mid-segment defect (the CLI's tests/verify.rs has the same through the command):
/// along y_t with a vertical tool, rows 0.5 mm apart, lambda_max peaks between two rows near
/// y_t = 0. With lambda_max set between the rows' largest value and the value at the midpoint of
/// the segment holding the peak, only that segment is found, at s = 0.5, with that value.
#[test]
fn an_amplification_peak_between_two_rows_is_found_mid_segment() {
    let m = Machine::default_verne();
    let mut state = PathState::new(FirstRowChoice::SmallestTheta1);
    let axis = Vector3::new(0.0, 0.0, 1.0);
    let (mut joints, mut path) = (Vec::new(), Vec::new());
    for k in 0..200 {
        let tip = Vector3::new(0.0, -50.25 + 0.5 * k as f64, 40.0);
        let r = state
            .next_row(&m, &tip, &ToolOrientation::Axis(axis), m.tool_length)
            .unwrap();
        joints.push(Joints {
            rho: r.rho,
            theta1: r.theta1,
            theta2: r.theta2,
            t: Some(0.02 * k as f64),
            feed: None,
            duration: None,
            rapid: false,
        });
        path.push(PathPoint::new(tip, axis));
    }
    let rows: Vec<f64> = joints
        .iter()
        .map(|j| lambda_max_at(&m, &j.rho, None).0)
        .collect();
    let mids: Vec<f64> = joints
        .windows(2)
        .map(|w| {
            let (_, pa) = lambda_max_at(&m, &w[0].rho, None);
            lambda_max_at(&m, &(w[0].rho + (w[1].rho - w[0].rho) * 0.5), Some(pa)).0
        })
        .collect();
    // A segment (ending at row e, 0-based) whose midpoint beats both ends and both neighbours.
    let e = (20..joints.len() - 20)
        .filter(|&e| {
            let mid = mids[e - 1];
            mid > rows[e - 1].max(rows[e]) && mid > mids[e - 2].max(mids[e])
        })
        .max_by(|&a, &b| {
            let excess = |e: usize| mids[e - 1] - rows[e - 1].max(rows[e]);
            excess(a).total_cmp(&excess(b))
        })
        .expect("a local maximum of lambda_max inside a segment");
    let window = e - 10..e + 11;
    let top_row = rows[window.clone()].iter().copied().fold(0.0, f64::max);
    let other_mids = (window.start + 1..window.end)
        .filter(|&k| k != e)
        .map(|k| mids[k - 1])
        .fold(0.0, f64::max);
    let floor = top_row.max(other_mids);
    assert!(mids[e - 1] > floor, "{} vs {floor}", mids[e - 1]);
    let limit = 0.5 * (floor + mids[e - 1]);
    let (_, found) = run(
        &m,
        &thresholds(&[("lambda_max", limit)]),
        oks(&joints[window.clone()]),
        path[window.clone()].to_vec(),
    );
    assert_eq!(found.len(), 1, "{found:?}");
    let v = &found[0];
    // Rows are numbered 1.. within the window; the segment ends at window row 11.
    assert_eq!((v.check, v.row.as_str()), (Check::Singularity, "11"));
    assert!(v.detail.contains("s = 0.5"), "{}", v.detail);
    assert!(
        (v.value - mids[e - 1]).abs() < 1e-9,
        "{v:?} vs {}",
        mids[e - 1]
    );
    assert_eq!(v.limit, limit);
    // With the limit just above the peak (and the other two singularity limits far away), the
    // summary's closest approach is that midpoint, within the limit.
    let th = thresholds(&[
        ("lambda_max", mids[e - 1] * (1.0 + 1e-9)),
        ("lambda_min", 1e-9),
        ("parallel_margin_min", 1e-12),
    ]);
    let (summary, found) = run(&m, &th, oks(&joints[window.clone()]), path[window].to_vec());
    assert!(found.is_empty(), "{found:?}");
    let worst = worst_of(&summary, Check::Singularity);
    assert_eq!(worst.row, "11");
    assert!((worst.value - mids[e - 1]).abs() < 1e-9, "{worst:?}");
    assert_eq!(worst.detail, "mid-segment (within the limit)");
}

fn worst_of(summary: &Summary, check: Check) -> Violation {
    stats(summary, check)
        .worst
        .clone()
        .unwrap_or_else(|| panic!("{check:?}: nothing measured"))
}

/// The summary's closest approach to the jump and speed limits on a clean run: the joint
/// change (and speed) largest relative to its limit, with its value and limit in mm or degrees;
/// a rapid move is not measured against the jump limit.
#[test]
fn the_summary_gives_the_jump_and_the_speed_closest_to_their_limits() {
    let m = Machine::default_verne();
    let (joints, path) = clean();
    // (segment, joint, value) with the largest value / limit, skipping segment `skip`.
    let closest = |values: &dyn Fn(usize) -> Vec<f64>, limits: &[f64; 5], skip: Option<usize>| {
        (0..5)
            .flat_map(|i| {
                values(i)
                    .into_iter()
                    .enumerate()
                    .map(move |(k, v)| (k, i, v))
            })
            .filter(|(k, _, _)| Some(*k) != skip)
            .max_by(|a, b| (a.2 / limits[a.1]).total_cmp(&(b.2 / limits[b.1])))
            .unwrap()
    };
    let jumps = |i: usize| -> Vec<f64> {
        change(&joints, i)
            .iter()
            .map(|d| shown(i, d.abs()))
            .collect()
    };
    let check = |worst: &Violation, (k, i, v): (usize, usize, f64), limits: &[f64; 5]| {
        assert_eq!(worst.row, (k + 2).to_string(), "{worst:?}");
        assert!((worst.value - v).abs() <= 1e-12 * v, "{worst:?} vs {v}");
        assert!(
            (worst.limit - limits[i]).abs() <= 1e-12 * limits[i],
            "{worst:?}"
        );
        assert_eq!(
            worst.detail,
            format!("{} (within the limit)", JOINT_NAMES[i])
        );
    };
    // The default limits (theta2 comes closest), then each joint group made the closest by
    // widening the others' limits ten thousandfold: each is reported in its own unit.
    let steps = [Th::RhoStepMm, Th::Theta1StepDeg, Th::Theta2StepDeg];
    let speed_limits = [
        Th::RhoVelocityMmS,
        Th::Theta1VelocityDegS,
        Th::Theta2VelocityDegS,
    ];
    for favoured in [None, Some(0), Some(1), Some(2)] {
        let mut th = Thresholds::default();
        for group in [steps, speed_limits] {
            for (g, key) in group.into_iter().enumerate() {
                if favoured.is_some_and(|f| f != g) {
                    let name = verne::verify::THRESHOLDS[key as usize].name;
                    th.set(name, 1e4 * th.get(key)).unwrap();
                }
            }
        }
        let per_joint = |[rho, theta1, theta2]: [Th; 3]| {
            let (r, t1, t2) = (th.get(rho), th.get(theta1), th.get(theta2));
            [r, r, r, t1, t2]
        };
        let (step, vmax) = (per_joint(steps), per_joint(speed_limits));
        let (summary, found) = run(&m, &th, oks(&joints), path.clone());
        assert!(found.is_empty(), "{favoured:?}: {found:?}");
        let top = closest(&jumps, &step, None);
        let group_of = |i: usize| i.saturating_sub(2);
        if let Some(f) = favoured {
            assert_eq!(group_of(top.1), f);
        }
        check(&worst_of(&summary, Check::JointJump), top, &step);
        check(
            &worst_of(&summary, Check::Velocity),
            closest(&|i| speeds(&joints, i), &vmax, None),
            &vmax,
        );
        // That segment a rapid move: the next closest jump.
        let mut rapid = path.clone();
        rapid[top.0 + 1].rapid = true;
        let (summary, _) = run(&m, &th, oks(&joints), rapid);
        check(
            &worst_of(&summary, Check::JointJump),
            closest(&jumps, &step, Some(top.0)),
            &step,
        );
    }
}

/// Two slider triples, each with a mode of the machine's kind, found by a scan of random
/// segments (3 of 55,801): tracked from the first, the module leaves the machine's kind a
/// little way along the segment.
#[test]
fn joints_that_leave_the_machine_s_assembly_mode_mid_segment_are_a_branch_change() {
    let m = Machine::default_verne();
    let ends = [
        Vector3::new(1114.8098962832719, 457.0534324386325, 179.893518392908),
        Vector3::new(151.5151959394836, -177.48689885838002, 264.4637304372717),
    ];
    let joints: Vec<Joints> = ends.iter().map(|rho| at_rest(*rho, 0.0, 0.0)).collect();
    let path: Vec<PathPoint> = joints
        .iter()
        .map(|q| {
            let md = &modes_of_the_machine_kind(&m, q)[0];
            PathPoint::new(md.tool.tip, md.axis)
        })
        .collect();
    // (The rows are far beyond the strokes and near singularities: row findings, which do
    // not stop the segment's checks; the slider step limit is lifted.)
    let (_, found) = run(
        &m,
        &thresholds(&[("rho_step_mm", 5000.0)]),
        oks(&joints),
        path,
    );
    let branch = of(&found, Check::Branch);
    assert_eq!(branch.len(), 1, "{found:?}");
    // Samples at most SEGMENT_SAMPLE_MM of slider travel apart, an even number: the module
    // leaves at the first, s = 1/n, leg I's slider then below its attachment.
    let travel = (ends[1] - ends[0]).amax();
    let n = 2.0 * (travel / (2.0 * SEGMENT_SAMPLE_MM)).ceil();
    assert_eq!(n, 482.0);
    let v = branch[0];
    assert_eq!((v.row.as_str(), v.value), ("2", 1.0 / n));
    assert!(
        v.detail
            .contains("leaves the machine's assembly mode at s = 0.0021 (s = (1,-1,-1)"),
        "{}",
        v.detail
    );
}

/// A move that turns the tool about a fixed tip has no length, so a feed does not time it
/// (docs/verify.md): no speed is checked, although the joints move.
#[test]
fn a_turn_about_a_fixed_tip_under_a_feed_is_not_timed() {
    let m = Machine::default_verne();
    let tip = Vector3::new(10.0, 20.0, 40.0);
    let tilt = |deg: f64| Vector3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
    let a = joints_for(&m, &tip, &tilt(10.0), None);
    let b = joints_for(&m, &tip, &tilt(11.0), Some(&a));
    assert!((b.theta1 - a.theta1).abs() > 1e-3, "{a:?} {b:?}");
    let path: Vec<PathPoint> = [10.0, 11.0]
        .iter()
        .map(|&d| PathPoint {
            feed: Some(10.0),
            ..PathPoint::new(tip, tilt(d))
        })
        .collect();
    let (summary, found) = run(&m, &Thresholds::default(), vec![Ok(a), Ok(b)], path);
    assert!(found.is_empty(), "{found:?}");
    let stats = stats(&summary, Check::Velocity);
    assert!(stats.worst.is_none(), "{stats:?}");
}

/// A row over the rod-tilt or the amplification limit is that row's finding only: the
/// segments next to it are not sampled for the same limit (their samples near the row would
/// repeat it). The limit is set between the second largest row value and a midpoint next to
/// the largest row, so that a sampled segment would be a finding.
#[test]
fn a_row_over_a_limit_leaves_its_segments_unsampled_for_it() {
    let (joints, _) = clean();
    let m = Machine::default_verne();
    let g = &m.module;
    let pose_at = |rho: &Sliders, near: Option<ModulePose>| match near {
        None => fk::working(&fk::solve(&m, rho)).unwrap().pose,
        Some(p) => polish_pose(g, p, rho),
    };
    let tilt = |pose: &ModulePose, rho: &Sliders| {
        rod_tilts(g, pose, rho)
            .iter()
            .fold(0.0f64, |a, t| a.max(*t))
            .to_degrees()
    };
    let lambda = |pose: &ModulePose, rho: &Sliders| kinetostatics(g, pose, rho).amplification[0];
    type Measure<'a> = &'a dyn Fn(&ModulePose, &Sliders) -> f64;
    for (name, measure, check) in [
        ("rod_tilt_max", &tilt as Measure, Check::Limits),
        ("lambda_max", &lambda as Measure, Check::Singularity),
    ] {
        let rows: Vec<f64> = joints
            .iter()
            .map(|q| measure(&pose_at(&q.rho, None), &q.rho))
            .collect();
        let mut order: Vec<usize> = (0..rows.len()).collect();
        order.sort_by(|a, b| rows[*b].total_cmp(&rows[*a]));
        let (k, second) = (order[0], rows[order[1]]);
        let mid = [k.wrapping_sub(1), k + 1]
            .into_iter()
            .filter(|&j| j < rows.len())
            .map(|j| {
                let (a, b) = (&joints[j.min(k)], &joints[j.max(k)]);
                let rho = a.rho + (b.rho - a.rho) * 0.5;
                measure(&pose_at(&rho, Some(pose_at(&a.rho, None))), &rho)
            })
            .fold(f64::MIN, f64::max);
        assert!(
            mid > second && mid < rows[k],
            "{name}: {second} {mid} {}",
            rows[k]
        );
        let limit = 0.5 * (second + mid);
        let (m, th) = if name == "rod_tilt_max" {
            (
                machine(&format!("rod_tilt_max = {limit}")),
                Thresholds::default(),
            )
        } else {
            (Machine::default_verne(), thresholds(&[(name, limit)]))
        };
        let (_, found) = run_clean(&m, &th);
        let over = of(&found, check);
        assert_eq!(over.len(), 1, "{name}: {found:?}");
        assert_eq!(over[0].row, (k + 1).to_string(), "{name}");
        assert!(
            (over[0].value - rows[k]).abs() < 1e-9,
            "{name}: {:?}",
            over[0]
        );
    }
}

/// A rod tilted most between two rows: on a machine whose legs II and III stand closer
/// (r4 = 300 mm instead of 565 mm), a scan of random segments with both ends in the machine's
/// mode found interior maxima of rod tilt (12 of 13,233; 101 of 3,187 at r4 = 150 mm; none on
/// the VERNE machine in 200,000 segments). With the tilt limit between the ends' tilts and the
/// interior maximum, that segment is a finding at the maximum, refined between the samples to
/// the value found here by a golden-section search on the tracked poses.
#[test]
fn a_rod_tilt_peak_between_two_rows_is_found_at_its_maximum() {
    let m = Machine::from_toml_str(
        "base = \"verne\"\n[module]\nr4 = 300.0\n[limits]\nrod_tilt_max = 80.28\n",
        "test",
    )
    .unwrap();
    let g = &m.module;
    let ends = [
        Vector3::new(529.3934706124653, -182.138342247086, 198.23287709284347),
        Vector3::new(637.1946331507618, 51.03363321207647, 788.7988728503867),
    ];
    let start = fk::solve(&m, &ends[0])
        .iter()
        .map(|md| md.pose)
        .find(|p| {
            config_of(g, p, &ends[0]) == WORKING_CONFIG && g.r_big1 * p.alpha.cos() > g.r_small1
        })
        .unwrap();
    // The pose tracked from the start to s (in steps of at most 1 mm of slider travel).
    let tracked = |s: f64| -> ModulePose {
        let steps = ((ends[1] - ends[0]).amax() * s).ceil().max(1.0) as usize;
        (1..=steps).fold(start, |p, k| {
            polish_pose(
                g,
                p,
                &(ends[0] + (ends[1] - ends[0]) * (s * k as f64 / steps as f64)),
            )
        })
    };
    let tilt_at = |s: f64| -> f64 {
        let rho = ends[0] + (ends[1] - ends[0]) * s;
        rod_tilts(g, &tracked(s), &rho)
            .iter()
            .fold(0.0f64, |a, t| a.max(*t))
            .to_degrees()
    };
    // Golden-section search for the maximum.
    let (mut a, mut b) = (0.0, 1.0);
    let r = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (x1, x2) = (b - r * (b - a), a + r * (b - a));
        if tilt_at(x1) < tilt_at(x2) {
            a = x1;
        } else {
            b = x2;
        }
    }
    let (s_max, t_max) = (0.5 * (a + b), tilt_at(0.5 * (a + b)));
    let end_pose = tracked(1.0);
    let joints: Vec<Joints> = ends.iter().map(|rho| at_rest(*rho, 0.0, 0.0)).collect();
    let path: Vec<PathPoint> = [start, end_pose]
        .iter()
        .zip(&ends)
        .map(|(pose, rho)| {
            let md = machine_fk(&m, rho, 0.0, 0.0, m.tool_length)
                .into_iter()
                .filter(|md| md.config == WORKING_CONFIG)
                .min_by(|x, y| {
                    (x.module.p - pose.p)
                        .norm()
                        .total_cmp(&(y.module.p - pose.p).norm())
                })
                .unwrap();
            PathPoint::new(md.tool.tip, md.axis)
        })
        .collect();
    let th = thresholds(&[("rho_step_mm", 5000.0), ("chord_error_mm", 1000.0)]);
    let (_, found) = run(&m, &th, oks(&joints), path);
    let tilts = of(&found, Check::Limits)
        .into_iter()
        .filter(|v| v.detail.contains("mid-segment"))
        .collect::<Vec<_>>();
    assert_eq!(tilts.len(), 1, "{found:?}");
    let v = tilts[0];
    assert_eq!(v.row, "2");
    assert!((v.limit - 80.28).abs() < 1e-9, "{v:?}");
    // The refined maximum is a tilt at a tracked pose: at most the true maximum, and within
    // 1e-9 deg of it (the nearest 2 mm sample alone is 6e-7 deg short).
    assert!(
        v.value <= t_max + 1e-10 && v.value > t_max - 1e-9,
        "{v:?} vs {t_max}"
    );
    let ends_detail = format!(
        "at s = {s_max:.4} (ends {:.4} and {:.4} deg)",
        tilt_at(0.0),
        tilt_at(1.0)
    );
    assert!(
        v.detail.contains(&ends_detail),
        "{} vs {ends_detail}",
        v.detail
    );
    assert!(tilt_at(0.0).max(tilt_at(1.0)) < 80.28 && t_max > 80.28);
}
