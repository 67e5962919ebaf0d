//! The checks of one row: branch (working assembly mode), tip and axis errors against the
//! intended pose, limits, singularity proximity.

use super::*;
use crate::machine::MachineFkMode;

/// The assembly mode a joint row is taken in: of the modes of the machine's kind, the one whose
/// tip is nearest `tip`; the first of them when `tip` is `None` or on a tie.
pub(super) fn mode_of_kind<'a>(
    modes: &'a MachineFkModes,
    m: &Machine,
    tip: Option<&Vector3<f64>>,
) -> Option<&'a MachineFkMode> {
    let near = |md: &MachineFkMode| tip.map_or(0.0, |p| (md.tool.tip - p).norm());
    modes
        .iter()
        .filter(|md| machine_kind(md.config, md.module.alpha, m))
        .min_by(|a, b| near(a).total_cmp(&near(b)))
}

/// Row checks: branch (working assembly mode), tip and axis errors, limits, singularity.
pub(super) fn eval_row(
    m: &Machine,
    opt: &VerifyOptions,
    p: &Paired,
    break_before: bool,
) -> RowEval {
    let th = &opt.thresholds;
    let label = label_of(&p.joints);
    let mut e = RowEval {
        label,
        good: false,
        violations: Vec::new(),
        obs: ArrayVec::new(),
        q: None,
        point: None,
        module: ModulePose {
            p: Vector3::zeros(),
            alpha: 0.0,
        },
        phi1: 0.0,
        tilt_ok: false,
        singular_ok: false,
        break_before,
        joints_line: p.joints.line,
        path_line: p.point.as_ref().map(|i| i.line),
        index: p.joints.index,
        has_mode: false,
    };
    // Path rows the pairing passed over without a joint row of their own.
    for item in &p.missing {
        e.violations.push(super::missing_row(
            item,
            &label_of(&p.joints),
            p.joints.line,
        ));
    }
    let q = match &p.joints.value {
        Ok(q) => *q,
        Err(msg) => {
            let d = format!("joint table line {}: {msg}", p.joints.line);
            e.violations
                .push(Violation::plain(&e.label, Check::Input, f64::NAN, d));
            return e;
        }
    };
    e.q = Some(q);
    let point = match &p.point {
        None => {
            let d = match (&p.unpaired, &p.joints.id) {
                (Some(why), _) => why.clone(),
                (None, Some(id)) => format!("id `{id}` is not in the intended path"),
                (None, None) => "no intended row".into(),
            };
            e.violations
                .push(Violation::plain(&e.label, Check::Pairing, f64::NAN, d));
            return e;
        }
        Some(item) => match &item.value {
            Ok(pt) => *pt,
            Err(msg) => {
                let d = format!("intended path line {}: {msg}", item.line);
                e.violations
                    .push(Violation::plain(&e.label, Check::Input, f64::NAN, d));
                return e;
            }
        },
    };
    e.point = Some(point);
    // The modes the pairing computed (a recording's), or computed here.
    let computed;
    let modes = match &p.modes {
        Some(modes) => &**modes,
        None => {
            computed = machine_fk(m, &q.rho, q.theta1, q.theta2, opt.tool_length);
            &computed
        }
    };
    let Some(mode) = mode_of_kind(modes, m, Some(&point.tip)) else {
        let listed: Vec<String> = modes
            .iter()
            .map(|md| {
                format!(
                    "s=({},{},{}) alpha={:.3}: {}",
                    md.config[0],
                    md.config[1],
                    md.config[2],
                    md.module.alpha.to_degrees(),
                    md.verdict
                )
            })
            .collect();
        let d = if modes.is_empty() {
            "the joints cannot be assembled (no real assembly mode)".to_string()
        } else {
            format!(
                "no assembly mode of the machine's kind (s=-1,-1,-1, rods of leg I not crossing); {} real: {}",
                modes.len(),
                listed.join("; ")
            )
        };
        e.violations.push(Violation::plain(
            &e.label,
            Check::Branch,
            modes.len() as f64,
            d,
        ));
        return e;
    };
    e.module = mode.module;
    e.has_mode = true;
    e.phi1 = mode.tool.phi1;
    let tip_err = (mode.tool.tip - point.tip).norm();
    let cross = mode.axis.cross(&point.axis).norm();
    let axis_err = cross.atan2(mode.axis.dot(&point.axis)).to_degrees();
    e.obs.push(Obs::over(
        Check::TipError,
        tip_err,
        th.get(Th::TipErrorMm),
        "tip error",
    ));
    e.obs.push(Obs::over(
        Check::AxisError,
        axis_err,
        th.get(Th::AxisErrorDeg),
        "axis error",
    ));
    let mut pose_ok = true;
    if exceeds(tip_err, th.get(Th::TipErrorMm)) {
        let d = mode.tool.tip - point.tip;
        e.violations.push(Violation::over(
            &e.label,
            Check::TipError,
            tip_err,
            th.get(Th::TipErrorMm),
            format!(
                "fk tip - intended = ({:.4}, {:.4}, {:.4}) mm",
                d.x, d.y, d.z
            ),
        ));
        pose_ok = false;
    }
    if exceeds(axis_err, th.get(Th::AxisErrorDeg)) {
        e.violations.push(Violation::over(
            &e.label,
            Check::AxisError,
            axis_err,
            th.get(Th::AxisErrorDeg),
            format!(
                "fk axis ({:.6}, {:.6}, {:.6}) vs intended ({:.6}, {:.6}, {:.6})",
                mode.axis.x, mode.axis.y, mode.axis.z, point.axis.x, point.axis.y, point.axis.z
            ),
        ));
        pose_ok = false;
    }
    e.good = pose_ok;
    // Limits, with the numbers.
    let lim = &m.limits;
    e.tilt_ok = !mode.verdict.has(Reason::RodTilt);
    let (_, tilt) = max_tilt(m, &mode.module, &q.rho);
    e.obs.push(Obs::over(
        Check::Limits,
        tilt.to_degrees(),
        lim.rod_tilt_max.to_degrees(),
        "largest rod tilt",
    ));
    for (i, r) in [Reason::Rho1Stroke, Reason::Rho2Stroke, Reason::Rho3Stroke]
        .into_iter()
        .enumerate()
    {
        if mode.verdict.has(r) {
            let v = q.rho[i];
            let (limit, side) = if v < lim.rho_min[i] {
                (lim.rho_min[i], "below")
            } else {
                (lim.rho_max[i], "above")
            };
            let mut viol = Violation::plain(
                &e.label,
                Check::Limits,
                v,
                format!(
                    "rho{} = {v:.4} mm is {side} its stroke end {limit} mm",
                    i + 1
                ),
            );
            viol.limit = limit;
            viol.severity = 1.0 + (v - limit).abs();
            e.violations.push(viol);
        }
    }
    if mode.verdict.has(Reason::Theta1Range) {
        let v = q.theta1.to_degrees();
        let limit = if q.theta1 < lim.theta1_min {
            lim.theta1_min.to_degrees()
        } else {
            lim.theta1_max.to_degrees()
        };
        let mut viol = Violation::plain(
            &e.label,
            Check::Limits,
            v,
            format!(
                "theta1 = {v:.4} deg is outside [{:.4}, {:.4}] deg",
                lim.theta1_min.to_degrees(),
                lim.theta1_max.to_degrees()
            ),
        );
        viol.limit = limit;
        viol.severity = 1.0 + (v - limit).abs();
        e.violations.push(viol);
    }
    if !e.tilt_ok {
        let tilts = rod_tilts(&m.module, &mode.module, &q.rho);
        let (k, t) =
            tilts.iter().enumerate().fold(
                (0, 0.0f64),
                |acc, (k, &t)| if t > acc.1 { (k, t) } else { acc },
            );
        e.violations.push(Violation::over(
            &e.label,
            Check::Limits,
            t.to_degrees(),
            lim.rod_tilt_max.to_degrees(),
            format!("rod {} tilted {:.4} deg", ROD_NAMES[k], t.to_degrees()),
        ));
    }
    let before = e.violations.len();
    let o = singularity_checks(m, th, &mode.module, &q.rho, &e.label, "", &mut e.violations);
    e.obs.push(o);
    e.singular_ok = e.violations.len() == before;
    e
}

