//! The continuation against the complete solve's choice on random walks of a million tool
//! poses: in the workspace at a servo period's steps (1 ms: the tip 0.2 mm, phi1 0.09 and phi2
//! 0.18 degrees) and at steps a hundred times larger, and across the workspace's boundary at a
//! servo period's steps. Every pose is answered both ways and compared (the branch,
//! its joints within 1e-12 mm and degrees, the verdicts of the limits and of the singularity
//! thresholds), fallbacks included; `tests/machine_kin.rs` runs the same comparison on shorter
//! walks. Exits non-zero on any difference.
//!
//! `cargo run --release -p verne --example continuation_walk [POSES]` (docs/benchmarks.md).

#[path = "../tests/continuation_walk/mod.rs"]
mod continuation_walk;

use continuation_walk::{ACROSS, SERVO_STEP, WORKSPACE, walk};
use verne::spec::Machine;

fn main() {
    let n: u64 = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().expect("POSES: a count"));
    let m = Machine::default_verne();
    let mut failed = false;
    for (name, region, scale, seed) in [
        ("workspace", WORKSPACE, 1.0, 0x3a1c_0000_0000_0011),
        ("workspace", WORKSPACE, 100.0, 0x3a1c_0000_0000_0012),
        ("across its boundary", ACROSS, 1.0, 0x3a1c_0000_0000_0013),
    ] {
        let t = std::time::Instant::now();
        let w = walk(&m, n, region, SERVO_STEP.times(scale), seed);
        let fallbacks: u64 = w.fallbacks.iter().sum();
        println!(
            "{name}, steps x{scale}: {} poses, {} continued, {fallbacks} fallbacks ({:.4} %; \
             not finite, no posture, not working, not isolated: {:?}), the complete solve's \
             non-answers (uncertified, unreachable, branch lost, limits): {:?}, near a \
             singularity: {}, \
             largest joint difference {:.1e} (mm, deg), the same joints bit for bit: {}, \
             different answers: {} ({:.1} s)",
            w.poses,
            w.continued,
            100.0 * fallbacks as f64 / w.poses as f64,
            w.fallbacks,
            w.no_branch,
            w.near_singularity,
            w.worst,
            w.identical,
            w.different,
            t.elapsed().as_secs_f64()
        );
        for d in &w.differences {
            println!("  {d}");
        }
        failed |= w.different > 0;
    }
    if failed {
        std::process::exit(1);
    }
}
