//! The time of every block of a joint program, as fast as the drives and the programmed feeds
//! allow.
//!
//! The model (docs/post.md), the one `verne verify` checks: the controller moves each block's
//! joints at the constant velocity v_k = dq_k / T_k (T_k the block's time); at the vertex between
//! blocks k and k+1 each joint's acceleration is the change of its velocity over the mean of the
//! two times,
//!
//!   a = (v_(k+1) - v_k) / ((T_k + T_(k+1)) / 2),
//!
//! and a run of feed blocks starts and ends at rest, the first (last) block's velocity reached
//! over half its time. Each joint's |v| and |a| must stay within the drives' limits, and the tool
//! tip's speed within the block's programmed feed. [`vertex_acceleration`] is the model's one
//! formula.
//!
//! The timing is the time-optimal parameterization of the path through the vertices (TOPP-RA:
//! H. Pham and Q.-C. Pham, *A new approach to time-optimal path parameterization based on
//! reachability analysis*, IEEE T-RO 34(3), 2018): the path parameter s is the tip's arc length
//! (with the tool axis's turn where the tip stays), the squared path speed x = (ds/dt)^2 at the
//! vertices the state, the path acceleration u constant on each block the control; the joints'
//! derivatives at the vertices are finite differences of the polyline. A backward pass gives
//! each vertex's largest controllable x (the largest speed from which the path can still stop at
//! its end), a forward pass then takes the largest reachable x at every vertex: the time-optimal
//! profile of the discretized problem. Block k then takes T_k = 2 h_k / (sqrt(x_k) +
//! sqrt(x_(k+1))). The finite differences agree with the block model to second order;
//! [`SAFETY`] covers the rest, and a last pass (`repair`) lowers the speed of any block the
//! block model still finds over a limit, so that the timing holds in the model exactly.
//!
//! Streaming, in bounded memory: the backward pass over the blocks read so far assumes rest after
//! the last; its value at a vertex equals the value with the whole path from the last vertex
//! whose controllable speed reached the vertex's own limit (nothing later can raise a vertex
//! above its own limit, so nothing later can change the vertices before it): those blocks are
//! final and are released.

use super::deviation::JointVector;

/// The share of each limit the optimal profile is computed for: the block model then holds with
/// room to spare (the finite differences and the blocks differ by a few per mille on a
/// linearized path).
pub const SAFETY: f64 = 0.98;

/// The share of each limit [`repair`] holds the blocks to, so that the rounding of the written
/// feed words cannot take a block over.
const REPAIR_SHARE: f64 = 0.999;

/// A block's time (s) when it moves nothing.
pub const STILL_TIME_S: f64 = 1e-3;

/// The joints' limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest |velocity| of each joint (mm/s, rad/s).
    pub velocity: JointVector,
    /// Largest |acceleration| of each joint (mm/s^2, rad/s^2).
    pub acceleration: JointVector,
}

impl Limits {
    /// The machine's drives.
    pub fn of(drives: &crate::spec::drives::Drives) -> Limits {
        Limits {
            velocity: drives.velocity,
            acceleration: drives.acceleration,
        }
    }

    fn scaled(&self, k: f64) -> Limits {
        Limits {
            velocity: self.velocity.map(|v| v * k),
            acceleration: self.acceleration.map(|a| a * k),
        }
    }
}

/// One block to time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockMove {
    /// The joints' change over the block.
    pub dq: JointVector,
    /// The tool tip's travel (mm).
    pub tip_mm: f64,
    /// The tool axis's turn (rad).
    pub turn_rad: f64,
    /// The shortest time (s) the programmed feed allows: the tip's travel at the feed (or, when
    /// the tip stays, the turn at the feed in degrees per minute), or the time the path states.
    pub min_time: f64,
}

impl BlockMove {
    /// Whether the block moves nothing (a repeated pose): the machine stops there.
    pub fn still(&self) -> bool {
        self.dq.iter().all(|v| v.abs() < 1e-12) && self.tip_mm < 1e-9
    }

