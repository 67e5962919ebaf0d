//! `verne calibrate` and `verne calibrate plan` as a user runs them: the shipped data, a
//! synthetic machine whose calibrated file `verne ik` then uses, and bad input, each with its
//! exit code, its lines and no machine file written.
//!
//! The synthetic machines come from the library ([`verne::calibrate::synthetic`]: a perturbed
//! machine file, its own forward kinematics): the truth the command's output is compared with.

use crate::common;

use std::path::{Path, PathBuf};

use common::{col, num, run, table};
use nalgebra::{DMatrix, DVector, Rotation3, Vector3};
use verne::calibrate::Param;
use verne::calibrate::model::{Device, Instrument, Measurement, Observed};
use verne::calibrate::synthetic::{TYPICAL, joints, measure, perturbed};
use verne::spec::Machine;

/// The synthetic readings' noise (mm).
const NOISE_MM: f64 = 0.01;

/// A scratch folder of its own for each test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("verne-calibrate-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A measurement file as a user writes it (theta in degrees).
fn write_rows(path: &Path, rows: &[Measurement]) {
    let mut text = String::new();
    let header = match rows[0].observed {
        Observed::Tip { .. } => "rho1,rho2,rho3,theta1,theta2,x,y,z",
        Observed::Platform(_) => "rho1,rho2,rho3,theta1,theta2,xp,yp,zp",
        Observed::Distance(_) => "rho1,rho2,rho3,theta1,theta2,distance",
        Observed::Height(_) => "rho1,rho2,rho3,theta1,theta2,height",
    };
    text.push_str(header);
    text.push('\n');
    for r in rows {
        let reading = match r.observed {
            Observed::Tip { tip: v, .. } | Observed::Platform(v) => {
                format!("{:?},{:?},{:?}", v.x, v.y, v.z)
            }
            Observed::Distance(d) | Observed::Height(d) => format!("{d:?}"),
        };
        text.push_str(&format!(
            "{:?},{:?},{:?},{:?},{:?},{reading}\n",
            r.rho.x,
            r.rho.y,
            r.rho.z,
            r.theta[0].to_degrees(),
            r.theta[1].to_degrees()
        ));
    }
    std::fs::write(path, text).unwrap();
}

/// The instrument a synthetic data set is read by.
fn instrument() -> Instrument {
    Instrument {
        rotation: Rotation3::new(Vector3::new(0.3, -0.1, 1.2)),
        translation: Vector3::new(1800.0, 600.0, -250.0),
        ball: Vector3::zeros(),
    }
}

/// A report's rows of one item: (key, value, sigma, detail); empty cells as NaN.
fn report_rows(path: &Path, item: &str) -> Vec<(String, f64, f64, String)> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let h = r.headers().unwrap().clone();
    let at = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (i, k, v, sg, d) = (
        at("item"),
        at("key"),
        at("value"),
        at("sigma"),
        at("detail"),
    );
    let cell = |s: &str| s.parse().unwrap_or(f64::NAN);
    r.records()
        .map(Result::unwrap)
        .filter(|row| &row[i] == item)
        .map(|row| {
            (
                row[k].to_string(),
                cell(&row[v]),
                cell(&row[sg]),
                row[d].to_string(),
            )
        })
        .collect()
}

/// The truth's parameters (shown units) moved along the combinations the report says the
/// readings cannot see, until the held parameters are at their nominal values: the values a
/// fit of those readings can recover.
fn truth_in_gauge(truth: &Machine, report: &Path) -> Vec<(Param, f64)> {
    let params = report_rows(report, "parameter");
    let nominal = |p: Param| {
        let (_, v, _, _) = params.iter().find(|(k, ..)| k == p.key()).unwrap();
        *v
    };
    // Each held parameter's combination: "...; moves KEY +C, KEY +C".
    let held: Vec<(Param, Vec<(Param, f64)>)> = report_rows(report, "combination")
        .into_iter()
        .map(|(key, _, _, detail)| {
            let moves = detail.rsplit_once("; moves ").unwrap().1;
            let combination = moves
                .split(", ")
                .map(|m| {
                    let (k, c) = m.rsplit_once(' ').unwrap();
                    (Param::from_key(k).unwrap(), num(c))
                })
                .collect();
            (Param::from_key(&key).unwrap(), combination)
        })
        .collect();
    let coef = |k: usize, p: Param| {
        held[k]
            .1
            .iter()
            .find(|(q, _)| *q == p)
            .map_or(0.0, |(_, c)| *c)
    };
    let n = held.len();
    let a = DMatrix::from_fn(n, n, |i, k| coef(k, held[i].0));
    let b = DVector::from_fn(n, |i, _| {
        let p = held[i].0;
        nominal(p) - p.shown(p.value(truth))
    });
    let c = a.lu().solve(&b).expect("independent combinations");
    params
        .iter()
        .map(|(key, ..)| {
            let p = Param::from_key(key).unwrap();
            let moved: f64 = (0..n).map(|k| c[k] * coef(k, p)).sum();
            (p, p.shown(p.value(truth)) + moved)
        })
        .collect()
}

