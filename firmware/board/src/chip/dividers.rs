//! Divider arithmetic for the tick timer, the servo PWM timer, the USARTs and the SPI, from the
//! clock frequencies the clock tree actually runs at. Pure functions, tested on the host.

/// Servo PWM counter frequency [Hz]: one count per microsecond, so a compare value is
/// the pulse width in µs.
pub const SERVO_COUNTER_HZ: u32 = 1_000_000;

/// Why a divider cannot be programmed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum DividerError {
    /// A requested rate of zero.
    ZeroRate,
    /// The input clock is too slow for the requested rate.
    ClockTooSlow,
    /// The result does not fit the register.
    OutOfRange,
}

/// Auto-reload value of a 32-bit timer counting at `timer_hz` with prescaler 0 so that
/// it overflows at `rate_hz`: f_update = f_timer / (ARR + 1), ARR = round(f_timer/f) − 1.
/// Prescaler 0 keeps the full timer resolution (and QEMU's timer model mishandles a
/// non-zero prescaler on the update interrupt).
pub fn tick_reload(timer_hz: u32, rate_hz: u32) -> Result<u32, DividerError> {
    if rate_hz == 0 {
        return Err(DividerError::ZeroRate);
    }
    let counts = (timer_hz + rate_hz / 2) / rate_hz;
    if counts < 2 {
        return Err(DividerError::ClockTooSlow);
    }
    Ok(counts - 1)
}

/// The update rate a reload value really gives [mHz], for the boot log: f_timer /(ARR+1).
pub fn achieved_rate_millihz(timer_hz: u32, reload: u32) -> u64 {
    u64::from(timer_hz) * 1000 / (u64::from(reload) + 1)
}

/// Prescaler and auto-reload of a 16-bit timer at `timer_hz` counting microseconds with
/// a PWM frame of `frame_hz`: PSC = f_timer / 1 MHz − 1, ARR = 1 MHz / f_frame − 1.
pub fn servo_dividers(timer_hz: u32, frame_hz: u32) -> Result<(u16, u16), DividerError> {
    if frame_hz == 0 {
        return Err(DividerError::ZeroRate);
    }
    if timer_hz < SERVO_COUNTER_HZ {
        return Err(DividerError::ClockTooSlow);
    }
    let prescaler =
        u16::try_from(timer_hz / SERVO_COUNTER_HZ - 1).map_err(|_| DividerError::OutOfRange)?;
    let period = SERVO_COUNTER_HZ / frame_hz;
    if period < 2 {
        return Err(DividerError::ClockTooSlow);
    }
    let reload = u16::try_from(period - 1).map_err(|_| DividerError::OutOfRange)?;
    Ok((prescaler, reload))
}

/// USART baud-rate register with 16× oversampling (OVER8 = 0, RM0090 §30.3.4):
/// USARTDIV = f_pclk / (16·baud), BRR = mantissa·16 + fraction = round(f_pclk / baud).
pub fn usart_brr(pclk_hz: u32, baud: u32) -> Result<u32, DividerError> {
    if baud == 0 {
        return Err(DividerError::ZeroRate);
    }
    let brr = (pclk_hz + baud / 2) / baud;
    // USARTDIV ≥ 1 (mantissa ≥ 1); the mantissa has 12 bits.
    if brr < 16 {
        return Err(DividerError::ClockTooSlow);
    }
    if brr > 0xFFFF {
        return Err(DividerError::OutOfRange);
    }
    Ok(brr)
}

/// Loop-timer ticks per control tick when the timer runs at `timer_hz` (the IMU's rate)
/// and the flight logic at `rate_hz`: None unless `rate_hz` divides `timer_hz`, since
/// the control tick must fall on an IMU sample every time.
pub fn ticks_per_control(timer_hz: u32, rate_hz: u32) -> Option<u32> {
    (rate_hz > 0 && timer_hz.is_multiple_of(rate_hz)).then(|| timer_hz / rate_hz)
}

