//! The calibration against machines built here: synthetic machines (a perturbed machine file)
//! whose readings come from their own forward kinematics ([`super::synthetic`]), so that the
//! fitted parameters can be compared with the truth; the plan's predicted sigmas against a
//! Monte Carlo of fits; bad input refused.

use nalgebra::{DMatrix, DVector, Rotation3, Vector3};

use super::model::{Device, Instrument, Observed};
use super::params::Param;
use super::plan::{PlanOptions, plan};
use super::synthetic::{TYPICAL, gaussian, joints, measure, perturbed};
use super::*;
use crate::math::test_rng::lcg;
use crate::spec::Machine;

/// The noise of the synthetic tracker (mm), the 10 um.
const NOISE_MM: f64 = 0.01;

/// A random instrument frame: any rotation, a few metres away.
fn random_instrument(u: &mut impl FnMut() -> f64) -> Instrument {
    let axis = Vector3::new(gaussian(u), gaussian(u), gaussian(u)).normalize();
    Instrument {
        rotation: Rotation3::new(axis * (std::f64::consts::PI * u())),
        translation: Vector3::new(4000.0 * u() - 2000.0, 4000.0 * u() - 2000.0, 2000.0 * u()),
        ball: Vector3::new(super::plan::BALL_X_MM, 0.0, 0.0),
    }
}

/// The truth moved along the combinations the readings cannot see until the held parameters
/// are at their nominal values: what a fit can recover (the same readings, exactly).
fn truth_in_gauge(truth: &Machine, nominal: &Machine, held: &[Held]) -> Machine {
    let n = held.len();
    if n == 0 {
        return truth.clone();
    }
    // (combination k)'s move of held parameter i, stored units.
    let coef = |k: usize, p: Param| {
        held[k]
            .combination
            .iter()
            .find(|(q, _)| *q == p)
            .map_or(0.0, |(q, c)| q.stored(*c))
    };
    let a = DMatrix::from_fn(n, n, |i, k| coef(k, held[i].param));
    let b = DVector::from_fn(n, |i, _| {
        held[i].param.value(nominal) - held[i].param.value(truth)
    });
    let c = a.lu().solve(&b).expect("independent combinations");
    let mut out = truth.clone();
    for (k, h) in held.iter().enumerate() {
        for &(p, coefficient) in &h.combination {
            p.add_to(&mut out, c[k] * p.stored(coefficient));
        }
    }
    out
}

/// 200 synthetic machines (lengths +-0.5 mm, offsets +-0.3 mm and 0.2 degrees), each read by a
/// tracker at 80 poses with 10 um noise from a random frame: every identified parameter
/// within 3 predicted sigmas of the truth (brought to the fit's gauge) in at least 99 % of
/// cases; the four structural combinations named every time and nothing else held; the
/// pooled hold-out RMS within 10 % of the noise.
#[test]
fn synthetic_machines_are_recovered_within_their_sigmas() {
    let nominal = Machine::default_verne();
    let mut u = lcg(0xca1b_0001);
    let (mut within, mut checked) = (0usize, 0usize);
    let (mut holdout_sq, mut holdout_n) = (0.0, 0.0);
    let trials = 200;
    for trial in 0..trials {
        let truth = perturbed(&nominal, &TYPICAL, 1000 + trial);
        let inst = random_instrument(&mut u);
        let j = joints(&nominal, Device::Tracker, 80, 2000 + trial);
        let rows = measure(
            &truth,
            &j,
            Device::Tracker,
            &inst,
            NOISE_MM,
            0.0,
            false,
            3000 + trial,
        );
        let c = calibrate(&nominal, &rows, &Options::default()).expect("a calibration");
        let held: Vec<Param> = c.identifiability.held.iter().map(|h| h.param).collect();
        assert_eq!(
            held,
            [Param::LowerD1, Param::LowerD2, Param::D2, Param::Rho3Zero],
            "trial {trial}"
        );
        for (h, words) in c.identifiability.held.iter().zip([
            "only as D1 - d1",
            "only as D2 - d2",
            "instrument frame's x",
            "instrument frame's z",
        ]) {
            assert!(h.why.contains(words), "{}", h.why);
        }
        assert!(c.weak.is_empty(), "trial {trial}: {:?}", c.weak);
        let gauge = truth_in_gauge(&truth, &nominal, &c.identifiability.held);
        for e in &c.estimates {
            let Some(sigma) = e.sigma else { continue };
            checked += 1;
            if (e.value - e.param.value(&gauge)).abs() <= 3.0 * sigma {
                within += 1;
            }
        }
        let h = c.holdout.expect("a hold-out");
        let n = 3.0 * rows.len() as f64;
        holdout_sq += h.rms_mm * h.rms_mm * n;
        holdout_n += n;
    }
    let share = within as f64 / checked as f64;
    assert!(share >= 0.99, "{within} of {checked} within 3 sigma");
    let pooled = (holdout_sq / holdout_n).sqrt();
    assert!(
        (pooled / NOISE_MM - 1.0).abs() <= 0.1,
        "hold-out RMS {pooled}"
    );
}

