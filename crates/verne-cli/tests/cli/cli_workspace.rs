//! The workspace's pictures (both formats, and the branch schematic of one query) and the
//! `verne workspace` command: it writes the points its summary counts (the workspace's
//! invariants are in crates/verne/tests/workspace.rs).

use std::process::Command;

use crate::common;
use common::run;

use nalgebra::Vector3;
use verne::parallel_module::equations::ModulePose;
use verne::parallel_module::ik;
use verne::spec::Machine;
use verne::workspace::{self, Of, PAPER_LAMBDA_BOUNDS, WorkspaceOptions};
use verne_cli::plot;

#[test]
fn pictures_are_written_in_both_formats() {
    let m = Machine::default_verne();
    let opts = WorkspaceOptions {
        of: Of::Tool,
        tool_length: 50.0,
        step: 60.0,
        bounds: None,
        lambda: PAPER_LAMBDA_BOUNDS,
    };
    let ws = workspace::compute::<()>(&m, &opts, &|_| {}, |_| Ok(()))
        .unwrap()
        .unwrap();
    let dir = std::env::temp_dir().join(format!("verne-ws-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["ws.svg", "ws.png"] {
        let path = dir.join(name);
        let views = plot::default_views(&ws.summary);
        plot::workspace_picture(&path, &ws.map, &ws.summary, &views, "test").unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.len() > 1000, "{name}: {} bytes", bytes.len());
    }
    let svg = std::fs::read_to_string(dir.join("ws.svg")).unwrap();
    assert!(svg.contains("slice z") && svg.contains("(ii) rod tilt"));
    // Branch schematic of the IFToMM reference point: sixteen branches.
    let p = Vector3::new(-240.0, -86.0, 1000.0);
    let sketches: Vec<plot::BranchSketch> = ik::solve(&m, &p)
        .iter()
        .enumerate()
        .map(|(k, b)| plot::BranchSketch {
            pose: ModulePose { p, alpha: b.alpha },
            rho: b.rho,
            label: format!(
                "{}: s=({},{},{})",
                k + 1,
                b.config[0],
                b.config[1],
                b.config[2]
            ),
            detail: b.verdict.to_string(),
            working: b.working(),
        })
        .collect();
    assert_eq!(sketches.len(), 16);
    let path = dir.join("modes.svg");
    plot::branches_picture(&path, &m, "P = (-240, -86, 1000)", &sketches).unwrap();
    assert!(
        std::fs::read_to_string(&path)
            .unwrap()
            .contains("rods_cross, rod_tilt")
    );
    assert!(
        plot::workspace_picture(
            &dir.join("x.pdf"),
            &ws.map,
            &ws.summary,
            &[plot::View::Projection { axis: 2 }],
            ""
        )
        .is_err()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_command_writes_the_points_its_summary_counts() {
    let dir = std::env::temp_dir().join(format!("verne-wscli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("points.csv");
    let svg = dir.join("ws.svg");
    let out = Command::new(env!("CARGO_BIN_EXE_verne"))
        .args([
            "workspace",
            "--of",
            "tool",
            "--tool-length",
            "0,100",
            "--step",
            "60",
            "-o",
        ])
        .arg(&csv)
        .arg("--plot")
        .arg(&svg)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("volume against tool length"), "{text}");
    let inside_counts: Vec<u64> = text
        .lines()
        .filter_map(|l| l.trim().strip_prefix("inside"))
        .map(|rest| rest.trim().parse().unwrap())
        .collect();
    assert_eq!(inside_counts.len(), 2, "{text}");
    let points = std::fs::read_to_string(&csv).unwrap();
    let mut lines = points.lines();
    assert_eq!(
        lines.next().unwrap(),
        "tool_length,x,y,z,xp,yp,zp,alpha,rho1,rho2,rho3,lambda1,lambda2,lambda3,status,fails"
    );
    for (k, len) in ["0", "100"].iter().enumerate() {
        let n = points
            .lines()
            .filter(|l| l.starts_with(&format!("{len},")) && l.contains(",inside,"))
            .count() as u64;
        assert_eq!(n, inside_counts[k]);
    }
    assert!(dir.join("ws-L0.svg").exists() && dir.join("ws-L100.svg").exists());
    // The platform has no tool: a usage error, exit 2.
    let bad = Command::new(env!("CARGO_BIN_EXE_verne"))
        .args(["workspace", "--of", "platform", "--tool-length", "50"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--tool-length"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn adaptive_sampling_gives_the_uniform_volume() {
    let out = |args: &[&str]| {
        let o = run(args, None);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let adaptive = out(&["workspace", "--step", "20", "--adaptive"]);
    let uniform = out(&["workspace", "--step", "20", "--uniform"]);
    let volume = |text: &str, key: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(key))
            .unwrap_or_else(|| panic!("{text}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let a = volume(&adaptive, "volume");
    let u = volume(&uniform, "volume");
    assert!(
        (a - u).abs() < 1e-3,
        "adaptive {a} l, uniform {u} l\n{adaptive}\n{uniform}"
    );
    assert!(adaptive.contains("bracket") && adaptive.contains("points classified"));
    // Points and pictures need every grid point.
    let refused = run(
        &["workspace", "--step", "20", "--adaptive", "-o", "-"],
        None,
    );
    assert_eq!(refused.status.code(), Some(2));
}

#[test]
fn a_sweep_row_is_the_workspace_of_that_machine() {
    let o = run(
        &[
            "workspace",
            "--step",
            "40",
            "--sweep",
            "module.L1=800..850:2",
        ],
        None,
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2);
    assert_eq!((rows[0][0], rows[1][0]), ("800", "850"));
    // L1 = 850 is the default machine: its row is `workspace --adaptive` of it.
    let one = run(&["workspace", "--step", "40", "--adaptive"], None);
    let summary = String::from_utf8_lossy(&one.stdout).into_owned();
    let volume = summary
        .lines()
        .find(|l| l.trim_start().starts_with("volume"))
        .and_then(|l| l.split_whitespace().nth(1))
        .unwrap();
    assert_eq!(rows[1][1], volume, "{summary}");
    // And its largest box and bound, by the header's names.
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let cell = |name: &str| rows[1][header.iter().position(|h| *h == name).unwrap()];
    let box_line = summary
        .lines()
        .find(|l| l.trim_start().starts_with("largest box"))
        .unwrap();
    let litres = |after: &str| {
        let rest = &box_line[box_line.find(after).unwrap() + after.len()..];
        rest.split_whitespace()
            .next()
            .unwrap()
            .parse::<f64>()
            .unwrap()
    };
    let close = |a: &str, b: f64| (a.parse::<f64>().unwrap() - b).abs() < 1e-3;
    assert!(close(cell("largest_box_l"), litres("mm = ")), "{box_line}");
    // At 40 mm the search is exhaustive: no bound printed, the table's bound is the box.
    assert!(!box_line.contains("larger than"), "{box_line}");
    assert!(
        close(cell("largest_box_upper_l"), litres("mm = ")),
        "{box_line}"
    );
    assert!(
        cell("largest_box_l").parse::<f64>().unwrap() > 0.0
            && cell("box_xmin").parse::<f64>().unwrap() < cell("box_xmax").parse::<f64>().unwrap(),
        "{text}"
    );
    // L1 = 800 as a machine file over the default gives the same as its row.
    let dir = std::env::temp_dir().join(format!("verne-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("l800.toml");
    std::fs::write(&f, "base = \"verne\"\n[module]\nL1 = 800\n").unwrap();
    let m = run(
        &[
            "workspace",
            "-m",
            f.to_str().unwrap(),
            "--step",
            "40",
            "--adaptive",
        ],
        None,
    );
    let s = String::from_utf8_lossy(&m.stdout).into_owned();
    assert!(
        s.contains(&format!("volume             {} l", rows[0][1])),
        "{s}\n{text}"
    );
    // A value that makes an invalid machine stops the sweep before it runs.
    let bad = run(
        &[
            "workspace",
            "--step",
            "40",
            "--sweep",
            "module.L1=-5..900:2",
        ],
        None,
    );
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("module.L1"));
}

#[test]
fn a_sweep_draws_its_volumes_and_gives_the_binding_shares() {
    let dir = std::env::temp_dir().join(format!("verne-sweep-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("sweep.svg");
    let o = run(
        &[
            "workspace",
            "--step",
            "40",
            "--sweep",
            "module.L1=800..850:2",
            "--sweep",
            "module.L2=800..820:2",
            "--plot",
            svg.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let shares: Vec<usize> = (0..header.len())
        .filter(|&k| header[k].starts_with("share_"))
        .collect();
    assert_eq!(shares.len(), 6, "{header:?}");
    for line in text.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        // Every lattice point outside has one binding constraint: the shares add up to 1.
        let sum: f64 = shares
            .iter()
            .map(|&k| cells[k].parse::<f64>().unwrap())
            .sum();
        assert!((sum - 1.0).abs() < 5e-4, "{line}");
    }
    assert_eq!(text.lines().count(), 5);
    let picture = std::fs::read_to_string(&svg).unwrap();
    for label in [
        "module.L1",
        "module.L2 = 800",
        "module.L2 = 820",
        "workspace volume (l)",
    ] {
        assert!(picture.contains(label), "{label} missing from the picture");
    }
    // A picture path that cannot be written is refused before the sweep runs.
    let bad = run(
        &[
            "workspace",
            "--step",
            "40",
            "--sweep",
            "module.L1=800..850:2",
            "--plot",
            "x.gif",
        ],
        None,
    );
    assert_eq!(bad.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}
