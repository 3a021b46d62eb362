//! The STM32F405 board under the flight logic: clocks, the tick timer, the servo PWM,
//! the USART frame link and the loop that ties them to
//! [`sweephold_firmware::FlightController`].
//!
//! | function            | peripheral | pins                  |
//! |---------------------|------------|-----------------------|
//! | frame link (8N1)    | USART1     | PA9 TX, PA10 RX (AF7) |
//! | servo 1, 2 (swash)  | TIM3 CH1/2 | PA6, PA7 (AF2)        |
//! | servo 3 (swash)     | TIM3 CH3   | PB0 (AF2)             |
//! | servo 4 (tail)      | TIM3 CH4   | PB1 (AF2)             |
//! | loop tick           | TIM2       | —                     |
//! | logs (defmt)        | RTT        | SWD (QEMU: semihosting file, see [`log`]) |
//!
//! Register access goes through [`regs`] only (no PAC); the drivers above it are safe
//! code. See `firmware/README.md` for wiring, flashing and the QEMU boot check.

pub mod clocks;
pub mod dividers;
pub mod gpio;
pub mod interrupts;
pub mod link;
pub mod log;
pub mod nvic;
pub mod regs;
pub mod ring;
pub mod runner;
pub mod semihosting;
pub mod servo;
pub mod ticker;
pub mod usart;

/// Put the aircraft in the safe state from any context (panic, fault): interrupts off,
/// servos to their failsafe pulses, the link's interrupt masked. Touches registers only,
/// no driver state, so it works whatever the interrupted code held.
pub fn safe_state() {
    cortex_m::interrupt::disable();
    servo::force_failsafe();
    usart::silence();
}
