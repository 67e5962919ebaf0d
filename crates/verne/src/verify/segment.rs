//! The checks of one segment between two rows, with the joints interpolated linearly as a
//! controller does: branch changes, theta2 flips, joint jumps, velocities, and along the
//! interpolated joints the assembly mode, rod tilts, singularity proximity and the chordal error.

use super::row::{ROD_NAMES, exceeds, max_tilt, singularity_checks};
use super::*;
use crate::machine::intended::followed_angles;
use crate::machine::orientation::tool_axis;

/// The module pose at sliders `rho`, continued from `prev` (Newton; if it fails, the nearest
/// assembly mode of the forward kinematics). None when the sliders cannot be assembled.
fn track(m: &Machine, prev: &ModulePose, rho: &Sliders) -> Option<ModulePose> {
    let g = &m.module;
    let p = polish_pose(g, *prev, rho);
    if residual_mm(g, &p, rho) <= ACCEPT_RESIDUAL_MM {
        return Some(p);
    }
    crate::parallel_module::fk::solve(m, rho)
        .iter()
        .map(|md| md.pose)
        .min_by(|a, b| pose_distance(g, a, prev).total_cmp(&pose_distance(g, b, prev)))
}

fn pose_distance(g: &crate::spec::ModuleGeometry, a: &ModulePose, b: &ModulePose) -> f64 {
    (a.p - b.p)
        .amax()
        .max((wrap_angle(a.alpha - b.alpha) * g.r_big2).abs())
}

