//! `verne verify`: checks a joint table written by a postprocessor (rho1, rho2, rho3, theta1,
//! theta2) against the tool path it was made from, row by row and along each segment between
//! rows with the joints interpolated linearly, as a controller does. The checks, their
//! thresholds and the report are described in docs/verify.md.
//!
//! - Rows: the machine's forward kinematics (AIM 2007 section III.D, eq. (26)) in the working
//!   assembly mode (IFToMM 2007 section VI: s = -1,-1,-1, rods of leg I not crossing) against
//!   the intended tip and tool axis; joint, stroke and rod-tilt limits; the velocity
//!   amplification factors of the module against the bounds 1/3 < lambda < 3 of the comparative
//!   study (Wenger, Gosselin, Chablat 2001, eq. (4)) and the parallel margin.
//! - Segments: a change of branch (orientation solution, assembly mode), theta2 flips, joint
//!   jumps, joint velocities and accelerations (with a `t` or `feed` column), and, along the
//!   interpolated joints, the assembly mode, rod tilts, singularity proximity and the chordal
//!   error at the midpoint.
//!
//! Streaming, on the row engine of the streaming commands ([`crate::stream`]): rows are paired
//! in batches of [`BATCH_ROWS`]; while one batch is read, the previous one is solved in parallel
//! (rayon) and the one before is reported, in input order, so memory does not grow with the
//! files and results do not depend on the number of threads. Only the previous row and segment
//! are kept between batches.

pub mod contour;
mod findings;
mod row;
mod segment;
mod thresholds;

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt;

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::error::shown;
use crate::machine::orientation::ROTARY_SINGULAR_CONE_RAD;
use crate::machine::{MachineFkModes, machine_fk, tool_pose_eq26};
use crate::par::*;
use crate::parallel_module::branches::{Config, Reason, WORKING_CONFIG, config_of};
use crate::parallel_module::equations::{ModulePose, Sliders, polish_pose, residual_mm, rod_tilts};
use crate::parallel_module::ik::wrap_angle;
use crate::parallel_module::kinetostatics::kinetostatics;
use crate::spec::Machine;
use crate::tolerance::ACCEPT_RESIDUAL_MM;

pub use findings::{Check, CheckStats, Summary, Violation};
pub use thresholds::{
    THRESHOLDS, Th, ThresholdSpec, Thresholds, check_threshold_value, threshold_index,
};

use row::eval_row;
use segment::eval_segment;

/// Rows read, solved in parallel and reported together: bounds memory and amortises the thread
/// hand-off.
pub const BATCH_ROWS: usize = 1024;

/// Largest slider travel (mm) between two samples of a segment's interior. Rod tilts change by
/// about 1/L rad per mm of slider (L ~ 900 mm: 0.06 deg/mm) and the worst sample is refined by a
/// parabola, so 2 mm sampling places a mid-segment maximum within ~1e-4 deg.
pub const SEGMENT_SAMPLE_MM: f64 = 2.0;

/// Most interior samples of one segment (a 2 m slider move at [`SEGMENT_SAMPLE_MM`]).
pub const MAX_SEGMENT_SAMPLES: usize = 1024;

/// The module pose tracked along a segment must arrive at the end row's pose within this (mm,
/// and rad times R2 for alpha); otherwise the joints changed assembly mode on the way.
pub const TRACK_ARRIVAL_MM: f64 = 1e-5;

/// An orientation solution is labelled only when |phi1| is at least this (rad): inside this cone
/// around the table normal both solutions are the same axis up to the input's resolution
/// (`orientation::ROTARY_SINGULAR_CONE_RAD`).
pub const ORIENTATION_LABEL_RAD: f64 = ROTARY_SINGULAR_CONE_RAD;

/// Two consecutive rows with opposite orientation solutions are a flip (not a passage of the tool
/// through the table normal) when theta2 also turns by more than this (rad): the two solutions
/// of one axis differ by half a turn of theta2.
pub const ORIENTATION_FLIP_RAD: f64 = PI / 2.0;

