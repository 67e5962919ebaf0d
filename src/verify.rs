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
//! Streaming: rows are read in batches of [`BATCH_ROWS`]; each batch is solved in parallel (rayon)
//! and reported in input order, so memory does not grow with the files and results do not depend
//! on the number of threads. Only the previous row and segment are kept between batches.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt::{self, Write as _};
use std::io::BufRead;
use std::path::Path;

use arrayvec::ArrayVec;
use csv::ByteRecord;
use nalgebra::Vector3;
use rayon::prelude::*;

use crate::apt::{AptReader, MotionKind};
use crate::branches::{Config, Reason, WORKING_CONFIG, config_of};
use crate::error::VerneError;
use crate::jacobian::kinetostatics;
use crate::machine::{Machine, MachineError, Problem};
use crate::machine_kin::{machine_fk, tool_pose_eq26};
use crate::module_geometry::{ModulePose, Sliders, polish_pose, residual_mm, rod_tilts};
use crate::module_ik::wrap_angle;
use crate::orientation::{ROTARY_SINGULAR_CONE_RAD, tool_axis, unit_axis};
use crate::table::{CellError, CsvSource, parse_number, shown};
use crate::tolerance::ACCEPT_RESIDUAL_MM;

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

// ---------------------------------------------------------------------------------------------
// Thresholds

/// One threshold: name (as in `[verify]` and `--threshold`), default, unit, meaning.
#[derive(Debug, Clone, Copy)]
pub struct ThresholdSpec {
    pub name: &'static str,
    pub default: f64,
    pub unit: &'static str,
    pub meaning: &'static str,
}

/// Index of a threshold in [`THRESHOLDS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Th {
    TipErrorMm,
    AxisErrorDeg,
    ChordErrorMm,
    LambdaMin,
    LambdaMax,
    ParallelMarginMin,
    RhoStepMm,
    Theta1StepDeg,
    Theta2StepDeg,
    Theta2FlipTolDeg,
    RhoVelocityMmS,
    Theta1VelocityDegS,
    Theta2VelocityDegS,
    RhoAccelMmS2,
    Theta1AccelDegS2,
    Theta2AccelDegS2,
}

/// Every threshold with its default. The velocity and acceleration limits are assumptions (the
/// VERNE's drive data are not published): set them from the machine's data sheet.
pub const THRESHOLDS: [ThresholdSpec; 16] = [
    ThresholdSpec {
        name: "tip_error_mm",
        default: 0.005,
        unit: "mm",
        meaning: "tip of fk(joints) vs the intended tip",
    },
    ThresholdSpec {
        name: "axis_error_deg",
        default: 0.005,
        unit: "deg",
        meaning: "axis of fk(joints) vs the intended axis",
    },
    ThresholdSpec {
        name: "chord_error_mm",
        default: 0.01,
        unit: "mm",
        meaning: "tip at the joints' midpoint vs the intended midpoint",
    },
    ThresholdSpec {
        name: "lambda_min",
        default: 1.0 / 3.0,
        unit: "",
        meaning: "smallest velocity amplification factor",
    },
    ThresholdSpec {
        name: "lambda_max",
        default: 3.0,
        unit: "",
        meaning: "largest velocity amplification factor",
    },
    ThresholdSpec {
        name: "parallel_margin_min",
        default: 0.05,
        unit: "",
        meaning: "smallest inverse condition number of A",
    },
    ThresholdSpec {
        name: "rho_step_mm",
        default: 20.0,
        unit: "mm",
        meaning: "largest slider change between rows",
    },
    ThresholdSpec {
        name: "theta1_step_deg",
        default: 5.0,
        unit: "deg",
        meaning: "largest tilting-axis change between rows",
    },
    ThresholdSpec {
        name: "theta2_step_deg",
        default: 30.0,
        unit: "deg",
        meaning: "largest rotary-axis change between rows",
    },
    ThresholdSpec {
        name: "theta2_flip_tol_deg",
        default: 20.0,
        unit: "deg",
        meaning: "theta2 change this close to 180 deg: a flip",
    },
    ThresholdSpec {
        name: "rho_velocity_mm_s",
        default: 500.0,
        unit: "mm/s",
        meaning: "slider speed (needs a t or feed column)",
    },
    ThresholdSpec {
        name: "theta1_velocity_deg_s",
        default: 90.0,
        unit: "deg/s",
        meaning: "tilting-axis speed",
    },
    ThresholdSpec {
        name: "theta2_velocity_deg_s",
        default: 180.0,
        unit: "deg/s",
        meaning: "rotary-axis speed",
    },
    ThresholdSpec {
        name: "rho_accel_mm_s2",
        default: 5000.0,
        unit: "mm/s^2",
        meaning: "slider acceleration",
    },
    ThresholdSpec {
        name: "theta1_accel_deg_s2",
        default: 900.0,
        unit: "deg/s^2",
        meaning: "tilting-axis acceleration",
    },
    ThresholdSpec {
        name: "theta2_accel_deg_s2",
        default: 1800.0,
        unit: "deg/s^2",
        meaning: "rotary-axis acceleration",
    },
];

/// The thresholds of one run, in the units of [`THRESHOLDS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds([f64; 16]);

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds(std::array::from_fn(|i| THRESHOLDS[i].default))
    }
}

/// The `--help` epilogue of `verne verify`: example, thresholds with defaults, exit codes.
pub fn help_text() -> String {
    let mut s = String::from(
        "Example:\n  verne verify --joints data/verify/joints.csv --path data/verify/path.csv\n  \
         verne verify --joints post.csv --path part.cl --report report.csv --format json \\\n    \
         --threshold tip_error_mm=0.01 --threshold lambda_max=4\n\n\
         Thresholds (--threshold NAME=VALUE, or NAME = VALUE in the machine file's [verify] table):\n",
    );
    for t in &THRESHOLDS {
        let _ = writeln!(
            s,
            "  {:<21} {:>6} {:<7} {}",
            t.name,
            if t.name == "lambda_min" {
                "1/3".to_string()
            } else {
                short_number(t.default)
            },
            t.unit,
            t.meaning
        );
    }
    s.push_str(
        "\nReport columns: row,check,value,limit,detail (docs/verify.md).\n\n\
         Exit codes: 0 every check passed, 1 some check failed, 2 fatal (bad arguments,\n\
         unreadable or malformed input, row counts differ without ids).",
    );
    s
}

/// Index of a threshold by name.
pub fn threshold_index(name: &str) -> Option<usize> {
    THRESHOLDS.iter().position(|t| t.name == name)
}

