//! Angles as binary fractions of a turn, and a single-precision sine of them.
//!
//! The sweep's phase reaches several hundred radians. Kept in radians it needs `f64`
//! (soft-float on the Cortex-M4F, thousands of instructions per tick) to keep its
//! fraction; kept as a *fraction of a turn* in 0.64 fixed point it needs none:
//!
//! ```text
//! Turns(k) ≙ 2π · k / 2⁶⁴ rad,  k ∈ [0, 2⁶⁴)
//! ```
//!
//! Wrapping addition of two `Turns` is addition modulo 2π, exactly (no rounding at all),
//! so a phase advanced tick by tick by exact integer increments never loses digits
//! however long it runs; the resolution is 2π/2⁶⁴ ≈ 3.4·10⁻¹⁹ rad. Only construction
//! ([`Turns::from_radians`], used when a test is configured) touches `f64`.
//!
//! [`Turns::sin`] evaluates sin(2π k/2⁶⁴) from the top 32 bits in `f32`: the two top bits
//! pick the quadrant, the remaining 30 bits the angle inside it (exact integer
//! arithmetic), and a short Taylor polynomial in `f32` on [0, π/4] does the rest. Its
//! error is below 2·10⁻⁷ (a few `f32` ulps), and |sin| ≤ 1 holds exactly.

/// An angle as a fraction of a turn: `Turns(k)` is 2π·k/2⁶⁴ rad. Arithmetic wraps, i.e.
/// it is modulo one turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Turns(pub u64);

/// 2⁶⁴ as an `f64` (exact).
const TWO_POW_64: f64 = 18_446_744_073_709_551_616.0;

impl Turns {
    /// Zero angle.
    pub const ZERO: Turns = Turns(0);

    /// The angle `radians` reduced modulo 2π. For construction, not for the tick path
    /// (`f64`). Non-finite input gives zero.
    ///
    /// x = θ/2π, reduced to x − round(x) ∈ [−½, ½] (exact in `f64`: it is the fraction
    /// the double already carries), then scaled by 2⁶⁴ and taken modulo 2⁶⁴ through the
    /// signed integer (two's complement wraps the negative half onto [½, 1)).
    pub fn from_radians(radians: f64) -> Turns {
        if !radians.is_finite() {
            return Turns::ZERO;
        }
        let turns = radians / core::f64::consts::TAU;
        let fraction = turns - libm::round(turns);
        // |fraction| ≤ ½, so fraction·2⁶⁴ fits i64 except exactly +½ (saturates to
        // i64::MAX, one part in 2⁶³ short of half a turn).
        Turns((fraction * TWO_POW_64) as i64 as u64)
    }

    /// The angle in radians in [0, 2π) (`f64`; for tests and diagnostics).
    pub fn to_radians(self) -> f64 {
        self.0 as f64 / TWO_POW_64 * core::f64::consts::TAU
    }

    /// `self + other` modulo one turn (exact).
    pub const fn wrapping_add(self, other: Turns) -> Turns {
        Turns(self.0.wrapping_add(other.0))
    }

    /// `self · n` modulo one turn (exact).
    pub const fn wrapping_mul(self, n: u64) -> Turns {
        Turns(self.0.wrapping_mul(n))
    }

    /// sin of the angle, from its top 32 bits (resolution 1.5·10⁻⁹ rad); |error| < 2·10⁻⁷.
    pub fn sin(self) -> f32 {
        sin_turns(self.high_word())
    }

    /// cos of the angle: sin of the angle plus a quarter turn.
    pub fn cos(self) -> f32 {
        sin_turns(self.high_word().wrapping_add(QUARTER))
    }

    /// The top 32 bits: the angle in units of 2π/2³².
    const fn high_word(self) -> u32 {
        (self.0 >> 32) as u32
    }
}

