//! `verne calibrate` and `verne calibrate plan` as a user runs them: the shipped data, a
//! synthetic machine whose calibrated file `verne ik` then uses, and bad input, each with its
//! exit code, its lines and no machine file written.
//!
//! The synthetic machines come from the library ([`verne::calibrate::synthetic`]: a perturbed
//! machine file, its own forward kinematics): the truth the command's output is compared with.

mod common;

use std::path::{Path, PathBuf};

use common::{col, num, run, table};
use nalgebra::{Rotation3, Vector3};
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

#[test]
fn the_shipped_tracker_data_calibrates() {
    let dir = scratch("shipped");
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
    // A machine file on the embedded machine that `machine check` accepts.
    let file = std::fs::read_to_string(&out).unwrap();
    assert!(file.contains("base = \"verne\""), "{file}");
    let check = run(&["machine", "check", s(&out)], None);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    // The report: every parameter, the instrument, the residuals.
    let (h, rows) = table(&std::fs::read_to_string(&report).unwrap());
    let (item, key, value) = (col(&h, "item"), col(&h, "key"), col(&h, "value"));
    let find = |i: &str, k: &str| {
        rows.iter()
            .find(|r| r[item] == i && r[key] == k)
            .unwrap_or_else(|| panic!("{i} {k}"))
    };
    assert!(num(&find("residual", "rms_after")[value]) < 0.012);
    assert!(num(&find("residual", "rms_before")[value]) > 0.1);
    assert_eq!(rows.iter().filter(|r| r[item] == "parameter").count(), 15);
    assert_eq!(rows.iter().filter(|r| r[item] == "instrument").count(), 6);
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
    let mut nan = lines.clone();
    let replaced = nan[5].replacen(',', ",NaN,", 1);
    let replaced = replaced
        .splitn(3, ',')
        .enumerate()
        .filter(|(k, _)| *k != 1)
        .map(|(_, v)| v)
        .collect::<Vec<_>>()
        .join(",");
    nan[5] = &replaced;
    let (code, err) = attempt("nan.csv", &(nan.join("\n") + "\n"), &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("nan.csv:6: column rho2"), "{err}");
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
