//! The simulator's deterministic generator: xoshiro256** seeded through SplitMix64, with
//! Gaussian samples by the Box–Muller transform.
//!
//! The generator is `rand_xoshiro`'s `Xoshiro256StarStar`, drawn through `rand_core`'s
//! `Rng` trait. Why that crate: it is the algorithm and the seeding (SplitMix64
//! expanding one `u64` into the four state words) the simulator always used, so every
//! seed keeps its sequence — the tests below pin the first values as they were — and it
//! is `no_std`, small and `forbid(unsafe_code)`. The Gaussian stays here: its uniforms
//! and its fast `sin_cos` are part of what a seed means.

use rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::Xoshiro256StarStar;

/// xoshiro256** and the spare Box–Muller deviate.
#[derive(Clone, Debug)]
pub(crate) struct Rng {
    generator: Xoshiro256StarStar,
    spare_normal: Option<f64>,
}

impl Rng {
    /// Seed from one u64 (SplitMix64 expands it; any seed, including 0, is fine).
    pub(crate) fn new(seed: u64) -> Rng {
        Rng {
            generator: Xoshiro256StarStar::seed_from_u64(seed),
            spare_normal: None,
        }
    }

    /// Next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.generator.next_u64()
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal: Box–Muller, z0 = √(−2 ln u1) cos 2πu2, z1 = … sin 2πu2.
    pub(crate) fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare_normal.take() {
            return z;
        }
        // u1 in (0, 1] so the logarithm is finite.
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        let radius = (-2.0 * u1.ln()).sqrt();
        // The centred angle 2π(u2 − ½) ∈ [−π, π) has the same distribution of (sin, cos) up
        // to sign, which the symmetric normal does not see; it keeps the fast sin_cos in range.
        let (sin, cos) = crate::trig::sin_cos(2.0 * std::f64::consts::PI * (u2 - 0.5));
        self.spare_normal = Some(radius * sin);
        radius * cos
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first values for two seeds as the simulator has always drawn them (before the
    /// generator came from `rand_xoshiro`): a crate update that changed them would
    /// change every simulated record, and fails here.
    #[test]
    fn seeded_sequences_are_pinned() {
        for (seed, bits) in [
            (
                0,
                [
                    0x99ec_5f36_cb75_f2b4u64,
                    0xbf6e_1f78_4956_452a,
                    0x1a5f_849d_4933_e6e0,
                    0x6aa5_94f1_262d_2d2c,
                ],
            ),
            (
                42,
                [
                    0x1578_0b2e_0c2e_c716,
                    0x6104_d986_6d11_3a7e,
                    0xae17_5332_39e4_99a1,
                    0xecb8_ad47_03b3_60a1,
                ],
            ),
        ] {
            let mut rng = Rng::new(seed);
            for expected in bits {
                assert_eq!(rng.next_u64(), expected, "seed {seed}");
            }
        }
        for (seed, normals) in [
            (
                0,
                [
                    0x3f93_6b8e_f9b1_3360u64,
                    0x3ff5_b1e3_e4d1_d349,
                    0x3fd9_d691_0322_7bc7,
                    0xbfcd_de71_e47b_c859,
                ],
            ),
            (
                42,
                [
                    0x3fd3_68a9_7c38_507d,
                    0xbfd2_7628_399a_dbd8,
                    0xbff5_8040_c37f_1763,
                    0x3fe6_03e4_8643_db8d,
                ],
            ),
        ] {
            let mut rng = Rng::new(seed);
            for expected in normals {
                assert_eq!(rng.normal().to_bits(), expected, "seed {seed}");
            }
        }
    }

    #[test]
    fn same_seed_same_sequence_and_normal_moments() {
        let mut a = Rng::new(42);
        let mut b = Rng::new(42);
        for _ in 0..100 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
        let mut rng = Rng::new(7);
        let n = 20_000;
        let samples: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
        let mean = samples.iter().sum::<f64>() / n as f64;
        let var = samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.03, "mean {mean}");
        assert!((var - 1.0).abs() < 0.05, "variance {var}");
    }
}
