//! `verne ik --period`: a toolpath resampled at the controller's servo period, so that a joint
//! stream played one row per period (LinuxCNC's halstreamer) reproduces the programmed speed.
//! Each move takes the time its feed gives (the tool tip's path at the feed, or, when the tip
//! stays, the axis's turn in degrees at the feed, as the G-code post times it; a G-code
//! program's own time of the move where it states one, `G93`; rapids at `--rapid`); the tool
//! pose is sampled at every multiple of the period, the tip on the straight line and the tool
//! angles (phi1, phi2) interpolated linearly as the controller does
//! (`verne::machine::orientation::move_angles`: as the input states them, or from the axes), and
//! each sample is then solved by the inverse kinematics like any row.

use std::io;

use csv::ByteRecord;
use nalgebra::Vector3;
use verne::machine::orientation::{move_angles, tool_axis};

use crate::error::VerneError;
use crate::input::rows::{FieldRow, FieldRows, invalid_data};
use crate::table::{CsvSource, parse_number};

#[derive(Clone, Copy)]
enum Orientation {
    Axis([usize; 3]),
    /// phi1, phi2 columns, and whether they are in radians.
    Angles([usize; 2], bool),
}

#[derive(Clone, Copy)]
struct Pose {
    tip: Vector3<f64>,
    axis: Vector3<f64>,
    /// The tool angles (rad) when the input states them (phi1,phi2 columns, a program's angle
    /// words).
    angles: Option<(f64, f64)>,
}

/// One pose of a toolpath and the move to it, as the resampler reads it.
pub struct PathPose {
    pub tip: Vector3<f64>,
    /// Unit tool axis.
    pub axis: Vector3<f64>,
    /// The tool angles (phi1, phi2) (rad) when the input states them: the controller
    /// interpolates these.
    pub angles: Option<(f64, f64)>,
    /// The input's line, for the samples' `line` column and messages.
    pub line: String,
    /// A rapid move (timed at `--rapid`).
    pub rapid: bool,
    /// The move's feed (mm/min), when the input gives one.
    pub feed_mm_min: Option<f64>,
    /// The move's time (s) when the input states it (a program's feed rule, `G93`).
    pub dt: Option<f64>,
}

/// A toolpath read pose by pose: a CSV ([`CsvPoses`]) or a tool-centre program's reader
/// directly (`input::gcode::TcpRows`, whose angle words are kept).
pub trait PoseStream: Send {
    /// The next pose, or `None` at the end; an error names the line.
    fn next_pose(&mut self) -> io::Result<Option<PathPose>>;
    /// Whether every pose states its tool angles (phi1,phi2 columns, a program's angle words):
    /// the samples then carry the interpolated angles, which the inverse kinematics follows as
    /// the controller does (theta2 = -phi2 even on the table normal), instead of the axis.
    fn states_angles(&self) -> bool;
}

/// The move being sampled: from `a` at `t0` to `b` at `t1` (s).
struct Move {
    a: Pose,
    b: Pose,
    t0: f64,
    t1: f64,
    line: String,
}

/// The poses of a CSV toolpath (x,y,z with i,j,k or phi1,phi2, and feed, motion, line, dt when
/// present).
pub struct CsvPoses {
    src: CsvSource,
    line: Option<usize>,
    motion: Option<usize>,
    feed: Option<usize>,
    dt: Option<usize>,
    xyz: [usize; 3],
    orientation: Orientation,
    rec: ByteRecord,
}