/// Segment checks that need only its two rows (run in parallel).
pub(super) fn eval_segment(m: &Machine, opt: &VerifyOptions, a: &RowEval, b: &RowEval) -> SegEval {
    let th = &opt.thresholds;
    let mut s = SegEval::default();
    let (Some(qa), Some(qb), Some(pa), Some(pb)) = (a.q, b.q, a.point, b.point) else {
        return s;
    };
    let row = b.label.as_str();
    let from = format!("segment from row {}", a.label);
    let dq: [f64; 5] = std::array::from_fn(|i| qb.as_array()[i] - qa.as_array()[i]);
    let dtheta2 = dq[4];
    // 4. A change of orientation solution that is not a passage through the table normal.
    let (la, lb) = (orientation_label(a.phi1), orientation_label(b.phi1));
    if la * lb == -1 && wrap_angle(dtheta2).abs() > ORIENTATION_FLIP_RAD {
        s.violations.push(Violation::over(
            row,
            Check::Branch,
            wrap_angle(dtheta2).abs().to_degrees(),
            ORIENTATION_FLIP_RAD.to_degrees(),
            format!(
                "{from}: orientation solution {} -> {} (phi1 {:.4} -> {:.4} deg, theta2 {:+.4} deg, theta1 {:+.4} deg)",
                if la > 0 { 1 } else { 2 },
                if lb > 0 { 1 } else { 2 },
                a.phi1.to_degrees(),
                b.phi1.to_degrees(),
                dtheta2.to_degrees(),
                dq[3].to_degrees()
            ),
        ));
        return s;
    }
    // 6. theta2 flip: about half a turn (mod a full turn).
    let turns = dtheta2.abs() % (2.0 * PI);
    if (turns - PI).abs() < th.get(Th::Theta2FlipTolDeg).to_radians() {
        s.violations.push(Violation::over(
            row,
            Check::Theta2Flip,
            dtheta2.abs().to_degrees(),
            th.get(Th::Theta2StepDeg),
            format!(
                "{from}: theta2 {:.4} -> {:.4} deg ({:+.4} deg)",
                qa.theta2.to_degrees(),
                qb.theta2.to_degrees(),
                dtheta2.to_degrees()
            ),
        ));
        s.flip = Some(dtheta2);
        return s;
    }
    s.dq = dq;
    // A rapid move is not interpolated along the line by the controller: no jump, chord or
    // speed check (its speed is the machine's rapid rate, not a programmed feed). A rapid where
    // the path cuts is a finding of its own.
    let rapid = pb.rapid || qb.rapid;
    if qb.rapid && !pb.rapid {
        s.violations.push(Violation::plain(
            row,
            Check::Motion,
            f64::NAN,
            format!("{from}: the joint program moves rapid (G0) where the intended path cuts"),
        ));
    }
    // 6. Joint jumps.
    let step = th.per_joint(Th::RhoStepMm, Th::Theta1StepDeg, Th::Theta2StepDeg);
    let mut jumped = false;
    let mut worst = None;
    for i in 0..5 {
        let (v, l) = if i < 3 {
            (dq[i].abs(), step[i])
        } else {
            (dq[i].abs().to_degrees(), step[i].to_degrees())
        };
        keep_worst(
            &mut worst,
            Obs::over(Check::JointJump, v, l, JOINT_NAMES[i]),
        );
        if dq[i].abs() > step[i] && !rapid {
            let (v, l, u) = if i < 3 {
                (dq[i].abs(), step[i], "mm")
            } else {
                (dq[i].abs().to_degrees(), step[i].to_degrees(), "deg")
            };
            s.violations.push(Violation::over(
                row,
                Check::JointJump,
                v,
                l,
                format!(
                    "{from}: {} changes by {:+.4} {u}",
                    JOINT_NAMES[i],
                    if i < 3 { dq[i] } else { dq[i].to_degrees() }
                ),
            ));
            jumped = true;
        }
    }
    if !rapid {
        s.obs.extend(worst);
    }
    // A jump does not end the checks: its chord, axis and limits are measured along the
    // interpolated joints like any segment's (the size of the gouge is the finding a user
    // needs); its speeds are the jump's own finding.
    // 6. Velocities: from the joint table's time or feed, else from the path's feed.
    let dt = match (qa.t, qb.t, qb.duration.or(pb.duration), qb.feed.or(pb.feed)) {
        (Some(ta), Some(tb), _, _) => Some(tb - ta),
        _ if rapid => None,
        (_, _, Some(d), _) => Some(d),
        (_, _, _, Some(f)) if f > 0.0 => Some((pb.tip - pa.tip).norm() / f),
        _ => None,
    };
    if let Some(dt) = dt {
        s.dt = dt;
        if qa.t.is_some() && dt <= 0.0 {
            s.violations.push(Violation::plain(
                row,
                Check::Velocity,
                dt,
                format!("{from}: t does not increase (dt = {dt} s)"),
            ));
        } else if dt > 0.0 && jumped {
            s.rates = Some(std::array::from_fn(|i| dq[i] / dt));
        } else if dt > 0.0 {
            let vmax = th.per_joint(
                Th::RhoVelocityMmS,
                Th::Theta1VelocityDegS,
                Th::Theta2VelocityDegS,
            );
            let rates: [f64; 5] = std::array::from_fn(|i| dq[i] / dt);
            let mut ok = true;
            let mut worst = None;
            for i in 0..5 {
                let (v, l) = if i < 3 {
                    (rates[i].abs(), vmax[i])
                } else {
                    (rates[i].abs().to_degrees(), vmax[i].to_degrees())
                };
                keep_worst(&mut worst, Obs::over(Check::Velocity, v, l, JOINT_NAMES[i]));
                if rates[i].abs() > vmax[i] {
                    let (v, l, u) = if i < 3 {
                        (rates[i].abs(), vmax[i], "mm/s")
                    } else {
                        (rates[i].abs().to_degrees(), vmax[i].to_degrees(), "deg/s")
                    };
                    s.violations.push(Violation::over(
                        row,
                        Check::Velocity,
                        v,
                        l,
                        format!("{from}: {} at {v:.4} {u} (dt = {dt:.6} s)", JOINT_NAMES[i]),
                    ));
                    ok = false;
                }
            }
            s.obs.extend(worst);
            s.accelerations_checked = ok;
            s.rates = Some(rates);
        }
    }
    // 2, 3, 4, 5 along the interpolated joints.
    interior(m, opt, a, b, &qa, &qb, &pa, &pb, &from, &mut s);
    s
}

