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
mod observe;
mod row;
mod segment;
mod thresholds;

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt;

use arrayvec::ArrayVec;
use nalgebra::Vector3;

use crate::error::shown;
use crate::machine::intended::IntendedMove;
use crate::machine::orientation::ROTARY_SINGULAR_CONE_RAD;
use crate::machine::{MachineFkModes, machine_fk, tool_pose_eq26};
use crate::par::*;
use crate::parallel_module::branches::{Config, Reason, WORKING_CONFIG, config_of};
use crate::parallel_module::equations::{ModulePose, Sliders, polish_pose, residual_mm, rod_tilts};
use crate::parallel_module::ik::wrap_angle;
use crate::parallel_module::kinetostatics::kinetostatics;
use crate::post::schedule::vertex_acceleration;
use crate::spec::Machine;
use crate::tolerance::ACCEPT_RESIDUAL_MM;

pub use findings::{Check, CheckStats, Summary, Violation};
pub use observe::{PoseObservation, RowObservation, SegmentObservation};
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
    /// For a block of a joint program that names the path row it leads to (as `verne ik
    /// --format gcode` writes them): that row, and the fraction of the move to it for a pose
    /// the post inserted. The program is then paired with the path by it.
    pub tag: Option<PathTag>,
}

/// The path row a joint program's block leads to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathTag {
    /// The path's 1-based data row.
    pub row: u64,
    /// The fraction of the move to that row (a pose inserted on the move), or `None` for the
    /// row itself.
    pub fraction: Option<f64>,
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
    /// True when the machine is at rest before each run of timed moves and after it (a program
    /// for the controller: it starts still, and stops at a rapid and at its end), so that the
    /// accelerations into and out of those runs are checked too. A table of joints sampled
    /// from a motion (a CSV with `t`, a recording) may start and end in motion: the default.
    fn starts_at_rest(&self) -> bool {
        false
    }
}

/// Why the rows of the two inputs cannot be paired: a fatal error of the run, at a line of one
/// of the inputs. (Rows of one input without a partner in the other are findings, not errors.)
#[derive(Debug, Clone, PartialEq)]
pub enum PairingError {
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
            PairingError::DuplicateId { file, .. } => file,
        }
    }

    /// The 1-based line of that input.
    pub fn line(&self) -> u64 {
        match self {
            PairingError::DuplicateId { line, .. } => *line,
        }
    }

    /// The column concerned, when there is one.
    pub fn column(&self) -> Option<&'static str> {
        match self {
            PairingError::DuplicateId { .. } => Some("id"),
        }
    }
}

impl fmt::Display for PairingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
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
#[allow(clippy::large_enum_variant)] // one per run
enum Pairer {
    /// Before the first joint row: by tags if it has one, else in order.
    Undecided,
    InOrder,
    /// By the path row each block names ([`PathTag`]).
    ByTag {
        /// The last path row read, and whether a block landed on it.
        current: Option<Item<PathPoint>>,
        covered: bool,
        /// The path row before it (the start of the move to it).
        before: Option<Item<PathPoint>>,
    },
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
    /// With an observer: each row's observation, and the number of the batch's findings up to
    /// the end of that row's.
    observed: Vec<(RowObservation, usize)>,
}

impl VerifyBatch {
    fn new() -> VerifyBatch {
        VerifyBatch {
            pairs: Vec::with_capacity(BATCH_ROWS),
            findings: Vec::new(),
            observed: Vec::new(),
        }
    }
}

/// A joint row with its intended pose (None: no partner in the path).
struct Paired {
    joints: Item<Joints>,
    point: Option<Item<PathPoint>>,
    /// The joint row's assembly modes, when the pairing computed them.
    modes: Option<Box<MachineFkModes>>,
    /// Path rows passed over before this row without a joint row of their own.
    missing: Vec<Item<PathPoint>>,
    /// Why the row has no partner, when the pairing knows.
    unpaired: Option<String>,
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
    /// The joint row's line, and its intended row's.
    joints_line: u64,
    path_line: Option<u64>,
    /// The joint row's 1-based data row.
    index: u64,
    /// `module` is the assembly mode the row was checked in (the row has one).
    has_mode: bool,
}