/// (sin x, cos x) of an `f32` angle in radians, without `f64` (libm's `sinf`/`cosf`
/// work in double precision, soft-float on the Cortex-M4): x is scaled to units of
/// 2π/2³² in `f32` (relative error 6·10⁻⁸, i.e. ~2·10⁻⁷ rad at |x| = π) and reduced modulo
/// one turn by the integer wrap. Non-finite x gives (0, 1).
pub fn sin_cos(radians: f32) -> (f32, f32) {
    /// 2³²/2π.
    const UNITS_PER_RADIAN: f32 = 683_565_275.576_431_6;
    // Through i64: wraps modulo 2³² for |x| up to ~10¹⁰ rad; the cast saturates beyond
    // and maps NaN to 0.
    let units = if radians.is_finite() {
        (radians * UNITS_PER_RADIAN) as i64 as u32
    } else {
        0
    };
    (sin_turns(units), sin_turns(units.wrapping_add(QUARTER)))
}

/// A quarter turn in units of 2π/2³².
const QUARTER: u32 = 1 << 30;
/// An eighth of a turn in units of 2π/2³².
const EIGHTH: u32 = 1 << 29;
/// Radians per unit of 2π/2³² (π/2³¹).
const RADIANS_PER_UNIT: f32 = core::f32::consts::PI / 2_147_483_648.0;

/// sin(2π·k/2³²).
///
/// ```text
/// k = q·2³⁰ + m,  q ∈ {0,1,2,3} (quadrant),  m ∈ [0, 2³⁰)
/// sin = +s(m)  q = 0      s(m) = sin(m·π/2³¹)
///       +s(2³⁰ − m) q = 1 (sin(π/2 + x) = cos x = sin(π/2 − x))
///       −s(m)  q = 2,     −s(2³⁰ − m)  q = 3
/// s(m)  = sin_poly(m·π/2³¹)            for m ≤ 2²⁹ (angle ≤ π/4)
///       = cos_poly((2³⁰ − m)·π/2³¹)    otherwise   (sin(π/2 − y) = cos y)
/// ```
///
/// The folds are integer arithmetic, so the polynomial argument is exact to the `f32`
/// conversion (relative 6·10⁻⁸).
pub fn sin_turns(k: u32) -> f32 {
    let quadrant = k >> 30;
    let within = k & (QUARTER - 1);
    // Distance into the quarter wave that rises from 0 to 1, in [0, 2³⁰].
    let rising = if quadrant & 1 == 0 {
        within
    } else {
        QUARTER - within
    };
    let magnitude = if rising <= EIGHTH {
        sin_poly(rising as f32 * RADIANS_PER_UNIT)
    } else {
        cos_poly((QUARTER - rising) as f32 * RADIANS_PER_UNIT)
    };
    if quadrant & 2 == 0 {
        magnitude
    } else {
        -magnitude
    }
}

/// sin x for x ∈ [0, π/4]: Taylor to x⁹, truncation error < x¹¹/11! < 2.5·10⁻⁹.
/// Horner in x²: x(1 − x²/6(1 − x²/20(1 − x²/42(1 − x²/72)))).
fn sin_poly(x: f32) -> f32 {
    let x2 = x * x;
    let tail = 1.0 - x2 * (1.0 / 72.0);
    let tail = 1.0 - x2 * (1.0 / 42.0) * tail;
    let tail = 1.0 - x2 * (1.0 / 20.0) * tail;
    let tail = 1.0 - x2 * (1.0 / 6.0) * tail;
    x * tail
}

