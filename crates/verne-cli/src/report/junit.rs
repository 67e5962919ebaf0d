//! `verne verify --junit FILE`: JUnit XML that CI systems show as test results (GitLab's test
//! reports, Jenkins): one test suite for the verified pair, one test case per check, failed
//! with its count, worst value, limit and first rows, skipped when it could not run. The schema
//! it follows is the Jenkins xunit plugin's `junit-10.xsd` (tests/data/schemas/). At most
//! [`FIRST_ROWS`] rows are named per check, so the file stays a few kilobytes whatever the
//! program's length (GitLab reads at most 30 MB a file).

use std::collections::HashMap;
use std::fmt::Write as _;

use verne::verify::{Summary, Violation};

use crate::report::html::verify::{Inputs, Status, statuses};
use crate::report::verify::rounded_number;

/// Rows named per failed check.
pub const FIRST_ROWS: usize = 10;

/// The first findings of each check, collected as the run streams.
#[derive(Debug, Default)]
pub struct JunitReport {
    first: HashMap<&'static str, Vec<Violation>>,
}

impl JunitReport {
    pub fn new() -> JunitReport {
        JunitReport::default()
    }

    /// A finding, in row order.
    pub fn finding(&mut self, v: &Violation) {
        let list = self.first.entry(v.check.code()).or_default();
        if list.len() < FIRST_ROWS {
            list.push(v.clone());
        }
    }

    /// The document; `seconds` is the run's time.
    pub fn render(&self, summary: &Summary, inputs: &Inputs, seconds: f64) -> String {
        let st = statuses(summary);
        let tests = st.len();
        let failures = st
            .iter()
            .filter(|(_, s)| matches!(s, Status::Found(_)))
            .count();
        let skipped = st
            .iter()
            .filter(|(_, s)| matches!(s, Status::NotChecked(_)))
            .count();
        let joints = inputs.joints.display().to_string();
        let path = inputs.path.display().to_string();
        let time = format!("{seconds:.3}");
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            x,
            "<testsuites name=\"verne verify\" tests=\"{tests}\" failures=\"{failures}\" errors=\"0\" time=\"{time}\">"
        );
        let _ = writeln!(
            x,
            "  <testsuite name=\"{}\" package=\"verne.verify\" tests=\"{tests}\" failures=\"{failures}\" errors=\"0\" skipped=\"{skipped}\" time=\"{time}\">",
            attr(&format!("verne verify {joints} against {path}"))
        );
        x.push_str("    <properties>\n");
        for (name, value) in [
            ("joints", joints.clone()),
            ("path", path.clone()),
            ("machine", inputs.machine.to_string()),
            ("rows", summary.rows.to_string()),
            ("segments", summary.segments.to_string()),
            ("segments_skipped", summary.segments_skipped.to_string()),
            ("timed", summary.timed.to_string()),
            ("findings", summary.violations().to_string()),
            ("verne", env!("CARGO_PKG_VERSION").to_string()),
        ] {
            let _ = writeln!(
                x,
                "      <property name=\"{name}\" value=\"{}\"/>",
                attr(&value)
            );
        }
        x.push_str("    </properties>\n");
        let classname = attr(&format!("verne verify {joints}"));
        for ((check, stats), (_, status)) in summary.checks.iter().zip(&st) {
            let _ = write!(
                x,
                "    <testcase name=\"{}\" classname=\"{classname}\" time=\"0\">",
                check.code()
            );
            let worst = stats.worst.as_ref().map(|w| {
                format!(
                    "worst {} (limit {}) at row {}{}: {}",
                    rounded_number(w.value, 6),
                    if w.limit.is_nan() {
                        "none".to_string()
                    } else {
                        rounded_number(w.limit, 6)
                    },
                    w.row,
                    lines(w, inputs),
                    w.detail
                )
            });
            match status {
                Status::Found(n) => {
                    let message = format!(
                        "{n} finding{}; {}",
                        if *n == 1 { "" } else { "s" },
                        worst.clone().unwrap_or_default()
                    );
                    let mut body = format!("{n} finding{}\n", if *n == 1 { "" } else { "s" });
                    if let Some(w) = &worst {
                        let _ = writeln!(body, "{w}");
                    }
                    let first = self.first.get(check.code()).map_or(&[][..], |v| v);
                    let _ = writeln!(
                        body,
                        "first rows ({} of {n}; all in the --report CSV):",
                        first.len()
                    );
                    for v in first {
                        let _ = writeln!(
                            body,
                            "  row {}{}: {} (limit {}) {}",
                            v.row,
                            lines(v, inputs),
                            rounded_number(v.value, 6),
                            rounded_number(v.limit, 6),
                            v.detail
                        );
                    }
                    let _ = write!(
                        x,
                        "\n      <failure type=\"{}\" message=\"{}\">{}</failure>\n    ",
                        check.code(),
                        attr(&message),
                        text(&body)
                    );
                }
                Status::NotChecked(why) => {
                    let _ = write!(
                        x,
                        "\n      <skipped message=\"{}\"/>\n    ",
                        attr(&format!("not checked: {why}"))
                    );
                }
                Status::Clean => {
                    let out = match &worst {
                        Some(w) => format!("clean; {w}"),
                        None => "clean".to_string(),
                    };
                    let _ = write!(x, "\n      <system-out>{}</system-out>\n    ", text(&out));
                }
            }
            x.push_str("</testcase>\n");
        }
        x.push_str("  </testsuite>\n</testsuites>\n");
        x
    }
}

/// ` (joint table line N, path line M)` where known.
fn lines(v: &Violation, inputs: &Inputs) -> String {
    let mut parts = Vec::new();
    if let Some(l) = v.joints_line {
        parts.push(format!("{} line {l}", inputs.joints.display()));
    }
    if let (Some(l), false) = (v.path_line, inputs.recording) {
        parts.push(format!("{} line {l}", inputs.path.display()));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(" ({})", parts.join(", "))
    }
}

/// Characters XML 1.0 allows, the others replaced by U+FFFD.
fn allowed(c: char) -> char {
    match c {
        '\t' | '\n' | '\r' => c,
        c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => '\u{fffd}',
        c => c,
    }
}

/// Element text.
fn text(t: &str) -> String {
    let mut s = String::with_capacity(t.len());
    for c in t.chars().map(allowed) {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '\r' => s.push_str("&#13;"),
            c => s.push(c),
        }
    }
    s
}

/// An attribute value (double-quoted): line breaks kept as character references.
fn attr(t: &str) -> String {
    let mut s = String::with_capacity(t.len());
    for c in t.chars().map(allowed) {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\n' => s.push_str("&#10;"),
            '\r' => s.push_str("&#13;"),
            '\t' => s.push_str("&#9;"),
            c => s.push(c),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_and_forbidden_characters_are_escaped() {
        assert_eq!(
            attr("a<b>&\"c\"\n\u{1}"),
            "a&lt;b&gt;&amp;&quot;c&quot;&#10;\u{fffd}"
        );
        assert_eq!(text("x < y && z\u{0}\n"), "x &lt; y &amp;&amp; z\u{fffd}\n");
    }
}
