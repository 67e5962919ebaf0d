//! `verne ik` on a toolpath: typed rows from a reader ([`crate::toolpath`]) to a writer
//! ([`mod@write`]), through the machine's inverse kinematics along the path. Rows go through in
//! batches on the core's row engine ([`verne::stream::run_batches`]): while one batch is read,
//! the one before is solved (every branch of each row in parallel, then the branch chosen in
//! order, nearest the previous row) and the one before that is written.

pub mod post;
pub mod write;

use arrayvec::ArrayVec;
use nalgebra::Vector3;
use rayon::prelude::*;

use verne::machine::{
    FirstRowChoice, MAX_MACHINE_IK_BRANCHES, MachineIkBranch, PathCandidates, PathError, PathRow,
    PathState, path_candidates, path_candidates_into,
};
use verne::spec::Machine;

use crate::engine::pipeline::{Cell, RunSummary};
use crate::error::VerneError;
use crate::toolpath::{Column, PoseRow, ToolpathSource};

/// Rows read, solved and written together.
const BATCH_ROWS: usize = 1024;
/// Rows handed to one thread at a time.
const RUN_ROWS: usize = 64;

/// Every branch of a row's tool pose (`--all`), over both orientation solutions: the branch,
/// its orientation solution (1 or 2) and theta2 (rad).
pub type AllBranches = ArrayVec<(MachineIkBranch, u8, f64), { 2 * MAX_MACHINE_IK_BRANCHES }>;

/// The result of one row.
#[derive(Debug, Clone)]
pub enum RowResult {
    /// The joints of the branch followed along the path.
    Joints(PathRow),
    /// Every real branch (`--all`), and whether the list is proved complete.
    Branches(Box<AllBranches>, bool),
    /// No joints: why (`invalid_input`, `invalid_axis`, `unreachable`, `uncertified`, the
    /// limits the nearest branch fails, or `no_working_branch`).
    NotOk(Cell),
}

/// A row of the path with its result.
#[derive(Debug, Clone)]
pub struct Followed {
    pub row: PoseRow,
    /// The 1-based row of the path it is (or, for a pose the post inserted, leads to).
    pub path_row: u64,
    pub result: RowResult,
    /// The time of the move to this row (s), when the post scheduled it.
    pub time: Option<f64>,
}

impl Followed {
    /// The row's status: `ok`, or why not.
    pub fn status(&self) -> Cell {
        match &self.result {
            RowResult::Joints(_) => Cell::Str("ok"),
            RowResult::Branches(b, proved) => Cell::Str(match (b.is_empty(), proved) {
                (false, true) => "ok",
                (true, true) => "unreachable",
                (_, false) => "uncertified",
            }),
            RowResult::NotOk(status) => *status,
        }
    }

    /// Whether the row is ok.
    pub fn ok(&self) -> bool {
        match &self.result {
            RowResult::Joints(_) => true,
            RowResult::Branches(b, proved) => *proved && !b.is_empty(),
            RowResult::NotOk(_) => false,
        }
    }
}

/// The text of a status cell (`ok`, a code, or the failed limits).
pub fn status_text(status: Cell) -> String {
    match status {
        Cell::Str(s) => s.to_string(),
        Cell::Verdict(v) => v.to_string(),
        other => format!("{other:?}"),
    }
}

/// A writer of followed rows (CSV, a halstreamer joint list, a joint program).
pub trait RowSink: Send {
    /// Called once before any row, with the input's columns.
    fn begin(&mut self, columns: &[Column]) -> Result<(), VerneError>;
    /// Writes a batch of rows, in order.
    fn write(&mut self, rows: &[Followed]) -> Result<(), VerneError>;
    /// Whether every row must have joints: a program for the controller cannot leave one out.
    fn every_row_needed(&self) -> Option<&'static str> {
        None
    }
    /// Flushes the output and puts it in place.
    fn finish(self: Box<Self>) -> Result<(), VerneError>;
    /// Abandons the output (nothing is left in place).
    fn discard(&mut self);
}