/// Per-segment result of the parallel solve, before the order-dependent checks.
#[derive(Debug, Clone, Default)]
struct SegEval {
    violations: Vec<Violation>,
    obs: ArrayVec<Obs, 8>,
    /// Joint rates (per s) when timed.
    rates: Option<[f64; 5]>,
    /// The rates are within the velocity limits (and not a jump): the accelerations at the
    /// segment's vertices are checked.
    accelerations_checked: bool,
    dt: f64,
    /// The joints' change over the segment.
    dq: [f64; 5],
    /// Signed theta2 change (rad) when the segment is a theta2 flip.
    flip: Option<f64>,
}

/// The previous segment, kept for accelerations and flip reversals.
#[derive(Debug, Clone)]
struct PrevSeg {
    end_row: String,
    rates: Option<[f64; 5]>,
    accelerations_checked: bool,
    dt: f64,
    /// The joints' change over the segment.
    dq: [f64; 5],
    flip: Option<f64>,
    /// The lines of the row that ends it.
    lines: (u64, Option<u64>),
}

/// `v` at the lines of its row, unless it names its own.
fn with_lines(v: &Violation, (joints, path): (u64, Option<u64>)) -> Violation {
    let mut v = v.clone();
    v.joints_line = v.joints_line.or(Some(joints));
    v.path_line = v.path_line.or(path);
    v
}

/// The acceleration check of one vertex: the worst joint's observation, and a finding for
/// each joint over its limit.
fn acceleration_findings(
    opt: &VerifyOptions,
    acc: &[f64; 5],
    label: &str,
    where_: &str,
) -> (Obs, Vec<Violation>) {
    let amax =
        opt.thresholds
            .per_joint(Th::RhoAccelMmS2, Th::Theta1AccelDegS2, Th::Theta2AccelDegS2);
    let mut worst = None;
    let mut found = Vec::new();
    for i in 0..5 {
        let (v, l, u) = if i < 3 {
            (acc[i].abs(), amax[i], "mm/s^2")
        } else {
            (acc[i].abs().to_degrees(), amax[i].to_degrees(), "deg/s^2")
        };
        keep_worst(
            &mut worst,
            Obs::over(Check::Acceleration, v, l, JOINT_NAMES[i]),
        );
        if acc[i].abs() > amax[i] {
            found.push(Violation::over(
                label,
                Check::Acceleration,
                v,
                l,
                format!("{} at {v:.4} {u} {where_}", JOINT_NAMES[i]),
            ));
        }
    }
    (worst.expect("five joints"), found)
}

/// The stop at the end of a timed run: the last segment's velocities reached zero over half its
/// time.
fn stop_at_rest<E>(
    p: &PrevSeg,
    opt: &VerifyOptions,
    summary: &mut Summary,
    emit: &mut impl FnMut(&Violation, &mut Summary) -> Result<(), E>,
) -> Result<(), E> {
    if p.rates.is_none() || !p.accelerations_checked {
        return Ok(());
    }
    let acc = vertex_acceleration(&p.dq, p.dt, None);
    let (o, found) = acceleration_findings(
        opt,
        &acc,
        &p.end_row,
        &format!("to rest after the segment ending at row {}", p.end_row),
    );
    summary.observe(&o, &p.end_row, p.lines);
    for v in &found {
        emit(&with_lines(v, p.lines), summary)?;
    }
    Ok(())
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
    verify_observed(m, opt, joints, path, report, None)
}

/// An observer of [`verify_observed`]: receives what was measured at each row.
pub type Observer<'a> = &'a mut (dyn FnMut(&RowObservation) + Send);

