//! The reports of `verne verify` for people and CI systems, from the real binary on the
//! shipped example with its five defects (data/verify/): the SARIF log against the SARIF 2.1.0
//! schema (tests/data/schemas/), the JUnit XML against the rules of the Jenkins xunit plugin's
//! XSD (scripts/browser-test.sh also runs xmllint on it), and the HTML report's data against
//! the CSV report of the same run. (The pages in a browser: scripts/browser-test.sh.)

use crate::common;

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use common::*;
use serde_json::Value;

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-reports-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `verne verify` with every report into `dir`: (exit code, the CSV report's rows).
fn verify_all(dir: &Path, joints: &str, path: &str, extra: &[&str]) -> (i32, Vec<Vec<String>>) {
    let files: Vec<String> = ["report.csv", "r.html", "r.xml", "r.sarif"]
        .iter()
        .map(|f| dir.join(f).display().to_string())
        .collect();
    let mut args = vec![
        "verify", "--joints", joints, "--path", path, "--report", &files[0], "--html", &files[1],
        "--junit", &files[2], "--sarif", &files[3],
    ];
    args.extend(extra);
    let out = run(&args, None);
    let code = out.status.code().unwrap();
    assert!(code <= 1, "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("report.csv")).unwrap();
    let rows = csv
        .lines()
        .skip(1)
        .map(|l| {
            // row,check,value,limit,detail (the detail may be quoted; it is not used here).
            l.splitn(5, ',').map(str::to_string).collect()
        })
        .collect();
    (code, rows)
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn sarif_validator() -> jsonschema::Validator {
    let text =
        std::fs::read_to_string(format!("{ROOT}/tests/data/schemas/sarif-schema-2.1.0.json"))
            .unwrap();
    // The published schema's pattern for a language (of a run, of a tool component) has a
    // stray `]`, which ECMA-262 (Annex B) reads as a literal `]` but this crate's check of the
    // schema refuses: the same patterns with that `]` escaped (the only change).
    let stray = r#""^[a-zA-Z]{2}|^[a-zA-Z]{2}-[a-zA-Z]{2}]?$""#;
    assert_eq!(text.matches(stray).count(), 2);
    let text = text.replace(stray, r#""^[a-zA-Z]{2}|^[a-zA-Z]{2}-[a-zA-Z]{2}\\]?$""#);
    let schema: Value = serde_json::from_str(&text).unwrap();
    jsonschema::options()
        .should_validate_formats(true)
        .build(&schema)
        .expect("the SARIF schema compiles")
}

fn assert_valid_sarif(log: &Value) {
    let v = sarif_validator();
    let errors: Vec<String> = v
        .iter_errors(log)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
}

/// The validator rejects what the schema forbids: the tests' check can fail.
#[test]
fn the_sarif_schema_rejects_a_broken_log() {
    let v = sarif_validator();
    let ok: Value = serde_json::from_str(r#"{"version":"2.1.0","runs":[]}"#).unwrap();
    assert!(v.is_valid(&ok));
    for bad in [
        r#"{"version":"2.0.0","runs":[]}"#,
        r#"{"version":"2.1.0","runs":[{"results":[]}]}"#,
        r#"{"version":"2.1.0","runs":[{"tool":{"driver":{"name":"x"}},"results":[{"message":{"text":"m"},"locations":[{"physicalLocation":{"region":{"startLine":0}}}]}]}]}"#,
    ] {
        let log: Value = serde_json::from_str(bad).unwrap();
        assert!(!v.is_valid(&log), "{bad}");
    }
}

/// The defects: one result per finding of the CSV report, at the joint table's line of its row
/// (data row r is line r + 1) with the path's line related, the unmeasured first and then the
/// most severe; the log follows the schema.
#[test]
fn sarif_locates_every_finding_at_its_lines() {
    let dir = scratch("sarif");
    let (code, csv) = verify_all(
        &dir,
        "data/verify/joints_defects.csv",
        "data/verify/path.csv",
        &[],
    );
    assert_eq!(code, 1);
    let log = json(&dir.join("r.sarif"));
    assert_valid_sarif(&log);
    let run = &log["runs"][0];
    let results = run["results"].as_array().unwrap();
    assert_eq!(results.len(), csv.len());
    assert_eq!(run["properties"]["omitted"], 0);
    let rules: Vec<&str> = run["tool"]["driver"]["rules"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["id"].as_str().unwrap())
        .collect();
    let mut seen = BTreeSet::new();
    let mut last_severity = f64::INFINITY;
    for r in results {
        let rule = r["ruleId"].as_str().unwrap();
        assert_eq!(rules[r["ruleIndex"].as_u64().unwrap() as usize], rule);
        let row: u64 = r["properties"]["row"].as_str().unwrap().parse().unwrap();
        let loc = &r["locations"][0]["physicalLocation"];
        assert_eq!(
            loc["artifactLocation"]["uri"],
            "data/verify/joints_defects.csv"
        );
        assert_eq!(loc["region"]["startLine"], row + 1);
        let rel = &r["relatedLocations"][0]["physicalLocation"];
        assert_eq!(rel["artifactLocation"]["uri"], "data/verify/path.csv");
        assert_eq!(rel["region"]["startLine"], row + 1);
        let severity = r["properties"]["severity"].as_f64().unwrap();
        if r["properties"]["limit"].is_number() {
            assert!(severity <= last_severity, "{r}");
            last_severity = severity;
        }
        seen.insert((row.to_string(), rule.to_string()));
    }
    let expected: BTreeSet<(String, String)> =
        csv.iter().map(|r| (r[0].clone(), r[1].clone())).collect();
    assert_eq!(seen, expected);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// 6000 findings (every row's tip and axis over thresholds of 1e-9): the 5000 most severe are
/// listed, the other 1000 are counted in the run's properties and a notification, and no
/// finding left out is more severe than one listed.
#[test]
fn sarif_lists_the_most_severe_and_counts_the_rest() {
    let dir = scratch("cap");
    let (_, csv) = verify_all(
        &dir,
        "data/verify/joints.csv",
        "data/verify/path.csv",
        &[
            "--threshold",
            "tip_error_mm=1e-9",
            "--threshold",
            "axis_error_deg=1e-9",
        ],
    );
    assert_eq!(csv.len(), 6000);
    let log = json(&dir.join("r.sarif"));
    assert_valid_sarif(&log);
    let run = &log["runs"][0];
    let results = run["results"].as_array().unwrap();
    assert_eq!(results.len(), 5000);
    assert_eq!(run["properties"]["omitted"], 1000);
    assert_eq!(run["properties"]["findings"], 6000);
    let notes = run["invocations"][0]["toolExecutionNotifications"]
        .as_array()
        .unwrap();
    assert!(
        notes.iter().any(|n| n["message"]["text"]
            .as_str()
            .unwrap()
            .starts_with("1000 further findings are not listed")),
        "{notes:?}"
    );
    let severity = |value: &str, limit: &str| num(value) / num(limit);
    let listed: BTreeSet<(String, String)> = results
        .iter()
        .map(|r| {
            (
                r["properties"]["row"].as_str().unwrap().to_string(),
                r["ruleId"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    let least_listed = results
        .iter()
        .map(|r| r["properties"]["severity"].as_f64().unwrap())
        .fold(f64::INFINITY, f64::min);
    // The CSV's numbers have 9 digits: compare with that much slack.
    for r in &csv {
        if !listed.contains(&(r[0].clone(), r[1].clone())) {
            assert!(
                severity(&r[2], &r[3]) <= least_listed * (1.0 + 1e-8),
                "{r:?} left out, less severe listed: {least_listed}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The rules of tests/data/schemas/junit-10.xsd, element by element: (allowed attributes,
/// required attributes, allowed children).
fn junit_rules(
    name: &str,
) -> Option<(
    &'static [&'static str],
    &'static [&'static str],
    &'static [&'static str],
)> {
    Some(match name {
        "testsuites" => (
            &["name", "time", "tests", "failures", "errors"],
            &[],
            &["testsuite"],
        ),
        "testsuite" => (
            &[
                "name",
                "tests",
                "failures",
                "errors",
                "group",
                "time",
                "skipped",
                "timestamp",
                "hostname",
                "id",
                "package",
                "file",
                "log",
                "url",
                "version",
            ],
            &["name", "tests", "failures", "errors"],
            &[
                "testsuite",
                "properties",
                "testcase",
                "system-out",
                "system-err",
            ],
        ),
        "properties" => (&[], &[], &["property"]),
        "property" => (&["name", "value"], &["name", "value"], &[]),
        "testcase" => (
            &["name", "time", "classname", "group"],
            &["name"],
            &[
                "skipped",
                "error",
                "failure",
                "rerunFailure",
                "rerunError",
                "flakyFailure",
                "flakyError",
                "system-out",
                "system-err",
            ],
        ),
        "failure" | "error" | "skipped" => (&["type", "message"], &[], &[]),
        "system-out" | "system-err" => (&[], &[], &[]),
        _ => return None,
    })
}

/// The XSD's SUREFIRE_TIME: digits (in groups of three with commas, or not) and at most three
/// decimals.
fn surefire_time(t: &str) -> bool {
    let (int, frac) = t.split_once('.').unwrap_or((t, ""));
    !int.contains(',')
        && int.bytes().all(|b| b.is_ascii_digit())
        && frac.len() <= 3
        && frac.bytes().all(|b| b.is_ascii_digit())
}

fn check_junit_structure(node: roxmltree::Node) {
    let name = node.tag_name().name();
    let (allowed, required, children) =
        junit_rules(name).unwrap_or_else(|| panic!("element {name} is not in the schema"));
    for a in node.attributes() {
        assert!(
            allowed.contains(&a.name()),
            "{name} has attribute {}",
            a.name()
        );
    }
    for r in required {
        assert!(node.attribute(*r).is_some(), "{name} lacks {r}");
    }
    if let Some(t) = node.attribute("time").filter(|_| name != "testcase") {
        assert!(surefire_time(t), "{name} time={t}");
    }
    for c in node.children().filter(|c| c.is_element()) {
        assert!(
            children.contains(&c.tag_name().name()),
            "{name} holds {}",
            c.tag_name().name()
        );
        check_junit_structure(c);
    }
}

#[test]
fn the_junit_check_rejects_what_the_schema_forbids() {
    for bad in [
        "<testsuites skipped=\"1\"/>",
        "<testsuites><testsuite name=\"a\" tests=\"1\" failures=\"0\"/></testsuites>",
        "<testsuites><testsuite name=\"a\" tests=\"1\" failures=\"0\" errors=\"0\"><testcase name=\"x\"><failed/></testcase></testsuite></testsuites>",
        "<testsuites time=\"1.2345\"/>",
    ] {
        let doc = roxmltree::Document::parse(bad).unwrap();
        let r = std::panic::catch_unwind(|| check_junit_structure(doc.root_element()));
        assert!(r.is_err(), "{bad}");
    }
}

/// One suite, one test case per check: the failed ones with their count, worst value and first
/// rows; the others clean; the counts in the attributes are the elements'.
#[test]
fn junit_has_a_case_per_check_with_its_findings() {
    let dir = scratch("junit");
    let (_, csv) = verify_all(
        &dir,
        "data/verify/joints_defects.csv",
        "data/verify/path.csv",
        &[],
    );
    let text = std::fs::read_to_string(dir.join("r.xml")).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let root = doc.root_element();
    check_junit_structure(root);
    let suites: Vec<_> = root.children().filter(|c| c.is_element()).collect();
    assert_eq!(suites.len(), 1);
    let suite = suites[0];
    let cases: Vec<_> = suite
        .children()
        .filter(|c| c.has_tag_name("testcase"))
        .collect();
    assert_eq!(cases.len(), 14);
    assert_eq!(suite.attribute("tests"), Some("14"));
    let mut per_check: HashMap<&str, Vec<&str>> = HashMap::new();
    for r in &csv {
        per_check.entry(&r[1]).or_default().push(&r[0]);
    }
    let failed: Vec<_> = cases
        .iter()
        .filter_map(|c| {
            c.children()
                .find(|f| f.has_tag_name("failure"))
                .map(|f| (c, f))
        })
        .collect();
    assert_eq!(failed.len(), per_check.len());
    assert_eq!(
        suite.attribute("failures"),
        Some(failed.len().to_string().as_str())
    );
    assert_eq!(
        root.attribute("failures"),
        Some(failed.len().to_string().as_str())
    );
    for (case, failure) in failed {
        let check = case.attribute("name").unwrap();
        let rows = &per_check[check];
        let message = failure.attribute("message").unwrap();
        assert!(
            message.starts_with(&format!("{} finding", rows.len())),
            "{check}: {message}"
        );
        let body = failure.text().unwrap();
        for row in rows {
            assert!(body.contains(&format!("  row {row} (")), "{check}: {body}");
        }
    }
    let tip = cases
        .iter()
        .find(|c| c.attribute("name") == Some("tip_error"))
        .unwrap();
    let message = tip
        .children()
        .find(|f| f.has_tag_name("failure"))
        .unwrap()
        .attribute("message")
        .unwrap();
    assert!(
        message.contains("worst 89.5802 (limit 0.005) at row 500 (data/verify/joints_defects.csv line 501, data/verify/path.csv line 501)"),
        "{message}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Base64 (RFC 4648) decoding, for the HTML report's arrays.
fn unbase64(s: &str) -> Vec<u8> {
    let v = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => 0,
    };
    let mut out = Vec::new();
    for q in s.as_bytes().chunks(4) {
        let n = q.iter().fold(0u32, |n, c| (n << 6) | u32::from(v(*c)));
        let pad = q.iter().filter(|c| **c == b'=').count();
        let b = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&b[..3 - pad]);
    }
    out
}

fn f32s(v: &Value) -> Vec<f32> {
    unbase64(v.as_str().unwrap())
        .chunks(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn u32s(v: &Value) -> Vec<u32> {
    unbase64(v.as_str().unwrap())
        .chunks(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The page's data, from its `<script id="verne-data">` element.
fn page_data(page: &str) -> Value {
    let start = page
        .find("<script id=\"verne-data\" type=\"application/json\">")
        .unwrap();
    let body = &page[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</script>").unwrap();
    serde_json::from_str(&body[open..close]).unwrap()
}

/// The defects' page: offline (its policy forbids every fetch; nothing names a remote file);
/// the verdict first; every finding of the CSV listed at its row, with its lines and their
/// text; the plotted tip error at row 1000 is that finding's value; the 3D view's row of each
/// finding is its row.
#[test]
fn the_html_report_holds_the_run() {
    let dir = scratch("html");
    let (_, csv) = verify_all(
        &dir,
        "data/verify/joints_defects.csv",
        "data/verify/path.csv",
        &[],
    );
    let page = std::fs::read_to_string(dir.join("r.html")).unwrap();
    assert!(page.contains("content=\"default-src 'none';"));
    for remote in [" src=", "<link", "@import", "url(", "<iframe"] {
        assert!(!page.contains(remote), "{remote}");
    }
    let verdict = page.find("12 findings in 7 checks").expect("the verdict");
    assert!(verdict < page.find("<section id=\"summary\"").unwrap());
    let d = page_data(&page);
    assert_eq!(d["summary"]["violations"], 12);
    assert_eq!(d["findings_total"], 12);
    let findings = d["findings"].as_array().unwrap();
    assert_eq!(findings.len(), csv.len());
    let frames = &d["frames"];
    let frame_rows = u32s(&frames["row"]);
    for (f, r) in findings.iter().zip(&csv) {
        assert_eq!(f["row"].as_str().unwrap(), r[0]);
        assert_eq!(f["check"].as_str().unwrap(), r[1]);
        let row: u64 = r[0].parse().unwrap();
        assert_eq!(f["jl"], row + 1);
        assert_eq!(f["pl"], row + 1);
        assert!(
            f["jt"].as_str().unwrap().starts_with(&format!("{row},")),
            "{f}"
        );
        let frame = f["frame"].as_u64().unwrap() as usize;
        assert_eq!(u64::from(frame_rows[frame]), row);
    }
    // The plot: 3000 rows as 1500 buckets of two rows, every row's value kept.
    let plot = &d["plot"];
    assert_eq!(plot["n"], 3000);
    let rows = u32s(&plot["row"]);
    let tip = f32s(&plot["series"]["tip_error"]);
    let k = rows.iter().position(|r| *r == 1000).unwrap();
    let finding = findings
        .iter()
        .find(|f| f["row"] == "1000" && f["check"] == "tip_error")
        .unwrap();
    assert_eq!(tip[k], finding["value"].as_f64().unwrap() as f32);
    let marks = u32s(&plot["marks"]);
    let tip_bit = 1
        << d["checks"]
            .as_array()
            .unwrap()
            .iter()
            .position(|c| c == "tip_error")
            .unwrap();
    assert_ne!(marks[k] & tip_bit, 0);
    assert_eq!(marks.iter().filter(|m| **m & tip_bit != 0).count(), 4);
    // The 3D view: the joints and the platform of row 1000, P below the sliders' tops.
    let channels = frames["channels"].as_array().unwrap().len();
    let ch = f32s(&frames["ch"]);
    assert_eq!(ch.len(), channels * frames["n"].as_u64().unwrap() as usize);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A joint table without `t` or `feed`: every report says velocity and acceleration were not
/// checked, none says they are clean.
#[test]
fn an_untimed_table_is_reported_not_checked() {
    let dir = scratch("untimed");
    let joints = std::fs::read_to_string(format!("{ROOT}/data/verify/joints.csv")).unwrap();
    let untimed: String = joints
        .lines()
        .map(|l| {
            let mut c: Vec<&str> = l.split(',').collect();
            c.remove(1);
            c.join(",") + "\n"
        })
        .collect();
    assert!(untimed.starts_with("id,rho1,"));
    let jp = dir.join("untimed.csv");
    std::fs::write(&jp, untimed).unwrap();
    let (code, csv) = verify_all(&dir, jp.to_str().unwrap(), "data/verify/path.csv", &[]);
    assert_eq!((code, csv.len()), (0, 0));
    let page = std::fs::read_to_string(dir.join("r.html")).unwrap();
    assert!(
        page.contains("Clean: no finding in 3000 rows and 2999 segments; not checked: velocity, acceleration (no time"),
        "the verdict"
    );
    let d = page_data(&page);
    for c in d["summary"]["checks"].as_array().unwrap() {
        let timed = c["code"] == "velocity" || c["code"] == "acceleration";
        assert_eq!(c["status"] == "not_checked", timed, "{c}");
    }
    let xml = std::fs::read_to_string(dir.join("r.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    check_junit_structure(doc.root_element());
    let skipped: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("skipped"))
        .map(|n| n.parent().unwrap().attribute("name").unwrap())
        .collect();
    assert_eq!(skipped, ["velocity", "acceleration"]);
    let log = json(&dir.join("r.sarif"));
    assert_valid_sarif(&log);
    let notes = log["runs"][0]["invocations"][0]["toolExecutionNotifications"].to_string();
    assert!(notes.contains("velocity not checked") && notes.contains("acceleration not checked"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A report's folder that does not exist is fatal before the run, naming the file; nothing is
/// written.
#[test]
fn a_report_that_cannot_be_written_is_refused_first() {
    let dir = scratch("refused");
    let bad = dir.join("missing/r.html");
    let csv = dir.join("report.csv");
    let out = run(
        &[
            "verify",
            "--joints",
            "data/verify/joints.csv",
            "--path",
            "data/verify/path.csv",
            "--report",
            csv.to_str().unwrap(),
            "--html",
            bad.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&bad.display().to_string()) && err.contains("does not exist"),
        "{err}"
    );
    assert!(!csv.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `verne modes --plot FILE.html`: one branch per row of the listing, the machine's branch
/// marked, the table's angles for a tool pose.
#[test]
fn modes_draws_every_branch_in_3d() {
    let dir = scratch("modes");
    let page = dir.join("modes.html");
    let out = run(
        &[
            "modes",
            "--tool",
            "80,0,30,0.342020,0,0.939693",
            "--csv",
            "--plot",
            page.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let listing = String::from_utf8(out.stdout).unwrap();
    let rows = listing.lines().count() - 1;
    let d = page_data(&std::fs::read_to_string(&page).unwrap());
    let branches = d["branches"].as_array().unwrap();
    assert_eq!(branches.len(), rows);
    assert!(branches.iter().any(|b| b["working"] == true));
    assert!(
        branches
            .iter()
            .all(|b| b["theta1"].is_number() && b["tip"][0] == 80.0)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A glider has no 3D view: `--plot FILE.html` is refused before any work, naming the formats
/// that it has.
#[test]
fn a_glider_has_no_3d_view() {
    let dir = scratch("glider");
    let page = dir.join("g.html");
    let out = run(
        &[
            "modes",
            "-m",
            "biglide1",
            "--pose",
            "0.97,0.5",
            "--plot",
            page.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("biglide1 is a glider") && err.contains("FILE.svg"),
        "{err}"
    );
    assert!(out.stdout.is_empty() && !page.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