impl CsvPoses {
    /// The poses of `src`; angle columns in radians when `radians`.
    pub fn new(src: CsvSource, radians: bool) -> Result<CsvPoses, VerneError> {
        let has = |c: &str| src.column(c).is_some();
        let orientation = if has("i") || !has("phi1") {
            let c = src.require(&["x", "y", "z", "i", "j", "k"])?;
            Orientation::Axis([c[3], c[4], c[5]])
        } else {
            let c = src.require(&["x", "y", "z", "phi1", "phi2"])?;
            Orientation::Angles([c[3], c[4]], radians)
        };
        let xyz = src.require(&["x", "y", "z"])?;
        if src.column("feed").is_none() && src.column("dt").is_none() {
            return Err(VerneError::input(
                src.name(),
                Some(1),
                None,
                "--period times each move by its feed: the input needs a `feed` column (mm/min), as CL files and G-code programs give",
            ));
        }
        Ok(CsvPoses {
            line: src.column("line"),
            motion: src.column("motion"),
            feed: src.column("feed"),
            dt: src.column("dt"),
            xyz: [xyz[0], xyz[1], xyz[2]],
            orientation,
            rec: ByteRecord::new(),
            src,
        })
    }

    fn number(&self, i: usize, what: &str, line: &str) -> io::Result<f64> {
        parse_number(self.rec.get(i).unwrap_or(b"")).map_err(|_| {
            invalid_data(format!(
                "line {line}: expected a number in `{what}`, found `{}`",
                String::from_utf8_lossy(self.rec.get(i).unwrap_or(b""))
            ))
        })
    }

    /// A cell that may hold a number: its value, or None (empty, or not a number).
    fn optional(&self, i: Option<usize>) -> Option<f64> {
        i.and_then(|i| parse_number(self.rec.get(i).unwrap_or(b"")).ok())
    }
}

impl PoseStream for CsvPoses {
    fn states_angles(&self) -> bool {
        matches!(self.orientation, Orientation::Angles(..))
    }

    fn next_pose(&mut self) -> io::Result<Option<PathPose>> {
        let more = self
            .src
            .read(&mut self.rec)
            .map_err(|e| invalid_data(e.to_string()))?;
        if !more {
            return Ok(None);
        }
        let line = match self.line {
            Some(i) => String::from_utf8_lossy(self.rec.get(i).unwrap_or(b"")).into_owned(),
            None => self
                .rec
                .position()
                .map(|p| p.line().to_string())
                .unwrap_or_default(),
        };
        let tip = Vector3::new(
            self.number(self.xyz[0], "x", &line)?,
            self.number(self.xyz[1], "y", &line)?,
            self.number(self.xyz[2], "z", &line)?,
        );
        let mut angles = None;
        let axis = match self.orientation {
            Orientation::Axis(c) => {
                let v = Vector3::new(
                    self.number(c[0], "i", &line)?,
                    self.number(c[1], "j", &line)?,
                    self.number(c[2], "k", &line)?,
                );
                let n = v.norm();
                if n.is_nan() || n <= 1e-12 {
                    return Err(invalid_data(format!("line {line}: the tool axis is zero")));
                }
                v / n
            }
            Orientation::Angles(c, radians) => {
                let to_rad = |v: f64| if radians { v } else { v.to_radians() };
                let (p1, p2) = (
                    to_rad(self.number(c[0], "phi1", &line)?),
                    to_rad(self.number(c[1], "phi2", &line)?),
                );
                angles = Some((p1, p2));
                tool_axis(p1, p2)
            }
        };
        let rapid = self
            .motion
            .is_some_and(|i| self.rec.get(i).is_some_and(|m| m == b"rapid"));
        Ok(Some(PathPose {
            tip,
            axis,
            angles,
            feed_mm_min: self.optional(self.feed),
            dt: self.optional(self.dt),
            rapid,
            line,
        }))
    }
}

/// A toolpath resampled at a period; rows `line,t,x,y,z,i,j,k`, or `line,t,x,y,z,phi1,phi2`
/// when the input states its angles.
pub struct Resampler {
    poses: Box<dyn PoseStream>,
    /// The samples' angles and their unit, when the input states angles: Some(radians).
    angles_out: Option<bool>,
    period: f64,
    rapid_mm_min: Option<f64>,
    current: Option<Move>,
    /// Index of the next sample (time = index * period).
    tick: u64,
    last: Option<(Pose, f64, String)>,
    done: bool,
}