    /// The path parameter's length of the block: the tip's travel, or the turn as an arc of
    /// [`TURN_RADIUS_MM`] where the tip stays.
    fn length(&self) -> f64 {
        (self.tip_mm).max(self.turn_rad * TURN_RADIUS_MM).max(1e-12)
    }
}

/// The radius (mm) that makes a turn of the tool axis a length of the path parameter.
const TURN_RADIUS_MM: f64 = 100.0;

/// Each joint's acceleration at the vertex between a block (`dq_a` in `t_a` s) and the next
/// (`dq_b` in `t_b` s), in the block model; `None` for the next block means rest (the end of a
/// run), and a rest before is `dq_a` = 0 with `t_a` = 0.
pub fn vertex_acceleration(
    dq_a: &JointVector,
    t_a: f64,
    next: Option<(&JointVector, f64)>,
) -> JointVector {
    let (dq_b, t_b) = next.map_or(([0.0; 5], 0.0), |(d, t)| (*d, t));
    let span = 0.5 * (t_a + t_b);
    std::array::from_fn(|j| {
        let va = if t_a > 0.0 { dq_a[j] / t_a } else { 0.0 };
        let vb = if t_b > 0.0 { dq_b[j] / t_b } else { 0.0 };
        (vb - va) / span
    })
}

/// The largest |acceleration| over a limit at a vertex, as a share of the limits (1 = at the
/// limit).
fn acceleration_share(acc: &JointVector, limits: &Limits) -> f64 {
    (0..5)
        .map(|j| acc[j].abs() / limits.acceleration[j])
        .fold(0.0, f64::max)
}

/// The largest rate (1/s) a block may have alone: its feed, and each joint's velocity.
fn rate_cap(b: &BlockMove, limits: &Limits) -> f64 {
    let mut cap = 1.0 / b.min_time.max(1e-300);
    for j in 0..5 {
        if b.dq[j] != 0.0 {
            cap = cap.min(limits.velocity[j] / b.dq[j].abs());
        }
    }
    cap
}

/// One vertex of the path for the reachability analysis: the constraints on (x, u) there.
#[derive(Debug, Clone, Copy)]
struct VertexConstraints {
    /// Largest x from velocities and feeds.
    x_max: f64,
    /// q' (per unit of s) and q'' of each joint.
    d1: JointVector,
    d2: JointVector,
    /// The block after the vertex's parameter length (0 at the last vertex).
    h: f64,
}

/// The constraints of the vertices of blocks: vertex i is the start of block i (vertex n the end
/// of the last). `before` is the block before the first, when the run does not start at rest
/// there (its finite differences need it); the last vertex is a rest.
fn constraints(
    before: Option<&BlockMove>,
    blocks: &[BlockMove],
    limits: &Limits,
) -> Vec<VertexConstraints> {
    let n = blocks.len();
    let h: Vec<f64> = blocks.iter().map(BlockMove::length).collect();
    let slope = |k: usize| -> JointVector { std::array::from_fn(|j| blocks[k].dq[j] / h[k]) };
    let before_slope = before.map(|b| -> (JointVector, f64) {
        let hb = b.length();
        (std::array::from_fn(|j| b.dq[j] / hb), hb)
    });
    let mut out = Vec::with_capacity(n + 1);
    for i in 0..=n {
        let (d1, d2) = match (i.checked_sub(1), (i < n).then_some(i)) {
            (None, Some(b)) if before_slope.is_some() => {
                let (w0, h0) = before_slope.unwrap_or(([0.0; 5], 1.0));
                let (w1, h1) = (slope(b), h[b]);
                (
                    std::array::from_fn(|j| (h0 * w1[j] + h1 * w0[j]) / (h0 + h1)),
                    std::array::from_fn(|j| 2.0 * (w1[j] - w0[j]) / (h0 + h1)),
                )
            }
            (Some(a), Some(b)) => {
                let (w0, w1) = (slope(a), slope(b));
                let (h0, h1) = (h[a], h[b]);
                (
                    std::array::from_fn(|j| (h0 * w1[j] + h1 * w0[j]) / (h0 + h1)),
                    std::array::from_fn(|j| 2.0 * (w1[j] - w0[j]) / (h0 + h1)),
                )
            }
            (None, Some(b)) => (slope(b), [0.0; 5]),
            (Some(a), None) => (slope(a), [0.0; 5]),
            (None, None) => ([0.0; 5], [0.0; 5]),
        };
        // Velocities, and the feeds of the blocks on either side (as path speeds).
        let mut x_max = f64::INFINITY;
        for (d, v) in d1.iter().zip(&limits.velocity) {
            if *d != 0.0 {
                x_max = x_max.min((v / d).powi(2));
            }
        }
        for k in [i.checked_sub(1), (i < n).then_some(i)]
            .into_iter()
            .flatten()
        {
            x_max = x_max.min((h[k] / blocks[k].min_time.max(1e-300)).powi(2));
        }
        if (i == 0 && before.is_none()) || i == n {
            x_max = 0.0;
        }
        out.push(VertexConstraints {
            x_max,
            d1,
            d2,
            h: if i < n { h[i] } else { 0.0 },
        });
    }
    out
}