/// A value measured by a check, within its limit or not: the summary reports the worst of each
/// check even on a clean run (the margin left).
#[derive(Debug, Clone, Copy)]
struct Obs {
    check: Check,
    value: f64,
    limit: f64,
    severity: f64,
    what: &'static str,
}

impl Obs {
    fn over(check: Check, value: f64, limit: f64, what: &'static str) -> Obs {
        Obs {
            check,
            value,
            limit,
            severity: if limit > 0.0 {
                value.abs() / limit
            } else {
                f64::INFINITY
            },
            what,
        }
    }

    fn under(check: Check, value: f64, limit: f64, what: &'static str) -> Obs {
        Obs {
            check,
            value,
            limit,
            severity: if value > 0.0 {
                limit / value
            } else {
                f64::INFINITY
            },
            what,
        }
    }
}

/// Keeps the worse of two observations.
fn keep_worst(slot: &mut Option<Obs>, o: Obs) {
    if slot.is_none_or(|w| o.severity > w.severity) {
        *slot = Some(o);
    }
}

// ---------------------------------------------------------------------------------------------
// Inputs

/// One row of joints (mm and rad), with its time or feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joints {
    pub rho: Sliders,
    pub theta1: f64,
    pub theta2: f64,
    /// `t` (s).
    pub t: Option<f64>,
    /// `feed` (mm/s; the column is mm/min).
    pub feed: Option<f64>,
    /// The time of the move to this row (s), when the joint program states it (a G-code
    /// program's feed under the controller's rule, or inverse time `G93`).
    pub duration: Option<f64>,
    /// The joint program moves to this row at the rapid rate (`G0`): no straight-line checks.
    pub rapid: bool,
}

impl Joints {
    fn as_array(&self) -> [f64; 5] {
        [self.rho.x, self.rho.y, self.rho.z, self.theta1, self.theta2]
    }
}

/// One intended tool pose in the workpiece frame: tip (mm) and unit axis (tip towards spindle),
/// and how the path moves to it when the path says so (CL files do; CSV paths do not).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    pub tip: Vector3<f64>,
    pub axis: Vector3<f64>,
    /// The move to this point is a rapid (positioning) move: the controller does not follow the
    /// straight line, so the joint-jump and chordal-error checks do not apply to it.
    pub rapid: bool,
    /// The programmed feed of the move to this point (mm/s), when the path gives one: the speed
    /// checks use it when the joint table has no `t` or `feed`.
    pub feed: Option<f64>,
    /// The time of the move to this point (s), when the path states it (a G-code program: the
    /// controller's feed rule, or inverse time): preferred to `feed`.
    pub duration: Option<f64>,
    /// The tool angles (phi1, phi2) (rad) as the path states them (a CSV with phi1,phi2, a
    /// program's angle words), not only the axis: a controller interpolates these, and near the
    /// table normal they say which way it turns ([`contour`]).
    pub angles: Option<(f64, f64)>,
}

impl PathPoint {
    /// A point of a path that says nothing about its moves (a feed move at an unknown feed).
    pub fn new(tip: Vector3<f64>, axis: Vector3<f64>) -> PathPoint {
        PathPoint {
            tip,
            axis,
            rapid: false,
            feed: None,
            duration: None,
            angles: None,
        }
    }
}

/// A row as read: where it is, its id, and its values or why they are unusable.
#[derive(Debug, Clone)]
pub struct Item<T> {
    /// 1-based data row.
    pub index: u64,
    /// 1-based line of the file.
    pub line: u64,
    pub id: Option<String>,
    pub value: Result<T, String>,
}

/// The joint columns of a joint table, in order (mm, mm, mm, degrees, degrees).
pub const JOINT_NAMES: [&str; 5] = ["rho1", "rho2", "rho3", "theta1", "theta2"];

