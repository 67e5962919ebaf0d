//! CLI tests of the glider mechanisms: run the real binary (`verne ik/fk/modes -m PRESET`,
//! `verne design`) and compare parsed numbers within named tolerances (docs/gliders.md).

use crate::common;
use std::collections::HashMap;

use common::run;
use std::process::Output;

const PRESETS: [&str; 3] = ["biglide1", "biglide2", "orthoglide"];

/// Joints read back after fk -> ik (multiples of L).
const ROUND_TRIP_TOL: f64 = 1e-9;

/// L0 and delta-rho of Table 1 within 1 % of the paper, S within 5 %.
const DIMENSION_REL_TOL: f64 = 0.01;
const S_REL_TOL: f64 = 0.05;

/// Table 2 (scaled by 1/sqrt(S) and 1/S) within the S tolerance.
const TABLE2_REL_TOL: f64 = 0.05;

/// Grid nodes of `verne design` in the tests (the default 1201 is slower, S closer).
const DESIGN_NODES: &str = "401";

/// Parsed CSV output: header and rows of cells.
struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    fn of(out: &Output) -> Table {
        let (header, rows) = common::table(&String::from_utf8(out.stdout.clone()).unwrap());
        Table { header, rows }
    }

    fn col(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.header))
    }

    fn get<'a>(&self, row: &'a [String], name: &str) -> &'a str {
        &row[self.col(name)]
    }

    fn num(&self, row: &[String], name: &str) -> f64 {
        let s = self.get(row, name);
        s.parse()
            .unwrap_or_else(|_| panic!("{name}: not a number: {s:?}"))
    }
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The preset's joint range (both joints share it), read from `verne modes`-independent data.
fn delta_rho(preset: &str) -> f64 {
    let text = std::fs::read_to_string(format!(
        "{}/../../data/{preset}.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let line = text.lines().find(|l| l.starts_with("rho1_range")).unwrap();
    let hi = line.split(',').nth(1).unwrap().trim().trim_end_matches(']');
    hi.trim().parse().unwrap()
}

#[test]
fn fk_then_ik_round_trip_through_the_cli_for_each_preset() {
    for preset in PRESETS {
        let dr = delta_rho(preset);
        // A 6 x 6 grid strictly inside the joint box; `r1,r2` keep the inputs.
        let mut csv = String::from("id,r1,r2,rho1,rho2\n");
        let n = 6;
        for a in 0..n {
            for b in 0..n {
                let (r1, r2) = (
                    dr * (a as f64 + 0.5) / n as f64,
                    dr * (b as f64 + 0.5) / n as f64,
                );
                csv.push_str(&format!("{a}-{b},{r1},{r2},{r1},{r2}\n"));
            }
        }
        let fk = run(&["fk", "-m", preset], Some(&csv));
        assert_eq!(fk.status.code(), Some(0), "{preset}: {}", stderr(&fk));
        let fk_text = String::from_utf8(fk.stdout.clone()).unwrap();
        let t = Table::of(&fk);
        assert_eq!(
            t.header,
            ["id", "r1", "r2", "rho1", "rho2", "x", "y", "status"]
        );
        assert_eq!(t.rows.len(), n * n);
        assert!(t.rows.iter().all(|r| t.get(r, "status") == "ok"));

        let ik = run(&["ik", "-m", preset], Some(&fk_text));
        assert_eq!(ik.status.code(), Some(0), "{preset}: {}", stderr(&ik));
        let t = Table::of(&ik);
        // rho1, rho2 and status are replaced in place: the same columns come back.
        assert_eq!(
            t.header,
            ["id", "r1", "r2", "rho1", "rho2", "x", "y", "status"]
        );
        for r in &t.rows {
            assert_eq!(t.get(r, "status"), "ok");
            for (k, j) in [("r1", "rho1"), ("r2", "rho2")] {
                let d = (t.num(r, k) - t.num(r, j)).abs();
                assert!(d < ROUND_TRIP_TOL, "{preset} {}: {k} vs {j}: {d}", r[0]);
            }
        }
    }
}

#[test]
fn ik_then_fk_round_trip_with_inline_poses() {
    // Points of the paper's working region: FK of the centre of the joint box, then a pose.
    for preset in PRESETS {
        let dr = delta_rho(preset);
        let fk = run(
            &[
                "fk",
                "-m",
                preset,
                "--joints",
                &format!("{},{},0", 0.5 * dr, 0.25 * dr),
            ],
            None,
        );
        let t = Table::of(&fk);
        let (x, y) = (t.num(&t.rows[0], "x"), t.num(&t.rows[0], "y"));
        let ik = run(&["ik", "-m", preset, &format!("--pose={x},{y},0")], None);
        assert_eq!(ik.status.code(), Some(0), "{}", stderr(&ik));
        let t = Table::of(&ik);
        assert_eq!(t.header, ["x", "y", "rho1", "rho2", "status"]);
        assert!((t.num(&t.rows[0], "rho1") - 0.5 * dr).abs() < ROUND_TRIP_TOL);
        assert!((t.num(&t.rows[0], "rho2") - 0.25 * dr).abs() < ROUND_TRIP_TOL);
    }
}

#[test]
fn ik_all_writes_one_row_per_working_mode() {
    let out = run(
        &[
            "ik",
            "-m",
            "orthoglide",
            "--all",
            "--pose",
            "0.98,1.5,0",
            "--pose",
            "10,10,0",
        ],
        None,
    );
    // Every input row has a real solution except the far one: exit 1.
    assert_eq!(out.status.code(), Some(1));
    let t = Table::of(&out);
    assert_eq!(
        t.header,
        [
            "x", "y", "branch", "mode", "assembly", "rho1", "rho2", "working", "status"
        ]
    );
    assert_eq!(t.rows.len(), 5);
    let modes: Vec<&str> = t.rows[..4].iter().map(|r| t.get(r, "mode")).collect();
    assert_eq!(modes, ["++", "+-", "-+", "--"]);
    let working: Vec<&str> = t.rows[..4].iter().map(|r| t.get(r, "working")).collect();
    assert_eq!(working, ["true", "false", "false", "false"]);
    assert_eq!(t.get(&t.rows[0], "status"), "ok");
    assert!(t.get(&t.rows[3], "status").contains("rho1_range"));
    assert_eq!(t.get(&t.rows[4], "status"), "unreachable");
    assert_eq!(t.get(&t.rows[4], "rho1"), "");
}

#[test]
fn biglide1_mixed_modes_are_structural_singularities() {
    let out = run(
        &["ik", "-m", "biglide1", "--all", "--pose=0.97,0.5,0"],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let t = Table::of(&out);
    assert_eq!(t.rows.len(), 4);
    for r in &t.rows {
        let structural = t.get(r, "status").contains("structural_singularity");
        let mixed = matches!(t.get(r, "mode"), "+-" | "-+");
        assert_eq!(structural, mixed, "{r:?}");
    }
}

#[test]
fn fk_all_writes_both_assembly_modes_and_reports_structural_singularity() {
    let out = run(
        &[
            "fk",
            "-m",
            "orthoglide",
            "--all",
            "--joints",
            "0.5,0.5,0",
            "--joints",
            "5,5,0",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    let t = Table::of(&out);
    assert_eq!(
        t.header,
        [
            "rho1", "rho2", "branch", "mode", "assembly", "x", "y", "working", "status"
        ]
    );
    assert_eq!(t.rows.len(), 3);
    assert_eq!(t.get(&t.rows[0], "assembly"), "+");
    assert_eq!(t.get(&t.rows[1], "assembly"), "-");
    assert_eq!(t.get(&t.rows[0], "working"), "true");
    assert_eq!(t.get(&t.rows[2], "status"), "unreachable");

    // C = D at the meeting point of the orthoglide's guides: rho1 = rho2 = L0 / sqrt 2.
    let l0: f64 = 1.961161351381801;
    let r = l0 / 2f64.sqrt();
    let out = run(
        &["fk", "-m", "orthoglide", "--joints", &format!("{r},{r},0")],
        None,
    );
    assert_eq!(
        out.status.code(),
        Some(1),
        "a row not ok, not a fatal error"
    );
    let t = Table::of(&out);
    assert_eq!(t.get(&t.rows[0], "status"), "structural_singularity");
    assert_eq!(t.get(&t.rows[0], "x"), "");
    let err = stderr(&out);
    assert!(err.contains("structural singularity") && err.contains("circle of radius 1"));
}

#[test]
fn exit_codes_follow_the_contract() {
    // 0: every row ok.
    let ok = run(&["ik", "-m", "orthoglide", "--pose", "0.98,1.5,0"], None);
    assert_eq!(ok.status.code(), Some(0));
    // 1: a row outside the joint ranges: its status, its cells empty as for the VERNE machine
    // (docs/csv.md); --all writes them.
    let out = run(
        &["ik", "-m", "orthoglide"],
        Some("x,y\n0.98,1.5\n0.98,1.9\n"),
    );
    assert_eq!(out.status.code(), Some(1));
    let t = Table::of(&out);
    assert_eq!(t.rows.len(), 2);
    assert_eq!(t.get(&t.rows[0], "status"), "ok");
    assert!(t.get(&t.rows[1], "status").contains("range"));
    assert!(t.get(&t.rows[1], "rho1").is_empty() && t.get(&t.rows[1], "rho2").is_empty());
    assert!(stderr(&out).contains("1 of 2 rows not ok"));
    let all = run(
        &["ik", "-m", "orthoglide", "--all"],
        Some("x,y\n0.98,1.9\n"),
    );
    let t = Table::of(&all);
    let first = &t.rows[0];
    assert_eq!(t.get(first, "mode"), "++");
    assert!(t.get(first, "status").contains("range") && !t.get(first, "rho1").is_empty());
    // fk the same: a mode outside the ranges is written by --all only.
    let fk = run(&["fk", "-m", "orthoglide"], Some("rho1,rho2\n1.9,0.1\n"));
    assert_eq!(fk.status.code(), Some(1));
    let t = Table::of(&fk);
    assert!(t.get(&t.rows[0], "status").contains("rho1_range"));
    assert!(t.get(&t.rows[0], "x").is_empty());
    // 2: a non-zero third value, a missing column, a malformed cell.
    let planar = run(&["ik", "-m", "biglide2", "--pose", "1,2,3"], None);
    assert_eq!(planar.status.code(), Some(2));
    assert!(stderr(&planar).contains("a third value must be 0"));
    let missing = run(&["ik", "-m", "biglide2"], Some("xp,yp\n1,2\n"));
    assert_eq!(missing.status.code(), Some(2));
    assert!(stderr(&missing).contains("missing column"));
    let bad = run(&["fk", "-m", "biglide2"], Some("rho1,rho2\n0.1,abc\n"));
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains(":2: column rho2"));
}

#[test]
fn glider_file_behaves_like_its_preset() {
    let file = run(
        &["ik", "-m", "data/biglide2.toml", "--pose", "0.23,1.2,0"],
        None,
    );
    let preset = run(&["ik", "-m", "biglide2", "--pose", "0.23,1.2,0"], None);
    assert_eq!(file.status.code(), Some(0), "{}", stderr(&file));
    assert_eq!(file.stdout, preset.stdout);
}

#[test]
fn modes_lists_jacobians_singularities_and_amplification() {
    let out = run(
        &["modes", "-m", "orthoglide", "--pose", "0.98,1.5,0", "--csv"],
        None,
    );
    assert_eq!(out.status.code(), Some(0));
    let t = Table::of(&out);
    for c in [
        "mode",
        "det_a",
        "det_b",
        "parallel_singular",
        "serial_singular",
        "lambda1",
        "lambda2",
        "eq4",
        "working",
        "status",
    ] {
        t.col(c);
    }
    assert_eq!(t.rows.len(), 4);
    let w = &t.rows[0];
    assert_eq!(t.get(w, "mode"), "++");
    assert!(t.num(w, "lambda1") <= t.num(w, "lambda2"));
    assert!(t.num(w, "lambda1") > 1.0 / 3.0 && t.num(w, "lambda2") < 3.0);

    // At the isotropic configuration (P at the meeting point of the guides, struts along
    // them) both factors of the orthoglide are 1.
    let l0: f64 = 1.961161351381801;
    let r = l0 / 2f64.sqrt() - 1.0;
    let out = run(
        &[
            "modes",
            "-m",
            "orthoglide",
            "--joints",
            &format!("{r},{r},0"),
            "--csv",
        ],
        None,
    );
    let t = Table::of(&out);
    let plus = t.rows.iter().find(|r| t.get(r, "assembly") == "+").unwrap();
    assert!((t.num(plus, "lambda1") - 1.0).abs() < 1e-9);
    assert!((t.num(plus, "lambda2") - 1.0).abs() < 1e-9);

    // For a person: a title line and aligned columns.
    let human = run(&["modes", "-m", "orthoglide", "--pose", "0.98,1.5,0"], None);
    let text = String::from_utf8(human.stdout).unwrap();
    assert!(text.starts_with("orthoglide: inverse kinematics of P = (0.98, 1.5): 4 real"));
    assert_eq!(text.lines().count(), 6);
}

/// `verne design --csv`: (table, mechanism, target, quantity, unit) -> (computed, paper, diff).
type DesignRows =
    HashMap<(String, String, String, String, String), (f64, Option<f64>, Option<f64>)>;

fn design_csv(extra: &[&str]) -> (Output, DesignRows) {
    let mut args = vec!["design", "--csv", "--nodes", DESIGN_NODES];
    args.extend(extra);
    let out = run(&args, None);
    let t = Table::of(&out);
    assert_eq!(
        t.header,
        [
            "table",
            "mechanism",
            "target",
            "quantity",
            "unit",
            "computed",
            "paper",
            "rel_diff"
        ]
    );
    let opt = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().unwrap());
    let rows = t
        .rows
        .iter()
        .map(|r| {
            (
                (
                    r[0].clone(),
                    r[1].clone(),
                    r[2].clone(),
                    r[3].clone(),
                    r[4].clone(),
                ),
                (r[5].parse().unwrap(), opt(&r[6]), opt(&r[7])),
            )
        })
        .collect();
    (out, rows)
}

fn key(
    table: &str,
    mech: &str,
    target: &str,
    q: &str,
    unit: &str,
) -> (String, String, String, String, String) {
    (
        table.into(),
        mech.into(),
        target.into(),
        q.into(),
        unit.into(),
    )
}

#[test]
fn design_reproduces_tables_1_and_2_within_the_issue_tolerances() {
    let (out, rows) = design_csv(&["--l", "1000"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    for mech in PRESETS {
        for (q, unit, tol) in [
            ("l0", "L", DIMENSION_REL_TOL),
            ("delta_rho", "L", DIMENSION_REL_TOL),
            ("s", "L^2", S_REL_TOL),
        ] {
            let (computed, paper, diff) = rows[&key("1", mech, "", q, unit)];
            let (paper, diff) = (paper.unwrap(), diff.unwrap());
            assert!(
                ((computed - paper) / paper - diff).abs() < 1e-12,
                "{mech} {q}: rel_diff is (computed - paper) / paper"
            );
            assert!(diff.abs() <= tol, "{mech} {q}: {computed} vs {paper}");
        }
        // --l scales Table 1 to mm.
        let (l0, _, _) = rows[&key("1", mech, "", "l0", "L")];
        let (l0_mm, _, _) = rows[&key("1", mech, "", "l0", "mm")];
        assert!((l0_mm - 1000.0 * l0).abs() < 1e-9);
        for target in ["rectangle", "square"] {
            for (q, unit) in [
                ("l0", "m"),
                ("l", "m"),
                ("delta_rho", "m"),
                ("envelope", "m^2"),
            ] {
                let (computed, paper, diff) = rows[&key("2", mech, target, q, unit)];
                if let (Some(p), Some(d)) = (paper, diff) {
                    assert!(
                        d.abs() <= TABLE2_REL_TOL,
                        "{mech} {target} {q}: {computed} vs {p}"
                    );
                }
            }
        }
    }
    // The orthoglide is the most compact design of Table 2 (section 3.3).
    let env = |m: &str| rows[&key("2", m, "rectangle", "envelope", "m^2")].0;
    assert!(env("orthoglide") < env("biglide2") && env("biglide2") < env("biglide1"));
}

#[test]
fn design_for_a_person_and_for_other_bounds() {
    let out = run(&["design", "--nodes", "201"], None);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("Table 1 (Wenger 2001)"));
    assert!(text.contains("\nTable 2 (Wenger 2001)"));
    for mech in PRESETS {
        assert_eq!(text.matches(&format!("\n{mech} ")).count(), 3, "{mech}");
    }
    // Other bounds: no paper values (they were computed for 1/3, 3).
    let (out, rows) = design_csv(&["--bounds", "1/2,2"]);
    assert!(stderr(&out).contains("not the paper's"));
    assert!(rows.values().all(|(_, p, d)| p.is_none() && d.is_none()));
    // Bad bounds are a usage error.
    let bad = run(&["design", "--bounds", "3,1"], None);
    assert_eq!(bad.status.code(), Some(2));
    // A strut length whose S in mm^2 overflows is refused, not printed as inf; the largest
    // allowed gives finite numbers.
    let huge = run(&["design", "--nodes", "101", "--l", "1e200"], None);
    assert_eq!(huge.status.code(), Some(2), "{}", stderr(&huge));
    assert!(stderr(&huge).contains("overflow"), "{}", stderr(&huge));
    assert!(huge.stdout.is_empty());
    let (out, rows) = design_csv(&["--l", "1e150"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(rows.values().all(|(c, _, _)| c.is_finite()), "{rows:?}");
}

#[test]
fn the_mechanism_is_resolved_once_and_its_options_checked() {
    let stderr = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).into_owned();
    // machine check knows glider files.
    let c = run(&["machine", "check", "data/biglide1.toml"], None);
    assert_eq!(c.status.code(), Some(0), "{}", stderr(&c));
    assert!(String::from_utf8_lossy(&c.stdout).contains("valid glider `biglide1`"));
    // selftest refuses a glider clearly (not "No such file").
    let s = run(&["selftest", "-m", "biglide1"], None);
    assert_eq!(s.status.code(), Some(2));
    assert!(stderr(&s).contains("planar glider"), "{}", stderr(&s));
    // Options of the VERNE machine are refused for a glider, not ignored.
    let t = run(&["ik", "-m", "orthoglide", "--tool", "1,2,3,0,0,1"], None);
    assert_eq!(t.status.code(), Some(2));
    assert!(
        stderr(&t).contains("--tool is an option for the VERNE machine"),
        "{}",
        stderr(&t)
    );
    let f = run(
        &[
            "fk",
            "-m",
            "biglide2",
            "--joints",
            "0.5,0.6",
            "--tool-length",
            "10",
        ],
        None,
    );
    assert_eq!(f.status.code(), Some(2));
    assert!(stderr(&f).contains("--tool-length"), "{}", stderr(&f));
    // Planar points take two values; the VERNE machine refuses two.
    let two = run(&["ik", "-m", "biglide1", "--pose", "0.98,0.5"], None);
    let three = run(&["ik", "-m", "biglide1", "--pose", "0.98,0.5,0"], None);
    assert_eq!(two.status.code(), Some(0), "{}", stderr(&two));
    assert_eq!(two.stdout, three.stdout);
    let m = run(&["modes", "-m", "biglide1", "--joints", "0.5,0.6"], None);
    assert_eq!(m.status.code(), Some(0), "{}", stderr(&m));
    let v = run(&["ik", "--pose", "1,2"], None);
    assert_eq!(v.status.code(), Some(2));
    assert!(stderr(&v).contains("needs XP,YP,ZP"), "{}", stderr(&v));
}

#[test]
fn modes_plot_draws_every_branch_of_a_glider() {
    let dir = std::env::temp_dir().join(format!("verne-glider-modes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (args, panels) in [
        (vec!["modes", "-m", "biglide1", "--pose", "0.97,0.5"], 4),
        (vec!["modes", "-m", "orthoglide", "--joints", "0.5,0.5"], 2),
    ] {
        let svg = dir.join("modes.svg");
        let mut a = args.clone();
        a.extend(["--plot", svg.to_str().unwrap()]);
        let out = run(&a, None);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let picture = std::fs::read_to_string(&svg).unwrap();
        assert_eq!(picture.matches(": mode ").count(), panels, "{args:?}");
        assert!(picture.contains("mode ++, assembly +"));
        assert!(picture.contains("x (L)") && picture.contains("strut CP"));
        std::fs::remove_file(&svg).unwrap();
    }
    // PNG too, and a glider workspace in PNG.
    let png = dir.join("modes.png");
    let out = run(
        &[
            "modes",
            "-m",
            "biglide2",
            "--pose",
            "0.2,1.2",
            "--plot",
            png.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    let ws = dir.join("ws.png");
    let out = run(
        &[
            "workspace",
            "-m",
            "biglide2",
            "--step",
            "0.05",
            "--plot",
            ws.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(std::fs::read(&ws).unwrap().starts_with(b"\x89PNG"));
    // The orthoglide's S is its largest square: one outline, named so (they overlapped).
    let svg = dir.join("ortho.svg");
    let out = run(
        &[
            "workspace",
            "-m",
            "orthoglide",
            "--plot",
            svg.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.contains("S = largest square") && !picture.contains("(dashed)"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `verne workspace -m GLIDER`: the adaptive grid writes the uniform grid's points CSV byte
/// for byte, and the same summary but for the count of points classified (fewer); the default
/// at 801 nodes is adaptive; the VERNE machine's options are refused, not ignored (and a
/// sweep of a VERNE key: `glider_sweep_rows_are_the_workspaces_of_those_gliders`).
#[test]
fn glider_workspace_adaptive_writes_what_the_uniform_grid_writes() {
    let dir = std::env::temp_dir().join(format!("verne-glider-adaptive-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (preset, step) in [
        ("orthoglide", "0.005"),
        ("biglide1", "0.004"),
        ("biglide2", "0.004"),
    ] {
        let mut summaries = Vec::new();
        let mut files = Vec::new();
        for how in ["--uniform", "--adaptive"] {
            let csv = dir.join(format!("{preset}{how}.csv"));
            let out = run(
                &[
                    "workspace",
                    "-m",
                    preset,
                    "--step",
                    step,
                    how,
                    "-o",
                    csv.to_str().unwrap(),
                ],
                None,
            );
            assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
            summaries.push(stderr(&out).replace(csv.to_str().unwrap(), "OUT"));
            files.push(std::fs::read(&csv).unwrap());
        }
        assert_eq!(files[0], files[1], "{preset}: the points CSV");
        let count = |text: &str| -> u64 {
            let line = text.lines().find(|l| l.starts_with("  grid:")).unwrap();
            let before = line.strip_suffix(" points classified").unwrap();
            before.rsplit(' ').next().unwrap().parse().unwrap()
        };
        assert!(
            count(&summaries[1]) * 3 < count(&summaries[0]),
            "{preset}: {} and {} classified",
            count(&summaries[0]),
            count(&summaries[1])
        );
        let without_grid = |text: &str| -> Vec<String> {
            text.lines()
                .filter(|l| !l.starts_with("  grid:"))
                .map(str::to_string)
                .collect()
        };
        assert_eq!(
            without_grid(&summaries[0]),
            without_grid(&summaries[1]),
            "{preset}"
        );
    }
    let out = run(&["workspace", "-m", "orthoglide"], None);
    assert_eq!(out.status.code(), Some(0));
    assert!(stderr(&out).contains("801 x 801 nodes, step 0.002079, adaptive from a coarse step"));
    for refused in [
        &["--of", "tool"][..],
        &["--tool-length", "10"],
        &["--bounds", "0,1,0,1,0,1"],
        &["--inside-only", "-o", "-"],
        &["--slice", "z=1", "--plot", "x.svg"],
    ] {
        let mut args = vec!["workspace", "-m", "biglide1"];
        args.extend_from_slice(refused);
        let out = run(&args, None);
        assert_eq!(out.status.code(), Some(2), "{refused:?}");
        assert!(
            stderr(&out).contains(&format!(
                "{} applies to the VERNE machine's workspace",
                refused[0]
            )),
            "{refused:?}: {}",
            stderr(&out)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `verne workspace -m GLIDER --sweep KEY=FROM..TO:N`: each row is `verne workspace` of the
/// glider file with that value (area, its bracket, S and the largest square, as the summary
/// prints them); two keys make a grid; the picture is drawn; a key a glider file has no
/// number for, or a value that makes an invalid glider, is refused before anything runs; an
/// empty workspace gives empty cells and exit 1.
#[test]
fn glider_sweep_rows_are_the_workspaces_of_those_gliders() {
    let dir = std::env::temp_dir().join(format!("verne-glider-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (csv, svg) = (dir.join("sweep.csv"), dir.join("sweep.svg"));
    let out = run(
        &[
            "workspace",
            "-m",
            "orthoglide",
            "--sweep",
            "l0=1.8..2.1:4",
            "-o",
            csv.to_str().unwrap(),
            "--plot",
            svg.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = std::fs::read_to_string(&csv).unwrap();
    let (header, rows) = common::table(&text);
    assert_eq!(rows.len(), 4);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(
        rows.iter().map(|r| r[0].as_str()).collect::<Vec<_>>(),
        ["1.8", "1.9", "2", "2.1"]
    );
    let template =
        String::from_utf8(run(&["machine", "show", "--base", "orthoglide"], None).stdout).unwrap();
    for row in &rows {
        let file = dir.join(format!("l0_{}.toml", row[0]));
        let body: String = template
            .lines()
            .map(|l| {
                if l.starts_with("l0 =") {
                    format!("l0 = {}", row[0])
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        std::fs::write(&file, body).unwrap();
        let one = run(&["workspace", "-m", file.to_str().unwrap()], None);
        assert_eq!(one.status.code(), Some(0), "{}", stderr(&one));
        let summary = stderr(&one);
        let number_after = |line_start: &str, after: &str| -> String {
            let line = summary
                .lines()
                .find(|l| l.trim_start().starts_with(line_start))
                .unwrap();
            let rest = &line[line.find(after).unwrap() + after.len()..];
            rest.split([' ', ';', ',', ')']).next().unwrap().to_string()
        };
        for (column, line, after) in [
            ("region_area", "t-connected region", "area "),
            ("area_lo", "t-connected region", "between "),
            ("area_hi", "t-connected region", " and "),
            ("sampled_area", "t-connected region", "sampled "),
            ("s_area", "largest rectangle", " = "),
            ("square_area", "largest square", " = "),
        ] {
            assert_eq!(row[col(column)], number_after(line, after), "{column}");
        }
    }
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.contains("t-connected region") && picture.contains("S, largest rectangle"));
    // Two keys: a grid, the second key fastest.
    let out = run(
        &[
            "workspace",
            "-m",
            "orthoglide",
            "--sweep",
            "l0=1.9..2:2",
            "--sweep",
            "l2=0.95..1.05:3",
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (header, rows) = common::table(&String::from_utf8(out.stdout).unwrap());
    assert_eq!(&header[..2], ["l0", "l2"]);
    let keys: Vec<(&str, &str)> = rows
        .iter()
        .map(|r| (r[0].as_str(), r[1].as_str()))
        .collect();
    assert_eq!(
        keys,
        [
            ("1.9", "0.95"),
            ("1.9", "1"),
            ("1.9", "1.05"),
            ("2", "0.95"),
            ("2", "1"),
            ("2", "1.05")
        ]
    );
    // Refused before anything runs: no output file.
    let refused = dir.join("refused.csv");
    for (sweep, message) in [
        (
            "rho1_range=0..1:2",
            "numeric keys are alpha1_deg, alpha2_deg, l1, l2, l0",
        ),
        ("l1=-1..1:3", "l1=-1: the glider is invalid"),
    ] {
        let out = run(
            &[
                "workspace",
                "-m",
                "orthoglide",
                "--sweep",
                sweep,
                "-o",
                refused.to_str().unwrap(),
            ],
            None,
        );
        assert_eq!(out.status.code(), Some(2), "{sweep}");
        assert!(stderr(&out).contains(message), "{sweep}: {}", stderr(&out));
        assert!(!refused.exists(), "{sweep}");
    }
    // The guides too far apart for the struts: an empty workspace, empty cells, exit 1.
    let out = run(
        &["workspace", "-m", "orthoglide", "--sweep", "l0=2..9:2"],
        None,
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let (header, rows) = common::table(&String::from_utf8(out.stdout).unwrap());
    let s = header.iter().position(|h| h == "s_area").unwrap();
    assert!(!rows[0][s].is_empty() && rows[1][s].is_empty(), "{rows:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
