//! `verne verify --sarif FILE`: SARIF 2.1.0 (OASIS), which code-scanning tools show as
//! annotations on the lines of the files (GitHub reads at most 25,000 results a run and shows
//! 5,000): one result per finding, located at its line of the joint program (and, related, of
//! the intended path), most severe first, at most [`MAX_RESULTS`]; the count of the rest is
//! stated in the run's notifications and properties. Validated against the SARIF 2.1.0 schema
//! (tests/data/schemas/).

use std::fmt::Write as _;
use std::path::Path;

use verne::verify::{Check, Summary, Violation};

use crate::report::html::verify::{Inputs, Status, statuses};
use crate::report::html::{json_num, json_str};

/// Results written at most (the ones GitHub shows).
pub const MAX_RESULTS: usize = 5000;

/// What each check finds, as a rule of the tool (docs/verify.md, Checks).
const RULES: [(Check, &str, &str); 14] = [
    (
        Check::Input,
        "Input",
        "A required cell is empty, NaN or infinite, or the axis is not a unit vector.",
    ),
    (
        Check::Pairing,
        "Pairing",
        "A joint row has no intended row, or an intended row no joint row.",
    ),
    (
        Check::TipError,
        "TipError",
        "The tool tip of the joints (forward kinematics, AIM 2007 eq. (26)) is farther from the intended tip than tip_error_mm.",
    ),
    (
        Check::AxisError,
        "AxisError",
        "The tool axis of the joints is farther from the intended axis than axis_error_deg.",
    ),
    (
        Check::Limits,
        "Limits",
        "A slider stroke, the tilting-axis range or the largest rod tilt is exceeded, at a row or between two rows.",
    ),
    (
        Check::ChordError,
        "ChordError",
        "Between two rows, the tip of the linearly interpolated joints leaves the intended move by more than chord_error_mm.",
    ),
    (
        Check::ChordAxis,
        "ChordAxis",
        "Between two rows, the tool axis of the interpolated joints leaves the intended move by more than chord_axis_error_deg.",
    ),
    (
        Check::Motion,
        "Motion",
        "The joint program moves rapid (G0) where the intended path cuts.",
    ),
    (
        Check::Branch,
        "Branch",
        "The joints are not in the machine's assembly mode, or change orientation solution or assembly mode between two rows.",
    ),
    (
        Check::Singularity,
        "Singularity",
        "A velocity amplification factor or the parallel margin is outside its bounds (lambda_min, lambda_max, parallel_margin_min).",
    ),
    (
        Check::JointJump,
        "JointJump",
        "A joint changes by more than its step limit between two rows.",
    ),
    (
        Check::Theta2Flip,
        "Theta2Flip",
        "theta2 turns by about half a turn between two rows without a change of orientation solution.",
    ),
    (
        Check::Velocity,
        "Velocity",
        "A joint moves faster than its speed limit, or the time does not increase.",
    ),
    (
        Check::Acceleration,
        "Acceleration",
        "A joint's speed changes faster than its acceleration limit.",
    ),
];

/// A finding kept: its order of arrival and how severe it is.
#[derive(Debug, Clone)]
struct Kept {
    order: u64,
    v: Violation,
}

/// How findings are ranked: those no number measures against a limit (an unusable row, a
/// missing partner, a change of branch at a row, a rapid where the path cuts) first, then by
/// how far beyond their limit, then in row order.
fn rank(a: &Kept, b: &Kept) -> std::cmp::Ordering {
    let unmeasured = |k: &Kept| !k.v.limit.is_finite();
    unmeasured(b)
        .cmp(&unmeasured(a))
        .then(b.v.severity.total_cmp(&a.v.severity))
        .then(a.order.cmp(&b.order))
}

/// The most severe findings, collected as the run streams (memory bounded by twice the cap).
#[derive(Debug, Default)]
pub struct SarifReport {
    kept: Vec<Kept>,
    total: u64,
}

impl SarifReport {
    pub fn new() -> SarifReport {
        SarifReport::default()
    }

