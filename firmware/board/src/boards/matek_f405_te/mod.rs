//! Matek F405-TE (STM32F405RGT6, ICM-42688-P on SPI1, 8 MHz HSE) flying a TREX 700L:
//! the second board of the image (`cargo fw --features board-matek-f405-te`). Every pin,
//! alternate function and timer channel the image uses on it is named here (its memory
//! layout is the chip's: the workspace's `memory.x`). Where the map comes from and what
//! is still to be checked on a real board: `README.md` in this folder.
//!
//! | function                 | peripheral     | pin(s)            | pad on the board |
//! |--------------------------|----------------|-------------------|------------------|
//! | IMU (ICM-42688-P)        | SPI1           | PA5 SCK, PB4 MISO, PA7 MOSI, PC14 CS, PC15 INT | on board |
//! | SBUS receiver            | USART2 RX      | PA3 (AF7)         | RX2 (through an inverter: see README) |
//! | host link (telemetry, in the loop) | USART1 | PA9 TX, PA10 RX (AF7) | TX1 / RX1   |
//! | onboard log (OpenLog)    | USART3 TX      | PC10 (AF7)        | TX3              |
//! | swash servo 1            | TIM2 CH4       | PB11 (AF1)        | S5               |
//! | swash servo 2            | TIM2 CH3       | PB10 (AF1)        | S6               |
//! | swash servo 3            | TIM2 CH2       | PB3 (AF1)         | S7               |
//! | tail servo               | TIM8 CH4       | PC9 (AF3)         | S1               |
//! | ESC (throttle)           | TIM1 CH1       | PA8 (AF1)         | S4               |
//! | loop tick                | TIM5           | —                 | —                |
//! | status LED               | —              | (PA14, PA13: the SWD pins) | —       |
//! | SWD (probe-rs, RTT logs) | —              | PA13 SWDIO, PA14 SWCLK | SWD pads    |
//!
//! The three swash servos share TIM2 (one frame rate, [`SWASH_FRAME_HZ`]); the tail has
//! TIM8 and the ESC TIM1 to themselves. S2 (PC8, TIM8 CH3) shares the tail's TIM8, S8
//! (PA15, TIM2 CH1) the swash's TIM2; S3 (PB15) is TIM1's complementary output CH3N,
//! which the servo driver does not drive. The board's two LEDs sit on the SWD pins: the
//! image leaves them to the debugger and has no status LED here.
//!
//! Under QEMU (`-M netduinoplus2`, the same chip) only TIM2..TIM5 are emulated: the
//! tail's TIM8 and the ESC's TIM1 writes go nowhere, the swash servos' TIM2 compare
//! registers are written as on the board.

use crate::chip::pins::{pin, BoardMap, Crystal, ImuPins, Output, OutputTimer, Port, TimerRate};
use sweephold_firmware::imu::ImuRotation;

/// Frame rate of the swash servos (TIM2) at boot [Hz], until `SERVO_RATE` is applied.
pub const SWASH_FRAME_HZ: u32 = 50;
/// Frame rate of the tail servo (TIM8) at boot [Hz], until `TAIL_RATE` is applied.
pub const TAIL_FRAME_HZ: u32 = 50;
/// Frame rate of the ESC's throttle pulse (TIM1) [Hz].
pub const ESC_FRAME_HZ: u32 = 50;

/// The board's map.
pub const BOARD: BoardMap = BoardMap {
    name: "Matek F405-TE",
    crystal: Crystal::hz(8_000_000),
    servos: [
        // S5, S6, S7: the swash servos.
        Output {
            pin: pin(Port::B, 11, 1),
            timer: OutputTimer::Tim2,
            channel: 4,
        },
        Output {
            pin: pin(Port::B, 10, 1),
            timer: OutputTimer::Tim2,
            channel: 3,
        },
        Output {
            pin: pin(Port::B, 3, 1),
            timer: OutputTimer::Tim2,
            channel: 2,
        },
        // S1: the tail servo.
        Output {
            pin: pin(Port::C, 9, 3),
            timer: OutputTimer::Tim8,
            channel: 4,
        },
    ],
    // S4.
    esc: Output {
        pin: pin(Port::A, 8, 1),
        timer: OutputTimer::Tim1,
        channel: 1,
    },
    output_timers: &[
        TimerRate {
            timer: OutputTimer::Tim2,
            frame_hz: SWASH_FRAME_HZ,
        },
        TimerRate {
            timer: OutputTimer::Tim8,
            frame_hz: TAIL_FRAME_HZ,
        },
        TimerRate {
            timer: OutputTimer::Tim1,
            frame_hz: ESC_FRAME_HZ,
        },
    ],
    link_tx: pin(Port::A, 9, 7),
    link_rx: pin(Port::A, 10, 7),
    sbus_rx: pin(Port::A, 3, 7),
    log_tx: pin(Port::C, 10, 7),
    imu: ImuPins {
        sck: pin(Port::A, 5, 5),
        miso: pin(Port::B, 4, 5),
        mosi: pin(Port::A, 7, 5),
        cs: pin(Port::C, 14, 0),
        int: pin(Port::C, 15, 0),
    },
    // The chip top face down: body = (−y, x, z), Betaflight's `GYRO_1_ALIGN
    // CW270_DEG_FLIP` (docs/decisions/2026-11-26-imu-mounting-defaults.md).
    imu_mounting: ImuRotation::Yaw90,
    led: None,
    swd: [pin(Port::A, 13, 0), pin(Port::A, 14, 0)],
};

const _: () = BOARD.check();
