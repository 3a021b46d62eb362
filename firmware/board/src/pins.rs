//! The board's pin map: a SpeedyBee F405 V4 (STM32F405RGT6, ICM-42688-P on SPI1, 8 MHz
//! HSE) flying a TREX 700L. Every pin, alternate function and timer channel the image
//! uses is named here and nowhere else.
//!
//! Taken from the board's published Betaflight target (`configs/SPEEDYBEEF405V4`):
//!
//! | function                 | peripheral     | pin(s)            | pad on the board |
//! |--------------------------|----------------|-------------------|------------------|
//! | IMU (ICM-42688-P)        | SPI1           | PA5 SCK, PA6 MISO, PA7 MOSI, PA4 CS, PC4 INT | on board |
//! | SBUS receiver            | USART2 RX      | PA3 (AF7)         | SBUS (hardware inverter into RX2) |
//! | host link (telemetry, in the loop) | USART1 | PA9 TX, PA10 RX (AF7) | T1 / R1     |
//! | onboard log (OpenLog)    | USART3 TX      | PC10 (AF7)        | T3               |
//! | swash servo 1            | TIM4 CH1       | PB6 (AF2)         | M1               |
//! | swash servo 2            | TIM4 CH2       | PB7 (AF2)         | M2               |
//! | swash servo 3            | TIM3 CH3       | PB0 (AF2)         | M3               |
//! | tail servo               | TIM8 CH3       | PC8 (AF3)         | M5               |
//! | ESC (throttle)           | TIM2 CH3       | PB10 (AF1)        | M7               |
//! | loop tick                | TIM5           | —                 | —                |
//! | status LED               | GPIO           | PC13              | on board         |
//! | SWD (probe-rs, RTT logs) | —              | PA13 SWDIO, PA14 SWCLK | SWD pads    |
//!
//! Nothing of the image sits on the IMU's SPI1 pins. The STM32F405's USARTs cannot
//! invert their input: SBUS (inverted UART, 100 000 Bd 8E2) reaches PA3 through the
//! board's own inverter behind the SBUS pad. UART4 (PA0/PA1), UART6 (PC6/PC7) and the
//! pads M4 (TIM3 CH4), M6 (TIM8 CH4) and M8 (TIM2 CH1) stay free; M4 shares TIM3 with
//! swash servo 3 and runs at the swash frame rate, M6 shares the tail's TIM8, M8 the
//! ESC's TIM2.
//!
//! **Frame rates** are per timer, so per group of outputs sharing one: the swash servos
//! (TIM4 and TIM3), the tail servo (TIM8) and the ESC (TIM2) each have their own
//! ([`SWASH_FRAME_HZ`], [`TAIL_FRAME_HZ`], [`ESC_FRAME_HZ`]). A frame rate is usable
//! when its period is longer than the longest pulse ([`MAX_FRAME_HZ`], checked when the
//! image is built). Every servo pulse is clamped to 900–2100 µs (the standard 1520 µs
//! centre convention); servos of the narrow-band 760 µs-centre convention (some tail
//! servos) are not supported by this range.
//!
//! Under QEMU (`-M netduinoplus2`, the same chip): USART1 is the machine's first
//! `-serial`, USART2 the second; TIM2..TIM5 and USART1..6 are emulated, TIM8 is not
//! (its writes go nowhere), which leaves the emulated runs unchanged.

// The map names the whole board: pins of drivers the image does not start yet (IMU,
// SBUS receiver, LED) are part of it, so they are reserved here.
#![allow(dead_code)]

/// A GPIO port of the pins the image uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Port {
    /// GPIOA.
    A,
    /// GPIOB.
    B,
    /// GPIOC.
    C,
}

/// One pin in one of its alternate functions (STM32F405 datasheet, Table 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pin {
    /// Port.
    pub port: Port,
    /// Pin number in the port, 0..=15.
    pub number: u8,
    /// Alternate function number, 0..=15.
    pub af: u8,
}

const fn pin(port: Port, number: u8, af: u8) -> Pin {
    Pin { port, number, af }
}