/// The range [lo, hi] of u at vertex `c` with state `x`, such that the next state
/// x + 2 h u lies in [0, next_max]; `None` when empty.
fn u_range(c: &VertexConstraints, x: f64, next_max: f64, limits: &Limits) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for j in 0..5 {
        let (a, b) = (c.d1[j], c.d2[j]);
        let acc = limits.acceleration[j];
        if a == 0.0 {
            if (b * x).abs() > acc * (1.0 + 1e-12) {
                return None;
            }
            continue;
        }
        let (u1, u2) = ((-acc - b * x) / a, (acc - b * x) / a);
        lo = lo.max(u1.min(u2));
        hi = hi.min(u1.max(u2));
    }
    if c.h > 0.0 {
        lo = lo.max(-x / (2.0 * c.h));
        hi = hi.min((next_max - x) / (2.0 * c.h));
    }
    (lo <= hi + 1e-12 * (lo.abs() + hi.abs() + 1.0)).then_some((lo, hi.max(lo)))
}

/// The largest x at vertex `c` from which the next state can be kept within [0, next_max]: the
/// upper end of the controllable set (a two-variable linear program, solved by its constraint
/// lines pairwise).
fn controllable(c: &VertexConstraints, next_max: f64, limits: &Limits) -> f64 {
    // Constraints as lower and upper bounds on u, each linear in x: u >= p + q x, u <= r + t x.
    let mut lower: Vec<(f64, f64)> = Vec::with_capacity(7);
    let mut upper: Vec<(f64, f64)> = Vec::with_capacity(7);
    let mut x_max = c.x_max;
    for j in 0..5 {
        let (a, b) = (c.d1[j], c.d2[j]);
        let acc = limits.acceleration[j];
        if a == 0.0 {
            if b != 0.0 {
                x_max = x_max.min(acc / b.abs());
            }
            continue;
        }
        // -acc <= a u + b x <= acc.
        let l = ((-acc) / a, -b / a);
        let u = (acc / a, -b / a);
        if a > 0.0 {
            lower.push(l);
            upper.push(u);
        } else {
            lower.push(u);
            upper.push(l);
        }
    }
    if c.h > 0.0 {
        // 0 <= x + 2 h u <= next_max.
        lower.push((0.0, -1.0 / (2.0 * c.h)));
        upper.push((next_max / (2.0 * c.h), -1.0 / (2.0 * c.h)));
    }
    // Each pair: p + q x <= r + t x, i.e. (q - t) x <= r - p.
    for &(p, q) in &lower {
        for &(r, t) in &upper {
            let slope = q - t;
            if slope > 0.0 {
                x_max = x_max.min((r - p) / slope);
            }
        }
    }
    x_max.max(0.0)
}

/// The largest controllable x at each vertex (the backward pass), with rest after the last.
fn backward(cons: &[VertexConstraints], limits: &Limits) -> Vec<f64> {
    let n = cons.len() - 1;
    let mut k_max = vec![0.0; n + 1];
    for i in (0..n).rev() {
        k_max[i] = controllable(&cons[i], k_max[i + 1], limits);
    }
    k_max
}