/// The plan's predicted sigmas are those of fits: 150 fits of readings with 10 um noise at the
/// planned poses of the nominal machine, the spread of each identified parameter within 25 %
/// of its predicted sigma (the spread of a sample of 150 is within 17 % at 3 sigma).
#[test]
fn the_plans_sigmas_are_those_of_fits() {
    let nominal = Machine::default_verne();
    let p = plan(
        &nominal,
        &PlanOptions {
            poses: 30,
            candidates: 600,
            random_sets: 10,
            ..PlanOptions::default()
        },
    )
    .expect("a plan");
    let joints: Vec<_> = p.rows.iter().map(|r| (r.rho, r.theta)).collect();
    let mut u = lcg(0xca1b_0002);
    let runs = 150;
    let mut values: Vec<Vec<f64>> = vec![Vec::new(); p.sigmas.len()];
    for run in 0..runs {
        let inst = random_instrument(&mut u);
        let rows = measure(
            &nominal,
            &joints,
            Device::Tracker,
            &inst,
            NOISE_MM,
            0.0,
            false,
            run,
        );
        let options = Options {
            folds: 0,
            ..Options::default()
        };
        let c = calibrate(&nominal, &rows, &options).expect("a calibration");
        for (k, (param, _)) in p.sigmas.iter().enumerate() {
            let e = c.estimates.iter().find(|e| e.param == *param).unwrap();
            values[k].push(e.value);
        }
    }
    for (k, (param, sigma)) in p.sigmas.iter().enumerate() {
        let v = &values[k];
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
        assert!(
            (sd / sigma - 1.0).abs() <= 0.25,
            "{}: spread {sd} predicted {sigma}",
            param.key()
        );
    }
}

/// 30 planned poses give a worst sigma at most 0.6 of the median of random sets of 30 drawn
/// from the same candidates (the sigmas of each set computed from its own readings).
#[test]
fn a_plan_beats_random_poses() {
    let nominal = Machine::default_verne();
    let p = plan(
        &nominal,
        &PlanOptions {
            poses: 30,
            ..PlanOptions::default()
        },
    )
    .expect("a plan");
    assert!(
        p.worst_mm <= 0.6 * p.random_worst_mm,
        "{} vs {}",
        p.worst_mm,
        p.random_worst_mm
    );
    // The probe's heights cannot determine R1: the plan says so.
    let probe = plan(
        &nominal,
        &PlanOptions {
            device: Device::Probe,
            poses: 30,
            random_sets: 5,
            ..PlanOptions::default()
        },
    )
    .expect("a plan");
    assert!(
        probe
            .undetermined
            .iter()
            .any(|(q, s)| *q == Param::R1 && *s > 10.0),
        "{:?}",
        probe.undetermined
    );
}

