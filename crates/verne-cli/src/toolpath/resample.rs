//! `verne ik --period`: a toolpath resampled at the controller's servo period, so that a joint
//! stream played one row per period (LinuxCNC's halstreamer) reproduces the programmed speed.
//! Each move takes the time its feed gives (the tool tip's path at the feed, or, when the tip
//! stays, the axis's turn in degrees at the feed, as the G-code post times it; the input's own
//! time of the move where it states one, a program's `G93` or a `dt` cell; rapids at the rapid
//! rate); the tool pose is sampled at every multiple of the period, the tip on the straight line
//! and the tool angles (phi1, phi2) interpolated linearly as the controller does
//! (`verne::machine::orientation::move_angles`: as the input states them, or from the axes), and
//! each sample is then solved by the inverse kinematics like any row.

use nalgebra::Vector3;
use verne::machine::orientation::{ToolAngles, ToolOrientation, move_angles, tool_axis};

use super::{Column, Field, PoseRow, ReaderReport, ToolpathSource};
use crate::error::VerneError;

/// A pose of the path: tip, unit axis and the angles the input states.
#[derive(Clone, Copy)]
struct Pose {
    tip: Vector3<f64>,
    axis: Vector3<f64>,
    angles: Option<(f64, f64)>,
}

/// The move being sampled: from `a` at `t0` to `b` at `t1` (s), towards the row of `line`.
struct Move {
    a: Pose,
    b: Pose,
    t0: f64,
    t1: f64,
    line: u64,
}

/// Most samples one run writes: a path whose feeds would make more (a feed of 1e-6 mm/min, a
/// stated time of 1e300 s) is refused at the move that passes it, with its line.
pub const MAX_SAMPLES: u64 = 1_000_000_000;

/// A toolpath resampled at a period; rows `line,t,x,y,z,i,j,k`, or `line,t,x,y,z,phi1,phi2`
/// when the input states its angles.
pub struct Resampler<S> {
    poses: S,
    /// Whether the samples carry the interpolated angles (the input states them).
    angles_out: bool,
    period: f64,
    rapid_mm_min: Option<f64>,
    current: Option<Move>,
    /// Index of the next sample (time = index * period).
    tick: u64,
    last: Option<(Pose, f64, u64)>,
    done: bool,
    row: PoseRow,
    columns: Vec<Column>,
}

impl<S: ToolpathSource> Resampler<S> {
    /// Resamples `poses` every `period` seconds; rapids at `rapid_mm_min` (mm/min) when given.
    pub fn new(poses: S, period: f64, rapid_mm_min: Option<f64>) -> Resampler<S> {
        let angles_out = poses.states_angles();
        let fields: &[Field] = if angles_out {
            &[
                Field::Line,
                Field::T,
                Field::X,
                Field::Y,
                Field::Z,
                Field::Phi1,
                Field::Phi2,
            ]
        } else {
            &[
                Field::Line,
                Field::T,
                Field::X,
                Field::Y,
                Field::Z,
                Field::I,
                Field::J,
                Field::K,
            ]
        };
        Resampler {
            angles_out,
            poses,
            period,
            rapid_mm_min,
            current: None,
            tick: 0,
            last: None,
            done: false,
            row: PoseRow::default(),
            columns: Column::typed_all(fields),
        }
    }

    fn error(&self, line: u64, message: String) -> VerneError {
        VerneError::input(self.poses.name(), Some(line), None, message)
    }

    /// The time of the move from `a` to `b` (s): as the input states it, else its length (or,
    /// when the tip stays, the axis's turn in degrees) at its feed or the rapid rate.
    fn duration(&self, a: &Pose, b: &Pose, to: &PoseRow) -> Result<f64, VerneError> {
        if let Some(dt) = to.dt {
            return Ok(dt.max(0.0));
        }
        let line = to.line;
        let rate = if to.rapid() {
            self.rapid_mm_min.ok_or_else(|| {
                self.error(
                    line,
                    "a rapid move: --period needs the machine's rapid rate to time it (the machine file's [limits] rapid_mm_min, or --rapid MM_MIN)".into(),
                )
            })?
        } else {
            to.feed.filter(|f| *f > 0.0).ok_or_else(|| {
                self.error(
                    line,
                    "a feed move without a feed: --period times each move by its feed (a CL file's FEDRAT, a program's F, a `feed` column)".into(),
                )
            })?
        };
        let length = (b.tip - a.tip).norm();
        let turn = a.axis.angle(&b.axis).to_degrees();
        let per_minute = if length > 1e-9 { length } else { turn };
        Ok(60.0 * per_minute / rate)
    }

