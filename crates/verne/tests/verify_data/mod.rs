//! What the in-memory tests of `verne::verify` share (`verify_rows.rs`, `verify_segments.rs`):
//! the first rows of data/verify as joints and path points, sources that hold rows in memory,
//! and a run that collects the findings. Each test file uses part of it.
#![allow(dead_code)]

use std::collections::VecDeque;

use nalgebra::Vector3;
use verne::machine::{MachineFkMode, machine_fk};
use verne::parallel_module::branches::WORKING_CONFIG;
use verne::spec::Machine;
use verne::verify::{
    Check, CheckStats, Item, JointSource, Joints, PairingError, PathPoint, RowSource, Summary,
    Thresholds, VerifyOptions, Violation, verify,
};

/// Rows of data/verify read here.
pub const ROWS: usize = 30;

#[derive(Debug)]
pub struct Fail(pub String);

impl From<PairingError> for Fail {
    fn from(e: PairingError) -> Fail {
        Fail(format!("{e:?}"))
    }
}

/// Rows held in memory.
pub struct Rows<T> {
    pub name: &'static str,
    pub items: VecDeque<Item<T>>,
}

impl<T> RowSource for Rows<T> {
    type Row = T;
    type Error = Fail;
    fn name(&self) -> &str {
        self.name
    }
    fn has_id(&self) -> bool {
        true
    }
    fn next_item(&mut self) -> Result<Option<Item<T>>, Fail> {
        Ok(self.items.pop_front())
    }
}

impl JointSource for Rows<Joints> {
    fn timed(&self) -> bool {
        true
    }
}

/// The first `ROWS` data rows of a CSV of data/verify, as numbers (the id column first).
pub fn table(file: &str) -> Vec<Vec<f64>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/verify/");
    let text = std::fs::read_to_string(format!("{path}{file}")).unwrap();
    text.lines()
        .skip(1)
        .take(ROWS)
        .map(|l| l.split(',').map(|c| c.trim().parse().unwrap()).collect())
        .collect()
}

pub fn item<T>(k: usize, value: Result<T, String>) -> Item<T> {
    Item {
        index: k as u64 + 1,
        line: k as u64 + 2,
        id: Some((k + 1).to_string()),
        value,
        tag: None,
    }
}

/// The clean inputs: joints (id, t, rho1..3, theta1, theta2 in degrees) and path (id, tip,
/// axis).
pub fn clean() -> (Vec<Joints>, Vec<PathPoint>) {
    let joints = table("joints.csv")
        .iter()
        .map(|r| Joints {
            rho: Vector3::new(r[2], r[3], r[4]),
            theta1: r[5].to_radians(),
            theta2: r[6].to_radians(),
            t: Some(r[1]),
            feed: None,
            duration: None,
            rapid: false,
        })
        .collect();
    let path = table("path.csv")
        .iter()
        .map(|r| {
            PathPoint::new(
                Vector3::new(r[1], r[2], r[3]),
                Vector3::new(r[4], r[5], r[6]),
            )
        })
        .collect();
    (joints, path)
}

/// Joint rows, all usable.
pub fn oks(joints: &[Joints]) -> Vec<Result<Joints, String>> {
    joints.iter().copied().map(Ok).collect()
}

/// Rows numbered 1, 2, ... with ids "1", "2", ...
pub fn numbered<T>(name: &'static str, rows: Vec<Result<T, String>>) -> Rows<T> {
    Rows {
        name,
        items: rows
            .into_iter()
            .enumerate()
            .map(|(k, v)| item(k, v))
            .collect(),
    }
}

/// Runs verify on the rows (a joint row replaced by an error where `joints` holds one).
pub fn run(
    m: &Machine,
    th: &Thresholds,
    joints: Vec<Result<Joints, String>>,
    path: Vec<PathPoint>,
) -> (Summary, Vec<Violation>) {
    run_sources(
        m,
        th,
        numbered("joints", joints),
        numbered("path", path.into_iter().map(Ok).collect()),
    )
}

/// Runs verify on two in-memory sources and collects the findings.
pub fn run_sources(
    m: &Machine,
    th: &Thresholds,
    mut joints: Rows<Joints>,
    mut path: Rows<PathPoint>,
) -> (Summary, Vec<Violation>) {
    let opt = VerifyOptions {
        thresholds: *th,
        tool_length: m.tool_length,
    };
    let mut found = Vec::new();
    let summary = verify(m, &opt, &mut joints, &mut path, &mut |v: &Violation| {
        found.push(v.clone());
        Ok::<(), Fail>(())
    })
    .unwrap_or_else(|Fail(e)| panic!("{e}"));
    (summary, found)
}

pub fn run_clean(m: &Machine, th: &Thresholds) -> (Summary, Vec<Violation>) {
    let (joints, path) = clean();
    run(m, th, joints.into_iter().map(Ok).collect(), path)
}

pub fn of(found: &[Violation], check: Check) -> Vec<&Violation> {
    found.iter().filter(|v| v.check == check).collect()
}

pub fn machine(limits: &str) -> Machine {
    Machine::from_toml_str(&format!("base = \"verne\"\n[limits]\n{limits}\n"), "test").unwrap()
}

/// What the summary measured for `check`.
pub fn stats(summary: &Summary, check: Check) -> &CheckStats {
    &summary.checks.iter().find(|(c, _)| *c == check).unwrap().1
}

/// Joints at rest: no time, feed or duration.
pub fn at_rest(rho: Vector3<f64>, theta1: f64, theta2: f64) -> Joints {
    Joints {
        rho,
        theta1,
        theta2,
        t: None,
        feed: None,
        duration: None,
        rapid: false,
    }
}

/// The assembly modes of the machine's kind (verify's rule: the working configuration, rods of
/// leg I not crossing) at joints `q`.
pub fn modes_of_the_machine_kind(m: &Machine, q: &Joints) -> Vec<MachineFkMode> {
    machine_fk(m, &q.rho, q.theta1, q.theta2, m.tool_length)
        .into_iter()
        .filter(|md| {
            md.config == WORKING_CONFIG
                && m.module.r_big1 * md.module.alpha.cos() > m.module.r_small1
        })
        .collect()
}

/// Joints with two assembly modes of the machine's kind, their tips far apart (a thin set: 9 of
/// 200,000 random slider triples, found by a scan).
pub fn joints_with_two_modes() -> Joints {
    at_rest(
        Vector3::new(993.8134583763522, 36.74643683672117, 373.9948975572779),
        0.1,
        0.2,
    )
}
