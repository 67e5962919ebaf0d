//! Arcs (`G2` clockwise, `G3` counter-clockwise, seen from the positive end of the axis normal
//! to the plane): centre format (`I J K`, incremental under `G91.1`, absolute under `G90.1`)
//! or radius format (`R`, negative for more than half a turn), `P` turns, helices (the normal
//! axis and every other axis move linearly along the arc), interpolated so that every chord
//! stays within the chord tolerance of the arc.

use std::f64::consts::{FRAC_PI_2, TAU};

use super::block::Word;
use super::error::GcodeError;
use super::reader::{Feed, Plane, State, target};
use super::types::{Axis, Kind, Motion, Options, Row};

/// The most turns an arc's `P` word may ask for (each turn is interpolated).
pub const MAX_ARC_TURNS: f64 = 10_000.0;

/// The words of an arc block.
pub(crate) struct ArcWords<'a> {
    pub axes: &'a [Option<(f64, Word)>; 9],
    pub ijk: [Option<(f64, Word)>; 3],
    pub r: Option<(f64, Word)>,
    pub p: Option<(f64, Word)>,
    pub first: Word,
}

/// Radii at the start and the end may differ by this much (mm) before the arc is refused
/// (LinuxCNC refuses at about this; smaller differences make a spiral).
pub const RADIUS_TOLERANCE_MM: f64 = 0.01;