/// Samples a segment's interior: assembly mode, rod tilts, singularity, chordal error.
#[allow(clippy::too_many_arguments)]
fn interior(
    m: &Machine,
    opt: &VerifyOptions,
    a: &RowEval,
    b: &RowEval,
    qa: &Joints,
    qb: &Joints,
    pa: &PathPoint,
    pb: &PathPoint,
    from: &str,
    seg: &mut SegEval,
) {
    let out = &mut seg.violations;
    let mut singular_worst: Option<Obs> = None;
    let mut tilt_worst: Option<Obs> = None;
    let th = &opt.thresholds;
    let row = b.label.as_str();
    let g = &m.module;
    let drho = qb.rho - qa.rho;
    let travel = drho.amax();
    let half =
        ((travel / (2.0 * SEGMENT_SAMPLE_MM)).ceil() as usize).clamp(1, MAX_SEGMENT_SAMPLES / 2);
    let n = 2 * half;
    let tilt_limit = m.limits.rod_tilt_max;
    let check_tilt = a.tilt_ok && b.tilt_ok;
    let check_singular = a.singular_ok && b.singular_ok;
    let mut pose = a.module;
    // (s, rod, tilt) of the worst sample, and the tilts either side of it.
    let mut worst: Option<(usize, usize, f64, ModulePose)> = None;
    let mut tilts_prev = max_tilt(m, &a.module, &qa.rho).1;
    let mut around = [f64::NAN; 3];
    let mut singular: Vec<Violation> = Vec::new();
    // The intended move (docs/verify.md): the tip along the line, the axis along the arc (or
    // the stated angles), uniformly; the worst deviation of each, at (s, value).
    let rapid = pb.rapid || qb.rapid;
    // Stated angles are interpolated where the joints realize them (phi1 = alpha - theta1,
    // phi2 = -theta2).
    let achieved = |e: &RowEval, q: &Joints| (e.module.alpha - q.theta1, -q.theta2);
    let (sa, sb) = (
        followed_angles(pa.angles, achieved(a, qa)),
        followed_angles(pb.angles, achieved(b, qb)),
    );
    let intended = IntendedMove::new(pa.tip, pa.axis, sa, pb.tip, pb.axis, sb).ok();
    // The ends' own errors (their tip and axis findings), taken off along the segment: the
    // chord is what the interpolation adds between them.
    let ends = intended
        .as_ref()
        .map(|mv| end_errors(m, opt, qa, qb, a, b, mv));
    let (mut chord_worst, mut axis_worst) = ((0.0, 0.0f64), (0.0, 0.0f64));
    for j in 1..n {
        let s = j as f64 / n as f64;
        let rho = qa.rho + drho * s;
        let Some(next) = track(m, &pose, &rho) else {
            out.push(Violation::plain(
                row,
                Check::Branch,
                s,
                format!("{from}: the interpolated joints cannot be assembled at s = {s:.4}"),
            ));
            return;
        };
        pose = next;
        let config = config_of(g, &pose, &rho);
        if !machine_kind(config, pose.alpha, m) {
            out.push(Violation::plain(
                row,
                Check::Branch,
                s,
                format!(
                    "{from}: leaves the machine's assembly mode at s = {s:.4} (s = ({},{},{}), alpha = {:.4} deg)",
                    config[0],
                    config[1],
                    config[2],
                    pose.alpha.to_degrees()
                ),
            ));
            return;
        }
        if !rapid {
            let q1 = qa.theta1 + (qb.theta1 - qa.theta1) * s;
            let q2 = qa.theta2 + (qb.theta2 - qa.theta2) * s;
            let tool = tool_pose_eq26(&m.table, &pose, q1, q2, opt.tool_length);
            if let (Some(mv), Some(ends)) = (&intended, &ends) {
                let (tip_dev, axis_dev) = chord_deviation(&tool, mv, ends, s);
                if tip_dev > chord_worst.1 {
                    chord_worst = (s, tip_dev);
                }
                if axis_dev > axis_worst.1 {
                    axis_worst = (s, axis_dev);
                }
            }
        }
        if check_tilt {
            let (rod, t) = max_tilt(m, &pose, &rho);
            keep_worst(
                &mut tilt_worst,
                Obs::over(
                    Check::Limits,
                    t.to_degrees(),
                    tilt_limit.to_degrees(),
                    "largest rod tilt, mid-segment",
                ),
            );
            if let Some((wj, _, _, _)) = worst
                && wj + 1 == j
            {
                around[2] = t;
            }
            if t > tilt_limit && worst.as_ref().is_none_or(|w| t > w.2) {
                worst = Some((j, rod, t, pose));
                around = [tilts_prev, t, f64::NAN];
            }
            tilts_prev = t;
        }
        if check_singular && singular.is_empty() {
            let o = singularity_checks(
                m,
                th,
                &pose,
                &rho,
                row,
                &format!("{from}, at s = {s:.4}: "),
                &mut singular,
            );
            keep_worst(
                &mut singular_worst,
                Obs {
                    what: "mid-segment",
                    ..o
                },
            );
        }
    }
    seg.obs.extend(singular_worst);
    seg.obs.extend(tilt_worst);
    if !rapid && let Some(mv) = &intended {
        let out = &mut seg.violations;
        // The worst sample's neighbourhood, a sample either side, looked at finely: the
        // deviation is smooth in s, and the samples are at most 2 mm of slider travel apart.
        for (worst, is_tip) in [(chord_worst, true), (axis_worst, false)] {
            let ends = ends.unwrap_or_default();
            let (s0, value) =
                refine_deviation(m, opt, qa, qb, mv, &ends, &a.module, worst, n, is_tip);
            let (check, limit, shown, unit) = if is_tip {
                (Check::ChordError, th.get(Th::ChordErrorMm), value, "mm")
            } else {
                (
                    Check::ChordAxis,
                    th.get(Th::ChordAxisErrorDeg),
                    value.to_degrees(),
                    "deg",
                )
            };
            seg.obs.push(Obs::over(
                check,
                shown,
                limit,
                if is_tip {
                    "chordal error"
                } else {
                    "chordal axis error"
                },
            ));
            if exceeds(shown, limit) {
                out.push(Violation::over(
                    row,
                    check,
                    shown,
                    limit,
                    format!(
                        "{from}: the {} of the interpolated joints is {shown:.5} {unit} off the intended move at s = {s0:.4}",
                        if is_tip { "tip" } else { "tool axis" }
                    ),
                ));
            }
        }
    }
    let out = &mut seg.violations;
    // The tracked mode must arrive at the end row's mode.
    let end = track(m, &pose, &qb.rho);
    let arrived = end.is_some_and(|p| pose_distance(g, &p, &b.module) <= TRACK_ARRIVAL_MM);
    if !arrived {
        out.push(Violation::plain(
            row,
            Check::Branch,
            1.0,
            format!(
                "{from}: the interpolated joints arrive in another assembly mode than the row's"
            ),
        ));
        return;
    }
    if let Some((j, rod, t, wpose)) = worst {
        if around[2].is_nan() {
            around[2] = max_tilt(m, &b.module, &qb.rho).1;
        }
        let best = refine_worst(j, n, (t, rod), around, |s| {
            let rho = qa.rho + drho * s;
            track(m, &wpose, &rho).map(|p| {
                let (r2, t2) = max_tilt(m, &p, &rho);
                (t2, r2)
            })
        });
        out.push(Violation::over(
            row,
            Check::Limits,
            best.1.to_degrees(),
            tilt_limit.to_degrees(),
            format!(
                "{from}: mid-segment, rod {} tilted {:.4} deg at s = {:.4} (ends {:.4} and {:.4} deg)",
                ROD_NAMES[best.2],
                best.1.to_degrees(),
                best.0,
                max_tilt(m, &a.module, &qa.rho).1.to_degrees(),
                max_tilt(m, &b.module, &qb.rho).1.to_degrees()
            ),
        ));
    }
    out.extend(singular);
}

