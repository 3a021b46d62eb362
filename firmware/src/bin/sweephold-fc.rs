//! `sweephold-fc`: the STM32F405 flight-controller image (`cargo fw`).
//!
//! Boots on the board and, unchanged, in `qemu-system-arm -M netduinoplus2`. The board
//! support lives in `firmware/src/board/` (included below); the flight logic is the
//! `sweephold_firmware` library. On the host this is an empty program so that
//! `cargo build --workspace` works; the board's divider arithmetic is unit-tested there.
#![cfg_attr(target_os = "none", no_std, no_main)]
#![deny(unsafe_op_in_unsafe_fn)]

#[cfg(target_os = "none")]
#[path = "../board/mod.rs"]
mod board;

/// Host unit tests of the board's pure arithmetic.
#[cfg(all(test, not(target_os = "none")))]
#[path = "../board/dividers.rs"]
mod dividers;

/// Host unit tests of the board's pin map.
#[cfg(all(test, not(target_os = "none")))]
#[path = "../board/pins.rs"]
mod pins;

/// Host unit tests of the board's byte ring.
#[cfg(all(test, not(target_os = "none")))]
#[path = "../board/ring.rs"]
mod ring;

#[cfg(target_os = "none")]
mod image {
    use cortex_m_rt::{entry, exception, ExceptionFrame};

    use crate::board;

    // Log lines carry the loop tick they were written in (the `tick` of the Sample).
    defmt::timestamp!("{=u32}", board::log::tick());

    #[entry]
    fn main() -> ! {
        board::log::init();
        defmt::info!(
            "sweephold-fc {=str}, protocol {=u16}.{=u16}",
            env!("CARGO_PKG_VERSION"),
            sweephold_protocol::PROTOCOL_VERSION.major,
            sweephold_protocol::PROTOCOL_VERSION.minor
        );
        board::runner::run()
    }

    /// Every device interrupt lands here (no PAC, so no named vectors): route it.
    /// cortex-m-rt requires the `unsafe fn` signature; the body is safe code.
    #[exception]
    unsafe fn DefaultHandler(irqn: i16) {
        if !board::interrupts::dispatch(irqn) {
            defmt::panic!("unexpected exception or interrupt {=i16}", irqn);
        }
    }

    /// A fault: outputs to the safe state, then stop. cortex-m-rt requires the `unsafe
    /// fn` signature; the body is safe code.
    #[exception]
    unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
        board::safe_state();
        defmt::error!("hard fault at pc {=u32:#010x}", frame.pc());
        loop {
            cortex_m::asm::nop();
        }
    }

    /// A panic: outputs to the safe state (servos at their failsafe pulses, interrupts
    /// off so nothing moves them again), say where, and stop.
    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        board::safe_state();
        match info.location() {
            Some(at) => defmt::error!("panic at {=str}:{=u32}", at.file(), at.line()),
            None => defmt::error!("panic"),
        }
        loop {
            cortex_m::asm::nop();
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("sweephold-fc is the flight-controller image: build it with `cargo fw`.");
    std::process::exit(2);
}