/// Checks one threshold value on its own; the message says what was expected.
pub fn check_threshold_value(name: &str, value: f64) -> Result<(), String> {
    let Some(i) = threshold_index(name) else {
        let names: Vec<&str> = THRESHOLDS.iter().map(|t| t.name).collect();
        return Err(format!(
            "unknown threshold `{}`; known: {}",
            shown(name.as_bytes()),
            names.join(", ")
        ));
    };
    let ok = value.is_finite()
        && match i {
            i if i == Th::ParallelMarginMin as usize => (0.0..1.0).contains(&value),
            i if i == Th::Theta2FlipTolDeg as usize => value > 0.0 && value < 90.0,
            _ => value > 0.0,
        };
    if ok {
        Ok(())
    } else if i == Th::ParallelMarginMin as usize {
        Err(format!("{name} must be in [0, 1), found {value}"))
    } else if i == Th::Theta2FlipTolDeg as usize {
        Err(format!("{name} must be in (0, 90) degrees, found {value}"))
    } else {
        Err(format!("{name} must be a positive number, found {value}"))
    }
}

impl Thresholds {
    pub fn get(&self, t: Th) -> f64 {
        self.0[t as usize]
    }

    /// Sets a threshold by name, checking the value (not the cross-checks, see [`Self::check`]).
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), String> {
        check_threshold_value(name, value)?;
        if let Some(i) = threshold_index(name) {
            self.0[i] = value;
        }
        Ok(())
    }

    /// Cross-checks between thresholds.
    pub fn check(&self) -> Result<(), String> {
        let (lo, hi) = (self.get(Th::LambdaMin), self.get(Th::LambdaMax));
        if lo >= hi {
            return Err(format!("lambda_min ({lo}) must be below lambda_max ({hi})"));
        }
        Ok(())
    }

    /// The defaults overridden by the machine file's `[verify]` table. Unknown names and bad
    /// values are reported all at once, each with its line.
    pub fn from_machine(m: &Machine, source: &str) -> Result<Thresholds, MachineError> {
        let mut t = Thresholds::default();
        let mut problems = Vec::new();
        for (name, value, line) in &m.verify {
            if let Err(message) = t.set(name, *value) {
                problems.push(Problem {
                    line: *line,
                    key: format!("verify.{name}"),
                    message,
                });
            }
        }
        if problems.is_empty()
            && let Err(message) = t.check()
        {
            problems.push(Problem {
                line: None,
                key: "verify".into(),
                message,
            });
        }
        if problems.is_empty() {
            Ok(t)
        } else {
            Err(MachineError {
                source: source.to_string(),
                problems,
            })
        }
    }

    /// Per-joint limits (rho1, rho2, rho3 in mm..., theta1, theta2 in rad...) of a kind.
    fn per_joint(&self, rho: Th, t1: Th, t2: Th) -> [f64; 5] {
        let r = self.get(rho);
        [
            r,
            r,
            r,
            self.get(t1).to_radians(),
            self.get(t2).to_radians(),
        ]
    }
}

// ---------------------------------------------------------------------------------------------
// Checks and violations

/// A kind of check, as named in the report's `check` column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Check {
    /// A required cell is empty or not finite (the row is skipped).
    Input,
    /// A joint row without an intended row, or an intended row without a joint row (ids).
    Pairing,
    /// Check 1: tool-tip position error (mm).
    TipError,
    /// Check 1: tool-axis angle error (deg).
    AxisError,
    /// Check 4: the joints are not in the working assembly mode, or consecutive rows are in
    /// different branches, or the assembly mode changes along a segment.
    Branch,
    /// Check 2: strokes, tilting-axis range, rod tilts, at a row or along a segment.
    Limits,
    /// Check 5: velocity amplification factors or parallel margin, at a row or along a segment.
    Singularity,
    /// Check 3: chordal error at the segment's midpoint (mm).
    ChordError,
    /// Check 6: joint change between two rows above its limit.
    JointJump,
    /// Check 6: theta2 turns by about half a turn between two rows.
    Theta2Flip,
    /// Check 6: joint speed (needs `t` or `feed`).
    Velocity,
    /// Check 6: joint acceleration (needs `t` or `feed`).
    Acceleration,
}

impl Check {
    pub const ALL: [Check; 12] = [
        Check::Input,
        Check::Pairing,
        Check::TipError,
        Check::AxisError,
        Check::Limits,
        Check::ChordError,
        Check::Branch,
        Check::Singularity,
        Check::JointJump,
        Check::Theta2Flip,
        Check::Velocity,
        Check::Acceleration,
    ];

    pub fn code(self) -> &'static str {
        match self {
            Check::Input => "input",
            Check::Pairing => "pairing",
            Check::TipError => "tip_error",
            Check::AxisError => "axis_error",
            Check::Branch => "branch",
            Check::Limits => "limits",
            Check::Singularity => "singularity",
            Check::ChordError => "chord_error",
            Check::JointJump => "joint_jump",
            Check::Theta2Flip => "theta2_flip",
            Check::Velocity => "velocity",
            Check::Acceleration => "acceleration",
        }
    }

    fn slot(self) -> usize {
        Check::ALL.iter().position(|c| *c == self).unwrap_or(0)
    }
}

impl fmt::Display for Check {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.code())
    }
}

/// One finding: a row of the report.
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The 1-based data row of the joint table, or its `id` when the files are paired by id. A
    /// segment's finding is placed on the row that ends it.
    pub row: String,
    pub check: Check,
    /// The measured value (units in docs/verify.md; NaN when the check has no number).
    pub value: f64,
    /// The limit it broke (NaN when none applies).
    pub limit: f64,
    /// What, where and which joint.
    pub detail: String,
    /// How far beyond the limit (>= 1, larger is worse): picks the worst finding of a check.
    pub severity: f64,
}

impl Violation {
    fn over(row: &str, check: Check, value: f64, limit: f64, detail: String) -> Violation {
        Violation {
            row: row.to_string(),
            check,
            value,
            limit,
            detail,
            severity: if limit > 0.0 {
                value.abs() / limit
            } else {
                f64::INFINITY
            },
        }
    }

    fn under(row: &str, check: Check, value: f64, limit: f64, detail: String) -> Violation {
        Violation {
            row: row.to_string(),
            check,
            value,
            limit,
            detail,
            severity: if value > 0.0 {
                limit / value
            } else {
                f64::INFINITY
            },
        }
    }

    fn plain(row: &str, check: Check, value: f64, detail: String) -> Violation {
        Violation {
            row: row.to_string(),
            check,
            value,
            limit: f64::NAN,
            detail,
            severity: 1.0,
        }
    }
}

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

/// Counts and worst finding of one check.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CheckStats {
    /// Violations.
    pub count: u64,
    /// The worst value measured (a violation, or on a clean run the value closest to its
    /// limit); `detail` is the violation's, or what was measured.
    pub worst: Option<Violation>,
}

/// The outcome of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Joint rows read.
    pub rows: u64,
    /// Segments between consecutive rows whose checks ran.
    pub segments: u64,
    /// Segments not checked because a row at either end failed its input, pairing, branch, tip
    /// or axis check (that row's finding is the one reported).
    pub segments_skipped: u64,
    /// Whether velocities and accelerations were checked (`t` or `feed` column).
    pub timed: bool,
    /// Per check, in the order of [`Check::ALL`].
    pub checks: Vec<(Check, CheckStats)>,
}

