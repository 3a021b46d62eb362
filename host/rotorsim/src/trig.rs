//! A fast `sin_cos` for the integrator's inner loop (three calls per derivative
//! evaluation). Cody–Waite reduction by π/2, then Taylor polynomials on |r| ≤ π/4:
//!
//! ```text
//! x = k·π/2 + r,  k = round(2x/π),  r = (x − k·C1) − k·C2   (C1 + C2 = π/2)
//! sin r = r − r³/3! + … − r¹⁵/15!,   cos r = 1 − r²/2! + … + r¹⁶/16!
//! (sin x, cos x) = (s, c), (c, −s), (−s, −c), (−c, s) for k mod 4 = 0, 1, 2, 3
//! ```
//!
//! The truncation error at |r| = π/4 is below (π/4)¹⁷/17! ≈ 2e-17, so the result is
//! within a few ulp of the libm value for the arguments a flight state produces
//! (|x| ≲ 1e6); beyond that it defers to `f64::sin_cos`.

/// Upper part of π/2 (exact in 33 bits, so k·C1 is exact for |k| < 2²⁰).
const HALF_PI_HI: f64 = 1.570_796_326_734_125_6;
/// π/2 − HALF_PI_HI.
const HALF_PI_LO: f64 = 6.077_100_506_506_192e-11;

/// (sin x, cos x).
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    // NaN and huge arguments go to libm.
    if x.is_nan() || x.abs() >= 1.0e6 {
        return x.sin_cos();
    }
    if x.abs() <= std::f64::consts::FRAC_PI_4 {
        // Attitude angles mostly land here: no reduction needed.
        return kernel(x);
    }
    // Round to nearest by truncation of x·2/π ± 0.5 (exact enough here, and cheaper than
    // `round`, which is a libm call on baseline x86-64).
    let scaled = x * std::f64::consts::FRAC_2_PI;
    let k = ((scaled + 0.5f64.copysign(scaled)) as i64) as f64;
    let r = (x - k * HALF_PI_HI) - k * HALF_PI_LO;
    let (s, c) = kernel(r);
    match (k as i64).rem_euclid(4) {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Taylor polynomials of sin and cos for |r| ≤ π/4.
#[inline(always)]
fn kernel(r: f64) -> (f64, f64) {
    let r2 = r * r;
    // Horner forms of the Taylor series (coefficients 1/n!).
    let s = r
        * (1.0
            + r2 * (-1.0 / 6.0
                + r2 * (1.0 / 120.0
                    + r2 * (-1.0 / 5040.0
                        + r2 * (1.0 / 362_880.0
                            + r2 * (-1.0 / 39_916_800.0
                                + r2 * (1.0 / 6_227_020_800.0
                                    + r2 * (-1.0 / 1_307_674_368_000.0))))))));
    let c = 1.0
        + r2 * (-0.5
            + r2 * (1.0 / 24.0
                + r2 * (-1.0 / 720.0
                    + r2 * (1.0 / 40_320.0
                        + r2 * (-1.0 / 3_628_800.0
                            + r2 * (1.0 / 479_001_600.0
                                + r2 * (-1.0 / 87_178_291_200.0
                                    + r2 * (1.0 / 20_922_789_888_000.0))))))));
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn matches_libm(x in -1.0e4f64..1.0e4) {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            prop_assert!((s - s0).abs() < 4e-15, "sin {x}: {s} vs {s0}");
            prop_assert!((c - c0).abs() < 4e-15, "cos {x}: {c} vs {c0}");
        }
    }

    #[test]
    fn special_points_and_huge_arguments() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_2);
        assert!((s - 1.0).abs() < 1e-16 && c.abs() < 1e-16);
        assert_eq!(sin_cos(1e9), 1e9f64.sin_cos());
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }
}