pub(super) const ROD_NAMES: [&str; 4] = ["11", "12", "2", "3"];

/// `value > limit`, NaN counting as a failure.
pub(super) fn exceeds(value: f64, limit: f64) -> bool {
    value.is_nan() || value > limit
}

/// `value < limit`, NaN counting as a failure.
pub(super) fn below(value: f64, limit: f64) -> bool {
    value.is_nan() || value < limit
}

/// Amplification factors and parallel margin of the module at (pose, rho).
pub(super) fn singularity_checks(
    m: &Machine,
    th: &Thresholds,
    pose: &ModulePose,
    rho: &Sliders,
    label: &str,
    where_: &str,
    out: &mut Vec<Violation>,
) -> Obs {
    let k = kinetostatics(&m.module, pose, rho);
    let (lo, hi) = (th.get(Th::LambdaMin), th.get(Th::LambdaMax));
    let lmax = k.amplification[0];
    let lmin = k.amplification[2];
    let pm = th.get(Th::ParallelMarginMin);
    let mut worst = None;
    keep_worst(
        &mut worst,
        Obs::over(Check::Singularity, lmax, hi, "largest amplification factor"),
    );
    keep_worst(
        &mut worst,
        Obs::under(
            Check::Singularity,
            lmin,
            lo,
            "smallest amplification factor",
        ),
    );
    keep_worst(
        &mut worst,
        Obs::under(Check::Singularity, k.parallel_margin, pm, "parallel margin"),
    );
    if exceeds(lmax, hi) {
        out.push(Violation::over(
            label,
            Check::Singularity,
            lmax,
            hi,
            format!("{where_}largest amplification factor {lmax:.4} > {hi:.4}"),
        ));
    }
    if below(lmin, lo) {
        out.push(Violation::under(
            label,
            Check::Singularity,
            lmin,
            lo,
            format!("{where_}smallest amplification factor {lmin:.4} < {lo:.4}"),
        ));
    }
    if below(k.parallel_margin, pm) {
        out.push(Violation::under(
            label,
            Check::Singularity,
            k.parallel_margin,
            pm,
            format!("{where_}parallel margin {:.5} < {pm}", k.parallel_margin),
        ));
    }
    worst.unwrap_or(Obs::over(
        Check::Singularity,
        lmax,
        hi,
        "largest amplification factor",
    ))
}

