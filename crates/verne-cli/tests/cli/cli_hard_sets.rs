//! The command on the solvers' degenerate sets: a path across the thin set of the default
//! machine through `verne fk` and `verne verify`, and `verne selftest` on machines where the
//! degenerate sets are sampled or where nothing can be tested (the library side is in
//! crates/verne/tests/hard_sets.rs).

use crate::common;

use verne::parallel_module::fk;
use verne::spec::Machine;

/// An 11-row path, 0.002 mm steps of rho2 across the thin set of the default machine:
/// `verne fk` gives the working mode on every row (tracked or solved), and `verne verify` of the
/// machine joints against the tool poses `verne fk` computes for them is clean (no false
/// `branch` finding).
#[test]
fn a_path_across_the_thin_set_is_ok_in_fk_and_verify() {
    let rows: Vec<[f64; 3]> = (-5..=5)
        .map(|k| {
            [
                923.8484370198487,
                967.2529090413111 + 0.002 * k as f64,
                876.4439649983864,
            ]
        })
        .collect();
    let module: String = std::iter::once("rho1,rho2,rho3\n".to_string())
        .chain(
            rows.iter()
                .map(|r| format!("{:?},{:?},{:?}\n", r[0], r[1], r[2])),
        )
        .collect();
    let out = common::run(&["fk"], Some(&module));
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (h, cells) = common::table_of(&out);
    let status = common::col(&h, "status");
    assert_eq!(cells.len(), 11);
    assert!(cells.iter().all(|r| r[status] == "ok"), "{cells:?}");
    // The library's tracker along the same rows: the working mode on every row.
    let m = Machine::default_verne();
    let mut tracker = verne::parallel_module::track::FkTracker::new(&m);
    let mut modes = fk::FkModes::new();
    for r in &rows {
        tracker.working_into(&nalgebra::Vector3::new(r[0], r[1], r[2]), &mut modes);
        assert!(fk::working(&modes).is_some(), "{r:?}");
    }
    // Machine joints (theta1 = theta2 = 0), their tool poses, and verify.
    let dir = std::env::temp_dir().join(format!("verne-thin-set-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let joints: String = std::iter::once("id,t,rho1,rho2,rho3,theta1,theta2\n".to_string())
        .chain(rows.iter().enumerate().map(|(k, r)| {
            format!(
                "{},{},{:?},{:?},{:?},0,0\n",
                k + 1,
                0.01 * k as f64,
                r[0],
                r[1],
                r[2]
            )
        }))
        .collect();
    let jpath = dir.join("joints.csv");
    std::fs::write(&jpath, &joints).unwrap();
    let fk = common::run(&["fk", jpath.to_str().unwrap()], None);
    assert_eq!(fk.status.code(), Some(0));
    let (h, cells) = common::table_of(&fk);
    let cols = ["id", "x", "y", "z", "i", "j", "k"].map(|c| common::col(&h, c));
    let path: String = std::iter::once("id,x,y,z,i,j,k\n".to_string())
        .chain(cells.iter().map(|r| {
            let v: Vec<&str> = cols.iter().map(|&c| r[c].as_str()).collect();
            format!("{}\n", v.join(","))
        }))
        .collect();
    let ppath = dir.join("path.csv");
    std::fs::write(&ppath, &path).unwrap();
    let verify = common::run(
        &[
            "verify",
            "--joints",
            jpath.to_str().unwrap(),
            "--path",
            ppath.to_str().unwrap(),
        ],
        None,
    );
    let text = String::from_utf8_lossy(&verify.stdout).to_string()
        + &String::from_utf8_lossy(&verify.stderr);
    assert_eq!(verify.status.code(), Some(0), "{text}");
    assert!(text.contains("clean"), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `verne selftest` tells the truth: the L2 = L3 machine of the issue passes (its degenerate
/// sets sampled too), and a machine on which nothing can be assembled within its strokes fails,
/// saying that nothing was tested.
#[test]
fn selftest_samples_the_hard_sets_and_fails_when_nothing_is_tested() {
    let dir = std::env::temp_dir().join(format!("verne-selftest-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let show = common::run(&["machine", "show"], None);
    let text = String::from_utf8(show.stdout).unwrap();
    let sym = text
        .lines()
        .map(|l| {
            if l.starts_with("L3 =") {
                "L3 = 950.30"
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let sym_path = dir.join("sym.toml");
    std::fs::write(&sym_path, &sym).unwrap();
    let out = common::run(&["selftest", "-m", sym_path.to_str().unwrap()], None);
    let report = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(out.status.code(), Some(0), "{report}");
    assert!(report.contains("PASS"), "{report}");
    let line = report
        .lines()
        .find(|l| l.starts_with("poses on degenerate sets"))
        .unwrap();
    let n: u64 = line.split_whitespace().nth(4).unwrap().parse().unwrap();
    assert!(n > 100, "{line}");
    // Slider II 5 m above the others: the rods cannot close, no mode anywhere.
    let far: Vec<String> = text
        .lines()
        .map(|l| match l.split('=').next().map(str::trim) {
            Some("rho1_min") | Some("rho3_min") => {
                format!("{} = 0.0", l.split('=').next().unwrap())
            }
            Some("rho1_max") | Some("rho3_max") => {
                format!("{} = 1.0", l.split('=').next().unwrap())
            }
            Some("rho2_min") => "rho2_min = 5000.0".to_string(),
            Some("rho2_max") => "rho2_max = 5001.0".to_string(),
            _ => l.to_string(),
        })
        .collect();
    let far_path = dir.join("far.toml");
    std::fs::write(&far_path, far.join("\n")).unwrap();
    let out = common::run(&["selftest", "-m", far_path.to_str().unwrap()], None);
    let report =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{report}");
    assert!(report.contains("FAIL: no assembly mode"), "{report}");
    std::fs::remove_dir_all(&dir).ok();
}