/// How a path is followed.
#[derive(Debug, Clone)]
pub struct FollowOptions {
    pub machine: Machine,
    pub tool_length: f64,
    /// Where the part sits on the table (mm, `--offset`): added to every tip read.
    pub offset: Vector3<f64>,
    /// Every branch of each row instead of the followed one.
    pub all: bool,
    pub first: FirstRowChoice,
    /// The theta2 the path's first decided row needs, for the rows before it
    /// ([`verne::machine::first_decided_theta2`]).
    pub seed_theta2: Option<f64>,
    /// The servo period (s) when the rows are samples at it (`--period`).
    pub period: Option<f64>,
}

/// Where each joint went along a path: its range over the ok rows, and how far theta2 turned.
#[derive(Debug, Clone, Default)]
pub struct JointTravel {
    pub rows: u64,
    /// rho1, rho2, rho3 (mm), theta1, theta2 (rad).
    pub min: [f64; 5],
    pub max: [f64; 5],
    /// Sum of |change of theta2| from row to row (rad).
    pub theta2_travel: f64,
    /// Rows flagged `near_rotary_singularity` (the tool axis near the rotary axis).
    pub near_rotary_singularity: u64,
    /// The servo period (s) when the rows are samples at it (`--period`): the joints' speeds
    /// are then known, the feeds having timed the samples.
    pub period: Option<f64>,
    /// Largest |change| per period of each joint (mm/s, rad/s), with `period`.
    pub max_speed: [f64; 5],
    last: Option<[f64; 5]>,
}

impl JointTravel {
    fn add(&mut self, q: [f64; 5]) {
        if self.rows == 0 {
            self.min = q;
            self.max = q;
        }
        for ((lo, hi), v) in self.min.iter_mut().zip(self.max.iter_mut()).zip(q) {
            *lo = lo.min(v);
            *hi = hi.max(v);
        }
        if let Some(last) = self.last {
            self.theta2_travel += (q[4] - last[4]).abs();
            if let Some(period) = self.period {
                for k in 0..5 {
                    self.max_speed[k] = self.max_speed[k].max((q[k] - last[k]).abs() / period);
                }
            }
        }
        self.last = Some(q);
        self.rows += 1;
    }

    /// One line for stderr: each joint's range and its margins to the machine's limits (mm and
    /// degrees; theta2 is unlimited, its turns are given instead).
    pub fn line(&self, m: &Machine) -> String {
        let l = &m.limits;
        let mut parts = Vec::new();
        for k in 0..3 {
            parts.push(format!(
                "rho{} {:.3}..{:.3} mm (margins {:.3} / {:.3})",
                k + 1,
                self.min[k],
                self.max[k],
                self.min[k] - l.rho_min[k],
                l.rho_max[k] - self.max[k]
            ));
        }
        parts.push(format!(
            "theta1 {:.3}..{:.3} deg (margins {:.3} / {:.3})",
            self.min[3].to_degrees(),
            self.max[3].to_degrees(),
            (self.min[3] - l.theta1_min).to_degrees(),
            (l.theta1_max - self.max[3]).to_degrees()
        ));
        parts.push(format!(
            "theta2 {:.3}..{:.3} deg ({:.2} turns travelled)",
            self.min[4].to_degrees(),
            self.max[4].to_degrees(),
            self.theta2_travel / std::f64::consts::TAU
        ));
        let speeds = match self.period {
            Some(_) => {
                let s = &self.max_speed;
                format!(
                    "; largest speeds rho1 {:.3}, rho2 {:.3}, rho3 {:.3} mm/s, theta1 {:.3}, theta2 {:.3} deg/s",
                    s[0],
                    s[1],
                    s[2],
                    s[3].to_degrees(),
                    s[4].to_degrees()
                )
            }
            None => String::new(),
        };
        format!(
            "joint travel over {} ok rows: {}; {} rows near the rotary-axis singularity{speeds}",
            self.rows,
            parts.join(", "),
            self.near_rotary_singularity
        )
    }
}

