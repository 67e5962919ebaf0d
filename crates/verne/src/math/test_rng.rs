//! Deterministic random numbers for the unit tests.

/// Uniform numbers in [0, 1) from a fixed seed (a 64-bit LCG).
pub fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}
