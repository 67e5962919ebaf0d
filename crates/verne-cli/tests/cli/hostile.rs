//! Hostile inputs (tests/data/hostile): for each, the exact message and exit code. The messages
//! are the contract a user reads; docs/reliability.md lists the same table.

use std::process::{Command, Output, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_verne");
const DIR: &str = "tests/data/hostile";

fn verne(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .stdin(Stdio::null())
        .output()
        .expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn rows(o: &Output) -> usize {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .count()
        .saturating_sub(1)
}

/// (file, exit code, the first stderr line, output data rows)
const CSV_CASES: &[(&str, i32, &str, usize)] = &[
    (
        "empty.csv",
        2,
        "verne: error: tests/data/hostile/empty.csv:1: empty input: expected a CSV header line",
        0,
    ),
    ("header_only.csv", 0, "", 0),
    (
        "missing_column.csv",
        2,
        "verne: error: tests/data/hostile/missing_column.csv:1: missing column `zp`; expected a header with xp,yp,zp, found `xp,yp`. Inputs verne reads (column names in any case): tool poses x,y,z with i,j,k or phi1,phi2; platform points xp,yp,zp; machine joints rho1,rho2,rho3,theta1,theta2; slider rows rho1,rho2,rho3",
        0,
    ),
    (
        "duplicated_column.csv",
        2,
        "verne: error: tests/data/hostile/duplicated_column.csv:1: column yp: column `yp` appears twice in the header (names are matched ignoring case); expected unique column names",
        0,
    ),
    (
        "nan.csv",
        1,
        "verne ik: tests/data/hostile/nan.csv: 1 of 2 rows not ok (1 invalid_input)",
        2,
    ),
    (
        "inf.csv",
        1,
        "verne ik: tests/data/hostile/inf.csv: 2 of 3 rows not ok (2 invalid_input)",
        3,
    ),
    (
        "huge.csv",
        1,
        "verne ik: tests/data/hostile/huge.csv: 2 of 2 rows not ok (2 unreachable)",
        2,
    ),
    (
        "decimal_comma.csv",
        2,
        "verne: error: tests/data/hostile/decimal_comma.csv:2: column xp: expected a number (mm), found `-240,5`",
        0,
    ),
    (
        "units.csv",
        2,
        "verne: error: tests/data/hostile/units.csv:2: column xp: expected a number (mm), found `-240mm`",
        0,
    ),
    (
        "semicolons.csv",
        2,
        "verne: error: tests/data/hostile/semicolons.csv:1: missing columns `xp`, `yp`, `zp`; expected a header with xp,yp,zp, found `xp;yp;zp` (the file looks separated by `;`; verne reads comma-separated values). Inputs verne reads (column names in any case): tool poses x,y,z with i,j,k or phi1,phi2; platform points xp,yp,zp; machine joints rho1,rho2,rho3,theta1,theta2; slider rows rho1,rho2,rho3",
        0,
    ),
    (
        "ragged.csv",
        2,
        "verne: error: tests/data/hostile/ragged.csv:3: row has 2 fields; expected 3 like the header (an unterminated quote also reads to the end of the file)",
        0,
    ),
    (
        "unterminated_quote.csv",
        2,
        "verne: error: tests/data/hostile/unterminated_quote.csv:2: row has 1 field; expected 3 like the header (an unterminated quote also reads to the end of the file)",
        0,
    ),
    (
        "non_utf8.csv",
        2,
        "verne: error: tests/data/hostile/non_utf8.csv:2: column yp: expected a number (mm), found `\\xff\\xfe`",
        0,
    ),
    ("bom.csv", 0, "", 1),
    ("crlf.csv", 0, "", 1),
    ("quoted.csv", 0, "", 1),
];

#[test]
fn hostile_csv_inputs_give_exact_messages_and_exit_codes() {
    for &(file, code, first_line, n_rows) in CSV_CASES {
        let path = format!("{DIR}/{file}");
        let out = verne(&["ik", &path]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(code), "{file}: {err}");
        assert_eq!(err.lines().next().unwrap_or(""), first_line, "{file}");
        if code != 2 {
            assert_eq!(
                rows(&out),
                n_rows,
                "{file}: every input row yields one output row"
            );
        }
    }
}

#[test]
fn valid_but_odd_inputs_give_the_same_joints_as_a_plain_file() {
    let plain = verne(&["ik", &format!("{DIR}/good.csv")]);
    for odd in ["bom.csv", "crlf.csv", "quoted.csv"] {
        let out = verne(&["ik", &format!("{DIR}/{odd}")]);
        assert_eq!(out.stdout, plain.stdout, "{odd}");
    }
}

/// (file, the problem lines expected in the report)
const MACHINE_CASES: &[(&str, &[&str])] = &[
    (
        "machine_bad_toml.toml",
        &[
            "tests/data/hostile/machine_bad_toml.toml:2: not valid TOML: invalid table header; expected `.`, `]`",
        ],
    ),
    (
        "machine_negative_zero.toml",
        &[
            "tests/data/hostile/machine_negative_zero.toml:21: module.R2: must be a positive length (legs II-III platform half-width (mm)), found -190.11",
            "tests/data/hostile/machine_negative_zero.toml:24: module.L3: must be a positive length (leg-III rod length (mm)), found 0",
        ],
    ),
    (
        "machine_too_short.toml",
        &[
            "tests/data/hostile/machine_too_short.toml:18: module.L1: L1 = 40 mm is too short to reach: it must exceed |R1 - r1| = 50 mm",
        ],
    ),
    (
        "machine_leg2_short.toml",
        &[
            "tests/data/hostile/machine_leg2_short.toml:23: module.L2: L2 = 300 mm is too short to reach: the slider and platform joints are at least r4 - R2 = 375.26 mm apart, so the machine has no workspace",
        ],
    ),
    (
        "machine_rods_cross.toml",
        &[
            "tests/data/hostile/machine_rods_cross.toml:16: module.R1: R1 = 130 mm <= r1 = 150 mm: R1 cos(alpha) > r1 never holds, the leg-I rods always cross",
        ],
    ),
];

#[test]
fn hostile_machine_files_report_every_problem_with_its_line() {
    for &(file, expected) in MACHINE_CASES {
        let path = format!("{DIR}/{file}");
        for args in [
            vec!["machine", "check", &path],
            vec!["ik", "-m", &path, "--pose", "0,0,1000"],
        ] {
            let out = verne(&args);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(2), "{file}: {err}");
            let n = expected.len();
            assert_eq!(
                err.lines().next().unwrap_or(""),
                format!(
                    "verne: error: invalid machine file {path}: {n} problem{}",
                    if n == 1 { "" } else { "s" }
                )
            );
            let reported: Vec<&str> = err.lines().skip(1).map(str::trim).collect();
            assert_eq!(reported, expected, "{file}");
        }
    }
}

#[test]
fn a_hundred_megabyte_line_is_refused_with_a_short_message() {
    let dir = std::env::temp_dir().join(format!("verne-hostile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("long.csv");
    std::fs::write(&path, vec![b'x'; 100 * 1024 * 1024]).unwrap();
    let out = verne(&["ik", path.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(err.len() < 600, "message is bounded: {} bytes", err.len());
    assert!(
        err.contains("line 1 is longer than 16 MiB: expected CSV text"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