/// [`verify`], and `observe` receives each row's [`RowObservation`] in row order, before that
/// row's findings reach `report` (the findings after the last row's observation are those of
/// the path's end: the last stop, the path rows without a joint row).
pub fn verify_observed<J, P, E>(
    m: &Machine,
    opt: &VerifyOptions,
    joints: &mut J,
    path: &mut P,
    report: &mut (dyn FnMut(&Violation) -> Result<(), E> + Send),
    mut observe: Option<Observer<'_>>,
) -> Result<Summary, E>
where
    J: JointSource<Error = E> + Send,
    P: RowSource<Row = PathPoint, Error = E> + Send,
    E: From<PairingError> + Send,
{
    let observing = observe.is_some();
    let mut summary = Summary::new();
    summary.timed = joints.timed();
    let at_rest = joints.starts_at_rest();
    let mut pairer = if joints.has_id() && path.has_id() {
        Pairer::ById {
            pending: HashMap::new(),
            path_done: false,
            joint_lines: HashMap::new(),
        }
    } else {
        Pairer::Undecided
    };
    let mut last_label = String::new();
    let mut last_line = 0;
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
            batch.observed.clear();
            let observed = &mut batch.observed;
            let found = std::cell::Cell::new(0);
            let mut emit = |v: &Violation, summary: &mut Summary| -> Result<(), E> {
                summary.add(v);
                batch.findings.push(v.clone());
                found.set(found.get() + 1);
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
            // For an observer, the rows' tool poses and kinetostatics (as the row checks have
            // them), in parallel too.
            let poses: Vec<Option<PoseObservation>> = if observing {
                rows.par_iter()
                    .with_min_len(16)
                    .map(|r| pose_observation(m, opt, r))
                    .collect()
            } else {
                Vec::new()
            };
            // In order: accelerations, flip reversals, output.
            for (k, (row, seg)) in rows.iter().zip(segs).enumerate() {
                summary.rows += 1;
                let lines = (row.joints_line, row.path_line);
                last_label = row.label.clone();
                last_line = row.joints_line;
                for o in &row.obs {
                    summary.observe(o, &row.label, lines);
                }
                for v in &row.violations {
                    emit(&with_lines(v, lines), summary)?;
                }
                let has_prev = k > 0 || prev_row.is_some();
                let Some(mut seg) = seg else {
                    if has_prev && !row.break_before {
                        summary.segments_skipped += 1;
                    }
                    if let Some(p) = prev_seg.take().filter(|_| at_rest) {
                        stop_at_rest(&p, opt, summary, &mut emit)?;
                    }
                    if observing {
                        observed.push((observation(row, poses[k], None), found.get()));
                    }
                    continue;
                };
                let mut acceleration = None;
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
                // The vertex between the previous segment and this one (the block model of
                // docs/post.md): from rest when this one starts a timed run, to rest when the
                // previous one ended one.
                match (
                    seg.rates,
                    prev_seg.as_ref().and_then(|p| p.rates.map(|r| (p, r))),
                ) {
                    (Some(_), Some((p, _)))
                        if !(seg.accelerations_checked && p.accelerations_checked) => {}
                    (Some(_), Some((p, _))) => {
                        let acc = vertex_acceleration(&p.dq, p.dt, Some((&seg.dq, seg.dt)));
                        acceleration = Some(acc);
                        let (o, found) = acceleration_findings(
                            opt,
                            &acc,
                            &row.label,
                            &format!(
                                "between the segments ending at rows {} and {}",
                                p.end_row, row.label
                            ),
                        );
                        summary.observe(&o, &row.label, lines);
                        seg.violations.extend(found);
                    }
                    (Some(_), None) if at_rest && seg.accelerations_checked => {
                        let acc = vertex_acceleration(&[0.0; 5], 0.0, Some((&seg.dq, seg.dt)));
                        acceleration = Some(acc);
                        let (o, found) = acceleration_findings(
                            opt,
                            &acc,
                            &row.label,
                            &format!("from rest into the segment ending at row {}", row.label),
                        );
                        summary.observe(&o, &row.label, lines);
                        seg.violations.extend(found);
                    }
                    (None, Some((p, _))) if at_rest => {
                        stop_at_rest(p, opt, summary, &mut emit)?;
                    }
                    _ => {}
                }
                for o in &seg.obs {
                    summary.observe(o, &row.label, lines);
                }
                for v in &seg.violations {
                    emit(&with_lines(v, lines), summary)?;
                }
                if observing {
                    let measured =
                        |c: Check| seg.obs.iter().find(|o| o.check == c).map(|o| o.value);
                    let s = SegmentObservation {
                        dt: (seg.dt > 0.0).then_some(seg.dt),
                        rates: seg.rates,
                        acceleration,
                        chord_error_mm: measured(Check::ChordError),
                        chord_axis_deg: measured(Check::ChordAxis),
                    };
                    observed.push((observation(row, poses[k], Some(s)), found.get()));
                }
                prev_seg = Some(PrevSeg {
                    end_row: row.label.clone(),
                    rates: seg.rates,
                    accelerations_checked: seg.accelerations_checked,
                    dt: seg.dt,
                    dq: seg.dq,
                    flip: seg.flip,
                    lines,
                });
            }
            if let Some(last) = rows.into_iter().last() {
                prev_row = Some(last);
            }
            Ok(())
        },
        // Write: the findings, in row order, each row's after its observation.
        |batch: &mut VerifyBatch| {
            let mut written = 0;
            if let Some(observe) = observe.as_mut() {
                for (o, end) in &batch.observed {
                    observe(o);
                    for v in &batch.findings[written..*end] {
                        report(v)?;
                    }
                    written = *end;
                }
            }
            for v in &batch.findings[written..] {
                report(v)?;
            }
            Ok(())
        },
    )?;
    // The path's end: the last timed run stops.
    if let Some(p) = prev_seg.take().filter(|_| at_rest) {
        stop_at_rest(
            &p,
            opt,
            &mut summary,
            &mut |v: &Violation, s: &mut Summary| {
                s.add(v);
                report(v)
            },
        )?;
    }
    // Intended rows never matched by a joint row.
    let mut rest: Vec<Item<PathPoint>> = Vec::new();
    match &mut pairer {
        Pairer::ById {
            pending, path_done, ..
        } => {
            rest.extend(pending.drain().map(|(_, v)| v));
            if !*path_done {
                while let Some(item) = path.next_item()? {
                    rest.push(item);
                }
            }
            rest.sort_by_key(|i| i.index);
        }
        Pairer::ByTag {
            current, covered, ..
        } => {
            if let Some(c) = current.take().filter(|_| !*covered) {
                rest.push(c);
            }
            while let Some(item) = path.next_item()? {
                rest.push(item);
            }
        }
        Pairer::InOrder | Pairer::Undecided => {
            while let Some(item) = path.next_item()? {
                rest.push(item);
            }
        }
    }
    for item in rest {
        let v = missing_row(&item, &last_label, last_line);
        summary.add(&v);
        report(&v)?;
    }
    Ok(summary)
}

