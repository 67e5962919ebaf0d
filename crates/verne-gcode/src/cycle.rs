//! Canned cycles in the XY plane under G90, expanded into their moves as LinuxCNC makes them
//! (LinuxCNC G-code reference, "Canned cycles", checked against `rs274 -g`): preliminary
//! motion (Z up to R if below it, rapid to X Y, rapid down to R), the cycle's moves, then the
//! retract to R (G99) or to the level the block started from, if above R (G98). G81 drill, G82 drill and dwell, G83 peck drill
//! (rapid out to R after each peck), G73 chip-breaking peck (a small retract after each peck),
//! G85/G89 bore (feed out), G86 bore (rapid out with the spindle stopped), G84/G74 tapping (feed
//! in and out at the programmed feed). The rest are refused with the line.

use super::block::Word;
use super::error::GcodeError;
use super::reader::{Feed, Plane, State, target};
use super::types::{Axis, Kind, Motion, Row};

/// The words of a cycle block.
pub(crate) struct CycleWords<'a> {
    pub axes: &'a [Option<(f64, Word)>; 9],
    pub r: Option<(f64, Word)>,
    pub q: Option<(f64, Word)>,
    pub p: Option<(f64, Word)>,
    pub l: Option<(f64, Word)>,
    pub first: Word,
}

/// Clearance of G73's retract and of G83's return above the previous depth: LinuxCNC's 0.010
/// inch, in mm.
pub const PECK_CLEARANCE_MM: f64 = 0.254;

const X: usize = Axis::X as usize;
const Y: usize = Axis::Y as usize;
const Z: usize = Axis::Z as usize;