/// One input of `verify`, read row by row by the caller (the command reads CSV and CL files).
pub trait RowSource {
    /// What one row holds when it is usable.
    type Row;
    /// A fatal error of the reader (unreadable file, malformed cell).
    type Error;
    /// The input's name, for messages.
    fn name(&self) -> &str;
    /// Whether the rows carry an `id` (both inputs with ids are paired by id).
    fn has_id(&self) -> bool;
    /// The next row, or `None` at the end.
    fn next_item(&mut self) -> Result<Option<Item<Self::Row>>, Self::Error>;
    /// The assembly modes of the joint row just paired with the row just read, when this
    /// source computed them to find that row (a recording's nearest path point), so that the
    /// row check does not compute them again. The default: none.
    fn take_joint_modes(&mut self) -> Option<Box<MachineFkModes>> {
        None
    }
}

/// The joint table: rows of [`Joints`], and whether they carry a time (`t` or `feed`).
pub trait JointSource: RowSource<Row = Joints> {
    /// True when velocities and accelerations can be checked.
    fn timed(&self) -> bool;
}

/// Why the rows of the two inputs cannot be paired: a fatal error of the run, at a line of one
/// of the inputs.
#[derive(Debug, Clone, PartialEq)]
pub enum PairingError {
    /// Without ids, the joint table goes on after the intended path ended.
    ExtraJointRow {
        joints: String,
        path: String,
        /// The joint row's line and 1-based data row.
        line: u64,
        index: u64,
    },
    /// Without ids, the intended path goes on after the joint table ended.
    ExtraPathRow {
        joints: String,
        path: String,
        /// The path row's line and 1-based data row.
        line: u64,
        index: u64,
    },
    /// An id appears twice in one input (`file`: the joint table or the intended path).
    DuplicateId {
        file: String,
        id: String,
        line: u64,
        first_line: u64,
    },
}

impl PairingError {
    /// The input the error is in.
    pub fn file(&self) -> &str {
        match self {
            PairingError::ExtraJointRow { joints, .. } => joints,
            PairingError::ExtraPathRow { path, .. } => path,
            PairingError::DuplicateId { file, .. } => file,
        }
    }

    /// The 1-based line of that input.
    pub fn line(&self) -> u64 {
        match self {
            PairingError::ExtraJointRow { line, .. }
            | PairingError::ExtraPathRow { line, .. }
            | PairingError::DuplicateId { line, .. } => *line,
        }
    }

    /// The column concerned, when there is one.
    pub fn column(&self) -> Option<&'static str> {
        match self {
            PairingError::DuplicateId { .. } => Some("id"),
            _ => None,
        }
    }
}

impl fmt::Display for PairingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PairingError::ExtraJointRow {
                path,
                line: _,
                index,
                ..
            } => write!(
                f,
                "the joint table has more rows than the intended path {} ({} rows): row {} has no intended row; expected one joint row per path row, or an `id` column in both files",
                path,
                index - 1,
                index
            ),
            PairingError::ExtraPathRow {
                joints,
                line: _,
                index,
                ..
            } => write!(
                f,
                "the intended path has more rows than the joint table {} ({} rows): path row {} has no joint row; expected one joint row per path row, or an `id` column in both files",
                joints,
                index - 1,
                index
            ),
            PairingError::DuplicateId {
                id,
                line,
                first_line,
                ..
            } => write!(
                f,
                "id `{}` appears twice (lines {} and {}); expected unique ids",
                shown(id.as_bytes()),
                first_line,
                line
            ),
        }
    }
}

impl std::error::Error for PairingError {}

/// How the rows of the two files are matched.
enum Pairer {
    InOrder,
    ById {
        /// Path rows read ahead, waiting for their joint row.
        pending: HashMap<String, Item<PathPoint>>,
        path_done: bool,
        /// The line of every joint id seen: a second row with the same id is fatal.
        joint_lines: HashMap<String, u64>,
    },
}

/// The rows in flight in the row engine ([`crate::stream`]): read as pairs, their findings
/// kept for the write stage.
struct VerifyBatch {
    /// Each joint row with its intended pose, and whether a pairing gap comes before it.
    pairs: Vec<(Paired, bool)>,
    findings: Vec<Violation>,
}

impl VerifyBatch {
    fn new() -> VerifyBatch {
        VerifyBatch {
            pairs: Vec::with_capacity(BATCH_ROWS),
            findings: Vec::new(),
        }
    }
}