/// cos x for x ∈ [0, π/4]: Taylor to x¹⁰, truncation error < x¹²/12! < 1.1·10⁻¹⁰.
/// Horner in x²: 1 − x²/2(1 − x²/12(1 − x²/30(1 − x²/56(1 − x²/90)))). At x = 0 it is
/// exactly 1, and never above 1.
fn cos_poly(x: f32) -> f32 {
    let x2 = x * x;
    let tail = 1.0 - x2 * (1.0 / 90.0);
    let tail = 1.0 - x2 * (1.0 / 56.0) * tail;
    let tail = 1.0 - x2 * (1.0 / 30.0) * tail;
    let tail = 1.0 - x2 * (1.0 / 12.0) * tail;
    1.0 - x2 * 0.5 * tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::TAU;
    use proptest::prelude::*;

    /// Against the f64 sine on a dense grid over the whole turn, quadrant and octant
    /// boundaries included.
    #[test]
    fn sine_matches_f64_over_the_turn() {
        let mut worst = 0.0f64;
        for i in 0..=(1u64 << 20) {
            let k = (i << 12).min(u64::from(u32::MAX)) as u32;
            let exact = (f64::from(k) / 4_294_967_296.0 * TAU).sin();
            let error = (f64::from(sin_turns(k)) - exact).abs();
            worst = worst.max(error);
        }
        for k in [
            0,
            EIGHTH,
            QUARTER - 1,
            QUARTER,
            QUARTER + 1,
            3 * EIGHTH,
            2 * QUARTER,
        ] {
            let exact = (f64::from(k) / 4_294_967_296.0 * TAU).sin();
            worst = worst.max((f64::from(sin_turns(k)) - exact).abs());
        }
        assert!(worst < 2e-7, "worst sine error {worst}");
        assert_eq!(sin_turns(QUARTER), 1.0);
        assert_eq!(sin_turns(3 * QUARTER), -1.0);
        assert_eq!(sin_turns(0), 0.0);
    }

    #[test]
    fn cosine_is_the_shifted_sine() {
        assert_eq!(Turns(0).cos(), 1.0);
        assert_eq!(Turns::from_radians(core::f64::consts::PI).cos(), -1.0);
        let angle = Turns::from_radians(1.0);
        assert!((f64::from(angle.cos()) - 1.0f64.cos()).abs() < 2e-7);
    }

    #[test]
    fn from_radians_reduces_modulo_two_pi() {
        for theta in [0.0, 1.0, -1.0, 3.0, 700.123, -700.123, 1e6] {
            let reduced = Turns::from_radians(theta).to_radians();
            let expected = theta.rem_euclid(TAU);
            let difference = (reduced - expected).abs();
            assert!(
                difference < 1e-9 || (TAU - difference) < 1e-9,
                "{theta}: {reduced} vs {expected}"
            );
        }
        assert_eq!(Turns::from_radians(f64::NAN), Turns::ZERO);
        assert_eq!(Turns::from_radians(f64::INFINITY), Turns::ZERO);
    }

    #[test]
    fn sin_cos_of_radians_matches_f64() {
        let mut worst = 0.0f64;
        for i in -20_000..=20_000 {
            let x = i as f32 * 1e-3;
            let (s, c) = sin_cos(x);
            let x = f64::from(x);
            worst = worst
                .max((f64::from(s) - x.sin()).abs())
                .max((f64::from(c) - x.cos()).abs());
        }
        assert!(worst < 3e-6, "worst {worst}");
        assert_eq!(sin_cos(f32::NAN), (0.0, 1.0));
        assert_eq!(sin_cos(f32::INFINITY), (0.0, 1.0));
    }

    proptest! {
        /// Adding fixed-point angles is adding radians modulo 2π.
        #[test]
        fn addition_is_modular(a in -1e4f64..1e4, b in -1e4f64..1e4) {
            let sum = Turns::from_radians(a).wrapping_add(Turns::from_radians(b));
            let expected = Turns::from_radians(a + b);
            // Both sides carry the f64 rounding of numbers up to 2·10⁴ (~4·10⁻¹²).
            let difference = sum.0.wrapping_sub(expected.0) as i64;
            prop_assert!((difference as f64).abs() / TWO_POW_64 * TAU < 1e-10);
        }

        /// |sin| ≤ 1 and the sine is odd: sin(−x) = −sin(x) to rounding.
        #[test]
        fn sine_is_bounded_and_odd(k in any::<u32>()) {
            let s = sin_turns(k);
            prop_assert!(s.abs() <= 1.0);
            prop_assert!((s + sin_turns(k.wrapping_neg())).abs() < 2e-7);
        }
    }
}
