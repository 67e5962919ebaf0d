//! The post's stages between the path follower and the writer: the linearization (poses
//! inserted so that every block stays within the tolerances, [`verne::post::linearize`]) and the
//! block times (as fast as the drives and the feeds allow, [`verne::post::schedule`]). Rows come
//! in batches, in order, and leave in order; the scheduler holds a window of them until their
//! times are final.

use std::collections::VecDeque;

use nalgebra::Vector3;
use rayon::prelude::*;
use verne::machine::PathRow;
use verne::machine::intended::{IntendedMove, followed_angles};
use verne::machine::orientation::{ToolAngles, ToolOrientation, tool_axis};
use verne::post::linearize::{Linearizer, Tolerances, Vertex};
use verne::post::schedule::{BlockMove, Limiting, Limits, Scheduler, limiting};
use verne::spec::Machine;

use super::{Followed, RowResult};
use crate::error::VerneError;
use crate::toolpath::Motion;

/// What the post does.
#[derive(Debug, Clone, Copy)]
pub struct PostOptions {
    /// Linearize within these tolerances.
    pub linearize: Option<Tolerances>,
    /// Time every feed block within these limits and the feeds.
    pub schedule: Option<Limits>,
}

/// What the post did, for the summary.
#[derive(Debug, Clone, Default)]
pub struct PostReport {
    /// Rows of the path, and poses inserted.
    pub rows: u64,
    pub inserted: u64,
    /// Moves that could not be linearized: (line, why).
    pub not_linearized: Vec<(u64, String)>,
    /// Timed blocks, their total time (s), and the total at the programmed feeds alone (s).
    pub timed_blocks: u64,
    pub time_s: f64,
    pub feed_time_s: f64,
    /// Blocks slower than their programmed feed (the drives hold them back).
    pub slowed: u64,
    /// Most rows the scheduler held at once.
    pub most_held: usize,
}

/// A row's pose in the machine's workpiece frame, with its joints, for a move's ends.
#[derive(Debug, Clone, Copy)]
struct End {
    tip: Vector3<f64>,
    axis: Vector3<f64>,
    stated: Option<(f64, f64)>,
    path: PathRow,
}

impl End {
    fn of(f: &Followed, offset: &Vector3<f64>) -> Option<End> {
        let RowResult::Joints(path) = f.result else {
            return None;
        };
        let axis = f.row.axis().ok()?;
        Some(End {
            tip: f.row.tip + offset,
            axis,
            // phi1 = alpha - theta1, phi2 = -theta2 (eq. (26), AIM 2007).
            stated: followed_angles(
                f.row.stated_angles,
                (path.module.alpha - path.theta1, -path.theta2),
            ),
            path,
        })
    }

    fn vertex(&self, s: f64) -> Vertex {
        let p = &self.path;
        Vertex {
            s,
            joints: [p.rho.x, p.rho.y, p.rho.z, p.theta1, p.theta2],
            module: p.module,
            orientation: p.orientation,
        }
    }
}

/// A row waiting for its time, and the block that leads to it when it needs one (a feed block
/// does; a rapid or the first row does not).
struct Waiting {
    row: Followed,
    block: Option<BlockMove>,
}

/// A line of the schedule report: a timed block, what limits it, its programmed and scheduled
/// speeds.
#[derive(Debug, Clone)]
pub struct ScheduleLine {
    /// The block's number in the program (1-based, the rapids and first row included).
    pub block: u64,
    /// The toolpath line it leads to.
    pub line: u64,
    pub limit: Limiting,
    /// How near the limit (1 = at it).
    pub share: f64,
    /// The block's shortest time at the programmed feed, and its scheduled time (s).
    pub feed_time_s: f64,
    pub time_s: f64,
}

/// The stages' state over a run.
pub struct Post<'a> {
    machine: &'a Machine,
    tool_length: f64,
    offset: Vector3<f64>,
    options: PostOptions,
    /// The last row handed on (the start of the next move).
    last: Option<Followed>,
    scheduler: Option<Scheduler>,
    waiting: VecDeque<Waiting>,
    times: VecDeque<f64>,
    /// The last row scheduled (the start of the next block).
    last_scheduled: Option<Followed>,
    pub report: PostReport,
    /// Rows released so far (the number of the next block).
    released: u64,
    /// The last two timed blocks released, waiting for their neighbour before their report
    /// line: (block number, line, block, time).
    recent: Vec<(u64, u64, BlockMove, f64)>,
    /// The schedule report's lines of the blocks the drives hold back, when asked for.
    pub schedule_lines: Option<Vec<ScheduleLine>>,
}