/// The timers that drive outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputTimer {
    /// TIM2 (APB1, 32-bit): the ESC.
    Tim2,
    /// TIM3 (APB1, 16-bit): swash servo 3 (and the free M4).
    Tim3,
    /// TIM4 (APB1, 16-bit): swash servos 1 and 2.
    Tim4,
    /// TIM8 (APB2, advanced, 16-bit): the tail servo (and the free M6).
    Tim8,
}

impl OutputTimer {
    /// Every output timer, in the order they are started.
    pub const ALL: [OutputTimer; 4] = [
        OutputTimer::Tim4,
        OutputTimer::Tim3,
        OutputTimer::Tim8,
        OutputTimer::Tim2,
    ];

    /// The PWM frame rate of this timer's outputs [Hz].
    pub const fn frame_hz(self) -> u32 {
        match self {
            OutputTimer::Tim3 | OutputTimer::Tim4 => SWASH_FRAME_HZ,
            OutputTimer::Tim8 => TAIL_FRAME_HZ,
            OutputTimer::Tim2 => ESC_FRAME_HZ,
        }
    }
}

/// One PWM output pad: its pin and its timer channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Output {
    /// The pin, in its timer alternate function.
    pub pin: Pin,
    /// The timer.
    pub timer: OutputTimer,
    /// The compare channel, 1..=4.
    pub channel: u8,
}

/// The servo outputs in wire order (`ActuatorOut::servo_us`): swash 1, 2, 3, tail.
pub const SERVOS: [Output; 4] = [
    Output {
        pin: pin(Port::B, 6, 2),
        timer: OutputTimer::Tim4,
        channel: 1,
    },
    Output {
        pin: pin(Port::B, 7, 2),
        timer: OutputTimer::Tim4,
        channel: 2,
    },
    Output {
        pin: pin(Port::B, 0, 2),
        timer: OutputTimer::Tim3,
        channel: 3,
    },
    Output {
        pin: pin(Port::C, 8, 3),
        timer: OutputTimer::Tim8,
        channel: 3,
    },
];

/// The ESC's throttle output (pad M7).
pub const ESC: Output = Output {
    pin: pin(Port::B, 10, 1),
    timer: OutputTimer::Tim2,
    channel: 3,
};

/// Frame rate of the swash servos (TIM4 and TIM3) [Hz]. 50 Hz is safe for every servo;
/// digital 700-class cyclic servos take up to 333 Hz (a 3003 µs frame).
pub const SWASH_FRAME_HZ: u32 = 50;
/// Frame rate of the tail servo (TIM8) [Hz]. Digital tail servos of the standard
/// convention take up to 333 Hz.
pub const TAIL_FRAME_HZ: u32 = 50;
/// Frame rate of the ESC's throttle pulse (TIM2) [Hz]: every PWM ESC reads 50 Hz.
pub const ESC_FRAME_HZ: u32 = 50;

/// Shortest pulse ever put on a pin [µs].
pub const MIN_PULSE_US: u16 = 900;
/// Longest pulse ever put on a pin [µs].
pub const MAX_PULSE_US: u16 = 2100;
/// Highest frame rate whose period still holds the longest pulse plus a 100 µs gap [Hz].
pub const MAX_FRAME_HZ: u32 = 1_000_000 / (MAX_PULSE_US as u32 + 100);

const _: () = {
    let mut i = 0;
    while i < OutputTimer::ALL.len() {
        let hz = OutputTimer::ALL[i].frame_hz();
        assert!(hz > 0 && hz <= MAX_FRAME_HZ, "frame rate out of range");
        i += 1;
    }
};

/// Host link USART1 TX (pad T1).
pub const LINK_TX: Pin = pin(Port::A, 9, 7);
/// Host link USART1 RX (pad R1).
pub const LINK_RX: Pin = pin(Port::A, 10, 7);

/// SBUS receiver input, USART2 RX (behind the SBUS pad's inverter).
pub const SBUS_RX: Pin = pin(Port::A, 3, 7);

/// Onboard logger output, USART3 TX (pad T3).
pub const LOG_TX: Pin = pin(Port::C, 10, 7);

