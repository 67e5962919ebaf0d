//! `verne::verify_observed`: the observer receives one observation per joint row, in row order,
//! each before that row's findings, and its values are the ones the checks judged (the
//! findings' values, the summary's worst values, the joints' rates from the table).

mod verify_data;

use std::collections::VecDeque;

use nalgebra::Vector3;
use verify_data::*;
use verne::parallel_module::equations::residual_mm;
use verne::spec::Machine;
use verne::verify::{
    Check, Joints, PathPoint, RowObservation, Thresholds, VerifyOptions, Violation, verify_observed,
};

/// What reached the caller, in order.
#[derive(Debug)]
enum Event {
    Row(Box<RowObservation>),
    Finding(Violation),
}

/// The first `rows` data rows of a CSV of data/verify (the id column first).
fn rows_of(file: &str, rows: usize) -> Vec<Vec<f64>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/verify/");
    let text = std::fs::read_to_string(format!("{path}{file}")).unwrap();
    text.lines()
        .skip(1)
        .take(rows)
        .map(|l| l.split(',').map(|c| c.trim().parse().unwrap()).collect())
        .collect()
}

fn inputs(joints_file: &str, rows: usize) -> (Rows<Joints>, Rows<PathPoint>) {
    let joints = rows_of(joints_file, rows)
        .iter()
        .map(|r| {
            Ok(Joints {
                rho: Vector3::new(r[2], r[3], r[4]),
                theta1: r[5].to_radians(),
                theta2: r[6].to_radians(),
                t: Some(r[1]),
                feed: None,
                duration: None,
                rapid: false,
            })
        })
        .collect();
    let path = rows_of("path.csv", rows)
        .iter()
        .map(|r| {
            Ok(PathPoint::new(
                Vector3::new(r[1], r[2], r[3]),
                Vector3::new(r[4], r[5], r[6]),
            ))
        })
        .collect();
    (numbered("joints", joints), numbered("path", path))
}

/// Runs with an observer (or without) and returns the summary and what reached the caller.
fn observed(
    m: &Machine,
    mut joints: Rows<Joints>,
    mut path: Rows<PathPoint>,
    observe: bool,
) -> (verne::verify::Summary, Vec<Event>) {
    let opt = VerifyOptions {
        thresholds: Thresholds::default(),
        tool_length: m.tool_length,
    };
    let events = std::sync::Mutex::new(Vec::new());
    let mut on_row =
        |o: &RowObservation| events.lock().unwrap().push(Event::Row(Box::new(o.clone())));
    let summary = verify_observed(
        m,
        &opt,
        &mut joints,
        &mut path,
        &mut |v: &Violation| {
            events.lock().unwrap().push(Event::Finding(v.clone()));
            Ok::<(), Fail>(())
        },
        if observe { Some(&mut on_row) } else { None },
    )
    .unwrap_or_else(|Fail(e)| panic!("{e}"));
    (summary, events.into_inner().unwrap())
}

fn findings(events: &[Event]) -> Vec<Violation> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Finding(v) => Some(v.clone()),
            Event::Row(_) => None,
        })
        .collect()
}

fn rows(events: &[Event]) -> Vec<&RowObservation> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Row(o) => Some(&**o),
            Event::Finding(_) => None,
        })
        .collect()
}

