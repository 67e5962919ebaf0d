//! Cost of one call through the C interface, as a controller makes it once per servo period:
//! `verne_kins_inverse` on every pose of a path, then `verne_kins_forward` on the joints it
//! returned (the previous call's values passed in, as LinuxCNC does). Each call is timed alone
//! (Instant, about 20 ns of its own), so the worst case shows, not only the median.
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
    let mut psi = 0.0f64;
    let mut joints = [0.0; 5];
    let mut world_back = [0.0; 5];
    let (mut inv, mut fwd) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut failures = [0usize; 8];
    for i in 0..n {
        let beta = b0 + db * psi;
        let axis = [beta.sin() * psi.cos(), beta.sin() * psi.sin(), beta.cos()];
        let world = [
            r * axis[0],
            r * axis[1],
            -100.0 + r * axis[2],
            beta.to_degrees(),
            psi.to_degrees() + 90.0,
        ];
        if i == 0 {
            // The first call seeds from the embedded machine's home joints.
            joints = [300.0, 250.0, 250.0, 0.0, -world[4]];
        }
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
        psi += 0.5 / (r * (beta.sin().powi(2) + db * db).sqrt());
    }
    // SAFETY: the handle from verne_kins_new.
    unsafe { verne_kins_free(k) };
    for (name, v) in [
        ("verne_kins_inverse", &mut inv),
        ("verne_kins_forward", &mut fwd),
    ] {
        v.sort_unstable();
        println!(
            "{name}: {n} calls, ns per call: median {}, p99 {}, p99.99 {}, max {}",
            percentile(v, 0.5),
            percentile(v, 0.99),
            percentile(v, 0.9999),
            v[v.len() - 1]
        );
    }
    println!("statuses other than ok (index = status code): {failures:?}");
}