/// A joint row with its intended pose (None: no partner in the path).
struct Paired {
    joints: Item<Joints>,
    point: Option<Item<PathPoint>>,
    /// The joint row's assembly modes, when the pairing computed them.
    modes: Option<Box<MachineFkModes>>,
}

// ---------------------------------------------------------------------------------------------
// Options and the engine

/// What `verify` needs besides the inputs.
#[derive(Debug, Clone)]
pub struct VerifyOptions {
    pub thresholds: Thresholds,
    /// Tool length Delta (mm).
    pub tool_length: f64,
}

/// Per-row result of the parallel solve.
#[derive(Debug, Clone)]
struct RowEval {
    label: String,
    /// Usable as a segment end: valid, paired, in the working mode, tip and axis within limits.
    good: bool,
    violations: Vec<Violation>,
    obs: ArrayVec<Obs, 6>,
    q: Option<Joints>,
    point: Option<PathPoint>,
    module: ModulePose,
    /// phi1 of the achieved tool pose (rad): its sign labels the orientation solution.
    phi1: f64,
    tilt_ok: bool,
    singular_ok: bool,
    /// A pairing gap: no segment joins this row to the previous one.
    break_before: bool,
}

/// Per-segment result of the parallel solve, before the order-dependent checks.
#[derive(Debug, Clone, Default)]
struct SegEval {
    violations: Vec<Violation>,
    obs: ArrayVec<Obs, 8>,
    /// Joint rates (per s) when timed and within the velocity limits.
    rates: Option<[f64; 5]>,
    dt: f64,
    /// Signed theta2 change (rad) when the segment is a theta2 flip.
    flip: Option<f64>,
}

/// The previous segment, kept for accelerations and flip reversals.
#[derive(Debug, Clone)]
struct PrevSeg {
    end_row: String,
    rates: Option<[f64; 5]>,
    dt: f64,
    flip: Option<f64>,
}

fn orientation_label(phi1: f64) -> i8 {
    let s = wrap_angle(phi1);
    if s.abs() < ORIENTATION_LABEL_RAD || (PI - s.abs()) < ORIENTATION_LABEL_RAD {
        0
    } else if s > 0.0 {
        1
    } else {
        -1
    }
}

fn machine_kind(config: Config, alpha: f64, m: &Machine) -> bool {
    config == WORKING_CONFIG && m.module.r_big1 * alpha.cos() > m.module.r_small1
}

fn label_of(item: &Item<Joints>) -> String {
    match &item.id {
        Some(id) => id.clone(),
        None => item.index.to_string(),
    }
}

