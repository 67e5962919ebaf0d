//! What `verne verify` writes: the summary as aligned text or JSON, the report's numbers, and the
//! `--help` epilogue listing the thresholds.

use std::fmt::Write as _;

use verne::verify::{Summary, THRESHOLDS};

/// The `--help` epilogue of `verne verify`: example, thresholds with defaults, exit codes.
pub fn help_text() -> String {
    let mut s = String::from(
        "Example:\n  verne verify --joints data/verify/joints.csv --path data/verify/path.csv\n  \
         verne verify --joints data/example-post.ngc --path data/example-tcp.ngc\n  \
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
        "\nReport columns: row,check,value,limit,detail,joints_line,path_line (docs/verify.md).\n\n\
         Exit codes: 0 every check passed, 1 some check failed, 2 fatal (bad arguments,\n\
         unreadable or malformed input, an id given twice).",
    );
    s
}

/// The summary as aligned text (one line per check).
pub fn summary_text(summary: &Summary) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} rows, {} segments checked ({} skipped next to a failed row){}: {}",
        summary.rows,
        summary.segments,
        summary.segments_skipped,
        if summary.timed {
            ""
        } else {
            "; no t or feed column: velocity and acceleration not checked"
        },
        if summary.clean() {
            "clean".to_string()
        } else {
            format!("{} violations", summary.violations())
        }
    );
    let _ = writeln!(
        s,
        "{:<13} {:>7}  {:>12}  {:>12}  {:>8}  detail of the worst",
        "check", "count", "worst", "limit", "row"
    );
    for (c, st) in &summary.checks {
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
                    with_lines(w)
                );
            }
        }
    }
    s
}

/// The summary as one JSON object (docs/verify.md).
pub fn summary_json(summary: &Summary) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "{{\"rows\":{},\"segments\":{},\"segments_skipped\":{},\"timed\":{},\"violations\":{},\"clean\":{},\"checks\":{{",
        summary.rows,
        summary.segments,
        summary.segments_skipped,
        summary.timed,
        summary.violations(),
        summary.clean()
    );
    for (k, (c, st)) in summary.checks.iter().enumerate() {
        if k > 0 {
            s.push(',');
        }
        let _ = write!(s, "\"{}\":{{\"count\":{}", c.code(), st.count);
        match &st.worst {
            None => s.push_str(
                ",\"worst\":null,\"limit\":null,\"row\":null,\"detail\":null,\"joints_line\":null,\"path_line\":null}",
            ),
            Some(w) => {
                let line = |l: Option<u64>| l.map_or("null".to_string(), |l| l.to_string());
                let _ = write!(
                    s,
                    ",\"worst\":{},\"limit\":{},\"row\":{},\"detail\":{},\"joints_line\":{},\"path_line\":{}}}",
                    json_number(w.value),
                    json_number(w.limit),
                    json_string(&w.row),
                    json_string(&w.detail),
                    line(w.joints_line),
                    line(w.path_line)
                );
            }
        }
    }
    s.push_str("}}");
    s
}

/// A finding's detail with the lines of both inputs it is at.
fn with_lines(w: &verne::verify::Violation) -> String {
    match (w.joints_line, w.path_line) {
        (Some(j), Some(p)) => format!("{} [joints line {j}, path line {p}]", w.detail),
        (Some(j), None) => format!("{} [joints line {j}]", w.detail),
        (None, Some(p)) => format!("{} [path line {p}]", w.detail),
        (None, None) => w.detail.clone(),
    }
}

/// A fatal error as the JSON object `--format json` writes instead of a summary: the file, line
/// and column when the error has them, and the message.
pub fn error_json(e: &crate::error::VerneError) -> String {
    use crate::error::VerneError;
    if let VerneError::RowFailed(inner) = e {
        return error_json(inner);
    }
    let (file, line, column, message) = match e {
        VerneError::Input {
            file,
            line,
            column,
            message,
        } => (Some(file.clone()), *line, column.clone(), message.clone()),
        VerneError::Io { file, error } => (Some(file.clone()), None, None, error.to_string()),
        other => (None, None, None, other.to_string()),
    };
    format!(
        "{{\"error\":{},\"file\":{},\"line\":{},\"column\":{}}}",
        json_string(&message),
        file.as_deref().map_or("null".to_string(), json_string),
        line.map_or("null".to_string(), |l| l.to_string()),
        column.as_deref().map_or("null".to_string(), json_string)
    )
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_escapes_and_numbers() {
        assert_eq!(json_string("a\"b\n"), "\"a\\\"b\\u000a\"");
        assert_eq!(json_number(f64::NAN), "null");
        assert_eq!(short_number(0.1 + 0.2), "0.3");
    }
}