/// Expands one cycle block (the cycle `code` is the G number times ten) into `out`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn expand(
    state: &mut State,
    line: u64,
    n: Option<u64>,
    code: u16,
    w: &CycleWords,
    feed: Feed,
    out: &mut Vec<Row>,
) -> Result<(), GcodeError> {
    let col = |word: &Word| Some(u64::from(word.column));
    let fail = |word: &Word, m: String| Err(GcodeError::new(line, col(word), m));
    if state.plane != Plane::Xy {
        return fail(
            &w.first,
            "canned cycles are expanded in the XY plane (G17) only".into(),
        );
    }
    if state.incremental {
        return fail(
            &w.first,
            "canned cycles under G91 (incremental, with L repeats) are not expanded by verne: write them under G90".into(),
        );
    }
    if let Some((_, lw)) = w.l {
        return fail(
            &lw,
            "L (repeats of a cycle) is not expanded by verne".into(),
        );
    }
    for (i, a) in w.axes.iter().enumerate() {
        if let Some((_, aw)) = a
            && i > Z
        {
            return fail(aw, "a canned cycle with axis words other than X Y Z".into());
        }
    }
    for a in [Axis::X, Axis::Y, Axis::Z] {
        // Z must be known: the Z word of a cycle is its depth, not where the tool is.
        if state.known & a.bit() == 0 && (a == Axis::Z || w.axes[a as usize].is_none()) {
            return fail(
                &w.first,
                format!(
                    "a canned cycle from a position not known yet: {} has no value",
                    a.letter()
                ),
            );
        }
    }
    let scale = state.units.mm_per_unit();
    if let Some((r, _)) = w.r {
        state.cycle_r = Some(r * scale);
    }
    if let Some((z, _)) = w.axes[Z] {
        state.cycle_z = Some(z * scale);
    }
    if let Some((q, qw)) = w.q {
        if q <= 0.0 {
            return fail(&qw, format!("the peck depth Q must be > 0, found {q}"));
        }
        state.cycle_q = Some(q * scale);
    }
    if let Some((p, pw)) = w.p {
        if p < 0.0 {
            return fail(&pw, format!("the dwell P must be >= 0 s, found {p}"));
        }
        state.cycle_p = Some(p);
    }
    if matches!(code, 820 | 860 | 890) && state.cycle_p.is_none() {
        return fail(
            &w.first,
            format!("G{} needs its dwell time P (s)", code / 10),
        );
    }
    let Some(r) = state.cycle_r else {
        return fail(&w.first, "a canned cycle needs its retract plane R".into());
    };
    let Some(depth) = state.cycle_z else {
        return fail(&w.first, "a canned cycle needs its depth Z".into());
    };
    if depth > r {
        return fail(
            &w.first,
            format!("the cycle's depth Z = {depth} is above its retract plane R = {r}"),
        );
    }
    let q = match code {
        730 | 830 => match state.cycle_q {
            Some(q) => Some(q),
            None => return fail(&w.first, format!("G{} needs the peck depth Q", code / 10)),
        },
        _ => None,
    };
    // Where the hole is: X Y of the block (Z is the depth, not a position).
    let mut xy_axes = *w.axes;
    xy_axes[Z] = None;
    let (hole, _) = target(state, &xy_axes, line)?;
    // LinuxCNC's levels (interp_cycles.cc, as `rs274 -g` shows them): the first cycle of a
    // series lifts Z to R on its own if below it; every block then moves X Y at the higher of
    // Z and R (a continuing cycle with a higher R rises on the way), goes down to R, and
    // returns to R (G99) or to that level (G98).
    let fresh = !state.cycle_continuing;
    let mut p = state.position;
    let push =
        |p: &mut [f64; 9], z: f64, x: Option<(f64, f64)>, motion: Motion, out: &mut Vec<Row>| {
            let from = *p;
            if let Some((x, y)) = x {
                p[X] = x;
                p[Y] = y;
            }
            p[Z] = z;
            if motion == Motion::Rapid && from[..3] == p[..3] {
                // A rapid that goes nowhere (already at R): LinuxCNC makes none.
                return;
            }
            let feed_row = motion == Motion::Feed;
            out.push(Row {
                line,
                n,
                kind: Kind::Cycle,
                motion,
                feed_per_min: if feed_row { feed.per_minute() } else { None },
                duration_s: if feed_row {
                    feed.duration_s(&from, p, 1.0)
                } else {
                    None
                },
                tool: state.tool,
                position: *p,
                known: state.known | Axis::X.bit() | Axis::Y.bit() | Axis::Z.bit(),
                written: Axis::X.bit() | Axis::Y.bit() | Axis::Z.bit(),
                tool_vector: state.tool_vector,
                comment: None,
            });
        };
    if fresh && p[Z] < r {
        push(&mut p, r, None, Motion::Rapid, out);
    }
    let level = p[Z].max(r);
    let clear = if state.retract_to_r { r } else { level };
    push(&mut p, level, Some((hole[X], hole[Y])), Motion::Rapid, out);
    push(&mut p, r, None, Motion::Rapid, out);
    match code {
        810 | 820 => {
            push(&mut p, depth, None, Motion::Feed, out);
            push(&mut p, clear, None, Motion::Rapid, out);
        }
        860 => {
            push(&mut p, depth, None, Motion::Feed, out);
            push(&mut p, clear, None, Motion::Rapid, out);
        }
        850 | 890 | 840 | 740 => {
            push(&mut p, depth, None, Motion::Feed, out);
            push(&mut p, r, None, Motion::Feed, out);
            if clear > r {
                push(&mut p, clear, None, Motion::Rapid, out);
            }
        }
        830 | 730 => {
            let q = q.unwrap_or(r - depth);
            let mut reached = r;
            while reached > depth {
                let next = (reached - q).max(depth);
                if code == 830 && reached < r {
                    // Rapid back down to just above the previous depth.
                    push(
                        &mut p,
                        reached + PECK_CLEARANCE_MM,
                        None,
                        Motion::Rapid,
                        out,
                    );
                }
                push(&mut p, next, None, Motion::Feed, out);
                reached = next;
                if reached > depth {
                    let up = if code == 830 {
                        r
                    } else {
                        reached + PECK_CLEARANCE_MM
                    };
                    push(&mut p, up, None, Motion::Rapid, out);
                }
                if out.len() > 1_000_000 {
                    return fail(
                        &w.first,
                        "this peck cycle makes more than a million moves".into(),
                    );
                }
            }
            push(&mut p, clear, None, Motion::Rapid, out);
        }
        _ => {
            return fail(
                &w.first,
                format!("G{} is not a canned cycle verne expands", code / 10),
            );
        }
    }
    state.position = p;
    state.known |= Axis::X.bit() | Axis::Y.bit() | Axis::Z.bit();
    state.cycle_continuing = true;
    Ok(())
}