/// The tip's and axis's errors at a segment's two ends (fk of the end joints against the
/// intended poses): (tip error at s = 0, at s = 1, axis error vector at 0, at 1).
#[derive(Debug, Clone, Copy, Default)]
struct EndErrors {
    tip: [Vector3<f64>; 2],
    axis: [Vector3<f64>; 2],
}

/// The errors at the ends of a segment, in the rows' assembly modes.
fn end_errors(
    m: &Machine,
    opt: &VerifyOptions,
    qa: &Joints,
    qb: &Joints,
    a: &RowEval,
    b: &RowEval,
    mv: &IntendedMove,
) -> EndErrors {
    let at = |q: &Joints, pose: &ModulePose, s: f64| {
        let tool = tool_pose_eq26(&m.table, pose, q.theta1, q.theta2, opt.tool_length);
        (
            tool.tip - mv.tip(s),
            tool_axis(tool.phi1, tool.phi2) - mv.axis(s),
        )
    };
    let (t0, a0) = at(qa, &a.module, 0.0);
    let (t1, a1) = at(qb, &b.module, 1.0);
    EndErrors {
        tip: [t0, t1],
        axis: [a0, a1],
    }
}

/// The chord's deviation at s: the tool pose of the interpolated joints against the intended
/// one, less the ends' errors interpolated (tip in mm, axis in rad).
fn chord_deviation(
    tool: &crate::machine::ToolPose,
    mv: &IntendedMove,
    ends: &EndErrors,
    s: f64,
) -> (f64, f64) {
    let tip = tool.tip - mv.tip(s) - (ends.tip[0] * (1.0 - s) + ends.tip[1] * s);
    let axis = tool_axis(tool.phi1, tool.phi2)
        - mv.axis(s)
        - (ends.axis[0] * (1.0 - s) + ends.axis[1] * s);
    // |a - h| = 2 sin(angle / 2) for unit vectors.
    (tip.norm(), 2.0 * (0.5 * axis.norm()).min(1.0).asin())
}