impl Resampler {
    /// Resamples `poses` every `period` seconds; rapids at `rapid_mm_min` (mm/min) when given;
    /// angles written in radians when `radians` (as the rows' reader will read them).
    pub fn new(
        poses: Box<dyn PoseStream>,
        period: f64,
        rapid_mm_min: Option<f64>,
        radians: bool,
    ) -> Resampler {
        Resampler {
            angles_out: poses.states_angles().then_some(radians),
            poses,
            period,
            rapid_mm_min,
            current: None,
            tick: 0,
            last: None,
            done: false,
        }
    }

    /// The time of the move from `a` to `b` (s): as the input states it, else its length (or,
    /// when the tip stays, the axis's turn in degrees) at its feed or the rapid rate.
    fn duration(&self, a: &Pose, b: &Pose, to: &PathPose) -> io::Result<f64> {
        if let Some(dt) = to.dt {
            return Ok(dt.max(0.0));
        }
        let line = &to.line;
        let rate = if to.rapid {
            self.rapid_mm_min.ok_or_else(|| {
                invalid_data(format!(
                    "line {line}: a rapid move: --period needs the machine's rapid rate to time it (--rapid MM_MIN)"
                ))
            })?
        } else {
            to.feed_mm_min.filter(|f| *f > 0.0).ok_or_else(|| {
                invalid_data(format!(
                    "line {line}: a feed move without a feed: --period times each move by its feed"
                ))
            })?
        };
        let length = (b.tip - a.tip).norm();
        let turn = a.axis.angle(&b.axis).to_degrees();
        let per_minute = if length > 1e-9 { length } else { turn };
        Ok(60.0 * per_minute / rate)
    }

    fn write_sample(&self, row: &mut FieldRow<'_>, line: &str, t: f64, p: &Pose) {
        row.field(line);
        row.field(format_args!("{t:.6}"));
        for v in p.tip.iter() {
            row.field(v);
        }
        match (self.angles_out, p.angles) {
            (Some(radians), Some((p1, p2))) => {
                let unit = |v: f64| if radians { v } else { v.to_degrees() };
                row.field(unit(p1));
                row.field(unit(p2));
            }
            _ => {
                for v in p.axis.iter() {
                    row.field(v);
                }
            }
        }
    }
}

impl PathPose {
    fn pose(&self) -> Pose {
        Pose {
            tip: self.tip,
            axis: self.axis,
            angles: self.angles,
        }
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

impl FieldRows for Resampler {
    fn header(&self) -> &'static [&'static str] {
        if self.angles_out.is_some() {
            &["line", "t", "x", "y", "z", "phi1", "phi2"]
        } else {
            &["line", "t", "x", "y", "z", "i", "j", "k"]
        }
    }

    fn next_row(&mut self, out: &mut FieldRow<'_>) -> io::Result<bool> {
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
                    self.write_sample(out, &m.line, t, &p);
                    self.tick += 1;
                    return Ok(true);
                }
                self.current = None;
            }
            if self.done {
                return Ok(false);
            }
            match self.poses.next_pose()? {
                None => {
                    self.done = true;
                    // The end of the path, if it fell between two ticks.
                    if let Some((p, t, line)) = self.last.take()
                        && (self.tick as f64 * self.period) - t < self.period * (1.0 - 1e-9)
                        && self.tick > 0
                        && ((self.tick - 1) as f64 * self.period) < t - 1e-9 * self.period
                    {
                        self.write_sample(out, &line, t, &p);
                        return Ok(true);
                    }
                    return Ok(false);
                }
                Some(to) => match self.last.take() {
                    None => {
                        let (b, line) = (to.pose(), to.line);
                        self.last = Some((b, 0.0, line.clone()));
                        self.current = Some(Move {
                            a: b,
                            b,
                            t0: 0.0,
                            t1: 0.0,
                            line,
                        });
                    }
                    Some((a, t0, _)) => {
                        let b = to.pose();
                        let d = self.duration(&a, &b, &to)?;
                        let line = to.line;
                        let t1 = t0 + d;
                        self.last = Some((b, t1, line.clone()));
                        self.current = Some(Move { a, b, t0, t1, line });
                    }
                },
            }
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