/// IMU SPI1 clock.
pub const IMU_SCK: Pin = pin(Port::A, 5, 5);
/// IMU SPI1 data from the IMU.
pub const IMU_MISO: Pin = pin(Port::A, 6, 5);
/// IMU SPI1 data to the IMU.
pub const IMU_MOSI: Pin = pin(Port::A, 7, 5);
/// IMU chip select (GPIO output, active low).
pub const IMU_CS: Pin = pin(Port::A, 4, 0);
/// IMU data-ready interrupt (GPIO input, EXTI4).
pub const IMU_INT: Pin = pin(Port::C, 4, 0);

/// Status LED (GPIO output).
pub const LED: Pin = pin(Port::C, 13, 0);

/// The SWD pins: never reconfigured by the image.
pub const SWD: [Pin; 2] = [pin(Port::A, 13, 0), pin(Port::A, 14, 0)];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pin the map names, with what it is for.
    fn all_pins() -> Vec<(Pin, &'static str)> {
        let mut pins = vec![
            (LINK_TX, "link tx"),
            (LINK_RX, "link rx"),
            (SBUS_RX, "sbus"),
            (LOG_TX, "log"),
            (IMU_SCK, "imu sck"),
            (IMU_MISO, "imu miso"),
            (IMU_MOSI, "imu mosi"),
            (IMU_CS, "imu cs"),
            (IMU_INT, "imu int"),
            (LED, "led"),
            (SWD[0], "swdio"),
            (SWD[1], "swclk"),
            (ESC.pin, "esc"),
        ];
        pins.extend(SERVOS.iter().map(|servo| (servo.pin, "servo")));
        pins
    }

    #[test]
    fn no_pin_is_used_twice() {
        let pins = all_pins();
        for (i, (a, what_a)) in pins.iter().enumerate() {
            for (b, what_b) in pins.iter().skip(i + 1) {
                assert!(
                    (a.port, a.number) != (b.port, b.number),
                    "{what_a} and {what_b} share a pin"
                );
            }
        }
    }

    #[test]
    fn no_output_sits_on_the_imu_spi() {
        let imu = [IMU_SCK, IMU_MISO, IMU_MOSI, IMU_CS, IMU_INT];
        for output in SERVOS.iter().chain([&ESC]) {
            assert!(!imu
                .iter()
                .any(|p| (p.port, p.number) == (output.pin.port, output.pin.number)));
        }
    }

    #[test]
    fn timer_channels_are_distinct_and_groups_share_no_timer() {
        let outputs: Vec<Output> = SERVOS.iter().copied().chain([ESC]).collect();
        for (i, a) in outputs.iter().enumerate() {
            assert!((1..=4).contains(&a.channel));
            for b in outputs.iter().skip(i + 1) {
                assert!((a.timer, a.channel) != (b.timer, b.channel));
            }
        }
        // The swash servos share a rate group; the tail and the ESC have timers of their
        // own, so their rates are set independently.
        let swash = [SERVOS[0].timer, SERVOS[1].timer, SERVOS[2].timer];
        assert!(!swash.contains(&SERVOS[3].timer));
        assert!(!swash.contains(&ESC.timer));
        assert_ne!(SERVOS[3].timer, ESC.timer);
        assert!(swash.iter().all(|t| t.frame_hz() == SWASH_FRAME_HZ));
    }

    #[test]
    fn alternate_functions_match_the_peripherals() {
        // Datasheet Table 9: TIM1/2 AF1, TIM3..5 AF2, TIM8..11 AF3, SPI1/2 AF5,
        // USART1..3 AF7.
        for output in SERVOS.iter().chain([&ESC]) {
            let af = match output.timer {
                OutputTimer::Tim2 => 1,
                OutputTimer::Tim3 | OutputTimer::Tim4 => 2,
                OutputTimer::Tim8 => 3,
            };
            assert_eq!(output.pin.af, af);
        }
        for spi in [IMU_SCK, IMU_MISO, IMU_MOSI] {
            assert_eq!(spi.af, 5);
        }
        for usart in [LINK_TX, LINK_RX, SBUS_RX, LOG_TX] {
            assert_eq!(usart.af, 7);
        }
    }
}
