//! `verne::verify`'s row checks through the library, without the CLI: the first rows of
//! data/verify (a clean joint table and its intended path), each changed to break one check by
//! a known amount; every finding's check, row, value and limit asserted, and a change within
//! the limit asserted to find nothing. (The CLI's tests/verify.rs covers the same checks through
//! the command; these run with the core crate's tests, so `cargo mutants -f
//! crates/verne/src/verify/row.rs` measures them in about 25 s a mutant, not 1.5 minutes.)

mod verify_data;

use nalgebra::{Rotation3, Unit, Vector3};
use verify_data::*;
use verne::spec::Machine;
use verne::verify::{Check, Joints, PathPoint, Thresholds, Violation};

#[test]
fn the_clean_rows_find_nothing_and_measure_each_check() {
    let m = Machine::default_verne();
    let (summary, found) = run_clean(&m, &Thresholds::default());
    assert!(found.is_empty(), "{found:?}");
    assert_eq!(
        (summary.rows, summary.segments),
        (ROWS as u64, ROWS as u64 - 1)
    );
    // Every row check measured something within its limit.
    for check in [
        Check::TipError,
        Check::AxisError,
        Check::Limits,
        Check::Singularity,
    ] {
        let stats = stats(&summary, check);
        let worst = stats.worst.as_ref().unwrap_or_else(|| panic!("{check:?}"));
        assert_eq!(stats.count, 0);
        assert!(
            worst.value.is_finite() && worst.limit.is_finite(),
            "{worst:?}"
        );
    }
}

#[test]
fn a_tip_moved_beyond_its_limit_is_found_with_its_error() {
    let m = Machine::default_verne();
    let th = Thresholds::default();
    let limit = th.get(verne::verify::Th::TipErrorMm);
    let (joints, path) = clean();
    for (scale, expect) in [(2.0, true), (0.5, false)] {
        let mut path = path.clone();
        let moved = Vector3::new(0.6, -0.8, 0.0) * limit * scale;
        path[9].tip += moved;
        let (_, found) = run(&m, &th, oks(&joints), path);
        let tip = of(&found, Check::TipError);
        if expect {
            assert_eq!(tip.len(), 1, "{found:?}");
            assert_eq!(tip[0].row, "10");
            // The detail gives fk tip - intended: the move reversed.
            if scale == 2.0 {
                assert!(
                    tip[0].detail.contains("= (-0.0060, 0.0080, "),
                    "{}",
                    tip[0].detail
                );
            }
            // The row's own fk tip is within rounding of the clean path's (the clean run finds
            // nothing): the error is the move.
            assert!(
                (tip[0].value - moved.norm()).abs() < 1e-3 * limit,
                "{:?}",
                tip[0]
            );
            assert_eq!(tip[0].limit, limit);
        } else {
            assert!(tip.is_empty(), "{found:?}");
        }
    }
}

#[test]
fn an_axis_turned_beyond_its_limit_is_found_with_its_angle() {
    let m = Machine::default_verne();
    let th = Thresholds::default();
    let limit = th.get(verne::verify::Th::AxisErrorDeg);
    let (joints, path) = clean();
    for (scale, expect) in [(3.0, true), (0.4, false)] {
        let mut path = path.clone();
        let axis = path[4].axis;
        let turn = Unit::new_normalize(axis.cross(&Vector3::x()));
        path[4].axis = Rotation3::from_axis_angle(&turn, (limit * scale).to_radians()) * axis;
        let (_, found) = run(&m, &th, oks(&joints), path);
        let turned = of(&found, Check::AxisError);
        if expect {
            assert_eq!(turned.len(), 1, "{found:?}");
            assert_eq!(turned[0].row, "5");
            assert!(
                (turned[0].value - limit * scale).abs() < 0.05 * limit,
                "{:?}",
                turned[0]
            );
            assert_eq!(turned[0].limit, limit);
        } else {
            assert!(turned.is_empty(), "{found:?}");
        }
    }
}

/// The row of the largest (or smallest) value of a joint, and the value and the next one.
fn extreme(values: &[f64], largest: bool) -> (usize, f64, f64) {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    if largest {
        order.reverse();
    }
    (order[0], values[order[0]], values[order[1]])
}