/// The deviation of the tip (`is_tip`) or the axis from the intended move near the worst
/// sample `worst` = (s, value) of `n`: 16 points across the two sample intervals around it,
/// tracked from the segment's start; the largest (s, value) found, at least the sample's.
#[allow(clippy::too_many_arguments)]
fn refine_deviation(
    m: &Machine,
    opt: &VerifyOptions,
    qa: &Joints,
    qb: &Joints,
    mv: &IntendedMove,
    ends: &EndErrors,
    start: &ModulePose,
    worst: (f64, f64),
    n: usize,
    is_tip: bool,
) -> (f64, f64) {
    let step = 1.0 / n as f64;
    let (lo, hi) = ((worst.0 - step).max(0.0), (worst.0 + step).min(1.0));
    let drho = qb.rho - qa.rho;
    let mut best = worst;
    let mut pose = *start;
    // From the start to the neighbourhood, then across it, in steps of the samples' spacing.
    let steps = ((lo / step).round() as usize).max(1);
    for k in 1..=steps {
        let s = lo * k as f64 / steps as f64;
        match track(m, &pose, &(qa.rho + drho * s)) {
            Some(p) => pose = p,
            None => return best,
        }
    }
    for k in 0..=16 {
        let s = lo + (hi - lo) * k as f64 / 16.0;
        let rho = qa.rho + drho * s;
        let Some(p) = track(m, &pose, &rho) else {
            return best;
        };
        pose = p;
        let q1 = qa.theta1 + (qb.theta1 - qa.theta1) * s;
        let q2 = qa.theta2 + (qb.theta2 - qa.theta2) * s;
        let tool = tool_pose_eq26(&m.table, &pose, q1, q2, opt.tool_length);
        let (tip_dev, axis_dev) = chord_deviation(&tool, mv, ends, s);
        let value = if is_tip { tip_dev } else { axis_dev };
        if value > best.1 {
            best = (s, value);
        }
    }
    best
}

