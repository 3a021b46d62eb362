//! SplitMix64 (Steele, Lea & Flood 2014): the crate's one small deterministic generator —
//! the optimizer's perturbed restarts, the noise of tests and benches, the simulated
//! pilot's hands in `sweephold fly` — written once, without a dependency, so that a seed
//! gives the same sequence on every machine and after every update.

/// SplitMix64 state: a Weyl sequence (+ the golden-ratio increment) through a mixing
/// function.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

/// 2⁵³: the uniform deviates keep the top 53 bits, exactly what an f64 mantissa holds.
const TWO_POW_53: f64 = (1u64 << 53) as f64;

impl SplitMix64 {
    /// A generator from a seed (any seed, including 0).
    pub fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / TWO_POW_53
    }

    /// Uniform in (0, 1), at the centres of the 2⁵³ cells: never 0, so its logarithm is
    /// finite (Box–Muller).
    pub fn unit_open(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / TWO_POW_53
    }

    /// Uniform in [−1, 1).
    pub fn symmetric(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference outputs of SplitMix64 seeded with 1234567 (Rosetta Code,
    /// "Pseudo-random numbers/Splitmix64", from Vigna's C implementation).
    #[test]
    fn matches_the_reference_sequence() {
        let mut random = SplitMix64::new(1_234_567);
        let expected = [
            6_457_827_717_110_365_317u64,
            3_203_168_211_198_807_973,
            9_817_491_932_198_370_423,
            4_593_380_528_125_082_431,
            16_408_922_859_458_223_821,
        ];
        for value in expected {
            assert_eq!(random.next_u64(), value);
        }
    }

    #[test]
    fn deviates_stay_in_their_ranges() {
        let mut random = SplitMix64::new(0);
        for _ in 0..10_000 {
            let unit = random.unit();
            assert!((0.0..1.0).contains(&unit));
            let open = random.unit_open();
            assert!(open > 0.0 && open < 1.0);
            let symmetric = random.symmetric();
            assert!((-1.0..1.0).contains(&symmetric));
        }
    }
}