impl Summary {
    fn new() -> Summary {
        Summary {
            rows: 0,
            segments: 0,
            segments_skipped: 0,
            timed: false,
            checks: Check::ALL
                .iter()
                .map(|c| (*c, CheckStats::default()))
                .collect(),
        }
    }

    fn add(&mut self, v: &Violation) {
        let s = &mut self.checks[v.check.slot()].1;
        s.count += 1;
        if s.worst.as_ref().is_none_or(|w| v.severity >= w.severity) {
            s.worst = Some(v.clone());
        }
    }

    fn observe(&mut self, o: &Obs, row: &str) {
        let s = &mut self.checks[o.check.slot()].1;
        if s.worst.as_ref().is_none_or(|w| o.severity > w.severity) {
            s.worst = Some(Violation {
                row: row.to_string(),
                check: o.check,
                value: o.value,
                limit: o.limit,
                detail: format!("{} (within the limit)", o.what),
                severity: o.severity,
            });
        }
    }

    /// Total findings.
    pub fn violations(&self) -> u64 {
        self.checks.iter().map(|(_, s)| s.count).sum()
    }

    /// True when no check failed.
    pub fn clean(&self) -> bool {
        self.violations() == 0
    }

    /// The summary as aligned text (one line per check).
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} rows, {} segments checked ({} skipped next to a failed row){}: {}",
            self.rows,
            self.segments,
            self.segments_skipped,
            if self.timed {
                ""
            } else {
                "; no t or feed column: velocity and acceleration not checked"
            },
            if self.clean() {
                "clean".to_string()
            } else {
                format!("{} violations", self.violations())
            }
        );
        let _ = writeln!(
            s,
            "{:<13} {:>7}  {:>12}  {:>12}  {:>8}  detail of the worst",
            "check", "count", "worst", "limit", "row"
        );
        for (c, st) in &self.checks {
            match &st.worst {
                None => {
                    let _ = writeln!(s, "{:<13} {:>7}", c.code(), 0);
                }
                Some(w) => {
                    let _ = writeln!(
                        s,
                        "{:<13} {:>7}  {:>12}  {:>12}  {:>8}  {}",
                        c.code(),
                        st.count,
                        rounded_number(w.value, 6),
                        rounded_number(w.limit, 6),
                        w.row,
                        w.detail
                    );
                }
            }
        }
        s
    }

    /// The summary as one JSON object (docs/verify.md).
    pub fn to_json(&self) -> String {
        let mut s = String::new();
        let _ = write!(
            s,
            "{{\"rows\":{},\"segments\":{},\"segments_skipped\":{},\"timed\":{},\"violations\":{},\"clean\":{},\"checks\":{{",
            self.rows,
            self.segments,
            self.segments_skipped,
            self.timed,
            self.violations(),
            self.clean()
        );
        for (k, (c, st)) in self.checks.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            let _ = write!(s, "\"{}\":{{\"count\":{}", c.code(), st.count);
            match &st.worst {
                None => s.push_str(",\"worst\":null,\"limit\":null,\"row\":null,\"detail\":null}"),
                Some(w) => {
                    let _ = write!(
                        s,
                        ",\"worst\":{},\"limit\":{},\"row\":{},\"detail\":{}}}",
                        json_number(w.value),
                        json_number(w.limit),
                        json_string(&w.row),
                        json_string(&w.detail)
                    );
                }
            }
        }
        s.push_str("}}");
        s
    }
}

/// A number rounded to 9 significant digits in its shortest form; empty for NaN.
pub fn short_number(v: f64) -> String {
    rounded_number(v, 9)
}

/// A number rounded to `digits` significant digits in its shortest form; empty for NaN.
pub fn rounded_number(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return if v.is_nan() {
            String::new()
        } else {
            format!("{v}")
        };
    }
    let r: f64 = format!("{v:.*e}", digits.clamp(1, 17) - 1)
        .parse()
        .unwrap_or(v);
    let mut out = Vec::new();
    crate::table::format_number(&mut out, r, None);
    String::from_utf8(out).unwrap_or_default()
}

fn json_number(v: f64) -> String {
    if v.is_finite() {
        short_number(v)
    } else {
        "null".into()
    }
}

fn json_string(t: &str) -> String {
    let mut s = String::with_capacity(t.len() + 2);
    s.push('"');
    for ch in t.chars() {
        match ch {
            '"' => s.push_str("\\\""),
            '\\' => s.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(s, "\\u{:04x}", c as u32);
            }
            c => s.push(c),
        }
    }
    s.push('"');
    s
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
}

impl Joints {
    fn as_array(&self) -> [f64; 5] {
        [self.rho.x, self.rho.y, self.rho.z, self.theta1, self.theta2]
    }
}

/// One intended tool pose in the workpiece frame: tip (mm) and unit axis (tip towards spindle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    pub tip: Vector3<f64>,
    pub axis: Vector3<f64>,
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

const JOINT_NAMES: [&str; 5] = ["rho1", "rho2", "rho3", "theta1", "theta2"];

/// Reads a cell as a number; a non-number is fatal (file, line, column), an empty or non-finite
/// cell makes the row invalid.
fn cell(
    src_name: &str,
    rec: &ByteRecord,
    i: usize,
    col: &str,
    unit: &str,
) -> Result<Result<f64, String>, VerneError> {
    let field = rec.get(i).unwrap_or(b"");
    match parse_number(field) {
        Ok(v) => Ok(Ok(v)),
        Err(CellError::NotFinite) => Ok(Err(format!(
            "{col} is empty or not finite (`{}`)",
            shown(field)
        ))),
        Err(CellError::NotANumber) => Err(VerneError::input(
            src_name,
            rec.position().map(|p| p.line()),
            Some(col),
            format!("expected a number ({unit}), found `{}`", shown(field)),
        )),
    }
}

/// The postprocessor's joint table: `rho1,rho2,rho3` (mm), `theta1,theta2` (deg); optional `id`,
/// `t` (s), `feed` (mm/min).
pub struct JointReader {
    src: CsvSource,
    cols: [usize; 5],
    id: Option<usize>,
    t: Option<usize>,
    feed: Option<usize>,
    rec: ByteRecord,
    index: u64,
}

impl JointReader {
    pub fn new(src: CsvSource) -> Result<JointReader, VerneError> {
        let c = src.require(&JOINT_NAMES)?;
        Ok(JointReader {
            cols: [c[0], c[1], c[2], c[3], c[4]],
            id: src.column("id"),
            t: src.column("t"),
            feed: src.column("feed"),
            src,
            rec: ByteRecord::new(),
            index: 0,
        })
    }

    pub fn name(&self) -> &str {
        self.src.name()
    }

    pub fn has_id(&self) -> bool {
        self.id.is_some()
    }

    /// True when velocities can be checked.
    pub fn timed(&self) -> bool {
        self.t.is_some() || self.feed.is_some()
    }