    /// A finding, in row order.
    pub fn finding(&mut self, v: &Violation) {
        self.kept.push(Kept {
            order: self.total,
            v: v.clone(),
        });
        self.total += 1;
        if self.kept.len() >= 2 * MAX_RESULTS {
            self.kept.sort_by(rank);
            self.kept.truncate(MAX_RESULTS);
        }
    }

    /// The log.
    pub fn render(mut self, summary: &Summary, inputs: &Inputs) -> String {
        self.kept.sort_by(rank);
        self.kept.truncate(MAX_RESULTS);
        let omitted = self.total - self.kept.len() as u64;
        let joints_uri = uri(inputs.joints);
        let path_uri = uri(inputs.path);
        let mut s = String::with_capacity(1024 + 600 * self.kept.len());
        s.push_str(
            "{\"$schema\":\"https://json.schemastore.org/sarif-2.1.0.json\",\"version\":\"2.1.0\",\"runs\":[{",
        );
        let _ = write!(
            s,
            "\"tool\":{{\"driver\":{{\"name\":\"verne verify\",\"version\":{},\"semanticVersion\":{},\"rules\":[",
            json_str(env!("CARGO_PKG_VERSION")),
            json_str(env!("CARGO_PKG_VERSION"))
        );
        for (k, (check, name, text)) in RULES.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            let _ = write!(
                s,
                "{{\"id\":{},\"name\":{},\"shortDescription\":{{\"text\":{}}},\"help\":{{\"text\":{}}},\"defaultConfiguration\":{{\"level\":\"error\"}}}}",
                json_str(check.code()),
                json_str(name),
                json_str(text),
                json_str(&format!(
                    "{text} Thresholds and definitions: docs/verify.md of verne."
                ))
            );
        }
        s.push_str("]}},");
        // The run: what could not be checked, and what was left out.
        let mut notes: Vec<(&str, String)> = Vec::new();
        for (c, st) in statuses(summary) {
            if let Status::NotChecked(why) = st {
                notes.push(("warning", format!("{} not checked: {why}", c.code())));
            }
        }
        if omitted > 0 {
            notes.push((
                "note",
                format!(
                    "{omitted} further findings are not listed: {} findings, the {MAX_RESULTS} most severe listed (all in the --report CSV)",
                    self.total
                ),
            ));
        }
        s.push_str(
            "\"invocations\":[{\"executionSuccessful\":true,\"toolExecutionNotifications\":[",
        );
        for (k, (level, text)) in notes.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            let _ = write!(
                s,
                "{{\"level\":\"{level}\",\"message\":{{\"text\":{}}}}}",
                json_str(text)
            );
        }
        s.push_str("]}],");
        let _ = write!(
            s,
            "\"artifacts\":[{{\"location\":{{\"uri\":{}}},\"roles\":[\"analysisTarget\"]}},{{\"location\":{{\"uri\":{}}},\"roles\":[\"referencedOnCommandLine\"]}}],",
            json_str(&joints_uri),
            json_str(&path_uri)
        );
        s.push_str("\"results\":[");
        for (k, kept) in self.kept.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            let v = &kept.v;
            let rule = RULES
                .iter()
                .position(|(c, _, _)| *c == v.check)
                .unwrap_or(0);
            let measured = if v.value.is_finite() && v.limit.is_finite() {
                format!(
                    " ({} against the limit {})",
                    crate::report::verify::rounded_number(v.value, 6),
                    crate::report::verify::rounded_number(v.limit, 6)
                )
            } else {
                String::new()
            };
            let message = format!("row {}: {}{measured}: {}", v.row, v.check.code(), v.detail);
            let path_line = if inputs.recording { None } else { v.path_line };
            let location = |uri: &str, index: usize, line: Option<u64>| {
                let region = line.map_or(String::new(), |l| {
                    format!(",\"region\":{{\"startLine\":{l}}}")
                });
                format!(
                    "{{\"physicalLocation\":{{\"artifactLocation\":{{\"uri\":{},\"index\":{index}}}{region}}}}}",
                    json_str(uri)
                )
            };
            // The finding is at the joint program's line; a path row without a joint row is
            // at the path's.
            let (primary, related) = match (v.joints_line, path_line) {
                (Some(j), p) => (
                    location(&joints_uri, 0, Some(j)),
                    p.map(|p| location(&path_uri, 1, Some(p))),
                ),
                (None, Some(p)) => (location(&path_uri, 1, Some(p)), None),
                (None, None) => (location(&joints_uri, 0, None), None),
            };
            let _ = write!(
                s,
                "{{\"ruleId\":{},\"ruleIndex\":{rule},\"level\":\"error\",\"message\":{{\"text\":{}}},\"locations\":[{primary}]",
                json_str(v.check.code()),
                json_str(&message)
            );
            if let Some(r) = related {
                // relatedLocations are locations with an id and a message.
                let r = r.trim_start_matches('{');
                let _ = write!(
                    s,
                    ",\"relatedLocations\":[{{\"id\":1,\"message\":{{\"text\":\"the intended path's row\"}},{r}]"
                );
            }
            let _ = write!(
                s,
                ",\"properties\":{{\"row\":{},\"value\":{},\"limit\":{},\"severity\":{}}}}}",
                json_str(&v.row),
                json_num(v.value),
                json_num(v.limit),
                json_num(v.severity)
            );
        }
        let _ = write!(
            s,
            "],\"properties\":{{\"rows\":{},\"segments\":{},\"findings\":{},\"listed\":{},\"omitted\":{omitted},\"maxResults\":{MAX_RESULTS}}}}}]}}",
            summary.rows,
            summary.segments,
            self.total,
            self.kept.len()
        );
        s.push('\n');
        s
    }
}