    /// Writes the sample at `t` of pose `p` into `out`.
    fn sample(&self, out: &mut PoseRow, line: u64, t: f64, p: &Pose) {
        out.line = line;
        out.n = None;
        out.kind = None;
        out.motion = None;
        out.feed = None;
        out.dt = None;
        out.t = Some(t);
        out.tool = None;
        out.id = None;
        out.tip = p.tip;
        (out.orientation, out.stated_angles) = match (self.angles_out, p.angles) {
            (true, Some((phi1, phi2))) => (
                ToolOrientation::Angles(ToolAngles { phi1, phi2 }),
                Some((phi1, phi2)),
            ),
            _ => (ToolOrientation::Axis(p.axis), None),
        };
        out.invalid = None;
        out.cells.clear();
        out.fraction = None;
    }

    /// The pose of a row of the input, or why it has none.
    fn pose_of(&self, r: &PoseRow) -> Result<Pose, VerneError> {
        if let Some(why) = &r.invalid {
            return Err(self.error(r.line, format!("{why}: --period needs every pose")));
        }
        let axis = r.axis().map_err(|m| self.error(r.line, m))?;
        Ok(Pose {
            tip: r.tip,
            axis,
            angles: r.stated_angles,
        })
    }
}

/// The pose a fraction `s` of the way from `a` to `b`: the tip on the line, the tool angles
/// interpolated as the controller does (`orientation::move_angles`: as stated, or from the
/// axes), so that the stream follows the same path as the program run by LinuxCNC and as
/// `verne verify --recording` measures it.
fn between(a: &Pose, b: &Pose, s: f64) -> Pose {
    let tip = a.tip + (b.tip - a.tip) * s;
    let [ea, eb] = move_angles(&a.axis, a.angles, &b.axis, b.angles);
    let angles = (ea.0 + s * (eb.0 - ea.0), ea.1 + s * (eb.1 - ea.1));
    Pose {
        tip,
        axis: tool_axis(angles.0, angles.1),
        angles: Some(angles),
    }
}

impl<S: ToolpathSource> ToolpathSource for Resampler<S> {
    fn name(&self) -> &str {
        self.poses.name()
    }

    fn columns(&self) -> &[Column] {
        &self.columns
    }

    fn states_angles(&self) -> bool {
        self.angles_out
    }

    fn report(&self) -> ReaderReport {
        self.poses.report()
    }