    pub fn next_item(&mut self) -> Result<Option<Item<Joints>>, VerneError> {
        if !self.src.read(&mut self.rec)? {
            return Ok(None);
        }
        self.index += 1;
        let name = self.src.name().to_string();
        let line = self.rec.position().map(|p| p.line()).unwrap_or(0);
        let mut v = [0.0; 5];
        let mut bad = None;
        for k in 0..5 {
            let unit = if k < 3 { "mm" } else { "degrees" };
            match cell(&name, &self.rec, self.cols[k], JOINT_NAMES[k], unit)? {
                Ok(x) => v[k] = if k < 3 { x } else { x.to_radians() },
                Err(e) => {
                    bad.get_or_insert(e);
                }
            }
        }
        let optional =
            |i: Option<usize>, col: &str, unit: &str| -> Result<Option<f64>, VerneError> {
                match i {
                    None => Ok(None),
                    Some(i) => Ok(cell(&name, &self.rec, i, col, unit)?.ok()),
                }
            };
        let t = optional(self.t, "t", "s")?;
        let feed = optional(self.feed, "feed", "mm/min")?.map(|f| f / 60.0);
        let id = self
            .id
            .map(|i| String::from_utf8_lossy(self.rec.get(i).unwrap_or(b"")).into_owned());
        let value = match bad {
            Some(e) => Err(e),
            None => Ok(Joints {
                rho: Sliders::new(v[0], v[1], v[2]),
                theta1: v[3],
                theta2: v[4],
                t,
                feed,
            }),
        };
        Ok(Some(Item {
            index: self.index,
            line,
            id,
            value,
        }))
    }
}

#[allow(clippy::large_enum_variant)] // one per run
enum PathKind {
    Csv {
        src: CsvSource,
        xyz: [usize; 3],
        /// i,j,k or phi1,phi2 (then the third is unused).
        orient: [usize; 3],
        angles: bool,
        id: Option<usize>,
        rec: ByteRecord,
    },
    Apt {
        reader: Box<AptReader<Box<dyn BufRead + Send>>>,
    },
}

/// The intended path: a CSV (`x,y,z` and `i,j,k` or `phi1,phi2` in degrees, optional `id`) or an
/// APT CL file (FROM and GOTO records in file order; a 3-value record has the axis (0, 0, 1)).
pub struct PathReader {
    kind: PathKind,
    name: String,
    index: u64,
}

impl PathReader {
    /// Opens a path file: `.cl`, `.apt`, `.cls` (any case) as APT, anything else as CSV.
    pub fn open(path: &Path) -> Result<PathReader, VerneError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let name = path.display().to_string();
        if matches!(ext.as_str(), "cl" | "apt" | "cls") {
            let f = std::fs::File::open(path).map_err(|e| VerneError::io(&name, e))?;
            let r: Box<dyn BufRead + Send> = Box::new(std::io::BufReader::new(f));
            return Ok(PathReader {
                kind: PathKind::Apt {
                    reader: Box::new(AptReader::new(r)),
                },
                name,
                index: 0,
            });
        }
        Self::from_csv(CsvSource::open(Some(path))?)
    }

    /// A CSV path from an opened source.
    pub fn from_csv(src: CsvSource) -> Result<PathReader, VerneError> {
        let xyz = src.require(&["x", "y", "z"])?;
        let (orient, angles) = if src.column("i").is_some() || src.column("phi1").is_none() {
            let c = src.require(&["x", "y", "z", "i", "j", "k"])?;
            ([c[3], c[4], c[5]], false)
        } else {
            let c = src.require(&["x", "y", "z", "phi1", "phi2"])?;
            ([c[3], c[4], c[4]], true)
        };
        Ok(PathReader {
            name: src.name().to_string(),
            kind: PathKind::Csv {
                xyz: [xyz[0], xyz[1], xyz[2]],
                orient,
                angles,
                id: src.column("id"),
                src,
                rec: ByteRecord::new(),
            },
            index: 0,
        })
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn has_id(&self) -> bool {
        matches!(&self.kind, PathKind::Csv { id: Some(_), .. })
    }

    pub fn next_item(&mut self) -> Result<Option<Item<PathPoint>>, VerneError> {
        match &mut self.kind {
            PathKind::Apt { reader } => {
                let row = reader
                    .next_row()
                    .map_err(|e| VerneError::input(&self.name, None, None, e.to_string()))?;
                let Some(row) = row else { return Ok(None) };
                self.index += 1;
                let axis = row.axis.unwrap_or(Vector3::new(0.0, 0.0, 1.0));
                let value = unit_axis(&axis)
                    .map(|axis| PathPoint { tip: row.tip, axis })
                    .map_err(|e| {
                        format!(
                            "{} at line {}: {e}",
                            if row.kind == MotionKind::From {
                                "FROM"
                            } else {
                                "GOTO"
                            },
                            row.line
                        )
                    });
                Ok(Some(Item {
                    index: self.index,
                    line: row.line as u64,
                    id: None,
                    value,
                }))
            }
            PathKind::Csv {
                src,
                xyz,
                orient,
                angles,
                id,
                rec,
            } => {
                if !src.read(rec)? {
                    return Ok(None);
                }
                self.index += 1;
                let name = src.name().to_string();
                let line = rec.position().map(|p| p.line()).unwrap_or(0);
                let names: [&str; 6] = if *angles {
                    ["x", "y", "z", "phi1", "phi2", "phi2"]
                } else {
                    ["x", "y", "z", "i", "j", "k"]
                };
                let cols = [xyz[0], xyz[1], xyz[2], orient[0], orient[1], orient[2]];
                let mut v = [0.0; 6];
                let mut bad = None;
                for k in 0..6 {
                    let unit = if k < 3 {
                        "mm"
                    } else if *angles {
                        "degrees"
                    } else {
                        "unit vector component"
                    };
                    match cell(&name, rec, cols[k], names[k], unit)? {
                        Ok(x) => v[k] = x,
                        Err(e) => {
                            bad.get_or_insert(e);
                        }
                    }
                }
                let id =
                    id.map(|i| String::from_utf8_lossy(rec.get(i).unwrap_or(b"")).into_owned());
                let tip = Vector3::new(v[0], v[1], v[2]);
                let value = match bad {
                    Some(e) => Err(e),
                    None if *angles => Ok(PathPoint {
                        tip,
                        axis: tool_axis(v[3].to_radians(), v[4].to_radians()),
                    }),
                    None => unit_axis(&Vector3::new(v[3], v[4], v[5]))
                        .map(|axis| PathPoint { tip, axis })
                        .map_err(|e| e.to_string()),
                };
                Ok(Some(Item {
                    index: self.index,
                    line,
                    id,
                    value,
                }))
            }
        }
    }
}

/// How the rows of the two files are matched.
enum Pairer {
    InOrder,
    ById {
        /// Path rows read ahead, waiting for their joint row.
        pending: HashMap<String, Item<PathPoint>>,
        path_done: bool,
    },
}

