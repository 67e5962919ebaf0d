//! The LinuxCNC simulation's programs replayed through the C interface as the controller calls
//! it: each program's moves sampled at the 1 ms servo period (each move at its feed, rapids at
//! the simulation's 50 mm/s, the tip and the angles A, C interpolated linearly, as
//! `verne ik --period 1ms` and LinuxCNC's planner without its acceleration ramps do), and every
//! sample's inverse answered twice from the previous answer: as it is (the continuation, with
//! the complete solve as its fallback) and with `VERNE_KINS_COMPLETE` (every branch solved and
//! the continuation chosen among them). The answers must be the same on every call: status,
//! and joints within 1e-12 (mm, degrees).

use verne_gcode::{Axis, Motion, Options, read_all};
use verne_kins::*;

/// The servo period (s).
const PERIOD_S: f64 = 1e-3;
/// The simulation's rapid rate (mm/s, linuxcnc/sim/verne.ini.in `MAX_LINEAR_VELOCITY`) and its
/// rotary axes' (degrees/s, `MAX_VELOCITY` of A and C).
const RAPID_MM_S: f64 = 50.0;
const RAPID_DEG_S: f64 = 90.0;
/// Largest difference between the two answers' joints (mm, degrees).
const SAME_JOINTS: f64 = 1e-12;
/// Where the simulation homes: X0 Y0 Z100 A0 C0.
const HOME: [f64; 5] = [0.0, 0.0, 100.0, 0.0, 0.0];

/// The world positions (X, Y, Z, A, C) the controller asks the inverse for, one per servo
/// period, from the home position through every move of the program.
fn servo_poses(program: &str) -> Vec<[f64; 5]> {
    let text = std::fs::read_to_string(program).unwrap();
    let (rows, _) = read_all(text.as_bytes(), &Options::default()).unwrap();
    let axes = [Axis::X, Axis::Y, Axis::Z, Axis::A, Axis::C];
    let mut at = HOME;
    let mut out = vec![at];
    for row in &rows {
        let mut to = at;
        for (k, a) in axes.iter().enumerate() {
            if row.get(*a).is_finite() {
                to[k] = row.get(*a);
            }
        }
        let tip = (0..3).map(|k| (to[k] - at[k]).powi(2)).sum::<f64>().sqrt();
        let turn = (3..5).map(|k| (to[k] - at[k]).abs()).fold(0.0, f64::max);
        let rapid = (tip / RAPID_MM_S).max(turn / RAPID_DEG_S);
        let t = match (row.motion, row.duration_s) {
            (Motion::Feed, Some(t)) => t,
            _ => rapid,
        };
        let n = (t / PERIOD_S).ceil().max(1.0) as usize;
        for i in 1..=n {
            let f = (i as f64 / n as f64).min(1.0);
            out.push(std::array::from_fn(|k| at[k] + f * (to[k] - at[k])));
        }
        at = to;
    }
    out
}

/// What one program's replay found.
#[derive(Debug, Default)]
struct Replay {
    calls: u64,
    ok: u64,
    fallbacks: u64,
    /// Statuses other than ok, by code.
    refused: [u64; 8],
    worst: f64,
}

fn replay(program: &str) -> Replay {
    let k = unsafe { verne_kins_new(std::ptr::null(), std::ptr::null_mut(), 0) };
    assert!(!k.is_null());
    let poses = servo_poses(program);
    // The home joints: the complete solve's continuation from the machine's middle.
    let mut home = [300.0, 250.0, 250.0, 0.0, 0.0];
    let s = unsafe {
        verne_kins_inverse(
            k,
            poses[0].as_ptr(),
            home.as_mut_ptr(),
            VERNE_KINS_COMPLETE,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, VerneKinsStatus::Ok);
    let (mut cont, mut full) = (home, home);
    let mut out = Replay::default();
    for (i, w) in poses.iter().enumerate() {
        let a = unsafe {
            verne_kins_inverse(k, w.as_ptr(), cont.as_mut_ptr(), 0, std::ptr::null_mut())
        };
        let b = unsafe {
            verne_kins_inverse(
                k,
                w.as_ptr(),
                full.as_mut_ptr(),
                VERNE_KINS_COMPLETE,
                std::ptr::null_mut(),
            )
        };
        out.calls += 1;
        assert_eq!(a, b, "{program}, call {i}, world {w:?}");
        if a == VerneKinsStatus::Ok {
            out.ok += 1;
        } else {
            out.refused[a as usize] += 1;
        }
        let gap = (0..5)
            .map(|d| (cont[d] - full[d]).abs())
            .fold(0.0, f64::max);
        assert!(
            gap <= SAME_JOINTS,
            "{program}, call {i}: {cont:?} vs {full:?}"
        );
        out.worst = out.worst.max(gap);
    }
    out.fallbacks = unsafe { verne_kins_inverse_fallbacks(k) };
    unsafe { verne_kins_free(k) };
    out
}

/// Every call of the simulation's two programs and of the example tool-centre program answers
/// the same with and without the complete solve, and the fallbacks are few: the simulation's
/// program (which starts and ends at the home pose, a double root of the theta1 equation,
/// Table II of IFToMM 2007) falls back on under 1 % of its calls.
#[test]
fn the_simulation_s_programs_answer_the_same_on_every_call() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    for (program, fallback_share) in [
        ("data/linuxcnc/verne-tcp.ngc", Some(0.01)),
        ("data/linuxcnc/verne-unreachable.ngc", None),
        ("data/example-tcp.ngc", None),
    ] {
        let r = replay(&format!("{root}/{program}"));
        println!(
            "{program}: {} calls, {} ok, refused by status {:?}, {} fallbacks ({:.3} %), \
             largest joint difference {:.1e}",
            r.calls,
            r.ok,
            r.refused,
            r.fallbacks,
            100.0 * r.fallbacks as f64 / r.calls as f64,
            r.worst
        );
        assert!(r.calls > 1000, "{program}: {r:?}");
        if let Some(share) = fallback_share {
            assert_eq!(r.ok, r.calls, "{r:?}");
            assert!((r.fallbacks as f64) < share * r.calls as f64, "{r:?}");
        }
    }
}