/// What the checks measured at `row`, and along the segment that ends on it.
fn observation(
    row: &RowEval,
    pose: Option<PoseObservation>,
    segment: Option<SegmentObservation>,
) -> RowObservation {
    RowObservation {
        label: row.label.clone(),
        index: row.index,
        joints_line: row.joints_line,
        path_line: row.path_line,
        joints: row.q,
        intended: row.point,
        pose,
        segment,
    }
}

/// The tool pose and kinetostatics of a row in the assembly mode it was checked in, by the same
/// functions as its checks (eq. (26), `kinetostatics`), and the errors and rod tilt they
/// measured; `None` for a row without a mode.
fn pose_observation(m: &Machine, opt: &VerifyOptions, r: &RowEval) -> Option<PoseObservation> {
    let q = r.q.filter(|_| r.has_mode)?;
    let measured = |c: Check| r.obs.iter().find(|o| o.check == c).map(|o| o.value);
    let tool = tool_pose_eq26(&m.table, &r.module, q.theta1, q.theta2, opt.tool_length);
    let k = kinetostatics(&m.module, &r.module, &q.rho);
    Some(PoseObservation {
        module: r.module,
        tip: tool.tip,
        axis: crate::machine::orientation::tool_axis(tool.phi1, tool.phi2),
        tip_error_mm: measured(Check::TipError)?,
        axis_error_deg: measured(Check::AxisError)?,
        rod_tilt_deg: measured(Check::Limits)?,
        amplification: k.amplification,
        parallel_margin: k.parallel_margin,
    })
}

/// The finding of a path row no joint row was paired with, placed at the joint row `at`.
fn missing_row(item: &Item<PathPoint>, at: &str, joints_line: u64) -> Violation {
    let what = match &item.id {
        Some(id) => format!("id `{id}` (intended path line {})", item.line),
        None => format!("intended path row {} (line {})", item.index, item.line),
    };
    let mut v = Violation::plain(
        item.id.as_deref().unwrap_or(at),
        Check::Pairing,
        f64::NAN,
        format!("{what} has no joint row"),
    );
    v.path_line = Some(item.line);
    v.joints_line = Some(joints_line);
    v
}