/// A joint row with its intended pose (None: no partner in the path).
struct Paired {
    joints: Item<Joints>,
    point: Option<Item<PathPoint>>,
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

/// Row checks: branch (working assembly mode), tip and axis errors, limits, singularity.
fn eval_row(m: &Machine, opt: &VerifyOptions, p: &Paired, break_before: bool) -> RowEval {
    let th = &opt.thresholds;
    let label = label_of(&p.joints);
    let mut e = RowEval {
        label,
        good: false,
        violations: Vec::new(),
        obs: ArrayVec::new(),
        q: None,
        point: None,
        module: ModulePose {
            p: Vector3::zeros(),
            alpha: 0.0,
        },
        phi1: 0.0,
        tilt_ok: false,
        singular_ok: false,
        break_before,
    };
    let q = match &p.joints.value {
        Ok(q) => *q,
        Err(msg) => {
            let d = format!("joint table line {}: {msg}", p.joints.line);
            e.violations
                .push(Violation::plain(&e.label, Check::Input, f64::NAN, d));
            return e;
        }
    };
    e.q = Some(q);
    let point = match &p.point {
        None => {
            let d = match &p.joints.id {
                Some(id) => format!("id `{id}` is not in the intended path"),
                None => "no intended row".into(),
            };
            e.violations
                .push(Violation::plain(&e.label, Check::Pairing, f64::NAN, d));
            return e;
        }
        Some(item) => match &item.value {
            Ok(pt) => *pt,
            Err(msg) => {
                let d = format!("intended path line {}: {msg}", item.line);
                e.violations
                    .push(Violation::plain(&e.label, Check::Input, f64::NAN, d));
                return e;
            }
        },
    };
    e.point = Some(point);
    let modes = machine_fk(m, &q.rho, q.theta1, q.theta2, opt.tool_length);
    let chosen = modes
        .iter()
        .filter(|md| machine_kind(md.config, md.module.alpha, m))
        .min_by(|a, b| {
            (a.tool.tip - point.tip)
                .norm()
                .total_cmp(&(b.tool.tip - point.tip).norm())
        });
    let Some(mode) = chosen else {
        let listed: Vec<String> = modes
            .iter()
            .map(|md| {
                format!(
                    "s=({},{},{}) alpha={:.3}: {}",
                    md.config[0],
                    md.config[1],
                    md.config[2],
                    md.module.alpha.to_degrees(),
                    md.verdict
                )
            })
            .collect();
        let d = if modes.is_empty() {
            "the joints cannot be assembled (no real assembly mode)".to_string()
        } else {
            format!(
                "no assembly mode of the machine's kind (s=-1,-1,-1, rods of leg I not crossing); {} real: {}",
                modes.len(),
                listed.join("; ")
            )
        };
        e.violations.push(Violation::plain(
            &e.label,
            Check::Branch,
            modes.len() as f64,
            d,
        ));
        return e;
    };
    e.module = mode.module;
    e.phi1 = mode.tool.phi1;
    let tip_err = (mode.tool.tip - point.tip).norm();
    let cross = mode.axis.cross(&point.axis).norm();
    let axis_err = cross.atan2(mode.axis.dot(&point.axis)).to_degrees();
    e.obs.push(Obs::over(
        Check::TipError,
        tip_err,
        th.get(Th::TipErrorMm),
        "tip error",
    ));
    e.obs.push(Obs::over(
        Check::AxisError,
        axis_err,
        th.get(Th::AxisErrorDeg),
        "axis error",
    ));
    let mut pose_ok = true;
    if exceeds(tip_err, th.get(Th::TipErrorMm)) {
        let d = mode.tool.tip - point.tip;
        e.violations.push(Violation::over(
            &e.label,
            Check::TipError,
            tip_err,
            th.get(Th::TipErrorMm),
            format!(
                "fk tip - intended = ({:.4}, {:.4}, {:.4}) mm",
                d.x, d.y, d.z
            ),
        ));
        pose_ok = false;
    }
    if exceeds(axis_err, th.get(Th::AxisErrorDeg)) {
        e.violations.push(Violation::over(
            &e.label,
            Check::AxisError,
            axis_err,
            th.get(Th::AxisErrorDeg),
            format!(
                "fk axis ({:.6}, {:.6}, {:.6}) vs intended ({:.6}, {:.6}, {:.6})",
                mode.axis.x, mode.axis.y, mode.axis.z, point.axis.x, point.axis.y, point.axis.z
            ),
        ));
        pose_ok = false;
    }
    e.good = pose_ok;
    // Limits, with the numbers.
    let lim = &m.limits;
    e.tilt_ok = !mode.verdict.has(Reason::RodTilt);
    let (_, tilt) = max_tilt(m, &mode.module, &q.rho);
    e.obs.push(Obs::over(
        Check::Limits,
        tilt.to_degrees(),
        lim.rod_tilt_max.to_degrees(),
        "largest rod tilt",
    ));
    for (i, r) in [Reason::Rho1Stroke, Reason::Rho2Stroke, Reason::Rho3Stroke]
        .into_iter()
        .enumerate()
    {
        if mode.verdict.has(r) {
            let v = q.rho[i];
            let (limit, side) = if v < lim.rho_min[i] {
                (lim.rho_min[i], "below")
            } else {
                (lim.rho_max[i], "above")
            };
            let mut viol = Violation::plain(
                &e.label,
                Check::Limits,
                v,
                format!(
                    "rho{} = {v:.4} mm is {side} its stroke end {limit} mm",
                    i + 1
                ),
            );
            viol.limit = limit;
            viol.severity = 1.0 + (v - limit).abs();
            e.violations.push(viol);
        }
    }
    if mode.verdict.has(Reason::Theta1Range) {
        let v = q.theta1.to_degrees();
        let limit = if q.theta1 < lim.theta1_min {
            lim.theta1_min.to_degrees()
        } else {
            lim.theta1_max.to_degrees()
        };
        let mut viol = Violation::plain(
            &e.label,
            Check::Limits,
            v,
            format!(
                "theta1 = {v:.4} deg is outside [{:.4}, {:.4}] deg",
                lim.theta1_min.to_degrees(),
                lim.theta1_max.to_degrees()
            ),
        );
        viol.limit = limit;
        viol.severity = 1.0 + (v - limit).abs();
        e.violations.push(viol);
    }
    if !e.tilt_ok {
        let tilts = rod_tilts(&m.module, &mode.module, &q.rho);
        let (k, t) =
            tilts.iter().enumerate().fold(
                (0, 0.0f64),
                |acc, (k, &t)| if t > acc.1 { (k, t) } else { acc },
            );
        e.violations.push(Violation::over(
            &e.label,
            Check::Limits,
            t.to_degrees(),
            lim.rod_tilt_max.to_degrees(),
            format!("rod {} tilted {:.4} deg", ROD_NAMES[k], t.to_degrees()),
        ));
    }
    let before = e.violations.len();
    let o = singularity_checks(m, th, &mode.module, &q.rho, &e.label, "", &mut e.violations);
    e.obs.push(o);
    e.singular_ok = e.violations.len() == before;
    e
}

const ROD_NAMES: [&str; 4] = ["11", "12", "2", "3"];

/// `value > limit`, NaN counting as a failure.
fn exceeds(value: f64, limit: f64) -> bool {
    value.is_nan() || value > limit
}

/// `value < limit`, NaN counting as a failure.
fn below(value: f64, limit: f64) -> bool {
    value.is_nan() || value < limit
}

/// Amplification factors and parallel margin of the module at (pose, rho).
fn singularity_checks(
    m: &Machine,
    th: &Thresholds,
    pose: &ModulePose,
    rho: &Sliders,
    label: &str,
    where_: &str,
    out: &mut Vec<Violation>,
) -> Obs {
    let k = kinetostatics(&m.module, pose, rho);
    let (lo, hi) = (th.get(Th::LambdaMin), th.get(Th::LambdaMax));
    let lmax = k.amplification[0];
    let lmin = k.amplification[2];
    let pm = th.get(Th::ParallelMarginMin);
    let mut worst = None;
    keep_worst(
        &mut worst,
        Obs::over(Check::Singularity, lmax, hi, "largest amplification factor"),
    );
    keep_worst(
        &mut worst,
        Obs::under(
            Check::Singularity,
            lmin,
            lo,
            "smallest amplification factor",
        ),
    );
    keep_worst(
        &mut worst,
        Obs::under(Check::Singularity, k.parallel_margin, pm, "parallel margin"),
    );
    if exceeds(lmax, hi) {
        out.push(Violation::over(
            label,
            Check::Singularity,
            lmax,
            hi,
            format!("{where_}largest amplification factor {lmax:.4} > {hi:.4}"),
        ));
    }
    if below(lmin, lo) {
        out.push(Violation::under(
            label,
            Check::Singularity,
            lmin,
            lo,
            format!("{where_}smallest amplification factor {lmin:.4} < {lo:.4}"),
        ));
    }
    if below(k.parallel_margin, pm) {
        out.push(Violation::under(
            label,
            Check::Singularity,
            k.parallel_margin,
            pm,
            format!("{where_}parallel margin {:.5} < {pm}", k.parallel_margin),
        ));
    }
    worst.unwrap_or(Obs::over(
        Check::Singularity,
        lmax,
        hi,
        "largest amplification factor",
    ))
}

/// The module pose at sliders `rho`, continued from `prev` (Newton; if it fails, the nearest
/// assembly mode of the forward kinematics). None when the sliders cannot be assembled.
fn track(m: &Machine, prev: &ModulePose, rho: &Sliders) -> Option<ModulePose> {
    let g = &m.module;
    let p = polish_pose(g, *prev, rho);
    if residual_mm(g, &p, rho) <= ACCEPT_RESIDUAL_MM {
        return Some(p);
    }
    crate::module_fk::solve(m, rho)
        .iter()
        .map(|md| md.pose)
        .min_by(|a, b| pose_distance(g, a, prev).total_cmp(&pose_distance(g, b, prev)))
}

fn pose_distance(g: &crate::machine::ModuleGeometry, a: &ModulePose, b: &ModulePose) -> f64 {
    (a.p - b.p)
        .amax()
        .max((wrap_angle(a.alpha - b.alpha) * g.r_big2).abs())
}

fn max_tilt(m: &Machine, pose: &ModulePose, rho: &Sliders) -> (usize, f64) {
    rod_tilts(&m.module, pose, rho).iter().enumerate().fold(
        (0, f64::NEG_INFINITY),
        |acc, (k, &t)| {
            if t > acc.1 { (k, t) } else { acc }
        },
    )
}

/// Segment checks that need only its two rows (run in parallel).
fn eval_segment(m: &Machine, opt: &VerifyOptions, a: &RowEval, b: &RowEval) -> SegEval {
    let th = &opt.thresholds;
    let mut s = SegEval::default();
    let (Some(qa), Some(qb), Some(pa), Some(pb)) = (a.q, b.q, a.point, b.point) else {
        return s;
    };
    let row = b.label.as_str();
    let from = format!("segment from row {}", a.label);
    let dq: [f64; 5] = std::array::from_fn(|i| qb.as_array()[i] - qa.as_array()[i]);
    let dtheta2 = dq[4];
    // 4. A change of orientation solution that is not a passage through the table normal.
    let (la, lb) = (orientation_label(a.phi1), orientation_label(b.phi1));
    if la * lb == -1 && wrap_angle(dtheta2).abs() > ORIENTATION_FLIP_RAD {
        s.violations.push(Violation::over(
            row,
            Check::Branch,
            wrap_angle(dtheta2).abs().to_degrees(),
            ORIENTATION_FLIP_RAD.to_degrees(),
            format!(
                "{from}: orientation solution {} -> {} (phi1 {:.4} -> {:.4} deg, theta2 {:+.4} deg, theta1 {:+.4} deg)",
                if la > 0 { 1 } else { 2 },
                if lb > 0 { 1 } else { 2 },
                a.phi1.to_degrees(),
                b.phi1.to_degrees(),
                dtheta2.to_degrees(),
                dq[3].to_degrees()
            ),
        ));
        return s;
    }
    // 6. theta2 flip: about half a turn (mod a full turn).
    let turns = dtheta2.abs() % (2.0 * PI);
    if (turns - PI).abs() < th.get(Th::Theta2FlipTolDeg).to_radians() {
        s.violations.push(Violation::over(
            row,
            Check::Theta2Flip,
            dtheta2.abs().to_degrees(),
            th.get(Th::Theta2StepDeg),
            format!(
                "{from}: theta2 {:.4} -> {:.4} deg ({:+.4} deg)",
                qa.theta2.to_degrees(),
                qb.theta2.to_degrees(),
                dtheta2.to_degrees()
            ),
        ));
        s.flip = Some(dtheta2);
        return s;
    }
    // 6. Joint jumps.
    let step = th.per_joint(Th::RhoStepMm, Th::Theta1StepDeg, Th::Theta2StepDeg);
    let mut jumped = false;
    let mut worst = None;
    for i in 0..5 {
        let (v, l) = if i < 3 {
            (dq[i].abs(), step[i])
        } else {
            (dq[i].abs().to_degrees(), step[i].to_degrees())
        };
        keep_worst(
            &mut worst,
            Obs::over(Check::JointJump, v, l, JOINT_NAMES[i]),
        );
        if dq[i].abs() > step[i] {
            let (v, l, u) = if i < 3 {
                (dq[i].abs(), step[i], "mm")
            } else {
                (dq[i].abs().to_degrees(), step[i].to_degrees(), "deg")
            };
            s.violations.push(Violation::over(
                row,
                Check::JointJump,
                v,
                l,
                format!(
                    "{from}: {} changes by {:+.4} {u}",
                    JOINT_NAMES[i],
                    if i < 3 { dq[i] } else { dq[i].to_degrees() }
                ),
            ));
            jumped = true;
        }
    }
    s.obs.extend(worst);
    if jumped {
        return s;
    }
    // 6. Velocities.
    let dt = match (qa.t, qb.t, qb.feed) {
        (Some(ta), Some(tb), _) => Some(tb - ta),
        (_, _, Some(f)) if f > 0.0 => Some((pb.tip - pa.tip).norm() / f),
        _ => None,
    };
    if let Some(dt) = dt {
        s.dt = dt;
        if qa.t.is_some() && dt <= 0.0 {
            s.violations.push(Violation::plain(
                row,
                Check::Velocity,
                dt,
                format!("{from}: t does not increase (dt = {dt} s)"),
            ));
        } else if dt > 0.0 {
            let vmax = th.per_joint(
                Th::RhoVelocityMmS,
                Th::Theta1VelocityDegS,
                Th::Theta2VelocityDegS,
            );
            let rates: [f64; 5] = std::array::from_fn(|i| dq[i] / dt);
            let mut ok = true;
            let mut worst = None;
            for i in 0..5 {
                let (v, l) = if i < 3 {
                    (rates[i].abs(), vmax[i])
                } else {
                    (rates[i].abs().to_degrees(), vmax[i].to_degrees())
                };
                keep_worst(&mut worst, Obs::over(Check::Velocity, v, l, JOINT_NAMES[i]));
                if rates[i].abs() > vmax[i] {
                    let (v, l, u) = if i < 3 {
                        (rates[i].abs(), vmax[i], "mm/s")
                    } else {
                        (rates[i].abs().to_degrees(), vmax[i].to_degrees(), "deg/s")
                    };
                    s.violations.push(Violation::over(
                        row,
                        Check::Velocity,
                        v,
                        l,
                        format!("{from}: {} at {v:.4} {u} (dt = {dt:.6} s)", JOINT_NAMES[i]),
                    ));
                    ok = false;
                }
            }
            s.obs.extend(worst);
            if ok {
                s.rates = Some(rates);
            }
        }
    }
    // 2, 3, 4, 5 along the interpolated joints.
    interior(m, opt, a, b, &qa, &qb, &pa, &pb, &from, &mut s);
    s
}

/// Samples a segment's interior: assembly mode, rod tilts, singularity, chordal error.
#[allow(clippy::too_many_arguments)]
fn interior(
    m: &Machine,
    opt: &VerifyOptions,
    a: &RowEval,
    b: &RowEval,
    qa: &Joints,
    qb: &Joints,
    pa: &PathPoint,
    pb: &PathPoint,
    from: &str,
    seg: &mut SegEval,
) {
    let out = &mut seg.violations;
    let mut singular_worst: Option<Obs> = None;
    let mut tilt_worst: Option<Obs> = None;
    let th = &opt.thresholds;
    let row = b.label.as_str();
    let g = &m.module;
    let drho = qb.rho - qa.rho;
    let travel = drho.amax();
    let half =
        ((travel / (2.0 * SEGMENT_SAMPLE_MM)).ceil() as usize).clamp(1, MAX_SEGMENT_SAMPLES / 2);
    let n = 2 * half;
    let tilt_limit = m.limits.rod_tilt_max;
    let check_tilt = a.tilt_ok && b.tilt_ok;
    let check_singular = a.singular_ok && b.singular_ok;
    let mut pose = a.module;
    // (s, rod, tilt) of the worst sample, and the tilts either side of it.
    let mut worst: Option<(usize, usize, f64, ModulePose)> = None;
    let mut tilts_prev = max_tilt(m, &a.module, &qa.rho).1;
    let mut around = [f64::NAN; 3];
    let mut singular: Vec<Violation> = Vec::new();
    for j in 1..n {
        let s = j as f64 / n as f64;
        let rho = qa.rho + drho * s;
        let Some(next) = track(m, &pose, &rho) else {
            out.push(Violation::plain(
                row,
                Check::Branch,
                s,
                format!("{from}: the interpolated joints cannot be assembled at s = {s:.4}"),
            ));
            return;
        };
        pose = next;
        let config = config_of(g, &pose, &rho);
        if !machine_kind(config, pose.alpha, m) {
            out.push(Violation::plain(
                row,
                Check::Branch,
                s,
                format!(
                    "{from}: leaves the machine's assembly mode at s = {s:.4} (s = ({},{},{}), alpha = {:.4} deg)",
                    config[0],
                    config[1],
                    config[2],
                    pose.alpha.to_degrees()
                ),
            ));
            return;
        }
        if j == half {
            let q1 = qa.theta1 + (qb.theta1 - qa.theta1) * 0.5;
            let q2 = qa.theta2 + (qb.theta2 - qa.theta2) * 0.5;
            let tip = tool_pose_eq26(&m.table, &pose, q1, q2, opt.tool_length).tip;
            let chord = (tip - (pa.tip + pb.tip) * 0.5).norm();
            seg.obs.push(Obs::over(
                Check::ChordError,
                chord,
                th.get(Th::ChordErrorMm),
                "chordal error",
            ));
            if exceeds(chord, th.get(Th::ChordErrorMm)) {
                out.push(Violation::over(
                    row,
                    Check::ChordError,
                    chord,
                    th.get(Th::ChordErrorMm),
                    format!(
                        "{from}: tip at the joints' midpoint is {chord:.5} mm off the intended line"
                    ),
                ));
            }
        }
        if check_tilt {
            let (rod, t) = max_tilt(m, &pose, &rho);
            keep_worst(
                &mut tilt_worst,
                Obs::over(
                    Check::Limits,
                    t.to_degrees(),
                    tilt_limit.to_degrees(),
                    "largest rod tilt, mid-segment",
                ),
            );
            if let Some((wj, _, _, _)) = worst
                && wj + 1 == j
            {
                around[2] = t;
            }
            if t > tilt_limit && worst.as_ref().is_none_or(|w| t > w.2) {
                worst = Some((j, rod, t, pose));
                around = [tilts_prev, t, f64::NAN];
            }
            tilts_prev = t;
        }
        if check_singular && singular.is_empty() {
            let o = singularity_checks(
                m,
                th,
                &pose,
                &rho,
                row,
                &format!("{from}, at s = {s:.4}: "),
                &mut singular,
            );
            keep_worst(
                &mut singular_worst,
                Obs {
                    what: "mid-segment",
                    ..o
                },
            );
        }
    }
    seg.obs.extend(singular_worst);
    seg.obs.extend(tilt_worst);
    let out = &mut seg.violations;
    // The tracked mode must arrive at the end row's mode.
    let end = track(m, &pose, &qb.rho);
    let arrived = end.is_some_and(|p| pose_distance(g, &p, &b.module) <= TRACK_ARRIVAL_MM);
    if !arrived {
        out.push(Violation::plain(
            row,
            Check::Branch,
            1.0,
            format!(
                "{from}: the interpolated joints arrive in another assembly mode than the row's"
            ),
        ));
        return;
    }
    if let Some((j, rod, t, wpose)) = worst {
        if around[2].is_nan() {
            around[2] = max_tilt(m, &b.module, &qb.rho).1;
        }
        // Parabola through the worst sample and its neighbours: refine the maximum.
        let (f0, f1, f2) = (around[0], around[1], around[2]);
        let den = f0 - 2.0 * f1 + f2;
        let mut best = (j as f64 / n as f64, t, rod);
        if den < 0.0 {
            let off = 0.5 * (f0 - f2) / den;
            if off.abs() < 1.0 {
                let s = (j as f64 + off) / n as f64;
                let rho = qa.rho + drho * s;
                if let Some(p) = track(m, &wpose, &rho) {
                    let (r2, t2) = max_tilt(m, &p, &rho);
                    if t2 > best.1 {
                        best = (s, t2, r2);
                    }
                }
            }
        }
        out.push(Violation::over(
            row,
            Check::Limits,
            best.1.to_degrees(),
            tilt_limit.to_degrees(),
            format!(
                "{from}: mid-segment, rod {} tilted {:.4} deg at s = {:.4} (ends {:.4} and {:.4} deg)",
                ROD_NAMES[best.2],
                best.1.to_degrees(),
                best.0,
                max_tilt(m, &a.module, &qa.rho).1.to_degrees(),
                max_tilt(m, &b.module, &qb.rho).1.to_degrees()
            ),
        ));
    }
    out.extend(singular);
}

/// Checks the joint table against the intended path, streaming; `report` receives every finding
/// in row order. Fatal input errors (unreadable files, malformed cells, a row-count mismatch
/// without ids) are returned as errors.
pub fn verify(
    m: &Machine,
    opt: &VerifyOptions,
    joints: &mut JointReader,
    path: &mut PathReader,
    report: &mut dyn FnMut(&Violation) -> Result<(), VerneError>,
) -> Result<Summary, VerneError> {
    let mut summary = Summary::new();
    summary.timed = joints.timed();
    let mut pairer = if joints.has_id() && path.has_id() {
        Pairer::ById {
            pending: HashMap::new(),
            path_done: false,
        }
    } else {
        Pairer::InOrder
    };
    let mut prev_row: Option<RowEval> = None;
    let mut prev_seg: Option<PrevSeg> = None;
    let mut batch: Vec<(Paired, bool)> = Vec::with_capacity(BATCH_ROWS);
    let mut gap = false;
    let mut emit = |v: &Violation, summary: &mut Summary| -> Result<(), VerneError> {
        summary.add(v);
        report(v)
    };
    loop {
        batch.clear();
        let mut done = false;
        while batch.len() < BATCH_ROWS {
            match next_pair(&mut pairer, joints, path)? {
                Some(p) => {
                    let unpaired = p.point.is_none();
                    batch.push((p, gap));
                    gap = unpaired;
                }
                None => {
                    done = true;
                    break;
                }
            }
        }
        // Rows in parallel.
        let rows: Vec<RowEval> = batch
            .par_iter()
            .with_min_len(16)
            .map(|(p, brk)| eval_row(m, opt, p, *brk))
            .collect();
        // Segments in parallel: (previous row, row) for every row of the batch.
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
                emit(v, &mut summary)?;
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
                emit(v, &mut summary)?;
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
        if done {
            break;
        }
    }
    // Intended rows never matched by a joint row.
    if let Pairer::ById { pending, path_done } = &mut pairer {
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
            emit(&v, &mut summary)?;
        }
    }
    Ok(summary)
}

