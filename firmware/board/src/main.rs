//! `sweephold-fc`: the flight-controller image for an STM32F405 flight controller, one
//! image for every aircraft: what it flies is its parameter table, stored in the chip's
//! flash (`cargo fw`; by default for a SpeedyBee F405 V4, `--features
//! board-matek-f405-te` for a Matek F405-TE).
//!
//! Boots on the board and, unchanged, in `qemu-system-arm -M netduinoplus2`. Three rooms:
//!
//! - `image/`: the image logic, the same on every board (boot, the control loop of both
//!   run modes, the frame link, the defmt logger, the parameters and their store)
//!   around [`sweephold_firmware::FlightController`] and the board application;
//! - `chip/`: the STM32F405 drivers on the `stm32f4` peripheral access crate, which take
//!   the peripherals once (`chip::devices`) and their pins from a board map;
//! - `boards/`: one folder per board (its pin map and crystal) and the choice
//!   of the board the image is built for.
//!
//! `ring` is the byte ring the drivers and the logger share. On the host this is an
//! empty program (so that `cargo build --workspace` works) whose unit tests cover the
//! board maps, the divider arithmetic and the byte ring.
//!
//! A panic or a hard fault puts the outputs in their safe state (servos at their
//! failsafe pulses, the ESC at the throttle cut) and resets the MCU; the boot path
//! starts with the same outputs. `unsafe` appears only where the PAC or the Cortex-M
//! core requires it, each with a `SAFETY` comment.
//!
//! **What it may import.** The flight logic (`sweephold-firmware`), the wire protocol
//! (`sweephold-protocol`), the PAC and the Cortex-M runtime crates; no host crate. It is
//! the only library or program of the workspace with `unsafe`: every other one forbids
//! it (`#![forbid(unsafe_code)]`).
#![cfg_attr(target_os = "none", no_std, no_main)]
#![deny(unsafe_op_in_unsafe_fn)]

#[cfg(any(target_os = "none", test))]
mod boards;
#[cfg(any(target_os = "none", test))]
mod chip;
#[cfg(target_os = "none")]
mod image;
#[cfg(any(target_os = "none", test))]
mod ring;

#[cfg(target_os = "none")]
mod vectors {
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use stm32f4::stm32f405::interrupt;

    use crate::boards::BOARD;
    use crate::chip::{logport, sbus_uart, servo, ticker, usart};
    use crate::image::{log, runner};

    // Log lines carry the loop tick they were written in (the `tick` of the Sample).
    defmt::timestamp!("{=u32}", log::tick());

    #[entry]
    fn main() -> ! {
        log::init();
        defmt::info!(
            "sweephold-fc {=str}, protocol {=u16}.{=u16}",
            env!("CARGO_PKG_VERSION"),
            sweephold_protocol::PROTOCOL_VERSION.major,
            sweephold_protocol::PROTOCOL_VERSION.minor
        );
        runner::run()
    }

    /// The loop tick.
    #[interrupt]
    fn TIM5() {
        ticker::on_interrupt();
    }

    /// The host link: a received byte, or room in the transmitter.
    #[interrupt]
    fn USART1() {
        usart::on_interrupt();
    }

    /// The SBUS receiver: a received byte.
    #[interrupt]
    fn USART2() {
        sbus_uart::on_interrupt();
    }

    /// The onboard log: room in its transmitter.
    #[interrupt]
    fn USART3() {
        logport::on_interrupt();
    }

    /// Put the aircraft in the safe state from any context (panic, fault): interrupts
    /// off, servos to their failsafe pulses, the ESC to the throttle cut, the link's
    /// interrupt masked. Touches registers only, no driver state, so it works whatever
    /// the interrupted code held.
    fn safe_state() {
        cortex_m::interrupt::disable();
        servo::force_failsafe_anywhere(&BOARD);
        usart::silence();
        sbus_uart::silence();
        logport::silence();
    }

    /// An interrupt or exception the image never enabled: a fault like any other.
    /// cortex-m-rt requires the `unsafe fn` signature; the body is safe code.
    #[exception]
    unsafe fn DefaultHandler(irqn: i16) {
        safe_state();
        defmt::error!("unexpected exception or interrupt {=i16}: reset", irqn);
        cortex_m::peripheral::SCB::sys_reset()
    }

    /// A fault: outputs to the safe state, say where, and reset: the boot path starts
    /// Disarmed with the same safe outputs. cortex-m-rt requires the `unsafe fn`
    /// signature; the body is safe code.
    #[exception]
    unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
        safe_state();
        defmt::error!("hard fault at pc {=u32:#010x}: reset", frame.pc());
        cortex_m::peripheral::SCB::sys_reset()
    }

    /// A panic: outputs to the safe state, say where, and reset.
    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        safe_state();
        match info.location() {
            Some(at) => defmt::error!("panic at {=str}:{=u32}: reset", at.file(), at.line()),
            None => defmt::error!("panic: reset"),
        }
        cortex_m::peripheral::SCB::sys_reset()
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("sweephold-fc is the flight-controller image: build it with `cargo fw`.");
    std::process::exit(2);
}
