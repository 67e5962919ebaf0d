//! Writes data/calibration/: a synthetic VERNE machine and what instruments read of it, for
//! docs/calibration.md.
//!
//! `truth.toml` is the default machine with every parameter a calibration can identify moved
//! (lengths within +-0.5 mm, offsets within +-0.3 mm and 0.2 degrees,
//! [`verne::calibrate::synthetic::TYPICAL`]). The readings are computed by verne's own forward
//! kinematics of that file (its working assembly mode) at joint sets drawn inside the default
//! machine's workspace, with Gaussian noise:
//!
//! - `tracker.csv`: 100 tool tips read by a laser tracker standing 2.5 m away, turned, 10 um;
//! - `ballbar.csv`: 60 distances from the tool ball to a ball on the table, 80 mm off the rotary
//!   axis (its place unknown to the fit), the table tilted and turned, 1 um.
//!
//! `cargo run --release -p verne --example make_calibration_data` rewrites them (the draws are
//! seeded: the same files every time).

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::{Rotation3, Vector3};
use verne::calibrate::model::{Device, Instrument, Measurement, Observed};
use verne::calibrate::plan::BALL_X_MM;
use verne::calibrate::synthetic::{TYPICAL, joints, measure, perturbed};
use verne::spec::Machine;

/// The seeds of the truth, the joints and the noise.
const TRUTH_SEED: u64 = 2024;
const TRACKER_SEED: u64 = 11;
const BALLBAR_SEED: u64 = 12;

fn csv(rows: &[Measurement]) -> String {
    let mut out = String::new();
    let header = match rows[0].observed {
        Observed::Tip { .. } => "rho1,rho2,rho3,theta1,theta2,x,y,z",
        Observed::Distance(_) => "rho1,rho2,rho3,theta1,theta2,distance",
        _ => unreachable!("the files written here"),
    };
    out.push_str(header);
    out.push('\n');
    for r in rows {
        let _ = write!(
            out,
            "{:.4},{:.4},{:.4},{:.4},{:.4}",
            r.rho.x,
            r.rho.y,
            r.rho.z,
            r.theta[0].to_degrees(),
            r.theta[1].to_degrees()
        );
        match r.observed {
            Observed::Tip { tip, .. } => {
                let _ = writeln!(out, ",{:.4},{:.4},{:.4}", tip.x, tip.y, tip.z);
            }
            Observed::Distance(d) => {
                let _ = writeln!(out, ",{d:.5}");
            }
            _ => {}
        }
    }
    out
}

fn main() -> std::io::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/calibration");
    std::fs::create_dir_all(&root)?;
    let nominal = Machine::default_verne();
    let mut truth = perturbed(&nominal, &TYPICAL, TRUTH_SEED);
    truth.name = "VERNE as built (synthetic)".into();
    let tracker = Instrument {
        rotation: Rotation3::new(Vector3::new(0.02, -0.01, 2.3)),
        translation: Vector3::new(2500.0, -800.0, 350.0),
        ball: Vector3::zeros(),
    };
    // The joints as the file writes them (0.1 um, 1e-4 degrees), so that the readings are
    // those of the joints written; the readings are written to 0.1 um (distances 0.01 um).
    let round = |j: Vec<(verne::parallel_module::equations::Sliders, [f64; 2])>| {
        j.into_iter()
            .map(|(rho, theta)| {
                (
                    rho.map(|v| (v * 1e4).round() / 1e4),
                    theta.map(|t| ((t.to_degrees() * 1e4).round() / 1e4).to_radians()),
                )
            })
            .collect::<Vec<_>>()
    };
    let j = round(joints(&nominal, Device::Tracker, 100, TRACKER_SEED));
    let rows = measure(
        &truth,
        &j,
        Device::Tracker,
        &tracker,
        0.01,
        0.0,
        false,
        TRACKER_SEED,
    );
    std::fs::write(root.join("tracker.csv"), csv(&rows))?;
    let ballbar = Instrument {
        ball: Vector3::new(BALL_X_MM + 0.37, -0.21, 0.12),
        ..Instrument::default()
    };
    let j = round(joints(&nominal, Device::Ballbar, 60, BALLBAR_SEED));
    let rows = measure(
        &truth,
        &j,
        Device::Ballbar,
        &ballbar,
        0.001,
        0.0,
        false,
        BALLBAR_SEED,
    );
    std::fs::write(root.join("ballbar.csv"), csv(&rows))?;
    let text = format!(
        "# The synthetic machine of data/calibration/: the default machine with every parameter a\n# calibration identifies moved (written by `cargo run --release -p verne --example\n# make_calibration_data`). The calibration does not read it: compare with what it finds.\n{}",
        truth.to_toml()
    );
    std::fs::write(root.join("truth.toml"), text)?;
    println!("wrote {}", root.display());
    Ok(())
}
