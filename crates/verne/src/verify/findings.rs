//! What the checks find: the kinds of check ([`Check`]), one finding ([`Violation`]), and the
//! counts and worst finding of a run ([`Summary`]).

use std::fmt;

use super::Obs;

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
    /// Check 3: the tool tip of the interpolated joints from the intended move's, along the
    /// segment (mm).
    ChordError,
    /// Check 3: the tool axis of the interpolated joints from the intended move's, along the
    /// segment (deg).
    ChordAxis,
    /// The joint program moves rapid (`G0`) where the intended path cuts.
    Motion,
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
    pub const ALL: [Check; 14] = [
        Check::Input,
        Check::Pairing,
        Check::TipError,
        Check::AxisError,
        Check::Limits,
        Check::ChordError,
        Check::ChordAxis,
        Check::Motion,
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
            Check::ChordAxis => "chord_axis",
            Check::Motion => "motion",
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
    /// The line of the joint table (or program) the finding is at, and of the intended path.
    pub joints_line: Option<u64>,
    pub path_line: Option<u64>,
}

impl Violation {
    pub(super) fn over(
        row: &str,
        check: Check,
        value: f64,
        limit: f64,
        detail: String,
    ) -> Violation {
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
            joints_line: None,
            path_line: None,
        }
    }

    pub(super) fn under(
        row: &str,
        check: Check,
        value: f64,
        limit: f64,
        detail: String,
    ) -> Violation {
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
            joints_line: None,
            path_line: None,
        }
    }

    pub(super) fn plain(row: &str, check: Check, value: f64, detail: String) -> Violation {
        Violation {
            row: row.to_string(),
            check,
            value,
            limit: f64::NAN,
            detail,
            severity: 1.0,
            joints_line: None,
            path_line: None,
        }
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
    pub(super) fn new() -> Summary {
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

    pub(super) fn add(&mut self, v: &Violation) {
        let s = &mut self.checks[v.check.slot()].1;
        s.count += 1;
        if s.worst.as_ref().is_none_or(|w| v.severity >= w.severity) {
            s.worst = Some(v.clone());
        }
    }

    pub(super) fn observe(&mut self, o: &Obs, row: &str, lines: (u64, Option<u64>)) {
        let s = &mut self.checks[o.check.slot()].1;
        if s.worst.as_ref().is_none_or(|w| o.severity > w.severity) {
            s.worst = Some(Violation {
                row: row.to_string(),
                check: o.check,
                value: o.value,
                limit: o.limit,
                detail: format!("{} (within the limit)", o.what),
                severity: o.severity,
                joints_line: Some(lines.0),
                path_line: lines.1,
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
}