/// A joint row paired with `point`, nothing passed over.
fn paired(joints: Item<Joints>, point: Option<Item<PathPoint>>) -> Paired {
    Paired {
        joints,
        point,
        modes: None,
        missing: Vec::new(),
        unpaired: None,
    }
}

/// The intended pose at `fraction` of the move from `before` to `to`, as an item of the path
/// (at `to`'s row and line).
fn between(
    before: Option<&Item<PathPoint>>,
    to: &Item<PathPoint>,
    fraction: f64,
) -> Result<Item<PathPoint>, String> {
    let b = to.value.as_ref().map_err(Clone::clone)?;
    let Some(a) = before else {
        return Err(format!(
            "a pose at {fraction} of the move to path row {}, the path's first row: there is no move to it",
            to.index
        ));
    };
    let a = a
        .value
        .as_ref()
        .map_err(|e| format!("the move's start: {e}"))?;
    let mv = IntendedMove::new(a.tip, a.axis, a.angles, b.tip, b.axis, b.angles)
        .map_err(|e| e.to_string())?;
    Ok(Item {
        index: to.index,
        line: to.line,
        id: None,
        value: Ok(PathPoint {
            tip: mv.tip(fraction),
            axis: mv.axis(fraction),
            rapid: b.rapid,
            feed: b.feed,
            duration: None,
            angles: mv.angles(fraction),
        }),
        tag: None,
    })
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
    let Some(j) = joints.next_item()? else {
        return Ok(None);
    };
    if let Pairer::Undecided = pairer {
        *pairer = if j.tag.is_some() {
            Pairer::ByTag {
                current: None,
                covered: false,
                before: None,
            }
        } else {
            Pairer::InOrder
        };
    }
    match pairer {
        Pairer::Undecided | Pairer::InOrder => {
            let p = path.next_item()?;
            let mut pair = paired(j, p);
            pair.modes = path.take_joint_modes();
            if pair.point.is_none() {
                pair.unpaired = Some(format!(
                    "no intended row: the joint table goes on after the intended path {} ended",
                    path.name()
                ));
            }
            Ok(Some(pair))
        }
        Pairer::ByTag {
            current,
            covered,
            before,
        } => {
            let Some(tag) = j.tag else {
                let mut pair = paired(j, None);
                pair.unpaired =
                    Some("the block names no path row, where the program's other blocks do".into());
                return Ok(Some(pair));
            };
            let mut missing = Vec::new();
            // Read on to the row the block names; rows passed over without a block of their
            // own are missing.
            while current.as_ref().is_none_or(|c| c.index < tag.row) {
                let Some(next) = path.next_item()? else {
                    break;
                };
                if let Some(c) = current.take() {
                    if !*covered {
                        missing.push(c.clone());
                    }
                    *before = Some(c);
                }
                *current = Some(next);
                *covered = false;
            }
            let mut pair = paired(j, None);
            pair.missing = missing;
            match current.as_ref() {
                Some(c) if c.index == tag.row => match tag.fraction {
                    None => {
                        pair.point = Some(c.clone());
                        *covered = true;
                    }
                    Some(f) => match between(before.as_ref(), c, f) {
                        Ok(point) => pair.point = Some(point),
                        Err(why) => pair.unpaired = Some(why),
                    },
                },
                Some(c) if c.index > tag.row => {
                    pair.unpaired = Some(format!(
                        "the block names path row {}, behind the row of the block before it ({}): blocks out of order",
                        tag.row, c.index
                    ))
                }
                _ => {
                    pair.unpaired = Some(format!(
                        "the block names path row {}, past the end of the intended path {}",
                        tag.row,
                        path.name()
                    ))
                }
            }
            Ok(Some(pair))
        }
        Pairer::ById {
            pending,
            path_done,
            joint_lines,
        } => {
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
                return Ok(Some(paired(j, Some(p))));
            }
            while !*path_done {
                match path.next_item()? {
                    None => *path_done = true,
                    Some(p) => {
                        let pid = p.id.clone().unwrap_or_default();
                        if pid == id {
                            return Ok(Some(paired(j, Some(p))));
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
            Ok(Some(paired(j, None)))
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