impl<'a> Post<'a> {
    pub fn new(
        machine: &'a Machine,
        tool_length: f64,
        offset: Vector3<f64>,
        options: PostOptions,
    ) -> Post<'a> {
        Post {
            machine,
            tool_length,
            offset,
            options,
            last: None,
            scheduler: options.schedule.map(Scheduler::new),
            waiting: VecDeque::new(),
            times: VecDeque::new(),
            last_scheduled: None,
            report: PostReport::default(),
            released: 0,
            recent: Vec::new(),
            schedule_lines: None,
        }
    }

    /// Takes the next rows of the path, in order; returns the rows ready to write, in order.
    pub fn process(
        &mut self,
        rows: Vec<Followed>,
        file: &str,
    ) -> Result<Vec<Followed>, VerneError> {
        self.report.rows += rows.len() as u64;
        let rows = match self.options.linearize {
            Some(tol) => self.linearize(rows, tol),
            None => rows,
        };
        if let Some(last) = rows.last() {
            self.last = Some(last.clone());
        }
        if self.scheduler.is_none() {
            return Ok(rows);
        }
        for row in rows {
            self.schedule(row, file)?;
        }
        Ok(self.release())
    }

    /// The rows still held, at the path's end.
    pub fn finish(&mut self) -> Vec<Followed> {
        if let Some(s) = &mut self.scheduler {
            s.end_run();
            self.times.extend(s.take_times());
            self.report.most_held = s.most_held;
        }
        let out = self.release();
        self.report_recent(true);
        out
    }

    /// The rows with the poses inserted between them.
    fn linearize(&mut self, rows: Vec<Followed>, tol: Tolerances) -> Vec<Followed> {
        let lin = Linearizer {
            machine: self.machine,
            tool_length: self.tool_length,
            tolerances: tol,
        };
        let offset = self.offset;
        let previous = self.last.as_ref();
        let inserted: Vec<Result<Vec<Followed>, (u64, String)>> = (0..rows.len())
            .into_par_iter()
            .with_min_len(8)
            .map(|i| {
                let from = if i == 0 { previous } else { Some(&rows[i - 1]) };
                let to = &rows[i];
                let (Some(from), false) = (from, to.row.rapid()) else {
                    return Ok(Vec::new());
                };
                let (Some(a), Some(b)) = (End::of(from, &offset), End::of(to, &offset)) else {
                    return Ok(Vec::new());
                };
                let intended = IntendedMove::new(a.tip, a.axis, a.stated, b.tip, b.axis, b.stated)
                    .map_err(|e| (to.row.line, e.to_string()))?;
                let poses = lin
                    .linearize(&a.vertex(0.0), &b.vertex(1.0), &intended)
                    .map_err(|e| (to.row.line, e.to_string()))?;
                Ok(poses
                    .iter()
                    .map(|v| inserted_row(to, v, &intended, &offset))
                    .collect())
            })
            .collect();
        let mut out = Vec::with_capacity(rows.len());
        for (row, ins) in rows.into_iter().zip(inserted) {
            match ins {
                Ok(ins) => {
                    self.report.inserted += ins.len() as u64;
                    out.extend(ins);
                }
                Err(finding) => self.report.not_linearized.push(finding),
            }
            out.push(row);
        }
        out
    }

    /// Queues a row; the block from the previous row to it goes to the scheduler.
    fn schedule(&mut self, row: Followed, file: &str) -> Result<(), VerneError> {
        let Some(scheduler) = self.scheduler.as_mut() else {
            return Ok(());
        };
        let block = match (&self.last_scheduled, &row.result) {
            (Some(prev), RowResult::Joints(b)) if !row.row.rapid() => {
                let RowResult::Joints(a) = &prev.result else {
                    unreachable!("only rows with joints are scheduled from")
                };
                let block = block_move(prev, a, &row, b, file)?;
                scheduler.push(block);
                Some(block)
            }
            _ => {
                scheduler.end_run();
                None
            }
        };
        self.times.extend(scheduler.take_times());
        if matches!(row.result, RowResult::Joints(_)) {
            self.last_scheduled = Some(row.clone());
        } else {
            self.last_scheduled = None;
        }
        self.waiting.push_back(Waiting { row, block });
        Ok(())
    }

    /// The rows at the front of the queue whose times are known.
    fn release(&mut self) -> Vec<Followed> {
        let mut out = Vec::new();
        while let Some(front) = self.waiting.front() {
            let t = match front.block {
                Some(_) => match self.times.pop_front() {
                    Some(t) => Some(t),
                    None => break,
                },
                None => None,
            };
            let mut w = self.waiting.pop_front().expect("front");
            self.released += 1;
            match (w.block, t) {
                (Some(block), Some(t)) => {
                    w.row.time = Some(t);
                    self.report.timed_blocks += 1;
                    self.report.time_s += t;
                    self.report.feed_time_s += block.min_time;
                    if t > block.min_time * (1.0 + 1e-6) && moves(&block) {
                        self.report.slowed += 1;
                    }
                    self.recent.push((self.released, w.row.row.line, block, t));
                    self.report_recent(false);
                }
                _ => self.report_recent(true),
            }
            out.push(w.row);
        }
        out
    }

    /// Adds the report lines of the recent blocks whose neighbours are known (all of them at a
    /// stop: `stop`).
    fn report_recent(&mut self, stop: bool) {
        let (Some(limits), Some(lines)) = (self.options.schedule, self.schedule_lines.as_mut())
        else {
            self.recent.clear();
            return;
        };
        while self.recent.len() >= 2 || (stop && !self.recent.is_empty()) {
            // The block before the first (if it was timed and adjacent) is gone: its vertex is
            // measured from rest only at a stop, so look at the block and its successor.
            let blocks: Vec<BlockMove> = self.recent.iter().take(2).map(|r| r.2).collect();
            let times: Vec<f64> = self.recent.iter().take(2).map(|r| r.3).collect();
            let (n, line, block, t) = self.recent[0];
            let (limit, share) = limiting(&blocks, &times, 0, &limits);
            if t > block.min_time * (1.0 + 1e-6) && moves(&block) {
                lines.push(ScheduleLine {
                    block: n,
                    line,
                    limit,
                    share,
                    feed_time_s: block.min_time,
                    time_s: t,
                });
            }
            self.recent.remove(0);
        }
    }
}