/// Every identified parameter of a report against the truth in the fit's gauge: within 3
/// sigma. The largest |error| / sigma.
fn within_three_sigma(truth: &Machine, report: &Path) -> f64 {
    let gauge = truth_in_gauge(truth, report);
    let mut worst = 0.0f64;
    for (key, value, sigma, detail) in report_rows(report, "parameter") {
        if detail != "identified" {
            continue;
        }
        let p = Param::from_key(&key).unwrap();
        let (_, t) = gauge.iter().find(|(q, _)| *q == p).unwrap();
        let z = (value - t).abs() / sigma;
        assert!(z <= 3.0, "{key}: {value} vs truth {t}, 1 sigma {sigma}");
        worst = worst.max(z);
    }
    worst
}

/// The shipped tracker data: the four combinations a tracker cannot see named, the other
/// parameters recovered within 3 sigma of data/calibration/truth.toml (brought to the fit's
/// gauge), a machine file `machine check` accepts; the tracker and the ballbar together
/// determine the table too, also within 3 sigma.
#[test]
fn the_shipped_data_calibrate_to_their_truth() {
    let dir = scratch("shipped");
    let truth = Machine::from_toml_str(
        &std::fs::read_to_string(format!("{}/data/calibration/truth.toml", common::ROOT)).unwrap(),
        "truth.toml",
    )
    .unwrap();
    let out = dir.join("calibrated.toml");
    let report = dir.join("ident.csv");
    let r = run(
        &[
            "calibrate",
            "data/calibration/tracker.csv",
            "-o",
            s(&out),
            "--report",
            s(&report),
        ],
        None,
    );
    let text = stderr(&r);
    assert_eq!(r.status.code(), Some(0), "{text}");
    // The four combinations a tracker cannot see, named.
    for words in [
        "module.d1: D1 and d1 enter eqs. (3)-(4) of IFToMM 2007 only as D1 - d1",
        "module.d2: D2 and d2 enter eqs. (5)-(6) of IFToMM 2007 only as D2 - d2",
        "module.D2: a common x shift of the legs",
        "zeros.rho3: a common offset of the three slider zeros",
    ] {
        assert!(text.contains(words), "{words}:\n{text}");
    }
    assert_eq!(report_rows(&report, "combination").len(), 4);
    within_three_sigma(&truth, &report);
    // A machine file on the embedded machine that `machine check` accepts.
    let file = std::fs::read_to_string(&out).unwrap();
    assert!(file.contains("base = \"verne\""), "{file}");
    let check = run(&["machine", "check", s(&out)], None);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    // The residuals: the stated noise (10 um) after, the hold-out within 10 % of it.
    let residual = |k: &str| {
        report_rows(&report, "residual")
            .into_iter()
            .find(|r| r.0 == k)
            .unwrap()
            .1
    };
    assert!((residual("rms_after") / NOISE_MM - 1.0).abs() < 0.1);
    assert!((residual("rms_holdout") / NOISE_MM - 1.0).abs() < 0.1);
    assert!(residual("rms_before") > 10.0 * NOISE_MM);
    assert_eq!(report_rows(&report, "parameter").len(), 15);
    assert_eq!(report_rows(&report, "instrument").len(), 6);
    // Both files: the table's parameters too.
    let r = run(
        &[
            "calibrate",
            "data/calibration/tracker.csv",
            "data/calibration/ballbar.csv",
            "-o",
            s(&out),
            "--report",
            s(&report),
        ],
        None,
    );
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    let identified: Vec<String> = report_rows(&report, "parameter")
        .into_iter()
        .filter(|r| r.3 == "identified")
        .map(|r| r.0)
        .collect();
    for key in ["table.d_a", "table.y_t", "zeros.theta1", "module.D2"] {
        assert!(identified.iter().any(|k| k == key), "{key}: {identified:?}");
    }
    within_three_sigma(&truth, &report);
}