/// The largest reachable x at vertices 1..=upto from `x0` at vertex 0 within the controllable
/// sets (the forward pass); x[0] = x0.
fn forward(
    cons: &[VertexConstraints],
    k_max: &[f64],
    x0: f64,
    upto: usize,
    limits: &Limits,
) -> Vec<f64> {
    let mut x = vec![0.0; upto + 1];
    x[0] = x0.min(k_max[0]);
    for i in 0..upto {
        let next = match u_range(&cons[i], x[i], k_max[i + 1], limits) {
            Some((_, hi)) => x[i] + 2.0 * cons[i].h * hi,
            None => 0.0,
        };
        x[i + 1] = next.clamp(0.0, k_max[i + 1]);
    }
    x
}

/// Block times from the vertices' states: T = 2 h / (sqrt(x_i) + sqrt(x_(i+1))), the path
/// acceleration constant over the block. A block next to a stop moves at its other end's speed
/// (the vertex model would spread the start over the whole block and take twice the time the
/// block model needs); a block at rest at both its ends (a run of one block) takes the shortest
/// time that starts and stops it within the block model ([`rest_to_rest_time`]).
fn times_of(
    cons: &[VertexConstraints],
    x: &[f64],
    blocks: &[BlockMove],
    limits: &Limits,
) -> Vec<f64> {
    (0..x.len().saturating_sub(1))
        .map(|i| {
            let (a, b) = (x[i].sqrt(), x[i + 1].sqrt());
            let (lo, hi) = (a.min(b), a.max(b));
            if hi <= 0.0 {
                rest_to_rest_time(&blocks[i], limits)
            } else if lo <= 1e-6 * hi {
                // A block next to a stop: in the block model its velocity is reached (or lost)
                // at the vertex, not spread over the block; [`repair`] holds that vertex to the
                // acceleration limits.
                cons[i].h / hi
            } else {
                2.0 * cons[i].h / (a + b)
            }
        })
        .collect()
}

/// The shortest time of a block from rest to rest in the block model: each joint's velocity
/// dq / T reached and lost over half the time, 2 |dq| / T^2 <= a_max; within the joints'
/// speeds and the feed too.
pub fn rest_to_rest_time(b: &BlockMove, limits: &Limits) -> f64 {
    let mut t = b.min_time.max(1.0 / rate_cap(b, limits));
    for j in 0..5 {
        t = t.max((2.0 * b.dq[j].abs() / limits.acceleration[j]).sqrt());
    }
    t.max(STILL_TIME_S * 1e-3)
}

/// The time-optimal durations of a run of blocks from rest to rest under `limits` (TOPP-RA on
/// the vertices), before [`repair`].
fn optimal_times(blocks: &[BlockMove], limits: &Limits) -> Vec<f64> {
    let cons = constraints(None, blocks, limits);
    let k_max = backward(&cons, limits);
    let x = forward(&cons, &k_max, 0.0, blocks.len(), limits);
    times_of(&cons, &x, blocks, limits)
}

/// The largest y in (0, y_max] with |b w - a y| <= (acc / 2) (1/y + 1/w): block k's rate y
/// (velocity a y) next to block k+1's rate w (velocity b w), one joint.
fn largest_rate_below(a: f64, b: f64, w: f64, acc: f64, y_max: f64) -> f64 {
    let ok = |y: f64| (b * w - a * y).abs() <= 0.5 * acc * (1.0 / y + 1.0 / w);
    if ok(y_max) {
        return y_max;
    }
    // phi(y) = |c - a y| y - acc/2 - acc y / (2 w) <= 0, c = b w: two quadratic pieces meeting
    // at y = c / a; the feasible set's ends are among their roots.
    let c = b * w;
    let k = acc / (2.0 * w);
    let mut ends: Vec<f64> = Vec::with_capacity(4);
    for (qa, qb) in [(-a, c - k), (a, -(c + k))] {
        // qa y^2 + qb y - acc/2 = 0.
        let qc = -0.5 * acc;
        if qa == 0.0 {
            if qb != 0.0 {
                ends.push(-qc / qb);
            }
            continue;
        }
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let r = disc.sqrt();
            ends.push((-qb + r) / (2.0 * qa));
            ends.push((-qb - r) / (2.0 * qa));
        }
    }
    ends.retain(|y| *y > 0.0 && *y < y_max);
    ends.sort_by(|x, y| y.total_cmp(x));
    for e in ends {
        // Just below a root, in case rounding left it outside.
        for y in [e, e * (1.0 - 1e-12), e * (1.0 - 1e-9)] {
            if ok(y) {
                return y;
            }
        }
    }
    // The feasible set always reaches down to zero: the smallest rate tried.
    let mut y = y_max;
    while y > 1e-300 && !ok(y) {
        y *= 0.5;
    }
    y
}