/// The most tilted rod at (pose, rho): its index in [`ROD_NAMES`] and its tilt (rad).
pub(super) fn max_tilt(m: &Machine, pose: &ModulePose, rho: &Sliders) -> (usize, f64) {
    rod_tilts(&m.module, pose, rho).iter().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |acc, (k, &t)| {
            if t > acc.1 { (k, t) } else { acc }
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::ToolPose;

    /// `mode_of_kind` takes the nearest of the modes of the machine's kind, and skips nearer
    /// ones of another kind. Real joints with two modes of the kind are rare (tests/verify_rows.rs
    /// uses one found by a scan), and a tie or a nearer mode of another kind is not known in
    /// any, so the modes are built from the working mode of a real row: copies with the tip
    /// moved along itself to 0.95 T and 0.99 T (so |t + T| would pick the other), a twin of
    /// the second with the same tip (a tie), and two at T itself of another kind: a
    /// configuration not the working one, and alpha with R1 cos(alpha) below r1.
    #[test]
    fn the_row_is_taken_in_the_nearest_mode_of_the_machines_kind() {
        let m = Machine::default_verne();
        let p = Vector3::new(40.0, -25.0, 1000.0);
        let branch =
            *crate::parallel_module::ik::working(&crate::parallel_module::ik::solve(&m, &p))
                .expect("a working branch at the test point");
        let real = machine_fk(&m, &branch.rho, 0.2, -0.3, 100.0);
        let working = *real
            .iter()
            .find(|md| machine_kind(md.config, md.module.alpha, &m))
            .expect("the row's mode of the machine's kind");
        let target = working.tool.tip;
        assert!(
            target.norm() > 100.0,
            "a tip away from the origin: {target}"
        );
        let moved = |scale: f64| MachineFkMode {
            tool: ToolPose {
                tip: target * scale,
                ..working.tool
            },
            ..working
        };
        let (far, near) = (moved(0.95), moved(0.99));
        let other_config = MachineFkMode {
            config: [1, -1, -1],
            ..working
        };
        let crossing = MachineFkMode {
            module: ModulePose {
                alpha: (m.module.r_small1 / m.module.r_big1).acos() + 0.01,
                ..working.module
            },
            ..working
        };
        assert!(!machine_kind(
            other_config.config,
            other_config.module.alpha,
            &m
        ));
        assert!(!machine_kind(crossing.config, crossing.module.alpha, &m));
        // The same tip as `near`, after it: a tie.
        let near_twin = MachineFkMode {
            module: ModulePose {
                alpha: near.module.alpha + 1e-3,
                ..near.module
            },
            ..near
        };
        let mut modes = MachineFkModes::new();
        for md in [other_config, far, crossing, near, near_twin] {
            modes.push(md);
        }
        let index_of = |tip: Option<&Vector3<f64>>| {
            let chosen = mode_of_kind(&modes, &m, tip)?;
            modes.iter().position(|md| std::ptr::eq(md, chosen))
        };
        // Nearest the row's own tip: `near`, and the first of it and its twin.
        assert_eq!(index_of(Some(&target)), Some(3));
        assert_eq!(index_of(Some(&(target * 0.9))), Some(1));
        // No tip to be near: the first of the kind.
        assert_eq!(index_of(None), Some(1));
        let mut none_of_kind = MachineFkModes::new();
        none_of_kind.push(other_config);
        none_of_kind.push(crossing);
        assert!(mode_of_kind(&none_of_kind, &m, Some(&target)).is_none());
    }
}
