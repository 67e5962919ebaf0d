//! Cost of the adaptive workspace against the resolution: points classified and time at each
//! step, the volume and its bracket, and (with `--uniform`) the uniform grid at the same step
//! for comparison (inside points equal).
//!
//! `cargo run --release -p verne --example workspace_adaptive -- [--uniform] [STEP ...]`
//! (default steps 8 4 2 1 mm; platform workspace of the default machine, coarse step 8x).

use std::time::Instant;

use verne::spec::Machine;
use verne::workspace::{
    DEFAULT_COARSE_FACTOR, Of, PAPER_LAMBDA_BOUNDS, WorkspaceOptions, compute, compute_adaptive,
};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let uniform = args.iter().any(|a| a == "--uniform");
    let mut steps: Vec<f64> = args.iter().filter_map(|a| a.parse().ok()).collect();
    if steps.is_empty() {
        steps = vec![8.0, 4.0, 2.0, 1.0];
    }
    let m = Machine::default_verne();
    println!(
        "step_mm,classified,lattice_points,seconds,volume_l,bracket_lo_l,bracket_hi_l,error_bound_pct,sampled_l,sampled_half_width_pct,sampled_cells,largest_box_l,largest_box_upper_l,largest_cube_l,largest_cube_upper_l,box_points,uniform_inside,adaptive_inside,uniform_seconds"
    );
    for step in steps {
        let opts = WorkspaceOptions {
            of: Of::Platform,
            tool_length: 0.0,
            step,
            bounds: None,
            lambda: PAPER_LAMBDA_BOUNDS,
        };
        let t = Instant::now();
        let a = compute_adaptive(&m, &opts, DEFAULT_COARSE_FACTOR, &|_| {}).unwrap();
        let secs = t.elapsed().as_secs_f64();
        let (ui, us) = if uniform {
            let t = Instant::now();
            let u = compute(&m, &opts, &|_| {}, |_| Ok::<(), ()>(()))
                .unwrap()
                .unwrap();
            let best = u.summary.largest_box_size().map_or(0.0, |b| b.1 * 1e-6);
            let cube = u.summary.largest_cube_size().map_or(0.0, |b| b.1 * 1e-6);
            (
                format!(
                    "{} (largest box {best:.4} l; cube {cube:.4} l)",
                    u.summary.inside
                ),
                format!("{:.2}", t.elapsed().as_secs_f64()),
            )
        } else {
            (String::new(), String::new())
        };
        println!(
            "{step},{},{},{secs:.2},{:.4},{:.4},{:.4},{:.3},{:.4},{:.4},{},{:.4},{:.4},{:.4},{:.4},{},{ui},{},{us}",
            a.classified,
            a.lattice_points,
            a.volume_mm3 * 1e-6,
            a.volume_lo_mm3 * 1e-6,
            a.volume_hi_mm3 * 1e-6,
            100.0 * a.error_bound_mm3() / a.volume_mm3,
            a.volume_sampled_mm3 * 1e-6,
            100.0 * a.sampled_half_width_mm3 / a.volume_sampled_mm3,
            a.sampled_cells,
            a.largest_box_mm3 * 1e-6,
            a.largest_box_upper_mm3 * 1e-6,
            a.largest_cube_mm3 * 1e-6,
            a.largest_cube_upper_mm3 * 1e-6,
            a.box_points_examined,
            a.inside_points
        );
    }
}