/// A file's URI as SARIF wants it: a relative path as given (with `/`), which code scanning
/// resolves against the repository's root; an absolute one as a `file:` URL.
fn uri(p: &Path) -> String {
    let t = p.to_string_lossy().replace('\\', "/");
    let t = t.strip_prefix("./").unwrap_or(&t).to_string();
    let mut out = String::with_capacity(t.len());
    if t.starts_with('/') {
        out.push_str("file://");
    }
    for b in t.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            out.push(b as char);
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_check_is_a_rule() {
        for c in Check::ALL {
            assert!(RULES.iter().any(|(r, _, _)| *r == c), "{c}");
        }
    }

    #[test]
    fn uris_are_relative_or_file_urls() {
        assert_eq!(
            uri(Path::new("./data/verify/joints.csv")),
            "data/verify/joints.csv"
        );
        assert_eq!(uri(Path::new("a b/c#1.ngc")), "a%20b/c%231.ngc");
        assert_eq!(uri(Path::new("/tmp/x.csv")), "file:///tmp/x.csv");
    }

    /// Unmeasured findings first, then the most severe, then in order; the cap keeps the
    /// first of those.
    #[test]
    fn the_most_severe_are_kept() {
        let mut r = SarifReport::new();
        let n = 3 * MAX_RESULTS as u64;
        for k in 0..n {
            let mut v = Violation {
                row: (k + 1).to_string(),
                check: Check::TipError,
                value: 0.0,
                limit: 0.005,
                detail: String::new(),
                severity: 1.0 + (k % 1000) as f64,
                joints_line: Some(k + 2),
                path_line: Some(k + 2),
            };
            if k == n - 1 {
                v.check = Check::Input;
                v.limit = f64::NAN;
                v.severity = 1.0;
            }
            r.finding(&v);
        }
        r.kept.sort_by(rank);
        r.kept.truncate(MAX_RESULTS);
        assert_eq!(r.kept[0].v.check, Check::Input);
        assert_eq!(r.kept[1].v.severity, 1000.0);
        assert_eq!(r.kept[1].order, 999);
        // 15 findings of each severity but 1000 (14: the last is the unmeasured one): the
        // unmeasured, 14 of 1000, 15 of each from 999 to 668 (4995 in all) and 5 of 667.
        assert!(r.kept.iter().skip(1).all(|k| k.v.severity >= 667.0));
        assert_eq!(r.kept.iter().filter(|k| k.v.severity == 1000.0).count(), 14);
        assert_eq!(r.kept.iter().filter(|k| k.v.severity == 667.0).count(), 5);
        assert_eq!(r.total, n);
    }
}