/// The worst tilt sample, sample `j` of `n` with (tilt, rod) `worst`, refined by the parabola
/// through its tilt and its neighbours' (`around`): (s, tilt, rod) of the vertex when `probe`
/// finds the tilt there higher, else of the sample. `probe(s)` is (tilt, rod) at s, `None`
/// where the segment cannot be tracked.
fn refine_worst(
    j: usize,
    n: usize,
    worst: (f64, usize),
    around: [f64; 3],
    probe: impl FnOnce(f64) -> Option<(f64, usize)>,
) -> (f64, f64, usize) {
    let (f0, f1, f2) = (around[0], around[1], around[2]);
    let den = f0 - 2.0 * f1 + f2;
    let mut best = (j as f64 / n as f64, worst.0, worst.1);
    if den < 0.0 {
        let off = 0.5 * (f0 - f2) / den;
        if off.abs() < 1.0 {
            let s = (j as f64 + off) / n as f64;
            if let Some((t2, r2)) = probe(s)
                && t2 > best.1
            {
                best = (s, t2, r2);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parabola through tilts 1, 2 and 1.5 at samples 9, 10 and 11 of 40 peaks 1/6 of a
    /// sample past 10 (through (-1, f0), (0, f1), (1, f2) with f0 - 2 f1 + f2 < 0, the vertex
    /// is at 0.5 (f0 - f2) / (f0 - 2 f1 + f2)). The tilt found there is taken only when it is
    /// higher than the sample's (2.1: the vertex; 2.0, 1.9 or not tracked: sample 10 at s =
    /// 0.25). Flat tilts, or a vertex a sample or more away, are not probed.
    #[test]
    fn the_worst_tilt_is_refined_only_where_the_vertex_is_higher() {
        let vertex = (10.0 + 1.0 / 6.0) / 40.0;
        let sample = (0.25, 2.0, 1);
        for (found, expect) in [
            (Some((2.1, 2)), (vertex, 2.1, 2)),
            (Some((2.0, 2)), sample),
            (Some((1.9, 2)), sample),
            (None, sample),
        ] {
            let mut probed = None;
            let best = refine_worst(10, 40, (2.0, 1), [1.0, 2.0, 1.5], |s| {
                probed = Some(s);
                found
            });
            let s = probed.expect("the vertex is probed");
            assert!((s - vertex).abs() < 1e-15, "probed at {s}, vertex {vertex}");
            assert_eq!(best.1, expect.1);
            assert_eq!(best.2, expect.2);
            assert!(
                (best.0 - expect.0).abs() < 1e-15,
                "{best:?} against {expect:?}"
            );
        }
        for around in [[2.0, 2.0, 2.0], [0.0, 1.0, 1.9]] {
            let best = refine_worst(10, 40, (2.0, 1), around, |s| {
                panic!("probed at {s} for tilts {around:?}")
            });
            assert_eq!(best, sample);
        }
    }

    /// Where Newton from the previous pose fails, `track` falls back to the forward
    /// kinematics: the mode nearest the previous pose (by `pose_distance`), assembled within
    /// [`ACCEPT_RESIDUAL_MM`]. Slider triples of poses through the default machine's
    /// workspace, from previous poses 0 to 1e4 mm off in position, with alpha at 3, 1.5, -2.5
    /// and 0 rad; where Newton succeeds, its pose is kept. Both cases are counted.
    #[test]
    fn track_falls_back_to_the_nearest_mode_where_newton_fails() {
        let m = Machine::default_verne();
        let g = &m.module;
        let (mut fell_back, mut kept) = (0, 0);
        for (x, y, z) in [
            (0.0, 0.0, 0.0),
            (-150.0, 80.0, 120.0),
            (200.0, -120.0, -60.0),
        ] {
            let p = Vector3::new(x, y, z);
            for branch in crate::parallel_module::ik::solve(&m, &p).iter() {
                let rho = branch.rho;
                for (dp, alpha) in [(0.0, 3.0), (400.0, 1.5), (3000.0, -2.5), (1e4, 0.0)] {
                    let prev = ModulePose {
                        p: p + Vector3::new(dp, -dp, dp),
                        alpha,
                    };
                    let got = track(&m, &prev, &rho).expect("the sliders are assembled");
                    assert!(residual_mm(g, &got, &rho) <= ACCEPT_RESIDUAL_MM, "{got:?}");
                    let newton = polish_pose(g, prev, &rho);
                    if residual_mm(g, &newton, &rho) <= ACCEPT_RESIDUAL_MM {
                        assert_eq!(got, newton);
                        kept += 1;
                        continue;
                    }
                    let modes = crate::parallel_module::fk::solve(&m, &rho);
                    let nearest = modes
                        .iter()
                        .map(|md| pose_distance(g, &md.pose, &prev))
                        .fold(f64::INFINITY, f64::min);
                    assert_eq!(pose_distance(g, &got, &prev), nearest, "{got:?} {prev:?}");
                    fell_back += 1;
                }
            }
        }
        assert!(
            fell_back >= 4 && kept >= 4,
            "{fell_back} fell back, {kept} kept"
        );
    }

    /// Two poses' distance (mm) is the larger of their largest coordinate difference and their
    /// alpha difference (wrapped) as an arc at R2.
    #[test]
    fn pose_distance_weighs_alpha_at_r2() {
        let m = Machine::default_verne();
        let g = &m.module;
        let a = ModulePose {
            p: Vector3::new(10.0, -20.0, 30.0),
            alpha: 3.0,
        };
        let moved = |dp: Vector3<f64>, da: f64| ModulePose {
            p: a.p + dp,
            alpha: wrap_angle(a.alpha + da),
        };
        let d = |b: &ModulePose| pose_distance(g, &a, b);
        assert_eq!(d(&moved(Vector3::new(0.0, -5.0, 1.0), 0.0)), 5.0);
        let arc = d(&moved(Vector3::zeros(), 0.1));
        assert!((arc - 0.1 * g.r_big2).abs() < 1e-9 * g.r_big2, "{arc}");
        // 3.2 rad is -3.08 wrapped: the difference is still 0.2 rad.
        let across_pi = d(&moved(Vector3::new(1.0, 0.0, 0.0), 0.2));
        assert!(
            (across_pi - 0.2 * g.r_big2).abs() < 1e-9 * g.r_big2,
            "{across_pi}"
        );
    }
}