#[test]
fn strokes_and_the_tilting_range_are_found_with_their_ends() {
    let (joints, _) = clean();
    let rho1: Vec<f64> = joints.iter().map(|q| q.rho.x).collect();
    let rho3: Vec<f64> = joints.iter().map(|q| q.rho.z).collect();
    let theta1: Vec<f64> = joints.iter().map(|q| q.theta1.to_degrees()).collect();
    // A limit set between a joint's most extreme value and the next: that row only, with the
    // value (mm, or degrees for theta1), the limit, the severity and the side. The strokes are
    // compared exactly; theta1 goes through degrees and back.
    for (values, largest, key, words, exact) in [
        (&rho1, true, "rho1_max", ["rho1", "above"], true),
        (&rho3, false, "rho3_min", ["rho3", "below"], true),
        (&theta1, true, "theta1_max", ["theta1", "outside"], false),
        (&theta1, false, "theta1_min", ["theta1", "outside"], false),
    ] {
        let (k, extreme_value, next) = extreme(values, largest);
        let limit = 0.5 * (extreme_value + next);
        let (_, found) = run_clean(
            &machine(&format!("{key} = {limit}")),
            &Thresholds::default(),
        );
        let lim = of(&found, Check::Limits);
        assert_eq!(lim.len(), 1, "{key}: {found:?}");
        let v = lim[0];
        assert_eq!(v.row, (k + 1).to_string(), "{key}");
        if exact {
            assert_eq!((v.value, v.limit), (extreme_value, limit), "{key}");
        } else {
            assert!((v.value - extreme_value).abs() < 1e-9, "{key}: {v:?}");
            assert!((v.limit - limit).abs() < 1e-9, "{key}: {v:?}");
        }
        assert!(
            (v.severity - (1.0 + (extreme_value - limit).abs())).abs() < 1e-9,
            "{key}"
        );
        assert!(
            words.iter().all(|w| v.detail.contains(w)),
            "{key}: {}",
            v.detail
        );
    }
}

#[test]
fn a_rod_tilted_beyond_its_limit_is_found_with_its_tilt() {
    // The clean run's largest tilt (its worst Limits measurement), then a limit just below it.
    let m = Machine::default_verne();
    let (summary, _) = run_clean(&m, &Thresholds::default());
    let stats = stats(&summary, Check::Limits);
    let tilt = stats.worst.as_ref().unwrap().value;
    assert!(tilt > 1.0 && tilt < 60.0, "{tilt}");
    let limit = tilt - 0.01;
    let (_, found) = run_clean(
        &machine(&format!("rod_tilt_max = {limit}")),
        &Thresholds::default(),
    );
    let lim = of(&found, Check::Limits);
    assert!(!lim.is_empty(), "{found:?}");
    let worst = lim
        .iter()
        .max_by(|a, b| a.value.total_cmp(&b.value))
        .unwrap();
    assert!((worst.value - tilt).abs() < 1e-9, "{worst:?}");
    assert!((worst.limit - limit).abs() < 1e-9);
    assert!(worst.detail.starts_with("rod "), "{}", worst.detail);
    assert!(lim.iter().all(|v| v.value > limit - 1e-9), "{lim:?}");
}

#[test]
fn amplification_and_parallel_margin_limits_are_found_with_their_values() {
    let m = Machine::default_verne();
    let (summary, _) = run_clean(&m, &Thresholds::default());
    let stats = stats(&summary, Check::Singularity);
    assert!(stats.worst.is_some());
    // Thresholds that every row breaks: the largest factor above a tiny ceiling, the smallest
    // below a floor above it, the margin below a floor of 1.
    for (name, expect) in [
        ("lambda_max", "largest amplification factor"),
        ("lambda_min", "smallest amplification factor"),
        ("parallel_margin_min", "parallel margin"),
    ] {
        let mut th = Thresholds::default();
        let value = match name {
            "lambda_max" => 0.01,
            "lambda_min" => 50.0,
            _ => 0.999,
        };
        th.set(name, value).unwrap();
        let (_, found) = run_clean(&m, &th);
        let sing: Vec<_> = of(&found, Check::Singularity)
            .into_iter()
            .filter(|v| v.detail.contains(expect))
            .collect();
        // One a row, and none along the segments: a segment is checked between rows within
        // the limits only (the row's finding is the one reported).
        assert_eq!(sing.len(), ROWS, "{name}: {found:?}");
        assert_eq!(of(&found, Check::Singularity).len(), ROWS, "{name}");
        for v in sing {
            assert_eq!(v.limit, value, "{v:?}");
            let broken = match name {
                "lambda_max" => v.value > value,
                _ => v.value < value,
            };
            assert!(broken && v.value.is_finite(), "{v:?}");
        }
    }
}