/// Bad input gives no machine: too few rows, a NaN, joints that are not the machine's, a
/// reading far from any pose, a fit beyond the prior bounds, a calibrated machine that is not
/// valid; each names its lines.
#[test]
fn bad_input_is_refused() {
    let nominal = Machine::default_verne();
    let truth = perturbed(&nominal, &TYPICAL, 5);
    let mut u = lcg(0xca1b_0003);
    let inst = random_instrument(&mut u);
    let j = joints(&nominal, Device::Tracker, 40, 6);
    let rows = measure(&truth, &j, Device::Tracker, &inst, NOISE_MM, 0.0, false, 7);
    let options = Options::default();
    // Too few.
    match calibrate(&nominal, &rows[..6], &options) {
        Err(CalibrationError::TooFew {
            readings: 18,
            unknowns: 21,
        }) => {}
        other => panic!("{other:?}"),
    }
    // A NaN.
    let mut bad = rows.clone();
    bad[3].rho.y = f64::NAN;
    match calibrate(&nominal, &bad, &options) {
        Err(CalibrationError::Rows(r)) => assert_eq!(r[0].line, bad[3].line),
        other => panic!("{other:?}"),
    }
    // Joints with no assembly mode, and a reading 40 mm off.
    let mut bad = rows.clone();
    bad[5].rho.x = 5000.0;
    match calibrate(&nominal, &bad, &options) {
        Err(CalibrationError::Rows(r)) => {
            assert_eq!(r[0].line, bad[5].line);
            assert!(
                r[0].message.contains("no assembly mode"),
                "{}",
                r[0].message
            );
        }
        other => panic!("{other:?}"),
    }
    let mut bad = rows.clone();
    if let Observed::Tip { tip, .. } = &mut bad[8].observed {
        tip.x += 40.0;
    }
    match calibrate(&nominal, &bad, &options) {
        Err(CalibrationError::Rows(r)) => {
            assert_eq!(r.len(), 1);
            assert_eq!(r[0].line, bad[8].line);
            assert!(
                r[0].message.contains("far from any pose"),
                "{}",
                r[0].message
            );
        }
        other => panic!("{other:?}"),
    }
    // A reading 0.5 mm off: an outlier after the fit.
    let mut bad = rows.clone();
    if let Observed::Tip { tip, .. } = &mut bad[9].observed {
        tip.y += 0.5;
    }
    match calibrate(&nominal, &bad, &options) {
        Err(CalibrationError::Rows(r)) => assert_eq!(r[0].line, bad[9].line),
        other => panic!("{other:?}"),
    }
    // A machine 8 mm longer in L1: refused, unless allowed.
    let mut long = truth.clone();
    long.module.l1 += 8.0;
    let rows_long = measure(&long, &j, Device::Tracker, &inst, NOISE_MM, 0.0, false, 8);
    match calibrate(&nominal, &rows_long, &options) {
        Err(CalibrationError::Prior(list)) => {
            assert!(
                list.iter()
                    .any(|(p, change, _, _)| *p == Param::L1 && *change > 7.0)
            );
        }
        other => panic!("{other:?}"),
    }
    let allowed = Options {
        allow_large: true,
        ..Options::default()
    };
    assert!(calibrate(&nominal, &rows_long, &allowed).is_ok());
    // Slider 1 of the nominal has a stroke of 2 mm, the truth a zero offset of 3 mm (within the
    // prior bound): the calibrated machine file would not be valid.
    let mut short = nominal.clone();
    short.limits.rho_min[0] = 300.0;
    short.limits.rho_max[0] = 302.0;
    let mut offset = nominal.clone();
    offset.module.rho_zero = [3.0, 0.0, 0.0];
    let rows_off = measure(&offset, &j, Device::Tracker, &inst, NOISE_MM, 0.0, false, 9);
    match calibrate(&short, &rows_off, &options) {
        Err(CalibrationError::Invalid(e)) => {
            assert!(e.to_string().contains("zeros.rho1"), "{e}")
        }
        other => panic!("{other:?}"),
    }
}

/// The calibrated machine reproduces what it was not fitted to, the instrument's frame taken as
/// fitted: from a tracker's tool tips, the tool tips of other joints (the truth's forward
/// kinematics) within 3 times the noise; from the module alone's platform points, the truth's
/// joints of other platform points (the calibrated inverse kinematics) within 3 times the noise.
/// (A tracker reading tool tips fixes the platform point only to the tool length's sigma, some
/// 0.05 mm: the joints of a platform point need readings of the platform point.)
#[test]
fn the_calibrated_machine_reproduces_held_out_poses() {
    let nominal = Machine::default_verne();
    let truth = perturbed(&nominal, &TYPICAL, 11);
    let mut u = lcg(0xca1b_0004);
    let inst = random_instrument(&mut u);
    let held_out = joints(&nominal, Device::Tracker, 50, 14);
    let truth_pose = |rho: &crate::parallel_module::equations::Sliders| {
        let modes = crate::parallel_module::fk::solve(&truth, rho);
        crate::parallel_module::fk::working(&modes).unwrap().pose
    };
    for device in [Device::Tracker, Device::Platform] {
        let j = joints(&nominal, device, 100, 12);
        let rows = measure(&truth, &j, device, &inst, NOISE_MM, 0.0, false, 13);
        let c = calibrate(&nominal, &rows, &Options::default()).expect("a calibration");
        let fitted = c.instruments[0];
        let mut worst = 0.0f64;
        for (rho, _) in &held_out {
            let pose = truth_pose(rho);
            match device {
                Device::Tracker => {
                    let tip = pose.p + truth.tool_length * super::model::platform_axis(pose.alpha);
                    let seen = inst.rotation * tip + inst.translation;
                    let modes = crate::parallel_module::fk::solve(&c.machine, rho);
                    let cal = crate::parallel_module::fk::working(&modes).unwrap().pose;
                    let cal_tip = super::model::tool_tip(&c.machine, &cal);
                    worst =
                        worst.max((fitted.rotation * cal_tip + fitted.translation - seen).amax());
                }
                _ => {
                    let seen = inst.rotation * pose.p + inst.translation;
                    let p_cal = fitted.rotation.inverse() * (seen - fitted.translation);
                    let b = crate::parallel_module::ik::working_fast(&c.machine, &p_cal)
                        .expect("a working branch");
                    worst = worst.max((b.rho - rho).amax());
                }
            }
        }
        assert!(worst <= 3.0 * NOISE_MM, "{device:?}: {worst}");
    }
}