/// Checks the joint table against the intended path, streaming; `report` receives every finding
/// in row order. Fatal errors (the readers' own, a row-count mismatch without ids, a duplicated
/// id: [`PairingError`]) are returned as errors.
pub fn verify<J, P, E>(
    m: &Machine,
    opt: &VerifyOptions,
    joints: &mut J,
    path: &mut P,
    report: &mut (dyn FnMut(&Violation) -> Result<(), E> + Send),
) -> Result<Summary, E>
where
    J: JointSource<Error = E> + Send,
    P: RowSource<Row = PathPoint, Error = E> + Send,
    E: From<PairingError> + Send,
{
    let mut summary = Summary::new();
    summary.timed = joints.timed();
    let mut pairer = if joints.has_id() && path.has_id() {
        Pairer::ById {
            pending: HashMap::new(),
            path_done: false,
            joint_lines: HashMap::new(),
        }
    } else {
        Pairer::InOrder
    };
    let mut prev_row: Option<RowEval> = None;
    let mut prev_seg: Option<PrevSeg> = None;
    let mut gap = false;
    let mut finished = false;
    let summary_ref = &mut summary;
    crate::stream::run_batches::<_, E, _, _, _>(
        [VerifyBatch::new(), VerifyBatch::new(), VerifyBatch::new()],
        // Read: pair the next rows of the two inputs, in order.
        |batch: &mut VerifyBatch| {
            batch.pairs.clear();
            while !finished && batch.pairs.len() < BATCH_ROWS {
                match next_pair(&mut pairer, joints, path)? {
                    Some(p) => {
                        let unpaired = p.point.is_none();
                        batch.pairs.push((p, gap));
                        gap = unpaired;
                    }
                    None => finished = true,
                }
            }
            Ok(!batch.pairs.is_empty())
        },
        // Process: rows and segments in parallel, then the order-dependent checks.
        |batch: &mut VerifyBatch| {
            let summary = &mut *summary_ref;
            batch.findings.clear();
            let mut emit = |v: &Violation, summary: &mut Summary| -> Result<(), E> {
                summary.add(v);
                batch.findings.push(v.clone());
                Ok(())
            };
            let rows: Vec<RowEval> = batch
                .pairs
                .par_iter()
                .with_min_len(16)
                .map(|(p, brk)| eval_row(m, opt, p, *brk))
                .collect();
            // Segments: (previous row, row) for every row of the batch.
            let segs: Vec<Option<SegEval>> = (0..rows.len())
                .into_par_iter()
                .with_min_len(16)
                .map(|k| {
                    let b = &rows[k];
                    let a = if k == 0 {
                        prev_row.as_ref()
                    } else {
                        Some(&rows[k - 1])
                    };
                    match a {
                        Some(a) if a.good && b.good && !b.break_before => {
                            Some(eval_segment(m, opt, a, b))
                        }
                        _ => None,
                    }
                })
                .collect();
            // In order: accelerations, flip reversals, output.
            for (k, (row, seg)) in rows.iter().zip(segs).enumerate() {
                summary.rows += 1;
                for o in &row.obs {
                    summary.observe(o, &row.label);
                }
                for v in &row.violations {
                    emit(v, summary)?;
                }
                let has_prev = k > 0 || prev_row.is_some();
                let Some(mut seg) = seg else {
                    if has_prev && !row.break_before {
                        summary.segments_skipped += 1;
                    }
                    prev_seg = None;
                    continue;
                };
                summary.segments += 1;
                if seg.dt > 0.0 {
                    // Timed by the joint table, or by the path's feeds.
                    summary.timed = true;
                }
                if let (Some(flip), Some(p)) = (seg.flip, &prev_seg)
                    && let Some(pf) = p.flip
                    && pf * flip < 0.0
                    && let Some(v) = seg
                        .violations
                        .iter_mut()
                        .find(|v| v.check == Check::Theta2Flip)
                {
                    v.detail
                        .push_str(&format!("; reverses the flip at row {}", p.end_row));
                }
                if let (Some(r), Some(p)) = (seg.rates, &prev_seg)
                    && let Some(pr) = p.rates
                {
                    let amax = opt.thresholds.per_joint(
                        Th::RhoAccelMmS2,
                        Th::Theta1AccelDegS2,
                        Th::Theta2AccelDegS2,
                    );
                    let span = 0.5 * (seg.dt + p.dt);
                    let mut worst = None;
                    for i in 0..5 {
                        let acc = (r[i] - pr[i]) / span;
                        let (v, l) = if i < 3 {
                            (acc.abs(), amax[i])
                        } else {
                            (acc.abs().to_degrees(), amax[i].to_degrees())
                        };
                        keep_worst(
                            &mut worst,
                            Obs::over(Check::Acceleration, v, l, JOINT_NAMES[i]),
                        );
                        if acc.abs() > amax[i] {
                            let (v, l, u) = if i < 3 {
                                (acc.abs(), amax[i], "mm/s^2")
                            } else {
                                (acc.abs().to_degrees(), amax[i].to_degrees(), "deg/s^2")
                            };
                            seg.violations.push(Violation::over(
                                &row.label,
                                Check::Acceleration,
                                v,
                                l,
                                format!(
                                    "{} at {v:.4} {u} between the segments ending at rows {} and {}",
                                    JOINT_NAMES[i], p.end_row, row.label
                                ),
                            ));
                        }
                    }
                    if let Some(o) = worst {
                        summary.observe(&o, &row.label);
                    }
                }
                for o in &seg.obs {
                    summary.observe(o, &row.label);
                }
                for v in &seg.violations {
                    emit(v, summary)?;
                }
                prev_seg = Some(PrevSeg {
                    end_row: row.label.clone(),
                    rates: seg.rates,
                    dt: seg.dt,
                    flip: seg.flip,
                });
            }
            if let Some(last) = rows.into_iter().last() {
                prev_row = Some(last);
            }
            Ok(())
        },
        // Write: the findings, in row order.
        |batch: &mut VerifyBatch| {
            for v in &batch.findings {
                report(v)?;
            }
            Ok(())
        },
    )?;
    // Intended rows never matched by a joint row.
    if let Pairer::ById {
        pending, path_done, ..
    } = &mut pairer
    {
        let mut rest: Vec<Item<PathPoint>> = pending.drain().map(|(_, v)| v).collect();
        if !*path_done {
            while let Some(item) = path.next_item()? {
                rest.push(item);
            }
        }
        rest.sort_by_key(|i| i.index);
        for item in rest {
            let id = item.id.clone().unwrap_or_default();
            let v = Violation::plain(
                &id,
                Check::Pairing,
                f64::NAN,
                format!(
                    "id `{id}` (intended path line {}) has no joint row",
                    item.line
                ),
            );
            summary.add(&v);
            report(&v)?;
        }
    }
    Ok(summary)
}