/// The status of a row without a working branch.
pub fn path_error_status(e: &PathError) -> Cell {
    match e {
        PathError::Axis(_) => Cell::Str("invalid_axis"),
        PathError::NoWorkingBranch {
            real_branches: 0,
            proved: true,
            ..
        } => Cell::Str("unreachable"),
        PathError::NoWorkingBranch {
            real_branches: 0,
            proved: false,
            ..
        } => Cell::Str("uncertified"),
        PathError::NoWorkingBranch {
            nearest: Some(b), ..
        } if b.verdict.only_limits() => Cell::Verdict(b.verdict),
        PathError::NoWorkingBranch { .. } => Cell::Str("no_working_branch"),
    }
}

/// One row's solve, before the choice that depends on the previous row: the candidates
/// computed with no previous row (recomputed in order when the axis is inside the rotary
/// cone), kept from batch to batch and refilled in place.
#[derive(Default)]
struct Solved {
    candidates: PathCandidates,
    outcome: Option<Result<(), PathError>>,
}

/// The rows in flight.
#[derive(Default)]
struct Batch {
    rows: Vec<PoseRow>,
    solved: Vec<Solved>,
    out: Vec<Followed>,
    /// Rows written, kept for their buffers.
    spare: Vec<PoseRow>,
}

/// The path followed so far, what the run counted, and where the joints went.
pub struct Follower {
    pub options: FollowOptions,
    pub state: PathState,
    pub travel: JointTravel,
    pub summary: RunSummary,
}

impl Follower {
    pub fn new(options: FollowOptions) -> Follower {
        let state = match options.seed_theta2 {
            Some(theta2) => PathState::with_theta2(options.first, theta2),
            None => PathState::new(options.first),
        };
        let travel = JointTravel {
            period: options.period,
            ..JointTravel::default()
        };
        Follower {
            options,
            state,
            travel,
            summary: RunSummary::default(),
        }
    }

    /// The candidates of a row (every branch of both orientation solutions), with no previous
    /// row: the part of the solve that runs in parallel.
    fn solve(&self, row: &PoseRow, solved: &mut Solved) {
        solved.outcome = row.invalid.is_none().then(|| {
            path_candidates_into(
                &self.options.machine,
                &(row.tip + self.options.offset),
                &row.orientation,
                self.options.tool_length,
                None,
                &mut solved.candidates,
            )
        });
    }

    /// The result of a row, in order: the branch nearest the previous row's.
    fn choose(&mut self, row: &PoseRow, solved: &Solved) -> RowResult {
        let Some(outcome) = &solved.outcome else {
            return RowResult::NotOk(Cell::Str("invalid_input"));
        };
        let o = &self.options;
        let recomputed;
        let candidates = match (outcome, self.state.reference_theta2()) {
            (Ok(()), Some(theta2)) if solved.candidates.needs_previous() && !o.all => {
                recomputed = path_candidates(
                    &o.machine,
                    &(row.tip + o.offset),
                    &row.orientation,
                    o.tool_length,
                    Some(theta2),
                );
                recomputed.as_ref()
            }
            (Ok(()), _) => Ok(&solved.candidates),
            (Err(e), _) => Err(e),
        };
        let candidates = match candidates {
            Ok(c) => c,
            Err(e) => return RowResult::NotOk(path_error_status(e)),
        };
        if o.all {
            let branches: AllBranches = candidates.iter().collect();
            return RowResult::Branches(Box::new(branches), candidates.certificate.proved());
        }
        match self.state.choose(candidates) {
            Ok(r) => {
                self.travel
                    .add([r.rho.x, r.rho.y, r.rho.z, r.theta1, r.theta2]);
                self.travel.near_rotary_singularity += u64::from(r.near_rotary_singularity);
                RowResult::Joints(r)
            }
            Err(e) => RowResult::NotOk(path_error_status(&e)),
        }
    }