/// False for a block that moves no joint (a repeated pose): it takes the schedule's still time,
/// which no drive's limit sets.
fn moves(block: &BlockMove) -> bool {
    block.dq.iter().any(|d| *d != 0.0)
}

/// The row of a pose inserted on the move to `to`: the move's line, feed and tool, the intended
/// pose at `v.s` (in the part's frame), and `v`'s joints.
fn inserted_row(
    to: &Followed,
    v: &Vertex,
    intended: &IntendedMove,
    offset: &Vector3<f64>,
) -> Followed {
    let mut row = to.row.clone();
    row.tip = intended.tip(v.s) - offset;
    let stated = intended.angles(v.s);
    row.orientation = match stated {
        Some((phi1, phi2)) => ToolOrientation::Angles(ToolAngles { phi1, phi2 }),
        None => ToolOrientation::Axis(intended.axis(v.s)),
    };
    row.stated_angles = stated;
    row.fraction = Some(v.s);
    row.motion = Some(Motion::Feed);
    row.n = None;
    let angles = match stated {
        Some((phi1, phi2)) => ToolAngles { phi1, phi2 },
        None => ToolAngles {
            phi1: v.joints[3] - v.module.alpha,
            phi2: -v.joints[4],
        },
    };
    let axis = tool_axis(angles.phi1, angles.phi2);
    let path = PathRow {
        rho: verne::parallel_module::equations::Sliders::new(v.joints[0], v.joints[1], v.joints[2]),
        theta1: v.joints[3],
        theta2: v.joints[4],
        angles,
        orientation: v.orientation,
        module: v.module,
        switched: false,
        near_rotary_singularity: axis.z.abs()
            > (verne::machine::orientation::ROTARY_SINGULAR_CONE_RAD).cos(),
        real_branches: 0,
    };
    Followed {
        row,
        path_row: to.path_row,
        result: RowResult::Joints(path),
        time: None,
    }
}

/// The fraction of its move a row is at: an inserted pose's, else the move's end.
fn fraction(f: &Followed) -> f64 {
    f.row.fraction.unwrap_or(1.0)
}

/// The block from row `p` (joints `a`) to row `r` (joints `b`) for the scheduler: the joints'
/// change, the tip's travel and the axis's turn, and the shortest time the feed allows (the
/// tip's travel at the feed, or, where the tip stays, the table's turn in degrees at the feed:
/// LinuxCNC's rule for A B C), or the move's stated time shared by the fraction of it the block
/// covers.
fn block_move(
    p: &Followed,
    a: &PathRow,
    r: &Followed,
    b: &PathRow,
    file: &str,
) -> Result<BlockMove, VerneError> {
    let dq = [
        b.rho.x - a.rho.x,
        b.rho.y - a.rho.y,
        b.rho.z - a.rho.z,
        b.theta1 - a.theta1,
        b.theta2 - a.theta2,
    ];
    let tip_mm = (r.row.tip - p.row.tip).norm();
    let turn_rad = match (p.row.axis(), r.row.axis()) {
        (Ok(u), Ok(v)) => u.angle(&v),
        _ => 0.0,
    };
    let share = {
        let from = if p.row.line == r.row.line && p.row.fraction.is_some() {
            fraction(p)
        } else {
            0.0
        };
        (fraction(r) - from).clamp(0.0, 1.0)
    };
    let min_time = match (r.row.dt, r.row.feed) {
        (Some(dt), _) => dt * share,
        (None, Some(feed)) if feed > 0.0 => {
            let table_turn_deg = (dq[3].powi(2) + dq[4].powi(2)).sqrt().to_degrees();
            60.0 * if tip_mm > 1e-9 {
                tip_mm
            } else {
                table_turn_deg
            } / feed
        }
        _ => {
            return Err(VerneError::input(
                file,
                Some(r.row.line),
                None,
                "a feed move without a feed: the post times each feed move by the path's feed (a CL file's FEDRAT, a program's F, a `feed` column)",
            ));
        }
    };
    Ok(BlockMove {
        dq,
        tip_mm,
        turn_rad,
        min_time,
    })
}