fn next_pair<J, P, E>(
    pairer: &mut Pairer,
    joints: &mut J,
    path: &mut P,
) -> Result<Option<Paired>, E>
where
    J: RowSource<Row = Joints, Error = E>,
    P: RowSource<Row = PathPoint, Error = E>,
    E: From<PairingError>,
{
    match pairer {
        Pairer::InOrder => {
            let j = joints.next_item()?;
            let p = path.next_item()?;
            match (j, p) {
                (None, None) => Ok(None),
                (Some(j), Some(p)) => Ok(Some(Paired {
                    joints: j,
                    point: Some(p),
                    modes: path.take_joint_modes(),
                })),
                (Some(j), None) => Err(PairingError::ExtraJointRow {
                    joints: joints.name().to_string(),
                    path: path.name().to_string(),
                    line: j.line,
                    index: j.index,
                }
                .into()),
                (None, Some(p)) => Err(PairingError::ExtraPathRow {
                    joints: joints.name().to_string(),
                    path: path.name().to_string(),
                    line: p.line,
                    index: p.index,
                }
                .into()),
            }
        }
        Pairer::ById {
            pending,
            path_done,
            joint_lines,
        } => {
            let Some(j) = joints.next_item()? else {
                return Ok(None);
            };
            let id = j.id.clone().unwrap_or_default();
            if let Some(&first_line) = joint_lines.get(&id) {
                return Err(PairingError::DuplicateId {
                    file: joints.name().to_string(),
                    id,
                    line: j.line,
                    first_line,
                }
                .into());
            }
            joint_lines.insert(id.clone(), j.line);
            if let Some(p) = pending.remove(&id) {
                return Ok(Some(Paired {
                    joints: j,
                    point: Some(p),
                    modes: None,
                }));
            }
            while !*path_done {
                match path.next_item()? {
                    None => *path_done = true,
                    Some(p) => {
                        let pid = p.id.clone().unwrap_or_default();
                        if pid == id {
                            return Ok(Some(Paired {
                                joints: j,
                                point: Some(p),
                                modes: None,
                            }));
                        }
                        if let Some(old) = pending.get(&pid) {
                            return Err(PairingError::DuplicateId {
                                file: path.name().to_string(),
                                id: pid,
                                line: p.line,
                                first_line: old.line,
                            }
                            .into());
                        }
                        pending.insert(pid, p);
                    }
                }
            }
            Ok(Some(Paired {
                joints: j,
                point: None,
                modes: None,
            }))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_labels_ignore_the_table_normal() {
        assert_eq!(orientation_label(0.3), 1);
        assert_eq!(orientation_label(-0.3), -1);
        assert_eq!(orientation_label(1e-9), 0);
        assert_eq!(orientation_label(PI), 0);
    }
}