/// A synthetic machine read by the module alone (platform points, 10 um): the calibrated file
/// that `verne ik` reads gives the synthetic machine's joints of held-out platform points,
/// seen through the fitted instrument frame of the report, within 3 times the noise; the
/// perturbed file itself, zero offsets and all, gives them exactly.
#[test]
fn a_calibrated_file_gives_the_machines_joints() {
    let dir = scratch("joints");
    let nominal = Machine::default_verne();
    let truth = perturbed(&nominal, &TYPICAL, 77);
    let inst = instrument();
    let j = joints(&nominal, Device::Platform, 100, 78);
    let rows = measure(
        &truth,
        &j,
        Device::Platform,
        &inst,
        NOISE_MM,
        0.0,
        false,
        79,
    );
    let meas = dir.join("platform.csv");
    write_rows(&meas, &rows);
    let truth_file = dir.join("truth.toml");
    std::fs::write(&truth_file, truth.to_toml()).unwrap();
    let out = dir.join("cal.toml");
    let report = dir.join("ident.csv");
    let r = run(
        &["calibrate", s(&meas), "-o", s(&out), "--report", s(&report)],
        None,
    );
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    // The fitted frame, from the report (rotation vector in degrees).
    let (h, rep) = table(&std::fs::read_to_string(&report).unwrap());
    let (key, value) = (col(&h, "key"), col(&h, "value"));
    let get = |k: &str| num(&rep.iter().find(|r| r[key] == k).unwrap()[value]);
    let rot = Rotation3::new(
        Vector3::new(
            get("instrument.rx"),
            get("instrument.ry"),
            get("instrument.rz"),
        )
        .map(f64::to_radians),
    );
    let t = Vector3::new(
        get("instrument.x"),
        get("instrument.y"),
        get("instrument.z"),
    );
    // Held-out poses: other joints of the truth, their platform points as the instrument
    // sees them, then in the calibrated machine's frame.
    let held_out = joints(&nominal, Device::Platform, 40, 80);
    let mut poses = String::from("xp,yp,zp\n");
    let mut truth_poses = String::from("xp,yp,zp\n");
    for (rho, _) in &held_out {
        let modes = verne::parallel_module::fk::solve(&truth, rho);
        let p = verne::parallel_module::fk::working(&modes).unwrap().pose.p;
        let seen = inst.rotation * p + inst.translation;
        let q = rot.inverse() * (seen - t);
        poses.push_str(&format!("{:?},{:?},{:?}\n", q.x, q.y, q.z));
        truth_poses.push_str(&format!("{:?},{:?},{:?}\n", p.x, p.y, p.z));
    }
    for (file, text, tol) in [
        (&out, &poses, 3.0 * NOISE_MM),
        (&truth_file, &truth_poses, 1e-6),
    ] {
        let ik = run(&["ik", "-m", s(file), "--radians"], Some(text));
        assert_eq!(ik.status.code(), Some(0), "{}", stderr(&ik));
        let (h, got) = table(&String::from_utf8(ik.stdout).unwrap());
        let cols = [col(&h, "rho1"), col(&h, "rho2"), col(&h, "rho3")];
        let mut worst = 0.0f64;
        for (row, (rho, _)) in got.iter().zip(&held_out) {
            for k in 0..3 {
                worst = worst.max((num(&row[cols[k]]) - rho[k]).abs());
            }
        }
        assert_eq!(got.len(), held_out.len());
        assert!(worst <= tol, "{}: {worst}", file.display());
    }
}