/// Interpolates one arc block into `out`, ending exactly at its end point.
#[allow(clippy::too_many_arguments)]
pub(crate) fn interpolate(
    state: &mut State,
    options: &Options,
    line: u64,
    n: Option<u64>,
    clockwise: bool,
    w: &ArcWords,
    feed: Feed,
    out: &mut Vec<Row>,
) -> Result<(), GcodeError> {
    let col = |word: &Word| Some(u64::from(word.column));
    let err = |word: &Word, m: String| Err(GcodeError::new(line, col(word), m));
    // The plane's two axes and its normal; the centre words of each (LinuxCNC: G17 I J,
    // G18 K I, G19 J K).
    let (a0, a1, c0, c1) = match state.plane {
        Plane::Xy => (Axis::X, Axis::Y, 0, 1),
        Plane::Zx => (Axis::Z, Axis::X, 2, 0),
        Plane::Yz => (Axis::Y, Axis::Z, 1, 2),
    };
    let start = state.position;
    for a in [a0, a1] {
        if state.known & a.bit() == 0 {
            return err(
                &w.first,
                format!(
                    "an arc from a position not known yet: {} has no value before this block",
                    a.letter()
                ),
            );
        }
    }
    let (end, written) = target(state, w.axes, line)?;
    let scale = state.units.mm_per_unit();
    let (s0, s1) = (start[a0 as usize], start[a1 as usize]);
    let (e0, e1) = (end[a0 as usize], end[a1 as usize]);
    let turns_extra = match w.p {
        None => 0.0,
        Some((p, _)) if p >= 1.0 && p.fract() == 0.0 && p <= MAX_ARC_TURNS => p - 1.0,
        Some((p, pw)) => {
            return err(
                &pw,
                format!(
                    "P on an arc is the number of turns: a whole number from 1 to {MAX_ARC_TURNS}, found {p}"
                ),
            );
        }
    };
    let (centre0, centre1) = if let Some((r, rw)) = w.r {
        if let Some((_, ow)) = w.ijk.iter().flatten().next() {
            return err(
                ow,
                "an arc gives R or the centre offsets I J K, not both".into(),
            );
        }
        let r = r * scale;
        let (dx, dy) = (e0 - s0, e1 - s1);
        let d = (dx * dx + dy * dy).sqrt();
        if d < 1e-9 {
            return err(
                &rw,
                "an arc in radius format (R) cannot be a full circle: give the centre with I J K"
                    .into(),
            );
        }
        if r == 0.0 {
            return err(&rw, "the arc radius R must not be zero".into());
        }
        let half = d / 2.0;
        let h2 = r * r - half * half;
        if r.abs() < half - 1e-6 * half.max(1.0) {
            return err(
                &rw,
                format!(
                    "the radius |R| = {} mm is smaller than half the distance to the end point ({half} mm)",
                    r.abs()
                ),
            );
        }
        let h = h2.max(0.0).sqrt();
        // The centre is on the left of the chord (start -> end) for a counter-clockwise arc
        // of less than half a turn (R > 0); R < 0 or clockwise takes the other side.
        let left = clockwise == (r < 0.0);
        let (ux, uy) = (-dy / d, dx / d);
        let sign = if left { 1.0 } else { -1.0 };
        (s0 + dx / 2.0 + sign * h * ux, s1 + dy / 2.0 + sign * h * uy)
    } else {
        let o0 = w.ijk[c0].map(|(v, _)| v * scale);
        let o1 = w.ijk[c1].map(|(v, _)| v * scale);
        let normal_word = [0usize, 1, 2].into_iter().find(|&k| k != c0 && k != c1);
        if let Some(k) = normal_word
            && let Some((_, ow)) = w.ijk[k]
        {
            return err(
                &ow,
                format!(
                    "{} is not a centre offset in this plane (G17: I J, G18: I K, G19: J K)",
                    ow.letter as char
                ),
            );
        }
        if o0.is_none() && o1.is_none() {
            return err(
                &w.first,
                "an arc needs its centre (I J K) or its radius (R)".into(),
            );
        }
        if state.arc_incremental {
            (s0 + o0.unwrap_or(0.0), s1 + o1.unwrap_or(0.0))
        } else {
            match (o0, o1) {
                (Some(a), Some(b)) => (a, b),
                _ => {
                    return err(
                        &w.first,
                        "absolute arc centres (G90.1) need both centre words of the plane".into(),
                    );
                }
            }
        }
    };
    let r_start = ((s0 - centre0).powi(2) + (s1 - centre1).powi(2)).sqrt();
    let r_end = ((e0 - centre0).powi(2) + (e1 - centre1).powi(2)).sqrt();
    if r_start < 1e-9 {
        return err(
            &w.first,
            "the arc's centre is its start point (zero radius)".into(),
        );
    }
    let diff = (r_end - r_start).abs();
    if diff > RADIUS_TOLERANCE_MM && diff > 1e-3 * r_start {
        return err(
            &w.first,
            format!(
                "the end point is {r_end:.6} mm from the arc's centre but the start is {r_start:.6} mm from it (more than {RADIUS_TOLERANCE_MM} mm apart): not an arc"
            ),
        );
    }
    let th_s = (s1 - centre1).atan2(s0 - centre0);
    let th_e = (e1 - centre1).atan2(e0 - centre0);
    let full = ((s0 - e0).powi(2) + (s1 - e1).powi(2)).sqrt() < 1e-9;
    let mut sweep = if clockwise { th_s - th_e } else { th_e - th_s };
    sweep = sweep.rem_euclid(TAU);
    if full || sweep < 1e-12 {
        sweep = TAU;
    }
    sweep += turns_extra * TAU;
    let signed = if clockwise { -sweep } else { sweep };
    // Segments: the sagitta r (1 - cos(step / 2)) within the tolerance, a quarter turn at most.
    let r_max = r_start.max(r_end);
    let cos_arg = (1.0 - options.chord_tol_mm / r_max).clamp(-1.0, 1.0);
    let step = (2.0 * cos_arg.acos()).min(FRAC_PI_2);
    let segments = if step > 0.0 {
        (sweep / step).ceil().max(1.0)
    } else {
        f64::INFINITY
    };
    if segments > options.max_arc_points as f64 {
        return err(
            &w.first,
            format!(
                "this arc (radius {r_max:.4} mm, {:.1} deg) needs more than {} points at a chord tolerance of {} mm: raise the tolerance",
                sweep.to_degrees(),
                options.max_arc_points,
                options.chord_tol_mm
            ),
        );
    }
    let segments = segments as u64;
    let first_row = out.len();
    for k in 1..=segments {
        let f = k as f64 / segments as f64;
        let mut p = [0.0; 9];
        for i in 0..9 {
            p[i] = if written & (1 << i) != 0 || state.known & (1 << i) != 0 {
                start[i] + (end[i] - start[i]) * f
            } else {
                f64::NAN
            };
        }
        if k == segments {
            p = end;
        } else {
            let th = th_s + signed * f;
            let r = r_start + (r_end - r_start) * f;
            p[a0 as usize] = centre0 + r * th.cos();
            p[a1 as usize] = centre1 + r * th.sin();
        }
        out.push(Row {
            line,
            n,
            kind: Kind::Arc,
            motion: Motion::Feed,
            feed_per_min: feed.per_minute(),
            duration_s: None,
            tool: state.tool,
            position: p,
            known: state.known | written,
            written,
            tool_vector: state.tool_vector,
            comment: None,
        });
    }
    // Durations: each chord at the feed; under G93 the block's time shared by chord length.
    let rows = &mut out[first_row..];
    let mut total = 0.0;
    let mut prev = start;
    for row in rows.iter() {
        total += chord(&prev, &row.position);
        prev = row.position;
    }
    let mut prev = start;
    let count = rows.len() as f64;
    for row in rows.iter_mut() {
        let fraction = if total > 0.0 {
            chord(&prev, &row.position) / total
        } else {
            1.0 / count
        };
        row.duration_s = feed.duration_s(&prev, &row.position, fraction);
        prev = row.position;
    }
    state.position = end;
    state.known |= written;
    Ok(())
}

/// Length of the X Y Z chord from `a` to `b`.
fn chord(a: &[f64; 9], b: &[f64; 9]) -> f64 {
    (0..3)
        .map(|i| {
            let d = b[i] - a[i];
            if d.is_nan() { 0.0 } else { d * d }
        })
        .sum::<f64>()
        .sqrt()
}