/// SPI baud-rate field CR1.BR (RM0090 §28.5.1): the SPI clock is f_pclk / 2^(BR+1),
/// BR in 0..=7. Returns the smallest divisor whose clock does not exceed `max_hz`.
pub fn spi_baud_bits(pclk_hz: u32, max_hz: u32) -> Result<u8, DividerError> {
    if max_hz == 0 {
        return Err(DividerError::ZeroRate);
    }
    (0u8..=7)
        .find(|&bits| pclk_hz >> (bits + 1) <= max_hz)
        .ok_or(DividerError::OutOfRange)
}

/// Baud rate error of a BRR value [parts per million]: |f_pclk/BRR − baud| / baud.
pub fn baud_error_ppm(pclk_hz: u32, baud: u32, brr: u32) -> u32 {
    let actual = u64::from(pclk_hz) * 1_000_000 / u64::from(brr.max(1));
    let wanted = u64::from(baud) * 1_000_000;
    let error = actual.abs_diff(wanted) * 1_000_000 / wanted.max(1);
    u32::try_from(error).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_reload_gives_the_rate_on_every_clock_tree() {
        // PLL tree: TIM2 at 84 MHz; HSI fallback: 16 MHz; QEMU: 1 GHz.
        assert_eq!(tick_reload(84_000_000, 200), Ok(419_999));
        assert_eq!(tick_reload(16_000_000, 200), Ok(79_999));
        assert_eq!(tick_reload(1_000_000_000, 200), Ok(4_999_999));
        for (clock, rate) in [(84_000_000, 200), (16_000_000, 333), (1_000_000_000, 1000)] {
            let reload = tick_reload(clock, rate).unwrap();
            let achieved = achieved_rate_millihz(clock, reload);
            let wanted = u64::from(rate) * 1000;
            // Rounding the count to the nearest integer bounds the error by half a count.
            assert!(
                achieved.abs_diff(wanted) * u64::from(reload + 1) <= wanted,
                "{clock} {rate}"
            );
        }
    }

    /// Servo frames from 50 to 333 Hz (the table's `SERVO_RATE`/`TAIL_RATE` range) on
    /// every timer clock the image runs at (APB1 and APB2 timers on the PLL, HSI, QEMU's
    /// emulated clock): the counter ticks exactly 1 MHz (1 µs resolution), and the frame
    /// holds the longest pulse plus a gap, so a 760 µs tail centre (and its 560–960 µs
    /// travel) is a compare value of 760 inside a 3003 µs frame at 333 Hz.
    #[test]
    fn servo_frames_up_to_333_hz_hold_a_760_us_tail_centre() {
        use crate::chip::pins::{MAX_FRAME_HZ, MAX_PULSE_US, MIN_PULSE_US};
        for timer_hz in [84_000_000, 168_000_000, 16_000_000, 1_000_000_000] {
            for frame_hz in [50, 200, 250, 333] {
                let (prescaler, reload) = servo_dividers(timer_hz, frame_hz).unwrap();
                assert_eq!(timer_hz / (u32::from(prescaler) + 1), SERVO_COUNTER_HZ);
                assert_eq!(timer_hz % (u32::from(prescaler) + 1), 0);
                let period_us = u32::from(reload) + 1;
                assert_eq!(period_us, SERVO_COUNTER_HZ / frame_hz);
                assert!(period_us >= u32::from(MAX_PULSE_US) + 100, "{frame_hz} Hz");
                assert!(MIN_PULSE_US <= 560 && 760 < period_us);
            }
            let (_, reload) = servo_dividers(timer_hz, 333).unwrap();
            assert_eq!(reload, 3002);
        }
        const { assert!(MAX_FRAME_HZ >= 333) };
    }

    #[test]
    fn tick_reload_rejects_impossible_rates() {
        assert_eq!(tick_reload(16_000_000, 0), Err(DividerError::ZeroRate));
        assert_eq!(tick_reload(1000, 1000), Err(DividerError::ClockTooSlow));
    }

    #[test]
    fn servo_timer_counts_microseconds() {
        assert_eq!(servo_dividers(84_000_000, 50), Ok((83, 19_999)));
        assert_eq!(servo_dividers(16_000_000, 333), Ok((15, 3002)));
        assert_eq!(servo_dividers(1_000_000_000, 50), Ok((999, 19_999)));
        assert_eq!(servo_dividers(500_000, 50), Err(DividerError::ClockTooSlow));
        // 10 Hz needs a 100 000-count period: more than 16 bits.
        assert_eq!(
            servo_dividers(84_000_000, 10),
            Err(DividerError::OutOfRange)
        );
        assert_eq!(servo_dividers(84_000_000, 0), Err(DividerError::ZeroRate));
    }

    #[test]
    fn the_control_tick_falls_on_an_imu_sample() {
        assert_eq!(ticks_per_control(1000, 200), Some(5));
        assert_eq!(ticks_per_control(1000, 1000), Some(1));
        assert_eq!(ticks_per_control(1000, 300), None);
        assert_eq!(ticks_per_control(1000, 0), None);
        // Both presets fly at a rate the 1 kHz IMU divides.
        for rate in [
            sweephold_firmware::Config::bo105_default(sweephold_protocol::Axis::Lat).rate_hz,
            sweephold_firmware::Config::trex700l_default(sweephold_protocol::Axis::Lat).rate_hz,
        ] {
            assert!(ticks_per_control(1000, u32::from(rate)).is_some(), "{rate}");
        }
    }

    #[test]
    fn spi_clock_stays_at_or_below_the_imu_limit() {
        // ICM-42688-P: 24 MHz at most. PLL tree: APB2 84 MHz → /4 = 21 MHz; HSI: /2 = 8 MHz.
        assert_eq!(spi_baud_bits(84_000_000, 24_000_000), Ok(1));
        assert_eq!(spi_baud_bits(16_000_000, 24_000_000), Ok(0));
        assert_eq!(spi_baud_bits(48_000_000, 24_000_000), Ok(0));
        assert_eq!(spi_baud_bits(84_000_000, 1_000_000), Ok(6));
        // Even /256 is above 100 kHz at 84 MHz.
        assert_eq!(
            spi_baud_bits(84_000_000, 100_000),
            Err(DividerError::OutOfRange)
        );
        assert_eq!(spi_baud_bits(84_000_000, 0), Err(DividerError::ZeroRate));
    }

    #[test]
    fn sbus_baud_rate_is_exact_on_both_clock_trees() {
        // SBUS: 100 000 Bd from APB1 (42 MHz on the PLL tree, 16 MHz on HSI).
        assert_eq!(usart_brr(42_000_000, 100_000), Ok(420));
        assert_eq!(usart_brr(16_000_000, 100_000), Ok(160));
        assert_eq!(baud_error_ppm(42_000_000, 100_000, 420), 0);
    }

    #[test]
    fn brr_matches_the_reference_manual_and_stays_accurate() {
        // f_PCLK = 84 MHz, OVER8 = 0, 460.8 kBd: USARTDIV = 84e6 / (16 · 460800) = 11.39
        // → mantissa 11, fraction round(0.39 · 16) = 6 → BRR = 11·16 + 6 = 0xB6.
        assert_eq!(usart_brr(84_000_000, 460_800), Ok(0xB6));
        for pclk in [16_000_000, 84_000_000] {
            let brr = usart_brr(pclk, 460_800).unwrap();
            // A UART receiver tolerates a few percent; stay under 1 %.
            assert!(baud_error_ppm(pclk, 460_800, brr) < 10_000, "{pclk}");
        }
        assert_eq!(
            usart_brr(1_000_000, 460_800),
            Err(DividerError::ClockTooSlow)
        );
        assert_eq!(usart_brr(84_000_000, 0), Err(DividerError::ZeroRate));
        assert_eq!(usart_brr(84_000_000, 1), Err(DividerError::OutOfRange));
    }
}