fn next_pair(
    pairer: &mut Pairer,
    joints: &mut JointReader,
    path: &mut PathReader,
) -> Result<Option<Paired>, VerneError> {
    match pairer {
        Pairer::InOrder => {
            let j = joints.next_item()?;
            let p = path.next_item()?;
            match (j, p) {
                (None, None) => Ok(None),
                (Some(j), Some(p)) => Ok(Some(Paired {
                    joints: j,
                    point: Some(p),
                })),
                (Some(j), None) => Err(VerneError::input(
                    joints.name(),
                    Some(j.line),
                    None,
                    format!(
                        "the joint table has more rows than the intended path {} ({} rows): row {} has no intended row; expected one joint row per path row, or an `id` column in both files",
                        path.name(),
                        j.index - 1,
                        j.index
                    ),
                )),
                (None, Some(p)) => Err(VerneError::input(
                    path.name(),
                    Some(p.line),
                    None,
                    format!(
                        "the intended path has more rows than the joint table {} ({} rows): path row {} has no joint row; expected one joint row per path row, or an `id` column in both files",
                        joints.name(),
                        p.index - 1,
                        p.index
                    ),
                )),
            }
        }
        Pairer::ById { pending, path_done } => {
            let Some(j) = joints.next_item()? else {
                return Ok(None);
            };
            let id = j.id.clone().unwrap_or_default();
            if let Some(p) = pending.remove(&id) {
                return Ok(Some(Paired {
                    joints: j,
                    point: Some(p),
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
                            }));
                        }
                        if let Some(old) = pending.get(&pid) {
                            return Err(VerneError::input(
                                path.name(),
                                Some(p.line),
                                Some("id"),
                                format!(
                                    "id `{}` appears twice (lines {} and {}); expected unique ids",
                                    shown(pid.as_bytes()),
                                    old.line,
                                    p.line
                                ),
                            ));
                        }
                        pending.insert(pid, p);
                    }
                }
            }
            Ok(Some(Paired {
                joints: j,
                point: None,
            }))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_parse_and_validate() {
        let mut t = Thresholds::default();
        assert_eq!(t.get(Th::TipErrorMm), 0.005);
        assert!(t.set("tip_error_mm", 0.01).is_ok());
        assert_eq!(t.get(Th::TipErrorMm), 0.01);
        assert!(t.set("tip_eror_mm", 1.0).unwrap_err().contains("unknown"));
        assert!(t.set("chord_error_mm", -1.0).is_err());
        assert!(t.set("parallel_margin_min", 0.0).is_ok());
        assert!(t.set("theta2_flip_tol_deg", 95.0).is_err());
        t.set("lambda_min", 4.0).unwrap();
        assert!(t.check().is_err());
        assert_eq!(THRESHOLDS.len(), Th::Theta2AccelDegS2 as usize + 1);
    }

    #[test]
    fn orientation_labels_ignore_the_table_normal() {
        assert_eq!(orientation_label(0.3), 1);
        assert_eq!(orientation_label(-0.3), -1);
        assert_eq!(orientation_label(1e-9), 0);
        assert_eq!(orientation_label(PI), 0);
    }

    #[test]
    fn json_escapes_and_numbers() {
        assert_eq!(json_string("a\"b\n"), "\"a\\\"b\\u000a\"");
        assert_eq!(json_number(f64::NAN), "null");
        assert_eq!(short_number(0.1 + 0.2), "0.3");
    }
}
