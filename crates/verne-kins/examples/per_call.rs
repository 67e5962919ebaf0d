//! Cost of one call through the C interface, as a controller makes it once per servo period:
//! `verne_kins_inverse` on every pose of a path, then `verne_kins_forward` on the joints it
//! returned (the previous call's values passed in, as LinuxCNC does). Each call is timed alone
//! (Instant, about 20 ns of its own), so the worst case shows, not only the median. A second pass
//! times the inverse with `VERNE_KINS_COMPLETE` (every branch solved on every call), and the
//! ratios to the forward are printed, all from the same run.
//!
//! `cargo run --release -p verne-kins --example per_call [POSES]`. The path is the benchmarks'
//! dome spiral (crates/verne-cli/benches/kernels.rs): tips 0.5 mm apart on a sphere of radius
//! 150 mm about (0, 0, -100), the tool along the normal, tilted 6 to 30 degrees; in world
//! coordinates phi1 = the tilt, phi2 = the azimuth + 90 degrees (AIM 2007 eq. (8)).

use std::time::Instant;

use verne_kins::*;

fn percentile(sorted: &[u64], p: f64) -> u64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(200_000, |s| s.parse().expect("POSES: a count"));
    let mut err = [0 as std::ffi::c_char; 256];
    // SAFETY: null path (the embedded machine), a 256-byte error buffer.
    let k = unsafe { verne_kins_new(std::ptr::null(), err.as_mut_ptr(), err.len()) };
    assert!(!k.is_null());
    let (r, b0, b1) = (150.0f64, 6f64.to_radians(), 30f64.to_radians());
    let turns =
        n as f64 * 0.5 / (2.0 * std::f64::consts::PI * r * (b0.cos() - b1.cos()) / (b1 - b0));
    let db = (b1 - b0) / (2.0 * std::f64::consts::PI * turns);
    let mut worlds = Vec::with_capacity(n);
    let mut psi = 0.0f64;
    for _ in 0..n {
        let beta = b0 + db * psi;
        let axis = [beta.sin() * psi.cos(), beta.sin() * psi.sin(), beta.cos()];
        worlds.push([
            r * axis[0],
            r * axis[1],
            -100.0 + r * axis[2],
            beta.to_degrees(),
            psi.to_degrees() + 90.0,
        ]);
        psi += 0.5 / (r * (beta.sin().powi(2) + db * db).sqrt());
    }
    // The first call seeds from the embedded machine's home joints.
    let seed = [300.0, 250.0, 250.0, 0.0, -worlds[0][4]];
    let mut failures = [0usize; 8];
    let (mut inv, mut fwd, mut complete) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let mut joints = seed;
    let mut world_back = [0.0; 5];
    for world in &worlds {
        let t = Instant::now();
        // SAFETY: a valid handle, arrays of 5 doubles, null info.
        let s = unsafe {
            verne_kins_inverse(
                k,
                world.as_ptr(),
                joints.as_mut_ptr(),
                0,
                std::ptr::null_mut(),
            )
        };
        inv.push(t.elapsed().as_nanos() as u64);
        failures[s as usize] += (s != VerneKinsStatus::Ok) as usize;
        let t = Instant::now();
        // SAFETY: as above.
        let s = unsafe {
            verne_kins_forward(
                k,
                joints.as_ptr(),
                world_back.as_mut_ptr(),
                0,
                std::ptr::null_mut(),
            )
        };
        fwd.push(t.elapsed().as_nanos() as u64);
        failures[s as usize] += (s != VerneKinsStatus::Ok) as usize;
    }
    // SAFETY: a valid handle.
    let fallbacks = unsafe { verne_kins_inverse_fallbacks(k) };
    let mut joints = seed;
    for world in &worlds {
        let t = Instant::now();
        // SAFETY: as above.
        let s = unsafe {
            verne_kins_inverse(
                k,
                world.as_ptr(),
                joints.as_mut_ptr(),
                VERNE_KINS_COMPLETE,
                std::ptr::null_mut(),
            )
        };
        complete.push(t.elapsed().as_nanos() as u64);
        failures[s as usize] += (s != VerneKinsStatus::Ok) as usize;
    }
    // SAFETY: the handle from verne_kins_new.
    unsafe { verne_kins_free(k) };
    let mut stats = Vec::new();
    for (name, v) in [
        ("verne_kins_inverse", &mut inv),
        ("verne_kins_forward", &mut fwd),
        ("verne_kins_inverse, VERNE_KINS_COMPLETE", &mut complete),
    ] {
        v.sort_unstable();
        let q = [0.5, 0.99, 0.9999].map(|p| percentile(v, p));
        println!(
            "{name}: {n} calls, ns per call: median {}, p99 {}, p99.99 {}, max {}",
            q[0],
            q[1],
            q[2],
            v[v.len() - 1]
        );
        stats.push(q);
    }
    let ratio = |a: usize, b: usize, i: usize| stats[a][i] as f64 / stats[b][i] as f64;
    println!(
        "inverse / forward: median {:.2}, p99 {:.2}; complete inverse / forward: median {:.2}, \
         p99 {:.2}",
        ratio(0, 1, 0),
        ratio(0, 1, 1),
        ratio(2, 1, 0),
        ratio(2, 1, 1)
    );
    println!(
        "inverse calls answered by the complete solve (fallbacks): {fallbacks} of {n} ({:.3} %)",
        100.0 * fallbacks as f64 / n as f64
    );
    println!("statuses other than ok (index = status code): {failures:?}");
}