/// Lowers block rates until every vertex of the run holds the block model within `limits`:
/// of two blocks whose vertex is over, the faster one (the larger |velocity| in the worst joint)
/// is slowed to the largest rate that holds it. Rates only go down, so the passes end. The
/// first block is fixed when `fixed_first` (a block already written: the next one is slowed
/// instead); the run starts at rest when `rest_start`, ends at rest when `rest_end`.
fn repair(
    blocks: &[BlockMove],
    times: &mut [f64],
    limits: &Limits,
    fixed_first: bool,
    rest_start: bool,
    rest_end: bool,
) {
    let n = blocks.len();
    let rate = |t: f64| {
        if t.is_finite() && t > 0.0 {
            1.0 / t
        } else {
            0.0
        }
    };
    let mut y: Vec<f64> = times.iter().map(|&t| rate(t)).collect();
    for k in 0..n {
        y[k] = y[k].min(rate_cap(&blocks[k], limits));
    }
    // From and to rest: |dq| y <= acc / (2 y).
    let rests = [(rest_start, 0), (rest_end, n.saturating_sub(1))];
    for k in rests.iter().filter(|r| r.0 && n > 0).map(|r| r.1) {
        for j in 0..5 {
            let d = blocks[k].dq[j].abs();
            if d > 0.0 {
                y[k] = y[k].min((limits.acceleration[j] / (2.0 * d)).sqrt());
            }
        }
    }
    for _ in 0..4 * n + 8 {
        let mut changed = false;
        for k in 0..n.saturating_sub(1) {
            let (a, b) = (&blocks[k].dq, &blocks[k + 1].dq);
            let acc = vertex_acceleration(a, 1.0 / y[k], Some((b, 1.0 / y[k + 1])));
            if acceleration_share(&acc, limits) <= 1.0 {
                continue;
            }
            let worst = (0..5)
                .max_by(|&i, &j| {
                    (acc[i].abs() / limits.acceleration[i])
                        .total_cmp(&(acc[j].abs() / limits.acceleration[j]))
                })
                .unwrap_or(0);
            let slow_first =
                (a[worst] * y[k]).abs() >= (b[worst] * y[k + 1]).abs() && !(fixed_first && k == 0);
            let (idx, other, mine, theirs) = if slow_first {
                (k, k + 1, a, b)
            } else {
                (k + 1, k, b, a)
            };
            let mut r = y[idx];
            for _ in 0..8 {
                let before = r;
                for j in 0..5 {
                    // The constraint is symmetric in the two blocks: this block's rate with
                    // the other's fixed.
                    r = largest_rate_below(mine[j], theirs[j], y[other], limits.acceleration[j], r);
                }
                if r == before {
                    break;
                }
            }
            if r < y[idx] {
                y[idx] = r;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    for (t, r) in times.iter_mut().zip(&y) {
        *t = if *r > 0.0 { 1.0 / r } else { f64::INFINITY };
    }
}

/// The times (s) of a run of blocks from rest to rest: time-optimal within `limits`
/// ([`SAFETY`] of them) and the programmed feeds, then held to the block model. A block that
/// moves nothing takes [`STILL_TIME_S`] and the machine stops there.
pub fn schedule_run(blocks: &[BlockMove], limits: &Limits) -> Vec<f64> {
    let mut times = Vec::with_capacity(blocks.len());
    let mut start = 0;
    while start < blocks.len() {
        if blocks[start].still() {
            times.push(STILL_TIME_S);
            start += 1;
            continue;
        }
        let end = (start..blocks.len())
            .find(|&k| blocks[k].still())
            .unwrap_or(blocks.len());
        let run = &blocks[start..end];
        let mut t = optimal_times(run, &limits.scaled(SAFETY));
        repair(run, &mut t, &limits.scaled(REPAIR_SHARE), false, true, true);
        times.extend(t);
        start = end;
    }
    times
}

/// Blocks between two checks for final blocks in [`Scheduler`].
const CHECK_EVERY: usize = 256;

/// Most blocks [`Scheduler`] holds: beyond, the first half is released as if the path stopped
/// after the held blocks (slower there, never over a limit).
pub const MAX_HELD_BLOCKS: usize = 100_000;

/// The block times of a path read block by block, in bounded memory: [`Scheduler::push`] the
/// blocks of a run of feed moves, [`Scheduler::end_run`] where the machine stops (a rapid, the
/// end); each returns the times that became final, in order.
#[derive(Debug, Clone)]
pub struct Scheduler {
    limits: Limits,
    held: Vec<BlockMove>,
    /// The squared path speed at the first held block's start.
    x0: f64,
    /// The last released block and its time, when the run goes on from it.
    released: Option<(BlockMove, f64)>,
    /// Blocks released so far whose times [`Scheduler::take_times`] has not handed out.
    out: Vec<f64>,
    /// Blocks held since the last check.
    since_check: usize,
    /// Most blocks held at once.
    pub most_held: usize,
}

impl Scheduler {
    pub fn new(limits: Limits) -> Scheduler {
        Scheduler {
            limits,
            held: Vec::new(),
            x0: 0.0,
            released: None,
            out: Vec::new(),
            since_check: 0,
            most_held: 0,
        }
    }

    /// Adds the next block of the run.
    pub fn push(&mut self, b: BlockMove) {
        if b.still() {
            self.end_run();
            self.out.push(STILL_TIME_S);
            return;
        }
        self.held.push(b);
        self.most_held = self.most_held.max(self.held.len());
        self.since_check += 1;
        if self.since_check >= CHECK_EVERY {
            self.since_check = 0;
            self.release(false);
        }
    }

    /// The machine stops after the blocks pushed: every held block is released.
    pub fn end_run(&mut self) {
        self.release(true);
        self.x0 = 0.0;
        self.released = None;
    }

    /// The times released so far, in order.
    pub fn take_times(&mut self) -> Vec<f64> {
        std::mem::take(&mut self.out)
    }

    /// Releases the held blocks whose times are final (all of them at the run's end).
    fn release(&mut self, end: bool) {
        if self.held.is_empty() {
            return;
        }
        let safe = self.limits.scaled(SAFETY);
        let before = self.released.map(|(b, _)| b);
        let cons = constraints(before.as_ref(), &self.held, &safe);
        let k_max = backward(&cons, &safe);
        let n = self.held.len();
        // The last vertex whose controllable speed reached its own limit: the vertices up to it
        // are final, whatever follows.
        let upto = if end {
            n
        } else {
            match (1..n)
                .rev()
                .find(|&i| k_max[i] >= cons[i].x_max * (1.0 - 1e-12))
            {
                Some(i) => i,
                None if n >= MAX_HELD_BLOCKS => n / 2,
                None => return,
            }
        };
        let x = forward(&cons, &k_max, self.x0, upto, &safe);
        let mut times = times_of(&cons[..=upto], &x, &self.held[..upto], &safe);
        // The block model, with the block released before fixed.
        let mut run: Vec<BlockMove> = Vec::with_capacity(upto + 1);
        let mut t: Vec<f64> = Vec::with_capacity(upto + 1);
        if let Some((b, tb)) = self.released {
            run.push(b);
            t.push(tb);
        }
        run.extend_from_slice(&self.held[..upto]);
        t.append(&mut times);
        let fixed = self.released.is_some();
        repair(
            &run,
            &mut t,
            &self.limits.scaled(REPAIR_SHARE),
            fixed,
            !fixed,
            end,
        );
        let new = if fixed { &t[1..] } else { &t[..] };
        self.out.extend_from_slice(new);
        self.released = Some((self.held[upto - 1], *new.last().unwrap_or(&0.0)));
        self.x0 = x[upto];
        self.held.drain(..upto);
    }
}

/// What limits a block's time: its feed, a joint's speed, a joint's acceleration at one of its
/// vertices, or nothing (a block whose neighbours hold it back).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Limiting {
    Feed,
    Velocity(usize),
    Acceleration(usize),
}

/// The constraint nearest its limit in block `k` of a timed run (`times`), and how near (1 = at
/// the limit).
pub fn limiting(blocks: &[BlockMove], times: &[f64], k: usize, limits: &Limits) -> (Limiting, f64) {
    let b = &blocks[k];
    let t = times[k];
    let mut best = (Limiting::Feed, b.min_time / t);
    for j in 0..5 {
        let share = (b.dq[j] / t).abs() / limits.velocity[j];
        if share > best.1 {
            best = (Limiting::Velocity(j), share);
        }
    }
    let before = k
        .checked_sub(1)
        .map(|p| vertex_acceleration(&blocks[p].dq, times[p], Some((&b.dq, t))))
        .unwrap_or_else(|| vertex_acceleration(&[0.0; 5], 0.0, Some((&b.dq, t))));
    let after = vertex_acceleration(&b.dq, t, blocks.get(k + 1).map(|n| (&n.dq, times[k + 1])));
    for acc in [before, after] {
        for (j, (a, l)) in acc.iter().zip(&limits.acceleration).enumerate() {
            let share = a.abs() / l;
            if share > best.1 {
                best = (Limiting::Acceleration(j), share);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Limits {
        Limits::of(&crate::spec::drives::Drives::default())
    }

    /// A straight move of one slider in n equal blocks, at a feed it can reach: the profile is
    /// the bang-bang one (accelerate at the limit, cruise at the feed, decelerate), its time
    /// within 2 % of the closed form, every vertex and both rests within the model's limits.
    #[test]
    fn a_straight_move_accelerates_cruises_and_stops() {
        let l = limits();
        let (n, total, feed) = (400, 200.0, 100.0);
        let d = total / n as f64;
        let blocks: Vec<BlockMove> = (0..n)
            .map(|_| BlockMove {
                dq: [d, 0.0, 0.0, 0.0, 0.0],
                tip_mm: d,
                turn_rad: 0.0,
                min_time: d / feed,
            })
            .collect();
        let times = schedule_run(&blocks, &l);
        let a = l.acceleration[0];
        let exact = total / feed + feed / a;
        let got: f64 = times.iter().sum();
        assert!(
            got >= exact * 0.999 && got < exact * 1.02,
            "{got} vs {exact}"
        );
        check_model(&blocks, &times, &l);
    }

    /// The model holds everywhere (velocities, feeds, vertices, rests), to the rounding of the
    /// limits' share.
    fn check_model(blocks: &[BlockMove], times: &[f64], l: &Limits) {
        let n = blocks.len();
        for k in 0..n {
            assert!(
                times[k] >= blocks[k].min_time * (1.0 - 1e-12),
                "feed at {k}"
            );
            for j in 0..5 {
                assert!((blocks[k].dq[j] / times[k]).abs() <= l.velocity[j] * (1.0 + 1e-9));
            }
            let prev = if k == 0 {
                vertex_acceleration(&[0.0; 5], 0.0, Some((&blocks[0].dq, times[0])))
            } else {
                vertex_acceleration(
                    &blocks[k - 1].dq,
                    times[k - 1],
                    Some((&blocks[k].dq, times[k])),
                )
            };
            assert!(
                acceleration_share(&prev, l) <= 1.0 + 1e-9,
                "vertex before {k}: {prev:?}"
            );
        }
        let last = vertex_acceleration(&blocks[n - 1].dq, times[n - 1], None);
        assert!(acceleration_share(&last, l) <= 1.0 + 1e-9, "stop: {last:?}");
    }

    /// A reversal of one joint (a V in joint space): the joint must stop at the corner; the
    /// times hold the model, and a coarse independent optimum (every block at one rate from a
    /// fine grid, the best feasible sequence by dynamic programming) is not faster by more
    /// than 5 %.
    #[test]
    fn a_reversal_is_timed_near_the_independent_optimum() {
        let l = limits();
        let mut blocks = Vec::new();
        for k in 0..12 {
            let d = if k < 6 { 2.0 } else { -2.0 };
            blocks.push(BlockMove {
                dq: [d, 0.5, 0.0, 0.0, 0.0],
                tip_mm: 2.0,
                turn_rad: 0.0,
                min_time: 2.0 / 400.0,
            });
        }
        let times = schedule_run(&blocks, &l);
        check_model(&blocks, &times, &l);
        let ours: f64 = times.iter().sum();
        let best = dp_optimum(&blocks, &l, 600);
        assert!(
            ours <= best * 1.05,
            "{ours} vs the dynamic programme's {best}"
        );
    }

    /// Pushed block by block, with ends of runs between, the scheduler gives the times of the
    /// whole run scheduled at once (its windows are exact), in fewer blocks held than the path
    /// has; every vertex holds the model.
    #[test]
    fn streaming_gives_the_whole_path_times() {
        let l = limits();
        // A long path of short blocks: a slider sweep with slow corners every 300 blocks.
        let blocks: Vec<BlockMove> = (0..3000)
            .map(|k| {
                let phase = (k / 300) % 2;
                let d = if phase == 0 { 0.3 } else { -0.3 };
                let wobble = 0.05 * ((k as f64) * 0.05).sin();
                BlockMove {
                    dq: [d, wobble, 0.0, 0.0, 0.002 * wobble],
                    tip_mm: 0.3,
                    turn_rad: 0.0,
                    min_time: 0.3 / 200.0,
                }
            })
            .collect();
        let whole = schedule_run(&blocks, &l);
        let mut s = Scheduler::new(l);
        let mut streamed = Vec::new();
        for b in &blocks {
            s.push(*b);
            streamed.extend(s.take_times());
        }
        s.end_run();
        streamed.extend(s.take_times());
        assert_eq!(streamed.len(), blocks.len());
        check_model(&blocks, &streamed, &l);
        let (a, b): (f64, f64) = (whole.iter().sum(), streamed.iter().sum());
        assert!((a - b).abs() <= 1e-3 * a, "whole {a} vs streamed {b}");
        assert!(s.most_held < blocks.len() / 2, "held {}", s.most_held);
    }

    /// The fastest feasible times by dynamic programming over `grid` rates per block (log
    /// spaced), in the block model itself: an independent, slow optimum.
    fn dp_optimum(blocks: &[BlockMove], l: &Limits, grid: usize) -> f64 {
        let n = blocks.len();
        let caps: Vec<f64> = blocks.iter().map(|b| rate_cap(b, l)).collect();
        let rates = |k: usize| -> Vec<f64> {
            (0..grid)
                .map(|i| caps[k] * (1e-3f64).powf(i as f64 / (grid - 1) as f64))
                .collect()
        };
        let start_ok = |k: usize, y: f64| {
            let acc = vertex_acceleration(&[0.0; 5], 0.0, Some((&blocks[k].dq, 1.0 / y)));
            acceleration_share(&acc, l) <= 1.0
        };
        let mut cost: Vec<f64> = rates(0)
            .iter()
            .map(|&y| {
                if start_ok(0, y) {
                    1.0 / y
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        let mut prev_rates = rates(0);
        for k in 1..n {
            let r = rates(k);
            let next: Vec<f64> = r
                .iter()
                .map(|&y| {
                    prev_rates
                        .iter()
                        .zip(&cost)
                        .filter(|&(&yp, _)| {
                            let acc = vertex_acceleration(
                                &blocks[k - 1].dq,
                                1.0 / yp,
                                Some((&blocks[k].dq, 1.0 / y)),
                            );
                            acceleration_share(&acc, l) <= 1.0
                        })
                        .map(|(_, c)| c + 1.0 / y)
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            cost = next;
            prev_rates = r;
        }
        prev_rates
            .iter()
            .zip(&cost)
            .filter(|&(&y, _)| {
                let acc = vertex_acceleration(&blocks[n - 1].dq, 1.0 / y, None);
                acceleration_share(&acc, l) <= 1.0
            })
            .map(|(_, c)| *c)
            .fold(f64::INFINITY, f64::min)
    }
}