    /// Counts a row's outcome; a row that is not ok is fatal when the output needs every row.
    fn count(
        &mut self,
        f: &Followed,
        every_row: Option<&str>,
        file: &str,
    ) -> Result<(), VerneError> {
        self.summary.input_rows += 1;
        self.summary.output_rows += match &f.result {
            RowResult::Branches(b, _) => b.len().max(1) as u64,
            _ => 1,
        };
        if f.ok() {
            self.summary.ok_rows += 1;
            return Ok(());
        }
        let status = status_text(f.status());
        if let Some(what) = every_row {
            return Err(VerneError::RowFailed(Box::new(VerneError::input(
                file,
                Some(f.row.line),
                None,
                format!(
                    "row status `{status}`: {what} cannot leave out a row; fix the path or use CSV output to see every row's status (exit 1)"
                ),
            ))));
        }
        self.summary.count(&status, f.row.line);
        Ok(())
    }
}

/// Progress callback: rows done so far.
pub type Progress<'a> = &'a (dyn Fn(u64) + Sync);

/// Follows the path of `source` into `sink` through the post's stages (`post`, when the output
/// is linearized or timed): reads, solves and writes batch by batch. A fatal error stops the run
/// (the caller discards the sink); rows without joints are written with their status and
/// counted.
pub fn run(
    source: &mut dyn ToolpathSource,
    follower: &mut Follower,
    mut post: Option<&mut post::Post<'_>>,
    sink: &mut dyn RowSink,
    progress: Progress<'_>,
) -> Result<(), VerneError> {
    sink.begin(source.columns())?;
    let every_row = sink.every_row_needed();
    let file = source.name().to_string();
    let mut finished = false;
    let sink_ref = &mut *sink;
    let post_ref = &mut post;
    verne::stream::run_batches::<_, VerneError, _, _, _>(
        [Batch::default(), Batch::default(), Batch::default()],
        |batch: &mut Batch| {
            batch.rows.clear();
            while !finished && batch.rows.len() < BATCH_ROWS {
                let mut row = batch.spare.pop().unwrap_or_default();
                if source.next_row(&mut row)? {
                    batch.rows.push(row);
                } else {
                    finished = true;
                }
            }
            Ok(!batch.rows.is_empty())
        },
        |batch: &mut Batch| {
            let n = batch.rows.len();
            batch
                .solved
                .resize_with(n.max(batch.solved.len()), Solved::default);
            let f: &Follower = follower;
            batch.rows[..n]
                .par_chunks(RUN_ROWS)
                .zip(batch.solved[..n].par_chunks_mut(RUN_ROWS))
                .for_each(|(rows, solved)| {
                    for (row, s) in rows.iter().zip(solved) {
                        f.solve(row, s);
                    }
                });
            batch.out.clear();
            for (row, solved) in batch.rows.drain(..).zip(&batch.solved) {
                let result = follower.choose(&row, solved);
                let followed = Followed {
                    row,
                    path_row: follower.summary.input_rows + 1,
                    result,
                    time: None,
                };
                follower.count(&followed, every_row, &file)?;
                batch.out.push(followed);
            }
            if let Some(p) = post_ref.as_deref_mut() {
                let rows = std::mem::take(&mut batch.out);
                batch.out = p.process(rows, &file)?;
            }
            progress(follower.summary.input_rows);
            Ok(())
        },
        |batch: &mut Batch| {
            sink_ref.write(&batch.out)?;
            batch.spare.extend(batch.out.drain(..).map(|f| f.row));
            Ok(())
        },
    )?;
    if let Some(p) = post {
        let rest = p.finish();
        sink.write(&rest)?;
    }
    Ok(())
}