/// 2100 rows of data/verify/joints_defects.csv (three batches of the row engine, four of its
/// defects): one observation per row in order; every finding comes after its own row's
/// observation and before the next row's; the findings are the same as without an observer.
#[test]
fn each_row_is_observed_in_order_before_its_findings() {
    let m = Machine::default_verne();
    let n = 2100;
    let (j, p) = inputs("joints_defects.csv", n);
    let (summary, events) = observed(&m, j, p, true);
    let (j, p) = inputs("joints_defects.csv", n);
    let (plain_summary, plain) = observed(&m, j, p, false);
    assert_eq!(findings(&events), findings(&plain));
    assert_eq!(summary, plain_summary);
    assert!(rows(&plain).is_empty());
    let seen = rows(&events);
    assert_eq!(seen.len(), n);
    for (k, o) in seen.iter().enumerate() {
        assert_eq!(o.index, k as u64 + 1);
        assert_eq!(o.label, (k + 1).to_string());
        assert_eq!(o.joints_line, k as u64 + 2);
    }
    // A finding's row is the row observed last before it (a stop's finding may name the row
    // before, whose segment it ends).
    let mut last: Option<&RowObservation> = None;
    let mut previous: Option<&RowObservation> = None;
    let mut placed = 0;
    for e in &events {
        match e {
            Event::Row(o) => {
                previous = last;
                last = Some(o);
            }
            Event::Finding(v) => {
                let at = [last, previous].map(|o| o.map(|o| o.label.as_str()));
                assert!(at.contains(&Some(v.row.as_str())), "{v:?} after {at:?}");
                placed += 1;
            }
        }
    }
    assert!(placed >= 7, "{placed} findings");
    // The defect of row 1000 (rho1 + 0.02 mm) is a tip error whose value is the observation's.
    let tip = findings(&events)
        .into_iter()
        .find(|v| v.check == Check::TipError && v.row == "1000")
        .expect("row 1000's tip error");
    let pose = seen[999].pose.expect("row 1000 has an assembly mode");
    assert_eq!(pose.tip_error_mm, tip.value);
    assert!(pose.tip_error_mm > 0.02, "{pose:?}");
    // Row 500 (theta1 with the wrong sign) fails: its segments are not checked.
    assert!(seen[499].segment.is_none() && seen[500].segment.is_none());
    assert!(seen[498].segment.is_some());
}

/// The clean rows: the module pose observed assembles the row's sliders; the rates are the
/// joints' change over the table's dt; the largest values observed are the summary's worst of
/// each check (tip, axis, chord, rod tilt, amplification, speed, acceleration).
#[test]
fn the_observed_values_are_the_checks_values() {
    let m = Machine::default_verne();
    let (j, p) = inputs("joints.csv", ROWS);
    let (summary, events) = observed(&m, j, p, true);
    assert!(findings(&events).is_empty());
    let seen = rows(&events);
    assert_eq!(seen.len(), ROWS);
    assert!(seen[0].segment.is_none());
    let worst = |check| stats(&summary, check).worst.clone().unwrap().value;
    let largest = |f: &dyn Fn(&RowObservation) -> Option<f64>| {
        seen.iter()
            .filter_map(|o| f(o))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    for o in &seen {
        let q = o.joints.unwrap();
        let pose = o.pose.unwrap();
        assert!(residual_mm(&m.module, &pose.module, &q.rho) < 1e-6, "{o:?}");
        let intended = o.intended.unwrap();
        assert!(((pose.tip - intended.tip).norm() - pose.tip_error_mm).abs() < 1e-12);
    }
    for k in 1..ROWS {
        let (a, b) = (seen[k - 1].joints.unwrap(), seen[k].joints.unwrap());
        let s = seen[k].segment.unwrap();
        let dt = b.t.unwrap() - a.t.unwrap();
        assert_eq!(s.dt, Some(dt));
        let rates = s.rates.unwrap();
        assert!((rates[0] - (b.rho.x - a.rho.x) / dt).abs() < 1e-9);
        assert!((rates[4] - (b.theta2 - a.theta2) / dt).abs() < 1e-9);
    }
    assert_eq!(
        largest(&|o| o.pose.map(|p| p.tip_error_mm)),
        worst(Check::TipError)
    );
    assert_eq!(
        largest(&|o| o.pose.map(|p| p.axis_error_deg)),
        worst(Check::AxisError)
    );
    assert_eq!(
        largest(&|o| o.segment.and_then(|s| s.chord_error_mm)),
        worst(Check::ChordError)
    );
    assert_eq!(
        largest(&|o| o.pose.map(|p| p.amplification[0])),
        worst(Check::Singularity)
    );
    // The summary's worst speed and acceleration are of a joint in its unit (theta2 here,
    // deg/s and deg/s^2).
    assert_eq!(
        largest(&|o| o
            .segment
            .and_then(|s| s.rates)
            .map(|r| r[4].abs().to_degrees())),
        worst(Check::Velocity)
    );
    assert_eq!(
        largest(&|o| o
            .segment
            .and_then(|s| s.acceleration)
            .map(|r| r[4].abs().to_degrees())),
        worst(Check::Acceleration)
    );
}

/// A source of no rows observes nothing and reports nothing.
#[test]
fn no_rows_no_observation() {
    let m = Machine::default_verne();
    let joints = Rows {
        name: "joints",
        items: VecDeque::new(),
    };
    let path = Rows {
        name: "path",
        items: VecDeque::new(),
    };
    let (summary, events) = observed(&m, joints, path, true);
    assert_eq!(summary.rows, 0);
    assert!(events.is_empty());
}
