//! SpeedyBee F405 V4 (STM32F405RGT6, ICM-42688-P on SPI1, 8 MHz
//! HSE) flying a TREX 700L: the default board of the image. Every pin, alternate function
//! and timer channel the image uses on it is named here and nowhere else (its memory
//! layout is the chip's: the workspace's `memory.x`).
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
//! | status LED (active low)  | GPIO           | PC13              | on board         |
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
//! ([`SWASH_FRAME_HZ`], [`TAIL_FRAME_HZ`], [`ESC_FRAME_HZ`]: the rates at boot; the
//! swash and tail timers then take the parameters `SERVO_RATE` and `TAIL_RATE`). A frame
//! rate is usable when its period is longer than the longest pulse (`MAX_FRAME_HZ`,
//! checked when the image is built). Every servo pulse is clamped to 500–2100 µs, which
//! holds the standard 1520 µs centre convention and the narrow-band 760 µs one.
//!
//! Under QEMU (`-M netduinoplus2`, the same chip): USART1 is the machine's first
//! `-serial`, USART2 the second; TIM2..TIM5 and USART1..6 are emulated, TIM8 is not
//! (its writes go nowhere), which leaves the emulated runs unchanged.

use crate::chip::pins::{
    pin, BoardMap, Crystal, ImuPins, Led, Output, OutputTimer, Port, TimerRate,
};
use sweephold_firmware::imu::ImuRotation;

/// Frame rate of the swash servos (TIM4 and TIM3) at boot [Hz], until the parameter
/// table's `SERVO_RATE` is applied. 50 Hz is safe for every servo.
pub const SWASH_FRAME_HZ: u32 = 50;
/// Frame rate of the tail servo (TIM8) at boot [Hz], until `TAIL_RATE` is applied.
pub const TAIL_FRAME_HZ: u32 = 50;
/// Frame rate of the ESC's throttle pulse (TIM2) [Hz]: every PWM ESC reads 50 Hz.
pub const ESC_FRAME_HZ: u32 = 50;

/// The board's map.
pub const BOARD: BoardMap = BoardMap {
    name: "SpeedyBee F405 V4",
    crystal: Crystal::hz(8_000_000),
    servos: [
        // M1, M2: swash servos 1 and 2.
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
        // M3: swash servo 3.
        Output {
            pin: pin(Port::B, 0, 2),
            timer: OutputTimer::Tim3,
            channel: 3,
        },
        // M5: the tail servo.
        Output {
            pin: pin(Port::C, 8, 3),
            timer: OutputTimer::Tim8,
            channel: 3,
        },
    ],
    // M7.
    esc: Output {
        pin: pin(Port::B, 10, 1),
        timer: OutputTimer::Tim2,
        channel: 3,
    },
    output_timers: &[
        TimerRate {
            timer: OutputTimer::Tim4,
            frame_hz: SWASH_FRAME_HZ,
        },
        TimerRate {
            timer: OutputTimer::Tim3,
            frame_hz: SWASH_FRAME_HZ,
        },
        TimerRate {
            timer: OutputTimer::Tim8,
            frame_hz: TAIL_FRAME_HZ,
        },
        TimerRate {
            timer: OutputTimer::Tim2,
            frame_hz: ESC_FRAME_HZ,
        },
    ],
    link_tx: pin(Port::A, 9, 7),
    link_rx: pin(Port::A, 10, 7),
    sbus_rx: pin(Port::A, 3, 7),
    log_tx: pin(Port::C, 10, 7),
    imu: ImuPins {
        sck: pin(Port::A, 5, 5),
        miso: pin(Port::A, 6, 5),
        mosi: pin(Port::A, 7, 5),
        cs: pin(Port::A, 4, 0),
        int: pin(Port::C, 4, 0),
    },
    // The chip top face up, turned 90° clockwise seen from above: body = (y, x, −z),
    // Betaflight's `GYRO_1_ALIGN CW90_DEG` and ArduPilot's `ROTATION_PITCH_180_YAW_270`
    // alike (docs/decisions/2026-11-26-imu-mounting-defaults.md).
    imu_mounting: ImuRotation::Roll180Yaw90,
    // Betaflight's `LED0_PIN PC13` without `LED0_INVERTED` (its LED driver lights a
    // non-inverted LED by driving the pin low), ArduPilot's `PC13 LED0 OUTPUT`.
    led: Some(Led {
        pin: pin(Port::C, 13, 0),
        active_low: true,
    }),
    swd: [pin(Port::A, 13, 0), pin(Port::A, 14, 0)],
};

const _: () = BOARD.check();