    fn next_row(&mut self, out: &mut PoseRow) -> Result<bool, VerneError> {
        loop {
            if let Some(m) = &self.current {
                let t = self.tick as f64 * self.period;
                if t <= m.t1 + 1e-9 * self.period {
                    let s = if m.t1 > m.t0 {
                        ((t - m.t0) / (m.t1 - m.t0)).clamp(0.0, 1.0)
                    } else {
                        1.0
                    };
                    let p = between(&m.a, &m.b, s);
                    self.sample(out, m.line, t, &p);
                    self.tick += 1;
                    return Ok(true);
                }
                self.current = None;
            }
            if self.done {
                return Ok(false);
            }
            let mut row = std::mem::take(&mut self.row);
            let more = self.poses.next_row(&mut row);
            let more = match more {
                Ok(m) => m,
                Err(e) => {
                    self.row = row;
                    return Err(e);
                }
            };
            if !more {
                self.row = row;
                self.done = true;
                // The end of the path, if it fell between two ticks.
                if let Some((p, t, line)) = self.last.take()
                    && (self.tick as f64 * self.period) - t < self.period * (1.0 - 1e-9)
                    && self.tick > 0
                    && ((self.tick - 1) as f64 * self.period) < t - 1e-9 * self.period
                {
                    self.sample(out, line, t, &p);
                    return Ok(true);
                }
                return Ok(false);
            }
            let b = self.pose_of(&row);
            let line = row.line;
            let next = match (b, self.last.take()) {
                (Err(e), _) => Err(e),
                (Ok(b), None) => Ok(Move {
                    a: b,
                    b,
                    t0: 0.0,
                    t1: 0.0,
                    line,
                }),
                (Ok(b), Some((a, t0, _))) => self.duration(&a, &b, &row).and_then(|d| {
                    let t1 = t0 + d;
                    if t1 / self.period > MAX_SAMPLES as f64 {
                        return Err(self.error(
                            line,
                            format!(
                                "this move ends at t = {t1:.6e} s: more than {MAX_SAMPLES} samples of {} s, the most one run writes (is the feed or the stated time right?)",
                                self.period
                            ),
                        ));
                    }
                    Ok(Move { a, b, t0, t1, line })
                }),
            };
            self.row = row;
            let m = next?;
            self.last = Some((m.b, m.t1, line));
            self.current = Some(m);
        }
    }
}

/// Parses a servo period: `1ms`, `250us`, `0.001s` or seconds (`0.001`); > 0.
pub fn parse_period(s: &str) -> Result<f64, String> {
    let t = s.trim();
    let (number, scale) = if let Some(v) = t.strip_suffix("ms") {
        (v, 1e-3)
    } else if let Some(v) = t.strip_suffix("us") {
        (v, 1e-6)
    } else if let Some(v) = t.strip_suffix('s') {
        (v, 1.0)
    } else {
        (t, 1.0)
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v * scale >= 1e-6 && v * scale <= 10.0 => {
            Ok(v * scale)
        }
        Ok(_) => Err(format!("`{s}`: the period must be between 1us and 10s")),
        Err(_) => Err(format!(
            "`{s}` is not a period: expected e.g. 1ms, 250us, 0.001s"
        )),
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn periods() {
        assert_eq!(parse_period("1ms"), Ok(1e-3));
        assert_eq!(parse_period("250us"), Ok(250e-6));
        assert_eq!(parse_period("0.002s"), Ok(0.002));
        assert_eq!(parse_period("0.004"), Ok(0.004));
        assert!(parse_period("0ms").is_err());
        assert!(parse_period("fast").is_err());
        assert!(parse_period("1ns").is_err());
    }

    #[test]
    fn the_axis_follows_the_controllers_angles() {
        // A tilt in one plane (phi2 fixed): phi1 grows evenly, the axis stays unit.
        let a = Pose {
            tip: Vector3::zeros(),
            axis: Vector3::z(),
            angles: None,
        };
        let b = Pose {
            tip: Vector3::new(10.0, 0.0, 0.0),
            axis: tool_axis(FRAC_PI_2 / 2.0, 0.0),
            angles: None,
        };
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let p = between(&a, &b, s);
            assert!((p.axis.norm() - 1.0).abs() < 1e-12);
            assert!((p.axis.angle(&a.axis) - s * FRAC_PI_2 / 2.0).abs() < 1e-12);
            assert!((p.tip.x - 10.0 * s).abs() < 1e-12);
        }
        // Stated angles are interpolated as stated: A10 C30 -> A0 C0 turns C as it tilts back
        // (the axis alone would keep C at 30 all the way).
        let a = Pose {
            tip: Vector3::zeros(),
            axis: tool_axis(10f64.to_radians(), 30f64.to_radians()),
            angles: Some((10f64.to_radians(), 30f64.to_radians())),
        };
        let b = Pose {
            tip: Vector3::zeros(),
            axis: Vector3::z(),
            angles: Some((0.0, 0.0)),
        };
        let p = between(&a, &b, 0.5);
        let want = tool_axis(5f64.to_radians(), 15f64.to_radians());
        assert!((p.axis - want).norm() < 1e-12);
    }
}
