//! Sampled estimates of the adaptive workspaces: a deterministic hash (which cells of a
//! lattice are sampled, and where, depend on the cell's key alone, so an estimate is the same
//! whatever the threads) and the confidence half-width of a share of sampled points.

/// The confidence of a sampled estimate's half-width: 1 - delta = 99.7 %.
pub const SAMPLED_CONFIDENCE_DELTA: f64 = 0.003;

/// The half-width t of the 99.7 % confidence interval of the mean of `n` independent
/// variables in [0, 1] (Hoeffding: P(|mean - expectation| >= t) <= 2 exp(-2 n t^2) = delta),
/// at most 1; 1 for no sample.
pub fn hoeffding_half_width(n: u64) -> f64 {
    if n == 0 {
        return 1.0;
    }
    ((2.0 / SAMPLED_CONFIDENCE_DELTA).ln() / (2.0 * n as f64))
        .sqrt()
        .min(1.0)
}

/// SplitMix64 (Steele, Lea, Flood 2014): a well-mixed 64-bit hash of the state, advanced.
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `N` numbers in [0, 1) from the state (53 bits each), the state advanced past them.
pub fn unit_offsets<const N: usize>(state: &mut u64) -> [f64; N] {
    [0; N].map(|_| (splitmix64(state) >> 11) as f64 * (1.0 / (1u64 << 53) as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first outputs of the reference implementation for seed 1234567
    /// (https://prng.di.unimi.it/splitmix64.c), and offsets spread over [0, 1).
    #[test]
    fn hoeffding_half_width_solves_its_inequality() {
        for n in [1u64, 10, 1000, 200_000] {
            let t = hoeffding_half_width(n);
            let delta = 2.0 * (-2.0 * n as f64 * t * t).exp();
            assert!(
                t == 1.0 || (delta - SAMPLED_CONFIDENCE_DELTA).abs() < 1e-12,
                "{n}"
            );
        }
        assert_eq!(hoeffding_half_width(0), 1.0);
        assert!((hoeffding_half_width(200_000) - 0.004_031_839).abs() < 1e-9);
    }

    #[test]
    fn matches_the_reference_and_spreads() {
        let mut s = 1_234_567u64;
        assert_eq!(splitmix64(&mut s), 6_457_827_717_110_365_317);
        assert_eq!(splitmix64(&mut s), 3_203_168_211_198_807_973);
        let mut s = 0u64;
        let u: Vec<f64> = (0..10_000)
            .flat_map(|_| unit_offsets::<2>(&mut s))
            .collect();
        assert!(u.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = u.iter().sum::<f64>() / u.len() as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
    }
}
