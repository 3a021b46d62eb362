//! The STM32F405 board under the flight logic: clocks, the tick timer, the servo PWM,
//! the USART frame link and the loop that ties them to
//! [`sweephold_firmware::FlightController`].
//!
//! Which pin and peripheral does what is the board's pin map, [`pins`] (a SpeedyBee
//! F405 V4 flying a TREX 700L): the frame link on USART1, the servos and the ESC on
//! TIM4/TIM3/TIM8/TIM2, the loop tick on TIM5, logs over RTT (SWD; QEMU: a semihosting
//! file, see [`log`]).
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
pub mod pins;
pub mod regs;
pub mod ring;
pub mod runner;
pub mod semihosting;
pub mod servo;
pub mod ticker;
pub mod usart;

/// Put the aircraft in the safe state from any context (panic, fault): interrupts off,
/// servos to their failsafe pulses, the ESC to the throttle cut, the link's interrupt masked. Touches registers only,
/// no driver state, so it works whatever the interrupted code held.
pub fn safe_state() {
    cortex_m::interrupt::disable();
    servo::force_failsafe();
    usart::silence();
}