#[test]
fn joints_that_cannot_be_assembled_a_bad_row_and_a_missing_id_are_findings() {
    let m = Machine::default_verne();
    let (joints, mut path) = clean();
    let mut rows: Vec<Result<Joints, String>> = oks(&joints);
    // Sliders apart: assembled only in modes of other kinds; and too far apart for the rods.
    let mut apart = joints[3];
    apart.rho = Vector3::new(0.0, 1100.0, 0.0);
    rows[3] = Ok(apart);
    apart.rho = Vector3::new(0.0, 5000.0, 0.0);
    rows[12] = Ok(apart);
    rows[7] = Err("rho2: `x` is not a number".into());
    // The path has no row 20 (the joint row 20 has no intended pose).
    path.remove(19);
    let path_rows = Rows {
        name: "path",
        items: path
            .into_iter()
            .enumerate()
            .map(|(k, v)| item(if k >= 19 { k + 1 } else { k }, Ok(v)))
            .collect(),
    };
    let (summary, found) = run_sources(
        &m,
        &Thresholds::default(),
        numbered("joints", rows),
        path_rows,
    );
    let branch = of(&found, Check::Branch);
    assert_eq!(branch.len(), 2, "{found:?}");
    assert_eq!((branch[0].row.as_str(), branch[0].value), ("4", 4.0));
    assert!(
        branch[0]
            .detail
            .contains("no assembly mode of the machine's kind")
            && branch[0].detail.contains("4 real"),
        "{}",
        branch[0].detail
    );
    assert_eq!((branch[1].row.as_str(), branch[1].value), ("13", 0.0));
    assert!(
        branch[1].detail.contains("cannot be assembled"),
        "{}",
        branch[1].detail
    );
    let input = of(&found, Check::Input);
    assert_eq!(input.len(), 1, "{found:?}");
    assert_eq!(input[0].row, "8");
    assert!(input[0].detail.contains("line 9") && input[0].detail.contains("rho2"));
    let pairing = of(&found, Check::Pairing);
    assert_eq!(pairing.len(), 1, "{found:?}");
    assert_eq!(pairing[0].row, "20");
    assert!(pairing[0].detail.contains("`20`"), "{}", pairing[0].detail);
    // Rows 4, 8 and 13 leave the segments on both sides unchecked (6), the unpaired row 20
    // the one before it (7); the gap after it starts the chain anew (no segment 20-21):
    // 29 = 21 checked + 7 skipped + 1 not formed.
    assert_eq!(
        (summary.segments, summary.segments_skipped),
        (21, 7),
        "{summary:?}"
    );
    assert_eq!(found.len(), 4, "{found:?}");
}

/// A value exactly at its limit is within it: the largest tip error of the clean rows as the
/// tip limit, and the smallest amplification factor as its floor, find nothing; a limit one
/// step (ulp) inside finds that row.
#[test]
fn a_value_exactly_at_its_limit_is_within_it() {
    let m = Machine::default_verne();
    let worst_of = |th: &Thresholds, check: Check| -> Violation {
        let (summary, found) = run_clean(&m, th);
        assert!(found.is_empty(), "{found:?}");
        let stats = stats(&summary, check);
        stats.worst.clone().unwrap()
    };
    // The tip: exceeds(value, limit) is value > limit.
    let tip = worst_of(&Thresholds::default(), Check::TipError).value;
    let mut th = Thresholds::default();
    th.set("tip_error_mm", tip).unwrap();
    assert!(run_clean(&m, &th).1.is_empty());
    th.set("tip_error_mm", tip.next_down()).unwrap();
    let found = run_clean(&m, &th).1;
    assert_eq!(of(&found, Check::TipError).len(), 1, "{found:?}");
    // The smallest factor: below(value, limit) is value < limit. Its observation is the worst
    // singularity one when the other two limits are far away.
    let mut th = Thresholds::default();
    th.set("lambda_max", 1e9).unwrap();
    th.set("parallel_margin_min", 1e-12).unwrap();
    let smallest = worst_of(&th, Check::Singularity);
    assert!(
        smallest.detail.contains("smallest amplification factor"),
        "{smallest:?}"
    );
    th.set("lambda_min", smallest.value).unwrap();
    assert!(run_clean(&m, &th).1.is_empty());
    th.set("lambda_min", smallest.value.next_up()).unwrap();
    let found = run_clean(&m, &th).1;
    assert!(!of(&found, Check::Singularity).is_empty(), "{found:?}");
}

/// Joints with two assembly modes of the machine's kind: the row is checked in the mode nearest
/// its intended tip, so either mode's pose as the intended one finds no tip or axis error.
#[test]
fn the_mode_nearest_the_intended_tip_is_checked() {
    let m = Machine::default_verne();
    let q = joints_with_two_modes();
    let kind = modes_of_the_machine_kind(&m, &q);
    assert_eq!(kind.len(), 2, "{kind:?}");
    assert!((kind[0].tool.tip - kind[1].tool.tip).norm() > 10.0);
    for md in &kind {
        let (_, found) = run(
            &m,
            &Thresholds::default(),
            vec![Ok(q)],
            vec![PathPoint::new(md.tool.tip, md.axis)],
        );
        for check in [Check::TipError, Check::AxisError, Check::Branch] {
            assert!(of(&found, check).is_empty(), "{check:?}: {found:?}");
        }
    }
}