/// Bad input: each refused with its exit code and line, and no machine file written.
#[test]
fn bad_input_is_refused_with_its_line() {
    let dir = scratch("bad");
    let nominal = Machine::default_verne();
    let truth = perturbed(&nominal, &TYPICAL, 5);
    let j = joints(&nominal, Device::Tracker, 40, 6);
    let rows = measure(
        &truth,
        &j,
        Device::Tracker,
        &instrument(),
        NOISE_MM,
        0.0,
        false,
        7,
    );
    let good = dir.join("good.csv");
    write_rows(&good, &rows);
    let text = std::fs::read_to_string(&good).unwrap();
    let out = dir.join("out.toml");
    let attempt = |name: &str, content: &str, extra: &[&str]| {
        let path = dir.join(name);
        std::fs::write(&path, content).unwrap();
        let _ = std::fs::remove_file(&out);
        let mut args = vec!["calibrate", s(&path), "-o", s(&out)];
        args.extend_from_slice(extra);
        let r = run(&args, None);
        assert!(!out.exists(), "{name}: a machine file was written");
        (r.status.code(), stderr(&r))
    };
    let lines: Vec<&str> = text.lines().collect();
    // Too few rows: 6 rows give 18 readings for 21 unknowns.
    let (code, err) = attempt("few.csv", &(lines[..7].join("\n") + "\n"), &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("18 readings for 21 unknowns"), "{err}");
    // A NaN and an empty cell: the file, line and column.
    // The measurement file with cell `col` of line `row` (0-based) replaced by `value`.
    let with_cell = |row: usize, col: usize, value: &str| -> String {
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        let mut c: Vec<&str> = lines[row].split(',').collect();
        c[col] = value;
        out[row] = c.join(",");
        out.join("\n") + "\n"
    };
    let (code, err) = attempt("nan.csv", &with_cell(5, 1, "NaN"), &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("nan.csv:6: column rho2"), "{err}");
    let (code, err) = attempt("empty.csv", &with_cell(7, 5, ""), &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("empty.csv:8: column x"), "{err}");
    // A reading 40 mm off: far from any pose, its line; exit 1.
    let mut far = lines.clone();
    let cells: Vec<String> = far[9].split(',').map(str::to_string).collect();
    let moved = {
        let mut c = cells.clone();
        c[5] = format!("{:?}", num(&c[5]) + 40.0);
        c.join(",")
    };
    far[9] = &moved;
    let (code, err) = attempt("far.csv", &(far.join("\n") + "\n"), &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("far.csv:10:") && err.contains("far from any pose"),
        "{err}"
    );
    // Joints the machine cannot assemble.
    let mut wild = lines.clone();
    let w = {
        let mut c: Vec<String> = wild[3].split(',').map(str::to_string).collect();
        c[0] = "5000".into();
        c.join(",")
    };
    wild[3] = &w;
    let (code, err) = attempt("wild.csv", &(wild.join("\n") + "\n"), &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("wild.csv:4:") && err.contains("no assembly mode"),
        "{err}"
    );
    // An unknown column and a mix of devices.
    let (code, err) = attempt("col.csv", &text.replacen("theta2", "theta3", 1), &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("col.csv:1: column theta"), "{err}");
    let (code, err) = attempt("mix.csv", &text.replacen(",z\n", ",z,height\n", 1), &[]);
    assert_eq!(code, Some(2), "{err}");
    // The output over an input or over the report.
    let (code, err) = attempt("same.csv", &text, &["--report", s(&out)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("the same file"), "{err}");
    let nominal_file = dir.join("nominal.toml");
    std::fs::write(&nominal_file, "base = \"verne\"\n").unwrap();
    let r = run(
        &[
            "calibrate",
            s(&good),
            "-m",
            s(&nominal_file),
            "-o",
            s(&nominal_file),
        ],
        None,
    );
    assert_eq!(r.status.code(), Some(2), "{}", stderr(&r));
    assert!(stderr(&r).contains("is the input -m"), "{}", stderr(&r));
    assert_eq!(
        std::fs::read_to_string(&nominal_file).unwrap(),
        "base = \"verne\"\n"
    );
    // An unknown key to free.
    let (code, err) = attempt("good2.csv", &text, &["--free", "module.L9"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("module.L9"), "{err}");
    // A machine 8 mm longer in L1: beyond the prior bound (refused, exit 1), unless allowed.
    let mut long = truth.clone();
    long.module.l1 += 8.0;
    let rows_long = measure(
        &long,
        &j,
        Device::Tracker,
        &instrument(),
        NOISE_MM,
        0.0,
        false,
        8,
    );
    let long_csv = dir.join("long.csv");
    write_rows(&long_csv, &rows_long);
    let long_text = std::fs::read_to_string(&long_csv).unwrap();
    let (code, err) = attempt("long.csv", &long_text, &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("module.L1") && err.contains("prior bound"),
        "{err}"
    );
    let r = run(
        &["calibrate", s(&long_csv), "-o", s(&out), "--allow-large"],
        None,
    );
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    let r = run(
        &[
            "calibrate",
            s(&long_csv),
            "-o",
            s(&out),
            "--prior",
            "module.L1=10",
        ],
        None,
    );
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    // A fit that drives the machine file out of validity: slider 1's stroke is 2 mm, its zero
    // 3 mm off.
    let short = dir.join("short.toml");
    std::fs::write(
        &short,
        "base = \"verne\"\n[limits]\nrho1_min = 300\nrho1_max = 302\n",
    )
    .unwrap();
    let mut offset = nominal.clone();
    offset.module.rho_zero = [3.0, 0.0, 0.0];
    let rows_off = measure(
        &offset,
        &j,
        Device::Tracker,
        &instrument(),
        NOISE_MM,
        0.0,
        false,
        9,
    );
    let off_csv = dir.join("off.csv");
    write_rows(&off_csv, &rows_off);
    let off_text = std::fs::read_to_string(&off_csv).unwrap();
    let (code, err) = attempt("off2.csv", &off_text, &["-m", s(&short)]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("zeros.rho1") && err.contains("not valid"),
        "{err}"
    );
}

/// The output names its base relative to itself, and a file on that base reads back.
#[test]
fn the_output_is_a_machine_file_over_its_base() {
    let dir = scratch("base");
    let sub = dir.join("out");
    std::fs::create_dir_all(&sub).unwrap();
    let nominal = dir.join("nominal.toml");
    std::fs::write(&nominal, "base = \"verne\"\nname = \"shop VERNE\"\n").unwrap();
    let out = sub.join("cal.toml");
    let r = run(
        &[
            "calibrate",
            "data/calibration/tracker.csv",
            "-m",
            s(&nominal),
            "-o",
            s(&out),
        ],
        None,
    );
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    let file = std::fs::read_to_string(&out).unwrap();
    assert!(file.contains("base = \"../nominal.toml\""), "{file}");
    let check = run(&["machine", "check", s(&out)], None);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    assert!(String::from_utf8_lossy(&check.stdout).contains("shop VERNE"));
}

/// The plan: 30 poses whose worst sigma is at most 0.6 of random sets', written as a
/// measurement file (the nominal machine's readings), which calibrates the nominal machine to
/// itself; a probe's plan says what heights cannot determine.
#[test]
fn a_plan_is_poses_to_measure() {
    let dir = scratch("plan");
    let poses = dir.join("poses.csv");
    let r = run(
        &[
            "calibrate",
            "plan",
            "--device",
            "tracker",
            "--poses",
            "30",
            "-o",
            s(&poses),
        ],
        None,
    );
    let text = stderr(&r);
    assert_eq!(r.status.code(), Some(0), "{text}");
    let ratio: f64 = text
        .split('(')
        .filter_map(|t| t.split("x)").next())
        .filter_map(|t| t.parse().ok())
        .next_back()
        .unwrap_or_else(|| panic!("{text}"));
    assert!(ratio <= 0.6, "{text}");
    let (h, rows) = table(&std::fs::read_to_string(&poses).unwrap());
    assert_eq!(rows.len(), 30);
    assert_eq!(
        h,
        ["rho1", "rho2", "rho3", "theta1", "theta2", "x", "y", "z"]
    );
    let out = dir.join("self.toml");
    let r = run(&["calibrate", s(&poses), "-o", s(&out)], None);
    assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
    assert!(stderr(&r).contains("0.0000 mm after"), "{}", stderr(&r));
    let r = run(
        &["calibrate", "plan", "--device", "probe", "--poses", "30"],
        None,
    );
    let text = stderr(&r);
    assert_eq!(r.status.code(), Some(0), "{text}");
    assert!(text.contains("determined too poorly"), "{text}");
    assert!(text.contains("module.R1: 1 sigma"), "{text}");
}
